"""Projected time of the full reproduction (`snakemake --cores 2`) from per-run costs.

    python benchmarks/reproduction_time.py [--config config/config.yaml]

Counts the particles and steps of every MPM run of the config (plough.study.cost, within a few
per cent of the solver's counts) and divides by the particle-steps per second measured on the
reference scene at 2 threads (benchmarks/results/mpm_reference_sized.json, the slowest of its sizes).
The total is their sum at that throughput, one two-thread run at a time (the workflow makes two one-thread runs
at once, 1.1-1.3x faster: docs/performance.md, "Two runs at once"; not counted here).
Also projected: the lower bound with `mpm.skip_finest_tolerance` set, when every finest-size sweep
run is skipped (the pictures' finest runs always run); how many are skipped depends on the results.
With ``numerics.graded`` on, the particle counts are the graded ones and the throughput is scaled
by the graded runs' particle-steps per second over the uniform runs' at the same scene and size
(median over docs/journal/2026-11-22-graded-particles/graded_particles.json, fine zone as
configured): a graded run has fewer particles on the same grid, so the grid's share of a step grows.
With ``numerics.active_zone_contact_radii`` set, each run's particle-steps are those its active
zone works on (plough.study.cost), and the throughput is scaled by the zoned runs' particle-steps
worked on per second over the same scenes' runs without a zone (median over
docs/journal/2026-11-23-active-zone/active_zone.json, zone as configured).
Runs whose layers use the real materials' flow laws (hardening, rate terms, heating: Figs. 14-23)
go at the real-materials' share of the constant-flow throughput measured on the same block
(docs/journal/2026-11-23-flow-law-cost/material_cost.json, measured by the retired
``benchmarks/material_cost.py``); the rigid-plastic runs at the reference throughput.
With ``--calibration FILE ...`` (``benchmarks/projection_check.py`` results: workflow runs that were made,
their job wall times beside the projection) the projection is also scaled per family (rigid-plastic, real
materials) by measured / projected over that family's measured runs at the particle size nearest in
log h (job time, start-up and writing included; the projection recomputed with today's throughput model
from each run's particle-steps): the calibrated total says what the measured runs say of the rest.
Last, the floor no code can beat on this machine: the particle-steps of the matrix (all, and with
every skippable finest run skipped) at the memory-bandwidth bound of a step (bytes a particle-step
moves, from a kernel profile, over the triad bandwidth: benchmarks/kernel_profile.py), and the
throughput each would need to finish within the issue's 4 hours.
Writes benchmarks/results/reproduction_time.json and prints a Markdown table.
"""

from __future__ import annotations

import argparse
import copy
import json
import math
import statistics
from pathlib import Path

import yaml

from plough.materials import ConstantFlow
from plough.mpm.scene import Scene
from plough.study import cost, matrix
from plough.study.plan import calibrating, measured_from_json

ROOT = Path(__file__).resolve().parents[1]


def graded_throughput_ratio(path: Path, k: float) -> float:
    """Median over scenes and sizes of (particle-steps/s of the graded run) / (of the uniform run)."""
    runs = json.loads(path.read_text())["runs"]
    ratios = []
    for sizes in runs.values():
        for variants in sizes.values():
            graded, uniform = variants.get(f"graded k={k:g}"), variants.get("uniform")
            if graded and uniform:
                rate = [r["particles"] * r["steps"] / r["wall_s"] for r in (graded, uniform)]
                ratios.append(rate[0] / rate[1])
    if not ratios:
        raise SystemExit(f"{path} has no graded run with fine_zone_contact_radii = {k:g} (the file of "
                         "docs/journal/2026-11-22-graded-particles.md has 1.5 and 1)")
    return statistics.median(ratios)


