/*
 * libodhs - driver.h: what drives the particles.
 *
 * Overdamped dynamics with Stokes drag: F_drag = -xi0^{-1} (V - V_aff), with
 * xi0 the mobility (time/mass). The imposed affine flow is V_aff = G R with
 * velocity gradient
 *     G = gammadot e_x e_y^T  -  c I,       c = compression_rate
 *                                            (or c = kappa*gammadot at fixed p)
 * (simple shear in the x-y plane with Lees-Edwards boundaries, plus isotropic
 * compression for c > 0). The box deforms with the same G, so the flow is
 * continuous across the periodic boundaries. External forces F_ext act on
 * particles (fixed vector or user callback); forces and flow can be combined.
 *
 * Between events the contact forces solve N f = -S (V_aff + xi0 F_ext) / xi0
 * and V = V_aff + xi0 (F_ext + S^T f) (eqs. 11-12 and 18-19 of the paper).
 *
 * Fixed pressure (Sect. II C): with a shear rate set, kappa is recomputed at
 * every force computation so that p = <f|r>/(Omega d) equals the target
 * (eq. 25 with the sign typo of eqs. 21/23 corrected: V_aff = gammadot (R_y x
 * - kappa R), kappa > 0 compresses).
 *
 * Time unit tau (the stepper's step size dt is measured in it). The natural
 * unit, which makes trajectories rate-invariant (Sect. II D):
 * 1/max(|gammadot|, |c|) when a flow is set; otherwise lambda / (xi0 f_rms)
 * for fixed forces, with lambda the mean diameter and f_rms = sqrt(<F|F>/N);
 * otherwise (a force callback, or nothing) lambda / xi0, i.e. unit force.
 * A unit set with odhs_driver_set_time_unit replaces the natural one in every
 * scene (since 0.2.7; before, it was used only where no natural unit
 * existed): set 1 and dt is physical time, the same whatever forces a
 * framework sets from step to step. The force scale is summed without
 * overflow; a unit that is not a positive normal double (forces of 1e-310,
 * or 1e310 with a tiny lambda) is refused with ODHS_E_INVALID. The stepper
 * squares velocities (collision prediction, error estimates), so it also
 * refuses (ODHS_E_INVALID; ODHS_E_CALLBACK for a callback's forces) external
 * forces with xi0 max|F| above 1e150, or nonzero below 1e-150 without a
 * flow, and flow rates with rate times the box edge outside
 * [1e-150, 1e150]: change the units instead (since 0.2.7; 0.2.6 stalled).
 * With self-propulsion and/or gravity the force scale is
 *     f_ext^2 = <F_d|F_d>/N + <|F_p|^2>,
 * F_d the deterministic forces (fixed forces plus gravity), <|F_p|^2> =
 * (fmin^2 + fmin fmax + fmax^2)/3 the mean square propulsion force (its
 * expectation, so tau does not jump when forces are redrawn); with fixed
 * forces alone this is the f_rms above.
 *
 * Self-propulsion (Sect. V B of the paper): particle i carries a propulsion
 * force F_i of magnitude uniform in [fmin, fmax] and direction uniform on the
 * circle (2D) or sphere (3D), held for a persistence time uniform in
 * [tmin, tmax] tau_p, after which a new force and a new persistence time are
 * drawn. tau_p = lambda / (xi0 f_p) with f_p = sqrt(<|F_p|^2>) is the paper's
 * tau = lambda/(f_ext xi0), f_ext = sqrt(<F_ext|F_ext>/N) (the paper prints
 * the /N outside the square root: a typo, f_ext must scale like one force).
 * Random numbers come from xoshiro256** seeded with the given seed and kept in
 * the driver, so a run is reproducible bit for bit. The stepper ends a step
 * exactly at every switch time, so the sequence of forces and switch times
 * does not depend on the step size, the integrator or the dynamics; a switch
 * that makes contact forces negative shows up as openings at the switch time.
 * Drawing order: at setting time, for i = 0..N-1 the force of i (2D: angle,
 * magnitude; 3D: cos(theta), azimuth, magnitude) then its persistence; at a
 * switch time t the particles due, in index order, the same way.
 * The clock starts when a stepper first takes the setting (its reset or next
 * step): switch times are then t0 + persistence * tau_p, t0 the stepper's
 * time; later persistence times use the tau_p (xi0) current when drawn. A driver with self-propulsion follows the clock of one stepper; share
 * it between steppers only if they run in lock step.
 *
 * Gravity: a uniform field g adds F_i = w_i g to every particle, with weight
 * w_i = (a_i / <a>)^d (mass proportional to the volume, <a> the mean radius;
 * a particle of mean size carries g) or weights set by the user.
 *
 * Fixed forces (or the callback), self-propulsion and gravity add up.
 */
