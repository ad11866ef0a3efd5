"""Quadratic B-spline shape functions (model.md section 2).

Chosen over linear hat functions because they are C1: a particle crossing a cell face sees a
continuous force, so there is no cell-crossing noise in the quasi-static contact force. Their
support is 3 nodes per direction (27 in 3D). With x in units of the cell size and
base = floor(x - 0.5), fx = x - base in [0.5, 1.5):

    w0 = 0.5 (1.5 - fx)^2,  w1 = 0.75 - (fx - 1)^2,  w2 = 0.5 (fx - 0.5)^2

and the derivatives with respect to x are fx - 1.5, -2 (fx - 1), fx - 0.5. The weights sum
to 1 and reproduce linear functions exactly; the APIC/MLS inertia matrix is D = dx^2/4 I.
"""

from __future__ import annotations

import math

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
