"""Analytical ploughing model of a rigid sphere on a coated substrate (model.md section 1).

Equations (the paper's numbers):

- (1)       effective hardness  Hcs = Hc + (Hs - Hc) exp(-k1 t / r)
- (2.1-2.3) contact in the coating only: Axy = Fn / Hcs, dp = r - sqrt(r^2 - a^2), Ayz = seg(r, a, r - dp)
            (evaluated as dp = a^2 / (r + sqrt(r^2 - a^2)): finite and accurate for any finite input)
- (3.1-3.5) contact reaching the substrate (dp > t): Axyc, the quadratic for ds, Axys, Ayzs, Ayzc
- (4.1-4.4) mu = mu_pl + mu_sh, mu_pl = (Hs Ayzs + Hc Ayzc) / Fn, mu_sh = (tau_s Axys + tau_c Axyc) / Fn
- (5.1-5.2) normal-load correction Fn' = Fn + Fz_sh, Fz_sh = tau_s Ayzs + tau_c Ayzc
- (8.3)     boundary-layer interface shear tau = Cp P^np, P = load / Axy

Everything is numpy and broadcasts over its inputs; SI units throughout.

Decisions where model.md leaves room (also in docs/model.md, section 2):

- Friction is divided by the *applied* load Fn, also when the geometry is computed for the
  corrected load Fn' (the corrected load is the reaction the contact carries, the applied load is
  what a tribometer divides by; for the proportional case this gives Fz_sh / Fn = mu_pl / k0).
- The boundary-layer pressure is the load the geometry carries over the load-bearing area,
  P = Fn' / Axy (= Fn / Axy without correction).
- A contact wider than the sphere's equator (dp > r) is refused as "load too large".
"""

from __future__ import annotations

from dataclasses import dataclass, fields
from typing import Literal

import numpy as np

from plough.materials import K0

InterfaceName = Literal["proportional", "constant", "boundary_layer"]
Correction = Literal["none", "once", "converged"]
INTERFACE_NAMES: tuple[str, ...] = ("proportional", "constant", "boundary_layer")
CORRECTIONS: tuple[str, ...] = ("none", "once", "converged")

#: units and long names of every field of :class:`PloughingResult` (also used for datasets).
RESULT_META: dict[str, tuple[str, str]] = {
    "Hcs": ("Pa", "effective hardness of the coated system (eq. 1)"),
    "load_carried": ("N", "normal load the contact geometry carries (Fn, or Fn' when corrected)"),
    "dp": ("m", "ploughing depth"),
    "ds": ("m", "ploughing depth into the substrate"),
    "a": ("m", "contact radius"),
    "a_s": ("m", "contact radius in the substrate"),
    "Axy": ("m2", "load-bearing (front half) contact area"),
    "Axys": ("m2", "load-bearing contact area on the substrate"),
    "Axyc": ("m2", "load-bearing contact area on the coating"),
    "Ayz": ("m2", "frontal ploughed cross-section"),
    "Ayzs": ("m2", "frontal ploughed cross-section in the substrate"),
    "Ayzc": ("m2", "frontal ploughed cross-section in the coating"),
    "tau_c": ("Pa", "interface shear strength on the coating"),
    "tau_s": ("Pa", "interface shear strength on the substrate"),
    "Fz_sh": ("N", "downward pull of interfacial shear on the ploughed face (eq. 5.1)"),
    "mu_pl": ("1", "ploughing part of the friction coefficient"),
    "mu_sh": ("1", "interface-shear part of the friction coefficient"),
    "mu": ("1", "friction coefficient"),
    "regime": ("1", "1: contact in the coating only (dp <= t); 2: contact reaches the substrate"),
}


