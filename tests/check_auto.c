/*
 * libodhs - tests of the "auto" solver (lib/solvers/auto.c) and of
 * odhs_solver_backend_name.
 *
 *  - choice: the primary backend follows Nc and the build (dense for small
 *    networks, cholmod-pcg / cholmod with SuiteSparse, cg without; the
 *    no-SuiteSparse choice is also exercised in a SuiteSparse build through
 *    the "suitesparse" parameter, and a build with SUITESPARSE=0 checks that
 *    asking for it gives ODHS_E_NOTINSTALLED);
 *  - agreement: on random full-rank networks (2D, 3D) auto agrees with every
 *    other backend to 1e-9 in the forces (N x = b and least squares) and in
 *    the velocities g - S^T x; a sheared stepper run with auto matches one
 *    with dense (stress series, event counts);
 *  - fallback on an ill-conditioned full-rank chain (cond(N) ~ 1e16):
 *    Cholesky is rejected, QR answers, the fallback is visible (name,
 *    description, counters) and the forces match a binary128-free check
 *    (|S^T x - g| minimal: S (S^T x - g) = 0 to round-off of cond(S^T));
 *  - hyperstatic (rank-deficient) networks: the fallback reaches the
 *    least-squares route, the reported rank equals the SVD's, and the forces
 *    are the minimum-norm least-squares ones, compared with LAPACK dgelsd on
 *    the dense S^T (an independent route), through both the SVD and the CG
 *    variant and both entry points (solve_ls and solve with b = S g);
 *  - stickiness and retry of the primary after "retry_after" solves;
 *  - parameters and statistics.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <check.h>
#include <float.h>
#include <lapacke.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "testutil.h"

#include "netcase.h"

typedef tu_netcase au_case;
#define au_free tu_netcase_free
#define au_refresh tu_netcase_refresh
#define au_make tu_netcase_make

static au_case au_random(int dim, size_t n, uint64_t seed, size_t extra, double maxgap)
{
    return tu_netcase_random(dim, n, seed, extra, maxgap, 0.11);
}

static odhs_solver *au_solver(const char *name)
{
    odhs_solver *s = NULL;
    CK_OK(odhs_solver_create_by_name(name, &s));
    return s;
}

static double au_stat(const odhs_solver *s, const char *key)
{
    double v = NAN;
    int st = odhs_solver_get_stat(s, key, &v);
    ck_assert_msg(st == ODHS_OK, "get_stat(%s) = %d: %s", key, st, odhs_solver_errmsg(s));
    return v;
}

static const char *au_backend(const odhs_solver *s, const char **why)
{
    const char *name = NULL, *w = NULL;
    CK_OK(odhs_solver_backend_name(s, &name, &w));
    ck_assert_ptr_nonnull(name);
    ck_assert_ptr_nonnull(w);
    if (why) *why = w;
    return name;
}

static double au_reldiff(size_t n, const double *a, const double *b)
{
    double d = 0.0, s = 0.0;
    for (size_t k = 0; k < n; ++k) {
        d += (a[k] - b[k]) * (a[k] - b[k]);
        s += b[k] * b[k];
    }
    return s > 0.0 ? sqrt(d / s) : sqrt(d);
}

/* dense S^T, column-major nd x nc */
static double *au_dense_ST(const au_case *c)
{
    double *A = xcalloc(c->nd * c->nc, sizeof *A), *e = xcalloc(c->nc, sizeof *e);
    for (size_t j = 0; j < c->nc; ++j) {
        e[j] = 1.0;
        CK_OK(odhs_network_apply_ST(c->net, e, A + j * c->nd));
        e[j] = 0.0;
    }
    free(e);
    return A;
}

/* minimum-norm least-squares x = (S^T)^+ g by LAPACK dgelsd (SVD, divide and
 * conquer), singular values below 1e-10 s_max treated as zero; *rank out */
static void au_pinv_ref(const au_case *c, const double *g, double *x, size_t *rank)
{
    double *A = au_dense_ST(c);
    size_t m = c->nd, n = c->nc, ldb = m > n ? m : n;
    double *B = xcalloc(ldb, sizeof *B), *sv = xcalloc(m < n ? m : n, sizeof *sv);
    memcpy(B, g, m * sizeof *g);
    lapack_int rk = 0;
    lapack_int info = LAPACKE_dgelsd(LAPACK_COL_MAJOR, (lapack_int)m, (lapack_int)n, 1, A, (lapack_int)m, B,
                                     (lapack_int)ldb, sv, 1e-10, &rk);
    ck_assert_int_eq(info, 0);
    memcpy(x, B, n * sizeof *x);
    *rank = (size_t)rk;
    free(A);
    free(B);
    free(sv);
}

