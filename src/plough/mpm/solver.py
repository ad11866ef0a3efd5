"""Explicit MPM ploughing solver: initialise a state from a scene, advance it step by step.

One step (model.md section 2):

1. P2G: particle mass, momentum and stress divergence to the grid (APIC/MLS); with the projected
   dilatation, the pressure in the stress divergence is projected the same way first (so that the
   internal force does the work the stress update takes: no energy made or lost).
2. Grid update: nodal velocities with the internal force; fixed curved surface, mirror plane
   (exact: nodes at +y also get their ghosts' contributions, ghosts mirror them after contact).
3. Contact: the rigid sphere on the nodes inside it, traction-limited interface shear (eq. 8);
   the reaction is the force on the sphere.
4. Sphere motion: pressing, then sliding along x; its height floats under load control.
5. G2P: velocities (APIC blended with the FLIP increment) and velocity gradients back to the
   particles; their dilatation rates to the grid and back (the projection against volumetric
   locking); stress update (eqs. 6.1-6.2, 7.1-7.3) with the projected dilatation, advection,
   instability checks.

The time step is dt = CFL dx / c with c = sqrt((K + 4G/3) / (ms rho)) the mass-scaled elastic
wave speed.

With ``discretisation.active_zone_contact_radii`` the step works only on the particles that
started within that many expected contact radii of the sphere's centre along x, and on the grid
slabs around them (:class:`ActiveZone`): particles and nodes are stored x-major, so both are
index ranges; the material beyond is frozen and clamps the active part.

Material that rises past the grid's top (a prow that keeps growing), is flung past the block's far end
(fragments of a soft coating's chip) or thrown out through the side face y = R makes the grid grow there
mid-run where the scene leaves the headroom automatic (:mod:`plough.mpm.growth`), up to limits past which a
flung particle is retired as debris; a particle that flows back out of the active zone's trailing slabs is
frozen where it is (:mod:`plough.mpm.strays`). Any other particle leaving the grid, and a hand-set headroom,
stop the run (:func:`check_stability`).

The run's constants (:class:`Constants`) are frozen but for the grid, whose growth replaces it
(:class:`GrowingGrid`); the state (:class:`State`) is everything else that changes.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field

import numba
import numpy as np

from plough.materials import (
    BoundaryLayerShear,
    ConstantShear,
    ProportionalShear,
)
from plough.mpm import contact, growth, transfers
from plough.mpm.bundles import ContactLaw, GridData, MaterialData, SphereData, Zone
from plough.mpm.constitutive import I_G, I_K, I_RHO, pack_materials
from plough.mpm.errors import InstabilityError, SimulationError  # noqa: F401 (callers catch solver.SimulationError)
from plough.mpm.grid import Grid, boundary_flags, make_grid, mirror_plane_index
from plough.mpm.growth import GRID_END_LIMIT_RADII, GRID_SIDE_LIMIT_RADII, GRID_TOP_LIMIT_RADII, physical_memory_bytes
from plough.mpm.particles import Particles, seed_particles, uniform_particle_count
from plough.mpm.scene import Scene

# Load controller (see control_sphere): force filter, loop time constant and integral time in
# steps, gain from the elastic contact stiffness 2 E* a times STIFFNESS_FACTOR. Measured on the
# reference scene at h = 10 um (docs/model.md, 3.9 Load control): the vertical speed varies by 3.5%
# of the pressing speed (it swung by +-75% with a gain tuned to the plastic stiffness Fn / dp),
# contact on 92% of the steps, mean Fz within 0.3% of the load.
FILTER_STEPS = 10.0
CONTROL_STEPS = 40.0
STIFFNESS_FACTOR = 1.0
SETTLE_STEPS = 300
INTEGRAL_STEPS = 100.0
#: grid slabs worked on beyond each clamp face of the active zone, so that the stencils of the
#: active particles stay on nodes the step updates: a particle at its starting position keeps two
#: slabs to spare, one of which the positions check (the zone's ``check_lo``, :class:`ActiveZone`) may use up: a
#: particle moved about a cell past its start at the zone's end (material the sphere pushes far
#: ahead) stops the run
ZONE_PAD_CELLS = 4


@dataclass
class SphereState:
    centre: np.ndarray  # (3,) m
    velocity: np.ndarray  # (3,) m/s
    fz_filtered: float = 0.0
    load_error_integral: float = 0.0  # N s, integral term of the load controller
    phase: str = "press"  # press -> settle -> slide -> done
    settle_left: int = SETTLE_STEPS
    slid_m: float = 0.0


@dataclass
class GrowingGrid:
    """The one part of the run's constants that changes: the grid, which grows mid-run (:mod:`plough.mpm.growth`)."""

    grid: Grid
    shape: np.ndarray = field(init=False)  # (3,) int64: the grid's shape as the kernels take it
    hi: np.ndarray = field(init=False)  # (3,) m: the high corner of the grid's interior (a cell in from the last nodes)

    def __post_init__(self) -> None:
        self.set(self.grid)

    def set(self, grid: Grid) -> None:
        """Take ``grid`` (the grown one) and what follows from it."""
        self.grid, self.shape, self.hi = grid, np.array(grid.shape, dtype=np.int64), grid.upper - 1.0 * grid.dx


