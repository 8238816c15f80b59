"""The experiments: time-series format, CSV import, virtual lever experiment and analysis."""
