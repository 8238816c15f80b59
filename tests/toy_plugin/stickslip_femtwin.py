"""A second solver of the ``fem-run`` format, registered through an entry point only.

``fem-twin`` runs the package's fem model under another name, as a third-party solver of
the format would: it declares the formats it consumes (``mesh``) and produces (``fem-run``),
writes the format through its writer with its own name as the producer, and offers the event
replay of the files it writes. What it proves is the workflow's seam: the package's analyses,
figures and database take its runs with no edit (tests/test_second_solver.py). The execution
backends of the fem model (another kernel set, a GPU) are a seam of their own, inside the
solver: tests/test_fem_backends.py runs the same events through two of them.
"""

from stickslip.fem.backends import make_backend
from stickslip.fem.parameters import FemParams
from stickslip.fem.replay import EventReplay
from stickslip.fem.run import simulate_to_file
from stickslip.registry import register
from stickslip.solvers.fem import stack_mesh

VERSION = "1"


@register("solver", "fem-twin", VERSION, FemParams, consumes=("mesh",), produces="fem-run", replay=EventReplay)
def run(params, output, *, threads, inputs):
    """The fem model under another name (test plugin: a second producer of the fem-run format)."""
    simulate_to_file(params, output, stack_mesh(params, inputs), make_backend(params.backend, threads),
                   producer=("fem-twin", VERSION))
