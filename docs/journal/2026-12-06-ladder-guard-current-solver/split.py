"""Where the size-to-size scatter of mu lives at the five guard points (one-off probe).

    python docs/journal/2026-12-06-ladder-guard-current-solver/split.py /work/guardrun

(at 38e49d6: the run files carry that solver's fingerprint, which the check against this tree's solver needs.)

Reads every run file of the guard points in the run directory (each checked against its scene and this tree's
solver, as other_ladders.py does) and prints, per size, mu and its two parts (ploughing mu_pl, interface shear
mu_sh), the nodes' summed surface share in contact (``contact_shear_area``) and the mean interface strength
over it (``contact_shear_capacity`` / ``contact_shear_area``), both averaged over the steady window; then for
each point and part the spread over the sizes with a contact at least 6 particles wide (max - min over the
mean, in %).
"""

from __future__ import annotations

import json
import sys
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "src"))
sys.path.insert(0, str(Path(__file__).parent))

from other_ladders import all_scenes  # noqa: E402

from plough.fingerprint import solver_fingerprint  # noqa: E402
from plough.study.runfiles import load_run  # noqa: E402

#: sizes whose expected contact radius is at least this many particles enter the spread
MIN_CONTACT_PARTICLES = 6.0


def main(workdir: Path) -> None:
    guard = json.loads((ROOT / "benchmarks" / "results" / "ladder_guard.json").read_text())
    keys = [p["point"] for p in guard["points"]]
    scenes = all_scenes()
    solver = solver_fingerprint()
    print(f"solver {solver}")
    for key in keys:
        rows = []
        for rid, scene in scenes.items():
            path = workdir / "results" / "runs" / f"{rid}.nc"
            if not (rid.startswith(key + "_h") and path.exists()):
                continue
            ds = load_run(path, rid, scene, solver)
            w = ds["in_steady_window"].values.astype(bool)
            area = float(np.mean(ds["contact_shear_area"].values[w]))
            tau = float(np.mean(ds["contact_shear_capacity"].values[w])) / area
            rows.append((float(rid.rsplit("_h", 1)[1]), float(ds.attrs["contact_radius_particles"]),
                         float(ds["mu"]), float(ds["mu_pl"]), float(ds["mu_sh"]), area * 1e12, tau / 1e6))
        rows.sort(reverse=True)
        print(f"\n{key}\n\n| h (µm) | a / h | mu | mu_pl | mu_sh | shear area (µm²) | mean tau (MPa) |\n"
              "|---|---|---|---|---|---|---|")
        for h, ah, mu, pl, sh, area, tau in rows:
            print(f"| {h:g} | {ah:.1f} | {mu:.4f} | {pl:.4f} | {sh:.4f} | {area:,.0f} | {tau:.1f} |")
        fine = np.array([r for r in rows if r[1] >= MIN_CONTACT_PARTICLES])
        if len(fine) >= 2:
            spread = {name: 100 * np.ptp(fine[:, c]) / np.mean(fine[:, c])
                      for name, c in (("mu", 2), ("mu_pl", 3), ("mu_sh", 4), ("area", 5), ("tau", 6))}
            dev_pl = fine[:, 3] - fine[:, 3].mean()
            dev_sh = fine[:, 4] - fine[:, 4].mean()
            corr = float(np.corrcoef(dev_pl, dev_sh)[0, 1]) if len(fine) > 2 else float("nan")
            print(f"\nspread over the {len(fine)} sizes with a / h >= {MIN_CONTACT_PARTICLES:g} (max - min over mean): "
                  + ", ".join(f"{k} {v:.1f}%" for k, v in spread.items())
                  + f"; correlation of mu_pl's and mu_sh's deviations {corr:+.2f}")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
