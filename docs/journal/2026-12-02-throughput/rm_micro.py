import time, numpy as np
from numba import njit
from plough.mpm import constitutive as c
from plough.materials import DX56
prm = c.pack_material(DX56); G = DX56.shear_modulus_Pa
eps, T, dt, rs = 0.1, 300.0, 9.7e-7, 0.01
sig0 = c.flow_stress(prm, eps, 0.0, T)
d, _, n = c.return_map_at_rest(prm, prm, 1.0, sig0 * 1.001, G, eps, dt, rs, T, sig0, 0.0)
@njit
def loop(prm, qs, G, eps, dt, rs, T, sig0, guesses):
    s = 0.0; ev = 0
    for i in range(qs.size):
        d, sy, n = c.return_map_at_rest(prm, prm, 1.0, qs[i], G, eps, dt, rs, T, sig0, guesses[i])
        s += d; ev += n
        s += c.mixed_flow_stress(prm, prm, 1.0, eps + d, 0.0, T)
    return s, ev
@njit
def evals(prm, n, T):
    s = 0.0
    for i in range(n):
        a, b, cc = c.flow_stress_slopes(prm, 0.1 + i * 1e-9, 1e-3 + i * 1e-9, T)
        s += a + b + cc
    return s
N = 200000
rng = np.random.default_rng(0)
qs = sig0 * (1.0 + 1e-3 * rng.uniform(0.5, 1.5, N))
roots = np.array([c.return_map_at_rest(prm, prm, 1.0, q, G, eps, dt, rs, T, sig0, 0.0)[0] for q in qs[:1000]])
gs = np.resize(roots, N) * rng.uniform(0.9, 1.1, N)
loop(prm, qs[:10], G, eps, dt, rs, T, sig0, gs[:10]); evals(prm, 10, T)
for _ in range(3):
    t = time.perf_counter(); s, ev = loop(prm, qs, G, eps, dt, rs, T, sig0, gs); w = time.perf_counter() - t
    t = time.perf_counter(); evals(prm, N, T); w2 = time.perf_counter() - t
    print("per return map + rest eval ns", 1e9 * w / N, "evals/map", ev / N, "per slopes eval ns", 1e9 * w2 / N)
