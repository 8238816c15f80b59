# Layered meshes read by the solvers that declare the "mesh" input (fem).


rule mesh:
    output:
        h5=STUDY.path("mesh"),
        record=record_of(STUDY.path("mesh")),
    log:
        STUDY.log("mesh/{mesh_id}"),
    params:
        params=lambda wildcards: Study.dumps(STUDY.meshes[wildcards.mesh_id]),
        code=Study.code("mesh", "mesh") if STUDY.meshes else "",
    conda:
        CONDA_ENV
    script:
        "../scripts/mesh.py"
