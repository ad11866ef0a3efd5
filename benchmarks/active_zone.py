"""What the active zone (discretisation.active_zone_contact_radii) saves and what it moves.

    python benchmarks/active_zone.py [--sizes-um 10 5] [--zones 3 4 6]

Runs the three reference scenes as the workflow does (block sized from the expected contact,
graded particles with fine zone 1.5 contact radii, 2 threads; uncoated f = 1, coated f = 1 and
coated f = 0.5, as in benchmarks/steadiness_check.py) with every particle updated and with an
active zone of each given half-width (in expected contact radii; at least 20 h,
``Scene.active_zone_half_width_m``, whose value each row records in contact radii and in h), and records mu, dp, the
steadiness values, the wall time and the share of particle-steps the zone worked on. The change a
zone makes is to be read against the change from halving h (the discretisation error).
Writes benchmarks/results/active_zone.json (after every run) and prints a Markdown table.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numba
from common import run_scene
from steadiness_check import scenes

from plough.io import git_commit
from plough.mpm.run import warm_up

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes-um", type=float, nargs="+", default=[10.0, 5.0])
    parser.add_argument("--zones", type=float, nargs="+", default=[3.0, 4.0, 6.0])
    parser.add_argument("--scenes", nargs="+", default=None, help="labels to run (default: all three)")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--out", default=str(ROOT / "benchmarks" / "results" / "active_zone.json"))
    args = parser.parse_args()
    numba.set_num_threads(args.threads)
    out = Path(args.out)
    data = json.loads(out.read_text()) if out.exists() else {"runs": {}}
    data["git_commit"] = git_commit()
    print(f"warm-up (compilation, not timed below): {warm_up(args.threads):.1f} s")
    print("| scene | zone (a) | mu | dp (um) | vs all particles (mu, dp) | active share | wall (s) | speed-up |")
    print("|---|---|---|---|---|---|---|---|")
    for h in args.sizes_um:
        for label, scene in scenes(h).items():
            if args.scenes and not any(label.startswith(s) for s in args.scenes):
                continue
            rows = data["runs"].setdefault(label, {})
            for k in [None, *args.zones]:
                disc = replace(scene.discretisation, active_zone_contact_radii=k)
                zoned = replace(scene, discretisation=disc)
                row = run_scene(zoned, args.threads)
                if k is not None:
                    a, h = scene.expected_contact()[0], scene.discretisation.particle_size_m
                    row["half_width_contact_radii"] = zoned.active_zone_half_width_m / a
                    row["half_width_particles"] = zoned.active_zone_half_width_m / h
                rows["all" if k is None else f"zone {k:g}"] = row
                out.write_text(json.dumps(data, indent=1) + "\n")
                ref = rows["all"]
                change = "" if k is None else f"{row['mu'] / ref['mu'] - 1:+.1%}, {row['dp'] / ref['dp'] - 1:+.1%}"
                print(f"| {label} | {'all' if k is None else f'{k:g}'} | {row['mu']:.3f} | {row['dp'] * 1e6:.2f} | "
                      f"{change} | {row['active_fraction']:.2f} | {row['wall_s']:.1f} | "
                      f"{ref['wall_s'] / row['wall_s']:.2f}x |", flush=True)


if __name__ == "__main__":
    main()
