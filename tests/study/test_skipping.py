"""plough.study.skipping: the refinement decision (is a point's finest size needed?), the gated runs."""

from __future__ import annotations

import copy
import json
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from plough.study import matrix, skipping

ROOT = Path(__file__).resolve().parents[2]
SMOKE = yaml.safe_load((ROOT / "config" / "smoke.yaml").read_text())


def _run(mu: float, dp: float) -> xr.Dataset:
    return xr.Dataset({"mu": ((), mu), "dp": ((), dp)})


def test_two_size_extrapolation_is_richardson_order_one_with_safety_factor_three():
    ex = skipping.two_size_extrapolation(_run(0.40, 5e-6), _run(0.44, 6e-6), 20.0, 10.0)
    assert ex["mu"]["value"] == pytest.approx(0.48, rel=1e-12)  # r = 2, p = 1: f1 + (f1 - f2)
    assert ex["mu"]["uncertainty"] == pytest.approx(3 * 0.04, rel=1e-12)
    assert ex["mu"]["relative_uncertainty"] == pytest.approx(0.12 / 0.48, rel=1e-12)
    assert ex["dp"]["value"] == pytest.approx(7e-6, rel=1e-12)
    assert skipping.should_skip(ex, 0.45) and not skipping.should_skip(ex, 0.40)  # dp: 3e-6 / 7e-6 = 0.43
    converged = skipping.two_size_extrapolation(_run(0.4, 5e-6), _run(0.4, 5e-6), 20.0, 10.0)
    assert skipping.should_skip(converged, 1e-6)


@pytest.mark.parametrize("tol", [0.0, -0.1, float("nan"), float("inf"), True, {"mu": 0.05}, {"mu": 0.05, "dp": 0.0},
                                 {"mu": 0.05, "dp": 0.3, "hpu": 0.1}])
def test_tolerance_outside_its_range_is_refused(tol):
    ex = skipping.two_size_extrapolation(_run(0.4, 5e-6), _run(0.4, 5e-6), 20.0, 10.0)
    with pytest.raises(ValueError, match="skip_finest_tolerance"):
        skipping.should_skip(ex, tol)


def test_a_tolerance_per_output_decides_each_output_by_its_own():
    ex = skipping.two_size_extrapolation(_run(0.40, 5e-6), _run(0.44, 6e-6), 20.0, 10.0)  # mu 0.25, dp 0.43
    assert skipping.tolerances(0.5) == {"mu": 0.5, "dp": 0.5}
    assert skipping.should_skip(ex, {"mu": 0.25, "dp": 0.45})
    assert not skipping.should_skip(ex, {"mu": 0.24, "dp": 0.45})
    assert not skipping.should_skip(ex, {"mu": 0.25, "dp": 0.42})


def test_non_finite_uncertainty_never_skips():
    ex = {"mu": {"value": 0.0, "uncertainty": 1.0, "relative_uncertainty": np.inf}}
    assert not skipping.should_skip(ex, 0.5)


def _scene_run(mu: float, dp: float, h_um: float, name: str) -> xr.Dataset:
    scene = {"name": name, "discretisation": {"particle_size_m": h_um * 1e-6}}
    return _run(mu, dp).assign_attrs(scene=json.dumps(scene))


def test_the_decision_reads_the_sizes_the_coarser_runs_record_and_says_why():
    coarse, mid = _scene_run(0.40, 5e-6, 40.0, "p_h40"), _scene_run(0.44, 6e-6, 20.0, "p_h20")
    d = skipping.decide("p_h10", coarse, mid, ["p_h40", "p_h20"], {"mu": 0.3, "dp": 0.45})
    assert d["run_finest"] is False and d["finest_run"] == "p_h10" and d["coarser_sizes_um"] == [40.0, 20.0]
    assert d["extrapolations"]["mu"]["value"] == pytest.approx(0.48, rel=1e-12)
    assert d["tolerance"] == {"mu": 0.3, "dp": 0.45}
    assert "p_h40, p_h20 (h = 40, 20 um) is within" in d["reason"]
    assert json.loads(json.dumps(d)) == d  # the checkpoint writes it as JSON
    needed = skipping.decide("p_h10", coarse, mid, ["p_h40", "p_h20"], 0.3)
    assert needed["run_finest"] is True and "is not within" in needed["reason"]


