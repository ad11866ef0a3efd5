"""Face gaps of the particles against the sphere in steady sliding: `gaps.py CONTACT tiny` (the tiny scene of
tests/mpm/test_verification.py, f = 1, h = 10 um, half block: the smallest gap ring by ring) or
`gaps.py CONTACT SCENE F H_UM` (a reference scene of benchmarks/common.py with the workflow's numerics: the
projected area sum A_p |n_z| of the front-half particles within each gap tolerance, against the analytical Axy).
Stops at 3/4 of the sliding distance. Run from the repository root with PYTHONPATH=src:tests/mpm:benchmarks."""

import sys
from dataclasses import replace

import numpy as np

from plough.mpm import solver

mode = sys.argv[1]
if sys.argv[2] == "tiny":
    from test_verification import tiny_sliding_scene
    sc = tiny_sliding_scene(True)
    stop = 150e-6
else:
    import common

    from plough.materials import ProportionalShear
    sc = common.workflow_scene(sys.argv[2], float(sys.argv[4]) * 1e-6)
    sc = replace(sc, interface=ProportionalShear(f=float(sys.argv[3])))
    stop = 0.75 * sc.sliding.distance_m
sc = replace(sc, discretisation=replace(sc.discretisation, contact=mode))
state, const = solver.init(sc)
while state.sphere.phase != "slide" or state.sphere.slid_m < stop:
    solver.step(state, const)
P, c, R = state.particles, state.sphere.centre, const.sphere_radius
size = (P.vol0 * P.J) ** (1 / 3)
q = P.x - c
dist = np.linalg.norm(q, axis=1)
gap = dist - R - 0.5 * size
n = q / dist[:, None]
below = q[:, 2] < 0
r = np.hypot(q[:, 0], q[:, 1])
h = float(size.min())
print(mode, sys.argv[2:], "sphere bottom", (c[2] - R) * 1e6, "um; h", h * 1e6, "um")
if sys.argv[2] == "tiny":
    for half, sel in (("front", below & (q[:, 0] > 0)), ("rear", below & (q[:, 0] <= 0))):
        print(half)
        for k in range(8):
            ring = sel & (r >= k * 0.5 * h) & (r < (k + 1) * 0.5 * h)
            if ring.any():
                g = np.sort(gap[ring]) / h
                print(f"  r {k * 0.5 * h * 1e6:5.1f}-{(k + 1) * 0.5 * h * 1e6:5.1f} um: min gap {g[0]:+.3f} h, "
                      f"5 smallest {np.round(g[:5], 3)}")
else:
    area = size**2 / np.abs(n).sum(axis=1) * np.abs(n[:, 2]) * const.symmetry_factor
    for half, sel in (("front", below & (q[:, 0] > 0)), ("rear", below & (q[:, 0] <= 0))):
        for tol in (h * h / (2 * R), 0.05 * h, 0.1 * h, 0.25 * h, 0.5 * h, 0.75 * h):
            s = sel & (gap <= tol)
            print(f"  {half} gap <= {tol / h:.3f} h: {s.sum()} particles, area_xy {area[s].sum() * 1e12:.0f} um2")
    front = below & (q[:, 0] > 0) & (gap < 1.5 * h)
    print("  front gaps < 1.5 h, histogram in h (0.05 bins):",
          np.histogram(gap[front] / h, bins=np.arange(-0.1, 1.5, 0.05))[0].tolist())
