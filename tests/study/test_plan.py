"""plough plan (plough.study.plan): the projection of a workflow config before it runs, calibrated by measured jobs.

The measured jobs here are made up, so that each projected time can be computed by hand: a run's time is its
particle-steps (counted by plough.study.cost) over the rate of its family at the measured size nearest in log h.
"""

from __future__ import annotations

import copy
import json
import os
import subprocess
import sys
from datetime import UTC, datetime
from pathlib import Path

import pytest
import xarray as xr
import yaml

from plough.cli import main
from plough.io import to_json
from plough.mpm.scene import Scene
from plough.study import cost, matrix
from plough.study.plan import (
    Measured,
    Rates,
    _hours,
    family_of,
    load_config,
    make_plan,
    measured_from_benchmarks,
    measured_from_json,
    merge,
)

ROOT = Path(__file__).resolve().parents[2]
SMOKE = yaml.safe_load((ROOT / "config" / "smoke.yaml").read_text())


def test_configfiles_merge_key_by_key_as_snakemake():
    base = {"mpm": {"threads": 2, "ladder": "relative", "ladder_targets": {"contact_radius_particles": 12}},
            "power_law": {"load_N": [1, 2]}}
    merge(base, {"mpm": {"ladder": "paper", "ladder_targets": {"coating_particles": 1}}, "power_law": {"load_N": [3]}})
    assert base == {"mpm": {"threads": 2, "ladder": "paper",
                            "ladder_targets": {"contact_radius_particles": 12, "coating_particles": 1}},
                    "power_law": {"load_N": [3]}}
    config = load_config(["config/paper.yaml"], ROOT)
    assert config["mpm"]["ladder"] == "paper"
    assert config["mpm"]["ladder_targets"] == yaml.safe_load((ROOT / "config" / "config.yaml").read_text())["mpm"][
        "ladder_targets"]  # kept from config.yaml, as Snakemake keeps it


def _row(run: str, family: str, h: float, steps: float, seconds: float, threads: int = 2) -> Measured:
    return Measured(run, family, h, steps, seconds, threads, "test")


def test_rates_per_family_at_the_nearest_measured_size():
    rows = [_row("a", "rigid-plastic", 10, 2e9, 1000), _row("b", "rigid-plastic", 10, 1e9, 1000),
            _row("c", "rigid-plastic", 20, 1e8, 200), _row("d", "real materials", 5, 3e9, 1000, threads=4),
            _row("a", "rigid-plastic", 10, 2e9, 500)]  # measured again: the last row counts
    rates = Rates.from_measured(rows, threads=2)
    assert rates.rate("rigid-plastic", 10) == pytest.approx(3e9 / 1500)
    assert rates.rate("rigid-plastic", 2.5) == pytest.approx(3e9 / 1500)  # nearest in log h: 10
    assert rates.rate("rigid-plastic", 40) == pytest.approx(1e8 / 200)
    assert rates.rate("rigid-plastic", 14) == pytest.approx(3e9 / 1500)  # nearer in log h to 10 than to 20
    assert rates.rate("rigid-plastic", 15) == pytest.approx(1e8 / 200)
    assert rates.rate("real materials", 80) == pytest.approx(3e9 / 2000)  # 4 threads scaled to 2, linearly
    only_rp = Rates.from_measured(rows[:3], threads=2)
    assert only_rp.rate("real materials", 5) == pytest.approx(cost.THROUGHPUT_PER_THREAD * 2)


