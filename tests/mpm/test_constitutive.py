"""Tests of plough.mpm.constitutive: flow stress (eqs. 7.1-7.3), radial return (6.1), heating (6.2).

Expected values are computed here in plain Python from the dataclass fields (never by calling a
kernel twice), so a wrong formula, unit, index or sign in the kernels makes these tests fail.
"""

from __future__ import annotations

import math
from dataclasses import replace

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from plough.materials import (
    BOLTZMANN_EV_PER_K,
    DX56,
    ZINC_BULK,
    ZINC_COATING,
    BergstromVanLiempt,
    CoatingPowerLaw,
    ConstantFlow,
    JohnsonCook,
    Material,
    rigid_plastic,
)
from plough.mpm import constitutive as c
from plough.mpm.bundles import MaterialData
from plough.mpm.particles import particles_of

RIGID = rigid_plastic("rp_substrate", 900e6, coating=False)
MATERIALS = {"constant": RIGID, "bvl": DX56, "jc": ZINC_BULK, "power": ZINC_COATING}
T_ROOM = 298.0


# ----------------------------------------------------------------------------- reference formulas
def expected_flow(mat: Material, eps: float, rate: float, T: float) -> float:
    """Closed forms of model.md section 2, written independently of the kernels."""
    f = mat.flow
    if isinstance(f, ConstantFlow):
        return f.sigma_y_Pa
    if isinstance(f, BergstromVanLiempt):
        e = eps + f.eps0
        s = f.sigma_f0_Pa + f.dsigma_m_Pa * (f.beta * e + (1.0 - math.exp(-f.omega * e)) ** f.c)
        if rate > 0.0:
            x = 1.0 + BOLTZMANN_EV_PER_K * T / f.dG0_eV * math.log(rate / f.rate0_per_s)
            s += f.sigma_v0_Pa * max(0.0, x) ** f.m
        return s
    if isinstance(f, JohnsonCook):
        theta = min(max((T - f.T0_K) / (f.Tm_K - f.T0_K), 0.0), 1.0)
        rate_factor = 1.0 + f.C * math.log(max(rate, f.rate0_per_s) / f.rate0_per_s)
        return (f.A_Pa + f.B_Pa * eps**f.p) * rate_factor * (1.0 - theta**f.q)
    if isinstance(f, CoatingPowerLaw):
        return f.sigma_y0_Pa * (1.0 + f.E_Pa * eps / f.sigma_y0_Pa) ** f.n
    raise TypeError(f)


def rest(prm_a: np.ndarray, prm_b: np.ndarray, frac_a: float, eps_p: np.ndarray, temp: np.ndarray) -> np.ndarray:
    """The flow stress at rest of a one-particle state, the cache ``update_stress`` reads and keeps."""
    return np.array([c.mixed_flow_stress(prm_a, prm_b, frac_a, eps_p[0], 0.0, temp[0])])


def one_particle_step(stress, L, dt, J, eps_p, temp, sy0, deps_last, prm_a, prm_b, frac_a, rate_scale, tq):
    """``update_stress`` of a one-particle state of materials prm_a / prm_b; its arrays are updated in place."""
    P = particles_of(1, stress=stress, J=np.array([J], dtype=float), eps_p=eps_p, temperature=temp, sigma_y0=sy0,
                     deps_last=deps_last, mat_b=np.ones(1, dtype=np.int32), frac_a=np.array([frac_a], dtype=float))
    return c.update_stress(P, 0, L, dt, MaterialData(np.stack([prm_a, prm_b]), rate_scale, tq))


def von_mises(row: np.ndarray) -> float:
    s = np.array(row[:3]) - row[:3].mean()
    return math.sqrt(1.5 * (s @ s + 2.0 * (row[3] ** 2 + row[4] ** 2 + row[5] ** 2)))


def pressure(row: np.ndarray) -> float:
    return -float(row[:3].mean())


def voigt(m: np.ndarray) -> np.ndarray:
    return np.array([m[0, 0], m[1, 1], m[2, 2], m[1, 2], m[0, 2], m[0, 1]])


def tensor(v: np.ndarray) -> np.ndarray:
    return np.array([[v[0], v[5], v[4]], [v[5], v[1], v[3]], [v[4], v[3], v[2]]])


