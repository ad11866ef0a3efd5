"""Tests of plough.mpm.contact: the rigid sphere on the grid and the interface shear (eq. 8).

A hand-made grid with random nodal masses, velocities and contact stresses is given to
``sphere_contact``; the tests check the rules of the module docstring from the nodal data:
impenetrability of approaching contact nodes (within one cell of the sphere surface or inside it,
carrying a touching particle), untouched separating, non-touching and outside nodes, reaction =
minus the impulses, the traction-limited tangential impulse that never reverses the slip, the
energy account, and the consumption of the contact stress buffer. Single calls start without
contact memory (no node pushed before); separate tests cover the gap-limited approach of nodes
whose closest particle has not reached the sphere yet and the hold (a node pushed within the last
``hold_steps`` steps stays in contact). The surface vector sum_p V_p grad N_i that gives the
shear area is checked against an independent accumulation and, for a flat lattice block, against
the block's top-face area to round-off.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from plough.materials import rigid_plastic
from plough.mpm import contact as ct
from plough.mpm.bundles import ContactLaw, SphereData, grid_of, whole
from plough.mpm.constitutive import pack_materials, rest_flow_stresses
from plough.mpm.grid import Grid
from plough.mpm.particles import particles_of
from plough.mpm.shape import bspline2, bspline2_grad

DX = 1e-5
SHAPE = np.array([12, 11, 13], dtype=np.int64)
ORIGIN = np.array([-4e-5, -5e-5, -6e-5])
NODES = Grid(origin=ORIGIN, dx=DX, shape=tuple(int(s) for s in SHAPE)).node_positions()
N_NODES = NODES.shape[0]
NO_FLAGS = np.zeros(N_NODES, dtype=np.int8)  # every node free (no mirror ghosts)
DT = 1e-3  # large, so that both the traction limit and the stop-the-slip limit occur


def voigt_to_tensor(s):
    return np.array([[s[0], s[5], s[4]], [s[5], s[1], s[3]], [s[4], s[3], s[2]]])


def make_case(seed, centre=None, radius=3.3 * DX):
    """Random grid state and contact buffer; pressure and kappa span many decades."""
    rng = np.random.default_rng(seed)
    if centre is None:
        centre = ORIGIN + DX * (SHAPE - 1) / 2 + rng.uniform(-0.3, 0.3, 3) * DX
    grid_m = rng.uniform(0.5e-3, 1.5e-3, N_NODES)
    grid_m[rng.random(N_NODES) < 0.05] = 0.0
    v_sphere = np.array([0.1, 0.0, -0.02])
    # relative velocities over three decades: slips that the traction stops and slips it only slows
    grid_v = v_sphere + rng.normal(0.0, 1.0, (N_NODES, 3)) * 10.0 ** rng.uniform(-4, -1, N_NODES)[:, None]
    # and a tenth of the nodes approaching the sphere head-on with barely any slip, so that the
    # traction (tau / P times the normal impulse) stops them for every interface law
    slow = rng.random(N_NODES) < 0.1
    outward = NODES[slow] - centre
    outward /= np.linalg.norm(outward, axis=1)[:, None]
    grid_v[slow] = v_sphere - 1e-3 * outward + rng.normal(0.0, 1e-12, (slow.sum(), 3))
    cbuf = np.zeros((N_NODES, ct.N_CBUF))
    w = rng.uniform(0.1, 2.0, N_NODES)
    p0 = 10.0 ** rng.uniform(5, 12, N_NODES) * np.where(rng.random(N_NODES) < 0.15, -1.0, 1.0)
    dev = rng.normal(0.0, 0.2, (N_NODES, 6)) * np.abs(p0)[:, None]
    sig = dev.copy()
    sig[:, :3] -= p0[:, None]  # mostly compressive
    kappa = 10.0 ** rng.uniform(5, 10, N_NODES)
    cbuf[:, :6] = w[:, None] * sig
    cbuf[:, 6] = w * kappa
    cbuf[:, 7] = w
    cbuf[:, 8] = DX * (rng.random(N_NODES) < 0.85)  # proximity DX - gap: a particle of the node touches
    # surface vector sum V grad N: shares of up to a cell face
    cbuf[:, ct.C_AREA:ct.C_AREA + 3] = rng.normal(size=(N_NODES, 3)) * (DX * DX * rng.uniform(0, 0.6, N_NODES))[:, None]
    cbuf[rng.random(N_NODES) < 0.05, :] = 0.0  # nodes no particle reached
    return dict(grid_m=grid_m, grid_v=grid_v, cbuf=cbuf, centre=np.asarray(centre, float), radius=radius,
                v_sphere=v_sphere)


HOLD = 6.0  # steps a node stays in contact after its last push


def no_memory():
    """Contact memory of a first step: no node pushed before (last_push, step, hold_steps)."""
    return np.full(N_NODES, ct.NEVER_PUSHED), 0, HOLD


def run_contact(grid_m, grid_v, cbuf, flags, memory, centre, radius, v_sphere, model, iparams):
    """``sphere_contact`` on this grid with the contact ``memory`` (last_push, step, hold_steps); the reaction."""
    last_push, step, hold_steps = memory
    out = np.zeros(ct.N_OUT)
    G = grid_of(ORIGIN, DX, SHAPE, m=grid_m, v=grid_v, cbuf=cbuf, flags=flags, last_push=last_push)
    ct.sphere_contact(G, SphereData(np.asarray(centre, float), v_sphere, radius, 3 * DX),
                      ContactLaw(model, np.asarray(iparams, float), hold_steps), step, DT, out)
    return out


def call(case, model, iparams):
    grid_v = case["grid_v"].copy()
    cbuf = case["cbuf"].copy()
    out = run_contact(case["grid_m"], grid_v, cbuf, NO_FLAGS, no_memory(), case["centre"], case["radius"],
                      case["v_sphere"], model, iparams)
    return grid_v, cbuf, out


def classify(case):
    rel = case["grid_v"] - case["v_sphere"]
    d = NODES - case["centre"]
    dist = np.linalg.norm(d, axis=1)
    inside = dist < case["radius"] + DX  # the nodes the contact looks at: up to one cell outside
    n = d / np.where(dist > 0, dist, 1.0)[:, None]
    vn = (rel * n).sum(1)
    contact = inside & (case["grid_m"] > 0) & (case["cbuf"][:, 8] > 0) & (vn < 0)
    return inside, contact, n, vn, rel


def expected_tau(model, iparams, pressure, kappa):
    if model == ct.INTERFACE_PROPORTIONAL:
        tau = iparams[0] * kappa
    elif model == ct.INTERFACE_CONSTANT:
        tau = iparams[0]
    else:
        tau = iparams[0] * max(pressure, 0.0) ** iparams[1]
    return min(tau, kappa)


MODELS = [
    (ct.INTERFACE_PROPORTIONAL, [0.6, 0.0]),
    (ct.INTERFACE_CONSTANT, [1.5e8, 0.0]),
    (ct.INTERFACE_BOUNDARY_LAYER, [3.0, 0.95]),  # Cp large enough that some slips stop
]
CENTRES = [None, ORIGIN + DX * np.array([5.2, 4.9, 11.6])]  # inside / straddling the top of the grid


# ----------------------------------------------------------------------------- normal direction
@pytest.mark.parametrize("ci", range(len(CENTRES)))
def test_impenetrability_and_untouched_nodes(ci):
    case = make_case(10 + ci, centre=CENTRES[ci])
    inside, contact, n, vn, _ = classify(case)
    assert contact.sum() >= 10 and (inside & ~contact).sum() >= 10
    # some approaching nodes are left alone only because no touching particle marks them
    assert (inside & (case["grid_m"] > 0) & (vn < 0) & (case["cbuf"][:, 8] == 0)).sum() >= 3
    grid_v, _, out = call(case, *MODELS[0])
    rel_after = grid_v - case["v_sphere"]
    # approaching nodes move with the sphere along the normal
    np.testing.assert_allclose((rel_after[contact] * n[contact]).sum(1), 0.0, atol=1e-15)
    # separating, massless or non-touching nodes near the sphere and all nodes farther out are untouched
    np.testing.assert_array_equal(grid_v[~contact], case["grid_v"][~contact])
    assert out[ct.OUT_NODES] == contact.sum()


# ----------------------------------------------------------------------------- reaction
@pytest.mark.parametrize("model,iparams", MODELS)
def test_reaction_is_minus_the_impulses(model, iparams):
    case = make_case(20 + model)
    _, contact, n, _, _ = classify(case)
    grid_v, _, out = call(case, model, iparams)
    m = case["grid_m"][:, None]
    dmv = m * (grid_v - case["grid_v"])
    dn = (dmv * n).sum(1)[:, None] * n
    dt_part = dmv - dn
    fn = out[ct.OUT_FN:ct.OUT_FN + 3]
    ft = out[ct.OUT_FT:ct.OUT_FT + 3]
    scale = np.abs(dmv).sum() / DT
    np.testing.assert_allclose(fn + ft, -dmv.sum(0) / DT, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(fn, -dn[contact].sum(0) / DT, rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(ft, -dt_part[contact].sum(0) / DT, rtol=0, atol=1e-12 * scale)
    # the sphere pushes the material: the normal reaction points into the sphere (n . F_n <= 0 per node),
    # so its component along the sphere's motion resists pressing
    assert np.all((dn[contact] * n[contact]).sum(1) >= 0.0)


def test_pressing_on_resting_material_gives_upward_normal_force():
    rng = np.random.default_rng(3)
    centre = ORIGIN + DX * np.array([5.5, 5.0, 9.0])
    grid_m = rng.uniform(0.5e-3, 1.5e-3, N_NODES)
    grid_v = np.zeros((N_NODES, 3))
    cbuf = np.zeros((N_NODES, ct.N_CBUF))
    cbuf[:, 8] = DX  # touching, but no stress: kappa = 0
    v_sphere = np.array([0.0, 0.0, -0.05])
    out = run_contact(grid_m, grid_v, cbuf, NO_FLAGS, no_memory(), centre, 3.3 * DX, v_sphere,
                      ct.INTERFACE_PROPORTIONAL, [1.0, 0.0])
    assert out[ct.OUT_FN + 2] > 0  # material pushes the sphere up
    # nodes below the centre move down with the sphere's normal velocity
    below = (np.linalg.norm(NODES - centre, axis=1) < 4.3 * DX) & (NODES[:, 2] < centre[2])
    assert np.all(grid_v[below, 2] < 0)
    # no stress reached the nodes: kappa = 0, so no interface shear at all
    np.testing.assert_array_equal(out[ct.OUT_FT:ct.OUT_FT + 3], 0.0)


# ----------------------------------------------------------------------------- tangential direction
@pytest.mark.parametrize("model,iparams", MODELS)
@pytest.mark.parametrize("ci", range(len(CENTRES)))
def test_tangential_impulse_is_traction_limited_and_never_reverses(model, iparams, ci):
    case = make_case(30 + 3 * model + ci, centre=CENTRES[ci])
    _, contact, n, vn, rel = classify(case)
    grid_v, _, out = call(case, model, iparams)
    rel_after = grid_v - case["v_sphere"]
    m = case["grid_m"]
    cb = case["cbuf"]
    n_limited = n_stopped = 0
    area_xy = 0.0
    for i in np.flatnonzero(contact):
        t_before = rel[i] - vn[i] * n[i]
        t_after = rel_after[i]  # no normal part left
        vt_b, vt_a = np.linalg.norm(t_before), np.linalg.norm(t_after)
        if cb[i, 7] > 0:
            sig = voigt_to_tensor(cb[i, :6] / cb[i, 7])
            pressure = -n[i] @ sig @ n[i]
            kappa = cb[i, 6] / cb[i, 7]
        else:
            pressure = kappa = 0.0
        tau = expected_tau(model, iparams, pressure, kappa)
        assert tau <= kappa * (1 + 1e-15)
        area = np.linalg.norm(cb[i, ct.C_AREA:ct.C_AREA + 3])  # the node's share of the surface
        if n[i][2] < 0:
            area_xy += area * -n[i][2]
        limit = tau * area * DT
        if vt_b < 1e-9:
            # grid_v - v_sphere keeps few digits of such slips: check only that they are stopped or
            # slowed, never grown beyond round-off
            assert vt_a <= vt_b + 1e-15
            n_stopped += bool(vt_a == 0.0 and limit >= m[i] * vt_b)
            continue
        # same direction, smaller magnitude: the slip shrinks and never reverses
        assert vt_a <= vt_b * (1 + 1e-12)
        np.testing.assert_allclose(np.cross(t_before, t_after), 0.0, atol=1e-12 * vt_b * vt_b)
        assert t_before @ t_after >= -1e-15
        jt = m[i] * (vt_b - vt_a)  # loses digits to cancellation when jt << m vt
        tol = 1e-12 * m[i] * vt_b
        assert jt <= limit + tol
        assert jt == pytest.approx(min(m[i] * vt_b, limit), rel=1e-9, abs=tol)
        if limit < m[i] * vt_b:
            n_limited += 1
        elif limit > 0:
            n_stopped += 1
    # both regimes were exercised
    assert n_limited > 0 and n_stopped > 0
    assert out[ct.OUT_AREA_XY] == pytest.approx(area_xy, rel=1e-12)


@pytest.mark.parametrize("held", [False, True], ids=["first-step", "held"])
@pytest.mark.parametrize("model,iparams", MODELS)
def test_energy_account_of_contact(model, iparams, held):
    """The contact's losses are powers at the end-of-step relative velocity: friction times the slip left
    (interface dissipation) and each push times the approach left (impact loss, jn gap / dt where a particle
    face is a gap away). The node's kinetic-energy change is the sphere's work minus those minus |J|^2 / 2m
    per node (in a lasting contact the velocity this step's internal force gave and the push took back, no
    loss: docs/journal/2026-12-02-cfl.md); the identity checks all three terms at once. ``held``: every node was
    pushed on the step before, so a node that now moves away from the sphere is in contact without a push
    (friction only)."""
    case = make_case(40 + model)
    rng = np.random.default_rng(7)
    touching = case["cbuf"][:, 8] > 0
    half = touching & (rng.random(N_NODES) < 0.5)
    case["cbuf"][half, 8] = DX * rng.uniform(0.2, 0.9, half.sum())  # a gap of 0.1-0.8 DX: the push term
    gap = np.maximum(DX - case["cbuf"][:, 8], 0.0)
    inside, _, n, vn, _ = classify(case)
    pushed = inside & (case["grid_m"] > 0) & touching & (vn < -gap / DT)
    grid_v = case["grid_v"].copy()
    memory = (np.zeros(N_NODES, dtype=np.int64), 1, HOLD) if held else no_memory()
    out = run_contact(case["grid_m"], grid_v, case["cbuf"].copy(), NO_FLAGS, memory, case["centre"], case["radius"],
                      case["v_sphere"], model, iparams)
    if held:  # friction on nodes that are held, not pushed
        moved = np.linalg.norm(grid_v - case["grid_v"], axis=1) > 0
        assert (moved & inside & ~pushed).sum() >= 5
    m, v0, vs = case["grid_m"], case["grid_v"], case["v_sphere"]
    J = m[:, None] * (grid_v - v0)
    jn = (J * n).sum(1)
    np.testing.assert_allclose(jn[pushed], m[pushed] * (-gap[pushed] / DT - vn[pushed]), rtol=1e-9)
    rel_after = grid_v - vs
    assert out[ct.OUT_IMPACT] == pytest.approx((jn[pushed] * gap[pushed] / DT).sum(), rel=1e-10)
    assert (gap[pushed] > 0).sum() >= 5 and out[ct.OUT_IMPACT] > 0.0  # the case pushes nodes a gap away
    jt_vec = J - jn[:, None] * n
    slip_after = rel_after - (rel_after * n).sum(1)[:, None] * n
    dissipation = np.linalg.norm(jt_vec, axis=1) * np.linalg.norm(slip_after, axis=1)
    assert out[ct.OUT_DISSIPATION] == pytest.approx(dissipation[inside].sum(), rel=1e-9)
    dke = 0.5 * (m * ((grid_v**2).sum(1) - (v0**2).sum(1))).sum()
    work = (J @ vs).sum()
    assert out[ct.OUT_WORK] == pytest.approx(work, rel=1e-10)
    massive = m > 0
    taken_back = ((J[massive] ** 2).sum(1) / (2 * m[massive])).sum()
    scale = 0.5 * (m * (v0**2).sum(1)).sum()
    assert dke == pytest.approx(out[ct.OUT_WORK] - out[ct.OUT_DISSIPATION] - out[ct.OUT_IMPACT] - taken_back,
                                abs=1e-10 * scale)


def test_contact_buffer_is_consumed_where_the_contact_looks_only():
    """Within the reach every entry is consumed; outside it the stress entries are left alone, and
    the surface vectors are consumed in the box the contact scans (a folded one may land there)."""
    case = make_case(50)
    inside, _, _, _, _ = classify(case)
    _, cbuf, _ = call(case, *MODELS[0])
    np.testing.assert_array_equal(cbuf[inside], 0.0)
    np.testing.assert_array_equal(cbuf[~inside, :ct.C_AREA], case["cbuf"][~inside, :ct.C_AREA])
    reach = case["radius"] + DX
    lo = np.maximum(np.floor((case["centre"] - reach - ORIGIN) / DX), 0)
    hi = np.minimum(np.ceil((case["centre"] + reach - ORIGIN) / DX), SHAPE - 1)
    ijk = np.rint((NODES - ORIGIN) / DX)
    box = np.all((ijk >= lo) & (ijk <= hi), axis=1)
    np.testing.assert_array_equal(cbuf[box, ct.C_AREA:], 0.0)
    np.testing.assert_array_equal(cbuf[~box, ct.C_AREA:], case["cbuf"][~box, ct.C_AREA:])
    assert (~inside & box).sum() > 10 and (~box).sum() > 10


# ----------------------------------------------------------------------------- interface shear
def test_interface_shear_models():
    kappa = 2.0e8
    # proportional: f kappa
    assert ct.interface_shear(ct.INTERFACE_PROPORTIONAL, np.array([0.6, 0.0]), 5e8, kappa) == pytest.approx(1.2e8)
    assert ct.interface_shear(ct.INTERFACE_PROPORTIONAL, np.array([1.0, 0.0]), 5e8, kappa) == pytest.approx(kappa)
    # constant, capped at kappa
    assert ct.interface_shear(ct.INTERFACE_CONSTANT, np.array([1.5e8, 0.0]), 0.0, kappa) == pytest.approx(1.5e8)
    assert ct.interface_shear(ct.INTERFACE_CONSTANT, np.array([3.0e8, 0.0]), 0.0, kappa) == pytest.approx(kappa)
    # boundary layer: Cp P^np with P in Pa (Table 5, zinc: 0.32 P^0.95), capped at kappa
    bl = np.array([0.32, 0.95])
    P = 1.0e8
    assert ct.interface_shear(ct.INTERFACE_BOUNDARY_LAYER, bl, P, kappa) == pytest.approx(0.32 * P**0.95, rel=1e-12)
    assert ct.interface_shear(ct.INTERFACE_BOUNDARY_LAYER, bl, P, 1.0e6) == pytest.approx(1.0e6)
    assert ct.interface_shear(ct.INTERFACE_BOUNDARY_LAYER, bl, -P, kappa) == 0.0  # tension: no shear
    assert ct.interface_shear(ct.INTERFACE_BOUNDARY_LAYER, np.array([1.34, 0.88]), 2.0e9, 1e12) == pytest.approx(
        1.34 * 2.0e9**0.88, rel=1e-12)


# ----------------------------------------------------------------------------- contact stress scatter
def test_scatter_contact_stress_writes_only_nodes_near_the_sphere():
    rng = np.random.default_rng(60)
    centre = ORIGIN + DX * (SHAPE - 1) / 2 + np.array([0.1, -0.2, 0.3]) * DX
    radius = 2.2 * DX
    # particles on a shell around the sphere surface, well inside the grid
    n = 200
    d = rng.normal(size=(n, 3))
    d /= np.linalg.norm(d, axis=1)[:, None]
    # upper half: some particles touch the sphere; lower half: none does (nodes there get no flag)
    shell = np.where(d[:, 2] > 0, rng.uniform(0.7, 1.3, n), rng.uniform(1.25, 1.6, n))
    x = centre + d * radius * shell[:, None]
    stress = rng.normal(0.0, 1e8, (n, 6))
    mass = rng.uniform(1e-4, 2e-4, n)
    vol0 = np.full(n, (0.5 * DX) ** 3)
    J = rng.uniform(0.8, 1.2, n)
    eps_p = np.zeros(n)
    temperature = np.full(n, 298.0)
    table = pack_materials([rigid_plastic("coat", 450e6, coating=True), rigid_plastic("sub", 900e6, coating=False)])
    mat_a = np.where(rng.random(n) < 0.5, 0, 1).astype(np.int32)
    mat_b = np.ones(n, dtype=np.int32)
    frac_a = np.where(rng.random(n) < 0.3, 0.4, 1.0)
    near = (rng.random(n) < 0.7).astype(np.int8)
    cbuf = np.zeros((N_NODES, ct.N_CBUF))
    sigma_y0 = np.zeros(n)
    rest_flow_stresses(eps_p, temperature, mat_a, mat_b, frac_a, table, sigma_y0)
    P = particles_of(n, x=x, stress=stress, mass=mass, vol0=vol0, J=J, sigma_y0=sigma_y0, near=near)
    ct.scatter_contact_stress(P, grid_of(ORIGIN, DX, SHAPE, cbuf=cbuf), SphereData(centre, np.zeros(3), radius, 3 * DX),
                              whole(n, SHAPE), False)
    # independent accumulation
    sy = np.array([450e6 / 3, 900e6 / 3])
    kappa = (frac_a * sy[mat_a] + (1 - frac_a) * sy[mat_b]) / math.sqrt(3.0)
    gap = np.linalg.norm(x - centre, axis=1) - radius - 0.5 * np.cbrt(vol0 * J)
    touching = gap <= 0.0
    assert 0 < (touching & (near == 1)).sum() < (near == 1).sum()
    expected = np.zeros_like(cbuf)
    reach = np.linalg.norm(NODES - centre, axis=1) < radius + DX
    nz, ny = SHAPE[2], SHAPE[1]
    for p in np.flatnonzero(near):
        g = (x[p] - ORIGIN) / DX
        stencil = [bspline2(gd) for gd in g]
        slopes = [bspline2_grad(gd) for gd in g]  # per grid unit
        for a in range(3):
            for b in range(3):
                for c in range(3):
                    i, j, k = stencil[0][0] + a, stencil[1][0] + b, stencil[2][0] + c
                    node = (i * ny + j) * nz + k
                    if not reach[node]:
                        continue
                    w = stencil[0][1 + a] * stencil[1][1 + b] * stencil[2][1 + c] * mass[p]
                    expected[node, :6] += w * stress[p]
                    expected[node, 6] += w * kappa[p]
                    expected[node, 7] += w
                    expected[node, 8] = max(expected[node, 8], DX - gap[p])
                    wx, wy, wz = stencil[0][1 + a], stencil[1][1 + b], stencil[2][1 + c]
                    dwx, dwy, dwz = slopes[0][1 + a], slopes[1][1 + b], slopes[2][1 + c]
                    v = vol0[p] * J[p] / DX
                    grad = np.array([dwx * wy * wz, wx * dwy * wz, wx * wy * dwz])
                    expected[node, ct.C_AREA:ct.C_AREA + 3] += v * grad
    np.testing.assert_array_equal(cbuf[~reach], 0.0)
    assert (cbuf[reach, 7] > 0).sum() > 10
    assert 0 < (cbuf[reach, 8] >= DX).sum() < (cbuf[reach, 8] > 0).sum() <= (cbuf[reach, 7] > 0).sum()
    np.testing.assert_allclose(cbuf, expected, rtol=1e-12, atol=1e-12 * np.abs(expected).max())


# ----------------------------------------------------------------------------- gap and contact memory
def one_node_case(rel_velocity_n, rel_velocity_t, prox, kappa=1.0e8, pressure=3.0e8, area=0.5 * DX * DX):
    """A single massive node just under the sphere; relative velocity given along n and one tangent;
    its surface vector points up (out of the material, towards the sphere) with |g| = area."""
    centre = ORIGIN + DX * np.array([5.0, 5.0, 9.0])
    radius = 3.0 * DX
    node = (5 * SHAPE[1] + 5) * SHAPE[2] + 6  # straight below the centre, on the sphere surface
    n = np.array([0.0, 0.0, -1.0])
    t = np.array([1.0, 0.0, 0.0])
    v_sphere = np.array([0.1, 0.0, -0.01])
    grid_m = np.zeros(N_NODES)
    grid_m[node] = 1e-6
    grid_v = np.zeros((N_NODES, 3))
    grid_v[node] = v_sphere + rel_velocity_n * n + rel_velocity_t * t
    cbuf = np.zeros((N_NODES, ct.N_CBUF))
    cbuf[node, :3] = -pressure  # isotropic compression: P = pressure along any normal
    cbuf[node, 6] = kappa
    cbuf[node, 7] = 1.0
    cbuf[node, 8] = prox
    cbuf[node, ct.C_AREA + 2] = area  # the material below: outward normal up, towards the sphere
    return dict(node=node, centre=centre, radius=radius, n=n, t=t, v_sphere=v_sphere, grid_m=grid_m, grid_v=grid_v,
                cbuf=cbuf)


def call_with_memory(c, last_push, step, hold_steps, f=1.0):
    grid_v = c["grid_v"].copy()
    out = run_contact(c["grid_m"], grid_v, c["cbuf"].copy(), NO_FLAGS, (last_push, step, hold_steps), c["centre"],
                      c["radius"], c["v_sphere"], ct.INTERFACE_PROPORTIONAL, [f, 0.0])
    rel = grid_v[c["node"]] - c["v_sphere"]
    return rel @ c["n"], rel @ c["t"], out


def test_node_may_approach_by_its_closest_particles_gap():
    gap = 0.3 * DX
    # approaching at twice the speed that closes the gap in one step: held to closing it exactly
    c = one_node_case(-2.0 * gap / DT, 0.0, prox=DX - gap)
    vn, _, out = call_with_memory(c, *no_memory())
    assert vn == pytest.approx(-gap / DT, rel=1e-12)
    assert out[ct.OUT_FN + 2] == pytest.approx(c["grid_m"][c["node"]] * gap / DT / DT, rel=1e-12)
    # approaching slower than that: free, no force
    c = one_node_case(-0.5 * gap / DT, 0.0, prox=DX - gap)
    vn, _, out = call_with_memory(c, *no_memory())
    assert vn == pytest.approx(-0.5 * gap / DT, rel=1e-12)
    assert out[ct.OUT_NODES] == 0 and np.all(out[ct.OUT_FN:ct.OUT_FN + 3] == 0.0)
    # no particle within a cell of the sphere (proximity 0): never in contact
    c = one_node_case(-10.0 * DX / DT, 0.0, prox=0.0)
    vn, _, out = call_with_memory(c, *no_memory())
    assert vn == pytest.approx(-10.0 * DX / DT) and out[ct.OUT_NODES] == 0


def test_held_node_keeps_interface_shear_while_separating_until_the_hold_ends():
    kappa, step, hold = 1.0e8, 40, 6.0
    slip = 100.0  # m/s: far more than the traction can stop in one step (DT is large)
    area = 0.37 * DX * DX
    c = one_node_case(+1e-3, slip, prox=DX, kappa=kappa, area=area)  # separating this step
    node = c["node"]
    m = c["grid_m"][node]
    last = np.full(N_NODES, ct.NEVER_PUSHED)
    for since in (1, 3, 6):  # pushed this many steps ago: within the hold
        last[node] = step - since
        vn, vt, out = call_with_memory(c, last, step, hold)
        assert vn == pytest.approx(1e-3, rel=1e-9)  # the normal velocity is left alone
        assert m * (slip - vt) == pytest.approx(kappa * area * DT, rel=1e-9)  # tau = f kappa over the surface share
        assert last[node] == step - since  # not pushed now: the memory keeps the last push
        assert out[ct.OUT_NODES] == 1 and np.all(out[ct.OUT_FN:ct.OUT_FN + 3] == 0.0)
        assert out[ct.OUT_FT + 0] == pytest.approx(kappa * area, rel=1e-9)  # the shear force on the sphere
    # pushed longer ago than the hold: released, untouched
    last[node] = step - 7
    vn, vt, out = call_with_memory(c, last, step, hold)
    assert vt == pytest.approx(slip, rel=1e-12) and out[ct.OUT_NODES] == 0 and last[node] == step - 7
    # never pushed: a separating node is not in contact
    last[node] = ct.NEVER_PUSHED
    vn, vt, out = call_with_memory(c, last, step, hold)
    assert vt == pytest.approx(slip, rel=1e-12) and out[ct.OUT_NODES] == 0
    # pushed now: in contact and remembered
    c = one_node_case(-1e-3, slip, prox=DX, kappa=kappa, area=area)
    vn, vt, out = call_with_memory(c, last, step, hold)
    assert last[node] == step and out[ct.OUT_NODES] == 1 and vn == pytest.approx(0.0, abs=1e-12)


def test_a_ringing_node_carries_the_same_shear_on_every_step():
    """Pushed every third step (the contact rings), the node's interface shear does not switch off in
    between: the shear area is the surface share, not the step's normal impulse."""
    slip, area, kappa = 100.0, 0.5 * DX * DX, 1.0e8
    pushed = one_node_case(-2e-4, slip, prox=DX, kappa=kappa, area=area)
    resting = one_node_case(+1e-9, slip, prox=DX, kappa=kappa, area=area)
    node = pushed["node"]
    last = np.full(N_NODES, ct.NEVER_PUSHED)
    shear = []
    for step in range(30):
        _, _, out = call_with_memory(pushed if step % 3 == 0 else resting, last, step, HOLD)
        shear.append(out[ct.OUT_FT + 0])
        assert last[node] == step - step % 3
    np.testing.assert_allclose(shear, kappa * area, rtol=1e-9)


