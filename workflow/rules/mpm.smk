# MPM runs (one per job, cached by file), their extrapolation to h -> 0, and the figure datasets.
# The run matrix and its helpers are defined in common.smk.


# numba compiles its kernels into __pycache__ on first use; parallel first compilations of
# cache=True functions can race, so one small scene compiles them before the runs fan out.
rule numba_warmup:
    input:
        PACKAGE_SOURCES,
    output:
        touch("results/.numba_warm"),
    log:
        "logs/numba_warmup.log",
    conda:
        "../envs/plough.yaml"
    script:
        "../scripts/numba_warmup.py"


# The whole scene (materials expanded, SI) is the job's params: changing one material parameter
# reruns exactly the runs that use it. The package source is an input for the same reason.
# A skippable finest-size run first reads its point's two coarser runs: if their extrapolation is
# within mpm.skip_finest_tolerance its result file is a skip marker (plough.study.skipping). The
# skip params are None for every other run, so they never trigger reruns of those; changing the
# tolerance reruns every skippable finest run (its params change): choose it before they run.
rule mpm_run:
    input:
        PACKAGE_SOURCES,
        warm="results/.numba_warm",
        coarser=lambda wc: [f"results/runs/{r}.nc" for r in SKIPPABLE.get(wc.run, ())],
    output:
        "results/runs/{run}.nc",
    params:
        scene=lambda wc: MPM_RUNS[wc.run],
        skip_tolerance=lambda wc: SKIP_TOLERANCE if wc.run in SKIPPABLE else None,
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


rule mpm_dataset:
    input:
        PACKAGE_SOURCES,
        runs=lambda wc: list(runs_of(wc.figure).values()),
    output:
        "results/datasets/{figure}.nc",
    params:
        mpm=config["mpm"],
        power_law=lambda wc: config["power_law"] if wc.figure == "fig22" else None,
        runs=lambda wc: runs_of(wc.figure),
    wildcard_constraints:
        figure="|".join(MPM_DATASET_FIGURES),
    log:
        "logs/datasets/{figure}.log",
    conda:
        "../envs/plough.yaml"
    script:
        "../scripts/mpm_dataset.py"
