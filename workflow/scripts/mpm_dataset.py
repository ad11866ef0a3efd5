"""Snakemake script: the netCDF dataset of one MPM figure from its runs (extrapolated to h -> 0).

Each run file is checked against the run it stands for (its scene as the config makes it, and the
solver that made it: plough.study.runfiles); a wrong or unreadable one ends the job with one line
naming the file and how to remake it.
"""

import logging
import sys

from plough.fingerprint import solver_fingerprint
from plough.io import write_netcdf_atomic
from plough.study.mpm_figures import build_dataset
from plough.study.runfiles import RunFileError

smk = snakemake  # noqa: F821 - injected by Snakemake
logging.basicConfig(filename=smk.log[0], level=logging.INFO, force=True)
try:
    # the whole config: the dataset reads only the part in params.view (plough.study.runfiles.figure_view)
    ds = build_dataset(smk.config, smk.wildcards.figure, smk.params.runs, solver=solver_fingerprint())
except RunFileError as exc:
    logging.error("%s", exc)
    sys.exit(str(exc))
write_netcdf_atomic(ds, smk.output[0])
logging.info("wrote %s", smk.output[0])
