"""The locking check's numbers: the Hertz error at nu = 0.3 and 0.499, both dilatations, the settled hold.

Run from the repository root: python docs/journal/2026-12-02-hertz-block/locking.py DOMAIN_UM (output: locking.txt)
"""

import sys

from plough.mpm.indentation import hertz_force, hertz_scene, hold_at_depth

for nu in (0.3, 0.499):
    for dil in ("projected", "local"):
        r = hold_at_depth(hertz_scene(10.0, 2.0, float(sys.argv[1]), poisson_ratio=nu, dilatation=dil))
        err = r.force_N / hertz_force(2e-6, poisson_ratio=nu) - 1
        print(nu, dil, f"err {err:+.4f} drift {r.force_drift:+.4f} steps {r.steps} wall {r.wall_s:.0f}", flush=True)
