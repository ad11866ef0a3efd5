"""One thread, no bundles: a DX56 flow-law evaluation with slopes, and a whole return map with its rest value,
at a real-material scene's time step and rate scale, from guesses within 10% of the root."""

import time

import numpy as np
from numba import njit

from plough.materials import DX56
from plough.mpm import constitutive as c

prm = c.pack_material(DX56)
G = DX56.shear_modulus_Pa
eps, T, dt, rs = 0.1, 300.0, 9.7e-7, 0.01
sig0 = c.flow_stress(prm, eps, 0.0, T)


@njit
def return_maps(prm, qs, G, eps, dt, rs, T, sig0, guesses):
    total = 0.0
    evaluations = 0
    for i in range(qs.size):
        d, _, n = c.return_map_at_rest(prm, prm, 1.0, qs[i], G, eps, dt, rs, T, sig0, guesses[i])
        total += d + c.mixed_flow_stress(prm, prm, 1.0, eps + d, 0.0, T)
        evaluations += n
    return total, evaluations


@njit
def slope_evaluations(prm, n, T):
    total = 0.0
    for i in range(n):
        a, b, r = c.flow_stress_slopes(prm, 0.1 + i * 1e-9, 1e-3 + i * 1e-9, T)
        total += a + b + r
    return total


N = 200_000
rng = np.random.default_rng(0)
qs = sig0 * (1.0 + 1e-3 * rng.uniform(0.5, 1.5, N))
roots = np.array([c.return_map_at_rest(prm, prm, 1.0, q, G, eps, dt, rs, T, sig0, 0.0)[0] for q in qs])
guesses = roots * rng.uniform(0.9, 1.1, N)
return_maps(prm, qs[:10], G, eps, dt, rs, T, sig0, guesses[:10])
slope_evaluations(prm, 10, T)
for _ in range(3):
    t = time.perf_counter()
    _, evaluations = return_maps(prm, qs, G, eps, dt, rs, T, sig0, guesses)
    w = time.perf_counter() - t
    t = time.perf_counter()
    slope_evaluations(prm, N, T)
    w2 = time.perf_counter() - t
    print("return map + rest value ns", 1e9 * w / N, "evaluations a map", evaluations / N,
          "slopes evaluation ns", 1e9 * w2 / N)
