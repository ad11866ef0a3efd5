"""The main command's 15 figures drawn again from a finished run directory with this tree's datasets and figures
(one-off probe): what `snakemake --cores 2` draws from those runs today, without remaking them.

    PYTHONPATH=src python docs/journal/2026-12-07-gci-safety-factor/redraw.py RUN_DIR OUT_DIR [--config FILE]

RUN_DIR is a workflow directory the main command finished in (its ``results/runs/*.nc`` and the refinement
decisions ``results/refinement/*.json``); each MPM figure's dataset is built as the workflow's ``mpm_dataset`` job
builds it (``plough.study.mpm_figures.build_dataset``, each run file checked against its scene as the config makes
it), except that the solver check is the runs' own: every run file read must carry one and the same solver
fingerprint, which the dataset records (``runs_solver_fingerprint``, ``runs_git_commit``) beside this tree's
provenance. Fig. 3 and 4 (analytical) are built as ``analytical_dataset`` builds them. Each figure is drawn with
``plough.figures.plot`` to OUT_DIR/figNN.png and .pdf beside its dataset OUT_DIR/figNN.nc.

Runs made before ``interface.pressure`` existed (ba5a491) record a boundary-layer scene without that key; they ran
the one reading there was, ``particles``, today's default (the key's commit left it bitwise unchanged). Where the
config's scene has ``interface.pressure: particles`` and the run's lacks the key, the run file is read from a copy
under OUT_DIR/runs whose recorded scene has the key added; nothing else of the scene check is relaxed.
"""

from __future__ import annotations

import argparse
import json
import shutil
from pathlib import Path

import xarray as xr
import yaml

from plough.figures import plot
from plough.io import write_netcdf_atomic
from plough.study import analytical_figures, matrix, mpm_figures


def runs_fingerprint(paths: list[Path]) -> tuple[str, str]:
    """The one solver fingerprint and git commit the run files share (markers included)."""
    seen = set()
    for path in paths:
        with xr.open_dataset(path) as ds:
            seen.add((str(ds.attrs.get("solver_fingerprint")), str(ds.attrs.get("git_commit"))))
    if len({s for s, _ in seen}) != 1:
        raise SystemExit(f"the run files carry {len({s for s, _ in seen})} solver fingerprints, not one: "
                         f"{sorted(seen)}")
    return min(seen)


def with_pressure_key(path: Path, copies: Path) -> Path:
    """``path``, or a copy under ``copies`` whose recorded boundary-layer scene names the reading it ran with,
    ``particles``, where the run predates the ``interface.pressure`` key (module docstring)."""
    with xr.open_dataset(path) as ds:
        scene = json.loads(ds.attrs["scene"])
    interface = scene.get("interface", {})
    if interface.get("model") != "boundary_layer" or "pressure" in interface:
        return path
    interface["pressure"] = "particles"
    copies.mkdir(parents=True, exist_ok=True)
    copy = copies / path.name
    shutil.copyfile(path, copy)
    with xr.load_dataset(copy) as ds:
        ds.attrs["scene"] = json.dumps(scene)
        ds.attrs["scene_pressure_key_added"] = "interface.pressure: particles (the run predates the key)"
        ds.to_netcdf(copy)
    return copy


def main(run_dir: Path, out_dir: Path, config_path: Path) -> None:
    config = yaml.safe_load(config_path.read_text())
    out_dir.mkdir(parents=True, exist_ok=True)
    decisions = [json.loads(p.read_text()) for p in sorted((run_dir / "results" / "refinement").glob("*.json"))]
    not_needed = {d["finest_run"] for d in decisions if not d["run_finest"]}
    for figure in ("fig03", "fig04", *matrix.MPM_FIGURES, "fig22"):
        if figure in ("fig03", "fig04"):
            ds = analytical_figures.build_dataset(figure, config[analytical_figures.config_section(figure)])
        else:
            runs = matrix.figure_runs(config, "fig21" if figure == "fig22" else figure)
            paths = {rid: run_dir / "results" / "runs" / f"{rid}.nc" for rid in runs if rid not in not_needed}
            solver, commit = runs_fingerprint(list(paths.values()))
            paths = {rid: with_pressure_key(path, out_dir / "runs") for rid, path in paths.items()}
            ds = mpm_figures.build_dataset(config, figure, paths, solver=solver,
                                           not_needed=[r for r in runs if r in not_needed])
            ds.attrs.update(runs_solver_fingerprint=solver, runs_git_commit=commit)
        write_netcdf_atomic(ds, out_dir / f"{figure}.nc")
        plot(figure, ds, [out_dir / f"{figure}.png", out_dir / f"{figure}.pdf"])
        print(figure, "drawn", flush=True)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir", type=Path)
    parser.add_argument("out_dir", type=Path)
    parser.add_argument("--config", type=Path, default=Path("config/config.yaml"))
    args = parser.parse_args()
    main(args.run_dir, args.out_dir, args.config)
