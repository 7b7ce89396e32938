/*
 * libodhs - soft-core reference models (Vagberg's thesis, ch. 4): RD0, CD0,
 * quasistatic shear with steepest descent / FIRE / Polak-Ribiere CG, and the
 * massive RD, CD, CD_n, CD_t models with SLLOD. See include/odhs/softcore.h.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "network/network.h"

struct odhs_softcore {
    odhs_system *sys;
    int dim;
    size_t n, nd;
    /* settings */
    int model;
    double alpha, ke, kd, k0, mass, gdot;
    int integ;
    double cdt, tol;
    int minimiser;
    double gtol;
    uint64_t maxit;
    double ltol;
    /* state */
    double time, strain;
    uint64_t nsteps, nforce, nmin;
    double h_ad;         /* adaptive: current step (0 = not started) */
    double *u;           /* non-affine velocities (nd) */
    double *F;           /* elastic forces of the last evaluation (nd) */
    int fc_ok;           /* massive: F and the contact list belong to sys->x */
    double *w1, *w2, *w3, *w4, *w5; /* nd work */
    double *xs, *us;     /* rollback snapshot (nd) */
    double *xw;          /* nd work for the pair builder */
    double dmin, lambda; /* smallest and mean diameter */
    /* neighbour (Verlet) list */
    size_t *pi, *pj;
    uint64_t *pk;        /* sort keys i*n + j (pkcap) */
    size_t np, pcap, pkcap;
    double skin;
    double *xb;          /* positions at the last build */
    double strain_b;
    int nb_ok;
    /* overlapping pairs of the last elastic evaluation */
    size_t *ci, *cj;
    double *cr;          /* separations (ccap*dim) */
    size_t nc, ccap;
    /* CD0 solve work (n each) */
    double *g_r, *g_z, *g_p, *g_q, *g_diag, *g_b, *g_x;
    double *relax;       /* dim*dim: integral of sigma dt over the last SD relaxation */
    double relax_acc[9];
    int has_relax;
    uint64_t nforce_s;   /* snapshot of the counter (rollback) */
    int fc_ok_s;
    double h_ad_s;
    char errmsg[ODHS_ERRMSG_LEN];
};

ODHS_PRINTF(3, 4)
static int scerr(const odhs_softcore *sc, int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int s = odhs__verr(((odhs_softcore *)sc)->errmsg, status, fmt, ap);
    va_end(ap);
    return s;
}

static int is_massive(int model) { return model >= ODHS_SOFTCORE_RD; }

/* ---- neighbour list ------------------------------------------------------------ */
static int nb_push(size_t i, size_t j, const double *rij, double gap, void *ctx)
{
    (void)rij;
    (void)gap;
    odhs_softcore *sc = ctx;
    if (sc->np == sc->pcap) {
        size_t cap = sc->pcap ? 2 * sc->pcap : 64;
        size_t *a = odhs__realloc(sc->pi, cap * sizeof *a);
        if (!a) return 1;
        sc->pi = a;
        size_t *b = odhs__realloc(sc->pj, cap * sizeof *b);
        if (!b) return 1;
        sc->pj = b;
        sc->pcap = cap;
    }
    sc->pi[sc->np] = i;
    sc->pj[sc->np] = j;
    sc->np++;
    return 0;
}

static int key_cmp(const void *a, const void *b)
{
    uint64_t u = *(const uint64_t *)a, v = *(const uint64_t *)b;
    return (u > v) - (u < v);
}

static int nb_build(odhs_softcore *sc, const double *x)
{
    odhs_system *sys = sc->sys;
    int d = sc->dim;
    memcpy(sc->xw, x, sc->nd * sizeof *x);
    for (size_t i = 0; i < sc->n; ++i) odhs__wrap(d, sys->L, sys->gamma, sc->xw + i * d);
    sc->np = 0;
    int s = odhs__pairs(d, sc->n, sc->xw, sys->r, sys->rmax, sys->L, sys->gamma, sc->skin, nb_push, sc);
    if (s == ODHS_STOPPED) s = ODHS_E_NOMEM;
    if (s == ODHS_OK && sc->np > sc->pkcap) {
        uint64_t *k = odhs__realloc(sc->pk, sc->pcap * sizeof *k);
        if (!k) s = ODHS_E_NOMEM;
        else {
            sc->pk = k;
            sc->pkcap = sc->pcap;
        }
    }
    if (s != ODHS_OK) {
        sc->nb_ok = 0;
        return scerr(sc, s, "neighbour list: %s", odhs_strerror(s));
    }
    /* a fixed order (by pair) makes every sum independent of where and when
     * the list was built: pairs that do not overlap contribute exact zeros */
    for (size_t p = 0; p < sc->np; ++p) sc->pk[p] = (uint64_t)sc->pi[p] * sc->n + sc->pj[p];
    qsort(sc->pk, sc->np, sizeof *sc->pk, key_cmp);
    for (size_t p = 0; p < sc->np; ++p) {
        sc->pi[p] = (size_t)(sc->pk[p] / sc->n);
        sc->pj[p] = (size_t)(sc->pk[p] % sc->n);
    }
    memcpy(sc->xb, x, sc->nd * sizeof *x);
    sc->strain_b = sc->strain;
    sc->nb_ok = 1;
    return ODHS_OK;
}

/* make sure the list holds every pair that can overlap at positions x */
static int nb_check(odhs_softcore *sc, const double *x)
{
    if (!sc->nb_ok) return nb_build(sc, x);
    odhs_system *sys = sc->sys;
    int d = sc->dim;
    double m2 = 0.0;
    for (size_t i = 0; i < sc->n; ++i) {
        double v[3] = {0, 0, 0};
        for (int k = 0; k < d; ++k) v[k] = x[i * d + k] - sc->xb[i * d + k];
        odhs__min_image(d, sys->L, sys->gamma, v, NULL);
        double s = 0.0;
        for (int k = 0; k < d; ++k) s += v[k] * v[k];
        if (s > m2) m2 = s;
    }
    double dg = fabs(sc->strain - sc->strain_b) * sys->L[1];
    if (!(2.0 * sqrt(m2) + 3.0 * dg <= sc->skin)) return nb_build(sc, x);
    return ODHS_OK;
}

/* ---- elastic forces ------------------------------------------------------------ */
/* Minimum image for separations of particles that are at most a few box
 * lengths out of the primary cell (positions are wrapped every few
 * iterations): a branch per axis instead of a libm rounding call. */
static inline void min_image_fast(int d, const double *L, double gL, double *v)
{
    while (v[1] > 0.5 * L[1]) {
        v[1] -= L[1];
        v[0] -= gL;
    }
    while (v[1] < -0.5 * L[1]) {
        v[1] += L[1];
        v[0] += gL;
    }
    if (d == 3) {
        while (v[2] > 0.5 * L[2]) v[2] -= L[2];
        while (v[2] < -0.5 * L[2]) v[2] += L[2];
    }
    while (v[0] > 0.5 * L[0]) v[0] -= L[0];
    while (v[0] < -0.5 * L[0]) v[0] += L[0];
}

static inline double powm1(double delta, double alpha)
{
    if (alpha == 2.0) return delta;
    if (alpha == 2.5) return delta * sqrt(delta);
    return pow(delta, alpha - 1.0);
}

