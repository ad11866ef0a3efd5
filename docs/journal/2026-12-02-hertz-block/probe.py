"""Hertz force against the block's size: is the finite, clamped block the Hertz 'error' that does not shrink with h?

Run from the repository root: python docs/journal/2026-12-02-hertz-block/probe.py --cases grid:10:2:240 ...
Each case is contact:h_um:depth_um:domain_um[:sweeps] (sweeps only for the particle contact; default the
solver's 4). One JSON line per case to --out (appended) and to stdout.
"""

import argparse
import json
import math

import numpy as np

from plough.mpm import contact, solver
from plough.mpm.indentation import R_M, hertz_force, hertz_scene

orig = contact.particle_contact
SWEEPS = [None]


def wrapped(P, G, S, Z, law, step, dt, lp, out):
    if SWEEPS[0] is not None:
        law = law._replace(sweeps=SWEEPS[0])
    return orig(P, G, S, Z, law, step, dt, lp, out)


contact.particle_contact = wrapped
ap = argparse.ArgumentParser()
ap.add_argument("--cases", nargs="+", required=True)
ap.add_argument("--out", default=None)
ap.add_argument("--series", default=None, help="save each case's force series (N, per step) to this .npz")
ap.add_argument("--crossings", type=float, default=8.0,
                help="settle for this many times the steps a wave takes to cross the block's radius (CFL dx per step)")
args = ap.parse_args()
SERIES = {}
for case in args.cases:
    parts = case.split(":")
    mode, h, d, L = parts[0], float(parts[1]), float(parts[2]), float(parts[3])
    SWEEPS[0] = int(parts[4]) if len(parts) > 4 else None
    state, const = solver.init(hertz_scene(h, d, domain_um=L, contact_mode=mode))
    state.sphere.centre[0] = L * 1e-6  # the middle of the block (length 2 L)
    # a wave crosses the block's radius L in L / (cfl dx) steps (dt = cfl dx / c); the slowest mode's period is
    # about four crossings: settle for --crossings of them and average over the last four (one period)
    crossing = L / (0.3 * 2 * h)
    state.sphere.settle_left = int(args.crossings * crossing)
    window = int(4 * crossing)
    fz, closest = [], np.inf
    while state.sphere.phase != "slide":
        solver.step(state, const)
        out = state.work.contact_out
        fz.append(const.symmetry_factor * (out[contact.OUT_FN + 2] + out[contact.OUT_FT + 2]))
        closest = min(closest, -float(state.work.acc[:, solver.transfers.ACC_PENETRATION].max()))
    fz = np.array(fz)
    SERIES[case] = fz
    force, previous = fz[-window:].mean(), fz[-2 * window:-window].mean()
    ref = hertz_force(d * 1e-6)
    a = math.sqrt(R_M * d * 1e-6)
    row = {"case": case, "contact": mode, "h_um": h, "depth_um": d, "domain_um": L, "sweeps": SWEEPS[0],
           "a_over_L": a / (L * 1e-6), "force_N": force, "hertz_N": ref, "error": force / ref - 1.0,
           "error_previous_window": previous / ref - 1.0, "force_std_rel": fz[-window:].std() / force,
           "particles": int(state.particles.n), "steps": state.step, "window_steps": window,
           "closest_centre_h": closest / (h * 1e-6)}
    line = json.dumps(row)
    print(line, flush=True)
    if args.out:
        with open(args.out, "a") as f:
            f.write(line + "\n")
    if args.series:
        np.savez(args.series, **{k.replace(":", "_").replace(".", "p"): v for k, v in SERIES.items()})
