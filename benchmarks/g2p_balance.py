"""The stress update's split over the threads: two slabs against blocks dealt in turn.

    python benchmarks/g2p_balance.py [--blocks 256 1024 4096 16384] [--reps 11] [--threads 2] [--out FILE]

``transfers.g2p_update`` deals blocks of ``block`` particles to the chunks in turn; ``block`` =
ceil(n / n_chunks) gives one contiguous slab per chunk, the split it used before (for 2 threads
the slab boundary is at most one particle off the earlier one). Plastic particles, whose
return map costs several flow-law evaluations, cluster around the sphere, so a slab split can give
one thread most of them. For each case (a scene, its numerics, how far into the slide) this runs
the scene to that point, then times ``g2p_update`` alone on the same state (restored before every
call) with the slab split and with each block size, alternating, ``--reps`` times; the particle
state must come out the same to the bit for every split. It also times the two slabs alone on one
thread. Reports medians and the median of the per-repetition ratios slab / blocks. Writes
benchmarks/results/g2p_balance.json.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from dataclasses import replace
from pathlib import Path

import numba
import numpy as np

from plough.io import git_commit
from plough.mpm import solver, transfers
from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]
# (label, scene file, h (m), the workflow's numerics (graded particles, active zone of 4 contact radii)?,
#  sliding steps before timing)
CASES = [
    ("zinc-coated steel, uniform, start of the slide", "zinc_coated_steel.yaml", 10e-6, False, 50),
    ("zinc-coated steel, workflow numerics, start of the slide", "zinc_coated_steel.yaml", 10e-6, True, 50),
    ("zinc-coated steel, workflow numerics, 1,550 steps in", "zinc_coated_steel.yaml", 10e-6, True, 1550),
    ("uncoated rigid-plastic reference, uniform, 3,050 steps in", "uncoated_rigid_plastic.yaml", 5e-6, False, 3050),
    ("coated rigid-plastic, workflow numerics, 3,050 steps in", "coated_rigid_plastic.yaml", 5e-6, True, 3050),
]
STATE = ("x", "stress", "eps_p", "temperature", "sigma_y0", "deps_last", "J", "near")


def prepared(scene_file: str, h_m: float, workflow: bool, steps: int) -> tuple[solver.State, solver.Constants]:
    """The scene on its sized block, run through the press and ``steps`` steps of the slide."""
    scene = Scene.from_yaml(ROOT / "examples" / scene_file)
    extra = {"graded": True, "active_zone_contact_radii": 4.0} if workflow else {}
    disc = replace(scene.discretisation, particle_size_m=h_m, **extra)
    state, const = solver.init(replace(scene, discretisation=disc).with_sized_domain())
    while state.sphere.phase != "slide":
        solver.step(state, const)
    for _ in range(steps):
        solver.step(state, const)
    return state, const


def timer(state: solver.State, const: solver.Constants):
    """A function that restores the particle state, runs g2p_update over [lo, hi) and returns its seconds."""
    p, w, g, c, z = state.particles, state.work, const.grid, const, state.zone
    keep = {k: getattr(p, k).copy() for k in STATE}

    def run(block: int, lo: int, hi: int, acc: np.ndarray, L_buf: np.ndarray) -> float:
        for k, a in keep.items():
            getattr(p, k)[:] = a
        t0 = time.perf_counter()
        transfers.g2p_update(g.origin, g.dx, c.dt, c.shape, p.x, p.v, w.v_grid, p.C, p.stress, p.J, p.vol0, p.mass,
                             p.eps_p, p.temperature, p.sigma_y0, p.deps_last, p.mat_a, p.mat_b, p.frac_a, c.table,
                             c.rate_scale, c.taylor_quinney, state.sphere.centre, c.sphere_radius, c.near_dist,
                             p.near, acc, z.check_lo_m, z.check_hi_m, w.grid_div, c.project_dilatation, L_buf, lo, hi,
                             block)
        return time.perf_counter() - t0

    return run, keep


def measure(case: tuple, blocks: list[int], reps: int, threads: int) -> dict:
    label, scene_file, h_m, workflow, steps = case
    numba.set_num_threads(threads)
    state, const = prepared(scene_file, h_m, workflow, steps)
    p, z = state.particles, state.zone
    n = z.p_hi - z.p_lo
    run, keep = timer(state, const)
    acc, L_buf = np.zeros((threads, transfers.N_ACC)), transfers.allocate_velocity_gradient_scratch(threads)
    splits = {"slab": (n + threads - 1) // threads, **{f"block {b}": b for b in blocks}}
    results = {}
    for name, b in splits.items():
        run(b, z.p_lo, z.p_hi, acc, L_buf)
        results[name] = tuple(getattr(p, k).copy() for k in STATE)
    flowed = int((results["slab"][2] > keep["eps_p"]).sum())
    same = all(all(np.array_equal(a, b) for a, b in zip(results["slab"], r, strict=True)) for r in results.values())
    times = {name: [] for name in splits}
    for _ in range(reps):
        for name, b in splits.items():
            times[name].append(run(b, z.p_lo, z.p_hi, acc, L_buf))
    # the two slabs alone, one thread each
    numba.set_num_threads(1)
    acc1, L1 = np.zeros((1, transfers.N_ACC)), transfers.allocate_velocity_gradient_scratch(1)
    mid = z.p_lo + n // 2
    slab_ms = {"first": [], "second": []}
    for _ in range(max(reps // 2, 3)):
        slab_ms["first"].append(run(n, z.p_lo, mid, acc1, L1))
        slab_ms["second"].append(run(n, mid, z.p_hi, acc1, L1))
    numba.set_num_threads(threads)
    return {
        "case": label, "scene": scene_file, "h_um": h_m * 1e6, "workflow_numerics": workflow, "sliding_steps": steps,
        "particles_updated": n, "particles_flowing": flowed, "same_state_to_the_bit": same,
        "median_ms": {k: statistics.median(v) * 1e3 for k, v in times.items()},
        "slab_over_split_pair_median": {k: statistics.median([a / b for a, b in zip(times["slab"], v, strict=True)])
                                        for k, v in times.items()},
        "one_thread_slab_ms": {k: statistics.median(v) * 1e3 for k, v in slab_ms.items()},
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--blocks", type=int, nargs="+", default=[256, 1024, 4096, 16384])
    parser.add_argument("--reps", type=int, default=11)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "g2p_balance.json")
    args = parser.parse_args()
    rows = []
    print("| case | particles (flowing) | slab ms | " + " | ".join(f"block {b}" for b in args.blocks)
          + " | slabs alone, 1 thread (ms) |")
    print("|---|---|---|" + "---|" * len(args.blocks) + "---|")
    for case in CASES:
        row = measure(case, args.blocks, args.reps, args.threads)
        rows.append(row)
        med, ratio = row["median_ms"], row["slab_over_split_pair_median"]
        cells = " | ".join(f"{med[f'block {b}']:.2f} ({ratio[f'block {b}']:.2f}x)" for b in args.blocks)
        one = row["one_thread_slab_ms"]
        print(f"| {row['case']} | {row['particles_updated']:,} ({row['particles_flowing']:,}) | {med['slab']:.2f} | "
              f"{cells} | {one['first']:.1f} / {one['second']:.1f} |", flush=True)
        if not row["same_state_to_the_bit"]:
            raise SystemExit(f"{row['case']}: the splits gave different particle states")
        args.out.write_text(json.dumps({"git_commit": git_commit(), "threads": args.threads, "reps": args.reps,
                                        "production_block": transfers.G2P_BLOCK, "cases": rows}, indent=2) + "\n")


if __name__ == "__main__":
    main()
