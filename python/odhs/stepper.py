"""The event-driven integrator (odhs_stepper), with its walls (walls.h),
composite particles (composite.h), jamming certificate (jamming.h) and
checkpoints (checkpoint.h).

A Stepper keeps its System, Driver and Solver alive (Python references and
the C handles): closing or dropping them while the stepper lives only closes
the Python objects. Run calls return a Status (OK, STOPPED, JAMMED,
POTENTIALLY_JAMMED, STEP_LIMIT) and raise an odhs.Error subclass on errors;
an exception raised in an event or force callback is re-raised by the call
that ran it. Every array returned is a copy (pass ``out=`` to reuse one)."""

import numpy as np

from ._core import INT, NULL, SIZE_T, Owned, _tls, cstr, enc, ffi, in_array, lib, out_array, take_pending
from ._callbacks import EventContext, reraise
from .constants import EventKind, Feature, Integrator, to_enum
from .driver import Driver
from .errors import last_error, make_error
from .network import Network
from .records import (AdaptiveStats, BatchedStats, Certificate, CorrectionStats, Contacts, Counts, Errors, Event,
                      JamLpReport, RunLimits, Settings, StepInfo)
from .solver import Solver
from .system import System

_STATUS = {}


def _status(rc):
    s = _STATUS.get(rc)
    if s is None:
        from .errors import status_of

        s = _STATUS[rc] = status_of(rc)
    return s


