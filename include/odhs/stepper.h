/*
 * libodhs - stepper.h: the event-driven integrator (Sect. IV of the paper).
 *
 * The stepper advances a system under a driver. Each step moves the particles
 * along their current velocities for dt (in the driver's natural time unit
 * tau, see driver.h), truncated at the first collision among particles not in
 * contact (predicted exactly for the straight-line motion of the step). After
 * the move the contact forces are recomputed; contacts whose force would be
 * negative are removed and approaching removed pairs re-connected by the
 * rewiring procedure of Sect. IV B, which yields the unique valid network
 * (Appendix A). Every `correction_interval` steps the contact-distance drift
 * is removed (Sect. IV C).
 *
 * The stepper borrows the system, driver and solver: they must outlive it.
 * Driver changes are picked up by the next step. The system must not be
 * changed behind its back: since 0.2.7 the stepper compares the system's
 * change count (odhs_system_change_count) with the one it last saw and
 * refuses to step (ODHS_E_STATE) after odhs_system_set_positions, _scale_box,
 * _set_radii etc. until odhs_stepper_reset is called (setting the values the
 * system already holds is no change).
 *
 * Time is physical time; strain is the accumulated shear strain
 * integral(gammadot dt). At fixed volume the system's Lees-Edwards strain is
 * that value remapped (see system.h); under compression or fixed pressure the
 * box tilt also follows the compression (H -> (I + t G) H), so the cell strain
 * then differs slightly from the accumulated strain.
 *
 * Event times: collisions are located exactly on the step's motion; openings
 * are found when a force is negative at the end of a step, so their time
 * resolution is the step dt*tau (Sect. IV A (ii.b) of the paper). A change of
 * the driver between steps is applied at the start of the next step; if it
 * opens or closes contacts, that step ends at once with those events and no
 * motion. With self-propulsion (driver.h) a step also ends exactly at every
 * switch time of a propulsion force, and the new forces act from there.
 */
#ifndef ODHS_STEPPER_H
#define ODHS_STEPPER_H

#include "odhs/driver.h"
#include "odhs/network.h"
#include "odhs/solver.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct odhs_stepper odhs_stepper;

/** Event kinds (pinned values). */
enum {
    ODHS_EVENT_NONE = 0,
    ODHS_EVENT_COLLISION = 1, /* a new contact formed                        */
    ODHS_EVENT_OPENING = 2    /* a contact opened (its force reached zero)   */
};

/** One event. Its layout is frozen (since 0.2.7: it never gains fields), so
 *  callers may allocate it for odhs_stepper_step; more about a step comes in
 *  odhs_step_info (odhs_stepper_step_ex), which carries its size. (0.2.6 and
 *  older said it might gain fields; none was ever added.) */
typedef struct odhs_event {
    int kind;      /* ODHS_EVENT_*                                   */
    size_t i, j;   /* the pair, i < j                                */
    double time;   /* physical time of the event                     */
    double strain; /* accumulated strain at the event                */
} odhs_event;

/** Event callback: return 0 to go on, nonzero to stop the run after the
 *  current step (the run call then returns ODHS_STOPPED). */
typedef int (*odhs_event_fn)(const odhs_event *ev, void *ctx);

/** Create a stepper on sys (must be ready: radii and positions set).
 *  On failure odhs_last_error() says why. */
ODHS_API int odhs_stepper_create(odhs_system *sys, odhs_driver *drv, odhs_solver *solver,
                                 odhs_stepper **out);
/** Destroy; NULL is a no-op. The system keeps its current configuration. */
ODHS_API void odhs_stepper_destroy(odhs_stepper *st);
/** The message of the last failed call on this stepper ("" if none).
 *  Since 0.2.7 a successful call that changes the stepper (settings,
 *  reset, step, run, correct) clears it; read-only calls leave it. The
 *  create failure's message: odhs_last_error() (common.h). */
ODHS_API const char *odhs_stepper_errmsg(const odhs_stepper *st);

