"""Work–precision benchmark (issue 5): error in mu and dp against wall time, per numerical knob.

    python benchmarks/work_precision.py --scene rigid_plastic           # H~ = 0.5, t = 25 um, r 0.2 mm, 3 N
    python benchmarks/work_precision.py --scene real                    # zinc-coated steel t 15 um, r 0.5 mm, 22 N
    python benchmarks/work_precision.py --scene rigid_plastic --plot-only

What it runs (every run with 2 threads, one after another, the sized block unless a case says
otherwise):

* the **ladder**: the defaults at every particle size of ``--ladder-um``; its h -> 0 extrapolation
  (``plough.study.extrapolation``: Richardson with the observed order from three sizes, else the
  flagged fallbacks, with the grid convergence index as uncertainty) is the converged reference;
* the **sweep** at ``--sweep-um``: one knob changed at a time: CFL number, mass scaling, sliding
  speed, particles per cell, domain size (the block sized 1.5x larger; the paper's fixed block
  with the paper's settings, ``Scene.with_paper_settings``), sliding distance;
* the **inertia** cases at ``--inertia-um`` (the finest size): mass scaling x 4 and / 4
  (``--skip-inertia`` leaves them for a later invocation).

float32 against float64 is not measured: the kernels are float64 only (issue 3 asks for float64).

Each run is kept in ``benchmarks/results/work_precision_<scene>.json`` as soon as it finishes, so
an interrupted benchmark resumes where it stopped; ``--plot-only`` redraws the figure
``benchmarks/results/work_precision_<scene>.png`` and prints the Markdown table from that file.
The error of a run is |value - reference| / |reference|; errors below the reference's own
uncertainty are not resolved (the band in the plot).
"""

from __future__ import annotations

import argparse
import json
from collections.abc import Callable
from dataclasses import replace
from pathlib import Path

import numpy as np
from common import run_scene

from plough.mpm.scene import CFL_MAX, Scene

ROOT = Path(__file__).resolve().parents[1]
RESULTS = ROOT / "benchmarks" / "results"
SCENES = {"rigid_plastic": ("coated_rigid_plastic.yaml", [20.0, 10.0, 5.0], 10.0, 5.0),
          "real": ("zinc_coated_steel.yaml", [40.0, 20.0, 10.0], 20.0, None)}
QUANTITIES = ("mu", "dp")


def _disc(s: Scene, **kw: float) -> Scene:
    return replace(s, discretisation=replace(s.discretisation, **kw))


def _slide(s: Scene, **kw: float) -> Scene:
    return replace(s, sliding=replace(s.sliding, **kw))


def sweep_cases(base: Scene) -> dict[str, Callable[[], Scene]]:
    """One knob at a time around the defaults ``base`` (already at the sweep size, sized block)."""
    d, sl = base.discretisation, base.sliding
    return {
        "CFL 0.15": lambda: _disc(base, cfl=d.cfl / 2),
        f"CFL {CFL_MAX}": lambda: _disc(base, cfl=CFL_MAX),  # the largest accepted (2 x 0.3 until 2026-12-03)
        "mass scaling x4": lambda: _disc(base, mass_scaling=4 * d.mass_scaling),
        "mass scaling /4": lambda: _disc(base, mass_scaling=d.mass_scaling / 4),
        "speed x2": lambda: _slide(base, speed_m_s=2 * sl.speed_m_s),
        "speed /2": lambda: _slide(base, speed_m_s=sl.speed_m_s / 2),
        "local dilatation (locks)": lambda: _disc(base, dilatation="local"),
        "1 particle per cell": lambda: _disc(base, particles_per_cell=1),
        "3 particles per cell": lambda: _disc(base, particles_per_cell=3),
        "block x1.5": lambda: base.with_sized_domain(radius_contact_radii=3.75, end_margin_contact_radii=4.5),
        "paper's settings": lambda: base.with_paper_settings(),
        "slide 0.3 mm": lambda: _slide(base, distance_m=0.5 * sl.distance_m).with_sized_domain(),
        "slide 0.45 mm": lambda: _slide(base, distance_m=0.75 * sl.distance_m).with_sized_domain(),
    }


