"""The runs left in a run directory that fit a part of the main command of a given length, as snakemake targets.

A part shorter than the runs left cuts the runs still going at its end (the second measurement's part 1 lost
37 min of two cores that way). This picks the runs to give snakemake as explicit targets so that none is cut: it
goes through the runs left (ungated, or gated and decided needed) in snakemake's own order (``mpm_run``'s
priority, the counted particle-steps, largest first) and keeps a run if the list schedule of the runs kept so far
plus this one, one run a core at a time in that order, still ends within the part at the projected times of
``plough plan``. Since each run kept comes after every run kept before it, the schedule snakemake will follow is
the one simulated here.

    PYTHONPATH=src python pack_targets.py RUN_DIR --minutes 45 [--cores 2] [--calibration FILE ...] \
        [--out targets.txt]
"""
import argparse
from pathlib import Path

from plough.study.plan import load_config, make_plan

p = argparse.ArgumentParser()
p.add_argument("run_dir", type=Path)
p.add_argument("--minutes", type=float, required=True, help="the part's length")
p.add_argument("--cores", type=int, default=2)
p.add_argument("--calibration", type=Path, nargs="+",
               default=sorted(Path("benchmarks/results").glob("projection_check_*.json")))
p.add_argument("--out", type=Path, help="write the targets here, one line")
a = p.parse_args()

config = load_config([], a.run_dir)
plan = make_plan(config, cores=a.cores, directory=a.run_dir, calibration=a.calibration)
left = [plan.runs[r] for r in plan.made((r for r in plan.runs if r not in plan.done), undecided=False)]
left.sort(key=lambda r: -r.particle_steps)  # mpm_run's priority (workflow/rules/common.smk)
budget_s = a.minutes * 60
cores = [0.0] * plan.parallel_jobs
kept = []
for r in left:
    i = min(range(len(cores)), key=cores.__getitem__)  # the next run starts on the core that frees first
    if cores[i] + r.here_s <= budget_s:
        cores[i] += r.here_s
        kept.append(r)
print(f"{len(left)} runs left, {sum(r.here_s for r in left) / 60:.1f} min of jobs; "
      f"{len(kept)} fit {a.minutes:g} min on {len(cores)} at once:")
for r in kept:
    print(f"  {r.here_s / 60:6.1f} min  {r.run}")
print("each at once: " + ", ".join(f"{c / 60:.1f} min" for c in cores))
if a.out:
    a.out.write_text(" ".join(f"results/runs/{r.run}.nc" for r in kept) + "\n")
