"""A ploughing scene as data: frozen dataclasses validated on construction (model.md section 2).

Geometry of Table 1: the substrate is a half cylinder with its axis along x (the sliding
direction), flat face up at z = 0; the coating is the material with initial z > -t. A rigid
sphere of radius r is pressed with a normal load and slid along x. With ``symmetric`` the
problem is cut at the mirror plane y = 0 and only y >= 0 is simulated.

A scene converts to and from a plain dict / YAML file. Keys carry their unit; on reading, keys
ending in ``_um``, ``_mm``, ``_MPa`` or ``_GPa`` are converted to the SI field (``_m``, ``_Pa``),
so a scene file may say ``radius_um: 200`` for the field ``radius_m``.
"""

from __future__ import annotations

import math
import re
from dataclasses import MISSING, asdict, dataclass, field, fields, replace
from pathlib import Path
from typing import Any

import yaml

from plough.materials import (
    FLOW_MODELS,
    INTERFACES,
    ROOM_TEMPERATURE_K,
    BoundaryLayerShear,
    ConstantFlow,
    ConstantShear,
    Interface,
    JohnsonCook,
    Material,
    ProportionalShear,
    get_material,
    interface_from_dict,
    interface_to_dict,
    reference_flow_stress,
    representative_hardness,
    rigid_plastic,
)


class _UniqueKeyLoader(yaml.SafeLoader):
    """PyYAML's safe loader, refusing a key given twice in one mapping (it keeps the last one silently)."""


def _construct_unique_mapping(loader: _UniqueKeyLoader, node: yaml.MappingNode, deep: bool = False) -> dict:
    # the mapping's own keys only, before merge keys (<<) splice theirs in: overriding a merged key is allowed
    seen: set = set()
    for key_node, _ in node.value:
        if key_node.tag == "tag:yaml.org,2002:merge":
            continue
        key = loader.construct_object(key_node, deep=True)
        try:
            twice = key in seen
        except TypeError:  # an unhashable key: construct_mapping names it
            break
        if twice:
            raise yaml.constructor.ConstructorError(None, None, f"key {key!r} is given twice in one mapping",
                                                    key_node.start_mark)
        seen.add(key)
    loader.flatten_mapping(node)
    return loader.construct_mapping(node, deep=deep)


_UniqueKeyLoader.add_constructor(yaml.resolver.BaseResolver.DEFAULT_MAPPING_TAG, _construct_unique_mapping)

_UNIT_SUFFIXES = {"_um": ("_m", 1e-6), "_mm": ("_m", 1e-3), "_MPa": ("_Pa", 1e6), "_GPa": ("_Pa", 1e9)}

#: Largest CFL number accepted. Explicit MPM with quadratic B-splines is stable below ~1 for the
#: elastic wave, but the load control is not: on the 1 N stability scene the mean normal force is
#: 0.95 / 1.14 / 1.22 x the load at CFL 0.3 / 0.5 / 0.6 with the pressure projected as the dilatation
#: (1.18 / 1.23 / 1.24 at CFL 0.6 / 0.8 / 0.9 before; docs/journal/2026-11-22-stability-matrix-and-cfl-limit.md,
#: docs/journal/2026-12-03-consistent-pressure.md), so above 0.5 a run would complete with a load more than 20%
#: from the one it was asked for.
CFL_MAX = 0.5
#: largest accepted inertia number ms rho v^2 / H (softest layer): at 8.7 (mass scaling 1e8 at
#: 0.1 m/s) the mean force was twice the load; at 0.09 (the paper's settings, hard substrate)
#: inertia moved mu by 1.6% (benchmarks/stability_matrix.py, docs/journal/2026-11-22-timestep-and-transfer.md); the
#: paper's own matrix reaches 1.6 (softest coatings). Between 1.6 and 8.7 is not measured.
INERTIA_MAX = 4.0


#: A scene's name becomes part of file names (snapshots): letters, digits and ``._+-=`` only, no path.
_NAME_PATTERN = re.compile(r"[A-Za-z0-9_][A-Za-z0-9._+=-]*")


def _number(value: Any, where: str) -> float:
    """``value`` as a float, or a one-line error naming ``where`` (true / false are not numbers)."""
    if isinstance(value, bool):
        raise ValueError(f"{where} = {value!r} is not a number")
    try:
        return float(value)
    except (TypeError, ValueError):
        raise ValueError(f"{where} = {value!r} is not a number") from None


def _to_si(d: dict[str, Any], where: str = "") -> dict[str, Any]:
    out: dict[str, Any] = {}
    given_as: dict[str, str] = {}  # SI key -> the key it was given as
    prefix = f"{where}." if where else ""
    for key, value in d.items():
        for suffix, (si_suffix, factor) in _UNIT_SUFFIXES.items():
            if isinstance(key, str) and key.endswith(suffix):
                new = key[: -len(suffix)] + si_suffix
                if new in d:
                    raise ValueError(f"both {prefix}{key} and {prefix}{new} given; give one")
                if new in given_as:
                    raise ValueError(f"both {prefix}{given_as[new]} and {prefix}{key} given (the same "
                                     "quantity in two units); give one")
                given_as[new] = key
                out[new] = None if value is None else _number(value, f"{prefix}{key}") * factor
                break
        else:
            out[key] = value
    return out


def _as_given(keys: Any, given: dict[Any, Any]) -> list[str]:
    """``keys`` (of the SI dict made by ``_to_si``) named as the user wrote them in ``given``:
    ``hardness_MPa``, not the ``hardness_Pa`` it was converted to."""
    back = {}
    for k in given:
        for suffix, (si_suffix, _) in _UNIT_SUFFIXES.items():
            if isinstance(k, str) and k.endswith(suffix):
                back[k[: -len(suffix)] + si_suffix] = k
                break
    return sorted(str(back.get(k, k)) for k in keys)


def _coerce(value: Any, type_name: str, where: str) -> Any:
    """YAML 1.1 reads 1.0e6 as a string: convert numbers by the field's declared type."""
    if value is None or type_name not in ("float", "int", "float | None"):
        return value
    number = _number(value, where)
    if type_name == "int":
        if not math.isfinite(number) or number != int(number):
            raise ValueError(f"{where} = {value!r} is not an integer")
        return int(number)
    return number


def _mapping(d: Any, where: str) -> dict[str, Any]:
    if d is None:
        return {}
    if not isinstance(d, dict):
        raise ValueError(f"{where} = {d!r} must be a mapping of keys to values")
    return dict(d)


def _from_dict(cls: type, d: dict[str, Any] | None, where: str) -> Any:
    given = _mapping(d, where)
    d = _to_si(given, where)
    types = {f.name: str(f.type) for f in fields(cls)}
    unknown = set(d) - set(types)
    if unknown:
        raise ValueError(f"{where}: unknown key(s) {_as_given(unknown, given)}; allowed: {sorted(types)}")
    return cls(**{k: _coerce(v, types[k], f"{where}.{k}") for k, v in d.items()})


