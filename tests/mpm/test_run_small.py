"""End-to-end tests of plough.mpm.run / solver / cli on a tiny scene (about 2000 particles).

The scene is far too coarse for physics (h = 10 um against an expected ploughing depth of ~2 um);
it checks the plumbing: load control, the results dataset and its metadata, the stability
checks and the command line. Everything runs single-threaded (numba threads = 1) so that the
run is deterministic and cheap on a loaded machine.
"""

from __future__ import annotations

import copy
import json
import math
import warnings
from dataclasses import replace

import numba
import numpy as np
import pytest
import xarray as xr
import yaml

from plough import cli
from plough.mpm import contact, growth, io, solver, transfers
from plough.mpm import run as run_module
from plough.mpm import scene as scene_module
from plough.mpm.grid import FIXED, FREE, boundary_flags
from plough.mpm.run import simulate
from plough.mpm.scene import Scene

TINY = {
    "name": "tiny",
    # 1.5 N, not 1 N: with the projected dilatation the 1 N scene (penetration 0.3 um, a thirtieth of a
    # particle) swings by 40% of the load over 5 um of sliding and its window mean was 7.5% low
    "load_N": 1.5,
    "sphere": {"radius_um": 200},
    "layers": {"substrate": {"rigid_plastic_hardness_MPa": 900}},
    "interface": {"model": "proportional", "f": 1.0},
    "domain": {"radius_um": 80, "length_um": 400, "symmetric": True},
    "sliding": {"distance_um": 200, "speed_m_s": 0.1, "experiment_speed_m_s": 0.001},
    "discretisation": {"particle_size_um": 10, "particles_per_cell": 2, "cfl": 0.3, "mass_scaling": 1.0e6},
    "outputs": {"steady_window": [0.5, 1.0], "records": 40},
}
#: Inertia-dominated variant that blows up within a few hundred steps (a particle is flung off the grid).
UNSTABLE = {"sliding": {"distance_um": 200, "speed_m_s": 50.0}, "discretisation": {"particle_size_um": 10, "cfl": 0.5}}


def scene_dict(**parts):
    d = copy.deepcopy(TINY)
    d.update(copy.deepcopy(parts))
    return d


@pytest.fixture(scope="module", autouse=True)
def single_thread():
    old = numba.get_num_threads()
    numba.set_num_threads(1)
    yield
    numba.set_num_threads(old)


@pytest.fixture(scope="module")
def tiny_scene():
    return Scene.from_dict(TINY)


@pytest.fixture(scope="module")
def tiny_run(tiny_scene):
    return simulate(tiny_scene, progress=False, threads=1)


# ----------------------------------------------------------------------------- the dataset
def test_tiny_scene_passes_validation(tiny_scene):
    a, dp = tiny_scene.expected_contact()
    assert 2 * a <= tiny_scene.domain.radius_m
    assert tiny_scene.sliding.distance_m + 4 * a <= tiny_scene.domain.length_m


def test_results_are_present_and_finite(tiny_run):
    for name in ("mu", "mu_pl", "mu_sh", "dp", "dg", "hpu", "penetration", "Fz_mean", "Fx_mean",
                 "max_particle_penetration"):
        assert name in tiny_run, name
        assert tiny_run[name].dims == ()
        assert math.isfinite(float(tiny_run[name])), name
    for name in ("Fx", "Fz", "Fx_pl", "Fx_sh", "depth", "external_work", "plastic_work", "time"):
        assert np.all(np.isfinite(tiny_run[name].values)), name
    assert float(tiny_run.dp) == pytest.approx(float(tiny_run.dg) + float(tiny_run.hpu), abs=1e-15)
    assert float(tiny_run.dg) >= 0 and float(tiny_run.hpu) >= 0
    assert 0 < float(tiny_run.mu) < 1.5
    assert float(tiny_run.penetration) > 0


def test_friction_parts_add_up(tiny_run):
    ds = tiny_run
    assert float(ds.mu) == pytest.approx(float(ds.mu_pl) + float(ds.mu_sh), abs=1e-12)
    np.testing.assert_allclose(ds.Fx, ds.Fx_pl + ds.Fx_sh, rtol=1e-12, atol=1e-15)
    np.testing.assert_allclose(ds.Fz, ds.Fz_pl + ds.Fz_sh, rtol=1e-12, atol=1e-15)
    mask = ds.in_steady_window.values
    assert mask.sum() >= 3
    assert float(ds.mu) == pytest.approx(ds.Fx.values[mask].mean() / ds.Fz.values[mask].mean(), rel=1e-12)
    # full-body forces with the mirror plane: no lateral force
    assert ds.attrs["forces_and_energies"].startswith("full body (twice")
    np.testing.assert_array_equal(ds.Fy, 0.0)


def test_load_control_holds_the_normal_force(tiny_run, tiny_scene):
    assert float(tiny_run.Fz_mean) == pytest.approx(tiny_scene.load_N, rel=0.05)


def test_sliding_record(tiny_run, tiny_scene):
    slid = tiny_run.sliding_distance.values
    assert np.all(np.diff(slid) >= 0)
    assert slid[-1] == pytest.approx(tiny_scene.sliding.distance_m, rel=0.02)
    mask = tiny_run.in_steady_window.values
    d = tiny_scene.sliding.distance_m
    # the last record may overshoot the distance by one step; the window's tolerance is one record interval
    tol = d / tiny_scene.outputs.records
    assert np.all(slid[mask] >= 0.5 * d - 1e-12) and np.all(slid[mask] <= d + tol)
    assert np.all((slid[~mask] < 0.5 * d) | (slid[~mask] > d + tol))
    assert np.all(np.diff(tiny_run.time.values) > 0)
    assert tiny_run.attrs["cost_steps"] > tiny_run.sliding_distance.size
    assert tiny_run.attrs["cost_particles"] > 1000


def test_last_record_is_in_the_steady_window(tiny_run):
    assert bool(tiny_run.in_steady_window.values[-1])


def test_no_particle_enters_the_sphere(tiny_run, tiny_scene):
    h = tiny_scene.discretisation.particle_size_m
    assert float(tiny_run.max_particle_penetration) < 0.5 * h
    assert np.all(tiny_run.particle_penetration.values < 0.5 * h)


def test_material_top_bounds_the_residual_surface(tiny_run, tiny_scene):
    """The highest particle centre, recorded over the run, is near the undeformed top layer's centre
    (-h/2) at the first record, lies above the residual profile's top face minus half a (possibly
    dilated) particle at the end, and stays below the automatic headroom (room for the pile-up)."""
    h = tiny_scene.discretisation.particle_size_m
    top = tiny_run.material_top.values
    assert np.all(np.isfinite(top)) and abs(top[0] + 0.5 * h) < 0.1 * h
    profile_top = float(np.nanmax(tiny_run.profile_z.values))
    assert profile_top - 0.5 * h <= top[-1] + 0.05 * h
    assert top.max() > -0.5 * h + 0.01 * h  # the pile-up lifted some particle
    assert top.max() < tiny_scene.grid_headroom_m


