"""Run a scene: the time loop with recording, progress, snapshots, and the results dataset.

``simulate(scene)`` returns an ``xarray.Dataset``; ``run_scene_file`` is the command-line path
(scene YAML in, netCDF out, written atomically: a failed run leaves no result file).
"""

from __future__ import annotations

import numbers
import os
import sys
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import Any

import numba
import numpy as np
import xarray as xr

from plough.io import to_json
from plough.mpm import contact, io, solver, transfers
from plough.mpm.constitutive import pack_materials
from plough.mpm.particles import Particles
from plough.mpm.scene import PRESETS, RESOLVED_CONTACT_PARTICLES, Scene, defaults_taken, read_scene_data


def _split_channels() -> tuple[list[str], np.ndarray, np.ndarray]:
    """The series of the grid contact's shear split (io.CONTACT_SPLIT_META), their contact.OUT_* channels and
    signs (friction forces positive against the sliding, as Fx_sh)."""
    regions = ("front", "rear", "front_up", "rear_up")
    chans = {"contact_shear_area": (contact.OUT_SH_AREA, 1.0),
             "contact_shear_capacity": (contact.OUT_SH_TAU_AREA, 1.0)}
    for r, name in enumerate(regions):
        chans[f"contact_area_{name}"] = (contact.OUT_REGION_AREA + r, 1.0)
        chans[f"contact_fx_sh_{name}"] = (contact.OUT_REGION_FX + r, -1.0)
        chans[f"contact_area_xy_{name}"] = (contact.OUT_REGION_AREA_XY + r, 1.0)
        chans[f"contact_fz_pl_{name}"] = (contact.OUT_REGION_FZ + r, 1.0)
    for kind, (area, fx) in {"stuck": (contact.OUT_STUCK_AREA, contact.OUT_STUCK_FX),
                             "carried": (contact.OUT_CARRIED_AREA, contact.OUT_CARRIED_FX),
                             "outside": (contact.OUT_OUTSIDE_AREA, contact.OUT_OUTSIDE_FX),
                             "gap": (contact.OUT_GAP_AREA, contact.OUT_GAP_FX),
                             "lateral": (contact.OUT_LATERAL_AREA, contact.OUT_LATERAL_FX)}.items():
        chans[f"contact_area_{kind}"] = (area, 1.0)
        chans[f"contact_fx_sh_{kind}"] = (fx, -1.0)
    assert set(chans) == set(io.CONTACT_SPLIT_META)
    names = list(io.CONTACT_SPLIT_META)
    return names, np.array([chans[n][0] for n in names]), np.array([chans[n][1] for n in names])


SPLIT_NAMES, SPLIT_CHANNELS, SPLIT_SIGNS = _split_channels()