static void au_vec(size_t n, double *v, tu_rng *rng)
{
    for (size_t k = 0; k < n; ++k) v[k] = tu_uniform_in(rng, -1.0, 1.0);
}

/* ------------------------------------------------------------------------ */
/* choice                                                                    */
/* ------------------------------------------------------------------------ */

START_TEST(test_choice)
{
    au_case small = au_random(2, 8, 11, 2, 0.6), big = au_random(2, 150, 12, 60, 0.5);
    ck_assert_uint_le(small.nc, 16);
    ck_assert_uint_gt(big.nc, 100);
    odhs_solver *a = au_solver("auto");
    ck_assert_str_eq(odhs_solver_name(a), "auto");
    ck_assert_str_eq(au_backend(a, NULL), "auto"); /* before the first solve */
    ck_assert_double_eq(au_stat(a, "backend"), -1.0);
    tu_rng rng;
    tu_rng_seed(&rng, 13);
    double *b = xcalloc(big.nc, sizeof *b), *x = xcalloc(big.nc, sizeof *x);
    au_vec(big.nc, b, &rng);
    const char *why;
    CK_OK(odhs_solver_solve(a, small.net, b, x));
    ck_assert_str_eq(au_backend(a, &why), "dense");
    ck_assert_str_eq(why, "");
    ck_assert_double_eq(au_stat(a, "backend"), 1.0);
    ck_assert_double_eq(au_stat(a, "primary"), 1.0);
    memset(x, 0, big.nc * sizeof *x);
    CK_OK(odhs_solver_solve(a, big.net, b, x));
#ifdef ODHS_HAVE_SUITESPARSE
    ck_assert_double_eq(au_stat(a, "suitesparse"), 1.0);
    ck_assert_str_eq(au_backend(a, &why), "cholmod-pcg");
    ck_assert_double_eq(au_stat(a, "primary"), 3.0);
    /* the backend's own statistics pass through */
    ck_assert(au_stat(a, "iterations") >= 1.0);
    ck_assert(au_stat(a, "nnz_L") > 0.0);
    CK_OK(odhs_solver_set_param(a, "prefer", 1.0));
    CK_OK(odhs_solver_solve(a, big.net, b, x));
    ck_assert_str_eq(au_backend(a, NULL), "cholmod");
    ck_assert_double_eq(au_stat(a, "factorizations"), 1.0);
    CK_OK(odhs_solver_set_param(a, "prefer", 0.0));
    /* as without SuiteSparse: dense up to 400 contacts, cg above */
    CK_OK(odhs_solver_set_param(a, "suitesparse", 0.0));
#else
    ck_assert_double_eq(au_stat(a, "suitesparse"), 0.0);
    /* a build with SUITESPARSE=0: the SuiteSparse backends are not there */
    odhs_solver *none = NULL;
    ck_assert_int_eq(odhs_solver_create_by_name("cholmod-pcg", &none), ODHS_E_NOTINSTALLED);
    ck_assert_int_eq(odhs_solver_create_by_name("spqr", &none), ODHS_E_NOTINSTALLED);
    ck_assert_int_eq(odhs_solver_set_param(a, "suitesparse", 1.0), ODHS_E_NOTINSTALLED);
#endif
    CK_OK(odhs_solver_solve(a, big.net, b, x));
    ck_assert_str_eq(au_backend(a, NULL), "dense");
    CK_OK(odhs_solver_set_param(a, "dense_max", 50.0));
    memset(x, 0, big.nc * sizeof *x);
    CK_OK(odhs_solver_solve(a, big.net, b, x));
    ck_assert_str_eq(au_backend(a, &why), "cg");
    ck_assert_str_eq(why, "");
    ck_assert(au_stat(a, "iterations") >= 1.0);
    ck_assert_double_eq(au_stat(a, "fallbacks"), 0.0);
    ck_assert_double_eq(au_stat(a, "fallback_solves"), 0.0);
    #ifdef ODHS_HAVE_SUITESPARSE
    ck_assert_double_eq(au_stat(a, "solves"), 5.0);
#else
    ck_assert_double_eq(au_stat(a, "solves"), 4.0);
#endif
    /* other handles: their own name */
    odhs_solver *cg = au_solver("cg");
    ck_assert_str_eq(au_backend(cg, &why), "cg");
    ck_assert_str_eq(why, "");
    odhs_solver_destroy(cg);
    odhs_solver_destroy(a);
    free(b);
    free(x);
    au_free(&small);
    au_free(&big);
}
END_TEST

