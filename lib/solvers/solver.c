/* libodhs - solver handle: wraps a backend table, checks every result. */
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "solvers/solvers.h"

static int solerr(const odhs_solver *s, int status, const char *fmt, ...) ODHS_PRINTF(3, 4);
static int solerr(const odhs_solver *s, int status, const char *fmt, ...)
{
    if (!s) return status;
    va_list ap;
    va_start(ap, fmt);
    odhs__verr(((odhs_solver *)s)->errmsg, status, fmt, ap);
    va_end(ap);
    return status;
}

static int solver_create_impl(const odhs_solver_type *type, odhs_solver **out)
{
    if (!out) return odhs__create_err(ODHS_E_NULL, "odhs_solver_create: out is NULL");
    *out = NULL;
    if (!type) return odhs__create_err(ODHS_E_NULL, "odhs_solver_create: solver type is NULL");
    if (type->version < 1 || type->version > ODHS_SOLVER_TYPE_VERSION)
        return odhs__create_err(ODHS_E_INVALID,
                                "odhs_solver_create: solver type version %d is not in 1..%d (set ODHS_SOLVER_TYPE_VERSION)",
                                type->version, ODHS_SOLVER_TYPE_VERSION);
    if (!type->name || !type->create || !type->destroy || !type->solve)
        return odhs__create_err(ODHS_E_INVALID, "odhs_solver_create: the solver type has no %s (name, create, destroy "
                                "and solve are required)",
                                !type->name ? "name" : !type->create ? "create" : !type->destroy ? "destroy" : "solve");
    odhs_solver *s = odhs__calloc(1, sizeof *s);
    if (!s) return odhs__create_err(ODHS_E_NOMEM, "odhs_solver_create: out of memory");
    s->type = type;
    s->check_tol = 1e-6;
    s->refine = 3;
    int st = type->create(&s->state);
    if (st) {
        odhs__free(s);
        return odhs__create_err(st < 0 ? st : ODHS_E_INTERNAL, "odhs_solver_create: %s's create returned %d",
                                type->name, st);
    }
    *out = s;
    return ODHS_OK;
}

int odhs_solver_create(const odhs_solver_type *type, odhs_solver **out)
{
    odhs__create_begin();
    return odhs__create_end(solver_create_impl(type, out));
}

/* the built-in solvers by name, in the order odhs_solver_list gives them */
static const struct {
    const char *name;
    const odhs_solver_type *type; /* NULL: not built into this library */
} builtin[] = {
    {"auto", &odhs_solver_type_auto}, /* lib/solvers/auto.c */
    {"cholmod",
#ifdef ODHS_HAVE_SUITESPARSE
     &odhs_solver_type_cholmod
#else
     NULL
#endif
    },
    {"cholmod-pcg",
#ifdef ODHS_HAVE_SUITESPARSE
     &odhs_solver_type_cholmod_pcg
#else
     NULL
#endif
    },
    {"spqr",
#ifdef ODHS_HAVE_SUITESPARSE
     &odhs_solver_type_spqr
#else
     NULL
#endif
    },
    {"cg", &odhs_solver_type_cg},
    {"dense", &odhs_solver_type_dense},
};
#define NBUILTIN (sizeof builtin / sizeof builtin[0])

int odhs_solver_list(size_t k, const char **name, int *installed)
{
    if (!name) return ODHS_E_NULL;
    *name = NULL;
    if (k >= NBUILTIN) return ODHS_E_RANGE;
    *name = builtin[k].name;
    if (installed) *installed = builtin[k].type != NULL;
    return ODHS_OK;
}

