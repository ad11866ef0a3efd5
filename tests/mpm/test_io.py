"""plough.mpm.io: the residual cross-sections behind the sphere (dg, hpu, dp) and the steadiness check."""

from __future__ import annotations

import math
from dataclasses import replace
from pathlib import Path
from types import SimpleNamespace

import numpy as np
import pytest
import xarray as xr

from plough.mpm import io
from plough.mpm.io import residual_profiles
from plough.mpm.scene import CONTACT_MODES, Scene

ROOT = Path(__file__).resolve().parents[2]


def _particles(x: np.ndarray, vol0: np.ndarray, z0: np.ndarray, J: np.ndarray | None = None) -> SimpleNamespace:
    """The particle fields the residual profile reads (n derived from x; J 1 unless given)."""
    return SimpleNamespace(x=x, J=np.ones(x.shape[0]) if J is None else J, vol0=vol0, z0=z0, n=x.shape[0])


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
    return _particles(x, np.full(n, h**3), np.full(n, -0.5 * h)), xs


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


def test_material_thrown_past_the_blocks_side_is_not_read_as_its_surface(scene):
    """A particle high above the surface beyond y = R (the grid widens for it) is not folded into the last
    y bin: the profile is that of the block without it."""
    s = replace(scene, outputs=replace(scene.outputs, profile_sections=3))
    p, _ = _grooved_block(s, lambda r: np.full(r.shape, 2e-6))
    a, x_end = 50e-6, s.start_x_m + s.sliding.distance_m
    y, z0, sections = residual_profiles(p, s, x_end, a)
    thrown = np.array([[sections[1], s.domain.radius_m + 0.6 * s.discretisation.particle_size_m, 13e-6]])
    q = _particles(np.vstack([p.x, thrown]), np.append(p.vol0, p.vol0[0]), np.append(p.z0, p.z0[0]))
    _, z1, _ = residual_profiles(q, s, x_end, a)
    np.testing.assert_array_equal(z1, z0)
    inside = q.x.copy()
    inside[-1, 1] = s.domain.radius_m - 3e-6  # the same particle inside the block's width does count
    _, z2, _ = residual_profiles(_particles(inside, q.vol0, q.z0), s, x_end, a)
    assert z2[-1] > z0[-1]


def _stretched_skin_block(scene: Scene, stretch: float):
    """A groove's cross-section repeated along x: the surface layer (z0 = -h/2) lowered 10 um and stretched
    sideways by ``stretch`` (particle centres ``stretch`` h apart in y), on the unstretched layer below it
    (z0 = -3h/2, one h deeper): the residual profile of journal 2026-12-03-groove-below-sphere."""
    h = scene.discretisation.particle_size_m
    xs = (np.arange(int(scene.domain.length_m / h)) + 0.5) * h
    n_y = int(scene.domain.radius_m / h)
    skin_y = (np.arange(int(n_y / stretch)) + 0.5) * stretch * h
    below_y = (np.arange(n_y) + 0.5) * h
    rows = []
    for ys, zc, z0 in ((skin_y, -10e-6 - 0.5 * h, -0.5 * h), (below_y, -10e-6 - 1.5 * h, -1.5 * h)):
        X, Y = np.meshgrid(xs, ys, indexing="ij")
        rows.append(np.stack([X.ravel(), Y.ravel(), np.full(X.size, zc), np.full(X.size, z0)], axis=1))
    a = np.vstack(rows)
    return _particles(a[:, :3].copy(), np.full(a.shape[0], h**3), a[:, 3].copy())


@pytest.mark.parametrize("stretch", [1.1, 1.19, 1.5, 1.9])
def test_the_profile_bridges_gaps_in_a_stretched_surface_layer(scene, stretch, monkeypatch):
    """A surface layer stretched sideways opens bins without a particle of it; the profile keeps to the layer
    (10 um deep everywhere) instead of falling one particle size to the layer below in those bins."""
    h = scene.discretisation.particle_size_m
    p = _stretched_skin_block(scene, stretch)
    a, x_end = 50e-6, scene.start_x_m + scene.sliding.distance_m
    y, z, _ = residual_profiles(p, scene, x_end, a)
    covered = y < (int(int(scene.domain.radius_m / h) / stretch) - 0.5) * stretch * h  # inside the layer's span
    np.testing.assert_allclose(z[covered], -10e-6, rtol=1e-12)
    assert io.groove_depths(y[covered], z[covered], a)[0] == pytest.approx(10e-6)
    # the scene does have gaps: without bridging those bins drop to the layer below
    monkeypatch.setattr(io, "SKIN_BRIDGE_SPAN_H", 0.0)
    _, z_raw, _ = residual_profiles(p, scene, x_end, a)
    assert np.nanmin(z_raw[covered]) == pytest.approx(-10e-6 - h)


