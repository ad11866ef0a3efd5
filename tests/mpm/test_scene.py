"""Tests of plough.mpm.scene (validation, units, YAML) and of the particle seeding it drives.

Seeding is checked through ``solver.init(scene)``: particle positions fill the half cylinder
(a quarter cylinder with the mirror plane), the particle straddling the coating interface carries
both materials with the coating's volume fraction, and the masses are the layers' densities
times mass scaling times volume.
"""

from __future__ import annotations

import copy
import math
from dataclasses import replace
from pathlib import Path

import numpy as np
import pytest
import yaml

from plough.materials import DX56, ZINC_BULK, ZINC_COATING, ConstantShear, ProportionalShear, rigid_plastic
from plough.mpm import contact, io, solver
from plough.mpm.constitutive import I_RHO
from plough.mpm.scene import Discretisation, Domain, Layers, Scene, Sliding

EXAMPLES_DIR = Path(__file__).resolve().parents[2] / "examples"
EXAMPLES = sorted(EXAMPLES_DIR.glob("*.yaml"))


def example_dict(name="uncoated_rigid_plastic"):
    return yaml.safe_load((EXAMPLES[0].parent / f"{name}.yaml").read_text())


# ----------------------------------------------------------------------------- round trips
def test_the_examples_are_found():
    assert {p.stem for p in EXAMPLES} == {"coated_rigid_plastic", "uncoated_rigid_plastic", "zinc_coated_steel",
                                          "stability_small", "quickstart"}


@pytest.mark.parametrize("path", EXAMPLES, ids=lambda p: p.stem)
def test_round_trip_dict_and_yaml(path, tmp_path):
    scene = Scene.from_yaml(path)
    assert Scene.from_dict(scene.to_dict()) == scene
    assert Scene.from_yaml(scene.to_yaml()) == scene
    out = tmp_path / "scene.yaml"
    scene.to_yaml(out)
    assert Scene.from_yaml(out) == scene
    assert Scene.from_yaml(str(out)) == scene
    # equality is not vacuous
    assert scene.with_(load_N=scene.load_N * 0.9) != scene


def test_examples_parse_to_the_documented_values():
    zinc = Scene.from_yaml(EXAMPLES[0].parent / "zinc_coated_steel.yaml")
    assert zinc.layers.substrate == DX56 and zinc.layers.coating == ZINC_COATING
    assert zinc.layers.coating_thickness_m == pytest.approx(15e-6)
    assert zinc.sphere.radius_m == pytest.approx(500e-6)
    assert zinc.load_N == 22.0
    assert zinc.interface.Cp == 0.32 and zinc.interface.np == 0.95
    coated = Scene.from_yaml(EXAMPLES[0].parent / "coated_rigid_plastic.yaml")
    assert coated.layers.coating.flow.sigma_y_Pa == pytest.approx(450e6 / 3)
    assert coated.layers.substrate.flow.sigma_y_Pa == pytest.approx(900e6 / 3)
    assert coated.discretisation.mass_scaling == 1e6
    assert coated.rate_scale == pytest.approx(1e-3 / 0.1)
    # the slide is centred in the block
    assert coated.start_x_m == pytest.approx(0.5 * (1000e-6 - 600e-6))


# ----------------------------------------------------------------------------- units and coercion
def test_unit_suffix_keys_are_converted_to_si():
    d = example_dict()
    d["sphere"] = {"radius_um": 250}
    d["domain"] = {"radius_mm": 0.2, "length_um": 1000}
    d["layers"]["substrate"] = {"rigid_plastic_hardness_MPa": 600}
    s = Scene.from_dict(d)
    assert s.sphere.radius_m == pytest.approx(250e-6, rel=1e-15)
    assert s.domain.radius_m == pytest.approx(0.2e-3, rel=1e-15)
    assert s.domain.length_m == pytest.approx(1e-3, rel=1e-15)
    assert s.layers.substrate.flow.sigma_y_Pa == pytest.approx(200e6, rel=1e-15)
    # a full material dict may use _GPa / _MPa too
    mat = rigid_plastic("m", 600e6, coating=False).to_dict()
    mat["youngs_modulus_GPa"] = mat.pop("youngs_modulus_Pa") / 1e9
    d["layers"]["substrate"] = mat
    assert Scene.from_dict(d).layers.substrate.youngs_modulus_Pa == pytest.approx(210e9)
    # the same quantity twice is refused
    d["sphere"] = {"radius_um": 250, "radius_m": 250e-6}
    with pytest.raises(ValueError, match="radius_um.*radius_m"):
        Scene.from_dict(d)


def test_yaml_exponent_without_sign_is_coerced_to_a_number():
    text = (EXAMPLES[0].parent / "uncoated_rigid_plastic.yaml").read_text()
    text = text.replace("mass_scaling: 1.0e+6", "mass_scaling: 1.0e6").replace("load_N: 3.0", "load_N: 3.0e0")
    assert "1.0e6" in text and "3.0e0" in text
    raw = yaml.safe_load(text)
    assert raw["discretisation"]["mass_scaling"] == "1.0e6"  # YAML 1.1 reads it as a string
    s = Scene.from_yaml(text)
    assert s.discretisation.mass_scaling == 1e6 and isinstance(s.discretisation.mass_scaling, float)
    assert s.load_N == 3.0 and isinstance(s.load_N, float)
    d = copy.deepcopy(raw)
    d["discretisation"]["particles_per_cell"] = "2.0e0"
    n = Scene.from_dict(d).discretisation.particles_per_cell
    assert n == 2 and isinstance(n, int)


