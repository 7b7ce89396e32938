"""Status codes and exceptions.

Every C call returns a status: 0 success, positive a warning or an
informative stop (the call did its work), negative an error (the handle is as
it was before the call). The bindings return the non-negative ones as
:class:`Status` values and raise the negative ones as :class:`Error`
subclasses (one per status, named after it) that carry the status, its name
(``"ODHS_E_INVALID"``), the library's description (``odhs_strerror``) and the
message of the handle the call was made on (``odhs_<handle>_errmsg``; for a
failed create ``odhs_last_error()``; for the file readers their error
buffer)."""

import enum

from ._core import cstr, lib


class Status(enum.IntEnum):
    """The library's status codes (common.h), with the ``ODHS_`` prefix
    dropped: ``Status.JAMMED`` is ``ODHS_JAMMED``, ``Status.E_INVALID`` is
    ``ODHS_E_INVALID``. Calls return the non-negative ones."""

    OK = lib.ODHS_OK
    STOPPED = lib.ODHS_STOPPED
    POTENTIALLY_JAMMED = lib.ODHS_POTENTIALLY_JAMMED
    JAMMED = lib.ODHS_JAMMED
    STEP_LIMIT = lib.ODHS_STEP_LIMIT
    E_NULL = lib.ODHS_E_NULL
    E_INVALID = lib.ODHS_E_INVALID
    E_NOMEM = lib.ODHS_E_NOMEM
    E_DIM = lib.ODHS_E_DIM
    E_RANGE = lib.ODHS_E_RANGE
    E_NONFINITE = lib.ODHS_E_NONFINITE
    E_OVERLAP = lib.ODHS_E_OVERLAP
    E_BOX = lib.ODHS_E_BOX
    E_EMPTY = lib.ODHS_E_EMPTY
    E_IO = lib.ODHS_E_IO
    E_FORMAT = lib.ODHS_E_FORMAT
    E_STATE = lib.ODHS_E_STATE
    E_SINGULAR = lib.ODHS_E_SINGULAR
    E_NOCONV = lib.ODHS_E_NOCONV
    E_NOTINSTALLED = lib.ODHS_E_NOTINSTALLED
    E_REWIRE = lib.ODHS_E_REWIRE
    E_CALLBACK = lib.ODHS_E_CALLBACK
    E_UNSUPPORTED = lib.ODHS_E_UNSUPPORTED
    E_TOODENSE = lib.ODHS_E_TOODENSE
    E_INTERNAL = lib.ODHS_E_INTERNAL
    E_STALLED = lib.ODHS_E_STALLED

    @property
    def c_name(self):
        """The C name, e.g. ``"ODHS_E_INVALID"``."""
        return "ODHS_" + self.name

    @property
    def description(self):
        """The library's English description (odhs_strerror)."""
        return strerror(self.value)


def strerror(status):
    """The library's description of a status code (``odhs_strerror``)."""
    return cstr(lib.odhs_strerror(int(status)))


def status_name(status):
    """The C name of a status code ("ODHS_E_INVALID"), or "ODHS_<n>" for a
    code this module does not know (a newer library)."""
    try:
        return Status(status).c_name
    except ValueError:
        return "ODHS_%d" % status


def last_error():
    """The message of the last failed create in this thread
    (``odhs_last_error``; "" after a successful one)."""
    return cstr(lib.odhs_last_error())


class Error(Exception):
    """A libodhs call failed. Attributes: ``status`` (the negative code),
    ``status_name`` ("ODHS_E_..."), ``description`` (odhs_strerror),
    ``message`` (the handle's message, may be "") and ``function`` (the
    binding that failed, may be "")."""

    status = None
    status_code = None  # the class's status (set on the subclasses)

    def __init__(self, *args):
        """Error(status, message="", function=""), or for a subclass
        Error(message="", function=""): e.g. a Python solver backend raises
        odhs.SingularError("pivot 3 is zero")."""
        if args and isinstance(args[0], int):
            status, rest = args[0], args[1:]
        else:
            status, rest = self.status_code, args
        if status is None:
            raise TypeError("odhs.Error(status, message='', function=''): the status is missing")
        message = rest[0] if rest else ""
        function = rest[1] if len(rest) > 1 else ""
        self.status = int(status)
        self.status_name = status_name(self.status)
        self.description = strerror(self.status)
        self.message = message or ""
        self.function = function or ""
        text = "%s (%s)" % (self.status_name, self.description)
        if self.function:
            text = "%s: %s" % (self.function, text)
        if self.message:
            text += ": " + self.message
        super().__init__(text)


Error.__module__ = "odhs"


def _make(name, status, bases, doc):
    # shown as odhs.InvalidError (the package exports them)
    return type(name, (Error,) + bases, {"__doc__": doc, "__module__": "odhs", "status_code": status})


