"""The energy terms of the uncoated reference scene at the workflow's numerics (default contact), and the plastic work
against the sphere's work along the slide. Usage: python energy_probe.py H_UM F (2026-12-03-grid-local.md)."""

import sys
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "benchmarks"))

import common  # noqa: E402

from plough.materials import ProportionalShear  # noqa: E402
from plough.mpm.io import energy_balance  # noqa: E402
from plough.mpm.run import simulate  # noqa: E402

h_um, f = float(sys.argv[1]), float(sys.argv[2])
scene = common.workflow_scene("uncoated", h_um * 1e-6)
scene = replace(scene, interface=ProportionalShear(f=f))
ds = simulate(scene, progress=False, threads=2)
print("balance", energy_balance(ds))
for v in ds.data_vars:
    if any(k in v for k in ("energy", "work", "dissipation", "loss")):
        a = ds[v]
        print(v, a.dims, float(a[-1]) if a.dims else float(a), a.attrs.get("units"))
n = ds.external_work.size
for i in range(0, n, max(1, n // 25)):
    w, p = float(ds.external_work[i]), float(ds.plastic_work[i])
    x_um, fz, depth_um = float(ds.sliding_distance[i]) * 1e6, float(ds.Fz[i]), float(ds.depth[i]) * 1e6
    print(f"{i} x {x_um:.1f} um W {w:.3e} plastic {p:.3e} ratio {p / max(w, 1e-30):.3f} Fz {fz:.3f} "
          f"depth {depth_um:.2f} um")
