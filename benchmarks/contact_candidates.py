"""The contact candidates of issue 32 side by side (docs/journal/2026-12-02-contact-candidates.md).

Each case runs every contact named by ``--contact`` (``discretisation.contact``: grid, particle) and records the
error against its reference, the wall time, the closest a particle centre came to the sphere's surface (in h;
negative: inside) and, for the ploughing scenes, the energy balance:

- ``hertz``: the sphere held 2 and 8 um deep in an elastic block (the verification tests' set-up,
  :mod:`plough.mpm.indentation`), the force against Hertz's closed form; with two or more ``--domains-um`` also
  the half-space's force extrapolated in 1 / L (``indentation.half_space_force``: the block is clamped on its
  curved face, which stiffens it), a row per block (case ``hertz:hH:dD:LL``; the checks' 240 um block keeps
  ``hertz:hH:dD``) and one for the half-space (``hertz:hH:dD:L-inf-L1-L2...``, ``stiffening_um`` = A);
- ``tabor``: held 8 um deep in the uncoated rigid-plastic material (sigma_y = 300 MPa, E = 210 GPa, fully plastic:
  E a / (sigma_y R) ~ 200), the mean pressure Fz / (pi a_c^2) over the true contact (a_c where the particles'
  faces leave the sphere, pile-up included) against Tabor's 2.8-3.0 sigma_y; also with the contact's own area;
- ``plough``: the reference ploughing scenes (``benchmarks/common.py``: uncoated, coated) with the workflow's
  numerics at an interface factor f, mu against the analytical mu (mu_pl at f = 0).

Run the pieces separately (each merges its rows into the one results file, keyed by case and contact):

    python benchmarks/contact_candidates.py hertz --sizes-um 10 5 --depths-um 2 8
    python benchmarks/contact_candidates.py hertz --sizes-um 10 --depths-um 2 8 --domains-um 240 480 720 --contact grid
    python benchmarks/contact_candidates.py tabor --sizes-um 10 --depths-um 8
    python benchmarks/contact_candidates.py plough --scene uncoated coated --f 0 --sizes-um 10
    python benchmarks/contact_candidates.py plough --scene uncoated coated --f 0.5 1 --sizes-um 20 10
"""

from __future__ import annotations

import argparse
import inspect
import json
import math
import time
from collections.abc import Sequence
from dataclasses import replace
from pathlib import Path

import common
import numba
import numpy as np

from plough import __version__
from plough.analytical import ploughing
from plough.io import git_commit
from plough.materials import ProportionalShear
from plough.mpm.indentation import (
    PLASTIC_SETTLE_CROSSINGS,
    TABOR_HARDNESS_PA,
    Indentation,
    contact_radius_from_particles,
    half_space_extrapolation,
    hertz_force,
    hertz_scene,
    hold_at_depth,
    section_radius,
    tabor_scene,
)
from plough.mpm.io import energy_balance
from plough.mpm.run import warm_up

OUT = common.ROOT / "benchmarks" / "results" / "contact_candidates.json"
CHECK_BLOCK_UM = inspect.signature(hertz_scene).parameters["domain_um"].default  # the verification checks' block


def _hertz_row(h_um: float, depth_um: float, mode: str, domains_um: Sequence[float], force_N: float,
               run: Indentation | None) -> dict:
    """A result row: one block (``domains_um`` of one radius, ``run`` its hold) or the half-space fitted through
    several (``run`` None); the checks' 240 um block keeps the case key it had before the blocks were varied."""
    ref = hertz_force(depth_um * 1e-6)
    if run is None:
        block = ":L-inf-" + "-".join(f"{L:g}" for L in domains_um)
    else:
        block = "" if domains_um[0] == CHECK_BLOCK_UM else f":L{domains_um[0]:g}"
    row = {"case": f"hertz:h{h_um:g}:d{depth_um:g}{block}", "contact": mode, "h_um": h_um, "depth_um": depth_um,
           "domains_um": list(domains_um), "force_N": force_N, "hertz_N": ref, "error": force_N / ref - 1.0}
    if run is not None:
        row.update({"force_std_rel": run.force_std_N / run.force_N, "force_drift": run.force_drift,
                    "steps": run.steps, "wall_s": run.wall_s, "particles": run.state.particles.n,
                    "closest_centre_h": run.closest_centre_m / (h_um * 1e-6),
                    "plastic": bool(run.state.particles.eps_p.max() > 0.0)})
    where = "half-space (1 / L)" if run is None else f"L={domains_um[0]:g}"
    print(f"hertz h={h_um:g} d={depth_um:g} {where} {mode:8s} F={force_N:.4g} N err={row['error']:+.3f}"
          + ("" if run is None else f" drift={run.force_drift:+.4f} wall={run.wall_s:.1f}s "
                                    f"closest={row['closest_centre_h']:.3f} h"), flush=True)
    return row


