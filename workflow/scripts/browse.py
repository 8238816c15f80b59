"""Rule browse: the study's pages as a static site (stickslip.browse.site.build_site)."""

from stickslip.workflow_api import build_browse

build_browse(snakemake.params.study, snakemake.output[0], snakemake.log[0])
