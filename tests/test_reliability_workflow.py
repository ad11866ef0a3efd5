"""The workflow's cache and recovery (issue 31, items 1-4), each case as a user or a tester meets it.

1. A run's identity is its physics: its scene and the solver's code, not the mtime of every source
   file, not the workflow's scripts, not a figure; a dataset depends on the points it reads.
2. A run file that is not the run it is read as (another scene, another solver) is refused, naming it.
3. A corrupt run file is a one-line error naming it and saying what to do; the workflow remakes it.
4. A workflow killed with ``kill -9`` resumes with the documented commands, keeping a run that the
   orphaned job finished.

The DAG cases need no MPM run: every output is created empty and ``snakemake --touch`` records it as
made by the current workflow (its params and inputs), so a dry run (``-n``) says exactly what a change
would rerun. That state is made once and copied per test: a copy, being the same workflow in another place,
plans nothing (the cheap rules name the package sources relative to the working directory). They run Snakemake
in a temporary copy of the project with its ``src/`` first on the Python path, so that an edit of the copy's
package is what the workflow sees.
"""

from __future__ import annotations

import json
import os
import re
import runpy
import shutil
import signal
import subprocess
import sys
import time
from pathlib import Path

import pytest
import xarray as xr
import yaml

from plough.io import to_json
from plough.study import matrix
from tests.test_workflow_mpm import _job_counts as job_stats

ROOT = Path(__file__).resolve().parents[1]
SMOKE = yaml.safe_load((ROOT / "config" / "smoke.yaml").read_text())
SMOKE_RUNS = matrix.all_runs(SMOKE)
MPM_FIGURES = [*matrix.MPM_FIGURES, "fig22"]
ALL_FIGURES = sorted(["fig03", "fig04", *MPM_FIGURES])


# ----------------------------------------------------------------------------- helpers
def _project_copy(dest: Path, *, fresh: bool = True) -> Path:
    """A checkout of the project: the files git tracks that the workflow uses (``fresh``: all of
    them modified now, as a ``git clone`` leaves them)."""
    dest.mkdir(parents=True, exist_ok=True)
    for name in ("Snakefile", "config", "workflow", "src", "profiles"):
        src = ROOT / name
        if not src.exists():
            continue
        if src.is_dir():
            shutil.copytree(src, dest / name, ignore=shutil.ignore_patterns("__pycache__", "*.pyc", "*.egg-info"))
        else:
            shutil.copy2(src, dest / name)
    if fresh:
        now = time.time()
        for p in dest.rglob("*"):
            os.utime(p, (now, now))
    return dest


def _env(work: Path, own_src: bool) -> dict[str, str]:
    env = dict(os.environ)
    if own_src:  # the copy's package, not the installed one: edits of the copy are what the workflow sees
        env["PYTHONPATH"] = os.pathsep.join([str(work / "src"), env.get("PYTHONPATH", "")]).rstrip(os.pathsep)
    return env


def _snakemake(work: Path, *args: str, own_src: bool = True, timeout: int = 600) -> subprocess.CompletedProcess:
    return subprocess.run([sys.executable, "-m", "snakemake", "--cores", "1", *args], cwd=work,
                          env=_env(work, own_src), capture_output=True, text=True, timeout=timeout)


def _job_counts(text: str) -> dict[str, int]:
    """The 'Job stats' table of a Snakemake (dry) run: rule -> number of jobs (empty: nothing to do)."""
    if "Job stats:" not in text.splitlines():
        assert "Nothing to be done" in text, text[-3000:]
        return {}
    return job_stats(text)


def _planned(work: Path, *args: str) -> tuple[dict[str, int], str]:
    out = _snakemake(work, "-n", "--configfile=config/smoke.yaml", *args, timeout=300)
    text = out.stdout + out.stderr
    assert out.returncode == 0, text[-4000:]
    return _job_counts(text), text


def _planned_outputs(text: str, rule: str) -> set[str]:
    """Output files of the planned jobs of one rule in a dry run's listing."""
    outs, current = set(), None
    for line in text.splitlines():
        s = line.strip()
        if s.startswith(("rule ", "localrule ")):
            current = s.split()[1].rstrip(":")
        elif s.startswith("output:") and current == rule:
            outs.update(x.strip() for x in s[len("output:"):].split(","))
    return outs


