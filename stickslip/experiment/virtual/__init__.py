"""Virtual lever experiment: the paper's apparatus with aging, disordered, creeping interfaces.

:mod:`.apparatus` (statics of slabs, springs and lever), :mod:`.friction` (aging law,
disorder, creep onset), :mod:`.history` (event-by-event integration), :mod:`.sensors`
(camera and force sensor). The model and its equations: docs/experiment-model.md.
"""

from .apparatus import Apparatus
from .friction import FrictionLaw, first_crossing
from .history import SlipHistory, integrate
from .sensors import record, relative_positions, sample_times

__all__ = ["Apparatus", "FrictionLaw", "first_crossing", "SlipHistory", "integrate", "record",
           "relative_positions", "sample_times"]
