"""What the real materials' flow laws cost per particle-step, against constant flow stresses on the same block.

    python benchmarks/material_cost.py [--h-um 10] [--steps 200] [--rounds 3] [--threads 2] [--out FILE]

The zinc-coated steel scene (examples/zinc_coated_steel.yaml: power-law coating, eq. 7.3, on
Bergstrom-van Liempt DX56, eq. 7.1, with rate terms and adiabatic heating) on its sized block,
and the same block, particles, grid, sphere, load and interface with the two layers replaced by
the Table-2 rigid-plastic materials of the coated reference scene (constant flow stresses,
450 / 900 MPa hardness). Each run presses, slides 50 steps, then times ``--steps`` steps in
blocks of 20 (median per step); the two alternate ``--rounds`` times in one process. The
ratio of their particle-steps per second is what ``benchmarks/reproduction_time.py`` applies
to the real-material runs of the workflow, whose throughput it otherwise takes from the
rigid-plastic reference scene. Writes benchmarks/results/material_cost.json.
"""

from __future__ import annotations

import argparse
import json
import statistics
import time
from dataclasses import replace
from pathlib import Path

import numba

from plough.io import git_commit
from plough.materials import rigid_plastic
from plough.mpm import solver
from plough.mpm.scene import Layers, Scene

ROOT = Path(__file__).resolve().parents[1]


def scenes(h_m: float) -> dict[str, Scene]:
    real = Scene.from_yaml(ROOT / "examples" / "zinc_coated_steel.yaml")
    real = replace(real, discretisation=replace(real.discretisation, particle_size_m=h_m)).with_sized_domain()
    layers = Layers(substrate=rigid_plastic("substrate_900MPa", 900e6, coating=False),
                    coating=rigid_plastic("coating_450MPa", 450e6, coating=True),
                    coating_thickness_m=real.layers.coating_thickness_m)
    return {"real materials": real, "constant flow stress": replace(real, layers=layers, name="constant_flow")}


def time_steps(scene: Scene, steps: int) -> dict[str, float]:
    state, const = solver.init(scene)
    while state.sphere.phase != "slide":
        solver.step(state, const)
    for _ in range(50):
        solver.step(state, const)
    blocks = []
    flowing = []
    for _ in range(max(steps // 20, 1)):
        eps0 = state.particles.eps_p.copy()
        t0 = time.perf_counter()
        for _ in range(20):
            solver.step(state, const)
        blocks.append((time.perf_counter() - t0) / 20)
        flowing.append(float((state.particles.eps_p != eps0).mean()))
    per_step = statistics.median(blocks)
    n = state.particles.n
    return {"particles": n, "seconds_per_step": per_step, "particle_steps_per_s": n / per_step,
            "share_flowing_in_20_steps": statistics.median(flowing)}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--h-um", type=float, default=10.0)
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--rounds", type=int, default=3)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "material_cost.json")
    args = parser.parse_args()
    numba.set_num_threads(args.threads)
    variants = scenes(args.h_um * 1e-6)
    runs: dict[str, list[dict[str, float]]] = {name: [] for name in variants}
    for r in range(args.rounds):
        for name, scene in variants.items():
            runs[name].append(time_steps(scene, args.steps))
            print(f"round {r + 1}, {name}: {runs[name][-1]['seconds_per_step'] * 1e3:.1f} ms per step, "
                  f"{runs[name][-1]['particle_steps_per_s'] / 1e6:.2f} M particle-steps/s", flush=True)
    ratios = [a["particle_steps_per_s"] / b["particle_steps_per_s"]
              for a, b in zip(runs["real materials"], runs["constant flow stress"], strict=True)]
    ratio = statistics.median(ratios)
    out = {"git_commit": git_commit(), "h_um": args.h_um, "threads": args.threads, "steps_timed": args.steps,
           "runs": runs, "ratio_per_round": ratios, "real_over_constant_throughput": ratio}
    args.out.write_text(json.dumps(out, indent=2) + "\n")
    print(f"real materials run at {ratio:.3f} of the constant-flow throughput (median of {args.rounds} rounds: "
          + ", ".join(f"{x:.3f}" for x in ratios) + f"); {args.out}")


if __name__ == "__main__":
    main()
