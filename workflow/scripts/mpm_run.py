"""Snakemake script: one MPM run, its progress bar in the job's log, the result written atomically.

A finest-size run with ``params.skip_tolerance`` set first extrapolates its point's two coarser
runs; within the tolerance it writes a skip marker instead of running (plough.study.skipping).
A finest sweep run that stops unstable (``InstabilityError``: not a refused scene, a load it cannot
reach or lost contact) writes a failure marker instead of failing the job when the
config's ``mpm.finest_failure`` is ``record`` (read here, not a param, so that changing it does not
rerun the finest runs that succeeded).
"""

import contextlib

import xarray as xr

from plough.io import write_netcdf_atomic
from plough.mpm.io import write_result
from plough.mpm.run import simulate
from plough.mpm.scene import Scene
from plough.mpm.solver import InstabilityError
from plough.study import matrix, skipping

smk = snakemake  # noqa: F821 - injected by Snakemake


def skipped(log) -> bool:
    """Write the skip marker and say so when the two coarser runs extrapolate within the tolerance."""
    if smk.params.skip_tolerance is None:
        return False
    coarse, mid = (xr.load_dataset(p) for p in smk.input.coarser)
    h_coarse, h_mid = smk.params.coarser_sizes_um
    ex = skipping.two_size_extrapolation(coarse, mid, h_coarse, h_mid)
    print(f"two-size extrapolation of h = {h_coarse:g}, {h_mid:g} um: {ex}", file=log)
    if not skipping.should_skip(ex, smk.params.skip_tolerance):
        return False
    marker = skipping.skip_marker(smk.params.scene, ex, smk.params.skip_tolerance, list(smk.input.coarser))
    write_netcdf_atomic(marker, smk.output[0])
    print(f"skipped (within skip_finest_tolerance = {smk.params.skip_tolerance:g}): wrote the marker "
          f"{smk.output[0]}", file=log)
    return True


# the progress bar (sliding distance, ETA, Fx/Fz) goes to logs/runs/<run>.log; stderr is given back before the
# log closes, so that a failing run's traceback reaches Snakemake's output (not "lost sys.stderr")
with open(smk.log[0], "w", buffering=1) as log, contextlib.redirect_stderr(log):
    scene = Scene.from_dict(smk.params.scene)
    if not skipped(log):
        try:
            ds = simulate(scene, progress=True, threads=smk.threads)
        except Exception as exc:  # the solver's message in the log, then the job fails (or the marker)
            print(f"\nrun {scene.name} failed: {type(exc).__name__}: {exc}", file=log)
            coarser = matrix.failure_recordable_runs(smk.config).get(smk.wildcards.run)
            if not (isinstance(exc, InstabilityError) and coarser):
                raise
            write_netcdf_atomic(skipping.failure_marker(smk.params.scene, smk.wildcards.run, str(exc), list(coarser)),
                                smk.output[0])
            print(f"recorded as a failure marker (mpm.finest_failure: record): {smk.output[0]}; the figure "
                  f"dataset extrapolates this point from {', '.join(coarser)}", file=log)
        else:
            write_result(ds, smk.output[0])
            print(f"\nwrote {smk.output[0]}: mu = {float(ds.mu):.4g}, dp = {float(ds.dp):.4g} m, "
                  f"{ds.attrs['cost_wall_time_s']:.1f} s wall", file=log)
