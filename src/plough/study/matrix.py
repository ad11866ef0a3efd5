"""The MPM study matrix of studies.md: workflow config -> scenes (one per run) and figure plans.

A figure is a set of *panels*; a panel is a set of *series* (curves) along one study axis
(hardness ratio H~, coating thickness t or load); each point of a series is one physical scene,
run at every configured particle size h and extrapolated to h -> 0. Single-run figures (pictures
and force histories) use one scene at the finest size.

Scenes are keyed by what makes them physically distinct (materials, thickness, interface, ball,
load), so a scene shared by several figures (Figs. 11 and 13, 15 and 20, ...) is one run. The run
id is ``<scene key>_h<h in um>``; its scene dict is complete and in SI units (materials expanded),
so the workflow can pass it through ``params:`` and rerun exactly the runs whose physics changed.

Analytical values on the same coordinates use eqs. 1-5 with each layer's hardness: H for the
rigid-plastic studies, 3 sigma_y at a plastic strain of 0.08 (Tabor) for the real materials.
"""

from __future__ import annotations

import json
import math
import re
from dataclasses import dataclass, field, replace
from functools import cache
from pathlib import Path
from typing import Any

import numpy as np

from plough.materials import (
    DEFAULT_BOUNDARY_LAYER_PRESSURE,
    ConstantFlow,
    ConstantShear,
    Interface,
    ProportionalShear,
    interface_from_dict,
    interface_to_dict,
    representative_hardness,
)
from plough.mpm.scene import (
    Discretisation,
    Domain,
    Layers,
    Outputs,
    Scene,
    Sliding,
    Sphere,
    expected_contact,
    material_from_spec,
    sized_domain,
)
from plough.study import cost

#: Steady-state outputs extrapolated to h -> 0 (named as in the analytical model).
OUTPUTS = ("mu", "mu_pl", "mu_sh", "dp", "dg", "hpu", "penetration")
#: Outputs the analytical model gives on the same coordinates.
ANALYTICAL_OUTPUTS = ("mu", "mu_pl", "mu_sh", "dp")
SWEEP_FIGURES = ("fig11", "fig13", "fig15", "fig16", "fig18", "fig20", "fig21", "fig23")
SINGLE_RUN_FIGURES = ("fig12", "fig14", "fig17", "fig19")
MPM_FIGURES = tuple(sorted(SWEEP_FIGURES + SINGLE_RUN_FIGURES))
#: ``mpm.finest_failure``: what a finest sweep run that stops unstable leaves (docs/workflow.md)
FINEST_FAILURE_CHOICES = ("record", "stop")
FINEST_FAILURE_DEFAULT = "record"
#: ``mpm.ladder``: the particle sizes of each MPM point (``point_ladder``; docs/workflow.md, "The ladder")
LADDER_CHOICES = ("paper", "relative")
LADDER_DEFAULT = "paper"
#: ``mpm.ladder_targets`` of the relative ladder: particles across each length at a point's finest size
LADDER_TARGETS = ("contact_radius_particles", "groove_depth_particles", "coating_particles")
#: ``mpm.ladder_sizes_per_octave`` of the relative ladder: 1 = a point's sizes are the paper's times 2^k; 2 = also
#: times 2^k x the paper's finest size x sqrt(2) rounded to two digits (3.5 um for 2.5): a finest size within a
#: factor 1.43, not 2, of the coarsest that meets the targets (docs/workflow.md, "The ladder")
LADDER_SIZES_PER_OCTAVE_CHOICES = (1, 2)
LADDER_SIZES_PER_OCTAVE_DEFAULT = 2
#: targets whose finest size refinement only where needed never stands in for (``skippable_runs``): such a target
#: added that size because it judged the two sizes above it too coarse for the groove or the coating, so letting
#: those two stand in would undo it; where the contact target asks for the same size (a tie) the contact's gate
#: applies (docs/workflow.md, "Refinement only where needed")
UNGATED_TARGETS = ("groove_depth_particles", "coating_particles")

AXES = {
    "hardness_ratio": ("1", "coating to substrate hardness ratio H~ = Hc / Hs"),
    "thickness_um": ("um", "coating thickness t"),
    "load_N": ("N", "normal load Fn"),
}


def fmt(x: float) -> str:
    """One spelling per value for keys and wildcards (25.0 and 25 are the same run)."""
    return f"{float(x):g}"


# ----------------------------------------------------------------------------- the config's numbers
#: the workflow's config schema (the Snakefile validates the config against it before anything else)
CONFIG_SCHEMA = Path(__file__).resolve().parents[3] / "workflow" / "schemas" / "config.schema.yaml"
#: text that reads as a number (the schema's ``number`` definition): YAML 1.1 reads 3e-1 as text
_NUMBER_TEXT = re.compile(r"[-+]?([0-9]+[.]?[0-9]*|[.][0-9]+)([eE][-+]?[0-9]+)?")


def _key_path(parts: Any) -> str:
    """``mpm.numerics.cfl``, ``analytical.thickness_um[1]``: a key path as the messages name it."""
    out = ""
    for part in parts:
        out += f"[{part}]" if isinstance(part, int) else (f".{part}" if out else str(part))
    return out


