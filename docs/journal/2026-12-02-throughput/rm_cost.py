"""The return map's share of g2p_update on zinc-coated steel at h = 10 um (run from the repository root).

Blocks of 10 steps timed as they are, alternating with blocks in which every particle's cached flow stress at
rest is set out of reach, so that no particle calls the return map (four pairs).
"""

import time

from zinc_slide import zinc_state_in_slide  # this folder

from plough.mpm import solver, transfers

state, const = zinc_state_in_slide(30)
original = transfers.g2p_update
spent = [0.0]


def timed_g2p_update(*args):
    t0 = time.perf_counter()
    result = original(*args)
    spent[0] += time.perf_counter() - t0
    return result


def block(n: int = 10) -> tuple[float, float]:
    spent[0] = 0.0
    t0 = time.perf_counter()
    for _ in range(n):
        solver.step(state, const)
    return spent[0] / n, (time.perf_counter() - t0) / n


transfers.g2p_update = timed_g2p_update
saved = state.particles.sigma_y0.copy()
res: dict[str, list[tuple[float, float]]] = {"normal": [], "elastic": []}
for _ in range(4):
    state.particles.sigma_y0[:] = saved
    res["normal"].append(block())
    saved = state.particles.sigma_y0.copy()
    state.particles.sigma_y0[:] = 1e30
    res["elastic"].append(block())
for k, v in res.items():
    print(k, "g2p_update ms", [round(1e3 * a, 1) for a, _ in v], "step ms", [round(1e3 * b, 1) for _, b in v])
