"""The data the step's kernels pass around, as named tuples numba compiles against (model.md section 2).

A kernel takes a few of these bundles instead of their arrays one by one (``p2g(P, G, dt, Z)``); each
kernel's docstring names the fields it reads and writes. The bundles hold references to the run's
arrays, so building one copies nothing and a kernel's writes land in the run's state:

- ``P``, :class:`plough.mpm.particles.Particles`: the particles' state (positions, velocities, stress,
  history, materials), one row per particle;
- ``G``, :class:`GridData`: the background grid, its geometry and its per-node arrays (the per-chunk
  P2G copies, mass, velocities, boundary flags, the projected dilatation, the contact scratch and memory);
- ``M``, :class:`MaterialData`: the packed flow laws and the constants of the stress update;
- ``S``, :class:`SphereData`: the rigid sphere, where it is and how it moves;
- ``law``, :class:`ContactLaw`: the interface shear law and the contact's hold;
- ``SP``, :class:`StressState`: the particles' stress fields alone, what ``g2p_update`` hands the stress update;
- ``Z``, :class:`Zone`: the particle and node ranges a step works on (the active zone) and the box the
  particles must stay in.

The solver builds ``G``, ``S`` and ``Z`` each step from its state (the grid's arrays are reallocated
when it grows, the sphere moves, the zone advances); ``P`` is the particle state itself and ``M`` and
``law`` are fixed for the run.
"""

from __future__ import annotations

from typing import NamedTuple

import numpy as np


class GridData(NamedTuple):
    """The background grid (``G``): nodes at origin + (i, j, k) dx, flat index (i ny + j) nz + k."""

    origin: np.ndarray  # (3,) m
    dx: float  # m
    shape: np.ndarray  # (3,) int64, nodes along x, y, z
    mirror_j0: int  # index j of the node plane y = 0 with the mirror plane, -1 without
    flags: np.ndarray  # (nodes,) int8 FREE / FIXED / MIRROR / GHOST (plough.mpm.grid)
    buf: np.ndarray  # (chunks, nodes, 7) per-chunk scatter copies (P2G; later the dilatation's scatter)
    m: np.ndarray  # (nodes,) nodal mass, kg
    v: np.ndarray  # (nodes, 6) velocity after the step's forces 0:3 and before the internal force 3:6, m/s
    div: np.ndarray  # (nodes,) projected dilatation rate, 1/s
    cbuf: np.ndarray  # (nodes, contact.N_CBUF) contact scratch (near particles: stress, strength, surface), traction
    last_push: np.ndarray  # (nodes,) int64 step of each node's last normal push by the sphere


class MaterialData(NamedTuple):
    """The materials (``M``): packed rows (plough.mpm.constitutive) and the stress update's constants."""

    table: np.ndarray  # (materials, N_MAT_PARAMS) packed flow laws and elastic moduli
    rate_scale: float  # v_experiment / v_simulation: simulated plastic strain rates to physical ones
    taylor_quinney: float  # share of the plastic work that heats the material


class SphereData(NamedTuple):
    """The rigid sphere (``S``); ``centre`` and ``velocity`` are the solver's own arrays, moved in place."""

    centre: np.ndarray  # (3,) m
    velocity: np.ndarray  # (3,) m/s
    radius: float  # m
    near_dist: float  # m, a particle within this of the surface is flagged near (the contact's reach)


class ContactLaw(NamedTuple):
    """The interface shear law of eq. 8, the contact's hold and the particle contact's sweeps (plough.mpm.contact)."""

    model: int  # INTERFACE_PROPORTIONAL / _CONSTANT / _BOUNDARY_LAYER / _BOUNDARY_LAYER_TRACTION
    params: np.ndarray  # (2,) the law's parameters (f; tau; Cp, np)
    hold_steps: float  # a node (or a particle) stays in contact this many steps after its last normal push
    sweeps: int = 4  # projected Gauss-Seidel sweeps of particle_contact over the touching particles