# ----------------------------------------------------------------------------- the surface vector
def _lattice(lo, hi, h):
    """Particle centres of a block [lo, hi] (grid units of DX) filled with cubes of edge h (grid units)."""
    axes = [np.arange(lo[d] + 0.5 * h, hi[d], h) for d in range(3)]
    g = np.stack(np.meshgrid(*axes, indexing="ij"), axis=-1).reshape(-1, 3)
    return ORIGIN + g * DX


def _scatter_block(x, h, centre, radius, mirror_j0=-1):
    """The contact buffer of lattice particles x (cubes of edge h grid units, unstressed, all near)."""
    n = x.shape[0]
    ones = np.ones(n)
    sigma_y0 = np.zeros(n)
    rest_flow_stresses(np.zeros(n), np.full(n, 298.0), np.zeros(n, dtype=np.int32), np.zeros(n, dtype=np.int32), ones,
                       pack_materials([rigid_plastic("sub", 900e6, coating=False)]), sigma_y0)
    G = grid_of(ORIGIN, DX, SHAPE, mirror_j0=mirror_j0)
    P = particles_of(n, x=x, vol0=np.full(n, (h * DX) ** 3), sigma_y0=sigma_y0, near=np.ones(n, dtype=np.int8))
    ct.scatter_contact_stress(P, G, SphereData(np.asarray(centre), np.zeros(3), radius, 3 * DX), whole(n, SHAPE), False)
    return G.cbuf


