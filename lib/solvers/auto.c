/*
 * libodhs - "auto" solver: picks a built-in backend from the network size
 * and what this build has, and falls back when it fails.
 *
 * Choice (the "primary" for a network of Nc contacts):
 *   Nc <= "dense_max"                       dense (LAPACK Cholesky)
 *   else, with SuiteSparse                  cholmod-pcg ("prefer" = 0, the
 *                                           default) or cholmod ("prefer" = 1)
 *   else, without SuiteSparse               cg
 * dense_max defaults to 16 with SuiteSparse (cholmod-pcg is faster from a few
 * dozen contacts on; docs/results/bench_solvers.txt) and to 400 without
 * (dense is slower than CG there, but it is direct: accurate close to
 * jamming).
 *
 * Fallback chain, tried in order while a backend reports ODHS_E_SINGULAR
 * (non-positive or tiny pivot, reciprocal condition below its min_rcond,
 * backward error above the check tolerance), ODHS_E_NOCONV or ODHS_E_NOMEM:
 *   primary -> spqr (SuiteSparse; least squares on S^T, rank-revealing)
 *           -> dense (without SuiteSparse, when the primary was cg and
 *              Nc <= "dense_fallback_max")
 *           -> minimum-norm least squares ("lsq"): when the network is
 *              rank deficient (hyperstatic: S^T has a null space, N is
 *              singular), the forces x minimising |S^T x - g| are not unique;
 *              auto returns the one of least norm, x = (S^T)^+ g (= N^+ b for
 *              b = S g), from a truncated SVD ("lsq-svd", Nc <=
 *              "lsq_dense_max"; for N x = b the truncated eigendecomposition
 *              of the symmetric N since 0.2.17) or, above it, from CG started at zero:
 *              first "lsq-pcg" with SuiteSparse (since 0.2.16; preconditioned
 *              by a factor of N + beta I, which keeps the iterates in
 *              range(N): lsq_pcg.c), then "lsq-cg" (the Jacobi
 *              preconditioner of N = S S^T is a multiple of the identity,
 *              diag N = 2, so the iterates stay in range(N) and converge to
 *              the minimum-norm solution of a consistent system). lsq-pcg
 *              stalls fast on an inconsistent system (b not in range(N)), and
 *              lsq-cg, which would grind through 10 Nc + 100 iterations
 *              there (88 % of a batched run's CPU time at 2D N = 16 384 that
 *              met two such solves), is then skipped.
 *              The SVD rank is SuiteSparseQR's when it ran, else the number
 *              of singular values above "lsq_rcond" times the largest (of S^T
 *              on the least-squares route; of N, with lsq_rcond squared but
 *              at least 1e-13, on the N x = b route).
 * After a fallback the backend that answered is used first for the next
 * "retry_after" solves (default 20; the state that made Cholesky fail is
 * usually still there), then the primary is tried again. A least-squares
 * backend (lsq-svd, lsq-cg) is kept only for "retry_after_lsq" solves
 * (since 0.2.13, default 0): a rank-deficient network is usually one step's
 * state, and an SVD costs ~100 Cholesky solves (fixed-pressure shear, 2D
 * N = 256, p = 1e4: 84 solves of 5 600 events went to lsq-svd with 20, a
 * third of the CPU time; 26-28 s against 38-48 s per 0.03 strain with 0).
 *
 * Visibility: odhs_solver_backend_name gives the backend that produced the
 * last solution and a description of the last fallback; statistics
 * "fallbacks" (failed attempts that led to another backend), "fallback_solves"
 * (solves answered by a backend other than the primary), "rank_deficient"
 * (solves answered by lsq), "backend" and "primary" (codes, see
 * odhs_solver_type_auto in solver.h), "last_failure" (status of the last
 * failed attempt, 0 if none), and every statistic of the backend that
 * answered last (e.g. "iterations", "rcond", "rank" after a QR fallback).
 *
 * auto declares itself ODHS_SOLVER_ITERATIVE: every inner backend runs behind
 * its own library wrapper, which checks its result and does the iterative
 * refinement of direct backends, so the outer wrapper must not refine again.
 */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "solvers/solvers.h"

enum { B_CG, B_DENSE, B_CHOLMOD, B_CHOLMOD_PCG, B_SPQR, B_LSQ_SVD, B_LSQ_CG, B_LSQ_PCG, B_COUNT };

