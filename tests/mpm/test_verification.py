"""Physics verification of the MPM solver: Hertz, Tabor, ploughing without interface shear against the analytical
mu_pl, energy balance, mirror symmetry, inertia (issues 3 and 32).

Slow runs (a few seconds to ~20 s each); the numbers they check are reported in docs/verification.md.
"""

from __future__ import annotations

import json
import math
from dataclasses import replace
from pathlib import Path

import pytest

from plough.analytical import ploughing
from plough.materials import ProportionalShear, representative_hardness
from plough.mpm import solver
from plough.mpm.indentation import (
    NU,
    PLASTIC_SETTLE_CROSSINGS,
    R_M,
    TABOR_HARDNESS_PA,
    contact_radius_from_particles,
    half_space_force,
    hertz_force,
    hertz_scene,
    hold_at_depth,
    section_radius,
    tabor_scene,
)
from plough.mpm.io import energy_balance
from plough.mpm.run import simulate
from plough.mpm.scene import CFL_MAX, Scene

pytestmark = [pytest.mark.slow, pytest.mark.usefixtures("two_threads")]


def indentation_force(h_um: float, depth_um: float, domain_um: float = 240.0, poisson_ratio: float = NU,
                      dilatation: str = "projected", contact_mode: str = "grid") -> float:
    """Full-body normal force on the sphere held at a depth (no sliding), elastic block."""
    run = hold_at_depth(hertz_scene(h_um, depth_um, domain_um, poisson_ratio, dilatation, contact_mode))
    assert run.state.particles.eps_p.max() == 0.0  # purely elastic
    return run.force_N


@pytest.mark.long  # 110 s (its h = 5 um hold): out of CI's 20 minutes; the h = 10 um half-space test stays
def test_hertz_indentation_error_shrinks_with_h():
    """F = 4/3 E* sqrt(R) d^1.5 for a rigid sphere on an elastic half-space (depth d = 2 um), the grid contact.

    Measured in the checks' block (radius 240 um, clamped; the hold settled, docs/journal/2026-12-02-hertz-block.md):
    +85.8% at h = 10 um, +29.3% at h = 5 um (with the earlier 300-step hold +89% / +34%, a transient). The block
    itself adds about 13% at this depth (half-space +64% / +15.0%): the contact acts on grid nodes up to one
    cell outside the sphere, an error of order h that halving h more than halves.
    """
    depth = 2e-6
    err = {h: indentation_force(h, depth * 1e6, contact_mode="grid") / hertz_force(depth) - 1.0 for h in (10.0, 5.0)}
    assert err[10.0] > err[5.0] > 0.0
    assert err[5.0] < 0.5 * err[10.0]


@pytest.mark.parametrize(("contact_mode", "depth_um", "measured"), [("grid_local", 2.0, 0.010), ("grid", 8.0, 0.097)])
def test_contact_meets_the_hertz_target_at_h10_in_a_half_space(contact_mode, depth_um, measured):
    """Issue 32's Hertz target at h = 10 um (within 25%) against the half-space Hertz's formula is for: the block is
    clamped on its curved face, which stiffens it in proportion to a / L, so the force is measured in blocks of
    radius 160 and 320 um and extrapolated in 1 / L (indentation.half_space_force).

    ``grid_local`` (the default), 2 um deep, where the contact is a cell wide: +17.7% / +9.3% in the two blocks, the
    half-space +0.95% (A = 1.33 sqrt(R d); docs/journal/2026-12-04-contact-switch.md); from 240 and 480 um blocks
    +0.1% (benchmarks/contact_candidates.py hertz --domains-um 240 480), +1.9% at h = 5 um. 8 um deep: +1.8%.
    ``grid`` (the default until 2026-12-04), 8 um deep: +51.9% / +30.8%, the half-space +9.7% (A = 61.6 um); from
    240 and 480 um blocks +9.3%, +5.0% at h = 5 um; 2 um deep +57% (docs/journal/2026-12-04-contact-bbar.md).
    Asserted: both settled and elastic, the block's stiffening of order one, the target and the number reached."""
    depth = depth_um * 1e-6
    hs = half_space_force(lambda domain_um: hertz_scene(10.0, depth_um, domain_um=domain_um, contact_mode=contact_mode),
                          (160.0, 320.0))
    small, large = hs.runs
    for run in hs.runs:
        assert run.state.particles.eps_p.max() == 0.0  # purely elastic
        assert abs(run.force_drift) < 0.02  # settled: the last window within 2% of the one before
    assert small.force_N > large.force_N > hs.force_N  # the clamped block stiffens, the less the larger it is
    assert 0.5 < hs.stiffening_m / math.sqrt(R_M * depth) < 3.0  # first order in a / L, of order one
    error = hs.force_N / hertz_force(depth) - 1.0
    assert abs(error) < 0.25
    assert error == pytest.approx(measured, abs=0.02)


