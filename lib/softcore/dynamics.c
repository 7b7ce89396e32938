/*
 * libodhs - soft-core models (include/odhs/softcore.h): time stepping
 * (overdamped Euler, adaptive Heun, SLLOD velocity Verlet) and the snapshot /
 * rollback of a failed step.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <string.h>

#include "softcore/softcore.h"

/* ---- time stepping ------------------------------------------------------------------- */
static double tau_e(const odhs_softcore *sc)
{
    double drag = sc->kd;
    if (sc->model == ODHS_SOFTCORE_CD0 && sc->k0 > drag) drag = sc->k0;
    return drag * sc->dmin * sc->dmin / sc->ke;
}

double odhs__sc_base_step(const odhs_softcore *sc)
{
    double h;
    if (odhs__sc_is_massive(sc->model)) {
        double tm = sqrt(sc->mass * sc->dmin * sc->dmin / sc->ke), td = sc->kd > 0.0 ? sc->mass / sc->kd : INFINITY;
        h = sc->cdt * (tm < td ? tm : td);
    } else {
        h = sc->cdt * tau_e(sc);
    }
    if (sc->gdot != 0.0 && h * fabs(sc->gdot) > 0.01) h = 0.01 / fabs(sc->gdot);
    return h;
}

void odhs__sc_snapshot(odhs_softcore *sc, double *gam, double *str, double *tim)
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

void odhs__sc_rollback(odhs_softcore *sc, double gam, double str, double tim)
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

void odhs__sc_advance_strain(odhs_softcore *sc, double dg)
{
    sc->strain += dg;
    sc->sys->gamma = odhs__remap_strain(sc->sys->gamma + dg, sc->sys->L);
}

int odhs__sc_all_finite(const double *v, size_t n)
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
    int s = odhs__sc_od_velocity(sc, x, sc->F, sc->u);
    if (s) return s;
    for (size_t i = 0; i < sc->n; ++i) {
        x[i * d] += h * (sc->u[i * d] + sc->gdot * x[i * d + 1]);
        for (int k = 1; k < d; ++k) x[i * d + k] += h * sc->u[i * d + k];
    }
    odhs__sc_advance_strain(sc, sc->gdot * h);
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
    int s = odhs__sc_od_velocity(sc, x, sc->F, sc->u);
    if (s) return s;
    for (size_t i = 0; i < sc->n; ++i)
        for (int k = 0; k < d; ++k) k1[i * d + k] = sc->u[i * d + k] + (k == 0 ? sc->gdot * x[i * d + 1] : 0.0);
    double gam0 = sc->sys->gamma, str0 = sc->strain;
    memcpy(u2, sc->u, sc->nd * sizeof *u2);
    for (int tries = 0; tries < 200; ++tries) {
        double h = sc->h_ad < hmax ? sc->h_ad : hmax;
        for (size_t k = 0; k < sc->nd; ++k) xp[k] = x[k] + h * k1[k];
        odhs__sc_advance_strain(sc, sc->gdot * h);
        s = odhs__sc_od_velocity(sc, xp, sc->F, u2);
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
    return odhs__scerr(sc, ODHS_E_NOCONV, "adaptive step could not meet the tolerance");
}

/* massive: SLLOD half kick, u += (h/2) ((F + F_d)/m - gammadot u_y xhat)
 * with the dissipative forces F_d at u (into w1) */
static void sllod_kick(odhs_softcore *sc, double h)
{
    int d = sc->dim;
    double *u = sc->u, *Fd = sc->w1;
    double m = sc->mass;
    odhs__sc_dissipative(sc, sc->model, u, Fd, NULL);
    for (size_t i = 0; i < sc->n; ++i) {
        double uy = u[i * d + 1];
        for (int k = 0; k < d; ++k) {
            double a = (sc->F[i * d + k] + Fd[i * d + k]) / m;
            if (k == 0) a -= sc->gdot * uy;
            u[i * d + k] += 0.5 * h * a;
        }
    }
}