/* the least-squares routes (the answer on rank-deficient networks) */
static int is_lsq(int b) { return b == B_LSQ_SVD || b == B_LSQ_CG || b == B_LSQ_PCG; }
static const char *const bname[B_COUNT] = {"cg",      "dense",  "cholmod", "cholmod-pcg",
                                           "spqr",    "lsq-svd", "lsq-cg", "lsq-pcg"};
#define NHANDLES 5 /* B_CG..B_SPQR have handles; lsq-cg and lsq-pcg have their own */

typedef struct {
    odhs_solver *h[NHANDLES];
    odhs_solver *lsqcg;
    odhs_solver *lsqpcg;  /* SuiteSparse builds (since 0.2.16) */
    int have_ss;          /* SuiteSparse backends usable (build and "suitesparse") */
    /* parameters */
    double dense_max, dense_fallback_max, lsq_dense_max, lsq_rcond, check_tol;
    double tol;           /* "tol" of the iterative backends (cg, cholmod-pcg); 0: their own */
    double update_max;    /* "update_max" of cholmod-pcg */
    double supernodal;    /* "supernodal" of cholmod-pcg (since 0.2.20; default -1 since 0.2.21) */
    double supernodal_switch; /* of cholmod-pcg (since 0.2.21); NAN: the backend's default */
    double openmp;        /* "openmp" of cholmod and cholmod-pcg (since 0.2.21) */
    double ordering;      /* "ordering" of cholmod-pcg (since 0.2.23); NAN: the backend's default */
    double ordering_reuse; /* "ordering_reuse" of cholmod-pcg (since 0.2.23); NAN: the backend's default */
    int prefer, retry_after, retry_after_lsq;
    /* state */
    int sticky_backend;   /* backend to try first, -1: none */
    int sticky_left;
    int last, primary;    /* backend codes, -1 before the first solve */
    double fallbacks, fallback_solves, rank_deficient, last_failure, last_rank;
    double *x0, *A, *sv, *U, *VT, *rhs, *tmp; /* guess copy, SVD work */
    size_t x0cap, Acap, svcap, Ucap, VTcap, rcap, tcap;
    char why[ODHS_ERRMSG_LEN];
} auto_state;

static int auto_create(void **state)
{
    auto_state *s = odhs__calloc(1, sizeof *s);
    if (!s) return ODHS_E_NOMEM;
#ifdef ODHS_HAVE_SUITESPARSE
    s->have_ss = 1;
#else
    s->have_ss = 0;
#endif
    s->dense_max = -1; /* automatic */
    s->dense_fallback_max = 4000;
    s->lsq_dense_max = 600;
    s->lsq_rcond = 1e-9;
    s->check_tol = 1e-6;
    s->prefer = 0;
    s->retry_after = 20;
    s->retry_after_lsq = 0;
    s->update_max = 0.125;
    s->supernodal = -1.0;
    s->supernodal_switch = NAN;
    s->ordering = NAN;
    s->ordering_reuse = NAN;
    s->sticky_backend = -1;
    s->last = s->primary = -1;
    *state = s;
    return ODHS_OK;
}

static void auto_destroy(void *state)
{
    auto_state *s = state;
    if (!s) return;
    for (int k = 0; k < NHANDLES; ++k) odhs_solver_destroy(s->h[k]);
    odhs_solver_destroy(s->lsqcg);
    odhs_solver_destroy(s->lsqpcg);
    odhs__free(s->x0);
    odhs__free(s->A);
    odhs__free(s->sv);
    odhs__free(s->U);
    odhs__free(s->VT);
    odhs__free(s->rhs);
    odhs__free(s->tmp);
    odhs__free(s);
}

