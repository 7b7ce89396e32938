/* Check suite "propulsion": self-propelled particles (Sect. V B of the paper)
 * and gravity.
 *
 * - reproducible: the same seed gives bit-identical runs; a run split by a
 *   checkpoint continues bit for bit; the propulsion history (forces, switch
 *   times) does not depend on the step size or the integrator at all.
 * - switches: every switch time is the end of a step exactly, the switching
 *   particle gets a new force and a persistence in [tmin, tmax] tau_p.
 * - statistics: magnitudes, directions (2D angle; 3D cos(theta) and azimuth)
 *   and persistence times against their uniform laws (chi-square with a fixed
 *   seed and N = 4000, 10 bins, bound 33.7: |F| uniform in the annulus area
 *   instead, density ~ |F|, would give an expected chi^2 of about 720 from
 *   the bin probabilities), and mean direction ~ 0.
 * - free particles move by xi0 F dt over each interval between switches,
 *   exactly (the trajectory is the same for any dt).
 * - two particles driven head-on stop at contact at the analytic collision
 *   time, with the analytic contact force |F1 - F0|/2 and common velocity
 *   xi0 (F0 + F1)/2.
 * - gravity: V_i = xi0 w_i g with w_i = (a_i/<a>)^d, or the user's weights;
 *   sums with propulsion; time unit lambda/(xi0 |g| sqrt(<w^2>)).
 * - rate invariance: forces x2 and xi0 x4 give the same trajectory in units
 *   of tau (exact powers of two: identical to round-off).
 */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "odhs.h"

#define PI 3.14159265358979323846

/* phi = 0.5 discs of mean diameter 1 with 3% uniform polydispersity */
static odhs_system *dense_scene(size_t n, unsigned seed)
{
    odhs_system *sys;
    ck_assert_int_eq(odhs_system_create(2, n, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(sys, 0.5, 1.0, 0.03, seed), ODHS_OK);
    ck_assert_int_eq(odhs_system_place_random(sys, 0.5, seed + 1), ODHS_OK);
    return sys;
}

/* n particles on a coarse grid in a big box (no contacts) */
static odhs_system *dilute_scene(int dim, size_t n, double spacing, const double *r)
{
    odhs_system *sys;
    ck_assert_int_eq(odhs_system_create(dim, n, &sys), ODHS_OK);
    size_t side = (size_t)ceil(pow((double)n, 1.0 / dim));
    double L[3] = {side * spacing, side * spacing, side * spacing};
    double *x = malloc(n * dim * sizeof *x), *rr = malloc(n * sizeof *rr);
    for (size_t i = 0; i < n; ++i) {
        size_t q = i;
        for (int k = 0; k < dim; ++k) {
            x[i * dim + k] = (q % side + 0.5) * spacing;
            q /= side;
        }
        rr[i] = r ? r[i] : 0.5;
    }
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, rr, x), ODHS_OK);
    free(x);
    free(rr);
    return sys;
}

static double mean_diameter(const odhs_system *sys)
{
    size_t n = odhs_system_count(sys);
    double *r = malloc(n * sizeof *r), lam = 0.0;
    odhs_system_get_radii(sys, r);
    for (size_t i = 0; i < n; ++i) lam += 2.0 * r[i];
    free(r);
    return lam / (double)n;
}

typedef struct {
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
} sim;

static void sim_make(sim *s, odhs_system *sys, const char *solver)
{
    s->sys = sys;
    ck_assert_int_eq(odhs_driver_create(&s->drv), ODHS_OK);
    ck_assert_int_eq(odhs_solver_create_by_name(solver, &s->sol), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_create(sys, s->drv, s->sol, &s->st), ODHS_OK);
}

static void sim_free(sim *s)
{
    odhs_stepper_destroy(s->st);
    odhs_solver_destroy(s->sol);
    odhs_driver_destroy(s->drv);
    odhs_system_destroy(s->sys);
}

static int bits_eq(const double *a, const double *b, size_t n) { return memcmp(a, b, n * sizeof *a) == 0; }

/* positions, propulsion forces and switch times after a run */
typedef struct {
    double *x, *F, *ts, t;
    uint64_t steps, ncoll, nopen;
} fp;

