"""Rule simulate: run one solver (stickslip.workflow_api.run_simulation)."""

from stickslip.workflow_api import run_simulation

run_simulation(snakemake.wildcards.solver, snakemake.params.params, snakemake.output.h5,
               snakemake.output.record, snakemake.log[0], inputs=snakemake.params.inputs,
               threads=snakemake.threads, numba_cache=snakemake.resources.get("numba_cache", "shared"),
               module=snakemake.params.module)
