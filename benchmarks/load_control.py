"""How well the load control holds the load, and what a stiffer controller would change.

    python benchmarks/load_control.py [--config config/preview.yaml] [--size-um 20] [--match REGEX]
        [--setting 1,100] [--setting 0.3,30] [--trace RUN] [--out FILE]
    python benchmarks/load_control.py --extrapolate FILE FILE [FILE ...] [--out FILE]

For every MPM run of the config at one particle size (optionally those whose id matches ``--match``), each
``--setting`` ``STIFFNESS_FACTOR,INTEGRAL_STEPS`` of ``plough.mpm.solver`` (the gain from the elastic contact
stiffness times the factor, the integral time in steps; the defaults are 1, 100) runs the scene on one thread
and records the mean Fz over the steady window against the load, mu, dp, whether the window is steady, and
the spread of the sphere's depth and of Fz over the window. With ``--trace RUN`` the first setting's run of
that id is stepped by hand instead and the load controller's integral is read at the window's ends: the
window's mean load error is the integral's change over the window divided by its duration (the integral
integrates the filtered error on every unbounded step), which says where a missed load comes from.

Writes ``--out`` (default benchmarks/results/load_control_h<size>.json) and prints a table and a summary
(runs within 1% of the load, the largest miss, the changes in mu and dp between the settings).

With ``--extrapolate`` no run is made: the results files of several particle sizes (this script's own, with the
same settings, one file per size) are read, every point present at two or more sizes is extrapolated to h -> 0 in
mu and dp for each setting (``plough.study.extrapolation.extrapolate``, the workflow's extrapolation, without its
sampling error), and so is the change the second setting makes at each size, with its own uncertainty: a
controller whose extrapolated change lies inside that uncertainty leaves the h -> 0 results where they were,
whatever it does at one size.
"""

from __future__ import annotations

import argparse
import json
import re
import statistics
import time
import warnings
from pathlib import Path

import numpy as np
import yaml

from plough.mpm import solver
from plough.mpm.run import simulate
from plough.mpm.scene import Scene
from plough.study import matrix
from plough.study.extrapolation import extrapolate

ROOT = Path(__file__).resolve().parents[1]


def set_controller(stiffness_factor: float, integral_steps: float) -> None:
    """The load controller's constants for the runs that follow (module constants of ``plough.mpm.solver``,
    read at ``init`` and on every step)."""
    solver.STIFFNESS_FACTOR = stiffness_factor
    solver.INTEGRAL_STEPS = integral_steps


def measure(scene: Scene) -> dict[str, float]:
    wall0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # an unsteady window is recorded below, not warned about
        ds = simulate(scene, progress=False, threads=1)
    w = ds.in_steady_window.values.astype(bool)
    return {"fz_over_load": float(ds.Fz_mean) / scene.load_N, "mu": float(ds.mu), "dp_um": float(ds.dp) * 1e6,
            "steady": int(ds.steady), "depth_sd_um": float(np.std(ds.depth.values[w])) * 1e6,
            "fz_sd_over_load": float(np.std(ds.Fz.values[w])) / scene.load_N,
            "wall_s": time.perf_counter() - wall0}


def trace(scene: Scene) -> dict[str, float]:
    """Step the scene by hand; the controller's integral and the filtered Fz over the steady window."""
    s, c = solver.init(scene, n_chunks=1)
    lo, hi = (f * scene.sliding.distance_m for f in scene.outputs.steady_window)
    start = end = None
    filtered = []
    while s.sphere.phase != "done":
        solver.step(s, c)
        if s.sphere.phase == "slide" and lo <= s.sphere.slid_m <= hi:
            if start is None:
                start = (s.time, s.sphere.load_error_integral)
            end = (s.time, s.sphere.load_error_integral)
            filtered.append(s.sphere.fz_filtered)
    duration = end[0] - start[0]
    return {"window_s": duration, "integral_start_Ns": start[1], "integral_end_Ns": end[1],
            "integral_change_over_window_N": (end[1] - start[1]) / duration,
            "mean_filtered_error_N": scene.load_N - float(np.mean(filtered)), "load_N": scene.load_N}


def summarise(runs: dict[str, dict[str, dict[str, float]]], settings: list[tuple[float, ...]]) -> dict[str, object]:
    """Per setting: runs within 1% of the load, the largest and the median miss, steady windows; and the
    changes in mu and dp of the second setting against the first (median, median magnitude, range)."""
    keys = [f"{sf:g},{steps:g}" for sf, steps in settings]
    summary: dict[str, object] = {}
    for key in keys:
        miss = [r[key]["fz_over_load"] - 1.0 for r in runs.values()]
        summary[key] = {"runs": len(miss), "within_1pct": sum(abs(m) <= 0.01 for m in miss),
                        "largest_miss": max(miss, key=abs) if miss else None,
                        "median_abs_miss": statistics.median(abs(m) for m in miss) if miss else None,
                        "steady": sum(r[key]["steady"] for r in runs.values())}
    if len(keys) > 1 and runs:
        base, other = keys[:2]
        for q in ("mu", "dp_um"):
            change = [r[other][q] / r[base][q] - 1.0 for r in runs.values() if r[base][q] > 0.0]
            summary[f"{q}_change_{other}_vs_{base}"] = {
                "median": statistics.median(change), "median_abs": statistics.median(abs(c) for c in change),
                "min": min(change), "max": max(change)}
    return summary


