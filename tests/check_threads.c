/*
 * libodhs - thread tests: separate handles in separate threads (docs/guide.md,
 * "Threads": the library has no global mutable state).
 *
 * One unit of work builds a scene (bidisperse radii, random placement),
 * compresses it a little and shears it with the stepper (with an event
 * callback), applies the drift correction, writes the configuration to an
 * XYZ file of its own and reads it back, then solves with a second solver
 * handle on the stepper's network (N x = S g and the least-squares form) and
 * on a network detected from the re-read system. Everything it produced is
 * kept and compared bit for bit:
 *   - the same work in 4 threads at once must equal a serial run;
 *   - different work in each of 4 threads must equal each work's serial run
 *     (2D/3D, Euler/Heun, solvers cg, dense and, when built in, cholmod and
 *     spqr);
 *   - concurrent XYZ parsing/writing (good and bad inputs, one directory) and
 *     solver creation by name must behave as in a single thread.
 * Worker threads never call ck_assert (Check's no-fork mode longjmps out of
 * the test): they record the first failure and the main thread asserts.
 * `make check-tsan` runs this suite under ThreadSanitizer.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <check.h>
#include <dirent.h>
#include <pthread.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "odhs.h"

#define NTHREADS 4

/* ---- a private directory for the files of one test ---------------------- */
static char th_dir[64];

static void th_setup(void)
{
    strcpy(th_dir, "/tmp/odhs-threads-XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(th_dir));
}

static void th_teardown(void)
{
    DIR *d = opendir(th_dir);
    if (d) {
        struct dirent *e;
        char p[600];
        while ((e = readdir(d)) != NULL) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
            snprintf(p, sizeof p, "%s/%s", th_dir, e->d_name);
            remove(p);
        }
        closedir(d);
    }
    rmdir(th_dir);
}

/* ---- one unit of work ------------------------------------------------------ */
typedef struct {
    int dim;
    size_t n;
    uint64_t seed;
    const char *solver; /* name for odhs_solver_create_by_name */
    int integrator;     /* ODHS_INTEGRATOR_* */
    double phi_place, phi_target, strain;
    char path[160]; /* XYZ file of this unit */
} work;

typedef struct {
    /* first failure: 0 = none */
    int fail_line, fail_rc;
    char fail_msg[600];
    /* system after the run */
    int dim;
    size_t n;
    double L[3], gamma, phi;
    double *x, *r;
    /* stepper */
    double time, strain, sigma[9], p, z, kappa, D, P, gap_err, overlap;
    uint64_t steps, coll, open, events_seen;
    double *V;
    size_t nc;
    size_t *ci, *cj;
    double *f;
    /* re-read file */
    double Lr[3], gammar;
    double *xr, *rr;
    /* solves */
    double *x_ls, *x_n, *x_det;
    size_t nc_det;
    double res_ls, res_n;
} result;

static void result_free(result *r)
{
    free(r->x);
    free(r->r);
    free(r->V);
    free(r->ci);
    free(r->cj);
    free(r->f);
    free(r->xr);
    free(r->rr);
    free(r->x_ls);
    free(r->x_n);
    free(r->x_det);
    memset(r, 0, sizeof *r);
}

/* record the first failure and leave the work function */
#define TH_OK(res, expr, errmsg_expr)                                                            \
    do {                                                                                        \
        int w_rc_ = (expr);                                                                     \
        if (w_rc_ < 0 && !(res)->fail_line) {                                                   \
            (res)->fail_line = __LINE__;                                                        \
            (res)->fail_rc = w_rc_;                                                             \
            snprintf((res)->fail_msg, sizeof (res)->fail_msg, "%s -> %d (%s): %s", #expr, w_rc_, \
                     odhs_strerror(w_rc_), (errmsg_expr));                                      \
        }                                                                                       \
        if (w_rc_ < 0) goto done;                                                               \
    } while (0)

