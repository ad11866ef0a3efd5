"""Tests of plough.study.matrix: workflow config -> physical points, run ids, scenes and figure plans.

Expected run counts are computed here from the config lists, independently of the module: a run is
a physically distinct scene (materials, thickness, interface, ball, load) at one particle size.
"""

from __future__ import annotations

import copy
import math
import re
from pathlib import Path

import numpy as np
import pytest
import yaml

from plough.analytical import ploughing
from plough.materials import (
    DX56,
    BoundaryLayerShear,
    ConstantShear,
    ProportionalShear,
    get_material,
    representative_hardness,
    rigid_plastic,
)
from plough.mpm.run import simulate
from plough.mpm.scene import CONTACT_MODES, Discretisation, Layers, Scene
from plough.study import matrix

ROOT = Path(__file__).resolve().parents[2]
CONFIGS = {name: yaml.safe_load((ROOT / "config" / f"{name}.yaml").read_text())
           for name in ("config", "preview", "smoke")}


@pytest.fixture(params=sorted(CONFIGS), scope="module")
def config_name(request):
    return request.param


@pytest.fixture(scope="module")
def config(config_name):
    return copy.deepcopy(CONFIGS[config_name])


@pytest.fixture(scope="module")
def runs(config):
    return matrix.all_runs(config)


# ----------------------------------------------------------------------------- independent expectation
def _r(x: float) -> float:
    return round(float(x), 9)


def expected_points(config: dict) -> tuple[set, set]:
    """(sweep points, single-run points) as physical tuples, straight from the config lists.

    Rigid plastic: ("rp", Hc, Hs, t, interface, radius, load) with Hc = None when uncoated.
    Real materials: ("real", system, t, radius, load) with t = 0 for the uncoated systems.
    """
    mpm = config["mpm"]
    rp, real = mpm["rigid_plastic"], mpm["real_materials"]

    def iface(name, hardnesses):
        # the solver caps tau at kappa: a constant H0 at or above every layer's hardness is the f = 1 law
        if name == "constant" and rp["H0_MPa"] < max(hardnesses):
            return ("constant", _r(rp["H0_MPa"]))
        return ("proportional", _r(1.0 if name == "constant" else rp.get("f", 1.0)))

    def rp_point(ratio, hs, t, name):
        t = _r(t)
        hardnesses = (ratio * hs, hs) if t > 0 else (hs,)
        return ("rp", _r(ratio * hs) if t > 0 else None, _r(hs), t, iface(name, hardnesses), _r(rp["radius_um"]),
                _r(rp["load_N"]))

    def real_pt(system, radius, load, t=None):
        coated = "coating" in real["systems"][system]
        thick = _r(real["coating_thickness_um"] if t is None else t) if coated else 0.0
        return ("real", system, thick, _r(radius), _r(load))

    sweep = set()
    rs = rp["ratio_sweep"]
    sweep |= {rp_point(x, rs["substrate_hardness_MPa"], rs["thickness_um"], i)
              for x in rs["hardness_ratio"] for i in rs["interfaces"]}
    ts = rp["thickness_sweep"]
    sweep |= {rp_point(ts[case]["hardness_ratio"], ts[case]["substrate_hardness_MPa"], t, ts["interface"])
              for case in ("soft", "hard") for t in ts["thickness_um"]}
    r1, r3 = real["ball_radii_um"]
    for load in real["loads_N"]:
        sweep |= {real_pt("zinc_block", r1, load), real_pt("steel", r1, load),  # Figs. 15, 20, 23
                  real_pt("coated", r1, load), real_pt("coated", r3, load)}  # Figs. 16, 21, 23
    rts = real["thickness_sweep"]  # Fig. 18
    sweep |= {real_pt("coated", rts["radius_um"], rts["load_N"], t) for t in rts["thickness_um"]}
    sweep.add(real_pt("zinc_block", rts["radius_um"], rts["load_N"]))

    pic, rpic = rp["picture"], real["picture"]
    single = {rp_point(pic["hardness_ratio"], pic["substrate_hardness_MPa"], pic["thickness_um"], pic["interface"]),
              real_pt("coated", rpic["radius_um"], rpic["load_N"]),
              real_pt("zinc_block", rpic["radius_um"], rpic["load_N"])}
    return sweep, single


