"""Event replay: a stored kick increment of a ``fem`` run redone with every block failure recorded.

The replay is the ``fem`` solver's capability (:func:`stickslip.registry.register`,
``replay=``): an analysis asks the solver that wrote a file to replay its events. The
model is built once per run file; each replay restores the stored state before the kick
and runs the same kick and relaxation as the run
(:meth:`.protocol.EventLoop.perturb_and_relax` with :class:`.loading.KickAlongResponse`).
For a thermal run it also holds a stored state at a load and reloads it
(:meth:`EventReplay.hold`, :mod:`.thermal.holds`), or holds it at its load and records the events
(:meth:`EventReplay.aftershocks`, :mod:`.thermal.aftershocks`), and for any run it gives the interface fields of
a stored increment (:meth:`EventReplay.interface_state`, what :meth:`stickslip.runs.FemRun.state` shows).
"""

import numpy as np
import pandas as pd

from ..formats.fem_run import RunFile
from ..h5io import FileFormatError, open_file
from .backends import make_backend
from .loading import KickAlongResponse
from .parameters import stored_params
from .simulation import Simulation
from .thermal import hold_trial
from .thermal.aftershocks import aftershock_trial

__all__ = ["EventReplay"]


class EventReplay:
    """Replays stored kick increments of one run file.

    Parameters
    ----------
    path : str or os.PathLike
        A ``fem-run`` file.
    backend : optional
        How the numbers are computed (:mod:`.backends`); default: the run's own backend
        (``params.backend``) with one thread, which reproduces the stored increments bit for bit.

    Notes
    -----
    Cost: the file's header and increment table are read, and the model (yield strains,
    stiffness) built, once; each :meth:`failures` costs one kick and one minimisation.
    """

    def __init__(self, path, backend=None):
        self.path = path
        with open_file(path) as file:
            run = RunFile(file)
            self.params, self.nstored = stored_params(file), run.nstored
            table = run.increments()
            self.N = run.mesh.N
            self.simulation = Simulation(self.params, run.mesh, backend or make_backend(self.params.backend),
                                         response=run.linear_response())
        self._kick = table["kick"].to_numpy(dtype=bool)
        self._yield_element = table["yield_element"].to_numpy(dtype=bool)

    def _state(self, increment):
        with open_file(self.path) as file:
            return RunFile(file).state(increment)

    def _thermal(self):
        if self.params.temperature <= 0.0:
            raise FileFormatError(f"{self.path}: an athermal run (temperature = 0) has no hold trials")

    def hold(self, increment, hold_time, below, replica, each=0):
        """A hold trial from a stored increment of a thermal run (:func:`.thermal.holds.hold_trial`).

        Raises
        ------
        FileFormatError
            If the run is athermal (``temperature = 0``) or the increment is not stored.
        """
        self._thermal()
        return hold_trial(self.simulation, self._state(increment), hold_time, below, replica, each)

    def aftershocks(self, increment, hold_time, replica, control=None):
        """An aftershock or control hold from a stored increment of a thermal run (:func:`.thermal.aftershocks.aftershock_trial`).

        Raises
        ------
        FileFormatError
            If the run is athermal (``temperature = 0``) or the increment is not stored.
        """
        self._thermal()
        return aftershock_trial(self.simulation, self._state(increment), hold_time, replica, control)

    def interface_state(self, increment):
        """Strain, stress and well of every interface Gauss point at a stored increment.

        The stored state is restored on the run's model (nothing is re-run): these are the fields
        from which the run computed that increment's observables.

        Parameters
        ----------
        increment : int
            A stored increment.

        Returns
        -------
        dict[str, numpy.ndarray]
            ``eps``: float64 [n_interfaces, N, 4, 3] strain (xx, yy, xy) [1]; ``sig``: float64
            [n_interfaces, N, 4, 3] stress (xx, yy, xy) [FE stress, the unit of ``G``] (the run file's
            ``eps0`` and ``sig0`` are the units of its observables); ``well``: int64 [n_interfaces, N, 4]
            the well each Gauss point is in, counted from the start of its block's yield-strain
            sequence. Interfaces a = 1 (lowest) first, blocks left to right, the element's 4 Gauss points.

        Raises
        ------
        FileFormatError
            If the increment is not stored.
        """
        stack = self.simulation.stack
        stack.restore(self._state(increment))
        eps, sig = stack.read("eps", "sig")
        return {"eps": eps.reshape(-1, self.N, 4, 3).copy(), "sig": sig.reshape(-1, self.N, 4, 3).copy(),
                "well": stack.well_index().reshape(-1, self.N, 4)}

    def failures(self, increment):
        """Redo one kick increment and record every well hop of the interface blocks.

        The state of ``increment - 1`` is restored, the stored kick redone (the whole-element
        fallback if the run used it), and the result must reproduce the stored increment
        exactly (asserted).

        Parameters
        ----------
        increment : int
            A stored kick increment (>= 1).

        Returns
        -------
        pandas.DataFrame
            Columns ``a`` (interface, 1 = lowest), ``block`` (0 ... N-1), ``t`` (time since the
            kick [FE time units]), ``direction`` (+1 / -1); one row per well hop, in time order.

        Raises
        ------
        FileFormatError
            If the increment is not a stored kick, or the run is thermal (its events are hops, kicks at its
            clock and junction redraws, which this replay does not redo).
        """
        if self.params.temperature > 0.0:
            raise FileFormatError(f"{self.path}: a thermal run (temperature = {self.params.temperature:g}); its events "
                                  "are hops, athermal kicks and junction redraws, and failures() replays the kicks "
                                  "of an athermal run (temperature = 0) only")
        if not 1 <= increment < self.nstored or not self._kick[increment]:
            raise FileFormatError(f"{self.path}: increment {increment} is not a stored kick increment")
        before, after = self._state(increment - 1), self._state(increment)
        s = self.simulation
        s.stack.restore(before)
        kick = KickAlongResponse(s.loading, bool(self._yield_element[increment]))
        niter, events = s.protocol.perturb_and_relax(kick, self.params.margin, record=True)
        u, = s.stack.read("u")
        if niter == 0 or not np.array_equal(u, after.u) or s.stack.time != after.t:
            raise AssertionError(f"{self.path}: replaying increment {increment} did not reproduce the stored state")
        element = events[:, 0].astype(np.int64)
        return pd.DataFrame({"a": element // self.N + 1, "block": element % self.N, "t": events[:, 1] - before.t,
                             "direction": events[:, 2].astype(np.int64)})
