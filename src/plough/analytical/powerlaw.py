"""Power-law fits of the paper's section 4.2.2 (eqs. 9.1-9.2).

    dp = a1 Fn^x1,  Ayz = b1 dp^y1,  Axy = c1 dp^z1
    mu_pl = Hc b1 dp^y1 / Fn,  mu_sh = Cp Axy^(1 - np) Fn^(np - 1)

The constants are the paper's as printed (model.md). They are not self-consistent in SI units
(a1 gives dp = 163 um at 22 N for the 1 mm ball; b1, y1 of the 1 mm ball give frontal areas far
larger than the sphere's), so these curves are shown as the paper's fits, flagged on the figure,
and never used to validate the MPM solver.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

PAPER_FIT_WARNING = (
    "power-law constants as printed in the paper; not self-consistent in SI units "
    "(see model.md) - shown for reference only"
)


@dataclass(frozen=True)
class PowerLawFit:
    """Constants of eqs. 9.1-9.2 for one ball."""

    a1: float
    x1: float
    b1: float
    y1: float
    c1: float
    z1: float
    coating_hardness_Pa: float = 3 * 85e6
    Cp: float = 0.32
    np: float = 0.95


#: The paper's printed fits (section 4.2.2), keyed by ball diameter in mm.
PAPER_FITS: dict[float, PowerLawFit] = {
    1.0: PowerLawFit(a1=8.6e-6, x1=0.95, b1=1.51, y1=0.96, c1=0.0015, z1=0.997),
    3.0: PowerLawFit(a1=4.7e-6, x1=0.85, b1=0.15, y1=1.5, c1=0.0046, z1=0.999),
}


@dataclass(frozen=True)
class PowerLawResult:
    dp: np.ndarray
    Ayz: np.ndarray
    Axy: np.ndarray
    mu_pl: np.ndarray
    mu_sh: np.ndarray
    mu: np.ndarray


def power_law_friction(load_N: float | np.ndarray, fit: PowerLawFit) -> PowerLawResult:
    """Eqs. 9.1-9.2 evaluated for the loads given (N)."""
    load = np.asarray(load_N, dtype=float)
    if np.any(~np.isfinite(load) | (load <= 0)):
        bad = load[~np.isfinite(load) | (load <= 0)].flat[0] if load.ndim else float(load)
        raise ValueError(f"load_N = {float(bad):g} N is not allowed; it must be > 0")
    dp = fit.a1 * load**fit.x1
    Ayz = fit.b1 * dp**fit.y1
    Axy = fit.c1 * dp**fit.z1
    mu_pl = fit.coating_hardness_Pa * Ayz / load
    mu_sh = fit.Cp * Axy ** (1.0 - fit.np) * load ** (fit.np - 1.0)
    return PowerLawResult(dp=dp, Ayz=Ayz, Axy=Axy, mu_pl=mu_pl, mu_sh=mu_sh, mu=mu_pl + mu_sh)
