"""Particle-steps per second of this tree against another commit (and the peers), side by side in one invocation.

    python benchmarks/throughput.py --against 7545dab [--repeats 3] [--steps 300] [--threads 2]
        [--peers --peer-python /tmp/peer/bin/python] [--out benchmarks/results/throughput.json]

Two scenes, each run on both sides:

- ``reference``: the uncoated rigid-plastic reference scene (examples/uncoated_rigid_plastic.yaml:
  H = 900 MPa, r = 0.2 mm, 3 N) at h = 5 um on the paper's 0.2 x 1 mm block (the scene file's domain);
- ``zinc_coated_steel``: examples/zinc_coated_steel.yaml (DX56 with its zinc coating, 1 mm ball, 22 N)
  at h = 10 um on the block sized from the expected contact (as ``kernel_profile.py --scene`` runs it).

Each run presses and settles the sphere, takes ``WARM_SLIDE_STEPS`` steps into the slide (every kernel
compiled), then times ``--steps`` steps of the slide: particle-steps per second = the particles the steps
work on (all of them: these scenes have no active zone) over the wall time. ``REF`` is unpacked with
``git archive REF | tar -x -C TMPDIR`` and imported from there (``PYTHONPATH=TMPDIR/src``) in a
subprocess; this tree runs the same way from its own ``src``, with the same scene files (this tree's) and
the same thread count. This machine's speed drifts by up to +-30% between invocations, so the sides
alternate, ``--repeats`` times (the order flipped every repeat), and the ratio this / REF is taken of the
medians (the per-repeat ratios are the spread). ``--peers`` adds the peers of ``../shared/peer-bench``
(Taichi's CPU MLS-MPM and the plain numba MLS-MPM of a J2 block, ``--peer-n`` particles, f64) to every
repeat; they run in a throwaway virtual environment (``--peer-python``, see the peer-bench README), never
as a dependency of plough.

Writes one file (``--out``): both sides' commits (this tree's with ``+dirty`` where src/plough has
uncommitted edits), the physics each side ran (its resolved discretisation, its interface law, the
first line of its contact module's docstring, and its solver fingerprint where it has one), the
per-repeat rates, the medians and the ratios. ``--h-um-reference`` / ``--h-um-zinc`` change the particle
sizes (a quick check of the script at coarse sizes; not the benchmark).
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
import time
from datetime import date
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: ../shared/peer-bench beside the checkout, or beside the folder of a git worktree (wt/NAME)
PEER_DIR = next((d for d in (ROOT.parent / "shared" / "peer-bench", ROOT.parents[1] / "shared" / "peer-bench")
                 if d.is_dir()), ROOT.parent / "shared" / "peer-bench")
#: steps run into the slide before the clock starts
WARM_SLIDE_STEPS = 20
#: name: (scene file, default particle size in um, block: "paper" (the file's domain) or "sized")
SCENES = {"reference": ("examples/uncoated_rigid_plastic.yaml", 5.0, "paper"),
          "zinc_coated_steel": ("examples/zinc_coated_steel.yaml", 10.0, "sized")}
#: peer name: (script in the peer-bench folder, its extra options)
PEERS = {"taichi": ("taichi_mpm3d.py", ["--f64"]), "plain_numba": ("numba_mpm3d.py", ["--f64", "--p2g", "tls"])}


# ----------------------------------------------------------------------------- one run (in a subprocess)
def measure(scene_file: Path, h_um: float, block: str, steps: int, threads: int, expect_root: Path) -> dict:
    """Run one scene with the plough found on ``sys.path`` (checked to come from ``expect_root``) and time
    ``steps`` steps of its slide. Uses only what both sides have: ``solver.init``, ``solver.step``, the
    state's sphere phase and particles."""
    from dataclasses import asdict, replace

    import numba

    import plough
    from plough.mpm import contact, solver
    from plough.mpm.scene import Scene

    if not Path(plough.__file__).resolve().is_relative_to(expect_root.resolve()):
        raise RuntimeError(f"plough imported from {plough.__file__}, not from {expect_root}")
    numba.set_num_threads(threads)
    scene = Scene.from_yaml(scene_file)
    scene = replace(scene, discretisation=replace(scene.discretisation, particle_size_m=h_um * 1e-6))
    if block == "sized":
        scene = scene.with_sized_domain()
    t0 = time.perf_counter()
    state, const = solver.init(scene)
    while state.sphere.phase != "slide":
        solver.step(state, const)
    for _ in range(WARM_SLIDE_STEPS):
        solver.step(state, const)
    setup_s = time.perf_counter() - t0
    worked = 0
    timed = 0
    t0 = time.perf_counter()
    while timed < steps and state.sphere.phase == "slide":
        solver.step(state, const)
        # the zone's ranges after this step (a new tuple each step in this tree; on the zone itself in earlier ones)
        zone = getattr(state, "zone", None)
        zone = getattr(zone, "ranges", zone)
        worked += (zone.p_hi - zone.p_lo) if zone is not None else state.particles.n
        timed += 1
    seconds = time.perf_counter() - t0
    try:
        from plough.fingerprint import solver_fingerprint
        fingerprint = solver_fingerprint()
    except ImportError:
        fingerprint = None
    physics = {"discretisation": asdict(scene.discretisation), "interface": repr(scene.interface),
               "contact": (contact.__doc__ or "").strip().splitlines()[0], "solver_fingerprint": fingerprint,
               "plough_version": getattr(plough, "__version__", "unknown")}
    return {"particles": int(state.particles.n), "steps_timed": timed, "seconds": seconds,
            "particle_steps_per_s": worked / seconds if seconds > 0 else float("nan"),
            "setup_seconds": setup_s, "setup_steps": int(state.step) - timed, "physics": physics}