#define TH_TRUE(res, cond)                                                                     \
    do {                                                                                      \
        if (!(cond)) {                                                                        \
            if (!(res)->fail_line) {                                                          \
                (res)->fail_line = __LINE__;                                                  \
                (res)->fail_rc = ODHS_E_INTERNAL;                                             \
                snprintf((res)->fail_msg, sizeof (res)->fail_msg, "condition failed: %s", #cond); \
            }                                                                                 \
            goto done;                                                                        \
        }                                                                                     \
    } while (0)

static int count_events(const odhs_event *ev, void *ctx)
{
    (void)ev;
    ++*(uint64_t *)ctx;
    return 0;
}

/* splitmix64: deterministic right-hand sides, independent of the library */
static double th_uniform(uint64_t *s)
{
    uint64_t z = (*s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    z ^= z >> 31;
    return (double)(z >> 11) * 0x1.0p-53 * 2.0 - 1.0;
}

static void do_work(const work *w, result *res)
{
    odhs_system *sys = NULL, *back = NULL;
    odhs_driver *drv = NULL;
    odhs_solver *sol = NULL, *sol2 = NULL;
    odhs_stepper *st = NULL;
    odhs_network *det = NULL;
    double *g = NULL;
    char err[256] = "";

    memset(res, 0, sizeof *res);
    res->dim = w->dim;
    res->n = w->n;
    size_t nd = w->n * (size_t)w->dim;

    /* scene */
    TH_OK(res, odhs_system_create(w->dim, w->n, &sys), "create");
    TH_OK(res, odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, w->seed), odhs_system_errmsg(sys));
    TH_OK(res, odhs_system_place_random(sys, w->phi_place, w->seed), odhs_system_errmsg(sys));

    /* compress a little, then shear */
    TH_OK(res, odhs_driver_create(&drv), "driver");
    TH_OK(res, odhs_driver_set_compression_rate(drv, 1.0), odhs_driver_errmsg(drv));
    TH_OK(res, odhs_solver_create_by_name(w->solver, &sol), w->solver);
    TH_OK(res, odhs_stepper_create(sys, drv, sol, &st), odhs_system_errmsg(sys));
    TH_OK(res, odhs_stepper_set_integrator(st, w->integrator), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_stepper_set_event_callback(st, count_events, &res->events_seen), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_stepper_run_until_packing_fraction(st, w->phi_target), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_driver_set_compression_rate(drv, 0.0), odhs_driver_errmsg(drv));
    TH_OK(res, odhs_driver_set_shear_rate(drv, 1.0), odhs_driver_errmsg(drv));
    TH_OK(res, odhs_stepper_reset(st), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_stepper_run_until_strain(st, w->strain), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_stepper_correct(st), odhs_stepper_errmsg(st));

    /* observables */
    TH_OK(res, odhs_stepper_time(st, &res->time), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_stepper_strain(st, &res->strain), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_stepper_stress(st, res->sigma), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_stepper_pressure(st, &res->p), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_stepper_coordination(st, &res->z), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_stepper_kappa(st, &res->kappa), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_stepper_dissipation(st, &res->D), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_stepper_power(st, &res->P), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_stepper_errors(st, &res->gap_err, &res->overlap), odhs_stepper_errmsg(st));
    TH_OK(res, odhs_stepper_counts(st, &res->steps, &res->coll, &res->open), odhs_stepper_errmsg(st));
    res->V = calloc(nd, sizeof *res->V);
    TH_TRUE(res, res->V != NULL);
    TH_OK(res, odhs_stepper_velocities(st, res->V), odhs_stepper_errmsg(st));

    const odhs_network *net = odhs_stepper_network(st);
    TH_TRUE(res, net != NULL);
    res->nc = odhs_network_count(net);
    size_t ncap = res->nc ? res->nc : 1;
    res->ci = calloc(ncap, sizeof *res->ci);
    res->cj = calloc(ncap, sizeof *res->cj);
    res->f = calloc(ncap, sizeof *res->f);
    TH_TRUE(res, res->ci && res->cj && res->f);
    for (size_t c = 0; c < res->nc; ++c)
        TH_OK(res, odhs_network_get_contact(net, c, &res->ci[c], &res->cj[c], NULL), odhs_network_errmsg(net));
    TH_OK(res, odhs_network_get_forces(net, res->f), odhs_network_errmsg(net));

    /* system state */
    res->x = calloc(nd, sizeof *res->x);
    res->r = calloc(w->n, sizeof *res->r);
    TH_TRUE(res, res->x && res->r);
    TH_OK(res, odhs_system_get_positions(sys, res->x), odhs_system_errmsg(sys));
    TH_OK(res, odhs_system_get_radii(sys, res->r), odhs_system_errmsg(sys));
    TH_OK(res, odhs_system_get_box(sys, res->L), odhs_system_errmsg(sys));
    TH_OK(res, odhs_system_get_strain(sys, &res->gamma), odhs_system_errmsg(sys));
    TH_OK(res, odhs_system_packing_fraction(sys, &res->phi), odhs_system_errmsg(sys));

    /* XYZ round trip through this unit's own file */
    TH_OK(res, odhs_xyz_write(sys, w->path), odhs_system_errmsg(sys));
    TH_OK(res, odhs_xyz_read(w->path, &back, err, sizeof err), err);
    res->xr = calloc(nd, sizeof *res->xr);
    res->rr = calloc(w->n, sizeof *res->rr);
    TH_TRUE(res, res->xr && res->rr);
    TH_OK(res, odhs_system_get_positions(back, res->xr), odhs_system_errmsg(back));
    TH_OK(res, odhs_system_get_radii(back, res->rr), odhs_system_errmsg(back));
    TH_OK(res, odhs_system_get_box(back, res->Lr), odhs_system_errmsg(back));
    TH_OK(res, odhs_system_get_strain(back, &res->gammar), odhs_system_errmsg(back));

    /* solves with a second solver handle: least squares and N x = S g on the
     * stepper's network, then N x = S g on a network detected afresh */
    TH_OK(res, odhs_solver_create_by_name(w->solver, &sol2), w->solver);
    g = calloc(nd, sizeof *g);
    res->x_ls = calloc(ncap, sizeof *res->x_ls);
    res->x_n = calloc(ncap, sizeof *res->x_n);
    TH_TRUE(res, g && res->x_ls && res->x_n);
    uint64_t rs = w->seed * 7919u + 1u;
    for (size_t k = 0; k < nd; ++k) g[k] = th_uniform(&rs);
    TH_OK(res, odhs_solver_solve_ls(sol2, net, g, res->x_ls), odhs_solver_errmsg(sol2));
    TH_OK(res, odhs_solver_get_stat(sol2, "residual", &res->res_ls), odhs_solver_errmsg(sol2));
    {
        double *b = calloc(ncap, sizeof *b);
        TH_TRUE(res, b != NULL);
        int rc = odhs_network_apply_S(net, g, b);
        if (rc == ODHS_OK) rc = odhs_solver_solve(sol2, net, b, res->x_n);
        free(b);
        TH_OK(res, rc, odhs_solver_errmsg(sol2));
    }
    TH_OK(res, odhs_solver_get_stat(sol2, "residual", &res->res_n), odhs_solver_errmsg(sol2));

    TH_OK(res, odhs_network_create(back, &det), "network");
    TH_OK(res, odhs_network_detect(det, back, 1e-9), odhs_network_errmsg(det));
    res->nc_det = odhs_network_count(det);
    res->x_det = calloc(res->nc_det ? res->nc_det : 1, sizeof *res->x_det);
    TH_TRUE(res, res->x_det != NULL);
    TH_OK(res, odhs_solver_solve_ls(sol2, det, g, res->x_det), odhs_solver_errmsg(sol2));

done:
    free(g);
    odhs_network_destroy(det);
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol2);
    odhs_solver_destroy(sol);
    odhs_driver_destroy(drv);
    odhs_system_destroy(back);
    odhs_system_destroy(sys);
}

