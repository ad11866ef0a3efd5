"""plough.mpm.io: the residual cross-sections behind the sphere (dg, hpu, dp)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest

from plough.mpm.io import residual_profiles
from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[2]


def _grooved_block(scene: Scene, depth_of_row):
    """Top particle layer of a block whose top face sits at -depth_of_row(row) across |y| < 30 um."""
    h = scene.discretisation.particle_size_m
    xs = (np.arange(int(scene.domain.length_m / h)) + 0.5) * h
    ys = (np.arange(int(scene.domain.radius_m / h)) + 0.5) * h
    X, Y = np.meshgrid(xs, ys, indexing="ij")
    rows = np.broadcast_to(np.arange(xs.size)[:, None], X.shape)
    top = np.where(Y < 30e-6, -depth_of_row(rows), 0.0)
    x = np.stack([X.ravel(), Y.ravel(), (top - 0.5 * h).ravel()], axis=1)
    n = x.shape[0]
    return SimpleNamespace(x=x, J=np.ones(n), vol0=np.full(n, h**3), n=n), xs


@pytest.fixture
def scene():
    return Scene.from_yaml(ROOT / "examples" / "coated_rigid_plastic.yaml")


def test_default_averages_every_particle_row_between_the_limits(scene):
    """Alternate rows 2 and 4 um deep: every row gives the mean 3 um; the sections cover the rows
    between the start of the steady window and 1.25 contact radii behind the sphere."""
    h = scene.discretisation.particle_size_m
    p, xs = _grooved_block(scene, lambda r: np.where(r % 2 == 0, 2e-6, 4e-6))
    a = 50e-6
    x_end = scene.start_x_m + scene.sliding.distance_m
    y, z, sections = residual_profiles(p, scene, x_end, a)
    x_lo, x_hi = scene.start_x_m + 0.5 * scene.sliding.distance_m, x_end - 1.25 * a
    inside = xs[(xs >= x_lo - 0.5 * h) & (xs <= x_hi + 0.5 * h)]
    assert sections[0] == pytest.approx(x_lo) and sections[-1] == pytest.approx(x_hi)
    assert sections.size == int(np.floor((x_hi - x_lo) / h)) + 1 >= inside.size - 1
    assert np.all(np.diff(sections) >= h * (1 - 1e-12))  # adjacent one-row bands: no particle twice
    groove = z[y < 30e-6]
    n_even = sum(np.any(np.abs(xs[::2] - s) < 0.5 * h) for s in sections)
    expected = -(2e-6 * n_even + 4e-6 * (sections.size - n_even)) / sections.size
    assert np.allclose(groove, expected, rtol=1e-12)
    assert abs(expected + 3e-6) < 0.2e-6  # close to the mean of the two rows


def test_a_number_of_sections_is_kept(scene):
    s = replace(scene, outputs=replace(scene.outputs, profile_sections=3))
    p, _ = _grooved_block(s, lambda r: np.full(r.shape, 2e-6))
    _, z, sections = residual_profiles(p, s, s.start_x_m + s.sliding.distance_m, 50e-6)
    assert sections.size == 3
    assert np.nanmin(z) == pytest.approx(-2e-6, rel=1e-12)


def test_coarse_particles_are_sampled_on_the_fine_columns():
    """A 2 h particle's top face gives four h-wide samples at its quarter points, at z + h J^(1/3)."""
    from plough.mpm.io import surface_samples

    h = 1e-5
    x = np.array([[0.5 * h, 0.5 * h, -0.5 * h], [3 * h, 3 * h, -h]])
    vol0 = np.array([h**3, 8 * h**3])
    J = np.array([1.0, 1.331])
    sx, sy, top, index = surface_samples(SimpleNamespace(x=x, vol0=vol0, J=J, n=2), h)
    assert sx.size == 5 and list(index) == [0, 1, 1, 1, 1]
    np.testing.assert_allclose(top, [0.0] + [-h + h * 1.1] * 4, atol=1e-18)
    np.testing.assert_allclose(sorted(sx[1:]), [3 * h - 0.55 * h] * 2 + [3 * h + 0.55 * h] * 2)
    np.testing.assert_allclose(sorted(sy[1:]), [3 * h - 0.55 * h] * 2 + [3 * h + 0.55 * h] * 2)
