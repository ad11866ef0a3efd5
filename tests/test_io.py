"""plough.io: results are written atomically and readable as the user's umask allows."""

from __future__ import annotations

import os
import stat

import matplotlib
import numpy as np
import pytest
import xarray as xr

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402

from plough.figures.style import save  # noqa: E402
from plough.io import write_netcdf_atomic  # noqa: E402


@pytest.fixture(params=[0o022, 0o077, 0o002])
def umask(request):
    old = os.umask(request.param)
    yield request.param
    os.umask(old)


def test_results_get_the_mode_a_plain_open_would_give(umask, tmp_path):
    expected = 0o666 & ~umask  # what open(path, "w") creates under this umask
    nc = write_netcdf_atomic(xr.Dataset({"mu": ((), 0.3, {"units": "1", "long_name": "friction"})}), tmp_path / "r.nc")
    fig = plt.figure()
    save(fig, [tmp_path / "f.png"])
    for path in (nc, tmp_path / "f.png"):
        assert stat.S_IMODE(path.stat().st_mode) == expected
    assert [p.name for p in tmp_path.iterdir() if p.name.startswith(".")] == []  # no temporary file left


def test_a_refused_dataset_leaves_no_file(tmp_path):
    with pytest.raises(ValueError, match="'mu' holds non-finite values"):
        write_netcdf_atomic(xr.Dataset({"mu": ((), np.nan)}), tmp_path / "r.nc")
    assert list(tmp_path.iterdir()) == []
