/*
 * libodhs - tests of the CHOLMOD backends (lib/solvers/cholmod*.c):
 *   "cholmod"      sparse Cholesky of N = S S^T (analysis kept while the
 *                  contact list is unchanged, numeric refactorisation when only
 *                  the geometry moved);
 *   "cholmod-pcg"  PCG preconditioned by a simplicial LDL' factor that is
 *                  updated with cholmod_rowadd / cholmod_rowdel when contacts
 *                  appear or disappear.
 * Agreement with the dense LAPACK backend on random full-rank networks in 2D
 * and 3D, reuse of the symbolic analysis, singular and hyperstatic networks,
 * factor updates after many random contact changes, parameters/statistics,
 * and a whole sheared stepper run against the CG backend.
 * Without SuiteSparse the suite checks that the name "cholmod" reports
 * ODHS_E_NOTINSTALLED.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <check.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "testutil.h"

#ifdef ODHS_HAVE_SUITESPARSE

/* declared here until solver.h carries them */
ODHS_API extern const odhs_solver_type odhs_solver_type_cholmod;
ODHS_API extern const odhs_solver_type odhs_solver_type_cholmod_pcg;

/* ------------------------------------------------------------------------ */
/* helpers                                                                   */
/* ------------------------------------------------------------------------ */

