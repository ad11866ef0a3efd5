"""Outputs of an MPM run: the results dataset, residual groove profiles, particle snapshots.

Steady-state results are named as in the analytical model (``mu``, ``mu_pl``, ``mu_sh``, ``dp``)
plus ``dg`` (groove depth below the original surface), ``hpu`` (pile-up height above it) and
``penetration`` (depth of the sphere's lowest point under load), so the two compare directly:
mu = mean Fx / mean Fz over the steady window, mu_pl and mu_sh the same with the normal-traction
and interface-shear parts of Fx; dp = dg + hpu from the residual cross-sections (Fig. 14c).
Whether the window is a steady state is checked, not assumed: ``mu_drift`` (mu of the window's
second half against its first) and ``material_top_rise`` (how far the highest particle rose
between the halves: a growing prow) give ``steady``. ``<name>_standard_error`` (mu, mu_pl, mu_sh,
dp) are the sampling errors of those means: a delete-one-batch jackknife over contiguous batches
of the window's records and of the residual sections (docs/model.md, 5 The noise of one run).

Snapshots are VTK XML PolyData (.vtp) files, which ParaView and OVITO open.
"""

from __future__ import annotations

import base64
import errno
import json
import os
import shutil
import warnings
from collections.abc import Callable
from pathlib import Path

import numpy as np
import xarray as xr

from plough.io import provenance_attrs, temporary_beside, write_netcdf_atomic
from plough.mpm.particles import Particles
from plough.mpm.scene import RESOLVED_CONTACT_PARTICLES, Scene

SERIES_META = {
    "Fx": ("N", "friction force on the sphere (resisting the sliding, positive)"),
    "Fy": ("N", "lateral force on the sphere (0 by symmetry with the mirror plane)"),
    "Fz": ("N", "normal force on the sphere (upward reaction, positive)"),
    "Fx_pl": ("N", "friction force from normal traction (ploughing part)"),
    "Fx_sh": ("N", "friction force from interface shear (shear part)"),
    "Fz_pl": ("N", "normal force from normal traction"),
    "Fz_sh": ("N", "normal force from interface shear"),
    "depth": ("m", "depth of the sphere's lowest point below the original surface"),
    "particle_penetration": ("m", "deepest penetration of a particle centre into the sphere"),
    "contact_area_xy": ("m2", "contact area projected on the sliding plane"),
    "material_top": ("m", "height of the highest particle centre above the original surface (pile-up, prow; "
                          "debris counts until it is retired past the grid's growth limits)"),
    "external_work": ("J", "work done by the sphere on the block (cumulative)"),
    "plastic_work": ("J", "plastic work (cumulative)"),
    "elastic_energy": ("J", "elastic strain energy"),
    "kinetic_energy": ("J", "kinetic energy (mass-scaled)"),
    "interface_dissipation": ("J", "energy dissipated by interface slip: friction impulse times the slip left "
                                     "(grid contact; particle contact: the tangential impulses' work less the "
                                     "nodes' kinetic-energy gain) (cumulative)"),
    "contact_impact_loss": ("J", "work of the normal contact pushes against the approach left, jn gap / dt "
                                   "(grid contact; particle contact: the normal impulses' work less the nodes' "
                                   "kinetic-energy gain) (cumulative)"),
    "frozen_kinetic_loss": ("J", "kinetic energy of the particles frozen as the active zone left them, or retired "
                                 "as debris past the grid's growth limits (cumulative; plough.mpm.strays)"),
    "heat": ("J", "adiabatic heat, Taylor-Quinney factor x plastic work (cumulative)"),
    "time": ("s", "simulated time"),
}
#: the terms the sphere's work (``external_work``) goes into, each cumulative in J: their sum over that work is the
#: run's energy balance (:func:`energy_balance`; docs/verification.md, the energy rows)
ENERGY_TERMS = ("plastic_work", "elastic_energy", "kinetic_energy", "interface_dissipation", "contact_impact_loss",
                "frozen_kinetic_loss")


def energy_balance(ds: xr.Dataset) -> float:
    """The sum of :data:`ENERGY_TERMS` over ``external_work`` at a run's end (1: every joule accounted for).

    Reads those variables' last values from a run's dataset; NaN if the sphere did no work.
    """
    work = float(ds["external_work"][-1])
    return sum(float(ds[k][-1]) for k in ENERGY_TERMS) / work if work > 0.0 else float("nan")


#: the grid contact's split of its interface shear (contact.OUT_SH_AREA on; interval means like the forces, full
#: body; 0 with the particle contact): a region is in front of the sphere's centre in x or behind it (rear), and
#: below the original surface or above it (_up: pile-up, prow)
_REGIONS = {"front": "in front of the centre, below the original surface", "rear": "behind the centre, below it",
            "front_up": "in front of the centre, above the original surface",
            "rear_up": "behind the centre, above the original surface"}
_KINDS = {"stuck": "whose slip the impulse stopped (not traction-limited)",
          "carried": "arriving with a slip under half the sliding speed (carried with the sphere)",
          "outside": "outside the sphere (within a cell of its surface)",
          "gap": "whose closest particle face lies more than a quarter cell from the sphere",
          "lateral": "on the sides (|n_y| > |n_x|)"}
