/*
 * libodhs - tests of the event-driven stepper (suite "stepper").
 *
 * Every test checks physics with numbers: analytic two-body solutions,
 * invariants (no overlap, no negative force, power balance) after every step,
 * rate invariance, uniqueness of the rewired network (Appendix A of Lerner,
 * During & Wyart 2013) by brute force over all subsets, fixed pressure,
 * agreement of the CG and dense solvers, event bookkeeping, drift correction
 * and compression targets.
 *
 * Every stepping loop goes through step_checked(), which after each step
 * asserts
 *   - no overlap beyond 1e-12 of the mean diameter, both from
 *     odhs_stepper_errors and from an independent O(N^2) brute-force search
 *     over lattice images (tests/testutil.h);
 *   - no negative force on temporary contacts (f_min >= -1e-12 f_max);
 *   - power balance: dissipation == power to 1e-10 relative;
 *   - rigidity of the contacts (eqs. 4, 17): (S V)_c = 0 to 1e-9 of the
 *     velocity scale.
 * The run_*_checked() helpers step with step_checked() until one step before
 * the target and let the library land on it, then check again.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "testutil.h"

/* ---- tolerances of the invariants ---------------------------------------- */
#define TOL_OVERLAP 1e-12 /* overlap / mean diameter                        */
#define TOL_NEGF 1e-12    /* min force >= -TOL_NEGF * max force             */
#define TOL_POWER 1e-10   /* |dissipation - power| / scale                  */

#define CHECK_OK(call)                                                                  \
    do {                                                                                \
        int rc_ = (call);                                                               \
        ck_assert_msg(rc_ == ODHS_OK, "%s returned %d (%s)", #call, rc_, odhs_strerror(rc_)); \
    } while (0)

#define CHECK_ST(st, call)                                                                      \
    do {                                                                                        \
        int rc_ = (call);                                                                       \
        ck_assert_msg(rc_ == ODHS_OK, "%s returned %d (%s): %s", #call, rc_, odhs_strerror(rc_), \
                      odhs_stepper_errmsg(st));                                                 \
    } while (0)

static void *xcalloc(size_t n, size_t size)
{
    void *p = calloc(n ? n : 1, size ? size : 1);
    ck_assert_msg(p != NULL, "out of memory");
    return p;
}

/* ========================================================================== */
/* Event log                                                                  */
/* ========================================================================== */
typedef struct {
    int kind;
    size_t i, j;
    double time, strain;
    uint64_t step; /* stepper step counter when the event was reported */
} evrec;

typedef struct {
    evrec *e;
    size_t n, cap;
    size_t stop_at;              /* callback returns 1 once n >= stop_at (0: never) */
    const odhs_stepper *st;      /* for the step counter                          */
    const odhs_system *sys;      /* positions at the last callback                */
    double *xcb;                 /* (nd doubles)                                  */
    size_t bad_order;            /* events with i >= j                            */
} evlog;

static int ev_cb(const odhs_event *ev, void *ctx)
{
    evlog *lg = ctx;
    if (lg->n == lg->cap) {
        size_t c = lg->cap ? 2 * lg->cap : 64;
        evrec *p = realloc(lg->e, c * sizeof *p);
        if (!p) return 1;
        lg->e = p;
        lg->cap = c;
    }
    evrec *r = &lg->e[lg->n++];
    r->kind = ev->kind;
    r->i = ev->i;
    r->j = ev->j;
    r->time = ev->time;
    r->strain = ev->strain;
    r->step = 0;
    if (lg->st) odhs_stepper_counts(lg->st, &r->step, NULL, NULL);
    if (ev->i >= ev->j) lg->bad_order++;
    if (lg->sys && lg->xcb) odhs_system_get_positions(lg->sys, lg->xcb);
    return lg->stop_at && lg->n >= lg->stop_at;
}

/* ========================================================================== */
/* Scene: system + driver + solver + stepper, with scratch and statistics     */
/* ========================================================================== */
typedef struct {
    int dim;
    size_t n, nd;
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
    double lambda; /* mean diameter */
    double dt;     /* stepper dt (in tau) as set by us */
    double *F;     /* copy of the driver's fixed forces (NULL: none) */
    double *x, *r, *U, *cf, *cg; /* scratch: positions, radii, velocities, contact data */
    size_t ccap;
    int allow_stop; /* step_checked accepts ODHS_STOPPED */
    evlog log;
    /* worst values seen by check_invariants */
    double w_overlap, w_overlap_bf, w_negf, w_power, w_rigid;
    long nchecks;
} scene;

static void scene_reserve_contacts(scene *s, size_t nc)
{
    if (nc <= s->ccap) return;
    size_t c = s->ccap ? s->ccap : 64;
    while (c < nc) c *= 2;
    free(s->cf);
    free(s->cg);
    s->cf = xcalloc(c * 3, sizeof(double));
    s->cg = xcalloc(c * 3, sizeof(double));
    s->ccap = c;
}

/* takes ownership of sys */
static void scene_init(scene *s, odhs_system *sys, const char *solver)
{
    memset(s, 0, sizeof *s);
    s->sys = sys;
    s->dim = odhs_system_dim(sys);
    s->n = odhs_system_count(sys);
    s->nd = s->n * (size_t)s->dim;
    CHECK_OK(odhs_driver_create(&s->drv));
    CHECK_OK(odhs_solver_create_by_name(solver, &s->sol));
    CHECK_OK(odhs_stepper_create(sys, s->drv, s->sol, &s->st));
    /* this suite checks the paper's scheme (explicit Euler, fixed step dt,
     * correction every 10 steps) step by step; the adaptive default has its
     * own suite (check_adaptive.c) */
    CHECK_OK(odhs_stepper_set_integrator(s->st, ODHS_INTEGRATOR_EULER));
    s->x = xcalloc(s->nd, sizeof(double));
    s->U = xcalloc(s->nd, sizeof(double));
    s->r = xcalloc(s->n, sizeof(double));
    s->log.xcb = xcalloc(s->nd, sizeof(double));
    s->log.st = s->st;
    s->log.sys = sys;
    CHECK_OK(odhs_stepper_set_event_callback(s->st, ev_cb, &s->log));
    CHECK_OK(odhs_system_get_radii(sys, s->r));
    double lam = 0.0;
    for (size_t i = 0; i < s->n; ++i) lam += 2.0 * s->r[i];
    s->lambda = lam / (double)s->n;
    s->dt = 1e-3;
    scene_reserve_contacts(s, 64);
}

static void scene_free(scene *s)
{
    odhs_stepper_destroy(s->st);
    odhs_solver_destroy(s->sol);
    odhs_driver_destroy(s->drv);
    odhs_system_destroy(s->sys);
    free(s->F);
    free(s->x);
    free(s->U);
    free(s->r);
    free(s->cf);
    free(s->cg);
    free(s->log.e);
    free(s->log.xcb);
    memset(s, 0, sizeof *s);
}

static void scene_set_dt(scene *s, double dt)
{
    CHECK_ST(s->st, odhs_stepper_set_dt(s->st, dt));
    s->dt = dt;
}

/* fixed external forces (kept in s->F for the power checks) */
static void scene_set_forces(scene *s, const double *F)
{
    free(s->F);
    s->F = NULL;
    if (F) {
        s->F = xcalloc(s->nd, sizeof(double));
        memcpy(s->F, F, s->nd * sizeof(double));
    }
    CHECK_OK(odhs_driver_set_forces(s->drv, F ? s->n : 0, s->dim, F));
}

static void log_clear(scene *s) { s->log.n = 0; }

/* ---- independent brute-force overlap search ------------------------------- */
/* Largest (a_i + a_j - |R_ij|) / lambda over all pairs, with the minimum image
 * found by exhaustive search over the lattice images of tests/testutil.h. */
static double brute_overlap(scene *s, size_t *wi, size_t *wj)
{
    int dim = s->dim;
    double L[3] = {1, 1, 1}, gamma;
    CHECK_OK(odhs_system_get_box(s->sys, L));
    CHECK_OK(odhs_system_get_strain(s->sys, &gamma));
    CHECK_OK(odhs_system_get_positions(s->sys, s->x));
    /* all lattice shifts of tu_min_image_brute */
    int K = tu_brute_n0max(L, gamma), m2 = dim == 3 ? 2 : 0;
    size_t nsh = (size_t)(2 * K + 1) * 5u * (size_t)(2 * m2 + 1);
    double *sh = xcalloc(nsh * 3, sizeof(double));
    size_t q = 0;
    for (int n2 = -m2; n2 <= m2; ++n2)
        for (int n1 = -2; n1 <= 2; ++n1)
            for (int n0 = -K; n0 <= K; ++n0) {
                int nn[3] = {n0, n1, n2};
                tu_lattice_shift(dim, L, gamma, nn, sh + 3 * q);
                q++;
            }
    double worst = -INFINITY;
    for (size_t i = 0; i < s->n; ++i)
        for (size_t j = i + 1; j < s->n; ++j) {
            double d[3] = {0, 0, 0};
            for (int k = 0; k < dim; ++k) d[k] = s->x[j * dim + k] - s->x[i * dim + k];
            double best = INFINITY;
            for (size_t p = 0; p < nsh; ++p) {
                const double *v = sh + 3 * p;
                double a = d[0] + v[0], b = d[1] + v[1], c = dim == 3 ? d[2] + v[2] : 0.0;
                double s2 = a * a + b * b + c * c;
                if (s2 < best) best = s2;
            }
            double ov = (s->r[i] + s->r[j] - sqrt(best)) / s->lambda;
            if (ov > worst) {
                worst = ov;
                if (wi) *wi = i;
                if (wj) *wj = j;
            }
        }
    free(sh);
    return worst;
}

/* min/max force over temporary contacts of the stepper's network */
static void force_range(scene *s, double *fmin_out, double *fmax_out, size_t *nc_out)
{
    const odhs_network *net = odhs_stepper_network(s->st);
    size_t nc = odhs_network_count(net);
    scene_reserve_contacts(s, nc);
    double lo = INFINITY, hi = 0.0;
    if (nc) CHECK_OK(odhs_network_get_forces(net, s->cf));
    for (size_t c = 0; c < nc; ++c) {
        int kind;
        CHECK_OK(odhs_network_get_contact(net, c, NULL, NULL, &kind));
        hi = fmax(hi, fabs(s->cf[c]));
        if (kind == ODHS_CONTACT_TEMPORARY) lo = fmin(lo, s->cf[c]);
    }
    *fmin_out = nc ? lo : 0.0;
    *fmax_out = hi;
    if (nc_out) *nc_out = nc;
}

/* power scale: |D|, |P| and, with forces, xi0 |F|^2 (the dissipation without
 * contacts), so that states with U ~ 0 (e.g. two discs pressed together) are
 * compared on the driving scale and not on round-off */
static double power_scale(scene *s, double D, double P)
{
    double xi0, sc = fmax(fabs(D), fabs(P));
    CHECK_OK(odhs_driver_get_mobility(s->drv, &xi0));
    if (s->F) {
        double f2 = 0.0;
        for (size_t k = 0; k < s->nd; ++k) f2 += s->F[k] * s->F[k];
        sc += xi0 * f2;
    }
    return sc;
}

/* Rigidity (eqs. 4, 17): every contact keeps its length, (S U)_c + (S V_aff)_c
 * = 0 with (S V_aff)_c = |R_c| (gdot n_x n_y - c_eff), c_eff the isotropic
 * compression rate (kappa gdot under pressure control). Returns the worst
 * violation relative to the velocity scale max|U| + |G| lambda. */
static double rigidity_violation(scene *s)
{
    const odhs_network *net = odhs_stepper_network(s->st);
    size_t nc = odhs_network_count(net);
    if (nc == 0) return 0.0;
    int dim = s->dim;
    double gd, kappa;
    CHECK_OK(odhs_driver_get_shear_rate(s->drv, &gd));
    CHECK_OK(odhs_stepper_kappa(s->st, &kappa));
    double ceff = gd != 0.0 ? kappa * gd : kappa;
    scene_reserve_contacts(s, nc);
    double *nrm = s->cg;
    double *gap = xcalloc(nc, sizeof(double));
    CHECK_OK(odhs_stepper_nonaffine_velocities(s->st, s->U));
    CHECK_OK(odhs_network_get_normals(net, nrm));
    CHECK_OK(odhs_network_get_gaps(net, gap));
    double umax = 0.0;
    for (size_t k = 0; k < s->nd; ++k) umax = fmax(umax, fabs(s->U[k]));
    double xi0;
    CHECK_OK(odhs_driver_get_mobility(s->drv, &xi0));
    double vs = umax + (fabs(gd) + fabs(ceff)) * 2.0 * s->lambda, worst = 0.0;
    if (s->F)
        for (size_t k = 0; k < s->nd; ++k) vs = fmax(vs, xi0 * fabs(s->F[k]));
    for (size_t c = 0; c < nc; ++c) {
        size_t i, j;
        CHECK_OK(odhs_network_get_contact(net, c, &i, &j, NULL));
        double su = 0.0;
        for (int k = 0; k < dim; ++k) su += (s->U[j * dim + k] - s->U[i * dim + k]) * nrm[c * dim + k];
        double dist = gap[c] + s->r[i] + s->r[j];
        double aff = dist * (gd * nrm[c * dim] * nrm[c * dim + 1] - ceff);
        worst = fmax(worst, fabs(su + aff) / vs);
    }
    free(gap);
    return worst;
}

static void check_invariants(scene *s)
{
    double cgap, ov;
    CHECK_ST(s->st, odhs_stepper_errors(s->st, &cgap, &ov));
    ck_assert_msg(ov <= TOL_OVERLAP, "odhs_stepper_errors: overlap %.3g > %.1g", ov, TOL_OVERLAP);
    size_t bi = 0, bj = 0;
    double bo = brute_overlap(s, &bi, &bj);
    ck_assert_msg(bo <= TOL_OVERLAP, "brute force: pair (%zu,%zu) overlaps by %.3g mean diameters", bi, bj, bo);
    double flo, fhi;
    force_range(s, &flo, &fhi, NULL);
    ck_assert_msg(flo >= -TOL_NEGF * fhi, "negative contact force %.6g (max %.6g)", flo, fhi);
    double D, P;
    CHECK_ST(s->st, odhs_stepper_dissipation(s->st, &D));
    CHECK_ST(s->st, odhs_stepper_power(s->st, &P));
    double sc = power_scale(s, D, P);
    double pe = sc > 0.0 ? fabs(D - P) / sc : fabs(D - P);
    ck_assert_msg(pe <= TOL_POWER, "power balance: dissipation %.17g, power %.17g (rel %.3g)", D, P, pe);
    s->w_overlap = fmax(s->w_overlap, ov);
    s->w_overlap_bf = fmax(s->w_overlap_bf, bo);
    if (fhi > 0.0) s->w_negf = fmax(s->w_negf, -flo / fhi);
    s->w_power = fmax(s->w_power, pe);
    double rv = rigidity_violation(s);
    ck_assert_msg(rv <= 1e-9, "contacts change length: |S V| = %.3g of the velocity scale", rv);
    s->w_rigid = fmax(s->w_rigid, rv);
    s->nchecks++;
}

/* one step, then every invariant */
static int step_checked(scene *s, odhs_event *ev)
{
    int rc = odhs_stepper_step(s->st, ev);
    ck_assert_msg(rc == ODHS_OK || (s->allow_stop && rc == ODHS_STOPPED), "odhs_stepper_step returned %d (%s): %s", rc,
                  odhs_strerror(rc), odhs_stepper_errmsg(s->st));
    check_invariants(s);
    return rc;
}

static double cur_time(scene *s)
{
    double t;
    CHECK_OK(odhs_stepper_time(s->st, &t));
    return t;
}

static double cur_strain(scene *s)
{
    double g;
    CHECK_OK(odhs_stepper_strain(s->st, &g));
    return g;
}

static double cur_phi(scene *s)
{
    double phi;
    CHECK_OK(odhs_system_packing_fraction(s->sys, &phi));
    return phi;
}

/* checked steps until one step before phi, then the library lands on it */
static void run_phi_checked(scene *s, double phi)
{
    for (long k = 0; cur_phi(s) * (1.0 + 2.0 * s->dim * s->dt) < phi; ++k) {
        ck_assert_msg(k < 10000000, "compression does not progress");
        step_checked(s, NULL);
    }
    CHECK_ST(s->st, odhs_stepper_run_until_packing_fraction(s->st, phi));
    check_invariants(s);
}

/* checked steps until one step before the strain target (shear rate > 0, time
 * unit 1/gammadot so that a step is dt in strain), then the library lands */
static void run_strain_checked(scene *s, double gamma)
{
    for (long k = 0; cur_strain(s) + 1.5 * s->dt < gamma; ++k) {
        ck_assert_msg(k < 10000000, "shear does not progress");
        step_checked(s, NULL);
    }
    CHECK_ST(s->st, odhs_stepper_run_until_strain(s->st, gamma));
    check_invariants(s);
}

static void run_time_checked(scene *s, double t)
{
    double tau;
    CHECK_OK(odhs_driver_time_unit(s->drv, s->sys, &tau));
    for (long k = 0; cur_time(s) + 1.5 * s->dt * tau < t; ++k) {
        ck_assert_msg(k < 10000000, "time does not progress");
        step_checked(s, NULL);
    }
    CHECK_ST(s->st, odhs_stepper_run_until_time(s->st, t));
    check_invariants(s);
}

/* ---- the dense scene -------------------------------------------------------
 * 50:50 bidisperse (r = 0.5, ratio 1.4, 3% polydispersity), random placement
 * (phi 0.45 in 2D, 0.30 in 3D), compression at rate 1 to phi with checked
 * steps, landing on phi (asserted to 1e-12), drift correction. Afterwards the
 * driver is reset to no flow and the event log is cleared. */
static void scene_dense(scene *s, int dim, size_t n, double phi, uint64_t seed, const char *solver)
{
    odhs_system *sys;
    CHECK_OK(odhs_system_create(dim, n, &sys));
    CHECK_OK(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, seed));
    CHECK_OK(odhs_system_place_random(sys, dim == 2 ? 0.45 : 0.30, seed));
    scene_init(s, sys, solver);
    CHECK_OK(odhs_driver_set_compression_rate(s->drv, 1.0));
    CHECK_ST(s->st, odhs_stepper_reset(s->st));
    run_phi_checked(s, phi);
    double ph = cur_phi(s);
    ck_assert_msg(fabs(ph - phi) <= 1e-12 * phi, "compression landed on phi = %.17g, target %.17g (rel %.3g)", ph,
                  phi, fabs(ph - phi) / phi);
    CHECK_ST(s->st, odhs_stepper_correct(s->st));
    check_invariants(s);
    CHECK_OK(odhs_driver_set_compression_rate(s->drv, 0.0));
    log_clear(s);
}