class StressState(NamedTuple):
    """The particle fields the stress update reads and writes (``SP``, ``constitutive.update_stress``), a subset of
    ``P``'s: ``g2p_update`` hands this to the stress update (``constitutive.stress_update``, inlined) and so to
    ``constitutive.plastic_flow``, a call made for each plastic trial state: a bundle is passed by value (each
    array's pointer, shape and strides), and the nine arrays cost a call less than all of ``P``'s (g2p_update on
    one thread, 10% less time on an elastic block before the inlining: docs/journal/2026-12-02-throughput.md).
    Inside a ``prange`` body an array of a bundle is only read: numba may drop a store into it
    (``constitutive.stress_update`` says why)."""

    stress: np.ndarray  # (n, 6) Voigt xx, yy, zz, yz, xz, xy, Pa
    J: np.ndarray  # (n,) det F
    eps_p: np.ndarray  # (n,) equivalent plastic strain
    temperature: np.ndarray  # (n,) K
    sigma_y0: np.ndarray  # (n,) flow stress at rest, Pa
    deps_last: np.ndarray  # (n,) last plastic strain increment
    mat_a: np.ndarray  # (n,) int32 material row a
    mat_b: np.ndarray  # (n,) int32 material row b
    frac_a: np.ndarray  # (n,) volume fraction of a


class Zone(NamedTuple):
    """What a step works on (``Z``): particles p_lo <= p < p_hi, flat nodes n_lo <= node < n_hi; nodes of
    x index outside [i_free_lo, i_free_hi] are clamped; the particles must stay in [check_lo, check_hi]."""

    p_lo: int
    p_hi: int
    n_lo: int
    n_hi: int
    i_free_lo: int
    i_free_hi: int
    check_lo: np.ndarray  # (3,) m
    check_hi: np.ndarray  # (3,) m


def grid_of(origin: np.ndarray, dx: float, shape, n_chunks: int = 1, mirror_j0: int = -1,
            **arrays: np.ndarray) -> GridData:
    """A grid bundle with the given per-node arrays and, for the rest, an empty grid: free nodes, no mass
    or velocity, an empty contact scratch, nodes never pushed (for kernels called on their own: tests and
    benchmarks; the solver builds its own, ``solver.grid_data``)."""
    from plough.mpm.contact import N_CBUF, NEVER_PUSHED
    from plough.mpm.grid import FREE

    unknown = set(arrays) - set(GridData._fields[4:])
    if unknown:
        raise ValueError(f"grid_of: {sorted(unknown)} are not per-node fields of GridData {GridData._fields[4:]}")
    shape = np.asarray(shape, dtype=np.int64)
    n = int(np.prod(shape))
    default = {"flags": np.full(n, FREE, dtype=np.int8), "buf": np.zeros((n_chunks, n, 7)), "m": np.zeros(n),
               "v": np.zeros((n, 6)), "div": np.zeros(n), "cbuf": np.zeros((n, N_CBUF)),
               "last_push": np.full(n, NEVER_PUSHED, dtype=np.int64)}
    return GridData(origin=np.asarray(origin, dtype=float), dx=float(dx), shape=shape, mirror_j0=int(mirror_j0),
                    **{**default, **arrays})


def whole(n_particles: int, shape, check_lo: np.ndarray | None = None, check_hi: np.ndarray | None = None) -> Zone:
    """The zone of every particle and node, nothing clamped; the positions check box ``check_lo``..``check_hi``
    (none by default)."""
    shape = np.asarray(shape, dtype=np.int64)
    return Zone(p_lo=0, p_hi=int(n_particles), n_lo=0, n_hi=int(np.prod(shape)), i_free_lo=0,
                i_free_hi=int(shape[0]), check_lo=np.full(3, -np.inf) if check_lo is None else np.asarray(check_lo),
                check_hi=np.full(3, np.inf) if check_hi is None else np.asarray(check_hi))
