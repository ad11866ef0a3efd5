"""Analytical ploughing model of Mishra et al. (2020), section 2: eqs. 1-5 and 9.1-9.2.

numpy only (plus an xarray front end); never imports :mod:`plough.mpm`.
"""

from plough.analytical.model import (
    CORRECTIONS,
    INTERFACE_NAMES,
    RESULT_META,
    PloughingResult,
    effective_hardness,
    ploughing,
    segment_area,
)
from plough.analytical.powerlaw import PAPER_FITS, PowerLawFit, power_law_friction
from plough.analytical.sweep import COORD_META, ploughing_dataset

__all__ = [
    "CORRECTIONS", "COORD_META", "INTERFACE_NAMES", "PAPER_FITS", "RESULT_META", "PloughingResult",
    "PowerLawFit", "effective_hardness", "ploughing", "ploughing_dataset", "power_law_friction",
    "segment_area",
]
