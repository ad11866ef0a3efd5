"""Extrapolation of simulation outputs to zero particle size, with an uncertainty.

Every MPM output (friction coefficient, ploughing depth, ...) is computed at a few particle
sizes ``h`` and extrapolated to ``h -> 0`` by :func:`extrapolate`:

**Richardson extrapolation with the observed order** (three or more sizes). With the finest
three sizes ``h1 < h2 < h3`` and values ``f1, f2, f3``, let ``e21 = f1 - f2``,
``e32 = f2 - f3`` and ``R = e21 / e32``. Assuming ``f = f0 + c h^p``, the observed order ``p``
solves ``R = (h2^p - h1^p) / (h3^p - h2^p)``, which is eqs. (3)-(4) of Celik et al. (2008) for a
non-constant refinement ratio (``p = ln(1/R) / ln r`` when ``r21 = r32 = r``). Then, with
``r = h2 / h1``::

    value       = f1 + e21 / (r^p - 1)
    uncertainty = Fs * |e21| / (r^q - 1),   q = min(p, p_f)

The uncertainty is Roache's grid convergence index of the finest solution written as an
absolute error (``GCI_fine * |f1|``), after Oberkampf & Roy (2010, sec. 8.7): the safety factor is
``Fs = 1.25`` where the observed order lies within 10% of the formal one ``p_f`` (``assumed_order``,
1 for plough's MPM; ``|p - p_f| <= 0.1 p_f``, the asymptotic range), else ``Fs = 3``; and the band's
order ``q`` never exceeds ``p_f``, so that an observed order above it (error cancellation between sizes
not yet in the asymptotic range) does not narrow the band below what the formal order gives. Oberkampf &
Roy take ``q = p_f`` inside the 10% and floor ``q`` at 0.5 outside it; ``min(p, p_f)`` is never narrower
than either, and ``order_bounds`` (from 0.5 by default) already keeps ``p`` off the floor.
Roache (J. Fluids Eng. 133 (2011) 115501) states the same reversion: where the observed order is not
reasonable, use the theoretical one and ``Fs = 3`` rather than blindly ``Fs = 1.25``.

The value keeps the observed order; since ``Fs >= 1`` and ``q <= p`` the band covers ``f1``, and
outside the 10% also the value the formal order would extrapolate to.

The convergence is accepted as monotone only if ``R > 0`` and the observed order lies in
``order_bounds`` (default 0.5 to 4). For a constant ratio this is the classical test
``0 < R < 1`` tightened to ``r^-p_max <= R <= r^-p_min``; for a non-constant ratio the admissible
range of ``R`` is ``(0, ln r21 / ln r32)`` and the bounds tighten it in the same way.

**Least-squares fallback** (oscillating, divergent or implausible-order cases, three or more
sizes): ``f = f0 + c h^q`` is fitted over *all* sizes by linear regression on ``h^q`` with the
fixed order ``q = assumed_order``; the result is flagged. Its uncertainty is the largest of

* ``|f0 - f1|``, the extrapolation distance (as a GCI with ``Fs = 1`` would be),
* the standard error of ``f0`` from the regression residuals (captures noise, 1 dof for 3 sizes),
* the range ``max(f) - min(f)`` over the sizes: once the data do not converge we do not claim
  to know the limit better than the data vary across the sizes that were run.

**Two sizes** (the workflow may skip the finest size): the order cannot be observed, so
Richardson extrapolation uses ``p = assumed_order`` with Roache's ``Fs = 3`` and is flagged.

**Exactly converged** (the finest three, or both, values equal to rounding): ``value = f1``,
``uncertainty = 0``, ``order = NaN`` (undefined), not flagged. Points with any non-finite value
get ``method = MISSING`` and NaN results.

References: L.F. Richardson, Phil. Trans. R. Soc. A 210 (1911) 307; P.J. Roache, "Verification
and Validation in Computational Science and Engineering", Hermosa (1998); I.B. Celik et al.,
"Procedure for estimation and reporting of uncertainty due to discretization in CFD
applications", J. Fluids Eng. 130 (2008) 078001; W.L. Oberkampf and C.J. Roy, "Verification and
Validation in Scientific Computing", Cambridge University Press (2010), sec. 8.7.
"""

