"""The zinc block at 11 N: mu's h -> 0 limit over every three-size ladder its run files allow (one-off probe).

    python docs/journal/2026-12-06-ladder-guard-current-solver/other_ladders.py /work/guardrun

Reads the point's run files (28, 20, 14, 10, 7, 5, 3.5, 2.5 µm; the 20 µm one made with config/preview.yaml, the
3.5 µm one with contact20.yaml beside this file), each checked against its scene and this tree's solver, and
extrapolates mu as benchmarks/ladder_guard.py does (its ``limit``).
"""

from __future__ import annotations

import itertools
import sys
from pathlib import Path

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT / "src"))

from ladder_guard import limit  # noqa: E402

from plough.fingerprint import solver_fingerprint  # noqa: E402
from plough.study import matrix  # noqa: E402
from plough.study.plan import load_config  # noqa: E402
from plough.study.runfiles import load_run  # noqa: E402

KEY = "zinc_bulk_bl0.32-0.95_r500_F11"


def all_scenes() -> dict:
    """The scene of every run the configs that made the run files name (run id -> scene dict)."""
    scenes: dict = {}
    config = ROOT / "config"
    for files in ([config / "config.yaml"], [config / "paper.yaml"], [config / "preview.yaml"],
                  [config / "config.yaml", Path(__file__).parent / "contact20.yaml"]):
        scenes |= matrix.all_runs(load_config(files, ROOT))
    return scenes


def main(workdir: Path) -> None:
    scenes = all_scenes()
    solver = solver_fingerprint()
    runs = {}
    for rid, scene in scenes.items():
        path = workdir / "results" / "runs" / f"{rid}.nc"
        if rid.startswith(KEY + "_h") and path.exists():
            ds = load_run(path, rid, scene, solver)
            runs[float(rid.rsplit("_h", 1)[1])] = (float(ds["mu"]), float(ds["mu_standard_error"]),
                                                   float(ds.attrs["cost_wall_time_s"]))
    print(f"solver {solver}; runs (h um: mu, SE, wall s):", {h: runs[h] for h in sorted(runs, reverse=True)})
    print("\n| sizes (µm) | mu limit | uncertainty | method | runs' wall (s) |\n|---|---|---|---|---|")
    for sizes in itertools.combinations(sorted(runs, reverse=True), 3):
        if not 1.9 <= sizes[0] / sizes[1] <= 2.1 or not 1.9 <= sizes[1] / sizes[2] <= 2.1:
            continue  # the ladders step by a factor 2
        lim = limit(sizes, [runs[h][0] for h in sizes], [runs[h][1] for h in sizes])
        wall = sum(runs[h][2] for h in sizes)
        print(f"| {' / '.join(f'{h:g}' for h in sizes)} | {lim['value']:.4f} | {lim['uncertainty']:.4f} | "
              f"{lim['method']} | {wall:,.0f} |")


if __name__ == "__main__":
    main(Path(sys.argv[1]))
