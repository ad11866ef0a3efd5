"""The Hertz error with indentation.hold_at_depth as it is (settled by shear-wave crossings), per case.

Run from the repository root: python docs/journal/2026-12-02-hertz-block/hold.py CONTACT:H_UM:DEPTH_UM:DOMAIN_UM ...
"""

import json
import sys

from plough.mpm.indentation import hertz_force, hertz_scene, hold_at_depth

for case in sys.argv[1:]:
    mode, h, d, L = case.split(":")
    h, d, L = float(h), float(d), float(L)
    run = hold_at_depth(hertz_scene(h, d, domain_um=L, contact_mode=mode))
    print(json.dumps({"case": case, "error": run.force_N / hertz_force(d * 1e-6) - 1.0, "drift": run.force_drift,
                      "closest_centre_h": run.closest_centre_m / (h * 1e-6), "steps": run.steps,
                      "wall_s": run.wall_s}), flush=True)
