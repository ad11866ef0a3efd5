"""plough.study.cost: the particle count of a run before it runs, against the solver's seeding."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from plough.mpm import scene as scene_module
from plough.mpm import solver
from plough.mpm.run import simulate
from plough.mpm.scene import Scene
from plough.study.cost import active_fraction, estimate

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("graded", [False, True])
@pytest.mark.parametrize("example", ["uncoated_rigid_plastic", "coated_rigid_plastic"])
def test_particle_estimate_follows_the_seeding(example, graded):
    scene = Scene.from_yaml(ROOT / "examples" / f"{example}.yaml").with_sized_domain()
    scene = replace(scene, discretisation=replace(scene.discretisation, graded=graded))
    state, _ = solver.init(scene, n_chunks=1)
    assert estimate(scene).particles == pytest.approx(state.particles.n, rel=0.03)


@pytest.mark.parametrize("example", ["uncoated_rigid_plastic", "zinc_coated_steel"])
def test_memory_request_counts_the_solver_grid_and_its_thread_copies(example):
    """The request holds the grid the solver allocates (with the per-thread P2G copies of the cluster's
    8 threads) besides the particles: a graded block with a shallow fine zone has far fewer particles on the
    same grid."""
    scene = Scene.from_yaml(ROOT / "examples" / f"{example}.yaml").with_sized_domain()
    scene = replace(scene, discretisation=replace(scene.discretisation, graded=True, fine_zone_depth_particles=6.0))
    state, const = solver.init(scene, n_chunks=8)
    est = estimate(scene)
    assert est.grid_nodes == const.grid.n_nodes
    grid_bytes = sum(a.nbytes for a in (state.work.grid_buf, state.work.grid_m, state.work.grid_v,
                                        state.work.grid_div, state.work.cbuf, state.work.last_push, state.work.flags))
    particle_bytes = sum(a.nbytes for a in state.particles if hasattr(a, "nbytes"))
    assert est.memory_mb * 1e6 >= 600e6 + grid_bytes + particle_bytes


def test_active_fraction_of_simple_runs():
    # a zone wider than the block covers all of it
    assert active_fraction(0.5, 0.2, 1.0, 2.0, 100, 100) == 1.0
    # a zone inside the block all along covers 2 w / L
    assert active_fraction(0.3, 0.4, 1.0, 0.1, 50, 500) == pytest.approx(0.2, rel=1e-12)
    # clipped at the start: half the zone while in place, then sliding out of the clip
    f = active_fraction(0.0, 0.2, 1.0, 0.1, 1000, 0, samples=10)
    assert f == pytest.approx(0.1, rel=1e-12)


def test_active_fraction_follows_the_solver(monkeypatch):
    """The estimate's share of particle-steps against the solver's count on a coarse reference run
    (its zone in contact radii: the 20 h floor would cover most of the block at h = 20 um)."""
    monkeypatch.setattr(scene_module, "ACTIVE_ZONE_MIN_PARTICLES", 0.0)
    scene = Scene.from_yaml(ROOT / "examples" / "uncoated_rigid_plastic.yaml").with_sized_domain()
    scene = replace(scene, discretisation=replace(scene.discretisation, particle_size_m=20e-6,
                                                  active_zone_contact_radii=4.0))
    ds = simulate(scene, progress=False, threads=1)
    est = estimate(scene)
    assert est.active_fraction == pytest.approx(ds.attrs["cost_active_fraction"], rel=0.05)
    assert est.particle_steps == pytest.approx(ds.attrs["cost_particle_steps"], rel=0.1)
    assert est.active_fraction < 0.8


def test_cluster_request_rate_is_no_faster_than_the_measured_workflow_jobs():
    """The rate behind a cluster time request is at most that of every workflow job measured here that ran
    long enough for its start-up not to count (over 200 s, 2 threads), so the request's safety factor is
    left for the scaling to more threads."""
    import json
    from pathlib import Path

    from plough.study.cost import THROUGHPUT_PER_THREAD

    results = Path(__file__).parents[2] / "benchmarks/results"
    runs = [r for name in ("projection_check_preview.json", "projection_check_h5_h2.5.json")
            for r in json.loads((results / name).read_text())["runs"] if r["measured_s"] > 200.0]
    assert len(runs) >= 10
    for r in runs:
        assert r["particle_steps"] / (THROUGHPUT_PER_THREAD * 2) >= r["measured_s"], r["run"]