@pytest.mark.long  # 22 s, the non-default contact: out of CI's 20 minutes (the default's Hertz test stays)
def test_particle_contact_stays_outside_the_sphere_in_hertz_at_h10():
    """The particle contact (discretisation.contact: particle) acts where the sphere is. In the checks' 240 um block,
    held, at the solver's 4 Gauss-Seidel sweeps its force falls as its particles creep into the sphere (8 um: +25%
    to +12% over 96 P-wave crossings, the closest centre 0.48 h -> 0.26 h; docs/journal/2026-12-02-hertz-block.md);
    this hold measures +10.1% / +18.9% at 2 / 8 um, drifting -1% / -2% a window (benchmarks/contact_candidates.py
    hertz). At 20 sweeps it holds: +15.7% / +24.6% in this block, +4.1% / +2.9% in the half-space. Asserted in this
    block, at 4 sweeps: the error within 20% / 25% and positive (the block alone adds 13-25%), and no particle
    centre inside the sphere."""
    for depth_um, bound in ((2.0, 0.20), (8.0, 0.25)):
        run = hold_at_depth(hertz_scene(10.0, depth_um, contact_mode="particle"))
        err = run.force_N / hertz_force(depth_um * 1e-6) - 1.0
        assert 0.0 < err < bound, (depth_um, err)
        assert run.closest_centre_m > 0.0


def test_projected_dilatation_removes_volumetric_locking_in_hertz_contact():
    """Hertz holds for any Poisson ratio; a locking discretisation gets stiffer as nu -> 0.5.

    In a clamped block the force grows with nu beyond Hertz's E* = E / (1 - nu^2) too (an incompressible layer on a
    rigid base is stiffer), so only the two dilatations' changes are compared, in one block. Measured at h = 10 um,
    depth 2 um, settled (the hold of a nearly incompressible block lasts 22 times longer: its shear waves are that
    much slower; docs/journal/2026-12-02-hertz-block.md), the change of the error from nu = 0.3 to 0.499: block of
    radius 120 um (this test) local +1.20, projected +0.26; 240 um local +0.69, projected +0.16 (the earlier
    300-step hold gave +0.51 / +0.02: a transient). The projected dilatation takes away three quarters of it.
    """
    depth = 2e-6

    def error(nu: float, dilatation: str) -> float:
        return indentation_force(10.0, depth * 1e6, domain_um=120.0, poisson_ratio=nu,
                                 dilatation=dilatation) / hertz_force(depth, poisson_ratio=nu) - 1.0

    local = error(0.499, "local") - error(0.3, "local")
    projected = error(0.499, "projected") - error(0.3, "projected")
    assert local > 0.5  # the check can see locking
    assert 0.0 < projected < 0.35 * local


