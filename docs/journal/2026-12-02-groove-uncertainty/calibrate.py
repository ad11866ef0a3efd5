"""rms z of one run's groove errors against the lattice-phase spread, for several lattice-phase terms c h.

    python docs/journal/2026-12-02-groove-uncertainty/calibrate.py benchmarks/results/lattice_phase*.json

Reads the per-run values of benchmarks/lattice_phase.py result files, takes each error's jackknife part
(the file's error less the lattice-phase term the run was written with, ``lattice_phase_term_m``), adds
c h in quadrature for each c, and prints per case and over all runs the root mean square of
``(value - mean over the phases) / error * sqrt(n / (n - 1))`` (1: calibrated; below 1: conservative) and
the share of runs within one error of the mean.
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "benchmarks"))
from lattice_phase import rms_z  # noqa: E402

TERMS = (0.0, 0.05, 0.1, 0.15, 0.2)


def jackknife_part(run: dict, q: str) -> float:
    se = run.get(f"{q}_standard_error", np.nan)
    term = run.get("lattice_phase_term_m", 0.0)
    return float(np.sqrt(max(se**2 - term**2, 0.0)))


def main() -> None:
    cases = [c for f in sys.argv[1:] for c in json.load(open(f))["cases"]]
    for q in ("dp", "dg", "hpu"):
        print(f"\n{q}: rms z (share within one error) per case, at lattice-phase terms c h")
        print("| case | n | std / h | " + " | ".join(f"c = {c:g}" for c in TERMS) + " |")
        print("|---" * (3 + len(TERMS)) + "|")
        pooled = {c: [] for c in TERMS}
        for case in cases:
            runs = case["runs"]
            if not all(f"{q}_standard_error" in r for r in runs):
                continue
            h = case["h_um"] * 1e-6
            v = np.array([r[q] for r in runs])
            jack = np.array([jackknife_part(r, q) for r in runs])
            n = v.size
            dev = (v - v.mean()) * np.sqrt(n / (n - 1))
            cells = []
            for c in TERMS:
                err = np.hypot(jack, c * h)
                rms = rms_z(v, err)
                if rms is None:
                    cells.append("-")
                    continue
                z = dev / err  # for the pooled rms and the share within one error
                pooled[c].extend(z)
                cells.append(f"{rms:.2f} ({np.mean(np.abs(z) <= 1):.0%})")
            name = f"{case['scene']} {case['h_um']:g} µm"
            print(f"| {name} | {n} | {v.std(ddof=1) / h:.3f} | " + " | ".join(cells) + " |")
        print("| all | | | " + " | ".join(
            f"{np.sqrt(np.mean(np.square(z))):.2f} ({np.mean(np.abs(np.array(z)) <= 1):.0%})" if z else "-"
            for z in pooled.values()) + " |")


if __name__ == "__main__":
    main()
