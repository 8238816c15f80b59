"""Backend ``cuda``: the fem model on an NVIDIA GPU, whole minimisations on the device, batches of realisations.

A run's state lives in one slot of a :class:`.batch.DeviceBatch` on the device; the backend of the
run (:class:`CudaBackend`) implements the seam of :mod:`..base` on that slot. A minimisation is one
or more launches of the minimisation kernel (:mod:`.minimise`), each advancing up to
:data:`.launch.STEPS_PER_LAUNCH` time steps before the host reads a status word: velocity Verlet, the
interface law (the law's own Python functions compiled for the device), the drive, the residual
criterion, the quiet window and the margin all run there. Runs of one mesh started together
(:func:`run_ensemble`) share their launches: one launch advances every realisation of the batch,
each computed exactly as alone.

What is kept: the same run gives the same bytes run after run on one GPU, whatever the batch and
the number of blocks a realisation is spread over (no floating-point atomics; every sum in a fixed
order, :mod:`.layout`). Against the CPU the round-off differs (other summation orders, and the
device compiler fuses multiplies and adds): the same events from the same state within the
reference tolerance, not the same bytes, so ``cuda`` is a value of the ``backend`` parameter with
its own run ids. The exact relaxation solves on the host (:meth:`CudaBackend.correct`: the force
out, the correction in, once per Newton iteration). Needs ``numba-cuda`` (``pip install -e
".[gpu]"`` in a clone) and a GPU with its driver; ``NUMBA_ENABLE_CUDASIM=1`` runs it on numba's CUDA
simulator (tests, tiny meshes).
"""

import importlib.util
import threading
from typing import NamedTuple

import numpy as np

from ..base import Backend, register_backend

__all__ = ["CudaBackend", "run_ensemble"]


def _why_not():
    """Why the device cannot be used ("" if it can)."""
    if importlib.util.find_spec("numba_cuda") is None:
        return "numba-cuda is not installed; install the GPU extra: pip install -e '.[gpu]' in a clone"
    from numba import cuda  # numba-cuda's target (numba's own is deprecated)
    from numba import config

    if config.ENABLE_CUDASIM:
        return ""
    try:
        if cuda.is_available():
            return ""
        reason = "numba-cuda found no CUDA driver or GPU"
    except Exception as error:  # numba-cuda raises its own errors for a missing or broken driver
        reason = f"numba-cuda cannot use the GPU: {error}"
    return f"{reason}; run on a machine with an NVIDIA GPU or choose a CPU backend (structured, assembled)"


class Checkpoint(NamedTuple):
    """A checkpoint of a ``cuda`` run: device copies of its slot's state and the yield strains it held."""

    device: dict
    epsy: object


