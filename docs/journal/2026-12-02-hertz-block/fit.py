"""The half-space fits of the journal's tables from settled16.jsonl (16 P-wave crossings): F(L) = F_inf (1 + A / L).

Run from the repository root: python docs/journal/2026-12-02-hertz-block/fit.py
"""

import json
import math
from collections import defaultdict
from pathlib import Path

from plough.mpm.indentation import R_M, half_space_extrapolation

rows = [json.loads(line) for line in (Path(__file__).parent / "settled16.jsonl").read_text().splitlines()]
groups = defaultdict(dict)
for r in rows:
    groups[(r["contact"], r["sweeps"], r["h_um"], r["depth_um"])][r["domain_um"]] = 1.0 + r["error"]
for (mode, sweeps, h, d), by_L in sorted(groups.items()):
    blocks = ", ".join(f"L={L:g}: {f - 1:+.4f}" for L, f in sorted(by_L.items()))
    if len(by_L) < 2:
        print(f"{mode} sweeps={sweeps} h={h:g} d={d:g}: {blocks}")
        continue
    Ls = sorted(by_L)
    f_inf, a = half_space_extrapolation([L * 1e-6 for L in Ls], [by_L[L] for L in Ls])
    resid = [by_L[L] - f_inf * (1 + a / (L * 1e-6)) for L in Ls]
    print(f"{mode} sweeps={sweeps} h={h:g} d={d:g}: {blocks}; half-space {f_inf - 1:+.4f}, A = {a * 1e6:.1f} um "
          f"({a / math.sqrt(R_M * d * 1e-6):.2f} a), residuals {max(abs(x) for x in resid):.4f}")
