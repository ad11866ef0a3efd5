"""Analytical figures: Fig. 3 (friction), Fig. 4 (ploughing depth), Fig. 22 (power-law fits)."""

from __future__ import annotations

import os

import numpy as np
import xarray as xr

from plough.figures.style import COLOURS, FAILED_FINEST_LABEL, LABELS, caption, new_figure, ring, save, shade_where

FRICTION = ("mu", "mu_pl", "mu_sh")


def plot_fig03(ds: xr.Dataset, outputs: list[str | os.PathLike[str]]) -> None:
    fig, axes = new_figure(2, 2)
    t = ds["thickness_um"].values
    for ax, case, letter in ((axes[0, 0], "soft", "a"), (axes[0, 1], "hard", "b")):
        sub = ds.sel(coating=case)
        shade_where(ax, t, sub["regime"].values == 2, label="coating worn through (dp > t)")
        for name in FRICTION:
            ax.plot(t, sub[name], color=COLOURS[name], label=LABELS[name])
        ax.set_xlabel("coating thickness t (µm)")
        ax.set_ylabel("friction coefficient (-)")
        ax.set_title(f"({letter}) {case} coating, H~ = {float(sub['case_hardness_ratio']):g}, "
                     f"Hs = {float(sub['substrate_hardness_MPa']):g} MPa", fontsize=10)
        ax.set_ylim(bottom=0)
        ax.legend(fontsize=8)
    ratio = ds["hardness_ratio"].values
    for ax, t_panel, letter in zip(axes[1], ds["panel_thickness_um"].values, "cd", strict=False):
        sub = ds.sel(panel_thickness_um=t_panel, correction="none")
        shade_where(ax, ratio, sub["regime_vs_ratio"].values == 2, label="coating worn through (dp > t)")
        for name in FRICTION:
            ax.plot(ratio, sub[name + "_vs_ratio"], color=COLOURS[name], label=LABELS[name])
        ax.set_xscale("log")
        ax.set_xlabel("hardness ratio H~ = Hc/Hs (-)")
        ax.set_ylabel("friction coefficient (-)")
        ax.set_title(f"({letter}) t = {t_panel:g} µm, Hs = {ds.attrs['ratio_sweep_substrate_hardness_MPa']:g} MPa",
                     fontsize=10)
        ax.set_ylim(bottom=0)
        ax.legend(fontsize=8)
    caption(fig, ds.attrs["title"] + ". Shaded: the sphere ploughs through the coating (dp > t, eqs. 3.1-3.5); "
            "unshaded: contact in the coating only (eqs. 2.1-2.3). The friction changes slope where dp = t.")
    save(fig, outputs)


def plot_fig04(ds: xr.Dataset, outputs: list[str | os.PathLike[str]]) -> None:
    fig, axes = new_figure(1, 2, height_per_row=4.0)
    ax = axes[0, 0]
    t = ds["thickness_um"].values
    for case in ds["coating"].values:
        sub = ds.sel(coating=case)
        ax.plot(t, sub["dp"] * 1e6, color=COLOURS[str(case)],
                label=f"{case}, H~ = {float(sub['case_hardness_ratio']):g}")
    top = 1.3 * float(ds["dp"].max()) * 1e6
    ax.plot(t[t <= top], t[t <= top], color="0.5", ls=":", label="dp = t")
    ax.set_ylim(0, top)
    ax.set_xlabel("coating thickness t (µm)")
    ax.set_ylabel("ploughing depth dp (µm)")
    ax.set_title("(a) dp vs coating thickness", fontsize=10)
    ax.legend(fontsize=8)
    ax = axes[0, 1]
    ratio = ds["hardness_ratio"].values
    t_panel = ds["panel_thickness_um"].values[0]
    first = ds.sel(panel_thickness_um=t_panel)
    shade_where(ax, ratio, first["regime_vs_ratio"].sel(correction="none").values == 2,
                label="coating worn through (dp > t)")
    for corr in ds["correction"].values:
        ax.plot(ratio, first["dp_vs_ratio"].sel(correction=corr) * 1e6, color=COLOURS.get(str(corr), "k"),
                label=f"normal-load correction: {corr}")
    ax.axhline(t_panel, color="0.5", ls=":", label=f"dp = t = {t_panel:g} µm")
    ax.set_xscale("log")
    ax.set_xlabel("hardness ratio H~ = Hc/Hs (-)")
    ax.set_ylabel("ploughing depth dp (µm)")
    ax.set_title(f"(b) dp vs H~, t = {t_panel:g} µm, Hs = {ds.attrs['ratio_sweep_substrate_hardness_MPa']:g} MPa",
                 fontsize=10)
    ax.legend(fontsize=8)
    caption(fig, ds.attrs["title"] + ". Dotted: dp = t, the sphere reaches the substrate. (b) compares the "
            "model without and with the normal-load correction of eq. 5 (paper: applied once).")
    save(fig, outputs)


def plot_fig22(ds: xr.Dataset, outputs: list[str | os.PathLike[str]]) -> None:
    fig, axes = new_figure(1, 2, height_per_row=4.0)
    load = ds["load_N"].values
    for ax, d in zip(axes[0], ds["ball_diameter_mm"].values, strict=False):
        sub = ds.sel(ball_diameter_mm=d)
        for name in FRICTION:
            ax.plot(load, sub[name + "_fit"], color=COLOURS[name], label=LABELS[name] + " (power-law fit)")
        if "mu_mpm" in ds:
            mpm = ds["mu_mpm"].sel(ball_diameter_mm=d)
            unc = ds["mu_mpm_uncertainty"].sel(ball_diameter_mm=d)
            x = ds["mpm_load_N"].values
            flagged = (ds["mu_mpm_flagged"].sel(ball_diameter_mm=d).values.astype(bool) if "mu_mpm_flagged" in ds
                       else np.zeros(x.shape, dtype=bool))  # datasets from before the flags carry none
            ax.errorbar(x[~flagged], mpm.values[~flagged], yerr=unc.values[~flagged], fmt="o", color="k",
                        label="MPM (h -> 0)")
            if flagged.any():
                ax.errorbar(x[flagged], mpm.values[flagged], yerr=unc.values[flagged], fmt="o", mfc="white",
                            color="k", label="MPM (h -> 0), flagged (least squares / two sizes)")
            if "mu_mpm_failed_finest" in ds:
                stopped = ds["mu_mpm_failed_finest"].sel(ball_diameter_mm=d).values.astype(bool)
                if stopped.any():
                    ring(ax, x[stopped], mpm.values[stopped], FAILED_FINEST_LABEL)
        ax.set_yscale("log")
        ax.set_xlabel("normal load Fn (N)")
        ax.set_ylabel("friction coefficient (-)")
        ax.set_title(f"{d:g} mm ball", fontsize=10)
        ax.legend(fontsize=8)
        ax.text(0.02, 0.02, "fit constants as printed: inconsistent in SI (see model.md)",
                transform=ax.transAxes, fontsize=7.5, color="tab:red")
    caption(fig, ds.attrs["title"] + f". WARNING: {ds.attrs['warning']}. Paper's finding: the 1 mm ball's "
            "friction rises with load, the 3 mm ball's stays low and nearly constant.")
    save(fig, outputs)


PLOTTERS = {"fig03": plot_fig03, "fig04": plot_fig04, "fig22": plot_fig22}

