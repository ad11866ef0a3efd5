"""Stability stress matrix (issue 5): extreme numerical settings and scenes on a small
rigid-plastic scene (r = 0.2 mm, 1 N, h = 10 um, 0.2 mm slide, sized block).

    python benchmarks/stability_matrix.py [--active-zone 4 --out FILE]

Each case either completes — then mu, Fz/load, the deepest particle penetration into the sphere
(in units of h) and the energy ratio (sum of the energy terms / external work) are reported — or
stops with the solver's error, which is reported verbatim. ``--active-zone K`` runs every case
with ``discretisation.active_zone_contact_radii: K`` (the workflow uses 4). Writes
benchmarks/results/stability_matrix.json (or ``--out``) and prints a Markdown table.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numba
import yaml

from plough.mpm.io import energy_balance
from plough.mpm.run import simulate
from plough.mpm.scene import Scene
from plough.mpm.solver import SimulationError

ROOT = Path(__file__).resolve().parents[1]
BASE = yaml.safe_load((ROOT / "examples" / "stability_small.yaml").read_text())


def variant(**changes) -> dict:
    d = json.loads(json.dumps(BASE))
    for path, value in changes.items():
        *keys, last = path.split(".")
        node = d
        for k in keys:
            node = node[k]
        node[last] = value
    return d


CASES = {
    "defaults (cfl 0.3, ms 1e6)": variant(),
    "cfl 0.5 (the accepted maximum)": variant(**{"discretisation.cfl": 0.5}),
    "cfl 0.9 (refused)": variant(**{"discretisation.cfl": 0.9}),
    "mass scaling 1e4": variant(**{"discretisation.mass_scaling": 1e4}),
    "mass scaling 1e8": variant(**{"discretisation.mass_scaling": 1e8}),
    "mass scaling 1e9": variant(**{"discretisation.mass_scaling": 1e9}),
    "speed 1 m/s": variant(**{"sliding.speed_m_s": 1.0}),
    "H~ = 0.1 coating, t = 25 um, 0.3 mm slide": variant(**{
        "layers": {"coating_thickness_um": 25, "coating": {"rigid_plastic_hardness_MPa": 90},
                   "substrate": {"rigid_plastic_hardness_MPa": 900}}, "sliding.distance_um": 300}),
    "t = 200 um (bulk coating)": variant(**{"layers": {"coating_thickness_um": 200,
                                                         "coating": {"rigid_plastic_hardness_MPa": 450},
                                                         "substrate": {"rigid_plastic_hardness_MPa": 900}}}),
    "long slide 0.6 mm": variant(**{"sliding.distance_um": 600}),
}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--active-zone", type=float, default=None, help="active zone, expected contact radii")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "stability_matrix.json")
    args = parser.parse_args()
    numba.set_num_threads(2)
    rows = {}
    print("| case | outcome | mu | Fz / load | max particle penetration / h | energy terms / work |")
    print("|---|---|---|---|---|---|")
    for name, d in CASES.items():
        try:
            scene = Scene.from_dict(d).with_sized_domain()
            scene = replace(scene, discretisation=replace(scene.discretisation,
                                                          active_zone_contact_radii=args.active_zone))
            ds = simulate(scene, progress=False)
        except (ValueError, SimulationError) as exc:
            rows[name] = {"outcome": f"{type(exc).__name__}: {exc}"}
            print(f"| {name} | stopped: {exc} | | | | |", flush=True)
            continue
        h = scene.discretisation.particle_size_m
        ratio = energy_balance(ds)
        rows[name] = {"outcome": "completed", "mu": float(ds.mu), "Fz_over_load": float(ds.Fz_mean) / scene.load_N,
                      "max_penetration_over_h": float(ds.max_particle_penetration) / h, "energy_ratio": ratio}
        r = rows[name]
        print(f"| {name} | completed | {r['mu']:.3f} | {r['Fz_over_load']:.4f} | {r['max_penetration_over_h']:.3f} | "
              f"{ratio:.3f} |", flush=True)
    args.out.write_text(json.dumps(rows, indent=2) + "\n")


if __name__ == "__main__":
    main()
