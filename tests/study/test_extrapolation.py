"""Tests of plough.study.extrapolation on synthetic data with known limits and orders."""

import numpy as np
import pytest
import xarray as xr

from plough.study.extrapolation import (
    FLAG_MEANINGS,
    Method,
    extrapolate,
    extrapolate_dataarray,
    sampling_error,
    total_uncertainty,
)

F0 = 0.3
SIZES = {
    "uniform": np.array([2.5, 5.0, 10.0]),
    "non_uniform": np.array([3.0, 5.0, 10.0]),
    # ln r32 > 2 ln r21: Celik's fixed-point iteration would diverge here.
    "strongly_non_uniform": np.array([2.5, 3.0, 10.0]),
}


@pytest.mark.parametrize("sizes", SIZES.values(), ids=SIZES.keys())
@pytest.mark.parametrize("p", [1.0, 2.0, 1.5])
@pytest.mark.parametrize("c", [0.01, -0.2])
def test_synthetic_power_law_recovers_limit_and_order(sizes, p, c):
    res = extrapolate(sizes, F0 + c * sizes**p)
    assert res.method == Method.RICHARDSON
    assert not res.flagged
    assert res.value == pytest.approx(F0, abs=1e-10)
    assert res.order == pytest.approx(p, rel=1e-9)
    # Roache's GCI of the finest solution, absolute form: Fs = 1.25 at the formal order 1; an
    # observed order above it gets Fs = 3 with the order bounded to 1 (Oberkampf & Roy).
    r = sizes[1] / sizes[0]
    e21 = c * (sizes[0] ** p - sizes[1] ** p)
    expected = 1.25 * abs(e21) / (r - 1) if p == 1.0 else 3.0 * abs(e21) / (r - 1)
    assert res.uncertainty == pytest.approx(expected, rel=1e-9)


@pytest.mark.parametrize(
    ("p", "fs", "band_order"),
    [
        (1.09, 1.25, 1.0),  # within 10% of the formal order: Roache's asymptotic Fs, the order at most 1
        (1.1, 1.25, 1.0),  # on the edges of the 10% alike
        (0.9, 1.25, 0.9),
        (0.91, 1.25, 0.91),
        (1.12, 3.0, 1.0),  # just outside: Fs = 3, the order bounded to the formal one
        (2.7, 3.0, 1.0),  # error cancellation between sizes must not shrink the band 5x
        (0.7, 3.0, 0.7),  # below the formal order: Fs = 3 at the observed order
        (0.5, 3.0, 0.5),
    ],
)
def test_gci_safety_factor_follows_the_distance_of_the_observed_order_from_the_formal(p, fs, band_order):
    h = SIZES["uniform"]
    f = F0 + 0.02 * h**p
    res = extrapolate(h, f)
    assert res.method == Method.RICHARDSON
    assert res.value == pytest.approx(F0, abs=1e-10)  # the value keeps the observed order
    e21 = f[0] - f[1]
    assert res.uncertainty == pytest.approx(fs * abs(e21) / (2.0**band_order - 1), rel=1e-9)


@pytest.mark.parametrize("sizes", SIZES.values(), ids=SIZES.keys())
@pytest.mark.parametrize("p", [0.15, 0.4, 0.8, 0.95, 1.0, 1.05, 1.3, 2.0, 3.5, 5.5])
@pytest.mark.parametrize("c", [0.02, -0.3])
def test_gci_band_covers_the_finest_value_and_the_formal_order_extrapolation(sizes, p, c):
    # orders outside the default bounds too: the band must not narrow below the formal order's however far p is
    f = F0 + c * sizes**p
    res = extrapolate(sizes, f, order_bounds=(0.1, 6.0))
    assert res.method == Method.RICHARDSON
    e21 = f[0] - f[1]
    formal = f[0] + e21 / (sizes[1] / sizes[0] - 1)
    assert res.uncertainty >= abs(res.value - f[0]) * (1 - 1e-12)
    if abs(p - 1) > 0.1:
        assert res.uncertainty >= abs(res.value - formal) * (1 - 1e-12)