def _numbers_read(node: Any, path: tuple = ()) -> list[tuple[tuple, str]]:
    """Convert, in place, text that reads as a number to the number; returns (path, text) of each."""
    read = []
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, value in list(items):
        if isinstance(value, str) and _NUMBER_TEXT.fullmatch(value.strip()):
            node[key] = float(value)
            read.append(((*path, key), value))
        else:
            read += _numbers_read(value, (*path, key))
    return read


def _not_finite(node: Any, path: tuple = ()) -> tuple[tuple, float] | None:
    items = node.items() if isinstance(node, dict) else enumerate(node) if isinstance(node, list) else ()
    for key, value in items:
        if isinstance(value, float) and not math.isfinite(value):
            return (*path, key), value
        found = _not_finite(value, (*path, key))
        if found is not None:
            return found
    return None


def check_config(config: dict[str, Any], schema: Path = CONFIG_SCHEMA) -> None:
    """The checks the schema cannot make, before any scene is built, each a one-line error naming the key path.

    * Text that reads as a number (``cfl: 3e-1``: YAML 1.1, which Snakemake reads config files with, takes an
      exponent without a dot for text; the schema lets it through as scene files do) becomes the number, in
      place, and the config is validated against ``schema`` again so that its range is checked too.
    * NaN and infinity are refused anywhere (a JSON schema's ranges let NaN through: every comparison with
      NaN is false).

    ``all_runs`` calls it first, so the workflow makes these checks when it builds its run matrix, before any job.
    """
    read = _numbers_read(config)
    bad = _not_finite(config)
    if bad is not None:
        raise ValueError(f"config: {_key_path(bad[0])} = {bad[1]:g} is not a finite number")
    if not read or not schema.exists():
        return
    import jsonschema
    import yaml

    validator = jsonschema.Draft202012Validator(yaml.safe_load(schema.read_text()))
    error = jsonschema.exceptions.best_match(validator.iter_errors(config))
    if error is not None:
        where = _key_path(error.absolute_path)
        given = dict(read).get(tuple(error.absolute_path))
        as_text = f" (given as {given!r})" if given is not None else ""
        raise ValueError(f"config: {where} = {error.instance!r}{as_text}: {error.message}")


#: scene key -> the ``mpm.numerics`` key (or ``mpm.particle_sizes_um``) it is made from (``scene_for``); the
#: domain's depend on its mode, the physical keys on the point (``Point.source``)
_NUMERICS_KEYS = {
    "discretisation.particle_size_m": "mpm.particle_sizes_um",
    **{f"discretisation.{k}": f"mpm.numerics.{k}" for k in (
        "particles_per_cell", "cfl", "mass_scaling", "flip", "dilatation", "graded", "fine_zone_contact_radii",
        "fine_zone_shape", "fine_zone_depth_particles", "active_zone_contact_radii")},
    "sliding.distance_m": "mpm.numerics.sliding_distance_um",
    "sliding.speed_m_s": "mpm.numerics.speed_m_s",
    "sliding.experiment_speed_m_s": "mpm.numerics.experiment_speed_m_s",
    "outputs.steady_window": "mpm.numerics.steady_window",
    "outputs.records": "mpm.numerics.records",
    "outputs.buried_profile_depth_m": "mpm.numerics.buried_profile_depth_um",
    "domain.headroom_m": "mpm.numerics.domain.headroom_um",
}
_DOMAIN_KEYS = {"sized": {"domain.radius_m": "mpm.numerics.domain.radius_contact_radii",
                          "domain.length_m": "mpm.numerics.domain.end_margin_contact_radii"},
                "fixed": {"domain.radius_m": "mpm.numerics.domain.radius_um",
                          "domain.length_m": "mpm.numerics.domain.length_um"}}
_UNIT = re.compile(r"_(m_s|um|mm|m|N|MPa|Pa)$")


def _unit(key: str) -> str:
    found = _UNIT.search(key)
    return found.group(1) if found else ""


def in_config_terms(message: str, point: Point, numerics: dict[str, Any], rid: str) -> str:
    """A scene's refusal with its scene keys (``discretisation.cfl``) named as the config keys they come from
    (``mpm.numerics.cfl``; ``mpm.numerics.sliding_distance_um (in SI: sliding.distance_m)`` where the units
    differ), and the run named."""
    keys = _NUMERICS_KEYS | _DOMAIN_KEYS.get(numerics.get("domain", {}).get("mode"), {}) | point.source
    shown = {k: v if _unit(k) == _unit(v) else f"{v} (in SI: {k})" for k, v in keys.items()}
    alternatives = "|".join(re.escape(k) for k in sorted(keys, key=len, reverse=True))
    pattern = re.compile(r"(?<![\w.])(?:scene\.)?(" + alternatives + r")(?!\w)")
    return f"config: run {rid}: " + pattern.sub(lambda m: shown[m.group(1)], message)


