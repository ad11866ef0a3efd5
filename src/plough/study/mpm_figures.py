"""Datasets behind the MPM figures of studies.md (Figs. 11-21, 23 and the MPM points of Fig. 22).

Sweep figures: for every panel, each output of :data:`plough.study.matrix.OUTPUTS` per particle
size (dims ``series, axis, h``), its extrapolation to h -> 0 (Richardson with the observed order and
Roache's GCI, least-squares fallback flagged; :mod:`plough.study.extrapolation`) as
``<output>_h0``, ``<output>_h0_uncertainty``, ``<output>_h0_order``, ``<output>_h0_method``,
``<output>_h0_flagged``, the runs' sampling errors (``<output>_standard_error`` per size) and
their propagation to the limit (``<output>_h0_sampling_error``), and the analytical model (eqs.
1-5) on the same coordinates as ``<output>_analytical``. A figure with two panels suffixes its
variables with the panel name (``dp_a``, ``dp_b``). Single-run figures keep the force histories,
profiles and particle pictures of the finest run of each case, along a ``case`` dimension.

Coordinates are the config's values (never float arithmetic), so datasets align exactly.
"""

from __future__ import annotations

import json
from collections.abc import Collection, Mapping
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from plough.io import provenance_attrs
from plough.mpm.io import STANDARD_ERROR_META, STEADINESS_META, STEADY_META
from plough.study import matrix
from plough.study.extrapolation import extrapolate_dataarray, sampling_error
from plough.study.runfiles import load_run, remedy
from plough.study.skipping import is_failed, is_skipped

TITLES = {
    "fig11": "Fig. 11 - ploughing depth dp, MPM vs analytical, rigid-plastic coating",
    "fig12": "Fig. 12 - soft coating piling up ahead of the sphere, and the forces while sliding",
    "fig13": "Fig. 13 - friction coefficient mu and its parts mu_pl, mu_sh, MPM vs analytical, rigid-plastic coating",
    "fig14": "Fig. 14 - zinc-coated steel ploughed by a ball: height map, residual cross-section, materials",
    "fig15": "Fig. 15 - ploughing depth vs load, zinc block and DX56 steel",
    "fig16": "Fig. 16 - ploughing depth vs load, zinc-coated steel, two ball sizes",
    "fig17": "Fig. 17 - residual cross-sections at the surface and at depth, coated steel vs zinc block",
    "fig18": "Fig. 18b - ploughing depth vs coating thickness, zinc-coated steel and bulk zinc",
    "fig19": "Fig. 19 - forces vs sliding distance, zinc-coated steel",
    "fig20": "Fig. 20 - friction coefficient vs load, zinc block and DX56 steel",
    "fig21": "Fig. 21 - friction coefficient vs load, zinc-coated steel, two ball sizes",
    "fig23": "Fig. 23a - friction coefficient vs load: coated steel, zinc block and DX56 steel",
}

#: What the single-run figures draw of their run(s).
SINGLE_RUN_VARIABLES = {
    "fig12": ("Fx", "Fz", "Fx_pl", "Fx_sh", "depth", "in_steady_window", "midplane_x", "midplane_z",
              "midplane_coating", "midplane_eps_p", "profile_z"),
    "fig14": ("height_map", "profile_z", "section_y", "section_z", "section_coating", "section_eps_p"),
    "fig17": ("profile_z", "buried_profile_z"),
    "fig19": ("Fx", "Fz", "Fx_pl", "Fx_sh", "depth", "in_steady_window"),
}


def load_runs(run_ids: list[str], paths: Mapping[str, str | Path], scenes: Mapping[str, dict[str, Any]] | None = None,
              solver: str | None = None) -> dict[str, xr.Dataset]:
    """Load the result file of every run, each checked against the run it stands for
    (:func:`plough.study.runfiles.load_run`: its scene, ``scenes[run]`` if given, and the solver
    fingerprint ``solver`` if given); a missing, unreadable or wrong file is an error naming it
    (never an empty plot, never another run's numbers)."""
    out = {}
    for rid in run_ids:
        if rid not in paths:
            raise FileNotFoundError(f"the result of run {rid!r} is missing (no file given); run it first")
        out[rid] = load_run(paths[rid], rid, None if scenes is None else scenes[rid], solver)
    return out