static void fp_grab(const sim *s, fp *f)
{
    size_t n = odhs_system_count(s->sys), nd = n * (size_t)odhs_system_dim(s->sys);
    f->x = malloc(nd * sizeof *f->x);
    f->F = malloc(nd * sizeof *f->F);
    f->ts = malloc(n * sizeof *f->ts);
    ck_assert_int_eq(odhs_system_get_positions(s->sys, f->x), ODHS_OK);
    ck_assert_int_eq(odhs_driver_get_propulsion(s->drv, f->F, f->ts), ODHS_OK);
    odhs_stepper_time(s->st, &f->t);
    odhs_stepper_counts(s->st, &f->steps, &f->ncoll, &f->nopen);
}

static void fp_free(fp *f)
{
    free(f->x);
    free(f->F);
    free(f->ts);
}

static void run_dense(sim *s, size_t n, double dt, int integrator, double T)
{
    sim_make(s, dense_scene(n, 3), "dense");
    ck_assert_int_eq(odhs_driver_set_self_propulsion(s->drv, n, 2, 0.5, 1.5, 0.0, 2.0, 42), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_set_dt(s->st, dt), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_set_integrator(s->st, integrator), ODHS_OK);
    double tau;
    ck_assert_int_eq(odhs_driver_time_unit(s->drv, s->sys, &tau), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_time(s->st, T * tau), ODHS_OK);
}

START_TEST(test_reproducible)
{
    /* two independent runs with the same seed: identical bit for bit */
    sim a, b, c, h;
    fp A, B, C, H;
    run_dense(&a, 64, 1e-2, ODHS_INTEGRATOR_EULER, 3.0);
    run_dense(&b, 64, 1e-2, ODHS_INTEGRATOR_EULER, 3.0);
    fp_grab(&a, &A);
    fp_grab(&b, &B);
    size_t nd = 128;
    ck_assert(bits_eq(A.x, B.x, nd));
    ck_assert(bits_eq(A.F, B.F, nd));
    ck_assert(bits_eq(A.ts, B.ts, 64));
    ck_assert_uint_eq(A.steps, B.steps);
    ck_assert_uint_eq(A.ncoll, B.ncoll);
    ck_assert_uint_gt(A.ncoll, 20); /* a real many-body run */
    /* another step size and another integrator: the propulsion history is the
     * same bit for bit (it does not depend on the dynamics), the positions
     * agree within the integration error */
    run_dense(&c, 64, 2e-3, ODHS_INTEGRATOR_EULER, 3.0);
    run_dense(&h, 64, 1e-1, ODHS_INTEGRATOR_HEUN, 3.0);
    fp_grab(&c, &C);
    fp_grab(&h, &H);
    ck_assert(bits_eq(A.F, C.F, nd) && bits_eq(A.F, H.F, nd));
    ck_assert(bits_eq(A.ts, C.ts, 64) && bits_eq(A.ts, H.ts, 64));
    ck_assert(A.t == C.t && A.t == H.t);
    /* a different seed gives different forces */
    ck_assert_int_eq(odhs_driver_set_self_propulsion(b.drv, 64, 2, 0.5, 1.5, 0.0, 2.0, 43), ODHS_OK);
    double *F2 = malloc(nd * sizeof *F2);
    ck_assert_int_eq(odhs_driver_get_propulsion(b.drv, F2, NULL), ODHS_OK);
    size_t same = 0;
    for (size_t k = 0; k < nd; ++k) same += F2[k] == B.F[k];
    ck_assert_uint_lt(same, 4);
    free(F2);
    fp_free(&A);
    fp_free(&B);
    fp_free(&C);
    fp_free(&H);
    sim_free(&a);
    sim_free(&b);
    sim_free(&c);
    sim_free(&h);
}
END_TEST

