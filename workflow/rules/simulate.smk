# One rule for every solver: the solver is a wildcard (a path component), chosen in the config. The job
# receives its upstream files (the mesh) with their lineage (params.inputs). A run on a GPU (fem, backend cuda)
# is made by rule simulate_gpu, the same rule asking for a GPU; runs of a GPU batch (config gpu_batch,
# stickslip.study_plan.device_batches) by one job of their batch's rule, each to its usual file. Every job on a GPU
# has the resources that a profile sets for simulate_gpu (GPU_RULE, common.smk: a GPU partition, profiles/slurm).
# Runs at a finite temperature start first (Study.run_priority: their analyses may replay them for as long again).


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
    priority: lambda wildcards: STUDY.run_priority(wildcards.solver, wildcards.run_id)
    wildcard_constraints:
        run_id=STUDY.single_runs(on_gpu=False),
    params:
        params=lambda wildcards: Study.dumps(STUDY.simulation(wildcards.solver, wildcards.run_id).params),
        inputs=lambda wildcards: Study.dumps(STUDY.solver_inputs(wildcards.solver, wildcards.run_id)),
        code=lambda wildcards: STUDY.simulation_code(wildcards.solver, wildcards.run_id),
        module=lambda wildcards: Study.module("solver", wildcards.solver),
    conda:
        CONDA_ENV
    script:
        "../scripts/simulate.py"


use rule simulate as simulate_gpu with:
    wildcard_constraints:
        run_id=STUDY.single_runs(on_gpu=True),
    resources:
        gpu=1,


for BATCH in STUDY.batches:

    rule:
        name:
            f"simulate_batch_{BATCH.batch_id}"
        input:
            sorted({str(path) for sim in BATCH.runs for path in STUDY.solver_inputs(sim.solver, sim.run_id).values()}),
        output:
            h5=[sim.path for sim in BATCH.runs],
            record=[record_of(sim.path) for sim in BATCH.runs],
        log:
            STUDY.log(f"sim/{BATCH.solver}/batch-{BATCH.batch_id}"),
        threads: STUDY.threads
        resources:
            gpu=1,
        params:
            solver=BATCH.solver,
            params=[Study.dumps(sim.params) for sim in BATCH.runs],
            inputs=[Study.dumps(STUDY.solver_inputs(sim.solver, sim.run_id)) for sim in BATCH.runs],
            code=[STUDY.simulation_code(sim.solver, sim.run_id) for sim in BATCH.runs],
            module=Study.module("solver", BATCH.solver),
        conda:
            CONDA_ENV
        script:
            "../scripts/simulate_batch.py"

    with_gpu_rule_resources(f"simulate_batch_{BATCH.batch_id}")
