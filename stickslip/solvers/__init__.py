"""Solver plugins: turn parameters into simulation output files (``fem``, ``lever``)."""
