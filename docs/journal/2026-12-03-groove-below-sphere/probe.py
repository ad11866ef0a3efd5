"""Is the residual groove deeper than the loaded sphere because of the paper's inertia? The Fig. 14 scene (zinc-coated
steel, 1 mm ball, 22 N, the workflow's numerics of config/config.yaml) with the mass scaling divided by 4, 16, 64
(journal 2026-12-03-groove-below-sphere.md).

    python docs/journal/2026-12-03-groove-below-sphere/probe.py --h-um 20 --ms-factors 1 0.25 0.0625 0.015625 \
        --out docs/journal/2026-12-03-groove-below-sphere/h20.json

Each run is written to ``--out`` as it finishes (resumable): mu, the sphere's mean penetration under load over the
steady window, the residual profile (mean of the sections) and where it is deepest, dg / hpu / dp, the energy account.
"""

from __future__ import annotations

import argparse
import json
import time
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np
import yaml

from plough.io import git_commit
from plough.mpm.run import simulate
from plough.study import matrix

ROOT = Path(__file__).resolve().parents[3]
ENERGY = ("plastic_work", "elastic_energy", "kinetic_energy", "interface_dissipation", "contact_impact_loss",
          "frozen_kinetic_loss")


def fig14_scene(h_um: float):
    config = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    (point,) = matrix.figure_points(config, "fig14").values()
    return matrix.scene_for(point, h_um, config["mpm"]["numerics"])


def fig18_scene(thickness_um: float, h_um: float):
    """One of Fig. 18's scenes (22 N, 1 mm ball) as the workflow builds it; thickness 0 is the zinc block."""
    config = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())
    points = {round(p.thickness_m * 1e6): p for p in matrix.all_points(config, ("fig18",)).values()}
    return matrix.scene_for(points[round(thickness_um)], h_um, config["mpm"]["numerics"])


def run_quietly(scene, threads: int = 2):
    """The run's dataset, without the progress bar or the solver's warnings."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return simulate(scene, progress=False, threads=threads)


def measure(scene, threads: int = 2) -> dict:
    """Run ``scene`` and keep what this entry compares: mu and its parts, the penetration under load, the residual
    profile (mean of the sections) with its centre and where it is deepest within 1.5 expected contact radii, the
    groove's dg / hpu / dp, the energy account, the wall time."""
    t0 = time.perf_counter()
    ds = run_quietly(scene, threads)
    y, z = ds["y"].values, ds["profile_z"].values
    a_exp, _ = scene.expected_contact()
    near = np.abs(y) <= 1.5 * a_exp
    deepest = int(np.nanargmin(np.where(near, z, np.nan)))
    row = {"wall_s": time.perf_counter() - t0, "steps": int(ds.attrs["cost_steps"]),
           "expected_contact_radius_m": a_exp, "y_deepest_m": float(y[deepest]), "z_centre_m": float(z[0]),
           "profile_y_m": y.tolist(), "profile_z_m": [None if not np.isfinite(v) else float(v) for v in z]}
    row.update({q: float(ds[q]) for q in ("mu", "mu_pl", "mu_sh", "penetration", "dg", "hpu", "dp",
                                           "dp_standard_error", "max_particle_penetration", "mu_drift", "steady")})
    row["energy_ratio"] = sum(float(ds[q][-1]) for q in ENERGY) / float(ds["external_work"][-1])
    return row


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--h-um", type=float, required=True)
    ap.add_argument("--ms-factors", type=float, nargs="+", default=[1.0, 0.25, 0.0625, 0.015625])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--out", type=Path, required=True)
    a = ap.parse_args()
    data = json.loads(a.out.read_text()) if a.out.exists() else {"commit": git_commit(), "runs": []}
    done = {r["ms_factor"] for r in data["runs"]}
    for factor in a.ms_factors:
        if factor in done:
            continue
        scene = fig14_scene(a.h_um)
        disc = scene.discretisation
        scene = replace(scene, discretisation=replace(disc, mass_scaling=disc.mass_scaling * factor))
        row = {"h_um": a.h_um, "ms_factor": factor, "mass_scaling": disc.mass_scaling * factor,
               **measure(scene, a.threads)}
        data["runs"].append(row)
        a.out.write_text(json.dumps(data, indent=1))
        print(f"h {a.h_um:g} ms x {factor:g}: mu {row['mu']:.4f} penetration {row['penetration'] * 1e6:.2f} um "
              f"centre {-row['z_centre_m'] * 1e6:.2f} um deepest {row['dg'] * 1e6:.2f} um at y "
              f"{row['y_deepest_m'] * 1e6:.0f} um hpu {row['hpu'] * 1e6:.2f} energy {row['energy_ratio']:.3f} "
              f"steady {row['steady']:.0f} wall {row['wall_s']:.0f} s", flush=True)


if __name__ == "__main__":
    main()