def _panel_dataset(panel: matrix.Panel, sizes_um: tuple[float, ...], runs: Mapping[str, xr.Dataset],
                   suffix: str, not_needed: Collection[str] = (), recordable: Collection[str] = (),
                   ladders: Mapping[str, tuple[float, ...]] | None = None) -> xr.Dataset:
    """One panel's per-size values and their h -> 0 extrapolation. ``sizes_um`` descending; a run in
    ``not_needed`` (gated finest runs their refinement decision did not ask for) is not read, one in
    ``recordable`` (``matrix.failure_recordable_runs``) may be a failure marker; any other marker is
    refused. Either way the point is extrapolated from the two coarser sizes."""
    labels = [s.label for s in panel.series]
    ax_units, ax_long = matrix.AXES[panel.axis]
    coords = {
        panel.series_dim: ((panel.series_dim,), labels, {"long_name": panel.series_dim.replace("_", " ")}),
        panel.axis: ((panel.axis,), np.asarray(panel.values, dtype=float), {"units": ax_units, "long_name": ax_long}),
        "h": (("h",), np.asarray(sizes_um, dtype=float), {"units": "um", "long_name": "particle size h", **(
            {"comment": "the sizes of mpm.particle_sizes_um; each point's own (mpm.ladder: relative) are "
                        "particle_size_um, these times a scale: its extrapolation is the same"}
            if ladders else {})}),
    }
    shape = (len(labels), len(panel.values), len(sizes_um))
    per_size = {o: np.full(shape, np.nan) for o in (*matrix.OUTPUTS, "Fz_mean", "max_particle_penetration")}
    wall = np.full(shape, np.nan)
    size = np.full(shape, np.nan)  # each run's own particle size (the point's ladder: matrix.point_ladder)
    steady = np.full(shape, np.nan)  # stays NaN for skipped runs and files written before the check
    # sampling errors of each run (plough.mpm.io.standard_errors): NaN where skipped, not estimable, or
    # written before they were
    errors = {name: np.full(shape, np.nan) for name in STANDARD_ERROR_META}
    analytical = {o: np.full(shape[:2], np.nan) for o in matrix.ANALYTICAL_OUTPUTS}
    skipped = np.zeros(shape[:2], dtype=bool)
    failed = np.zeros(shape[:2], dtype=bool)
    for i, series in enumerate(panel.series):
        for j, point in enumerate(series.points):
            own = ladders[point.key] if ladders else sizes_um
            for k, h in enumerate(own):
                size[i, j, k] = h
                rid = matrix.run_id(point, h)
                if rid in not_needed:
                    skipped[i, j] = True
                    continue
                ds = runs[rid]
                if is_skipped(ds):
                    raise ValueError(f"run {rid!r} is a skip marker, which this workflow no longer writes (a "
                                     "finest run is now made only where its refinement decision asks for it); "
                                     f"{remedy(f'results/runs/{rid}.nc')}")
                if is_failed(ds):
                    if rid not in recordable:
                        raise ValueError(f"run {rid!r} is a failure marker ({ds.attrs.get('failure_reason')}), but "
                                         "the config does not allow one there (mpm.finest_failure is stop, fewer "
                                         "than three sizes, not the finest size, or a picture's run); "
                                         f"{remedy(f'results/runs/{rid}.nc')}")
                    failed[i, j] = True
                    continue
                for o in per_size:
                    per_size[o][i, j, k] = float(ds[o])
                wall[i, j, k] = float(ds.attrs["cost_wall_time_s"])
                if "steady" in ds:
                    steady[i, j, k] = float(ds["steady"])
                for name, values in errors.items():
                    if name in ds:
                        values[i, j, k] = float(ds[name])
            for o, v in matrix.analytical_values(point).items():
                analytical[o][i, j] = v
    dims3 = (panel.series_dim, panel.axis, "h")
    out = xr.Dataset(coords=coords)
    two_sizes = skipped | failed  # points extrapolated from the two coarser sizes
    for o, values in per_size.items():
        units, long_name = STEADY_META[o]
        da = xr.DataArray(values, dims=dims3, coords=coords, name=o,
                          attrs={"units": units, "long_name": f"{long_name} (MPM, per particle size)",
                                 **({"allow_missing": 1} if two_sizes.any() else {})})
        out[o + suffix] = da
        if o not in matrix.OUTPUTS:
            continue
        ex = extrapolate_dataarray(da, "h")
        # points whose finest run was skipped or failed: the two coarser sizes' extrapolation (flagged)
        ex_coarse = extrapolate_dataarray(da.sel(h=list(sizes_um[-3:-1])), "h") if two_sizes.any() else ex
        for field in ("value", "uncertainty", "order", "method", "flagged"):
            name = f"{o}_h0{suffix}" if field == "value" else f"{o}_h0_{field}{suffix}"
            var = ex[field].copy(data=np.where(two_sizes, ex_coarse[field].values, ex[field].values))
            if var.dtype == bool:
                var = var.astype(np.int8)
            if field == "order":
                var.attrs["allow_missing"] = 1  # NaN: undefined order of an exactly converged point
            if field == "uncertainty":  # which rule made the bars, in the file itself
                var.attrs["comment"] = ex.attrs["extrapolation"] + (
                    f"; from two sizes where the finest run was skipped or failed: {ex_coarse.attrs['extrapolation']}"
                    if two_sizes.any() else "")
            out[name] = var
        se = errors.get(f"{o}_standard_error")
        if se is not None and np.isfinite(se).any():
            out[f"{o}_h0_sampling_error{suffix}"] = (
                (panel.series_dim, panel.axis), _limit_sampling_error(sizes_um, values, se, two_sizes),
                {"units": units, "allow_missing": 1,
                 "long_name": f"standard error of {o} extrapolated to h -> 0 from the runs' sampling errors "
                              "(linear propagation; missing where a needed run's error is)"})
    for o, values in analytical.items():
        units, long_name = STEADY_META[o]
        out[f"{o}_analytical{suffix}"] = ((panel.series_dim, panel.axis), values,
                                          {"units": units, "long_name": f"{long_name} (analytical model, eqs. 1-5)",
                                           "allow_missing": 1})
    out[f"wall_time_s{suffix}"] = (dims3, wall, {"units": "s", "long_name": "wall time of the run",
                                                 **({"allow_missing": 1} if two_sizes.any() else {})})
    if ladders:  # mpm.ladder: relative: each point at its own sizes
        out[f"particle_size_um{suffix}"] = (dims3, size, {"units": "um", "long_name": "the run's particle size "
                                                          "(the point's own ladder: h times a scale)"})
    if np.isfinite(steady).any():  # result files written before the check carry none
        out[f"steady{suffix}"] = (dims3, steady, {"units": "1", "allow_missing": 1,
                                                  "long_name": STEADINESS_META["steady"][1] + " (per run; missing: "
                                                  "skipped, failed, or written before the check)"})
    for name, values in errors.items():
        if np.isfinite(values).any():
            units, long_name = STANDARD_ERROR_META[name]
            out[name + suffix] = (dims3, values, {"units": units, "allow_missing": 1,
                                                  "long_name": f"{long_name} (per run; missing: skipped, failed, not "
                                                               "estimable, or written before it was)"})
    out[f"skipped_finest{suffix}"] = ((panel.series_dim, panel.axis), skipped.astype(np.int8),
                                      {"units": "1", "long_name": "finest size skipped (mpm.skip_finest_tolerance): "
                                       "extrapolated from the two coarser sizes"})
    out[f"failed_finest{suffix}"] = ((panel.series_dim, panel.axis), failed.astype(np.int8),
                                     {"units": "1", "long_name": "finest run stopped unstable (mpm.finest_failure: "
                                      "record): extrapolated from the two coarser sizes"})
    return out


