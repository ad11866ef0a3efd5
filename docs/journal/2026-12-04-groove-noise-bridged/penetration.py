"""The residual groove against the loaded sphere on the rigid-plastic reference scenes (f = 1, workflow
numerics, lattice phase 0): mu, the sphere's mean penetration under load over the steady window, dg, hpu and
dp = dg + hpu of the bridged profile, per scene and size.

    python docs/journal/2026-12-04-groove-noise-bridged/penetration.py [--cases coated:10 uncoated:10] [--out FILE]
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / "benchmarks"))
from common import workflow_scene  # noqa: E402

from plough.io import git_commit  # noqa: E402
from plough.mpm.run import simulate  # noqa: E402

KEEP = ("mu", "penetration", "dg", "hpu", "dp", "dp_standard_error")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cases", nargs="+", default=["coated:20", "coated:10", "uncoated:20", "uncoated:10"])
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--out", type=Path, default=HERE / "penetration.json")
    args = parser.parse_args()
    rows = []
    for case in args.cases:
        name, h_um = case.split(":")
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = simulate(workflow_scene(name, float(h_um) * 1e-6), progress=False, threads=args.threads)
        row = {"scene": name, "h_um": float(h_um), **{q: float(ds[q]) for q in KEEP}}
        rows.append(row)
        print(f"  {name} h = {h_um} um: mu {row['mu']:.4f}, penetration {row['penetration'] * 1e6:.2f} um, "
              f"dg {row['dg'] * 1e6:.2f}, hpu {row['hpu'] * 1e6:.2f}, dp {row['dp'] * 1e6:.2f} um", flush=True)
        args.out.write_text(json.dumps({"git_commit": git_commit(), "runs": rows}, indent=1) + "\n")


if __name__ == "__main__":
    main()