@pytest.mark.parametrize(("contact_mode", "pressure", "pile_up"), [("grid_local", 1.814, 1.296), ("grid", 3.305, 1.15)])
def test_tabor_indentation_at_h10(contact_mode, pressure, pile_up):
    """Fully plastic static indentation (issue 32, item 4): the sphere pressed quasi-statically
    (indentation.QUASI_STATIC_PRESS_FRACTION) and held 8 um deep (PLASTIC_SETTLE_CROSSINGS) in the uncoated
    rigid-plastic block (sigma_y = 300 MPa, E a / (sigma_y R) ~ 200), h = 10 um; the mean pressure over the true
    contact (pile-up included, where the particles' faces leave the sphere, radius a_c) against Tabor's 2.8-3.0
    sigma_y (the issue's target 2.6-3.3), and a_c over the sphere's section at the original surface (56.0 um).
    Measured (docs/verification.md, the Tabor row): ``grid_local`` (the default) F = 9.01 N, a_c = 72.6 um,
    1.814 sigma_y (target missed; 2.18 / 2.21 at h = 5 um, docs/journal/2026-12-04-contact-bbar.md); ``grid``
    F = 12.96 N, a_c = 64.5 um, 3.305 sigma_y (missed by 0.2%; its force spread over nodes up to a cell outside the
    sphere; 2.57 at h = 5 um). Pressed at the scenes' default speed the grid's held force was 8.2 N (1.92 sigma_y):
    the plastic zone overshoots when the press stops (docs/journal/2026-12-03-tabor.md). Asserted: the number
    reached, a settled hold, and the pile-up's size (a_c / a_section)."""
    depth = 8e-6
    run = hold_at_depth(tabor_scene(10.0, depth * 1e6, contact_mode=contact_mode),
                        settle_crossings=PLASTIC_SETTLE_CROSSINGS)
    sigma_y = TABOR_HARDNESS_PA / 3.0
    a_c = contact_radius_from_particles(run.state, run.const)
    a_section = section_radius(depth)
    assert run.state.particles.eps_p.max() > 0.01  # fully plastic under the sphere
    assert abs(run.force_drift) < 0.02  # settled
    assert run.force_N / (math.pi * a_c**2) / sigma_y == pytest.approx(pressure, abs=0.03)
    assert a_c / a_section == pytest.approx(pile_up, abs=0.03)


def _workflow_example(name: str, h_um: float, f: float, contact_mode: str) -> Scene:
    """An example scene with the workflow's numerics as benchmarks/common.py gives them (graded, fine zone 1.5
    contact radii, active zone 4, sized block), interface factor f, the contact ``contact_mode``."""
    base = Scene.from_yaml(Path(__file__).resolve().parents[2] / "examples" / f"{name}_rigid_plastic.yaml")
    disc = replace(base.discretisation, particle_size_m=h_um * 1e-6, graded=True, fine_zone_contact_radii=1.5,
                   active_zone_contact_radii=4.0, contact=contact_mode)
    return replace(base, interface=ProportionalShear(f=f), discretisation=disc).with_sized_domain()


@pytest.mark.parametrize(("name", "contact_mode", "measured"), [("coated", "grid", -0.102),
                                                                  ("coated", "grid_local", -0.278),
                                                                  ("uncoated", "particle", -0.064),
                                                                  ("uncoated", "grid_local", 0.028)])
