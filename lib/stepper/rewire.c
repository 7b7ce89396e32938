/* libodhs - the rewiring (Sect. IV B of the paper) and its anti-cycling
 * fallback: the unique valid network after every event. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

/* Forces for the rewiring: on a potentially jammed network (*pj = 1 on
 * return) the self-stress f0 (Sect. IV D). Under fixed pressure the volume
 * is one more degree of freedom: an isostatic network flows (*pj = 0, the
 * bordered forces of pressure.c) unless p >= the jamming pressure and f0 is
 * positive (jammed, *pj = 1); with one contact more it has the zero-pressure
 * self-stress as its direction (*pj = 1). A failed f0 is
 * ODHS_POTENTIALLY_JAMMED (or ODHS_E_NOMEM). */
static int rewire_forces(odhs_stepper *st, int *pj)
{
    odhs_network *net = st->net;
    int s;
    long excess;
    st->pj_bordered = 0;
    if ((s = odhs__net_excess(net, &excess))) return odhs__sterr(st, s, "%s", net->errmsg);
    *pj = excess >= 1;
    if (!*pj) return odhs__st_compute_forces(st);
    if (st->drv->pressure_on && excess == 2) return odhs__st_pressure_open_direction(st);
    if (!st->drv->pressure_on) {
        if ((s = odhs__null_vector(net, st->sol, net->f, NULL)))
            return odhs__sterr(st, s == ODHS_E_NOMEM ? s : ODHS_POTENTIALLY_JAMMED, "potentially jammed at t = %.17g: %s",
                         st->time, net->errmsg);
        return ODHS_OK;
    }
    if ((s = odhs__st_isostatic_f0(st))) {
        if (s == ODHS_E_NOMEM) return s;
        /* no unique f0: two self-stresses beside a floppy mode, and one of
         * their combinations carries no pressure: over-constrained, as one
         * contact more than isostatic */
        return odhs__st_pressure_open_direction(st);
    }
    if (st->drv->p < st->drv->p_jam) {
        *pj = 0;
        return odhs__st_compute_forces(st);
    }
    memcpy(net->f, st->fpj, net->nc * sizeof *net->f);
    double fmax = 0.0;
    for (size_t c = 0; c < net->nc; ++c) fmax = fmax > fabs(net->f[c]) ? fmax : fabs(net->f[c]);
    for (size_t c = 0; c < net->nc; ++c)
        if (odhs__can_open(net->kind[c]) && net->f[c] < -EPS_F * fmax) {
            *pj = 0;
            return odhs__st_compute_forces(st);
        }
    return ODHS_OK;
}

/* Open contact k: into the removed pairs, out of the network (the last
 * contact takes its place, in net->f and, when given, in x). */
int odhs__st_open_contact(odhs_stepper *st, size_t k, double *x)
{
    odhs_network *net = st->net;
    size_t i = net->ci[k], j = net->cj[k];
    if (odhs__reserve((void **)&st->rem, &st->remcap, st->nrem + 1, sizeof *st->rem))
        return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    st->rem[st->nrem].i = i;
    st->rem[st->nrem].j = j;
    st->nrem++;
    if (x) x[k] = x[net->nc - 1];
    odhs__net_remove_at(net, k);
    if (odhs__st_record_change(st, i, j, -1)) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    return ODHS_OK;
}

/* Re-connect the most approaching removed pair (velocities computed on the
 * current network); *added = 0 when none approaches. The new contact is the
 * network's last, with force 0. */