@dataclass(frozen=True)
class Constants:
    """Everything a step needs that does not change during a run: frozen, but for the grid (``growing``:
    ``grid``, ``shape`` and ``grid_hi`` read it), which :mod:`plough.mpm.growth` replaces when it grows."""

    dt: float
    growing: GrowingGrid
    table: np.ndarray
    rate_scale: float
    taylor_quinney: float
    interface_model: int
    interface_params: np.ndarray
    near_dist: float
    grid_lo: np.ndarray  # (3,) m: the low corner of the grid's interior (it never grows that way)
    load_N: float
    symmetry_factor: float  # 2 with the mirror plane: the simulated half carries load_N / 2
    press_speed: float
    slide_speed: float
    slide_distance: float
    control_gain: float  # m/s per N
    contact_hold_steps: float  # a node stays in contact this many steps after its last normal push
    flip: float  # FLIP share of the particle velocity update (0 = APIC)
    project_dilatation: int  # 1: J and pressure from the grid-projected dilatation rate
    contact_mode: str  # discretisation.contact: grid, grid_local (nodes) or particle (contact.particle_contact)
    filter_alpha: float
    control: str
    target_depth: float | None
    sphere_radius: float
    steps_slide: int
    mirror_j0: int = -1  # index of the node plane y = 0 with symmetry, -1 without
    zone_half_width_m: float = 0.0  # m, active zone behind and ahead of the sphere centre; 0: every particle
    zone_x0_m: np.ndarray = field(default_factory=lambda: np.zeros(0))  # initial x of the particles, ascending
    #: m, the highest the grid's top may be raised to when material reaches it (:mod:`plough.mpm.growth`); 0: never
    #: (a headroom the scene sets by hand is kept)
    grid_top_limit_m: float = 0.0
    #: m, the farthest the grid's far end may move to when material passes it (:mod:`plough.mpm.growth`); 0: never
    grid_end_limit_m: float = 0.0
    #: m, the farthest the grid's side (high y) may move to when material passes it (:mod:`plough.mpm.growth`); 0: never
    grid_side_limit_m: float = 0.0
    block_end_m: float = 0.0  # m, x of the block's far end face (the grid starts a few cells past it)
    block_side_m: float = 0.0  # m, y of the block's side face, its radius R (the grid starts a few cells past it)

    @property
    def grid(self) -> Grid:
        return self.growing.grid

    @property
    def shape(self) -> np.ndarray:
        return self.growing.shape

    @property
    def grid_hi(self) -> np.ndarray:
        return self.growing.hi

    @property
    def material(self) -> MaterialData:
        """The materials bundle ``M`` the stress update takes."""
        return MaterialData(table=self.table, rate_scale=self.rate_scale, taylor_quinney=self.taylor_quinney)

    @property
    def contact_law(self) -> ContactLaw:
        """The interface law and the contact's hold, as ``sphere_contact`` takes them."""
        return ContactLaw(model=self.interface_model, params=self.interface_params, hold_steps=self.contact_hold_steps)


