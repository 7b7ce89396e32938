/*
 * libodhs - solver.h: pluggable linear solvers for N f = b with N = S S^T.
 *
 * A backend is a const table of functions (odhs_solver_type). Built-in
 * backends are exported as constants and can be looked up by name; user
 * backends fill their own table. The library wraps every backend: it checks
 * the result (residual and finiteness) and records statistics.
 */
#ifndef ODHS_SOLVER_H
#define ODHS_SOLVER_H

#include "odhs/network.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Version of odhs_solver_type understood by this library. Tables of an
 *  older version are accepted: the fields they lack count as NULL. */
#define ODHS_SOLVER_TYPE_VERSION 2

/* capability flags */
#define ODHS_SOLVER_ITERATIVE 0x1u /* result depends on a tolerance          */
#define ODHS_SOLVER_DIRECT 0x2u    /* factorisation-based                     */
#define ODHS_SOLVER_USES_GUESS 0x4u /* uses x on input as initial guess       */
#define ODHS_SOLVER_LEAST_SQUARES 0x8u /* solves on S^T without forming N   */

/**
 * A solver backend. Required: version, name, create, destroy, solve. Optional
 * (may be NULL; the library supplies defaults): setup, set_param, get_stat,
 * solve_ls. Fill it with designated initializers (.name = ...) so that fields
 * appended in later versions stay NULL; a table declaring an older version is
 * read only up to that version's fields.
 * Functions return ODHS_OK or an error code (ODHS_E_SINGULAR, ODHS_E_NOCONV,
 * ODHS_E_NOMEM, ...).
 */
typedef struct odhs_solver_type {
    int version;       /* ODHS_SOLVER_TYPE_VERSION                         */
    const char *name;  /* short unique name, e.g. "cg"                     */
    unsigned flags;    /* ODHS_SOLVER_* capability flags                   */
    /** Allocate the backend state. */
    int (*create)(void **state);
    /** Free the backend state (NULL-safe). */
    void (*destroy)(void *state);
    /** The network's contacts or geometry changed (called before solve
     *  whenever that happened since the last call). */
    int (*setup)(void *state, const odhs_network *net);
    /** Solve N x = b (b and x of length Nc). With ODHS_SOLVER_USES_GUESS, x
     *  holds an initial guess on input. Use the odhs_network_* functions to
     *  access S. */
    int (*solve)(void *state, const odhs_network *net, const double *b, double *x);
    /** Set a named numeric parameter; ODHS_E_INVALID for unknown names. */
    int (*set_param)(void *state, const char *key, double value);
    /** Get a named statistic of the last solve (e.g. "iterations"). */
    int (*get_stat)(void *state, const char *key, double *value);
    /* ---- version >= 2 ---- */
    /** Optional: the least-squares solution x of S^T x = g (g of length
     *  N*dim), i.e. N x = S g without forming N (better conditioned). The
     *  library supplies b = S g and calls solve when this is NULL. */
    int (*solve_ls)(void *state, const odhs_network *net, const double *g, double *x);
} odhs_solver_type;

/** Preconditioned (Jacobi) conjugate gradient, matrix-free on S S^T.
 *  Parameters: "tol" (relative residual, default 1e-12), "maxiter" (default
 *  0 = 10*Nc + 100). Statistics: "iterations". Warm-started from the previous
 *  forces by the stepper. */
ODHS_API extern const odhs_solver_type odhs_solver_type_cg;
/** CHOLMOD sparse Cholesky of N = S S^T, factored from S without forming N
 *  (only in builds with SuiteSparse; otherwise "cholmod" gives
 *  ODHS_E_NOTINSTALLED). The symbolic analysis is kept while the contact
 *  list is unchanged; a geometry change refactors numerically only. A
 *  non-positive pivot or a reciprocal condition estimate (cholmod_rcond)
 *  below "min_rcond" (default 1e-14) gives ODHS_E_SINGULAR. Parameters:
 *  "min_rcond", "supernodal" (0 simplicial, 1 supernodal, -1 automatic,
 *  the default), "openmp" (since 0.2.21; 0, the default: the OpenMP loops
 *  of CHOLMOD's supernodal factorisation run on the calling thread alone;
 *  1: on CHOLMOD's own threads, which Debian's build asks for 4 of per
 *  loop; the result is the same to the bit; the library reaches the OpenMP
 *  runtime that CHOLMOD loaded through weak references, so in a fully
 *  static link without them, or with a runtime older than GCC 11's libgomp
 *  (whose setting is per process, unsafe with solves in several threads),
 *  set OMP_THREAD_LIMIT=1 instead). Statistics: "analyses",
 *  "factorizations", "rcond", "nnz_L", "flops", "cholmod_status",
 *  "supernodal", "openmp". */
