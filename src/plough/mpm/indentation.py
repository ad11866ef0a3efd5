"""Static indentation: the sphere pressed to a depth and held there (no sliding), for the verification tests
and the contact benchmark (docs/verification.md: Hertz, Tabor).

- :func:`hertz_scene`: an elastic block that never yields, so the force has Hertz's closed form
  F = 4/3 E* sqrt(R) d^1.5 (:func:`hertz_force`);
- :func:`tabor_scene`: the uncoated rigid-plastic material (H = 900 MPa, sigma_y = H / 3, E = 210 GPa), fully
  plastic at a few um depth, whose mean pressure over the true contact is about 2.8-3 sigma_y (Tabor), pressed
  quasi-statically (:data:`QUASI_STATIC_PRESS_FRACTION`);
- :func:`hold_at_depth`: press to the depth, settle until the block's elastic ringing has died down
  (:data:`SETTLE_CROSSINGS` times the steps a shear wave takes to cross the block; a plastic block
  :data:`PLASTIC_SETTLE_CROSSINGS`), and average the full-body force over about one period of the block's slowest
  mode (:data:`AVERAGE_CROSSINGS` crossings);
- :func:`crossing_steps`: the steps a shear wave takes to cross the block, the hold's unit of time;
- :func:`half_space_force` (:class:`HalfSpace`; the fit :func:`half_space_extrapolation`): Hertz's half-space
  from blocks of two or more sizes. The block is clamped on its
  curved face, which stiffens it: F(L) = F_inf (1 + A / L) to first order in a / L, as for an elastic layer on a
  rigid base. Measured (docs/journal/2026-12-02-hertz-block.md): at h = 10 um and 8 um depth, the grid contact's
  force is +38.7% / +24.6% / +20.6% above Hertz in blocks of radius 240 / 480 / 720 um, and 1 / L fits the three
  within 0.4%: the half-space error is +11.3%, the 240 um block adds about a fifth;
- :func:`contact_radius_from_particles`: the radius where the material's surface (the particles' faces, pile-up
  included) leaves the sphere, from rings of one particle size around the sphere's axis.
"""

from __future__ import annotations

import math
import time
from collections.abc import Callable, Sequence
from dataclasses import dataclass, replace

import numpy as np

from plough.materials import rigid_plastic
from plough.mpm import contact, solver
from plough.mpm.scene import Discretisation, Scene

R_M, E_PA, NU = 200e-6, 210e9, 0.3
#: the rigid-plastic hardness of the Tabor scene, Pa (the uncoated reference scene's)
TABOR_HARDNESS_PA = 900e6


def hertz_force(depth_m: float, radius_m: float = R_M, youngs_Pa: float = E_PA, poisson_ratio: float = NU) -> float:
    """Hertz's force on a rigid sphere pressed ``depth_m`` into an elastic half-space, N."""
    return 4.0 / 3.0 * youngs_Pa / (1.0 - poisson_ratio**2) * math.sqrt(radius_m) * depth_m**1.5


#: press speed of the plastic indentation as a fraction of the scenes' 0.1 m/s (the scenes' default is 0.25). A
#: mass-scaled press that stops at the depth leaves the plastic zone under the sphere moving: it flows on, the crater
#: deepens past the sphere and the contact unloads elastically, and plastic flow does not give the force back. The
#: overshoot's depth, about v a / c_s (c_s the mass-scaled shear speed), compares with the contact's elastic recovery
#: p a / E* as v E* / (c_s p): about 2 at the default press (v sqrt(mass_scaling) = 25 m/s), where the held force was
#: 8.2 N against 12.7 N pressed slowly (h = 10 um, 8 um deep). The held force converges as the press
#: slows: 12.35 / 12.51 / 12.69 N at v sqrt(mass_scaling) = 5 / 2 / 1 m/s (mass scaling 1e6), 12.70 / 12.73 N at 1 /
#: 0.5 m/s with mass scaling 1e4 (docs/journal/2026-12-03-tabor.md). An elastic block gives its force back, so the
#: Hertz checks keep the default press.
QUASI_STATIC_PRESS_FRACTION = 0.01


def section_radius(depth_m: float, radius_m: float = R_M) -> float:
    """Radius of the sphere's section at the original surface, ``depth_m`` below the top of the sphere, m."""
    return math.sqrt(2.0 * radius_m * depth_m - depth_m**2)


def _indentation_scene(name: str, substrate, h_um: float, depth_um: float, domain_um: float, dilatation: str,
                       contact_mode: str, particles_per_cell: int, press_speed_fraction: float | None = None) -> Scene:
    sliding = {"distance_um": 100, "control": "displacement", "depth_um": depth_um}
    if press_speed_fraction is not None:  # otherwise the scene's default press
        sliding["press_speed_fraction"] = press_speed_fraction
    return Scene.from_dict({
        "name": name, "load_N": 1.0, "sphere": {"radius_um": R_M * 1e6},
        "layers": {"substrate": substrate},
        "interface": {"model": "proportional", "f": 0.0},
        "domain": {"radius_um": domain_um, "length_um": 2 * domain_um, "symmetric": True},
        "sliding": sliding,
        "discretisation": {"particle_size_um": h_um, "particles_per_cell": particles_per_cell, "cfl": 0.3,
                           "mass_scaling": 1e6, "dilatation": dilatation, "contact": contact_mode},
    })


