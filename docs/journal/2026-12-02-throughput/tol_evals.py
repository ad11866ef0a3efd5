"""Return-map evaluations against the tolerance (DX56 and the zinc coating's power law, guesses around the root).

Run one tolerance per process, each in a numba cache folder of its own (RETURN_RTOL is frozen into the compiled
code, and numba's cache key does not see it):
    for t in 1e-13 1e-11 1e-10 1e-9; do NUMBA_CACHE_DIR=/tmp/nbc_$t python tol_evals.py $t; done
"""

import os
import sys

import numpy as np
from numba import njit

if not os.environ.get("NUMBA_CACHE_DIR"):  # a loosened tolerance must not land in the solver's own kernel cache
    sys.exit("set NUMBA_CACHE_DIR to a folder of this tolerance's own (see the docstring)")

from plough.materials import DX56, ZINC_COATING  # noqa: E402
from plough.mpm import constitutive as c  # noqa: E402

c.RETURN_RTOL = float(sys.argv[1])


@njit
def count(prm, qs, G, eps, dt, rs, T, sig0, guesses):
    evaluations = 0
    roots = np.empty(qs.size)
    for i in range(qs.size):
        d, _, n = c.return_map_at_rest(prm, prm, 1.0, qs[i], G, eps, dt, rs, T, sig0, guesses[i])
        evaluations += n
        roots[i] = d
    return evaluations, roots


for mat, over in ((DX56, 1e-3), (ZINC_COATING, 1e-2)):
    prm = c.pack_material(mat)
    G = mat.shear_modulus_Pa
    eps, T, dt, rs = 0.1, 300.0, 9.7e-7, 0.01
    sig0 = c.flow_stress(prm, eps, 0.0, T)
    rng = np.random.default_rng(0)
    N = 20_000
    qs = sig0 * (1.0 + over * rng.uniform(0.5, 1.5, N))
    cold, roots = count(prm, qs, G, eps, dt, rs, T, sig0, np.zeros(N))
    for spread in (0.01, 0.1, 0.3):
        warm, _ = count(prm, qs, G, eps, dt, rs, T, sig0, roots * rng.uniform(1 - spread, 1 + spread, N))
        print(mat.name, "rtol", c.RETURN_RTOL, "guess spread", spread, "evaluations", warm / N,
              "(no guess", cold / N, ")")