static int close_pair(odhs_stepper *st, int *added)
{
    *added = 0;
    if (st->nrem == 0) return ODHS_OK;
    double vs = odhs__st_velocity_scale(st), vmin = 0.0;
    size_t rmin = SIZE_MAX;
    for (size_t q = 0; q < st->nrem; ++q) {
        double v = odhs__st_pair_velocity(st, st->rem[q].i, st->rem[q].j);
        if (v < vmin) {
            vmin = v;
            rmin = q;
        }
    }
    if (rmin == SIZE_MAX || vmin >= -EPS_V * vs) return ODHS_OK;
    size_t i = st->rem[rmin].i, j = st->rem[rmin].j;
    st->rem[rmin] = st->rem[st->nrem - 1];
    st->nrem--;
    size_t c;
    int s = odhs__st_add_contact(st, i, j, &c);
    if (s) return s;
    odhs__st_contact_geometry(st, c);
    *added = 1;
    return ODHS_OK;
}

/* One step of the active-set method from the feasible point x towards the
 * solution z = net->f on the current network (or along the direction z on
 * a potentially jammed one, pj): up to the first openable contact that
 * reaches zero, which opens. */
static int monotone_step(odhs_stepper *st, double *x, int pj, double zmax, double xmax)
{
    odhs_network *net = st->net;
    size_t nc = net->nc;
    double *z = net->f;
    int s;
    if (pj && !st->drv->pressure_on) {
        /* descend along f0: b.f0 > 0 */
        if ((s = odhs__st_reserve_contacts(st, nc))) return odhs__sterr(st, s, "out of memory");
        odhs__st_affine_rhs(st, st->cb);
        double bz = 0.0;
        for (size_t c = 0; c < nc; ++c) bz += st->cb[c] * z[c];
        if (bz < 0.0)
            for (size_t c = 0; c < nc; ++c) z[c] = -z[c];
    }
    /* the step x -> x + t d, d = z - x (a solution) or z (a direction),
     * up to the first openable contact that reaches zero */
    double t = INFINITY;
    size_t kb = SIZE_MAX;
    for (size_t c = 0; c < nc; ++c) {
        double d = pj ? z[c] : z[c] - x[c];
        if (!odhs__can_open(net->kind[c]) || !(z[c] < -EPS_F * zmax) || !(d < 0.0)) continue;
        double tc = fmax(x[c], 0.0) / -d;
        if (tc < t) {
            t = tc;
            kb = c;
        }
    }
    if (kb == SIZE_MAX) { /* z < 0 only where d >= 0: x = 0 there, open them */
        t = 0.0;
        for (size_t c = 0; c < nc && kb == SIZE_MAX; ++c)
            if (odhs__can_open(net->kind[c]) && z[c] < -EPS_F * zmax) kb = c;
    }
    if (!pj && t > 1.0) t = 1.0;
    for (size_t c = 0; c < nc; ++c) x[c] += t * (pj ? z[c] : z[c] - x[c]);
    x[kb] = 0.0;
    /* open the blocking contact and every other one that the step
     * brought to zero and that the solution pulls further down */
    double xtol = EPS_F * fmax(xmax, zmax);
    for (size_t c = nc; c-- > 0;)
        if (c == kb || (odhs__can_open(net->kind[c]) && z[c] < -EPS_F * zmax && x[c] <= xtol))
            if ((s = odhs__st_open_contact(st, c, x))) return s;
    return ODHS_OK;
}

/* Anti-cycling rewiring. The rewiring solves a linear complementarity
 * problem: forces f >= 0 on the candidate pairs (the network and the pairs
 * removed so far), gap rates xi0 (N f - b) >= 0, one of the two zero on every
 * pair. With N = S S^T positive semidefinite these are the optimality
 * conditions of the convex quadratic programme min 1/2 f.N f - b.f over
 * f >= 0 (under fixed pressure also r.f = p V d, whose multiplier is the
 * compression rate). Sect. IV B's rule (drop the most negative force) can
 * cycle on degenerate, nearly jammed networks; the active-set method of
 * Lawson and Hanson cannot: it keeps a feasible x, moves it towards the
 * solution z on the current network only as far as x stays >= 0, opens the
 * contact that blocks the move, and adds the most approaching pair only at
 * a solution, so the objective decreases from one network to the next and
 * no network repeats. A potentially jammed network has no solution but a
 * direction of descent: its self-stress f0, signed so that b.f0 > 0 (under
 * fixed pressure the zero-pressure self-stress); a positive f0 is jamming,
 * as in Sect. IV D. The stopping tests are those of the paper's rule. */
