/*
 * libodhs - SuiteSparseQR backend: sparse multifrontal QR of A = S^T.
 *
 * A = S^T is (N*dim) x Nc, one column per contact holding -n_c on particle
 * i's rows and +n_c on particle j's (always all 2*dim entries, zeros
 * included, so that the pattern depends only on the contact pairs).
 * SuiteSparseQR factorizes A E = Q R (E a fill-reducing column permutation,
 * Q in Householder form, R upper triangular when A has full column rank).
 *
 *  - solve_ls (least squares, min |S^T x - g|): x = E R^{-1} (Q^T g)_{1..Nc}.
 *    Q and R only: the normal equations are never formed, so the error grows
 *    with cond(S^T) and not with cond(N) = cond(S^T)^2.
 *  - solve (N x = b, b in contact space): N = A^T A = E R^T R E^T, so
 *    x = E R^{-1} R^{-T} E^T b: two triangular solves (SPQR_RTX_EQUALS_ETB,
 *    then SPQR_RETX_EQUALS_B). Q is not touched.
 *
 * Rank: SuiteSparseQR's rank-revealing factorization (Heath's method: a
 * column whose remaining 2-norm is <= tol is declared dead) estimates the
 * numerical rank of S^T. Below Nc, S^T has a null space (self-stresses of a
 * hyperstatic patch) and N is singular: setup returns ODHS_E_SINGULAR. The
 * statistics "rank", "nc" and "rank_deficiency" are recorded even then.
 *
 * Symbolic analysis (ordering, elimination tree, front sizes) depends only
 * on the pattern, that is on the list of contact pairs: it is kept while the
 * pairs are unchanged and only the numeric factorization is redone
 * (SuiteSparseQR_C_symbolic once, SuiteSparseQR_C_numeric per setup). This
 * route does not exploit singletons (SuiteSparseQR_C_factorize would; here
 * they come only from particles with a single contact). A rank-deficient
 * factorization is discarded whole (see spqr_setup), so the setup after a
 * singular one analyses again.
 *
 * Parameters: "tol" (rank tolerance: <= -2 SuiteSparseQR's default
 * 20 (m+n) eps max_j |A_j|, the default; in (-2,0) no rank detection; >= 0
 * that absolute column-norm threshold), "ordering" (SPQR_ORDERING_*: 0 fixed,
 * 1 natural, 2 COLAMD, 4 CHOLMOD, 5 AMD, 6 METIS, 7 default (the default),
 * 8 best, 9 best of COLAMD/AMD). Both take effect at the next setup, i.e.
 * the next solve on a changed network; the current factor stays in use.
 * Statistics: "rank", "nc", "rank_deficiency", "tol_used", "symbolic" and
 * "numeric" (counts of analyses / factorizations), "ordering_used",
 * "iterations" (0).
 *
 * Each state owns its own cholmod_common, started with printing off; errors
 * are read from its status, never printed.
 */
#ifdef ODHS_HAVE_SUITESPARSE

#include <string.h>

#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#include <SuiteSparseQR_C.h>
#pragma GCC diagnostic pop

#include "solvers/solvers.h"

typedef struct {
    cholmod_common cc;
    int started;
    SuiteSparseQR_C_factorization *qr; /* symbolic (+ numeric when factored) */
    cholmod_sparse *A;                 /* S^T, pattern of the analysis */
    /* the pattern the symbolic analysis is for */
    size_t n, nc;
    int dim;
    size_t *pci, *pcj;
    size_t pcap;
    int have_symbolic;
    int factored;
    /* work vectors wrapped as cholmod_dense (m = n*dim entries) */
    double *w;
    size_t wcap;
    /* parameters */
    double tol;
    int ordering;
    /* statistics */
    double rank, nc_stat, tol_used, nsym, nnum, ord_used;
} spqr_state;

static int cc_status(const spqr_state *s)
{
    return s->cc.status == CHOLMOD_OUT_OF_MEMORY ? ODHS_E_NOMEM : ODHS_E_INTERNAL;
}

static void drop_factor(spqr_state *s)
{
    if (s->qr) SuiteSparseQR_C_free(&s->qr, &s->cc);
    s->qr = NULL;
    if (s->A) cholmod_l_free_sparse(&s->A, &s->cc);
    s->A = NULL;
    s->have_symbolic = 0;
    s->factored = 0;
}

static int spqr_create(void **state)
{
    spqr_state *s = odhs__calloc(1, sizeof *s);
    if (!s) return ODHS_E_NOMEM;
    if (!cholmod_l_start(&s->cc)) {
        odhs__free(s);
        return ODHS_E_INTERNAL;
    }
    s->started = 1;
    s->cc.print = 0;            /* quiet: statuses only */
    s->cc.error_handler = NULL;
    s->tol = SPQR_DEFAULT_TOL;
    s->ordering = SPQR_ORDERING_DEFAULT;
    s->rank = s->nc_stat = NAN;
    s->tol_used = NAN;
    s->ord_used = NAN;
    *state = s;
    return ODHS_OK;
}

