/*
 * libodhs private header: the solver handle and the solves the library makes through it.
 * Not installed.
 */
#ifndef ODHS_SOLVERS_SOLVERS_H
#define ODHS_SOLVERS_SOLVERS_H

#include "network/network.h"

/* ---- solver handle ----------------------------------------------------------- */
struct odhs_solver {
    const odhs_solver_type *type;
    void *state;
    const odhs_network *last_net;
    uint64_t last_version;
    uint64_t last_sum; /* checksum of the operator last set up (public path) */
    int have_setup;
    double check_tol;
    int refine;        /* iterative refinement steps for direct backends */
    double last_residual;
    double last_backward; /* normwise backward error of the last solve */
    double nsolves;
    double *work;    /* residual check */
    size_t work_cap;
    /* fallback (odhs_solver_set_fallback): borrowed solver tried when a solve
     * fails with ODHS_E_NOCONV or ODHS_E_SINGULAR */
    struct odhs_solver *fallback;
    double nfallbacks, nrescued; /* solves handed over / rescued by it */
    int last_fallback;           /* the last solve was handed over */
    char errmsg[ODHS_ERRMSG_LEN];
};

/* Solve N x = b. reuse = 1: skip the backend setup when this network's
 * version is the one last set up (callers that own the network and call
 * odhs__solver_invalidate when it may have been replaced); reuse = 0: set up
 * whenever the backend has a setup. */
int odhs__solver_solve(odhs_solver *s, const odhs_network *net, const double *b, double *x, int reuse);
/* the same with a relative residual of rtol where the backend has a "tol".
 * A scratch network (one made for this solve and destroyed after it) needs
 * reuse = 0: a new one can get the address and version of the last one
 * solved, and reuse = 1 would then keep that one's setup (the results then
 * depended on the heap's history) */
int odhs__solver_solve_relaxed(odhs_solver *s, const odhs_network *net, const double *b, double *x, double rtol,
                               int reuse);
void odhs__solver_invalidate(odhs_solver *s);
/* set a backend parameter for a while (where the backend has it, quietly):
 * 1 when set, with its value before in *old, for odhs__solver_pop_param */
int odhs__solver_push_param(odhs_solver *s, const char *key, double v, double *old);
void odhs__solver_pop_param(odhs_solver *s, const char *key, int pushed, double old);

#ifdef ODHS_HAVE_SUITESPARSE
/* "lsq-pcg" (lsq_pcg.c): minimum-norm solutions of singular N x = b by CG
 * preconditioned with a factor of N + beta I; the auto solver's
 * least-squares route above lsq_dense_max contacts (since 0.2.16) */
extern const odhs_solver_type odhs__solver_type_lsq_pcg;
#endif

#endif /* ODHS_SOLVERS_SOLVERS_H */