CONTACT_SPLIT_META = {
    "contact_shear_area": ("m2", "contact area carrying interface shear: sum of the contact nodes' surface shares"),
    "contact_shear_capacity": ("N", "sum of tau A over the contact nodes (the interface shear they could carry)"),
    **{f"contact_area_{r}": ("m2", f"contact nodes' surface shares {text}") for r, text in _REGIONS.items()},
    **{f"contact_fx_sh_{r}": ("N", f"friction force from interface shear on the contact nodes {text}")
       for r, text in _REGIONS.items()},
    **{f"contact_area_xy_{r}": ("m2", f"contact area projected on the sliding plane {text}")
       for r, text in _REGIONS.items()},
    **{f"contact_fz_pl_{r}": ("N", f"normal force from normal traction on the contact nodes {text}")
       for r, text in _REGIONS.items()},
    **{name: meta for k, text in _KINDS.items()
       for name, meta in ((f"contact_area_{k}", ("m2", f"surface shares of the contact nodes {text}")),
                          (f"contact_fx_sh_{k}", ("N", f"friction force from interface shear on the nodes {text}")))},
}
SERIES_META.update(CONTACT_SPLIT_META)
#: steady-window summaries of the shear split (means over the window; written when the series are there)
CONTACT_SUMMARY_META = {
    "contact_shear_area_mean": ("m2", "mean contact area carrying interface shear over the steady window"),
    "contact_front_pressure": ("Pa", "mean Fz over the mean projected area of the contact's front half (the "
                                     "analytical model's hardness H; nan without the grid contact's series)"),
    "mu_sh_rear": ("1", "part of mu_sh from the contact behind the sphere's centre"),
    "mu_sh_carried": ("1", "part of mu_sh from nodes carried with the sphere (arriving slip under half the speed)"),
}


def contact_summary(series: dict[str, np.ndarray], mask: np.ndarray, fz: float) -> dict[str, float]:
    """The steady-window summaries of the grid contact's shear split (CONTACT_SUMMARY_META); none (an empty dict)
    when the window holds no front contact area, so that no summary is written as NaN."""
    mean = {k: float(series[k][mask].mean()) for k in CONTACT_SPLIT_META}
    front = mean["contact_area_xy_front"] + mean["contact_area_xy_front_up"]
    if not front > 0.0:
        return {}
    return {"contact_shear_area_mean": mean["contact_shear_area"],
            "contact_front_pressure": fz / front,
            "mu_sh_rear": (mean["contact_fx_sh_rear"] + mean["contact_fx_sh_rear_up"]) / fz,
            "mu_sh_carried": mean["contact_fx_sh_carried"] / fz}
STEADY_META = {
    "mu": ("1", "friction coefficient, mean Fx / mean Fz over the steady window"),
    "mu_pl": ("1", "ploughing part of the friction coefficient"),
    "mu_sh": ("1", "interface-shear part of the friction coefficient"),
    "Fz_mean": ("N", "mean normal force over the steady window"),
    "Fx_mean": ("N", "mean friction force over the steady window"),
    "penetration": ("m", "mean depth of the sphere's lowest point under load over the steady window"),
    "dg": ("m", "residual groove depth below the original surface"),
    "hpu": ("m", "residual pile-up height above the original surface"),
    "dp": ("m", "ploughing depth dp = dg + hpu"),
    "max_particle_penetration": ("m", "deepest penetration of a particle centre into the sphere (whole run)"),
}

#: contiguous batches the steady window's records and the residual sections are cut into for the jackknife
SE_BATCHES = 10
#: one run's groove (dg, hpu, dp) moves with where the sphere starts against the particle lattice beyond what the
#: jackknife over the residual sections sees, by an amount that depends on the contact: this fraction of the
#: particle size is added to their standard errors in quadrature. The grid contact closes nodes by its particles'
#: whole stencils, a discrete choice a shifted start changes: a tenth of a particle size covers its phase spread
#: (rms z 0.44 over 60 runs, two cases need the term). With the gap on each node's own ray (grid_local) the groove
#: hardly remembers the start (dp moves 0.02-1.4% at h = 10-20 um, 0.0013 h at most): the jackknife alone covers dp
#: and dg but not the pile-up height at h = 20 um (rms z 1.68 / 1.19 on two of six cases), and 0.002 h covers
#: every case measured (rms z at most 0.53, 24 runs). The particle contact was never measured: the grid's, on the
#: safe side (docs/verification.md, "Noise and reproducibility"; docs/journal/2026-12-02-groove-uncertainty.md,
#: docs/journal/2026-12-04-preview-grid-local.md)
GROOVE_LATTICE_PHASE_ERROR_H = {"grid": 0.1, "grid_local": 0.002, "particle": 0.1}
GROOVE_OUTPUTS = ("dp", "dg", "hpu")
STANDARD_ERROR_META = {
    f"{name}_standard_error": ("1", f"sampling standard error of {name} (jackknife over up to {SE_BATCHES} "
                                    "contiguous batches of the steady window's records)")
    for name in ("mu", "mu_pl", "mu_sh")
} | {
    f"{name}_standard_error": ("m", f"standard error of {name}: the jackknife over up to {SE_BATCHES} contiguous "
                                    "batches of the residual sections and the contact's lattice-phase term "
                                    "(attribute lattice_phase_term_m) in quadrature")
    for name in GROOVE_OUTPUTS
}

#: a window is steady when mu moves by at most this fraction between its halves ...
STEADY_MU_DRIFT = 0.05
#: ... and the highest particle rises (or falls) by at most this many particle sizes (a prow that comes and goes
#: moves its top by about a particle; the growing prows at h = 2.5 um rose by tens of um over 0.3 mm)
STEADY_TOP_RISE_PARTICLES = 2.0
STEADINESS_META = {
    "mu_drift": ("1", "mu over the second half of the steady window minus mu over its first half, relative to mu"),
    "material_top_rise": ("m", "mean highest particle over the second half of the steady window minus over its first"),
    "steady": ("1", f"1 if the window is a steady state: |mu_drift| <= {STEADY_MU_DRIFT:g} and |material_top_rise| <= "
               f"{STEADY_TOP_RISE_PARTICLES:g} particle sizes, else 0"),
}


