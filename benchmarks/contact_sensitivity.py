"""Where the interface shear of the coated reference scene comes from, and what it depends on.

    python benchmarks/contact_sensitivity.py [--h-um 10] [--only NAME ...]

Coated rigid-plastic scene (examples/coated_rigid_plastic.yaml: H~ = 0.5, t = 25 um, r = 0.2 mm,
3 N, f = 1), sized block, 2 threads. Three measurements, written to
benchmarks/results/contact_sensitivity.json (a case is run only when missing or named in --only):

1. Filter ladder: the time constant of the per-node contact-force filter
   (``plough.mpm.contact.FILTER_WAVE_TIMES``, in elastic-wave transits of a cell) at 5 / 10 / 20.
   A numerical parameter: mu_sh should not follow it.
2. Mass-scaling ladder: ms x 4, / 4, / 16 (mass scaling / k^2 is speed / k at k times the steps,
   benchmarks/timestep_check.py). "ms/4, filter 20" keeps the filter's sliding distance of the
   defaults (ms / 4 doubles the wave speed), separating inertia from the filter.
3. Contact-pressure probe at the defaults: over the last 0.1 mm of a 0.4 mm slide, the normal stress
   -n.sigma.n that the contact uses at each contact node (mass-weighted over the node's particles),
   against the hardness, and the share of the normal force on nodes whose shear area is capped at
   a cell face (``contact.contact_area``). P is reported before the solver's floor at kappa, from
   the particles' stress after the step (the contact used the stress before it: one step apart).
   Also the normal stress of the particles whose face lies within a fraction of h of the sphere
   ahead of its centre, in one snapshot at the end of the slide.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numba
import numpy as np

from plough.mpm import contact, solver
from plough.mpm.run import simulate
from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]
OUT = ROOT / "benchmarks" / "results" / "contact_sensitivity.json"
KEYS = ("mu", "mu_pl", "mu_sh", "dp", "penetration", "Fz_mean")


def run_case(scene: Scene, filter_wave_times: float) -> dict[str, float]:
    default = contact.FILTER_WAVE_TIMES
    contact.FILTER_WAVE_TIMES = filter_wave_times  # read by solver.init when it sets the filter weight
    try:
        ds = simulate(scene, progress=False, threads=2)
    finally:
        contact.FILTER_WAVE_TIMES = default
    row = {k: float(ds[k]) for k in KEYS}
    row.update(wall_s=float(ds.attrs["cost_wall_time_s"]), filter_wave_times=filter_wave_times,
               mass_scaling=scene.discretisation.mass_scaling, git_commit=str(ds.attrs.get("git_commit")))
    return row


def _normal_stress(sig: np.ndarray, n: np.ndarray) -> np.ndarray:
    """-n . sigma . n for Voigt stresses (xx yy zz yz xz xy), rows of n unit normals."""
    return -(n[:, 0] ** 2 * sig[:, 0] + n[:, 1] ** 2 * sig[:, 1] + n[:, 2] ** 2 * sig[:, 2]
             + 2.0 * (n[:, 1] * n[:, 2] * sig[:, 3] + n[:, 0] * n[:, 2] * sig[:, 4] + n[:, 0] * n[:, 1] * sig[:, 5]))


def pressure_probe(scene: Scene, slide_m: float = 400e-6, window_m: float = 100e-6, every: int = 50) -> dict:
    """Contact pressure seen by the interface-shear area A_i = min(F_n,i / P_i, face), sampled every
    ``every`` steps over the last ``window_m`` of a ``slide_m`` slide."""
    st, c = solver.init(scene)
    g = c.grid
    fn_all, p_all, kap_all, capped_all, nx_all = [], [], [], [], []
    while st.sphere.slid_m < slide_m:
        solver.step(st, c)
        if st.sphere.phase != "slide" or st.sphere.slid_m < slide_m - window_m or st.step % every:
            continue
        p, w = st.particles, st.work
        cb = np.zeros_like(w.cbuf)
        contact.scatter_contact_stress(p.x, p.stress, p.mass, p.vol0, p.J, p.eps_p, p.temperature, p.mat_a,
                                       p.mat_b, p.frac_a, c.table, p.near, g.origin, g.dx, c.shape, st.sphere.centre,
                                       c.sphere_radius, cb)
        nodes = np.nonzero(w.last_contact == st.step - 1)[0]  # in contact on the step just taken
        ny, nz = int(c.shape[1]), int(c.shape[2])
        ijk = np.stack([nodes // (ny * nz), (nodes // nz) % ny, nodes % nz], axis=1)
        rel = g.origin + ijk * g.dx - st.sphere.centre
        n = rel / np.linalg.norm(rel, axis=1)[:, None]
        wsum = np.where(cb[nodes, 7] > 0, cb[nodes, 7], 1.0)
        pres = _normal_stress(cb[nodes, :6] / wsum[:, None], n)
        kap = cb[nodes, 6] / wsum
        fn = w.fn_filtered[nodes]
        face = np.where(ijk[:, 1] == c.mirror_j0, 0.5, 1.0) * g.dx**2
        capped = fn / np.maximum(pres, kap) >= 0.999 * face
        samples = (fn, pres, kap, capped, n[:, 0])
        for acc, val in zip((fn_all, p_all, kap_all, capped_all, nx_all), samples, strict=True):
            acc.append(val)
    fn, pres, kap, capped, nx = (np.concatenate(a) for a in (fn_all, p_all, kap_all, capped_all, nx_all))
    hardness = 3.0 * scene.layers.coating.flow.sigma_y_Pa
    p = st.particles
    q = p.x - st.sphere.centre
    d = np.linalg.norm(q, axis=1)
    hp = (p.vol0 * p.J) ** (1.0 / 3.0)
    gap = d - c.sphere_radius - 0.5 * hp
    pn = _normal_stress(p.stress, q / d[:, None])
    touching = {}
    for frac in (0.1, 0.25, 0.5):
        sel = (gap < frac * hp) & (q[:, 2] < 0) & (q[:, 0] > 0)  # below the centre, ahead of it
        touching[f"gap<{frac}h"] = {"particles": int(sel.sum()),
                                    "median_normal_stress_over_H": float(np.median(pn[sel]) / hardness)}
    return {
        "coating_hardness_Pa": hardness,
        "contact_nodes_per_sample": len(fn) / max(len(fn_all), 1),
        "Fn_weighted_P_over_H": float((fn * pres).sum() / fn.sum() / hardness),
        "Fn_weighted_P_over_kappa": float((fn * pres / np.maximum(kap, 1.0)).sum() / fn.sum()),
        "Fn_share_area_capped": float(fn[capped].sum() / fn.sum()),
        "Fn_share_P_below_kappa": float(fn[pres < kap].sum() / fn.sum()),
        "Fn_share_front": float(fn[nx > 0].sum() / fn.sum()),
        "front_particles": touching,
    }


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--h-um", type=float, default=10.0)
    parser.add_argument("--only", nargs="*", default=None, help="(re)run only these cases")
    args = parser.parse_args()
    numba.set_num_threads(2)
    base = Scene.from_yaml(ROOT / "examples" / "coated_rigid_plastic.yaml")
    base = replace(base, discretisation=replace(base.discretisation, particle_size_m=args.h_um * 1e-6))
    base = base.with_sized_domain()
    ms = base.discretisation.mass_scaling
    fw = contact.FILTER_WAVE_TIMES

    def with_ms(k: float) -> Scene:
        return replace(base, discretisation=replace(base.discretisation, mass_scaling=ms * k))

    cases = {"defaults": (base, fw), "filter 5": (base, 0.5 * fw), "filter 20": (base, 2.0 * fw),
             "ms x4": (with_ms(4.0), fw), "ms/4": (with_ms(0.25), fw), "ms/16": (with_ms(1 / 16), fw),
             "ms/4, filter 20": (with_ms(0.25), 2.0 * fw)}
    data = json.loads(OUT.read_text()) if OUT.exists() else {}
    data["h_um"] = args.h_um
    runs = data.setdefault("runs", {})
    for name, (scene, fwt) in cases.items():
        if (args.only is None and name in runs) or (args.only is not None and name not in args.only):
            continue
        runs[name] = run_case(scene, fwt)
        print(name, json.dumps(runs[name]), flush=True)
        OUT.write_text(json.dumps(data, indent=2) + "\n")
    if args.only is None and "probe" not in data or args.only is not None and "probe" in args.only:
        data["probe"] = pressure_probe(base)
        print("probe", json.dumps(data["probe"]), flush=True)
        OUT.write_text(json.dumps(data, indent=2) + "\n")
    print(f"{'case':18s} {'mu':>6s} {'mu_pl':>6s} {'mu_sh':>6s} {'dp um':>6s} {'pen um':>6s} {'wall s':>7s}")
    for name, r in runs.items():
        print(f"{name:18s} {r['mu']:6.3f} {r['mu_pl']:6.3f} {r['mu_sh']:6.3f} {r['dp'] * 1e6:6.2f} "
              f"{r['penetration'] * 1e6:6.2f} {r['wall_s']:7.1f}")


if __name__ == "__main__":
    main()