@dataclass(frozen=True)
class PloughingResult:
    """Outputs of :func:`ploughing`, named as in model.md, SI units (see ``RESULT_META``)."""

    Hcs: np.ndarray
    load_carried: np.ndarray
    dp: np.ndarray
    ds: np.ndarray
    a: np.ndarray
    a_s: np.ndarray
    Axy: np.ndarray
    Axys: np.ndarray
    Axyc: np.ndarray
    Ayz: np.ndarray
    Ayzs: np.ndarray
    Ayzc: np.ndarray
    tau_c: np.ndarray
    tau_s: np.ndarray
    Fz_sh: np.ndarray
    mu_pl: np.ndarray
    mu_sh: np.ndarray
    mu: np.ndarray
    regime: np.ndarray

    @property
    def coating_worn(self) -> np.ndarray:
        """True where the sphere ploughs through the coating (dp > t, regime 2)."""
        return self.regime == 2

    def as_dict(self) -> dict[str, np.ndarray]:
        return {f.name: getattr(self, f.name) for f in fields(self)}

    def squeeze(self) -> PloughingResult:
        """Scalars as 0-d arrays turned into Python floats/ints (for printing)."""
        return PloughingResult(**{k: v[()] if np.ndim(v) == 0 else v for k, v in self.as_dict().items()})


# ----------------------------------------------------------------------------- geometry
#: below this angle x = 2 theta, (x - sin x) / x^3 is summed as its series (cancellation-free); above it,
#: x - sin x loses at most eps / (x^2 / 6) ~ 5e-15 relative
_SERIES_BELOW = 0.5
#: (-1)^k / (2k + 3)! for k = 0..7: (x - sin x) / x^3 = sum_k c_k x^(2k); the next term is below 1e-20 at x = 0.5
_SINE_REST = tuple((-1) ** k / float(np.prod(np.arange(1, 2 * k + 4))) for k in range(8))


def _sine_rest(x: np.ndarray) -> np.ndarray:
    """(x - sin x) / x^2 for x in [0, pi], without the cancellation of x - sin x at small x."""
    x = np.asarray(x, dtype=float)
    x2 = x * x
    series = np.zeros_like(x)
    for c in reversed(_SINE_REST):
        series = series * x2 + c
    with np.errstate(invalid="ignore", divide="ignore"):
        direct = (x - np.sin(x)) / x2
    return np.where(x < _SERIES_BELOW, x * series, direct)


def segment_area(r: np.ndarray, a: np.ndarray, h: np.ndarray) -> np.ndarray:
    """Area of the circular segment of half-chord a whose chord lies at distance h >= 0 from the centre
    (a chord of the circle: a^2 + h^2 = r^2).

    seg(r, a, h) = r^2 theta - a h with theta = atan(a / h), written as 2 (r theta)^2 (x - sin x) / x^2,
    x = 2 theta: no cancellation for a small segment (a / r = 1e-9 keeps its (2/3) a^3 / r) and no overflow
    of r^2 (r = 1e300 m). arctan2 keeps h = 0, the half disc, exact.
    """
    r, a, h = (np.asarray(v, dtype=float) for v in (r, a, h))
    theta = np.arctan2(a, h)
    r_theta = r * theta
    return 2.0 * r_theta * r_theta * _sine_rest(2.0 * theta)