static int ct_reserve(odhs_softcore *sc, size_t need)
{
    if (need <= sc->ccap) return ODHS_OK;
    size_t cap = sc->ccap ? sc->ccap : 64;
    while (cap < need) cap *= 2;
    size_t *a = odhs__realloc(sc->ci, cap * sizeof *a);
    if (!a) return ODHS_E_NOMEM;
    sc->ci = a;
    size_t *b = odhs__realloc(sc->cj, cap * sizeof *b);
    if (!b) return ODHS_E_NOMEM;
    sc->cj = b;
    double *c = odhs__realloc(sc->cr, cap * (size_t)sc->dim * sizeof *c);
    if (!c) return ODHS_E_NOMEM;
    sc->cr = c;
    sc->ccap = cap;
    return ODHS_OK;
}

/* Elastic forces F (may be NULL), energy U, elastic stress sum (unnormalised,
 * -sum f r n n; may be NULL), max overlap at positions x; records the
 * overlapping pairs. */
static int elastic(odhs_softcore *sc, const double *x, double *F, double *U, double *sig, double *maxov)
{
    int s = nb_check(sc, x);
    if (s) return s;
    /* reserve first: a failure leaves the forces and the contact list of the
     * last evaluation intact (the massive models' cache survives a rollback) */
    if (ct_reserve(sc, sc->np > 0 ? sc->np : 1)) return scerr(sc, ODHS_E_NOMEM, "out of memory (contact list)");
    odhs_system *sys = sc->sys;
    int d = sc->dim;
    if (F) memset(F, 0, sc->nd * sizeof *F);
    if (sig) memset(sig, 0, 9 * sizeof *sig);
    double Usum = 0.0, mo = 0.0, gL = sys->gamma * sys->L[1];
    sc->nc = 0;
    sc->fc_ok = 0;
    sc->nforce++;
    for (size_t p = 0; p < sc->np; ++p) {
        size_t i = sc->pi[p], j = sc->pj[p];
        double v[3] = {0, 0, 0};
        for (int k = 0; k < d; ++k) v[k] = x[j * d + k] - x[i * d + k];
        min_image_fast(d, sys->L, gL, v);
        double r2 = 0.0;
        for (int k = 0; k < d; ++k) r2 += v[k] * v[k];
        double dij = sys->r[i] + sys->r[j];
        if (r2 >= dij * dij) continue;
        double r = sqrt(r2);
        double delta = 1.0 - r / dij;
        if (delta > mo) mo = delta;
        double pm = powm1(delta, sc->alpha);
        double f = sc->ke / dij * pm;
        Usum += sc->ke / sc->alpha * pm * delta;
        sc->ci[sc->nc] = i;
        sc->cj[sc->nc] = j;
        for (int k = 0; k < d; ++k) sc->cr[sc->nc * d + k] = v[k];
        sc->nc++;
        if (r > 0.0) {
            if (F)
                for (int k = 0; k < d; ++k) {
                    double fk = f * v[k] / r;
                    F[j * d + k] += fk;
                    F[i * d + k] -= fk;
                }
            if (sig)
                for (int a = 0; a < d; ++a)
                    for (int b = 0; b < d; ++b) sig[a * 3 + b] -= f * v[a] * v[b] / r;
        }
    }
    if (U) *U = Usum;
    if (maxov) *maxov = mo;
    return ODHS_OK;
}

/* ---- CD0: (k_d L + k_0 I) u = F + k_d gammadot sum_j r_ij,y xhat ----------------- */
static void cd0_apply(const odhs_softcore *sc, const double *x, double *y)
{
    for (size_t i = 0; i < sc->n; ++i) y[i] = sc->k0 * x[i];
    for (size_t c = 0; c < sc->nc; ++c) {
        size_t i = sc->ci[c], j = sc->cj[c];
        double t = sc->kd * (x[i] - x[j]);
        y[i] += t;
        y[j] -= t;
    }
}

static int cd0_solve(odhs_softcore *sc, const double *F, double *u)
{
    size_t n = sc->n;
    int d = sc->dim;
    if (!(sc->k0 > 0.0)) return scerr(sc, ODHS_E_UNSUPPORTED, "CD0 needs a substrate drag k_0 > 0");
    for (size_t i = 0; i < n; ++i) sc->g_diag[i] = sc->k0;
    for (size_t c = 0; c < sc->nc; ++c) {
        sc->g_diag[sc->ci[c]] += sc->kd;
        sc->g_diag[sc->cj[c]] += sc->kd;
    }
    size_t maxit = 10 * n + 100;
    for (int k = 0; k < d; ++k) {
        double *b = sc->g_b, *x = sc->g_x, *r = sc->g_r, *z = sc->g_z, *p = sc->g_p, *q = sc->g_q;
        for (size_t i = 0; i < n; ++i) {
            b[i] = F[i * d + k];
            x[i] = u[i * d + k];
            if (!isfinite(x[i])) x[i] = 0.0;
        }
        if (k == 0 && sc->gdot != 0.0)
            for (size_t c = 0; c < sc->nc; ++c) {
                double t = sc->kd * sc->gdot * sc->cr[c * d + 1];
                b[sc->ci[c]] += t;
                b[sc->cj[c]] -= t;
            }
        double bn = 0.0;
        for (size_t i = 0; i < n; ++i) bn += b[i] * b[i];
        bn = sqrt(bn);
        if (bn == 0.0) {
            for (size_t i = 0; i < n; ++i) u[i * d + k] = 0.0;
            continue;
        }
        cd0_apply(sc, x, q);
        double rz = 0.0, rn = 0.0;
        for (size_t i = 0; i < n; ++i) {
            r[i] = b[i] - q[i];
            z[i] = r[i] / sc->g_diag[i];
            p[i] = z[i];
            rz += r[i] * z[i];
            rn += r[i] * r[i];
        }
        size_t it = 0;
        while (sqrt(rn) > sc->ltol * bn) {
            if (it++ >= maxit || !isfinite(rn))
                return scerr(sc, ODHS_E_NOCONV, "CD0 solve: relative residual %.3g after %zu iterations",
                             sqrt(rn) / bn, it);
            cd0_apply(sc, p, q);
            double pq = 0.0;
            for (size_t i = 0; i < n; ++i) pq += p[i] * q[i];
            if (!(pq > 0.0)) return scerr(sc, ODHS_E_SINGULAR, "CD0 matrix not positive definite");
            double al = rz / pq, rz2 = 0.0;
            rn = 0.0;
            for (size_t i = 0; i < n; ++i) {
                x[i] += al * p[i];
                r[i] -= al * q[i];
                z[i] = r[i] / sc->g_diag[i];
                rz2 += r[i] * z[i];
                rn += r[i] * r[i];
            }
            double be = rz2 / rz;
            rz = rz2;
            for (size_t i = 0; i < n; ++i) p[i] = z[i] + be * p[i];
        }
        for (size_t i = 0; i < n; ++i) u[i * d + k] = x[i];
    }
    return ODHS_OK;
}

/* overdamped non-affine velocities at x (forces into F) */
static int od_velocity(odhs_softcore *sc, const double *x, double *F, double *u)
{
    int s = elastic(sc, x, F, NULL, NULL, NULL);
    if (s) return s;
    if (sc->model == ODHS_SOFTCORE_CD0) return cd0_solve(sc, F, u);
    if (!(sc->kd > 0.0)) return scerr(sc, ODHS_E_UNSUPPORTED, "RD0 needs a drag coefficient k_d > 0");
    double m = 1.0 / sc->kd;
    for (size_t k = 0; k < sc->nd; ++k) u[k] = m * F[k];
    return ODHS_OK;
}