def drive(mat: Material, L: np.ndarray, dt: float, nsteps: int, rate_scale: float, tq: float):
    """Drive one pure particle with a constant velocity gradient; return per-step histories."""
    prm = c.pack_material(mat)
    stress = np.zeros((1, 6))
    eps_p = np.zeros(1)
    temp = np.full(1, T_ROOM)
    sy0 = rest(prm, prm, 1.0, eps_p, temp)  # carried through the steps: update_stress keeps it current
    deps_last = np.zeros(1)  # so is the return map's starting guess
    F = np.eye(3)
    step = np.eye(3) + dt * L
    hist = {k: [] for k in ("vm", "eps_p", "deps", "w", "T_before", "T_after", "J")}
    for _ in range(nsteps):
        F = step @ F
        J = float(np.linalg.det(F))
        T_before = float(temp[0])
        deps, w = one_particle_step(stress, L, dt, J, eps_p, temp, sy0, deps_last, prm, prm, 1.0, rate_scale, tq)
        assert sy0[0] == c.flow_stress(prm, float(eps_p[0]), 0.0, float(temp[0]))  # the cache stays exact
        hist["vm"].append(von_mises(stress[0]))
        hist["eps_p"].append(float(eps_p[0]))
        hist["deps"].append(deps)
        hist["w"].append(w)
        hist["T_before"].append(T_before)
        hist["T_after"].append(float(temp[0]))
        hist["J"].append(J)
    out = {k: np.array(v) for k, v in hist.items()}
    out["stress"] = stress[0].copy()
    return out


# ----------------------------------------------------------------------------- packing
def test_pack_layout() -> None:
    table = c.pack_materials(list(MATERIALS.values()))
    assert table.shape == (4, c.N_MAT_PARAMS) and table.dtype == np.float64
    codes = [c.FLOW_CONSTANT, c.FLOW_BVL, c.FLOW_JC, c.FLOW_POWER]
    for row, mat, code in zip(table, MATERIALS.values(), codes, strict=True):
        assert row[c.I_MODEL] == code
        assert row[c.I_K] == pytest.approx(
            mat.youngs_modulus_Pa / (3 * (1 - 2 * mat.poisson_ratio))
        )
        assert row[c.I_G] == pytest.approx(mat.youngs_modulus_Pa / (2 * (1 + mat.poisson_ratio)))
        assert row[c.I_RHO] == mat.density_kg_m3
        assert row[c.I_CP] == mat.heat_capacity_J_kgK
    np.testing.assert_array_equal(table[1], c.pack_material(DX56))
    assert table[0, c.I_SIGMA_Y] == 300e6
    assert table[1, c.I_BVL_RATE0] == 1e8 and table[1, c.I_BVL_DG0] == 0.8
    assert table[2, c.I_JC_TM] == 692.68 and table[3, c.I_PL_N] == 0.14


# ----------------------------------------------------------------------------- flow stress
FLOW_POINTS = [
    (0.0, 0.0, T_ROOM),
    (0.0, 1e-3, T_ROOM),
    (0.05, 0.5, T_ROOM),  # JC: below rate0 -> no rate term
    (0.3, 10.0, 350.0),
    (1.2, 1e4, 500.0),
    (2.0, 1e6, 800.0),  # JC: above Tm -> zero
    (0.1, -1.0, 250.0),  # negative rate, JC: T below T0 -> no softening
]


@pytest.mark.parametrize("name", MATERIALS)
@pytest.mark.parametrize(("eps", "rate", "T"), FLOW_POINTS)
def test_flow_stress_closed_forms(name: str, eps: float, rate: float, T: float) -> None:
    mat = MATERIALS[name]
    prm = c.pack_material(mat)
    got = c.flow_stress(prm, eps, rate, T)
    assert got == pytest.approx(expected_flow(mat, eps, rate, T), rel=1e-13, abs=1e-6)
    assert c.flow_stress_slopes(prm, eps, rate, T)[0] == pytest.approx(got, rel=1e-13, abs=1e-6)


def test_flow_stress_literal_values() -> None:
    """A few values worked out by hand from Tables 2-4."""
    assert c.flow_stress(c.pack_material(RIGID), 0.7, 1e3, 900.0) == 300e6
    assert c.flow_stress(c.pack_material(ZINC_COATING), 0.0, 0.0, T_ROOM) == pytest.approx(85e6)
    # coating at eps = 85e6 / 80e9: sigma = 85 MPa * 2^0.14
    assert c.flow_stress(c.pack_material(ZINC_COATING), 85e6 / 80e9, 0.0, T_ROOM) == pytest.approx(
        85e6 * 2.0**0.14, rel=1e-14
    )
    # bulk zinc at eps = 1, rate = rate0 * e, T = T0: (A + B)(1 + C)
    assert c.flow_stress(c.pack_material(ZINC_BULK), 1.0, math.e, 298.0) == pytest.approx(
        (82.51e6 + 288.34e6) * 1.0202, rel=1e-13
    )
    # DX56 at rate 0 and eps = 0: sigma_f0 + dsigma_m (beta eps0 + (1 - exp(-omega eps0))^c)
    sig = 82.988e6 + 279.436e6 * (0.482 * 0.005 + (1 - math.exp(-6.69 * 0.005)) ** 0.5)
    assert c.flow_stress(c.pack_material(DX56), 0.0, 0.0, T_ROOM) == pytest.approx(sig, rel=1e-14)
    # DX56 thermal term switched off where 1 + kT/dG0 ln(rate/rate0) <= 0
    assert c.flow_stress(c.pack_material(DX56), 0.0, 1e-12, T_ROOM) == pytest.approx(sig, rel=1e-14)