def hertz_scene(h_um: float, depth_um: float, domain_um: float = 240.0, poisson_ratio: float = NU,
                dilatation: str = "projected", contact_mode: str = Discretisation.contact,
                particles_per_cell: int = 2) -> Scene:
    """The sphere (R = 200 um) held ``depth_um`` deep in an elastic block that never yields (half block of radius
    ``domain_um``, twice as long, mirror plane; frictionless)."""
    substrate = replace(rigid_plastic("elastic", 1e15, coating=False), poisson_ratio=poisson_ratio)  # never yields
    return _indentation_scene("hertz", substrate, h_um, depth_um, domain_um, dilatation, contact_mode,
                              particles_per_cell)


def tabor_scene(h_um: float, depth_um: float, domain_um: float = 240.0, contact_mode: str = Discretisation.contact,
                particles_per_cell: int = 2, press_speed_fraction: float = QUASI_STATIC_PRESS_FRACTION) -> Scene:
    """The sphere held ``depth_um`` deep in the rigid-plastic block of the uncoated reference scene (H = 900 MPa,
    sigma_y = 300 MPa, E = 210 GPa; frictionless), pressed at ``press_speed_fraction`` of 0.1 m/s."""
    substrate = rigid_plastic("tabor", TABOR_HARDNESS_PA, coating=False)
    return _indentation_scene("tabor", substrate, h_um, depth_um, domain_um, "projected", contact_mode,
                              particles_per_cell, press_speed_fraction)


@dataclass
class Indentation:
    """What :func:`hold_at_depth` measured."""

    force_N: float  # full-body normal force, mean over the averaging window (about a period of the slowest mode)
    force_std_N: float  # its standard deviation over that window
    force_drift: float  # the window's mean over the mean of the window before it, less 1: settled if small
    steps: int
    wall_s: float
    closest_centre_m: float  # over the run, the closest a particle centre came to the sphere's surface (< 0: inside)
    contact_area_xy_m2: float  # the contact's own projected area (nodes or particles), full body, mean like the force
    forces_N: np.ndarray  # the full-body normal force of every step, N
    press_steps: int  # the steps the press took: forces_N[press_steps:] is the hold
    state: solver.State
    const: solver.Constants


#: settle for this many times the steps a shear wave takes to cross the block's radius (the grid contact's force in
#: the 240 um block at h = 10 um, nu = 0.3, is then within about 1.5% of where it ends after 96 P-wave crossings)
SETTLE_CROSSINGS = 12.0
#: average the force over this many crossings, at least a period of the block's slowest mode
AVERAGE_CROSSINGS = 4.0
#: the plastic block's hold: after a quasi-static press the held force still relaxes by about 0.3% a crossing for
#: 20 crossings (12.69 N after 12, 12.57 N from 24 to 48, h = 10 um, 8 um deep; docs/journal/2026-12-03-tabor.md)
PLASTIC_SETTLE_CROSSINGS = 24.0


def crossing_steps(scene: Scene, dt_s: float) -> int:
    """Steps of ``dt_s`` a shear wave takes to cross the block's radius, in the scene's slowest material.

    The shear speed is sqrt(G / (mass_scaling rho)); dt = cfl dx / (c_p + v_max) is set by the fastest P wave, so
    a P wave crosses the radius in about radius / (cfl dx) steps and a shear wave in sqrt((K + 4 G / 3) / G) times
    as many (1.87 at nu = 0.3, 22 at nu = 0.499): the slowest modes of a nearly incompressible block are its shear
    modes.
    """
    ms = scene.discretisation.mass_scaling
    c_s = min(math.sqrt(m.shear_modulus_Pa / (ms * m.density_kg_m3)) for m in scene.layers.materials)
    return max(1, math.ceil(scene.domain.radius_m / (c_s * dt_s)))


