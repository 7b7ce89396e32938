"""Files: configurations (extended XYZ, LAMMPS data), pictures (SVG),
contacts (text, CSV) and trajectories (odhs_traj: multi-frame extended XYZ,
LAMMPS custom dumps, contact networks as LAMMPS dump local).

The readers return new System objects; the writers are also methods of
System, Network and Stepper."""

from ._core import Owned, cstr, enc, ffi, lib
from .constants import TrajFormat, to_enum
from .errors import make_error
from .system import System


def read_xyz(path, frame=None):
    """A System from an extended XYZ file (frame: see System.read_xyz)."""
    return System.read_xyz(path, frame)


def parse_xyz(data):
    """A System from extended XYZ text."""
    return System.parse_xyz(data)


def count_xyz_frames(path):
    """The number of frames of a multi-frame extended XYZ file."""
    return System.count_xyz_frames(path)


def write_xyz(system, path):
    """Write system as extended XYZ (odhs_xyz_write)."""
    system.write_xyz(path)


def read_lammps_data(path):
    """A System from a LAMMPS data file (atom_style sphere)."""
    return System.read_lammps_data(path)


def parse_lammps_data(data):
    """A System from LAMMPS data text."""
    return System.parse_lammps_data(data)


def write_lammps_data(system, path):
    """Write system as a LAMMPS data file (odhs_lammps_data_write)."""
    system.write_lammps_data(path)


def write_svg(path, system, network=None, mark=None):
    """Draw system (and the contacts of network) as SVG (odhs_svg_write)."""
    system.write_svg(path, network, mark)


def write_contacts(path, network, system):
    """Write network's contacts as text (odhs_contacts_write)."""
    network.write_contacts(path, system)


def write_contacts_csv(path, network, system):
    """Write network's contacts as CSV i,j,kind,force,gap
    (odhs_contacts_write_csv)."""
    network.write_contacts_csv(path, system)


def traj_format_for(path):
    """The trajectory format for a file name (.xyz/.extxyz: XYZ,
    .dump/.lammpstrj: LAMMPS_DUMP; odhs_traj_format_for); InvalidError for
    another ending."""
    f = ffi.new("int *")
    rc = lib.odhs_traj_format_for(enc(path, "path"), f)
    if rc:
        raise make_error(rc, "no trajectory format for the name %r (.xyz, .extxyz, .dump, .lammpstrj)" % (path,),
                         "traj_format_for")
    return TrajFormat(f[0])


class Trajectory(Owned):
    """A trajectory file opened for writing (odhs_traj_open; the file is
    created or truncated). format: a TrajFormat or its name ("xyz",
    "lammps_dump", "lammps_local"); None picks it from the file name. Use as
    a context manager or call close() (which reports a failed final write
    as FileError)."""

    _kind = "trajectory"

    def __init__(self, path, format=None):
        self.path = str(path)
        fmt = traj_format_for(path) if format is None else to_enum(TrajFormat, format, "trajectory format")
        out = ffi.new("odhs_traj **")
        err = ffi.new("char[]", 1024)
        rc = lib.odhs_traj_open(enc(path, "path"), int(fmt), out, err, len(err))
        if rc:
            raise make_error(rc, ffi.string(err).decode(errors="replace"), "Trajectory")
        self.format = fmt
        self._init_handle(out[0], _close_quietly)

    def _err(self, rc, fn):
        p = self._p
        raise make_error(rc, cstr(lib.odhs_traj_errmsg(p)) if p is not None else "", fn)

    def _repr_extra(self):
        return " %r %s" % (self.path, self.format.name)

    @property
    def errmsg(self):
        """The message of the handle's last error ("" if none)."""
        return cstr(lib.odhs_traj_errmsg(self._p or self._closed()))

    def write(self, system, stepper=None):
        """Append one frame: the system and, when given, the stepper moving
        it (velocities, forces, observables; needed for LAMMPS_LOCAL)
        (odhs_traj_write). On error nothing is added."""
        sp = ffi.NULL if stepper is None else (stepper._p or stepper._closed())
        rc = lib.odhs_traj_write(self._p or self._closed(), system._p or system._closed(), sp)
        if rc:
            self._err(rc, "Trajectory.write")

    @property
    def frames(self):
        """The number of frames written so far (odhs_traj_frames)."""
        c = ffi.new("uint64_t *")
        rc = lib.odhs_traj_frames(self._p or self._closed(), c)
        if rc:
            self._err(rc, "Trajectory.frames")
        return int(c[0])

    def close(self):
        """Flush and close the file (odhs_traj_close); FileError when the
        last data could not be written. Closing twice is harmless."""
        p = getattr(self, "_p", None)
        if p is None:
            return
        self._p = None
        status = []
        self._h.destroy = lambda ptr: status.append(lib.odhs_traj_close(ptr))
        self._h.release()  # a trajectory has no dependents: closed now
        if status and status[0]:
            raise make_error(status[0], "writing %s" % self.path, "Trajectory.close")


def _close_quietly(p):
    lib.odhs_traj_close(p)


__all__ = ["read_xyz", "parse_xyz", "count_xyz_frames", "write_xyz", "read_lammps_data", "parse_lammps_data",
           "write_lammps_data", "write_svg", "write_contacts", "write_contacts_csv", "traj_format_for",
           "Trajectory"]
