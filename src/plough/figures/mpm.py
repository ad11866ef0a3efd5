"""MPM figures (Figs. 11-21, 23): extrapolated MPM marks with uncertainty bars, per-size values faint
with each run's sampling standard error (crossed where the run's window was not a steady state),
analytical lines, the coating-wear region shaded where dp > t, and pictures from particle data."""

from __future__ import annotations

import json
import re

import numpy as np
import xarray as xr
from matplotlib.artist import Artist
from matplotlib.lines import Line2D
from matplotlib.patches import Circle, Patch
from matplotlib.ticker import FixedFormatter, FixedLocator, NullLocator

from plough.figures.style import (
    FAILED_FINEST_LABEL,
    SideBySide,
    axes_entries,
    header,
    lighter,
    new_figure,
    note_entry,
    ring,
    save,
    shade_where,
)
from plough.study.extrapolation import total_uncertainty

SERIES_COLOURS = ["tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange"]
SIZE_MARKERS = ["^", "s", "v", "D", "P"]
#: the coating-thickness axis (Figs. 11b, 13b) is linear up to this thickness (um), logarithmic beyond
THICKNESS_LINEAR_UM = 10.0
THICKNESS_TICKS_UM = (0, 2, 4, 6, 8, 10, 20, 50, 100, 200, 500, 1000)
QUANTITY = {"dp": ("ploughing depth dp (µm)", 1e6), "mu": ("friction coefficient mu (-)", 1.0),
            "mu_pl": ("ploughing part mu_pl (-)", 1.0), "mu_sh": ("interface-shear part mu_sh (-)", 1.0),
            "penetration": ("penetration under load (µm)", 1e6)}
#: what a row of Figs. 11 / 13 shows, in its panels' titles
ROW_TITLES = {"dp": "ploughing depth dp", "mu": "friction mu", "mu_pl": "ploughing part mu_pl",
              "mu_sh": "interface-shear part mu_sh"}
#: Fig. 13's rows: mu and its two parts. The analytical model takes the interface part on an area fixed at
#: Fn / H, the MPM on its own contact (which with the grid contact grows under shear, and on coated scenes
#: carries a prow): mu alone would hide which part departs (docs/journal/2026-12-02-interface-shear-split.md)
FIG13_ROWS = ("mu", "mu_pl", "mu_sh")
FIG13_NOTE = ("note: mu_sh is the interface part. The analytical model takes it on the projected front area Fn / H,\n"
              "the MPM on its own contact (docs/journal/2026-12-02-interface-shear-split.md)")
#: the extrapolated marks and the line joining them (the trend), drawn above their bars
MARK_SIZE = 6.0
TREND_WIDTH = 1.6
#: per-size values: faint, under everything else
FAINT = 0.3
#: the key's entries for the flags and encodings the sweep figures share
UNSTEADY_LABEL = "x: run not steady"
FLAGGED_LABEL = "hollow: flagged (fallback fit)"
WORN_LABEL = "shaded: coating worn through (dp > t)"
SERIES_NAMES = {"zinc_block": "zinc block", "steel": "DX56 steel", "coated": "zinc-coated steel"}


def _label(value: object) -> str:
    return str(value).replace("_", " ")


def _series_name(series_dim: str, label: object) -> str:
    """A series' name in the key: 'soft coating', 'constant interface', '1 mm ball', 'DX56 steel'."""
    label = str(label)
    ball = re.fullmatch(r"r([0-9.]+)um", label)
    if series_dim == "ball" and ball:
        return f"{2.0 * float(ball[1]) / 1000.0:g} mm ball"
    if series_dim == "interface":
        return f"{label} interface"
    if series_dim == "coating":
        return f"{label} coating"
    return SERIES_NAMES.get(label, _label(label))


def _axis_label(da: xr.DataArray) -> str:
    units = da.attrs.get("units", "1")
    return da.attrs.get("long_name", da.name) + ("" if units == "1" else f" ({units.replace('um', 'µm')})")


