"""The compute floor of the full reproduction: the matrix's particle-steps at this machine's peak flop rate.

    python benchmarks/compute_floor.py [--reproduction benchmarks/results/reproduction_time.json]

The bandwidth floor of ``benchmarks/reproduction_time.py`` divides the matrix's particle-steps by the
memory-bandwidth bound of plough's own kernels (the bytes they move per particle-step). This floor
does not depend on plough's kernels: it counts the floating-point operations that one particle-step
of *any* 3D MLS-MPM with quadratic B-splines must do (:func:`min_flops_per_particle_step`, counted
low) and divides the matrix's particle-steps (from the reproduction-time results) by an upper bound
of this machine's flop rate: the core's whole width (two 4-wide FMA pipes and two 4-wide add pipes,
24 flops a cycle) at the clock the fastest repeat of an FMA probe implies (:func:`peak_flops`:
independent FMA chains on data in the L1 cache, no memory traffic), or the fastest rate any probe
measured, whichever is larger. Where even that time exceeds the 4-hour target of issue 5, no
implementation of the method at the chosen particle-steps can meet it on this machine.

Writes benchmarks/results/compute_floor.json and prints a summary.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import time
from datetime import date
from pathlib import Path

import numba
import numpy as np
from numba import njit, prange

from plough.io import git_commit

ROOT = Path(__file__).resolve().parents[1]
#: nodes of a quadratic B-spline stencil in 3D
STENCIL_NODES = 27
#: dependent fused multiply-adds per element and round of the probe
CHAIN_LENGTH = 16
#: double-precision flops a cycle of one core: two 4-wide FMA pipes (AVX2), and with the two 4-wide add pipes
FMA_FLOPS_PER_CYCLE = 16
WIDE_FLOPS_PER_CYCLE = 24


def min_flops_per_particle_step() -> dict[str, int]:
    """Floating-point operations one particle-step of any 3D MLS-MPM (quadratic B-splines) must do.

    Counted low (an FMA counts 2), on the 27 stencil nodes only; the weights, the stress update, the
    grid update and the advection are left out, and every sum that a tensor-product factoring can
    hoist out of the node loop is taken as hoisted:
    - P2G: each node receives four values of its own (mass and three momentum components: the
      particle's m v plus its affine part Q (x_i - x_p), different at every node): at least one
      operation to form each and one to add it into the node, 8 per node;
    - G2P: the velocity sum_i w_i v_i and the velocity gradient sum_i w_i v_i (x_i - x_p)^T; with
      the sums taken line by line (z, then y, then x), every node enters two 3-vector FMA sums along
      its z line (the weighted velocity and its first moment in z, from which the z column of the
      gradient comes; the x and y columns come from the line sums), 12 per node.
    """
    p2g = STENCIL_NODES * (4 + 4)
    g2p = STENCIL_NODES * (2 * 3 * 2)
    return {"p2g": p2g, "g2p": g2p, "total": p2g + g2p}


@njit(cache=True, parallel=True, fastmath=True)
def _fma_chains(a, reps, s, t):
    """Run ``reps`` rounds of CHAIN_LENGTH dependent FMAs on each element of a (threads x n), in place.

    Reads and writes a. Each thread c works on its own row a[c] (race-free); within a row eight
    elements a stride apart are carried together, so that eight independent chains (vectorised
    across i) hide the FMA latency. ``fastmath`` lets LLVM contract y * s + t into one FMA.
    """
    for c in prange(a.shape[0]):
        row = a[c]
        h = row.size // 8
        for _ in range(reps):
            for i in range(h):
                y0 = row[i]
                y1 = row[i + h]
                y2 = row[i + 2 * h]
                y3 = row[i + 3 * h]
                y4 = row[i + 4 * h]
                y5 = row[i + 5 * h]
                y6 = row[i + 6 * h]
                y7 = row[i + 7 * h]
                for _k in range(CHAIN_LENGTH):
                    y0 = y0 * s + t
                    y1 = y1 * s + t
                    y2 = y2 * s + t
                    y3 = y3 * s + t
                    y4 = y4 * s + t
                    y5 = y5 * s + t
                    y6 = y6 * s + t
                    y7 = y7 * s + t
                row[i] = y0
                row[i + h] = y1
                row[i + 2 * h] = y2
                row[i + 3 * h] = y3
                row[i + 4 * h] = y4
                row[i + 5 * h] = y5
                row[i + 6 * h] = y6
                row[i + 7 * h] = y7


def peak_flops(threads: int, repeats: int, n: int = 1024, flops_per_call: float = 4e9) -> list[float]:
    """FLOP/s of the FMA probe on ``threads`` threads, one value per repetition (after a warm-up call)."""
    numba.set_num_threads(threads)
    a = np.ones((threads, n))
    s, t = 0.999999, 1e-6  # fixed point 1: the values neither grow nor go subnormal
    flops_per_rep = threads * n * CHAIN_LENGTH * 2
    _fma_chains(a, 1, s, t)
    reps = max(1, int(flops_per_call / flops_per_rep))
    rates = []
    for _ in range(repeats):
        t0 = time.perf_counter()
        _fma_chains(a, reps, s, t)
        rates.append(reps * flops_per_rep / (time.perf_counter() - t0))
    if not np.all(np.isfinite(a)):
        raise RuntimeError("the FMA probe produced non-finite values")
    return rates


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--reproduction", default=str(ROOT / "benchmarks" / "results" / "reproduction_time.json"),
                        help="benchmarks/reproduction_time.py results (the matrix's particle-steps and the target)")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "compute_floor.json"))
    args = parser.parse_args()
    flops = min_flops_per_particle_step()
    rates = {f"fma {n} thread(s)": peak_flops(n, args.repeats) for n in (1, args.threads)}
    for name, r in rates.items():
        print(f"{name:22s} median {statistics.median(r) / 1e9:5.1f} GFLOP/s, fastest {max(r) / 1e9:5.1f} "
              f"({args.repeats} repeats)")
    # the clock the fastest FMA repeat implies at two 4-wide FMA pipes a core (16 flops a cycle), and the
    # core's whole width at that clock: Zen 3 has two add pipes beside them (a scatter's adds could run
    # there), 24 flops a cycle
    clock_hz = max(rates[f"fma {args.threads} thread(s)"]) / (FMA_FLOPS_PER_CYCLE * args.threads)
    peak = max([WIDE_FLOPS_PER_CYCLE * clock_hz * args.threads] + [max(r) for r in rates.values()])
    print(f"clock implied {clock_hz / 1e9:.2f} GHz; upper bound {peak / 1e9:.1f} GFLOP/s on {args.threads} threads "
          f"({WIDE_FLOPS_PER_CYCLE} flops a cycle a core)")
    print(f"lower bound per particle-step: {flops['total']} flops (P2G {flops['p2g']}, G2P {flops['g2p']})")
    bound = peak / flops["total"]
    print(f"so at most {bound / 1e6:.0f} M particle-steps/s on this machine with any MLS-MPM code")
    repro = json.loads(Path(args.reproduction).read_text())
    target_s = repro["target_s"]
    floors = {}
    for name, row in repro["floor"].items():
        ps = row["particle_steps"]
        seconds = ps / bound
        needed = ps / target_s * flops["total"]
        floors[name] = {"particle_steps": ps, "at_peak_s": seconds, "flops_needed_per_s_for_target": needed,
                        "needed_over_peak": needed / peak}
        print(f"{name}: {ps:.3g} particle-steps -> at least {seconds / 3600:.1f} h; within {target_s / 3600:g} h it "
              f"needs {needed / 1e9:.0f} GFLOP/s, {needed / peak:.2f}x the upper bound")
    machine = platform.processor() or platform.machine()
    out = {"date": date.today().isoformat(), "commit": git_commit(), "machine": machine,
           "threads": args.threads, "repeats": args.repeats, "flops_per_s": rates,
           "clock_implied_hz": clock_hz, "peak_flops_per_s_upper_bound": peak,
           "min_flops_per_particle_step": flops, "particle_steps_per_s_bound": bound,
           "reproduction": args.reproduction, "target_s": target_s, "floor": floors}
    Path(args.out).write_text(json.dumps(out, indent=2) + "\n")


if __name__ == "__main__":
    main()
