"""Property-based tests of the numba kernels of plough.mpm on random states (hypothesis).

Constitutive update (``update_stress``) for the four flow laws and for straddling particles:
finite results, the stress never outside the yield surface at the updated state, non-negative
plastic strain increments and plastic work, elastic steps that leave the plastic strain alone,
the linear equation of state for the pressure, the consistency condition of the radial return
(against a trial state computed here with numpy), objectivity under pure spin and frame
indifference under a rotated frame; each with a random starting guess of the return map (none, or
anything from 1e-14 to 10), which must not move the result off the consistency condition.

Contact (``sphere_contact``) on random grid states with FREE, FIXED, MIRROR and GHOST nodes:
impenetrability, slips that never reverse or grow, untouched ghosts that do not influence the
result, the traction limit tau * A * dt with the node's surface share A = |sum V grad N| (its y
component dropped on the mirror plane, ``surface_share``), non-negative dissipation and
reaction = minus the impulses / dt.
Interface shear (``interface_shear``): capped at kappa, monotone in pressure for the boundary layer.

Reference values (flow stresses, trial deviators, areas, shear strengths) are computed here in
plain Python / numpy, never by calling the kernel under test a second time.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, assume, event, given, settings
from hypothesis import strategies as st

from plough.materials import DX56, ZINC_BULK, ZINC_COATING, reference_flow_stress, rigid_plastic
from plough.mpm import constitutive as c
from plough.mpm import contact as ct
from plough.mpm.bundles import ContactLaw, SphereData, grid_of
from plough.mpm.grid import FIXED, FREE, GHOST, MIRROR, Grid
from tests.mpm.test_constitutive import one_particle_step

EPS = np.finfo(float).eps
TQ = 0.9  # Taylor-Quinney factor

# ============================================================================= constitutive update
FLOW = {
    "constant": rigid_plastic("rp_coating", 450e6, coating=True),
    "bvl": DX56,
    "jc": ZINC_BULK,
    "power": ZINC_COATING,
}
ROW = {name: c.pack_material(mat) for name, mat in FLOW.items()}
NAMES = list(FLOW)


def tensor(v: np.ndarray) -> np.ndarray:
    return np.array([[v[0], v[5], v[4]], [v[5], v[1], v[3]], [v[4], v[3], v[2]]])


def voigt(m: np.ndarray) -> np.ndarray:
    return np.array([m[0, 0], m[1, 1], m[2, 2], m[1, 2], m[0, 2], m[0, 1]])


def dev(m: np.ndarray) -> np.ndarray:
    return m - np.trace(m) / 3.0 * np.eye(3)


def q_of(s: np.ndarray) -> float:
    """von Mises equivalent sqrt(3/2 s:s) of a deviatoric 3x3 tensor."""
    return math.sqrt(1.5 * float(np.sum(s * s)))


def split(row: np.ndarray) -> tuple[np.ndarray, float]:
    """(deviator, pressure) of a Voigt stress row."""
    sig = tensor(row)
    return dev(sig), -float(np.trace(sig)) / 3.0


def ref_flow(st_: dict, eps: float, rate: float, T: float) -> float:
    """Volume-weighted flow stress of the plain-Python reference of plough.materials."""
    sa = reference_flow_stress(FLOW[st_["a"]].flow, eps, rate, T)
    if st_["frac"] >= 1.0:
        return sa
    sb = reference_flow_stress(FLOW[st_["b"]].flow, eps, rate, T)
    return st_["frac"] * sa + (1.0 - st_["frac"]) * sb


def moduli(st_: dict) -> tuple[float, float]:
    a, b, f = FLOW[st_["a"]], FLOW[st_["b"]], st_["frac"]
    return (f * a.bulk_modulus_Pa + (1 - f) * b.bulk_modulus_Pa, f * a.shear_modulus_Pa + (1 - f) * b.shear_modulus_Pa)


def hughes_winget_trial(s_old: np.ndarray, L: np.ndarray, dt: float, G: float) -> np.ndarray:
    """Trial deviator R s R^T + 2 G dt dev(D), R = (I - dt/2 W)^-1 (I + dt/2 W), with numpy."""
    W = 0.5 * (L - L.T)
    R = np.linalg.solve(np.eye(3) - 0.5 * dt * W, np.eye(3) + 0.5 * dt * W)
    return dev(R @ s_old @ R.T + 2.0 * G * dt * dev(0.5 * (L + L.T)))


def directions(size: int):
    """Lists of numbers in [-1, 1], the largest of magnitude >= 0.1 (directions that can be scaled safely)."""
    return st.lists(st.floats(-1.0, 1.0), min_size=size, max_size=size).filter(lambda v: max(map(abs, v)) >= 0.1)


unit3, unit6, unit9 = directions(3), directions(6), directions(9)


@st.composite
def particles(draw) -> dict:
    """A particle of one of the four flow laws or a straddling one, with a stress inside the yield surface."""
    kind = draw(st.sampled_from([*NAMES, "mixed"]))
    if kind == "mixed":
        a, b = draw(st.lists(st.sampled_from(NAMES), min_size=2, max_size=2, unique=True))
        frac = draw(st.floats(0.0, 1.0, exclude_min=True, exclude_max=True))
    else:
        a = b = kind
        frac = 1.0
    state = dict(a=a, b=b, frac=frac)
    state["eps0"] = draw(st.one_of(st.just(0.0), st.floats(0.0, 2.0), st.floats(1e-12, 1e-4)))
    state["T0"] = draw(st.floats(250.0, 600.0))  # below the Johnson-Cook melting temperature
    state["J"] = draw(st.floats(0.97, 1.03))
    state["p_old"] = draw(st.floats(-3e9, 3e9))  # the old pressure must play no role
    state["ratio"] = draw(st.one_of(st.just(0.0), st.floats(1e-6, 0.999)))  # q0 / sigma_y(eps0, rate 0, T0)
    state["dir"] = draw(unit6)
    # the return map's starting guess (the particle's last plastic increment): none, or anything
    state["guess"] = draw(st.one_of(st.just(0.0), st.floats(1e-14, 10.0)))
    return state


def initial_deviator(state: dict) -> tuple[np.ndarray, float]:
    """Deviator with q = ratio * sigma_y(eps0, 0, T0) in a random direction, and that sigma_y."""
    sy0 = ref_flow(state, state["eps0"], 0.0, state["T0"])
    s = dev(tensor(np.array(state["dir"])))
    q = q_of(s)
    s = s * (state["ratio"] * sy0 / q) if q > 1e-6 else np.zeros((3, 3))
    return s, sy0


def run_update(state: dict, s_old: np.ndarray, L: np.ndarray, dt: float, rate_scale: float):
    stress = voigt(s_old - state["p_old"] * np.eye(3))[None, :].copy()
    eps_p = np.full(1, state["eps0"])
    temp = np.full(1, state["T0"])
    sy0 = np.array([c.mixed_flow_stress(ROW[state["a"]], ROW[state["b"]], state["frac"], eps_p[0], 0.0, temp[0])])
    deps_last = np.full(1, state["guess"])
    deps, w = one_particle_step(stress, np.ascontiguousarray(L), dt, state["J"], eps_p, temp, sy0, deps_last,
                              ROW[state["a"]], ROW[state["b"]], state["frac"], rate_scale, TQ)
    assert deps_last[0] == (deps if deps > 0.0 else state["guess"])
    # the cache of the flow stress at rest follows the new plastic strain and temperature exactly
    assert sy0[0] == c.mixed_flow_stress(ROW[state["a"]], ROW[state["b"]], state["frac"], eps_p[0], 0.0, temp[0])
    return stress[0], float(eps_p[0]), float(temp[0]), deps, w


def velocity_gradient(direction: list[float], log_mag: float) -> np.ndarray:
    L = np.array(direction).reshape(3, 3)
    return L * (10.0**log_mag / np.abs(L).max())


@settings(max_examples=250, deadline=None)
@given(state=particles(), Ldir=unit9, log_de=st.floats(-8.0, 0.5), log_dt=st.floats(-10.0, -4.0),
       log_rs=st.floats(-5.0, 0.0))
def test_stress_update_stays_on_or_inside_the_yield_surface(state, Ldir, log_de, log_dt, log_rs):
    """Random L (strain increments |L| dt 1e-8 .. 3, |L| 1e-4 .. 3e10 1/s), dt, rate scale; start inside."""
    dt, rs = 10.0**log_dt, 10.0**log_rs
    L = velocity_gradient(Ldir, log_de - log_dt)
    K, G = moduli(state)
    s_old, sy0 = initial_deviator(state)
    row, eps_p, temp, deps, w = run_update(state, s_old, L, dt, rs)

    assert np.all(np.isfinite(row)) and math.isfinite(deps) and math.isfinite(w) and math.isfinite(temp)
    # plastic strain increment and plastic work (dissipation) are never negative; heating only
    assert deps >= 0.0 and w >= 0.0
    assert eps_p == state["eps0"] + deps and temp >= state["T0"]
    s_new, p_new = split(row)
    q_new = q_of(s_new)
    # splitting the old and the stored rows into deviator and pressure costs round-off of the pressures
    noise = 1e-14 * (np.abs(row).max() + abs(state["p_old"]))
    # never outside the yield surface at the updated plastic strain, its rate and the step's temperature
    rate = deps / dt * rs
    sy = ref_flow(state, state["eps0"] + deps, rate, state["T0"])
    assert q_new <= sy * (1.0 + 1e-9) + noise
    # linear equation of state for the volumetric part, whatever the old pressure was
    assert abs(p_new - (-K * (state["J"] - 1.0))) <= 1e-12 * K * abs(state["J"] - 1.0) + noise

    # against the trial state computed here: elastic inside, radial return onto the surface outside
    s_tr = hughes_winget_trial(s_old, L, dt, G)
    q_tr = q_of(s_tr)
    scale = q_of(s_old) + 2.0 * G * dt * q_of(dev(0.5 * (L + L.T))) + np.abs(row).max() + abs(state["p_old"])
    event(f"{state['a']}/{state['b']}: {'elastic' if deps == 0.0 else 'plastic'}")
    if deps == 0.0:
        assert w == 0.0 and temp == state["T0"]
        assert q_tr <= sy0 * (1.0 + 1e-12) + 1e-12 * scale
        np.testing.assert_allclose(s_new, s_tr, rtol=0, atol=1e-12 * scale)
    else:
        assert q_tr >= sy0 * (1.0 - 1e-12) - 1e-12 * scale
        # consistency condition q_trial - 3 G deps = sigma_y(eps0 + deps, deps / dt * rate_scale, T0)
        assert abs(q_tr - 3.0 * G * deps - sy) <= 1e-9 * q_tr + 1e-12 * scale
        assert abs(q_new - sy) <= 1e-9 * sy + noise
        np.testing.assert_allclose(s_new, s_tr * (sy / q_tr), rtol=0, atol=1e-9 * sy + 1e-12 * scale)
        assert abs(w - sy * deps) <= 1e-9 * sy * deps


@settings(max_examples=120, deadline=None)
@given(state=particles(), Ldir=unit9, log_b=st.floats(-10.0, math.log10(0.99)), log_dt=st.floats(-10.0, -5.0),
       log_rs=st.floats(-5.0, 0.0))
def test_purely_elastic_step_leaves_plastic_state_alone(state, Ldir, log_b, log_dt, log_rs):
    """L scaled so that q(s_old) + q(2 G dt dev D) < sigma_y: no plastic flow can be admissible."""
    dt, rs = 10.0**log_dt, 10.0**log_rs
    K, G = moduli(state)
    s_old, sy0 = initial_deviator(state)
    L = np.array(Ldir).reshape(3, 3)
    q_dir = 2.0 * G * dt * q_of(dev(0.5 * (L + L.T)))
    assume(q_dir > 1e-6 * 2.0 * G * dt)
    # the rotation keeps q(s_old); the triangle inequality bounds q_trial by q_old + the increment
    L = L * (10.0**log_b * (1.0 - state["ratio"]) * sy0 / q_dir)
    row, eps_p, temp, deps, w = run_update(state, s_old, L, dt, rs)
    assert deps == 0.0 and w == 0.0
    assert eps_p == state["eps0"] and temp == state["T0"]
    s_new, p_new = split(row)
    noise = 1e-14 * (np.abs(row).max() + abs(state["p_old"]))
    scale = q_of(s_old) + 2.0 * G * dt * q_of(dev(0.5 * (L + L.T))) + np.abs(row).max() + abs(state["p_old"])
    np.testing.assert_allclose(s_new, hughes_winget_trial(s_old, L, dt, G), rtol=0, atol=1e-12 * scale)
    assert abs(p_new + K * (state["J"] - 1.0)) <= 1e-12 * K * abs(state["J"] - 1.0) + noise


@settings(max_examples=120, deadline=None)
@given(state=particles(), wdir=unit3, log_w=st.floats(-3.0, 7.0),
       log_dt=st.floats(-10.0, -4.0), nsteps=st.integers(1, 4))
def test_pure_spin_preserves_invariants(state, wdir, log_w, log_dt, nsteps):
    """Objectivity: an antisymmetric L (rotation angles per step 1e-13 .. 1e3 rad) changes neither the
    von Mises stress nor the pressure nor the principal deviatoric stresses, and causes no plastic flow."""
    w = np.array(wdir) * (10.0**log_w / max(map(abs, wdir)))
    W = np.array([[0.0, -w[2], w[1]], [w[2], 0.0, -w[0]], [-w[1], w[0], 0.0]])
    dt = 10.0**log_dt
    K, _ = moduli(state)
    s_old, _ = initial_deviator(state)
    q0 = q_of(s_old)
    stress = voigt(s_old - state["p_old"] * np.eye(3))[None, :].copy()
    eps_p = np.full(1, state["eps0"])
    temp = np.full(1, state["T0"])
    sy0 = np.array([c.mixed_flow_stress(ROW[state["a"]], ROW[state["b"]], state["frac"], eps_p[0], 0.0, temp[0])])
    for _ in range(nsteps):
        deps, wp = one_particle_step(stress, W, dt, state["J"], eps_p, temp, sy0, np.zeros(1), ROW[state["a"]],
                                   ROW[state["b"]], state["frac"], 1.0, TQ)
        assert deps == 0.0 and wp == 0.0
    assert eps_p[0] == state["eps0"] and temp[0] == state["T0"]
    assert np.all(np.isfinite(stress))
    s_new, p_new = split(stress[0])
    noise = 1e-14 * (np.abs(stress).max() + abs(state["p_old"]))
    assert abs(q_of(s_new) - q0) <= 1e-12 * q0 + noise
    assert abs(p_new + K * (state["J"] - 1.0)) <= 1e-12 * K * abs(state["J"] - 1.0) + noise
    np.testing.assert_allclose(np.linalg.eigvalsh(s_new), np.linalg.eigvalsh(s_old), rtol=0,
                               atol=1e-12 * q0 + noise)


def rotation(axis: list[float], angle: float) -> np.ndarray:
    """Rotation by ``angle`` about ``axis`` (Rodrigues)."""
    k = np.array(axis) / np.linalg.norm(axis)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * K @ K


@settings(max_examples=100, deadline=None)
@given(state=particles(), Ldir=unit9, log_L=st.floats(-3.0, 6.0), log_dt=st.floats(-10.0, -5.0),
       axis=unit3, angle=st.floats(-math.pi, math.pi))
def test_update_is_frame_indifferent(state, Ldir, log_L, log_dt, axis, angle):
    """Observed from a rotated frame (s, L) -> (Q s Q^T, Q L Q^T), the update gives Q s_new Q^T."""
    Q = rotation(axis, angle)
    L = velocity_gradient(Ldir, log_L)
    dt = 10.0**log_dt
    _, G = moduli(state)
    s_old, _ = initial_deviator(state)
    row1, eps1, _, deps1, _ = run_update(state, s_old, L, dt, 0.01)
    row2, eps2, _, deps2, _ = run_update(state, Q @ s_old @ Q.T, Q @ L @ Q.T, dt, 0.01)
    q_tr = q_of(hughes_winget_trial(s_old, L, dt, G))
    # the return map converges to |residual| <= 1e-13 q_trial: deps agrees to that over 3G
    assert abs(deps2 - deps1) <= 1e-9 * deps1 + 1e-12 * q_tr / (3.0 * G)
    assert abs(eps2 - eps1) <= 1e-9 * deps1 + 1e-12 * q_tr / (3.0 * G) + 4 * EPS * eps1
    scale = np.abs(row1).max() + q_tr + abs(state["p_old"])
    np.testing.assert_allclose(tensor(row2), Q @ tensor(row1) @ Q.T, rtol=0, atol=1e-10 * scale)


# ============================================================================= sphere contact
DX = 1e-5
SHAPE = np.array([10, 9, 11], dtype=np.int64)
ORIGIN = np.array([-4.5e-5, -3e-5, -6e-5])
NODES = Grid(origin=ORIGIN, dx=DX, shape=tuple(int(s) for s in SHAPE)).node_positions()
N_NODES = NODES.shape[0]
MODELS = (ct.INTERFACE_PROPORTIONAL, ct.INTERFACE_CONSTANT, ct.INTERFACE_BOUNDARY_LAYER)


@st.composite
def contact_states(draw) -> dict:
    """Scalars from hypothesis, the per-node arrays from a seeded generator (too many for hypothesis)."""
    rng = np.random.default_rng(draw(st.integers(0, 2**32 - 1)))
    model = draw(st.sampled_from(MODELS))
    if model == ct.INTERFACE_PROPORTIONAL:
        iparams = [draw(st.floats(0.0, 1.0)), 0.0]
    elif model == ct.INTERFACE_CONSTANT:
        iparams = [10.0 ** draw(st.floats(4.0, 10.0)), 0.0]
    else:
        iparams = [10.0 ** draw(st.floats(-2.0, 1.0)), draw(st.floats(0.0, 1.0))]
    # the sphere may stick out of the grid (the node box is clamped)
    centre = ORIGIN + DX * np.array(draw(st.lists(st.floats(-1.0, 11.0), min_size=3, max_size=3)))
    radius = DX * draw(st.floats(1.0, 4.0))
    dt = 10.0 ** draw(st.floats(-10.0, -3.0))
    v_sphere = rng.normal(size=3) * 10.0 ** draw(st.floats(-4.0, 1.0))
    m_scale = 10.0 ** draw(st.floats(-12.0, -3.0))
    v_rel = 10.0 ** draw(st.floats(-5.0, 1.0))
    symmetric = draw(st.booleans())

    grid_m = rng.uniform(0.1, 2.0, N_NODES) * m_scale
    grid_m[rng.random(N_NODES) < 0.05] = 0.0
    # relative velocities over six decades, and a tenth of the nodes head-on with barely any slip
    rel = rng.normal(size=(N_NODES, 3)) * (v_rel * 10.0 ** rng.uniform(-6.0, 0.0, N_NODES))[:, None]
    head_on = rng.random(N_NODES) < 0.1
    outward = NODES[head_on] - centre
    outward /= np.maximum(np.linalg.norm(outward, axis=1), 1e-300)[:, None]
    rel[head_on] = -v_rel * outward + rng.normal(size=(head_on.sum(), 3)) * v_rel * 1e-9
    grid_v = v_sphere + rel
    # contact buffer: mass-weighted stress (pressures 1e3 .. 1e12 Pa, 15 % tensile) and kappa
    wgt = rng.uniform(0.1, 2.0, N_NODES) * m_scale
    p0 = 10.0 ** rng.uniform(3.0, 12.0, N_NODES) * np.where(rng.random(N_NODES) < 0.15, -1.0, 1.0)
    sig = rng.normal(0.0, 0.3, (N_NODES, 6)) * np.abs(p0)[:, None]
    sig[:, :3] -= p0[:, None]
    kappa = 10.0 ** rng.uniform(4.0, 10.0, N_NODES)
    kappa[rng.random(N_NODES) < 0.03] = 0.0
    cbuf = np.zeros((N_NODES, ct.N_CBUF))
    cbuf[:, :6] = wgt[:, None] * sig
    cbuf[:, 6] = wgt * kappa
    cbuf[:, 7] = wgt
    cbuf[rng.random(N_NODES) < 0.05, :8] = 0.0  # touching but without weight: pressure = kappa = 0
    cbuf[:, 8] = DX * (rng.random(N_NODES) < 0.85)  # proximity DX - gap: 0 gap (touching) or no particle near
    # surface vectors sum V grad N: up to one and a half cell faces, a tenth of the nodes inside the body (0)
    surf = rng.normal(size=(N_NODES, 3)) * (DX * DX * rng.uniform(0.0, 1.0, N_NODES))[:, None]
    surf[rng.random(N_NODES) < 0.1] = 0.0
    cbuf[:, ct.C_AREA:ct.C_AREA + 3] = surf
    if symmetric:
        flags = rng.choice(np.array([FREE, FIXED, MIRROR, GHOST], dtype=np.int8), N_NODES, p=[0.35, 0.1, 0.3, 0.25])
    else:
        flags = rng.choice(np.array([FREE, FIXED], dtype=np.int8), N_NODES, p=[0.8, 0.2])
    return dict(grid_m=grid_m, grid_v=grid_v, cbuf=cbuf, flags=flags, centre=centre, radius=radius, dt=dt,
                v_sphere=v_sphere, model=model, iparams=np.array(iparams), seed=rng.integers(2**32))


def call_contact(s: dict, grid_m=None, grid_v=None, cbuf=None):
    grid_v = (s["grid_v"] if grid_v is None else grid_v).copy()
    cbuf = (s["cbuf"] if cbuf is None else cbuf).copy()
    out = np.zeros(ct.N_OUT)
    G = grid_of(ORIGIN, DX, SHAPE, m=s["grid_m"] if grid_m is None else grid_m, v=grid_v, cbuf=cbuf, flags=s["flags"])
    law = ContactLaw(s["model"], s["iparams"], 6.0)  # first step: no node pushed before, none held
    ct.sphere_contact(G, SphereData(s["centre"], s["v_sphere"], s["radius"], 3 * DX), law, 0, s["dt"], out)
    return grid_v, out


def norm(a: np.ndarray) -> np.ndarray:
    return np.sqrt((a * a).sum(1))


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(s=contact_states())
def test_sphere_contact_properties(s):
    m, v0, cb, flags, dt, vs = s["grid_m"], s["grid_v"], s["cbuf"], s["flags"], s["dt"], s["v_sphere"]
    v1, out = call_contact(s)
    ghost = flags == GHOST

    # geometry and classification in the kernel's own floating-point order
    P = NODES - s["centre"]
    d2 = P[:, 0] * P[:, 0] + P[:, 1] * P[:, 1] + P[:, 2] * P[:, 2]
    reach = d2 < (s["radius"] + DX) * (s["radius"] + DX)
    dist = np.sqrt(d2)
    n = P / np.where(dist > 0.0, dist, 1.0)[:, None]
    rel0 = v0 - vs
    vn0 = rel0[:, 0] * n[:, 0] + rel0[:, 1] * n[:, 1] + rel0[:, 2] * n[:, 2]
    acting = reach & (m > 0.0) & (cb[:, 8] > 0.0) & ~ghost & (dist > 0.0)  # nodes the sphere acts on
    contact = acting & (vn0 < 0.0)

    assert np.all(np.isfinite(v1)) and np.all(np.isfinite(out))
    # ghost nodes and all nodes that are not in contact are left exactly as they were
    np.testing.assert_array_equal(v1[ghost], v0[ghost])
    np.testing.assert_array_equal(v1[~contact], v0[~contact])
    assert out[ct.OUT_NODES] == contact.sum()

    # impenetrability: no node the sphere acts on approaches it after the call
    rel1 = v1 - vs
    vn1 = (rel1 * n).sum(1)
    tol_v = 1e-15 * (np.linalg.norm(vs) + norm(v1) + norm(rel0))  # grid_v - v_sphere keeps few digits
    assert np.all(vn1[acting] >= -tol_v[acting])
    assert np.all(np.abs(vn1[contact]) <= tol_v[contact])

    # tangential slip: same direction, never larger (it never reverses, never grows)
    t0 = rel0 - vn0[:, None] * n
    t1 = rel1 - vn1[:, None] * n
    vt0, vt1 = norm(t0), norm(t1)
    c_ = contact
    assert np.all(vt1[c_] <= vt0[c_] + tol_v[c_])
    assert np.all((t0[c_] * t1[c_]).sum(1) >= -tol_v[c_] * vt0[c_])
    assert np.all(norm(np.cross(t0[c_], t1[c_])) <= 2.0 * tol_v[c_] * vt0[c_])

    # traction limit: J_t <= tau A dt, A = |surface vector|, its y component dropped on the mirror plane
    cw = cb[:, 7]
    inv = np.where(cw > 0.0, 1.0 / np.where(cw > 0.0, cw, 1.0), 0.0)
    s6 = cb[:, :6]
    pressure = -(n[:, 0] ** 2 * s6[:, 0] + n[:, 1] ** 2 * s6[:, 1] + n[:, 2] ** 2 * s6[:, 2]
                 + 2.0 * (n[:, 1] * n[:, 2] * s6[:, 3] + n[:, 0] * n[:, 2] * s6[:, 4]
                          + n[:, 0] * n[:, 1] * s6[:, 5])) * inv
    kappa = cb[:, 6] * inv
    f, e = s["iparams"]
    if s["model"] == ct.INTERFACE_PROPORTIONAL:
        law = f * kappa
    elif s["model"] == ct.INTERFACE_CONSTANT:
        law = np.full(N_NODES, f)
    else:
        law = f * np.maximum(pressure, 0.0) ** e
    tau = np.minimum(law, kappa)
    g = cb[:, ct.C_AREA:ct.C_AREA + 3].copy()
    g[flags == MIRROR, 1] = 0.0
    area = norm(g)
    limit = tau * area * dt
    jt = m * (vt0 - vt1)  # loses digits to cancellation when J_t << m vt: allowance m tol_v
    slack = 1e-12 * limit + 2.0 * m * tol_v
    assert np.all(jt[c_] <= limit[c_] + slack[c_])
    expected = np.minimum(m * vt0, limit)
    limited = c_ & (limit < m * vt0)
    yes_no = {True: "yes", False: "no"}
    event(f"contact nodes: {'>= 10' if c_.sum() >= 10 else ('1-9' if c_.any() else '0')}")
    event(f"traction-limited nodes: {yes_no[bool(limited.any())]}")
    event(f"stopped slips: {yes_no[bool((c_ & ~limited).any())]}")
    event(f"traction-limited mirror nodes: {yes_no[bool((limited & (flags == MIRROR)).any())]}")
    assert np.all(np.abs(jt[c_] - expected[c_]) <= 1e-9 * expected[c_] + 2.0 * m[c_] * tol_v[c_])

    # energy: interface slip and the inelastic projection only dissipate
    assert out[ct.OUT_DISSIPATION] >= 0.0 and out[ct.OUT_IMPACT] >= 0.0

    # reaction on the sphere = minus the sum of the impulses on the material per unit time
    dmv = m[:, None] * (v1 - v0)
    force = out[ct.OUT_FN:ct.OUT_FN + 3] + out[ct.OUT_FT:ct.OUT_FT + 3]
    atol = (1e-10 * np.abs(dmv).sum() + 1e-14 * (m * (norm(v0) + norm(v1) + np.linalg.norm(vs))).sum()) / dt
    np.testing.assert_allclose(force, -dmv.sum(0) / dt, rtol=0, atol=atol)

    # ghosts contribute nothing: whatever they carry, the result is bit for bit the same
    if ghost.any():
        rng = np.random.default_rng(s["seed"])
        m2, v2, cb2 = m.copy(), v0.copy(), cb.copy()
        k = int(ghost.sum())
        m2[ghost] = rng.uniform(0.5, 5.0, k) * (m.max() + 1e-30)
        v2[ghost] = vs - n[ghost] * (10.0 * np.abs(v0).max() + 1.0)  # all approaching, fast
        cb2[ghost, :6] = rng.normal(0.0, 1e9, (k, 6))
        cb2[ghost, 6] = 1e9
        cb2[ghost, 7] = 1.0
        cb2[ghost, 8] = 1.0
        cb2[ghost, ct.C_AREA:ct.C_AREA + 3] = DX * DX
        v1g, outg = call_contact(s, grid_m=m2, grid_v=v2, cbuf=cb2)
        np.testing.assert_array_equal(outg, out)
        np.testing.assert_array_equal(v1g[~ghost], v1[~ghost])
        np.testing.assert_array_equal(v1g[ghost], v2[ghost])


# ============================================================================= interface shear
pressures = st.one_of(st.just(0.0), st.floats(-1e12, 1e12), st.floats(-1e3, 1e3))
gaps = st.one_of(st.just(0.0), st.floats(0.0, 1e12), st.floats(0.0, 1e3), st.floats(0.0, 1e-6))
kappas = st.one_of(st.just(0.0), st.floats(1.0, 1e11))


@settings(max_examples=300, deadline=None)
@given(model=st.sampled_from(MODELS), f=st.floats(0.0, 1.0), tau0=st.floats(1e3, 1e11), cp=st.floats(1e-3, 10.0),
       np_=st.floats(0.0, 1.0), p=pressures, gap=gaps, kappa=kappas)
def test_interface_shear_capped_and_monotone(model, f, tau0, cp, np_, p, gap, kappa):
    """0 <= tau <= kappa for every law; tau(P) <= tau(P + gap) for the boundary layer (pressures in Pa,
    tensile ones included, gaps from 0 and below an ulp to 1e12 Pa)."""
    if model == ct.INTERFACE_PROPORTIONAL:
        iparams = np.array([f, 0.0])
    elif model == ct.INTERFACE_CONSTANT:
        iparams = np.array([tau0, 0.0])
    else:
        iparams = np.array([cp, np_])
    lo, hi = p, p + gap
    t_lo = ct.interface_shear(model, iparams, lo, kappa)
    t_hi = ct.interface_shear(model, iparams, hi, kappa)
    for t in (t_lo, t_hi):
        assert 0.0 <= t <= kappa
    if model == ct.INTERFACE_BOUNDARY_LAYER:
        # monotone non-decreasing in pressure (pow is faithful to an ulp, hence the 4 eps allowance)
        assert t_lo <= t_hi * (1.0 + 4 * EPS)