def _floats(obj):
    """Every number of a config as a float (25 -> 25.0), keeping bools and strings."""
    if isinstance(obj, dict):
        return {k: _floats(v) for k, v in obj.items()}
    if isinstance(obj, list):
        return [_floats(v) for v in obj]
    if isinstance(obj, int) and not isinstance(obj, bool):
        return float(obj)
    return obj


# ----------------------------------------------------------------------------- run ids and scenes
def test_every_run_is_a_valid_scene_named_by_its_id(config, runs):
    sizes = {matrix.fmt(h): float(h) for h in config["mpm"]["particle_sizes_um"]}
    relative = config["mpm"].get("ladder") == "relative"
    assert runs
    for rid, d in runs.items():
        scene = Scene.from_dict(d)
        assert scene.name == rid == d["name"]
        suffix = re.fullmatch(r".+_h([0-9.e+-]+)", rid).group(1)
        if relative:  # a size of the config's, or the half-octave size, times a power of two: the ladders share runs
            bases = [*sizes.values(), 3.5] if config["mpm"].get("ladder_sizes_per_octave", 2) == 2 else sizes.values()
            assert any(math.log2(float(suffix) / h).is_integer() for h in bases), rid
            sizes[suffix] = float(suffix)
        assert suffix in sizes, rid
        assert scene.discretisation.particle_size_m == pytest.approx(sizes[suffix] * 1e-6, rel=1e-12), rid
        # the dict is complete: it survives the round trip through the Scene unchanged
        assert scene.to_dict() == d, rid


def test_run_count_is_distinct_points_times_sizes_plus_finest_pictures(config, config_name, runs):
    sweep, single = expected_points(config)
    n_sizes = len(set(config["mpm"]["particle_sizes_um"]))
    expected = len(sweep) * n_sizes + len(single - sweep)
    assert len(runs) == expected
    assert len(matrix.all_points(config)) == len(sweep | single)
    if config_name == "config":
        # spelled out for the full matrix: rigid plastic 7 ratios x 2 interfaces + 11 thicknesses x 2 cases,
        # less the 4 constant-interface points at H~ <= 1 (H0 = 450 MPa >= both hardnesses: the f = 1 law, the
        # proportional point's run) and the hard t = 25 um proportional point that is also in the ratio sweep;
        # real materials: zinc block + steel (Figs. 15/20) and the coated steel with two balls (Figs. 16/21),
        # each at 7 loads, plus 5 coating thicknesses of Fig. 18 less the t = 15 um one of Fig. 16 (its
        # bulk zinc point is Fig. 15's at 22 N); every picture point (Figs. 12, 14, 17, 19) is a sweep point.
        assert len(sweep) == (7 * 2 - 4 + 11 * 2 - 1) + (2 * 7 + 2 * 7 + 5 - 1) == 63
        assert single <= sweep
        assert len(runs) == 63 * 3 == 189


def test_runs_are_the_union_of_the_figures_runs(config, runs):
    union = {rid for fig in (*matrix.MPM_FIGURES, "fig22") for rid in matrix.figure_runs(config, fig)}
    assert set(runs) == union


def test_shared_figures_share_runs(config):
    runs_of = {fig: matrix.figure_runs(config, fig) for fig in (*matrix.MPM_FIGURES, "fig22")}
    assert runs_of["fig22"] == runs_of["fig21"]
    assert runs_of["fig11"] == runs_of["fig13"]
    assert runs_of["fig15"] == runs_of["fig20"]
    assert runs_of["fig16"] == runs_of["fig21"]
    # Fig. 18's point at the standard coating thickness is Fig. 16's run at that load and ball
    real = config["mpm"]["real_materials"]
    t0 = matrix.fmt(real["coating_thickness_um"])
    fig18_std = {r for r in runs_of["fig18"] if f"_t{t0}_" in r}
    assert len(fig18_std) == len(config["mpm"]["particle_sizes_um"])
    assert fig18_std <= set(runs_of["fig16"])
    # Fig. 23 is made of Fig. 15's and Fig. 16's runs only
    assert set(runs_of["fig23"]) <= set(runs_of["fig15"]) | set(runs_of["fig16"])


