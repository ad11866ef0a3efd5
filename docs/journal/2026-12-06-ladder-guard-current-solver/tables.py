"""The journal's tables from a ladder_guard.py result: each point's runs, then both ladders' h -> 0 limits.

    python docs/journal/2026-12-06-ladder-guard-current-solver/tables.py benchmarks/results/ladder_guard.json
"""

from __future__ import annotations

import json
import sys
from pathlib import Path


def fmt(x: float | None, scale: float = 1.0, digits: int = 4) -> str:
    return "-" if x is None else f"{x * scale:.{digits}g}"


def main(path: Path) -> None:
    data = json.loads(path.read_text())
    prov = data["provenance"]
    print(f"tree {prov['git_commit'][:7]}, solver fingerprint {prov.get('solver_fingerprint', 'not recorded')}\n")
    for p in data["points"]:
        print(f"### {p['point']}\n")
        print("| run | mu (SE) | mu_pl | mu_sh | dp (um) | steady | wall (s) |")
        print("|---|---|---|---|---|---|---|")
        for rid, v in p["run_values"].items():
            print(f"| {rid.rsplit('_', 1)[1]} | {fmt(v['mu'])} ({fmt(v['mu_standard_error'], digits=2)}) | "
                  f"{fmt(v['mu_pl'])} | {fmt(v['mu_sh'])} | {fmt(v['dp'], 1e6, 3)} | {v['steady']} | "
                  f"{fmt(v['wall_time_s'], digits=4)} |")
        print()
        limits = [("every size", p["relative"]["limit"], p["verdicts"])]
        if "limit_as_shown" in p["relative"]:
            limits.append(("as the default workflow shows it", p["relative"]["limit_as_shown"],
                           p["verdicts_as_shown"]))
        print("| output | relative | paper | agree | relative / paper uncertainty |")
        print("|---|---|---|---|---|")
        for label, rel, verdicts in limits:
            for out in ("mu", "mu_pl", "mu_sh", "dp"):
                r, q = rel[out], p["paper"]["limit"][out]
                scale = 1e6 if out == "dp" else 1.0
                print(f"| {out} ({label}) | {fmt(r['value'], scale)} ± {fmt(r['uncertainty'], scale, 2)} "
                      f"({r['method']}) | {fmt(q['value'], scale)} ± {fmt(q['uncertainty'], scale, 2)} ({q['method']}) "
                      f"| {'yes' if verdicts[out]['agree'] else 'NO'} | {r['uncertainty'] / q['uncertainty']:.2f}x |")
        print()


if __name__ == "__main__":
    main(Path(sys.argv[1]))
