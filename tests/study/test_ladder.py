"""The particle sizes of each MPM point (plough.study.matrix.point_ladder): the paper's ladder and the relative one.

The relative ladder's sizes are checked against the targets directly (the expected contact radius and groove
depth of the analytical model, the coating thickness), and the default config against issue 34's budget.
"""

from __future__ import annotations

import copy
import math
from pathlib import Path

import jsonschema
import pytest
import yaml

from plough.mpm.scene import Scene, expected_contact
from plough.study import cost, matrix

ROOT = Path(__file__).resolve().parents[2]
SCHEMA = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())


def _load(name: str) -> dict:
    return yaml.safe_load((ROOT / "config" / f"{name}.yaml").read_text())


CONFIG = _load("config")


def _relative(targets: dict) -> dict:
    config = copy.deepcopy(CONFIG)
    config["mpm"]["ladder"] = "relative"
    config["mpm"]["ladder_targets"] = targets
    return config


def _lengths_um(point: matrix.Point) -> tuple[float, float, float]:
    a, dp = expected_contact(point.layers(), point.load_N, point.radius_m)
    return a * 1e6, dp * 1e6, point.thickness_m * 1e6


def test_the_paper_ladder_runs_every_point_at_the_configs_sizes():
    paper = _load("paper")
    assert paper["mpm"]["ladder"] == "paper" and paper["mpm"]["skip_finest_tolerance"] is None
    sizes = tuple(sorted((float(h) for h in paper["mpm"]["particle_sizes_um"]), reverse=True))
    assert sizes == (10.0, 5.0, 2.5)
    for p in matrix.all_points(paper).values():
        lad = matrix.point_ladder(paper, p)
        assert lad.sizes_um == sizes and lad.scale == 1.0 and lad.set_by == "paper"
    # without the key: the paper's ladder (the preview and smoke configs set it, as a merge over config.yaml needs)
    plain = copy.deepcopy(paper)
    del plain["mpm"]["ladder"]
    assert matrix.all_runs(plain) == matrix.all_runs(paper)
    for name in ("preview", "smoke"):
        assert _load(name)["mpm"]["ladder"] == "paper"


def test_paper_yaml_is_config_yaml_with_the_papers_ladder():
    """config/paper.yaml follows the study matrix of config/config.yaml: only the ladder differs, and every size
    of every point runs (no refinement only where needed)."""
    paper, same = _load("paper"), copy.deepcopy(CONFIG)
    same["mpm"]["ladder"] = "paper"
    del same["mpm"]["ladder_targets"], same["mpm"]["ladder_sizes_per_octave"]
    assert CONFIG["mpm"]["skip_finest_tolerance"] is not None  # on by default
    same["mpm"]["skip_finest_tolerance"] = None
    assert paper == same