#ifndef ODHS_DRIVER_H
#define ODHS_DRIVER_H

#include "odhs/system.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct odhs_driver odhs_driver;

/**
 * External force callback: fill F[0..N*dim-1] with the forces at time t on the
 * configuration sys. Return 0 on success, nonzero to signal failure (the
 * stepper then returns ODHS_E_CALLBACK and rolls the step back).
 */
typedef int (*odhs_force_fn)(double t, const odhs_system *sys, double *F, void *ctx);

/** Create a driver: no flow, no forces, xi0 = 1. */
ODHS_API int odhs_driver_create(odhs_driver **out);
/** Destroy; NULL is a no-op. */
ODHS_API void odhs_driver_destroy(odhs_driver *drv);
/** Last error message ("" if none). */
ODHS_API const char *odhs_driver_errmsg(const odhs_driver *drv);

/** Mobility xi0 > 0 (default 1). */
ODHS_API int odhs_driver_set_mobility(odhs_driver *drv, double xi0);
/** Simple shear rate gammadot (any finite value; 0 turns shear off). */
ODHS_API int odhs_driver_set_shear_rate(odhs_driver *drv, double gammadot);
/** Shapes of odhs_driver_set_oscillatory_shear. */
enum {
    /** gamma(t) = gamma0 sin(2 pi (t - t0) / T): peak rate 2 pi gamma0 / T */
    ODHS_OSCILLATION_SINE = 1,
    /** a constant rate +-4 gamma0 / T reversing every half period, at
     *  t0 + T/4 + k T/2: gamma(t) the triangle wave between -gamma0 and
     *  gamma0 through 0 at t0 (rising) */
    ODHS_OSCILLATION_TRIANGLE = 2
};
/**
 * Oscillatory simple shear of amplitude gamma0 > 0 and period T > 0 (times as
 * the stepper's), shape ODHS_OSCILLATION_*, phase origin t0 (gamma(t0) = 0).
 * Replaces the constant shear rate (odhs_driver_set_shear_rate replaces the
 * oscillation in turn); odhs_driver_get_shear_rate then reports the peak
 * rate, which sets the natural time unit. The stepper ends a step exactly at
 * every reversal of the triangle shape; the accumulated strain
 * (odhs_stepper_strain) is gamma(t) - gamma(t_start) exactly, while the box
 * tilt follows the step chords (drift of the order of the integrator's
 * error). Not with fixed pressure (ODHS_E_UNSUPPORTED at the next step);
 * odhs_stepper_run_until_strain refuses it (the strain is not monotonic).
 * Errors: ODHS_E_NULL, ODHS_E_NONFINITE, ODHS_E_INVALID, ODHS_E_RANGE.
 */
ODHS_API int odhs_driver_set_oscillatory_shear(odhs_driver *drv, int shape, double amplitude, double period,
                                               double t0);
/** The oscillation's settings (shape 0: none; outputs may be NULL). */
ODHS_API int odhs_driver_get_oscillatory_shear(const odhs_driver *drv, int *shape, double *amplitude,
                                               double *period, double *t0);
