"""Tests of plough.mpm.contact.particle_contact: the exact sphere imposed on the particles through their nodes.

The grids are made from the particles' own P2G mass (m_i = sum_p w_ip m_p), so that a particle's effective mass
through the grid is known: one particle alone has m_eff = m_p exactly. Checked: the closed form for one particle
(impulse, velocity after, force, energy split), the identities on a block with random velocities (reaction =
minus the momentum given to the nodes, the sphere's work and the energy account closing exactly, the constraint
met after enough sweeps, particles out of reach untouched), and the mirror fold (a half block against the full
block, converged).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from plough.mpm import contact as ct
from plough.mpm.bundles import ContactLaw, SphereData, grid_of, whole
from plough.mpm.grid import GHOST, MIRROR
from plough.mpm.particles import particles_of
from plough.mpm.shape import stencil, stencil_node

DX = 1e-5
SHAPE = np.array([12, 11, 13], dtype=np.int64)
ORIGIN = np.array([-4e-5, -5e-5, -6e-5])  # the node plane j = 5 is y = 0
J0 = 5
DT = 1e-6
N_NODES = int(np.prod(SHAPE))


def _lattice(lo, hi, h):
    """Particle centres of a block [lo, hi] (grid units of DX) filled with cubes of edge h (grid units)."""
    axes = [np.arange(lo[d] + 0.5 * h, hi[d], h) for d in range(3)]
    g = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    return ORIGIN + g * DX


def _grid_of_particles(x, mass, v, mirror_j0=-1):
    """Nodal mass and velocity of particles x (P2G of mass and momentum, no APIC term), with the mirror fold
    of plough.mpm.transfers.grid_update when ``mirror_j0`` >= 0 (ghosts get their partner's mirror image)."""
    m = np.zeros(N_NODES)
    mom = np.zeros((N_NODES, 3))
    ny, nz = int(SHAPE[1]), int(SHAPE[2])
    for p in range(x.shape[0]):
        st = stencil(x, p, ORIGIN, 1.0 / DX)
        for a in range(3):
            for b in range(3):
                for c in range(3):
                    node, w = stencil_node(st, a, b, c, ny, nz)
                    m[node] += w * mass[p]
                    mom[node] += w * mass[p] * v[p]
    flags = np.zeros(N_NODES, dtype=np.int8)
    if mirror_j0 >= 0:
        m3, mom3 = m.reshape(*SHAPE), mom.reshape(*SHAPE, 3)
        for j in range(mirror_j0):
            jm = 2 * mirror_j0 - j
            m3[:, jm] += m3[:, j]
            mom3[:, jm, :, 0::2] += mom3[:, j, :, 0::2]
            mom3[:, jm, :, 1] -= mom3[:, j, :, 1]
            m3[:, j] = m3[:, jm]
            mom3[:, j] = mom3[:, jm] * np.array([1.0, -1.0, 1.0])
        mom3[:, mirror_j0, :, 1] = 0.0
        j = (np.arange(N_NODES) // nz) % ny
        flags = np.where(j < mirror_j0, GHOST, np.where(j == mirror_j0, MIRROR, 0)).astype(np.int8)
    grid_v = np.zeros((N_NODES, 6))
    has = m > 0
    grid_v[has, :3] = mom[has] / m[has, None]
    return grid_of(ORIGIN, DX, SHAPE, mirror_j0=mirror_j0, flags=flags, m=m, v=grid_v)


def _advected(G, x, p):
    """sum_i w_ip v_i: the velocity particle p is advected with (the grid's ghosts already mirrored)."""
    st = stencil(x, p, ORIGIN, 1.0 / DX)
    u = np.zeros(3)
    for a in range(3):
        for b in range(3):
            for c in range(3):
                node, w = stencil_node(st, a, b, c, int(SHAPE[1]), int(SHAPE[2]))
                u += w * G.v[node, :3]
    return u


def _mirror_ghosts(G):
    v3 = G.v.reshape(*SHAPE, 6)
    for j in range(G.mirror_j0):
        v3[:, j, :, :3] = v3[:, 2 * G.mirror_j0 - j, :, :3] * np.array([1.0, -1.0, 1.0])


def _call(P, G, centre, radius, v_sphere, f=0.0, sweeps=4, step=0, last_push=None):
    n = P.x.shape[0]
    out = np.zeros(ct.N_OUT)
    law = ContactLaw(ct.INTERFACE_PROPORTIONAL, np.array([f, 0.0]), 6.0, sweeps)
    last_push = np.full(n, ct.NEVER_PUSHED) if last_push is None else last_push
    ct.particle_contact(P, G, SphereData(np.asarray(centre, float), np.asarray(v_sphere, float), radius, 3 * DX),
                        whole(n, SHAPE), law, step, DT, last_push, out)
    return out, last_push


def test_one_particle_closed_form():
    """One particle at rest, its face g below the sphere that approaches at V > g / dt along its normal: the
    impulse brings its advected velocity to exactly the allowed approach, lambda = m_p (V - g / dt), the force on
    the sphere is lambda / dt upward, the sphere's work lambda V, the kinetic energy given lambda^2 / (2 m_p)."""
    h = 0.5 * DX
    x = ORIGIN + np.array([[5.3, 4.6, 6.2]]) * DX
    mass = np.array([2.0e-9])
    P = particles_of(1, x=x, vol0=np.full(1, h**3), mass=mass, near=np.ones(1, dtype=np.int8))
    G = _grid_of_particles(x, mass, np.zeros((1, 3)))
    radius, gap, speed = 40 * DX, 0.2 * DX * 1e-3, 0.5
    centre = x[0] + np.array([0.0, 0.0, radius + 0.5 * h + gap])
    out, last_push = _call(P, G, centre, radius, [0.0, 0.0, -speed])
    lam = mass[0] * (speed - gap / DT)
    assert lam > 0.0
    u = _advected(G, x, 0)
    assert u[2] - (-speed) == pytest.approx(gap / DT, rel=1e-9)  # (u - v_s) . n = -g / dt, n = -z
    np.testing.assert_allclose(u[:2], 0.0, atol=1e-12 * speed)
    assert out[ct.OUT_FN + 2] == pytest.approx(lam / DT, rel=1e-9)
    assert out[ct.OUT_WORK] == pytest.approx(lam * speed, rel=1e-9)
    assert out[ct.OUT_IMPACT] == pytest.approx(lam * speed - lam**2 / (2 * mass[0]), rel=1e-9)
    assert out[ct.OUT_NODES] == 1 and last_push[0] == 0
    assert out[ct.OUT_AREA_XY] == pytest.approx(h * h, rel=1e-12)  # A_p = e^2 on a face normal to z


def _block_case(seed, sweeps, f=0.0):
    rng = np.random.default_rng(seed)
    h = 0.5 * DX
    x = _lattice([2, 2, 2], [9, 9, 8], 0.5)
    n = x.shape[0]
    mass = rng.uniform(0.5, 1.5, n) * 8e-10
    v = rng.normal(0.0, 0.05, (n, 3))
    stress = np.zeros((n, 6))
    stress[:, :3] = -3e8
    P = particles_of(n, x=x, vol0=np.full(n, h**3), mass=mass, near=np.ones(n, dtype=np.int8), stress=stress,
                     sigma_y0=np.full(n, 3e8))
    G = _grid_of_particles(x, mass, v)
    radius = 6 * DX
    top = ORIGIN[2] + 8 * DX
    centre = np.array([ORIGIN[0] + 5.4 * DX, ORIGIN[1] + 5.6 * DX, top + radius - 0.4 * DX])
    v_sphere = np.array([0.3, 0.0, -0.2])
    v0 = G.v[:, :3].copy()
    out, last_push = _call(P, G, centre, radius, v_sphere, f=f, sweeps=sweeps)
    return P, G, v0, out, centre, radius, v_sphere, last_push


@pytest.mark.parametrize("f", [0.0, 0.5])
def test_reaction_work_and_energy_account_on_a_block(f):
    """A sphere pressed 0.4 cell into a lattice block with random velocities: the force on the sphere is minus
    the momentum the nodes gained (/ dt), the sphere's work that momentum . v_sphere, and the work less the
    nodes' kinetic energy gain is the impact loss plus the slip dissipation, both >= 0."""
    P, G, v0, out, centre, radius, v_sphere, _ = _block_case(1, 4, f)
    dmom = (G.m[:, None] * (G.v[:, :3] - v0)).sum(axis=0)
    force = out[ct.OUT_FN:ct.OUT_FN + 3] + out[ct.OUT_FT:ct.OUT_FT + 3]
    np.testing.assert_allclose(force, -dmom / DT, rtol=1e-9, atol=1e-9 * np.abs(dmom).max() / DT)
    assert out[ct.OUT_FN + 2] > 0.0  # the material pushes the sphere up
    assert out[ct.OUT_WORK] == pytest.approx(dmom @ v_sphere, rel=1e-9)
    dke = 0.5 * (G.m * ((G.v[:, :3] ** 2).sum(axis=1) - (v0**2).sum(axis=1))).sum()
    losses = out[ct.OUT_IMPACT] + out[ct.OUT_DISSIPATION]
    assert out[ct.OUT_WORK] - dke == pytest.approx(losses, rel=1e-9)
    assert out[ct.OUT_IMPACT] > 0.0
    if f > 0.0:
        assert out[ct.OUT_DISSIPATION] > 0.0 and np.linalg.norm(out[ct.OUT_FT:ct.OUT_FT + 3]) > 0.0
    else:
        assert out[ct.OUT_DISSIPATION] == 0.0 and np.all(out[ct.OUT_FT:ct.OUT_FT + 3] == 0.0)


def test_constraint_met_after_enough_sweeps_and_far_particles_untouched():
    """With enough sweeps (2000; 4 in a run) no particle's face ends the step inside the sphere (to first order
    in dt: (u - v_s) . n >= -max(g, 0) / dt, to 1e-5 of the sphere's speed), of the particles the sphere holds
    back (that would have crossed it before any impulse) at least 20 meet it with equality (to 1e-4; the others
    are stopped by their neighbours' impulses), and the nodes no particle within a cell of the sphere reaches
    keep their velocity."""
    P, G, v0, out, centre, radius, v_sphere, last_push = _block_case(2, 2000)
    x = P.x
    q = x - centre
    dist = np.linalg.norm(q, axis=1)
    gap = dist - radius - 0.5 * (P.vol0 * P.J) ** (1 / 3)
    tol = 1e-5 * np.linalg.norm(v_sphere)
    pushed = last_push == 0
    at_equality = 0
    for p in range(x.shape[0]):
        if gap[p] >= DX:
            continue
        vn = (_advected(G, x, p) - v_sphere) @ (q[p] / dist[p])
        allowed = -max(gap[p], 0.0) / DT  # a particle found inside stops approaching
        assert vn >= allowed - tol
        if pushed[p] and vn == pytest.approx(allowed, abs=10 * tol):  # complementarity converges more slowly
            at_equality += 1
    assert at_equality >= 20
    reached = np.zeros(N_NODES, dtype=bool)
    for p in np.flatnonzero(gap < DX):
        st = stencil(x, p, ORIGIN, 1.0 / DX)
        for a in range(3):
            for b in range(3):
                for c in range(3):
                    reached[stencil_node(st, a, b, c, int(SHAPE[1]), int(SHAPE[2]))[0]] = True
    np.testing.assert_array_equal(G.v[~reached, :3], v0[~reached])
    assert np.abs(G.v[reached, :3] - v0[reached]).max() > 0.01


def test_mirror_fold_half_block_equals_full_block():
    """A block symmetric about y = 0 pressed by a sphere centred on the plane, against its half y > 0 with the
    mirror fold, both converged (2000 sweeps; at 4, as in a run, the forces agree within 1.1% and the
    velocities within 6% of the largest): on the nodes j >= j0 the velocities agree, and the half carries half
    the full block's normal force (x and z)."""
    h = 0.5
    x_full = _lattice([2, 2, 2], [9, 8, 8], h)
    x_half = _lattice([2, 5, 2], [9, 8, 8], h)
    results = []
    for x, j0 in ((x_full, -1), (x_half, J0)):
        n = x.shape[0]
        mass = np.full(n, 8e-10)
        P = particles_of(n, x=x, vol0=np.full(n, (h * DX) ** 3), mass=mass, near=np.ones(n, dtype=np.int8))
        G = _grid_of_particles(x, mass, np.zeros((n, 3)), mirror_j0=j0)
        radius = 6 * DX
        centre = np.array([ORIGIN[0] + 5.4 * DX, 0.0, ORIGIN[2] + 8 * DX + radius - 0.3 * DX])
        out, _ = _call(P, G, centre, radius, [0.0, 0.0, -0.2], sweeps=2000)
        if j0 >= 0:
            _mirror_ghosts(G)
        results.append((G.v[:, :3].reshape(*SHAPE, 3), out))
    (v_full, out_full), (v_half, out_half) = results
    scale = np.abs(v_full).max()
    assert scale > 0.01
    np.testing.assert_allclose(v_half, v_full, rtol=0, atol=1e-4 * scale)  # the ghosts too, once mirrored
    for d in (0, 2):
        assert 2 * out_half[ct.OUT_FN + d] == pytest.approx(out_full[ct.OUT_FN + d], rel=1e-4,
                                                           abs=1e-4 * abs(out_full[ct.OUT_FN + 2]))
    assert math.isclose(out_full[ct.OUT_FN + 1], 0.0, abs_tol=1e-5 * out_full[ct.OUT_FN + 2])


@pytest.mark.parametrize("approach", [0.0, 0.2])
def test_interface_shear_is_tau_times_the_touching_face(approach):
    """A lattice block whose top face touches a flat sphere (R = 1 m, its lowest point 10 nm into the face),
    the block sliding fast under it (traction-limited: m |v_t| >> tau A dt), the sphere at rest or pressing
    down: the shear force is tau times the whole top face (kappa = sigma_y0 / sqrt 3 at f = 1), whether or not
    the particles are pushed in this step (at rest none is; pressing, a few impulses stop their neighbours
    too), and the second layer (a particle size below) carries none."""
    h = 0.5 * DX
    lo, hi = [2, 2, 2], [9, 9, 8]
    x = _lattice(lo, hi, 0.5)
    n = x.shape[0]
    mass = np.full(n, 8e-10)
    sigma_y = 3e8
    P = particles_of(n, x=x, vol0=np.full(n, h**3), mass=mass, near=np.ones(n, dtype=np.int8),
                     sigma_y0=np.full(n, sigma_y))
    G = _grid_of_particles(x, mass, np.tile([50.0, 20.0, 0.0], (n, 1)))
    radius = 1.0
    top = ORIGIN[2] + hi[2] * DX
    centre = np.array([ORIGIN[0] + 5.5 * DX, ORIGIN[1] + 5.5 * DX, top + radius - 1e-8])
    out, _ = _call(P, G, centre, radius, [0.0, 0.0, -approach], f=1.0)
    face = (hi[0] - lo[0]) * (hi[1] - lo[1]) * DX * DX
    tau = sigma_y / math.sqrt(3.0)
    ft = out[ct.OUT_FT:ct.OUT_FT + 3]
    assert np.hypot(ft[0], ft[1]) == pytest.approx(tau * face, rel=1e-3)
    assert ft[0] / ft[1] == pytest.approx(50.0 / 20.0, rel=1e-3)  # against the slip, on the sphere along it
    assert out[ct.OUT_NODES] == (hi[0] - lo[0]) * (hi[1] - lo[1]) * 4  # the top layer's particles only
    assert out[ct.OUT_AREA_XY] == pytest.approx(face, rel=1e-3)
