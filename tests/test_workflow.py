"""The Snakemake workflow driven from pytest in a temporary copy (smoke config)."""

import shutil
import subprocess
import sys
from pathlib import Path

import pytest
import xarray as xr

ROOT = Path(__file__).resolve().parents[1]


@pytest.fixture(scope="module")
def workdir(tmp_path_factory):
    d = tmp_path_factory.mktemp("wf")
    for name in ("Snakefile", "config", "workflow"):
        src = ROOT / name
        (shutil.copytree if src.is_dir() else shutil.copy)(src, d / name)
    (d / "src").symlink_to(ROOT / "src")
    return d


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


def test_full_matrix_dry_run(workdir):
    out = _snakemake(workdir, "-n")
    assert out.returncode == 0, out.stderr[-3000:]
    text = out.stdout + out.stderr
    for fig in ("fig03", "fig04", "fig22"):
        assert fig in text
    # refinement only where needed (config/config.yaml): the decisions are planned, the DAG changes after them
    assert "rule mpm_refine:" in text and "checkpoint jobs" in text