def _finite_positive(where: str, name: str, value: float, unit: str = "") -> None:
    if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
        raise ValueError(f"{where}.{name} = {value!r} {unit} is not allowed; it must be > 0".replace("  ", " "))


# ----------------------------------------------------------------------------- parts
@dataclass(frozen=True)
class Sphere:
    """The rigid indenter: an exact analytic sphere."""

    radius_m: float = 200e-6

    def __post_init__(self) -> None:
        _finite_positive("sphere", "radius_m", self.radius_m, "m")


@dataclass(frozen=True)
class Layers:
    """Coating (thickness, material) on a substrate. ``coating_thickness_m = 0``: uncoated."""

    substrate: Material
    coating: Material | None = None
    coating_thickness_m: float = 0.0

    def __post_init__(self) -> None:
        t = self.coating_thickness_m
        if not (isinstance(t, int | float) and math.isfinite(t) and t >= 0):
            raise ValueError(f"layers.coating_thickness_m = {t!r} m is not allowed; it must be >= 0")
        if t > 0 and self.coating is None:
            raise ValueError("layers.coating is missing although coating_thickness_m > 0")
        for name in ("substrate", "coating"):
            m = getattr(self, name)
            if m is not None and not isinstance(m, Material):
                raise ValueError(f"layers.{name} = {m!r} is not a Material")

    @property
    def coated(self) -> bool:
        return self.coating_thickness_m > 0

    @property
    def materials(self) -> tuple[Material, ...]:
        return (self.coating, self.substrate) if self.coated else (self.substrate,)


@dataclass(frozen=True)
class Domain:
    """The simulated block: a half cylinder of radius ``radius_m`` and length ``length_m``.

    ``headroom_m`` is the height of the grid above the original surface, the room material has to
    rise into (pile-up, and the prow an adhesive interface pushes up the sphere's front); None
    sizes it from the expected groove (``Scene.grid_headroom_m``) and lets the solver raise it
    mid-run where material reaches it, and lengthen it past the block's far end where material flung
    ahead passes it, and widen it past the side face where material thrown sideways passes it
    (:mod:`plough.mpm.growth`); a value set here fixes the whole
    grid, the top, the far end and the side. It costs grid nodes, not particles.
    """

    radius_m: float = 200e-6
    length_m: float = 1000e-6
    symmetric: bool = True
    headroom_m: float | None = None

    def __post_init__(self) -> None:
        _finite_positive("domain", "radius_m", self.radius_m, "m")
        _finite_positive("domain", "length_m", self.length_m, "m")
        if self.headroom_m is not None:
            _finite_positive("domain", "headroom_m", self.headroom_m, "m")
        if not isinstance(self.symmetric, bool):
            raise ValueError(f"domain.symmetric = {self.symmetric!r} must be true or false")


#: Named numerical presets a scene file can be run with (``plough mpm --preset``,
#: ``plough.mpm.run.apply_preset``): the paper's setup, or the block sized from the contact.
PRESETS = ("paper", "sized")

#: The paper's block: a half cylinder of radius 0.2 mm and length 1 mm, mirror plane at y = 0.
PAPER_DOMAIN = Domain(radius_m=200e-6, length_m=1000e-6, symmetric=True)


@dataclass(frozen=True)
class Sliding:
    """Path of the sphere: press to the load (or to a depth), then slide ``distance_m`` along x.

    ``speed_m_s`` is the simulated sliding speed; ``experiment_speed_m_s`` the physical one, used
    to evaluate strain-rate terms at the physical rate (rate_phys = rate_sim * v_exp / v_sim).
    ``control`` is ``load`` (the sphere's height floats so that Fz = load) or ``displacement``
    (the sphere is held at ``depth_m`` below the original surface). With ``stop_when_steady`` the
    slide ends before ``distance_m`` once mu over the steady window (the same fractions of the
    distance slid so far) has changed by less than ``steady_tolerance`` (relative) over the last
    three checks, a tenth of ``distance_m`` apart (see ``plough.mpm.run.SteadyStop``).
    """

    distance_m: float = 600e-6
    speed_m_s: float = 0.1
    experiment_speed_m_s: float = 1e-3
    control: str = "load"
    depth_m: float | None = None
    press_speed_fraction: float = 0.25
    stop_when_steady: bool = False
    steady_tolerance: float = 0.01

    def __post_init__(self) -> None:
        _finite_positive("sliding", "distance_m", self.distance_m, "m")
        if not isinstance(self.stop_when_steady, bool):
            raise ValueError(f"sliding.stop_when_steady = {self.stop_when_steady!r} must be true or false")
        if not (0.0 < self.steady_tolerance <= 0.2):
            raise ValueError(f"sliding.steady_tolerance = {self.steady_tolerance!r} is outside the allowed "
                             "range (0, 0.2]")
        _finite_positive("sliding", "speed_m_s", self.speed_m_s, "m/s")
        _finite_positive("sliding", "experiment_speed_m_s", self.experiment_speed_m_s, "m/s")
        if self.control not in ("load", "displacement"):
            raise ValueError(f"sliding.control = {self.control!r} is unknown; allowed: load, displacement")
        if self.control == "displacement":
            if self.depth_m is None:
                raise ValueError("sliding.depth_m is required when sliding.control = displacement")
            _finite_positive("sliding", "depth_m", self.depth_m, "m")
        if not (0 < self.press_speed_fraction <= 1):
            raise ValueError(f"sliding.press_speed_fraction = {self.press_speed_fraction!r} is outside (0, 1]")


#: smallest fine zone of graded particles, in expected contact radii: the sphere touches only h particles
FINE_ZONE_MIN_CONTACT_RADII = 1.0

#: smallest active zone, in expected contact radii behind and ahead of the sphere: the plastic zone
#: of a sliding sphere reaches about 2 a, and the sized block's end margins are at least 2 a too
ACTIVE_ZONE_MIN_CONTACT_RADII = 2.0
#: ... and never narrower than this many particle sizes h: on a coarse scene the contact and the
#: plastic zone spread over cells, not contact radii (the stability matrix's 1 N bulk-coating scene,
#: a = 3.8 h: a zone of 4 a moved mu -12%, of 20 h -0.8%, of 24 h -0.1%)
ACTIVE_ZONE_MIN_PARTICLES = 20.0

