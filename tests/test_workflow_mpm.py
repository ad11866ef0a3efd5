"""The MPM part of the Snakemake workflow, driven from pytest in a temporary copy of the project.

The runs import the installed plough (whose numba cache is warm); the copied ``src/`` provides the
package sources that every rule takes as an input, as in a checkout.
"""

import copy
import json
import math
import re
import shutil
import subprocess
import sys
from pathlib import Path

import numpy as np
import pytest
import xarray as xr
import yaml

from plough.study import matrix

ROOT = Path(__file__).resolve().parents[1]
SMOKE = yaml.safe_load((ROOT / "config" / "smoke.yaml").read_text())
FULL = yaml.safe_load((ROOT / "config" / "config.yaml").read_text())


def _project_copy(dest: Path) -> Path:
    for name in ("Snakefile", "config", "workflow", "src"):
        src = ROOT / name
        if src.is_dir():
            shutil.copytree(src, dest / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc"))
        else:
            shutil.copy(src, dest / name)
    return dest


def _snakemake(workdir: Path, *args: str, timeout: int = 600) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "snakemake", "--cores", "2", *args], cwd=workdir,
                          capture_output=True, text=True, timeout=timeout)


def _job_counts(text: str) -> dict[str, int]:
    """The 'Job stats' table of a Snakemake (dry) run: rule -> number of jobs."""
    lines = text.splitlines()
    start = lines.index("Job stats:")
    assert lines[start + 1].split() == ["job", "count"]
    counts = {}
    for line in lines[start + 3:]:
        if not line.strip():
            break
        name, count = line.split()
        counts[name] = int(count)
    return counts


FIG15_TARGETS = ("results/datasets/fig15.nc", "results/figures/fig15.png")


@pytest.fixture(scope="module")
def smoke_fig15(tmp_path_factory) -> Path:
    """The smoke Fig. 15 made once (its runs, dataset and figure) in a copy of the project, for the tests
    that read it or start from its runs."""
    work = _project_copy(tmp_path_factory.mktemp("fig15"))
    out = _snakemake(work, "--configfile=config/smoke.yaml", *FIG15_TARGETS)
    assert out.returncode == 0, (out.stdout + out.stderr)[-4000:]
    return work


@pytest.mark.slow
def test_smoke_fig15_runs_extrapolates_draws_and_caches(smoke_fig15):
    work, targets = smoke_fig15, FIG15_TARGETS

    mpm = SMOKE["mpm"]
    real = mpm["real_materials"]
    ds = xr.load_dataset(work / "results/datasets/fig15.nc")
    assert ds["dp"].dims == ("material", "load_N", "h")
    assert dict(ds.sizes) == {"material": 2, "load_N": len(real["loads_N"]), "h": len(mpm["particle_sizes_um"])}
    assert list(ds["load_N"].values) == [float(x) for x in real["loads_N"]]
    assert list(ds["h"].values) == sorted((float(h) for h in mpm["particle_sizes_um"]), reverse=True)
    for o in (*matrix.OUTPUTS, "Fz_mean", "max_particle_penetration", "wall_time_s"):
        assert np.isfinite(ds[o].values).all(), o
    for o in ("mu_h0", "dp_h0", "mu_h0_uncertainty", "dp_h0_uncertainty"):
        assert np.isfinite(ds[o].values).all(), o
    assert ds.attrs["plough_version"] and ds.attrs["git_commit"]
    assert json.loads(ds.attrs["config"])["particle_sizes_um"] == mpm["particle_sizes_um"]
    assert (work / "results/figures/fig15.png").stat().st_size > 10_000
    assert (work / "results/figures/fig15.pdf").exists()

    # one result file and one log per run, and only the runs Fig. 15 needs
    run_ids = matrix.figure_runs(SMOKE, "fig15")
    assert {p.stem for p in (work / "results/runs").glob("*.nc")} == set(run_ids)
    for rid in run_ids:
        log = (work / "logs/runs" / f"{rid}.log").read_text()
        assert "um slid" in log, rid  # the progress bar
        assert f"wrote results/runs/{rid}.nc: mu = " in log, rid
    # the dataset holds the runs' own numbers at their coordinates
    rid = run_ids[-1]  # steel at the highest load, finest size
    run = xr.load_dataset(work / "results/runs" / f"{rid}.nc")
    assert json.loads(run.attrs["scene"])["name"] == rid
    sel = {"material": "steel", "load_N": float(real["loads_N"][-1]), "h": min(float(h) for h in
                                                                                mpm["particle_sizes_um"])}
    for o in ("mu", "dp"):
        assert math.isclose(float(ds[o].sel(sel)), float(run[o]), rel_tol=1e-12), o

    # nothing left to do: every run and the dataset are cached
    again = _snakemake(work, "--configfile=config/smoke.yaml", "-n", *targets, timeout=120)
    assert again.returncode == 0, again.stderr[-3000:]
    assert "Nothing to be done" in again.stdout + again.stderr