# ----------------------------------------------------------------------------- physical points
@dataclass(frozen=True)
class Point:
    """One physical scene, independent of the particle size."""

    key: str
    load_N: float
    radius_m: float
    thickness_m: float
    substrate: Any  # material spec: a name or {"rigid_plastic_hardness_Pa": H}
    coating: Any | None
    #: the interface law the MPM runs (:func:`solver_interface` of the config's law)
    interface: dict[str, Any]
    k1: float = field(default=125.0, compare=False)  # the analytical model's only: one run serves any k1
    #: the config's interface law where it differs from ``interface`` (the analytical model's only: its
    #: constant shear is not capped at kappa, the solver's is); None: the same
    analytical_interface: dict[str, Any] | None = field(default=None, compare=False)
    #: the config key each of the scene's physical keys comes from (``load_N``, ``sphere.radius_m``,
    #: ``layers.coating_thickness_m``), so that a refused scene names what to change in the config
    source: dict[str, str] = field(default_factory=dict, compare=False, repr=False)

    def layers(self) -> Layers:
        return _layers(self.substrate, self.coating, self.thickness_m, self.key)

    def hardnesses_Pa(self) -> tuple[float, float]:
        """(Hc, Hs) for the analytical model (Hc = Hs when uncoated)."""
        lay = self.layers()
        Hs = representative_hardness(lay.substrate)
        return (representative_hardness(lay.coating) if lay.coated else Hs), Hs


def _layers(substrate: Any, coating: Any | None, thickness_m: float, where: str) -> Layers:
    """The layers of material specs (``material_from_spec``); ``where`` names them in messages."""
    coat = material_from_spec(coating, coating=True, where=f"{where}.coating") if thickness_m > 0 else None
    return Layers(substrate=material_from_spec(substrate, coating=False, where=f"{where}.substrate"),
                  coating=coat, coating_thickness_m=thickness_m)


@dataclass(frozen=True)
class Series:
    label: str
    points: tuple[Point, ...]


@dataclass(frozen=True)
class Panel:
    name: str
    series_dim: str
    axis: str
    values: tuple[float, ...]
    series: tuple[Series, ...]


def _interface_key(d: dict[str, Any]) -> str:
    model = d["model"]
    if model == "constant":
        return f"const{fmt(d['H0_Pa'] / 1e6)}"
    if model == "proportional":
        return f"prop{fmt(d.get('f', 1.0))}"
    # the pressure the MPM reads is named only where it is not the default, so the default's run ids stay
    pressure = d.get("pressure", DEFAULT_BOUNDARY_LAYER_PRESSURE)
    return f"bl{fmt(d['Cp'])}-{fmt(d['np'])}" + ("" if pressure == DEFAULT_BOUNDARY_LAYER_PRESSURE else f"-{pressure}")


def _interface(name: str, rp: dict[str, Any]) -> dict[str, Any]:
    if name == "constant":
        return {"model": "constant", "H0_Pa": float(rp["H0_MPa"]) * 1e6}
    if name == "proportional":
        return {"model": "proportional", "f": float(rp.get("f", 1.0))}
    raise ValueError(f"interface = {name!r} is unknown for the rigid-plastic studies; allowed: constant, proportional")


def solver_interface(layers: Layers, interface: Interface) -> Interface:
    """The interface law the solver runs for ``interface`` on ``layers``, in its simplest form: the law a
    point's runs are named and made with (``rigid_plastic_point``), so that two points that compute the same
    thing are one run.

    The solver caps the interface shear at the contacting material's kappa = sigma_y0 / sqrt(3)
    (``plough.mpm.contact.interface_shear``; sigma_y0 the flow stress at rest, mixed by volume in a particle
    that straddles the coating). Where every layer is perfectly plastic (``ConstantFlow``: sigma_y0 never
    changes) and a constant shear tau = H0 / k0 is at or above kappa of every layer (H0 >= 3 sigma_y,
    k0 = 3 sqrt 3), the cap acts at every node: the law is the proportional one with f = 1, returned as that.
    At H0 = 3 sigma_y exactly the two differ in round-off only (H0 / k0 against sigma_y / sqrt 3). Anything
    else is returned unchanged: a hardening layer's kappa grows past any tau. Here, not in the solver, so that
    naming runs is no change of the solver (its fingerprint, which every cached run is checked against).
    """
    if not isinstance(interface, ConstantShear):
        return interface
    flows = [m.flow for m in layers.materials]
    if all(isinstance(f, ConstantFlow) and interface.H0_Pa >= 3.0 * f.sigma_y_Pa for f in flows):
        return ProportionalShear(f=1.0)
    return interface


def rigid_plastic_point(rp: dict[str, Any], ratio: float, substrate_MPa: float, thickness_um: float,
                        interface: str, k1: float, *, where: str = "mpm.rigid_plastic") -> Point:
    """A rigid-plastic point; ``where``: the config section its thickness comes from (for messages)."""
    Hs, Hc = float(substrate_MPa), float(ratio) * float(substrate_MPa)
    declared = _interface(interface, rp)
    t = float(thickness_um)
    substrate = {"rigid_plastic_hardness_Pa": Hs * 1e6}
    coating = {"rigid_plastic_hardness_Pa": Hc * 1e6} if t > 0 else None
    # a constant interface at or above both hardnesses runs as the proportional f = 1 law: one run for both
    layers = _layers(substrate, coating, t * 1e-6, where)
    iface = interface_to_dict(solver_interface(layers, interface_from_dict(declared)))
    coated = f"Hc{fmt(Hc)}_Hs{fmt(Hs)}_t{fmt(t)}" if t > 0 else f"Hs{fmt(Hs)}_t0"
    key = f"rp_{coated}_{_interface_key(iface)}_r{fmt(rp['radius_um'])}_F{fmt(rp['load_N'])}"
    return Point(key=key, load_N=float(rp["load_N"]), radius_m=float(rp["radius_um"]) * 1e-6, thickness_m=t * 1e-6,
                 substrate=substrate, coating=coating, interface=iface, k1=float(k1),
                 analytical_interface=None if iface == declared else declared,
                 source={"load_N": "mpm.rigid_plastic.load_N", "sphere.radius_m": "mpm.rigid_plastic.radius_um",
                         "layers.coating_thickness_m": f"{where}.thickness_um"})