# ----------------------------------------------------------------------------- one run for one computation
#: a coarse coated rigid-plastic scene (h = 10 um; about 2 s a run): 450 MPa coating 15 um thick on 900 MPa
TINY_LAYERED = {
    "name": "tiny_layered", "load_N": 1.5, "sphere": {"radius_um": 200},
    "layers": {"substrate": {"rigid_plastic_hardness_MPa": 900}, "coating": {"rigid_plastic_hardness_MPa": 450},
               "coating_thickness_um": 15},
    "domain": {"radius_um": 100, "length_um": 340, "symmetric": True},
    "sliding": {"distance_um": 130, "speed_m_s": 0.1, "experiment_speed_m_s": 0.001},
    "discretisation": {"particle_size_um": 10, "particles_per_cell": 2, "cfl": 0.3, "mass_scaling": 1.0e6},
    "outputs": {"steady_window": [0.5, 1.0], "records": 40},
}


def test_a_constant_interface_at_or_above_every_hardness_is_the_proportional_f1_law():
    """The solver caps tau at kappa = sigma_y / sqrt 3, so tau = H0 / k0 >= kappa of every perfectly plastic
    layer (H0 >= H = 3 sigma_y) is the f = 1 law; below either hardness, or on a hardening layer, it is not."""
    coat, sub = rigid_plastic("c", 225e6, coating=True), rigid_plastic("s", 450e6, coating=False)
    coated = Layers(substrate=sub, coating=coat, coating_thickness_m=15e-6)
    for H0 in (450e6, 900e6):  # at the substrate's hardness (the paper's H0 over H~ <= 1) and above
        assert matrix.solver_interface(coated, ConstantShear(H0_Pa=H0)) == ProportionalShear(f=1.0)
        assert matrix.solver_interface(Layers(substrate=sub), ConstantShear(H0_Pa=H0)) == ProportionalShear(f=1.0)
    for H0 in (449e6, 300e6):  # under the substrate's hardness: the cap does not act there
        assert matrix.solver_interface(coated, ConstantShear(H0_Pa=H0)) == ConstantShear(H0_Pa=H0)
    # a hard coating (H~ = 2) above the constant shear
    hard = Layers(substrate=sub, coating=rigid_plastic("c", 900e6, coating=True), coating_thickness_m=15e-6)
    assert matrix.solver_interface(hard, ConstantShear(H0_Pa=450e6)) == ConstantShear(H0_Pa=450e6)
    # a hardening layer: its kappa grows with strain, so no constant shear is the f = 1 law for sure
    assert matrix.solver_interface(Layers(substrate=DX56), ConstantShear(H0_Pa=5e9)) == ConstantShear(H0_Pa=5e9)
    for other in (ProportionalShear(f=0.5), BoundaryLayerShear(Cp=0.32, np=0.95)):
        assert matrix.solver_interface(coated, other) is other