/* ---- bit-for-bit comparison ----------------------------------------------- */
static int same_bits(const void *a, const void *b, size_t bytes)
{
    if (bytes == 0) return 1;
    if (!a || !b) return 0;
    return memcmp(a, b, bytes) == 0;
}

/* "" if equal, else the name of the first differing field */
static const char *result_diff(const result *a, const result *b)
{
    size_t nd = a->n * (size_t)a->dim, D = sizeof(double);
    if (a->fail_line || b->fail_line) return "a run failed";
    if (a->dim != b->dim || a->n != b->n) return "dim/n";
#define CMP(field, bytes) \
    if (!same_bits(a->field, b->field, (bytes))) return #field
#define CMPV(field) \
    if (!same_bits(&a->field, &b->field, sizeof a->field)) return #field
    CMPV(L);
    CMPV(gamma);
    CMPV(phi);
    CMP(x, nd * D);
    CMP(r, a->n * D);
    CMPV(time);
    CMPV(strain);
    CMPV(sigma);
    CMPV(p);
    CMPV(z);
    CMPV(kappa);
    CMPV(D);
    CMPV(P);
    CMPV(gap_err);
    CMPV(overlap);
    CMPV(steps);
    CMPV(coll);
    CMPV(open);
    CMPV(events_seen);
    CMP(V, nd * D);
    CMPV(nc);
    CMP(ci, a->nc * sizeof(size_t));
    CMP(cj, a->nc * sizeof(size_t));
    CMP(f, a->nc * D);
    CMPV(Lr);
    CMPV(gammar);
    CMP(xr, nd * D);
    CMP(rr, a->n * D);
    CMP(x_ls, a->nc * D);
    CMP(x_n, a->nc * D);
    CMPV(res_ls);
    CMPV(res_n);
    CMPV(nc_det);
    CMP(x_det, a->nc_det * D);
#undef CMP
#undef CMPV
    return "";
}

