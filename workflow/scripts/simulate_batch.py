"""Rule simulate_batch_<id>: the runs of one GPU batch (stickslip.workflow_api.run_simulation_batch)."""

from stickslip.workflow_api import run_simulation_batch

run_simulation_batch(snakemake.params.solver, snakemake.params.params, snakemake.output.h5, snakemake.output.record,
                     snakemake.log[0], inputs=snakemake.params.inputs, threads=snakemake.threads,
                     numba_cache=snakemake.resources.get("numba_cache", "shared"), module=snakemake.params.module)
