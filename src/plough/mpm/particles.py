"""Material points as a struct of arrays, seeded on a regular lattice in the half cylinder.

Each particle fills a cube of edge h at the start (volume h^3), centred at ((i + 1/2) h,
(j + 1/2) h, -(k + 1/2) h) so the top face of the first layer lies on the original surface z = 0.
The coating is the material above z = -t. A particle whose cube straddles the interface is
represented faithfully rather than rounded: it carries both materials with the coating's volume
fraction ``frac_a`` (density, elastic moduli and flow stress are volume-weighted mixes, see
:mod:`plough.mpm.constitutive`). Pure particles have ``frac_a = 1`` and ``mat_b = mat_a``.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from plough.mpm.scene import Scene


@dataclass
class Particles:
    x: np.ndarray  # (n, 3) position, m
    v: np.ndarray  # (n, 3) velocity, m/s
    C: np.ndarray  # (n, 3, 3) APIC affine matrix = velocity gradient, 1/s
    stress: np.ndarray  # (n, 6) Cauchy stress, Voigt xx yy zz yz xz xy, Pa
    J: np.ndarray  # (n,) volume ratio
    vol0: np.ndarray  # (n,) initial volume, m^3
    mass: np.ndarray  # (n,) mass including mass scaling, kg
    eps_p: np.ndarray  # (n,) equivalent plastic strain
    temperature: np.ndarray  # (n,) K
    mat_a: np.ndarray  # (n,) int32 material row
    mat_b: np.ndarray  # (n,) int32 second material row (straddling particles)
    frac_a: np.ndarray  # (n,) volume fraction of mat_a
    near: np.ndarray  # (n,) int8: within reach of the sphere's contact nodes
    z0: np.ndarray  # (n,) initial height, m: labels material lines (the coating interface) after deformation

    @property
    def n(self) -> int:
        return self.x.shape[0]


def seed_particles(scene: Scene, material_rows: dict[str, int], densities: np.ndarray) -> Particles:
    """Lattice particles of the scene's block with their materials.

    ``material_rows`` maps 'coating'/'substrate' to rows of the packed material table and
    ``densities`` gives each row's physical density (kg/m^3).
    """
    h = scene.discretisation.particle_size_m
    R, L = scene.domain.radius_m, scene.domain.length_m
    nx = int(round(L / h))
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
    n = x.shape[0]

    t = scene.layers.coating_thickness_m
    sub = material_rows["substrate"]
    mat_a = np.full(n, sub, dtype=np.int32)
    mat_b = np.full(n, sub, dtype=np.int32)
    frac_a = np.ones(n)
    if scene.layers.coated:
        coat = material_rows["coating"]
        # coating volume fraction of the cube [z - h/2, z + h/2] above z = -t
        frac = np.clip((x[:, 2] + 0.5 * h + t) / h, 0.0, 1.0)
        frac[np.abs(frac - 1.0) < 1e-9] = 1.0  # exact multiples of h: full layers despite round-off
        frac[frac < 1e-9] = 0.0
        mat_a[frac > 0] = coat
        frac_a = np.where(frac > 0, frac, 1.0)
    rho = frac_a * densities[mat_a] + (1.0 - frac_a) * densities[mat_b]
    vol0 = np.full(n, h**3)
    mass = rho * scene.discretisation.mass_scaling * vol0
    return Particles(
        x=x, v=np.zeros((n, 3)), C=np.zeros((n, 3, 3)), stress=np.zeros((n, 6)), J=np.ones(n), vol0=vol0,
        mass=mass, eps_p=np.zeros(n), temperature=np.full(n, scene.outputs.initial_temperature_K),
        mat_a=mat_a, mat_b=mat_b, frac_a=frac_a, near=np.zeros(n, dtype=np.int8), z0=x[:, 2].copy(),
    )