# ----------------------------------------------------------------------------- bad input
def _flow_changed(material, **flow):
    d = material.to_dict()
    d["flow"] = {**d["flow"], **flow}
    return d


def _mutate(**changes):
    d = example_dict()
    for path, value in changes.items():
        keys = path.split("__")
        target = d
        for k in keys[:-1]:
            target = target.setdefault(k, {})
        target[keys[-1]] = value
    return d


BAD = {
    "negative radius": (_mutate(sphere__radius_um=-5), r"sphere\.radius_m"),
    "unknown key in a part": (_mutate(sphere__colour="red"), r"unknown key.*colour"),
    "unknown top-level key": (_mutate(colour="red"), r"unknown key.*colour"),
    "unknown layers key": (_mutate(layers__thickness_um=3), r"layers.*unknown key.*thickness"),
    "unknown material": (_mutate(layers__substrate="unobtainium"),
                         r"layers\.substrate.*unobtainium.*dx56.*zinc_bulk.*zinc_coating"),
    "cfl above 1": (_mutate(discretisation__cfl=1.5), r"discretisation\.cfl"),
    "cfl zero": (_mutate(discretisation__cfl=0.0), r"discretisation\.cfl"),
    "domain too small": (_mutate(domain__radius_um=60), r"domain\.radius_m"),
    "domain too short": (_mutate(domain__length_um=500), r"domain\.length_m"),
    "load too large": (_mutate(load_N=1e4), r"load_N"),
    "negative load": (_mutate(load_N=-1.0), r"load_N"),
    "coating thickness without coating": (_mutate(layers__coating_thickness_um=10), r"layers\.coating"),
    "negative coating thickness": (_mutate(layers__coating_thickness_um=-3,
                                           layers__coating={"rigid_plastic_hardness_MPa": 450}),
                                   r"layers\.coating_thickness_m"),
    "particles_per_cell 7": (_mutate(discretisation__particles_per_cell=7), r"discretisation\.particles_per_cell"),
    "particles_per_cell 2.5": (_mutate(discretisation__particles_per_cell=2.5),
                               r"discretisation\.particles_per_cell"),
    "not a number": (_mutate(discretisation__cfl="abc"), r"discretisation\.cfl"),
    "particles too coarse": (_mutate(discretisation__particle_size_um=60), r"discretisation\.particle_size_m"),
    "mass scaling below 1": (_mutate(discretisation__mass_scaling=0.5), r"discretisation\.mass_scaling"),
    "steady tolerance 0": (_mutate(sliding__steady_tolerance=0.0), r"sliding\.steady_tolerance.*\(0, 0\.2\]"),
    "stop_when_steady not a bool": (_mutate(sliding__stop_when_steady="yes"), r"sliding\.stop_when_steady"),
    "flip above 1": (_mutate(discretisation__flip=1.5), r"discretisation\.flip.*\[0, 1\]"),
    "inertia dominates": (_mutate(discretisation__mass_scaling=1e8),
                          r"discretisation\.mass_scaling.*speed_m_s.*inertia number .* = 8\.72 above the allowed 4"),
    "unknown control": (_mutate(sliding__control="force"), r"sliding\.control"),
    "displacement without depth": (_mutate(sliding__control="displacement"), r"sliding\.depth_m"),
    "unknown interface model": (_mutate(interface={"model": "magic"}), r"interface\.model"),
    "symmetric not a bool": (_mutate(domain__symmetric="yes"), r"domain\.symmetric"),
    "records too few": (_mutate(outputs__records=5), r"outputs\.records"),
    "active zone below 2 contact radii": (_mutate(discretisation__active_zone_contact_radii=1.5),
                                          r"discretisation\.active_zone_contact_radii = 1\.5 .*\[2, inf\) or null"),
    "active zone not finite": (_mutate(discretisation__active_zone_contact_radii=float("inf")),
                               r"discretisation\.active_zone_contact_radii = inf"),
    "active zone not a number": (_mutate(discretisation__active_zone_contact_radii="wide"),
                                 r"discretisation\.active_zone_contact_radii"),
    "rigid-plastic extra key": (_mutate(layers__substrate={"rigid_plastic_hardness_MPa": 900, "foo": 1}),
                                r"layers\.substrate.*foo"),
    # an integer field holding inf / NaN, text in a unit-suffixed key, a bool as a number
    "particles_per_cell inf": (_mutate(discretisation__particles_per_cell=float("inf")),
                               r"discretisation\.particles_per_cell = inf is not an integer"),
    "records nan": (_mutate(outputs__records=float("nan")), r"outputs\.records = nan is not an integer"),
    "text in a _um key": (_mutate(sphere__radius_um="abc"), r"sphere\.radius_um = 'abc' is not a number"),
    "text in a layers _um key": (_mutate(layers__coating_thickness_um="thick"),
                                 r"layers\.coating_thickness_um = 'thick' is not a number"),
    "text in a material _MPa key": (_mutate(layers__substrate={"rigid_plastic_hardness_MPa": "soft"}),
                                    r"layers\.substrate\.rigid_plastic_hardness_MPa = 'soft' is not a number"),
    "load true": (_mutate(load_N=True), r"load_N = True is not a number"),
    "initial temperature nan": (_mutate(outputs__initial_temperature_K=float("nan")),
                                r"outputs\.initial_temperature_K = nan K is outside the allowed range \(0, 2000\]"),
    "initial temperature negative": (_mutate(outputs__initial_temperature_K=-500),
                                     r"outputs\.initial_temperature_K = -500"),
    "a name with a path": (_mutate(name="../../escape/x"), r"name = '\.\./\.\./escape/x' is not allowed"),
    "a name with a space": (_mutate(name="my run"), r"name = 'my run' is not allowed"),
    # unknown keys named as written, not as the SI key they were converted to
    "material dict missing keys": (_mutate(layers__substrate={"hardness_MPa": 450}),
                                   r"layers\.substrate: not a material: missing key\(s\).*"
                                   r"unknown key\(s\) \['hardness_MPa'\]"),
    "unknown unit key in a section": (_mutate(sphere__diameter_mm=1.0), r"sphere: unknown key\(s\) \['diameter_mm'\]"),
    "unknown unit key in layers": (_mutate(layers__thickness_um=15), r"layers: unknown key\(s\) \['thickness_um'\]"),
    "unknown unit key in a flow law": (_mutate(layers__substrate={**DX56.to_dict(), "flow": {
        "model": "constant", "sigma_y_Pa": 1e8, "sigma_u_MPa": 300}}),
        r"layers\.substrate\.flow \(constant\): unknown key\(s\) \['sigma_u_MPa'\]"),
    "rigid-plastic extra unit key": (_mutate(layers__substrate={"rigid_plastic_hardness_MPa": 900, "E_GPa": 200}),
                                     r"unknown key\(s\) \['E_GPa'\] for a rigid-plastic material"),
    "material flow key unknown": (_mutate(layers__substrate={**DX56.to_dict(), "flow": {"model": "constant",
                                                                                        "sigma_y": 1e8}}),
                                  r"layers\.substrate\.flow \(constant\): missing key\(s\) \['sigma_y_Pa'\]"),
    "flow model a list": (_mutate(layers__substrate={**DX56.to_dict(), "flow": {"model": ["constant"]}}),
                          r"layers\.substrate\.flow\.model = \['constant'\] is not one of"),
    "interface model a list": (_mutate(interface={"model": ["proportional"]}),
                               r"interface\.model = \['proportional'\]"),
    "material keys of mixed types": (_mutate(layers__substrate={1: 2, "foo": 3}),
                                     r"layers\.substrate: not a material: missing key\(s\).*"
                                     r"unknown key\(s\) \['1', 'foo'\]"),
    "rigid-plastic hardness null": (_mutate(layers__substrate={"rigid_plastic_hardness_MPa": None}),
                                    r"layers\.substrate\.rigid_plastic_hardness_Pa = None is not a number"),
    "rigid-plastic SI hardness text": (_mutate(layers__substrate={"rigid_plastic_hardness_Pa": "hard"}),
                                       r"layers\.substrate\.rigid_plastic_hardness_Pa = 'hard' is not a number"),
    # flow-law constants: refused by name, not a traceback from the analytical sizing or a NaN mid-run
    "Bergstrom-van Liempt eps0 negative": (_mutate(layers__substrate=_flow_changed(DX56, eps0=-1.0)),
                                           r"BergstromVanLiempt: eps0 = -1\.0 is not allowed; .* >= 0"),
    "Bergstrom-van Liempt sigma_v0 nan": (_mutate(layers__substrate=_flow_changed(DX56, sigma_v0_Pa=float("nan"))),
                                          r"BergstromVanLiempt: sigma_v0_Pa = nan"),
    "Bergstrom-van Liempt beta nan": (_mutate(layers__substrate=_flow_changed(DX56, beta=float("nan"))),
                                      r"BergstromVanLiempt: beta = nan"),
    "Johnson-Cook B nan": (_mutate(layers__substrate=_flow_changed(ZINC_BULK, B_Pa=float("nan"))),
                           r"JohnsonCook: B_Pa = nan"),
    "Johnson-Cook C inf": (_mutate(layers__substrate=_flow_changed(ZINC_BULK, C=float("inf"))),
                           r"JohnsonCook: C = inf is not allowed; it must be a finite number"),
    "Johnson-Cook Tm inf": (_mutate(layers__substrate=_flow_changed(ZINC_BULK, Tm_K=float("inf"))),
                            r"JohnsonCook: Tm_K = inf"),
    "initial temperature above the melting point": (
        _mutate(layers__substrate="zinc_bulk", outputs__initial_temperature_K=800),
        r"outputs\.initial_temperature_K = 800 K is not below the melting temperature Tm_K = 692\.68 K of the "
        r"substrate material 'zinc_bulk'"),
    "one length in two units": (_mutate(sphere__radius_mm=0.5), r"both sphere\.radius_um and sphere\.radius_mm given"),
    "one hardness in two units": (_mutate(layers__substrate={"rigid_plastic_hardness_MPa": 900,
                                                             "rigid_plastic_hardness_GPa": 2}),
                                  r"both layers\.substrate\.rigid_plastic_hardness_MPa and "
                                  r"layers\.substrate\.rigid_plastic_hardness_GPa given"),
    "material flow text": (_mutate(layers__substrate={**DX56.to_dict(), "flow": {"model": "constant",
                                                                                 "sigma_y_Pa": "hard"}}),
                           r"layers\.substrate\.flow\.sigma_y_Pa = 'hard' is not a number"),
}


