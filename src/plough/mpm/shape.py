"""Quadratic B-spline shape functions (model.md section 2).

Chosen over linear hat functions because they are C1: a particle crossing a cell face sees a
continuous force, so there is no cell-crossing noise in the quasi-static contact force. Their
support is 3 nodes per direction (27 in 3D). With x in units of the cell size and
base = floor(x - 0.5), fx = x - base in [0.5, 1.5):

    w0 = 0.5 (1.5 - fx)^2,  w1 = 0.75 - (fx - 1)^2,  w2 = 0.5 (fx - 0.5)^2

and the derivatives with respect to x are fx - 1.5, -2 (fx - 1), fx - 0.5. The weights sum
to 1 and reproduce linear functions exactly; the APIC/MLS inertia matrix is D = dx^2/4 I.

A particle's stencil (:func:`stencil`) is set up here once for every kernel that visits its 27
nodes (the transfers and the contact): node (a, b, c), each 0..2, has the flat index
:func:`stencil_node` gives and the weight wx[a] wy[b] wz[c].
"""

from __future__ import annotations

import math
from typing import NamedTuple

from numba import njit

#: APIC inertia factor: D^-1 = 4 / dx^2 for quadratic B-splines.
APIC_D_INV_FACTOR = 4.0


@njit(cache=True, inline="always")
def bspline2(x):
    """Base node index and the three weights of a point at ``x`` (grid units) in one direction."""
    base = int(math.floor(x - 0.5))
    fx = x - base
    return base, 0.5 * (1.5 - fx) ** 2, 0.75 - (fx - 1.0) ** 2, 0.5 * (fx - 0.5) ** 2


@njit(cache=True, inline="always")
def bspline2_grad(x):
    """Base node index and the three weight derivatives d w / d x (grid units)."""
    base = int(math.floor(x - 0.5))
    fx = x - base
    return base, fx - 1.5, -2.0 * (fx - 1.0), fx - 0.5


class Stencil(NamedTuple):
    """The 27 nodes around a particle: the lowest node's (i, j, k), the particle's position in grid units
    from the grid's origin, and the three weights along each axis."""

    base: tuple[int, int, int]
    g: tuple[float, float, float]
    wx: tuple[float, float, float]
    wy: tuple[float, float, float]
    wz: tuple[float, float, float]


@njit(cache=True, inline="always")
def stencil(x, p, origin, inv_dx):
    """The stencil of particle p at x[p] on the grid of origin ``origin`` and cell size 1 / ``inv_dx``."""
    gx = (x[p, 0] - origin[0]) * inv_dx
    gy = (x[p, 1] - origin[1]) * inv_dx
    gz = (x[p, 2] - origin[2]) * inv_dx
    bx, wx0, wx1, wx2 = bspline2(gx)
    by, wy0, wy1, wy2 = bspline2(gy)
    bz, wz0, wz1, wz2 = bspline2(gz)
    return Stencil((bx, by, bz), (gx, gy, gz), (wx0, wx1, wx2), (wy0, wy1, wy2), (wz0, wz1, wz2))


@njit(cache=True, inline="always")
def stencil_row(s, a, b, ny, nz):
    """Flat index of the stencil's node (a, b, 0) on a grid of ny x nz nodes per x slab (z fastest)."""
    return ((s.base[0] + a) * ny + (s.base[1] + b)) * nz + s.base[2]


@njit(cache=True, inline="always")
def stencil_node(s, a, b, c, ny, nz):
    """Flat index and weight wx[a] wy[b] wz[c] of the stencil's node (a, b, c)."""
    return stencil_row(s, a, b, ny, nz) + c, s.wx[a] * s.wy[b] * s.wz[c]


@njit(cache=True, inline="always")
def stencil_axis_offset(s, axis, a, dx):
    """Component ``axis`` of x_i - x_p, m, for the stencil's nodes of index ``a`` along that axis (grid of cell
    size ``dx``)."""
    return (s.base[axis] + a - s.g[axis]) * dx


@njit(cache=True, inline="always")
def stencil_row_weight(s, a, b, ny, nz, dx):
    """What the stencil's row (a, b) of three nodes along z shares: the flat index of node (a, b, 0) (node
    (a, b, c) is that + c), the weight wx[a] wy[b] (node (a, b, c): that times wz[c], the product of
    :func:`stencil_node`) and the x and y components of x_i - x_p, m. The kernels take them once per row."""
    return (stencil_row(s, a, b, ny, nz), s.wx[a] * s.wy[b], stencil_axis_offset(s, 0, a, dx),
            stencil_axis_offset(s, 1, b, dx))


@njit(cache=True, inline="always")
def stencil_offset(s, a, b, c, dx):
    """x_i - x_p of the stencil's node (a, b, c), m, on a grid of cell size ``dx``."""
    return stencil_axis_offset(s, 0, a, dx), stencil_axis_offset(s, 1, b, dx), stencil_axis_offset(s, 2, c, dx)