def test_gci_band_judges_the_observed_order_against_the_assumed_one():
    h = SIZES["uniform"]
    f = F0 + 0.02 * h**2
    formal_two = extrapolate(h, f, assumed_order=2.0)
    e21 = f[0] - f[1]
    assert formal_two.uncertainty == pytest.approx(1.25 * abs(e21) / 3.0, rel=1e-9)
    assert extrapolate(h, f).uncertainty == pytest.approx(3.0 * abs(e21), rel=1e-9)


def test_a_given_safety_factor_is_the_plain_gci_at_the_observed_order():
    h = SIZES["uniform"]
    f = F0 + 0.02 * h**2
    e21 = f[0] - f[1]
    assert extrapolate(h, f, safety_factor=1.25).uncertainty == pytest.approx(1.25 * abs(e21) / 3.0, rel=1e-9)


def test_sizes_in_any_order():
    h = np.array([10.0, 2.5, 5.0])
    res = extrapolate(h, F0 + 0.01 * h**2)
    assert res.value == pytest.approx(F0, abs=1e-12)
    assert res.order == pytest.approx(2.0, rel=1e-9)
    np.testing.assert_array_equal(res.h, [2.5, 5.0, 10.0])


def test_more_than_three_sizes_use_the_finest_three():
    h = np.array([2.5, 5.0, 10.0, 20.0])
    f = F0 + 0.01 * h**2
    f[-1] = 7.0  # an arbitrary coarsest value must not change the Richardson result
    res = extrapolate(h, f)
    assert res.method == Method.RICHARDSON
    assert res.value == pytest.approx(F0, abs=1e-12)
    assert res.order == pytest.approx(2.0, rel=1e-9)


@pytest.mark.parametrize("sizes", SIZES.values(), ids=SIZES.keys())
def test_higher_order_term_is_bracketed(sizes):
    f = F0 + 0.01 * sizes + 0.001 * sizes**2
    res = extrapolate(sizes, f)
    assert res.method == Method.RICHARDSON
    assert 1.0 < res.order < 2.0
    assert abs(res.value - F0) < abs(f[0] - F0)
    assert abs(res.value - F0) <= res.uncertainty


def test_oscillating_case_falls_back_to_least_squares():
    h = SIZES["uniform"]
    f = F0 + 0.01 * h + np.array([0.02, -0.02, 0.02])  # e21 and e32 of opposite signs
    res = extrapolate(h, f)
    assert res.method == Method.LEAST_SQUARES
    assert res.flagged
    assert res.order == 1.0
    assert np.isfinite(res.value) and np.isfinite(res.uncertainty)
    assert abs(res.value - F0) <= res.uncertainty
    # "reasonable": not wider than the data themselves vary plus their distance to the limit
    assert res.uncertainty <= np.ptp(f) + abs(f[0] - F0)
    # the least-squares line through all three points with q = assumed_order = 1
    slope, intercept = np.polyfit(h, f, 1)
    assert res.value == pytest.approx(intercept, rel=1e-12)


def test_noisy_least_squares_uses_the_assumed_order():
    h = SIZES["uniform"]
    f = F0 + 0.01 * h**2 + np.array([0.1, -0.1, 0.0])
    res = extrapolate(h, f, assumed_order=2.0)
    assert (f[0] - f[1]) * (f[1] - f[2]) < 0
    assert res.method == Method.LEAST_SQUARES
    assert res.order == 2.0
    _, intercept = np.polyfit(h**2, f, 1)
    assert res.value == pytest.approx(intercept, rel=1e-12)
    assert abs(res.value - F0) <= res.uncertainty


def _least_squares_reference(h, f, q):
    x = np.column_stack([np.ones_like(h), h**q])
    coef, rss, *_ = np.linalg.lstsq(x, f, rcond=None)
    se = np.sqrt(rss[0] / (h.size - 2) * np.linalg.inv(x.T @ x)[0, 0])
    return coef[0], se


