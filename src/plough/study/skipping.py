"""Skipping the finest particle size where the two coarser sizes already extrapolate well enough.

The finest size costs about 8 x 2 = 16 times the next one (eight times the particles, twice the
steps), so it dominates the full reproduction. With ``mpm.skip_finest_tolerance`` set, the run of
a sweep point at the finest size first reads the point's two next-coarser runs and extrapolates
them to h -> 0 (:func:`plough.study.extrapolation.extrapolate` with two sizes: Richardson with the
assumed order 1 and Roache's safety factor 3). If that extrapolation's uncertainty (the GCI and the
two runs' sampling errors carried to the limit, in quadrature) is within the
tolerance of its value for every steady-state output in :data:`CHECKED` the finest run is not
made: its result file is a *skip marker* (no result variables; attributes say why, with the two
extrapolations), and the figure dataset extrapolates that point from the two coarser sizes, flagged
``TWO_SIZES_ASSUMED_ORDER`` (``CONVERGED``, not flagged, when the two agree exactly). Pictures
(the single-run figures) always use a real finest run. A marker where the config does not allow
skipping that run is refused by the dataset builder.

Default off (``null``): the faithful reproduction runs every size.

**Failure markers.** A finest sweep run may also stop unstable (``plough.mpm.solver.InstabilityError``:
at h = 2.5 um a prow can grow until material leaves the grid, docs/journal/2026-11-22-prow-at-h2.5.md). With
``mpm.finest_failure: record`` (the default) its result file is then a *failure marker* (no result
variables; the solver's message, the run id and provenance as attributes) and the figure dataset
extrapolates that point from the two coarser sizes, as for a skipped run, flagged ``failed_finest``.
With ``stop`` the job fails and the workflow with it. Any other error (a refused scene, a load
the sphere cannot reach, lost contact, a bug) always fails the job, and a failure marker where the
config does not allow one is refused by the dataset builder. A picture's finest run is never
recorded: in config/config.yaml each is also a sweep point (the rigid-plastic one of Figs. 11-13,
the zinc-coated steel one at 22 N of Figs. 14, 16-19 and 21-23, the zinc block at 22 N of Figs. 15,
17, 18, 20 and 23), so its stop fails every figure that needs it.
"""

from __future__ import annotations

import json
from typing import Any

import numpy as np
import xarray as xr

from plough.io import provenance_attrs
from plough.mpm.io import STANDARD_ERROR_META
from plough.study.extrapolation import extrapolate, sampling_error

#: Outputs whose two-size extrapolation must be within the tolerance to skip the finest run.
CHECKED = ("mu", "dp")
SKIPPED_ATTR = "skipped_finest_size"
FAILED_ATTR = "failed_finest_size"


def two_size_extrapolation(coarse: xr.Dataset, mid: xr.Dataset, h_coarse_um: float, h_mid_um: float,
                           outputs: tuple[str, ...] = CHECKED) -> dict[str, dict[str, float]]:
    """output -> {value, uncertainty, sampling_error, relative_uncertainty} of the two-size extrapolation.

    ``uncertainty`` is the GCI (safety factor 3); ``sampling_error`` the two runs' own standard
    errors (``<output>_standard_error``; 0 for files from before they were written, NaN, so no skip,
    where a newer run could not estimate it) carried to the limit, 2 s_mid and s_coarse in
    quadrature at order 1 and r = 2. The relative uncertainty that decides takes both in
    quadrature: two coarse runs whose noise alone exceeds the tolerance do not stand in for the
    finest.
    """
    out = {}
    h = [h_coarse_um, h_mid_um]
    for o in outputs:
        f = [float(coarse[o]), float(mid[o])]
        ex = extrapolate(h, f)
        sampling = float(sampling_error(h, f, [_run_error(run, o) for run in (coarse, mid)]))
        value, unc = float(ex.value), float(ex.uncertainty)
        total = float(np.hypot(unc, sampling))
        rel = total / abs(value) if value != 0 else (0.0 if total == 0 else np.inf)
        out[o] = {"value": value, "uncertainty": unc, "sampling_error": sampling, "relative_uncertainty": rel}
    return out


def _run_error(run: xr.Dataset, output: str) -> float:
    """A run's sampling error of ``output``: 0 for a file from before the errors were written (none of
    them), NaN where this one could not be estimated (then the finest run is never skipped)."""
    name = f"{output}_standard_error"
    if name in run:
        return float(run[name])
    return 0.0 if not any(n in run for n in STANDARD_ERROR_META) else float("nan")


def should_skip(extrapolations: dict[str, dict[str, float]], tolerance: float) -> bool:
    """True when every checked output's relative uncertainty is within ``tolerance``."""
    if not (np.isfinite(tolerance) and tolerance > 0):
        raise ValueError(f"mpm.skip_finest_tolerance = {tolerance!r} must be a finite number > 0")
    return all(np.isfinite(e["relative_uncertainty"]) and e["relative_uncertainty"] <= tolerance
               for e in extrapolations.values())


def skip_marker(scene: dict[str, Any], extrapolations: dict[str, dict[str, float]], tolerance: float,
                coarse_runs: list[str]) -> xr.Dataset:
    """The result file of a skipped run: no result variables, the reason and provenance as attributes."""
    return xr.Dataset(attrs={
        SKIPPED_ATTR: 1,
        "skip_reason": (f"the two-size extrapolation of {', '.join(coarse_runs)} is within "
                        f"skip_finest_tolerance = {tolerance:g} for {', '.join(extrapolations)}"),
        "skip_extrapolations": json.dumps(extrapolations),
        **provenance_attrs(scene, key="scene"),
    })


def is_skipped(ds: xr.Dataset) -> bool:
    return bool(ds.attrs.get(SKIPPED_ATTR, 0))


def failure_marker(scene: dict[str, Any], run_id: str, message: str, coarse_runs: list[str]) -> xr.Dataset:
    """The result file of a finest sweep run that stopped unstable: no result variables; the solver's
    message, the run and the two coarser runs that stand in for it, and provenance, as attributes."""
    return xr.Dataset(attrs={
        FAILED_ATTR: 1,
        "failure_reason": f"run {run_id} stopped: {message}",
        "failure_stands_in": (f"the two-size extrapolation of {', '.join(coarse_runs)} "
                              "(mpm.finest_failure: record)"),
        **provenance_attrs(scene, key="scene"),
    })


def is_failed(ds: xr.Dataset) -> bool:
    return bool(ds.attrs.get(FAILED_ATTR, 0))
