"""How the main command's projected wall time here depends on the refinement tolerance, from the 64 decisions
the second measurement made (their two-size relative uncertainties of mu and dp) and `plough plan`'s projection
in the run's directory (calibrated by its measured jobs). A finest run is skipped as the workflow skips it
(plough.study.skipping.should_skip); "-" for dp: mu alone decides.

    PYTHONPATH=src python tolerance_vs_time.py RUN_DIR REPO
"""
import json
import math
import sys
from pathlib import Path

from plough.study.plan import DECISIONS, load_config, make_plan
from plough.study.skipping import should_skip

run_dir, repo = Path(sys.argv[1]), Path(sys.argv[2])
plan = make_plan(load_config([], repo), cores=2, directory=run_dir)
extrapolations = {}
for rid in plan.gated:
    made = json.loads((run_dir / DECISIONS / f"{rid}.json").read_text())["extrapolations"]
    for e in made.values():  # a decision writes null where an output had no uncertainty: never within tolerance
        e["relative_uncertainty"] = math.nan if e["relative_uncertainty"] is None else e["relative_uncertainty"]
    extrapolations[rid] = made
ungated = [r for r in plan.runs if r not in plan.gated]
gated_s = sum(plan.runs[r].here_s for r in plan.gated)
print(f"{len(ungated)} runs always made: {plan.wall_s(ungated) / 3600:.2f} h with two at once; "
      f"the {len(plan.gated)} gated finest runs {gated_s / plan.parallel_jobs / 3600:.2f} h more if all are made")
print("| mu tolerance | dp tolerance | finest runs made | wall here (h) |")
print("|---|---|---|---|")
for tmu in (0.05, 0.1, 0.2, 0.3, 0.5, 1.0):
    for tdp in (0.3, None):
        checked = ("mu", "dp") if tdp is not None else ("mu",)
        made = [r for r, ex in extrapolations.items()
                if not should_skip({o: ex[o] for o in checked}, {"mu": tmu, "dp": tdp or 1.0})]
        print(f"| {tmu:g} | {'-' if tdp is None else f'{tdp:g}'} | {len(made)} | "
              f"{plan.wall_s(ungated + made) / 3600:.2f} |")
print("finest runs by projected time here (min), mu and dp two-size relative uncertainty:")
for r in sorted(plan.gated, key=lambda r: -plan.runs[r].here_s)[:15]:
    ex = extrapolations[r]
    print(f"  {plan.runs[r].here_s / 60:6.1f}  {r}  mu {ex['mu']['relative_uncertainty']:.3g}  "
          f"dp {ex['dp']['relative_uncertainty']:.3g}")