/* a second scene on a copy of src's current configuration */
static void scene_clone(scene *dst, const scene *src, const char *solver)
{
    odhs_system *sys;
    CHECK_OK(odhs_system_clone(src->sys, &sys));
    scene_init(dst, sys, solver);
}

static void random_forces(size_t nd, double *F, tu_rng *rng, double scale)
{
    for (size_t k = 0; k < nd; ++k) F[k] = scale * tu_uniform_in(rng, -1.0, 1.0);
}

/* largest minimum-image distance between the positions of two scenes with the
 * same box, in mean diameters */
static double max_position_difference(scene *a, scene *b)
{
    int dim = a->dim;
    double L[3] = {1, 1, 1}, gamma;
    double *xb = xcalloc(b->nd, sizeof(double));
    CHECK_OK(odhs_system_get_box(a->sys, L));
    CHECK_OK(odhs_system_get_strain(a->sys, &gamma));
    CHECK_OK(odhs_system_get_positions(a->sys, a->x));
    CHECK_OK(odhs_system_get_positions(b->sys, xb));
    double worst = 0.0;
    for (size_t i = 0; i < a->n; ++i) {
        double d[3] = {0, 0, 0}, m[3];
        for (int k = 0; k < dim; ++k) d[k] = xb[i * dim + k] - a->x[i * dim + k];
        double s2 = tu_min_image_brute(dim, L, gamma, d, m, NULL);
        worst = fmax(worst, sqrt(s2) / a->lambda);
    }
    free(xb);
    return worst;
}

static double gap_of_pair(scene *s, size_t i, size_t j)
{
    double rij[3], dist;
    CHECK_OK(odhs_system_separation(s->sys, i, j, rij, &dist, NULL));
    return dist - (s->r[i] + s->r[j]);
}

/* ========================================================================== */
/* 0. The checkers themselves can fail                                        */
/* ========================================================================== */
/* A pair overlapping by 5e-11 of its contact distance (below the library's
 * 1e-10 acceptance, above TOL_OVERLAP), once directly and once only through
 * a Lees-Edwards image: both the brute-force search and odhs_stepper_errors
 * must report it. */
START_TEST(test_checkers_detect_overlap)
{
    for (int img = 0; img <= 1; ++img) {
        odhs_system *sys;
        CHECK_OK(odhs_system_create(2, 2, &sys));
        double L[2] = {10, 10}, r[2] = {0.5, 0.5}, gamma = img ? 0.3 : 0.0, ov = 5e-11;
        /* img = 0: both inside the box; img = 1: particle 1 is the image of
         * x0 + R under b = (gamma Ly, Ly), i.e. stored near the top edge */
        double x[4] = {img ? 1.0 : 5.0, img ? 0.2 : 5.2, 0, 0};
        double R[2] = {0.6 * (1.0 - ov), -0.8 * (1.0 - ov)};
        x[2] = x[0] + R[0] + (img ? gamma * L[1] : 0.0);
        x[3] = x[1] + R[1] + (img ? L[1] : 0.0);
        CHECK_OK(odhs_system_set_configuration(sys, L, gamma, r, x));
        scene s;
        scene_init(&s, sys, "dense");
        size_t bi = 9, bj = 9;
        double bo = brute_overlap(&s, &bi, &bj), lo;
        CHECK_OK(odhs_stepper_errors(s.st, NULL, &lo));
        ck_assert_msg(fabs(bo - ov) <= 1e-14 && bi == 0 && bj == 1, "brute force found overlap %.6g (image %d)", bo,
                      img);
        ck_assert_msg(fabs(lo - ov) <= 1e-14, "odhs_stepper_errors found overlap %.6g (image %d)", lo, img);
        ck_assert(bo > TOL_OVERLAP && lo > TOL_OVERLAP);
        scene_free(&s);
    }
}
END_TEST