def _sweep_panel(ax, ds: xr.Dataset, quantity: str, suffix: str, *, logx: bool = False,
                 thickness_axis: bool = False, thickness_um: float | None = None, panel: str = "",
                 extra_marks: tuple[float, ...] = ()) -> list[tuple[Artist, str]]:
    """One panel: every series of the figure along its axis. The trend first: the extrapolated marks
    joined by a line, their bars lighter and thinner behind them, the per-size values faint; the y axis
    follows the marks and lines (bars may leave it). Returns the panel's entries of the figure's key
    (``panel``: the panel's letter, which prefixes its series' names)."""
    name, scale = QUANTITY[quantity]
    per_size = ds[quantity + suffix]
    series_dim, axis = per_size.dims[0], per_size.dims[1]
    x = ds[axis].values
    h_values = ds["h"].values
    steady = ds.get(f"steady{suffix}")  # per run; absent for result files from before the check
    error = ds.get(f"{quantity}_standard_error{suffix}")  # per run (mu, mu_pl, mu_sh, dp); absent in old files
    unsteady_label, failed_label = UNSTEADY_LABEL, FAILED_FINEST_LABEL
    prefix = f"({panel}) " if panel else ""
    series_entries: list[tuple[Artist, str]] = []
    flag_entries: list[tuple[Artist, str]] = []
    any_flagged = any_analytical = False
    for i, label in enumerate(ds[series_dim].values):
        colour = SERIES_COLOURS[i % len(SERIES_COLOURS)]
        sel = {series_dim: label}
        for k in range(h_values.size):
            y = per_size.sel(sel).isel(h=k).values * scale
            ax.plot(x, y, ls="none", marker=SIZE_MARKERS[k % 5], ms=3.5, color=colour, alpha=FAINT, zorder=1.5)
            if error is not None:  # the run's own sampling error; none drawn where it was not estimable
                yerr = np.nan_to_num(error.sel(sel).isel(h=k).values * scale, nan=0.0)
                ax.errorbar(x, y, yerr=yerr, ls="none", color=colour, alpha=FAINT, elinewidth=0.6, zorder=1.5)
            if steady is not None:
                bad = steady.sel(sel).isel(h=k).values == 0
                if bad.any():
                    line, = ax.plot(x[bad], y[bad], ls="none", marker="x", ms=4.5, mew=0.9, color="k", zorder=2.5,
                                    label=unsteady_label)
                    if unsteady_label:
                        flag_entries.append((line, unsteady_label))
                    unsteady_label = None
        val = ds[f"{quantity}_h0{suffix}"].sel(sel).values * scale
        unc = ds[f"{quantity}_h0_uncertainty{suffix}"].sel(sel).values * scale
        sampling = ds.get(f"{quantity}_h0_sampling_error{suffix}")
        if sampling is not None:  # the runs' own noise carried to the limit, in quadrature with the GCI
            unc = total_uncertainty(unc, sampling.sel(sel).values * scale)
        flagged = ds[f"{quantity}_h0_flagged{suffix}"].sel(sel).values.astype(bool)
        any_flagged |= bool(flagged.any())
        ax.errorbar(x, val, yerr=unc, fmt="none", ecolor=lighter(colour), elinewidth=1.0, capsize=2, zorder=2)
        ax.plot(x, val, color=colour, lw=TREND_WIDTH, zorder=3)
        ax.plot(x[~flagged], val[~flagged], ls="none", marker="o", ms=MARK_SIZE, color=colour, zorder=4)
        if flagged.any():
            ax.plot(x[flagged], val[flagged], ls="none", marker="o", ms=MARK_SIZE, mfc="white", color=colour,
                    zorder=4)
        series_entries.append((Line2D([], [], color=colour, lw=TREND_WIDTH, marker="o", ms=MARK_SIZE),
                               prefix + _series_name(series_dim, label)))
        failed = ds.get(f"failed_finest{suffix}")  # absent in datasets from before mpm.finest_failure
        if failed is not None:
            stopped = failed.sel(sel).values.astype(bool)
            if stopped.any():
                ring(ax, x[stopped], val[stopped], failed_label)
                if failed_label:
                    flag_entries.append((ax.lines[-1], failed_label))
                failed_label = None
        ana = f"{quantity}_analytical{suffix}"
        if ana in ds:
            any_analytical = True
            ax.plot(x, ds[ana].sel(sel) * scale, color=colour, lw=1.2, ls="--", zorder=2.8)
    dp = ds.get(f"dp_h0{suffix}")
    if dp is not None:
        if thickness_axis:
            worn = (dp.isel({series_dim: 0}).values * 1e6) > x
        elif thickness_um is not None:
            worn = (dp.isel({series_dim: 0}).values * 1e6) > thickness_um
        else:
            worn = None
        if worn is not None and worn.any():
            shade_where(ax, x, worn, label=WORN_LABEL)
            flag_entries.append((ax.collections[-1], WORN_LABEL))
    if thickness_axis and quantity == "dp":
        line, = ax.plot(x, x, color="0.5", ls=":", lw=1, label="dotted: dp = t")
        flag_entries.append((line, "dotted: dp = t"))
    _follow_marks(ax, [per_size.values * scale, ds[f"{quantity}_h0{suffix}"].values * scale,
                       *([ds[f"{quantity}_analytical{suffix}"].values * scale] if any_analytical else []),
                       np.asarray(extra_marks, dtype=float)])
    if logx:  # ticks at the swept values, written plainly (0.5, 2), not as powers of ten
        ax.set_xscale("log")
        ax.xaxis.set_major_locator(FixedLocator(x))
        ax.xaxis.set_major_formatter(FixedFormatter([f"{v:g}" for v in x]))
        ax.xaxis.set_minor_locator(NullLocator())
    if thickness_axis:  # linear over the thin coatings where dp crosses t, logarithmic out to the bulk coating
        _thickness_axis(ax, x)
    ax.set_xlabel(_axis_label(ds[axis]))
    ax.set_ylabel(name)
    sizes = SideBySide(Line2D([], [], ls="none", marker=SIZE_MARKERS[k % 5], ms=4, color="0.3", alpha=0.6)
                  for k in range(h_values.size))
    style_entries = [(Line2D([], [], color="k", lw=TREND_WIDTH, marker="o", ms=MARK_SIZE),
                      "line + marks: MPM, h -> 0"),
                     *([(Line2D([], [], color="k", lw=1.2, ls="--"), "dashed: analytical model")]
                       if any_analytical else []),
                     *([(Line2D([], [], ls="none", color="k", marker="o", ms=MARK_SIZE, mfc="white"),
                         FLAGGED_LABEL)] if any_flagged else []),
                     (sizes, "faint: per size, coarsest to finest (each point's own sizes)"
                      if f"particle_size_um{suffix}" in ds  # mpm.ladder: relative
                      else "faint: per size, h = " + ", ".join(f"{h:g}" for h in h_values) + " µm")]
    return [*series_entries, *style_entries, *flag_entries]


