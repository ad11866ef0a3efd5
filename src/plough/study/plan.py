"""The plan before the run: ``plough plan`` projects the wall time of a workflow config, per figure and in
total, on this machine and per cluster job, before anything runs.

    plough plan [--configfile FILE ...] [--cores 2] [--profile profiles/slurm] [--points]

The config is read as Snakemake reads it: ``config/config.yaml``, then each ``--configfile`` merged into it
key by key. Each MPM run's particle-steps are counted by :func:`plough.study.cost.estimate` (within a few
per cent of the solver's), and its time is its particle-steps over the throughput *measured* for workflow
jobs of its family (rigid-plastic or real materials, whose flow laws cost more) at the measured particle
size nearest in log h: the sum of the measured jobs' wall times over the sum of their particle-steps, so
a job's start-up, its result's writing and the fixed cost of a step are in it. The measured jobs are

* the workflow's own benchmark files of the runs of this config, ``benchmarks/runs/<run>.tsv`` (Snakemake's
  ``benchmark:``, column ``s``) beside a result file that is a run (not a skip or failure marker), its
  threads read from the result (``cost_threads``); and
* the rows of ``benchmarks/results/projection_check_*.json`` (``benchmarks/projection_check.py``: workflow
  runs measured here, at the threads each row or file records, 2 where neither says), where no benchmark
  file of the same run is present.

A run measured more than once counts once: at its benchmark file here, else at the row whose job ended last
(rows without the time, from files written before it was recorded, count as older, in file-name order).

Where jobs of a family and size were measured at the config's threads, only they set its rate. Elsewhere jobs
measured at other thread counts are scaled linearly: optimistic for more threads a run (a run gains 1.6-1.8x
from a second thread here), pessimistic for fewer (two one-thread runs at once beat one two-thread run by
1.1-1.3x: docs/performance.md, "Two runs at once"). With no
measured job of a family, its runs go at :data:`plough.study.cost.THROUGHPUT_PER_THREAD` a thread, the
slowest rate measured for workflow jobs here. On a cluster each run is one job with the profile's threads
(``set-threads: mpm_run``), its time scaled linearly from the time here, and its request the profile's
(:func:`plough.study.cost.runtime_minutes`). What this leaves out: the analytical figures and the datasets
(seconds each), the machine's drift (whole-run times vary by up to 30% between invocations,
docs/performance.md), and a finest run that stops (counted in full).

Refinement only where needed (``mpm.skip_finest_tolerance``; the workflow's checkpoint ``mpm_refine``):
whether a gated finest run is made is known only once its point's two coarser runs are, so the plan
states a range: every gated finest run made (the upper end, the tables' figures) and every one not
yet decided skipped (the lower end). Decisions already made (``results/refinement/<run>.json`` under
the workflow's directory) are followed at both ends.

Resuming: the runs already made under the workflow's directory (``results/runs/<run>.nc`` holding this run's
scene, made by this solver: the files the workflow would not redo) are left out of what is *left*, stated
as the same range and, once decisions are made, as an expected time that counts each undecided gated finest
run at the share of the decisions made so far that needed theirs (a guess from the points decided first,
which are not a random sample: a point's coarser runs land in the workflow's order, longest first).
"""

from __future__ import annotations

import argparse
import csv
import json
import math
from collections.abc import Iterable, Mapping
from dataclasses import dataclass, field
from datetime import UTC, datetime
from pathlib import Path
from typing import Any

#: where the measured calibration lives, relative to the working directory (the repository root)
CALIBRATION_FILES = "benchmarks/results/projection_check_*.json"
RUN_BENCHMARKS = "benchmarks/runs"
#: the refinement decisions of the workflow's checkpoint mpm_refine, relative to its directory
DECISIONS = "results/refinement"
BASE_CONFIG = "config/config.yaml"
FAMILIES = ("rigid-plastic", "real materials")
#: every figure the workflow draws; the analytical ones (and Fig. 22's fits) need no MPM run of their own
ALL_FIGURES = ("fig03", "fig04", "fig11", "fig12", "fig13", "fig14", "fig15", "fig16", "fig17", "fig18", "fig19",
               "fig20", "fig21", "fig22", "fig23")


