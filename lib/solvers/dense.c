/* libodhs - dense Cholesky of N = S S^T through LAPACK (dpotrf/dpotrs). */
#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "solvers/solvers.h"

typedef struct {
    double *A;      /* nc*nc column-major factor */
    size_t cap;     /* capacity of A in doubles */
    size_t nc;
    int factored;
    size_t *start, *inc; /* particle -> incident contacts */
    size_t icap, pcap;
    double info;    /* last LAPACK info */
    double rcond;   /* reciprocal condition estimate of the last factor */
    double min_rcond; /* below this N counts as singular */
} dense_state;

static int dense_create(void **state)
{
    dense_state *s = odhs__calloc(1, sizeof *s);
    if (!s) return ODHS_E_NOMEM;
    s->min_rcond = 1e-14;
    *state = s;
    return ODHS_OK;
}

static int dense_set_param(void *state, const char *key, double v)
{
    dense_state *s = state;
    if (!strcmp(key, "min_rcond") && v >= 0.0 && v < 1.0) s->min_rcond = v;
    else return ODHS_E_INVALID;
    return ODHS_OK;
}

static void dense_destroy(void *state)
{
    dense_state *s = state;
    if (!s) return;
    odhs__free(s->A);
    odhs__free(s->start);
    odhs__free(s->inc);
    odhs__free(s);
}

static int dense_setup(void *state, const odhs_network *net)
{
    dense_state *s = state;
    size_t nc = net->nc, n = net->n;
    int d = net->dim;
    s->factored = 0;
    if (nc > 46340) return ODHS_E_NOMEM; /* nc*nc must fit LAPACK's int */
    if (s->cap < nc * nc) {
        double *A = odhs__realloc(s->A, nc * nc * sizeof *A);
        if (!A) return ODHS_E_NOMEM;
        s->A = A;
        s->cap = nc * nc;
    }
    if (s->pcap < n + 1) {
        size_t *p = odhs__realloc(s->start, (n + 1) * sizeof *p);
        if (!p) return ODHS_E_NOMEM;
        s->start = p;
        s->pcap = n + 1;
    }
    if (s->icap < 2 * nc) {
        size_t *p = odhs__realloc(s->inc, 2 * nc * sizeof *p);
        if (!p) return ODHS_E_NOMEM;
        s->inc = p;
        s->icap = 2 * nc;
    }
    memset(s->start, 0, (n + 1) * sizeof *s->start);
    for (size_t c = 0; c < nc; ++c) {
        s->start[net->ci[c] + 1]++;
        if (net->cj[c] < n) s->start[net->cj[c] + 1]++; /* a wall has no block */
    }
    for (size_t i = 0; i < n; ++i) s->start[i + 1] += s->start[i];
    for (size_t c = 0; c < nc; ++c) {
        s->inc[s->start[net->ci[c]]++] = c;
        if (net->cj[c] < n) s->inc[s->start[net->cj[c]]++] = c;
    }
    for (size_t i = n; i > 0; --i) s->start[i] = s->start[i - 1];
    s->start[0] = 0;

    double *A = s->A;
    memset(A, 0, nc * nc * sizeof *A);
    for (size_t p = 0; p < n; ++p) {
        for (size_t u = s->start[p]; u < s->start[p + 1]; ++u) {
            size_t a = s->inc[u];
            double sa = net->ci[a] == p ? -1.0 : 1.0;
            const double *na = net->nrm + a * d;
            for (size_t v = s->start[p]; v < s->start[p + 1]; ++v) {
                size_t b = s->inc[v];
                double sb = net->ci[b] == p ? -1.0 : 1.0;
                const double *nb = net->nrm + b * d;
                double dot = 0.0;
                for (int k = 0; k < d; ++k) dot += na[k] * nb[k];
                A[b * nc + a] += sa * sb * dot;
            }
        }
    }
    /* 1-norm of N (symmetric: lower triangle holds it all) for the condition
     * estimate after the factorisation */
    double anorm = 0.0;
    for (size_t b = 0; b < nc; ++b) {
        double col = 0.0;
        for (size_t a = 0; a < nc; ++a) col += fabs(A[b * nc + a]);
        anorm = fmax(anorm, col);
    }
    lapack_int info = LAPACKE_dpotrf(LAPACK_COL_MAJOR, 'L', (lapack_int)nc, A, (lapack_int)nc);
    s->info = (double)info;
    if (info > 0) return ODHS_E_SINGULAR;
    if (info < 0) return ODHS_E_INTERNAL;
    /* a hyperstatic network can factor with round-off pivots: reject it */
    double rcond = 0.0;
    info = LAPACKE_dpocon(LAPACK_COL_MAJOR, 'L', (lapack_int)nc, A, (lapack_int)nc, anorm, &rcond);
    s->rcond = rcond;
    if (info != 0) return ODHS_E_INTERNAL;
    if (!(rcond > s->min_rcond)) return ODHS_E_SINGULAR;
    s->nc = nc;
    s->factored = 1;
    return ODHS_OK;
}

static int dense_solve(void *state, const odhs_network *net, const double *b, double *x)
{
    dense_state *s = state;
    if (!s->factored || s->nc != net->nc) return ODHS_E_STATE;
    memcpy(x, b, net->nc * sizeof *x);
    lapack_int info = LAPACKE_dpotrs(LAPACK_COL_MAJOR, 'L', (lapack_int)s->nc, 1, s->A, (lapack_int)s->nc,
                                     x, (lapack_int)s->nc);
    s->info = (double)info;
    return info == 0 ? ODHS_OK : ODHS_E_INTERNAL;
}

static int dense_get_stat(void *state, const char *key, double *v)
{
    dense_state *s = state;
    if (!strcmp(key, "lapack_info")) *v = s->info;
    else if (!strcmp(key, "rcond")) *v = s->rcond;
    else if (!strcmp(key, "iterations")) *v = 0.0;
    else return ODHS_E_INVALID;
    return ODHS_OK;
}

const odhs_solver_type odhs_solver_type_dense = {
    ODHS_SOLVER_TYPE_VERSION, "dense", ODHS_SOLVER_DIRECT,
    dense_create, dense_destroy, dense_setup, dense_solve, dense_set_param, dense_get_stat, NULL,
};
