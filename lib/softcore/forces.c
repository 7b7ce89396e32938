/*
 * libodhs - soft-core models (include/odhs/softcore.h): the neighbour list,
 * the elastic forces, the CD0 linear solve and the dissipative forces.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <stdlib.h>
#include <string.h>

#include "softcore/softcore.h"

/* ---- neighbour list ------------------------------------------------------------ */
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
    int s = odhs__pair_list(d, sc->n, sc->xw, sys->r, sys->rmax, sys->L, sys->gamma, sc->skin, &sc->pi, &sc->pj,
                            &sc->np, &sc->pcap);
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
        return odhs__scerr(sc, s, "neighbour list: %s", odhs_strerror(s));
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
int odhs__sc_elastic(odhs_softcore *sc, const double *x, double *F, double *U, double *sig, double *maxov)
{
    int s = nb_check(sc, x);
    if (s) return s;
    /* reserve first: a failure leaves the forces and the contact list of the
     * last evaluation intact (the massive models' cache survives a rollback) */
    if (ct_reserve(sc, sc->np > 0 ? sc->np : 1)) return odhs__scerr(sc, ODHS_E_NOMEM, "out of memory (contact list)");
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

int odhs__sc_cd0_solve(odhs_softcore *sc, const double *F, double *u)
{
    size_t n = sc->n;
    int d = sc->dim;
    if (!(sc->k0 > 0.0)) return odhs__scerr(sc, ODHS_E_UNSUPPORTED, "CD0 needs a substrate drag k_0 > 0");
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
                return odhs__scerr(sc, ODHS_E_NOCONV, "CD0 solve: relative residual %.3g after %zu iterations",
                                   sqrt(rn) / bn, it);
            cd0_apply(sc, p, q);
            double pq = 0.0;
            for (size_t i = 0; i < n; ++i) pq += p[i] * q[i];
            if (!(pq > 0.0)) return odhs__scerr(sc, ODHS_E_SINGULAR, "CD0 matrix not positive definite");
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
int odhs__sc_od_velocity(odhs_softcore *sc, const double *x, double *F, double *u)
{
    int s = odhs__sc_elastic(sc, x, F, NULL, NULL, NULL);
    if (s) return s;
    if (sc->model == ODHS_SOFTCORE_CD0) return odhs__sc_cd0_solve(sc, F, u);
    if (!(sc->kd > 0.0)) return odhs__scerr(sc, ODHS_E_UNSUPPORTED, "RD0 needs a drag coefficient k_d > 0");
    double m = 1.0 / sc->kd;
    for (size_t k = 0; k < sc->nd; ++k) u[k] = m * F[k];
    return ODHS_OK;
}

/* dissipative forces of the massive models at the recorded contacts,
 * velocities u; optional unnormalised stress sum (sum dv_a r_b k_d). */
void odhs__sc_dissipative(const odhs_softcore *sc, int model, const double *u, double *Fd, double *sig)
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

/* ---- vector helpers -------------------------------------------------------------------- */
double odhs__sc_max_norm(const odhs_softcore *sc, const double *F)
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

double odhs__sc_dot(const double *a, const double *b, size_t n)
{
    double s = 0.0;
    for (size_t k = 0; k < n; ++k) s += a[k] * b[k];
    return s;
}