def hertz(args) -> list[dict]:
    rows = []
    for h in args.sizes_um:
        for d in args.depths_um:
            for mode in args.contact:
                runs = [hold_at_depth(hertz_scene(h, d, domain_um=L, contact_mode=mode)) for L in args.domains_um]
                for L, run in zip(args.domains_um, runs, strict=True):
                    rows.append(_hertz_row(h, d, mode, [L], run.force_N, run))
                if len(set(args.domains_um)) > 1:
                    f_inf, stiffening = half_space_extrapolation([L * 1e-6 for L in args.domains_um],
                                                                 [run.force_N for run in runs])
                    row = _hertz_row(h, d, mode, args.domains_um, f_inf, None)
                    row["stiffening_um"] = stiffening * 1e6
                    rows.append(row)
    return rows


def tabor(args) -> list[dict]:
    rows = []
    sigma_y = TABOR_HARDNESS_PA / 3.0
    for h in args.sizes_um:
        for d in args.depths_um:
            for mode in args.contact:
                run = hold_at_depth(tabor_scene(h, d, contact_mode=mode), settle_crossings=PLASTIC_SETTLE_CROSSINGS)
                a_c = contact_radius_from_particles(run.state, run.const)
                a_geo = section_radius(d * 1e-6)
                row = {"case": f"tabor:h{h:g}:d{d:g}", "contact": mode, "h_um": h, "depth_um": d,
                       "force_N": run.force_N, "a_c_um": a_c * 1e6, "a_geometric_um": a_geo * 1e6,
                       "p_over_sigma_y": run.force_N / (math.pi * a_c**2) / sigma_y,
                       "p_over_sigma_y_own_area": (run.force_N / run.contact_area_xy_m2 / sigma_y
                                                   if run.contact_area_xy_m2 > 0 else float("nan")),
                       "contact_area_xy_um2": run.contact_area_xy_m2 * 1e12, "steps": run.steps,
                       "wall_s": run.wall_s, "particles": run.state.particles.n,
                       "closest_centre_h": run.closest_centre_m / (h * 1e-6)}
                print(f"tabor h={h:g} d={d:g} {mode:8s} F={run.force_N:.4g} N a_c={a_c * 1e6:.1f} um "
                      f"(geometric {a_geo * 1e6:.1f}) p/sy={row['p_over_sigma_y']:.3f} "
                      f"(own area {row['p_over_sigma_y_own_area']:.3f}) wall={run.wall_s:.1f}s "
                      f"closest={row['closest_centre_h']:.3f} h", flush=True)
                rows.append(row)
    return rows