static void spqr_destroy(void *state)
{
    spqr_state *s = state;
    if (!s) return;
    drop_factor(s);
    if (s->started) cholmod_l_finish(&s->cc);
    odhs__free(s->pci);
    odhs__free(s->pcj);
    odhs__free(s->w);
    odhs__free(s);
}

static int spqr_set_param(void *state, const char *key, double v)
{
    spqr_state *s = state;
    if (!strcmp(key, "tol")) {
        /* any finite value has a meaning (see the top of the file) */
        s->tol = v;
    } else if (!strcmp(key, "ordering")) {
        if (!(v >= 0.0 && v <= 9.0) || v != floor(v) || v == SPQR_ORDERING_GIVEN) return ODHS_E_INVALID;
        /* the next setup analyses again; the current factor stays usable */
        if ((int)v != s->ordering) s->have_symbolic = 0;
        s->ordering = (int)v;
    } else {
        return ODHS_E_INVALID;
    }
    return ODHS_OK;
}

static int ensure_work(spqr_state *s, size_t need)
{
    if (s->wcap >= need) return ODHS_OK;
    double *w = odhs__realloc(s->w, need * sizeof *w);
    if (!w) return ODHS_E_NOMEM;
    s->w = w;
    s->wcap = need;
    return ODHS_OK;
}

static int same_pattern(const spqr_state *s, const odhs_network *net)
{
    return s->have_symbolic && s->n == net->n && s->dim == net->dim && s->nc == net->nc &&
           memcmp(s->pci, net->ci, net->nc * sizeof *net->ci) == 0 &&
           memcmp(s->pcj, net->cj, net->nc * sizeof *net->cj) == 0;
}

/* New pattern: allocate A = S^T with its structure and analyse it. */
static int analyse(spqr_state *s, const odhs_network *net)
{
    size_t nc = net->nc, d = (size_t)net->dim, m = net->n * d;
    drop_factor(s);
    if (s->pcap < nc) {
        size_t *a = odhs__realloc(s->pci, nc * sizeof *a);
        if (!a) return ODHS_E_NOMEM;
        s->pci = a;
        size_t *b = odhs__realloc(s->pcj, nc * sizeof *b);
        if (!b) return ODHS_E_NOMEM;
        s->pcj = b;
        s->pcap = nc;
    }
    s->A = cholmod_l_allocate_sparse(m, nc, 2 * d * nc, 1 /* sorted */, 1 /* packed */, 0 /* unsymmetric */,
                                     CHOLMOD_REAL, &s->cc);
    if (!s->A) return cc_status(s);
    SuiteSparse_long *Ap = s->A->p, *Ai = s->A->i;
    double *Ax = s->A->x;
    size_t p = 0;
    for (size_t c = 0; c < nc; ++c) {
        size_t i = net->ci[c], j = net->cj[c]; /* i < j: rows come out sorted */
        Ap[c] = (SuiteSparse_long)p;
        for (size_t k = 0; k < d; ++k) {
            Ai[p] = (SuiteSparse_long)(i * d + k);
            Ax[p++] = 0.0;
        }
        if (j >= net->n) continue; /* a wall has no block */
        for (size_t k = 0; k < d; ++k) {
            Ai[p] = (SuiteSparse_long)(j * d + k);
            Ax[p++] = 0.0;
        }
    }
    Ap[nc] = (SuiteSparse_long)p;
    s->qr = SuiteSparseQR_C_symbolic(s->ordering, 1 /* allow_tol: rank detection */, s->A, &s->cc);
    if (!s->qr) {
        int st = cc_status(s);
        drop_factor(s);
        return st;
    }
    s->nsym += 1.0;
    s->ord_used = (double)s->cc.SPQR_istat[7];
    memcpy(s->pci, net->ci, nc * sizeof *net->ci);
    memcpy(s->pcj, net->cj, nc * sizeof *net->cj);
    s->n = net->n;
    s->dim = net->dim;
    s->nc = nc;
    s->have_symbolic = 1;
    return ODHS_OK;
}

