"""A second solver of the ``fem-run`` format, registered through an entry point only.

``fem-twin`` is a thin wrapper around the package's ``fem`` solver under another name, as a
third-party backend (another kernel set, a GPU) would be: it declares the formats it consumes
(``mesh``) and produces (``fem-run``) and offers the event replay of the files it writes.
The package's analyses, figures and database take its runs with no edit
(tests/test_second_solver.py).
"""

from stickslip.fem.parameters import FemParams
from stickslip.fem.replay import EventReplay
from stickslip.registry import register
from stickslip.solvers import fem


@register("solver", "fem-twin", "1", FemParams, consumes=("mesh",), produces="fem-run", replay=EventReplay)
def run(params, output, *, threads, inputs):
    """The fem model under another name (test plugin: a second fem-run solver)."""
    fem.run(params, output, threads=threads, inputs=inputs)
