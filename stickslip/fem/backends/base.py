"""The backend seam: what the rest of the fem package asks of the object that computes the numbers.

A backend is chosen per run (:func:`..backends.make_backend`) and prepared once for a model on its
mesh (:meth:`Backend.prepare`); from then on it **owns the state** of the stack: displacement,
velocity, acceleration, forces, the well of every interface Gauss point, the yield strains (the model has none:
the backend's copy is the only one, given by :meth:`Backend.set_yield_strains`), the
drive targets and the time of its dynamics. The rest of the package reads and changes that state only through
the methods below, each a point where a device backend synchronises with the host
(FrictionQPotFEM's ``setU`` -> ``updated_u``): a change of displacement, drive or yield strains
re-evaluates everything that follows from it before the call returns. The CPU backends hand out
read-only views and change their arrays in place (nothing is copied); a device backend copies what
:meth:`Backend.read` asks for and nothing else, and runs whole minimisations on the device. What needs no
array on the host stays where the state is: an exact copy of the state and the return to it
(:meth:`Backend.checkpoint`, :meth:`Backend.rollback`), and whether a Gauss point changed well since such a
copy (:meth:`Backend.wells_changed`, a number).

State fields (:data:`FIELDS`): ``u``, ``v``, ``a`` float64 [ndof] (displacement [length],
velocity, acceleration), ``f`` float64 [ndof] (internal force, material and drive [force]),
``idx`` int64 [ni, 4] (held well of every interface Gauss point), ``eps``, ``sig`` float64
[ni, 4, 3] (interface strain and stress, ``xx, yy, xy``), ``target``, ``ubar`` float64 [nlayer]
(drive target and volume-averaged x-displacement of every layer [length]), ``lever`` float64 [2]
(free lever: drive target and lever position [length]), ``t`` float64 [1] (the time of the dynamics: set
with the state, advanced by ``dt`` per time step; a thermal run's physical time is its protocol's, :mod:`..clock`).

Statuses of :meth:`Backend.minimise`: :data:`CONVERGED`, :data:`MARGIN`, :data:`QUIET`,
:data:`MAX_ITER_REACHED`.
"""

import abc

import numpy as np

__all__ = ["Backend", "BACKENDS", "register_backend", "FIELDS", "CONVERGED", "MARGIN", "QUIET", "MAX_ITER_REACHED",
           "read_only", "unbounded_wells"]

#: Backend classes by name (:func:`register_backend`): the choices of the ``backend`` parameter.
BACKENDS = {}

#: The state fields a backend holds (module docstring).
FIELDS = ("u", "v", "a", "f", "idx", "eps", "sig", "target", "ubar", "lever", "t")

#: Status of a minimisation: the residual criterion was met (state quenched).
CONVERGED = 1
#: Status of a minimisation: a Gauss point came within ``margin`` wells of the end of its held yield strains.
MARGIN = 0
#: Status of a minimisation: ``quiet`` consecutive steps without any well change (not quenched).
QUIET = 2
#: Status of a minimisation: ``max_iter`` steps did not converge.
MAX_ITER_REACHED = -1


def register_backend(cls):
    """Register a backend class (class decorator); its ``name`` becomes a choice of the ``backend`` parameter."""
    if cls.name in BACKENDS:
        raise ValueError(f"backend {cls.name!r} is registered twice")
    BACKENDS[cls.name] = cls
    return cls


def read_only(array):
    """A view of ``array`` that cannot be written (what a CPU backend's :meth:`Backend.read` hands out)."""
    view = array.view()
    view.flags.writeable = False
    return view


def unbounded_wells(ni):
    """Yield strains of one unbounded well per Gauss point, ``[-inf, inf]``: float64 [ni, 2], for a model whose
    interfaces are elastic (:class:`..laws.Elastic`; the linear response's)."""
    return np.tile(np.array([[-np.inf, np.inf]]), (ni, 1))


