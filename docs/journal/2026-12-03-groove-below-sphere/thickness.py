"""Does the trench follow the coating's thickness in particles? Fig. 18's scenes (zinc-coated steel t = 10-55 um and
bulk zinc, 1 mm ball, 22 N) at one particle size, built as the workflow builds them, at the paper's inertia
(journal 2026-12-03-groove-below-sphere.md).

    python docs/journal/2026-12-03-groove-below-sphere/thickness.py --h-um 10 --thickness-um 10 30 55 0 \
        --out docs/journal/2026-12-03-groove-below-sphere/thickness_h10.json

Each run is written to ``--out`` as it finishes (resumable); 0 is the zinc block.
"""

from __future__ import annotations

import argparse
import importlib.util
import json
from pathlib import Path

from plough.io import git_commit

_spec = importlib.util.spec_from_file_location("probe", Path(__file__).with_name("probe.py"))
probe = importlib.util.module_from_spec(_spec)
_spec.loader.exec_module(probe)


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--h-um", type=float, required=True)
    ap.add_argument("--thickness-um", type=float, nargs="+", required=True)
    ap.add_argument("--out", type=Path, required=True)
    a = ap.parse_args()
    data = json.loads(a.out.read_text()) if a.out.exists() else {"commit": git_commit(), "runs": []}
    done = {r["thickness_um"] for r in data["runs"]}
    for t in a.thickness_um:
        if t in done:
            continue
        row = {"thickness_um": t, "h_um": a.h_um, **probe.measure(probe.fig18_scene(t, a.h_um))}
        data["runs"].append(row)
        a.out.write_text(json.dumps(data, indent=1))
        prof = " ".join("nan" if v is None else f"{v * 1e6:.1f}" for v in row["profile_z_m"][:10])
        print(f"t {t:g} um: mu {row['mu']:.4f} penetration {row['penetration'] * 1e6:.2f} centre "
              f"{-row['z_centre_m'] * 1e6:.2f} deepest {row['dg'] * 1e6:.2f} at y {row['y_deepest_m'] * 1e6:.0f} um "
              f"dp {row['dp'] * 1e6:.2f} wall {row['wall_s']:.0f} s | profile {prof}", flush=True)


if __name__ == "__main__":
    main()
