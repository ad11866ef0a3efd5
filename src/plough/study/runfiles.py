"""Run files as the workflow reads them: each checked against the run it stands for.

A run's result file (``results/runs/<run id>.nc``, a skip or failure marker included) records the
scene it ran (attribute ``scene``, JSON, SI) and, when the workflow wrote it, the fingerprint of the
solver that made it (``solver_fingerprint``, :mod:`plough.fingerprint`). Every reader of run files
(the figure datasets, the skip decision of a finest run) loads them through :func:`load_run`, which
refuses, in one line naming the file and saying how to remake it, a file that cannot be read, one
that holds another run's scene (another point, another particle size, other numerics) and one made
by another solver. The workflow never reads a run silently as another.

:func:`figure_view` is the part of the config a figure's dataset reads: the workflow's dataset rule
takes it as its params, so that a config change reruns exactly the datasets whose points changed.
"""

from __future__ import annotations

import dataclasses
import json
from collections.abc import Mapping
from pathlib import Path
from typing import Any

import xarray as xr

from plough.io import to_json
from plough.study import matrix

#: The attribute holding the fingerprint of the solver that made a run file.
SOLVER_ATTR = "solver_fingerprint"


def remedy(path: str | Path) -> str:
    """What to do about a bad run file. Forced, not deleted: Snakemake remakes a missing file only when
    an output that needs it is to be made, and a dataset built before the file went bad is not."""
    return f"remake it with `snakemake --cores 2 --forcerun {path}`"


class RunFileError(ValueError):
    """A run file that is not the run it is read as, or not readable: one line, naming the file."""

    def __init__(self, path: str | Path, problem: str):
        self.path = str(path)
        super().__init__(f"{path}: {problem}; {remedy(path)}")

    @classmethod
    def unreadable(cls, path: str | Path, run_id: str, exc: BaseException) -> RunFileError:
        detail = (str(exc).strip().splitlines() or [""])[0].replace(f": '{path}'", "")
        if len(detail) > 160:
            detail = detail[:157] + "..."
        return cls(path, f"unreadable as the result of run {run_id} ({type(exc).__name__}: {detail})")


def _differences(found: Any, expected: Any, prefix: str = "") -> list[str]:
    """Key paths where two JSON values differ."""
    if isinstance(found, dict) and isinstance(expected, dict):
        out = []
        for k in sorted(set(found) | set(expected)):
            out += _differences(found.get(k), expected.get(k), f"{prefix}.{k}" if prefix else str(k))
        return out
    return [] if found == expected else [prefix or "(the whole scene)"]


def _size_um(scene: dict[str, Any]) -> float | None:
    try:
        return float(scene["discretisation"]["particle_size_m"]) * 1e6
    except (KeyError, TypeError, ValueError):
        return None


def check_run(ds: xr.Dataset, path: str | Path, run_id: str, scene: Mapping[str, Any] | None = None,
              solver: str | None = None) -> None:
    """Refuse (:class:`RunFileError`) a loaded run file that is not run ``run_id``: its recorded scene
    must be named ``run_id`` and, if ``scene`` is given, equal it (after a JSON round trip, as
    recorded); if ``solver`` is given, its recorded solver fingerprint must equal it."""
    try:
        found = json.loads(ds.attrs["scene"])
        if not isinstance(found, dict):
            raise TypeError("not a JSON object")
    except (KeyError, TypeError, ValueError):
        raise RunFileError(path, f"holds no scene record, so it is not a plough run file for run {run_id}") from None
    name = found.get("name")
    expected = json.loads(to_json(scene)) if scene is not None else None
    if name != run_id or (expected is not None and found != expected):
        what = (f"holds the result of run {name}, not of run {run_id}" if name != run_id
                else f"holds another scene than run {run_id}")
        details = []
        if expected is not None:
            fs, es = _size_um(found), _size_um(expected)
            if fs != es:
                details.append(f"particle size {fs:g} um, not {es:g} um" if fs is not None and es is not None
                               else "particle size differs")
            diff = [d for d in _differences(found, expected)
                    if d not in ("name", "discretisation.particle_size_m")]
            if diff:
                details.append("differs in " + ", ".join(diff[:3]) + (f" and {len(diff) - 3} more" if len(diff) > 3
                                                                        else ""))
        raise RunFileError(path, what + (f" ({'; '.join(details)})" if details else ""))
    if solver is not None:
        made_by = ds.attrs.get(SOLVER_ATTR)
        if made_by is None:
            raise RunFileError(path, f"holds no solver fingerprint (written before run files recorded the solver "
                                     f"that made them), so it cannot be checked against this solver ({solver})")
        if made_by != solver:
            raise RunFileError(path, f"was made by another solver (fingerprint {made_by}; this checkout's solver "
                                     f"is {solver})")


def load_run(path: str | Path, run_id: str, scene: Mapping[str, Any] | None = None,
             solver: str | None = None) -> xr.Dataset:
    """Load the result file of run ``run_id`` and check it (:func:`check_run`): a missing file is a
    FileNotFoundError naming the run; an unreadable or wrong one a :class:`RunFileError`."""
    if not Path(path).exists():
        raise FileNotFoundError(f"the result of run {run_id!r} is missing ({path}); run it first")
    try:
        ds = xr.load_dataset(path, engine="netcdf4")
    except Exception as exc:  # any reader error: a corrupt, truncated, empty or foreign file
        raise RunFileError.unreadable(path, run_id, exc) from exc
    check_run(ds, path, run_id, scene, solver)
    return ds


def figure_view(config: dict[str, Any], figure: str) -> dict[str, Any]:
    """The part of the config the dataset of an MPM figure reads (JSON-serialisable): its runs, its
    points (labels, axes, the physical points with the analytical model's k1), which of its finest
    runs may be a skip or failure marker, and the figure's own extras. Equal views, equal datasets
    (given equal run files)."""
    runs = matrix.figure_runs(config, figure)
    sizes = matrix.particle_sizes_um(config)
    view: dict[str, Any] = {"runs": runs, "particle_sizes_um": list(sizes)}
    sweep = "fig21" if figure == "fig22" else figure
    if sweep in matrix.SINGLE_RUN_FIGURES:
        view["cases"] = {label: dataclasses.asdict(p) for label, p in matrix.figure_points(config, sweep).items()}
    else:
        view["panels"] = [dataclasses.asdict(p) for p in matrix.figure_panels(config, sweep)]
        skippable, recordable = matrix.finest_run_roles(config)
        view["skippable"] = [r for r in runs if r in skippable]
        view["recordable"] = [r for r in runs if r in recordable]
    if figure in ("fig11", "fig13"):
        view["ratio_sweep_thickness_um"] = float(config["mpm"]["rigid_plastic"]["ratio_sweep"]["thickness_um"])
    if figure == "fig22":
        view["power_law"] = config["power_law"]
        view["ball_radii_um"] = [float(x) for x in config["mpm"]["real_materials"]["ball_radii_um"]]
    return json.loads(to_json(view))