def test_a_constant_interface_above_every_hardness_runs_as_the_proportional_f1_law():
    """Why ``solver_interface`` may name the two laws alike (and the study make them one run): on a
    450 MPa coating 15 um thick over the 900 MPa substrate (a particle straddling the interface mixes the two),
    tau = 1000 MPa / k0 is capped at kappa everywhere and the run is the f = 1 run, bit for bit (at 900 MPa, the
    substrate's hardness, to round-off); at 300 MPa,
    under the coating's hardness, it is not (mu a third lower)."""
    runs = {}
    for name, interface in (("f1", {"model": "proportional", "f": 1.0}),
                            ("H0_1000", {"model": "constant", "H0_MPa": 1000}),
                            ("H0_900", {"model": "constant", "H0_MPa": 900}),  # = the substrate's H, the shipped case
                            ("H0_300", {"model": "constant", "H0_MPa": 300})):
        scene = Scene.from_dict(TINY_LAYERED | {"interface": interface})
        runs[name] = (scene, simulate(scene, progress=False, threads=1))
    above, below = runs["H0_1000"][0], runs["H0_300"][0]
    assert matrix.solver_interface(above.layers, above.interface) == runs["f1"][0].interface
    assert matrix.solver_interface(below.layers, below.interface) == below.interface
    assert matrix.solver_interface(runs["H0_900"][0].layers, runs["H0_900"][0].interface) == runs["f1"][0].interface
    for var in ("Fx", "Fz", "depth"):
        np.testing.assert_array_equal(runs["H0_1000"][1][var].values, runs["f1"][1][var].values)
        # at H0 = H the node's averaged kappa may differ from H0 / k0 by a rounding step: equal to round-off
        np.testing.assert_allclose(runs["H0_900"][1][var].values, runs["f1"][1][var].values, rtol=1e-9, atol=0.0)
    assert float(runs["H0_300"][1].mu) < 0.8 * float(runs["f1"][1].mu)


def test_a_constant_interface_the_solver_caps_everywhere_shares_the_proportional_run(config):
    """Fig. 11a's constant-interface point is the proportional (f = 1) point's run where H0 is at or above both
    hardnesses (the solver caps tau at kappa), its own run where the coating is harder; the analytical values
    stay the constant law's (eq. 8 is not capped)."""
    rp = config["mpm"]["rigid_plastic"]
    rs = rp["ratio_sweep"]
    if not {"constant", "proportional"} <= set(rs["interfaces"]) or float(rp.get("f", 1.0)) != 1.0:
        pytest.skip("needs both interfaces with f = 1")
    a = matrix.figure_panels(config, "fig11")[0]
    const = a.series[rs["interfaces"].index("constant")].points
    prop = a.series[rs["interfaces"].index("proportional")].points
    n_shared = 0
    for ratio, c, p in zip(rs["hardness_ratio"], const, prop, strict=True):
        shared = float(rp["H0_MPa"]) >= max(float(ratio), 1.0) * float(rs["substrate_hardness_MPa"])
        assert (c.key == p.key) is shared, (ratio, c.key)
        assert c.interface == ({"model": "proportional", "f": 1.0} if shared
                               else {"model": "constant", "H0_Pa": float(rp["H0_MPa"]) * 1e6})
        assert matrix.scene_for(c, 5.0, config["mpm"]["numerics"]).interface == (
            matrix.scene_for(p, 5.0, config["mpm"]["numerics"]).interface if shared
            else ConstantShear(H0_Pa=float(rp["H0_MPa"]) * 1e6))
        # the analytical model keeps the uncapped constant law (tau = H0 / k0 above the soft coating's kappa)
        direct = ploughing(float(rp["load_N"]), float(rp["radius_um"]) * 1e-6, float(rs["thickness_um"]) * 1e-6,
                           float(ratio) * float(rs["substrate_hardness_MPa"]) * 1e6,
                           float(rs["substrate_hardness_MPa"]) * 1e6, k1=float(rs["k1"]), interface="constant",
                           H0_Pa=float(rp["H0_MPa"]) * 1e6)
        assert matrix.analytical_values(c)["mu"] == pytest.approx(float(direct.mu), rel=1e-12)
        n_shared += shared
    assert n_shared >= 1
    # H0 under the substrate's hardness: no constant point is shared any more, the prop1 runs stay as they were
    lower = copy.deepcopy(config)
    lower["mpm"]["rigid_plastic"]["H0_MPa"] = 0.9 * float(rs["substrate_hardness_MPa"])
    before, after = matrix.all_runs(config), matrix.all_runs(lower)
    const_lower = matrix.figure_panels(lower, "fig11")[0].series[rs["interfaces"].index("constant")].points
    assert all(c.interface["model"] == "constant" and c.key != p.key for c, p in zip(const_lower, prop, strict=True))
    const_runs = {matrix.run_id(c, h) for c in const_lower for h in matrix.point_ladder(lower, c).sizes_um}
    assert const_runs <= set(after) and not const_runs & set(before)
    assert {r for r in before if "_prop1_" in r} == {r for r in after if "_prop1_" in r}
    assert all(before[r] == after[r] for r in before if "_prop1_" in r)


