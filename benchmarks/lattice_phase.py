"""How much one run's mu and dp depend on where the sphere starts against the particle lattice.

    python benchmarks/lattice_phase.py [--cases coated:20 coated:10 real:20] [--phases 8] [--threads 2] [--out FILE]

The particle lattice and the grid are anchored at x = 0 and the sphere starts at the middle of the
block minus half the slide. Lengthening the block by 2 phi h moves the start by phi h against the
lattice while the slide, the steady window and everything else stay the same: a change with no
physical meaning. Each case runs the scene with the workflow's numerics (graded particles, fine zone
1.5 contact radii, active zone of 4, sized block; ``common.workflow_scene``) at phases
phi = 0, 1/N, ..., (N-1)/N. The spread of mu and dp over the phases is the noise floor of a single
run: two settings whose results differ by less than it cannot be told apart with one run each. It
is set beside each run's own sampling error (``mu_standard_error``, ``dp_standard_error``: the
jackknife over the steady window's records and the residual sections, ``plough.mpm.io``) to see
whether that error, which every result file carries, measures this noise. Writes
benchmarks/results/lattice_phase.json after every case.
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
from common import workflow_scene

from plough.io import git_commit
from plough.mpm.run import simulate

ROOT = Path(__file__).resolve().parents[1]
KEEP = ("mu", "mu_standard_error", "mu_pl", "mu_sh", "dp", "dp_standard_error", "dg", "hpu", "Fz_mean", "mu_drift",
        "material_top_rise", "steady")


def phase_runs(name: str, h_um: float, phases: int, threads: int) -> dict:
    h = h_um * 1e-6
    base = workflow_scene(name, h)
    runs = []
    for k in range(phases):
        shift = k / phases * h
        scene = replace(base, domain=replace(base.domain, length_m=base.domain.length_m + 2.0 * shift))
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # unsteady windows are reported in the row (mu_drift, steady)
            ds = simulate(scene, progress=False, threads=threads)
        row = {q: float(ds[q]) if q in ds else float("nan") for q in KEEP}  # dp's error may be left out
        row.update(phase=k / phases, start_x_m=scene.start_x_m, wall_s=time.perf_counter() - t0,
                   particles=int(ds.attrs["cost_particles"]), steps=int(ds.attrs["cost_steps"]))
        runs.append(row)
        print(f"  {name} h={h_um:g} phase {k}/{phases}: mu {row['mu']:.4f} +- {row['mu_standard_error']:.4f}, "
              f"dp {row['dp'] * 1e6:.2f} +- {row['dp_standard_error'] * 1e6:.2f} um, drift {row['mu_drift']:+.3f}, "
              f"{row['wall_s']:.0f} s", flush=True)
    summary = {}
    for q in ("mu", "dp"):
        v = np.array([r[q] for r in runs])
        se = np.array([r[f"{q}_standard_error"] for r in runs])
        summary[q] = {"mean": float(v.mean()), "std": float(v.std(ddof=1)),
                      "relative_std": float(v.std(ddof=1) / v.mean()), "min": float(v.min()), "max": float(v.max()),
                      "median_standard_error": float(np.nanmedian(se)),
                      "std_over_median_standard_error": float(v.std(ddof=1) / np.nanmedian(se))}
    return {"scene": name, "h_um": h_um, "phases": phases, "runs": runs, "summary": summary}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cases", nargs="+", default=["coated:20", "coated:10", "real:20"], help="scene:h_um")
    parser.add_argument("--phases", type=int, default=8)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "lattice_phase.json")
    args = parser.parse_args()
    cases = []
    for case in args.cases:
        name, h_um = case.split(":")
        cases.append(phase_runs(name, float(h_um), args.phases, args.threads))
        args.out.write_text(json.dumps({"git_commit": git_commit(), "threads": args.threads, "cases": cases},
                                       indent=1) + "\n")
    print("| scene | h (um) | mu: mean, spread (std) over phases | median SE | dp (um): mean, spread | median SE |")
    print("|---|---|---|---|---|---|")
    for c in cases:
        m, d = c["summary"]["mu"], c["summary"]["dp"]
        print(f"| {c['scene']} | {c['h_um']:g} | {m['mean']:.4f}, {m['relative_std']:.1%} "
              f"({m['min']:.4f}-{m['max']:.4f}) "
              f"| {m['median_standard_error']:.4f} | {d['mean'] * 1e6:.2f}, {d['relative_std']:.1%} "
              f"({d['min'] * 1e6:.2f}-{d['max'] * 1e6:.2f}) | {d['median_standard_error'] * 1e6:.2f} |")


if __name__ == "__main__":
    main()
