"""Snakemake script (checkpoint mpm_refine): does a sweep point need its finest run?

Reads the point's two coarser runs (each checked against its run and this solver: plough.study.runfiles;
a wrong or unreadable one ends the job with one line naming the file and how to remake it), extrapolates
them to h -> 0 at the particle sizes their files record, and writes the decision
(plough.study.skipping.decide) as JSON, atomically; the reason goes to the log.
"""

import json
import os
import sys
import tempfile
from pathlib import Path

from plough.fingerprint import solver_fingerprint
from plough.study import matrix, skipping
from plough.study.runfiles import RunFileError, load_run

smk = snakemake  # noqa: F821 - injected by Snakemake


def decide(log) -> None:
    solver = solver_fingerprint()
    if solver != smk.params.solver:
        raise RuntimeError(f"this job's solver ({solver}) is not the one the workflow planned with "
                           f"({smk.params.solver}); rerun snakemake")
    scenes = matrix.all_runs(smk.config)
    coarse, mid = (load_run(path, rid, scenes.get(rid), solver)
                   for path, rid in zip(smk.input.coarser, smk.params.coarser, strict=True))
    decision = skipping.decide(smk.wildcards.run, coarse, mid, list(smk.params.coarser), smk.params.tolerance)
    out = Path(smk.output[0])
    out.parent.mkdir(parents=True, exist_ok=True)
    fd, tmp = tempfile.mkstemp(prefix=f".{out.name}.", suffix=".part", dir=out.parent)
    with os.fdopen(fd, "w") as f:
        json.dump(decision, f, indent=1, allow_nan=False)  # strict JSON: not-a-number is null (skipping.decide)
    os.replace(tmp, out)
    print(f"{'run' if decision['run_finest'] else 'skip'} {smk.wildcards.run}: {decision['reason']}", file=log)


with open(smk.log[0], "w", buffering=1) as log:
    try:
        decide(log)
    except RunFileError as exc:  # a coarser run that is not its run: one line, naming it
        print(exc, file=log)
        sys.exit(str(exc))
