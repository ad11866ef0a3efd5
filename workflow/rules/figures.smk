# Figures: one PNG and one PDF per figure, drawn from the figure's netCDF dataset.


rule figure:
    input:
        "results/datasets/{figure}.nc",
        PACKAGE_SOURCES,
        str(SCRIPTS / "plot_figure.py"),
    output:
        png=report("results/figures/{figure}.png", caption="../report/figure.rst", category="Figures"),
        pdf="results/figures/{figure}.pdf",
    log:
        "logs/figures/{figure}.log",
    conda:
        "../envs/plough.yaml"
    script:
        "../scripts/plot_figure.py"
