"""What drives the particles (odhs_driver): shear and compression rates,
fixed pressure, oscillatory shear, external forces (fixed arrays or a Python
callback), self-propulsion, gravity, mobility and the time unit."""

import numpy as np

from ._core import F64, NULL, Owned, cstr, ffi, lib, out_array
from ._callbacks import ForceContext
from .constants import Oscillation, to_enum
from .errors import last_error, make_error
from .records import OscillatoryShear, Propulsion


class Driver(Owned):
    """A driver (odhs_driver_create): no flow, no forces, mobility xi0 = 1.
    Keyword arguments set properties at once, e.g. ``Driver(shear_rate=1.0)``
    or ``Driver(compression_rate=1.0)``. Changes are picked up by the next
    step of the steppers using it."""

    _kind = "driver"

    def __init__(self, **settings):
        out = ffi.new("odhs_driver **")
        rc = lib.odhs_driver_create(out)
        if rc:
            raise make_error(rc, last_error(), "Driver")
        self._adopt(out[0])
        try:
            for k, v in settings.items():
                if not isinstance(getattr(type(self), k, None), property):
                    raise TypeError("Driver() got an unexpected keyword argument %r" % k)
                setattr(self, k, v)
        except BaseException:
            self.close()
            raise

    def _adopt(self, ptr, deps=()):
        self._init_handle(ptr, lib.odhs_driver_destroy, deps)
        self._force_fn = None
        self._prop_shape = None  # (n, dim) of the self-propulsion, when known

    @classmethod
    def _from_ptr(cls, ptr, deps=(), prop_shape=None):
        obj = cls.__new__(cls)
        obj._adopt(ptr, deps)
        obj._prop_shape = prop_shape
        return obj

    def _err(self, rc, fn):
        p = self._p
        raise make_error(rc, cstr(lib.odhs_driver_errmsg(p)) if p is not None else "", fn)

    def _get(self, cfn, name):
        v = ffi.new("double *")
        rc = cfn(self._p or self._closed(), v)
        if rc:
            self._err(rc, name)
        return v[0]

    def _set(self, cfn, value, name):
        rc = cfn(self._p or self._closed(), float(value))
        if rc:
            self._err(rc, name)

    @property
    def errmsg(self):
        """The message of the last failed call on this handle ("" if none)."""
        return cstr(lib.odhs_driver_errmsg(self._p or self._closed()))

    # --- flow ------------------------------------------------------------------
    @property
    def mobility(self):
        """Mobility xi0 > 0 (default 1)."""
        return self._get(lib.odhs_driver_get_mobility, "Driver.mobility")

    @mobility.setter
    def mobility(self, xi0):
        self._set(lib.odhs_driver_set_mobility, xi0, "Driver.mobility")

    @property
    def shear_rate(self):
        """Simple shear rate gammadot (0: off; with oscillatory shear, the
        peak rate)."""
        return self._get(lib.odhs_driver_get_shear_rate, "Driver.shear_rate")

    @shear_rate.setter
    def shear_rate(self, gammadot):
        self._set(lib.odhs_driver_set_shear_rate, gammadot, "Driver.shear_rate")

    @property
    def compression_rate(self):
        """Isotropic compression rate c (V_aff = -c R; < 0 dilates; 0: off)."""
        return self._get(lib.odhs_driver_get_compression_rate, "Driver.compression_rate")

    @compression_rate.setter
    def compression_rate(self, c):
        self._set(lib.odhs_driver_set_compression_rate, c, "Driver.compression_rate")

    def set_oscillatory_shear(self, amplitude, period, shape=Oscillation.SINE, t0=0.0):
        """Oscillatory shear of strain amplitude and period, shape
        Oscillation.SINE or TRIANGLE (or "sine", "triangle"), phase origin t0
        (odhs_driver_set_oscillatory_shear)."""
        rc = lib.odhs_driver_set_oscillatory_shear(self._p or self._closed(),
                                                   int(to_enum(Oscillation, shape, "oscillation shape")),
                                                   float(amplitude), float(period), float(t0))
        if rc:
            self._err(rc, "Driver.set_oscillatory_shear")

    @property
    def oscillatory_shear(self):
        """The oscillation's settings as OscillatoryShear(shape, amplitude,
        period, t0), or None without one."""
        shape, a, T, t0 = ffi.new("int *"), ffi.new("double *"), ffi.new("double *"), ffi.new("double *")
        rc = lib.odhs_driver_get_oscillatory_shear(self._p or self._closed(), shape, a, T, t0)
        if rc:
            self._err(rc, "Driver.oscillatory_shear")
        if shape[0] == 0:
            return None
        return OscillatoryShear(Oscillation(shape[0]), a[0], T[0], t0[0])

    # --- pressure ----------------------------------------------------------------
    @property
    def pressure(self):
        """Target pressure under pressure control, or None when off
        (odhs_driver_get_pressure). Assign a value > 0 to shear at fixed
        pressure (odhs_driver_set_pressure), None to turn it off
        (odhs_driver_clear_pressure)."""
        p, on = ffi.new("double *"), ffi.new("int *")
        rc = lib.odhs_driver_get_pressure(self._p or self._closed(), p, on)
        if rc:
            self._err(rc, "Driver.pressure")
        return p[0] if on[0] else None

    @pressure.setter
    def pressure(self, p):
        if p is None:
            rc = lib.odhs_driver_clear_pressure(self._p or self._closed())
        else:
            rc = lib.odhs_driver_set_pressure(self._p or self._closed(), float(p))
        if rc:
            self._err(rc, "Driver.pressure")

    def set_kappa_max(self, kappa_max):
        """Bound on |kappa| under pressure control (default 100)."""
        self._set(lib.odhs_driver_set_kappa_max, kappa_max, "Driver.set_kappa_max")

    @property
    def jamming_pressure(self):
        """Jamming pressure p_jam under pressure control (default inf;
        odhs_driver_set_jamming_pressure)."""
        return self._get(lib.odhs_driver_get_jamming_pressure, "Driver.jamming_pressure")

    @jamming_pressure.setter
    def jamming_pressure(self, p_jam):
        self._set(lib.odhs_driver_set_jamming_pressure, p_jam, "Driver.jamming_pressure")

    # --- external forces -----------------------------------------------------------
    def set_forces(self, F):
        """Fixed external forces, (n, dim) (copied in; odhs_driver_set_forces);
        None removes them. Replaces a force callback."""
        p = self._p or self._closed()
        if F is None:
            rc = lib.odhs_driver_set_forces(p, 0, 0, NULL)
        else:
            arr = np.ascontiguousarray(F, dtype=F64)
            if arr.ndim != 2:
                raise ValueError("forces must have shape (n, dim), got %s" % (arr.shape,))
            rc = lib.odhs_driver_set_forces(p, arr.shape[0], arr.shape[1], ffi.from_buffer("double[]", arr))
        if rc:
            self._err(rc, "Driver.set_forces")
        self._force_fn = None
        self._h.keep.pop("force", None)

    def set_force_callback(self, fn):
        """External forces from a Python function ``fn(t, system) -> forces``
        returning n*dim values ((n, dim) array-like), called by the stepper
        whenever it needs forces at a new state (odhs_driver_set_force_callback;
        `system` is a read-only view valid only during the call: read
        system.positions etc.). It must be a pure function of t and the
        positions: it may be called several times per step and at times that
        go back. An exception inside fn makes the step fail (rolled back,
        ODHS_E_CALLBACK) and is re-raised from the run call. None removes
        the callback. Replaces fixed forces."""
        p = self._p or self._closed()
        if fn is None:
            rc = lib.odhs_driver_set_force_callback(p, NULL, NULL)
            if rc:
                self._err(rc, "Driver.set_force_callback")
            self._h.keep.pop("force", None)
            self._force_fn = None
            return
        if not callable(fn):
            raise TypeError("the force callback must be callable")
        ctx = ffi.new_handle(ForceContext(fn))
        rc = lib.odhs_driver_set_force_callback(p, lib._odhs_py_force, ctx)
        if rc:
            self._err(rc, "Driver.set_force_callback")
        self._h.keep["force"] = ctx  # the C driver points to it
        self._force_fn = fn

    @property
    def force_callback(self):
        """The Python force callback in use, or None."""
        return self._force_fn

    # --- time unit -------------------------------------------------------------------
    def set_time_unit(self, tau):
        """A time unit replacing the natural one (tau = 1: dt is physical
        time; odhs_driver_set_time_unit)."""
        self._set(lib.odhs_driver_set_time_unit, tau, "Driver.set_time_unit")

    def clear_time_unit(self):
        """Back to the natural time unit (odhs_driver_clear_time_unit)."""
        rc = lib.odhs_driver_clear_time_unit(self._p or self._closed())
        if rc:
            self._err(rc, "Driver.clear_time_unit")

    def time_unit(self, system):
        """The time unit tau of this driver acting on system
        (odhs_driver_time_unit)."""
        v = ffi.new("double *")
        rc = lib.odhs_driver_time_unit(self._p or self._closed(), system._p or system._closed(), v)
        if rc:
            self._err(rc, "Driver.time_unit")
        return v[0]

    # --- self-propulsion -------------------------------------------------------------
    def set_self_propulsion(self, n, dim, fmin, fmax, tmin, tmax, seed):
        """Self-propulsion of n particles in dim dimensions: magnitudes
        uniform in [fmin, fmax], persistence times uniform in [tmin, tmax]
        tau_p, reproducible from seed (odhs_driver_set_self_propulsion)."""
        if int(n) < 0 or int(seed) < 0:
            raise make_error(lib.ODHS_E_INVALID, "n and seed must be >= 0", "Driver.set_self_propulsion")
        rc = lib.odhs_driver_set_self_propulsion(self._p or self._closed(), int(n), int(dim), float(fmin),
                                                 float(fmax), float(tmin), float(tmax), int(seed))
        if rc:
            self._err(rc, "Driver.set_self_propulsion")
        self._prop_shape = (int(n), int(dim))

    def clear_self_propulsion(self):
        """Turn self-propulsion off."""
        rc = lib.odhs_driver_clear_self_propulsion(self._p or self._closed())
        if rc:
            self._err(rc, "Driver.clear_self_propulsion")
        self._prop_shape = None

    def propulsion(self):
        """Current propulsion forces (n, dim) and next switch times (n,) as a
        Propulsion record (switch_times None before a stepper started the
        clock) (odhs_driver_get_propulsion; StateError when off)."""
        if self._prop_shape is None:
            raise make_error(lib.ODHS_E_STATE, "self-propulsion is off", "Driver.propulsion")
        n, dim = self._prop_shape
        F, pF = out_array((n, dim))
        T, pT = out_array((n,))
        p = self._p or self._closed()
        rc = lib.odhs_driver_get_propulsion(p, pF, pT)
        if rc == lib.ODHS_E_STATE:
            rc = lib.odhs_driver_get_propulsion(p, pF, NULL)
            T = None
        if rc:
            self._err(rc, "Driver.propulsion")
        return Propulsion(F, T)

    def next_switch(self):
        """Earliest switch time of the propulsion forces
        (odhs_driver_next_switch)."""
        return self._get(lib.odhs_driver_next_switch, "Driver.next_switch")

    # --- gravity -----------------------------------------------------------------------
    def set_gravity(self, g):
        """Uniform gravity field g (dim values; odhs_driver_set_gravity);
        None removes it."""
        p = self._p or self._closed()
        if g is None:
            rc = lib.odhs_driver_set_gravity(p, 0, NULL)
        else:
            arr = np.ascontiguousarray(g, dtype=F64).ravel()
            rc = lib.odhs_driver_set_gravity(p, arr.size, ffi.from_buffer("double[]", arr))
        if rc:
            self._err(rc, "Driver.set_gravity")

    def set_gravity_weights(self, w):
        """Per-particle gravity weights (n values; None: the volume weights)
        (odhs_driver_set_gravity_weights)."""
        p = self._p or self._closed()
        if w is None:
            rc = lib.odhs_driver_set_gravity_weights(p, 0, NULL)
        else:
            arr = np.ascontiguousarray(w, dtype=F64).ravel()
            rc = lib.odhs_driver_set_gravity_weights(p, arr.size, ffi.from_buffer("double[]", arr))
        if rc:
            self._err(rc, "Driver.set_gravity_weights")


__all__ = ["Driver"]
