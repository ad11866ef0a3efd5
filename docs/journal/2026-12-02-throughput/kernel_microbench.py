"""The transfer kernels alone on one thread, CPU time (a throwaway of the 2026-12-02 throughput entry).

    PYTHONPATH=TREE/src python kernel_microbench.py [reps]  ->  one JSON line: ns CPU time per particle, best of reps

A lattice block of particles (2 per cell per direction) on a grid, random small grid velocities (elastic), one
material row (a constant flow stress, or with PLASTIC=1 a soft one so that some flow)."""
import json
import os
import sys
import time

import numba
import numpy as np

numba.set_num_threads(int(os.environ.get("THREADS", "1")))
from plough.materials import rigid_plastic  # noqa: E402
from plough.mpm import transfers as tr  # noqa: E402
from plough.mpm.bundles import MaterialData, SphereData, grid_of, whole  # noqa: E402
from plough.mpm.constitutive import pack_materials, rest_flow_stresses  # noqa: E402
from plough.mpm.particles import particles_of  # noqa: E402

reps = int(sys.argv[1]) if len(sys.argv) > 1 else 5
DX = 10e-6
cells = (60, 30, 30)
shape = np.array([c + 6 for c in cells])
origin = np.zeros(3)
h = DX / 2
k = [np.arange(2 * c) for c in cells]
idx = np.stack(np.meshgrid(*k, indexing="ij"), -1).reshape(-1, 3)
x = origin + 3 * DX + (idx + 0.5) * h
n = x.shape[0]
rng = np.random.default_rng(1)
n_nodes = int(np.prod(shape))
grid_v = rng.normal(0, 1e-3, (n_nodes, 6))
sy = 3.0e6 if os.environ.get("PLASTIC") else 300e6
table = pack_materials([rigid_plastic("m", sy * 3, coating=False)])
vol0 = np.full(n, h**3)
P = particles_of(n, x=x.copy(), v=np.zeros((n, 3)), vol0=vol0, mass=7800 * vol0,
                 stress=rng.normal(0, 1e5, (n, 6)))
rest_flow_stresses(P.eps_p, P.temperature, P.mat_a, P.mat_b, P.frac_a, table, P.sigma_y0)
n_chunks = numba.get_num_threads()
G = grid_of(origin, DX, shape, n_chunks=n_chunks, v=grid_v)
Z = whole(n, shape, origin + DX, origin + DX * (shape - 2))
M = MaterialData(table, 1.0, 0.9)
S = SphereData(x.mean(0) + np.array([0, 0, 1e-3]), np.zeros(3), 0.5e-3, 3 * DX)
v_grid = np.zeros((n, 3))
L_buf = tr.allocate_velocity_gradient_scratch(n_chunks)
acc = np.zeros((n_chunks, tr.N_ACC))
dt = 1e-9
calls = {
    "p2g": lambda: tr.p2g(P, G, dt, Z),
    "g2p_kinematics": lambda: tr.g2p_kinematics(P, G, v_grid, 0.0, 1, Z),
    "grid_dilatation": lambda: tr.grid_dilatation(G, Z),
    "g2p_update": lambda: tr.g2p_update(P, G, M, S, Z, dt, 1, v_grid, L_buf, acc, tr.G2P_BLOCK),
}
for f in calls.values():
    f()
best = {name: 1e9 for name in calls}
clock = time.process_time if n_chunks == 1 else time.perf_counter
for _ in range(reps):
    for name, f in calls.items():
        t0 = clock()
        f()
        best[name] = min(best[name], clock() - t0)
print(json.dumps({"n": n, **{k: v * 1e9 / n for k, v in best.items()}}))