@pytest.mark.parametrize("per_octave", [1, 2])
@pytest.mark.parametrize("targets", [
    {"contact_radius_particles": 12, "groove_depth_particles": 1, "coating_particles": 1.5},
    {"contact_radius_particles": 9, "groove_depth_particles": None, "coating_particles": None},
    {"contact_radius_particles": 20, "groove_depth_particles": 3, "coating_particles": 4},
])
def test_the_relative_ladder_is_the_coarsest_that_meets_its_targets(targets, per_octave):
    """Each point's finest size is the coarsest of the sizes it may take (the config's 2.5 um times a power of
    two; with two sizes an octave also 3.5 um times one) at which its targets hold, and its sizes keep the
    config's ratios."""
    config = _relative(targets)
    config["mpm"]["ladder_sizes_per_octave"] = per_octave
    paper = matrix.particle_sizes_um(config)
    finest_paper = paper[-1]
    allowed = sorted(b * 2.0 ** k for k in range(-4, 8) for b in ((2.5,) if per_octave == 1 else (2.5, 3.5)))
    na, nd, nt = (targets[k] for k in matrix.LADDER_TARGETS)
    finest_sizes = set()
    for p in matrix.all_points(config).values():
        lad = matrix.point_ladder(config, p)
        a, dp, t = _lengths_um(p)
        assert lad.contact_radius_um == pytest.approx(a) and lad.groove_depth_um == pytest.approx(dp)
        h = lad.finest_um
        assert any(h == pytest.approx(size, rel=1e-12) for size in allowed), (p.key, h)
        assert lad.sizes_um == pytest.approx(tuple(x * h / finest_paper for x in paper), rel=1e-12), p.key
        assert lad.scale == pytest.approx(h / finest_paper, rel=1e-12)
        finest_sizes.add(h)

        def meets(size: float, a: float = a, dp: float = dp, t: float = t) -> bool:
            """The targets at a finest size; groove and coating down to the config's finest size only."""
            ok = a / size >= na * (1 - 1e-9)
            if nd is not None and size > finest_paper:
                ok &= dp / size >= nd * (1 - 1e-9)
            if nt is not None and t > 0 and size > finest_paper:
                ok &= t / size >= nt * (1 - 1e-9)
            return ok

        assert meets(h), (p.key, lad)
        assert not meets(min(size for size in allowed if size > h * (1 + 1e-9))), (p.key, lad)  # the coarsest
        if nd is not None and h < finest_paper * (1 - 1e-9):
            assert dp / h >= nd or lad.set_by == "contact_radius_particles"
    assert (per_octave == 2) == any(math.log2(h / 3.5).is_integer() for h in finest_sizes)  # both kinds taken


def test_half_octave_sizes_are_exact_and_a_bad_choice_is_refused():
    """The half-octave size of 2.5 um is 3.5 um (sqrt(2) x 2.5 to two digits), and a point's sizes are what their
    ids spell, also where a scaled size is not exact in binary (a config of 5, 2.5, 1.25 um: 14.399999999999999
    unrounded); any other ladder_sizes_per_octave is refused by the schema and by the matrix, naming the key, the
    value and the allowed values."""
    assert matrix.half_octave_um(2.5) == 3.5 and matrix.half_octave_um(10.0) == 14.0
    ladders = [matrix.point_ladder(CONFIG, p) for p in matrix.all_points(CONFIG).values()]
    assert any(lad.finest_um in (1.75, 3.5, 7.0, 14.0) for lad in ladders)
    for lad in ladders:
        assert all(float(matrix.fmt(h)) == h for h in lad.sizes_um), lad
    fine = copy.deepcopy(CONFIG)  # a finest size of 1.25 um: half-octave 1.8, whose products are not all exact
    fine["mpm"]["particle_sizes_um"] = [5, 2.5, 1.25]
    fine_ladders = [matrix.point_ladder(fine, p) for p in matrix.all_points(fine).values()]
    assert any(lad.finest_um in (0.9, 1.8, 3.6, 7.2, 14.4) for lad in fine_ladders)
    for lad in fine_ladders:
        assert all(float(matrix.fmt(h)) == h for h in lad.sizes_um), lad
    validator = jsonschema.Draft202012Validator(SCHEMA)
    for bad in (3, 0, True, 1.5):
        config = copy.deepcopy(CONFIG)
        config["mpm"]["ladder_sizes_per_octave"] = bad
        assert list(validator.iter_errors(config)), bad
        with pytest.raises(ValueError, match=r"mpm.ladder_sizes_per_octave = .* allowed: 1, 2"):
            matrix.all_runs(config)


#: the five accuracy-guard points of issue 34 (benchmarks/ladder_guard.py; docs/workflow.md, *The ladder*)
GUARD_POINTS = ("zinc_bulk_bl0.32-0.95_r500_F7", "zinc_bulk_bl0.32-0.95_r500_F11", "rp_Hc450_Hs900_t8_prop1_r200_F3",
                "rp_Hs450_t0_prop1_r200_F3", "zinc_coating-on-dx56_t15_bl0.32-0.95_r500_F4")


