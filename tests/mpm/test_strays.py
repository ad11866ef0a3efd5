"""plough.mpm.strays: stragglers behind the active zone frozen, debris past the grid's growth limits retired."""

from __future__ import annotations

from dataclasses import replace

import numpy as np
import pytest

from plough.mpm import growth, solver, strays, transfers
from plough.mpm import run as run_module
from plough.mpm import scene as scene_module
from plough.mpm.scene import Scene

from .test_run_small import (
    TINY,
    _flag_above_the_top,
    end_of_step,
    single_thread,  # noqa: F401 - autouse: deterministic, cheap single-threaded runs
)


@pytest.fixture
def zoned_scene(monkeypatch):
    """The tiny scene with an active zone of 2 contact radii (its floor in particle sizes off)."""
    monkeypatch.setattr(scene_module, "ACTIVE_ZONE_MIN_PARTICLES", 0.0)
    base = Scene.from_dict(TINY)
    return replace(base, discretisation=replace(base.discretisation, active_zone_contact_radii=2.0))


def _into_the_slide(scene: Scene, slid_m: float = 60e-6):
    state, const = solver.init(scene, n_chunks=1)
    while not (state.sphere.phase == "slide" and state.sphere.slid_m >= slid_m):
        solver.step(state, const)
    assert state.zone.ranges.n_lo > 0 and state.zone.ranges.p_lo > 0  # the zone has left slabs behind
    return state, const


def test_every_per_particle_array_is_permuted(zoned_scene):
    """The arrays with a row per particle are the particle bundle's and the two of Work: a new one must be
    added to ``strays.per_particle_arrays`` or a retirement would tear the particles apart."""
    state, const = solver.init(zoned_scene, n_chunks=1)
    n = state.particles.n
    assert n != const.grid.n_nodes
    def rows(obj) -> set[str]:
        return {name for name, a in vars(obj).items() if isinstance(a, np.ndarray) and a.shape[:1] == (n,)}

    assert rows(state.work) == {"v_grid", "last_push_p"}
    assert rows(const) == {"zone_x0_m"}  # kept sorted by freeze_out_of_order
    assert rows(state.zone) == {"retired"}  # its slots lie below p_lo, never moved again
    assert not (rows(state) | rows(state.sphere) | rows(const.growing))
    ids = {id(a) for a in strays.per_particle_arrays(state)}
    assert all(id(a) in ids for a in state.particles)
    assert id(state.work.v_grid) in ids and id(state.work.last_push_p) in ids


def test_freezing_out_of_order_moves_whole_particles_and_keeps_the_keys_sorted(zoned_scene):
    state, const = _into_the_slide(zoned_scene)
    z = state.zone.ranges
    lo = z.p_lo
    chosen = [lo + 3, lo + 10]
    p = state.particles
    p.v[lo:lo + 20] = np.arange(60.0).reshape(20, 3) * 1e-4  # distinct, to follow the particles
    before = [a.copy() for a in strays.per_particle_arrays(state)]
    keys = const.zone_x0_m.copy()
    kinetic = sum(0.5 * p.mass[i] * float(p.v[i] @ p.v[i]) for i in chosen)
    state.work.acc[0, transfers.ACC_KINETIC] = 1.0
    loss_before = state.zone.frozen_kinetic_loss_J
    elastic, lost = strays.freeze_out_of_order(state, const, np.array(chosen))
    assert state.zone.ranges.p_lo == lo + 2 and lost == pytest.approx(kinetic, rel=1e-12) and elastic >= 0.0
    assert state.work.acc[0, transfers.ACC_KINETIC] == pytest.approx(1.0 - kinetic)
    assert state.zone.frozen_kinetic_loss_J == loss_before  # the caller counts it (strays.settle)
    rest = [i for i in range(lo, lo + 11) if i not in chosen]
    order = chosen + rest
    zeroed = {id(p.v), id(p.C), id(state.work.v_grid)}
    for a, old in zip(strays.per_particle_arrays(state), before, strict=True):
        if id(a) in zeroed:  # frozen at rest; the others moved with their values
            assert np.all(a[lo:lo + 2] == 0.0)
            np.testing.assert_array_equal(a[lo + 2:lo + 11], old[rest])
        else:
            np.testing.assert_array_equal(a[lo:lo + 11], old[order])
        np.testing.assert_array_equal(a[:lo], old[:lo])
        np.testing.assert_array_equal(a[lo + 11:], old[lo + 11:])
    x0 = const.zone_x0_m
    assert np.all(np.diff(x0) >= 0.0)
    np.testing.assert_array_equal(x0[lo + 2:lo + 11], keys[rest])  # each particle keeps its own key
    with pytest.raises(ValueError, match="not all active"):
        strays.freeze_out_of_order(state, const, np.array([lo]))  # now frozen