/* dissipative forces of the massive models at the recorded contacts,
 * velocities u; optional unnormalised stress sum (sum dv_a r_b k_d). */
static void dissipative(const odhs_softcore *sc, int model, const double *u, double *Fd, double *sig)
{
    int d = sc->dim;
    if (Fd) memset(Fd, 0, sc->nd * sizeof *Fd);
    if (sig) memset(sig, 0, 9 * sizeof *sig);
    if (model == ODHS_SOFTCORE_RD || model == ODHS_SOFTCORE_RD0) {
        if (Fd && model == ODHS_SOFTCORE_RD)
            for (size_t k = 0; k < sc->nd; ++k) Fd[k] = -sc->kd * u[k];
        return;
    }
    for (size_t c = 0; c < sc->nc; ++c) {
        size_t i = sc->ci[c], j = sc->cj[c];
        const double *r = sc->cr + c * d;
        double dv[3] = {0, 0, 0}, r2 = 0.0, vn = 0.0;
        for (int k = 0; k < d; ++k) dv[k] = u[j * d + k] - u[i * d + k];
        dv[0] += sc->gdot * r[1];
        for (int k = 0; k < d; ++k) {
            r2 += r[k] * r[k];
            vn += dv[k] * r[k];
        }
        if (model == ODHS_SOFTCORE_CDN || model == ODHS_SOFTCORE_CDT) {
            double t = r2 > 0.0 ? vn / r2 : 0.0;
            for (int k = 0; k < d; ++k) {
                double nk = t * r[k];
                dv[k] = model == ODHS_SOFTCORE_CDN ? nk : dv[k] - nk;
            }
        }
        for (int k = 0; k < d; ++k) {
            double f = sc->kd * dv[k];
            if (Fd) {
                Fd[i * d + k] += f;
                Fd[j * d + k] -= f;
            }
        }
        if (sig)
            for (int a = 0; a < d; ++a)
                for (int b = 0; b < d; ++b) sig[a * 3 + b] += sc->kd * dv[a] * r[b];
    }
}

/* ---- creation and settings -------------------------------------------------------- */
static void sc_free_arrays(odhs_softcore *sc)
{
    double **arr[] = {&sc->u, &sc->F, &sc->w1, &sc->w2, &sc->w3, &sc->w4, &sc->w5, &sc->xs, &sc->us,
                      &sc->xw, &sc->xb, &sc->cr, &sc->g_r, &sc->g_z, &sc->g_p, &sc->g_q, &sc->g_diag,
                      &sc->g_b, &sc->g_x, &sc->relax};
    for (size_t k = 0; k < sizeof arr / sizeof arr[0]; ++k) {
        odhs__free(*arr[k]);
        *arr[k] = NULL;
    }
    odhs__free(sc->pi);
    odhs__free(sc->pj);
    odhs__free(sc->pk);
    odhs__free(sc->ci);
    odhs__free(sc->cj);
}

static void geometry(odhs_softcore *sc)
{
    const odhs_system *sys = sc->sys;
    double rmin = sys->r[0], rsum = 0.0;
    for (size_t i = 0; i < sc->n; ++i) {
        if (sys->r[i] < rmin) rmin = sys->r[i];
        rsum += sys->r[i];
    }
    sc->dmin = 2.0 * rmin;
    sc->lambda = 2.0 * rsum / (double)sc->n;
    double lmin = sys->L[0];
    for (int k = 1; k < sc->dim; ++k)
        if (sys->L[k] < lmin) lmin = sys->L[k];
    double room = 0.5 * lmin - 2.0 * sys->rmax;
    sc->skin = 0.3 * sc->lambda;
    if (sc->skin > 0.9 * room) sc->skin = room > 0.0 ? 0.9 * room : 0.0;
    sc->nb_ok = 0;
    sc->fc_ok = 0;
}

int odhs_softcore_create(odhs_system *sys, odhs_softcore **out)
{
    if (!out) return ODHS_E_NULL;
    *out = NULL;
    if (!sys) return ODHS_E_NULL;
    if (!odhs_system_is_ready(sys))
        return odhs__syserr(sys, ODHS_E_STATE, "softcore: the system needs radii and positions");
    odhs_softcore *sc = odhs__calloc(1, sizeof *sc);
    if (!sc) return ODHS_E_NOMEM;
    sc->sys = sys;
    sc->dim = sys->dim;
    sc->n = sys->n;
    sc->nd = sys->n * (size_t)sys->dim;
    sc->model = ODHS_SOFTCORE_RD0;
    sc->alpha = 2.0;
    sc->ke = 1.0;
    sc->kd = 1.0;
    sc->k0 = 1e-3;
    sc->mass = 1.0;
    sc->integ = ODHS_SOFTCORE_FIXED;
    sc->cdt = 0.1;
    sc->tol = 1e-6;
    sc->minimiser = ODHS_SOFTCORE_SD;
    sc->gtol = 1e-9;
    sc->maxit = 100000000u;
    sc->ltol = 1e-12;
    double **nd_arr[] = {&sc->u, &sc->F, &sc->w1, &sc->w2, &sc->w3, &sc->w4, &sc->w5, &sc->xs, &sc->us, &sc->xw, &sc->xb};
    for (size_t k = 0; k < sizeof nd_arr / sizeof nd_arr[0]; ++k) {
        *nd_arr[k] = odhs__calloc(sc->nd, sizeof(double));
        if (!*nd_arr[k]) goto nomem;
    }
    double **n_arr[] = {&sc->g_r, &sc->g_z, &sc->g_p, &sc->g_q, &sc->g_diag, &sc->g_b, &sc->g_x};
    for (size_t k = 0; k < sizeof n_arr / sizeof n_arr[0]; ++k) {
        *n_arr[k] = odhs__calloc(sc->n, sizeof(double));
        if (!*n_arr[k]) goto nomem;
    }
    sc->relax = odhs__calloc(9, sizeof(double));
    if (!sc->relax) goto nomem;
    geometry(sc);
    *out = sc;
    return ODHS_OK;
nomem:
    sc_free_arrays(sc);
    odhs__free(sc);
    return ODHS_E_NOMEM;
}

void odhs_softcore_destroy(odhs_softcore *sc)
{
    if (!sc) return;
    sc_free_arrays(sc);
    odhs__free(sc);
}

const char *odhs_softcore_errmsg(const odhs_softcore *sc) { return sc ? sc->errmsg : ""; }

#define SCNULL(sc)                      \
    do {                                \
        if (!(sc)) return ODHS_E_NULL;  \
    } while (0)