def _limit_sampling_error(sizes_um: tuple[float, ...], values: np.ndarray, se: np.ndarray,
                          two_sizes: np.ndarray) -> np.ndarray:
    """The runs' sampling errors carried through the h -> 0 extrapolation (the two coarser sizes' where
    the finest run was skipped or failed)."""
    h = np.asarray(sizes_um, dtype=float)
    out = sampling_error(h, values, se)
    if two_sizes.any():
        coarse = sampling_error(h[-3:-1], values[..., -3:-1], se[..., -3:-1])
        out = np.where(two_sizes, coarse, out)
    return out


def sweep_dataset(config: dict[str, Any], figure: str, runs: Mapping[str, xr.Dataset],
                  not_needed: Collection[str] = ()) -> xr.Dataset:
    """A sweep figure's dataset; ``not_needed``: the gated finest runs (``matrix.skippable_runs``) whose
    refinement decision did not ask for them (any other run named there is refused)."""
    panels = matrix.figure_panels(config, figure)
    sizes = matrix.particle_sizes_um(config)
    _check_not_needed(config, not_needed)
    recordable = set(matrix.failure_recordable_runs(config))
    # each point's own sizes (mpm.ladder: relative); the h -> 0 extrapolation runs along the config's sizes,
    # which a point's are times a scale (the same ratios): Richardson, the GCI, the least-squares fallback and the
    # sampling errors' weights depend on the sizes' ratios only, so the values and uncertainties are those of its own
    ladders = {pt.key: matrix.point_ladder(config, pt).sizes_um for p in panels for s in p.series for pt in s.points}
    parts = [_panel_dataset(p, sizes, runs, f"_{p.name}" if len(panels) > 1 else "", set(not_needed), recordable,
                            ladders if any(lad != sizes for lad in ladders.values()) else None)
             for p in panels]
    ds = xr.merge(parts, combine_attrs="drop_conflicts", join="exact")
    ds.attrs["panels"] = ",".join(p.name for p in panels)
    if figure in ("fig11", "fig13"):
        ds.attrs["ratio_sweep_thickness_um"] = float(config["mpm"]["rigid_plastic"]["ratio_sweep"]["thickness_um"])
    return ds


