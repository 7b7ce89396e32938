/* libodhs - Jacobi-preconditioned conjugate gradient on N = S S^T, matrix free. */
#include <math.h>
#include <string.h>

#include "solvers/solvers.h"

typedef struct {
    double tol;
    double maxiter; /* 0 = automatic */
    double iterations;
    double *w;      /* workspace */
    size_t cap;
} cg_state;

static int cg_create(void **state)
{
    cg_state *s = odhs__calloc(1, sizeof *s);
    if (!s) return ODHS_E_NOMEM;
    s->tol = 1e-12;
    *state = s;
    return ODHS_OK;
}

static void cg_destroy(void *state)
{
    cg_state *s = state;
    if (!s) return;
    odhs__free(s->w);
    odhs__free(s);
}

static int cg_set_param(void *state, const char *key, double v)
{
    cg_state *s = state;
    if (!strcmp(key, "tol") && v > 0.0 && v < 1.0) s->tol = v;
    else if (!strcmp(key, "maxiter") && v >= 0.0) s->maxiter = floor(v);
    else return ODHS_E_INVALID;
    return ODHS_OK;
}

static int cg_get_stat(void *state, const char *key, double *v)
{
    cg_state *s = state;
    if (!strcmp(key, "iterations")) *v = s->iterations;
    else if (!strcmp(key, "tol")) *v = s->tol;
    else return ODHS_E_INVALID;
    return ODHS_OK;
}

static int cg_solve(void *state, const odhs_network *net, const double *b, double *x)
{
    cg_state *s = state;
    size_t nc = net->nc, nd = net->n * (size_t)net->dim;
    size_t need = 4 * nc + nd;
    if (s->cap < need) {
        double *w = odhs__realloc(s->w, need * sizeof *w);
        if (!w) return ODHS_E_NOMEM;
        s->w = w;
        s->cap = need;
    }
    double *r = s->w, *z = r + nc, *p = z + nc, *q = p + nc, *tmp = q + nc;
    /* Jacobi preconditioner: diag(N)_c = sum of squared entries of row c of S
     * = 2 |n_c|^2 = 2 for particle pairs */
    const double dinv = 0.5;
    double bn = 0.0;
    for (size_t c = 0; c < nc; ++c) bn += b[c] * b[c];
    bn = sqrt(bn);
    s->iterations = 0;
    if (bn == 0.0) {
        memset(x, 0, nc * sizeof *x);
        return ODHS_OK;
    }
    odhs__net_N(net, x, q, tmp);
    double rz = 0.0, rn = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        r[c] = b[c] - q[c];
        z[c] = dinv * r[c];
        p[c] = z[c];
        rz += r[c] * z[c];
        rn += r[c] * r[c];
    }
    size_t maxit = s->maxiter > 0 ? (size_t)s->maxiter : 10 * nc + 100;
    double target = s->tol * bn;
    size_t it = 0;
    while (sqrt(rn) > target && it < maxit) {
        odhs__net_N(net, p, q, tmp);
        double pq = 0.0;
        for (size_t c = 0; c < nc; ++c) pq += p[c] * q[c];
        if (!(pq > 0.0)) {
            s->iterations = (double)it;
            return ODHS_E_SINGULAR;
        }
        double alpha = rz / pq, rz_new = 0.0;
        rn = 0.0;
        for (size_t c = 0; c < nc; ++c) {
            x[c] += alpha * p[c];
            r[c] -= alpha * q[c];
            z[c] = dinv * r[c];
            rz_new += r[c] * z[c];
            rn += r[c] * r[c];
        }
        double beta = rz_new / rz;
        rz = rz_new;
        for (size_t c = 0; c < nc; ++c) p[c] = z[c] + beta * p[c];
        ++it;
        if (it % 50 == 0) { /* refresh the recursive residual against drift */
            odhs__net_N(net, x, q, tmp);
            rn = 0.0;
            rz = 0.0;
            for (size_t c = 0; c < nc; ++c) {
                r[c] = b[c] - q[c];
                rn += r[c] * r[c];
                rz += r[c] * r[c] * dinv;
            }
        }
    }
    s->iterations = (double)it;
    return sqrt(rn) <= target ? ODHS_OK : ODHS_E_NOCONV;
}

const odhs_solver_type odhs_solver_type_cg = {
    ODHS_SOLVER_TYPE_VERSION, "cg", ODHS_SOLVER_ITERATIVE | ODHS_SOLVER_USES_GUESS,
    cg_create, cg_destroy, NULL, cg_solve, cg_set_param, cg_get_stat, NULL,
};