class _Recorder:
    """Interval means of the per-step forces and snapshots of the energies, every ``every`` steps.

    ``split``: whether to record the grid contact's split of its interface shear (SPLIT_NAMES); the particle
    contact has no such split, so its runs record none (and their result files hold no empty series).
    """

    def __init__(self, every: int, split: bool = True) -> None:
        self.every = max(int(every), 1)
        self.split = split
        self.rows: list[dict[str, float]] = []
        self.slid: list[float] = []
        self._sum = np.zeros(7)
        self._split = np.zeros(len(SPLIT_NAMES))
        self._count = 0
        self.max_penetration = -np.inf

    def add(self, s: solver.State, c: solver.Constants) -> None:
        out = s.work.contact_out
        # full-body forces: the mirror half carries half of Fx and Fz, and Fy of the full body is 0
        k = c.symmetry_factor
        fn, ft = k * out[contact.OUT_FN:contact.OUT_FN + 3], k * out[contact.OUT_FT:contact.OUT_FT + 3]
        fy = 0.0 if k == 2.0 else fn[1] + ft[1]
        self._sum += np.array([-(fn[0] + ft[0]), fy, fn[2] + ft[2], -fn[0], -ft[0], fn[2], ft[2]])
        if self.split:
            self._split += k * SPLIT_SIGNS * out[SPLIT_CHANNELS]
        self._count += 1
        pen = float(s.work.acc[:, transfers.ACC_PENETRATION].max())
        self.max_penetration = max(self.max_penetration, pen)
        if self._count >= self.every:
            self.flush(s, c, pen)

    def flush(self, s: solver.State, c: solver.Constants, pen: float) -> None:
        if self._count == 0:
            return
        m = self._sum / self._count
        acc, w, k = s.work.acc, s.work, c.symmetry_factor
        self.rows.append({
            "Fx": m[0], "Fy": m[1], "Fz": m[2], "Fx_pl": m[3], "Fx_sh": m[4], "Fz_pl": m[5], "Fz_sh": m[6],
            "depth": c.sphere_radius - s.sphere.centre[2],
            "particle_penetration": pen, "contact_area_xy": k * float(w.contact_out[contact.OUT_AREA_XY]),
            "material_top": material_top(s),
            "external_work": k * w.external_work, "plastic_work": k * w.plastic_work,
            "elastic_energy": k * solver.elastic_energy(s, c),
            "kinetic_energy": k * float(acc[:, transfers.ACC_KINETIC].sum()),
            "interface_dissipation": k * w.interface_dissipation, "contact_impact_loss": k * w.contact_impact_loss,
            "frozen_kinetic_loss": k * s.zone.frozen_kinetic_loss_J,
            "heat": k * w.heat, "time": s.time,
        })
        if self.split:
            self.rows[-1].update(zip(SPLIT_NAMES, (self._split / self._count).tolist(), strict=True))
        self.slid.append(s.sphere.slid_m if s.sphere.phase in ("slide", "done") else 0.0)
        self._sum[:] = 0.0
        self._split[:] = 0.0
        self._count = 0

    def series(self) -> tuple[dict[str, np.ndarray], np.ndarray]:
        keys = self.rows[0].keys()
        return {k: np.array([r[k] for r in self.rows]) for k in keys}, np.array(self.slid)


class SteadyStop:
    """Ends the slide once the steady-state friction has stopped changing (``sliding.stop_when_steady``).

    Every tenth of ``sliding.distance_m`` (after at least 2.7 expected contact radii and a third of
    the distance, so that a residual groove is left behind the sphere), mu is taken over the steady
    window as the same fractions of the distance slid so far. The slide stops when the last three
    such values differ by less than ``sliding.steady_tolerance`` of their mean.
    """

    CHECKS = 10

    def __init__(self, scene: Scene) -> None:
        a, _ = scene.expected_contact()
        self.scene = scene
        self.window = scene.outputs.steady_window
        self.tolerance = scene.sliding.steady_tolerance
        self.every = scene.sliding.distance_m / self.CHECKS
        self.minimum = max(2.7 * a / (1.0 - self.window[0]), scene.sliding.distance_m / 3.0)
        self.next_check = self.every
        self.history: list[float] = []

    def steady(self, rec: _Recorder, slid_m: float) -> bool:
        """Whether the slide may stop at ``slid_m`` (call once per step while sliding)."""
        if slid_m < self.next_check or not rec.rows:
            return False
        self.next_check += self.every
        mask = io.steady_window_mask(np.array(rec.slid), self.scene, slid_m)
        if mask.sum() < 3:
            return False
        fx = np.array([r["Fx"] for r in rec.rows])[mask].mean()
        fz = np.array([r["Fz"] for r in rec.rows])[mask].mean()
        self.history.append(fx / fz)
        last = self.history[-3:]
        return (slid_m >= self.minimum and len(last) == 3
                and max(last) - min(last) <= self.tolerance * abs(float(np.mean(last))))


class SteadyStateWarning(UserWarning):
    """The run's steady window does not hold a steady state (``io.steadiness``)."""


class ResolutionWarning(UserWarning):
    """The expected contact radius is under ``scene.RESOLVED_CONTACT_PARTICLES`` particle sizes."""


def warn_if_under_resolved(scene: Scene) -> None:
    """Warn (ResolutionWarning) before a run whose expected contact spans too few particles to resolve it."""
    if scene.contact_resolution < RESOLVED_CONTACT_PARTICLES:
        warnings.warn(f"scene {scene.name!r}: {scene.resolution_text()}", ResolutionWarning, stacklevel=3)


def check_threads(threads: int) -> None:
    """Refuse a thread count numba cannot use, naming it (numba's own error names no parameter)."""
    most = numba.config.NUMBA_NUM_THREADS
    if isinstance(threads, bool) or not isinstance(threads, numbers.Integral) or not 1 <= threads <= most:
        raise ValueError(f"threads = {threads!r} is outside the allowed range 1..{most} (this machine's cores, or "
                         "NUMBA_NUM_THREADS)")


