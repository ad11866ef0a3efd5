"""What the interface shear of the coated reference scene depends on: the contact's hold and the inertia.

    python benchmarks/contact_sensitivity.py [--h-um 10] [--only NAME ...]

Coated rigid-plastic scene (examples/coated_rigid_plastic.yaml: H~ = 0.5, t = 25 um, r = 0.2 mm,
3 N, f = 1), sized block, 2 threads. Writes benchmarks/results/contact_sensitivity.json (a case is
run only when missing or named in --only):

1. Hold ladder: how long a node stays in contact after its last normal push
   (``plough.mpm.contact.HOLD_WAVE_TIMES``, in elastic-wave transits of a cell) at 1 / 2 / 4 / 8.
   A numerical parameter: mu_sh should not follow it.
2. Mass-scaling ladder: ms x 4, / 4, / 16 (mass scaling / k^2 is speed / k at k times the steps,
   benchmarks/timestep_check.py): inertia, which should fade as the mass scaling falls.
3. The same ladder at interface strength f = 0 (no interface shear) and f = 0.5: whether the
   mass-scaling dependence belongs to the ploughing or to an interface as strong as the coating
   (f = 1: tau = kappa, the coating's own shear strength).

The same measurements of the earlier contact (shear area min(F_n / P, cell face) with a filtered
normal force, before d23eeb2) are kept in contact_sensitivity_filtered_area.json, with a probe of
the contact pressure it divided by (README, "Interface shear").
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numba
from common import coated_reference

from plough.materials import ProportionalShear
from plough.mpm import contact
from plough.mpm.run import simulate
from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "contact_sensitivity.json"
KEYS = ("mu", "mu_pl", "mu_sh", "dp", "penetration", "Fz_mean")


def run_case(scene: Scene, hold_wave_times: float) -> dict[str, float]:
    default = contact.HOLD_WAVE_TIMES
    contact.HOLD_WAVE_TIMES = hold_wave_times  # read by solver.init when it sets the hold in steps
    try:
        ds = simulate(scene, progress=False, threads=2)
    finally:
        contact.HOLD_WAVE_TIMES = default
    row = {k: float(ds[k]) for k in KEYS}
    row.update(wall_s=float(ds.attrs["cost_wall_time_s"]), hold_wave_times=hold_wave_times,
               mass_scaling=scene.discretisation.mass_scaling, f=float(getattr(scene.interface, "f", float("nan"))),
               git_commit=str(ds.attrs.get("git_commit")))
    return row


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--h-um", type=float, default=10.0)
    parser.add_argument("--only", nargs="*", default=None, help="(re)run only these cases")
    args = parser.parse_args()
    numba.set_num_threads(2)
    base = coated_reference(args.h_um)
    ms = base.discretisation.mass_scaling
    hold = contact.HOLD_WAVE_TIMES

    def with_ms(k: float, f: float | None = None) -> Scene:
        scene = base if f is None else replace(base, interface=ProportionalShear(f=f))
        return replace(scene, discretisation=replace(base.discretisation, mass_scaling=ms * k))

    cases = {"defaults": (base, hold), "hold 1": (base, 1.0), "hold 4": (base, 4.0), "hold 8": (base, 8.0),
             "ms x4": (with_ms(4.0), hold), "ms/4": (with_ms(0.25), hold), "ms/16": (with_ms(1 / 16), hold)}
    for f in (0.0, 0.5):
        for label, k in (("ms x4", 4.0), ("ms", 1.0), ("ms/4", 0.25), ("ms/16", 1 / 16)):
            cases[f"f {f:g} {label}"] = (with_ms(k, f), hold)
    data = json.loads(OUT.read_text()) if OUT.exists() else {}
    data["h_um"] = args.h_um
    runs = data.setdefault("runs", {})
    for name, (scene, hold_wt) in cases.items():
        if (args.only is None and name in runs) or (args.only is not None and name not in args.only):
            continue
        runs[name] = run_case(scene, hold_wt)
        print(name, json.dumps(runs[name]), flush=True)
        OUT.write_text(json.dumps(data, indent=2) + "\n")
    print(f"{'case':10s} {'mu':>6s} {'mu_pl':>6s} {'mu_sh':>6s} {'dp um':>6s} {'pen um':>6s} {'wall s':>7s}")
    for name, r in runs.items():
        print(f"{name:10s} {r['mu']:6.3f} {r['mu_pl']:6.3f} {r['mu_sh']:6.3f} {r['dp'] * 1e6:6.2f} "
              f"{r['penetration'] * 1e6:6.2f} {r['wall_s']:7.1f}")


if __name__ == "__main__":
    main()
