"""Tabor's mean pressure with the settled hold (indentation.hold_at_depth) in blocks of two sizes.

Run from the repository root: python docs/journal/2026-12-02-hertz-block/tabor.py CONTACT:H_UM:DEPTH_UM:DOMAIN_UM ...
"""

import json
import math
import sys

from plough.mpm.indentation import TABOR_HARDNESS_PA, contact_radius_from_particles, hold_at_depth, tabor_scene

for case in sys.argv[1:]:
    mode, h, d, L = case.split(":")
    h, d, L = float(h), float(d), float(L)
    run = hold_at_depth(tabor_scene(h, d, domain_um=L, contact_mode=mode))
    sigma_y = TABOR_HARDNESS_PA / 3.0
    a_c = contact_radius_from_particles(run.state, run.const)
    a_sec = math.sqrt(2 * 200e-6 * d * 1e-6 - (d * 1e-6) ** 2)
    print(json.dumps({"case": case, "force_N": run.force_N, "drift": run.force_drift, "a_c_um": a_c * 1e6,
                      "p_true_over_sigma_y": run.force_N / (math.pi * a_c**2) / sigma_y,
                      "p_section_over_sigma_y": run.force_N / (math.pi * a_sec**2) / sigma_y,
                      "steps": run.steps, "wall_s": run.wall_s}), flush=True)