/* ========================================================================== */
/* 1. Two discs/spheres: analytic collision, force, opening                   */
/* ========================================================================== */
/* Two particles of radius 0.5 in a box of edge 10, centres on a line along x
 * with gap g, forces +Fvec on 0 and -Fvec on 1, Fvec = F (cos a, sin a cos b,
 * sin a sin b). Before contact the separation moves as d(t) = (1+g) e_x - w t
 * Fhat with w = 2 xi0 F; contact when |d| = 1. */
static void two_body_scene(scene *s, int dim, double g, const double *Fvec, double xi0, const char *solver)
{
    odhs_system *sys;
    CHECK_OK(odhs_system_create(dim, 2, &sys));
    double L[3] = {10, 10, 10}, r[2] = {0.5, 0.5};
    double x[6] = {5.0 - 0.5 * (1.0 + g), 5.0, 5.0, 5.0 + 0.5 * (1.0 + g), 5.0, 5.0};
    if (dim == 2) {
        x[2] = x[3];
        x[3] = 5.0;
    }
    CHECK_OK(odhs_system_set_configuration(sys, L, 0.0, r, x));
    scene_init(s, sys, solver);
    CHECK_OK(odhs_driver_set_mobility(s->drv, xi0));
    double F[6];
    for (int k = 0; k < dim; ++k) {
        F[k] = Fvec[k];
        F[dim + k] = -Fvec[k];
    }
    scene_set_forces(s, F);
    scene_set_dt(s, 1e-3);
    CHECK_ST(s->st, odhs_stepper_reset(s->st));
}

/* step until the event log holds at least one event (bounded) */
static void step_until_event(scene *s, long max_steps)
{
    size_t n0 = s->log.n;
    long k = 0;
    while (s->log.n == n0) {
        ck_assert_msg(++k <= max_steps, "no event within %ld steps", max_steps);
        step_checked(s, NULL);
    }
}

static void get_contact_normal(scene *s, double *n)
{
    const odhs_network *net = odhs_stepper_network(s->st);
    ck_assert_uint_eq(odhs_network_count(net), 1);
    CHECK_OK(odhs_network_get_normals(net, n));
}

static double contact_force(scene *s)
{
    const odhs_network *net = odhs_stepper_network(s->st);
    ck_assert_uint_eq(odhs_network_count(net), 1);
    double f;
    CHECK_OK(odhs_network_get_forces(net, &f));
    return f;
}

static void test_two_body_head_on(int dim)
{
    const double xi0 = 0.7, F = 1.3, g = 0.3;
    double Fvec[3] = {F, 0, 0};
    scene s;
    two_body_scene(&s, dim, g, Fvec, xi0, "dense");
    double tau;
    CHECK_OK(odhs_driver_time_unit(s.drv, s.sys, &tau));
    ck_assert_msg(fabs(tau - 1.0 / (xi0 * F)) <= 1e-14 * tau, "tau = %.17g, expected lambda/(xi0 f_rms) = %.17g", tau,
                  1.0 / (xi0 * F));

    /* approach: velocities +-xi0 F before contact */
    CHECK_ST(s.st, odhs_stepper_nonaffine_velocities(s.st, s.U));
    ck_assert_msg(fabs(s.U[0] - xi0 * F) <= 1e-15 && fabs(s.U[dim] + xi0 * F) <= 1e-15, "approach velocity %.17g",
                  s.U[0]);

    step_until_event(&s, 100000);
    ck_assert_uint_eq(s.log.n, 1);
    evrec e = s.log.e[0];
    double tc = g / (2.0 * xi0 * F);
    ck_assert_int_eq(e.kind, ODHS_EVENT_COLLISION);
    ck_assert_uint_eq(e.i, 0);
    ck_assert_uint_eq(e.j, 1);
    ck_assert_msg(fabs(e.time - tc) <= 1e-12 * tc, "collision at t = %.17g, analytic %.17g (rel %.3g)", e.time, tc,
                  fabs(e.time - tc) / tc);
    ck_assert_msg(fabs(cur_time(&s) - tc) <= 1e-12 * tc, "stepper time %.17g at the collision", cur_time(&s));
    ck_assert_msg(fabs(gap_of_pair(&s, 0, 1)) <= 1e-14, "gap at contact %.3g", gap_of_pair(&s, 0, 1));
    double f = contact_force(&s);
    ck_assert_msg(fabs(f - F) <= 1e-12 * F, "contact force %.17g, expected F = %.17g", f, F);
    CHECK_ST(s.st, odhs_stepper_nonaffine_velocities(s.st, s.U));
    double V[6];
    CHECK_ST(s.st, odhs_stepper_velocities(s.st, V));
    for (size_t k = 0; k < s.nd; ++k) {
        ck_assert_msg(fabs(s.U[k]) <= 1e-12 * xi0 * F, "U[%zu] = %.3g after contact", k, s.U[k]);
        ck_assert_msg(fabs(V[k]) <= 1e-12 * xi0 * F, "V[%zu] = %.3g after contact", k, V[k]);
    }
    double D;
    CHECK_OK(odhs_stepper_dissipation(s.st, &D));
    ck_assert_msg(D <= 1e-24 * xi0 * F * F, "dissipation %.3g after contact", D);

    /* pressed together: nothing moves, nothing happens */
    double x0[6];
    CHECK_OK(odhs_system_get_positions(s.sys, x0));
    for (int k = 0; k < 5; ++k) step_checked(&s, NULL);
    CHECK_OK(odhs_system_get_positions(s.sys, s.x));
    for (size_t k = 0; k < s.nd; ++k)
        ck_assert_msg(fabs(s.x[k] - x0[k]) <= 1e-14, "pressed pair moved by %.3g", s.x[k] - x0[k]);
    ck_assert_uint_eq(s.log.n, 1);
    f = contact_force(&s);
    ck_assert_msg(fabs(f - F) <= 1e-12 * F, "contact force %.17g after 5 steps", f);

    /* reverse the forces: the contact opens at once, then separation at 2 xi0 F */
    double Frev[6];
    for (int k = 0; k < dim; ++k) {
        Frev[k] = -Fvec[k];
        Frev[dim + k] = Fvec[k];
    }
    scene_set_forces(&s, Frev);
    double t0 = cur_time(&s);
    CHECK_OK(odhs_system_get_positions(s.sys, x0));
    odhs_event ev;
    step_checked(&s, &ev);
    double t1 = cur_time(&s);
    double x1[6], xcb[6];
    CHECK_OK(odhs_system_get_positions(s.sys, x1));
    memcpy(xcb, s.log.xcb, s.nd * sizeof(double));
    ck_assert_uint_eq(s.log.n, 2);
    evrec eo = s.log.e[1];
    ck_assert_int_eq(ev.kind, ODHS_EVENT_OPENING);
    ck_assert_int_eq(eo.kind, ODHS_EVENT_OPENING);
    ck_assert_uint_eq(eo.i, 0);
    ck_assert_uint_eq(eo.j, 1);
    ck_assert_uint_eq(odhs_network_count(odhs_stepper_network(s.st)), 0);
    CHECK_ST(s.st, odhs_stepper_nonaffine_velocities(s.st, s.U));
    for (int k = 0; k < dim; ++k) {
        ck_assert_msg(fabs(s.U[k] - xi0 * Frev[k]) <= 1e-14, "U0[%d] = %.17g after opening", k, s.U[k]);
        ck_assert_msg(fabs(s.U[dim + k] - xi0 * Frev[dim + k]) <= 1e-14, "U1[%d] = %.17g after opening", k,
                      s.U[dim + k]);
    }
    /* separation grows at 2 xi0 F from the opening time t0 */
    double w = 2.0 * xi0 * F;
    for (int k = 0; k < 5; ++k) {
        step_checked(&s, NULL);
        double t = cur_time(&s), gp = gap_of_pair(&s, 0, 1);
        ck_assert_msg(fabs(gp - w * (t - t0)) <= 1e-12 * w * (t - t0) + 1e-14,
                      "gap %.17g at t - t0 = %.17g, expected 2 xi0 F (t - t0) = %.17g", gp, t - t0, w * (t - t0));
    }
    ck_assert_uint_eq(s.log.n, 2);
    /* the opening happened at t0, with no motion: event time, the stepper's
     * time and the positions after that step are those before it */
    double dx = 0.0, dcb = 0.0;
    for (size_t k = 0; k < s.nd; ++k) {
        dx = fmax(dx, fabs(x1[k] - x0[k]));
        dcb = fmax(dcb, fabs(xcb[k] - x0[k]));
    }
    fprintf(stderr,
            "[stepper] head-on d=%d: collision rel err %.2e, force rel err %.2e; reversal step: event time - t0 = "
            "%.3g (%.3g dt tau), step motion %.3g, callback positions moved %.3g\n",
            dim, fabs(e.time - tc) / tc, fabs(f - F) / F, eo.time - t0, (eo.time - t0) / (s.dt * tau), dx, dcb);
    ck_assert_msg(fabs(eo.time - t0) <= 1e-12 * t0 && dcb <= 1e-14 && dx <= 1e-14 && fabs(t1 - t0) <= 1e-12 * t0,
                  "opening on force reversal: expected no motion at the event, got event time - t0 = %.3g (%.3g dt "
                  "tau), positions seen by the callback moved %.3g, the step moved the particles %.3g and the time "
                  "%.3g",
                  eo.time - t0, (eo.time - t0) / (s.dt * tau), dcb, dx, t1 - t0);
    scene_free(&s);
}

START_TEST(test_two_discs_head_on) { test_two_body_head_on(2); }
END_TEST

START_TEST(test_two_spheres_head_on) { test_two_body_head_on(3); }
END_TEST

/* Oblique: Fvec at angle a to the line of centres. Collision at
 *   t_c = [d0 c - sqrt(d0^2 c^2 - (d0^2 - 1))] / w,   c = cos a, w = 2 xi0 F,
 * with normal n = d(t_c). In contact: f = n.Fvec (normal component), U_0 =
 * xi0 (Fvec - f n) = -U_1 (tangential sliding, relative speed 2 xi0 |F x n|).
 * The angle phi between n and Fvec then obeys phi' = w sin(phi): the pair
 * rolls over until phi = pi/2, where f = 0 and the contact opens, at
 *   t_open = t_c + ln(1 / tan(phi_c / 2)) / w. */
