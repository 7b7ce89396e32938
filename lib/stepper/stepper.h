/*
 * libodhs private header: the event stepper handle.
 * Not installed.
 */
#ifndef ODHS_STEPPER_STEPPER_H
#define ODHS_STEPPER_STEPPER_H

#include "driver/driver.h"
#include "jamming/jamming.h"

/* restored stepper: mark the neighbour list stale unless it holds every pair
 * closer than the unused skin (lib/stepper.c); ODHS_OK or ODHS_E_NOMEM */
int odhs__stepper_check_neighbours(odhs_stepper *st);
/* tests: 1 = always the anti-cycling rewiring, 0 = the paper's rule first */
int odhs__stepper_set_rewire_mode(odhs_stepper *st, int mode);
/* tests: the smallest backbone force (relative to the mean) below which
 * odhs_stepper_jam_lp shakes a packing (lib/jamming/lp.c; 0: its default) */
void odhs__stepper_set_lp_min_force(odhs_stepper *st, double v);
/* tests: 1 = jam_lp solves a programme without a basis by the dual simplex
 * from the slack basis (up to 0.2.10) instead of the primal values pass */
void odhs__stepper_set_lp_cold_dual(odhs_stepper *st, int v);
/* tests: the next v resets of odhs_stepper_jam_lp on a chain's packing are
 * refused as ODHS_POTENTIALLY_JAMMED (a degenerate packing; lp.c) */
void odhs__stepper_set_lp_reset_fail(odhs_stepper *st, int v);

/* ---- stepper ------------------------------------------------------------------ */
typedef struct {
    size_t i, j;
    int delta; /* +1 added, -1 removed */
} odhs_change;

