"""Internal plumbing shared by the odhs modules: the compiled cffi module,
ownership of C handles, array conversion and the slot through which an
exception raised inside a Python callback reaches the caller of the C call
that ran it. Nothing here is public API."""

import threading

import numpy as np

try:
    from ._cffi import ffi, lib
except ImportError as e:  # pragma: no cover - a clear message for an unbuilt tree
    raise ImportError(
        "odhs: the compiled module odhs._cffi is missing or cannot load libodhs (%s). Build it with "
        "`make python` in the libodhs tree (then PYTHONPATH=python), or install the package with "
        "`pip install --no-build-isolation --no-index ./python` against an installed libodhs "
        "(pkg-config odhs)." % e) from e

HEADER_VERSION = ffi.string(lib.odhs_py_header_version).decode()
LIBRARY_VERSION = ffi.string(lib.odhs_version_string()).decode()
if lib.odhs_version_number() != lib.ODHS_VERSION_NUMBER:  # pragma: no cover
    raise ImportError("odhs: compiled against libodhs %s headers but loaded libodhs %s: rebuild the module "
                      "(make python)" % (HEADER_VERSION, LIBRARY_VERSION))

NULL = ffi.NULL
F64 = np.dtype(np.float64)
# numpy types of the C types the API hands out
SIZE_T = np.dtype(np.uintp)
INT = np.dtype(np.intc)
assert SIZE_T.itemsize == ffi.sizeof("size_t") and INT.itemsize == ffi.sizeof("int")


def cstr(p):
    """A C string (const char *) as str; "" for NULL."""
    return ffi.string(p).decode("utf-8", "replace") if p != NULL else ""


def enc(s, what="string"):
    """str or bytes or os.PathLike -> bytes for a const char * argument."""
    import os

    if isinstance(s, os.PathLike):
        s = os.fspath(s)
    if isinstance(s, str):
        s = s.encode("utf-8")
    if not isinstance(s, bytes):
        raise TypeError("%s must be str, bytes or a path, not %s" % (what, type(s).__name__))
    if b"\0" in s:
        raise ValueError("%s contains a NUL character" % what)
    return s


# ---------------------------------------------------------------------------
# Ownership
# ---------------------------------------------------------------------------


_live = [0]


def live_handles():
    """How many C objects the bindings own and have not destroyed yet (for
    leak tests)."""
    return _live[0]


class Handle:
    """One C handle and what it needs kept alive.

    A wrapper (System, Stepper, ...) holds a Handle. A Handle holds strong
    references to the Handles it depends on (a stepper's system, driver and
    solver; a solver's fallback; a borrowed network's stepper) and counts the
    Handles that depend on it (``users``). The C object is destroyed when the
    Python side has let go (``release``: an explicit close, or the Handle
    being collected) *and* no dependent is left, so that neither an explicit
    close nor the order in which the garbage collector finalises a cycle can
    free a C object another C object still points to. ``keep`` holds Python
    objects the C side points to (callback contexts, solver tables)."""

    __slots__ = ("ptr", "destroy", "deps", "users", "released", "keep", "__weakref__")

    def __init__(self, ptr, destroy, deps=()):
        self.ptr = ptr
        self.destroy = destroy
        if destroy is not None:
            _live[0] += 1
        self.deps = []
        self.users = 0
        self.released = False
        self.keep = {}
        for d in deps:
            self.add_dep(d)

    def add_dep(self, dep):
        """Keep dep's C object alive at least as long as this one."""
        dep.users += 1
        self.deps.append(dep)

    def remove_dep(self, dep):
        """Undo add_dep (dep may then be destroyed)."""
        self.deps.remove(dep)
        dep.users -= 1
        dep._maybe_free()

    def release(self):
        """The Python side lets go; the C object goes once no dependent is left."""
        if not self.released:
            self.released = True
            self._maybe_free()

    def _maybe_free(self):
        if self.released and self.users == 0 and self.ptr is not None:
            ptr, self.ptr = self.ptr, None
            if self.destroy is not None:
                _live[0] -= 1
                self.destroy(ptr)
            deps, self.deps = self.deps, []
            self.keep = {}
            for d in deps:
                d.users -= 1
                d._maybe_free()

    def __del__(self):
        try:
            self.release()
        except Exception:  # pragma: no cover - never raise from a finaliser
            pass


