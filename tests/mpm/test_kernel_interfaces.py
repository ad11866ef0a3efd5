"""The kernels' interfaces stay readable (issue 33): every numba kernel of plough.mpm takes at most 12
parameters; the particle, grid, material, sphere and zone data travel as the named bundles of plough.mpm.bundles."""

from __future__ import annotations

import ast
from pathlib import Path

import plough.mpm

MAX_KERNEL_PARAMETERS = 12


def _kernels() -> list[tuple[str, str, int]]:
    """(file, function, parameter count) of every function decorated with numba's njit in plough/mpm."""
    out = []
    for path in sorted(Path(plough.mpm.__file__).parent.glob("*.py")):
        for node in ast.walk(ast.parse(path.read_text())):
            if not isinstance(node, ast.FunctionDef):
                continue
            names = {(d.func if isinstance(d, ast.Call) else d) for d in node.decorator_list}
            if any(isinstance(n, ast.Name) and n.id == "njit" for n in names):
                a = node.args
                out.append((path.name, node.name, len(a.posonlyargs) + len(a.args) + len(a.kwonlyargs)))
    return out


def test_the_scan_finds_the_kernels():
    found = {(f, name) for f, name, _ in _kernels()}
    assert {("transfers.py", "p2g"), ("transfers.py", "g2p_update"), ("contact.py", "sphere_contact"),
            ("shape.py", "stencil")} <= found
    assert len(found) > 30


def test_no_kernel_takes_more_than_twelve_parameters():
    wide = [(f, name, n) for f, name, n in _kernels() if n > MAX_KERNEL_PARAMETERS]
    assert not wide, f"kernels with more than {MAX_KERNEL_PARAMETERS} parameters: {wide}"
