"""Does the trench follow the coating's thickness in particles? Fig. 18's scenes (zinc-coated steel t = 10-55 um and
bulk zinc, 1 mm ball, 22 N) at one particle size, built as the workflow builds them, at the paper's inertia
(journal 2026-12-03-groove-below-sphere.md).

    python docs/journal/2026-12-03-groove-below-sphere/thickness.py --h-um 10 --thickness-um 10 30 55 0 \
        --out docs/journal/2026-12-03-groove-below-sphere/thickness_h10.json

Each run is written to ``--out`` as it finishes (resumable); 0 is the zinc block.
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from pathlib import Path

import numpy as np
import yaml

from plough.io import git_commit
from plough.mpm.run import simulate
from plough.study import matrix

ROOT = Path(__file__).resolve().parents[3]


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--h-um", type=float, required=True)
    ap.add_argument("--thickness-um", type=float, nargs="+", required=True)
    ap.add_argument("--out", type=Path, required=True)
    a = ap.parse_args()
    config = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    points = {round(p.thickness_m * 1e6): p for p in matrix.all_points(config, ("fig18",)).values()}
    data = json.loads(a.out.read_text()) if a.out.exists() else {"commit": git_commit(), "runs": []}
    done = {r["thickness_um"] for r in data["runs"]}
    for t in a.thickness_um:
        if t in done:
            continue
        scene = matrix.scene_for(points[round(t)], a.h_um, config["mpm"]["numerics"])
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = simulate(scene, progress=False, threads=2)
        y, z = ds["y"].values, ds["profile_z"].values
        a_exp, _ = scene.expected_contact()
        near = np.abs(y) <= 1.5 * a_exp
        deepest = int(np.nanargmin(np.where(near, z, np.nan)))
        row = {"thickness_um": t, "h_um": a.h_um, "wall_s": time.perf_counter() - t0,
               "y_deepest_m": float(y[deepest]), "z_centre_m": float(z[0]),
               "profile_y_m": y.tolist(), "profile_z_m": [None if not np.isfinite(v) else float(v) for v in z]}
        row.update({q: float(ds[q]) for q in ("mu", "penetration", "dg", "hpu", "dp", "dp_standard_error", "steady")})
        data["runs"].append(row)
        a.out.write_text(json.dumps(data, indent=1))
        prof = " ".join(f"{v * 1e6:.1f}" for v in z[:10])
        print(f"t {t:g} um: mu {row['mu']:.4f} penetration {row['penetration'] * 1e6:.2f} centre "
              f"{-row['z_centre_m'] * 1e6:.2f} deepest {row['dg'] * 1e6:.2f} at y {row['y_deepest_m'] * 1e6:.0f} um "
              f"dp {row['dp'] * 1e6:.2f} wall {row['wall_s']:.0f} s | profile {prof}", flush=True)


if __name__ == "__main__":
    main()
