/*
 * libodhs - "lsq-pcg" (since 0.2.16): the minimum-norm solution of a
 * consistent, possibly singular system N x = b, N = S S^T, by conjugate
 * gradients from zero preconditioned with a CHOLMOD factor of N + beta I.
 * Internal to the "auto" solver (its least-squares route on rank-deficient
 * networks above "lsq_dense_max" contacts); compiled only with SuiteSparse.
 *
 * Why it converges to the minimum-norm solution: N and P = (N + beta I)^-1
 * share their eigenvectors, so P maps range(N) into itself; from x = 0 and a
 * right-hand side in range(N) every residual, search direction and iterate
 * stays there, and the only solution of N x = b in range(N) is N^+ b. The
 * preconditioned operator P N has the eigenvalues lambda / (lambda + beta)
 * on range(N): all within [lambda_min / (lambda_min + beta), 1), so the
 * iterations are few unless a nonzero eigenvalue lies far below beta
 * (plain CG from zero, "lsq-cg", needs of the order of sqrt(lambda_max /
 * lambda_min) of them: tens of thousands at N = 16 384 near a hyperstatic
 * cluster, 88 % of the CPU time of a batched run that met one).
 * Round-off puts components into the null space of N (a self-stress added to
 * the forces), amplified by P by up to 1/beta: about eps |b| / beta per
 * iteration, which is why beta is not smaller. Parameters: "shift" (beta
 * relative to the largest diagonal entry of N, default 1e-6), "tol" (relative
 * residual, default 1e-12), "maxiter" (default 0 = 500). It gives up
 * (ODHS_E_NOCONV) when the residual has not halved in 50 iterations: the
 * system is inconsistent (b has a part in the null space of N: no solution
 * exists) or hopeless. Statistics: "iterations", "factorizations".
 */
#ifdef ODHS_HAVE_SUITESPARSE

#include <math.h>
#include <string.h>

#include "solvers/cholmod_common.h"

typedef struct {
    cholmod_common c;
    cholmod_sparse *A; /* S: contacts x particle coordinates */
    cholmod_factor *L; /* of S S^T + beta I */
    cholmod_dense *work[4]; /* cholmod_solve2: B (right-hand side), X (solution), Y, E */
    size_t *cnt, cntcap;
    double *w;
    size_t wcap;
    size_t nc;
    int valid;
    double shift, tol, maxiter;
    double iterations, factorizations;
} lp_state;

static int lp_create(void **state)
{
    lp_state *s = odhs__calloc(1, sizeof *s);
    if (!s) return ODHS_E_NOMEM;
    odhs__cm_start(&s->c);
    s->shift = 1e-6;
    s->tol = 1e-12;
    *state = s;
    return ODHS_OK;
}

static void lp_destroy(void *state)
{
    lp_state *s = state;
    if (!s) return;
    odhs__cm_release(&s->c, &s->L, &s->A, s->work);
    odhs__free(s->cnt);
    odhs__free(s->w);
    odhs__free(s);
}

static int lp_set_param(void *state, const char *key, double v)
{
    lp_state *s = state;
    if (!strcmp(key, "shift") && v > 0.0 && v < 1.0) s->shift = v;
    else if (!strcmp(key, "tol") && v > 0.0 && v < 1.0) s->tol = v;
    else if (!strcmp(key, "maxiter") && v >= 0.0) s->maxiter = floor(v);
    else return ODHS_E_INVALID;
    return ODHS_OK;
}

static int lp_get_stat(void *state, const char *key, double *v)
{
    lp_state *s = state;
    if (!strcmp(key, "iterations")) *v = s->iterations;
    else if (!strcmp(key, "factorizations")) *v = s->factorizations;
    else if (!strcmp(key, "shift")) *v = s->shift;
    else if (!strcmp(key, "tol")) *v = s->tol;
    else return ODHS_E_INVALID;
    return ODHS_OK;
}

/* factor S S^T + beta I for the network's contacts and geometry */
static int lp_setup(void *state, const odhs_network *net)
{
    lp_state *s = state;
    size_t nc = net->nc, n = net->n, nd = n * (size_t)net->dim;
    int st;
    s->valid = 0;
    cholmod_free_factor(&s->L, &s->c);
    if (nc == 0) {
        s->nc = 0;
        s->valid = 1;
        return ODHS_OK;
    }
    if (!odhs__cm_fits_int(net, 0)) return ODHS_E_NOMEM;
    if ((st = odhs__reserve((void **)&s->cnt, &s->cntcap, n + 1, sizeof *s->cnt))) return st;
    if ((st = odhs__cm_ensure_sparse(&s->A, nc, nd, 2 * (size_t)net->dim * nc, &s->c))) return st;
    odhs__cm_fill_S(net, 0, s->A, s->cnt);
    /* the largest diagonal entry of N: 2 |n|^2 for a pair, |n|^2 at a wall */
    double dmax = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        double q = 0.0;
        for (int k = 0; k < net->dim; ++k) q += net->nrm[c * net->dim + k] * net->nrm[c * net->dim + k];
        dmax = fmax(dmax, (net->cj[c] < n ? 2.0 : 1.0) * q);
    }
    if (!(dmax > 0.0)) return ODHS_E_SINGULAR;
    s->L = cholmod_analyze(s->A, &s->c);
    if (!s->L) return odhs__cm_error(&s->c);
    double beta[2] = {s->shift * dmax, 0.0};
    int ok = odhs__cm_factorize(s->A, beta, s->L, &s->c, 0); /* CHOLMOD on the calling thread */
    s->factorizations += 1.0;
    if (!ok || s->c.status < 0) {
        st = odhs__cm_error(&s->c);
        cholmod_free_factor(&s->L, &s->c);
        return st;
    }
    /* beta I makes the matrix positive definite: a failure here is a
     * breakdown of the arithmetic, not of the network */
    if (s->c.status == CHOLMOD_NOT_POSDEF) {
        cholmod_free_factor(&s->L, &s->c);
        return ODHS_E_SINGULAR;
    }
    s->nc = nc;
    s->valid = 1;
    return ODHS_OK;
}

