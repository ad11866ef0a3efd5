"""Hertz with the particle contact at law.sweeps = N (wraps contact.particle_contact; the solver passes 4).

Run: PYTHONPATH=src python sweeps.py N [h_um:depth_um ...] (default 5:8); output lines "sweeps ..." in run.log.
"""

import sys

from plough.mpm import contact
from plough.mpm.indentation import hertz_force, hertz_scene, hold_at_depth

orig = contact.particle_contact
N = int(sys.argv[1])


def wrapped(P, G, S, Z, law, step, dt, lp, out):
    return orig(P, G, S, Z, law._replace(sweeps=N), step, dt, lp, out)


contact.particle_contact = wrapped
CASES = [tuple(map(float, c.split(":"))) for c in sys.argv[2:]] or [(5.0, 8.0)]
for h, d in CASES:
    run = hold_at_depth(hertz_scene(h, d, contact_mode="particle"))
    print("sweeps", N, "h", h, "d", d, "err", run.force_N / hertz_force(d * 1e-6) - 1,
          "closest_h", run.closest_centre_m / (h * 1e-6), "wall", run.wall_s, flush=True)
