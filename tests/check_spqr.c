/*
 * libodhs - tests of the SuiteSparseQR backend (lib/solvers/spqr.c).
 *
 * With SuiteSparse: agreement with the dense Cholesky backend and with an
 * explicit LAPACK least-squares solve (dgels) on random full-rank networks
 * in 2D and 3D, for N x = b and for the least-squares route solve_ls;
 * reuse of the symbolic analysis while the contact pattern is unchanged;
 * parameters and statistics; rank detection on hyperstatic networks against
 * the null-space dimension of S^T from a LAPACK SVD; accuracy on
 * ill-conditioned networks (a nearly straight zigzag force chain with a
 * controlled condition number, and packings compressed to just before
 * jamming) against a binary128 reference; a sheared stepper run against CG.
 * Without SuiteSparse: the backend reports ODHS_E_NOTINSTALLED by name.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <check.h>
#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "testutil.h"

/* until solver.h declares it (harmless afterwards) */
ODHS_API extern const odhs_solver_type odhs_solver_type_spqr;

#ifdef ODHS_HAVE_SUITESPARSE

#include <lapacke.h>

/* ------------------------------------------------------------------------ */
/* helpers                                                                   */
/* ------------------------------------------------------------------------ */

#include "netcase.h"

typedef tu_netcase sp_case;
#define sp_case_free tu_netcase_free
#define sp_case_refresh tu_netcase_refresh
#define sp_make tu_netcase_make

static sp_case sp_random_case_gap(int dim, size_t n, uint64_t seed, size_t extra, double maxgap)
{
    sp_case c = tu_netcase_random(dim, n, seed, extra, maxgap, 0.13);
    ck_assert_msg(c.nc >= n / 2, "only %zu contacts", c.nc);
    return c;
}

static sp_case sp_random_case(int dim, size_t n, uint64_t seed, size_t extra)
{
    return sp_random_case_gap(dim, n, seed, extra, 0.5);
}

static odhs_solver *sp_new(void)
{
    odhs_solver *s = NULL;
    CK_OK(odhs_solver_create(&odhs_solver_type_spqr, &s));
    ck_assert_str_eq(odhs_solver_name(s), "spqr");
    return s;
}

static odhs_solver *sp_by_name(const char *name)
{
    odhs_solver *s = NULL;
    CK_OK(odhs_solver_create_by_name(name, &s));
    return s;
}

static double sp_stat(const odhs_solver *s, const char *key)
{
    double v = NAN;
    int st = odhs_solver_get_stat(s, key, &v);
    ck_assert_msg(st == ODHS_OK, "get_stat(%s) = %d", key, st);
    return v;
}

static void sp_random_vec(size_t n, double *v, tu_rng *rng)
{
    for (size_t k = 0; k < n; ++k) v[k] = tu_uniform_in(rng, -1.0, 1.0);
}

/* |a - b| / |b| in the 2-norm */
static double sp_reldiff(size_t n, const double *a, const double *b)
{
    double d = 0.0, s = 0.0;
    for (size_t k = 0; k < n; ++k) {
        d += (a[k] - b[k]) * (a[k] - b[k]);
        s += b[k] * b[k];
    }
    return s > 0.0 ? sqrt(d / s) : sqrt(d);
}

/* S^T as a dense column-major nd x nc matrix (from apply_ST on unit vectors) */
static double *sp_dense_ST(const sp_case *c)
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

/* Singular values of S^T (LAPACK dgesvd), descending, min(nd, nc) of them
 * into sv (caller frees). */
static double *sp_singular_values(const sp_case *c, size_t *count)
{
    double *A = sp_dense_ST(c);
    size_t k = c->nd < c->nc ? c->nd : c->nc;
    double *sv = xcalloc(k, sizeof *sv), *sup = xcalloc(k, sizeof *sup);
    lapack_int info = LAPACKE_dgesvd(LAPACK_COL_MAJOR, 'N', 'N', (lapack_int)c->nd, (lapack_int)c->nc, A,
                                     (lapack_int)c->nd, sv, NULL, 1, NULL, 1, sup);
    ck_assert_int_eq(info, 0);
    free(A);
    free(sup);
    *count = k;
    return sv;
}

/* Null-space dimension of S^T (nc - numerical rank) from the SVD, requiring a
 * clear gap: zero singular values below 1e-12 s_max, the others above
 * 1e-6 s_max. *smin receives the smallest nonzero singular value / s_max. */
static size_t sp_nullity_svd(const sp_case *c, double *smin)
{
    size_t k, rank = 0;
    double *sv = sp_singular_values(c, &k);
    double smax = sv[0];
    for (size_t q = 0; q < k; ++q) {
        double rel = sv[q] / smax;
        ck_assert_msg(rel < 1e-12 || rel > 1e-6, "singular value %zu = %.3g s_max: no clear rank gap", q, rel);
        if (rel > 1e-6) rank++;
    }
    if (smin) *smin = rank ? sv[rank - 1] / smax : 0.0;
    free(sv);
    return c->nc - rank;
}

/* ---- high-precision reference -------------------------------------------
 * x = N^{-1} S g with N assembled exactly from the double normals, solved by
 * LDL^T (no square roots) in binary128 where the compiler has it. */
#if defined(__SIZEOF_FLOAT128__)
__extension__ typedef __float128 sp_real;
#define SP_REF_NAME "binary128"
#else
typedef long double sp_real;
#define SP_REF_NAME "long double"
#endif

typedef struct {
    size_t nc, nd;
    int dim;
    size_t *ci, *cj;
    double *nrm;
} sp_geom;

static sp_geom sp_geom_get(const sp_case *c)
{
    sp_geom g;
    g.nc = c->nc;
    g.nd = c->nd;
    g.dim = c->dim;
    g.ci = xcalloc(c->nc, sizeof *g.ci);
    g.cj = xcalloc(c->nc, sizeof *g.cj);
    g.nrm = xcalloc(c->nc * c->dim, sizeof *g.nrm);
    for (size_t k = 0; k < c->nc; ++k) CK_OK(odhs_network_get_contact(c->net, k, &g.ci[k], &g.cj[k], NULL));
    CK_OK(odhs_network_get_normals(c->net, g.nrm));
    return g;
}

static void sp_geom_free(sp_geom *g)
{
    free(g->ci);
    free(g->cj);
    free(g->nrm);
}

/* out(nd) = S^T f in sp_real */
static void sp_ST_q(const sp_geom *g, const sp_real *f, sp_real *out)
{
    for (size_t q = 0; q < g->nd; ++q) out[q] = 0;
    for (size_t c = 0; c < g->nc; ++c)
        for (int k = 0; k < g->dim; ++k) {
            sp_real t = f[c] * (sp_real)g->nrm[c * g->dim + k];
            out[g->ci[c] * g->dim + k] -= t;
            out[g->cj[c] * g->dim + k] += t;
        }
}

