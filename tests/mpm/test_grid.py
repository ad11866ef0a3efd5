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


def test_a_taller_grid_keeps_every_node_where_it_was_and_its_data_with_it():
    from plough.mpm.grid import extend_node_array, grown

    g = make_grid(300e-6, 80e-6, True, 10e-6, 20e-6)
    t = grown(g, 4)
    nx, ny, nz = g.shape
    assert t.shape == (nx, ny, nz + 4) and np.array_equal(t.origin, g.origin) and t.dx == g.dx
    old_pos = g.node_positions().reshape(nx, ny, nz, 3)
    assert np.array_equal(t.node_positions().reshape(nx, ny, nz + 4, 3)[:, :, :nz], old_pos)
    data = np.arange(g.n_nodes * 2, dtype=float).reshape(g.n_nodes, 2)
    new = extend_node_array(data, g.shape, 4, fill=-1.0).reshape(nx, ny, nz + 4, 2)
    assert np.array_equal(new[:, :, :nz], data.reshape(nx, ny, nz, 2)) and np.all(new[:, :, nz:] == -1.0)
    per_chunk = np.stack([data, 2 * data])  # (chunks, nodes, 2), nodes along axis 1
    new = extend_node_array(per_chunk, g.shape, 4, axis=1, fill=0.0)
    assert new.shape == (2, t.n_nodes, 2) and new.flags.c_contiguous
    assert np.array_equal(new[1].reshape(nx, ny, nz + 4, 2)[:, :, :nz], 2 * data.reshape(nx, ny, nz, 2))
    top = extend_node_array(np.arange(g.n_nodes), g.shape, 4).reshape(nx, ny, nz + 4)
    assert np.array_equal(top[:, :, nz + 3], top[:, :, nz - 1])  # fill None: the old top layer again
    with pytest.raises(ValueError, match="extra_cells = 0"):
        grown(g, 0)
    with pytest.raises(ValueError, match=r"axis = 3 must be 0 \(x, the far end\), 1 \(y, the side\) or 2"):
        grown(g, 2, axis=3)
    wide = grown(g, 3, axis=1)  # past the side face: every node keeps its (i, j, k) and position
    assert wide.shape == (nx, ny + 3, nz) and np.array_equal(wide.origin, g.origin)
    assert np.array_equal(wide.node_positions().reshape(nx, ny + 3, nz, 3)[:, :ny], old_pos)
    side = extend_node_array(data, g.shape, 3, fill=None, grid_axis=1).reshape(nx, ny + 3, nz, 2)
    assert np.array_equal(side[:, :ny], data.reshape(nx, ny, nz, 2))
    assert np.array_equal(side[:, ny + 2], side[:, ny - 1])


def test_a_longer_grid_keeps_every_node_where_it_was_and_its_flags_are_the_longer_grids_own():
    """Past the block's far end the flags depend on y and z alone: copying the last x layer gives exactly the
    flags a grid made that long from the start has (x-major nodes: the new layers are appended)."""
    from plough.mpm.grid import extend_node_array, grown

    g = make_grid(300e-6, 80e-6, True, 10e-6, 20e-6)
    t = grown(g, 5, axis=0)
    nx, ny, nz = g.shape
    assert t.shape == (nx + 5, ny, nz) and np.array_equal(t.origin, g.origin)
    assert np.array_equal(t.node_positions()[:g.n_nodes], g.node_positions())
    data = np.arange(g.n_nodes * 2, dtype=float).reshape(g.n_nodes, 2)
    new = extend_node_array(data, g.shape, 5, fill=-1.0, grid_axis=0)
    assert np.array_equal(new[:g.n_nodes], data) and np.all(new[g.n_nodes:] == -1.0)
    per_chunk = np.stack([data, 2 * data])
    new = extend_node_array(per_chunk, g.shape, 5, axis=1, fill=0.0, grid_axis=0)
    assert new.shape == (2, t.n_nodes, 2) and np.array_equal(new[1, :g.n_nodes], 2 * data)
    assert np.all(new[:, g.n_nodes:] == 0.0)
    flags = extend_node_array(boundary_flags(g, 80e-6, True), g.shape, 5, grid_axis=0)
    assert np.array_equal(flags, boundary_flags(t, 80e-6, True))
    assert np.array_equal(boundary_flags(t, 80e-6, True), boundary_flags(make_grid(350e-6, 80e-6, True, 10e-6, 20e-6),
                                                                        80e-6, True))
