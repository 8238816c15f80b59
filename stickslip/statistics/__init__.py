"""Statistics of samples of slips: is a shift of the mean resolved, do two samples differ, the Omori law of aftershocks.

Each module is one test or fit with its resolution or confidence interval, on samples that the analyses of
:mod:`stickslip.events` and :mod:`stickslip.experiment` produce: :mod:`.mean_shift` (a two-sample shift of the
mean and the smallest shift detectable), :mod:`.sample_comparison` (two runs' slip statistics compared),
:mod:`.omori` (the Omori-Utsu law fitted by maximum likelihood, bootstrapped over mainshocks), :mod:`.estimator`
(the paper's estimator of the aging rate, Delta mu against ln T, with confidence intervals and its biases),
:mod:`.calibration` (that estimator against the truth: the lab's eye and clock, errors over seeds, calibration
lines), :mod:`.loading_contrast` (an estimator beside the paper's: an interface's loading paths as the instrument, and
the slips it needs), :mod:`.drop_law` (what records of drops and waiting times can tell about aging: the drop law at
equal waiting time).
"""
