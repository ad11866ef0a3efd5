"""Zinc-coated steel (examples/zinc_coated_steel.yaml, the workflow's numerics) with each contact at each size.

Run from the repository root (one JSON line per run appended to --out):
    python docs/journal/2026-12-04-contact-switch/probe_real.py --sizes-um 20 10 --contact grid grid_local --out FILE
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "benchmarks"))
import common  # noqa: E402

from plough.mpm.io import energy_balance  # noqa: E402
from plough.mpm.run import simulate  # noqa: E402


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--scene", default="real", choices=sorted(common.EXAMPLES))
    parser.add_argument("--sizes-um", type=float, nargs="+", default=[20.0, 10.0])
    parser.add_argument("--contact", nargs="+", default=["grid", "grid_local"])
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--out", required=True)
    args = parser.parse_args()
    for h in args.sizes_um:
        for mode in args.contact:
            scene = common.workflow_scene(args.scene, h * 1e-6)
            scene = replace(scene, discretisation=replace(scene.discretisation, contact=mode))
            t0 = time.perf_counter()
            ds = simulate(scene, progress=False, threads=args.threads)
            n = len(ds.contact_area_xy)
            row = {"scene": args.scene, "h_um": h, "contact": mode, "wall_s": time.perf_counter() - t0,
                   **{q: float(ds[q]) for q in common.RESULTS},
                   "contact_area_xy_um2": float(ds.contact_area_xy[n // 2:].mean()) * 1e12,
                   "energy_parts_over_work": energy_balance(ds), "steady": float(ds.steady),
                   "mu_drift": float(ds.mu_drift), "closest_centre_h": -float(ds.max_particle_penetration) / (h * 1e-6),
                   "steps": int(ds.attrs["cost_steps"]), "particles": int(ds.attrs["cost_particles"]),
                   "git_commit": str(ds.attrs.get("git_commit", "unknown"))}
            print(json.dumps(row), flush=True)
            with open(args.out, "a") as fh:
                fh.write(json.dumps(row) + "\n")


if __name__ == "__main__":
    main()
