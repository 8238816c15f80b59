"""stickslip: stick-slip friction in a stack of elastic slabs.

Simulations (the paper's finite-element model and a virtual lever experiment),
analyses of their outputs and of lab recordings, the paper's figures, and the
provenance database of a Snakemake study. See README.md for the workflow.
"""

from importlib.metadata import PackageNotFoundError, version

try:
    __version__ = version("stickslip")
except PackageNotFoundError:  # running from a source tree that is not installed
    __version__ = "0.0.0+unknown"

__all__ = ["__version__"]