#: how J and the pressure see the dilatation rate (see Discretisation)
DILATATION_MODES = ("projected", "local")
FINE_ZONE_SHAPES = ("square", "disc")
#: smallest fine-zone depth below the expected groove or the coating, in particle sizes h: the groove's
#: bottom and the coating-substrate interface each keep at least two layers of h particles below them
FINE_ZONE_MIN_DEPTH_PARTICLES = 2.0
#: where the sphere acts on the material (see Discretisation and plough.mpm.contact)
CONTACT_MODES = ("grid", "particle", "grid_local")


@dataclass(frozen=True)
class Discretisation:
    """Particle size h (edge of the cube a particle fills), cells, time step, mass scaling, transfer.

    ``flip`` is the FLIP share of the particle velocity update (0: APIC alone). APIC damps the
    velocity modes the affine field cannot hold on every transfer, so its numerical dissipation
    grows with the number of steps: on the reference scene at h = 10 um (frictionless), APIC lost
    41% of the sphere's work at CFL 0.075 and the groove depth fell from 2.37 to 1.41 um between
    CFL 0.3 and 0.075. With flip = 1 mu, mu_sh and dp agree within 1.5% between the two (f = 1)
    (measured with the local dilatation).

    ``dilatation``: "projected" (default) drives J and the pressure with the dilatation rate
    projected on the grid (an F-bar-like treatment of volumetric locking, see
    :mod:`plough.mpm.transfers`); "local" uses each particle's own. Plastic flow is isochoric, and
    with "local" the block locks: on the coated reference scene at h = 20 / 10 um dp was 1.36 /
    3.69 um against 4.07 / 12.99 um projected (docs/journal/2026-11-22-projected-dilatation.md).

    ``graded``: particles of size h only in the *fine zone* along the track (|y| and depth within
    ``fine_zone_contact_radii`` (>= 1) expected contact radii and at least 6 h, over the block's whole
    length); outside it
    each complete 2 x 2 x 2 group of lattice particles is one particle of size 2 h (one per cell
    at two particles per cell). The grid stays uniform. Off by default (docs/journal/2026-11-22-graded-particles.md).
    ``fine_zone_shape``: the zone's cross-section, "square" (default: |y| and the depth each
    within the half-width) or "disc" (the distance from the track's centre line on the surface
    within it: the corners, about 2 contact radii from the track in both y and depth, are coarse;
    12-16% fewer particles on the reference scenes; docs/journal/2026-11-23-disc-fine-zone.md).
    ``fine_zone_depth_particles``: when set, the zone's depth follows the deformation instead: the
    expected groove depth or the coating thickness, whichever is deeper, plus this many particle
    sizes h (>= 2), never deeper than the half-width (nor shallower than 6 h); the half-width stays
    ``fine_zone_contact_radii`` expected contact radii. None (default): as deep as wide
    (docs/journal/2026-12-02-fine-zone-depth.md).

    ``active_zone_contact_radii``: when set, only the particles that started within this many
    expected contact radii (and at least 20 h) behind or ahead of the sphere's centre (along the
    slide) are updated;
    the rest are frozen (they keep their position and stress, and the grid nodes in their region
    hold zero velocity, so the active material is clamped there as at the block's curved surface).
    The zone moves with the sphere and a particle that leaves it behind stays frozen; until
    particles lie frozen beyond an end of the zone, the block's own end face there stays free.
    None (default) updates every particle (docs/journal/2026-11-23-active-zone.md).

    ``contact``: "grid_local" (default) imposes the sphere on the grid nodes within a cell of it, each limited
    by the gap of the closest particle within half a cell of the node's own ray from the sphere's centre
    (:func:`plough.mpm.contact.sphere_contact`: the contact acts where the material meets the sphere; chosen
    2026-12-04, docs/journal/2026-12-04-contact-switch.md); "grid" the same with the gap of the closest particle
    of the node's whole stencil (the contact acts up to a cell outside the sphere; the default until then);
    "particle" imposes
    it on each near particle whose face would cross the sphere's exact surface in the step, through the
    particle's own nodes (:func:`plough.mpm.contact.particle_contact`; docs/journal/2026-12-02-contact-candidates.md).
    """

    particle_size_m: float = 10e-6
    particles_per_cell: int = 2
    cfl: float = 0.3
    mass_scaling: float = 1e6
    flip: float = 1.0
    dilatation: str = "projected"
    graded: bool = False
    fine_zone_contact_radii: float = 1.5
    fine_zone_shape: str = "square"
    fine_zone_depth_particles: float | None = None
    active_zone_contact_radii: float | None = None
    contact: str = "grid_local"

    def __post_init__(self) -> None:
        _finite_positive("discretisation", "particle_size_m", self.particle_size_m, "m")
        if self.particles_per_cell not in (1, 2, 3, 4):
            raise ValueError(f"discretisation.particles_per_cell = {self.particles_per_cell!r} "
                             "(per direction) is outside the allowed range 1..4")
        if not (0 < self.cfl <= CFL_MAX):
            raise ValueError(f"discretisation.cfl = {self.cfl!r} is outside the stable range (0, {CFL_MAX}]")
        if not (math.isfinite(self.mass_scaling) and self.mass_scaling >= 1):
            raise ValueError(f"discretisation.mass_scaling = {self.mass_scaling!r} must be >= 1")
        if not (0.0 <= self.flip <= 1.0):
            raise ValueError(f"discretisation.flip = {self.flip!r} is outside the allowed range [0, 1]")
        if self.dilatation not in DILATATION_MODES:
            raise ValueError(f"discretisation.dilatation = {self.dilatation!r} is not one of {list(DILATATION_MODES)}")
        if not isinstance(self.graded, bool):
            raise ValueError(f"discretisation.graded = {self.graded!r} must be true or false")
        k = self.fine_zone_contact_radii
        if not (isinstance(k, int | float) and math.isfinite(k) and k >= FINE_ZONE_MIN_CONTACT_RADII):
            raise ValueError(f"discretisation.fine_zone_contact_radii = {k!r} is outside the allowed range "
                             f"[{FINE_ZONE_MIN_CONTACT_RADII:g}, inf): the contact (one expected contact radius) "
                             "must lie in the fine zone")
        if self.fine_zone_shape not in FINE_ZONE_SHAPES:
            raise ValueError(f"discretisation.fine_zone_shape = {self.fine_zone_shape!r} is not one of "
                             f"{list(FINE_ZONE_SHAPES)}")
        k = self.fine_zone_depth_particles
        if k is not None and not (isinstance(k, int | float) and not isinstance(k, bool) and math.isfinite(k)
                                  and k >= FINE_ZONE_MIN_DEPTH_PARTICLES):
            raise ValueError(f"discretisation.fine_zone_depth_particles = {k!r} is outside the allowed range "
                             f"[{FINE_ZONE_MIN_DEPTH_PARTICLES:g}, inf) or null: particles of size h below the "
                             "expected groove and the coating")
        k = self.active_zone_contact_radii
        if k is not None and not (isinstance(k, int | float) and not isinstance(k, bool) and math.isfinite(k)
                                  and k >= ACTIVE_ZONE_MIN_CONTACT_RADII):
            raise ValueError(f"discretisation.active_zone_contact_radii = {k!r} is outside the allowed range "
                             f"[{ACTIVE_ZONE_MIN_CONTACT_RADII:g}, inf) or null: the plastic zone (about 2 expected "
                             "contact radii) must lie in the active zone")
        if self.contact not in CONTACT_MODES:
            raise ValueError(f"discretisation.contact = {self.contact!r} is not one of {list(CONTACT_MODES)}")
        if self.graded and self.particles_per_cell < 2:
            raise ValueError("discretisation.graded = true needs discretisation.particles_per_cell >= 2 (got "
                             f"{self.particles_per_cell}): the far-field particles of size 2 h must not exceed a cell")

    @property
    def cell_size_m(self) -> float:
        return self.particle_size_m * self.particles_per_cell