def test_jobs_at_the_configs_threads_set_the_rate_where_measured():
    """A second thread is not linear (1.6-1.8x here): where a size was measured at the config's threads, jobs
    measured at other threads do not dilute its rate; elsewhere they are scaled linearly and said to be."""
    rows = [_row("a", "real materials", 5, 1e9, 1000, threads=1), _row("b", "real materials", 5, 4e9, 1000),
            _row("c", "real materials", 10, 1e9, 100, threads=2), _row("d", "real materials", 10, 1e9, 100, threads=4),
            _row("e", "real materials", 20, 1e9, 100, threads=1), _row("e", "real materials", 20, 1e9, 300),
            _row("f", "real materials", 40, 1e9, 100), _row("f", "real materials", 40, 1e9, 400, threads=4)]
    rates = Rates.from_measured(rows, threads=1)
    assert rates.rate("real materials", 20) == pytest.approx(1e9 / 100)  # e at 1 thread, though measured again at 2
    assert rates.rate("real materials", 40) == pytest.approx(1e9 / 1600)  # f's last row, 4 threads scaled to 1
    assert rates.rate("real materials", 5) == pytest.approx(1e9 / 1000)  # b (2 threads) left out
    assert rates.by_family["real materials"][5][0] == 1
    assert rates.rate("real materials", 10) == pytest.approx(2e9 / 600)  # 200 + 400 s scaled to one thread
    assert rates.scaled == {("real materials", 10), ("real materials", 40)}


def _benchmark_file(directory: Path, rid: str, seconds: float, ended: datetime | None = None) -> None:
    """A Snakemake benchmark file of a run's job under ``directory``, written (its time set) at ``ended``."""
    tsv = directory / "benchmarks" / "runs" / f"{rid}.tsv"
    tsv.parent.mkdir(parents=True, exist_ok=True)
    tsv.write_text(f"s\th:m:s\tmax_rss\n{seconds}\t0:00:12\t100\n")
    if ended is not None:
        os.utime(tsv, (ended.timestamp(), ended.timestamp()))


#: when the made-up jobs of the benchmark-file tests ended
ENDED = datetime(2026, 12, 6, 17, 10, 9, tzinfo=UTC)


def test_a_run_measured_more_than_once_counts_at_its_latest_end(tmp_path):
    """Calibration files need not sort by name in the order they were measured: a run in several files counts at
    the row whose job ended last; rows from before the end was recorded count as older than any that records it,
    and among themselves in file-name order."""
    row = {"family": "rigid-plastic", "h_um": 10.0, "particle_steps": 1e9}
    files = {"a_old.json": [{**row, "run": "r", "measured_s": 100.0}, {**row, "run": "s", "measured_s": 100.0}],
             "b_undated.json": [{**row, "run": "s", "measured_s": 200.0}],
             "c_late.json": [{**row, "run": "r", "measured_s": 400.0, "ended": "2026-12-06T17:10:09+00:00"}],
             "d_early.json": [{**row, "run": "r", "measured_s": 800.0, "ended": "2026-12-05T09:00:00Z"}]}
    for name, runs in files.items():
        (tmp_path / name).write_text(json.dumps({"threads": 2, "runs": runs}))
    rows = measured_from_json(sorted(tmp_path.glob("*.json")))
    # oldest first: the undated rows in file-name order, then d_early ("Z" read as UTC), then c_late
    assert [(Path(r.source).stem, r.run) for r in rows] == [("a_old", "r"), ("a_old", "s"), ("b_undated", "s"),
                                                            ("d_early", "r"), ("c_late", "r")]
    assert rows[3].ended == datetime(2026, 12, 5, 9, tzinfo=UTC)
    rates = Rates.from_measured(rows, threads=2)
    # r: c_late's 400 s (ended last), not d_early's, which sorts after it by name; s: b_undated's, the later file
    assert rates.rate("rigid-plastic", 10) == pytest.approx(2e9 / (400 + 200))
    assert rates.by_family["rigid-plastic"][10][0] == 2
    (tmp_path / "e_bad.json").write_text(json.dumps({"runs": [{**row, "run": "t", "measured_s": 1.0,
                                                               "ended": "2026-12-06 17:10"}]}))
    with pytest.raises(ValueError, match=r"e_bad.json: run 't': ended = '2026-12-06 17:10' has no time zone"):
        measured_from_json([tmp_path / "e_bad.json"])