def test_unknown_model_gives_nan() -> None:
    prm = c.pack_material(DX56)
    prm[c.I_MODEL] = 7.0
    assert math.isnan(c.flow_stress(prm, 0.1, 1.0, T_ROOM))
    assert all(math.isnan(v) for v in c.flow_stress_slopes(prm, 0.1, 1.0, T_ROOM))


SLOPE_POINTS = [(0.02, 2.0, T_ROOM), (0.3, 50.0, 400.0), (1.5, 3e3, 320.0)]


@pytest.mark.parametrize("name", MATERIALS)
@pytest.mark.parametrize(("eps", "rate", "T"), SLOPE_POINTS)
def test_slopes_against_central_differences(name: str, eps: float, rate: float, T: float) -> None:
    mat = MATERIALS[name]
    prm = c.pack_material(mat)
    _, dse, dsr = c.flow_stress_slopes(prm, eps, rate, T)
    he = 1e-6 * eps
    fd_e = (expected_flow(mat, eps + he, rate, T) - expected_flow(mat, eps - he, rate, T)) / (
        2 * he
    )
    hr = 1e-6 * rate
    fd_r = (expected_flow(mat, eps, rate + hr, T) - expected_flow(mat, eps, rate - hr, T)) / (
        2 * hr
    )
    assert dse == pytest.approx(fd_e, rel=1e-6, abs=1e-3)
    assert dsr == pytest.approx(fd_r, rel=1e-6, abs=1e-9)
    if name in ("bvl", "jc"):
        assert dsr > 0.0
    if name != "constant":
        assert dse > 0.0


def test_slopes_finite_at_zero_strain() -> None:
    bvl0 = replace(DX56, flow=replace(DX56.flow, eps0=0.0))
    for mat in (*MATERIALS.values(), bvl0):
        for rate in (0.0, 1e-3, 1.0, 1e5):
            vals = c.flow_stress_slopes(c.pack_material(mat), 0.0, rate, T_ROOM)
            assert all(math.isfinite(v) for v in vals), (mat.name, rate, vals)
    # eps^p with p < 1: a very large but finite slope at eps = 0
    assert c.flow_stress_slopes(c.pack_material(ZINC_BULK), 0.0, 1.0, T_ROOM)[1] > 1e15
    assert c.flow_stress_slopes(c.pack_material(bvl0), 0.0, 1.0, T_ROOM)[1] > 1e15


def test_mixed_flow_stress_and_moduli() -> None:
    a, b = c.pack_material(ZINC_COATING), c.pack_material(DX56)
    eps, rate, T = 0.2, 5.0, 310.0
    sa, sb = expected_flow(ZINC_COATING, eps, rate, T), expected_flow(DX56, eps, rate, T)
    assert c.mixed_flow_stress(a, b, 0.5, eps, rate, T) == pytest.approx(0.5 * (sa + sb), rel=1e-13)
    assert c.mixed_flow_stress(a, b, 0.25, eps, rate, T) == pytest.approx(
        0.25 * sa + 0.75 * sb, rel=1e-13
    )
    s_mix, e_mix, r_mix = c.mixed_flow_stress_slopes(a, b, 0.5, eps, rate, T)
    _, ea, ra = c.flow_stress_slopes(a, eps, rate, T)
    _, eb, rb = c.flow_stress_slopes(b, eps, rate, T)
    assert s_mix == pytest.approx(0.5 * (sa + sb), rel=1e-13)
    assert (e_mix, r_mix) == pytest.approx((0.5 * (ea + eb), 0.5 * (ra + rb)), rel=1e-13)
    K, G = c.mixed_moduli(a, b, 0.5)
    assert K == pytest.approx(0.5 * (ZINC_COATING.bulk_modulus_Pa + DX56.bulk_modulus_Pa))
    assert G == pytest.approx(0.5 * (ZINC_COATING.shear_modulus_Pa + DX56.shear_modulus_Pa))
    # a pure particle never evaluates its second material
    nan_row = np.full(c.N_MAT_PARAMS, np.nan)
    assert c.mixed_flow_stress(a, nan_row, 1.0, eps, rate, T) == pytest.approx(sa, rel=1e-13)
    assert all(math.isfinite(v) for v in c.mixed_flow_stress_slopes(a, nan_row, 1.0, eps, rate, T))


# ----------------------------------------------------------------------------- loading paths
@pytest.mark.parametrize("name", MATERIALS)
def test_isochoric_uniaxial_stretch(name: str) -> None:
    """L = diag(e, -e/2, -e/2): no spin, the deviator stays coaxial, so exactly
    eps_p = (total equivalent strain) - q / (3G) for every flow law, and q = sigma_y."""
    mat = MATERIALS[name]
    e, dt, n, rate_scale, tq = 100.0, 5e-7, 1000, 0.1, 0.9
    h = drive(mat, np.diag([e, -e / 2, -e / 2]), dt, n, rate_scale, tq)
    G = mat.shear_modulus_Pa
    plastic = h["deps"] > 0
    assert plastic.sum() > 0.9 * n
    for k in np.flatnonzero(plastic):
        expect = expected_flow(mat, h["eps_p"][k], h["deps"][k] / dt * rate_scale, h["T_before"][k])
        assert h["vm"][k] == pytest.approx(expect, rel=1e-8)
    total = e * dt * np.arange(1, n + 1)
    np.testing.assert_allclose(h["eps_p"], total - h["vm"] / (3 * G), rtol=1e-9, atol=1e-15)
    assert np.all(h["deps"] >= 0) and np.all(np.diff(h["T_after"]) >= 0)
    assert h["T_after"][-1] > T_ROOM
    # pressure from the linear equation of state p = -K (J - 1)
    assert pressure(h["stress"]) == pytest.approx(-mat.bulk_modulus_Pa * (h["J"][-1] - 1), rel=1e-9)


