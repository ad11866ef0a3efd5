"""Particle-grid transfers of explicit MLS-MPM / APIC (model.md section 2).

One step moves momentum particle -> grid (P2G), updates the grid velocity with the internal
force, applies boundary conditions and contact, and moves velocity grid -> particle (G2P), where
the velocity gradient drives the stress update (eq. 6.1) and the particles are advected.

- P2G (APIC with the MLS internal force, Hu et al. 2018):
      m_i  = sum_p w_ip m_p
      (mv)_i = sum_p w_ip [m_p v_p + (m_p C_p - dt V_p D^-1 sigma_p)(x_i - x_p)],  D^-1 = 4/dx^2
- G2P: v_p <- (1 - flip) sum_i w_ip v_i + flip (v_p + sum_i w_ip (v_i - v_i^old)),
      C_p = D^-1 sum_i w_ip v_i (x_i - x_p)^T  (= velocity gradient L_p),
      J_p <- J_p det(I + dt L_p),  x_p <- x_p + dt sum_i w_ip v_i,
  with v_i^old the nodal velocity before the internal force, boundary conditions and contact.
- Projected dilatation (a B-bar / F-bar treatment of volumetric locking, after Telikicherla and
  Moutsanidis 2024): the volumetric strain rate d_p = tr L_p is replaced by its lumped L2
  projection on the grid, d_i = sum_p w_ip V_p d_p / V_i (V_i = sum_p w_ip V_p), d_bar_p = sum_i w_ip d_i, and
  L_bar_p = L_p + (d_bar_p - d_p) I / 3 drives J and the pressure (the deviator and the spin are
  L_p's). Plastic flow is isochoric: with one dilatation constraint per particle (8 per cell at
  two particles per cell) against three velocity unknowns per node, the discrete velocity field
  cannot deform at constant volume and the block is far too stiff under the sphere (the coated
  reference scene at h = 20 / 10 um: dp 1.36 / 3.69 um without, 4.07 / 12.99 um with the
  projection). The projection conserves sum_p V_p d_p (the rate of the body's volume) exactly. The
  pressure is projected with the same operator before P2G, so that the internal force does the work
  the stress update takes (a B-bar scheme): p_i = sum_p w_ip V_p p_p / V_i, and the force takes each
  particle's deviatoric stress with p_bar_p = sum_i w_ip p_i, so that sum_p V_p p_bar_p d_p =
  sum_p V_p p_p d_bar_p exactly; the volume weights (not mass weights) keep a uniform pressure and a
  uniform dilatation unchanged across a change of density (a coating on a substrate). With each
  particle's own pressure in the force the work of the pressure on d_bar_p - d_p went into no
  energy term and was not small: on the uncoated reference scene at f = 0, h = 5 um, it created
  0.6 of the sphere's work, dissipated as plastic work while the sphere rose under its load
  (docs/journal/2026-12-03-consistent-pressure.md).
  flip = 0 is APIC. APIC drops the part of the velocity field an affine field cannot hold on
  every transfer: a numerical dissipation per step, so the more steps a slide takes the more of
  the sphere's work it eats (41% at CFL 0.075 on the frictionless reference scene) and the
  results followed the time step. The FLIP increment keeps that part; positions move with the
  grid velocity, so the particles do not drift apart.

Interfaces: each kernel takes the named bundles of :mod:`plough.mpm.bundles` (``P`` the particles, ``G``
the grid, ``M`` the materials, ``S`` the sphere, ``Z`` the zone's ranges) and says which of their fields it
reads and writes; a particle's 27-node stencil is set up by :func:`plough.mpm.shape.stencil`, for these
kernels and the contact's alike.

Threads: P2G and the kinematics cut the particles into ``n_chunks`` contiguous chunks (in seeding
order, so a chunk is a slab of the block); ``g2p_update``, whose cost per particle varies (a
plastic particle's return map costs several flow-law evaluations, and they cluster around the
sphere), deals blocks of ``G2P_BLOCK`` particles to the chunks in turn. The scatter is race-free
by construction: chunk c writes only its own grid copy ``G.buf[c]``; the grid update sums the
copies node by node (each node owned by one iteration). The gathers read the grid and write only
particle p's own entries; the dilatation scatter inside ``g2p_kinematics`` writes only its
chunk's ``G.buf[c]`` and ``g2p_update`` only its chunk's scratch ``L_buf[c]``.

Stores inside a ``prange`` body go to arrays taken from the bundles before the ``prange`` (or read again in
the body): numba's parallel dead-code elimination drops a store into an array taken from a named tuple inside
the body that the body does not read again (numba issues 7135, 10338; ``constitutive.stress_update``).
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit, prange

from plough.mpm.bundles import StressState
from plough.mpm.constitutive import elastic_energy_density, mixed_moduli, stress_update
from plough.mpm.grid import FIXED, GHOST, MIRROR
from plough.mpm.shape import APIC_D_INV_FACTOR, stencil, stencil_axis_offset, stencil_row, stencil_row_weight

# per-chunk accumulators written by g2p_update (ACC_ELASTIC by elastic_energies, on the steps that need it)
ACC_PLASTIC_WORK = 0
ACC_KINETIC = 1
ACC_ELASTIC = 2
ACC_PENETRATION = 3
ACC_BAD = 4
ACC_BAD_INDEX = 5
ACC_HEAT = 6
N_ACC = 7
# codes of ACC_BAD, worst last
BAD_NONE, BAD_LEFT_GRID, BAD_J, BAD_NONFINITE = 0, 1, 2, 3
# particles per block of g2p_update's round-robin split over the chunks: small against the plastic
# zone, so that it spreads over every thread, large enough to keep each thread's memory streams long
# (256 cost 7% on the uncoated reference scene at h = 5 um, 1024 and 4096 nothing)
G2P_BLOCK = 1024
# LLVM's fast-math flags for P2G and the kinematics (sums of 27 nodes' products, no NaN test, no function call):
# fused multiply-adds and reassociated sums. Not nnan / ninf, which would let LLVM assume no NaN or infinity and
# fold tests for them away. Not bitwise: mu and dp of the lattice-phase cases at h = 20 and 10 um moved by at most
# 1e-12 relative, against a spread of 0.1-2% (mu) and 9-27% (dp) over the phases; the kinematics 1.21x faster, P2G
# 1.03x (docs/journal/2026-12-02-throughput.md)
TRANSFER_FASTMATH = {"contract", "arcp", "nsz", "reassoc", "afn"}


@njit(cache=True, inline="always")
def _chunked_stencil_setup(G, Z):
    """What P2G and the kinematics share before their loop: the first active particle, their count, the
    chunks (one per grid copy in G.buf), the grid's y and z node counts, the cell dx, 1 / dx and the APIC
    D^-1 = 4 / dx^2. Reads G.buf's shape, G.shape, G.dx and Z.p_lo, Z.p_hi; writes nothing."""
    dx = G.dx
    inv_dx = 1.0 / dx
    return (Z.p_lo, Z.p_hi - Z.p_lo, G.buf.shape[0], G.shape[1], G.shape[2], dx, inv_dx,
            APIC_D_INV_FACTOR * inv_dx * inv_dx)


