"""Background grid: a box of nodes covering only the block and the room above it for pile-up.

Nodes sit at origin + (i, j, k) dx. Node data live in flat arrays indexed by
``(i * ny + j) * nz + k`` (z fastest, matching the particle seeding order for cache locality).
Boundary flags per node: 0 free, 1 fixed (outside the curved surface of the half cylinder: the
paper fixes that surface), 2 mirror plane (y = 0 with symmetry: the normal velocity vanishes),
3 ghost (y < 0 with symmetry: the mirror image of the node at -y, see ``transfers.grid_update``).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

FREE, FIXED, MIRROR, GHOST = 0, 1, 2, 3
#: Cells of padding beyond the particles so that every 27-node stencil lies on the grid.
PAD_CELLS = 3


@dataclass(frozen=True)
class Grid:
    origin: np.ndarray  # (3,) m
    dx: float  # m
    shape: tuple[int, int, int]

    @property
    def n_nodes(self) -> int:
        return int(np.prod(self.shape))

    def node_positions(self) -> np.ndarray:
        nx, ny, nz = self.shape
        i, j, k = np.meshgrid(np.arange(nx), np.arange(ny), np.arange(nz), indexing="ij")
        return self.origin + self.dx * np.stack([i.ravel(), j.ravel(), k.ravel()], axis=1)

    @property
    def upper(self) -> np.ndarray:
        return self.origin + self.dx * (np.array(self.shape) - 1)


def make_grid(length_m: float, radius_m: float, symmetric: bool, dx: float, headroom_m: float) -> Grid:
    """A grid over x in [0, L], y in [0, R] (or [-R, R]), z in [-R, headroom], padded.

    The top face z = 0 and the plane y = 0 are node planes whatever R is: where the free surface
    falls between nodes changes how the contact nodes see it (the coated reference scene at
    h = 10 um: mu_pl 0.169 with the surface at mid-cell, R = 170 um, against 0.122 on a node
    plane, R = 200 um), so a block radius that is not a whole number of cells must not shift it.
    """
    pad = PAD_CELLS * dx
    below = dx * np.ceil((radius_m + pad) / dx - 1e-9)  # a whole number of cells below z = 0 (and y = 0)
    lo = np.array([-pad, -pad if symmetric else -below, -below])
    hi = np.array([length_m + pad, radius_m + pad, headroom_m + pad])
    shape = tuple(int(np.ceil((hi[d] - lo[d]) / dx)) + 1 for d in range(3))
    return Grid(origin=lo, dx=dx, shape=shape)


def grown(grid: Grid, extra_cells: int, axis: int = 2) -> Grid:
    """The same grid with ``extra_cells`` more node layers at the high end of ``axis`` (2: on top, 0: past
    the far end, 1: past the side face y = R): every existing node keeps its (i, j, k) and its position, since
    the origin stays put."""
    if extra_cells < 1:
        raise ValueError(f"extra_cells = {extra_cells} must be >= 1")
    if axis not in (0, 1, 2):
        raise ValueError(f"axis = {axis} must be 0 (x, the far end), 1 (y, the side) or 2 (z, the top)")
    shape = list(grid.shape)
    shape[axis] += extra_cells
    return Grid(origin=grid.origin, dx=grid.dx, shape=(shape[0], shape[1], shape[2]))


def extend_node_array(data: np.ndarray, shape: tuple[int, int, int], extra_cells: int, axis: int = 0,
                      fill: float | None = None, grid_axis: int = 2) -> np.ndarray:
    """Node data of a grid of ``shape`` (flat nodes along array ``axis``) laid out on the grid with
    ``extra_cells`` more layers at the high end of ``grid_axis`` (:func:`grown`). The new layers hold
    ``fill``, or with ``fill`` None a copy of the old last layer (for the boundary flags: above the
    surface they depend on y alone, along x on y and z alone, and past the side face y = R on z alone)."""
    data = np.ascontiguousarray(data)
    pre, post = data.shape[:axis], data.shape[axis + 1:]
    new_shape = list(shape)
    new_shape[grid_axis] += extra_cells
    # one allocation in the final layout (a copy through a moved axis held the new array twice: the
    # per-chunk P2G buffers are most of a run's node memory)
    out = np.empty(pre + (int(np.prod(new_shape)),) + post, dtype=data.dtype)
    old = data.reshape(pre + tuple(shape) + post)
    new = out.reshape(pre + tuple(new_shape) + post)
    lead = (slice(None),) * (len(pre) + grid_axis)  # up to the grown axis of the node index
    n = shape[grid_axis]
    new[lead + (slice(0, n),)] = old
    new[lead + (slice(n, None),)] = old[lead + (slice(n - 1, n),)] if fill is None else fill
    return out


def mirror_plane_index(grid: Grid, symmetric: bool) -> int:
    """Index j of the node plane y = 0 with symmetry, -1 without."""
    if not symmetric:
        return -1
    j0 = int(round(-grid.origin[1] / grid.dx))
    if abs(grid.origin[1] + j0 * grid.dx) > 1e-9 * grid.dx:
        raise ValueError("the grid has no node plane at y = 0")
    return j0


def boundary_flags(grid: Grid, radius_m: float, symmetric: bool) -> np.ndarray:
    """Per-node boundary flag (FREE, FIXED, MIRROR, GHOST) for the half-cylinder block.

    Nodes at or beyond the curved surface y^2 + z^2 >= R^2 (below the top face) are fixed; with
    symmetry, nodes on y = 0 carry the mirror condition v_y = 0 and nodes with y < 0 are ghosts.
    """
    pos = grid.node_positions()
    y, z = pos[:, 1], pos[:, 2]
    flags = np.full(grid.n_nodes, FREE, dtype=np.int8)
    if symmetric:
        flags[np.abs(y) <= 1e-9 * grid.dx] = MIRROR
        flags[y < -1e-9 * grid.dx] = GHOST
    flags[(y * y + z * z >= radius_m * radius_m) & (z < 0)] = FIXED
    return flags