def plough(args) -> list[dict]:
    from plough.mpm.run import simulate

    rows = []
    for name in args.scene:
        for f in args.f:
            for h in args.sizes_um:
                for mode in args.contact:
                    scene = common.workflow_scene(name, h * 1e-6)
                    scene = replace(scene, interface=ProportionalShear(f=f),
                                    discretisation=replace(scene.discretisation, contact=mode))
                    base = scene.layers
                    Hs = 3.0 * base.substrate.flow.sigma_y_Pa
                    Hc = 3.0 * base.coating.flow.sigma_y_Pa if base.coated else Hs
                    ana = ploughing(scene.load_N, scene.sphere.radius_m, base.coating_thickness_m, Hc, Hs,
                                    k1=args.k1, f=f)
                    t0 = time.perf_counter()
                    ds = simulate(scene, progress=False, threads=args.threads)
                    wall = time.perf_counter() - t0
                    n_rec = len(ds.contact_area_xy)  # the contact's own area, mean over the second half
                    row = {"case": f"plough:{name}:f{f:g}:h{h:g}", "contact": mode, "scene": name, "f": f,
                           "h_um": h, **{q: float(ds[q]) for q in common.RESULTS},
                           "analytical_mu": float(ana.mu), "analytical_mu_pl": float(ana.mu_pl),
                           "analytical_dp_um": float(ana.dp) * 1e6, "analytical_mu_sh": float(ana.mu_sh),
                           "analytical_Axy_um2": float(ana.Axy) * 1e12,
                           "contact_area_xy_um2": float(ds.contact_area_xy[n_rec // 2:].mean()) * 1e12,
                           "mu_error": float(ds.mu) / float(ana.mu) - 1.0,
                           "energy_parts_over_work": energy_balance(ds),
                           "closest_centre_h": -float(ds.max_particle_penetration) / (h * 1e-6),
                           "steady": float(ds.steady), "wall_s": wall, "steps": int(ds.attrs["cost_steps"]),
                           "particles": int(ds.attrs["cost_particles"])}
                    print(f"plough {name} f={f:g} h={h:g} {mode:8s} mu={row['mu']:.4f} (analytical "
                          f"{row['analytical_mu']:.4f}, err {row['mu_error']:+.3f}) mu_pl={row['mu_pl']:.4f} "
                          f"(ana {row['analytical_mu_pl']:.4f}) mu_sh={row['mu_sh']:.4f} (ana "
                          f"{row['analytical_mu_sh']:.4f}) area_xy={row['contact_area_xy_um2']:.0f} um2 (ana Axy "
                          f"{row['analytical_Axy_um2']:.0f}) "
                          f"dp={row['dp'] * 1e6:.2f} um (ana {row['analytical_dp_um']:.2f}) energy "
                          f"{row['energy_parts_over_work']:.3f} closest={row['closest_centre_h']:.3f} h "
                          f"wall={wall:.1f}s", flush=True)
                    rows.append(row)
    return rows


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("case", choices=["hertz", "tabor", "plough"])
    parser.add_argument("--contact", nargs="+", default=["grid_local", "grid"])
    parser.add_argument("--sizes-um", type=float, nargs="+", default=[10.0])
    parser.add_argument("--depths-um", type=float, nargs="+", default=[2.0, 8.0])
    parser.add_argument("--domains-um", type=float, nargs="+", default=[CHECK_BLOCK_UM],
                        help="hertz: block radii; two or more add the half-space extrapolated in 1 / L")
    parser.add_argument("--scene", nargs="+", default=["uncoated", "coated"], choices=sorted(common.EXAMPLES))
    parser.add_argument("--f", type=float, nargs="+", default=[0.0])
    parser.add_argument("--k1", type=float, default=125.0, help="analytical model's k1 (coated scenes)")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--out", default=str(OUT))
    args = parser.parse_args()
    numba.set_num_threads(args.threads)
    t0 = time.perf_counter()
    warm_up(args.threads)
    for mode in args.contact:  # each contact's kernels (warm_up runs the default one)
        hold_at_depth(hertz_scene(20.0, 1.0, domain_um=80.0, contact_mode=mode))
    print(f"warm-up (compilation, not timed below): {time.perf_counter() - t0:.1f} s", flush=True)
    rows = {"hertz": hertz, "tabor": tabor, "plough": plough}[args.case](args)
    out = Path(args.out)
    old = json.loads(out.read_text()) if out.exists() else {"runs": []}
    keep = [r for r in old["runs"] if (r["case"], r["contact"]) not in {(n["case"], n["contact"]) for n in rows}]
    runs = sorted(keep + [dict(r, git_commit=git_commit(), plough_version=__version__, threads=args.threads)
                          for r in rows], key=lambda r: (r["case"], r["contact"]))
    out.parent.mkdir(parents=True, exist_ok=True)
    out.write_text(json.dumps({"note": "rows of benchmarks/contact_candidates.py, merged run by run", "runs": runs},
                              indent=2, default=lambda o: float(o) if isinstance(o, np.floating) else str(o)))


if __name__ == "__main__":
    main()
