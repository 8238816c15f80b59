# The only rule that writes the results database. update(): Snakemake keeps the previous database
# until the job succeeds; the job builds the new one in a temporary file and renames it.


rule database:
    input:
        STUDY.records(),
    output:
        update(STUDY.path("database")),
    log:
        STUDY.log("database"),
    params:
        code=code_hash("stickslip.provenance.ingest"),
    conda:
        CONDA_ENV
    script:
        "../scripts/database.py"
