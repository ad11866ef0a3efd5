"""Materials and interfaces of the paper as typed, frozen data (Tables 2-5 of model.md).

This module is the single source of truth for material constants: the analytical model
(`plough.analytical`) reads hardness values from here and the MPM solver (`plough.mpm`)
packs the same objects into kernel arrays. Everything is SI (Pa, kg/m^3, K, J, W).

Flow-stress models (model.md section 2):

- :class:`ConstantFlow`        sigma_y = const (rigid-plastic studies, sigma_y = H / 3, Table 2)
- :class:`BergstromVanLiempt`  eq. 7.1, DX56 steel (Table 3)
- :class:`JohnsonCook`         eq. 7.2, bulk zinc (Table 4)
- :class:`CoatingPowerLaw`     eq. 7.3, zinc coating (Table 4)

Interface shear laws (eq. 8 and section 2 of the paper):

- :class:`ProportionalShear`   tau = f * kappa, kappa = shear strength of the softer body
- :class:`ConstantShear`       tau = H0 / k0
- :class:`BoundaryLayerShear`  tau = Cp * P^np (Table 5), P in Pa
"""

from __future__ import annotations

import math
from dataclasses import dataclass, fields, replace
from typing import Any

#: k0 = 3 sqrt(3): ratio of hardness to shear strength of a rigid-plastic metal (H = 3 sigma_y,
#: kappa = sigma_y / sqrt(3)).
K0 = 3.0 * math.sqrt(3.0)
#: Boltzmann constant in eV/K (used by eq. 7.1 with dG0 in eV).
BOLTZMANN_EV_PER_K = 8.617333262e-5


def _check_positive(owner: str, **values: float) -> None:
    for name, value in values.items():
        if not (isinstance(value, int | float) and math.isfinite(value) and value > 0):
            raise ValueError(f"{owner}: {name} = {value!r} is not allowed; it must be a finite number > 0")


def _check_non_negative(owner: str, **values: float) -> None:
    for name, value in values.items():
        if not (isinstance(value, int | float) and math.isfinite(value) and value >= 0):
            raise ValueError(f"{owner}: {name} = {value!r} is not allowed; it must be a finite number >= 0")


def _check_range(owner: str, name: str, value: float, lo: float, hi: float) -> None:
    if not (isinstance(value, int | float) and lo <= value <= hi):
        raise ValueError(f"{owner}: {name} = {value!r} is outside the allowed range [{lo}, {hi}]")


# ----------------------------------------------------------------------------- flow models
@dataclass(frozen=True)
class ConstantFlow:
    """Perfectly plastic: sigma_y = sigma_y_Pa (rigid-plastic studies use H / 3)."""

    sigma_y_Pa: float

    def __post_init__(self) -> None:
        _check_positive("ConstantFlow", sigma_y_Pa=self.sigma_y_Pa)


@dataclass(frozen=True)
class BergstromVanLiempt:
    """Bergstrom-van Liempt as modified by Vegter (eq. 7.1).

    sigma_y = sigma_f0 + dsigma_m (beta (eps + eps0) + (1 - exp(-omega (eps + eps0)))^c)
              + sigma_v0 (1 + (k_B T / dG0) ln(rate / rate0))^m,   last term >= 0
    """

    sigma_f0_Pa: float
    dsigma_m_Pa: float
    beta: float
    omega: float
    c: float
    eps0: float
    rate0_per_s: float
    sigma_v0_Pa: float
    m: float
    dG0_eV: float

    def __post_init__(self) -> None:
        _check_positive(
            "BergstromVanLiempt",
            sigma_f0_Pa=self.sigma_f0_Pa,
            dsigma_m_Pa=self.dsigma_m_Pa,
            omega=self.omega,
            c=self.c,
            rate0_per_s=self.rate0_per_s,
            m=self.m,
            dG0_eV=self.dG0_eV,
        )
        _check_non_negative("BergstromVanLiempt", beta=self.beta, eps0=self.eps0, sigma_v0_Pa=self.sigma_v0_Pa)


@dataclass(frozen=True)
class JohnsonCook:
    """Johnson-Cook (eq. 7.2).

    sigma_y = (A + B eps^p)(1 + C ln(rate / rate0))(1 - ((T - T0) / (Tm - T0))^q)
    """

    A_Pa: float
    B_Pa: float
    p: float
    C: float
    rate0_per_s: float
    q: float
    T0_K: float
    Tm_K: float

    def __post_init__(self) -> None:
        _check_positive(
            "JohnsonCook", A_Pa=self.A_Pa, p=self.p, rate0_per_s=self.rate0_per_s, q=self.q,
            T0_K=self.T0_K, Tm_K=self.Tm_K,
        )
        _check_non_negative("JohnsonCook", B_Pa=self.B_Pa)
        if not (isinstance(self.C, int | float) and math.isfinite(self.C)):  # C < 0 (softening with rate) is allowed
            raise ValueError(f"JohnsonCook: C = {self.C!r} is not allowed; it must be a finite number")
        if not self.Tm_K > self.T0_K:
            raise ValueError(f"JohnsonCook: Tm_K = {self.Tm_K!r} must exceed T0_K = {self.T0_K!r}")