static double test_two_body_oblique(int dim, double a, double b, double dt)
{
    const double xi0 = 0.7, F = 1.3, g = 0.2, d0 = 1.0 + g;
    double Fvec[3] = {F * cos(a), F * sin(a) * cos(b), F * sin(a) * sin(b)};
    double Fhat[3] = {cos(a), sin(a) * cos(b), sin(a) * sin(b)};
    scene s;
    two_body_scene(&s, dim, g, Fvec, xi0, "dense");
    scene_set_dt(&s, dt);
    double w = 2.0 * xi0 * F, c = cos(a);
    double tc = (d0 * c - sqrt(d0 * d0 * c * c - (d0 * d0 - 1.0))) / w;
    double n_exact[3];
    for (int k = 0; k < 3; ++k) n_exact[k] = (k == 0 ? d0 : 0.0) - w * tc * Fhat[k];

    step_until_event(&s, 100000);
    ck_assert_uint_eq(s.log.n, 1);
    evrec e = s.log.e[0];
    ck_assert_int_eq(e.kind, ODHS_EVENT_COLLISION);
    ck_assert_uint_eq(e.i, 0);
    ck_assert_uint_eq(e.j, 1);
    /* ~1e-12 at dt = 1e-3; more steps (smaller dt) accumulate more round-off
     * in the positions, and the oblique approach amplifies it by 1/(n.Fhat) */
    double ttol = dt >= 1e-3 ? 1e-12 : 1e-11;
    ck_assert_msg(fabs(e.time - tc) <= ttol * tc, "oblique collision at %.17g, analytic %.17g (rel %.3g)", e.time, tc,
                  fabs(e.time - tc) / tc);
    double n[3] = {0, 0, 0};
    get_contact_normal(&s, n);
    for (int k = 0; k < dim; ++k)
        ck_assert_msg(fabs(n[k] - n_exact[k]) <= ttol, "contact normal[%d] = %.17g, analytic %.17g", k, n[k], n_exact[k]);

    /* in contact: f = n.F, tangential sliding */
    long steps = 0;
    double t_open = NAN, phi_c = NAN;
    double worst_f = 0.0, worst_u = 0.0;
    for (;;) {
        if (odhs_network_count(odhs_stepper_network(s.st)) == 0) break;
        get_contact_normal(&s, n);
        double nF = 0.0;
        for (int k = 0; k < dim; ++k) nF += n[k] * Fvec[k];
        double f = contact_force(&s);
        worst_f = fmax(worst_f, fabs(f - nF) / F);
        CHECK_ST(s.st, odhs_stepper_nonaffine_velocities(s.st, s.U));
        double vn = 0.0, ut2 = 0.0;
        for (int k = 0; k < dim; ++k) {
            double ut = xi0 * (Fvec[k] - nF * n[k]);
            worst_u = fmax(worst_u, fabs(s.U[k] - ut) / (xi0 * F));
            worst_u = fmax(worst_u, fabs(s.U[dim + k] + ut) / (xi0 * F));
            vn += (s.U[dim + k] - s.U[k]) * n[k];
            ut2 += ut * ut;
        }
        worst_u = fmax(worst_u, fabs(vn) / (xi0 * F));
        if (steps == 0) {
            double cosphi = nF / F;
            phi_c = acos(cosphi);
            /* relative sliding speed 2 xi0 |F| sin(phi) */
            ck_assert_msg(fabs(2.0 * sqrt(ut2) - w * sin(phi_c)) <= 1e-12 * w, "sliding speed %.17g, analytic %.17g",
                          2.0 * sqrt(ut2), w * sin(phi_c));
        }
        ck_assert_msg(worst_f <= 1e-12, "contact force differs from n.F by %.3g F (step %ld)", worst_f, steps);
        ck_assert_msg(worst_u <= 1e-12, "velocity differs from the tangential projection by %.3g xi0 F (step %ld)",
                      worst_u, steps);
        ck_assert_msg(++steps < 200000, "the pair never opened");
        step_checked(&s, NULL);
    }
    ck_assert_uint_eq(s.log.n, 2);
    evrec eo = s.log.e[1];
    ck_assert_int_eq(eo.kind, ODHS_EVENT_OPENING);
    ck_assert_uint_eq(eo.i, 0);
    ck_assert_uint_eq(eo.j, 1);
    t_open = tc + log(1.0 / tan(0.5 * phi_c)) / w;
    double tau;
    CHECK_OK(odhs_driver_time_unit(s.drv, s.sys, &tau));
    /* Euler steps of dt tau: the opening is found within O(dt) of the exact
     * rolling solution (the caller checks the convergence order) */
    double err = (eo.time - t_open) / (t_open - tc);
    ck_assert_msg(fabs(eo.time - t_open) <= 2.0 * dt * tau,
                  "opening at %.10g, analytic %.10g (%.3g steps of dt tau off, dt %g)", eo.time, t_open,
                  (eo.time - t_open) / (dt * tau), dt);
    fprintf(stderr,
            "[stepper] oblique d=%d: collision rel err %.2e, |f - n.F| <= %.2e F, |U - U_t| <= %.2e xi0 F over %ld "
            "steps (dt %g), opening at %.8g vs analytic %.8g (rel %.2e)\n",
            dim, fabs(e.time - tc) / tc, worst_f, worst_u, steps, dt, eo.time, t_open, err);
    /* after opening: free motion */
    CHECK_ST(s.st, odhs_stepper_nonaffine_velocities(s.st, s.U));
    for (int k = 0; k < dim; ++k)
        ck_assert_msg(fabs(s.U[k] - xi0 * Fvec[k]) <= 1e-14 && fabs(s.U[dim + k] + xi0 * Fvec[k]) <= 1e-14,
                      "free velocity after opening wrong: %.17g", s.U[k]);
    scene_free(&s);
    return err;
}

static void oblique_converges(int dim, double a, double b)
{
    double e1 = test_two_body_oblique(dim, a, b, 1e-3);
    double e2 = test_two_body_oblique(dim, a, b, 2.5e-4);
    double e3 = test_two_body_oblique(dim, a, b, 6.25e-5);
    fprintf(stderr, "[stepper] oblique d=%d: opening time error %.3e, %.3e, %.3e for dt = 1e-3, 2.5e-4, 6.25e-5\n", dim,
            e1, e2, e3);
    /* O(dt): a 16 times smaller step gives a much smaller error */
    ck_assert_msg(fabs(e3) < 0.25 * fabs(e1),
                  "opening time does not converge with dt: %.3e, %.3e, %.3e", e1, e2, e3);
}

START_TEST(test_two_discs_oblique) { oblique_converges(2, 0.4, 0.0); }
END_TEST

START_TEST(test_two_spheres_oblique) { oblique_converges(3, 0.5, 1.1); }
END_TEST

/* ========================================================================== */
/* 2/3. Invariants and power balance on the dense scene                       */
/* ========================================================================== */
/* shear: D == P == sigma_xy gammadot Omega at every step */
static void power_shear(int dim, size_t n, double phi, uint64_t seed, const char *solver, long nsteps,
                        double gdot)
{
    scene s;
    scene_dense(&s, dim, n, phi, seed, solver);
    CHECK_OK(odhs_driver_set_shear_rate(s.drv, gdot));
    CHECK_ST(s.st, odhs_stepper_reset(s.st));
    double worst = 0.0;
    long loaded = 0;
    for (long k = 0; k < nsteps; ++k) {
        step_checked(&s, NULL);
        double D, P, sxy, vol;
        CHECK_OK(odhs_stepper_dissipation(s.st, &D));
        CHECK_OK(odhs_stepper_power(s.st, &P));
        CHECK_OK(odhs_stepper_shear_stress(s.st, &sxy));
        CHECK_OK(odhs_system_volume(s.sys, &vol));
        double Ps = sxy * gdot * vol;
        double sc = fmax(fabs(D), fabs(Ps));
        double e1 = sc > 0 ? fabs(D - Ps) / sc : 0.0, e2 = sc > 0 ? fabs(D - P) / sc : 0.0;
        ck_assert_msg(e1 <= TOL_POWER, "step %ld: dissipation %.17g != sigma_xy gdot Omega %.17g (rel %.3g)", k, D, Ps,
                      e1);
        ck_assert_msg(e2 <= TOL_POWER, "step %ld: dissipation %.17g != power %.17g (rel %.3g)", k, D, P, e2);
        if (D > 0) loaded++;
        worst = fmax(worst, fmax(e1, e2));
    }
    ck_assert_msg(loaded > nsteps / 2, "only %ld of %ld steps carried stress", loaded, nsteps);
    fprintf(stderr,
            "[stepper] power/shear d=%d N=%zu %s: worst rel %.2e, overlap lib %.2e bf %.2e, negf %.2e, |SV| %.2e, %ld "
            "checks\n",
            dim, n, solver, worst, s.w_overlap, s.w_overlap_bf, s.w_negf, s.w_rigid, s.nchecks);
    scene_free(&s);
}

/* forces: D == P == sum_k F_k . U_k at every step */
static void power_forces(int dim, size_t n, double phi, uint64_t seed, const char *solver, long nsteps)
{
    scene s;
    scene_dense(&s, dim, n, phi, seed, solver);
    tu_rng rng;
    tu_rng_seed(&rng, seed * 7 + 1);
    double *F = xcalloc(s.nd, sizeof(double));
    random_forces(s.nd, F, &rng, 1.0);
    scene_set_forces(&s, F);
    CHECK_ST(s.st, odhs_stepper_reset(s.st));
    double worst = 0.0;
    for (long k = 0; k < nsteps; ++k) {
        step_checked(&s, NULL);
        double D, P, xi0;
        CHECK_OK(odhs_stepper_dissipation(s.st, &D));
        CHECK_OK(odhs_stepper_power(s.st, &P));
        CHECK_OK(odhs_driver_get_mobility(s.drv, &xi0));
        CHECK_OK(odhs_stepper_nonaffine_velocities(s.st, s.U));
        double FU = 0.0, U2 = 0.0;
        for (size_t q = 0; q < s.nd; ++q) {
            FU += F[q] * s.U[q];
            U2 += s.U[q] * s.U[q];
        }
        U2 /= xi0;
        double sc = fmax(fabs(D), fabs(FU));
        double e1 = fabs(D - FU) / sc, e2 = fabs(D - P) / sc, e3 = fabs(D - U2) / sc;
        ck_assert_msg(e1 <= TOL_POWER, "step %ld: dissipation %.17g != F.U %.17g (rel %.3g)", k, D, FU, e1);
        ck_assert_msg(e2 <= TOL_POWER, "step %ld: dissipation %.17g != power %.17g (rel %.3g)", k, D, P, e2);
        ck_assert_msg(e3 <= 1e-13, "step %ld: dissipation %.17g != |U|^2/xi0 %.17g", k, D, U2);
        worst = fmax(worst, fmax(e1, e2));
    }
    fprintf(stderr,
            "[stepper] power/forces d=%d N=%zu %s: worst rel %.2e, overlap lib %.2e bf %.2e, negf %.2e, |SV| %.2e\n",
            dim, n, solver, worst, s.w_overlap, s.w_overlap_bf, s.w_negf, s.w_rigid);
    free(F);
    scene_free(&s);
}

START_TEST(test_power_shear_2d) { power_shear(2, 64, 0.78, 11, "cg", 300, 1.0); }
END_TEST

START_TEST(test_power_shear_2d_dense) { power_shear(2, 64, 0.78, 12, "dense", 200, 2.5); }
END_TEST

START_TEST(test_power_forces_2d) { power_forces(2, 64, 0.78, 13, "cg", 300); }
END_TEST

START_TEST(test_power_shear_3d) { power_shear(3, 48, 0.55, 21, "cg", 200, 1.0); }
END_TEST

START_TEST(test_power_forces_3d) { power_forces(3, 48, 0.55, 22, "cg", 200); }
END_TEST

/* ========================================================================== */
/* 4. Rate invariance                                                         */
/* ========================================================================== */
static void compare_runs(scene *ref, scene *o, const char *what, double scale)
{
    double dx = max_position_difference(ref, o);
    ck_assert_msg(dx <= 1e-9, "%s %.0e: positions differ by %.3g mean diameters", what, scale, dx);
    ck_assert_msg(ref->log.n == o->log.n, "%s %.0e: %zu events vs %zu", what, scale, o->log.n, ref->log.n);
    for (size_t k = 0; k < ref->log.n; ++k) {
        const evrec *a = &ref->log.e[k], *b = &o->log.e[k];
        ck_assert_msg(a->kind == b->kind && a->i == b->i && a->j == b->j,
                      "%s %.0e: event %zu is (%d,%zu,%zu), reference (%d,%zu,%zu)", what, scale, k, b->kind, b->i,
                      b->j, a->kind, a->i, a->j);
    }
    fprintf(stderr, "[stepper] rate invariance %s x %.0e: max position difference %.2e lambda, %zu events equal\n",
            what, scale, dx, ref->log.n);
}