@dataclass
class ActiveZone:
    """The zone a step works on, and the energy of the particles it has left behind (J).

    ``ranges`` is the zone as the kernels take it (:class:`plough.mpm.bundles.Zone`: the particles [p_lo, p_hi)
    and flat grid nodes [n_lo, n_hi); nodes of x index below i_free_lo or above i_free_hi lie in frozen material
    and hold zero velocity; check_lo and check_hi bound the particles' positions: the grid's interior, narrowed
    in x so that every active particle's stencil stays in [n_lo, n_hi) on the next step). The ranges only move
    forward (:func:`update_active_zone` replaces them): a particle the zone has left stays frozen, with the
    elastic energy it keeps and the kinetic energy it lost counted here.
    """

    ranges: Zone
    frozen_elastic_J: float = 0.0
    frozen_kinetic_loss_J: float = 0.0
    #: particles frozen early, behind the zone's trailing slabs (:mod:`plough.mpm.strays`)
    stragglers_frozen: int = 0
    #: (n,) the particles retired as debris past the grid's growth limits (frozen; left out of the groove, the
    #: pictures and material_top; snapshots show them)
    retired: np.ndarray = field(default_factory=lambda: np.zeros(0, dtype=bool))
    retired_mass_kg: float = 0.0  # their mass (mass-scaled, as stored)
    #: (step, sliding distance m, particles) of each retirement
    retired_log: list[tuple[int, float, int]] = field(default_factory=list)


@dataclass
class Work:
    """Per-step scratch and the running energy account (J)."""

    grid_buf: np.ndarray
    grid_m: np.ndarray
    grid_v: np.ndarray  # (nodes, 6): velocity, and velocity before the internal force (FLIP)
    flags: np.ndarray
    cbuf: np.ndarray
    last_push: np.ndarray  # per-node step of the last normal push of the contact
    last_push_p: np.ndarray  # per-particle step of the last normal push (particle contact)
    acc: np.ndarray
    contact_out: np.ndarray
    grid_div: np.ndarray  # the projected nodal pressure (Pa) before P2G, the projected dilatation rate (1/s) after G2P
    L_buf: np.ndarray  # per-chunk scratch for the projected velocity gradient
    v_grid: np.ndarray  # (n, 3) grid velocity at each particle, m/s: what it is advected with
    external_work: float = 0.0
    plastic_work: float = 0.0
    interface_dissipation: float = 0.0
    contact_impact_loss: float = 0.0
    heat: float = 0.0


@dataclass
class State:
    particles: Particles
    sphere: SphereState
    work: Work
    zone: ActiveZone
    step: int = 0
    time: float = 0.0
    #: (step, sliding distance m, new grid top m) of each raise of the grid's top (:mod:`plough.mpm.growth`)
    grid_raises: list[tuple[int, float, float]] = field(default_factory=list)
    #: (step, sliding distance m, new grid end m) of each lengthening past the far end
    grid_extensions: list[tuple[int, float, float]] = field(default_factory=list)
    #: (step, sliding distance m, new grid side m) of each widening past the side face
    grid_widenings: list[tuple[int, float, float]] = field(default_factory=list)


# ----------------------------------------------------------------------------- set-up
def wave_speed(table: np.ndarray, mass_scaling: float) -> float:
    """Largest mass-scaled P-wave speed sqrt((K + 4G/3) / (ms rho)) over the materials."""
    return float(np.max(np.sqrt((table[:, I_K] + 4.0 / 3.0 * table[:, I_G]) / (mass_scaling * table[:, I_RHO]))))


def interface_arrays(scene: Scene) -> tuple[int, np.ndarray]:
    itf = scene.interface
    if isinstance(itf, ProportionalShear):
        return contact.INTERFACE_PROPORTIONAL, np.array([itf.f, 0.0])
    if isinstance(itf, ConstantShear):
        return contact.INTERFACE_CONSTANT, np.array([itf.tau_Pa, 0.0])
    if isinstance(itf, BoundaryLayerShear):
        if itf.pressure == "traction":
            return contact.INTERFACE_BOUNDARY_LAYER_TRACTION, np.array([itf.Cp, itf.np])
        return contact.INTERFACE_BOUNDARY_LAYER, np.array([itf.Cp, itf.np])
    raise ValueError(f"interface = {itf!r} is unknown")


#: bytes of one particle's state (position, velocity, affine matrix, stress and the scalars, float64)
#: without the grid or any scratch: a lower bound, so that only a run that cannot fit is refused
STATE_BYTES_PER_PARTICLE = 250


