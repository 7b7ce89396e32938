/* libodhs - the batched-event step type (ODHS_INTEGRATOR_BATCHED): a step
 * of length h is not truncated at collisions. Every pair that would close
 * within the step takes part in it as a unilateral constraint on the end
 * gap, linearised at the start,
 *     f >= 0,   gap + h (S V)  >= 0,   f (gap + h S V) = 0,
 * with V = xi0 (S^T f + F) the step's velocities: time-stepping contact
 * dynamics for overdamped bodies (Moreau-Jean; Maury and Venel's crowd
 * motion). The linearised gap is a lower bound of the real one (|r + h w| >=
 * n.(r + h w)), so no pair overlaps at the step's end; a pair whose
 * constraint is active ends touching to second order, and the drift
 * correction and rewiring of every step end (step.c) make it an exact
 * contact. The complementarity problem is the rewiring's, with the gap rate
 * -gap/h for 0 (forces.c: st->bh), solved by a block active-set method:
 * every negative force opens and every violated pair closes at once (a
 * primal-dual active set), then one removal at a time if that does not
 * settle (for a few iterations). A network the problem cannot take (one that is potentially
 * jammed, a singular solve, no convergence) makes the step an exact,
 * event-driven one of the Heun scheme.
 *
 * Error control: the local error of this first-order step is h/2 times
 * the change of the non-affine velocities over it; the controller keeps
 * h/2 rms_i |U_i(end) - U_i(step)| (and h/2 |G(end) - G(step)| for the
 * affine flow) below tol times the mean diameter. The root mean square
 * over particles, not the maximum: at large N some particle meets a
 * collision in every step, and a maximum would shrink the step to the
 * time between events. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

/* the smallest step, relative to dt (as Heun's) */
#define BATCHED_HMIN 1e-12
/* block (primal-dual) iterations before one removal at a time */
#define BLOCK_ITERS 8
/* single removals after them before the step is left to the exact scheme */
#define SINGLE_ITERS 24
/* a pair counts as violated when its linearised end gap is below this
 * fraction of its contact distance */
#define GAP_TOL 1e-13

static double batched_hmin(const odhs_stepper *st) { return fmax(BATCHED_HMIN * st->dt, fmin(st->dt, DBL_MIN)); }

static double frob3(const double *A)
{
    double s = 0.0;
    for (int a = 0; a < 9; ++a) s += A[a] * A[a];
    return sqrt(s);
}

/* the displacement record and velocities of the step's start */
static void batched_begin(odhs_stepper *st)
{
    memcpy(st->disps, st->disp, st->nd * sizeof *st->disps);
    memcpy(st->Ms, st->M, sizeof st->Ms);
    memcpy(st->U0, st->U, st->nd * sizeof *st->U0);
}

/* back to the start of the step: configuration, clock, network, forces,
 * flow and velocities (the step's contact changes are forgotten) */
static int back_to_start(odhs_stepper *st)
{
    st->bh = 0.0;
    odhs__st_restore_network(st);
    int s = odhs__st_restart(st);
    memcpy(st->U, st->U0, st->nd * sizeof *st->U);
    st->nchg = 0;
    st->chg_mark = 0;
    st->nrem = 0;
    return s;
}

static int cmp_pair(const void *a, const void *b)
{
    const odhs_change *x = a, *y = b;
    if (x->i != y->i) return x->i < y->i ? -1 : 1;
    return x->j < y->j ? -1 : x->j > y->j;
}

/* the pair (i, j) into bviol (as i < j) unless it is a contact or within
 * one body; *nv counts the pairs there */
static int collect(odhs_stepper *st, size_t i, size_t j, size_t *nv)
{
    if (odhs__net_find(st->net, i, j) != SIZE_MAX || odhs__same_body(st->net, i, j)) return ODHS_OK;
    if (odhs__reserve((void **)&st->bviol, &st->bviolcap, *nv + 1, sizeof *st->bviol))
        return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    st->bviol[*nv].i = i < j ? i : j;
    st->bviol[*nv].j = i < j ? j : i;
    ++*nv;
    return ODHS_OK;
}

/* Close every pair (and particle-wall pair) outside the network whose
 * linearised end gap gap + h w_n is negative under the current flow and
 * velocities; *added counts them. The pairs join the network in the order
 * of their indices, not of the neighbour list: a list rebuilt elsewhere
 * (after a failed step, in a restored run) holds the pairs in another
 * order, and the run must not depend on it. */
