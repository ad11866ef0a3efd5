"""Datasets behind the analytical figures of studies.md (Figs. 3, 4 and the fits of Fig. 22).

Each builder takes the figure's block of the workflow config (units in the key names) and
returns an ``xarray.Dataset`` with ``units``/``long_name`` on every variable and the config as a
provenance attribute. Coordinates come from the config values, never from float arithmetic.
"""

from __future__ import annotations

from typing import Any

import numpy as np
import xarray as xr

from plough.analytical import PAPER_FITS, RESULT_META, ploughing, power_law_friction
from plough.analytical.powerlaw import PAPER_FIT_WARNING
from plough.io import provenance_attrs

FRICTION = ("mu", "mu_pl", "mu_sh")


def axis_values(spec: Any) -> np.ndarray:
    """A config axis: a list of values, or {start, stop, num[, log]} for a dense line."""
    if isinstance(spec, dict):
        if spec.get("log", False):
            return np.geomspace(spec["start"], spec["stop"], int(spec["num"]))
        return np.linspace(spec["start"], spec["stop"], int(spec["num"]))
    return np.asarray(spec, dtype=float)


def _attrs(name: str) -> dict[str, str]:
    units, long_name = RESULT_META[name]
    return {"units": units, "long_name": long_name}


def _coord(values: np.ndarray, units: str, long_name: str) -> tuple:
    return (values, {"units": units, "long_name": long_name})


def _common(cfg: dict[str, Any]) -> dict[str, float]:
    return dict(load_N=float(cfg["load_N"]), radius_m=float(cfg["radius_mm"]) * 1e-3,
                k1=float(cfg["k1"]), f=float(cfg["f"]))


def _coating_cases(cfg: dict[str, Any]) -> tuple[list[str], np.ndarray, np.ndarray]:
    names = ["soft", "hard"]
    ratio = np.array([cfg[n]["hardness_ratio"] for n in names], dtype=float)
    Hs = np.array([cfg[n]["substrate_hardness_MPa"] for n in names], dtype=float) * 1e6
    return names, ratio, Hs


def thickness_sweep(cfg: dict[str, Any], correction: str = "none") -> xr.Dataset:
    """Panels (a)/(b) of Figs. 3 and 4: outputs vs t for the soft and the hard coating."""
    names, ratio, Hs = _coating_cases(cfg)
    t_um = axis_values(cfg["thickness_um"])
    res = ploughing(thickness_m=t_um[None, :] * 1e-6, coating_hardness_Pa=(ratio * Hs)[:, None],
                    substrate_hardness_Pa=Hs[:, None], correction=correction, **_common(cfg))
    dims = ("coating", "thickness_um")
    ds = xr.Dataset(
        {name: (dims, np.asarray(getattr(res, name)), _attrs(name)) for name in (*FRICTION, "dp", "regime")},
        coords={
            "coating": ("coating", names, {"long_name": "coating case"}),
            "thickness_um": ("thickness_um", t_um, {"units": "um", "long_name": "coating thickness t"}),
            "case_hardness_ratio": ("coating", ratio, {"units": "1", "long_name": "hardness ratio Hc/Hs"}),
            "substrate_hardness_MPa": ("coating", Hs * 1e-6, {"units": "MPa", "long_name": "substrate hardness"}),
        },
    )
    return ds


def ratio_sweep(cfg: dict[str, Any], corrections: list[str]) -> xr.Dataset:
    """Panels (c)/(d) of Fig. 3 and (b) of Fig. 4: outputs vs H~ at fixed thicknesses."""
    sweep = cfg["ratio_sweep"]
    ratio = axis_values(sweep["hardness_ratio"])
    t_um = np.asarray(sweep["thickness_um"], dtype=float)
    Hs = float(sweep["substrate_hardness_MPa"]) * 1e6
    per_corr = []
    for corr in corrections:
        res = ploughing(thickness_m=t_um[:, None] * 1e-6, coating_hardness_Pa=ratio[None, :] * Hs,
                        substrate_hardness_Pa=Hs, correction=corr, **_common(cfg))
        per_corr.append({name: np.asarray(getattr(res, name)) for name in (*FRICTION, "dp", "regime")})
    dims = ("correction", "panel_thickness_um", "hardness_ratio")
    return xr.Dataset(
        {name + "_vs_ratio": (dims, np.stack([p[name] for p in per_corr]), _attrs(name))
         for name in (*FRICTION, "dp", "regime")},
        coords={
            "correction": ("correction", list(corrections), {"long_name": "normal-load correction (eq. 5)"}),
            "panel_thickness_um": ("panel_thickness_um", t_um, {"units": "um", "long_name": "coating thickness t"}),
            "hardness_ratio": ("hardness_ratio", ratio, {"units": "1", "long_name": "hardness ratio Hc/Hs"}),
        },
        attrs={"ratio_sweep_substrate_hardness_MPa": Hs * 1e-6},
    )