def test_isochoric_stretch_stress_strain_curve_perfectly_plastic() -> None:
    mat = RIGID
    G, sy = mat.shear_modulus_Pa, 300e6
    e, dt, n = 100.0, 5e-7, 400
    h = drive(mat, np.diag([e, -e / 2, -e / 2]), dt, n, 1.0, 0.9)
    total = e * dt * np.arange(1, n + 1)
    np.testing.assert_allclose(h["vm"], np.minimum(3 * G * total, sy), rtol=1e-10)
    assert h["deps"][total < sy / (3 * G)].max() == 0.0
    np.testing.assert_allclose(
        h["eps_p"], np.maximum(total - sy / (3 * G), 0.0), rtol=1e-9, atol=1e-15
    )
    # uniaxial-stress-equivalent deviator: s = q/3 diag(2, -1, -1)
    s = h["stress"][:3] - h["stress"][:3].mean()
    np.testing.assert_allclose(s, sy / 3 * np.array([2.0, -1.0, -1.0]), rtol=1e-10)
    np.testing.assert_allclose(h["stress"][3:], 0.0, atol=1e-6)


@pytest.mark.parametrize("name", MATERIALS)
def test_simple_shear(name: str) -> None:
    mat = MATERIALS[name]
    g, dt, n, rate_scale, tq = 200.0, 5e-7, 1500, 0.1, 0.9
    L = np.zeros((3, 3))
    L[0, 1] = g
    h = drive(mat, L, dt, n, rate_scale, tq)
    plastic = h["deps"] > 0
    assert plastic.sum() > 0.9 * n
    for k in np.flatnonzero(plastic):
        expect = expected_flow(mat, h["eps_p"][k], h["deps"][k] / dt * rate_scale, h["T_before"][k])
        assert h["vm"][k] == pytest.approx(expect, rel=1e-8)
    np.testing.assert_allclose(h["J"], 1.0, rtol=0, atol=1e-14)
    if name == "constant":
        # gamma / sqrt(3) - sigma_y / (3G); the spin of simple shear makes the normal stresses
        # s_xx = -s_yy ~ tau^2 / G, which lowers tau by O((sigma_y / G)^2) ~ 1e-5
        gamma = g * dt * n
        closed = gamma / math.sqrt(3) - 300e6 / (3 * mat.shear_modulus_Pa)
        assert h["eps_p"][-1] == pytest.approx(closed, rel=2e-5)
        tau = h["stress"][5]
        assert tau == pytest.approx(300e6 / math.sqrt(3), rel=2e-5)


def test_elastic_below_yield() -> None:
    mat = DX56
    prm = c.pack_material(mat)
    K, G = mat.bulk_modulus_Pa, mat.shear_modulus_Pa
    rng = np.random.default_rng(1)
    a = rng.uniform(-1e-5, 1e-5, (3, 3))
    eps = 0.5 * (a + a.T)
    dt = 1e-6
    stress = np.zeros((1, 6))
    eps_p = np.zeros(1)
    temp = np.full(1, T_ROOM)
    J = 1.0 + np.trace(eps)
    deps, w = one_particle_step(stress, eps / dt, dt, J, eps_p, temp, rest(prm, prm, 1.0, eps_p, temp), np.zeros(1),
                              prm, prm,
                              1.0, 0.01, 0.9)
    dev = eps - np.trace(eps) / 3 * np.eye(3)
    expect = voigt(2 * G * dev + K * np.trace(eps) * np.eye(3))
    # round-off: J - 1 ~ 1e-5 carries an absolute error ~1e-16, i.e. ~1e-11 relative
    np.testing.assert_allclose(stress[0], expect, rtol=0, atol=1e-10 * np.abs(expect).max())
    assert deps == 0.0 and w == 0.0 and eps_p[0] == 0.0 and temp[0] == T_ROOM


def test_elastic_energy_density() -> None:
    K, G = 1.7e11, 8.1e10
    row = np.array([3e8, -1e8, 5e7, 2e7, -4e7, 6e7])
    sig = tensor(row)
    p = -np.trace(sig) / 3
    s = sig + p * np.eye(3)
    expect = np.sum(s * s) / (4 * G) + p**2 / (2 * K)
    assert c.elastic_energy_density(row[None, :], 0, K, G) == pytest.approx(expect, rel=1e-14)