def test_a_straggler_behind_the_zones_slabs_is_frozen_and_the_run_goes_on(zoned_scene):
    """A particle that flowed back out of the zone's trailing slabs (the H~ = 5, t = 25 um run at h = 2.5 um
    stopped on one) is frozen where it is, and the run goes on to its end."""
    state, const = _into_the_slide(zoned_scene)
    z = state.zone.ranges
    k = z.p_lo + 2
    state.work.acc[:] = 0.0
    state.work.acc[0, transfers.ACC_BAD] = transfers.BAD_LEFT_GRID
    state.work.acc[0, transfers.ACC_BAD_INDEX] = k
    state.particles.x[k, 0] = z.check_lo[0] - 0.2 * const.grid.dx
    where = state.particles.x[k].copy()
    end_of_step(state, const)  # no error
    assert state.zone.ranges.p_lo == z.p_lo + 1 and state.zone.stragglers_frozen == 1
    assert np.array_equal(state.particles.x[z.p_lo], where) and not state.zone.retired.any()
    while state.sphere.phase != "done":
        solver.step(state, const)
    assert np.array_equal(state.particles.x[z.p_lo], where)  # frozen to the end


def test_debris_past_more_than_a_thousandth_of_the_mass_stops_the_run_naming_a_prow(zoned_scene):
    """Past the limits by more than RETIRED_MASS_FRACTION_MAX of the block's mass is not debris: the run stops
    and nothing is retired."""
    state, const = solver.init(zoned_scene, n_chunks=1)
    p = state.particles
    many = np.arange(state.zone.ranges.p_lo, state.zone.ranges.p_hi)[:: 1 + (p.n // 40)][:8]
    assert float(p.mass[many].sum()) > strays.RETIRED_MASS_FRACTION_MAX * float(p.mass.sum())
    _flag_above_the_top(state, const, index=int(many[0]), over_m=const.grid_top_limit_m)
    p.x[many, 2] = const.grid_top_limit_m + const.grid.dx
    with pytest.raises(solver.InstabilityError, match=r"past the grid's growth limits.*prow or chip"):
        end_of_step(state, const)
    assert not state.zone.retired.any() and state.zone.retired_mass_kg == 0.0


@pytest.mark.parametrize("axis", [0, 1, 2], ids=["far end", "side", "top"])
def test_a_particle_is_either_held_by_a_growth_or_retired(axis):
    """A hundredth of a cell inside the farthest a grown grid holds, the grid grows for the particle; a third of
    a cell past it, the particle is retired and nothing grows. Either way the run goes on (the whole block
    active: the zone's leading slabs would stop a particle flung past them)."""
    for past, retired in ((-0.01, False), (0.3, True)):
        state, const = solver.init(Scene.from_dict(TINY), n_chunks=1)
        k = state.particles.n - 5  # a particle near the far end
        far = growth.farthest_held_m(const, axis)
        assert far <= getattr(const, growth.FACES[axis].limit) - const.grid.dx + 1e-12
        state.work.acc[:] = 0.0
        state.work.acc[0, transfers.ACC_BAD] = transfers.BAD_LEFT_GRID
        state.work.acc[0, transfers.ACC_BAD_INDEX] = k
        state.particles.x[k, axis] = far + past * const.grid.dx
        end_of_step(state, const)  # no error either way
        grown = getattr(state, growth.FACES[axis].log)
        assert bool(state.zone.retired.any()) == retired and bool(grown) != retired
        assert const.grid_hi[axis] <= getattr(const, growth.FACES[axis].limit) + 1e-12
        if not retired:
            assert state.particles.x[k, axis] < const.grid_hi[axis]


def test_debris_and_a_straggler_on_one_step_are_both_moved_and_told_apart(zoned_scene):
    """Debris is retired first (its slot marked), then the straggler frozen (not marked); the run goes on."""
    state, const = _into_the_slide(zoned_scene)
    z = state.zone.ranges
    flung, late = z.p_hi - 3, z.p_lo + 4
    state.work.acc[:] = 0.0
    state.work.acc[0, transfers.ACC_BAD] = transfers.BAD_LEFT_GRID
    state.work.acc[0, transfers.ACC_BAD_INDEX] = late
    state.particles.x[flung, 2] = const.grid_top_limit_m + const.grid.dx
    state.particles.x[late, 0] = z.check_lo[0] - 0.2 * const.grid.dx
    x_flung, x_late = state.particles.x[flung].copy(), state.particles.x[late].copy()
    end_of_step(state, const)  # no error
    lo = z.p_lo
    assert state.zone.ranges.p_lo == lo + 2 and state.zone.stragglers_frozen == 1
    assert state.zone.retired[lo] and not state.zone.retired[lo + 1] and state.zone.retired.sum() == 1
    assert np.array_equal(state.particles.x[lo], x_flung) and np.array_equal(state.particles.x[lo + 1], x_late)
    for _ in range(20):
        solver.step(state, const)


def test_a_retired_particle_leaves_the_material_top_and_the_outputs(zoned_scene):
    state, const = solver.init(zoned_scene, n_chunks=1)
    _flag_above_the_top(state, const, index=state.zone.ranges.p_lo + 5, over_m=const.grid_top_limit_m)
    top_with = float(state.particles.x[:, 2].max())
    assert run_module.material_top(state) == top_with  # debris counts until it is retired
    end_of_step(state, const)
    assert state.zone.retired.sum() == 1
    assert run_module.material_top(state) < top_with
    assert run_module.kept_particles(state).n == state.particles.n - 1
