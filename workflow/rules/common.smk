# Shared definitions: figure lists, the MPM run matrix, what identifies a run, and the package source
# as an input of the cheap rules (datasets, figures).
#
# What reruns what (docs/workflow.md, "Caching, reruns and recovery"): an MPM run reruns when its
# scene (params) or the solver's fingerprint (params: the hash of plough.mpm and plough.materials
# without comments and docstrings, plough.fingerprint) changes, never for a file's time: its rule
# takes no source file as input. The code trigger (a script newer than its outputs) is off
# (profiles/default, the workflow profile Snakemake reads by itself); the cheap rules take the
# package source and their script as inputs instead, so an edit still redoes them.
import json
import os
import re
from pathlib import Path

from snakemake.exceptions import IncompleteCheckpointException

from plough.fingerprint import files_fingerprint, solver_fingerprint
from plough.mpm.scene import Scene
from plough.study import cost, matrix
from plough.study.runfiles import figure_view

# relative to the working directory: Snakemake records a job's inputs by these names, so a checkout moved
# or copied elsewhere (its results/ and .snakemake/ with it) plans nothing new; absolute names would make
# every dataset and figure look changed there ("Set of input files has changed")
PROJECT = Path(os.path.relpath(workflow.basedir))
PACKAGE_SOURCES = sorted(str(p) for p in Path(PROJECT, "src", "plough").rglob("*.py"))
SCRIPTS = Path(PROJECT, "workflow", "scripts")
# the solver the jobs import (the installed plough), and the run job's own code without comments
SOLVER_FINGERPRINT = solver_fingerprint()
RUN_SCRIPT_FINGERPRINT = files_fingerprint([SCRIPTS / "mpm_run.py"], SCRIPTS)
# a gated finest run's refinement decision (plough.study.skipping) reads the two coarser runs' extrapolation
SKIP_DECISION_FINGERPRINT = files_fingerprint(
    [Path(matrix.__file__).with_name(n) for n in ("skipping.py", "extrapolation.py")], Path(matrix.__file__).parent)

# Fig. 22 shows the power-law fits with the MPM points of Fig. 21: its dataset needs MPM runs.
ANALYTICAL_FIGURES = ["fig03", "fig04"]
MPM_DATASET_FIGURES = [*matrix.MPM_FIGURES, "fig22"]
ALL_FIGURES = sorted(ANALYTICAL_FIGURES + MPM_DATASET_FIGURES)

# MPM run matrix: run id -> complete scene (SI); a scene shared by several figures appears once.
MPM_RUNS = matrix.all_runs(config)
MPM_THREADS = int(config["mpm"]["threads"])
# particles and steps of every run, for the memory and wall-time requests of cluster jobs
MPM_COST = {rid: cost.estimate(Scene.from_dict(scene)) for rid, scene in MPM_RUNS.items()}
# a run's scheduling priority: its counted particle-steps in thousands, so that with several runs at once
# (--cores over mpm.threads) the longest ready run starts first and none is left to finish alone; a
# refinement decision (seconds) goes before any run, so that the finest runs it lets in join the queue at once
MPM_PRIORITY = {rid: int(c.particle_steps // 1e3) for rid, c in MPM_COST.items()}
DECISION_PRIORITY = max(MPM_PRIORITY.values(), default=0) + 1
# finest-size runs made only where needed (mpm.skip_finest_tolerance, checkpoint mpm_refine): run id -> its
# two coarser runs
SKIPPABLE = matrix.skippable_runs(config)
SKIP_TOLERANCE = config["mpm"].get("skip_finest_tolerance")


def refinement_needed(decision_file):
    """Whether a refinement decision (results/refinement/<finest run>.json) asks for its finest run."""
    return bool(json.loads(Path(decision_file).read_text())["run_finest"])


def dataset_inputs(wc):
    """The run files a figure's dataset reads and the refinement decisions it follows (checkpoint mpm_refine,
    mpm.smk): a gated finest run (SKIPPABLE) only once its decision says it is needed. Until a decision is
    made its file (the checkpoint's target) stands in, caught here rather than raised, so that every decision
    of the figure is scheduled at once and the dataset is re-planned as each one lands."""
    runs = runs_of(wc.figure)
    decisions = []
    for finest in [r for r in runs if r in SKIPPABLE]:
        try:
            path = checkpoints.mpm_refine.get(run=finest).output[0]
        except IncompleteCheckpointException as undecided:
            decisions.append(undecided.targetfile)
            del runs[finest]
            continue
        decisions.append(path)
        if not refinement_needed(path):
            del runs[finest]
    return {"runs": list(runs.values()), "decisions": decisions}


def runs_of(figure):
    """run id -> result file of every run a figure's dataset needs."""
    return {rid: f"results/runs/{rid}.nc" for rid in matrix.figure_runs(config, figure)}


wildcard_constraints:
    figure="|".join(ALL_FIGURES),