def test_full_matrix_dry_run_schedules_every_run_once(tmp_path):
    """One dry run of the full matrix (config/config.yaml) for every check of it: the figures, the refinement
    checkpoint, and each rule's number of jobs."""
    work = _project_copy(tmp_path)
    out = _snakemake(work, "-n", timeout=300)
    assert out.returncode == 0, (out.stdout + out.stderr)[-4000:]
    text = out.stdout + out.stderr
    for fig in ("fig03", "fig04", "fig22"):
        assert fig in text
    # refinement only where needed (config/config.yaml): the decisions are planned, the DAG changes after them
    assert "checkpoint mpm_refine:" in text and "checkpoint jobs" in text
    counts = _job_counts(text)
    gated = matrix.skippable_runs(FULL)  # refinement only where needed is on in config/config.yaml
    assert gated and FULL["mpm"]["skip_finest_tolerance"] is not None
    assert counts["mpm_run"] == len(matrix.all_runs(FULL)) - len(gated)  # a gated finest run waits for its decision
    assert counts["mpm_refine"] == len(gated)
    assert counts["mpm_dataset"] == len(matrix.MPM_FIGURES) + 1  # and Fig. 22's
    assert counts["figure"] == len(matrix.MPM_FIGURES) + 3  # and Figs. 3, 4, 22
    assert "numba_warmup" not in counts  # each run job compiles numba's kernels when needed, under a lock
    assert counts["total"] == sum(n for name, n in counts.items() if name != "total")


@pytest.mark.slow
def test_smoke_refinement_makes_the_finest_run_only_where_the_coarser_sizes_do_not_agree(smoke_fig15, tmp_path):
    """Refinement only where needed end to end on Fig. 15 (the checkpoint mpm_refine): the coarser runs first,
    then a tolerance between the points' two-size uncertainties, so that some finest runs are needed and some
    not. Before running, `snakemake -n` lists every decision and no gated finest run; each decision follows
    plough.study.skipping from the run files; a finest run is made exactly where its decision asks; the dataset
    says which points were extrapolated from two sizes; a picture's finest run always runs."""
    from plough.study import skipping

    sizes = matrix.particle_sizes_um(SMOKE)
    finest_ids = [r for r in matrix.figure_runs(SMOKE, "fig15") if r.endswith(f"_h{matrix.fmt(sizes[-1])}")]
    stems = [r.rsplit("_h", 1)[0] for r in finest_ids]
    coarse = [f"results/runs/{s}_h{matrix.fmt(h)}.nc" for s in stems for h in sizes[:2]]
    # the coarser runs as the smoke Fig. 15 made them (its files and Snakemake's records of them); no finest run
    work = tmp_path / "wf"
    shutil.copytree(smoke_fig15, work, symlinks=True)
    for path in (*FIG15_TARGETS, "results/figures/fig15.pdf", *(f"results/runs/{r}.nc" for r in finest_ids)):
        (work / path).unlink()
    out = _snakemake(work, "--configfile=config/smoke.yaml", *coarse)
    assert out.returncode == 0, (out.stdout + out.stderr)[-4000:]
    assert "Nothing to be done" in out.stdout + out.stderr  # made once, in the fixture

    def worst(stem: str) -> float:
        runs = [xr.load_dataset(work / f"results/runs/{stem}_h{matrix.fmt(h)}.nc") for h in sizes[:2]]
        ex = skipping.two_size_extrapolation(*runs, sizes[0], sizes[1])
        # NaN (a run's sampling error not estimable) never skips: as infinite
        return max(float("inf") if math.isnan(e["relative_uncertainty"]) else e["relative_uncertainty"]
                   for e in ex.values())

    cfg = copy.deepcopy(SMOKE)
    cfg["mpm"]["skip_finest_tolerance"] = 0.5
    gated = matrix.skippable_runs(cfg)
    spread = sorted(w for r, s in zip(finest_ids, stems, strict=True) if r in gated and math.isfinite(w := worst(s)))
    assert len(spread) >= 2 and spread[0] < spread[-1]
    tol = 0.5 * (spread[0] + spread[-1])  # the smoke sizes are coarse: this may exceed 1
    cfg["mpm"]["skip_finest_tolerance"] = tol
    (work / "config" / "smoke.yaml").write_text(yaml.safe_dump(cfg))
    in_fig = [r for r in finest_ids if r in gated]
    assert in_fig and len(in_fig) < len(finest_ids)  # the smoke's Fig. 15 has a picture's run too

    plan = _snakemake(work, "--configfile=config/smoke.yaml", "-n", "results/datasets/fig15.nc")
    assert plan.returncode == 0, (plan.stdout + plan.stderr)[-4000:]
    counts = _job_counts(plan.stdout + plan.stderr)
    assert counts["mpm_refine"] == len(in_fig)
    assert counts["mpm_run"] == len(finest_ids) - len(in_fig)  # the pictures' finest runs: never gated
    assert not any(f"results/runs/{r}.nc" in plan.stdout for r in in_fig)

    out = _snakemake(work, "--configfile=config/smoke.yaml", "results/datasets/fig15.nc")
    assert out.returncode == 0, (out.stdout + out.stderr)[-4000:]
    ds = xr.load_dataset(work / "results/datasets/fig15.nc")
    n_skipped = 0
    for rid, stem in zip(finest_ids, stems, strict=True):
        made = (work / "results/runs" / f"{rid}.nc").exists()
        if rid not in gated:
            assert made, rid
            continue
        decision = json.loads((work / "results/refinement" / f"{rid}.json").read_text())
        expect_skip = worst(stem) <= tol
        assert decision["run_finest"] == (not expect_skip) == made, rid
        assert decision["coarser_sizes_um"] == list(sizes[:2])
        assert decision["reason"] in (work / "logs/refinement" / f"{rid}.log").read_text()
        n_skipped += expect_skip
    assert 0 < n_skipped < len(in_fig)
    assert int(ds["skipped_finest"].sum()) == n_skipped
    assert np.isfinite(ds["mu_h0"].values).all() and np.isfinite(ds["dp_h0"].values).all()
    again = _snakemake(work, "--configfile=config/smoke.yaml", "-n", "results/datasets/fig15.nc")
    assert "Nothing to be done" in again.stdout + again.stderr, (again.stdout + again.stderr)[-3000:]


