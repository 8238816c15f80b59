"""The errors of the fem solver."""

from ..errors import SolverError

__all__ = ["SolverError"]