#: Fewest particle sizes h across the expected contact radius a (``Scene.contact_resolution``) for a run to
#: count as resolving its contact; below it the run warns (``plough.mpm.run.ResolutionWarning``) and its result
#: says so (``resolution``). Why 2: the contact acts on grid nodes up to one cell (2 h at 2 particles per cell)
#: outside the sphere, so below a = 2 h that error is as large as the contact itself; measured on the preview
#: matrix at the default controller (benchmarks/results/load_control_h20.json against load_control_h10_subset.json,
#: setting "1,100"), mu moved +40% from h = 20 to 10 um at a = 1.83 h, and by -20% to +10% at a = 2.3-3.3 h
#: (-4% at 5.3 h); issue 31's scene at a = 0.95 h gave mu 0.557 against the analytical 0.136. Every run of
#: config/config.yaml has a >= 2.06 h (its smoke and preview matrices, coarse on purpose, go down to 0.94 h).
RESOLVED_CONTACT_PARTICLES = 2.0

#: Highest initial temperature accepted, K: above the melting point of every metal of the materials
#: data (zinc 693 K, steel about 1800 K) the flow laws mean nothing; the check catches typos (in degC
#: or negative) rather than setting a physical bound per material.
INITIAL_TEMPERATURE_MAX_K = 2000.0


@dataclass(frozen=True)
class Outputs:
    """What a run records. ``steady_window`` is the fraction of the slide averaged for the
    steady-state results (paper: the last half, 0.3-0.6 mm of 0.6 mm). ``profile_sections``: the
    residual cross-sections averaged for dg, hpu, dp (0, the default: every particle row between
    the start of the steady window and 1.25 contact radii behind the sphere)."""

    steady_window: tuple[float, float] = (0.5, 1.0)
    records: int = 400
    snapshots: int = 0
    profile_sections: int = 0
    taylor_quinney: float = 0.9
    initial_temperature_K: float = ROOM_TEMPERATURE_K
    buried_profile_depth_m: float = 15e-6

    def __post_init__(self) -> None:
        lo, hi = self.steady_window
        if not (0 <= lo < hi <= 1):
            raise ValueError(f"outputs.steady_window = {self.steady_window!r} must satisfy 0 <= start < end <= 1")
        if self.records < 10:
            raise ValueError(f"outputs.records = {self.records!r} must be >= 10")
        if self.snapshots < 0:
            raise ValueError(f"outputs.snapshots = {self.snapshots!r} must be >= 0")
        if self.profile_sections < 0:
            raise ValueError(f"outputs.profile_sections = {self.profile_sections!r} must be >= 0 "
                             "(0: every particle row between the limits)")
        if not (math.isfinite(self.buried_profile_depth_m) and self.buried_profile_depth_m > 0):
            raise ValueError(f"outputs.buried_profile_depth_m = {self.buried_profile_depth_m!r} m must be > 0")
        if not (0 <= self.taylor_quinney <= 1):
            raise ValueError(f"outputs.taylor_quinney = {self.taylor_quinney!r} is outside [0, 1]")
        T = self.initial_temperature_K
        if isinstance(T, bool) or not (isinstance(T, int | float) and math.isfinite(T)
                                       and 0 < T <= INITIAL_TEMPERATURE_MAX_K):
            raise ValueError(f"outputs.initial_temperature_K = {T!r} K is outside the allowed range "
                             f"(0, {INITIAL_TEMPERATURE_MAX_K:g}] K")


# ----------------------------------------------------------------------------- materials in files
def material_from_spec(spec: Any, *, coating: bool, where: str) -> Material:
    """A material from a scene file: a name, ``{rigid_plastic_hardness_Pa: H}`` or a full dict."""
    if isinstance(spec, Material):
        return spec
    if isinstance(spec, str):
        try:
            return get_material(spec)
        except ValueError as exc:
            raise ValueError(f"{where}: {exc}") from None
    if isinstance(spec, dict):
        d = _to_si(spec, where)
        if "rigid_plastic_hardness_Pa" in d:
            extra = set(d) - {"rigid_plastic_hardness_Pa", "name"}
            if extra:
                raise ValueError(f"{where}: unknown key(s) {_as_given(extra, spec)} for a rigid-plastic material")
            H = _number(d["rigid_plastic_hardness_Pa"], f"{where}.rigid_plastic_hardness_Pa")
            name = str(d.get("name", f"rigid_plastic_H{H / 1e6:g}MPa"))
            return rigid_plastic(name, H, coating=coating)
        return Material.from_dict(_material_numbers(d, where, spec))
    raise ValueError(f"{where} = {spec!r} is not a material name, a rigid-plastic hardness or a material dict")


def _material_numbers(d: dict[str, Any], where: str, given: dict[Any, Any]) -> dict[str, Any]:
    """A material dict (``d``, in SI keys; ``given``, as written) with its keys checked and its numbers
    converted (``_MPa`` etc. in the flow mapping too), so that ``Material.from_dict`` sees only what it
    can build."""
    allowed = {f.name: str(f.type) for f in fields(Material)}
    missing = sorted(set(allowed) - set(d))
    unknown = _as_given(set(d) - set(allowed), given)
    if missing or unknown:
        raise ValueError(f"{where}: not a material: " + "; ".join(
            ([f"missing key(s) {missing}"] if missing else []) + ([f"unknown key(s) {unknown}"] if unknown else []))
            + f" (a material needs {sorted(allowed)}, or is a name of the materials data, or "
            "{rigid_plastic_hardness_MPa: H})")
    out = {k: _coerce(v, allowed[k], f"{where}.{k}") for k, v in d.items() if k != "flow"}
    given_flow = _mapping(d["flow"], f"{where}.flow")
    flow = _to_si(given_flow, f"{where}.flow")
    model = flow.get("model")
    if not isinstance(model, str) or model not in FLOW_MODELS:
        raise ValueError(f"{where}.flow.model = {model!r} is not one of {list(FLOW_MODELS)}")
    types = {f.name: str(f.type) for f in fields(FLOW_MODELS[model])}
    unknown = _as_given(set(flow) - set(types) - {"model"}, given_flow)
    missing = sorted(set(types) - set(flow))
    if missing or unknown:
        raise ValueError(f"{where}.flow ({model}): " + "; ".join(
            ([f"missing key(s) {missing}"] if missing else []) + ([f"unknown key(s) {unknown}"] if unknown else []))
            + f"; allowed: {sorted(types)}")
    out["flow"] = {"model": model} | {k: _coerce(v, types[k], f"{where}.flow.{k}") for k, v in flow.items()
                                      if k != "model"}
    return out


