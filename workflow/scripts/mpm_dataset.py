"""Snakemake script: the netCDF dataset of one MPM figure from its runs (extrapolated to h -> 0).

Each run file is checked against the run it stands for (its scene as the config makes it, and the
solver that made it: plough.study.runfiles); a wrong or unreadable one ends the job with one line
naming the file and how to remake it. A gated finest run whose refinement decision (input.decisions, the
checkpoint mpm_refine) says it is not needed is not read: that point is extrapolated from its two coarser sizes.
"""

import json
import logging
import sys
from pathlib import Path

from plough.fingerprint import solver_fingerprint
from plough.io import write_netcdf_atomic
from plough.study.mpm_figures import build_dataset
from plough.study.runfiles import RunFileError

smk = snakemake  # noqa: F821 - injected by Snakemake
logging.basicConfig(filename=smk.log[0], level=logging.INFO, force=True)
try:
    # the whole config: the dataset reads only the part in params.view (plough.study.runfiles.figure_view)
    decisions = [json.loads(Path(p).read_text()) for p in smk.input.decisions]
    not_needed = [d["finest_run"] for d in decisions if not d["run_finest"]]
    for d in decisions:
        logging.info("%s: %s", "needed" if d["run_finest"] else "not needed", d["reason"])
    paths = {rid: path for rid, path in smk.params.runs.items() if rid not in not_needed}
    ds = build_dataset(smk.config, smk.wildcards.figure, paths, solver=solver_fingerprint(), not_needed=not_needed)
except RunFileError as exc:
    logging.error("%s", exc)
    sys.exit(str(exc))
write_netcdf_atomic(ds, smk.output[0])
logging.info("wrote %s", smk.output[0])
