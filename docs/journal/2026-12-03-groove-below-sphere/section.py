"""The particles of the Fig. 14 run's middle residual cross-section (journal 2026-12-03-groove-below-sphere.md,
"The trench's particles"): the highest two particles of each column of width h (centre y, z in um; coating
volume fraction).

    python docs/journal/2026-12-03-groove-below-sphere/section.py --h-um 10 --keep /tmp/fig14_h10.nc
"""

from __future__ import annotations

import argparse
import importlib.util
from pathlib import Path

import numpy as np
import xarray as xr

_spec = importlib.util.spec_from_file_location("probe", Path(__file__).with_name("probe.py"))
probe = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(probe)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--h-um", type=float, default=10.0)
    ap.add_argument("--keep", type=Path, required=True, help="the run's dataset (made if missing)")
    ap.add_argument("--width-um", type=float, default=60.0)
    a = ap.parse_args()
    if not a.keep.exists():
        probe.run_quietly(probe.fig14_scene(a.h_um)).to_netcdf(a.keep)
    ds = xr.load_dataset(a.keep)
    y, z = ds["section_y"].values * 1e6, ds["section_z"].values * 1e6
    coat, h = ds["section_coating"].values, a.h_um
    for lo in np.arange(0.0, a.width_um, h):
        sel = np.flatnonzero((y >= lo) & (y < lo + h))
        top = sel[np.argsort(-z[sel])][:2]
        print(f"{lo:.0f}-{lo + h:.0f} um: " + "  ".join(
            f"({y[i]:.1f}, {z[i]:.1f}) coating {coat[i]:.2f}" for i in top))


if __name__ == "__main__":
    main()