def _interface_numbers(d: dict[str, Any]) -> dict[str, Any]:
    """The interface dict with its numbers converted by the model's field types (YAML 1.1 reads 5e-1 as text)."""
    model = d.get("model")
    if not isinstance(model, str) or model not in INTERFACES:
        raise ValueError(f"interface.model = {model!r} is not one of {list(INTERFACES)}")
    cls = INTERFACES[model]
    types = {f.name: str(f.type) for f in fields(cls)}
    return {k: _coerce(v, types[k], f"interface.{k}") if k in types else v for k, v in d.items()}


# ----------------------------------------------------------------------------- the scene
@dataclass(frozen=True)
class Scene:
    """Everything a ploughing run needs, in SI units."""

    layers: Layers
    load_N: float = 3.0
    sphere: Sphere = field(default_factory=Sphere)
    interface: Interface = field(default_factory=ProportionalShear)
    domain: Domain = field(default_factory=Domain)
    sliding: Sliding = field(default_factory=Sliding)
    discretisation: Discretisation = field(default_factory=Discretisation)
    outputs: Outputs = field(default_factory=Outputs)
    name: str = "scene"

    def __post_init__(self) -> None:
        if not (isinstance(self.name, str) and _NAME_PATTERN.fullmatch(self.name)):
            raise ValueError(f"name = {self.name!r} is not allowed: it names the run's files, so it must be letters, "
                             "digits and . _ + - = only, starting with a letter, digit or _ (no path, no spaces)")
        if isinstance(self.load_N, bool):
            raise ValueError(f"load_N = {self.load_N!r} is not a number")
        _finite_positive("scene", "load_N", self.load_N, "N")
        if not isinstance(self.interface, ProportionalShear | ConstantShear | BoundaryLayerShear):
            raise ValueError(f"interface = {self.interface!r} is not an interface model")
        if isinstance(self.interface, BoundaryLayerShear) and self.interface.pressure == "traction" \
                and self.discretisation.contact == "particle":
            raise ValueError("interface.pressure = 'traction' needs discretisation.contact 'grid_local' or 'grid' "
                             "(the grid contact's nodal traction), not 'particle'")
        self._check_below_melting()
        self._check_fits()

    def _check_below_melting(self) -> None:
        """A Johnson-Cook layer has no strength at or above its melting temperature Tm_K."""
        T = self.outputs.initial_temperature_K
        for m in self.layers.materials:
            where = "substrate" if m is self.layers.substrate else "coating"
            if isinstance(m.flow, JohnsonCook) and T >= m.flow.Tm_K:
                raise ValueError(f"outputs.initial_temperature_K = {T:g} K is not below the melting temperature "
                                 f"Tm_K = {m.flow.Tm_K:g} K of the {where} material {m.name!r} (allowed: "
                                 f"0 < T < {m.flow.Tm_K:g} K)")

    # -- feasibility: refuse what cannot work before running
    def expected_contact(self) -> tuple[float, float]:
        """(contact radius a, ploughing depth dp) from the analytical model, for sizing and checks."""
        return expected_contact(self.layers, self.load_N, self.sphere.radius_m)

    def _check_fits(self) -> None:
        a, dp = self.expected_contact()
        r, dom, h = self.sphere.radius_m, self.domain, self.discretisation.particle_size_m
        if dp >= 0.5 * r:
            raise ValueError(f"load_N = {self.load_N:g} N is too large for sphere.radius_m = {r:g} m: the "
                             f"expected ploughing depth {dp:.3g} m exceeds half the radius")
        # the plastic zone reaches ~2-3 contact radii; the fixed boundary must stay outside it
        if 2.0 * a > dom.radius_m:
            raise ValueError(f"domain.radius_m = {dom.radius_m:g} m is too small for the expected contact radius "
                             f"{a:.3g} m (need domain.radius_m >= 2 a = {2 * a:.3g} m)")
        if self.sliding.distance_m + 4.0 * a > dom.length_m:
            raise ValueError(f"domain.length_m = {dom.length_m:g} m is too short for sliding.distance_m = "
                             f"{self.sliding.distance_m:g} m plus 2 contact diameters ({4 * a:.3g} m)")
        if self.sliding.distance_m < 2.7 * a:
            raise ValueError(f"sliding.distance_m = {self.sliding.distance_m:g} m is too short to leave a residual "
                             f"groove behind the sphere: it must be >= 2.7 expected contact radii ({2.7 * a:.3g} m)")
        if h > 0.25 * dom.radius_m:
            raise ValueError(f"discretisation.particle_size_m = {h:g} m is too coarse for domain.radius_m = "
                             f"{dom.radius_m:g} m (allowed: h <= radius / 4)")
        inertia = self.inertia_number
        if inertia > INERTIA_MAX:
            raise ValueError(f"discretisation.mass_scaling = {self.discretisation.mass_scaling:g} with "
                             f"sliding.speed_m_s = {self.sliding.speed_m_s:g} m/s gives an inertia number "
                             f"ms rho v^2 / H = {inertia:.3g} above the allowed {INERTIA_MAX:g}: inertia dominates and "
                             "the load is not held (lower mass_scaling or speed_m_s; the paper's settings give ~0.09)")
        if self.sliding.control == "displacement" and self.sliding.depth_m >= 0.5 * r:
            raise ValueError(f"sliding.depth_m = {self.sliding.depth_m:g} m must be below half the sphere radius")

    # -- derived quantities
    @property
    def grid_headroom_m(self) -> float:
        """Height of the grid above the original surface: ``domain.headroom_m``, or room for the
        pile-up of the expected groove, max(2 dp, 2 cells) + 0.5 dp (the grid adds 2-3 cells of
        padding). A prow that keeps growing (f = 1 at h = 2.5 um, docs/journal/2026-11-22-prow-at-h2.5.md; a soft
        coating the sphere sweeps ahead) outgrows any fixed rule, and one expected contact radius more would
        cost 9-22% more grid nodes at h <= 5 um on the reference scenes: with this automatic value
        the solver raises the grid's top mid-run where material reaches it
        and lengthens the grid past the block's far end and widens it past the side face
        (:mod:`plough.mpm.growth`)."""
        if self.domain.headroom_m is not None:
            return self.domain.headroom_m
        _, dp = self.expected_contact()
        return max(2.0 * dp, 2.0 * self.discretisation.cell_size_m) + 0.5 * dp

    @property
    def contact_resolution(self) -> float:
        """The expected contact radius in particle sizes, a / h (``RESOLVED_CONTACT_PARTICLES``)."""
        a, _ = self.expected_contact()
        return a / self.discretisation.particle_size_m

    def resolution_text(self) -> str:
        """The contact's resolution in words, under-resolved or not (the run's ``resolution`` attribute)."""
        a, _ = self.expected_contact()
        h = self.discretisation.particle_size_m
        text = f"expected contact radius a = {a * 1e6:.3g} um is {a / h:.3g} particle sizes (h = {h * 1e6:g} um)"
        if a / h >= RESOLVED_CONTACT_PARTICLES:
            return text
        return (f"{text}: under-resolved, below the {RESOLVED_CONTACT_PARTICLES:g} that resolve it (the contact acts "
                "on grid nodes up to a cell outside the sphere, an error as large as the contact): mu and dp say "
                "more about h than about the model; refine discretisation.particle_size_m")

    @property
    def active_zone_half_width_m(self) -> float | None:
        """Half-length of the active zone along x: ``active_zone_contact_radii`` expected contact
        radii, at least ACTIVE_ZONE_MIN_PARTICLES particle sizes; None without a zone."""
        k = self.discretisation.active_zone_contact_radii
        if k is None:
            return None
        a, _ = self.expected_contact()
        return max(k * a, ACTIVE_ZONE_MIN_PARTICLES * self.discretisation.particle_size_m)

    @property
    def inertia_number(self) -> float:
        """ms rho v^2 / H of the softest layer: the dynamic pressure of the slide over the hardness."""
        ms, v = self.discretisation.mass_scaling, self.sliding.speed_m_s
        return max(ms * m.density_kg_m3 * v * v / representative_hardness(m) for m in self.layers.materials)

    def _contact_surfaces(self) -> list[tuple[float, bool]]:
        """(kappa at the onset of yield, perfectly plastic?) of each surface the sphere can touch.

        The top particle layer (the coating; the volume-weighted coating / substrate mix when the
        coating is thinner than a particle, as the particles carry it), and the substrate when the
        expected ploughing depth reaches it. kappa = sigma_y(eps_p = 0, static, initial
        temperature) / sqrt 3, as the contact evaluates it on a fresh particle.
        """
        T = self.outputs.initial_temperature_K
        sub = self.layers.substrate

        def kappa(m: Material) -> float:
            return reference_flow_stress(m.flow, 0.0, 0.0, T) / math.sqrt(3.0)

        if not self.layers.coated:
            return [(kappa(sub), isinstance(sub.flow, ConstantFlow))]
        coat, t = self.layers.coating, self.layers.coating_thickness_m
        frac = min(t / self.discretisation.particle_size_m, 1.0)
        top_kappa = frac * kappa(coat) + (1.0 - frac) * kappa(sub)
        top_plastic = isinstance(coat.flow, ConstantFlow) and (frac >= 1.0 or isinstance(sub.flow, ConstantFlow))
        surfaces = [(top_kappa, top_plastic)]
        if self.expected_contact()[1] >= t:
            surfaces.append((kappa(sub), isinstance(sub.flow, ConstantFlow)))
        return surfaces

    def _surface_ratios(self) -> list[tuple[float, bool]] | None:
        """(tau / kappa capped at 1, perfectly plastic?) per surface of ``_contact_surfaces``; None when tau
        follows the contact pressure (boundary-layer interface)."""
        itf = self.interface
        if isinstance(itf, ProportionalShear):
            return [(itf.f, plastic) for _, plastic in self._contact_surfaces()]
        if isinstance(itf, ConstantShear):
            return [(min(itf.tau_Pa / k, 1.0), plastic) for k, plastic in self._contact_surfaces()]
        return None

    @property
    def interface_strength_ratio(self) -> float | None:
        """Largest tau / kappa over the surfaces the sphere can touch (``_contact_surfaces``); None when tau
        follows the contact pressure (boundary-layer interface). The solver caps tau at kappa, so the
        ratio is at most 1."""
        ratios = self._surface_ratios()
        return None if ratios is None else max(r for r, _ in ratios)

    @property
    def wave_limit_ratio(self) -> float:
        """cos^2 alpha, alpha the attack angle at the leading edge of the expected contact (sin alpha = a / r).

        The interface strength tau / kappa above which no steady ploughing wave exists: in Challen and Oxley's
        plane-strain wave model (Wear 53, 1979), in the form usually quoted, the friction contains
        arcsin(sin alpha / sqrt(1 - f)), real only for f <= cos^2 alpha; above it their analysis gives
        wedge formation, material building up ahead of the asperity. (The formula was not checked against
        the original here; the measured boundary below is what the flag rests on.) Under displacement
        control the contact is the one the set depth cuts, a^2 = 2 r d - d^2; otherwise the expected contact
        of the load."""
        r = self.sphere.radius_m
        if self.sliding.control == "displacement" and self.sliding.depth_m is not None:
            d = min(self.sliding.depth_m, r)
            a = math.sqrt(2.0 * r * d - d * d)
        else:
            a, _ = self.expected_contact()
        s = min(a / r, 1.0)
        return 1.0 - s * s

    @property
    def sticking_ratio(self) -> float | None:
        """Largest tau / kappa over the perfectly plastic surfaces the sphere touches whose ratio is at or above
        ``wave_limit_ratio``; None where there is none (``interface_sticks``)."""
        limit = self.wave_limit_ratio
        ratios = [r for r, plastic in self._surface_ratios() or [] if plastic and r >= limit]
        return max(ratios) if ratios else None

    @property
    def interface_sticks(self) -> bool:
        """Whether the interface is strong enough on a perfectly plastic surface the sphere touches that no
        steady state is expected: tau / kappa at or above ``wave_limit_ratio`` (``sticking_ratio``).

        The contact then sticks and drags the layer just below the surface along, a wedge of it builds
        up ahead of the sphere, and mu follows the simulated speed and mass scaling without settling
        (docs/journal/2026-11-22-interface-entrainment.md). Measured on the coated rigid-plastic scene at
        h = 20 um, down to 1/256 of the paper's inertia: mu settles at f = 0.5, 0.7 and 0.8 and wanders by +-6
        to 9% at f = 0.9, 0.95 and 1, where ``wave_limit_ratio`` is 0.894
        (docs/journal/2026-11-24-inertia-ladder-and-wave-limit.md); at h = 10 and 5 um the f = 1 runs rise
        with the simulated time (f = 0.5 settles). A hardening layer is not flagged: its strength grows
        under the sphere (not measured).
        """
        return self.sticking_ratio is not None

    @property
    def start_x_m(self) -> float:
        """x of the sphere centre when pressing: the slide is centred in the block."""
        return 0.5 * (self.domain.length_m - self.sliding.distance_m)

    @property
    def rate_scale(self) -> float:
        """Physical over simulated strain rate, v_experiment / v_simulation."""
        return self.sliding.experiment_speed_m_s / self.sliding.speed_m_s

    # -- conversion
    def to_dict(self) -> dict[str, Any]:
        layers = {"coating_thickness_m": self.layers.coating_thickness_m,
                  "substrate": self.layers.substrate.to_dict(),
                  "coating": None if self.layers.coating is None else self.layers.coating.to_dict()}
        outputs = asdict(self.outputs)
        outputs["steady_window"] = list(self.outputs.steady_window)
        return {
            "name": self.name,
            "load_N": self.load_N,
            "sphere": asdict(self.sphere),
            "layers": layers,
            "interface": interface_to_dict(self.interface),
            "domain": asdict(self.domain),
            "sliding": asdict(self.sliding),
            "discretisation": asdict(self.discretisation),
            "outputs": outputs,
        }

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Scene:
        d = dict(d)
        allowed = {f.name for f in fields(cls)}
        unknown = set(d) - allowed
        if unknown:
            raise ValueError(f"scene: unknown key(s) {sorted(map(str, unknown))}; allowed: {sorted(allowed)}")
        if "layers" not in d:
            raise ValueError("scene: the key 'layers' (substrate, coating, coating_thickness) is required")
        given_layers = _mapping(d["layers"], "layers")
        lay = _to_si(given_layers, "layers")
        unknown = set(lay) - {"substrate", "coating", "coating_thickness_m"}
        if unknown:
            raise ValueError(f"layers: unknown key(s) {_as_given(unknown, given_layers)}")
        if "substrate" not in lay:
            raise ValueError("layers.substrate is required")
        coating_spec = lay.get("coating")
        if coating_spec is not None and lay.get("coating_thickness_m") is None:
            raise ValueError("layers.coating_thickness (_um, _mm or _m) is missing or null although layers.coating "
                             "is given: give the thickness (0 for an uncoated scene) or leave the coating out")
        t = _coerce(lay.get("coating_thickness_m", 0.0) or 0.0, "float", "layers.coating_thickness_m")
        layers = Layers(
            substrate=material_from_spec(lay["substrate"], coating=False, where="layers.substrate"),
            coating=None if coating_spec is None else material_from_spec(coating_spec, coating=True,
                                                                           where="layers.coating"),
            coating_thickness_m=t,
        )
        kwargs: dict[str, Any] = {"layers": layers}
        if "name" in d:
            kwargs["name"] = str(d["name"])
        if "load_N" in d:
            kwargs["load_N"] = _coerce(d["load_N"], "float", "load_N")
        if "interface" in d:
            kwargs["interface"] = interface_from_dict(_interface_numbers(_to_si(_mapping(d["interface"], "interface"),
                                                                                "interface")))
        for key, cls_ in (("sphere", Sphere), ("domain", Domain), ("sliding", Sliding),
                          ("discretisation", Discretisation), ("outputs", Outputs)):
            if key in d:
                part = _mapping(d[key], key)
                if key == "outputs" and "steady_window" in part:
                    window = part["steady_window"]
                    if not (isinstance(window, list | tuple) and len(window) == 2):
                        raise ValueError(f"outputs.steady_window = {window!r} must be [start, end] fractions")
                    part["steady_window"] = tuple(_coerce(x, "float", "outputs.steady_window") for x in window)
                kwargs[key] = _from_dict(cls_, part, key)
        return cls(**kwargs)

    def to_yaml(self, path: str | Path | None = None) -> str:
        text = yaml.safe_dump(self.to_dict(), sort_keys=False)
        if path is not None:
            Path(path).write_text(text)
        return text

    @classmethod
    def from_yaml(cls, path_or_text: str | Path) -> Scene:
        return cls.from_dict(read_scene_data(path_or_text))

    def with_sized_domain(self, radius_contact_radii: float = 2.5, end_margin_contact_radii: float = 3.0) -> Scene:
        """A copy whose block is sized from the expected contact radius (see :func:`sized_domain`)."""
        dom = sized_domain(self.layers, self.load_N, self.sphere.radius_m, self.sliding.distance_m,
                           self.discretisation.particle_size_m, self.domain.symmetric,
                           radius_contact_radii, end_margin_contact_radii)
        return replace(self, domain=replace(dom, headroom_m=self.domain.headroom_m))

    def with_paper_settings(self) -> Scene:
        """The paper's numerical setup as a named preset: the fixed 0.2 mm x 1 mm half cylinder
        (mirror plane on), a 0.6 mm slide at 0.1 m/s, mass scaling 1e6, uniform particles, every
        particle updated on every step (no active zone), steady window the last half of the slide.
        Physics (layers, load, sphere, interface) and the particle size, CFL number and transfer are
        kept. ``benchmarks/work_precision.py`` runs it beside the defaults."""
        return replace(self, domain=replace(PAPER_DOMAIN, headroom_m=self.domain.headroom_m),
                       sliding=replace(self.sliding, distance_m=600e-6, speed_m_s=0.1, stop_when_steady=False),
                       discretisation=replace(self.discretisation, mass_scaling=1e6, graded=False,
                                              active_zone_contact_radii=None),
                       outputs=replace(self.outputs, steady_window=(0.5, 1.0)))

    def with_(self, **changes: Any) -> Scene:
        """A copy with some top-level parts replaced (validated again)."""
        return replace(self, **changes)


