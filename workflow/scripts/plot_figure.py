"""Snakemake script: draw one figure (PNG and PDF) from its dataset."""

import logging

import xarray as xr

from plough.figures import plot

smk = snakemake  # noqa: F821 - injected by Snakemake
logging.basicConfig(filename=smk.log[0], level=logging.INFO, force=True)
ds = xr.load_dataset(smk.input[0])
plot(smk.wildcards.figure, ds, [smk.output.png, smk.output.pdf])
logging.info("wrote %s and %s", smk.output.png, smk.output.pdf)