class Backend(abc.ABC):
    """How the numbers of the fem model are computed; after :meth:`prepare` it owns the state.

    Class attributes: ``name`` (the value of the ``backend`` parameter), ``summary`` (one line), and, for a
    device backend that runs several runs together, ``run_ensemble(runs)`` (each ``run(backend)`` made with a
    backend of the ensemble; returns what each returned; the ``fem`` solver's GPU batches).
    Attributes of a prepared backend: ``model`` (the :class:`..model.Model` it computes, read only)
    and ``threads``.
    """

    name = ""
    summary = ""

    @classmethod
    def unavailable(cls):
        """Why this backend cannot run on this machine ("" if it can): e.g. no GPU."""
        return ""

    @abc.abstractmethod
    def prepare(self, model, mesh, epsy):
        """A backend for ``model`` on ``mesh`` (a new object) owning a state at rest at the origin.

        ``model`` (:class:`..model.Model`) built from ``mesh`` (:class:`...mesh.LayeredMesh`); ``epsy`` the yield
        strains it holds (as :meth:`set_yield_strains`'s; :func:`unbounded_wells` for elastic interfaces). The state:
        ``u = v = a = 0``, drive targets 0, ``t = 0``, every Gauss point in the well of its strain, forces evaluated.
        """

    @abc.abstractmethod
    def for_model(self, model, epsy):
        """A prepared backend for another model on the same mesh and drive (e.g. another law), holding ``epsy``.

        It shares what depends on the mesh only and owns a state of its own, at rest at the origin (as
        :meth:`prepare`'s).
        """

    @abc.abstractmethod
    def read(self, *fields):
        """The state fields ``fields`` (:data:`FIELDS`), as a tuple of arrays.

        CPU backends return read-only views of the state (change it through the methods below); a
        device backend returns host copies.
        """

    @abc.abstractmethod
    def set_state(self, u, target, lever_target, t):
        """Set a state at rest: displacement [ndof], layer targets [nlayer], free lever's drive target, time.

        ``v = a = 0``; every Gauss point moves to the well of its strain; forces evaluated (a free
        lever's layer targets follow from ``lever_target``).
        """

    @abc.abstractmethod
    def set_load_direction(self, delta_u, delta_target, delta_lever):
        """Set the direction of :meth:`load`: displacement [ndof], layer targets [nlayer], free lever's drive target."""

    @abc.abstractmethod
    def load(self, step):
        """Move the displacement and the drive by ``step`` times the load direction; re-evaluate (wells updated)."""

    @abc.abstractmethod
    def add_u(self, dofs, delta):
        """Add ``delta`` [len(dofs)] to the displacement of ``dofs`` (int64); re-evaluate (wells updated)."""

    @abc.abstractmethod
    def correct(self, dofs, solve):
        """One correction of the equilibrium solve in fixed wells: ``u[dofs] -= solve(f[dofs])``.

        The forces are then re-evaluated with every Gauss point held in its well. One exchange with
        the host: the force out, the correction in.

        Returns
        -------
        float
            The relative residual after the correction (:meth:`residual`).
        """

    @abc.abstractmethod
    def rest_in_wells(self):
        """Stop the state (``v = a = 0``) and evaluate the force with every Gauss point held in its current well."""

    @abc.abstractmethod
    def set_yield_strains(self, epsy, shift=None):
        """Replace the held yield strains by ``epsy`` [ni, ny]; lower every well index of block ``e`` by ``shift[e]``.

        The window of held yield strains moved (the same wells, numbered from another start) or was
        widened, or restarted (``shift`` None); forces re-evaluated, every Gauss point moved to
        the well of its strain. ``epsy`` is the backend's from now on: the caller never changes it.
        """

    @abc.abstractmethod
    def checkpoint(self):
        """An exact copy of the whole state, the held yield strains included, kept where the state is (an opaque
        token for :meth:`rollback` and :meth:`wells_changed`; nothing comes to the host)."""

    @abc.abstractmethod
    def rollback(self, token):
        """Return to the state of :meth:`checkpoint` ``token``, bit for bit (its yield strains too)."""

    @abc.abstractmethod
    def wells_changed(self, token, shift=None, elements=None):
        """How many interface Gauss points are in another well than at :meth:`checkpoint` ``token`` (counted where the
        state is: one number comes to the host).

        Parameters
        ----------
        token
            A checkpoint of this backend.
        shift : numpy.ndarray, optional
            int64 [ni]: how far the wells of block ``e`` were renumbered down since (:meth:`set_yield_strains`'s
            ``shift``, summed): a Gauss point changed well if ``idx + shift`` differs from the checkpoint's.
        elements : numpy.ndarray, optional
            int64: count the Gauss points of these interface elements only (default: all).

        Returns
        -------
        int
        """

    @abc.abstractmethod
    def minimise(self, tol, niter_tol, max_iter, margin, record, quiet=0):
        """Minimise by damped inertial dynamics, the whole loop in the backend.

        Time steps (velocity Verlet, ``dt``) until the relative residual of the last ``niter_tol``
        steps is below ``tol`` and non-increasing, or all below ``tol^2`` (then ``v = a = 0``,
        status :data:`CONVERGED`); or until a Gauss point comes within ``margin`` wells of the end of
        its held yield strains (``margin > 0``, :data:`MARGIN`); or, with ``quiet > 0``, until
        ``quiet`` consecutive steps changed no well (:data:`QUIET`); at most ``max_iter`` steps
        (:data:`MAX_ITER_REACHED`).

        Returns
        -------
        status : int
        niter : int
            Time steps made.
        events : numpy.ndarray
            float64 [nevent, 3]: every well change of Gauss point 0 of an interface element,
            ``(element, time, direction +1/-1)``, if ``record`` (else empty).
        """

    @abc.abstractmethod
    def advance(self, nsteps):
        """Make ``nsteps`` time steps of the damped dynamics, without any stopping criterion."""

    @abc.abstractmethod
    def residual(self):
        """Relative residual ``|f_res| / |f_ext|`` of the state [1] (:mod:`.cpu.dynamics`)."""

    @abc.abstractmethod
    def wells_hold(self):
        """True if every interface Gauss point's strain lies in its held well."""
