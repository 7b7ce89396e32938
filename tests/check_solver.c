/*
 * libodhs - tests of the linear solvers (solver.h) for N f = b, N = S S^T:
 * CG and dense Cholesky against each other and against a hand-written dense
 * Gaussian elimination plugged in as a user backend, the backend-table
 * validation, the result checks of the wrapper (residual, finiteness),
 * parameters, statistics, singular (hyperstatic) networks and NULL handling.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "internal.h"
#include "odhs.h"
#include "testutil.h"

/* ------------------------------------------------------------------------ */
/* helpers                                                                   */
/* ------------------------------------------------------------------------ */

typedef struct {
    odhs_system *sys;
    odhs_network *net;
    size_t n, nc;
    int dim;
} sv_case;

static void sv_case_free(sv_case *c)
{
    odhs_network_destroy(c->net);
    odhs_system_destroy(c->sys);
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

/* Random polydisperse configuration; contacts = a random spanning forest of
 * the pairs with gap <= maxgap, plus `extra` further near pairs that close
 * cycles. A forest has linearly independent rows of S (peel the leaves: a
 * leaf's only contact carries zero force in any self-stress), so N = S S^T is
 * positive definite; a few cycles on random positions keep that generically. */
static sv_case sv_random_case(int dim, size_t n, uint64_t seed, size_t extra)
{
    sv_case c;
    memset(&c, 0, sizeof c);
    c.dim = dim;
    c.n = n;
    double L[3];
    /* packing fraction about 0.35 (2D) / 0.2 (3D) for radii in [0.4, 0.7] */
    double vol = 0.0;
    tu_rng rng;
    tu_rng_seed(&rng, seed);
    double *r = malloc(n * sizeof *r), *x = malloc(n * dim * sizeof *x);
    ck_assert(r && x);
    tu_radii_loguniform(n, 0.4, 0.7, r, &rng);
    for (size_t i = 0; i < n; ++i) vol += dim == 2 ? TU_PI * r[i] * r[i] : 4.0 / 3.0 * TU_PI * pow(r[i], 3);
    double side = dim == 2 ? sqrt(vol / 0.35) : cbrt(vol / 0.2);
    for (int k = 0; k < dim; ++k) L[k] = side * (1.0 + 0.05 * k);
    double gamma = 0.17;
    ck_assert_msg(tu_random_config(dim, n, L, gamma, r, 1e-9, x, &rng), "RSA failed");
    ck_assert_int_eq(odhs_system_create(dim, n, &c.sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_configuration(c.sys, L, gamma, r, x), ODHS_OK);
    ck_assert_int_eq(odhs_network_create(c.sys, &c.net), ODHS_OK);
    tu_pairlist pl;
    tu_brute_pairs(dim, n, x, r, L, gamma, 0.5, &pl);
    for (size_t k = pl.n; k > 1; --k) {
        size_t m = tu_index(&rng, k);
        tu_pair t = pl.p[k - 1];
        pl.p[k - 1] = pl.p[m];
        pl.p[m] = t;
    }
    size_t *par = malloc(n * sizeof *par);
    ck_assert_ptr_nonnull(par);
    for (size_t i = 0; i < n; ++i) par[i] = i;
    size_t added_extra = 0;
    for (size_t k = 0; k < pl.n; ++k) {
        size_t a = uf_find(par, pl.p[k].i), b = uf_find(par, pl.p[k].j);
        if (a != b) {
            par[a] = b;
            ck_assert_int_eq(odhs_network_add(c.net, pl.p[k].i, pl.p[k].j, ODHS_CONTACT_TEMPORARY), ODHS_OK);
        } else if (added_extra < extra) {
            added_extra++;
            ck_assert_int_eq(odhs_network_add(c.net, pl.p[k].i, pl.p[k].j, ODHS_CONTACT_TEMPORARY), ODHS_OK);
        }
    }
    ck_assert_int_eq(odhs_network_update_geometry(c.net, c.sys), ODHS_OK);
    c.nc = odhs_network_count(c.net);
    ck_assert_msg(c.nc >= n / 2, "only %zu contacts", c.nc);
    tu_pairlist_free(&pl);
    free(par);
    free(r);
    free(x);
    return c;
}

/* Dense N (nc x nc, row-major) from apply_N on unit vectors. */
static double *sv_dense_N(const odhs_network *net)
{
    size_t nc = odhs_network_count(net);
    double *A = malloc((nc * nc + 1) * sizeof *A), *e = calloc(nc + 1, sizeof *e), *col = malloc((nc + 1) * sizeof *col);
    ck_assert(A && e && col);
    for (size_t b = 0; b < nc; ++b) {
        e[b] = 1.0;
        ck_assert_int_eq(odhs_network_apply_N(net, e, col, NULL), ODHS_OK);
        e[b] = 0.0;
        for (size_t a = 0; a < nc; ++a) A[a * nc + b] = col[a];
    }
    free(e);
    free(col);
    return A;
}

/* Gaussian elimination with partial pivoting on a copy of A (n x n):
 * solves A x = b. Returns 0, or 1 if a pivot is below tiny * max|A|. */
static int sv_gepp(size_t n, const double *A0, const double *b, double *x)
{
    double *A = malloc((n * n + 1) * sizeof *A), *y = malloc((n + 1) * sizeof *y);
    if (!A || !y) {
        free(A);
        free(y);
        return 2;
    }
    memcpy(A, A0, n * n * sizeof *A);
    memcpy(y, b, n * sizeof *y);
    double amax = 0.0;
    for (size_t k = 0; k < n * n; ++k) amax = fmax(amax, fabs(A[k]));
    int status = 0;
    for (size_t k = 0; k < n && !status; ++k) {
        size_t p = k;
        for (size_t i = k + 1; i < n; ++i)
            if (fabs(A[i * n + k]) > fabs(A[p * n + k])) p = i;
        if (!(fabs(A[p * n + k]) > 1e-13 * amax)) {
            status = 1;
            break;
        }
        if (p != k) {
            for (size_t j = 0; j < n; ++j) {
                double t = A[k * n + j];
                A[k * n + j] = A[p * n + j];
                A[p * n + j] = t;
            }
            double t = y[k];
            y[k] = y[p];
            y[p] = t;
        }
        for (size_t i = k + 1; i < n; ++i) {
            double m = A[i * n + k] / A[k * n + k];
            if (m == 0.0) continue;
            for (size_t j = k; j < n; ++j) A[i * n + j] -= m * A[k * n + j];
            y[i] -= m * y[k];
        }
    }
    if (!status)
        for (size_t k = n; k-- > 0;) {
            double s = y[k];
            for (size_t j = k + 1; j < n; ++j) s -= A[k * n + j] * x[j];
            x[k] = s / A[k * n + k];
        }
    free(A);
    free(y);
    return status;
}

/* relative residual |N x - b| / |b| computed independently */
static double sv_residual(const odhs_network *net, const double *x, const double *b)
{
    size_t nc = odhs_network_count(net);
    double *Nx = malloc((nc + 1) * sizeof *Nx);
    ck_assert_ptr_nonnull(Nx);
    ck_assert_int_eq(odhs_network_apply_N(net, x, Nx, NULL), ODHS_OK);
    double rn = 0.0, bn = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        rn += (Nx[c] - b[c]) * (Nx[c] - b[c]);
        bn += b[c] * b[c];
    }
    free(Nx);
    return sqrt(rn / bn);
}

static double sv_reldiff(size_t n, const double *a, const double *b)
{
    double d = 0.0, s = 0.0;
    for (size_t k = 0; k < n; ++k) {
        d += (a[k] - b[k]) * (a[k] - b[k]);
        s += b[k] * b[k];
    }
    return sqrt(d / s);
}

static odhs_solver *sv_by_name(const char *name)
{
    odhs_solver *s = NULL;
    int st = odhs_solver_create_by_name(name, &s);
    ck_assert_msg(st == ODHS_OK, "create_by_name(%s) = %d", name, st);
    ck_assert_ptr_nonnull(s);
    ck_assert_str_eq(odhs_solver_name(s), name);
    ck_assert_str_eq(odhs_solver_errmsg(s), "");
    return s;
}

static double sv_stat(const odhs_solver *s, const char *key)
{
    double v = NAN;
    int st = odhs_solver_get_stat(s, key, &v);
    ck_assert_msg(st == ODHS_OK, "get_stat(%s) = %d", key, st);
    return v;
}

/* ------------------------------------------------------------------------ */
/* a user backend: dense Gaussian elimination with partial pivoting         */
/* ------------------------------------------------------------------------ */

typedef struct {
    double *A;
    size_t nc;
    int have;
    int setups, solves;
    double eps;     /* solve returns (1+eps) x: a controlled residual eps */
    int mode;       /* 0 normal, 1 write NaN, 2 return NOCONV, 3 fail setup */
    double iters;   /* reported "iterations" */
} ge_state;

static ge_state *ge_last; /* the most recently created state */
static int ge_creates, ge_destroys;

static int ge_create(void **state)
{
    ge_state *s = calloc(1, sizeof *s);
    if (!s) return ODHS_E_NOMEM;
    s->iters = 42.0;
    *state = s;
    ge_last = s;
    ge_creates++;
    return ODHS_OK;
}

static void ge_destroy(void *state)
{
    ge_state *s = state;
    if (!s) return;
    free(s->A);
    free(s);
    ge_destroys++;
}

static int ge_build(ge_state *s, const odhs_network *net)
{
    free(s->A);
    s->A = sv_dense_N(net);
    s->nc = odhs_network_count(net);
    s->have = 1;
    return ODHS_OK;
}

static int ge_setup(void *state, const odhs_network *net)
{
    ge_state *s = state;
    s->setups++;
    if (s->mode == 3) return ODHS_E_SINGULAR;
    return ge_build(s, net);
}

static int ge_solve(void *state, const odhs_network *net, const double *b, double *x)
{
    ge_state *s = state;
    s->solves++;
    if (!s->have || s->nc != odhs_network_count(net)) return ODHS_E_STATE;
    if (s->mode == 2) return ODHS_E_NOCONV;
    if (sv_gepp(s->nc, s->A, b, x)) return ODHS_E_SINGULAR;
    for (size_t c = 0; c < s->nc; ++c) x[c] *= 1.0 + s->eps;
    if (s->mode == 1) x[s->nc / 2] = NAN;
    return ODHS_OK;
}

/* solve without setup: build the matrix every time */
static int ge_solve_nosetup(void *state, const odhs_network *net, const double *b, double *x)
{
    ge_state *s = state;
    ge_build(s, net);
    return ge_solve(state, net, b, x);
}

static int ge_set_param(void *state, const char *key, double v)
{
    ge_state *s = state;
    if (!strcmp(key, "eps") && v > -1.0) s->eps = v;
    else if (!strcmp(key, "mode") && v >= 0 && v <= 3) s->mode = (int)v;
    else return ODHS_E_INVALID;
    return ODHS_OK;
}

static int ge_get_stat(void *state, const char *key, double *v)
{
    ge_state *s = state;
    if (!strcmp(key, "iterations")) *v = s->iters;
    else if (!strcmp(key, "setups")) *v = s->setups;
    else return ODHS_E_INVALID;
    return ODHS_OK;
}

/* Version-1 tables (written before solve_ls existed) must keep working:
 * designated initializers leave the newer fields NULL. */
static const odhs_solver_type ge_type = {
    .version = 1, .name = "user-gepp", .flags = ODHS_SOLVER_DIRECT, .create = ge_create,
    .destroy = ge_destroy, .setup = ge_setup, .solve = ge_solve, .set_param = ge_set_param,
    .get_stat = ge_get_stat,
};

static const odhs_solver_type ge_type_iterative = {
    .version = 1, .name = "user-gepp-it", .flags = ODHS_SOLVER_ITERATIVE, .create = ge_create,
    .destroy = ge_destroy, .setup = ge_setup, .solve = ge_solve, .set_param = ge_set_param,
    .get_stat = ge_get_stat,
};

/* only the required entries, current version */
static const odhs_solver_type ge_type_min = {
    .version = ODHS_SOLVER_TYPE_VERSION, .name = "user-min", .flags = 0u, .create = ge_create,
    .destroy = ge_destroy, .solve = ge_solve_nosetup,
};

static int failing_create(void **state)
{
    (void)state;
    return ODHS_E_NOMEM;
}

/* ------------------------------------------------------------------------ */
/* CG vs dense vs user backend                                              */
/* ------------------------------------------------------------------------ */

static void check_agreement(int dim, size_t n, uint64_t seed, size_t extra)
{
    sv_case c = sv_random_case(dim, n, seed, extra);
    size_t nc = c.nc;
    odhs_solver *cg = sv_by_name("cg"), *dn = sv_by_name("dense"), *ge = NULL;
    ck_assert_int_eq(odhs_solver_create(&ge_type, &ge), ODHS_OK);
    ck_assert_str_eq(odhs_solver_name(ge), "user-gepp");
    double *b = malloc(nc * sizeof *b), *xcg = calloc(nc, sizeof *xcg), *xd = calloc(nc, sizeof *xd);
    double *xg = calloc(nc, sizeof *xg), *xref = calloc(nc, sizeof *xref);
    ck_assert(b && xcg && xd && xg && xref);
    tu_rng rng;
    tu_rng_seed(&rng, seed + 99);
    double *A = sv_dense_N(c.net);
    /* N is symmetric with diagonal 2 (|n_c|^2 on both particles) */
    for (size_t a = 0; a < nc; ++a) {
        ck_assert_msg(fabs(A[a * nc + a] - 2.0) <= 1e-14, "N_%zu%zu = %.17g", a, a, A[a * nc + a]);
        for (size_t q = 0; q < a; ++q) ck_assert(fabs(A[a * nc + q] - A[q * nc + a]) <= 1e-15);
    }
    for (int rep = 0; rep < 3; ++rep) {
        for (size_t k = 0; k < nc; ++k) b[k] = tu_uniform_in(&rng, -1.0, 1.0);
        if (rep == 2) {
            /* b = S V for a random velocity field (the physical right-hand side) */
            double *V = malloc(n * dim * sizeof *V);
            ck_assert_ptr_nonnull(V);
            for (size_t k = 0; k < n * (size_t)dim; ++k) V[k] = tu_uniform_in(&rng, -1.0, 1.0);
            ck_assert_int_eq(odhs_network_apply_S(c.net, V, b), ODHS_OK);
            free(V);
        }
        ck_assert_int_eq(sv_gepp(nc, A, b, xref), 0);
        memset(xcg, 0, nc * sizeof *xcg);
        int st = odhs_solver_solve(cg, c.net, b, xcg);
        ck_assert_msg(st == ODHS_OK, "cg: %d (%s)", st, odhs_solver_errmsg(cg));
        st = odhs_solver_solve(dn, c.net, b, xd);
        ck_assert_msg(st == ODHS_OK, "dense: %d (%s)", st, odhs_solver_errmsg(dn));
        st = odhs_solver_solve(ge, c.net, b, xg);
        ck_assert_msg(st == ODHS_OK, "user: %d (%s)", st, odhs_solver_errmsg(ge));
        double rcg = sv_residual(c.net, xcg, b), rd = sv_residual(c.net, xd, b), rg = sv_residual(c.net, xg, b);
        ck_assert_msg(rcg < 1e-11 && rd < 1e-11 && rg < 1e-11, "residuals cg %g dense %g user %g", rcg, rd, rg);
        /* the library's own residual statistic agrees in magnitude */
        ck_assert_msg(sv_stat(cg, "residual") < 1e-11, "cg residual stat %g", sv_stat(cg, "residual"));
        ck_assert_msg(sv_stat(dn, "residual") < 1e-11, "dense residual stat %g", sv_stat(dn, "residual"));
        ck_assert_msg(sv_stat(ge, "residual") < 1e-11, "user residual stat %g", sv_stat(ge, "residual"));
        double d1 = sv_reldiff(nc, xcg, xd), d2 = sv_reldiff(nc, xg, xd), d3 = sv_reldiff(nc, xd, xref);
        ck_assert_msg(d1 < 1e-10, "cg vs dense: relative difference %g (dim %d, Nc %zu)", d1, dim, nc);
        ck_assert_msg(d2 < 1e-10, "user vs dense: relative difference %g", d2);
        ck_assert_msg(d3 < 1e-10, "dense vs independent GE: relative difference %g", d3);
        ck_assert_msg(sv_stat(cg, "iterations") >= 1.0, "cg did no iteration");
        ck_assert_msg(sv_stat(cg, "iterations") <= 10.0 * nc + 100, "cg iterations beyond the default cap");
        ck_assert_double_eq(sv_stat(ge, "iterations"), 42.0); /* passed through from the backend */
        ck_assert_double_eq(sv_stat(cg, "solves"), rep + 1.0);
        ck_assert_double_eq(sv_stat(dn, "solves"), rep + 1.0);
        ck_assert_double_eq(sv_stat(ge, "solves"), rep + 1.0);
    }
    /* the user backend was set up once for the three solves on one network */
    ck_assert_int_eq(ge_last->setups, 1);
    ck_assert_int_eq(ge_last->solves, 3);
    free(A);
    free(b);
    free(xcg);
    free(xd);
    free(xg);
    free(xref);
    odhs_solver_destroy(cg);
    odhs_solver_destroy(dn);
    odhs_solver_destroy(ge);
    sv_case_free(&c);
}

START_TEST(test_agree_2d_tree)
{
    check_agreement(2, 120, 1, 0);
    check_agreement(2, 200, 2, 0);
}
END_TEST

START_TEST(test_agree_2d_cycles)
{
    check_agreement(2, 150, 3, 15);
}
END_TEST

START_TEST(test_agree_3d)
{
    check_agreement(3, 120, 4, 0);
    check_agreement(3, 150, 5, 20);
}
END_TEST

/* a backend with only the required entries works the same */
START_TEST(test_user_minimal_table)
{
    sv_case c = sv_random_case(2, 60, 7, 3);
    odhs_solver *mn = NULL, *dn = sv_by_name("dense");
    ck_assert_int_eq(odhs_solver_create(&ge_type_min, &mn), ODHS_OK);
    ck_assert_str_eq(odhs_solver_name(mn), "user-min");
    double *b = malloc(c.nc * sizeof *b), *x1 = calloc(c.nc, sizeof *x1), *x2 = calloc(c.nc, sizeof *x2);
    ck_assert(b && x1 && x2);
    for (size_t k = 0; k < c.nc; ++k) b[k] = sin(1.0 + k);
    ck_assert_int_eq(odhs_solver_solve(mn, c.net, b, x1), ODHS_OK);
    ck_assert_int_eq(odhs_solver_solve(dn, c.net, b, x2), ODHS_OK);
    ck_assert_msg(sv_reldiff(c.nc, x1, x2) < 1e-10, "minimal user backend differs from dense");
    /* defaults for the optional entries */
    ck_assert_int_eq(odhs_solver_set_param(mn, "tol", 1e-3), ODHS_E_INVALID);
    ck_assert_str_ne(odhs_solver_errmsg(mn), "");
    double v;
    ck_assert_int_eq(odhs_solver_get_stat(mn, "iterations", &v), ODHS_E_INVALID);
    ck_assert_double_eq(sv_stat(mn, "solves"), 1.0);
    ck_assert(sv_stat(mn, "residual") < 1e-11);
    free(b);
    free(x1);
    free(x2);
    odhs_solver_destroy(mn);
    odhs_solver_destroy(dn);
    sv_case_free(&c);
}
END_TEST

/* setup runs again whenever the network changed, and for another network */
START_TEST(test_setup_on_change)
{
    sv_case c1 = sv_random_case(2, 50, 8, 0), c2 = sv_random_case(2, 70, 9, 0);
    odhs_solver *ge = NULL, *dn = sv_by_name("dense");
    ck_assert_int_eq(odhs_solver_create(&ge_type, &ge), ODHS_OK);
    ge_state *gs = ge_last;
    size_t cap = c1.nc + c2.nc + 4;
    double *b = malloc(cap * sizeof *b), *x = calloc(cap, sizeof *x), *xd = calloc(cap, sizeof *xd);
    ck_assert(b && x && xd);
    for (size_t k = 0; k < cap; ++k) b[k] = cos(0.3 * k) + 0.1;
    int expect_setups = 0;
    for (int round = 0; round < 2; ++round) {
        ck_assert_int_eq(odhs_solver_solve(ge, c1.net, b, x), ODHS_OK);
        ck_assert_int_eq(gs->setups, ++expect_setups);
        ck_assert_int_eq(odhs_solver_solve(ge, c1.net, b, x), ODHS_OK);
        ck_assert_int_eq(gs->setups, expect_setups);
        ck_assert_int_eq(odhs_solver_solve(dn, c1.net, b, xd), ODHS_OK);
        ck_assert(sv_reldiff(c1.nc, x, xd) < 1e-10);
        /* another network */
        ck_assert_int_eq(odhs_solver_solve(ge, c2.net, b, x), ODHS_OK);
        ck_assert_int_eq(gs->setups, ++expect_setups);
        ck_assert_int_eq(odhs_solver_solve(dn, c2.net, b, xd), ODHS_OK);
        ck_assert(sv_reldiff(c2.nc, x, xd) < 1e-10);
        ck_assert_msg(sv_residual(c2.net, xd, b) < 1e-11, "dense after switching networks");
    }
    /* contact forces are not part of the operator: no new setup */
    {
        double *f = malloc(c1.nc * sizeof *f);
        ck_assert_ptr_nonnull(f);
        for (size_t k = 0; k < c1.nc; ++k) f[k] = 0.5 + k;
        ck_assert_int_eq(odhs_network_set_forces(c1.net, f), ODHS_OK);
        ck_assert_int_eq(odhs_solver_solve(ge, c1.net, b, x), ODHS_OK);
        ck_assert_int_eq(gs->setups, ++expect_setups); /* back from c2 */
        ck_assert_int_eq(odhs_network_set_forces(c1.net, b), ODHS_OK);
        ck_assert_int_eq(odhs_solver_solve(ge, c1.net, b, x), ODHS_OK);
        ck_assert_int_eq(gs->setups, expect_setups);
        free(f);
    }
    /* geometry change of the same network: one particle moved a little */
    {
        double *pos = malloc(c1.n * 2 * sizeof *pos), *n0 = malloc(c1.nc * 2 * sizeof *n0),
               *n1 = malloc(c1.nc * 2 * sizeof *n1);
        ck_assert(pos && n0 && n1);
        ck_assert_int_eq(odhs_network_get_normals(c1.net, n0), ODHS_OK);
        int moved = 0;
        for (size_t c = 0; c < c1.nc && !moved; ++c) {
            size_t i0, j0;
            ck_assert_int_eq(odhs_network_get_contact(c1.net, c, &i0, &j0, NULL), ODHS_OK);
            ck_assert_int_eq(odhs_system_get_positions(c1.sys, pos), ODHS_OK);
            pos[j0 * 2 + 1] += 1e-3;
            pos[j0 * 2] -= 2e-3;
            moved = odhs_system_set_positions(c1.sys, pos) == ODHS_OK;
        }
        ck_assert_msg(moved, "could not move any particle");
        ck_assert_int_eq(odhs_network_update_geometry(c1.net, c1.sys), ODHS_OK);
        ck_assert_int_eq(odhs_network_get_normals(c1.net, n1), ODHS_OK);
        ck_assert(memcmp(n0, n1, c1.nc * 2 * sizeof *n0) != 0);
        ck_assert_int_eq(odhs_solver_solve(ge, c1.net, b, x), ODHS_OK);
        ck_assert_int_eq(gs->setups, ++expect_setups);
        ck_assert_int_eq(odhs_solver_solve(dn, c1.net, b, xd), ODHS_OK);
        ck_assert_msg(sv_residual(c1.net, xd, b) < 1e-11, "dense not refactored after a geometry change");
        ck_assert(sv_reldiff(c1.nc, x, xd) < 1e-10);
        free(pos);
        free(n0);
        free(n1);
    }
    /* adding a contact: the new (larger) system is set up and solved */
    {
        size_t a = SIZE_MAX, bb = SIZE_MAX;
        for (size_t i = 0; i < c1.n && a == SIZE_MAX; ++i)
            for (size_t j = i + 1; j < c1.n; ++j) {
                size_t idx;
                odhs_network_find(c1.net, i, j, &idx);
                if (idx == SIZE_MAX) {
                    a = i;
                    bb = j;
                    break;
                }
            }
        ck_assert_int_eq(odhs_network_add(c1.net, a, bb, ODHS_CONTACT_TEMPORARY), ODHS_OK);
        ck_assert_int_eq(odhs_network_update_geometry(c1.net, c1.sys), ODHS_OK);
        size_t nc = odhs_network_count(c1.net);
        ck_assert_uint_eq(nc, c1.nc + 1);
        ck_assert_int_eq(odhs_solver_solve(ge, c1.net, b, x), ODHS_OK);
        ck_assert_int_eq(gs->setups, ++expect_setups);
        ck_assert_int_eq(odhs_solver_solve(dn, c1.net, b, xd), ODHS_OK);
        ck_assert_msg(sv_residual(c1.net, xd, b) < 1e-11, "dense after adding a contact");
        ck_assert(sv_reldiff(nc, x, xd) < 1e-10);
    }
    free(b);
    free(x);
    free(xd);
    odhs_solver_destroy(ge);
    odhs_solver_destroy(dn);
    sv_case_free(&c1);
    sv_case_free(&c2);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* the wrapper checks every backend result                                  */
/* ------------------------------------------------------------------------ */

START_TEST(test_wrapper_checks)
{
    sv_case c = sv_random_case(2, 60, 10, 2);
    double *b = malloc(c.nc * sizeof *b), *x = calloc(c.nc, sizeof *x), *xd = calloc(c.nc, sizeof *xd);
    ck_assert(b && x && xd);
    for (size_t k = 0; k < c.nc; ++k) b[k] = 1.0 - 0.01 * k;
    odhs_solver *dn = sv_by_name("dense");
    ck_assert_int_eq(odhs_solver_solve(dn, c.net, b, xd), ODHS_OK);

    /* a controlled error eps: relative residual = eps exactly up to round-off */
    odhs_solver *ge = NULL, *gi = NULL;
    ck_assert_int_eq(odhs_solver_create(&ge_type, &ge), ODHS_OK);
    ck_assert_int_eq(odhs_solver_create(&ge_type_iterative, &gi), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(ge, "eps", 1e-4), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(gi, "eps", 1e-4), ODHS_OK);
    /* with the default iterative refinement, the (1+eps)-scaled direct
     * solution is refined to round-off ((1+eps)(1-eps) -> 1 - eps^2 -> ...) */
    int st = odhs_solver_solve(ge, c.net, b, x);
    ck_assert_msg(st == ODHS_OK, "refined direct backend: %d", st);
    ck_assert_msg(sv_stat(ge, "residual") < 1e-12, "refined residual %g", sv_stat(ge, "residual"));
    for (size_t k = 0; k < c.nc; ++k) ck_assert(fabs(x[k] - xd[k]) <= 1e-10 * (1.0 + fabs(xd[k])));
    ck_assert_int_eq(odhs_solver_set_refinement(ge, -1), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_refinement(NULL, 1), ODHS_E_NULL);
    /* without refinement, default check tolerance 1e-6: a direct backend is
     * reported singular, an iterative one as not converged */
    ck_assert_int_eq(odhs_solver_set_refinement(ge, 0), ODHS_OK);
    st = odhs_solver_solve(ge, c.net, b, x);
    ck_assert_msg(st == ODHS_E_SINGULAR, "direct backend with residual 1e-4: %d", st);
    ck_assert_str_ne(odhs_solver_errmsg(ge), "");
    ck_assert_msg(fabs(sv_stat(ge, "residual") / 1e-4 - 1.0) < 1e-6, "residual stat %.17g, expected 1e-4",
                  sv_stat(ge, "residual"));
    st = odhs_solver_solve(gi, c.net, b, x);
    ck_assert_msg(st == ODHS_E_NOCONV, "iterative backend with residual 1e-4: %d", st);
    /* the check tolerance setter */
    ck_assert_int_eq(odhs_solver_set_check_tolerance(ge, 0.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_check_tolerance(ge, -1e-3), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_check_tolerance(ge, NAN), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_check_tolerance(ge, INFINITY), ODHS_E_INVALID);
    /* rejected values left the tolerance at its default */
    ck_assert_int_eq(odhs_solver_solve(ge, c.net, b, x), ODHS_E_SINGULAR);
    ck_assert_int_eq(odhs_solver_set_check_tolerance(ge, 1e-3), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_check_tolerance(gi, 2e-4), ODHS_OK);
    ck_assert_int_eq(odhs_solver_solve(ge, c.net, b, x), ODHS_OK);
    ck_assert_int_eq(odhs_solver_solve(gi, c.net, b, x), ODHS_OK);
    for (size_t k = 0; k < c.nc; ++k) ck_assert(fabs(x[k] - (1.0 + 1e-4) * xd[k]) <= 1e-9 * (1.0 + fabs(xd[k])));
    ck_assert_msg(fabs(sv_stat(gi, "residual") / 1e-4 - 1.0) < 1e-6, "residual stat %g", sv_stat(gi, "residual"));
    /* the check is on the normwise backward error |r| / (|N| |x| + |b|),
     * which is below the relative residual: a tolerance just under it fails
     * again, just over it passes */
    {
        double be = sv_stat(gi, "backward_error");
        ck_assert_msg(be > 0.0 && be < 1e-4, "backward error %g", be);
        ck_assert_int_eq(odhs_solver_set_check_tolerance(gi, 0.9 * be), ODHS_OK);
        ck_assert_int_eq(odhs_solver_solve(gi, c.net, b, x), ODHS_E_NOCONV);
        ck_assert_int_eq(odhs_solver_set_check_tolerance(gi, 1.1 * be), ODHS_OK);
        ck_assert_int_eq(odhs_solver_solve(gi, c.net, b, x), ODHS_OK);
    }

    /* a non-finite solution is caught */
    ck_assert_int_eq(odhs_solver_set_param(ge, "eps", 0.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_param(ge, "mode", 1), ODHS_OK);
    ck_assert_int_eq(odhs_solver_solve(ge, c.net, b, x), ODHS_E_SINGULAR);
    /* backend errors are passed through */
    ck_assert_int_eq(odhs_solver_set_param(ge, "mode", 2), ODHS_OK);
    ck_assert_int_eq(odhs_solver_solve(ge, c.net, b, x), ODHS_E_NOCONV);
    ck_assert_str_ne(odhs_solver_errmsg(ge), "");
    /* a failing setup is reported, and retried on the next solve */
    {
        odhs_solver *g2 = NULL;
        ck_assert_int_eq(odhs_solver_create(&ge_type, &g2), ODHS_OK);
        ge_state *s2 = ge_last;
        ck_assert_int_eq(odhs_solver_set_param(g2, "mode", 3), ODHS_OK);
        ck_assert_int_eq(odhs_solver_solve(g2, c.net, b, x), ODHS_E_SINGULAR);
        ck_assert_int_eq(s2->solves, 0);
        ck_assert_int_eq(odhs_solver_set_param(g2, "mode", 0), ODHS_OK);
        memset(x, 0, c.nc * sizeof *x);
        ck_assert_int_eq(odhs_solver_solve(g2, c.net, b, x), ODHS_OK);
        ck_assert_int_eq(s2->setups, 2);
        ck_assert(sv_reldiff(c.nc, x, xd) < 1e-10);
        odhs_solver_destroy(g2);
    }
    /* user parameters are passed to the backend; bad values rejected */
    ck_assert_int_eq(odhs_solver_set_param(ge, "eps", -2.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(ge, "nonsense", 1.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(ge, "eps", NAN), ODHS_E_NONFINITE);
    ck_assert_int_eq(odhs_solver_set_param(ge, "mode", 0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_solve(ge, c.net, b, x), ODHS_OK);
    ck_assert_double_eq(sv_stat(ge, "setups"), 1.0);
    /* non-finite right-hand side */
    b[1] = NAN;
    ck_assert_int_eq(odhs_solver_solve(dn, c.net, b, x), ODHS_E_NONFINITE);
    b[1] = INFINITY;
    ck_assert_int_eq(odhs_solver_solve(ge, c.net, b, x), ODHS_E_NONFINITE);
    free(b);
    free(x);
    free(xd);
    odhs_solver_destroy(ge);
    odhs_solver_destroy(gi);
    odhs_solver_destroy(dn);
    sv_case_free(&c);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* backend tables, names                                                     */
/* ------------------------------------------------------------------------ */

START_TEST(test_malformed_tables)
{
    odhs_solver_type t;
    odhs_solver *s = (odhs_solver *)&t;
    int c0 = ge_creates;
    t = ge_type;
    t.version = 0;
    ck_assert_int_eq(odhs_solver_create(&t, &s), ODHS_E_INVALID);
    ck_assert_ptr_null(s);
    t = ge_type;
    t.version = ODHS_SOLVER_TYPE_VERSION + 1;
    s = (odhs_solver *)&t;
    ck_assert_int_eq(odhs_solver_create(&t, &s), ODHS_E_INVALID);
    ck_assert_ptr_null(s);
    t = ge_type;
    t.version = -1;
    ck_assert_int_eq(odhs_solver_create(&t, &s), ODHS_E_INVALID);
    t = ge_type;
    t.name = NULL;
    ck_assert_int_eq(odhs_solver_create(&t, &s), ODHS_E_INVALID);
    t = ge_type;
    t.create = NULL;
    ck_assert_int_eq(odhs_solver_create(&t, &s), ODHS_E_INVALID);
    t = ge_type;
    t.destroy = NULL;
    ck_assert_int_eq(odhs_solver_create(&t, &s), ODHS_E_INVALID);
    t = ge_type;
    t.solve = NULL;
    ck_assert_int_eq(odhs_solver_create(&t, &s), ODHS_E_INVALID);
    ck_assert_ptr_null(s);
    /* nothing was created for a rejected table */
    ck_assert_int_eq(ge_creates, c0);
    /* a failing create is reported with its own code */
    t = ge_type;
    t.create = failing_create;
    s = (odhs_solver *)&t;
    ck_assert_int_eq(odhs_solver_create(&t, &s), ODHS_E_NOMEM);
    ck_assert_ptr_null(s);
    /* NULL arguments */
    ck_assert_int_eq(odhs_solver_create(NULL, &s), ODHS_E_NULL);
    ck_assert_int_eq(odhs_solver_create(&ge_type, NULL), ODHS_E_NULL);
    ck_assert_int_eq(ge_creates, c0);
    /* create / destroy pair up */
    int d0 = ge_destroys;
    ck_assert_int_eq(odhs_solver_create(&ge_type, &s), ODHS_OK);
    ck_assert_int_eq(ge_creates, c0 + 1);
    odhs_solver_destroy(s);
    ck_assert_int_eq(ge_destroys, d0 + 1);
}
END_TEST

START_TEST(test_create_by_name)
{
    odhs_solver *s = sv_by_name("cg");
    odhs_solver_destroy(s);
    s = sv_by_name("dense");
    odhs_solver_destroy(s);
    const char *absent[3] = {"cholmod", "spqr", "cholmod-pcg"};
    for (int k = 0; k < 3; ++k) {
        s = (odhs_solver *)&k;
        int st = odhs_solver_create_by_name(absent[k], &s);
        if (st == ODHS_OK) {
            /* built with SuiteSparse backends: then they must really work */
            ck_assert_str_eq(odhs_solver_name(s), absent[k]);
            sv_case c = sv_random_case(2, 60, 11, 3);
            double *b = malloc(c.nc * sizeof *b), *x = calloc(c.nc, sizeof *x);
            ck_assert(b && x);
            for (size_t q = 0; q < c.nc; ++q) b[q] = 0.5 + sin((double)q);
            ck_assert_int_eq(odhs_solver_solve(s, c.net, b, x), ODHS_OK);
            ck_assert(sv_residual(c.net, x, b) < 1e-11);
            free(b);
            free(x);
            sv_case_free(&c);
            odhs_solver_destroy(s);
        } else {
            ck_assert_msg(st == ODHS_E_NOTINSTALLED, "create_by_name(%s) = %d, expected NOTINSTALLED", absent[k], st);
            ck_assert_ptr_null(s);
        }
    }
    const char *bad[4] = {"nonsense", "", "CG", "dense "};
    for (int k = 0; k < 4; ++k) {
        s = (odhs_solver *)&k;
        ck_assert_msg(odhs_solver_create_by_name(bad[k], &s) == ODHS_E_INVALID, "name '%s'", bad[k]);
        ck_assert_ptr_null(s);
    }
    ck_assert_int_eq(odhs_solver_create_by_name(NULL, &s), ODHS_E_NULL);
    ck_assert_int_eq(odhs_solver_create_by_name("cg", NULL), ODHS_E_NULL);
    /* the built-in tables are valid user-style tables too */
    ck_assert_int_eq(odhs_solver_type_cg.version, ODHS_SOLVER_TYPE_VERSION);
    ck_assert_str_eq(odhs_solver_type_cg.name, "cg");
    ck_assert(odhs_solver_type_cg.flags & ODHS_SOLVER_ITERATIVE);
    ck_assert(odhs_solver_type_dense.flags & ODHS_SOLVER_DIRECT);
    ck_assert_int_eq(odhs_solver_create(&odhs_solver_type_dense, &s), ODHS_OK);
    ck_assert_str_eq(odhs_solver_name(s), "dense");
    odhs_solver_destroy(s);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* parameters and statistics of CG                                           */
/* ------------------------------------------------------------------------ */

START_TEST(test_cg_params_stats)
{
    sv_case c = sv_random_case(2, 250, 12, 0);
    size_t nc = c.nc;
    double *b = malloc(nc * sizeof *b), *x = calloc(nc, sizeof *x), *xd = calloc(nc, sizeof *xd);
    ck_assert(b && x && xd);
    for (size_t k = 0; k < nc; ++k) b[k] = sin(0.7 * k) + 0.2;
    odhs_solver *cg = sv_by_name("cg"), *dn = sv_by_name("dense");
    ck_assert_int_eq(odhs_solver_solve(dn, c.net, b, xd), ODHS_OK);
    ck_assert_double_eq(sv_stat(cg, "solves"), 0.0);

    /* default: converges to 1e-12 */
    ck_assert_int_eq(odhs_solver_solve(cg, c.net, b, x), ODHS_OK);
    double it_full = sv_stat(cg, "iterations");
    ck_assert_msg(it_full >= 5, "a %zu-contact tree converged in %g iterations?", nc, it_full);
    ck_assert_msg(sv_stat(cg, "residual") <= 1e-12 * 1.01, "residual %g above the default tol",
                  sv_stat(cg, "residual"));
    ck_assert(fabs(sv_stat(cg, "residual") - sv_residual(c.net, x, b)) <= 1e-13);

    /* warm start from the solution: no iteration needed */
    ck_assert_int_eq(odhs_solver_solve(cg, c.net, b, x), ODHS_OK);
    ck_assert_msg(sv_stat(cg, "iterations") <= 1.0, "warm start took %g iterations", sv_stat(cg, "iterations"));
    ck_assert(sv_reldiff(nc, x, xd) < 1e-10);

    /* maxiter 1 on a hard problem: not converged, exactly one iteration */
    ck_assert_int_eq(odhs_solver_set_param(cg, "maxiter", 1), ODHS_OK);
    memset(x, 0, nc * sizeof *x);
    int st = odhs_solver_solve(cg, c.net, b, x);
    ck_assert_msg(st == ODHS_E_NOCONV, "maxiter 1: %d", st);
    ck_assert_double_eq(sv_stat(cg, "iterations"), 1.0);
    ck_assert_str_ne(odhs_solver_errmsg(cg), "");
    ck_assert_msg(sv_residual(c.net, x, b) > 1e-6, "one CG iteration reached %g", sv_residual(c.net, x, b));
    /* maxiter = a few: still NOCONV, iterations = maxiter */
    ck_assert_int_eq(odhs_solver_set_param(cg, "maxiter", 3), ODHS_OK);
    memset(x, 0, nc * sizeof *x);
    ck_assert_int_eq(odhs_solver_solve(cg, c.net, b, x), ODHS_E_NOCONV);
    ck_assert_double_eq(sv_stat(cg, "iterations"), 3.0);
    /* invalid values rejected, the setting kept */
    ck_assert_int_eq(odhs_solver_set_param(cg, "maxiter", -1), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(cg, "maxiter", NAN), ODHS_E_NONFINITE);
    ck_assert_int_eq(odhs_solver_set_param(cg, "maxiter", INFINITY), ODHS_E_NONFINITE);
    memset(x, 0, nc * sizeof *x);
    ck_assert_int_eq(odhs_solver_solve(cg, c.net, b, x), ODHS_E_NOCONV);
    ck_assert_double_eq(sv_stat(cg, "iterations"), 3.0);
    /* back to automatic */
    ck_assert_int_eq(odhs_solver_set_param(cg, "maxiter", 0), ODHS_OK);
    memset(x, 0, nc * sizeof *x);
    ck_assert_int_eq(odhs_solver_solve(cg, c.net, b, x), ODHS_OK);
    ck_assert_double_eq(sv_stat(cg, "iterations"), it_full);

    /* a loose tolerance: fewer iterations, residual between 1e-12 and tol;
     * the wrapper's check (1e-6) then needs relaxing */
    ck_assert_int_eq(odhs_solver_set_param(cg, "tol", 1e-4), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_check_tolerance(cg, 1e-3), ODHS_OK);
    memset(x, 0, nc * sizeof *x);
    ck_assert_int_eq(odhs_solver_solve(cg, c.net, b, x), ODHS_OK);
    double it_loose = sv_stat(cg, "iterations"), res_loose = sv_stat(cg, "residual");
    ck_assert_msg(it_loose < it_full, "tol 1e-4 took %g >= %g iterations", it_loose, it_full);
    ck_assert_msg(res_loose <= 1e-4 && res_loose > 1e-12, "residual %g with tol 1e-4", res_loose);
    ck_assert_msg(fabs(res_loose / sv_residual(c.net, x, b) - 1.0) < 1e-6, "residual stat %g vs %g", res_loose,
                  sv_residual(c.net, x, b));
    /* invalid tolerances rejected, setting kept */
    ck_assert_int_eq(odhs_solver_set_param(cg, "tol", 0.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(cg, "tol", -1e-8), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(cg, "tol", 1.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(cg, "tol", 5.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(cg, "tol", NAN), ODHS_E_NONFINITE);
    ck_assert_int_eq(odhs_solver_set_param(cg, "nonsense", 1.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(cg, NULL, 1.0), ODHS_E_NULL);
    memset(x, 0, nc * sizeof *x);
    ck_assert_int_eq(odhs_solver_solve(cg, c.net, b, x), ODHS_OK);
    ck_assert_double_eq(sv_stat(cg, "iterations"), it_loose);
    /* with the default check tolerance a loose CG is reported unconverged */
    ck_assert_int_eq(odhs_solver_set_param(cg, "tol", 1e-2), ODHS_OK);
    ck_assert_int_eq(odhs_solver_set_check_tolerance(cg, 1e-6), ODHS_OK);
    memset(x, 0, nc * sizeof *x);
    st = odhs_solver_solve(cg, c.net, b, x);
    if (sv_stat(cg, "residual") > 1e-6) ck_assert_int_eq(st, ODHS_E_NOCONV);

    /* statistics */
    double v;
    ck_assert_int_eq(odhs_solver_get_stat(cg, "nonsense", &v), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_get_stat(cg, NULL, &v), ODHS_E_NULL);
    ck_assert_int_eq(odhs_solver_get_stat(cg, "solves", NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_solver_get_stat(NULL, "solves", &v), ODHS_E_NULL);
    double solves = sv_stat(cg, "solves");
    /* 6 successful solves, 3 that ran the backend but failed to converge */
    ck_assert_msg(solves >= 6.0 && solves <= 9.0, "solves = %g after 9 solves (6 successful)", solves);
    /* the dense backend has no parameters and reports 0 iterations */
    ck_assert_int_eq(odhs_solver_set_param(dn, "tol", 1e-3), ODHS_E_INVALID);
    ck_assert_double_eq(sv_stat(dn, "iterations"), 0.0);
    ck_assert_double_eq(sv_stat(dn, "solves"), 1.0);
    free(b);
    free(x);
    free(xd);
    odhs_solver_destroy(cg);
    odhs_solver_destroy(dn);
    sv_case_free(&c);
}
END_TEST

/* "residual" is documented as that of the last solve: after a solve that
 * failed (NOCONV) it must describe that solve, or be NaN (unknown), not keep
 * the value of an earlier successful solve. */
START_TEST(test_residual_stat_after_failure)
{
    sv_case c = sv_random_case(2, 250, 12, 0);
    size_t nc = c.nc;
    double *b = malloc(nc * sizeof *b), *x = calloc(nc, sizeof *x);
    ck_assert(b && x);
    for (size_t k = 0; k < nc; ++k) b[k] = sin(0.7 * k) + 0.2;
    odhs_solver *cg = sv_by_name("cg");
    ck_assert_int_eq(odhs_solver_solve(cg, c.net, b, x), ODHS_OK);
    ck_assert(sv_stat(cg, "residual") < 1e-11);
    ck_assert_int_eq(odhs_solver_set_param(cg, "maxiter", 1), ODHS_OK);
    memset(x, 0, nc * sizeof *x);
    ck_assert_int_eq(odhs_solver_solve(cg, c.net, b, x), ODHS_E_NOCONV);
    double res = sv_stat(cg, "residual"), actual = sv_residual(c.net, x, b);
    ck_assert_msg(actual > 1e-6, "one CG iteration reached %g", actual);
    ck_assert_msg(isnan(res) || fabs(res - actual) <= 1e-9 * actual,
                  "residual statistic after a NOCONV solve is %g, but that solve's residual is %g "
                  "(stale value of the previous, successful solve)",
                  res, actual);
    free(b);
    free(x);
    odhs_solver_destroy(cg);
    sv_case_free(&c);
}
END_TEST

/* One solver used on a sequence of networks that are created, solved and
 * destroyed in turn (e.g. a user loop over configurations). The allocator
 * often hands out the same address again and the new network is built with
 * the same number of calls, so the solver must not mistake it for the old one
 * and reuse its factorisation: every solve has to be correct. */
START_TEST(test_recreated_network)
{
    odhs_system *sys = NULL;
    ck_assert_int_eq(odhs_system_create(2, 3, &sys), ODHS_OK);
    double L[2] = {10, 10}, r[3] = {0.5, 0.5, 0.5};
    odhs_solver *dn = sv_by_name("dense"), *ge = NULL;
    ck_assert_int_eq(odhs_solver_create(&ge_type, &ge), ODHS_OK);
    ge_state *gs = ge_last;
    int failures = 0, first_fail = -1, gfail = 0;
    for (int it = 0; it < 40; ++it) {
        /* disc 2 touches disc 1 at an angle that changes every time */
        double a = 0.05 * it;
        double x[6] = {1.0, 1.0, 2.0, 1.0, 2.0 + cos(a), 1.0 + sin(a)};
        ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
        odhs_network *net = NULL;
        ck_assert_int_eq(odhs_network_create(sys, &net), ODHS_OK);
        ck_assert_int_eq(odhs_network_add(net, 0, 1, ODHS_CONTACT_TEMPORARY), ODHS_OK);
        ck_assert_int_eq(odhs_network_add(net, 1, 2, ODHS_CONTACT_TEMPORARY), ODHS_OK);
        ck_assert_int_eq(odhs_network_update_geometry(net, sys), ODHS_OK);
        /* exact solution: N = [[2, -c], [-c, 2]] with c = n01.n12 = cos(a) */
        double b[2] = {1.0, 2.0}, xs[2] = {0, 0}, xg[2] = {0, 0}, c = cos(a);
        double det = 4.0 - c * c, e0 = (2.0 * b[0] + c * b[1]) / det, e1 = (c * b[0] + 2.0 * b[1]) / det;
        int st = odhs_solver_solve(dn, net, b, xs);
        int sg = odhs_solver_solve(ge, net, b, xg);
        if (st != ODHS_OK || fabs(xs[0] - e0) > 1e-12 || fabs(xs[1] - e1) > 1e-12) {
            if (first_fail < 0) first_fail = it;
            failures++;
        }
        if (sg != ODHS_OK || fabs(xg[0] - e0) > 1e-12 || fabs(xg[1] - e1) > 1e-12) gfail++;
        odhs_network_destroy(net);
    }
    ck_assert_msg(failures == 0 && gfail == 0 && gs->setups == 40,
                  "on 40 freshly created networks the dense solver failed %d times (first at %d), the "
                  "user backend %d times, and the user backend was set up %d times: the setup of a "
                  "destroyed network (same address, same version count) was reused",
                  failures, first_fail, gfail, gs->setups);
    odhs_solver_destroy(dn);
    odhs_solver_destroy(ge);
    odhs_system_destroy(sys);
}
END_TEST

/* The stepper's solves on scratch networks (the isostatic sub-networks under
 * fixed pressure, through the relaxed solve) must not keep the setup of a
 * destroyed network that had the same address and version: with reuse = 0
 * every fresh network is set up (0.2.3 reused it, and a fixed-pressure run
 * gave different results depending on the heap's history). */
START_TEST(test_recreated_network_relaxed)
{
    odhs_system *sys = NULL;
    ck_assert_int_eq(odhs_system_create(2, 3, &sys), ODHS_OK);
    double L[2] = {10, 10}, r[3] = {0.5, 0.5, 0.5};
    odhs_solver *ge = NULL;
    ck_assert_int_eq(odhs_solver_create(&ge_type, &ge), ODHS_OK);
    ge_state *gs = ge_last;
    int gfail = 0;
    for (int it = 0; it < 40; ++it) {
        double a = 0.05 * it;
        double x[6] = {1.0, 1.0, 2.0, 1.0, 2.0 + cos(a), 1.0 + sin(a)};
        ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
        odhs_network *net = NULL;
        ck_assert_int_eq(odhs_network_create(sys, &net), ODHS_OK);
        ck_assert_int_eq(odhs_network_add(net, 0, 1, ODHS_CONTACT_TEMPORARY), ODHS_OK);
        ck_assert_int_eq(odhs_network_add(net, 1, 2, ODHS_CONTACT_TEMPORARY), ODHS_OK);
        ck_assert_int_eq(odhs_network_update_geometry(net, sys), ODHS_OK);
        double b[2] = {1.0, 2.0}, xg[2] = {0, 0}, c = cos(a);
        double det = 4.0 - c * c, e0 = (2.0 * b[0] + c * b[1]) / det, e1 = (c * b[0] + 2.0 * b[1]) / det;
        int sg = odhs__solver_solve_relaxed(ge, net, b, xg, 1e-7, 0);
        if (sg != ODHS_OK || fabs(xg[0] - e0) > 1e-12 || fabs(xg[1] - e1) > 1e-12) gfail++;
        odhs_network_destroy(net);
    }
    ck_assert_msg(gfail == 0 && gs->setups == 40,
                  "relaxed solves on 40 fresh networks: %d wrong, %d setups (a destroyed network's setup was reused)",
                  gfail, gs->setups);
    odhs_solver_destroy(ge);
    odhs_system_destroy(sys);
}
END_TEST

/* The dense backend's reciprocal condition estimate against the exact
 * 1-norm condition number of N (from an explicit inverse by GE), and its
 * "min_rcond" threshold. */
START_TEST(test_dense_rcond)
{
    sv_case c = sv_random_case(2, 80, 14, 4);
    size_t nc = c.nc;
    double *A = sv_dense_N(c.net), *Ainv = malloc(nc * nc * sizeof *Ainv), *e = calloc(nc, sizeof *e),
           *col = malloc(nc * sizeof *col);
    ck_assert(A && Ainv && e && col);
    double anorm = 0.0, inorm = 0.0;
    for (size_t j = 0; j < nc; ++j) {
        double cs = 0.0;
        for (size_t i = 0; i < nc; ++i) cs += fabs(A[i * nc + j]);
        anorm = fmax(anorm, cs);
        e[j] = 1.0;
        ck_assert_int_eq(sv_gepp(nc, A, e, col), 0);
        e[j] = 0.0;
        cs = 0.0;
        for (size_t i = 0; i < nc; ++i) cs += fabs(col[i]);
        inorm = fmax(inorm, cs);
    }
    double rcond = 1.0 / (anorm * inorm);
    double *b = malloc(nc * sizeof *b), *x = calloc(nc, sizeof *x);
    ck_assert_ptr_nonnull(b);
    for (size_t k = 0; k < nc; ++k) b[k] = 1.0;
    odhs_solver *dn = sv_by_name("dense");
    ck_assert_int_eq(odhs_solver_solve(dn, c.net, b, x), ODHS_OK);
    double est = sv_stat(dn, "rcond");
    /* the estimate of |N^-1|_1 never exceeds the true norm, and is close */
    ck_assert_msg(est >= rcond * (1.0 - 1e-8) && est <= 10.0 * rcond, "rcond estimate %g, exact %g", est, rcond);
    ck_assert_double_eq(sv_stat(dn, "lapack_info"), 0.0);
    /* a threshold above the network's rcond: reported singular */
    odhs_solver *strict = sv_by_name("dense");
    ck_assert_int_eq(odhs_solver_set_param(strict, "min_rcond", fmin(0.9, 2.0 * est)), ODHS_OK);
    memset(x, 0, nc * sizeof *x);
    ck_assert_int_eq(odhs_solver_solve(strict, c.net, b, x), ODHS_E_SINGULAR);
    ck_assert_str_ne(odhs_solver_errmsg(strict), "");
    ck_assert_int_eq(odhs_solver_set_param(strict, "min_rcond", 0.5 * est), ODHS_OK);
    ck_assert_int_eq(odhs_solver_solve(strict, c.net, b, x), ODHS_OK);
    ck_assert(sv_residual(c.net, x, b) < 1e-11);
    /* validation */
    ck_assert_int_eq(odhs_solver_set_param(strict, "min_rcond", -1e-3), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(strict, "min_rcond", 1.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_param(strict, "min_rcond", NAN), ODHS_E_NONFINITE);
    ck_assert_int_eq(odhs_solver_set_param(strict, "min_rcond", 0.0), ODHS_OK);
    free(A);
    free(Ainv);
    free(e);
    free(col);
    free(b);
    free(x);
    odhs_solver_destroy(dn);
    odhs_solver_destroy(strict);
    sv_case_free(&c);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* singular N                                                                */
/* ------------------------------------------------------------------------ */

/* b = kernel vector of S^T (a self-stress) or a generic vector; both have a
 * component outside the range of N, so no x solves N x = b. */
static void check_singular(const odhs_network *net, const double *kernel, const char *what)
{
    size_t nc = odhs_network_count(net);
    double *b = malloc(nc * sizeof *b), *x = calloc(nc, sizeof *x), *Sf = NULL;
    ck_assert(b && x);
    /* the self-stress really is one: S^T f0 = 0 */
    size_t nd = odhs_network_particles(net) * (size_t)odhs_network_dim(net);
    Sf = malloc(nd * sizeof *Sf);
    ck_assert_ptr_nonnull(Sf);
    ck_assert_int_eq(odhs_network_apply_ST(net, kernel, Sf), ODHS_OK);
    for (size_t q = 0; q < nd; ++q) ck_assert_msg(fabs(Sf[q]) < 1e-12, "%s: S^T f0 != 0", what);
    for (int variant = 0; variant < 2; ++variant) {
        for (size_t c = 0; c < nc; ++c) b[c] = variant == 0 ? kernel[c] : kernel[c] + 0.3 * sin(1.0 + c);
        odhs_solver *dn = sv_by_name("dense"), *cg = sv_by_name("cg");
        memset(x, 0, nc * sizeof *x);
        int st = odhs_solver_solve(dn, net, b, x);
        ck_assert_msg(st == ODHS_E_SINGULAR, "%s (b variant %d): dense returned %d (%s)", what, variant, st,
                      odhs_solver_errmsg(dn));
        ck_assert_str_ne(odhs_solver_errmsg(dn), "");
        memset(x, 0, nc * sizeof *x);
        st = odhs_solver_solve(cg, net, b, x);
        ck_assert_msg(st == ODHS_E_SINGULAR || st == ODHS_E_NOCONV, "%s (b variant %d): cg returned %d", what,
                      variant, st);
        /* the user GE backend's own singularity report goes through as well */
        odhs_solver *ge = NULL;
        ck_assert_int_eq(odhs_solver_create(&ge_type, &ge), ODHS_OK);
        memset(x, 0, nc * sizeof *x);
        st = odhs_solver_solve(ge, net, b, x);
        ck_assert_msg(st == ODHS_E_SINGULAR, "%s: user GE returned %d", what, st);
        odhs_solver_destroy(ge);
        odhs_solver_destroy(dn);
        odhs_solver_destroy(cg);
    }
    free(b);
    free(x);
    free(Sf);
}

/* three discs in a row that touch around the periodic box: f = (1,1,1) is a
 * self-stress and N = [[2,-1,-1],[-1,2,-1],[-1,-1,2]] is singular */
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
    double f0[3] = {1.0, 1.0, 1.0};
    check_singular(net, f0, "periodic ring");
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* a 3x3 square lattice of touching discs filling a periodic 3x3 box: 18
 * contacts on 18 degrees of freedom, 2 of which are translations: rows along
 * a line of the lattice carry a uniform self-stress */
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
    size_t nc = odhs_network_count(net);
    ck_assert_uint_eq(nc, 18);
    /* self-stress: unit force on the three contacts of the bottom row */
    double f0[18] = {0};
    for (size_t c = 0; c < nc; ++c) {
        size_t i, j;
        odhs_network_get_contact(net, c, &i, &j, NULL);
        if (i / 3 == 0 && j / 3 == 0) f0[c] = 1.0;
    }
    check_singular(net, f0, "square lattice");
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* a hyperstatic triangular patch of 7 identical discs (12 contacts > 2N - 3 =
 * 11): N is singular up to round-off of the irrational normals */
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
    size_t nc = odhs_network_count(net);
    ck_assert_uint_eq(nc, 12);
    /* self-stress: tension t on the spokes and compression on the ring with
     * force balance on a ring disc: spoke force + 2 ring forces at 60 deg:
     * f_spoke = f_ring (with signs), i.e. spokes -1, ring +1 */
    double f0[12];
    for (size_t c = 0; c < nc; ++c) {
        size_t i, j;
        odhs_network_get_contact(net, c, &i, &j, NULL);
        f0[c] = i == 0 ? -1.0 : 1.0;
    }
    check_singular(net, f0, "hexagonal patch");
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* NULL arguments, empty network                                             */
/* ------------------------------------------------------------------------ */

START_TEST(test_null_and_empty)
{
    sv_case c = sv_random_case(2, 40, 13, 0);
    odhs_solver *cg = sv_by_name("cg");
    double *b = malloc(c.nc * sizeof *b), *x = calloc(c.nc, sizeof *x);
    ck_assert(b && x);
    for (size_t k = 0; k < c.nc; ++k) b[k] = 1.0;
    ck_assert_int_eq(odhs_solver_solve(NULL, c.net, b, x), ODHS_E_NULL);
    ck_assert_int_eq(odhs_solver_solve(cg, NULL, b, x), ODHS_E_NULL);
    ck_assert_int_eq(odhs_solver_solve(cg, c.net, NULL, x), ODHS_E_NULL);
    ck_assert_int_eq(odhs_solver_solve(cg, c.net, b, NULL), ODHS_E_NULL);
    ck_assert_str_ne(odhs_solver_errmsg(cg), "");
    ck_assert_int_eq(odhs_solver_set_param(NULL, "tol", 1e-3), ODHS_E_NULL);
    ck_assert_int_eq(odhs_solver_set_check_tolerance(NULL, 1e-3), ODHS_E_NULL);
    double v;
    ck_assert_int_eq(odhs_solver_get_stat(NULL, "residual", &v), ODHS_E_NULL);
    ck_assert_str_eq(odhs_solver_errmsg(NULL), "");
    ck_assert_ptr_nonnull(odhs_solver_name(NULL));
    odhs_solver_destroy(NULL);
    /* the failed calls did not count as solves; a good one still works */
    ck_assert_int_eq(odhs_solver_solve(cg, c.net, b, x), ODHS_OK);
    ck_assert(sv_residual(c.net, x, b) < 1e-11);
    /* an empty network: nothing to solve */
    odhs_network *empty = NULL;
    ck_assert_int_eq(odhs_network_create(c.sys, &empty), ODHS_OK);
    odhs_solver *dn = sv_by_name("dense");
    ck_assert_int_eq(odhs_solver_solve(dn, empty, b, x), ODHS_OK);
    ck_assert_int_eq(odhs_solver_solve(cg, empty, b, x), ODHS_OK);
    odhs_network_destroy(empty);
    free(b);
    free(x);
    odhs_solver_destroy(cg);
    odhs_solver_destroy(dn);
    sv_case_free(&c);
}
END_TEST

Suite *make_solver_suite(void)
{
    Suite *s = suite_create("solver");
    TCase *tc = tcase_create("agreement");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_agree_2d_tree);
    tcase_add_test(tc, test_agree_2d_cycles);
    tcase_add_test(tc, test_agree_3d);
    tcase_add_test(tc, test_user_minimal_table);
    tcase_add_test(tc, test_setup_on_change);
    tcase_add_test(tc, test_recreated_network);
    tcase_add_test(tc, test_recreated_network_relaxed);
    suite_add_tcase(s, tc);

    tc = tcase_create("interface");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_wrapper_checks);
    tcase_add_test(tc, test_malformed_tables);
    tcase_add_test(tc, test_create_by_name);
    tcase_add_test(tc, test_cg_params_stats);
    tcase_add_test(tc, test_residual_stat_after_failure);
    tcase_add_test(tc, test_dense_rcond);
    tcase_add_test(tc, test_null_and_empty);
    suite_add_tcase(s, tc);

    tc = tcase_create("singular");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_singular_ring);
    tcase_add_test(tc, test_singular_square_lattice);
    tcase_add_test(tc, test_singular_hex_patch);
    suite_add_tcase(s, tc);
    return s;
}
