"""One more size of issue 32's f = 0.5 ladder (f05_ladder.py of docs/journal/2026-12-02-groove-uncertainty):
the same scene, numerics and outputs, one scene at one particle size, appended to a JSON file.

    python docs/journal/2026-12-03-bbar-preview/finest.py --scene coated --h-um 2.5 [--threads 2] [--out FILE]
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from dataclasses import replace
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / "benchmarks"))
from common import workflow_scene  # noqa: E402

from plough.io import git_commit  # noqa: E402
from plough.materials import ProportionalShear  # noqa: E402
from plough.mpm.run import simulate  # noqa: E402

OUTPUTS = ("mu", "mu_pl", "mu_sh", "dp")


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scene", choices=("coated", "uncoated"), required=True)
    parser.add_argument("--h-um", type=float, required=True)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--out", type=Path, default=HERE / "finest.json")
    args = parser.parse_args()
    scene = replace(workflow_scene(args.scene, args.h_um * 1e-6), interface=ProportionalShear(f=0.5))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        ds = simulate(scene, progress=True, threads=args.threads)
    row = {o: float(ds[o]) for o in OUTPUTS}
    row.update({f"{o}_standard_error": float(ds[f"{o}_standard_error"]) for o in OUTPUTS})
    row.update(scene=args.scene, h_um=args.h_um, steady=int(ds["steady"]), mu_drift=float(ds["mu_drift"]),
               wall_s=float(ds.attrs["cost_wall_time_s"]), git_commit=git_commit())
    rows = json.loads(args.out.read_text()) if args.out.exists() else []
    rows.append(row)
    args.out.write_text(json.dumps(rows, indent=1) + "\n")
    print(json.dumps(row, indent=1))


if __name__ == "__main__":
    main()
