"""Time-step and inertia dependence of the reference scene (uncoated, 3 N, r = 0.2 mm, sized block).

    python benchmarks/timestep_check.py [--h-um 10]

Runs the reference scene with: the defaults; sliding speed / 2; CFL / 2 and / 4 (same inertia,
more steps per distance: converges in dt?); mass scaling / 4 (the same inertia number ms v^2 and steps per distance as
speed / 2, so it must give the same numbers); speed / 2 with CFL x 2 (a quarter of the inertia,
the baseline's steps per distance). Separates inertia (ms v^2 / H) from time-step effects.
Writes benchmarks/results/timestep_check_h<h>.json and prints a Markdown table.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numba

from plough.mpm.run import simulate
from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--h-um", type=float, default=10.0)
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    numba.set_num_threads(args.threads)
    base = Scene.from_yaml(ROOT / "examples" / "uncoated_rigid_plastic.yaml")
    base = replace(base, discretisation=replace(base.discretisation, particle_size_m=args.h_um * 1e-6))
    base = base.with_sized_domain()
    d, sl = base.discretisation, base.sliding
    cases = {
        "defaults": base,
        "speed / 2": replace(base, sliding=replace(sl, speed_m_s=sl.speed_m_s / 2)),
        "cfl / 2": replace(base, discretisation=replace(d, cfl=d.cfl / 2)),
        "cfl / 4": replace(base, discretisation=replace(d, cfl=d.cfl / 4)),
        "mass scaling / 4": replace(base, discretisation=replace(d, mass_scaling=d.mass_scaling / 4)),
        "speed / 2, cfl x 2": replace(base, sliding=replace(sl, speed_m_s=sl.speed_m_s / 2),
                                      discretisation=replace(d, cfl=2 * d.cfl)),
    }
    rows = {}
    print("| case | steps | inertia ms rho v^2 / H | mu | mu_pl | mu_sh | dp (um) | penetration (um) | Fz / load |")
    print("|---|---|---|---|---|---|---|---|---|")
    for name, s in cases.items():
        ds = simulate(s, progress=False)
        mat = s.layers.substrate
        inertia = s.discretisation.mass_scaling * mat.density_kg_m3 * s.sliding.speed_m_s**2 / (3 * mat.flow.sigma_y_Pa)
        row = {k: float(ds[k]) for k in ("mu", "mu_pl", "mu_sh", "dp", "penetration", "Fz_mean")}
        row.update(steps=int(ds.attrs["cost_steps"]), inertia_number=inertia, wall_time_s=ds.attrs["cost_wall_time_s"])
        rows[name] = row
        print(f"| {name} | {row['steps']:,} | {inertia:.3f} | {row['mu']:.3f} | {row['mu_pl']:.3f} | "
              f"{row['mu_sh']:.3f} | {row['dp'] * 1e6:.2f} | {row['penetration'] * 1e6:.2f} | "
              f"{row['Fz_mean'] / s.load_N:.4f} |", flush=True)
    out = ROOT / "benchmarks" / "results" / f"timestep_check_h{args.h_um:g}.json"
    out.write_text(json.dumps({"h_um": args.h_um, "threads": args.threads, "cases": rows}, indent=2) + "\n")


if __name__ == "__main__":
    main()