class Owned:
    """Base of the wrappers of C handles: close(), context manager, closed.

    Subclasses set ``_kind`` (the C handle name, for messages) and create
    ``self._h`` (a Handle) and ``self._p`` (its pointer, None once closed)."""

    __slots__ = ("_h", "_p", "__weakref__")
    _kind = "handle"

    def _init_handle(self, ptr, destroy, deps=()):
        self._h = Handle(ptr, destroy, deps)
        self._p = ptr

    def _closed(self):
        raise ValueError("this %s is closed" % self._kind)

    @property
    def closed(self):
        """True after close() (the object can no longer be used)."""
        return self._p is None

    def close(self):
        """Release the C handle. Objects that still use it (a stepper using
        this system, driver or solver) keep it alive until they are closed or
        collected themselves; this object can no longer be used. Closing
        twice is harmless."""
        if getattr(self, "_p", None) is not None:
            self._p = None
            self._h.release()

    def __enter__(self):
        if self._p is None:
            self._closed()
        return self

    def __exit__(self, *exc):
        self.close()
        return False

    def _repr_extra(self):
        return ""

    def __repr__(self):
        if self._p is None:
            return "<odhs.%s (closed)>" % type(self).__name__
        return "<odhs.%s%s>" % (type(self).__name__, self._repr_extra())


# ---------------------------------------------------------------------------
# Arrays
# ---------------------------------------------------------------------------


def in_array(a, size, what, shape_hint=None):
    """a as a C-contiguous float64 array of `size` elements (any shape with
    that many elements is refused unless its size fits); returns (array,
    cdata pointer) - keep the array alive while the pointer is used."""
    arr = np.ascontiguousarray(a, dtype=F64)
    if arr.size != size:
        raise ValueError("%s must have %d values%s, got shape %s" % (
            what, size, " (shape %s)" % (shape_hint,) if shape_hint else "", arr.shape))
    return arr, ffi.from_buffer("double[]", arr)


def out_array(shape, out=None, dtype=F64, what="out"):
    """An output array of the given shape and dtype (out, checked, when
    given: C-contiguous, writable, right dtype and shape); returns (array,
    cdata pointer)."""
    if out is None:
        arr = np.empty(shape, dtype=dtype)
        if dtype is F64:  # the common case, without the table below
            return arr, ffi.from_buffer("double[]", arr)
    else:
        arr = out
        if not isinstance(arr, np.ndarray) or arr.dtype != dtype or arr.shape != tuple(shape) or \
                not arr.flags.c_contiguous or not arr.flags.writeable:
            raise ValueError("%s must be a writable C-contiguous %s array of shape %s" % (what, np.dtype(dtype),
                                                                                     tuple(shape)))
    ctype = {F64: "double[]", SIZE_T: "size_t[]", INT: "int[]", np.dtype(np.uint8): "unsigned char[]",
             np.dtype(np.int64): "int64_t[]"}[np.dtype(dtype)]
    return arr, ffi.from_buffer(ctype, arr, require_writable=True)


def view_of(ptr, n, writable=False):
    """A zero-copy float64 numpy view of n doubles at ptr (library memory:
    valid only as long as the library keeps it)."""
    if n == 0:
        return np.empty(0, dtype=F64)
    arr = np.frombuffer(ffi.buffer(ptr, n * 8), dtype=F64)
    if not writable:
        arr.flags.writeable = False
    return arr


# ---------------------------------------------------------------------------
# Exceptions raised inside callbacks
# ---------------------------------------------------------------------------

_tls = threading.local()


def set_pending(exc):
    """Remember exc (raised by a Python callback) for the C call running it;
    the first one wins."""
    if getattr(_tls, "pending", None) is None:
        _tls.pending = exc


def take_pending():
    """The exception a callback raised during the last C call (and forget
    it), or None."""
    exc = getattr(_tls, "pending", None)
    if exc is not None:
        _tls.pending = None
    return exc


def clear_pending():
    _tls.pending = None
