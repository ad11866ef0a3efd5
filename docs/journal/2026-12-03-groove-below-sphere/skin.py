"""Where the bridged profile still dips: the surface layer's particles around one y bin in every residual section
of one of Fig. 18's scenes (journal 2026-12-03-groove-below-sphere.md, section "The bridged profile").

    python docs/journal/2026-12-03-groove-below-sphere/skin.py --h-um 10 --thickness-um 30 --y-um 35

Runs the scene as the workflow builds it, keeps the final particles (by wrapping ``section_profiles``), and for
each section prints the surface-layer particles within two bins of ``--y-um`` that draw its bridging line (within
``SKIN_BRIDGE_REACH_H`` h along x; y, top face, µm), the span of the pair around the bin's centre, and the bin's
bridged and unbridged heights.
"""

from __future__ import annotations

import argparse
import sys
from pathlib import Path

import numpy as np

from plough.mpm import io as pio

sys.path.insert(0, str(Path(__file__).parent))  # this entry's probe.py: the scene and the quiet run
import probe  # noqa: E402


def main() -> None:
    ap = argparse.ArgumentParser()
    ap.add_argument("--h-um", type=float, required=True)
    ap.add_argument("--thickness-um", type=float, required=True)
    ap.add_argument("--y-um", type=float, required=True)
    a = ap.parse_args()
    scene = probe.fig18_scene(a.thickness_um, a.h_um)
    kept = {}
    original = pio.section_profiles

    def keep(p, *args, **kwargs):
        kept["p"], kept["args"] = p, args
        return original(p, *args, **kwargs)

    pio.section_profiles = keep
    probe.run_quietly(scene)
    pio.section_profiles = original
    p = kept["p"]
    h = scene.discretisation.particle_size_m
    y, bridged, sections = original(p, *kept["args"])
    b = int(np.argmin(np.abs(y - a.y_um * 1e-6)))
    saved = pio.SKIN_BRIDGE_SPAN_H
    pio.SKIN_BRIDGE_SPAN_H = 0.0
    _, raw, _ = original(p, *kept["args"])
    pio.SKIN_BRIDGE_SPAN_H = saved
    sx, sy, top, index = pio.surface_samples(p, h)
    skin = pio.started_at_surface(p)[index]
    print(f"bin y = {y[b] * 1e6:.1f} um; mean bridged {np.nanmean(bridged[:, b]) * 1e6:.2f} um, "
          f"unbridged {np.nanmean(raw[:, b]) * 1e6:.2f} um, neighbours {np.nanmean(bridged[:, b - 1]) * 1e6:.2f} / "
          f"{np.nanmean(bridged[:, b + 1]) * 1e6:.2f} um")
    for s, xs in enumerate(sections):
        band = (np.abs(sx - xs) < pio.SKIN_BRIDGE_REACH_H * h) & skin & (np.abs(sy - y[b]) < 2.5 * h)
        order = np.argsort(sy[band])
        ys, ts = sy[band][order] * 1e6, top[band][order] * 1e6
        k = np.searchsorted(ys, y[b] * 1e6)
        span = ys[k] - ys[k - 1] if 0 < k < ys.size else float("nan")
        pts = " ".join(f"({u:.1f},{t:.1f})" for u, t in zip(ys, ts, strict=True))
        print(f"x {xs * 1e6:7.1f}: bridged {bridged[s, b] * 1e6:6.1f} raw {raw[s, b] * 1e6:6.1f} "
              f"span {span:5.1f} | {pts}")


if __name__ == "__main__":
    main()