def test_steadiness_is_reported_from_the_run_records(tiny_run, tiny_scene):
    ds = tiny_run
    mask = ds.in_steady_window.values
    idx = np.flatnonzero(mask)
    first, second = idx[: idx.size // 2], idx[idx.size // 2:]
    mu = float(ds.mu)
    mu_1 = ds.Fx.values[first].mean() / ds.Fz.values[first].mean()
    mu_2 = ds.Fx.values[second].mean() / ds.Fz.values[second].mean()
    assert float(ds.mu_drift) == pytest.approx((mu_2 - mu_1) / mu, rel=1e-12)
    rise = ds.material_top.values[second].mean() - ds.material_top.values[first].mean()
    assert float(ds.material_top_rise) == pytest.approx(rise, rel=1e-12, abs=1e-18)
    h = tiny_scene.discretisation.particle_size_m
    expected = abs(float(ds.mu_drift)) <= io.STEADY_MU_DRIFT and rise <= io.STEADY_TOP_RISE_PARTICLES * h
    assert int(ds.steady) == int(expected)


def test_standard_errors_are_written_from_the_run_records(tiny_run, tiny_scene):
    """mu's sampling error is the jackknife over the window's own records (recomputed here from the
    file's series), with units; the groove's (dp, dg, hpu) are at least the contact's lattice-phase term
    (0.002 h for the default grid_local), which each carries as an attribute."""
    ds = tiny_run
    mask = ds.in_steady_window.values
    series = {q: ds[q].values for q in ("Fx", "Fz", "Fx_pl", "Fx_sh")}
    idx = np.flatnonzero(mask)
    fx, fz = series["Fx"][idx], series["Fz"][idx]
    expected = io.jackknife_standard_error(lambda k: fx[k].sum() / fz[k].sum(), idx.size)
    assert float(ds.mu_standard_error) == pytest.approx(expected, rel=1e-12)
    assert ds.mu_standard_error.attrs["units"] == "1" and ds.dp_standard_error.attrs["units"] == "m"
    term = io.groove_lattice_phase_term_m(tiny_scene)
    for q in ("dp", "dg", "hpu"):
        se = ds[f"{q}_standard_error"]
        assert se.attrs["units"] == "m" and se.attrs["lattice_phase_term_m"] == term
        assert np.isfinite(float(se)) and float(se) >= term


def test_an_unsteady_window_warns_and_a_steady_one_does_not(tiny_run):
    import warnings

    unsteady = tiny_run.assign(steady=tiny_run.steady * 0)
    with pytest.warns(run_module.SteadyStateWarning, match="'tiny': the steady window is not a steady state"):
        run_module.warn_if_unsteady(unsteady, "tiny")
    steady = tiny_run.assign(steady=tiny_run.steady * 0 + 1)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        run_module.warn_if_unsteady(steady, "tiny")


def test_warm_up_does_not_warn_about_its_own_scene(monkeypatch):
    import warnings

    monkeypatch.setattr(io, "STEADY_MU_DRIFT", -1.0)  # no window is steady: simulate() alone would warn
    with warnings.catch_warnings():
        warnings.simplefilter("error", run_module.SteadyStateWarning)
        run_module.warm_up(threads=1)
    # the workflow's runs use the active zone: its freezing kernel is compiled too (no cache race later)
    assert transfers.freeze_particles.signatures


def test_units_and_long_names(tiny_run):
    for name, var in tiny_run.variables.items():
        assert "units" in var.attrs, name
        assert "long_name" in var.attrs, name
    assert tiny_run.mu.attrs["units"] == "1" and tiny_run.Fx.attrs["units"] == "N"
    assert tiny_run.dp.attrs["units"] == "m" and tiny_run.external_work.attrs["units"] == "J"


def test_boolean_mask_has_units(tiny_run):
    assert "units" in tiny_run.in_steady_window.attrs


def test_scene_attribute_round_trips(tiny_run, tiny_scene):
    assert Scene.from_dict(json.loads(tiny_run.attrs["scene"])) == tiny_scene
    assert tiny_run.attrs["coating_representation"] == "uncoated"
    assert tiny_run.attrs["interface_regime"] == io.interface_regime(tiny_scene)
    assert json.loads(tiny_run.attrs["steady_window"]) == [0.5, 1.0]
    assert tiny_run.attrs["plough_version"] and tiny_run.attrs["git_commit"]


# ----------------------------------------------------------------------------- stability
@pytest.fixture()
def tiny_state(tiny_scene):
    return solver.init(tiny_scene, n_chunks=2)


@pytest.mark.parametrize("code", [transfers.BAD_LEFT_GRID, transfers.BAD_J, transfers.BAD_NONFINITE])
def test_check_stability_names_step_sliding_distance_and_cause(tiny_state, code):
    state, const = tiny_state
    state.step = 1234
    state.time = 5.0e-4
    state.sphere.slid_m = 123.4e-6
    state.work.acc[:] = 0.0
    state.work.acc[1, transfers.ACC_BAD] = code
    state.work.acc[1, transfers.ACC_BAD_INDEX] = 77
    with pytest.raises(solver.InstabilityError) as err:
        solver.check_stability(state, const)
    msg = str(err.value)
    assert "step 1234" in msg and "sliding distance 123.4 um" in msg
    assert solver.CAUSES[code] in msg
    x = state.particles.x[77] * 1e6  # the offending particle (chunk 1's index) is located
    assert f"particle 77 at ({x[0]:.1f}, {x[1]:.1f}, {x[2]:.1f}) um" in msg and "grid interior" in msg
    # all clear: no error
    state.work.acc[:] = 0.0
    solver.check_stability(state, const)


def end_of_step(state, const):
    """What a step does after its kernels: the grid grows for the particles past a growing face, then the
    checks stop the run on what is left."""
    growth.grow_to_hold(state, const)
    solver.check_stability(state, const)


def _flag_outside(state, const, index, axis, over_m):
    """Mark particle ``index`` as having left the grid ``over_m`` past its high face along ``axis``, as the
    G2P kernel reports it."""
    state.work.acc[:] = 0.0
    state.work.acc[0, transfers.ACC_BAD] = transfers.BAD_LEFT_GRID
    state.work.acc[0, transfers.ACC_BAD_INDEX] = index
    state.particles.x[index, axis] = const.grid_hi[axis] + over_m


def _flag_above_the_top(state, const, index=5, over_m=None):
    """Particle ``index`` risen ``over_m`` (default a tenth of a cell) above the grid's top."""
    _flag_outside(state, const, index, 2, 0.1 * const.grid.dx if over_m is None else over_m)


def test_a_particle_above_a_hand_set_grid_top_is_named_a_prow_and_points_at_the_headroom(tiny_scene):
    scene = tiny_scene.with_(domain=replace(tiny_scene.domain, headroom_m=tiny_scene.grid_headroom_m))
    state, const = solver.init(scene, n_chunks=1)
    assert const.grid_top_limit_m == 0.0  # the scene's own headroom is kept
    _flag_above_the_top(state, const)
    with pytest.raises(solver.InstabilityError, match=r"rose above the grid's top.*domain\.headroom_m") as err:
        end_of_step(state, const)
    assert "stops at" not in str(err.value) and not state.grid_raises
    state.particles.x[5, 2] = 0.0  # left through a side: the general cause
    with pytest.raises(solver.SimulationError) as err:
        end_of_step(state, const)
    assert solver.CAUSES[transfers.BAD_LEFT_GRID] in str(err.value) and "headroom" not in str(err.value)


def _assert_retired(state, const, index):
    """End the step on particle ``index`` (of a state with nothing frozen yet) flagged past a growing face's limit:
    it is retired as debris (plough.mpm.strays), moved to the frozen slot 0 at rest with its position, left out
    of the outputs' particles, and the run goes on."""
    p = state.particles
    before = {name: a[index].copy() for name, a in p._asdict().items()}
    mass_before = float(p.mass.sum())
    end_of_step(state, const)  # no error
    assert state.zone.ranges.p_lo == 1 and state.zone.retired.tolist()[:2] == [True, False]
    for name in ("x", "stress", "mass", "z0", "eps_p"):
        assert np.array_equal(getattr(p, name)[0], before[name]), name
    assert np.all(p.v[0] == 0.0) and state.zone.retired_mass_kg == pytest.approx(float(p.mass[0]))
    assert float(p.mass.sum()) == pytest.approx(mass_before, rel=1e-14)  # moved, not lost
    kept = run_module.kept_particles(state)
    assert kept.n == p.n - 1 and not np.any(np.all(kept.x == p.x[0], axis=1))
    assert run_module.material_top(state) == np.delete(p.x[:, 2], 0).max()


def _flag_past_the_end(state, const, index=7, over_m=None):
    """Particle ``index`` moved ``over_m`` (default a fifth of a cell) past the grid's far end."""
    _flag_outside(state, const, index, 0, 0.2 * const.grid.dx if over_m is None else over_m)


def test_a_particle_past_a_fixed_grids_far_end_is_named_material_pushed_ahead(tiny_scene):
    """With a hand-set headroom the grid does not grow: leaving through the far end (the soft coating's chip of
    the H~ = 0.25 run at h = 5 um) names the block's length and how far ahead of the sphere; leaving through the
    near end keeps the general cause."""
    scene = tiny_scene.with_(domain=replace(tiny_scene.domain, headroom_m=tiny_scene.grid_headroom_m))
    state, const = solver.init(scene, n_chunks=1)
    assert const.grid_end_limit_m == 0.0
    _flag_past_the_end(state, const)
    ahead = (state.particles.x[7, 0] - state.sphere.centre[0]) * 1e6
    end = tiny_scene.domain.length_m * 1e6
    where = rf"past the grid's far end .*the block ends at {end:.1f} um\), {ahead:.1f} um ahead of the sphere's centre"
    with pytest.raises(solver.InstabilityError, match=where + r".*domain\.length_m") as err:
        end_of_step(state, const)
    assert "lengthens" not in str(err.value) and not state.grid_extensions
    state.particles.x[7, 0] = const.grid_lo[0] - 0.2 * const.grid.dx
    with pytest.raises(solver.InstabilityError) as err:
        end_of_step(state, const)
    assert solver.CAUSES[transfers.BAD_LEFT_GRID] in str(err.value) and "far end" not in str(err.value)


def test_a_particle_past_the_far_end_lengthens_the_automatic_grid_up_to_its_limit(tiny_scene):
    """Room for the particle plus a quarter sphere radius, flags the longer grid's own, the run goes on; a
    particle past the limit (two sphere radii past the block's end) is retired as debris (plough.mpm.strays):
    the grid grows no further and the run goes on; the near end never grows."""
    state, const = solver.init(tiny_scene, n_chunks=1)
    r, dx = tiny_scene.sphere.radius_m, const.grid.dx
    (nx, ny, nz), end0 = const.grid.shape, float(const.grid_hi[0])
    assert const.grid_end_limit_m == pytest.approx(tiny_scene.domain.length_m + 2.0 * r, rel=1e-12)
    assert end0 > tiny_scene.domain.length_m  # the grid starts a few cells past the block
    _flag_past_the_end(state, const)
    far = float(state.particles.x[7, 0])
    end_of_step(state, const)  # no error
    assert const.grid.shape[1:] == (ny, nz) and const.grid.shape[0] > nx
    assert far + dx + 0.25 * r <= const.grid_hi[0] < far + 2.0 * dx + 0.25 * r
    assert list(const.shape) == list(const.grid.shape) and np.array_equal(const.grid.origin, solver.init(
        tiny_scene, n_chunks=1)[1].grid.origin)
    assert state.zone.ranges.check_hi[0] == const.grid_hi[0] and state.zone.ranges.n_hi == const.grid.n_nodes
    assert state.zone.ranges.i_free_hi == const.grid.shape[0]  # the new layers are free, not clamped
    assert state.grid_extensions == [(state.step, state.sphere.slid_m, float(const.grid_hi[0]))]
    assert np.array_equal(state.work.flags, boundary_flags(const.grid, tiny_scene.domain.radius_m, True))
    assert state.work.grid_buf.shape[1] == state.work.grid_m.size == state.work.last_push.size == const.grid.n_nodes
    assert np.all(state.work.last_push[nx * ny * nz:] == contact.NEVER_PUSHED)
    _flag_past_the_end(state, const, over_m=2.0 * r)
    _assert_retired(state, const, 7)
    assert len(state.grid_extensions) == 1
    # past the limit by less than the quarter radius wanted: the grid ends at the limit
    state2, const2 = solver.init(tiny_scene, n_chunks=1)
    _flag_past_the_end(state2, const2, over_m=2.0 * r - 3.0 * dx)
    end_of_step(state2, const2)
    assert const2.grid_end_limit_m - dx < const2.grid_hi[0] <= const2.grid_end_limit_m + 1e-12
    # a particle past the far end and above the top on one step, or one past the end (the flagged one) and
    # another above the top: both grow
    for other in (7, 9):
        state3, const3 = solver.init(tiny_scene, n_chunks=1)
        _flag_past_the_end(state3, const3)
        state3.particles.x[other, 2] = const3.grid_hi[2] + 0.1 * dx
        end_of_step(state3, const3)
        assert len(state3.grid_extensions) == len(state3.grid_raises) == 1, other
        assert growth._outside_index(state3) == -1
    state4, const4 = solver.init(tiny_scene, n_chunks=1)
    _flag_past_the_end(state4, const4)
    state4.particles.x[7, 0] = const4.grid_lo[0] - 0.2 * dx
    with pytest.raises(solver.InstabilityError):
        end_of_step(state4, const4)
    assert not state4.grid_extensions


def test_a_particle_flung_past_the_far_end_flies_on_over_the_lengthened_grid(tiny_scene):
    """Behaviour, not bookkeeping: a lone particle flung along x above the surface near the block's end (no
    stress, nothing near it) keeps its velocity as it crosses into the new x layers; nodes past the old end
    left clamped (frozen slabs) would stop it."""
    state, const = solver.init(tiny_scene, n_chunks=1)
    p, dx = state.particles, const.grid.dx
    i = int(np.argmax(p.x[:, 0] + p.x[:, 2]))  # a top particle at the far end
    p.x[i] = [const.grid_hi[0] - 0.3 * dx, p.x[i, 1], 3.0 * dx]
    p.stress[i] = 0.0
    p.C[i] = 0.0
    v0 = 0.08 * dx / const.dt  # slow enough for the kinetic energy check
    p.v[i] = [v0, 0.0, 0.0]
    for _ in range(45):
        solver.step(state, const)
    assert state.grid_extensions and p.x[i, 0] > const.block_end_m + 2.0 * dx + 2.5 * dx
    assert p.v[i, 0] == pytest.approx(v0, rel=1e-6) and abs(p.v[i, 2]) < 1e-6 * v0


def _growth_peak_bytes(state, shape, extra, axis):
    """The memory a growth by ``extra`` layers along ``axis`` should count, written out: the run's arrays, plus
    the added layers of every per-node array or the new per-chunk P2G buffers beside the old, whichever is more."""
    w = state.work
    held = growth._array_bytes(state.particles) + growth._array_bytes(w)
    per_layer = sum(a.nbytes for a in (w.grid_buf, w.grid_m, w.grid_v, w.grid_div, w.cbuf, w.last_push,
                                       w.flags)) // shape[axis]
    return held + max(per_layer * extra, w.grid_buf.nbytes // shape[axis] * (shape[axis] + extra))


def test_a_lengthening_that_would_not_fit_in_memory_stops_the_run_naming_the_memory(tiny_scene, monkeypatch):
    state, const = solver.init(tiny_scene, n_chunks=2)
    shape = const.grid.shape
    for extra in (1, 4, shape[0]):
        peak = _growth_peak_bytes(state, shape, extra, axis=0)
        assert growth.raise_bytes(state, shape, extra, axis=0) == peak
        with pytest.raises(solver.InstabilityError, match=rf"passed the grid's far end, and lengthening it by {extra} "
                                                          "node layers would hold"):
            growth.check_raise_memory(state, shape, extra, peak - 1, axis=0)
    _flag_past_the_end(state, const)  # a fifth of a cell past the end: needs 2 layers, wants a quarter radius more
    need = growth.raise_bytes(state, shape, 2, axis=0)
    monkeypatch.setattr(growth, "physical_memory_bytes", lambda: need)
    end_of_step(state, const)
    assert const.grid.shape[0] == shape[0] + 2 and len(state.grid_extensions) == 1


def test_a_raise_and_a_lengthening_on_one_step_share_the_memory(tiny_scene, monkeypatch):
    """Memory for the two needed growths, not for the doubled top and then the lengthening: the top rises by
    the room its particle needs and the grid still lengthens, where sizing the raise alone (the doubled room
    fits by itself) would leave too little for the lengthening and stop the run."""
    state, const = solver.init(tiny_scene, n_chunks=2)
    shape = const.grid.shape
    _flag_past_the_end(state, const)  # needs 2 x layers
    state.particles.x[5, 2] = const.grid_hi[2] + 0.1 * const.grid.dx  # needs 2 z layers; doubling wants more
    assert growth._layers_past(state, const, 0) == 2
    wanted = math.ceil(const.grid_hi[2] / const.grid.dx - 1e-9)
    assert wanted > 2
    both_needed = growth.growth_bytes(state, shape, [(2, 2), (0, 2)])
    assert growth.raise_bytes(state, shape, wanted) <= both_needed  # the doubled room alone would fit
    assert growth.growth_bytes(state, shape, [(2, wanted), (0, 2)]) > both_needed  # but not with the lengthening
    # a byte less: the run stops before either grows, naming both
    monkeypatch.setattr(growth, "physical_memory_bytes", lambda: both_needed - 1)
    with pytest.raises(solver.InstabilityError, match=r"raising it by 2 node layers and then lengthening it by 2 "
                                                      "would hold"):
        end_of_step(state, const)
    assert const.grid.shape == shape and not state.grid_raises and not state.grid_extensions
    monkeypatch.setattr(growth, "physical_memory_bytes", lambda: both_needed)
    end_of_step(state, const)
    assert const.grid.shape == (shape[0] + 2, shape[1], shape[2] + 2)
    assert len(state.grid_raises) == len(state.grid_extensions) == 1 and growth._outside_index(state) == -1
    # the same whichever of the two particles the kernel flagged
    state1, const1 = solver.init(tiny_scene, n_chunks=2)
    _flag_above_the_top(state1, const1)
    state1.particles.x[7, 0] = const1.grid_hi[0] + 0.2 * const1.grid.dx
    end_of_step(state1, const1)
    assert const1.grid.shape == (shape[0] + 2, shape[1], shape[2] + 2)
    # with memory for the doubled top and the needed lengthening the top doubles (the lengthening then takes
    # what room it wants within what is left)
    state2, const2 = solver.init(tiny_scene, n_chunks=2)
    _flag_past_the_end(state2, const2)
    state2.particles.x[5, 2] = const2.grid_hi[2] + 0.1 * const2.grid.dx
    monkeypatch.setattr(growth, "physical_memory_bytes",
                        lambda: growth.growth_bytes(state2, shape, [(2, wanted), (0, 2)]))
    end_of_step(state2, const2)
    assert const2.grid.shape[2] == shape[2] + wanted and const2.grid.shape[0] >= shape[0] + 2
    assert len(state2.grid_raises) == len(state2.grid_extensions) == 1 and growth._outside_index(state2) == -1


def test_growth_bytes_counts_growths_in_turn_as_the_grid_really_grows(tiny_scene):
    """Two growths counted in turn: the peak is the larger of the first growth's and the second's counted on the
    arrays the first really left; each growth adds exactly its layers of every per-node array."""
    state, const = solver.init(tiny_scene, n_chunks=2)
    shape = const.grid.shape
    assert growth.growth_bytes(state, shape, [(0, 4)]) == growth.raise_bytes(state, shape, 4, axis=0)
    predicted = growth.growth_bytes(state, shape, [(2, 3), (0, 4)])
    first_peak = growth.raise_bytes(state, shape, 3, axis=2)

    def held():
        return growth._array_bytes(state.particles) + growth._array_bytes(state.work)

    def node_bytes():
        w = state.work
        return sum(a.nbytes for a in (w.grid_buf, w.grid_m, w.grid_v, w.grid_div, w.cbuf, w.last_push, w.flags))

    held0, node0 = held(), node_bytes()
    growth.grow_grid(state, const, 2, 3)
    assert held() - held0 == node0 * 3 // shape[2]
    second_peak = growth.raise_bytes(state, const.grid.shape, 4, axis=0)
    assert predicted == max(first_peak, second_peak) > growth.raise_bytes(
        solver.init(tiny_scene, n_chunks=2)[0], shape, 4, axis=0)  # more than the lengthening on the old grid
    held1, node1 = held(), node_bytes()
    growth.grow_grid(state, const, 0, 4)
    assert held() - held1 == node1 * 4 // shape[0]


def _assert_same_run(a, b, scene):
    """Two states of one scene hold the same particles, sphere and contact forces (to round-off), and they
    moved: a growth that scrambled the contact memory or the grid would not match."""
    for name in ("x", "v", "stress", "eps_p", "J"):
        np.testing.assert_allclose(getattr(a.particles, name), getattr(b.particles, name),
                                   rtol=1e-12, atol=1e-300, err_msg=name)
    np.testing.assert_allclose(a.sphere.centre, b.sphere.centre, rtol=1e-12)
    np.testing.assert_allclose(a.work.contact_out, b.work.contact_out, rtol=1e-10, atol=1e-18)
    assert np.abs(a.particles.x - solver.init(scene, n_chunks=1)[0].particles.x).max() > 1e-7


def _grown_at_start_and_both_run_on(scene, late, c_late, axis, extra):
    """The same scene grown by ``extra`` layers along ``axis`` at step 0 (flags those of the grown grid); then
    both it and ``late`` (grown mid-run) step on to 150 steps past ``late``'s step. Returns the one grown at
    the start."""
    start, c_start = solver.init(scene, n_chunks=1)
    growth.grow_grid(start, c_start, axis, extra)
    assert c_start.grid.shape == c_late.grid.shape
    assert np.array_equal(start.work.flags, boundary_flags(c_start.grid, scene.domain.radius_m, True))
    for _ in range(late.step + 150 - start.step):
        solver.step(start, c_start)
    for _ in range(150):
        solver.step(late, c_late)
    assert start.step == late.step
    return start, c_start


@pytest.mark.parametrize("zone", [None, 2.0], ids=["whole block", "active zone"])
def test_a_run_whose_grid_was_lengthened_goes_on_as_if_it_had_started_on_the_longer_grid(tiny_scene, zone):
    """Lengthened mid-slide (contact memory and grid buffers in use, the zone at the block's end) against
    lengthened at step 0: same particles, same forces."""
    scene = tiny_scene.with_(discretisation=replace(tiny_scene.discretisation, active_zone_contact_radii=zone))
    late, c_late = solver.init(scene, n_chunks=1)
    while not (late.sphere.phase == "slide" and late.sphere.slid_m >= 10e-6
               and late.zone.ranges.p_hi == late.particles.n):
        solver.step(late, c_late)  # until the zone reached the block's end: it must follow the new end
    growth.grow_grid(late, c_late, 0, 6)
    start, c_start = _grown_at_start_and_both_run_on(scene, late, c_late, 0, 6)
    assert late.zone.ranges.n_hi == start.zone.ranges.n_hi == c_late.grid.n_nodes
    assert late.zone.ranges.check_hi[0] == start.zone.ranges.check_hi[0] == c_late.grid_hi[0]
    _assert_same_run(late, start, scene)


def _flag_past_the_side(state, const, index=7, over_m=None):
    """Particle ``index`` moved ``over_m`` (default a fifth of a cell) out through the grid's side (high y)."""
    _flag_outside(state, const, index, 1, 0.2 * const.grid.dx if over_m is None else over_m)


def test_a_particle_past_a_fixed_grids_side_is_named_material_thrown_sideways(tiny_scene):
    """With a hand-set headroom the grid does not widen: leaving through the side face names it and the
    block's radius (the f = 0.5 coated run at h = 2.5 um threw a coating particle out there)."""
    scene = tiny_scene.with_(domain=replace(tiny_scene.domain, headroom_m=tiny_scene.grid_headroom_m))
    state, const = solver.init(scene, n_chunks=1)
    assert const.grid_side_limit_m == 0.0
    _flag_past_the_side(state, const)
    side = tiny_scene.domain.radius_m * 1e6
    with pytest.raises(solver.InstabilityError, match=rf"out through the grid's side .*the block's side is at "
                                                      rf"{side:.1f} um\).*domain\.radius_m") as err:
        end_of_step(state, const)
    assert "widens" not in str(err.value) and not state.grid_widenings


def test_a_particle_past_the_side_widens_the_automatic_grid_up_to_its_limit(tiny_scene):
    """Room for the particle plus a quarter sphere radius along y, flags the wider grid's own (fixed below the
    surface, free above), the run goes on; a particle past the limit (two sphere radii past the block's side)
    is retired as debris and the run goes on; a particle through the bottom on the same step is not hidden by
    the widening."""
    state, const = solver.init(tiny_scene, n_chunks=1)
    r, dx = tiny_scene.sphere.radius_m, const.grid.dx
    (nx, ny, nz), side0 = const.grid.shape, float(const.grid_hi[1])
    assert const.grid_side_limit_m == pytest.approx(tiny_scene.domain.radius_m + 2.0 * r, rel=1e-12)
    assert side0 > tiny_scene.domain.radius_m
    old_flags = state.work.flags.copy()
    _flag_past_the_side(state, const)
    far = float(state.particles.x[7, 1])
    end_of_step(state, const)  # no error
    assert const.grid.shape[0] == nx and const.grid.shape[2] == nz and const.grid.shape[1] > ny
    assert far + dx + 0.25 * r <= const.grid_hi[1] < far + 2.0 * dx + 0.25 * r
    assert list(const.shape) == list(const.grid.shape)
    assert state.zone.ranges.check_hi[1] == const.grid_hi[1] and state.zone.ranges.n_hi == const.grid.n_nodes
    assert state.grid_widenings == [(state.step, state.sphere.slid_m, float(const.grid_hi[1]))]
    new_ny = const.grid.shape[1]
    flags = state.work.flags.reshape(nx, new_ny, nz)
    assert np.array_equal(flags[:, :ny, :], old_flags.reshape(nx, ny, nz))
    assert np.array_equal(state.work.flags, boundary_flags(const.grid, tiny_scene.domain.radius_m, True))
    z = const.grid.node_positions()[:, 2].reshape(nx, new_ny, nz)
    assert np.all(flags[:, ny:, :][z[:, ny:, :] < 0] == FIXED) and np.all(flags[:, ny:, :][z[:, ny:, :] >= 0] == FREE)
    assert state.work.grid_buf.shape[1] == state.work.grid_m.size == state.work.last_push.size == const.grid.n_nodes
    _flag_past_the_side(state, const, over_m=2.0 * r)
    _assert_retired(state, const, 7)
    assert len(state.grid_widenings) == 1
    state2, const2 = solver.init(tiny_scene, n_chunks=1)
    _flag_past_the_side(state2, const2)
    state2.particles.x[9, 2] = const2.grid_lo[2] - dx
    with pytest.raises(solver.InstabilityError, match="particle 9 "):
        end_of_step(state2, const2)
    assert not state2.grid_widenings and const2.grid.shape == (nx, ny, nz)


def test_a_particle_past_the_sides_limit_is_retired_and_another_above_the_top_still_raises_it(tiny_scene):
    """A particle out through the side beyond the limit and another above the top on one step: the first is
    retired as debris, the top is raised for the second (now in slot 5 + 1: the retired one moved first)."""
    state, const = solver.init(tiny_scene, n_chunks=1)
    shape = const.grid.shape
    _flag_above_the_top(state, const)
    above = state.particles.x[5].copy()
    state.particles.x[9, 1] = const.grid_side_limit_m + const.grid.dx
    end_of_step(state, const)
    assert state.zone.ranges.p_lo == 1 and state.zone.retired.tolist()[:2] == [True, False]
    assert np.array_equal(state.particles.x[6], above)  # the raised-for particle, one slot on
    assert len(state.grid_raises) == 1 and not state.grid_widenings and const.grid.shape[1] == shape[1]


def test_a_full_block_widens_at_its_high_side_with_its_own_flags(tiny_scene):
    """Without the mirror plane the block spans y in [-R, R]: the high side widens with the flags of the wider
    full grid; the low side does not grow (a particle out there stops the run)."""
    scene = tiny_scene.with_(domain=replace(tiny_scene.domain, symmetric=False))
    state, const = solver.init(scene, n_chunks=1)
    shape = const.grid.shape
    _flag_past_the_side(state, const)
    end_of_step(state, const)
    assert const.grid.shape[1] > shape[1] and len(state.grid_widenings) == 1
    assert np.array_equal(state.work.flags, boundary_flags(const.grid, scene.domain.radius_m, False))
    state.particles.x[7, 1] = const.grid_lo[1] - 0.2 * const.grid.dx
    state.work.acc[0, transfers.ACC_BAD] = transfers.BAD_LEFT_GRID
    with pytest.raises(solver.InstabilityError, match="particle 7 "):
        end_of_step(state, const)
    assert len(state.grid_widenings) == 1


def test_three_growths_on_one_step_all_grow_and_share_the_memory(tiny_scene, monkeypatch):
    """A particle above the top, one past the far end and one past the side on one step: all three growths
    happen, and the memory check counts them together (a byte less than the three needed stops the run before
    any grows, naming all three)."""
    state, const = solver.init(tiny_scene, n_chunks=2)
    shape, dx = const.grid.shape, const.grid.dx
    _flag_past_the_side(state, const)  # needs 2 y layers
    state.particles.x[5, 2] = const.grid_hi[2] + 0.1 * dx  # 2 z layers
    state.particles.x[9, 0] = const.grid_hi[0] + 0.2 * dx  # 2 x layers
    needed = growth.growth_bytes(state, shape, [(2, 2), (0, 2), (1, 2)])
    monkeypatch.setattr(growth, "physical_memory_bytes", lambda: needed - 1)
    with pytest.raises(solver.InstabilityError, match=r"raising it by 2 node layers and then lengthening it by 2 "
                                                      r"and then widening it by 2 would hold"):
        end_of_step(state, const)
    assert const.grid.shape == shape and not (state.grid_raises or state.grid_extensions or state.grid_widenings)
    monkeypatch.setattr(growth, "physical_memory_bytes", lambda: needed)
    end_of_step(state, const)
    assert const.grid.shape == (shape[0] + 2, shape[1] + 2, shape[2] + 2)
    assert len(state.grid_raises) == len(state.grid_extensions) == len(state.grid_widenings) == 1
    assert growth._outside_index(state) == -1
    assert np.array_equal(state.work.flags, boundary_flags(const.grid, tiny_scene.domain.radius_m, True))


@pytest.mark.parametrize("zone", [None, 2.0], ids=["whole block", "active zone"])
def test_a_run_whose_grid_was_widened_goes_on_as_if_it_had_started_on_the_wider_grid(tiny_scene, zone):
    """Widened mid-slide (contact memory and grid buffers in use) against widened at step 0: same particles,
    same forces; the zone's node range keeps its slabs, each slab wider."""
    scene = tiny_scene.with_(discretisation=replace(tiny_scene.discretisation, active_zone_contact_radii=zone))
    late, c_late = solver.init(scene, n_chunks=1)
    while not (late.sphere.phase == "slide" and late.sphere.slid_m >= 10e-6):
        solver.step(late, c_late)
    old_slab, slabs = c_late.grid.shape[1] * c_late.grid.shape[2], (late.zone.ranges.n_lo, late.zone.ranges.n_hi)
    growth.grow_grid(late, c_late, 1, 5)
    new_slab = c_late.grid.shape[1] * c_late.grid.shape[2]
    assert (late.zone.ranges.n_lo, late.zone.ranges.n_hi) == (slabs[0] // old_slab * new_slab,
                                                              slabs[1] // old_slab * new_slab)
    start, c_start = _grown_at_start_and_both_run_on(scene, late, c_late, 1, 5)
    assert (late.zone.ranges.n_lo, late.zone.ranges.n_hi) == (start.zone.ranges.n_lo, start.zone.ranges.n_hi)
    assert (late.zone.ranges.p_hi - late.zone.ranges.p_lo < late.particles.n) == (zone is not None)
    assert late.zone.ranges.check_hi[1] == start.zone.ranges.check_hi[1] == c_late.grid_hi[1]
    _assert_same_run(late, start, scene)


def test_a_particle_above_the_automatic_grid_top_raises_it(tiny_scene):
    """The room above the surface doubles, every node keeps its flags, and the run goes on."""
    state, const = solver.init(tiny_scene, n_chunks=1)
    old_shape, old_top, old_flags = const.grid.shape, float(const.grid_hi[2]), state.work.flags.copy()
    _flag_above_the_top(state, const)
    end_of_step(state, const)  # no error
    nx, ny, nz = const.grid.shape
    assert (nx, ny) == old_shape[:2] and nz > old_shape[2]
    assert 2.0 * old_top <= const.grid_hi[2] < 2.0 * old_top + const.grid.dx
    assert const.grid_hi[2] == pytest.approx(const.grid.upper[2] - const.grid.dx, rel=1e-12)
    assert state.zone.ranges.check_hi[2] == const.grid_hi[2] and list(const.shape) == [nx, ny, nz]
    assert state.grid_raises == [(state.step, state.sphere.slid_m, float(const.grid_hi[2]))]
    flags = state.work.flags.reshape(nx, ny, nz)
    assert np.array_equal(flags[:, :, :old_shape[2]], old_flags.reshape(old_shape))
    assert np.array_equal(state.work.flags, boundary_flags(const.grid, tiny_scene.domain.radius_m, True))
    for name in ("grid_m", "grid_div", "last_push"):
        assert getattr(state.work, name).shape[0] == nx * ny * nz, name
    assert state.work.grid_v.shape == (nx * ny * nz, 6) and state.work.grid_buf.shape[1] == nx * ny * nz
    # another particle left through the bottom on the same step: the raise does not hide it
    state2, const2 = solver.init(tiny_scene, n_chunks=1)
    _flag_above_the_top(state2, const2)
    state2.particles.x[9, 2] = const2.grid_lo[2] - const2.grid.dx
    with pytest.raises(solver.InstabilityError, match="particle 9 ") as err:
        end_of_step(state2, const2)
    assert solver.CAUSES[transfers.BAD_LEFT_GRID] in str(err.value)
    assert not state2.grid_raises and const2.grid.shape == old_shape  # nothing grown for a run that stops


def test_the_automatic_grid_top_stops_at_the_spheres_top_and_a_particle_past_it_is_retired(tiny_scene):
    state, const = solver.init(tiny_scene, n_chunks=1)
    assert const.grid_top_limit_m == pytest.approx(2.0 * tiny_scene.sphere.radius_m)
    _flag_above_the_top(state, const, over_m=2.0 * tiny_scene.sphere.radius_m)
    _assert_retired(state, const, 5)
    assert not state.grid_raises


def test_a_raise_that_doubling_would_carry_past_the_limit_stops_at_the_limit(tiny_scene):
    """Room for the particle below the limit: the top goes to the limit (not refused because 2x passes it)."""
    state, const = solver.init(tiny_scene, n_chunks=1)
    dx, top0 = const.grid.dx, float(const.grid_hi[2])
    const = replace(const, grid_top_limit_m=1.5 * top0)  # the constants are frozen: a copy
    _flag_above_the_top(state, const)
    end_of_step(state, const)
    assert const.grid_top_limit_m - dx < const.grid_hi[2] <= const.grid_top_limit_m + 1e-12
    assert state.particles.x[5, 2] < const.grid_hi[2]
    _flag_above_the_top(state, const)  # no room left: the particle is retired, the top stays
    top = float(const.grid_hi[2])
    _assert_retired(state, const, 5)
    assert len(state.grid_raises) == 1 and const.grid_hi[2] == top


def test_a_raise_that_would_not_fit_in_memory_stops_the_run_naming_the_memory(tiny_scene, monkeypatch):
    """A raise counts the run's arrays and, at its peak, the new per-chunk P2G buffers beside the old ones or
    the added layers: exactly enough memory passes, a byte less stops the run with nothing grown; where the
    doubled room does not fit but the room the particle needs does, the top rises by that much."""
    state, const = solver.init(tiny_scene, n_chunks=2)
    shape = const.grid.shape
    for extra in (1, 3, shape[2]):
        peak = _growth_peak_bytes(state, shape, extra, axis=2)
        assert growth.raise_bytes(state, shape, extra) == peak
        growth.check_raise_memory(state, shape, extra, peak)
        with pytest.raises(solver.InstabilityError, match=rf"raising it by {extra} node layers would hold"):
            growth.check_raise_memory(state, shape, extra, peak - 1)
    # through check_stability: the particle, a tenth of a cell over the top, needs 2 layers (one cell of room
    # above it); doubling wants more
    _flag_above_the_top(state, const)
    assert 2 < shape[2]
    need = growth.raise_bytes(state, shape, 2)
    monkeypatch.setattr(growth, "physical_memory_bytes", lambda: need - 1)
    with pytest.raises(solver.InstabilityError, match=r"raising it by 2 node layers would hold .* GiB, more than"):
        end_of_step(state, const)
    assert const.grid.shape == shape and not state.grid_raises and state.work.grid_m.size == np.prod(shape)
    monkeypatch.setattr(growth, "physical_memory_bytes", lambda: need)
    end_of_step(state, const)
    assert const.grid.shape[2] == shape[2] + 2 and len(state.grid_raises) == 1
    assert state.particles.x[5, 2] < const.grid_hi[2]


@pytest.mark.parametrize("zone", [None, 2.0], ids=["whole block", "active zone"])
def test_a_run_whose_grid_top_was_raised_goes_on_as_if_it_had_started_on_the_taller_grid(tiny_scene, zone):
    """Raised mid-slide (contact memory and grid buffers in use) against raised at step 0, which is the
    taller grid from the start (same flags as the taller grid's own): same particles, same forces."""
    scene = tiny_scene.with_(discretisation=replace(tiny_scene.discretisation, active_zone_contact_radii=zone))
    raised_late, c_late = solver.init(scene, n_chunks=1)
    while not (raised_late.sphere.phase == "slide" and raised_late.sphere.slid_m >= 10e-6):
        solver.step(raised_late, c_late)
    assert growth.grow_face(raised_late, c_late, 2)
    from_start, c_start = solver.init(scene, n_chunks=1)
    assert growth.grow_face(from_start, c_start, 2)
    assert np.array_equal(from_start.work.flags, boundary_flags(c_start.grid, scene.domain.radius_m, True))
    assert c_start.grid.shape == c_late.grid.shape
    for _ in range(raised_late.step + 150 - from_start.step):
        solver.step(from_start, c_start)
    for _ in range(150):
        solver.step(raised_late, c_late)
    assert from_start.step == raised_late.step and raised_late.sphere.slid_m > 10e-6
    assert (raised_late.zone.ranges.p_hi - raised_late.zone.ranges.p_lo < raised_late.particles.n) == (zone is not None)
    _assert_same_run(raised_late, from_start, scene)


def test_a_raised_grid_top_is_recorded_and_told(tiny_scene, tiny_run, monkeypatch, capsys):
    assert tiny_run.attrs["cost_grid_top_raises"] == 0
    _, const = solver.init(tiny_scene, n_chunks=1)
    assert tiny_run.attrs["cost_grid_top_m"] == pytest.approx(const.grid_hi[2], rel=1e-12)
    assert tiny_run.attrs["cost_grid_nodes"] == tiny_run.attrs["cost_grid_nodes_end"] == const.grid.n_nodes
    real_step = solver.step

    def step_raising_once(s, c):  # as growth.grow_to_hold would on a particle past the top, the end, then the side
        real_step(s, c)
        if s.step == 40:
            assert growth.grow_face(s, c, 2)
        if s.step == 50:
            s.particles.x[3, 0] = c.grid_hi[0] + 0.1 * c.grid.dx
            assert growth.grow_face(s, c, 0)
            s.particles.x[3, 0] -= 0.1 * c.grid.dx
        if s.step == 60:
            s.particles.x[3, 1] = c.grid_hi[1] + 0.1 * c.grid.dx
            assert growth.grow_face(s, c, 1)
            s.particles.x[3, 1] -= 0.1 * c.grid.dx

    monkeypatch.setattr(solver, "step", step_raising_once)
    short = tiny_scene.with_(sliding=replace(tiny_scene.sliding, distance_m=100e-6))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", run_module.SteadyStateWarning)  # a short slide; not what is tested
        ds = simulate(short, progress=True, threads=1)
    assert ds.attrs["cost_grid_top_raises"] == 1
    assert ds.attrs["cost_grid_top_m"] >= 2.0 * const.grid_hi[2]
    assert ds.attrs["cost_grid_nodes_end"] > ds.attrs["cost_grid_nodes"] == const.grid.n_nodes
    captured = capsys.readouterr()
    told = captured.err  # with the progress bar, on standard error: the workflow keeps it in the run's log
    assert "material reached the grid" not in captured.out
    assert "material reached the grid's top at step 40" in told
    assert "material passed the grid's far end at step 50" in told and "the grid lengthened to x = " in told
    assert tiny_run.attrs["cost_grid_end_extensions"] == 0
    assert tiny_run.attrs["cost_grid_end_m"] == pytest.approx(const.grid_hi[0], rel=1e-12)
    assert ds.attrs["cost_grid_end_extensions"] == 1
    assert ds.attrs["cost_grid_end_m"] > const.grid_hi[0] + 0.25 * tiny_scene.sphere.radius_m
    assert "material passed the grid's side at step 60" in told and "the grid widened to y = " in told
    assert tiny_run.attrs["cost_grid_side_widenings"] == 0
    assert tiny_run.attrs["cost_grid_side_m"] == pytest.approx(const.grid_hi[1], rel=1e-12)
    assert ds.attrs["cost_grid_side_widenings"] == 1
    assert ds.attrs["cost_grid_side_m"] > const.grid_hi[1] + 0.25 * tiny_scene.sphere.radius_m


def test_grid_top_follows_the_headroom(tiny_scene):
    """Material may rise to the grid interior's top: the headroom plus the padding (2 to 3 cells)."""
    for headroom in (None, 3.0 * tiny_scene.grid_headroom_m):
        scene = tiny_scene.with_(domain=replace(tiny_scene.domain, headroom_m=headroom))
        _, const = solver.init(scene, n_chunks=1)
        top, dx = const.grid_hi[2], const.grid.dx
        assert scene.grid_headroom_m + 2 * dx <= top + 1e-12 < scene.grid_headroom_m + 3 * dx


def test_check_stability_flags_runaway_kinetic_energy(tiny_state):
    state, const = tiny_state
    state.step = 10
    state.sphere.slid_m = 0.0
    state.work.external_work = 1e-9
    state.work.acc[:] = 0.0
    state.work.acc[0, transfers.ACC_KINETIC] = 10.0 * (2e-9 + const.load_N * const.grid.dx)
    with pytest.raises(solver.InstabilityError, match=r"step 10 .*sliding distance 0\.0 um.*kinetic energy"):
        end_of_step(state, const)


def test_non_finite_particle_during_sliding_stops_the_run(tiny_state):
    state, const = tiny_state
    for _ in range(20000):
        solver.step(state, const)
        if state.sphere.phase == "slide" and state.sphere.slid_m >= 20e-6:
            break
    assert state.sphere.phase == "slide"
    state.particles.v[0, 2] = np.nan
    failing_step = state.step
    with pytest.raises(solver.InstabilityError) as err:
        solver.step(state, const)
    msg = str(err.value)
    assert f"at step {failing_step} " in msg
    slid_um = state.sphere.slid_m * 1e6  # the sphere had moved in the failing step
    assert f"sliding distance {slid_um:.1f} um" in msg and slid_um >= 20.0
    assert "non-finite" in msg


@pytest.fixture()
def allow_inertia(monkeypatch):
    """Lift the inertia-number refusal so that the run-time guards behind it can be tested."""
    monkeypatch.setattr(scene_module, "INERTIA_MAX", math.inf)


def test_inertia_dominated_scene_is_refused_before_running():
    with pytest.raises(ValueError, match=r"inertia number ms rho v\^2 / H = .* above the allowed"):
        Scene.from_dict(scene_dict(**UNSTABLE))


def test_inertia_dominated_scene_raises_simulation_error(allow_inertia):
    scene = Scene.from_dict(scene_dict(**UNSTABLE))  # passes validation with the refusal lifted
    # either the kinetic-energy / state checks stop it, or the sphere flies off and the run ends
    # with the lost-contact error: both name inertia as the cause
    with pytest.raises(solver.SimulationError,
                       match=r"(unstable run at step \d+ \(t = .*sliding distance .* um\))|(lost contact.*inertia)"):
        simulate(scene, progress=False, threads=1)


def test_lost_contact_while_sliding_is_an_error(allow_inertia):
    scene = Scene.from_dict(scene_dict(sliding={"distance_um": 200, "speed_m_s": 200.0}))
    with pytest.raises(solver.SimulationError) as err:
        with np.errstate(invalid="ignore"):
            simulate(scene, progress=False, threads=1)
    # lost contact is not the state going unstable: the workflow never records it as a failed finest run
    assert "lost contact" in str(err.value) and not isinstance(err.value, solver.InstabilityError)


def test_sphere_stays_in_contact_while_sliding(tiny_scene):
    """No chattering: the load controller's gain comes from the elastic contact stiffness.

    With a gain tuned to the plastic stiffness Fn / dp (an earlier version) the per-step normal
    force was 0 on ~90% of the steps and the vertical speed swung by +-75% of the pressing speed.
    """
    state, const = solver.init(tiny_scene, n_chunks=1)
    fz, vz = [], []
    while state.sphere.phase != "done":
        solver.step(state, const)
        if state.sphere.phase == "slide":
            out = state.work.contact_out
            fz.append(out[contact.OUT_FN + 2] + out[contact.OUT_FT + 2])
            vz.append(state.sphere.velocity[2])
    fz, vz = np.array(fz), np.array(vz)
    assert np.mean(fz > 0) > 0.5
    assert np.std(vz) < 0.1 * const.press_speed


# ----------------------------------------------------------------------------- active zone
def zoned(scene: Scene, k: float | None) -> Scene:
    return replace(scene, discretisation=replace(scene.discretisation, active_zone_contact_radii=k))


@pytest.fixture
def no_zone_floor(monkeypatch):
    """The tiny scene's zone in contact radii (its 20 h floor would cover the whole 40 h block)."""
    monkeypatch.setattr(scene_module, "ACTIVE_ZONE_MIN_PARTICLES", 0.0)


def test_active_zone_half_width_has_a_floor_in_particle_sizes(tiny_scene):
    a, h = tiny_scene.expected_contact()[0], tiny_scene.discretisation.particle_size_m
    assert zoned(tiny_scene, None).active_zone_half_width_m is None
    assert zoned(tiny_scene, 4.0).active_zone_half_width_m == pytest.approx(20 * h)  # 4 a = 13 h here
    assert zoned(tiny_scene, 8.0).active_zone_half_width_m == pytest.approx(8 * a)
    assert solver.init(zoned(tiny_scene, 4.0), n_chunks=1)[1].zone_half_width_m == pytest.approx(20 * h)


def test_active_zone_follows_the_sphere_and_freezes_what_it_leaves(tiny_scene, no_zone_floor):
    """The zone holds the particles that started within k a of the sphere's centre; those it has
    left keep their position and stress, those it has not reached are untouched, and the grid
    slabs it has left hold zero velocity."""
    state, const = solver.init(zoned(tiny_scene, 2.0), n_chunks=1)
    p = state.particles
    seeded = p.x.copy()
    half_width = 2.0 * tiny_scene.expected_contact()[0]
    assert const.zone_half_width_m == pytest.approx(half_width)
    ranges = []
    frozen = None
    g = const.grid
    slab = g.shape[1] * g.shape[2]
    while state.sphere.phase != "done":
        xc = state.sphere.centre[0]  # where the step's zone update sees the sphere
        solver.step(state, const)
        z = state.zone.ranges  # the ranges the step worked on (each update replaces them)
        ranges.append((z.p_lo, z.p_hi, z.n_lo, z.n_hi, z.i_free_lo, z.i_free_hi))
        # every active particle's stencil (x slabs bx .. bx + 2) lies in the node range the step worked on
        bx = np.floor((p.x[z.p_lo:z.p_hi, 0] - g.origin[0]) / g.dx - 0.5)
        assert bx.min() >= z.n_lo // slab and bx.max() + 2 < z.n_hi // slab
        if frozen is None and state.sphere.slid_m > 0.5 * tiny_scene.sliding.distance_m:
            frozen = (z.p_lo, p.x[:z.p_lo].copy(), p.stress[:z.p_lo].copy(), state.step)
    # the zone's ends bracket the sphere's centre -/+ k a in the particles' initial x
    x0 = const.zone_x0_m
    assert x0[z.p_lo] >= xc - half_width and x0[z.p_lo - 1] < xc - half_width
    assert x0[z.p_hi - 1] <= xc + half_width and x0[z.p_hi] > xc + half_width
    assert 0 < z.p_lo < z.p_hi < p.n
    # every range only moves forward
    assert np.all(np.diff(np.array(ranges), axis=0) >= 0)
    # frozen at mid-slide: unchanged to the end of the run, and at rest
    p_lo, x_then, stress_then, step_then = frozen
    assert p_lo > 0 and state.step > step_then + 100
    np.testing.assert_array_equal(p.x[:p_lo], x_then)
    np.testing.assert_array_equal(p.stress[:p_lo], stress_then)
    assert np.all(p.v[:z.p_lo] == 0.0)
    # ahead of the zone: never touched
    np.testing.assert_array_equal(p.x[z.p_hi:], seeded[z.p_hi:])
    assert np.all(p.stress[z.p_hi:] == 0.0) and np.all(p.v[z.p_hi:] == 0.0)
    # the slabs left behind hold no mass and no velocity
    assert np.all(state.work.grid_v[:z.n_lo] == 0.0) and np.all(state.work.grid_m[:z.n_lo] == 0.0)
    # the material that deformed before it froze still carries stress
    assert np.abs(p.stress[:z.p_lo]).max() > 0.0


def test_a_particle_leaving_the_active_zone_stops_the_run_naming_the_zone(tiny_scene, no_zone_floor):
    state, const = solver.init(zoned(tiny_scene, 2.0), n_chunks=1)
    while state.sphere.phase != "slide":
        solver.step(state, const)
    z = state.zone.ranges
    assert z.p_hi < state.particles.n  # the zone's front clamp is on
    state.particles.x[z.p_hi - 1, 0] = z.check_hi[0] + 0.5 * const.grid.dx  # pushed past the zone's slabs
    with pytest.raises(solver.SimulationError, match=r"active zone's grid slabs.*active_zone_contact_radii"):
        solver.step(state, const)


def test_an_active_zone_covering_the_block_changes_nothing(tiny_scene, tiny_run):
    wide = simulate(zoned(tiny_scene, 100.0), progress=False, threads=1)
    for q in ("mu", "mu_pl", "dp", "Fz_mean", "penetration"):
        assert float(wide[q]) == float(tiny_run[q])
    assert wide.attrs["cost_active_fraction"] == 1.0
    assert float(wide.frozen_kinetic_loss[-1]) == 0.0


def test_an_active_zone_reports_its_work_and_keeps_the_energy_balance(tiny_scene, tiny_run, no_zone_floor):
    """A zone of 4 expected contact radii works on about half the particle-steps of the tiny scene,
    keeps the energy account (the frozen particles' elastic energy stays in it, their kinetic
    energy is counted as lost) and moves mu by a few per cent, far less than halving h does
    (-8% to +24% on the reference scenes, README)."""
    ds = simulate(zoned(tiny_scene, 4.0), progress=False, threads=1)
    frac = ds.attrs["cost_active_fraction"]
    assert 0.3 < frac < 0.8
    assert ds.attrs["cost_particle_steps"] == pytest.approx(frac * ds.attrs["cost_particles"] * ds.attrs["cost_steps"])
    assert io.energy_balance(ds) == pytest.approx(1.0, rel=0.10)
    assert float(ds.frozen_kinetic_loss[-1]) > 0.0
    assert float(ds.mu) == pytest.approx(float(tiny_run.mu), rel=0.05)


def test_stop_when_steady_ends_the_slide_early_and_says_so():
    """A loose tolerance stops the tiny scene's slide early; the outputs refer to the distance slid."""
    d = scene_dict()
    d["sliding"] = {**d["sliding"], "stop_when_steady": True, "steady_tolerance": 0.2}
    scene = Scene.from_dict(d)
    ds = simulate(scene, progress=False, threads=1)
    slid = ds.attrs["slid_distance_m"]
    assert ds.attrs["stopped_when_steady"] == 1
    assert run_module.SteadyStop(scene).minimum <= slid < scene.sliding.distance_m
    assert float(ds.sliding_distance.max()) <= slid + 1e-12
    window = ds.sliding_distance[ds.in_steady_window]
    assert window.size >= 3 and float(window.min()) >= 0.5 * slid - 1e-12
    for name in ("mu", "dp", "Fz_mean"):
        assert np.isfinite(float(ds[name]))


def test_steady_stop_waits_for_three_agreeing_checks():
    scene = Scene.from_dict(TINY)
    stop = run_module.SteadyStop(scene)

    class Rec:  # records every 2 um with a constant mu of 0.5 after the first 30 um
        slid = list(np.arange(0.0, 200e-6, 2e-6))
        rows = [{"Fx": 0.5 if s > 30e-6 else 0.1, "Fz": 1.0} for s in slid]

    decisions = [(x, stop.steady(Rec, x)) for x in np.arange(1e-6, 200e-6, 1e-6)]
    first = next(x for x, yes in decisions if yes)
    assert first >= stop.minimum
    assert len(stop.history) >= 3 and stop.history[-1] == pytest.approx(0.5)


# ----------------------------------------------------------------------------- command line
def test_cli_writes_the_result(tmp_path, tiny_run):
    scene_file = tmp_path / "tiny.yaml"
    scene_file.write_text(yaml.safe_dump(TINY))
    out = tmp_path / "res" / "tiny.nc"
    assert cli.main(["mpm", str(scene_file), "-o", str(out), "--quiet", "--threads", "1"]) == 0
    assert out.exists()
    ds = xr.load_dataset(out)
    assert Scene.from_dict(json.loads(ds.attrs["scene"])) == Scene.from_dict(TINY)
    # same scene, same thread count: the same numbers as simulate()
    assert float(ds.mu) == pytest.approx(float(tiny_run.mu), rel=1e-12)
    assert not list(tmp_path.glob("res/.*part"))


def test_cli_bad_scene_exits_2_and_writes_nothing(tmp_path, capsys):
    scene_file = tmp_path / "bad.yaml"
    bad = scene_dict()
    bad["sphere"]["colour"] = "red"
    scene_file.write_text(yaml.safe_dump(bad))
    out = tmp_path / "bad.nc"
    assert cli.main(["mpm", str(scene_file), "-o", str(out), "--quiet"]) == 2
    assert not out.exists() and list(tmp_path.iterdir()) == [scene_file]
    err = capsys.readouterr().err
    assert "colour" in err and "Traceback" not in err and err.count("\n") == 1
    assert cli.main(["mpm", str(tmp_path / "missing.yaml"), "-o", str(out), "--quiet"]) == 2
    assert not out.exists()


def test_cli_unstable_run_exits_2_without_traceback(tmp_path, capsys, allow_inertia):
    scene_file = tmp_path / "unstable.yaml"
    scene_file.write_text(yaml.safe_dump(scene_dict(**UNSTABLE)))
    out = tmp_path / "unstable.nc"
    rc = cli.main(["mpm", str(scene_file), "-o", str(out), "--quiet", "--threads", "1"])
    assert rc == 2 and not out.exists()
    lines = [ln for ln in capsys.readouterr().err.splitlines() if not ln.startswith("plough: note: ")]
    assert len(lines) == 1 and lines[0].startswith("plough mpm: error: ")  # one line, no traceback
    assert "unstable run at step" in lines[0] or "lost contact" in lines[0]


def test_the_cached_flow_stress_at_rest_follows_every_particle_through_a_run():
    """``sigma_y0`` (the flow stress at zero rate the elastic check and the contact read) equals the
    flow law at the particle's plastic strain and temperature after a run with hardening, heating
    and a mixed coating layer: the cache never goes stale."""
    from plough.mpm.constitutive import mixed_flow_stress

    scene = Scene.from_dict(scene_dict(load_N=0.5, layers={"coating_thickness_um": 15, "coating": "zinc_coating",
                                                           "substrate": "dx56"},
                                       interface={"model": "boundary_layer", "Cp": 0.32, "np": 0.95}))
    state, const = solver.init(scene, n_chunks=1)
    p = state.particles
    for _ in range(1500):
        solver.step(state, const)
    assert state.sphere.phase == "slide"
    flowed = p.eps_p > 0.0
    assert flowed.sum() > 50 and p.temperature.max() > scene.outputs.initial_temperature_K
    assert np.any((p.frac_a > 0.0) & (p.frac_a < 1.0) & flowed)  # straddling particles flowed too
    table = const.table
    expected = np.array([mixed_flow_stress(table[p.mat_a[i]], table[p.mat_b[i]], p.frac_a[i], p.eps_p[i], 0.0,
                                           p.temperature[i]) for i in range(p.n)])
    np.testing.assert_array_equal(p.sigma_y0, expected)


@pytest.mark.filterwarnings("ignore::plough.mpm.run.SteadyStateWarning")
def test_snapshots_closer_than_a_micrometre_keep_their_own_files(tmp_path):
    """Snapshots 0.67 um apart: each gets its own file (names in whole micrometres overwrote half of them)."""
    scene = Scene.from_dict(scene_dict(outputs={**TINY["outputs"], "snapshots": 300}))
    simulate(scene, progress=False, threads=1, snapshots_dir=tmp_path)
    files = sorted(p.name for p in tmp_path.glob("*.vtp"))
    assert "tiny_final.vtp" in files
    assert len(files) >= 301


def test_a_particle_contact_run_writes_no_grid_split_and_no_nan():
    """The contact_* series and their summaries are the grid contact's; a particle-contact run (whose split
    channels stay zero) leaves them out rather than writing zeros and a NaN front pressure."""
    d = scene_dict(sliding={"distance_um": 100, "speed_m_s": 0.1, "experiment_speed_m_s": 0.001},
                   domain={"radius_um": 80, "length_um": 300, "symmetric": True})
    d["discretisation"] = {**d["discretisation"], "contact": "particle"}
    ds = simulate(Scene.from_dict(d), progress=False, threads=1)
    from plough.mpm.io import CONTACT_SPLIT_META, CONTACT_SUMMARY_META

    assert not set(ds.variables) & (set(CONTACT_SPLIT_META) | set(CONTACT_SUMMARY_META))
    for name, var in ds.data_vars.items():
        if np.issubdtype(var.dtype, np.floating) and not var.attrs.get("allow_missing"):
            assert np.isfinite(var.values).all(), name
    assert float(ds.mu_sh) > 0.0


def test_the_traction_boundary_layer_integrates_to_cp_times_the_load():
    """With ``interface.pressure: traction`` and np = 1 the law's strength summed over the contact,
    sum Cp P_i A_i, is Cp times the normal force the contact nodes carry (P_i A_i is a node's normal force,
    averaged over the hold): at least Cp Fz, a few per cent more for the tilt of the nodes' normals on a
    shallow contact. Cp = 0.02 keeps tau far below kappa, so the cap does not bind. The particles' stress
    (the default) reads less than half of that pressure next to the sphere, so reading it would fail here."""
    Cp = 0.02
    d = scene_dict(interface={"model": "boundary_layer", "Cp": Cp, "np": 1.0, "pressure": "traction"})
    ds = simulate(Scene.from_dict(d), progress=False, threads=1)
    w = ds.in_steady_window.values.astype(bool)
    ratio = ds.contact_shear_capacity.values[w].mean() / (Cp * ds.Fz.values[w].mean())
    assert 0.98 <= ratio <= 1.12
    assert float(ds.mu_sh) == pytest.approx(Cp * ratio, rel=0.05)  # every node slides: the strength is the force
