"""Analytical model (eqs. 1-5) against hand-evaluated closed forms and its physical limits."""

import math

import numpy as np
import pytest

from plough.analytical import ploughing, segment_area
from plough.materials import K0

R = 200e-6
FN = 3.0


def _case1_by_hand(Fn, r, t, Hc, Hs, k1):
    Hcs = Hc + (Hs - Hc) * math.exp(-k1 * t / r)
    Axy = Fn / Hcs
    a = math.sqrt(2 * Axy / math.pi)
    dp = r - math.sqrt(r * r - a * a)
    h = r - dp
    Ayz = r * r * math.atan(a / h) - a * h
    return Hcs, Axy, a, dp, Ayz


def _case2_by_hand(Fn, r, t, Hc, Hs, k1):
    Hcs = Hc + (Hs - Hc) * math.exp(-k1 * t / r)
    A = 0.5 * math.pi * Hs
    B = math.pi * (Hcs * t - Hs * r)
    C = Fn - 0.5 * math.pi * t * (2 * r - t) * Hcs
    ds = (-B - math.sqrt(B * B - 4 * A * C)) / (2 * A)
    dp = ds + t
    a_s = math.sqrt(r * r - (r - ds) ** 2)
    a = math.sqrt(r * r - (r - dp) ** 2)
    Axys = 0.5 * math.pi * a_s**2
    Axyc = 0.5 * math.pi * t * (2 * (r - ds) - t)
    Ayzs = r * r * math.atan(a_s / (r - ds)) - a_s * (r - ds)
    Ayz = r * r * math.atan(a / (r - dp)) - a * (r - dp)
    return dict(Hcs=Hcs, ds=ds, dp=dp, a=a, a_s=a_s, Axys=Axys, Axyc=Axyc, Ayzs=Ayzs, Ayz=Ayz,
                Ayzc=Ayz - Ayzs)


def test_segment_area_limits():
    # a half disc when the chord passes through the centre, a thin-segment limit 4/3 a d
    assert segment_area(1.0, 1.0, 0.0) == pytest.approx(math.pi / 2, rel=1e-15)
    r, d = 1.0, 1e-4
    a = math.sqrt(2 * r * d - d * d)
    assert segment_area(r, a, r - d) == pytest.approx(4 / 3 * a * d, rel=1e-3)


def test_case1_hand_values():
    Hc, Hs, t, k1 = 450e6, 900e6, 25e-6, 125.0
    Hcs, Axy, a, dp, Ayz = _case1_by_hand(FN, R, t, Hc, Hs, k1)
    res = ploughing(FN, R, t, Hc, Hs, k1=k1)
    assert res.regime == 1
    assert res.Hcs == pytest.approx(Hcs, rel=1e-14)
    assert res.Axy == pytest.approx(Axy, rel=1e-12)
    assert res.a == pytest.approx(a, rel=1e-12)
    assert res.dp == pytest.approx(dp, rel=1e-12)
    assert res.Ayz == pytest.approx(Ayz, rel=1e-10)
    assert res.Axys == 0 and res.Ayzs == 0 and res.Axyc == res.Axy
    # eqs 4.1-4.4, proportional shear f = 1
    assert res.mu_pl == pytest.approx(Hc * Ayz / FN, rel=1e-10)
    assert res.mu_sh == pytest.approx(Hc / K0 * Axy / FN, rel=1e-10)
    assert res.mu == pytest.approx(res.mu_pl + res.mu_sh, rel=1e-15)
    # spot value computed once by hand: dp = 10.9078 um for a 450 MPa coating
    assert res.dp == pytest.approx(10.9078e-6, rel=1e-5)


def test_case2_hand_values():
    Hc, Hs, t, k1 = 450e6, 900e6, 2e-6, 12.5
    ref = _case2_by_hand(FN, R, t, Hc, Hs, k1)
    res = ploughing(FN, R, t, Hc, Hs, k1=k1)
    assert res.regime == 2 and res.coating_worn
    for key, value in ref.items():
        assert getattr(res, key) == pytest.approx(value, rel=1e-9), key
    assert res.mu_pl == pytest.approx((Hs * ref["Ayzs"] + Hc * ref["Ayzc"]) / FN, rel=1e-9)
    assert res.mu_sh == pytest.approx((Hs * ref["Axys"] + Hc * ref["Axyc"]) / K0 / FN, rel=1e-9)


