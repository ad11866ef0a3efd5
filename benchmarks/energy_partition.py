"""Where the sphere's work goes during steady sliding, and how that depends on the time step.

    python benchmarks/energy_partition.py [--h-um 10] [--cfl-divisors 1 4] [--f 0 1] [--flip 0 1]

The reference scene (uncoated rigid-plastic, 3 N, r = 0.2 mm, sized block) with interface factor
f (0: frictionless, the work is ploughing alone) at CFL 0.3 / divisor, with the APIC transfer
(flip 0) and the FLIP increment (flip 1, the default). Over the steady window
(the second half of the slide) it compares the sphere's work dW with the increments of plastic
work, the plastic work recomputed from the particles (sum sigma_y eps_p V, rigid-plastic), the
interface slip and the inelastic contact loss; whatever is not accounted for is numerical
dissipation of the transfers. Writes benchmarks/results/energy_partition_h<h>.json and prints a
Markdown table.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numba

from plough.materials import ProportionalShear
from plough.mpm import solver
from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]


def window_increments(scene: Scene) -> dict[str, float]:
    """Energy increments over the second half of the slide, relative to the sphere's work there."""
    state, const = solver.init(scene)
    sigma_y = scene.layers.substrate.flow.sigma_y_Pa
    marks: dict[float, dict[str, float]] = {}
    while state.sphere.phase != "done":
        solver.step(state, const)
        for frac in (0.5, 1.0):
            if (frac not in marks and state.sphere.phase in ("slide", "done")
                    and state.sphere.slid_m >= frac * scene.sliding.distance_m * (1 - 1e-9)):
                p, w = state.particles, state.work
                marks[frac] = {"work": w.external_work, "plastic": w.plastic_work,
                               "plastic_from_particles": float((p.eps_p * p.vol0 * p.J).sum() * sigma_y),
                               "interface": w.interface_dissipation, "contact_loss": w.contact_impact_loss}
    a, b = marks[0.5], marks[1.0]
    d_work = b["work"] - a["work"]
    rows = {k: (b[k] - a[k]) / d_work for k in a if k != "work"}
    rows["unaccounted"] = 1.0 - rows["plastic"] - rows["interface"] - rows["contact_loss"]
    rows["work_J"] = const.symmetry_factor * d_work
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--h-um", type=float, default=10.0)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--cfl-divisors", type=float, nargs="+", default=[1.0, 4.0])
    parser.add_argument("--f", type=float, nargs="+", default=[0.0, 1.0])
    parser.add_argument("--flip", type=float, nargs="+", default=[0.0, 1.0])
    args = parser.parse_args()
    numba.set_num_threads(args.threads)
    base = Scene.from_yaml(ROOT / "examples" / "uncoated_rigid_plastic.yaml")
    base = replace(base, discretisation=replace(base.discretisation, particle_size_m=args.h_um * 1e-6))
    base = base.with_sized_domain()
    results = []
    print("| flip | f | CFL | plastic / work | same from particles | interface slip | contact loss | unaccounted |")
    print("|---|---|---|---|---|---|---|---|")
    for flip in args.flip:
        for f in args.f:
            for k in args.cfl_divisors:
                d = base.discretisation
                scene = replace(base, interface=ProportionalShear(f=f),
                                discretisation=replace(d, cfl=d.cfl / k, flip=flip))
                r = window_increments(scene)
                r.update(flip=flip, f=f, cfl=scene.discretisation.cfl)
                results.append(r)
                print(f"| {flip:g} | {f:g} | {r['cfl']:.3g} | {r['plastic']:.3f} | {r['plastic_from_particles']:.3f} | "
                      f"{r['interface']:.3f} | {r['contact_loss']:.3f} | {r['unaccounted']:+.3f} |", flush=True)
    out = ROOT / "benchmarks" / "results" / f"energy_partition_h{args.h_um:g}.json"
    out.write_text(json.dumps({"h_um": args.h_um, "threads": args.threads, "rows": results}, indent=2) + "\n")


if __name__ == "__main__":
    main()
