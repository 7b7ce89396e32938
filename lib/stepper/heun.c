/* libodhs - the adaptive Heun scheme (the library default since 0.2) as a step type. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

/* ---- adaptive Heun --------------------------------------------------------
 * Predictor: move by tau*V0 (no collision checks: the configuration is only
 * used to evaluate velocities on the same network), solve there for V*. The
 * step uses the average velocity on a straight chord, so collisions are
 * still located exactly on the motion actually taken. Error estimate: the
 * difference between the Euler and Heun non-affine displacements,
 * tau/2 max_i |U*_i - U0_i|, relative to the mean diameter, or that of the
 * affine displacement of neighbours when the shear rate changes over the
 * step. On return *Ga, st->Ua hold the chord's gradient and velocities and
 * *tau the accepted step. */
/* Smallest adaptive step, relative to dt: without a floor an accepted step
 * with an infinite error estimate (fac = 0) or repeated rejections from a
 * tiny h set h to 0 and the integrator stalls forever (found by fuzzing the
 * checkpoint reader). */
#define HEUN_HMIN 1e-12

/* the smallest adaptive step: HEUN_HMIN dt, and never 0 (dt may be tiny) */
static double heun_hmin(const odhs_stepper *st) { return fmax(HEUN_HMIN * st->dt, fmin(st->dt, DBL_MIN)); }

/* Heun's step for dx/dt = G(t) x + U(x, t), k1 = G0 x0 + U0, predictor
 * x* = x0 + tau k1, k2 = G* x* + U*:
 *   x1 = x0 + tau/2 (k1 + k2) = x0 + tau Ga x0 + tau Ua with
 *   Ga = (G0 + G*)/2 + tau/2 G* G0   (applied to positions and box alike)
 *   Ua = (U0 + U*)/2 + tau/2 G* U0   (the flow advects the non-affine step).
 * The G* G0 term matters under compression (G = -c I, G G = c^2 I): without it
 * a touching pair's separation shrinks by (c tau)^2/2 per step; in simple
 * shear G G = 0. Ua goes to st->Ua, from st->U0 and Us. */
static void heun_chord(odhs_stepper *st, const double *G0, const double *Gs, const double *Us, double tau, double *Ga)
{
    int dim = st->dim;
    for (size_t i = 0; i < st->n; ++i) {
        double gu[3];
        odhs__apply_G(Gs, dim, st->U0 + i * dim, gu);
        for (int a = 0; a < dim; ++a)
            st->Ua[i * dim + a] = 0.5 * (st->U0[i * dim + a] + Us[i * dim + a]) + 0.5 * tau * gu[a];
    }
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
            double gg = 0.0;
            for (int c = 0; c < 3; ++c) gg += Gs[3 * a + c] * G0[3 * c + b];
            Ga[3 * a + b] = 0.5 * (G0[3 * a + b] + Gs[3 * a + b]) + 0.5 * tau * gg;
        }
}

/* The predictor of a step of length tau from the start of the step, moved
 * along G0 and st->U0: U* into st->U (on success), G* into Gs, the error
 * estimate into *err. The configuration is put back (M0, and the
 * displacement record as it was), the forces in net->f stay as a guess. */
static int heun_probe(odhs_stepper *st, const double *G0, const double *M0, double k0, double tau, double *Gs,
                      double *err)
{
    odhs_system *sys = st->sys;
    odhs_network *net = st->net;
    size_t nd = st->nd;
    double *disp0 = st->Ua; /* borrow: disp is restored from it below */
    memcpy(disp0, st->disp, nd * sizeof *disp0);
    double t0 = st->time;
    odhs__st_advance(st, G0, st->U0, tau);
    if (net->nwalls) odhs__st_advance_walls(st, tau);
    st->time = t0 + tau;
    st->flow_end = 1;
    odhs__net_geometry(net, sys);
    int s = odhs__st_external_forces(st);
    if (!s) s = odhs__st_compute_forces(st);
    st->time = t0;
    st->flow_end = 0;
    if (!s) odhs__st_compute_velocities(st); /* st->U = U*, st->G = G* */
    double emax = 0.0;
    for (size_t i = 0; i < st->n && !s; ++i) {
        double e2 = 0.0, gu[3];
        /* k2 - k1 = U* - U0 + tau G* U0 (non-affine part) */
        odhs__apply_G(st->G, st->dim, st->U0 + i * st->dim, gu);
        for (int k = 0; k < st->dim; ++k) {
            double dv = st->U[i * st->dim + k] - st->U0[i * st->dim + k] + tau * gu[k];
            e2 += dv * dv;
        }
        emax = fmax(emax, e2);
    }
    *err = 0.5 * tau * sqrt(emax) / st->lambda;
    if (!s && !isfinite(*err)) {
        /* velocities so large (forces of 1e200) that their squares overflow:
         * the same estimate from displacements (|dv| tau stays finite) */
        emax = 0.0;
        for (size_t i = 0; i < st->n; ++i) {
            double e2 = 0.0, gu[3];
            odhs__apply_G(st->G, st->dim, st->U0 + i * st->dim, gu);
            for (int k = 0; k < st->dim; ++k) {
                double dx = (st->U[i * st->dim + k] - st->U0[i * st->dim + k] + tau * gu[k]) * tau;
                e2 += dx * dx;
            }
            emax = fmax(emax, e2);
        }
        *err = 0.5 * sqrt(emax) / st->lambda;
    }
    /* a shear rate that changes over the step (a time-dependent flow) moves
     * neighbours, a distance lambda apart, off the chord by tau/2 |dgdot|
     * lambda: relative to lambda, that counts too (0 for a constant rate) */
    double dg = st->G[3 * 0 + 1] - G0[3 * 0 + 1];
    if (!s && dg != 0.0) *err = fmax(*err, 0.5 * tau * fabs(dg));
    memcpy(Gs, st->G, 9 * sizeof *Gs);
    /* back to the start of the step */
    odhs__st_restore_motion(st);
    memcpy(st->M, M0, 9 * sizeof *M0);
    memcpy(st->disp, disp0, nd * sizeof *disp0);
    odhs__net_geometry(net, sys);
    memcpy(st->G, G0, 9 * sizeof *G0);
    st->kappa = k0;
    return s;
}

