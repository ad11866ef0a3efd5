"""The stability test's scene (examples/stability_small.yaml, sized block) at the CFL numbers given: mu, the mean
normal force over the load, the energy parts over the work (2026-12-03-consistent-pressure.md). Run from the
repository root: python docs/journal/2026-12-03-consistent-pressure/cfl_probe.py 0.3 0.5"""

import json
import sys

sys.path.insert(0, "tests/mpm")

import numba  # noqa: E402
from test_stability import scene  # noqa: E402

from plough.mpm.io import energy_balance  # noqa: E402
from plough.mpm.run import simulate  # noqa: E402

numba.set_num_threads(2)
for cfl in [float(a) for a in sys.argv[1:]]:
    s = scene(discretisation={"cfl": cfl})
    ds = simulate(s, progress=False)
    print(json.dumps(dict(cfl=cfl, mu=round(float(ds.mu), 4), fz_over_load=round(float(ds.Fz_mean) / s.load_N, 3),
                          energy=round(energy_balance(ds), 3), steady=float(ds.steady))), flush=True)