static int close_violated(odhs_stepper *st, double h, size_t *added)
{
    const odhs_system *sys = st->sys;
    odhs_network *net = st->net;
    int dim = st->dim, s;
    size_t nv = 0;
    *added = 0;
    for (size_t p = 0; p < st->npairs; ++p) {
        size_t i = st->pi[p], j = st->pj[p];
        double d[3], gd[3] = {0, 0, 0}, b = 0.0, dd = 0.0;
        odhs__st_min_sep(st, i, j, d);
        odhs__apply_G(st->G, dim, d, gd);
        for (int k = 0; k < dim; ++k) {
            b += d[k] * (gd[k] + st->U[j * dim + k] - st->U[i * dim + k]);
            dd += d[k] * d[k];
        }
        if (b >= 0.0) continue; /* not approaching */
        double r = sqrt(dd), sig = sys->r[i] + sys->r[j];
        if (r - sig + h * b / r >= -GAP_TOL * sig) continue;
        if ((s = collect(st, i, j, &nv))) return s;
    }
    if (nv > 1) qsort(st->bviol, nv, sizeof *st->bviol, cmp_pair);
    for (size_t q = 0; q < nv; ++q) {
        size_t c;
        if ((s = odhs__st_add_contact(st, st->bviol[q].i, st->bviol[q].j, &c))) return s;
        odhs__st_contact_geometry(st, c);
        ++*added;
    }
    for (size_t w = 0; w < net->nwalls; ++w)
        for (size_t i = 0; i < st->n; ++i) {
            double nrm[3], g = odhs__wall_geom(&net->walls[w], dim, sys->L, sys->gamma, sys->x + i * dim, nrm, NULL) -
                                sys->r[i];
            double rate = odhs__st_pair_velocity(st, i, st->n + w);
            if (!(rate < 0.0) || g + h * rate >= -GAP_TOL * sys->r[i]) continue;
            if (odhs__net_find(net, i, st->n + w) != SIZE_MAX) continue;
            size_t c;
            if ((s = odhs__st_add_contact(st, i, st->n + w, &c))) return s;
            odhs__st_contact_geometry(st, c);
            ++*added;
        }
    return ODHS_OK;
}

/* The drift correction's block pass (correct.c) under this integrator:
 * every pair outside the network that its chord (flow G, velocities vel,
 * over the unit correction time) would close, in the order of their
 * indices, into bviol; *nv counts them. The end gaps a batched step leaves
 * are O(h^2) (a linearised gap bounds the real one from below), about
 * 1e-3 of a diameter at the default tolerance, and their correction closes
 * tens of pairs at N = 10^4: one pass (a solve) per pair, as for the exact
 * schemes' gaps of 1e-11, cost as much as the step's contact problem. */
int odhs__st_batched_chord_pairs(odhs_stepper *st, const double *G, const double *vel, size_t *nv)
{
    const odhs_system *sys = st->sys;
    int dim = st->dim, s;
    *nv = 0;
    for (size_t p = 0; p < st->npairs; ++p) {
        size_t i = st->pi[p], j = st->pj[p];
        double d[3], gd[3] = {0, 0, 0}, a = 0.0, b = 0.0, dd = 0.0;
        odhs__st_min_sep(st, i, j, d);
        odhs__apply_G(G, dim, d, gd);
        for (int k = 0; k < dim; ++k) {
            double w = gd[k] + vel[j * dim + k] - vel[i * dim + k];
            a += w * w;
            b += d[k] * w;
            dd += d[k] * d[k];
        }
        if (b >= 0.0) continue; /* not approaching */
        double sig = sys->r[i] + sys->r[j], c = dd - sig * sig;
        /* |d + t w| = sig for some t in [0, 1]: the smaller root */
        if (c > 0.0 && (b * b - a * c < 0.0 || c > -b + sqrt(b * b - a * c))) continue;
        if ((s = collect(st, i, j, nv))) return s;
    }
    if (*nv > 1) qsort(st->bviol, *nv, sizeof *st->bviol, cmp_pair);
    return ODHS_OK;
}

/* Open the contacts with negative forces: all of them (block), or only the
 * most negative one; *opened counts them. */
