"""The MPM solver's fingerprint: a short hash of the code a run's result depends on, by meaning.

A run is identified by its scene and by the solver that computed it. The solver is every module of
:mod:`plough.mpm` (the scene, the kernels, the run loop, the result's measurements) and
:mod:`plough.materials` (flow laws, named materials, interfaces): the import closure of
``plough.mpm.run`` less :mod:`plough.io` and the package's ``__init__``, which write provenance (version,
commit) and files, never a number of the result, and less the verification set-ups (``NOT_SOLVER``).

Each module is hashed by its syntax tree with the docstrings removed, printed back as source
(:func:`ast.unparse`): comments, docstrings, blank lines and formatting do not change what the solver
computes, so they do not change the fingerprint; any other edit does (an error message included,
being code). The tree is printed by the running Python, so another Python minor version may print
some constructs differently and give another fingerprint: the safe side (runs are redone, never
wrongly reused).
"""

from __future__ import annotations

import ast
import hashlib
from collections.abc import Iterable
from functools import cache
from pathlib import Path

PACKAGE = Path(__file__).resolve().parent
#: The solver's modules, relative to the plough package (a folder means every module in it).
SOLVER_PARTS = ("mpm", "materials.py")
#: Modules inside those parts that no run's result depends on: the verification set-ups (Hertz, Tabor)
#: that tests and benchmarks build their scenes with (no kernel in them); editing one reruns nothing.
NOT_SOLVER = ("mpm/indentation.py",)
#: Hex digits kept: 64 bits, far beyond any chance collision between two versions of the solver.
DIGITS = 16


def _strip_docstrings(tree: ast.AST) -> ast.AST:
    for node in ast.walk(tree):
        if isinstance(node, ast.Module | ast.ClassDef | ast.FunctionDef | ast.AsyncFunctionDef):
            body = node.body
            if body and isinstance(body[0], ast.Expr) and isinstance(body[0].value, ast.Constant) \
                    and isinstance(body[0].value.value, str):
                node.body = body[1:] or [ast.Pass()]
    return tree


def normalized_source(text: str) -> str:
    """Python source as its syntax tree without docstrings prints it: comments and layout dropped."""
    return ast.unparse(_strip_docstrings(ast.parse(text)))


def files_fingerprint(files: Iterable[Path], root: Path) -> str:
    """Hash of the normalized source of ``files``, each named by its path relative to ``root``."""
    h = hashlib.sha256()
    for f in sorted(Path(f) for f in files):
        h.update(f.relative_to(root).as_posix().encode() + b"\0")
        h.update(normalized_source(f.read_text(encoding="utf-8")).encode() + b"\0")
    return h.hexdigest()[:DIGITS]


def solver_files(package: Path = PACKAGE) -> list[Path]:
    """The solver's source files in ``package`` (the plough package folder)."""
    files: list[Path] = []
    for part in SOLVER_PARTS:
        p = package / part
        files.extend(sorted(p.glob("*.py")) if p.is_dir() else [p])
    return [f for f in files if f.relative_to(package).as_posix() not in NOT_SOLVER]


@cache
def solver_fingerprint(package: Path = PACKAGE) -> str:
    """The fingerprint of the solver in ``package`` (default: the plough being run)."""
    return files_fingerprint(solver_files(package), package)
