"""stickslip: stick-slip friction in a stack of elastic slabs.

Simulations (the paper's finite-element model and a virtual lever experiment),
analyses of their outputs and of lab recordings, the paper's figures, and the
provenance database of a Snakemake study. See README.md for the workflow and
docs/tutorial.md for this API:

>>> import stickslip
>>> run = stickslip.simulate("lever", "lab.h5", n=3, seed=1)   # doctest: +SKIP
>>> run.slip_events()                                          # doctest: +SKIP

The public surface is :data:`__all__` (:mod:`stickslip.api`); every other module stays
importable, but is not part of it.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("stickslip")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"

# after __version__: the API's modules read it (the file formats record the version that wrote them)
from .api import open_run, params, plugins, simulate, study  # noqa: E402

__all__ = ["__version__", "simulate", "open_run", "study", "plugins", "params"]
