"""Energy outlier probe: uncoated f = 0 at h = 5 um (workflow numerics, default contact) and variants, one JSON
line each (2026-12-03-consistent-pressure.md). Usage: PYTHONPATH=TREE/src python energy_variants.py H_UM VARIANT...
(variants: base, flipF, local, uniform, nozone, cflC, msM). "heat" is printed over the work: with
pressure_work_diagnostic.patch applied to TREE it holds the work of the pressure on d_bar - d instead."""

import json
import sys
import time
from dataclasses import replace
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parents[3] / "benchmarks"))

import common  # noqa: E402

from plough.materials import ProportionalShear  # noqa: E402
from plough.mpm.io import energy_balance  # noqa: E402
from plough.mpm.run import simulate  # noqa: E402

h_um = float(sys.argv[1])
for name in sys.argv[2:]:
    scene = common.workflow_scene("uncoated", h_um * 1e-6)
    scene = replace(scene, interface=ProportionalShear(f=0.0))
    d = scene.discretisation
    if name.startswith("flip"):
        d = replace(d, flip=float(name[4:]))
    elif name == "local":
        d = replace(d, dilatation="local")
    elif name == "uniform":
        d = replace(d, graded=False)
    elif name == "nozone":
        d = replace(d, active_zone_contact_radii=None)
    elif name.startswith("cfl"):
        d = replace(d, cfl=float(name[3:]))
    elif name.startswith("ms"):
        d = replace(d, mass_scaling=float(name[2:]))
    scene = replace(scene, discretisation=d)
    t = time.perf_counter()
    ds = simulate(scene, progress=False, threads=2)
    W = float(ds.external_work[-1])
    print("heat(diag)/W", float(ds.heat[-1]) / W, "plastic/W", float(ds.plastic_work[-1]) / W)
    n = ds.external_work.size
    at = (n // 6, n // 3, n // 2, 2 * n // 3, n - 1)
    ratios = [round(float(ds.plastic_work[i]) / max(float(ds.external_work[i]), 1e-30), 3) for i in at]
    depth = [round(float(ds.depth[i]) * 1e6, 2) for i in at]
    print(json.dumps(dict(variant=name, h_um=h_um, balance=round(energy_balance(ds), 4), mu=round(float(ds.mu), 4),
                          dp=round(float(ds.dp) * 1e6, 2), plastic_over_work=ratios, depth_um=depth,
                          wall_s=round(time.perf_counter() - t, 1))), flush=True)
