/*
 * libodhs - what the CHOLMOD backends share (lib/solvers/cholmod_common.h):
 * CHOLMOD's status codes, the operator S as a CHOLMOD matrix, checks of a
 * factor. Compiled only with SuiteSparse (ODHS_HAVE_SUITESPARSE); otherwise
 * this file defines nothing.
 */
#ifdef ODHS_HAVE_SUITESPARSE

#include <limits.h>
#include <math.h>
#include <string.h>

#include "solvers/cholmod_common.h"

/* status of a failed CHOLMOD call */
int odhs__cm_error(const cholmod_common *c)
{
    if (c->status == CHOLMOD_OUT_OF_MEMORY || c->status == CHOLMOD_TOO_LARGE) return ODHS_E_NOMEM;
    if (c->status == CHOLMOD_NOT_POSDEF) return ODHS_E_SINGULAR;
    return ODHS_E_INTERNAL;
}

void odhs__cm_start(cholmod_common *c)
{
    cholmod_start(c);
    c->print = 0;            /* never print: status codes only */
    c->error_handler = NULL;
}

int odhs__cm_solve(cholmod_common *c, cholmod_factor *L, cholmod_dense *work[4], size_t n, const double *b, double *x)
{
    int st = odhs__cm_ensure_dense(&work[0], n, c);
    if (st) return st;
    memcpy(work[0]->x, b, n * sizeof *b);
    if (!cholmod_solve2(CHOLMOD_A, L, work[0], NULL, &work[1], NULL, &work[2], &work[3], c)) return odhs__cm_error(c);
    memcpy(x, work[1]->x, n * sizeof *x);
    return ODHS_OK;
}

void odhs__cm_release(cholmod_common *c, cholmod_factor **L, cholmod_sparse **A, cholmod_dense *work[4])
{
    cholmod_free_factor(L, c);
    cholmod_free_sparse(A, c);
    for (int k = 0; k < 4; ++k) cholmod_free_dense(&work[k], c);
    cholmod_finish(c);
}

/* Whether the network's sizes fit CHOLMOD's int interface for a matrix
 * [S | E] with nextra extra unit columns. */
int odhs__cm_fits_int(const odhs_network *net, size_t nextra)
{
    size_t nc = net->nc, nd = net->n * (size_t)net->dim;
    size_t lim = (size_t)INT_MAX / 8;
    return nc + nextra < lim && nd + nextra < lim && nc < lim / 6;
}

/* (Re)allocate A (nrow x ncol, CSC, packed, sorted, unsymmetric) unless the
 * current one has exactly these dimensions and nonzero count. */
int odhs__cm_ensure_sparse(cholmod_sparse **A, size_t nrow, size_t ncol, size_t nnz, cholmod_common *c)
{
    if (*A && (*A)->nrow == nrow && (*A)->ncol == ncol && (*A)->nzmax == nnz) return ODHS_OK;
    cholmod_free_sparse(A, c);
    *A = cholmod_allocate_sparse(nrow, ncol, nnz, 1, 1, 0, CHOLMOD_REAL, c);
    return *A ? ODHS_OK : odhs__cm_error(c);
}

/* (Re)allocate the dense column B unless it has nrow rows already. */
int odhs__cm_ensure_dense(cholmod_dense **B, size_t nrow, cholmod_common *c)
{
    if (*B && (*B)->nrow == nrow) return ODHS_OK;
    cholmod_free_dense(B, c);
    *B = cholmod_allocate_dense(nrow, 1, nrow, CHOLMOD_REAL, c);
    return *B ? ODHS_OK : odhs__cm_error(c);
}

/* A = [S | E] in compressed columns: S is the network's Nc x Nd operator
 * (row c: -n_c on particle ci's block, +n_c on cj's), E has nextra columns,
 * column k with a unit entry in row nc + k. Rows come out sorted in every
 * column since contacts are visited in increasing order. Entries are stored
 * even when a normal component is exactly zero, so the pattern of A depends
 * on the contact list only. cnt: n entries of workspace. */
