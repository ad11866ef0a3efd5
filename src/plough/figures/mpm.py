"""MPM figures (Figs. 11-21, 23): extrapolated MPM marks with uncertainty bars, per-size values faint
with each run's sampling standard error (crossed where the run's window was not a steady state),
analytical lines, the coating-wear region shaded where dp > t, and pictures from particle data."""

from __future__ import annotations

import json

import numpy as np
import xarray as xr
from matplotlib.patches import Circle
from matplotlib.ticker import FixedFormatter, FixedLocator, NullLocator
from matplotlib.transforms import offset_copy

from plough.figures.style import FAILED_FINEST_LABEL, caption, new_figure, ring, save, shade_where

SERIES_COLOURS = ["tab:blue", "tab:red", "tab:green", "tab:purple", "tab:orange"]
SIZE_MARKERS = ["^", "s", "v", "D", "P"]
#: the coating-thickness axis (Figs. 11b, 13b) is linear up to this thickness (um), logarithmic beyond
THICKNESS_LINEAR_UM = 10.0
THICKNESS_TICKS_UM = (0, 2, 4, 6, 8, 10, 20, 50, 100, 200, 500, 1000)
QUANTITY = {"dp": ("ploughing depth dp (µm)", 1e6), "mu": ("friction coefficient mu (-)", 1.0),
            "penetration": ("penetration under load (µm)", 1e6)}
FINDINGS = {
    "fig11": "Paper: MPM and analytical dp agree for H~ >= 0.5; below, the soft coating piles up, stacks and "
             "wears (CW). MPM slope change (dp = t) at t = 5.75 µm (soft) and 4.3 µm (hard).",
    "fig13": "Paper: MPM and analytical mu agree for H~ >= 0.5; the analytical mu changes regime at "
             "t = 6.5 µm (soft) and 7.8 µm (hard).",
    "fig15": "Paper: zinc ploughs deeper than DX56 steel at every load and its dp grows faster.",
    "fig16": "Paper: the 3 mm ball ploughs less than the 1 mm ball.",
    "fig18": "Paper: dp grows with the coating thickness (the effective hardness falls) towards bulk zinc.",
    "fig20": "Paper: zinc's friction is slightly above steel's above 7 N.",
    "fig21": "Paper: with the 1 mm ball mu rises steadily with load; with the 3 mm ball it is lower and nearly "
             "constant.",
    "fig23": "Paper: the zinc coating gives the lowest friction of the three.",
}


def _label(value: object) -> str:
    return str(value).replace("_", " ")


