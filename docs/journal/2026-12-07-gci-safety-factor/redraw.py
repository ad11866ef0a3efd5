"""The main command's 15 figures drawn again from a finished run directory with this tree's datasets and figures
(one-off probe): what `snakemake --cores 2` draws from those runs today, without remaking them.

    PYTHONPATH=src python docs/journal/2026-12-07-gci-safety-factor/redraw.py RUN_DIR OUT_DIR [--config FILE]

RUN_DIR is a workflow directory the main command finished in (its ``results/runs/*.nc`` and the refinement
decisions ``results/refinement/*.json``, each checked to be the decision on a gated finest run of the config, from
its two coarser runs, under the config's tolerance); each MPM figure's dataset is built as the workflow's
``mpm_dataset`` job builds it (``plough.study.mpm_figures.build_dataset``, each run file checked against its scene
as the config makes it), except that the solver check is the runs' own: every run file of every figure must carry
one and the same solver fingerprint and git commit (or ``--solver``'s fingerprint), which the datasets record
(``runs_solver_fingerprint``, ``runs_git_commit``) beside this tree's provenance. Fig. 3 and 4 (analytical) are
built as ``analytical_dataset`` builds them. Each figure is drawn with ``plough.figures.plot`` from its dataset as
written, to OUT_DIR/figNN.png beside OUT_DIR/figNN.nc.

Runs made before ``interface.pressure`` existed (ba5a491) record a boundary-layer scene without that key; they ran
the one reading there was, ``particles``, today's default (the key's commit left it bitwise unchanged). Such a run
file is read from a temporary copy whose recorded scene has ``interface.pressure: particles`` added, and then checked
against the config's scene as any other: a config of another reading refuses it. Nothing else is relaxed.
"""

from __future__ import annotations

import argparse
import json
import shutil
import tempfile
from pathlib import Path

import xarray as xr
import yaml

from plough.figures import plot
from plough.io import write_netcdf_atomic
from plough.study import analytical_figures, matrix, mpm_figures
from plough.study.runfiles import SOLVER_ATTR


def runs_fingerprint(paths: list[Path], solver: str | None) -> tuple[str, str]:
    """The one solver fingerprint and git commit the run files share (markers included), which must be ``solver``'s
    fingerprint where it is given."""
    seen = set()
    for path in paths:
        with xr.open_dataset(path) as ds:
            seen.add((str(ds.attrs.get(SOLVER_ATTR)), str(ds.attrs.get("git_commit"))))
    if len(seen) != 1 or (solver is not None and min(seen)[0] != solver):
        raise SystemExit(f"the run files carry {sorted(seen)} (solver fingerprint, git commit), not one"
                         + (f" of solver {solver}" if solver is not None else ""))
    return min(seen)


def not_needed_runs(run_dir: Path, config: dict) -> set[str]:
    """The gated finest runs whose refinement decision in ``run_dir`` did not ask for them, each decision checked
    against the config: its run gated, its coarser runs the point's, its tolerance the config's."""
    gated = matrix.skippable_runs(config)
    tolerance = config["mpm"].get("skip_finest_tolerance")
    out = set()
    for path in sorted((run_dir / "results" / "refinement").glob("*.json")):
        d = json.loads(path.read_text())
        if d["finest_run"] not in gated or list(gated[d["finest_run"]]) != list(d["coarser_runs"]) \
                or d["tolerance"] != tolerance:
            raise SystemExit(f"{path}: not the decision this config would make on a gated finest run")
        if not d["run_finest"]:
            out.add(d["finest_run"])
    return out


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


def main(run_dir: Path, out_dir: Path, config_path: Path, solver: str | None) -> None:
    """Build every figure's dataset from ``run_dir`` and draw it into ``out_dir`` (module docstring)."""
    config = yaml.safe_load(config_path.read_text())
    out_dir.mkdir(parents=True, exist_ok=True)
    not_needed = not_needed_runs(run_dir, config)
    figures = ("fig03", "fig04", *matrix.MPM_FIGURES, "fig22")
    # each MPM figure's runs (Fig. 22 draws Fig. 21's points)
    runs = {f: matrix.figure_runs(config, "fig21" if f == "fig22" else f) for f in figures
            if f not in ("fig03", "fig04")}
    every = sorted({run_dir / "results" / "runs" / f"{r}.nc" for ids in runs.values() for r in ids
                    if r not in not_needed})
    solver, commit = runs_fingerprint(every, solver)
    with tempfile.TemporaryDirectory() as copies:
        for figure in figures:
            if figure in ("fig03", "fig04"):
                ds = analytical_figures.build_dataset(figure, config[analytical_figures.config_section(figure)])
            else:
                paths = {r: with_pressure_key(run_dir / "results" / "runs" / f"{r}.nc", Path(copies))
                         for r in runs[figure] if r not in not_needed}
                gated_off = [r for r in runs[figure] if r in not_needed]
                ds = mpm_figures.build_dataset(config, figure, paths, solver=solver, not_needed=gated_off)
                ds.attrs.update(runs_solver_fingerprint=solver, runs_git_commit=commit)
            write_netcdf_atomic(ds, out_dir / f"{figure}.nc")
            plot(figure, xr.load_dataset(out_dir / f"{figure}.nc"), [out_dir / f"{figure}.png"])
            print(figure, "drawn", flush=True)


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("run_dir", type=Path)
    parser.add_argument("out_dir", type=Path)
    parser.add_argument("--config", type=Path, default=Path("config/config.yaml"))
    parser.add_argument("--solver", default=None, help="the solver fingerprint every run file must carry")
    args = parser.parse_args()
    main(args.run_dir, args.out_dir, args.config, args.solver)