static int auto_set_param(void *state, const char *key, double v)
{
    auto_state *s = state;
    if (!strcmp(key, "dense_max") && v >= -1.0) s->dense_max = v < 0.0 ? -1.0 : floor(v);
    else if (!strcmp(key, "dense_fallback_max") && v >= 0.0 && v <= 46340.0) s->dense_fallback_max = floor(v);
    else if (!strcmp(key, "lsq_dense_max") && v >= 0.0 && v <= 46340.0) s->lsq_dense_max = floor(v);
    else if (!strcmp(key, "lsq_rcond") && v > 0.0 && v < 1.0) s->lsq_rcond = v;
    else if (!strcmp(key, "check_tol") && v > 0.0) {
        s->check_tol = v;
        for (int k = 0; k < NHANDLES; ++k)
            if (s->h[k]) odhs_solver_set_check_tolerance(s->h[k], v);
        if (s->lsqcg) odhs_solver_set_check_tolerance(s->lsqcg, v);
        if (s->lsqpcg) odhs_solver_set_check_tolerance(s->lsqpcg, v);
    } else if (!strcmp(key, "tol") && v > 0.0 && v < 1.0) {
        s->tol = v;
        for (int k = 0; k < NHANDLES; ++k)
            if (s->h[k] && (k == B_CG || k == B_CHOLMOD_PCG)) odhs_solver_set_param(s->h[k], "tol", v);
    } else if (!strcmp(key, "update_max") && v >= 0.0 && v <= 1.0) {
        s->update_max = v;
        if (s->h[B_CHOLMOD_PCG]) odhs_solver_set_param(s->h[B_CHOLMOD_PCG], "update_max", v);
    } else if (!strcmp(key, "supernodal") && (v == -1.0 || v == 0.0 || v == 1.0)) {
        s->supernodal = v;
        if (s->h[B_CHOLMOD_PCG]) odhs_solver_set_param(s->h[B_CHOLMOD_PCG], "supernodal", v);
    } else if (!strcmp(key, "supernodal_switch") && v >= 0.0 && v <= 1e300) {
        s->supernodal_switch = v;
        if (s->h[B_CHOLMOD_PCG]) odhs_solver_set_param(s->h[B_CHOLMOD_PCG], "supernodal_switch", v);
    } else if (!strcmp(key, "ordering") && (v == -1.0 || v == 0.0 || v == 1.0)) {
        s->ordering = v;
        if (s->h[B_CHOLMOD_PCG]) odhs_solver_set_param(s->h[B_CHOLMOD_PCG], "ordering", v);
    } else if (!strcmp(key, "ordering_reuse") && (v == -1.0 || v == 0.0 || (v >= 1.0 && v <= 1e300))) {
        s->ordering_reuse = v;
        if (s->h[B_CHOLMOD_PCG]) odhs_solver_set_param(s->h[B_CHOLMOD_PCG], "ordering_reuse", v);
    } else if (!strcmp(key, "openmp") && (v == 0.0 || v == 1.0)) {
        s->openmp = v;
        if (s->h[B_CHOLMOD]) odhs_solver_set_param(s->h[B_CHOLMOD], "openmp", v);
        if (s->h[B_CHOLMOD_PCG]) odhs_solver_set_param(s->h[B_CHOLMOD_PCG], "openmp", v);
    } else if (!strcmp(key, "prefer") && (v == 0.0 || v == 1.0)) s->prefer = (int)v;
    else if (!strcmp(key, "retry_after") && v >= 0.0 && v <= 1e9) {
        s->retry_after = (int)v;
        if (s->sticky_left > s->retry_after) s->sticky_left = s->retry_after;
    } else if (!strcmp(key, "retry_after_lsq") && v >= 0.0 && v <= 1e9) {
        s->retry_after_lsq = (int)v;
        if (is_lsq(s->sticky_backend) && s->sticky_left > s->retry_after_lsq)
            s->sticky_left = s->retry_after_lsq;
    }
    else if (!strcmp(key, "suitesparse") && (v == 0.0 || v == 1.0)) {
#ifdef ODHS_HAVE_SUITESPARSE
        s->have_ss = (int)v;
#else
        if (v == 1.0) return ODHS_E_NOTINSTALLED;
#endif
        s->sticky_backend = -1;
    } else return ODHS_E_INVALID;
    return ODHS_OK;
}

static const odhs_solver_type *type_of(int b)
{
    switch (b) {
    case B_CG: return &odhs_solver_type_cg;
    case B_DENSE: return &odhs_solver_type_dense;
#ifdef ODHS_HAVE_SUITESPARSE
    case B_CHOLMOD: return &odhs_solver_type_cholmod;
    case B_CHOLMOD_PCG: return &odhs_solver_type_cholmod_pcg;
    case B_SPQR: return &odhs_solver_type_spqr;
#endif
    default: return NULL;
    }
}

