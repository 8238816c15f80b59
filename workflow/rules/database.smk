# The only rule that writes the results database, from the records of the study's jobs and of the simulations added
# to it (results/{study}/added/, stickslip.study(...).add(run)). update(): Snakemake keeps the previous database
# until the job succeeds; the job builds the new one in a temporary file and renames it.


rule database:
    input:
        STUDY.records(),
        STUDY.added_records(),
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
