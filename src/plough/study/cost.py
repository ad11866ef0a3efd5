"""What an MPM run will cost before it runs: particles, time steps, memory and wall time.

Used for cluster resources (``mem_mb``, ``runtime`` of the Slurm profile) and to project the
time of the full reproduction from a measured throughput. The counts follow the solver:
particles fill the half cylinder below z = 0 (a quarter with the mirror plane) on an h lattice
(graded scenes: times the count ratio of one slice of the block);
dt = CFL * dx / (c + 2 v) with c the mass-scaled P-wave speed of the stiffest layer; the sphere
presses at
``press_speed_fraction * v`` to about the expected ploughing depth, settles, then slides. With an
active zone (``discretisation.active_zone_contact_radii``) a step works on the particles within
the zone only: ``active_fraction`` is the mean share of the block's length the zone covers over
the run's steps (the particles are spread evenly along x).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

from plough.mpm.grid import make_grid
from plough.mpm.particles import particle_count_ratio, uniform_particle_count
from plough.mpm.scene import Scene

#: Bytes per particle: the state (about 250 B) and the scratch, rounded up; with the grid of a uniform
#: run at 2 particles per cell and 2 threads the measured peak RSS of the reference scene is below it.
BYTES_PER_PARTICLE = 400
#: Bytes a grid node holds besides the per-thread P2G copies (plough.mpm.solver.Work: mass, 6 velocities,
#: dilatation, 12 contact sums and the held traction, last push, flags), and per thread (the P2G copy: 7 float64
#: channels).
#: Counted apart because graded runs with a shallow fine zone have 0.2-0.25 of the uniform particle count on
#: the same grid, and a cluster job's 8 threads multiply the copies.
GRID_BYTES_PER_NODE = 177
GRID_BYTES_PER_NODE_PER_THREAD = 56
#: the threads a memory request allows for: the cluster profile's 8 (this machine runs 2)
REQUEST_THREADS = 8
BASE_MEMORY_MB = 600  # interpreter, numba, xarray
SETTLE_STEPS = 300


@dataclass(frozen=True)
class RunCost:
    particles: int
    steps: int
    active_fraction: float = 1.0  # mean share of the particles a step works on
    grid_nodes: int = 0  # the grid's nodes at the start (it may grow mid-run: not counted)

    @property
    def particle_steps(self) -> float:
        """Particle updates of the run: what its wall time follows."""
        return float(self.particles) * self.steps * self.active_fraction

    @property
    def memory_mb(self) -> int:
        grid = self.grid_nodes * (GRID_BYTES_PER_NODE + REQUEST_THREADS * GRID_BYTES_PER_NODE_PER_THREAD)
        return int(BASE_MEMORY_MB + (self.particles * BYTES_PER_PARTICLE + grid) / 1e6)


def wave_speed_m_s(scene: Scene) -> float:
    c = 0.0
    for m in scene.layers.materials:
        E, nu = m.youngs_modulus_Pa, m.poisson_ratio
        K, G = E / (3 * (1 - 2 * nu)), E / (2 * (1 + nu))
        c = max(c, math.sqrt((K + 4 * G / 3) / (scene.discretisation.mass_scaling * m.density_kg_m3)))
    return c


def estimate(scene: Scene) -> RunCost:
    """Particles and steps of a run of ``scene`` (within a few per cent of the solver's)."""
    dom = scene.domain
    particles = int(uniform_particle_count(scene) * particle_count_ratio(scene))
    v = scene.sliding.speed_m_s
    dt = scene.discretisation.cfl * scene.discretisation.cell_size_m / (wave_speed_m_s(scene) + 2 * v)
    _, dp = scene.expected_contact()
    press = dp / (scene.sliding.press_speed_fraction * v) / dt
    slide = scene.sliding.distance_m / v / dt
    fraction = 1.0
    half_width = scene.active_zone_half_width_m
    if half_width is not None:
        fraction = active_fraction(scene.start_x_m, scene.sliding.distance_m, dom.length_m, half_width,
                                   press + SETTLE_STEPS, slide)
    grid = make_grid(dom.length_m, dom.radius_m, dom.symmetric, scene.discretisation.cell_size_m,
                     scene.grid_headroom_m)
    return RunCost(particles=particles, steps=int(press + SETTLE_STEPS + slide), active_fraction=fraction,
                   grid_nodes=grid.n_nodes)


def active_fraction(start_m: float, slide_m: float, length_m: float, half_width_m: float, steps_in_place: float,
                    steps_sliding: float, samples: int = 400) -> float:
    """Mean share of the block [0, length] inside the zone [x - w, x + w] over a run whose sphere
    stays at ``start`` for ``steps_in_place`` steps and then moves evenly to ``start + slide``."""
    def share(x: float) -> float:
        return (min(x + half_width_m, length_m) - max(x - half_width_m, 0.0)) / length_m

    sliding = sum(share(start_m + slide_m * (i + 0.5) / samples) for i in range(samples)) / samples
    return (steps_in_place * share(start_m) + steps_sliding * sliding) / (steps_in_place + steps_sliding)


#: Particle-steps per second per thread for cluster run-time requests: the slowest aggregate rate
#: measured for workflow jobs, the preview's 70 rigid-plastic runs as Snakemake jobs on 2 threads
#: (1.45 M/s; its 64 real-material runs 1.67 M/s; benchmarks/results/projection_check_preview.json).
#: The reference scene's 4.6 M/s on 2 threads let a job's request fall short of its run. Scaling to
#: more threads is taken as linear, which the request's safety factor has to cover; the fixed 5 min
#: covers the start-up of small runs.
THROUGHPUT_PER_THREAD = 0.72e6


def runtime_minutes(cost: RunCost, threads: int, safety: float = 2.0) -> int:
    """A wall-time request for a cluster job: the projected time times ``safety``, plus 5 min."""
    return int(math.ceil(safety * cost.particle_steps / (THROUGHPUT_PER_THREAD * threads) / 60.0)) + 5