/* numbers for the record, printed when ODHS_TEST_VERBOSE is set */
#if defined(__GNUC__)
static void cm_note(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
#endif
static void cm_note(const char *fmt, ...)
{
    if (!getenv("ODHS_TEST_VERBOSE")) return;
    va_list ap;
    va_start(ap, fmt);
    fprintf(stderr, "  [cholmod] ");
    vfprintf(stderr, fmt, ap);
    fputc('\n', stderr);
    va_end(ap);
}

typedef struct {
    odhs_system *sys;
    odhs_network *net;
    size_t n, nc;
    int dim;
    double L[3], gamma;
    double *x, *r;     /* positions and radii (n*dim, n) */
    double *x0;        /* initial positions: moves are relative to them */
    tu_pairlist pool;  /* near pairs: candidates for contacts */
} cm_case;

static void cm_case_free(cm_case *c)
{
    odhs_network_destroy(c->net);
    odhs_system_destroy(c->sys);
    free(c->x);
    free(c->x0);
    free(c->r);
    tu_pairlist_free(&c->pool);
    memset(c, 0, sizeof *c);
}

static size_t uf_find(size_t *p, size_t i)
{
    while (p[i] != i) {
        p[i] = p[p[i]];
        i = p[i];
    }
    return i;
}

/* Random polydisperse configuration under a Lees-Edwards strain; contacts: a
 * random spanning forest of the pairs with gap <= 0.5 (independent rows of S)
 * plus `extra` pairs that close cycles (generically still independent). */
static cm_case cm_random_case(int dim, size_t n, uint64_t seed, size_t extra)
{
    cm_case c;
    memset(&c, 0, sizeof c);
    c.dim = dim;
    c.n = n;
    tu_rng rng;
    tu_rng_seed(&rng, seed);
    c.r = malloc(n * sizeof *c.r);
    c.x = malloc(n * dim * sizeof *c.x);
    ck_assert(c.r && c.x);
    tu_radii_loguniform(n, 0.4, 0.7, c.r, &rng);
    double vol = 0.0;
    for (size_t i = 0; i < n; ++i)
        vol += dim == 2 ? TU_PI * c.r[i] * c.r[i] : 4.0 / 3.0 * TU_PI * pow(c.r[i], 3);
    double side = dim == 2 ? sqrt(vol / 0.35) : cbrt(vol / 0.2);
    c.L[2] = 1.0;
    for (int k = 0; k < dim; ++k) c.L[k] = side * (1.0 + 0.05 * k);
    c.gamma = 0.13;
    /* gaps of at least 0.01 leave room for the moves of cm_jiggle */
    ck_assert_msg(tu_random_config(dim, n, c.L, c.gamma, c.r, 0.01, c.x, &rng), "RSA failed");
    c.x0 = malloc(n * dim * sizeof *c.x0);
    ck_assert_ptr_nonnull(c.x0);
    memcpy(c.x0, c.x, n * dim * sizeof *c.x0);
    ck_assert_int_eq(odhs_system_create(dim, n, &c.sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_configuration(c.sys, c.L, c.gamma, c.r, c.x), ODHS_OK);
    ck_assert_int_eq(odhs_network_create(c.sys, &c.net), ODHS_OK);
    tu_brute_pairs(dim, n, c.x, c.r, c.L, c.gamma, 0.5, &c.pool);
    for (size_t k = c.pool.n; k > 1; --k) {
        size_t m = tu_index(&rng, k);
        tu_pair t = c.pool.p[k - 1];
        c.pool.p[k - 1] = c.pool.p[m];
        c.pool.p[m] = t;
    }
    size_t *par = malloc(n * sizeof *par);
    ck_assert_ptr_nonnull(par);
    for (size_t i = 0; i < n; ++i) par[i] = i;
    size_t added_extra = 0;
    for (size_t k = 0; k < c.pool.n; ++k) {
        size_t a = uf_find(par, c.pool.p[k].i), b = uf_find(par, c.pool.p[k].j);
        if (a != b) par[a] = b;
        else if (added_extra < extra) added_extra++;
        else continue;
        ck_assert_int_eq(odhs_network_add(c.net, c.pool.p[k].i, c.pool.p[k].j, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    }
    free(par);
    ck_assert_int_eq(odhs_network_update_geometry(c.net, c.sys), ODHS_OK);
    c.nc = odhs_network_count(c.net);
    ck_assert_msg(c.nc >= n / 2, "only %zu contacts", c.nc);
    return c;
}

/* move every particle to a random point within eps (per coordinate) of its
 * initial position: a geometry change only, the contact list stays. With
 * eps <= 2e-3 no two particles can come to overlap (initial gaps >= 0.01). */
static void cm_jiggle(cm_case *c, tu_rng *rng, double eps)
{
    ck_assert(eps <= 2e-3);
    for (size_t k = 0; k < c->n * (size_t)c->dim; ++k) c->x[k] = c->x0[k] + eps * tu_uniform_in(rng, -1.0, 1.0);
    /* set_configuration wraps positions that left the box */
    ck_assert_int_eq(odhs_system_set_configuration(c->sys, c->L, c->gamma, c->r, c->x), ODHS_OK);
    ck_assert_int_eq(odhs_network_update_geometry(c->net, c->sys), ODHS_OK);
}

static odhs_solver *cm_new(const odhs_solver_type *t)
{
    odhs_solver *s = NULL;
    ck_assert_int_eq(odhs_solver_create(t, &s), ODHS_OK);
    ck_assert_ptr_nonnull(s);
    return s;
}

static odhs_solver *cm_by_name(const char *name)
{
    odhs_solver *s = NULL;
    ck_assert_int_eq(odhs_solver_create_by_name(name, &s), ODHS_OK);
    return s;
}

/* cholmod-pcg with these "ordering" and "ordering_reuse" (since 0.2.23) */
static odhs_solver *cm_pcg_ordered(double ordering, double reuse)
{
    odhs_solver *p = cm_new(&odhs_solver_type_cholmod_pcg);
    ck_assert_int_eq(odhs_solver_set_param(p, "ordering", ordering), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(p, "ordering_reuse", reuse), ODHS_OK);
    return p;
}

static double cm_stat(const odhs_solver *s, const char *key)
{
    double v = NAN;
    ck_assert_msg(odhs_solver_get_stat(s, key, &v) == ODHS_OK, "%s: no statistic %s", odhs_solver_name(s), key);
    return v;
}

static double cm_reldiff(size_t n, const double *a, const double *b)
{
    double d = 0.0, s = 0.0;
    for (size_t k = 0; k < n; ++k) {
        d += (a[k] - b[k]) * (a[k] - b[k]);
        s += b[k] * b[k];
    }
    return s > 0.0 ? sqrt(d / s) : sqrt(d);
}

/* b = S V for a random velocity field plus a random vector */
static void cm_rhs(const odhs_network *net, tu_rng *rng, double *b)
{
    size_t nc = odhs_network_count(net);
    size_t nd = odhs_network_particles(net) * (size_t)odhs_network_dim(net);
    double *V = malloc(nd * sizeof *V);
    ck_assert_ptr_nonnull(V);
    for (size_t k = 0; k < nd; ++k) V[k] = tu_uniform_in(rng, -1.0, 1.0);
    ck_assert_int_eq(odhs_network_apply_S(net, V, b), ODHS_OK);
    for (size_t c = 0; c < nc; ++c) b[c] += 0.3 * tu_uniform_in(rng, -1.0, 1.0);
    free(V);
}

/* Solve with s and with a dense reference; relative difference of the two
 * (asserts that both succeeded). x is used as the initial guess. */
static double cm_vs_dense(odhs_solver *s, const odhs_network *net, const double *b, double *x)
{
    size_t nc = odhs_network_count(net);
    double *xd = calloc(nc + 1, sizeof *xd);
    ck_assert_ptr_nonnull(xd);
    odhs_solver *dn = cm_by_name("dense");
    int st = odhs_solver_solve(dn, net, b, xd);
    ck_assert_msg(st == ODHS_OK, "dense: %d (%s)", st, odhs_solver_errmsg(dn));
    st = odhs_solver_solve(s, net, b, x);
    ck_assert_msg(st == ODHS_OK, "%s: %d (%s)", odhs_solver_name(s), st, odhs_solver_errmsg(s));
    ck_assert_msg(cm_stat(s, "residual") < 1e-11, "%s: residual %g", odhs_solver_name(s), cm_stat(s, "residual"));
    double d = cm_reldiff(nc, x, xd);
    odhs_solver_destroy(dn);
    free(xd);
    return d;
}

/* ------------------------------------------------------------------------ */
/* agreement with the dense backend                                          */
/* ------------------------------------------------------------------------ */

static odhs_system *cm_scene(int dim, size_t n, double phi, uint64_t seed, odhs_network **net_out);

static void check_agreement(int dim, size_t n, uint64_t seed, size_t extra)
{
    cm_case c = cm_random_case(dim, n, seed, extra);
    size_t nc = c.nc;
    tu_rng rng;
    tu_rng_seed(&rng, seed + 7);
    double *b = malloc(nc * sizeof *b), *x = calloc(nc, sizeof *x);
    ck_assert(b && x);
    /* cholmod with CHOLMOD's automatic choice, forced simplicial LDL', forced
     * supernodal LL'; cholmod-pcg */
    const double modes[3] = {-1.0, 0.0, 1.0};
    for (int m = 0; m < 4; ++m) {
        odhs_solver *s = cm_new(m < 3 ? &odhs_solver_type_cholmod : &odhs_solver_type_cholmod_pcg);
        if (m < 3) ck_assert_int_eq(odhs_solver_set_param(s, "supernodal", modes[m]), ODHS_OK);
        double dmax = 0.0;
        for (int rep = 0; rep < 2; ++rep) {
            cm_rhs(c.net, &rng, b);
            memset(x, 0, nc * sizeof *x);
            double d = cm_vs_dense(s, c.net, b, x);
            dmax = fmax(dmax, d);
            ck_assert_msg(d < 1e-10, "%s (mode %d) vs dense: %g (dim %d, N %zu, Nc %zu)", odhs_solver_name(s), m, d,
                          dim, n, nc);
        }
        cm_note("agree dim %d N %zu Nc %zu %s mode %d: last diff %.2e rcond %.2e nnz_L %g flops %g supernodal %g it %g",
                dim, n, nc, odhs_solver_name(s), m, dmax, cm_stat(s, "rcond"), cm_stat(s, "nnz_L"),
                cm_stat(s, "flops"), m < 3 ? cm_stat(s, "supernodal") : 0.0, cm_stat(s, "iterations"));
        /* one setup for both solves */
        ck_assert_double_eq(cm_stat(s, "analyses"), 1.0);
        ck_assert_double_eq(cm_stat(s, "factorizations"), 1.0);
        ck_assert(cm_stat(s, "rcond") > 1e-14 && cm_stat(s, "rcond") <= 1.0);
        ck_assert(cm_stat(s, "nnz_L") >= (double)nc);
        ck_assert(cm_stat(s, "flops") > 0.0);
        ck_assert_double_eq(cm_stat(s, "cholmod_status"), 0.0);
        if (m == 1) ck_assert_double_eq(cm_stat(s, "supernodal"), 0.0);
        if (m == 2) ck_assert_double_eq(cm_stat(s, "supernodal"), 1.0);
        if (m == 3) ck_assert(cm_stat(s, "iterations") <= 3.0); /* fresh exact factor */
        odhs_solver_destroy(s);
    }
    free(b);
    free(x);
    cm_case_free(&c);
}

START_TEST(test_agree_2d)
{
    check_agreement(2, 150, 1, 0);
    check_agreement(2, 300, 2, 60);
}
END_TEST

START_TEST(test_agree_3d)
{
    check_agreement(3, 120, 3, 0);
    check_agreement(3, 250, 4, 80);
}
END_TEST

/* networks of compressed packings (rattlers, stressed backbone, much larger
 * condition numbers than the random networks above) */
static void check_packing(int dim, size_t n, double phi, uint64_t seed)
{
    odhs_network *net = NULL;
    odhs_system *sys = cm_scene(dim, n, phi, seed, &net);
    size_t nc = odhs_network_count(net);
    tu_rng rng;
    tu_rng_seed(&rng, seed + 3);
    double *b = malloc(nc * sizeof *b), *x = calloc(nc, sizeof *x);
    ck_assert(b && x);
    cm_rhs(net, &rng, b);
    double z;
    ck_assert_int_eq(odhs_network_coordination(net, &z), ODHS_OK);
    const double modes[3] = {-1.0, 0.0, 1.0};
    for (int m = 0; m < 4; ++m) {
        odhs_solver *s = cm_new(m < 3 ? &odhs_solver_type_cholmod : &odhs_solver_type_cholmod_pcg);
        if (m < 3) ck_assert_int_eq(odhs_solver_set_param(s, "supernodal", modes[m]), ODHS_OK);
        memset(x, 0, nc * sizeof *x);
        double d = cm_vs_dense(s, net, b, x);
        cm_note("packing dim %d N %zu phi %.2f Nc %zu z %.3f %s mode %d: diff %.2e rcond %.2e nnz_L %g it %g", dim, n,
                phi, nc, z, odhs_solver_name(s), m, d, cm_stat(s, "rcond"), cm_stat(s, "nnz_L"),
                cm_stat(s, "iterations"));
        ck_assert_msg(d < 1e-10, "%s (mode %d) vs dense on a packing: %g", odhs_solver_name(s), m, d);
        odhs_solver_destroy(s);
    }
    free(b);
    free(x);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}

START_TEST(test_agree_packing)
{
    check_packing(2, 200, 0.82, 81);
    check_packing(3, 120, 0.60, 82);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* reuse of the symbolic analysis                                            */
/* ------------------------------------------------------------------------ */

START_TEST(test_symbolic_reuse)
{
    cm_case c = cm_random_case(2, 200, 11, 20);
    tu_rng rng;
    tu_rng_seed(&rng, 12);
    size_t cap = c.nc + 8;
    double *b = malloc(cap * sizeof *b), *x = calloc(cap, sizeof *x);
    ck_assert(b && x);
    odhs_solver *s = cm_new(&odhs_solver_type_cholmod);
    ck_assert_str_eq(odhs_solver_name(s), "cholmod");
    cm_rhs(c.net, &rng, b);
    ck_assert(cm_vs_dense(s, c.net, b, x) < 1e-10);
    ck_assert_double_eq(cm_stat(s, "analyses"), 1.0);
    ck_assert_double_eq(cm_stat(s, "factorizations"), 1.0);
    /* geometry only: numeric refactorisation on the same analysis */
    for (int rep = 0; rep < 4; ++rep) {
        cm_jiggle(&c, &rng, 1e-3);
        cm_rhs(c.net, &rng, b);
        ck_assert(cm_vs_dense(s, c.net, b, x) < 1e-10);
        ck_assert_double_eq(cm_stat(s, "analyses"), 1.0);
        ck_assert_double_eq(cm_stat(s, "factorizations"), 2.0 + rep);
    }
    ck_assert_double_eq(cm_stat(s, "updates"), 0.0);
    /* a contact added: new analysis */
    size_t k, idx = SIZE_MAX;
    for (k = 0; k < c.pool.n; ++k) {
        ck_assert_int_eq(odhs_network_find(c.net, c.pool.p[k].i, c.pool.p[k].j, &idx), ODHS_OK);
        if (idx == SIZE_MAX) break;
    }
    ck_assert(k < c.pool.n);
    ck_assert_int_eq(odhs_network_add(c.net, c.pool.p[k].i, c.pool.p[k].j, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    ck_assert_int_eq(odhs_network_update_geometry(c.net, c.sys), ODHS_OK);
    cm_rhs(c.net, &rng, b);
    ck_assert(cm_vs_dense(s, c.net, b, x) < 1e-10);
    ck_assert_double_eq(cm_stat(s, "analyses"), 2.0);
    /* and geometry again: kept */
    cm_jiggle(&c, &rng, 1e-3);
    ck_assert(cm_vs_dense(s, c.net, b, x) < 1e-10);
    ck_assert_double_eq(cm_stat(s, "analyses"), 2.0);
    /* a contact removed from the middle (the last one moves into its place) */
    size_t i0, j0;
    ck_assert_int_eq(odhs_network_get_contact(c.net, 3, &i0, &j0, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_network_remove(c.net, i0, j0), ODHS_OK);
    cm_rhs(c.net, &rng, b);
    ck_assert(cm_vs_dense(s, c.net, b, x) < 1e-10);
    ck_assert_double_eq(cm_stat(s, "analyses"), 3.0);
    /* the same set of pairs in another order is another pattern of S */
    ck_assert_int_eq(odhs_network_get_contact(c.net, 5, &i0, &j0, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_network_remove(c.net, i0, j0), ODHS_OK);
    ck_assert_int_eq(odhs_network_add(c.net, i0, j0, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    ck_assert_int_eq(odhs_network_update_geometry(c.net, c.sys), ODHS_OK);
    ck_assert(cm_vs_dense(s, c.net, b, x) < 1e-10);
    ck_assert_double_eq(cm_stat(s, "analyses"), 4.0);
    /* changing the factorisation kind forces a new analysis */
    ck_assert_int_eq(odhs_solver_set_param(s, "supernodal", 1.0), ODHS_OK);
    cm_jiggle(&c, &rng, 1e-3);
    ck_assert(cm_vs_dense(s, c.net, b, x) < 1e-10);
    ck_assert_double_eq(cm_stat(s, "analyses"), 5.0);
    ck_assert_double_eq(cm_stat(s, "supernodal"), 1.0);
    /* a solve on the same network without a change: no setup at all */
    double f = cm_stat(s, "factorizations");
    ck_assert(cm_vs_dense(s, c.net, b, x) < 1e-10);
    ck_assert_double_eq(cm_stat(s, "factorizations"), f);
    odhs_solver_destroy(s);
    free(b);
    free(x);
    cm_case_free(&c);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* singular and hyperstatic networks                                         */
/* ------------------------------------------------------------------------ */

static void check_singular_all(const odhs_network *net, const char *what)
{
    size_t nc = odhs_network_count(net);
    double *b = malloc(nc * sizeof *b), *x = calloc(nc, sizeof *x);
    ck_assert(b && x);
    for (size_t c = 0; c < nc; ++c) b[c] = 1.0 + 0.3 * sin(1.0 + c);
    const double modes[3] = {-1.0, 0.0, 1.0};
    for (int m = 0; m < 4; ++m) {
        odhs_solver *s = cm_new(m < 3 ? &odhs_solver_type_cholmod : &odhs_solver_type_cholmod_pcg);
        if (m < 3) ck_assert_int_eq(odhs_solver_set_param(s, "supernodal", modes[m]), ODHS_OK);
        memset(x, 0, nc * sizeof *x);
        int st = odhs_solver_solve(s, net, b, x);
        ck_assert_msg(st == ODHS_E_SINGULAR, "%s: %s (mode %d) returned %d (%s)", what, odhs_solver_name(s), m, st,
                      odhs_solver_errmsg(s));
        ck_assert_str_ne(odhs_solver_errmsg(s), "");
        double status = cm_stat(s, "cholmod_status");
        ck_assert(status == 0.0 || status == 1.0); /* OK or CHOLMOD_NOT_POSDEF, never an error */
        odhs_solver_destroy(s);
    }
    free(b);
    free(x);
}

/* three discs in a row touching around the periodic box: (1,1,1) is a
 * self-stress; after lifting the middle disc the same contact list is regular */
START_TEST(test_singular_ring)
{
    odhs_system *sys = NULL;
    ck_assert_int_eq(odhs_system_create(2, 3, &sys), ODHS_OK);
    double L[2] = {3.0, 3.0}, r[3] = {0.5, 0.5, 0.5}, x[6] = {0.5, 1.5, 1.5, 1.5, 2.5, 1.5};
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
    odhs_network *net = NULL;
    ck_assert_int_eq(odhs_network_create(sys, &net), ODHS_OK);
    ck_assert_int_eq(odhs_network_detect(net, sys, 1e-9), ODHS_OK);
    ck_assert_uint_eq(odhs_network_count(net), 3);
    check_singular_all(net, "periodic ring");
    /* one handle: singular first, then regular on the same analysis */
    odhs_solver *s = cm_new(&odhs_solver_type_cholmod);
    double b[3] = {1.0, -0.5, 0.25}, xs[3] = {0, 0, 0};
    ck_assert_int_eq(odhs_solver_solve(s, net, b, xs), ODHS_E_SINGULAR);
    ck_assert_double_eq(cm_stat(s, "analyses"), 1.0);
    x[3] = 1.8; /* lift the middle disc: the normals are no longer collinear */
    ck_assert_int_eq(odhs_system_set_positions(sys, x), ODHS_OK);
    ck_assert_int_eq(odhs_network_update_geometry(net, sys), ODHS_OK);
    ck_assert(cm_vs_dense(s, net, b, xs) < 1e-12);
    ck_assert_double_eq(cm_stat(s, "analyses"), 1.0);
    ck_assert_double_eq(cm_stat(s, "factorizations"), 2.0);
    odhs_solver_destroy(s);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* 3x3 square lattice of touching discs in a periodic 3x3 box: 18 contacts on
 * 18 degrees of freedom with 2 translations: rows of the lattice carry
 * self-stresses */
START_TEST(test_singular_square_lattice)
{
    odhs_system *sys = NULL;
    ck_assert_int_eq(odhs_system_create(2, 9, &sys), ODHS_OK);
    double L[2] = {3.0, 3.0}, r[9], x[18];
    for (int i = 0; i < 9; ++i) {
        r[i] = 0.5;
        x[2 * i] = 0.5 + (i % 3);
        x[2 * i + 1] = 0.5 + (i / 3);
    }
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
    odhs_network *net = NULL;
    ck_assert_int_eq(odhs_network_create(sys, &net), ODHS_OK);
    ck_assert_int_eq(odhs_network_detect(net, sys, 1e-9), ODHS_OK);
    ck_assert_uint_eq(odhs_network_count(net), 18);
    check_singular_all(net, "square lattice");
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* a hexagonal patch of 7 equal discs: 12 contacts > 2*7 - 3, singular up to
 * the round-off of the irrational normals (caught by the rcond test) */
START_TEST(test_singular_hex_patch)
{
    odhs_system *sys = NULL;
    ck_assert_int_eq(odhs_system_create(2, 7, &sys), ODHS_OK);
    double L[2] = {10.0, 10.0}, r[7], x[14];
    for (int i = 0; i < 7; ++i) r[i] = 0.5;
    x[0] = 5.0;
    x[1] = 5.0;
    for (int k = 0; k < 6; ++k) {
        x[2 * (k + 1)] = 5.0 + cos(k * TU_PI / 3.0);
        x[2 * (k + 1) + 1] = 5.0 + sin(k * TU_PI / 3.0);
    }
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
    odhs_network *net = NULL;
    ck_assert_int_eq(odhs_network_create(sys, &net), ODHS_OK);
    ck_assert_int_eq(odhs_network_detect(net, sys, 1e-9), ODHS_OK);
    ck_assert_uint_eq(odhs_network_count(net), 12);
    check_singular_all(net, "hexagonal patch");
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* a regular network is reported singular once min_rcond exceeds its rcond;
 * a hyperstatic contact added to a regular network makes cholmod-pcg's
 * updated factor fail and the fresh one report singularity */
START_TEST(test_min_rcond_and_pcg_singular)
{
    cm_case c = cm_random_case(2, 80, 21, 5);
    tu_rng rng;
    tu_rng_seed(&rng, 22);
    double *b = malloc((c.nc + 4) * sizeof *b), *x = calloc(c.nc + 4, sizeof *x);
    ck_assert(b && x);
    cm_rhs(c.net, &rng, b);
    odhs_solver *s = cm_new(&odhs_solver_type_cholmod);
    ck_assert(cm_vs_dense(s, c.net, b, x) < 1e-10);
    double rc = cm_stat(s, "rcond");
    ck_assert(rc > 0.0 && rc < 1.0);
    ck_assert_int_eq(odhs_solver_set_param(s, "min_rcond", fmin(0.99, 2.0 * rc)), ODHS_OK);
    cm_jiggle(&c, &rng, 0.0); /* same geometry, new version: set up again */
    ck_assert_int_eq(odhs_solver_solve(s, c.net, b, x), ODHS_E_SINGULAR);
    ck_assert_int_eq(odhs_solver_set_param(s, "min_rcond", 0.5 * rc), ODHS_OK);
    cm_jiggle(&c, &rng, 0.0);
    ck_assert_int_eq(odhs_solver_solve(s, c.net, b, x), ODHS_OK);
    ck_assert_double_eq(cm_stat(s, "analyses"), 1.0);
    odhs_solver_destroy(s);

    /* cholmod-pcg with the same threshold logic */
    odhs_solver *p = cm_new(&odhs_solver_type_cholmod_pcg);
    memset(x, 0, c.nc * sizeof *x);
    ck_assert(cm_vs_dense(p, c.net, b, x) < 1e-10);
    ck_assert_int_eq(odhs_solver_set_param(p, "min_rcond", 0.99), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(p, "refactor_every", 1.0), ODHS_OK);
    cm_jiggle(&c, &rng, 1e-3); /* moved normals: refactorisation at once */
    ck_assert_int_eq(odhs_solver_solve(p, c.net, b, x), ODHS_E_SINGULAR);
    odhs_solver_destroy(p);
    free(b);
    free(x);
    cm_case_free(&c);
}
END_TEST

/* a hyperstatic cluster created by an added contact: the pcg backend sees it
 * through an update, must not return a wrong answer */
START_TEST(test_pcg_update_to_singular)
{
    /* four equal discs at the corners of a rhombus made of two equilateral
     * triangles 0-1-3 and 0-2-3 (short diagonal 0-3, long diagonal 1-2 of
     * length sqrt(3)). The four sides plus 0-3 are 5 = 2*4 - 3 independent
     * contacts; the long diagonal 1-2 as a sixth contact is hyperstatic. */
    odhs_system *sys = NULL;
    ck_assert_int_eq(odhs_system_create(2, 4, &sys), ODHS_OK);
    double L[2] = {10.0, 10.0}, r[4] = {0.5, 0.5, 0.5, 0.5};
    double h = sqrt(3.0) / 2.0;
    double x[8] = {4.0, 5.0, 4.5, 5.0 + h, 4.5, 5.0 - h, 5.0, 5.0};
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
    odhs_network *net = NULL;
    ck_assert_int_eq(odhs_network_create(sys, &net), ODHS_OK);
    ck_assert_int_eq(odhs_network_add(net, 0, 1, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    ck_assert_int_eq(odhs_network_add(net, 0, 2, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    ck_assert_int_eq(odhs_network_add(net, 1, 3, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    ck_assert_int_eq(odhs_network_add(net, 2, 3, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    ck_assert_int_eq(odhs_network_update_geometry(net, sys), ODHS_OK);
    odhs_solver *p = cm_new(&odhs_solver_type_cholmod_pcg);
    double b[6] = {1.0, 0.5, -0.25, 0.75, 0.1, 0.2}, xs[6] = {0};
    ck_assert(cm_vs_dense(p, net, b, xs) < 1e-12);
    ck_assert_int_eq(odhs_network_add(net, 0, 3, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    ck_assert_int_eq(odhs_network_update_geometry(net, sys), ODHS_OK);
    ck_assert(cm_vs_dense(p, net, b, xs) < 1e-12); /* 5 contacts: still regular */
    {
        /* "update_max" 0: the same added contact costs a full
         * factorisation instead of an update, with the same answer */
        odhs_solver *q = cm_new(&odhs_solver_type_cholmod_pcg);
        ck_assert_int_eq(odhs_solver_set_param(q, "update_max", 0.0), ODHS_OK);
        ck_assert_int_eq(odhs_network_remove(net, 0, 3), ODHS_OK);
        double xq[6] = {0};
        ck_assert(cm_vs_dense(q, net, b, xq) < 1e-12);
        ck_assert_int_eq(odhs_network_add(net, 0, 3, ODHS_CONTACT_TEMPORARY), ODHS_OK);
        ck_assert_int_eq(odhs_network_update_geometry(net, sys), ODHS_OK);
        memset(xq, 0, sizeof xq);
        ck_assert(cm_vs_dense(q, net, b, xq) < 1e-12);
        ck_assert_double_eq(cm_stat(q, "updates"), 0.0);
        ck_assert_double_eq(cm_stat(q, "factorizations"), 2.0);
        for (int k = 0; k < 5; ++k) ck_assert_double_eq_tol(xq[k], xs[k], 1e-12);
        odhs_solver_destroy(q);
    }
    /* 1-2 (not touching, but any pair may be a contact): 6 rows on 8 - 3 = 5
     * non-trivial degrees of freedom */
    ck_assert_double_eq(cm_stat(p, "updates"), 1.0);
    ck_assert_int_eq(odhs_network_add(net, 1, 2, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    ck_assert_int_eq(odhs_network_update_geometry(net, sys), ODHS_OK);
    memset(xs, 0, sizeof xs);
    int st = odhs_solver_solve(p, net, b, xs);
    ck_assert_msg(st == ODHS_E_SINGULAR, "pcg on a hyperstatic update: %d (%s)", st, odhs_solver_errmsg(p));
    /* and back to regular */
    ck_assert_int_eq(odhs_network_remove(net, 0, 3), ODHS_OK);
    memset(xs, 0, sizeof xs);
    ck_assert(cm_vs_dense(p, net, b, xs) < 1e-12);
    odhs_solver_destroy(p);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* cholmod-pcg: factor updates                                               */
/* ------------------------------------------------------------------------ */

/* Apply a random add or remove (keeping between nmin and nmax contacts);
 * undo it if it made N singular (checked with the dense backend). Returns 1
 * if the network changed. */
static int random_change(cm_case *c, tu_rng *rng, size_t nmin, size_t nmax)
{
    size_t nc = odhs_network_count(c->net);
    int add = nc <= nmin ? 1 : nc >= nmax ? 0 : tu_uniform(rng) < 0.5;
    if (!add) {
        size_t k = tu_index(rng, nc), i, j;
        ck_assert_int_eq(odhs_network_get_contact(c->net, k, &i, &j, NULL), ODHS_OK);
        ck_assert_int_eq(odhs_network_remove(c->net, i, j), ODHS_OK);
        return 1; /* removing rows keeps S of full row rank */
    }
    for (int tries = 0; tries < 50; ++tries) {
        tu_pair *p = &c->pool.p[tu_index(rng, c->pool.n)];
        size_t idx;
        ck_assert_int_eq(odhs_network_find(c->net, p->i, p->j, &idx), ODHS_OK);
        if (idx != SIZE_MAX) continue;
        ck_assert_int_eq(odhs_network_add(c->net, p->i, p->j, ODHS_CONTACT_TEMPORARY), ODHS_OK);
        ck_assert_int_eq(odhs_network_update_geometry(c->net, c->sys), ODHS_OK);
        /* reject additions that make N singular */
        nc = odhs_network_count(c->net);
        double *b = malloc(nc * sizeof *b), *x = calloc(nc, sizeof *x);
        ck_assert(b && x);
        for (size_t q = 0; q < nc; ++q) b[q] = 1.0;
        odhs_solver *dn = cm_by_name("dense");
        int st = odhs_solver_solve(dn, c->net, b, x);
        odhs_solver_destroy(dn);
        free(b);
        free(x);
        if (st == ODHS_OK) return 1;
        ck_assert_int_eq(st, ODHS_E_SINGULAR);
        ck_assert_int_eq(odhs_network_remove(c->net, p->i, p->j), ODHS_OK);
    }
    return 0;
}

START_TEST(test_pcg_updates_fixed_geometry)
{
    /* at a fixed geometry every updated factor is exact: PCG converges at
     * once, and the answer is the fresh factorisation's */
    cm_case c = cm_random_case(2, 160, 31, 10);
    tu_rng rng;
    tu_rng_seed(&rng, 32);
    size_t nmax = c.nc + 40;
    double *b = malloc(nmax * sizeof *b), *x = calloc(nmax, sizeof *x), *xf = calloc(nmax, sizeof *xf);
    ck_assert(b && x && xf);
    odhs_solver *p = cm_new(&odhs_solver_type_cholmod_pcg), *f = cm_new(&odhs_solver_type_cholmod);
    ck_assert_str_eq(odhs_solver_name(p), "cholmod-pcg");
    ck_assert_int_eq(odhs_solver_set_param(p, "refactor_every", 0.0), ODHS_OK);
    cm_rhs(c.net, &rng, b);
    ck_assert(cm_vs_dense(p, c.net, b, x) < 1e-10);
    double dmax = 0.0, itmax = 0.0;
    for (int op = 0; op < 120; ++op) {
        random_change(&c, &rng, c.nc - 10, c.nc + 12);
        size_t nc = odhs_network_count(c.net);
        cm_rhs(c.net, &rng, b);
        memset(x, 0, nc * sizeof *x);
        double d = cm_vs_dense(p, c.net, b, x);
        dmax = fmax(dmax, d);
        itmax = fmax(itmax, cm_stat(p, "iterations"));
        ck_assert_msg(d < 1e-10, "op %d: pcg vs dense %g", op, d);
        memset(xf, 0, nc * sizeof *xf);
        ck_assert_int_eq(odhs_solver_solve(f, c.net, b, xf), ODHS_OK);
        ck_assert_msg(cm_reldiff(nc, x, xf) < 1e-10, "op %d: pcg vs cholmod %g", op, cm_reldiff(nc, x, xf));
        ck_assert_msg(cm_stat(p, "iterations") <= 3.0, "op %d: %g iterations with an exact factor", op,
                      cm_stat(p, "iterations"));
    }
    /* a non-finite initial guess is replaced by zero */
    {
        size_t nc = odhs_network_count(c.net);
        for (size_t q = 0; q < nc; ++q) x[q] = q == 0 ? NAN : 1.0;
        ck_assert(cm_vs_dense(p, c.net, b, x) < 1e-10);
    }
    double upd = cm_stat(p, "updates"), fac = cm_stat(p, "factorizations");
    cm_note("pcg fixed geometry: 120 ops, %g updates, %g factorizations, %g analyses, max diff %.2e, max it %g", upd,
            fac, cm_stat(p, "analyses"), dmax, itmax);
    ck_assert_msg(upd >= 100.0, "only %g updates", upd);
    ck_assert_msg(fac <= 4.0, "%g full factorisations in 120 single changes", fac);
    odhs_solver_destroy(p);
    odhs_solver_destroy(f);
    free(b);
    free(x);
    free(xf);
    cm_case_free(&c);
}
END_TEST

static void check_pcg_moving(int dim, size_t n, uint64_t seed, size_t extra, int nops)
{
    /* contacts change and the particles move: the updated factor is only a
     * preconditioner; results still agree with the dense backend */
    cm_case c = cm_random_case(dim, n, seed, extra);
    tu_rng rng;
    tu_rng_seed(&rng, seed + 1);
    size_t nmax = c.nc + 40;
    double *b = malloc(nmax * sizeof *b), *x = calloc(nmax, sizeof *x);
    ck_assert(b && x);
    odhs_solver *p = cm_new(&odhs_solver_type_cholmod_pcg);
    ck_assert_int_eq(odhs_solver_set_param(p, "tol", 1e-13), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(p, "refactor_every", 25.0), ODHS_OK);
    cm_rhs(c.net, &rng, b);
    ck_assert(cm_vs_dense(p, c.net, b, x) < 1e-10);
    double itmax = 0.0, dmax = 0.0, itsum = 0.0;
    for (int op = 0; op < nops; ++op) {
        int k = (int)tu_index(&rng, 3);
        for (int q = 0; q < k; ++q) random_change(&c, &rng, c.nc - 15, c.nc + 20);
        cm_jiggle(&c, &rng, 2e-3);
        size_t nc = odhs_network_count(c.net);
        cm_rhs(c.net, &rng, b);
        memset(x, 0, nc * sizeof *x);
        double d = cm_vs_dense(p, c.net, b, x);
        ck_assert_msg(d < 1e-10, "op %d: pcg vs dense %g", op, d);
        itmax = fmax(itmax, cm_stat(p, "iterations"));
        itsum += cm_stat(p, "iterations");
        dmax = fmax(dmax, d);
    }
    double upd = cm_stat(p, "updates"), fac = cm_stat(p, "factorizations");
    cm_note("pcg moving dim %d: %d setups, %g updates, %g factorizations, iterations mean %.1f max %g, max diff %.2e",
            dim, nops, upd, fac, itsum / nops, itmax, dmax);
    ck_assert_msg(upd > 0.0, "no updates");
    /* periodic refactorisation every 25 setups (plus capacity / failures) */
    ck_assert_msg(fac >= nops / 25 && fac <= nops / 3, "%g factorisations for %d setups", fac, nops);
    ck_assert_msg(itmax <= 40.0, "up to %g iterations", itmax);
    odhs_solver_destroy(p);
    free(b);
    free(x);
    cm_case_free(&c);
}

START_TEST(test_pcg_updates_moving_2d)
{
    check_pcg_moving(2, 200, 41, 20, 150);
}
END_TEST

START_TEST(test_pcg_updates_moving_3d)
{
    check_pcg_moving(3, 150, 51, 20, 100);
}
END_TEST

/* many insertions at once (update_max 1 lets them all through as updates):
 * the free slots sit where the last analysis put them, and the fill they
 * make is bounded while the insertions run (the factor's allocation beyond
 * 2.5 times the fresh one's stops them and setup refactors) */
START_TEST(test_pcg_bulk_insertions)
{
    cm_case c = cm_random_case(2, 1500, 65, 0);
    tu_rng rng;
    tu_rng_seed(&rng, 66);
    size_t nmax = c.nc + c.nc / 8 + 1;
    double *b = malloc(nmax * sizeof *b), *x = calloc(nmax, sizeof *x);
    ck_assert(b && x);
    odhs_solver *p = cm_new(&odhs_solver_type_cholmod_pcg);
    ck_assert_int_eq(odhs_solver_set_param(p, "refactor_every", 0.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(p, "update_max", 1.0), ODHS_OK);
    cm_rhs(c.net, &rng, b);
    ck_assert(cm_vs_dense(p, c.net, b, x) < 1e-10);
    double nnz0 = cm_stat(p, "nnz_L");
    /* swap nc/9 contacts for pool pairs that were not in the network */
    size_t k = c.nc / 9, added = 0;
    size_t *gone = malloc(2 * k * sizeof *gone);
    ck_assert_ptr_nonnull(gone);
    for (size_t r = 0; r < k; ++r) {
        size_t q = tu_index(&rng, odhs_network_count(c.net));
        ck_assert_int_eq(odhs_network_get_contact(c.net, q, &gone[2 * r], &gone[2 * r + 1], NULL), ODHS_OK);
        ck_assert_int_eq(odhs_network_remove(c.net, gone[2 * r], gone[2 * r + 1]), ODHS_OK);
    }
    for (size_t q = 0; q < c.pool.n && added < k; ++q) {
        size_t idx, i = c.pool.p[q].i, j = c.pool.p[q].j, was = 0;
        for (size_t r = 0; r < k; ++r)
            was |= (gone[2 * r] == i && gone[2 * r + 1] == j) || (gone[2 * r] == j && gone[2 * r + 1] == i);
        ck_assert_int_eq(odhs_network_find(c.net, i, j, &idx), ODHS_OK);
        if (idx != SIZE_MAX || was) continue;
        ck_assert_int_eq(odhs_network_add(c.net, i, j, ODHS_CONTACT_TEMPORARY), ODHS_OK);
        added++;
    }
    ck_assert_uint_eq(added, k);
    free(gone);
    ck_assert_int_eq(odhs_network_update_geometry(c.net, c.sys), ODHS_OK);
    cm_rhs(c.net, &rng, b);
    memset(x, 0, nmax * sizeof *x);
    ck_assert(cm_vs_dense(p, c.net, b, x) < 1e-10);
    double upd = cm_stat(p, "updates");
    cm_note("bulk: nc %zu, %zu swapped: nnz_L %g -> %g, updates %g, factorizations %g", c.nc, k, nnz0,
            cm_stat(p, "nnz_L"), upd, cm_stat(p, "factorizations"));
    /* the k deletions went through, the insertions stopped part-way */
    ck_assert_msg(upd >= (double)k && upd < 2.0 * (double)k, "%g updates for %zu + %zu changes", upd, k, k);
    ck_assert_double_eq(cm_stat(p, "factorizations"), 2.0);
    odhs_solver_destroy(p);
    free(b);
    free(x);
    cm_case_free(&c);
}
END_TEST

/* slot capacity: many contacts added one by one outgrow the factor */
START_TEST(test_pcg_capacity)
{
    cm_case c = cm_random_case(2, 200, 61, 0);
    tu_rng rng;
    tu_rng_seed(&rng, 62);
    size_t nmax = c.nc + 80;
    double *b = malloc(nmax * sizeof *b), *x = calloc(nmax, sizeof *x);
    ck_assert(b && x);
    odhs_solver *p = cm_new(&odhs_solver_type_cholmod_pcg);
    ck_assert_int_eq(odhs_solver_set_param(p, "refactor_every", 0.0), ODHS_OK);
    cm_rhs(c.net, &rng, b);
    ck_assert(cm_vs_dense(p, c.net, b, x) < 1e-10);
    double cap0 = cm_stat(p, "capacity");
    ck_assert(cap0 >= (double)c.nc + 16.0);
    size_t added = 0;
    while ((double)odhs_network_count(c.net) <= cap0 + 2.0) {
        size_t before = odhs_network_count(c.net);
        random_change(&c, &rng, 0, SIZE_MAX);
        if (odhs_network_count(c.net) == before) break; /* pool exhausted */
        added++;
        size_t nc = odhs_network_count(c.net);
        cm_rhs(c.net, &rng, b);
        memset(x, 0, nc * sizeof *x);
        ck_assert(cm_vs_dense(p, c.net, b, x) < 1e-10);
    }
    ck_assert_msg((double)odhs_network_count(c.net) > cap0, "could not add enough contacts (%zu)", added);
    ck_assert(cm_stat(p, "capacity") > cap0);
    ck_assert(cm_stat(p, "factorizations") >= 2.0);
    ck_assert(cm_stat(p, "updates") >= cap0 - (double)c.nc);
    odhs_solver_destroy(p);
    free(b);
    free(x);
    cm_case_free(&c);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* parameters and statistics                                                 */
/* ------------------------------------------------------------------------ */

START_TEST(test_params_stats)
{
    odhs_solver *s = cm_new(&odhs_solver_type_cholmod), *p = cm_new(&odhs_solver_type_cholmod_pcg);
    double v;
    ck_assert_int_eq(odhs_solver_set_param(s, "min_rcond", 1e-10), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(s, "min_rcond", 1.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(s, "min_rcond", -1.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(s, "supernodal", 0.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(s, "supernodal", 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(s, "supernodal", -1.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(s, "supernodal", 0.5), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(s, "supernodal", 2.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(s, "tol", 1e-8), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(s, "refactor_every", 10.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(s, "no_such_thing", 1.0), ODHS_E_INVALID);
    ck_assert_str_ne(odhs_solver_errmsg(s), "");
    ck_assert_int_eq(odhs_solver_set_param(p, "tol", 1e-10), ODHS_OK);
    ck_assert_int_eq(odhs_solver_get_stat(p, "tol", &v), ODHS_OK);
    ck_assert_double_eq(v, 1e-10);
    ck_assert_int_eq(odhs_solver_set_param(p, "tol", 0.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "tol", 1.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "maxiter", 500.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(p, "maxiter", -1.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "refactor_every", 0.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(p, "refactor_every", 7.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(p, "refactor_every", -7.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "refactor_iterations", 0.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "refactor_iterations", 20.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(p, "supernodal", 0.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(p, "supernodal", 1.0), ODHS_OK); /* since 0.2.20 */
    ck_assert_int_eq(odhs_solver_set_param(p, "supernodal", -1.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(p, "supernodal", 0.5), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "supernodal", 2.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "min_rcond", 1e-12), ODHS_OK);
    ck_assert_int_eq(odhs_solver_get_stat(p, "update_max", &v), ODHS_OK);
    ck_assert_double_eq(v, 0.125);
    ck_assert_int_eq(odhs_solver_set_param(p, "update_max", 1.5), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "update_max", -0.1), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_get_stat(p, "update_max", &v), ODHS_OK);
    ck_assert_double_eq(v, 0.125); /* a rejected value leaves the old one */
    ck_assert_int_eq(odhs_solver_set_param(s, "update_max", 0.5), ODHS_E_INVALID); /* pcg only */
    /* statistics before any solve */
    const char *keys[] = {"analyses", "factorizations", "updates", "rcond", "nnz_L", "flops", "iterations",
                          "cholmod_status"};
    for (size_t k = 0; k < sizeof keys / sizeof *keys; ++k) {
        ck_assert_msg(odhs_solver_get_stat(s, keys[k], &v) == ODHS_OK && v == 0.0, "cholmod %s", keys[k]);
        ck_assert_msg(odhs_solver_get_stat(p, keys[k], &v) == ODHS_OK && v == 0.0, "pcg %s", keys[k]);
    }
    ck_assert_int_eq(odhs_solver_get_stat(p, "capacity", &v), ODHS_OK);
    ck_assert_int_eq(odhs_solver_get_stat(s, "bogus", &v), ODHS_E_INVALID);
    /* flags of the tables */
    ck_assert_uint_eq(odhs_solver_type_cholmod.flags, ODHS_SOLVER_DIRECT);
    ck_assert_uint_eq(odhs_solver_type_cholmod_pcg.flags, ODHS_SOLVER_ITERATIVE | ODHS_SOLVER_USES_GUESS);
    ck_assert_int_eq(odhs_solver_type_cholmod.version, ODHS_SOLVER_TYPE_VERSION);
    ck_assert_int_eq(odhs_solver_type_cholmod_pcg.version, ODHS_SOLVER_TYPE_VERSION);
    odhs_solver_destroy(s);
    odhs_solver_destroy(p);

    /* refactor_every = 1: a full factorisation at every setup */
    cm_case c = cm_random_case(2, 60, 71, 3);
    tu_rng rng;
    tu_rng_seed(&rng, 72);
    double *b = malloc(c.nc * sizeof *b), *x = calloc(c.nc, sizeof *x);
    ck_assert(b && x);
    p = cm_new(&odhs_solver_type_cholmod_pcg);
    ck_assert_int_eq(odhs_solver_set_param(p, "refactor_every", 1.0), ODHS_OK);
    for (int rep = 0; rep < 5; ++rep) {
        cm_jiggle(&c, &rng, 1e-3);
        cm_rhs(c.net, &rng, b);
        ck_assert(cm_vs_dense(p, c.net, b, x) < 1e-10);
        ck_assert_double_eq(cm_stat(p, "factorizations"), rep + 1.0);
        /* the contact list did not change: numeric refactorisation only */
        ck_assert_double_eq(cm_stat(p, "analyses"), 1.0);
        ck_assert(cm_stat(p, "iterations") <= 3.0);
    }
    odhs_solver_destroy(p);
    free(b);
    free(x);
    cm_case_free(&c);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* a full stepper run                                                        */
/* ------------------------------------------------------------------------ */

/* dense bidisperse scene compressed with the cholmod backend; *net_out (if
 * not NULL) receives a copy of the final contact network */
static odhs_system *cm_scene(int dim, size_t n, double phi, uint64_t seed, odhs_network **net_out)
{
    odhs_system *sys = NULL;
    ck_assert_int_eq(odhs_system_create(dim, n, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, seed), ODHS_OK);
    ck_assert_int_eq(odhs_system_place_random(sys, dim == 2 ? 0.45 : 0.30, seed + 1), ODHS_OK);
    odhs_solver *sol = cm_new(&odhs_solver_type_cholmod);
    odhs_driver *drv = NULL;
    odhs_stepper *st = NULL;
    ck_assert_int_eq(odhs_driver_create(&drv), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_compression_rate(drv, 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_create(sys, drv, sol, &st), ODHS_OK);
    /* the paper's fixed-step scheme: the series of the backends are compared step by step */
    ck_assert_int_eq(odhs_stepper_set_integrator(st, ODHS_INTEGRATOR_EULER), ODHS_OK);
    int rc = odhs_stepper_run_until_packing_fraction(st, phi);
    ck_assert_msg(rc == ODHS_OK, "compression: %d (%s)", rc, odhs_stepper_errmsg(st));
    ck_assert_int_eq(odhs_stepper_correct(st), ODHS_OK);
    ck_assert(cm_stat(sol, "factorizations") > 10.0);
    if (net_out) {
        const odhs_network *sn = odhs_stepper_network(st);
        ck_assert_int_eq(odhs_network_create(sys, net_out), ODHS_OK);
        for (size_t c = 0; c < odhs_network_count(sn); ++c) {
            size_t i, j;
            int kind;
            ck_assert_int_eq(odhs_network_get_contact(sn, c, &i, &j, &kind), ODHS_OK);
            ck_assert_int_eq(odhs_network_add(*net_out, i, j, kind), ODHS_OK);
        }
        ck_assert_int_eq(odhs_network_update_geometry(*net_out, sys), ODHS_OK);
    }
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    return sys;
}

/* a stepper shearing a clone of base at rate 1 with the given solver */
static odhs_stepper *cm_shear_stepper(const odhs_system *base, odhs_solver *sol, odhs_system **sys,
                                      odhs_driver **drv)
{
    odhs_stepper *st = NULL;
    *sys = NULL;
    *drv = NULL;
    ck_assert_int_eq(odhs_system_clone(base, sys), ODHS_OK);
    ck_assert_int_eq(odhs_driver_create(drv), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_shear_rate(*drv, 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_create(*sys, *drv, sol, &st), ODHS_OK);
    return st;
}

/* shear a clone of base with the given solver for nsteps steps; returns the
 * shear stress after every step (malloc'ed), event count in *events */
static double *cm_shear_series(const odhs_system *base, odhs_solver *sol, int nsteps, uint64_t *events)
{
    odhs_system *sys;
    odhs_driver *drv;
    odhs_stepper *st = cm_shear_stepper(base, sol, &sys, &drv);
    /* the paper's fixed-step scheme: the series of the backends are compared step by step */
    ck_assert_int_eq(odhs_stepper_set_integrator(st, ODHS_INTEGRATOR_EULER), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_set_dt(st, 2e-3), ODHS_OK);
    double *sig = malloc((size_t)nsteps * sizeof *sig);
    ck_assert_ptr_nonnull(sig);
    for (int k = 0; k < nsteps; ++k) {
        odhs_event ev;
        int rc = odhs_stepper_step(st, &ev);
        ck_assert_msg(rc == ODHS_OK, "%s: step %d: %d (%s)", odhs_solver_name(sol), k, rc, odhs_stepper_errmsg(st));
        ck_assert_int_eq(odhs_stepper_shear_stress(st, &sig[k]), ODHS_OK);
    }
    uint64_t steps, coll, open;
    ck_assert_int_eq(odhs_stepper_counts(st, &steps, &coll, &open), ODHS_OK);
    *events = coll + open;
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    return sig;
}

START_TEST(test_stepper_shear)
{
    odhs_system *base = cm_scene(2, 64, 0.80, 5, NULL);
    const int nsteps = 400;
    odhs_solver *cg = cm_by_name("cg"), *ch = cm_new(&odhs_solver_type_cholmod),
                *pc = cm_new(&odhs_solver_type_cholmod_pcg), *pr = cm_pcg_ordered(1.0, 1.25);
    uint64_t ecg, ech, epc, epr;
    double *scg = cm_shear_series(base, cg, nsteps, &ecg);
    double *sch = cm_shear_series(base, ch, nsteps, &ech);
    double *spc = cm_shear_series(base, pc, nsteps, &epc);
    /* pcg on carried METIS orderings (0.2.23): slots, updates and rewiring on them */
    double *spr = cm_shear_series(base, pr, nsteps, &epr);
    ck_assert_msg(ecg > 5, "only %llu events", (unsigned long long)ecg);
    ck_assert_uint_eq(ech, ecg);
    ck_assert_uint_eq(epc, ecg);
    ck_assert_uint_eq(epr, ecg);
    double smax = 0.0, d1 = 0.0, d2 = 0.0, d3 = 0.0;
    for (int k = 0; k < nsteps; ++k) {
        smax = fmax(smax, fabs(scg[k]));
        d1 = fmax(d1, fabs(sch[k] - scg[k]));
        d2 = fmax(d2, fabs(spc[k] - scg[k]));
        d3 = fmax(d3, fabs(spr[k] - scg[k]));
    }
    cm_note("stepper, pcg on carried orderings: max diff %.2e; %g analyses, %g orderings", d3, cm_stat(pr, "analyses"),
            cm_stat(pr, "orderings"));
    ck_assert_msg(d3 <= 1e-9 * smax, "cholmod-pcg, carried orderings, vs cg: max stress difference %g", d3);
    ck_assert_msg(cm_stat(pr, "orderings") < cm_stat(pr, "analyses"), "%g orderings for %g analyses",
                  cm_stat(pr, "orderings"), cm_stat(pr, "analyses"));
    free(spr);
    odhs_solver_destroy(pr);
    ck_assert(smax > 0.0);
    cm_note("stepper: %d steps, %llu events; max |sigma_xy| %.6g; max diff cholmod %.2e, pcg %.2e; cholmod %g analyses "
            "%g factorizations; pcg %g updates %g factorizations %g analyses",
            nsteps, (unsigned long long)ecg, smax, d1, d2, cm_stat(ch, "analyses"), cm_stat(ch, "factorizations"),
            cm_stat(pc, "updates"), cm_stat(pc, "factorizations"), cm_stat(pc, "analyses"));
    ck_assert_msg(d1 <= 1e-9 * smax, "cholmod vs cg: max stress difference %g (max stress %g)", d1, smax);
    ck_assert_msg(d2 <= 1e-9 * smax, "cholmod-pcg vs cg: max stress difference %g (max stress %g)", d2, smax);
    /* the cholmod backend reused analyses between events; the pcg backend
     * updated its factor instead of refactoring at every event */
    double an = cm_stat(ch, "analyses"), fa = cm_stat(ch, "factorizations");
    ck_assert_msg(an < fa, "cholmod: %g analyses for %g factorisations", an, fa);
    ck_assert_msg(cm_stat(pc, "updates") > 0.0, "cholmod-pcg did no update");
    ck_assert_msg(cm_stat(pc, "factorizations") < fa, "cholmod-pcg: %g factorisations (cholmod %g)",
                  cm_stat(pc, "factorizations"), fa);
    free(scg);
    free(sch);
    free(spc);
    odhs_solver_destroy(cg);
    odhs_solver_destroy(ch);
    odhs_solver_destroy(pc);
    odhs_system_destroy(base);
}
END_TEST

/* cholmod-pcg's supernodal route (since 0.2.20): full factorisations by
 * supernodes, converted to the simplicial LDL' that the updates modify. On a
 * 3D network it must give what the simplicial route gives: the answer of the
 * dense backend, an exact factor at a fixed geometry after single contact
 * changes (three iterations at most), and agreement while the particles
 * move; "supernodal" says which route the last full factorisation took. The
 * same through "auto", which hands the parameter on. */
static void cm_pcg_route(double mode, double *itmax_fixed, double *facs)
{
    cm_case c = cm_random_case(3, 200, 71, 30);
    tu_rng rng;
    tu_rng_seed(&rng, 72);
    size_t nmax = c.nc + 40;
    double *b = malloc(nmax * sizeof *b), *x = calloc(nmax, sizeof *x);
    ck_assert(b && x);
    odhs_solver *p = cm_new(&odhs_solver_type_cholmod_pcg);
    ck_assert_int_eq(odhs_solver_set_param(p, "supernodal", mode), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(p, "refactor_every", 0.0), ODHS_OK);
    cm_rhs(c.net, &rng, b);
    ck_assert(cm_vs_dense(p, c.net, b, x) < 1e-10);
    ck_assert_double_eq(cm_stat(p, "supernodal"), mode == 1.0 ? 1.0 : 0.0);
    ck_assert_double_eq(cm_stat(p, "factorizations"), 1.0);
    double itmax = 0.0;
    for (int op = 0; op < 60; ++op) { /* fixed geometry: updates keep the factor exact */
        random_change(&c, &rng, c.nc - 10, c.nc + 12);
        size_t nc = odhs_network_count(c.net);
        cm_rhs(c.net, &rng, b);
        memset(x, 0, nc * sizeof *x);
        double d = cm_vs_dense(p, c.net, b, x);
        ck_assert_msg(d < 1e-10, "supernodal %g, op %d: pcg vs dense %g", mode, op, d);
        itmax = fmax(itmax, cm_stat(p, "iterations"));
    }
    ck_assert_msg(itmax <= 3.0, "supernodal %g: %g iterations with an exact updated factor", mode, itmax);
    ck_assert_msg(cm_stat(p, "updates") >= 50.0, "supernodal %g: only %g updates", mode, cm_stat(p, "updates"));
    *itmax_fixed = itmax;
    ck_assert_int_eq(odhs_solver_set_param(p, "refactor_every", 10.0), ODHS_OK);
    for (int op = 0; op < 40; ++op) { /* moving: an aged factor, refactored every 10 changes */
        random_change(&c, &rng, c.nc - 10, c.nc + 12);
        cm_jiggle(&c, &rng, 2e-3);
        size_t nc = odhs_network_count(c.net);
        cm_rhs(c.net, &rng, b);
        memset(x, 0, nc * sizeof *x);
        double d = cm_vs_dense(p, c.net, b, x);
        ck_assert_msg(d < 1e-10, "supernodal %g, moving op %d: pcg vs dense %g", mode, op, d);
    }
    *facs = cm_stat(p, "factorizations");
    ck_assert_msg(*facs >= 4.0, "supernodal %g: %g factorisations", mode, *facs);
    ck_assert_double_eq(cm_stat(p, "supernodal"), mode == 1.0 ? 1.0 : 0.0);
    odhs_solver_destroy(p);
    free(b);
    free(x);
    cm_case_free(&c);
}

START_TEST(test_pcg_supernodal)
{
    double it0, it1, f0, f1;
    cm_pcg_route(0.0, &it0, &f0);
    cm_pcg_route(1.0, &it1, &f1);
    cm_note("pcg supernodal route: fixed-geometry max iterations %g (simplicial %g), factorisations %g (%g)", it1,
            it0, f1, f0);
    /* a 3D packing: the supernodal route through auto, against the simplicial one */
    odhs_network *net = NULL;
    odhs_system *sys = cm_scene(3, 300, 0.62, 9, &net);
    size_t nc = odhs_network_count(net);
    tu_rng rng;
    tu_rng_seed(&rng, 10);
    double *b = malloc(nc * sizeof *b), *x0 = calloc(nc, sizeof *x0), *x1 = calloc(nc, sizeof *x1);
    ck_assert(b && x0 && x1);
    cm_rhs(net, &rng, b);
    odhs_solver *a0 = cm_by_name("auto"), *a1 = cm_by_name("auto");
    ck_assert_int_eq(odhs_solver_set_param(a1, "supernodal", 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(a1, "supernodal", 3.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_solve(a0, net, b, x0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_solve(a1, net, b, x1), ODHS_OK);
    const char *bname = NULL, *why = NULL;
    ck_assert_int_eq(odhs_solver_backend_name(a1, &bname, &why), ODHS_OK);
    ck_assert_str_eq(bname, "cholmod-pcg");
    ck_assert_double_eq(cm_stat(a0, "supernodal"), 0.0);
    ck_assert_double_eq(cm_stat(a1, "supernodal"), 1.0);
    double d = cm_reldiff(nc, x0, x1);
    cm_note("pcg supernodal route, 3D packing N = 300, Nc = %zu: auto simplicial vs supernodal %.2e", nc, d);
    ck_assert_msg(d < 1e-10, "auto: supernodal vs simplicial %g", d);
    odhs_solver_destroy(a0);
    odhs_solver_destroy(a1);
    free(b);
    free(x0);
    free(x1);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* cholmod-pcg's "ordering" and "ordering_reuse" (since 0.2.23). "ordering":
 * -1 CHOLMOD's choice (AMD, and METIS too when AMD's fill is high; the
 * default), 0 AMD, 1 METIS of the contact matrix: each gives the dense
 * backend's answer on 2D and 3D packings. "ordering_reuse" X >= 1: an
 * analysis for a changed contact set carries the last ordering over (kept
 * contacts keep their rank, new ones go last) instead
 * of ordering afresh, while the fill per contact stays within X times the
 * last fresh ordering's; 0 orders every analysis afresh; -1 (the default)
 * carries with X = 1.1 after a fresh ordering that called METIS. */

START_TEST(test_pcg_ordering)
{
    odhs_network *net3 = NULL; /* the 3D packing, kept for the stale case */
    odhs_system *sys3 = NULL;
    for (int dim = 2; dim <= 3; ++dim) {
        odhs_network *net = NULL;
        odhs_system *sys = cm_scene(dim, 200, dim == 2 ? 0.82 : 0.62, 40 + (uint64_t)dim, &net);
        size_t nc = odhs_network_count(net);
        tu_rng rng;
        tu_rng_seed(&rng, 41);
        double *b = malloc(nc * sizeof *b), *x = calloc(nc, sizeof *x);
        ck_assert(b && x);
        cm_rhs(net, &rng, b);
        for (int o = -1; o <= 1; ++o) {
            odhs_solver *p = cm_pcg_ordered((double)o, 0.0);
            memset(x, 0, nc * sizeof *x);
            double d = cm_vs_dense(p, net, b, x);
            cm_note("ordering %d, %dD packing N = 200, Nc = %zu: diff %.2e, lnz %g, flops %g", o, dim, nc, d,
                    cm_stat(p, "lnz"), cm_stat(p, "flops"));
            ck_assert_msg(d < 1e-10, "ordering %d, %dD: pcg vs dense %g", o, dim, d);
            ck_assert_double_eq(cm_stat(p, "ordering"), (double)o);
            ck_assert_double_eq(cm_stat(p, "analyses"), 1.0);
            ck_assert_double_eq(cm_stat(p, "orderings"), 1.0);
            ck_assert(cm_stat(p, "iterations") <= 3.0); /* a fresh exact factor */
            odhs_solver_destroy(p);
        }
        free(b);
        free(x);
        if (dim == 3) {
            net3 = net;
            sys3 = sys;
        } else {
            odhs_network_destroy(net);
            odhs_system_destroy(sys);
        }
    }

    /* contact changes, each refactorised with a new analysis (update_max 0).
     * mode 0: reuse off, an ordering per analysis; 1: reuse 1.25, one
     * ordering for all and a fill within the bound; 2: the default (-1) on
     * a network that AMD alone orders (fill below 5x): off; 3: the default
     * with METIS forced ("ordering" 1): carried */
    const double mode_order[4] = {-1.0, -1.0, -1.0, 1.0}, mode_reuse[4] = {0.0, 1.25, -1.0, -1.0};
    for (int mode = 0; mode < 4; ++mode) {
        cm_case c = cm_random_case(3, 200, 43, 60);
        tu_rng rng;
        tu_rng_seed(&rng, 44);
        size_t nmax = c.nc + 40;
        double *b = malloc(nmax * sizeof *b), *x = calloc(nmax, sizeof *x);
        ck_assert(b && x);
        odhs_solver *p = cm_new(&odhs_solver_type_cholmod_pcg);
        ck_assert_double_eq(cm_stat(p, "ordering_reuse"), -1.0); /* the default */
        ck_assert_double_eq(cm_stat(p, "ordering"), -1.0);
        ck_assert_int_eq(odhs_solver_set_param(p, "ordering", mode_order[mode]), ODHS_OK);
        ck_assert_int_eq(odhs_solver_set_param(p, "ordering_reuse", mode_reuse[mode]), ODHS_OK);
        ck_assert_int_eq(odhs_solver_set_param(p, "update_max", 0.0), ODHS_OK);
        cm_rhs(c.net, &rng, b);
        ck_assert(cm_vs_dense(p, c.net, b, x) < 1e-10);
        double fresh0 = cm_stat(p, "lnz") / (double)odhs_network_count(c.net);
        double bound = mode_reuse[mode] > 0.0 ? mode_reuse[mode] : 1.1;
        for (int op = 0; op < 12; ++op) {
            random_change(&c, &rng, c.nc - 6, c.nc + 6);
            size_t nc = odhs_network_count(c.net);
            cm_rhs(c.net, &rng, b);
            memset(x, 0, nc * sizeof *x);
            double d = cm_vs_dense(p, c.net, b, x);
            ck_assert_msg(d < 1e-10, "mode %d, op %d: pcg vs dense %g", mode, op, d);
            ck_assert(cm_stat(p, "iterations") <= 3.0);
            /* carried or fresh, never beyond the bound */
            if (cm_stat(p, "orderings") == 1.0)
                ck_assert_msg(cm_stat(p, "lnz") / (double)nc <= bound * fresh0 * (1.0 + 1e-12),
                              "mode %d, op %d: lnz per contact %g, fresh %g", mode, op,
                              cm_stat(p, "lnz") / (double)nc, fresh0);
        }
        double an = cm_stat(p, "analyses"), ord = cm_stat(p, "orderings");
        /* the fill of the carried ordering against a fresh one on the final network */
        odhs_solver *f = cm_pcg_ordered(mode_order[mode], 0.0);
        size_t nc = odhs_network_count(c.net);
        memset(x, 0, nc * sizeof *x);
        ck_assert(cm_vs_dense(f, c.net, b, x) < 1e-10);
        cm_note("mode %d (ordering %g, reuse %g): %g analyses, %g orderings; lnz %g, fresh ordering %g", mode,
                mode_order[mode], mode_reuse[mode], an, ord, cm_stat(p, "lnz"), cm_stat(f, "lnz"));
        ck_assert_msg(an >= 10.0, "mode %d: %g analyses", mode, an);
        if (mode == 1 || mode == 3) { /* 1.1 lets the fill of this small network pass its bound now and then */
            ck_assert_msg(mode == 1 ? ord <= 2.0 : ord <= 0.5 * an, "mode %d: %g orderings in %g analyses", mode, ord,
                          an);
            ck_assert(cm_stat(p, "lnz") <= bound * bound * cm_stat(f, "lnz"));
        } else
            ck_assert_msg(ord == an, "mode %d: %g orderings in %g analyses", mode, ord, an);
        odhs_solver_destroy(f);
        odhs_solver_destroy(p);
        free(b);
        free(x);
        cm_case_free(&c);
    }

    /* stale: the ordering of a thinned packing network (every third contact
     * kept) fills much more per contact on the whole network; that analysis
     * orders afresh, with the fill of a fresh solver */
    odhs_network *net = net3, *thin = NULL;
    odhs_system *sys = sys3;
    size_t nc = odhs_network_count(net);
    ck_assert_int_eq(odhs_network_create(sys, &thin), ODHS_OK);
    for (size_t k = 0; k < nc; k += 3) {
        size_t i, j;
        ck_assert_int_eq(odhs_network_get_contact(net, k, &i, &j, NULL), ODHS_OK);
        ck_assert_int_eq(odhs_network_add(thin, i, j, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    }
    ck_assert_int_eq(odhs_network_update_geometry(thin, sys), ODHS_OK);
    tu_rng rng;
    tu_rng_seed(&rng, 46);
    double *b = malloc(nc * sizeof *b), *x = calloc(nc, sizeof *x);
    ck_assert(b && x);
    odhs_solver *p = cm_pcg_ordered(-1.0, 1.15), *f = cm_pcg_ordered(-1.0, 0.0);
    cm_rhs(thin, &rng, b);
    ck_assert(cm_vs_dense(p, thin, b, x) < 1e-10);
    double lnz_thin = cm_stat(p, "lnz") / (double)odhs_network_count(thin);
    cm_rhs(net, &rng, b);
    memset(x, 0, nc * sizeof *x);
    ck_assert(cm_vs_dense(p, net, b, x) < 1e-10);
    memset(x, 0, nc * sizeof *x);
    ck_assert(cm_vs_dense(f, net, b, x) < 1e-10);
    cm_note("stale ordering: lnz per contact %g thinned, %g whole; %g orderings", lnz_thin,
            cm_stat(p, "lnz") / (double)nc, cm_stat(p, "orderings"));
    ck_assert_double_eq(cm_stat(p, "orderings"), 2.0);
    ck_assert_double_eq(cm_stat(p, "analyses"), 3.0); /* the thinned, the carried one rejected, the fresh one */
    ck_assert_double_eq(cm_stat(p, "lnz"), cm_stat(f, "lnz"));
    /* the carried permutation is the one analysed: a new analysis of the
     * same contacts (forced by a new "supernodal_switch") on the carried
     * METIS ordering has METIS's fill to the entry */
    {
        odhs_solver *m = cm_pcg_ordered(1.0, 1.5);
        memset(x, 0, nc * sizeof *x);
        ck_assert(cm_vs_dense(m, net, b, x) < 1e-10);
        double lnz_metis = cm_stat(m, "lnz");
        ck_assert_int_eq(odhs_solver_set_param(m, "supernodal_switch", 1e6), ODHS_OK);
        ck_assert_int_eq(odhs_network_update_geometry(net, sys), ODHS_OK);
        memset(x, 0, nc * sizeof *x);
        ck_assert(cm_vs_dense(m, net, b, x) < 1e-10);
        ck_assert_double_eq(cm_stat(m, "analyses"), 2.0);
        ck_assert_double_eq(cm_stat(m, "orderings"), 1.0);
        ck_assert_double_eq(cm_stat(m, "lnz"), lnz_metis);
        odhs_solver_destroy(m);
    }
    /* new contacts go last: from the packing without every tenth contact
     * to the whole, the carried ordering (never rejected) fills within 1.3
     * times a fresh one (1.17; ranked right after their latest neighbour
     * instead, the new contacts coupled subtrees: 1.39) */
    {
        odhs_network *most = NULL;
        ck_assert_int_eq(odhs_network_create(sys, &most), ODHS_OK);
        for (size_t k = 0; k < nc; ++k) {
            if (k % 10 == 5) continue;
            size_t i, j;
            ck_assert_int_eq(odhs_network_get_contact(net, k, &i, &j, NULL), ODHS_OK);
            ck_assert_int_eq(odhs_network_add(most, i, j, ODHS_CONTACT_TEMPORARY), ODHS_OK);
        }
        ck_assert_int_eq(odhs_network_update_geometry(most, sys), ODHS_OK);
        odhs_solver *m = cm_pcg_ordered(-1.0, 1e6);
        cm_rhs(most, &rng, b);
        memset(x, 0, nc * sizeof *x);
        ck_assert(cm_vs_dense(m, most, b, x) < 1e-10);
        cm_rhs(net, &rng, b);
        memset(x, 0, nc * sizeof *x);
        ck_assert(cm_vs_dense(m, net, b, x) < 1e-10);
        ck_assert_double_eq(cm_stat(m, "orderings"), 1.0);
        cm_note("new contacts last: lnz carried %g, fresh %g", cm_stat(m, "lnz"), cm_stat(f, "lnz"));
        ck_assert_msg(cm_stat(m, "lnz") <= 1.3 * cm_stat(f, "lnz"), "carried lnz %g, fresh %g", cm_stat(m, "lnz"),
                      cm_stat(f, "lnz"));
        odhs_solver_destroy(m);
        odhs_network_destroy(most);
    }
    /* another system (other N): ordered afresh */
    cm_case c2 = cm_random_case(3, 250, 47, 80);
    odhs_network *net2 = c2.net;
    size_t nc2 = odhs_network_count(net2);
    double *b2 = malloc(nc2 * sizeof *b2), *x2 = calloc(nc2, sizeof *x2);
    ck_assert(b2 && x2);
    cm_rhs(net2, &rng, b2);
    ck_assert(cm_vs_dense(p, net2, b2, x2) < 1e-10);
    ck_assert_double_eq(cm_stat(p, "orderings"), 3.0);
    /* bad values leave the parameters as they were */
    ck_assert_int_eq(odhs_solver_set_param(p, "ordering", 2.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "ordering", 0.5), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "ordering", -2.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "ordering_reuse", 0.5), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "ordering_reuse", -0.5), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "ordering_reuse", -2.0), ODHS_E_INVALID);
    ck_assert_int_ne(odhs_solver_set_param(p, "ordering_reuse", NAN), ODHS_OK); /* refused before the backend */
    ck_assert_double_eq(cm_stat(p, "ordering"), -1.0);
    ck_assert_double_eq(cm_stat(p, "ordering_reuse"), 1.15);
    /* through auto, which hands both on */
    odhs_solver *a = cm_by_name("auto");
    ck_assert_int_eq(odhs_solver_set_param(a, "ordering", 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(a, "ordering_reuse", 1.5), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(a, "ordering", 5.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(a, "ordering_reuse", 0.5), ODHS_E_INVALID);
    memset(x2, 0, nc2 * sizeof *x2);
    ck_assert(cm_vs_dense(a, net2, b2, x2) < 1e-10);
    const char *bname = NULL, *why = NULL;
    ck_assert_int_eq(odhs_solver_backend_name(a, &bname, &why), ODHS_OK);
    ck_assert_str_eq(bname, "cholmod-pcg");
    ck_assert_double_eq(cm_stat(a, "ordering"), 1.0);
    ck_assert_double_eq(cm_stat(a, "ordering_reuse"), 1.5);
    odhs_solver_destroy(a);
    odhs_solver_destroy(p);
    odhs_solver_destroy(f);
    odhs_network_destroy(thin);
    odhs_network_destroy(net);
    cm_case_free(&c2);
    odhs_system_destroy(sys);
    free(b);
    free(x);
    free(b2);
    free(x2);
}
END_TEST

/* The default route since 0.2.21: "supernodal" = -1 goes by supernodes
 * exactly when the analysis predicts at least "supernodal_switch" (200)
 * flops per entry of L, and a new switch takes effect at the next solve with
 * the same answer. "openmp" (0, the default: CHOLMOD's OpenMP loops on the
 * calling thread) does not change a bit of the result, and the calling
 * thread's OpenMP setting is as it was after the solve. */
#if defined(__GNUC__) && defined(__ELF__)
extern int omp_get_max_active_levels(void) __attribute__((weak));
extern void omp_set_max_active_levels(int) __attribute__((weak));
#endif
/* threads of this process (Linux), -1 where unknown */
static long cm_threads(void)
{
    FILE *f = fopen("/proc/self/status", "r");
    if (!f) return -1;
    char line[256];
    long t = -1;
    while (fgets(line, sizeof line, f))
        if (!strncmp(line, "Threads:", 8)) {
            t = strtol(line + 8, NULL, 10);
            break;
        }
    fclose(f);
    return t;
}
START_TEST(test_pcg_supernodal_switch)
{
    /* two copies of one network: a solve on the other copy makes the solver
     * set up again, where a new route takes effect */
    odhs_network *net = NULL, *net2 = NULL;
    odhs_system *sys = cm_scene(3, 300, 0.62, 9, &net), *sys2 = cm_scene(3, 300, 0.62, 9, &net2);
    ck_assert_uint_eq(odhs_network_count(net2), odhs_network_count(net));
    size_t nc = odhs_network_count(net);
    tu_rng rng;
    tu_rng_seed(&rng, 11);
    double *b = malloc(nc * sizeof *b), *x[4];
    ck_assert(b);
    for (int k = 0; k < 4; ++k) ck_assert((x[k] = calloc(nc, sizeof *x[k])) != NULL);
    cm_rhs(net, &rng, b);
    odhs_solver *p = cm_new(&odhs_solver_type_cholmod_pcg);
    ck_assert_double_eq(cm_stat(p, "supernodal_switch"), 200.0);
    ck_assert_double_eq(cm_stat(p, "openmp"), 0.0);
    ck_assert_int_eq(odhs_solver_solve(p, net, b, x[0]), ODHS_OK);
    double ratio = cm_stat(p, "flops") / cm_stat(p, "lnz");
    cm_note("pcg default route, 3D packing N = 300, Nc = %zu: %.1f flops per entry of L, supernodal %g", nc, ratio,
            cm_stat(p, "supernodal"));
    ck_assert(ratio > 10.0 && ratio < 200.0);
    ck_assert_double_eq(cm_stat(p, "supernodal"), 0.0); /* below the switch */
    /* a switch below this network's ratio: a new analysis, by supernodes */
    ck_assert_int_eq(odhs_solver_set_param(p, "supernodal_switch", 0.5 * ratio), ODHS_OK);
    ck_assert_int_eq(odhs_solver_solve(p, net, b, x[1]), ODHS_OK); /* the same network: the factor serves */
    ck_assert_double_eq(cm_stat(p, "supernodal"), 0.0);
    ck_assert_double_eq(cm_stat(p, "analyses"), 1.0);
    long t0 = cm_threads();
    ck_assert_int_eq(odhs_solver_solve(p, net2, b, x[1]), ODHS_OK);
    ck_assert_double_eq(cm_stat(p, "supernodal"), 1.0);
    long t1 = cm_threads(); /* "openmp" 0: CHOLMOD started no thread */
    ck_assert_msg(t1 == t0, "threads %ld -> %ld in a supernodal factorisation with openmp 0", t0, t1);
    ck_assert_double_eq(cm_stat(p, "analyses"), 2.0);
    ck_assert_msg(cm_reldiff(nc, x[0], x[1]) < 1e-10, "switch: %g", cm_reldiff(nc, x[0], x[1]));
    /* CHOLMOD's threads give the same bits */
    ck_assert_int_eq(odhs_solver_set_param(p, "openmp", 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(p, "supernodal_switch", 0.4 * ratio), ODHS_OK); /* analyse again */
    double f0 = cm_stat(p, "factorizations");
    ck_assert_int_eq(odhs_solver_solve(p, net, b, x[2]), ODHS_OK);
    ck_assert_double_eq(cm_stat(p, "factorizations"), f0 + 1.0);
    ck_assert_double_eq(cm_stat(p, "supernodal"), 1.0);
    /* CHOLMOD's threads (Debian's OpenMP build: 4 per parallel loop) start
     * only now: every supernodal factorisation before this one, the scenes'
     * compressions included, ran with the default "openmp" 0 on the
     * calling thread. Asserted where the process has an OpenMP runtime and
     * no OMP_THREAD_LIMIT. */
    long t2 = cm_threads();
    cm_note("threads: %ld before, %ld after a supernodal factorisation with openmp 0, %ld after one with openmp 1",
            t0, t1, t2);
#if defined(__GNUC__) && defined(__ELF__)
    if (omp_get_max_active_levels && !getenv("OMP_THREAD_LIMIT") && t1 > 0)
        ck_assert_msg(t2 > t1, "openmp 1 started no thread (%ld -> %ld): were CHOLMOD's threads on before?", t1, t2);
    else
        cm_note("threads with openmp 1 not checked (no OpenMP runtime bound, or OMP_THREAD_LIMIT set)");
#endif
    f0 = cm_stat(p, "factorizations");
    ck_assert_int_eq(odhs_solver_set_param(p, "openmp", 0.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(p, "supernodal_switch", 0.3 * ratio), ODHS_OK);
#if defined(__GNUC__) && defined(__ELF__)
    int levels = -1;
    if (omp_get_max_active_levels && omp_set_max_active_levels) {
        levels = omp_get_max_active_levels();
        omp_set_max_active_levels(3);
    }
#endif
    ck_assert_int_eq(odhs_solver_solve(p, net2, b, x[3]), ODHS_OK);
#if defined(__GNUC__) && defined(__ELF__)
    if (levels >= 0) {
        ck_assert_int_eq(omp_get_max_active_levels(), 3); /* restored after the factorisation */
        omp_set_max_active_levels(levels);
    }
#endif
    ck_assert_double_eq(cm_stat(p, "factorizations"), f0 + 1.0);
    ck_assert_double_eq(cm_stat(p, "supernodal"), 1.0);
    ck_assert(!memcmp(x[2], x[3], nc * sizeof *x[2]));
    /* back above the ratio: simplicial again */
    ck_assert_int_eq(odhs_solver_set_param(p, "supernodal_switch", 1e300), ODHS_OK);
    ck_assert_int_eq(odhs_solver_solve(p, net, b, x[1]), ODHS_OK);
    ck_assert_double_eq(cm_stat(p, "analyses"), 5.0);
    ck_assert_double_eq(cm_stat(p, "supernodal"), 0.0);
    ck_assert_msg(cm_reldiff(nc, x[0], x[1]) < 1e-10, "switch back: %g", cm_reldiff(nc, x[0], x[1]));
    /* bad values are refused and leave the old ones */
    ck_assert_int_eq(odhs_solver_set_param(p, "supernodal_switch", -1.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "supernodal_switch", NAN), ODHS_E_NONFINITE);
    ck_assert_int_eq(odhs_solver_set_param(p, "openmp", 0.5), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "openmp", 2.0), ODHS_E_INVALID);
    ck_assert_double_eq(cm_stat(p, "supernodal_switch"), 1e300);
    ck_assert_double_eq(cm_stat(p, "openmp"), 0.0);
    odhs_solver_destroy(p);
    /* through auto, which hands both on; and the direct backend's "openmp" */
    odhs_solver *a = cm_by_name("auto");
    ck_assert_int_eq(odhs_solver_set_param(a, "supernodal_switch", 0.5 * ratio), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(a, "openmp", 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(a, "supernodal_switch", -2.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(a, "openmp", 3.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_solve(a, net, b, x[2]), ODHS_OK);
    ck_assert_double_eq(cm_stat(a, "supernodal"), 1.0);
    ck_assert_double_eq(cm_stat(a, "openmp"), 1.0);
    ck_assert_msg(cm_reldiff(nc, x[0], x[2]) < 1e-10, "auto: %g", cm_reldiff(nc, x[0], x[2]));
    /* and to the backend it already has */
    ck_assert_int_eq(odhs_solver_set_param(a, "openmp", 0.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(a, "supernodal_switch", 1e300), ODHS_OK);
    ck_assert_double_eq(cm_stat(a, "openmp"), 0.0);
    ck_assert_double_eq(cm_stat(a, "supernodal_switch"), 1e300);
    odhs_solver_destroy(a);
    odhs_solver *d = cm_new(&odhs_solver_type_cholmod);
    ck_assert_double_eq(cm_stat(d, "openmp"), 0.0);
    ck_assert_int_eq(odhs_solver_set_param(d, "supernodal", 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_solve(d, net, b, x[2]), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(d, "openmp", 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(d, "openmp", -1.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_solve(d, net2, b, x[3]), ODHS_OK); /* a new factorisation, same pattern */
    ck_assert_double_eq(cm_stat(d, "factorizations"), 2.0);
    ck_assert_double_eq(cm_stat(d, "supernodal"), 1.0);
    ck_assert(!memcmp(x[2], x[3], nc * sizeof *x[2]));
    ck_assert_msg(cm_reldiff(nc, x[0], x[3]) < 1e-10, "cholmod: %g", cm_reldiff(nc, x[0], x[3]));
    odhs_solver_destroy(d);
    for (int k = 0; k < 4; ++k) free(x[k]);
    free(b);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
    odhs_network_destroy(net2);
    odhs_system_destroy(sys2);
}
END_TEST

/* A shear run's events at N = 512: each new contact enters the factor in a
 * free slot, and a column of L that outgrows its room moves to the end of the
 * factor and leaves a hole, so the allocation outgrows PCG_NZMAX_GROWTH (2.5)
 * times the fresh factor's long before the fill doubles. Since 0.2.19 the
 * backend packs the factor then instead of refactoring: with periodic
 * refactoring off, 0.2.18 refactored 24 times over this run and 0.2.19 13
 * times. The run must equal the direct backend's (the same events, the same
 * stress to 1e-9). */
static void cm_pack_run(const odhs_system *base, odhs_solver *sol, double *sxy, uint64_t *events)
{
    odhs_system *sys;
    odhs_driver *drv;
    odhs_stepper *st = cm_shear_stepper(base, sol, &sys, &drv);
    int rc = odhs_stepper_run_until_strain(st, 0.05);
    ck_assert_msg(rc == ODHS_OK, "%s: %d (%s)", odhs_solver_name(sol), rc, odhs_stepper_errmsg(st));
    uint64_t steps, coll, open;
    ck_assert_int_eq(odhs_stepper_counts(st, &steps, &coll, &open), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_shear_stress(st, sxy), ODHS_OK);
    *events = coll + open;
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
}

START_TEST(test_pcg_pack_shear)
{
    odhs_system *base = NULL;
    odhs_driver *drv = NULL;
    odhs_stepper *st = NULL;
    odhs_solver *au = cm_by_name("auto");
    ck_assert_int_eq(odhs_system_create(2, 512, &base), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(base, 0.5, 1.4, 0.03, 5), ODHS_OK);
    ck_assert_int_eq(odhs_system_place_random(base, 0.45, 6), ODHS_OK);
    ck_assert_int_eq(odhs_driver_create(&drv), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_compression_rate(drv, 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_create(base, drv, au, &st), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_set_integrator(st, ODHS_INTEGRATOR_BATCHED), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_packing_fraction(st, 0.80), ODHS_OK);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(au);
    odhs_solver *pc = cm_new(&odhs_solver_type_cholmod_pcg), *ch = cm_new(&odhs_solver_type_cholmod);
    ck_assert_int_eq(odhs_solver_set_param(pc, "refactor_every", 0.0), ODHS_OK);
    double spc, sch;
    uint64_t epc, ech;
    cm_pack_run(base, pc, &spc, &epc);
    cm_pack_run(base, ch, &sch, &ech);
    cm_note("pack: %llu events, sigma_xy %.12g (cholmod %.12g); packs %g, factorizations %g, updates %g",
            (unsigned long long)epc, spc, sch, cm_stat(pc, "packs"), cm_stat(pc, "factorizations"),
            cm_stat(pc, "updates"));
    ck_assert_msg(epc > 300, "only %llu events", (unsigned long long)epc);
    ck_assert_uint_eq(epc, ech);
    ck_assert_msg(fabs(spc - sch) <= 1e-9 * fabs(sch), "sigma_xy %.15g against cholmod's %.15g", spc, sch);
    ck_assert_msg(cm_stat(pc, "packs") >= 1.0, "the factor was never packed");
    ck_assert_msg(cm_stat(pc, "factorizations") <= 18.0, "%g factorisations (0.2.18: 24)",
                  cm_stat(pc, "factorizations"));
    odhs_solver_destroy(pc);
    odhs_solver_destroy(ch);
    odhs_system_destroy(base);
}
END_TEST

Suite *make_cholmod_suite(void)
{
    Suite *s = suite_create("cholmod");
    TCase *tc = tcase_create("agreement");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_agree_2d);
    tcase_add_test(tc, test_agree_3d);
    tcase_add_test(tc, test_agree_packing);
    tcase_add_test(tc, test_symbolic_reuse);
    tcase_add_test(tc, test_params_stats);
    suite_add_tcase(s, tc);

    tc = tcase_create("singular");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_singular_ring);
    tcase_add_test(tc, test_singular_square_lattice);
    tcase_add_test(tc, test_singular_hex_patch);
    tcase_add_test(tc, test_min_rcond_and_pcg_singular);
    tcase_add_test(tc, test_pcg_update_to_singular);
    suite_add_tcase(s, tc);

    tc = tcase_create("updates");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_pcg_updates_fixed_geometry);
    tcase_add_test(tc, test_pcg_updates_moving_2d);
    tcase_add_test(tc, test_pcg_updates_moving_3d);
    tcase_add_test(tc, test_pcg_capacity);
    tcase_add_test(tc, test_pcg_bulk_insertions);
    tcase_add_test(tc, test_pcg_supernodal);
    tcase_add_test(tc, test_pcg_supernodal_switch);
    suite_add_tcase(s, tc);

    tc = tcase_create("ordering");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_pcg_ordering);
    suite_add_tcase(s, tc);

    tc = tcase_create("stepper");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_stepper_shear);
    tcase_add_test(tc, test_pcg_pack_shear);
    suite_add_tcase(s, tc);
    return s;
}

#else /* !ODHS_HAVE_SUITESPARSE */

START_TEST(test_not_installed)
{
    odhs_solver *s = (odhs_solver *)&s; /* must be reset to NULL */
    ck_assert_int_eq(odhs_solver_create_by_name("cholmod", &s), ODHS_E_NOTINSTALLED);
    ck_assert_ptr_null(s);
}
END_TEST

Suite *make_cholmod_suite(void)
{
    Suite *s = suite_create("cholmod");
    TCase *tc = tcase_create("not_installed");
    tcase_add_test(tc, test_not_installed);
    suite_add_tcase(s, tc);
    return s;
}

#endif /* ODHS_HAVE_SUITESPARSE */
