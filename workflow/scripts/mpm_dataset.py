"""Snakemake script: the netCDF dataset of one MPM figure from its runs (extrapolated to h -> 0)."""

import logging

from plough.io import write_netcdf_atomic
from plough.study.mpm_figures import build_dataset

smk = snakemake  # noqa: F821 - injected by Snakemake
logging.basicConfig(filename=smk.log[0], level=logging.INFO, force=True)
config = {"mpm": smk.params.mpm, "power_law": smk.params.power_law}
ds = build_dataset(config, smk.wildcards.figure, smk.params.runs)
write_netcdf_atomic(ds, smk.output[0])
logging.info("wrote %s", smk.output[0])
