"""Snakemake script: draw one figure (PNG and PDF) from its dataset.

Each file is drawn under a temporary name beside its target and renamed into place, so a killed job
never leaves a truncated figure under its final name (the workflow does not track incomplete files:
profiles/default).
"""

import logging
import os
from pathlib import Path

import xarray as xr

from plough.figures import plot
from plough.io import temporary_beside

smk = snakemake  # noqa: F821 - injected by Snakemake
logging.basicConfig(filename=smk.log[0], level=logging.INFO, force=True)
ds = xr.load_dataset(smk.input[0])
targets = [smk.output.png, smk.output.pdf]
temporary = [temporary_beside(p, suffix=Path(p).suffix) for p in targets]  # the suffix names the format
try:
    plot(smk.wildcards.figure, ds, temporary)
    for tmp, target in zip(temporary, targets, strict=True):
        os.replace(tmp, target)
finally:
    for tmp in temporary:
        tmp.unlink(missing_ok=True)
logging.info("wrote %s and %s", smk.output.png, smk.output.pdf)