def real_point(real: dict[str, Any], system: str, load_N: float, radius_um: float,
               thickness_um: float | None = None, *, where: str = "mpm.real_materials") -> Point:
    """``system``: ``coated`` (zinc coating on DX56), ``zinc_block`` or ``steel`` (DX56). ``where``: the config
    section its load and radius come from (for messages): ``mpm.real_materials`` (``loads_N``, ``ball_radii_um``,
    ``coating_thickness_um``), or its ``thickness_sweep`` or ``picture`` (``load_N``, ``radius_um``)."""
    spec = real["systems"][system]
    lub = real["lubricants"][spec["lubricant"]]
    iface = {"model": "boundary_layer", "Cp": float(lub["Cp"]), "np": float(lub["np"]),
             "pressure": str(lub.get("pressure", DEFAULT_BOUNDARY_LAYER_PRESSURE))}
    t = float(real["coating_thickness_um"] if thickness_um is None else thickness_um) if spec.get("coating") else 0.0
    mats = f"{spec['coating']}-on-{spec['substrate']}_t{fmt(t)}" if t > 0 else spec["substrate"]
    key = f"{mats}_{_interface_key(iface)}_r{fmt(radius_um)}_F{fmt(load_N)}"
    top = where == "mpm.real_materials"
    source = {"load_N": f"{where}.loads_N" if top else f"{where}.load_N",
              "sphere.radius_m": f"{where}.ball_radii_um" if top else f"{where}.radius_um",
              "layers.coating_thickness_m": (f"{where}.thickness_um" if thickness_um is not None
                                             else "mpm.real_materials.coating_thickness_um")}
    return Point(key=key, load_N=float(load_N), radius_m=float(radius_um) * 1e-6, thickness_m=t * 1e-6,
                 substrate=spec["substrate"], coating=spec.get("coating") if t > 0 else None, interface=iface,
                 k1=float(real["k1"]), source=source)


# ----------------------------------------------------------------------------- figures
def figure_panels(config: dict[str, Any], figure: str) -> tuple[Panel, ...]:
    """The panels of a sweep figure (Figs. 11, 13, 15, 16, 18, 20, 21, 23)."""
    mpm = config["mpm"]
    rp, real = mpm["rigid_plastic"], mpm["real_materials"]
    if figure in ("fig11", "fig13"):
        rs = rp["ratio_sweep"]
        ratios = tuple(float(x) for x in rs["hardness_ratio"])
        a = Panel("a", "interface", "hardness_ratio", ratios, tuple(
            Series(iface, tuple(rigid_plastic_point(rp, x, rs["substrate_hardness_MPa"], rs["thickness_um"], iface,
                                                    rs["k1"], where="mpm.rigid_plastic.ratio_sweep") for x in ratios))
            for iface in rs["interfaces"]))
        ts = rp["thickness_sweep"]
        thick = tuple(float(x) for x in ts["thickness_um"])
        where = "mpm.rigid_plastic.thickness_sweep"
        b = Panel("b", "coating", "thickness_um", thick, tuple(
            Series(case, tuple(rigid_plastic_point(rp, ts[case]["hardness_ratio"], ts[case]["substrate_hardness_MPa"],
                                                   t, ts["interface"], ts["k1"], where=where) for t in thick))
            for case in ("soft", "hard")))
        return (a, b)
    loads = tuple(float(x) for x in real["loads_N"])
    r1, r3 = (float(x) for x in real["ball_radii_um"])

    def vs_load(system: str, radius_um: float, label: str) -> Series:
        return Series(label, tuple(real_point(real, system, f, radius_um) for f in loads))

    if figure in ("fig15", "fig20"):
        return (Panel("", "material", "load_N", loads,
                      (vs_load("zinc_block", r1, "zinc_block"), vs_load("steel", r1, "steel"))),)
    if figure in ("fig16", "fig21"):
        return (Panel("", "ball", "load_N", loads,
                      (vs_load("coated", r1, f"r{fmt(r1)}um"), vs_load("coated", r3, f"r{fmt(r3)}um"))),)
    if figure == "fig23":
        return (Panel("", "material", "load_N", loads,
                      tuple(vs_load(s, r1, s) for s in ("coated", "zinc_block", "steel"))),)
    if figure == "fig18":
        ts = real["thickness_sweep"]
        thick = tuple(float(x) for x in ts["thickness_um"])
        where = "mpm.real_materials.thickness_sweep"
        coated = Series("coated", tuple(real_point(real, "coated", ts["load_N"], ts["radius_um"], t, where=where)
                                        for t in thick))
        bulk = Series("zinc_block", (real_point(real, "zinc_block", ts["load_N"], ts["radius_um"], where=where),))
        return (Panel("t", "coated_system", "thickness_um", thick, (coated,)),
                Panel("bulk", "block", "load_N", (float(ts["load_N"]),), (bulk,)))
    raise ValueError(f"figure = {figure!r} is not a sweep figure; sweep figures: {SWEEP_FIGURES}")


