"""What the main command's figures rest on: per MPM figure dataset (benchmarks/results/main_octave/figNN.nc; the
current main command's in benchmarks/results/main) and panel (the variables' suffix: none, _a / _b, _t / _bulk),
how many points have an h -> 0 value of mu, by which
extrapolation method, how many of mu's and dp's are flagged (a fallback from Richardson), how many of the points'
runs are not steady, the median relative uncertainty of mu at h -> 0, and the h -> 0 values of mu and dp against
the analytical model's (the range of their ratio, and at how many points the analytical value lies within the
h -> 0 value's uncertainty). Figs. 11 and 13, 15 and 20, 16, 21 and
22 share their runs; Fig. 22's MPM points are Fig. 16's.

    PYTHONPATH=src python figures_quality.py benchmarks/results/main_octave
"""
import argparse
from pathlib import Path

import numpy as np
import xarray as xr

from plough.study.extrapolation import Method


def against_analytical(ds: xr.Dataset, q: str, sfx: str) -> str:
    """'min-max ratio | n of m within bars' of quantity q's h -> 0 value against the analytical model's."""
    h0 = ds[f"{q}_h0{sfx}"].values.ravel()
    err = ds[f"{q}_h0_uncertainty{sfx}"].values.ravel()
    ana = np.broadcast_to(ds[f"{q}_analytical{sfx}"].values, ds[f"{q}_h0{sfx}"].shape).ravel()
    ok = np.isfinite(h0) & np.isfinite(ana) & (ana != 0)
    if not ok.any():
        return "- | -"
    ratio = h0[ok] / ana[ok]
    within = int(np.sum(np.abs(h0[ok] - ana[ok]) <= err[ok]))
    return f"{ratio.min():.2f}-{ratio.max():.2f} | {within} of {int(ok.sum())}"


p = argparse.ArgumentParser()
p.add_argument("folder", type=Path)
a = p.parse_args()
print(f"| figure | panel | points | mu: {' / '.join(m.name.lower() for m in Method)} | mu flagged "
      "| dp flagged | runs | runs not steady | median relative uncertainty of mu | mu / analytical "
      "| mu within its bars | dp / analytical | dp within its bars |")
print("|---|---|---|---|---|---|---|---|---|---|---|---|---|")
for nc in sorted(a.folder.glob("fig*.nc")):
    with xr.open_dataset(nc) as ds:
        for name in sorted(v for v in ds.data_vars if v.startswith("mu_h0_method")):
            sfx = name.removeprefix("mu_h0_method")
            method = ds[name].values.ravel()
            have = method != Method.MISSING
            counts = " / ".join(str(int(np.sum(method == m))) for m in Method)
            mu_flag = int(np.sum(ds[f"mu_h0_flagged{sfx}"].values.ravel()[have]))
            dp_have = ds[f"dp_h0_method{sfx}"].values.ravel() != Method.MISSING
            dp_flag = int(np.sum(ds[f"dp_h0_flagged{sfx}"].values.ravel()[dp_have]))
            made = np.isfinite(ds[f"mu{sfx}"].values)
            not_steady = int(np.sum(made & (ds[f"steady{sfx}"].values == 0)))
            rel = np.abs(ds[f"mu_h0_uncertainty{sfx}"].values / ds[f"mu_h0{sfx}"].values).ravel()[have]
            rel = rel[np.isfinite(rel)]
            against = [against_analytical(ds, q, sfx) for q in ("mu", "dp")]
            print(f"| {nc.stem} | {sfx.lstrip('_') or '-'} | {int(have.sum())} | {counts} | {mu_flag} | {dp_flag} "
                  f"| {int(made.sum())} | {not_steady} | {np.median(rel):.2f} | {' | '.join(against)} |")