def test_a_paper_budget_keeps_the_papers_sizes_where_they_are_cheap():
    """mpm.ladder_paper_budget_particle_steps: a point the targets coarsen keeps the paper's sizes where they cost
    at most the budget (the cost model's particle-steps of its paper runs, summed); every other point is as
    without it. 1e10 holds the five guard points, whose paper ladders cost 4e9-9e9 particle-steps."""
    plain = copy.deepcopy(CONFIG)
    plain["mpm"]["ladder_paper_budget_particle_steps"] = None
    budget = 1e10
    config = copy.deepcopy(CONFIG)
    config["mpm"]["ladder_paper_budget_particle_steps"] = budget
    assert not list(jsonschema.Draft202012Validator(SCHEMA).iter_errors(config))
    paper_sizes = matrix.particle_sizes_um(config)
    numerics = config["mpm"]["numerics"]
    kept = 0
    for key, p in matrix.all_points(config).items():
        lad, without = matrix.point_ladder(config, p), matrix.point_ladder(plain, p)
        steps = sum(cost.estimate(matrix.scene_for(p, h, numerics)).particle_steps for h in paper_sizes)
        assert matrix.paper_ladder_particle_steps(p, paper_sizes, numerics) == pytest.approx(steps, rel=1e-12)
        if without.scale > 1.0 and steps <= budget:
            assert lad.sizes_um == paper_sizes and lad.scale == 1.0 and lad.set_by == "paper_budget", key
            kept += 1
        else:
            assert lad == without, key
        if key in GUARD_POINTS:
            assert without.scale > 1.0 and lad.set_by == "paper_budget", key
    assert kept == 22
    assert set(GUARD_POINTS) <= set(matrix.all_points(config))
    for bad in (0, -1.0, "many"):
        config["mpm"]["ladder_paper_budget_particle_steps"] = bad
        assert list(jsonschema.Draft202012Validator(SCHEMA).iter_errors(config)), bad


def test_the_default_config_within_issue_34s_budget_and_resolved_as_the_validated_scene():
    """config/config.yaml: at most 4e11 particle-steps counted by the cost model (the paper's ladder: 4.16e12),
    every point's finest contact at least as resolved as the rigid-plastic reference scene the paper validated
    at h = 5 um (a / h = 9.2), and the coarsest of its three sizes at a >= 3 h."""
    assert CONFIG["mpm"]["ladder"] == "relative"
    runs = matrix.all_runs(CONFIG)
    steps = sum(cost.estimate(Scene.from_dict(s)).particle_steps for s in runs.values())
    assert steps <= 4e11
    rp = CONFIG["mpm"]["rigid_plastic"]
    ts = rp["thickness_sweep"]
    reference = matrix.rigid_plastic_point(rp, 1.0, ts["soft"]["substrate_hardness_MPa"], 0, ts["interface"], 12.5)
    validated = _lengths_um(reference)[0] / 5.0
    assert validated == pytest.approx(9.2, abs=0.05)
    for p in matrix.all_points(CONFIG).values():
        lad = matrix.point_ladder(CONFIG, p)
        assert lad.contact_radius_um / lad.finest_um >= validated, p.key
        assert lad.contact_radius_um / lad.sizes_um[0] >= 3.0, p.key


def test_runs_of_the_two_ladders_at_the_same_size_are_one_run():
    relative, paper = matrix.all_runs(CONFIG), matrix.all_runs(_load("paper"))
    shared = set(relative) & set(paper)
    assert shared  # points whose relative ladder has a paper size
    assert all(relative[r] == paper[r] for r in shared)


def test_finest_sweep_runs_and_their_coarser_sizes_follow_each_point():
    finest = matrix.finest_sweep_runs(CONFIG)
    assert len(finest) == 60
    for rid, (coarse, middle) in finest.items():
        h_coarse, h_mid = matrix.coarser_sizes_um(CONFIG, rid)
        h = float(rid.rsplit("_h", 1)[1])
        assert (h_coarse, h_mid) == (4 * h, 2 * h)
        assert coarse.endswith(f"_h{matrix.fmt(h_coarse)}") and middle.endswith(f"_h{matrix.fmt(h_mid)}")
    with pytest.raises(ValueError, match="not the finest run"):
        matrix.coarser_sizes_um(CONFIG, next(iter(finest.values()))[0])