def hold_at_depth(scene: Scene, settle_crossings: float = SETTLE_CROSSINGS) -> Indentation:
    """Press the sphere to the scene's depth at the middle of the block, settle, and measure the force.

    The press excites the block's elastic modes; with no damping but the transfers' they ring for many periods,
    the slowest with a period of a few shear-wave crossings of the block's radius (:func:`crossing_steps`). So the
    sphere is held for ``settle_crossings`` crossings (at least ``solver.SETTLE_STEPS`` steps) and the force averaged
    over the last :data:`AVERAGE_CROSSINGS` of them; ``force_drift`` compares that mean with the window before it.
    The hold lasts at least two averaging windows (eight crossings), whatever ``settle_crossings`` says.
    """
    state, const = solver.init(scene)
    state.sphere.centre[0] = 0.5 * scene.domain.length_m
    crossing = crossing_steps(scene, const.dt)
    window = max(1, int(AVERAGE_CROSSINGS * crossing))
    state.sphere.settle_left = max(solver.SETTLE_STEPS, int(settle_crossings * crossing), 2 * window)
    fz, area = [], []
    press_steps = 0
    closest = math.inf
    t0 = time.perf_counter()
    while state.sphere.phase != "slide":  # press to the depth, then settle
        solver.step(state, const)
        out = state.work.contact_out
        fz.append(const.symmetry_factor * (out[contact.OUT_FN + 2] + out[contact.OUT_FT + 2]))
        area.append(const.symmetry_factor * out[contact.OUT_AREA_XY])
        # ACC_PENETRATION: the deepest a particle centre lies inside the sphere (negative: the closest outside)
        closest = min(closest, -float(state.work.acc[:, solver.transfers.ACC_PENETRATION].max()))
        if not press_steps and state.sphere.phase == "settle":
            press_steps = state.step
    force = float(np.mean(fz[-window:]))
    return Indentation(force_N=force, force_std_N=float(np.std(fz[-window:])),
                       force_drift=force / float(np.mean(fz[-2 * window:-window])) - 1.0,
                       steps=state.step, wall_s=time.perf_counter() - t0, closest_centre_m=closest,
                       contact_area_xy_m2=float(np.mean(area[-window:])), forces_N=np.asarray(fz),
                       press_steps=press_steps, state=state, const=const)


@dataclass
class HalfSpace:
    """What :func:`half_space_force` measured: the force extrapolated to an unbounded block, and the blocks'."""

    force_N: float  # F_inf, the half-space's force
    stiffening_m: float  # A of F(L) = F_inf (1 + A / L): the clamped block's stiffening, a length
    domains_m: tuple[float, ...]  # the blocks' radii L
    runs: tuple[Indentation, ...]  # one per block


def half_space_extrapolation(domains_m: Sequence[float], forces_N: Sequence[float]) -> tuple[float, float]:
    """(F_inf, A) of F(L) = F_inf (1 + A / L) through the forces measured in blocks of radius L (least squares in
    1 / L; exact for two blocks)."""
    inv = 1.0 / np.asarray(domains_m, dtype=float)
    if len(forces_N) != inv.size:
        raise ValueError(f"forces_N: {len(forces_N)} forces for {inv.size} block radii; give one per block")
    if inv.size < 2 or np.unique(inv).size < 2:
        raise ValueError(f"domains_m: {list(domains_m)} must hold at least two different block radii")
    slope, intercept = np.polyfit(inv, np.asarray(forces_N, dtype=float), 1)
    return float(intercept), float(slope / intercept)


def half_space_force(scene_of: Callable[[float], Scene], domains_um: Sequence[float] = (240.0, 480.0)) -> HalfSpace:
    """The force in an unbounded block, from :func:`hold_at_depth` in blocks of radius ``domains_um``.

    ``scene_of(domain_um)`` makes the scene (for example ``lambda L: hertz_scene(10.0, 8.0, domain_um=L)``). The
    block is clamped on its curved face, which stiffens it in proportion to a / L to first order (a the contact
    radius), as an elastic layer on a rigid base is (Dimitriadis et al. 2002 for the flat layer):
    F(L) = F_inf (1 + A / L), extrapolated by :func:`half_space_extrapolation`.
    """
    runs = tuple(hold_at_depth(scene_of(L)) for L in domains_um)
    domains_m = tuple(L * 1e-6 for L in domains_um)
    f_inf, stiffening = half_space_extrapolation(domains_m, [r.force_N for r in runs])
    return HalfSpace(force_N=f_inf, stiffening_m=stiffening, domains_m=domains_m, runs=runs)


def contact_radius_from_particles(state: solver.State, const: solver.Constants, tolerance: float = 0.25) -> float:
    """Radius of the true contact, m: where the material's surface leaves the sphere, pile-up included.

    Rings of one particle size h around the sphere's axis; in each, the smallest face gap of its particles
    (centre distance to the sphere's centre less R less half the particle's size). The contact ends where
    that gap first exceeds ``tolerance`` h, outward from the axis; the radius is interpolated linearly between
    the last ring in contact and the first out (ring midpoints). The same measure for every contact."""
    x, c = state.particles.x, state.sphere.centre
    size = (state.particles.vol0 * state.particles.J) ** (1.0 / 3.0)
    h = float(np.min(size))
    r = np.hypot(x[:, 0] - c[0], x[:, 1] - c[1])
    gap = np.linalg.norm(x - c, axis=1) - const.sphere_radius - 0.5 * size
    below = x[:, 2] < c[2]
    tol = tolerance * h
    ring = np.floor(r / h).astype(np.int64)
    n_rings = int(const.sphere_radius / h)
    g_min = np.full(n_rings, np.inf)
    sel = below & (ring < n_rings)
    np.minimum.at(g_min, ring[sel], gap[sel])
    mid = (np.arange(n_rings) + 0.5) * h
    for k in range(n_rings):
        if g_min[k] > tol:
            if k == 0:
                return 0.0
            g0, g1 = g_min[k - 1], min(g_min[k], 4.0 * h)
            return float(mid[k - 1] + (tol - g0) / (g1 - g0) * h)
    return float(mid[-1])
