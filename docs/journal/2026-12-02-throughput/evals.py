"""Return-map evaluations per flowing particle on zinc-coated steel at h = 10 um, replayed from the states before
the step (run from the repository root). A flowing particle's trial stress is rebuilt from its increment d:
q_trial = 3 G d + sigma_y(eps_p + d, d rate_scale / dt, T)."""

import collections

import numpy as np
from zinc_slide import zinc_state_in_slide  # this folder

from plough.mpm import constitutive as c
from plough.mpm import solver

state, const = zinc_state_in_slide(30)
P = state.particles
table, dt, rs = const.table, const.dt, const.rate_scale
hist: collections.Counter = collections.Counter()
guess_over_root = []
for _ in range(5):
    before = {k: getattr(P, k).copy() for k in ("eps_p", "temperature", "sigma_y0", "deps_last")}
    solver.step(state, const)
    idx = np.nonzero(P.eps_p != before["eps_p"])[0]
    for p in idx[:: max(1, idx.size // 3000)]:
        pa, pb, fa = table[P.mat_a[p]], table[P.mat_b[p]], P.frac_a[p]
        _, G = c.mixed_moduli(pa, pb, fa)
        eps, T, d = before["eps_p"][p], before["temperature"][p], P.eps_p[p] - before["eps_p"][p]
        q = 3 * G * d + c.mixed_flow_stress(pa, pb, fa, eps + d, d * rs / dt, T)
        n = c.return_map_at_rest(pa, pb, fa, q, G, eps, dt, rs, T, before["sigma_y0"][p], before["deps_last"][p])[2]
        hist[(int(P.mat_a[p]), int(P.mat_b[p]), bool(0.0 < fa < 1.0), n)] += 1
        if before["deps_last"][p] > 0:
            guess_over_root.append(before["deps_last"][p] / d)
print("(mat_a, mat_b, mixed, evaluations): count", sorted(hist.items()))
g = np.array(guess_over_root)
print("guess / root quantiles 10/25/50/75/90%", np.quantile(g, [0.1, 0.25, 0.5, 0.75, 0.9]),
      "without a guess", sum(hist.values()) - g.size)