static void assert_ran(const result *r, const char *what)
{
    ck_assert_msg(r->fail_line == 0, "%s: failed at line %d: %s", what, r->fail_line, r->fail_msg);
}

/* ---- threads ------------------------------------------------------------------ */
typedef struct {
    const work *w;
    result *res;
    int repeat; /* run the work this many times; keep the last result */
} job;

static void *job_main(void *arg)
{
    job *j = arg;
    for (int k = 0; k < j->repeat; ++k) {
        result_free(j->res);
        do_work(j->w, j->res);
        if (j->res->fail_line) break;
    }
    return NULL;
}

static void run_threads(job *jobs, int n)
{
    pthread_t tid[NTHREADS];
    ck_assert_int_le(n, NTHREADS);
    for (int t = 0; t < n; ++t) ck_assert_int_eq(pthread_create(&tid[t], NULL, job_main, &jobs[t]), 0);
    for (int t = 0; t < n; ++t) ck_assert_int_eq(pthread_join(tid[t], NULL), 0);
}

static void work_init(work *w, int dim, size_t n, uint64_t seed, const char *solver, int integrator,
                      const char *tag)
{
    memset(w, 0, sizeof *w);
    w->dim = dim;
    w->n = n;
    w->seed = seed;
    w->solver = solver;
    w->integrator = integrator;
    w->phi_place = dim == 2 ? 0.45 : 0.30;
    w->phi_target = dim == 2 ? 0.72 : 0.48;
    w->strain = 0.05;
    snprintf(w->path, sizeof w->path, "%s/%s.xyz", th_dir, tag);
}

static int solver_available(const char *name)
{
    odhs_solver *s = NULL;
    int rc = odhs_solver_create_by_name(name, &s);
    odhs_solver_destroy(s);
    return rc == ODHS_OK;
}

/* ========================================================================== */
START_TEST(test_same_work_matches_serial)
{
    /* serial reference, then 4 threads at once, each with its own handles and
     * file; every thread's result must equal the reference bit for bit */
    work ws;
    work_init(&ws, 2, 48, 4242, "cg", ODHS_INTEGRATOR_EULER, "serial");
    result ref;
    memset(&ref, 0, sizeof ref);
    do_work(&ws, &ref);
    assert_ran(&ref, "serial run");
    ck_assert_msg(ref.steps > 0 && ref.nc > 0, "the reference run did nothing (steps %llu, contacts %zu)",
                  (unsigned long long)ref.steps, ref.nc);

    work w[NTHREADS];
    result res[NTHREADS];
    job jobs[NTHREADS];
    memset(res, 0, sizeof res);
    for (int t = 0; t < NTHREADS; ++t) {
        char tag[32];
        snprintf(tag, sizeof tag, "same%d", t);
        w[t] = ws;
        snprintf(w[t].path, sizeof w[t].path, "%s/%s.xyz", th_dir, tag);
        jobs[t] = (job){&w[t], &res[t], 2};
    }
    run_threads(jobs, NTHREADS);
    for (int t = 0; t < NTHREADS; ++t) {
        char what[32];
        snprintf(what, sizeof what, "thread %d", t);
        assert_ran(&res[t], what);
        const char *d = result_diff(&ref, &res[t]);
        ck_assert_msg(d[0] == '\0', "thread %d differs from the serial run in %s", t, d);
    }
    fprintf(stderr, "[threads] same work x%d: %llu steps, %llu events, %zu contacts, bit-identical\n", NTHREADS,
            (unsigned long long)ref.steps, (unsigned long long)ref.events_seen, ref.nc);
    for (int t = 0; t < NTHREADS; ++t) result_free(&res[t]);
    result_free(&ref);
}
END_TEST