def _sagitta(a: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Eq. 2.2 in its cancellation-free form: dp = r - sqrt(r^2 - a^2) = a^2 / (r + sqrt(r^2 - a^2)).

    Written with s = a / r as a s / (1 + sqrt((1 - s)(1 + s))): r^2 never formed (no overflow at r = 1e300 m),
    and no cancellation at a / r = 1e-9 (where r - sqrt(r^2 - a^2) is 0). NaN-free for a > r (the caller
    refuses that contact).
    """
    s = a / r
    return a * s / (1.0 + np.sqrt(np.maximum((1.0 - s) * (1.0 + s), 0.0)))


def _half_chord(d: np.ndarray, r: np.ndarray) -> np.ndarray:
    """Contact radius of a cap of depth d <= r: sqrt(r^2 - (r - d)^2) = sqrt(d (2 r - d)), without cancellation
    (a small depth) or overflow (a huge radius)."""
    return np.sqrt(d) * np.sqrt(r) * np.sqrt(np.maximum(2.0 - d / r, 0.0))


def effective_hardness(
    thickness_m: np.ndarray, radius_m: np.ndarray, Hc: np.ndarray, Hs: np.ndarray, k1: np.ndarray
) -> np.ndarray:
    """Eq. 1: Hcs = Hc + (Hs - Hc) exp(-k1 t / r)."""
    return Hc + (Hs - Hc) * np.exp(-k1 * thickness_m / radius_m)


def _contact_geometry(load: np.ndarray, r: np.ndarray, t: np.ndarray, Hcs: np.ndarray,
                      Hs: np.ndarray) -> dict[str, np.ndarray]:
    """Eqs. 2.1-3.5 for a given load carried by the contact; returns areas and depths."""
    with np.errstate(invalid="ignore", divide="ignore", under="ignore", over="ignore"):  # the other case's branch
        # Case 1 (eqs. 2.1-2.3): the coating alone carries the load at hardness Hcs.
        Axy1 = load / Hcs
        a1 = np.sqrt(2.0 * Axy1 / np.pi)
        dp1 = _sagitta(a1, r)
        too_wide1 = a1 > r

        # Case 2 (eqs. 3.1-3.5): the quadratic A ds^2 + B ds + C = 0 with A = pi Hs / 2, B = pi (Hcs t - Hs r),
        # C = Fn - pi t (2 r - t) Hcs / 2, divided by pi Hs r (Hs r^2 would overflow at a huge radius, and
        # Fn / (Hs r^2) underflow): ds^2 / (2 r) - b ds + g = 0 with b = 1 - (Hcs / Hs)(t / r) and the length
        # g = Fn / (pi Hs r) - t (2 - t / r)(Hcs / Hs) / 2. The smaller root in the stable form
        # ds = 2 g / (b + sqrt(b^2 - 2 g / r)): b > 0 whenever a root with ds < r exists, so nothing cancels
        # (uncoated, t = 0: the form of eq. 2.2), and g = 0 gives ds = 0 exactly.
        tau, eta = t / r, Hcs / Hs
        b = 1.0 - eta * tau
        g = load / Hs / r / np.pi - 0.5 * t * (2.0 - tau) * eta
        disc = b * b - 2.0 * g / r
        ds2 = np.maximum(2.0 * g / (b + np.sqrt(np.maximum(disc, 0.0))), 0.0)
        dp2 = ds2 + t
        case2 = dp1 > t
        too_wide2 = case2 & ((disc < 0.0) | (b <= 0.0) | (dp2 > r))

        dp = np.where(case2, dp2, dp1)
        ds = np.where(case2, ds2, 0.0)
        a = np.where(case2, _half_chord(dp, r), a1)
        a_s = _half_chord(ds, r)
        Axy = 0.5 * np.pi * a * a
        Ayz = segment_area(r, a, r - dp)
        Axys = np.where(case2, 0.5 * np.pi * a_s * a_s, 0.0)
        Ayzs = np.where(case2, segment_area(r, a_s, r - ds), 0.0)
        Axyc = np.where(case2, np.pi * t * ((r - ds) - 0.5 * t), Axy)  # pi t (2 (r - ds) - t) / 2, no 2 r
        Ayzc = Ayz - Ayzs
    return {
        "dp": dp, "ds": ds, "a": a, "a_s": a_s, "Axy": Axy, "Ayz": Ayz, "Axys": Axys,
        "Ayzs": Ayzs, "Axyc": Axyc, "Ayzc": Ayzc, "regime": np.where(case2, 2, 1),
        "too_wide": np.where(case2, too_wide2, too_wide1),
    }


def _interface_shear(interface: str, Hc: np.ndarray, Hs: np.ndarray, f: np.ndarray,
                     H0: np.ndarray, Cp: np.ndarray, np_: np.ndarray, load: np.ndarray,
                     Axy: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Interface shear strengths (tau_c, tau_s) of the three interface models."""
    if interface == "proportional":
        return f * Hc / K0, f * Hs / K0
    if interface == "constant":
        tau = H0 / K0
        return tau, tau
    pressure = load / Axy
    tau = Cp * pressure**np_
    return tau, tau


# ----------------------------------------------------------------------------- validation
def _positive(name: str, value: np.ndarray, unit: str) -> None:
    bad = ~(np.isfinite(value) & (value > 0))
    if np.any(bad):
        v = np.asarray(value)[bad].flat[0] if np.ndim(value) else value
        raise ValueError(f"{name} = {float(v):g} {unit} is not allowed; it must be > 0 (0 < {name} < inf)")


def _validate(load, r, t, Hc, Hs, k1, interface, f, H0, Cp, np_, correction) -> None:
    _positive("load_N", load, "N")
    _positive("radius_m", r, "m")
    _positive("coating_hardness_Pa", Hc, "Pa")
    _positive("substrate_hardness_Pa", Hs, "Pa")
    _positive("k1", k1, "")
    bad = ~(np.isfinite(t) & (t >= 0))
    if np.any(bad):
        v = np.asarray(t)[bad].flat[0] if np.ndim(t) else t
        raise ValueError(f"thickness_m = {float(v):g} m is not allowed; it must be >= 0 (0 <= t < inf)")
    if interface not in INTERFACE_NAMES:
        raise ValueError(f"interface = {interface!r} is unknown; allowed: {', '.join(INTERFACE_NAMES)}")
    if correction not in CORRECTIONS:
        raise ValueError(f"correction = {correction!r} is unknown; allowed: {', '.join(CORRECTIONS)}")
    if interface == "proportional":
        bad = ~((f >= 0) & (f <= 1))
        if np.any(bad):
            v = np.asarray(f)[bad].flat[0] if np.ndim(f) else f
            raise ValueError(f"f = {float(v):g} is outside the allowed range [0, 1]")
    if interface == "constant":
        _positive("H0_Pa", H0, "Pa")
    if interface == "boundary_layer":
        _positive("Cp", Cp, "")
        bad = ~((np_ >= 0) & (np_ <= 1))
        if np.any(bad):
            v = np.asarray(np_)[bad].flat[0] if np.ndim(np_) else np_
            raise ValueError(f"np = {float(v):g} is outside the allowed range [0, 1]")


def _check_representable(values: dict[str, np.ndarray], load: np.ndarray, r: np.ndarray) -> None:
    """Refuse inputs whose results leave double precision (an area of 1e600 m2), naming them, rather than
    print inf or nan."""
    for name, value in values.items():
        bad = ~np.isfinite(value)
        if np.any(bad):
            i = np.flatnonzero(np.ravel(np.broadcast_to(bad, load.shape)))[0]
            raise ValueError(f"load_N = {float(np.ravel(load)[i]):g} N with radius_m = {float(np.ravel(r)[i]):g} m "
                             f"gives {name} = {float(np.ravel(np.broadcast_to(value, load.shape))[i]):g}, beyond "
                             "double precision (allowed: inputs whose contact areas and forces are finite numbers)")


# ----------------------------------------------------------------------------- entry point
def ploughing(
    load_N: float | np.ndarray,
    radius_m: float | np.ndarray,
    thickness_m: float | np.ndarray,
    coating_hardness_Pa: float | np.ndarray,
    substrate_hardness_Pa: float | np.ndarray,
    k1: float | np.ndarray = 125.0,
    interface: InterfaceName = "proportional",
    *,
    f: float | np.ndarray = 1.0,
    H0_Pa: float | np.ndarray = 450e6,
    Cp: float | np.ndarray = 0.32,
    np_exponent: float | np.ndarray = 0.95,
    correction: Correction = "none",
    max_iterations: int = 200,
    rtol: float = 1e-12,
) -> PloughingResult:
    """Friction and ploughing depth of a rigid sphere sliding on a coated substrate.

    Every numeric input may be a scalar or an array; arrays broadcast against each other.

    Parameters
    ----------
    load_N: normal load Fn (N). radius_m: sphere radius r (m). thickness_m: coating thickness t
    (m, 0 = uncoated). coating_hardness_Pa, substrate_hardness_Pa: Hc, Hs (Pa). k1: factor of
    eq. 1. interface: ``proportional`` (tau = f H / k0), ``constant`` (tau = H0 / k0) or
    ``boundary_layer`` (tau = Cp P^np). correction: normal-load correction of eq. 5,
    ``none``, ``once`` (the paper) or ``converged`` (fixed point of Fn' = Fn + Fz_sh(Fn')).
    """
    load, r, t, Hc, Hs, k1a, fa, H0, Cpa, npa = np.broadcast_arrays(
        *(np.asarray(x, dtype=float) for x in
          (load_N, radius_m, thickness_m, coating_hardness_Pa, substrate_hardness_Pa, k1, f,
           H0_Pa, Cp, np_exponent))
    )
    _validate(load, r, t, Hc, Hs, k1a, interface, fa, H0, Cpa, npa, correction)
    Hcs = effective_hardness(t, r, Hc, Hs, k1a)

    def evaluate(carried: np.ndarray) -> tuple[dict[str, np.ndarray], np.ndarray, np.ndarray]:
        geo = _contact_geometry(carried, r, t, Hcs, Hs)
        if np.any(geo["too_wide"]):
            i = np.flatnonzero(np.ravel(geo["too_wide"]))[0]
            given, held = float(np.ravel(load)[i]), float(np.ravel(carried)[i])
            raised = "" if held == given else (
                f" once the normal-load correction (eq. 5, correction = {correction!r}) has raised the carried "
                f"load to {held:.4g} N by the interface shear's vertical part (a smaller interface shear, or "
                "correction = 'none')")
            raise ValueError(
                f"load_N = {given:g} N is too large for radius_m = "
                f"{float(np.ravel(r)[i]):g} m{raised}: the model has no contact with the ploughing depth "
                f"below the sphere's equator (allowed: dp < r, contact radius a < r)"
            )
        tau_c, tau_s = _interface_shear(interface, Hc, Hs, fa, H0, Cpa, npa, carried, geo["Axy"])
        return geo, np.broadcast_to(tau_c, load.shape), np.broadcast_to(tau_s, load.shape)

    carried = load
    geo, tau_c, tau_s = evaluate(carried)
    if correction != "none":
        n_iter = 1 if correction == "once" else max_iterations
        for _ in range(n_iter):
            new = load + tau_s * geo["Ayzs"] + tau_c * geo["Ayzc"]
            done = np.all(np.abs(new - carried) <= rtol * new)
            carried = new
            geo, tau_c, tau_s = evaluate(carried)
            if done:
                break
        else:
            if correction == "converged":
                raise RuntimeError(f"normal-load correction did not converge in {max_iterations} iterations")

    Fz_sh = tau_s * geo["Ayzs"] + tau_c * geo["Ayzc"]
    mu_pl = (Hs * geo["Ayzs"] + Hc * geo["Ayzc"]) / load
    mu_sh = (tau_s * geo["Axys"] + tau_c * geo["Axyc"]) / load
    _check_representable({"Axy": geo["Axy"], "Ayz": geo["Ayz"], "Fz_sh": Fz_sh, "mu_pl": mu_pl, "mu_sh": mu_sh},
                         load, r)
    return PloughingResult(
        Hcs=Hcs, load_carried=np.asarray(carried, dtype=float), dp=geo["dp"], ds=geo["ds"],
        a=geo["a"], a_s=geo["a_s"], Axy=geo["Axy"], Axys=geo["Axys"], Axyc=geo["Axyc"],
        Ayz=geo["Ayz"], Ayzs=geo["Ayzs"], Ayzc=geo["Ayzc"], tau_c=np.array(tau_c),
        tau_s=np.array(tau_s), Fz_sh=Fz_sh, mu_pl=mu_pl, mu_sh=mu_sh, mu=mu_pl + mu_sh,
        regime=geo["regime"],
    )
