"""Do the h -> 0 bars of three sizes cover the finer runs? The GCI's safety factor before and after (one-off probe).

    PYTHONPATH=src python docs/journal/2026-12-07-gci-safety-factor/finer_runs.py /work/guardrun/results/runs \
        /work/tractionrun /work/lawprobe

Every point with at least four sizes in the given directories (run files ``<point>_h<h>.nc``, read as they are) gives
triples of sizes with one refinement ratio (2 or 1.4); each triple is extrapolated to h -> 0 as the figures do
(``plough.study.extrapolation``) and its bar (the GCI-type uncertainty and the runs' sampling errors carried to the
limit, in quadrature) is set against every run finer than the triple: z = |finer run - limit| / hypot(bar, the finer
run's own standard error). Where three sizes converge at their order, a finer run lies between the finest of them
and the limit, inside any bar at least as wide as the extrapolation distance, so z <= 1; z > 1 says the bar claims
more than the runs bear out. ``before``: Roache's Fs = 1.25 with the observed order for every Richardson limit (the
rule to 2026-12-07); ``after``: today's (Fs = 1.25 within 10% of the formal order 1, else 3; the band's
order at most 1). The fallbacks' bars are the same under both. Triples overlap and most come from one point (the zinc
block at 11 N, eight sizes): the counts describe these runs, not a population.
"""

from __future__ import annotations

import itertools
import re
import sys
from pathlib import Path

import numpy as np
import xarray as xr

from plough.study.extrapolation import SAFETY_FACTOR_THREE_OR_MORE, Method, extrapolate, sampling_error

# the rule before 2026-12-07: Roache's Fs = 1.25 at the observed order for every Richardson limit (a given Fs is that)
BEFORE = {"safety_factor": SAFETY_FACTOR_THREE_OR_MORE}

OUTPUTS = ("mu", "mu_pl", "mu_sh", "dp")


def load(directory: Path) -> dict[str, dict[float, dict[str, float]]]:
    """point -> size (µm) -> output and output_se values, from the run files under ``directory``."""
    points: dict[str, dict[float, dict[str, float]]] = {}
    for path in sorted(directory.glob("*_h*.nc")):
        match = re.fullmatch(r"(.*)_h([0-9.]+)\.nc", path.name)
        with xr.open_dataset(path) as ds:
            if match is None or "mu" not in ds:  # failure and skip markers carry no outputs
                continue
            row = {o: float(ds[o]) for o in OUTPUTS}
            row |= {f"{o}_se": float(ds[f"{o}_standard_error"]) if f"{o}_standard_error" in ds else np.nan
                    for o in OUTPUTS}
        points.setdefault(match.group(1), {})[float(match.group(2))] = row
    return points


def rows(directories: list[Path]) -> list[dict[str, object]]:
    """One row per point, triple of sizes with one ratio, output and run finer than the triple: the limit's
    method and order and the finer run's z under the rule before and today's."""
    out = []
    for directory in directories:
        for key, runs in load(directory).items():
            sizes = sorted(runs)
            if len(sizes) < 4:
                continue
            for triple in itertools.combinations(sizes, 3):
                r21, r32 = triple[1] / triple[0], triple[2] / triple[1]
                finer = [s for s in sizes if s < triple[0]]
                if abs(r21 - r32) > 0.05 or not finer:
                    continue
                h = np.array(triple)
                for o in OUTPUTS:
                    f = np.array([runs[s][o] for s in triple])
                    se = np.array([runs[s][f"{o}_se"] for s in triple])
                    ex = extrapolate(h, f)
                    bar_before = float(extrapolate(h, f, **BEFORE).uncertainty)
                    s = float(np.nan_to_num(sampling_error(h, f, se)))
                    for x in finer:
                        miss = abs(runs[x][o] - float(ex.value))
                        own = float(np.nan_to_num(runs[x][f"{o}_se"]))
                        out.append({"point": key, "triple": triple, "output": o, "finer": x,
                                    "method": Method(int(ex.method)).name.lower(), "order": float(ex.order),
                                    "z_before": miss / np.hypot(np.hypot(bar_before, s), own),
                                    "z_after": miss / np.hypot(np.hypot(float(ex.uncertainty), s), own)})
    return out


def main(directories: list[Path]) -> None:
    """Print the coverage by kind of limit, then every Richardson case."""
    table = rows(directories)
    print("| limits | triples x finer runs | covered (z <= 1) before | after | largest z before | after |")
    print("|---|---|---|---|---|---|")
    for label, keep in (("Richardson", lambda r: r["method"] == "richardson"),
                        ("Richardson, order within 10% of 1", lambda r: r["method"] == "richardson"
                         and abs(r["order"] - 1) <= 0.1),
                        ("Richardson, order above 1.1", lambda r: r["method"] == "richardson" and r["order"] > 1.1),
                        ("Richardson, order below 0.9", lambda r: r["method"] == "richardson" and r["order"] < 0.9),
                        ("least-squares fallback", lambda r: r["method"] == "least_squares")):
        sel = [r for r in table if keep(r)]
        if not sel:
            print(f"| {label} | 0 | | | | |")
            continue
        zb, za = np.array([r["z_before"] for r in sel]), np.array([r["z_after"] for r in sel])
        print(f"| {label} | {len(sel)} | {np.mean(zb <= 1):.0%} | {np.mean(za <= 1):.0%} | {zb.max():.1f} | "
              f"{za.max():.1f} |")
    print()
    print("Richardson limits, one row per triple and finer run:")
    print()
    print("| point | sizes (µm) | output | order | finer run (µm) | z before | z after |")
    print("|---|---|---|---|---|---|---|")
    for r in table:
        if r["method"] == "richardson":
            sizes = " / ".join(f"{s:g}" for s in r["triple"][::-1])
            print(f"| {r['point']} | {sizes} | {r['output']} | {r['order']:.2f} | {r['finer']:g} | "
                  f"{r['z_before']:.2f} | {r['z_after']:.2f} |")


if __name__ == "__main__":
    main([Path(a) for a in sys.argv[1:]])