def _scatter_surface(x, h, mirror_j0=-1):
    # a sphere so large that every node is within its reach: the whole surface vector field is written
    cbuf = _scatter_block(x, h, ORIGIN + DX * (SHAPE - 1) / 2, 1.0, mirror_j0)
    return cbuf[:, ct.C_AREA:ct.C_AREA + 3].reshape(*SHAPE, 3)


@pytest.mark.parametrize("h", [0.5, 1.0 / 3.0])
def test_surface_vector_gives_the_top_face_area_of_a_flat_block_exactly(h):
    """Block [2, 9] x [2, 9] x [2, 10] cells. The nodes k >= 7 see the top face only: the sum of the
    z components there is the face's area (7 x 7 cells) to round-off: the particles' midpoint rule
    integrates the B-spline derivatives exactly on these node-symmetric lattices (2 and 3 particles
    per cell); the whole field sums to zero (partition of unity)."""
    g = _scatter_surface(_lattice([2, 2, 2], [9, 9, 10], h), h)
    area = 49.0 * DX * DX
    assert g[:, :, 7:, 2].sum() == pytest.approx(area, rel=1e-12)
    np.testing.assert_allclose(g[:, :, 7:, :2].sum(axis=(0, 1, 2)), 0.0, atol=1e-12 * area)
    np.testing.assert_allclose(g.sum(axis=(0, 1, 2)), 0.0, atol=1e-12 * area)
    # inside the block, away from every face, the shares vanish
    np.testing.assert_allclose(g[4:8, 4:8, 4:6], 0.0, atol=1e-12 * area)
    # and the top face's nodes point up: out of the material
    assert np.all(g[4:8, 4:8, 9:, 2] >= -1e-12 * area)


