"""How many particles of the zinc-coated steel scene (h = 10 um) flow on a step (run from the repository root)."""

import time

import numpy as np
from zinc_slide import zinc_state_in_slide  # this folder

from plough.mpm import solver

state, const = zinc_state_in_slide(50)
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
