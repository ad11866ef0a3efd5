"""The boundary layer's two pressures at the three real-material guard points (one-off probe).

    PYTHONPATH=src python docs/journal/2026-12-06-interface-law-scatter/compare.py /work/guardrun /work/tractionrun

Reads each point's runs with ``interface.pressure: particles`` (the main command's and the guard's, in the first
directory) and with ``traction`` (``traction_runs.py``'s, named ``<point>_traction_h<h>.nc`` in the second), and
prints per size mu, mu_pl, mu_sh and the mean interface strength (``contact_shear_capacity`` /
``contact_shear_area``, steady window), then each pressure's h -> 0 limit over the relative ladder's sizes
(``benchmarks/ladder_guard.py``'s ``limit``), and over the paper's 10 / 5 / 2.5 µm where
those runs are there, beside the analytical model's value (nominal pressure Fn / Axy).
"""

from __future__ import annotations

import sys
from pathlib import Path

import xarray as xr

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "benchmarks"))

from ladder_guard import limit  # noqa: E402

from plough.study import matrix  # noqa: E402
from plough.study.plan import load_config  # noqa: E402

#: the three real-material guard points and their relative ladder (config/config.yaml)
POINTS = {"zinc_bulk_bl0.32-0.95_r500_F7": (20.0, 10.0, 5.0),
          "zinc_coating-on-dx56_t15_bl0.32-0.95_r500_F4": (20.0, 10.0, 5.0),
          "zinc_bulk_bl0.32-0.95_r500_F11": (28.0, 14.0, 7.0)}
PAPER = (10.0, 5.0, 2.5)


def main(particles_dir: Path, traction_dir: Path) -> None:
    points = matrix.all_points(load_config([ROOT / "config" / "config.yaml"], ROOT))
    for key, ladder in POINTS.items():
        ana = matrix.analytical_values(points[key])
        print(f"\n{key} (analytical: mu {ana['mu']:.4f}, mu_pl {ana['mu_pl']:.4f}, mu_sh {ana['mu_sh']:.4f})\n")
        print("| pressure | h (µm) | mu | mu_pl | mu_sh | mean tau (MPa) | Fz / Axy (MPa) |")
        print("|---|---|---|---|---|---|---|")
        limits = {}
        for pressure, pattern in (("particles", particles_dir / "results" / "runs" / f"{key}_h{{h}}.nc"),
                                  ("traction", traction_dir / f"{key}_traction_h{{h}}.nc")):
            vals: dict[str, list[float]] = {"mu": [], "mu_sh": [], "se": []}
            paper: dict[float, tuple[float, float, float]] = {}
            for h in sorted({h for h in (28.0, 20.0, 14.0, 10.0, 7.0, 5.0, 2.5)
                             if Path(str(pattern).format(h=f"{h:g}")).exists()}, reverse=True):
                ds = xr.open_dataset(str(pattern).format(h=f"{h:g}"))
                w = ds["in_steady_window"].values.astype(bool)
                tau = ds["contact_shear_capacity"].values[w].mean() / ds["contact_shear_area"].values[w].mean()
                pn = ds["Fz"].values[w].mean() / ds["contact_area_xy"].values[w].mean()
                print(f"| {pressure} | {h:g} | {float(ds.mu):.4f} | {float(ds.mu_pl):.4f} | {float(ds.mu_sh):.4f} | "
                      f"{tau / 1e6:.1f} | {pn / 1e6:.0f} |")
                if h in ladder:
                    vals["mu"].append(float(ds.mu))
                    vals["mu_sh"].append(float(ds.mu_sh))
                    vals["se"].append(float(ds.mu_standard_error))
                if h in PAPER:
                    paper[h] = (float(ds.mu), float(ds.mu_sh), float(ds.mu_standard_error))
            limits[pressure] = {q: limit(ladder, vals[q], vals["se"]) for q in ("mu", "mu_sh")}
            if len(paper) == len(PAPER):  # the paper's ladder too, where its three runs are there
                limits[f"{pressure}, paper's sizes"] = {
                    q: limit(PAPER, [paper[h][i] for h in PAPER], [paper[h][2] for h in PAPER])
                    for i, q in enumerate(("mu", "mu_sh"))}
        print(f"\nh -> 0 over {' / '.join(f'{h:g}' for h in ladder)} µm (the paper's: 10 / 5 / 2.5 µm):")
        for pressure, lim in limits.items():
            print(f"- {pressure}: " + ", ".join(
                f"{q} {v['value']:.4f} ± {v['uncertainty']:.4f} ({v['method']}; {v['value'] / ana[q]:.2f}x analytical)"
                for q, v in lim.items()))


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