class Stepper(Owned):
    """The event-driven stepper on a system under a driver with a solver
    (odhs_stepper_create; the system must be ready: radii and positions
    set). The stepper keeps all three alive. Keyword arguments set
    properties: ``Stepper(sys, drv, solver, dt=1e-3, integrator="euler")``.

    Raises StateError (system not ready) etc. with odhs_last_error()'s
    message."""

    _kind = "stepper"

    def __init__(self, system, driver, solver, **settings):
        if not isinstance(system, System) or not isinstance(driver, Driver) or not isinstance(solver, Solver):
            raise TypeError("Stepper(system, driver, solver) takes an odhs.System, an odhs.Driver and an "
                            "odhs.Solver")
        out = ffi.new("odhs_stepper **")
        rc = lib.odhs_stepper_create(system._p or system._closed(), driver._p or driver._closed(),
                                     solver._p or solver._closed(), out)
        if rc:
            raise make_error(rc, last_error(), "Stepper")
        self._adopt(out[0], system, driver, solver)
        try:
            for k, v in settings.items():
                if not isinstance(getattr(type(self), k, None), property):
                    raise TypeError("Stepper() got an unexpected keyword argument %r" % k)
                setattr(self, k, v)
        except BaseException:
            self.close()
            raise

    def _adopt(self, ptr, system, driver, solver):
        self._init_handle(ptr, lib.odhs_stepper_destroy, (system._h, driver._h, solver._h))
        self._system = system
        self._driver = driver
        self._solver = solver
        self._event_fn = None
        self._ev = ffi.new("odhs_event *")
        self._info = ffi.new("odhs_step_info *")
        self._n = system._n
        self._dim = system._dim
        self._network = None

    @classmethod
    def _from_ptr(cls, ptr, system, driver, solver):
        obj = cls.__new__(cls)
        obj._adopt(ptr, system, driver, solver)
        return obj

    def _errmsg(self):
        p = self._p
        return cstr(lib.odhs_stepper_errmsg(p)) if p is not None else ""

    def _err(self, rc, fn):
        raise make_error(rc, self._errmsg(), fn)

    def _run_result(self, rc, fn):
        """After a call that can run callbacks: re-raise their exception,
        raise an error, or return the Status."""
        exc = take_pending()
        if exc is not None:
            reraise(exc, fn, rc, self._errmsg())
        if rc < 0:
            self._err(rc, fn)
        return _status(rc)

    def _repr_extra(self):
        return " n=%d dim=%d solver=%r" % (self._n, self._dim, self.solver.name if not self.solver.closed else "?")

    @property
    def system(self):
        """The System this stepper moves (kept alive by the stepper)."""
        return self._system

    @property
    def driver(self):
        """The Driver of this stepper (kept alive by the stepper)."""
        return self._driver

    @property
    def solver(self):
        """The Solver of this stepper (kept alive by the stepper)."""
        return self._solver

    def close(self):
        """Release the C stepper (a Network view from ``network`` that is
        still referenced keeps it alive until it goes); the system, driver
        and solver it kept alive are released with it."""
        self._network = None
        super().close()

    @property
    def errmsg(self):
        """The message of the last failed call on this stepper ("" if none)."""
        return cstr(lib.odhs_stepper_errmsg(self._p or self._closed()))

    # --- settings ------------------------------------------------------------------
    @property
    def settings(self):
        """The integration settings in force (odhs_stepper_get_settings): a
        Settings(integrator, dt, tolerance, correction_interval) record."""
        integ, dt, tol, k = ffi.new("int *"), ffi.new("double *"), ffi.new("double *"), ffi.new("unsigned *")
        rc = lib.odhs_stepper_get_settings(self._p or self._closed(), integ, dt, tol, k)
        if rc:
            self._err(rc, "Stepper.settings")
        return Settings(Integrator(integ[0]), dt[0], tol[0], int(k[0]))

    @property
    def dt(self):
        """Step size in units of tau: the fixed Euler step, the largest Heun
        step (default 1e-3; odhs_stepper_set_dt)."""
        return self.settings.dt

    @dt.setter
    def dt(self, dt):
        rc = lib.odhs_stepper_set_dt(self._p or self._closed(), float(dt))
        if rc:
            self._err(rc, "Stepper.dt")

    @property
    def integrator(self):
        """Integrator.HEUN (default, adaptive) or Integrator.EULER (the
        paper's), Integrator.BATCHED; strings "heun", "euler", "batched" accepted (odhs_stepper_set_integrator)."""
        return self.settings.integrator

    @integrator.setter
    def integrator(self, integ):
        rc = lib.odhs_stepper_set_integrator(self._p or self._closed(), int(to_enum(Integrator, integ, "integrator")))
        if rc:
            self._err(rc, "Stepper.integrator")

    @property
    def tolerance(self):
        """Error tolerance of the adaptive integrators (default 1e-6 for Heun, 1e-3 batched;
        odhs_stepper_set_tolerance)."""
        return self.settings.tolerance

    @tolerance.setter
    def tolerance(self, tol):
        rc = lib.odhs_stepper_set_tolerance(self._p or self._closed(), float(tol))
        if rc:
            self._err(rc, "Stepper.tolerance")

    @property
    def correction_interval(self):
        """Drift correction every k steps (0 disables;
        odhs_stepper_set_correction_interval)."""
        return self.settings.correction_interval

    @correction_interval.setter
    def correction_interval(self, k):
        if int(k) < 0:
            raise make_error(lib.ODHS_E_INVALID, "k = %d must be >= 0" % k, "Stepper.correction_interval")
        rc = lib.odhs_stepper_set_correction_interval(self._p or self._closed(), int(k))
        if rc:
            self._err(rc, "Stepper.correction_interval")

    def set_contact_tolerance(self, tol):
        """Relative gap below which pairs count as initial contacts when the
        stepper starts (default 1e-9; odhs_stepper_set_contact_tolerance)."""
        rc = lib.odhs_stepper_set_contact_tolerance(self._p or self._closed(), float(tol))
        if rc:
            self._err(rc, "Stepper.set_contact_tolerance")

    @property
    def run_limits(self):
        """Guards of the run calls as RunLimits(max_steps, stall_steps)
        (odhs_stepper_get_run_limits); assign a (max_steps, stall_steps) pair
        or use set_run_limits."""
        a, b = ffi.new("uint64_t *"), ffi.new("uint64_t *")
        rc = lib.odhs_stepper_get_run_limits(self._p or self._closed(), a, b)
        if rc:
            self._err(rc, "Stepper.run_limits")
        return RunLimits(int(a[0]), int(b[0]))

    @run_limits.setter
    def run_limits(self, limits):
        self.set_run_limits(*limits)

    def set_run_limits(self, max_steps=0, stall_steps=1000):
        """At most max_steps steps per run call (0: no cap; reaching it
        returns Status.STEP_LIMIT), StalledError after stall_steps steps
        without progress (0 disables) (odhs_stepper_set_run_limits)."""
        if int(max_steps) < 0 or int(stall_steps) < 0:
            raise make_error(lib.ODHS_E_INVALID, "limits must be >= 0", "Stepper.set_run_limits")
        rc = lib.odhs_stepper_set_run_limits(self._p or self._closed(), int(max_steps), int(stall_steps))
        if rc:
            self._err(rc, "Stepper.set_run_limits")

    # --- events ----------------------------------------------------------------------
    def set_event_callback(self, fn):
        """Call fn(event) at every event (an Event record; odhs_stepper_set_
        event_callback). fn returning a true value stops the run after the
        current step (the run call returns Status.STOPPED); an exception in
        fn stops it the same way and is re-raised by the run call (the step
        itself is complete). None removes the callback."""
        p = self._p or self._closed()
        if fn is None:
            rc = lib.odhs_stepper_set_event_callback(p, NULL, NULL)
            if rc:
                self._err(rc, "Stepper.set_event_callback")
            self._h.keep.pop("event", None)
            self._event_fn = None
            return
        if not callable(fn):
            raise TypeError("the event callback must be callable")
        ctx = ffi.new_handle(EventContext(fn))
        rc = lib.odhs_stepper_set_event_callback(p, lib._odhs_py_event, ctx)
        if rc:
            self._err(rc, "Stepper.set_event_callback")
        self._h.keep["event"] = ctx
        self._event_fn = fn

    @property
    def event_callback(self):
        """The Python event callback in use, or None."""
        return self._event_fn

    # --- stepping ----------------------------------------------------------------------
    def reset(self):
        """(Re)build the contact network from the system and compute forces
        and velocities (odhs_stepper_reset). Needed after changing the system
        through its setters; the first step does it by itself."""
        return self._run_result(lib.odhs_stepper_reset(self._p or self._closed()), "Stepper.reset")

    def correct(self):
        """Remove the contact-distance drift now (odhs_stepper_correct)."""
        return self._run_result(lib.odhs_stepper_correct(self._p or self._closed()), "Stepper.correct")

    def step(self):
        """Take one step (odhs_stepper_step). Returns (status, event): the
        Status and the step's first Event, or None when there was none."""
        ev = self._ev
        rc = lib.odhs_stepper_step(self._p or self._closed(), ev)
        if rc or getattr(_tls, "pending", None) is not None:
            st = self._run_result(rc, "Stepper.step")
        else:
            st = _OK
        kind = ev.kind
        if kind == 0:
            return st, None
        return st, Event(_KINDS.get(kind, kind), ev.i, ev.j, ev.time, ev.strain)

    def step_ex(self):
        """Take one step and describe it (odhs_stepper_step_ex): returns
        (status, StepInfo)."""
        info = self._info
        info.size = ffi.sizeof("odhs_step_info")
        rc = lib.odhs_stepper_step_ex(self._p or self._closed(), info)
        st = self._run_result(rc, "Stepper.step_ex")
        return st, StepInfo(EventKind(info.kind), info.i, info.j, info.event_time, info.event_strain,
                            int(info.collisions), int(info.openings), info.time_start, info.time_end,
                            info.strain_start, info.strain_end, bool(info.advanced), bool(info.driver_change))

    def run_until_time(self, t):
        """Step until physical time t (odhs_stepper_run_until_time)."""
        return self._run_result(lib.odhs_stepper_run_until_time(self._p or self._closed(), float(t)),
                                "Stepper.run_until_time")

    def run_until_strain(self, gamma):
        """Step until the accumulated strain gamma
        (odhs_stepper_run_until_strain)."""
        return self._run_result(lib.odhs_stepper_run_until_strain(self._p or self._closed(), float(gamma)),
                                "Stepper.run_until_strain")

    def run_events(self, count):
        """Step until count more events happened (odhs_stepper_run_events)."""
        if int(count) < 0:
            raise make_error(lib.ODHS_E_INVALID, "count = %d must be >= 0" % count, "Stepper.run_events")
        return self._run_result(lib.odhs_stepper_run_events(self._p or self._closed(), int(count)),
                                "Stepper.run_events")

    def run_until_packing_fraction(self, phi):
        """Step until the packing fraction phi (compression or pressure
        driving; odhs_stepper_run_until_packing_fraction)."""
        return self._run_result(lib.odhs_stepper_run_until_packing_fraction(self._p or self._closed(), float(phi)),
                                "Stepper.run_until_packing_fraction")

    # --- scalar observables --------------------------------------------------------------
    def _scalar(self, cfn, name):
        v = ffi.new("double *")
        rc = cfn(self._p or self._closed(), v)
        if rc:
            self._err(rc, name)
        return v[0]

    @property
    def time(self):
        """Physical time (odhs_stepper_time)."""
        return self._scalar(lib.odhs_stepper_time, "Stepper.time")

    @property
    def strain(self):
        """Accumulated shear strain (odhs_stepper_strain)."""
        return self._scalar(lib.odhs_stepper_strain, "Stepper.strain")

    @property
    def shear_stress(self):
        """Shear stress sigma_xy (odhs_stepper_shear_stress; StateError
        before the first reset or step)."""
        return self._scalar(lib.odhs_stepper_shear_stress, "Stepper.shear_stress")

    @property
    def pressure(self):
        """Pressure p = <f|r>/(Omega d) (odhs_stepper_pressure)."""
        return self._scalar(lib.odhs_stepper_pressure, "Stepper.pressure")

    @property
    def kappa(self):
        """Compression-to-shear rate ratio kappa (odhs_stepper_kappa)."""
        return self._scalar(lib.odhs_stepper_kappa, "Stepper.kappa")

    @property
    def dissipation(self):
        """Dissipation rate (odhs_stepper_dissipation)."""
        return self._scalar(lib.odhs_stepper_dissipation, "Stepper.dissipation")

    @property
    def power(self):
        """Power injected (odhs_stepper_power)."""
        return self._scalar(lib.odhs_stepper_power, "Stepper.power")

    @property
    def coordination(self):
        """Mean coordination z = 2 Nc / N (odhs_stepper_coordination)."""
        return self._scalar(lib.odhs_stepper_coordination, "Stepper.coordination")

    @property
    def counts(self):
        """Counts(steps, collisions, openings) (odhs_stepper_counts)."""
        a, b, c = ffi.new("uint64_t *"), ffi.new("uint64_t *"), ffi.new("uint64_t *")
        rc = lib.odhs_stepper_counts(self._p or self._closed(), a, b, c)
        if rc:
            self._err(rc, "Stepper.counts")
        return Counts(int(a[0]), int(b[0]), int(c[0]))

    @property
    def adaptive_stats(self):
        """AdaptiveStats(rejected, h) (odhs_stepper_adaptive_stats)."""
        r, h = ffi.new("uint64_t *"), ffi.new("double *")
        rc = lib.odhs_stepper_adaptive_stats(self._p or self._closed(), r, h)
        if rc:
            self._err(rc, "Stepper.adaptive_stats")
        return AdaptiveStats(int(r[0]), h[0])

    @property
    def batched_stats(self):
        """BatchedStats(batched_steps, exact_steps, solves) of the batched
        integrator (odhs_stepper_batched_stats)."""
        a, b, c = ffi.new("uint64_t *"), ffi.new("uint64_t *"), ffi.new("uint64_t *")
        rc = lib.odhs_stepper_batched_stats(self._p or self._closed(), a, b, c)
        if rc:
            self._err(rc, "Stepper.batched_stats")
        return BatchedStats(int(a[0]), int(b[0]), int(c[0]))

    @property
    def correction_stats(self):
        """CorrectionStats(corrections, passes, closed) of the drift
        correction (odhs_stepper_correction_stats; since 0.2.15)."""
        a, b, c = ffi.new("uint64_t *"), ffi.new("uint64_t *"), ffi.new("uint64_t *")
        rc = lib.odhs_stepper_correction_stats(self._p or self._closed(), a, b, c)
        if rc:
            self._err(rc, "Stepper.correction_stats")
        return CorrectionStats(int(a[0]), int(b[0]), int(c[0]))

    @property
    def rewire_count(self):
        """Rewirings finished by the anti-cycling method
        (odhs_stepper_rewire_stats)."""
        c = ffi.new("uint64_t *")
        rc = lib.odhs_stepper_rewire_stats(self._p or self._closed(), c)
        if rc:
            self._err(rc, "Stepper.rewire_count")
        return int(c[0])

    def feature_work(self, feature):
        """How often the code of an optional feature ran (Feature.PRESSURE,
        COMPOSITE, WALLS; odhs_stepper_feature_work)."""
        c = ffi.new("uint64_t *")
        rc = lib.odhs_stepper_feature_work(self._p or self._closed(), int(to_enum(Feature, feature, "feature")), c)
        if rc:
            self._err(rc, "Stepper.feature_work")
        return int(c[0])

    @property
    def errors(self):
        """Errors(contact_gap, overlap): the largest relative contact gap and
        overlap (odhs_stepper_errors)."""
        g, o = ffi.new("double *"), ffi.new("double *")
        rc = lib.odhs_stepper_errors(self._p or self._closed(), g, o)
        if rc:
            self._err(rc, "Stepper.errors")
        return Errors(g[0], o[0])

    # --- array observables ---------------------------------------------------------------
    def set_pre_event_stress(self, on=True):
        """Record the stress just before each step's events (one more force
        solve per step; odhs_stepper_set_pre_event_stress)."""
        rc = lib.odhs_stepper_set_pre_event_stress(self._p or self._closed(), 1 if on else 0)
        if rc:
            self._err(rc, "Stepper.set_pre_event_stress")

    def pre_event_stress(self):
        """The stress tensor (dim, dim) at the end of the last step's motion
        on the network of its start (odhs_stepper_pre_event_stress;
        StateError, with the reason, when there is no record)."""
        arr, p = out_array((self._dim, self._dim))
        rc = lib.odhs_stepper_pre_event_stress(self._p or self._closed(), p)
        if rc:
            self._err(rc, "Stepper.pre_event_stress")
        return arr

    @property
    def stress(self):
        """Stress tensor (dim, dim) (copy; odhs_stepper_stress)."""
        arr, p = out_array((self._dim, self._dim))
        rc = lib.odhs_stepper_stress(self._p or self._closed(), p)
        if rc:
            self._err(rc, "Stepper.stress")
        return arr

    def _nd(self, cfn, name, out):
        arr, p = out_array((self._n, self._dim), out)
        rc = cfn(self._p or self._closed(), p)
        if rc:
            self._err(rc, name)
        return arr

    def velocities(self, out=None):
        """Velocities V (n, dim), lab frame (copy, into out when given;
        odhs_stepper_velocities)."""
        return self._nd(lib.odhs_stepper_velocities, "Stepper.velocities", out)

    def nonaffine_velocities(self, out=None):
        """Non-affine velocities V - V_aff (n, dim) (copy;
        odhs_stepper_nonaffine_velocities)."""
        return self._nd(lib.odhs_stepper_nonaffine_velocities, "Stepper.nonaffine_velocities", out)

    def external_forces(self, out=None):
        """External force on each particle (n, dim): fixed forces, callback,
        gravity and self-propulsion summed (copy;
        odhs_stepper_external_forces)."""
        return self._nd(lib.odhs_stepper_external_forces, "Stepper.external_forces", out)

    def contact_forces(self):
        """The contact force on every particle, S^T f (n, dim), computed from
        the network (Network.apply_ST)."""
        return self.network.apply_ST(self.network.forces)

    def contacts(self):
        """The current contacts in one call (odhs_stepper_contacts): a
        Contacts record of arrays i, j (uintp), kind (intc), force, gap
        (float64), each of Nc entries, filled by the library directly (one
        copy). StateError before the first reset or step."""
        p = self._p or self._closed()
        nc = ffi.new("size_t *")
        rc = lib.odhs_stepper_contacts(p, 0, nc, NULL, NULL, NULL, NULL, NULL)
        if rc and rc != lib.ODHS_E_RANGE:
            self._err(rc, "Stepper.contacts")
        n = int(nc[0])
        i, pi = out_array((n,), dtype=SIZE_T)
        j, pj = out_array((n,), dtype=SIZE_T)
        k, pk = out_array((n,), dtype=INT)
        f, pf = out_array((n,))
        g, pg = out_array((n,))
        rc = lib.odhs_stepper_contacts(p, n, nc, pi, pj, pk, pf, pg)
        if rc:
            self._err(rc, "Stepper.contacts")
        return Contacts(i, j, k, f, g)

    @property
    def network(self):
        """The current contact network, a read-only Network view (it keeps
        this stepper alive; odhs_stepper_network)."""
        if self._network is None or self._network.closed:
            p = self._p or self._closed()
            self._network = Network._borrow(lib.odhs_stepper_network(p), deps=(self._h,))
        return self._network

    # --- composite particles ------------------------------------------------------------
    def add_bond(self, i, j, rest=0.0):
        """Bond particles i and j at centre distance rest (0: their current
        distance) (odhs_stepper_add_bond)."""
        if int(i) < 0 or int(j) < 0:
            raise make_error(lib.ODHS_E_RANGE, "negative index", "Stepper.add_bond")
        rc = lib.odhs_stepper_add_bond(self._p or self._closed(), int(i), int(j), float(rest))
        if rc:
            self._err(rc, "Stepper.add_bond")

    def _beads(self, beads, fn):
        arr = np.ascontiguousarray(beads, dtype=np.int64).ravel()
        if (arr < 0).any():
            raise make_error(lib.ODHS_E_RANGE, "negative bead index", fn)
        arr = arr.astype(np.uintp)
        return arr, ffi.from_buffer("size_t[]", arr)

    def add_chain(self, beads):
        """A floppy chain of bonds between consecutive beads
        (odhs_stepper_add_chain)."""
        arr, p = self._beads(beads, "Stepper.add_chain")
        rc = lib.odhs_stepper_add_chain(self._p or self._closed(), arr.size, p)
        if rc:
            self._err(rc, "Stepper.add_chain")

    def add_rigid_body(self, beads):
        """A rigid body of the beads at their current relative positions
        (odhs_stepper_add_rigid_body)."""
        arr, p = self._beads(beads, "Stepper.add_rigid_body")
        rc = lib.odhs_stepper_add_rigid_body(self._p or self._closed(), arr.size, p)
        if rc:
            self._err(rc, "Stepper.add_rigid_body")

    @property
    def bond_count(self):
        """Number of permanent contacts (odhs_stepper_bond_count)."""
        c = ffi.new("size_t *")
        rc = lib.odhs_stepper_bond_count(self._p or self._closed(), c)
        if rc:
            self._err(rc, "Stepper.bond_count")
        return int(c[0])

    # --- walls -----------------------------------------------------------------------------
    def _vec(self, v, what):
        return in_array(v, self._dim, what)

    def add_wall_plane(self, normal, offset):
        """A plane wall: particles live where normal.x >= offset + a_i.
        Returns the wall's index (odhs_stepper_add_wall_plane)."""
        arr, p = self._vec(normal, "normal")
        wid = ffi.new("size_t *")
        rc = lib.odhs_stepper_add_wall_plane(self._p or self._closed(), p, float(offset), wid)
        if rc:
            self._err(rc, "Stepper.add_wall_plane")
        return int(wid[0])

    def add_wall_sphere(self, centre, radius):
        """A spherical (2D: circular) container; returns its index
        (odhs_stepper_add_wall_sphere)."""
        arr, p = self._vec(centre, "centre")
        wid = ffi.new("size_t *")
        rc = lib.odhs_stepper_add_wall_sphere(self._p or self._closed(), p, float(radius), wid)
        if rc:
            self._err(rc, "Stepper.add_wall_sphere")
        return int(wid[0])

    def add_wall_segment(self, a, b):
        """A segment wall from a to b (2D only); returns its index
        (odhs_stepper_add_wall_segment)."""
        pa_arr, pa = self._vec(a, "a")
        pb_arr, pb = self._vec(b, "b")
        wid = ffi.new("size_t *")
        rc = lib.odhs_stepper_add_wall_segment(self._p or self._closed(), pa, pb, wid)
        if rc:
            self._err(rc, "Stepper.add_wall_segment")
        return int(wid[0])

    def set_wall_velocity(self, wall, v):
        """Translate wall `wall` at velocity v (odhs_stepper_set_wall_velocity)."""
        arr, p = self._vec(v, "velocity")
        if int(wall) < 0:
            raise make_error(lib.ODHS_E_RANGE, "wall index %d < 0" % wall, "Stepper.set_wall_velocity")
        rc = lib.odhs_stepper_set_wall_velocity(self._p or self._closed(), int(wall), p)
        if rc:
            self._err(rc, "Stepper.set_wall_velocity")

    @property
    def wall_count(self):
        """Number of walls (odhs_stepper_wall_count)."""
        c = ffi.new("size_t *")
        rc = lib.odhs_stepper_wall_count(self._p or self._closed(), c)
        if rc:
            self._err(rc, "Stepper.wall_count")
        return int(c[0])

    def _wall_vec(self, cfn, wall, name):
        if int(wall) < 0:
            raise make_error(lib.ODHS_E_RANGE, "wall index %d < 0" % wall, name)
        arr, p = out_array((self._dim,))
        rc = cfn(self._p or self._closed(), int(wall), p)
        if rc:
            self._err(rc, name)
        return arr

    def wall_force(self, wall):
        """Force the particles exert on the wall, (dim,)
        (odhs_stepper_wall_force)."""
        return self._wall_vec(lib.odhs_stepper_wall_force, wall, "Stepper.wall_force")

    def wall_displacement(self, wall):
        """Displacement of the wall since it was added, (dim,)
        (odhs_stepper_wall_displacement)."""
        return self._wall_vec(lib.odhs_stepper_wall_displacement, wall, "Stepper.wall_displacement")

    # --- jamming ---------------------------------------------------------------------------
    def certificate(self):
        """The jamming certificate of the current state
        (odhs_stepper_certificate): a Certificate record."""
        c = ffi.new("odhs_jam_certificate *")
        c.size = ffi.sizeof("odhs_jam_certificate")
        rc = lib.odhs_stepper_certificate(self._p or self._closed(), c)
        if rc:
            self._err(rc, "Stepper.certificate")
        return Certificate(bool(c.jammed), bool(c.isostatic), c.phi, c.pressure, int(c.n_particles),
                           int(c.n_rattlers), int(c.n_backbone), int(c.n_contacts), int(c.n_contacts_backbone),
                           int(c.n_contacts_isostatic), c.z, c.z_backbone, c.force_balance, c.gap_error, c.overlap,
                           c.min_force, int(c.n_pivots))

    def jam_lp(self, trust=0.0, tol=0.0, max_lps=0, max_steps=0, quench=False, quench_phi=0.0,
               own_integrator=False):
        """The fast route to a certified jammed packing (odhs_stepper_jam_lp, since 0.2.9): a
        chain of linear programmes compresses the system to jamming, then the stepper's exact
        end game certifies it. The driver must compress and do nothing else. Options left 0
        take the library's defaults (trust region 0.1 mean diameters, tol 1e-12). quench=True
        (since 0.2.10) starts the chain from a soft-sphere quench to quench_phi (default 0.86
        in 2D, 0.66 in 3D), brought toward phi_J by rescalings of its mean overlap (since
        0.2.11) and dilated until no pair overlaps: the fastest route, a quench protocol.
        Where the chain leaves the packing unjammed, the end game steps with the batched-event
        integrator (since 0.2.22; the stepper's settings are put back after the call);
        own_integrator=True steps with the stepper's own integrator instead, as up to 0.2.21.
        Returns (status, JamLpReport); status is Status.JAMMED when the packing is made."""
        o = ffi.new("odhs_jam_lp_options *")
        o.size = ffi.sizeof("odhs_jam_lp_options")
        o.trust = float(trust)
        o.tol = float(tol)
        o.max_lps = int(max_lps)
        o.quench = 1 if quench else 0
        o.quench_phi = float(quench_phi)
        o.max_steps = int(max_steps)
        o.own_integrator = 1 if own_integrator else 0
        r = ffi.new("odhs_jam_lp_report *")
        r.size = ffi.sizeof("odhs_jam_lp_report")
        rc = lib.odhs_stepper_jam_lp(self._p or self._closed(), o, r)
        st = self._run_result(rc, "Stepper.jam_lp")
        return st, JamLpReport(int(r.n_lps), int(r.simplex_iterations), int(r.rows_max), r.phi_lp, r.growth_last,
                               int(r.end_steps), int(r.shakes), int(r.polishes), int(r.quench_iterations),
                               r.phi_start, int(r.quench_steps))

    # --- files -------------------------------------------------------------------------------
    def write_checkpoint(self, path):
        """Save the whole simulation (system, driver, stepper) to path,
        atomically (odhs_checkpoint_write). Callbacks and the solver are not
        saved: see odhs.read_checkpoint."""
        rc = lib.odhs_checkpoint_write(self._p or self._closed(), enc(path, "path"))
        if rc:
            self._err(rc, "Stepper.write_checkpoint")

    def write_svg(self, path, mark="rattlers"):
        """Draw the system with the current contact forces (odhs_svg_write);
        mark "rattlers" (default) rings the rattlers, None marks nothing, an
        array of n values marks as System.write_svg."""
        net = self.network
        if isinstance(mark, str):
            if mark != "rattlers":
                raise ValueError("mark must be 'rattlers', None or an array")
            mark = net.rattlers().astype(np.uint8)
        self.system.write_svg(path, net, mark)

    def write_contacts_csv(self, path):
        """Write the contacts as CSV i,j,kind,force,gap
        (odhs_contacts_write_csv)."""
        self.network.write_contacts_csv(path, self.system)

    def write_contacts(self, path):
        """Write the contacts as text with lattice images (odhs_contacts_write)."""
        self.network.write_contacts(path, self.system)


