"""The jobs a part of the main command made (benchmark files written between --since and --until) against
plough plan's projection calibrated as on a fresh clone of REPO (its committed projection_check files, or
--calibration), by particle size and family: how far the projection holds at the half-octave sizes, where no job
had been measured before.

    PYTHONPATH=src python part_vs_plan.py RUN_DIR REPO --since 2026-12-06T09:03:53 [--until ...]
        [--calibration FILE ...]
"""
import argparse
import csv
import datetime as dt
from collections import defaultdict
from pathlib import Path

import xarray as xr

from plough.study.plan import load_config, make_plan

p = argparse.ArgumentParser()
p.add_argument("run_dir", type=Path)
p.add_argument("repo", type=Path)
p.add_argument("--since", required=True)
p.add_argument("--until", default="2100-01-01T00:00:00")
p.add_argument("--calibration", nargs="+", type=Path)
a = p.parse_args()
since = dt.datetime.fromisoformat(a.since).replace(tzinfo=dt.UTC).timestamp()
until = dt.datetime.fromisoformat(a.until).replace(tzinfo=dt.UTC).timestamp()
calibration = a.calibration or sorted((a.repo / "benchmarks/results").glob("projection_check_*.json"))
plan = make_plan(load_config([], a.repo), cores=2, directory=a.repo, calibration=calibration)
rows = []
for tsv in sorted((a.run_dir / "benchmarks" / "runs").glob("*.tsv")):
    if not since <= tsv.stat().st_mtime <= until:
        continue
    rid = tsv.stem
    res = a.run_dir / "results" / "runs" / f"{rid}.nc"
    if not res.exists():
        continue
    with xr.open_dataset(res) as ds:
        threads = int(ds.attrs.get("cost_threads", 0))
    with tsv.open() as f:
        s = float(next(csv.DictReader(f, delimiter="\t"))["s"])
    rp = plan.runs[rid]
    projected = rp.here_s * plan.threads / threads  # linear, as the plan scales
    rows.append((rid, rp.family, rp.h_um, rp.particle_steps, s, projected, threads))
print(f"{len(rows)} jobs; calibration: {', '.join(c.name for c in calibration)}")
print("| run | family | h (um) | particle-steps | measured s | projected s (its threads, linear) | ratio | threads |")
print("|---|---|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r[0]} | {r[1]} | {r[2]:g} | {r[3]:.3g} | {r[4]:.0f} | {r[5]:.0f} | {r[4] / r[5]:.2f} | {r[6]} |")
print()
print("| family | h (um) | jobs | measured s | projected s | ratio |")
print("|---|---|---|---|---|---|")
groups = defaultdict(list)
for r in rows:
    groups[(r[1], r[2])].append(r)
for (fam, h), sel in sorted(groups.items()):
    m, pr = sum(r[4] for r in sel), sum(r[5] for r in sel)
    print(f"| {fam} | {h:g} | {len(sel)} | {m:.0f} | {pr:.0f} | {m / pr:.2f} |")
for fam in ("rigid-plastic", "real materials"):
    sel = [r for r in rows if r[1] == fam]
    if sel:
        print(f"{fam}: {len(sel)} jobs, measured {sum(r[4] for r in sel):.0f} s, projected "
              f"{sum(r[5] for r in sel):.0f} s: {sum(r[4] for r in sel) / sum(r[5] for r in sel):.2f}")
tot_m, tot_p = sum(r[4] for r in rows), sum(r[5] for r in rows)
print(f"total measured {tot_m:.0f} s, projected {tot_p:.0f} s: {tot_m / tot_p:.2f}")