@pytest.mark.parametrize(
    ("h", "f"),
    [
        # closely spaced sizes far from h = 0: the standard error of the intercept dominates
        (np.array([8.0, 9.0, 10.0]), np.array([0.31, 0.30, 0.32])),
        # five sizes, noisy around a trend
        (np.array([2.0, 3.0, 5.0, 7.0, 11.0]), np.array([0.32, 0.30, 0.36, 0.33, 0.41])),
    ],
)
def test_least_squares_uncertainty_is_the_documented_maximum(h, f):
    res = extrapolate(h, f)
    assert res.method == Method.LEAST_SQUARES
    f0, se = _least_squares_reference(h, f, 1.0)
    assert res.value == pytest.approx(f0, rel=1e-12)
    expected = max(abs(f0 - f[0]), se, np.ptp(f))
    assert res.uncertainty == pytest.approx(expected, rel=1e-12)
    if h[0] == 8.0:
        assert se > max(abs(f0 - f[0]), np.ptp(f))


def test_divergent_case_is_flagged_and_finite():
    h = SIZES["uniform"]
    f = np.array([0.5, 0.45, 0.44])  # |e21| > |e32|: the error grows under refinement
    res = extrapolate(h, f)
    assert res.method == Method.LEAST_SQUARES
    assert res.flagged
    assert np.isfinite(res.value) and np.isfinite(res.uncertainty)
    assert res.uncertainty >= np.ptp(f)


@pytest.mark.parametrize("p", [0.3, 5.0])
def test_order_outside_bounds_is_flagged(p):
    h = SIZES["uniform"]
    res = extrapolate(h, F0 + 0.01 * h**p)
    assert res.method == Method.LEAST_SQUARES
    assert res.flagged
    # widening the bounds accepts the same data as Richardson
    wide = extrapolate(h, F0 + 0.01 * h**p, order_bounds=(0.1, 6.0))
    assert wide.method == Method.RICHARDSON
    assert wide.order == pytest.approx(p, rel=1e-9)


def test_order_on_a_bound_is_accepted():
    h = SIZES["uniform"]
    res = extrapolate(h, F0 + 0.01 * h**0.5)
    assert res.method == Method.RICHARDSON
    assert res.value == pytest.approx(F0, abs=1e-10)


def test_two_sizes_use_the_assumed_order():
    h = np.array([5.0, 10.0])
    f = F0 + 0.02 * h**1.5
    res = extrapolate(h, f, assumed_order=1.5)
    assert res.method == Method.TWO_SIZES_ASSUMED_ORDER
    assert res.flagged
    assert res.order == 1.5
    assert res.value == pytest.approx(F0, abs=1e-12)
    e21 = f[0] - f[1]
    assert res.uncertainty == pytest.approx(3.0 * abs(e21) / (2**1.5 - 1), rel=1e-12)
    # a wrong assumed order misses the limit, but the Fs = 3 band still covers it here
    wrong = extrapolate(h, f, assumed_order=1.0)
    assert wrong.value != pytest.approx(F0, abs=1e-3)
    assert abs(wrong.value - F0) <= wrong.uncertainty


def test_safety_factor_override():
    h = SIZES["uniform"]
    f = F0 + 0.01 * h
    base = extrapolate(h, f)
    assert extrapolate(h, f, safety_factor=3.0).uncertainty == pytest.approx(
        base.uncertainty * 3.0 / 1.25, rel=1e-12
    )


def _random_field(rng, shape, h):
    f0 = rng.normal(size=shape[:-1])[..., None]
    c = rng.normal(size=shape[:-1])[..., None]
    p = rng.uniform(0.7, 2.5, size=shape[:-1])[..., None]
    f = f0 + c * h**p
    # perturb a third of the points so that fallbacks are mixed with Richardson points
    noisy = rng.random(shape[:-1]) < 0.35
    f[noisy] += rng.normal(scale=5.0, size=(noisy.sum(), h.size))
    return f