START_TEST(test_checkpoint_split)
{
    char dir[] = "/tmp/odhs_prop_XXXXXX", path[64];
    ck_assert_ptr_nonnull(mkdtemp(dir));
    snprintf(path, sizeof path, "%s/p.ckpt", dir);
    for (int integ = 0; integ < 2; ++integ) {
        int integrator = integ ? ODHS_INTEGRATOR_HEUN : ODHS_INTEGRATOR_EULER;
        sim a;
        run_dense(&a, 48, 2e-2, integrator, 1.0);
        ck_assert_int_eq(odhs_checkpoint_write(a.st, path), ODHS_OK);
        double tau, t0;
        ck_assert_int_eq(odhs_driver_time_unit(a.drv, a.sys, &tau), ODHS_OK);
        odhs_stepper_time(a.st, &t0);
        ck_assert_int_eq(odhs_stepper_run_until_time(a.st, t0 + 2.0 * tau), ODHS_OK);
        fp A, B;
        fp_grab(&a, &A);
        sim b;
        char err[256];
        ck_assert_int_eq(odhs_solver_create_by_name("dense", &b.sol), ODHS_OK);
        ck_assert_int_eq(odhs_checkpoint_read(path, b.sol, &b.sys, &b.drv, &b.st, err, sizeof err), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_run_until_time(b.st, t0 + 2.0 * tau), ODHS_OK);
        fp_grab(&b, &B);
        ck_assert(bits_eq(A.x, B.x, 96));
        ck_assert(bits_eq(A.F, B.F, 96));
        ck_assert(bits_eq(A.ts, B.ts, 48));
        ck_assert(A.t == B.t);
        ck_assert_uint_eq(A.steps, B.steps);
        ck_assert_uint_eq(A.ncoll + A.nopen, B.ncoll + B.nopen);
        fp_free(&A);
        fp_free(&B);
        sim_free(&a);
        sim_free(&b);
    }
    remove(path);
    rmdir(dir);
}
END_TEST

START_TEST(test_switch_exact)
{
    /* dilute, no contacts: every switch must be the end of some step */
    size_t n = 9;
    sim s;
    sim_make(&s, dilute_scene(2, n, 6.0, NULL), "cg");
    const double tmin = 0.2, tmax = 1.0, xi0 = 1.7;
    ck_assert_int_eq(odhs_driver_set_mobility(s.drv, xi0), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_self_propulsion(s.drv, n, 2, 0.01, 0.02, tmin, tmax, 5), ODHS_OK);
    double ts[9], ts_new[9], F[18], F_new[18], t;
    ck_assert_int_eq(odhs_driver_get_propulsion(s.drv, NULL, ts), ODHS_E_STATE); /* clock not started */
    ck_assert_int_eq(odhs_driver_next_switch(s.drv, &t), ODHS_E_STATE);
    ck_assert_int_eq(odhs_stepper_set_dt(s.st, 0.37), ODHS_OK); /* steps much longer than persistences */
    ck_assert_int_eq(odhs_stepper_reset(s.st), ODHS_OK);
    double fp = sqrt((0.01 * 0.01 + 0.01 * 0.02 + 0.02 * 0.02) / 3.0);
    double taup = 1.0 / (xi0 * fp), tau;
    ck_assert_int_eq(odhs_driver_time_unit(s.drv, s.sys, &tau), ODHS_OK);
    ck_assert_double_eq_tol(tau, taup, 1e-14 * taup);
    ck_assert_int_eq(odhs_driver_get_propulsion(s.drv, F, ts), ODHS_OK);
    for (size_t i = 0; i < n; ++i) { /* started at t = 0 */
        ck_assert(ts[i] >= tmin * taup && ts[i] <= tmax * taup);
    }
    int nswitch = 0;
    for (int step = 0; step < 400; ++step) {
        double tnext;
        ck_assert_int_eq(odhs_driver_next_switch(s.drv, &tnext), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_step(s.st, NULL), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_time(s.st, &t), ODHS_OK);
        ck_assert(t <= tnext); /* never steps over a switch */
        ck_assert_int_eq(odhs_driver_get_propulsion(s.drv, F_new, ts_new), ODHS_OK);
        for (size_t i = 0; i < n; ++i) {
            if (ts[i] == tnext && t == tnext) {
                /* switched exactly at its time: new force, new persistence */
                nswitch++;
                ck_assert(F_new[2 * i] != F[2 * i]);
                double dur = ts_new[i] - t;
                ck_assert(dur >= tmin * taup * (1 - 1e-12) && dur <= tmax * taup * (1 + 1e-12));
            } else {
                ck_assert(ts_new[i] == ts[i]);
                ck_assert(F_new[2 * i] == F[2 * i] && F_new[2 * i + 1] == F[2 * i + 1]);
            }
        }
        memcpy(ts, ts_new, sizeof ts);
        memcpy(F, F_new, sizeof F);
    }
    ck_assert_int_gt(nswitch, 100);
    sim_free(&s);
}
END_TEST

/* chi-square of counts against a uniform law over nb bins */
static double chi2(const size_t *cnt, int nb, size_t n)
{
    double e = (double)n / nb, c = 0.0;
    for (int b = 0; b < nb; ++b) c += (cnt[b] - e) * (cnt[b] - e) / e;
    return c;
}