void odhs__cm_fill_S(const odhs_network *net, size_t nextra, cholmod_sparse *A, size_t *cnt)
{
    size_t n = net->n, nc = net->nc;
    int d = net->dim;
    int *Ap = A->p, *Ai = A->i;
    double *Ax = A->x;
    memset(cnt, 0, n * sizeof *cnt);
    for (size_t c = 0; c < nc; ++c) {
        cnt[net->ci[c]]++;
        if (net->cj[c] < n) cnt[net->cj[c]]++; /* a wall has no block */
    }
    Ap[0] = 0;
    for (size_t p = 0; p < n; ++p)
        for (int k = 0; k < d; ++k) Ap[p * d + k + 1] = Ap[p * d + k] + (int)cnt[p];
    memset(cnt, 0, n * sizeof *cnt);
    for (size_t c = 0; c < nc; ++c) {
        size_t i = net->ci[c], j = net->cj[c];
        size_t oi = cnt[i]++;
        const double *nr = net->nrm + c * d;
        for (int k = 0; k < d; ++k) {
            size_t qi = (size_t)Ap[i * d + k] + oi;
            Ai[qi] = (int)c;
            Ax[qi] = -nr[k];
        }
        if (j >= n) continue;
        size_t oj = cnt[j]++;
        for (int k = 0; k < d; ++k) {
            size_t qj = (size_t)Ap[j * d + k] + oj;
            Ai[qj] = (int)c;
            Ax[qj] = nr[k];
        }
    }
    size_t nd = n * (size_t)d;
    int base = Ap[nd];
    for (size_t k = 0; k < nextra; ++k) {
        Ai[base + k] = (int)(nc + k);
        Ax[base + k] = 1.0;
        Ap[nd + k + 1] = base + (int)k + 1;
    }
}

/* Smallest and largest pivot of a simplicial factor: D of LDL', diag(L)^2
 * of LL'. Returns 0 for a supernodal factor (not inspected here). */
int odhs__cm_simplicial_pivots(const cholmod_factor *L, double *dmin, double *dmax)
{
    if (L->is_super || L->xtype != CHOLMOD_REAL) return 0;
    const int *Lp = L->p;
    const double *Lx = L->x;
    double lo = INFINITY, hi = -INFINITY;
    for (size_t j = 0; j < L->n; ++j) {
        double v = Lx[Lp[j]];
        if (L->is_ll) v *= v;
        if (!(v >= lo)) lo = v; /* NaN counts as the smallest */
        if (v > hi) hi = v;
    }
    *dmin = lo;
    *dmax = hi;
    return 1;
}

/* Number of stored entries of L (simplicial: current column counts; the
 * Modify module can grow them). */
double odhs__cm_factor_nnz(const cholmod_factor *L, const cholmod_common *c)
{
    if (!L) return 0.0;
    if (L->is_super || !L->nz) return c->lnz;
    const int *nz = L->nz;
    double s = 0.0;
    for (size_t j = 0; j < L->n; ++j) s += nz[j];
    return s;
}

/* The OpenMP runtime's calls, bound only when the process has one (CHOLMOD's
 * libgomp): weak references, so that neither the library nor a program that
 * links it needs an OpenMP runtime of its own. */
#if defined(__GNUC__) && defined(__ELF__)
#define ODHS_WEAK_OMP 1
extern int omp_get_max_active_levels(void) __attribute__((weak));
extern void omp_set_max_active_levels(int) __attribute__((weak));
#endif

int odhs__cm_factorize(cholmod_sparse *A, double *beta, cholmod_factor *L, cholmod_common *c, int openmp)
{
    double zero[2] = {0.0, 0.0}; /* cholmod_factorize's beta: CHOLMOD reads it */
    if (!beta) beta = zero;
#ifdef ODHS_WEAK_OMP
    if (!openmp && L && L->is_super && omp_get_max_active_levels && omp_set_max_active_levels) {
        int levels = omp_get_max_active_levels();
        omp_set_max_active_levels(0);
        int ok = cholmod_factorize_p(A, beta, NULL, 0, L, c);
        omp_set_max_active_levels(levels);
        return ok;
    }
#else
    (void)openmp;
#endif
    return cholmod_factorize_p(A, beta, NULL, 0, L, c);
}

/* Check a fresh numeric factorisation: ODHS_OK, ODHS_E_SINGULAR or an error. */
int odhs__cm_check_factor(cholmod_factor *L, cholmod_common *c, double min_rcond, double *rcond)
{
    *rcond = 0.0;
    if (c->status < 0) return odhs__cm_error(c);
    if (c->status == CHOLMOD_NOT_POSDEF || L->minor < L->n) return ODHS_E_SINGULAR;
    double dmin, dmax;
    if (odhs__cm_simplicial_pivots(L, &dmin, &dmax) && !(dmin > 0.0)) return ODHS_E_SINGULAR;
    double r = cholmod_rcond(L, c);
    *rcond = r < 0.0 ? 0.0 : r;
    if (!(r > min_rcond)) return ODHS_E_SINGULAR;
    return ODHS_OK;
}

#else /* !ODHS_HAVE_SUITESPARSE */

/* ISO C forbids an empty translation unit */
typedef int odhs__cholmod_common_not_built;

#endif /* ODHS_HAVE_SUITESPARSE */
