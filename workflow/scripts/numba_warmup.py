"""Snakemake script: compile numba's kernels once before the MPM runs fan out."""

import logging

from plough.mpm.run import warm_up

smk = snakemake  # noqa: F821 - injected by Snakemake
logging.basicConfig(filename=smk.log[0], level=logging.INFO, force=True)
logging.info("numba kernels ready in %.1f s", warm_up(threads=1))
