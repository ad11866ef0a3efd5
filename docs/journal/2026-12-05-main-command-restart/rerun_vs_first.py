"""The jobs of the restarted main command against the same runs' times in the first measurement (the rows of
benchmarks/results/projection_check_main.json, made by the same solver, fingerprint 0749708876b540fc): how well a
run's time repeats between sessions on this machine.

    PYTHONPATH=src python rerun_vs_first.py RUN_DIR FIRST_JSON [--until 2026-12-05T12:20:00]
"""
import argparse
import datetime as dt
import json
import statistics
from pathlib import Path

import xarray as xr

from plough.study.plan import job_seconds

p = argparse.ArgumentParser()
p.add_argument("run_dir", type=Path)
p.add_argument("first", type=Path)
p.add_argument("--until", default="2100-01-01T00:00:00")
a = p.parse_args()
until = dt.datetime.fromisoformat(a.until).replace(tzinfo=dt.UTC).timestamp()
first = {r["run"]: r for r in json.loads(a.first.read_text())["runs"]}
rows = []
for tsv in sorted((a.run_dir / "benchmarks" / "runs").glob("*.tsv")):
    res = a.run_dir / "results" / "runs" / f"{tsv.stem}.nc"
    if tsv.stat().st_mtime > until or not res.exists() or tsv.stem not in first:
        continue
    with xr.open_dataset(res) as ds:
        threads = int(ds.attrs.get("cost_threads", 0))
    old = first[tsv.stem]
    if threads != old["threads"]:
        continue
    s = job_seconds(tsv)
    rows.append((tsv.stem, old["family"], old["h_um"], old["measured_s"], s))
rows.sort(key=lambda r: -r[3])
print(f"{len(rows)} jobs made in both measurements at the same threads")
print("| run | family | h (um) | first s | again s | ratio |")
print("|---|---|---|---|---|---|")
for r in rows:
    print(f"| {r[0]} | {r[1]} | {r[2]:g} | {r[3]:.0f} | {r[4]:.0f} | {r[4] / r[3]:.2f} |")
for label, sel in (("all", rows), ("over 60 s", [r for r in rows if r[3] > 60])):
    if sel:
        ratios = [r[4] / r[3] for r in sel]
        print(f"{label}: {len(sel)} jobs, first {sum(r[3] for r in sel):.0f} s, again {sum(r[4] for r in sel):.0f} s: "
              f"{sum(r[4] for r in sel) / sum(r[3] for r in sel):.2f} (median {statistics.median(ratios):.2f}, "
              f"{min(ratios):.2f}-{max(ratios):.2f})")