from __future__ import annotations

import enum
from dataclasses import dataclass
from typing import TYPE_CHECKING

import numpy as np
from numpy.typing import ArrayLike, NDArray

if TYPE_CHECKING:
    import xarray as xr

__all__ = [
    "ASYMPTOTIC_ORDER_TOLERANCE",
    "FLAG_MEANINGS",
    "SAFETY_FACTOR_THREE_OR_MORE",
    "SAFETY_FACTOR_TWO",
    "Extrapolation",
    "Method",
    "extrapolate",
    "extrapolate_dataarray",
    "sampling_error",
    "total_uncertainty",
]

#: Roache's safety factors: 1.25 when three or more sizes observe the formal order, 3 when the order
#: is assumed (two sizes) or the observed one is not the formal one (Oberkampf & Roy 2010).
SAFETY_FACTOR_THREE_OR_MORE = 1.25
SAFETY_FACTOR_TWO = 3.0
#: Relative distance of the observed order from the formal one within which it counts as asymptotic.
ASYMPTOTIC_ORDER_TOLERANCE = 0.1

# Values equal to within a few ulps of their magnitude are treated as converged: differencing them
# would only extrapolate rounding noise.
_CONVERGED_ULPS = 4.0
# Rounding in the differences e21, e32 moves ln R by far more than an ulp; this slack keeps an
# order lying on a bound inside the (inclusive) bounds, and the bisection then clips it to them.
_BOUND_SLACK = 1e-9
# 64 halvings of an O(1) bracket reach the float64 resolution of p.
_BISECTION_STEPS = 64


class Method(enum.IntEnum):
    """How a point was extrapolated (the integer stored in :attr:`Extrapolation.method`)."""

    RICHARDSON = 0
    LEAST_SQUARES = 1
    TWO_SIZES_ASSUMED_ORDER = 2
    CONVERGED = 3
    MISSING = 4


#: CF ``flag_meanings`` for :class:`Method`, in code order.
FLAG_MEANINGS = " ".join(m.name.lower() for m in Method)


@dataclass(frozen=True, eq=False)  # element-wise array equality has no single truth value
class Extrapolation:
    """Result of :func:`extrapolate`; every array has the shape ``f.shape[:-1]``.

    Attributes:
        value: extrapolated value at ``h = 0``.
        uncertainty: absolute uncertainty (same units as ``f``), >= 0.
        order: observed order (Richardson), the assumed order (least squares, two sizes), NaN
            when converged or missing.
        method: :class:`Method` codes (int8).
        flagged: True where the result is not a regular Richardson extrapolation
            (least squares, two sizes, missing); False for Richardson and converged points.
        h: the sizes used, sorted ascending.
    """

    value: NDArray[np.float64]
    uncertainty: NDArray[np.float64]
    order: NDArray[np.float64]
    method: NDArray[np.int8]
    flagged: NDArray[np.bool_]
    h: NDArray[np.float64]


def _log_ratio_model(p: NDArray[np.float64], a: float, b: float) -> NDArray[np.float64]:
    """``ln[(h2^p - h1^p) / (h3^p - h2^p)]`` with ``a = ln(h2/h1)``, ``b = ln(h3/h2)``.

    Written with expm1 so that it stays accurate for small ``p``; it decreases strictly in ``p``
    (from ``ln(a/b)`` at ``p -> 0`` to ``-inf``), which is what makes bisection safe.
    """
    return np.log(-np.expm1(-p * a)) - np.log(np.expm1(p * b))


def _observed_order(
    log_ratio: NDArray[np.float64], a: float, b: float, lo: float, hi: float
) -> NDArray[np.float64]:
    # Celik et al. iterate p = |ln|e32/e21| + q(p)| / ln r21, which diverges when
    # ln r32 > 2 ln r21; the residual is monotone in p, so bracketing bisection always converges
    # and solves the same equation.
    p_lo = np.full(log_ratio.shape, lo)
    p_hi = np.full(log_ratio.shape, hi)
    for _ in range(_BISECTION_STEPS):
        mid = 0.5 * (p_lo + p_hi)
        root_above = _log_ratio_model(mid, a, b) > log_ratio
        p_lo = np.where(root_above, mid, p_lo)
        p_hi = np.where(root_above, p_hi, mid)
    return 0.5 * (p_lo + p_hi)