ODHS_API extern const odhs_solver_type odhs_solver_type_cholmod;
/** CHOLMOD factor as a preconditioner for CG ("cholmod-pcg"): a simplicial
 *  LDL' factor over stable contact slots, updated with CHOLMOD's Modify
 *  module (cholmod_rowadd / cholmod_rowdel; GPL-2.0-or-later) when contacts
 *  appear or disappear, and refactored after "refactor_every" geometry
 *  changes (default 50), when CG needs more than "refactor_iterations"
 *  (default 40), when the slots run out or the fill doubles, when the
 *  factor's allocation passes 4 times that of the fresh factor (since 0.2.19
 *  the factor is packed first when it passes 2.5 times), and when more
 *  than "update_max" (Nc + 64) contacts changed at once (default 0.125, in
 *  [0, 1]; since 0.2.14; the batched integrator lowers it to 1/256 inside
 *  its contact problems). Exact (one iteration) while the geometry is
 *  unchanged, e.g. during rewiring.
 *  Parameters: "tol" (default 1e-12), "maxiter", "min_rcond",
 *  "refactor_every", "refactor_iterations", "update_max", "supernodal"
 *  (0: full factorisations by the simplicial LDL' itself, the default up to
 *  0.2.20; since 0.2.20 also 1: by supernodes (LL' in dense blocks,
 *  converted to LDL'), and -1: by supernodes where the analysis predicts at
 *  least "supernodal_switch" flops per entry of L, the default since
 *  0.2.21), "supernodal_switch" (since 0.2.21, >= 0; default 200: by
 *  supernodes on 3D networks from about 1000 particles on, where that is
 *  2-2.5x cheaper for batched steps, simplicial on 2D ones up to N = 65536,
 *  where supernodes are 1.1-1.9x dearer; 150 also takes 3D networks of
 *  500-1000 particles, 1.5x cheaper at N = 600; docs/performance.md,
 *  0.2.21; 0.2.20's -1 used CHOLMOD's switch, 40), "openmp" (since
 *  0.2.21; as for "cholmod"), "ordering" (since 0.2.23; the fill-reducing
 *  ordering of the contact matrix: -1, the default, CHOLMOD's choice (AMD,
 *  and METIS too when AMD's factor has at least 500 flops per entry and 5
 *  times the entries of the matrix; the better of the two), 0 AMD, 1 METIS),
 *  "ordering_reuse" (since 0.2.23; -1, the default: on, with bound 1.1,
 *  after a fresh ordering that called METIS, off otherwise; 0: off, every
 *  analysis orders afresh, as up to 0.2.22; X >= 1: on, with bound X): an
 *  analysis for a changed contact set carries the last ordering over
 *  (contacts kept keep their rank, new contacts go last) instead of ordering
 *  afresh, while the fill per contact stays within the bound times that of the last
 *  fresh ordering; past it, the analysis orders afresh. METIS is the dear
 *  part of an analysis: on 3D networks from a few thousand particles this
 *  makes batched steps about 1.6x cheaper; where AMD alone orders, the
 *  carried orderings' extra fill (4-5 % more entries in L) made them 5-10 %
 *  dearer (docs/performance.md, 0.2.23). In a CHOLMOD built without METIS,
 *  "ordering" = 1 falls back to AMD (CHOLMOD's own backup). A new
 *  "supernodal", "supernodal_switch" or "ordering" takes effect at the next
 *  full factorisation after an analysis: at the next setup (the next change
 *  of the network) or a refactorisation inside a solve. Statistics:
 *  "iterations",
 *  "updates", "packs" (since 0.2.19), "supernodal" (since 0.2.20: 1 when
 *  the last full factorisation went by supernodes), "factorizations",
 *  "analyses", "rcond", "nnz_L", "flops" and "lnz" (since 0.2.21: the
 *  flops and the entries of L that the last analysis predicts; their ratio
 *  decides "supernodal" = -1), "orderings" (since 0.2.23: analyses that
 *  ordered afresh; "analyses" counts all, a carried one rejected as stale
 *  included), "capacity", and the parameters
 *  "tol", "update_max", "supernodal_switch", "openmp", "ordering",
 *  "ordering_reuse". */