/** Integrators (pinned values). */
enum {
    /** The paper's scheme: explicit Euler with the fixed step dt. */
    ODHS_INTEGRATOR_EULER = 0,
    /** Adaptive Heun (2nd-order Runge-Kutta with an embedded Euler error
     *  estimate): the step is chosen so that the estimated non-affine position
     *  error of a step stays below tol times the mean diameter, up to dt;
     *  2 force solves per accepted step; contact gaps drift as O(h^3). */
    ODHS_INTEGRATOR_HEUN = 1,
    /** Batched events (since 0.2.14): a step of size h is not truncated at
     *  collisions. Pairs that would close within the step take part in it
     *  as unilateral constraints on their end gaps, linearised at the start
     *  (gap + h S V >= 0, forces >= 0, complementary: time-stepping contact
     *  dynamics, as Moreau-Jean's or Maury-Venel's scheme), so a step takes
     *  many events at once and its cost no longer follows the number of
     *  events. The linearised gap bounds the real one from below: no pair
     *  overlaps at a step end; pairs whose constraint is active end touching
     *  and join the network (collisions), contacts whose force would be
     *  negative leave it (openings). Events are reported at the end of their
     *  step (time resolution h): first the net changes of the step's contact
     *  problem, then those of its end (a pair closed by the problem and
     *  opened by the end's rewiring is a collision and an opening). First order in h: an error controller keeps
     *  h/2 times the root mean square (over particles) change of the
     *  non-affine velocities over a step below tol times the mean diameter
     *  (default tol 1e-3, steps up to dt, default 5e-2 with this integrator;
     *  odhs_stepper_set_tolerance, odhs_stepper_set_dt).
     *  Drift correction after every step. A step whose contact problem is
     *  degenerate (a potentially jammed constrained set, a singular solve)
     *  is taken by the exact Heun scheme instead (odhs_stepper_batched_stats
     *  counts them). */
    ODHS_INTEGRATOR_BATCHED = 2
};

/** Step size in units of tau: the fixed step of ODHS_INTEGRATOR_EULER, the
 *  largest step of ODHS_INTEGRATOR_HEUN and ODHS_INTEGRATOR_BATCHED. Default
 *  1e-3, and 5e-2 for ODHS_INTEGRATOR_BATCHED (whose steps its tolerance
 *  sets): odhs_stepper_set_integrator brings its integrator's default unless
 *  dt was set here, which is then kept (as is the dt of a stepper read from
 *  a checkpoint; since 0.2.14). */
ODHS_API int odhs_stepper_set_dt(odhs_stepper *st, double dt);
/** Choose the integrator (default ODHS_INTEGRATOR_HEUN, with tolerance 1e-6
 *  and drift correction after every step). The paper's scheme is the named mode
 *  ODHS_INTEGRATOR_EULER (with the "cg" solver for the paper's solver): it
 *  brings the paper's correction interval, 10, unless an interval was set
 *  with odhs_stepper_set_correction_interval, which is then kept. (Before
 *  version 0.2 the default was ODHS_INTEGRATOR_EULER.) */
ODHS_API int odhs_stepper_set_integrator(odhs_stepper *st, int integrator);
/** Error tolerance of the adaptive integrators (relative to the mean
 *  diameter, per step; in (0, 1)). Default: 1e-6 for ODHS_INTEGRATOR_HEUN,
 *  1e-3 for ODHS_INTEGRATOR_BATCHED (whose error is a root mean square over
 *  particles, Heun's the maximum); odhs_stepper_set_integrator brings its
 *  integrator's default unless a tolerance was set here, which is then kept
 *  (as is the tolerance of a stepper read from a checkpoint). */
ODHS_API int odhs_stepper_set_tolerance(odhs_stepper *st, double tol);
/** Drift correction every k steps (0 disables). Default: 1 with
 *  ODHS_INTEGRATOR_HEUN, 10 (the paper's) with ODHS_INTEGRATOR_EULER; once
 *  set here, the interval no longer follows the integrator. */
ODHS_API int odhs_stepper_set_correction_interval(odhs_stepper *st, unsigned k);
/** Relative gap (gap / (a_i + a_j)) below which pairs count as initial contacts
 *  when the stepper starts (default 1e-9). */