/** Isotropic compression rate c (V_aff = -c R; c < 0 dilates; 0 = off). */
ODHS_API int odhs_driver_set_compression_rate(odhs_driver *drv, double c);
/**
 * Shear at fixed pressure p > 0 (requires a nonzero shear rate and no
 * compression rate when stepping). kappa is clamped to [-kappa_max,
 * kappa_max] (default 100), which only matters when the contacts cannot carry
 * the pressure (for example when there are none). The flow never stops at a
 * finite p unless p >= the jamming pressure (odhs_driver_set_jamming_pressure).
 */
ODHS_API int odhs_driver_set_pressure(odhs_driver *drv, double p);
/** Turn pressure control off (back to fixed volume). */
ODHS_API int odhs_driver_clear_pressure(odhs_driver *drv);
/** Bound on |kappa| under pressure control (> 0). */
ODHS_API int odhs_driver_set_kappa_max(odhs_driver *drv, double kappa_max);
/**
 * Jamming pressure p_jam (>= 0, +INFINITY allowed; default +INFINITY) under
 * pressure control. An isostatic network (one self-stress f0 on the
 * constrained subset) whose f0 is positive on every contact that can open
 * can still flow at fixed pressure: the volume is one more degree of
 * freedom, so it dilates or compacts with kappa set by the geometry and the
 * forces f = f_reg + alpha f0 carry p. With p < p_jam the stepper lets it
 * flow (the physics of shear at a finite pressure, docs/guide.md section 6);
 * with p >= p_jam it stops there as jammed (ODHS_JAMMED with a certificate),
 * the limit p -> infinity that a jamming protocol (pressure raised without
 * bound, as jam_packing --protocol pressure does) stands for. p_jam = 0 is
 * the rule of libodhs <= 0.2.4: jammed whenever such a network appears.
 * Errors: ODHS_E_NULL, ODHS_E_NONFINITE (NaN), ODHS_E_INVALID (< 0).
 */
ODHS_API int odhs_driver_set_jamming_pressure(odhs_driver *drv, double p_jam);
/** The jamming pressure (see odhs_driver_set_jamming_pressure). */
ODHS_API int odhs_driver_get_jamming_pressure(const odhs_driver *drv, double *p_jam);
/** Fixed external forces F[0..n*dim-1] (copied); F == NULL removes them.
 *  Replaces any force callback. */
ODHS_API int odhs_driver_set_forces(odhs_driver *drv, size_t n, int dim, const double *F);
/** Force callback (fn == NULL removes it). Replaces any fixed forces.
 *  Timing (the callback must be a pure function of t and the positions):
 *  the stepper asks for the forces whenever it needs them at a new state:
 *  at odhs_stepper_reset (the current time), at the end of every step (its
 *  end time and positions, and since 0.2.7 again after the drift correction
 *  moved them, so that the forces belong to the final positions), with the
 *  Heun integrator also at the
 *  predictor (the planned end time t0 + h of the step, on positions
 *  x0 + h V0 that are not on the trajectory), again when a step is repeated
 *  shorter (a collision or an opening inside it) and after a driver change.
 *  So a Heun step calls it at least twice, both at end times of the step
 *  (the forces at its start are those of the previous step's end); it may
 *  be called more than once at the same t, and t may go back (a rejected or
 *  repeated step). A callback is code and is not saved in checkpoints: a
 *  stepper restored from a checkpoint of a run that had one refuses to step
 *  (ODHS_E_STATE) until this function (or odhs_driver_set_forces) is called
 *  on its driver. */
ODHS_API int odhs_driver_set_force_callback(odhs_driver *drv, odhs_force_fn fn, void *ctx);
/** The time unit tau (> 0, finite) for every scene: it replaces the natural
 *  unit above, so the stepper's dt (the Euler step, the Heun scheme's
 *  largest step) is dt * tau in the user's time; tau = 1 makes dt physical.
 *  Since 0.2.7 it is honoured with flows and fixed forces too (0.2.6 and
 *  older used it only for callback-driven runs and ignored it otherwise). */