static int rewire_monotone(odhs_stepper *st)
{
    odhs_network *net = st->net;
    odhs_driver *drv = st->drv;
    int s = ODHS_OK;
    size_t ncand = net->nc + st->nrem, maxit = 20 * (ncand + 16) + 1000;
    double *x = odhs__calloc(ncand + 1, sizeof *x);
    if (!x) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    st->nrewire_monotone++;
    if (drv->pressure_on && net->nc) {
        /* a feasible start: the pressure on the longest contact alone */
        double vol;
        size_t k = 0;
        odhs_system_volume(st->sys, &vol);
        for (size_t c = 1; c < net->nc; ++c)
            if (net->dist[c] > net->dist[k]) k = c;
        x[k] = drv->p * vol * st->dim / net->dist[k];
    }
    for (size_t it = 0;; ++it) {
        if (it > maxit) {
            s = odhs__sterr(st, ODHS_E_REWIRE, "anti-cycling rewiring did not terminate after %zu iterations", maxit);
            break;
        }
        int pj = 0;
        if ((s = rewire_forces(st, &pj))) break;
        size_t nc = net->nc;
        double *z = net->f, zmax = 0.0, xmax = 0.0;
        for (size_t c = 0; c < nc; ++c) {
            zmax = fmax(zmax, fabs(z[c]));
            xmax = fmax(xmax, fabs(x[c]));
        }
        int neg = 0;
        for (size_t c = 0; c < nc && !neg; ++c) neg = odhs__can_open(net->kind[c]) && z[c] < -EPS_F * zmax;
        if (pj && !neg) {
            s = odhs__st_jam_finish(st);
            break;
        }
        if (!neg) {
            /* a solution on this network: the new feasible point */
            for (size_t c = 0; c < nc; ++c) x[c] = odhs__can_open(net->kind[c]) ? fmax(z[c], 0.0) : z[c];
            odhs__st_compute_velocities(st);
            int added = 0;
            if ((s = close_pair(st, &added)) || !added) break;
            x[net->nc - 1] = 0.0;
            continue;
        }
        if ((s = monotone_step(st, x, pj, zmax, xmax))) break;
    }
    odhs__free(x);
    return s;
}

/* Rewiring (Sect. IV B): remove the most negative force until none is left,
 * then re-connect the most approaching removed pair, and repeat. The rule
 * can cycle near jamming: after a bounded number of iterations (or always,
 * st->rewire_mode == 1) the anti-cycling method above takes over from the
 * network reached so far. */
int odhs__st_rewire(odhs_stepper *st)
{
    odhs_network *net = st->net;
    int s;
    st->nrem = 0;
    if (st->rewire_mode == 1) return rewire_monotone(st);
    size_t maxit = 2 * (net->nc + 16) + 100, it = 0;
    for (;;) {
        if (++it > maxit) return rewire_monotone(st);
        /* Sect. IV D: on a potentially jammed network N is singular and the
         * self-stress f0 plays the part of the forces */
        int pj = 0;
        if ((s = rewire_forces(st, &pj))) return s;
        double fmax = 0.0, fmin = 0.0;
        size_t kmin = SIZE_MAX;
        for (size_t c = 0; c < net->nc; ++c) {
            fmax = fmax > fabs(net->f[c]) ? fmax : fabs(net->f[c]);
            if (odhs__can_open(net->kind[c]) && net->f[c] < fmin) {
                fmin = net->f[c];
                kmin = c;
            }
        }
        if (kmin != SIZE_MAX && fmin < -EPS_F * fmax) {
            if ((s = odhs__st_open_contact(st, kmin, NULL))) return s;
            continue;
        }
        if (pj) return odhs__st_jam_finish(st);
        odhs__st_compute_velocities(st);
        int added = 0;
        if ((s = close_pair(st, &added)) || !added) return s;
    }
}