def check_memory(scene: Scene, available_bytes: int | None = None) -> None:
    """Refuse, before allocating anything, a scene whose particles alone exceed the physical memory.

    The count is the block's volume over h^3 (an eighth of it for graded particles: every far-field
    group of 8 may become one), a lower bound of what ``seed_particles`` makes.
    """
    available = physical_memory_bytes() if available_bytes is None else available_bytes
    if available is None:
        return
    dom, h = scene.domain, scene.discretisation.particle_size_m
    particles = uniform_particle_count(scene) / (8.0 if scene.discretisation.graded else 1.0)
    need = particles * STATE_BYTES_PER_PARTICLE
    if need > available:
        raise ValueError(f"discretisation.particle_size_m = {h:g} m gives at least {particles:.3g} particles in the "
                         f"{dom.length_m:g} m x {dom.radius_m:g} m block, at least {need / 2**30:.3g} GiB, more than "
                         f"this machine's {available / 2**30:.3g} GiB of memory (coarser particles or a smaller "
                         "domain)")


def init(scene: Scene, n_chunks: int | None = None) -> tuple[State, Constants]:
    """The initial state (undeformed block, sphere touching the surface) and the run constants."""
    check_memory(scene)
    mats = scene.layers.materials
    table = pack_materials(mats)
    rows = {"substrate": len(mats) - 1}
    if scene.layers.coated:
        rows["coating"] = 0
    particles = seed_particles(scene, rows, table)

    disc = scene.discretisation
    dx = disc.cell_size_m
    a_exp, _ = scene.expected_contact()
    grid = make_grid(scene.domain.length_m, scene.domain.radius_m, scene.domain.symmetric, dx, scene.grid_headroom_m)
    c = wave_speed(table, disc.mass_scaling)
    v_max = scene.sliding.speed_m_s * 2.0
    dt = disc.cfl * dx / (c + v_max)

    model, iparams = interface_arrays(scene)
    r = scene.sphere.radius_m
    n_chunks = n_chunks or max(numba.get_num_threads(), 1)
    centre = np.array([scene.start_x_m, 0.0, r])
    k_est = contact_stiffness(scene, a_exp)
    zone_x0 = particles.x[:, 0].copy() if scene.active_zone_half_width_m is not None else np.zeros(0)
    if np.any(np.diff(zone_x0) < 0.0):
        raise AssertionError("particles are not seeded x-major: the active zone needs them sorted along x")
    const = Constants(
        dt=dt, growing=GrowingGrid(grid), table=table, rate_scale=scene.rate_scale,
        taylor_quinney=scene.outputs.taylor_quinney, interface_model=model, interface_params=iparams,
        near_dist=3.0 * dx, grid_lo=grid.origin + 1.0 * dx, load_N=scene.load_N,
        symmetry_factor=2.0 if scene.domain.symmetric else 1.0,
        press_speed=scene.sliding.press_speed_fraction * scene.sliding.speed_m_s,
        slide_speed=scene.sliding.speed_m_s, slide_distance=scene.sliding.distance_m,
        control_gain=1.0 / (k_est * CONTROL_STEPS * dt), filter_alpha=1.0 / FILTER_STEPS,
        flip=disc.flip, project_dilatation=int(disc.dilatation == "projected"),
        contact_mode=disc.contact,
        contact_hold_steps=contact.HOLD_WAVE_TIMES * dx / (c * dt),
        control=scene.sliding.control, target_depth=scene.sliding.depth_m, sphere_radius=r,
        steps_slide=int(math.ceil(scene.sliding.distance_m / (scene.sliding.speed_m_s * dt))),
        mirror_j0=mirror_plane_index(grid, scene.domain.symmetric),
        grid_top_limit_m=GRID_TOP_LIMIT_RADII * r if scene.domain.headroom_m is None else 0.0,
        grid_end_limit_m=(scene.domain.length_m + GRID_END_LIMIT_RADII * r if scene.domain.headroom_m is None
                          else 0.0),
        grid_side_limit_m=(scene.domain.radius_m + GRID_SIDE_LIMIT_RADII * r if scene.domain.headroom_m is None
                           else 0.0),
        block_end_m=scene.domain.length_m, block_side_m=scene.domain.radius_m,
        zone_half_width_m=scene.active_zone_half_width_m or 0.0, zone_x0_m=zone_x0,
    )
    work = Work(
        grid_buf=transfers.allocate_grid_buffers(n_chunks, grid.n_nodes), grid_m=np.zeros(grid.n_nodes),
        grid_v=np.zeros((grid.n_nodes, 6)),
        flags=boundary_flags(grid, scene.domain.radius_m, scene.domain.symmetric),
        cbuf=np.zeros((grid.n_nodes, contact.N_CBUF)), last_push=np.full(grid.n_nodes, contact.NEVER_PUSHED),
        last_push_p=np.full(particles.n, contact.NEVER_PUSHED),
        acc=np.zeros((n_chunks, transfers.N_ACC)),
        contact_out=np.zeros(contact.N_OUT), grid_div=np.zeros(grid.n_nodes),
        L_buf=transfers.allocate_velocity_gradient_scratch(n_chunks), v_grid=np.zeros((particles.n, 3)),
    )
    sphere = SphereState(centre=centre, velocity=np.array([0.0, 0.0, -const.press_speed]))
    box = {"check_lo": const.grid_lo.copy(), "check_hi": const.grid_hi.copy()}
    if const.zone_half_width_m > 0.0:  # empty ranges, opened by the first update
        zone = ActiveZone(Zone(p_lo=0, p_hi=0, n_lo=0, n_hi=0, i_free_lo=-1, i_free_hi=-1, **box))
    else:
        zone = ActiveZone(Zone(p_lo=0, p_hi=particles.n, n_lo=0, n_hi=grid.n_nodes, i_free_lo=0,
                               i_free_hi=grid.shape[0], **box))
    zone.retired = np.zeros(particles.n, dtype=bool)
    state = State(particles=particles, sphere=sphere, work=work, zone=zone)
    update_active_zone(state, const)
    return state, const