START_TEST(test_rate_invariance_shear)
{
    scene base;
    scene_dense(&base, 2, 64, 0.78, 31, "dense");
    const double gd[3] = {1.0, 1e-8, 1e8};
    scene run[3];
    for (int q = 0; q < 3; ++q) {
        scene_clone(&run[q], &base, "dense");
        CHECK_OK(odhs_driver_set_shear_rate(run[q].drv, gd[q]));
        CHECK_ST(run[q].st, odhs_stepper_reset(run[q].st));
        /* run_until_strain with checked steps; a step is dt in strain */
        double gamma = 0.05;
        for (long k = 0; cur_strain(&run[q]) + 1.5 * run[q].dt < gamma; ++k) step_checked(&run[q], NULL);
        CHECK_ST(run[q].st, odhs_stepper_run_until_strain(run[q].st, gamma));
        check_invariants(&run[q]);
        ck_assert_msg(fabs(cur_strain(&run[q]) - gamma) <= 1e-12 * gamma, "strain %.17g", cur_strain(&run[q]));
        double t = cur_time(&run[q]);
        ck_assert_msg(fabs(t * gd[q] - gamma) <= 1e-12 * gamma, "time %.17g at gammadot %.0e", t, gd[q]);
        /* event strains agree too */
        if (q > 0) {
            compare_runs(&run[0], &run[q], "gammadot", gd[q]);
            for (size_t k = 0; k < run[0].log.n; ++k)
                ck_assert_msg(fabs(run[0].log.e[k].strain - run[q].log.e[k].strain) <= 1e-9,
                              "event %zu at strain %.17g vs %.17g", k, run[q].log.e[k].strain,
                              run[0].log.e[k].strain);
        }
    }
    ck_assert_msg(run[0].log.n > 0, "no events: the test would be vacuous");
    for (int q = 0; q < 3; ++q) scene_free(&run[q]);
    scene_free(&base);
}
END_TEST

/* Changing the shear rate between steps keeps the trajectory in strain: the
 * rates 1 and 2 alternate from step to step and every quantity scales by a
 * power of two, so the run must equal the constant-rate one bit for bit.
 * (0.2.3 restarted a step repeated shorter right after a change from the
 * forces and flow of the old rate: the relocated chord moved with it.) */
START_TEST(test_rate_changes)
{
    scene base;
    scene_dense(&base, 2, 64, 0.78, 33, "dense");
    scene run[2];
    for (int q = 0; q < 2; ++q) {
        scene_clone(&run[q], &base, "dense");
        /* the library's default scheme, which repeats steps shorter */
        CHECK_OK(odhs_stepper_set_integrator(run[q].st, ODHS_INTEGRATOR_HEUN));
        CHECK_OK(odhs_driver_set_shear_rate(run[q].drv, 1.0));
        CHECK_ST(run[q].st, odhs_stepper_reset(run[q].st));
        for (int k = 1; cur_strain(&run[q]) < 0.2; ++k) {
            if (q == 1) CHECK_OK(odhs_driver_set_shear_rate(run[q].drv, k % 2 ? 2.0 : 1.0));
            CHECK_ST(run[q].st, odhs_stepper_step(run[q].st, NULL));
        }
        check_invariants(&run[q]);
    }
    double dx = max_position_difference(&run[0], &run[1]);
    uint64_t c0, c1;
    odhs_stepper_counts(run[0].st, NULL, &c0, NULL);
    odhs_stepper_counts(run[1].st, NULL, &c1, NULL);
    fprintf(stderr, "[stepper] rate changes 1 <-> 2: max position difference %.2e lambda, %llu / %llu collisions\n",
            dx, (unsigned long long)c0, (unsigned long long)c1);
    ck_assert_msg(c0 > 0 && c0 == c1 && dx == 0.0, "rate changes: position difference %g, collisions %llu vs %llu",
                  dx, (unsigned long long)c1, (unsigned long long)c0);
    for (int q = 0; q < 2; ++q) scene_free(&run[q]);
    scene_free(&base);
}
END_TEST

START_TEST(test_rate_invariance_mobility)
{
    scene base;
    scene_dense(&base, 2, 64, 0.78, 32, "dense");
    const double xi[3] = {1.0, 1e-8, 1e8};
    scene run[3];
    double sig0 = 0.0;
    for (int q = 0; q < 3; ++q) {
        scene_clone(&run[q], &base, "dense");
        CHECK_OK(odhs_driver_set_shear_rate(run[q].drv, 1.0));
        CHECK_OK(odhs_driver_set_mobility(run[q].drv, xi[q]));
        CHECK_ST(run[q].st, odhs_stepper_reset(run[q].st));
        run_strain_checked(&run[q], 0.05);
        /* forces scale as lambda gammadot / xi0: sigma xi0 is invariant */
        double sxy;
        CHECK_OK(odhs_stepper_shear_stress(run[q].st, &sxy));
        if (q == 0) sig0 = sxy;
        else {
            compare_runs(&run[0], &run[q], "xi0", xi[q]);
            ck_assert_msg(fabs(sxy * xi[q] - sig0) <= 1e-8 * fabs(sig0), "sigma xi0 = %.17g vs %.17g", sxy * xi[q],
                          sig0);
        }
    }
    ck_assert_msg(run[0].log.n > 0, "no events: the test would be vacuous");
    for (int q = 0; q < 3; ++q) scene_free(&run[q]);
    scene_free(&base);
}
END_TEST

START_TEST(test_rate_invariance_forces)
{
    scene base;
    scene_dense(&base, 2, 64, 0.78, 33, "dense");
    const double fs[3] = {1.0, 1e-8, 1e8};
    tu_rng rng;
    tu_rng_seed(&rng, 3301);
    double *F1 = xcalloc(base.nd, sizeof(double)), *F = xcalloc(base.nd, sizeof(double));
    random_forces(base.nd, F1, &rng, 1.0);
    scene run[3];
    double tau0 = 0.0;
    for (int q = 0; q < 3; ++q) {
        scene_clone(&run[q], &base, "dense");
        for (size_t k = 0; k < base.nd; ++k) F[k] = fs[q] * F1[k];
        scene_set_forces(&run[q], F);
        CHECK_ST(run[q].st, odhs_stepper_reset(run[q].st));
        double tau;
        CHECK_OK(odhs_driver_time_unit(run[q].drv, run[q].sys, &tau));
        if (q == 0) tau0 = tau;
        ck_assert_msg(fabs(tau * fs[q] - tau0) <= 1e-14 * tau0, "tau %.17g does not scale as 1/F", tau);
        run_time_checked(&run[q], 0.1 * tau);
        ck_assert_msg(fabs(cur_time(&run[q]) - 0.1 * tau) <= 1e-12 * 0.1 * tau, "time %.17g, target %.17g",
                      cur_time(&run[q]), 0.1 * tau);
        if (q > 0) compare_runs(&run[0], &run[q], "F_ext", fs[q]);
    }
    ck_assert_msg(run[0].log.n > 0, "no events: the test would be vacuous");
    for (int q = 0; q < 3; ++q) scene_free(&run[q]);
    scene_free(&base);
    free(F1);
    free(F);
}
END_TEST

/* ========================================================================== */
/* 5. Rewiring uniqueness (Appendix A) by brute force over subsets of Gamma   */
/* ========================================================================== */
/* Cluster of n particles in a large box: particle 0 in the middle, each new one
 * touching one or two earlier ones exactly (two-sphere intersection), rejected
 * if it overlaps or nearly touches (1e-12 < gap/sigma < 1e-3) anything else.
 * Returns 1 on success. */
static int build_cluster(int dim, size_t n, double box, tu_rng *rng, double *x, double *r)
{
    for (size_t i = 0; i < n; ++i) r[i] = tu_uniform_in(rng, 0.35, 0.65);
    for (int k = 0; k < dim; ++k) x[k] = 0.5 * box;
    for (size_t i = 1; i < n; ++i) {
        int placed = 0;
        for (int t = 0; t < 2000 && !placed; ++t) {
            double *xi = x + i * dim;
            int two = i >= 2 && tu_uniform(rng) < 0.75;
            if (!two) {
                size_t p = tu_index(rng, i);
                double u[3] = {0, 0, 0}, nu;
                do {
                    nu = 0.0;
                    for (int k = 0; k < dim; ++k) {
                        u[k] = tu_uniform_in(rng, -1, 1);
                        nu += u[k] * u[k];
                    }
                } while (nu > 1.0 || nu < 1e-4);
                nu = sqrt(nu);
                for (int k = 0; k < dim; ++k) xi[k] = x[p * dim + k] + (r[p] + r[i]) * u[k] / nu;
            } else {
                size_t p = tu_index(rng, i), q = tu_index(rng, i);
                if (p == q) continue;
                double R1 = r[p] + r[i], R2 = r[q] + r[i], e[3] = {0, 0, 0}, D = 0.0;
                for (int k = 0; k < dim; ++k) {
                    e[k] = x[q * dim + k] - x[p * dim + k];
                    D += e[k] * e[k];
                }
                D = sqrt(D);
                if (D >= R1 + R2 || D <= fabs(R1 - R2)) continue;
                for (int k = 0; k < dim; ++k) e[k] /= D;
                double a = (R1 * R1 - R2 * R2 + D * D) / (2.0 * D);
                double h = sqrt(R1 * R1 - a * a);
                double perp[3] = {0, 0, 0};
                if (dim == 2) {
                    double sgn = tu_uniform(rng) < 0.5 ? -1.0 : 1.0;
                    perp[0] = -sgn * e[1];
                    perp[1] = sgn * e[0];
                } else {
                    /* e1, e2 orthonormal to e; random angle on the circle */
                    double t0[3] = {1, 0, 0};
                    if (fabs(e[0]) > 0.9) {
                        t0[0] = 0;
                        t0[1] = 1;
                    }
                    double dot = t0[0] * e[0] + t0[1] * e[1] + t0[2] * e[2];
                    double e1[3], e2[3], m = 0.0;
                    for (int k = 0; k < 3; ++k) {
                        e1[k] = t0[k] - dot * e[k];
                        m += e1[k] * e1[k];
                    }
                    m = sqrt(m);
                    for (int k = 0; k < 3; ++k) e1[k] /= m;
                    e2[0] = e[1] * e1[2] - e[2] * e1[1];
                    e2[1] = e[2] * e1[0] - e[0] * e1[2];
                    e2[2] = e[0] * e1[1] - e[1] * e1[0];
                    double th = tu_uniform_in(rng, 0.0, 2.0 * TU_PI);
                    for (int k = 0; k < 3; ++k) perp[k] = cos(th) * e1[k] + sin(th) * e2[k];
                }
                for (int k = 0; k < dim; ++k) xi[k] = x[p * dim + k] + a * e[k] + h * perp[k];
            }
            int ok = 1;
            for (int k = 0; k < dim; ++k)
                if (xi[k] < 0.2 * box || xi[k] > 0.8 * box) ok = 0;
            for (size_t j = 0; j < i && ok; ++j) {
                double s2 = 0.0;
                for (int k = 0; k < dim; ++k) {
                    double d = xi[k] - x[j * dim + k];
                    s2 += d * d;
                }
                double rel = (sqrt(s2) - (r[i] + r[j])) / (r[i] + r[j]);
                if (rel < -1e-13 || (rel > 1e-12 && rel < 1e-3)) ok = 0;
            }
            placed = ok;
        }
        if (!placed) return 0;
    }
    return 1;
}