def figure_points(config: dict[str, Any], figure: str) -> dict[str, Point]:
    """Cases of a single-run figure (Figs. 12, 14, 17, 19): case label -> point."""
    mpm = config["mpm"]
    rp, real = mpm["rigid_plastic"], mpm["real_materials"]
    if figure == "fig12":
        pic = rp["picture"]
        return {"coated": rigid_plastic_point(rp, pic["hardness_ratio"], pic["substrate_hardness_MPa"],
                                              pic["thickness_um"], pic["interface"], rp["ratio_sweep"]["k1"],
                                              where="mpm.rigid_plastic.picture")}
    pic = real["picture"]
    where = "mpm.real_materials.picture"
    coated = real_point(real, "coated", pic["load_N"], pic["radius_um"], where=where)
    if figure in ("fig14", "fig19"):
        return {"coated": coated}
    if figure == "fig17":
        return {"coated": coated, "zinc_block": real_point(real, "zinc_block", pic["load_N"], pic["radius_um"],
                                                           where=where)}
    raise ValueError(f"figure = {figure!r} is not a single-run figure; single-run figures: {SINGLE_RUN_FIGURES}")


def particle_sizes_um(config: dict[str, Any]) -> tuple[float, ...]:
    """The config's particle sizes ``mpm.particle_sizes_um``, descending: the paper's ladder, which every
    point runs with ``mpm.ladder: paper`` and which the relative ladder scales per point
    (:func:`point_ladder`). A point's own sizes: ``point_ladder(config, point).sizes_um``."""
    return tuple(sorted((float(h) for h in config["mpm"]["particle_sizes_um"]), reverse=True))


@dataclass(frozen=True)
class Ladder:
    """The particle sizes of one point (descending, um) and the length scales they were chosen from (um)."""

    sizes_um: tuple[float, ...]
    #: sizes_um = the config's particle_sizes_um x scale; scale = 2^k, or (half-octave size / finest) x 2^k with
    #: ``ladder_sizes_per_octave: 2`` (1 for the paper's ladder)
    scale: float
    contact_radius_um: float  # the analytical model's expected contact radius a
    groove_depth_um: float  # its ploughing depth dp
    coating_um: float  # the coating thickness t (0: uncoated)
    #: the target that set the finest size (a key of LADDER_TARGETS), "paper" (the paper's ladder) or
    #: "paper_budget" (the relative ladder keeping the paper's sizes of a point they make cheap enough)
    set_by: str

    @property
    def finest_um(self) -> float:
        return self.sizes_um[-1]

    def particles(self) -> dict[str, float | None]:
        """Particles across each length at the finest size (a / h, dp / h, t / h; None for t uncoated)."""
        h = self.finest_um
        return {"contact_radius_particles": self.contact_radius_um / h,
                "groove_depth_particles": self.groove_depth_um / h,
                "coating_particles": self.coating_um / h if self.coating_um > 0 else None}


def _exponent(length_um: float, target: float, finest_um: float) -> int:
    """The largest k with ``length / (finest 2^k) >= target`` (round-off in favour of the target)."""
    return math.floor(math.log2(length_um / (target * finest_um)) + 1e-9)


def half_octave_um(finest_um: float) -> float:
    """The size between ``finest_um`` and twice it: ``finest_um`` x sqrt(2) to two significant digits (3.5 for
    2.5), so that its run ids stay short and its multiples by powers of two exact."""
    return float(f"{finest_um * math.sqrt(2.0):.2g}")


def ladder_bases_um(config: dict[str, Any]) -> tuple[float, ...]:
    """The sizes whose multiples by a power of two a relative ladder's finest size may be: the config's finest
    size, and with ``mpm.ladder_sizes_per_octave: 2`` (the default) also its half-octave size (checked here)."""
    per_octave = config["mpm"].get("ladder_sizes_per_octave", LADDER_SIZES_PER_OCTAVE_DEFAULT)
    if per_octave not in LADDER_SIZES_PER_OCTAVE_CHOICES or isinstance(per_octave, bool):
        raise ValueError(f"mpm.ladder_sizes_per_octave = {per_octave!r} is not allowed; allowed: "
                         f"{', '.join(map(str, LADDER_SIZES_PER_OCTAVE_CHOICES))}")
    finest = particle_sizes_um(config)[-1]
    return (finest,) if per_octave == 1 else (finest, half_octave_um(finest))


def _scale(length_um: float, target: float, bases_um: tuple[float, ...], floor: bool) -> float:
    """The largest scale s, (base / the first base) x 2^k over ``bases_um``, with ``length / (bases_um[0] s) >=
    target``; ``floor``: never below 1 (the groove and coating targets)."""
    scale = max(base / bases_um[0] * 2.0 ** _exponent(length_um, target, base) for base in bases_um)
    return max(scale, 1.0) if floor else scale