def contact_stiffness(scene: Scene, contact_radius: float) -> float:
    """Upper estimate of the full-body contact stiffness dFz/d(depth), N/m, for the load controller.

    Elastic (Hertz) stiffness 2 E* a of the contacting layer over the expected contact radius: on
    loading and unloading the contact responds elastically, much stiffer than the plastic Fn / dp,
    and a gain tuned to the plastic stiffness makes the sphere chatter.
    """
    top = scene.layers.coating if scene.layers.coated else scene.layers.substrate
    e_star = top.youngs_modulus_Pa / (1.0 - top.poisson_ratio**2)
    return STIFFNESS_FACTOR * 2.0 * e_star * contact_radius


# ----------------------------------------------------------------------------- one step
def step(s: State, c: Constants) -> None:
    """Advance the state by one time step dt (the module docstring's steps 1-5; the kernels' bundles:
    :mod:`plough.mpm.bundles`)."""
    update_active_zone(s, c)
    P, G, S, Z, w = s.particles, grid_data(s, c), sphere_data(s, c), s.zone.ranges, s.work
    if c.project_dilatation:  # 1. P2G, with the pressure projected as the dilatation is
        transfers.scatter_pressure(P, G, Z)
        transfers.grid_dilatation(G, Z)
    transfers.p2g(P, G, c.dt, Z, c.project_dilatation)
    transfers.grid_update(G, Z)  # 2. grid velocities, boundary conditions
    if c.contact_mode == "particle":  # 3. contact: the sphere on the near particles, through their nodes
        contact.particle_contact(P, G, S, Z, c.contact_law, s.step, c.dt, w.last_push_p, w.contact_out)
    else:  # or: the near particles' stress on the nodes, then the sphere on the nodes
        contact.scatter_contact_stress(P, G, S, Z, c.contact_mode == "grid_local")
        contact.sphere_contact(G, S, c.contact_law, s.step, c.dt, w.contact_out)
    if G.mirror_j0 >= 0:
        transfers.mirror_ghosts(G, Z)
    move_sphere(s.sphere, c)  # 4. sphere motion
    transfers.g2p_kinematics(P, G, w.v_grid, c.flip, c.project_dilatation, Z)  # 5. G2P: velocities,
    if c.project_dilatation:
        transfers.grid_dilatation(G, Z)  # the projected dilatation,
    transfers.g2p_update(P, G, c.material, S, Z, c.dt, c.project_dilatation, w.v_grid, w.L_buf, w.acc,
                         transfers.G2P_BLOCK)  # the stress update and advection
    account_energy(w)
    growth.grow_to_hold(s, c)  # room for the particles past a growing face of the grid
    check_stability(s, c)
    control_sphere(s.sphere, c.symmetry_factor * reaction_z(w), c)
    s.step += 1
    s.time += c.dt


