from plough.study.analytical_figures import config_section

# Analytical datasets: all points of a figure in one job (each job costs ~1 s of overhead).


rule analytical_dataset:
    input:
        PACKAGE_SOURCES,
        str(SCRIPTS / "analytical_dataset.py"),
    output:
        "results/datasets/{figure}.nc",
    params:
        config=lambda wc: config[config_section(wc.figure)],
    wildcard_constraints:
        figure="|".join(ANALYTICAL_FIGURES),
    log:
        "logs/datasets/{figure}.log",
    conda:
        "../envs/plough.yaml"
    script:
        "../scripts/analytical_dataset.py"