static int solver_create_by_name_impl(const char *name, odhs_solver **out)
{
    if (!out) return odhs__create_err(ODHS_E_NULL, "odhs_solver_create_by_name: out is NULL");
    *out = NULL;
    if (!name) return odhs__create_err(ODHS_E_NULL, "odhs_solver_create_by_name: name is NULL");
    char known[128] = "";
    size_t used = 0;
    for (size_t k = 0; k < NBUILTIN; ++k) {
        if (!strcmp(name, builtin[k].name)) {
            if (!builtin[k].type)
                return odhs__create_err(ODHS_E_NOTINSTALLED,
                                        "odhs_solver_create_by_name: \"%s\" is not built into this library (built "
                                        "without SuiteSparse; rebuild with SUITESPARSE=1)",
                                        name);
            return solver_create_impl(builtin[k].type, out);
        }
        if (builtin[k].type && used < sizeof known) {
            int w = snprintf(known + used, sizeof known - used, "%s%s", used ? ", " : "", builtin[k].name);
            if (w > 0) used += (size_t)w;
        }
    }
    return odhs__create_err(ODHS_E_INVALID,
                            "odhs_solver_create_by_name: unknown solver \"%.64s\" (names are case-sensitive; this "
                            "library has: %s)",
                            name, known);
}

int odhs_solver_create_by_name(const char *name, odhs_solver **out)
{
    odhs__create_begin();
    return odhs__create_end(solver_create_by_name_impl(name, out));
}

void odhs_solver_destroy(odhs_solver *s)
{
    if (!s) return;
    s->type->destroy(s->state);
    odhs__free(s->work);
    odhs__free(s);
}

const char *odhs_solver_errmsg(const odhs_solver *s) { return s ? s->errmsg : ""; }
const char *odhs_solver_name(const odhs_solver *s) { return s ? s->type->name : ""; }

int odhs_solver_set_param(odhs_solver *s, const char *key, double value)
{
    if (!s) return ODHS_E_NULL;
    s->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!key) return solerr(s, ODHS_E_NULL, "parameter name is NULL");
    if (!isfinite(value)) return solerr(s, ODHS_E_NONFINITE, "parameter %s is not finite", key);
    if (!s->type->set_param) return solerr(s, ODHS_E_INVALID, "backend %s has no parameters", s->type->name);
    int st = s->type->set_param(s->state, key, value);
    if (st) return solerr(s, st, "backend %s rejected parameter %s = %g", s->type->name, key, value);
    return ODHS_OK;
}

int odhs_solver_get_stat(const odhs_solver *s, const char *key, double *value)
{
    if (!s) return ODHS_E_NULL;
    if (!key || !value) return solerr(s, ODHS_E_NULL, "NULL argument");
    if (!strcmp(key, "residual")) {
        *value = s->last_residual;
        return ODHS_OK;
    }
    if (!strcmp(key, "backward_error")) {
        *value = s->last_backward;
        return ODHS_OK;
    }
    if (!strcmp(key, "solves")) {
        *value = s->nsolves;
        return ODHS_OK;
    }
    if (!strcmp(key, "chain_fallbacks")) {
        *value = s->nfallbacks;
        return ODHS_OK;
    }
    if (!strcmp(key, "chain_rescued")) {
        *value = s->nrescued;
        return ODHS_OK;
    }
    if (!strcmp(key, "chain_last")) {
        *value = s->last_fallback;
        return ODHS_OK;
    }
    if (s->type->get_stat && s->type->get_stat(s->state, key, value) == ODHS_OK) return ODHS_OK;
    return solerr(s, ODHS_E_INVALID, "unknown statistic %s", key);
}

int odhs_solver_set_refinement(odhs_solver *s, int steps)
{
    if (!s) return ODHS_E_NULL;
    s->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (steps < 0 || steps > 100) return solerr(s, ODHS_E_INVALID, "refinement steps must be in [0, 100]");
    s->refine = steps;
    return ODHS_OK;
}

int odhs_solver_set_check_tolerance(odhs_solver *s, double tol)
{
    if (!s) return ODHS_E_NULL;
    s->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(tol) || !(tol > 0.0)) return solerr(s, ODHS_E_INVALID, "check tolerance must be > 0");
    s->check_tol = tol;
    return ODHS_OK;
}

void odhs__solver_invalidate(odhs_solver *s)
{
    if (s) s->have_setup = 0;
}

int odhs_solver_solve(odhs_solver *s, const odhs_network *net, const double *b, double *x)
{
    return odhs__solver_solve(s, net, b, x, 0);
}

