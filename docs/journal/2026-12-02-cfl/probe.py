"""What a larger time step costs in accuracy: the workflow's scenes at CFL 0.3 / 0.45 / 0.6, each at a few
lattice phases (journal 2026-12-02-cfl.md).

    python docs/journal/2026-12-02-cfl/probe.py --cases uncoated:10:1 coated:10:1 coated:10:0.5 uncoated:10:0.5 \
        real:20 --cfl 0.15 0.3 0.45 0.6 --phases 3 --out docs/journal/2026-12-02-cfl/cfl.json

A case is scene:h_um[:f] (``common.EXAMPLES``; f overrides the proportional interface's f). Each run uses the
workflow's numerics (``common.workflow_scene`` with the fine zone as deep as config/config.yaml makes it) and
shifts the start against the particle lattice by phi h as ``benchmarks/lattice_phase.py`` does. Every run is
written to ``--out`` as it finishes (resumable: runs already there are skipped).
"""

from __future__ import annotations

import argparse
import json
import sys
import time
import warnings
from dataclasses import replace
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "benchmarks"))

from common import EXAMPLES  # noqa: E402

from plough.io import git_commit  # noqa: E402
from plough.mpm.run import simulate  # noqa: E402
from plough.mpm.scene import Scene  # noqa: E402

KEEP = ("mu", "mu_standard_error", "mu_pl", "mu_sh", "dp", "dp_standard_error", "Fz_mean", "mu_drift", "steady")
ENERGY = ("plastic_work", "elastic_energy", "kinetic_energy", "interface_dissipation", "contact_impact_loss",
          "frozen_kinetic_loss")


def scene_of(case: str, cfl: float, phase: float) -> Scene:
    parts = case.split(":")
    name, h = parts[0], float(parts[1]) * 1e-6
    base = Scene.from_yaml(ROOT / "examples" / EXAMPLES[name])
    if len(parts) > 2:
        base = replace(base, interface=replace(base.interface, f=float(parts[2])))
    # common.workflow_scene's numerics with config/config.yaml's fine-zone depth
    disc = replace(base.discretisation, particle_size_m=h, graded=True, fine_zone_contact_radii=1.5,
                   fine_zone_depth_particles=6.0, active_zone_contact_radii=4.0, cfl=cfl)
    base = replace(base, discretisation=disc).with_sized_domain()
    return replace(base, domain=replace(base.domain, length_m=base.domain.length_m + 2.0 * phase * h))


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--cases", nargs="+", required=True)
    ap.add_argument("--cfl", type=float, nargs="+", default=[0.3, 0.45, 0.6])
    ap.add_argument("--phases", type=int, default=3)
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", type=Path, required=True)
    a = ap.parse_args()
    data = json.loads(a.out.read_text()) if a.out.exists() else {"commit": git_commit(), "runs": []}
    done = {(r["case"], r["cfl"], r["phase"]) for r in data["runs"]}
    for case in a.cases:
        for k in range(a.phases):
            for cfl in a.cfl:
                phase = k / a.phases
                if (case, cfl, phase) in done:
                    continue
                scene = scene_of(case, cfl, phase)
                t0 = time.perf_counter()
                with warnings.catch_warnings():
                    warnings.simplefilter("ignore")
                    ds = simulate(scene, progress=False, threads=a.threads)
                row = {"case": case, "cfl": cfl, "phase": phase, "wall_s": time.perf_counter() - t0,
                       "steps": int(ds.attrs["cost_steps"]), "particle_steps": float(ds.attrs["cost_particle_steps"]),
                       "load_N": scene.load_N}
                row.update({q: float(ds[q]) for q in KEEP})
                work = float(ds["external_work"][-1])
                row["energy_ratio"] = sum(float(ds[q][-1]) for q in ENERGY) / work
                row["Fz_over_load"] = row["Fz_mean"] / scene.load_N
                data["runs"].append(row)
                a.out.write_text(json.dumps(data, indent=1))
                print(f"{case} cfl {cfl} phase {phase:.2f}: mu {row['mu']:.4f} dp {row['dp'] * 1e6:.2f} um "
                      f"Fz/load {row['Fz_over_load']:.3f} energy {row['energy_ratio']:.3f} "
                      f"steps {row['steps']} {row['wall_s']:.0f} s", flush=True)


if __name__ == "__main__":
    main()