/* Block rewiring, for a step that ends with many events at once (the
 * batched integrator, whose openings all surface at the step's end): every
 * contact with a negative force opens and every removed pair that
 * approaches is re-connected at once, from one solve (a primal-dual active
 * set), a few times over. It stops on the tests of the paper's rule, so it
 * reaches the same (unique) valid network, with a few solves instead of one
 * per event. A network beyond isostatic, or no settling within the few
 * iterations (more while the number of changes keeps falling: from a
 * detected network at large N, e.g. a reset, the first block opens half
 * the contacts and the changes then shrink geometrically), puts every
 * removed pair back and leaves the rest to the rewiring above. */
#define BLOCK_REWIRE_ITERS 8
#define BLOCK_REWIRE_ITERS_MAX 64
static int rewire_block(odhs_stepper *st)
{
    odhs_network *net = st->net;
    int s, settled = 0;
    size_t prev = SIZE_MAX;
    st->nrem = 0;
    for (int it = 0; it < BLOCK_REWIRE_ITERS_MAX && !settled; ++it) {
        long excess;
        if ((s = odhs__net_excess(net, &excess))) return odhs__sterr(st, s, "%s", net->errmsg);
        if (excess > (st->drv->pressure_on ? 1 : 0)) break;
        int pj = 0;
        if ((s = rewire_forces(st, &pj))) {
            if (s == ODHS_E_NOMEM) return s;
            break; /* the rewiring above reports it */
        }
        if (pj) break;
        double fmax = 0.0;
        for (size_t c = 0; c < net->nc; ++c) fmax = fmax > fabs(net->f[c]) ? fmax : fabs(net->f[c]);
        odhs__st_compute_velocities(st);
        /* the removed pairs that approach under these velocities ... */
        const double vs = odhs__st_velocity_scale(st);
        size_t nback = 0;
        for (size_t q = 0; q < st->nrem; ++q)
            if (odhs__st_pair_velocity(st, st->rem[q].i, st->rem[q].j) < -EPS_V * vs) {
                odhs_change t = st->rem[q];
                st->rem[q] = st->rem[nback];
                st->rem[nback++] = t;
            }
        /* ... open the negative contacts (into the removed pairs, after
         * those) ... */
        size_t opened = 0;
        for (size_t c = net->nc; c-- > 0;)
            if (odhs__can_open(net->kind[c]) && net->f[c] < -EPS_F * fmax) {
                if ((s = odhs__st_open_contact(st, c, NULL))) return s;
                opened++;
            }
        /* ... and re-connect the approaching ones */
        for (size_t q = 0; q < nback; ++q) {
            size_t c;
            if ((s = odhs__st_add_contact(st, st->rem[q].i, st->rem[q].j, &c))) return s;
            odhs__st_contact_geometry(st, c);
        }
        if (nback) memmove(st->rem, st->rem + nback, (st->nrem - nback) * sizeof *st->rem); /* rem may be NULL */
        st->nrem -= nback;
        settled = !opened && !nback;
        if (!settled && it + 1 >= BLOCK_REWIRE_ITERS && opened + nback >= prev) break;
        prev = opened + nback;
    }
    if (settled) return ODHS_OK;
    /* the network of this rewiring's start back, then the paper's rule */
    for (size_t q = 0; q < st->nrem; ++q) {
        size_t c;
        if ((s = odhs__st_add_contact(st, st->rem[q].i, st->rem[q].j, &c))) return s;
        odhs__st_contact_geometry(st, c);
    }
    st->nrem = 0;
    return odhs__st_rewire(st);
}

int odhs__st_rewire_block(odhs_stepper *st)
{
    double old;
    const int pushed = odhs__solver_push_param(st->sol, "update_max", ODHS__BATCH_UPDATE_MAX, &old);
    int s = rewire_block(st);
    odhs__solver_pop_param(st->sol, "update_max", pushed, old);
    return s;
}