class _Namespace:
    def __init__(self, **kw):
        self.__dict__.update(kw)


def _run_script(tmp_path: Path, monkeypatch, config: dict, rid: str, error: Exception) -> tuple[Path, str]:
    """workflow/scripts/mpm_run.py in-process with a fake snakemake object and a solver that raises ``error``."""
    import runpy

    import plough.mpm.run

    def failing_simulate(*args, **kwargs):
        raise error

    monkeypatch.setattr(plough.mpm.run, "simulate", failing_simulate)
    monkeypatch.setattr(plough.mpm.run, "warm_up", lambda threads=None: 0.0)  # nothing to compile for a fake solver
    monkeypatch.setattr(sys, "stderr", sys.stderr)  # the script points it at its log; restored after
    out, log = tmp_path / f"{rid}.nc", tmp_path / f"{rid}.log"
    from plough.fingerprint import solver_fingerprint

    smk = _Namespace(params=_Namespace(scene=matrix.all_runs(config)[rid], skip_tolerance=None, coarser_sizes_um=None,
                                       solver=solver_fingerprint()),
                     input=_Namespace(coarser=[]), output=[str(out)], log=[str(log)], threads=1, config=config,
                     wildcards=_Namespace(run=rid))
    try:
        runpy.run_path(str(ROOT / "workflow" / "scripts" / "mpm_run.py"), init_globals={"snakemake": smk})
    finally:
        text = log.read_text() if log.exists() else ""
    return out, text


def test_a_finest_run_that_stops_unstable_leaves_a_failure_marker(tmp_path, monkeypatch):
    """mpm.finest_failure: record turns the solver's instability error of a finest sweep run into a failure
    marker naming the error; with stop (the smoke config), at a coarser size, for a picture's run, for lost
    contact or any other error the job fails and writes nothing."""
    from plough.mpm.solver import InstabilityError, SimulationError
    from plough.study import skipping

    record = copy.deepcopy(SMOKE)
    record["mpm"]["finest_failure"] = "record"
    recordable = matrix.failure_recordable_runs(record)
    finest = sorted(recordable)[0]
    unstable = InstabilityError("unstable run at step 12 (slid 3 um): a particle left the grid")
    (tmp_path / "a").mkdir()
    out, log = _run_script(tmp_path / "a", monkeypatch, record, finest, unstable)
    marker = xr.load_dataset(out)
    assert skipping.is_failed(marker) and "a particle left the grid" in marker.attrs["failure_reason"]
    assert ", ".join(recordable[finest]) in marker.attrs["failure_stands_in"]
    assert "recorded as a failure marker" in log and "a particle left the grid" in log

    coarse = recordable[finest][0]
    picture = matrix.figure_runs(record, "fig19")[0]  # a picture's finest run, also a sweep point
    assert picture.endswith(f"_h{matrix.fmt(min(matrix.particle_sizes_um(record)))}") and picture not in recordable
    lost = SimulationError("the sphere lost contact while sliding")
    for i, (config, rid, error) in enumerate([(SMOKE, finest, unstable), (record, coarse, unstable),
                                              (record, picture, unstable), (record, finest, lost),
                                              (record, finest, ValueError("a refused scene"))]):
        (tmp_path / str(i)).mkdir()
        stderr = sys.stderr
        with pytest.raises(type(error), match=re.escape(str(error))):
            _run_script(tmp_path / str(i), monkeypatch, config, rid, error)
        assert not list((tmp_path / str(i)).glob("*.nc")), (rid, error)
        assert sys.stderr is stderr  # given back before the log closed: the traceback is not lost
