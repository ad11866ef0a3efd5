"""The tiny sliding scene of tests/mpm/test_verification.py (f = 1, h = 10 um), half and full block, with each
contact: mu, dp, the energy balance and the closest particle centre. Run from the repository root with
PYTHONPATH=src:tests/mpm (its output is in run.log, lines starting with "tiny")."""

import time
from dataclasses import replace

from test_verification import tiny_sliding_scene

from plough.mpm.run import simulate

PARTS = ("plastic_work", "elastic_energy", "kinetic_energy", "interface_dissipation", "contact_impact_loss",
         "frozen_kinetic_loss")

for mode in ("particle", "grid"):
    for sym in (True, False):
        sc = tiny_sliding_scene(sym)
        sc = replace(sc, discretisation=replace(sc.discretisation, contact=mode))
        t0 = time.perf_counter()
        ds = simulate(sc, progress=False, threads=2)
        work = float(ds.external_work[-1])
        parts = {k: float(ds[k][-1]) for k in PARTS}
        print("tiny", mode, "half" if sym else "full", "mu", float(ds.mu), "mu_pl", float(ds.mu_pl), "dp_um",
              float(ds.dp) * 1e6, "energy", sum(parts.values()) / work,
              {k: round(v / work, 4) for k, v in parts.items()},
              "closest_h", -float(ds.max_particle_penetration) / 10e-6, "Fz/load", float(ds.Fz_mean), "wall",
              time.perf_counter() - t0, flush=True)