def _touched_smoke_outputs(work: Path) -> None:
    """Every output of the smoke workflow, empty, recorded by ``snakemake --touch`` as made by the
    current workflow: the state after a complete run, without running anything."""
    for rid in SMOKE_RUNS:
        (work / "results/runs").mkdir(parents=True, exist_ok=True)
        (work / "results/runs" / f"{rid}.nc").touch()
    (work / "results/.numba_warm").touch()  # the warm-up marker of the workflow before issue 31
    for fig in ALL_FIGURES:
        for path in (f"results/datasets/{fig}.nc", f"results/figures/{fig}.png", f"results/figures/{fig}.pdf"):
            (work / path).parent.mkdir(parents=True, exist_ok=True)
            (work / path).touch()
    # --forceall: every job "runs" (is touched, in the DAG's order) and is recorded with its params and inputs
    out = _snakemake(work, "--touch", "--forceall", "--configfile=config/smoke.yaml", timeout=300)
    assert out.returncode == 0, (out.stdout + out.stderr)[-4000:]
    _assert_nothing_planned(work)  # a complete state


@pytest.fixture(scope="module")
def touched_smoke(tmp_path_factory) -> Path:
    """A fresh checkout after a complete smoke run (:func:`_touched_smoke_outputs`), made once for the module's
    DAG cases: each copies it (:func:`_copy_of`) before changing anything."""
    work = _project_copy(tmp_path_factory.mktemp("touched") / "wf")
    _touched_smoke_outputs(work)
    return work


def _copy_of(touched: Path, dest: Path) -> Path:
    """A copy of a checkout elsewhere, its files' times kept (as ``cp -a`` does), Snakemake's records included:
    the same workflow in another place, so nothing is planned in it (asserted)."""
    shutil.copytree(touched, dest, symlinks=True)
    _assert_nothing_planned(dest)
    return dest


def _assert_nothing_planned(work: Path) -> None:
    counts, _ = _planned(work)
    assert counts == {}, counts


def _append(path: Path, text: str) -> None:
    path.write_text(path.read_text() + text)


# ----------------------------------------------------------------------------- 1. identity by physics
def test_a_comment_docstring_or_figure_change_reruns_no_mpm_run_a_solver_change_reruns_all(touched_smoke, tmp_path):
    work = _copy_of(touched_smoke, tmp_path / "wf")

    # a figure's code (comment and code): figures may redraw, no MPM run reruns
    _append(work / "src/plough/figures/style.py", "\n# a comment added by a test\nTEST_CONSTANT = 1\n")
    counts, _ = _planned(work)
    assert counts.get("mpm_run", 0) == 0, counts
    # the workflow's own scripts: a comment in the run script reruns nothing
    _append(work / "workflow/scripts/mpm_run.py", "\n# a comment added by a test\n")
    counts, _ = _planned(work)
    assert counts.get("mpm_run", 0) == 0, counts

    # the solver's comments and docstrings: no rerun (they do not change what it computes)
    solver = work / "src/plough/mpm/solver.py"
    text = solver.read_text()
    first_doc = re.search(r'(def \w+\([^)]*\)[^:]*:\n\s+""")', text)
    assert first_doc is not None
    text = text.replace(first_doc.group(1), first_doc.group(1) + "Reworded by a test. ", 1)
    solver.write_text(text + "\n# a comment added by a test\n")
    counts, _ = _planned(work)
    assert counts.get("mpm_run", 0) == 0, counts

    # the solver's code: every run reruns, and says why
    _append(solver, "\nTEST_CODE_CHANGE = 1\n")
    counts, text = _planned(work)
    assert counts.get("mpm_run", 0) == len(SMOKE_RUNS), counts
    assert "Params have changed" in text or "params" in text.lower()


def test_copied_runs_rerun_nothing_in_a_fresh_checkout(touched_smoke, tmp_path):
    """The README's reuse advice: copy results/runs/ (with their times, as cp -a or rsync -a do) into a
    fresh checkout of the same solver; only datasets and figures are made."""
    old = touched_smoke  # read only
    newest_run = max(p.stat().st_mtime for p in (old / "results/runs").iterdir())
    time.sleep(max(0.0, newest_run + 1.1 - time.time()))  # the fresh checkout is newer than every run file
    new = _project_copy(tmp_path / "new")
    shutil.copytree(old / "results/runs", new / "results/runs")  # copy2: times kept
    counts, _ = _planned(new)
    assert counts.get("mpm_run", 0) == 0, counts
    assert counts.get("mpm_dataset", 0) == len(MPM_FIGURES), counts