def zone_throughput_ratio(path: Path, k: float) -> float:
    """Median over scenes and sizes of (particle-steps worked on per second with zone k) / (without a zone)."""
    runs = json.loads(path.read_text())["runs"]
    ratios = [rows[f"zone {k:g}"]["active_fraction"] * rows["all"]["wall_s"] / rows[f"zone {k:g}"]["wall_s"]
              for rows in runs.values() if f"zone {k:g}" in rows and "all" in rows]
    if not ratios:
        raise SystemExit(f"{path} has no run with active_zone_contact_radii = {k:g} (the file of "
                         "docs/journal/2026-11-23-active-zone.md has 3, 4 and 6)")
    return statistics.median(ratios)


def add_measured_arguments(parser: argparse.ArgumentParser) -> None:
    """The measured results files the throughput model reads (shared with projection_check.py)."""
    parser.add_argument("--measured", default=str(ROOT / "benchmarks" / "results" / "mpm_reference_sized.json"))
    parser.add_argument("--graded-measured", default=str(ROOT / "docs" / "journal" / "2026-11-22-graded-particles"
                                                         / "graded_particles.json"))
    parser.add_argument("--zone-measured", default=str(ROOT / "docs" / "journal" / "2026-11-23-active-zone"
                                                       / "active_zone.json"))
    parser.add_argument("--material-measured", default=str(ROOT / "docs" / "journal" / "2026-11-23-flow-law-cost"
                                                           / "material_cost.json"))


def throughput_model(config: dict, args: argparse.Namespace) -> tuple[float, float, float, float]:
    """(rigid-plastic particle-steps per second, graded factor, active-zone factor, real-material factor):
    the slowest reference run's throughput times the graded and zone factors the config's numerics call
    for; a real-material run goes at the first value times the last."""
    measured = json.loads(Path(args.measured).read_text())
    throughput = min(r["particle_steps_per_s"] for r in measured["runs"])
    numerics = config["mpm"]["numerics"]
    graded_factor = 1.0
    if numerics.get("graded", False):
        k = float(numerics.get("fine_zone_contact_radii", 1.5))
        graded_factor = graded_throughput_ratio(Path(args.graded_measured), k)
        print(f"graded particles: throughput x {graded_factor:.3f} (graded over uniform, {args.graded_measured})")
        throughput *= graded_factor
    zone_factor = 1.0
    if numerics.get("active_zone_contact_radii") is not None:
        zone_factor = zone_throughput_ratio(Path(args.zone_measured), float(numerics["active_zone_contact_radii"]))
        print(f"active zone: throughput x {zone_factor:.3f} (particle-steps worked on per second, zoned over "
              f"every particle, {args.zone_measured})")
        throughput *= zone_factor
    material_factor = json.loads(Path(args.material_measured).read_text())["real_over_constant_throughput"]
    print(f"real materials: throughput x {material_factor:.3f} (real over constant flow stresses on the same block, "
          f"{args.material_measured})")
    return throughput, graded_factor, zone_factor, material_factor


def calibration_ratios(paths: list[str], throughput: float, material_factor: float
                       ) -> dict[str, dict[float, tuple[int, float]]]:
    """family -> h (um) -> (runs, sum of measured job seconds / sum of projected seconds) over the
    ``projection_check.py`` files' rows, read and picked as ``plough plan`` picks them (``plough.study.plan.
    measured_from_json`` and ``calibrating``: each at the threads it records, a run once, its last measurement
    at 2 threads else its last, only the jobs at the projection's 2 threads where a size has them); a job at
    other threads is scaled linearly to 2."""
    rows = [m for path in paths for m in measured_from_json([Path(path)])]
    groups, _ = calibrating(rows, 2)
    out: dict[str, dict[float, tuple[int, float]]] = {}
    for (family, h), used in groups.items():
        rate = throughput * (material_factor if family == "real materials" else 1.0)
        measured = sum(r.seconds * r.threads / 2 for r in used)
        projected = sum(r.particle_steps / rate for r in used)
        out.setdefault(family, {})[h] = (len(used), measured / projected)
    return out