ODHS_API int odhs_stepper_set_contact_tolerance(odhs_stepper *st, double tol);
/** Event callback (NULL removes). */
ODHS_API int odhs_stepper_set_event_callback(odhs_stepper *st, odhs_event_fn fn, void *ctx);

/* Composite particles (bonds, chains, rigid bodies): odhs/composite.h,
 * included at the end of this header. */

/**
 * (Re)build the initial contact network from the system (pairs within the
 * contact tolerance), compute the valid network, forces and velocities. Called
 * automatically by the first step; call it again after changing the system,
 * driver or solver. Time and strain are kept. With ODHS_INTEGRATOR_BATCHED
 * the valid network is found in blocks of events, a few solves instead of
 * one per opening (since 0.2.14; the same network).
 */
ODHS_API int odhs_stepper_reset(odhs_stepper *st);

/**
 * Apply the drift correction of Sect. IV C now, repeated until the contact
 * gaps are at round-off (a few passes: each leaves a second-order residual),
 * then re-solve and rewire; e.g. before saving a configuration. Events it
 * causes go to the event callback. Returns like odhs_stepper_step. Under
 * ODHS_INTEGRATOR_BATCHED a pass takes every pair its motion would close
 * at once (since 0.2.15; odhs_stepper_correction_stats).
 */
ODHS_API int odhs_stepper_correct(odhs_stepper *st);

/**
 * Take one step. *ev (may be NULL) receives the first event of the step, or
 * kind ODHS_EVENT_NONE. Returns ODHS_OK; ODHS_POTENTIALLY_JAMMED when a
 * collision made the constrained subset isostatic (the step up to that
 * collision is taken, the contact is in the network, N = S S^T is singular and
 * forces are not recomputed; every later call returns ODHS_POTENTIALLY_JAMMED
 * without moving); or an error (the configuration is rolled back to the start
 * of the step).
 */
ODHS_API int odhs_stepper_step(odhs_stepper *st, odhs_event *ev);
/**
 * What one step did (odhs_stepper_step_ex). The caller sets `size` to
 * sizeof(odhs_step_info) of the header it was compiled with; the library
 * fills only that many bytes, so a program built against an older, smaller
 * struct keeps working with a newer library, and fields a newer header adds
 * (only ever at the end) are left as the caller set them by an older
 * library: zero-initialise the struct. Since 0.2.7.
 */
typedef struct odhs_step_info {
    size_t size;           /* set by the caller: sizeof(odhs_step_info)          */
    int kind;              /* the step's first event: ODHS_EVENT_* (NONE if none) */
    size_t i, j;           /* ... its pair, i < j                                */
    double event_time;     /* ... its time                                       */
    double event_strain;   /* ... its accumulated strain                         */
    uint64_t collisions;   /* contacts formed in this step                      */
    uint64_t openings;     /* contacts opened in this step                      */
    double time_start;     /* physical time at the start of the step            */
    double time_end;       /* ... and at its end                                */
    double strain_start;   /* accumulated strain at the start of the step       */
    double strain_end;     /* ... and at its end                                */
    int advanced;          /* 1 if the time moved (time_end > time_start)       */
    int driver_change;     /* 1 if the step only applied a change of the driver
                            * that opened or closed contacts: events at the
                            * current time and no motion (advanced = 0)        */
} odhs_step_info;

/**
 * Take one step like odhs_stepper_step and describe it in *info (which
 * must have info->size set, at least offsetof(odhs_step_info, kind) +
 * sizeof(int): else ODHS_E_INVALID). Steps that do not advance the time
 * (after the driver changed, see driver_change; or a collision at the
 * step's start) say so in `advanced`. Returns as odhs_stepper_step; *info
 * is written when the step was taken (ODHS_OK, ODHS_STOPPED, ODHS_JAMMED,
 * ODHS_POTENTIALLY_JAMMED) and left alone on an error. Since 0.2.7.
 */
ODHS_API int odhs_stepper_step_ex(odhs_stepper *st, odhs_step_info *info);

