# One rule per figure (figure_<name>, "-" as "_"), so that `--forcerun figure_<name>` redraws
# that figure alone. The caption comes from the figure plugin's summary (report/figure.rst).

for _figure, _job in STUDY.figures.items():

    rule:
        name:
            f"figure_{_figure.replace('-', '_')}"
        input:
            [path for paths in _job.inputs.values() for path in paths],
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
            inputs=json.dumps(_job.inputs, sort_keys=True),
            code=Study.code("figure", _figure),
            caption=STUDY.caption(_figure),
        conda:
            CONDA_ENV
        script:
            "../scripts/figure.py"