ODHS_API extern const odhs_solver_type odhs_solver_type_cholmod_pcg;
/** SuiteSparseQR on A = S^T (only in builds with SuiteSparse; otherwise
 *  "spqr" gives ODHS_E_NOTINSTALLED): solve_ls computes the least-squares
 *  forces from Q^T g and R without forming N (the error grows with cond(S^T),
 *  not its square); solve uses x = E R^-1 R^-T E^T b. Rank detection: a
 *  numerical rank below Nc (a hyperstatic network: S^T has a null space)
 *  makes setup fail with ODHS_E_SINGULAR. Parameters: "tol" (rank tolerance;
 *  <= -2: SPQR's default 20 (m+n) eps max|col|; in (-2,0): off; >= 0:
 *  absolute), "ordering" (SPQR ordering 0-9 except 3). Statistics: "rank",
 *  "nc", "rank_deficiency", "tol_used", "symbolic", "numeric",
 *  "ordering_used". The symbolic analysis is kept while the contact pairs
 *  are unchanged. */
ODHS_API extern const odhs_solver_type odhs_solver_type_spqr;
/** Dense Cholesky of N through LAPACK dpotrf/dpotrs. Reports a non-positive
 *  pivot, or a reciprocal condition estimate (dpocon) below "min_rcond"
 *  (parameter, default 1e-14), as ODHS_E_SINGULAR: singular or hyperstatic
 *  networks. Statistics: "rcond", "lapack_info". O(Nc^3) per setup. */
ODHS_API extern const odhs_solver_type odhs_solver_type_dense;