def test_sweep_points_at_every_size_pictures_at_the_finest(config):
    sizes = matrix.particle_sizes_um(config)
    assert list(sizes) == sorted((float(h) for h in config["mpm"]["particle_sizes_um"]), reverse=True)
    if config["mpm"].get("ladder") == "relative":  # each point's own sizes: tests/study/test_ladder.py
        config = copy.deepcopy(config)
        config["mpm"]["ladder"] = "paper"
    finest = matrix.fmt(min(float(h) for h in config["mpm"]["particle_sizes_um"]))
    for fig in matrix.SINGLE_RUN_FIGURES:
        ids = matrix.figure_runs(config, fig)
        assert ids and all(r.endswith(f"_h{finest}") for r in ids), fig
    for fig in matrix.SWEEP_FIGURES:
        ids = matrix.figure_runs(config, fig)
        # a point shared by two panels (fig11's hard t = 25 um coating) is one run, listed once
        n_points = len({pt.key for p in matrix.figure_panels(config, fig) for s in p.series for pt in s.points})
        assert len(ids) == len(set(ids)) == n_points * len(sizes), fig
        for h in sizes:
            assert sum(r.endswith(f"_h{matrix.fmt(h)}") for r in ids) == n_points, (fig, h)


def test_a_picture_off_the_sweeps_adds_one_run_at_the_finest_size():
    config = copy.deepcopy(CONFIGS["smoke"])
    before = matrix.all_runs(config)
    config["mpm"]["rigid_plastic"]["picture"]["hardness_ratio"] = 0.3  # in no ratio sweep
    after = matrix.all_runs(config)
    new = set(after) - set(before)
    assert set(before) <= set(after)
    finest = matrix.fmt(min(config["mpm"]["particle_sizes_um"]))
    assert len(new) == 1
    (rid,) = new
    assert rid.endswith(f"_h{finest}")
    assert matrix.figure_runs(config, "fig12") == [rid]
    scene = Scene.from_dict(after[rid])
    hc, hs = (representative_hardness(m) for m in (scene.layers.coating, scene.layers.substrate))
    assert hc / hs == pytest.approx(0.3)


# ----------------------------------------------------------------------------- what changes a run
def _steel_runs(runs: dict) -> set[str]:
    return {rid for rid, d in runs.items() if d["layers"]["substrate"]["name"] == "dx56" and d["layers"]["coating"]
            is None}


@pytest.mark.parametrize(("path", "value", "affected"), [
    (("real_materials", "lubricants", "dx56", "Cp"), 1.5, "steel"),
    (("real_materials", "lubricants", "zinc", "np"), 0.9, "zinc"),
    # the pressure the MPM reads: the default's ids carry no name for it, the traction runs are new ids
    (("real_materials", "lubricants", "zinc", "pressure"), "traction", "zinc"),
    # 500 MPa, above 450: the constant points at H~ <= 1 stay the f = 1 law (test above), the others change
    (("rigid_plastic", "H0_MPa"), 500, "constant"),
], ids=["lubricant_dx56_Cp", "lubricant_zinc_np", "lubricant_zinc_pressure", "H0_MPa"])
def test_changing_a_parameter_changes_exactly_the_runs_that_use_it(config, runs, path, value, affected):
    changed_config = copy.deepcopy(config)
    node = changed_config["mpm"]
    for key in path[:-1]:
        node = node[key]
    node[path[-1]] = value
    after = matrix.all_runs(changed_config)

    if affected == "steel":
        users = _steel_runs(runs)
    elif affected == "zinc":  # every run with the zinc lubricant: coated steel and the zinc block
        zinc = config["mpm"]["real_materials"]["lubricants"]["zinc"]
        users = {rid for rid, d in runs.items()
                 if d["interface"] == {"model": "boundary_layer", "Cp": zinc["Cp"], "np": zinc["np"],
                                       "pressure": "particles"}}
    else:
        users = {rid for rid, d in runs.items() if d["interface"]["model"] == "constant"}
    assert users and len(users) < len(runs)

    unchanged = {rid for rid in runs if rid in after and after[rid] == runs[rid]}
    assert set(runs) - unchanged == users
    # the others are the same runs with the new parameter, under new ids (the key spells the interface)
    new = set(after) - set(runs)
    assert len(new) == len(users) and len(after) == len(runs)
    field = {"Cp": "Cp", "np": "np", "pressure": "pressure", "H0_MPa": "H0_Pa"}[path[-1]]
    scene_value = value * 1e6 if field == "H0_Pa" else value  # the scene's units: Pa
    by_rest = {}
    for rid in users:
        d = copy.deepcopy(runs[rid])
        d.pop("name")
        d["interface"][field] = scene_value
        by_rest[repr(d)] = rid
    for rid in new:
        d = copy.deepcopy(after[rid])
        d.pop("name")
        assert repr(d) in by_rest, rid  # nothing but the parameter differs
    if field == "pressure":  # the default's ids name no pressure; the new ones do
        assert all("_bl" in rid and "-traction_" not in rid for rid in users)
        assert all("-traction_" in rid for rid in new)


