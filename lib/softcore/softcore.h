/*
 * libodhs private header: the soft-core reference models (Vagberg's thesis,
 * ch. 4): RD0, CD0, quasistatic shear with steepest descent / FIRE /
 * Polak-Ribiere CG, and the massive RD, CD, CD_n, CD_t models with SLLOD
 * (include/odhs/softcore.h). The handle and the helpers shared by the files
 * of lib/softcore/: handle.c (creation, settings), forces.c (neighbour list,
 * elastic and dissipative forces, CD0 solve), dynamics.c (time stepping),
 * minimise.c (minimisers, quasistatic shear), observables.c.
 * Not installed.
 */
#ifndef ODHS_SOFTCORE_SOFTCORE_H
#define ODHS_SOFTCORE_SOFTCORE_H

#include "system/system.h"

struct odhs_softcore {
    odhs_system *sys;
    int dim;
    size_t n, nd;
    /* settings */
    int model;
    double alpha, ke, kd, k0, mass, gdot;
    int integ;
    double cdt, tol;
    int minimiser;
    double gtol;
    uint64_t maxit;
    double ltol;
    /* state */
    double time, strain;
    uint64_t nsteps, nforce, nmin;
    double h_ad;         /* adaptive: current step (0 = not started) */
    double *u;           /* non-affine velocities (nd) */
    double *F;           /* elastic forces of the last evaluation (nd) */
    int fc_ok;           /* massive: F and the contact list belong to sys->x */
    double *w1, *w2, *w3, *w4, *w5; /* nd work */
    double *xs, *us;     /* rollback snapshot (nd) */
    double *xw;          /* nd work for the pair builder */
    double dmin, lambda; /* smallest and mean diameter */
    /* neighbour (Verlet) list */
    size_t *pi, *pj;
    uint64_t *pk;        /* sort keys i*n + j (pkcap) */
    size_t np, pcap, pkcap;
    double skin;
    double *xb;          /* positions at the last build */
    double strain_b;
    int nb_ok;
    /* overlapping pairs of the last elastic evaluation */
    size_t *ci, *cj;
    double *cr;          /* separations (ccap*dim) */
    size_t nc, ccap;
    /* CD0 solve work (n each) */
    double *g_r, *g_z, *g_p, *g_q, *g_diag, *g_b, *g_x;
    double *relax;       /* dim*dim: integral of sigma dt over the last SD relaxation */
    double relax_acc[9];
    int has_relax;
    uint64_t nforce_s;   /* snapshot of the counter (rollback) */
    int fc_ok_s;
    double h_ad_s;
    char errmsg[ODHS_ERRMSG_LEN];
};

/* format the handle's error message, return status (handle.c) */
int odhs__scerr(const odhs_softcore *sc, int status, const char *fmt, ...) ODHS_PRINTF(3, 4);

#define SCNULL(sc)                      \
    do {                                \
        if (!(sc)) return ODHS_E_NULL;  \
    } while (0)

static inline int odhs__sc_is_massive(int model) { return model >= ODHS_SOFTCORE_RD; }

/* ---- handle.c ---------------------------------------------------------------- */
/* wrap every particle of x into the primary cell */
void odhs__sc_wrap_all(odhs_softcore *sc, double *x);

/* ---- forces.c ---------------------------------------------------------------- */
/* Elastic forces F (may be NULL), energy U, elastic stress sum (unnormalised,
 * -sum f r n n; may be NULL), max overlap at positions x; records the
 * overlapping pairs. */
int odhs__sc_elastic(odhs_softcore *sc, const double *x, double *F, double *U, double *sig, double *maxov);
/* CD0: (k_d L + k_0 I) u = F + k_d gammadot sum_j r_ij,y xhat at the recorded contacts */
int odhs__sc_cd0_solve(odhs_softcore *sc, const double *F, double *u);
/* overdamped non-affine velocities at x (forces into F) */
int odhs__sc_od_velocity(odhs_softcore *sc, const double *x, double *F, double *u);
/* dissipative forces of the massive models at the recorded contacts,
 * velocities u; optional unnormalised stress sum (sum dv_a r_b k_d). */
void odhs__sc_dissipative(const odhs_softcore *sc, int model, const double *u, double *Fd, double *sig);
/* largest per-particle norm of F */
double odhs__sc_max_norm(const odhs_softcore *sc, const double *F);
double odhs__sc_dot(const double *a, const double *b, size_t n);

/* ---- dynamics.c -------------------------------------------------------------- */
/* step length of the fixed-step integrators (overdamped Euler, SLLOD) */
double odhs__sc_base_step(const odhs_softcore *sc);
/* save / restore positions, velocities, strain, time and the force cache */
void odhs__sc_snapshot(odhs_softcore *sc, double *gam, double *str, double *tim);
void odhs__sc_rollback(odhs_softcore *sc, double gam, double str, double tim);
void odhs__sc_advance_strain(odhs_softcore *sc, double dg);
int odhs__sc_all_finite(const double *v, size_t n);

#endif /* ODHS_SOFTCORE_SOFTCORE_H */
