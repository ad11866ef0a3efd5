"""Analytical figures: Fig. 3 (friction), Fig. 4 (ploughing depth), Fig. 22 (power-law fits)."""

from __future__ import annotations

import os

import numpy as np
import xarray as xr
from matplotlib.lines import Line2D

from plough.figures.style import (
    COLOURS,
    FAILED_FINEST_LABEL,
    LABELS,
    axes_entries,
    header,
    lighter,
    new_figure,
    note_entry,
    ring,
    save,
    shade_where,
)

FRICTION = ("mu", "mu_pl", "mu_sh")
WORN_LABEL = "shaded: coating worn through (dp > t)"


def plot_fig03(ds: xr.Dataset, outputs: list[str | os.PathLike[str]]) -> None:
    fig, axes = new_figure(2, 2)
    t = ds["thickness_um"].values
    for ax, case, letter in ((axes[0, 0], "soft", "a"), (axes[0, 1], "hard", "b")):
        sub = ds.sel(coating=case)
        shade_where(ax, t, sub["regime"].values == 2, label=WORN_LABEL)
        for name in FRICTION:
            ax.plot(t, sub[name], color=COLOURS[name], label=LABELS[name])
        ax.set_xlabel("coating thickness t (µm)")
        ax.set_ylabel("friction coefficient (-)")
        ax.set_title(f"({letter}) {case} coating, H~ = {float(sub['case_hardness_ratio']):g}, "
                     f"Hs = {float(sub['substrate_hardness_MPa']):g} MPa", fontsize=10)
        ax.set_ylim(bottom=0)
    ratio = ds["hardness_ratio"].values
    for ax, t_panel, letter in zip(axes[1], ds["panel_thickness_um"].values, "cd", strict=False):
        sub = ds.sel(panel_thickness_um=t_panel, correction="none")
        shade_where(ax, ratio, sub["regime_vs_ratio"].values == 2, label=WORN_LABEL)
        for name in FRICTION:
            ax.plot(ratio, sub[name + "_vs_ratio"], color=COLOURS[name], label=LABELS[name])
        ax.set_xscale("log")
        ax.set_xlabel("hardness ratio H~ = Hc/Hs (-)")
        ax.set_ylabel("friction coefficient (-)")
        ax.set_title(f"({letter}) t = {t_panel:g} µm, Hs = {ds.attrs['ratio_sweep_substrate_hardness_MPa']:g} MPa",
                     fontsize=10)
        ax.set_ylim(bottom=0)
    header(fig, "fig03", axes_entries(axes))
    save(fig, outputs)


def plot_fig04(ds: xr.Dataset, outputs: list[str | os.PathLike[str]]) -> None:
    fig, axes = new_figure(1, 2, height_per_row=4.0)
    ax = axes[0, 0]
    t = ds["thickness_um"].values
    for case in ds["coating"].values:
        sub = ds.sel(coating=case)
        ax.plot(t, sub["dp"] * 1e6, color=COLOURS[str(case)],
                label=f"(a) {case} coating, H~ = {float(sub['case_hardness_ratio']):g}")
    top = 1.3 * float(ds["dp"].max()) * 1e6
    ax.plot(t[t <= top], t[t <= top], color="0.5", ls=":", label="dotted: dp = t")
    ax.set_ylim(0, top)
    ax.set_xlabel("coating thickness t (µm)")
    ax.set_ylabel("ploughing depth dp (µm)")
    ax.set_title("(a) dp vs coating thickness", fontsize=10)
    ax = axes[0, 1]
    ratio = ds["hardness_ratio"].values
    t_panel = ds["panel_thickness_um"].values[0]
    first = ds.sel(panel_thickness_um=t_panel)
    shade_where(ax, ratio, first["regime_vs_ratio"].sel(correction="none").values == 2, label=WORN_LABEL)
    for corr in ds["correction"].values:
        ax.plot(ratio, first["dp_vs_ratio"].sel(correction=corr) * 1e6, color=COLOURS.get(str(corr), "k"),
                label=f"(b) normal-load correction: {corr}")
    ax.axhline(t_panel, color="0.5", ls=":", label="dotted: dp = t")
    ax.set_xscale("log")
    ax.set_xlabel("hardness ratio H~ = Hc/Hs (-)")
    ax.set_ylabel("ploughing depth dp (µm)")
    ax.set_title(f"(b) dp vs H~, t = {t_panel:g} µm, Hs = {ds.attrs['ratio_sweep_substrate_hardness_MPa']:g} MPa",
                 fontsize=10)
    header(fig, "fig04", axes_entries(axes), ncol=3)
    save(fig, outputs)


def plot_fig22(ds: xr.Dataset, outputs: list[str | os.PathLike[str]]) -> None:
    fig, axes = new_figure(1, 2, height_per_row=4.0)
    load = ds["load_N"].values
    for ax, d in zip(axes[0], ds["ball_diameter_mm"].values, strict=False):
        sub = ds.sel(ball_diameter_mm=d)
        for name in FRICTION:
            ax.plot(load, sub[name + "_fit"], color=COLOURS[name], label=LABELS[name] + " (power-law fit)")
        if "mu_mpm" in ds:
            mpm = ds["mu_mpm"].sel(ball_diameter_mm=d).values
            unc = ds["mu_mpm_uncertainty"].sel(ball_diameter_mm=d).values
            x = ds["mpm_load_N"].values
            flagged = (ds["mu_mpm_flagged"].sel(ball_diameter_mm=d).values.astype(bool) if "mu_mpm_flagged" in ds
                       else np.zeros(x.shape, dtype=bool))  # datasets from before the flags carry none
            # the trend first: the marks joined by a line, their bars lighter and thinner behind them
            ax.errorbar(x, mpm, yerr=unc, fmt="none", ecolor=lighter("k"), elinewidth=1.0, capsize=2, zorder=2)
            ax.plot(x, mpm, color="0.3", lw=1.0, zorder=3)  # thinner than the fits' black mu line
            ax.plot(x[~flagged], mpm[~flagged], ls="none", marker="o", ms=6, color="k", zorder=4)
            if flagged.any():
                ax.plot(x[flagged], mpm[flagged], ls="none", marker="o", ms=6, mfc="white", color="k", zorder=4,
                        label="hollow: flagged (fallback fit)")
            if "mu_mpm_failed_finest" in ds:
                stopped = ds["mu_mpm_failed_finest"].sel(ball_diameter_mm=d).values.astype(bool)
                if stopped.any():
                    ring(ax, x[stopped], mpm[stopped], FAILED_FINEST_LABEL)
        ax.set_yscale("log")
        ax.set_xlabel("normal load Fn (N)")
        ax.set_ylabel("friction coefficient (-)")
        ax.set_title(f"{d:g} mm ball", fontsize=10)
    entries = axes_entries(axes)
    if "mu_mpm" in ds:
        entries.insert(3, (Line2D([], [], color="0.3", lw=1.0, marker="o", ms=6, mfc="k", mec="k"),
                           "line + marks: MPM friction, h -> 0"))
    warning = (note_entry("tab:red"), "fit constants as printed: inconsistent in SI (docs/model.md)")
    header(fig, "fig22", [*entries, warning], ncol=2)
    save(fig, outputs)


PLOTTERS = {"fig03": plot_fig03, "fig04": plot_fig04, "fig22": plot_fig22}
