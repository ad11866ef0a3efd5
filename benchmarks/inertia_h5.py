"""Inertia check of issue 3 at h = 5 um: the reference scene (sized block) with mass scaling / 2
and with sliding speed / 2, / 4, / 8 against the defaults.

    python benchmarks/inertia_h5.py [--only NAME ...] [--f 0.5 --out benchmarks/results/inertia_h5_f0.5.json]
    python benchmarks/inertia_h5.py --f 0.5 --graded --zone 4 --with-h2.5 --only baseline h10 h2.5 speed/2 \
        --out benchmarks/results/inertia_h5_f0.5_graded_zone4.json

Writes benchmarks/results/inertia_h5.json (or --out), keeping the cases already there (a case is run
only when it is missing or named in --only). ``--f`` replaces the scene's interface factor (the
example's f = 1 makes the interface as strong as the substrate, ``Scene.interface_sticks``); the
case ``h10`` is the same scene at h = 10 um, for the discretisation change it is compared with, and
``h2.5`` (with ``--with-h2.5``) at h = 2.5 um, so that the discretisation error at h = 5 um is extrapolated
from three sizes, not read off one change. ``--graded`` and ``--zone K`` run every case with the workflow's
graded particles (fine zone 1.5 expected contact radii) and active zone of K contact radii.
Speed / k is the inertia number ms rho v^2 / H / k^2 at k times
the steps (mass scaling / k^2 gives the same numbers, benchmarks/timestep_check.py).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numba

from plough.io import git_commit
from plough.materials import ProportionalShear
from plough.mpm.run import simulate
from plough.mpm.scene import Scene
from plough.mpm.solver import SimulationError

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--only", nargs="*", default=None, help="(re)run only these cases")
    parser.add_argument("--f", type=float, default=None, help="interface factor f (default: the example's)")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "inertia_h5.json")
    parser.add_argument("--graded", action="store_true", help="graded particles (fine zone 1.5 contact radii)")
    parser.add_argument("--zone", type=float, default=None, help="active zone of this many expected contact radii")
    parser.add_argument("--with-h2.5", dest="h25", action="store_true", help="add the case h2.5 (h = 2.5 um)")
    args = parser.parse_args()
    numba.set_num_threads(2)
    example = Scene.from_yaml(ROOT / "examples" / "uncoated_rigid_plastic.yaml")
    if args.f is not None:
        example = replace(example, interface=ProportionalShear(f=args.f))
    example = replace(example, discretisation=replace(
        example.discretisation, active_zone_contact_radii=args.zone,
        **({"graded": True, "fine_zone_contact_radii": 1.5} if args.graded else {})))

    def at_size(h_m: float) -> Scene:
        return replace(example, discretisation=replace(example.discretisation, particle_size_m=h_m)).with_sized_domain()

    base = at_size(5e-6)
    cases = {"baseline": base, "h10": at_size(10e-6),
             "mass_scaling/2": replace(base, discretisation=replace(base.discretisation, mass_scaling=5e5))}
    if args.h25:
        cases["h2.5"] = at_size(2.5e-6)
    for k in (2, 4, 8):
        cases[f"speed/{k}"] = replace(base, sliding=replace(base.sliding, speed_m_s=0.1 / k))
    out = args.out
    rows = json.loads(out.read_text()) if out.exists() else {}
    for name, s in cases.items():
        if (args.only is None and name in rows) or (args.only is not None and name not in args.only):
            continue
        try:
            ds = simulate(s, progress=False)
        except SimulationError as exc:  # a stopped run is a result too: keep its message
            rows[name] = {"stopped": str(exc), "git_commit": git_commit()}
            print(name, "stopped:", exc, flush=True)
            out.write_text(json.dumps(rows, indent=2) + "\n")
            continue
        rows[name] = {k: float(ds[k]) for k in ("mu", "mu_pl", "mu_sh", "dp", "dg", "hpu", "penetration", "Fz_mean",
                                                "mu_standard_error", "dp_standard_error", "mu_drift") if k in ds}
        rows[name].update(wall_s=ds.attrs["cost_wall_time_s"], particles=int(ds.attrs["cost_particles"]),
                          steps=int(ds.attrs["cost_steps"]), inertia_number=s.inertia_number,
                          graded=args.graded, zone_contact_radii=args.zone,
                          grid_side_widenings=int(ds.attrs["cost_grid_side_widenings"]),
                          git_commit=str(ds.attrs.get("git_commit")))
        print(name, json.dumps(rows[name]), flush=True)
        out.write_text(json.dumps(rows, indent=2) + "\n")


if __name__ == "__main__":
    main()