struct odhs_stepper {
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_network *net;
    int dim;
    size_t n, nd;
    /* settings */
    double dt;
    int integrator;   /* ODHS_INTEGRATOR_* */
    double tol;       /* adaptive: error per step, relative to the mean diameter */
    double tol_exact; /* > 0: the tolerance of the Heun step a batched step falls
                       * back to (batched.c, exact_step), instead of tol
                       * (odhs_stepper_jam_lp's end game sets it for the
                       * duration of the call; not checkpointed) */
    int tol_user;     /* the tolerance was set (not the integrator's default) */
    int dt_user;      /* dt was set (not the integrator's default) */
    double bh;        /* > 0 while the batched step's contact problem is solved:
                       * the step, over which each contact's gap closes (forces.c) */
    uint64_t nbatched, nbatched_exact, nbatched_solves; /* batched.c (not checkpointed) */
    uint64_t ncorr, ncorr_passes, ncorr_closed;         /* correct.c (not checkpointed) */
    odhs_change *bviol; /* batched.c: the pairs a contact problem closes */
    size_t bviolcap;
    double h;         /* adaptive: current step in units of tau */
    double lambda;    /* mean diameter */
    double *U0, *Ua;  /* adaptive: velocities at the start, averaged (nd) */
    double *Up;       /* adaptive: predictor velocities U* of the accepted step (nd) */
    double Gp[9], taup; /* ... its gradient and step length */
    int pred_ok;      /* Up, Gp, taup belong to the current step */
    int flow_end;     /* the forces are evaluated at the end of a step (the
                       * driver's flow up to st->time) */
    int corr_user;    /* the correction interval was set (not the integrator's default) */
    double *disps;    /* adaptive: displacement record at the start (nd) */
    double Ms[9];
    uint64_t nrejected, nsolves_pred;
    uint64_t work_pressure; /* pressure-control solves (odhs_stepper_feature_work) */
    unsigned corr_every;
    int corr_skipped;  /* the last drift correction waited for the rewiring (correct.c) */
    double contact_tol;
    odhs_event_fn evfn;
    void *evctx;
    /* state */
    int ready, jammed;
    double time, strain;
    uint64_t nsteps, ncoll, nopen;
    double tau;       /* natural time unit */
    uint64_t drv_version; /* driver version the current forces were solved for */
    double G[9];      /* velocity gradient of the affine flow, row-major */
    double kappa;
    double *F;        /* external forces at the current time (nd) */
    int has_F;
    double *U;        /* non-affine velocities (nd) */
    double *tmp;      /* nd work */
    double *cb, *cx;  /* contact-space work */
    size_t ccap;
    /* neighbour list */
    size_t *pi, *pj;
    size_t npairs, pcap;
    double skin, rc;
    double *disp;     /* non-affine displacement since the last build (nd) */
    double M[9];      /* affine deformation since the last build */
    /* contact flags of the neighbour pairs (predict.c): pflag[p] = 1 only if
     * pair p is a contact, so that the collision sweep skips it at once;
     * kept up to date from the network's change log (pflag_log: its count
     * the flags follow). ppart/pidx: each particle's pairs as the smaller
     * index (CSR). pflag_state: 0 = to build (a new neighbour list), 1 =
     * current as of pflag_log, 2 = unavailable until the next list (out of
     * memory: the sweep then asks the network's hash, as without flags) */
    unsigned char *pflag;
    size_t *ppart, *pidx;
    size_t pflag_cap, ppart_cap, pidx_cap;
    uint64_t pflag_log;
    int pflag_state;
    /* rewiring */
    odhs_change *rem; /* pairs removed during the current rewiring */
    size_t nrem, remcap;
    int rewire_mode;            /* 0: paper's rule, anti-cycling takeover; 1: anti-cycling only (tests) */
    uint64_t nrewire_monotone;  /* rewirings the anti-cycling method finished (not checkpointed) */
    uint64_t njam_pivots;       /* pivots of jam_finish on the final packing (not checkpointed) */
    double lp_min_force;        /* tests: jam_lp's degeneracy threshold (0: default; lp.c) */
    int lp_reset_fail;          /* tests: resets of jam_lp refused (lp.c) */
    int lp_cold_dual;           /* tests: jam_lp solves a programme without a basis by the dual
                                 * simplex from the slack basis, as up to 0.2.10 (lp.c) */
    /* fixed pressure through the network without contact iso_k (pressure.c):
     * scratch vectors in fpj (f0 and freg first, nc each); pj_bordered while
     * the velocities are S^T freg + pj_alpha pj_res (res: nd, then nd of
     * scratch) */
    double *fpj;
    size_t fpjcap;
    uint64_t fpj_version;       /* net->version of the f0 in fpj (0: none) */
    uint64_t iso_sub_version;   /* net->version of iso_sub */
    uint64_t iso_basis_version; /* net->version of the basis (u, w, res) for iso_k */
    odhs_network *iso_sub;      /* the network without contact iso_k */
    size_t iso_k, iso_ci, iso_cj; /* that contact and its pair (iso_ci SIZE_MAX: none) */
    double *pj_res;
    size_t pj_rescap;
    double pj_alpha;
    int pj_bordered;
    odhs_change *chg;
    size_t nchg, chgcap;
    size_t chg_mark;  /* changes before it net on their own (events.c) */
    /* rollback snapshot: xs holds 3 nd doubles, positions then Us, Fs */
    double *xs, *Us, *Fs; /* Us, Fs: velocities and external forces */
    int has_Fs;
    double Ls[3], gammas, times, strains, kappas;
    uint64_t nsteps_s;
    double Gs[9];
    int nb_stale;
    size_t *sci, *scj;
    int *skind;
    double *sf;
    /* the step's start after a driver change was re-solved (step.c): what a
     * step repeated shorter returns to (the snapshot above keeps the state
     * before the call, for the rollback); fr has the capacity scap */
    double *fr, Gr[9], kappar;
    double *srest;    /* rest lengths (copied only with permanent contacts) */
    odhs_wall *wsnap; /* walls at the snapshot */
    size_t wsnapcap;
    size_t snc, scap;
    /* events of the last step */
    odhs_event *ev;
    size_t nev, evcap;
    int last_driver_only; /* the last step only applied a driver change (no motion) */
    /* embedding safety (since 0.2.7) */
    uint64_t sys_version;  /* the system's change count the state belongs to */
    uint64_t max_steps;    /* steps one run call may take (0: no cap) */
    uint64_t stall_steps;  /* steps without progress before ODHS_E_STALLED (0: never) */
    /* the stress before the step's events (since 0.2.8, observables.c):
     * recorded when pre_on, at the end configuration of each step's motion
     * on the network of its start; pending until the step succeeds */
    int pre_on;
    int pre_state, pre_pend_state; /* ODHS__PRE_*: why there is no value */
    double pre_sigma[9], pre_pend[9];
    double *pre_b, *pre_f;        /* contact-space work */
    size_t pre_bcap, pre_fcap;
    char errmsg[ODHS_ERRMSG_LEN];
};

