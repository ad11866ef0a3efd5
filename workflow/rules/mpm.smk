# MPM runs (one per job, identified by scene and solver), their extrapolation to h -> 0, and the figure
# datasets.
# The run matrix and its helpers are defined in common.smk.


# A run is its scene and its solver. The whole scene (materials expanded, SI) and the solver's
# fingerprint are the job's params: changing one material parameter reruns exactly the runs that use
# it, changing the solver's code (not its comments or docstrings) reruns every run, and nothing else
# does: no source file is an input, so neither a figure's code nor a file's time reruns a run, and
# run files copied into another checkout of the same solver are reused. The run script's own code
# (comments and docstrings aside) is a param too.
# numba compiles the kernels on first use into a cache folder named by the solver's fingerprint (plough.mpm); parallel first compilations of cache=True
# functions can race, so the first job of a new solver compiles them while the others wait on a lock
# (workflow/scripts/mpm_run.py); no job depends on a warm-up file, which a copy would lack.
# A gated finest run (plough.study.skipping: a sweep point's finest size under mpm.skip_finest_tolerance) is
# made only when the point's refinement decision (checkpoint mpm_refine, below) says the two coarser sizes
# do not extrapolate within the tolerance: nothing of the decision is a param or an input of the run, so
# a finest run, once made, stays valid whatever the tolerance.
rule mpm_run:
    output:
        "results/runs/{run}.nc",
    params:
        scene=lambda wc: MPM_RUNS[wc.run],
        solver=SOLVER_FINGERPRINT,
        run_script=RUN_SCRIPT_FINGERPRINT,
    wildcard_constraints:
        run="|".join(re.escape(r) for r in MPM_RUNS) if MPM_RUNS else "NO_RUNS",
    threads: MPM_THREADS
    priority: lambda wc: MPM_PRIORITY[wc.run]  # the longest first (common.smk)
    resources:
        mem_mb=lambda wc: MPM_COST[wc.run].memory_mb,
        runtime=lambda wc, threads: cost.runtime_minutes(MPM_COST[wc.run], threads),
    log:
        "logs/runs/{run}.log",
    benchmark:
        "benchmarks/runs/{run}.tsv"
    conda:
        "../envs/plough.yaml"
    script:
        "../scripts/mpm_run.py"


# Refinement only where needed (docs/workflow.md): the decision whether a sweep point needs its finest run,
# from its two coarser runs (each checked against its run and this solver, as every run file read). A
# checkpoint: the datasets' inputs are known only once it has run, so `snakemake -n` lists the coarser
# runs and the decisions, and the finest runs only of the points already decided. Its params are the
# tolerance and the decision's code: changing either redoes the decisions (seconds), never a run. Remade
# when a coarser run is (its input is newer).
checkpoint mpm_refine:
    input:
        coarser=lambda wc: [f"results/runs/{r}.nc" for r in SKIPPABLE[wc.run]],
    output:
        "results/refinement/{run}.json",
    params:
        tolerance=SKIP_TOLERANCE,
        decision=SKIP_DECISION_FINGERPRINT,
        coarser=lambda wc: list(SKIPPABLE[wc.run]),
        solver=SOLVER_FINGERPRINT,
    wildcard_constraints:
        run="|".join(re.escape(r) for r in SKIPPABLE) if SKIPPABLE else "NO_RUNS",
    priority: DECISION_PRIORITY  # before any run (common.smk)
    log:
        "logs/refinement/{run}.log",
    conda:
        "../envs/plough.yaml"
    script:
        "../scripts/mpm_refine.py"


# A figure's dataset reads its runs' files, its points' refinement decisions, and the part of the config
# that places them (its points, sizes, which finest runs may be gated or failure markers:
# plough.study.runfiles.figure_view), not the whole mpm section: a config change redoes exactly the
# datasets whose points changed. Each run file is checked against its run (scene and solver) as it is read.
rule mpm_dataset:
    input:
        PACKAGE_SOURCES,
        str(SCRIPTS / "mpm_dataset.py"),
        unpack(dataset_inputs),
    output:
        "results/datasets/{figure}.nc",
    params:
        view=lambda wc: figure_view(config, wc.figure),
        runs=lambda wc: runs_of(wc.figure),
    wildcard_constraints:
        figure="|".join(MPM_DATASET_FIGURES),
    log:
        "logs/datasets/{figure}.log",
    conda:
        "../envs/plough.yaml"
    script:
        "../scripts/mpm_dataset.py"