def extrapolated(files: list[Path]) -> dict[str, object]:
    """Per point (run id without its size) and setting: mu and dp at each size and their h -> 0 values with
    uncertainty; and the second setting's change to them, extrapolated itself from the per-size differences
    (the two settings share a point's discretisation error, so the difference is extrapolated rather than the
    two uncertainties added), with its uncertainty."""
    by_point: dict[str, dict[float, dict[str, dict[str, float]]]] = {}
    keys: list[str] | None = None
    seen: dict[float, Path] = {}
    for f in files:
        data = json.loads(Path(f).read_text())
        file_keys = [f"{sf:g},{steps:g}" for sf, steps in data["settings"]]
        if keys is not None and file_keys != keys:
            raise SystemExit(f"{f}: settings {file_keys} differ from {files[0]}'s {keys}")
        keys = file_keys
        size = float(data["size_um"])
        if size in seen:
            raise SystemExit(f"{f} and {seen[size]} are both of h = {size:g} um: merge them into one file")
        seen[size] = f
        suffix = f"_h{size:g}"
        for rid, rows in data["runs"].items():
            if not rid.endswith(suffix):
                raise SystemExit(f"{f}: run {rid} is not of the file's size h = {size:g} um")
            by_point.setdefault(rid[: -len(suffix)], {})[size] = rows
    points: dict[str, object] = {}
    for point, sizes in sorted(by_point.items()):
        if len(sizes) < 2:
            continue
        h = sorted(sizes)
        entry: dict[str, object] = {"h_um": h}
        for q in ("mu", "dp_um"):
            per_setting: dict[str, object] = {}
            for key in keys:
                values = [sizes[hh][key][q] for hh in h]
                per_setting[key] = _extrapolated_entry(h, values)
            if len(keys) > 1:
                difference = [sizes[hh][keys[1]][q] - sizes[hh][keys[0]][q] for hh in h]
                change = _extrapolated_entry(h, difference)
                change["outside_uncertainty"] = bool(abs(change["h0"]) > change["uncertainty"])
                per_setting["change"] = change
            entry[q] = per_setting
        points[point] = entry
    return {"files": [str(f) for f in files], "settings": keys, "points": points}


def _extrapolated_entry(h: list[float], values: list[float]) -> dict[str, object]:
    e = extrapolate(h, values)
    return {"values": values, "h0": float(e.value), "uncertainty": float(e.uncertainty), "order": float(e.order),
            "flagged": bool(e.flagged)}


def print_extrapolated(result: dict[str, object]) -> None:
    keys = result["settings"]
    for point, entry in result["points"].items():
        print(point, "h =", "/".join(f"{h:g}" for h in entry["h_um"]), "um")
        for q in ("mu", "dp_um"):
            cells = [f"{k}: " + " ".join(f"{v:.4g}" for v in entry[q][k]["values"])
                     + f" -> {entry[q][k]['h0']:.4g} +- {entry[q][k]['uncertainty']:.2g}"
                     + (" (flagged)" if entry[q][k]["flagged"] else "") for k in keys]
            if "change" in entry[q]:
                ch = entry[q]["change"]
                cells.append(f"change {ch['h0']:+.4g} +- {ch['uncertainty']:.2g}" + (" (flagged)" if ch["flagged"]
                                                                                     else ""))
            print(f"  {q:6s}", " | ".join(cells))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--config", default=str(ROOT / "config" / "preview.yaml"))
    parser.add_argument("--size-um", type=float, default=20.0)
    parser.add_argument("--match", default="", help="only the run ids this regular expression finds")
    parser.add_argument("--setting", action="append", default=None,
                        help="STIFFNESS_FACTOR,INTEGRAL_STEPS (repeatable; default 1,100 and 0.3,30)")
    parser.add_argument("--trace", default=None, help="a run id to trace the controller's integral in")
    parser.add_argument("--extrapolate", nargs="+", type=Path, default=None,
                        help="results files of several sizes: extrapolate them instead of running")
    parser.add_argument("--out", default=None)
    args = parser.parse_args()
    if args.extrapolate:
        result = extrapolated(args.extrapolate)
        print_extrapolated(result)
        if args.out:
            Path(args.out).write_text(json.dumps(result, indent=1))
        return
    settings = [tuple(float(v) for v in s.split(",")) for s in (args.setting or ["1,100", "0.3,30"])]
    config = yaml.safe_load(Path(args.config).read_text())
    suffix = f"_h{args.size_um:g}"
    runs = {rid: d for rid, d in matrix.all_runs(config).items()
            if rid.endswith(suffix) and re.search(args.match, rid)}
    out = Path(args.out or ROOT / "benchmarks" / "results" / f"load_control_h{args.size_um:g}.json")
    result: dict[str, object] = {"config": args.config, "size_um": args.size_um, "settings": settings, "runs": {}}
    if args.trace:
        set_controller(*settings[0])
        result["trace"] = {args.trace: trace(Scene.from_dict(matrix.all_runs(config)[args.trace]))}
        print(json.dumps(result["trace"], indent=1))
    for rid, scene_dict in runs.items():
        scene = Scene.from_dict(scene_dict)
        rows = {}
        for sf, steps in settings:
            set_controller(sf, steps)
            rows[f"{sf:g},{steps:g}"] = measure(scene)
        result["runs"][rid] = rows
        print(rid, " | ".join(f"{k}: Fz/load {r['fz_over_load']:.4f} mu {r['mu']:.4f} dp {r['dp_um']:.2f}"
                              for k, r in rows.items()), flush=True)
        out.write_text(json.dumps(result, indent=1))  # kept as it goes: a long sweep can be stopped
    result["summary"] = summary = summarise(result["runs"], settings)
    out.write_text(json.dumps(result, indent=1))
    print(json.dumps(summary, indent=1))


if __name__ == "__main__":
    main()