static int open_negative(odhs_stepper *st, int block, size_t *opened)
{
    odhs_network *net = st->net;
    double fmax = 0.0, fmin = 0.0;
    size_t kmin = SIZE_MAX;
    int s;
    *opened = 0;
    for (size_t c = 0; c < net->nc; ++c) {
        fmax = fmax > fabs(net->f[c]) ? fmax : fabs(net->f[c]);
        if (odhs__can_open(net->kind[c]) && net->f[c] < fmin) {
            fmin = net->f[c];
            kmin = c;
        }
    }
    if (kmin == SIZE_MAX || !(fmin < -EPS_F * fmax)) return ODHS_OK;
    if (!block) {
        *opened = 1;
        return odhs__st_open_contact(st, kmin, NULL);
    }
    for (size_t c = net->nc; c-- > 0;)
        if (odhs__can_open(net->kind[c]) && net->f[c] < -EPS_F * fmax) {
            if ((s = odhs__st_open_contact(st, c, NULL))) return s;
            ++*opened;
        }
    return ODHS_OK;
}

/* The step's contact problem at the start configuration, over the step h:
 * the active set into the network, its forces, flow and velocities into
 * net->f, st->G, st->kappa, st->U. *ok = 0 when the problem is one the
 * batched step does not take (the caller takes an exact step). */
static int contact_problem(odhs_stepper *st, double h, int *ok)
{
    odhs_network *net = st->net;
    const int pressure = st->drv->pressure_on;
    int s = ODHS_OK;
    /* a problem that settles neither in blocks nor in a few single
     * removals is left to the exact scheme, which is then cheaper */
    const size_t maxit = BLOCK_ITERS + SINGLE_ITERS;
    *ok = 0;
    st->bh = h;
    st->nrem = 0;
    double old_um;
    const int pushed = odhs__solver_push_param(st->sol, "update_max", ODHS__BATCH_UPDATE_MAX, &old_um);
    for (size_t it = 0; it < maxit; ++it) {
        long excess;
        if ((s = odhs__net_excess(net, &excess))) {
            s = odhs__sterr(st, s, "%s", net->errmsg);
            break;
        }
        /* potentially jammed (under pressure: beyond isostatic) */
        if (excess > (pressure ? 1 : 0)) break;
        st->nbatched_solves++;
        s = odhs__st_compute_forces(st);
        if (s == ODHS_E_SINGULAR || s == ODHS_E_NOCONV || s == ODHS_POTENTIALLY_JAMMED) {
            odhs__solver_invalidate(st->sol); /* its failed setup is not reusable */
            s = ODHS_OK;
            break;
        }
        if (s) break;
        size_t opened = 0, added = 0;
        const int block = it < BLOCK_ITERS;
        if ((s = open_negative(st, block, &opened))) break;
        if (opened && !block) continue;
        odhs__st_compute_velocities(st);
        if ((s = close_violated(st, h, &added))) break;
        if (!opened && !added) {
            *ok = 1;
            break;
        }
    }
    st->bh = 0.0;
    odhs__solver_pop_param(st->sol, "update_max", pushed, old_um);
    return s;
}

/* the exact, event-driven step of the Heun scheme, from the start of the
 * step; the batched step h is kept aside (Heun has its own) and halved */
static int exact_step(odhs_stepper *st, odhs__step_plan *p, double h)
{
    int s;
    if ((s = back_to_start(st))) return s;
    st->nbatched_exact++;
    p->exact = 1;
    st->h = fmax(0.5 * h / st->tau, batched_hmin(st));
    const double hb = st->h;
    /* the factor holds the contact problem's last active set: the first
     * setup of the exact step undoes many changes at once, which a fresh
     * factorisation does more cheaply (and in far less memory at large N)
     * than updates */
    double old_um;
    const int pushed = odhs__solver_push_param(st->sol, "update_max", ODHS__BATCH_UPDATE_MAX, &old_um);
    /* odhs_stepper_jam_lp's end game keeps the exact scheme's accuracy
     * here (st->tol_exact): its Heun tolerance, not the batched one */
    const double tol = st->tol;
    if (st->tol_exact > 0.0) st->tol = st->tol_exact;
    s = odhs__st_advance_exact(st, &odhs__step_heun, p);
    st->tol = tol;
    odhs__solver_pop_param(st->sol, "update_max", pushed, old_um);
    st->h = hb;
    return s;
}

/* the neighbour list covers a motion over h at the skin rate `rate`; else
 * it is rebuilt here, at the start of the step (the start's displacement
 * record is then the new, empty one). *rebuilt = 1 when it was. */