START_TEST(test_params)
{
    odhs_solver *a = au_solver("auto");
    const char *bad[] = {"dense_max", "lsq_rcond", "lsq_rcond", "prefer", "retry_after", "check_tol", "suitesparse",
                         "no-such-param", "retry_after_lsq"};
    const double val[] = {-2.0, 0.0, 1.0, 0.5, -1.0, 0.0, 2.0, 1.0, -1.0};
    for (size_t k = 0; k < sizeof val / sizeof *val; ++k)
        ck_assert_msg(odhs_solver_set_param(a, bad[k], val[k]) == ODHS_E_INVALID, "%s = %g accepted", bad[k],
                      val[k]);
    CK_OK(odhs_solver_set_param(a, "dense_max", -1.0));
    CK_OK(odhs_solver_set_param(a, "lsq_dense_max", 0.0));
    CK_OK(odhs_solver_set_param(a, "check_tol", 1e-8));
    double v;
    /* "tol": the iterative backends' residual, their default 1e-12 until set */
    ck_assert_double_eq(au_stat(a, "tol"), 1e-12);
    CK_OK(odhs_solver_set_param(a, "tol", 1e-9));
    ck_assert_double_eq(au_stat(a, "tol"), 1e-9);
    ck_assert_int_eq(odhs_solver_set_param(a, "tol", 1.0), ODHS_E_INVALID);
    ck_assert_double_eq(au_stat(a, "tol"), 1e-9);
    ck_assert_int_eq(odhs_solver_get_stat(a, "no-such-stat", &v), ODHS_E_INVALID);
    ck_assert_double_eq(au_stat(a, "fallbacks"), 0.0);
    ck_assert_double_eq(au_stat(a, "last_failure"), 0.0);
    odhs_solver_destroy(a);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* agreement                                                                 */
/* ------------------------------------------------------------------------ */

static void agree(int dim, size_t n, uint64_t seed, size_t extra)
{
    au_case c = au_random(dim, n, seed, extra, 0.5);
    tu_rng rng;
    tu_rng_seed(&rng, seed + 1);
    double *g = xcalloc(c.nd, sizeof *g), *b = xcalloc(c.nc, sizeof *b);
    au_vec(c.nd, g, &rng);
    CK_OK(odhs_network_apply_S(c.net, g, b));
    const char *names[] = {"dense", "cg", "cholmod", "cholmod-pcg", "spqr", "auto"};
    enum { NS = 6 };
    double *x[NS], *xl[NS], *v[NS];
    int have[NS] = {0};
    for (int k = 0; k < NS; ++k) {
        x[k] = xcalloc(c.nc, sizeof *x[k]);
        xl[k] = xcalloc(c.nc, sizeof *xl[k]);
        v[k] = xcalloc(c.nd, sizeof *v[k]);
        odhs_solver *s = NULL;
        int st = odhs_solver_create_by_name(names[k], &s);
        if (st == ODHS_E_NOTINSTALLED) continue;
        CK_OK(st);
        if (!strcmp(names[k], "cg")) CK_OK(odhs_solver_set_param(s, "tol", 1e-14));
        st = odhs_solver_solve(s, c.net, b, x[k]);
        ck_assert_msg(st == ODHS_OK, "%s: %s", names[k], odhs_solver_errmsg(s));
        st = odhs_solver_solve_ls(s, c.net, g, xl[k]);
        ck_assert_msg(st == ODHS_OK, "%s (ls): %s", names[k], odhs_solver_errmsg(s));
        /* velocities (non-affine part): u = g - S^T x */
        CK_OK(odhs_network_apply_ST(c.net, xl[k], v[k]));
        for (size_t q = 0; q < c.nd; ++q) v[k][q] = g[q] - v[k][q];
        have[k] = 1;
        odhs_solver_destroy(s);
    }
    double worst = 0.0;
    for (int k = 1; k < NS; ++k) {
        if (!have[k]) continue;
        double e1 = au_reldiff(c.nc, x[k], x[0]), e2 = au_reldiff(c.nc, xl[k], x[0]),
               e3 = au_reldiff(c.nd, v[k], v[0]);
        ck_assert_msg(e1 <= 1e-9 && e2 <= 1e-9 && e3 <= 1e-9,
                      "%dD N=%zu: %s differs from dense: forces %.3g, least squares %.3g, velocities %.3g", dim, n,
                      names[k], e1, e2, e3);
        worst = fmax(worst, fmax(e1, fmax(e2, e3)));
    }
    fprintf(stderr, "[auto] %dD N=%zu Nc=%zu: all backends agree with dense to %.1e\n", dim, n, c.nc, worst);
    for (int k = 0; k < NS; ++k) {
        free(x[k]);
        free(xl[k]);
        free(v[k]);
    }
    free(g);
    free(b);
    au_free(&c);
}

START_TEST(test_agree_2d) { agree(2, 300, 103, 80); }
END_TEST
START_TEST(test_agree_3d) { agree(3, 120, 22, 30); }
END_TEST

/* a sheared stepper run with auto against one with dense */
START_TEST(test_stepper_shear)
{
    const size_t n = 48;
    odhs_system *base = tu_compressed_discs(n, 31, 0.78);
    odhs_system *sys[2];
    odhs_driver *drv[2];
    odhs_solver *sol[2];
    odhs_stepper *st[2];
    for (int k = 0; k < 2; ++k) {
        CK_OK(odhs_system_clone(base, &sys[k]));
        CK_OK(odhs_driver_create(&drv[k]));
        CK_OK(odhs_driver_set_shear_rate(drv[k], 1.0));
        sol[k] = au_solver(k ? "dense" : "auto");
        CK_OK(odhs_stepper_create(sys[k], drv[k], sol[k], &st[k]));
        CK_OK(odhs_stepper_reset(st[k]));
    }
    double smax = 0.0, worst = 0.0, g0 = 0.0, s[2];
    long steps = 0;
    while (steps < 300) {
        CK_OK(odhs_stepper_strain(st[0], &g0));
        if (g0 >= 0.02) break;
        for (int k = 0; k < 2; ++k) {
            int rc = odhs_stepper_step(st[k], NULL);
            ck_assert_msg(rc == ODHS_OK, "step %ld (%s): %d %s", steps, k ? "dense" : "auto", rc,
                          odhs_stepper_errmsg(st[k]));
            CK_OK(odhs_stepper_shear_stress(st[k], &s[k]));
        }
        smax = fmax(smax, fabs(s[1]));
        worst = fmax(worst, fabs(s[0] - s[1]));
        /* default settings: the drift correction after every step (its solve
         * at a relaxed residual) leaves the contact gaps at round-off */
        double gap, ov;
        CK_OK(odhs_stepper_errors(st[0], &gap, &ov));
        ck_assert_msg(gap <= 1e-13 && ov <= 1e-13, "step %ld: contact gap %.3g, overlap %.3g", steps, gap, ov);
        steps++;
    }
    ck_assert(smax > 0.0);
    ck_assert_msg(worst <= 1e-9 * smax, "stress series differ by %.3g of max", worst / smax);
    uint64_t e[2][3];
    for (int k = 0; k < 2; ++k) CK_OK(odhs_stepper_counts(st[k], &e[k][0], &e[k][1], &e[k][2]));
    ck_assert_uint_eq(e[0][1], e[1][1]);
    ck_assert_uint_eq(e[0][2], e[1][2]);
    ck_assert_uint_gt(e[0][1], 0);
    const char *name = au_backend(sol[0], NULL);
    fprintf(stderr, "[auto] stepper shear vs dense: %ld steps, %llu collisions, stress diff %.1e of max, backend %s\n",
            steps, (unsigned long long)e[0][1], worst / smax, name);
    for (int k = 0; k < 2; ++k) {
        odhs_stepper_destroy(st[k]);
        odhs_solver_destroy(sol[k]);
        odhs_driver_destroy(drv[k]);
        odhs_system_destroy(sys[k]);
    }
    odhs_system_destroy(base);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* fallbacks                                                                 */
/* ------------------------------------------------------------------------ */

/* a nearly straight zigzag ring of K discs closing through the periodic box
 * (as in check_spqr.c): smallest singular value of S^T ~ theta, so cond(N) ~
 * theta^-2 while S^T keeps full rank */
static au_case zigzag(size_t K, double theta, tu_rng *rng)
{
    const double a = 0.6, e[2] = {cos(a), sin(a)}, p[2] = {-sin(a), cos(a)};
    double *r = xcalloc(K, sizeof *r), *x = xcalloc(2 * K, sizeof *x), *tk = xcalloc(K, sizeof *tk);
    for (size_t k = 0; k < K; ++k) tk[k] = theta * (1.0 + 0.5 * tu_uniform_in(rng, -1.0, 1.0));
    double along = 0.0, s = 0.0, perp = 0.0;
    for (size_t k = 0; k < K; ++k) along += cos(tk[k]);
    for (size_t k = 0; k < K; ++k) {
        r[k] = 0.45;
        x[2 * k] = 0.5 + s * e[0] + perp * p[0];
        x[2 * k + 1] = 0.5 + s * e[1] + perp * p[1];
        s += cos(tk[k]);
        perp += k % 2 ? -sin(tk[k]) : sin(tk[k]);
    }
    double L[2] = {along * e[0], along * e[1]};
    au_case c = au_make(2, K, L, 0.0, r, x);
    for (size_t k = 0; k < K; ++k) {
        size_t i = k, j = (k + 1) % K;
        CK_OK(odhs_network_add(c.net, i < j ? i : j, i < j ? j : i, ODHS_CONTACT_TEMPORARY));
    }
    CK_OK(odhs_network_update_geometry(c.net, c.sys));
    au_refresh(&c);
    free(r);
    free(x);
    free(tk);
    return c;
}

/* normwise least-squares backward error |S (S^T x - g)| / (|S|^2 |x| + |S| |g|)
 * (|S| <= 2 for discs of degree <= 2) */
static double ls_eta(const au_case *c, const double *x, const double *g)
{
    double *rp = xcalloc(c->nd, sizeof *rp), *sr = xcalloc(c->nc, sizeof *sr), gn = 0.0, srn = 0.0, xn = 0.0;
    CK_OK(odhs_network_apply_ST(c->net, x, rp));
    for (size_t q = 0; q < c->nd; ++q) {
        rp[q] -= g[q];
        gn += g[q] * g[q];
    }
    for (size_t k = 0; k < c->nc; ++k) xn += x[k] * x[k];
    CK_OK(odhs_network_apply_S(c->net, rp, sr));
    for (size_t k = 0; k < c->nc; ++k) srn += sr[k] * sr[k];
    free(rp);
    free(sr);
    return sqrt(srn) / (4.0 * sqrt(xn) + 2.0 * sqrt(gn));
}

/* without SuiteSparse (any build, "suitesparse" = 0): dense rejects the
 * chain, the SVD least-squares route answers (full rank at lsq_rcond) */
START_TEST(test_fallback_ill_conditioned_nosuitesparse)
{
    tu_rng rng;
    tu_rng_seed(&rng, 42);
    au_case c = zigzag(40, 1e-8, &rng);
    double *g = xcalloc(c.nd, sizeof *g), *x = xcalloc(c.nc, sizeof *x), *xr = xcalloc(c.nc, sizeof *xr);
    au_vec(c.nd, g, &rng);
    odhs_solver *a = au_solver("auto");
    CK_OK(odhs_solver_set_param(a, "suitesparse", 0.0));
    CK_OK(odhs_solver_solve_ls(a, c.net, g, x));
    const char *why;
    ck_assert_str_eq(au_backend(a, &why), "lsq-svd");
    ck_assert_msg(strstr(why, "dense failed") && strstr(why, "-> lsq-svd"), "why = \"%s\"", why);
    ck_assert_double_eq(au_stat(a, "rank"), (double)c.nc);
    double eta = ls_eta(&c, x, g);
    ck_assert_msg(eta <= 1e-13, "least-squares backward error %.3g", eta);
    size_t rank;
    au_pinv_ref(&c, g, xr, &rank);
    ck_assert_uint_eq(rank, c.nc);
    /* two SVD routes to the same least-squares solution */
    double e = au_reldiff(c.nc, x, xr);
    ck_assert_msg(e <= 1e-9, "differs from dgelsd by %.3g", e);
    fprintf(stderr, "[auto] zigzag without SuiteSparse: %s (vs dgelsd %.1e, eta %.1e)\n", why, e, eta);
    odhs_solver_destroy(a);
    free(g);
    free(x);
    free(xr);
    au_free(&c);
}
END_TEST

START_TEST(test_fallback_ill_conditioned)
{
#ifdef ODHS_HAVE_SUITESPARSE
    tu_rng rng;
    tu_rng_seed(&rng, 41);
    au_case c = zigzag(40, 1e-8, &rng);
    ck_assert_uint_eq(c.nc, 40);
    double *g = xcalloc(c.nd, sizeof *g), *x = xcalloc(c.nc, sizeof *x), *xq = xcalloc(c.nc, sizeof *xq);
    au_vec(c.nd, g, &rng);
    /* Cholesky of N alone rejects it */
    odhs_solver *pcg = au_solver("cholmod-pcg"), *qr = au_solver("spqr"), *a = au_solver("auto");
    ck_assert_int_eq(odhs_solver_solve_ls(pcg, c.net, g, x), ODHS_E_SINGULAR);
    CK_OK(odhs_solver_solve_ls(qr, c.net, g, xq));
    ck_assert_double_eq(au_stat(qr, "rank"), (double)c.nc);
    memset(x, 0, c.nc * sizeof *x);
    CK_OK(odhs_solver_solve_ls(a, c.net, g, x));
    const char *why;
    ck_assert_str_eq(au_backend(a, &why), "spqr");
    ck_assert_msg(strstr(why, "cholmod-pcg failed") && strstr(why, "-> spqr"), "why = \"%s\"", why);
    ck_assert_double_eq(au_stat(a, "fallbacks"), 1.0);
    ck_assert_double_eq(au_stat(a, "fallback_solves"), 1.0);
    ck_assert_double_eq(au_stat(a, "rank_deficient"), 0.0);
    ck_assert_double_eq(au_stat(a, "last_failure"), (double)ODHS_E_SINGULAR);
    ck_assert_double_eq(au_stat(a, "rank"), (double)c.nc); /* spqr's statistic */
    ck_assert(au_reldiff(c.nc, x, xq) <= 1e-12);
    /* least squares: the residual S^T x - g is orthogonal to range(S^T) */
    double eta = ls_eta(&c, x, g);
    ck_assert_msg(eta <= 1e-13, "|S (S^T x - g)| / (|S|^2 |x| + |S| |g|) = %.3g", eta);
    /* sticky: the next solve goes to spqr directly, without a new failure */
    CK_OK(odhs_solver_solve_ls(a, c.net, g, x));
    ck_assert_str_eq(au_backend(a, &why), "spqr");
    ck_assert_msg(strstr(why, "kept"), "why = \"%s\"", why);
    ck_assert_double_eq(au_stat(a, "fallbacks"), 1.0);
    ck_assert_double_eq(au_stat(a, "fallback_solves"), 2.0);
    /* retry_after = 0: the primary is tried (and fails) again */
    CK_OK(odhs_solver_set_param(a, "retry_after", 0.0));
    CK_OK(odhs_solver_solve_ls(a, c.net, g, x));
    CK_OK(odhs_solver_solve_ls(a, c.net, g, x));
    ck_assert_double_eq(au_stat(a, "fallbacks"), 3.0);
    ck_assert_double_eq(au_stat(a, "fallback_solves"), 4.0);
    fprintf(stderr, "[auto] zigzag Nc=%zu theta=1e-8: %s\n", c.nc, why);
    odhs_solver_destroy(pcg);
    odhs_solver_destroy(qr);
    odhs_solver_destroy(a);
    free(g);
    free(x);
    free(xq);
    au_free(&c);
#endif
}
END_TEST

/* hyperstatic network: auto's least-squares forces against dgelsd */
static void check_hyperstatic(au_case *c, const char *what, size_t expect_nullity)
{
    tu_rng rng;
    tu_rng_seed(&rng, 51 + c->nc);
    double *g = xcalloc(c->nd, sizeof *g), *b = xcalloc(c->nc, sizeof *b), *xr = xcalloc(c->nc, sizeof *xr),
           *x = xcalloc(c->nc, sizeof *x);
    au_vec(c->nd, g, &rng);
    CK_OK(odhs_network_apply_S(c->net, g, b));
    size_t rank;
    au_pinv_ref(c, g, xr, &rank);
    ck_assert_msg(c->nc - rank == expect_nullity || expect_nullity == SIZE_MAX, "%s: SVD nullity %zu", what,
                  c->nc - rank);
    ck_assert_msg(c->nc > rank, "%s: not hyperstatic", what);
    /* configurations: default; without SuiteSparse; CG variant of lsq;
     * (SuiteSparse builds) the preconditioned CG variant, lsq-pcg */
#ifdef ODHS_HAVE_SUITESPARSE
    const int ncfg = 4;
#else
    const int ncfg = 3;
#endif
    for (int cfg = 0; cfg < ncfg; ++cfg) {
        odhs_solver *a = au_solver("auto");
        if (cfg == 3) CK_OK(odhs_solver_set_param(a, "lsq_dense_max", 0.0));
        if (cfg == 1 || cfg == 2) {
            int st = odhs_solver_set_param(a, "suitesparse", 0.0);
            ck_assert(st == ODHS_OK);
        }
        if (cfg == 2) {
            CK_OK(odhs_solver_set_param(a, "dense_max", 0.0));
            CK_OK(odhs_solver_set_param(a, "lsq_dense_max", 0.0));
        }
        for (int route = 0; route < 2; ++route) {
            memset(x, 0, c->nc * sizeof *x);
            if (route == 0) CK_OK(odhs_solver_solve_ls(a, c->net, g, x));
            else CK_OK(odhs_solver_solve(a, c->net, b, x));
            const char *why, *name = au_backend(a, &why);
            double e = au_reldiff(c->nc, x, xr);
            double tol = cfg == 2 ? 1e-8 : 1e-9;
            ck_assert_msg(e <= tol, "%s cfg %d route %d: %s forces differ from the minimum-norm ones by %.3g (%s)",
                          what, cfg, route, name, e, why);
            if (cfg < 2) {
                ck_assert_str_eq(name, "lsq-svd");
                ck_assert_double_eq(au_stat(a, "rank"), (double)rank);
                if (route == 0) {
                    ck_assert_msg(strstr(why, "failed") && strstr(why, "-> lsq-svd"), "why = \"%s\"", why);
#ifdef ODHS_HAVE_SUITESPARSE
                    if (cfg == 0) ck_assert_msg(strstr(why, "spqr failed"), "why = \"%s\"", why);
#endif
                } else {
                    /* least squares is not kept by default (retry_after_lsq
                     * = 0: an SVD costs far more than a failed Cholesky):
                     * the primary is tried, and fails, again */
                    ck_assert_msg(strstr(why, "failed") && strstr(why, "-> lsq-svd"), "why = \"%s\"", why);
                    /* with retry_after_lsq it is kept for the next solves */
                    odhs_solver *k = au_solver("auto");
                    if (cfg == 1) CK_OK(odhs_solver_set_param(k, "suitesparse", 0.0));
                    CK_OK(odhs_solver_set_param(k, "retry_after_lsq", 20.0));
                    for (int rep = 0; rep < 2; ++rep) {
                        memset(x, 0, c->nc * sizeof *x);
                        CK_OK(odhs_solver_solve(k, c->net, b, x));
                    }
                    const char *kwhy, *kname = au_backend(k, &kwhy);
                    ck_assert_str_eq(kname, "lsq-svd");
                    ck_assert_msg(strstr(kwhy, "lsq-svd (kept"), "why = \"%s\"", kwhy);
                    ck_assert_msg(au_reldiff(c->nc, x, xr) <= tol, "kept lsq-svd: forces differ");
                    ck_assert_double_eq(au_stat(k, "fallbacks"), au_stat(a, "fallbacks") / 2.0);
                    odhs_solver_destroy(k);
                }
            } else if (cfg == 2) {
                /* cg from zero on the consistent singular system: minimum
                 * norm already, no fallback needed */
                ck_assert(!strcmp(name, "cg") || !strcmp(name, "lsq-cg"));
            } else {
                /* after cholmod-pcg and spqr fail: CG preconditioned by a
                 * factor of N + beta I, from zero (minimum norm), in few
                 * iterations; the rank is spqr's */
                ck_assert_str_eq(name, "lsq-pcg");
                ck_assert_msg(strstr(why, "spqr failed") && strstr(why, "-> lsq-pcg"), "why = \"%s\"", why);
                double it = au_stat(a, "iterations");
                ck_assert_msg(it >= 1.0 && it <= 30.0, "%s: lsq-pcg took %g iterations", what, it);
                ck_assert_double_eq(au_stat(a, "rank"), (double)rank);
                if (route == 0)
                    fprintf(stderr, "[auto] %-28s lsq-pcg: %g iterations, forces vs dgelsd %.1e\n", what, it, e);
            }
            if (route == 0 && cfg == 0)
                fprintf(stderr, "[auto] %-28s Nc=%3zu rank %zu: %s (forces vs dgelsd %.1e)\n", what, c->nc, rank,
                        why, e);
            if (cfg != 2) ck_assert_double_eq(au_stat(a, "rank_deficient"), (double)(route + 1));
            ck_assert_double_eq(au_stat(a, "fallback_solves"), cfg != 2 ? (double)(route + 1) : 0.0);
        }
        if (cfg == 3) {
            /* an inconsistent system (b with a part in the null space of N:
             * no solution): lsq-pcg stalls and gives up fast, and plain CG
             * is not tried after it (it would stall too, after up to
             * 10 Nc + 100 iterations) */
            double *bi = xcalloc(c->nc, sizeof *bi);
            au_vec(c->nc, bi, &rng);
            memset(x, 0, c->nc * sizeof *x);
            int st = odhs_solver_solve(a, c->net, bi, x);
            ck_assert_msg(st == ODHS_E_NOCONV, "%s: inconsistent system gave %d", what, st);
            const char *why;
            au_backend(a, &why);
            ck_assert_msg(strstr(why, "lsq-pcg failed") && !strstr(why, "lsq-cg"), "why = \"%s\"", why);
            free(bi);
        }
        odhs_solver_destroy(a);
    }
    free(g);
    free(b);
    free(xr);
    free(x);
}

START_TEST(test_hyperstatic_hex)
{
    double L[2] = {10.0, 10.0}, r[7], x[14];
    for (int i = 0; i < 7; ++i) r[i] = 0.5;
    x[0] = x[1] = 5.0;
    for (int k = 0; k < 6; ++k) {
        x[2 * (k + 1)] = 5.0 + cos(k * TU_PI / 3.0);
        x[2 * (k + 1) + 1] = 5.0 + sin(k * TU_PI / 3.0);
    }
    au_case c = au_make(2, 7, L, 0.0, r, x);
    CK_OK(odhs_network_detect(c.net, c.sys, 1e-9));
    au_refresh(&c);
    ck_assert_uint_eq(c.nc, 12);
    check_hyperstatic(&c, "hexagonal 7-disc patch", 1);
    au_free(&c);
}
END_TEST

START_TEST(test_hyperstatic_square_lattice)
{
    double L[2] = {4.0, 4.0}, r[16], x[32];
    for (int i = 0; i < 16; ++i) {
        r[i] = 0.5;
        x[2 * i] = 0.5 + (i % 4);
        x[2 * i + 1] = 0.5 + (i / 4);
    }
    au_case c = au_make(2, 16, L, 0.0, r, x);
    CK_OK(odhs_network_detect(c.net, c.sys, 1e-9));
    au_refresh(&c);
    ck_assert_uint_eq(c.nc, 32);
    check_hyperstatic(&c, "4x4 periodic square lattice", 8);
    au_free(&c);
}
END_TEST

START_TEST(test_hyperstatic_random)
{
    au_case c2 = au_random(2, 40, 61, SIZE_MAX, 1.2), c3 = au_random(3, 60, 62, SIZE_MAX, 1.0);
    check_hyperstatic(&c2, "random all-pairs 2D", SIZE_MAX);
    check_hyperstatic(&c3, "random all-pairs 3D", SIZE_MAX);
    au_free(&c2);
    au_free(&c3);
}
END_TEST

#ifdef ODHS_HAVE_SUITESPARSE
extern const odhs_solver_type odhs__solver_type_lsq_pcg; /* internal: auto's lsq-pcg */
#endif

/* lsq-pcg on its own: a consistent singular system in a few iterations, to
 * the minimum-norm solution; an inconsistent one (no solution) given up
 * after 50 iterations without progress, not after maxiter; its parameters */
START_TEST(test_lsq_pcg_direct)
{
#ifdef ODHS_HAVE_SUITESPARSE
    au_case c = au_random(2, 40, 61, SIZE_MAX, 1.2);
    tu_rng rng;
    tu_rng_seed(&rng, 71);
    double *g = xcalloc(c.nd, sizeof *g), *b = xcalloc(c.nc, sizeof *b), *x = xcalloc(c.nc, sizeof *x),
           *xr = xcalloc(c.nc, sizeof *xr);
    au_vec(c.nd, g, &rng);
    CK_OK(odhs_network_apply_S(c.net, g, b));
    size_t rank;
    au_pinv_ref(&c, g, xr, &rank);
    ck_assert(rank < c.nc);
    odhs_solver *p;
    CK_OK(odhs_solver_create(&odhs__solver_type_lsq_pcg, &p));
    ck_assert_int_eq(odhs_solver_set_param(p, "shift", 0.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "shift", 1.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(p, "no-such", 1.0), ODHS_E_INVALID);
    CK_OK(odhs_solver_solve(p, c.net, b, x));
    double it = au_stat(p, "iterations");
    ck_assert_msg(it >= 1.0 && it <= 5.0, "consistent: %g iterations", it);
    ck_assert_msg(au_reldiff(c.nc, x, xr) <= 1e-9, "consistent: %.3g from the minimum-norm forces",
                  au_reldiff(c.nc, x, xr));
    ck_assert_double_eq(au_stat(p, "factorizations"), 1.0);
    /* a larger shift: more iterations, less round-off in the null space */
    odhs_solver *p3;
    CK_OK(odhs_solver_create(&odhs__solver_type_lsq_pcg, &p3));
    CK_OK(odhs_solver_set_param(p3, "shift", 1e-3));
    CK_OK(odhs_solver_solve(p3, c.net, b, x));
    ck_assert_msg(au_reldiff(c.nc, x, xr) <= 1e-11, "shift 1e-3: %.3g", au_reldiff(c.nc, x, xr));
    ck_assert_double_ge(au_stat(p3, "iterations"), it);
    fprintf(stderr, "[auto] lsq-pcg direct Nc=%zu: %g iterations at shift 1e-6, %g at 1e-3\n", c.nc, it,
            au_stat(p3, "iterations"));
    odhs_solver_destroy(p3);
    /* inconsistent: b with a part in the null space */
    double *bi = xcalloc(c.nc, sizeof *bi);
    au_vec(c.nc, bi, &rng);
    ck_assert_int_eq(odhs_solver_solve(p, c.net, bi, x), ODHS_E_NOCONV);
    double its = au_stat(p, "iterations");
    ck_assert_msg(its >= 50.0 && its <= 80.0, "inconsistent: gave up after %g iterations (maxiter 500)", its);
    odhs_solver_destroy(p);
    free(bi);
    free(g);
    free(b);
    free(x);
    free(xr);
    au_free(&c);
#endif
}
END_TEST

Suite *make_auto_suite(void)
{
    Suite *s = suite_create("auto");
    TCase *tc = tcase_create("auto");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_choice);
    tcase_add_test(tc, test_params);
    tcase_add_test(tc, test_agree_2d);
    tcase_add_test(tc, test_agree_3d);
    tcase_add_test(tc, test_stepper_shear);
    tcase_add_test(tc, test_fallback_ill_conditioned);
    tcase_add_test(tc, test_fallback_ill_conditioned_nosuitesparse);
    tcase_add_test(tc, test_hyperstatic_hex);
    tcase_add_test(tc, test_hyperstatic_square_lattice);
    tcase_add_test(tc, test_hyperstatic_random);
    tcase_add_test(tc, test_lsq_pcg_direct);
    suite_add_tcase(s, tc);
    return s;
}
