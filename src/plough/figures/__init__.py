"""Figures of studies.md drawn from their netCDF datasets (matplotlib, Agg backend)."""

from __future__ import annotations

import os

import xarray as xr

from plough.figures import analytical

PLOTTERS = dict(analytical.PLOTTERS)


def plot(figure: str, ds: xr.Dataset, outputs: list[str | os.PathLike[str]]) -> None:
    """Draw ``figure`` from its dataset into each of ``outputs`` (PNG, PDF)."""
    if figure not in PLOTTERS:
        raise ValueError(f"figure = {figure!r} is unknown; allowed: {sorted(PLOTTERS)}")
    analytical.plot(figure, ds, outputs) if figure in analytical.PLOTTERS else PLOTTERS[figure](ds, outputs)


__all__ = ["PLOTTERS", "plot"]