static int handle(auto_state *s, int b, odhs_solver **out)
{
    if (!s->h[b]) {
        const odhs_solver_type *t = type_of(b);
        if (!t) return ODHS_E_NOTINSTALLED;
        int st = odhs_solver_create(t, &s->h[b]);
        if (st) return st;
        odhs_solver_set_check_tolerance(s->h[b], s->check_tol);
        if (s->tol > 0.0 && (b == B_CG || b == B_CHOLMOD_PCG)) odhs_solver_set_param(s->h[b], "tol", s->tol);
        if (b == B_CHOLMOD_PCG && s->update_max != 0.125) odhs_solver_set_param(s->h[b], "update_max", s->update_max);
        if (b == B_CHOLMOD_PCG && s->supernodal != -1.0) odhs_solver_set_param(s->h[b], "supernodal", s->supernodal);
        if (b == B_CHOLMOD_PCG && !isnan(s->supernodal_switch))
            odhs_solver_set_param(s->h[b], "supernodal_switch", s->supernodal_switch);
        if (b == B_CHOLMOD_PCG && !isnan(s->ordering)) odhs_solver_set_param(s->h[b], "ordering", s->ordering);
        if (b == B_CHOLMOD_PCG && !isnan(s->ordering_reuse))
            odhs_solver_set_param(s->h[b], "ordering_reuse", s->ordering_reuse);
        if ((b == B_CHOLMOD || b == B_CHOLMOD_PCG) && s->openmp != 0.0) odhs_solver_set_param(s->h[b], "openmp", s->openmp);
    }
    *out = s->h[b];
    return ODHS_OK;
}

/* The operator changed (the outer wrapper saw it): every inner handle sets up
 * again at its next solve (cholmod-pcg then updates its factor). */
static int auto_setup(void *state, const odhs_network *net)
{
    auto_state *s = state;
    (void)net;
    for (int k = 0; k < NHANDLES; ++k) odhs__solver_invalidate(s->h[k]);
    odhs__solver_invalidate(s->lsqcg);
    odhs__solver_invalidate(s->lsqpcg);
    return ODHS_OK;
}

static int grow(double **p, size_t *cap, size_t n)
{
    if (*cap >= n) return ODHS_OK;
    double *q = odhs__realloc(*p, (n ? n : 1) * sizeof *q);
    if (!q) return ODHS_E_NOMEM;
    *p = q;
    *cap = n;
    return ODHS_OK;
}

/* x = A^+ y by a truncated SVD of the m x n column-major A (overwritten):
 * rank r if r >= 0, else singular values above rc * s_max. */
static int pinv_solve(auto_state *s, double *A, size_t m, size_t n, const double *y, double *x, long r, double rc)
{
    size_t k = m < n ? m : n;
    int st;
    if ((st = grow(&s->sv, &s->svcap, k + 1)) || (st = grow(&s->U, &s->Ucap, m * k)) ||
        (st = grow(&s->VT, &s->VTcap, k * n)) || (st = grow(&s->tmp, &s->tcap, k + 1)))
        return st;
    lapack_int info = LAPACKE_dgesvd(LAPACK_COL_MAJOR, 'S', 'S', (lapack_int)m, (lapack_int)n, A, (lapack_int)m,
                                     s->sv, s->U, (lapack_int)m, s->VT, (lapack_int)k, s->tmp);
    if (info != 0) return ODHS_E_INTERNAL;
    size_t rank = 0;
    if (r >= 0) rank = (size_t)r < k ? (size_t)r : k;
    else
        while (rank < k && s->sv[rank] > rc * s->sv[0]) rank++;
    /* x = V diag(1/sv) U^T y over the first rank triplets */
    for (size_t q = 0; q < rank; ++q) {
        double c = 0.0;
        for (size_t i = 0; i < m; ++i) c += s->U[q * m + i] * y[i];
        s->tmp[q] = c / s->sv[q];
    }
    for (size_t j = 0; j < n; ++j) {
        double v = 0.0;
        for (size_t q = 0; q < rank; ++q) v += s->VT[j * k + q] * s->tmp[q];
        x[j] = v;
    }
    s->last_rank = (double)rank;
    return ODHS_OK;
}

/* x = A^+ y for the symmetric positive semidefinite n x n A (overwritten)
 * from its eigendecomposition (LAPACK dsyevd, divide and conquer): rank r
 * if r >= 0, else eigenvalues above rc * lambda_max. The N x = b route of
 * the least-squares fallback: N is symmetric, and the eigendecomposition
 * costs a fifth of the SVD at Nc = 500 (0.047 against 0.258 s; the SVD's
 * rotations were 63 % of a batched run's CPU time at fixed pressure, 2D
 * N = 256, p = 100). ODHS_E_INTERNAL when LAPACK fails. */
