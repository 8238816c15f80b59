# One rule per figure (figure_<name>, "-" and "@" as "_"), so that `--forcerun figure_<name>` redraws
# that figure alone. The caption comes from the figure plugin's summary (report/figure.rst). The job
# receives its inputs with their lineage: each analysis output paired with its simulation.

for _figure, _job in STUDY.figures.items():

    rule:
        name:
            f"figure_{_figure.replace('-', '_').replace('@', '_')}"
        input:
            _job.files(),
        output:
            pdf=report(_job.path, caption="../report/figure.rst", category="Figures",
                       labels={"figure": _figure, "format": "PDF"}),
            png=report(_job.path.replace(".pdf", ".png"), caption="../report/figure.rst", category="Figures",
                       labels={"figure": _figure, "format": "PNG"}),
            record=record_of(_job.path),
        log:
            STUDY.log(f"figures/{_figure}"),
        params:
            figure=_figure,
            params=Study.dumps(_job.params),
            inputs=Study.dumps(_job.inputs),
            code=Study.code("figure", _figure),
            module=Study.module("figure", _figure),
            caption=STUDY.caption(_figure),
        conda:
            CONDA_ENV
        script:
            "../scripts/figure.py"
