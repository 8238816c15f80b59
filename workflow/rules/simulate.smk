# One rule for every solver: the solver is a wildcard (a path component), chosen in the config.


rule simulate:
    input:
        unpack(lambda wildcards: STUDY.solver_inputs(wildcards.solver, wildcards.run_id)),
    output:
        h5=STUDY.path("simulation"),
        record=record_of(STUDY.path("simulation")),
    log:
        STUDY.log("sim/{solver}/{run_id}"),
    benchmark:
        STUDY.path("benchmark")
    threads: STUDY.threads
    params:
        params=lambda wildcards: Study.dumps(STUDY.simulation(wildcards.solver, wildcards.run_id).params),
        code=lambda wildcards: Study.code("solver", wildcards.solver),
    conda:
        CONDA_ENV
    script:
        "../scripts/simulate.py"
