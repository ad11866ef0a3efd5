"""Benchmark: time of the vectorised analytical model on a sweep of 10^6 points.

    python benchmarks/analytical_sweep.py [--points 1000000] [--repeats 7]

Writes benchmarks/results/analytical_sweep.json (median and spread of the wall times) and prints
a Markdown table row for the README.
"""

from __future__ import annotations

import argparse
import json
import platform
import statistics
import time
from pathlib import Path

import numpy as np

from plough import __version__
from plough.analytical import ploughing


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--points", type=int, default=1_000_000)
    parser.add_argument("--repeats", type=int, default=7)
    parser.add_argument("--out", default=str(Path(__file__).parent / "results" / "analytical_sweep.json"))
    args = parser.parse_args()
    rng = np.random.default_rng(0)
    n = args.points
    load = rng.uniform(1.0, 46.0, n)
    t = rng.uniform(0.0, 200e-6, n)
    ratio = np.geomspace(0.1, 10.0, n)
    rows = {}
    for correction in ("none", "once", "converged"):
        times = []
        for _ in range(args.repeats):
            t0 = time.perf_counter()
            ploughing(load, 0.5e-3, t, ratio * 450e6, 450e6, k1=12.5, correction=correction)
            times.append(time.perf_counter() - t0)
        rows[correction] = {"median_s": statistics.median(times), "min_s": min(times), "max_s": max(times)}
        print(f"| {n:,} points, correction={correction} | {rows[correction]['median_s']:.3f} s median "
              f"({min(times):.3f}-{max(times):.3f}) | {n / rows[correction]['median_s'] / 1e6:.2f} M points/s |")
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps({"points": n, "repeats": args.repeats, "plough_version": __version__,
                                          "machine": platform.processor() or platform.machine(),
                                          "results": rows}, indent=2))


if __name__ == "__main__":
    main()