START_TEST(test_different_work_matches_serial)
{
    /* four different units (2D/3D, cg/dense, Euler/Heun) run serially, then
     * all at once; each concurrent result must equal its serial one */
    /* the SuiteSparse backends when this library has them (each backend state
     * owns its own cholmod_common), else cg and dense again */
    work w[NTHREADS];
    const char *sparse1 = solver_available("cholmod") ? "cholmod" : "cg";
    const char *sparse2 = solver_available("spqr") ? "spqr" : "dense";
    work_init(&w[0], 2, 32, 11, "cg", ODHS_INTEGRATOR_EULER, "diff0");
    work_init(&w[1], 3, 24, 12, sparse1, ODHS_INTEGRATOR_EULER, "diff1");
    work_init(&w[2], 2, 24, 13, "dense", ODHS_INTEGRATOR_HEUN, "diff2");
    work_init(&w[3], 3, 20, 14, sparse2, ODHS_INTEGRATOR_EULER, "diff3");
    result ref[NTHREADS], res[NTHREADS];
    job jobs[NTHREADS];
    memset(ref, 0, sizeof ref);
    memset(res, 0, sizeof res);
    for (int t = 0; t < NTHREADS; ++t) {
        char what[32];
        do_work(&w[t], &ref[t]);
        snprintf(what, sizeof what, "serial work %d", t);
        assert_ran(&ref[t], what);
        ck_assert_msg(ref[t].steps > 0, "work %d took no step", t);
    }
    for (int t = 0; t < NTHREADS; ++t) jobs[t] = (job){&w[t], &res[t], 1};
    run_threads(jobs, NTHREADS);
    for (int t = 0; t < NTHREADS; ++t) {
        char what[32];
        snprintf(what, sizeof what, "thread %d", t);
        assert_ran(&res[t], what);
        const char *d = result_diff(&ref[t], &res[t]);
        ck_assert_msg(d[0] == '\0', "work %d (d=%d, %s) in a thread differs from its serial run in %s", t,
                      w[t].dim, w[t].solver, d);
        fprintf(stderr, "[threads] work %d (d=%d, N=%zu, %s, %s): %llu steps, %zu contacts, bit-identical\n", t,
                w[t].dim, w[t].n, w[t].solver, w[t].integrator == ODHS_INTEGRATOR_HEUN ? "heun" : "euler",
                (unsigned long long)ref[t].steps, ref[t].nc);
    }
    for (int t = 0; t < NTHREADS; ++t) {
        result_free(&ref[t]);
        result_free(&res[t]);
    }
}
END_TEST

/* ---- XYZ parsing and writing, and solver creation, from 4 threads ----------- */
static const char *const xyz_inputs[] = {
    "2\nLattice=\"4 0 0 0 4 0 0 0 4\" Properties=species:S:1:pos:R:3:radius:R:1\nA 1 1 1 0.5\nB 3 3 3 0.6\n",
    "1\nLattice=\"4 0 0 1 4 0 0 0 1\" Properties=species:S:1:pos:R:3:radius:R:1 pbc=\"T T F\"\nA 9 -3 0 0.5\n",
    "2\nLattice=\"4 0 0 0 4 0 0 0 4\" Properties=species:S:1:pos:R:3:radius:R:1\nA 1 1 1 0.5\nB 1.2 1 1 0.5\n",
    "2\nLattice=\"4 0 0 0 4 0 0 0 4\" Properties=species:S:1:pos:R:3:radius:R:1\nA 1 1 1 0.5\n",
    "1\nLattice=\"4 0 0 0 4 0 0 0 4\" Properties=species:S:1:pos:R:2:radius:R:1\nA 1 1 0.5\n",
    "x\n",
};
#define N_XYZ (sizeof xyz_inputs / sizeof xyz_inputs[0])

typedef struct {
    int rc[N_XYZ];
    char msg[N_XYZ][256];
    double x[N_XYZ][6]; /* positions of the parsed systems (N <= 2, d <= 3) */
    int write_rc[N_XYZ], reread_rc[N_XYZ];
    int solver_rc[4];
    int id;
    int fail;
} xyz_job;

