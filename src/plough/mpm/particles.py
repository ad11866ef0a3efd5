"""Material points as a struct of arrays, seeded on a regular lattice in the half cylinder.

Each particle fills a cube of edge h at the start (volume h^3), centred at ((i + 1/2) h,
(j + 1/2) h, -(k + 1/2) h) so the top face of the first layer lies on the original surface z = 0.
The coating is the material above z = -t. A particle whose cube straddles the interface is
represented faithfully rather than rounded: it carries both materials with the coating's volume
fraction ``frac_a`` (density, elastic moduli and flow stress are volume-weighted mixes, see
:mod:`plough.mpm.constitutive`). Pure particles have ``frac_a = 1`` and ``mat_b = mat_a``.

Graded particles (``discretisation.graded``): outside the fine zone along the track (k expected
contact radii wide and, unless ``fine_zone_depth_particles`` shapes its depth by the groove and the
coating, as deep; at least 6 h), each complete
2 x 2 x 2 group of lattice cubes (all eight inside the half cylinder) becomes one particle of edge
2 h at the group's centre, with the group's volume, mass and coating volume fraction, so the block's
mass, volume, coating volume and centre of mass are those of the uniform lattice exactly. A
particle's edge is ``cbrt(vol0)``; nothing downstream assumes h.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numpy as np

from plough.mpm.constitutive import I_RHO, rest_flow_stresses
from plough.mpm.scene import FINE_ZONE_SHAPES, Scene


class Particles(NamedTuple):
    """The particles' state, one row per particle: the kernels' particle bundle ``P``
    (:mod:`plough.mpm.bundles`); the arrays are updated in place, never replaced."""

    x: np.ndarray  # (n, 3) position, m
    v: np.ndarray  # (n, 3) velocity, m/s
    C: np.ndarray  # (n, 3, 3) APIC affine matrix = velocity gradient, 1/s
    stress: np.ndarray  # (n, 6) Cauchy stress, Voigt xx yy zz yz xz xy, Pa
    J: np.ndarray  # (n,) volume ratio
    vol0: np.ndarray  # (n,) initial volume, m^3
    mass: np.ndarray  # (n,) mass including mass scaling, kg
    eps_p: np.ndarray  # (n,) equivalent plastic strain
    temperature: np.ndarray  # (n,) K
    sigma_y0: np.ndarray  # (n,) flow stress at rest sigma_y(eps_p, 0, T), Pa: a cache update_stress keeps
    deps_last: np.ndarray  # (n,) plastic strain increment of the particle's last plastic step (return-map guess)
    mat_a: np.ndarray  # (n,) int32 material row
    mat_b: np.ndarray  # (n,) int32 second material row (straddling particles)
    frac_a: np.ndarray  # (n,) volume fraction of mat_a
    near: np.ndarray  # (n,) int8: within reach of the sphere's contact nodes
    z0: np.ndarray  # (n,) initial height, m: labels material lines (the coating interface) after deformation

    @property
    def n(self) -> int:
        return self.x.shape[0]


def seed_particles(scene: Scene, material_rows: dict[str, int], table: np.ndarray) -> Particles:
    """Lattice particles of the scene's block with their materials.

    ``material_rows`` maps 'coating'/'substrate' to rows of the packed material ``table``
    (:func:`plough.mpm.constitutive.pack_materials`), which gives each row's physical density and
    the flow stress at rest the particles start with.
    """
    h = scene.discretisation.particle_size_m
    x = _lattice(scene, int(round(scene.domain.length_m / h)))
    n = x.shape[0]
    vol0 = np.full(n, h**3)
    if scene.discretisation.graded:
        x, vol0 = coarsen_far_field(x, h, _fine_half_width(scene), scene.discretisation.fine_zone_shape,
                                    _fine_depth(scene))
        n = x.shape[0]

    t = scene.layers.coating_thickness_m
    sub = material_rows["substrate"]
    mat_a = np.full(n, sub, dtype=np.int32)
    mat_b = np.full(n, sub, dtype=np.int32)
    frac_a = np.ones(n)
    if scene.layers.coated:
        coat = material_rows["coating"]
        # coating volume fraction of the cube [z - e/2, z + e/2] (edge e) above z = -t
        edge = np.cbrt(vol0)
        frac = np.clip((x[:, 2] + 0.5 * edge + t) / edge, 0.0, 1.0)
        frac[np.abs(frac - 1.0) < 1e-9] = 1.0  # exact multiples of h: full layers despite round-off
        frac[frac < 1e-9] = 0.0
        mat_a[frac > 0] = coat
        frac_a = np.where(frac > 0, frac, 1.0)
    densities = table[:, I_RHO]
    rho = frac_a * densities[mat_a] + (1.0 - frac_a) * densities[mat_b]
    mass = rho * scene.discretisation.mass_scaling * vol0
    eps_p = np.zeros(n)
    temperature = np.full(n, scene.outputs.initial_temperature_K)
    sigma_y0 = np.empty(n)
    rest_flow_stresses(eps_p, temperature, mat_a, mat_b, frac_a, table, sigma_y0)
    return Particles(
        x=x, v=np.zeros((n, 3)), C=np.zeros((n, 3, 3)), stress=np.zeros((n, 6)), J=np.ones(n), vol0=vol0,
        mass=mass, eps_p=eps_p, temperature=temperature, sigma_y0=sigma_y0, deps_last=np.zeros(n),
        mat_a=mat_a, mat_b=mat_b, frac_a=frac_a, near=np.zeros(n, dtype=np.int8), z0=x[:, 2].copy(),
    )


def _lattice(scene: Scene, nx: int) -> np.ndarray:
    """Centres of the h-cubes of the first ``nx`` layers along x that lie in the half cylinder."""
    h = scene.discretisation.particle_size_m
    R = scene.domain.radius_m
    nr = int(np.ceil(R / h))
    xs = (np.arange(nx) + 0.5) * h
    ys = (np.arange(nr) + 0.5) * h
    if not scene.domain.symmetric:
        ys = np.concatenate([-ys[::-1], ys])
    zs = -(np.arange(nr) + 0.5) * h
    Y, Z = np.meshgrid(ys, zs, indexing="ij")
    inside = Y**2 + Z**2 <= R * R
    y2, z2 = Y[inside], Z[inside]
    n_cross = y2.size
    x = np.empty((nx * n_cross, 3))
    x[:, 0] = np.repeat(xs, n_cross)
    x[:, 1] = np.tile(y2, nx)
    x[:, 2] = np.tile(z2, nx)
    return x


#: the fine zone is never narrower than this many particle sizes h: on a 1 N scene whose expected
#: contact radius is 2.7 h (tests/mpm/test_verification.py's tiny scene at h = 10 um) a 4 h zone moved dp +63%
#: (1.45 -> 2.36 um), a 5.3 h zone +2.7%
FINE_ZONE_MIN_PARTICLES = 6.0


def _fine_half_width(scene: Scene) -> float:
    """Half-width and depth of the fine zone: k expected contact radii, at least 6 h."""
    a, _ = scene.expected_contact()
    h = scene.discretisation.particle_size_m
    return max(scene.discretisation.fine_zone_contact_radii * a, FINE_ZONE_MIN_PARTICLES * h)


def _fine_depth(scene: Scene) -> float:
    """Depth of the fine zone: its half-width, or with ``fine_zone_depth_particles`` = m the expected groove
    depth or the coating thickness, whichever is deeper, plus m h, within [6 h, the half-width]."""
    width = _fine_half_width(scene)
    m = scene.discretisation.fine_zone_depth_particles
    if m is None:
        return width
    _, dp = scene.expected_contact()
    h = scene.discretisation.particle_size_m
    deformed = max(dp, scene.layers.coating_thickness_m if scene.layers.coated else 0.0)
    return min(width, max(deformed + m * h, FINE_ZONE_MIN_PARTICLES * h))


def uniform_particle_count(scene: Scene) -> float:
    """Particles of the uniform h lattice filling the block: its volume (a quarter cylinder with the
    mirror plane, half without) over h^3, within a fraction of a per cent of what is seeded."""
    dom, h = scene.domain, scene.discretisation.particle_size_m
    cross = (0.25 if dom.symmetric else 0.5) * math.pi * dom.radius_m**2
    return cross * dom.length_m / h**3


def particle_count_ratio(scene: Scene) -> float:
    """Particles of the scene's seeding over those of the uniform lattice (1 unless graded), from one
    2 h slice of the block (the grading does not change along x)."""
    if not scene.discretisation.graded:
        return 1.0
    h = scene.discretisation.particle_size_m
    x = _lattice(scene, 2)
    coarse = coarsen_far_field(x, h, _fine_half_width(scene), scene.discretisation.fine_zone_shape,
                               _fine_depth(scene))[0]
    return coarse.shape[0] / x.shape[0]


def coarsen_far_field(x: np.ndarray, h: float, fine_half_width_m: float, shape: str = "square",
                      fine_depth_m: float | None = None) -> tuple[np.ndarray, np.ndarray]:
    """Merge the lattice particles outside the fine zone into particles of edge 2 h.

    ``x`` are the centres of a lattice of cubes of edge h with faces on multiples of h (y and z
    measured from the mirror plane and the surface). A cube is in the fine zone if a point of it
    is: with ``shape`` "square" where |y| <= ``fine_half_width_m`` and z >= -``fine_depth_m``,
    with "disc" where (y / half-width)^2 + (z / depth)^2 <= 1 (z <= 0 in the block; ``fine_depth_m``
    None: the half-width, a square or a half disc); a group of 2 x 2 x 2
    cubes (aligned to even multiples of h) is
    merged when all eight of its cubes exist and none lies in the fine zone. Returns the new centres
    (sorted x-major, as the lattice was, so that thread chunks stay slabs of the block) and volumes.
    """
    idx = np.floor(x / h).astype(np.int64)  # cube index per axis
    parent = np.floor_divide(idx, 2)
    gap_y = np.maximum(np.abs(x[:, 1]) - 0.5 * h, 0.0)  # from the cube's nearest point to the track's axis
    gap_z = np.maximum(-x[:, 2] - 0.5 * h, 0.0)
    depth = fine_half_width_m if fine_depth_m is None else fine_depth_m
    if shape == "square":
        fine = (gap_y <= fine_half_width_m) & (gap_z <= depth)
    elif shape == "disc" and fine_depth_m is None:
        fine = gap_y**2 + gap_z**2 <= fine_half_width_m**2
    elif shape == "disc":
        fine = (gap_y / fine_half_width_m) ** 2 + (gap_z / depth) ** 2 <= 1.0
    else:
        raise ValueError(f"fine-zone shape {shape!r} is not one of {list(FINE_ZONE_SHAPES)}")
    lo = parent.min(axis=0)
    span = parent.max(axis=0) - lo + 1
    key = ((parent[:, 0] - lo[0]) * span[1] + (parent[:, 1] - lo[1])) * span[2] + (parent[:, 2] - lo[2])
    _, group, count = np.unique(key, return_inverse=True, return_counts=True)
    group_fine = np.zeros(count.size, dtype=bool)
    np.logical_or.at(group_fine, group, fine)
    merge = (count[group] == 8) & ~group_fine[group]
    keep = x[~merge]
    first = np.unique(group[merge], return_index=True)[1]  # one member per merged group
    merged = (2 * parent[merge][first] + 1).astype(float) * h  # the group's centre
    xs = np.concatenate([keep, merged])
    vol = np.concatenate([np.full(keep.shape[0], h**3), np.full(merged.shape[0], 8.0 * h**3)])
    order = np.lexsort((xs[:, 2], xs[:, 1], xs[:, 0]))
    return xs[order], vol[order]


def particles_of(n: int, **arrays: np.ndarray) -> Particles:
    """``n`` particles with the given arrays and, for the rest, particles at rest at the origin: unit volume,
    mass and J, no stress, no plastic strain, at 298 K, of material row 0 alone (for kernels called on
    their own: tests and benchmarks)."""
    unknown = set(arrays) - set(Particles._fields)
    if unknown:
        raise ValueError(f"particles_of: {sorted(unknown)} are not fields of Particles ({list(Particles._fields)})")
    default = {"x": np.zeros((n, 3)), "v": np.zeros((n, 3)), "C": np.zeros((n, 3, 3)), "stress": np.zeros((n, 6)),
               "J": np.ones(n), "vol0": np.ones(n), "mass": np.ones(n), "eps_p": np.zeros(n),
               "temperature": np.full(n, 298.0), "sigma_y0": np.zeros(n), "deps_last": np.zeros(n),
               "mat_a": np.zeros(n, dtype=np.int32), "mat_b": np.zeros(n, dtype=np.int32), "frac_a": np.ones(n),
               "near": np.zeros(n, dtype=np.int8), "z0": np.zeros(n)}
    return Particles(**{**default, **arrays})
