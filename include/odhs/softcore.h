/*
 * libodhs - softcore.h: soft-core reference models (Vagberg's thesis, ch. 4)
 * on the same system handle as the event-driven core.
 *
 * Pair potential (thesis eq. 4.7), for every pair closer than the contact
 * distance d_ij = r_i + r_j (radii of the system):
 *     V(r) = (k_e/alpha) (1 - r/d_ij)^alpha,   alpha = 2 (harmonic),
 *                                               5/2 (Hertzian), any alpha > 1,
 * with the repulsive pair force f = (k_e/d_ij) (1 - r/d_ij)^(alpha-1).
 *
 * Frames and units. Positions are the system's lab-frame positions (updated
 * in place, in the user's particle order) in the Lees-Edwards box; shear
 * flow is simple shear in the x-y plane with affine velocity
 * V_aff = gammadot y xhat measured from the box origin, exactly as in
 * driver.h. u denotes the non-affine ("peculiar") velocity v - V_aff, which
 * is continuous across the Lees-Edwards boundaries. Time is physical time in
 * the units of the parameters: with drag coefficient k_d (force per
 * velocity), stiffness k_e (energy) and lengths of the system, the elastic
 * relaxation time is tau_e = k_d d_min^2 / k_e (d_min = twice the smallest
 * radius); for massive models also tau_m = sqrt(m d_min^2 / k_e) and the
 * damping time m / k_d. Step sizes are set as fractions of these (see
 * odhs_softcore_set_dt). The event-driven core with mobility xi0 (driver.h)
 * corresponds to k_d = 1/xi0; RD0 approaches it as gammadot tau_e -> 0.
 *
 * Models (all with the same potential):
 *  - RD0 (eqs. 4.21-4.22): overdamped, drag against the affine flow:
 *        k_d u_i = F_i^el.
 *  - CD0 (eqs. 4.11-4.19): overdamped, drag on the relative velocities of
 *    overlapping pairs plus a substrate drag k_0 against the affine flow:
 *        F_i^el + k_d sum_j (v_j - v_i) - k_0 u_i = 0,
 *    with v_j - v_i = u_j - u_i + gammadot [y_j - y_i] xhat (minimum image);
 *    one sparse symmetric positive definite solve per force evaluation
 *    (k_d Laplacian of the overlap graph + k_0 I, one system per Cartesian
 *    component). NOTE: the thesis writes the k_0 term against the lab
 *    velocity (eq. 4.16); here it acts against the affine flow so that the
 *    model is Lees-Edwards invariant and reduces to RD0 with drag k_0 when
 *    k_d -> 0. The solve is a Jacobi-preconditioned conjugate gradient on the
 *    matrix-free operator (the library's solver backends only handle the
 *    contact operator N = S S^T, see solver.h), warm-started from the last
 *    velocities.
 *  - RD, CD, CD_n, CD_t (sect. 4.6): particles of mass m integrated with the
 *    SLLOD equations (eq. 4.25) in the lab frame,
 *        dr/dt = u + gammadot y xhat,   m du/dt = F^el + F^dis - m gammadot u_y xhat,
 *    with F^dis = -k_d u (RD), -k_d sum_j (v_i - v_j) (CD), its normal part
 *    along the pair direction (CD_n) or its tangential part (CD_t), by a
 *    velocity-Verlet scheme (exact velocity Verlet without shear and
 *    dissipation; the dissipative force of the second half kick uses the half
 *    step velocities).
 *  - Quasistatic shear (sect. 4.7): odhs_softcore_quasistatic_step applies an
 *    affine strain step and minimises the energy at fixed strain with the
 *    chosen minimiser: steepest descent (the gradient flow k_d dx/dt = F^el
 *    integrated by explicit Euler, the route of the paper's Fig. 6), FIRE, or
 *    Polak-Ribiere conjugate gradient. FIRE is inertial and CG follows search
 *    directions, so below jamming (where the zero-energy states form a
 *    manifold) they end at other points of that manifold than the gradient
 *    flow: only steepest descent follows the overdamped (hard-sphere limit)
 *    trajectory. docs/softcore.md measures the difference.
 *
 * Stress tensor (same convention as the event-driven core, stepper.h):
 * sigma_ab = -(1/Omega) [ sum_pairs F_a r_b + sum_i m u_a u_b ], with r the
 * minimum-image separation R_j - R_i and F the force exerted by i on j; for
 * central repulsive forces it equals -(1/Omega) sum f r n_a n_b, and sigma_xy
 * is positive under positive shear and is the component conjugate to the
 * shear rate (work rate gammadot Omega sigma_xy). Pressure p = -tr(sigma)/d.
 *
 * The handle borrows the system (it must outlive the handle). Soft-core
 * states overlap: other library calls that check overlaps (system setters,
 * the stepper) refuse such states; run those on a clone taken before. After
 * changing the system through other calls, call odhs_softcore_reset.
 *
 * Every call returns ODHS_OK or an error of common.h; an error leaves the
 * handle and the system as they were (a failed step or minimisation is
 * rolled back).
 */
