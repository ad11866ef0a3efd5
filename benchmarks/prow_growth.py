"""How high and how far ahead the material the sphere pushes (the prow) grows over the slide.

    python benchmarks/prow_growth.py --h-um 2.5 --headroom-um 80 --out benchmarks/results/prow_uncoated_h2.5.json
    python benchmarks/prow_growth.py --scene coated --h-um 5 --f 0.5
    python benchmarks/prow_growth.py --scene coated --f 0.5 --h-um 2.5 --headroom-um 70.6 --flip 0.9 --stop-um 120 \
        --out benchmarks/results/prow_coated_f0.5_h2.5_flip0.9_to120um.json

Runs a reference scene (examples/uncoated_rigid_plastic.yaml or coated_rigid_plastic.yaml, block
sized from the expected contact, graded particles with fine zone 1.5 contact radii as the workflow
runs them) and every ``--every`` steps records the highest particle centre above the original
surface, where it is relative to the sphere centre, how many particles stand above 5 and 10 um,
and the friction (mu, mu_pl, mu_sh) averaged over the steps since the last record. An interface
as strong as the material (f = 1) can drag a prow up the sphere's front that grows without
reaching a steady state; a run that stops (a particle leaving the grid) keeps its record up to
the stop and the solver's message. ``--cfl``, ``--flip``, ``--f``, ``--mass-scaling`` and
``--speed`` change one knob to ask what the growth needs; ``--stop-um`` ends the run early (its
outcome says so; no steady-state results then). Writes the JSON after every record.
"""

from __future__ import annotations

import argparse
import json
import time
from dataclasses import replace
from pathlib import Path

import numba
import numpy as np

from plough.io import git_commit
from plough.materials import ProportionalShear
from plough.mpm import contact, solver
from plough.mpm.run import simulate
from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = {"uncoated": "uncoated_rigid_plastic.yaml", "coated": "coated_rigid_plastic.yaml"}


class ProbeEnd(Exception):
    """Raised from the probe to end a run early (``--stop-um``); not a solver failure."""


def prow_record(state: solver.State, const: solver.Constants, t0: float, forces: np.ndarray) -> dict:
    """The highest particle and the prow's size at this step, and the friction since the last record.

    ``forces`` holds the sums since the last record of the reaction's Fx_pl, Fx_sh (drag, +) and Fz;
    it is zeroed here.
    """
    fx_pl, fx_sh, fz = forces
    friction = {"mu_window": (fx_pl + fx_sh) / fz, "mu_pl_window": fx_pl / fz, "mu_sh_window": fx_sh / fz} \
        if fz > 0 else {}
    forces[:] = 0.0
    x = state.particles.x
    i = int(np.argmax(x[:, 2]))
    c = state.sphere.centre
    return {"step": state.step, "phase": state.sphere.phase, "slid_um": state.sphere.slid_m * 1e6,
            "top_um": x[i, 2] * 1e6, "top_ahead_of_centre_um": (x[i, 0] - c[0]) * 1e6, "top_y_um": x[i, 1] * 1e6,
            "particles_above_5um": int((x[:, 2] > 5e-6).sum()), "particles_above_10um": int((x[:, 2] > 10e-6).sum()),
            "sphere_bottom_um": (c[2] - const.sphere_radius) * 1e6, "grid_interior_top_um": const.grid_hi[2] * 1e6,
            "grid_interior_end_x_um": const.grid_hi[0] * 1e6, "wall_s": time.perf_counter() - t0, **friction}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scene", choices=sorted(EXAMPLES), default="uncoated")
    parser.add_argument("--h-um", type=float, default=5.0)
    parser.add_argument("--f", type=float, default=None, help="interface f (default: the scene's own, 1)")
    parser.add_argument("--headroom-um", type=float, default=None, help="domain.headroom_m (default: automatic)")
    parser.add_argument("--uniform", action="store_true", help="uniform particles instead of graded")
    parser.add_argument("--cfl", type=float, default=None, help="discretisation.cfl (default: the scene's, 0.3)")
    parser.add_argument("--flip", type=float, default=None, help="discretisation.flip (default: the scene's, 1)")
    parser.add_argument("--mass-scaling", type=float, default=None,
                        help="discretisation.mass_scaling (default: the scene's, 1e6)")
    parser.add_argument("--speed", type=float, default=None, help="sliding.speed_m_s (default: the scene's, 0.1)")
    parser.add_argument("--stop-um", type=float, default=None,
                        help="end the run after this much sliding (a probe of the prow's early growth)")
    parser.add_argument("--every", type=int, default=500, help="steps between records")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--out", type=Path, default=None)
    args = parser.parse_args()
    numba.set_num_threads(args.threads)
    base = Scene.from_yaml(ROOT / "examples" / EXAMPLES[args.scene])
    disc = replace(base.discretisation, particle_size_m=args.h_um * 1e-6, graded=not args.uniform,
                   fine_zone_contact_radii=1.5)
    if args.cfl is not None:
        disc = replace(disc, cfl=args.cfl)
    if args.flip is not None:
        disc = replace(disc, flip=args.flip)
    if args.mass_scaling is not None:
        disc = replace(disc, mass_scaling=args.mass_scaling)
    scene = replace(base, discretisation=disc).with_sized_domain()
    if args.f is not None:
        scene = replace(scene, interface=ProportionalShear(f=args.f))
    if args.speed is not None:
        scene = replace(scene, sliding=replace(scene.sliding, speed_m_s=args.speed))
    if args.headroom_um is not None:
        scene = replace(scene, domain=replace(scene.domain, headroom_m=args.headroom_um * 1e-6))
    out = args.out or ROOT / "benchmarks" / "results" / f"prow_{args.scene}_h{args.h_um:g}.json"
    data = {"scene": scene.to_dict(), "git_commit": git_commit(), "records": [], "outcome": "running"}
    t0 = time.perf_counter()
    plain_step = solver.step
    forces = np.zeros(3)

    def step_and_record(state: solver.State, const: solver.Constants) -> None:
        plain_step(state, const)
        r = state.work.contact_out
        forces[:] += (-r[contact.OUT_FN], -r[contact.OUT_FT], r[contact.OUT_FN + 2] + r[contact.OUT_FT + 2])
        if state.step % args.every == 0:
            data["records"].append(prow_record(state, const, t0, forces))
            out.write_text(json.dumps(data, indent=1) + "\n")
        if args.stop_um is not None and state.sphere.slid_m * 1e6 >= args.stop_um:
            if state.step % args.every:  # the record of this step is not there yet
                data["records"].append(prow_record(state, const, t0, forces))
            raise ProbeEnd(f"ended by --stop-um after {state.sphere.slid_m * 1e6:.1f} um of sliding")

    solver.step = step_and_record  # the run loop calls solver.step: the probe sees every step
    try:
        ds = simulate(scene, progress=False)
        data["outcome"] = "completed"
        data["results"] = {q: float(ds[q]) for q in ("mu", "mu_pl", "mu_sh", "dp", "dg", "hpu", "penetration")}
    except solver.SimulationError as exc:
        data["outcome"] = f"stopped: {exc}"
    except ProbeEnd as exc:
        data["outcome"] = str(exc)
    finally:
        solver.step = plain_step
    out.write_text(json.dumps(data, indent=1) + "\n")
    last = data["records"][-1] if data["records"] else {}
    print(data["outcome"][:300])
    print(f"highest particle at the last record: {last.get('top_um', float('nan')):.1f} um, "
          f"{last.get('top_ahead_of_centre_um', float('nan')):.1f} um ahead of the sphere centre")


if __name__ == "__main__":
    main()
