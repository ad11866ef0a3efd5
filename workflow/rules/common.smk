# Shared definitions: figure lists, the package source as an input of every rule that runs it
# (neither the cache key nor the code trigger sees an installed package).
from pathlib import Path

PACKAGE_SOURCES = sorted(str(p) for p in Path(workflow.basedir, "src", "plough").rglob("*.py"))
import re

from plough.study.matrix import MPM_FIGURES

# Fig. 22 shows the power-law fits with the MPM points of Fig. 21: its dataset needs MPM runs.
ANALYTICAL_FIGURES = ["fig03", "fig04"]
MPM_DATASET_FIGURES = [*MPM_FIGURES, "fig22"]
ALL_FIGURES = sorted(ANALYTICAL_FIGURES + MPM_DATASET_FIGURES)


wildcard_constraints:
    figure="|".join(ALL_FIGURES),
