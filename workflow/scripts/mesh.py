"""Rule mesh: write one mesh (stickslip.workflow_api.run_mesh)."""

from stickslip.workflow_api import run_mesh

run_mesh(snakemake.params.params, snakemake.output.h5, snakemake.output.record, snakemake.log[0],
         numba_cache=snakemake.resources.get("numba_cache", "shared"))