@pytest.mark.parametrize("case", BAD, ids=list(BAD))
def test_bad_input_raises_value_error_naming_the_parameter(case):
    d, pattern = BAD[case]
    with pytest.raises(ValueError, match=pattern):
        Scene.from_dict(d)


def test_bad_input_in_constructors():
    with pytest.raises(ValueError, match=r"discretisation\.cfl"):
        Discretisation(cfl=0.51)
    with pytest.raises(ValueError, match=r"domain\.radius_m"):
        Domain(radius_m=-1.0)
    with pytest.raises(ValueError, match=r"sliding\.speed_m_s"):
        Sliding(speed_m_s=0.0)
    with pytest.raises(ValueError, match=r"layers\.coating"):
        Layers(substrate=DX56, coating_thickness_m=5e-6)
    # a feasible scene assembled from parts, then made infeasible with with_()
    s = Scene(layers=Layers(substrate=DX56), load_N=1.0, domain=Domain(radius_m=150e-6, length_m=1000e-6))
    with pytest.raises(ValueError, match=r"domain\.radius_m"):
        s.with_(domain=Domain(radius_m=40e-6, length_m=1000e-6))


@pytest.mark.parametrize("interface", [{"model": "proportional", "g": 1.0}, {"model": "boundary_layer", "Cp": 0.3}])
def test_unknown_or_missing_interface_key_is_a_value_error(interface):
    with pytest.raises(ValueError, match="interface"):
        Scene.from_dict(_mutate(interface=interface))