static int bin(double u, int nb)
{
    int b = (int)floor(u * nb);
    return b < 0 ? 0 : (b >= nb ? nb - 1 : b);
}

START_TEST(test_statistics)
{
    /* chi^2 with 9 degrees of freedom: 99.99% quantile 33.7 */
    const double chi_max = 33.7;
    const size_t n = 4000;
    for (int dim = 2; dim <= 3; ++dim) {
        sim s;
        sim_make(&s, dilute_scene(dim, n, 1.5, NULL), "cg");
        const double fmin = 0.3, fmax = 2.0, tmin = 1.0, tmax = 10.0;
        ck_assert_int_eq(odhs_driver_set_self_propulsion(s.drv, n, dim, fmin, fmax, tmin, tmax, 2024 + dim),
                         ODHS_OK);
        double *F = malloc(n * dim * sizeof *F), *ts = malloc(n * sizeof *ts);
        ck_assert_int_eq(odhs_stepper_reset(s.st), ODHS_OK);
        ck_assert_int_eq(odhs_driver_get_propulsion(s.drv, F, ts), ODHS_OK);
        size_t cm[10] = {0}, ca[10] = {0}, cz[10] = {0}, ct[10] = {0};
        double mean[3] = {0, 0, 0}, f2 = 0.0;
        double lam = mean_diameter(s.sys);
        double fp = sqrt((fmin * fmin + fmin * fmax + fmax * fmax) / 3.0), taup = lam / fp;
        for (size_t i = 0; i < n; ++i) {
            const double *f = F + i * dim;
            double m = 0.0;
            for (int k = 0; k < dim; ++k) m += f[k] * f[k];
            f2 += m;
            m = sqrt(m);
            ck_assert(m >= fmin * (1 - 1e-15) && m <= fmax * (1 + 1e-15));
            cm[bin((m - fmin) / (fmax - fmin), 10)]++;
            for (int k = 0; k < dim; ++k) mean[k] += f[k] / m;
            ca[bin((atan2(f[1], f[0]) + PI) / (2 * PI), 10)]++;
            if (dim == 3) cz[bin(0.5 * (f[2] / m + 1.0), 10)]++;
            double u = (ts[i] / taup - tmin) / (tmax - tmin);
            ck_assert(u >= -1e-12 && u <= 1 + 1e-12);
            ct[bin(u, 10)]++;
        }
        ck_assert_double_le(chi2(cm, 10, n), chi_max);
        ck_assert_double_le(chi2(ca, 10, n), chi_max);
        if (dim == 3) ck_assert_double_le(chi2(cz, 10, n), chi_max);
        ck_assert_double_le(chi2(ct, 10, n), chi_max);
        /* mean unit vector: each component ~ N(0, 1/(d N)); 5 sigma */
        for (int k = 0; k < dim; ++k) ck_assert_double_le(fabs(mean[k] / n), 5.0 / sqrt(dim * (double)n));
        /* mean square force against its expectation (sampling error ~1.5%) */
        ck_assert_double_le(fabs(f2 / n / (fp * fp) - 1.0), 0.05);
        /* time unit: the paper's tau with the expected f_ext */
        double tau;
        ck_assert_int_eq(odhs_driver_time_unit(s.drv, s.sys, &tau), ODHS_OK);
        ck_assert_double_eq_tol(tau, taup, 1e-14 * taup);
        free(F);
        free(ts);
        sim_free(&s);
    }
}
END_TEST