typedef struct {
    size_t m;        /* |Gamma| */
    size_t *gi, *gj; /* pairs of Gamma */
    size_t n, nd;
    int dim;
    double gdot;
    const double *F;        /* external forces (nd) or NULL */
    odhs_network *gam;      /* network on Gamma (geometry) */
    double *gdrive;         /* (S_Gamma V_aff)_a = gdot dist n_x n_y */
    long singular;          /* subsets skipped as singular */
} gamma_set;

/* evaluate subset B (bitmask) on network netB (already holding B with
 * geometry): returns 1 if (A6) and (A8) hold; margins out */
static int subset_valid(gamma_set *G, odhs_network *netB, odhs_solver *dense, uint32_t mask, double *fB_out,
                        double *minf, double *minv, int *singular)
{
    size_t nb = odhs_network_count(netB);
    double *b = xcalloc(nb, sizeof(double)), *f = xcalloc(nb, sizeof(double));
    double *SF = xcalloc(nb, sizeof(double));
    double *U = xcalloc(G->nd, sizeof(double)), *v = xcalloc(G->m, sizeof(double));
    *singular = 0;
    int valid = 1;
    double scale = fabs(G->gdot) * 2.0;
    if (G->F)
        for (size_t k = 0; k < G->nd; ++k) scale = fmax(scale, fabs(G->F[k]));
    /* b = -S_B (F + V_aff) (xi0 = 1) */
    if (nb) {
        if (G->F) CHECK_OK(odhs_network_apply_S(netB, G->F, SF));
        for (size_t c = 0; c < nb; ++c) {
            size_t i, j;
            CHECK_OK(odhs_network_get_contact(netB, c, &i, &j, NULL));
            /* shear drive of this pair, precomputed on Gamma */
            double drive = 0.0;
            for (size_t a = 0; a < G->m; ++a)
                if (G->gi[a] == i && G->gj[a] == j) drive = G->gdrive[a];
            b[c] = -(SF[c] + drive);
        }
        int rc = odhs_solver_solve(dense, netB, b, f);
        if (rc == ODHS_E_SINGULAR) {
            *singular = 1;
            valid = 0;
            goto out;
        }
        ck_assert_msg(rc == ODHS_OK, "dense solve failed: %d %s", rc, odhs_solver_errmsg(dense));
        CHECK_OK(odhs_network_apply_ST(netB, f, U));
    }
    if (G->F)
        for (size_t k = 0; k < G->nd; ++k) U[k] += G->F[k];
    /* v = S_Gamma V = S_Gamma U + S_Gamma V_aff */
    CHECK_OK(odhs_network_apply_S(G->gam, U, v));
    for (size_t a = 0; a < G->m; ++a) v[a] += G->gdrive[a];
    double mf = INFINITY, mv = INFINITY;
    for (size_t c = 0; c < nb; ++c) {
        size_t i, j;
        CHECK_OK(odhs_network_get_contact(netB, c, &i, &j, NULL));
        mf = fmin(mf, f[c] / scale);
        for (size_t a = 0; a < G->m; ++a)
            if (G->gi[a] == i && G->gj[a] == j && fB_out) fB_out[a] = f[c];
    }
    for (size_t a = 0; a < G->m; ++a)
        if (!(mask & (1u << a))) mv = fmin(mv, v[a] / scale);
    *minf = mf;
    *minv = mv;
    valid = mf > -1e-10 && mv > -1e-10;
out:
    free(b);
    free(f);
    free(SF);
    free(U);
    free(v);
    return valid;
}

static size_t popcount32(uint32_t m)
{
    size_t c = 0;
    for (; m; m &= m - 1) c++;
    return c;
}

static void rewiring_case(int dim, size_t n, uint64_t seed, int mode, double *worst_margin, long *nsubsets)
{
    tu_rng rng;
    tu_rng_seed(&rng, seed);
    double box = dim == 2 ? 40.0 : 24.0;
    double *x = xcalloc(n * dim, sizeof(double)), *r = xcalloc(n, sizeof(double));
    int built = 0;
    for (int t = 0; t < 50 && !built; ++t) built = build_cluster(dim, n, box, &rng, x, r);
    ck_assert_msg(built, "could not build a cluster (seed %llu)", (unsigned long long)seed);
    odhs_system *sys;
    CHECK_OK(odhs_system_create(dim, n, &sys));
    double L[3] = {box, box, box};
    CHECK_OK(odhs_system_set_configuration(sys, L, 0.0, r, x));
    scene s;
    scene_init(&s, sys, "dense");
    /* driving: mode 0 forces, 1 shear, 2 both */
    double *F = NULL, gdot = 0.0;
    if (mode != 1) {
        F = xcalloc(s.nd, sizeof(double));
        random_forces(s.nd, F, &rng, 1.0);
        scene_set_forces(&s, F);
    }
    if (mode != 0) {
        gdot = tu_uniform_in(&rng, 0.5, 1.5) * (tu_uniform(&rng) < 0.5 ? -1.0 : 1.0);
        CHECK_OK(odhs_driver_set_shear_rate(s.drv, gdot));
    }

    /* Gamma: all touching pairs (brute force, relative gap <= 1e-9) */
    gamma_set G;
    memset(&G, 0, sizeof G);
    G.n = n;
    G.nd = s.nd;
    G.dim = dim;
    G.gdot = gdot;
    G.F = F;
    G.gi = xcalloc(n * n, sizeof(size_t));
    G.gj = xcalloc(n * n, sizeof(size_t));
    CHECK_OK(odhs_network_create(sys, &G.gam));
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 1; j < n; ++j) {
            double s2 = 0.0;
            for (int k = 0; k < dim; ++k) {
                double d = x[j * dim + k] - x[i * dim + k];
                s2 += d * d;
            }
            if (fabs(sqrt(s2) - (r[i] + r[j])) <= 1e-9 * (r[i] + r[j])) {
                G.gi[G.m] = i;
                G.gj[G.m] = j;
                G.m++;
                CHECK_OK(odhs_network_add(G.gam, i, j, ODHS_CONTACT_TEMPORARY));
            }
        }
    ck_assert_msg(G.m >= n - 1 && G.m <= 20, "|Gamma| = %zu for N = %zu", G.m, n);
    CHECK_OK(odhs_network_update_geometry(G.gam, sys));
    /* the library's own detection finds the same Gamma */
    {
        odhs_network *det;
        CHECK_OK(odhs_network_create(sys, &det));
        CHECK_OK(odhs_network_detect(det, sys, 1e-9));
        ck_assert_uint_eq(odhs_network_count(det), G.m);
        for (size_t a = 0; a < G.m; ++a) {
            size_t idx;
            CHECK_OK(odhs_network_find(det, G.gi[a], G.gj[a], &idx));
            ck_assert_msg(idx != SIZE_MAX, "detect missed (%zu,%zu)", G.gi[a], G.gj[a]);
        }
        odhs_network_destroy(det);
    }
    /* shear drive of each Gamma pair: gdot |R| n_x n_y (contacts in the
     * middle of the box: no boundary crossing) */
    G.gdrive = xcalloc(G.m, sizeof(double));
    {
        double *nrm = xcalloc(G.m * 3, sizeof(double)), *gap = xcalloc(G.m, sizeof(double));
        CHECK_OK(odhs_network_get_normals(G.gam, nrm));
        CHECK_OK(odhs_network_get_gaps(G.gam, gap));
        for (size_t a = 0; a < G.m; ++a) {
            size_t i, j;
            CHECK_OK(odhs_network_get_contact(G.gam, a, &i, &j, NULL));
            ck_assert(i == G.gi[a] && j == G.gj[a]);
            double dist = gap[a] + r[i] + r[j];
            G.gdrive[a] = gdot * dist * nrm[a * dim] * nrm[a * dim + 1];
        }
        free(nrm);
        free(gap);
    }

    /* brute force over all subsets B of Gamma */
    odhs_solver *dense;
    CHECK_OK(odhs_solver_create_by_name("dense", &dense));
    odhs_network *netB;
    CHECK_OK(odhs_network_create(sys, &netB));
    uint32_t nsub = 1u << G.m, found = 0, valid_mask = 0;
    double *fvalid = xcalloc(G.m, sizeof(double));
    double vminf = 0, vminv = 0;
    for (uint32_t mask = 0; mask < nsub; ++mask) {
        CHECK_OK(odhs_network_clear(netB));
        for (size_t a = 0; a < G.m; ++a)
            if (mask & (1u << a)) CHECK_OK(odhs_network_add(netB, G.gi[a], G.gj[a], ODHS_CONTACT_TEMPORARY));
        CHECK_OK(odhs_network_update_geometry(netB, sys));
        double mf, mv;
        int sing;
        double *fb = xcalloc(G.m, sizeof(double));
        if (subset_valid(&G, netB, dense, mask, fb, &mf, &mv, &sing)) {
            found++;
            valid_mask = mask;
            memcpy(fvalid, fb, G.m * sizeof(double));
            vminf = mf;
            vminv = mv;
        }
        free(fb);
        if (sing) G.singular++;
    }
    *nsubsets += (long)nsub;
    ck_assert_msg(found == 1, "%u subsets of Gamma (|Gamma| = %zu, N = %zu, d = %d, seed %llu) satisfy (A6) and (A8)",
                  found, G.m, n, dim, (unsigned long long)seed);
    double margin = fmin(vminf, vminv);
    if (margin < *worst_margin) *worst_margin = margin;

    /* the stepper's reset finds exactly that subset, with the same forces */
    CHECK_ST(s.st, odhs_stepper_reset(s.st));
    check_invariants(&s);
    const odhs_network *net = odhs_stepper_network(s.st);
    size_t nc = odhs_network_count(net);
    ck_assert_uint_eq(nc, popcount32(valid_mask));
    double *fst = xcalloc(nc, sizeof(double));
    if (nc) CHECK_OK(odhs_network_get_forces(net, fst));
    double fmaxv = 0.0;
    for (size_t a = 0; a < G.m; ++a) fmaxv = fmax(fmaxv, fabs(fvalid[a]));
    for (size_t c = 0; c < nc; ++c) {
        size_t i, j;
        CHECK_OK(odhs_network_get_contact(net, c, &i, &j, NULL));
        size_t a = SIZE_MAX;
        for (size_t q = 0; q < G.m; ++q)
            if (G.gi[q] == i && G.gj[q] == j) a = q;
        ck_assert_msg(a != SIZE_MAX && (valid_mask & (1u << a)),
                      "stepper contact (%zu,%zu) is not in the unique valid subset (seed %llu)", i, j,
                      (unsigned long long)seed);
        ck_assert_msg(fabs(fst[c] - fvalid[a]) <= 1e-10 * fmaxv, "force on (%zu,%zu): stepper %.17g, brute %.17g", i,
                      j, fst[c], fvalid[a]);
    }
    free(fst);
    free(fvalid);
    odhs_network_destroy(netB);
    odhs_solver_destroy(dense);
    odhs_network_destroy(G.gam);
    free(G.gi);
    free(G.gj);
    free(G.gdrive);
    free(F);
    free(x);
    free(r);
    scene_free(&s);
}

