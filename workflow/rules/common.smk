# Shared definitions: figure lists, the MPM run matrix, and the package source as an input of
# every rule that runs it (neither the cache key nor the code trigger sees an installed package).
import re
from pathlib import Path

from plough.mpm.scene import Scene
from plough.study import cost, matrix

PACKAGE_SOURCES = sorted(str(p) for p in Path(workflow.basedir, "src", "plough").rglob("*.py"))

# Fig. 22 shows the power-law fits with the MPM points of Fig. 21: its dataset needs MPM runs.
ANALYTICAL_FIGURES = ["fig03", "fig04"]
MPM_DATASET_FIGURES = [*matrix.MPM_FIGURES, "fig22"]
ALL_FIGURES = sorted(ANALYTICAL_FIGURES + MPM_DATASET_FIGURES)

# MPM run matrix: run id -> complete scene (SI); a scene shared by several figures appears once.
MPM_RUNS = matrix.all_runs(config)
MPM_THREADS = int(config["mpm"]["threads"])
# particles and steps of every run, for the memory and wall-time requests of cluster jobs
MPM_COST = {rid: cost.estimate(Scene.from_dict(scene)) for rid, scene in MPM_RUNS.items()}
# finest-size runs that may be skipped (mpm.skip_finest_tolerance): run id -> its two coarser runs
SKIPPABLE = matrix.skippable_runs(config)
SKIP_TOLERANCE = config["mpm"].get("skip_finest_tolerance")


def runs_of(figure):
    """run id -> result file of every run a figure's dataset needs."""
    return {rid: f"results/runs/{rid}.nc" for rid in matrix.figure_runs(config, figure)}


wildcard_constraints:
    figure="|".join(ALL_FIGURES),