def merge(base: dict[str, Any], override: Mapping[str, Any]) -> dict[str, Any]:
    """``override`` merged into ``base`` key by key, as Snakemake merges a ``--configfile`` (in place)."""
    for key, value in override.items():
        if isinstance(value, Mapping):
            base[key] = merge(base.get(key) if isinstance(base.get(key), dict) else {}, value)
        else:
            base[key] = value
    return base


def load_config(configfiles: Iterable[str | Path], directory: str | Path = ".") -> dict[str, Any]:
    """The workflow's config: ``config/config.yaml`` of ``directory``, then each file merged into it."""
    import yaml

    config: dict[str, Any] = yaml.safe_load((Path(directory) / BASE_CONFIG).read_text())
    for f in configfiles:
        path = Path(f) if Path(f).is_absolute() or Path(f).exists() else Path(directory) / f
        merge(config, yaml.safe_load(path.read_text()) or {})
    return config


@dataclass(frozen=True)
class Measured:
    """One measured workflow job: its run, family, size, counted particle-steps, wall time, threads, where it was
    read and when the job ended (``None`` where that was not recorded: calibration files written before 2026-12-06
    evening)."""

    run: str
    family: str
    h_um: float
    particle_steps: float
    seconds: float
    threads: int
    source: str
    ended: datetime | None = None


def ended_at(tsv: Path) -> datetime:
    """When a Snakemake benchmark file was written, the end of its job: the file's modification time, in UTC."""
    return datetime.fromtimestamp(tsv.stat().st_mtime, UTC)


def _ended(row: Mapping[str, Any], path: Path) -> datetime | None:
    """A calibration row's ``ended`` (ISO 8601 with its time zone), ``None`` where the row has none."""
    text = row.get("ended")
    if text is None:
        return None
    where = f"{path}: run {row.get('run')!r}: ended = {text!r}"
    try:
        when = datetime.fromisoformat(text)
    except (TypeError, ValueError):
        raise ValueError(f"{where} is not an ISO 8601 time") from None
    if when.tzinfo is None:
        raise ValueError(f"{where} has no time zone (write it in UTC, Z)")
    return when


def family_of(scene: Any) -> str:
    """``real materials`` for a run whose layers use the real flow laws, else ``rigid-plastic``."""
    from plough.materials import ConstantFlow

    constant = all(isinstance(m.flow, ConstantFlow) for m in scene.layers.materials)
    return "rigid-plastic" if constant else "real materials"


#: the threads a run of a ``projection_check.py`` result ran at where the file does not say: every file written
#: before it recorded them was measured with ``mpm.threads: 2`` (the config files named in them say so at the
#: commits that made them; today's content of a named config says nothing about a past measurement)
UNRECORDED_THREADS = 2


def measured_from_json(paths: Iterable[Path]) -> list[Measured]:
    """The rows of ``projection_check.py`` results, each at the threads it records (``threads`` of the row, else
    of the file, else ``UNRECORDED_THREADS``), oldest first: the rows that record when their job ended in the
    order of their end, after those that do not (written before it was recorded), which keep the order of
    their files' names."""
    rows = []
    for path in sorted(paths):
        data = json.loads(path.read_text())
        threads = int(data.get("threads", UNRECORDED_THREADS))
        for r in data["runs"]:
            if math.isfinite(r.get("measured_s", math.nan)) and r["measured_s"] > 0:
                rows.append(Measured(r["run"], r["family"], float(r["h_um"]), float(r["particle_steps"]),
                                     float(r["measured_s"]), int(r.get("threads", threads)), str(path),
                                     _ended(r, path)))
    undated = [r for r in rows if r.ended is None]
    return undated + sorted((r for r in rows if r.ended is not None), key=lambda r: r.ended)