def _follow_marks(ax, values: list[np.ndarray]) -> None:
    """The y axis from zero (or the lowest mark) to the highest mark, per-size value or analytical value:
    the trend fills the panel, and a bar longer than the spread of the marks runs past the edge."""
    marks = np.concatenate([np.ravel(v) for v in values])
    marks = marks[np.isfinite(marks)]
    if not marks.size:
        return
    lo, hi = min(0.0, float(marks.min())), max(float(marks.max()), 0.0)
    pad = 0.08 * (hi - lo) if hi > lo else max(abs(hi), 1e-9)
    ax.set_ylim(lo - (pad if lo < 0 else 0.0), hi + pad)


def _thickness_axis(ax, x: np.ndarray) -> None:
    """Symlog thickness axis: linear up to THICKNESS_LINEAR_UM, ticks where the thin coatings are."""
    ax.set_xscale("symlog", linthresh=THICKNESS_LINEAR_UM)
    lo, hi = float(np.nanmin(x)), max(float(np.nanmax(x)), THICKNESS_LINEAR_UM)
    left = -0.05 * THICKNESS_LINEAR_UM if lo < THICKNESS_LINEAR_UM else lo / 1.15
    ax.set_xlim(left, 1.3 * hi)
    ticks = [t for t in THICKNESS_TICKS_UM if left <= t <= 1.3 * hi]
    ax.xaxis.set_major_locator(FixedLocator(ticks))
    ax.xaxis.set_major_formatter(FixedFormatter([f"{t:g}" for t in ticks]))
    ax.xaxis.set_minor_locator(NullLocator())
    if lo < THICKNESS_LINEAR_UM:
        ax.axvline(THICKNESS_LINEAR_UM, color="0.8", lw=0.6, zorder=0)


