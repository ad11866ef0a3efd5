"""``benchmarks/ladder_guard.py``'s verdicts in its result files judged again under today's GCI rule (one-off probe).

    PYTHONPATH=src python docs/journal/2026-12-07-gci-safety-factor/rejudge.py [--all] FILE.json ...

Each file is a ``ladder_guard.py`` output (its points' ``run_values``, each ladder's sizes and runs, the stored limits
and verdicts). Every limit is recomputed from the stored run values with ``ladder_guard.ladder_limits`` (so with
today's ``extrapolate``) and set beside the stored one; the verdicts (agreement within the combined bars, the first
ladder's bar no larger) with ``ladder_guard.verdicts``. Only limits whose bar moved are printed, or with ``--all``
every one; the last column is the first ladder's bar over the second's under today's rule.
"""

from __future__ import annotations

import argparse
import json
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "benchmarks"))

from ladder_guard import OUTPUTS, ladder_limits, verdicts  # noqa: E402


def fmt(lim: dict, o: str) -> str:
    """``value ± uncertainty (method)`` in the output's display unit (dp in µm)."""
    scale = 1e6 if o == "dp" else 1.0
    return f"{lim['value'] * scale:.4g} ± {lim['uncertainty'] * scale:.2g} ({lim['method']})"


def verdict(v: dict) -> str:
    ratio = "no larger" if v["relative_uncertainty_not_larger"] else "larger"
    return f"{'agree' if v['agree'] else 'DISAGREE'} ({abs(v['difference']) / v['combined_uncertainty']:.2f}), {ratio}"


def main(paths: list[Path], every: bool) -> None:
    """Print one row per limit (file, point, output): both ladders' limits and the verdict, stored and today."""
    print("| file | point | output | first ladder: stored / today | second: stored / today | verdict: stored / today "
          "| bar ratio today |")
    print("|---|---|---|---|---|---|---|")
    for path in paths:
        for entry in json.loads(path.read_text())["points"]:
            if "verdicts" not in entry:
                continue
            today = {}
            for name in ("relative", "paper"):
                lad = entry[name]
                today[name] = ladder_limits(tuple(lad["sizes_um"]), lad["runs"], entry["run_values"],
                                            lad.get("finest_failed", False))
            checks = verdicts(today["relative"], today["paper"])
            for o in OUTPUTS:
                stored = [entry[n]["limit"][o] for n in ("relative", "paper")]
                new = [today[n][o] for n in ("relative", "paper")]
                if not every and all(abs(s["uncertainty"] - t["uncertainty"]) <= 1e-12 * abs(s["uncertainty"])
                                     for s, t in zip(stored, new, strict=True)):
                    continue
                ratio = new[0]["uncertainty"] / new[1]["uncertainty"] if new[1]["uncertainty"] > 0 else float("inf")
                print(f"| {path.name} | {entry['point']} | {o} | {fmt(stored[0], o)} / {fmt(new[0], o)} | "
                      f"{fmt(stored[1], o)} / {fmt(new[1], o)} | {verdict(entry['verdicts'][o])} / "
                      f"{verdict(checks[o])} | {ratio:.2f}x |")


if __name__ == "__main__":
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("--all", action="store_true", help="every limit, not only those whose bar moved")
    parser.add_argument("files", type=Path, nargs="+")
    args = parser.parse_args()
    main(args.files, args.all)
