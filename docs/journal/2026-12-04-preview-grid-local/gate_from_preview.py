"""The refinement decisions the default config would make, read from the preview's runs.

For every sweep point of `config/config.yaml` the preview (`config/preview.yaml`: the same scenes and numerics,
20 and 10 um for every point) has made the runs at 20 and 10 um: `plough.study.skipping.decide` on them. Where
the point's own ladder's two coarser sizes are 20 and 10 um this is the default workflow's decision for its
finest run ("exact"); elsewhere it is the decision one pair coarser (10 / 5 / 2.5 um ladders) or finer (40 / 20 /
10 um). Each decision is made twice: from the runs as written (their groove errors carry the grid contact's
lattice-phase term, 0.1 h) and with grid_local's term, 0.002 h, in its place (the errors its runs carry since the
term follows the contact). Prints one row a point (dp's relative uncertainty and the decision, with the grid's /
grid_local's term) and writes them as JSON.

    python gate_from_preview.py --runs /path/to/preview/results/runs [--out gate_from_preview.json]
"""

from __future__ import annotations

import argparse
import json
from pathlib import Path

import numpy as np
import xarray as xr
import yaml

from plough.mpm.io import groove_lattice_phase_term_m
from plough.mpm.scene import Scene
from plough.study import matrix, skipping


def with_grid_local_term(run: xr.Dataset) -> xr.Dataset:
    """The run with its groove errors' lattice-phase term (as written: the grid's before the term followed the
    contact) replaced by the one the solver now writes for its contact, which must be grid_local."""
    scene = Scene.from_dict(json.loads(run.attrs["scene"]))
    if scene.discretisation.contact != "grid_local":
        raise SystemExit(f"a preview run with contact {scene.discretisation.contact!r}: this reading needs grid_local")
    new = groove_lattice_phase_term_m(scene)
    run = run.copy()
    for q in ("dp", "dg", "hpu"):
        name = f"{q}_standard_error"
        if name in run:
            term = float(run[name].attrs.get("lattice_phase_term_m", 0.0))
            jackknife = np.sqrt(max(float(run[name]) ** 2 - term**2, 0.0))
            run[name] = run[name].copy(data=np.hypot(jackknife, new))
    return run


def main() -> None:
    parser = argparse.ArgumentParser()
    parser.add_argument("--runs", type=Path, required=True, help="the preview's results/runs folder")
    parser.add_argument("--config", type=Path, default=Path("config/config.yaml"))
    parser.add_argument("--out", type=Path, default=Path(__file__).with_name("gate_from_preview.json"))
    args = parser.parse_args()
    config = yaml.safe_load(args.config.read_text())
    tolerance = config["mpm"]["skip_finest_tolerance"]
    rows = []
    for key, point in matrix.all_points(config).items():
        sizes = matrix.point_ladder(config, point).sizes_um
        coarse, mid = (args.runs / f"{key}_h{h}.nc" for h in ("20", "10"))
        if not (coarse.exists() and mid.exists()):
            continue
        with xr.open_dataset(coarse) as c, xr.open_dataset(mid) as m:
            c, m = c.load(), m.load()
        # the decision itself where the point's own coarser pair is 20 / 10 um (about its finest run), else a pair
        # coarser or finer than its own (about the 5 um run)
        exact = tuple(sizes[:2]) == (20.0, 10.0)
        finest = matrix.run_id(point, sizes[2]) if exact else f"{key}_h5"
        d = skipping.decide(finest, c, m, [coarse.stem, mid.stem], tolerance)
        local = skipping.decide(finest, with_grid_local_term(c), with_grid_local_term(m), [coarse.stem, mid.stem],
                               tolerance)
        d["with_grid_local_term"] = {"run_finest": local["run_finest"], "extrapolations": local["extrapolations"]}
        d["exact"] = exact
        d["ladder_um"] = list(sizes)
        rows.append({"point": key, **d})
        ex, exl = d["extrapolations"], local["extrapolations"]
        print(f"{key:52s} {'/'.join(f'{h:g}' for h in sizes):11s} mu {ex['mu']['value']:.4f} "
              f"rel {ex['mu']['relative_uncertainty']:.3f}  dp {ex['dp']['value'] * 1e6:6.2f} um "
              f"rel {ex['dp']['relative_uncertainty']:.3f} / {exl['dp']['relative_uncertainty']:.3f}  "
              f"{'skip' if not d['run_finest'] else 'run'} / {'skip' if not local['run_finest'] else 'run'}"
              f"{'' if d['exact'] else ' (not its pair)'}")
    args.out.write_text(json.dumps(rows, indent=1))
    exact = [r for r in rows if r["exact"]]
    for label, pick in (("with the grid's lattice-phase term (as the runs were written)", lambda r: r),
                        ("with grid_local's term, 0.002 h (its errors now)", lambda r: r["with_grid_local_term"])):
        print(f"{label}: points whose coarser pair is 20 / 10 um: "
              f"{sum(not pick(r)['run_finest'] for r in exact)} of {len(exact)} finest runs skipped; all points "
              f"(one pair off for most): {sum(not pick(r)['run_finest'] for r in rows)} of {len(rows)}")


if __name__ == "__main__":
    main()