def test_k1_changes_no_run_but_the_analytical_values(config, runs):
    changed = copy.deepcopy(config)
    rp, real = changed["mpm"]["rigid_plastic"], changed["mpm"]["real_materials"]
    rp["ratio_sweep"]["k1"] = 60.0
    rp["thickness_sweep"]["k1"] = 30.0
    real["k1"] = 250.0
    assert matrix.all_runs(changed) == runs
    for fig in ("fig11", "fig16"):
        old = matrix.figure_panels(config, fig)[-1].series[0].points[-1]
        new = matrix.figure_panels(changed, fig)[-1].series[0].points[-1]
        assert old == new  # the same physical point ...
        assert matrix.analytical_values(old)["mu"] != pytest.approx(matrix.analytical_values(new)["mu"], rel=1e-6)


def test_fmt_spells_a_value_one_way(config, runs):
    assert matrix.fmt(25.0) == matrix.fmt(25) == "25"
    assert matrix.fmt(2.5) == "2.5"
    assert matrix.fmt(0.5) == matrix.fmt("0.5") == "0.5"
    # a config with every number written as a float is the same set of runs
    assert matrix.all_runs(_floats(config)) == runs


# ----------------------------------------------------------------------------- domains and analytical values
def test_sized_domains_cover_the_contact_in_whole_particles(config, runs):
    dom = config["mpm"]["numerics"]["domain"]
    assert dom["mode"] == "sized"
    k_r, k_end = float(dom["radius_contact_radii"]), float(dom["end_margin_contact_radii"])
    slide = float(config["mpm"]["numerics"]["sliding_distance_um"]) * 1e-6
    for rid, d in runs.items():
        scene = Scene.from_dict(d)
        a, _ = scene.expected_contact()
        h = scene.discretisation.particle_size_m
        radius, length = scene.domain.radius_m, scene.domain.length_m
        assert radius >= k_r * a * (1 - 1e-12), rid
        assert radius >= 4 * h * (1 - 1e-12), rid
        assert radius < max(k_r * a, 4 * h) + h, rid  # rounded up to the next whole particle, no further
        assert length >= slide + 2 * k_end * a - 1e-15, rid
        assert length < slide + 2 * k_end * a + h, rid
        for x in (radius, length):
            assert abs(x / h - round(x / h)) < 1e-6, (rid, x, h)
        assert scene.domain.symmetric is bool(config["mpm"]["numerics"]["symmetric"])


