"""The relative ladder against the paper's at guard points (issue 34, item 6): do their h -> 0 values agree?

    python benchmarks/ladder_guard.py --points zinc_bulk_bl0.32-0.95_r500_F7 [--run] [--cores 2]
        [--relative config/config.yaml] [--paper config/paper.yaml] [--out benchmarks/results/ladder_guard.json]

For each point (a key of ``plough.study.matrix.all_points``): its three sizes under the relative ladder
(``--relative``) and under the paper's (``--paper``), and the run ids of both. With ``--run``, the workflow itself
brings the runs up to date (``snakemake --cores N --configfile=<config> results/runs/<id>.nc``, each run under the
config that lists it; a run the two ladders share is one file; a file of another solver or scene is remade).
Every run file is read checked against its scene and this tree's solver (``plough.study.runfiles.load_run``).

Per ladder, mu, mu_pl, mu_sh and dp are extrapolated to h -> 0 as the figures' datasets do
(``plough.study.extrapolation.extrapolate``: Richardson with the observed order and Roache's GCI, else the
flagged fallbacks; from the two coarser sizes where the finest run left a failure marker), with the runs'
sampling errors carried to the limit (``sampling_error``) in quadrature. For the relative ladder also as the
default workflow would show it: from the two coarser sizes where its refinement decision, for a gated finest run
(``plough.study.matrix.skippable_runs``),
(``plough.study.skipping.decide`` under the config's ``mpm.skip_finest_tolerance``) would skip the finest run.

The ladders agree on an output when |value_relative - value_paper| <= hypot(uncertainty_relative,
uncertainty_paper). Caveats the verdicts carry: the two ladders share runs (two of three where the ladders are a
factor 2 apart), so their errors are not independent and the combined uncertainty overstates the noise of the
difference; a flagged limit (fallback or two sizes, Fs = 3) has a wide uncertainty that makes agreement easy; a
missing sampling error is counted as none (``sampling_error_missing``). The issue's other target: the relative
ladder's uncertainty of mu no larger than the paper's.

Writes ``--out`` (the provenance with the solver's fingerprint, which every run read was checked against; one
entry per point: the sizes, each run's values, sampling errors, steadiness and wall time,
each ladder's extrapolations, the verdicts; JSON without NaN: an undefined number is null) and prints a table. A
point whose runs are not all there is reported as such.
"""

from __future__ import annotations

import argparse
import json
import os
import subprocess
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT / "src"))

from plough.fingerprint import solver_fingerprint  # noqa: E402
from plough.io import provenance_attrs  # noqa: E402
from plough.study import matrix, skipping  # noqa: E402
from plough.study.extrapolation import Method, extrapolate, sampling_error, total_uncertainty  # noqa: E402
from plough.study.plan import load_config  # noqa: E402
from plough.study.runfiles import load_run  # noqa: E402

OUTPUTS = ("mu", "mu_pl", "mu_sh", "dp")


def ladders(relative: dict, paper: dict, key: str) -> dict[str, dict]:
    """The point's sizes and run ids under each ladder."""
    out = {}
    for name, config in (("relative", relative), ("paper", paper)):
        point = matrix.all_points(config)[key]
        sizes = tuple(float(h) for h in matrix.point_ladder(config, point).sizes_um)
        out[name] = {"sizes_um": sizes, "runs": [matrix.run_id(point, h) for h in sizes]}
    return out


def make_runs(workdir: Path, configfile: Path, run_ids: list[str], cores: int) -> None:
    """Bring the run files up to date with the workflow (one snakemake call per config; it remakes a file of
    another solver or scene and skips an up-to-date one)."""
    if not run_ids:
        return
    cmd = [sys.executable, "-m", "snakemake", "--cores", str(cores), f"--configfile={configfile}", "--keep-going",
           *(f"results/runs/{r}.nc" for r in run_ids)]
    print("running:", " ".join(cmd), flush=True)
    # the jobs' scripts run with the python of this environment
    env = {**os.environ, "PATH": f"{Path(sys.executable).parent}{os.pathsep}{os.environ.get('PATH', '')}"}
    subprocess.run(cmd, cwd=workdir, check=True, env=env)


def finite_or_none(x: float) -> float | None:
    return float(x) if np.isfinite(x) else None