/** Automatic choice with fallbacks ("auto"; in every build). The primary
 *  backend follows the number of contacts Nc: dense for Nc <= "dense_max"
 *  (-1, the default, means 16 with SuiteSparse and 400 without), else
 *  cholmod-pcg (or cholmod with "prefer" = 1) with SuiteSparse, cg without.
 *  When a backend reports ODHS_E_SINGULAR (non-positive or tiny pivot,
 *  condition estimate below its min_rcond, backward error above the check
 *  tolerance), ODHS_E_NOCONV or ODHS_E_NOMEM, the next one is tried: spqr
 *  with SuiteSparse (least squares on S^T, rank-revealing); without it dense
 *  (after cg, for Nc <= "dense_fallback_max", default 4000); last the
 *  minimum-norm least-squares forces x = (S^T)^+ g (= N^+ b for b = S g),
 *  the answer on a rank-deficient (hyperstatic) network, where the
 *  least-squares forces are not unique: backend "lsq-svd" (truncated SVD,
 *  Nc <= "lsq_dense_max", default 600; rank from SuiteSparseQR when it ran,
 *  else singular values above "lsq_rcond" (default 1e-9) times the largest,
 *  of S^T for odhs_solver_solve_ls and of N, with the threshold squared but
 *  at least 1e-13, for odhs_solver_solve; on N since 0.2.17 from its
 *  eigendecomposition, LAPACK dsyevd, a fifth of the SVD's cost, the SVD
 *  if that fails) or, above lsq_dense_max, "lsq-pcg"
 *  (since 0.2.16, SuiteSparse builds: CG from zero preconditioned by a
 *  CHOLMOD factor of N + beta I, beta = 1e-6 max diag N; a few iterations,
 *  minimum norm to about 1e-10 relative; it gives up after 50 iterations
 *  without halving the residual, the sign of an inconsistent system, and
 *  lsq-cg is then not tried) and "lsq-cg" (CG from zero). The
 *  backend that answered after a fallback is tried first for the next
 *  "retry_after" solves (default 20); a least-squares backend only for
 *  the next "retry_after_lsq" solves (since 0.2.13; default 0: the primary is
 *  tried again at once, since an SVD costs far more than a failed Cholesky
 *  and a rank-deficient network seldom outlives a step: 1.5-1.7x less CPU for
 *  fixed-pressure shear at 2D N = 256, p = 1e4). Inner backends run behind their own
 *  wrappers (result check, iterative refinement); their check tolerance is
 *  the parameter "check_tol" (default 1e-6). "suitesparse" = 0 makes a
 *  SuiteSparse build choose as a build without it (1 in a build without
 *  gives ODHS_E_NOTINSTALLED). "tol" (since 0.2) is handed to the iterative
 *  backends cg and cholmod-pcg (their relative residual; default theirs,
 *  1e-12); "update_max" (since 0.2.14), "supernodal" (since 0.2.20),
 *  "supernodal_switch" (since 0.2.21), "ordering" and "ordering_reuse"
 *  (since 0.2.23) to cholmod-pcg; "openmp" (since
 *  0.2.21) to cholmod and cholmod-pcg. Statistics: "backend" and "primary" (codes
 *  0 cg, 1 dense, 2 cholmod, 3 cholmod-pcg, 4 spqr, 5 lsq-svd, 6 lsq-cg,
 *  7 lsq-pcg (since 0.2.16); -1
 *  before the first solve), "fallbacks" (failed attempts followed by another
 *  backend), "fallback_solves" (solves not answered by the primary),
 *  "rank_deficient" (solves answered by lsq-*), "last_failure" (status of
 *  the last failed attempt), "suitesparse", and those of the backend that
 *  answered last ("rank" after lsq-*). See odhs_solver_backend_name. */
ODHS_API extern const odhs_solver_type odhs_solver_type_auto;

typedef struct odhs_solver odhs_solver; /* struct tag declared in network.h */

/** Create a solver handle for a backend type (user or built-in). The table
 *  must outlive the handle. ODHS_E_INVALID for a malformed table (version
 *  not in 1..ODHS_SOLVER_TYPE_VERSION, or no name, create, destroy or
 *  solve); odhs_last_error() says which (as for every failure here). */
ODHS_API int odhs_solver_create(const odhs_solver_type *type, odhs_solver **out);
/** Create a built-in solver by name: "cg", "dense", "auto", and with
 *  SuiteSparse "cholmod", "cholmod-pcg", "spqr". Names of backends not built into this
 *  library give ODHS_E_NOTINSTALLED; unknown names ODHS_E_INVALID. */
ODHS_API int odhs_solver_create_by_name(const char *name, odhs_solver **out);
/**
 * The k-th built-in solver name (k = 0, 1, ... until ODHS_E_RANGE), in the
 * order "auto", "cholmod", "cholmod-pcg", "spqr", "cg", "dense"; *installed
 * (may be NULL) is 1 when this library was built with it (0: the name gives
 * ODHS_E_NOTINSTALLED). *name is a static string. Since 0.2.7.
 *     for (size_t k = 0; odhs_solver_list(k, &name, &ok) == ODHS_OK; ++k) ...
 */
ODHS_API int odhs_solver_list(size_t k, const char **name, int *installed);
/** Destroy; NULL is a no-op. */
ODHS_API void odhs_solver_destroy(odhs_solver *s);
/** Last error message ("" if none). */
ODHS_API const char *odhs_solver_errmsg(const odhs_solver *s);
/** Backend name. */
ODHS_API const char *odhs_solver_name(const odhs_solver *s);
/**
 * The backend that produced the last solution: for an "auto" handle the one
 * it chose or fell back to ("cg", "dense", "cholmod", "cholmod-pcg", "spqr",
 * "lsq-svd", "lsq-pcg" (since 0.2.16), "lsq-cg"; "auto" before its first
 * solve), for any other handle
 * its own name. *why (why may be NULL) receives a description of the
 * fallbacks of the last solve ("cholmod-pcg failed (...) -> spqr"), "" when
 * there was none; after a failed solve it lists every attempt. Both strings
 * live until the next solve or the destruction of the handle.
 * ODHS_E_NULL for a NULL handle or name.
 */