@register_backend
class CudaBackend(Backend):
    """The fem model on an NVIDIA GPU (module docstring).

    Parameters
    ----------
    threads : int, optional
        Ignored (the device's threads are the kernels' business); kept for the common signature.
    member : .ensemble.Member, optional
        The run's place in an ensemble (:func:`run_ensemble`): its minimisations share launches with the
        other members'; None: the run has the device to itself.
    groups : int, optional
        Blocks a realisation is spread over in a minimisation at most (default: as many as its tiles and the
        device allow, :class:`.launch.Launcher`); the results do not depend on it.
    kernel : str, optional
        The minimisation kernel: ``"tiles"`` (the default) or ``"resident"`` (:class:`.launch.Launcher`); the
        results do not depend on it.
    """

    name = "cuda"
    summary = "NVIDIA GPU (numba-cuda): whole minimisations on the device, batches of runs in one launch"

    def __init__(self, threads=1, member=None, groups=None, kernel="tiles"):
        self.threads = int(threads)
        self.member = member
        self.groups = groups
        self.kernel = kernel
        self.model = self.batch = self.slot = self.mesh = None
        self.device_mesh = None
        self._epsy = None  # the yield strains held (the host array they came from: a rollback may hold them again)

    @classmethod
    def unavailable(cls):
        return _why_not()

    @staticmethod
    def run_ensemble(runs, groups=None):
        """Run several simulations of one mesh on the GPU together: :func:`run_ensemble`."""
        return run_ensemble(runs, groups)

    def prepare(self, model, mesh, epsy):
        from .batch import DeviceBatch  # numba-cuda is optional: imported when a run asks for it
        from .device import DeviceMesh

        if self.member is not None:
            return self.bound(model, mesh, self.member.ensemble.batch_for(model, mesh), epsy)
        return self.bound(model, mesh, DeviceBatch(self.device_mesh or DeviceMesh(model, mesh), model.law, 1,
                                                   self.groups, self.kernel), epsy)

    def for_model(self, model, epsy):
        from .batch import DeviceBatch

        if self.member is not None:
            return self.bound(model, self.mesh, self.member.ensemble.batch_for(model, self.mesh), epsy)
        return self.bound(model, self.mesh, DeviceBatch(self.batch.mesh, model.law, 1, self.groups, self.kernel), epsy)

    def bound(self, model, mesh, batch, epsy):
        """A backend for ``model`` on ``mesh`` holding the yield strains ``epsy`` [ni, ny] in a free slot of ``batch``,
        at rest at the origin."""
        bound = CudaBackend(self.threads, self.member, self.groups, self.kernel)
        bound.model, bound.mesh, bound.batch, bound.device_mesh = model, mesh, batch, batch.mesh
        bound.slot = batch.attach(model, bound)
        bound._epsy = epsy
        batch.set_yield_strains(bound.slot, epsy, None)
        bound.set_state(np.zeros(model.ndof), np.zeros(model.layer_volume.size), 0.0, 0.0)
        return bound

    def read(self, *fields):
        return self.batch.read(self.slot, fields)

    def set_state(self, u, target, lever_target, t):
        zeros = np.zeros(self.model.ndof)
        self.batch.upload(self.slot, u=u, v=zeros, a=zeros, target=target, lever0=lever_target, clock=t)
        self.batch.evaluate(self.slot, True)

    def set_load_direction(self, delta_u, delta_target, delta_lever):
        self.batch.upload(self.slot, delta_u=delta_u, delta_target=delta_target, delta_lever=np.array(delta_lever))

    def load(self, step):
        self.batch.load(self.slot, step)
        self.batch.evaluate(self.slot, True)

    def add_u(self, dofs, delta):
        self.batch.add_u(self.slot, dofs, delta)
        self.batch.evaluate(self.slot, True)

    def correct(self, dofs, solve):
        f = self.batch.read(self.slot, ("f",))[0]
        self.batch.add_u(self.slot, dofs, -solve(f[dofs]))
        return self.batch.evaluate(self.slot, False)

    def rest_in_wells(self):
        self.batch.stop(self.slot)
        self.batch.evaluate(self.slot, False)

    def set_yield_strains(self, epsy, shift=None):
        self._epsy = epsy
        self.batch.set_yield_strains(self.slot, epsy, shift)
        self.batch.evaluate(self.slot, True)

    def checkpoint(self):
        return Checkpoint(self.batch.checkpoint(self.slot), self._epsy)

    def rollback(self, token):
        if token.epsy is not self._epsy:  # other yield strains held since: held again (no evaluation: the state is
            self._epsy = token.epsy       # copied back whole)
            self.batch.set_yield_strains(self.slot, token.epsy, None)
        self.batch.rollback(self.slot, token.device)

    def wells_changed(self, token, shift=None, elements=None):
        return self.batch.state.wells_changed(self.slot, token.device, shift, elements)

    def minimise(self, tol, niter_tol, max_iter, margin, record, quiet=0):
        return self.batch.minimise(self.slot, (tol, niter_tol, max_iter, margin, record, quiet), self.member)

    def advance(self, nsteps):
        # no stopping criterion: a tolerance no residual is below, no margin, no quiet window
        self.batch.minimise(self.slot, (0.0, 1, nsteps, 0, False, 0), self.member)

    def residual(self):
        return self.batch.residual(self.slot)

    def wells_hold(self):
        return self.batch.wells_hold(self.slot)


def run_ensemble(runs, groups=None, kernel="tiles"):
    """Run several simulations of one mesh on the GPU as one batch: one thread per run, shared launches.

    Parameters
    ----------
    runs : Sequence[callable]
        ``run(backend)`` makes one run with the backend it is given (e.g. a closure over
        :func:`stickslip.fem.run.simulate_to_file` with its parameters and output file).
    groups : int, optional
        Blocks per realisation at most (default: spread over the device).
    kernel : str, optional
        The minimisation kernel (:class:`CudaBackend`).

    Returns
    -------
    list
        What each run returned, in order.

    Raises
    ------
    BaseException
        The first error of a run, after every run ended (the others are not interrupted).
    """
    from .ensemble import Ensemble

    ensemble = Ensemble(len(runs), groups, kernel)
    members = [ensemble.join() for _ in runs]  # every run is a member before any minimisation is launched
    results, errors = [None] * len(runs), [None] * len(runs)

    def one(i):
        try:
            results[i] = runs[i](CudaBackend(member=members[i], groups=groups, kernel=kernel))
        except BaseException as error:  # reported after the others ended
            errors[i] = error
        finally:
            members[i].leave()

    threads = [threading.Thread(target=one, args=(i,), name=f"cuda-run-{i}") for i in range(len(runs))]
    for thread in threads:
        thread.start()
    for thread in threads:
        thread.join()
    for error in errors:
        if error is not None:
            raise error
    return results