#ifndef ODHS_SOFTCORE_H
#define ODHS_SOFTCORE_H

#include "odhs/system.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct odhs_softcore odhs_softcore;

/** Models (pinned values). */
enum {
    ODHS_SOFTCORE_RD0 = 0, /* overdamped, reservoir (Stokes) drag          */
    ODHS_SOFTCORE_CD0 = 1, /* overdamped, contact drag + substrate k_0     */
    ODHS_SOFTCORE_RD = 2,  /* massive, reservoir drag                      */
    ODHS_SOFTCORE_CD = 3,  /* massive, contact drag on relative velocities */
    ODHS_SOFTCORE_CDN = 4, /* massive, contact drag on the normal part     */
    ODHS_SOFTCORE_CDT = 5  /* massive, contact drag on the tangential part */
};

/** Integrators of the overdamped models (pinned values). */
enum {
    ODHS_SOFTCORE_FIXED = 0,   /* explicit Euler, fixed step (default)      */
    ODHS_SOFTCORE_ADAPTIVE = 1 /* Heun with embedded Euler error estimate:
                                  the step keeps the estimated position
                                  error per step below tol times the mean
                                  diameter; at most tau_e                   */
};

/** Energy minimisers (pinned values). */
enum {
    ODHS_SOFTCORE_SD = 0,   /* steepest descent = gradient flow (default)  */
    ODHS_SOFTCORE_FIRE = 1, /* FIRE (Bitzek et al. 2006)                   */
    ODHS_SOFTCORE_CG = 2    /* Polak-Ribiere nonlinear conjugate gradient  */
};

/** Parts of the stress tensor (pinned values). */
enum {
    ODHS_SOFTCORE_STRESS_TOTAL = 0,
    ODHS_SOFTCORE_STRESS_ELASTIC = 1,
    ODHS_SOFTCORE_STRESS_DISSIPATIVE = 2, /* contact drag (CD0, CD, CD_n, CD_t) */
    ODHS_SOFTCORE_STRESS_KINETIC = 3      /* massive models                     */
};

/**
 * Create a soft-core handle on sys (borrowed; must be ready: radii and
 * positions set). Defaults: RD0, alpha 2, k_e 1, k_d 1, k_0 1e-3, m 1,
 * shear rate 0, fixed step 0.1, tolerance 1e-6, steepest descent to a largest
 * force of 1e-9 (at most 10^8 iterations), CD0 solve tolerance 1e-12.
 * Velocities start at zero. Errors: ODHS_E_NULL, ODHS_E_STATE (system not
 * ready), ODHS_E_NOMEM.
 */
ODHS_API int odhs_softcore_create(odhs_system *sys, odhs_softcore **out);
/** Destroy; NULL is a no-op. The system keeps its current positions. */
ODHS_API void odhs_softcore_destroy(odhs_softcore *sc);
/** Last error message ("" if none; never NULL). */
ODHS_API const char *odhs_softcore_errmsg(const odhs_softcore *sc);

/** Choose the model (ODHS_SOFTCORE_RD0 ... ODHS_SOFTCORE_CDT). Velocities
 *  are kept. ODHS_E_INVALID for an unknown model. */
ODHS_API int odhs_softcore_set_model(odhs_softcore *sc, int model);
/** Potential exponent alpha (> 1, at most 10) and stiffness k_e (> 0). */
ODHS_API int odhs_softcore_set_potential(odhs_softcore *sc, double alpha, double k_e);
/** Drag coefficient k_d (>= 0): reservoir drag (RD0, RD) or pair drag
 *  (CD*). 0 is allowed (e.g. dissipation-free SLLOD, or CD0 with only the
 *  substrate drag); RD0 steps and steepest descent then fail with
 *  ODHS_E_UNSUPPORTED. */
