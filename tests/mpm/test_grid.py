"""plough.mpm.grid: node planes at the top face and the mirror plane; the block inside the padding."""

from __future__ import annotations

import numpy as np
import pytest

from plough.mpm.grid import FIXED, GHOST, MIRROR, PAD_CELLS, boundary_flags, make_grid


@pytest.mark.parametrize("radius_um", [120, 165, 170, 200, 255, 380])
@pytest.mark.parametrize("dx_um", [5, 10, 20, 40])
@pytest.mark.parametrize("symmetric", [True, False])
def test_top_face_and_mirror_plane_are_node_planes_for_any_radius(radius_um, dx_um, symmetric):
    R, dx = radius_um * 1e-6, dx_um * 1e-6
    g = make_grid(1e-3, R, symmetric, dx, 30e-6)
    k0 = -g.origin[2] / dx
    j0 = -g.origin[1] / dx
    assert abs(k0 - round(k0)) < 1e-9 and abs(j0 - round(j0)) < 1e-9
    # at least PAD_CELLS whole cells beyond the block on every side, at most one cell more
    assert -g.origin[2] - R >= PAD_CELLS * dx * (1 - 1e-12)
    assert -g.origin[2] - R < (PAD_CELLS + 1) * dx
    assert g.upper[0] >= 1e-3 + PAD_CELLS * dx * (1 - 1e-12) and g.upper[1] >= R + PAD_CELLS * dx * (1 - 1e-12)
    assert g.upper[2] >= 30e-6 + PAD_CELLS * dx * (1 - 1e-12)


def test_flags_of_a_symmetric_grid():
    dx = 20e-6
    g = make_grid(4e-4, 170e-6, True, dx, 3e-5)
    flags = boundary_flags(g, 170e-6, True)
    pos = g.node_positions()
    inside = (pos[:, 1] ** 2 + pos[:, 2] ** 2 < (170e-6) ** 2) | (pos[:, 2] >= 0)
    assert np.all(flags[np.isclose(pos[:, 1], 0.0, atol=1e-12) & inside] == MIRROR)
    assert np.all(flags[(pos[:, 1] < -1e-12) & inside] == GHOST)
    outside = (pos[:, 1] ** 2 + pos[:, 2] ** 2 >= (170e-6) ** 2) & (pos[:, 2] < 0) & (pos[:, 1] > 1e-12)
    assert np.all(flags[outside] == FIXED)
