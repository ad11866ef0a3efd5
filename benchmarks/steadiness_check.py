"""Does the results' steadiness check (plough.mpm.io.steadiness) tell steady runs from changing ones?

    python benchmarks/steadiness_check.py [--sizes-um 10 5]

Runs the reference scenes as the workflow does (block sized from the expected contact, graded
particles with fine zone 1.5 contact radii, 2 threads): the uncoated one (examples/
uncoated_rigid_plastic.yaml, f = 1), the coated one (examples/coated_rigid_plastic.yaml, f = 1) and
the coated one at f = 0.5, and records mu, mu_drift (mu over the window's second half against its
first), material_top_rise (the highest particle's rise between the halves) and the flag ``steady``
(|mu_drift| <= 5%, |rise| <= 2 particle sizes). The runs at h = 2.5 um, whose
prow grows, stop before they write a result (README, Status); their prow records
(benchmarks/results/prow_*.json) give material_top_rise over the part of the window they reached.
Writes benchmarks/results/steadiness_check.json.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numba
import numpy as np
from common import run_scene

from plough.io import git_commit
from plough.materials import ProportionalShear
from plough.mpm import io
from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "steadiness_check.json"
PROW_RECORDS = {"uncoated f 1 h 2.5 (stopped at 526 um)": "prow_uncoated_h2.5.json",
                "coated f 0.5 h 2.5 (stopped at 317 um)": "prow_coated_f0.5_h2.5.json"}


def scenes(h_um: float) -> dict[str, Scene]:
    """The three reference scenes at particle size ``h_um``, as the workflow runs them."""
    out = {}
    for label, example, f in (("uncoated f 1", "uncoated_rigid_plastic.yaml", None),
                              ("coated f 1", "coated_rigid_plastic.yaml", None),
                              ("coated f 0.5", "coated_rigid_plastic.yaml", 0.5)):
        base = Scene.from_yaml(ROOT / "examples" / example)
        disc = replace(base.discretisation, particle_size_m=h_um * 1e-6, graded=True, fine_zone_contact_radii=1.5)
        scene = replace(base, discretisation=disc).with_sized_domain()
        if f is not None:
            scene = replace(scene, interface=ProportionalShear(f=f))
        out[f"{label} h {h_um:g}"] = scene
    return out


def prow_rise(path: Path, window_start_fraction: float = 0.5, distance_um: float = 600.0) -> dict:
    """material_top_rise over the part of the steady window a stopped prow probe reached."""
    rec = [r for r in json.loads(path.read_text())["records"] if r["slid_um"] >= window_start_fraction * distance_um]
    if len(rec) < 2:
        return {"records_in_window": len(rec)}
    top = np.array([r["top_um"] for r in rec]) * 1e-6
    half = top.size // 2
    return {"records_in_window": len(rec), "window_reached_um": [rec[0]["slid_um"], rec[-1]["slid_um"]],
            "material_top_rise": float(top[half:].mean() - top[:half].mean())}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes-um", type=float, nargs="+", default=[10.0, 5.0])
    parser.add_argument("--threads", type=int, default=2)
    args = parser.parse_args()
    numba.set_num_threads(args.threads)
    data = {"git_commit": git_commit(), "limits": {"mu_drift": io.STEADY_MU_DRIFT,
                                                   "material_top_rise_particles": io.STEADY_TOP_RISE_PARTICLES},
            "runs": {}, "prow_records": {}}
    for label, name in PROW_RECORDS.items():
        data["prow_records"][label] = prow_rise(ROOT / "benchmarks" / "results" / name)
    for h in args.sizes_um:
        for label, scene in scenes(h).items():
            row = run_scene(scene, args.threads)
            row["material_top_rise_particles"] = row["material_top_rise"] / scene.discretisation.particle_size_m
            data["runs"][label] = row
            OUT.write_text(json.dumps(data, indent=1) + "\n")
            print(f"{label:22s} mu {row['mu']:.3f} mu_drift {row['mu_drift']:+.3f} top rise "
                  f"{row['material_top_rise'] * 1e6:+.2f} um ({row['material_top_rise_particles']:+.2f} h) "
                  f"steady {int(row['steady'])} ({row['wall_s']:.0f} s)", flush=True)
    OUT.write_text(json.dumps(data, indent=1) + "\n")


if __name__ == "__main__":
    main()
