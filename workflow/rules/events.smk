# Analyses: one rule for every analysis plugin; the analysis and the solver are path components.


rule events:
    input:
        PATHS["simulation"],
    output:
        h5=PATHS["events"],
        record=record_of(PATHS["events"]),
    log:
        "logs/events/{analysis}/{solver}/{run_id}.log",
    params:
        params=lambda wildcards: Study.dumps(STUDY.analyses[wildcards.analysis]),
        code=lambda wildcards: Study.code("analysis", wildcards.analysis),
    conda:
        CONDA_ENV
    script:
        "../scripts/events.py"
