"""Refinement only where needed: the finest particle size of a sweep point runs only where the two
coarser sizes do not already extrapolate well enough.

The finest size costs about 8 x 2 = 16 times the next one (eight times the particles, twice the
steps), so it dominates a reproduction. With ``mpm.skip_finest_tolerance`` set, a sweep point's two
coarser runs are extrapolated to h -> 0 (:func:`plough.study.extrapolation.extrapolate` with two
sizes: Richardson with the assumed order 1 and Roache's safety factor 3) by the workflow's
checkpoint ``mpm_refine`` (docs/workflow.md, "Refinement only where needed"), which writes the
*decision* (:func:`decide`, a JSON file ``results/refinement/<finest run id>.json``). If that
extrapolation's uncertainty (the GCI and the two runs' sampling errors carried to the limit, in
quadrature) is within the tolerance of its value for every steady-state output in :data:`CHECKED`
the finest run is not needed: the figure datasets read the decision, extrapolate that point from the
two coarser sizes, flagged ``TWO_SIZES_ASSUMED_ORDER`` (``CONVERGED``, not flagged, when the two
agree exactly), and the finest run is never scheduled. Otherwise the datasets need the finest run
and Snakemake makes it. Pictures (the single-run figures) always use a real finest run: their runs
are never gated; nor is a finest size the relative ladder's groove or coating target set
(``plough.study.matrix.UNGATED_TARGETS``): such a target added that size because it judged the two sizes
above it too coarse for the groove or the coating, so they do not stand in for it. The tolerance is one number for every
checked output or one per output (:func:`tolerances`).

Default off (``null``): every size runs (the paper's ladder, ``config/paper.yaml``).

*Skip markers*, the result files an earlier workflow wrote in place of a skipped finest run
(:data:`SKIPPED_ATTR`), are no longer written; :func:`is_skipped` lets the dataset builder refuse one.

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
from collections.abc import Mapping
from typing import Any

import numpy as np
import xarray as xr

from plough.io import provenance_attrs
from plough.mpm.io import STANDARD_ERROR_META
from plough.study.extrapolation import extrapolate, sampling_error, total_uncertainty

#: Outputs whose two-size extrapolation must be within the tolerance to skip the finest run.
CHECKED = ("mu", "dp")
#: the attribute of the skip markers an earlier workflow wrote (refused now: :func:`is_skipped`)
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
        total = float(total_uncertainty(unc, sampling, missing_sampling="unknown"))
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


def tolerances(tolerance: float | Mapping[str, float]) -> dict[str, float]:
    """``mpm.skip_finest_tolerance`` as output -> relative tolerance for every output of :data:`CHECKED`:
    one number for all, or a mapping naming each (``{mu: 0.05, dp: 0.3}``)."""
    given = dict(tolerance) if isinstance(tolerance, Mapping) else dict.fromkeys(CHECKED, tolerance)
    if set(given) != set(CHECKED):
        raise ValueError(f"mpm.skip_finest_tolerance = {tolerance!r} must be a number or name each of "
                         f"{', '.join(CHECKED)} (allowed: a finite number > 0 for each)")
    out = {}
    for name in CHECKED:
        value = given[name]
        if isinstance(value, bool) or not isinstance(value, int | float) or not (np.isfinite(value) and value > 0):
            raise ValueError(f"mpm.skip_finest_tolerance = {tolerance!r}: {name} = {value!r} must be a finite "
                             "number > 0")
        out[name] = float(value)
    return out


def should_skip(extrapolations: dict[str, dict[str, float]], tolerance: float | Mapping[str, float]) -> bool:
    """True when every checked output's relative uncertainty is within its tolerance (:func:`tolerances`)."""
    tol = tolerances(tolerance)
    return all(np.isfinite(e["relative_uncertainty"]) and e["relative_uncertainty"] <= tol[o]
               for o, e in extrapolations.items())


def run_size_um(run: xr.Dataset) -> float:
    """A run file's particle size (um), from the scene it records."""
    return float(json.loads(run.attrs["scene"])["discretisation"]["particle_size_m"]) * 1e6


def decide(finest_run: str, coarse: xr.Dataset, mid: xr.Dataset, coarse_runs: list[str],
           tolerance: float | Mapping[str, float]) -> dict[str, Any]:
    """The refinement decision of a sweep point (JSON-serialisable): whether its finest run ``finest_run`` is
    needed, from its two coarser runs (already checked against their runs), extrapolated at the particle
    sizes their files record (the point's own ladder)."""
    sizes = [run_size_um(coarse), run_size_um(mid)]
    ex = two_size_extrapolation(coarse, mid, sizes[0], sizes[1])
    skip = should_skip(ex, tolerance)
    # strict JSON: a number that is not finite (a sampling error not estimable, a limit of 0) is written as null
    # and named in the reason, never as NaN or Infinity
    written = {o: {k: (v if np.isfinite(v) else None) for k, v in e.items()} for o, e in ex.items()}
    return {"finest_run": finest_run, "run_finest": not skip, "coarser_runs": list(coarse_runs),
            "coarser_sizes_um": sizes, "tolerance": tolerances(tolerance), "extrapolations": written,
            "reason": (f"the two-size extrapolation of {', '.join(coarse_runs)} (h = {sizes[0]:g}, {sizes[1]:g} um) is "
                       f"{'not ' if not skip else ''}within skip_finest_tolerance for {', '.join(ex)}: relative "
                       "uncertainty " + ", ".join(f"{o} {_relative(e)}" for o, e in ex.items()))}


def _relative(extrapolation: dict[str, float]) -> str:
    """A relative uncertainty for the decision's reason; where it is not a number, why."""
    rel = extrapolation["relative_uncertainty"]
    if np.isfinite(rel):
        return f"{rel:.3g}"
    if not np.isfinite(extrapolation["sampling_error"]):
        return "unknown (a coarser run could not estimate its sampling error)"
    return "unbounded (the limit is 0)"


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