@pytest.mark.parametrize("Hc,Hs", [(450e6, 900e6), (900e6, 450e6), (90e6, 900e6)])
def test_load_balance_in_regime_2(Hc, Hs):
    t = np.linspace(0.0, 5e-6, 51)
    res = ploughing(FN, R, t, Hc, Hs, k1=12.5)
    two = res.regime == 2
    assert two.sum() > 10
    carried = Hs * res.Axys + res.Hcs * res.Axyc
    np.testing.assert_allclose(carried[two], FN, rtol=1e-9)
    # the areas add up: Axy = Axys + Axyc
    np.testing.assert_allclose((res.Axys + res.Axyc)[two], res.Axy[two], rtol=1e-9)


def _transition_thickness(Hc, Hs, k1=12.5, r=R, Fn=FN):
    lo, hi = 1e-9, 1e-3  # regime 2 at lo, regime 1 at hi
    for _ in range(200):
        mid = 0.5 * (lo + hi)
        if ploughing(Fn, r, mid, Hc, Hs, k1=k1).regime == 2:
            lo = mid
        else:
            hi = mid
    return 0.5 * (lo + hi)


def test_reference_transitions_of_model_md():
    # model.md: dp = t at about 6.5 um (soft coating) and 7.8 um (hard coating)
    assert _transition_thickness(450e6, 900e6) * 1e6 == pytest.approx(6.5, abs=0.05)
    assert _transition_thickness(900e6, 450e6) * 1e6 == pytest.approx(7.8, abs=0.05)


@pytest.mark.parametrize("Hc,Hs,interface", [(450e6, 900e6, "proportional"),
                                              (900e6, 450e6, "constant"),
                                              (200e6, 900e6, "boundary_layer")])
def test_continuity_at_dp_equals_t(Hc, Hs, interface):
    t_star = _transition_thickness(Hc, Hs)
    below = ploughing(FN, R, t_star * (1 - 1e-9), Hc, Hs, k1=12.5, interface=interface)
    above = ploughing(FN, R, t_star * (1 + 1e-9), Hc, Hs, k1=12.5, interface=interface)
    assert below.regime == 2 and above.regime == 1
    for name, value in below.as_dict().items():
        if name in ("regime", "ds", "a_s", "Axys", "Ayzs"):
            continue
        assert value == pytest.approx(getattr(above, name), rel=1e-6, abs=1e-18), name
    # substrate parts vanish continuously
    assert below.ds < 1e-6 * t_star and below.Axys < 1e-6 * below.Axy


def test_thin_and_thick_limits():
    Hc, Hs = 450e6, 900e6
    uncoated = ploughing(FN, R, 0.0, Hc, Hs, k1=12.5)
    bulk_substrate = ploughing(FN, R, 1.0, Hs, Hs, k1=12.5)
    for name in ("dp", "a", "Axy", "Ayz", "mu_pl", "mu_sh", "mu"):
        assert getattr(uncoated, name) == pytest.approx(getattr(bulk_substrate, name), rel=1e-10)
    thick = ploughing(FN, R, 1.0, Hc, Hs, k1=12.5)  # t = 1 m: exp(-k1 t / r) = 0
    bulk_coating = ploughing(FN, R, 1.0, Hc, Hc, k1=12.5)
    for name in ("dp", "a", "Axy", "Ayz", "mu_pl", "mu_sh", "mu"):
        assert getattr(thick, name) == pytest.approx(getattr(bulk_coating, name), rel=1e-12)
    # and the uncoated case is the textbook one: Axy = Fn / Hs
    assert uncoated.Axy == pytest.approx(FN / Hs, rel=1e-9)


def test_scalar_and_vectorised_identical():
    rng = np.random.default_rng(1)
    n = 200
    load = rng.uniform(0.5, 20, n)
    t = rng.uniform(0, 60e-6, n)
    Hc = rng.uniform(50e6, 2e9, n)
    for interface in ("proportional", "constant", "boundary_layer"):
        vec = ploughing(load, 0.5e-3, t, Hc, 900e6, k1=12.5, interface=interface, correction="once")
        for i in range(0, n, 7):
            one = ploughing(load[i], 0.5e-3, t[i], Hc[i], 900e6, k1=12.5, interface=interface,
                            correction="once")
            for name, value in one.as_dict().items():
                np.testing.assert_allclose(getattr(vec, name)[i], value, rtol=1e-14, atol=0,
                                           err_msg=name)