@pytest.mark.parametrize("column", [3, 0])  # an inner column, and the one next to the mirror plane
def test_a_particle_missing_from_one_section_is_bridged_from_the_neighbouring_rows(scene, monkeypatch, column):
    """The surface layer unstretched but one particle of it gone from one row (moved along x, as the sliding
    shears the layer): its neighbours in the same row are 2 h apart, too far to bridge, but the rows beside it
    along x still hold that column, so the section keeps to the layer (10 um deep) there too; next to the
    mirror plane the layer's image across it closes the line."""
    h = scene.discretisation.particle_size_m
    p = _stretched_skin_block(scene, 1.0)
    a, x_end = 50e-6, scene.start_x_m + scene.sliding.distance_m
    s = replace(scene, outputs=replace(scene.outputs, profile_sections=0))
    assert s.domain.symmetric
    _, _, sections = residual_profiles(p, s, x_end, a)
    xs = sections[sections.size // 2]
    gone = (np.abs(p.x[:, 0] - xs) < 0.5 * h) & (np.abs(p.x[:, 1] - (column + 0.5) * h) < 0.1 * h) & (p.z0 > -h)
    assert gone.sum() == 1
    q = _particles(p.x[~gone], p.vol0[~gone], p.z0[~gone])
    y, z, _ = residual_profiles(q, s, x_end, a)
    np.testing.assert_allclose(z[y < 20 * h], -10e-6, rtol=1e-12)
    monkeypatch.setattr(io, "SKIN_BRIDGE_REACH_H", 0.5)  # the section's own band only: the bin dips
    _, z_band, _ = residual_profiles(q, s, x_end, a)
    assert z_band[column] == pytest.approx(-10e-6 - h / sections.size)


def test_a_layer_torn_wider_than_a_particle_is_not_bridged(scene, monkeypatch):
    """Surface-layer particles 2.5 h apart leave gaps wider than a particle: the material below shows in the
    bins between them (and a looser limit would have bridged them)."""
    h = scene.discretisation.particle_size_m
    p = _stretched_skin_block(scene, 2.5)
    a, x_end = 50e-6, scene.start_x_m + scene.sliding.distance_m
    y, z, _ = residual_profiles(p, scene, x_end, a)
    layer_y = (np.arange(20) + 0.5) * 2.5 * h
    bins_without = [b for b in range(1, 12) if not np.any(np.abs(layer_y - (b + 0.5) * h) < 0.5 * h)]
    assert len(bins_without) >= 5
    np.testing.assert_allclose(z[bins_without], -10e-6 - h, rtol=1e-12)
    monkeypatch.setattr(io, "SKIN_BRIDGE_SPAN_H", 3.0)
    _, z_loose, _ = residual_profiles(p, scene, x_end, a)
    np.testing.assert_allclose(z_loose[bins_without], -10e-6, rtol=1e-12)


def test_bridging_leaves_bins_holding_the_surface_layer_alone():
    """A V-shaped valley sampled by its own surface layer (one particle per bin, off the bins' centres): no bin
    changes, so the valley's bottom stays its particle's top; an empty bin takes the line between its
    neighbours; neighbours 2 h apart or more bridge nothing; a second set of samples bridges what the first
    could not."""
    h = 1e-5
    centres = (np.arange(6) + 0.5) * h
    skin_y = centres + np.array([0.3, -0.3, 0.4, -0.2, 0.1, 0.0]) * h
    skin_top = -np.abs(skin_y - 2.5 * h) * 0.5  # slope 0.5, lowest near bin 2
    z = np.full(6, -np.inf)
    np.maximum.at(z, np.arange(6), skin_top)
    before = z.copy()
    io.bridge_skin_gaps(z, centres, np.ones(6, dtype=bool), [(skin_y, skin_top)], h)
    np.testing.assert_array_equal(z, before)
    # drop bin 3's particle and put a deep one there: bin 3 takes the line between bins 2 and 4 (1.7 h apart)
    keep = np.arange(6) != 3
    z = before.copy()
    z[3] = -5 * h
    io.bridge_skin_gaps(z, centres, keep, [(skin_y[keep], skin_top[keep])], h)
    w = (centres[3] - skin_y[2]) / (skin_y[4] - skin_y[2])
    assert z[3] == pytest.approx(skin_top[2] + w * (skin_top[4] - skin_top[2]))
    np.testing.assert_array_equal(z[keep], before[keep])
    # bins 2, 3 and 4 emptied: neighbours 1 and 5 are 3.5 h apart, nothing bridged by that set ...
    keep = ~np.isin(np.arange(6), [2, 3, 4])
    z = np.where(keep, before, -5 * h)
    io.bridge_skin_gaps(z, centres, keep, [(skin_y[keep], skin_top[keep])], h)
    np.testing.assert_array_equal(z[~keep], -5 * h)
    # ... but a second set that also holds bin 2's particle (from a neighbouring row) bridges bin 2 (1.2 h to
    # 2.9 h: 1.7 h), not bins 3 and 4 (2.9 h to 5.5 h: 2.6 h)
    second = (np.append(skin_y[keep], skin_y[2]), np.append(skin_top[keep], skin_top[2]))
    io.bridge_skin_gaps(z, centres, keep, [(skin_y[keep], skin_top[keep]), second], h)
    w = (centres[2] - skin_y[1]) / (skin_y[2] - skin_y[1])
    assert z[2] == pytest.approx(skin_top[1] + w * (skin_top[2] - skin_top[1]))
    assert z[3] == -5 * h and z[4] == -5 * h


def test_the_surface_layer_is_the_top_row_at_every_particle_size(scene):
    """started_at_surface: the lattice's top row (z0 = -h/2) and the graded far field's (2 h particles at
    z0 = -h), nothing below."""
    h = 1e-5
    p = SimpleNamespace(z0=np.array([-0.5 * h, -1.5 * h, -h, -3 * h]),
                        vol0=np.array([h**3, h**3, 8 * h**3, 8 * h**3]))
    assert list(io.started_at_surface(p)) == [True, False, True, False]


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
    corners = {(3 * h + a * 0.55 * h, 3 * h + b * 0.55 * h) for a in (-1, 1) for b in (-1, 1)}
    got = set(zip(sx[1:], sy[1:], strict=True))
    assert len(got) == 4
    for c in corners:  # every quarter-point column once
        assert min(math.hypot(c[0] - g[0], c[1] - g[1]) for g in got) < 1e-18


@pytest.mark.parametrize("shift_h", [0.0, 0.5, 1.0, 1.5])  # the middle section at either parity of the 2 h rows
def test_graded_block_gives_the_lattice_surface_and_sections(shift_h):
    """An undeformed graded block: the same flat residual profile and height map as the uniform
    lattice (no bin left empty by the 2 h particles), and the middle section holds far-field particles."""
    from plough.mpm import solver
    from plough.mpm.io import picture_variables

    base = Scene.from_yaml(ROOT / "examples" / "coated_rigid_plastic.yaml").with_sized_domain()
    a = 50e-6
    x_end = base.start_x_m + base.sliding.distance_m + shift_h * base.discretisation.particle_size_m
    out = {}
    for graded in (False, True):
        s = replace(base, discretisation=replace(base.discretisation, graded=graded, fine_zone_contact_radii=1.0))
        p = solver.init(s, n_chunks=1)[0].particles
        y, z, sections = residual_profiles(p, s, x_end, a)
        variables, _ = picture_variables(p, s, np.array([x_end, 0.0, 0.0]), 0, a, sections)
        out[graded] = (p, y, z, variables)
    p_g, y_g, z_g, v_g = out[True]
    _, y_u, z_u, v_u = out[False]
    assert np.any(np.isclose(p_g.vol0, 8 * p_g.vol0.min()))  # the far field is coarse
    np.testing.assert_array_equal(y_g, y_u)
    np.testing.assert_allclose(z_u, 0.0, atol=1e-18)
    np.testing.assert_allclose(z_g, 0.0, atol=1e-18)  # every bin sampled, flat
    hmap_u, hmap_g = v_u["height_map"][1], v_g["height_map"][1]
    assert np.isfinite(hmap_u).all() and np.isfinite(hmap_g).all()
    np.testing.assert_allclose(hmap_g, 0.0, atol=1e-18)
    # the middle section outside the fine zone: one row of h particles, or one row of 2 h particles
    # holding a quarter as many per area (plus the unmerged h particles along the curved boundary)
    h = base.discretisation.particle_size_m
    w = max(base.expected_contact()[0], 6 * h)

    def far_count(v):
        sy, sz = v["section_y"][1], v["section_z"][1]
        return int(((sy > w + h) | (sz < -w - h)).sum())

    assert far_count(v_u) > 100
    assert far_count(v_g) >= 0.25 * far_count(v_u)


def test_snapshot_is_vtk_polydata_with_the_particle_fields(tmp_path):
    """Decode the .vtp: every point array has one value per particle; positions and sizes round-trip."""
    import base64
    import xml.etree.ElementTree as ET

    from plough.mpm import solver
    from plough.mpm.io import write_snapshot

    scene = Scene.from_yaml(ROOT / "examples" / "coated_rigid_plastic.yaml").with_sized_domain()
    scene = replace(scene, discretisation=replace(scene.discretisation, graded=True, fine_zone_contact_radii=1.0))
    p = solver.init(scene, n_chunks=1)[0].particles
    path = write_snapshot(p, tmp_path / "s.vtp", np.array([0.0, 0.0, 1e-4]), 1e-4, coating_row=0)
    piece = ET.parse(path).getroot().find("PolyData/Piece")
    assert int(piece.get("NumberOfPoints")) == p.n

    def decode(el):
        # the 4-byte length header is its own base64 block of 8 characters, then the data
        nbytes = int(np.frombuffer(base64.b64decode(el.text[:8]), np.uint32)[0])
        body = base64.b64decode(el.text[8:])
        assert len(body) == nbytes
        return np.frombuffer(body, np.float32).reshape(p.n, int(el.get("NumberOfComponents")))

    arrays = {el.get("Name"): decode(el) for el in piece.find("PointData")}
    assert {"material", "coating_fraction", "plastic_strain", "stress_Pa", "size_m"} <= set(arrays)
    np.testing.assert_allclose(decode(piece.find("Points/DataArray")), p.x, rtol=1e-6)
    h = scene.discretisation.particle_size_m
    np.testing.assert_allclose(np.unique(np.round(arrays["size_m"][:, 0] / h, 5)), [1.0, 2.0])


# ----------------------------------------------------------------------------- steadiness of the window
def _series(fx, fz, top):
    return {"Fx": np.asarray(fx, float), "Fz": np.asarray(fz, float), "material_top": np.asarray(top, float)}


def test_constant_window_is_steady_with_zero_drift_and_rise():
    n = 20
    mask = np.arange(n) >= 8  # 12 records: halves of 6
    out = io.steadiness(_series(np.full(n, 0.9), np.full(n, 3.0), np.full(n, 4e-6)), mask, 2.5e-6)
    assert out == {"mu_drift": 0.0, "material_top_rise": 0.0, "steady": 1}


def test_drift_and_rise_are_the_halves_difference():
    n = 10
    mask = np.arange(n) >= 2  # records 2..9: first half 2..5, second 6..9
    fx = np.where(np.arange(n) < 6, 0.8, 1.2)  # mu 0.8/3 then 1.2/3 (Fz constant): drift 0.4 / 1.0
    top = np.where(np.arange(n) < 6, 5e-6, 20e-6)
    out = io.steadiness(_series(fx, np.full(n, 3.0), top), mask, 2.5e-6)
    assert out["mu_drift"] == pytest.approx(0.4)
    assert out["material_top_rise"] == pytest.approx(15e-6)
    assert out["steady"] == 0
    # records outside the window do not count: the same halves with wild values outside it
    fx_out, top_out = fx.copy(), top.copy()
    fx_out[:2], top_out[:2] = 50.0, 1.0
    assert io.steadiness(_series(fx_out, np.full(n, 3.0), top_out), mask, 2.5e-6) == out


@pytest.mark.parametrize("drift_ok", [True, False])
def test_each_criterion_alone_decides(drift_ok):
    n, h = 8, 5e-6
    mask = np.ones(n, bool)
    mu_2 = 1.0 + (0.9 if drift_ok else 3) * io.STEADY_MU_DRIFT  # (mu_2 - 1) / mean mu just inside / outside
    fx = np.where(np.arange(n) < 4, 1.0, mu_2)
    top_rise = (0.5 if not drift_ok else 3.0) * io.STEADY_TOP_RISE_PARTICLES * h  # the other one fails
    top = np.where(np.arange(n) < 4, 0.0, top_rise)
    out = io.steadiness(_series(fx, np.ones(n), top), mask, h)
    assert (abs(out["mu_drift"]) <= io.STEADY_MU_DRIFT) is drift_ok
    assert (out["material_top_rise"] <= io.STEADY_TOP_RISE_PARTICLES * h) is (not drift_ok)
    assert out["steady"] == 0
    # both inside the limits: steady
    small = np.where(np.arange(n) < 4, 0.0, 0.5 * io.STEADY_TOP_RISE_PARTICLES * h)
    fx_small = np.where(np.arange(n) < 4, 1.0, 1.0 + 0.5 * io.STEADY_MU_DRIFT)
    assert io.steadiness(_series(fx_small, np.ones(n), small), mask, h)["steady"] == 1
    assert io.steadiness(_series(fx_small, np.ones(n), -small), mask, h)["steady"] == 1


def test_a_falling_top_is_a_change_too():
    """A prow shedding material: the top falls by more than the limit."""
    n, h = 8, 2.5e-6
    top = np.where(np.arange(n) < 4, 30e-6, 10e-6)
    out = io.steadiness(_series(np.ones(n), np.ones(n), top), np.ones(n, bool), h)
    assert out["material_top_rise"] == pytest.approx(-20e-6)
    assert out["mu_drift"] == 0.0 and out["steady"] == 0


def test_a_half_without_normal_force_is_finite_and_not_steady():
    """The sphere bounced off over one half (mean Fz <= 0 there): no inf or NaN, and not steady."""
    n = 8
    fz = np.where(np.arange(n) < 4, 0.0, 3.0)
    fx = np.where(np.arange(n) < 4, 0.0, 0.9)
    out = io.steadiness(_series(fx, fz, np.zeros(n)), np.ones(n, bool), 5e-6)
    assert np.isfinite(out["mu_drift"]) and out["steady"] == 0
    # drift of the halves' Fx over the window's Fz, relative to the window's mu: (0.9 - 0) / 0.45
    assert out["mu_drift"] == pytest.approx(2.0)


def test_a_window_too_short_to_split_is_not_called_steady():
    out = io.steadiness(_series(np.ones(3), np.ones(3), np.zeros(3)), np.array([False, False, True]), 5e-6)
    assert out == {"mu_drift": 0.0, "material_top_rise": 0.0, "steady": 0}


# ----------------------------------------------------------------------------- sampling standard errors
def test_jackknife_of_a_mean_is_the_batch_means_standard_error():
    """For the mean over equal batches the delete-one-batch jackknife equals std(batch means) / sqrt(k)
    exactly; a wrong (k - 1) / k factor or a left-in batch breaks this."""
    rng = np.random.default_rng(7)
    x = rng.normal(size=120)
    se = io.jackknife_standard_error(lambda k: x[k].mean(), x.size, batches=10)
    batch_means = x.reshape(10, 12).mean(axis=1)
    assert se == pytest.approx(batch_means.std(ddof=1) / np.sqrt(10), rel=1e-12)
    assert io.jackknife_standard_error(lambda k: x[k].mean(), 1) is None
    assert io.jackknife_standard_error(lambda k: x[k].mean(), 3, batches=10) == pytest.approx(
        x[:3].std(ddof=1) / np.sqrt(3), rel=1e-12)  # fewer samples than batches: one sample a batch


def test_standard_errors_of_the_window_and_the_sections():
    """A constant force has no sampling error; Fx alternating between batch halves of the window
    gives mu's jackknife error from its two values; records outside the window do not count; the
    groove's errors come from the sections' scatter of depth and the lattice-phase term in quadrature."""
    n, k = 40, io.SE_BATCHES
    mask = np.arange(n) >= 20  # 20 records: 10 batches of 2
    fz = np.full(n, 2.0)
    fx = np.where(np.arange(n) < 30, 1.0, 1.4)  # the window's first 5 batches 1.0, last 5 1.4
    fx[:20] = 99.0
    series = {"Fx": fx, "Fz": fz, "Fx_pl": 0.25 * fx, "Fx_sh": np.full(n, 0.5)}
    y = np.array([0.0, 10e-6, 20e-6, 100e-6])
    depth = np.array([2e-6, 4e-6, 2e-6, 4e-6])  # four sections, two groove depths; pile-up 1 um
    prof = np.array([[-d, -d, 0.0, 1e-6] for d in depth])
    h = 5e-6
    phase = io.GROOVE_LATTICE_PHASE_ERROR_H["grid"] * h
    out = io.standard_errors(series, mask, y, prof, contact_radius=15e-6, lattice_phase_term_m=phase)
    theta = np.array([(fx[20:].sum() - fx[20 + 2 * b: 22 + 2 * b].sum()) / (fz[20:].sum() - 4.0) for b in range(k)])
    expected = np.sqrt((k - 1) / k * np.sum((theta - theta.mean()) ** 2))
    assert out["mu_standard_error"] == pytest.approx(expected, rel=1e-12) and expected > 0
    assert out["mu_pl_standard_error"] == pytest.approx(0.25 * expected, rel=1e-12)
    assert out["mu_sh_standard_error"] == pytest.approx(0.0, abs=1e-15)
    # dp = mean depth + 1 um; leave one section of four out: depth 8/3 or 10/3 um, two each
    dp_theta = np.array([10 / 3, 8 / 3, 10 / 3, 8 / 3]) * 1e-6
    dp_expected = np.sqrt(3 / 4 * np.sum((dp_theta - dp_theta.mean()) ** 2))
    assert 0 < phase < dp_expected
    assert out["dp_standard_error"] == pytest.approx(np.hypot(dp_expected, phase), rel=1e-12)
    assert out["dg_standard_error"] == pytest.approx(np.hypot(dp_expected, phase), rel=1e-12)  # dg carries dp's scatter
    assert out["hpu_standard_error"] == pytest.approx(phase, rel=1e-12)  # the same pile-up in every section
    no_phase = io.standard_errors(series, mask, y, prof, contact_radius=15e-6, lattice_phase_term_m=0.0)
    assert no_phase["dp_standard_error"] == pytest.approx(dp_expected, rel=1e-12)
    assert no_phase["hpu_standard_error"] == 0.0
    # one section: the groove's errors cannot be estimated and are left out, not written as NaN or 0
    one = io.standard_errors(series, mask, y, prof[:1], contact_radius=15e-6, lattice_phase_term_m=phase)
    assert not {"dp_standard_error", "dg_standard_error", "hpu_standard_error"} & set(one)


def test_the_groove_lattice_phase_term_follows_the_contact():
    """Every contact has a term; the grid's is a tenth of the particle size (its phase spread), grid_local's 0.002
    of it (its spread is a tenth of the grid's or less), the unmeasured particle contact the grid's (the safe
    side)."""
    assert set(io.GROOVE_LATTICE_PHASE_ERROR_H) == set(CONTACT_MODES)
    scene = Scene.from_dict({"load_N": 1.0, "sphere": {"radius_um": 200},
                             "layers": {"substrate": {"rigid_plastic_hardness_MPa": 900}},
                             "discretisation": {"particle_size_um": 10}})
    terms = {mode: io.groove_lattice_phase_term_m(replace(scene, discretisation=replace(scene.discretisation,
                                                                                          contact=mode)))
             for mode in CONTACT_MODES}
    tenth = pytest.approx(1e-6, rel=1e-12)
    assert terms == {"grid": tenth, "grid_local": pytest.approx(2e-8, rel=1e-12), "particle": tenth}


def test_contact_summary_of_the_shear_split():
    """The steady-window summaries: means over the window only, the front pressure over both front regions."""
    from plough.mpm.io import CONTACT_SPLIT_META, contact_summary

    mask = np.array([False, True, True])
    series = {k: np.array([1e9, 1.0, 3.0]) for k in CONTACT_SPLIT_META}  # the first record lies outside
    out = contact_summary(series, mask, fz=4.0)
    assert out["contact_shear_area_mean"] == 2.0
    assert out["contact_front_pressure"] == 4.0 / (2.0 + 2.0)
    assert out["mu_sh_rear"] == (2.0 + 2.0) / 4.0 and out["mu_sh_carried"] == 2.0 / 4.0
    series = {k: np.zeros(3) for k in CONTACT_SPLIT_META}  # no front contact in the window: nothing, never NaN
    assert contact_summary(series, mask, fz=4.0) == {}


def test_energy_balance_sums_the_energy_terms_over_the_work_at_the_end():
    steps = 3
    terms = {k: ("step", np.linspace(0.0, 0.1 * (i + 1), steps)) for i, k in enumerate(io.ENERGY_TERMS)}
    work = 0.1 * sum(range(1, len(io.ENERGY_TERMS) + 1)) / 0.97  # the terms hold 0.97 of it at the end
    ds = xr.Dataset({**terms, "external_work": ("step", np.linspace(0.0, work, steps))})
    assert io.energy_balance(ds) == pytest.approx(0.97, rel=1e-12)
    assert set(io.ENERGY_TERMS) <= set(io.SERIES_META)  # each term is a recorded series with units
    assert math.isnan(io.energy_balance(ds.assign(external_work=("step", np.zeros(steps)))))