def _fig11_13(ds: xr.Dataset, outputs, quantities: tuple[str, ...], figure: str,
              notes: tuple[tuple[Artist, str], ...] = ()) -> None:
    """Figs. 11 / 13: one row per quantity, (left) against the hardness ratio, (right) against the coating
    thickness; panels lettered row by row, one key, ``notes`` at its end."""
    rows = len(quantities)
    fig, axes = new_figure(rows, 2, height_per_row=4.4 if rows == 1 else 3.6)
    t_a = float(ds.attrs.get("ratio_sweep_thickness_um", np.nan))
    letters = [(chr(ord("a") + 2 * r), chr(ord("b") + 2 * r)) for r in range(rows)]
    # a column's series are the same in every row: named once in the key, with every panel they appear in
    left, right = (", ".join(pair[c] for pair in letters) for c in (0, 1))
    entries: list[list[tuple[Artist, str]]] = []
    for r, quantity in enumerate(quantities):
        ax_a, ax_b = axes[r, 0], axes[r, 1]
        entries.append(_sweep_panel(ax_a, ds, quantity, "_a", logx=True,
                                    thickness_um=t_a if np.isfinite(t_a) else None, panel=left))
        entries.append(_sweep_panel(ax_b, ds, quantity, "_b", thickness_axis=True, panel=right))
        what = f"{ROW_TITLES[quantity]} " if rows > 1 else ""  # one row: the figure's title says what
        ax_a.set_title(f"({letters[r][0]}) {what}vs hardness ratio H~", fontsize=10)
        ax_b.set_title(f"({letters[r][1]}) {what}vs coating thickness t", fontsize=10)
        if r < rows - 1:  # the rows share their x axes: labelled once, under the last row
            ax_a.set_xlabel("")
            ax_b.set_xlabel("")
    # one row: four columns, every series in the first line; more rows: two columns, so that each line holds
    # the series of one column of panels (two each), then the encodings two by two
    header(fig, figure, [*_series_first(*entries), *notes], ncol=4 if rows == 1 else 2)
    save(fig, outputs)


def _series_first(*panels: list[tuple[Artist, str]]) -> list[tuple[Artist, str]]:
    """The panels' entries with every panel's series names ahead of the shared encodings."""
    named = [e for p in panels for e in p if e[1].startswith("(")]
    return [*named, *(e for p in panels for e in p if not e[1].startswith("("))]


def plot_fig11(ds: xr.Dataset, outputs) -> None:
    _fig11_13(ds, outputs, ("dp",), "fig11")


def plot_fig13(ds: xr.Dataset, outputs) -> None:
    _fig11_13(ds, outputs, FIG13_ROWS, "fig13", notes=((note_entry("0.25"), FIG13_NOTE),))


def _vs_load(quantity: str, figure: str):
    def plot(ds: xr.Dataset, outputs) -> None:
        fig, axes = new_figure(1, 1, width=6.5, height_per_row=4.4)
        entries = _sweep_panel(axes[0, 0], ds, quantity, "")
        header(fig, figure, entries, ncol=2)
        save(fig, outputs)

    return plot


def plot_fig18(ds: xr.Dataset, outputs) -> None:
    fig, axes = new_figure(1, 1, width=6.5, height_per_row=4.4)
    ax = axes[0, 0]
    bulk = float(ds["dp_h0_bulk"].values.ravel()[0]) * 1e6
    unc = float(ds["dp_h0_uncertainty_bulk"].values.ravel()[0]) * 1e6
    entries = _sweep_panel(ax, ds, "dp", "_t", extra_marks=(bulk,))
    ax.axhspan(bulk - unc, bulk + unc, color="0.85", zorder=0)
    line = ax.axhline(bulk, color="k", ls="-.", lw=1.2, zorder=2.8)
    band = (Patch(color="0.85"), line)
    header(fig, "fig18", [*entries, (band, "dash-dot + band: bulk zinc, MPM h -> 0")], ncol=2)
    save(fig, outputs)


