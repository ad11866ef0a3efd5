"""Strays: active particles the grid no longer holds that the run goes on without (model.md, "The headroom
and the growing grid").

Two kinds, both answered after the step's kernels, before the grid grows (:func:`plough.mpm.growth.hold`):

* **Debris** past a growing face's reach (automatic headroom only): a particle the grid cannot grow to hold
  (``growth.beyond_reach``: within a cell or two of the face's limit, ``growth.GRID_TOP_LIMIT_RADII`` sphere
  radii above the original surface, the sphere's own top, or as many radii past the far end or the side) is
  a fragment in free flight far from the contact (the 1e6 mass scaling flings surface fragments of a hard
  thin coating at about the sliding speed). It is retired: frozen where it is, left out of the groove, the
  pictures and, from then on, the material's top (snapshots still show it), counted
  (``cost_retired_particles``, ``cost_retired_mass_fraction``) with its kinetic energy in
  ``frozen_kinetic_loss``. More than :data:`RETIRED_MASS_FRACTION_MAX` of the block's mass past the limits is
  not debris but a prow or a chip the grid cannot hold: the run stops.
* **Stragglers** behind the active zone: a particle that moved back out of the zone's trailing grid slabs
  (the slabs the zone has retired). The zone freezes material by its initial position; a particle that
  flowed back more than the slabs' pad (``solver.ZONE_PAD_CELLS`` less a stencil) is frozen where it is,
  as the zone freezes the material around it (by initial position, so sooner or later), its kinetic energy
  counted as the zone's freezing counts it (``cost_stragglers_frozen``). Debris is settled first: a particle
  both behind the zone and beyond reach is retired.

Both move the particles to the frozen range: the particles are stored x-major by initial position and the
zone works on the index range [p_lo, p_hi) (``solver.ActiveZone``), so a particle leaves it by a stable
permutation of the slots p_lo..k that puts it first, then p_lo moves past it (:func:`freeze_out_of_order`).
The frozen slots below p_lo never move again, and the zone's sorted initial positions stay sorted.
A scene with a hand-set ``domain.headroom_m`` (a fixed grid) retires nothing: a particle past it stops the
run (``solver.check_stability``).
"""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np

from plough.mpm import transfers
from plough.mpm.errors import InstabilityError

if TYPE_CHECKING:
    from plough.mpm.solver import Constants, State

#: the most of the block's mass (mass-scaled, as stored) that may be retired as debris in a run: a fragment is
#: a few particles; material past the limits beyond this share is a prow or chip the grid cannot hold
RETIRED_MASS_FRACTION_MAX = 1e-3


def per_particle_arrays(s: State) -> list[np.ndarray]:
    """Every array with a row per particle that the run keeps: the particle bundle's fields, the grid velocity
    each particle was advected with and the particle contact's memory (``solver.Work``)."""
    return [*s.particles, s.work.v_grid, s.work.last_push_p]


def freeze_out_of_order(s: State, c: Constants, indices: np.ndarray) -> tuple[float, float]:
    """Move the active particles ``indices`` (each in [p_lo, p_hi)) to the frozen range and freeze them.

    Permutes the rows p_lo..max(indices) of every per-particle array (:func:`per_particle_arrays`) stably so
    that ``indices`` come first, gives their slots of the zone's initial positions ``c.zone_x0_m`` the range's
    smallest (the array stays sorted), freezes them (``transfers.freeze_particles``: at rest, stress kept) and
    advances p_lo past them. Returns (elastic energy they keep, kinetic energy they lose), J; takes their
    kinetic energy out of this step's accumulated kinetic energy (``g2p_update`` counted it).
    """
    z = s.zone.ranges
    idx = np.unique(np.asarray(indices, dtype=np.int64))
    if idx.size == 0:
        return 0.0, 0.0
    if idx[0] < z.p_lo or idx[-1] >= z.p_hi:
        raise ValueError(f"particles {idx.tolist()} are not all active ({z.p_lo} <= p < {z.p_hi})")
    top = int(idx[-1]) + 1
    rows = np.arange(z.p_lo, top)
    chosen = np.isin(rows, idx)
    order = np.concatenate([rows[chosen], rows[~chosen]])
    for a in per_particle_arrays(s):
        a[z.p_lo:top] = a[order]
    keys = c.zone_x0_m
    if keys.size:
        keys[z.p_lo:top] = np.concatenate([np.full(idx.size, keys[z.p_lo]), keys[rows[~chosen]]])
    new_lo = z.p_lo + idx.size
    elastic, kinetic = transfers.freeze_particles(s.particles, s.work.v_grid, c.table, z.p_lo, new_lo)
    s.work.acc[0, transfers.ACC_KINETIC] -= kinetic
    s.zone.ranges = z._replace(p_lo=new_lo)
    return elastic, kinetic


def _freeze_and_count(s: State, c: Constants, indices: np.ndarray) -> None:
    """:func:`freeze_out_of_order`, its energies counted as the zone counts those of the particles it freezes."""
    elastic, kinetic = freeze_out_of_order(s, c, indices)
    s.zone.frozen_elastic_J += elastic
    s.zone.frozen_kinetic_loss_J += kinetic


def stragglers(s: State) -> np.ndarray:
    """Active particles behind the zone's trailing slabs (x below the positions check's low end where the
    zone has retired slabs there), as indices."""
    z = s.zone.ranges
    if z.n_lo == 0:
        return np.zeros(0, dtype=np.int64)
    x = s.particles.x[z.p_lo:z.p_hi, 0]
    return z.p_lo + np.flatnonzero(x < z.check_lo[0])


def settle(s: State, c: Constants, flung: np.ndarray) -> int:
    """Retire the debris ``flung`` (the active particles no growth can hold: ``growth.beyond_reach``), then freeze
    the stragglers (:func:`stragglers`) of this step (the module docstring); the number of particles moved to the
    frozen range. Stops the run, retiring nothing, where the debris would pass :data:`RETIRED_MASS_FRACTION_MAX`
    of the block's mass."""
    moved = 0
    if flung.size:
        mass = s.particles.mass
        share = (s.zone.retired_mass_kg + float(mass[flung].sum())) / float(mass.sum())
        if share > RETIRED_MASS_FRACTION_MAX:
            raise InstabilityError(
                f"unstable run at step {s.step} (sliding distance {s.sphere.slid_m * 1e6:.1f} um): material past the "
                f"grid's growth limits ({c.grid_top_limit_m * 1e6:.1f} um above the surface, x "
                f"{c.grid_end_limit_m * 1e6:.1f} um, y {c.grid_side_limit_m * 1e6:.1f} um) would make {share:.2%} "
                f"of the block's mass, more than the {RETIRED_MASS_FRACTION_MAX:.1%} retired as flung fragments: a "
                "prow or chip the grid cannot hold (coarser particles, a lower load, or a hand-set domain.headroom_m)")
        s.zone.retired_mass_kg += float(mass[flung].sum())
        slots_from = s.zone.ranges.p_lo
        _freeze_and_count(s, c, flung)
        s.zone.retired[slots_from:slots_from + flung.size] = True
        s.zone.retired_log.append((s.step, s.sphere.slid_m, int(flung.size)))
        moved += int(flung.size)
    late = stragglers(s)
    if late.size:
        _freeze_and_count(s, c, late)
        s.zone.stragglers_frozen += int(late.size)
        moved += int(late.size)
    return moved
