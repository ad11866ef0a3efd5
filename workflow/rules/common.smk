# Shared definitions: figure lists, the package source as an input of every rule that runs it
# (neither the cache key nor the code trigger sees an installed package).
from pathlib import Path

PACKAGE_SOURCES = sorted(str(p) for p in Path(workflow.basedir, "src", "plough").rglob("*.py"))
ANALYTICAL_FIGURES = ["fig03", "fig04", "fig22"]
ALL_FIGURES = ANALYTICAL_FIGURES


wildcard_constraints:
    figure="|".join(ALL_FIGURES),