SEVEN_N_COATED = "zinc_coating-on-dx56_t15_bl0.32-0.95_r1500_F7"


def test_a_finest_size_the_groove_or_coating_target_set_is_never_gated():
    """Refinement only where needed stands in for a finest run only where the contact target set its size
    (the contact first where targets tie): a groove or coating target added that size because it judged the two
    above it too coarse (docs/workflow.md: at the 3 mm ball on coated steel at 7 N the 2.5 um run moved mu by
    -4.4% and dp by +25% from 5 um, the finest run 1.5 and 1.7 of the two-size bars from that limit). Such a
    run may still leave a failure marker; with the groove target dropped the 7 N point is the contact's again
    and gated; under the paper's ladder every finest sweep run is gated."""
    finest = matrix.finest_sweep_runs(CONFIG)
    skippable = matrix.skippable_runs(CONFIG)
    points = {matrix.run_id(p, matrix.point_ladder(CONFIG, p).finest_um): p
              for p in matrix.all_points(CONFIG, matrix.SWEEP_FIGURES).values()}
    set_by = {rid: matrix.point_ladder(CONFIG, points[rid]).set_by for rid in finest}
    assert {rid for rid, by in set_by.items() if by != "contact_radius_particles"} == set(finest) - set(skippable)
    assert {set_by[rid] for rid in set(finest) - set(skippable)} == {"groove_depth_particles", "coating_particles"}
    assert len(skippable) == 45 and set(matrix.failure_recordable_runs(CONFIG)) == set(finest)
    assert set(finest) - set(skippable) == {  # the groove set seven, the coating eight
        "dx56_bl1.34-0.88_r500_F4_h2.5", "zinc_bulk_bl0.32-0.95_r500_F4_h2.5",
        "rp_Hc450_Hs900_t4_prop1_r200_F3_h2.5", "rp_Hc900_Hs450_t4_prop1_r200_F3_h2.5",
        "zinc_coating-on-dx56_t15_bl0.32-0.95_r1500_F4_h2.5", "zinc_coating-on-dx56_t15_bl0.32-0.95_r1500_F7_h2.5",
        "zinc_coating-on-dx56_t15_bl0.32-0.95_r1500_F11_h3.5", "zinc_coating-on-dx56_t15_bl0.32-0.95_r1500_F22_h7",
        "zinc_coating-on-dx56_t15_bl0.32-0.95_r1500_F37_h10", "zinc_coating-on-dx56_t15_bl0.32-0.95_r1500_F46_h10",
        "zinc_coating-on-dx56_t15_bl0.32-0.95_r500_F37_h10", "zinc_coating-on-dx56_t15_bl0.32-0.95_r500_F46_h10",
        "rp_Hc450_Hs900_t2_prop1_r200_F3_h2.5", "rp_Hc900_Hs450_t2_prop1_r200_F3_h2.5",
        "zinc_coating-on-dx56_t10_bl0.32-0.95_r500_F22_h5"}
    seven = matrix.run_id(matrix.all_points(CONFIG)[SEVEN_N_COATED], 2.5)
    assert seven in finest and seven not in skippable
    no_groove = copy.deepcopy(CONFIG)
    no_groove["mpm"]["ladder_targets"]["groove_depth_particles"] = None
    seven_point = matrix.all_points(no_groove)[SEVEN_N_COATED]
    seven_coarse = matrix.point_ladder(no_groove, seven_point).finest_um
    assert seven_coarse > 2.5 and matrix.run_id(seven_point, seven_coarse) in matrix.skippable_runs(no_groove)
    paper = _load("paper")
    paper["mpm"]["skip_finest_tolerance"] = {"mu": 0.05, "dp": 0.3}
    assert matrix.skippable_runs(paper) == matrix.finest_sweep_runs(paper) != {}