def test_analytical_values_of_rigid_plastic_points_are_the_model(config):
    rp = config["mpm"]["rigid_plastic"]
    rs, ts = rp["ratio_sweep"], rp["thickness_sweep"]
    a, b = matrix.figure_panels(config, "fig11")
    ratio = float(rs["hardness_ratio"][-1])
    point_a = a.series[rs["interfaces"].index("constant")].points[-1]
    hs = float(rs["substrate_hardness_MPa"]) * 1e6
    direct_a = ploughing(float(rp["load_N"]), float(rp["radius_um"]) * 1e-6, float(rs["thickness_um"]) * 1e-6,
                         ratio * hs, hs, k1=float(rs["k1"]), interface="constant",
                         H0_Pa=float(rp["H0_MPa"]) * 1e6)
    soft = ts["soft"]
    t = float(ts["thickness_um"][-1])
    point_b = b.series[0].points[-1]
    assert b.series[0].label == "soft"
    hs_b = float(soft["substrate_hardness_MPa"]) * 1e6
    direct_b = ploughing(float(rp["load_N"]), float(rp["radius_um"]) * 1e-6, t * 1e-6,
                         float(soft["hardness_ratio"]) * hs_b, hs_b, k1=float(ts["k1"]), interface="proportional",
                         f=1.0)
    for point, direct in ((point_a, direct_a), (point_b, direct_b)):
        values = matrix.analytical_values(point)
        assert set(values) == set(matrix.ANALYTICAL_OUTPUTS)
        for name, v in values.items():
            assert math.isfinite(v)
            assert v == pytest.approx(float(getattr(direct, name)), rel=1e-9), (point.key, name)
    # the correction is passed through
    once = matrix.analytical_values(point_a, correction="once")
    direct_once = ploughing(float(rp["load_N"]), float(rp["radius_um"]) * 1e-6, float(rs["thickness_um"]) * 1e-6,
                            ratio * hs, hs, k1=float(rs["k1"]), interface="constant",
                            H0_Pa=float(rp["H0_MPa"]) * 1e6, correction="once")
    assert once["mu"] == pytest.approx(float(direct_once.mu), rel=1e-9)


def test_analytical_values_of_real_materials_use_tabor_hardness(config):
    real = config["mpm"]["real_materials"]
    load, radius = float(real["loads_N"][-1]), float(real["ball_radii_um"][0])
    point = matrix.real_point(real, "coated", load, radius)
    lub = real["lubricants"][real["systems"]["coated"]["lubricant"]]
    direct = ploughing(load, radius * 1e-6, float(real["coating_thickness_um"]) * 1e-6,
                       representative_hardness(get_material("zinc_coating")),
                       representative_hardness(get_material("dx56")), k1=float(real["k1"]),
                       interface="boundary_layer", Cp=float(lub["Cp"]), np_exponent=float(lub["np"]))
    values = matrix.analytical_values(point)
    for name, v in values.items():
        assert v == pytest.approx(float(getattr(direct, name)), rel=1e-9), name


def test_unknown_figures_are_refused():
    config = CONFIGS["smoke"]
    with pytest.raises(ValueError, match="not a sweep figure"):
        matrix.figure_panels(config, "fig12")
    with pytest.raises(ValueError, match="not a single-run figure"):
        matrix.figure_points(config, "fig15")
    assert matrix.figure_runs(config, "fig03") == []


def test_graded_particles_reach_every_scene_of_the_matrix(config):
    """numerics.graded / fine_zone_contact_radii / fine_zone_shape go into each run's discretisation (and so
    into its params)."""
    changed = copy.deepcopy(config)
    shape = "disc" if config["mpm"]["numerics"].get("fine_zone_shape", "square") == "square" else "square"
    changed["mpm"]["numerics"].update(graded=not config["mpm"]["numerics"].get("graded", False),
                                      fine_zone_contact_radii=1.25, fine_zone_shape=shape)
    before, after = matrix.all_runs(config), matrix.all_runs(changed)
    assert set(before) == set(after)
    for rid, d in after.items():
        disc = Scene.from_dict(d).discretisation
        assert disc.graded is changed["mpm"]["numerics"]["graded"] and disc.fine_zone_contact_radii == 1.25
        assert disc.fine_zone_shape == shape
        assert d != before[rid]  # a changed scene: the workflow reruns it


