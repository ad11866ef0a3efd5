"""plough.mpm.particles: graded seeding (fine particles along the track, 2 h particles elsewhere).

References are the uniform lattice of the same scene: merging 2 x 2 x 2 groups must keep the
block's mass, volume, coating volume and (for one material) centre of mass exactly, leave the fine
zone untouched, and only merge complete groups inside the half cylinder.
"""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from plough.mpm import solver
from plough.mpm.particles import coarsen_far_field
from plough.mpm.scene import Scene

from .test_scene import coated_scene


def graded(scene: Scene, k: float = 1.0, shape: str = "square") -> Scene:
    return replace(scene, discretisation=replace(scene.discretisation, graded=True, fine_zone_contact_radii=k,
                                                 fine_zone_shape=shape))


def in_zone(x: np.ndarray, half_edge: float, w: float, shape: str) -> np.ndarray:
    """True where a point of the cube of half-edge ``half_edge`` centred at x lies in the fine zone (reference)."""
    gap_y = np.maximum(np.abs(x[:, 1]) - half_edge, 0.0)
    gap_z = np.maximum(-x[:, 2] - half_edge, 0.0)
    if shape == "square":
        return (gap_y <= w) & (gap_z <= w)
    return np.hypot(gap_y, gap_z) <= w


@pytest.fixture(scope="module", params=[(True, "square"), (False, "square"), (True, "disc")],
                ids=["mirror", "full", "mirror-disc"])
def pair(request):
    """(graded scene, uniform particles, graded particles) of the coated scene, t = 25 um, h = 10 um."""
    symmetric, shape = request.param
    scene = coated_scene(symmetric=symmetric)
    uniform, _ = solver.init(scene, n_chunks=1)
    grad, _ = solver.init(graded(scene, shape=shape), n_chunks=1)
    return graded(scene, shape=shape), uniform.particles, grad.particles


def test_graded_seeding_keeps_mass_volume_and_coating_volume(pair):
    scene, u, g = pair
    assert g.n < 0.8 * u.n  # something was merged
    assert g.vol0.sum() == pytest.approx(u.vol0.sum(), rel=1e-12)
    assert g.mass.sum() == pytest.approx(u.mass.sum(), rel=1e-12)
    coat_u = (u.vol0 * np.where(u.mat_a == 0, u.frac_a, 0.0)).sum()
    coat_g = (g.vol0 * np.where(g.mat_a == 0, g.frac_a, 0.0)).sum()
    assert coat_g == pytest.approx(coat_u, rel=1e-12)
    # the volume centroid is the lattice's (merged centres are their groups' centroids)
    np.testing.assert_allclose((g.vol0[:, None] * g.x).sum(0) / g.vol0.sum(),
                               (u.vol0[:, None] * u.x).sum(0) / u.vol0.sum(), rtol=0, atol=1e-12)


def test_fine_zone_is_untouched_and_merged_particles_are_double_size(pair):
    scene, u, g = pair
    h = scene.discretisation.particle_size_m
    a, _ = scene.expected_contact()
    w = max(scene.discretisation.fine_zone_contact_radii * a, 6 * h)
    shape = scene.discretisation.fine_zone_shape
    in_zone_u = in_zone(u.x, 0.5 * h, w, shape)
    assert in_zone_u.sum() > 0
    fine = np.isclose(g.vol0, h**3, rtol=1e-12, atol=0)
    coarse = np.isclose(g.vol0, 8 * h**3, rtol=1e-12, atol=0)
    assert np.all(fine | coarse) and coarse.sum() > 0
    # every fine-zone lattice particle is still there, at its place
    key = lambda x: set(map(tuple, np.rint(x / (0.5 * h)).astype(np.int64)))  # noqa: E731
    assert key(u.x[in_zone_u]) <= key(g.x[fine])
    assert fine.sum() == u.n - 8 * coarse.sum()
    # coarse particles: outside the zone, centred on even lattice planes, inside the half cylinder
    xc = g.x[coarse]
    assert not np.any(in_zone(xc, h - 1e-12, w, shape))
    np.testing.assert_allclose(np.mod(xc / h, 2.0), 1.0, atol=1e-9)
    R = scene.domain.radius_m
    assert np.all(xc[:, 1] ** 2 + xc[:, 2] ** 2 < R * R)
    assert np.all(np.diff(g.x[:, 0]) >= 0)  # still x-major: thread chunks are slabs


def test_coarse_particles_straddling_the_coating_carry_its_volume_fraction():
    """t = 15 um at h = 10 um: a 2 h particle spanning -20..0 um is 3/4 coating, -40..-20 um is pure substrate."""
    scene = graded(coated_scene(t_um=15.0), k=1.0)
    state, _ = solver.init(scene, n_chunks=1)
    p = state.particles
    h = 10e-6
    coarse = np.isclose(p.vol0, 8 * h**3, rtol=1e-12, atol=0)
    top = coarse & np.isclose(p.x[:, 2], -h, rtol=1e-12, atol=0)
    assert top.sum() > 0
    np.testing.assert_allclose(p.frac_a[top], 0.75, rtol=1e-12)
    assert np.all(p.mat_a[top] == 0) and np.all(p.mat_b[top] == 1)
    below = coarse & (p.x[:, 2] < -2 * h)
    assert np.all(p.mat_a[below] == 1) and np.all(p.frac_a[below] == 1.0)


def test_only_complete_groups_merge():
    """Seven of the eight cubes of a group: nothing merges; all eight: one particle of 8 h^3."""
    h = 1.0
    cubes = np.array([[i, j, k] for i in range(2) for j in range(2) for k in range(2)], dtype=float)
    x = (cubes + 0.5) * h + np.array([0.0, 10.0, 0.0])  # far from the fine zone at |y| <= 1
    xs, vol = coarsen_far_field(x, h, 1.0)
    assert xs.shape == (1, 3) and vol[0] == 8.0
    np.testing.assert_allclose(xs[0], x.mean(0))
    xs, vol = coarsen_far_field(x[:7], h, 1.0)
    assert xs.shape == (7, 3) and np.all(vol == 1.0)


