"""Where is the residual groove's bottom against the sphere's lowest point? The uncoated reference scene at f = 0,
the workflow's numerics. Usage: python groove_probe.py H_UM CONTACT (2026-12-03-grid-local.md)."""

import sys
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "benchmarks"))

import common  # noqa: E402

from plough.materials import ProportionalShear  # noqa: E402
from plough.mpm.run import simulate  # noqa: E402

h_um, mode = float(sys.argv[1]), sys.argv[2]
scene = common.workflow_scene("uncoated", h_um * 1e-6)
scene = replace(scene, interface=ProportionalShear(f=0.0), discretisation=replace(scene.discretisation, contact=mode))
ds = simulate(scene, progress=False, threads=2)
window = ds.depth[ds.in_steady_window] * 1e6
pen, dg, hpu = float(ds.penetration) * 1e6, float(ds.dg) * 1e6, float(ds.hpu) * 1e6
print(f"h {h_um} {mode}: sphere's lowest point {pen:.2f} um deep (window {float(window.min()):.2f} to "
      f"{float(window.max()):.2f}); dg {dg:.2f} um, hpu {hpu:.2f} um")
for y, z in zip(ds.y.values * 1e6, ds.profile_z.values * 1e6, strict=True):
    if abs(y) < 80:
        print(f"  y {y:7.2f} um  residual surface {z:7.3f} um")
