"""docs/scenes.md against the scene reader: every key documented, every documented key real, every default right.

The key tables of docs/scenes.md (header ``| key | unit | default | allowed | meaning |``) are parsed and compared
with the dataclasses the YAML reader builds (``plough.mpm.scene``, ``plough.materials``), so that adding a field or
changing a default without updating the page fails here. Defaults are read as YAML, converted by the key's unit
suffix with the reader's own conversion (``_um`` -> ``_m`` and so on) and compared with the dataclass default.
"""

from __future__ import annotations

import dataclasses
import math
import re
import textwrap
from pathlib import Path
from typing import Any

import pytest
import yaml

from plough.materials import FLOW_MODELS, INTERFACES, MATERIALS, Material, interface_from_dict
from plough.mpm import io
from plough.mpm.scene import Discretisation, Domain, Layers, Outputs, Scene, Sliding, Sphere, _to_si, material_from_spec

DOC = Path(__file__).resolve().parents[2] / "docs" / "scenes.md"
HEADER = ["key", "unit", "default", "allowed", "meaning"]
#: the scene's sections that are plain dataclasses read key by key (``scene._from_dict``)
SECTIONS: dict[str, type] = {"sphere": Sphere, "domain": Domain, "sliding": Sliding, "discretisation": Discretisation,
                             "outputs": Outputs}
#: the keys of the rigid-plastic shorthand ``{rigid_plastic_hardness_MPa: H}``, which scene.material_from_spec
#: spells out itself (no dataclass holds them)
RIGID_PLASTIC_KEYS = {"rigid_plastic_hardness_Pa", "name"}
#: unit column expected for a key's unit suffix (longest suffix first); other keys must say something (``-``)
UNITS = {"_kg_m3": "kg/m³", "_J_kgK": "J/(kg K)", "_W_mK": "W/(m K)", "_per_s": "1/s", "_m_s": "m/s",
         "_MPa": "MPa", "_GPa": "GPa", "_Pa": "Pa", "_um": "µm", "_mm": "mm", "_eV": "eV", "_m": "m", "_N": "N",
         "_K": "K"}
MINIMAL_LAYERS = {"substrate": {"rigid_plastic_hardness_MPa": 900}}
REQUIRED = "required"
_CELL = re.compile(r"^`?(.*?)`?$")
_SEGMENT = re.compile(r"^(\w+)(?:\[(\w+)\])?$")


def _cells(line: str) -> list[str]:
    return [c.strip() for c in line.strip().strip("|").split("|")]


def doc_rows() -> list[dict[str, str]]:
    """Rows of every key table of the page (indented tables too), as {column: text without backticks}."""
    rows, in_table = [], False
    for line in DOC.read_text(encoding="utf-8").splitlines():
        text = line.strip()
        if not text.startswith("|"):
            in_table = False
            continue
        cells = _cells(text)
        if cells == HEADER:
            in_table = True
            continue
        if not in_table or set(text) <= set("|-: "):
            continue
        assert len(cells) == len(HEADER), f"docs/scenes.md: a key row needs {len(HEADER)} cells: {text!r}"
        rows.append({k: _CELL.match(v).group(1) for k, v in zip(HEADER, cells, strict=True)})
    return rows


ROWS = doc_rows()


def parse_key(path: str) -> tuple[tuple[str, str | None], ...]:
    """``material.flow[johnson_cook].A_MPa`` -> (("material", None), ("flow", "johnson_cook"), ("A_MPa", None))."""
    segments = []
    for part in path.split("."):
        m = _SEGMENT.match(part)
        assert m, f"docs/scenes.md: key {path!r} does not follow the notation a.b[variant].c"
        segments.append((m.group(1), m.group(2)))
    return tuple(segments)


def si_key(key: str, value: Any = None) -> tuple[str, Any]:
    """The reader's own conversion of one key and value (``radius_um``, 200 -> ``radius_m``, 2e-4)."""
    ((name, converted),) = _to_si({key: value}).items()
    return name, converted


def target(path: str) -> tuple[Any, str]:
    """(owner, SI field name) of a documented key; owner is a dataclass, or a marker string for the keys that
    select a model (``interface.model``, ``material.flow.model``) and for the rigid-plastic shorthand."""
    segs = parse_key(path)
    last = si_key(segs[-1][0])[0]
    names = tuple(s for s, _ in segs)
    variants = tuple(v for _, v in segs)
    if len(segs) == 1:
        return Scene, last
    if len(segs) == 2 and names[0] in SECTIONS and variants == (None, None):
        return SECTIONS[names[0]], last
    if names[0] == "layers" and len(segs) == 2 and variants == (None, None):
        return Layers, last
    if names[0] == "interface" and len(segs) == 2:
        if variants[0] is None:
            return "interface", last
        return INTERFACES[variants[0]], last
    if names[0] == "material":
        if variants[0] == "rigid_plastic" and len(segs) == 2:
            return "rigid_plastic", last
        if len(segs) == 2 and variants == (None, None):
            return Material, last
        if len(segs) == 3 and names[1] == "flow" and variants[0] is None:
            if variants[1] is None:
                return "flow", last
            return FLOW_MODELS[variants[1]], last
    raise AssertionError(f"docs/scenes.md: key {path!r} is not a key of a scene file")


