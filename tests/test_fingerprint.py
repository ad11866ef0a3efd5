"""plough.fingerprint: which modules make the solver, and what changes its fingerprint."""

from __future__ import annotations

import shutil
from pathlib import Path

from plough.fingerprint import PACKAGE, solver_files, solver_fingerprint


def _names(package: Path) -> set[str]:
    return {f.relative_to(package).as_posix() for f in solver_files(package)}


def test_the_solver_is_the_mpm_package_and_the_materials_but_not_the_verification_set_ups():
    names = _names(PACKAGE)
    assert {"mpm/transfers.py", "mpm/contact.py", "mpm/constitutive.py", "mpm/__init__.py", "materials.py"} <= names
    assert "mpm/indentation.py" not in names
    assert not any(n.startswith(("study/", "figures/", "analytical/")) for n in names)


def test_code_changes_the_fingerprint_a_comment_or_a_verification_set_up_does_not(tmp_path):
    package = tmp_path / "plough"
    shutil.copytree(PACKAGE, package, ignore=shutil.ignore_patterns("__pycache__"))
    before = solver_fingerprint.__wrapped__(package)
    contact = package / "mpm" / "contact.py"
    contact.write_text(contact.read_text() + "\n# a comment\n")
    (package / "mpm" / "indentation.py").write_text("R_M = 1.0\n")
    assert solver_fingerprint.__wrapped__(package) == before
    contact.write_text(contact.read_text() + "\nEXTRA = 1\n")
    assert solver_fingerprint.__wrapped__(package) != before
