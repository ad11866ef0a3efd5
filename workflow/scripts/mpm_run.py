"""Snakemake script: one MPM run, its progress bar in the job's log, the result written atomically."""

import sys

from plough.mpm.io import write_result
from plough.mpm.run import simulate
from plough.mpm.scene import Scene

smk = snakemake  # noqa: F821 - injected by Snakemake
with open(smk.log[0], "w", buffering=1) as log:
    sys.stderr = log  # the progress bar (sliding distance, ETA, Fx/Fz) goes to logs/runs/<run>.log
    scene = Scene.from_dict(smk.params.scene)
    try:
        ds = simulate(scene, progress=True, threads=smk.threads)
    except Exception as exc:  # the solver's message in the log, then the job fails
        print(f"\nrun {scene.name} failed: {type(exc).__name__}: {exc}", file=log)
        raise
    write_result(ds, smk.output[0])
    print(f"\nwrote {smk.output[0]}: mu = {float(ds.mu):.4g}, dp = {float(ds.dp):.4g} m, "
          f"{ds.attrs['cost_wall_time_s']:.1f} s wall", file=log)