def steadiness(series: dict[str, np.ndarray], mask: np.ndarray, particle_size_m: float) -> dict[str, float | int]:
    """Does the steady window hold a steady state? Compares its two halves (by record count).

    mu_drift = (mu_2 - mu_1) / mu with mu_k = mean Fx / mean Fz over half k (when a half's mean Fz is
    not positive, a bounce, the halves' Fx over the window's Fz instead, and the window is not
    steady); material_top_rise is the mean of ``material_top`` over the second half minus over the
    first. A falling top counts as a change too (a prow shedding material). A window of fewer than
    2 records cannot be split: drift and rise 0, not steady.
    """
    idx = np.flatnonzero(mask)
    half = idx.size // 2
    if half == 0:
        return {"mu_drift": 0.0, "material_top_rise": 0.0, "steady": 0}
    first, second = idx[:half], idx[half:]
    fx, fz, top = series["Fx"], series["Fz"], series["material_top"]
    fz_window = fz[idx].mean()
    mu = fx[idx].mean() / fz_window
    fz_1, fz_2 = fz[first].mean(), fz[second].mean()
    bounced = not (fz_1 > 0 and fz_2 > 0)
    if bounced:
        fz_1 = fz_2 = fz_window
    drift = (fx[second].mean() / fz_2 - fx[first].mean() / fz_1) / abs(mu) if mu != 0 else 0.0
    rise = top[second].mean() - top[first].mean()
    steady = not bounced and abs(drift) <= STEADY_MU_DRIFT and abs(rise) <= STEADY_TOP_RISE_PARTICLES * particle_size_m
    return {"mu_drift": float(drift), "material_top_rise": float(rise), "steady": int(steady)}


def steady_window_mask(slid_m: np.ndarray, scene: Scene, distance_m: float | None = None) -> np.ndarray:
    """Records in the steady window: the window's fractions of the distance slid (default: the scene's)."""
    lo, hi = scene.outputs.steady_window
    d = scene.sliding.distance_m if distance_m is None else distance_m
    # the run stops on the first step past the distance, so the last record may overshoot it by v dt
    tol = d / scene.outputs.records
    return (slid_m >= lo * d - 1e-12) & (slid_m <= hi * d + tol)


def _y_edges(scene: Scene) -> np.ndarray:
    """Bin edges across the groove, one particle size wide, over the block's width."""
    h = scene.discretisation.particle_size_m
    y_max = scene.domain.radius_m
    return np.arange(0.0 if scene.domain.symmetric else -y_max, y_max + 0.5 * h, h)


def within_block_width(y: np.ndarray, scene: Scene) -> np.ndarray:
    """Samples within the block's width, |y| <= R + h / 2: material thrown out past the side face (the grid
    widens for it, ``plough.mpm.growth``) is not the groove's surface, whereas a column near the face still is
    (it goes to the last y bin, as before)."""
    return np.abs(y) <= scene.domain.radius_m + 0.5 * scene.discretisation.particle_size_m


def surface_samples(p: Particles, h: float) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """(x, y, top, index) with one sample per h x h column of every particle's top face.

    A lattice particle (edge h) gives one sample; a graded far-field particle (edge 2 h) gives four,
    at its quarter points in x and y, so bands and bins one h wide see every particle as they would
    on the uniform lattice. ``top`` is the top face z + e J^(1/3) / 2 (edge e = vol0^(1/3)) and
    ``index`` the particle each sample belongs to.
    """
    edge = np.cbrt(p.vol0)
    top = p.x[:, 2] + 0.5 * edge * np.cbrt(p.J)
    coarse = edge > 1.5 * h
    if not coarse.any():
        return p.x[:, 0], p.x[:, 1], top, np.arange(p.n)
    ci = np.flatnonzero(coarse)
    offsets = np.array([[-1, -1], [-1, 1], [1, -1], [1, 1]]) * 0.5 * h
    sx = (p.x[ci, 0][:, None] + offsets[:, 0] * np.cbrt(p.J[ci])[:, None]).ravel()
    sy = (p.x[ci, 1][:, None] + offsets[:, 1] * np.cbrt(p.J[ci])[:, None]).ravel()
    fi = np.flatnonzero(~coarse)
    index = np.concatenate([fi, np.repeat(ci, 4)])
    return (np.concatenate([p.x[fi, 0], sx]), np.concatenate([p.x[fi, 1], sy]), top[index], index)


#: the widest gap between two neighbouring particles of the surface layer that the residual profile bridges,
#: centre to centre in particle sizes h: below 2 h the gap between their faces is narrower than one particle
#: (a layer stretched sideways by less than 2x, each particle wider than h), so the material is continuous
#: there and the particle seen through the gap belongs to the layer below
SKIN_BRIDGE_SPAN_H = 2.0
#: where a section's own band (h wide) leaves a gap too wide to bridge, the layer's particles within this many
#: h of the section along x draw the line instead: the sliding shears and shifts the layer along x too, so a
#: one-h band can miss a column's particle that its neighbouring band holds
SKIN_BRIDGE_REACH_H = 1.5


def started_at_surface(p: Particles) -> np.ndarray:
    """Particles whose top face started at the block's top surface z = 0 (the surface layer, every particle
    size): the material the free surface is made of, since particles carry their material."""
    edge = np.cbrt(p.vol0)
    return np.abs(p.z0 + 0.5 * edge) < 0.25 * edge


