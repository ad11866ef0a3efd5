"""plough: ploughing of a hard sphere through a coated metal sheet.

Analytical model (``plough.analytical``), 3D material point method solver (``plough.mpm``),
study helpers (``plough.study``) and figures (``plough.figures``) reproducing Mishra et al.,
"Analytical, numerical and experimental studies on ploughing behaviour in soft metallic
coatings", Wear 448-449 (2020) 203219.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("plough")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0+unknown"

__all__ = ["__version__"]
