"""The 3D MPM solver: scene, kernels, contact, run loop and result measurements.

numba's ``cache=True`` keys a compiled kernel on its own source file only: a kernel that calls a
function of another module (``transfers.g2p_update`` calls ``constitutive.update_stress``) would be
loaded from the cache unchanged after an edit or upgrade of that other module, silently running the
old physics. So the kernels are cached in a folder named by the solver's fingerprint
(:func:`plough.fingerprint.solver_fingerprint`, the same one that identifies a run's result): any
change of the solver's code compiles afresh, and the result file's fingerprint names the code that
actually ran. The folder lies under ``NUMBA_CACHE_DIR`` if set, else under ``$XDG_CACHE_HOME/plough``
(``~/.cache/plough``); one that cannot be written leaves numba's default (``__pycache__`` beside the
sources).
"""

from __future__ import annotations

import os
import tempfile
from pathlib import Path

import numba

from plough.fingerprint import solver_fingerprint


def kernel_cache_dir() -> Path:
    """The folder the kernels of this solver are cached in (named by its fingerprint)."""
    base = os.environ.get("NUMBA_CACHE_DIR")
    if not base:
        base = Path(os.environ.get("XDG_CACHE_HOME") or Path.home() / ".cache") / "plough"
    return Path(base) / f"numba-{solver_fingerprint()}"


def _use_kernel_cache_dir() -> None:
    folder = kernel_cache_dir()
    try:
        folder.mkdir(parents=True, exist_ok=True)
        with tempfile.TemporaryFile(dir=folder):
            pass
    except OSError:
        return  # numba's default, beside the sources
    numba.config.CACHE_DIR = str(folder)


_use_kernel_cache_dir()
