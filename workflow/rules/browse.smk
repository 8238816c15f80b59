# The study's pages as a static site, read only (stickslip.browse): `snakemake --cores 2 browse` writes
# results/{study}/browse/ (open index.html; `stickslip browse --study NAME` serves them). Not part of `all`: the
# default study's run is left as it is.


rule browse:
    input:
        STUDY.path("database"),
        STUDY.outputs(),
    output:
        directory(f"{STUDY.root}/browse"),
    log:
        STUDY.log("browse"),
    params:
        study=STUDY.name,
        code=code_hash("stickslip.browse.site"),
    conda:
        CONDA_ENV
    script:
        "../scripts/browse.py"