/* FNV-1a over the contact pattern and geometry: identifies the operator even
 * when a destroyed network's address is reused by a new one */
static uint64_t net_checksum(const odhs_network *net)
{
    uint64_t h = 1469598103934665603ULL;
    const unsigned char *p[3] = {(const unsigned char *)net->ci, (const unsigned char *)net->cj,
                                 (const unsigned char *)net->nrm};
    size_t len[3] = {net->nc * sizeof *net->ci, net->nc * sizeof *net->cj,
                     net->nc * (size_t)net->dim * sizeof *net->nrm};
    for (int a = 0; a < 3; ++a)
        for (size_t k = 0; k < len[a]; ++k) {
            h ^= p[a][k];
            h *= 1099511628211ULL;
        }
    return h ^ net->nc;
}

/* the work space holds at least need doubles */
static int reserve_work(odhs_solver *s, size_t need)
{
    if (s->work_cap < need) {
        double *w = odhs__realloc(s->work, need * sizeof *w);
        if (!w) return solerr(s, ODHS_E_NOMEM, "out of memory");
        s->work = w;
        s->work_cap = need;
    }
    return ODHS_OK;
}

/* the right-hand side must be finite; given g, *b becomes bg = S g */
static int check_rhs(odhs_solver *s, const odhs_network *net, const double *g, const double **b, double *bg)
{
    size_t nc = net->nc, nd = net->n * (size_t)net->dim;
    if (g) {
        for (size_t k = 0; k < nd; ++k)
            if (!isfinite(g[k])) return solerr(s, ODHS_E_NONFINITE, "right-hand side entry %zu is not finite", k);
        odhs__net_S(net, g, bg);
        *b = bg;
    } else {
        for (size_t c = 0; c < nc; ++c)
            if (!isfinite((*b)[c])) return solerr(s, ODHS_E_NONFINITE, "right-hand side entry %zu is not finite", c);
    }
    return ODHS_OK;
}

/* set the backend up for net unless it already is (same network, version
 * and, without reuse, the same contact pattern and geometry) */
static int setup_backend(odhs_solver *s, const odhs_network *net, int reuse)
{
    int st;
    uint64_t sum = (reuse || !s->type->setup) ? 0 : net_checksum(net);
    if (s->type->setup && (!s->have_setup || s->last_net != net || s->last_version != net->version ||
                           (!reuse && sum != s->last_sum))) {
        st = s->type->setup(s->state, net);
        if (st) {
            s->have_setup = 0;
            return solerr(s, st < 0 ? st : ODHS_E_INTERNAL, "%s: setup failed (%s)", s->type->name,
                          odhs_strerror(st));
        }
        s->have_setup = 1;
        s->last_net = net;
        s->last_version = net->version;
        s->last_sum = sum;
    }
    return ODHS_OK;
}

/* the starting point: x itself for backends that use a guess, unless it
 * is not finite; zero otherwise */
static void start_guess(const odhs_solver *s, double *x, size_t nc)
{
    if (!(s->type->flags & ODHS_SOLVER_USES_GUESS)) memset(x, 0, nc * sizeof *x);
    else
        for (size_t c = 0; c < nc; ++c)
            if (!isfinite(x[c])) { /* an unusable guess: start from zero */
                memset(x, 0, nc * sizeof *x);
                break;
            }
}

/* iterative refinement for direct backends on ill-conditioned networks
 * (close to jamming): x += N^-1 (b - N x), a few times at most; Nx = N x
 * on entry and on return */