@cache
def _expected_contact_um(layers: Layers, load_N: float, radius_m: float) -> tuple[float, float]:
    """(a, dp) in um of the analytical model (``plough.mpm.scene.expected_contact``), computed once per
    physical point: a workflow start asks for every point's ladder many times (datasets, gates, costs)."""
    a_m, dp_m = expected_contact(layers, load_N, radius_m)
    return a_m * 1e6, dp_m * 1e6


def point_ladder(config: dict[str, Any], point: Point) -> Ladder:
    """The particle sizes of ``point``: ``mpm.ladder: paper`` (the default) runs every point at the config's
    ``particle_sizes_um``; ``relative`` runs it at those sizes times a scale, the largest at which the finest
    size holds ``mpm.ladder_targets`` particles across the point's own lengths:

    * ``contact_radius_particles`` across the expected contact radius a (``plough.mpm.scene.expected_contact``,
      the analytical model): the contact patch and the plastic zone under it, which set mu; it may take the
      point below the config's finest size (scale < 1);
    * ``groove_depth_particles`` across the expected ploughing depth dp: the groove and its rims (dp);
    * ``coating_particles`` across the coating thickness t (coated points): the coating's own flow, which
      sets the layered system's hardness.

    The scales a point may take (``mpm.ladder_sizes_per_octave``): 1, a power of two, so that a finest size
    lies within a factor 2 of the coarsest one meeting the targets; 2 (the default), also the half-octave
    size (the config's finest x sqrt(2) to two digits, 3.5 um for 2.5) over the finest times a power of two,
    within a factor 1.43: the targets bound the error, and a finest size up to twice as fine as they need
    costs up to 16x the particle-steps (particles x steps go as h^-4). The groove and coating targets never
    take a point below the config's finest size (scale >= 1 for them): where the paper's own ladder leaves a
    groove or a thin coating under a particle, so does this one. ``null`` leaves a target out. A point's
    sizes keep the ratios of the config's, and a run shared by both ladders is one run (its id names its
    size).

    ``mpm.ladder_paper_budget_particle_steps`` (null: none): a point the targets would coarsen (scale > 1) keeps
    the paper's sizes if they cost at most this many particle-steps together (:func:`paper_ladder_particle_steps`):
    where the paper's ladder is cheap the relative one saves little and its coarsest size, a contact radius of
    3-5 particles, widens the extrapolation's uncertainty (docs/workflow.md, *The ladder*)."""
    mpm = config["mpm"]
    paper = particle_sizes_um(config)
    choice = mpm.get("ladder", LADDER_DEFAULT)
    if choice not in LADDER_CHOICES:
        raise ValueError(f"mpm.ladder = {choice!r} is unknown; allowed: {', '.join(LADDER_CHOICES)}")
    a, dp = _expected_contact_um(point.layers(), point.load_N, point.radius_m)
    t = point.thickness_m * 1e6
    if choice == "paper":
        return Ladder(paper, 1.0, a, dp, t, "paper")
    targets = mpm.get("ladder_targets")
    if not isinstance(targets, dict) or targets.get("contact_radius_particles") is None:
        raise ValueError("mpm.ladder = relative needs mpm.ladder_targets with contact_radius_particles (> 0); "
                         f"optional: {', '.join(LADDER_TARGETS[1:])} (null: not a target)")
    bases = ladder_bases_um(config)
    scales = {"contact_radius_particles": _scale(a, float(targets["contact_radius_particles"]), bases, floor=False)}
    if targets.get("groove_depth_particles") is not None:
        scales["groove_depth_particles"] = _scale(dp, float(targets["groove_depth_particles"]), bases, floor=True)
    if targets.get("coating_particles") is not None and t > 0:
        scales["coating_particles"] = _scale(t, float(targets["coating_particles"]), bases, floor=True)
    set_by = min(scales, key=lambda name: scales[name])  # the first of equals: the contact before the others
    budget = mpm.get("ladder_paper_budget_particle_steps")
    if (scales[set_by] > 1.0 and budget is not None
            and paper_ladder_particle_steps(point, paper, mpm["numerics"]) <= float(budget)):
        return Ladder(paper, 1.0, a, dp, t, "paper_budget")
    scale = scales[set_by]
    # to twelve digits: a scaled size is not always exact in binary (5 x (1.8 / 1.25) x 2 is 14.399999999999999
    # for a config of 5, 2.5, 1.25 um), and a run's size is what its id (fmt) spells
    return Ladder(tuple(float(f"{h * scale:.12g}") for h in paper), scale, a, dp, t, set_by)


def paper_ladder_particle_steps(point: Point, sizes_um: tuple[float, ...], numerics: dict[str, Any]) -> float:
    """The particle-steps of ``point``'s runs at ``sizes_um`` (the paper's ladder) with the numerics, by the cost
    model (:func:`plough.study.cost.estimate`: particles x steps x the active zone's share), summed."""
    numerics_key = json.dumps(numerics, sort_keys=True)
    total = 0.0
    for h in sizes_um:
        # a point's key names one physical point (all_points checks it): the key, size and numerics name the run
        key = (point.key, float(h), numerics_key)
        if key not in _PARTICLE_STEPS:
            _PARTICLE_STEPS[key] = cost.estimate(scene_for(point, float(h), numerics)).particle_steps
        total += _PARTICLE_STEPS[key]
    return total