START_TEST(test_free_particles)
{
    /* no contacts: over every interval between switches each particle moves
     * by xi0 F dt exactly (Euler is exact for piecewise constant velocity);
     * two step sizes give the same trajectory to round-off */
    for (int dim = 2; dim <= 3; ++dim) {
        size_t n = dim == 2 ? 4 : 8, nd = n * dim;
        sim s[2];
        for (int v = 0; v < 2; ++v) {
            sim_make(&s[v], dilute_scene(dim, n, 50.0, NULL), "cg");
            ck_assert_int_eq(odhs_driver_set_mobility(s[v].drv, 2.5), ODHS_OK);
            ck_assert_int_eq(odhs_driver_set_self_propulsion(s[v].drv, n, dim, 0.5, 1.5, 1.0, 3.0, 11), ODHS_OK);
            ck_assert_int_eq(odhs_stepper_set_dt(s[v].st, v ? 0.7 : 0.013), ODHS_OK);
            ck_assert_int_eq(odhs_stepper_reset(s[v].st), ODHS_OK);
        }
        double *x0 = malloc(nd * sizeof *x0), *x1 = malloc(nd * sizeof *x1), *F = malloc(nd * sizeof *F);
        double *V = malloc(nd * sizeof *V), *y = malloc(nd * sizeof *y);
        double t0 = 0.0;
        for (int interval = 0; interval < 12; ++interval) {
            double t1;
            ck_assert_int_eq(odhs_system_get_positions(s[0].sys, x0), ODHS_OK);
            ck_assert_int_eq(odhs_driver_get_propulsion(s[0].drv, F, NULL), ODHS_OK);
            ck_assert_int_eq(odhs_stepper_velocities(s[0].st, V), ODHS_OK);
            for (size_t k = 0; k < nd; ++k) ck_assert_double_eq_tol(V[k], 2.5 * F[k], 1e-14);
            ck_assert_int_eq(odhs_driver_next_switch(s[0].drv, &t1), ODHS_OK);
            for (int v = 0; v < 2; ++v) ck_assert_int_eq(odhs_stepper_run_until_time(s[v].st, t1), ODHS_OK);
            ck_assert_int_eq(odhs_system_get_positions(s[0].sys, x1), ODHS_OK);
            ck_assert_int_eq(odhs_system_get_positions(s[1].sys, y), ODHS_OK);
            double L[3];
            odhs_system_get_box(s[0].sys, L);
            for (size_t i = 0; i < n; ++i)
                for (int k = 0; k < dim; ++k) {
                    double d = x1[i * dim + k] - x0[i * dim + k];
                    d -= L[k] * nearbyint(d / L[k]);
                    ck_assert_double_eq_tol(d, 2.5 * F[i * dim + k] * (t1 - t0), 1e-12);
                    ck_assert_double_eq_tol(y[i * dim + k], x1[i * dim + k], 1e-11);
                }
            t0 = t1;
        }
        uint64_t coll;
        odhs_stepper_counts(s[0].st, NULL, &coll, NULL);
        ck_assert_uint_eq(coll, 0);
        free(x0);
        free(x1);
        free(F);
        free(V);
        free(y);
        sim_free(&s[0]);
        sim_free(&s[1]);
    }
}
END_TEST

typedef struct {
    odhs_event ev[8];
    int n;
} evlog;

static int log_ev(const odhs_event *e, void *ctx)
{
    evlog *l = ctx;
    if (l->n < 8) l->ev[l->n] = *e;
    l->n++;
    return 0;
}

START_TEST(test_head_on)
{
    for (int dim = 2; dim <= 3; ++dim) {
        const double xi0 = 0.8, r0 = 0.5, r1 = 0.6, sig = r0 + r1, D = sig + 2.3;
        odhs_system *sys;
        ck_assert_int_eq(odhs_system_create(dim, 2, &sys), ODHS_OK);
        odhs_driver *drv;
        ck_assert_int_eq(odhs_driver_create(&drv), ODHS_OK);
        ck_assert_int_eq(odhs_driver_set_mobility(drv, xi0), ODHS_OK);
        /* long persistence: no switch during the test */
        ck_assert_int_eq(odhs_driver_set_self_propulsion(drv, 2, dim, 0.5, 1.0, 100.0, 100.0, 99), ODHS_OK);
        double F[6], w[3], wn = 0.0;
        ck_assert_int_eq(odhs_driver_get_propulsion(drv, F, NULL), ODHS_OK);
        for (int k = 0; k < dim; ++k) {
            w[k] = F[dim + k] - F[k];
            wn += w[k] * w[k];
        }
        wn = sqrt(wn);
        /* particle 1 placed behind particle 0 along -w: they meet head-on */
        double L[3] = {20, 20, 20}, r[2] = {r0, r1}, x[6];
        for (int k = 0; k < dim; ++k) {
            x[k] = 10.0;
            x[dim + k] = 10.0 - D * w[k] / wn;
        }
        ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
        odhs_solver *sol;
        odhs_stepper *st;
        ck_assert_int_eq(odhs_solver_create_by_name("dense", &sol), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_create(sys, drv, sol, &st), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_set_dt(st, 0.05), ODHS_OK);
        evlog log = {.n = 0};
        ck_assert_int_eq(odhs_stepper_set_event_callback(st, log_ev, &log), ODHS_OK);
        double tc = (D - sig) / (xi0 * wn);
        ck_assert_int_eq(odhs_stepper_run_until_time(st, 2.0 * tc), ODHS_OK);
        ck_assert_int_eq(log.n, 1);
        ck_assert_int_eq(log.ev[0].kind, ODHS_EVENT_COLLISION);
        ck_assert_double_eq_tol(log.ev[0].time, tc, 1e-12 * tc);
        const odhs_network *net = odhs_stepper_network(st);
        ck_assert_uint_eq(odhs_network_count(net), 1);
        double f;
        ck_assert_int_eq(odhs_network_get_forces(net, &f), ODHS_OK);
        ck_assert_double_eq_tol(f, 0.5 * wn, 1e-12 * wn);
        double V[6];
        ck_assert_int_eq(odhs_stepper_velocities(st, V), ODHS_OK);
        for (int k = 0; k < dim; ++k) {
            double vk = 0.5 * xi0 * (F[k] + F[dim + k]);
            /* the line of centres carries the round-off of ~100 steps */
            ck_assert_double_eq_tol(V[k], vk, 1e-12);
            ck_assert_double_eq_tol(V[dim + k], vk, 1e-12);
        }
        double gap;
        ck_assert_int_eq(odhs_stepper_errors(st, &gap, NULL), ODHS_OK);
        ck_assert_double_le(gap, 1e-12);
        odhs_stepper_destroy(st);
        odhs_solver_destroy(sol);
        odhs_driver_destroy(drv);
        odhs_system_destroy(sys);
    }
}
END_TEST