def test_the_boundary_layer_pressure_is_named_and_needs_the_grid_contact():
    d = _mutate(interface={"model": "boundary_layer", "Cp": 0.32, "np": 0.95})
    assert Scene.from_dict(d).interface.pressure == "particles"  # the default
    d["interface"]["pressure"] = "nodes"
    with pytest.raises(ValueError, match=r"interface\.pressure = 'nodes' is not one of \['particles', 'traction'\]"):
        Scene.from_dict(d)
    d["interface"]["pressure"] = "traction"
    assert Scene.from_dict(d).interface.pressure == "traction"
    d["discretisation"] = {**d.get("discretisation", {}), "contact": "particle"}
    with pytest.raises(ValueError, match=r"interface\.pressure = 'traction' needs discretisation\.contact"):
        Scene.from_dict(d)


def test_a_coating_without_its_thickness_is_refused_not_dropped():
    d = example_dict("coated_rigid_plastic")
    del d["layers"]["coating_thickness_um"]
    with pytest.raises(ValueError, match=r"layers\.coating_thickness \(_um, _mm or _m\) is missing or null although "
                                         r"layers\.coating"):
        Scene.from_dict(d)
    d["layers"]["coating_thickness_um"] = 0  # said so: an uncoated scene
    assert not Scene.from_dict(d).layers.coated


def test_exponents_without_a_decimal_point_are_numbers_everywhere_in_a_scene_file():
    """YAML 1.1 reads 5e-1 as text; the scene loader reads it as the number a user means, in every part."""
    text = (EXAMPLES[0].parent / "coated_rigid_plastic.yaml").read_text()
    d = yaml.safe_load(text)
    d["interface"] = {"model": "proportional", "f": "5e-1"}
    d["layers"]["coating"] = {**ZINC_COATING.to_dict(), "youngs_modulus_Pa": "90e9"}
    from_text = Scene.from_yaml(yaml.safe_dump(d).replace("'5e-1'", "5e-1").replace("'90e9'", "90e9"))
    from_dict = Scene.from_dict(d)  # the strings themselves (a dict from another YAML reader)
    for s in (from_text, from_dict):
        assert s.interface == ProportionalShear(f=0.5)
        assert s.layers.coating.youngs_modulus_Pa == 90e9
    flow = {"model": "constant", "sigma_y_MPa": "150e0"}
    s = Scene.from_dict(_mutate(layers__substrate={**DX56.to_dict(), "flow": flow}))
    assert s.layers.substrate.flow.sigma_y_Pa == 150e6  # _MPa converted inside the flow mapping too
    s = Scene.from_yaml(text.replace("coating: {rigid_plastic_hardness_MPa: 450}",
                                     "coating: {rigid_plastic_hardness_Pa: 45e7}"))
    assert s.layers.coating.flow.sigma_y_Pa == pytest.approx(150e6)  # H / 3, from a key in SI


@pytest.mark.parametrize("name", ["1e5", "5e-1", "2E3", "10"])
def test_names_that_look_like_numbers_stay_names_through_a_round_trip(name):
    s = replace(Scene.from_yaml(EXAMPLES[0].parent / "coated_rigid_plastic.yaml"), name=name)
    back = Scene.from_yaml(s.to_yaml())
    assert back == s and back.name == name
    coat = rigid_plastic(name, 450e6, coating=True)
    s = replace(s, layers=replace(s.layers, coating=coat))
    assert Scene.from_yaml(s.to_yaml()).layers.coating.name == name


