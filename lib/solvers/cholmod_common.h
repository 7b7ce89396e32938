/*
 * libodhs private header: what the two CHOLMOD backends ("cholmod" in
 * cholmod.c, "cholmod-pcg" in cholmod_pcg.c) share (cholmod_common.c).
 * Include only under ODHS_HAVE_SUITESPARSE. Not installed.
 *
 * Every backend state owns its own cholmod_common (cholmod_start /
 * cholmod_finish); CHOLMOD's printing is switched off (Common->print = 0):
 * problems are reported through status codes only. The int interface of
 * CHOLMOD is used throughout (sizes beyond INT_MAX give ODHS_E_NOMEM).
 */
#ifndef ODHS_SOLVERS_CHOLMOD_COMMON_H
#define ODHS_SOLVERS_CHOLMOD_COMMON_H

#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#endif
#include <cholmod.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif

#include "solvers/solvers.h"

/* status of a failed CHOLMOD call */
int odhs__cm_error(const cholmod_common *c);
/* cholmod_start with printing and the error handler off */
void odhs__cm_start(cholmod_common *c);
/* x = A^-1 b (n entries) with the factor L of A, through cholmod_solve2 and
 * its dense work (B, X, Y, E: kept between calls). */
int odhs__cm_solve(cholmod_common *c, cholmod_factor *L, cholmod_dense *work[4], size_t n, const double *b, double *x);
/* Free a backend's factor *L, matrix *A and cholmod_solve2's dense work
 * (B, X, Y, E), then cholmod_finish(c). */
void odhs__cm_release(cholmod_common *c, cholmod_factor **L, cholmod_sparse **A, cholmod_dense *work[4]);
/* Whether the network's sizes fit CHOLMOD's int interface for a matrix
 * [S | E] with nextra extra unit columns. */
int odhs__cm_fits_int(const odhs_network *net, size_t nextra);
/* (Re)allocate A (nrow x ncol, CSC, packed, sorted, unsymmetric) unless the
 * current one has exactly these dimensions and nonzero count. */
int odhs__cm_ensure_sparse(cholmod_sparse **A, size_t nrow, size_t ncol, size_t nnz, cholmod_common *c);
/* (Re)allocate the dense column B unless it has nrow rows already. */
int odhs__cm_ensure_dense(cholmod_dense **B, size_t nrow, cholmod_common *c);
/* A = [S | E] in compressed columns (nextra unit columns E); cnt: n entries
 * of workspace. */
void odhs__cm_fill_S(const odhs_network *net, size_t nextra, cholmod_sparse *A, size_t *cnt);
/* Smallest and largest pivot of a simplicial factor (0 for a supernodal one). */
int odhs__cm_simplicial_pivots(const cholmod_factor *L, double *dmin, double *dmax);
/* Number of stored entries of L. */
double odhs__cm_factor_nnz(const cholmod_factor *L, const cholmod_common *c);
/* cholmod_factorize_p(A, beta, NULL, 0, L, c) (beta NULL: zero). The
 * supernodal factorisation of CHOLMOD 3 (SuiteSparse 5) runs some loops of
 * every supernode as OpenMP parallel regions that ask for a fixed 4 threads;
 * unless openmp is nonzero they run on the calling thread alone: the OpenMP
 * ICV max-active-levels of the calling thread (a per-thread setting in
 * OpenMP 5.1 and libgomp since GCC 11) is set to 0 for the call and then
 * restored. The loops only fill and clear the factor's entries, so the
 * result does not depend on the thread count. Without an OpenMP runtime in
 * the process (a CHOLMOD built without OpenMP) this is cholmod_factorize_p.
 * The runtime's two calls are weak references: a fully static link that
 * does not pull them out of libgomp.a leaves them unbound, and CHOLMOD's
 * threads then run. A runtime older than GCC 11's libgomp keeps the ICV
 * per process, not per thread. */
int odhs__cm_factorize(cholmod_sparse *A, double *beta, cholmod_factor *L, cholmod_common *c, int openmp);
/* Check a fresh numeric factorisation: ODHS_OK, ODHS_E_SINGULAR or an error. */
int odhs__cm_check_factor(cholmod_factor *L, cholmod_common *c, double min_rcond, double *rcond);

#endif /* ODHS_SOLVERS_CHOLMOD_COMMON_H */
