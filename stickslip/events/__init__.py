"""Analyses of one fem run: its events and what follows from them.

One analysis per module: :mod:`.extraction` (events from the stored increments), :mod:`.plugin` (the
``numerical-events`` analysis plugin: slips, microscopic events, :mod:`.periodicity` of the slips), :mod:`.fronts`
(time-resolved failures and rupture fronts), :mod:`.thermal` (slips with waiting times, slow slip and the hold
trials of a thermal run, :mod:`.aging_trials`), :mod:`.waiting_times` (the waiting times between the slips of
an interface and their spread); :mod:`.analysis_files` reads their outputs back for figures.
Across runs: :mod:`stickslip.summaries`; statistics: :mod:`stickslip.statistics`.
"""