def limit(sizes_um: tuple[float, ...], values: list[float], errors: list[float]) -> dict:
    """One ladder's h -> 0 value of one output, its GCI-type uncertainty, its sampling error (none where a run's
    is missing) and the two in quadrature."""
    ex = extrapolate(sizes_um, np.asarray(values))
    se = float(sampling_error(sizes_um, np.asarray(values), np.asarray(errors)))
    gci = float(ex.uncertainty)
    return {"sizes_um": list(sizes_um), "value": float(ex.value), "uncertainty_gci": gci,
            "sampling_error": finite_or_none(se), "sampling_error_missing": not np.isfinite(se),
            "uncertainty": float(total_uncertainty(gci, se)), "order": finite_or_none(float(ex.order)),
            "method": Method(int(ex.method)).name.lower(), "flagged": bool(ex.flagged)}


def read_runs(workdir: Path, configs: dict[str, dict], entry: dict) -> tuple[dict, dict]:
    """The point's run files, checked against their scenes and this solver: run id -> dataset, and the
    JSON-ready per-run values (a failure marker: its reason)."""
    solver = solver_fingerprint()
    datasets, values = {}, {}
    for name, config in configs.items():
        scenes = matrix.all_runs(config)
        for rid in entry[name]["runs"]:
            path = workdir / "results" / "runs" / f"{rid}.nc"
            if rid in datasets or not path.exists():
                continue
            ds = load_run(path, rid, scenes[rid], solver)
            datasets[rid] = ds
            if skipping.is_failed(ds) or skipping.is_skipped(ds):
                values[rid] = {"failed": str(ds.attrs.get("failure_reason") or ds.attrs.get("skip_reason"))}
                continue
            values[rid] = {o: float(ds[o]) for o in OUTPUTS} | {
                f"{o}_standard_error": finite_or_none(float(ds[f"{o}_standard_error"]))
                for o in OUTPUTS if f"{o}_standard_error" in ds} | {
                "steady": bool(int(ds["steady"])) if "steady" in ds else None,
                "wall_time_s": float(ds.attrs["cost_wall_time_s"])}
    return datasets, values


def ladder_limits(sizes: tuple[float, ...], ids: list[str], values: dict, two_sizes: bool) -> dict:
    """Each output's limit over the ladder's three sizes, or its two coarser ones."""
    if two_sizes:
        sizes, ids = sizes[:2], ids[:2]

    def err(rid: str, o: str) -> float:
        e = values[rid].get(f"{o}_standard_error")
        return float("nan") if e is None else e

    return {o: limit(sizes, [values[r][o] for r in ids], [err(r, o) for r in ids]) for o in OUTPUTS}


def verdicts(a: dict, b: dict) -> dict:
    out = {}
    for o in OUTPUTS:
        combined = float(np.hypot(a[o]["uncertainty"], b[o]["uncertainty"]))
        out[o] = {"difference": a[o]["value"] - b[o]["value"], "combined_uncertainty": combined,
                  "agree": bool(abs(a[o]["value"] - b[o]["value"]) <= combined),
                  "relative_uncertainty_not_larger": bool(a[o]["uncertainty"] <= b[o]["uncertainty"]),
                  "either_flagged": a[o]["flagged"] or b[o]["flagged"],
                  "sampling_error_missing": a[o]["sampling_error_missing"] or b[o]["sampling_error_missing"]}
    return out


def guard(workdir: Path, relative: dict, paper: dict, key: str) -> dict:
    entry: dict = {"point": key, **ladders(relative, paper, key)}
    datasets, values = read_runs(workdir, {"relative": relative, "paper": paper}, entry)
    entry["run_values"] = values
    missing = sorted({r for name in ("relative", "paper") for r in entry[name]["runs"] if r not in values})
    failed_coarse = [r for name in ("relative", "paper") for r in entry[name]["runs"][:2]
                     if "failed" in values.get(r, {})]
    if missing or failed_coarse:
        entry["missing_runs"] = missing
        entry["failed_coarser_runs"] = failed_coarse
        return entry
    for name in ("relative", "paper"):
        finest = entry[name]["runs"][2]
        entry[name]["finest_failed"] = "failed" in values[finest]
        entry[name]["limit"] = ladder_limits(entry[name]["sizes_um"], entry[name]["runs"], values,
                                             entry[name]["finest_failed"])
    entry["verdicts"] = verdicts(entry["relative"]["limit"], entry["paper"]["limit"])
    # the relative ladder as the default workflow shows it: its refinement decision on the two coarser runs
    tolerance = relative["mpm"].get("skip_finest_tolerance")
    if tolerance is not None and entry["relative"]["runs"][2] in matrix.skippable_runs(relative):
        coarse, mid = entry["relative"]["runs"][:2]
        decision = skipping.decide(entry["relative"]["runs"][2], datasets[coarse], datasets[mid], [coarse, mid],
                                   tolerance)
        entry["relative"]["decision"] = {"run_finest": decision["run_finest"], "reason": decision["reason"]}
        if not decision["run_finest"]:
            shown = ladder_limits(entry["relative"]["sizes_um"], entry["relative"]["runs"], values, True)
            entry["relative"]["limit_as_shown"] = shown
            entry["verdicts_as_shown"] = verdicts(shown, entry["paper"]["limit"])
    return entry


