# Analyses: one rule for every analysis plugin; the analysis and the solver are path components. The job
# receives the lineage of its simulation (run id, solver, format) from the study, never from the path.


rule events:
    input:
        STUDY.path("simulation"),
    output:
        h5=STUDY.path("events"),
        record=record_of(STUDY.path("events")),
    log:
        STUDY.log("events/{analysis}/{solver}/{run_id}"),
    benchmark:
        STUDY.path("events_benchmark")
    params:
        params=lambda wildcards: Study.dumps(STUDY.analyses[wildcards.analysis]),
        simulation=lambda wildcards: Study.dumps(STUDY.simulation(wildcards.solver, wildcards.run_id).artifact()),
        code=lambda wildcards: Study.code("analysis", wildcards.analysis),
        module=lambda wildcards: Study.module("analysis", wildcards.analysis),
    priority: ANALYSIS_PRIORITY
    conda:
        CONDA_ENV
    script:
        "../scripts/events.py"
