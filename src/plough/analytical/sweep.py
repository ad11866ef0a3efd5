"""The analytical model over the cartesian product of coordinates, as an ``xarray.Dataset``.

Same equations as :mod:`plough.analytical.model` (eqs. 1-5); this module only lays the inputs
out on a grid and attaches units and long names.
"""

from __future__ import annotations

from collections.abc import Mapping, Sequence

import numpy as np
import xarray as xr

from plough.analytical.model import RESULT_META, ploughing

#: Coordinates a sweep may span, with units and long names. ``hardness_ratio`` (H~ = Hc / Hs)
#: may replace ``coating_hardness_Pa``: then Hc = H~ * Hs.
COORD_META: dict[str, tuple[str, str]] = {
    "load_N": ("N", "normal load"),
    "radius_m": ("m", "sphere radius"),
    "thickness_m": ("m", "coating thickness"),
    "coating_hardness_Pa": ("Pa", "coating hardness"),
    "substrate_hardness_Pa": ("Pa", "substrate hardness"),
    "hardness_ratio": ("1", "coating to substrate hardness ratio Hc/Hs"),
    "k1": ("1", "effective-hardness factor k1 of eq. 1"),
    "f": ("1", "interface shear factor f"),
}


def ploughing_dataset(
    coords: Mapping[str, Sequence[float] | np.ndarray],
    **fixed: float | str,
) -> xr.Dataset:
    """Evaluate :func:`~plough.analytical.ploughing` on the product of ``coords``.

    ``coords`` maps input names (keys of ``COORD_META``) to 1-D values; ``fixed`` gives the
    remaining inputs as scalars (and ``interface``, ``correction``). Every variable carries
    ``units`` and ``long_name``.
    """
    unknown = set(coords) - set(COORD_META)
    if unknown:
        raise ValueError(f"coords {sorted(unknown)} are unknown; allowed: {sorted(COORD_META)}")
    names = list(coords)
    values = [np.asarray(coords[n], dtype=float) for n in names]
    for n, v in zip(names, values, strict=True):
        if v.ndim != 1 or v.size == 0:
            raise ValueError(f"coordinate {n} must be a non-empty 1-D sequence, got shape {v.shape}")
    grids = np.meshgrid(*values, indexing="ij") if values else []
    inputs: dict[str, object] = dict(fixed)
    inputs.update(zip(names, grids, strict=True))
    ratio = inputs.pop("hardness_ratio", None)
    if ratio is not None:
        if "coating_hardness_Pa" in inputs:
            raise ValueError("give either hardness_ratio or coating_hardness_Pa, not both")
        inputs["coating_hardness_Pa"] = np.asarray(ratio) * np.asarray(inputs["substrate_hardness_Pa"])
    np_exponent = inputs.pop("np", None)
    if np_exponent is not None:
        inputs["np_exponent"] = np_exponent
    result = ploughing(**inputs)

    shape = tuple(v.size for v in values)
    data_vars = {}
    for name, arr in result.as_dict().items():
        units, long_name = RESULT_META[name]
        data_vars[name] = (names, np.broadcast_to(arr, shape).copy(), {"units": units, "long_name": long_name})
    ds = xr.Dataset(
        data_vars,
        coords={n: (n, v, {"units": COORD_META[n][0], "long_name": COORD_META[n][1]})
                for n, v in zip(names, values, strict=True)},
    )
    ds["coating_worn"] = ds["regime"] == 2
    ds["coating_worn"].attrs = {"units": "1", "long_name": "sphere ploughs through the coating (dp > t)"}
    ds.attrs["model"] = "plough.analytical.ploughing (Mishra et al. 2020, eqs. 1-5)"
    for k, v in fixed.items():
        ds.attrs[k] = v
    return ds