def fig03_dataset(cfg: dict[str, Any]) -> xr.Dataset:
    ds = xr.merge([thickness_sweep(cfg)[[*FRICTION, "regime"]], ratio_sweep(cfg, ["none"])
                   .drop_vars(["dp_vs_ratio"])], combine_attrs="drop_conflicts")
    ds.attrs.update(provenance_attrs(cfg), figure="fig03", title=(
        f"Fig. 3 - analytical friction, r = {cfg['radius_mm']} mm, Fn = {cfg['load_N']} N, "
        f"k1 = {cfg['k1']}, proportional shear f = {cfg['f']}"))
    return ds


def fig04_dataset(cfg: dict[str, Any]) -> xr.Dataset:
    corrections = list(cfg["corrections"])
    ds = xr.merge([thickness_sweep(cfg)[["dp", "regime"]],
                   ratio_sweep(cfg, corrections)[["dp_vs_ratio", "regime_vs_ratio"]]],
                  combine_attrs="drop_conflicts")
    ds.attrs.update(provenance_attrs(cfg), figure="fig04", title=(
        f"Fig. 4 - analytical ploughing depth, r = {cfg['radius_mm']} mm, Fn = {cfg['load_N']} N, "
        f"k1 = {cfg['k1']}"))
    return ds


def fig22_dataset(cfg: dict[str, Any]) -> xr.Dataset:
    """Power-law fits (eqs. 9.1-9.2) vs load for the 1 mm and 3 mm balls."""
    loads = axis_values(cfg["load_N"])
    balls = np.asarray(cfg["ball_diameters_mm"], dtype=float)
    out = {name: [] for name in ("mu", "mu_pl", "mu_sh", "dp")}
    for d in balls:
        if float(d) not in PAPER_FITS:
            raise ValueError(f"ball_diameters_mm = {d:g} has no power-law fit; allowed: {sorted(PAPER_FITS)}")
        res = power_law_friction(loads, PAPER_FITS[float(d)])
        for name in out:
            out[name].append(getattr(res, name))
    dims = ("ball_diameter_mm", "load_N")
    ds = xr.Dataset(
        {f"{name}_fit": (dims, np.array(v), {"units": RESULT_META[name][0],
                                              "long_name": RESULT_META[name][1] + " (power-law fit, eqs. 9.1-9.2)"})
         for name, v in out.items()},
        coords={"ball_diameter_mm": ("ball_diameter_mm", balls, {"units": "mm", "long_name": "ball diameter"}),
                "load_N": ("load_N", loads, {"units": "N", "long_name": "normal load"})},
    )
    ds.attrs.update(provenance_attrs(cfg), figure="fig22", warning=PAPER_FIT_WARNING,
                    title="Fig. 22 - friction vs load from the paper's power-law fits (eqs. 9.1-9.2)")
    return ds


BUILDERS = {"fig03": ("analytical", fig03_dataset), "fig04": ("analytical", fig04_dataset),
            "fig22": ("power_law", fig22_dataset)}


def config_section(figure: str) -> str:
    """The key of the workflow config that a figure's dataset reads."""
    if figure not in BUILDERS:
        raise ValueError(f"figure = {figure!r} has no analytical dataset; allowed: {sorted(BUILDERS)}")
    return BUILDERS[figure][0]


def build_dataset(figure: str, section_config: dict[str, Any]) -> xr.Dataset:
    """The dataset of one analytical figure from its section of the workflow config."""
    config_section(figure)
    return BUILDERS[figure][1](section_config)