def test_broadcasting_shapes():
    res = ploughing(np.array([1.0, 2.0, 3.0])[:, None], R, np.array([0.0, 5e-6, 50e-6]), 450e6, 900e6)
    assert res.mu.shape == (3, 3) and res.regime.shape == (3, 3)


def test_interface_models():
    Hc, Hs, t = 450e6, 900e6, 2e-6
    prop = ploughing(FN, R, t, Hc, Hs, k1=12.5, f=0.5)
    assert prop.tau_c == pytest.approx(0.5 * Hc / K0) and prop.tau_s == pytest.approx(0.5 * Hs / K0)
    const = ploughing(FN, R, t, Hc, Hs, k1=12.5, interface="constant", H0_Pa=450e6)
    assert const.tau_c == const.tau_s == pytest.approx(450e6 / K0)
    bl = ploughing(FN, R, t, Hc, Hs, k1=12.5, interface="boundary_layer", Cp=0.32, np_exponent=0.95)
    assert bl.tau_c == pytest.approx(0.32 * (FN / bl.Axy) ** 0.95, rel=1e-12)
    assert bl.mu_sh == pytest.approx(bl.tau_c * bl.Axy / FN, rel=1e-12)
    # the ploughing part does not depend on the interface without correction
    assert prop.mu_pl == const.mu_pl == bl.mu_pl


def test_normal_load_correction():
    Hc, Hs, t = 450e6, 900e6, 25e-6
    none = ploughing(FN, R, t, Hc, Hs)
    # proportional shear, f = 1: Fz_sh / Fn = mu_pl / k0 (model.md)
    assert none.Fz_sh / FN == pytest.approx(none.mu_pl / K0, rel=1e-12)
    once = ploughing(FN, R, t, Hc, Hs, correction="once")
    assert once.load_carried == pytest.approx(FN + none.Fz_sh, rel=1e-14)
    assert once.dp > none.dp
    conv = ploughing(FN, R, t, Hc, Hs, correction="converged")
    assert conv.load_carried == pytest.approx(FN + conv.Fz_sh, rel=1e-10)
    assert conv.dp > once.dp > none.dp
    assert conv.dp - once.dp < once.dp - none.dp  # a contraction


@pytest.mark.parametrize(
    "kwargs,match",
    [
        (dict(radius_m=0.0), r"radius_m = 0 m .* > 0"),
        (dict(radius_m=-1e-3), r"radius_m = -0.001 m"),
        (dict(load_N=-1.0), r"load_N = -1 N .* > 0"),
        (dict(coating_hardness_Pa=0.0), r"coating_hardness_Pa = 0 Pa"),
        (dict(substrate_hardness_Pa=-5.0), r"substrate_hardness_Pa = -5 Pa"),
        (dict(thickness_m=-1e-6), r"thickness_m = -1e-06 m .* >= 0"),
        (dict(k1=0.0), r"k1 = 0 "),
        (dict(f=1.5), r"f = 1.5 is outside the allowed range \[0, 1\]"),
        (dict(f=-0.1), r"f = -0.1 is outside"),
        (dict(load_N=1e4), r"load_N = 10000 N is too large for radius_m = 0.0002 m: the model .* dp < r"),
        (dict(interface="constant", H0_Pa=1e10, correction="converged"),
         r"load_N = 3 N is too large for radius_m = 0.0002 m once the normal-load correction .* 'converged'\) has "
         r"raised the carried load to [0-9.e+]+ N"),
        (dict(interface="sticky"), r"interface = 'sticky' is unknown; allowed: proportional"),
        (dict(correction="twice"), r"correction = 'twice' is unknown"),
        (dict(load_N=np.array([1.0, np.nan])), r"load_N = nan N"),
    ],
)
def test_bad_input(kwargs, match):
    args = dict(load_N=FN, radius_m=R, thickness_m=25e-6, coating_hardness_Pa=450e6,
                substrate_hardness_Pa=900e6)
    args.update(kwargs)
    with pytest.raises(ValueError, match=match):
        ploughing(**args)


def test_large_load_on_thin_hard_coating_is_refused_not_nan():
    with pytest.raises(ValueError, match="too large"):
        ploughing(400.0, R, 2e-6, 900e6, 450e6, k1=12.5)