def test_vectorised_matches_scalar_loop():
    rng = np.random.default_rng(12345)
    h = SIZES["non_uniform"]
    f = _random_field(rng, (4, 5, 3), h)
    f[0, 0, 1] = np.nan
    f[1, 2] = 0.25
    res = extrapolate(h, f)
    for name in ("value", "uncertainty", "order", "method", "flagged"):
        assert getattr(res, name).shape == (4, 5)
    methods = set(np.unique(res.method))
    assert {Method.RICHARDSON, Method.LEAST_SQUARES, Method.MISSING, Method.CONVERGED} <= methods
    for idx in np.ndindex(4, 5):
        one = extrapolate(h, f[idx])
        assert one.value.shape == ()
        np.testing.assert_array_equal(one.method, res.method[idx])
        np.testing.assert_array_equal(one.flagged, res.flagged[idx])
        np.testing.assert_allclose(one.value, res.value[idx], rtol=1e-13, equal_nan=True)
        np.testing.assert_allclose(one.uncertainty, res.uncertainty[idx], rtol=1e-13, equal_nan=True)
        np.testing.assert_allclose(one.order, res.order[idx], rtol=1e-13, equal_nan=True)


@pytest.mark.filterwarnings("error")
def test_nan_input_is_missing_without_warnings():
    h = SIZES["uniform"]
    f = np.array([[np.nan, 0.4, 0.5], [0.31, 0.32, 0.34], [np.nan] * 3, [0.3, 0.4, np.inf]])
    res = extrapolate(h, f)
    np.testing.assert_array_equal(
        res.method, [Method.MISSING, Method.RICHARDSON, Method.MISSING, Method.MISSING]
    )
    missing = res.method == Method.MISSING
    assert np.all(np.isnan(res.value[missing]))
    assert np.all(np.isnan(res.uncertainty[missing]))
    assert np.all(res.flagged[missing])
    assert np.isfinite(res.value[1])


@pytest.mark.filterwarnings("error")
@pytest.mark.parametrize("h", [SIZES["uniform"], np.array([5.0, 10.0])], ids=["three", "two"])
@pytest.mark.parametrize("level", [0.0, 0.42, -3.0e5])
def test_all_equal_values_are_converged(h, level):
    res = extrapolate(h, np.full(h.size, level))
    assert res.method == Method.CONVERGED
    assert not res.flagged
    assert res.value == level
    assert res.uncertainty == 0.0


@pytest.mark.filterwarnings("error")
def test_zero_coarse_difference_falls_back_without_warnings():
    h = SIZES["uniform"]
    res = extrapolate(h, [0.3, 0.4, 0.4])  # e32 == 0: R is infinite
    assert res.method == Method.LEAST_SQUARES
    assert res.flagged
    assert np.isfinite(res.value) and np.isfinite(res.uncertainty)
    res = extrapolate(h, [0.4, 0.4, 0.3])  # e21 == 0: R == 0, order unbounded
    assert res.method == Method.LEAST_SQUARES
    assert np.isfinite(res.value) and np.isfinite(res.uncertainty)


@pytest.mark.parametrize(
    ("h", "f", "kwargs"),
    [
        ([2.5], [1.0], {}),
        ([2.5, 2.5, 5.0], [1.0, 1.0, 2.0], {}),
        ([0.0, 5.0], [1.0, 2.0], {}),
        ([2.5, 5.0], [1.0, 2.0, 3.0], {}),
        ([2.5, 5.0], [1.0, 2.0], {"assumed_order": 0.0}),
        ([2.5, 5.0, 10.0], [1.0, 2.0, 3.0], {"order_bounds": (2.0, 1.0)}),
        ([2.5, 5.0, 10.0], [1.0, 2.0, 3.0], {"safety_factor": -1.0}),
    ],
)
def test_invalid_input_raises(h, f, kwargs):
    with pytest.raises(ValueError):
        extrapolate(h, f, **kwargs)


