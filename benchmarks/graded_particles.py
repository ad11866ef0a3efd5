"""Graded particles against uniform ones: what the coarse far field costs in mu and dp, and what it saves.

    python benchmarks/graded_particles.py [--scenes coated uncoated real] [--k 1.5 1.0] [--threads 2]
    python benchmarks/graded_particles.py --scenes coated --sizes 10 --paper \
        --out benchmarks/results/graded_vs_paper.json

For each scene at two particle sizes (coarse, fine) runs the defaults (uniform particles) and
``discretisation.graded`` with the fine zone ``--k`` expected contact radii wide and deep, all on
the block sized from the expected contact. It pays if the graded run's change in mu and dp
against the uniform run at the same h is well below the change of the uniform runs from the
coarse to the fine h (the discretisation error it would otherwise be traded against), at a
shorter wall time. Scenes:

- coated: examples/coated_rigid_plastic.yaml (H~ = 0.5, t = 25 um, r = 0.2 mm, 3 N, f = 1), h = 10, 5 um;
- uncoated: examples/uncoated_rigid_plastic.yaml (H = 900 MPa, r = 0.2 mm, 3 N, f = 1), h = 10, 5 um;
- real: examples/zinc_coated_steel.yaml (zinc t = 15 um on DX56, r = 0.5 mm, 22 N), h = 20, 10 um.

``--zones`` adds, for each value, the graded run (first ``--k``) with an active zone of that
many expected contact radii (``discretisation.active_zone_contact_radii``; README, *Active zone*).
``--paper`` adds the paper's numerical setup (``Scene.with_paper_settings()``: its fixed block,
uniform particles) at each size, for the speed-up of the defaults against it at equal error.
``--shapes square disc`` runs every graded case with each fine-zone cross-section
(``discretisation.fine_zone_shape``). ``--sizes`` replaces the scenes' two sizes; ``--skip-uniform``
runs the graded cases only (the
uncoated reference at h = 2.5 um: ``--scenes uncoated --sizes 2.5 --k 1.5 --skip-uniform --out
benchmarks/results/graded_uncoated_h2.5.json``).

Writes benchmarks/results/graded_particles.json (or ``--out``) after every run (a stopped invocation keeps what
it measured) and prints a Markdown table.
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

from common import run_scene

from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]
SCENES = {"coated": ("coated_rigid_plastic.yaml", (10.0, 5.0)),
          "uncoated": ("uncoated_rigid_plastic.yaml", (10.0, 5.0)),
          "real": ("zinc_coated_steel.yaml", (20.0, 10.0))}


def scene_at(example: str, h_um: float, k: float | str | None, zone: float | None = None,
             shape: str = "square") -> Scene:
    """Uniform (k None), graded with fine zone k of cross-section ``shape``, or the paper's settings (k
    "paper") at size h_um; with an active zone of ``zone`` expected contact radii if given."""
    base = Scene.from_yaml(ROOT / "examples" / example)
    disc = replace(base.discretisation, particle_size_m=h_um * 1e-6, active_zone_contact_radii=zone)
    if k == "paper":
        return replace(base, discretisation=disc).with_paper_settings()
    if k is not None:
        disc = replace(disc, graded=True, fine_zone_contact_radii=float(k), fine_zone_shape=shape)
    return replace(base, discretisation=disc).with_sized_domain()


def label(k: float | str | None, zone: float | None = None, shape: str = "square") -> str:
    if k == "paper":
        return "paper's settings"
    name = "uniform" if k is None else f"graded k={k:g}" + ("" if shape == "square" else f" {shape}")
    return name if zone is None else f"{name} zone {zone:g}"


def summary(runs: dict) -> str:
    lines = ["| scene | h (um) | particles | wall (s) | mu | mu_sh | dp (um) | vs uniform at this h (mu, dp, wall) |",
             "|---|---|---|---|---|---|---|---|"]
    for name, sizes in runs.items():
        for h, variants in sizes.items():
            uni = variants.get("uniform")
            for var, r in variants.items():
                rel = ""
                if uni is not None and var != "uniform":
                    rel = (f"{r['mu'] / uni['mu'] - 1:+.1%}, {r['dp'] / uni['dp'] - 1:+.1%}, "
                           f"{uni['wall_s'] / r['wall_s']:.2f}x faster")
                lines.append(f"| {name} {var} | {h} | {r['particles']:,} | {r['wall_s']:.1f} | {r['mu']:.3f} | "
                             f"{r['mu_sh']:.3f} | {r['dp'] * 1e6:.2f} | {rel} |")
        hs = list(sizes)
        if len(hs) == 2 and all("uniform" in sizes[h] for h in hs):
            a, b = sizes[hs[0]]["uniform"], sizes[hs[1]]["uniform"]
            lines.append(f"| {name}: uniform h = {hs[0]} -> {hs[1]} um | | | | {b['mu'] / a['mu'] - 1:+.1%} | | "
                         f"{b['dp'] / a['dp'] - 1:+.1%} | (the discretisation change) |")
    return "\n".join(lines)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scenes", nargs="+", choices=list(SCENES), default=list(SCENES))
    parser.add_argument("--k", nargs="+", type=float, default=[1.5, 1.0], help="fine-zone sizes, contact radii")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--sizes", nargs="+", type=float, default=None, help="particle sizes, um")
    parser.add_argument("--paper", action="store_true", help="also the paper's numerical setup")
    parser.add_argument("--zones", nargs="+", type=float, default=[], help="active zones (contact radii) added to "
                        "the graded run of the first --k")
    parser.add_argument("--shapes", nargs="+", choices=["square", "disc"], default=["square"],
                        help="fine-zone cross-sections of the graded runs (and of the zoned ones)")
    parser.add_argument("--zones-only", action="store_true", help="of the graded runs only those with a --zones zone")
    parser.add_argument("--skip-uniform", action="store_true", help="graded runs only (e.g. at h = 2.5 um)")
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "graded_particles.json")
    args = parser.parse_args()

    runs: dict = {}
    for name in args.scenes:
        example, sizes = SCENES[name]
        runs[name] = {}
        for h in args.sizes or sizes:
            runs[name][str(h)] = {}
            cases = [*([] if args.skip_uniform else [(None, None, "square")]),
                     *([] if args.zones_only else ((k, None, sh) for k in args.k for sh in args.shapes)),
                     *((args.k[0], z, sh) for z in args.zones for sh in args.shapes),
                     *([("paper", None, "square")] if args.paper else [])]
            for k, zone, shape in cases:
                row = run_scene(scene_at(example, h, k, zone, shape), args.threads)
                runs[name][str(h)][label(k, zone, shape)] = row
                print(f"{name} h = {h} um {label(k, zone, shape)}: {row['particles']:,} particles, "
                      f"{row['wall_s']:.1f} s, "
                      f"mu {row['mu']:.4f}, mu_sh {row['mu_sh']:.4f}, dp {row['dp'] * 1e6:.2f} um", flush=True)
                args.out.write_text(json.dumps({"threads": args.threads, "runs": runs}, indent=2) + "\n")
    print(summary(runs))


if __name__ == "__main__":
    main()