ODHS_API int odhs_softcore_set_drag(odhs_softcore *sc, double k_d);
/** Substrate drag k_0 (>= 0) of CD0 (must be > 0 when CD0 steps). */
ODHS_API int odhs_softcore_set_substrate(odhs_softcore *sc, double k_0);
/** Particle mass m (> 0) of the massive models. */
ODHS_API int odhs_softcore_set_mass(odhs_softcore *sc, double m);
/** Shear rate gammadot (finite; 0 turns shear off). */
ODHS_API int odhs_softcore_set_shear_rate(odhs_softcore *sc, double gammadot);
/** Integrator of the overdamped models (ODHS_SOFTCORE_FIXED or _ADAPTIVE). */
ODHS_API int odhs_softcore_set_integrator(odhs_softcore *sc, int integrator);
/**
 * Step size factor c in (0, 10]: the fixed step is c tau_e (overdamped and
 * steepest descent) or c min(tau_m, m/k_d) (massive), also capped so that a
 * step shears by at most 0.01. Explicit Euler is stable for c up to about
 * 2/(2 z_max) with z_max the largest number of overlaps of a particle
 * (default 0.1).
 */
ODHS_API int odhs_softcore_set_dt(odhs_softcore *sc, double c);
/** Error tolerance per step of the adaptive integrator, relative to the
 *  mean diameter, in (0, 1) (default 1e-6). */
ODHS_API int odhs_softcore_set_tolerance(odhs_softcore *sc, double tol);
/** Minimiser (ODHS_SOFTCORE_SD, _FIRE or _CG). */
ODHS_API int odhs_softcore_set_minimiser(odhs_softcore *sc, int minimiser);
/** Stop minimising when the largest |grad_i U| is below tol (> 0, in
 *  force units; default 1e-9), or fail after max_iter (> 0) iterations. */
ODHS_API int odhs_softcore_set_min_tolerance(odhs_softcore *sc, double tol, uint64_t max_iter);
/** Relative residual of the CD0 linear solve, in (0, 1) (default 1e-12). */
ODHS_API int odhs_softcore_set_linear_tolerance(odhs_softcore *sc, double tol);

/**
 * Overwrite the positions x[0..n*dim-1] (lab frame, wrapped into the box).
 * Unlike odhs_system_set_positions, overlaps are allowed. Errors:
 * ODHS_E_NULL, ODHS_E_NONFINITE.
 */
ODHS_API int odhs_softcore_set_positions(odhs_softcore *sc, const double *x);
/**
 * Scale the box and every position by s (> 0) about the origin: an affine
 * isotropic compression (s < 1) or dilation (s > 1) that, unlike
 * odhs_system_scale_box, may create overlaps (soft-sphere jamming protocols
 * compress and minimise). The strain, radii and velocities are kept.
 * Errors: ODHS_E_NULL, ODHS_E_NONFINITE (s or a scaled edge not finite),
 * ODHS_E_INVALID (s <= 0), ODHS_E_BOX (an edge would be shorter than twice the
 * largest diameter); the system is then unchanged. (Since 0.2.1.)
 */
ODHS_API int odhs_softcore_scale_box(odhs_softcore *sc, double s);
/** Set the non-affine velocities u[0..n*dim-1] (massive models; the
 *  overdamped models compute them). ODHS_E_NONFINITE for NaN/Inf. */
ODHS_API int odhs_softcore_set_velocities(odhs_softcore *sc, const double *u);
/** Forget cached neighbour lists and forces after the system was changed
 *  through other calls (box, radii, positions, strain). Time, strain and
 *  velocities are kept. ODHS_E_STATE if the system is not ready. */
ODHS_API int odhs_softcore_reset(odhs_softcore *sc);

/**
 * Take one time step of the current model at the current shear rate.
 * Errors (the step is rolled back): ODHS_E_NONFINITE (the integration blew up:
 * reduce the step), ODHS_E_NOCONV (CD0 solve), ODHS_E_UNSUPPORTED (CD0 with
 * k_0 = 0, RD0 with k_d = 0), ODHS_E_NOMEM.
 */
ODHS_API int odhs_softcore_step(odhs_softcore *sc);
/** Step until the accumulated strain reaches gamma (the last step is
 *  truncated to land on it). ODHS_E_INVALID if the shear rate is 0 or gamma
 *  lies behind the current strain in the direction of the shear. On error,
 *  the steps taken before the failing one are kept. */
ODHS_API int odhs_softcore_run_until_strain(odhs_softcore *sc, double gamma);
/** Step until time t (>= current time; the last step lands on t). */
ODHS_API int odhs_softcore_run_until_time(odhs_softcore *sc, double t);

