"""Scenes the benchmark scripts share (imported as ``common`` when a script runs from benchmarks/)."""

from __future__ import annotations

from dataclasses import replace
from pathlib import Path

from plough.mpm.scene import Scene

ROOT = Path(__file__).resolve().parents[1]


def coated_reference(h_um: float) -> Scene:
    """examples/coated_rigid_plastic.yaml (H~ = 0.5, t = 25 um, r = 0.2 mm, 3 N, f = 1) at particle size
    ``h_um`` on the block sized from the expected contact."""
    base = Scene.from_yaml(ROOT / "examples" / "coated_rigid_plastic.yaml")
    return replace(base, discretisation=replace(base.discretisation, particle_size_m=h_um * 1e-6)).with_sized_domain()
