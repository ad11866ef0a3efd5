"""The return map's share of g2p_update on zinc-coated steel at h = 10 um: steps timed as they are, then with
every particle's cached flow stress set out of reach (no particle calls the return map)."""
import time, numpy as np, numba, statistics
from dataclasses import replace
from plough.mpm import solver, transfers
from plough.mpm.scene import Scene
numba.set_num_threads(2)
scene = Scene.from_yaml("examples/zinc_coated_steel.yaml")
scene = replace(scene, discretisation=replace(scene.discretisation, particle_size_m=10e-6)).with_sized_domain()
state, const = solver.init(scene)
while state.sphere.phase != "slide":
    solver.step(state, const)
for _ in range(30):
    solver.step(state, const)
orig = transfers.g2p_update
spent = [0.0]
def wrapper(*a):
    t0 = time.perf_counter(); r = orig(*a); spent[0] += time.perf_counter() - t0; return r
transfers.g2p_update = wrapper
def block(n=10):
    spent[0] = 0.0; t0 = time.perf_counter()
    for _ in range(n):
        solver.step(state, const)
    return spent[0] / n, (time.perf_counter() - t0) / n
saved = state.particles.sigma_y0.copy()
res = {"normal": [], "elastic": []}
for rep in range(4):
    state.particles.sigma_y0[:] = saved
    res["normal"].append(block())
    saved = state.particles.sigma_y0.copy()
    state.particles.sigma_y0[:] = 1e30
    res["elastic"].append(block())
for k, v in res.items():
    print(k, "g2p_update ms", [round(1e3 * a, 1) for a, _ in v], "step ms", [round(1e3 * b, 1) for _, b in v])