START_TEST(test_gravity)
{
    for (int dim = 2; dim <= 3; ++dim) {
        /* a single particle: V = xi0 g (weight 1: it has the mean size) */
        {
            double r1 = 0.7;
            sim s;
            sim_make(&s, dilute_scene(dim, 1, 10.0, &r1), "cg");
            double g[3] = {0.3, -2.0, 0.5}, V[3];
            ck_assert_int_eq(odhs_driver_set_mobility(s.drv, 1.5), ODHS_OK);
            ck_assert_int_eq(odhs_driver_set_gravity(s.drv, dim, g), ODHS_OK);
            ck_assert_int_eq(odhs_stepper_reset(s.st), ODHS_OK);
            ck_assert_int_eq(odhs_stepper_velocities(s.st, V), ODHS_OK);
            for (int k = 0; k < dim; ++k) ck_assert_double_eq_tol(V[k], 1.5 * g[k], 1e-15);
            sim_free(&s);
        }
        const size_t n = 4;
        double r[4] = {0.3, 0.5, 0.6, 0.8}, amean = 0.55, xi0 = 0.7;
        double g[3] = {0.0, -3.0, 0.0};
        if (dim == 3) {
            g[1] = 1.0;
            g[2] = -2.0;
        }
        sim s;
        sim_make(&s, dilute_scene(dim, n, 8.0, r), "cg");
        ck_assert_int_eq(odhs_driver_set_mobility(s.drv, xi0), ODHS_OK);
        ck_assert_int_eq(odhs_driver_set_gravity(s.drv, dim, g), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_reset(s.st), ODHS_OK);
        double V[12], w[4], w2 = 0.0, g2 = 0.0;
        ck_assert_int_eq(odhs_stepper_velocities(s.st, V), ODHS_OK);
        for (size_t i = 0; i < n; ++i) {
            w[i] = pow(r[i] / amean, dim);
            w2 += w[i] * w[i];
            for (int k = 0; k < dim; ++k) ck_assert_double_eq_tol(V[i * dim + k], xi0 * w[i] * g[k], 1e-13);
        }
        for (int k = 0; k < dim; ++k) g2 += g[k] * g[k];
        /* time unit: lambda / (xi0 f_rms), f_rms = |g| sqrt(<w^2>) */
        double tau, want = 2.0 * amean / (xi0 * sqrt(g2 * w2 / n));
        ck_assert_int_eq(odhs_driver_time_unit(s.drv, s.sys, &tau), ODHS_OK);
        ck_assert_double_eq_tol(tau, want, 1e-13 * want);
        /* the particles fall: after time T, displaced by xi0 w g T */
        double x0[12], x1[12], T = 0.9;
        ck_assert_int_eq(odhs_stepper_set_dt(s.st, 0.05), ODHS_OK);
        odhs_system_get_positions(s.sys, x0);
        ck_assert_int_eq(odhs_stepper_run_until_time(s.st, T), ODHS_OK);
        odhs_system_get_positions(s.sys, x1);
        for (size_t i = 0; i < n; ++i)
            for (int k = 0; k < dim; ++k) {
                double d = x1[i * dim + k] - x0[i * dim + k], L = 16.0;
                d -= L * nearbyint(d / L);
                ck_assert_double_eq_tol(d, xi0 * w[i] * g[k] * T, 1e-12);
            }
        /* user weights (a negative one rises) plus propulsion: forces add */
        double uw[4] = {1.0, -0.5, 2.0, 0.0}, F[12];
        ck_assert_int_eq(odhs_driver_set_gravity_weights(s.drv, n, uw), ODHS_OK);
        ck_assert_int_eq(odhs_driver_set_self_propulsion(s.drv, n, dim, 0.1, 0.2, 5.0, 5.0, 3), ODHS_OK);
        ck_assert_int_eq(odhs_driver_get_propulsion(s.drv, F, NULL), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_step(s.st, NULL), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_velocities(s.st, V), ODHS_OK);
        for (size_t i = 0; i < n; ++i)
            for (int k = 0; k < dim; ++k)
                ck_assert_double_eq_tol(V[i * dim + k], xi0 * (F[i * dim + k] + uw[i] * g[k]), 1e-13);
        /* weights for another N fail the step */
        ck_assert_int_eq(odhs_driver_set_gravity_weights(s.drv, 3, uw), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_step(s.st, NULL), ODHS_E_DIM);
        ck_assert_int_eq(odhs_driver_set_gravity_weights(s.drv, 0, NULL), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_step(s.st, NULL), ODHS_OK);
        /* removing gravity and propulsion: at rest */
        ck_assert_int_eq(odhs_driver_set_gravity(s.drv, dim, NULL), ODHS_OK);
        ck_assert_int_eq(odhs_driver_clear_self_propulsion(s.drv), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_step(s.st, NULL), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_velocities(s.st, V), ODHS_OK);
        for (size_t k = 0; k < n * dim; ++k) ck_assert(V[k] == 0.0);
        sim_free(&s);
    }
}
END_TEST