static void *xyz_main(void *arg)
{
    xyz_job *j = arg;
    static const char *const names[4] = {"cg", "dense", "cholmod", "spqr"}; /* last two may be absent */
    for (int rep = 0; rep < 20; ++rep) {
        for (size_t k = 0; k < N_XYZ; ++k) {
            odhs_system *sys = NULL;
            j->rc[k] = odhs_xyz_parse(xyz_inputs[k], strlen(xyz_inputs[k]), &sys, j->msg[k], sizeof j->msg[k]);
            if (sys) {
                odhs_system_get_positions(sys, j->x[k]);
                char path[200];
                snprintf(path, sizeof path, "%s/t%d.xyz", th_dir, j->id); /* same directory for all */
                j->write_rc[k] = odhs_xyz_write(sys, path);
                odhs_system *back = NULL;
                j->reread_rc[k] = odhs_xyz_read(path, &back, NULL, 0);
                odhs_system_destroy(back);
                remove(path);
            }
            odhs_system_destroy(sys);
        }
        for (int s = 0; s < 4; ++s) {
            odhs_solver *sol = NULL;
            j->solver_rc[s] = odhs_solver_create_by_name(names[s], &sol);
            if ((j->solver_rc[s] == ODHS_OK) != (sol != NULL)) j->fail = 1;
            odhs_solver_destroy(sol);
        }
    }
    return NULL;
}

START_TEST(test_xyz_and_solvers_concurrent)
{
    xyz_job ref, jobs[NTHREADS];
    memset(&ref, 0, sizeof ref);
    memset(jobs, 0, sizeof jobs);
    ref.id = 99;
    xyz_main(&ref);
    ck_assert_int_eq(ref.fail, 0);
    ck_assert_int_eq(ref.rc[0], ODHS_OK);
    ck_assert_int_eq(ref.rc[1], ODHS_OK);
    ck_assert_int_eq(ref.rc[2], ODHS_E_OVERLAP);
    ck_assert_int_eq(ref.rc[3], ODHS_E_FORMAT);
    ck_assert_int_eq(ref.rc[4], ODHS_E_FORMAT);
    ck_assert_int_eq(ref.rc[5], ODHS_E_FORMAT);
    pthread_t tid[NTHREADS];
    for (int t = 0; t < NTHREADS; ++t) {
        jobs[t].id = t;
        ck_assert_int_eq(pthread_create(&tid[t], NULL, xyz_main, &jobs[t]), 0);
    }
    for (int t = 0; t < NTHREADS; ++t) ck_assert_int_eq(pthread_join(tid[t], NULL), 0);
    for (int t = 0; t < NTHREADS; ++t) {
        ck_assert_int_eq(jobs[t].fail, 0);
        for (size_t k = 0; k < N_XYZ; ++k) {
            ck_assert_msg(jobs[t].rc[k] == ref.rc[k], "thread %d input %zu: %d, serial %d", t, k, jobs[t].rc[k],
                          ref.rc[k]);
            ck_assert_msg(strcmp(jobs[t].msg[k], ref.msg[k]) == 0, "thread %d input %zu: message '%s' vs '%s'", t,
                          k, jobs[t].msg[k], ref.msg[k]);
            ck_assert_msg(memcmp(jobs[t].x[k], ref.x[k], sizeof ref.x[k]) == 0, "thread %d input %zu: positions", t,
                          k);
            if (ref.rc[k] == ODHS_OK) {
                ck_assert_msg(jobs[t].write_rc[k] == ODHS_OK && jobs[t].reread_rc[k] == ODHS_OK,
                              "thread %d input %zu: write %d, re-read %d", t, k, jobs[t].write_rc[k],
                              jobs[t].reread_rc[k]);
            }
        }
        for (int s = 0; s < 4; ++s) ck_assert_int_eq(jobs[t].solver_rc[s], ref.solver_rc[s]);
    }
}
END_TEST

/* ========================================================================== */
Suite *make_threads_suite(void)
{
    Suite *s = suite_create("threads");
    TCase *tc = tcase_create("threads");
    tcase_add_checked_fixture(tc, th_setup, th_teardown);
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, test_same_work_matches_serial);
    tcase_add_test(tc, test_different_work_matches_serial);
    tcase_add_test(tc, test_xyz_and_solvers_concurrent);
    suite_add_tcase(s, tc);
    return s;
}
