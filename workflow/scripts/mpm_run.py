"""Snakemake script: one MPM run, its progress bar in the job's log, the result written atomically.

The result (or marker) records the fingerprint of the solver that made it (``solver_fingerprint``,
plough.fingerprint), which must be the one the workflow planned with (``params.solver``): every
reader checks a run file against its run with it (plough.study.runfiles).

numba compiles the kernels into its cache on first use, and parallel first compilations of
``cache=True`` functions can race on the cache files: the first job that finds the kernels' sources
changed (results/.numba_warm records their times and sizes, numba's own cache key, with numba's and
Python's versions and the cache folder, named by the solver's fingerprint: plough.mpm) compiles them
with a tiny scene while the other jobs wait on a lock.

Whether a gated finest run is needed at all is decided before it is scheduled (workflow/scripts/mpm_refine.py,
the checkpoint mpm_refine); this job only runs.
A finest sweep run that stops unstable (``InstabilityError``: not a refused scene, a load it cannot
reach or lost contact) writes a failure marker instead of failing the job when the
config's ``mpm.finest_failure`` is ``record`` (read here, not a param, so that changing it does not
rerun the finest runs that succeeded).
"""

import contextlib
import fcntl
import json
import sys
from pathlib import Path

import numba

from plough.fingerprint import solver_files, solver_fingerprint
from plough.io import write_netcdf_atomic
from plough.mpm.io import write_result
from plough.mpm.run import simulate, warm_up
from plough.mpm.scene import Scene
from plough.mpm.solver import InstabilityError
from plough.study import matrix, skipping
from plough.study.runfiles import SOLVER_ATTR

smk = snakemake  # noqa: F821 - injected by Snakemake
SOLVER = solver_fingerprint()


def warm_numba(log) -> None:
    """Compile numba's kernels unless this source state is already compiled; one job at a time."""
    stamp = Path(smk.output[0]).parents[1] / ".numba_warm"  # results/.numba_warm
    key = json.dumps({"sources": [(str(p), p.stat().st_mtime_ns, p.stat().st_size) for p in solver_files()],
                      "numba": numba.__version__, "python": sys.version, "executable": sys.executable,
                      "cache": numba.config.CACHE_DIR})
    stamp.parent.mkdir(parents=True, exist_ok=True)
    with open(stamp.with_name(".numba_warm.lock"), "a") as lock:
        fcntl.flock(lock, fcntl.LOCK_EX)  # released when the file closes, or the process dies
        if stamp.exists() and stamp.read_text() == key:
            return
        print(f"compiling numba's kernels (the solver's sources changed): {warm_up(threads=1):.1f} s", file=log)
        stamp.write_text(key)


def run(log) -> None:
    if SOLVER != smk.params.solver:
        raise RuntimeError(f"this job's solver ({SOLVER}, plough in {solver_files()[0].parents[1]}) is not the one "
                           f"the workflow planned with ({smk.params.solver}): the solver's code changed since "
                           "snakemake started, or the jobs import another plough than snakemake does; rerun snakemake "
                           "(from the Python environment its jobs use)")
    scene = Scene.from_dict(smk.params.scene)
    warm_numba(log)
    try:
        ds = simulate(scene, progress=True, threads=smk.threads)
    except Exception as exc:  # the solver's message in the log, then the job fails (or the marker)
        print(f"\nrun {scene.name} failed: {type(exc).__name__}: {exc}", file=log)
        coarser = matrix.failure_recordable_runs(smk.config).get(smk.wildcards.run)
        if not (isinstance(exc, InstabilityError) and coarser):
            raise
        marker = skipping.failure_marker(smk.params.scene, smk.wildcards.run, str(exc), list(coarser))
        marker.attrs[SOLVER_ATTR] = SOLVER
        write_netcdf_atomic(marker, smk.output[0])
        print(f"recorded as a failure marker (mpm.finest_failure: record): {smk.output[0]}; the figure "
              f"dataset extrapolates this point from {', '.join(coarser)}", file=log)
    else:
        ds.attrs[SOLVER_ATTR] = SOLVER
        write_result(ds, smk.output[0])
        print(f"\nwrote {smk.output[0]}: mu = {float(ds.mu):.4g}, dp = {float(ds.dp):.4g} m, "
              f"{ds.attrs['cost_wall_time_s']:.1f} s wall", file=log)


# the progress bar (sliding distance, ETA, Fx/Fz) goes to logs/runs/<run>.log; stderr is given back before the
# log closes, so that a failing run's traceback reaches Snakemake's output (not "lost sys.stderr")
with open(smk.log[0], "w", buffering=1) as log, contextlib.redirect_stderr(log):
    run(log)