def inertia_cases(base: Scene) -> dict[str, Callable[[], Scene]]:
    d = base.discretisation
    return {"mass scaling x4": lambda: _disc(base, mass_scaling=4 * d.mass_scaling),
            "mass scaling /4": lambda: _disc(base, mass_scaling=d.mass_scaling / 4)}


def at_size(scene: Scene, h_um: float) -> Scene:
    return _disc(scene, particle_size_m=h_um * 1e-6).with_sized_domain()


def run_one(scene: Scene, threads: int) -> dict[str, float]:
    row = run_scene(scene, threads)
    row.update(h_um=scene.discretisation.particle_size_m * 1e6, inertia_number=scene.inertia_number,
               load_N=scene.load_N)
    return row


def reference(runs: dict[str, dict], ladder: list[float]) -> dict[str, dict[str, float]]:
    """The h -> 0 extrapolation of the ladder for mu and dp, with its uncertainty and method."""
    from plough.study.extrapolation import Method, extrapolate

    hs = [h for h in ladder if f"ladder h={h:g}" in runs]
    out = {}
    for q in QUANTITIES:
        if len(hs) < 2:
            break
        f = [runs[f"ladder h={h:g}"][q] for h in hs]
        ex = extrapolate(hs, f)
        out[q] = {"value": float(ex.value), "uncertainty": float(ex.uncertainty), "order": float(ex.order),
                  "method": Method(int(ex.method)).name, "sizes_um": hs, "values": f}
    return out


def errors(runs: dict[str, dict], ref: dict[str, dict]) -> dict[str, dict[str, float]]:
    return {name: {q: abs(r[q] - ref[q]["value"]) / abs(ref[q]["value"]) for q in QUANTITIES if q in ref}
            for name, r in runs.items()}


def pareto(runs: dict[str, dict], err: dict[str, dict], q: str) -> list[str]:
    """Runs no other run beats in both wall time and error in q."""
    names = list(runs)
    front = []
    for a in names:
        dominated = any(runs[b]["wall_s"] <= runs[a]["wall_s"] and err[b][q] <= err[a][q]
                        and (runs[b]["wall_s"] < runs[a]["wall_s"] or err[b][q] < err[a][q]) for b in names)
        if not dominated:
            front.append(a)
    return sorted(front, key=lambda n: runs[n]["wall_s"])


def table(runs: dict[str, dict], ref: dict[str, dict], err: dict[str, dict]) -> str:
    lines = ["| run | h (µm) | particles | steps | wall (s) | mu | error mu | dp (µm) | error dp "
             "| vs same-h defaults (mu, dp) |",
             "|---|---|---|---|---|---|---|---|---|---|"]
    for name, r in sorted(runs.items(), key=lambda kv: (-kv[1]["h_um"], kv[0])):
        base = runs.get(f"ladder h={r['h_um']:g}")
        rel = ""
        if base is not None and base is not r:
            rel = f"{(r['mu'] / base['mu'] - 1) * 100:+.1f}%, {(r['dp'] / base['dp'] - 1) * 100:+.1f}%"
        e = err[name]
        lines.append(f"| {name} | {r['h_um']:g} | {r['particles']:,} | {r['steps']:,} | {r['wall_s']:.1f} | "
                     f"{r['mu']:.3f} | {e.get('mu', np.nan) * 100:.1f}% | {r['dp'] * 1e6:.2f} | "
                     f"{e.get('dp', np.nan) * 100:.1f}% | {rel} |")
    for q in QUANTITIES:
        if q in ref:
            scale = 1e6 if q == "dp" else 1.0
            lines.append(f"\nreference {q} (h -> 0, {ref[q]['method']}, order {ref[q]['order']:.2f}, sizes "
                         f"{ref[q]['sizes_um']} µm): {ref[q]['value'] * scale:.3f} ± "
                         f"{ref[q]['uncertainty'] * scale:.3f}{' µm' if q == 'dp' else ''}")
    return "\n".join(lines)


