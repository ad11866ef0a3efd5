"""Tests of plough.mpm.transfers: APIC/MLS P2G, the grid update and G2P (model.md section 2).

Expected values are conservation laws and exact reproductions of the quadratic B-spline APIC
scheme, computed here from the particle data alone:

- P2G conserves mass, linear momentum and (APIC) angular momentum
  sum_i x_i x m_i v_i = sum_p [x_p x m_p v_p + m_p dx^2/4 eps : C_p^T];
- an affine velocity field v = v0 + A x with C = A survives P2G -> G2P exactly;
- the MLS stress term of a uniform stress gives no force on interior nodes, and the force
  transmitted across a plane between node layers equals -sigma . n x area (exact for a regular
  particle lattice with two particles per cell);
- the chunked scatter gives the same grid for any number of chunks.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from plough.materials import DX56, ZINC_BULK, ZINC_COATING, rigid_plastic
from plough.mpm import transfers as tr
from plough.mpm.bundles import MaterialData, SphereData, grid_of, whole
from plough.mpm.constitutive import I_G, I_K, pack_materials, rest_flow_stresses, update_stress
from plough.mpm.grid import FIXED, FREE, GHOST, MIRROR, Grid, boundary_flags, make_grid, mirror_plane_index
from plough.mpm.particles import particles_of

DX = 1e-5
SHAPE = np.array([17, 16, 18], dtype=np.int64)  # non-cubic: catches index mix-ups
ORIGIN = np.array([-3.0e-5, 2.0e-5, -7.0e-5])
RHO = 7850.0
STIFF = pack_materials([rigid_plastic("stiff", 1e15, coating=False)])  # never yields here


def moving(x, v, C, stress, vol0, J, mass):
    """The particle bundle of what P2G reads (the rest: defaults)."""
    return particles_of(x.shape[0], x=x, v=v, C=C, stress=stress, vol0=vol0, J=J, mass=mass)


def node_positions(origin=ORIGIN, dx=DX, shape=SHAPE) -> np.ndarray:
    return Grid(origin=np.asarray(origin), dx=dx, shape=tuple(int(s) for s in shape)).node_positions()


def random_particles(n=300, seed=0, lo_cells=3.0, hi_cells=None):
    """n particles uniformly inside the grid, at least lo_cells from every face."""
    rng = np.random.default_rng(seed)
    hi = (SHAPE - 1 - lo_cells) if hi_cells is None else np.asarray(hi_cells)
    x = ORIGIN + DX * rng.uniform(lo_cells, hi, size=(n, 3))
    vol0 = rng.uniform(0.5, 1.5, n) * (0.5 * DX) ** 3
    J = rng.uniform(0.9, 1.1, n)
    mass = RHO * vol0 * rng.uniform(0.8, 1.2, n)
    v = rng.normal(0.0, 0.1, (n, 3))
    return rng, x, v, vol0, J, mass


def p2g_update(x, v, C, stress, vol0, J, mass, dt, n_chunks=1, flags=None):
    G = grid_of(ORIGIN, DX, SHAPE, n_chunks)
    if flags is not None:
        G = G._replace(flags=flags)
    tr.p2g(moving(x, v, C, stress, vol0, J, mass), G, dt, whole(x.shape[0], SHAPE))
    tr.grid_update(G, whole(x.shape[0], SHAPE))
    return G.buf, G.m, G.v[:, :3].copy()  # the new velocity; columns 3:6 are tested on their own


def random_sym_stress(rng, n, scale=1e8):
    return rng.normal(0.0, scale, (n, 6))


# ----------------------------------------------------------------------------- conservation
@pytest.mark.parametrize("with_C", [False, True])
def test_p2g_conserves_mass_and_linear_momentum(with_C):
    rng, x, v, vol0, J, mass = random_particles(seed=1)
    n = x.shape[0]
    C = rng.normal(0.0, 1e4, (n, 3, 3)) if with_C else np.zeros((n, 3, 3))
    stress = np.zeros((n, 6))
    buf, grid_m, grid_v = p2g_update(x, v, C, stress, vol0, J, mass, dt=1e-8)
    assert grid_m.sum() == pytest.approx(mass.sum(), rel=1e-13)
    assert buf[0, :, 0].sum() == pytest.approx(mass.sum(), rel=1e-13)
    p_particles = (mass[:, None] * v).sum(0)
    p_grid = (grid_m[:, None] * grid_v).sum(0)
    scale = (mass[:, None] * np.abs(v)).sum()
    np.testing.assert_allclose(p_grid, p_particles, rtol=0, atol=1e-12 * scale)
    # the grid really carries the APIC term: nodal velocities differ when C is set
    if with_C:
        _, _, grid_v0 = p2g_update(x, v, np.zeros_like(C), stress, vol0, J, mass, dt=1e-8)
        assert np.abs(grid_v - grid_v0).max() > 1e-3


def test_p2g_stress_adds_no_net_momentum_or_angular_momentum():
    """Any (symmetric) particle stress: internal forces sum to zero and exert no net torque."""
    rng, x, v, vol0, J, mass = random_particles(seed=2)
    n = x.shape[0]
    C = np.zeros((n, 3, 3))
    stress = random_sym_stress(rng, n)
    dt = 1e-7
    _, grid_m, grid_v = p2g_update(x, np.zeros_like(v), C, stress, vol0, J, mass, dt)
    mom = grid_m[:, None] * grid_v
    # scale of individual nodal impulses, to judge round-off
    scale = np.abs(mom).max() * grid_m.size
    assert scale > 0
    np.testing.assert_allclose(mom.sum(0), 0.0, atol=1e-13 * scale)
    L = np.cross(node_positions(), mom).sum(0)
    np.testing.assert_allclose(L, 0.0, atol=1e-13 * scale * np.abs(node_positions()).max())


def test_apic_p2g_conserves_angular_momentum():
    """sum_i x_i x m_i v_i = sum_p x_p x m_p v_p + m_p dx^2/4 (C_zy - C_yz, C_xz - C_zx, C_yx - C_xy)."""
    rng, x, v, vol0, J, mass = random_particles(seed=3)
    n = x.shape[0]
    C = rng.normal(0.0, 1e4, (n, 3, 3))
    stress = random_sym_stress(rng, n)  # symmetric stress: no torque
    _, grid_m, grid_v = p2g_update(x, v, C, stress, vol0, J, mass, dt=1e-8)
    L_grid = np.cross(node_positions(), grid_m[:, None] * grid_v).sum(0)
    spin = np.stack([C[:, 2, 1] - C[:, 1, 2], C[:, 0, 2] - C[:, 2, 0], C[:, 1, 0] - C[:, 0, 1]], axis=1)
    L_part = (np.cross(x, mass[:, None] * v) + (mass * DX * DX / 4.0)[:, None] * spin).sum(0)
    scale = (mass * (np.linalg.norm(x, axis=1) * np.linalg.norm(v, axis=1)
                     + DX * DX * np.abs(spin).sum(1))).sum()
    np.testing.assert_allclose(L_grid, L_part, rtol=0, atol=1e-11 * scale)
    # the spin term matters: without it the balance fails
    assert np.abs(L_grid - np.cross(x, mass[:, None] * v).sum(0)).max() > 1e-3 * np.abs(L_part).max()


# ----------------------------------------------------------------------------- affine field
def run_g2p(grid_v, x, v, C, stress, J, vol0, mass, dt, n_chunks=1, sphere_c=None, sphere_r=1e-6,
            near_dist=3 * DX, grid_lo=None, grid_hi=None, table=STIFF, flip=0.0, project=0, block=tr.G2P_BLOCK,
            eps_p=None):
    n = x.shape[0]
    if grid_v.shape[1] == 3:  # no FLIP increment: the old velocity equals the new one
        grid_v = np.hstack([grid_v, grid_v])
    v_grid = np.zeros((n, 3))
    eps_p = np.zeros(n) if eps_p is None else eps_p
    temperature = np.full(n, 298.0)
    mat = np.zeros(n, dtype=np.int32)
    frac = np.ones(n)
    near = np.zeros(n, dtype=np.int8)
    acc = np.zeros((n_chunks, tr.N_ACC))
    if sphere_c is None:
        sphere_c = np.array([1.0, 1.0, 1.0])  # far away
    lo = ORIGIN + DX if grid_lo is None else grid_lo
    hi = ORIGIN + DX * (SHAPE - 2) if grid_hi is None else grid_hi
    sigma_y0 = np.zeros(n)
    rest_flow_stresses(eps_p, temperature, mat, mat, frac, table, sigma_y0)
    P = particles_of(n, x=x, v=v, C=C, stress=stress, J=J, vol0=vol0, mass=mass, eps_p=eps_p,
                     temperature=temperature, sigma_y0=sigma_y0, mat_a=mat, mat_b=mat, frac_a=frac, near=near)
    G, Z = grid_of(ORIGIN, DX, SHAPE, n_chunks, v=grid_v), whole(n, SHAPE, lo, hi)
    tr.g2p_kinematics(P, G, v_grid, flip, project, Z)
    if project:
        tr.grid_dilatation(G, Z)
    tr.g2p_update(P, G, MaterialData(table, 1.0, 0.9), SphereData(sphere_c, np.zeros(3), sphere_r, near_dist), Z, dt,
                  project, v_grid, tr.allocate_velocity_gradient_scratch(n_chunks), acc, block)
    return acc, near, eps_p


def test_affine_velocity_field_is_reproduced_exactly():
    rng, x, _, vol0, _, mass = random_particles(seed=4)
    n = x.shape[0]
    v0 = np.array([0.1, -0.05, 0.02])
    A = rng.normal(0.0, 1e3, (3, 3))  # not symmetric: checks C = dv_i/dx_j, not its transpose
    v = v0 + x @ A.T
    C = np.repeat(A[None], n, axis=0)
    J = np.ones(n)
    stress = np.zeros((n, 6))
    dt = 1e-9
    _, grid_m, grid_v = p2g_update(x, v, C, stress, vol0, J, mass, dt)
    nodes = node_positions()
    has = grid_m > 0
    np.testing.assert_allclose(grid_v[has], v0 + nodes[has] @ A.T, rtol=0, atol=1e-12)

    x_old = x.copy()
    v_new = np.zeros_like(v)
    C_new = np.zeros_like(C)
    acc, _, eps_p = run_g2p(grid_v, x, v_new, C_new, stress, J, vol0, mass, dt)
    v_exact = v0 + x_old @ A.T
    np.testing.assert_allclose(v_new, v_exact, rtol=0, atol=1e-10 * np.abs(v_exact).max())
    np.testing.assert_allclose(C_new, C, rtol=0, atol=1e-10 * np.abs(A).max())
    np.testing.assert_allclose(x, x_old + dt * v_new, rtol=0, atol=1e-20)
    np.testing.assert_allclose(J, np.linalg.det(np.eye(3) + dt * A), rtol=1e-13)
    # elastic stress from zero: 2 G dt dev(sym A) + K (J - 1) I, Voigt xx yy zz yz xz xy
    K, G = STIFF[0, I_K], STIFF[0, I_G]
    D = 0.5 * (A + A.T)
    dev = D - np.trace(D) / 3 * np.eye(3)
    sig = 2 * G * dt * dev + K * (J[0] - 1.0) * np.eye(3)
    expected = np.array([sig[0, 0], sig[1, 1], sig[2, 2], sig[1, 2], sig[0, 2], sig[0, 1]])
    np.testing.assert_allclose(stress, np.tile(expected, (n, 1)), rtol=1e-8, atol=1e-8 * np.abs(sig).max())
    assert np.all(eps_p == 0.0)
    assert acc[0, tr.ACC_BAD] == tr.BAD_NONE
    assert acc[0, tr.ACC_KINETIC] == pytest.approx(0.5 * (mass * (v_exact**2).sum(1)).sum(), rel=1e-10)
    assert acc[0, tr.ACC_PLASTIC_WORK] == 0.0


def test_g2p_near_flags_and_penetration():
    _, x, _, vol0, J, mass = random_particles(seed=5)
    n = x.shape[0]
    grid_v = np.zeros((int(np.prod(SHAPE)), 3))
    centre = x.mean(0) + np.array([0.0, 0.0, 4 * DX])
    r = 2.5 * DX
    acc, near, _ = run_g2p(grid_v, x.copy(), np.zeros((n, 3)), np.zeros((n, 3, 3)), np.zeros((n, 6)), J, vol0, mass,
                           1e-9, n_chunks=2, sphere_c=centre, sphere_r=r, near_dist=DX)
    dist = np.linalg.norm(x - centre, axis=1)
    np.testing.assert_array_equal(near, (dist < r + DX).astype(np.int8))
    assert 0 < near.sum() < n
    assert acc[:, tr.ACC_PENETRATION].max() == pytest.approx((r - dist).max(), rel=1e-12)


@pytest.mark.parametrize("case", ["left_grid", "J", "nonfinite"])
def test_g2p_reports_instabilities(case):
    _, x, v, vol0, J, mass = random_particles(seed=6)
    n = x.shape[0]
    n_nodes = int(np.prod(SHAPE))
    grid_v = np.zeros((n_nodes, 3))
    lo, hi = None, None
    dt = 1e-9
    if case == "left_grid":
        hi = ORIGIN + DX * (SHAPE - 2)
        hi[0] = np.sort(x[:, 0])[-5]  # five particles lie beyond the allowed box
        expected = tr.BAD_LEFT_GRID
        offenders = np.flatnonzero(x[:, 0] > hi[0])
    elif case == "J":
        grid_v[:] = 0.0
        A = -2.0e3 * np.eye(3)  # 1 + dt A = -1 with dt = 1e-3: volume inverts
        grid_v = node_positions() @ A.T
        dt = 1e-3
        lo, hi = ORIGIN - 1.0, ORIGIN + 1.0  # the advected particles may go anywhere
        expected = tr.BAD_J
        offenders = np.arange(n)
    else:
        node = ((6 * SHAPE[1] + 6) * SHAPE[2]) + 7
        grid_v[node, 1] = np.nan
        expected = tr.BAD_NONFINITE
        offenders = None
    block = 16
    acc, _, _ = run_g2p(grid_v, x, np.zeros((n, 3)), np.zeros((n, 3, 3)), np.zeros((n, 6)), J, vol0, mass, dt,
                        n_chunks=3, grid_lo=lo, grid_hi=hi, block=block)
    codes = acc[:, tr.ACC_BAD]
    assert codes.max() == expected
    c = int(np.argmax(codes))
    p = int(acc[c, tr.ACC_BAD_INDEX])
    assert (p // block) % 3 == c  # the index names a particle of that chunk's blocks
    if offenders is not None:
        assert p in offenders
    else:
        assert not np.isfinite(x[p]).all()
    # chunks without trouble report none
    for cc in range(3):
        if codes[cc] == tr.BAD_NONE:
            assert acc[cc, tr.ACC_BAD_INDEX] == -1


# ----------------------------------------------------------------------------- stress term
def lattice_block(n_side=16, first_cell=4, ppc=2):
    """A regular lattice, ppc particles per cell and direction, filling n_side / ppc cells per side."""
    h = DX / ppc
    k = np.arange(n_side)
    idx = np.stack(np.meshgrid(k, k, k, indexing="ij"), -1).reshape(-1, 3)
    x = ORIGIN + first_cell * DX + (idx + 0.5) * h
    n = x.shape[0]
    vol0 = np.full(n, h**3)
    return x, vol0, RHO * vol0, h


@pytest.mark.parametrize("J_value", [1.0, 1.3])
def test_uniform_stress_interior_nodes_free_and_traction_across_planes(J_value):
    x, vol0, mass, h = lattice_block()
    n = x.shape[0]
    sig = np.array([[3.0e8, 0.7e8, -0.4e8],
                    [0.7e8, -1.0e8, 1.1e8],
                    [-0.4e8, 1.1e8, 2.0e8]])
    voigt = np.array([sig[0, 0], sig[1, 1], sig[2, 2], sig[1, 2], sig[0, 2], sig[0, 1]])
    stress = np.tile(voigt, (n, 1))
    J = np.full(n, J_value)
    dt = 1e-7
    _, grid_m, grid_v = p2g_update(x, np.zeros((n, 3)), np.zeros((n, 3, 3)), stress, vol0, J, mass, dt)
    force = grid_m[:, None] * grid_v / dt
    g = np.rint((node_positions() - ORIGIN) / DX).astype(int)
    # the block spans grid units [4, 12]; nodes in [6, 10]^3 see a full, symmetric particle stencil
    interior = np.all((g >= 6) & (g <= 10), axis=1)
    fmax = np.abs(force).max()
    assert fmax > 0
    np.testing.assert_allclose(force[interior], 0.0, atol=1e-10 * fmax)
    np.testing.assert_allclose(force.sum(0), 0.0, atol=1e-12 * fmax * force.shape[0])
    # across the mid-plane of the block (between node layers 8 and 9) the block on the + side
    # is pulled by -sigma . n times the cross-section (times J: the particle volume is vol0 J)
    area = (16 * h) ** 2
    for d in range(3):
        plus = g[:, d] >= 9
        np.testing.assert_allclose(force[plus].sum(0), -sig[:, d] * area * J_value, rtol=1e-10,
                                   atol=1e-10 * np.abs(sig).max() * area)


# ----------------------------------------------------------------------------- chunks
def test_chunked_scatter_gives_same_grid():
    rng, x, v, vol0, J, mass = random_particles(n=301, seed=7)
    n = x.shape[0]
    C = rng.normal(0.0, 1e4, (n, 3, 3))
    stress = random_sym_stress(rng, n)
    results = {}
    for n_chunks in (1, 2, 3):
        buf, grid_m, grid_v = p2g_update(x, v, C, stress, vol0, J, mass, 1e-8, n_chunks=n_chunks)
        results[n_chunks] = (grid_m, grid_v)
        # chunk c holds exactly the scatter of its own contiguous particle slice
        for c in range(n_chunks):
            sl = slice(c * n // n_chunks, (c + 1) * n // n_chunks)
            one = grid_of(ORIGIN, DX, SHAPE)
            tr.p2g(moving(x[sl], v[sl], C[sl], stress[sl], vol0[sl], J[sl], mass[sl]), one, 1e-8,
                   whole(sl.stop - sl.start, SHAPE))
            np.testing.assert_array_equal(buf[c], one.buf[0])
    m1, v1 = results[1]
    vscale = np.abs(v1).max()
    for k in (2, 3):
        mk, vk = results[k]
        np.testing.assert_allclose(mk, m1, rtol=1e-13, atol=1e-13 * m1.max())
        np.testing.assert_allclose(vk, v1, rtol=0, atol=1e-12 * vscale)


def test_g2p_update_blocks_cover_every_particle_once():
    """The round-robin blocks give every chunk count and block size the slab split's particle state."""
    rng, x, v, vol0, J, mass = random_particles(n=301, seed=11)
    n = x.shape[0]
    n_nodes = node_positions().shape[0]
    grid_v = rng.normal(0.0, 2e-2, (n_nodes, 6)) * rng.uniform(0.0, 3.0, (n_nodes, 1))
    soft = pack_materials([rigid_plastic("soft", 3.0e7, coating=False)])  # some particles flow, some do not
    stress0 = random_sym_stress(rng, n) * 1e-2
    # the kinematics and the projected dilatation once, with one chunk: only g2p_update's split varies
    C, v_grid = np.zeros((n, 3, 3)), np.zeros((n, 3))
    G = grid_of(ORIGIN, DX, SHAPE, v=grid_v)
    tr.g2p_kinematics(particles_of(n, x=x, v=v.copy(), C=C, mass=mass), G, v_grid, 1.0, 1, whole(n, SHAPE))
    tr.grid_dilatation(G, whole(n, SHAPE))
    mat, frac = np.zeros(n, dtype=np.int32), np.ones(n)
    lo, hi = ORIGIN + DX, ORIGIN + DX * (SHAPE - 2)

    def run(n_chunks: int, block: int, p_lo: int = 0, p_hi: int = n):
        xs, ss, Js = x.copy(), stress0.copy(), J.copy()
        eps_p, temperature, sigma_y0, deps_last = np.zeros(n), np.full(n, 298.0), np.zeros(n), np.zeros(n)
        rest_flow_stresses(eps_p, temperature, mat, mat, frac, soft, sigma_y0)
        near, acc = np.zeros(n, dtype=np.int8), np.zeros((n_chunks, tr.N_ACC))
        P = particles_of(n, x=xs, v=v, C=C, stress=ss, J=Js, vol0=vol0, mass=mass, eps_p=eps_p,
                         temperature=temperature, sigma_y0=sigma_y0, deps_last=deps_last, mat_a=mat, mat_b=mat,
                         frac_a=frac, near=near)
        Z = whole(n, SHAPE, lo, hi)._replace(p_lo=p_lo, p_hi=p_hi)
        tr.g2p_update(P, G, MaterialData(soft, 1.0, 0.9), SphereData(x.mean(0), np.zeros(3), 4 * DX, DX), Z, 1e-8, 1,
                      v_grid, tr.allocate_velocity_gradient_scratch(n_chunks), acc, block)
        tr.elastic_energies(P, soft, Z, acc, block)  # the energy the recorder takes, split as g2p_update splits
        return acc, (xs, ss, Js, near, eps_p, temperature, sigma_y0, deps_last)

    acc_ref, ref = run(1, n)
    flowed = int((ref[4] > 0.0).sum())
    assert 0 < flowed < n and 0 < ref[3].sum() < n
    # the elastic energy is s:s / (4 G) + p^2 / (2 K) of the updated stress times the current volume
    sig, K, G_shear = ref[1], soft[0, I_K], soft[0, I_G]
    pressure = sig[:, :3].mean(1)
    dev = sig[:, :3] - pressure[:, None]
    ss = (dev**2).sum(1) + 2.0 * (sig[:, 3:] ** 2).sum(1)
    assert acc_ref[0, tr.ACC_ELASTIC] == pytest.approx(
        ((ss / (4.0 * G_shear) + pressure**2 / (2.0 * K)) * vol0 * ref[2]).sum(), rel=1e-12)
    for n_chunks, block in [(1, tr.G2P_BLOCK), (2, 1), (3, 7), (3, 8), (2, (n + 1) // 2), (3, n), (4, 64)]:
        acc, got = run(n_chunks, block)
        for a, b in zip(got, ref, strict=True):
            np.testing.assert_array_equal(a, b)  # a particle skipped or updated twice would differ
        for k in (tr.ACC_PLASTIC_WORK, tr.ACC_KINETIC, tr.ACC_ELASTIC, tr.ACC_HEAT):
            assert acc[:, k].sum() == pytest.approx(acc_ref[0, k], rel=1e-12)
        assert acc[:, tr.ACC_PENETRATION].max() == acc_ref[0, tr.ACC_PENETRATION]
    # an active range inside the arrays (the active zone): the same particles updated, the others untouched
    first, last = 37, 280
    acc_ref, ref = run(1, n, first, last)
    for a, b0 in zip(ref, (x, stress0, J), strict=False):
        np.testing.assert_array_equal(a[:first], b0[:first])
        np.testing.assert_array_equal(a[last:], b0[last:])
    assert np.all(ref[4][:first] == 0.0) and np.all(ref[4][last:] == 0.0) and ref[4][first:last].max() > 0.0
    for n_chunks, block in [(2, 1), (3, 7), (2, 16), (4, 64), (2, last - first)]:
        acc, got = run(n_chunks, block, first, last)
        for a, b in zip(got, ref, strict=True):
            np.testing.assert_array_equal(a, b)


@pytest.mark.parametrize("n_chunks", [1, 2])
def test_g2p_update_stores_what_the_stress_update_of_each_particle_stores(n_chunks):
    """g2p_update's inlined stress update against ``update_stress`` called particle by particle, to the bit.

    Every field the stress update writes (stress, J, eps_p, temperature, sigma_y0, deps_last) for the four flow
    laws' kin (DX56, bulk zinc, the coating, mixed particles), most particles flowing. Fails on a build whose stores
    inside the prange body are dropped (numba drops stores into an array taken from a named tuple there)."""
    rng, x, v, vol0, J0, mass = random_particles(n=240, seed=21)
    n = x.shape[0]
    table = pack_materials([DX56, ZINC_BULK, ZINC_COATING])
    mat_a, mat_b = rng.integers(0, 3, n).astype(np.int32), rng.integers(0, 3, n).astype(np.int32)
    frac_a = rng.choice([0.0, 1.0, 0.3, 0.8], n)
    C = rng.normal(0.0, 2e4, (n, 3, 3))
    dt = 1e-7
    M = MaterialData(table, 50.0, 0.9)

    def state():
        eps_p = rng.uniform(0.0, 0.3, n)
        temperature = rng.uniform(298.0, 400.0, n)
        sigma_y0 = np.zeros(n)
        rest_flow_stresses(eps_p, temperature, mat_a, mat_b, frac_a, table, sigma_y0)
        return particles_of(n, x=x.copy(), v=v, C=C, stress=random_sym_stress(rng, n), J=J0.copy(), vol0=vol0,
                            mass=mass, eps_p=eps_p, temperature=temperature, sigma_y0=sigma_y0,
                            deps_last=rng.uniform(0.0, 1e-3, n), mat_a=mat_a, mat_b=mat_b, frac_a=frac_a)

    P = state()
    fields = ("stress", "J", "eps_p", "temperature", "sigma_y0", "deps_last")
    P_ref = P._replace(**{f: getattr(P, f).copy() for f in fields})
    eps0 = P.eps_p.copy()
    G, Z = grid_of(ORIGIN, DX, SHAPE, n_chunks), whole(n, SHAPE)
    acc = np.zeros((n_chunks, tr.N_ACC))
    tr.g2p_update(P, G, M, SphereData(np.ones(3), np.zeros(3), DX, DX), Z, dt, 0, np.zeros((n, 3)),
                  tr.allocate_velocity_gradient_scratch(n_chunks), acc, 5)
    for p in range(n):  # project 0: L = C; J first, as g2p_update does
        P_ref.J[p] = P_ref.J[p] * tr._det_i_plus(dt, C[p])
        update_stress(P_ref, p, C[p], dt, M)
    flowed = P_ref.eps_p > eps0
    assert n // 2 < flowed.sum() < n  # most flow, some stay elastic
    assert len(set(zip(mat_a[flowed], mat_b[flowed], frac_a[flowed], strict=True))) > 9  # every law, mixed ones
    for f in fields:
        np.testing.assert_array_equal(getattr(P, f), getattr(P_ref, f), err_msg=f)


def test_p2g_zeroes_stale_buffer():
    """A buffer reused from a previous step is overwritten, not accumulated."""
    _, x, v, vol0, J, mass = random_particles(seed=8)
    n = x.shape[0]
    C, stress = np.zeros((n, 3, 3)), np.zeros((n, 6))
    G = grid_of(ORIGIN, DX, SHAPE, 2)
    G.buf[:] = 123.0
    tr.p2g(moving(x, v, C, stress, vol0, J, mass), G, 1e-8, whole(n, SHAPE))
    assert G.buf[:, :, 0].sum() == pytest.approx(mass.sum(), rel=1e-13)


# ----------------------------------------------------------------------------- grid update
def test_grid_update_boundary_conditions():
    rng = np.random.default_rng(9)
    n_nodes = 500
    buf = np.zeros((3, n_nodes, 7))
    buf[:, :, 0] = rng.uniform(0.0, 1.0, (3, n_nodes))
    buf[:, :, 1:] = rng.normal(0.0, 1.0, (3, n_nodes, 6))
    buf[:, :20, 0] = 0.0  # empty nodes
    flags = rng.choice(np.array([FREE, FIXED, MIRROR], dtype=np.int8), n_nodes)
    grid_m = np.full(n_nodes, -1.0)
    grid_v = np.full((n_nodes, 6), 99.0)
    tr.grid_update(grid_of(ORIGIN, DX, [1, 1, n_nodes], buf=buf, flags=flags, m=grid_m, v=grid_v),
                   whole(0, [1, 1, n_nodes]))
    m = buf[:, :, 0].sum(0)
    mom = buf[:, :, 1:4].sum(0)
    impulse = buf[:, :, 4:7].sum(0)
    np.testing.assert_allclose(grid_m, m, rtol=1e-15)
    empty = m <= 0
    # the velocity before the internal force (for the FLIP increment) on every node with mass
    np.testing.assert_allclose(grid_v[~empty, 3:], (mom - impulse)[~empty] / m[~empty, None], rtol=1e-12)
    free = (flags == FREE) & ~empty
    fixed = flags == FIXED
    mirror = (flags == MIRROR) & ~empty
    assert free.any() and fixed.any() and mirror.any() and empty.any()
    np.testing.assert_allclose(grid_v[free, :3], mom[free] / m[free, None], rtol=1e-14)
    np.testing.assert_array_equal(grid_v[fixed, :3], 0.0)
    np.testing.assert_array_equal(grid_v[empty], 0.0)
    np.testing.assert_array_equal(grid_v[mirror, 1], 0.0)
    np.testing.assert_allclose(grid_v[mirror][:, [0, 2]], mom[mirror][:, [0, 2]] / m[mirror, None], rtol=1e-14)


def test_make_grid_covers_block_with_padding():
    L, R, dx, head = 400e-6, 80e-6, 20e-6, 30e-6
    for symmetric in (True, False):
        g = make_grid(L, R, symmetric, dx, head)
        lo = np.array([0.0, 0.0 if symmetric else -R, -R])
        hi = np.array([L, R, head])
        assert np.all(g.origin <= lo - 3 * dx + 1e-12 * dx)
        assert np.all(g.upper >= hi + 3 * dx - 1e-12 * dx)
        assert g.node_positions().shape == (g.n_nodes, 3)
        assert math.isclose(g.node_positions()[1, 2] - g.node_positions()[0, 2], dx)


MIRROR_DX = 1e-5


def half_and_full_grids() -> tuple[Grid, Grid]:
    """The same block meshed as a half domain (mirror plane y = 0) and as a full domain."""
    return make_grid(2e-4, 8e-5, True, MIRROR_DX, 3e-5), make_grid(2e-4, 8e-5, False, MIRROR_DX, 3e-5)


def particles_near_the_mirror(rng, n: int) -> np.ndarray:
    return np.column_stack([rng.uniform(3e-5, 1.7e-4, n), rng.uniform(0.0, 5e-5, n), rng.uniform(-6e-5, 0.0, n)])


def matching_nodes(half_grid: Grid, full_grid: Grid):
    """Pairs (i, j): node i of the half-domain grid sits where node j of the full-domain grid does."""
    index_f = {tuple(np.round(q / MIRROR_DX).astype(int)): j for j, q in enumerate(full_grid.node_positions())}
    for i, q in enumerate(half_grid.node_positions()):
        j = index_f.get(tuple(np.round(q / MIRROR_DX).astype(int)))
        if j is not None:
            yield i, j


def test_mirror_fold_reproduces_the_full_domain():
    """Half domain with the mirror fold == full domain with the mirrored particles, node by node."""
    rng = np.random.default_rng(7)
    dx = MIRROR_DX
    half_grid, full_grid = half_and_full_grids()
    n = 400
    x = particles_near_the_mirror(rng, n)
    v = rng.normal(0.0, 0.1, (n, 3))
    C = rng.normal(0.0, 1e3, (n, 3, 3))
    stress = rng.normal(0.0, 1e8, (n, 6))
    vol0, J, mass = np.full(n, (0.5 * dx) ** 3), np.ones(n), np.full(n, RHO * (0.5 * dx) ** 3)
    mirror = np.diag([1.0, -1.0, 1.0])
    x_m, v_m = x @ mirror, v @ mirror
    C_m = mirror @ C @ mirror  # velocity gradient of the mirrored field
    stress_m = stress * np.array([1, 1, 1, -1, 1, -1])  # yz and xy change sign

    def grid_v(grid, xs, vs, Cs, ss, symmetric):
        flags = boundary_flags(grid, 1.0, symmetric)  # radius 1 m: nothing fixed
        G = grid_of(grid.origin, dx, grid.shape, mirror_j0=mirror_plane_index(grid, symmetric), flags=flags)
        k = len(xs) // n
        tr.p2g(moving(xs, vs, Cs, ss, np.tile(vol0, k), np.tile(J, k), np.tile(mass, k)), G, 1e-7,
               whole(len(xs), grid.shape))
        tr.grid_update(G, whole(len(xs), grid.shape))
        return G.m, G.v, flags

    gm_h, gv_h, flags_h = grid_v(half_grid, x, v, C, stress, True)
    gm_f, gv_f, _ = grid_v(full_grid, np.vstack([x, x_m]), np.vstack([v, v_m]), np.vstack([C, C_m]),
                           np.vstack([stress, stress_m]), False)
    checked = 0
    for i, j in matching_nodes(half_grid, full_grid):
        if gm_f[j] == 0.0:
            continue
        checked += 1
        if flags_h[i] == MIRROR:  # the plane keeps the half body's mass; v_y = 0 there
            assert gm_h[i] == pytest.approx(0.5 * gm_f[j], rel=1e-12)
            np.testing.assert_allclose(gv_h[i, [0, 2]], gv_f[j, [0, 2]], rtol=1e-9, atol=1e-12)
            assert gv_h[i, 1] == 0.0 and abs(gv_f[j, 1]) < 1e-9
        else:  # interior nodes and ghosts alike
            assert flags_h[i] in (FREE, GHOST)
            assert gm_h[i] == pytest.approx(gm_f[j], rel=1e-12)
            np.testing.assert_allclose(gv_h[i], gv_f[j], rtol=1e-9, atol=1e-12)
    assert checked > 100


# ----------------------------------------------------------------------------- FLIP increment
def test_p2g_keeps_the_internal_force_impulse_apart():
    """Channels 4:7 hold the stress part of the momentum: with v = 0 and C = 0 they are all of it."""
    rng, x, _, vol0, J, mass = random_particles(seed=21)
    n = x.shape[0]
    stress = random_sym_stress(rng, n)
    buf, _, _ = p2g_update(x, np.zeros((n, 3)), np.zeros((n, 3, 3)), stress, vol0, J, mass, 1e-8)
    np.testing.assert_allclose(buf[0, :, 4:7], buf[0, :, 1:4], rtol=0, atol=1e-14 * np.abs(buf[0, :, 1:4]).max())
    assert np.abs(buf[0, :, 4:7]).max() > 0
    # with velocities and no stress the impulse channels stay zero
    v = rng.normal(0.0, 0.1, (n, 3))
    buf, _, _ = p2g_update(x, v, np.zeros((n, 3, 3)), np.zeros((n, 6)), vol0, J, mass, 1e-8)
    np.testing.assert_array_equal(buf[0, :, 4:7], 0.0)


@pytest.mark.parametrize("flip", [0.0, 0.3, 1.0])
def test_g2p_blends_the_flip_increment_with_the_grid_velocity(flip):
    """v_p <- (1 - flip) sum w v_i + flip (v_p + sum w (v_i - v_i_old)); positions move with sum w v_i."""
    rng, x, _, vol0, J, mass = random_particles(seed=22)
    n = x.shape[0]
    n_nodes = int(np.prod(SHAPE))
    grid_v = np.zeros((n_nodes, 6))
    grid_v[:, :3] = rng.normal(0.0, 0.1, (n_nodes, 3))  # new: random, not affine
    delta = np.array([0.01, -0.02, 0.03])
    grid_v[:, 3:] = grid_v[:, :3] - delta  # old: every node gained delta in this step
    v_old = rng.normal(0.0, 0.1, (n, 3))
    v = v_old.copy()
    x0 = x.copy()
    run_g2p(grid_v, x, v, np.zeros((n, 3, 3)), np.zeros((n, 6)), J, vol0, mass, 1e-7, flip=flip)
    # the grid velocity at the particles, from a second gather with flip = 0
    v_pic = np.zeros((n, 3))
    run_g2p(grid_v, x0.copy(), v_pic, np.zeros((n, 3, 3)), np.zeros((n, 6)), J, vol0, mass, 1e-7)
    np.testing.assert_allclose(v, (1 - flip) * v_pic + flip * (v_old + delta), rtol=0, atol=1e-15)
    np.testing.assert_allclose(x, x0 + 1e-7 * v_pic, rtol=0, atol=1e-18)
    if flip > 0:
        assert np.abs(v - v_pic).max() > 1e-3  # the particles keep what the grid cannot hold


# ----------------------------------------------------------------------------- dilatation projection
def weights_reference(x, origin=ORIGIN, dx=DX, shape=SHAPE):
    """Slow reference: the 27 node indices and quadratic B-spline weights of each particle."""
    g = (x - origin) / dx
    base = np.floor(g - 0.5).astype(int)
    f = g - base
    w1d = np.stack([0.5 * (1.5 - f) ** 2, 0.75 - (f - 1.0) ** 2, 0.5 * (f - 0.5) ** 2], axis=-1)  # (n, 3, 3)
    nodes, weights = [], []
    for a in range(3):
        for b in range(3):
            for c in range(3):
                idx = ((base[:, 0] + a) * shape[1] + base[:, 1] + b) * shape[2] + base[:, 2] + c
                nodes.append(idx)
                weights.append(w1d[:, 0, a] * w1d[:, 1, b] * w1d[:, 2, c])
    return np.stack(nodes, axis=1), np.stack(weights, axis=1)


def projection_reference(grid_v, x, vol):
    """Per particle: tr L_p, the lumped projection d_i = sum w V tr / V_i and d_bar_p = sum w d_i (V the particles'
    current volumes)."""
    nodes, w = weights_reference(x)
    rel = node_positions()[nodes] - x[:, None, :]  # (n, 27, 3)
    tr_p = 4.0 / DX**2 * np.einsum("pk,pkd,pkd->p", w, grid_v[nodes, :3], rel)
    n_nodes = grid_v.shape[0]
    m_i = np.bincount(nodes.ravel(), (w * vol[:, None]).ravel(), n_nodes)
    mt_i = np.bincount(nodes.ravel(), (w * (vol * tr_p)[:, None]).ravel(), n_nodes)
    d_i = np.divide(mt_i, m_i, out=np.zeros(n_nodes), where=m_i > 0)
    return tr_p, d_i, (w * d_i[nodes]).sum(1)


@pytest.mark.parametrize("n_chunks", [1, 3])
def test_dilatation_projection_matches_reference_and_conserves_the_volume_rate(n_chunks):
    """The kernels give the slow reference's nodal field and the particles' tr L; gathered back
    from the kernels' nodal field, sum_p V_p d_bar_p = sum_p V_p tr L_p, and the norm shrinks."""
    rng, x, _, vol0, J, _ = random_particles(n=500, seed=11)
    vol = vol0 * J
    grid_v = rng.normal(0.0, 0.1, (int(np.prod(SHAPE)), 6))
    G = grid_of(ORIGIN, DX, SHAPE, n_chunks, v=grid_v, div=np.full(grid_v.shape[0], np.nan))
    G.buf[:] = 1.0  # stale content must not leak in
    grid_div = G.div
    n = x.shape[0]
    C = np.zeros((n, 3, 3))
    tr.g2p_kinematics(particles_of(n, x=x, C=C, vol0=vol0, J=J), G, np.zeros((n, 3)), 0.0, 1, whole(n, SHAPE))
    tr.grid_dilatation(G, whole(n, SHAPE))
    tr_ref, d_ref, _ = projection_reference(grid_v, x, vol)
    scale = np.abs(d_ref).max()
    np.testing.assert_allclose(grid_div, d_ref, rtol=0, atol=1e-12 * scale)
    tr_p = np.trace(C, axis1=1, axis2=2)  # the kernel's own tr L
    np.testing.assert_allclose(tr_p, tr_ref, rtol=0, atol=1e-12 * np.abs(tr_ref).max())
    nodes, w = weights_reference(x)
    d_bar = (w * grid_div[nodes]).sum(1)  # the kernels' nodal field gathered back
    assert (vol * d_bar).sum() == pytest.approx((vol * tr_p).sum(), rel=1e-10, abs=1e-12 * scale * vol.sum())
    # both steps are weighted means, so (Jensen) the volume-weighted norm can only shrink; a random field shrinks
    assert (vol * d_bar**2).sum() < 0.9 * (vol * tr_p**2).sum()


def test_g2p_with_projection_moves_J_with_the_projected_dilatation_and_keeps_the_deviator():
    rng, x, _, vol0, J0, mass = random_particles(n=400, seed=12)
    n = x.shape[0]
    grid_v = np.hstack([rng.normal(0.0, 0.05, (int(np.prod(SHAPE)), 3))] * 2)
    dt = 1e-7
    tr_p, _, d_bar = projection_reference(grid_v, x, vol0 * J0)
    runs = {}
    for project in (0, 1):
        xs, C, stress, J = x.copy(), np.zeros((n, 3, 3)), np.zeros((n, 6)), J0.copy()
        run_g2p(grid_v, xs, np.zeros((n, 3)), C, stress, J, vol0, mass, dt, n_chunks=2, project=project)
        runs[project] = (xs, C, stress, J)
    (x0, C0, s0, J_local), (x1, C1, s1, J_proj) = runs[0], runs[1]
    np.testing.assert_array_equal(x0, x1)  # advection and the stored velocity gradient are L's
    np.testing.assert_array_equal(C0, C1)
    L_bar = C0 + ((d_bar - tr_p) / 3.0)[:, None, None] * np.eye(3)
    np.testing.assert_allclose(J_proj, J0 * np.linalg.det(np.eye(3) + dt * L_bar), rtol=1e-12)
    assert np.abs(J_proj / J_local - 1).max() > 1e-6  # the projection acts on this random field
    K = STIFF[0, I_K]
    np.testing.assert_allclose(s1[:, :3].mean(1), K * (J_proj - 1.0), rtol=1e-9)  # pressure from J_bar
    dev0, dev1 = s0[:, :3] - s0[:, :3].mean(1, keepdims=True), s1[:, :3] - s1[:, :3].mean(1, keepdims=True)
    np.testing.assert_allclose(dev1, dev0, rtol=0, atol=1e-9 * np.abs(dev0).max())
    np.testing.assert_allclose(s1[:, 3:], s0[:, 3:], rtol=0, atol=1e-9 * np.abs(s0[:, 3:]).max())


def internal_force_power(stress, x, v, vol0, J, mass, grid_v, dt, n_chunks, project):
    """sum_i f_i . v_i of P2G's internal force (its impulse channels over dt) on the nodal velocities grid_v,
    with the particles' own pressure (project 0) or the projected one (project 1, after scatter_pressure)."""
    n = x.shape[0]
    G = grid_of(ORIGIN, DX, SHAPE, n_chunks)
    G.buf[:] = 1.0  # stale content must not leak in
    P = moving(x, v, np.zeros((n, 3, 3)), stress, vol0, J, mass)
    if project:
        tr.scatter_pressure(P, G, whole(n, SHAPE))
        tr.grid_dilatation(G, whole(n, SHAPE))
    tr.p2g(P, G, dt, whole(n, SHAPE), project)
    return float((G.buf[:, :, 4:7].sum(0) * grid_v[:, :3]).sum()) / dt


@pytest.mark.parametrize("n_chunks", [1, 3])
def test_projected_pressure_makes_the_internal_force_work_conjugate_to_the_projected_dilatation(n_chunks):
    """The stress update works with L_bar (C with the projected dilatation as its trace), so the internal force
    must do -sum_p V_p sigma_p : L_bar_p on the same nodal velocities, or the scheme creates or destroys
    energy. With the projected pressure in P2G it does, to round-off; with each particle's own pressure it does
    -sum V sigma : C instead (the MLS identity), which differs for a pressure that varies between particles."""
    rng, x, v, vol0, J, mass = random_particles(n=400, seed=21)
    n = x.shape[0]
    stress = random_sym_stress(rng, n)
    grid_v = np.hstack([rng.normal(0.0, 0.1, (int(np.prod(SHAPE)), 3))] * 2)
    tr_p, _, d_bar = projection_reference(grid_v, x, vol0 * J)
    nodes, w = weights_reference(x)
    rel = node_positions()[nodes] - x[:, None, :]
    C = 4.0 / DX**2 * np.einsum("pk,pkd,pke->pde", w, grid_v[nodes, :3], rel)  # L_p of the kinematics
    L_bar = C + ((d_bar - tr_p) / 3.0)[:, None, None] * np.eye(3)
    s0, s1, s2, s3, s4, s5 = stress.T
    sigma = np.stack([np.stack([s0, s5, s4], -1), np.stack([s5, s1, s3], -1), np.stack([s4, s3, s2], -1)], 1)
    vol = vol0 * J
    power_update = float(np.einsum("p,pde,pde->", vol, sigma, L_bar))  # what the stress update takes
    power_own = float(np.einsum("p,pde,pde->", vol, sigma, C))
    scale = float(np.einsum("p,pde,pde->", vol, np.abs(sigma), np.abs(C)))
    dt = 1e-8
    projected = internal_force_power(stress, x, v, vol0, J, mass, grid_v, dt, n_chunks, 1)
    own = internal_force_power(stress, x, v, vol0, J, mass, grid_v, dt, n_chunks, 0)
    assert projected == pytest.approx(-power_update, rel=0, abs=1e-10 * scale)
    assert own == pytest.approx(-power_own, rel=0, abs=1e-10 * scale)
    assert abs(power_own - power_update) > 1e-3 * scale  # the two differ: the test can tell them apart


def test_projected_pressure_of_a_uniform_pressure_is_that_pressure():
    """A uniform stress projects onto itself, whatever the particles' densities (a coating on a substrate): P2G
    with the projected pressure gives the same grid. The projection is a volume-weighted mean; a mass-weighted one
    would give p rho_p / <rho> where the density changes."""
    rng, x, v, vol0, J, mass = random_particles(n=300, seed=22)
    n = x.shape[0]
    mass = np.where(x[:, 2] > x[:, 2].mean(), 7140.0, 7850.0) * vol0 * J  # zinc on steel
    stress = np.tile(rng.normal(0.0, 1e8, 6), (n, 1))
    grids = []
    for project in (0, 1):
        G = grid_of(ORIGIN, DX, SHAPE, 2)
        P = moving(x, v, np.zeros((n, 3, 3)), stress, vol0, J, mass)
        if project:
            tr.scatter_pressure(P, G, whole(n, SHAPE))
            tr.grid_dilatation(G, whole(n, SHAPE))
        tr.p2g(P, G, 1e-8, whole(n, SHAPE), project)
        grids.append(G.buf.sum(0))
    np.testing.assert_allclose(grids[1], grids[0], rtol=0, atol=1e-12 * np.abs(grids[0]).max())


def test_uniform_dilatation_passes_the_projection_unchanged():
    """An affine velocity field has the same tr L at every particle: projecting it changes nothing."""
    rng, x, _, vol0, J0, mass = random_particles(n=300, seed=13)
    n = x.shape[0]
    A = rng.normal(0.0, 1e3, (3, 3))
    grid_v = node_positions() @ A.T
    out = {}
    for project in (0, 1):
        J = J0.copy()
        stress = np.zeros((n, 6))
        run_g2p(grid_v, x.copy(), np.zeros((n, 3)), np.zeros((n, 3, 3)), stress, J, vol0, mass, 1e-7,
                project=project)
        out[project] = (J, stress)
    np.testing.assert_allclose(out[1][0], out[0][0], rtol=1e-13)
    np.testing.assert_allclose(out[1][1], out[0][1], rtol=1e-9, atol=1e-6)


def test_dilatation_projection_with_the_mirror_plane_reproduces_the_full_domain():
    """Half domain (mirror fold) and full domain with mirrored particles give the same nodal field."""
    rng = np.random.default_rng(8)
    dx = MIRROR_DX
    half_grid, full_grid = half_and_full_grids()
    n = 300
    x = particles_near_the_mirror(rng, n)
    mass = RHO * (0.5 * dx) ** 3 * rng.uniform(0.8, 1.2, n)

    def velocity(pos):  # a smooth field even in y for v_x, v_z and odd for v_y
        return np.column_stack([np.sin(pos[:, 0] / 4e-5) * np.cos(pos[:, 1] / 3e-5), np.sin(pos[:, 1] / 2e-5),
                                np.cos(pos[:, 2] / 5e-5 + pos[:, 1] ** 2 / 1e-9)])

    def project(grid, xs, ms, symmetric):
        gv = np.hstack([velocity(grid.node_positions())] * 2)
        G = grid_of(grid.origin, dx, grid.shape, 2, mirror_j0=mirror_plane_index(grid, symmetric), v=gv)
        k = len(xs)
        tr.g2p_kinematics(particles_of(k, x=xs, mass=ms), G, np.zeros((k, 3)), 0.0, 1, whole(k, grid.shape))
        tr.grid_dilatation(G, whole(k, grid.shape))
        return G.div

    d_h = project(half_grid, x, mass, True)
    d_f = project(full_grid, np.vstack([x, x * [1.0, -1.0, 1.0]]), np.concatenate([mass, mass]), False)
    checked = 0
    for i, j in matching_nodes(half_grid, full_grid):
        if d_f[j] == 0.0:
            continue
        checked += 1
        assert d_h[i] == pytest.approx(d_f[j], rel=1e-9, abs=1e-9 * np.abs(d_f).max())
    assert checked > 100


# ----------------------------------------------------------------------------- active zone (index ranges)
def test_p2g_over_a_particle_range_is_the_scatter_of_those_particles_and_keeps_other_nodes():
    """The active zone's particle range [p_lo, p_hi) scatters exactly those particles; nodes outside
    the node range [n_lo, n_hi) are neither zeroed nor summed."""
    rng, x, v, vol0, J, mass = random_particles(n=400, seed=21)
    n = x.shape[0]
    order = np.argsort(x[:, 0])  # x-major, as the solver seeds them
    x, v, vol0, J, mass = x[order], v[order], vol0[order], J[order], mass[order]
    C, stress = rng.normal(0.0, 50.0, (n, 3, 3)), random_sym_stress(rng, n)
    n_nodes = int(np.prod(SHAPE))
    p_lo, p_hi = 100, 300
    P = moving(x, v, C, stress, vol0, J, mass)
    for n_chunks in (1, 2):
        ranged = np.full((n_chunks, n_nodes, 7), 7.0)
        tr.p2g(P, grid_of(ORIGIN, DX, SHAPE, buf=ranged), 1e-8, whole(n, SHAPE)._replace(p_lo=p_lo, p_hi=p_hi))
        sub = grid_of(ORIGIN, DX, SHAPE)
        sl = slice(p_lo, p_hi)
        tr.p2g(moving(x[sl], v[sl], C[sl], stress[sl], vol0[sl], J[sl], mass[sl]), sub, 1e-8,
               whole(p_hi - p_lo, SHAPE))
        np.testing.assert_allclose(ranged.sum(0), sub.buf[0], rtol=1e-12, atol=1e-12 * np.abs(sub.buf).max())
    slab = SHAPE[1] * SHAPE[2]
    kept = np.full((1, n_nodes, 7), 7.0)
    tr.p2g(P, grid_of(ORIGIN, DX, SHAPE, buf=kept), 1e-8,
           whole(n, SHAPE)._replace(p_lo=0, p_hi=0, n_lo=4 * slab, n_hi=9 * slab))
    assert np.all(kept[0, 4 * slab:9 * slab] == 0.0)  # the range was zeroed, no particle scattered
    assert np.all(kept[0, :4 * slab] == 7.0) and np.all(kept[0, 9 * slab:] == 7.0)


def test_grid_update_clamps_the_frozen_slabs_and_leaves_nodes_outside_its_range():
    """Nodes of x index outside [i_free_lo, i_free_hi] hold zero velocity (the frozen material), the
    others are the plain update; nodes outside [n_lo, n_hi) are not written."""
    rng = np.random.default_rng(22)
    n_nodes = int(np.prod(SHAPE))
    slab = int(SHAPE[1] * SHAPE[2])
    buf = np.zeros((2, n_nodes, 7))
    buf[:, :, 0] = rng.uniform(0.1, 1.0, (2, n_nodes))
    buf[:, :, 1:] = rng.normal(0.0, 1.0, (2, n_nodes, 6))
    flags = np.full(n_nodes, FREE, dtype=np.int8)
    full = grid_of(ORIGIN, DX, SHAPE, buf=buf, flags=flags)
    tr.grid_update(full, whole(0, SHAPE))
    full_m, full_v = full.m, full.v
    grid_m, grid_v = np.full(n_nodes, -1.0), np.full((n_nodes, 6), 99.0)
    n_lo, n_hi, i_free_lo, i_free_hi = 3 * slab, 12 * slab, 5, 9
    tr.grid_update(grid_of(ORIGIN, DX, SHAPE, buf=buf, flags=flags, m=grid_m, v=grid_v),
                   whole(0, SHAPE)._replace(n_lo=n_lo, n_hi=n_hi, i_free_lo=i_free_lo, i_free_hi=i_free_hi))
    i = np.arange(n_nodes) // slab
    inside = (np.arange(n_nodes) >= n_lo) & (np.arange(n_nodes) < n_hi)
    free = inside & (i >= i_free_lo) & (i <= i_free_hi)
    clamped = inside & ~free
    assert clamped.any() and free.any()
    np.testing.assert_array_equal(grid_m[~inside], -1.0)
    np.testing.assert_array_equal(grid_v[~inside], 99.0)
    np.testing.assert_array_equal(grid_m[inside], full_m[inside])
    np.testing.assert_array_equal(grid_v[free], full_v[free])
    np.testing.assert_array_equal(grid_v[clamped, :3], 0.0)
    np.testing.assert_array_equal(grid_v[clamped, 3:], full_v[clamped, 3:])  # FLIP's old velocity is kept


def test_freeze_particles_stops_them_and_counts_their_energies():
    rng, x, v, vol0, J, mass = random_particles(n=50, seed=23)
    n = x.shape[0]
    table = pack_materials([rigid_plastic("coat", 450e6, coating=True), rigid_plastic("sub", 900e6, coating=False)])
    mat_a = rng.integers(0, 2, n).astype(np.int32)
    mat_b = np.ones(n, dtype=np.int32)
    frac = rng.uniform(0.2, 1.0, n)
    stress = random_sym_stress(rng, n)
    C, v_grid = rng.normal(0.0, 1.0, (n, 3, 3)), rng.normal(0.0, 1.0, (n, 3))
    v0, C0, v_grid0 = v.copy(), C.copy(), v_grid.copy()
    P = particles_of(n, v=v, C=C, stress=stress, J=J, vol0=vol0, mass=mass, mat_a=mat_a, mat_b=mat_b, frac_a=frac)
    elastic, kinetic = tr.freeze_particles(P, v_grid, table, 10, 30)
    sl = slice(10, 30)
    assert kinetic == pytest.approx(0.5 * np.sum(mass[sl, None] * v0[sl] ** 2), rel=1e-13)
    # the elastic energy density of an isotropic solid: p^2 / 2K + s:s / 4G, moduli mixed by volume
    K = frac * table[mat_a, I_K] + (1 - frac) * table[mat_b, I_K]
    G = frac * table[mat_a, I_G] + (1 - frac) * table[mat_b, I_G]
    p = stress[:, :3].mean(axis=1)
    dev = stress.copy()
    dev[:, :3] -= p[:, None]
    ss = np.sum(dev[:, :3] ** 2, axis=1) + 2 * np.sum(dev[:, 3:] ** 2, axis=1)
    density = p**2 / (2 * K) + ss / (4 * G)
    assert elastic == pytest.approx(np.sum((density * vol0 * J)[sl]), rel=1e-12)
    assert np.all(v[sl] == 0.0) and np.all(C[sl] == 0.0) and np.all(v_grid[sl] == 0.0)
    rest = np.r_[0:10, 30:n]
    np.testing.assert_array_equal(v[rest], v0[rest])
    np.testing.assert_array_equal(C[rest], C0[rest])
    np.testing.assert_array_equal(v_grid[rest], v_grid0[rest])
