"""fastmath on p2g / g2p_kinematics against the exact build: mu and dp of the lattice-phase cases, phase by phase
(a throwaway of the 2026-12-02 throughput entry; run from the repository root).

The two files: `python benchmarks/lattice_phase.py --cases uncoated:20 coated:20 real:20 coated:10 --phases 8
--out FILE`, run with each tree first on PYTHONPATH, one locked command."""
import json
from pathlib import Path

import numpy as np

HERE = Path(__file__).parent
exact = json.loads((HERE / "fastmath_lattice_phase_exact.json").read_text())
fast = json.loads((HERE / "fastmath_lattice_phase_fastmath.json").read_text())
for ca, cb in zip(exact["cases"], fast["cases"], strict=True):
    print(f"{ca['scene']} h = {ca['h_um']:g} um:")
    for q in ("mu", "dp"):
        va = np.array([r[q] for r in ca["runs"]])
        vb = np.array([r[q] for r in cb["runs"]])
        rel = (vb - va) / va
        print(f"  {q}: relative spread (std) over the phases {va.std(ddof=1) / va.mean():.2%}; fastmath - exact, "
              f"relative, phase by phase: " + " ".join(f"{x:.1e}" for x in rel)
              + f"; largest |.| {np.abs(rel).max():.1e}")
    wa = sum(r["wall_s"] for r in ca["runs"])
    wb = sum(r["wall_s"] for r in cb["runs"])
    print(f"  wall of the 8 runs: exact {wa:.1f} s, fastmath {wb:.1f} s (the lock's load, not a benchmark)")