def test_a_lubricant_constant_reruns_its_runs_and_only_the_datasets_that_read_them(touched_smoke, tmp_path):
    work = _copy_of(touched_smoke, tmp_path / "wf")
    cfg = yaml.safe_load((work / "config/smoke.yaml").read_text())
    cfg["mpm"]["real_materials"]["lubricants"]["dx56"]["Cp"] = 1.5
    (work / "config/smoke.yaml").write_text(yaml.safe_dump(cfg))
    changed = set(matrix.all_runs(cfg)) - set(SMOKE_RUNS)
    assert 0 < len(changed) < len(SMOKE_RUNS)
    counts, text = _planned(work)
    assert counts.get("mpm_run", 0) == len(changed), counts
    expected = {fig for fig in MPM_FIGURES if set(matrix.figure_runs(cfg, fig)) & changed}
    assert 0 < len(expected) < len(MPM_FIGURES)
    assert _planned_outputs(text, "mpm_dataset") == {f"results/datasets/{fig}.nc" for fig in expected}


# ----------------------------------------------------------------------------- 2. the run a file stands for
def _fake_runs(tmp_path: Path, figure: str) -> dict[str, Path]:
    from tests.study.test_mpm_figures import fake_run

    paths = {}
    for rid in matrix.figure_runs(SMOKE, figure):
        paths[rid] = tmp_path / f"{rid}.nc"
        fake_run(SMOKE_RUNS[rid]).to_netcdf(paths[rid])
    return paths


def _one_line(message: str) -> None:
    assert "\n" not in message.strip() and len(message) < 600, message


def test_a_run_file_holding_another_scene_is_refused_naming_it(tmp_path):
    from plough.study.mpm_figures import build_dataset

    paths = _fake_runs(tmp_path, "fig13")
    ids = list(paths)
    a, b = ids[0], next(r for r in ids if r.rsplit("_h", 1)[1] == ids[0].rsplit("_h", 1)[1] and r != ids[0])
    shutil.copy(paths[a], paths[b])  # the test: one run file copied over another of the same size
    with pytest.raises(ValueError) as err:
        build_dataset(SMOKE, "fig13", paths)
    msg = str(err.value)
    _one_line(msg)
    assert str(paths[b]) in msg and a in msg and "snakemake" in msg

    paths = _fake_runs(tmp_path, "fig13")
    coarse, fine = ids[0], ids[0].rsplit("_h", 1)[0] + f"_h{matrix.fmt(min(matrix.particle_sizes_um(SMOKE)))}"
    shutil.copy(paths[coarse], paths[fine])  # the same point at another particle size
    with pytest.raises(ValueError, match="particle size") as err:
        build_dataset(SMOKE, "fig13", paths)
    _one_line(str(err.value))
    assert str(paths[fine]) in str(err.value)


class _Namespace:
    def __init__(self, **kw):
        self.__dict__.update(kw)


def _dataset_script(tmp_path: Path, figure: str, paths: dict[str, Path]) -> Path:
    """workflow/scripts/mpm_dataset.py in-process with a fake snakemake object, as the workflow calls it."""
    out, log = tmp_path / f"{figure}.nc", tmp_path / f"{figure}.log"
    from plough.study import runfiles

    params = _Namespace(mpm=SMOKE["mpm"], power_law=SMOKE["power_law"], runs={r: str(p) for r, p in paths.items()},
                        view=runfiles.figure_view(SMOKE, figure))
    smk = _Namespace(params=params, config=SMOKE, output=[str(out)], log=[str(log)],
                     wildcards=_Namespace(figure=figure),
                     # the smoke config gates no finest run: no refinement decisions (checkpoint mpm_refine)
                     input=_Namespace(runs=[str(p) for p in paths.values()], decisions=[]))
    runpy.run_path(str(ROOT / "workflow/scripts/mpm_dataset.py"), init_globals={"snakemake": smk})
    return out