def _rodrigues(w: np.ndarray, t: float) -> np.ndarray:
    W = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    a = np.linalg.norm(w)
    return np.eye(3) + math.sin(a * t) / a * W + (1 - math.cos(a * t)) / a**2 * W @ W


def test_rigid_rotation_preserves_invariants() -> None:
    mat = DX56
    prm = c.pack_material(mat)
    K = mat.bulk_modulus_Pa
    rng = np.random.default_rng(7)
    a = rng.normal(size=(3, 3))
    s0 = 0.5 * (a + a.T)
    s0 -= np.trace(s0) / 3 * np.eye(3)
    s0 *= 0.5 * 150e6 / math.sqrt(1.5 * np.sum(s0 * s0))  # q = 75 MPa, below yield
    J = 1.0005
    p0 = -K * (J - 1)
    stress = voigt(s0 - p0 * np.eye(3))[None, :].copy()
    w = np.array([3.0, -1.0, 2.0]) * 1e4
    W = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    dt, n = 2e-6, 300  # 0.075 rad per step, 22 rad in all
    eps_p = np.zeros(1)
    temp = np.full(1, T_ROOM)
    sy0 = rest(prm, prm, 1.0, eps_p, temp)
    for _ in range(n):
        one_particle_step(stress, W, dt, J, eps_p, temp, sy0, np.zeros(1), prm, prm, 1.0, 0.01, 0.9)
    assert von_mises(stress[0]) == pytest.approx(75e6, rel=1e-12)
    assert pressure(stress[0]) == pytest.approx(p0, rel=1e-12)
    assert eps_p[0] == 0.0 and temp[0] == T_ROOM
    # exactly the Hughes-Winget rotation R = (I - dt/2 W)^-1 (I + dt/2 W), applied n times
    R = np.linalg.solve(np.eye(3) - dt / 2 * W, np.eye(3) + dt / 2 * W)
    Rn = np.linalg.matrix_power(R, n)
    np.testing.assert_allclose(
        tensor(stress[0]), Rn @ s0 @ Rn.T - p0 * np.eye(3), rtol=0, atol=1e-9 * 75e6
    )


def test_rotation_direction_matches_spin() -> None:
    """One small step: s1 = Q s0 Q^T with Q = exp(W dt), i.e. s1 ~ s0 + dt (W s0 - s0 W)."""
    prm = c.pack_material(DX56)
    s0 = np.array([[4e7, 2e7, -1e7], [2e7, -3e7, 1.5e7], [-1e7, 1.5e7, -1e7]])
    w = np.array([1.0, 2.0, -0.5]) * 50.0
    W = np.array([[0, -w[2], w[1]], [w[2], 0, -w[0]], [-w[1], w[0], 0]])
    dt = 1e-5
    stress = voigt(s0)[None, :].copy()
    eps_p, temp = np.zeros(1), np.full(1, T_ROOM)
    one_particle_step(stress, W, dt, 1.0, eps_p, temp, rest(prm, prm, 1.0, eps_p, temp), np.zeros(1), prm, prm, 1.0,
                    1.0, 0.9)
    Q = _rodrigues(w, dt)
    exact = Q @ s0 @ Q.T
    first = dt * (W @ s0 - s0 @ W)
    err = np.abs(tensor(stress[0]) - exact).max()
    assert err < 1e-3 * np.abs(first).max()


# ----------------------------------------------------------------------------- rate and heat
@pytest.mark.parametrize("name", ["bvl", "jc"])
def test_rate_scale_raises_flow_stress(name: str) -> None:
    mat = MATERIALS[name]
    e, dt, n = 100.0, 5e-7, 300
    L = np.diag([e, -e / 2, -e / 2])
    slow = drive(mat, L, dt, n, 1e-3, 0.0)  # physical rate 0.1 / s
    fast = drive(mat, L, dt, n, 1.0, 0.0)  # physical rate 100 / s
    assert fast["vm"][-1] > slow["vm"][-1] * 1.01
    # and both sit on their own flow curve at their own rate
    for h, rs in ((slow, 1e-3), (fast, 1.0)):
        rate = h["deps"][-1] / dt * rs
        assert h["vm"][-1] == pytest.approx(
            expected_flow(mat, h["eps_p"][-1], rate, T_ROOM), rel=1e-10
        )
    prm = c.pack_material(mat)
    assert c.flow_stress(prm, 0.1, 1e3, T_ROOM) > c.flow_stress(prm, 0.1, 1e1, T_ROOM)


STRONG_RATE = {
    "bvl": replace(DX56, flow=replace(DX56.flow, sigma_v0_Pa=3e9, rate0_per_s=1e-2, dG0_eV=0.2)),
    "jc": replace(ZINC_BULK, flow=replace(ZINC_BULK.flow, C=0.4, rate0_per_s=1e-3)),
}


