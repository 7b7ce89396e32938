/*
 * libodhs - sparse direct solvers for N = S S^T through CHOLMOD (SuiteSparse).
 *
 * This file: the backend "cholmod" ("cholmod-pcg" is in cholmod_pcg.c, what
 * both share in cholmod_common.c), compiled only when the Makefile finds
 * SuiteSparse (ODHS_HAVE_SUITESPARSE); otherwise this file defines nothing.
 *
 * "cholmod" (odhs_solver_type_cholmod): sparse Cholesky of N = S S^T.
 *   S (Nc x Nd) is handed to CHOLMOD as an unsymmetric matrix (stype = 0), for
 *   which cholmod_analyze / cholmod_factorize order and factor A*A' = S S^T
 *   without our forming N. The symbolic analysis (fill-reducing ordering,
 *   elimination tree, pattern of L) depends only on the nonzero pattern of S,
 *   i.e. on the list of contact pairs in their order; it is kept while that
 *   list is unchanged (a copy of the (ci,cj) lists decides) and only the
 *   numeric factorisation is redone when just the geometry (the normals)
 *   changed. Any added, removed or permuted contact triggers a new analysis.
 *   A not-positive-definite pivot (CHOLMOD_NOT_POSDEF, L->minor < n, or a
 *   non-positive D of a simplicial LDL' factor) or a diagonal-ratio condition
 *   estimate (cholmod_rcond) not above "min_rcond" is reported as
 *   ODHS_E_SINGULAR: singular or hyperstatic networks.
 *   Parameters: "min_rcond" (default 1e-14), "supernodal" (0 = simplicial
 *   LDL', 1 = supernodal LL', -1 = CHOLMOD's automatic choice, the default),
 *   "openmp" (since 0.2.21; 0, the default: the OpenMP loops of CHOLMOD's
 *   supernodal factorisation run on the calling thread alone; 1: they use
 *   CHOLMOD's own threads, 4 per loop in Debian's build, fewer under
 *   OMP_THREAD_LIMIT; the same result either way: odhs__cm_factorize).
 *   Statistics: "analyses", "factorizations", "updates" (always 0 here),
 *   "rcond", "nnz_L", "flops" (CHOLMOD's flop count of the factorisation,
 *   from the analysis), "iterations" (0), "cholmod_status" (Common->status
 *   after the last CHOLMOD call of setup: 0 ok, 1 not positive definite,
 *   negative errors).
 *
 * As for both backends (cholmod_common.h): each state owns its own
 * cholmod_common, CHOLMOD never prints, and its int interface is used.
 */
#ifdef ODHS_HAVE_SUITESPARSE

#include <string.h>

#include "solvers/cholmod_common.h"

ODHS_API extern const odhs_solver_type odhs_solver_type_cholmod;

typedef struct {
    cholmod_common c;
    cholmod_sparse *A;        /* S, Nc x Nd */
    cholmod_factor *L;        /* factor of S S^T */
    cholmod_dense *work[4]; /* cholmod_solve2: B (right-hand side), X (solution), Y, E */
    size_t *pci, *pcj;        /* contact list of the current analysis */
    size_t pnc, pcicap, pcjcap, pn;
    int pdim;
    int have_pattern;         /* pci/pcj/pn/pdim describe L's analysis */
    size_t *cnt;
    size_t cntcap;
    int factored;
    int supernodal;           /* -1 auto, 0 simplicial, 1 supernodal */
    int openmp;               /* CHOLMOD's OpenMP threads in supernodal factorisations */
    double min_rcond;
    double rcond, analyses, factorizations, status;
} chm_state;

static int chm_create(void **state)
{
    chm_state *s = odhs__calloc(1, sizeof *s);
    if (!s) return ODHS_E_NOMEM;
    odhs__cm_start(&s->c);
    s->supernodal = -1;
    s->min_rcond = 1e-14;
    *state = s;
    return ODHS_OK;
}

static void chm_destroy(void *state)
{
    chm_state *s = state;
    if (!s) return;
    odhs__cm_release(&s->c, &s->L, &s->A, s->work);
    odhs__free(s->pci);
    odhs__free(s->pcj);
    odhs__free(s->cnt);
    odhs__free(s);
}

static int chm_set_param(void *state, const char *key, double v)
{
    chm_state *s = state;
    if (!strcmp(key, "min_rcond") && v >= 0.0 && v < 1.0) s->min_rcond = v;
    else if (!strcmp(key, "supernodal") && (v == -1.0 || v == 0.0 || v == 1.0)) {
        if ((int)v != s->supernodal) s->have_pattern = 0; /* analyse again */
        s->supernodal = (int)v;
    } else if (!strcmp(key, "openmp") && (v == 0.0 || v == 1.0)) s->openmp = (int)v;
    else return ODHS_E_INVALID;
    return ODHS_OK;
}