def test_pictures_run_at_their_points_finest_size():
    for fig in matrix.SINGLE_RUN_FIGURES:
        for p, rid in zip(matrix.figure_points(CONFIG, fig).values(), matrix.figure_runs(CONFIG, fig), strict=True):
            assert rid == matrix.run_id(p, matrix.point_ladder(CONFIG, p).finest_um)


def test_the_schema_and_the_matrix_refuse_a_bad_ladder():
    validator = jsonschema.Draft202012Validator(SCHEMA)
    assert not list(validator.iter_errors(CONFIG))
    bad = copy.deepcopy(CONFIG)
    del bad["mpm"]["ladder_targets"]
    assert any("ladder_targets" in e.message for e in validator.iter_errors(bad))
    with pytest.raises(ValueError, match="ladder_targets"):
        matrix.all_runs(bad)
    for key, value in (("contact_radius_particles", 0), ("groove_depth_particles", -1), ("coating", 1)):
        bad = copy.deepcopy(CONFIG)
        bad["mpm"]["ladder_targets"][key] = value
        assert list(validator.iter_errors(bad)), key
    bad = copy.deepcopy(CONFIG)
    bad["mpm"]["ladder"] = "absolute"
    assert list(validator.iter_errors(bad))
    with pytest.raises(ValueError, match="mpm.ladder = 'absolute'"):
        matrix.all_runs(bad)
    unset = copy.deepcopy(CONFIG)
    unset["mpm"]["ladder_targets"] = {"contact_radius_particles": 12, "groove_depth_particles": None}
    assert not list(validator.iter_errors(unset))
    assert len(matrix.all_runs(unset)) == 189


# ----------------------------------------------------------------------------- the figure datasets
def test_figure_datasets_read_each_point_at_its_own_sizes(tmp_path):
    """The smoke matrix under a relative ladder whose points differ in scale: each sweep point is read at its own
    sizes (``particle_size_um``) and extrapolated as from them (the fake runs follow f0 + c h^1.5 in their own h,
    so Richardson recovers f0 only if every value sits at its level); pictures at each case's finest size."""
    from plough.study.mpm_figures import build_dataset
    from tests.study.test_mpm_figures import SMOKE, fake_run, is_noisy, limit, signature_of

    config = copy.deepcopy(SMOKE)
    config["mpm"]["ladder"] = "relative"
    config["mpm"]["ladder_targets"] = {"contact_radius_particles": 3}
    runs = matrix.all_runs(config)
    paths = {}
    for rid, scene in runs.items():
        paths[rid] = tmp_path / f"{rid}.nc"
        fake_run(scene).to_netcdf(paths[rid])
    scales = set()
    for fig in ("fig11", "fig15"):
        ds = build_dataset(config, fig, paths)
        for panel in matrix.figure_panels(config, fig):
            suffix = f"_{panel.name}" if fig == "fig11" else ""
            for series in panel.series:
                for x, p in zip(panel.values, series.points, strict=True):
                    lad = matrix.point_ladder(config, p)
                    scales.add(lad.scale)
                    sel = {panel.series_dim: series.label, panel.axis: x}
                    own = ds[f"particle_size_um{suffix}"].sel(sel).values
                    assert list(own) == list(lad.sizes_um), (fig, p.key)
                    scene = runs[matrix.run_id(p, lad.finest_um)]
                    if not is_noisy(scene):
                        assert float(ds[f"mu_h0{suffix}"].sel(sel)) == pytest.approx(
                            limit("mu", signature_of(scene)), rel=1e-9), (fig, p.key)
    assert len(scales) > 1  # the test's points do differ in scale
    for fig in ("fig12", "fig17"):
        ds = build_dataset(config, fig, paths)
        for label, p in matrix.figure_points(config, fig).items():
            assert ds.attrs[f"particle_size_um_{label}"] == matrix.point_ladder(config, p).finest_um
