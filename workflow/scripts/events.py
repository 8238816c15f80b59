"""Rule events: run one analysis on one simulation (stickslip.workflow_api.run_analysis)."""

from stickslip.workflow_api import run_analysis

run_analysis(snakemake.wildcards.analysis, snakemake.params.params, snakemake.params.simulation, snakemake.output.h5,
             snakemake.output.record, snakemake.log[0], numba_cache=snakemake.resources.get("numba_cache", "shared"),
               module=snakemake.params.module)