def accepted_keys() -> set[tuple[Any, str]]:
    """Every (owner, SI field) the YAML reader accepts, from the dataclasses it builds."""
    keys = {(Scene, f.name) for f in dataclasses.fields(Scene)}
    keys |= {(cls, f.name) for cls in SECTIONS.values() for f in dataclasses.fields(cls)}
    keys |= {(Layers, f.name) for f in dataclasses.fields(Layers)}
    keys |= {("interface", "model")} | {(cls, f.name) for cls in INTERFACES.values() for f in dataclasses.fields(cls)}
    keys |= {(Material, f.name) for f in dataclasses.fields(Material) if f.name != "flow"} | {("flow", "model")}
    keys |= {(cls, f.name) for cls in FLOW_MODELS.values() for f in dataclasses.fields(cls)}
    keys |= {("rigid_plastic", k) for k in RIGID_PLASTIC_KEYS}
    return keys


def documented_value(row: dict[str, str]) -> Any:
    """The default column as YAML, in the unit of the key (numbers such as 1e6 that YAML 1.1 reads as text too)."""
    value = yaml.safe_load(row["default"])
    if isinstance(value, str):
        try:
            value = float(value)
        except ValueError:
            pass
    return value


def same(documented: Any, actual: Any) -> bool:
    if isinstance(actual, tuple) and isinstance(documented, list):
        documented = tuple(documented)
    if isinstance(actual, tuple) and isinstance(documented, tuple):
        return len(actual) == len(documented) and all(same(d, a) for d, a in zip(documented, actual, strict=True))
    if isinstance(actual, bool) or isinstance(documented, bool) or actual is None or documented is None:
        return documented is actual
    if isinstance(actual, int | float) and isinstance(documented, int | float):
        return math.isclose(documented, actual, rel_tol=1e-12, abs_tol=0.0)
    return documented == actual


def close(a: Any, b: Any) -> bool:
    """Nested dicts and lists equal, numbers to round-off (200 um is 200 * 1e-6 m, not quite 2e-4)."""
    if isinstance(a, dict) and isinstance(b, dict):
        return a.keys() == b.keys() and all(close(a[k], b[k]) for k in a)
    if isinstance(a, list | tuple) and isinstance(b, list | tuple):
        return len(a) == len(b) and all(close(x, y) for x, y in zip(a, b, strict=True))
    return same(a, b)


def field_of(cls: type, name: str) -> dataclasses.Field:
    found = [f for f in dataclasses.fields(cls) if f.name == name]
    assert found, f"docs/scenes.md documents {cls.__name__}.{name}, which the scene reader does not know"
    return found[0]


# ----------------------------------------------------------------------------- the tests
def test_the_page_has_key_tables():
    assert len(ROWS) > 50, "docs/scenes.md: the key tables were not found (header | key | unit | default | ...)"


def test_every_key_is_documented_once_and_every_documented_key_exists():
    documented = [target(row["key"]) for row in ROWS]
    twice = {k for k in documented if documented.count(k) > 1}
    assert not twice, f"docs/scenes.md documents these keys twice: {sorted(map(str, twice))}"
    accepted = accepted_keys()
    missing = sorted(f"{getattr(o, '__name__', o)}.{k}" for o, k in accepted - set(documented))
    unknown = sorted(f"{getattr(o, '__name__', o)}.{k}" for o, k in set(documented) - accepted)
    assert not missing, f"keys the scene reader accepts but docs/scenes.md does not list: {missing}"
    assert not unknown, f"keys docs/scenes.md lists but the scene reader does not accept: {unknown}"