/* the accepted predictor: the chord of Heun's x1 = x0 + tau/2 (k1 + k2), the
 * predictor kept for a shorter chord of this step (heun_shorter) */
static void heun_accept(odhs_stepper *st, const double *G0, const double *Gs, double tau, double *Ga)
{
    heun_chord(st, G0, Gs, st->U, tau, Ga);
    memcpy(st->Up, st->U, st->nd * sizeof *st->Up);
    memcpy(st->Gp, Gs, sizeof st->Gp);
    st->taup = tau;
    st->pred_ok = 1;
    memcpy(st->U, st->U0, st->nd * sizeof *st->U);
}

static int heun(odhs_stepper *st, double limit, double *Ga, double *tau_out)
{
    size_t nd = st->nd;
    double G0[9], M0[9], k0 = st->kappa;
    memcpy(G0, st->G, sizeof G0);
    memcpy(M0, st->M, sizeof M0);
    memcpy(st->U0, st->U, nd * sizeof *st->U0);
    st->pred_ok = 0;
    for (int attempt = 0;; ++attempt) {
        double tau = st->h * st->tau, truncated = 0;
        if (limit < tau) {
            tau = limit;
            truncated = 1;
        }
        double err, Gs[9];
        int s = heun_probe(st, G0, M0, k0, tau, Gs, &err);
        if (s == ODHS_E_SINGULAR || s == ODHS_E_NOCONV) {
            /* the predictor's configuration is only a probe (no collision
             * checks): its network may be degenerate there. Shorter probes,
             * and in the end the Euler chord of the start velocities. */
            memcpy(st->U, st->U0, nd * sizeof *st->U);
            st->nrejected++;
            if (attempt < 20) {
                st->h = fmax(0.25 * st->h, heun_hmin(st));
                continue;
            }
            memcpy(st->Ua, st->U0, nd * sizeof *st->Ua);
            memcpy(Ga, G0, sizeof G0);
            *tau_out = tau;
            return ODHS_OK;
        }
        if (s) {
            memcpy(st->U, st->U0, nd * sizeof *st->U);
            return s;
        }
        st->nsolves_pred++;
        double fac = err > 0.0 ? 0.9 * sqrt(st->tol / err) : 2.0;
        if (err <= st->tol || attempt >= 40) {
            heun_accept(st, G0, Gs, tau, Ga);
            if (!truncated) st->h = fmin(st->dt, fmax(st->h * fmin(2.0, fac), heun_hmin(st)));
            *tau_out = tau;
            return ODHS_OK;
        }
        st->nrejected++;
        st->h = fmax(st->h * fmax(0.2, fac), heun_hmin(st));
    }
}

/* The Heun chord of [0, t] for t < taup, the accepted predictor's step, from
 * U*(t) = U0 + (t/taup)(U*(taup) - U0) (and G likewise) instead of a new
 * predictor solve. U*(t) is off by O(t taup), the chord by O(t^2 taup): the
 * order of Heun's own local error, so the step stays second order. Used when
 * a step is cut short at a collision or an opening inside it. */
static void heun_shorter(odhs_stepper *st, double t, double *Ga)
{
    double w = t / st->taup, G0[9], Gt[9];
    memcpy(G0, st->G, sizeof G0);
    for (int a = 0; a < 9; ++a) Gt[a] = G0[a] + w * (st->Gp[a] - G0[a]);
    /* U*(t) into st->tmp (free during the step) */
    for (size_t k = 0; k < st->nd; ++k) st->tmp[k] = st->U0[k] + w * (st->Up[k] - st->U0[k]);
    heun_chord(st, G0, Gt, st->tmp, t, Ga);
}

/* ---- the step type ---------------------------------------------------------- */
/* the displacement record at the start of the step, for odhs__st_restart */
static void heun_begin(odhs_stepper *st)
{
    memcpy(st->disps, st->disp, st->nd * sizeof *st->disps);
    memcpy(st->Ms, st->M, sizeof st->Ms);
}