def test_dataarray_wrapper():
    rng = np.random.default_rng(7)
    h = np.array([10.0, 5.0, 2.5])
    load = np.array([0.5, 1.0])
    f = _random_field(rng, (3, 2, 3), h).transpose(2, 0, 1)  # put h first to test transposing
    da = xr.DataArray(
        f,
        dims=("h", "scene", "load"),
        coords={
            "h": ("h", h, {"units": "um"}),
            "scene": ["a", "b", "c"],
            "load": ("load", load, {"units": "N"}),
            "h_ratio": ("h", h / h.min()),
        },
        name="mu",
        attrs={"units": "1", "long_name": "friction coefficient"},
    )
    ds = extrapolate_dataarray(da, "h")
    assert set(ds.data_vars) == {"value", "uncertainty", "order", "method", "flagged"}
    for var in ds.data_vars.values():
        assert var.dims == ("scene", "load")
    assert "h" not in ds.coords and "h_ratio" not in ds.coords
    assert list(ds.scene.values) == ["a", "b", "c"]
    assert ds["load"].attrs["units"] == "N"
    assert ds.value.attrs["units"] == "1" and ds.uncertainty.attrs["units"] == "1"
    assert "friction coefficient" in ds.value.attrs["long_name"]
    for var in ds.data_vars.values():
        assert var.attrs["long_name"]
    np.testing.assert_array_equal(ds.method.attrs["flag_values"], [int(m) for m in Method])
    assert ds.method.attrs["flag_meanings"].split() == [m.name.lower() for m in Method]
    assert ds.method.attrs["flag_meanings"] == FLAG_MEANINGS
    assert ds.flagged.dtype == bool
    np.testing.assert_array_equal(ds.attrs["sizes"], [2.5, 5.0, 10.0])
    assert ds.attrs["safety_factor"] == 1.25
    assert ds.attrs["safety_factor_outside_asymptotic_range"] == 3.0
    assert ds.attrs["asymptotic_order_tolerance"] == 0.1
    assert "Oberkampf" in ds.attrs["extrapolation"]

    direct = extrapolate(h, np.moveaxis(f, 0, -1))
    np.testing.assert_array_equal(ds.value.values, direct.value)
    np.testing.assert_array_equal(ds.method.values, direct.method)


def test_dataarray_wrapper_two_sizes_and_errors():
    da = xr.DataArray([0.5, 0.45], dims="h", coords={"h": [10.0, 5.0]})
    ds = extrapolate_dataarray(da)
    assert ds.value.dims == ()
    assert int(ds.method) == Method.TWO_SIZES_ASSUMED_ORDER
    assert bool(ds.flagged)
    assert "units" not in ds.value.attrs
    assert ds.attrs["safety_factor"] == 3.0
    with pytest.raises(ValueError):
        extrapolate_dataarray(da, "size")
    with pytest.raises(ValueError):
        extrapolate_dataarray(xr.DataArray([0.5, 0.45], dims="h"))


# ----------------------------------------------------------------------------- sampling error of the limit
def _jacobian(h, f, **kw):
    """d value / d f_i by central differences (exact for the fixed-order methods: the value is linear)."""
    f = np.asarray(f, float)
    out = []
    for i in range(f.size):
        d = np.zeros_like(f)
        d[i] = 1e-6 * max(abs(f[i]), 1.0)
        out.append((float(extrapolate(h, f + d, **kw).value) - float(extrapolate(h, f - d, **kw).value)) / (2 * d[i]))
    return np.array(out)