@dataclass(frozen=True)
class CoatingPowerLaw:
    """Power law from nanoindentation (eq. 7.3): sigma_y = sigma_y0 (1 + E eps / sigma_y0)^n."""

    sigma_y0_Pa: float
    E_Pa: float
    n: float

    def __post_init__(self) -> None:
        _check_positive("CoatingPowerLaw", sigma_y0_Pa=self.sigma_y0_Pa, E_Pa=self.E_Pa)
        _check_range("CoatingPowerLaw", "n", self.n, 0.0, 1.0)


FlowModel = ConstantFlow | BergstromVanLiempt | JohnsonCook | CoatingPowerLaw
FLOW_MODELS: dict[str, type] = {
    "constant": ConstantFlow,
    "bergstrom_van_liempt": BergstromVanLiempt,
    "johnson_cook": JohnsonCook,
    "coating_power_law": CoatingPowerLaw,
}


def flow_model_name(flow: FlowModel) -> str:
    for name, cls in FLOW_MODELS.items():
        if isinstance(flow, cls):
            return name
    raise TypeError(f"unknown flow model {flow!r}")


# ----------------------------------------------------------------------------- material
@dataclass(frozen=True)
class Material:
    """An elastic-plastic metal: elastic constants, thermal data and a flow-stress model."""

    name: str
    density_kg_m3: float
    youngs_modulus_Pa: float
    poisson_ratio: float
    heat_capacity_J_kgK: float
    conductivity_W_mK: float
    flow: FlowModel

    def __post_init__(self) -> None:
        owner = f"Material {self.name!r}"
        _check_positive(
            owner,
            density_kg_m3=self.density_kg_m3,
            youngs_modulus_Pa=self.youngs_modulus_Pa,
            heat_capacity_J_kgK=self.heat_capacity_J_kgK,
            conductivity_W_mK=self.conductivity_W_mK,
        )
        _check_range(owner, "poisson_ratio", self.poisson_ratio, 0.0, 0.499)
        if not isinstance(self.flow, tuple(FLOW_MODELS.values())):
            raise ValueError(f"{owner}: flow = {self.flow!r} is not one of {list(FLOW_MODELS)}")

    @property
    def bulk_modulus_Pa(self) -> float:
        """K = E / (3 (1 - 2 nu))."""
        return self.youngs_modulus_Pa / (3.0 * (1.0 - 2.0 * self.poisson_ratio))

    @property
    def shear_modulus_Pa(self) -> float:
        """G = E / (2 (1 + nu))."""
        return self.youngs_modulus_Pa / (2.0 * (1.0 + self.poisson_ratio))

    @property
    def uses_rate(self) -> bool:
        """True if the flow stress depends on the strain rate."""
        return isinstance(self.flow, BergstromVanLiempt | JohnsonCook) and not (
            isinstance(self.flow, JohnsonCook) and self.flow.C == 0.0
        )

    @property
    def uses_temperature(self) -> bool:
        """True if the flow stress depends on temperature (adiabatic heating matters)."""
        return isinstance(self.flow, BergstromVanLiempt | JohnsonCook)

    def to_dict(self) -> dict[str, Any]:
        d = {f.name: getattr(self, f.name) for f in fields(self) if f.name != "flow"}
        d["flow"] = {"model": flow_model_name(self.flow)} | {
            f.name: getattr(self.flow, f.name) for f in fields(self.flow)
        }
        return d

    @classmethod
    def from_dict(cls, d: dict[str, Any]) -> Material:
        d = dict(d)
        flow = dict(d.pop("flow"))
        model = flow.pop("model")
        if model not in FLOW_MODELS:
            raise ValueError(f"flow.model = {model!r} is not one of {list(FLOW_MODELS)}")
        return cls(flow=FLOW_MODELS[model](**flow), **d)


# ----------------------------------------------------------------------------- interfaces
@dataclass(frozen=True)
class ProportionalShear:
    """tau = f * kappa: a fraction f of the shear strength of the contacting material."""

    f: float = 1.0

    def __post_init__(self) -> None:
        _check_range("ProportionalShear", "f", self.f, 0.0, 1.0)


