"""The kernels' numba cache is named by the solver's fingerprint (plough.mpm's module docstring): a change
of any solver module, not only a kernel's own file, compiles afresh."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import numba

from plough.fingerprint import solver_fingerprint
from plough.mpm import kernel_cache_dir, transfers


def test_the_kernels_are_cached_in_a_folder_named_by_the_solver_fingerprint():
    folder = kernel_cache_dir()
    assert folder.name == f"numba-{solver_fingerprint()}"
    assert numba.config.CACHE_DIR == str(folder)
    # a kernel's own cache (made when its module was imported) lies in that folder
    assert Path(transfers.p2g._cache._cache_path).is_relative_to(folder)


def _cache_dir_in_fresh_process(env: dict[str, str]) -> str:
    code = "import numba, plough.mpm.transfers as t; print(numba.config.CACHE_DIR); print(t.p2g._cache._cache_path)"
    base = {k: v for k, v in os.environ.items() if k not in ("NUMBA_CACHE_DIR", "XDG_CACHE_HOME")}
    out = subprocess.run([sys.executable, "-c", code], env={**base, **env}, capture_output=True, text=True,
                         check=True)
    return out.stdout


def test_numba_cache_dir_is_honoured_with_the_fingerprint_below_it(tmp_path):
    out = _cache_dir_in_fresh_process({"NUMBA_CACHE_DIR": str(tmp_path)}).split()
    assert out[0] == str(tmp_path / f"numba-{solver_fingerprint()}")
    assert out[1].startswith(out[0])


def test_the_user_cache_folder_is_the_default(tmp_path):
    out = _cache_dir_in_fresh_process({"XDG_CACHE_HOME": str(tmp_path)}).split()
    assert out[0] == str(tmp_path / "plough" / f"numba-{solver_fingerprint()}")


def test_an_unwritable_cache_folder_leaves_numba_its_default(tmp_path):
    blocked = tmp_path / "file"
    blocked.write_text("not a folder")  # a folder cannot be made below a file, whoever runs the test
    out = _cache_dir_in_fresh_process({"XDG_CACHE_HOME": str(blocked)}).splitlines()
    assert out[0] == ""
    assert "__pycache__" in out[1]