def test_surface_vector_mirror_fold_equals_the_full_block():
    """A block symmetric about the node plane y = 0 (j = 5) against its half y > 0 with the fold: on the
    nodes j > 5 the half gives the full block's vectors; on the plane its own particles give half of
    the full block's x and z components (the half body's share)."""
    j0 = 5
    assert ORIGIN[1] + j0 * DX == pytest.approx(0.0, abs=1e-20)
    h = 0.5
    full = _scatter_surface(_lattice([2, 2, 2], [9, 8, 10], h), h)
    half = _scatter_surface(_lattice([2, 5, 2], [9, 8, 10], h), h, mirror_j0=j0)
    scale = DX * DX
    np.testing.assert_allclose(half[:, j0 + 1:], full[:, j0 + 1:], rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(half[:, j0, :, 0::2], 0.5 * full[:, j0, :, 0::2], rtol=0, atol=1e-12 * scale)
    np.testing.assert_allclose(full[:, j0, :, 1], 0.0, atol=1e-12 * scale)  # symmetric: no y share on the plane
    assert np.abs(full[:, j0 + 1:]).max() > 0.1 * scale  # the comparison is not between zeros


@pytest.mark.parametrize("centre_y", [0.0, -0.3 * DX])
def test_contact_consumes_every_folded_surface_vector(centre_y):
    """scatter_contact_stress with the mirror fold, then sphere_contact: the contact buffer is all
    zero afterwards, also where a folded vector lands on a partner node outside the reach (a centre
    off the mirror plane makes the ghost and its partner lie at different distances)."""
    from plough.mpm.grid import GHOST, MIRROR

    j0, h = 5, 0.5
    radius = 3.3 * DX
    centre = np.array([ORIGIN[0] + 5.0 * DX, centre_y, ORIGIN[2] + (10.0 - 0.3) * DX + radius])
    cbuf = _scatter_block(_lattice([2, 5, 2], [9, 8, 10], h), h, centre, radius, j0)
    assert np.abs(cbuf[:, ct.C_AREA:]).max() > 0.1 * DX * DX  # the sphere reaches the block's surface
    j = (np.arange(N_NODES) // SHAPE[2]) % SHAPE[1]
    flags = np.where(j < j0, GHOST, np.where(j == j0, MIRROR, 0)).astype(np.int8)
    run_contact(np.ones(N_NODES), np.zeros((N_NODES, 3)), cbuf, flags, no_memory(), centre, radius,
                np.array([0.1, 0.0, 0.0]), ct.INTERFACE_PROPORTIONAL, [1.0, 0.0])
    np.testing.assert_array_equal(cbuf, 0.0)


def test_ray_local_proximity_is_the_stencils_for_the_particles_on_the_nodes_ray():
    """grid_local (``ray_local``): a node's proximity comes from the particles within half a cell of its ray from
    the sphere's centre, so it never exceeds the whole stencil's, is the stencil's where the closest particle lies
    on the ray, and the stress, strength, mass and surface channels are the same."""
    h = 0.5
    radius = 3.3 * DX
    centre = np.array([ORIGIN[0] + 5.2 * DX, ORIGIN[1] + 4.9 * DX, ORIGIN[2] + (10.0 - 0.3) * DX + radius])
    x = _lattice([2, 2, 2], [9, 9, 10], h)
    n = x.shape[0]
    G = {}
    for local in (False, True):
        G[local] = grid_of(ORIGIN, DX, SHAPE)
        P = particles_of(n, x=x, vol0=np.full(n, (h * DX) ** 3), near=np.ones(n, dtype=np.int8))
        ct.scatter_contact_stress(P, G[local], SphereData(centre, np.zeros(3), radius, 3 * DX), whole(n, SHAPE), local)
    full, local = G[False].cbuf, G[True].cbuf
    others = [k for k in range(ct.N_CBUF) if k != 8]
    np.testing.assert_array_equal(local[:, others], full[:, others])
    assert np.all(local[:, 8] <= full[:, 8])
    assert np.any(local[:, 8] < full[:, 8]) and np.any((local[:, 8] == full[:, 8]) & (full[:, 8] > 0))


# ----------------------------------------------------------------------------- the shear split (diagnostics)
@pytest.mark.parametrize("model,iparams", MODELS)
@pytest.mark.parametrize("ci", range(len(CENTRES)))
def test_shear_split_adds_up_and_matches_the_nodes(model, iparams, ci):
    """The diagnostic channels (OUT_SH_AREA on): the regions' areas, shear forces, projected areas and normal
    forces add up to the totals, and each region, the stuck and the outside nodes match a classification made
    here from the nodal data (front: n_x > 0; up: the sphere's surface on the node's ray above z = 0)."""
    case = make_case(60 + 3 * model + ci, centre=CENTRES[ci])
    _, contact, n, vn, rel = classify(case)
    grid_v, _, out = call(case, model, iparams)
    m, cb, c, r = case["grid_m"], case["cbuf"], case["centre"], case["radius"]
    area = np.linalg.norm(cb[:, ct.C_AREA:ct.C_AREA + 3], axis=1)
    t_before = rel - vn[:, None] * n
    fx = m * (t_before[:, 0] - (grid_v - case["v_sphere"])[:, 0]) / DT  # minus the x impulse, per unit time
    fz = m * vn * n[:, 2] / DT  # the normal impulse -m vn along n, on the sphere
    region = np.where(n[:, 0] > 0, ct.REGION_FRONT, ct.REGION_REAR) + 2 * (c[2] + r * n[:, 2] > 0)
    for reg in range(ct.N_REGIONS):
        sel = contact & (region == reg)
        assert out[ct.OUT_REGION_AREA + reg] == pytest.approx(area[sel].sum(), rel=1e-12, abs=1e-30)
        assert out[ct.OUT_REGION_FX + reg] == pytest.approx(fx[sel].sum(), rel=1e-6, abs=1e-12)
        xy = sel & (n[:, 2] < 0)
        assert out[ct.OUT_REGION_AREA_XY + reg] == pytest.approx((area * -n[:, 2])[xy].sum(), rel=1e-12, abs=1e-30)
        assert out[ct.OUT_REGION_FZ + reg] == pytest.approx(fz[sel].sum(), rel=1e-9, abs=1e-12)
    regions = slice(0, ct.N_REGIONS)
    assert out[ct.OUT_REGION_AREA:][regions].sum() == pytest.approx(out[ct.OUT_SH_AREA], rel=1e-12)
    assert out[ct.OUT_REGION_FX:][regions].sum() == pytest.approx(out[ct.OUT_FT], rel=1e-12, abs=1e-15)
    assert out[ct.OUT_REGION_AREA_XY:][regions].sum() == pytest.approx(out[ct.OUT_AREA_XY], rel=1e-12)
    assert out[ct.OUT_REGION_FZ:][regions].sum() == pytest.approx(out[ct.OUT_FN + 2], rel=1e-12)
    # both halves and both sides of the original surface occur over the two centres
    assert (out[ct.OUT_REGION_AREA:][regions] > 0).sum() >= 2
    outside = contact & (np.linalg.norm(NODES - c, axis=1) > r)
    assert out[ct.OUT_OUTSIDE_AREA] == pytest.approx(area[outside].sum(), rel=1e-12, abs=1e-30)
    assert out[ct.OUT_OUTSIDE_FX] == pytest.approx(fx[outside].sum(), rel=1e-6, abs=1e-12)
    # stuck: the slip stopped (the impulse m v_t within the traction bound); every subset within the total
    assert 0.0 < out[ct.OUT_STUCK_AREA] < out[ct.OUT_SH_AREA]
    for a, f in ((ct.OUT_STUCK_AREA, ct.OUT_STUCK_FX), (ct.OUT_CARRIED_AREA, ct.OUT_CARRIED_FX),
                 (ct.OUT_OUTSIDE_AREA, ct.OUT_OUTSIDE_FX), (ct.OUT_GAP_AREA, ct.OUT_GAP_FX),
                 (ct.OUT_LATERAL_AREA, ct.OUT_LATERAL_FX)):
        assert 0.0 <= out[a] <= out[ct.OUT_SH_AREA] * (1 + 1e-12)
        assert abs(out[f]) <= np.abs(fx[contact]).sum() * (1 + 1e-9)


def test_held_traction_starts_afresh_and_averages_over_the_hold():
    """A node's held traction: a fresh contact takes this step's traction; within the contact each step moves
    the average 1 / hold_steps of the way to this step's traction (0 on a held step without a push)."""
    cbuf = np.zeros((2, ct.N_CBUF))
    cbuf[1, ct.C_TRACTION] = 5.0  # a stale value from an earlier contact of another node
    ct.held_traction(cbuf, 0, 100.0, True, 4.0)
    assert cbuf[0, ct.C_TRACTION] == 100.0
    ct.held_traction(cbuf, 0, 0.0, False, 4.0)  # held, not pushed
    assert cbuf[0, ct.C_TRACTION] == 75.0
    ct.held_traction(cbuf, 0, 100.0, False, 4.0)
    assert cbuf[0, ct.C_TRACTION] == 81.25
    ct.held_traction(cbuf, 1, 20.0, True, 4.0)  # a new contact forgets the stale value
    assert cbuf[1, ct.C_TRACTION] == 20.0
    ct.held_traction(cbuf, 0, 50.0, False, 0.5)  # a hold under one step: this step's traction
    assert cbuf[0, ct.C_TRACTION] == 50.0
    assert np.all(cbuf[:, : ct.C_TRACTION] == 0.0)  # the scratch channels are not touched
