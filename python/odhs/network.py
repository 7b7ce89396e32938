"""The contact network and the operator S (odhs_network).

A Network is either owned (``Network(system)``: an empty network you fill
and query, e.g. to test a solver), or a read-only view of a network the
library owns: ``Stepper.network`` (valid while the stepper lives: the view
keeps it alive) or the ``network`` argument of a Python solver backend's
methods (valid only during that call). Every array returned is a copy."""

import numpy as np

from ._core import INT, NULL, SIZE_T, Owned, cstr, enc, ffi, in_array, lib, out_array
from ._callbacks import check_pending
from .constants import ContactKind, to_enum
from .errors import last_error, make_error
from .records import Constrained


class Network(Owned):
    """An empty contact network for the particles of `system`
    (odhs_network_create; it remembers N and the dimension, and reads the
    geometry from a system in detect() and update_geometry()).

    Contacts (i, j) have i < j; walls are j = N + w. Contact indices
    0..Nc-1 change when contacts are added or removed."""

    _kind = "network"

    def __init__(self, system):
        out = ffi.new("odhs_network **")
        rc = lib.odhs_network_create(system._p or system._closed(), out)
        if rc:
            raise make_error(rc, last_error(), "Network")
        self._init_handle(out[0], lib.odhs_network_destroy)
        self._readonly = False
        self._view = False

    @classmethod
    def _borrow(cls, ptr, deps=()):
        obj = cls.__new__(cls)
        obj._init_handle(ptr, None, deps)
        obj._readonly = True
        obj._view = not deps
        return obj

    def _invalidate(self):
        self._p = None
        self._h.release()

    def _closed(self):
        if getattr(self, "_view", False):
            raise ValueError("this network view was only valid inside the solver call that received it")
        raise ValueError("this network is closed")

    def _cptr(self):
        return self._p or self._closed()

    def _w(self):
        p = self._p or self._closed()
        if self._readonly:
            raise ValueError("this network belongs to the library (a stepper's or a solver call's): it is read-only")
        return p

    def _err(self, rc, fn):
        p = self._p
        raise make_error(rc, cstr(lib.odhs_network_errmsg(p)) if p is not None else "", fn)

    def _repr_extra(self):
        return " n=%d dim=%d contacts=%d%s" % (self.particles, self.dim, self.count,
                                                 " (read-only)" if self._readonly else "")

    @property
    def readonly(self):
        """True for the library's networks (a stepper's, a solver call's)."""
        return self._readonly

    @property
    def errmsg(self):
        """The message of the last failed call on this handle ("" if none)."""
        return cstr(lib.odhs_network_errmsg(self._cptr()))

    # --- sizes -----------------------------------------------------------------
    @property
    def count(self):
        """Number of contacts Nc (odhs_network_count)."""
        return lib.odhs_network_count(self._cptr())

    def __len__(self):
        return self.count

    @property
    def particles(self):
        """Number of particles N the network was made for."""
        return lib.odhs_network_particles(self._cptr())

    @property
    def dim(self):
        """Dimension the network was made for."""
        return lib.odhs_network_dim(self._cptr())

    @property
    def nnz(self):
        """Nonzeros of S (2*dim per particle contact)."""
        return lib.odhs_network_nnz(self._cptr())

    # --- editing ---------------------------------------------------------------
    def add(self, i, j, kind=ContactKind.TEMPORARY):
        """Add the contact (i, j) of the given kind (ContactKind or its
        name; odhs_network_add)."""
        _nonneg(i, j, fn="Network.add")
        rc = lib.odhs_network_add(self._w(), int(i), int(j), int(to_enum(ContactKind, kind, "contact kind")))
        if rc:
            self._err(rc, "Network.add")

    def add_bond(self, i, j, rest):
        """Add a permanent contact held at centre distance rest
        (odhs_network_add_bond)."""
        _nonneg(i, j, fn="Network.add_bond")
        rc = lib.odhs_network_add_bond(self._w(), int(i), int(j), float(rest))
        if rc:
            self._err(rc, "Network.add_bond")

    def rest_length(self, k, system):
        """Target distance of contact k: its rest length for a bond, else
        a_i + a_j with the radii of system (odhs_network_get_rest_length)."""
        _nonneg(k, fn="Network.rest_length")
        v = ffi.new("double *")
        rc = lib.odhs_network_get_rest_length(self._cptr(), system._p or system._closed(), int(k), v)
        if rc:
            self._err(rc, "Network.rest_length")
        return v[0]

    def remove(self, i, j):
        """Remove the contact (i, j) (odhs_network_remove)."""
        _nonneg(i, j, fn="Network.remove")
        rc = lib.odhs_network_remove(self._w(), int(i), int(j))
        if rc:
            self._err(rc, "Network.remove")

    def clear(self):
        """Remove every contact (odhs_network_clear)."""
        rc = lib.odhs_network_clear(self._w())
        if rc:
            self._err(rc, "Network.clear")

    def find(self, i, j):
        """The index of contact (i, j), or None (odhs_network_find)."""
        if int(i) < 0 or int(j) < 0:
            return None
        idx = ffi.new("size_t *")
        rc = lib.odhs_network_find(self._cptr(), int(i), int(j), idx)
        if rc:
            self._err(rc, "Network.find")
        return None if idx[0] == _SIZE_MAX else int(idx[0])

    def __contains__(self, pair):
        i, j = pair
        return self.find(min(i, j), max(i, j)) is not None

    def detect(self, system, tol):
        """Add as temporary contacts all pairs of system whose gap is at
        most tol*(a_i + a_j), then update the geometry (odhs_network_detect)."""
        rc = lib.odhs_network_detect(self._w(), system._p or system._closed(), float(tol))
        if rc:
            self._err(rc, "Network.detect")

    def update_geometry(self, system):
        """Recompute normals, distances and gaps from system
        (odhs_network_update_geometry)."""
        rc = lib.odhs_network_update_geometry(self._w(), system._p or system._closed())
        if rc:
            self._err(rc, "Network.update_geometry")

    # --- per-contact data ----------------------------------------------------------
    def contact(self, k):
        """Contact k as (i, j, kind) (odhs_network_get_contact)."""
        _nonneg(k, fn="Network.contact")
        i, j, kind = ffi.new("size_t *"), ffi.new("size_t *"), ffi.new("int *")
        rc = lib.odhs_network_get_contact(self._cptr(), int(k), i, j, kind)
        if rc:
            self._err(rc, "Network.contact")
        return int(i[0]), int(j[0]), ContactKind(kind[0])

    def contacts(self):
        """Every contact as arrays (i, j, kind): i, j uintp, kind intc, each
        of Nc entries (copies; odhs_network_get_contacts)."""
        nc = self.count
        i, pi = out_array((nc,), dtype=SIZE_T)
        j, pj = out_array((nc,), dtype=SIZE_T)
        kind, pk = out_array((nc,), dtype=INT)
        if nc:
            rc = lib.odhs_network_get_contacts(self._cptr(), pi, pj, pk)
            if rc:
                self._err(rc, "Network.contacts")
        return i, j, kind

    def _per_contact(self, fn, name, cols=None, out=None):
        nc = self.count
        shape = (nc,) if cols is None else (nc, cols)
        arr, p = out_array(shape, out)
        if nc:
            rc = fn(self._cptr(), p)
            if rc:
                self._err(rc, name)
        return arr

    def get_forces(self, out=None):
        """Contact forces (Nc,), a copy (odhs_network_get_forces)."""
        return self._per_contact(lib.odhs_network_get_forces, "Network.get_forces", out=out)

    def set_forces(self, f):
        """Set the forces (Nc values; odhs_network_set_forces)."""
        arr, p = in_array(f, self.count, "forces")
        rc = lib.odhs_network_set_forces(self._w(), p)
        if rc:
            self._err(rc, "Network.set_forces")

    forces = property(get_forces, set_forces, doc="Contact forces, (Nc,) float64 (a copy; assign to set).")

    @property
    def gaps(self):
        """Contact gaps r - a_i - a_j, (Nc,) (copy; odhs_network_get_gaps)."""
        return self._per_contact(lib.odhs_network_get_gaps, "Network.gaps")

    @property
    def normals(self):
        """Unit normals n_c = R_ij/r_ij, (Nc, dim) (copy;
        odhs_network_get_normals)."""
        return self._per_contact(lib.odhs_network_get_normals, "Network.normals", cols=self.dim)

    # --- the operator S ------------------------------------------------------------
    def apply_S(self, v):
        """S v: (Nc,) from v of N*dim values (odhs_network_apply_S)."""
        n, d, nc = self.particles, self.dim, self.count
        arr, p = in_array(v, n * d, "v", (n, d))
        out, po = out_array((nc,))
        rc = lib.odhs_network_apply_S(self._cptr(), p, po)
        if rc:
            self._err(rc, "Network.apply_S")
        return out

    def apply_ST(self, f):
        """S^T f: (N, dim) from f of Nc values (the contact force on every
        particle; odhs_network_apply_ST)."""
        n, d, nc = self.particles, self.dim, self.count
        arr, p = in_array(f, nc, "f")
        out, po = out_array((n, d))
        rc = lib.odhs_network_apply_ST(self._cptr(), p, po)
        if rc:
            self._err(rc, "Network.apply_ST")
        return out

    def apply_N(self, x):
        """N x = S S^T x: (Nc,) (odhs_network_apply_N)."""
        n, d, nc = self.particles, self.dim, self.count
        arr, p = in_array(x, nc, "x")
        out, po = out_array((nc,))
        work, pw = out_array((n * d,))
        rc = lib.odhs_network_apply_N(self._cptr(), p, po, pw)
        if rc:
            self._err(rc, "Network.apply_N")
        return out

    def S_csr(self):
        """S in compressed sparse row form (rowptr (Nc+1,), col (nnz,) uintp,
        val (nnz,)); scipy.sparse.csr_matrix((val, col, rowptr), shape=(Nc,
        N*dim)) builds the matrix (odhs_network_get_S_csr)."""
        nc, nnz = self.count, self.nnz
        rowptr, pr = out_array((nc + 1,), dtype=SIZE_T)
        col, pc = out_array((nnz,), dtype=SIZE_T)
        val, pv = out_array((nnz,))
        rc = lib.odhs_network_get_S_csr(self._cptr(), pr, pc, pv)
        if rc:
            self._err(rc, "Network.S_csr")
        return rowptr, col, val

    def S_dense(self):
        """S as a dense (Nc, N*dim) array (from S_csr; small networks)."""
        rowptr, col, val = self.S_csr()
        S = np.zeros((self.count, self.particles * self.dim))
        for c in range(self.count):
            S[c, col[rowptr[c]:rowptr[c + 1]]] = val[rowptr[c]:rowptr[c + 1]]
        return S

    # --- structure -------------------------------------------------------------------
    @property
    def coordination(self):
        """Mean coordination z = 2 Nc / N (odhs_network_coordination)."""
        z = ffi.new("double *")
        rc = lib.odhs_network_coordination(self._cptr(), z)
        if rc:
            self._err(rc, "Network.coordination")
        return z[0]

    def constrained(self):
        """The constrained subset (odhs_network_constrained): a Constrained
        record (n_backbone, n_contacts, in_subset bool (N,), zbar_num)."""
        nbar, ncon, zn = ffi.new("size_t *"), ffi.new("size_t *"), ffi.new("long *")
        flags, pf = out_array((self.particles,), dtype=np.uint8)
        rc = lib.odhs_network_constrained(self._cptr(), nbar, ncon, pf, zn)
        if rc:
            self._err(rc, "Network.constrained")
        return Constrained(int(nbar[0]), int(ncon[0]), flags.astype(bool), int(zn[0]))

    def rattlers(self):
        """Rattlers (particles outside the constrained subset) as an (N,) bool
        array (odhs_network_rattlers)."""
        flags, pf = out_array((self.particles,), dtype=np.uint8)
        rc = lib.odhs_network_rattlers(self._cptr(), pf, NULL)
        if rc:
            self._err(rc, "Network.rattlers")
        return flags.astype(bool)

    @property
    def potentially_jammed(self):
        """Whether the constrained subset is potentially jammed, Ncon >=
        d(Nbar-1)+1 (odhs_network_potentially_jammed)."""
        flag = ffi.new("int *")
        rc = lib.odhs_network_potentially_jammed(self._cptr(), flag)
        if rc:
            self._err(rc, "Network.potentially_jammed")
        return bool(flag[0])

    def null_vector(self, solver=None):
        """The self-stress f0 of a potentially jammed network and its
        residual max|S^T f0|/mean f0 (odhs_network_null_vector): (f0 (Nc,),
        residual). StateError when the network is not potentially jammed."""
        f0, pf = out_array((self.count,))
        res = ffi.new("double *")
        sp = solver._p or solver._closed() if solver is not None else NULL
        rc = lib.odhs_network_null_vector(self._cptr(), sp, pf, res)
        check_pending("Network.null_vector", rc)
        if rc:
            self._err(rc, "Network.null_vector")
        return f0, res[0]

    # --- files -----------------------------------------------------------------------
    def write_contacts(self, path, system):
        """Write the contacts as text with lattice images
        (odhs_contacts_write)."""
        rc = lib.odhs_contacts_write(self._cptr(), system._p or system._closed(), enc(path, "path"))
        if rc:
            self._err(rc, "Network.write_contacts")

    def write_contacts_csv(self, path, system):
        """Write the contacts as CSV i,j,kind,force,gap
        (odhs_contacts_write_csv)."""
        rc = lib.odhs_contacts_write_csv(self._cptr(), system._p or system._closed(), enc(path, "path"))
        if rc:
            self._err(rc, "Network.write_contacts_csv")


_SIZE_MAX = int(ffi.cast("size_t", -1))


def _nonneg(*vals, fn):
    for v in vals:
        if int(v) < 0:
            raise make_error(lib.ODHS_E_RANGE, "index %d < 0" % v, fn)


__all__ = ["Network"]
