# plough: reproduce the figures of Mishra et al. (Wear 2020). See README.md.
#   snakemake --cores 2                                   every figure of studies.md
#   snakemake --cores 2 results/figures/fig03.png         one figure and only what it needs
#   snakemake --cores 2 --configfile=config/smoke.yaml    the CI smoke matrix
from snakemake.utils import min_version, validate

min_version("9.0")


configfile: "config/config.yaml"


report: "workflow/report/workflow.rst"


validate(config, "workflow/schemas/config.schema.yaml")


include: "workflow/rules/common.smk"
include: "workflow/rules/analytical.smk"
include: "workflow/rules/mpm.smk"
include: "workflow/rules/figures.smk"


rule all:
    input:
        expand("results/figures/{figure}.{ext}", figure=ALL_FIGURES, ext=["png", "pdf"]),
    default_target: True
