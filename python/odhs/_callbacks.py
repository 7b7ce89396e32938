"""The Python side of the C callbacks (cffi ``extern "Python"`` functions).

Each callback catches every exception of the user's code, stores it
(_core.set_pending) and returns the failure value the C API defines: the
event callback 1 (stop the run: ODHS_STOPPED), the force callback 1 (the step
is rolled back: ODHS_E_CALLBACK), the pair visitor 1 (stop), the solver
backend ODHS_E_CALLBACK (or the status of an odhs.Error it raised). The
binding that made the C call then re-raises it (``reraise``) with a note
naming the call and its status."""

import numpy as np

from . import _core
from ._core import F64, ffi, lib, set_pending, take_pending, view_of
from .constants import EventKind
from .errors import Error, status_name
from .records import Event


def reraise(exc, function, rc, message=""):
    """Raise exc, a callback's exception, noting the C call that ran it."""
    if hasattr(exc, "add_note"):
        note = "odhs: raised in a Python callback run by %s, which then returned %s" % (function, status_name(rc))
        if message:
            note += " (%s)" % message
        exc.add_note(note)
    raise exc


def check_pending(function, rc, message_fn=None):
    """After a C call that may have run callbacks: re-raise their exception."""
    exc = take_pending()
    if exc is not None:
        reraise(exc, function, rc, message_fn() if message_fn else "")


# ---------------------------------------------------------------------------
# events
# ---------------------------------------------------------------------------


class EventContext:
    """What the C stepper's event callback context points to."""

    __slots__ = ("fn",)

    def __init__(self, fn):
        self.fn = fn


@ffi.def_extern()
def _odhs_py_event(ev, ctx):
    try:
        c = ffi.from_handle(ctx)
        kind = ev.kind
        try:
            kind = EventKind(kind)
        except ValueError:
            pass
        return 1 if c.fn(Event(kind, ev.i, ev.j, ev.time, ev.strain)) else 0
    except BaseException as exc:  # noqa: B902 - every exception stops the run
        set_pending(exc)
        return 1


# ---------------------------------------------------------------------------
# forces
# ---------------------------------------------------------------------------


class ForceContext:
    """What the C driver's force callback context points to."""

    __slots__ = ("fn",)

    def __init__(self, fn):
        self.fn = fn


@ffi.def_extern()
def _odhs_py_force(t, sys, F, ctx):
    from .system import System

    view = None
    try:
        c = ffi.from_handle(ctx)
        view = System._borrow(sys)
        res = c.fn(t, view)
        nd = view._n * view._dim
        arr = np.ascontiguousarray(res, dtype=F64)
        if arr.size != nd:
            raise ValueError("the force callback returned %d values, expected %d (shape (%d, %d))"
                             % (arr.size, nd, view._n, view._dim))
        ffi.memmove(F, arr, nd * 8)
        return 0
    except BaseException as exc:  # noqa: B902
        set_pending(exc)
        return 1
    finally:
        if view is not None:
            view._invalidate()


# ---------------------------------------------------------------------------
# pairs
# ---------------------------------------------------------------------------


class PairContext:
    __slots__ = ("fn", "dim")

    def __init__(self, fn, dim):
        self.fn = fn
        self.dim = dim


@ffi.def_extern()
def _odhs_py_pair(i, j, rij, gap, ctx):
    try:
        c = ffi.from_handle(ctx)
        r = np.frombuffer(ffi.buffer(rij, c.dim * 8), dtype=F64).copy()
        return 1 if c.fn(i, j, r, gap) else 0
    except BaseException as exc:  # noqa: B902
        set_pending(exc)
        return 1


def for_each_pair(system, max_gap, fn):
    """System.for_each_pair (see there)."""
    from .errors import status_of

    ctx = PairContext(fn, system.dim)
    h = ffi.new_handle(ctx)
    rc = lib.odhs_system_for_each_pair(system._p or system._closed(), float(max_gap), lib._odhs_py_pair, h)
    check_pending("System.for_each_pair", rc)
    if rc < 0:
        system._err(rc, "System.for_each_pair")
    return status_of(rc)


# ---------------------------------------------------------------------------
# solver backends
# ---------------------------------------------------------------------------


def _backend_status(exc):
    """The status a backend returns for exc: an odhs.Error's own status
    (SingularError lets the library's fallbacks act), else ODHS_E_CALLBACK
    with exc kept for re-raising."""
    if isinstance(exc, Error) and exc.status is not None and exc.status < 0:
        return exc.status
    set_pending(exc)
    return lib.ODHS_E_CALLBACK


@ffi.def_extern()
def _odhs_py_solver_create(state):
    ctx = getattr(_core._tls, "creating_backend", None)
    if ctx is None:  # pragma: no cover - only through Solver(backend)
        return lib.ODHS_E_INTERNAL
    state[0] = ctx
    return 0


@ffi.def_extern()
def _odhs_py_solver_destroy(state):
    # the backend object is released with the Solver's handle
    return None


def _net_view(net):
    from .network import Network

    return Network._borrow(net)


@ffi.def_extern()
def _odhs_py_solver_setup(state, net):
    view = None
    try:
        backend = ffi.from_handle(state)
        view = _net_view(net)
        backend.setup(view)
        return 0
    except BaseException as exc:  # noqa: B902
        return _backend_status(exc)
    finally:
        if view is not None:
            view._invalidate()


@ffi.def_extern()
def _odhs_py_solver_solve(state, net, b, x):
    view = None
    try:
        backend = ffi.from_handle(state)
        nc = lib.odhs_network_count(net)
        view = _net_view(net)
        res = backend.solve(view, view_of(b, nc), view_of(x, nc, writable=True))
        if res is not None:  # a returned array is copied into x
            arr = np.ascontiguousarray(res, dtype=F64)
            if arr.size != nc:
                raise ValueError("solve returned %d values, expected Nc = %d" % (arr.size, nc))
            ffi.memmove(x, arr, nc * 8)
        return 0
    except BaseException as exc:  # noqa: B902
        return _backend_status(exc)
    finally:
        if view is not None:
            view._invalidate()


@ffi.def_extern()
def _odhs_py_solver_solve_ls(state, net, g, x):
    view = None
    try:
        backend = ffi.from_handle(state)
        nc = lib.odhs_network_count(net)
        ng = lib.odhs_network_particles(net) * lib.odhs_network_dim(net)
        view = _net_view(net)
        res = backend.solve_ls(view, view_of(g, ng), view_of(x, nc, writable=True))
        if res is not None:
            arr = np.ascontiguousarray(res, dtype=F64)
            if arr.size != nc:
                raise ValueError("solve_ls returned %d values, expected Nc = %d" % (arr.size, nc))
            ffi.memmove(x, arr, nc * 8)
        return 0
    except BaseException as exc:  # noqa: B902
        return _backend_status(exc)
    finally:
        if view is not None:
            view._invalidate()


@ffi.def_extern()
def _odhs_py_solver_set_param(state, key, value):
    try:
        backend = ffi.from_handle(state)
        backend.set_param(ffi.string(key).decode(), value)
        return 0
    except (KeyError, ValueError, TypeError):
        return lib.ODHS_E_INVALID
    except BaseException as exc:  # noqa: B902
        return _backend_status(exc)


@ffi.def_extern()
def _odhs_py_solver_get_stat(state, key, value):
    try:
        backend = ffi.from_handle(state)
        value[0] = float(backend.get_stat(ffi.string(key).decode()))
        return 0
    except (KeyError, ValueError, TypeError):
        return lib.ODHS_E_INVALID
    except BaseException as exc:  # noqa: B902
        return _backend_status(exc)