#: (point key, h in um, numerics as JSON) -> the run's particle-steps (the ladder asks for each point often)
_PARTICLE_STEPS: dict[tuple[str, float, str], float] = {}


def run_id(point: Point, h_um: float) -> str:
    return f"{point.key}_h{fmt(h_um)}"


def figure_runs(config: dict[str, Any], figure: str) -> list[str]:
    """Run ids a figure needs: every size of every sweep point, the finest size for pictures (each point's
    own sizes: :func:`point_ladder`)."""
    if figure in SINGLE_RUN_FIGURES:
        return [run_id(p, point_ladder(config, p).finest_um) for p in figure_points(config, figure).values()]
    if figure == "fig22":  # the MPM points of Fig. 21 beside the power-law fits
        return figure_runs(config, "fig21")
    if figure not in SWEEP_FIGURES:
        return []
    ids = (run_id(p, h) for panel in figure_panels(config, figure) for s in panel.series for p in s.points
           for h in point_ladder(config, p).sizes_um)
    return list(dict.fromkeys(ids))  # a run shared by two panels is listed once


def coarser_sizes_um(config: dict[str, Any], finest_run: str) -> list[float]:
    """The sizes (um, coarsest first) of the two runs that may stand in for a finest sweep run
    (:func:`finest_sweep_runs`): its point's own ladder's next two sizes."""
    for p in all_points(config, SWEEP_FIGURES).values():
        sizes = point_ladder(config, p).sizes_um
        if len(sizes) >= 3 and run_id(p, sizes[-1]) == finest_run:
            return [sizes[-3], sizes[-2]]
    raise ValueError(f"run {finest_run!r} is not the finest run of a sweep point with three sizes or more")


# ----------------------------------------------------------------------------- scenes
def _optional_float(value: Any) -> float | None:
    return None if value is None else float(value)


def scene_for(point: Point, h_um: float, numerics: dict[str, Any]) -> Scene:
    """The complete scene of one run: the physical point at particle size h with the numerics."""
    h = float(h_um) * 1e-6
    slide = float(numerics["sliding_distance_um"]) * 1e-6
    layers = point.layers()
    dom = numerics["domain"]
    symmetric = bool(numerics.get("symmetric", True))
    headroom = None if dom.get("headroom_um") is None else float(dom["headroom_um"]) * 1e-6
    if dom["mode"] == "sized":
        domain = sized_domain(layers, point.load_N, point.radius_m, slide, h, symmetric,
                              float(dom["radius_contact_radii"]), float(dom["end_margin_contact_radii"]))
        domain = replace(domain, headroom_m=headroom)
    else:
        domain = Domain(radius_m=float(dom["radius_um"]) * 1e-6, length_m=float(dom["length_um"]) * 1e-6,
                        symmetric=symmetric, headroom_m=headroom)
    return Scene(
        layers=layers, load_N=point.load_N, sphere=Sphere(radius_m=point.radius_m),
        interface=interface_from_dict(point.interface), domain=domain,
        sliding=Sliding(distance_m=slide, speed_m_s=float(numerics["speed_m_s"]),
                        experiment_speed_m_s=float(numerics["experiment_speed_m_s"])),
        discretisation=Discretisation(particle_size_m=h, particles_per_cell=int(numerics["particles_per_cell"]),
                                      cfl=float(numerics["cfl"]), mass_scaling=float(numerics["mass_scaling"]),
                                      flip=float(numerics.get("flip", 1.0)),
                                      dilatation=str(numerics.get("dilatation", "projected")),
                                      graded=numerics.get("graded", False),
                                      fine_zone_contact_radii=float(numerics.get("fine_zone_contact_radii", 1.5)),
                                      fine_zone_shape=str(numerics.get("fine_zone_shape", "square")),
                                      fine_zone_depth_particles=_optional_float(
                                          numerics.get("fine_zone_depth_particles")),
                                      active_zone_contact_radii=_optional_float(
                                          numerics.get("active_zone_contact_radii")),
                                      contact=str(numerics.get("contact", Discretisation.contact))),
        outputs=Outputs(steady_window=tuple(float(x) for x in numerics["steady_window"]),
                        records=int(numerics["records"]),
                        buried_profile_depth_m=float(numerics["buried_profile_depth_um"]) * 1e-6),
        name=run_id(point, h_um),
    )


def all_points(config: dict[str, Any], figures: tuple[str, ...] = MPM_FIGURES) -> dict[str, Point]:
    """Every distinct physical point of the given figures; the same key must mean the same point."""
    points: dict[str, Point] = {}

    def add(p: Point) -> None:
        if p.key in points and points[p.key] != p:
            raise ValueError(f"two different scenes share the key {p.key!r}: {points[p.key]} and {p}")
        points[p.key] = p

    for fig in figures:
        if fig in SINGLE_RUN_FIGURES:
            for p in figure_points(config, fig).values():
                add(p)
        else:
            for panel in figure_panels(config, fig):
                for s in panel.series:
                    for p in s.points:
                        add(p)
    return points