def _sweep_panel(ax, ds: xr.Dataset, quantity: str, suffix: str, *, logx: bool = False,
                 thickness_axis: bool = False, thickness_um: float | None = None) -> None:
    """One panel: every series of the figure along its axis."""
    name, scale = QUANTITY[quantity]
    per_size = ds[quantity + suffix]
    series_dim, axis = per_size.dims[0], per_size.dims[1]
    x = ds[axis].values
    h_values = ds["h"].values
    steady = ds.get(f"steady{suffix}")  # per run; absent for result files from before the check
    error = ds.get(f"{quantity}_standard_error{suffix}")  # per run (mu, mu_pl, mu_sh, dp); absent in old files
    unsteady_label = "run not steady (mu_drift or prow growth in its window)"
    failed_label = FAILED_FINEST_LABEL
    for i, label in enumerate(ds[series_dim].values):
        colour = SERIES_COLOURS[i % len(SERIES_COLOURS)]
        sel = {series_dim: label}
        for k, h in enumerate(h_values):
            y = per_size.sel(sel).isel(h=k).values * scale
            ax.plot(x, y, ls="none", marker=SIZE_MARKERS[k % 5], ms=3.5,
                    color=colour, alpha=0.3, label=f"h = {h:g} µm" if i == 0 else None)
            if error is not None:  # the run's own sampling error; none drawn where it was not estimable
                yerr = np.nan_to_num(error.sel(sel).isel(h=k).values * scale, nan=0.0)
                ax.errorbar(x, y, yerr=yerr, ls="none", color=colour, alpha=0.3, elinewidth=0.8)
            if steady is not None:
                bad = steady.sel(sel).isel(h=k).values == 0
                if bad.any():
                    ax.plot(x[bad], y[bad], ls="none", marker="x", ms=5, color="k", label=unsteady_label)
                    unsteady_label = None
        val = ds[f"{quantity}_h0{suffix}"].sel(sel).values * scale
        unc = ds[f"{quantity}_h0_uncertainty{suffix}"].sel(sel).values * scale
        sampling = ds.get(f"{quantity}_h0_sampling_error{suffix}")
        if sampling is not None:  # the runs' own noise carried to the limit, in quadrature with the GCI
            unc = np.hypot(unc, np.nan_to_num(sampling.sel(sel).values * scale, nan=0.0))
        flagged = ds[f"{quantity}_h0_flagged{suffix}"].sel(sel).values.astype(bool)
        ax.errorbar(x[~flagged], val[~flagged], yerr=unc[~flagged], fmt="o", color=colour, capsize=3,
                    label=f"MPM h -> 0, {_label(label)}")
        if flagged.any():
            ax.errorbar(x[flagged], val[flagged], yerr=unc[flagged], fmt="o", mfc="white", color=colour, capsize=3,
                        label="MPM h -> 0, flagged (not converged: least squares / two sizes)")
        failed = ds.get(f"failed_finest{suffix}")  # absent in datasets from before mpm.finest_failure
        if failed is not None:
            stopped = failed.sel(sel).values.astype(bool)
            if stopped.any():
                ring(ax, x[stopped], val[stopped], failed_label)
                failed_label = None
        ana = f"{quantity}_analytical{suffix}"
        if ana in ds:
            ax.plot(x, ds[ana].sel(sel) * scale, color=colour, lw=1.3, label=f"analytical, {_label(label)}")
    dp = ds.get(f"dp_h0{suffix}")
    if dp is not None:
        if thickness_axis:
            worn = (dp.isel({series_dim: 0}).values * 1e6) > x
        elif thickness_um is not None:
            worn = (dp.isel({series_dim: 0}).values * 1e6) > thickness_um
        else:
            worn = None
        if worn is not None and worn.any():
            shade_where(ax, x, worn, label=f"coating wear (CW): MPM dp > t ({_label(ds[series_dim].values[0])})")
    if thickness_axis and quantity == "dp":
        ax.plot(x, x, color="0.5", ls=":", lw=1, label="dp = t")
        # the dp = t line would stretch the axis to the bulk coating's 200 um: the axis follows the marks and
        # the analytical lines (every per-size and extrapolated value in view, a negative extrapolation too;
        # bars may leave it)
        values = [per_size.values, ds[f"{quantity}_h0{suffix}"].values]
        if f"{quantity}_analytical{suffix}" in ds:
            values.append(ds[f"{quantity}_analytical{suffix}"].values)
        marks = np.concatenate([v.ravel() for v in values]) * scale
        marks = marks[np.isfinite(marks)]
        if marks.size:
            ax.set_ylim(min(0.0, 1.15 * float(marks.min())), 1.15 * max(float(marks.max()), 1e-9))
    if logx:
        ax.set_xscale("log")
    if thickness_axis:  # linear over the thin coatings where dp crosses t, logarithmic out to the bulk coating
        _thickness_axis(ax, x)
    ax.set_xlabel(ds[axis].attrs.get("long_name", axis) + (f" ({ds[axis].attrs['units']})"
                                                           if ds[axis].attrs.get("units", "1") != "1" else ""))
    ax.set_ylabel(name)
    _legend_below(ax)


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


#: points between the axes' bottom and the legend's top: below the tick labels and the axis label
LEGEND_DROP_PT = 34.0


def _legend_below(ax) -> None:
    """The sweep panels' legend under the axes and their label (inside the axes it covered marks); the gap
    is in points, so that it clears the label whatever the panel's height."""
    below = offset_copy(ax.transAxes, fig=ax.figure, y=-LEGEND_DROP_PT, units="points")
    ax.legend(fontsize=6.5, loc="upper center", bbox_to_anchor=(0.5, 0.0), bbox_transform=below, ncol=1,
              frameon=False)


def _scene_note(ds: xr.Dataset) -> str:
    return f"Particle sizes h = {', '.join(f'{h:g}' for h in ds['h'].values)} µm; marks: extrapolated to h -> 0 " \
           "(Richardson; bars: Roache GCI and the runs' sampling errors carried to the limit, in quadrature, " \
           "the GCI alone where a run's error is missing; " \
           "hollow = fallback, flagged; ringed = the finest run stopped unstable, from the two coarser sizes), " \
           "faint: per size with the run's sampling standard error; " \
           "lines: analytical model."