def test_a_run_file_made_by_another_solver_is_refused_by_the_workflow(tmp_path):
    from plough.fingerprint import solver_fingerprint

    paths = _fake_runs(tmp_path, "fig15")
    for p in paths.values():  # as the workflow writes them: with the solver that made them
        ds = xr.load_dataset(p)
        ds.attrs["solver_fingerprint"] = solver_fingerprint()
        ds.to_netcdf(p)
    assert _dataset_script(tmp_path, "fig15", paths).exists()

    stale = list(paths)[2]
    ds = xr.load_dataset(paths[stale])
    ds.attrs["solver_fingerprint"] = "0123456789abcdef"
    ds.to_netcdf(paths[stale])
    with pytest.raises(SystemExit) as err:
        _dataset_script(tmp_path, "fig15", paths)
    msg = str(err.value.code)
    _one_line(msg)
    assert str(paths[stale]) in msg and "another solver" in msg and "--forcerun" in msg

    ds.attrs.pop("solver_fingerprint")  # a file from before run files recorded their solver
    ds.to_netcdf(paths[stale])
    with pytest.raises(SystemExit, match="no solver fingerprint"):
        _dataset_script(tmp_path, "fig15", paths)


# ----------------------------------------------------------------------------- 3. corrupt run files
@pytest.mark.parametrize("damage", ["garbage", "truncated", "empty"])
def test_a_corrupt_run_file_is_a_one_line_error_naming_it(tmp_path, damage):
    from plough.study.mpm_figures import build_dataset

    paths = _fake_runs(tmp_path, "fig15")
    bad = paths[list(paths)[1]]
    data = bad.read_bytes()
    bad.write_bytes({"garbage": b"not a netCDF file\n" * 10, "truncated": data[: len(data) // 2],
                     "empty": b""}[damage])
    with pytest.raises(ValueError) as err:
        build_dataset(SMOKE, "fig15", paths)
    msg = str(err.value)
    _one_line(msg)
    assert str(bad) in msg and "unreadable" in msg and "snakemake" in msg


def test_the_refinement_decision_refuses_a_corrupt_coarser_run(tmp_path):
    """A point's refinement decision (checkpoint mpm_refine) reads its two coarser runs: a broken one is named."""
    import copy

    cfg = copy.deepcopy(SMOKE)
    cfg["mpm"]["skip_finest_tolerance"] = 0.5
    finest, (coarse, mid) = next(iter(matrix.skippable_runs(cfg).items()))
    from plough.fingerprint import solver_fingerprint
    from tests.study.test_mpm_figures import fake_run

    (tmp_path / "runs").mkdir()
    coarse_p, mid_p = tmp_path / "runs" / f"{coarse}.nc", tmp_path / "runs" / f"{mid}.nc"
    ds = fake_run(matrix.all_runs(cfg)[coarse])
    ds.attrs["solver_fingerprint"] = solver_fingerprint()
    ds.to_netcdf(coarse_p)  # a good coarse run
    mid_p.write_bytes(b"\x89HDF\r\n\x1a\n" + b"\0" * 100)  # an HDF5 signature, then nothing
    out = tmp_path / "refinement" / f"{finest}.json"
    smk = _Namespace(params=_Namespace(tolerance=0.5, coarser=[coarse, mid], solver=solver_fingerprint()),
                     input=_Namespace(coarser=[str(coarse_p), str(mid_p)]), output=[str(out)],
                     log=[str(tmp_path / "refine.log")], config=cfg, wildcards=_Namespace(run=finest))
    with pytest.raises(SystemExit) as err:
        runpy.run_path(str(ROOT / "workflow/scripts/mpm_refine.py"), init_globals={"snakemake": smk})
    msg = str(err.value.code)
    _one_line(msg)
    assert str(mid_p) in msg and "unreadable" in msg
    assert not out.exists()


def test_the_workflow_remakes_a_broken_run_file_the_way_the_error_says(touched_smoke, tmp_path):
    """The error's advice, --forcerun <file>, plans that run and what reads it. (Deleting the file would
    not do: Snakemake remakes a missing file only for an output that needs it.)"""
    from plough.study import runfiles

    work = _copy_of(touched_smoke, tmp_path / "wf")
    rid = matrix.figure_runs(SMOKE, "fig15")[1]
    path = f"results/runs/{rid}.nc"
    (work / path).write_bytes(b"garbage")
    err = runfiles.RunFileError.unreadable(path, rid, OSError("NetCDF: HDF error"))
    _one_line(str(err))
    advice = re.search(r"`snakemake (.*?)`", str(err))
    assert advice is not None, str(err)
    args = advice.group(1).split()
    assert "--forcerun" in args and path in args
    counts, text = _planned(work, *[a for a in args if not a.startswith("--cores") and not a.isdigit()])
    assert counts.get("mpm_run") == 1 and path in _planned_outputs(text, "mpm_run")
    readers = {f"results/datasets/{fig}.nc" for fig in MPM_FIGURES if rid in matrix.figure_runs(SMOKE, fig)}
    assert "results/datasets/fig15.nc" in readers
    assert _planned_outputs(text, "mpm_dataset") == readers


# ----------------------------------------------------------------------------- 4. a killed workflow resumes
def _descendants(pid: int) -> set[int]:
    children: dict[int, list[int]] = {}
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        children.setdefault(int(fields[1]), []).append(int(stat.parent.name))
    out, todo = set(), [pid]
    while todo:
        for c in children.get(todo.pop(), []):
            out.add(c)
            todo.append(c)
    return out


def _alive(pid: int) -> bool:
    try:
        return Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0] != "Z"
    except OSError:
        return False


