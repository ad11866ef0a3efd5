"""Face gaps of the particles under the sphere in steady sliding on the tiny scene (f = 1, h = 10 um, half block),
with the contact named on the command line: the first layer's gaps, ring by ring in the front half. Run from the
repository root with PYTHONPATH=src:tests/mpm."""

import sys
from dataclasses import replace

import numpy as np
from test_verification import tiny_sliding_scene

from plough.mpm import solver

mode = sys.argv[1]
sc = tiny_sliding_scene(True)
sc = replace(sc, discretisation=replace(sc.discretisation, contact=mode))
state, const = solver.init(sc)
while state.sphere.phase != "slide" or state.sphere.slid_m < 150e-6:
    solver.step(state, const)
P, c, R = state.particles, state.sphere.centre, const.sphere_radius
size = (P.vol0 * P.J) ** (1 / 3)
h = float(size.min())
gap = np.linalg.norm(P.x - c, axis=1) - R - 0.5 * size
dxy = P.x[:, :2] - c[:2]
r = np.hypot(dxy[:, 0], dxy[:, 1])
below = P.x[:, 2] < c[2]
print(mode, "sphere depth below the original top (um):", (sc.domain.depth_m if hasattr(sc.domain, "depth_m") else 0),
      "centre z", c[2] * 1e6, "R", R * 1e6)
for half, sel in (("front", below & (dxy[:, 0] > 0)), ("rear", below & (dxy[:, 0] <= 0))):
    print(half)
    for k in range(8):
        ring = sel & (r >= k * 0.5 * h) & (r < (k + 1) * 0.5 * h)
        if not ring.any():
            continue
        g = np.sort(gap[ring]) / h
        print(f"  r {k * 0.5 * h * 1e6:5.1f}-{(k + 1) * 0.5 * h * 1e6:5.1f} um: min gap {g[0]:+.3f} h, "
              f"5 smallest {np.round(g[:5], 3)}")