def test_the_decision_of_a_relative_ladder_point_uses_its_own_sizes(tmp_path):
    """The refinement checkpoint (workflow/scripts/mpm_refine.py) of a relative-ladder point whose sizes are not
    the config's extrapolates at the point's own two coarser sizes (matrix.coarser_sizes_um), read from the run
    files. (Before, the skip decision got the config's sizes from the rule, mpm.smk's
    particle_sizes_um(config)[-3:-1]: right by chance, as the two-size extrapolation depends on their ratio only,
    but named wrong in the log.)"""
    import runpy
    import sys

    from plough.fingerprint import solver_fingerprint
    from tests.study.test_mpm_figures import fake_run

    cfg = copy.deepcopy(yaml.safe_load((ROOT / "config" / "config.yaml").read_text()))
    cfg["mpm"]["skip_finest_tolerance"] = {"mu": 0.05, "dp": 0.3}
    gated = matrix.skippable_runs(cfg)
    finest = next(r for r in gated if matrix.coarser_sizes_um(cfg, r) != list(matrix.particle_sizes_um(cfg)[-3:-1]))
    coarse, mid = gated[finest]
    scenes = matrix.all_runs(cfg)
    paths = []
    for rid in (coarse, mid):
        ds = fake_run(scenes[rid])
        ds.attrs["solver_fingerprint"] = solver_fingerprint()
        paths.append(str(tmp_path / f"{rid}.nc"))
        ds.to_netcdf(paths[-1])

    class NS:
        def __init__(self, **kw):
            self.__dict__.update(kw)

    out = tmp_path / "refinement" / f"{finest}.json"
    smk = NS(params=NS(tolerance=cfg["mpm"]["skip_finest_tolerance"], coarser=[coarse, mid],
                       solver=solver_fingerprint()),
             input=NS(coarser=paths), output=[str(out)], log=[str(tmp_path / "refine.log")], config=cfg,
             wildcards=NS(run=finest))
    stderr = sys.stderr
    runpy.run_path(str(ROOT / "workflow" / "scripts" / "mpm_refine.py"), init_globals={"snakemake": smk})
    assert sys.stderr is stderr
    decision = json.loads(out.read_text())
    assert decision["coarser_sizes_um"] == matrix.coarser_sizes_um(cfg, finest)
    assert decision["finest_run"] == finest and decision["coarser_runs"] == [coarse, mid]
    assert decision["reason"] in (tmp_path / "refine.log").read_text()


def test_skippable_runs_are_finest_sweep_runs_never_pictures():
    assert matrix.skippable_runs(SMOKE) == {}  # off by default
    cfg = copy.deepcopy(SMOKE)
    cfg["mpm"]["skip_finest_tolerance"] = {"mu": 0.05}
    with pytest.raises(ValueError, match="skip_finest_tolerance .* must be a number or name each of mu, dp"):
        matrix.skippable_runs(cfg)
    cfg["mpm"]["skip_finest_tolerance"] = 0.05
    skippable = matrix.skippable_runs(cfg)
    sizes = matrix.particle_sizes_um(cfg)
    pictures = {rid for fig in matrix.SINGLE_RUN_FIGURES for rid in matrix.figure_runs(cfg, fig)}
    sweep_finest = {rid for fig in matrix.SWEEP_FIGURES for rid in matrix.figure_runs(cfg, fig)
                    if rid.endswith(f"_h{matrix.fmt(sizes[-1])}")}
    assert skippable and set(skippable) == sweep_finest - pictures
    assert pictures & sweep_finest  # the smoke matrix has a picture that is also a sweep point
    for finest, (coarse, mid) in skippable.items():
        stem = finest.rsplit("_h", 1)[0]
        assert (coarse, mid) == (f"{stem}_h{matrix.fmt(sizes[0])}", f"{stem}_h{matrix.fmt(sizes[1])}")
    cfg["mpm"]["particle_sizes_um"] = [40, 20, 14, 10]  # four sizes: the two next to the finest
    for finest, (coarse, mid) in matrix.skippable_runs(cfg).items():
        stem = finest.rsplit("_h", 1)[0]
        assert (finest, coarse, mid) == (f"{stem}_h10", f"{stem}_h20", f"{stem}_h14")
    cfg["mpm"]["particle_sizes_um"] = [20, 10]
    assert matrix.skippable_runs(cfg) == {}  # two sizes: nothing left to extrapolate from


def test_the_runs_sampling_errors_count_against_skipping():
    """Two coarse runs that agree within the tolerance by their GCI but whose own noise is larger do not
    let the finest run be skipped; the sampling error is 2 s_mid and s_coarse in quadrature (order 1, r = 2)."""
    coarse, mid = _run(0.40, 5e-6), _run(0.41, 5e-6)
    quiet = skipping.two_size_extrapolation(coarse, mid, 20.0, 10.0)
    assert quiet["mu"]["sampling_error"] == 0.0 and skipping.should_skip(quiet, 0.08)  # 0.03 / 0.42
    noisy_c = coarse.assign(mu_standard_error=0.01, dp_standard_error=0.0)
    noisy_m = mid.assign(mu_standard_error=0.02, dp_standard_error=0.0)
    noisy = skipping.two_size_extrapolation(noisy_c, noisy_m, 20.0, 10.0)
    assert noisy["mu"]["sampling_error"] == pytest.approx(np.hypot(2 * 0.02, 0.01), rel=1e-12)
    assert noisy["mu"]["uncertainty"] == pytest.approx(quiet["mu"]["uncertainty"], rel=1e-12)
    assert noisy["mu"]["relative_uncertainty"] == pytest.approx(np.hypot(0.03, np.hypot(0.04, 0.01)) / 0.42, rel=1e-12)
    assert not skipping.should_skip(noisy, 0.08)