@pytest.mark.parametrize("name", STRONG_RATE)
@pytest.mark.parametrize("over", [1e2, 1e5, 3e7, 1e9])
@pytest.mark.parametrize(("dt", "rate_scale"), [(1e-6, 0.01), (1e-9, 1.0), (1e-3, 1.0)])
def test_return_map_residual_strong_rate(
    name: str, over: float, dt: float, rate_scale: float
) -> None:
    mat = STRONG_RATE[name]
    prm = c.pack_material(mat)
    G = mat.shear_modulus_Pa
    eps, T = 0.05, 420.0
    q = expected_flow(mat, eps, 0.0, T) + over
    d, sy = c.return_map(prm, prm, 1.0, q, G, eps, dt, rate_scale, T)
    assert 0.0 < d < over / (3 * G)
    rate = d / dt * rate_scale
    assert sy == pytest.approx(expected_flow(mat, eps + d, rate, T), rel=1e-13)
    assert abs(q - 3 * G * d - sy) <= 1e-11 * q
    # the rate term carries a real part of the overstress here
    if over >= 3e7:
        assert sy - expected_flow(mat, eps + d, 0.0, T) > 1e-3 * over


#: the laws whose return map iterates (a constant flow stress returns at the bracket's end)
ITERATING = {"bvl": DX56, "jc": ZINC_BULK, "power": ZINC_COATING, **{f"strong_{k}": m for k, m in STRONG_RATE.items()}}


@pytest.mark.parametrize("name", ITERATING)
@pytest.mark.parametrize("guess", [1e-6, 0.3, 0.999, 1.001, 3.0, 1e3, 1e9])
def test_return_map_guess_changes_the_start_not_the_root(name: str, guess: float) -> None:
    """A starting guess (the particle's last increment), near the root, far from it or outside the
    bracket, gives the root found without one, within the return map's own tolerance: two
    increments whose residuals are both within tol differ by at most 2 tol / 3G (|f'| >= 3G)."""
    mat = ITERATING[name]
    prm = c.pack_material(mat)
    G = mat.shear_modulus_Pa
    eps, T, dt, rate_scale = 0.05, 320.0, 1e-6, 0.01
    sig0 = c.flow_stress(prm, eps, 0.0, T)
    for over in (1e-4, 1e-2, 0.3):
        q = sig0 * (1.0 + over)
        d, sy, _ = c.return_map_at_rest(prm, prm, 1.0, q, G, eps, dt, rate_scale, T, sig0, 0.0)
        d_g, sy_g, _ = c.return_map_at_rest(prm, prm, 1.0, q, G, eps, dt, rate_scale, T, sig0, guess * d)
        assert d > 0.0
        assert abs(q - 3 * G * d_g - sy_g) <= c.RETURN_RTOL * q
        assert abs(d_g - d) <= 2.0 * c.RETURN_RTOL * q / (3 * G)


def test_return_map_guess_near_the_root_saves_evaluations() -> None:
    """DX56 at a real-material scene's time step and rate scale (dt ~ 1e-6 s, v_exp / v_sim = 0.01):
    the rate term takes up most of the overstress, the root lies far below the elastic-predictor
    bound and the iteration from that bound takes 8-9 flow-law evaluations; a guess within 1% of the
    root (the last increment of a steadily flowing particle) saves at least three, one within 10%
    at least one."""
    prm = c.pack_material(DX56)
    G = DX56.shear_modulus_Pa
    eps, T, dt, rate_scale = 0.1, 300.0, 9.7e-7, 0.01
    sig0 = c.flow_stress(prm, eps, 0.0, T)
    q = sig0 * 1.001
    d, _, n_cold = c.return_map_at_rest(prm, prm, 1.0, q, G, eps, dt, rate_scale, T, sig0, 0.0)
    hi = (q - sig0) / (3 * G)
    assert d < hi / 100.0  # the root is orders of magnitude below the bound
    assert n_cold >= 8
    for factor, saved in ((0.9, 1), (0.99, 3), (1.01, 3), (1.1, 1)):
        _, _, n_warm = c.return_map_at_rest(prm, prm, 1.0, q, G, eps, dt, rate_scale, T, sig0, factor * d)
        assert n_warm <= n_cold - saved


@pytest.mark.parametrize("mat", [ZINC_COATING, ZINC_BULK], ids=["power", "jc"])
def test_return_map_guess_costs_nothing_where_the_root_is_near_the_bound(mat: Material) -> None:
    """Without a strong rate term the root lies within a few per cent of the elastic-predictor
    bound and Newton from there needs 3-5 evaluations; a guess below the root would cost more (9
    from half the root), so the return map does not take it: the same count with or without."""
    prm = c.pack_material(mat)
    G = mat.shear_modulus_Pa
    eps, T, dt, rate_scale = 0.1, 300.0, 9.7e-7, 0.01
    sig0 = c.flow_stress(prm, eps, 0.0, T)
    for over in (1e-4, 1e-2, 1e-1):
        q = sig0 * (1.0 + over)
        d, _, n_cold = c.return_map_at_rest(prm, prm, 1.0, q, G, eps, dt, rate_scale, T, sig0, 0.0)
        assert n_cold <= 5
        for factor in (0.5, 0.9, 0.99):
            assert c.return_map_at_rest(prm, prm, 1.0, q, G, eps, dt, rate_scale, T, sig0, factor * d)[2] == n_cold


