"""Measured workflow jobs of the main command (a run directory) against plough plan's calibrated projection,
calibrated as on a fresh clone (the committed projection_check files only, no benchmark files of the run dir)."""
import csv
import sys
from pathlib import Path

import xarray as xr

from plough.study.plan import load_config, make_plan

run_dir = Path(sys.argv[1])
clean = Path(sys.argv[2])  # a checkout without benchmarks/runs (calibration as on a fresh clone)
plan = make_plan(load_config([], clean), cores=2, directory=clean)
rows = []
for tsv in sorted((run_dir / "benchmarks" / "runs").glob("*.tsv")):
    rid = tsv.stem
    res = run_dir / "results" / "runs" / f"{rid}.nc"
    if not res.exists():
        continue
    with xr.open_dataset(res) as ds:
        threads = int(ds.attrs.get("cost_threads", 0))
        marker = bool(ds.attrs.get("skipped_finest_size") or ds.attrs.get("failed_finest_size"))
    with tsv.open() as f:
        s = float(next(csv.DictReader(f, delimiter="\t"))["s"])
    rp = plan.runs[rid]
    rows.append((rid, rp.family, rp.h_um, rp.particle_steps, s, rp.here_s, threads, marker))
tot_m = sum(r[4] for r in rows if not r[7])
tot_p = sum(r[5] for r in rows if not r[7])
print(f"plan threads {plan.threads}; {len(rows)} jobs")
print("| run | family | h | particle-steps | measured s | projected s (1 thread, linear) | ratio | threads |")
for r in rows:
    marker = " marker" if r[7] else ""
    print(f"| {r[0]} | {r[1]} | {r[2]:g} | {r[3]:.3g} | {r[4]:.0f} | {r[5]:.0f} | {r[4] / r[5]:.2f} | {r[6]}{marker} |")
print(f"total measured {tot_m:.0f} s, projected {tot_p:.0f} s: {tot_m / tot_p:.2f}")