ODHS_API int odhs_driver_set_time_unit(odhs_driver *drv, double tau);
/** Back to the natural time unit (undo odhs_driver_set_time_unit). Since 0.2.7. */
ODHS_API int odhs_driver_clear_time_unit(odhs_driver *drv);

/**
 * Self-propulsion for n particles in dimension dim (see above): magnitudes
 * uniform in [fmin, fmax] (0 <= fmin <= fmax, fmax > 0; fmin = fmax gives a
 * fixed magnitude), persistence times uniform in [tmin, tmax] in units of
 * tau_p (0 <= tmin <= tmax, tmax > 0), random numbers from seed. Draws the
 * initial forces and persistence times now (they can be read with
 * odhs_driver_get_propulsion before any step); replaces earlier propulsion
 * settings and restarts the clock. Errors: ODHS_E_NULL, ODHS_E_DIM,
 * ODHS_E_EMPTY (n = 0), ODHS_E_NONFINITE, ODHS_E_INVALID, ODHS_E_NOMEM.
 */
ODHS_API int odhs_driver_set_self_propulsion(odhs_driver *drv, size_t n, int dim, double fmin, double fmax,
                                             double tmin, double tmax, uint64_t seed);
/** Turn self-propulsion off (no-op when it is off). */
ODHS_API int odhs_driver_clear_self_propulsion(odhs_driver *drv);
/**
 * Current propulsion forces F[0..n*dim-1] and next switch times
 * tswitch[0..n-1] (absolute, in the stepper's time); either may be NULL.
 * Errors: ODHS_E_NULL (drv, or both outputs NULL), ODHS_E_STATE (propulsion
 * off; or tswitch requested before a stepper started the clock), with the
 * outputs untouched.
 */
ODHS_API int odhs_driver_get_propulsion(const odhs_driver *drv, double *F, double *tswitch);
/**
 * Earliest switch time of the propulsion forces (the stepper ends a step
 * there). Errors: ODHS_E_NULL, ODHS_E_STATE (propulsion off or its clock not
 * started yet).
 */
ODHS_API int odhs_driver_next_switch(const odhs_driver *drv, double *t);
/**
 * Uniform gravity field g[0..dim-1] (copied); g == NULL removes it.
 * F_i = w_i g, w_i = (a_i/<a>)^dim unless weights are set.
 * Errors: ODHS_E_NULL, ODHS_E_DIM, ODHS_E_NONFINITE.
 */
ODHS_API int odhs_driver_set_gravity(odhs_driver *drv, int dim, const double *g);
/**
 * Per-particle gravity weights w[0..n-1] (finite, any sign: a negative weight
 * is a buoyant particle); w == NULL restores the volume weights (a_i/<a>)^d.
 * Errors: ODHS_E_NULL, ODHS_E_EMPTY (n = 0), ODHS_E_NONFINITE, ODHS_E_NOMEM.
 */
ODHS_API int odhs_driver_set_gravity_weights(odhs_driver *drv, size_t n, const double *w);

/** Getters. */
ODHS_API int odhs_driver_get_shear_rate(const odhs_driver *drv, double *gammadot);
ODHS_API int odhs_driver_get_compression_rate(const odhs_driver *drv, double *c);
ODHS_API int odhs_driver_get_mobility(const odhs_driver *drv, double *xi0);
/** Target pressure; *enabled = 0 when pressure control is off. */
ODHS_API int odhs_driver_get_pressure(const odhs_driver *drv, double *p, int *enabled);
/** Natural time unit tau for this driver acting on sys (see above). */
ODHS_API int odhs_driver_time_unit(const odhs_driver *drv, const odhs_system *sys, double *tau);

#ifdef __cplusplus
}
#endif
#endif /* ODHS_DRIVER_H */
