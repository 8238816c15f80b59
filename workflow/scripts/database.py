"""Rule database: build the results database from every record (stickslip.workflow_api.build_database)."""

from stickslip.workflow_api import build_database

build_database(snakemake.input, snakemake.output[0], snakemake.log[0])