int odhs_softcore_set_model(odhs_softcore *sc, int model)
{
    SCNULL(sc);
    if (model < ODHS_SOFTCORE_RD0 || model > ODHS_SOFTCORE_CDT)
        return scerr(sc, ODHS_E_INVALID, "unknown soft-core model %d", model);
    sc->model = model;
    sc->fc_ok = 0;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

int odhs_softcore_set_potential(odhs_softcore *sc, double alpha, double k_e)
{
    SCNULL(sc);
    if (!isfinite(alpha) || !isfinite(k_e)) return scerr(sc, ODHS_E_NONFINITE, "non-finite potential parameter");
    if (!(alpha > 1.0 && alpha <= 10.0)) return scerr(sc, ODHS_E_INVALID, "alpha must be in (1, 10], got %g", alpha);
    if (!(k_e > 0.0)) return scerr(sc, ODHS_E_INVALID, "k_e must be > 0, got %g", k_e);
    sc->alpha = alpha;
    sc->ke = k_e;
    sc->fc_ok = 0;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

#define POSITIVE_SETTER(fname, field, what)                                                   \
    int fname(odhs_softcore *sc, double v)                                                    \
    {                                                                                         \
        SCNULL(sc);                                                                           \
        if (!isfinite(v)) return scerr(sc, ODHS_E_NONFINITE, what " is not finite");          \
        if (!(v > 0.0)) return scerr(sc, ODHS_E_INVALID, what " must be > 0, got %g", v);     \
        sc->field = v;                                                                        \
        sc->h_ad = 0.0;                                                                       \
        return ODHS_OK;                                                                       \
    }

int odhs_softcore_set_drag(odhs_softcore *sc, double kd)
{
    SCNULL(sc);
    if (!isfinite(kd)) return scerr(sc, ODHS_E_NONFINITE, "drag coefficient k_d is not finite");
    if (!(kd >= 0.0)) return scerr(sc, ODHS_E_INVALID, "drag coefficient k_d must be >= 0, got %g", kd);
    sc->kd = kd;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

POSITIVE_SETTER(odhs_softcore_set_mass, mass, "mass")

int odhs_softcore_set_substrate(odhs_softcore *sc, double k0)
{
    SCNULL(sc);
    if (!isfinite(k0)) return scerr(sc, ODHS_E_NONFINITE, "k_0 is not finite");
    if (!(k0 >= 0.0)) return scerr(sc, ODHS_E_INVALID, "k_0 must be >= 0, got %g", k0);
    sc->k0 = k0;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

int odhs_softcore_set_shear_rate(odhs_softcore *sc, double g)
{
    SCNULL(sc);
    if (!isfinite(g)) return scerr(sc, ODHS_E_NONFINITE, "shear rate is not finite");
    if (fabs(g) > 1e300) return scerr(sc, ODHS_E_INVALID, "shear rate %g too large", g);
    sc->gdot = g;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

int odhs_softcore_set_integrator(odhs_softcore *sc, int integ)
{
    SCNULL(sc);
    if (integ != ODHS_SOFTCORE_FIXED && integ != ODHS_SOFTCORE_ADAPTIVE)
        return scerr(sc, ODHS_E_INVALID, "unknown integrator %d", integ);
    sc->integ = integ;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

int odhs_softcore_set_dt(odhs_softcore *sc, double c)
{
    SCNULL(sc);
    if (!isfinite(c)) return scerr(sc, ODHS_E_NONFINITE, "step factor is not finite");
    if (!(c > 0.0 && c <= 10.0)) return scerr(sc, ODHS_E_INVALID, "step factor must be in (0, 10], got %g", c);
    sc->cdt = c;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

int odhs_softcore_set_tolerance(odhs_softcore *sc, double tol)
{
    SCNULL(sc);
    if (!isfinite(tol)) return scerr(sc, ODHS_E_NONFINITE, "tolerance is not finite");
    if (!(tol > 0.0 && tol < 1.0)) return scerr(sc, ODHS_E_INVALID, "tolerance must be in (0, 1), got %g", tol);
    sc->tol = tol;
    return ODHS_OK;
}

int odhs_softcore_set_minimiser(odhs_softcore *sc, int m)
{
    SCNULL(sc);
    if (m != ODHS_SOFTCORE_SD && m != ODHS_SOFTCORE_FIRE && m != ODHS_SOFTCORE_CG)
        return scerr(sc, ODHS_E_INVALID, "unknown minimiser %d", m);
    sc->minimiser = m;
    return ODHS_OK;
}

int odhs_softcore_set_min_tolerance(odhs_softcore *sc, double tol, uint64_t max_iter)
{
    SCNULL(sc);
    if (!isfinite(tol)) return scerr(sc, ODHS_E_NONFINITE, "minimiser tolerance is not finite");
    if (!(tol > 0.0)) return scerr(sc, ODHS_E_INVALID, "minimiser tolerance must be > 0, got %g", tol);
    if (max_iter == 0) return scerr(sc, ODHS_E_INVALID, "max_iter must be > 0");
    sc->gtol = tol;
    sc->maxit = max_iter;
    return ODHS_OK;
}

int odhs_softcore_set_linear_tolerance(odhs_softcore *sc, double tol)
{
    SCNULL(sc);
    if (!isfinite(tol)) return scerr(sc, ODHS_E_NONFINITE, "linear tolerance is not finite");
    if (!(tol > 0.0 && tol < 1.0)) return scerr(sc, ODHS_E_INVALID, "linear tolerance must be in (0, 1), got %g", tol);
    sc->ltol = tol;
    return ODHS_OK;
}

static void wrap_all(odhs_softcore *sc, double *x)
{
    for (size_t i = 0; i < sc->n; ++i) odhs__wrap(sc->dim, sc->sys->L, sc->sys->gamma, x + i * sc->dim);
}

int odhs_softcore_set_positions(odhs_softcore *sc, const double *x)
{
    SCNULL(sc);
    if (!x) return scerr(sc, ODHS_E_NULL, "positions are NULL");
    for (size_t k = 0; k < sc->nd; ++k)
        if (!isfinite(x[k])) return scerr(sc, ODHS_E_NONFINITE, "position %zu is not finite", k);
    for (size_t i = 0; i < sc->n; ++i)
        for (int k = 0; k < sc->dim; ++k)
            if (fabs(x[i * sc->dim + k]) > 0x1p50 * sc->sys->L[k])
                return scerr(sc, ODHS_E_INVALID, "position of particle %zu too far from the box", i);
    memcpy(sc->sys->x, x, sc->nd * sizeof *x);
    wrap_all(sc, sc->sys->x);
    sc->nb_ok = 0;
    sc->fc_ok = 0;
    return ODHS_OK;
}

int odhs_softcore_scale_box(odhs_softcore *sc, double s)
{
    SCNULL(sc);
    if (!isfinite(s)) return scerr(sc, ODHS_E_NONFINITE, "scale factor is not finite");
    if (!(s > 0.0)) return scerr(sc, ODHS_E_INVALID, "scale factor %g must be > 0", s);
    odhs_system *sys = sc->sys;
    for (int k = 0; k < sc->dim; ++k) {
        if (!isfinite(s * sys->L[k])) return scerr(sc, ODHS_E_NONFINITE, "box edge %d would overflow", k);
        if (!(s * sys->L[k] >= 4.0 * sys->rmax))
            return scerr(sc, ODHS_E_BOX, "box edge %d would be %g, shorter than twice the largest diameter %g", k,
                         s * sys->L[k], 4.0 * sys->rmax);
    }
    for (int k = 0; k < sc->dim; ++k) sys->L[k] *= s;
    for (size_t q = 0; q < sc->nd; ++q) sys->x[q] *= s;
    wrap_all(sc, sys->x);
    geometry(sc);
    return ODHS_OK;
}

int odhs_softcore_set_velocities(odhs_softcore *sc, const double *u)
{
    SCNULL(sc);
    if (!u) return scerr(sc, ODHS_E_NULL, "velocities are NULL");
    for (size_t k = 0; k < sc->nd; ++k)
        if (!isfinite(u[k])) return scerr(sc, ODHS_E_NONFINITE, "velocity %zu is not finite", k);
    memcpy(sc->u, u, sc->nd * sizeof *u);
    return ODHS_OK;
}

int odhs_softcore_reset(odhs_softcore *sc)
{
    SCNULL(sc);
    if (!odhs_system_is_ready(sc->sys)) return scerr(sc, ODHS_E_STATE, "the system is not ready");
    geometry(sc);
    sc->h_ad = 0.0;
    return ODHS_OK;
}

/* ---- time stepping ------------------------------------------------------------------- */
static double tau_e(const odhs_softcore *sc)
{
    double drag = sc->kd;
    if (sc->model == ODHS_SOFTCORE_CD0 && sc->k0 > drag) drag = sc->k0;
    return drag * sc->dmin * sc->dmin / sc->ke;
}

static double base_step(const odhs_softcore *sc)
{
    double h;
    if (is_massive(sc->model)) {
        double tm = sqrt(sc->mass * sc->dmin * sc->dmin / sc->ke), td = sc->kd > 0.0 ? sc->mass / sc->kd : INFINITY;
        h = sc->cdt * (tm < td ? tm : td);
    } else {
        h = sc->cdt * tau_e(sc);
    }
    if (sc->gdot != 0.0 && h * fabs(sc->gdot) > 0.01) h = 0.01 / fabs(sc->gdot);
    return h;
}

static void snapshot(odhs_softcore *sc, double *gam, double *str, double *tim)
{
    memcpy(sc->xs, sc->sys->x, sc->nd * sizeof(double));
    memcpy(sc->us, sc->u, sc->nd * sizeof(double));
    *gam = sc->sys->gamma;
    *str = sc->strain;
    *tim = sc->time;
    sc->nforce_s = sc->nforce;
    sc->fc_ok_s = sc->fc_ok;
    sc->h_ad_s = sc->h_ad;
}

static void rollback(odhs_softcore *sc, double gam, double str, double tim)
{
    memcpy(sc->sys->x, sc->xs, sc->nd * sizeof(double));
    memcpy(sc->u, sc->us, sc->nd * sizeof(double));
    sc->sys->gamma = gam;
    sc->strain = str;
    sc->time = tim;
    /* no evaluation completed since the snapshot: the cached forces and
     * contacts are those of the restored positions */
    sc->fc_ok = sc->nforce == sc->nforce_s ? sc->fc_ok_s : 0;
    sc->nforce = sc->nforce_s;
    sc->h_ad = sc->h_ad_s;
    sc->nb_ok = 0;
}

static void advance_strain(odhs_softcore *sc, double dg)
{
    sc->strain += dg;
    sc->sys->gamma = odhs__remap_strain(sc->sys->gamma + dg, sc->sys->L);
}

static int all_finite(const double *v, size_t n)
{
    for (size_t k = 0; k < n; ++k)
        if (!isfinite(v[k])) return 0;
    return 1;
}

/* one overdamped Euler step of length h */
static int step_euler(odhs_softcore *sc, double h)
{
    int d = sc->dim;
    double *x = sc->sys->x;
    int s = od_velocity(sc, x, sc->F, sc->u);
    if (s) return s;
    for (size_t i = 0; i < sc->n; ++i) {
        x[i * d] += h * (sc->u[i * d] + sc->gdot * x[i * d + 1]);
        for (int k = 1; k < d; ++k) x[i * d + k] += h * sc->u[i * d + k];
    }
    advance_strain(sc, sc->gdot * h);
    return ODHS_OK;
}

/* adaptive Heun: takes one accepted step of at most hmax; *taken = its length */
static int step_heun(odhs_softcore *sc, double hmax, double *taken)
{
    int d = sc->dim;
    double *x = sc->sys->x, *k1 = sc->w1, *k2 = sc->w2, *xp = sc->w3, *u2 = sc->w4;
    double hcap = tau_e(sc);
    if (sc->gdot != 0.0 && hcap * fabs(sc->gdot) > 0.01) hcap = 0.01 / fabs(sc->gdot);
    if (sc->h_ad <= 0.0) sc->h_ad = sc->cdt * tau_e(sc);
    if (sc->h_ad > hcap) sc->h_ad = hcap;
    int s = od_velocity(sc, x, sc->F, sc->u);
    if (s) return s;
    for (size_t i = 0; i < sc->n; ++i)
        for (int k = 0; k < d; ++k) k1[i * d + k] = sc->u[i * d + k] + (k == 0 ? sc->gdot * x[i * d + 1] : 0.0);
    double gam0 = sc->sys->gamma, str0 = sc->strain;
    memcpy(u2, sc->u, sc->nd * sizeof *u2);
    for (int tries = 0; tries < 200; ++tries) {
        double h = sc->h_ad < hmax ? sc->h_ad : hmax;
        for (size_t k = 0; k < sc->nd; ++k) xp[k] = x[k] + h * k1[k];
        advance_strain(sc, sc->gdot * h);
        s = od_velocity(sc, xp, sc->F, u2);
        if (s) {
            sc->sys->gamma = gam0;
            sc->strain = str0;
            return s;
        }
        double err = 0.0;
        for (size_t i = 0; i < sc->n; ++i) {
            double e2 = 0.0;
            for (int k = 0; k < d; ++k) {
                k2[i * d + k] = u2[i * d + k] + (k == 0 ? sc->gdot * xp[i * d + 1] : 0.0);
                double e = 0.5 * h * (k2[i * d + k] - k1[i * d + k]);
                e2 += e * e;
            }
            if (e2 > err) err = e2;
        }
        err = sqrt(err) / sc->lambda;
        double fac = err > 0.0 ? 0.9 * sqrt(sc->tol / err) : 5.0;
        if (!isfinite(err) || (err > sc->tol && tries < 199)) {
            sc->sys->gamma = gam0;
            sc->strain = str0;
            sc->h_ad = h * (isfinite(fac) && fac > 0.2 ? fac : 0.2);
            continue;
        }
        for (size_t k = 0; k < sc->nd; ++k) x[k] += 0.5 * h * (k1[k] + k2[k]);
        memcpy(sc->u, u2, sc->nd * sizeof *u2);
        if (h >= sc->h_ad) sc->h_ad = h * (fac < 5.0 ? fac : 5.0);
        if (sc->h_ad > hcap) sc->h_ad = hcap;
        *taken = h;
        return ODHS_OK;
    }
    return scerr(sc, ODHS_E_NOCONV, "adaptive step could not meet the tolerance");
}

/* massive: SLLOD velocity Verlet, step h */
static int step_sllod(odhs_softcore *sc, double h)
{
    int d = sc->dim;
    double *x = sc->sys->x, *u = sc->u, *Fd = sc->w1;
    double m = sc->mass;
    int s;
    if (!sc->fc_ok) {
        s = elastic(sc, x, sc->F, NULL, NULL, NULL);
        if (s) return s;
    }
    dissipative(sc, sc->model, u, Fd, NULL);
    for (size_t i = 0; i < sc->n; ++i) {
        double uy = u[i * d + 1];
        for (int k = 0; k < d; ++k) {
            double a = (sc->F[i * d + k] + Fd[i * d + k]) / m;
            if (k == 0) a -= sc->gdot * uy;
            u[i * d + k] += 0.5 * h * a;
        }
    }
    for (size_t i = 0; i < sc->n; ++i) {
        double ymid = x[i * d + 1] + 0.5 * h * u[i * d + 1];
        x[i * d] += h * (u[i * d] + sc->gdot * ymid);
        for (int k = 1; k < d; ++k) x[i * d + k] += h * u[i * d + k];
    }
    advance_strain(sc, sc->gdot * h);
    s = elastic(sc, x, sc->F, NULL, NULL, NULL);
    if (s) return s;
    dissipative(sc, sc->model, u, Fd, NULL);
    for (size_t i = 0; i < sc->n; ++i) {
        double uy = u[i * d + 1];
        for (int k = 0; k < d; ++k) {
            double a = (sc->F[i * d + k] + Fd[i * d + k]) / m;
            if (k == 0) a -= sc->gdot * uy;
            u[i * d + k] += 0.5 * h * a;
        }
    }
    sc->fc_ok = 1;
    return ODHS_OK;
}

/* one step of at most hmax; *taken receives its length */
static int step_once(odhs_softcore *sc, double hmax, double *taken)
{
    if (sc->model == ODHS_SOFTCORE_RD0 && !(sc->kd > 0.0))
        return scerr(sc, ODHS_E_UNSUPPORTED, "RD0 needs a drag coefficient k_d > 0");
    if (sc->model == ODHS_SOFTCORE_CD0 && !(sc->k0 > 0.0))
        return scerr(sc, ODHS_E_UNSUPPORTED, "CD0 needs a substrate drag k_0 > 0");
    double gam, str, tim;
    snapshot(sc, &gam, &str, &tim);
    double h = base_step(sc);
    if (h > hmax) h = hmax;
    int s;
    if (is_massive(sc->model)) {
        s = step_sllod(sc, h);
    } else if (sc->integ == ODHS_SOFTCORE_ADAPTIVE) {
        s = step_heun(sc, hmax, &h);
    } else {
        s = step_euler(sc, h);
    }
    if (s == ODHS_OK && (!all_finite(sc->sys->x, sc->nd) || !all_finite(sc->u, sc->nd)))
        s = scerr(sc, ODHS_E_NONFINITE, "the integration produced non-finite values: reduce the step");
    if (s != ODHS_OK) {
        rollback(sc, gam, str, tim);
        return s;
    }
    int fc = sc->fc_ok;
    wrap_all(sc, sc->sys->x);
    sc->fc_ok = fc; /* wrapping does not change the forces */
    sc->time = tim + h;
    sc->nsteps++;
    *taken = h;
    return ODHS_OK;
}

int odhs_softcore_step(odhs_softcore *sc)
{
    SCNULL(sc);
    double h;
    return step_once(sc, INFINITY, &h);
}

int odhs_softcore_run_until_strain(odhs_softcore *sc, double gamma)
{
    SCNULL(sc);
    if (!isfinite(gamma)) return scerr(sc, ODHS_E_NONFINITE, "target strain is not finite");
    if (sc->gdot == 0.0) return scerr(sc, ODHS_E_INVALID, "run_until_strain needs a nonzero shear rate");
    double rem = (gamma - sc->strain) / sc->gdot;
    if (rem < 0.0) return scerr(sc, ODHS_E_INVALID, "strain %g lies behind the current strain %g", gamma, sc->strain);
    double t_end = sc->time + rem;
    while (sc->time < t_end) {
        double left = t_end - sc->time, h;
        if (left <= 1e-14 * (fabs(t_end) + base_step(sc))) break;
        int s = step_once(sc, left, &h);
        if (s) return s;
    }
    /* land exactly (round-off of the sum of steps) */
    double dg = gamma - sc->strain;
    if (dg != 0.0 && fabs(dg) < 1e-9) {
        sc->strain = gamma;
        sc->sys->gamma = odhs__remap_strain(sc->sys->gamma + dg, sc->sys->L);
    }
    return ODHS_OK;
}

int odhs_softcore_run_until_time(odhs_softcore *sc, double t)
{
    SCNULL(sc);
    if (!isfinite(t)) return scerr(sc, ODHS_E_NONFINITE, "target time is not finite");
    if (t < sc->time) return scerr(sc, ODHS_E_INVALID, "time %g lies before the current time %g", t, sc->time);
    while (sc->time < t) {
        double left = t - sc->time, h;
        if (left <= 1e-14 * (fabs(t) + base_step(sc))) break;
        int s = step_once(sc, left, &h);
        if (s) return s;
    }
    return ODHS_OK;
}

/* ---- minimisation -------------------------------------------------------------------- */
static double max_norm(const odhs_softcore *sc, const double *F)
{
    double m = 0.0;
    int d = sc->dim;
    for (size_t i = 0; i < sc->n; ++i) {
        double s = 0.0;
        for (int k = 0; k < d; ++k) s += F[i * d + k] * F[i * d + k];
        if (s > m) m = s;
    }
    return sqrt(m);
}

static double dot(const double *a, const double *b, size_t n)
{
    double s = 0.0;
    for (size_t k = 0; k < n; ++k) s += a[k] * b[k];
    return s;
}

static int min_sd(odhs_softcore *sc, uint64_t *iters)
{
    double *x = sc->sys->x, sig[9];
    double h = sc->cdt * sc->kd * sc->dmin * sc->dmin / sc->ke;
    int d = sc->dim;
    memset(sc->relax_acc, 0, sizeof sc->relax_acc);
    uint64_t it = 0;
    for (;;) {
        int s = elastic(sc, x, sc->F, NULL, sig, NULL);
        if (s) return s;
        if (max_norm(sc, sc->F) < sc->gtol) break;
        if (it >= sc->maxit)
            return scerr(sc, ODHS_E_NOCONV, "steepest descent: largest force %.3g after %llu iterations",
                         max_norm(sc, sc->F), (unsigned long long)it);
        for (int a = 0; a < d; ++a)
            for (int b = 0; b < d; ++b) sc->relax_acc[a * 3 + b] += h * sig[a * 3 + b];
        double m = h / sc->kd;
        for (size_t k = 0; k < sc->nd; ++k) x[k] += m * sc->F[k];
        if ((it & 63u) == 63u) wrap_all(sc, x);
        it++;
    }
    *iters = it;
    return ODHS_OK;
}

static int min_fire(odhs_softcore *sc, uint64_t *iters)
{
    double *x = sc->sys->x, *v = sc->w1, *F = sc->F;
    size_t nd = sc->nd;
    double tf = sqrt(sc->dmin * sc->dmin / sc->ke);
    double dt = sc->cdt * tf, dtmax = 10.0 * dt;
    if (dtmax > 0.5 * tf) dtmax = 0.5 * tf;
    if (dt > dtmax) dt = dtmax;
    double al = 0.1;
    unsigned npos = 0;
    memset(v, 0, nd * sizeof *v);
    uint64_t it = 0;
    for (;;) {
        int s = elastic(sc, x, F, NULL, NULL, NULL);
        if (s) return s;
        if (max_norm(sc, F) < sc->gtol) break;
        if (it >= sc->maxit)
            return scerr(sc, ODHS_E_NOCONV, "FIRE: largest force %.3g after %llu iterations", max_norm(sc, F),
                         (unsigned long long)it);
        double P = dot(F, v, nd);
        if (P > 0.0) {
            if (++npos > 5) {
                dt = dt * 1.1 < dtmax ? dt * 1.1 : dtmax;
                al *= 0.99;
            }
        } else {
            npos = 0;
            dt *= 0.5;
            al = 0.1;
            for (size_t k = 0; k < nd; ++k) {
                x[k] -= 0.5 * dt * v[k];
                v[k] = 0.0;
            }
        }
        for (size_t k = 0; k < nd; ++k) v[k] += dt * F[k];
        double vn = sqrt(dot(v, v, nd)), fn = sqrt(dot(F, F, nd));
        if (fn > 0.0)
            for (size_t k = 0; k < nd; ++k) v[k] = (1.0 - al) * v[k] + al * vn * F[k] / fn;
        for (size_t k = 0; k < nd; ++k) x[k] += dt * v[k];
        if ((it & 63u) == 63u) wrap_all(sc, x);
        it++;
    }
    *iters = it;
    return ODHS_OK;
}

/* g(s) = F(x + s d) . d */
static int line_g(odhs_softcore *sc, const double *x, const double *dir, double s, double *xt, double *Ft, double *g)
{
    for (size_t k = 0; k < sc->nd; ++k) xt[k] = x[k] + s * dir[k];
    int st = elastic(sc, xt, Ft, NULL, NULL, NULL);
    if (st) return st;
    *g = dot(Ft, dir, sc->nd);
    return ODHS_OK;
}

static int min_cg(odhs_softcore *sc, uint64_t *iters)
{
    double *x = sc->sys->x, *F = sc->F, *dir = sc->w1, *Fo = sc->w2, *xt = sc->w3, *Ft = sc->w4;
    size_t nd = sc->nd;
    double s0 = sc->cdt * sc->dmin * sc->dmin / sc->ke;
    int st = elastic(sc, x, F, NULL, NULL, NULL);
    if (st) return st;
    memcpy(dir, F, nd * sizeof *dir);
    uint64_t it = 0, since = 0;
    for (;;) {
        if (max_norm(sc, F) < sc->gtol) break;
        if (it >= sc->maxit)
            return scerr(sc, ODHS_E_NOCONV, "CG: largest force %.3g after %llu iterations", max_norm(sc, F),
                         (unsigned long long)it);
        double g0 = dot(F, dir, nd);
        if (!(g0 > 0.0)) {
            memcpy(dir, F, nd * sizeof *dir);
            g0 = dot(F, dir, nd);
        }
        /* bracket the zero of g along dir, then Illinois regula falsi */
        double sa = 0.0, ga = g0, sb = s0, gb;
        if ((st = line_g(sc, x, dir, sb, xt, Ft, &gb))) return st;
        int k;
        for (k = 0; gb > 0.0 && k < 60; ++k) {
            sa = sb;
            ga = gb;
            sb *= 2.0;
            if ((st = line_g(sc, x, dir, sb, xt, Ft, &gb))) return st;
        }
        double sm = sb, gm = gb;
        if (gb <= 0.0) {
            int side = 0;
            for (k = 0; k < 60; ++k) {
                sm = (sa * gb - sb * ga) / (gb - ga);
                if (!(sm > sa && sm < sb)) sm = 0.5 * (sa + sb);
                if ((st = line_g(sc, x, dir, sm, xt, Ft, &gm))) return st;
                if (fabs(gm) <= 1e-8 * g0 || (sb - sa) <= 1e-14 * sb) break;
                if (gm > 0.0) {
                    sa = sm;
                    ga = gm;
                    if (side == 1) gb *= 0.5;
                    side = 1;
                } else {
                    sb = sm;
                    gb = gm;
                    if (side == -1) ga *= 0.5;
                    side = -1;
                }
            }
        }
        if (sm > 0.0 && sm < 1e6 * s0) s0 = 0.5 * (s0 + sm);
        memcpy(x, xt, nd * sizeof *x);
        memcpy(Fo, F, nd * sizeof *Fo);
        memcpy(F, Ft, nd * sizeof *F);
        double beta = (dot(F, F, nd) - dot(F, Fo, nd)) / dot(Fo, Fo, nd);
        if (!(beta > 0.0) || ++since >= nd) {
            beta = 0.0;
            since = 0;
        }
        for (size_t q = 0; q < nd; ++q) dir[q] = F[q] + beta * dir[q];
        if ((it & 63u) == 63u) wrap_all(sc, x);
        it++;
    }
    *iters = it;
    return ODHS_OK;
}

static int minimise_inner(odhs_softcore *sc, uint64_t *iters)
{
    int s;
    *iters = 0;
    if (sc->minimiser == ODHS_SOFTCORE_SD && !(sc->kd > 0.0))
        return scerr(sc, ODHS_E_UNSUPPORTED, "steepest descent needs a drag coefficient k_d > 0 (its mobility)");
    switch (sc->minimiser) {
    case ODHS_SOFTCORE_FIRE: s = min_fire(sc, iters); break;
    case ODHS_SOFTCORE_CG: s = min_cg(sc, iters); break;
    default: s = min_sd(sc, iters); break;
    }
    if (s == ODHS_OK && !all_finite(sc->sys->x, sc->nd))
        s = scerr(sc, ODHS_E_NONFINITE, "the minimiser produced non-finite positions: reduce the step");
    if (s == ODHS_OK) {
        wrap_all(sc, sc->sys->x);
        memset(sc->u, 0, sc->nd * sizeof *sc->u);
        sc->nmin += *iters;
        sc->fc_ok = 0;
    }
    return s;
}

int odhs_softcore_minimise(odhs_softcore *sc, uint64_t *iterations)
{
    SCNULL(sc);
    double gam, str, tim;
    uint64_t it = 0;
    snapshot(sc, &gam, &str, &tim);
    int s = minimise_inner(sc, &it);
    if (s) {
        rollback(sc, gam, str, tim);
        return s;
    }
    sc->has_relax = 0;
    if (iterations) *iterations = it;
    return ODHS_OK;
}

int odhs_softcore_quasistatic_step(odhs_softcore *sc, double dgamma, uint64_t *iterations)
{
    SCNULL(sc);
    if (!isfinite(dgamma)) return scerr(sc, ODHS_E_NONFINITE, "strain step is not finite");
    if (dgamma == 0.0 || fabs(dgamma) > 0.1)
        return scerr(sc, ODHS_E_INVALID, "strain step must be nonzero and at most 0.1, got %g", dgamma);
    double gam, str, tim;
    snapshot(sc, &gam, &str, &tim);
    int d = sc->dim;
    double *x = sc->sys->x;
    for (size_t i = 0; i < sc->n; ++i) x[i * d] += dgamma * x[i * d + 1];
    advance_strain(sc, dgamma);
    wrap_all(sc, x);
    uint64_t it = 0;
    int s = minimise_inner(sc, &it);
    if (s) {
        rollback(sc, gam, str, tim);
        return s;
    }
    if (sc->minimiser == ODHS_SOFTCORE_SD) {
        double vol;
        odhs_system_volume(sc->sys, &vol);
        for (int a = 0; a < d; ++a)
            for (int b = 0; b < d; ++b) sc->relax[a * d + b] = sc->relax_acc[a * 3 + b] / (vol * dgamma);
        sc->has_relax = 1;
    } else {
        sc->has_relax = 0;
    }
    if (iterations) *iterations = it;
    return ODHS_OK;
}

/* ---- observables ------------------------------------------------------------------------ */
#define NEED(sc, p)                                                          \
    do {                                                                     \
        if (!(sc)) return ODHS_E_NULL;                                       \
        if (!(p)) return scerr((sc), ODHS_E_NULL, "output pointer is NULL"); \
    } while (0)

int odhs_softcore_time(const odhs_softcore *sc, double *t)
{
    NEED(sc, t);
    *t = sc->time;
    return ODHS_OK;
}

int odhs_softcore_strain(const odhs_softcore *sc, double *g)
{
    NEED(sc, g);
    *g = sc->strain;
    return ODHS_OK;
}

int odhs_softcore_counts(const odhs_softcore *sc, uint64_t *steps, uint64_t *fe, uint64_t *mi)
{
    SCNULL(sc);
    if (steps) *steps = sc->nsteps;
    if (fe) *fe = sc->nforce;
    if (mi) *mi = sc->nmin;
    return ODHS_OK;
}

int odhs_softcore_step_size(const odhs_softcore *sc, double *h)
{
    NEED(sc, h);
    *h = (!is_massive(sc->model) && sc->integ == ODHS_SOFTCORE_ADAPTIVE && sc->h_ad > 0.0) ? sc->h_ad : base_step(sc);
    return ODHS_OK;
}

/* evaluate at the current positions (cache state is logically const) */
static int eval_here(const odhs_softcore *csc, double *U, double *sig, double *mo)
{
    odhs_softcore *sc = (odhs_softcore *)csc;
    int fc = sc->fc_ok;
    uint64_t nf = sc->nforce;
    int s = elastic(sc, sc->sys->x, sc->w5, U, sig, mo);
    /* positions unchanged: the massive models' cached forces stay valid */
    sc->fc_ok = s == ODHS_OK ? fc : 0;
    if (s != ODHS_OK) sc->nforce = nf; /* an error changes nothing visible */
    return s;
}

int odhs_softcore_energy(const odhs_softcore *sc, double *U)
{
    NEED(sc, U);
    double u;
    int s = eval_here(sc, &u, NULL, NULL);
    if (s) return s;
    *U = u;
    return ODHS_OK;
}

int odhs_softcore_kinetic_energy(const odhs_softcore *sc, double *K)
{
    NEED(sc, K);
    double k = 0.0;
    if (is_massive(sc->model)) k = 0.5 * sc->mass * dot(sc->u, sc->u, sc->nd);
    *K = k;
    return ODHS_OK;
}

int odhs_softcore_forces(const odhs_softcore *sc, double *F)
{
    NEED(sc, F);
    int s = eval_here(sc, NULL, NULL, NULL);
    if (s) return s;
    memcpy(F, sc->w5, sc->nd * sizeof *F);
    return ODHS_OK;
}

int odhs_softcore_max_force(const odhs_softcore *sc, double *fmax)
{
    NEED(sc, fmax);
    int s = eval_here(sc, NULL, NULL, NULL);
    if (s) return s;
    *fmax = max_norm(sc, sc->w5);
    return ODHS_OK;
}

int odhs_softcore_max_overlap(const odhs_softcore *sc, double *ov)
{
    NEED(sc, ov);
    double m;
    int s = eval_here(sc, NULL, NULL, &m);
    if (s) return s;
    *ov = m;
    return ODHS_OK;
}

int odhs_softcore_velocities(odhs_softcore *sc, double *u)
{
    NEED(sc, u);
    if (!is_massive(sc->model)) {
        int s = od_velocity(sc, sc->sys->x, sc->w5, sc->u);
        if (s) return s;
    }
    memcpy(u, sc->u, sc->nd * sizeof *u);
    return ODHS_OK;
}

int odhs_softcore_stress(odhs_softcore *sc, int part, double *sigma)
{
    NEED(sc, sigma);
    if (part < ODHS_SOFTCORE_STRESS_TOTAL || part > ODHS_SOFTCORE_STRESS_KINETIC)
        return scerr(sc, ODHS_E_INVALID, "unknown stress part %d", part);
    int d = sc->dim;
    double el[9], di[9], ki[9] = {0};
    int s = eval_here(sc, NULL, el, NULL);
    if (s) return s;
    memset(di, 0, sizeof di);
    if (sc->model == ODHS_SOFTCORE_CD0 && (part == ODHS_SOFTCORE_STRESS_TOTAL || part == ODHS_SOFTCORE_STRESS_DISSIPATIVE)) {
        s = cd0_solve(sc, sc->w5, sc->u);
        if (s) return s;
        dissipative(sc, ODHS_SOFTCORE_CD, sc->u, NULL, di);
    } else if (is_massive(sc->model)) {
        dissipative(sc, sc->model, sc->u, NULL, di);
        for (size_t i = 0; i < sc->n; ++i)
            for (int a = 0; a < d; ++a)
                for (int b = 0; b < d; ++b) ki[a * 3 + b] -= sc->mass * sc->u[i * d + a] * sc->u[i * d + b];
    }
    double vol;
    odhs_system_volume(sc->sys, &vol);
    for (int a = 0; a < d; ++a)
        for (int b = 0; b < d; ++b) {
            double v;
            switch (part) {
            case ODHS_SOFTCORE_STRESS_ELASTIC: v = el[a * 3 + b]; break;
            case ODHS_SOFTCORE_STRESS_DISSIPATIVE: v = di[a * 3 + b]; break;
            case ODHS_SOFTCORE_STRESS_KINETIC: v = ki[a * 3 + b]; break;
            default: v = el[a * 3 + b] + di[a * 3 + b] + ki[a * 3 + b]; break;
            }
            sigma[a * d + b] = v / vol;
        }
    return ODHS_OK;
}

int odhs_softcore_pressure(odhs_softcore *sc, double *p)
{
    NEED(sc, p);
    double sig[9];
    int s = odhs_softcore_stress(sc, ODHS_SOFTCORE_STRESS_TOTAL, sig);
    if (s) return s;
    double tr = 0.0;
    for (int a = 0; a < sc->dim; ++a) tr += sig[a * sc->dim + a];
    *p = -tr / sc->dim + 0.0; /* no -0 */
    return ODHS_OK;
}

int odhs_softcore_coordination(const odhs_softcore *csc, int rattler_free, double *z)
{
    NEED(csc, z);
    odhs_softcore *sc = (odhs_softcore *)csc;
    int s = eval_here(sc, NULL, NULL, NULL);
    if (s) return s;
    if (!rattler_free) {
        *z = 2.0 * (double)sc->nc / (double)sc->n;
        return ODHS_OK;
    }
    /* g_diag as alive flags, g_z as degrees */
    double *alive = sc->g_diag, *deg = sc->g_z;
    for (size_t i = 0; i < sc->n; ++i) alive[i] = 1.0;
    size_t nalive = sc->n, ncon = 0;
    for (int changed = 1; changed;) {
        changed = 0;
        memset(deg, 0, sc->n * sizeof *deg);
        ncon = 0;
        for (size_t c = 0; c < sc->nc; ++c)
            if (alive[sc->ci[c]] != 0.0 && alive[sc->cj[c]] != 0.0) {
                deg[sc->ci[c]] += 1.0;
                deg[sc->cj[c]] += 1.0;
                ncon++;
            }
        for (size_t i = 0; i < sc->n; ++i)
            if (alive[i] != 0.0 && deg[i] < sc->dim + 1) {
                alive[i] = 0.0;
                nalive--;
                changed = 1;
            }
    }
    *z = nalive ? 2.0 * (double)ncon / (double)nalive : 0.0;
    return ODHS_OK;
}

int odhs_softcore_relaxation_stress(const odhs_softcore *sc, double *sigma)
{
    NEED(sc, sigma);
    if (!sc->has_relax) return scerr(sc, ODHS_E_STATE, "no steepest-descent quasistatic step yet");
    memcpy(sigma, sc->relax, (size_t)(sc->dim * sc->dim) * sizeof *sigma);
    return ODHS_OK;
}
