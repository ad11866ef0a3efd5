"""How much one run's mu and dp depend on where the sphere starts against the particle lattice.

    python benchmarks/lattice_phase.py [--cases coated:20 coated:10 real:20] [--phases 8] [--threads 2] [--out FILE]
                                       [--contact MODE]   (a discretisation.contact of plough.mpm.scene.CONTACT_MODES)

The particle lattice and the grid are anchored at x = 0 and the sphere starts at the middle of the
block minus half the slide. Lengthening the block by 2 phi h moves the start by phi h against the
lattice while the slide, the steady window and everything else stay the same: a change with no
physical meaning. Each case runs the scene with the workflow's numerics (graded particles, fine zone
1.5 contact radii, active zone of 4, sized block; ``common.workflow_scene``) at phases
phi = 0, 1/N, ..., (N-1)/N. The spread of mu and dp over the phases is the noise floor of a single
run: two settings whose results differ by less than it cannot be told apart with one run each. It
is set beside each run's own error (``mu_standard_error``: the jackknife over the steady window's
records; ``dp_standard_error``, ``dg_...``, ``hpu_...``: the jackknife over the residual sections and
the contact's lattice-phase term ``GROOVE_LATTICE_PHASE_ERROR_H[contact] * h`` in quadrature, ``plough.mpm.io``) to see
whether that error, which every result file carries, measures this noise: per quantity the median
error, the spread over its median, and the root mean square of the runs' z-scores
``(value - mean over the phases) / error * sqrt(n / (n - 1))`` (1 for a calibrated error, below 1 for
a conservative one), for the groove also with its jackknife part alone. Writes
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
from plough.mpm.scene import CONTACT_MODES, Discretisation

ROOT = Path(__file__).resolve().parents[1]
KEEP = ("mu", "mu_standard_error", "mu_pl", "mu_sh", "dp", "dp_standard_error", "dg", "dg_standard_error", "hpu",
        "hpu_standard_error", "penetration", "Fz_mean", "mu_drift", "material_top_rise", "steady")
GROOVE = ("dp", "dg", "hpu")


def phase_runs(name: str, h_um: float, phases: int, threads: int, contact: str = Discretisation.contact) -> dict:
    h = h_um * 1e-6
    base = workflow_scene(name, h)
    base = replace(base, discretisation=replace(base.discretisation, contact=contact))
    runs = []
    for k in range(phases):
        shift = k / phases * h
        scene = replace(base, domain=replace(base.domain, length_m=base.domain.length_m + 2.0 * shift))
        t0 = time.perf_counter()
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # unsteady windows are reported in the row (mu_drift, steady)
            ds = simulate(scene, progress=False, threads=threads)
        row = {q: float(ds[q]) if q in ds else float("nan") for q in KEEP}  # the groove's errors may be left out
        row["lattice_phase_term_m"] = ds["dp_standard_error"].attrs.get("lattice_phase_term_m", 0.0) \
            if "dp_standard_error" in ds else float("nan")  # the term in the groove's errors, as the run wrote it
        row.update(phase=k / phases, start_x_m=scene.start_x_m, wall_s=time.perf_counter() - t0,
                   particles=int(ds.attrs["cost_particles"]), steps=int(ds.attrs["cost_steps"]))
        runs.append(row)
        print(f"  {name} h={h_um:g} phase {k}/{phases}: mu {row['mu']:.4f} +- {row['mu_standard_error']:.4f}, "
              f"dp {row['dp'] * 1e6:.2f} +- {row['dp_standard_error'] * 1e6:.2f} um, drift {row['mu_drift']:+.3f}, "
              f"{row['wall_s']:.0f} s", flush=True)
    summary = {}
    for q in ("mu", *GROOVE):
        v = np.array([r[q] for r in runs])
        se = np.array([r[f"{q}_standard_error"] for r in runs])
        summary[q] = {"mean": float(v.mean()), "std": float(v.std(ddof=1)),
                      "relative_std": float(v.std(ddof=1) / v.mean()), "min": float(v.min()), "max": float(v.max()),
                      "median_standard_error": float(np.nanmedian(se)),
                      "std_over_median_standard_error": float(v.std(ddof=1) / np.nanmedian(se)),
                      "rms_z": rms_z(v, se)}
        if q in GROOVE:  # the jackknife part alone: the error without the lattice-phase term
            term = np.array([r["lattice_phase_term_m"] for r in runs])
            jack = np.sqrt(np.maximum(se**2 - term**2, 0.0))
            summary[q]["rms_z_jackknife_only"] = rms_z(v, jack)
    return {"scene": name, "h_um": h_um, "contact": contact, "phases": phases, "runs": runs, "summary": summary}


def rms_z(values: np.ndarray, errors: np.ndarray) -> float | None:
    """Root mean square over the runs of ``(value - mean) / error * sqrt(n / (n - 1))``: 1 where the errors
    measure the spread over the phases, below 1 where they overstate it; None where an error is 0 or missing."""
    n = values.size
    if n < 2 or not np.all(errors > 0):
        return None
    z = (values - values.mean()) / errors * np.sqrt(n / (n - 1))
    return float(np.sqrt(np.mean(z**2)))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--cases", nargs="+", default=["coated:20", "coated:10", "real:20"], help="scene:h_um")
    parser.add_argument("--phases", type=int, default=8)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--contact", default=Discretisation.contact, choices=CONTACT_MODES,
                        help=f"discretisation.contact of every run (default: the scene's, {Discretisation.contact}; "
                             "the result files in benchmarks/results/ were measured with grid)")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "lattice_phase.json")
    args = parser.parse_args()
    cases = []
    for case in args.cases:
        name, h_um = case.split(":")
        cases.append(phase_runs(name, float(h_um), args.phases, args.threads, args.contact))
        args.out.write_text(json.dumps({"git_commit": git_commit(), "threads": args.threads, "cases": cases},
                                       indent=1) + "\n")
    print("| scene | h (um) | mu: mean, spread (std) over phases | median SE | rms z "
          + "".join(f"| {q} (um): mean, spread | median error | rms z (jackknife alone) " for q in GROOVE) + "|")
    print("|---" * (5 + 3 * len(GROOVE)) + "|")
    for c in cases:
        m = c["summary"]["mu"]
        line = (f"| {c['scene']} | {c['h_um']:g} | {m['mean']:.4f}, {m['relative_std']:.1%} "
                f"({m['min']:.4f}-{m['max']:.4f}) | {m['median_standard_error']:.4f} | {_num(m['rms_z'])} ")
        for q in GROOVE:
            d = c["summary"][q]
            line += (f"| {d['mean'] * 1e6:.2f}, {d['relative_std']:.1%} | {d['median_standard_error'] * 1e6:.2f} "
                     f"| {_num(d['rms_z'])} ({_num(d['rms_z_jackknife_only'])}) ")
        print(line + "|")


def _num(x: float | None) -> str:
    return "-" if x is None else f"{x:.2f}"


if __name__ == "__main__":
    main()