@pytest.mark.parametrize(("h", "f", "method"), [
    ([2.5, 5.0], [1.30, 1.10], Method.TWO_SIZES_ASSUMED_ORDER),
    ([10.0, 2.5, 5.0], [1.0, 1.3, 1.4], Method.LEAST_SQUARES),  # oscillating: e21, e32 of opposite sign
    ([2.5, 5.0, 10.0], [1.10, 1.22, 1.50], Method.RICHARDSON),  # order observed from the same values
    ([3.0, 5.0, 10.0], [0.52, 0.60, 0.95], Method.RICHARDSON),  # non-constant ratio
])
def test_sampling_error_is_the_linear_propagation_through_extrapolate(h, f, method):
    """The propagated error equals sqrt(sum (df0/df_i s_i)^2) with the derivatives taken by differencing
    extrapolate() itself; for Richardson that includes how the observed order moves with the values."""
    assert int(extrapolate(h, f).method) == method
    s = np.array([0.01, 0.02, 0.03])[: len(h)]
    jac = _jacobian(h, f)
    assert float(sampling_error(h, f, s)) == pytest.approx(np.sqrt(np.sum((jac * s) ** 2)), rel=1e-5)
    for i in range(len(h)):  # one size's error alone gives |df0/df_i| s_i
        one = np.zeros(len(h))
        one[i] = 0.05
        assert float(sampling_error(h, f, one)) == pytest.approx(abs(jac[i]) * 0.05, rel=1e-5, abs=1e-12)


def test_sampling_error_of_richardson_at_order_one():
    """Order 1, r = 2: f0 = f1 + e21 with p from the same values; the weights are (4, -4, 1), not the
    fixed-order (2, -1, 0). The errors follow their sizes in any order."""
    h = np.array([2.5, 5.0, 10.0])
    f = 1.0 + 0.1 * h
    assert int(extrapolate(h, f).method) == Method.RICHARDSON
    s = np.array([0.01, 0.02, 0.05])
    expected = np.sqrt((4 * 0.01) ** 2 + (4 * 0.02) ** 2 + 0.05**2)
    assert float(sampling_error(h, f, s)) == pytest.approx(expected, rel=1e-9)
    perm = [2, 0, 1]
    assert float(sampling_error(h[perm], f[perm], s[perm])) == pytest.approx(expected, rel=1e-9)


def test_sampling_error_of_converged_missing_and_vectorised_points():
    h = [2.5, 5.0, 10.0]
    f = np.array([[1.0, 1.0, 1.0], [1.0 + 0.25, 1.0 + 0.5, 1.0 + 1.0], [np.nan, 1.0, 1.0], [1.25, 1.5, 2.0],
                  [1.0, 1.0, 1.0]])
    se = np.array([[0.1, 0.2, 0.3], [0.01, 0.02, 0.03], [0.01, 0.02, 0.03], [0.01, np.nan, 0.03],
                   [0.1, np.nan, np.nan]])
    out = sampling_error(h, f, se)
    assert out.shape == (5,)
    assert out[0] == pytest.approx(0.1)  # converged: the finest value's own error
    assert out[1] == pytest.approx(np.sqrt((4 * 0.01) ** 2 + (4 * 0.02) ** 2 + 0.03**2))
    assert np.isnan(out[2]) and np.isnan(out[3])  # a missing point; a needed size's error missing
    assert out[4] == pytest.approx(0.1)  # converged: the coarser sizes' errors are not needed
    np.testing.assert_allclose(sampling_error(h, f.reshape(5, 1, 3), se.reshape(5, 1, 3)).ravel(), out)
    with pytest.raises(ValueError, match="standard_error"):
        sampling_error(h, f, se[:, :2])


def test_total_uncertainty_adds_the_sampling_error_in_quadrature_and_says_what_a_missing_one_counts_as():
    np.testing.assert_allclose(total_uncertainty([3.0, 0.0], [4.0, 2.0]), [5.0, 2.0])
    # the figures and the ladder guard: a missing sampling error leaves the discretisation uncertainty alone
    np.testing.assert_allclose(total_uncertainty([3.0, 1.0], [np.nan, 0.0]), [3.0, 1.0])
    # the refinement decision: an unknown error makes an unknown total, never a small one
    out = total_uncertainty([3.0, 3.0], [np.nan, 4.0], missing_sampling="unknown")
    assert np.isnan(out[0]) and out[1] == pytest.approx(5.0)
    with pytest.raises(ValueError, match="missing_sampling = 'zero'"):
        total_uncertainty(1.0, 1.0, missing_sampling="zero")
