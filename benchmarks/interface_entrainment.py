"""How far the sphere drags the coating's surface forward, against the interface strength and the inertia.

    python benchmarks/interface_entrainment.py [--h-um 20]

Coated rigid-plastic scene (examples/coated_rigid_plastic.yaml, sized block, 2 threads) at
interface strength f = 0, 0.5, 1 (tau = f kappa, kappa the coating's shear strength) and mass
scaling 1e6 and 1e6 / 16 (≡ speed / 4). After the slide, the particles that started within
0.02 mm of the track's centre line, past the first 0.3 mm of the slide and now half a sphere
radius or more behind the sphere, are grouped by their initial layer (one particle size each from
the top); the script reports their mean displacement (x along the slide, z up) and plastic strain.
An interface that slips leaves the surface where the ploughing put it; one as strong as the
coating (f = 1) can shear the coating just below instead, and how far it drags the surface then
has no quasi-static answer in a perfectly plastic coating. Writes
benchmarks/results/interface_entrainment.json.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numba
import numpy as np
from common import coated_reference

from plough.materials import ProportionalShear
from plough.mpm import solver
from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "interface_entrainment.json"
LAYERS = 3


def entrainment(scene: Scene) -> dict[str, list[float]]:
    """Run ``scene``; mean displacement (m) and plastic strain of the track's top layers left behind."""
    state, const = solver.init(scene)
    x_start = state.particles.x.copy()
    while state.sphere.phase != "done":
        solver.step(state, const)
    p, h = state.particles, scene.discretisation.particle_size_m
    behind = p.x[:, 0] < state.sphere.centre[0] - 0.5 * const.sphere_radius
    track = (x_start[:, 0] > scene.start_x_m + 0.3e-3) & (np.abs(x_start[:, 1]) < 0.02e-3) & behind
    rows: dict[str, list[float]] = {"dx_m": [], "dz_m": [], "eps_p": [], "count": []}
    for k in range(LAYERS):
        layer = track & (p.z0 > -(k + 1) * h) & (p.z0 <= -k * h)
        d = p.x[layer] - x_start[layer]
        rows["dx_m"].append(float(d[:, 0].mean()))
        rows["dz_m"].append(float(d[:, 2].mean()))
        rows["eps_p"].append(float(p.eps_p[layer].mean()))
        rows["count"].append(int(layer.sum()))
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--h-um", type=float, default=20.0)
    args = parser.parse_args()
    numba.set_num_threads(2)
    base = coated_reference(args.h_um)
    ms = base.discretisation.mass_scaling
    runs = {}
    print(f"{'f':>4s} {'ms':>8s} " + " ".join(f"{'dx' + str(k + 1) + ' um':>8s}" for k in range(LAYERS))
          + " " + " ".join(f"{'eps_p' + str(k + 1):>7s}" for k in range(LAYERS)))
    for f in (0.0, 0.5, 1.0):
        for k in (1.0, 1 / 16):
            scene = replace(base, interface=ProportionalShear(f=f),
                            discretisation=replace(base.discretisation, mass_scaling=ms * k))
            r = entrainment(scene)
            runs[f"f {f:g} ms {ms * k:g}"] = {"f": f, "mass_scaling": ms * k, **r}
            print(f"{f:4.1f} {ms * k:8.3g} " + " ".join(f"{v * 1e6:8.2f}" for v in r["dx_m"]) + " "
                  + " ".join(f"{v:7.3f}" for v in r["eps_p"]), flush=True)
    OUT.write_text(json.dumps({"h_um": args.h_um, "layers_from_top": LAYERS, "runs": runs}, indent=2) + "\n")


if __name__ == "__main__":
    main()
