"""How the main command's projected wall time here depends on the refinement tolerance, from the 64 decisions
the second measurement made (their two-size relative uncertainties of mu and dp) and `plough plan`'s projection
in the run's directory (calibrated by its measured jobs).

    PYTHONPATH=src python tolerance_vs_time.py RUN_DIR REPO
"""
import json
import sys
from pathlib import Path

from plough.study.plan import load_config, make_plan

run_dir, repo = Path(sys.argv[1]), Path(sys.argv[2])
plan = make_plan(load_config([], repo), cores=2, directory=run_dir)
rel = {}
for rid in plan.gated:
    d = json.loads((run_dir / "results" / "refinement" / f"{rid}.json").read_text())
    ex = d["extrapolations"]
    rel[rid] = (ex["mu"]["relative_uncertainty"], ex["dp"]["relative_uncertainty"])
ungated = [r for r in plan.runs if r not in plan.gated]
gated_s = sum(plan.runs[r].here_s for r in plan.gated)
print(f"{len(ungated)} runs always made: {plan.wall_s(ungated) / 3600:.2f} h with two at once; "
      f"the {len(plan.gated)} gated finest runs {gated_s / 2 / 3600:.2f} h more if all are made")
print("| mu tolerance | dp tolerance | finest runs made | wall here (h) |")
print("|---|---|---|---|")
for tmu in (0.05, 0.1, 0.2, 0.3, 0.5, 1.0):
    for tdp in (0.3, None):
        made = [r for r, (m, d) in rel.items()
                if not (m is not None and m <= tmu and (tdp is None or (d is not None and d <= tdp)))]
        print(f"| {tmu:g} | {'-' if tdp is None else f'{tdp:g}'} | {len(made)} | "
              f"{plan.wall_s(ungated + made) / 3600:.2f} |")
print("finest runs by projected time here (min), mu and dp two-size relative uncertainty:")
for r in sorted(plan.gated, key=lambda r: -plan.runs[r].here_s)[:15]:
    m, d = rel[r]
    print(f"  {plan.runs[r].here_s / 60:6.1f}  {r}  mu {m:.3g}  dp {d if d is None else f'{d:.3g}'}")
