# MPM runs (one per job, identified by scene and solver), their extrapolation to h -> 0, and the figure
# datasets.
# The run matrix and its helpers are defined in common.smk.


# A run is its scene and its solver. The whole scene (materials expanded, SI) and the solver's
# fingerprint are the job's params: changing one material parameter reruns exactly the runs that use
# it, changing the solver's code (not its comments or docstrings) reruns every run, and nothing else
# does: no source file is an input, so neither a figure's code nor a file's time reruns a run, and
# run files copied into another checkout of the same solver are reused. The run script's own code
# (comments and docstrings aside) is a param too, as a skippable run's skip decision code is.
# numba compiles the kernels into __pycache__ on first use; parallel first compilations of cache=True
# functions can race, so the first job of a new solver compiles them while the others wait on a lock
# (workflow/scripts/mpm_run.py); no job depends on a warm-up file, which a copy would lack.
# A skippable finest-size run first reads its point's two coarser runs: if their extrapolation is
# within mpm.skip_finest_tolerance its result file is a skip marker (plough.study.skipping). They are
# inputs for their order and data, ancient() so that remaking a coarser run never redoes a finest
# run that exists (a full run stays valid; a marker's decision is redone when its params change or
# it is forced). The skip params are None for every other run, so they never trigger reruns of
# those; changing the tolerance reruns every skippable finest run (its params change): choose it
# before they run.
rule mpm_run:
    input:
        coarser=lambda wc: [ancient(f"results/runs/{r}.nc") for r in SKIPPABLE.get(wc.run, ())],
    output:
        "results/runs/{run}.nc",
    params:
        scene=lambda wc: MPM_RUNS[wc.run],
        solver=SOLVER_FINGERPRINT,
        run_script=RUN_SCRIPT_FINGERPRINT,
        skip_tolerance=lambda wc: SKIP_TOLERANCE if wc.run in SKIPPABLE else None,
        skip_decision=lambda wc: SKIP_DECISION_FINGERPRINT if wc.run in SKIPPABLE else None,
        coarser_sizes_um=lambda wc: list(matrix.particle_sizes_um(config)[-3:-1]) if wc.run in SKIPPABLE else None,
    wildcard_constraints:
        run="|".join(re.escape(r) for r in MPM_RUNS) if MPM_RUNS else "NO_RUNS",
    threads: MPM_THREADS
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


# A figure's dataset reads its runs' files and the part of the config that places them (its points,
# sizes, which finest runs may be markers: plough.study.runfiles.figure_view), not the whole mpm
# section: a config change redoes exactly the datasets whose points changed. Each run file is checked
# against its run (scene and solver) as it is read.
rule mpm_dataset:
    input:
        PACKAGE_SOURCES,
        str(SCRIPTS / "mpm_dataset.py"),
        runs=lambda wc: list(runs_of(wc.figure).values()),
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
