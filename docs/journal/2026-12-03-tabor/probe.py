"""Why is Tabor's mean pressure low? The sphere held 8 um deep in the rigid-plastic block, with one setting
changed at a time; the full force history is kept so the relaxation under the held depth can be seen.

Run from the repository root:
    python docs/journal/2026-12-03-tabor/probe.py --case NAME:H_UM[:KEY=VALUE ...] ... --out FILE.jsonl
KEYs: ms (mass scaling), flip, cfl, press (press speed fraction of 0.1 m/s; default 0.25, the scenes'), settle
(shear-wave crossings held), L (block radius, um), depth (um), contact, dil (dilatation), ppc (particles per cell).
"""

from __future__ import annotations

import argparse
import json
import math
from dataclasses import replace

from plough.mpm.indentation import (
    TABOR_HARDNESS_PA,
    contact_radius_from_particles,
    crossing_steps,
    hold_at_depth,
    section_radius,
    tabor_scene,
)


def run(spec: str) -> dict:
    name, h, *kv = spec.split(":")
    opts = dict(item.split("=") for item in kv)
    depth = float(opts.get("depth", 8.0))
    scene = tabor_scene(float(h), depth, domain_um=float(opts.get("L", 240.0)),
                        contact_mode=opts.get("contact", "grid"), particles_per_cell=int(opts.get("ppc", 2)))
    d = scene.discretisation
    d = replace(d, mass_scaling=float(opts.get("ms", d.mass_scaling)), flip=float(opts.get("flip", d.flip)),
                cfl=float(opts.get("cfl", d.cfl)), dilatation=opts.get("dil", d.dilatation))
    s = replace(scene.sliding, press_speed_fraction=float(opts.get("press", 0.25)))  # the scenes' default press
    scene = replace(scene, discretisation=d, sliding=s)
    r = hold_at_depth(scene, settle_crossings=float(opts.get("settle", 12.0)))
    fz, press_steps, crossing = r.forces_N, r.press_steps, crossing_steps(scene, r.const.dt)
    sigma_y = TABOR_HARDNESS_PA / 3.0
    a_c = contact_radius_from_particles(r.state, r.const)
    a_sec = section_radius(depth * 1e-6)
    # the held force in windows of one crossing after the press, to see the relaxation
    held = fz[press_steps:]
    series = [float(held[i:i + crossing].mean()) for i in range(0, held.size - crossing + 1, crossing)]
    pressure = -r.state.particles.stress[:, :3].sum(axis=1) / 3.0
    return {"case": spec, "h_um": float(h), "dt_s": r.const.dt, "crossing_steps": crossing,
            "press_steps": press_steps, "steps": r.steps, "wall_s": r.wall_s, "force_N": r.force_N,
            "drift": r.force_drift, "a_c_um": a_c * 1e6,
            "p_true_over_sigma_y": r.force_N / (math.pi * a_c**2) / sigma_y,
            "p_section_over_sigma_y": r.force_N / (math.pi * a_sec**2) / sigma_y,
            "force_at_press_end_N": float(fz[press_steps - 1]), "held_by_crossing_N": series,
            "max_pressure_over_sigma_y": float(pressure.max() / sigma_y)}


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--case", nargs="+", required=True)
    ap.add_argument("--out", required=True)
    args = ap.parse_args()
    for spec in args.case:
        row = run(spec)
        print(json.dumps({k: v for k, v in row.items() if k != "held_by_crossing_N"}), flush=True)
        with open(args.out, "a") as f:
            f.write(json.dumps(row) + "\n")


if __name__ == "__main__":
    main()
