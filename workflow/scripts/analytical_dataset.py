"""Snakemake script: the netCDF dataset of one analytical figure."""

import logging

from plough.io import write_netcdf_atomic
from plough.study.analytical_figures import build_dataset

smk = snakemake  # noqa: F821 - injected by Snakemake
logging.basicConfig(filename=smk.log[0], level=logging.INFO, force=True)
ds = build_dataset(smk.wildcards.figure, smk.params.config)
write_netcdf_atomic(ds, smk.output[0])
logging.info("wrote %s", smk.output[0])