ODHS_API int odhs_solver_backend_name(const odhs_solver *s, const char **name, const char **why);
/** Set a backend parameter (see each backend). */
ODHS_API int odhs_solver_set_param(odhs_solver *s, const char *key, double value);
/**
 * Statistics: "iterations" (backend), "residual" (relative residual
 * |N x - b| / |b| of the last solve, computed by the library),
 * "backward_error" (|N x - b| / (|N| |x| + |b|) with |N| bounded by twice the
 * largest particle degree), "solves" (count), and with a fallback (see
 * odhs_solver_set_fallback) "chain_fallbacks", "chain_rescued",
 * "chain_last".
 */
ODHS_API int odhs_solver_get_stat(const odhs_solver *s, const char *key, double *value);
/** Set the normwise backward error above which a solve is reported as failed
 *  (default 1e-6; ODHS_E_NOCONV for iterative, ODHS_E_SINGULAR for direct).
 *  The backward error, not the relative residual, is checked: close to
 *  jamming a good solution has a relative residual of order eps cond(N). */
ODHS_API int odhs_solver_set_check_tolerance(odhs_solver *s, double tol);
/**
 * Iterative refinement for direct (non-iterative) backends: after a solve
 * whose relative residual is above 1e-14, x += N^-1 (b - N x) up to `steps`
 * times while it improves (default 3; 0 turns it off). It keeps direct
 * solves accurate on ill-conditioned networks close to jamming.
 */
ODHS_API int odhs_solver_set_refinement(odhs_solver *s, int steps);

/**
 * Opt-in recovery from numerical failure: when a solve of s fails with
 * ODHS_E_NOCONV (an iterative backend did not converge, e.g. "cg" with a
 * small "maxiter" on a stiff network close to jamming) or ODHS_E_SINGULAR
 * (singular or indefinite operator, or a backward error above the check
 * tolerance), the same problem is solved again with `fallback` (its own
 * fallback in turn, if it has one). If the fallback succeeds the solve
 * returns ODHS_OK with its result (the "residual" and "backward_error"
 * statistics are the fallback's) and the error message of s records what
 * happened; otherwise the fallback's error is returned. Other errors
 * (NULL, non-finite input, out of memory) are returned as they are.
 * Statistics of s: "chain_fallbacks" (solves handed to the fallback),
 * "chain_rescued" (of those, solved by it), "chain_last" (1 if the last
 * solve was handed over, else 0). The fallback is borrowed: it must outlive
 * s (or be removed first) and must not be used concurrently by another
 * thread. NULL removes it (the default). ODHS_E_INVALID if the chain of
 * fallbacks would lead back to s. Typical use: a "cg" solver with a "dense"
 * (small systems) or "cholmod" fallback.
 */
ODHS_API int odhs_solver_set_fallback(odhs_solver *s, odhs_solver *fallback);

/**
 * Solve N x = b on the network's current geometry. The backend's setup runs
 * first whenever the operator differs from the one last set up (another
 * network, a change of contacts or geometry, or a new network at a freed
 * one's address: a checksum of the contacts and normals decides). x holds the initial guess for
 * backends that use one (pass zeros otherwise). The "residual" statistic is
 * recorded even when the solve fails.
 */
ODHS_API int odhs_solver_solve(odhs_solver *s, const odhs_network *net, const double *b, double *x);
/**
 * Least-squares contact forces: x minimising |S^T x - g| (g has N*dim
 * entries), the same x as N x = S g. Uses the backend's solve_ls when it has
 * one (no squared condition number), otherwise forms b = S g and solves.
 * The "residual" statistic is that of N x = S g.
 */
ODHS_API int odhs_solver_solve_ls(odhs_solver *s, const odhs_network *net, const double *g, double *x);

#ifdef __cplusplus
}
#endif
#endif /* ODHS_SOLVER_H */