@njit(cache=True, parallel=True, fastmath=TRANSFER_FASTMATH)
def p2g(P, G, dt, Z, project=0):
    """Scatter particle mass and momentum (with dt * internal force) to per-chunk grid copies.

    Reads P.x, v, C, stress, vol0, J, mass of the active particles Z.p_lo <= p < Z.p_hi and the grid's
    geometry; if ``project`` is 1 also G.div, the nodal pressure of ``scatter_pressure`` and
    ``grid_dilatation``: the internal force then takes each particle's deviatoric stress with the projected
    pressure p_bar = sum_i w_ip G.div[i] (the module docstring says why). Writes G.buf[c, node, 0:7] =
    (mass, momentum x, y, z, and the internal-force impulse x, y, z already in that momentum) of chunk c,
    zeroing the active nodes Z.n_lo <= node < Z.n_hi first. Race-free: chunk c owns G.buf[c].
    """
    x, v, C, stress, vol0, J, mass, div = P.x, P.v, P.C, P.stress, P.vol0, P.J, P.mass, G.div
    p_lo, n, n_chunks, ny, nz, dx, inv_dx, dinv = _chunked_stencil_setup(G, Z)
    for c in prange(n_chunks):
        buf = G.buf[c]
        buf[Z.n_lo:Z.n_hi, :] = 0.0
        for p in range(p_lo + c * n // n_chunks, p_lo + (c + 1) * n // n_chunks):
            m = mass[p]
            vol = vol0[p] * J[p]
            k_stress = -dt * vol * dinv
            # the stress in locals: the grid stores below may alias the stress array as far as the compiler
            # knows, and would make it reload them at every node
            s0, s1, s2, s3, s4, s5 = stress[p, 0], stress[p, 1], stress[p, 2], stress[p, 3], stress[p, 4], stress[p, 5]
            st = stencil(x, p, G.origin, inv_dx)
            if project:
                # sigma_mean + p_bar: the particle's own mean stress out, the projected pressure in
                shift = (s0 + s1 + s2) / 3.0 + _gather_at(div, st, ny, nz)
                s0 -= shift
                s1 -= shift
                s2 -= shift
            # affine momentum matrix Q = m C - dt V D^-1 sigma
            q00 = m * C[p, 0, 0] + k_stress * s0
            q11 = m * C[p, 1, 1] + k_stress * s1
            q22 = m * C[p, 2, 2] + k_stress * s2
            q12 = m * C[p, 1, 2] + k_stress * s3
            q21 = m * C[p, 2, 1] + k_stress * s3
            q02 = m * C[p, 0, 2] + k_stress * s4
            q20 = m * C[p, 2, 0] + k_stress * s4
            q01 = m * C[p, 0, 1] + k_stress * s5
            q10 = m * C[p, 1, 0] + k_stress * s5
            mv0, mv1, mv2 = m * v[p, 0], m * v[p, 1], m * v[p, 2]
            # the x and y parts of each sum are taken once per (a, b) row of three nodes, in the order the sums
            # are written in (w = (wx wy) wz, (mv + q d0 + q d1) + q d2): the same round-off as per node
            for a in range(3):
                for b in range(3):
                    row, wab, d0, d1 = stencil_row_weight(st, a, b, ny, nz, dx)
                    r1 = mv0 + q00 * d0 + q01 * d1
                    r2 = mv1 + q10 * d0 + q11 * d1
                    r3 = mv2 + q20 * d0 + q21 * d1
                    f1 = s0 * d0 + s5 * d1
                    f2 = s5 * d0 + s1 * d1
                    f3 = s4 * d0 + s3 * d1
                    for cc in range(3):
                        w = wab * st.wz[cc]
                        d2 = stencil_axis_offset(st, 2, cc, dx)
                        wk = w * k_stress
                        node = row + cc
                        buf[node, 0] += w * m
                        buf[node, 1] += w * (r1 + q02 * d2)
                        buf[node, 2] += w * (r2 + q12 * d2)
                        buf[node, 3] += w * (r3 + q22 * d2)
                        buf[node, 4] += wk * (f1 + s4 * d2)
                        buf[node, 5] += wk * (f2 + s3 * d2)
                        buf[node, 6] += wk * (f3 + s2 * d2)


@njit(cache=True, inline="always")
def mirror_partner(node, ny, nz, mirror_j0):
    """The node at -y of ``node`` across the mirror plane j = mirror_j0, or -1 (no plane, on it, off the grid)."""
    if mirror_j0 < 0:
        return -1
    j = (node // nz) % ny
    jm = 2 * mirror_j0 - j
    if j == mirror_j0 or jm < 0 or jm >= ny:
        return -1
    return node + (jm - j) * nz


@njit(cache=True, parallel=True)
def grid_update(G, Z):
    """Sum the chunk copies into nodal mass and velocity and apply the boundary conditions.

    Reads G.buf (P2G output), G.flags (FREE / FIXED / MIRROR / GHOST), the grid shape and the
    index ``G.mirror_j0`` of the node plane y = 0 (-1 without symmetry), for the active nodes
    Z.n_lo <= node < Z.n_hi. Writes their G.m[node], G.v[node, 0:3] (velocity at the end of
    the step before contact) and G.v[node, 3:6] (velocity before the internal force, for the
    FLIP increment). Nodes of x index outside [Z.i_free_lo, Z.i_free_hi] lie in the frozen material
    beyond the active zone and hold zero velocity, as FIXED nodes do. Each node is owned by one
    iteration and only reads the buffers, so the reduction is race-free.

    Mirror symmetry is exact, not just v_y = 0 on the plane: a node at y = +j dx also receives
    what the mirror images of the particles would give it, i.e. the contributions its ghost at
    -j dx received, with the y momentum reversed (and the ghost gets the mirror image of the
    sum). A half domain then reproduces the full domain's grid state to round-off. Nodes on the
    plane keep their own (half) mass with v_y = 0, so impulses there are the half body's share.
    """
    grid_buf, flags, grid_m, grid_v, mirror_j0 = G.buf, G.flags, G.m, G.v, G.mirror_j0
    i_free_lo, i_free_hi = Z.i_free_lo, Z.i_free_hi
    n_chunks = grid_buf.shape[0]
    ny, nz = G.shape[1], G.shape[2]
    for node in prange(Z.n_lo, Z.n_hi):
        m = 0.0
        p0 = 0.0
        p1 = 0.0
        p2 = 0.0
        i0 = 0.0
        i1 = 0.0
        i2 = 0.0
        for c in range(n_chunks):
            m += grid_buf[c, node, 0]
            p0 += grid_buf[c, node, 1]
            p1 += grid_buf[c, node, 2]
            p2 += grid_buf[c, node, 3]
            i0 += grid_buf[c, node, 4]
            i1 += grid_buf[c, node, 5]
            i2 += grid_buf[c, node, 6]
        partner = mirror_partner(node, ny, nz, mirror_j0)
        if partner >= 0:
            for c in range(n_chunks):
                m += grid_buf[c, partner, 0]
                p0 += grid_buf[c, partner, 1]
                p1 -= grid_buf[c, partner, 2]
                p2 += grid_buf[c, partner, 3]
                i0 += grid_buf[c, partner, 4]
                i1 -= grid_buf[c, partner, 5]
                i2 += grid_buf[c, partner, 6]
        grid_m[node] = m
        if m > 0.0:
            grid_v[node, 3] = (p0 - i0) / m
            grid_v[node, 4] = (p1 - i1) / m
            grid_v[node, 5] = (p2 - i2) / m
        else:
            grid_v[node, 3] = 0.0
            grid_v[node, 4] = 0.0
            grid_v[node, 5] = 0.0
        i = node // (ny * nz)
        if m <= 0.0 or flags[node] == FIXED or i < i_free_lo or i > i_free_hi:
            grid_v[node, 0] = 0.0
            grid_v[node, 1] = 0.0
            grid_v[node, 2] = 0.0
            continue
        grid_v[node, 0] = p0 / m
        grid_v[node, 1] = 0.0 if flags[node] == MIRROR else p1 / m
        grid_v[node, 2] = p2 / m


@njit(cache=True, parallel=True)
def mirror_ghosts(G, Z):
    """Ghost nodes (y < 0) take the mirror image of their partner's velocity after contact.

    Reads G.v of nodes with y > 0 and G.flags; writes G.v of the GHOST nodes among Z.n_lo <= node <
    Z.n_hi (each written once; a partner lies in its ghost's x slab, so in the same range).
    """
    grid_v, flags, mirror_j0 = G.v, G.flags, G.mirror_j0
    ny, nz = G.shape[1], G.shape[2]
    for node in prange(Z.n_lo, Z.n_hi):
        if flags[node] != GHOST:
            continue
        j = (node // nz) % ny
        jm = 2 * mirror_j0 - j
        if jm >= ny:
            continue
        partner = node + (jm - j) * nz
        grid_v[node, 0] = grid_v[partner, 0]
        grid_v[node, 1] = -grid_v[partner, 1]
        grid_v[node, 2] = grid_v[partner, 2]


@njit(cache=True, inline="always")
def _scatter_volume_and(buf, st, ny, nz, dx, vol, t):
    """buf[node, 0] += w vol and buf[node, 1] += w t over the stencil ``st``'s 27 nodes: the scatter of a
    projection (the dilatation's, t = V tr L; the pressure's, t = V p)."""
    for a in range(3):
        for b in range(3):
            row, wab, _, _ = stencil_row_weight(st, a, b, ny, nz, dx)
            for cc in range(3):
                w = wab * st.wz[cc]
                buf[row + cc, 0] += w * vol
                buf[row + cc, 1] += w * t


@njit(cache=True, parallel=True)
def scatter_pressure(P, G, Z):
    """Scatter the particles' volume and volume times pressure for the pressure's projection (before P2G).

    Reads P.x, stress, vol0, J of the active particles Z.p_lo <= p < Z.p_hi; writes G.buf[c, node, 0] =
    sum w V and G.buf[c, node, 1] = sum w V p (p = -tr sigma / 3) over chunk c's particles (the split of P2G
    and the kinematics), zeroing those two channels of the active nodes Z.n_lo <= node < Z.n_hi first;
    ``grid_dilatation`` then forms the nodal pressure. Race-free: chunk c owns G.buf[c].
    """
    x, stress, vol0, J = P.x, P.stress, P.vol0, P.J
    p_lo, n, n_chunks, ny, nz, dx, inv_dx, _ = _chunked_stencil_setup(G, Z)
    for c in prange(n_chunks):
        buf = G.buf[c]
        buf[Z.n_lo:Z.n_hi, 0:2] = 0.0
        for p in range(p_lo + c * n // n_chunks, p_lo + (c + 1) * n // n_chunks):
            vol = vol0[p] * J[p]
            _scatter_volume_and(buf, stencil(x, p, G.origin, inv_dx), ny, nz, dx, vol,
                                -vol * (stress[p, 0] + stress[p, 1] + stress[p, 2]) / 3.0)


@njit(cache=True, parallel=True)
def grid_dilatation(G, Z):
    """Nodal dilatation rate d_i = (sum w V d) / V_i from the chunk copies of the ``g2p_kinematics`` scatter
    (before P2G, from those of ``scatter_pressure``: the nodal pressure p_i = (sum w V p) / V_i).

    Reads G.buf[:, node, 0:2] of the active nodes Z.n_lo <= node < Z.n_hi; writes their
    G.div[node] (0 where no material). With the mirror plane a
    node also sums its ghost's contributions (dilatation and pressure are even in y), so ghost and partner
    hold the same value and the half domain projects like the full one. Each node is owned by one
    iteration: race-free.
    """
    grid_buf, grid_div, mirror_j0 = G.buf, G.div, G.mirror_j0
    n_chunks = grid_buf.shape[0]
    ny, nz = G.shape[1], G.shape[2]
    for node in prange(Z.n_lo, Z.n_hi):
        vol = 0.0
        t = 0.0
        for c in range(n_chunks):
            vol += grid_buf[c, node, 0]
            t += grid_buf[c, node, 1]
        partner = mirror_partner(node, ny, nz, mirror_j0)
        if partner >= 0:
            for c in range(n_chunks):
                vol += grid_buf[c, partner, 0]
                t += grid_buf[c, partner, 1]
        grid_div[node] = t / vol if vol > 0.0 else 0.0


@njit(cache=True, parallel=True, fastmath=TRANSFER_FASTMATH)
def g2p_kinematics(P, G, v_grid, flip, scatter_dilatation, Z):
    """Gather the particle velocities and velocity gradients; scatter the dilatation for its projection.

    Reads G.v (0:3 new, 3:6 before the internal force), P.x, P.v (FLIP share ``flip``) and P.vol0, P.J
    of the active particles Z.p_lo <= p < Z.p_hi. Writes their P.v (the blended update), P.C (= L_p,
    the APIC velocity gradient) and v_grid (sum_i w v_i, the velocity the particle is advected with).
    If ``scatter_dilatation`` is 1 also writes G.buf[c, node, 0] = sum w V and
    G.buf[c, node, 1] = sum w V tr L over chunk c's particles (zeroing those two channels of
    the active nodes Z.n_lo <= node < Z.n_hi first; the P2G content is no longer needed), for
    ``grid_dilatation``. The active particles' stencils must lie in the node range (the solver's
    positions check keeps them there). Race-free: particle p writes only its own entries, chunk c
    only G.buf[c].
    """
    x, v, C, vol0, J, grid_v = P.x, P.v, P.C, P.vol0, P.J, G.v
    p_lo, n, n_chunks, ny, nz, dx, inv_dx, dinv = _chunked_stencil_setup(G, Z)
    for c in prange(n_chunks):
        buf = G.buf[c]
        if scatter_dilatation:
            buf[Z.n_lo:Z.n_hi, 0:2] = 0.0
        for p in range(p_lo + c * n // n_chunks, p_lo + (c + 1) * n // n_chunks):
            st = stencil(x, p, G.origin, inv_dx)
            v0 = 0.0
            v1 = 0.0
            v2 = 0.0
            dv0 = 0.0
            dv1 = 0.0
            dv2 = 0.0
            b00 = 0.0
            b01 = 0.0
            b02 = 0.0
            b10 = 0.0
            b11 = 0.0
            b12 = 0.0
            b20 = 0.0
            b21 = 0.0
            b22 = 0.0
            # x and y parts of each node's weight and offset taken once per (a, b) row: w = (wx wy) wz as per node
            for a in range(3):
                for b in range(3):
                    row, wab, d0, d1 = stencil_row_weight(st, a, b, ny, nz, dx)
                    for cc in range(3):
                        w = wab * st.wz[cc]
                        d2 = stencil_axis_offset(st, 2, cc, dx)
                        node = row + cc
                        g0 = grid_v[node, 0]
                        g1 = grid_v[node, 1]
                        g2 = grid_v[node, 2]
                        gv0 = w * g0
                        gv1 = w * g1
                        gv2 = w * g2
                        v0 += gv0
                        v1 += gv1
                        v2 += gv2
                        dv0 += w * (g0 - grid_v[node, 3])
                        dv1 += w * (g1 - grid_v[node, 4])
                        dv2 += w * (g2 - grid_v[node, 5])
                        b00 += gv0 * d0
                        b01 += gv0 * d1
                        b02 += gv0 * d2
                        b10 += gv1 * d0
                        b11 += gv1 * d1
                        b12 += gv1 * d2
                        b20 += gv2 * d0
                        b21 += gv2 * d1
                        b22 += gv2 * d2
            v[p, 0] = (1.0 - flip) * v0 + flip * (v[p, 0] + dv0)
            v[p, 1] = (1.0 - flip) * v1 + flip * (v[p, 1] + dv1)
            v[p, 2] = (1.0 - flip) * v2 + flip * (v[p, 2] + dv2)
            v_grid[p, 0] = v0
            v_grid[p, 1] = v1
            v_grid[p, 2] = v2
            Cp = C[p]
            Cp[0, 0] = dinv * b00
            Cp[0, 1] = dinv * b01
            Cp[0, 2] = dinv * b02
            Cp[1, 0] = dinv * b10
            Cp[1, 1] = dinv * b11
            Cp[1, 2] = dinv * b12
            Cp[2, 0] = dinv * b20
            Cp[2, 1] = dinv * b21
            Cp[2, 2] = dinv * b22
            if scatter_dilatation:
                vol = vol0[p] * J[p]
                _scatter_volume_and(buf, st, ny, nz, dx, vol, vol * (Cp[0, 0] + Cp[1, 1] + Cp[2, 2]))


@njit(cache=True, parallel=True)
def g2p_update(P, G, M, S, Z, dt, project, v_grid, L_buf, acc, block):
    """Update the stress (eq. 6.1-6.2), advect, and check the particle state.

    Works on the active particles Z.p_lo <= p < Z.p_hi only. Reads P.v and P.C (from
    ``g2p_kinematics``), v_grid, P.vol0, P.mass, the materials (P.mat_a, mat_b, frac_a; the table and
    constants M), the sphere (S.centre after this step, S.radius, S.near_dist) and, if ``project`` is
    1, the projected nodal dilatation G.div (``grid_dilatation``): J and the pressure then follow
    L_bar = C + (sum w d_i - tr C) I / 3, formed in the chunk's scratch L_buf[c]; with ``project`` 0
    they follow C (G.div and L_buf are not read). Writes P.x (x += dt v_grid), J, stress, eps_p,
    temperature, sigma_y0 and deps_last (the flow stress at rest and the last plastic increment,
    updated where the particle flowed), P.near (1 if within S.near_dist of the sphere surface), and
    per-chunk accumulators acc[c, :] (plastic work, kinetic energy, adiabatic heat,
    deepest penetration of a particle centre into the sphere, worst instability code and the particle
    showing it; a particle outside [Z.check_lo, Z.check_hi] has left the grid). Each particle writes
    only its own entries, chunk c only acc[c] and L_buf[c]: race-free.

    Chunk c works on the blocks of ``block`` particles numbered c, c + n_chunks, c + 2 n_chunks, ...
    (``G2P_BLOCK`` in the solver), not on one contiguous slab: the particles that flow, whose return
    map costs several flow-law evaluations, lie around the sphere, and a slab split gave one thread
    most of them (zinc-coated steel at h = 10 um, start of the slide: 29.3 against 12.1 ms for the two
    halves on one thread, docs/journal/2026-11-23-g2p-load-balance.md). ``block`` = ceil(n / n_chunks) gives one
    contiguous slab per chunk (the earlier split, whose slab ends could lie one particle off).
    """
    x, v, C, stress, J, vol0, mass, near = P.x, P.v, P.C, P.stress, P.J, P.vol0, P.mass, P.near
    taylor_quinney = M.taylor_quinney
    SP = StressState(P.stress, P.J, P.eps_p, P.temperature, P.sigma_y0, P.deps_last, P.mat_a, P.mat_b, P.frac_a)
    sphere_c, sphere_r, grid_lo, grid_hi = S.centre, S.radius, Z.check_lo, Z.check_hi
    p_lo, p_hi = Z.p_lo, Z.p_hi
    n_chunks = acc.shape[0]
    n_blocks = (p_hi - p_lo + block - 1) // block
    ny, nz = G.shape[1], G.shape[2]
    inv_dx = 1.0 / G.dx
    for c in prange(n_chunks):
        wp_sum = 0.0
        ke_sum = 0.0
        heat_sum = 0.0
        pen_max = -1e300
        bad = BAD_NONE
        bad_p = -1
        for blk in range(c, n_blocks, n_chunks):
            for p in range(p_lo + blk * block, min(p_lo + (blk + 1) * block, p_hi)):
                Cp = C[p]
                L = Cp
                if project:
                    L = L_buf[c]
                    _with_dilatation(Cp, _gather_scalar(G.div, x, p, G.origin, inv_dx, ny, nz), L)
                J_new = J[p] * _det_i_plus(dt, L)
                J[p] = J_new
                # inlined; the stress array is handed in from outside the prange (a store through SP.stress in
                # the prange body would be dropped: constitutive.stress_update says why)
                deps, w_pl = stress_update(stress, SP, p, L, dt, M)
                vol = vol0[p] * J_new
                wp_sum += w_pl * vol
                heat_sum += taylor_quinney * w_pl * vol
                ke_sum += 0.5 * mass[p] * (v[p, 0] * v[p, 0] + v[p, 1] * v[p, 1] + v[p, 2] * v[p, 2])
                x0 = x[p, 0] + dt * v_grid[p, 0]
                x1 = x[p, 1] + dt * v_grid[p, 1]
                x2 = x[p, 2] + dt * v_grid[p, 2]
                x[p, 0] = x0
                x[p, 1] = x1
                x[p, 2] = x2
                r0 = x0 - sphere_c[0]
                r1 = x1 - sphere_c[1]
                r2 = x2 - sphere_c[2]
                dist = math.sqrt(r0 * r0 + r1 * r1 + r2 * r2)
                near[p] = 1 if dist < sphere_r + S.near_dist else 0
                if sphere_r - dist > pen_max:
                    pen_max = sphere_r - dist
                # instability checks, worst code kept
                code = BAD_NONE
                if not (math.isfinite(x0 + x1 + x2) and math.isfinite(stress[p, 0] + stress[p, 1] + stress[p, 2])):
                    code = BAD_NONFINITE
                elif J_new <= 0.0 or J_new > 4.0:
                    code = BAD_J
                elif (x0 < grid_lo[0] or x1 < grid_lo[1] or x2 < grid_lo[2] or x0 > grid_hi[0] or x1 > grid_hi[1]
                      or x2 > grid_hi[2]):
                    code = BAD_LEFT_GRID
                if code > bad:
                    bad = code
                    bad_p = p
        acc[c, ACC_PLASTIC_WORK] = wp_sum
        acc[c, ACC_KINETIC] = ke_sum
        acc[c, ACC_HEAT] = heat_sum
        acc[c, ACC_PENETRATION] = pen_max
        acc[c, ACC_BAD] = bad
        acc[c, ACC_BAD_INDEX] = bad_p


@njit(cache=True, inline="always")
def _gather_scalar(field, x, p, origin, inv_dx, ny, nz):
    """sum_i w_ip field[i] at particle p (quadratic B-spline weights)."""
    return _gather_at(field, stencil(x, p, origin, inv_dx), ny, nz)


@njit(cache=True, inline="always")
def _gather_at(field, st, ny, nz):
    """sum_i w_i field[i] over the 27 nodes of the stencil ``st``."""
    total = 0.0
    for a in range(3):
        for b in range(3):
            row = stencil_row(st, a, b, ny, nz)
            total += st.wx[a] * st.wy[b] * (st.wz[0] * field[row] + st.wz[1] * field[row + 1]
                                            + st.wz[2] * field[row + 2])
    return total


@njit(cache=True, inline="always")
def _with_dilatation(C, d_bar, L):
    """L = C with its trace replaced by d_bar (the deviator and the spin of C are kept)."""
    shift = (d_bar - (C[0, 0] + C[1, 1] + C[2, 2])) / 3.0
    for i in range(3):
        for j in range(3):
            L[i, j] = C[i, j]
        L[i, i] += shift


@njit(cache=True, inline="always")
def _det_i_plus(dt, L):
    """det(I + dt L): the volume ratio of one step."""
    a00 = 1.0 + dt * L[0, 0]
    a01 = dt * L[0, 1]
    a02 = dt * L[0, 2]
    a10 = dt * L[1, 0]
    a11 = 1.0 + dt * L[1, 1]
    a12 = dt * L[1, 2]
    a20 = dt * L[2, 0]
    a21 = dt * L[2, 1]
    a22 = 1.0 + dt * L[2, 2]
    return a00 * (a11 * a22 - a12 * a21) - a01 * (a10 * a22 - a12 * a20) + a02 * (a10 * a21 - a11 * a20)


@njit(cache=True, parallel=True)
def elastic_energies(P, table, Z, acc, block):
    """The elastic energy of the active particles, per chunk, as ``g2p_update`` deals them.

    Reads P.stress, P.vol0, P.J and the materials (P.mat_a, mat_b, frac_a, rows of the packed ``table``) of
    the particles Z.p_lo <= p < Z.p_hi; writes acc[c, ACC_ELASTIC] = sum of s:s / (4 G) + p^2 / (2 K) times
    the volume over chunk c's blocks of ``block`` particles (the split of ``g2p_update``, so the sum over the
    chunks is the one it would give). Only the recorded steps need it (the run's energy account), so it is not
    part of the step. Chunk c writes only acc[c]: race-free.
    """
    stress, J, vol0, mat_a, mat_b, frac_a = P.stress, P.J, P.vol0, P.mat_a, P.mat_b, P.frac_a
    p_lo, p_hi = Z.p_lo, Z.p_hi
    n_chunks = acc.shape[0]
    n_blocks = (p_hi - p_lo + block - 1) // block
    for c in prange(n_chunks):
        el_sum = 0.0
        for blk in range(c, n_blocks, n_chunks):
            for p in range(p_lo + blk * block, min(p_lo + (blk + 1) * block, p_hi)):
                vol = vol0[p] * J[p]
                K, G_shear = mixed_moduli(table[mat_a[p]], table[mat_b[p]], frac_a[p])
                el_sum += elastic_energy_density(stress, p, K, G_shear) * vol
        acc[c, ACC_ELASTIC] = el_sum


@njit(cache=True)
def freeze_particles(P, v_grid, table, p_from, p_to):
    """Freeze the particles p_from <= p < p_to as the active zone leaves them behind.

    Reads their P.v, stress, J, vol0, mass, materials and the packed ``table``; zeroes their P.v, P.C and
    v_grid (a frozen particle is at rest and keeps its position and stress). Returns (elastic energy they
    keep, kinetic energy they lose), in J. Serial: a few particles per step.
    """
    v, C, stress = P.v, P.C, P.stress
    elastic = 0.0
    kinetic = 0.0
    for p in range(p_from, p_to):
        K, G = mixed_moduli(table[P.mat_a[p]], table[P.mat_b[p]], P.frac_a[p])
        elastic += elastic_energy_density(stress, p, K, G) * P.vol0[p] * P.J[p]
        kinetic += 0.5 * P.mass[p] * (v[p, 0] * v[p, 0] + v[p, 1] * v[p, 1] + v[p, 2] * v[p, 2])
        for d in range(3):
            v[p, d] = 0.0
            v_grid[p, d] = 0.0
            for e in range(3):
                C[p, d, e] = 0.0
    return elastic, kinetic


def allocate_grid_buffers(n_chunks: int, n_nodes: int) -> np.ndarray:
    return np.zeros((n_chunks, n_nodes, 7))


def allocate_velocity_gradient_scratch(n_chunks: int) -> np.ndarray:
    """Per-chunk 3 x 3 scratch for the projected velocity gradient L_bar in ``g2p_update``, each chunk's on cache
    lines of its own: a (n_chunks, 3, 3) view of a padded array, 256 bytes from one chunk's to the next. Packed
    (72 bytes each), two threads writing their scratch for every particle shared a cache line."""
    return np.zeros((n_chunks, 4, 8))[:, :3, :3]
