"""The refinement decisions of a run directory: how many need their finest run, and the two-size relative
uncertainties of mu and dp they rest on.

    python decisions.py RUN_DIR
"""
import json
import statistics
import sys
from pathlib import Path

decisions = [json.loads(f.read_text()) for f in sorted((Path(sys.argv[1]) / "results" / "refinement").glob("*.json"))]
print(f"{len(decisions)} decisions, {sum(d['run_finest'] for d in decisions)} need their finest run")
for d in decisions:
    if not d["run_finest"]:
        print("  not needed:", d["finest_run"])
for output, tolerance in (("mu", 0.05), ("dp", 0.3)):
    rel = [d["extrapolations"][output]["relative_uncertainty"] for d in decisions]
    q1, median, q3 = statistics.quantiles(rel, n=4)
    print(f"{output}: two-size relative uncertainty median {median:.3f} (quartiles {q1:.3f}, {q3:.3f}); "
          f"{sum(r <= tolerance for r in rel)} of {len(rel)} within {tolerance:g}")