def test_graded_needs_two_particles_per_cell():
    scene = coated_scene()
    with pytest.raises(ValueError, match="particles_per_cell"):
        replace(scene.discretisation, graded=True, particles_per_cell=1)
    for k in (0.0, 0.5, float("nan")):
        with pytest.raises(ValueError, match=r"fine_zone_contact_radii = .* outside the allowed range \[1, inf\)"):
            replace(scene.discretisation, fine_zone_contact_radii=k)
    with pytest.raises(ValueError, match="graded"):
        replace(scene.discretisation, graded="yes")


def test_graded_round_trips_through_the_scene_dict():
    scene = graded(coated_scene(), k=1.25)
    back = Scene.from_dict(scene.to_dict())
    assert back.discretisation.graded is True and back.discretisation.fine_zone_contact_radii == 1.25
    assert back.discretisation.fine_zone_shape == "square"
    disc = Scene.from_dict(graded(coated_scene(), shape="disc").to_dict())
    assert disc.discretisation.fine_zone_shape == "disc"


def test_the_disc_zone_is_the_square_zone_less_its_corners():
    """Same fine particles near the axes, coarse ones in the corners; the mass is kept either way."""
    scene = coated_scene()
    sq, _ = solver.init(graded(scene, k=1.0), n_chunks=1)
    dc, _ = solver.init(graded(scene, k=1.0, shape="disc"), n_chunks=1)
    s, d = sq.particles, dc.particles
    assert d.n < s.n
    assert d.mass.sum() == pytest.approx(s.mass.sum(), rel=1e-12)
    h = scene.discretisation.particle_size_m
    fine = lambda p: set(map(tuple, np.rint(p.x[p.vol0 < 2 * h**3] / (0.5 * h)).astype(np.int64)))  # noqa: E731
    assert fine(d) < fine(s)  # every fine particle of the disc is one of the square's, not the reverse


def test_an_unknown_fine_zone_shape_is_refused():
    with pytest.raises(ValueError, match=r"fine_zone_shape = 'circle' is not one of \['square', 'disc'\]"):
        replace(coated_scene().discretisation, fine_zone_shape="circle")


@pytest.mark.parametrize("shape", ["square", "disc"])
def test_a_fine_zone_shaped_by_the_groove_and_the_coating(shape):
    """fine_zone_depth_particles = m: the zone keeps its half-width w (k expected contact radii) but reaches only
    max(expected groove, coating) + m h deep (at least 6 h, at most w); every lattice particle of that zone is
    kept, no merged particle reaches into it, mass and volume are kept, and fewer particles remain than with
    the zone as deep as wide."""
    base = graded(coated_scene(), k=1.5, shape=shape)  # t = 25 um, h = 10 um
    m = 3.0
    scene = replace(base, discretisation=replace(base.discretisation, fine_zone_depth_particles=m))
    h = scene.discretisation.particle_size_m
    a, dp = scene.expected_contact()
    w = max(1.5 * a, 6 * h)
    d = min(w, max(max(dp, scene.layers.coating_thickness_m) + m * h, 6 * h))
    assert d < w - 2 * h  # the zone is shallower than wide: the test tells the two apart
    u = solver.init(replace(base, discretisation=replace(base.discretisation, graded=False)), n_chunks=1)[0].particles
    deep = solver.init(base, n_chunks=1)[0].particles
    g = solver.init(scene, n_chunks=1)[0].particles
    assert g.n < deep.n
    assert g.vol0.sum() == pytest.approx(u.vol0.sum(), rel=1e-12)
    assert g.mass.sum() == pytest.approx(u.mass.sum(), rel=1e-12)

    def zone(x: np.ndarray, half_edge: float) -> np.ndarray:
        gap_y = np.maximum(np.abs(x[:, 1]) - half_edge, 0.0)
        gap_z = np.maximum(-x[:, 2] - half_edge, 0.0)
        if shape == "square":
            return (gap_y <= w) & (gap_z <= d)
        return (gap_y / w) ** 2 + (gap_z / d) ** 2 <= 1.0

    fine = np.isclose(g.vol0, h**3, rtol=1e-12, atol=0)
    coarse = np.isclose(g.vol0, 8 * h**3, rtol=1e-12, atol=0)
    key = lambda x: set(map(tuple, np.rint(x / (0.5 * h)).astype(np.int64)))  # noqa: E731
    assert key(u.x[zone(u.x, 0.5 * h)]) <= key(g.x[fine])
    assert not np.any(zone(g.x[coarse], h - 1e-12))
    assert np.any(coarse & (np.abs(g.x[:, 1]) < 0.5 * w) & (g.x[:, 2] < -d - h))  # coarse under the track now


def test_the_fine_zone_depth_key_is_validated_and_round_trips():
    disc = coated_scene().discretisation
    for m in (0.0, 1.5, -3.0, float("nan"), float("inf"), True):
        with pytest.raises(ValueError, match=r"fine_zone_depth_particles = .* outside the allowed range \[2, inf\) "
                                             "or null"):
            replace(disc, fine_zone_depth_particles=m)
    scene = replace(coated_scene(), discretisation=replace(disc, graded=True, fine_zone_depth_particles=6))
    assert Scene.from_dict(scene.to_dict()).discretisation.fine_zone_depth_particles == 6
    assert coated_scene().discretisation.fine_zone_depth_particles is None  # default: as deep as wide
