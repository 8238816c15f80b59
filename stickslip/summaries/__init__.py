"""What a study measures across its runs: one module per study, from the analysis files of its runs.

:mod:`.phi_sweep` (slip statistics against the rigidity ratio Phi), :mod:`.size_series` (the paper's numerical
findings against N and the time step), :mod:`.aging_summary` (junction aging: paired holds, the aging rate,
aftershocks), :mod:`.dissonance_summary` (the paper's test of aging replayed: the waiting-time scan, the loading
rates, the contacts' age at the peaks). The analyses of single runs are in :mod:`stickslip.events` (fem runs) and
:mod:`stickslip.experiment` (lab recordings); the statistics they use in :mod:`stickslip.statistics`.
"""
