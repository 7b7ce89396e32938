"""Linear solvers for N f = b, N = S S^T (odhs_solver): the built-in
backends by name, and backends written in Python (SolverBackend) through the
library's user backend table (odhs_solver_type)."""

from . import _core
from ._core import NULL, Owned, cstr, enc, ffi, in_array, lib, out_array
from ._callbacks import check_pending
from .constants import SolverFlag
from .errors import last_error, make_error
from .records import SolverInfo


def available_solvers():
    """The built-in solver names in the library's order, each with whether
    this build has it (odhs_solver_list): a list of SolverInfo(name,
    installed)."""
    out = []
    name, ok = ffi.new("const char **"), ffi.new("int *")
    k = 0
    while lib.odhs_solver_list(k, name, ok) == lib.ODHS_OK:
        out.append(SolverInfo(cstr(name[0]), bool(ok[0])))
        k += 1
    return out


class SolverBackend:
    """Base class of linear-solver backends written in Python.

    Subclass it, set ``name`` (short, unique) and ``flags`` (SolverFlag
    values: ITERATIVE, DIRECT, USES_GUESS, LEAST_SQUARES) and implement
    ``solve``; the other methods are optional (a method left as inherited is
    not given to the library, which then uses its defaults). Pass an
    instance to Solver(backend): each Solver keeps its own instance as the
    backend's state.

    Arguments: ``network`` is a read-only Network view valid only during the
    call (apply_S, apply_ST, apply_N, S_csr, normals, ... work on it);
    ``b``, ``g`` are read-only float64 views of the library's input (zero
    copy, valid only during the call) and ``x`` a writable view of its output
    (Nc,): fill it in place (``x[:] = ...``) or return an array (copied into
    x). With USES_GUESS, x holds the initial guess on entry (zeros
    otherwise).

    Errors: raise odhs.SingularError or odhs.NoConvergenceError to report a
    singular network or no convergence (the library's fallbacks and the
    ``auto`` chain react to those statuses); any other exception makes the
    call return ODHS_E_CALLBACK and is re-raised from the Python call that
    ran the library (Stepper.step, Solver.solve, ...). ``set_param`` and
    ``get_stat`` raise KeyError (or ValueError) for unknown names
    (ODHS_E_INVALID)."""

    name = "python"
    flags = SolverFlag.DIRECT

    def setup(self, network):
        """The network's contacts or geometry changed (called before solve
        whenever that happened since the last call)."""

    def solve(self, network, b, x):
        """Solve N x = b (b and x of Nc values)."""
        raise NotImplementedError("a SolverBackend must implement solve(network, b, x)")

    def solve_ls(self, network, g, x):
        """Optional: the least-squares x of S^T x = g (g of N*dim values)."""
        raise NotImplementedError

    def set_param(self, key, value):
        """Set a named parameter (raise KeyError for unknown names)."""
        raise KeyError(key)

    def get_stat(self, key):
        """A named statistic of the last solve (raise KeyError if unknown)."""
        raise KeyError(key)


def _overrides(backend, name):
    return getattr(type(backend), name, None) is not getattr(SolverBackend, name)