def run_side(src: Path, scene: str, h_um: float, steps: int, threads: int) -> dict:
    """``measure`` in a fresh interpreter importing plough from ``src`` (numba's cache: that tree's own)."""
    file, _, block = SCENES[scene]
    env = {**os.environ, "PYTHONPATH": str(src), "NUMBA_NUM_THREADS": str(threads)}
    cmd = [sys.executable, str(Path(__file__).resolve()), "--measure", str(ROOT / file), "--h-um", f"{h_um:g}",
           "--block", block, "--steps", str(steps), "--threads", str(threads), "--expect-root", str(src)]
    done = subprocess.run(cmd, env=env, capture_output=True, text=True)
    if done.returncode != 0:
        raise RuntimeError(f"{scene} from {src} failed:\n{done.stderr[-4000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def run_peer(python: str, peer_dir: Path, peer: str, n: int, steps: int, threads: int) -> dict:
    script, extra = PEERS[peer]
    with tempfile.TemporaryDirectory() as tmp:
        out = Path(tmp) / "peer.jsonl"
        cmd = [python, script, "--n", str(n), "--steps", str(steps), "--threads", str(threads), *extra,
               "--json", str(out)]
        env = {**os.environ, "NUMBA_NUM_THREADS": str(threads)}
        subprocess.run(cmd, cwd=peer_dir, env=env, check=True, capture_output=True, text=True)
        return json.loads(out.read_text().splitlines()[-1])


# ----------------------------------------------------------------------------- the comparison
def git(*args: str) -> str:
    return subprocess.run(["git", *args], cwd=ROOT, check=True, capture_output=True, text=True).stdout.strip()


def this_commit() -> str:
    """HEAD, '+dirty' where src/plough has uncommitted edits to tracked files (``plough.io.git_commit``)."""
    dirty = git("status", "--porcelain", "--untracked-files=no", "--", "src/plough")
    return git("rev-parse", "HEAD") + ("+dirty" if dirty else "")


def unpack(ref: str, into: Path) -> str:
    """``git archive REF | tar -x -C into``; the full commit hash of REF."""
    commit = git("rev-parse", "--verify", f"{ref}^{{commit}}")
    archive = subprocess.run(["git", "archive", commit], cwd=ROOT, check=True, capture_output=True).stdout
    subprocess.run(["tar", "-x", "-C", str(into)], input=archive, check=True)
    return commit


def median(values: list[float]) -> float:
    return statistics.median(values) if values else float("nan")


def compare(args: argparse.Namespace, ref_root: Path, ref_commit: str) -> dict:
    h = {"reference": args.h_um_reference, "zinc_coated_steel": args.h_um_zinc}
    sides = {"this": ROOT / "src", "against": ref_root / "src"}
    runs: dict[str, dict[str, list[dict]]] = {s: {"this": [], "against": []} for s in SCENES}
    peers: dict[str, list[dict]] = {p: [] for p in PEERS} if args.peers else {}
    for repeat in range(args.repeats):
        order = ["this", "against"] if repeat % 2 == 0 else ["against", "this"]
        for scene in SCENES:
            for side in order:
                r = run_side(sides[side], scene, h[scene], args.steps, args.threads)
                runs[scene][side].append(r)
                print(f"repeat {repeat + 1}, {scene}, {side}: {r['particle_steps_per_s'] / 1e6:.3f} M particle-steps/s "
                      f"({r['particles']} particles, {r['steps_timed']} steps, {r['seconds']:.1f} s)", flush=True)
        for peer in peers:
            r = run_peer(args.peer_python, args.peer_dir, peer, args.peer_n, args.peer_steps, args.threads)
            peers[peer].append(r)
            print(f"repeat {repeat + 1}, peer {peer}: {r['pstep_per_s'] / 1e6:.3f} M particle-steps/s", flush=True)
    scenes = {}
    for scene, by_side in runs.items():
        row: dict = {"scene_file": SCENES[scene][0], "h_um": h[scene], "block": SCENES[scene][2]}
        for side, rs in by_side.items():
            rates = [r["particle_steps_per_s"] for r in rs]
            row[side] = {"particles": rs[0]["particles"], "steps_timed": [r["steps_timed"] for r in rs],
                         "rates": rates, "median": median(rates), "physics": rs[0]["physics"]}
        row["ratio"] = row["this"]["median"] / row["against"]["median"]
        row["repeat_ratios"] = [a / b for a, b in zip(row["this"]["rates"], row["against"]["rates"], strict=True)]
        scenes[scene] = row
    peer_rows = {}
    for peer, rs in peers.items():
        rates = [r["pstep_per_s"] for r in rs]
        peer_rows[peer] = {"script": PEERS[peer][0], "options": PEERS[peer][1], "particles": rs[0].get("N"),
                           "rates": rates, "median": median(rates),
                           "this_over_peer": {s: scenes[s]["this"]["median"] / median(rates) for s in scenes}}
    return {"date": date.today().isoformat(), "machine": f"{platform.node()} {platform.processor()}",
            "command": " ".join([Path(sys.argv[0]).name, *sys.argv[1:]]), "threads": args.threads,
            "steps": args.steps, "repeats": args.repeats, "warm_slide_steps": WARM_SLIDE_STEPS,
            "this": {"commit": this_commit()}, "against": {"ref": args.against, "commit": ref_commit},
            "scenes": scenes, "peers": peer_rows,
            "note": "ratios of medians of alternating runs in one invocation; absolute rates drift +-30% "
                    "between invocations on this machine"}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--against", help="the commit (or any git revision) to compare with, e.g. 7545dab")
    parser.add_argument("--repeats", type=int, default=3)
    parser.add_argument("--steps", type=int, default=300, help="timed steps of the slide per run")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--h-um-reference", type=float, default=SCENES["reference"][1])
    parser.add_argument("--h-um-zinc", type=float, default=SCENES["zinc_coated_steel"][1])
    parser.add_argument("--peers", action="store_true", help="also run the peers of ../shared/peer-bench")
    parser.add_argument("--peer-python", help="python of the throwaway venv with taichi and numba (with --peers)")
    parser.add_argument("--peer-dir", type=Path, default=PEER_DIR)
    parser.add_argument("--peer-n", type=int, default=262144)
    parser.add_argument("--peer-steps", type=int, default=200)
    parser.add_argument("--out", type=Path, default=ROOT / "benchmarks" / "results" / "throughput.json")
    # one run, in the subprocess run_side starts
    parser.add_argument("--measure", type=Path, help=argparse.SUPPRESS)
    parser.add_argument("--h-um", type=float, help=argparse.SUPPRESS)
    parser.add_argument("--block", choices=["paper", "sized"], help=argparse.SUPPRESS)
    parser.add_argument("--expect-root", type=Path, help=argparse.SUPPRESS)
    args = parser.parse_args()
    if args.measure is not None:
        print(json.dumps(measure(args.measure, args.h_um, args.block, args.steps, args.threads, args.expect_root)))
        return
    if not args.against:
        parser.error("--against REF is required")
    if args.peers and not args.peer_python:
        parser.error("--peers needs --peer-python (a throwaway venv, ../shared/peer-bench/README.md)")
    if args.repeats < 1 or args.steps < 1:
        parser.error("--repeats and --steps must be at least 1")
    with tempfile.TemporaryDirectory(prefix="throughput_ref_") as tmp:
        ref_commit = unpack(args.against, Path(tmp))
        result = compare(args, Path(tmp), ref_commit)
    args.out.parent.mkdir(parents=True, exist_ok=True)
    args.out.write_text(json.dumps(result, indent=1) + "\n")
    for scene, row in result["scenes"].items():
        print(f"{scene}: this {row['this']['median'] / 1e6:.3f} M/s, {args.against} "
              f"{row['against']['median'] / 1e6:.3f} M/s: {row['ratio']:.2f}x")
    for peer, row in result["peers"].items():
        ratios = ", ".join(f"{s} {r:.2f}x" for s, r in row["this_over_peer"].items())
        print(f"peer {peer}: {row['median'] / 1e6:.3f} M/s; this over it: {ratios}")
    print(f"wrote {args.out}")


if __name__ == "__main__":
    main()
