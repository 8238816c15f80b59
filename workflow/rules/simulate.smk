# One rule for every solver: the solver is a wildcard (a path component), chosen in the config. The job
# receives its upstream files (the mesh) with their lineage (params.inputs).


rule simulate:
    input:
        unpack(lambda wildcards: {k: str(v) for k, v in STUDY.solver_inputs(wildcards.solver, wildcards.run_id).items()}),
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
        inputs=lambda wildcards: Study.dumps(STUDY.solver_inputs(wildcards.solver, wildcards.run_id)),
        code=lambda wildcards: Study.code("solver", wildcards.solver),
        module=lambda wildcards: Study.module("solver", wildcards.solver),
    conda:
        CONDA_ENV
    script:
        "../scripts/simulate.py"