def test_return_map_ignores_the_guess_of_a_softening_law() -> None:
    """A JC rate constant C < 0 softens with rate: the root need not be unique, so the guess is not
    used and the result is that without a guess, to the bit."""
    mat = replace(ZINC_BULK, flow=replace(ZINC_BULK.flow, C=-0.02, rate0_per_s=1e-6))
    prm = c.pack_material(mat)
    assert not c.non_softening(prm) and c.non_softening(c.pack_material(ZINC_BULK))
    G = mat.shear_modulus_Pa
    eps, T, dt, rate_scale = 0.05, 320.0, 1e-6, 0.01
    sig0 = c.flow_stress(prm, eps, 0.0, T)
    q = sig0 * 1.01
    cold = c.return_map_at_rest(prm, prm, 1.0, q, G, eps, dt, rate_scale, T, sig0, 0.0)
    assert cold[0] > 0.0
    assert c.return_map_at_rest(prm, prm, 1.0, q, G, eps, dt, rate_scale, T, sig0, 0.5 * cold[0]) == cold


def test_return_map_elastic_and_zero_stress() -> None:
    prm = c.pack_material(ZINC_BULK)
    G = ZINC_BULK.shear_modulus_Pa
    sy0 = expected_flow(ZINC_BULK, 0.1, 0.0, T_ROOM)
    assert c.return_map(prm, prm, 1.0, 0.999 * sy0, G, 0.1, 1e-6, 1.0, T_ROOM) == (
        0.0,
        pytest.approx(sy0, rel=1e-14),
    )
    # above Tm the flow stress is zero: full return
    d, sy = c.return_map(prm, prm, 1.0, 1e8, G, 0.1, 1e-6, 1.0, 800.0)
    assert sy == 0.0 and d == pytest.approx(1e8 / (3 * G), rel=1e-13)


@pytest.mark.parametrize("frac_a", [1.0, 0.3])
def test_adiabatic_heating(frac_a: float) -> None:
    a, b = ZINC_BULK, DX56
    pa, pb = c.pack_material(a), c.pack_material(b)
    G = frac_a * a.shear_modulus_Pa + (1 - frac_a) * b.shear_modulus_Pa
    dt, tq, rate_scale = 1e-6, 0.85, 0.01
    eps0, T0 = 0.2, 330.0
    sy0 = frac_a * expected_flow(a, eps0, 0.0, T0) + (1 - frac_a) * expected_flow(b, eps0, 0.0, T0)
    # a deviatoric trial state 1.5 sigma_y above yield, reached with L = 0 from a pre-stress
    q = 1.5 * sy0
    stress = np.array([[2 * q / 3, -q / 3, -q / 3, 0.0, 0.0, 0.0]])
    eps_p = np.full(1, eps0)
    temp = np.full(1, T0)
    deps, w = one_particle_step(
        stress, np.zeros((3, 3)), dt, 1.0, eps_p, temp, rest(pa, pb, frac_a, eps_p, temp), np.zeros(1), pa, pb,
        frac_a, rate_scale, tq
    )
    rate = deps / dt * rate_scale
    sy = frac_a * expected_flow(a, eps0 + deps, rate, T0) + (1 - frac_a) * expected_flow(
        b, eps0 + deps, rate, T0
    )
    assert deps > 0 and deps == pytest.approx((q - sy) / (3 * G), rel=1e-10)
    assert w == pytest.approx(sy * deps, rel=1e-12)
    rho_cp = frac_a * a.density_kg_m3 * a.heat_capacity_J_kgK + (1 - frac_a) * (
        b.density_kg_m3 * b.heat_capacity_J_kgK
    )
    assert temp[0] - T0 == pytest.approx(tq * sy * deps / rho_cp, rel=1e-10)
    assert eps_p[0] == pytest.approx(eps0 + deps, rel=1e-15)
    assert von_mises(stress[0]) == pytest.approx(sy, rel=1e-12)