def test_scene_file_errors_are_one_line_value_errors(tmp_path):
    broken = tmp_path / "broken.yaml"
    broken.write_text("name: x\nsphere: {radius_um: 200\nload_N: 3\n")
    with pytest.raises(ValueError, match=r"broken\.yaml: not valid YAML at line \d+, column \d+"):
        Scene.from_yaml(broken)
    with pytest.raises(ValueError, match="is a directory"):
        Scene.from_yaml(tmp_path)
    twice = tmp_path / "twice.yaml"  # PyYAML would keep the second value silently
    twice.write_text(broken.read_text().replace("{radius_um: 200\n", "{radius_um: 200}\nload_N: 100\n"))
    with pytest.raises(ValueError, match=r"twice\.yaml: not valid YAML at line 4, column 1: key 'load_N' is given "
                                         r"twice in one mapping"):
        Scene.from_yaml(twice)
    binary = tmp_path / "binary.yaml"
    binary.write_bytes(b"name: \xff x\n")  # not UTF-8 (nor UTF-16: no byte-order mark)
    with pytest.raises(ValueError, match=r"binary\.yaml: not valid YAML: unacceptable character #x00ff"):
        Scene.from_yaml(binary)
    merged = tmp_path / "merged.yaml"  # overriding a key a merge key (<<) brings in is not a duplicate
    example = (EXAMPLES_DIR / "coated_rigid_plastic.yaml").read_text()
    line = "discretisation: {particle_size_um: 10, particles_per_cell: 2, cfl: 0.3, mass_scaling: 1.0e+6}"
    assert line in example
    merged.write_text(example.replace(line, "discretisation: {<<: {particle_size_um: 20, cfl: 0.2}, cfl: 0.25}"))
    assert (Scene.from_yaml(merged).discretisation.cfl, Scene.from_yaml(merged).discretisation.particle_size_m
            ) == (0.25, pytest.approx(20e-6))
    utf16 = tmp_path / "utf16.yaml"  # a byte-order mark: valid YAML in UTF-16, read as such whatever the locale
    utf16.write_bytes("name: µ\nload_N: 1\nload_N: 2\n".encode("utf-16"))
    with pytest.raises(ValueError, match=r"key 'load_N' is given twice"):
        Scene.from_yaml(utf16)


def test_a_scene_too_large_for_the_memory_is_refused_before_allocating():
    s = Scene.from_yaml(EXAMPLES[0].parent / "uncoated_rigid_plastic.yaml")
    solver.check_memory(s, available_bytes=10**12)  # the example fits in 1 TB
    small = replace(s, discretisation=replace(s.discretisation, particle_size_m=0.1e-6))
    with pytest.raises(ValueError, match=r"discretisation\.particle_size_m = 1e-07 m gives at least .* particles"):
        solver.check_memory(small, available_bytes=10**12)
    graded = replace(small, discretisation=replace(small.discretisation, graded=True))
    n = 0.25 * math.pi * s.domain.radius_m**2 * s.domain.length_m / 1e-21
    solver.check_memory(graded, available_bytes=int(n / 8 * solver.STATE_BYTES_PER_PARTICLE) + 1)  # the lower bound
    with pytest.raises(ValueError, match="GiB"):
        solver.check_memory(graded, available_bytes=int(n / 8 * solver.STATE_BYTES_PER_PARTICLE) - 1)


def test_part_that_is_not_a_mapping_is_a_value_error():
    with pytest.raises(ValueError, match="sphere"):
        Scene.from_dict(_mutate(sphere=200))


# ----------------------------------------------------------------------------- seeding
def coated_scene(t_um=25.0, h_um=10.0, symmetric=True):
    d = example_dict("coated_rigid_plastic")
    d["layers"]["coating_thickness_um"] = t_um
    d["discretisation"]["particle_size_um"] = h_um
    d["domain"]["symmetric"] = symmetric
    return Scene.from_dict(d)


@pytest.fixture(scope="module")
def coated_init():
    scene = coated_scene()
    state, const = solver.init(scene, n_chunks=1)
    return scene, state.particles, const


def test_straddling_particles_carry_both_materials(coated_init):
    scene, p, const = coated_init
    h = 10e-6
    z = p.x[:, 2]
    layer = np.rint(-z / h - 0.5).astype(int)  # 0 = top layer
    np.testing.assert_allclose(z, -(layer + 0.5) * h, atol=1e-9 * h)
    coat_row, sub_row = 0, 1
    assert const.table[coat_row, I_RHO] == ZINC_COATING.density_kg_m3  # rigid-plastic coating: zinc data
    assert const.table[sub_row, I_RHO] == DX56.density_kg_m3
    straddle = layer == 2  # centre at z = -25 um = -t: half of its cube lies above the interface
    assert straddle.sum() > 0
    np.testing.assert_allclose(p.frac_a[straddle], 0.5, rtol=1e-12)
    assert np.all(p.mat_a[straddle] == coat_row) and np.all(p.mat_b[straddle] == sub_row)
    assert np.all(p.mat_a[straddle] != p.mat_b[straddle])
    top = layer < 2
    assert np.all(p.mat_a[top] == coat_row) and np.all(p.frac_a[top] == 1.0)
    below = layer > 2
    assert np.all(p.mat_a[below] == sub_row) and np.all(p.mat_b[below] == sub_row)
    assert np.all(p.frac_a[below] == 1.0)