/* x_ref (double) and, optionally, gproj = S^T x_ref (sp_real, nd) */
static void sp_reference_ls(const sp_geom *g, const double *gv, double *xref, sp_real *gproj)
{
    size_t nc = g->nc;
    int d = g->dim;
    sp_real *N = xcalloc(nc * nc, sizeof *N), *b = xcalloc(nc, sizeof *b);
    /* N_ab = sum over the particle p shared by a and b of s_a s_b n_a . n_b */
    for (size_t a = 0; a < nc; ++a)
        for (size_t bb = 0; bb < nc; ++bb) {
            sp_real v = 0;
            size_t pa[2] = {g->ci[a], g->cj[a]}, pb[2] = {g->ci[bb], g->cj[bb]};
            for (int u = 0; u < 2; ++u)
                for (int w = 0; w < 2; ++w)
                    if (pa[u] == pb[w]) {
                        sp_real dot = 0;
                        for (int k = 0; k < d; ++k)
                            dot += (sp_real)g->nrm[a * d + k] * (sp_real)g->nrm[bb * d + k];
                        v += (u == w ? dot : -dot);
                    }
            N[a * nc + bb] = v;
        }
    for (size_t c = 0; c < nc; ++c) {
        sp_real s = 0;
        for (int k = 0; k < d; ++k)
            s += ((sp_real)gv[g->cj[c] * d + k] - (sp_real)gv[g->ci[c] * d + k]) * (sp_real)g->nrm[c * d + k];
        b[c] = s;
    }
    /* LDL^T in place: L below the diagonal, D on it */
    for (size_t j = 0; j < nc; ++j) {
        for (size_t k = 0; k < j; ++k) {
            sp_real ljk = N[j * nc + k];
            N[j * nc + j] -= ljk * ljk * N[k * nc + k];
        }
        ck_assert_msg(N[j * nc + j] > 0, "reference LDL^T: non-positive pivot %zu", j);
        for (size_t i = j + 1; i < nc; ++i) {
            sp_real s = N[i * nc + j];
            for (size_t k = 0; k < j; ++k) s -= N[i * nc + k] * N[j * nc + k] * N[k * nc + k];
            N[i * nc + j] = s / N[j * nc + j];
        }
    }
    for (size_t i = 0; i < nc; ++i)
        for (size_t k = 0; k < i; ++k) b[i] -= N[i * nc + k] * b[k];
    for (size_t i = 0; i < nc; ++i) b[i] /= N[i * nc + i];
    for (size_t i = nc; i-- > 0;)
        for (size_t k = i + 1; k < nc; ++k) b[i] -= N[k * nc + i] * b[k];
    for (size_t c = 0; c < nc; ++c) xref[c] = (double)b[c];
    if (gproj) sp_ST_q(g, b, gproj);
    free(N);
    free(b);
}

/* |S^T x - gproj|, evaluated in sp_real */
static double sp_range_residual(const sp_geom *g, const double *x, const sp_real *gproj)
{
    sp_real *xq = xcalloc(g->nc, sizeof *xq), *y = xcalloc(g->nd, sizeof *y);
    for (size_t c = 0; c < g->nc; ++c) xq[c] = x[c];
    sp_ST_q(g, xq, y);
    sp_real r2 = 0;
    for (size_t q = 0; q < g->nd; ++q) {
        sp_real d = y[q] - gproj[q];
        r2 += d * d;
    }
    free(xq);
    free(y);
    return sqrt((double)r2);
}

static double sp_norm(size_t n, const double *v)
{
    double s = 0.0;
    for (size_t k = 0; k < n; ++k) s += v[k] * v[k];
    return sqrt(s);
}

/* ------------------------------------------------------------------------ */
/* 1. agreement on full-rank networks                                        */
/* ------------------------------------------------------------------------ */

static void agree_case(int dim, size_t n, uint64_t seed, size_t extra, double *worst)
{
    sp_case c = sp_random_case(dim, n, seed, extra);
    size_t nc = c.nc, nd = c.nd;
    tu_rng rng;
    tu_rng_seed(&rng, seed * 7 + 1);
    double *b = xcalloc(nc, sizeof *b), *g = xcalloc(nd, sizeof *g);
    double *xs = xcalloc(nc, sizeof *xs), *xd = xcalloc(nc, sizeof *xd), *xl = xcalloc(nc, sizeof *xl);
    sp_random_vec(nc, b, &rng);
    sp_random_vec(nd, g, &rng);
    odhs_solver *sp = sp_new(), *dn = sp_by_name("dense");

    /* N x = b */
    CK_OK(odhs_solver_solve(sp, c.net, b, xs));
    CK_OK(odhs_solver_solve(dn, c.net, b, xd));
    double e1 = sp_reldiff(nc, xs, xd);
    ck_assert_msg(e1 <= 1e-10, "d=%d n=%zu seed %llu: spqr vs dense (N x = b) differ by %.3g", dim, n,
                  (unsigned long long)seed, e1);
    ck_assert_msg(sp_stat(sp, "residual") <= 1e-12, "spqr residual %.3g", sp_stat(sp, "residual"));
    ck_assert_double_eq(sp_stat(sp, "rank"), (double)nc);
    ck_assert_double_eq(sp_stat(sp, "rank_deficiency"), 0.0);

    /* least squares: spqr's solve_ls against N^-1 S g from dense */
    CK_OK(odhs_solver_solve_ls(sp, c.net, g, xs));
    CK_OK(odhs_solver_solve_ls(dn, c.net, g, xd));
    double e2 = sp_reldiff(nc, xs, xd);
    ck_assert_msg(e2 <= 1e-10, "d=%d n=%zu: spqr solve_ls vs dense N^-1 S g differ by %.3g", dim, n, e2);

    /* and against an explicit least-squares solve of S^T x = g (dgels) */
    double *A = sp_dense_ST(&c), *gg = xcalloc(nd, sizeof *gg);
    memcpy(gg, g, nd * sizeof *g);
    ck_assert_uint_ge(nd, nc);
    lapack_int info = LAPACKE_dgels(LAPACK_COL_MAJOR, 'N', (lapack_int)nd, (lapack_int)nc, 1, A, (lapack_int)nd,
                                    gg, (lapack_int)nd);
    ck_assert_int_eq(info, 0);
    memcpy(xl, gg, nc * sizeof *xl);
    double e3 = sp_reldiff(nc, xs, xl);
    ck_assert_msg(e3 <= 1e-10, "d=%d n=%zu: spqr solve_ls vs LAPACK dgels differ by %.3g", dim, n, e3);

    /* optimality: S (S^T x - g) = 0 */
    double *r = xcalloc(nd, sizeof *r), *Sr = xcalloc(nc, sizeof *Sr), rn = 0.0, gn = 0.0;
    CK_OK(odhs_network_apply_ST(c.net, xs, r));
    for (size_t q = 0; q < nd; ++q) r[q] -= g[q];
    CK_OK(odhs_network_apply_S(c.net, r, Sr));
    for (size_t k = 0; k < nc; ++k) rn += Sr[k] * Sr[k];
    for (size_t q = 0; q < nd; ++q) gn += g[q] * g[q];
    ck_assert_msg(sqrt(rn / gn) <= 1e-13, "normal-equation residual |S(S^T x - g)|/|g| = %.3g", sqrt(rn / gn));

    worst[0] = fmax(worst[0], e1);
    worst[1] = fmax(worst[1], e2);
    worst[2] = fmax(worst[2], e3);
    free(A);
    free(gg);
    free(r);
    free(Sr);
    free(b);
    free(g);
    free(xs);
    free(xd);
    free(xl);
    odhs_solver_destroy(sp);
    odhs_solver_destroy(dn);
    sp_case_free(&c);
}