def test_this_machines_benchmark_files_outrank_the_calibration_files(tmp_path):
    """A run with a benchmark file under the workflow's directory counts at it, though a calibration file (say one
    pulled later) measured the run after it: plough plan projects this machine from its own jobs first."""
    runs = {rid: Scene.from_dict(s) for rid, s in matrix.all_runs(SMOKE).items()}
    rid = sorted(runs)[0]
    family, h = family_of(runs[rid]), round(runs[rid].discretisation.particle_size_m * 1e6, 6)
    steps = cost.estimate(runs[rid]).particle_steps
    (tmp_path / "results" / "runs").mkdir(parents=True)
    _benchmark_file(tmp_path, rid, 12.5, ended=datetime(1970, 1, 1, tzinfo=UTC))  # older than any calibration row
    xr.Dataset(attrs={"cost_particle_steps": 1, "cost_threads": 1, "scene": to_json(runs[rid].to_dict())}).to_netcdf(
        tmp_path / "results" / "runs" / f"{rid}.nc")
    calib = _calibration(tmp_path, [{"run": rid, "family": family, "h_um": h, "particle_steps": steps,
                                     "measured_s": 99.0, "threads": 1, "ended": "2026-12-06T17:10:09Z"}])
    plan = make_plan(SMOKE, directory=tmp_path, calibration=[calib])
    assert plan.rates.by_family[family][h] == (1, pytest.approx(steps / 12.5 * SMOKE["mpm"]["threads"]))


def _calibration(tmp_path: Path, rows: list[dict]) -> Path:
    path = tmp_path / "projection_check_test.json"
    path.write_text(json.dumps({"config": "none.yaml", "runs": rows}))
    return path


def test_calibration_rows_carry_the_threads_they_ran_at(tmp_path):
    """A projection_check.py result's rows run at the threads the row records, else the file, else 2 (every file
    before the record was measured at mpm.threads 2): never at the threads today's copy of a named config has."""
    row = {"family": "rigid-plastic", "h_um": 10.0, "particle_steps": 1e8, "measured_s": 100.0}
    named = tmp_path / "named.yaml"
    named.write_text(yaml.safe_dump({"mpm": {"threads": 7}}))
    files = {"old.json": {"config": str(named), "runs": [{**row, "run": "a"}]},
             "file.json": {"config": str(named), "threads": 1, "runs": [{**row, "run": "b"}]},
             "rows.json": {"threads": 1, "runs": [{**row, "run": "c", "threads": 4}, {**row, "run": "d"}]}}
    for name, data in files.items():
        (tmp_path / name).write_text(json.dumps(data))
    threads = {r.run: r.threads for r in measured_from_json(sorted(tmp_path.glob("*.json")))}
    assert threads == {"a": 2, "b": 1, "c": 4, "d": 1}


def test_the_plan_of_a_config_from_measured_jobs(tmp_path):
    config = copy.deepcopy(SMOKE)
    config["mpm"]["threads"] = 1
    calib = _calibration(tmp_path, [
        {"run": "x", "family": "rigid-plastic", "h_um": 14.0, "particle_steps": 1e8, "measured_s": 100.0},
        {"run": "y", "family": "real materials", "h_um": 14.0, "particle_steps": 1e8, "measured_s": 400.0}])
    plan = make_plan(config, cores=4, directory=tmp_path, calibration=[calib], cluster=8)
    runs = matrix.all_runs(config)
    assert set(plan.runs) == set(runs)
    for rid, scene in runs.items():
        s = Scene.from_dict(scene)
        real = not rid.startswith("rp_")
        steps = cost.estimate(s).particle_steps
        # the JSON records no threads: its jobs ran at 2, scaled to this config's 1
        rate = 1e8 / (400.0 if real else 100.0) / 2
        assert plan.runs[rid].here_s == pytest.approx(steps / rate), rid
        assert plan.runs[rid].cluster_s == pytest.approx(steps / rate / 8), rid
        assert plan.runs[rid].request_min == cost.runtime_minutes(cost.estimate(s), 8)
    # four jobs at once with --cores 4 and one thread a run; never less than the longest run
    assert plan.parallel_jobs == 4
    total = sum(r.here_s for r in plan.runs.values())
    assert plan.wall_s(list(plan.runs)) == pytest.approx(max(total / 4, max(r.here_s for r in plan.runs.values())))
    assert plan.figures["fig03"] == [] and plan.figures["fig22"] == plan.figures["fig21"]
    assert set(plan.figures["fig12"]) == set(matrix.figure_runs(config, "fig12"))