# ----------------------------------------------------------------------------- single-run figures
FORCE_STYLES = {"Fx": ("k", "-", "Fx: tangential force"), "Fz": ("tab:blue", "-", "Fz: normal force"),
                "Fx_pl": ("tab:green", "--", "Fx_pl: ploughing part of Fx"),
                "Fx_sh": ("tab:orange", "--", "Fx_sh: shear part of Fx")}


def _forces(ax, ds: xr.Dataset, case: str, names=("Fx", "Fz", "Fx_pl", "Fx_sh"), window_note: str = "") -> None:
    sub = ds.sel(case=case)
    s = sub["sliding_distance"].values * 1e6
    ok = np.isfinite(s)
    for n in names:
        c, ls, label = FORCE_STYLES[n]
        ax.plot(s[ok], sub[n].values[ok], color=c, ls=ls, lw=1, label=label)
    window = sub["in_steady_window"].values[ok].astype(bool)
    shade_where(ax, s[ok], window, label="shaded: steady window (means)" + window_note)
    ax.axhline(float(sub["Fz_mean"]), color="tab:blue", lw=0.6, ls=":", label="dotted: mean Fz in the window")
    ax.set_xlabel("sliding distance (µm)")
    ax.set_ylabel("force on the sphere (N)")


def _material_scatter(ax, u, v, coating, size: float) -> None:
    colours = np.where(np.asarray(coating) > 0.5, "tab:red", "0.55")
    ax.scatter(u, v, s=size, c=colours, marker="s", linewidths=0)
    ax.set_aspect("equal")


def _material_entries(panel: str, substrate: str) -> list[tuple[Artist, str]]:
    return [(Line2D([], [], ls="none", marker="s", ms=5, color="tab:red"), f"({panel}) coating particles"),
            (Line2D([], [], ls="none", marker="s", ms=5, color="0.55"), f"({panel}) {substrate} particles")]


def plot_fig12(ds: xr.Dataset, outputs) -> None:
    fig, axes = new_figure(1, 2, height_per_row=4.2)
    sub = ds.sel(case="coated")
    ok = np.isfinite(sub["midplane_x"].values)
    ax = axes[0, 0]
    _material_scatter(ax, sub["midplane_x"].values[ok] * 1e6, sub["midplane_z"].values[ok] * 1e6,
                      sub["midplane_coating"].values[ok], 4)
    scene = json.loads(ds.attrs["scene_coated"])
    centre = np.asarray(ds.attrs["sphere_centre_end_m_coated"])
    r = scene["sphere"]["radius_m"] * 1e6
    ax.add_patch(Circle((centre[0] * 1e6, centre[2] * 1e6), r, fill=False, color="k", label="sphere"))
    xm = sub["midplane_x"].values[ok] * 1e6
    ax.set_xlim(xm.min(), xm.max())
    ax.set_ylim(sub["midplane_z"].values[ok].min() * 1e6, 0.25 * (xm.max() - xm.min()))
    ax.set_xlabel("x (µm), sliding to +x")
    ax.set_ylabel("z (µm)")
    ax.set_title("(a) mid-plane y = 0 at the end of the slide", fontsize=10)
    _forces(axes[0, 1], ds, "coated")
    axes[0, 1].set_title("(b) forces on the sphere", fontsize=10)
    header(fig, "fig12", [*_material_entries("a", "substrate"), *axes_entries(axes)], ncol=3)
    save(fig, outputs)


