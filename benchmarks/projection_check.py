"""The reproduction projection against a workflow run that was made: projected vs measured wall time per run.

    python benchmarks/projection_check.py --workdir DIR [--config config/preview.yaml] [--out FILE]

``DIR`` is the directory a ``snakemake --cores 2 --configfile=CONFIG`` ran in. For every MPM run of the
config whose per-run benchmark file ``DIR/benchmarks/runs/<run>.tsv`` exists (Snakemake's ``benchmark:``,
column ``s``: the job's wall time, numba's start-up included) and whose result is a run, not a failure or
skip marker, the projection of
``benchmarks/reproduction_time.py`` (particle-steps from ``plough.study.cost`` over the measured
throughput, with the graded, active-zone and real-material factors) is set beside it. Prints the
totals and the ratio measured / projected by particle size, family and material system (median, range). Writes the
per-run rows, each with when its job ended (``ended``), to ``--out`` (default benchmarks/results/projection_check.json).
"""

from __future__ import annotations

import argparse
import json
import math
import statistics
from pathlib import Path

import xarray as xr
import yaml
from reproduction_time import ROOT, add_measured_arguments, project_run, throughput_model

from plough.mpm.scene import Scene
from plough.study import matrix
from plough.study.plan import ended_at, is_marker, job_seconds


def result_attrs(result: Path) -> dict:
    """The result file's attributes ({} for a missing file)."""
    if not result.exists():
        return {}
    with xr.open_dataset(result) as ds:
        return dict(ds.attrs)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--workdir", type=Path, required=True, help="where the workflow ran")
    parser.add_argument("--config", default=str(ROOT / "config" / "preview.yaml"))
    add_measured_arguments(parser)
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "projection_check.json"))
    args = parser.parse_args()
    config = yaml.safe_load(Path(args.config).read_text())
    throughput, _, _, material_factor = throughput_model(config, args)
    rows = []
    for rid, scene_dict in matrix.all_runs(config).items():
        tsv = args.workdir / "benchmarks" / "runs" / f"{rid}.tsv"
        result = args.workdir / "results" / "runs" / f"{rid}.nc"
        if not tsv.exists():
            continue
        scene = Scene.from_dict(scene_dict)
        attrs = result_attrs(result)
        if is_marker(attrs):
            continue  # a marker's job made no run: its seconds are not its particle-steps' time
        c, real, projected = project_run(scene, throughput, material_factor)
        lay = scene.layers
        system = ("rigid-plastic" if not real else lay.substrate.name if lay.coating is None
                  else f"{lay.coating.name} on {lay.substrate.name}")
        rows.append({"run": rid, "h_um": round(scene.discretisation.particle_size_m * 1e6, 6),
                     "family": "real materials" if real else "rigid-plastic", "system": system,
                     "particles": c.particles,
                     "particle_steps": c.particle_steps, "projected_s": projected,
                     "measured_s": job_seconds(tsv),
                     # when the job ended (its benchmark file's time): plough plan counts a run measured in
                     # several files at its latest row
                     "ended": ended_at(tsv).isoformat(timespec="seconds"),
                     # the run's own wall time (press and slide, without the job's start-up and writing), NaN
                     # for a missing file; the threads it ran at, the config's for that
                     "simulate_s": float(attrs.get("cost_wall_time_s", math.nan)),
                     "threads": int(attrs.get("cost_threads", config["mpm"]["threads"]))})
    if not rows:
        raise SystemExit(f"no benchmark file of this config's runs under {args.workdir / 'benchmarks' / 'runs'}")
    print(f"{len(rows)} of {len(matrix.all_runs(config))} runs measured\n")
    print("| h (um) | family or material system | runs | projected | measured (job) | measured / projected: "
          "total (simulation alone), median (range) |")
    print("|---|---|---|---|---|---|")
    groups: dict[tuple[float, str], list[dict]] = {}
    for r in rows:
        for label in {r["system"], r["family"]}:  # rigid-plastic is both
            groups.setdefault((r["h_um"], label), []).append(r)
    groups[(0.0, "all")] = rows
    summary = []
    for (h, family), group in sorted(groups.items(), key=lambda kv: (-kv[0][0] if kv[0][0] else 1e9, kv[0][1])):
        proj = sum(r["projected_s"] for r in group)
        meas = sum(r["measured_s"] for r in group)
        ratios = [r["measured_s"] / r["projected_s"] for r in group]
        sim = sum(r["simulate_s"] for r in group if math.isfinite(r["simulate_s"]))
        overhead = sum(r["measured_s"] - r["simulate_s"] for r in group if math.isfinite(r["simulate_s"]))
        summary.append({"h_um": h or None, "family": family, "runs": len(group), "projected_s": proj,
                        "measured_s": meas, "simulate_s": sim, "job_overhead_s": overhead,
                        "ratio_total": meas / proj, "ratio_simulate_total": sim / proj,
                        "ratio_median": statistics.median(ratios), "ratio_min": min(ratios), "ratio_max": max(ratios)})
        label = f"{h:g}" if h else "all"
        print(f"| {label} | {family} | {len(group)} | {proj / 60:.1f} min | {meas / 60:.1f} min "
              f"({overhead / 60:.1f} min start-up and writing) | {meas / proj:.2f} ({sim / proj:.2f} without), "
              f"{statistics.median(ratios):.2f} ({min(ratios):.2f}-{max(ratios):.2f}) |")
    Path(args.out).write_text(json.dumps({"config": args.config, "threads": int(config["mpm"]["threads"]),
                                          "workdir": str(args.workdir),
                                          "throughput_particle_steps_per_s": throughput,
                                          "real_material_throughput_factor": material_factor,
                                          "summary": summary, "runs": rows}, indent=2) + "\n")


if __name__ == "__main__":
    main()