def test_benchmark_files_of_the_configs_runs_calibrate_markers_do_not(tmp_path):
    runs = {rid: Scene.from_dict(s) for rid, s in matrix.all_runs(SMOKE).items()}
    made, marker, stranger = sorted(runs)[:2] + ["not_a_run_h10"]
    (tmp_path / "results" / "runs").mkdir(parents=True)
    for rid, seconds in ((made, 12.5), (marker, 0.4), (stranger, 99.0)):
        _benchmark_file(tmp_path, rid, seconds, ENDED if rid == made else None)
    xr.Dataset(attrs={"cost_particle_steps": 1, "cost_threads": 1, "scene": to_json(runs[made].to_dict())}).to_netcdf(
        tmp_path / "results" / "runs" / f"{made}.nc")
    xr.Dataset(attrs={"skipped_finest_size": 1}).to_netcdf(tmp_path / "results" / "runs" / f"{marker}.nc")
    rows = measured_from_benchmarks(tmp_path, runs, threads=2)
    assert [(r.run, r.seconds, r.threads, r.ended) for r in rows] == [(made, 12.5, 1, ENDED)]
    assert rows[0].particle_steps == cost.estimate(runs[made]).particle_steps


def test_projection_check_rows_are_runs_not_markers(tmp_path):
    """benchmarks/projection_check.py writes the calibration rows plough plan reads: a failure marker's job made
    no run, and its seconds over the run's counted particle-steps would be a rate it never had. A row's threads
    are those its result records, not the config's (smoke: 1)."""
    runs = {rid: Scene.from_dict(s) for rid, s in matrix.all_runs(SMOKE).items()}
    made, marker = sorted(runs)[:2]
    (tmp_path / "results" / "runs").mkdir(parents=True)
    for rid, seconds in ((made, 12.5), (marker, 0.4)):
        _benchmark_file(tmp_path, rid, seconds, ENDED if rid == made else None)
    xr.Dataset(attrs={"cost_wall_time_s": 11.0, "cost_threads": 2}).to_netcdf(
        tmp_path / "results" / "runs" / f"{made}.nc")
    xr.Dataset(attrs={"failed_finest_size": 1}).to_netcdf(tmp_path / "results" / "runs" / f"{marker}.nc")
    out = tmp_path / "projection_check_test.json"
    subprocess.run([sys.executable, str(ROOT / "benchmarks" / "projection_check.py"), "--workdir", str(tmp_path),
                    "--config", str(ROOT / "config" / "smoke.yaml"), "--out", str(out)],
                   check=True, capture_output=True, cwd=ROOT)
    rows = measured_from_json([out])
    assert [(r.run, r.seconds, r.threads, r.ended) for r in rows] == [(made, 12.5, 2, ENDED)]
    assert rows[0].particle_steps == pytest.approx(cost.estimate(runs[made]).particle_steps)


def test_the_plan_states_the_range_refinement_only_where_needed_leaves(tmp_path):
    """Gated finest runs (mpm.skip_finest_tolerance) are made only where their decision asks: the plan counts each
    decision made (results/refinement/<run>.json) as it says, and an undecided one at both ends of a range."""
    from plough.study.plan import describe

    config = copy.deepcopy(SMOKE)
    assert make_plan(config, directory=tmp_path).gated == {}  # off: every run counted, no range
    config["mpm"]["skip_finest_tolerance"] = {"mu": 0.05, "dp": 0.3}
    coarser = matrix.skippable_runs(config)
    gated = sorted(coarser)
    needed, not_needed = gated[:2], gated[2:4]
    (tmp_path / "results" / "refinement").mkdir(parents=True)

    def decision(rid: str, tolerance: dict[str, float]) -> str:
        return json.dumps({"run_finest": rid in needed, "coarser_runs": list(coarser[rid]), "tolerance": tolerance})

    for rid in needed + not_needed:
        (tmp_path / "results" / "refinement" / f"{rid}.json").write_text(decision(rid, {"mu": 0.05, "dp": 0.3}))
    (tmp_path / "results" / "refinement" / f"{gated[4]}.json").write_text("{not json")  # unreadable: undecided
    # made under another tolerance: undecided until the workflow redoes it
    assert len(gated) > 5
    (tmp_path / "results" / "refinement" / f"{gated[5]}.json").write_text(decision(gated[5], {"mu": 0.1, "dp": 0.3}))
    plan = make_plan(config, directory=tmp_path)
    assert plan.gated == {rid: True if rid in needed else False if rid in not_needed else None for rid in gated}
    every = list(plan.runs)
    high, low = plan.made(every, undecided=True), plan.made(every, undecided=False)
    assert set(every) - set(high) == set(not_needed)
    assert set(every) - set(low) == set(gated) - set(needed)
    text = describe(plan)
    assert (f"{len(gated)} gated finest runs (2 decided needed, 2 decided not, {len(gated) - 4} undecided): between "
            f"**{_hours(plan.wall_s(low))}** ({len(low)} runs") in text
    assert f"and {_hours(plan.wall_s(high))} ({len(high)} runs" in text
    assert "skip_finest_tolerance: mu 0.05, dp 0.3" in text


