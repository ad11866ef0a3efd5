"""The grid contact's interface shear split by region and kind of node (journal 2026-12-02-interface-shear-split).

Runs the reference ploughing scenes (benchmarks/common.py: workflow numerics) at interface factors f and particle
sizes h with the grid contact, and keeps for each run the steady-window means of the contact_* series
(plough.mpm.io.CONTACT_SPLIT_META) with the run's results and the analytical model's. Rows merge into
results.json beside this file, keyed by scene, f and h:

    python docs/journal/2026-12-02-interface-shear-split/probe.py --scene uncoated coated --f 1 0.5 --sizes-um 20 10
"""

from __future__ import annotations

import argparse
import json
import sys
import time
from dataclasses import replace
from pathlib import Path

import numba
import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / "benchmarks"))
import common  # noqa: E402

from plough.analytical import ploughing  # noqa: E402
from plough.io import git_commit  # noqa: E402
from plough.materials import ProportionalShear  # noqa: E402
from plough.mpm.io import CONTACT_SPLIT_META  # noqa: E402
from plough.mpm.run import simulate, warm_up  # noqa: E402

OUT = HERE / "results.json"


def run(name: str, f: float, h_um: float, threads: int, k1: float) -> dict:
    scene = common.workflow_scene(name, h_um * 1e-6)
    scene = replace(scene, interface=ProportionalShear(f=f))
    lay = scene.layers
    Hs = 3.0 * lay.substrate.flow.sigma_y_Pa
    Hc = 3.0 * lay.coating.flow.sigma_y_Pa if lay.coated else Hs
    ana = ploughing(scene.load_N, scene.sphere.radius_m, lay.coating_thickness_m, Hc, Hs, k1=k1, f=f)
    t0 = time.perf_counter()
    ds = simulate(scene, progress=False, threads=threads)
    wall = time.perf_counter() - t0
    m = ds.in_steady_window.values
    row = {"scene": name, "f": f, "h_um": h_um, "dx_um": scene.discretisation.cell_size_m * 1e6,
           **{q: float(ds[q]) for q in common.RESULTS},
           **{k: float(ds[k][m].mean()) for k in ("Fx", "Fz", "Fx_sh", "Fx_pl", "Fz_pl", "Fz_sh", "contact_area_xy",
                                                 "depth", *CONTACT_SPLIT_META)},
           "kappa_substrate_Pa": lay.substrate.flow.sigma_y_Pa / np.sqrt(3.0),
           "kappa_coating_Pa": lay.coating.flow.sigma_y_Pa / np.sqrt(3.0) if lay.coated else float("nan"),
           **{f"analytical_{k}": float(np.asarray(getattr(ana, k))) for k in
              ("mu", "mu_pl", "mu_sh", "dp", "a", "Axy", "Axys", "Axyc", "tau_c", "tau_s", "Hcs")},
           "steady": float(ds.steady), "mu_drift": float(ds.mu_drift), "wall_s": wall,
           "steps": int(ds.attrs["cost_steps"]), "particles": int(ds.attrs["cost_particles"])}
    print(f"{name} f={f:g} h={h_um:g}: mu={row['mu']:.4f} mu_sh={row['mu_sh']:.4f} (analytical "
          f"{row['analytical_mu']:.4f} / {row['analytical_mu_sh']:.4f}) shear area "
          f"{row['contact_shear_area'] * 1e12:.0f} um2, front xy {row['contact_area_xy_front'] * 1e12:.0f} um2 "
          f"(analytical Axy {row['analytical_Axy'] * 1e12:.0f}) wall {wall:.0f} s", flush=True)
    return row


def main() -> None:
    ap = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    ap.add_argument("--scene", nargs="+", default=["uncoated", "coated"])
    ap.add_argument("--f", type=float, nargs="+", default=[1.0, 0.5])
    ap.add_argument("--sizes-um", type=float, nargs="+", default=[20.0, 10.0])
    ap.add_argument("--threads", type=int, default=2)
    ap.add_argument("--k1", type=float, default=125.0)
    args = ap.parse_args()
    numba.set_num_threads(args.threads)
    warm_up(args.threads)
    for h in args.sizes_um:
        for name in args.scene:
            for f in args.f:
                row = dict(run(name, f, h, args.threads, args.k1), git_commit=git_commit())
                old = json.loads(OUT.read_text()) if OUT.exists() else {"runs": []}
                key = (row["scene"], row["f"], row["h_um"])
                runs = [r for r in old["runs"] if (r["scene"], r["f"], r["h_um"]) != key] + [row]
                runs.sort(key=lambda r: (r["scene"], -r["f"], -r["h_um"]))
                OUT.write_text(json.dumps({"note": "rows of probe.py (steady-window means, full body, SI)",
                                           "runs": runs}, indent=1))


if __name__ == "__main__":
    main()