START_TEST(test_rewiring_unique_2d)
{
    double worst = INFINITY;
    long nsub = 0;
    int cases = 0;
    for (uint64_t seed = 1; seed <= 48; ++seed) {
        size_t n = 4 + (size_t)(seed % 6); /* 4..9 */
        rewiring_case(2, n, 1000 + seed, (int)(seed % 3), &worst, &nsub);
        cases++;
    }
    fprintf(stderr, "[stepper] rewiring 2D: %d clusters, %ld subsets, unique valid subset = stepper's; "
                    "smallest margin %.3g\n",
            cases, nsub, worst);
}
END_TEST

START_TEST(test_rewiring_unique_3d)
{
    double worst = INFINITY;
    long nsub = 0;
    int cases = 0;
    for (uint64_t seed = 1; seed <= 16; ++seed) {
        size_t n = 4 + (size_t)(seed % 5); /* 4..8 */
        rewiring_case(3, n, 5000 + seed, (int)(seed % 3), &worst, &nsub);
        cases++;
    }
    fprintf(stderr, "[stepper] rewiring 3D: %d clusters, %ld subsets, smallest margin %.3g\n", cases, nsub, worst);
}
END_TEST

/* ========================================================================== */
/* 6. Constant pressure                                                       */
/* ========================================================================== */
static void pressure_case(int dim, size_t n, double phi, uint64_t seed, double pfac, long nsteps)
{
    scene s;
    scene_dense(&s, dim, n, phi, seed, "cg");
    CHECK_OK(odhs_driver_set_shear_rate(s.drv, 1.0));
    CHECK_ST(s.st, odhs_stepper_reset(s.st));
    double p0;
    CHECK_OK(odhs_stepper_pressure(s.st, &p0));
    ck_assert_msg(p0 > 0.0, "no pressure under shear at phi %.2f", phi);
    double p = pfac * p0, kmax = 100.0;
    CHECK_OK(odhs_driver_set_pressure(s.drv, p));
    CHECK_ST(s.st, odhs_stepper_reset(s.st));
    double ph0 = cur_phi(&s), phmin = ph0, phmax = ph0, worst = 0.0, kmin_ = INFINITY, kmax_ = -INFINITY;
    long clamped = 0;
    double worst_box = 0.0, worst_ind = 0.0;
    for (long k = 0; k < nsteps; ++k) {
        double kap0, vol0, t0 = cur_time(&s);
        CHECK_OK(odhs_stepper_kappa(s.st, &kap0));
        CHECK_OK(odhs_system_volume(s.sys, &vol0));
        step_checked(&s, NULL);
        double pm, kap, vol1, dtk = cur_time(&s) - t0;
        CHECK_OK(odhs_system_volume(s.sys, &vol1));
        /* the box deforms with G = gdot e_x e_y - kappa gdot I over the step:
         * kappa > 0 compresses (eq. 21 with the sign fixed) */
        double vexp = vol0 * pow(1.0 - kap0 * dtk, (double)dim);
        double eb = fabs(vol1 - vexp) / vexp;
        ck_assert_msg(eb <= 1e-12, "step %ld: volume %.17g, expected %.17g from kappa %.6g", k, vol1, vexp, kap0);
        worst_box = fmax(worst_box, eb);
        CHECK_OK(odhs_stepper_pressure(s.st, &pm));
        CHECK_OK(odhs_stepper_kappa(s.st, &kap));
        ck_assert_msg(isfinite(kap), "kappa = %g", kap);
        if (fabs(kap) >= kmax) {
            clamped++;
            continue;
        }
        double e = fabs(pm - p) / p;
        ck_assert_msg(e <= 1e-9, "step %ld: pressure %.17g, target %.17g (rel %.3g), kappa %.6g", k, pm, p, e, kap);
        /* independently: <f|r> / (Omega d) */
        {
            const odhs_network *net = odhs_stepper_network(s.st);
            size_t nc = odhs_network_count(net);
            double *f = xcalloc(nc, sizeof(double)), *gap = xcalloc(nc, sizeof(double)), fr = 0.0;
            CHECK_OK(odhs_network_get_forces(net, f));
            CHECK_OK(odhs_network_get_gaps(net, gap));
            for (size_t c = 0; c < nc; ++c) {
                size_t i, j;
                CHECK_OK(odhs_network_get_contact(net, c, &i, &j, NULL));
                fr += f[c] * (gap[c] + s.r[i] + s.r[j]);
            }
            double pind = fr / (vol1 * dim), ei = fabs(pind - p) / p;
            ck_assert_msg(ei <= 1e-9, "step %ld: <f|r>/(Omega d) = %.17g, target %.17g", k, pind, p);
            worst_ind = fmax(worst_ind, ei);
            free(f);
            free(gap);
        }
        worst = fmax(worst, e);
        kmin_ = fmin(kmin_, kap);
        kmax_ = fmax(kmax_, kap);
        double ph = cur_phi(&s);
        phmin = fmin(phmin, ph);
        phmax = fmax(phmax, ph);
    }
    ck_assert_msg(clamped == 0, "kappa clamped at kappa_max in %ld of %ld steps (contacts could not carry p)", clamped,
                  nsteps);
    ck_assert_msg(phmax - phmin > 1e-3 * ph0, "phi did not change: %.10g .. %.10g", phmin, phmax);
    fprintf(stderr,
            "[stepper] pressure d=%d N=%zu p=%.4g: worst rel %.2e (independent %.2e), box %.2e, kappa in [%.3g, %.3g], "
            "phi %.4f -> [%.4f, %.4f], |SV| %.2e\n",
            dim, n, p, worst, worst_ind, worst_box, kmin_, kmax_, ph0, phmin, phmax, s.w_rigid);
    scene_free(&s);
}

START_TEST(test_pressure_2d) { pressure_case(2, 64, 0.78, 41, 2.0, 400); }
END_TEST

START_TEST(test_pressure_3d) { pressure_case(3, 48, 0.55, 42, 2.0, 300); }
END_TEST

/* ========================================================================== */
/* 7. CG and dense LAPACK agree                                               */
/* ========================================================================== */
/* forces of the stepper's current network for shear (xi0 = 1): N f = b with
 * b_c = -gdot |R_c| n_x n_y */
static void shear_rhs(scene *s, double gdot, double *b)
{
    const odhs_network *net = odhs_stepper_network(s->st);
    size_t nc = odhs_network_count(net);
    double *nrm = xcalloc(nc * 3, sizeof(double)), *gap = xcalloc(nc, sizeof(double));
    CHECK_OK(odhs_network_get_normals(net, nrm));
    CHECK_OK(odhs_network_get_gaps(net, gap));
    for (size_t c = 0; c < nc; ++c) {
        size_t i, j;
        CHECK_OK(odhs_network_get_contact(net, c, &i, &j, NULL));
        double dist = gap[c] + s->r[i] + s->r[j];
        b[c] = -gdot * dist * nrm[c * s->dim] * nrm[c * s->dim + 1];
    }
    free(nrm);
    free(gap);
}

START_TEST(test_cg_vs_dense_states)
{
    scene s;
    scene_dense(&s, 2, 64, 0.78, 51, "cg");
    CHECK_OK(odhs_driver_set_shear_rate(s.drv, 1.0));
    CHECK_ST(s.st, odhs_stepper_reset(s.st));
    odhs_solver *cg, *dn;
    CHECK_OK(odhs_solver_create_by_name("cg", &cg));
    CHECK_OK(odhs_solver_create_by_name("dense", &dn));
    double worst = 0.0, worst_st = 0.0;
    int states = 0;
    for (long k = 1; k <= 300; ++k) {
        step_checked(&s, NULL);
        if (k % 50) continue;
        const odhs_network *net = odhs_stepper_network(s.st);
        size_t nc = odhs_network_count(net);
        ck_assert_msg(nc > 0, "no contacts at step %ld", k);
        double *b = xcalloc(nc, sizeof(double)), *fc = xcalloc(nc, sizeof(double));
        double *fd = xcalloc(nc, sizeof(double)), *fs = xcalloc(nc, sizeof(double));
        shear_rhs(&s, 1.0, b);
        CHECK_OK(odhs_solver_solve(cg, net, b, fc));
        CHECK_OK(odhs_solver_solve(dn, net, b, fd));
        CHECK_OK(odhs_network_get_forces(net, fs));
        double fmx = 0.0, e = 0.0, es = 0.0;
        for (size_t c = 0; c < nc; ++c) fmx = fmax(fmx, fabs(fd[c]));
        for (size_t c = 0; c < nc; ++c) {
            e = fmax(e, fabs(fc[c] - fd[c]) / fmx);
            es = fmax(es, fabs(fs[c] - fd[c]) / fmx);
        }
        ck_assert_msg(e <= 1e-10, "step %ld (Nc = %zu): cg and dense forces differ by %.3g of max force", k, nc, e);
        ck_assert_msg(es <= 1e-10, "step %ld: the stepper's forces differ from dense by %.3g of max force", k, es);
        worst = fmax(worst, e);
        worst_st = fmax(worst_st, es);
        states++;
        free(b);
        free(fc);
        free(fd);
        free(fs);
    }
    fprintf(stderr, "[stepper] cg vs dense on %d states: worst %.2e (stepper vs dense %.2e)\n", states, worst,
            worst_st);
    odhs_solver_destroy(cg);
    odhs_solver_destroy(dn);
    scene_free(&s);
}
END_TEST

START_TEST(test_cg_vs_dense_trajectories)
{
    scene base;
    scene_dense(&base, 2, 64, 0.78, 52, "dense");
    scene a, b;
    scene_clone(&a, &base, "cg");
    scene_clone(&b, &base, "dense");
    CHECK_OK(odhs_driver_set_shear_rate(a.drv, 1.0));
    CHECK_OK(odhs_driver_set_shear_rate(b.drv, 1.0));
    CHECK_ST(a.st, odhs_stepper_reset(a.st));
    CHECK_ST(b.st, odhs_stepper_reset(b.st));
    long nsteps = 0;
    double smax = 0.0, worst = 0.0;
    double *sa = xcalloc(400, sizeof(double)), *sb = xcalloc(400, sizeof(double));
    while (cur_strain(&a) < 0.02 && nsteps < 400) {
        step_checked(&a, NULL);
        step_checked(&b, NULL);
        double ta = cur_strain(&a), tb = cur_strain(&b);
        ck_assert_msg(fabs(ta - tb) <= 1e-12, "step %ld: strains %.17g vs %.17g", nsteps, ta, tb);
        CHECK_OK(odhs_stepper_shear_stress(a.st, &sa[nsteps]));
        CHECK_OK(odhs_stepper_shear_stress(b.st, &sb[nsteps]));
        smax = fmax(smax, fabs(sb[nsteps]));
        nsteps++;
    }
    for (long k = 0; k < nsteps; ++k) {
        double e = fabs(sa[k] - sb[k]) / smax;
        ck_assert_msg(e <= 1e-8, "step %ld: shear stress cg %.17g, dense %.17g (rel %.3g)", k, sa[k], sb[k], e);
        worst = fmax(worst, e);
    }
    ck_assert_uint_eq(a.log.n, b.log.n);
    fprintf(stderr, "[stepper] cg vs dense stress series: %ld steps, %zu events, worst %.2e\n", nsteps, a.log.n,
            worst);
    free(sa);
    free(sb);
    scene_free(&a);
    scene_free(&b);
    scene_free(&base);
}
END_TEST

