"""The tiny sliding scene of tests/mpm/test_verification.py (f = 1, h = 10 um, half block) with the contacts named
on the command line: mu, mu_pl, mu_sh, dp, the contact's own projected area against the analytical front-half
area, the energy balance, the closest centre. Run from the repository root with PYTHONPATH=src:tests/mpm."""

import sys
import time
from dataclasses import replace

import numpy as np
from test_verification import tiny_sliding_scene

from plough.analytical import ploughing
from plough.mpm.run import simulate

PARTS = ("plastic_work", "elastic_energy", "kinetic_energy", "interface_dissipation", "contact_impact_loss",
         "frozen_kinetic_loss")
H = 900e6
ana = ploughing(1.0, 200e-6, 0.0, H, H, f=1.0)
print("analytical mu", float(ana.mu), "mu_pl", float(ana.mu_pl), "dp_um", float(ana.dp) * 1e6, flush=True)
for mode in sys.argv[1:]:
    sc = tiny_sliding_scene(True)
    sc = replace(sc, discretisation=replace(sc.discretisation, contact=mode))
    t0 = time.perf_counter()
    ds = simulate(sc, progress=False, threads=2)
    work = float(ds.external_work[-1])
    parts = {k: float(ds[k][-1]) for k in PARTS}
    n = len(ds.contact_area_xy)
    area = float(np.mean(ds.contact_area_xy[n // 2:]))
    print("tiny", mode, "mu", float(ds.mu), "mu_pl", float(ds.mu_pl), "mu_sh", float(ds.mu_sh),
          "dp_um", float(ds.dp) * 1e6, "area_xy_um2", area * 1e12, "Fz/load", float(ds.Fz_mean),
          "energy", sum(parts.values()) / work, {k: round(v / work, 4) for k, v in parts.items()},
          "closest_h", -float(ds.max_particle_penetration) / 10e-6, "wall", time.perf_counter() - t0, flush=True)