def grid_data(s: State, c: Constants) -> GridData:
    """The grid bundle ``G`` of this step: the grid's geometry and the work's per-node arrays (both change
    when the grid grows)."""
    w = s.work
    return GridData(origin=c.grid.origin, dx=c.grid.dx, shape=c.shape, mirror_j0=c.mirror_j0, flags=w.flags,
                    buf=w.grid_buf, m=w.grid_m, v=w.grid_v, div=w.grid_div, cbuf=w.cbuf, last_push=w.last_push)


def sphere_data(s: State, c: Constants) -> SphereData:
    """The sphere bundle ``S``: the state's centre and velocity (moved in place), the run's radius and reach."""
    return SphereData(centre=s.sphere.centre, velocity=s.sphere.velocity, radius=c.sphere_radius,
                      near_dist=c.near_dist)


def update_active_zone(s: State, c: Constants) -> None:
    """Move the active zone with the sphere: freeze the particles it leaves, retire the grid slabs.

    The zone holds the particles whose initial x lies within ``zone_half_width_m`` of the sphere's
    centre; a clamp face sits at each end of the zone where particles lie frozen beyond it (until
    then the block's own free end faces stay free). Retired nodes get zero mass and velocity.
    """
    if c.zone_half_width_m <= 0.0:
        return
    z, w, p = s.zone.ranges, s.work, s.particles
    g = c.grid
    nx, ny, nz = g.shape
    lo_x = s.sphere.centre[0] - c.zone_half_width_m
    hi_x = s.sphere.centre[0] + c.zone_half_width_m
    p_lo = max(z.p_lo, int(np.searchsorted(c.zone_x0_m, lo_x, side="left")))
    p_hi = max(z.p_hi, int(np.searchsorted(c.zone_x0_m, hi_x, side="right")))
    if p_lo > z.p_lo:
        elastic, kinetic = transfers.freeze_particles(p, w.v_grid, c.table, z.p_lo, p_lo)
        s.zone.frozen_elastic_J += elastic
        s.zone.frozen_kinetic_loss_J += kinetic
    n = c.zone_x0_m.size
    i_free_lo = math.ceil((lo_x - g.origin[0]) / g.dx) if p_lo > 0 else 0
    i_free_hi = math.floor((hi_x - g.origin[0]) / g.dx) if p_hi < n else nx
    slab = ny * nz
    n_lo = max(z.n_lo, max(i_free_lo - ZONE_PAD_CELLS, 0) * slab)
    n_hi = max(z.n_hi, min(i_free_hi + ZONE_PAD_CELLS + 1, nx) * slab)
    if n_lo > z.n_lo:
        w.grid_m[z.n_lo:n_lo] = 0.0
        w.grid_v[z.n_lo:n_lo] = 0.0
        w.grid_div[z.n_lo:n_lo] = 0.0
    s.zone.ranges = z._replace(p_lo=p_lo, p_hi=p_hi, n_lo=n_lo, n_hi=n_hi, i_free_lo=max(z.i_free_lo, i_free_lo),
                               i_free_hi=max(z.i_free_hi, i_free_hi))
    # a stencil spans x - 1.5 dx .. x + 1.5 dx; one cell more for the range's advance before the next check
    # (the check box's arrays are the zone's own: changed in place)
    z.check_lo[0] = c.grid_lo[0] if n_lo == 0 else max(c.grid_lo[0], g.origin[0] + (n_lo // slab + 1.5) * g.dx)
    z.check_hi[0] = c.grid_hi[0] if n_hi == nx * slab else min(c.grid_hi[0],
                                                                 g.origin[0] + (n_hi // slab - 2.5) * g.dx)


def reaction_z(w: Work) -> float:
    """Upward force of the simulated material on the sphere (normal traction plus interface shear).

    With the mirror plane this is the force of one half; the full-body force is twice it.
    """
    out = w.contact_out
    return float(out[contact.OUT_FN + 2] + out[contact.OUT_FT + 2])


def move_sphere(sph: SphereState, c: Constants) -> None:
    sph.centre += c.dt * sph.velocity
    if sph.phase == "slide":
        sph.slid_m += c.dt * sph.velocity[0]


def elastic_energy(s: State, c: Constants) -> float:
    """Elastic energy of the block, J: the active particles' (``transfers.elastic_energies``, summed over the
    chunks as ``g2p_update`` deals them) and what the frozen ones keep. Called where it is recorded, not every
    step."""
    transfers.elastic_energies(s.particles, c.table, s.zone.ranges, s.work.acc, transfers.G2P_BLOCK)
    return float(s.work.acc[:, transfers.ACC_ELASTIC].sum()) + s.zone.frozen_elastic_J


def account_energy(w: Work) -> None:
    out = w.contact_out
    # sphere power x dt = work on the material + interface slip loss + normal push loss (contact.OUT_*)
    w.external_work += float(out[contact.OUT_WORK])
    w.interface_dissipation += float(out[contact.OUT_DISSIPATION])
    w.contact_impact_loss += float(out[contact.OUT_IMPACT])
    w.plastic_work += float(w.acc[:, transfers.ACC_PLASTIC_WORK].sum())
    w.heat += float(w.acc[:, transfers.ACC_HEAT].sum())


def control_sphere(sph: SphereState, fz: float, c: Constants) -> None:
    """Press, settle, slide; under load control the height follows the filtered reaction.

    Proportional-integral law on the load error e = Fn - Fz_filtered:
    v_z = -gain (e + integral(e dt) / T_i), bounded by the pressing speed (no integration while
    bounded, so the integral does not wind up). The gain is set from an upper estimate of the
    contact stiffness (:func:`contact_stiffness`) so that the loop's time constant is at least
    CONTROL_STEPS steps, slower than the force filter: the sphere neither chatters nor bounces.
    The integral term removes the steady offset a proportional law leaves while the sphere sinks
    or rises as the groove develops.
    """
    sph.fz_filtered += c.filter_alpha * (fz - sph.fz_filtered)
    if c.control == "load":
        error = c.load_N - sph.fz_filtered
        vz = -c.control_gain * (error + sph.load_error_integral / (INTEGRAL_STEPS * c.dt))
        if sph.phase != "press" and abs(vz) < c.press_speed:
            sph.load_error_integral += error * c.dt
        vz = min(max(vz, -c.press_speed), c.press_speed)
        reached = sph.fz_filtered >= c.load_N
    else:
        depth = c.sphere_radius - sph.centre[2]
        vz = -c.press_speed if depth < c.target_depth else 0.0
        vz = max(vz, -(c.target_depth - depth) / c.dt)
        reached = depth >= c.target_depth * (1 - 1e-9)
    if sph.phase == "press":
        sph.velocity[2] = -c.press_speed if not reached else vz
        if reached:
            sph.phase = "settle"
    else:
        sph.velocity[2] = vz
    if sph.phase == "settle":
        sph.settle_left -= 1
        if sph.settle_left <= 0:
            sph.phase = "slide"
            sph.velocity[0] = c.slide_speed
    if sph.phase == "slide" and sph.slid_m >= c.slide_distance:
        sph.phase = "done"
        sph.velocity[:] = 0.0


CAUSES = {
    transfers.BAD_NONFINITE: "non-finite velocity or stress: the time step is too large (lower discretisation.cfl) "
                             "or the mass scaling too small",
    transfers.BAD_J: "a particle's volume collapsed or exploded (J <= 0 or J > 4): time step too large (cfl) or "
                     "the sphere tears the material (load too high for the particle size)",
    transfers.BAD_LEFT_GRID: "a particle left the grid: the load is too high for the domain (enlarge domain.radius_m"
                             " / length_m) or the material was flung out by inertia (lower mass_scaling or speed)",
}


def check_stability(s: State, c: Constants) -> None:
    """Stop at once on the worst flag the step's kernels left (``g2p_update``'s accumulators), naming the
    step, the sliding distance and the likely cause, and on kinetic energy out of proportion; it only
    detects: a particle past a face of the grid that grows has been answered before
    (:func:`plough.mpm.growth.grow_to_hold`: the flag is cleared, or names the particle still outside)."""
    acc = s.work.acc
    bad = int(acc[:, transfers.ACC_BAD].max())
    where = f"at step {s.step} (t = {s.time:.4g} s, sliding distance {s.sphere.slid_m * 1e6:.1f} um)"
    chunk = int(np.argmax(acc[:, transfers.ACC_BAD]))
    index = int(acc[chunk, transfers.ACC_BAD_INDEX])
    if bad != transfers.BAD_NONE:
        cause = CAUSES[bad]
        if bad == transfers.BAD_LEFT_GRID and index >= 0 and s.particles.x[index, 2] > c.grid_hi[2]:
            cause = (f"a particle rose above the grid's top (z = {c.grid_hi[2] * 1e6:.1f} um over the original "
                     "surface): material the sphere pushes up (a growing prow: set domain.headroom_m higher) or a "
                     "particle flung off the surface (lower mass_scaling or speed)")
        elif bad == transfers.BAD_LEFT_GRID and index >= 0 and s.particles.x[index, 0] > c.grid_hi[0]:
            ahead = (s.particles.x[index, 0] - s.sphere.centre[0]) * 1e6
            cause = (f"a particle moved past the grid's far end (x = {c.grid_hi[0] * 1e6:.1f} um; the block ends at "
                     f"{c.block_end_m * 1e6:.1f} um), {ahead:.1f} um ahead of the sphere's centre: material the sphere "
                     "pushes ahead of it (a prow or chip of a soft coating: lengthen domain.length_m) or a particle "
                     "flung off the surface (lower mass_scaling or speed)")
        elif bad == transfers.BAD_LEFT_GRID and index >= 0 and s.particles.x[index, 1] > c.grid_hi[1]:
            cause = (f"a particle moved out through the grid's side (y = {c.grid_hi[1] * 1e6:.1f} um; the block's "
                     f"side is at {c.block_side_m * 1e6:.1f} um): material the sphere throws sideways (a prow or "
                     "chip of a soft coating: enlarge domain.radius_m) or a particle flung off the surface (lower "
                     "mass_scaling or speed)")
        elif bad == transfers.BAD_LEFT_GRID and index >= 0 and _left_zone(s, c, s.particles.x[index, 0]):
            zone = s.zone.ranges
            cause = (f"a particle moved out of the active zone's grid slabs (x {zone.check_lo[0] * 1e6:.1f}.."
                     f"{zone.check_hi[0] * 1e6:.1f} um), about a cell past its start at the zone's end: material "
                     "the sphere pushes beyond the zone (widen discretisation.active_zone_contact_radii, or switch "
                     "it off)")
        raise InstabilityError(f"unstable run {where}: {cause}{_particle_report(s, c, index)}")
    kinetic = float(acc[:, transfers.ACC_KINETIC].sum())
    budget = 2.0 * abs(s.work.external_work) + c.load_N * c.grid.dx
    if kinetic > budget:
        raise InstabilityError(f"unstable run {where}: kinetic energy {kinetic:.3g} J exceeds twice the work done "
                              f"by the sphere ({s.work.external_work:.3g} J): inertia dominates; lower "
                              "discretisation.mass_scaling or sliding.speed_m_s, or the time step (cfl)")


def _left_zone(s: State, c: Constants, x: float) -> bool:
    """Whether x lies on the grid but outside the active zone's slabs (its ranges' ``check_lo``/``check_hi``)."""
    z = s.zone.ranges
    return c.grid_lo[0] <= x <= c.grid_hi[0] and not (z.check_lo[0] <= x <= z.check_hi[0])


def _particle_report(s: State, c: Constants, index: int) -> str:
    """Where the offending particle is, relative to the sphere and the grid, to tell the causes apart."""
    if index < 0:
        return ""
    x = s.particles.x[index]
    rel = (x - s.sphere.centre) * 1e6
    lo, hi = c.grid_lo, c.grid_hi
    return (f" [particle {index} at ({x[0] * 1e6:.1f}, {x[1] * 1e6:.1f}, {x[2] * 1e6:.1f}) um, "
            f"({rel[0]:.1f}, {rel[1]:.1f}, {rel[2]:.1f}) um from the sphere centre, initial height "
            f"{s.particles.z0[index] * 1e6:.1f} um, plastic strain {s.particles.eps_p[index]:.3g}; grid interior "
            f"x {lo[0] * 1e6:.1f}..{hi[0] * 1e6:.1f}, y {lo[1] * 1e6:.1f}..{hi[1] * 1e6:.1f}, "
            f"z {lo[2] * 1e6:.1f}..{hi[2] * 1e6:.1f} um]")
