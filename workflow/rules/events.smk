# Analyses: one rule for every analysis plugin; the analysis and the solver are path components.


rule events:
    input:
        STUDY.path("simulation"),
    output:
        h5=STUDY.path("events"),
        record=record_of(STUDY.path("events")),
    log:
        STUDY.log("events/{analysis}/{solver}/{run_id}"),
    params:
        params=lambda wildcards: Study.dumps(STUDY.analyses[wildcards.analysis]),
        code=lambda wildcards: Study.code("analysis", wildcards.analysis),
    conda:
        CONDA_ENV
    script:
        "../scripts/events.py"