START_TEST(test_sediment_on_contact)
{
    /* gravity pushes a heavy disc onto a light one held by an opposite fixed
     * force: the contact force balances the difference (f = (m1 g - F)/2
     * along the line when the two sit on a vertical line) */
    double L[2] = {12, 12}, r[2] = {0.5, 0.5}, x[4] = {6.0, 5.0, 6.0, 6.4};
    odhs_system *sys;
    ck_assert_int_eq(odhs_system_create(2, 2, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
    sim s;
    sim_make(&s, sys, "dense");
    double g[2] = {0.0, -1.0}, w[2] = {0.0, 3.0}, Ffix[4] = {0.0, 1.0, 0.0, 0.0};
    ck_assert_int_eq(odhs_driver_set_gravity(s.drv, 2, g), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_gravity_weights(s.drv, 2, w), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_forces(s.drv, 2, 2, Ffix), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_time(s.st, 2.0), ODHS_OK);
    const odhs_network *net = odhs_stepper_network(s.st);
    ck_assert_uint_eq(odhs_network_count(net), 1);
    double f, V[4];
    odhs_network_get_forces(net, &f);
    /* relative force along the line: 0 pushed up by 1, 1 pulled down by 3 */
    ck_assert_double_eq_tol(f, 0.5 * (3.0 + 1.0), 1e-12);
    ck_assert_int_eq(odhs_stepper_velocities(s.st, V), ODHS_OK);
    ck_assert_double_eq_tol(V[1], -1.0, 1e-12); /* the pair sinks with (1 - 3)/2 */
    ck_assert_double_eq_tol(V[3], -1.0, 1e-12);
    sim_free(&s);
}
END_TEST

START_TEST(test_rate_invariance)
{
    /* forces x2, xi0 x4: tau / 8; the trajectory in units of tau is the same */
    sim a, b;
    size_t n = 40;
    sim_make(&a, dense_scene(n, 8), "dense");
    sim_make(&b, dense_scene(n, 8), "dense");
    ck_assert_int_eq(odhs_driver_set_self_propulsion(a.drv, n, 2, 0.2, 1.0, 0.5, 3.0, 77), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_self_propulsion(b.drv, n, 2, 0.4, 2.0, 0.5, 3.0, 77), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_mobility(b.drv, 4.0), ODHS_OK);
    double ta, tb;
    ck_assert_int_eq(odhs_driver_time_unit(a.drv, a.sys, &ta), ODHS_OK);
    ck_assert_int_eq(odhs_driver_time_unit(b.drv, b.sys, &tb), ODHS_OK);
    ck_assert(ta == 8.0 * tb);
    ck_assert_int_eq(odhs_stepper_set_dt(a.st, 0.01), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_set_dt(b.st, 0.01), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_time(a.st, 4.0 * ta), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_time(b.st, 4.0 * tb), ODHS_OK);
    double xa[80], xb[80], tsa[40], tsb[40];
    odhs_system_get_positions(a.sys, xa);
    odhs_system_get_positions(b.sys, xb);
    for (size_t k = 0; k < 2 * n; ++k) ck_assert_double_eq_tol(xa[k], xb[k], 1e-12);
    ck_assert_int_eq(odhs_driver_get_propulsion(a.drv, NULL, tsa), ODHS_OK);
    ck_assert_int_eq(odhs_driver_get_propulsion(b.drv, NULL, tsb), ODHS_OK);
    for (size_t i = 0; i < n; ++i) ck_assert_double_eq_tol(tsa[i], 8.0 * tsb[i], 1e-13 * tsa[i]);
    uint64_t ca, cb;
    odhs_stepper_counts(a.st, NULL, &ca, NULL);
    odhs_stepper_counts(b.st, NULL, &cb, NULL);
    ck_assert_uint_eq(ca, cb);
    ck_assert_uint_gt(ca, 10);
    sim_free(&a);
    sim_free(&b);
}
END_TEST

START_TEST(test_with_shear)
{
    /* propulsion combined with shear: the time unit is the shear's, the
     * persistence unit stays tau_p, and the stepper still ends steps on
     * switches */
    sim s;
    size_t n = 32;
    sim_make(&s, dense_scene(n, 4), "dense");
    ck_assert_int_eq(odhs_driver_set_shear_rate(s.drv, 0.5), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_self_propulsion(s.drv, n, 2, 1.0, 1.0, 0.1, 0.3, 1), ODHS_OK);
    double tau;
    ck_assert_int_eq(odhs_driver_time_unit(s.drv, s.sys, &tau), ODHS_OK);
    ck_assert(tau == 2.0);
    ck_assert_int_eq(odhs_stepper_reset(s.st), ODHS_OK);
    double ts[32], lam = mean_diameter(s.sys);
    ck_assert_int_eq(odhs_driver_get_propulsion(s.drv, NULL, ts), ODHS_OK);
    for (size_t i = 0; i < n; ++i) ck_assert(ts[i] >= 0.1 * lam * (1 - 1e-14) && ts[i] <= 0.3 * lam * (1 + 1e-14));
    int hits = 0;
    ck_assert_int_eq(odhs_stepper_set_dt(s.st, 0.01), ODHS_OK);
    for (int k = 0; k < 300; ++k) {
        double tn, t;
        ck_assert_int_eq(odhs_driver_next_switch(s.drv, &tn), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_step(s.st, NULL), ODHS_OK);
        odhs_stepper_time(s.st, &t);
        ck_assert(t <= tn);
        hits += t == tn;
    }
    ck_assert_int_gt(hits, 20);
    double gap, ov;
    ck_assert_int_eq(odhs_stepper_errors(s.st, &gap, &ov), ODHS_OK);
    ck_assert_double_le(ov, 1e-9);
    sim_free(&s);
}
END_TEST

Suite *make_propulsion_suite(void)
{
    Suite *s = suite_create("propulsion");
    TCase *tc = tcase_create("propulsion");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_statistics);
    tcase_add_test(tc, test_switch_exact);
    tcase_add_test(tc, test_free_particles);
    tcase_add_test(tc, test_head_on);
    tcase_add_test(tc, test_gravity);
    tcase_add_test(tc, test_sediment_on_contact);
    tcase_add_test(tc, test_reproducible);
    tcase_add_test(tc, test_checkpoint_split);
    tcase_add_test(tc, test_rate_invariance);
    tcase_add_test(tc, test_with_shear);
    suite_add_tcase(s, tc);
    return s;
}