/**
 * Guards of the run calls below (run_until_time, _strain,
 * _packing_fraction, run_events), so that no input makes them loop forever:
 *  - max_steps: the most steps one run call takes (0, the default: no cap);
 *    reaching it returns ODHS_STEP_LIMIT (a positive status: the state is
 *    valid and a new call goes on).
 *  - stall_steps: a run returns ODHS_E_STALLED after this many steps in a
 *    row that move neither the time, the strain nor the event count
 *    (default 1000; 0 disables), e.g. a step dt * tau below the resolution
 *    of the time. run_events also returns ODHS_E_STALLED at once when no
 *    event can happen (no flow or pressure control, forces that do not
 *    change with time, every particle moving with the same velocity: an
 *    empty driver, uniform gravity on equal particles in a periodic box);
 *    in other scenes where events are possible but may never come (two
 *    discs drifting past each other), only max_steps bounds it.
 * Also, run_until_time and _strain refuse (ODHS_E_INVALID) a target more
 * than 1e15 largest steps (dt * tau) away. Since 0.2.7.
 */
ODHS_API int odhs_stepper_set_run_limits(odhs_stepper *st, uint64_t max_steps, uint64_t stall_steps);
/** The run limits (either output may be NULL). Since 0.2.7. */
ODHS_API int odhs_stepper_get_run_limits(const odhs_stepper *st, uint64_t *max_steps, uint64_t *stall_steps);

/** Step until physical time t (the last step is truncated to land on t). */
ODHS_API int odhs_stepper_run_until_time(odhs_stepper *st, double t);
/** Step until accumulated strain gamma (shear rate must be nonzero). */
ODHS_API int odhs_stepper_run_until_strain(odhs_stepper *st, double gamma);
/** Step until `count` more events have happened. */
ODHS_API int odhs_stepper_run_events(odhs_stepper *st, uint64_t count);
/** Step until the packing fraction reaches phi (compression or pressure
 *  driving; the last step is truncated to land on phi). */
ODHS_API int odhs_stepper_run_until_packing_fraction(odhs_stepper *st, double phi);

/* ---- observables (of the current state) --------------------------------
 * Observables that need forces or velocities (stress, shear stress,
 * pressure, dissipation, power, velocities) return ODHS_E_STATE until the
 * stepper has a valid state (after odhs_stepper_reset or the first step);
 * counters, time, strain, kappa, coordination and errors are available at
 * once (zero before the first step). */
ODHS_API int odhs_stepper_time(const odhs_stepper *st, double *t);
ODHS_API int odhs_stepper_strain(const odhs_stepper *st, double *gamma);
/** The integration settings in force: integrator, dt, adaptive tolerance
 *  and drift-correction interval (any output may be NULL). A new stepper
 *  reports ODHS_INTEGRATOR_HEUN, 1e-3, 1e-6, 1. (Since 0.2.) */
ODHS_API int odhs_stepper_get_settings(const odhs_stepper *st, int *integrator, double *dt, double *tol,
                                       unsigned *correction_interval);
/** Adaptive-integrator counters: rejected steps and the current step (in tau
 *  units); either may be NULL. */
ODHS_API int odhs_stepper_adaptive_stats(const odhs_stepper *st, uint64_t *rejected, double *h);
/** Counters of the batched integrator (ODHS_INTEGRATOR_BATCHED; any output
 *  may be NULL): accepted batched steps, steps taken by the exact Heun
 *  scheme instead (a degenerate contact problem), and force solves of the
 *  steps' contact problems (rejected steps included). Counted since the
 *  stepper was created or read from a checkpoint. Since 0.2.14. */
ODHS_API int odhs_stepper_batched_stats(const odhs_stepper *st, uint64_t *batched_steps, uint64_t *exact_steps,
                                        uint64_t *solves);
