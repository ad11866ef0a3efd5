"""Provenance and atomic writing shared by every result plough writes.

Results carry the package version, the git commit of the source tree (when it is a git checkout)
and the full parameters as a JSON string (netCDF attributes cannot hold dicts or bools).
A result is written to a temporary file next to its target and renamed into place, so an
interrupted run never leaves a half-written file that a workflow would take as complete.
"""

from __future__ import annotations

import json
import os
import secrets
import subprocess
from functools import lru_cache
from pathlib import Path
from typing import Any

import numpy as np
import xarray as xr

from plough import __version__


@lru_cache(maxsize=1)
def git_commit() -> str:
    """Commit of the source tree plough was imported from, '+dirty' if modified, or 'unknown'."""
    src = Path(__file__).resolve().parent
    try:
        head = subprocess.run(["git", "rev-parse", "HEAD"], cwd=src, capture_output=True, text=True,
                              timeout=10, check=True).stdout.strip()
        dirty = subprocess.run(["git", "status", "--porcelain", "--untracked-files=no", "--", "."],
                               cwd=src, capture_output=True, text=True, timeout=10).stdout.strip()
    except (OSError, subprocess.SubprocessError):
        return "unknown"
    return head + ("+dirty" if dirty else "")


def _jsonable(obj: Any) -> Any:
    if isinstance(obj, dict):
        return {str(k): _jsonable(v) for k, v in obj.items()}
    if isinstance(obj, list | tuple):
        return [_jsonable(v) for v in obj]
    if isinstance(obj, np.generic):
        return obj.item()
    if isinstance(obj, np.ndarray):
        return obj.tolist()
    return obj


def to_json(obj: Any) -> str:
    return json.dumps(_jsonable(obj), sort_keys=True)


def provenance_attrs(parameters: dict[str, Any] | None = None, *, key: str = "config") -> dict[str, str]:
    """Attributes naming what produced a result: package version, git commit, parameters (JSON)."""
    attrs = {"plough_version": __version__, "git_commit": git_commit(),
             "source": "plough (Mishra et al., Wear 448-449 (2020) 203219 reproduced)"}
    if parameters is not None:
        attrs[key] = to_json(parameters)
    return attrs


def check_finite(ds: xr.Dataset, name: str = "dataset") -> None:
    """Refuse to write NaN or infinity in a float variable that is not allowed to hold it.

    Variables may opt out with the attribute ``allow_missing = 1`` (e.g. a per-size value of a
    run that was skipped), in which case NaN means 'missing' and is documented as such.
    """
    for var_name, var in ds.data_vars.items():
        if var.dtype.kind == "f" and not var.attrs.get("allow_missing", 0):
            values = var.values
            if not np.all(np.isfinite(values)):
                raise ValueError(f"{name}: variable {var_name!r} holds non-finite values; not written")


def temporary_beside(path: str | os.PathLike[str], suffix: str = ".part") -> Path:
    """Create an empty hidden file next to ``path`` for an atomic write, and return its name.

    Made with ``os.open(..., 0o666)``, so the kernel applies the user's umask: the renamed result
    is as readable as a plain ``open`` would make it (``tempfile.mkstemp`` makes 0600 files, and
    reading the umask from Python means setting it, a race with other threads).
    """
    path = Path(path)
    for _ in range(100):
        tmp = path.parent / f".{path.name}.{secrets.token_hex(6)}{suffix}"
        try:
            os.close(os.open(tmp, os.O_WRONLY | os.O_CREAT | os.O_EXCL, 0o666))
        except FileExistsError:
            continue
        return tmp
    raise FileExistsError(f"no free temporary name next to {str(path)!r}")


def write_netcdf_atomic(ds: xr.Dataset, path: str | os.PathLike[str]) -> Path:
    """Write ``ds`` to ``path`` through a temporary file and an atomic rename."""
    path = Path(path)
    check_finite(ds, str(path))
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = temporary_beside(path)
    try:
        ds.to_netcdf(tmp, engine="netcdf4")
        os.replace(tmp, path)
    except BaseException:
        Path(tmp).unlink(missing_ok=True)
        raise
    return path