def test_particles_fill_the_quarter_cylinder(coated_init):
    scene, p, _ = coated_init
    R, L, h = scene.domain.radius_m, scene.domain.length_m, scene.discretisation.particle_size_m
    x = p.x
    assert np.all((x[:, 0] > 0) & (x[:, 0] < L))
    assert np.all(x[:, 1] > 0)
    assert np.all(x[:, 2] < 0)
    assert np.all(x[:, 1] ** 2 + x[:, 2] ** 2 <= R * R * (1 + 1e-12))
    assert x[:, 2].max() == pytest.approx(-0.5 * h)  # the top faces lie on z = 0
    np.testing.assert_allclose(p.vol0, h**3)
    volume = p.vol0.sum()
    assert volume == pytest.approx(math.pi * R * R * L / 4, rel=0.03)
    assert np.all(p.J == 1.0) and np.all(p.v == 0.0) and np.all(p.stress == 0.0) and np.all(p.eps_p == 0.0)
    assert np.all(p.temperature == scene.outputs.initial_temperature_K)


def test_full_cylinder_without_symmetry():
    scene = coated_scene(symmetric=False)
    state, _ = solver.init(scene, n_chunks=1)
    p = state.particles
    R, L = scene.domain.radius_m, scene.domain.length_m
    assert (p.x[:, 1] < 0).sum() == (p.x[:, 1] > 0).sum()
    assert p.vol0.sum() == pytest.approx(math.pi * R * R * L / 2, rel=0.03)


def test_masses_are_layer_density_times_mass_scaling_times_volume(coated_init):
    scene, p, _ = coated_init
    h, t = 10e-6, 25e-6
    ms = scene.discretisation.mass_scaling
    rho_c, rho_s = ZINC_COATING.density_kg_m3, DX56.density_kg_m3
    layer = np.rint(-p.x[:, 2] / h - 0.5).astype(int)
    coating_fraction = np.clip((t - layer * h) / h, 0.0, 1.0)  # of each layer's cube
    v_coat = (coating_fraction * p.vol0).sum()
    v_all = p.vol0.sum()
    assert p.mass.sum() == pytest.approx(ms * (rho_c * v_coat + rho_s * (v_all - v_coat)), rel=1e-12)
    for k, rho in ((0, rho_c), (1, rho_c), (2, 0.5 * (rho_c + rho_s)), (3, rho_s), (10, rho_s)):
        np.testing.assert_allclose(p.mass[layer == k], rho * ms * h**3, rtol=1e-12)
    # the coating volume is t times the top face's area (the block's top is R x L with symmetry)
    R, L = scene.domain.radius_m, scene.domain.length_m
    assert v_coat == pytest.approx(t * R * L, rel=0.03)


def test_thin_coating_is_one_straddling_layer():
    scene = coated_scene(t_um=3.0)
    text = io.coating_representation(scene)
    assert "0 full particle layer(s)" in text and "straddles" in text and "0.3" in text
    p = solver.init(scene, n_chunks=1)[0].particles
    top = p.x[:, 2] > -10e-6
    np.testing.assert_allclose(p.frac_a[top], 0.3, rtol=1e-12)
    assert np.all(p.mat_a[top] == 0) and np.all(p.mat_b[top] == 1)
    assert np.all(p.mat_a[~top] == 1) and np.all(p.frac_a[~top] == 1.0)


@pytest.mark.parametrize("t_um,full", [(25.0, 2), (20.0, 2), (10.0, 1)])
def test_coating_representation(t_um, full):
    text = io.coating_representation(coated_scene(t_um=t_um))
    assert text.startswith(f"{full} full particle layer(s)")
    assert ("straddles" in text) == (t_um % 10 != 0)
    uncoated = Scene.from_dict(example_dict())
    assert io.coating_representation(uncoated) == "uncoated"


@pytest.mark.parametrize("t_m,h_m,full", [(30e-6, 10e-6, 3), (15e-6, 2.5e-6, 6), (15e-6, 5e-6, 3)])
def test_coating_representation_exact_multiples_in_si(t_m, h_m, full):
    d = example_dict("coated_rigid_plastic")
    del d["layers"]["coating_thickness_um"]
    d["layers"]["coating_thickness_m"] = t_m  # SI keys, as a script or a config in metres gives them
    d["discretisation"]["particle_size_m"] = h_m
    del d["discretisation"]["particle_size_um"]
    text = io.coating_representation(Scene.from_dict(d))
    assert text.startswith(f"{full} full particle layer(s)") and "straddles" not in text


def test_interface_default_and_expected_contact():
    s = Scene.from_dict(example_dict())
    assert s.interface == ProportionalShear(f=1.0)
    a, dp = s.expected_contact()
    assert 0 < dp < a < s.sphere.radius_m