/* ==== shared by the stepper's files ======================================== */
/* states of the pre-event stress record (odhs_stepper_pre_event_stress) */
enum { ODHS__PRE_NONE = 0, ODHS__PRE_OK, ODHS__PRE_DRIVER, ODHS__PRE_PRESSURE, ODHS__PRE_SOLVE, ODHS__PRE_BATCHED };
/* the stress tensor (dim x dim) of contact forces f on the current network */
void odhs__st_stress_of(const odhs_stepper *st, const double *f, double *sigma);
/* record the stress at the current configuration on the current network
 * (before the step's events) into the pending record (forces.c) */
int odhs__st_pre_event_record(odhs_stepper *st);
#define EPS_F 1e-12 /* relative threshold for negative forces   */
/* while many contacts change per solve (a batched step's contact problem,
 * the block rewiring), cholmod-pcg refactorises instead of updating its
 * factor contact by contact once more than this fraction of the contacts
 * changed since its last solve (its own default 1/8 suits one event per
 * solve; the updates also grow the factor's storage) */
#ifndef ODHS__BATCH_UPDATE_MAX
#define ODHS__BATCH_UPDATE_MAX (1.0 / 256.0)
#endif
#define EPS_V 1e-12 /* relative threshold for approaching pairs */

/* record an error message on the stepper (logically mutable) */
int odhs__sterr(const odhs_stepper *st, int status, const char *fmt, ...) ODHS_PRINTF(3, 4);

/* the driver's shear rate at the stepper's time (its left limit while the
 * adaptive scheme evaluates the end of a step) */
static inline double odhs__st_shear_rate(const odhs_stepper *st)
{
    return odhs__flow_shear_rate(st->drv, st->time, st->flow_end ? -1 : +1);
}

/* minimum-image separation R_j - R_i (3 entries, unused ones 0) */
static inline void odhs__st_min_sep(const odhs_stepper *st, size_t i, size_t j, double *d)
{
    const odhs_system *s = st->sys;
    int dim = st->dim;
    d[0] = d[1] = d[2] = 0.0;
    for (int k = 0; k < dim; ++k) d[k] = s->x[j * dim + k] - s->x[i * dim + k];
    odhs__min_image(dim, s->L, s->gamma, d, NULL);
}

/* ---- step types (integrators), in the manner of GSL's gsl_odeiv2_step_type:
 * the step loop (step.c) plans a chord with `chord`, fits it to the
 * neighbour list, predicts the first collision on it, moves, and lets the
 * scheme repeat the step shorter at three points (the hooks may be NULL). */
typedef struct {
    double limit;      /* largest time the step may advance */
    double tplan;      /* planned length of the chord */
    double G[9];       /* the chord: velocity gradient ... */
    const double *vel; /* ... and non-affine velocities (nd) */
    double t;          /* length moved: to the first collision or tplan */
    size_t ci, cj;     /* that collision (SIZE_MAX: none) */
    double tsw, dsw;   /* next switch time of the driver, and the time left to it */
    int at_switch;     /* the step ended at the switch time */
    int relocated;     /* the step was repeated with a shorter chord */
    int nhalve;        /* times the planned step was halved */
    int exact;         /* a batched step taken by the exact scheme instead (batched.c) */
} odhs__step_plan;