def test_plough_plan_prints_every_figure_and_the_total(capsys, tmp_path):
    for path in ("config/config.yaml", "config/smoke.yaml", "profiles/slurm/config.yaml"):
        (tmp_path / path).parent.mkdir(parents=True, exist_ok=True)
        (tmp_path / path).write_text((ROOT / path).read_text())
    assert main(["plan", "--directory", str(tmp_path), "--configfile", "config/smoke.yaml"]) == 0
    out = capsys.readouterr().out
    assert "ladder: paper (20, 14, 10 um for every point)" in out
    for fig in ("fig03", "fig11", "fig12", "fig22", "fig23"):
        assert f"| {fig} |" in out
    assert f"| **all** (each run once) | {len(matrix.all_runs(SMOKE))} |" in out
    assert "on a cluster, one job a run at 8 threads" in out  # profiles/slurm: set-threads mpm_run 8
    # no measured job given: both families at the cluster request's rate, said so
    assert out.count("none measured") == 2
    assert main(["plan", "--directory", str(tmp_path), "--cores", "0"]) == 2


def test_the_plan_names_the_finest_sizes_the_relative_ladder_may_take(tmp_path):
    """The ladder line states the sizes a point's finest run may take: 2.5 or 3.5 um x 2^k with half-octaves (the
    default), 2.5 um x 2^k with octaves only."""
    from plough.study.plan import describe

    config = load_config([], ROOT)
    assert config["mpm"]["ladder"] == "relative" and config["mpm"]["ladder_sizes_per_octave"] == 2
    first = describe(make_plan(config, directory=tmp_path)).splitlines()[0]
    assert "um times 2^k or 1.4 x 2^k, a finest size of 2.5 or 3.5 um x 2^k; targets" in first
    config["mpm"]["ladder_sizes_per_octave"] = 1
    first = describe(make_plan(config, directory=tmp_path)).splitlines()[0]
    assert "um times 2^k, a finest size of 2.5 um x 2^k; targets" in first


