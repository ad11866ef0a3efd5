"""Figures of studies.md drawn from their netCDF datasets (matplotlib, Agg backend)."""

from __future__ import annotations

import os

import numpy as np
import xarray as xr

from plough.figures import analytical, mpm

PLOTTERS = {**analytical.PLOTTERS, **mpm.PLOTTERS}


def plot(figure: str, ds: xr.Dataset, outputs: list[str | os.PathLike[str]]) -> None:
    """Draw ``figure`` from its dataset into each of ``outputs`` (PNG, PDF).

    A dataset with an empty or all-NaN variable is an error, never an empty plot.
    """
    if figure not in PLOTTERS:
        raise ValueError(f"figure = {figure!r} is unknown; allowed: {sorted(PLOTTERS)}")
    for name, var in ds.data_vars.items():
        if var.size == 0 or (var.dtype.kind == "f" and not np.isfinite(var.values).any()):
            raise ValueError(f"{figure}: variable {name!r} has no data; refusing to draw an empty plot")
    PLOTTERS[figure](ds, outputs)


__all__ = ["PLOTTERS", "plot"]
