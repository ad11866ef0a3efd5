"""Issue 32's f = 0.5 targets with the groove errors of this change: the coated and uncoated rigid-plastic
reference scenes at f = 0.5 (below the wave limit), workflow numerics, h = 20 / 10 / 5 um, each extrapolated
to h -> 0 with its uncertainty (GCI-type and the runs' errors carried to the limit, in quadrature) against the
analytical model.

    python docs/journal/2026-12-02-groove-uncertainty/f05_ladder.py [--sizes-um 20 10 5] [--scenes coated uncoated]
        [--threads 2] [--out FILE]

Writes f05_ladder.json beside this file (or FILE) and prints a table.
"""

from __future__ import annotations

import argparse
import json
import sys
import warnings
from dataclasses import replace
from pathlib import Path

import numpy as np

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[2] / "benchmarks"))
from common import workflow_scene  # noqa: E402

from plough.analytical import ploughing  # noqa: E402
from plough.io import git_commit  # noqa: E402
from plough.materials import ProportionalShear  # noqa: E402
from plough.mpm.run import simulate  # noqa: E402
from plough.study.extrapolation import Method, extrapolate, sampling_error, total_uncertainty  # noqa: E402

OUTPUTS = ("mu", "mu_pl", "mu_sh", "dp")
MEASURED = ("penetration",)  # recorded beside the outputs, not extrapolated


def analytical(scene) -> dict[str, float]:
    hs = 3.0 * scene.layers.substrate.flow.sigma_y_Pa
    hc = 3.0 * scene.layers.coating.flow.sigma_y_Pa if scene.layers.coated else hs
    res = ploughing(scene.load_N, scene.sphere.radius_m, scene.layers.coating_thickness_m, hc, hs, k1=125.0,
                    interface="proportional", f=scene.interface.f)
    return {o: float(np.asarray(getattr(res, o))) for o in OUTPUTS}


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__, formatter_class=argparse.RawDescriptionHelpFormatter)
    parser.add_argument("--sizes-um", type=float, nargs="+", default=[20.0, 10.0, 5.0])
    parser.add_argument("--scenes", nargs="+", default=["coated", "uncoated"], choices=["coated", "uncoated"])
    parser.add_argument("--threads", type=int, default=2)
    parser.add_argument("--out", type=Path, help="default: f05_ladder.json beside this script (two sizes or more)")
    args = parser.parse_args()
    if args.out is None:
        if len(args.sizes_um) < 2:
            parser.error("one size needs --out FILE: its row alone would overwrite the ladder file beside this script")
        args.out = HERE / "f05_ladder.json"
    out = {"git_commit": git_commit(), "sizes_um": args.sizes_um, "scenes": {}}
    for name in args.scenes:
        runs = []
        for h in args.sizes_um:
            scene = workflow_scene(name, h * 1e-6)
            scene = replace(scene, interface=ProportionalShear(f=0.5))  # the block's size does not depend on f
            with warnings.catch_warnings():
                warnings.simplefilter("ignore")
                ds = simulate(scene, progress=False, threads=args.threads)
            row = {o: float(ds[o]) for o in OUTPUTS}
            row.update({f"{o}_standard_error": float(ds[f"{o}_standard_error"]) for o in OUTPUTS})
            row.update({m: float(ds[m]) for m in MEASURED})
            row.update(h_um=h, steady=int(ds["steady"]), wall_s=float(ds.attrs["cost_wall_time_s"]))
            runs.append(row)
            print(f"  {name} f = 0.5, h = {h:g} um: mu {row['mu']:.4f} +- {row['mu_standard_error']:.4f}, "
                  f"dp {row['dp'] * 1e6:.2f} +- {row['dp_standard_error'] * 1e6:.2f} um, {row['wall_s']:.0f} s",
                  flush=True)
        ana = analytical(scene)
        limits = {}
        for o in OUTPUTS if len(runs) >= 2 else ():  # one size: the run's row alone, no limit
            f = np.array([r[o] for r in runs])
            se = np.array([r[f"{o}_standard_error"] for r in runs])
            ex = extrapolate(args.sizes_um, f)
            s = float(sampling_error(args.sizes_um, f, se))
            total = float(total_uncertainty(float(ex.uncertainty), s))
            limits[o] = {"value": float(ex.value), "uncertainty_gci": float(ex.uncertainty), "sampling_error": s,
                         "uncertainty": total, "relative_uncertainty": total / abs(float(ex.value)),
                         "method": Method(int(ex.method)).name.lower(), "analytical": ana[o],
                         "relative_to_analytical": float(ex.value) / ana[o] - 1.0}
        out["scenes"][name] = {"runs": runs, "limits": limits}
        args.out.write_text(json.dumps(out, indent=1) + "\n")
    print("| scene | output | h -> 0 | method | uncertainty (GCI, sampling) | relative | analytical "
          "| MPM / analytical - 1 |")
    print("|---|---|---|---|---|---|---|---|")
    for name, d in out["scenes"].items():
        for o, lim in d["limits"].items():
            k = 1e6 if o == "dp" else 1.0
            print(f"| {name} | {o} | {lim['value'] * k:.4g} | {lim['method']} | {lim['uncertainty'] * k:.3g} "
                  f"({lim['uncertainty_gci'] * k:.3g}, {lim['sampling_error'] * k:.3g}) | "
                  f"{lim['relative_uncertainty']:.1%} | {lim['analytical'] * k:.4g} | "
                  f"{lim['relative_to_analytical']:+.1%} |")


if __name__ == "__main__":
    main()