static int cover(odhs_stepper *st, double h, double rate, int *rebuilt)
{
    const double used = odhs__st_skin_used(st);
    *rebuilt = 0;
    if (!st->nb_stale && isfinite(used) && !(used + rate * h > st->skin)) return ODHS_OK;
    st->nb_stale = 0;
    int s = odhs__st_build_neighbours(st);
    if (s) return s;
    memcpy(st->disps, st->disp, st->nd * sizeof *st->disps);
    memcpy(st->Ms, st->M, sizeof st->Ms);
    *rebuilt = 1;
    return ODHS_OK;
}

static int batched_advance(odhs_stepper *st, odhs__step_plan *p)
{
    int s, ok = 0, rebuilt;
    double h = fmin(st->h * st->tau, p->limit);
    p->ci = p->cj = SIZE_MAX;
    /* the list covers the start velocities twice over (those of the step
     * differ by its collisions) */
    if ((s = cover(st, h, 2.0 * odhs__st_skin_rate(st, st->G, st->U), &rebuilt))) return s;
    for (int attempt = 0;; ++attempt) {
        if ((s = contact_problem(st, h, &ok))) return s;
        if (!ok) return exact_step(st, p, h);
        const double rate = odhs__st_skin_rate(st, st->G, st->U);
        if (!st->nb_stale && !(odhs__st_skin_used(st) + rate * h > st->skin)) break;
        /* the step's velocities leave the list: rebuild it at the start, at
         * most 0.9 of the skin per step, and solve again */
        if (attempt >= 8) return exact_step(st, p, h);
        if ((s = back_to_start(st)) || (s = cover(st, h, INFINITY, &rebuilt))) return s;
        if (rate * h > 0.9 * st->skin) h = 0.9 * st->skin / rate;
    }
    /* the problem's contact changes are the step's collisions and openings
     * on their own; its end's (drift correction, rewiring) come after */
    st->chg_mark = st->nchg;
    memcpy(p->G, st->G, sizeof p->G);
    memcpy(st->Ua, st->U, st->nd * sizeof *st->Ua);
    p->vel = st->Ua;
    p->t = p->tplan = h;
    if ((s = odhs__st_move(st, p))) return s;
    if ((s = odhs__st_external_forces(st))) return s;
    odhs__net_geometry(st->net, st->sys);
    if (st->pre_on) st->pre_pend_state = ODHS__PRE_BATCHED;
    return ODHS_OK;
}

/* the error of the step just taken (after its end's rewiring): h/2 times
 * the rms change of the non-affine velocities relative to the mean
 * diameter, or h/2 times the change of the velocity gradient */
static double step_error(const odhs_stepper *st, const odhs__step_plan *p)
{
    double e2 = 0.0, dG[9];
    for (size_t k = 0; k < st->nd; ++k) {
        double dv = st->U[k] - st->Ua[k];
        e2 += dv * dv;
    }
    double err = 0.5 * p->t * sqrt(e2 / (double)st->n) / st->lambda;
    for (int a = 0; a < 9; ++a) dG[a] = st->G[a] - p->G[a];
    return fmax(err, 0.5 * p->t * frob3(dG));
}

static int batched_judge(odhs_stepper *st, odhs__step_plan *p, int *again)
{
    *again = 0;
    /* an exact step controls its own error; at a switch of the driving the
     * velocities jump by the new forces; a jammed end stays */
    if (p->exact) return ODHS_OK;
    if (p->at_switch || st->jammed) {
        st->nbatched++;
        return ODHS_OK;
    }
    const double err = step_error(st, p), hmin = batched_hmin(st);
    const double fac = err > 0.0 ? 0.9 * sqrt(st->tol / err) : 2.0;
    const double h = p->t / st->tau;
    if (!(err <= st->tol) && h > hmin) {
        st->nrejected++;
        st->h = fmax(h * fmax(0.2, fmin(fac, 0.9)), hmin);
        *again = 1;
        return back_to_start(st);
    }
    st->nbatched++;
    /* a step cut by the limit (a run's target) says nothing of the next */
    if (p->t >= st->h * st->tau * (1.0 - 1e-12)) st->h = fmin(st->dt, fmax(h * fmin(2.0, fac), hmin));
    return ODHS_OK;
}

/* default drift-correction interval: every step (the active pairs end
 * touching to second order in h); the first step 1/50 of dt (the
 * controller doubles it from there: a first step of dt, rejected, would
 * cost a contact problem with most near pairs in it) */
const odhs__step_type odhs__step_batched = {ODHS_INTEGRATOR_BATCHED, "batched", 1u, batched_begin, NULL, NULL, NULL,
                                            NULL,                    batched_advance, batched_judge, 1e-3, 5e-2, 2e-2, 1};