def simulate(scene: Scene, *, progress: bool = True, snapshots_dir: str | Path | None = None,
             threads: int | None = None) -> xr.Dataset:
    """Run the MPM ploughing simulation of ``scene`` and return its results dataset."""
    if threads is not None:
        check_threads(threads)
        numba.set_num_threads(threads)
    warn_if_under_resolved(scene)
    wall0 = time.perf_counter()
    state, const = solver.init(scene)
    max_press_steps = int(10 * scene.sphere.radius_m / (const.press_speed * const.dt))
    grid_nodes_start = const.grid.n_nodes  # the grid may grow (plough.mpm.growth)
    rec = _Recorder(const.steps_slide / scene.outputs.records, split=scene.discretisation.contact != "particle")
    n_snap = scene.outputs.snapshots
    snap_every = scene.sliding.distance_m / n_snap if n_snap else np.inf
    next_snap = 0.0
    coating_row = 0 if scene.layers.coated else -1
    bar = _progress(scene, enabled=progress)
    stopper = SteadyStop(scene) if scene.sliding.stop_when_steady else None
    slid_distance = scene.sliding.distance_m
    active_particle_steps = 0
    raises_told = extensions_told = widenings_told = retired_told = 0
    stragglers_told = False
    try:
        while state.sphere.phase != "done":
            solver.step(state, const)
            active_particle_steps += state.zone.ranges.p_hi - state.zone.ranges.p_lo
            rec.add(state, const)
            if stopper is not None and state.sphere.phase == "slide" and stopper.steady(rec, state.sphere.slid_m):
                slid_distance = state.sphere.slid_m
                state.sphere.phase = "done"
                state.sphere.velocity[:] = 0.0
            if state.sphere.phase in ("press", "settle") and state.step > max_press_steps:
                raise solver.SimulationError(
                    f"the sphere did not reach the load in {state.step} steps: load_N = {scene.load_N:g} N may be "
                    "too high for the domain, or the contact is lost")
            if snapshots_dir is not None and state.sphere.slid_m >= next_snap and state.sphere.phase == "slide":
                # nanometres: whole micrometres repeat where snapshots lie less than 1 um apart
                name = f"{scene.name}_{int(round(next_snap * 1e9)):010d}nm.vtp"
                io.write_snapshot(state.particles, Path(snapshots_dir) / name, state.sphere.centre,
                                  const.sphere_radius, coating_row)
                next_snap += snap_every
            if bar is not None and len(state.grid_raises) > raises_told:
                raises_told = len(state.grid_raises)
                step_no, slid_m, top_m = state.grid_raises[-1]
                _tell(bar, f"{scene.name}: material reached the grid's top at step {step_no} ({slid_m * 1e6:.1f} um "
                           f"slid); the grid's top raised to {top_m * 1e6:.1f} um above the original surface")
            if bar is not None and len(state.grid_extensions) > extensions_told:
                extensions_told = len(state.grid_extensions)
                step_no, slid_m, end_m = state.grid_extensions[-1]
                _tell(bar, f"{scene.name}: material passed the grid's far end at step {step_no} ({slid_m * 1e6:.1f} "
                           f"um slid); the grid lengthened to x = {end_m * 1e6:.1f} um")
            if bar is not None and len(state.grid_widenings) > widenings_told:
                widenings_told = len(state.grid_widenings)
                step_no, slid_m, side_m = state.grid_widenings[-1]
                _tell(bar, f"{scene.name}: material passed the grid's side at step {step_no} ({slid_m * 1e6:.1f} "
                           f"um slid); the grid widened to y = {side_m * 1e6:.1f} um")
            if bar is not None and len(state.zone.retired_log) > retired_told:
                retired_told = len(state.zone.retired_log)
                step_no, slid_m, count = state.zone.retired_log[-1]
                _tell(bar, f"{scene.name}: {count} particle(s) flung past the grid's growth limits at step {step_no} "
                           f"({slid_m * 1e6:.1f} um slid) retired as debris (plough.mpm.strays)")
            if bar is not None and state.zone.stragglers_frozen and not stragglers_told:
                stragglers_told = True
                _tell(bar, f"{scene.name}: material flowed back out of the active zone's trailing slabs at step "
                           f"{state.step} ({state.sphere.slid_m * 1e6:.1f} um slid); frozen where it is (plough.mpm."
                           "strays; the count in cost_stragglers_frozen)")
            if bar is not None and state.step % 20 == 0:
                _update_bar(bar, state, rec)
    finally:
        if bar is not None:
            bar.close()
    rec.flush(state, const, float(state.work.acc[:, transfers.ACC_PENETRATION].max()))
    if snapshots_dir is not None:
        io.write_snapshot(state.particles, Path(snapshots_dir) / f"{scene.name}_final.vtp", state.sphere.centre,
                          const.sphere_radius, coating_row)
    wall = time.perf_counter() - wall0
    series, slid = rec.series()
    n = state.particles.n
    # particle-steps count the particles a step worked on (all of them without an active zone)
    cost = {"wall_time_s": wall, "steps": state.step, "particles": n, "grid_nodes": grid_nodes_start,
            "grid_nodes_end": const.grid.n_nodes,
            "dt_s": const.dt, "particle_steps": active_particle_steps,
            "active_fraction": active_particle_steps / max(n * state.step, 1),
            "particle_steps_per_s": active_particle_steps / wall, "threads": numba.get_num_threads(),
            "grid_top_m": float(const.grid_hi[2]), "grid_top_raises": len(state.grid_raises),
            "grid_end_m": float(const.grid_hi[0]), "grid_end_extensions": len(state.grid_extensions),
            "grid_side_m": float(const.grid_hi[1]), "grid_side_widenings": len(state.grid_widenings),
            "retired_particles": int(state.zone.retired.sum()),
            "retired_mass_fraction": state.zone.retired_mass_kg / float(state.particles.mass.sum()),
            "stragglers_frozen": state.zone.stragglers_frozen}
    ds = io.build_dataset(scene, series, slid, kept_particles(state), state.sphere.centre.copy(), cost,
                          rec.max_penetration, coating_row, slid_distance_m=slid_distance)
    warn_if_unsteady(ds, scene.name)
    return ds


