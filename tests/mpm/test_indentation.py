"""The static-indentation helpers of plough.mpm.indentation that need no run: the half-space extrapolation and the
settling time."""

from __future__ import annotations

import math

import pytest

from plough.mpm import solver
from plough.mpm.indentation import crossing_steps, half_space_extrapolation, hertz_scene


@pytest.mark.parametrize("domains_um", [(240.0, 480.0), (240.0, 480.0, 720.0), (300.0, 900.0, 500.0)])
def test_half_space_extrapolation_recovers_a_first_order_block_stiffening(domains_um):
    f_inf, a = 12.5, 55e-6  # N, m
    domains = [d * 1e-6 for d in domains_um]
    got_f, got_a = half_space_extrapolation(domains, [f_inf * (1.0 + a / L) for L in domains])
    assert got_f == pytest.approx(f_inf, rel=1e-12)
    assert got_a == pytest.approx(a, rel=1e-10)


def test_half_space_extrapolation_needs_two_block_sizes_and_a_force_for_each():
    with pytest.raises(ValueError, match="domains_m"):
        half_space_extrapolation([240e-6, 240e-6], [1.0, 1.1])
    with pytest.raises(ValueError, match="forces_N"):
        half_space_extrapolation([240e-6, 480e-6], [1.0])


def test_crossing_steps_is_the_block_radius_over_a_shear_waves_travel_a_step():
    # the solver's dt = cfl dx / (c_p + v_max): a P wave travels just under cfl dx a step, 240 um at cfl 0.3 and
    # dx = 2 h = 20 um in about 40 steps; a shear wave is slower by sqrt(G / (K + 4 G / 3)) = sqrt((1 - 2 nu) /
    # (2 (1 - nu))): about 75 steps at nu = 0.3, 895 at nu = 0.499
    for nu in (0.3, 0.499):
        scene = hertz_scene(10.0, 2.0, domain_um=240.0, poisson_ratio=nu)
        _, const = solver.init(scene)
        steps = crossing_steps(scene, const.dt)
        expected = 240e-6 / (0.3 * 20e-6) * math.sqrt(2.0 * (1.0 - nu) / (1.0 - 2.0 * nu))
        assert expected <= steps <= 1.05 * expected, (nu, steps, expected)
        assert crossing_steps(scene, 0.5 * const.dt) in (2 * steps - 1, 2 * steps)
