"""Probe (2026-12-03 part of 2026-12-02-throughput.md): does the per-row switch from indexing the weight tuples by a
run-time (a, b) cost? The kinematics' gather (velocity, FLIP increment, APIC matrix; no dilatation scatter), looped
as the kernel is against fully unrolled (generated source), one thread, an elastic lattice block.
Usage: PYTHONPATH=TREE/src python unroll_probe.py"""

import time

import numba
import numpy as np
from numba import njit

from plough.mpm.shape import stencil, stencil_axis_offset, stencil_row_weight

numba.set_num_threads(1)
FASTMATH = {"contract", "arcp", "nsz", "reassoc", "afn"}
# the body shared by both versions: node ``node`` of weight ``w`` and z offset ``d2`` in row (d0, d1)
NODE = """
g0 = grid_v[node, 0]
g1 = grid_v[node, 1]
g2 = grid_v[node, 2]
gv0 = w * g0
gv1 = w * g1
gv2 = w * g2
v0 += gv0
v1 += gv1
v2 += gv2
dv0 += w * (g0 - grid_v[node, 3])
dv1 += w * (g1 - grid_v[node, 4])
dv2 += w * (g2 - grid_v[node, 5])
b00 += gv0 * d0
b01 += gv0 * d1
b02 += gv0 * d2
b10 += gv1 * d0
b11 += gv1 * d1
b12 += gv1 * d2
b20 += gv2 * d0
b21 += gv2 * d1
b22 += gv2 * d2
"""
HEAD = """
def {name}(x, grid_v, origin, inv_dx, dx, ny, nz, out):
    for p in range(x.shape[0]):
        st = stencil(x, p, origin, inv_dx)
        wx0, wx1, wx2 = st.wx
        wy0, wy1, wy2 = st.wy
        wz0, wz1, wz2 = st.wz
        bx, by, bz = st.base
        gx, gy, gz = st.g
        v0 = v1 = v2 = dv0 = dv1 = dv2 = 0.0
        b00 = b01 = b02 = b10 = b11 = b12 = b20 = b21 = b22 = 0.0
"""
TAIL = """
        out[p, 0] = v0 + dv0 + b00 + b11 + b22
        out[p, 1] = v1 + dv1 + b01 + b12 + b20
        out[p, 2] = v2 + dv2 + b02 + b10 + b21
"""


def indent(text: str, n: int) -> str:
    return "\n".join(" " * n + line for line in text.strip().splitlines())


looped_src = HEAD.format(name="looped") + indent("""
for a in range(3):
    for b in range(3):
        row, wab, d0, d1 = stencil_row_weight(st, a, b, ny, nz, dx)
        for cc in range(3):
            w = wab * st.wz[cc]
            d2 = stencil_axis_offset(st, 2, cc, dx)
            node = row + cc
""", 8) + "\n" + indent(NODE, 20) + TAIL
unrolled_src = HEAD.format(name="unrolled")
for a in range(3):
    for b in range(3):
        unrolled_src += indent(f"""
row = ((bx + {a}) * ny + (by + {b})) * nz + bz
wab = wx{a} * wy{b}
d0 = (bx + {a} - gx) * dx
d1 = (by + {b} - gy) * dx
""", 8) + "\n"
        for cc in range(3):
            head = f"w = wab * wz{cc}\nd2 = (bz + {cc} - gz) * dx\nnode = row + {cc}\n"
            unrolled_src += indent(head + NODE, 8) + "\n"
unrolled_src += TAIL
ns = {"stencil": stencil, "stencil_row_weight": stencil_row_weight, "stencil_axis_offset": stencil_axis_offset}
exec(looped_src, ns)
exec(unrolled_src, ns)
looped = njit(fastmath=FASTMATH)(ns["looped"])
unrolled = njit(fastmath=FASTMATH)(ns["unrolled"])

DX = 10e-6
cells = (60, 30, 30)
shape = np.array([c + 6 for c in cells])
h = DX / 2
k = [np.arange(2 * c) for c in cells]
idx = np.stack(np.meshgrid(*k, indexing="ij"), -1).reshape(-1, 3)
x = 3 * DX + (idx + 0.5) * h
grid_v = np.random.default_rng(1).normal(0, 1e-3, (int(np.prod(shape)), 6))
out1 = np.zeros((x.shape[0], 3))
out2 = out1.copy()
args = (x, grid_v, np.zeros(3), 1 / DX, DX, int(shape[1]), int(shape[2]))
looped(*args, out1)
unrolled(*args, out2)
print("max rel diff", np.max(np.abs(out1 - out2)) / np.max(np.abs(out1)))
for _ in range(3):
    for name, f, o in (("looped", looped, out1), ("unrolled", unrolled, out2)):
        t = time.process_time()
        f(*args, o)
        print(name, round(1e9 * (time.process_time() - t) / x.shape[0], 1), "ns")