def material_top(s: solver.State) -> float:
    """Height of the highest particle centre, m, but for the debris retired past the grid's limits."""
    z = s.particles.x[:, 2]
    return float(z[~s.zone.retired].max()) if s.zone.retired_mass_kg > 0.0 else float(z.max())


def kept_particles(s: solver.State) -> Particles:
    """The particles the outputs read: all but the debris retired past the grid's limits (:mod:`plough.mpm.strays`)."""
    if s.zone.retired_mass_kg == 0.0:
        return s.particles
    keep = ~s.zone.retired
    return Particles(*(a[keep] for a in s.particles))


def warn_if_unsteady(ds: xr.Dataset, name: str) -> None:
    """Warn (SteadyStateWarning) when the run's steady window is not a steady state (``io.steadiness``)."""
    if not int(ds["steady"]):
        warnings.warn(f"scene {name!r}: the steady window is not a steady state (mu moved "
                      f"{float(ds.mu_drift):+.1%} from its first half to its second, the highest particle "
                      f"{float(ds.material_top_rise) * 1e6:+.1f} um); mu and dp are means of a changing state "
                      "(variables mu_drift, material_top_rise, steady)", SteadyStateWarning, stacklevel=3)


def _progress(scene: Scene, enabled: bool):
    if not enabled:
        return None
    from tqdm import tqdm

    return tqdm(total=round(scene.sliding.distance_m * 1e6, 1), unit="um", desc=f"{scene.name}: pressing",
                bar_format="{desc} |{bar}| {n:.0f}/{total:.0f} um slid [{elapsed}<{remaining}] {postfix}")


def _tell(bar, message: str) -> None:
    """One line above the progress bar, on standard error with the bar (tqdm writes to standard output by default,
    which the workflow does not keep in the run's log)."""
    bar.write(message, file=sys.stderr)


def _update_bar(bar, state: solver.State, rec: _Recorder) -> None:
    slid_um = round(state.sphere.slid_m * 1e6, 1)
    bar.set_description_str(f"{state.sphere.phase}", refresh=False)
    if rec.rows:
        last = rec.rows[-1]
        bar.set_postfix_str(f"Fx={last['Fx']:.3g} N Fz={last['Fz']:.3g} N step={state.step}", refresh=False)
    bar.update(slid_um - bar.n)