typedef struct {
    int id;                /* ODHS_INTEGRATOR_* */
    const char *name;
    unsigned corr_default; /* default drift-correction interval */
    /* at the start of a step, before any motion (may be NULL) */
    void (*begin)(odhs_stepper *st);
    /* the chord over at most p->limit: p->G, p->vel, p->tplan */
    int (*chord)(odhs_stepper *st, odhs__step_plan *p);
    /* after the prediction: 1 = plan again (p->limit changed), 0 = move */
    int (*early)(odhs_stepper *st, odhs__step_plan *p);
    /* after the move, before a collision is added: *again = 1 after putting
     * the state back to the start of the step (odhs__st_restart) with a new
     * p->limit */
    int (*at_collision)(odhs_stepper *st, odhs__step_plan *p, int *again);
    /* likewise after the external forces at the end of a step without a
     * collision (an opening inside the step) */
    int (*at_opening)(odhs_stepper *st, odhs__step_plan *p, int *again);
    /* a step type that is not truncated at collisions: the whole motion of
     * the step (replaces chord, prediction and the hooks above; NULL: the
     * event-driven loop of step.c) */
    int (*advance)(odhs_stepper *st, odhs__step_plan *p);
    /* after the step's end (drift correction and rewiring), before its
     * events are emitted: *again = 1 after putting the state back to the
     * start of the step, to take it anew (an error controller) */
    int (*judge)(odhs_stepper *st, odhs__step_plan *p, int *again);
    double tol_default; /* the tolerance this integrator starts with */
    double dt_default;  /* and its dt (odhs_stepper_set_dt) */
    double h_first;     /* its first adaptive step, relative to dt */
    /* the step's end rewires by block updates (odhs__st_rewire_block), and
     * a pass of its drift correction closes every pair its motion meets at
     * once (odhs__st_batched_chord_pairs; correct.c) */
    int block_rewire;
} odhs__step_type;

extern const odhs__step_type odhs__step_euler; /* euler.c: the paper's scheme */
extern const odhs__step_type odhs__step_heun;  /* heun.c: adaptive Heun */
extern const odhs__step_type odhs__step_batched; /* batched.c: batched events */
/* the event-driven step (chord, first collision, motion) of a step type,
 * for a batched step that falls back to it (step.c) */
int odhs__st_advance_exact(odhs_stepper *st, const odhs__step_type *type, odhs__step_plan *p);
/* move by p->t along the chord p->G, p->vel; the clock follows (step.c) */
int odhs__st_move(odhs_stepper *st, odhs__step_plan *p);
/* the step type of ODHS_INTEGRATOR_* id, NULL if none (step.c) */
const odhs__step_type *odhs__step_type_find(int id);

/* ---- forces.c: forces and velocities on the current network ---------------- */
int odhs__st_reserve_contacts(odhs_stepper *st, size_t nc);
/* the affine velocity gradient with isotropic compression rate c_eff at the
 * stepper's time, from the driver's flow */
void odhs__st_set_gradient(odhs_stepper *st, double c_eff);
/* external forces at the current time into st->F (st->has_F) */
int odhs__st_external_forces(odhs_stepper *st);
int odhs__st_solve(odhs_stepper *st, const double *b, double *x);
/* (S V_aff)_c + w_c: the gap rate of contact c under the affine flow G
 * (w_c: a wall's own velocity) */
double odhs__st_affine_rate(const odhs_stepper *st, const double *G, size_t c);
/* b = -S (V_aff + xi0 F) / xi0 without the pressure part of V_aff */
void odhs__st_affine_rhs(odhs_stepper *st, double *b);
/* contact forces into net->f (and kappa, G) */
int odhs__st_compute_forces(odhs_stepper *st);
void odhs__st_compute_velocities(odhs_stepper *st);
double odhs__st_velocity_scale(const odhs_stepper *st);
/* relative normal velocity of a pair (j >= n: wall j - n), contact or not */
double odhs__st_pair_velocity(const odhs_stepper *st, size_t i, size_t j);
void odhs__st_contact_geometry(odhs_stepper *st, size_t c);
/* add contact (i, j) to the network and the step's changes; *c its index */
int odhs__st_add_contact(odhs_stepper *st, size_t i, size_t j, size_t *c);

