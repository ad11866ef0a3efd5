"""Runs of the main command that compute the same thing twice: each rigid-plastic constant-interface run
(`..._const450_...`) against its proportional-interface twin (`..._prop1_...`, the same coating, substrate and
size): whether their force histories are bitwise equal, the interface regime each scene resolved to, and the
one-thread job time of the constant one (benchmarks/runs/<run>.tsv).

    PYTHONPATH=src python identical_pairs.py RUN_DIR
"""
import argparse
from pathlib import Path

import numpy as np
import xarray as xr

from plough.study.plan import job_seconds

p = argparse.ArgumentParser()
p.add_argument("run_dir", type=Path)
a = p.parse_args()
runs = a.run_dir / "results" / "runs"
same_s = 0.0
print("| constant-interface run | bitwise equal to its prop1 twin | job s | regime (constant) |")
print("|---|---|---|---|")
for const in sorted(runs.glob("rp_*_const450_*.nc")):
    twin = runs / const.name.replace("const450", "prop1")
    if not twin.exists():
        continue
    with xr.open_dataset(const) as c, xr.open_dataset(twin) as t:
        same = all(np.array_equal(c[v].values, t[v].values) for v in ("Fx", "Fy", "Fz", "depth"))
        regime = c.attrs.get("interface_regime", "").split("(")[0].split(",")[0].strip()
    s = job_seconds(a.run_dir / "benchmarks" / "runs" / f"{const.stem}.tsv")
    same_s += s if same else 0.0
    print(f"| {const.stem} | {'yes' if same else 'no'} | {s:.0f} | {regime} |")
print(f"\nbitwise-equal pairs: {same_s:.0f} s of one-thread jobs made twice")