/* massive: SLLOD velocity Verlet, step h */
static int step_sllod(odhs_softcore *sc, double h)
{
    int d = sc->dim;
    double *x = sc->sys->x, *u = sc->u;
    int s;
    if (!sc->fc_ok) {
        s = odhs__sc_elastic(sc, x, sc->F, NULL, NULL, NULL);
        if (s) return s;
    }
    sllod_kick(sc, h);
    for (size_t i = 0; i < sc->n; ++i) {
        double ymid = x[i * d + 1] + 0.5 * h * u[i * d + 1];
        x[i * d] += h * (u[i * d] + sc->gdot * ymid);
        for (int k = 1; k < d; ++k) x[i * d + k] += h * u[i * d + k];
    }
    odhs__sc_advance_strain(sc, sc->gdot * h);
    s = odhs__sc_elastic(sc, x, sc->F, NULL, NULL, NULL);
    if (s) return s;
    sllod_kick(sc, h);
    sc->fc_ok = 1;
    return ODHS_OK;
}

/* one step of at most hmax; *taken receives its length */
static int step_once(odhs_softcore *sc, double hmax, double *taken)
{
    if (sc->model == ODHS_SOFTCORE_RD0 && !(sc->kd > 0.0))
        return odhs__scerr(sc, ODHS_E_UNSUPPORTED, "RD0 needs a drag coefficient k_d > 0");
    if (sc->model == ODHS_SOFTCORE_CD0 && !(sc->k0 > 0.0))
        return odhs__scerr(sc, ODHS_E_UNSUPPORTED, "CD0 needs a substrate drag k_0 > 0");
    double gam, str, tim;
    odhs__sc_snapshot(sc, &gam, &str, &tim);
    double h = odhs__sc_base_step(sc);
    if (h > hmax) h = hmax;
    int s;
    if (odhs__sc_is_massive(sc->model)) {
        s = step_sllod(sc, h);
    } else if (sc->integ == ODHS_SOFTCORE_ADAPTIVE) {
        s = step_heun(sc, hmax, &h);
    } else {
        s = step_euler(sc, h);
    }
    if (s == ODHS_OK && (!odhs__sc_all_finite(sc->sys->x, sc->nd) || !odhs__sc_all_finite(sc->u, sc->nd)))
        s = odhs__scerr(sc, ODHS_E_NONFINITE, "the integration produced non-finite values: reduce the step");
    if (s != ODHS_OK) {
        odhs__sc_rollback(sc, gam, str, tim);
        return s;
    }
    int fc = sc->fc_ok;
    odhs__sc_wrap_all(sc, sc->sys->x);
    sc->fc_ok = fc; /* wrapping does not change the forces */
    sc->time = tim + h;
    sc->nsteps++;
    *taken = h;
    return ODHS_OK;
}

int odhs_softcore_step(odhs_softcore *sc)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    double h;
    return step_once(sc, INFINITY, &h);
}

int odhs_softcore_run_until_strain(odhs_softcore *sc, double gamma)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(gamma)) return odhs__scerr(sc, ODHS_E_NONFINITE, "target strain is not finite");
    if (sc->gdot == 0.0) return odhs__scerr(sc, ODHS_E_INVALID, "run_until_strain needs a nonzero shear rate");
    double rem = (gamma - sc->strain) / sc->gdot;
    if (rem < 0.0)
        return odhs__scerr(sc, ODHS_E_INVALID, "strain %g lies behind the current strain %g", gamma, sc->strain);
    double t_end = sc->time + rem;
    while (sc->time < t_end) {
        double left = t_end - sc->time, h;
        if (left <= 1e-14 * (fabs(t_end) + odhs__sc_base_step(sc))) break;
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
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(t)) return odhs__scerr(sc, ODHS_E_NONFINITE, "target time is not finite");
    if (t < sc->time) return odhs__scerr(sc, ODHS_E_INVALID, "time %g lies before the current time %g", t, sc->time);
    while (sc->time < t) {
        double left = t - sc->time, h;
        if (left <= 1e-14 * (fabs(t) + odhs__sc_base_step(sc))) break;
        int s = step_once(sc, left, &h);
        if (s) return s;
    }
    return ODHS_OK;
}