def job_seconds(tsv: Path) -> float:
    """The wall time in seconds of a Snakemake benchmark file (its first row, column ``s``)."""
    with tsv.open() as f:
        return float(next(csv.DictReader(f, delimiter="\t"))["s"])


def is_marker(attrs: Mapping[str, Any]) -> bool:
    """Whether a result's attributes are a failure or skip marker's: its job made no run to calibrate with."""
    from plough.study.skipping import FAILED_ATTR, SKIPPED_ATTR

    return bool(attrs.get(FAILED_ATTR) or attrs.get(SKIPPED_ATTR))


def measured_from_benchmarks(directory: Path, runs: Mapping[str, Any], threads: int) -> list[Measured]:
    """The workflow's benchmark files of ``runs`` (run id -> scene) under ``directory``: each with a result
    file that is a run; a skip or failure marker's job made no run. Threads from the result
    (``cost_threads``), else ``threads``."""
    import xarray as xr

    from plough.study import cost

    rows = []
    for tsv in sorted((directory / RUN_BENCHMARKS).glob("*.tsv")):
        rid = tsv.stem
        result = directory / "results" / "runs" / f"{rid}.nc"
        if rid not in runs or not result.exists():
            continue
        try:
            with xr.open_dataset(result) as ds:
                attrs = dict(ds.attrs)
        except (OSError, ValueError):
            continue
        if is_marker(attrs) or "cost_particle_steps" not in attrs:
            continue
        seconds = job_seconds(tsv)
        if not (math.isfinite(seconds) and seconds > 0):
            continue
        scene = runs[rid]
        rows.append(Measured(rid, family_of(scene), round(scene.discretisation.particle_size_m * 1e6, 6),
                             cost.estimate(scene).particle_steps, seconds, int(attrs.get("cost_threads", threads)),
                             str(tsv), ended_at(tsv)))
    return rows


def calibrating(rows: Iterable[Measured], threads: int
                ) -> tuple[dict[tuple[str, float], list[Measured]], frozenset[tuple[str, float]]]:
    """The jobs that calibrate each (family, h) for runs at ``threads``, and the (family, h) with none measured at
    ``threads``. Scaling from other threads is linear in them, which a second thread is not (it gains 1.6-1.8x
    here), so jobs at ``threads`` go first: a run measured more than once counts once, its last row at
    ``threads``, else its last row; where jobs of a family and size ran at ``threads``, only they count.
    Elsewhere every job counts, to be scaled linearly."""
    last: dict[str, Measured] = {}
    for r in rows:
        if r.threads == threads or r.run not in last or last[r.run].threads != threads:
            last[r.run] = r
    groups: dict[tuple[str, float], list[Measured]] = {}
    for r in last.values():
        groups.setdefault((r.family, r.h_um), []).append(r)
    scaled: set[tuple[str, float]] = set()
    for key, group in groups.items():
        same = [r for r in group if r.threads == threads]
        if same:
            groups[key] = same
        else:
            scaled.add(key)
    return groups, frozenset(scaled)


@dataclass(frozen=True)
class Rates:
    """Particle-steps per second of a job at ``threads`` threads, by family and measured size."""

    threads: int
    by_family: dict[str, dict[float, tuple[int, float]]]  # family -> h (um) -> (jobs, particle-steps / s)
    #: the (family, h) whose rate is scaled from jobs measured at other threads (none measured at ``threads``)
    scaled: frozenset[tuple[str, float]] = frozenset()

    @classmethod
    def from_measured(cls, rows: Iterable[Measured], threads: int) -> Rates:
        """Sum of particle-steps over the sum of wall times per family and size, each wall time scaled linearly
        to ``threads``, over the jobs :func:`calibrating` picks."""
        groups, scaled = calibrating(rows, threads)
        by_family: dict[str, dict[float, tuple[int, float]]] = {}
        for (family, h), used in groups.items():
            seconds = sum(r.seconds * r.threads / threads for r in used)
            by_family.setdefault(family, {})[h] = (len(used), sum(r.particle_steps for r in used) / seconds)
        return cls(threads, by_family, scaled)

    def rate(self, family: str, h_um: float) -> float:
        """The family's rate at the measured size nearest in log h (the smaller of two as near, as
        benchmarks/reproduction_time.py calibrates); with none measured, ``cost.THROUGHPUT_PER_THREAD`` a thread."""
        from plough.study import cost

        by_h = self.by_family.get(family)
        if not by_h:
            return cost.THROUGHPUT_PER_THREAD * self.threads
        return by_h[min(by_h, key=lambda h: (abs(math.log(h / h_um)), h))][1]