def all_runs(config: dict[str, Any], figures: tuple[str, ...] = MPM_FIGURES) -> dict[str, dict[str, Any]]:
    """run id -> complete scene dict (SI, JSON-serialisable) for every run the figures need.

    Checks the whole config first (``check_config``: the workflow builds this matrix before any job); a scene
    the solver refuses is named by its run and the config keys it comes from (``in_config_terms``)."""
    check_config(config)
    points = all_points(config, figures)
    numerics = config["mpm"]["numerics"]
    wanted = {rid for fig in figures for rid in figure_runs(config, fig)}
    runs: dict[str, dict[str, Any]] = {}
    for p in points.values():
        for h in point_ladder(config, p).sizes_um:
            rid = run_id(p, h)
            if rid in wanted:
                try:
                    runs[rid] = scene_for(p, h, numerics).to_dict()
                except ValueError as exc:
                    raise ValueError(in_config_terms(str(exc), p, numerics, rid)) from None
    return dict(sorted(runs.items()))


def skippable_runs(config: dict[str, Any]) -> dict[str, tuple[str, str]]:
    """finest-size run id -> (coarsest, middle) run ids of the same point, for the *gated* finest runs, made
    only where the point's refinement decision asks for them (``plough.study.skipping``): empty unless
    ``mpm.skip_finest_tolerance`` is set (checked here) and there are at least three sizes; never a run a
    picture (single-run figure) needs, nor one whose size the groove or coating target set
    (:data:`UNGATED_TARGETS`)."""
    return finest_run_roles(config)[0]


def failure_recordable_runs(config: dict[str, Any]) -> dict[str, tuple[str, str]]:
    """The finest sweep runs (as :func:`finest_sweep_runs`) whose stop on the solver's instability
    error is recorded as a failure marker (``plough.study.skipping``) instead of failing the
    workflow: all of them with ``mpm.finest_failure: record`` (the default), none with ``stop``."""
    return finest_run_roles(config)[1]


def finest_run_roles(config: dict[str, Any]) -> tuple[dict[str, tuple[str, str]], dict[str, tuple[str, str]]]:
    """(:func:`skippable_runs`, :func:`failure_recordable_runs`), the finest sweep runs found once for both:
    each option is checked whatever the other says."""
    from plough.study.skipping import tolerances

    tolerance = config["mpm"].get("skip_finest_tolerance")
    if tolerance is not None:
        tolerances(tolerance)
    choice = config["mpm"].get("finest_failure", FINEST_FAILURE_DEFAULT)
    if choice not in FINEST_FAILURE_CHOICES:
        raise ValueError(f"mpm.finest_failure = {choice!r} is unknown; allowed: {', '.join(FINEST_FAILURE_CHOICES)}")
    finest = finest_sweep_runs(config) if tolerance is not None or choice == "record" else {}
    ungated = _finest_runs_set_by(config, UNGATED_TARGETS) if tolerance is not None else set()
    skippable = {rid: pair for rid, pair in finest.items() if rid not in ungated} if tolerance is not None else {}
    recordable = dict(finest) if choice == "record" else {}
    return skippable, recordable


def finest_sweep_runs(config: dict[str, Any]) -> dict[str, tuple[str, str]]:
    """finest-size run id -> (coarsest, middle) run ids of the same point, for every sweep point
    whose value two coarser sizes could stand in for: empty with fewer than three sizes; never a run
    a picture (single-run figure) needs."""
    if len(particle_sizes_um(config)) < 3:
        return {}
    pictures = {rid for fig in SINGLE_RUN_FIGURES for rid in figure_runs(config, fig)}
    out = {}
    for p in all_points(config, SWEEP_FIGURES).values():
        sizes = point_ladder(config, p).sizes_um
        finest = run_id(p, sizes[-1])
        if finest not in pictures:
            out[finest] = (run_id(p, sizes[-3]), run_id(p, sizes[-2]))
    return dict(sorted(out.items()))


def _finest_runs_set_by(config: dict[str, Any], targets: tuple[str, ...]) -> set[str]:
    """The finest-size run ids of the sweep points whose finest size one of ``targets`` set (``Ladder.set_by``)."""
    out = set()
    for p in all_points(config, SWEEP_FIGURES).values():
        ladder = point_ladder(config, p)
        if ladder.set_by in targets:
            out.add(run_id(p, ladder.finest_um))
    return out


def analytical_values(point: Point, correction: str = "none") -> dict[str, float]:
    """The analytical model (eqs. 1-5) at a point: mu, mu_pl, mu_sh, dp."""
    from plough.analytical import ploughing

    Hc, Hs = point.hardnesses_Pa()
    iface = point.interface if point.analytical_interface is None else point.analytical_interface
    kw: dict[str, Any] = {"interface": iface["model"]}
    if iface["model"] == "constant":
        kw["H0_Pa"] = iface["H0_Pa"]
    elif iface["model"] == "proportional":
        kw["f"] = iface.get("f", 1.0)
    else:
        kw["Cp"], kw["np_exponent"] = iface["Cp"], iface["np"]
    try:
        res = ploughing(point.load_N, point.radius_m, point.thickness_m, Hc, Hs, k1=point.k1,
                        correction=correction, **kw)
    except ValueError:
        return {k: float("nan") for k in ANALYTICAL_OUTPUTS}
    return {k: float(np.asarray(getattr(res, k))) for k in ANALYTICAL_OUTPUTS}