@pytest.mark.slow
def test_a_killed_workflow_resumes_keeping_the_run_an_orphaned_job_finished(tmp_path):
    """kill -9 of snakemake while an MPM job runs: the job runs on (orphaned) and writes its run. The
    documented resume, ``snakemake --unlock`` then the same command, keeps that run (complete: written
    atomically; valid: its scene and solver) and makes the rest."""
    work = _project_copy(tmp_path / "wf")
    sizes = matrix.particle_sizes_um(SMOKE)
    point_runs = [r for r in matrix.figure_runs(SMOKE, "fig13") if r.endswith(f"_h{matrix.fmt(sizes[0])}")]
    first, second = (f"results/runs/{r}.nc" for r in point_runs[:2])
    cmd = [sys.executable, "-m", "snakemake", "--cores", "1", "--configfile=config/smoke.yaml", first, second]
    log = open(tmp_path / "killed.log", "w")  # noqa: SIM115 - closed below
    proc = subprocess.Popen(cmd, cwd=work, stdout=log, stderr=subprocess.STDOUT, start_new_session=True)
    orphans: set[int] = set()
    try:
        deadline = time.time() + 600
        run_logs = [work / "logs/runs" / f"{Path(p).stem}.log" for p in (first, second)]
        while time.time() < deadline:  # an MPM job is sliding
            if any(p.exists() and "um slid" in p.read_text() for p in run_logs):
                break
            assert proc.poll() is None, (tmp_path / "killed.log").read_text()[-3000:]
            time.sleep(0.2)
        else:
            pytest.fail("no MPM job started")
        running = next(p for p in run_logs if p.exists())
        orphans = _descendants(proc.pid)
        assert orphans
        os.kill(proc.pid, signal.SIGKILL)
        proc.wait()
        assert any(_alive(p) for p in orphans)  # the job runs on without snakemake
        while any(_alive(p) for p in orphans) and time.time() < deadline:
            time.sleep(0.5)
        assert not any(_alive(p) for p in orphans)
    finally:
        log.close()
        for p in orphans | _descendants(proc.pid):
            if _alive(p):
                os.kill(p, signal.SIGKILL)
    finished = work / "results/runs" / f"{running.stem}.nc"
    other = work / (second if running.stem == Path(first).stem else first)
    assert finished.exists() and not other.exists()  # the orphan finished its run, the other never started
    kept = finished.stat()

    # the documented resume: unlock (snakemake was killed, its locks stayed), then the same command
    unlock = _snakemake(work, "--configfile=config/smoke.yaml", "--unlock", own_src=False)
    assert unlock.returncode == 0, (unlock.stdout + unlock.stderr)[-3000:]
    resume = subprocess.run(cmd, cwd=work, capture_output=True, text=True, timeout=900)
    assert resume.returncode == 0, (resume.stdout + resume.stderr)[-4000:]
    assert other.exists()
    now = finished.stat()
    assert (now.st_ino, now.st_mtime_ns) == (kept.st_ino, kept.st_mtime_ns)  # kept, not recomputed
    from plough.study import runfiles

    # valid: its run's scene, and the solver that made it recorded (the shared source tree may have changed
    # since, so the fingerprint is not compared with this process's)
    ds = runfiles.load_run(finished, running.stem, SMOKE_RUNS[running.stem])
    assert json.loads(ds.attrs["scene"]) == json.loads(to_json(SMOKE_RUNS[running.stem]))
    assert len(ds.attrs[runfiles.SOLVER_ATTR]) == 16