def _fig11_13(ds: xr.Dataset, outputs, quantity: str, figure: str) -> None:
    fig, axes = new_figure(1, 2, height_per_row=5.6)
    t_a = float(ds.attrs.get("ratio_sweep_thickness_um", np.nan))
    _sweep_panel(axes[0, 0], ds, quantity, "_a", logx=True, thickness_um=t_a if np.isfinite(t_a) else None)
    axes[0, 0].set_title("(a) vs hardness ratio H~", fontsize=10)
    _sweep_panel(axes[0, 1], ds, quantity, "_b", thickness_axis=True)
    axes[0, 1].set_title("(b) vs coating thickness t", fontsize=10)
    caption(fig, f"{ds.attrs['title']}. {_scene_note(ds)} {FINDINGS[figure]}")
    save(fig, outputs)


def plot_fig11(ds: xr.Dataset, outputs) -> None:
    _fig11_13(ds, outputs, "dp", "fig11")


def plot_fig13(ds: xr.Dataset, outputs) -> None:
    _fig11_13(ds, outputs, "mu", "fig13")


def _vs_load(quantity: str, figure: str):
    def plot(ds: xr.Dataset, outputs) -> None:
        fig, axes = new_figure(1, 1, width=6.5, height_per_row=5.8)
        _sweep_panel(axes[0, 0], ds, quantity, "")
        caption(fig, f"{ds.attrs['title']}. {_scene_note(ds)} {FINDINGS[figure]}")
        save(fig, outputs)

    return plot


def plot_fig18(ds: xr.Dataset, outputs) -> None:
    fig, axes = new_figure(1, 1, width=6.5, height_per_row=5.8)
    ax = axes[0, 0]
    _sweep_panel(ax, ds, "dp", "_t")
    bulk = float(ds["dp_h0_bulk"].values.ravel()[0]) * 1e6
    unc = float(ds["dp_h0_uncertainty_bulk"].values.ravel()[0]) * 1e6
    ax.axhspan(bulk - unc, bulk + unc, color="0.85", zorder=0)
    ax.axhline(bulk, color="k", ls="--", label="MPM h -> 0, bulk zinc")
    _legend_below(ax)
    caption(fig, f"{ds.attrs['title']}. {_scene_note(ds)} {FINDINGS['fig18']}")
    save(fig, outputs)


# ----------------------------------------------------------------------------- single-run figures
def _forces(ax, ds: xr.Dataset, case: str, names=("Fx", "Fz", "Fx_pl", "Fx_sh")) -> None:
    sub = ds.sel(case=case)
    s = sub["sliding_distance"].values * 1e6
    ok = np.isfinite(s)
    styles = {"Fx": ("k", "-"), "Fz": ("tab:blue", "-"), "Fx_pl": ("tab:green", "--"), "Fx_sh": ("tab:orange", "--")}
    for n in names:
        c, ls = styles[n]
        ax.plot(s[ok], sub[n].values[ok], color=c, ls=ls, lw=1, label=n)
    window = sub["in_steady_window"].values[ok].astype(bool)
    shade_where(ax, s[ok], window, label="steady window (means)")
    ax.axhline(float(sub["Fz_mean"]), color="tab:blue", lw=0.6, ls=":")
    ax.set_xlabel("sliding distance (µm)")
    ax.set_ylabel("force on the sphere (N)")
    ax.legend(fontsize=7)


