"""Where the time of an MPM step goes, kernel by kernel, and the memory-bandwidth bound.

    python benchmarks/kernel_profile.py [--h-um 5] [--threads 2] [--steps 400] [--paper-block] [--scene FILE]
        [--out FILE]

Runs the reference scene (examples/uncoated_rigid_plastic.yaml, or ``--scene``; sized block or --paper-block)
through the press
and into the slide, then times ``--steps`` steps with every kernel the step calls wrapped in a
timer (the wrappers replace the module attributes ``solver.step`` looks up, so the step itself is
the one that runs in production). Reports the median per-step time of each kernel over blocks of
steps, the Python overhead (step time minus the kernels), particle-steps per second, and the
bytes a step must move per particle (particle state read and written by P2G and G2P, plus the
grid traffic per particle), which with the triad bandwidth of ``../shared/peer-bench/bandwidth.py``
gives the bandwidth bound. Writes ``--out`` (default
benchmarks/results/kernel_profile[_<scene>]_h<h>[_paper_block].json).

It patches module attributes, and only these: each wrapper calls the original kernel with the same
arguments and returns its result, adding nothing but a clock read on either side, so the physics is
that of a normal run (no constant, option or kernel is changed); the originals are put back after
the timed steps, also on an error. Timing a kernel this way needs no option in the solver.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from pathlib import Path

import numba

from plough.mpm import contact, solver, transfers
from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]
KERNELS = [(transfers, "scatter_pressure"), (transfers, "p2g"), (transfers, "grid_update"),
           (contact, "scatter_contact_stress"), (contact, "sphere_contact"), (transfers, "mirror_ghosts"),
           (transfers, "g2p_kinematics"), (transfers, "grid_dilatation"), (transfers, "g2p_update")]


def bytes_per_particle_step(n_particles: int, n_nodes: int, n_chunks: int) -> dict[str, float]:
    """Bytes a step moves per particle: the particle arrays each kernel reads and writes, and the grid.

    P2G reads x (3), v (3), C (9), stress (6), vol0, J, mass (3 scalars): 24 float64; G2P reads x,
    C, stress, J, vol0, mass, eps_p, temperature, sigma_y0, deps_last, mat_a/mat_b/frac_a (about 28
    values) and writes x, v, C, stress, J, near (about 22; eps_p, temperature, sigma_y0 and
    deps_last only where a particle flows, not counted); its two passes (kinematics, then the
    update) also write and read the grid velocity at the particle (6) and read x again (3). The
    grid: P2G writes n_chunks copies of 7 values per node (mass, momentum, the internal force's impulse),
    the grid update reads them and writes m and v (7: the velocity before and after the internal force),
    each of the two projections (the pressure's before P2G, the dilatation's after the kinematics)
    writes and reads n_chunks copies of 2 values and writes the nodal value (1), P2G reads the nodal
    pressure (1) and G2P reads v and the dilatation (7). The pressure's projection reads x, the
    stress's diagonal, vol0 and J (8) of each particle.
    """
    particle = 8 * (24 + 28 + 22 + 9 + 8)
    grid = 8 * n_nodes * (n_chunks * 7 * 2 + 7 + 2 * (n_chunks * 2 * 2 + 1) + 1 + 7) / n_particles
    return {"particle_bytes": particle, "grid_bytes": grid, "total_bytes": particle + grid}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--h-um", type=float, default=5.0)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--steps", type=int, default=400)
    parser.add_argument("--paper-block", action="store_true", help="the paper's 0.2 x 1 mm block, not the sized one")
    parser.add_argument("--scene", type=Path, default=ROOT / "examples" / "uncoated_rigid_plastic.yaml",
                        help="scene file (default the uncoated rigid-plastic reference scene)")
    parser.add_argument("--bandwidth-GB-s", type=float, default=43.0,
                        help="STREAM triad bandwidth of the machine (../shared/peer-bench/bandwidth.py)")
    parser.add_argument("--out", type=Path, default=None,
                        help="results file (default benchmarks/results/kernel_profile_h<h>[_paper_block].json)")
    args = parser.parse_args()
    numba.set_num_threads(args.threads)
    from dataclasses import replace

    scene = Scene.from_yaml(args.scene)
    scene = replace(scene, discretisation=replace(scene.discretisation, particle_size_m=args.h_um * 1e-6))
    if not args.paper_block:
        scene = scene.with_sized_domain()
    state, const = solver.init(scene)
    while state.sphere.phase != "slide":
        solver.step(state, const)
    for _ in range(50):  # into the slide, kernels compiled
        solver.step(state, const)

    spent = {name: 0.0 for _, name in KERNELS}
    originals = {}

    def timed(module, name):
        fn = getattr(module, name)
        originals[(module, name)] = fn

        def wrapper(*a):
            t0 = time.perf_counter()
            r = fn(*a)
            spent[name] += time.perf_counter() - t0
            return r

        setattr(module, name, wrapper)

    for module, name in KERNELS:
        timed(module, name)
    block = 20
    per_block: dict[str, list[float]] = {name: [] for name in [*spent, "step", "python"]}
    try:
        for _ in range(args.steps // block):
            for k in spent:
                spent[k] = 0.0
            t0 = time.perf_counter()
            for _ in range(block):
                solver.step(state, const)
            total = (time.perf_counter() - t0) / block
            for k, v in spent.items():
                per_block[k].append(v / block)
            per_block["step"].append(total)
            per_block["python"].append(total - sum(spent.values()) / block)
    finally:
        for (module, name), fn in originals.items():
            setattr(module, name, fn)

    med = {k: statistics.median(v) for k, v in per_block.items()}
    n = state.particles.n
    bpp = bytes_per_particle_step(n, const.grid.n_nodes, state.work.grid_buf.shape[0])
    bound = args.bandwidth_GB_s * 1e9 / bpp["total_bytes"]
    result = {
        "scene": scene.name, "h_um": args.h_um, "threads": args.threads, "particles": n,
        "grid_nodes": const.grid.n_nodes,
        "steps_timed": args.steps, "median_seconds_per_step": med,
        "share": {k: med[k] / med["step"] for k in med if k != "step"},
        "particle_steps_per_s": n / med["step"], **bpp, "bandwidth_GB_s": args.bandwidth_GB_s,
        "bandwidth_bound_particle_steps_per_s": bound,
    }
    block_name = "_paper_block" if args.paper_block else ""
    result["block"] = "paper" if args.paper_block else "sized"
    default_scene = args.scene.resolve() == (ROOT / "examples" / "uncoated_rigid_plastic.yaml").resolve()
    scene_name = "" if default_scene else f"_{scene.name}"
    out = args.out or ROOT / "benchmarks" / "results" / f"kernel_profile{scene_name}_h{args.h_um:g}{block_name}.json"
    out.write_text(json.dumps(result, indent=2) + "\n")
    print(f"{n:,} particles, {const.grid.n_nodes:,} nodes, {args.threads} threads: "
          f"{n / med['step'] / 1e6:.2f} M particle-steps/s (median of {args.steps // block} blocks of {block})")
    print("| kernel | ms per step | share |\n|---|---|---|")
    for k in [*spent, "python"]:
        print(f"| {k} | {med[k] * 1e3:.2f} | {med[k] / med['step']:.0%} |")
    print(f"bytes per particle-step: {bpp['total_bytes']:.0f} ({bpp['particle_bytes']:.0f} particle, "
          f"{bpp['grid_bytes']:.0f} grid); bandwidth bound at {args.bandwidth_GB_s} GB/s: {bound / 1e6:.1f} M "
          f"particle-steps/s, measured {n / med['step'] / bound:.0%} of it")


if __name__ == "__main__":
    main()
