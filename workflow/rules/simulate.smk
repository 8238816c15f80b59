# One rule for every solver: the solver is a wildcard (a path component), chosen in the config.


rule simulate:
    input:
        unpack(lambda wildcards: STUDY.solver_inputs(wildcards.solver, wildcards.run_id)),
    output:
        h5=PATHS["simulation"],
        record=record_of(PATHS["simulation"]),
    log:
        "logs/sim/{solver}/{run_id}.log",
    benchmark:
        "logs/benchmarks/sim/{solver}/{run_id}.tsv"
    threads: STUDY.threads
    params:
        params=lambda wildcards: Study.dumps(STUDY.simulation(wildcards.solver, wildcards.run_id).params),
        code=lambda wildcards: Study.code("solver", wildcards.solver),
    conda:
        CONDA_ENV
    script:
        "../scripts/simulate.py"