def test_wave_limit_is_cos_squared_of_the_leading_edge_angle_of_the_expected_contact():
    """sin alpha = a / r of the analytical contact: 46.1 um on the uncoated reference scene (0.947), 65.1 um
    on the coated one (0.894, between the f = 0.8 that settles and the f = 0.9 that does not;
    docs/journal/2026-11-24-inertia-ladder-and-wave-limit.md)."""
    for name, expected in (("uncoated_rigid_plastic", 0.947), ("coated_rigid_plastic", 0.894)):
        s = Scene.from_dict(example_dict(name))
        a, _ = s.expected_contact()
        assert s.wave_limit_ratio == pytest.approx(1.0 - (a / s.sphere.radius_m) ** 2, rel=1e-12)
        assert s.wave_limit_ratio == pytest.approx(expected, abs=5e-4), name
    coated = Scene.from_dict(example_dict("coated_rigid_plastic"))
    assert coated.with_(interface=ProportionalShear(f=0.9)).interface_sticks
    assert not coated.with_(interface=ProportionalShear(f=0.8)).interface_sticks
    # a heavier load widens the contact: a steeper leading edge, a lower limit
    assert coated.with_(load_N=6.0).wave_limit_ratio < coated.wave_limit_ratio
    # under displacement control the set depth cuts the contact: a^2 = 2 r d - d^2
    d = 4e-6
    held = coated.with_(sliding=replace(coated.sliding, control="displacement", depth_m=d))
    r = coated.sphere.radius_m
    assert held.wave_limit_ratio == pytest.approx(1.0 - (2 * r * d - d * d) / r**2, rel=1e-12)


def test_interface_strength_ratio_says_when_the_contact_can_stick():
    """tau / kappa of the top layer; at or above the wave limit on a perfectly plastic layer it is flagged in
    the output, because mu then follows the simulated speed
    (docs/journal/2026-11-24-inertia-ladder-and-wave-limit.md)."""
    f1 = Scene.from_dict(example_dict())  # uncoated 900 MPa, proportional f = 1
    assert f1.interface_strength_ratio == 1.0 and f1.interface_sticks
    assert "prow" in io.interface_regime(f1) and "cos^2 alpha = 0.947" in io.interface_regime(f1)
    half = f1.with_(interface=ProportionalShear(f=0.5))
    assert half.interface_strength_ratio == 0.5 and not half.interface_sticks
    assert io.interface_regime(half).startswith("tau = 0.5 kappa")
    assert "below the wave limit cos^2 alpha = 0.947" in io.interface_regime(half)
    limit = f1.wave_limit_ratio
    assert f1.sticking_ratio == 1.0 and half.sticking_ratio is None
    assert f1.with_(interface=ProportionalShear(f=limit)).interface_sticks
    assert not f1.with_(interface=ProportionalShear(f=limit * (1 - 1e-9))).interface_sticks
    # constant tau = 450 MPa / (3 sqrt 3) = 86.6 MPa against kappa = 300 MPa / sqrt 3 = 173.2 MPa of the substrate
    const = f1.with_(interface=ConstantShear(H0_Pa=450e6))
    assert const.interface_strength_ratio == pytest.approx(0.5, rel=1e-12) and not const.interface_sticks
    # on a 225 MPa coating (kappa 43.3 MPa) the same tau is capped at kappa: it sticks
    soft = Scene.from_dict(example_dict("coated_rigid_plastic"))
    soft = soft.with_(interface=ConstantShear(H0_Pa=450e6),
                      layers=Layers(substrate=soft.layers.substrate, coating=rigid_plastic("c225", 225e6, coating=True),
                                    coating_thickness_m=25e-6))
    assert soft.interface_strength_ratio == 1.0 and soft.interface_sticks
    # a hardening coating at f = 1 has a quasi-static limit: not flagged; a pressure-dependent one has no ratio
    zinc = Scene.from_yaml(EXAMPLES[0].parent / "zinc_coated_steel.yaml")
    assert zinc.interface_strength_ratio is None and not zinc.interface_sticks
    assert zinc.with_(interface=ProportionalShear(f=1.0)).interface_sticks is False
    assert io.interface_regime(zinc).startswith("pressure-dependent")
    capped = zinc.with_(interface=ConstantShear(H0_Pa=450e6))  # tau 86.6 MPa above the zinc coating's kappa
    assert capped.interface_strength_ratio == 1.0 and not capped.interface_sticks
    assert "strain-hardening" in io.interface_regime(capped)
    # between the wave limit and 1 on a hardening surface: not flagged, and not said to be below the limit
    strong = zinc.with_(interface=ProportionalShear(f=0.99))
    assert strong.wave_limit_ratio < 0.99 and not strong.interface_sticks and strong.sticking_ratio is None
    text = io.interface_regime(strong)
    assert "strain-hardening" in text and "at or above the wave limit" in text and "below" not in text


def _coated_constant_scene(t_um: float, hc_MPa: float, hs_MPa: float, h_um: float = 10.0) -> Scene:
    d = example_dict("coated_rigid_plastic")
    d["layers"] = {"coating_thickness_um": t_um, "coating": {"rigid_plastic_hardness_MPa": hc_MPa},
                   "substrate": {"rigid_plastic_hardness_MPa": hs_MPa}}
    d["interface"] = {"model": "constant", "H0_MPa": 450}
    d["discretisation"]["particle_size_um"] = h_um
    return Scene.from_dict(d)


@pytest.mark.parametrize("t_um", [25.0, 5.0, 2.0])
def test_interface_strength_ratio_is_the_solvers_tau_over_kappa_on_the_top_particle(t_um):
    """A coating thinner than a particle: the top particle is the volume-weighted mix, and the ratio
    follows the solver's own kappa of that particle (450 MPa coating on 900 MPa, constant tau 86.6 MPa)."""
    from plough.mpm.constitutive import mixed_flow_stress

    scene = _coated_constant_scene(t_um, 450.0, 900.0)
    state, const = solver.init(scene)
    p = state.particles
    top = int(np.argmax(p.x[:, 2]))
    kappa = mixed_flow_stress(const.table[p.mat_a[top]], const.table[p.mat_b[top]], p.frac_a[top], 0.0, 0.0,
                              p.temperature[top]) / math.sqrt(3.0)
    tau = contact.interface_shear(const.interface_model, const.interface_params, 0.0, kappa)
    assert scene.interface_strength_ratio == pytest.approx(tau / kappa, rel=1e-12)
    assert scene.interface_sticks == (t_um == 25.0)  # 25 um: tau = kappa of the coating; thinner: the mix is harder