def _material_scatter(ax, u, v, coating, size: float) -> None:
    colours = np.where(np.asarray(coating) > 0.5, "tab:red", "0.55")
    ax.scatter(u, v, s=size, c=colours, marker="s", linewidths=0)
    ax.set_aspect("equal")


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
    ax.add_patch(Circle((centre[0] * 1e6, centre[2] * 1e6), r, fill=False, color="k"))
    xm = sub["midplane_x"].values[ok] * 1e6
    ax.set_xlim(xm.min(), xm.max())
    ax.set_ylim(sub["midplane_z"].values[ok].min() * 1e6, 0.25 * (xm.max() - xm.min()))
    ax.set_xlabel("x (µm), sliding to +x")
    ax.set_ylabel("z (µm)")
    ax.set_title("(a) mid-plane y = 0 at the end of the slide: coating (red), substrate (grey)", fontsize=9)
    _forces(axes[0, 1], ds, "coated")
    axes[0, 1].set_title("(b) forces on the sphere vs sliding distance", fontsize=10)
    caption(fig, f"{ds.attrs['title']} (h = {ds.attrs['particle_size_um']:g} µm, finest run). Paper: the soft "
            "coating piles up ahead of the sphere and stacks (coating wear) for H~ < 0.5.")
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
    ax.plot(hx, hmap[:, 0], color="k", label="groove bottom (y = 0)")
    ax.plot(hx, np.nanmax(hmap, axis=1), color="tab:red", label="highest pile-up across y")
    ax.set_xlabel("x (µm)")
    ax.set_ylabel("height (µm)")
    ax.set_title("(b) along the scratch", fontsize=10)
    ax.legend(fontsize=7)
    ax = axes[1, 0]
    y = ds["y"].values * 1e6
    z = sub["profile_z"].values * 1e6
    ax.plot(np.concatenate([-y[::-1], y]), np.concatenate([z[::-1], z]), color="k")
    dg, hpu, dp = (float(sub[v]) * 1e6 for v in ("dg", "hpu", "dp"))
    ax.axhline(0, color="0.6", lw=0.7)
    ax.axhline(-dg, color="tab:blue", ls="--", label=f"dg = {dg:.3g} µm")
    ax.axhline(hpu, color="tab:red", ls="--", label=f"hpu = {hpu:.3g} µm")
    ax.set_title(f"(c) residual cross-section: dp = dg + hpu = {dp:.3g} µm", fontsize=10)
    ax.set_xlabel("y (µm)")
    ax.set_ylabel("z (µm)")
    ax.legend(fontsize=7)
    ax = axes[1, 1]
    ok = np.isfinite(sub["section_y"].values)
    yy, zz = sub["section_y"].values[ok] * 1e6, sub["section_z"].values[ok] * 1e6
    cc = sub["section_coating"].values[ok]
    _material_scatter(ax, np.concatenate([-yy, yy]), np.concatenate([zz, zz]), np.concatenate([cc, cc]), 3)
    ax.set_xlabel("y (µm)")
    ax.set_ylabel("z (µm)")
    ax.set_title("(d) particles of the cross-section: coating (red), steel (grey)", fontsize=10)
    caption(fig, f"{ds.attrs['title']} (h = {ds.attrs['particle_size_um']:g} µm, finest run; the simulated half "
            "is mirrored at y = 0). Paper: the coating is pushed aside into pile-ups and thinned under the track.")
    save(fig, outputs)


def plot_fig17(ds: xr.Dataset, outputs) -> None:
    fig, axes = new_figure(1, 2, height_per_row=4.0)
    y = ds["y"].values * 1e6
    for ax, var, title in ((axes[0, 0], "profile_z", "(a) surface"),
                           (axes[0, 1], "buried_profile_z", "(b) material line that started at 15 µm depth")):
        for i, case in enumerate(ds["case"].values):
            z = ds[var].sel(case=case).values * 1e6
            ax.plot(np.concatenate([-y[::-1], y]), np.concatenate([z[::-1], z]), color=SERIES_COLOURS[i],
                    label=_label(case))
        ax.set_xlabel("y (µm)")
        ax.set_ylabel("z (µm)")
        ax.set_title(title, fontsize=10)
        ax.legend(fontsize=8)
    caption(fig, f"{ds.attrs['title']} (h = {ds.attrs['particle_size_um']:g} µm, finest runs). For the coated "
            "steel the line at 15 µm depth is the coating-steel interface. Paper: the coating deforms with a "
            "shallower groove than the zinc block, and the steel below is hardly deformed.")
    save(fig, outputs)


def plot_fig19(ds: xr.Dataset, outputs) -> None:
    fig, axes = new_figure(1, 1, width=7.0, height_per_row=4.2)
    _forces(axes[0, 0], ds, "coated")
    sub = ds.sel(case="coated")
    caption(fig, f"{ds.attrs['title']} (h = {ds.attrs['particle_size_um']:g} µm, finest run): mu = "
            f"{float(sub['mu']):.3g} (analytical {float(sub['mu_analytical']):.3g}). Paper: the forces settle "
            "within the first half of the slide; the paper averages over 0.3-0.6 mm.")
    save(fig, outputs)


PLOTTERS = {
    "fig11": plot_fig11, "fig12": plot_fig12, "fig13": plot_fig13, "fig14": plot_fig14,
    "fig15": _vs_load("dp", "fig15"), "fig16": _vs_load("dp", "fig16"), "fig17": plot_fig17,
    "fig18": plot_fig18, "fig19": plot_fig19, "fig20": _vs_load("mu", "fig20"),
    "fig21": _vs_load("mu", "fig21"), "fig23": _vs_load("mu", "fig23"),
}
__all__ = ["PLOTTERS"]
