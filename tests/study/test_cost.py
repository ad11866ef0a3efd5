"""plough.study.cost: the particle count of a run before it runs, against the solver's seeding."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

import pytest

from plough.mpm import solver
from plough.mpm.scene import Scene
from plough.study.cost import estimate

ROOT = Path(__file__).resolve().parents[2]


@pytest.mark.parametrize("graded", [False, True])
@pytest.mark.parametrize("example", ["uncoated_rigid_plastic", "coated_rigid_plastic"])
def test_particle_estimate_follows_the_seeding(example, graded):
    scene = Scene.from_yaml(ROOT / "examples" / f"{example}.yaml").with_sized_domain()
    scene = replace(scene, discretisation=replace(scene.discretisation, graded=graded))
    state, _ = solver.init(scene, n_chunks=1)
    assert estimate(scene).particles == pytest.approx(state.particles.n, rel=0.03)