static int pinv_sym_solve(auto_state *s, double *A, size_t n, const double *y, double *x, long r, double rc)
{
    int st;
    if ((st = grow(&s->sv, &s->svcap, n + 1)) || (st = grow(&s->tmp, &s->tcap, n + 1))) return st;
    lapack_int info = LAPACKE_dsyevd(LAPACK_COL_MAJOR, 'V', 'U', (lapack_int)n, A, (lapack_int)n, s->sv);
    if (info != 0) return ODHS_E_INTERNAL;
    /* eigenvalues ascending: the rank largest are the last ones */
    size_t rank = 0;
    const double lmax = n ? s->sv[n - 1] : 0.0;
    if (r >= 0) rank = (size_t)r < n ? (size_t)r : n;
    else
        while (rank < n && s->sv[n - 1 - rank] > rc * lmax) rank++;
    /* a rank from outside (SuiteSparseQR's) never takes in a round-off
     * eigenvalue at or below zero */
    while (rank > 0 && !(s->sv[n - rank] > 0.0)) rank--;
    for (size_t q = n - rank; q < n; ++q) {
        double c = 0.0;
        const double *v = A + q * n;
        for (size_t i = 0; i < n; ++i) c += v[i] * y[i];
        s->tmp[q] = c / s->sv[q];
    }
    for (size_t j = 0; j < n; ++j) x[j] = 0.0;
    for (size_t q = n - rank; q < n; ++q) {
        const double *v = A + q * n, c = s->tmp[q];
        for (size_t j = 0; j < n; ++j) x[j] += c * v[j];
    }
    s->last_rank = (double)rank;
    return ODHS_OK;
}

/* N, dense and column-major, into s->A (nc x nc, then nd entries of work) */
static void fill_N(auto_state *s, const odhs_network *net)
{
    size_t nc = net->nc;
    double *w = s->A + nc * nc;
    memset(s->rhs, 0, nc * sizeof *s->rhs);
    for (size_t c = 0; c < nc; ++c) {
        s->rhs[c] = 1.0;
        odhs__net_N(net, s->rhs, s->A + c * nc, w);
        s->rhs[c] = 0.0;
    }
}

/* minimum-norm least squares, dense SVD route (g given: on S^T; else on N,
 * from N's eigendecomposition, with the SVD when that fails) */
static int lsq_svd(auto_state *s, const odhs_network *net, const double *b, const double *g, double *x, long rank)
{
    size_t nc = net->nc, nd = net->n * (size_t)net->dim;
    int st;
    if (g) {
        if ((st = grow(&s->A, &s->Acap, nd * nc)) || (st = grow(&s->rhs, &s->rcap, nc))) return st;
        memset(s->rhs, 0, nc * sizeof *s->rhs);
        for (size_t c = 0; c < nc; ++c) {
            s->rhs[c] = 1.0;
            odhs__net_ST(net, s->rhs, s->A + c * nd);
            s->rhs[c] = 0.0;
        }
        return pinv_solve(s, s->A, nd, nc, g, x, rank, s->lsq_rcond);
    }
    if ((st = grow(&s->A, &s->Acap, nc * nc + nd)) || (st = grow(&s->rhs, &s->rcap, nc))) return st;
    double rc = fmax(s->lsq_rcond * s->lsq_rcond, 1e-13);
    fill_N(s, net);
    st = pinv_sym_solve(s, s->A, nc, b, x, rank, rc);
    if (st != ODHS_E_INTERNAL) return st;
    fill_N(s, net); /* dsyevd failed on it: the SVD takes a fresh copy */
    return pinv_solve(s, s->A, nc, nc, b, x, rank, rc);
}

static int primary_for(const auto_state *s, size_t nc)
{
    double dmax = s->dense_max >= 0.0 ? s->dense_max : (s->have_ss ? 16.0 : 400.0);
    if ((double)nc <= dmax) return B_DENSE;
    if (s->have_ss) return s->prefer ? B_CHOLMOD : B_CHOLMOD_PCG;
    return B_CG;
}