/**
 * Minimise the elastic energy at fixed strain with the chosen minimiser
 * until the largest force is below the minimiser tolerance. *iterations (may
 * be NULL) receives the number of iterations. Velocities are set to zero.
 * With steepest descent the time integral of the elastic stress along the
 * relaxation is accumulated (see odhs_softcore_relaxation_stress).
 * Errors: ODHS_E_NOCONV after max_iter iterations (rolled back).
 */
ODHS_API int odhs_softcore_minimise(odhs_softcore *sc, uint64_t *iterations);
/**
 * Quasistatic step: affine shear by dgamma (nonzero, |dgamma| <= 0.1;
 * x -> x + dgamma y xhat, box strain + dgamma), then odhs_softcore_minimise.
 * The accumulated strain grows by dgamma. After a steepest-descent step,
 * odhs_softcore_relaxation_stress gives (1/dgamma) integral sigma dt of the
 * relaxation. Errors as odhs_softcore_minimise (the whole step is rolled
 * back) and ODHS_E_INVALID.
 */
ODHS_API int odhs_softcore_quasistatic_step(odhs_softcore *sc, double dgamma, uint64_t *iterations);

/* ---- observables of the current state ----------------------------------- */
/** Physical time (sum of the steps; minimisation takes no time). */
ODHS_API int odhs_softcore_time(const odhs_softcore *sc, double *t);
/** Accumulated shear strain (steps and quasistatic steps). */
ODHS_API int odhs_softcore_strain(const odhs_softcore *sc, double *gamma);
/** Counters: time steps, force evaluations, minimiser iterations (any may be
 *  NULL). */
ODHS_API int odhs_softcore_counts(const odhs_softcore *sc, uint64_t *steps, uint64_t *force_evals,
                                  uint64_t *min_iterations);
/** Current step size (physical time) of the current model and settings. */
ODHS_API int odhs_softcore_step_size(const odhs_softcore *sc, double *h);
/** Elastic energy U = sum_pairs V. */
ODHS_API int odhs_softcore_energy(const odhs_softcore *sc, double *U);
/** Kinetic energy of the non-affine velocities, sum m |u|^2 / 2 (massive
 *  models; 0 for the overdamped ones). */
ODHS_API int odhs_softcore_kinetic_energy(const odhs_softcore *sc, double *K);
/** Elastic forces F_i = -grad_i U into F[0..n*dim-1]. */
ODHS_API int odhs_softcore_forces(const odhs_softcore *sc, double *F);
/** Largest |grad_i U| over particles. */
ODHS_API int odhs_softcore_max_force(const odhs_softcore *sc, double *fmax);
/** Non-affine velocities u into u[0..n*dim-1]: the state of a massive model,
 *  or the velocities of the overdamped model at the current configuration
 *  (CD0: solved now; may fail like a step). */
ODHS_API int odhs_softcore_velocities(odhs_softcore *sc, double *u);
/**
 * Stress tensor (dim*dim, row-major; see the header comment), part one of
 * ODHS_SOFTCORE_STRESS_*. The dissipative part of CD0 needs the velocities
 * and solves for them like odhs_softcore_velocities.
 */
ODHS_API int odhs_softcore_stress(odhs_softcore *sc, int part, double *sigma);
/** Pressure -tr(sigma_total)/dim. */
ODHS_API int odhs_softcore_pressure(odhs_softcore *sc, double *p);
/** Largest relative overlap 1 - r/d_ij over pairs (0 when nothing
 *  overlaps). */
ODHS_API int odhs_softcore_max_overlap(const odhs_softcore *sc, double *overlap);
/** Mean number of overlapping neighbours z = 2 N_c / N; with rattler_free
 *  nonzero, particles with fewer than dim+1 overlaps are removed
 *  iteratively first and z = 2 N_c' / N' over the rest (0 if none remain). */
ODHS_API int odhs_softcore_coordination(const odhs_softcore *sc, int rattler_free, double *z);
/**
 * Stress per unit shear rate of the last steepest-descent relaxation,
 * (1/dgamma) integral sigma_el dt (dim*dim, time integral over the gradient
 * flow after the last quasistatic step). In the hard-sphere limit it equals
 * the event-driven stress at unit shear rate with mobility 1/k_d.
 * ODHS_E_STATE before a steepest-descent quasistatic step.
 */
ODHS_API int odhs_softcore_relaxation_stress(const odhs_softcore *sc, double *sigma);

#ifdef __cplusplus
}
#endif
#endif /* ODHS_SOFTCORE_H */
