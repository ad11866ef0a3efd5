"""One-off probe (docs/journal/2026-12-02-groove-estimator.md): run each case at N lattice phases, as
benchmarks/lattice_phase.py does, and keep each run's final particle state (x, vol0, J), the sphere's
final centre and the dataset's dp, so groove estimators can be compared offline on the same states.

    python docs/journal/2026-12-02-groove-estimator/collect.py coated:20 coated:10 uncoated:10 real:20 --phases 8
"""

from __future__ import annotations

import argparse
import sys
import time
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "benchmarks"))
from common import workflow_scene  # noqa: E402

import plough.mpm.io as pio  # noqa: E402
from plough.mpm.run import simulate  # noqa: E402

HERE = Path(__file__).resolve().parent


def phase_scene(name: str, h_um: float, k: int, phases: int):
    h = h_um * 1e-6
    base = workflow_scene(name, h)
    shift = k / phases * h
    return replace(base, domain=replace(base.domain, length_m=base.domain.length_m + 2.0 * shift))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("cases", nargs="+")
    ap.add_argument("--phases", type=int, default=8)
    a = ap.parse_args()
    kept = {}
    original = pio.build_dataset

    def keep(scene, series, slid_m, p, sphere_centre, *args, **kw):
        kept.update(x=p.x.copy(), vol0=p.vol0.copy(), J=p.J.copy(), centre=np.array(sphere_centre))
        return original(scene, series, slid_m, p, sphere_centre, *args, **kw)

    pio.build_dataset = keep
    for case in a.cases:
        name, h_um = case.split(":")
        for k in range(a.phases):
            scene = phase_scene(name, float(h_um), k, a.phases)
            t0 = time.perf_counter()
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                ds = simulate(scene, progress=False, threads=2)
            out = HERE / "states" / f"{name}_{h_um}_{k}of{a.phases}.npz"
            out.parent.mkdir(exist_ok=True)
            np.savez_compressed(out, **kept, dp=float(ds.dp), dg=float(ds.dg), hpu=float(ds.hpu),
                                dp_se=float(ds.get("dp_standard_error", np.nan)), mu=float(ds.mu))
            print(f"{case} phase {k}: dp {float(ds.dp) * 1e6:.2f} um, {time.perf_counter() - t0:.0f} s", flush=True)


if __name__ == "__main__":
    main()