/** Counters of the drift correction (Sect. IV C; any output may be NULL):
 *  corrections applied (after steps and by odhs_stepper_correct), their
 *  passes (one force solve each) and the pairs the passes closed (a
 *  correction's motion that meets a pair adds it as a contact). With the
 *  exact schemes a pass stops at the first pair its motion meets, so
 *  closing k pairs takes at least k passes; with ODHS_INTEGRATOR_BATCHED
 *  every pair the pass's motion would close joins at once (since 0.2.15),
 *  as the step's contact problem closes its pairs, and the end gaps of a
 *  batched step (second order in h, ~1e-3 of a diameter at the default
 *  tolerance) take a few passes however many pairs they close. Counted
 *  since the stepper was created or read from a checkpoint. Since 0.2.15. */
ODHS_API int odhs_stepper_correction_stats(const odhs_stepper *st, uint64_t *corrections, uint64_t *passes,
                                           uint64_t *closed);
/** Rewirings that the anti-cycling method finished (since 0.2.2). The
 *  paper's rule (drop the most negative force, re-connect the most
 *  approaching removed pair; Sect. IV B) can cycle on degenerate networks
 *  close to jamming; after 2 (contacts + 16) + 100 iterations of it the
 *  stepper continues from the network reached with the active-set method of
 *  Lawson and Hanson for the same complementarity problem, which cannot
 *  cycle and stops on the same tests (forces >= 0, no removed pair
 *  approaching). Counted since the stepper was created or read from a
 *  checkpoint; *count may not be NULL. */
ODHS_API int odhs_stepper_rewire_stats(const odhs_stepper *st, uint64_t *count);
/** Counters: steps, collisions, openings (any output may be NULL). */
ODHS_API int odhs_stepper_counts(const odhs_stepper *st, uint64_t *steps, uint64_t *collisions,
                                 uint64_t *openings);
/** Stress tensor sigma_ab = -(1/Omega) sum_c f_c R_a R_b / r (dim*dim, row-major;
 *  eq. 30 generalised, positive shear stress sigma_xy under positive shear),
 *  over particle contacts and bonds (wall forces: odhs_stepper_wall_force). */
ODHS_API int odhs_stepper_stress(const odhs_stepper *st, double *sigma);
/**
 * Record the stress just before each step's events (on = 1) or not (on = 0,
 * the default; other values: ODHS_E_INVALID). The stress of a hard-sphere
 * network changes continuously while the network lasts and jumps where it
 * changes (a collision; the rewiring after it); this record separates the
 * two: with it on, every step also solves the forces of its end
 * configuration on the network of its start (one more force solve per step),
 * so that for each step
 *     odhs_stepper_pre_event_stress - the stress before the step
 * is the continuous change during the step, and
 *     odhs_stepper_stress - odhs_stepper_pre_event_stress
 * the jump at its end (its collisions, openings and drift correction). The
 * paper's Fig. 4 signal (relaxation between collisions, upward jumps at
 * them) is this pair of values. The record changes no other result: with a
 * stateless solver (dense, cholmod, spqr) a run is bit-identical with and
 * without it; solvers that keep state between solves (cg warm starts,
 * cholmod-pcg, auto's choices) may differ within their tolerance. Not
 * recorded under pressure control. Switching changes nothing else and
 * clears the record; checkpoints do not store it (a stepper read from one
 * starts with the record off). Since 0.2.8.
 */
ODHS_API int odhs_stepper_set_pre_event_stress(odhs_stepper *st, int on);
/**
 * The stress tensor (dim*dim, as odhs_stepper_stress) at the end of the last
 * step's motion, on the network of its start: the left limit of the stress
 * at the step's events. ODHS_E_STATE (with the reason in the message) when
 * there is no record: recording off, no step since it was switched on or
 * since odhs_stepper_reset, the last step only applied a change of the
 * driver (no motion), pressure control, or the solve on the start network
 * failed (e.g. a network that became potentially jammed). A failed step
 * leaves the previous record. Since 0.2.8.
 */
ODHS_API int odhs_stepper_pre_event_stress(const odhs_stepper *st, double *sigma);
/** Shear stress sigma_xy. */
ODHS_API int odhs_stepper_shear_stress(const odhs_stepper *st, double *sigma_xy);
/** Pressure p = <f|r>/(Omega d) (eq. 24). */
ODHS_API int odhs_stepper_pressure(const odhs_stepper *st, double *p);
/** Current kappa (compression-to-shear rate ratio; 0 without pressure control
 *  unless a compression rate is set, then c/gammadot or c when no shear). */