def plot_fig14(ds: xr.Dataset, outputs) -> None:
    fig, axes = new_figure(2, 2, height_per_row=3.8)
    sub = ds.sel(case="coated")
    hmap = sub["height_map"].values * 1e6
    hx, hy = ds["hx"].values * 1e6, ds["hy"].values * 1e6
    ax = axes[0, 0]
    full = np.concatenate([hmap[:, ::-1], hmap], axis=1)  # mirror plane y = 0: draw the whole groove
    yy = np.concatenate([-hy[::-1], hy])
    lim = np.nanmax(np.abs(hmap))
    im = ax.pcolormesh(hx, yy, full.T, cmap="RdBu_r", vmin=-lim, vmax=lim, shading="nearest")
    fig.colorbar(im, ax=ax, label="height (µm)")
    ax.set_aspect("equal")
    ax.set_xlabel("x (µm)")
    ax.set_ylabel("y (µm)")
    ax.set_title("(a) top view: residual surface height", fontsize=10)
    ax = axes[0, 1]
    ax.plot(hx, hmap[:, 0], color="k", label="(b) groove bottom (y = 0)")
    ax.plot(hx, np.nanmax(hmap, axis=1), color="tab:red", label="(b) highest pile-up across y")
    ax.set_xlabel("x (µm)")
    ax.set_ylabel("height (µm)")
    ax.set_title("(b) along the scratch", fontsize=10)
    ax = axes[1, 0]
    y = ds["y"].values * 1e6
    z = sub["profile_z"].values * 1e6
    ax.plot(np.concatenate([-y[::-1], y]), np.concatenate([z[::-1], z]), color="k")
    dg, hpu, dp = (float(sub[v]) * 1e6 for v in ("dg", "hpu", "dp"))
    ax.axhline(0, color="0.6", lw=0.7)
    ax.axhline(-dg, color="tab:blue", ls="--", label=f"(c) groove depth dg = {dg:.3g} µm")
    ax.axhline(hpu, color="tab:red", ls="--", label=f"(c) pile-up height hpu = {hpu:.3g} µm")
    ax.set_title(f"(c) residual cross-section: dp = dg + hpu = {dp:.3g} µm", fontsize=10)
    ax.set_xlabel("y (µm)")
    ax.set_ylabel("z (µm)")
    ax = axes[1, 1]
    ok = np.isfinite(sub["section_y"].values)
    yy, zz = sub["section_y"].values[ok] * 1e6, sub["section_z"].values[ok] * 1e6
    cc = sub["section_coating"].values[ok]
    _material_scatter(ax, np.concatenate([-yy, yy]), np.concatenate([zz, zz]), np.concatenate([cc, cc]), 3)
    ax.set_xlabel("y (µm)")
    ax.set_ylabel("z (µm)")
    ax.set_title("(d) particles of the cross-section", fontsize=10)
    header(fig, "fig14", [*axes_entries(axes), *_material_entries("d", "steel")], ncol=3)
    save(fig, outputs)


def plot_fig17(ds: xr.Dataset, outputs) -> None:
    fig, axes = new_figure(1, 2, height_per_row=4.0)
    y = ds["y"].values * 1e6
    depth = json.loads(ds.attrs[f"scene_{ds['case'].values[0]}"])["outputs"]["buried_profile_depth_m"] * 1e6
    for ax, var, panel in ((axes[0, 0], "profile_z", "(a) surface"),
                           (axes[0, 1], "buried_profile_z", f"(b) material line that started at {depth:g} µm depth")):
        for i, case in enumerate(ds["case"].values):
            z = ds[var].sel(case=case).values * 1e6
            ax.plot(np.concatenate([-y[::-1], y]), np.concatenate([z[::-1], z]), color=SERIES_COLOURS[i],
                    label=SERIES_NAMES.get(str(case), _label(case)))
        ax.set_xlabel("y (µm)")
        ax.set_ylabel("z (µm)")
        ax.set_title(panel, fontsize=10)
    header(fig, "fig17", axes_entries(axes))
    save(fig, outputs)


def plot_fig19(ds: xr.Dataset, outputs) -> None:
    fig, axes = new_figure(1, 1, width=7.0, height_per_row=4.2)
    sub = ds.sel(case="coated")
    _forces(axes[0, 0], ds, "coated", window_note=f"; its mu = {float(sub['mu']):.3g} "
                                                  f"(analytical {float(sub['mu_analytical']):.3g})")
    header(fig, "fig19", axes_entries(axes), ncol=2)
    save(fig, outputs)


PLOTTERS = {
    "fig11": plot_fig11, "fig12": plot_fig12, "fig13": plot_fig13, "fig14": plot_fig14,
    "fig15": _vs_load("dp", "fig15"), "fig16": _vs_load("dp", "fig16"), "fig17": plot_fig17,
    "fig18": plot_fig18, "fig19": plot_fig19, "fig20": _vs_load("mu", "fig20"),
    "fig21": _vs_load("mu", "fig21"), "fig23": _vs_load("mu", "fig23"),
}
__all__ = ["PLOTTERS"]
