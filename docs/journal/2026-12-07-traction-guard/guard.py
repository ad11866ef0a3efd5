"""Issue 34's accuracy guard at the three real-material guard points with each boundary-layer pressure (one-off probe).

    PYTHONPATH=src python docs/journal/2026-12-07-traction-guard/guard.py /work/guardrun /work/tractionrun

The same verdicts as ``benchmarks/ladder_guard.py`` (its ``ladder_limits`` and ``verdicts``: each ladder's h -> 0
value of mu, mu_pl, mu_sh and dp with the runs' sampling errors in quadrature; agreement within the two uncertainties in
quadrature; the relative ladder's uncertainty no larger than the paper's), for ``interface.pressure: particles``
(the main command's and the guard's runs, ``<run dir>/results/runs/<point>_h<h>.nc``) and ``traction``
(``2026-12-06-interface-law-scatter/traction_runs.py``'s, ``<dir>/<point>_traction_h<h>.nc``). The run files are
read as they are (the traction runs are of ba5a491's solver, the particles' of 38e49d6's: the fingerprint check
of ``ladder_guard.py`` would refuse them under today's tree).
"""

from __future__ import annotations

import sys
from pathlib import Path

import xarray as xr

ROOT = Path(__file__).resolve().parents[3]
sys.path.insert(0, str(ROOT / "benchmarks"))
sys.path.insert(0, str(ROOT / "docs" / "journal" / "2026-12-06-interface-law-scatter"))

# the three real-material guard points with their relative ladders, and the paper's sizes: the previous probe's
from compare import PAPER, POINTS  # noqa: E402
from ladder_guard import OUTPUTS, ladder_limits, verdicts  # noqa: E402


def abbrev(method: str) -> str:
    """richardson -> R, least_squares -> LS."""
    return "".join(w[0] for w in method.split("_")).upper()


def ladder(path_of, sizes: tuple[float, ...]) -> dict:
    """Each output's limit over ``sizes``: ``ladder_guard.ladder_limits`` on the runs' values, read from the files
    as they are (its ``read_runs`` would check them against today's solver)."""
    ids = [str(path_of(h)) for h in sizes]
    values = {}
    for rid in ids:
        ds = xr.open_dataset(rid)
        values[rid] = {o: float(ds[o]) for o in OUTPUTS} | {
            f"{o}_standard_error": float(ds[f"{o}_standard_error"]) for o in OUTPUTS if f"{o}_standard_error" in ds}
    return ladder_limits(sizes, ids, values, two_sizes=False)


def main(particles_dir: Path, traction_dir: Path) -> None:
    print("| point | pressure | output | relative ladder | paper's ladder | difference / combined | "
          "uncertainty ratio |")
    print("|---|---|---|---|---|---|---|")
    for key, sizes in POINTS.items():
        for pressure, pattern in (("particles", str(particles_dir / "results" / "runs" / f"{key}_h{{h}}.nc")),
                                  ("traction", str(traction_dir / f"{key}_traction_h{{h}}.nc"))):
            def path_of(h: float, pattern: str = pattern) -> Path:
                return Path(pattern.format(h=f"{h:g}"))

            if not all(path_of(h).exists() for h in (*sizes, *PAPER)):
                print(f"| {key} | {pressure} | (runs missing) | | | | |")
                continue
            rel, pap = ladder(path_of, sizes), ladder(path_of, PAPER)
            checks = verdicts(rel, pap)
            for o in OUTPUTS:
                s = 1e6 if o == "dp" else 1.0
                a, b, v = rel[o], pap[o], checks[o]
                print(f"| {key} | {pressure} | {o}{' (µm)' if o == 'dp' else ''} | "
                      f"{a['value'] * s:.4g} ± {a['uncertainty'] * s:.2g} ({abbrev(a['method'])}) | "
                      f"{b['value'] * s:.4g} ± {b['uncertainty'] * s:.2g} ({abbrev(b['method'])}) | "
                      f"{abs(v['difference']) / v['combined_uncertainty']:.2f} "
                      f"({'agree' if v['agree'] else 'DISAGREE'}) | "
                      f"{a['uncertainty'] / b['uncertainty']:.2f}x |")


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]))