def test_ploughing_without_interface_shear_gives_the_analytical_mu_pl_at_h10(name, contact_mode, measured):
    """f = 0 against the analytical mu_pl at h = 10 um (issue 32's target: within 5%, not met since the pressure is
    projected with the dilatation). Measured (benchmarks/contact_candidates.py plough --f 0; docs/verification.md,
    the f = 0 row): coated scene (H~ = 0.5, t = 25 um), grid contact, mu 0.1283 against 0.1429 (-10.2%; -0.8%
    while the scheme made energy, docs/journal/2026-12-03-consistent-pressure.md); uncoated scene (900 MPa),
    particle contact, -6.4% (-1.1% before); ``grid_local`` (the default, the gap on the node's ray), uncoated mu
    0.1022 against 0.0994 (+2.8%, issue 32's target met), coated 0.1033 (-27.8%; -20% / -3.1% at h = 5 / 2.5 um,
    converging from below; docs/journal/2026-12-04-contact-bbar.md). The uncoated scene with the grid contact: +20%,
    not asserted here. Asserted: no interface shear, and the number reached."""
    scene = _workflow_example(name, 10.0, 0.0, contact_mode)
    layers = scene.layers
    hs = representative_hardness(layers.substrate)  # 3 sigma_y: the Table-2 hardness of a constant flow stress
    hc = representative_hardness(layers.coating) if layers.coated else hs
    mu_pl = float(ploughing(scene.load_N, scene.sphere.radius_m, layers.coating_thickness_m, hc, hs, f=0.0).mu_pl)
    ds = simulate(scene, progress=False)
    error = float(ds.mu) / mu_pl - 1.0
    assert float(ds.mu_sh) == 0.0
    assert error == pytest.approx(measured, abs=0.02)