static int spqr_setup(void *state, const odhs_network *net)
{
    spqr_state *s = state;
    size_t nc = net->nc, d = (size_t)net->dim;
    s->factored = 0;
    s->nc_stat = (double)nc;
    s->rank = NAN;
    if (nc == 0) {
        s->rank = 0.0;
        return ODHS_OK;
    }
    int st = ensure_work(s, net->n * d > nc ? net->n * d : nc);
    if (st) return st;
    if (!same_pattern(s, net)) {
        st = analyse(s, net);
        if (st) return st;
    }
    /* values: column c = -n_c on i's rows, +n_c on j's */
    double *Ax = s->A->x;
    for (size_t c = 0; c < nc; ++c) {
        const double *nv = net->nrm + c * d;
        double *col = Ax + ((SuiteSparse_long *)s->A->p)[c];
        for (size_t k = 0; k < d; ++k) col[k] = -nv[k];
        if (net->cj[c] < net->n)
            for (size_t k = 0; k < d; ++k) col[d + k] = nv[k];
    }
    if (!SuiteSparseQR_C_numeric(s->tol, s->A, s->qr, &s->cc)) {
        st = cc_status(s);
        drop_factor(s); /* keep nothing half-done */
        return st;
    }
    s->nnum += 1.0;
    s->rank = (double)s->cc.SPQR_istat[4];
    s->tol_used = s->cc.SPQR_tol_used;
    if (s->cc.SPQR_istat[4] < (SuiteSparse_long)nc) {
        /* A rank-deficient factorization leaves the map from the squeezed R
         * (QR->Rmap) in the object; SuiteSparseQR_numeric only rebuilds it
         * when the next factorization is rank deficient too, and the
         * triangular solves use it whenever it is there. Start afresh. */
        drop_factor(s);
        return ODHS_E_SINGULAR;
    }
    s->factored = 1;
    return ODHS_OK;
}

static void wrap_dense(cholmod_dense *D, double *x, size_t rows)
{
    memset(D, 0, sizeof *D);
    D->nrow = rows;
    D->ncol = 1;
    D->nzmax = rows;
    D->d = rows;
    D->x = x;
    D->z = NULL;
    D->xtype = CHOLMOD_REAL;
    D->dtype = CHOLMOD_DOUBLE;
}

static int check_ready(const spqr_state *s, const odhs_network *net)
{
    if (!s->factored || !s->qr || s->nc != net->nc || s->n != net->n || s->dim != net->dim) return ODHS_E_STATE;
    return ODHS_OK;
}

/* x = E R^{-1} y with y of m entries; frees y */
static int finish_retx(spqr_state *s, cholmod_dense **y, double *x)
{
    cholmod_dense *X = SuiteSparseQR_C_solve(SPQR_RETX_EQUALS_B, s->qr, *y, &s->cc);
    cholmod_l_free_dense(y, &s->cc);
    if (!X) return cc_status(s);
    memcpy(x, X->x, s->nc * sizeof *x);
    cholmod_l_free_dense(&X, &s->cc);
    return ODHS_OK;
}

static int spqr_solve(void *state, const odhs_network *net, const double *b, double *x)
{
    spqr_state *s = state;
    int st = check_ready(s, net);
    if (st) return st;
    memcpy(s->w, b, s->nc * sizeof *b);
    cholmod_dense B;
    wrap_dense(&B, s->w, s->nc);
    /* y = R^{-T} E^T b (m entries, zero beyond the rank) */
    cholmod_dense *Y = SuiteSparseQR_C_solve(SPQR_RTX_EQUALS_ETB, s->qr, &B, &s->cc);
    if (!Y) return cc_status(s);
    return finish_retx(s, &Y, x);
}

static int spqr_solve_ls(void *state, const odhs_network *net, const double *g, double *x)
{
    spqr_state *s = state;
    int st = check_ready(s, net);
    if (st) return st;
    size_t m = s->n * (size_t)s->dim;
    memcpy(s->w, g, m * sizeof *g);
    cholmod_dense G;
    wrap_dense(&G, s->w, m);
    /* c = Q^T g, then x = E R^{-1} c(1..Nc) */
    cholmod_dense *C = SuiteSparseQR_C_qmult(SPQR_QTX, s->qr, &G, &s->cc);
    if (!C) return cc_status(s);
    return finish_retx(s, &C, x);
}

static int spqr_get_stat(void *state, const char *key, double *v)
{
    spqr_state *s = state;
    if (!strcmp(key, "rank")) *v = s->rank;
    else if (!strcmp(key, "nc")) *v = s->nc_stat;
    else if (!strcmp(key, "rank_deficiency")) *v = s->nc_stat - s->rank;
    else if (!strcmp(key, "tol_used")) *v = s->tol_used;
    else if (!strcmp(key, "symbolic")) *v = s->nsym;
    else if (!strcmp(key, "numeric")) *v = s->nnum;
    else if (!strcmp(key, "ordering_used")) *v = s->ord_used;
    else if (!strcmp(key, "iterations")) *v = 0.0;
    else return ODHS_E_INVALID;
    return ODHS_OK;
}

ODHS_API const odhs_solver_type odhs_solver_type_spqr = {
    .version = ODHS_SOLVER_TYPE_VERSION,
    .name = "spqr",
    .flags = ODHS_SOLVER_DIRECT | ODHS_SOLVER_LEAST_SQUARES,
    .create = spqr_create,
    .destroy = spqr_destroy,
    .setup = spqr_setup,
    .solve = spqr_solve,
    .set_param = spqr_set_param,
    .get_stat = spqr_get_stat,
    .solve_ls = spqr_solve_ls,
};

#else
/* ISO C forbids an empty translation unit */
typedef int odhs__spqr_not_built;
#endif /* ODHS_HAVE_SUITESPARSE */