def test_interface_ratio_counts_the_substrate_once_the_sphere_ploughs_through():
    """900 MPa coating 2 um thick on a 450 MPa substrate: the expected groove (9.5 um) reaches the
    substrate, whose kappa equals the constant tau: it sticks although the top particle does not."""
    scene = _coated_constant_scene(2.0, 900.0, 450.0)
    assert scene.expected_contact()[1] > 2e-6
    assert scene.interface_strength_ratio == 1.0 and scene.interface_sticks
    thick = _coated_constant_scene(100.0, 900.0, 450.0)
    assert thick.expected_contact()[1] < 100e-6
    assert thick.interface_strength_ratio == pytest.approx(0.5, rel=1e-12) and not thick.interface_sticks


def test_inertia_number_of_the_reference_scene():
    """ms rho v^2 / H: 1e6 x 7850 kg/m^3 x (0.1 m/s)^2 / 900 MPa (0.087, docs/model.md 3.3)."""
    s = Scene.from_dict(example_dict())
    assert s.inertia_number == pytest.approx(1e6 * s.layers.substrate.density_kg_m3 * 0.01 / 900e6, rel=1e-12)
    assert 0.08 < s.inertia_number < 0.09


def test_paper_preset_sets_the_papers_numerics_and_keeps_the_physics():
    from plough.mpm.run import apply_preset

    s = Scene.from_yaml(Path(__file__).resolve().parents[2] / "examples" / "coated_rigid_plastic.yaml")
    s = s.with_(sliding=Sliding(distance_m=500e-6, speed_m_s=0.05, stop_when_steady=True),
                discretisation=Discretisation(particle_size_m=5e-6, mass_scaling=1e4, cfl=0.2))
    p = apply_preset(s, "paper")
    assert (p.domain.radius_m, p.domain.length_m, p.domain.symmetric) == (200e-6, 1000e-6, True)
    assert (p.sliding.distance_m, p.sliding.speed_m_s, p.discretisation.mass_scaling) == (600e-6, 0.1, 1e6)
    assert not p.sliding.stop_when_steady  # the paper slides the whole 0.6 mm
    assert p.outputs.steady_window == (0.5, 1.0)
    # physics and the resolution are the scene's own
    assert (p.layers, p.load_N, p.sphere, p.interface) == (s.layers, s.load_N, s.sphere, s.interface)
    assert (p.discretisation.particle_size_m, p.discretisation.cfl) == (5e-6, 0.2)
    assert apply_preset(s, None) is s
    assert apply_preset(s, "sized").domain == s.with_sized_domain().domain
    with pytest.raises(ValueError, match="preset = 'fast' is unknown"):
        apply_preset(s, "fast")


def test_headroom_is_validated_round_trips_and_survives_the_presets():
    s = Scene.from_yaml(Path(__file__).resolve().parents[2] / "examples" / "coated_rigid_plastic.yaml")
    _, dp = s.expected_contact()
    for h in (10e-6, 2.5e-6):  # two cells set it at h = 10 um, the groove at h = 2.5 um
        fine = s.with_(discretisation=replace(s.discretisation, particle_size_m=h))
        assert fine.grid_headroom_m >= 2.5 * dp and fine.grid_headroom_m >= 2 * fine.discretisation.cell_size_m
    assert fine.grid_headroom_m == pytest.approx(2.5 * dp, rel=1e-12)
    d = s.to_dict()
    assert d["domain"]["headroom_m"] is None
    del d["domain"]["headroom_m"]
    d["domain"]["headroom_um"] = 150
    tall = Scene.from_dict(d)
    assert tall.domain.headroom_m == pytest.approx(150e-6) and tall.grid_headroom_m == pytest.approx(150e-6)
    assert Scene.from_yaml(tall.to_yaml()) == tall
    assert tall.with_sized_domain().domain.headroom_m == tall.domain.headroom_m
    assert tall.with_paper_settings().domain.headroom_m == tall.domain.headroom_m
    for bad in (0.0, -1e-6, float("nan")):
        with pytest.raises(ValueError, match=r"domain\.headroom_m"):
            Domain(headroom_m=bad)


def test_active_zone_round_trips_and_the_paper_preset_updates_every_particle():
    s = Scene.from_yaml(Path(__file__).resolve().parents[2] / "examples" / "coated_rigid_plastic.yaml")
    assert s.discretisation.active_zone_contact_radii is None
    d = s.to_dict()
    d["discretisation"]["active_zone_contact_radii"] = "3.0e0"  # YAML 1.1 reads it as a string
    zoned = Scene.from_dict(d)
    assert zoned.discretisation.active_zone_contact_radii == 3.0
    assert Scene.from_yaml(zoned.to_yaml()) == zoned
    assert zoned.with_sized_domain().discretisation.active_zone_contact_radii == 3.0
    assert zoned.with_paper_settings().discretisation.active_zone_contact_radii is None