static int refine_solution(odhs_solver *s, const odhs_network *net, const double *b, double *x, double *Nx,
                           double *tmp, double bn)
{
    size_t nc = net->nc;
    double *r = odhs__malloc_array(2 * nc, sizeof *r);
    if (!r) return solerr(s, ODHS_E_NOMEM, "%s: out of memory for iterative refinement", s->type->name);
    for (int pass = 0; pass < s->refine && s->last_residual > 1e-14; ++pass) {
        double *dx = r + nc;
        for (size_t c = 0; c < nc; ++c) r[c] = b[c] - Nx[c];
        memset(dx, 0, nc * sizeof *dx);
        if (s->type->solve(s->state, net, r, dx) != ODHS_OK) break;
        for (size_t c = 0; c < nc; ++c) dx[c] += x[c];
        odhs__net_N(net, dx, Nx, tmp);
        double rn2 = 0.0;
        for (size_t c = 0; c < nc; ++c) rn2 += (Nx[c] - b[c]) * (Nx[c] - b[c]);
        double res2 = bn > 0.0 ? sqrt(rn2 / bn) : sqrt(rn2);
        if (!(res2 < s->last_residual)) {
            odhs__net_N(net, x, Nx, tmp); /* keep the better x */
            break;
        }
        memcpy(x, dx, nc * sizeof *x);
        s->last_residual = res2;
    }
    odhs__free(r);
    return ODHS_OK;
}

/* accept on the normwise backward error |r| / (|N| |x| + |b|): close to
 * jamming cond(N) is huge and even an exact-arithmetic-quality solution
 * has a relative residual of order eps cond(N); |N|_2 <= 2 max degree */
static int check_backward(odhs_solver *s, const odhs_network *net, const double *x, double bn)
{
    size_t nc = net->nc;
    size_t maxdeg = 1;
    for (size_t i = 0; i < net->n; ++i) maxdeg = net->adjn[i] > maxdeg ? net->adjn[i] : maxdeg;
    double xn = 0.0;
    for (size_t c = 0; c < nc; ++c) xn += x[c] * x[c];
    double rnorm = s->last_residual * (bn > 0.0 ? sqrt(bn) : 1.0);
    double den = 2.0 * (double)maxdeg * sqrt(xn) + sqrt(bn);
    s->last_backward = den > 0.0 ? rnorm / den : rnorm;
    if (s->last_backward > s->check_tol) {
        int code = (s->type->flags & ODHS_SOLVER_ITERATIVE) ? ODHS_E_NOCONV : ODHS_E_SINGULAR;
        return solerr(s, code, "%s: backward error %.3g above %.3g (relative residual %.3g)", s->type->name,
                      s->last_backward, s->check_tol, s->last_residual);
    }
    return ODHS_OK;
}

/* The one solve path: b given (N x = b), or g given (least squares on S^T,
 * b = S g). Sets up the backend when needed and checks the result. */
static int solve_one(odhs_solver *s, const odhs_network *net, const double *b, const double *g, double *x,
                     int reuse)
{
    if (!s) return ODHS_E_NULL;
    if (!net) return solerr(s, ODHS_E_NULL, "network is NULL");
    size_t nc = net->nc, nd = net->n * (size_t)net->dim;
    if (nc == 0) return ODHS_OK;
    if ((!b && !g) || !x) return solerr(s, ODHS_E_NULL, "vector pointer is NULL");
    int st = reserve_work(s, 2 * nc + nd);
    if (st) return st;
    double *Nx = s->work, *tmp = s->work + nc, *bg = s->work + nc + nd;
    if ((st = check_rhs(s, net, g, &b, bg))) return st;
    if ((st = setup_backend(s, net, reuse))) return st;
    start_guess(s, x, nc);
    if (g && s->type->version >= 2 && s->type->solve_ls) st = s->type->solve_ls(s->state, net, g, x);
    else st = s->type->solve(s->state, net, b, x);
    s->nsolves += 1.0;
    /* check the result: finite, small residual (also recorded after a failure) */
    for (size_t c = 0; c < nc; ++c)
        if (!isfinite(x[c])) {
            s->last_residual = INFINITY;
            return solerr(s, st < 0 ? st : ODHS_E_SINGULAR, "%s: solution is not finite (singular network?)",
                          s->type->name);
        }
    odhs__net_N(net, x, Nx, tmp);
    double rn = 0.0, bn = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        double r = Nx[c] - b[c];
        rn += r * r;
        bn += b[c] * b[c];
    }
    s->last_residual = bn > 0.0 ? sqrt(rn / bn) : sqrt(rn);
    if (st == ODHS_OK && s->refine > 0 && !(s->type->flags & ODHS_SOLVER_ITERATIVE)) {
        int rs = refine_solution(s, net, b, x, Nx, tmp, bn);
        if (rs) return rs;
    }
    if (st < 0)
        return solerr(s, st, "%s: solve failed (%s), relative residual %.3g", s->type->name, odhs_strerror(st),
                      s->last_residual);
    return check_backward(s, net, x, bn);
}

