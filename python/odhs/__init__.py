"""odhs - Python bindings of libodhs, event-driven simulation of overdamped
frictionless hard spheres (Lerner, Duering and Wyart 2013).

The classes mirror the C handles: System (odhs_system), Driver
(odhs_driver), Solver (odhs_solver; SolverBackend for backends written in
Python), Stepper (odhs_stepper, with walls, composites, the jamming
certificate and checkpoints), Network (odhs_network), Softcore
(odhs_softcore) and Trajectory (odhs_traj); odhs.analysis holds the
analysis calls (analysis.h). Arrays go in and out as numpy
float64 arrays of shape (n, dim), (n,) or (Nc,); errors are raised as
odhs.Error subclasses named after the status (InvalidError for
ODHS_E_INVALID, ...), carrying the status and the handle's message. See
docs/python.md for the tutorial.

    import odhs
    with odhs.System(2, 64) as sys:
        sys.set_radii_bidisperse(0.5, 1.4, 0.03, 7)
        sys.place_random(0.45, 7)
        st = odhs.Stepper(sys, odhs.Driver(shear_rate=1.0), odhs.Solver("auto"))
        st.run_until_strain(0.5)
        print(st.shear_stress, st.pressure, st.coordination)
"""

from . import analysis
from ._core import HEADER_VERSION, LIBRARY_VERSION, ffi, lib
from .constants import (ContactKind, EventKind, Feature, Integrator, Minimiser, Oscillation, SoftcoreIntegrator,
                        SoftcoreModel, SolverFlag, StressPart, TrajFormat, WallShape)
from .driver import Driver
from .errors import (BoxError, CallbackError, DimensionError, EmptyError, Error, FileError, FormatError,
                     InternalError, InvalidError, NoConvergenceError, NoMemoryError, NonFiniteError,
                     NotInstalledError, NullError, OverlapError, RangeError, RewireError, SingularError,
                     StalledError, StateError, Status, TooDenseError, UnsupportedError, error_class, last_error,
                     status_name, strerror)
from .io import (Trajectory, count_xyz_frames, parse_lammps_data, parse_xyz, read_lammps_data, read_xyz,
                 traj_format_for, write_contacts, write_contacts_csv, write_lammps_data, write_svg, write_xyz)
from .network import Network
from .records import (AdaptiveStats, BatchedStats, Certificate, CorrectionStats, Constrained, Contacts, Counts, Errors,
                      Event, JamLpReport, OscillatoryShear, Propulsion, RunLimits, Settings, SoftcoreCounts, SolverInfo, StepInfo)
from .softcore import Softcore
from .solver import Solver, SolverBackend, available_solvers
from .stepper import Stepper, parse_checkpoint, read_checkpoint
from .system import Pairs, Separation, System

__version__ = LIBRARY_VERSION


def version():
    """The run-time version of the loaded libodhs, "MAJOR.MINOR.PATCH"
    (odhs_version_string)."""
    return LIBRARY_VERSION


def version_number():
    """The run-time version number MAJOR*10000 + MINOR*100 + PATCH
    (odhs_version_number)."""
    return lib.odhs_version_number()


def header_version():
    """The version of the headers the extension was compiled against."""
    return HEADER_VERSION


def library_path():
    """The file name of the loaded libodhs shared library (the dynamic
    loader's dladdr), or None when it cannot be told."""
    import ctypes

    class _DlInfo(ctypes.Structure):
        _fields_ = [("fname", ctypes.c_char_p), ("fbase", ctypes.c_void_p), ("sname", ctypes.c_char_p),
                    ("saddr", ctypes.c_void_p)]

    try:
        dladdr = ctypes.CDLL(None).dladdr
    except (OSError, AttributeError):
        return None
    dladdr.argtypes = [ctypes.c_void_p, ctypes.POINTER(_DlInfo)]
    info = _DlInfo()
    addr = int(ffi.cast("uintptr_t", lib.odhs_version_string()))  # a static string of libodhs itself
    if dladdr(ctypes.c_void_p(addr), ctypes.byref(info)) and info.fname:
        return info.fname.decode()
    return None


__all__ = [
    "System", "Driver", "Solver", "SolverBackend", "Stepper", "Network", "Softcore", "Trajectory",
    "read_checkpoint", "parse_checkpoint", "available_solvers",
    "read_xyz", "parse_xyz", "count_xyz_frames", "write_xyz", "read_lammps_data", "parse_lammps_data",
    "write_lammps_data", "write_svg", "write_contacts", "write_contacts_csv", "traj_format_for",
    "Status", "Error", "NullError", "InvalidError", "NoMemoryError", "DimensionError", "RangeError",
    "NonFiniteError", "OverlapError", "BoxError", "EmptyError", "FileError", "FormatError", "StateError",
    "SingularError", "NoConvergenceError", "NotInstalledError", "RewireError", "CallbackError",
    "UnsupportedError", "TooDenseError", "InternalError", "StalledError", "error_class", "strerror",
    "status_name", "last_error",
    "EventKind", "ContactKind", "Integrator", "Oscillation", "Feature", "WallShape", "TrajFormat",
    "SoftcoreModel", "SoftcoreIntegrator", "Minimiser", "StressPart", "SolverFlag",
    "Event", "StepInfo", "Counts", "Settings", "RunLimits", "AdaptiveStats", "BatchedStats", "CorrectionStats", "Errors", "Contacts", "Constrained",
    "Certificate", "JamLpReport", "Propulsion", "OscillatoryShear", "SoftcoreCounts", "SolverInfo", "Separation", "Pairs",
    "version", "version_number", "header_version", "library_path",
]
