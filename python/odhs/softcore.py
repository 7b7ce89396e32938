"""Soft-core reference models on the same system handle (odhs_softcore):
RD0, CD0, the massive RD, CD, CD_n, CD_t models, quasistatic shear and energy
minimisation (Vagberg's thesis, ch. 4; docs/softcore.md)."""

from ._core import Owned, cstr, ffi, in_array, lib, out_array
from .constants import Minimiser, SoftcoreIntegrator, SoftcoreModel, StressPart, to_enum
from .errors import last_error, make_error
from .records import SoftcoreCounts
from .system import System


class Softcore(Owned):
    """A soft-core handle on `system` (odhs_softcore_create; the system must
    be ready), which it keeps alive. Defaults: RD0, alpha 2, k_e 1, k_d 1,
    k_0 1e-3, m 1, shear rate 0, step factor 0.1. Keyword arguments set
    properties: ``Softcore(sys, model="CD0", shear_rate=1e-3)``.

    Soft-core states overlap: the stepper and the system setters refuse
    them; work on a System.clone() for those."""

    _kind = "softcore handle"

    def __init__(self, system, **settings):
        if not isinstance(system, System):
            raise TypeError("Softcore(system) takes an odhs.System")
        out = ffi.new("odhs_softcore **")
        rc = lib.odhs_softcore_create(system._p or system._closed(), out)
        if rc:
            raise make_error(rc, last_error(), "Softcore")
        self._init_handle(out[0], lib.odhs_softcore_destroy, (system._h,))
        self._system = system
        self._n, self._dim = system.n, system.dim
        self._model = SoftcoreModel.RD0
        self._shear_rate = 0.0
        try:
            for k, v in settings.items():
                if not isinstance(getattr(type(self), k, None), property):
                    raise TypeError("Softcore() got an unexpected keyword argument %r" % k)
                setattr(self, k, v)
        except BaseException:
            self.close()
            raise

    @property
    def system(self):
        """The System this handle works on (kept alive by it)."""
        return self._system

    def _err(self, rc, fn):
        p = self._p
        raise make_error(rc, cstr(lib.odhs_softcore_errmsg(p)) if p is not None else "", fn)

    def _call(self, cfn, name, *args):
        rc = cfn(self._p or self._closed(), *args)
        if rc:
            self._err(rc, name)

    def _scalar(self, cfn, name):
        v = ffi.new("double *")
        self._call(cfn, name, v)
        return v[0]

    @property
    def errmsg(self):
        """The message of the last failed call on this handle ("" if none)."""
        return cstr(lib.odhs_softcore_errmsg(self._p or self._closed()))

    # --- settings ------------------------------------------------------------------
    @property
    def model(self):
        """The model (SoftcoreModel or its name: "RD0", "CD0", "RD", "CD",
        "CDN", "CDT"; odhs_softcore_set_model)."""
        return self._model

    @model.setter
    def model(self, m):
        m = to_enum(SoftcoreModel, m, "model")
        self._call(lib.odhs_softcore_set_model, "Softcore.model", int(m))
        self._model = m

    def set_potential(self, alpha, k_e):
        """Potential exponent alpha (2 harmonic, 2.5 Hertzian) and stiffness
        k_e (odhs_softcore_set_potential)."""
        self._call(lib.odhs_softcore_set_potential, "Softcore.set_potential", float(alpha), float(k_e))

    def set_drag(self, k_d):
        """Drag coefficient k_d (odhs_softcore_set_drag)."""
        self._call(lib.odhs_softcore_set_drag, "Softcore.set_drag", float(k_d))

    def set_substrate(self, k_0):
        """Substrate drag k_0 of CD0 (odhs_softcore_set_substrate)."""
        self._call(lib.odhs_softcore_set_substrate, "Softcore.set_substrate", float(k_0))

    def set_mass(self, m):
        """Particle mass of the massive models (odhs_softcore_set_mass)."""
        self._call(lib.odhs_softcore_set_mass, "Softcore.set_mass", float(m))

    @property
    def shear_rate(self):
        """Shear rate gammadot (odhs_softcore_set_shear_rate)."""
        return self._shear_rate

    @shear_rate.setter
    def shear_rate(self, g):
        self._call(lib.odhs_softcore_set_shear_rate, "Softcore.shear_rate", float(g))
        self._shear_rate = float(g)

    def set_integrator(self, integrator):
        """SoftcoreIntegrator.FIXED or ADAPTIVE ("fixed", "adaptive";
        odhs_softcore_set_integrator)."""
        self._call(lib.odhs_softcore_set_integrator, "Softcore.set_integrator",
                   int(to_enum(SoftcoreIntegrator, integrator, "integrator")))

    def set_dt(self, c):
        """Step size factor c in (0, 10] (odhs_softcore_set_dt)."""
        self._call(lib.odhs_softcore_set_dt, "Softcore.set_dt", float(c))

    def set_tolerance(self, tol):
        """Adaptive integrator tolerance (odhs_softcore_set_tolerance)."""
        self._call(lib.odhs_softcore_set_tolerance, "Softcore.set_tolerance", float(tol))

    def set_minimiser(self, minimiser):
        """Minimiser.SD, FIRE or CG ("sd", "fire", "cg";
        odhs_softcore_set_minimiser)."""
        self._call(lib.odhs_softcore_set_minimiser, "Softcore.set_minimiser",
                   int(to_enum(Minimiser, minimiser, "minimiser")))

    def set_min_tolerance(self, tol, max_iter=100000000):
        """Stop minimising when the largest force is below tol, fail after
        max_iter iterations (odhs_softcore_set_min_tolerance)."""
        if int(max_iter) < 0:
            raise make_error(lib.ODHS_E_INVALID, "max_iter must be > 0", "Softcore.set_min_tolerance")
        self._call(lib.odhs_softcore_set_min_tolerance, "Softcore.set_min_tolerance", float(tol), int(max_iter))

    def set_linear_tolerance(self, tol):
        """Relative residual of the CD0 solve (odhs_softcore_set_linear_tolerance)."""
        self._call(lib.odhs_softcore_set_linear_tolerance, "Softcore.set_linear_tolerance", float(tol))

    # --- state -----------------------------------------------------------------------
    def set_positions(self, x):
        """Overwrite the positions, overlaps allowed (odhs_softcore_set_positions)."""
        arr, p = in_array(x, self._n * self._dim, "positions", (self._n, self._dim))
        self._call(lib.odhs_softcore_set_positions, "Softcore.set_positions", p)

    def scale_box(self, s):
        """Scale box and positions by s, overlaps allowed (odhs_softcore_scale_box)."""
        self._call(lib.odhs_softcore_scale_box, "Softcore.scale_box", float(s))

    def set_velocities(self, u):
        """Set the non-affine velocities (massive models;
        odhs_softcore_set_velocities)."""
        arr, p = in_array(u, self._n * self._dim, "velocities", (self._n, self._dim))
        self._call(lib.odhs_softcore_set_velocities, "Softcore.set_velocities", p)

    def reset(self):
        """Forget cached neighbour lists and forces after the system changed
        through other calls (odhs_softcore_reset)."""
        self._call(lib.odhs_softcore_reset, "Softcore.reset")

    # --- dynamics ------------------------------------------------------------------------
    def step(self):
        """One time step of the current model (odhs_softcore_step)."""
        self._call(lib.odhs_softcore_step, "Softcore.step")

    def run_until_strain(self, gamma):
        """Step until the accumulated strain gamma (odhs_softcore_run_until_strain)."""
        self._call(lib.odhs_softcore_run_until_strain, "Softcore.run_until_strain", float(gamma))

    def run_until_time(self, t):
        """Step until time t (odhs_softcore_run_until_time)."""
        self._call(lib.odhs_softcore_run_until_time, "Softcore.run_until_time", float(t))

    def minimise(self):
        """Minimise the elastic energy at fixed strain; returns the number of
        iterations (odhs_softcore_minimise)."""
        it = ffi.new("uint64_t *")
        self._call(lib.odhs_softcore_minimise, "Softcore.minimise", it)
        return int(it[0])

    def quasistatic_step(self, dgamma):
        """Affine shear by dgamma then minimise; returns the iterations
        (odhs_softcore_quasistatic_step)."""
        it = ffi.new("uint64_t *")
        self._call(lib.odhs_softcore_quasistatic_step, "Softcore.quasistatic_step", float(dgamma), it)
        return int(it[0])

    # --- observables ----------------------------------------------------------------------
    @property
    def time(self):
        """Physical time (odhs_softcore_time)."""
        return self._scalar(lib.odhs_softcore_time, "Softcore.time")

    @property
    def strain(self):
        """Accumulated shear strain (odhs_softcore_strain)."""
        return self._scalar(lib.odhs_softcore_strain, "Softcore.strain")

    @property
    def counts(self):
        """SoftcoreCounts(steps, force_evals, min_iterations)."""
        a, b, c = ffi.new("uint64_t *"), ffi.new("uint64_t *"), ffi.new("uint64_t *")
        self._call(lib.odhs_softcore_counts, "Softcore.counts", a, b, c)
        return SoftcoreCounts(int(a[0]), int(b[0]), int(c[0]))

    @property
    def step_size(self):
        """Current step size in physical time (odhs_softcore_step_size)."""
        return self._scalar(lib.odhs_softcore_step_size, "Softcore.step_size")

    @property
    def energy(self):
        """Elastic energy (odhs_softcore_energy)."""
        return self._scalar(lib.odhs_softcore_energy, "Softcore.energy")

    @property
    def kinetic_energy(self):
        """Kinetic energy of the non-affine velocities
        (odhs_softcore_kinetic_energy)."""
        return self._scalar(lib.odhs_softcore_kinetic_energy, "Softcore.kinetic_energy")

    def forces(self, out=None):
        """Elastic forces (n, dim) (copy; odhs_softcore_forces)."""
        arr, p = out_array((self._n, self._dim), out)
        self._call(lib.odhs_softcore_forces, "Softcore.forces", p)
        return arr

    @property
    def max_force(self):
        """Largest |grad_i U| (odhs_softcore_max_force)."""
        return self._scalar(lib.odhs_softcore_max_force, "Softcore.max_force")

    def velocities(self, out=None):
        """Non-affine velocities (n, dim) (copy; odhs_softcore_velocities)."""
        arr, p = out_array((self._n, self._dim), out)
        self._call(lib.odhs_softcore_velocities, "Softcore.velocities", p)
        return arr

    def stress(self, part=StressPart.TOTAL):
        """Stress tensor (dim, dim) of a StressPart (odhs_softcore_stress)."""
        arr, p = out_array((self._dim, self._dim))
        self._call(lib.odhs_softcore_stress, "Softcore.stress", int(to_enum(StressPart, part, "stress part")), p)
        return arr

    @property
    def pressure(self):
        """Pressure -tr(sigma)/dim (odhs_softcore_pressure)."""
        return self._scalar(lib.odhs_softcore_pressure, "Softcore.pressure")

    @property
    def max_overlap(self):
        """Largest relative overlap (odhs_softcore_max_overlap)."""
        return self._scalar(lib.odhs_softcore_max_overlap, "Softcore.max_overlap")

    def coordination(self, rattler_free=False):
        """Mean number of overlapping neighbours, optionally rattler-free
        (odhs_softcore_coordination)."""
        z = ffi.new("double *")
        self._call(lib.odhs_softcore_coordination, "Softcore.coordination", 1 if rattler_free else 0, z)
        return z[0]

    def relaxation_stress(self):
        """(1/dgamma) integral sigma dt of the last steepest-descent
        relaxation, (dim, dim) (odhs_softcore_relaxation_stress)."""
        arr, p = out_array((self._dim, self._dim))
        self._call(lib.odhs_softcore_relaxation_stress, "Softcore.relaxation_stress", p)
        return arr


__all__ = ["Softcore"]