/* ---- fallback (odhs_solver_set_fallback) ------------------------------------ */
int odhs_solver_set_fallback(odhs_solver *s, odhs_solver *fallback)
{
    if (!s) return ODHS_E_NULL;
    s->errmsg[0] = '\0'; /* a successful call leaves no message */
    for (const odhs_solver *f = fallback; f; f = f->fallback)
        if (f == s) return solerr(s, ODHS_E_INVALID, "fallback would form a cycle back to %s", s->type->name);
    s->fallback = fallback;
    return ODHS_OK;
}

/* solve_one, then on a numerical failure (no convergence, singular or
 * indefinite operator) the same problem with the fallback chain */
static int solve_any(odhs_solver *s, const odhs_network *net, const double *b, const double *g, double *x,
                     int reuse)
{
    if (s) s->last_fallback = 0;
    int st = solve_one(s, net, b, g, x, reuse);
    if (!s || !s->fallback || (st != ODHS_E_NOCONV && st != ODHS_E_SINGULAR)) return st;
    odhs_solver *fb = s->fallback;
    s->last_fallback = 1;
    s->nfallbacks += 1.0;
    char why[ODHS_ERRMSG_LEN];
    snprintf(why, sizeof why, "%s", s->errmsg);
    int fs = solve_any(fb, net, b, g, x, 0);
    s->last_residual = fb->last_residual;
    s->last_backward = fb->last_backward;
    if (fs == ODHS_OK) {
        s->nrescued += 1.0;
        solerr(s, ODHS_OK, "%s; solved by the fallback %s", why, fb->type->name);
        return ODHS_OK;
    }
    return solerr(s, fs, "%s; the fallback %s failed too: %s", why, fb->type->name, fb->errmsg);
}

int odhs__solver_solve(odhs_solver *s, const odhs_network *net, const double *b, double *x, int reuse)
{
    return solve_any(s, net, b, NULL, x, reuse);
}

/* A solve that needs only a relative residual of rtol (e.g. the drift
 * correction: the gaps it removes are ~1e-12 and a residual of 1e-7 leaves
 * ~1e-19). Backends with a "tol" parameter (cg, cholmod-pcg, auto) stop
 * there for this call; the others solve as always. rtol is kept at least a
 * factor 10 below the result check's tolerance. */
int odhs__solver_solve_relaxed(odhs_solver *s, const odhs_network *net, const double *b, double *x, double rtol,
                               int reuse)
{
    double cur;
    const odhs_solver_type *t = s->type;
    rtol = fmin(rtol, 0.1 * s->check_tol);
    if (!t->set_param || !t->get_stat || t->get_stat(s->state, "tol", &cur) != ODHS_OK || !(rtol > cur) ||
        t->set_param(s->state, "tol", rtol) != ODHS_OK)
        return odhs__solver_solve(s, net, b, x, reuse);
    int st = odhs__solver_solve(s, net, b, x, reuse);
    t->set_param(s->state, "tol", cur);
    return st;
}

int odhs__solver_push_param(odhs_solver *s, const char *key, double v, double *old)
{
    const odhs_solver_type *t = s->type;
    if (!t->set_param || !t->get_stat || t->get_stat(s->state, key, old) != ODHS_OK) return 0;
    return t->set_param(s->state, key, v) == ODHS_OK;
}

void odhs__solver_pop_param(odhs_solver *s, const char *key, int pushed, double old)
{
    if (pushed) s->type->set_param(s->state, key, old);
}

int odhs_solver_solve_ls(odhs_solver *s, const odhs_network *net, const double *g, double *x)
{
    if (s && !g) return solerr(s, ODHS_E_NULL, "vector pointer is NULL");
    return solve_any(s, net, NULL, g, x, 0);
}
