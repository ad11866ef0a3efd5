"""The Snakemake workflow driven from pytest in a temporary copy (smoke config)."""

import math
import re
import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr
import yaml

from plough.mpm.scene import Scene
from plough.study import cost, matrix

ROOT = Path(__file__).resolve().parents[1]


def _copy_workflow(d: Path) -> Path:
    """The workflow (Snakefile, config, rules) copied into ``d``, the package's source linked beside it."""
    for name in ("Snakefile", "config", "workflow"):
        src = ROOT / name
        (shutil.copytree if src.is_dir() else shutil.copy)(src, d / name)
    (d / "src").symlink_to(ROOT / "src")
    return d


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    return _copy_workflow(tmp_path_factory.mktemp("wf"))


def _snakemake(workdir, *args):
    return subprocess.run([sys.executable, "-m", "snakemake", "--cores", "1", *args], cwd=workdir,
                          capture_output=True, text=True, timeout=600)


def test_one_figure_builds_only_what_it_needs(workdir):
    out = _snakemake(workdir, "--configfile=config/smoke.yaml", "results/figures/fig04.png")
    assert out.returncode == 0, out.stderr[-3000:]
    assert (workdir / "results/figures/fig04.png").stat().st_size > 10_000
    assert (workdir / "results/figures/fig04.pdf").exists()
    assert not (workdir / "results/datasets/fig03.nc").exists()
    ds = xr.load_dataset(workdir / "results/datasets/fig04.nc")
    for name, var in ds.variables.items():
        if name not in ("coating", "correction"):
            assert "units" in var.attrs, name
        assert "long_name" in var.attrs, name
    assert ds.attrs["plough_version"] and ds.attrs["git_commit"] and "config" in ds.attrs
    # nothing left to do: the run is cached
    again = _snakemake(workdir, "--configfile=config/smoke.yaml", "-n", "results/figures/fig04.png")
    assert "Nothing to be done" in again.stdout + again.stderr


def test_bad_config_fails_before_any_job_naming_the_key(workdir, tmp_path):
    bad = tmp_path / "bad.yaml"
    bad.write_text((workdir / "config/smoke.yaml").read_text().replace("  k1: 12.5", "  k1: -1"))
    out = _snakemake(workdir, f"--configfile={bad}", "-n")
    assert out.returncode != 0
    text = out.stdout + out.stderr
    assert "['analytical']['k1']" in text and "minimum of 0" in text


def _job_counts(text: str) -> dict[str, int]:
    """The 'Job stats' table of a Snakemake (dry) run: rule -> number of jobs ({} when nothing is to be done)."""
    lines = text.splitlines()
    if "Job stats:" not in lines:
        return {}
    counts = {}
    for line in lines[lines.index("Job stats:") + 3:]:
        if not line.strip():
            break
        name, count = line.split()
        counts[name] = int(count)
    return counts


