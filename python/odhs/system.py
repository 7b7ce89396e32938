"""The system handle (odhs_system): particles, radii, the periodic box with
Lees-Edwards strain, geometry queries, neighbour search, scene builders and
configuration files (extended XYZ, LAMMPS data, SVG pictures).

Arrays: positions are (n, dim) float64, radii (n,), the box (dim,). Every
getter returns a new array holding a *copy* of the library's values (the C
API copies into caller arrays; pass ``out=`` to reuse an array); every setter
copies the values in. Row-major x[i, k] is the C layout x[i*dim + k]."""

import collections

import numpy as np

from ._core import F64, NULL, Owned, cstr, enc, ffi, in_array, lib, out_array
from .errors import last_error, make_error

Separation = collections.namedtuple("Separation", "rij dist image")
Separation.__doc__ = """Minimum-image separation of a pair: rij (dim,) = R_j - R_i, dist = |rij|,
image (dim,) int lattice shift with rij = x_j - x_i + n0 a + n1 b + n2 c."""

Pairs = collections.namedtuple("Pairs", "i j rij gap")
Pairs.__doc__ = """Close pairs (System.pairs): arrays i, j (uintp, i < j), rij (m, dim) minimum-image
separations and gap (m,) = |rij| - (r_i + r_j), sorted by (i, j)."""


def _errbuf():
    return ffi.new("char[]", 1024)