@pytest.mark.parametrize("row", ROWS, ids=lambda r: r["key"])
def test_documented_default_is_the_dataclass_default(row):
    owner, name = target(row["key"])
    last = parse_key(row["key"])[-1][0]
    required = row["default"] == REQUIRED
    if owner == "interface":  # the model must be named in an interface mapping
        assert required
        with pytest.raises(ValueError):
            interface_from_dict({})
        return
    if owner == "flow":
        assert required
        spec = MATERIALS["zinc_bulk"].to_dict()
        del spec["flow"]["model"]
        with pytest.raises(ValueError):
            material_from_spec(spec, coating=False, where="layers.substrate")
        return
    if owner == "rigid_plastic":
        if name == "rigid_plastic_hardness_Pa":
            assert required
            with pytest.raises(ValueError):
                material_from_spec({"name": "x"}, coating=False, where="layers.substrate")
        else:  # the name the shorthand makes up: the documented pattern with H = 900 MPa
            expected = row["default"].replace("<H>", "900")
            assert material_from_spec({"rigid_plastic_hardness_MPa": 900}, coating=False, where="x").name == expected
        return
    field = field_of(owner, name)
    has_default = field.default is not dataclasses.MISSING or field.default_factory is not dataclasses.MISSING
    if required:
        assert not has_default, f"{row['key']} is documented as required but has a default in {owner.__name__}"
        return
    assert has_default, f"{row['key']} is documented with a default but {owner.__name__}.{name} has none"
    documented = documented_value(row)
    if field.default_factory is not dataclasses.MISSING:  # a section of the scene: read the documented mapping
        assert isinstance(documented, dict), f"{row['key']}: the default of a section is a mapping"
        scene = Scene.from_dict({"layers": MINIMAL_LAYERS, name: documented})
        assert getattr(scene, name) == field.default_factory(), f"{row['key']}: documented default is not the default"
        return
    si_name, si_value = si_key(last, documented)
    assert si_name == name
    assert same(si_value, field.default), (f"docs/scenes.md: {row['key']} = {row['default']} ({si_value!r} in SI) "
                                           f"but {owner.__name__}.{name} defaults to {field.default!r}")


@pytest.mark.parametrize("row", [r for r in ROWS if r["default"] != REQUIRED], ids=lambda r: r["key"])
def test_the_reader_accepts_the_documented_default(row):
    """Each optional key, written as documented with its default, reads into the same scene as leaving it out."""
    segs = parse_key(row["key"])
    owner, _ = target(row["key"])
    value = documented_value(row)
    if owner in ("rigid_plastic",) or owner in FLOW_MODELS.values():
        return  # no optional keys there but the made-up name, checked above
    if len(segs) == 1:
        given, plain = {"layers": MINIMAL_LAYERS, segs[0][0]: value}, {"layers": MINIMAL_LAYERS}
    elif segs[0][0] == "interface":
        model = segs[0][1]
        # the model's required keys (Table 5's zinc lubricant for the boundary layer), so only the optional one differs
        required = {"boundary_layer": {"Cp": 0.32, "np": 0.95}}.get(model, {})
        given = {"layers": MINIMAL_LAYERS, "interface": {"model": model, **required, segs[1][0]: value}}
        plain = {"layers": MINIMAL_LAYERS, "interface": {"model": model, **required}}
    elif segs[0][0] == "layers":
        given = {"layers": dict(MINIMAL_LAYERS) | {segs[1][0]: value}}
        plain = {"layers": MINIMAL_LAYERS}
    else:
        given = {"layers": MINIMAL_LAYERS, segs[0][0]: {segs[1][0]: value}}
        plain = {"layers": MINIMAL_LAYERS}
    assert close(Scene.from_dict(given).to_dict(), Scene.from_dict(plain).to_dict())


def test_the_unit_column_follows_the_key():
    for row in ROWS:
        last = parse_key(row["key"])[-1][0]
        unit = next((u for suffix, u in UNITS.items() if last.endswith(suffix)), None)
        if unit is not None:
            assert row["unit"] == unit, f"docs/scenes.md: {row['key']} is in {unit}, the unit column says {row['unit']}"
        else:
            assert row["unit"], f"docs/scenes.md: {row['key']} has an empty unit column"


def test_every_named_material_and_result_variable_is_on_the_page():
    text = DOC.read_text(encoding="utf-8")
    for name in MATERIALS:
        assert f"| `{name}` |" in text, f"docs/scenes.md: the named material {name!r} is not in the materials table"
    variables = [*io.SERIES_META, *io.STEADY_META, *io.STANDARD_ERROR_META, *io.STEADINESS_META,
                 *io.CONTACT_SUMMARY_META]
    absent = [v for v in variables if f"`{v}`" not in text]
    assert not absent, f"docs/scenes.md: result variables not described: {absent}"


def yaml_blocks() -> list[str]:
    return re.findall(r"```yaml\n(.*?)```", DOC.read_text(encoding="utf-8"), flags=re.S)


def test_the_pages_yaml_examples_read():
    """The scene at the top is examples/coated_rigid_plastic.yaml; the full material mapping is bulk zinc."""
    scene, material = yaml_blocks()
    example = Path(__file__).resolve().parents[2] / "examples" / "coated_rigid_plastic.yaml"
    assert Scene.from_yaml(scene) == Scene.from_yaml(example)
    spec = yaml.safe_load(textwrap.dedent(material))["substrate"]
    read = material_from_spec(spec, coating=False, where="layers.substrate")
    assert close(dataclasses.asdict(read) | {"name": ""}, dataclasses.asdict(MATERIALS["zinc_bulk"]) | {"name": ""})