NullError = _make("NullError", lib.ODHS_E_NULL, (ValueError,), "ODHS_E_NULL: a required argument was missing.")
InvalidError = _make("InvalidError", lib.ODHS_E_INVALID, (ValueError,),
                     "ODHS_E_INVALID: an argument has an invalid value.")
NoMemoryError = _make("NoMemoryError", lib.ODHS_E_NOMEM, (MemoryError,), "ODHS_E_NOMEM: allocation failed.")
DimensionError = _make("DimensionError", lib.ODHS_E_DIM, (ValueError,),
                       "ODHS_E_DIM: dimension not 2 or 3, or inconsistent.")
RangeError = _make("RangeError", lib.ODHS_E_RANGE, (IndexError,), "ODHS_E_RANGE: an index is out of range.")
NonFiniteError = _make("NonFiniteError", lib.ODHS_E_NONFINITE, (ValueError,),
                       "ODHS_E_NONFINITE: a NaN or infinite number was given or found.")
OverlapError = _make("OverlapError", lib.ODHS_E_OVERLAP, (ValueError,), "ODHS_E_OVERLAP: two particles overlap.")
BoxError = _make("BoxError", lib.ODHS_E_BOX, (ValueError,),
                 "ODHS_E_BOX: a box edge is shorter than two largest diameters.")
EmptyError = _make("EmptyError", lib.ODHS_E_EMPTY, (ValueError,),
                   "ODHS_E_EMPTY: empty system (N = 0) or nothing to do.")
FileError = _make("FileError", lib.ODHS_E_IO, (OSError,),
                  "ODHS_E_IO: a file could not be opened, read or written.")
FormatError = _make("FormatError", lib.ODHS_E_FORMAT, (ValueError,), "ODHS_E_FORMAT: a file is malformed.")
StateError = _make("StateError", lib.ODHS_E_STATE, (RuntimeError,),
                   "ODHS_E_STATE: call made in the wrong order or state.")
SingularError = _make("SingularError", lib.ODHS_E_SINGULAR, (ArithmeticError,),
                      "ODHS_E_SINGULAR: singular or indefinite matrix. A Python solver backend may raise it to "
                      "report a singular network (the auto solver and fallbacks then try another backend).")
NoConvergenceError = _make("NoConvergenceError", lib.ODHS_E_NOCONV, (ArithmeticError,),
                           "ODHS_E_NOCONV: an iterative solver did not converge (a Python backend may raise it).")
NotInstalledError = _make("NotInstalledError", lib.ODHS_E_NOTINSTALLED, (),
                          "ODHS_E_NOTINSTALLED: feature or backend not built into this library.")
RewireError = _make("RewireError", lib.ODHS_E_REWIRE, (RuntimeError,),
                    "ODHS_E_REWIRE: rewiring did not reach a valid network.")
CallbackError = _make("CallbackError", lib.ODHS_E_CALLBACK, (RuntimeError,),
                      "ODHS_E_CALLBACK: a user callback failed or returned NaN. (When a Python callback raised, "
                      "its own exception is raised instead, with this status added as a note.)")
UnsupportedError = _make("UnsupportedError", lib.ODHS_E_UNSUPPORTED, (ValueError,),
                         "ODHS_E_UNSUPPORTED: combination of settings not supported.")
TooDenseError = _make("TooDenseError", lib.ODHS_E_TOODENSE, (ValueError,),
                      "ODHS_E_TOODENSE: random placement could not reach the packing fraction.")
InternalError = _make("InternalError", lib.ODHS_E_INTERNAL, (RuntimeError,),
                      "ODHS_E_INTERNAL: internal inconsistency (a bug in libodhs: report it).")
StalledError = _make("StalledError", lib.ODHS_E_STALLED, (RuntimeError,),
                     "ODHS_E_STALLED: a run made no progress over the stall limit, or no event can ever happen.")

_BY_STATUS = {cls.status_code: cls for cls in (
    NullError, InvalidError, NoMemoryError, DimensionError, RangeError, NonFiniteError, OverlapError, BoxError,
    EmptyError, FileError, FormatError, StateError, SingularError, NoConvergenceError, NotInstalledError,
    RewireError, CallbackError, UnsupportedError, TooDenseError, InternalError, StalledError)}


def error_class(status):
    """The exception class of a negative status (Error for an unknown one)."""
    return _BY_STATUS.get(int(status), Error)


def make_error(status, message="", function=""):
    """The exception for a negative status."""
    return error_class(status)(status, message, function)


def status_of(rc):
    """A non-negative return code as a Status (an int for unknown codes)."""
    try:
        return Status(rc)
    except ValueError:
        return rc