/* one attempt with backend b; 0 or an error status */
static int attempt(auto_state *s, int b, const odhs_network *net, const double *b_rhs, const double *g, double *x,
                   long rank)
{
    size_t nc = net->nc;
    if (b == B_LSQ_SVD) return lsq_svd(s, net, b_rhs, g, x, rank);
    odhs_solver *h;
    if (b == B_LSQ_CG) {
        if (!s->lsqcg) {
            int st = odhs_solver_create(&odhs_solver_type_cg, &s->lsqcg);
            if (st) return st;
            odhs_solver_set_check_tolerance(s->lsqcg, s->check_tol);
            odhs_solver_set_param(s->lsqcg, "maxiter", 0.0);
        }
        h = s->lsqcg;
        memset(x, 0, nc * sizeof *x); /* from zero: the minimum-norm solution */
    } else if (b == B_LSQ_PCG) {
#ifdef ODHS_HAVE_SUITESPARSE
        if (!s->lsqpcg) {
            int st = odhs_solver_create(&odhs__solver_type_lsq_pcg, &s->lsqpcg);
            if (st) return st;
            odhs_solver_set_check_tolerance(s->lsqpcg, s->check_tol);
        }
        h = s->lsqpcg; /* starts from zero itself: the minimum-norm solution */
#else
        return ODHS_E_NOTINSTALLED;
#endif
    } else {
        int st = handle(s, b, &h);
        if (st) return st;
    }
    return g ? odhs_solver_solve_ls(h, net, g, x) : odhs__solver_solve(h, net, b_rhs, x, 1);
}

static int fallback_ok(int st) { return st == ODHS_E_SINGULAR || st == ODHS_E_NOCONV || st == ODHS_E_NOMEM; }

static int auto_run(auto_state *s, const odhs_network *net, const double *b, const double *g, double *x)
{
    size_t nc = net->nc;
    int st = grow(&s->x0, &s->x0cap, nc);
    if (st) return st;
    memcpy(s->x0, x, nc * sizeof *x);
    int prim = primary_for(s, nc);
    s->primary = prim;
    /* the chain: sticky backend first, then the primary and its fallbacks */
    int chain[7], n = 0;
    if (s->sticky_backend >= 0 && s->sticky_left > 0) {
        chain[n++] = s->sticky_backend;
        s->sticky_left--;
    }
    chain[n++] = prim;
    if (s->have_ss) chain[n++] = B_SPQR;
    else if (prim != B_DENSE && (double)nc <= s->dense_fallback_max) chain[n++] = B_DENSE;
    if ((double)nc <= s->lsq_dense_max) chain[n++] = B_LSQ_SVD;
    else {
        /* with SuiteSparse the preconditioned route first: plain CG from
         * zero needs ~sqrt(cond N) iterations, tens of thousands at large N */
        if (s->have_ss) chain[n++] = B_LSQ_PCG;
        chain[n++] = B_LSQ_CG;
    }
    int tried[B_COUNT] = {0}, failures = 0;
    long rank = -1;
    char note[ODHS_ERRMSG_LEN] = "";
    for (int k = 0; k < n; ++k) {
        int b_ = chain[k];
        if (tried[b_]) continue;
        /* least squares is only for rank-deficient networks, or when every
         * Cholesky/QR route failed */
        tried[b_] = 1;
        memcpy(x, s->x0, nc * sizeof *x);
        st = attempt(s, b_, net, b, g, x, rank);
        if (b_ == B_SPQR && s->h[B_SPQR]) {
            double rk = NAN;
            if (odhs_solver_get_stat(s->h[B_SPQR], "rank", &rk) == ODHS_OK && isfinite(rk) && rk < (double)nc)
                rank = (long)rk;
        }
        if (st == ODHS_OK) {
            s->last = b_;
            if (failures) {
                s->fallbacks += failures;
                size_t len = strlen(note);
                snprintf(note + len, sizeof note - len, " -> %s", bname[b_]);
                memcpy(s->why, note, sizeof note);
                s->sticky_backend = b_;
                s->sticky_left = is_lsq(b_) ? s->retry_after_lsq : s->retry_after;
            } else if (b_ != prim) {
                snprintf(s->why, sizeof s->why, "%s (kept after an earlier fallback)", bname[b_]);
            } else {
                s->why[0] = '\0';
                if (s->sticky_backend == b_) s->sticky_backend = -1;
            }
            if (b_ != prim) s->fallback_solves += 1.0;
            if (is_lsq(b_)) s->rank_deficient += 1.0;
            else s->last_rank = NAN;
            if (b_ == B_LSQ_CG || b_ == B_LSQ_PCG) s->last_rank = rank >= 0 ? (double)rank : NAN; /* QR's, if it ran */
            return ODHS_OK;
        }
        s->last_failure = st;
        failures++;
        /* lsq-pcg stalls only on an inconsistent system (no solution: b has
         * a part in the null space of N) or a hopeless one; plain CG from
         * zero would stall there too, after up to 10 Nc + 100 iterations */
        if (b_ == B_LSQ_PCG && st == ODHS_E_NOCONV) tried[B_LSQ_CG] = 1;
        size_t len = strlen(note);
        const char *em = (b_ == B_LSQ_SVD) ? odhs_strerror(st)
                         : b_ == B_LSQ_CG  ? odhs_solver_errmsg(s->lsqcg)
                         : b_ == B_LSQ_PCG ? odhs_solver_errmsg(s->lsqpcg)
                                           : odhs_solver_errmsg(s->h[b_]);
        snprintf(note + len, sizeof note - len, "%s%s failed (%s)", len ? " -> " : "", bname[b_],
                 em && em[0] ? em : odhs_strerror(st));
        if (!fallback_ok(st)) break;
    }
    s->fallbacks += failures > 0 ? failures - 1 : 0;
    memcpy(s->why, note, sizeof note);
    s->sticky_backend = -1;
    return st ? st : ODHS_E_INTERNAL;
}

