"""Tests of plough.mpm.shape: quadratic B-spline weights and their gradients.

The expected values come from the closed-form quadratic B-spline N(r) of the node offset
r = x - node (written here independently of the kernels), from the reproducing properties
(partition of unity, linear completeness, second moment dx^2/4 behind the APIC factor D^-1 = 4/dx^2)
and from finite differences.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from plough.mpm.shape import APIC_D_INV_FACTOR, bspline2, bspline2_grad

RNG = np.random.default_rng(20240611)
XS = np.concatenate([RNG.uniform(-40.0, 40.0, 400), RNG.uniform(0.0, 1.0, 100),
                     [0.0, 0.5, 1.0, 1.5, -0.5, 2.5, 7.0, 7.5, 1e-9, 0.5 - 1e-12]])


def n_exact(r: float) -> float:
    """Quadratic B-spline kernel of the node offset r (grid units)."""
    a = abs(r)
    if a < 0.5:
        return 0.75 - a * a
    if a < 1.5:
        return 0.5 * (1.5 - a) ** 2
    return 0.0


def dn_exact(r: float) -> float:
    """d N / d r."""
    a = abs(r)
    if a < 0.5:
        return -2.0 * r
    if a < 1.5:
        return -math.copysign(1.5 - a, r)
    return 0.0


def nodal_weights(x: float) -> dict[int, float]:
    base, w0, w1, w2 = bspline2(x)
    return {base: w0, base + 1: w1, base + 2: w2}


def nodal_grads(x: float) -> dict[int, float]:
    base, g0, g1, g2 = bspline2_grad(x)
    return {base: g0, base + 1: g1, base + 2: g2}


def test_weights_match_closed_form_kernel():
    for x in XS:
        base, *w = bspline2(x)
        assert isinstance(base, int)
        # the stencil is the 3 nodes nearest x: x lies in [base + 0.5, base + 1.5)
        assert base + 0.5 <= x < base + 1.5
        for a in range(3):
            assert w[a] == pytest.approx(n_exact(x - (base + a)), abs=1e-14)


def test_partition_of_unity_and_nonnegative():
    for x in XS:
        _, *w = bspline2(x)
        assert min(w) >= 0.0
        assert sum(w) == pytest.approx(1.0, abs=1e-14)


def test_linear_completeness_and_second_moment():
    """sum w_i x_i = x (linear fields reproduced) and sum w_i (x_i - x)^2 = 1/4 (APIC D = dx^2/4)."""
    for x in XS:
        base, *w = bspline2(x)
        nodes = [base, base + 1, base + 2]
        assert sum(wi * xi for wi, xi in zip(w, nodes, strict=True)) == pytest.approx(x, abs=1e-12)
        second = sum(wi * (xi - x) ** 2 for wi, xi in zip(w, nodes, strict=True))
        assert second == pytest.approx(1.0 / APIC_D_INV_FACTOR, abs=1e-12)


def test_gradients_sum_to_zero_and_reproduce_unit_slope():
    for x in XS:
        base, *g = bspline2_grad(x)
        assert base == bspline2(x)[0]
        assert sum(g) == pytest.approx(0.0, abs=1e-13)
        # d/dx sum w_i x_i = 1
        assert sum(gi * (base + a) for a, gi in enumerate(g)) == pytest.approx(1.0, abs=1e-12)
        for a in range(3):
            assert g[a] == pytest.approx(dn_exact(x - (base + a)), abs=1e-13)


def test_gradient_is_finite_difference_of_weights():
    """Central differences of the nodal weights (by node index, so valid across a base change)."""
    eps = 1e-6
    xs = np.concatenate([RNG.uniform(-20.0, 20.0, 200), np.arange(-3, 4) + 0.5 + 0.3 * eps])
    for x in xs:
        grads = nodal_grads(x)
        wp, wm = nodal_weights(x + eps), nodal_weights(x - eps)
        for node, g in grads.items():
            fd = (wp.get(node, 0.0) - wm.get(node, 0.0)) / (2 * eps)
            assert g == pytest.approx(fd, abs=2e-6), (x, node)  # O(eps) error at a kink of w''


@pytest.mark.parametrize("k", [-7, -1, 0, 1, 4, 13])
def test_c1_continuity_across_cell_boundary(k):
    """At x = k + 1/2 the stencil shifts by one node; weights and slopes of every node stay continuous."""
    eps = 1e-10
    left, right = k + 0.5 - eps, k + 0.5 + eps
    assert bspline2(left)[0] == k - 1
    assert bspline2(right)[0] == k
    wl, wr = nodal_weights(left), nodal_weights(right)
    gl, gr = nodal_grads(left), nodal_grads(right)
    for node in set(wl) | set(wr):
        assert wl.get(node, 0.0) == pytest.approx(wr.get(node, 0.0), abs=1e-9)
        assert gl.get(node, 0.0) == pytest.approx(gr.get(node, 0.0), abs=1e-9)
    # the node leaving / entering the stencil does so with zero weight and zero slope (C1)
    assert wl[k - 1] == pytest.approx(0.0, abs=1e-9) and gl[k - 1] == pytest.approx(0.0, abs=1e-9)
    assert wr[k + 2] == pytest.approx(0.0, abs=1e-9) and gr[k + 2] == pytest.approx(0.0, abs=1e-9)
    # and the values at the boundary are the kernel's: 1/2, 1/2 with slopes -1, +1
    assert wr[k] == pytest.approx(0.5) and wr[k + 1] == pytest.approx(0.5)
    assert gr[k] == pytest.approx(-1.0) and gr[k + 1] == pytest.approx(1.0)