@dataclass(frozen=True)
class RunPlan:
    run: str
    family: str
    h_um: float
    particle_steps: float
    memory_mb: int
    here_s: float  # one job here, at the config's threads
    cluster_s: float  # one job at the profile's threads (linear scaling)
    request_min: int  # the profile's wall-time request (plough.study.cost.runtime_minutes)


@dataclass(frozen=True)
class Plan:
    config: dict[str, Any]
    threads: int
    cores: int
    cluster_threads: int
    rates: Rates
    measured: list[Measured]
    runs: dict[str, RunPlan]
    figures: dict[str, list[str]]
    #: gated finest run -> its refinement decision: True needed, False not, None not yet made
    gated: dict[str, bool | None] = field(default_factory=dict)
    #: the runs whose result file under the directory is this run by this solver (a failure marker included)
    done: frozenset[str] = frozenset()

    def made(self, runs: Iterable[str], *, undecided: bool) -> list[str]:
        """The runs of ``runs`` the workflow makes, each undecided gated finest run counted as ``undecided``."""
        return [r for r in runs if r not in self.gated
                or (self.gated[r] if self.gated[r] is not None else undecided)]

    @property
    def parallel_jobs(self) -> int:
        return max(1, self.cores // self.threads)

    def wall_s(self, runs: Iterable[str]) -> float:
        """Wall time here of these runs, ``parallel_jobs`` at a time: their sum over the jobs at once, or the
        longest run if longer."""
        times = [self.runs[r].here_s for r in runs]
        return max(sum(times) / self.parallel_jobs, max(times, default=0.0))

    @property
    def decided(self) -> list[bool]:
        """The refinement decisions made: True where the finest run was needed."""
        return [d for d in self.gated.values() if d is not None]

    def undecided(self, runs: Iterable[str]) -> list[str]:
        """The gated finest runs of ``runs`` whose decision is not yet made."""
        return [r for r in runs if r in self.gated and self.gated[r] is None]

    @property
    def need_share(self) -> float | None:
        """The share of the refinement decisions made that needed their finest run; None before any."""
        decided = self.decided
        return sum(decided) / len(decided) if decided else None

    def expected_wall_s(self, runs: Iterable[str]) -> float | None:
        """Wall time here of these runs with each undecided gated finest run counted at :attr:`need_share` of
        its time (``parallel_jobs`` at a time, never less than the longest run certain to be made); None
        before any decision is made."""
        share = self.need_share
        if share is None:
            return None
        runs = list(runs)
        certain = self.made(runs, undecided=False)
        open_s = sum(self.runs[r].here_s for r in self.undecided(runs))
        return max((sum(self.runs[r].here_s for r in certain) + share * open_s) / self.parallel_jobs,
                   max((self.runs[r].here_s for r in certain), default=0.0))


def cluster_threads(profile: str | Path | None) -> int | None:
    """``set-threads: mpm_run`` of a Snakemake profile directory (None without one)."""
    import yaml

    if profile is None:
        return None
    path = Path(profile) / "config.yaml"
    if not path.exists():
        return None
    data = yaml.safe_load(path.read_text()) or {}
    threads = (data.get("set-threads") or {}).get("mpm_run")
    return int(threads) if threads is not None else None


def make_plan(config: dict[str, Any], *, cores: int = 2, directory: str | Path = ".",
              calibration: Iterable[str | Path] | None = None, cluster: int = 8) -> Plan:
    """Project every MPM run of ``config``. ``calibration``: projection_check result files (default: those
    under ``directory``); the workflow's benchmark files under ``directory`` are read too."""
    from plough.mpm.scene import Scene
    from plough.study import cost, matrix

    directory = Path(directory)
    threads = int(config["mpm"]["threads"])
    params = matrix.all_runs(config)
    scenes = {rid: Scene.from_dict(s) for rid, s in params.items()}
    files = [Path(f) for f in calibration] if calibration is not None else sorted(directory.glob(CALIBRATION_FILES))
    measured = measured_from_json(files) + measured_from_benchmarks(directory, scenes, threads)
    rates = Rates.from_measured(measured, threads)
    runs = {}
    for rid, scene in scenes.items():
        c = cost.estimate(scene)
        family = family_of(scene)
        h = round(scene.discretisation.particle_size_m * 1e6, 6)
        here = c.particle_steps / rates.rate(family, h)
        runs[rid] = RunPlan(rid, family, h, c.particle_steps, c.memory_mb, here, here * threads / cluster,
                            cost.runtime_minutes(c, cluster))
    figures = {fig: [r for r in matrix.figure_runs(config, fig) if r in runs] for fig in ALL_FIGURES}
    tolerance = config["mpm"].get("skip_finest_tolerance")
    return Plan(config, threads, cores, cluster, rates, measured, runs, figures,
                decisions(directory, matrix.skippable_runs(config), tolerance),
                made_runs(directory, params))


def made_runs(directory: Path, runs: Mapping[str, Mapping[str, Any]], solver: str | None = None) -> frozenset[str]:
    """The runs of ``runs`` (run id -> scene, as the workflow's params) whose result file under ``directory``
    (``results/runs/<run>.nc``, a failure marker included) records this scene and ``solver`` (default: the
    solver being run), read as the workflow reads run files (:func:`plough.study.runfiles.check_run`). Any other
    file is redone, and so is a skip marker of an older workflow (the figures' datasets refuse them). Not
    recorded in the files, so not checked: the run script's own code, whose change also reruns every run."""
    import xarray as xr

    from plough.fingerprint import solver_fingerprint
    from plough.study.runfiles import check_run
    from plough.study.skipping import is_skipped

    solver = solver_fingerprint() if solver is None else solver
    done: set[str] = set()
    for rid, scene in runs.items():
        path = directory / "results" / "runs" / f"{rid}.nc"
        if not path.exists():
            continue
        try:
            with xr.open_dataset(path, engine="netcdf4") as ds:
                check_run(ds, path, rid, scene, solver)
                if is_skipped(ds):
                    continue
        except (OSError, ValueError):  # unreadable, or another run's (RunFileError): the workflow redoes it
            continue
        done.add(rid)
    return frozenset(done)


def decisions(directory: Path, gated: Mapping[str, tuple[str, str]],
              tolerance: Any = None) -> dict[str, bool | None]:
    """gated finest run -> its refinement decision under ``directory`` (``results/refinement/<run>.json``:
    True needed, False not), None where none is made, it cannot be read, or it was made from other coarser
    runs or under another tolerance than ``tolerance`` (``mpm.skip_finest_tolerance``; the workflow redoes
    such a decision before it counts)."""
    from plough.study.skipping import tolerances

    wanted = tolerances(tolerance) if tolerance is not None else None
    out: dict[str, bool | None] = {}
    for rid, coarser in gated.items():
        path = directory / DECISIONS / f"{rid}.json"
        try:
            made = json.loads(path.read_text())
            current = list(made["coarser_runs"]) == list(coarser) and (wanted is None or made["tolerance"] == wanted)
            out[rid] = bool(made["run_finest"]) if current else None
        except (OSError, ValueError, KeyError, TypeError):
            out[rid] = None
    return out


def _hours(seconds: float) -> str:
    if seconds < 90:
        return f"{seconds:.0f} s"
    if seconds < 5400:
        return f"{seconds / 60:.0f} min"
    return f"{seconds / 3600:.1f} h"


def describe(plan: Plan, *, points: bool = False) -> str:
    """The plan as text: the ladder, the calibration, a table per figure and the totals, the cluster."""
    from plough.study import matrix

    mpm = plan.config["mpm"]
    ladder = mpm.get("ladder", matrix.LADDER_DEFAULT)
    lines = []
    sizes = ", ".join(f"{h:g}" for h in matrix.particle_sizes_um(plan.config))
    if ladder == "relative":
        targets = ", ".join(f"{k} {v:g}" for k, v in mpm["ladder_targets"].items() if v is not None)
        finest, *half = matrix.ladder_bases_um(plan.config)
        scales = " or ".join(["2^k", *(f"{h / finest:g} x 2^k" for h in half)])
        finests = " or ".join(f"{h:g}" for h in (finest, *half))
        lines.append(f"ladder: relative (each point's sizes: {sizes} um times {scales}, a finest size of {finests} um "
                     f"x 2^k; targets at its finest size: {targets})")
    else:
        lines.append(f"ladder: paper ({sizes} um for every point)")
    sources = sorted({r.source for r in plan.measured})
    used = sum(n for by_h in plan.rates.by_family.values() for n, _ in by_h.values())
    left_out = len({r.run for r in plan.measured}) - used
    lines.append(f"calibration: {used} measured workflow jobs"
                 + (f" ({'; '.join(_short(s) for s in _sources(sources))})" if sources else "")
                 + (f"; {left_out} more at other threads left out where jobs at {_threads(plan.threads)} were "
                    "measured" if left_out else ""))
    for fam in FAMILIES:
        by_h = plan.rates.by_family.get(fam)
        if by_h:
            text = ", ".join(f"h = {h:g} um {rate / 1e6:.2f} M/s ({n} jobs)" for h, (n, rate) in sorted(by_h.items()))
        else:
            text = f"none measured: {plan.rates.rate(fam, 1.0) / 1e6:.2f} M/s (plough.study.cost.THROUGHPUT_PER_THREAD)"
        lines.append(f"  {fam}, particle-steps per second of a job at {_threads(plan.threads)}: {text}")
    if plan.rates.scaled:
        # linear in the threads: conservative for fewer threads a run (two one-thread runs at once measured 1.31x
        # the throughput of one two-thread run here: docs/performance.md, "Two runs at once")
        where = "; ".join(f"{fam} h = {h:g} um" for fam, h in sorted(plan.rates.scaled))
        lines.append(f"  (scaled linearly to {_threads(plan.threads)} a run from jobs at other threads, no job at "
                     f"{_threads(plan.threads)} there: {where})")
    lines.append("")
    lines.append(f"| figure | MPM runs | particle-steps | here (--cores {plan.cores}, {_threads(plan.threads)} "
                 f"a run) | longest job here | longest job on the cluster ({plan.cluster_threads} threads) |")
    lines.append("|---|---|---|---|---|---|")
    for fig, rids in plan.figures.items():
        if not rids:
            lines.append(f"| {fig} | 0 | | seconds (analytical) | | |")
            continue
        longest = max(rids, key=lambda r: plan.runs[r].here_s)
        lines.append(f"| {fig} | {len(rids)} | {sum(plan.runs[r].particle_steps for r in rids):.3g} | "
                     f"{_hours(plan.wall_s(rids))} | {_hours(plan.runs[longest].here_s)} | "
                     f"{_hours(plan.runs[longest].cluster_s)} |")
    every = list(plan.runs)
    total_ps = sum(r.particle_steps for r in plan.runs.values())
    longest = max(plan.runs.values(), key=lambda r: r.here_s, default=None)
    lines.append(f"| **all** (each run once) | {len(every)} | {total_ps:.3g} | **{_hours(plan.wall_s(every))}** | "
                 f"{_hours(longest.here_s) if longest else ''} | {_hours(longest.cluster_s) if longest else ''} |")
    lines.append("")
    for fam in FAMILIES:
        fam_runs = [r for r in plan.runs.values() if r.family == fam]
        if fam_runs:
            lines.append(f"{fam}: {len(fam_runs)} runs, {sum(r.particle_steps for r in fam_runs):.3g} particle-steps, "
                         f"{_hours(sum(r.here_s for r in fam_runs))} of jobs here")
    by_size: dict[float, list[RunPlan]] = {}
    for r in plan.runs.values():
        by_size.setdefault(r.h_um, []).append(r)
    lines.append("by particle size: " + "; ".join(
        f"h = {h:g} um: {len(rs)} runs, {sum(r.particle_steps for r in rs):.3g} particle-steps, "
        f"{_hours(sum(r.here_s for r in rs))}" for h, rs in sorted(by_size.items(), reverse=True)))
    if plan.gated:
        lines.append(_refinement(plan))
    if plan.done:
        lines.append(_left(plan))
    if longest is not None:
        core_h = sum(r.cluster_s for r in plan.runs.values()) * plan.cluster_threads / 3600
        requested = sum(r.request_min for r in plan.runs.values()) * plan.cluster_threads / 60
        biggest = max(plan.runs.values(), key=lambda r: r.memory_mb)
        lines.append(f"on a cluster, one job a run at {plan.cluster_threads} threads: {len(every)} jobs, the longest "
                     f"{longest.run} {_hours(longest.cluster_s)} (scaled linearly from here; its request "
                     f"{longest.request_min} min); {core_h:.0f} core-hours projected, {requested:.0f} core-hours "
                     f"requested; the largest memory request {biggest.memory_mb / 1000:.1f} GB ({biggest.run})")
    if points:
        lines.append("")
        lines.append("| point | sizes (um) | set by | a / h | dp / h | t / h | here |")
        lines.append("|---|---|---|---|---|---|---|")
        for p in matrix.all_points(plan.config).values():
            lad = matrix.point_ladder(plan.config, p)
            q = lad.particles()
            rids = [matrix.run_id(p, h) for h in lad.sizes_um if matrix.run_id(p, h) in plan.runs]
            t = q["coating_particles"]
            lines.append(f"| {p.key} | {', '.join(f'{h:g}' for h in lad.sizes_um)} | {lad.set_by} | "
                         f"{q['contact_radius_particles']:.1f} | {q['groove_depth_particles']:.2f} | "
                         f"{'' if t is None else f'{t:.2f}'} | {_hours(sum(plan.runs[r].here_s for r in rids))} |")
    return "\n".join(lines)


def _refinement(plan: Plan) -> str:
    """The range refinement only where needed leaves: every undecided gated finest run made, or none."""
    states = list(plan.gated.values())
    n_need, n_skip, n_open = states.count(True), states.count(False), states.count(None)
    every = list(plan.runs)
    high, low = plan.made(every, undecided=True), plan.made(every, undecided=False)
    from plough.study.skipping import tolerances

    tol = ", ".join(f"{o} {t:g}" for o, t in tolerances(plan.config["mpm"]["skip_finest_tolerance"]).items())
    text = (f"refinement only where needed (skip_finest_tolerance: {tol}): {len(states)} gated finest runs "
            f"({n_need} decided needed, {n_skip} decided not, {n_open} undecided): ")
    if not n_open:  # every decision made: one number, not a range
        return text + _amount(plan, low, bold=True, particle_steps=True)
    return (text + "between " + _amount(plan, low, "every undecided one skipped", bold=True, particle_steps=True)
            + " and " + _amount(plan, high, "every undecided one made", particle_steps=True) + _expected(plan, every))


def _left(plan: Plan) -> str:
    """What is left of the workflow where some runs are made: its range and, once decisions are made, the
    expected time."""
    left = [r for r in plan.runs if r not in plan.done]
    text = f"made already (results/runs, this solver): {len(plan.done)} of {len(plan.runs)} runs; left: "
    high, low = plan.made(left, undecided=True), plan.made(left, undecided=False)
    if not high:  # what is left, if anything, is decided not needed
        return text + "no run (the datasets and figures, minutes)"
    if not plan.undecided(left):
        return text + _amount(plan, low, bold=True)
    text += ("between " + _amount(plan, low, "every undecided gated finest run skipped", bold=True) + " and "
             + _amount(plan, high, "every one made"))
    return text + _expected(plan, left)


def _amount(plan: Plan, runs: list[str], note: str = "", *, bold: bool = False,
            particle_steps: bool = False) -> str:
    """``runs``' wall time here with their count (and particle-steps, and a note) in brackets: "**3.1 h** (12
    runs, 4.5e+10 particle-steps; every one made)"."""
    hours = f"**{_hours(plan.wall_s(runs))}**" if bold else _hours(plan.wall_s(runs))
    what = f"{len(runs)} runs"
    if particle_steps:
        what += f", {sum(plan.runs[r].particle_steps for r in runs):.3g} particle-steps"
    return f"{hours} ({what}{'; ' + note if note else ''})"


def _expected(plan: Plan, runs: list[str]) -> str:
    """The expected wall time of ``runs`` as a clause, once refinement decisions are made and while some run
    of ``runs`` is undecided; else nothing."""
    expected = plan.expected_wall_s(runs)
    if expected is None or not plan.undecided(runs):
        return ""
    decided = plan.decided
    return (f"; expected **{_hours(expected)}**, each undecided one counted at the share of the decisions made "
            f"that needed their finest run ({sum(decided)} of {len(decided)})")


def _sources(sources: list[str]) -> list[str]:
    """The calibration files, and the benchmark files as one entry (their folder)."""
    files = [s for s in sources if not s.endswith(".tsv")]
    tsv = [s for s in sources if s.endswith(".tsv")]
    return files + ([f"{len(tsv)} files in {Path(tsv[0]).parent}"] if tsv else [])


def _threads(n: int) -> str:
    return f"{n} thread" + ("s" if n != 1 else "")


def _short(path: str) -> str:
    try:
        return str(Path(path).resolve().relative_to(Path.cwd().resolve()))
    except ValueError:
        return path


def add_arguments(p: argparse.ArgumentParser) -> None:
    p.add_argument("--configfile", nargs="+", default=[], metavar="FILE",
                   help="config files merged into config/config.yaml key by key, as snakemake's --configfile")
    p.add_argument("--cores", type=int, default=2, help="cores snakemake is given here (default 2)")
    p.add_argument("--directory", default=".", help="the workflow's directory (default: the current one)")
    p.add_argument("--profile", default="profiles/slurm",
                   help="the cluster profile whose set-threads: mpm_run gives a job's threads (default "
                   "profiles/slurm; 8 if it has none)")
    p.add_argument("--calibration", nargs="*", default=None, metavar="FILE",
                   help=f"projection_check.py results to calibrate with (default: {CALIBRATION_FILES})")
    p.add_argument("--points", action="store_true", help="also each point's sizes and resolution")


def run_plan(args: argparse.Namespace) -> int:
    if args.cores < 1:
        raise ValueError(f"--cores = {args.cores} must be >= 1")
    directory = Path(args.directory)
    config = load_config(args.configfile, directory)
    profile = Path(args.profile) if Path(args.profile).is_absolute() else directory / args.profile
    threads = cluster_threads(profile) or 8
    plan = make_plan(config, cores=args.cores, directory=directory, calibration=args.calibration, cluster=threads)
    names = ", ".join([BASE_CONFIG, *args.configfile])
    print(f"plough plan: {names}; {len(plan.runs)} MPM runs; projected before anything runs")
    print(describe(plan, points=args.points))
    return 0
