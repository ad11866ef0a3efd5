"""Inertia check of issue 3 at h = 5 um: the reference scene (sized block) with mass scaling / 2
and with sliding speed / 2 against the defaults.

    python benchmarks/inertia_h5.py

Writes benchmarks/results/inertia_h5.json. See benchmarks/timestep_check.py for why speed / 2
also changes the steps per sliding distance (and what that does).
"""

from __future__ import annotations

import json
from dataclasses import replace
from pathlib import Path

import numba

from plough.mpm.run import simulate
from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    numba.set_num_threads(2)
    base = Scene.from_yaml(ROOT / "examples" / "uncoated_rigid_plastic.yaml")
    base = replace(base, discretisation=replace(base.discretisation, particle_size_m=5e-6)).with_sized_domain()
    cases = {"baseline": base,
             "mass_scaling/2": replace(base, discretisation=replace(base.discretisation, mass_scaling=5e5)),
             "speed/2": replace(base, sliding=replace(base.sliding, speed_m_s=0.05))}
    rows = {}
    for name, s in cases.items():
        ds = simulate(s, progress=False)
        rows[name] = {k: float(ds[k]) for k in ("mu", "mu_pl", "mu_sh", "dp", "penetration", "Fz_mean")}
        rows[name].update(wall_s=ds.attrs["cost_wall_time_s"], particles=int(ds.attrs["cost_particles"]))
        print(name, json.dumps(rows[name]), flush=True)
    (ROOT / "benchmarks" / "results" / "inertia_h5.json").write_text(json.dumps(rows, indent=2) + "\n")


if __name__ == "__main__":
    main()