def test_a_newer_run_without_its_dp_error_never_skips():
    """A run that writes the errors but could not estimate dp's (fewer than 2 sections) does not count as
    noiseless: the finest run is made. Files from before the errors (none of them) count as 0."""
    coarse, mid = _run(0.40, 5e-6), _run(0.41, 5e-6)
    assert skipping.should_skip(skipping.two_size_extrapolation(coarse, mid, 20.0, 10.0), 0.5)
    newer = mid.assign(mu_standard_error=0.0)  # no dp_standard_error
    ex = skipping.two_size_extrapolation(coarse, newer, 20.0, 10.0)
    assert np.isnan(ex["dp"]["sampling_error"]) and ex["mu"]["sampling_error"] == 0.0
    assert not skipping.should_skip(ex, 0.5)
    # the decision the checkpoint writes says so in strict JSON (null, never NaN) and in its reason
    d = skipping.decide("p_h10", _scene_run(0.40, 5e-6, 40.0, "p_h40"),
                        _scene_run(0.41, 5e-6, 20.0, "p_h20").assign(mu_standard_error=0.0),
                        ["p_h40", "p_h20"], 0.5)
    assert d["run_finest"] is True
    assert d["extrapolations"]["dp"]["sampling_error"] is None
    assert d["extrapolations"]["dp"]["relative_uncertainty"] is None
    assert d["extrapolations"]["dp"]["value"] == pytest.approx(5e-6, rel=1e-12)
    assert d["extrapolations"]["mu"]["sampling_error"] == 0.0
    assert json.loads(json.dumps(d, allow_nan=False)) == d
    assert d["reason"].endswith("dp unknown (a coarser run could not estimate its sampling error)")
    # a groove of 0 at both sizes: nothing uncertain; a limit of exactly 0 from two grooves: unbounded
    flat = skipping.decide("p_h10", _scene_run(0.40, 0.0, 40.0, "p_h40"), _scene_run(0.41, 0.0, 20.0, "p_h20"),
                           ["p_h40", "p_h20"], 0.5)
    assert flat["extrapolations"]["dp"]["relative_uncertainty"] == 0.0  # 0 / 0: nothing uncertain
    zero_limit = skipping.decide("p_h10", _scene_run(0.40, 2e-6, 40.0, "p_h40"), _scene_run(0.41, 1e-6, 20.0, "p_h20"),
                                 ["p_h40", "p_h20"], 0.5)
    assert zero_limit["extrapolations"]["dp"]["relative_uncertainty"] is None and zero_limit["run_finest"] is True
    assert "dp unbounded (the limit is 0)" in zero_limit["reason"]
    json.dumps(zero_limit, allow_nan=False)


def test_failure_marker_carries_the_message_and_no_results():
    m = skipping.failure_marker({"name": "p_h5"}, "p_h5", "unstable run at step 7: a particle left the grid",
                                ["p_h20", "p_h10"])
    assert skipping.is_failed(m) and not skipping.is_skipped(m)
    assert not skipping.is_failed(_run(0.4, 1e-6))
    assert not m.data_vars
    assert "a particle left the grid" in m.attrs["failure_reason"] and "p_h5" in m.attrs["failure_reason"]
    assert "p_h20, p_h10" in m.attrs["failure_stands_in"]
    assert json.loads(m.attrs["scene"]) == {"name": "p_h5"} and m.attrs["plough_version"]


def test_failure_recordable_runs_follow_mpm_finest_failure():
    """record (the default, also when the key is absent): every finest sweep run that is not a picture's,
    the same runs skipping may skip under the paper's ladder (the smoke matrix's); stop: none; an unknown choice
    is refused by name."""
    with_skip = copy.deepcopy(SMOKE)
    with_skip["mpm"]["skip_finest_tolerance"] = {"mu": 0.05, "dp": 0.3}
    record = copy.deepcopy(SMOKE)
    record["mpm"]["finest_failure"] = "record"
    assert matrix.failure_recordable_runs(record) == matrix.skippable_runs(with_skip) != {}
    absent = copy.deepcopy(SMOKE)
    del absent["mpm"]["finest_failure"]
    assert matrix.failure_recordable_runs(absent) == matrix.failure_recordable_runs(record)
    assert SMOKE["mpm"]["finest_failure"] == "stop"  # CI's smoke matrix fails on an unstable run
    stop = copy.deepcopy(SMOKE)
    assert matrix.failure_recordable_runs(stop) == {}
    stop["mpm"]["finest_failure"] = "ignore"
    with pytest.raises(ValueError, match="mpm.finest_failure = 'ignore' is unknown; allowed: record, stop"):
        matrix.failure_recordable_runs(stop)
    two = copy.deepcopy(record)
    two["mpm"]["particle_sizes_um"] = [20, 10]
    assert matrix.failure_recordable_runs(two) == {}  # nothing to stand in for the finest run
