/*
 * libodhs - soft-core models (include/odhs/softcore.h): observables (energies,
 * forces, velocities, stresses, coordination).
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <string.h>

#include "softcore/softcore.h"

/* ---- observables ------------------------------------------------------------------------ */
#define NEED(sc, p)                                                                \
    do {                                                                           \
        if (!(sc)) return ODHS_E_NULL;                                             \
        if (!(p)) return odhs__scerr((sc), ODHS_E_NULL, "output pointer is NULL"); \
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
    *h = (!odhs__sc_is_massive(sc->model) && sc->integ == ODHS_SOFTCORE_ADAPTIVE && sc->h_ad > 0.0)
             ? sc->h_ad
             : odhs__sc_base_step(sc);
    return ODHS_OK;
}

/* evaluate at the current positions (cache state is logically const) */
static int eval_here(const odhs_softcore *csc, double *U, double *sig, double *mo)
{
    odhs_softcore *sc = (odhs_softcore *)csc;
    int fc = sc->fc_ok;
    uint64_t nf = sc->nforce;
    int s = odhs__sc_elastic(sc, sc->sys->x, sc->w5, U, sig, mo);
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
    if (odhs__sc_is_massive(sc->model)) k = 0.5 * sc->mass * odhs__sc_dot(sc->u, sc->u, sc->nd);
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
    *fmax = odhs__sc_max_norm(sc, sc->w5);
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
    if (!odhs__sc_is_massive(sc->model)) {
        int s = odhs__sc_od_velocity(sc, sc->sys->x, sc->w5, sc->u);
        if (s) return s;
    }
    memcpy(u, sc->u, sc->nd * sizeof *u);
    return ODHS_OK;
}

int odhs_softcore_stress(odhs_softcore *sc, int part, double *sigma)
{
    NEED(sc, sigma);
    if (part < ODHS_SOFTCORE_STRESS_TOTAL || part > ODHS_SOFTCORE_STRESS_KINETIC)
        return odhs__scerr(sc, ODHS_E_INVALID, "unknown stress part %d", part);
    int d = sc->dim;
    double el[9], di[9], ki[9] = {0};
    int s = eval_here(sc, NULL, el, NULL);
    if (s) return s;
    memset(di, 0, sizeof di);
    if (sc->model == ODHS_SOFTCORE_CD0 && (part == ODHS_SOFTCORE_STRESS_TOTAL || part == ODHS_SOFTCORE_STRESS_DISSIPATIVE)) {
        s = odhs__sc_cd0_solve(sc, sc->w5, sc->u);
        if (s) return s;
        odhs__sc_dissipative(sc, ODHS_SOFTCORE_CD, sc->u, NULL, di);
    } else if (odhs__sc_is_massive(sc->model)) {
        odhs__sc_dissipative(sc, sc->model, sc->u, NULL, di);
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
    if (!sc->has_relax) return odhs__scerr(sc, ODHS_E_STATE, "no steepest-descent quasistatic step yet");
    memcpy(sigma, sc->relax, (size_t)(sc->dim * sc->dim) * sizeof *sigma);
    return ODHS_OK;
}