@pytest.mark.parametrize("zone", [None, 6.0])
def test_active_zone_reaches_every_scene_of_the_matrix(config, zone):
    """numerics.active_zone_contact_radii (null: every particle) goes into each run's discretisation."""
    changed = copy.deepcopy(config)
    changed["mpm"]["numerics"]["active_zone_contact_radii"] = zone
    for d in matrix.all_runs(changed).values():
        assert Scene.from_dict(d).discretisation.active_zone_contact_radii == zone
    del changed["mpm"]["numerics"]["active_zone_contact_radii"]  # absent: every particle
    for d in matrix.all_runs(changed).values():
        assert Scene.from_dict(d).discretisation.active_zone_contact_radii is None


def test_contact_reaches_every_scene_of_the_matrix_and_the_schema_offers_every_mode(config):
    """numerics.contact goes into each run's discretisation (and so its params: a changed contact reruns every
    run); absent, the scene's default; the schema's choices are the solver's CONTACT_MODES."""
    assert config["mpm"]["numerics"]["contact"] == Discretisation.contact  # the configs state the default
    before = matrix.all_runs(config)
    changed = copy.deepcopy(config)
    changed["mpm"]["numerics"]["contact"] = "grid"
    for rid, d in matrix.all_runs(changed).items():
        assert Scene.from_dict(d).discretisation.contact == "grid" and d != before[rid]
    del changed["mpm"]["numerics"]["contact"]
    assert matrix.all_runs(changed) == before
    schema = yaml.safe_load((ROOT / "workflow" / "schemas" / "config.schema.yaml").read_text())
    numerics = schema["properties"]["mpm"]["properties"]["numerics"]["properties"]
    assert sorted(numerics["contact"]["enum"]) == sorted(CONTACT_MODES)
    assert numerics["contact"]["default"] == Discretisation.contact


@pytest.mark.parametrize("mode", ["sized", "fixed"])
def test_grid_headroom_reaches_every_scene_of_the_matrix(config, mode):
    """numerics.domain.headroom_um is optional (automatic when absent) and, when given, sets every run's headroom."""
    auto = copy.deepcopy(config)
    dom = {"mode": "sized", "radius_contact_radii": 2.5, "end_margin_contact_radii": 3.0} if mode == "sized" else \
        {"mode": "fixed", "radius_um": 2000, "length_um": 6000}
    auto["mpm"]["numerics"]["domain"] = dom
    tall = copy.deepcopy(auto)
    tall["mpm"]["numerics"]["domain"]["headroom_um"] = 120
    before, after = matrix.all_runs(auto), matrix.all_runs(tall)
    assert set(before) == set(after)
    for rid, d in after.items():
        assert Scene.from_dict(before[rid]).domain.headroom_m is None
        assert Scene.from_dict(d).domain.headroom_m == pytest.approx(120e-6)
        assert Scene.from_dict(d).grid_headroom_m == pytest.approx(120e-6)


def test_preview_config_is_the_full_matrix_at_two_coarser_sizes():
    """config/preview.yaml differs from config/config.yaml only in the particle sizes and the ladder (the same
    two sizes for every point; so it follows the full matrix as that changes), and its runs at a size a point's
    ladder in the full config has are the full config's own scenes: one result file serves both."""
    full, preview = CONFIGS["config"], CONFIGS["preview"]
    assert matrix.particle_sizes_um(preview) == (20.0, 10.0)
    assert preview["mpm"]["ladder"] == "paper"
    same = copy.deepcopy(preview)
    for key in ("particle_sizes_um", "ladder", "ladder_targets", "ladder_sizes_per_octave"):
        same["mpm"][key] = full["mpm"][key]
    assert same == full
    runs_full, runs_preview = matrix.all_runs(full), matrix.all_runs(preview)
    shared = set(runs_full) & set(runs_preview)
    ladders = [matrix.point_ladder(full, p).sizes_um for p in matrix.all_points(full).values()]
    # a third, not half, since the half-octave sizes (14, 28 um ...) share nothing with the preview's
    assert len(shared) == sum((20.0 in s) + (10.0 in s) for s in ladders) > len(runs_preview) // 3
    assert all(runs_full[rid] == runs_preview[rid] for rid in shared)