class System(Owned):
    """A system of ``n`` discs (``dim`` = 2) or spheres (3) in a periodic box
    (``odhs_system_create``): a unit box, strain 0, radii and positions unset
    (the system is usable once both are set), species "A".

    Use as a context manager or call close(); a stepper or softcore handle
    using the system keeps it alive (closing it then only closes this
    Python object). Raises DimensionError, EmptyError, ..."""

    _kind = "system"

    def __init__(self, dim, n):
        if int(n) < 0:
            raise make_error(lib.ODHS_E_INVALID, "n = %d must be >= 0" % n, "System")
        out = ffi.new("odhs_system **")
        rc = lib.odhs_system_create(int(dim), int(n), out)
        if rc:
            raise make_error(rc, last_error(), "System")
        self._adopt(out[0])

    # --- construction helpers (not public) ---------------------------------
    def _adopt(self, ptr, deps=()):
        self._init_handle(ptr, lib.odhs_system_destroy, deps)
        self._view = False
        self._readonly = False
        self._dim = lib.odhs_system_dim(ptr)
        self._n = lib.odhs_system_count(ptr)

    @classmethod
    def _from_ptr(cls, ptr, deps=()):
        obj = cls.__new__(cls)
        obj._adopt(ptr, deps)
        return obj

    @classmethod
    def _borrow(cls, ptr, deps=()):
        """A read-only view of a system the library owns or that another
        wrapper owns (deps keep it alive; none: valid until invalidated)."""
        obj = cls.__new__(cls)
        obj._init_handle(ptr, None, deps)
        obj._view = True
        obj._readonly = True
        obj._dim = lib.odhs_system_dim(ptr)
        obj._n = lib.odhs_system_count(ptr)
        return obj

    def _invalidate(self):
        self._p = None
        self._h.release()

    def _closed(self):
        if getattr(self, "_view", False):
            raise ValueError("this system view was only valid inside the callback that received it")
        raise ValueError("this system is closed")

    def _err(self, rc, fn):
        p = self._p
        raise make_error(rc, cstr(lib.odhs_system_errmsg(p)) if p is not None else "", fn)

    def _w(self):
        """the pointer for a modifying call"""
        p = self._p or self._closed()
        if self._readonly:
            raise ValueError("this system is a read-only view (inside a callback): it cannot be changed")
        return p

    def _repr_extra(self):
        return " dim=%d n=%d%s" % (self._dim, self._n, "" if self.is_ready else " (not ready)")

    # --- basic queries -----------------------------------------------------
    @property
    def errmsg(self):
        """The message of the last failed call on this handle ("" if none)."""
        return cstr(lib.odhs_system_errmsg(self._p or self._closed()))

    @property
    def dim(self):
        """Dimension, 2 or 3 (odhs_system_dim)."""
        return self._dim

    @property
    def n(self):
        """Number of particles (odhs_system_count)."""
        return self._n

    def __len__(self):
        return self._n

    @property
    def is_ready(self):
        """Whether radii and positions are both set (odhs_system_is_ready)."""
        return bool(lib.odhs_system_is_ready(self._p or self._closed()))

    @property
    def change_count(self):
        """How many times the setters changed box, strain, radii or positions
        (odhs_system_change_count); a stepper refuses to step after a change
        until Stepper.reset()."""
        c = ffi.new("uint64_t *")
        rc = lib.odhs_system_change_count(self._p or self._closed(), c)
        if rc:
            self._err(rc, "System.change_count")
        return int(c[0])

    def clone(self):
        """A deep copy (odhs_system_clone): a new, independent System."""
        out = ffi.new("odhs_system **")
        rc = lib.odhs_system_clone(self._p or self._closed(), out)
        if rc:
            raise make_error(rc, last_error(), "System.clone")
        return System._from_ptr(out[0])

    # --- box and strain ----------------------------------------------------
    @property
    def box(self):
        """Box edge lengths, (dim,) float64 (copy). Setting it wraps the
        positions into the new box (odhs_system_set_box; no scaling)."""
        arr, p = out_array((self._dim,))
        rc = lib.odhs_system_get_box(self._p or self._closed(), p)
        if rc:
            self._err(rc, "System.box")
        return arr

    @box.setter
    def box(self, L):
        arr, p = in_array(L, self._dim, "box")
        rc = lib.odhs_system_set_box(self._w(), p)
        if rc:
            self._err(rc, "System.box")

    @property
    def volume(self):
        """Box volume (area in 2D) (odhs_system_volume)."""
        v = ffi.new("double *")
        rc = lib.odhs_system_volume(self._p or self._closed(), v)
        if rc:
            self._err(rc, "System.volume")
        return v[0]

    @property
    def strain(self):
        """The Lees-Edwards strain, remapped into [-Lx/(2Ly), Lx/(2Ly)]
        (odhs_system_get_strain / set_strain)."""
        g = ffi.new("double *")
        rc = lib.odhs_system_get_strain(self._p or self._closed(), g)
        if rc:
            self._err(rc, "System.strain")
        return g[0]

    @strain.setter
    def strain(self, gamma):
        rc = lib.odhs_system_set_strain(self._w(), float(gamma))
        if rc:
            self._err(rc, "System.strain")

    # --- radii and positions -----------------------------------------------
    def get_radii(self, out=None):
        """Radii as (n,) float64, a copy (into out when given)
        (odhs_system_get_radii; StateError before they are set)."""
        arr, p = out_array((self._n,), out)
        rc = lib.odhs_system_get_radii(self._p or self._closed(), p)
        if rc:
            self._err(rc, "System.get_radii")
        return arr

    def set_radii(self, r):
        """Set all radii from an array of n values (copied in;
        odhs_system_set_radii)."""
        arr, p = in_array(r, self._n, "radii")
        rc = lib.odhs_system_set_radii(self._w(), p)
        if rc:
            self._err(rc, "System.set_radii")

    radii = property(get_radii, set_radii, doc="Radii, (n,) float64 (a copy; assign to set them).")

    def get_positions(self, out=None):
        """Positions as (n, dim) float64 in the lab frame, wrapped into the box:
        a copy (into out when given) (odhs_system_get_positions)."""
        arr, p = out_array((self._n, self._dim), out)
        rc = lib.odhs_system_get_positions(self._p or self._closed(), p)
        if rc:
            self._err(rc, "System.get_positions")
        return arr

    def set_positions(self, x):
        """Set all positions from n*dim values, (n, dim) or flat (copied in,
        wrapped into the box; odhs_system_set_positions; OverlapError names
        the worst pair)."""
        arr, p = in_array(x, self._n * self._dim, "positions", (self._n, self._dim))
        rc = lib.odhs_system_set_positions(self._w(), p)
        if rc:
            self._err(rc, "System.set_positions")

    positions = property(get_positions, set_positions,
                         doc="Positions, (n, dim) float64 (a copy; assign to set them).")

    def set_configuration(self, box, strain, radii, positions):
        """Set box, strain, radii and positions at once and validate the
        whole; on any error nothing changes (odhs_system_set_configuration)."""
        L, pL = in_array(box, self._dim, "box")
        r, pr = in_array(radii, self._n, "radii")
        x, px = in_array(positions, self._n * self._dim, "positions", (self._n, self._dim))
        rc = lib.odhs_system_set_configuration(self._w(), pL, float(strain), pr, px)
        if rc:
            self._err(rc, "System.set_configuration")

    @classmethod
    def from_arrays(cls, box, radii, positions, strain=0.0):
        """A new system from a box (dim,), radii (n,) and positions (n, dim)."""
        x = np.asarray(positions, dtype=F64)
        if x.ndim != 2:
            raise ValueError("positions must have shape (n, dim), got %s" % (x.shape,))
        s = cls(x.shape[1], x.shape[0])
        try:
            s.set_configuration(box, strain, radii, x)
        except BaseException:
            s.close()
            raise
        return s

    # --- species -------------------------------------------------------------
    def set_species(self, i, label):
        """Set the species label of particle i (odhs_system_set_species)."""
        if int(i) < 0:
            raise make_error(lib.ODHS_E_RANGE, "index %d < 0" % i, "System.set_species")
        rc = lib.odhs_system_set_species(self._w(), int(i), enc(label, "label"))
        if rc:
            self._err(rc, "System.set_species")

    def get_species(self, i):
        """The species label of particle i (odhs_system_get_species)."""
        if int(i) < 0:
            raise make_error(lib.ODHS_E_RANGE, "index %d < 0" % i, "System.get_species")
        buf = ffi.new("char[]", lib.ODHS_SPECIES_MAX + 1)
        rc = lib.odhs_system_get_species(self._p or self._closed(), int(i), buf, lib.ODHS_SPECIES_MAX + 1)
        if rc:
            self._err(rc, "System.get_species")
        return ffi.string(buf).decode()

    @property
    def species(self):
        """All species labels as a list of str (one call per particle)."""
        return [self.get_species(i) for i in range(self._n)]

    # --- geometry ------------------------------------------------------------
    def scale_box(self, s):
        """Scale the box and all positions by s (odhs_system_scale_box)."""
        rc = lib.odhs_system_scale_box(self._w(), float(s))
        if rc:
            self._err(rc, "System.scale_box")

    @property
    def packing_fraction(self):
        """Sum of particle volumes over the box volume
        (odhs_system_packing_fraction)."""
        v = ffi.new("double *")
        rc = lib.odhs_system_packing_fraction(self._p or self._closed(), v)
        if rc:
            self._err(rc, "System.packing_fraction")
        return v[0]

    def separation(self, i, j):
        """Minimum-image separation of particles i and j
        (odhs_system_separation): a Separation(rij, dist, image)."""
        if int(i) < 0 or int(j) < 0:
            raise make_error(lib.ODHS_E_RANGE, "negative index", "System.separation")
        rij, prij = out_array((self._dim,))
        dist = ffi.new("double *")
        image = ffi.new("int[3]")
        rc = lib.odhs_system_separation(self._p or self._closed(), int(i), int(j), prij, dist, image)
        if rc:
            self._err(rc, "System.separation")
        return Separation(rij, dist[0], np.array([image[k] for k in range(self._dim)], dtype=np.intc))

    def validate(self, tol=0.0):
        """Check the whole configuration (odhs_system_validate); raises the
        error found (OverlapError, BoxError, ...)."""
        rc = lib.odhs_system_validate(self._p or self._closed(), float(tol))
        if rc:
            self._err(rc, "System.validate")

    def for_each_pair(self, max_gap, fn):
        """Call fn(i, j, rij, gap) for every pair with gap <= max_gap
        (odhs_system_for_each_pair; order unspecified; rij a new (dim,)
        array). fn returning a true value stops the enumeration (the call
        then returns Status.STOPPED); an exception in fn stops it and is
        re-raised here."""
        from . import _callbacks

        return _callbacks.for_each_pair(self, max_gap, fn)

    def pairs(self, max_gap):
        """Every pair with gap <= max_gap as arrays (a Pairs tuple sorted by
        (i, j)): i, j, rij (m, dim), gap (m,)."""
        I, J, R, G = [], [], [], []

        def collect(i, j, rij, gap):
            I.append(i)
            J.append(j)
            R.append(rij)
            G.append(gap)

        self.for_each_pair(max_gap, collect)
        i = np.array(I, dtype=np.uintp)
        j = np.array(J, dtype=np.uintp)
        order = np.lexsort((j, i))
        rij = np.array(R, dtype=F64).reshape(-1, self._dim)
        return Pairs(i[order], j[order], rij[order], np.array(G, dtype=F64)[order])

    # --- scene builders ------------------------------------------------------
    def set_radii_bidisperse(self, r_small, ratio, poly, seed):
        """50:50 bidisperse radii (odhs_system_set_radii_bidisperse):
        even particles r_small, odd r_small*ratio, each times a factor uniform
        in [1-poly, 1+poly]; species S and L; reproducible from seed."""
        rc = lib.odhs_system_set_radii_bidisperse(self._w(), float(r_small), float(ratio), float(poly),
                                                  _seed(seed))
        if rc:
            self._err(rc, "System.set_radii_bidisperse")

    def place_random(self, phi, seed):
        """Random sequential addition at packing fraction phi (sets the box;
        odhs_system_place_random; TooDenseError beyond its limit)."""
        rc = lib.odhs_system_place_random(self._w(), float(phi), _seed(seed))
        if rc:
            self._err(rc, "System.place_random")

    # --- files ---------------------------------------------------------------
    def write_xyz(self, path):
        """Write an extended XYZ file (odhs_xyz_write; bit-exact round trip)."""
        rc = lib.odhs_xyz_write(self._p or self._closed(), enc(path, "path"))
        if rc:
            self._err(rc, "System.write_xyz")

    def write_lammps_data(self, path):
        """Write a LAMMPS data file, atom_style sphere
        (odhs_lammps_data_write)."""
        rc = lib.odhs_lammps_data_write(self._p or self._closed(), enc(path, "path"))
        if rc:
            self._err(rc, "System.write_lammps_data")

    def write_svg(self, path, network=None, mark=None):
        """Draw the configuration as SVG (odhs_svg_write): discs coloured by
        size, contacts of `network` (a Network, e.g. Stepper.network) as lines
        of width proportional to the force; `mark` (n values) 1 = rattler
        ring, 2 = dark red."""
        net = network._cptr() if network is not None else NULL
        if mark is not None:
            m = np.ascontiguousarray(mark, dtype=np.uint8)
            if m.size != self._n:
                raise ValueError("mark must have %d values, got %d" % (self._n, m.size))
            pm = ffi.from_buffer("unsigned char[]", m)
        else:
            pm = NULL
        rc = lib.odhs_svg_write(self._p or self._closed(), net, pm, enc(path, "path"))
        if rc:
            self._err(rc, "System.write_svg")

    @classmethod
    def read_xyz(cls, path, frame=None):
        """Read an extended XYZ file (odhs_xyz_read), or frame `frame` of a
        multi-frame one (odhs_xyz_read_frame; -1 = the last). Raises
        FormatError etc. with the reader's message."""
        out = ffi.new("odhs_system **")
        err = _errbuf()
        if frame is None:
            rc = lib.odhs_xyz_read(enc(path, "path"), out, err, len(err))
        else:
            rc = lib.odhs_xyz_read_frame(enc(path, "path"), int(frame), out, NULL, err, len(err))
        if rc:
            raise make_error(rc, ffi.string(err).decode(errors="replace"), "System.read_xyz")
        return cls._from_ptr(out[0])

    @staticmethod
    def count_xyz_frames(path):
        """The number of frames of a multi-frame extended XYZ file."""
        out = ffi.new("odhs_system **")
        nframes = ffi.new("long *")
        err = _errbuf()
        rc = lib.odhs_xyz_read_frame(enc(path, "path"), 0, out, nframes, err, len(err))
        if rc:
            raise make_error(rc, ffi.string(err).decode(errors="replace"), "System.count_xyz_frames")
        lib.odhs_system_destroy(out[0])
        return int(nframes[0])

    @classmethod
    def parse_xyz(cls, data):
        """A system from extended XYZ text (str or bytes; odhs_xyz_parse)."""
        b = data.encode() if isinstance(data, str) else bytes(data)
        out = ffi.new("odhs_system **")
        err = _errbuf()
        rc = lib.odhs_xyz_parse(b, len(b), out, err, len(err))
        if rc:
            raise make_error(rc, ffi.string(err).decode(errors="replace"), "System.parse_xyz")
        return cls._from_ptr(out[0])

    @classmethod
    def read_lammps_data(cls, path):
        """Read a LAMMPS data file, atom_style sphere (odhs_lammps_data_read)."""
        out = ffi.new("odhs_system **")
        err = _errbuf()
        rc = lib.odhs_lammps_data_read(enc(path, "path"), out, err, len(err))
        if rc:
            raise make_error(rc, ffi.string(err).decode(errors="replace"), "System.read_lammps_data")
        return cls._from_ptr(out[0])

    @classmethod
    def parse_lammps_data(cls, data):
        """A system from LAMMPS data text (str or bytes; odhs_lammps_data_parse)."""
        b = data.encode() if isinstance(data, str) else bytes(data)
        out = ffi.new("odhs_system **")
        err = _errbuf()
        rc = lib.odhs_lammps_data_parse(b, len(b), out, err, len(err))
        if rc:
            raise make_error(rc, ffi.string(err).decode(errors="replace"), "System.parse_lammps_data")
        return cls._from_ptr(out[0])


def _seed(seed):
    s = int(seed)
    if s < 0 or s >= 1 << 64:
        raise make_error(lib.ODHS_E_INVALID, "seed %d is not in [0, 2^64)" % s, "seed")
    return s


__all__ = ["System", "Separation", "Pairs"]