class Solver(Owned):
    """A linear solver: ``Solver("auto")`` (a built-in backend by name:
    "auto", "cg", "dense", and with SuiteSparse "cholmod", "cholmod-pcg",
    "spqr"; odhs_solver_create_by_name) or ``Solver(backend)`` with a
    SolverBackend instance (odhs_solver_create with a table whose functions
    call the backend). InvalidError for an unknown name (its message lists
    the valid ones), NotInstalledError for a backend not built in."""

    _kind = "solver"

    def __init__(self, name="auto"):
        out = ffi.new("odhs_solver **")
        if isinstance(name, SolverBackend):
            self._backend = name
            keep = self._create_backend(name, out)
        elif isinstance(name, type) and issubclass(name, SolverBackend):
            raise TypeError("pass an instance of the backend class (%s()), not the class" % name.__name__)
        else:
            self._backend = None
            keep = None
            rc = lib.odhs_solver_create_by_name(enc(name, "solver name"), out)
            if rc:
                raise make_error(rc, last_error(), "Solver")
        self._init_handle(out[0], lib.odhs_solver_destroy)
        if keep:
            self._h.keep.update(keep)
        self._fallback = None

    def _create_backend(self, backend, out):
        if not callable(getattr(backend, "solve", None)) or not _overrides(backend, "solve"):
            raise TypeError("the backend must implement solve(network, b, x)")
        t = ffi.new("odhs_solver_type *")
        name = ffi.new("char[]", enc(backend.name, "backend name"))
        t.version = lib.ODHS_SOLVER_TYPE_VERSION
        t.name = name
        t.flags = int(backend.flags)
        t.create = lib._odhs_py_solver_create
        t.destroy = lib._odhs_py_solver_destroy
        t.solve = lib._odhs_py_solver_solve
        t.setup = lib._odhs_py_solver_setup if _overrides(backend, "setup") else NULL
        t.set_param = lib._odhs_py_solver_set_param if _overrides(backend, "set_param") else NULL
        t.get_stat = lib._odhs_py_solver_get_stat if _overrides(backend, "get_stat") else NULL
        t.solve_ls = lib._odhs_py_solver_solve_ls if _overrides(backend, "solve_ls") else NULL
        ctx = ffi.new_handle(backend)
        # create() receives no context: hand it the state through this thread
        _core._tls.creating_backend = ctx
        try:
            rc = lib.odhs_solver_create(t, out)
        finally:
            _core._tls.creating_backend = None
        if rc:
            raise make_error(rc, last_error(), "Solver")
        return {"table": t, "name": name, "state": ctx}

    def _err(self, rc, fn):
        p = self._p
        raise make_error(rc, cstr(lib.odhs_solver_errmsg(p)) if p is not None else "", fn)

    def _repr_extra(self):
        return " %r" % self.name

    @classmethod
    def available(cls):
        """Same as odhs.available_solvers()."""
        return available_solvers()

    @property
    def backend(self):
        """The SolverBackend instance of a Python backend, else None."""
        return self._backend

    @property
    def errmsg(self):
        """The message of the last failed call on this handle ("" if none)."""
        return cstr(lib.odhs_solver_errmsg(self._p or self._closed()))

    @property
    def name(self):
        """Backend name (odhs_solver_name)."""
        return cstr(lib.odhs_solver_name(self._p or self._closed()))

    @property
    def last_backend(self):
        """The backend that produced the last solution and a description of
        the fallbacks of the last solve, as (name, why)
        (odhs_solver_backend_name)."""
        name, why = ffi.new("const char **"), ffi.new("const char **")
        rc = lib.odhs_solver_backend_name(self._p or self._closed(), name, why)
        if rc:
            self._err(rc, "Solver.last_backend")
        return cstr(name[0]), cstr(why[0])

    def set_param(self, key, value):
        """Set a backend parameter (odhs_solver_set_param), e.g. "tol"."""
        rc = lib.odhs_solver_set_param(self._p or self._closed(), enc(key, "key"), float(value))
        check_pending("Solver.set_param", rc)
        if rc:
            self._err(rc, "Solver.set_param")

    def get_stat(self, key):
        """A statistic (odhs_solver_get_stat): "iterations", "residual",
        "backward_error", "solves", the backend's own ones."""
        v = ffi.new("double *")
        rc = lib.odhs_solver_get_stat(self._p or self._closed(), enc(key, "key"), v)
        check_pending("Solver.get_stat", rc)
        if rc:
            self._err(rc, "Solver.get_stat")
        return v[0]

    def set_check_tolerance(self, tol):
        """Backward error above which a solve fails (default 1e-6;
        odhs_solver_set_check_tolerance)."""
        rc = lib.odhs_solver_set_check_tolerance(self._p or self._closed(), float(tol))
        if rc:
            self._err(rc, "Solver.set_check_tolerance")

    def set_refinement(self, steps):
        """Iterative refinement steps for direct backends (default 3;
        odhs_solver_set_refinement)."""
        rc = lib.odhs_solver_set_refinement(self._p or self._closed(), int(steps))
        if rc:
            self._err(rc, "Solver.set_refinement")

    @property
    def fallback(self):
        """The fallback solver (odhs_solver_set_fallback), or None. The
        fallback is kept alive while it is set."""
        return self._fallback

    @fallback.setter
    def fallback(self, other):
        p = self._p or self._closed()
        op = NULL if other is None else (other._p or other._closed())
        rc = lib.odhs_solver_set_fallback(p, op)
        if rc:
            self._err(rc, "Solver.fallback")
        if self._fallback is not None:
            self._h.remove_dep(self._fallback._h)
        self._fallback = other
        if other is not None:
            self._h.add_dep(other._h)

    def set_fallback(self, other):
        """Same as ``solver.fallback = other``."""
        self.fallback = other

    def solve(self, network, b, x0=None):
        """Solve N x = b on the network's current geometry
        (odhs_solver_solve); x0 is the initial guess (zeros by default).
        Returns x (Nc,)."""
        nc = network.count
        barr, pb = in_array(b, nc, "b")
        x, px = out_array((nc,))
        x[:] = 0.0 if x0 is None else x0
        rc = lib.odhs_solver_solve(self._p or self._closed(), network._cptr(), pb, px)
        check_pending("Solver.solve", rc, lambda: self.errmsg)
        if rc:
            self._err(rc, "Solver.solve")
        return x

    def solve_ls(self, network, g):
        """Least-squares contact forces x minimising |S^T x - g|, g of N*dim
        values (odhs_solver_solve_ls). Returns x (Nc,)."""
        n, d, nc = network.particles, network.dim, network.count
        garr, pg = in_array(g, n * d, "g", (n, d))
        x, px = out_array((nc,))
        x[:] = 0.0
        rc = lib.odhs_solver_solve_ls(self._p or self._closed(), network._cptr(), pg, px)
        check_pending("Solver.solve_ls", rc, lambda: self.errmsg)
        if rc:
            self._err(rc, "Solver.solve_ls")
        return x


__all__ = ["Solver", "SolverBackend", "available_solvers"]