static int auto_solve(void *state, const odhs_network *net, const double *b, double *x)
{
    return auto_run(state, net, b, NULL, x);
}

static int auto_solve_ls(void *state, const odhs_network *net, const double *g, double *x)
{
    return auto_run(state, net, NULL, g, x);
}

static int auto_get_stat(void *state, const char *key, double *v)
{
    auto_state *s = state;
    if (!strcmp(key, "fallbacks")) *v = s->fallbacks;
    else if (!strcmp(key, "fallback_solves")) *v = s->fallback_solves;
    else if (!strcmp(key, "rank_deficient")) *v = s->rank_deficient;
    else if (!strcmp(key, "backend")) *v = s->last;
    else if (!strcmp(key, "primary")) *v = s->primary;
    else if (!strcmp(key, "last_failure")) *v = s->last_failure;
    else if (!strcmp(key, "suitesparse")) *v = s->have_ss;
    else if (!strcmp(key, "tol")) *v = s->tol > 0.0 ? s->tol : 1e-12; /* the iterative backends' default */
    else if (!strcmp(key, "update_max")) *v = s->update_max;
    else if (is_lsq(s->last)) {
        if (!strcmp(key, "rank")) *v = s->last_rank;
        else if (s->last == B_LSQ_CG) return odhs_solver_get_stat(s->lsqcg, key, v);
        else if (s->last == B_LSQ_PCG) return odhs_solver_get_stat(s->lsqpcg, key, v);
        else if (!strcmp(key, "iterations")) *v = 0.0;
        else return ODHS_E_INVALID;
    } else if (s->last >= 0 && s->h[s->last]) {
        /* quiet lookup: the inner handle's message is not the user's */
        if (!s->h[s->last]->type->get_stat) return ODHS_E_INVALID;
        if (!strcmp(key, "residual") || !strcmp(key, "backward_error") || !strcmp(key, "solves"))
            return ODHS_E_INVALID;
        return s->h[s->last]->type->get_stat(s->h[s->last]->state, key, v);
    } else return ODHS_E_INVALID;
    return ODHS_OK;
}

const odhs_solver_type odhs_solver_type_auto = {
    .version = ODHS_SOLVER_TYPE_VERSION,
    .name = "auto",
    .flags = ODHS_SOLVER_ITERATIVE | ODHS_SOLVER_USES_GUESS | ODHS_SOLVER_LEAST_SQUARES,
    .create = auto_create,
    .destroy = auto_destroy,
    .setup = auto_setup,
    .solve = auto_solve,
    .set_param = auto_set_param,
    .get_stat = auto_get_stat,
    .solve_ls = auto_solve_ls,
};

int odhs_solver_backend_name(const odhs_solver *s, const char **name, const char **why)
{
    if (!s) return ODHS_E_NULL;
    if (!name) return odhs__err(((odhs_solver *)s)->errmsg, ODHS_E_NULL, "name pointer is NULL");
    if (s->type == &odhs_solver_type_auto) {
        const auto_state *a = s->state;
        *name = a->last >= 0 ? bname[a->last] : "auto";
        if (why) *why = a->why;
    } else {
        *name = s->type->name;
        if (why) *why = "";
    }
    return ODHS_OK;
}