ODHS_API int odhs_stepper_kappa(const odhs_stepper *st, double *kappa);
/** Dissipation rate xi0^{-1} sum_k |V_k - V_aff,k|^2. */
ODHS_API int odhs_stepper_dissipation(const odhs_stepper *st, double *D);
/** Power injected: -<f|S V_aff> + <F_ext|V - V_aff> (equals the dissipation). */
ODHS_API int odhs_stepper_power(const odhs_stepper *st, double *P);
/** Velocities V (N*dim, lab frame, V_aff measured from the box origin). */
ODHS_API int odhs_stepper_velocities(const odhs_stepper *st, double *V);
/** Non-affine velocities V - V_aff (N*dim). */
ODHS_API int odhs_stepper_nonaffine_velocities(const odhs_stepper *st, double *U);
/**
 * The external force on each particle (N*dim) in the state the observables
 * describe: the driver's fixed forces, the force callback's output, gravity
 * and self-propulsion summed (not the contact forces); zeros when the scene
 * has none. Since 0.2.6.
 */
ODHS_API int odhs_stepper_external_forces(const odhs_stepper *st, double *F);
/**
 * The current contacts in one call, into the caller's arrays (the caller
 * owns them; the library keeps no pointer): pairs i[k] < j[k] (j = N + w
 * for wall w), kind[k] (ODHS_CONTACT_*), force f[k] (>= 0 on a valid
 * network; eq. 30's f_c) and gap[k] (r - a_i - a_j, or the wall gap), for
 * k < Nc; any array may be NULL. *nc receives Nc. When cap < Nc nothing is
 * written except *nc and the call returns ODHS_E_RANGE: call with cap = 0
 * to learn the size. The same order as odhs_network_get_contact on
 * odhs_stepper_network. ODHS_E_STATE before the first reset or step.
 * Since 0.2.7.
 */
ODHS_API int odhs_stepper_contacts(const odhs_stepper *st, size_t cap, size_t *nc, size_t *i, size_t *j, int *kind,
                                   double *f, double *gap);
/** Mean coordination z = 2 Nc / N. */
ODHS_API int odhs_stepper_coordination(const odhs_stepper *st, double *z);
/** Optional features whose code a scene runs only when it uses them (pinned
 *  values; more may be added). */
enum {
    ODHS_FEATURE_PRESSURE = 1,  /* pressure control: the extra solve for kappa  */
    ODHS_FEATURE_COMPOSITE = 2, /* bonds: rest lengths, body-level subset       */
    ODHS_FEATURE_WALLS = 3      /* walls: collision prediction against walls    */
};
/** How many times the stepper ran the code of an optional feature: passes of
 *  the pressure-control solve, passes over bond rest lengths and rebuilds of
 *  the body-level constrained subset, or wall collision predictions. A scene that does not use a feature
 *  reads 0: it pays nothing for it. ODHS_E_INVALID for an unknown feature. */
ODHS_API int odhs_stepper_feature_work(const odhs_stepper *st, int feature, uint64_t *count);
/** The current contact network (owned by the stepper; read only). */
ODHS_API const odhs_network *odhs_stepper_network(const odhs_stepper *st);
/** Largest |gap|/(a_i+a_j) over contacts (|gap|/a_i for wall contacts, the
 *  rest length for bonds) and the largest overlap (walls included)
 *  -gap/(a_i+a_j) over all pairs (<= 0 if none); either may be NULL. */
ODHS_API int odhs_stepper_errors(const odhs_stepper *st, double *contact_gap, double *overlap);

#ifdef __cplusplus
}
#endif

/* declared with their definitions (lib/scene/composite.c); included here for
 * code written before 0.2.4 that includes only odhs/stepper.h */
#include "odhs/composite.h"

#endif /* ODHS_STEPPER_H */