def read_scene_data(path_or_text: str | Path) -> dict[str, Any]:
    """The mapping a scene file (or YAML text) holds, as written (``Scene.from_dict`` builds the scene)."""
    p = Path(path_or_text)
    if isinstance(path_or_text, Path) or (isinstance(path_or_text, str) and "\n" not in path_or_text):
        if not p.exists():
            raise FileNotFoundError(f"scene file {str(p)!r} does not exist")
        if p.is_dir():
            raise ValueError(f"scene file {str(p)!r} is a directory, not a YAML file")
        # bytes: the YAML reader detects UTF-8 / UTF-16 itself, whatever the locale
        text: str | bytes = p.read_bytes()
        source = str(p)
    else:
        text = str(path_or_text)
        source = "scene text"
    try:
        # YAML 1.1: 5e-1 is text; the parts convert numbers by their field types
        data = yaml.load(text, Loader=_UniqueKeyLoader)  # noqa: S506 (a SafeLoader)
    except yaml.YAMLError as exc:
        where = getattr(exc, "problem_mark", None)
        at = f" at line {where.line + 1}, column {where.column + 1}" if where is not None else ""
        problem = getattr(exc, "problem", None) or str(exc).splitlines()[0]
        raise ValueError(f"{source}: not valid YAML{at}: {problem}") from None
    if not isinstance(data, dict):
        raise ValueError("a scene file must hold a mapping of keys to values")
    return data