def single_run_dataset(config: dict[str, Any], figure: str, runs: Mapping[str, xr.Dataset]) -> xr.Dataset:
    cases = matrix.figure_points(config, figure)
    finest = {label: matrix.point_ladder(config, p).finest_um for label, p in cases.items()}
    keep = SINGLE_RUN_VARIABLES[figure]
    # result files from before the steadiness check lack the flag: carry it only when every case has it
    with_steady = all("steady" in runs[matrix.run_id(p, finest[label])] for label, p in cases.items())
    parts = []
    for label, point in cases.items():
        rid = matrix.run_id(point, finest[label])
        run = runs[rid]
        if is_skipped(run) or is_failed(run):
            reason = run.attrs.get("failure_reason") or run.attrs.get("skip_reason")
            raise ValueError(f"run {rid!r} is a {'failure' if is_failed(run) else 'skip'} marker ({reason}), but "
                             f"{figure} draws that run itself; {remedy(f'results/runs/{rid}.nc')}")
        sub = run[[v for v in keep if v in run]]
        for o in (*matrix.OUTPUTS, "Fz_mean"):
            sub[o] = run[o]
        if with_steady:
            sub["steady"] = ((), np.int8(int(run["steady"])), {"units": "1", "long_name": STEADINESS_META["steady"][1]})
        for o, v in matrix.analytical_values(point).items():
            units, long_name = STEADY_META[o]
            sub[f"{o}_analytical"] = ((), v, {"units": units, "long_name": f"{long_name} (analytical model)"})
        sub = sub.drop_vars([c for c in ("hx", "hy") if c in sub.coords and "height_map" not in keep])
        sub.attrs = {"scene_" + label: run.attrs["scene"], "coating_representation_" + label:
                     run.attrs["coating_representation"],
                     "sphere_centre_end_m_" + label: run.attrs["sphere_centre_end_m"]}
        if point.analytical_interface is not None:  # the run is the law the solver runs (matrix.solver_interface)
            sub.attrs["interface_configured_" + label] = json.dumps(point.analytical_interface, sort_keys=True)
        parts.append(sub.expand_dims(case=[label]))
    ds = xr.concat(parts, dim="case", join="outer", data_vars="all", coords="different",
                   compat="equals", combine_attrs="drop_conflicts")
    if len(parts) > 1:
        for name in ds.data_vars:
            if ds[name].ndim > 1:
                ds[name].attrs["allow_missing"] = 1  # cases of different size are padded with NaN
    ds["case"].attrs["long_name"] = "case"
    if len(set(finest.values())) == 1:
        ds.attrs["particle_size_um"] = next(iter(finest.values()))
    for label, h in finest.items():  # the cases of one figure may differ (each point's own finest size)
        ds.attrs["particle_size_um_" + label] = h
    return ds


