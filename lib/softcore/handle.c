/*
 * libodhs - soft-core models (include/odhs/softcore.h): the handle: creation,
 * settings, positions, box and the error message.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <string.h>

#include "softcore/softcore.h"

int odhs__scerr(const odhs_softcore *sc, int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int s = odhs__verr(((odhs_softcore *)sc)->errmsg, status, fmt, ap);
    va_end(ap);
    return s;
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

static int softcore_create_impl(odhs_system *sys, odhs_softcore **out)
{
    if (!out) return odhs__create_err(ODHS_E_NULL, "odhs_softcore_create: out is NULL");
    *out = NULL;
    if (!sys) return odhs__create_err(ODHS_E_NULL, "odhs_softcore_create: system is NULL");
    if (!odhs_system_is_ready(sys)) {
        odhs__syserr(sys, ODHS_E_STATE, "softcore: the system needs radii and positions");
        return odhs__create_err(ODHS_E_STATE, "odhs_softcore_create: the system needs radii and positions (%s)",
                   sys->has_r ? "positions not set" : "radii not set");
    }
    odhs_softcore *sc = odhs__calloc(1, sizeof *sc);
    if (!sc) return odhs__create_err(ODHS_E_NOMEM, "odhs_softcore_create: out of memory");
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

int odhs_softcore_create(odhs_system *sys, odhs_softcore **out)
{
    odhs__create_begin();
    return odhs__create_end(softcore_create_impl(sys, out));
}

void odhs_softcore_destroy(odhs_softcore *sc)
{
    if (!sc) return;
    sc_free_arrays(sc);
    odhs__free(sc);
}

const char *odhs_softcore_errmsg(const odhs_softcore *sc) { return sc ? sc->errmsg : ""; }

int odhs_softcore_set_model(odhs_softcore *sc, int model)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (model < ODHS_SOFTCORE_RD0 || model > ODHS_SOFTCORE_CDT)
        return odhs__scerr(sc, ODHS_E_INVALID, "unknown soft-core model %d", model);
    sc->model = model;
    sc->fc_ok = 0;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

int odhs_softcore_set_potential(odhs_softcore *sc, double alpha, double k_e)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(alpha) || !isfinite(k_e)) return odhs__scerr(sc, ODHS_E_NONFINITE, "non-finite potential parameter");
    if (!(alpha > 1.0 && alpha <= 10.0))
        return odhs__scerr(sc, ODHS_E_INVALID, "alpha must be in (1, 10], got %g", alpha);
    if (!(k_e > 0.0)) return odhs__scerr(sc, ODHS_E_INVALID, "k_e must be > 0, got %g", k_e);
    sc->alpha = alpha;
    sc->ke = k_e;
    sc->fc_ok = 0;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

#define POSITIVE_SETTER(fname, field, what)                                                     \
    int fname(odhs_softcore *sc, double v)                                                      \
    {                                                                                           \
        SCNULL(sc);                                                                             \
        if (!isfinite(v)) return odhs__scerr(sc, ODHS_E_NONFINITE, what " is not finite");      \
        if (!(v > 0.0)) return odhs__scerr(sc, ODHS_E_INVALID, what " must be > 0, got %g", v); \
        sc->field = v;                                                                          \
        sc->h_ad = 0.0;                                                                         \
        return ODHS_OK;                                                                         \
    }

int odhs_softcore_set_drag(odhs_softcore *sc, double kd)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(kd)) return odhs__scerr(sc, ODHS_E_NONFINITE, "drag coefficient k_d is not finite");
    if (!(kd >= 0.0)) return odhs__scerr(sc, ODHS_E_INVALID, "drag coefficient k_d must be >= 0, got %g", kd);
    sc->kd = kd;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

POSITIVE_SETTER(odhs_softcore_set_mass, mass, "mass")

int odhs_softcore_set_substrate(odhs_softcore *sc, double k0)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(k0)) return odhs__scerr(sc, ODHS_E_NONFINITE, "k_0 is not finite");
    if (!(k0 >= 0.0)) return odhs__scerr(sc, ODHS_E_INVALID, "k_0 must be >= 0, got %g", k0);
    sc->k0 = k0;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

int odhs_softcore_set_shear_rate(odhs_softcore *sc, double g)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(g)) return odhs__scerr(sc, ODHS_E_NONFINITE, "shear rate is not finite");
    if (fabs(g) > 1e300) return odhs__scerr(sc, ODHS_E_INVALID, "shear rate %g too large", g);
    sc->gdot = g;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

int odhs_softcore_set_integrator(odhs_softcore *sc, int integ)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (integ != ODHS_SOFTCORE_FIXED && integ != ODHS_SOFTCORE_ADAPTIVE)
        return odhs__scerr(sc, ODHS_E_INVALID, "unknown integrator %d", integ);
    sc->integ = integ;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

int odhs_softcore_set_dt(odhs_softcore *sc, double c)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(c)) return odhs__scerr(sc, ODHS_E_NONFINITE, "step factor is not finite");
    if (!(c > 0.0 && c <= 10.0)) return odhs__scerr(sc, ODHS_E_INVALID, "step factor must be in (0, 10], got %g", c);
    sc->cdt = c;
    sc->h_ad = 0.0;
    return ODHS_OK;
}

int odhs_softcore_set_tolerance(odhs_softcore *sc, double tol)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(tol)) return odhs__scerr(sc, ODHS_E_NONFINITE, "tolerance is not finite");
    if (!(tol > 0.0 && tol < 1.0)) return odhs__scerr(sc, ODHS_E_INVALID, "tolerance must be in (0, 1), got %g", tol);
    sc->tol = tol;
    return ODHS_OK;
}

int odhs_softcore_set_minimiser(odhs_softcore *sc, int m)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (m != ODHS_SOFTCORE_SD && m != ODHS_SOFTCORE_FIRE && m != ODHS_SOFTCORE_CG)
        return odhs__scerr(sc, ODHS_E_INVALID, "unknown minimiser %d", m);
    sc->minimiser = m;
    return ODHS_OK;
}

int odhs_softcore_set_min_tolerance(odhs_softcore *sc, double tol, uint64_t max_iter)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(tol)) return odhs__scerr(sc, ODHS_E_NONFINITE, "minimiser tolerance is not finite");
    if (!(tol > 0.0)) return odhs__scerr(sc, ODHS_E_INVALID, "minimiser tolerance must be > 0, got %g", tol);
    if (max_iter == 0) return odhs__scerr(sc, ODHS_E_INVALID, "max_iter must be > 0");
    sc->gtol = tol;
    sc->maxit = max_iter;
    return ODHS_OK;
}

int odhs_softcore_set_linear_tolerance(odhs_softcore *sc, double tol)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(tol)) return odhs__scerr(sc, ODHS_E_NONFINITE, "linear tolerance is not finite");
    if (!(tol > 0.0 && tol < 1.0))
        return odhs__scerr(sc, ODHS_E_INVALID, "linear tolerance must be in (0, 1), got %g", tol);
    sc->ltol = tol;
    return ODHS_OK;
}

void odhs__sc_wrap_all(odhs_softcore *sc, double *x)
{
    for (size_t i = 0; i < sc->n; ++i) odhs__wrap(sc->dim, sc->sys->L, sc->sys->gamma, x + i * sc->dim);
}

int odhs_softcore_set_positions(odhs_softcore *sc, const double *x)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!x) return odhs__scerr(sc, ODHS_E_NULL, "positions are NULL");
    for (size_t k = 0; k < sc->nd; ++k)
        if (!isfinite(x[k])) return odhs__scerr(sc, ODHS_E_NONFINITE, "position %zu is not finite", k);
    for (size_t i = 0; i < sc->n; ++i)
        for (int k = 0; k < sc->dim; ++k)
            if (fabs(x[i * sc->dim + k]) > 0x1p50 * sc->sys->L[k])
                return odhs__scerr(sc, ODHS_E_INVALID, "position of particle %zu too far from the box", i);
    memcpy(sc->sys->x, x, sc->nd * sizeof *x);
    odhs__sc_wrap_all(sc, sc->sys->x);
    sc->nb_ok = 0;
    sc->fc_ok = 0;
    return ODHS_OK;
}

int odhs_softcore_scale_box(odhs_softcore *sc, double s)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(s)) return odhs__scerr(sc, ODHS_E_NONFINITE, "scale factor is not finite");
    if (!(s > 0.0)) return odhs__scerr(sc, ODHS_E_INVALID, "scale factor %g must be > 0", s);
    odhs_system *sys = sc->sys;
    for (int k = 0; k < sc->dim; ++k) {
        if (!isfinite(s * sys->L[k])) return odhs__scerr(sc, ODHS_E_NONFINITE, "box edge %d would overflow", k);
        if (!(s * sys->L[k] >= 4.0 * sys->rmax))
            return odhs__scerr(sc, ODHS_E_BOX, "box edge %d would be %g, shorter than twice the largest diameter %g", k,
                               s * sys->L[k], 4.0 * sys->rmax);
    }
    for (int k = 0; k < sc->dim; ++k) sys->L[k] *= s;
    for (size_t q = 0; q < sc->nd; ++q) sys->x[q] *= s;
    odhs__sc_wrap_all(sc, sys->x);
    geometry(sc);
    return ODHS_OK;
}

int odhs_softcore_set_velocities(odhs_softcore *sc, const double *u)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!u) return odhs__scerr(sc, ODHS_E_NULL, "velocities are NULL");
    for (size_t k = 0; k < sc->nd; ++k)
        if (!isfinite(u[k])) return odhs__scerr(sc, ODHS_E_NONFINITE, "velocity %zu is not finite", k);
    memcpy(sc->u, u, sc->nd * sizeof *u);
    return ODHS_OK;
}

int odhs_softcore_reset(odhs_softcore *sc)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!odhs_system_is_ready(sc->sys)) return odhs__scerr(sc, ODHS_E_STATE, "the system is not ready");
    geometry(sc);
    sc->h_ad = 0.0;
    return ODHS_OK;
}