@dataclass(frozen=True)
class ConstantShear:
    """tau = H0 / k0, the same on coating and substrate (paper: H0 = 450 MPa)."""

    H0_Pa: float = 450e6

    def __post_init__(self) -> None:
        _check_positive("ConstantShear", H0_Pa=self.H0_Pa)

    @property
    def tau_Pa(self) -> float:
        return self.H0_Pa / K0


#: where the MPM reads the boundary layer's local contact pressure P (docs/model.md, section 3.7)
BOUNDARY_LAYER_PRESSURES = ("particles", "traction")
DEFAULT_BOUNDARY_LAYER_PRESSURE = BOUNDARY_LAYER_PRESSURES[0]


@dataclass(frozen=True)
class BoundaryLayerShear:
    """tau = Cp * P^np with P the contact pressure in Pa (eq. 8.3, Table 5).

    ``pressure`` says where the MPM's grid contact reads the local P at a contact node: ``particles`` (the
    default), -n . sigma . n of the node's particles, mass-averaged; ``traction``, the normal traction the
    sphere puts on the node (its normal impulse over its surface share and the step), averaged over the
    contact's hold. The analytical model always takes the nominal Fn / Axy.
    """

    Cp: float
    np: float
    pressure: str = DEFAULT_BOUNDARY_LAYER_PRESSURE

    def __post_init__(self) -> None:
        _check_positive("BoundaryLayerShear", Cp=self.Cp)
        _check_range("BoundaryLayerShear", "np", self.np, 0.0, 1.0)
        if self.pressure not in BOUNDARY_LAYER_PRESSURES:
            raise ValueError(f"interface.pressure = {self.pressure!r} is not one of {list(BOUNDARY_LAYER_PRESSURES)}")


Interface = ProportionalShear | ConstantShear | BoundaryLayerShear
INTERFACES: dict[str, type] = {
    "proportional": ProportionalShear,
    "constant": ConstantShear,
    "boundary_layer": BoundaryLayerShear,
}


def interface_name(interface: Interface) -> str:
    for name, cls in INTERFACES.items():
        if isinstance(interface, cls):
            return name
    raise TypeError(f"unknown interface {interface!r}")


def interface_to_dict(interface: Interface) -> dict[str, Any]:
    return {"model": interface_name(interface)} | {
        f.name: getattr(interface, f.name) for f in fields(interface)
    }


def interface_from_dict(d: dict[str, Any]) -> Interface:
    d = dict(d)
    model = d.pop("model", None)
    if model not in INTERFACES:
        raise ValueError(f"interface.model = {model!r} is not one of {list(INTERFACES)}")
    cls = INTERFACES[model]
    allowed = {f.name for f in fields(cls)}
    unknown = set(d) - allowed
    if unknown:
        raise ValueError(f"interface: unknown key(s) {sorted(map(str, unknown))} for model {model!r}; "
                         f"allowed: {sorted(allowed)}")
    try:
        return cls(**d)
    except TypeError as exc:
        raise ValueError(f"interface ({model}): {exc}") from None


# ----------------------------------------------------------------------------- the paper's data
#: Table 3: DX56 deep-drawing steel, Bergstrom-van Liempt.
DX56 = Material(
    name="dx56",
    density_kg_m3=7850.0,
    youngs_modulus_Pa=210e9,
    poisson_ratio=0.3,
    heat_capacity_J_kgK=502.0,
    conductivity_W_mK=50.0,
    flow=BergstromVanLiempt(
        sigma_f0_Pa=82.988e6,
        dsigma_m_Pa=279.436e6,
        beta=0.482,
        omega=6.690,
        c=0.5,
        eps0=0.005,
        rate0_per_s=1e8,
        sigma_v0_Pa=1000e6,
        m=3.182,
        dG0_eV=0.8,
    ),
)

#: Table 4: bulk zinc, Johnson-Cook.
ZINC_BULK = Material(
    name="zinc_bulk",
    density_kg_m3=7140.0,
    youngs_modulus_Pa=108e9,
    poisson_ratio=0.25,
    heat_capacity_J_kgK=377.0,
    conductivity_W_mK=116.0,
    flow=JohnsonCook(
        A_Pa=82.51e6, B_Pa=288.34e6, p=0.1786, C=0.0202, rate0_per_s=1.0, q=0.843,
        T0_K=298.0, Tm_K=692.68,
    ),
)

#: Table 4: zinc coating, power law from nanoindentation (E of eq. 7.3 is the coating's E).
ZINC_COATING = Material(
    name="zinc_coating",
    density_kg_m3=7140.0,
    youngs_modulus_Pa=80e9,
    poisson_ratio=0.3,
    heat_capacity_J_kgK=377.0,
    conductivity_W_mK=116.0,
    flow=CoatingPowerLaw(sigma_y0_Pa=85e6, E_Pa=80e9, n=0.14),
)