def _default(cls: type, name: str) -> Any:
    f = {f.name: f for f in fields(cls)}[name]
    return f.default_factory() if f.default is MISSING else f.default  # type: ignore[misc]


def _plain(value: Any) -> Any:
    return list(value) if isinstance(value, tuple) else value


def defaults_taken(data: dict[str, Any], scene: Scene) -> dict[str, Any]:
    """The keys a scene file (``data``, as read) leaves out and the built-in default values the run takes for
    them: dotted SI key -> value (``interface`` -> its dict when the whole interface is left out).

    Decision (issue 31): a scene file may leave any key but ``layers`` out, and the dataclass defaults stay
    the one source of truth (docs/scenes.md lists them, tested against the dataclasses); a run says which it
    took (``plough mpm`` prints them, the result records them as ``scene_defaults``). A key a preset has set
    to another value since is not a default and is not listed; ``layers`` has no defaults worth naming (the
    substrate is required, a coating needs its thickness, no coating is uncoated).
    """
    out: dict[str, Any] = {}
    if "load_N" not in data and scene.load_N == _default(Scene, "load_N"):
        out["load_N"] = scene.load_N
    out |= _part_defaults(data, "sphere", scene.sphere)
    if "interface" not in data:
        if scene.interface == _default(Scene, "interface"):
            out["interface"] = interface_to_dict(scene.interface)
    else:
        given = _to_si(_mapping(data["interface"], "interface"), "interface")
        for f in fields(scene.interface):
            value = getattr(scene.interface, f.name)
            if f.name not in given and value == f.default:
                out[f"interface.{f.name}"] = value
    for part in ("domain", "sliding", "discretisation", "outputs"):
        out |= _part_defaults(data, part, getattr(scene, part))
    if "name" not in data and scene.name == _default(Scene, "name"):
        out["name"] = scene.name
    return out


