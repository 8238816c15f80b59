"""The errors of the fem solver."""

__all__ = ["SolverError"]


class SolverError(RuntimeError):
    """The protocol cannot continue (no convergence, no yielding step found, a hop that broke its promise)."""