def layer_line(centres: np.ndarray, y: np.ndarray, top: np.ndarray, h: float) -> tuple[np.ndarray, np.ndarray]:
    """(height, ok) at each of ``centres``: the straight line between the two samples (y, top) around it,
    ok where they lie less than ``SKIN_BRIDGE_SPAN_H`` h apart (and a sample lies on either side)."""
    if y.size < 2:
        return np.full(centres.size, -np.inf), np.zeros(centres.size, dtype=bool)
    order = np.argsort(y, kind="stable")
    ys, tops = y[order], top[order]
    k = np.searchsorted(ys, centres)  # centres[i] lies between ys[k - 1] and ys[k]
    ok = (k > 0) & (k < ys.size)
    k = np.clip(k, 1, ys.size - 1)
    span = ys[k] - ys[k - 1]
    ok &= span < SKIN_BRIDGE_SPAN_H * h
    w = np.divide(centres - ys[k - 1], span, out=np.zeros(centres.size), where=span > 0)
    return tops[k - 1] + w * (tops[k] - tops[k - 1]), ok


def bridge_skin_gaps(z: np.ndarray, centres: np.ndarray, held: np.ndarray,
                     layers: list[tuple[np.ndarray, np.ndarray]], h: float) -> None:
    """Raise, in place, the bins of one section's profile ``z`` that hold no surface-layer particle
    (``held`` False) to the surface layer's straight line between its two particles around the bin's centre,
    where those lie less than ``SKIN_BRIDGE_SPAN_H`` h apart in y, and only if the line is higher than the
    bin's own highest particle.

    Why: a groove's surface is longer than the flat surface it came from, so its top particle layer is
    stretched sideways (on Fig. 14's scene at h = 10 um by a fifth); about every fifth bin then holds no
    particle of that layer, and the highest particle there is one of the layer below, a particle size
    deeper (journal 2026-12-03-groove-below-sphere). ``layers``: the (y, top face) sets of the layer's
    samples that may draw the line, tried in turn (the section's own band, then within
    ``SKIN_BRIDGE_REACH_H`` h of it); a bin takes the first set that spans it narrowly enough. A held bin
    is never changed, so a valley wider than a particle keeps its own highest particle at the bottom.
    """
    todo = ~held
    for y, top in layers:
        if not todo.any():
            return
        line, ok = layer_line(centres, y, top, h)
        use = todo & ok
        z[use] = np.maximum(z[use], line[use])
        todo &= ~ok


def residual_profiles(p: Particles, scene: Scene, sphere_x_end: float, contact_radius: float,
                      distance_m: float | None = None) -> tuple:
    """Surface height z(y) at sections behind the sphere, averaged; (y, z_top, sections x)."""
    y, prof, sections = section_profiles(p, scene, sphere_x_end, contact_radius, distance_m)
    return y, _nanmean_rows(prof), sections


def _nanmean_rows(prof: np.ndarray) -> np.ndarray:
    """Mean over the sections (axis 0) ignoring empty bins; NaN where no section has the bin."""
    count = np.isfinite(prof).sum(axis=0)
    total = np.where(np.isfinite(prof), prof, 0.0).sum(axis=0)
    return np.divide(total, count, out=np.full(prof.shape[1], np.nan), where=count > 0)


def section_profiles(p: Particles, scene: Scene, sphere_x_end: float, contact_radius: float,
                     distance_m: float | None = None) -> tuple:
    """Surface height z(y) at each section behind the sphere; (y, z_top per section, sections x).

    z_top has one row per section: in each bin the highest particle top face of the section's band, or the
    surface layer's line across a gap narrower than a particle (:func:`bridge_skin_gaps`); NaN where
    neither reaches."""
    h = scene.discretisation.particle_size_m
    x0 = scene.start_x_m
    d = scene.sliding.distance_m if distance_m is None else distance_m
    lo, _ = scene.outputs.steady_window
    # sections where the sphere has passed and the material has unloaded: 1.25 contact radii behind
    # the sphere's final centre (a quarter radius behind the trailing edge), inside the steady window,
    # or past the initial dent if the window is too short (the positions are stored as section_x)
    x_hi = sphere_x_end - 1.25 * contact_radius
    x_lo = x0 + lo * d
    if x_hi <= x_lo:
        x_lo = x0 + 1.25 * contact_radius
    if x_hi <= x_lo:
        raise ValueError("the slide is too short to measure a residual groove behind the sphere "
                         "(sliding.distance_m must exceed ~2.7 contact radii)")
    # every particle row (bands of width h, adjacent) unless a number of sections is asked for: five
    # one-row sections left dp at h = 10 um to the particle lattice (it moved +55% with the block
    # length, +131% with CFL 0.6, mu within 3%); every row moved it -0.3% and +2.8%
    n_sections = scene.outputs.profile_sections or int(np.floor((x_hi - x_lo) / h)) + 1
    sections = np.linspace(x_lo, x_hi, n_sections) if n_sections > 1 else np.array([0.5 * (x_lo + x_hi)])
    edges = _y_edges(scene)
    centres = 0.5 * (edges[1:] + edges[:-1])
    sx, sy, top, index = surface_samples(p, h)
    inside = within_block_width(sy, scene)
    skin = started_at_surface(p)[index]
    profiles = []
    for xs in sections:
        dx = np.abs(sx - xs)
        band = (dx < 0.5 * h) & inside
        idx = np.clip(np.digitize(sy[band], edges) - 1, 0, centres.size - 1)
        z = np.full(centres.size, -np.inf)
        np.maximum.at(z, idx, top[band])
        held = np.zeros(centres.size, dtype=bool)
        held[idx[skin[band]]] = True
        layers = [(sy[m], top[m]) for m in (band & skin, (dx < SKIN_BRIDGE_REACH_H * h) & inside & skin)]
        if scene.domain.symmetric:  # the layer goes on across the mirror plane as its own image
            layers = [(np.concatenate([-y, y]), np.concatenate([t, t])) for y, t in layers]
        bridge_skin_gaps(z, centres, held, layers, h)
        profiles.append(z)
    prof = np.array(profiles)
    prof[~np.isfinite(prof)] = np.nan
    return centres, prof, sections