def _table(e: dict, limits: dict, checks: dict, label: str) -> None:
    print(f"  {label}:")
    for o in OUTPUTS:
        a, b, v = limits[o], e["paper"]["limit"][o], checks[o]
        scale = 1e6 if o == "dp" else 1.0
        notes = [n for n, on in (("flagged", v["either_flagged"]), ("a sampling error missing",
                                                                      v["sampling_error_missing"])) if on]
        print(f"    {o:6s} relative {a['value'] * scale:.4g} +- {a['uncertainty'] * scale:.2g} ({a['method']}), "
              f"paper {b['value'] * scale:.4g} +- {b['uncertainty'] * scale:.2g} ({b['method']}): "
              f"{'agree' if v['agree'] else 'DISAGREE'}; relative uncertainty "
              f"{'not larger' if v['relative_uncertainty_not_larger'] else 'LARGER'}"
              + (f" [{'; '.join(notes)}]" if notes else ""))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--points", nargs="+", required=True, help="point keys (plough.study.matrix.all_points)")
    parser.add_argument("--relative", type=Path, default=ROOT / "config" / "config.yaml")
    parser.add_argument("--paper", type=Path, default=ROOT / "config" / "paper.yaml")
    parser.add_argument("--workdir", type=Path, default=ROOT, help="the workflow's directory (its results/runs/)")
    parser.add_argument("--run", action="store_true", help="make the missing runs with the workflow first")
    parser.add_argument("--cores", type=int, default=2)
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "ladder_guard.json")
    args = parser.parse_args()
    relative, paper = load_config([args.relative], ROOT), load_config([args.paper], ROOT)
    for key in args.points:
        if key not in matrix.all_points(relative) or key not in matrix.all_points(paper):
            parser.error(f"--points: {key!r} is not a point of both configs")
    if args.run:
        for key in args.points:
            lad = ladders(relative, paper, key)
            make_runs(args.workdir, args.paper, lad["paper"]["runs"], args.cores)
            only_relative = [r for r in lad["relative"]["runs"] if r not in lad["paper"]["runs"]]
            make_runs(args.workdir, args.relative, only_relative, args.cores)
    entries = [guard(args.workdir, relative, paper, key) for key in args.points]
    # every run was read checked against this solver: its fingerprint says which solver the numbers belong to
    result = {"provenance": provenance_attrs() | {"solver_fingerprint": solver_fingerprint()},
              "relative_config": str(args.relative), "paper_config": str(args.paper),
              "points": entries}
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=1, allow_nan=False))
    for e in entries:
        print(f"\n{e['point']}: relative {e['relative']['sizes_um']} um, paper {e['paper']['sizes_um']} um")
        if e.get("missing_runs") or e.get("failed_coarser_runs"):
            print("  missing runs:", ", ".join(e["missing_runs"]) or "none", "; failed coarser runs:",
                  ", ".join(e["failed_coarser_runs"]) or "none")
            continue
        _table(e, e["relative"]["limit"], e["verdicts"], "every size run")
        if "verdicts_as_shown" in e:
            _table(e, e["relative"]["limit_as_shown"], e["verdicts_as_shown"],
                   "relative as the default workflow shows it (finest skipped: " + e["relative"]["decision"]["reason"]
                   + ")")
        for r, v in e["run_values"].items():
            if "failed" not in v and v["steady"] is False:
                print(f"  note: run {r} did not reach a steady state (its values are flagged on the figures)")
    print(f"\nwrote {args.out}")


if __name__ == "__main__":
    main()
