"""Scenes the benchmark scripts share (imported as ``common`` when a script runs from benchmarks/)."""

from __future__ import annotations

import time
from dataclasses import replace
from pathlib import Path

from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]


def coated_reference(h_um: float) -> Scene:
    """examples/coated_rigid_plastic.yaml (H~ = 0.5, t = 25 um, r = 0.2 mm, 3 N, f = 1) at particle size
    ``h_um`` on the block sized from the expected contact."""
    base = Scene.from_yaml(ROOT / "examples" / "coated_rigid_plastic.yaml")
    return replace(base, discretisation=replace(base.discretisation, particle_size_m=h_um * 1e-6)).with_sized_domain()


#: the example scenes a benchmark names by a short key (``real``, ``coated``, ``uncoated``)
EXAMPLES = {"real": "zinc_coated_steel.yaml", "coated": "coated_rigid_plastic.yaml",
            "uncoated": "uncoated_rigid_plastic.yaml"}


def workflow_scene(name: str, h_m: float) -> Scene:
    """The example scene ``name`` (a key of ``EXAMPLES``) at particle size ``h_m`` with the workflow's
    numerics (config/config.yaml): graded particles, fine zone 1.5 contact radii, active zone of 4, sized block."""
    base = Scene.from_yaml(ROOT / "examples" / EXAMPLES[name])
    disc = replace(base.discretisation, particle_size_m=h_m, graded=True, fine_zone_contact_radii=1.5,
                   active_zone_contact_radii=4.0)
    return replace(base, discretisation=disc).with_sized_domain()


#: the steady-state results a benchmark row keeps of a run
RESULTS = ("mu", "mu_pl", "mu_sh", "dp", "dg", "hpu", "penetration", "Fz_mean")


def run_scene(scene: Scene, threads: int) -> dict:
    """Simulate ``scene`` and return its steady-state results with the run's cost and provenance."""
    from plough.mpm.run import simulate

    t0 = time.perf_counter()
    ds = simulate(scene, progress=False, threads=threads)
    row = {q: float(ds[q]) for q in RESULTS}
    row.update(git_commit=str(ds.attrs.get("git_commit", "unknown")),
               wall_s=float(ds.attrs["cost_wall_time_s"]), total_s=time.perf_counter() - t0,
               steps=int(ds.attrs["cost_steps"]), particles=int(ds.attrs["cost_particles"]),
               material_top_max_m=float(ds.material_top.max()), grid_nodes=int(ds.attrs["cost_grid_nodes"]))
    row["active_fraction"] = float(ds.attrs.get("cost_active_fraction", 1.0))  # share of particle-steps worked on
    for q in ("mu_drift", "material_top_rise", "steady"):  # plough.mpm.io.steadiness
        row[q] = float(ds[q])
    return row