#: Table 5: boundary-layer shear with Quaker FERROCOAT N6130.
LUBRICANT_DX56 = BoundaryLayerShear(Cp=1.34, np=0.88)
LUBRICANT_ZINC = BoundaryLayerShear(Cp=0.32, np=0.95)

#: Table 2: elastic constants of the rigid-plastic studies.
RIGID_PLASTIC_SUBSTRATE_E_PA = 210e9
RIGID_PLASTIC_COATING_E_PA = 80e9
RIGID_PLASTIC_NU = 0.3
#: Reference temperature of the simulations (K).
ROOM_TEMPERATURE_K = 298.0

MATERIALS: dict[str, Material] = {m.name: m for m in (DX56, ZINC_BULK, ZINC_COATING)}
LUBRICANTS: dict[str, BoundaryLayerShear] = {"dx56": LUBRICANT_DX56, "zinc": LUBRICANT_ZINC}


def rigid_plastic(name: str, hardness_Pa: float, *, coating: bool) -> Material:
    """A Table-2 rigid-plastic material: constant flow stress H / 3.

    Density and thermal data are not in Table 2; we use steel's (substrate) and zinc's
    (coating) values. They only set inertia (mass-scaled anyway) and play no other role,
    because a constant flow stress depends neither on rate nor on temperature.
    """
    _check_positive(f"rigid_plastic {name!r}", hardness_Pa=hardness_Pa)
    base = ZINC_COATING if coating else DX56
    return replace(
        base,
        name=name,
        youngs_modulus_Pa=RIGID_PLASTIC_COATING_E_PA if coating else RIGID_PLASTIC_SUBSTRATE_E_PA,
        poisson_ratio=RIGID_PLASTIC_NU,
        flow=ConstantFlow(sigma_y_Pa=hardness_Pa / 3.0),
    )


def get_material(name: str) -> Material:
    """Look a named material up (``dx56``, ``zinc_bulk``, ``zinc_coating``)."""
    try:
        return MATERIALS[name]
    except KeyError:
        raise ValueError(f"material = {name!r} is unknown; known materials: {sorted(MATERIALS)}") from None


# ----------------------------------------------------------------------------- plain-Python reference
def reference_flow_stress(flow: FlowModel, eps_p: float, rate_per_s: float = 0.0,
                          temperature_K: float = ROOM_TEMPERATURE_K) -> float:
    """Flow stress (Pa) of eqs. 7.1-7.3 in plain Python: the slow reference for the numba kernels
    and the source of representative hardness values for scene checks.

    Rate conventions: the BvL thermal-activation term is 0 at zero rate and clipped at 0;
    Johnson-Cook rates below rate0 give no softening (max(rate, rate0)).
    """
    if isinstance(flow, ConstantFlow):
        return flow.sigma_y_Pa
    if isinstance(flow, BergstromVanLiempt):
        e = eps_p + flow.eps0
        athermal = flow.sigma_f0_Pa + flow.dsigma_m_Pa * (flow.beta * e + (1.0 - math.exp(-flow.omega * e)) ** flow.c)
        if rate_per_s <= 0.0:
            return athermal
        base = 1.0 + BOLTZMANN_EV_PER_K * temperature_K / flow.dG0_eV * math.log(rate_per_s / flow.rate0_per_s)
        return athermal + flow.sigma_v0_Pa * max(base, 0.0) ** flow.m
    if isinstance(flow, JohnsonCook):
        strain = flow.A_Pa + flow.B_Pa * eps_p**flow.p if eps_p > 0 else flow.A_Pa
        rate = 1.0 + flow.C * math.log(max(rate_per_s, flow.rate0_per_s) / flow.rate0_per_s)
        theta = min(max((temperature_K - flow.T0_K) / (flow.Tm_K - flow.T0_K), 0.0), 1.0)
        return strain * rate * (1.0 - theta**flow.q)
    if isinstance(flow, CoatingPowerLaw):
        return flow.sigma_y0_Pa * (1.0 + flow.E_Pa * eps_p / flow.sigma_y0_Pa) ** flow.n
    raise TypeError(f"unknown flow model {flow!r}")


#: Representative plastic strain of an indentation (Tabor): H ~ 3 sigma_y(0.08).
TABOR_STRAIN = 0.08


def representative_hardness(material: Material) -> float:
    """Hardness estimate H = 3 sigma_y(eps = 0.08, static rate, room temperature), in Pa.

    For the constant-flow rigid-plastic materials this is exactly the Table-2 hardness.
    """
    return 3.0 * reference_flow_stress(material.flow, TABOR_STRAIN, 0.0, ROOM_TEMPERATURE_K)