/* the Heun chord over the step, or, when the step is repeated shorter, the
 * shorter chord from the accepted predictor */
static int heun_plan(odhs_stepper *st, odhs__step_plan *p)
{
    memcpy(p->G, st->G, sizeof p->G);
    /* not under fixed pressure: there the interpolated predictor left
     * contact gaps of ~1e-10 after collision steps at p = 1e4, N = 64 (with
     * the full predictor: below 1e-13 on all but one step over strain 0.05,
     * at the same number of steps) */
    if (p->relocated && st->pred_ok && p->limit < st->taup && !st->drv->pressure_on) {
        heun_shorter(st, p->limit, p->G);
        p->tplan = p->limit;
    } else {
        int s = heun(st, p->limit, p->G, &p->tplan);
        if (s) return s;
    }
    p->vel = st->Ua;
    return ODHS_OK;
}

/* A collision at (almost) the start of the step of a pair that separates
 * with the start velocities: it approaches only on the averaged chord.
 * Added now, the rewiring would remove it again and the next step repeat
 * this (no progress): halve the step instead, until the chord is close
 * enough to the start velocities. */
static int heun_early(odhs_stepper *st, odhs__step_plan *p)
{
    if (p->ci == SIZE_MAX || p->relocated || !(p->t < 1e-3 * p->tplan) || p->nhalve >= 40 ||
        !(odhs__st_pair_velocity(st, p->ci, p->cj) >= -EPS_V * odhs__st_velocity_scale(st)))
        return 0;
    p->nhalve++;
    p->limit = 0.5 * p->tplan;
    return 1;
}

/* The chord was the Heun average over the planned step; repeat the step
 * with the Heun chord of [0, t_collision] (second order). */
static int heun_at_collision(odhs_stepper *st, odhs__step_plan *p, int *again)
{
    if (p->ci == SIZE_MAX || p->relocated || !(p->t < 0.999 * p->tplan) || !(p->t > 0.0)) return ODHS_OK;
    int s = odhs__st_restart(st);
    if (s) return s;
    p->relocated = 1;
    /* at least 1e-3 of the step: over [0, ~1e-17] the chord is the start
     * velocity, which may close the gap far slower than the averaged chord
     * did (a Zeno sequence of ~1e-17 steps otherwise) */
    p->limit = fmax(p->t * (1.0 + 1e-7), 1e-3 * p->tplan);
    *again = 1;
    return ODHS_OK;
}

/* Locate an opening inside a step without a collision: forces are smooth in
 * time, so the first zero crossing t* = t f0/(f0 - f1) (second-order
 * accurate) ends a repeated, shorter step, instead of the step's end. */
static int heun_at_opening(odhs_stepper *st, odhs__step_plan *p, int *again)
{
    odhs_network *net = st->net;
    if (p->ci != SIZE_MAX || p->relocated || net->nc != st->snc) return ODHS_OK;
    long excess = 0;
    odhs__net_excess(net, &excess);
    /* under fixed pressure an isostatic network still flows */
    int flows = excess < 1 || (st->drv->pressure_on && excess == 1), s;
    if (!flows) return ODHS_OK;
    if ((s = odhs__st_compute_forces(st)) != ODHS_OK)
        /* locating the opening is a probe: the rewiring decides */
        return s == ODHS_E_SINGULAR || s == ODHS_E_NOCONV ? ODHS_OK : s;
    double fbig = 0.0, tstar = INFINITY, t = p->t;
    for (size_t c = 0; c < net->nc; ++c) fbig = fmax(fbig, fabs(net->f[c]));
    for (size_t c = 0; c < net->nc; ++c) {
        double f0 = st->fr[c], f1 = net->f[c];
        /* f0 at round-off level: the contact opens now, at the step's end
         * (relocating to t f0/(f0 - f1) ~ 1e-16 t would repeat forever, as
         * the force stays at round-off) */
        if (!odhs__can_open(net->kind[c]) || !(f1 < -EPS_F * fbig) || !(f0 > EPS_F * fbig)) continue;
        tstar = fmin(tstar, t * f0 / (f0 - f1));
    }
    if (!(tstar < 0.999 * t)) return ODHS_OK;
    if ((s = odhs__st_restart(st))) return s;
    p->relocated = 1;
    /* a force that starts at (almost) zero would give steps of no length
     * forever: end the step a little later, where the force is negative and
     * the rewiring opens the contact */
    p->limit = fmax(tstar * (1.0 + 1e-9), 1e-6 * t);
    *again = 1;
    return ODHS_OK;
}

/* default drift-correction interval: every step, since the adaptive chord's
 * errors (O(h^3), either sign) would otherwise leave overlaps of ~1e-11 at
 * tol 1e-6 (docs/accuracy.md) */
const odhs__step_type odhs__step_heun = {ODHS_INTEGRATOR_HEUN, "heun", 1u, heun_begin, heun_plan, heun_early,
                                         heun_at_collision,    heun_at_opening, NULL, NULL, 1e-6, 1e-3, 1.0, 0};