def calibration_for(ratios: dict[str, dict[float, tuple[int, float]]], family: str, h_um: float) -> float:
    """The measured / projected ratio for a run of ``family`` at ``h_um``: that of the measured size nearest
    in log h; 1 where the family has no measured run."""
    by_h = ratios.get(family)
    if not by_h:
        return 1.0
    return by_h[min(by_h, key=lambda h: (abs(math.log(h / h_um)), h))][1]


def is_real_material(scene: Scene) -> bool:
    """A run whose layers use the real materials' flow laws (not constant flow stresses)."""
    return not all(isinstance(m.flow, ConstantFlow) for m in scene.layers.materials)


def project_run(scene: Scene, throughput: float, material_factor: float) -> tuple[cost.RunCost, bool, float]:
    """(the run's counted cost, whether its materials are real, its projected wall time in s)."""
    c = cost.estimate(scene)
    real = is_real_material(scene)
    return c, real, c.particle_steps / (throughput * (material_factor if real else 1.0))


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--config", default=str(ROOT / "config" / "config.yaml"))
    add_measured_arguments(parser)
    parser.add_argument("--bandwidth-measured",
                        default=str(ROOT / "benchmarks" / "results" / "kernel_profile_zinc_coated_steel_h10.json"),
                        help="kernel profile whose bytes per particle-step and triad bandwidth give the bound")
    parser.add_argument("--target-h", type=float, default=4.0, help="wall-time target of the full reproduction, h")
    parser.add_argument("--calibration", nargs="*", default=[],
                        help="projection_check.py results whose measured runs scale the projection per family")
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "reproduction_time.json"))
    args = parser.parse_args()
    config = yaml.safe_load(Path(args.config).read_text())
    numerics = config["mpm"]["numerics"]
    throughput, graded_factor, zone_factor, material_factor = throughput_model(config, args)
    by_size: dict[float, dict[str, float]] = {}
    with_skip = copy.deepcopy(config)
    with_skip["mpm"]["skip_finest_tolerance"] = 0.05
    skippable = matrix.skippable_runs(with_skip)
    skippable_s = 0.0
    skippable_ps = 0.0
    ratios = calibration_ratios(args.calibration, throughput, material_factor) if args.calibration else {}
    calibrated: dict[str, float] = {}  # family -> calibrated seconds
    calibrated_skippable_s = 0.0
    by_family = {"rigid-plastic": {"runs": 0, "particle_steps": 0.0, "projected_s": 0.0},
                 "real materials": {"runs": 0, "particle_steps": 0.0, "projected_s": 0.0}}
    for rid, scene_dict in matrix.all_runs(config).items():
        scene = Scene.from_dict(scene_dict)
        c, real, seconds = project_run(scene, throughput, material_factor)
        family = "real materials" if real else "rigid-plastic"
        h = round(scene.discretisation.particle_size_m * 1e6, 6)
        scaled = seconds * calibration_for(ratios, family, h)
        calibrated[family] = calibrated.get(family, 0.0) + scaled
        if rid in skippable:
            skippable_s += seconds
            skippable_ps += c.particle_steps
            calibrated_skippable_s += scaled
        row = by_size.setdefault(h, {"runs": 0, "particle_steps": 0.0, "largest_run_particles": 0, "projected_s": 0.0})
        row["runs"] += 1
        row["particle_steps"] += c.particle_steps
        row["projected_s"] += seconds
        row["largest_run_particles"] = max(row["largest_run_particles"], c.particles)
        fam = by_family[family]
        fam["runs"] += 1
        fam["particle_steps"] += c.particle_steps
        fam["projected_s"] += seconds
    print(f"throughput used: {throughput / 1e6:.2f} M particle-steps/s for rigid-plastic runs, "
          f"{throughput * material_factor / 1e6:.2f} M for real-material runs (measured, 2 threads)\n")
    print("| h (um) | runs | particle-steps | largest run (particles) | projected wall time |")
    print("|---|---|---|---|---|")
    total = 0.0
    for h in sorted(by_size, reverse=True):
        row = by_size[h]
        total += row["projected_s"]
        print(f"| {h:g} | {row['runs']} | {row['particle_steps']:.3g} | {row['largest_run_particles']:,} | "
              f"{row['projected_s'] / 3600:.1f} h |")
    print(f"| all | {sum(r['runs'] for r in by_size.values())} | | | {total / 3600:.1f} h ({total / 86400:.1f} days) |")
    print(f"\nwith skip_finest_tolerance, if all {len(skippable)} skippable finest runs are skipped: "
          f"{(total - skippable_s) / 3600:.1f} h (lower bound)")
    for name, fam in by_family.items():
        print(f"{name}: {fam['runs']} runs, {fam['particle_steps']:.3g} particle-steps, "
              f"{fam['projected_s'] / 3600:.1f} h")
    calibration = None
    if ratios:
        cal_total = sum(calibrated.values())
        print("\ncalibrated by the measured workflow runs (measured / projected, job time, by family and size):")
        for fam, by_h in sorted(ratios.items()):
            print(f"  {fam}: " + ", ".join(f"h = {h:g} um {r:.2f} ({n} runs)" for h, (n, r) in sorted(by_h.items())))
        for fam, sec in sorted(calibrated.items()):
            print(f"  {fam}: {sec / 3600:.1f} h calibrated")
        print(f"calibrated total: {cal_total / 3600:.1f} h ({cal_total / 86400:.1f} days); lower bound with every "
              f"skippable finest run skipped {(cal_total - calibrated_skippable_s) / 3600:.1f} h")
        calibration = {"files": args.calibration,
                       "ratios": {fam: {f"{h:g}": {"runs": n, "measured_over_projected": r}
                                        for h, (n, r) in sorted(by_h.items())} for fam, by_h in ratios.items()},
                       "rule": "each run scaled by its family's ratio at the measured size nearest in log h",
                       "by_family_s": calibrated, "total_s": cal_total,
                       "lower_bound_all_skipped_s": cal_total - calibrated_skippable_s}
    bound = json.loads(Path(args.bandwidth_measured).read_text())["bandwidth_bound_particle_steps_per_s"]
    target_s = args.target_h * 3600.0
    all_ps = sum(r["particle_steps"] for r in by_size.values())
    floor = {}
    for name, ps in (("every run", all_ps), ("every skippable finest run skipped", all_ps - skippable_ps)):
        floor[name] = {"particle_steps": ps, "at_bandwidth_bound_s": ps / bound,
                       "throughput_needed_for_target": ps / target_s}
        print(f"{name}: {ps:.3g} particle-steps; at the bandwidth bound ({bound / 1e6:.1f} M/s) "
              f"{ps / bound / 3600:.1f} h; within {args.target_h:g} h it needs {ps / target_s / 1e6:.1f} M "
              f"particle-steps/s ({ps / target_s / bound:.0%} of the bound, {ps / target_s / throughput:.1f}x "
              "the rigid-plastic throughput used above)")
    out = {"config": args.config, "throughput_particle_steps_per_s": throughput,
           "graded_throughput_factor": graded_factor, "active_zone_throughput_factor": zone_factor,
           "real_material_throughput_factor": material_factor, "by_family": by_family,
           "active_zone_contact_radii": numerics.get("active_zone_contact_radii"),
           "graded": bool(numerics.get("graded", False)), "by_size_um": by_size,
           "total_projected_s": total, "skippable_runs": len(skippable),
           "lower_bound_all_skipped_s": total - skippable_s,
           "bandwidth_bound_particle_steps_per_s": bound, "bandwidth_measured": args.bandwidth_measured,
           "target_s": target_s, "floor": floor, "calibrated": calibration}
    Path(args.out).write_text(json.dumps(out, indent=2) + "\n")


if __name__ == "__main__":
    main()