static int chm_get_stat(void *state, const char *key, double *v)
{
    chm_state *s = state;
    if (!strcmp(key, "analyses")) *v = s->analyses;
    else if (!strcmp(key, "factorizations")) *v = s->factorizations;
    else if (!strcmp(key, "updates") || !strcmp(key, "iterations")) *v = 0.0;
    else if (!strcmp(key, "rcond")) *v = s->rcond;
    else if (!strcmp(key, "nnz_L")) *v = odhs__cm_factor_nnz(s->L, &s->c);
    else if (!strcmp(key, "flops")) *v = s->L ? s->c.fl : 0.0;
    else if (!strcmp(key, "cholmod_status")) *v = s->status;
    else if (!strcmp(key, "supernodal")) *v = s->L ? (double)s->L->is_super : (double)s->supernodal;
    else if (!strcmp(key, "openmp")) *v = (double)s->openmp;
    else return ODHS_E_INVALID;
    return ODHS_OK;
}

static int chm_same_pattern(const chm_state *s, const odhs_network *net)
{
    return s->have_pattern && s->L && s->pn == net->n && s->pdim == net->dim && s->pnc == net->nc &&
           !memcmp(s->pci, net->ci, net->nc * sizeof *net->ci) &&
           !memcmp(s->pcj, net->cj, net->nc * sizeof *net->cj);
}

static int chm_setup(void *state, const odhs_network *net)
{
    chm_state *s = state;
    size_t nc = net->nc, n = net->n, nd = n * (size_t)net->dim;
    int st;
    s->factored = 0;
    if (!odhs__cm_fits_int(net, 0)) return ODHS_E_NOMEM;
    if ((st = odhs__reserve((void **)&s->cnt, &s->cntcap, n + 1, sizeof *s->cnt))) return st;
    int same = chm_same_pattern(s, net);
    if ((st = odhs__cm_ensure_sparse(&s->A, nc, nd, 2 * (size_t)net->dim * nc, &s->c))) return st;
    odhs__cm_fill_S(net, 0, s->A, s->cnt);
    if (!same) {
        s->have_pattern = 0;
        cholmod_free_factor(&s->L, &s->c);
        s->c.supernodal = s->supernodal == 0 ? CHOLMOD_SIMPLICIAL
                          : s->supernodal == 1 ? CHOLMOD_SUPERNODAL : CHOLMOD_AUTO;
        s->L = cholmod_analyze(s->A, &s->c);
        s->status = s->c.status;
        if (!s->L) return odhs__cm_error(&s->c);
        s->analyses += 1.0;
        if ((st = odhs__reserve((void **)&s->pci, &s->pcicap, nc, sizeof *s->pci)) ||
            (st = odhs__reserve((void **)&s->pcj, &s->pcjcap, nc, sizeof *s->pcj)))
            return st;
        memcpy(s->pci, net->ci, nc * sizeof *s->pci);
        memcpy(s->pcj, net->cj, nc * sizeof *s->pcj);
        s->pnc = nc;
        s->pn = n;
        s->pdim = net->dim;
        s->have_pattern = 1;
    }
    int ok = odhs__cm_factorize(s->A, NULL, s->L, &s->c, s->openmp);
    s->status = s->c.status;
    s->factorizations += 1.0;
    if (!ok || s->c.status < 0) {
        /* an error (not a pivot failure): start from a new analysis */
        st = odhs__cm_error(&s->c);
        cholmod_free_factor(&s->L, &s->c);
        s->have_pattern = 0;
        return st;
    }
    if ((st = odhs__cm_check_factor(s->L, &s->c, s->min_rcond, &s->rcond))) return st;
    s->factored = 1;
    return ODHS_OK;
}

static int chm_solve(void *state, const odhs_network *net, const double *b, double *x)
{
    chm_state *s = state;
    size_t nc = net->nc;
    if (!s->factored || !s->L || s->L->n != nc) return ODHS_E_STATE;
    return odhs__cm_solve(&s->c, s->L, s->work, nc, b, x);
}

ODHS_API const odhs_solver_type odhs_solver_type_cholmod = {
    .version = ODHS_SOLVER_TYPE_VERSION,
    .name = "cholmod",
    .flags = ODHS_SOLVER_DIRECT,
    .create = chm_create,
    .destroy = chm_destroy,
    .setup = chm_setup,
    .solve = chm_solve,
    .set_param = chm_set_param,
    .get_stat = chm_get_stat,
    .solve_ls = NULL,
};

#else /* !ODHS_HAVE_SUITESPARSE */

/* ISO C forbids an empty translation unit: without SuiteSparse this file
 * defines no backend (odhs_solver_create_by_name reports "not installed"). */
typedef int odhs__cholmod_not_built;

#endif /* ODHS_HAVE_SUITESPARSE */