def test_refinement_checkpoint_decides_then_asks_only_for_the_needed_finest_runs(tmp_path):
    """Refinement only where needed (checkpoint mpm_refine) on the smoke Fig. 15 with made-up run files (no MPM run):
    before the decisions `-n` lists them and no gated finest run; each decision follows plough.study.skipping from
    the coarser files; then `-n` lists exactly the needed finest runs; with those present the dataset is built,
    extrapolating the other points from two sizes, and nothing is left to do."""
    import json

    import yaml

    from plough.fingerprint import solver_fingerprint
    from plough.study import matrix, skipping
    from tests.study.test_mpm_figures import fake_run

    work = tmp_path / "wf"
    work.mkdir()
    for name in ("Snakefile", "config", "workflow"):
        src = ROOT / name
        (shutil.copytree if src.is_dir() else shutil.copy)(src, work / name)
    (work / "src").symlink_to(ROOT / "src")
    cfg = yaml.safe_load((ROOT / "config" / "smoke.yaml").read_text())
    cfg["mpm"]["skip_finest_tolerance"] = 0.5
    gated = {r: c for r, c in matrix.skippable_runs(cfg).items() if r in matrix.figure_runs(cfg, "fig15")}
    scenes = matrix.all_runs(cfg)
    runs = {}
    for rid in matrix.figure_runs(cfg, "fig15"):
        runs[rid] = fake_run(scenes[rid])
        runs[rid].attrs["solver_fingerprint"] = solver_fingerprint()
    sizes = matrix.particle_sizes_um(cfg)

    def worst(finest: str) -> float:
        ex = skipping.two_size_extrapolation(runs[gated[finest][0]], runs[gated[finest][1]], sizes[0], sizes[1])
        # NaN (a run's sampling error not estimable) never skips: as infinite
        return max(float("inf") if math.isnan(e["relative_uncertainty"]) else e["relative_uncertainty"]
                   for e in ex.values())

    spread = sorted(w for w in map(worst, gated) if math.isfinite(w))
    assert len(spread) >= 2 and spread[0] < spread[-1]
    cfg["mpm"]["skip_finest_tolerance"] = tol = 0.5 * (spread[0] + spread[-1])
    (work / "config" / "smoke.yaml").write_text(yaml.safe_dump(cfg))
    (work / "results" / "runs").mkdir(parents=True)
    for rid, ds in runs.items():
        if rid not in gated:
            ds.to_netcdf(work / "results" / "runs" / f"{rid}.nc")

    def dry() -> tuple[dict[str, int], str]:
        out = _snakemake(work, "--configfile=config/smoke.yaml", "-n", "results/datasets/fig15.nc")
        assert out.returncode == 0, (out.stdout + out.stderr)[-3000:]
        return _job_counts(out.stdout + out.stderr), out.stdout + out.stderr

    counts, text = dry()
    assert counts.get("mpm_refine") == len(gated) and "mpm_run" not in counts and counts.get("mpm_dataset") == 1
    assert not any(f"results/runs/{r}.nc" in text for r in gated)
    out = _snakemake(work, "--configfile=config/smoke.yaml", *[f"results/refinement/{r}.json" for r in gated])
    assert out.returncode == 0, (out.stdout + out.stderr)[-3000:]
    needed = [r for r in gated if json.loads((work / "results/refinement" / f"{r}.json").read_text())["run_finest"]]
    assert needed == [r for r in gated if worst(r) > tol] and 0 < len(needed) < len(gated)
    counts, text = dry()
    assert counts.get("mpm_run") == len(needed) and "mpm_refine" not in counts
    assert all(f"results/runs/{r}.nc" in text for r in needed)
    assert not any(f"results/runs/{r}.nc" in text for r in gated if r not in needed)
    for rid in needed:  # stand-ins for the needed finest runs
        runs[rid].to_netcdf(work / "results" / "runs" / f"{rid}.nc")
    out = _snakemake(work, "--configfile=config/smoke.yaml", "results/datasets/fig15.nc")
    assert out.returncode == 0, (out.stdout + out.stderr)[-3000:]
    ds = xr.load_dataset(work / "results/datasets/fig15.nc")
    assert int(ds["skipped_finest"].sum()) == len(gated) - len(needed)
    assert "not needed" in (work / "logs/datasets/fig15.log").read_text()
    counts, _ = dry()
    assert counts == {}  # nothing left to do


def test_the_longest_runs_start_first(workdir):
    """Each MPM run's priority is its counted particle-steps (in thousands), so that with several runs at once
    (--cores over mpm.threads) the scheduler starts the longest first and none is left to finish alone."""
    config = yaml.safe_load((workdir / "config/smoke.yaml").read_text())
    runs = matrix.all_runs(config)
    out = _snakemake(workdir, "--configfile=config/smoke.yaml", "-n", "--forceall", "results/datasets/fig15.nc")
    assert out.returncode == 0, out.stderr[-3000:]
    listed = {}
    for block in (out.stdout + out.stderr).split("rule ")[1:]:
        if block.startswith("mpm_run:"):
            run = block.split("wildcards: run=")[1].split()[0]
            listed[run] = int(block.split("priority: ")[1].split()[0])
    assert len(listed) >= 4
    for run, priority in listed.items():
        assert priority == int(cost.estimate(Scene.from_dict(runs[run])).particle_steps // 1e3), run
    assert len(set(listed.values())) > 1  # the runs differ, and so do their priorities


def test_refinement_decisions_go_before_any_run(tmp_path):
    """The default config's refinement decisions (seconds each) have a priority above every run's, so that the
    finest runs they let in (the longest of all) join the queue as soon as their coarser runs are made."""
    out = _snakemake(_copy_workflow(tmp_path), "-n")
    assert out.returncode == 0, out.stderr[-3000:]
    priorities: dict[str, list[int]] = {}
    for block in re.split(r"\n(?:rule|checkpoint) ", out.stdout + out.stderr)[1:]:
        rule = block.split(":")[0]
        if rule in ("mpm_run", "mpm_refine"):
            priorities.setdefault(rule, []).append(int(block.split("priority: ")[1].split()[0]))
    gated = matrix.skippable_runs(yaml.safe_load((ROOT / "config" / "config.yaml").read_text()))
    assert len(priorities["mpm_refine"]) == len(gated) > 0 and len(set(priorities["mpm_refine"])) == 1
    assert priorities["mpm_refine"][0] > max(priorities["mpm_run"])