def _part_defaults(data: dict[str, Any], part: str, obj: Any) -> dict[str, Any]:
    """The fields of one part (``sphere``, ``domain``, ...) the file leaves out, at their default values."""
    given = _to_si(_mapping(data.get(part), part), part)
    return {f"{part}.{f.name}": _plain(getattr(obj, f.name)) for f in fields(obj)
            if f.name not in given and _plain(getattr(obj, f.name)) == _plain(_default(type(obj), f.name))}


#: unit shown after a value, by its key's suffix (longest first)
_SHOWN_UNITS = (("_m_s", "m/s"), ("_Pa", "Pa"), ("_m", "m"), ("_N", "N"), ("_K", "K"))


def _shown(value: Any) -> str:
    if isinstance(value, bool) or value is None:
        return {True: "true", False: "false", None: "null"}[value]
    if isinstance(value, float | int):
        return f"{value:g}"
    if isinstance(value, list):
        return "[" + ", ".join(_shown(v) for v in value) + "]"
    return str(value)


def describe_defaults(defaults: dict[str, Any]) -> str:
    """``defaults_taken`` as one line: ``load_N = 3 N; sphere.radius_m = 0.0002 m; interface = proportional,
    f = 1; ...``."""
    items = []
    for key, value in defaults.items():
        if isinstance(value, dict):  # a whole interface
            items.append(f"{key} = " + ", ".join([str(value.get("model"))] + [f"{k} = {_shown(v)}" for k, v in
                                                                             value.items() if k != "model"]))
            continue
        unit = next((u for suffix, u in _SHOWN_UNITS if key.endswith(suffix)), "")
        items.append(f"{key} = {_shown(value)}" + (f" {unit}" if unit and value is not None else ""))
    return "; ".join(items)


def expected_contact(layers: Layers, load_N: float, sphere_radius_m: float) -> tuple[float, float]:
    """(contact radius a, ploughing depth dp) of the analytical model (eqs. 1-3), for sizing and checks.

    Hardness of each layer: 3 sigma_y at a representative plastic strain of 0.08 (Tabor), static
    rate, room temperature; k1 = 125.
    """
    from plough.analytical import ploughing

    Hs = representative_hardness(layers.substrate)
    Hc = representative_hardness(layers.coating) if layers.coated else Hs
    for where, H, m in (("substrate", Hs, layers.substrate), ("coating", Hc, layers.coating)):
        if not (math.isfinite(H) and H > 0):
            raise ValueError(f"layers.{where}: material {m.name!r} gives a hardness 3 sigma_y(0.08) = {H!r} Pa; "
                             "its flow-stress parameters must give a finite flow stress > 0")
    try:
        res = ploughing(load_N, sphere_radius_m, layers.coating_thickness_m, Hc, Hs, k1=125.0)
    except ValueError:
        return sphere_radius_m, sphere_radius_m
    return float(res.a), float(res.dp)


def sized_domain(layers: Layers, load_N: float, sphere_radius_m: float, slide_m: float, particle_size_m: float,
                 symmetric: bool = True, radius_contact_radii: float = 2.5,
                 end_margin_contact_radii: float = 3.0) -> Domain:
    """A block sized from the expected contact radius a instead of the paper's fixed 0.2 x 1 mm.

    Radius ``radius_contact_radii * a`` (at least 4 particle sizes), length the slide plus
    ``end_margin_contact_radii * a`` before the start and after the end, both rounded up to whole
    particle sizes. The plastic zone of a sliding sphere reaches about 2 a;
    ``benchmarks/mpm_reference.py --sized-domain`` against the same without the flag compares it
    with the paper's block (docs/journal/2026-11-22-paper-settings-cost.md).
    """
    if radius_contact_radii < 2.0 or end_margin_contact_radii < 2.0:
        raise ValueError(f"domain sizing factors radius_contact_radii = {radius_contact_radii!r}, "
                         f"end_margin_contact_radii = {end_margin_contact_radii!r} must be >= 2")
    a, _ = expected_contact(layers, load_N, sphere_radius_m)
    h = particle_size_m
    radius = round(h * math.ceil(max(radius_contact_radii * a, 4.0 * h) / h - 1e-9), 12)
    length = round(h * math.ceil((slide_m + 2.0 * end_margin_contact_radii * a) / h - 1e-9), 12)
    return Domain(radius_m=radius, length_m=length, symmetric=symmetric)