def test_the_plan_leaves_out_what_is_made_and_expects_the_share_of_decisions_that_needed_their_run(tmp_path):
    """A run counts as made where its result file records its scene and this solver (a failure marker included,
    an old skip marker not); what is left is stated as a range and, once decisions are made, as an expected time
    counting each undecided gated finest run at the share of the decisions made that needed theirs."""
    from plough.fingerprint import solver_fingerprint
    from plough.study import skipping
    from plough.study.plan import describe, made_runs

    config = copy.deepcopy(SMOKE)
    config["mpm"]["skip_finest_tolerance"] = {"mu": 0.05, "dp": 0.3}
    runs = matrix.all_runs(config)
    coarser = matrix.skippable_runs(config)
    gated = sorted(coarser)
    assert len(gated) >= 5
    ungated = sorted(set(runs) - set(gated))
    (tmp_path / "results" / "runs").mkdir(parents=True)
    (tmp_path / "results" / "refinement").mkdir(parents=True)
    solver = solver_fingerprint()

    def write(rid: str, ds: xr.Dataset) -> None:
        ds.to_netcdf(tmp_path / "results" / "runs" / f"{rid}.nc")

    def result(rid: str, scene: dict, by: str = solver, **attrs) -> None:
        write(rid, xr.Dataset(attrs={"scene": to_json(scene), "solver_fingerprint": by, **attrs}))

    made, other_solver, renamed, changed, unreadable = ungated[:5]
    result(made, runs[made])
    result(other_solver, runs[other_solver], by="0" * 16)
    result(renamed, runs[made])  # another run's scene under this run's name
    scene = copy.deepcopy(runs[changed])
    scene["load_N"] *= 1.5  # this run's name, one parameter changed: the workflow redoes it
    result(changed, scene)
    (tmp_path / "results" / "runs" / f"{unreadable}.nc").write_text("not netCDF")
    failed = gated[0]  # decided needed, stopped unstable: its failure marker is kept
    marker = skipping.failure_marker(runs[failed], failed, "unstable", list(coarser[failed]))
    marker.attrs["solver_fingerprint"] = solver
    write(failed, marker)
    result(gated[2], runs[gated[2]], **{skipping.SKIPPED_ATTR: 1.0})  # an older workflow's skip marker
    assert made_runs(tmp_path, runs) == {made, failed}

    # three decisions: two needed, one not; the rest undecided
    def decide(rid: str, need: bool) -> None:
        (tmp_path / "results" / "refinement" / f"{rid}.json").write_text(json.dumps(
            {"run_finest": need, "coarser_runs": list(coarser[rid]), "tolerance": {"mu": 0.05, "dp": 0.3}}))

    for rid, need in zip(gated[:3], (True, True, False), strict=True):
        decide(rid, need)
    plan = make_plan(config, cores=2, directory=tmp_path)  # two one-thread jobs at once
    assert plan.parallel_jobs == 2
    assert plan.done == {made, failed}
    assert plan.need_share == pytest.approx(2 / 3)
    left = [r for r in plan.runs if r not in (made, failed)]
    certain = [r for r in left if r not in gated[2:]]  # the ungated runs and gated[1], decided needed
    undecided = gated[3:]
    certain_s = sum(plan.runs[r].here_s for r in certain)
    expected = max((certain_s + 2 / 3 * sum(plan.runs[r].here_s for r in undecided)) / 2,
                   max(plan.runs[r].here_s for r in certain))
    assert plan.expected_wall_s(left) == pytest.approx(expected)
    line = next(x for x in describe(plan).splitlines() if x.startswith("made already"))
    assert line == (
        f"made already (results/runs, this solver): 2 of {len(runs)} runs; left: between "
        f"**{_hours(plan.wall_s(certain))}** ({len(certain)} runs; every undecided gated finest run skipped) and "
        f"{_hours(plan.wall_s(certain + undecided))} ({len(certain) + len(undecided)} runs; every one made); "
        f"expected **{_hours(expected)}**, each undecided one counted at the share of the decisions made that "
        "needed their finest run (2 of 3)")

    # every decision made: no expectation; every run made but those decided not needed: no run left
    for rid in gated[3:]:
        decide(rid, False)
    decided = make_plan(config, cores=2, directory=tmp_path)
    text = describe(decided)
    assert "expected" not in text
    # ... and one number, not a range from a number to itself
    needed = decided.made(list(decided.runs), undecided=False)
    refinement = next(x for x in text.splitlines() if x.startswith("refinement only where needed"))
    assert refinement.endswith(
        f"(2 decided needed, {len(gated) - 2} decided not, 0 undecided): **{_hours(decided.wall_s(needed))}** "
        f"({len(needed)} runs, {sum(decided.runs[r].particle_steps for r in needed):.3g} particle-steps)")
    for rid in set(runs) - set(gated[2:]):
        result(rid, runs[rid])
    line = next(x for x in describe(make_plan(config, cores=2, directory=tmp_path)).splitlines()
                if x.startswith("made already"))
    assert line.endswith(f"{len(runs) - len(gated[2:])} of {len(runs)} runs; left: no run (the datasets and "
                         "figures, minutes)")
    # before any decision no expectation is made up; with nothing made, no line on what is left
    fresh = make_plan(config, cores=2, directory=tmp_path / "fresh")
    assert fresh.need_share is None and fresh.expected_wall_s(list(fresh.runs)) is None
    assert "made already" not in describe(fresh) and "expected" not in describe(fresh)
