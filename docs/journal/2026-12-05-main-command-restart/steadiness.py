"""Which of the main command's runs are not steady, and by which test: mu_drift (mu over the steady window's second
half against its first, relative) beyond 5%, or material_top_rise (the highest particle's mean rise from the first
half to the second) beyond 2 particle sizes (plough.mpm.io). Grouped by family and particle size.

    PYTHONPATH=src python steadiness.py RUN_DIR
"""
import argparse
import json
import statistics
from collections import defaultdict
from pathlib import Path

import xarray as xr

from plough.mpm.io import STEADY_MU_DRIFT, STEADY_TOP_RISE_PARTICLES
from plough.mpm.scene import Scene
from plough.study.plan import family_of

p = argparse.ArgumentParser()
p.add_argument("run_dir", type=Path)
a = p.parse_args()
groups: dict[tuple[str, float], list[tuple[str, float, float, int]]] = defaultdict(list)
for nc in sorted((a.run_dir / "results" / "runs").glob("*.nc")):
    with xr.open_dataset(nc) as ds:
        if "steady" not in ds:
            continue
        scene = Scene.from_dict(json.loads(ds.attrs["scene"]))
        h_m = scene.discretisation.particle_size_m
        rise_h = float(ds["material_top_rise"]) / h_m
        groups[(family_of(scene), h_m * 1e6)].append((nc.stem, float(ds["mu_drift"]), rise_h, int(ds["steady"])))
print("| family | h (um) | runs | not steady | by mu drift only | by top rise only | by both | median abs mu drift |")
print("|---|---|---|---|---|---|---|---|")
for (family, h_um), rows in sorted(groups.items(), key=lambda kv: (kv[0][0], -kv[0][1])):
    bad = [r for r in rows if not r[3]]
    drift = [r for r in bad if abs(r[1]) > STEADY_MU_DRIFT]
    rise = [r for r in bad if abs(r[2]) > STEADY_TOP_RISE_PARTICLES]
    both = [r for r in drift if abs(r[2]) > STEADY_TOP_RISE_PARTICLES]
    med = statistics.median(abs(r[1]) for r in rows)
    print(f"| {family} | {h_um:g} | {len(rows)} | {len(bad)} | {len(drift) - len(both)} | {len(rise) - len(both)} "
          f"| {len(both)} | {med:.3f} |")
print()
print("not steady (run, mu drift, top rise in particle sizes):")
for rows in groups.values():
    for r in rows:
        if not r[3]:
            print(f"  {r[0]}  {r[1]:+.3f}  {r[2]:+.2f}")
