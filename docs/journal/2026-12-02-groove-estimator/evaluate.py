"""One-off probe (docs/journal/2026-12-02-groove-estimator.md): groove estimators on the kept final states
of collect.py, their spread over the lattice phases and their jackknife errors.

    python docs/journal/2026-12-02-groove-estimator/evaluate.py [--out FILE]
"""

from __future__ import annotations

import argparse
import json
import re
import sys
import warnings
from collections import defaultdict
from pathlib import Path
from typing import NamedTuple

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE))
from collect import phase_scene  # noqa: E402

from plough.mpm import io as pio  # noqa: E402


class P(NamedTuple):
    x: np.ndarray
    vol0: np.ndarray
    J: np.ndarray
    n: int


def profiles(p, scene, centre_x, a, y_shift=0.0):
    """section_profiles with the y bins shifted by y_shift (0 = the production bins)."""
    if y_shift == 0.0:
        return pio.section_profiles(p, scene, centre_x, a)
    orig = pio._y_edges
    try:
        pio._y_edges = lambda s: orig(s) + y_shift
        return pio.section_profiles(p, scene, centre_x, a)
    finally:
        pio._y_edges = orig


def production(y, prof, a):
    dg, hpu = pio.groove_depths(y, pio._nanmean_rows(prof), a)
    return dg + hpu


def vertex(y, z, i, half=2, kind="min"):
    """Quadratic through the bins i-half..i+half (finite ones); the extreme's value, clipped to the bins' range."""
    lo, hi = max(i - half, 0), min(i + half + 1, z.size)
    yy, zz = y[lo:hi], z[lo:hi]
    ok = np.isfinite(zz)
    if ok.sum() < 3:
        return z[i]
    c2, c1, c0 = np.polyfit(yy[ok], zz[ok], 2)
    if (kind == "min" and c2 <= 0) or (kind == "max" and c2 >= 0):
        return z[i]
    yv = np.clip(-c1 / (2 * c2), yy[ok].min(), yy[ok].max())
    return c0 + c1 * yv + c2 * yv * yv


def fitted(y, prof, a):
    """dg from the vertex of a parabola through the deepest mean bin and its neighbours, hpu likewise."""
    z = pio._nanmean_rows(prof)
    near = np.abs(y) <= 1.5 * a
    zi = np.where(near & np.isfinite(z), z, np.inf)
    i_min = int(np.argmin(zi))
    i_max = int(np.nanargmax(z))
    dg = max(-vertex(y, z, i_min, kind="min"), 0.0)
    hpu = max(vertex(y, z, i_max, kind="max"), 0.0)
    return dg + hpu


def centre_fit(y, prof, a):
    """dg from a least-squares z = c0 + c2 y^2 over every section's bins within a / 2 of the centre line
    (the groove's bottom, symmetric in y), hpu as the production's."""
    near = (np.abs(y) <= 0.5 * a)
    yy = np.broadcast_to(y[near], prof[:, near].shape)
    zz = prof[:, near]
    ok = np.isfinite(zz)
    c2, c0 = np.polyfit(yy[ok] ** 2, zz[ok], 1)
    _, hpu = pio.groove_depths(y, pio._nanmean_rows(prof), a)
    return max(-c0, 0.0) + hpu


def jack(stat, y, prof, a):
    return pio.jackknife_standard_error(lambda k: stat(y, prof[k], a), prof.shape[0])


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--out", default=str(HERE / "estimators.json"))
    args = ap.parse_args()
    rows = defaultdict(list)
    for f in sorted((HERE / "states").glob("*.npz")):
        name, h_um, k, n = re.match(r"(\w+?)_([\d.]+)_(\d+)of(\d+)\.npz", f.name).groups()
        d = np.load(f)
        scene = phase_scene(name, float(h_um), int(k), int(n))
        h = scene.discretisation.particle_size_m
        p = P(d["x"], d["vol0"], d["J"], d["x"].shape[0])
        a, _ = scene.expected_contact()
        cx = float(d["centre"][0])
        y, prof, _ = profiles(p, scene, cx, a)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", RuntimeWarning)
            r = {"phase": int(k) / int(n), "dp_dataset": float(d["dp"]), "production": production(y, prof, a),
                 "production_se": jack(production, y, prof, a), "fitted": fitted(y, prof, a),
                 "fitted_se": jack(fitted, y, prof, a), "centre_fit": centre_fit(y, prof, a),
                 "centre_fit_se": jack(centre_fit, y, prof, a)}
            shifted = []
            for s in (0.0, 0.25, 0.5, 0.75):
                ys, ps, _ = profiles(p, scene, cx, a, s * h)
                shifted.append(production(ys, ps, a))
            r["bin_shift_mean"] = float(np.mean(shifted))
            r["bin_shift_std"] = float(np.std(shifted, ddof=1))
        rows[f"{name}:{h_um}"].append(r)
    summary = {}
    for case, rs in rows.items():
        s = {"runs": len(rs)}
        for est in ("production", "fitted", "centre_fit", "bin_shift_mean"):
            v = np.array([r[est] for r in rs])
            s[est] = {"mean_um": v.mean() * 1e6, "std_um": v.std(ddof=1) * 1e6, "std_rel": v.std(ddof=1) / v.mean()}
            if f"{est}_se" in rs[0]:
                se = np.array([r[f"{est}_se"] or np.nan for r in rs])
                s[est]["median_se_um"] = float(np.nanmedian(se) * 1e6)
                s[est]["std_over_median_se"] = float(v.std(ddof=1) / np.nanmedian(se))
        s["bin_shift_std_median_um"] = float(np.median([r["bin_shift_std"] for r in rs]) * 1e6)
        summary[case] = s
        print(case, json.dumps(s, indent=None, default=float))
    Path(args.out).write_text(json.dumps({"summary": summary, "runs": rows}, indent=1, default=float))


if __name__ == "__main__":
    main()
