"""A study in the browser: its runs, each run's page and each figure's page, read only.

:func:`~stickslip.browse.site.build_site` writes the pages of a study (Jinja2 templates, one static site: HTML,
the figures' PNGs, each simulation's increments plotted as a PNG, a small script that filters and sorts the tables;
nothing fetched from elsewhere); :func:`~stickslip.browse.server.serve` serves a folder of them on the loopback
address with Python's own HTTP server, which answers GET and HEAD only. ``stickslip browse`` does both; the
workflow's ``browse`` rule writes the static export (``results/{study}/browse/``).
"""