def apply_preset(scene: Scene, preset: str | None) -> Scene:
    """``paper``: the paper's block, slide, speed and mass scaling (``Scene.with_paper_settings``);
    ``sized``: the block sized from the expected contact (``Scene.with_sized_domain``)."""
    if preset is None:
        return scene
    if preset == "paper":
        return scene.with_paper_settings()
    if preset == "sized":
        return scene.with_sized_domain()
    raise ValueError(f"preset = {preset!r} is unknown; allowed: {', '.join(PRESETS)}")


def run_scene_file(scene_path: str | Path, output: str | Path, *, snapshots_dir: str | Path | None = None,
                   threads: int | None = None, progress: bool = True, preset: str | None = None,
                   on_scene: Callable[[Scene], None] | None = None,
                   on_defaults: Callable[[dict[str, Any]], None] | None = None) -> Path:
    """Read a scene YAML, apply the optional preset, simulate, write the netCDF atomically
    (nothing is written on failure). ``on_scene`` sees the validated scene before the run, ``on_defaults``
    the keys the file left to their defaults (``scene.defaults_taken``), which the result records as the
    attribute ``scene_defaults`` (JSON, ``{}`` for a file that gives every key)."""
    if threads is not None:
        check_threads(threads)
    data = read_scene_data(Path(scene_path))
    scene = apply_preset(Scene.from_dict(data), preset)
    defaults = defaults_taken(data, scene)
    check_output_paths(output, snapshots_dir)
    if on_scene is not None:
        on_scene(scene)
    if on_defaults is not None and defaults:
        on_defaults(defaults)
    ds = simulate(scene, progress=progress, snapshots_dir=snapshots_dir, threads=threads)
    ds.attrs["scene_defaults"] = to_json(defaults)
    return io.write_result(ds, output)


def check_output_paths(output: str | Path, snapshots_dir: str | Path | None = None) -> None:
    """Refuse, before a run, an output file or snapshot directory that could not be written afterwards.

    Creates the output's folder and the snapshot directory (as the writers would).
    """
    out = Path(output)
    if out.is_dir():
        raise ValueError(f"output {str(out)!r} is a directory; give a file name (for example run.nc)")
    folders = [("output folder", out.parent)] + ([("snapshots", Path(snapshots_dir))] if snapshots_dir else [])
    for what, folder in folders:
        try:
            folder.mkdir(parents=True, exist_ok=True)
        except OSError as exc:
            raise ValueError(f"{what} {str(folder)!r} cannot be created: {exc.strerror}") from None
        if not os.access(folder, os.W_OK | os.X_OK):
            raise ValueError(f"{what} {str(folder)!r} is not writable")


def warm_up(threads: int | None = None) -> float:
    """Compile (or load from numba's cache) every kernel by running a tiny scene (and calling the
    active zone's freezing kernel); returns seconds.

    Workflows call this once before fanning runs out: parallel first-time compilation of
    ``cache=True`` functions can race on the cache files.
    """
    from plough.materials import rigid_plastic
    from plough.mpm.scene import Discretisation, Domain, Layers, Outputs, Sliding

    t0 = time.perf_counter()
    scene = Scene(layers=Layers(substrate=rigid_plastic("warm_up", 900e6, coating=False),
                                coating=rigid_plastic("warm_up_coating", 450e6, coating=True),
                                coating_thickness_m=15e-6),
                  load_N=0.5, domain=Domain(radius_m=100e-6, length_m=400e-6),
                  sliding=Sliding(distance_m=150e-6), discretisation=Discretisation(particle_size_m=20e-6),
                  outputs=Outputs(records=20), name="warm_up")
    with warnings.catch_warnings():  # the compile-only scene is short and coarse: not the user's run
        warnings.simplefilter("ignore", SteadyStateWarning)
        warnings.simplefilter("ignore", ResolutionWarning)
        simulate(scene, progress=False, threads=threads)
    _compile_freeze(pack_materials(scene.layers.materials))
    return time.perf_counter() - t0


def _compile_freeze(table: np.ndarray) -> None:
    """Compile the active zone's freezing kernel, which the warm-up scene (no zone) never calls."""
    from plough.mpm.particles import particles_of

    transfers.freeze_particles(particles_of(1), np.zeros((1, 3)), table, 0, 1)
