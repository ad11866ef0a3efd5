"""Constitutive update of the MPM particles: J2 plasticity with radial return.

Implements model.md section 2 (paper eqs. 6.1, 6.2, 7.1, 7.2, 7.3):

- eq. 6.1, stress: sigma = -p I + s. The pressure comes from the linear equation of state
  p = -K eps_v with eps_v = J - 1 (J = det F); the deviatoric stress s is advanced with an objective
  rate (Hughes-Winget incremental rotation) and returned radially to the flow stress
  sigma_y(eps_p, rate, T) by a safeguarded Newton iteration on the consistency condition.
- eq. 6.2, adiabatic heating: dT = beta_TQ * dW_p / (rho cp), with dW_p = sigma_y deps_p the
  plastic work per unit volume and beta_TQ the Taylor-Quinney factor.
- eq. 7.1, Bergstrom-van Liempt (Vegter) flow stress of DX56 steel,
- eq. 7.2, Johnson-Cook flow stress of bulk zinc,
- eq. 7.3, power-law flow stress of the zinc coating,
- and a constant flow stress sigma_y = H / 3 for the rigid-plastic studies (Table 2).

Material data are packed (Python level, :func:`pack_material`) into float64 rows of length
:data:`N_MAT_PARAMS`; the numba kernels read those rows. Layout of a row::

    [I_MODEL]  model code (FLOW_CONSTANT, FLOW_BVL, FLOW_JC, FLOW_POWER) as a float
    [I_K]      bulk modulus K (Pa)           [I_G]   shear modulus G (Pa)
    [I_RHO]    physical density (kg/m^3)     [I_CP]  heat capacity (J/(kg K))
    [5:]       the flow model's parameters (SI), see the I_* constants below.

Rates seen by the flow-stress functions are PHYSICAL equivalent plastic strain rates (1/s); the
simulated rate is multiplied by ``rate_scale = v_experiment / v_simulation`` inside
:func:`return_map_at_rest`. Stress is stored in Voigt order xx, yy, zz, yz, xz, xy.

All per-particle kernels work on scalars only (no heap allocation), so they can run inside a
``prange`` loop over millions of particles.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

import numpy as np
from numba import njit, prange

from plough.materials import (
    BOLTZMANN_EV_PER_K,
    BergstromVanLiempt,
    CoatingPowerLaw,
    ConstantFlow,
    JohnsonCook,
    Material,
)

__all__ = [
    "FLOW_BVL",
    "FLOW_CONSTANT",
    "FLOW_JC",
    "FLOW_POWER",
    "N_MAT_PARAMS",
    "elastic_energy_density",
    "flow_stress",
    "flow_stress_slopes",
    "mixed_flow_stress",
    "mixed_flow_stress_slopes",
    "mixed_moduli",
    "pack_material",
    "pack_materials",
    "rest_flow_stresses",
    "return_map",
    "return_map_at_rest",
    "non_softening",
    "plastic_flow",
    "stress_update",
    "update_stress",
    "update_stresses",
]

# ----------------------------------------------------------------------------- layout
FLOW_CONSTANT = 0
FLOW_BVL = 1
FLOW_JC = 2
FLOW_POWER = 3

I_MODEL = 0
I_K = 1
I_G = 2
I_RHO = 3
I_CP = 4
_I_FLOW = 5

# constant flow stress
I_SIGMA_Y = _I_FLOW + 0
# Bergstrom-van Liempt (eq. 7.1)
I_BVL_SIGMA_F0 = _I_FLOW + 0
I_BVL_DSIGMA_M = _I_FLOW + 1
I_BVL_BETA = _I_FLOW + 2
I_BVL_OMEGA = _I_FLOW + 3
I_BVL_C = _I_FLOW + 4
I_BVL_EPS0 = _I_FLOW + 5
I_BVL_RATE0 = _I_FLOW + 6
I_BVL_SIGMA_V0 = _I_FLOW + 7
I_BVL_M = _I_FLOW + 8
I_BVL_DG0 = _I_FLOW + 9  # activation energy dG0 in eV
I_BVL_KB = _I_FLOW + 10  # Boltzmann constant in eV/K
# Johnson-Cook (eq. 7.2)
I_JC_A = _I_FLOW + 0
I_JC_B = _I_FLOW + 1
I_JC_P = _I_FLOW + 2
I_JC_C = _I_FLOW + 3
I_JC_RATE0 = _I_FLOW + 4
I_JC_Q = _I_FLOW + 5
I_JC_T0 = _I_FLOW + 6
I_JC_TM = _I_FLOW + 7
# coating power law (eq. 7.3)
I_PL_SIGMA_Y0 = _I_FLOW + 0
I_PL_E = _I_FLOW + 1
I_PL_N = _I_FLOW + 2

#: Length of one packed material row.
N_MAT_PARAMS = _I_FLOW + 11

#: Slopes of eps^p (p < 1) and (1 - exp(-omega eps))^c (c < 1) are infinite at eps = 0; they are
#: evaluated at max(eps, SLOPE_EPS_FLOOR) instead (finite and large; values are not affected).
SLOPE_EPS_FLOOR = 1e-200
#: The return map stops when |residual| <= RETURN_RTOL * q_trial.
RETURN_RTOL = 1e-13
RETURN_MAX_ITER = 200
RETURN_MAX_NEWTON = 60
#: The return map starts from the particle's last increment only when the Newton step from the
#: elastic-predictor bound would shrink d by more than a factor 2 (a step below ln 0.5): where the
#: root lies close to the bound (hardening laws without a rate term: the zinc coating's root at
#: 0.998 of the bound, 3 evaluations) a guess below it costs evaluations (5 from 0.99 d, 9 from
#: 0.5 d); where a rate term puts the root far below it (DX56: 1/300 of the bound, 8-9
#: evaluations) the guess saves them.
GUESS_NEWTON_LOG_STEP = math.log(0.5)


# ----------------------------------------------------------------------------- packing
def pack_material(mat: Material) -> np.ndarray:
    """One material as a float64 row of length :data:`N_MAT_PARAMS` (layout: module docstring)."""
    row = np.zeros(N_MAT_PARAMS, dtype=np.float64)
    row[I_K] = mat.bulk_modulus_Pa
    row[I_G] = mat.shear_modulus_Pa
    row[I_RHO] = mat.density_kg_m3
    row[I_CP] = mat.heat_capacity_J_kgK
    f = mat.flow
    if isinstance(f, ConstantFlow):
        row[I_MODEL] = FLOW_CONSTANT
        row[I_SIGMA_Y] = f.sigma_y_Pa
    elif isinstance(f, BergstromVanLiempt):
        row[I_MODEL] = FLOW_BVL
        row[I_BVL_SIGMA_F0] = f.sigma_f0_Pa
        row[I_BVL_DSIGMA_M] = f.dsigma_m_Pa
        row[I_BVL_BETA] = f.beta
        row[I_BVL_OMEGA] = f.omega
        row[I_BVL_C] = f.c
        row[I_BVL_EPS0] = f.eps0
        row[I_BVL_RATE0] = f.rate0_per_s
        row[I_BVL_SIGMA_V0] = f.sigma_v0_Pa
        row[I_BVL_M] = f.m
        row[I_BVL_DG0] = f.dG0_eV
        row[I_BVL_KB] = BOLTZMANN_EV_PER_K
    elif isinstance(f, JohnsonCook):
        row[I_MODEL] = FLOW_JC
        row[I_JC_A] = f.A_Pa
        row[I_JC_B] = f.B_Pa
        row[I_JC_P] = f.p
        row[I_JC_C] = f.C
        row[I_JC_RATE0] = f.rate0_per_s
        row[I_JC_Q] = f.q
        row[I_JC_T0] = f.T0_K
        row[I_JC_TM] = f.Tm_K
    elif isinstance(f, CoatingPowerLaw):
        row[I_MODEL] = FLOW_POWER
        row[I_PL_SIGMA_Y0] = f.sigma_y0_Pa
        row[I_PL_E] = f.E_Pa
        row[I_PL_N] = f.n
    else:  # pragma: no cover - Material.__post_init__ already rejects this
        raise TypeError(f"pack_material: unknown flow model {f!r} of material {mat.name!r}")
    return row


def pack_materials(mats: Sequence[Material]) -> np.ndarray:
    """Materials as a (len(mats), N_MAT_PARAMS) float64 table; row i = pack_material(mats[i])."""
    table = np.zeros((len(mats), N_MAT_PARAMS), dtype=np.float64)
    for i, mat in enumerate(mats):
        table[i] = pack_material(mat)
    return table


# ----------------------------------------------------------------------------- flow stress
@njit(cache=True)
def flow_stress_slopes(prm, eps_p, rate, T):
    """Flow stress and its analytic slopes for one packed material row.

    Reads ``prm`` (packed row), ``eps_p`` (equivalent plastic strain, clamped to >= 0),
    ``rate`` (PHYSICAL equivalent plastic strain rate, 1/s) and ``T`` (K); writes nothing.
    Returns ``(sigma_y, dsigma/deps_p, dsigma/drate)`` in Pa, Pa, Pa s.

    Slopes that are infinite at eps_p = 0 (eps^p with p < 1 in eq. 7.2, (1 - exp(..))^c with
    c < 1 in eq. 7.1 when eps0 = 0) are evaluated at SLOPE_EPS_FLOOR: finite, large. The BvL rate
    slope is 0 where the thermally activated term is switched off (rate <= 0 or its base <= 0);
    the JC rate slope is 0 for rate <= rate0 (see :func:`flow_stress`). An unknown model code
    gives NaN.
    """
    model = int(prm[I_MODEL])
    eps = max(eps_p, 0.0)
    if model == FLOW_CONSTANT:
        return prm[I_SIGMA_Y], 0.0, 0.0
    elif model == FLOW_BVL:
        e1 = eps + prm[I_BVL_EPS0]
        omega = prm[I_BVL_OMEGA]
        c = prm[I_BVL_C]
        dsm = prm[I_BVL_DSIGMA_M]
        y = -math.expm1(-omega * e1)
        yc = y**c
        sig = prm[I_BVL_SIGMA_F0] + dsm * (prm[I_BVL_BETA] * e1 + yc)
        # the slopes reuse the powers and exponentials of the value (y^(c-1) = y^c / y,
        # exp(-omega e1) = 1 - y): this function runs in every Newton step of the return map
        if e1 >= SLOPE_EPS_FLOOR and y > 0.0:
            dse = dsm * (prm[I_BVL_BETA] + c * (yc / y) * omega * (1.0 - y))
        else:
            e1s = max(e1, SLOPE_EPS_FLOOR)
            ys = -math.expm1(-omega * e1s)
            dse = dsm * (prm[I_BVL_BETA] + c * ys ** (c - 1.0) * omega * math.exp(-omega * e1s))
        dsr = 0.0
        if rate > 0.0:
            kt = prm[I_BVL_KB] * T / prm[I_BVL_DG0]
            x = 1.0 + kt * math.log(rate / prm[I_BVL_RATE0])
            if x > 0.0:
                m = prm[I_BVL_M]
                sv0 = prm[I_BVL_SIGMA_V0]
                xm = x**m
                sig += sv0 * xm
                if x >= SLOPE_EPS_FLOOR:
                    dsr = sv0 * m * (xm / x) * kt / rate
                else:
                    dsr = sv0 * m * SLOPE_EPS_FLOOR ** (m - 1.0) * kt / rate
        return sig, dse, dsr
    elif model == FLOW_JC:
        B = prm[I_JC_B]
        p = prm[I_JC_P]
        ep = eps**p
        h = prm[I_JC_A] + B * ep
        dh = B * p * (ep / eps if eps >= SLOPE_EPS_FLOOR else SLOPE_EPS_FLOOR ** (p - 1.0))
        rate0 = prm[I_JC_RATE0]
        rf = 1.0
        drf = 0.0
        if rate > rate0:
            C = prm[I_JC_C]
            rf = 1.0 + C * math.log(rate / rate0)
            drf = C / rate
        T0 = prm[I_JC_T0]
        theta = min(max((T - T0) / (prm[I_JC_TM] - T0), 0.0), 1.0)
        tf = 1.0 - theta ** prm[I_JC_Q]
        return h * rf * tf, dh * rf * tf, h * drf * tf
    elif model == FLOW_POWER:
        s0 = prm[I_PL_SIGMA_Y0]
        E = prm[I_PL_E]
        n = prm[I_PL_N]
        base = 1.0 + E * eps / s0
        bn = base**n
        return s0 * bn, n * E * bn / base, 0.0
    return math.nan, math.nan, math.nan


@njit(cache=True)
def flow_stress(prm, eps_p, rate, T):
    """Flow stress sigma_y (Pa) of one packed material row; reads its arguments, writes nothing.

    ``eps_p``: equivalent plastic strain (clamped to >= 0); ``rate``: PHYSICAL equivalent plastic
    strain rate (1/s); ``T``: temperature (K). Models (kB in eV/K, dG0 in eV):

    - constant:  sigma_y
    - BvL, eq. 7.1: sigma_f0 + dsigma_m (beta (eps + eps0) + (1 - exp(-omega (eps + eps0)))^c)
      + sigma_v0 max(0, 1 + (kB T / dG0) ln(rate / rate0))^m; the last term is 0 for rate <= 0.
    - JC, eq. 7.2: (A + B eps^p)(1 + C ln(max(rate, rate0) / rate0))(1 - theta^q), with
      theta = clip((T - T0) / (Tm - T0), 0, 1). Decision: rates below rate0 give no rate softening
      (the usual Johnson-Cook convention), so the rate factor is >= 1 for C >= 0.
    - power law, eq. 7.3: sigma_y0 (1 + E eps / sigma_y0)^n.

    An unknown model code gives NaN.
    """
    model = int(prm[I_MODEL])
    eps = max(eps_p, 0.0)
    if model == FLOW_CONSTANT:
        return prm[I_SIGMA_Y]
    elif model == FLOW_BVL:
        e1 = eps + prm[I_BVL_EPS0]
        y = -math.expm1(-prm[I_BVL_OMEGA] * e1)
        sig = prm[I_BVL_SIGMA_F0] + prm[I_BVL_DSIGMA_M] * (prm[I_BVL_BETA] * e1 + y ** prm[I_BVL_C])
        if rate > 0.0:
            kt = prm[I_BVL_KB] * T / prm[I_BVL_DG0]
            x = 1.0 + kt * math.log(rate / prm[I_BVL_RATE0])
            if x > 0.0:
                sig += prm[I_BVL_SIGMA_V0] * x ** prm[I_BVL_M]
        return sig
    elif model == FLOW_JC:
        h = prm[I_JC_A] + prm[I_JC_B] * eps ** prm[I_JC_P]
        rate0 = prm[I_JC_RATE0]
        rf = 1.0
        if rate > rate0:
            rf = 1.0 + prm[I_JC_C] * math.log(rate / rate0)
        T0 = prm[I_JC_T0]
        theta = min(max((T - T0) / (prm[I_JC_TM] - T0), 0.0), 1.0)
        return h * rf * (1.0 - theta ** prm[I_JC_Q])
    elif model == FLOW_POWER:
        s0 = prm[I_PL_SIGMA_Y0]
        return s0 * (1.0 + prm[I_PL_E] * eps / s0) ** prm[I_PL_N]
    return math.nan


@njit(cache=True)
def mixed_flow_stress(prm_a, prm_b, frac_a, eps_p, rate, T):
    """Volume-weighted flow stress frac_a sigma_a + (1 - frac_a) sigma_b of a mixed particle.

    Reads two packed rows (a: e.g. coating, b: substrate) and the state; writes nothing.
    ``frac_a`` = 1 (or 0) evaluates only a (or b).
    """
    if frac_a >= 1.0:
        return flow_stress(prm_a, eps_p, rate, T)
    if frac_a <= 0.0:
        return flow_stress(prm_b, eps_p, rate, T)
    return frac_a * flow_stress(prm_a, eps_p, rate, T) + (1.0 - frac_a) * flow_stress(
        prm_b, eps_p, rate, T
    )


@njit(cache=True)
def mixed_flow_stress_slopes(prm_a, prm_b, frac_a, eps_p, rate, T):
    """Volume-weighted (sigma_y, dsigma/deps_p, dsigma/drate) of a mixed particle.

    Same arguments as :func:`mixed_flow_stress`; reads them, writes nothing.
    """
    if frac_a >= 1.0:
        return flow_stress_slopes(prm_a, eps_p, rate, T)
    if frac_a <= 0.0:
        return flow_stress_slopes(prm_b, eps_p, rate, T)
    sa, ea, ra = flow_stress_slopes(prm_a, eps_p, rate, T)
    sb, eb, rb = flow_stress_slopes(prm_b, eps_p, rate, T)
    fb = 1.0 - frac_a
    return frac_a * sa + fb * sb, frac_a * ea + fb * eb, frac_a * ra + fb * rb


@njit(cache=True)
def mixed_moduli(prm_a, prm_b, frac_a):
    """Volume-weighted (Voigt) bulk and shear moduli (K, G) in Pa; reads two packed rows."""
    fb = 1.0 - frac_a
    return frac_a * prm_a[I_K] + fb * prm_b[I_K], frac_a * prm_a[I_G] + fb * prm_b[I_G]


# ----------------------------------------------------------------------------- return map
@njit(cache=True)
def return_map(prm_a, prm_b, frac_a, q_trial, G, eps_p, dt, rate_scale, T):
    """Radial return of J2 plasticity: the plastic strain increment of one particle.

    :func:`return_map_at_rest` with the flow stress at rest sigma_y(eps_p, 0, T) evaluated here
    and no starting guess; returns ``(d, sigma_y)``.
    """
    d, sig, _ = return_map_at_rest(prm_a, prm_b, frac_a, q_trial, G, eps_p, dt, rate_scale, T,
                                   mixed_flow_stress(prm_a, prm_b, frac_a, eps_p, 0.0, T), 0.0)
    return d, sig


@njit(cache=True)
def non_softening(prm):
    """True if the packed law's flow stress never falls with plastic strain or rate (reads ``prm``).

    Then the return map's residual falls monotonically in the increment and its root is unique,
    so a starting guess cannot lead to another root. A JC rate constant C < 0 (or negative
    hardening moduli) is accepted by the materials data and makes the law softening.
    """
    model = int(prm[I_MODEL])
    if model == FLOW_BVL:
        return prm[I_BVL_DSIGMA_M] >= 0.0 and prm[I_BVL_BETA] >= 0.0 and prm[I_BVL_SIGMA_V0] >= 0.0
    if model == FLOW_JC:
        return prm[I_JC_B] >= 0.0 and prm[I_JC_C] >= 0.0
    if model == FLOW_POWER:
        return prm[I_PL_E] >= 0.0 and prm[I_PL_N] >= 0.0
    return True


@njit(cache=True)
def return_map_at_rest(prm_a, prm_b, frac_a, q_trial, G, eps_p, dt, rate_scale, T, sig0, d_guess):
    """Radial return of J2 plasticity, given the flow stress at rest and a guess of the increment.

    Reads the packed rows, ``frac_a``, the trial von Mises stress ``q_trial`` (Pa), shear modulus
    ``G``, plastic strain ``eps_p``, time step ``dt`` (simulated s), ``rate_scale`` (= v_experiment
    / v_simulation, turns simulated into physical rates), ``T`` (K), the flow stress at rest
    ``sig0`` = sigma_y(eps_p, 0, T) (Pa) and a starting guess ``d_guess`` of the increment (0:
    none); writes nothing.

    Elastic if q_trial <= sig0: returns ``(0.0, sig0, 0)``. Otherwise solves
    f(d) = q_trial - 3 G d - sigma_y(eps_p + d, d / dt * rate_scale, T) = 0  for d >= 0 with a
    safeguarded Newton iteration (full slope df/dd = -3G - dsigma/deps - dsigma/drate *
    rate_scale / dt; steps taken in ln d) on the bracket [0, (q_trial - sig0) / (3G)] (f > 0 at
    the left end, f <= 0 at the right one for non-softening laws; widened to q_trial / (3G) for
    softening ones), bisecting when a Newton step leaves the shrinking bracket, until
    |f| <= RETURN_RTOL * q_trial (or the bracket has collapsed to round-off). The iteration
    starts at the bracket's right end, or at ``d_guess`` if that lies inside the bracket, the
    Newton step from the right end points far below it (:data:`GUESS_NEWTON_LOG_STEP`) and the
    laws are non-softening (:func:`non_softening`: the root is then unique, so the guess changes
    the start, not the root beyond the tolerance).
    Returns ``(d, sigma_y(eps_p + d, d / dt * rate_scale, T), flow-law evaluations)``.

    Why the two inputs: the solver keeps ``sig0`` per particle (``sigma_y0``,
    :func:`rest_flow_stresses`), which changes only when the particle flows, so an elastic step
    (most particles on most steps) costs no flow-law evaluation, and the result is the same to
    the bit as evaluating it here. The guess is the particle's increment on its last plastic step
    (``deps_last``): where a rate term takes up most of the overstress the root lies orders of
    magnitude below the elastic-predictor bound (about 300x for DX56 at the physical rates of the
    real-material scenes) and the Newton steps from that bound take 8-9 evaluations; from a guess
    within 1% of the root, five (the bound, the guess and three Newton steps), within 10%, five
    or six.
    """
    if q_trial <= sig0:
        return 0.0, sig0, 0
    three_g = 3.0 * G
    rate_per_d = rate_scale / dt
    tol = RETURN_RTOL * q_trial
    lo = 0.0
    hi = (q_trial - sig0) / three_g
    x = hi
    sig, dse, dsr = mixed_flow_stress_slopes(prm_a, prm_b, frac_a, eps_p + x, x * rate_per_d, T)
    evals = 1
    f = q_trial - three_g * x - sig
    if f > tol:
        # only for softening laws (e.g. a JC rate constant C < 0): widen to the full return
        hi = q_trial / three_g
        x = hi
        sig, dse, dsr = mixed_flow_stress_slopes(prm_a, prm_b, frac_a, eps_p + x, x * rate_per_d, T)
        evals += 1
        f = q_trial - three_g * x - sig
        if f > 0.0:  # flow stress <= 0 there: the deviator vanishes
            return x, max(sig, 0.0), evals
    df = -three_g - dse - dsr * rate_per_d
    if (abs(f) > tol and 0.0 < d_guess < hi and x * df < 0.0 and -f / (x * df) < GUESS_NEWTON_LOG_STEP
            and non_softening(prm_a) and non_softening(prm_b)):
        # the Newton step from the bound would cut d by more than GUESS_NEWTON_LOG_STEP in ln d:
        # the root lies far below the bound, where the last increment is the better start.
        # f(hi) < 0 and f(0) > 0 still bracket the root; the loop below narrows the bracket
        # from the guess's side
        x = d_guess
        sig, dse, dsr = mixed_flow_stress_slopes(prm_a, prm_b, frac_a, eps_p + x, x * rate_per_d, T)
        evals += 1
        f = q_trial - three_g * x - sig
        df = -three_g - dse - dsr * rate_per_d
    for it in range(RETURN_MAX_ITER):
        if abs(f) <= tol:
            break
        if f > 0.0:
            lo = x
        else:
            hi = x
        if hi - lo <= 1e-15 * hi:
            break
        # Newton step in u = ln d: the residual is close to linear in ln d where the rate term or
        # eps^p hardening dominate, and concave in ln d for the laws here, so from the right of
        # the root these steps approach it monotonically even when it lies orders of magnitude
        # below the elastic-predictor bound; from its left (a guess below the root) a step
        # overshoots to its right, and the bracket catches a step that leaves it.
        # Every evaluation shrinks the bracket; after RETURN_MAX_NEWTON steps (never reached in
        # practice) only bisection, in ln d once the bracket is away from 0, is left.
        xn = -1.0
        dfu = x * df
        if dfu < 0.0 and it < RETURN_MAX_NEWTON:
            du = -f / dfu
            if du < 700.0:
                xn = x * math.exp(du)
        if not (lo < xn < hi):
            xn = math.sqrt(lo * hi) if lo > 0.0 else 0.5 * hi
        x = xn
        sig, dse, dsr = mixed_flow_stress_slopes(prm_a, prm_b, frac_a, eps_p + x, x * rate_per_d, T)
        evals += 1
        f = q_trial - three_g * x - sig
        df = -three_g - dse - dsr * rate_per_d
    return x, sig, evals


# ----------------------------------------------------------------------------- stress update
@njit(cache=True)
def plastic_flow(P, p, q_trial, G, dt, M):
    """The return map of particle ``p``'s plastic trial state (``q_trial`` > ``P.sigma_y0[p]``) and its flow.

    Reads ``P.eps_p[p]``, ``temperature[p]``, ``sigma_y0[p]``, ``deps_last[p]``, the materials (``P.mat_a[p]``,
    ``mat_b[p]``, ``frac_a[p]``, rows of ``M.table``), ``M.rate_scale``, ``M.taylor_quinney``, the shear modulus
    ``G`` and ``dt``. If it flowed (deps_p > 0) writes ``P.eps_p[p] += deps_p``, ``P.temperature[p] +=
    taylor_quinney sigma_y deps_p / (rho cp)``, ``P.sigma_y0[p]`` at the new state and ``P.deps_last[p] = deps_p``.
    Returns ``(deps_p, sigma_y)`` (:func:`return_map_at_rest`). Part of :func:`stress_update`, a call of its own:
    only plastic trial states come here, and its stores must not be inlined into a ``prange`` body (see there).
    """
    eps_p, temperature, sigma_y0, deps_last = P.eps_p, P.temperature, P.sigma_y0, P.deps_last
    prm_a, prm_b, frac_a = M.table[P.mat_a[p]], M.table[P.mat_b[p]], P.frac_a[p]
    T = temperature[p]
    deps, sig_y, _ = return_map_at_rest(prm_a, prm_b, frac_a, q_trial, G, eps_p[p], dt, M.rate_scale, T, sigma_y0[p],
                                        deps_last[p])
    if deps > 0.0:
        w = sig_y * deps
        eps_p[p] += deps
        fb = 1.0 - frac_a
        rho_cp = frac_a * prm_a[I_RHO] * prm_a[I_CP] + fb * prm_b[I_RHO] * prm_b[I_CP]
        temperature[p] = T + M.taylor_quinney * w / rho_cp
        sigma_y0[p] = mixed_flow_stress(prm_a, prm_b, frac_a, eps_p[p], 0.0, temperature[p])
        deps_last[p] = deps
    return deps, sig_y


@njit(cache=True)
def update_stress(P, p, L, dt, M):
    """Advance the Cauchy stress of particle ``p`` by one step (eqs. 6.1 and 6.2).

    Reads, of the particles ``P`` (:class:`plough.mpm.particles.Particles`, or the bundle of its stress fields
    :class:`plough.mpm.bundles.StressState`, which ``g2p_update`` passes): ``P.stress[p]`` ((n, 6) Voigt
    xx, yy, zz, yz, xz, xy; only its deviator is used), ``P.J[p]`` (det F after this step: the caller
    updates it first), ``P.eps_p[p]``, ``P.temperature[p]``, ``P.sigma_y0[p]`` (the flow stress at rest
    sigma_y(eps_p[p], 0, temperature[p]), kept by :func:`rest_flow_stresses`), ``P.deps_last[p]`` (the
    particle's plastic strain increment on its last plastic step, 0 before it first flowed: the return
    map's starting guess) and its materials, the rows ``P.mat_a[p]``/``P.mat_b[p]`` of ``M.table`` with
    volume fraction ``P.frac_a[p]`` of a; ``L`` ((3, 3) velocity gradient of the particle, L[i, j] =
    dv_i/dx_j), ``dt``, and of the materials ``M`` (:class:`plough.mpm.bundles.MaterialData`)
    ``M.rate_scale`` (v_experiment / v_simulation) and the Taylor-Quinney factor ``M.taylor_quinney``.
    Writes: ``P.stress[p]`` (new Cauchy stress), ``P.eps_p[p] += deps_p``, ``P.temperature[p] +=
    taylor_quinney * w / (rho cp)`` and, when it flowed, ``P.sigma_y0[p]`` at the new plastic strain
    and temperature and ``P.deps_last[p] = deps_p``.

    Steps: K, G = Voigt mix of a and b; s = dev(stress[p]); s_trial = R s R^T + 2 G dt dev(sym L)
    with the Hughes-Winget rotation R = (I - dt/2 W)^-1 (I + dt/2 W), W = skew(L) (exactly
    orthogonal); q_trial = sqrt(3/2 s:s); :func:`return_map_at_rest` at the start-of-step
    temperature, from the cached ``sigma_y0[p]`` and the guess ``deps_last[p]``;
    s *= sigma_y / q_trial if plastic; p = -K (J - 1); stress[p] = s - p I. The volumetric heat
    capacity of a mixed particle is frac_a rho_a cp_a + (1 - frac_a) rho_b cp_b (= mixed density
    times mass-weighted cp).

    Returns ``(deps_p, w)``: the plastic strain increment and the plastic work density
    w = sigma_y deps_p (J/m^3 of current volume).
    """
    return stress_update(P.stress, P, p, L, dt, M)


@njit(cache=True, inline="always")
def stress_update(stress, P, p, L, dt, M):
    """:func:`update_stress` with the stress array ``stress`` (= ``P.stress``) handed in apart, inlined in its caller.

    Why apart: numba's parallel dead-code elimination drops a store into an array taken from a named tuple inside a
    ``prange`` body when the body does not read that array again (the tuple is immutable, so its fields are not
    counted as aliases of the arguments; numba issues 7135, 10338). Inlined into ``g2p_update`` with the stress
    written through ``P.stress``, the new stress and ``deps_last`` were never stored. Here the one store of the
    inlined part goes to ``stress``, which the caller takes from its bundle outside the ``prange``; the stores of
    a flowing particle are made by :func:`plastic_flow`, a call of its own (no inlining, so nothing of it can be
    dropped). Same reads, writes, operations and order as :func:`update_stress` documents.
    """
    prm_a, prm_b, frac_a, J = M.table[P.mat_a[p]], M.table[P.mat_b[p]], P.frac_a[p], P.J[p]
    K, G = mixed_moduli(prm_a, prm_b, frac_a)

    # deviatoric part of the old stress
    sxx = stress[p, 0]
    syy = stress[p, 1]
    szz = stress[p, 2]
    tr3 = (sxx + syy + szz) / 3.0
    s11 = sxx - tr3
    s22 = syy - tr3
    s33 = szz - tr3
    s23 = stress[p, 3]
    s13 = stress[p, 4]
    s12 = stress[p, 5]

    # Hughes-Winget rotation via the Cayley formula R = I + 2 / (1 + |t|^2) (Th + Th^2),
    # Th = dt/2 W, t its axial vector (Th v = t x v)
    h = 0.5 * dt
    t1 = h * 0.5 * (L[2, 1] - L[1, 2])
    t2 = h * 0.5 * (L[0, 2] - L[2, 0])
    t3 = h * 0.5 * (L[1, 0] - L[0, 1])
    tt = t1 * t1 + t2 * t2 + t3 * t3
    c = 2.0 / (1.0 + tt)
    r11 = 1.0 + c * (t1 * t1 - tt)
    r22 = 1.0 + c * (t2 * t2 - tt)
    r33 = 1.0 + c * (t3 * t3 - tt)
    r12 = c * (-t3 + t1 * t2)
    r21 = c * (t3 + t1 * t2)
    r13 = c * (t2 + t1 * t3)
    r31 = c * (-t2 + t1 * t3)
    r23 = c * (-t1 + t2 * t3)
    r32 = c * (t1 + t2 * t3)

    # A = R s
    a11 = r11 * s11 + r12 * s12 + r13 * s13
    a12 = r11 * s12 + r12 * s22 + r13 * s23
    a13 = r11 * s13 + r12 * s23 + r13 * s33
    a21 = r21 * s11 + r22 * s12 + r23 * s13
    a22 = r21 * s12 + r22 * s22 + r23 * s23
    a23 = r21 * s13 + r22 * s23 + r23 * s33
    a31 = r31 * s11 + r32 * s12 + r33 * s13
    a32 = r31 * s12 + r32 * s22 + r33 * s23
    a33 = r31 * s13 + r32 * s23 + r33 * s33

    # deviatoric rate of deformation times 2 G dt
    g2 = 2.0 * G * dt
    trd3 = (L[0, 0] + L[1, 1] + L[2, 2]) / 3.0

    # s_trial = A R^T + 2 G dt dev(D)
    n11 = a11 * r11 + a12 * r12 + a13 * r13 + g2 * (L[0, 0] - trd3)
    n22 = a21 * r21 + a22 * r22 + a23 * r23 + g2 * (L[1, 1] - trd3)
    n33 = a31 * r31 + a32 * r32 + a33 * r33 + g2 * (L[2, 2] - trd3)
    n23 = a21 * r31 + a22 * r32 + a23 * r33 + g2 * 0.5 * (L[1, 2] + L[2, 1])
    n13 = a11 * r31 + a12 * r32 + a13 * r33 + g2 * 0.5 * (L[0, 2] + L[2, 0])
    n12 = a11 * r21 + a12 * r22 + a13 * r23 + g2 * 0.5 * (L[0, 1] + L[1, 0])
    # keep the trial deviator exactly traceless
    ntr3 = (n11 + n22 + n33) / 3.0
    n11 -= ntr3
    n22 -= ntr3
    n33 -= ntr3

    q_trial = math.sqrt(
        1.5 * (n11 * n11 + n22 * n22 + n33 * n33 + 2.0 * (n23 * n23 + n13 * n13 + n12 * n12))
    )
    deps, sig_y = 0.0, P.sigma_y0[p]
    if q_trial > sig_y:  # only a plastic trial state calls the return map (an elastic one would return these)
        deps, sig_y = plastic_flow(P, p, q_trial, G, dt, M)
    w = 0.0
    if deps > 0.0:
        scale = sig_y / q_trial
        n11 *= scale
        n22 *= scale
        n33 *= scale
        n23 *= scale
        n13 *= scale
        n12 *= scale
        w = sig_y * deps

    minus_p = K * (J - 1.0)  # -p, with p = -K (J - 1)
    stress[p, 0] = n11 + minus_p
    stress[p, 1] = n22 + minus_p
    stress[p, 2] = n33 + minus_p
    stress[p, 3] = n23
    stress[p, 4] = n13
    stress[p, 5] = n12
    return deps, w


@njit(cache=True)
def elastic_energy_density(stress, p, K, G):
    """Elastic strain energy per volume s:s / (4 G) + p^2 / (2 K) of ``stress[p]`` (J/m^3).

    Reads row p of the (n, 6) Voigt stress array (xx, yy, zz, yz, xz, xy); writes nothing.
    """
    sxx = stress[p, 0]
    syy = stress[p, 1]
    szz = stress[p, 2]
    tr3 = (sxx + syy + szz) / 3.0
    d1 = sxx - tr3
    d2 = syy - tr3
    d3 = szz - tr3
    ss = (
        d1 * d1
        + d2 * d2
        + d3 * d3
        + 2.0 * (stress[p, 3] ** 2 + stress[p, 4] ** 2 + stress[p, 5] ** 2)
    )
    return ss / (4.0 * G) + tr3 * tr3 / (2.0 * K)


@njit(cache=True, parallel=True)
def update_stresses(P, L_all, dt, M, deps_out, work_out):
    """Parallel driver: :func:`update_stress` for every particle of ``P``.

    Reads ``L_all`` (n, 3, 3) and what :func:`update_stress` reads; updates ``P.stress``, ``P.eps_p``,
    ``P.temperature``, ``P.sigma_y0`` and ``P.deps_last`` in place and writes ``deps_out[i]`` (plastic
    strain increment) and ``work_out[i]`` (plastic work density, J/m^3). Each particle writes only its
    own entries: race-free.
    """
    for i in prange(P.stress.shape[0]):
        d, w = update_stress(P, i, L_all[i], dt, M)
        deps_out[i] = d
        work_out[i] = w


@njit(cache=True, parallel=True)
def rest_flow_stresses(eps_p, temperature, mat_a, mat_b, frac_a, table, sigma_y0):
    """The flow stress at rest sigma_y(eps_p, 0, T) of every particle (the cache ``update_stress`` keeps).

    Reads eps_p, temperature, the materials (``mat_a``/``mat_b`` rows of ``table``, ``frac_a``);
    writes ``sigma_y0[i]`` = :func:`mixed_flow_stress` at zero plastic strain rate. Each particle
    writes only its own entry.
    """
    for i in prange(eps_p.shape[0]):
        sigma_y0[i] = mixed_flow_stress(table[mat_a[i]], table[mat_b[i]], frac_a[i], eps_p[i], 0.0, temperature[i])
