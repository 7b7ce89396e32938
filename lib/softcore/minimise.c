/*
 * libodhs - soft-core models (include/odhs/softcore.h): energy minimisation
 * (steepest descent, FIRE, Polak-Ribiere CG) and quasistatic shear.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <string.h>

#include "softcore/softcore.h"

/* ---- minimisation -------------------------------------------------------------------- */
static int min_sd(odhs_softcore *sc, uint64_t *iters)
{
    double *x = sc->sys->x, sig[9];
    double h = sc->cdt * sc->kd * sc->dmin * sc->dmin / sc->ke;
    int d = sc->dim;
    memset(sc->relax_acc, 0, sizeof sc->relax_acc);
    uint64_t it = 0;
    for (;;) {
        int s = odhs__sc_elastic(sc, x, sc->F, NULL, sig, NULL);
        if (s) return s;
        if (odhs__sc_max_norm(sc, sc->F) < sc->gtol) break;
        if (it >= sc->maxit)
            return odhs__scerr(sc, ODHS_E_NOCONV, "steepest descent: largest force %.3g after %llu iterations",
                               odhs__sc_max_norm(sc, sc->F), (unsigned long long)it);
        for (int a = 0; a < d; ++a)
            for (int b = 0; b < d; ++b) sc->relax_acc[a * 3 + b] += h * sig[a * 3 + b];
        double m = h / sc->kd;
        for (size_t k = 0; k < sc->nd; ++k) x[k] += m * sc->F[k];
        if ((it & 63u) == 63u) odhs__sc_wrap_all(sc, x);
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
        int s = odhs__sc_elastic(sc, x, F, NULL, NULL, NULL);
        if (s) return s;
        if (odhs__sc_max_norm(sc, F) < sc->gtol) break;
        if (it >= sc->maxit)
            return odhs__scerr(sc, ODHS_E_NOCONV, "FIRE: largest force %.3g after %llu iterations",
                               odhs__sc_max_norm(sc, F), (unsigned long long)it);
        double P = odhs__sc_dot(F, v, nd);
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
        double vn = sqrt(odhs__sc_dot(v, v, nd)), fn = sqrt(odhs__sc_dot(F, F, nd));
        if (fn > 0.0)
            for (size_t k = 0; k < nd; ++k) v[k] = (1.0 - al) * v[k] + al * vn * F[k] / fn;
        for (size_t k = 0; k < nd; ++k) x[k] += dt * v[k];
        if ((it & 63u) == 63u) odhs__sc_wrap_all(sc, x);
        it++;
    }
    *iters = it;
    return ODHS_OK;
}

/* g(s) = F(x + s d) . d */
static int line_g(odhs_softcore *sc, const double *x, const double *dir, double s, double *xt, double *Ft, double *g)
{
    for (size_t k = 0; k < sc->nd; ++k) xt[k] = x[k] + s * dir[k];
    int st = odhs__sc_elastic(sc, xt, Ft, NULL, NULL, NULL);
    if (st) return st;
    *g = odhs__sc_dot(Ft, dir, sc->nd);
    return ODHS_OK;
}

static int min_cg(odhs_softcore *sc, uint64_t *iters)
{
    double *x = sc->sys->x, *F = sc->F, *dir = sc->w1, *Fo = sc->w2, *xt = sc->w3, *Ft = sc->w4;
    size_t nd = sc->nd;
    double s0 = sc->cdt * sc->dmin * sc->dmin / sc->ke;
    int st = odhs__sc_elastic(sc, x, F, NULL, NULL, NULL);
    if (st) return st;
    memcpy(dir, F, nd * sizeof *dir);
    uint64_t it = 0, since = 0;
    for (;;) {
        if (odhs__sc_max_norm(sc, F) < sc->gtol) break;
        if (it >= sc->maxit)
            return odhs__scerr(sc, ODHS_E_NOCONV, "CG: largest force %.3g after %llu iterations",
                               odhs__sc_max_norm(sc, F), (unsigned long long)it);
        double g0 = odhs__sc_dot(F, dir, nd);
        if (!(g0 > 0.0)) {
            memcpy(dir, F, nd * sizeof *dir);
            g0 = odhs__sc_dot(F, dir, nd);
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
        double beta = (odhs__sc_dot(F, F, nd) - odhs__sc_dot(F, Fo, nd)) / odhs__sc_dot(Fo, Fo, nd);
        if (!(beta > 0.0) || ++since >= nd) {
            beta = 0.0;
            since = 0;
        }
        for (size_t q = 0; q < nd; ++q) dir[q] = F[q] + beta * dir[q];
        if ((it & 63u) == 63u) odhs__sc_wrap_all(sc, x);
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
        return odhs__scerr(sc, ODHS_E_UNSUPPORTED, "steepest descent needs a drag coefficient k_d > 0 (its mobility)");
    switch (sc->minimiser) {
    case ODHS_SOFTCORE_FIRE: s = min_fire(sc, iters); break;
    case ODHS_SOFTCORE_CG: s = min_cg(sc, iters); break;
    default: s = min_sd(sc, iters); break;
    }
    if (s == ODHS_OK && !odhs__sc_all_finite(sc->sys->x, sc->nd))
        s = odhs__scerr(sc, ODHS_E_NONFINITE, "the minimiser produced non-finite positions: reduce the step");
    if (s == ODHS_OK) {
        odhs__sc_wrap_all(sc, sc->sys->x);
        memset(sc->u, 0, sc->nd * sizeof *sc->u);
        sc->nmin += *iters;
        sc->fc_ok = 0;
    }
    return s;
}

int odhs_softcore_minimise(odhs_softcore *sc, uint64_t *iterations)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    double gam, str, tim;
    uint64_t it = 0;
    odhs__sc_snapshot(sc, &gam, &str, &tim);
    int s = minimise_inner(sc, &it);
    if (s) {
        odhs__sc_rollback(sc, gam, str, tim);
        return s;
    }
    sc->has_relax = 0;
    if (iterations) *iterations = it;
    return ODHS_OK;
}

int odhs_softcore_quasistatic_step(odhs_softcore *sc, double dgamma, uint64_t *iterations)
{
    SCNULL(sc);
    sc->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(dgamma)) return odhs__scerr(sc, ODHS_E_NONFINITE, "strain step is not finite");
    if (dgamma == 0.0 || fabs(dgamma) > 0.1)
        return odhs__scerr(sc, ODHS_E_INVALID, "strain step must be nonzero and at most 0.1, got %g", dgamma);
    double gam, str, tim;
    odhs__sc_snapshot(sc, &gam, &str, &tim);
    int d = sc->dim;
    double *x = sc->sys->x;
    for (size_t i = 0; i < sc->n; ++i) x[i * d] += dgamma * x[i * d + 1];
    odhs__sc_advance_strain(sc, dgamma);
    odhs__sc_wrap_all(sc, x);
    uint64_t it = 0;
    int s = minimise_inner(sc, &it);
    if (s) {
        odhs__sc_rollback(sc, gam, str, tim);
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
