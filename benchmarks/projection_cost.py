"""What the projected dilatation costs per step, kernel by kernel, on a synthetic particle set.

    python benchmarks/projection_cost.py [--particles 80000] [--threads 2]

Times G2P's two passes (``g2p_kinematics`` and ``g2p_update``) without and with the dilatation
projection, and the nodal reduction ``grid_dilatation``, on sorted random particles in an elastic
block (medians of 41 calls after a warm-up call), and whole G2P steps local and projected
alternating, whose paired ratio is the number to quote on a noisy machine. The ploughing scenes
cost more per particle in ``g2p_update`` (plastic return mapping), see
``benchmarks/kernel_profile.py``. Writes benchmarks/results/projection_cost.json.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numba
import numpy as np

from plough.materials import rigid_plastic
from plough.mpm import transfers as tr
from plough.mpm.constitutive import pack_materials


def median_ms(fn, repeats: int = 41) -> float:
    fn()
    times = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return 1e3 * statistics.median(times)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--particles", type=int, default=80_000)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=41)
    args = parser.parse_args()
    numba.set_num_threads(args.threads)
    chunks = args.threads
    table = pack_materials([rigid_plastic("block", 900e6, coating=False)])
    dx, shape, origin = 1e-5, np.array([60, 40, 40], dtype=np.int64), np.zeros(3)
    rng = np.random.default_rng(0)
    n = args.particles
    x = origin + dx * rng.uniform(3, 36, size=(n, 3))
    x = x[np.lexsort((x[:, 2], x[:, 1], x[:, 0]))].copy()  # grid order, as the seeding gives
    vol0 = np.full(n, (0.5 * dx) ** 3)
    J, mass = np.ones(n), 7850e6 * vol0
    v, C, stress = rng.normal(0, 0.01, (n, 3)), np.zeros((n, 3, 3)), np.zeros((n, 6))
    nodes = int(np.prod(shape))
    grid_v, grid_div, buf = rng.normal(0, 0.01, (nodes, 6)), np.zeros(nodes), tr.allocate_grid_buffers(chunks, nodes)
    eps_p, temperature = np.zeros(n), np.full(n, 298.0)
    sigma_y0 = np.full(n, 300e6)  # the rigid-plastic table's flow stress at rest
    mat, frac, near = np.zeros(n, dtype=np.int32), np.ones(n), np.zeros(n, dtype=np.int8)
    acc, v_grid, L_buf = np.zeros((chunks, tr.N_ACC)), np.zeros((n, 3)), tr.allocate_velocity_gradient_scratch(chunks)
    lo, hi, far = origin + dx, origin + dx * (shape - 2), np.ones(3)

    def kinematics(project: int) -> None:
        tr.g2p_kinematics(grid_v, origin, dx, shape, x, v, C, v_grid, mass, 1.0, buf, project, 0, n, 0, buf.shape[1])

    def update(project: int) -> None:
        tr.g2p_update(origin, dx, 1e-9, shape, x, v, v_grid, C, stress, J, vol0, mass, eps_p, temperature,
                      sigma_y0, np.zeros(n), mat, mat, frac, table, 1.0, 0.9, far, 1e-6, 3 * dx, near, acc, lo, hi,
                      grid_div, project, L_buf, 0, n, tr.G2P_BLOCK)

    def step(project: int) -> None:
        kinematics(project)
        if project:
            tr.grid_dilatation(buf, grid_div, shape, -1, 0, buf.shape[1])
        update(project)

    # local and projected steps alternate, so that both see the same machine state; the ratio is
    # the median of the per-pair ratios
    step(0)
    step(1)
    local, projected, ratio = [], [], []
    for _ in range(args.repeats):
        t = [0.0, 0.0]
        for project in (0, 1):
            t0 = time.perf_counter()
            step(project)
            t[project] = time.perf_counter() - t0
        local.append(t[0])
        projected.append(t[1])
        ratio.append(t[1] / t[0])
    parts = {"g2p_kinematics": [median_ms(lambda: kinematics(0)), median_ms(lambda: kinematics(1))],
             "grid_dilatation": [0.0, median_ms(lambda: tr.grid_dilatation(buf, grid_div, shape, -1, 0, buf.shape[1]))],
             "g2p_update": [median_ms(lambda: update(0)), median_ms(lambda: update(1))]}
    print(f"{n:,} particles, {args.threads} threads, ms per call (median of {args.repeats})")
    print("| kernel | local | projected |\n|---|---|---|")
    for k, (a, b) in parts.items():
        print(f"| {k} | {a:.2f} | {b:.2f} |")
    pair = (1e3 * statistics.median(local), 1e3 * statistics.median(projected))
    print(f"| G2P, alternating pairs | {pair[0]:.2f} | {pair[1]:.2f} |")
    print(f"projected / local, median of {args.repeats} paired ratios: {statistics.median(ratio):.2f} "
          f"(quartiles {np.percentile(ratio, 25):.2f}-{np.percentile(ratio, 75):.2f})")
    out = Path(__file__).resolve().parent / "results" / "projection_cost.json"
    out.write_text(json.dumps({
        "particles": n, "threads": args.threads, "repeats": args.repeats, "ms_per_call": parts,
        "g2p_pairs_ms": {"local": pair[0], "projected": pair[1]},
        "ratio_median": statistics.median(ratio),
        "ratio_quartiles": [float(np.percentile(ratio, 25)), float(np.percentile(ratio, 75))],
    }, indent=2) + "\n")

if __name__ == "__main__":
    main()
