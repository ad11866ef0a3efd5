"""Does mu_sh's size-to-size scatter at the zinc block, 11 N, come from the boundary-layer law? (one-off probe)

    python docs/journal/2026-12-06-interface-law-scatter/probe.py /work/guardrun OUTDIR [--sizes 14 10 7 5]

Takes the workflow's scene of the point at each size from its run file in the run directory (so the numerics are
exactly the main command's) and runs it again with the interface replaced: a constant tau (the same at every node,
so only the contact's area and which nodes carry shear can move with h) and a proportional tau = f kappa (the
contact particles' flow stress, work hardening included). Prints mu, mu_pl, mu_sh per law and size, the
boundary-layer runs read from the run directory.
"""

from __future__ import annotations

import argparse
import json
import time
from pathlib import Path

import xarray as xr

from plough.mpm.io import write_result
from plough.mpm.run import simulate
from plough.mpm.scene import Scene

KEY = "zinc_bulk_bl0.32-0.95_r500_F11"
#: tau of the constant law, Pa: about the boundary-layer law's mean over the contact at this point (33.8-36.8 MPa)
TAU_PA = 35e6
LAWS = {"constant": {"model": "constant", "H0_Pa": TAU_PA * 3.0 * 3.0**0.5},
        "proportional": {"model": "proportional", "f": 0.7}}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("workdir", type=Path)
    ap.add_argument("outdir", type=Path)
    ap.add_argument("--sizes", nargs="+", default=["14", "10", "7", "5"])
    ap.add_argument("--threads", type=int, default=2)
    args = ap.parse_args()
    args.outdir.mkdir(parents=True, exist_ok=True)
    rows = []
    for h in args.sizes:
        base = xr.open_dataset(args.workdir / "results" / "runs" / f"{KEY}_h{h}.nc")
        scene_d = json.loads(base.attrs["scene"])
        rows.append(("boundary_layer", h, float(base.mu), float(base.mu_pl), float(base.mu_sh),
                     float(base.attrs["cost_wall_time_s"])))
        for law, itf in LAWS.items():
            out = args.outdir / f"{KEY}_{law}_h{h}.nc"
            if not out.exists():
                d = dict(scene_d, interface=itf, name=f"{KEY}_{law}_h{h}")
                scene = Scene.from_dict(d)
                t0 = time.time()
                write_result(simulate(scene, progress=False, threads=args.threads), out)
                print(f"{law} h={h}: {time.time() - t0:.0f} s", flush=True)
            ds = xr.open_dataset(out)
            rows.append((law, h, float(ds.mu), float(ds.mu_pl), float(ds.mu_sh), float(ds.attrs["cost_wall_time_s"])))
    print("\n| law | h (µm) | mu | mu_pl | mu_sh | wall (s) |\n|---|---|---|---|---|---|")
    for law, h, mu, pl, sh, wall in sorted(rows, key=lambda r: (r[0], -float(r[1]))):
        print(f"| {law} | {h} | {mu:.4f} | {pl:.4f} | {sh:.4f} | {wall:.0f} |")


if __name__ == "__main__":
    main()
