"""plough against the peer (Taichi CPU MLS-MPM), measured side by side in one invocation.

    python benchmarks/peer_side_by_side.py --peer-python /tmp/peer/bin/python [--repeats 3]

The peer runs in its own throwaway virtual environment (``../shared/peer-bench/README.md``:
``python3 -m venv /tmp/peer && /tmp/peer/bin/pip install taichi numba numpy``); it is never a
dependency of plough. This machine's speed drifts by up to +-30% between invocations, so a ratio of
numbers measured in different sessions says little: here the two codes alternate, ``--repeats``
times each, at about the same particle count and thread count, and the ratio is taken of the
medians (and, as a spread, per pair).

- peer: ``taichi_mpm3d.py --n 262144 --steps 200 --threads 2 --f64`` (a J2 block squashed by a
  platen, APIC/MLS, 8 particles per cell; timed after warm-up).
- plough: ``benchmarks/kernel_profile.py --h-um 5 --paper-block --steps 200`` (the reference
  scene, uncoated, r = 0.2 mm, 3 N, on the paper's 0.2 x 1 mm block at h = 5 um: 251,200
  particles, full physics: contact, mirror fold, projected dilatation, FLIP, energy account;
  timed in the slide after the press).

Writes benchmarks/results/peer_side_by_side.json.
"""

from __future__ import annotations

import argparse
import json
import os
import platform
import statistics
import subprocess
import sys
import tempfile
from datetime import date
from pathlib import Path

from plough.io import git_commit

ROOT = Path(__file__).resolve().parents[1]
PEER_DIR = ROOT.parent / "shared" / "peer-bench"


def run_peer(python: str, peer_dir: Path, threads: int, n: int, steps: int) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "taichi.jsonl"
        cmd = [python, "taichi_mpm3d.py", "--n", str(n), "--steps", str(steps), "--threads", str(threads), "--f64",
               "--json", str(out)]
        env = {**os.environ, "NUMBA_NUM_THREADS": str(threads)}
        subprocess.run(cmd, cwd=peer_dir, env=env, check=True, capture_output=True, text=True)
        return json.loads(out.read_text().splitlines()[-1])


def run_plough(threads: int, steps: int, h_um: float) -> dict:
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "profile.json"
        cmd = [sys.executable, str(ROOT / "benchmarks" / "kernel_profile.py"), "--h-um", f"{h_um:g}", "--paper-block",
               "--steps", str(steps), "--threads", str(threads), "--out", str(out)]
        subprocess.run(cmd, check=True, capture_output=True, text=True)
        return json.loads(out.read_text())


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--peer-python", required=True, help="python of the throwaway venv with taichi")
    parser.add_argument("--peer-dir", type=Path, default=PEER_DIR)
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--peer-n", type=int, default=262144)
    parser.add_argument("--steps", type=int, default=200)
    parser.add_argument("--h-um", type=float, default=5.0)
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "peer_side_by_side.json")
    args = parser.parse_args()

    pairs = []
    for i in range(args.repeats):
        peer = run_peer(args.peer_python, args.peer_dir, args.threads, args.peer_n, args.steps)
        ours = run_plough(args.threads, args.steps, args.h_um)
        pair = {"peer_particle_steps_per_s": peer["pstep_per_s"], "peer_particles": peer["N"],
                "plough_particle_steps_per_s": ours["particle_steps_per_s"], "plough_particles": ours["particles"],
                "plough_share": ours["share"], "taichi_version": peer.get("taichi", "unknown")}
        pair["ratio"] = pair["plough_particle_steps_per_s"] / pair["peer_particle_steps_per_s"]
        pairs.append(pair)
        print(f"pair {i + 1}/{args.repeats}: taichi {peer['pstep_per_s'] / 1e6:.2f} M/s ({peer['N']:,} particles), "
              f"plough {ours['particle_steps_per_s'] / 1e6:.2f} M/s ({ours['particles']:,}): "
              f"ratio {pair['ratio']:.2f}", flush=True)

    peer_med = statistics.median(p["peer_particle_steps_per_s"] for p in pairs)
    ours_med = statistics.median(p["plough_particle_steps_per_s"] for p in pairs)
    ratios = [p["ratio"] for p in pairs]
    result = {
        "date": date.today().isoformat(), "machine": platform.processor() or platform.machine(),
        "threads": args.threads, "git_commit": git_commit(), "taichi_version": pairs[0]["taichi_version"],
        "peer_command": f"taichi_mpm3d.py --n {args.peer_n} --steps {args.steps} --threads {args.threads} --f64",
        "plough_command": f"kernel_profile.py --h-um {args.h_um:g} --paper-block --steps {args.steps}",
        "pairs": pairs, "peer_median_particle_steps_per_s": peer_med,
        "plough_median_particle_steps_per_s": ours_med, "ratio_of_medians": ours_med / peer_med,
        "ratio_min": min(ratios), "ratio_max": max(ratios),
    }
    args.out.write_text(json.dumps(result, indent=2) + "\n")
    print(f"medians: taichi {peer_med / 1e6:.2f} M/s, plough {ours_med / 1e6:.2f} M/s: ratio {ours_med / peer_med:.2f} "
          f"(pairs {min(ratios):.2f}-{max(ratios):.2f}); written to {args.out}")


if __name__ == "__main__":
    main()