START_TEST(test_agree_2d)
{
    double w[3] = {0, 0, 0};
    agree_case(2, 40, 101, 0, w);  /* a forest */
    agree_case(2, 120, 102, 30, w);
    agree_case(2, 300, 103, 80, w);
    fprintf(stderr, "[spqr] 2D vs dense: N x = b %.2e, solve_ls %.2e, vs dgels %.2e\n", w[0], w[1], w[2]);
}
END_TEST

START_TEST(test_agree_3d)
{
    double w[3] = {0, 0, 0};
    agree_case(3, 40, 201, 0, w);
    agree_case(3, 100, 202, 40, w);
    agree_case(3, 200, 203, 100, w);
    fprintf(stderr, "[spqr] 3D vs dense: N x = b %.2e, solve_ls %.2e, vs dgels %.2e\n", w[0], w[1], w[2]);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* 2. symbolic analysis kept while the pattern is unchanged                  */
/* ------------------------------------------------------------------------ */

START_TEST(test_pattern_reuse)
{
    sp_case c = sp_random_case(2, 80, 301, 20);
    odhs_solver *sp = sp_new(), *dn = sp_by_name("dense");
    tu_rng rng;
    tu_rng_seed(&rng, 302);
    double *b = xcalloc(c.nc + 4, sizeof *b), *xs = xcalloc(c.nc + 4, sizeof *xs), *xd = xcalloc(c.nc + 4, sizeof *xd);
    double *x = xcalloc(c.nd, sizeof *x), *r = xcalloc(c.n, sizeof *r);
    CK_OK(odhs_system_get_positions(c.sys, x));
    CK_OK(odhs_system_get_radii(c.sys, r));
    /* shrink the particles so that moving them cannot make overlaps */
    for (size_t i = 0; i < c.n; ++i) r[i] *= 0.5;
    CK_OK(odhs_system_set_radii(c.sys, r));
    for (int round = 0; round < 4; ++round) {
        if (round > 0) {
            for (size_t q = 0; q < c.nd; ++q) x[q] += 0.01 * tu_uniform_in(&rng, -1.0, 1.0);
            CK_OK(odhs_system_set_positions(c.sys, x));
            CK_OK(odhs_network_update_geometry(c.net, c.sys));
        }
        sp_random_vec(c.nc, b, &rng);
        CK_OK(odhs_solver_solve(sp, c.net, b, xs));
        CK_OK(odhs_solver_solve(dn, c.net, b, xd));
        ck_assert_msg(sp_reldiff(c.nc, xs, xd) <= 1e-10, "round %d: %.3g", round, sp_reldiff(c.nc, xs, xd));
        ck_assert_double_eq(sp_stat(sp, "symbolic"), 1.0);
        ck_assert_double_eq(sp_stat(sp, "numeric"), (double)(round + 1));
    }
    /* the same operator again: no new factorization */
    CK_OK(odhs_solver_solve(sp, c.net, b, xs));
    ck_assert_double_eq(sp_stat(sp, "numeric"), 4.0);
    /* a contact removed, then added back (at another index): new pattern */
    size_t i, j;
    CK_OK(odhs_network_get_contact(c.net, 0, &i, &j, NULL));
    CK_OK(odhs_network_remove(c.net, i, j));
    sp_case_refresh(&c);
    CK_OK(odhs_solver_solve(sp, c.net, b, xs));
    CK_OK(odhs_solver_solve(dn, c.net, b, xd));
    ck_assert(sp_reldiff(c.nc, xs, xd) <= 1e-10);
    ck_assert_double_eq(sp_stat(sp, "symbolic"), 2.0);
    CK_OK(odhs_network_add(c.net, i, j, ODHS_CONTACT_TEMPORARY));
    CK_OK(odhs_network_update_geometry(c.net, c.sys));
    sp_case_refresh(&c);
    CK_OK(odhs_solver_solve(sp, c.net, b, xs));
    CK_OK(odhs_solver_solve(dn, c.net, b, xd));
    ck_assert(sp_reldiff(c.nc, xs, xd) <= 1e-10);
    ck_assert_double_eq(sp_stat(sp, "symbolic"), 3.0);
    ck_assert_double_eq(sp_stat(sp, "numeric"), 6.0);
    /* every ordering gives the same forces; a change of ordering makes the
     * next setup analyse again */
    const int orderings[] = {0, 1, 2, 4, 5, 6, 7, 8, 9, 9};
    double sym = sp_stat(sp, "symbolic");
    int prev = 7; /* the default */
    for (size_t k = 0; k < sizeof orderings / sizeof *orderings; ++k) {
        CK_OK(odhs_solver_set_param(sp, "ordering", orderings[k]));
        /* a new geometry makes the wrapper call setup */
        for (size_t q = 0; q < c.nd; ++q) x[q] += 0.001 * tu_uniform_in(&rng, -1.0, 1.0);
        CK_OK(odhs_system_set_positions(c.sys, x));
        CK_OK(odhs_network_update_geometry(c.net, c.sys));
        CK_OK(odhs_solver_solve(sp, c.net, b, xs));
        CK_OK(odhs_solver_solve(dn, c.net, b, xd));
        double e = sp_reldiff(c.nc, xs, xd);
        ck_assert_msg(e <= 1e-10, "ordering %d: %.3g", orderings[k], e);
        if (orderings[k] != prev) sym += 1.0;
        prev = orderings[k];
        ck_assert_double_eq(sp_stat(sp, "symbolic"), sym);
    }
    free(b);
    free(xs);
    free(xd);
    free(x);
    free(r);
    odhs_solver_destroy(sp);
    odhs_solver_destroy(dn);
    sp_case_free(&c);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* 3. parameters and statistics                                              */
/* ------------------------------------------------------------------------ */

START_TEST(test_params_stats)
{
    odhs_solver *sp = sp_new();
    double v;
    /* before any setup: rank and nc unknown, iterations 0 */
    ck_assert(isnan(sp_stat(sp, "rank")));
    ck_assert_double_eq(sp_stat(sp, "iterations"), 0.0);
    ck_assert_int_eq(odhs_solver_get_stat(sp, "no_such_stat", &v), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(sp, "no_such_param", 1.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(sp, "ordering", 3.0), ODHS_E_INVALID); /* "given": no */
    ck_assert_int_eq(odhs_solver_set_param(sp, "ordering", 10.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(sp, "ordering", -1.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(sp, "ordering", 2.5), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(sp, "tol", NAN), ODHS_E_NONFINITE);
    CK_OK(odhs_solver_set_param(sp, "ordering", 2.0));
    CK_OK(odhs_solver_set_param(sp, "tol", -2.0));

    sp_case c = sp_random_case(2, 60, 401, 10);
    double *b = xcalloc(c.nc, sizeof *b), *x = xcalloc(c.nc, sizeof *x);
    for (size_t k = 0; k < c.nc; ++k) b[k] = 1.0;
    CK_OK(odhs_solver_solve(sp, c.net, b, x));
    ck_assert_double_eq(sp_stat(sp, "nc"), (double)c.nc);
    ck_assert_double_eq(sp_stat(sp, "rank"), (double)c.nc);
    ck_assert_double_eq(sp_stat(sp, "ordering_used"), 2.0); /* COLAMD as asked */
    /* default tolerance 20 (m + n) eps max column norm (sqrt 2 here) */
    double tol = sp_stat(sp, "tol_used"), expect = 20.0 * (double)(c.nd + c.nc) * DBL_EPSILON * sqrt(2.0);
    ck_assert_msg(fabs(tol - expect) <= 1e-6 * expect, "tol_used %.6g, expected %.6g", tol, expect);

    /* a tolerance above every column norm: every column dead, rank 0; the
     * parameter acts at the next setup (a new geometry here) */
    odhs_solver *big = sp_new();
    CK_OK(odhs_solver_set_param(big, "tol", 1.5));
    ck_assert_int_eq(odhs_solver_solve(big, c.net, b, x), ODHS_E_SINGULAR);
    ck_assert_str_ne(odhs_solver_errmsg(big), "");
    ck_assert_double_eq(sp_stat(big, "rank"), 0.0);
    ck_assert_double_eq(sp_stat(big, "rank_deficiency"), (double)c.nc);
    ck_assert_double_eq(sp_stat(big, "tol_used"), 1.5);
    /* back to the default: solvable again (the failed setup is retried) */
    CK_OK(odhs_solver_set_param(big, "tol", -2.0));
    CK_OK(odhs_solver_solve(big, c.net, b, x));
    ck_assert_double_eq(sp_stat(big, "rank"), (double)c.nc);
    /* solve_ls works right after solve on the same factor */
    double *g = xcalloc(c.nd, sizeof *g);
    for (size_t q = 0; q < c.nd; ++q) g[q] = sin(0.3 * (double)q);
    CK_OK(odhs_solver_solve_ls(big, c.net, g, x));
    ck_assert_double_eq(sp_stat(big, "numeric"), 2.0);
    free(g);
    free(b);
    free(x);
    odhs_solver_destroy(sp);
    odhs_solver_destroy(big);
    sp_case_free(&c);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* 4. hyperstatic networks: rank detection                                   */
/* ------------------------------------------------------------------------ */

/* setup must fail with ODHS_E_SINGULAR (or succeed if nullity == 0), with
 * rank statistics matching the SVD; returns the nullity found */
static size_t check_rank(sp_case *c, const char *what)
{
    double smin;
    size_t nullity = sp_nullity_svd(c, &smin);
    odhs_solver *sp = sp_new();
    double *b = xcalloc(c->nc, sizeof *b), *x = xcalloc(c->nc, sizeof *x), *g = xcalloc(c->nd, sizeof *g);
    for (size_t k = 0; k < c->nc; ++k) b[k] = 1.0 + 0.1 * sin((double)k);
    for (size_t q = 0; q < c->nd; ++q) g[q] = cos(0.7 * (double)q);
    int st = odhs_solver_solve(sp, c->net, b, x);
    ck_assert_double_eq(sp_stat(sp, "nc"), (double)c->nc);
    ck_assert_msg(sp_stat(sp, "rank_deficiency") == (double)nullity,
                  "%s: spqr rank deficiency %g, SVD null space of S^T has dimension %zu", what,
                  sp_stat(sp, "rank_deficiency"), nullity);
    ck_assert_double_eq(sp_stat(sp, "rank"), (double)(c->nc - nullity));
    if (nullity > 0) {
        ck_assert_msg(st == ODHS_E_SINGULAR, "%s: solve returned %d", what, st);
        ck_assert_str_ne(odhs_solver_errmsg(sp), "");
        ck_assert_int_eq(odhs_solver_solve_ls(sp, c->net, g, x), ODHS_E_SINGULAR);
        ck_assert_double_eq(sp_stat(sp, "rank_deficiency"), (double)nullity);
    } else {
        ck_assert_msg(st == ODHS_OK, "%s: solve returned %d (%s)", what, st, odhs_solver_errmsg(sp));
        double *xd = xcalloc(c->nc, sizeof *xd);
        odhs_solver *dn = sp_by_name("dense");
        CK_OK(odhs_solver_solve(dn, c->net, b, xd));
        ck_assert(sp_reldiff(c->nc, x, xd) <= 1e-10);
        CK_OK(odhs_solver_solve_ls(sp, c->net, g, x));
        CK_OK(odhs_solver_solve_ls(dn, c->net, g, xd));
        ck_assert(sp_reldiff(c->nc, x, xd) <= 1e-10);
        odhs_solver_destroy(dn);
        free(xd);
    }
    fprintf(stderr, "[spqr] %-34s N=%3zu Nc=%3zu rank %3g deficiency %2g (SVD: %zu; smallest nonzero sv %.2e)\n",
            what, c->n, c->nc, sp_stat(sp, "rank"), sp_stat(sp, "rank_deficiency"), nullity, smin);
    odhs_solver_destroy(sp);
    free(b);
    free(x);
    free(g);
    return nullity;
}

START_TEST(test_hyperstatic_hex_patch)
{
    /* 7 equal discs, a centre and a hexagonal ring: 12 contacts, 2*7-3 = 11
     * independent constraints, one self-stress */
    double L[2] = {10.0, 10.0}, r[7], x[14];
    for (int i = 0; i < 7; ++i) r[i] = 0.5;
    x[0] = x[1] = 5.0;
    for (int k = 0; k < 6; ++k) {
        x[2 * (k + 1)] = 5.0 + cos(k * TU_PI / 3.0);
        x[2 * (k + 1) + 1] = 5.0 + sin(k * TU_PI / 3.0);
    }
    sp_case c = sp_make(2, 7, L, 0.0, r, x);
    CK_OK(odhs_network_detect(c.net, c.sys, 1e-9));
    sp_case_refresh(&c);
    ck_assert_uint_eq(c.nc, 12);
    ck_assert_uint_eq(check_rank(&c, "hexagonal 7-disc patch"), 1);
    sp_case_free(&c);
}
END_TEST

START_TEST(test_hyperstatic_square_lattice)
{
    /* 3x3 square lattice filling a periodic 3x3 box: 18 contacts, each of the
     * 3 rows and 3 columns is a ring with a uniform self-stress */
    double L[2] = {3.0, 3.0}, r[9], x[18];
    for (int i = 0; i < 9; ++i) {
        r[i] = 0.5;
        x[2 * i] = 0.5 + (i % 3);
        x[2 * i + 1] = 0.5 + (i / 3);
    }
    sp_case c = sp_make(2, 9, L, 0.0, r, x);
    CK_OK(odhs_network_detect(c.net, c.sys, 1e-9));
    sp_case_refresh(&c);
    ck_assert_uint_eq(c.nc, 18);
    ck_assert_uint_eq(check_rank(&c, "3x3 periodic square lattice"), 6);
    sp_case_free(&c);
}
END_TEST

START_TEST(test_hyperstatic_ring)
{
    /* three discs in a row touching around the periodic box */
    double L[2] = {3.0, 3.0}, r[3] = {0.5, 0.5, 0.5}, x[6] = {0.5, 1.5, 1.5, 1.5, 2.5, 1.5};
    sp_case c = sp_make(2, 3, L, 0.0, r, x);
    CK_OK(odhs_network_detect(c.net, c.sys, 1e-9));
    sp_case_refresh(&c);
    ck_assert_uint_eq(c.nc, 3);
    ck_assert_uint_eq(check_rank(&c, "periodic ring of 3"), 1);
    sp_case_free(&c);
}
END_TEST

START_TEST(test_full_rank_triangle_plus_one)
{
    /* a triangle of mutually touching discs plus a fourth touching two of
     * them: two triangles sharing an edge, 5 = 2*4-3 contacts, rigid and
     * without self-stress */
    double L[2] = {10.0, 10.0}, r[4] = {0.5, 0.5, 0.5, 0.5};
    double h = sqrt(3.0) / 2.0;
    double x[8] = {4.0, 4.0, 5.0, 4.0, 4.5, 4.0 + h, 5.5, 4.0 + h};
    sp_case c = sp_make(2, 4, L, 0.0, r, x);
    CK_OK(odhs_network_detect(c.net, c.sys, 1e-9));
    sp_case_refresh(&c);
    ck_assert_uint_eq(c.nc, 5);
    ck_assert_uint_eq(check_rank(&c, "triangle + 1 (rigid, full rank)"), 0);
    sp_case_free(&c);
}
END_TEST

START_TEST(test_hyperstatic_fcc_patch)
{
    /* 3D: a 13-sphere cuboctahedral fcc patch (centre + 12 neighbours, 36
     * contacts > 3*13-6 = 33) */
    double L[3] = {10.0, 10.0, 10.0}, r[13], x[39];
    int k = 0;
    for (int i = 0; i < 13; ++i) r[i] = 0.5;
    x[0] = x[1] = x[2] = 5.0;
    for (int a = 0; a < 3; ++a)
        for (int sa = -1; sa <= 1; sa += 2)
            for (int sb = -1; sb <= 1; sb += 2) {
                double v[3] = {0, 0, 0};
                v[a] = sa / sqrt(2.0);
                v[(a + 1) % 3] = sb / sqrt(2.0);
                ++k;
                for (int q = 0; q < 3; ++q) x[3 * k + q] = 5.0 + v[q];
            }
    sp_case c = sp_make(3, 13, L, 0.0, r, x);
    CK_OK(odhs_network_detect(c.net, c.sys, 1e-9));
    sp_case_refresh(&c);
    ck_assert_uint_eq(c.nc, 36);
    size_t nul = check_rank(&c, "fcc 13-sphere patch (3D)");
    ck_assert_uint_ge(nul, 3);
    sp_case_free(&c);
}
END_TEST

START_TEST(test_hyperstatic_random)
{
    /* every near pair a contact: over-constrained random networks with a
     * generic null space, 2D and 3D */
    struct {
        int dim;
        size_t n;
        uint64_t seed;
        double gap;
    } cases[] = {{2, 30, 501, 1.2}, {2, 60, 502, 1.0}, {3, 60, 503, 1.0}, {3, 80, 504, 0.8}};
    size_t hyper = 0;
    for (size_t q = 0; q < sizeof cases / sizeof *cases; ++q) {
        sp_case c = sp_random_case_gap(cases[q].dim, cases[q].n, cases[q].seed, SIZE_MAX, cases[q].gap);
        char what[64];
        snprintf(what, sizeof what, "random all-pairs %dD seed %llu", cases[q].dim,
                 (unsigned long long)cases[q].seed);
        if (check_rank(&c, what) > 0) hyper++;
        sp_case_free(&c);
    }
    ck_assert_msg(hyper >= 2, "only %zu of the random networks were hyperstatic", hyper);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* 5. ill-conditioned networks                                               */
/* ------------------------------------------------------------------------ */

/* the solver configurations compared on ill-conditioned networks */
enum { M_QR, M_NE, M_NE_REF, M_QR_REF, M_COUNT };
static const char *const m_name[M_COUNT] = {"spqr", "dense", "dense+ref", "spqr+ref"};

typedef struct {
    double kappa;        /* cond(S^T) from the SVD */
    double err[M_COUNT]; /* |x - x_ref| / |x_ref| */
    double res[M_COUNT]; /* |S^T x - g_proj| / |g| */
    double eta[M_COUNT]; /* |S^T x - g_proj| / (|S^T|_2 |x_ref|): backward-type */
    int st[M_COUNT];     /* status with the default check and thresholds */
} sp_acc;

/* x minimising |S^T x - g| on one network by: spqr's solve_ls and dense
 * N x = S g (the normal equations), each without (M_QR, M_NE) and with the
 * wrapper's default iterative refinement (M_*_REF), against the
 * high-precision reference. A configuration the default checks reject is
 * measured again with the checks off. */
static sp_acc accuracy(sp_case *c, const double *g)
{
    sp_acc a;
    memset(&a, 0, sizeof a);
    size_t k;
    double *sv = sp_singular_values(c, &k);
    a.kappa = sv[0] / sv[k - 1];
    double smax = sv[0];
    free(sv);
    sp_geom geo = sp_geom_get(c);
    double *xr = xcalloc(c->nc, sizeof *xr), *x = xcalloc(c->nc, sizeof *x);
    sp_real *gp = xcalloc(c->nd, sizeof *gp);
    sp_reference_ls(&geo, g, xr, gp);
    double gn = sp_norm(c->nd, g), sx = smax * sp_norm(c->nc, xr);
    for (int m = 0; m < M_COUNT; ++m) {
        int qr = m == M_QR || m == M_QR_REF, ref = m == M_NE_REF || m == M_QR_REF;
        for (int relax = 0; relax < 2; ++relax) {
            odhs_solver *s = qr ? sp_new() : sp_by_name("dense");
            if (!ref) CK_OK(odhs_solver_set_refinement(s, 0));
            if (relax) {
                CK_OK(odhs_solver_set_check_tolerance(s, 1e300));
                if (!qr) CK_OK(odhs_solver_set_param(s, "min_rcond", 0.0));
            }
            memset(x, 0, c->nc * sizeof *x);
            int st = odhs_solver_solve_ls(s, c->net, g, x);
            odhs_solver_destroy(s);
            if (!relax) a.st[m] = st;
            if (st != ODHS_OK) {
                ck_assert_msg(!relax, "%s: solve failed with the checks off: %d", m_name[m], st);
                continue;
            }
            double r = sp_range_residual(&geo, x, gp);
            a.err[m] = sp_reldiff(c->nc, x, xr);
            a.res[m] = r / gn;
            a.eta[m] = r / sx;
            break;
        }
    }
    sp_geom_free(&geo);
    free(xr);
    free(x);
    free(gp);
    return a;
}

static void print_acc(const char *what, const sp_case *c, const sp_acc *a)
{
    fprintf(stderr, "[spqr] %-24s Nc=%3zu cond(S^T) %.1e | error vs %s / |S^T x-Pg|/(|S||x|):", what, c->nc,
            a->kappa, SP_REF_NAME);
    for (int m = 0; m < M_COUNT; ++m)
        fprintf(stderr, " %s %.1e/%.0e%s", m_name[m], a->err[m], a->eta[m], a->st[m] == ODHS_OK ? "" : " (rejected)");
    fprintf(stderr, "\n");
}

/* Nearly straight force chains: `rings` parallel rings (2.4 apart) of K
 * discs each (K even), every ring a zigzag closing on itself through the
 * periodic box along e = (cos a, sin a), the box diagonal. Consecutive
 * centres are 1 apart at angles +-theta (1 + 0.5 u) to e, u uniform in
 * [-1,1] (the same angles in every ring); the last bond closes the ring
 * through the periodic image and takes what is left, also O(theta).
 * Uniform tension in a ring is a self-stress only for theta = 0 (then
 * each ring adds 1 to the rank deficiency); otherwise the smallest
 * singular value of S^T is O(theta), so cond(S^T) ~ 1/theta and cond(N) ~
 * 1/theta^2. Radii 0.45: only the normals enter S. */
static sp_case zigzag_rings(size_t K, double theta, tu_rng *rng, size_t rings)
{
    const double a = 0.6, e[2] = {cos(a), sin(a)}, p[2] = {-sin(a), cos(a)};
    size_t n = K * rings;
    double *r = xcalloc(n, sizeof *r), *x = xcalloc(2 * n, sizeof *x), *tk = xcalloc(K, sizeof *tk);
    for (size_t k = 0; k < K; ++k) tk[k] = theta * (1.0 + 0.5 * tu_uniform_in(rng, -1.0, 1.0));
    double along = 0.0;
    for (size_t k = 0; k < K; ++k) along += cos(tk[k]);
    for (size_t m = 0; m < rings; ++m) {
        /* parallel rings 2.4 apart (their periodic images are >= 1.4 away) */
        double s = 0.0, perp = 2.4 * (double)m;
        for (size_t k = 0; k < K; ++k) {
            size_t i = m * K + k;
            r[i] = 0.45;
            x[2 * i] = 0.5 + s * e[0] + perp * p[0];
            x[2 * i + 1] = 0.5 + s * e[1] + perp * p[1];
            s += cos(tk[k]);
            perp += k % 2 ? -sin(tk[k]) : sin(tk[k]);
        }
    }
    /* each ring closes on the image of its first disc shifted by
     * (Lx, Ly) = along e */
    double L[2] = {along * e[0], along * e[1]};
    sp_case c = sp_make(2, n, L, 0.0, r, x);
    for (size_t m = 0; m < rings; ++m)
        for (size_t k = 0; k < K; ++k) {
            size_t i = m * K + k, j = m * K + (k + 1) % K;
            CK_OK(odhs_network_add(c.net, i < j ? i : j, i < j ? j : i, ODHS_CONTACT_TEMPORARY));
        }
    CK_OK(odhs_network_update_geometry(c.net, c.sys));
    sp_case_refresh(&c);
    /* the rings really are the intended ones: bond lengths 1 (last: ~1) */
    double *gap = xcalloc(c.nc, sizeof *gap);
    CK_OK(odhs_network_get_gaps(c.net, gap));
    for (size_t k = 0; k < c.nc; ++k) ck_assert_msg(fabs(gap[k] - 0.1) < 1e-3, "zigzag bond %zu: gap %.3g", k, gap[k]);
    free(gap);
    free(r);
    free(x);
    free(tk);
    return c;
}

static sp_case zigzag(size_t K, double theta, tu_rng *rng) { return zigzag_rings(K, theta, rng, 1); }

/* The same contact pattern first degenerate (three straight rings: uniform
 * tension in each is a self-stress, rank deficiency 3), then bent (full
 * rank), and back: the result must match dense every time. */
START_TEST(test_rank_recovery)
{
    tu_rng rng;
    tu_rng_seed(&rng, 611);
    sp_case flat = zigzag_rings(16, 0.0, &rng, 3);
    sp_case bent = zigzag_rings(16, 1e-2, &rng, 3);
    double L[2], *r = xcalloc(bent.n, sizeof *r), *x = xcalloc(bent.nd, sizeof *x);
    CK_OK(odhs_system_get_box(bent.sys, L));
    CK_OK(odhs_system_get_radii(bent.sys, r));
    CK_OK(odhs_system_get_positions(bent.sys, x));
    odhs_solver *sp = sp_new(), *dn = sp_by_name("dense");
    double *b = xcalloc(flat.nc, sizeof *b), *xs = xcalloc(flat.nc, sizeof *xs), *xd = xcalloc(flat.nc, sizeof *xd);
    for (int round = 0; round < 3; ++round) {
        /* flat: singular */
        for (size_t k = 0; k < flat.nc; ++k) b[k] = 1.0 + 0.5 * sin(3.0 * (double)k + round);
        ck_assert_int_eq(odhs_solver_solve(sp, flat.net, b, xs), ODHS_E_SINGULAR);
        ck_assert_double_eq(sp_stat(sp, "rank_deficiency"), 3.0);
        /* bent, on the same network object (same pattern) */
        sp_case c = flat;
        double Lf[2], *xf = xcalloc(flat.nd, sizeof *xf);
        CK_OK(odhs_system_get_box(flat.sys, Lf));
        CK_OK(odhs_system_get_positions(flat.sys, xf));
        CK_OK(odhs_system_set_configuration(c.sys, L, 0.0, r, x));
        CK_OK(odhs_network_update_geometry(c.net, c.sys));
        CK_OK(odhs_solver_solve(sp, c.net, b, xs));
        CK_OK(odhs_solver_solve(dn, c.net, b, xd));
        double e = sp_reldiff(c.nc, xs, xd);
        ck_assert_msg(e <= 1e-10, "round %d: spqr after a rank-deficient factorization differs from dense by %.3g",
                      round, e);
        ck_assert_double_eq(sp_stat(sp, "rank_deficiency"), 0.0);
        /* back to flat */
        CK_OK(odhs_system_set_configuration(c.sys, Lf, 0.0, r, xf));
        CK_OK(odhs_network_update_geometry(c.net, c.sys));
        free(xf);
    }
    free(b);
    free(xs);
    free(xd);
    free(r);
    free(x);
    odhs_solver_destroy(sp);
    odhs_solver_destroy(dn);
    sp_case_free(&flat);
    sp_case_free(&bent);
}
END_TEST

START_TEST(test_ill_conditioned_chain)
{
    const double thetas[] = {1e-2, 1e-3, 1e-4, 1e-5, 1e-6, 1e-7};
    tu_rng rng;
    tu_rng_seed(&rng, 601);
    for (size_t q = 0; q < sizeof thetas / sizeof *thetas; ++q) {
        sp_case c = zigzag(16, thetas[q], &rng);
        double *g = xcalloc(c.nd, sizeof *g);
        sp_random_vec(c.nd, g, &rng);
        sp_acc a = accuracy(&c, g);
        char what[48];
        snprintf(what, sizeof what, "zigzag theta=%.0e", thetas[q]);
        print_acc(what, &c, &a);
        /* QR: accepted by the default checks, forward error O(cond(S^T)
         * eps), backward-type residual at round-off */
        ck_assert_msg(a.st[M_QR] == ODHS_OK && a.st[M_QR_REF] == ODHS_OK, "%s: spqr rejected", what);
        ck_assert_msg(a.err[M_QR] <= 50.0 * a.kappa * DBL_EPSILON, "%s: spqr error %.3g, cond(S^T) %.3g", what,
                      a.err[M_QR], a.kappa);
        ck_assert_msg(a.eta[M_QR] <= 64.0 * DBL_EPSILON, "%s: spqr |S^T x - Pg|/(|S||x|) = %.3g", what,
                      a.eta[M_QR]);
        ck_assert_msg(a.err[M_QR_REF] <= 50.0 * a.kappa * DBL_EPSILON, "%s: spqr+ref error %.3g", what,
                      a.err[M_QR_REF]);
        /* plain normal equations: the error grows like cond(S^T)^2 eps */
        if (a.kappa > 1e5)
            ck_assert_msg(a.err[M_NE] >= 1e3 * a.err[M_QR], "%s: dense error %.3g not far above spqr's %.3g", what,
                          a.err[M_NE], a.err[M_QR]);
        free(g);
        sp_case_free(&c);
    }
}
END_TEST

/* Compress a random bidisperse packing (dense solver) until the stepper
 * stops at jamming; keep a copy of the network with the smallest dense
 * rcond on the way, i.e. the most ill-conditioned state before jamming. */
static sp_case near_jamming(int dim, size_t n, uint64_t seed, double *rcond_out, double *phi_out)
{
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
    CK_OK(odhs_system_create(dim, n, &sys));
    CK_OK(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, seed));
    CK_OK(odhs_system_place_random(sys, dim == 2 ? 0.45 : 0.30, seed));
    CK_OK(odhs_driver_create(&drv));
    CK_OK(odhs_driver_set_compression_rate(drv, 1.0));
    CK_OK(odhs_solver_create_by_name("dense", &sol));
    CK_OK(odhs_stepper_create(sys, drv, sol, &st));
    sp_case best;
    memset(&best, 0, sizeof best);
    double rmin = INFINITY;
    int rc = ODHS_OK;
    for (long k = 0; k < 100000 && rc == ODHS_OK; ++k) {
        rc = odhs_stepper_step(st, NULL);
        if (rc != ODHS_OK) break;
        const odhs_network *net = odhs_stepper_network(st);
        double rcond = NAN;
        if (odhs_network_count(net) == 0 || odhs_solver_get_stat(sol, "rcond", &rcond) != ODHS_OK) continue;
        if (!(rcond > 0.0 && rcond < rmin)) continue;
        rmin = rcond;
        sp_case_free(&best);
        CK_OK(odhs_system_clone(sys, &best.sys));
        CK_OK(odhs_network_create(best.sys, &best.net));
        for (size_t c = 0; c < odhs_network_count(net); ++c) {
            size_t i, j;
            int kind;
            CK_OK(odhs_network_get_contact(net, c, &i, &j, &kind));
            CK_OK(odhs_network_add(best.net, i, j, kind));
        }
        CK_OK(odhs_network_update_geometry(best.net, best.sys));
        sp_case_refresh(&best);
        CK_OK(odhs_system_packing_fraction(sys, phi_out));
    }
    /* normally ODHS_JAMMED; the dense solver may also give up first */
    fprintf(stderr, "[spqr] compression %dD N=%zu seed %llu ended: %s\n", dim, n, (unsigned long long)seed,
            rc ? odhs_stepper_errmsg(st) : "step limit");
    ck_assert_ptr_nonnull(best.net);
    *rcond_out = rmin;
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    return best;
}

START_TEST(test_ill_conditioned_near_jamming)
{
    struct {
        int dim;
        size_t n;
        uint64_t seed;
    } cases[] = {{2, 64, 2}, {2, 64, 3}, {3, 64, 1}};
    for (size_t q = 0; q < sizeof cases / sizeof *cases; ++q) {
        double rcond = NAN, phi = NAN;
        sp_case c = near_jamming(cases[q].dim, cases[q].n, cases[q].seed, &rcond, &phi);
        /* g: the affine shear flow (b = S g is the shear right-hand side),
         * plus a random part */
        double *g = xcalloc(c.nd, sizeof *g), *x = xcalloc(c.nd, sizeof *x);
        CK_OK(odhs_system_get_positions(c.sys, x));
        tu_rng rng;
        tu_rng_seed(&rng, 700 + q);
        for (size_t i = 0; i < c.n; ++i) {
            g[i * c.dim] = -x[i * c.dim + 1];
            for (int k = 0; k < c.dim; ++k) g[i * c.dim + k] += tu_uniform_in(&rng, -1.0, 1.0);
        }
        sp_acc a = accuracy(&c, g);
        char what[48];
        snprintf(what, sizeof what, "%dD N=%zu phi=%.4f", cases[q].dim, cases[q].n, phi);
        print_acc(what, &c, &a);
        ck_assert_msg(a.st[M_QR] == ODHS_OK, "%s: spqr rejected", what);
        ck_assert_msg(a.err[M_QR] <= 50.0 * a.kappa * DBL_EPSILON, "%s: spqr error %.3g, cond(S^T) %.3g", what,
                      a.err[M_QR], a.kappa);
        ck_assert_msg(a.eta[M_QR] <= 64.0 * DBL_EPSILON, "%s: spqr |S^T x - Pg|/(|S||x|) = %.3g", what,
                      a.eta[M_QR]);
        free(g);
        free(x);
        sp_case_free(&c);
    }
}
END_TEST

/* ------------------------------------------------------------------------ */
/* 6. a sheared stepper run: spqr against cg                                 */
/* ------------------------------------------------------------------------ */

START_TEST(test_stepper_shear)
{
    const size_t n = 64;
    odhs_system *base = tu_compressed_discs(n, 801, 0.78);
    odhs_system *sys[2];
    odhs_driver *drv[2];
    odhs_solver *sol[2];
    odhs_stepper *st[2];
    for (int k = 0; k < 2; ++k) {
        CK_OK(odhs_system_clone(base, &sys[k]));
        CK_OK(odhs_driver_create(&drv[k]));
        CK_OK(odhs_driver_set_shear_rate(drv[k], 1.0));
        if (k == 0) sol[k] = sp_new();
        else sol[k] = sp_by_name("cg");
        CK_OK(odhs_stepper_create(sys[k], drv[k], sol[k], &st[k]));
        CK_OK(odhs_stepper_reset(st[k]));
    }
    enum { MAXS = 400 };
    double s0[MAXS], s1[MAXS], smax = 0.0, worst = 0.0;
    long nsteps = 0;
    uint64_t ev[2][3];
    double g0 = 0.0;
    while (nsteps < MAXS) {
        CK_OK(odhs_stepper_strain(st[0], &g0));
        if (g0 >= 0.03) break;
        for (int k = 0; k < 2; ++k) {
            int rc = odhs_stepper_step(st[k], NULL);
            ck_assert_msg(rc == ODHS_OK, "%s stepper: step %ld returned %d: %s", k ? "cg" : "spqr", nsteps, rc,
                          odhs_stepper_errmsg(st[k]));
        }
        double g1;
        CK_OK(odhs_stepper_strain(st[1], &g1));
        CK_OK(odhs_stepper_strain(st[0], &g0));
        ck_assert_msg(fabs(g0 - g1) <= 1e-12, "step %ld: strains %.17g vs %.17g", nsteps, g0, g1);
        CK_OK(odhs_stepper_shear_stress(st[0], &s0[nsteps]));
        CK_OK(odhs_stepper_shear_stress(st[1], &s1[nsteps]));
        smax = fmax(smax, fabs(s1[nsteps]));
        nsteps++;
    }
    ck_assert(smax > 0.0);
    for (long k = 0; k < nsteps; ++k) {
        double e = fabs(s0[k] - s1[k]) / smax;
        ck_assert_msg(e <= 1e-9, "step %ld: shear stress spqr %.17g, cg %.17g (rel %.3g)", k, s0[k], s1[k], e);
        worst = fmax(worst, e);
    }
    for (int k = 0; k < 2; ++k) CK_OK(odhs_stepper_counts(st[k], &ev[k][0], &ev[k][1], &ev[k][2]));
    ck_assert_uint_eq(ev[0][1], ev[1][1]);
    ck_assert_uint_eq(ev[0][2], ev[1][2]);
    double nsym = sp_stat(sol[0], "symbolic"), nnum = sp_stat(sol[0], "numeric");
    ck_assert_msg(nsym < nnum, "symbolic analyses %g not fewer than factorizations %g", nsym, nnum);
    fprintf(stderr,
            "[spqr] stepper shear vs cg: %ld steps to strain %.3f, %llu collisions, %llu openings, worst stress "
            "diff %.2e of max; spqr %g symbolic analyses for %g factorizations\n",
            nsteps, g0, (unsigned long long)ev[0][1], (unsigned long long)ev[0][2], worst, nsym, nnum);
    for (int k = 0; k < 2; ++k) {
        odhs_stepper_destroy(st[k]);
        odhs_solver_destroy(sol[k]);
        odhs_driver_destroy(drv[k]);
        odhs_system_destroy(sys[k]);
    }
    odhs_system_destroy(base);
}
END_TEST

Suite *make_spqr_suite(void)
{
    Suite *s = suite_create("spqr");
    TCase *tc = tcase_create("agreement");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_agree_2d);
    tcase_add_test(tc, test_agree_3d);
    tcase_add_test(tc, test_pattern_reuse);
    tcase_add_test(tc, test_params_stats);
    suite_add_tcase(s, tc);

    tc = tcase_create("rank");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_hyperstatic_hex_patch);
    tcase_add_test(tc, test_hyperstatic_square_lattice);
    tcase_add_test(tc, test_hyperstatic_ring);
    tcase_add_test(tc, test_full_rank_triangle_plus_one);
    tcase_add_test(tc, test_hyperstatic_fcc_patch);
    tcase_add_test(tc, test_hyperstatic_random);
    tcase_add_test(tc, test_rank_recovery);
    suite_add_tcase(s, tc);

    tc = tcase_create("conditioning");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_ill_conditioned_chain);
    tcase_add_test(tc, test_ill_conditioned_near_jamming);
    suite_add_tcase(s, tc);

    tc = tcase_create("stepper");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_stepper_shear);
    suite_add_tcase(s, tc);
    return s;
}

#else /* !ODHS_HAVE_SUITESPARSE */

START_TEST(test_not_installed)
{
    static int dummy;
    odhs_solver *s = (odhs_solver *)(void *)&dummy; /* must be reset to NULL */
    ck_assert_int_eq(odhs_solver_create_by_name("spqr", &s), ODHS_E_NOTINSTALLED);
    ck_assert_ptr_null(s);
}
END_TEST

Suite *make_spqr_suite(void)
{
    Suite *s = suite_create("spqr");
    TCase *tc = tcase_create("not_installed");
    tcase_add_test(tc, test_not_installed);
    suite_add_tcase(s, tc);
    return s;
}

#endif /* ODHS_HAVE_SUITESPARSE */