/* z = (N + beta I)^-1 r */
static int lp_precond(lp_state *s, const double *r, double *z)
{
    return odhs__cm_solve(&s->c, s->L, s->work, s->nc, r, z);
}

static int lp_solve(void *state, const odhs_network *net, const double *b, double *x)
{
    lp_state *s = state;
    size_t nc = net->nc, nd = net->n * (size_t)net->dim;
    int st;
    s->iterations = 0.0;
    if (!s->valid || s->nc != nc) return ODHS_E_STATE;
    memset(x, 0, nc * sizeof *x); /* from zero: the minimum-norm solution */
    if (nc == 0) return ODHS_OK;
    if ((st = odhs__reserve((void **)&s->w, &s->wcap, 4 * nc + nd, sizeof *s->w))) return st;
    double *r = s->w, *z = r + nc, *p = z + nc, *q = p + nc, *tmp = q + nc;
    double bn = 0.0;
    for (size_t c = 0; c < nc; ++c) bn += b[c] * b[c];
    bn = sqrt(bn);
    if (bn == 0.0) return ODHS_OK;
    size_t maxit = s->maxiter > 0 ? (size_t)s->maxiter : 500, it = 0, best_it = 0;
    double target = s->tol * bn, best = bn;
    memcpy(r, b, nc * sizeof *r);
    if ((st = lp_precond(s, r, z))) return st;
    double rz = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        p[c] = z[c];
        rz += r[c] * z[c];
    }
    if (!(rz > 0.0)) return ODHS_E_SINGULAR;
    for (;;) {
        if (it >= maxit) {
            s->iterations = (double)it;
            return ODHS_E_NOCONV;
        }
        odhs__net_N(net, p, q, tmp);
        double pq = 0.0;
        for (size_t c = 0; c < nc; ++c) pq += p[c] * q[c];
        if (!(pq > 0.0)) break; /* a breakdown: judged on the true residual too */
        double alpha = rz / pq, rn = 0.0;
        for (size_t c = 0; c < nc; ++c) {
            x[c] += alpha * p[c];
            r[c] -= alpha * q[c];
            rn += r[c] * r[c];
        }
        ++it;
        /* stagnation: an inconsistent system (b not in range(N): no
         * solution, the residual stalls at b's null-space part) or one that
         * would take far too long; auto then gives up on least squares */
        if (sqrt(rn) < 0.5 * best) {
            best = sqrt(rn);
            best_it = it;
        } else if (it - best_it >= 50) {
            s->iterations = (double)it;
            return ODHS_E_NOCONV;
        }
        if (sqrt(rn) <= target) break; /* confirmed on the true residual below */
        if ((st = lp_precond(s, r, z))) return st;
        double rz_new = 0.0;
        for (size_t c = 0; c < nc; ++c) rz_new += r[c] * z[c];
        if (!(rz_new > 0.0)) break;
        double beta = rz_new / rz;
        rz = rz_new;
        for (size_t c = 0; c < nc; ++c) p[c] = z[c] + beta * p[c];
    }
    s->iterations = (double)it;
    odhs__net_N(net, x, q, tmp);
    double rn = 0.0;
    for (size_t c = 0; c < nc; ++c) rn += (b[c] - q[c]) * (b[c] - q[c]);
    return sqrt(rn) <= target ? ODHS_OK : ODHS_E_NOCONV;
}

const odhs_solver_type odhs__solver_type_lsq_pcg = {
    .version = ODHS_SOLVER_TYPE_VERSION,
    .name = "lsq-pcg",
    .flags = ODHS_SOLVER_ITERATIVE,
    .create = lp_create,
    .destroy = lp_destroy,
    .setup = lp_setup,
    .solve = lp_solve,
    .set_param = lp_set_param,
    .get_stat = lp_get_stat,
    .solve_ls = NULL,
};

#else /* !ODHS_HAVE_SUITESPARSE */

/* ISO C forbids an empty translation unit */
typedef int odhs__lsq_pcg_not_built;

#endif /* ODHS_HAVE_SUITESPARSE */
