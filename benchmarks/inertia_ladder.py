"""Does mu settle as the inertia vanishes? The coated scene down a long mass-scaling ladder.

    python benchmarks/inertia_ladder.py [--h-um 20] [--f 1 0.5] [--factors 4 1 0.25 0.0625 0.015625 0.00390625]

Coated rigid-plastic scene (examples/coated_rigid_plastic.yaml: H~ = 0.5, t = 25 um, r = 0.2 mm, 3 N,
sized block) with the interface tau = f kappa, at mass scaling 1e6 times each factor (a factor 1/k^2 is
the speed / k: the same numbers). The inertia number ms rho v^2 / H falls with the factor; each
quarter doubles the steps of the slide. At f = 1 mu rose over x 4 .. / 16 at h = 10 um without
settling (README, *Interface shear*); this asks whether it settles further down, at a particle size
(20 um by default) where a run down to 1/256 of the paper's inertia costs minutes on one thread.
Writes benchmarks/results/inertia_ladder_h<H>.json (a case already there is kept).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numba
from common import coated_reference, run_scene

from plough.io import git_commit
from plough.materials import ProportionalShear
from plough.mpm.solver import SimulationError

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--h-um", type=float, default=20.0)
    parser.add_argument("--f", type=float, nargs="+", default=[1.0, 0.5])
    parser.add_argument("--factors", type=float, nargs="+", default=[4.0, 1.0, 1 / 4, 1 / 16, 1 / 64, 1 / 256],
                        help="mass scaling factors against the paper's 1e6")
    parser.add_argument("--threads", type=int, default=1)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args()
    out = args.out or ROOT / "benchmarks" / "results" / f"inertia_ladder_h{args.h_um:g}.json"
    numba.set_num_threads(args.threads)
    data = json.loads(out.read_text()) if out.exists() else {"h_um": args.h_um, "runs": {}}
    if data["h_um"] != args.h_um:
        raise SystemExit(f"{out} holds runs at h = {data['h_um']:g} um, not --h-um {args.h_um:g}")
    runs = data["runs"]
    base = coated_reference(args.h_um)
    for f in args.f:
        for factor in args.factors:
            name = f"f {f:g} mass scaling x {factor:g}"
            if name in runs:
                continue
            scene = replace(base, interface=ProportionalShear(f=f),
                            discretisation=replace(base.discretisation,
                                                   mass_scaling=base.discretisation.mass_scaling * factor))
            row = {"f": f, "mass_scaling_factor": factor, "inertia_number": scene.inertia_number}
            try:
                row.update(run_scene(scene, threads=args.threads))
            except SimulationError as exc:  # a stopped run is a result too
                row.update(stopped=str(exc), git_commit=git_commit())
            runs[name] = row
            print(name, json.dumps(row), flush=True)
            out.write_text(json.dumps(data, indent=2) + "\n")
    print(f"{'case':34s} {'inertia':>8s} {'mu':>6s} {'mu_pl':>6s} {'mu_sh':>6s} {'dp um':>6s} {'steady':>6s} "
          f"{'steps':>7s} {'wall s':>7s}")
    for name, r in runs.items():
        if "stopped" in r:
            print(f"{name:34s} stopped: {r['stopped'][:100]}")
            continue
        print(f"{name:34s} {r['inertia_number']:8.4f} {r['mu']:6.3f} {r['mu_pl']:6.3f} {r['mu_sh']:6.3f} "
              f"{r['dp'] * 1e6:6.2f} {r['steady']:6.0f} {r['steps']:7d} {r['wall_s']:7.1f}")


if __name__ == "__main__":
    main()
