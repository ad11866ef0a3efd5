"""The explicit step's remainder 1/2 m |v^(n+1) - v^n|^2, summed over the grid's free nodes after every step, beside
the energy terms a run records (journal 2026-12-02-cfl.md, "What is left").

    python docs/journal/2026-12-02-cfl/remainder.py tiny uncoated:20:0.5 coated:10:1

v^n is the nodal velocity P2G gives before the internal force (G.v[:, 3:6]), v^(n+1) the velocity after the
internal force, the boundary conditions and the contact (G.v[:, 0:3]); FIXED and GHOST nodes and the frozen
slabs beyond the active zone are left out (their velocity is set, not integrated). A probe: it wraps
``solver.step`` and sums with numpy after each step.
"""

from __future__ import annotations

import sys
import warnings
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
sys.path.insert(0, str(HERE.parents[2]))

from probe import ENERGY, scene_of  # noqa: E402

from plough.mpm import solver  # noqa: E402
from plough.mpm.grid import FREE, MIRROR  # noqa: E402
from plough.mpm.run import simulate  # noqa: E402

ORIGINAL = solver.step
TOTAL = [0.0]


def step_and_sum(s, c) -> None:
    ORIGINAL(s, c)
    w, z = s.work, s.zone.ranges
    slab = c.shape[1] * c.shape[2]
    nodes = np.arange(w.grid_m.size)
    i = nodes // slab
    keep = ((w.grid_m > 0) & ((w.flags == FREE) | (w.flags == MIRROR)) & (i >= z.i_free_lo) & (i <= z.i_free_hi))
    d = w.grid_v[keep, 0:3] - w.grid_v[keep, 3:6]
    TOTAL[0] += c.symmetry_factor * 0.5 * float((w.grid_m[keep] * (d * d).sum(axis=1)).sum())


def main() -> None:
    solver.step = step_and_sum
    for case in sys.argv[1:]:
        if case == "tiny":
            from tests.mpm.test_verification import tiny_sliding_scene
            scene = tiny_sliding_scene(True, False)
        else:
            scene = scene_of(case, 0.3, 0.0)
        TOTAL[0] = 0.0
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            ds = simulate(scene, progress=False, threads=2)
        work = float(ds.external_work[-1])
        terms = sum(float(ds[q][-1]) for q in ENERGY) / work
        print(f"{case}: terms / work {terms:.4f}, remainder / work {TOTAL[0] / work:.4f}, "
              f"together {terms + TOTAL[0] / work:.4f}", flush=True)


if __name__ == "__main__":
    main()