def knob_changes(runs: dict[str, dict]) -> dict[str, dict[str, float]]:
    """|value / defaults at the same h - 1| of every non-ladder run: the knob's own effect."""
    out = {}
    for name, r in runs.items():
        base = runs.get(f"ladder h={r['h_um']:g}")
        if base is not None and not name.startswith("ladder"):
            out[name] = {q: abs(r[q] / base[q] - 1.0) for q in QUANTITIES}
    return out


def discretisation_changes(runs: dict[str, dict]) -> dict[float, dict[str, float]]:
    """h -> |f(h) / f(2h) - 1|: the change of the defaults when h is halved (the discretisation
    error estimate the issue compares a knob's effect with)."""
    out = {}
    for name, r in runs.items():
        coarse = runs.get(f"ladder h={2 * r['h_um']:g}")
        if name.startswith("ladder") and coarse is not None:
            out[r["h_um"]] = {q: abs(r[q] / coarse[q] - 1.0) for q in QUANTITIES}
    return out


def plot(runs: dict[str, dict], ref: dict[str, dict], err: dict[str, dict], title: str, path: Path) -> None:
    import matplotlib

    matplotlib.use("Agg")
    import matplotlib.pyplot as plt

    fig, axes = plt.subplots(2, 2, figsize=(13, 10), constrained_layout=True)
    ladder = sorted((r["wall_s"], name) for name, r in runs.items() if name.startswith("ladder"))
    changes, disc = knob_changes(runs), discretisation_changes(runs)
    for col, q in enumerate(QUANTITIES):
        ax = axes[0, col]
        if q not in ref:
            continue
        front = set(pareto(runs, err, q))
        xs = [runs[n]["wall_s"] for _, n in ladder]
        ax.plot(xs, [max(err[n][q], 1e-4) for _, n in ladder], "k-", lw=1, alpha=0.6, label="defaults, h ladder")
        for name, r in runs.items():
            e = max(err[name][q], 1e-4)
            marker = "s" if name.startswith("ladder") else "o"
            ax.plot(r["wall_s"], e, marker, ms=7, mfc="C3" if name in front else "C0", mec="k")
            ax.annotate(name, (r["wall_s"], e), fontsize=6, xytext=(4, 3), textcoords="offset points")
        unc = ref[q]["uncertainty"] / abs(ref[q]["value"])
        ax.axhspan(1e-4, max(unc, 1e-4), color="0.85", label="reference uncertainty (not resolved below)")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time on 2 threads (s)")
        ax.set_ylabel(f"relative error in {q} vs the h -> 0 reference")
        ax.set_title(f"{q} against the h -> 0 reference ({ref[q]['method'].lower()}); red = Pareto front",
                     fontsize=9)
        ax.legend(fontsize=7, loc="lower left")

        ax = axes[1, col]
        hs = sorted({runs[n]["h_um"] for n in changes})
        for k, h in enumerate(hs):
            color = f"C{k}"
            for name, c in changes.items():
                if runs[name]["h_um"] != h:
                    continue
                v = max(c[q], 1e-4)
                ax.plot(runs[name]["wall_s"], v, "o", ms=6, color=color, mec="k")
                ax.annotate(name, (runs[name]["wall_s"], v), fontsize=6, xytext=(4, 3), textcoords="offset points")
            if h in disc:
                ax.axhline(max(disc[h][q], 1e-4), color=color, ls="--", lw=1,
                           label=f"h = {h:g} µm: change from h = {2 * h:g} µm")
        ax.set_xscale("log")
        ax.set_yscale("log")
        ax.set_xlabel("wall time on 2 threads (s)")
        ax.set_ylabel(f"|{q} / {q} of the defaults at the same h - 1|")
        ax.set_title(f"{q}: each knob's own effect against the discretisation change (dashed)", fontsize=9)
        ax.legend(fontsize=7, loc="lower left")
    fig.suptitle(title, fontsize=10)
    fig.savefig(path, dpi=110)
    plt.close(fig)


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--scene", choices=sorted(SCENES), default="rigid_plastic")
    parser.add_argument("--ladder-um", type=float, nargs="+", default=None)
    parser.add_argument("--sweep-um", type=float, default=None)
    parser.add_argument("--inertia-um", type=float, default=None)
    parser.add_argument("--skip-inertia", action="store_true", help="do not run the inertia cases now")
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--only", nargs="*", default=None, help="run only these case names (others kept)")
    parser.add_argument("--plot-only", action="store_true")
    args = parser.parse_args()
    fname, ladder, sweep_h, inertia_h = SCENES[args.scene]
    ladder = args.ladder_um or ladder
    sweep_h = args.sweep_um or sweep_h
    inertia_h = args.inertia_um if args.inertia_um is not None else inertia_h
    scene = Scene.from_yaml(ROOT / "examples" / fname)
    out = RESULTS / f"work_precision_{args.scene}.json"
    data = json.loads(out.read_text()) if out.exists() else {"scene": scene.to_dict(), "runs": {}}
    runs = data["runs"]

    cases: dict[str, Callable[[], Scene]] = {f"ladder h={h:g}": (lambda h=h: at_size(scene, h)) for h in ladder}
    cases.update({f"{k} (h={sweep_h:g})": v for k, v in sweep_cases(at_size(scene, sweep_h)).items()})
    if inertia_h is not None:
        cases.update({f"{k} (h={inertia_h:g})": v for k, v in inertia_cases(at_size(scene, inertia_h)).items()})
    if not args.plot_only:
        from plough.study.cost import estimate

        todo = {}
        for name, make in cases.items():
            if (name in runs or (args.only is not None and name not in args.only)
                    or (args.skip_inertia and inertia_h is not None and name.endswith(f"(h={inertia_h:g})")
                        and not name.startswith("ladder"))):
                continue
            try:
                todo[name] = make()
            except ValueError as exc:  # a scene refused before running is a result too
                data.setdefault("refused", {})[name] = str(exc)
                print(f"{name}: refused: {exc}", flush=True)
        # cheapest first: the picture fills in early and an interruption loses the least
        for name, scene_ in sorted(todo.items(), key=lambda kv: estimate(kv[1]).particle_steps):
            try:
                runs[name] = run_one(scene_, args.threads)
            except ValueError as exc:
                data.setdefault("refused", {})[name] = str(exc)
                print(f"{name}: refused: {exc}", flush=True)
                continue
            print(name, json.dumps(runs[name]), flush=True)
            out.write_text(json.dumps(data, indent=2) + "\n")
    runs = {k: v for k, v in runs.items() if k in cases}
    ref = reference(runs, ladder)
    if not ref:
        print("fewer than two ladder sizes done: no reference yet")
        return
    commits = sorted({r.get("git_commit", "unknown") for r in runs.values()})
    if len(commits) > 1:
        print(f"warning: the runs come from {len(commits)} code versions {commits}; rerun the stale ones "
              "(delete them from the results file) if the solver changed between them")
    for q, r in ref.items():
        if r["method"] != "RICHARDSON":
            print(f"warning: the reference {q} is a {r['method']} extrapolation: its uncertainty is wide and "
                  "errors below it are not resolved")
    err = errors(runs, ref)
    data["reference"] = ref
    data["pareto"] = {q: pareto(runs, err, q) for q in QUANTITIES}
    out.write_text(json.dumps(data, indent=2) + "\n")
    title = (f"{scene.name}: error vs wall time (2 threads); reference = h -> 0 extrapolation of h = "
             f"{', '.join(f'{h:g}' for h in ladder)} µm")
    plot(runs, ref, err, title, RESULTS / f"work_precision_{args.scene}.png")
    print(table(runs, ref, err))
    print("\nPareto front:", json.dumps(data["pareto"]))


if __name__ == "__main__":
    main()