def _check_not_needed(config: dict[str, Any], not_needed: Collection[str]) -> None:
    wrong = sorted(set(not_needed) - set(matrix.skippable_runs(config)))
    if wrong:
        raise ValueError(f"run {wrong[0]!r} is named as not needed by a refinement decision, but the config does not "
                         "gate it (mpm.skip_finest_tolerance is null, fewer than three sizes, not the finest size, or "
                         "a picture's run, or a finest size the groove or coating target set)")


def fig22_mpm_points(config: dict[str, Any], runs: Mapping[str, xr.Dataset],
                     not_needed: Collection[str] = ()) -> xr.Dataset:
    """The MPM friction of Fig. 21 (h -> 0) on the coordinates Fig. 22's plot expects."""
    fig21 = sweep_dataset(config, "fig21", runs, not_needed)
    radii = [float(x) for x in config["mpm"]["real_materials"]["ball_radii_um"]]
    diam = np.array([2.0 * r / 1000.0 for r in radii])
    mu = fig21["mu_h0"].values
    unc = fig21["mu_h0_uncertainty"].values
    coords = {"ball_diameter_mm": ("ball_diameter_mm", diam, {"units": "mm", "long_name": "ball diameter"}),
              "mpm_load_N": ("mpm_load_N", fig21["load_N"].values, {"units": "N", "long_name": "normal load (MPM)"})}
    return xr.Dataset({
        "mu_mpm": (("ball_diameter_mm", "mpm_load_N"), mu,
                   {"units": "1", "long_name": "friction coefficient, MPM extrapolated to h -> 0"}),
        "mu_mpm_uncertainty": (("ball_diameter_mm", "mpm_load_N"), unc,
                               {"units": "1", "long_name": "uncertainty of the MPM friction coefficient"}),
        "mu_mpm_flagged": (("ball_diameter_mm", "mpm_load_N"), fig21["mu_h0_flagged"].values.astype(np.int8),
                           {"units": "1", "long_name": "MPM extrapolation flagged (least squares / two sizes)"}),
        "mu_mpm_failed_finest": (("ball_diameter_mm", "mpm_load_N"), fig21["failed_finest"].values.astype(np.int8),
                                 {"units": "1", "long_name": "finest run stopped unstable (mpm.finest_failure: "
                                  "record): extrapolated from the two coarser sizes"}),
    }, coords=coords)


def build_dataset(config: dict[str, Any], figure: str, paths: Mapping[str, str | Path],
                  solver: str | None = None, not_needed: Collection[str] = ()) -> xr.Dataset:
    """The dataset of one MPM figure from its run result files (run id -> path). Each file must hold
    its run's scene as the config makes it and, when ``solver`` is given (the workflow gives the
    current :func:`plough.fingerprint.solver_fingerprint`), have been made by that solver.
    ``not_needed``: gated finest runs whose refinement decision did not ask for them (the checkpoint
    ``mpm_refine``): not read, their points extrapolated from the two coarser sizes."""
    if figure != "fig22" and figure not in matrix.MPM_FIGURES:
        raise ValueError(f"figure = {figure!r} is not an MPM figure; allowed: {matrix.MPM_FIGURES}")
    _check_not_needed(config, not_needed)
    scenes = matrix.all_runs(config, ("fig21",) if figure == "fig22" else (figure,))
    runs = load_runs([r for r in matrix.figure_runs(config, figure) if r not in not_needed], paths, scenes, solver)
    if figure == "fig22":
        from plough.study.analytical_figures import fig22_dataset

        ds = xr.merge([fig22_dataset(config["power_law"]), fig22_mpm_points(config, runs, not_needed)],
                      combine_attrs="override")
        ds.attrs.update(provenance_attrs(config))
        return ds
    if figure in matrix.SINGLE_RUN_FIGURES:
        ds = single_run_dataset(config, figure, runs)
    elif figure in matrix.SWEEP_FIGURES:
        ds = sweep_dataset(config, figure, runs, not_needed)
    else:
        raise ValueError(f"figure = {figure!r} is not an MPM figure; allowed: {matrix.MPM_FIGURES}")
    scene_attrs = {k: v for k, v in ds.attrs.items()
                   if k.startswith(("scene_", "coating_representation_", "sphere_centre_end_m_"))}
    ds.attrs = {**ds.attrs, **provenance_attrs(config["mpm"]), **scene_attrs}
    ds.attrs.update(figure=figure, title=TITLES[figure])
    return ds
