"""Convergence in the particle size of the coated scene at interface strengths f = 0 and 0.5.

    python benchmarks/interface_convergence.py [--sizes-um 20 10 5] [--f 0 0.5]
    python benchmarks/interface_convergence.py --f 0.5 --sizes-um 10 5 2.5 --graded [--flip 0.9] [--zone 4]

Coated rigid-plastic scene (examples/coated_rigid_plastic.yaml: H~ = 0.5, t = 25 um, r = 0.2 mm,
3 N; sized block, defaults otherwise, 2 threads) with the interface shear tau = f kappa. At f = 1
(the scene's own interface, benchmarks/work_precision.py) mu follows the simulated speed
(README, *Interface shear*); this asks whether the ploughing alone (f = 0) and a slipping interface
(f = 0.5) converge in h, and to what (extrapolated to h -> 0 with plough.study's Richardson rule),
against the analytical model. ``--graded`` runs the workflow's graded particles (fine zone 1.5
expected contact radii; cases named "... graded"), which make h = 2.5 um affordable; ``--zone K``
adds the workflow's active zone of K expected contact radii (cases named "... zone K"). Writes
benchmarks/results/interface_convergence.json (a case already there is kept).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numba
import numpy as np
from common import coated_reference, run_scene

from plough.analytical import ploughing
from plough.io import git_commit
from plough.materials import ProportionalShear, representative_hardness
from plough.mpm.scene import Scene
from plough.mpm.solver import SimulationError
from plough.study.extrapolation import Method, extrapolate

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "interface_convergence.json"


def case_name(f: float, h: float, graded: bool, speed: float = 1.0, flip: float = 1.0, zone: float | None = None
              ) -> str:
    return (f"f {f:g} h {h:g}" + ("" if speed == 1.0 else f" speed x{speed:g}") + (" graded" if graded else "")
            + ("" if flip == 1.0 else f" flip {flip:g}") + ("" if zone is None else f" zone {zone:g}"))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes-um", type=float, nargs="+", default=[20.0, 10.0, 5.0])
    parser.add_argument("--f", type=float, nargs="+", default=[0.0, 0.5])
    parser.add_argument("--inertia-h-um", type=float, default=None,
                        help="also run speed / 2 at this size (issue 3's inertia check against the h change)")
    parser.add_argument("--graded", action="store_true", help="graded particles (fine zone 1.5 contact radii)")
    parser.add_argument("--flip", type=float, default=1.0,
                        help="discretisation.flip (default 1, the solver's; cases named '... flip F' otherwise)")
    parser.add_argument("--zone", type=float, default=None,
                        help="active zone of this many expected contact radii (active_zone_contact_radii)")
    args = parser.parse_args()
    numba.set_num_threads(2)
    base = Scene.from_yaml(ROOT / "examples" / "coated_rigid_plastic.yaml")
    data = json.loads(OUT.read_text()) if OUT.exists() else {"runs": {}}
    runs = data["runs"]
    for f in args.f:
        ref = ploughing(base.load_N, base.sphere.radius_m, base.layers.coating_thickness_m,
                        representative_hardness(base.layers.coating), representative_hardness(base.layers.substrate),
                        k1=125.0, interface="proportional", f=f)
        data[f"analytical f {f:g}"] = {"mu": float(ref.mu), "mu_pl": float(ref.mu_pl), "mu_sh": float(ref.mu_sh),
                                       "dp": float(ref.dp)}
        cases = [(h, 1.0) for h in args.sizes_um]
        if args.inertia_h_um is not None:
            cases.append((args.inertia_h_um, 0.5))
        for h, speed in cases:
            name = case_name(f, h, args.graded, speed, args.flip, args.zone)
            if name in runs:
                continue
            scene = replace(coated_reference(h), interface=ProportionalShear(f=f))
            if args.graded:
                scene = replace(scene, discretisation=replace(scene.discretisation, graded=True,
                                                              fine_zone_contact_radii=1.5))
            scene = replace(scene, discretisation=replace(scene.discretisation, flip=args.flip,
                                                          active_zone_contact_radii=args.zone))
            scene = replace(scene, sliding=replace(scene.sliding, speed_m_s=scene.sliding.speed_m_s * speed))
            try:
                row = run_scene(scene, threads=2)
            except SimulationError as exc:  # a stopped run is a result too: keep its message
                runs[name] = {"stopped": str(exc), "f": f, "h_um": h, "graded": args.graded, "flip": args.flip,
                              "zone_contact_radii": args.zone, "git_commit": git_commit()}
                print(name, "stopped:", exc, flush=True)
                OUT.write_text(json.dumps(data, indent=2) + "\n")
                continue
            runs[name] = {**row, "f": f, "h_um": h, "graded": args.graded, "flip": args.flip,
                          "zone_contact_radii": args.zone}
            print(name, json.dumps(runs[name]), flush=True)
            OUT.write_text(json.dumps(data, indent=2) + "\n")
    for f in args.f:
        sizes = [h for h in args.sizes_um
                 if "mu" in runs.get(case_name(f, h, args.graded, flip=args.flip, zone=args.zone), {})]
        slow = (runs.get(case_name(f, args.inertia_h_um, args.graded, 0.5, args.flip, args.zone))
                if args.inertia_h_um else None)
        if slow is not None:
            fast = runs[case_name(f, args.inertia_h_um, args.graded, flip=args.flip, zone=args.zone)]
            print(f"f = {f:g}, h = {args.inertia_h_um:g} um, speed / 2: mu {slow['mu'] / fast['mu'] - 1:+.1%}, "
                  f"dp {slow['dp'] / fast['dp'] - 1:+.1%}")
        if len(sizes) < 2:
            continue
        ex = {}
        for q in ("mu", "dp"):
            values = [runs[case_name(f, h, args.graded, flip=args.flip, zone=args.zone)][q] for h in sizes]
            e = extrapolate(np.array(sizes) * 1e-6, values)
            ex[q] = {"value": float(e.value), "uncertainty": float(e.uncertainty), "order": float(e.order),
                     "method": Method(int(e.method)).name.lower().replace("_", " ")}
            print(f"f = {f:g}: {q} extrapolated to h -> 0: {float(e.value):.4g} +- {float(e.uncertainty):.2g} "
                  f"({ex[q]['method']}, order {float(e.order):.2f})")
        suffix = ((" graded" if args.graded else "") + ("" if args.flip == 1.0 else f" flip {args.flip:g}")
                  + ("" if args.zone is None else f" zone {args.zone:g}"))
        data[f"extrapolated f {f:g}" + suffix] = ex
    OUT.write_text(json.dumps(data, indent=2) + "\n")
    print(f"{'case':28s} {'mu':>6s} {'mu_pl':>6s} {'mu_sh':>6s} {'dp um':>6s} {'wall s':>7s}")
    for name, r in runs.items():
        if "stopped" in r:
            print(f"{name:28s} stopped: {r['stopped'][:120]}")
            continue
        print(f"{name:28s} {r['mu']:6.3f} {r['mu_pl']:6.3f} {r['mu_sh']:6.3f} {r['dp'] * 1e6:6.2f} {r['wall_s']:7.1f}")


if __name__ == "__main__":
    main()