/* ---- pressure.c: fixed pressure -------------------------------------------- */
/* the forces (net->f), kappa and G at fixed pressure */
int odhs__st_pressure_forces(odhs_stepper *st);
/* the self-stress at zero pressure h of a network with one contact more
 * than isostatic (S^T h = 0, <r|h> = 0, max |h| = 1, sign undetermined):
 * by sparse solves, else the dense SVD; ODHS_POTENTIALLY_JAMMED when neither
 * finds a unique one */
int odhs__st_zero_pressure_stress(odhs_stepper *st, double *h);
/* the zero-pressure self-stress of a network with one contact more than
 * isostatic, signed against the driving, into net->f */
int odhs__st_pressure_open_direction(odhs_stepper *st);
/* the self-stress f0 of an isostatic network into st->fpj (max |f0| = 1,
 * sum > 0), and the bordered basis for its largest contact st->iso_k */
int odhs__st_isostatic_f0(odhs_stepper *st);
int odhs__st_correct_isostatic(odhs_stepper *st, double *Z);

/* ---- rewire.c, endgame.c ---------------------------------------------------- */
int odhs__st_rewire(odhs_stepper *st);
/* the same network by block updates (many events at once; rewire.c) */
int odhs__st_rewire_block(odhs_stepper *st);
/* batched.c: the pairs a drift-correction chord closes within its unit time
 * (into st->bviol, by index) */
int odhs__st_batched_chord_pairs(odhs_stepper *st, const double *G, const double *vel, size_t *nv);
int odhs__st_open_contact(odhs_stepper *st, size_t k, double *x);
int odhs__st_jam_finish(odhs_stepper *st);
/* endgame.c: rattlers pushed out of the pairs they overlap (part of
 * odhs__st_jam_finish; exported for the tests) */
int odhs__st_jam_rattlers(odhs_stepper *st);

/* ---- neighbours.c, predict.c, motion.c ------------------------------------ */
int odhs__st_build_neighbours(odhs_stepper *st);
double odhs__st_skin_used(const odhs_stepper *st);
double odhs__st_skin_rate(const odhs_stepper *st, const double *G, const double *vel);
/* bring st->pflag up to date with the network (predict.c): 1 when the
 * flags are usable, 0 when not (out of memory until the next list) */
int odhs__st_pair_flags(odhs_stepper *st);
double odhs__st_predict(odhs_stepper *st, const double *G, const double *vel, double horizon, double vtol,
                        int moving, int current, size_t *pi, size_t *pj);
void odhs__st_advance(odhs_stepper *st, const double *G, const double *vel, double t);
void odhs__st_advance_walls(odhs_stepper *st, double t);

/* ---- save.c, correct.c, events.c, lifecycle.c ------------------------------ */
int odhs__st_save(odhs_stepper *st);
/* back to the positions, walls and box of the saved state */
void odhs__st_restore_motion(odhs_stepper *st);
/* the whole saved state back (a failed step) */
void odhs__st_rollback(odhs_stepper *st);
/* the network of the saved state back (contacts, kinds, forces, rest lengths) */
void odhs__st_restore_network(odhs_stepper *st);
/* the forces and flow now are the step's start (odhs__st_restart) */
void odhs__st_mark_start(odhs_stepper *st);
/* back to the start of the step before any contact changed, with the
 * displacement record of the scheme's begin (a step repeated shorter) */
int odhs__st_restart(odhs_stepper *st);
int odhs__st_correct(odhs_stepper *st, int *added);
int odhs__st_record_change(odhs_stepper *st, size_t i, size_t j, int delta);
int odhs__st_emit_events(odhs_stepper *st, odhs_event *first, int *stop);
int odhs__st_check_driver(odhs_stepper *st);
/* the force callback of a checkpoint is set again and the system unchanged
 * behind the stepper's back (ODHS_OK or ODHS_E_STATE with a message) */
int odhs__st_check_handles(odhs_stepper *st);
/* default of odhs_stepper_set_run_limits' stall_steps */
#define ODHS_STALL_STEPS_DEFAULT 1000

#endif /* ODHS_STEPPER_STEPPER_H */