def _gci_safety_factor_and_order(
    p_obs: NDArray[np.float64], formal_order: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Roache's ``Fs`` and the order ``q`` of the GCI band for observed orders ``p_obs`` (module
    docstring): ``Fs`` 1.25 within 10% of the formal order ``p_f``, else 3; ``q = min(p, p_f)``."""
    # the slack keeps an order on either edge of the 10% inside it alike (|1.1 - 1| > 0.1 in binary)
    asymptotic = np.abs(p_obs - formal_order) <= ASYMPTOTIC_ORDER_TOLERANCE * formal_order + _BOUND_SLACK
    fs = np.where(asymptotic, SAFETY_FACTOR_THREE_OR_MORE, SAFETY_FACTOR_TWO)
    return fs, np.minimum(p_obs, formal_order)


def _least_squares(
    h: NDArray[np.float64], f: NDArray[np.float64], q: float
) -> tuple[NDArray[np.float64], NDArray[np.float64]]:
    """Fit ``f = f0 + c h^q`` row-wise over all sizes; return ``(f0, uncertainty)``."""
    n = h.size
    x = h**q
    x_mean = x.mean()
    sxx = np.sum((x - x_mean) ** 2)
    f_mean = f.mean(axis=-1)
    slope = ((f - f_mean[:, None]) @ (x - x_mean)) / sxx
    f0 = f_mean - slope * x_mean
    residual = f - f0[:, None] - slope[:, None] * x
    s2 = np.sum(residual**2, axis=-1) / (n - 2)
    standard_error = np.sqrt(s2 * (1.0 / n + x_mean**2 / sxx))
    spread = np.ptp(f, axis=-1)
    uncertainty = np.maximum.reduce([np.abs(f0 - f[:, 0]), standard_error, spread])
    return f0, uncertainty


def _validate_sizes(h: ArrayLike) -> NDArray[np.float64]:
    h = np.asarray(h, dtype=float)
    if h.ndim != 1 or h.size < 2:
        raise ValueError(f"h must be a 1-D array of at least 2 sizes, got shape {h.shape}")
    if not np.all(np.isfinite(h) & (h > 0)):
        raise ValueError(f"h must be finite and > 0, got {h}")
    if np.unique(h).size != h.size:
        raise ValueError(f"h must not repeat a size, got {h}")
    return h


def extrapolate(
    h: ArrayLike,
    f: ArrayLike,
    *,
    assumed_order: float = 1.0,
    safety_factor: float | None = None,
    order_bounds: tuple[float, float] = (0.5, 4.0),
) -> Extrapolation:
    """Extrapolate ``f(h)`` to ``h = 0`` with an uncertainty (see the module docstring).

    Args:
        h: particle sizes, 1-D, at least two distinct positive values, in any order.
        f: values; the last axis matches ``h``, leading axes are independent points.
        assumed_order: the formal order: used when the order cannot be observed (two sizes), for the
            least-squares fallback, and as the reference the observed order is judged against.
        safety_factor: Roache's ``Fs`` for every point, with the observed order in ``r^p`` (Celik et
            al.'s GCI); by default 3 for two sizes, and for three or more the rule of the module
            docstring (1.25 within 10% of ``assumed_order``, else 3, the band's order at most
            ``assumed_order``).
        order_bounds: inclusive range of observed orders accepted as asymptotic convergence.

    Returns:
        An :class:`Extrapolation` with arrays of shape ``f.shape[:-1]``.
    """
    h = _validate_sizes(h)
    f = np.asarray(f, dtype=float)
    if f.ndim == 0 or f.shape[-1] != h.size:
        raise ValueError(f"the last axis of f (shape {f.shape}) must match h ({h.size} sizes)")
    if not (np.isfinite(assumed_order) and assumed_order > 0):
        raise ValueError(f"assumed_order must be finite and > 0, got {assumed_order}")
    p_min, p_max = (float(b) for b in order_bounds)
    if not (0 < p_min < p_max < np.inf):
        raise ValueError(f"order_bounds must satisfy 0 < low < high < inf, got {order_bounds}")
    n = h.size
    if safety_factor is not None and not (np.isfinite(safety_factor) and safety_factor > 0):
        raise ValueError(f"safety_factor must be finite and > 0, got {safety_factor}")

    sort = np.argsort(h)
    h = h[sort]
    shape = f.shape[:-1]
    rows = f[..., sort].reshape(-1, n)

    value = np.full(rows.shape[0], np.nan)
    uncertainty = np.full(rows.shape[0], np.nan)
    order = np.full(rows.shape[0], np.nan)
    method = np.full(rows.shape[0], Method.MISSING, dtype=np.int8)

    # Work only on complete rows so that NaN never reaches a comparison or a division.
    complete = np.flatnonzero(np.all(np.isfinite(rows), axis=-1))
    fc = rows[complete]
    finest = fc[:, : min(n, 3)]
    converged = np.ptp(finest, axis=-1) <= _CONVERGED_ULPS * np.finfo(float).eps * np.max(
        np.abs(finest), axis=-1
    )
    f1 = fc[:, 0]
    e21 = f1 - fc[:, 1]
    r21 = h[1] / h[0]

    v = f1.copy()
    u = np.zeros_like(f1)
    p = np.full_like(f1, np.nan)
    m = np.full(f1.shape, Method.CONVERGED, dtype=np.int8)

    if n == 2:
        todo = ~converged
        gain = 1.0 / (r21**assumed_order - 1.0)
        v[todo] = f1[todo] + e21[todo] * gain
        fs = SAFETY_FACTOR_TWO if safety_factor is None else safety_factor
        u[todo] = fs * np.abs(e21[todo]) * gain
        p[todo] = assumed_order
        m[todo] = Method.TWO_SIZES_ASSUMED_ORDER
    else:
        e32 = fc[:, 1] - fc[:, 2]
        a, b = np.log(h[1] / h[0]), np.log(h[2] / h[1])
        # Signs rather than the product e21 * e32, which underflows to 0 for tiny differences.
        same_sign = ~converged & (np.sign(e21) * np.sign(e32) > 0)
        idx = np.flatnonzero(same_sign)
        log_ratio = np.log(np.abs(e21[idx])) - np.log(np.abs(e32[idx]))
        # The model ratio decreases with p, so the order is within bounds iff the observed ratio
        # lies between the model ratios at the bounds.
        bounds = _log_ratio_model(np.array([p_max, p_min]), a, b)
        inside = (log_ratio >= bounds[0] - _BOUND_SLACK) & (log_ratio <= bounds[1] + _BOUND_SLACK)
        rich = idx[inside]
        p_obs = _observed_order(log_ratio[inside], a, b, p_min, p_max)
        v[rich] = f1[rich] + e21[rich] / (r21**p_obs - 1.0)
        if safety_factor is None:
            fs, q = _gci_safety_factor_and_order(p_obs, assumed_order)
        else:  # a given Fs: Roache's GCI as Celik et al. state it, at the observed order
            fs, q = safety_factor, p_obs
        u[rich] = fs * np.abs(e21[rich]) / (r21**q - 1.0)
        p[rich] = p_obs
        m[rich] = Method.RICHARDSON

        fallback = ~converged
        fallback[rich] = False
        if np.any(fallback):
            v[fallback], u[fallback] = _least_squares(h, fc[fallback], assumed_order)
            p[fallback] = assumed_order
            m[fallback] = Method.LEAST_SQUARES

    value[complete], uncertainty[complete], order[complete], method[complete] = v, u, p, m
    flagged = (method != Method.RICHARDSON) & (method != Method.CONVERGED)
    return Extrapolation(
        value=value.reshape(shape),
        uncertainty=uncertainty.reshape(shape),
        order=order.reshape(shape),
        method=method.reshape(shape),
        flagged=flagged.reshape(shape),
        h=h,
    )


def sampling_error(h: ArrayLike, f: ArrayLike, standard_error: ArrayLike) -> NDArray[np.float64]:
    """Standard error of the extrapolated value ``extrapolate(h, f).value`` from independent standard
    errors of the per-size values, by linear propagation: ``sqrt(sum (d f0 / d f_i)^2 s_i^2)``.

    The derivatives, per method:

    * Richardson: ``f0 = f1 + e21 g(p)`` with ``g = 1 / (r^p - 1)`` and the observed order ``p``,
      which is itself a function of the three finest values (``ln(e21 / e32) = phi(p)``, see
      :func:`_log_ratio_model`), so ``d f0 = d f1 + g d e21 + e21 g'(p) d p`` with
      ``d p = d ln(e21 / e32) / phi'(p)``. At order 1 and r = 2 the weights are (4, -4, 1): the
      noise of the finest value enters four times over.
    * two sizes (assumed order): ``(1 + g) f1 - g f2``;
    * least squares (assumed order): the regression intercept's weights;
    * converged: ``f1``.

    ``standard_error`` has the shape of ``f`` with its sizes ordered like ``h``. NaN where a needed
    size's error is missing (an unused size's may be), or where the point is missing.
    """
    h = _validate_sizes(h)
    f = np.asarray(f, dtype=float)
    se = np.asarray(standard_error, dtype=float)
    if se.shape != f.shape or f.ndim == 0 or f.shape[-1] != h.size:
        raise ValueError(f"standard_error (shape {se.shape}) must have the shape of f ({f.shape}), "
                         f"whose last axis matches h ({h.size} sizes)")
    ex = extrapolate(h, f)
    sort = np.argsort(h)
    hs = h[sort]
    fs = f[..., sort].reshape(-1, h.size)
    se = se[..., sort].reshape(-1, h.size)
    method, order = ex.method.reshape(-1), ex.order.reshape(-1)
    weights = np.zeros_like(se)
    weights[:, 0] = 1.0  # converged: the finest value
    r21 = hs[1] / hs[0]
    two = method == Method.TWO_SIZES_ASSUMED_ORDER
    g = 1.0 / (r21 ** order[two] - 1.0)
    weights[two, 0], weights[two, 1] = 1.0 + g, -g
    rich = np.flatnonzero(method == Method.RICHARDSON)
    if rich.size:
        p = order[rich]
        a, b = np.log(hs[1] / hs[0]), np.log(hs[2] / hs[1])
        e21 = fs[rich, 0] - fs[rich, 1]
        e32 = fs[rich, 1] - fs[rich, 2]
        g = 1.0 / np.expm1(p * a)
        dg_dp = -a * np.exp(p * a) * g**2
        dphi_dp = a / np.expm1(p * a) - b * np.exp(p * b) / np.expm1(p * b)
        d_e21 = np.array([1.0, -1.0, 0.0])
        d_e32 = np.array([0.0, 1.0, -1.0])
        d_logratio = d_e21[None, :] / e21[:, None] - d_e32[None, :] / e32[:, None]
        dp = d_logratio / dphi_dp[:, None]
        jac = np.array([1.0, 0.0, 0.0])[None, :] + g[:, None] * d_e21[None, :] + (e21 * dg_dp)[:, None] * dp
        weights[rich, :3] = jac
    for row in np.flatnonzero(method == Method.LEAST_SQUARES):
        x = hs ** order[row]
        weights[row] = 1.0 / h.size - x.mean() * (x - x.mean()) / np.sum((x - x.mean()) ** 2)
    used = weights != 0.0
    out = np.sqrt(np.sum(np.where(used, weights * se, 0.0) ** 2, axis=-1))
    out[np.any(used & ~np.isfinite(se), axis=-1) | (method == Method.MISSING)] = np.nan
    return out.reshape(ex.value.shape)


def total_uncertainty(uncertainty: ArrayLike, sampling: ArrayLike, *,
                      missing_sampling: str = "none") -> NDArray[np.float64]:
    """The uncertainty of an extrapolated value as plough reports it: the discretisation uncertainty
    (``Extrapolation.uncertainty``, GCI-type) and the runs' sampling error carried to the limit
    (:func:`sampling_error`) in quadrature, as independent errors.

    ``missing_sampling`` says what a missing (NaN) sampling error counts as: ``"none"`` (the
    discretisation uncertainty alone: the figures, the ladder guard, which say so where it matters)
    or ``"unknown"`` (a NaN total: the refinement decision, which must never skip a run on an
    unknown error).
    """
    if missing_sampling not in ("none", "unknown"):
        raise ValueError(f"missing_sampling = {missing_sampling!r}; allowed: 'none', 'unknown'")
    s = np.asarray(sampling, dtype=float)
    if missing_sampling == "none":
        s = np.nan_to_num(s, nan=0.0)
    return np.hypot(np.asarray(uncertainty, dtype=float), s)


def extrapolate_dataarray(
    da: xr.DataArray,
    dim: str = "h",
    *,
    assumed_order: float = 1.0,
    safety_factor: float | None = None,
    order_bounds: tuple[float, float] = (0.5, 4.0),
) -> xr.Dataset:
    """Apply :func:`extrapolate` along ``dim`` of ``da``, whose coordinate holds the sizes.

    Returns a Dataset with variables ``value``, ``uncertainty``, ``order``, ``method`` and
    ``flagged`` over the remaining dimensions; coordinates not on ``dim`` are kept, ``units``
    is copied to ``value`` and ``uncertainty``, and ``method`` carries CF ``flag_values`` /
    ``flag_meanings``.
    """
    import xarray as xr

    if dim not in da.dims:
        raise ValueError(f"{dim!r} is not a dimension of the DataArray (dims {da.dims})")
    if dim not in da.coords:
        raise ValueError(f"dimension {dim!r} needs a coordinate holding the sizes")
    moved = da.transpose(..., dim)
    h = np.asarray(moved[dim].values, dtype=float)
    res = extrapolate(
        h,
        moved.values,
        assumed_order=assumed_order,
        safety_factor=safety_factor,
        order_bounds=order_bounds,
    )
    dims = moved.dims[:-1]
    coords = {k: c for k, c in da.coords.items() if dim not in c.dims}
    name = da.attrs.get("long_name", da.name if da.name is not None else "quantity")
    units = {"units": da.attrs["units"]} if "units" in da.attrs else {}
    # what the uncertainty was made with: a given Fs, the two-size rule, or the rule of the module docstring
    if safety_factor is not None:
        gci = f"safety factor {safety_factor:g} at the observed order"
        fs_attrs = {"safety_factor": float(safety_factor)}
    elif h.size == 2:
        gci = f"two sizes: safety factor {SAFETY_FACTOR_TWO:g} at assumed_order"
        fs_attrs = {"safety_factor": SAFETY_FACTOR_TWO}
    else:
        gci = (f"safety factor {SAFETY_FACTOR_THREE_OR_MORE:g} where the observed order is within "
               f"{ASYMPTOTIC_ORDER_TOLERANCE:.0%} of assumed_order, else {SAFETY_FACTOR_TWO:g}, the band's order at "
               "most assumed_order (Oberkampf and Roy 2010)")
        fs_attrs = {"safety_factor": SAFETY_FACTOR_THREE_OR_MORE,
                    "safety_factor_outside_asymptotic_range": SAFETY_FACTOR_TWO,
                    "asymptotic_order_tolerance": ASYMPTOTIC_ORDER_TOLERANCE}
    codes = np.array([int(m) for m in Method], dtype=np.int8)
    variables = {
        "value": (dims, res.value, {"long_name": f"{name} extrapolated to {dim} -> 0", **units}),
        "uncertainty": (
            dims,
            res.uncertainty,
            {"long_name": f"uncertainty of {name} extrapolated to {dim} -> 0", **units},
        ),
        "order": (
            dims,
            res.order,
            {"long_name": f"convergence order in {dim} (observed or assumed)", "units": "1"},
        ),
        "method": (
            dims,
            res.method,
            {
                "long_name": "extrapolation method",
                "flag_values": codes,
                "flag_meanings": FLAG_MEANINGS,
            },
        ),
        "flagged": (
            dims,
            res.flagged,
            {"long_name": "extrapolation fell back from Richardson (least squares, two sizes "
             "or missing)"},
        ),
    }
    attrs = {
        "extrapolation": f"Richardson with observed order and Roache GCI (Celik et al. 2008), {gci}; "
        "least-squares fallback in h**assumed_order",
        "extrapolated_dim": dim,
        "sizes": res.h,
        "assumed_order": float(assumed_order),
        "order_bounds": np.asarray(order_bounds, dtype=float),
        **fs_attrs,
    }
    if da.name is not None:
        attrs["source_variable"] = str(da.name)
    return xr.Dataset(variables, coords=coords, attrs=attrs)