def groove_depths(y: np.ndarray, z_top: np.ndarray, contact_radius: float) -> tuple[float, float]:
    """(dg, hpu) of a residual profile: the deepest point within 1.5 contact radii of the track's
    centre line below the original surface, and the highest point above it (each at least 0)."""
    near_track = np.abs(y) <= 1.5 * contact_radius
    return float(max(-np.nanmin(z_top[near_track]), 0.0)), float(max(np.nanmax(z_top), 0.0))


def jackknife_standard_error(statistic: Callable[[np.ndarray], float], n: int,
                             batches: int = SE_BATCHES) -> float | None:
    """Delete-one-batch jackknife standard error of ``statistic(kept indices)`` over ``n`` ordered samples.

    The samples (records of the steady window, or residual sections) are cut into ``min(batches, n)``
    contiguous batches; each batch is left out in turn. Contiguous batches, not single samples,
    because neighbouring records are correlated (the force saw-tooths with the prow); the
    jackknife, not the spread of batch values, because mu is a ratio of means and dp the extreme
    of a mean profile: nonlinear statistics of the samples. With fewer samples than batches each
    sample is a batch and the correlation argument no longer holds (a short window, a coarse run).
    None when fewer than 2 batches or when a leave-one-out value is not finite (a subset without
    normal force or without a profile).
    """
    k = min(batches, n)
    if k < 2:
        return None
    parts = np.array_split(np.arange(n), k)
    with np.errstate(all="ignore"), warnings.catch_warnings():
        warnings.simplefilter("ignore", RuntimeWarning)  # an all-empty bin in a subset: NaN, handled below
        theta = np.array([statistic(np.concatenate(parts[:b] + parts[b + 1:])) for b in range(k)], dtype=float)
    if not np.isfinite(theta).all():
        return None
    return float(np.sqrt((k - 1) / k * np.sum((theta - theta.mean()) ** 2)))


def groove_lattice_phase_term_m(scene: Scene) -> float:
    """The lattice-phase term of the scene's groove errors (m): ``GROOVE_LATTICE_PHASE_ERROR_H`` of its contact
    times its particle size."""
    d = scene.discretisation
    return GROOVE_LATTICE_PHASE_ERROR_H[d.contact] * d.particle_size_m


def standard_errors(series: dict[str, np.ndarray], mask: np.ndarray, y: np.ndarray, prof: np.ndarray,
                    contact_radius: float, lattice_phase_term_m: float) -> dict[str, float]:
    """Standard errors of the steady-state results (``STANDARD_ERROR_META``).

    The steady window is a finite sample of a fluctuating force and the residual groove a finite
    number of sections: the jackknife estimates how far the same run with a different but equally
    long sample would move mu and the groove. The groove's errors (dp, dg, hpu) also carry the
    lattice-phase term ``lattice_phase_term_m`` (:func:`groove_lattice_phase_term_m`) in quadrature: with the
    grid contact where the sphere starts against the particle lattice moves the groove by up to about a tenth
    of a particle size beyond the jackknife's reach (a groove a fraction of a particle deep shows no scatter
    over its sections at all). mu's errors carry no such term: measured against phase-shifted runs they are
    order-of-magnitude bars (docs/verification.md, "Noise and reproducibility"). The groove's errors are
    omitted when fewer than 2 sections were measured.
    """
    idx = np.flatnonzero(mask)
    fx, fz = series["Fx"][idx], series["Fz"][idx]
    out = {}
    for name, part in (("mu", fx), ("mu_pl", series["Fx_pl"][idx]), ("mu_sh", series["Fx_sh"][idx])):
        se = jackknife_standard_error(lambda k, part=part: part[k].sum() / fz[k].sum(), idx.size)
        if se is not None:
            out[f"{name}_standard_error"] = se
    phase = lattice_phase_term_m
    groove = {"dp": sum, "dg": lambda d: d[0], "hpu": lambda d: d[1]}
    for name, pick in groove.items():
        se = jackknife_standard_error(
            lambda k, pick=pick: pick(groove_depths(y, _nanmean_rows(prof[k]), contact_radius)), prof.shape[0])
        if se is not None:
            out[f"{name}_standard_error"] = float(np.hypot(se, phase))
    return out


