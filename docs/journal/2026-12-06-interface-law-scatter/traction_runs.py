"""The real-material guard points again with ``interface.pressure: traction`` (one-off probe).

    PYTHONPATH=src python docs/journal/2026-12-06-interface-law-scatter/traction_runs.py /work/guardrun OUTDIR \
        KEY:H[,H...] ...

Takes the workflow's scene of each point and size from its run file in the run directory (the main command's
numerics exactly), sets the boundary layer's pressure to ``traction`` and writes ``<KEY>_traction_h<H>.nc`` in
OUTDIR (two threads; an existing file is kept).
"""

from __future__ import annotations

import json
import sys
import time
from pathlib import Path

import xarray as xr

from plough.mpm.io import write_result
from plough.mpm.run import simulate
from plough.mpm.scene import Scene


def main(workdir: Path, outdir: Path, specs: list[str]) -> None:
    outdir.mkdir(parents=True, exist_ok=True)
    for spec in specs:
        key, sizes = spec.split(":")
        for h in sizes.split(","):
            out = outdir / f"{key}_traction_h{h}.nc"
            if out.exists():
                continue
            d = json.loads(xr.open_dataset(workdir / "results" / "runs" / f"{key}_h{h}.nc").attrs["scene"])
            d = dict(d, name=f"{key}_traction_h{h}", interface=dict(d["interface"], pressure="traction"))
            t0 = time.perf_counter()
            write_result(simulate(Scene.from_dict(d), progress=False, threads=2), out)
            print(f"{key} h = {h} um: {time.perf_counter() - t0:.0f} s", flush=True)


if __name__ == "__main__":
    main(Path(sys.argv[1]), Path(sys.argv[2]), sys.argv[3:])
