"""Rules figure_<name>: draw one figure (stickslip.workflow_api.run_figure)."""

from stickslip.workflow_api import run_figure

run_figure(snakemake.params.figure, snakemake.params.params, snakemake.params.inputs, snakemake.output.pdf,
           snakemake.output.record, snakemake.log[0], numba_cache=snakemake.resources.get("numba_cache", "shared"),
           module=snakemake.params.module)
