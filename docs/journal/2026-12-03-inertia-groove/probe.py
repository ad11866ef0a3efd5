"""Does the groove follow the paper's inertia? The workflow's scenes with the mass scaling divided by 4, 16, 64
(speed x sqrt(mass scaling) from 100 to 12.5 m/s), each at a few lattice phases (journal 2026-12-03-inertia-groove.md).

    python docs/journal/2026-12-03-inertia-groove/probe.py --cases coated:10:0.5 uncoated:10:0.5 \
        --ms-factors 1 0.25 0.0625 0.015625 --phases 2 --out docs/journal/2026-12-03-inertia-groove/ladder.json

A case is scene:h_um[:f] as in docs/journal/2026-12-02-cfl/probe.py (the workflow's numerics, the start shifted
by phi h against the lattice). Every run is written to ``--out`` as it finishes (resumable).
"""

from __future__ import annotations

import argparse
import importlib.util
import json
import time
import warnings
from dataclasses import replace
from pathlib import Path

from plough.io import git_commit
from plough.mpm.run import simulate

ROOT = Path(__file__).resolve().parents[3]
# the CFL probe's scenes (the workflow's numerics, shifted by a lattice phase), loaded by path: both are probe.py
_spec = importlib.util.spec_from_file_location("cfl_probe", ROOT / "docs" / "journal" / "2026-12-02-cfl" / "probe.py")
cfl_probe = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(cfl_probe)
ENERGY, KEEP, scene_of = cfl_probe.ENERGY, cfl_probe.KEEP, cfl_probe.scene_of


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", nargs="+", required=True)
    ap.add_argument("--ms-factors", type=float, nargs="+", default=[1.0, 0.25, 0.0625, 0.015625])
    ap.add_argument("--phases", type=int, default=2)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", type=Path, required=True)
    a = ap.parse_args()
    data = json.loads(a.out.read_text()) if a.out.exists() else {"commit": git_commit(), "runs": []}
    done = {(r["case"], r["ms_factor"], r["phase"]) for r in data["runs"]}
    for case in a.cases:
        for k in range(a.phases):
            for factor in a.ms_factors:
                phase = k / a.phases
                if (case, factor, phase) in done:
                    continue
                scene = scene_of(case, 0.3, phase)
                disc = scene.discretisation
                scene = replace(scene, discretisation=replace(disc, mass_scaling=disc.mass_scaling * factor))
                t0 = time.perf_counter()
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    ds = simulate(scene, progress=False, threads=a.threads)
                row = {"case": case, "ms_factor": factor, "mass_scaling": scene.discretisation.mass_scaling,
                       "phase": phase, "wall_s": time.perf_counter() - t0, "steps": int(ds.attrs["cost_steps"]),
                       "load_N": scene.load_N}
                row.update({q: float(ds[q]) for q in KEEP + ("dg", "hpu")})
                work = float(ds["external_work"][-1])
                row["energy_ratio"] = sum(float(ds[q][-1]) for q in ENERGY) / work
                data["runs"].append(row)
                a.out.write_text(json.dumps(data, indent=1))
                print(f"{case} ms x {factor:g} phase {phase:.2f}: mu {row['mu']:.4f} dp {row['dp'] * 1e6:.2f} "
                      f"+- {row['dp_standard_error'] * 1e6:.2f} um steady {row['steady']:.0f} "
                      f"wall {row['wall_s']:.0f} s", flush=True)


if __name__ == "__main__":
    main()
