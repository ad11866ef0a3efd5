"""Benchmark: the reference scene (uncoated rigid-plastic, r = 200 um, 3 N) at several particle sizes.

    python benchmarks/mpm_reference.py --sizes-um 10 5 --sized-domain [--threads 2] [--scene FILE] [--out FILE]

Writes ``--out`` (default benchmarks/results/mpm_reference[_<scene>]_sized.json, or ``_paper_block``
without ``--sized-domain``; ``_<scene>`` only for a scene other than the reference one) and prints a
Markdown table (wall time, steps, particles, particle-steps per second, and the physics: mu, mu_pl,
mu_sh, dp, penetration, against the analytical model). benchmarks/results/mpm_reference_sized.json
is the throughput the reproduction projection reads (benchmarks/reproduction_time.py).
"""

from __future__ import annotations

import argparse
import json
from dataclasses import replace
from pathlib import Path

import numba

from plough import __version__
from plough.analytical import ploughing
from plough.io import git_commit
from plough.mpm.run import simulate, warm_up
from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scene", default=str(ROOT / "examples" / "uncoated_rigid_plastic.yaml"))
    parser.add_argument("--sizes-um", type=float, nargs="+", default=[10.0, 5.0])
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--k1", type=float, default=125.0, help="analytical model's k1 (coated scenes)")
    parser.add_argument("--sized-domain", action="store_true", help="size the block from the expected contact")
    parser.add_argument("--out", default=None,
                        help="results file (default benchmarks/results/mpm_reference[_<scene>]_<block>.json)")
    args = parser.parse_args()
    if args.out is None:  # named for what it measures, so that another scene or block never overwrites the reference
        default_scene = Path(args.scene).resolve() == (ROOT / "examples" / "uncoated_rigid_plastic.yaml").resolve()
        scene_part = "" if default_scene else f"_{Scene.from_yaml(Path(args.scene)).name}"
        block_part = "_sized" if args.sized_domain else "_paper_block"
        args.out = str(ROOT / "benchmarks" / "results" / f"mpm_reference{scene_part}{block_part}.json")
    numba.set_num_threads(args.threads)
    base = Scene.from_yaml(Path(args.scene))
    Hs = 3.0 * base.layers.substrate.flow.sigma_y_Pa
    Hc = 3.0 * base.layers.coating.flow.sigma_y_Pa if base.layers.coated else Hs
    ana = ploughing(base.load_N, base.sphere.radius_m, base.layers.coating_thickness_m, Hc, Hs, k1=args.k1)
    rows = []
    # compile (or load from numba's cache) first: the first run's wall time would include it
    print(f"warm-up (compilation, not timed below): {warm_up(args.threads):.1f} s")
    print("| h (um) | particles | steps | wall (s) | M particle-steps/s | mu | mu_pl | mu_sh | dp (um) | "
          "penetration (um) | Fz mean / load |")
    print("|---|---|---|---|---|---|---|---|---|---|---|")
    for h in args.sizes_um:
        scene = replace(base, discretisation=replace(base.discretisation, particle_size_m=h * 1e-6))
        if args.sized_domain:
            scene = scene.with_sized_domain()
        ds = simulate(scene, progress=False)
        row = {"h_um": h, **{k: float(ds[k]) for k in ("mu", "mu_pl", "mu_sh", "dp", "dg", "hpu", "penetration",
                                                       "Fz_mean", "max_particle_penetration")},
               **{k[5:]: ds.attrs[k] for k in ds.attrs if k.startswith("cost_")}}
        rows.append(row)
        print(f"| {h:g} | {row['particles']:,} | {row['steps']:,} | {row['wall_time_s']:.1f} | "
              f"{row['particle_steps_per_s'] / 1e6:.2f} | {row['mu']:.3f} | {row['mu_pl']:.3f} | {row['mu_sh']:.3f} | "
              f"{row['dp'] * 1e6:.2f} | {row['penetration'] * 1e6:.2f} | {row['Fz_mean'] / scene.load_N:.4f} |",
              flush=True)
    print(f"| analytical | | | | | {float(ana.mu):.3f} | {float(ana.mu_pl):.3f} | {float(ana.mu_sh):.3f} | "
          f"{float(ana.dp) * 1e6:.2f} | | |")
    Path(args.out).parent.mkdir(parents=True, exist_ok=True)
    Path(args.out).write_text(json.dumps({
        "scene": base.to_dict(), "threads": args.threads, "sized_domain": args.sized_domain, "k1": args.k1,
        "plough_version": __version__, "git_commit": git_commit(),
        "analytical": {"mu": float(ana.mu), "mu_pl": float(ana.mu_pl), "mu_sh": float(ana.mu_sh), "dp": float(ana.dp)},
        "runs": rows}, indent=2))


if __name__ == "__main__":
    main()