/* ========================================================================== */
/* 9. Events                                                                  */
/* ========================================================================== */
START_TEST(test_events_bookkeeping)
{
    scene s;
    scene_dense(&s, 2, 64, 0.78, 61, "cg");
    CHECK_OK(odhs_driver_set_shear_rate(s.drv, 1.0));
    CHECK_ST(s.st, odhs_stepper_reset(s.st));
    uint64_t c0, o0;
    CHECK_OK(odhs_stepper_counts(s.st, NULL, &c0, &o0));
    const double ts = cur_time(&s), gs = cur_strain(&s); /* time keeps counting from the compression */
    run_strain_checked(&s, gs + 0.1);
    uint64_t c1, o1;
    CHECK_OK(odhs_stepper_counts(s.st, NULL, &c1, &o1));
    ck_assert_uint_eq(s.log.n, (c1 - c0) + (o1 - o0));
    ck_assert_uint_eq(s.log.bad_order, 0);
    size_t nc = 0, no = 0;
    for (size_t k = 0; k < s.log.n; ++k) {
        const evrec *e = &s.log.e[k];
        ck_assert(e->kind == ODHS_EVENT_COLLISION || e->kind == ODHS_EVENT_OPENING);
        ck_assert_msg(e->i < e->j && e->j < s.n, "event pair (%zu,%zu)", e->i, e->j);
        if (e->kind == ODHS_EVENT_COLLISION) nc++;
        else no++;
        if (k) {
            ck_assert_msg(e->time >= s.log.e[k - 1].time, "event %zu at t = %.17g before %.17g", k, e->time,
                          s.log.e[k - 1].time);
            ck_assert_msg(e->strain >= s.log.e[k - 1].strain, "event %zu strain decreases", k);
        }
        ck_assert_msg(fabs((e->strain - gs) - (e->time - ts)) <= 1e-12 * fmax(1.0, e->time),
                      "event strain %.17g != gammadot (t - t_s) = %.17g", e->strain - gs, e->time - ts);
    }
    ck_assert_uint_eq(nc, c1 - c0);
    ck_assert_uint_eq(no, o1 - o0);
    ck_assert_msg(nc > 5 && no > 5, "too few events (%zu collisions, %zu openings)", nc, no);
    fprintf(stderr, "[stepper] events: %zu collisions, %zu openings over strain 0.1\n", nc, no);

    /* a callback returning nonzero stops run_until_strain with ODHS_STOPPED */
    log_clear(&s);
    s.log.stop_at = 3;
    double g0 = cur_strain(&s);
    int rc = odhs_stepper_run_until_strain(s.st, g0 + 1.0);
    ck_assert_msg(rc == ODHS_STOPPED, "run_until_strain returned %d, expected ODHS_STOPPED", rc);
    check_invariants(&s);
    ck_assert_uint_ge(s.log.n, 3);
    ck_assert_msg(cur_strain(&s) < g0 + 1.0, "the run was not stopped");
    /* it stopped after the step that produced the third event */
    uint64_t steps;
    CHECK_OK(odhs_stepper_counts(s.st, &steps, NULL, NULL));
    ck_assert_uint_eq(s.log.e[2].step, steps);
    ck_assert_uint_eq(s.log.e[s.log.n - 1].step, steps);
    s.log.stop_at = 0;

    /* run_events(k) stops after >= k events, at the first step reaching k */
    for (uint64_t want = 1; want <= 7; want += 3) {
        log_clear(&s);
        CHECK_ST(s.st, odhs_stepper_run_events(s.st, want));
        check_invariants(&s);
        ck_assert_uint_ge(s.log.n, want);
        CHECK_OK(odhs_stepper_counts(s.st, &steps, NULL, NULL));
        size_t before_last = 0;
        for (size_t k = 0; k < s.log.n; ++k)
            if (s.log.e[k].step < steps) before_last++;
        ck_assert_msg(before_last < want, "run_events(%llu) went on after %zu events", (unsigned long long)want,
                      before_last);
    }

    /* run_until_time lands on the target */
    double t0 = cur_time(&s);
    for (int q = 1; q <= 3; ++q) {
        double target = t0 + 0.0123456789 * q;
        CHECK_ST(s.st, odhs_stepper_run_until_time(s.st, target));
        check_invariants(&s);
        double t = cur_time(&s);
        ck_assert_msg(fabs(t - target) <= 1e-12 * target, "run_until_time(%.17g) ended at %.17g", target, t);
        ck_assert_msg(fabs((cur_strain(&s) - gs) - (t - ts)) <= 1e-12 * t, "strain %.17g at t %.17g", cur_strain(&s),
                      t);
    }
    scene_free(&s);
}
END_TEST

/* ========================================================================== */
/* 10. Drift correction                                                       */
/* ========================================================================== */
START_TEST(test_drift_correction)
{
    scene base;
    scene_dense(&base, 2, 64, 0.78, 71, "dense");
    /* scene_dense ended with odhs_stepper_correct: gaps back to round-off */
    double g0;
    CHECK_OK(odhs_stepper_errors(base.st, &g0, NULL));

    /* interval 0: the gaps of long-lived contacts drift (O(dt^2) per step) */
    scene a;
    scene_clone(&a, &base, "dense");
    CHECK_OK(odhs_driver_set_shear_rate(a.drv, 1.0));
    CHECK_ST(a.st, odhs_stepper_set_correction_interval(a.st, 0));
    CHECK_ST(a.st, odhs_stepper_reset(a.st));
    double early = 0.0, late = 0.0;
    while (cur_strain(&a) < 0.05) {
        step_checked(&a, NULL);
        double cg;
        CHECK_OK(odhs_stepper_errors(a.st, &cg, NULL));
        if (cur_strain(&a) <= 0.005) early = fmax(early, cg);
        if (cur_strain(&a) >= 0.04) late = fmax(late, cg);
    }
    /* odhs_stepper_correct removes it */
    CHECK_ST(a.st, odhs_stepper_correct(a.st));
    check_invariants(&a);
    double ga;
    CHECK_OK(odhs_stepper_errors(a.st, &ga, NULL));

    /* interval 1: corrected after every step */
    scene b;
    scene_clone(&b, &base, "dense");
    CHECK_OK(odhs_driver_set_shear_rate(b.drv, 1.0));
    CHECK_ST(b.st, odhs_stepper_set_correction_interval(b.st, 1));
    CHECK_ST(b.st, odhs_stepper_reset(b.st));
    double worst1 = 0.0, worst1_strain = 0.0;
    while (cur_strain(&b) < 0.05) {
        step_checked(&b, NULL);
        double cg;
        CHECK_OK(odhs_stepper_errors(b.st, &cg, NULL));
        if (cg > worst1) {
            worst1 = cg;
            worst1_strain = cur_strain(&b);
        }
    }
    fprintf(stderr,
            "[stepper] drift: after compression+correct %.2e; interval 0: gap %.2e at strain >= 0.04 (%.2e at <= "
            "0.005) -> correct %.2e; interval 1 worst %.2e (strain %.4f)\n",
            g0, late, early, ga, worst1, worst1_strain);
    ck_assert_msg(g0 <= 1e-13, "after compression and odhs_stepper_correct the worst contact gap is %.3g", g0);
    ck_assert_msg(late > 1e-9 && late > 10.0 * early,
                  "without correction the contact gap should grow: %.3g at strain <= 0.005, %.3g at >= 0.04", early,
                  late);
    ck_assert_msg(ga <= 1e-13, "after odhs_stepper_correct the worst contact gap is %.3g (was %.3g)", ga, late);
    ck_assert_msg(worst1 <= 1e-12, "interval 1: contact gap %.3g at strain %.6g", worst1, worst1_strain);
    scene_free(&a);
    scene_free(&b);
    scene_free(&base);
}
END_TEST

/* ========================================================================== */
/* 11. Compression targets                                                    */
/* ========================================================================== */
START_TEST(test_compression_targets)
{
    /* scene_dense asserts landing on phi; here several targets in sequence,
     * in 2D and 3D, straight through run_until_packing_fraction */
    for (int dim = 2; dim <= 3; ++dim) {
        scene s;
        scene_dense(&s, dim, dim == 2 ? 32 : 24, dim == 2 ? 0.6 : 0.4, 80 + (uint64_t)dim, "cg");
        CHECK_OK(odhs_driver_set_compression_rate(s.drv, 1.0));
        CHECK_ST(s.st, odhs_stepper_reset(s.st));
        const double targets2[] = {0.65, 0.70, 0.7000001, 0.75}, targets3[] = {0.45, 0.5, 0.5000001, 0.52};
        const double *tg = dim == 2 ? targets2 : targets3;
        double worst = 0.0;
        for (int q = 0; q < 4; ++q) {
            CHECK_ST(s.st, odhs_stepper_run_until_packing_fraction(s.st, tg[q]));
            check_invariants(&s);
            double e = fabs(cur_phi(&s) - tg[q]) / tg[q];
            ck_assert_msg(e <= 1e-12, "d=%d: phi %.17g, target %.17g (rel %.3g)", dim, cur_phi(&s), tg[q], e);
            worst = fmax(worst, e);
        }
        fprintf(stderr, "[stepper] compression d=%d: worst rel phi error %.2e\n", dim, worst);
        scene_free(&s);
    }
}
END_TEST

/* ========================================================================== */
Suite *make_stepper_suite(void)
{
    Suite *s = suite_create("stepper");
    TCase *tc;

    tc = tcase_create("two_body");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_checkers_detect_overlap);
    tcase_add_test(tc, test_two_discs_head_on);
    tcase_add_test(tc, test_two_spheres_head_on);
    tcase_add_test(tc, test_two_discs_oblique);
    tcase_add_test(tc, test_two_spheres_oblique);
    suite_add_tcase(s, tc);

    tc = tcase_create("power");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_power_shear_2d);
    tcase_add_test(tc, test_power_shear_2d_dense);
    tcase_add_test(tc, test_power_forces_2d);
    tcase_add_test(tc, test_power_shear_3d);
    tcase_add_test(tc, test_power_forces_3d);
    suite_add_tcase(s, tc);

    tc = tcase_create("rate_invariance");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_rate_invariance_shear);
    tcase_add_test(tc, test_rate_changes);
    tcase_add_test(tc, test_rate_invariance_mobility);
    tcase_add_test(tc, test_rate_invariance_forces);
    suite_add_tcase(s, tc);

    tc = tcase_create("rewiring");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_rewiring_unique_2d);
    tcase_add_test(tc, test_rewiring_unique_3d);
    suite_add_tcase(s, tc);

    tc = tcase_create("pressure");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_pressure_2d);
    tcase_add_test(tc, test_pressure_3d);
    suite_add_tcase(s, tc);

    tc = tcase_create("solvers");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_cg_vs_dense_states);
    tcase_add_test(tc, test_cg_vs_dense_trajectories);
    suite_add_tcase(s, tc);

    tc = tcase_create("events");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_events_bookkeeping);
    suite_add_tcase(s, tc);

    tc = tcase_create("drift");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_drift_correction);
    tcase_add_test(tc, test_compression_targets);
    suite_add_tcase(s, tc);

    return s;
}
