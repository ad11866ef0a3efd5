"""What the GCI's new safety-factor rule does to the main command's figure datasets (one-off probe).

    PYTHONPATH=src python docs/journal/2026-12-07-gci-safety-factor/impact.py /work/guardrun/results/datasets \
        [--restamp OUT_DIR]

For every MPM figure dataset (``figNN.nc`` with ``<output>_h0_method`` variables) and every limit the figures
extrapolated by Richardson (a point counted once per figure and output), the GCI-type uncertainty is recomputed
from the point's per-size values with today's ``extrapolate`` and with the rule before (Fs = 1.25 with the observed
order); the stored uncertainty must equal the latter (a check that the probe reads what the figures drew). Printed
per output: how many limits are Richardson, their observed orders, and the ratio after / before of the GCI and of
the figures' bar (the GCI and the stored sampling error in quadrature). Fallback, two-size and converged limits do
not change. With ``--restamp``, writes each dataset to OUT_DIR with its Richardson limits' uncertainties recomputed
under today's rule (nothing else changed), for ``2026-12-05-main-command-restart/figures_quality.py`` to read
before and after.
"""

from __future__ import annotations

import argparse
from pathlib import Path

import numpy as np
import xarray as xr

from plough.study.extrapolation import SAFETY_FACTOR_THREE_OR_MORE, Method, extrapolate


def limits(directory: Path, restamp: Path | None = None) -> list[dict[str, object]]:
    """Every Richardson limit of the datasets under ``directory``: its order and the ratios after / before of
    its GCI and of its bar with the sampling error; with ``restamp``, the datasets written there with today's."""
    out = []
    for path in sorted(directory.glob("fig*.nc")):
        with xr.load_dataset(path) as ds:
            for name in ds.data_vars:
                if "_h0_method" not in name:
                    continue
                output, suffix = name.split("_h0_method")
                method = ds[name].values
                for idx in zip(*np.nonzero(method == Method.RICHARDSON), strict=True):
                    sel = dict(zip(ds[name].dims, idx, strict=True))
                    per_size = ds[output + suffix].isel(sel)
                    h = np.asarray(per_size["h"].values, dtype=float)
                    f = np.asarray(per_size.values, dtype=float)
                    order = np.argsort(h)
                    h, f = h[order], f[order]
                    ex = extrapolate(h, f)
                    # the rule before 2026-12-07: Fs = 1.25 at the observed order (a given Fs is that)
                    before = float(extrapolate(h, f, safety_factor=SAFETY_FACTOR_THREE_OR_MORE).uncertainty)
                    stored = float(ds[f"{output}_h0_uncertainty{suffix}"].isel(sel))
                    if not np.isclose(stored, before, rtol=1e-9, atol=0):
                        raise SystemExit(f"{path.name} {output}{suffix} {sel}: stored {stored} != {before}")
                    se_name = f"{output}_h0_sampling_error{suffix}"
                    se = float(np.nan_to_num(ds[se_name].isel(sel))) if se_name in ds else 0.0
                    if restamp is not None:
                        ds[f"{output}_h0_uncertainty{suffix}"][sel] = float(ex.uncertainty)
                    out.append({"figure": path.stem, "output": output, "order": float(ex.order),
                                "gci": float(ex.uncertainty) / before,
                                "bar": float(np.hypot(float(ex.uncertainty), se) / np.hypot(before, se))})
            if restamp is not None:
                ds.to_netcdf(restamp / path.name)
    return out


def main(directory: Path, restamp: Path | None) -> None:
    """Print the ratios per output."""
    if restamp is not None:
        restamp.mkdir(parents=True, exist_ok=True)
    table = limits(directory, restamp)
    print("| output | Richardson limits | order: median (range) | within 10% of 1 | GCI after / before: median "
          "(range) | bar after / before: median (range) |")
    print("|---|---|---|---|---|---|")
    for output in dict.fromkeys(r["output"] for r in table):
        rows = [r for r in table if r["output"] == output]
        p, g, b = (np.array([r[k] for r in rows]) for k in ("order", "gci", "bar"))
        print(f"| {output} | {len(rows)} | {np.median(p):.2f} ({p.min():.2f}-{p.max():.2f}) | "
              f"{np.sum(np.abs(p - 1) <= 0.1)} | {np.median(g):.1f}x ({g.min():.2f}-{g.max():.1f}x) | "
              f"{np.median(b):.1f}x ({b.min():.2f}-{b.max():.1f}x) |")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("datasets", type=Path)
    parser.add_argument("--restamp", type=Path, default=None)
    args = parser.parse_args()
    main(args.datasets, args.restamp)