def test_parallel_driver_matches_single_updates() -> None:
    rng = np.random.default_rng(3)
    n = 64
    table = c.pack_materials(list(MATERIALS.values()))
    mat_a = rng.integers(0, 4, n)
    mat_b = rng.integers(0, 4, n)
    frac_a = np.where(rng.random(n) < 0.5, 1.0, rng.random(n))
    L_all = rng.normal(scale=2e3, size=(n, 3, 3))
    J = 1.0 + rng.normal(scale=1e-3, size=n)
    stress = rng.normal(scale=2e8, size=(n, 6))
    eps_p = rng.uniform(0, 1, n)
    temp = rng.uniform(280, 450, n)
    dt, rs, tq = 1e-6, 0.01, 0.9
    sy0 = np.zeros(n)
    c.rest_flow_stresses(eps_p, temp, mat_a, mat_b, frac_a, table, sy0)
    # a guess for half the particles: some near the root, some far off, some outside the bracket
    deps_last = np.where(rng.random(n) < 0.5, 10.0 ** rng.uniform(-12, -2, n), 0.0)
    ref = (stress.copy(), eps_p.copy(), temp.copy(), sy0.copy(), deps_last.copy())
    ref_d, ref_w = np.zeros(n), np.zeros(n)
    M = MaterialData(table, rs, tq)
    P_ref = particles_of(n, stress=ref[0], J=J, eps_p=ref[1], temperature=ref[2], sigma_y0=ref[3], deps_last=ref[4],
                         mat_a=mat_a, mat_b=mat_b, frac_a=frac_a)
    for i in range(n):
        ref_d[i], ref_w[i] = c.update_stress(P_ref, i, L_all[i], dt, M)
    d, w = np.zeros(n), np.zeros(n)
    P = particles_of(n, stress=stress, J=J, eps_p=eps_p, temperature=temp, sigma_y0=sy0, deps_last=deps_last,
                     mat_a=mat_a, mat_b=mat_b, frac_a=frac_a)
    c.update_stresses(P, L_all, dt, M, d, w)
    for got, want in zip((stress, eps_p, temp, sy0, deps_last, d, w), (*ref, ref_d, ref_w), strict=True):
        np.testing.assert_allclose(got, want, rtol=1e-14, atol=0)
    assert (d > 0).sum() > n // 4  # the random states exercise the plastic branch


# ----------------------------------------------------------------------------- property test
TABLE = c.pack_materials(list(MATERIALS.values()))
MAT_LIST = list(MATERIALS.values())


@settings(max_examples=300, deadline=None)
@given(
    sig=st.lists(st.floats(-1e9, 1e9, allow_nan=False), min_size=6, max_size=6),
    Lc=st.lists(st.floats(-5e3, 5e3, allow_nan=False), min_size=9, max_size=9),
    ia=st.integers(0, 3),
    ib=st.integers(0, 3),
    frac=st.one_of(st.just(1.0), st.floats(0.0, 1.0)),
    eps0=st.one_of(st.just(0.0), st.floats(0.0, 3.0)),
    T0=st.floats(250.0, 750.0),
    J=st.floats(0.98, 1.02),
    log_dt=st.floats(-9.0, -4.0),
    log_rs=st.floats(-4.0, 0.0),
)
def test_property_never_outside_yield_surface(
    sig: list[float],
    Lc: list[float],
    ia: int,
    ib: int,
    frac: float,
    eps0: float,
    T0: float,
    J: float,
    log_dt: float,
    log_rs: float,
) -> None:
    stress = np.array([sig], dtype=np.float64)
    L = np.array(Lc, dtype=np.float64).reshape(3, 3)
    dt, rs = 10.0**log_dt, 10.0**log_rs
    eps_p = np.full(1, eps0)
    temp = np.full(1, T0)
    sy0 = rest(TABLE[ia], TABLE[ib], frac, eps_p, temp)
    deps, w = one_particle_step(stress, L, dt, J, eps_p, temp, sy0, np.zeros(1), TABLE[ia], TABLE[ib], frac, rs,
                              0.9)
    assert np.all(np.isfinite(stress)) and math.isfinite(deps) and math.isfinite(w)
    assert math.isfinite(temp[0]) and temp[0] >= T0
    assert deps >= 0.0 and w >= 0.0 and eps_p[0] == pytest.approx(eps0 + deps, rel=1e-15)
    rate = deps / dt * rs
    sy = frac * expected_flow(MAT_LIST[ia], eps0 + deps, rate, T0) + (1 - frac) * expected_flow(
        MAT_LIST[ib], eps0 + deps, rate, T0
    )
    # von_mises() here re-splits the stored row; that costs round-off ~1e-16 of the pressure
    noise = 1e-14 * np.abs(stress).max() + 1e-6
    assert von_mises(stress[0]) <= sy * (1 + 1e-9) + noise
    if deps > 0.0:
        assert von_mises(stress[0]) == pytest.approx(sy, rel=1e-9, abs=noise)
    K = frac * MAT_LIST[ia].bulk_modulus_Pa + (1 - frac) * MAT_LIST[ib].bulk_modulus_Pa
    assert pressure(stress[0]) == pytest.approx(-K * (J - 1), rel=1e-9, abs=1e-3)


def test_agrees_with_materials_reference_flow_stress() -> None:
    """Cross-check with the plain-Python reference of plough.materials, where it exists."""
    from plough import materials

    ref = getattr(materials, "reference_flow_stress", None)
    if ref is None:
        pytest.skip("plough.materials.reference_flow_stress is not there")
    for mat in MATERIALS.values():
        prm = c.pack_material(mat)
        for eps, rate, T in FLOW_POINTS:
            assert c.flow_stress(prm, eps, rate, T) == pytest.approx(
                ref(mat.flow, eps, rate, T), rel=1e-13, abs=1e-6
            )