def picture_variables(p: Particles, scene: Scene, sphere_centre: np.ndarray, coating_row: int,
                      contact_radius: float, sections: np.ndarray) -> tuple[dict, dict]:
    """What the figures draw of the final state, small enough to keep in every result file.

    * ``height_map`` (hx, hy): top surface height on an h x h raster around the track (Fig. 14a/b);
    * ``buried_profile_z`` (y): the material line that started at ``outputs.buried_profile_depth_m``
      below the surface, in the residual sections (Fig. 17: the coating interface for t = 15 um);
    * ``midplane_*``: particles of the first row next to the mirror plane around the sphere, the side
      view of the coating piling up ahead of it (Fig. 12a);
    * ``section_*``: particles of the middle residual cross-section (Fig. 14d).
    """
    h = scene.discretisation.particle_size_m
    x, y, z = p.x[:, 0], p.x[:, 1], p.x[:, 2]
    coat = np.where(p.mat_a == coating_row, p.frac_a, 0.0).astype(np.float32)
    sx, sy, top, sample_of = surface_samples(p, h)
    xs_edges = np.arange(scene.start_x_m - 2.0 * contact_radius, sphere_centre[0] + 2.0 * contact_radius + h, h)
    ys_edges = np.arange(0.0 if scene.domain.symmetric else -3.0 * contact_radius, 3.0 * contact_radius + h, h)
    ix = np.digitize(sx, xs_edges) - 1
    iy = np.digitize(sy, ys_edges) - 1
    ok = (ix >= 0) & (ix < xs_edges.size - 1) & (iy >= 0) & (iy < ys_edges.size - 1)
    hmap = np.full((xs_edges.size - 1, ys_edges.size - 1), -np.inf)
    np.maximum.at(hmap, (ix[ok], iy[ok]), top[ok])
    hmap[~np.isfinite(hmap)] = np.nan

    depth = scene.outputs.buried_profile_depth_m
    y_edges = _y_edges(scene)  # the bins of residual_profiles: profile_z and buried_profile_z share y
    in_sections = np.zeros(sx.size, dtype=bool)
    for xs in sections:
        in_sections |= np.abs(sx - xs) < 0.5 * h
    half_edge = 0.5 * np.cbrt(p.vol0)
    line = in_sections & (np.abs(p.z0 + depth) <= half_edge + 1e-12)[sample_of] & within_block_width(sy, scene)
    iyl = np.clip(np.digitize(sy[line], y_edges) - 1, 0, y_edges.size - 2)
    total = np.bincount(iyl, weights=(z - p.z0)[sample_of[line]], minlength=y_edges.size - 1)
    count = np.bincount(iyl, minlength=y_edges.size - 1)
    buried = np.where(count > 0, -depth + total / np.maximum(count, 1), np.nan)

    mid = (np.abs(y) < h) & (np.abs(x - sphere_centre[0]) < 4.0 * contact_radius) & (z > -3.0 * contact_radius)
    xs_mid = sections[len(sections) // 2]
    sec = np.abs(x - xs_mid) < 0.5 * np.cbrt(p.vol0)  # one particle row thick: 2 h where graded
    f32 = np.float32
    variables = {
        "height_map": (("hx", "hy"), hmap.astype(f32), {"units": "m", "long_name": "residual top-surface height",
                                                        "allow_missing": 1}),
        "buried_profile_z": (("y",), buried, {"units": "m", "allow_missing": 1,
                                              "long_name": f"height of the material line that started {depth:g} m "
                                                           "below the surface, in the residual sections"}),
        "midplane_x": (("midplane_particle",), x[mid].astype(f32), {"units": "m", "long_name": "particle x"}),
        "midplane_z": (("midplane_particle",), z[mid].astype(f32), {"units": "m", "long_name": "particle z"}),
        "midplane_coating": (("midplane_particle",), coat[mid], {"units": "1", "long_name": "coating fraction"}),
        "midplane_eps_p": (("midplane_particle",), p.eps_p[mid].astype(f32),
                           {"units": "1", "long_name": "equivalent plastic strain"}),
        "section_y": (("section_particle",), y[sec].astype(f32), {"units": "m", "long_name": "particle y"}),
        "section_z": (("section_particle",), z[sec].astype(f32), {"units": "m", "long_name": "particle z"}),
        "section_coating": (("section_particle",), coat[sec], {"units": "1", "long_name": "coating fraction"}),
        "section_eps_p": (("section_particle",), p.eps_p[sec].astype(f32),
                          {"units": "1", "long_name": "equivalent plastic strain"}),
    }
    coords = {
        "hx": (("hx",), 0.5 * (xs_edges[1:] + xs_edges[:-1]), {"units": "m", "long_name": "x of the height map"}),
        "hy": (("hy",), 0.5 * (ys_edges[1:] + ys_edges[:-1]), {"units": "m", "long_name": "y of the height map"}),
    }
    attrs = {"sphere_centre_end_m": np.asarray(sphere_centre, dtype=float), "midplane_section_x_m": float(xs_mid)}
    return variables, {"coords": coords, "attrs": attrs}


def build_dataset(scene: Scene, series: dict[str, np.ndarray], slid_m: np.ndarray, p: Particles,
                  sphere_centre: np.ndarray, cost: dict[str, float], max_penetration: float,
                  coating_row: int = -1, slid_distance_m: float | None = None) -> xr.Dataset:
    """The results of one run as an xarray Dataset with units, long names and provenance.

    ``slid_distance_m`` is the distance actually slid when the run stopped early (stop_when_steady);
    the steady window and the residual sections then refer to it.
    """
    slid_total = scene.sliding.distance_m if slid_distance_m is None else slid_distance_m
    mask = steady_window_mask(slid_m, scene, slid_total)
    if mask.sum() < 3:
        raise ValueError("fewer than 3 records in the steady window; raise outputs.records")
    Fx, Fz = series["Fx"][mask].mean(), series["Fz"][mask].mean()
    if not Fz > 0.05 * scene.load_N:
        from plough.mpm.solver import SimulationError

        raise SimulationError(f"the sphere lost contact while sliding (mean Fz = {Fz:.3g} N for load_N = "
                              f"{scene.load_N:g} N): inertia dominates; lower sliding.speed_m_s or mass_scaling")
    a_exp, _ = scene.expected_contact()
    y, prof, sections = section_profiles(p, scene, float(sphere_centre[0]), a_exp, slid_total)
    z_top = _nanmean_rows(prof)
    dg, hpu = groove_depths(y, z_top, a_exp)
    steady = {
        "mu": Fx / Fz, "mu_pl": series["Fx_pl"][mask].mean() / Fz, "mu_sh": series["Fx_sh"][mask].mean() / Fz,
        "Fz_mean": Fz, "Fx_mean": Fx, "penetration": series["depth"][mask].mean(), "dg": dg, "hpu": hpu,
        "dp": dg + hpu, "max_particle_penetration": max_penetration,
    }
    ds = xr.Dataset(
        {name: (("record",), series[name], {"units": u, "long_name": ln}) for name, (u, ln) in SERIES_META.items()
         if name in series},
        coords={"sliding_distance": (("record",), slid_m, {"units": "m", "long_name": "sliding distance"}),
                "y": (("y",), y, {"units": "m", "long_name": "lateral position across the groove"}),
                "section_x": (("section",), sections, {"units": "m", "long_name": "x of the residual cross-sections"})},
    )
    ds["profile_z"] = (("y",), z_top, {"units": "m", "long_name": "residual surface height, mean of the sections",
                                       "allow_missing": 1,
                                       "surface_layer_gaps": f"bridged where the layer's particles lie under "
                                                             f"{SKIN_BRIDGE_SPAN_H:g} h apart in y, drawn from "
                                                             f"within {SKIN_BRIDGE_REACH_H:g} h along x "
                                                             "(docs/model.md, the residual groove)"})
    pic_vars, pic_extra = picture_variables(p, scene, sphere_centre, coating_row, a_exp, sections)
    ds = ds.assign_coords(pic_extra["coords"])
    for name, var in pic_vars.items():
        ds[name] = var
    ds.attrs.update(pic_extra["attrs"])
    ds["in_steady_window"] = (("record",), mask, {"units": "1", "long_name": "record lies in the steady window"})
    for name, value in steady.items():
        u, ln = STEADY_META[name]
        ds[name] = ((), float(value), {"units": u, "long_name": ln})
    if all(k in series for k in CONTACT_SPLIT_META):
        for name, value in contact_summary(series, mask, Fz).items():
            u, ln = CONTACT_SUMMARY_META[name]
            ds[name] = ((), float(value), {"units": u, "long_name": ln})
    h = scene.discretisation.particle_size_m
    phase_term = groove_lattice_phase_term_m(scene)
    for name, value in standard_errors(series, mask, y, prof, a_exp, phase_term).items():
        u, ln = STANDARD_ERROR_META[name]
        ds[name] = ((), float(value), {"units": u, "long_name": ln})
        if name.removesuffix("_standard_error") in GROOVE_OUTPUTS:
            ds[name].attrs["lattice_phase_term_m"] = phase_term
    for name, value in steadiness(series, mask, h).items():
        u, ln = STEADINESS_META[name]
        ds[name] = ((), np.int8(value) if name == "steady" else value, {"units": u, "long_name": ln})
    ds.attrs["forces_and_energies"] = ("full body (twice the simulated half with the mirror plane)"
                                       if scene.domain.symmetric else "full body")
    for name, value in cost.items():
        ds.attrs[f"cost_{name}"] = value
    ds.attrs.update(provenance_attrs(scene.to_dict(), key="scene"))
    ds.attrs["steady_window"] = json.dumps(list(scene.outputs.steady_window))
    ds.attrs["slid_distance_m"] = float(slid_total)
    ds.attrs["stopped_when_steady"] = int(slid_total < scene.sliding.distance_m)
    ds.attrs["coating_representation"] = coating_representation(scene)
    ds.attrs["interface_regime"] = interface_regime(scene)
    ds.attrs["contact_radius_particles"] = float(scene.contact_resolution)
    ds.attrs["resolution"] = scene.resolution_text()
    if int(ds["steady"]) and scene.contact_resolution < RESOLVED_CONTACT_PARTICLES:
        # steady says the window's mu and prow settled in time; an under-resolved contact does not undo that,
        # but a steady flag must not read as a trustworthy number without saying so
        ds["steady"].attrs["comment"] = ("steady in time only: the contact is under-resolved (attribute "
                                         "resolution); the window settled on the discretisation's answer")
    return ds


def coating_representation(scene: Scene) -> str:
    """How the coating was discretised (said in the output, never silently rounded)."""
    if not scene.layers.coated:
        return "uncoated"
    h = scene.discretisation.particle_size_m
    t = scene.layers.coating_thickness_m
    ratio = t / h
    full = int(np.floor(ratio + 1e-9))  # t = 30e-6, h = 10e-6 is 3 layers despite round-off
    rest = ratio - full
    if rest < 1e-9:
        text = f"{full} full particle layer(s) of coating (t/h = {ratio:g})"
    else:
        text = (f"{full} full particle layer(s) of coating plus one layer that straddles the interface and carries "
                f"the volume-weighted mix (coating fraction {rest:.3g}); t/h = {ratio:.3g}")
    if scene.discretisation.graded:
        text += (f"; outside the fine zone (graded particles of 2 h) the same rule with t/(2h) = {0.5 * ratio:.3g}, "
                 "the coating's volume kept exactly")
    return text


def interface_regime(scene: Scene) -> str:
    """What the interface can do at this scene's strength: said in the output, since at or above the wave limit
    on a perfectly plastic layer mu follows the simulated speed without settling (``Scene.interface_sticks``)."""
    ratio = scene.interface_strength_ratio
    if ratio is None:
        return "pressure-dependent interface shear (tau = Cp P^np, capped at the contacting material's kappa)"
    limit = scene.wave_limit_ratio
    sticking = scene.sticking_ratio
    if sticking is not None:
        return (f"tau = {sticking:.3g} kappa of a perfectly plastic surface the sphere touches, at or above the wave "
                f"limit cos^2 alpha = {limit:.3g} of the expected contact: no steady state expected (the contact "
                "can stick and a prow of the layer build up ahead of the sphere); mu measured to follow the "
                "simulated speed and mass scaling without settling (docs/model.md, 3.8)")
    if ratio >= limit:
        capped = "capped at kappa" if ratio >= 1.0 else f"= {ratio:.3g} kappa, at or above the wave limit {limit:.3g},"
        return f"tau {capped} of a strain-hardening surface (not flagged; speed dependence not measured)"
    return (f"tau = {ratio:.3g} kappa (largest over the surfaces the sphere touches, at yield onset; below the wave "
            f"limit cos^2 alpha = {limit:.3g} of the expected contact)")


class DiskFullError(OSError):
    """No space left on the device a result or a snapshot goes to (errno ENOSPC), said with the file's name.

    netCDF reports a full disk as "NetCDF: HDF error", and only when the whole run is done: the writers here
    tell it by the free space left (``shutil.disk_usage``) against the bytes the file needs.
    """

    def __init__(self, path: Path, need: int, free: int | None, cause: str = "") -> None:
        super().__init__(errno.ENOSPC, os.strerror(errno.ENOSPC), str(path))
        room = "" if free is None else f", {_megabytes(free)} free there"
        said = f" ({cause})" if cause else ""
        self.message = (f"no space left on device for {path}{said}: it needs about {_megabytes(need)}{room}; free "
                        "some space (or write elsewhere) and run again; nothing was written under that name")

    def __str__(self) -> str:
        return self.message


def _megabytes(n: int) -> str:
    return f"{n / 1e6:.3g} MB"


def _free_bytes(folder: Path) -> int | None:
    try:
        return shutil.disk_usage(folder).free
    except OSError:
        return None


def write_result(ds: xr.Dataset, path: str | Path) -> Path:
    """Write a run's dataset atomically (``plough.io.write_netcdf_atomic``); a full disk is refused before
    writing when the free space is already short of the data, and named as such (with the path) when the
    writer fails on it. Any other failure names the path too."""
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    need = int(ds.nbytes)
    free = _free_bytes(path.parent)
    if free is not None and free < need:
        raise DiskFullError(path, need, free, "refused before writing")
    try:
        return write_netcdf_atomic(ds, path)
    except (OSError, RuntimeError) as exc:  # netCDF4: RuntimeError("NetCDF: HDF error") from a full disk
        free = _free_bytes(path.parent)  # the temporary file is gone again: what is left is what there was
        if getattr(exc, "errno", None) == errno.ENOSPC or (free is not None and free < need):
            raise DiskFullError(path, need, free, str(exc)) from exc
        raise OSError(f"{path} could not be written: {exc}") from exc


# ----------------------------------------------------------------------------- snapshots
def _data_array(name: str, arr: np.ndarray, ncomp: int) -> str:
    raw = np.ascontiguousarray(arr, dtype=np.float32).tobytes()
    header = np.array([len(raw)], dtype=np.uint32).tobytes()
    payload = base64.b64encode(header).decode() + base64.b64encode(raw).decode()
    return (f'<DataArray type="Float32" Name="{name}" NumberOfComponents="{ncomp}" format="binary">'
            f"{payload}</DataArray>")


def write_snapshot(p: Particles, path: str | Path, sphere_centre: np.ndarray, sphere_radius: float,
                   coating_row: int = -1) -> Path:
    """Particles as VTK XML PolyData (.vtp): position, material, plastic strain, temperature, stress, size.

    Written atomically (a temporary name, then a rename); a full disk raises ``DiskFullError`` naming the file.
    """
    path = Path(path)
    path.parent.mkdir(parents=True, exist_ok=True)
    n = p.n
    sig = p.stress
    pressure = -(sig[:, 0] + sig[:, 1] + sig[:, 2]) / 3.0
    s = sig[:, :3] + pressure[:, None]
    mises = np.sqrt(1.5 * (s**2).sum(1) + 3.0 * (sig[:, 3:] ** 2).sum(1))
    coating_fraction = np.where(p.mat_a == coating_row, p.frac_a, 0.0)
    conn = np.arange(n, dtype=np.int32)
    xml = [
        '<?xml version="1.0"?>',
        '<VTKFile type="PolyData" version="0.1" byte_order="LittleEndian" header_type="UInt32">',
        "<PolyData>",
        f'<Piece NumberOfPoints="{n}" NumberOfVerts="{n}" NumberOfLines="0" NumberOfStrips="0" NumberOfPolys="0">',
        "<PointData>",
        _data_array("material", p.mat_a.astype(np.float32), 1),
        _data_array("coating_fraction", coating_fraction, 1),
        _data_array("plastic_strain", p.eps_p, 1),
        _data_array("temperature_K", p.temperature, 1),
        _data_array("von_mises_Pa", mises, 1),
        _data_array("pressure_Pa", pressure, 1),
        _data_array("stress_Pa", sig, 6),
        _data_array("velocity_m_s", p.v, 3),
        _data_array("size_m", np.cbrt(p.vol0 * p.J), 1),  # current cube edge: h, or 2 h where graded
        "</PointData>",
        "<Points>", _data_array("Points", p.x, 3), "</Points>",
        "<Verts>",
        '<DataArray type="Int32" Name="connectivity" format="binary">'
        + base64.b64encode(np.array([conn.nbytes], np.uint32).tobytes()).decode()
        + base64.b64encode(conn.tobytes()).decode() + "</DataArray>",
        '<DataArray type="Int32" Name="offsets" format="binary">'
        + base64.b64encode(np.array([conn.nbytes], np.uint32).tobytes()).decode()
        + base64.b64encode((conn + 1).tobytes()).decode() + "</DataArray>",
        "</Verts>",
        "</Piece>",
        "</PolyData>",
        f"<!-- sphere centre {sphere_centre.tolist()} m, radius {sphere_radius} m -->",
        "</VTKFile>",
    ]
    text = "\n".join(xml)
    # under a temporary name, renamed when complete: a full disk or Ctrl-C never leaves a truncated .vtp
    tmp = None
    try:
        tmp = temporary_beside(path)
        tmp.write_text(text)
        os.replace(tmp, path)
    except BaseException as exc:
        if tmp is not None:
            tmp.unlink(missing_ok=True)
        if isinstance(exc, OSError) and exc.errno == errno.ENOSPC:
            raise DiskFullError(path, len(text), _free_bytes(path.parent), "a snapshot") from None
        if isinstance(exc, OSError):
            raise OSError(f"snapshot {path} could not be written: {exc.strerror or exc}") from exc
        raise
    return path
