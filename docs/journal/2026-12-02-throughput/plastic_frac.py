"""How many particles of the zinc-coated steel scene (h = 10 um) flow on a step (run from the repository root)."""

import time
from dataclasses import replace

import numba
import numpy as np

from plough.mpm import solver
from plough.mpm.scene import Scene

numba.set_num_threads(2)
scene = Scene.from_yaml("examples/zinc_coated_steel.yaml")
scene = replace(scene, discretisation=replace(scene.discretisation, particle_size_m=10e-6)).with_sized_domain()
state, const = solver.init(scene)
while state.sphere.phase != "slide":
    solver.step(state, const)
for _ in range(50):
    solver.step(state, const)
P = state.particles
flowing = []
t0 = time.perf_counter()
for _ in range(40):
    before = P.eps_p.copy()
    solver.step(state, const)
    flowing.append(np.count_nonzero(P.eps_p != before))
print("particles", P.n, "flowing per step", np.mean(flowing), "fraction", np.mean(flowing) / P.n,
      "step s", (time.perf_counter() - t0) / 40)
print("materials a", np.unique(P.mat_a, return_counts=True), "b", np.unique(P.mat_b, return_counts=True))
