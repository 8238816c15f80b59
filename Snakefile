# stickslip: the whole study, from the config to the figures and the results database.
# `snakemake --cores 2` runs workflow/config/default.yaml; `--configfile FILE` runs another study
# (it replaces the default config, it is not merged with it). Each study writes under results/{study}/
# (the config's `study` key, default: the config file's stem). See docs/workflow.md.

from snakemake.utils import min_version

min_version("9.0")


if not workflow.overwrite_configfiles:

    configfile: "workflow/config/default.yaml"


include: "workflow/rules/common.smk"
include: "workflow/rules/mesh.smk"
include: "workflow/rules/simulate.smk"
include: "workflow/rules/events.smk"
include: "workflow/rules/figures.smk"
include: "workflow/rules/database.smk"
include: "workflow/rules/browse.smk"


report: "workflow/report/workflow.rst"


rule all:
    default_target: True
    input:
        STUDY.outputs(),
        STUDY.path("database"),