_OK = _status(0)
_KINDS = {int(k): k for k in EventKind}


def read_checkpoint(path, solver):
    """Restore a checkpoint (odhs_checkpoint_read): a new Stepper whose
    ``system`` and ``driver`` are new objects, with the given solver.
    Callbacks are not saved: set them again (a stepper whose run had a force
    callback refuses to step, StateError, until
    ``stepper.driver.set_force_callback`` or ``set_forces`` is called).
    Raises FormatError, FileError, ... with the reader's message."""
    return _restore(lambda s, d, st, err: lib.odhs_checkpoint_read(enc(path, "path"), solver._p or solver._closed(),
                                                                   s, d, st, err, len(err)),
                    solver, "read_checkpoint")


def parse_checkpoint(data, solver):
    """As read_checkpoint, from bytes (odhs_checkpoint_parse)."""
    buf = bytes(data)
    return _restore(lambda s, d, st, err: lib.odhs_checkpoint_parse(buf, len(buf), solver._p or solver._closed(),
                                                                    s, d, st, err, len(err)),
                    solver, "parse_checkpoint")


def _restore(call, solver, name):
    if not isinstance(solver, Solver):
        raise TypeError("%s needs an odhs.Solver" % name)
    s, d, st = ffi.new("odhs_system **"), ffi.new("odhs_driver **"), ffi.new("odhs_stepper **")
    err = ffi.new("char[]", 1024)
    rc = call(s, d, st, err)
    if rc:
        raise make_error(rc, ffi.string(err).decode(errors="replace"), name)
    system = System._from_ptr(s[0])
    prop = (system.n, system.dim)
    driver = Driver._from_ptr(d[0], prop_shape=prop)
    if lib.odhs_driver_get_propulsion(d[0], ffi.new("double[]", system.n * system.dim), NULL) != lib.ODHS_OK:
        driver._prop_shape = None
    return Stepper._from_ptr(st[0], system, driver, solver)


__all__ = ["Stepper", "read_checkpoint", "parse_checkpoint"]