@pytest.mark.long  # 50 s, four runs: out of CI's 20 minutes
def test_grid_contact_area_grows_under_interface_shear_and_grid_local_does_not():
    """Issue 32, item 2: the grid contact's area grows under interface shear (uncoated scene, h = 10 um: 4,623 um^2
    at f = 0, 6,573 at f = 1, mu_sh 2.0x the analytical), because a node may close only the gap of the closest
    particle of its whole stencil. With the gap of the closest particle on its own ray (``grid_local``) the area does
    not grow (4,002 / 4,116 um^2) and mu_sh is 1.24x the analytical value (docs/journal/2026-12-04-contact-bbar.md;
    3,822 / 3,841 um^2 and 1.16x before the pressure was projected, docs/journal/2026-12-03-grid-local.md).
    Asserted: the grid contact's area at least 1.2x larger at f = 1, the local contact's unchanged by f within 5%
    and its mu_sh within 25% of the analytical tau Axy / Fn."""
    scenes = {(mode, f): _workflow_example("uncoated", 10.0, f, mode) for mode in ("grid", "grid_local")
              for f in (0.0, 1.0)}
    runs = {key: simulate(scene, progress=False) for key, scene in scenes.items()}
    area = {key: float(ds.contact_area_xy[ds.contact_area_xy.size // 2:].mean()) for key, ds in runs.items()}
    scene = scenes["grid_local", 1.0]
    hs = representative_hardness(scene.layers.substrate)
    mu_sh = float(ploughing(scene.load_N, scene.sphere.radius_m, 0.0, hs, hs, f=1.0).mu_sh)
    assert float(runs["grid_local", 0.0].mu_sh) == 0.0
    assert area["grid", 1.0] / area["grid", 0.0] > 1.2, area
    assert abs(area["grid_local", 1.0] / area["grid_local", 0.0] - 1.0) < 0.05, area
    assert abs(float(runs["grid_local", 1.0].mu_sh) / mu_sh - 1.0) < 0.25, float(runs["grid_local", 1.0].mu_sh)


def test_grid_local_contact_does_not_depend_on_the_lattice_phase():
    """Where the sphere starts against the particle lattice has no physical meaning. With the gap taken on each
    node's ray (``grid_local``) the steady state does not remember it: on the coated scene at f = 1 and h = 10 um,
    four starts a quarter particle apart gave mu 0.2522-0.2523 and dp 3.834-3.836 um, where the grid contact gave
    0.488-0.508 and 5.45-5.90 um (docs/journal/2026-12-04-contact-bbar.md). At h = 20 um two starts half a particle
    apart give 0.2905 / 0.2916 and 1.507 / 1.508 um (the grid 0.563 / 0.569, 4.55 / 4.81 um). Asserted at h = 10 um,
    starts half a particle apart (the block lengthened by one particle size, as benchmarks/lattice_phase.py does):
    mu and dp within 0.2% of each other (measured 0.01% and 0.03%; one run of the grid contact moves 1.8% / 3.6%)."""
    h_um = 10.0
    base = _workflow_example("coated", h_um, 1.0, "grid_local")
    shifted = replace(base, domain=replace(base.domain, length_m=base.domain.length_m + h_um * 1e-6))
    a, b = (simulate(scene, progress=False) for scene in (base, shifted))
    assert shifted.start_x_m != base.start_x_m
    assert float(b.mu) == pytest.approx(float(a.mu), rel=0.002)
    assert float(b.dp) == pytest.approx(float(a.dp), rel=0.002)
    # each run's groove error carries grid_local's lattice-phase term, 0.002 h (plough.mpm.io.
    # GROOVE_LATTICE_PHASE_ERROR_H; the grid's is 0.1 h), and here the jackknife over the sections alone, without
    # it, already covers the shift
    term = 0.002 * h_um * 1e-6
    assert float(a.dp_standard_error.attrs["lattice_phase_term_m"]) == pytest.approx(term, rel=1e-12)
    jackknife = [math.sqrt(max(float(r.dp_standard_error) ** 2 - term**2, 0.0)) for r in (a, b)]
    assert abs(float(b.dp) - float(a.dp)) <= math.hypot(*jackknife)


def tiny_sliding_scene(symmetric: bool, graded: bool = False) -> Scene:
    return Scene.from_dict({
        "name": "sym", "load_N": 1.0, "sphere": {"radius_um": 200},
        "layers": {"substrate": {"rigid_plastic_hardness_MPa": 900}},
        "interface": {"model": "proportional", "f": 1.0},
        # graded: a wider block, so that 2 h particles exist outside the 6 h fine zone
        # a 100 um slide: half and full domains agree to 0.02% (mu) and 0.3% (dp) (0.06% / 0.3% over 200 um),
        # in 40% of the time
        "domain": {"radius_um": 110 if graded else 80, "length_um": 300, "symmetric": symmetric},
        "sliding": {"distance_um": 100, "speed_m_s": 0.1, "experiment_speed_m_s": 0.001},
        "discretisation": {"particle_size_um": 10, "particles_per_cell": 2, "cfl": 0.3, "mass_scaling": 1.0e6,
                           "graded": graded, "fine_zone_contact_radii": 1.0},
        "outputs": {"steady_window": [0.5, 1.0], "records": 40},
    })


@pytest.fixture(scope="module", params=[False, True], ids=["uniform", "graded"])
def half_and_full(request):
    """Half (mirror plane) and full domain of the tiny scene, with uniform or graded particles (the
    2 h particles lie on one side of y = 0, so the mirror fold stays exact)."""
    return (simulate(tiny_sliding_scene(True, request.param), progress=False),
            simulate(tiny_sliding_scene(False, request.param), progress=False))


def test_mirror_symmetry_half_and_full_domain_agree(half_and_full):
    half, full = half_and_full
    assert full.attrs["cost_particles"] == 2 * half.attrs["cost_particles"]
    if json.loads(half.attrs["scene"])["discretisation"]["graded"]:  # the far field is coarse
        scene = tiny_sliding_scene(True, True)
        uniform_scene = replace(scene, discretisation=replace(scene.discretisation, graded=False))
        uniform = solver.init(uniform_scene, n_chunks=1)[0].particles.n
        assert half.attrs["cost_particles"] < 0.8 * uniform
    assert float(half.mu) == pytest.approx(float(full.mu), rel=0.01)
    assert float(half.dp) == pytest.approx(float(full.dp), rel=0.01)
    # the full body carries no net lateral force
    assert abs(float(full.Fy[full.in_steady_window].mean())) < 0.01 * float(full.Fz_mean)


def test_energy_balance(half_and_full):
    """External work = plastic + elastic + kinetic + interface slip + contact impact loss.

    Tolerance 10%: the terms are accumulated independently (grid impulses for the work and the
    two contact losses, particle stress power for the plastic and elastic parts), and the
    transfers and the projected dilatation move energy that no term counts, more at coarse sizes: the
    sum is 0.947 of the work on this scene (h = 10 um, 1 N, a 100 um slide) and 0.96-0.98 on the reference scenes at
    h = 10 um (docs/journal/2026-12-02-cfl.md). With the earlier impact loss (jn^2 / 2m, counting the
    velocity the step's internal force gave a pushed node again) it was 1.022 here.
    """
    for ds in half_and_full:
        assert float(ds.external_work[-1]) > 0
        assert energy_balance(ds) == pytest.approx(1.0, rel=0.10)


def test_energy_account_does_not_follow_the_time_step():
    """The contact's losses are powers at the end-of-step velocity (model.md, "Reaction"): the terms over the work
    are 0.968 / 0.957 / 0.950 at CFL 0.15 / 0.3 / 0.5 (CFL_MAX) on the tiny half scene (0.953 / 0.947 / 0.941 at
    0.15 / 0.3 / 0.6 before the pressure was projected with the dilatation). The earlier impact loss (1/2 m vn^2
    per pushed node, in a lasting contact the velocity the step's internal force gave it) made them 0.977 / 1.022 /
    1.112 at 0.15 / 0.3 / 0.6, a term proportional to the CFL number (docs/journal/2026-12-02-cfl.md)."""
    base = tiny_sliding_scene(True)
    ratios = []
    for cfl in (0.15, CFL_MAX):
        ds = simulate(replace(base, discretisation=replace(base.discretisation, cfl=cfl)), progress=False)
        ratios.append(energy_balance(ds))
    assert abs(ratios[1] - ratios[0]) < 0.03, ratios


def _coated_at(h_um: float, f: float, mass_scaling_factor: float = 1.0) -> Scene:
    base = Scene.from_yaml(Path(__file__).resolve().parents[2] / "examples" / "coated_rigid_plastic.yaml")
    disc = replace(base.discretisation, particle_size_m=h_um * 1e-6,
                   mass_scaling=base.discretisation.mass_scaling * mass_scaling_factor)
    return replace(base, interface=ProportionalShear(f=f), discretisation=disc).with_sized_domain()


@pytest.mark.long  # 12 min on the shared 2-core machine (three coated runs, one at a quarter of the mass scaling)
def test_inertia_moves_mu_less_than_the_discretisation_where_a_steady_state_exists():
    """Issue 3's inertia check at a size CI affords, below the wave limit (f = 0, the ploughing alone): on the
    coated scene at h = 10 um, mass scaling / 4 (the same numbers as speed / 2) moves mu by a small fraction
    of what halving h from 20 to 10 um does. Measured 2026-11-24
    (docs/journal/2026-11-24-inertia-check-below-the-wave-limit.md): mu 0.1429 -> 0.1438 (+0.6%) with mass
    scaling / 4, against 0.2194 at h = 20 um (+54%). (dp, about one particle deep at h = 10 um, is too noisy
    for a check at this size: 5.8 -> 12.1 um.) At f = 1, above the wave limit, mu has no limit to settle to
    (docs/journal/2026-11-24-inertia-ladder-and-wave-limit.md), which is why the check is made here."""
    scene = _coated_at(10.0, 0.0)
    assert not scene.interface_sticks
    mu = float(simulate(scene, progress=False)["mu"])
    slow = float(simulate(_coated_at(10.0, 0.0, 0.25), progress=False)["mu"])
    coarse = float(simulate(_coated_at(20.0, 0.0), progress=False)["mu"])
    assert abs(slow / mu - 1.0) < 0.25 * abs(coarse / mu - 1.0)
    assert abs(slow / mu - 1.0) < 0.03
