/* libodhs - collision prediction (Sect. IV A (ii.a) of the paper): exact
 * contact times of pairs and of particles with walls on a straight chord. */
#include <math.h>
#include <string.h>

#include "stepper/stepper.h"

/* earliest time in [0, best) at which a particle not in contact with a wall
 * touches it, moving as x + t (G x + vel) against walls translating with their
 * velocities (moving = 1) or at rest (moving = 0, the drift correction) */
/* Whether particle i would meet wall w at a point where it already touches
 * another wall with the same normal (two segments sharing an end): that
 * constraint is already in the network, and a second copy would make N
 * singular. x is the particle's image near w, moving with u, at time t. */
static int corner_duplicate(const odhs_stepper *st, size_t i, size_t w, const double *x, const double *u, double t)
{
    const odhs_network *net = st->net;
    int dim = st->dim;
    double y[3] = {0, 0, 0}, nw[3], no[3];
    for (uint32_t k = 0; k < net->adjn[i]; ++k) {
        size_t o = net->adj[i][k];
        if (o < st->n || o - st->n == w) continue;
        for (int a = 0; a < dim; ++a) y[a] = x[a] + t * u[a];
        odhs__wall_geom(&net->walls[w], dim, st->sys->L, st->sys->gamma, y, nw, NULL);
        odhs__wall_geom(&net->walls[o - st->n], dim, st->sys->L, st->sys->gamma, y, no, NULL);
        double dot = 0.0;
        for (int a = 0; a < dim; ++a) dot += nw[a] * no[a];
        if (dot > 1.0 - 1e-9) return 1;
    }
    return 0;
}

static double predict_walls(const odhs_stepper *st, const double *G, const double *vel, double best, double vtol,
                            int moving, int current, size_t *pi, size_t *pj)
{
    const odhs_system *s = st->sys;
    const odhs_network *net = st->net;
    int dim = st->dim;
    ((odhs_network *)net)->work_walls++;
    for (size_t w = 0; w < net->nwalls; ++w) {
        const odhs_wall *wl = &net->walls[w];
        for (size_t i = 0; i < st->n; ++i) {
            double x[3] = {0, 0, 0};
            double a = s->r[i], u[3] = {0, 0, 0}, nrm[3] = {0, 0, 0}, gx[3];
            double g0 = odhs__wall_geom(wl, dim, s->L, s->gamma, s->x + i * dim, nrm, x) - a, un = 0.0, uu = 0.0;
            odhs__apply_G(G, dim, x, gx);
            for (int k = 0; k < dim; ++k) u[k] = gx[k] + vel[i * dim + k] - (moving ? wl->v[k] : 0.0);
            for (int k = 0; k < dim; ++k) {
                un += nrm[k] * u[k]; /* > 0: approaching */
                uu += u[k] * u[k];
            }
            if (un <= 0.0 && wl->type == ODHS_WALL_PLANE) continue; /* moving away for good */
            if (g0 > 0.0 && g0 > best * sqrt(uu)) continue; /* cannot reach it in time */
            if (odhs__net_find(net, i, st->n + w) != SIZE_MAX) continue;
            double t = INFINITY;
            if (g0 <= 0.0) {
                /* touching (round-off) and approaching in the current state */
                if (current ? odhs__st_pair_velocity(st, i, st->n + w) < -vtol : un > vtol) t = 0.0;
            } else if (wl->type == ODHS_WALL_PLANE) {
                t = g0 / un;
            } else if (wl->type == ODHS_WALL_SPHERE) {
                /* |q + t u| = R - a from inside: the positive root */
                double q[3] = {0, 0, 0}, B = 0.0, C = 0.0, Rm = wl->R - a;
                for (int k = 0; k < dim; ++k) {
                    q[k] = x[k] - wl->c[k];
                    B += q[k] * u[k];
                    C += q[k] * q[k];
                }
                C -= Rm * Rm; /* < 0 inside */
                if (uu > 0.0) t = (-C) / (B + sqrt(B * B - uu * C));
            } else {
                /* segment: its sides, then its two ends */
                double e[3] = {0, 0, 0}, L2 = 0.0, q[3] = {0, 0, 0};
                for (int k = 0; k < dim; ++k) {
                    e[k] = wl->b[k] - wl->c[k];
                    L2 += e[k] * e[k];
                    q[k] = x[k] - wl->c[k];
                }
                double m0 = -e[1], m1 = e[0], Ls = sqrt(L2);
                double sd = (m0 * q[0] + m1 * q[1]) / Ls, su = (m0 * u[0] + m1 * u[1]) / Ls;
                double sg = sd >= 0.0 ? 1.0 : -1.0;
                if (sg * sd > a && sg * su < 0.0) {
                    double t1 = (sg * sd - a) / (-sg * su);
                    double p = ((q[0] + t1 * u[0]) * e[0] + (q[1] + t1 * u[1]) * e[1]) / L2;
                    if (p >= 0.0 && p <= 1.0) t = t1;
                }
                const double *ends[2] = {wl->c, wl->b};
                for (int k2 = 0; k2 < 2; ++k2) {
                    double qe[2] = {x[0] - ends[k2][0], x[1] - ends[k2][1]};
                    double B = qe[0] * u[0] + qe[1] * u[1], C = qe[0] * qe[0] + qe[1] * qe[1] - a * a;
                    if (B >= 0.0 || C <= 0.0) continue;
                    double disc = B * B - uu * C;
                    if (disc < 0.0) continue;
                    t = fmin(t, C / (-B + sqrt(disc)));
                }
            }
            if (t < best && !corner_duplicate(st, i, w, x, u, t)) {
                best = t;
                *pi = i;
                *pj = st->n + w;
            }
        }
    }
    return best;
}

/* ---- contact flags of the neighbour pairs ------------------------------------
 * A contact never collides, but the sweep below only learnt that from the
 * network's hash after computing the pair's minimum image and chord: at 2D
 * N = 10^4, 15 000 of the 25 000 neighbour pairs are contacts. st->pflag
 * marks them. It follows the network through its change log (network.h),
 * applied here before a sweep; a flag is set only for a pair the network
 * holds, so a stale or missing flag can only send a contact down the full
 * path, never skip a pair that is not one. */

/* pair index of (i, j), i < j, in the neighbour list; SIZE_MAX if absent */
static size_t pair_index(const odhs_stepper *st, size_t i, size_t j)
{
    for (size_t q = st->ppart[i]; q < st->ppart[i + 1]; ++q)
        if (st->pj[st->pidx[q]] == j) return st->pidx[q];
    return SIZE_MAX;
}

/* the flags up to date: 1 when usable, 0 when not (out of memory) */
int odhs__st_pair_flags(odhs_stepper *st)
{
    const odhs_network *net = st->net;
    const size_t n = st->n, np = st->npairs;
    if (st->pflag_state == 2) return 0;
    if (st->pflag_state == 1 && st->pflag_log == net->log_n) return 1;
    if (st->pflag_state == 0) {
        /* the index of a new neighbour list (pairs i < j) */
        if (odhs__reserve((void **)&st->pflag, &st->pflag_cap, np + 1, 1) ||
            odhs__reserve((void **)&st->ppart, &st->ppart_cap, n + 1, sizeof *st->ppart) ||
            odhs__reserve((void **)&st->pidx, &st->pidx_cap, np + 1, sizeof *st->pidx)) {
            st->pflag_state = 2;
            return 0;
        }
        memset(st->ppart, 0, (n + 1) * sizeof *st->ppart);
        for (size_t p = 0; p < np; ++p) st->ppart[st->pi[p] + 1]++;
        for (size_t i = 0; i < n; ++i) st->ppart[i + 1] += st->ppart[i];
        for (size_t p = 0; p < np; ++p) st->pidx[st->ppart[st->pi[p]]++] = p;
        for (size_t i = n; i > 0; --i) st->ppart[i] = st->ppart[i - 1];
        st->ppart[0] = 0;
    }
    if (st->pflag_state == 0 || net->log_n - st->pflag_log > ODHS__NET_LOG) {
        /* from the network's contacts */
        memset(st->pflag, 0, np);
        for (size_t c = 0; c < net->nc; ++c) {
            if (net->cj[c] >= n) continue; /* a wall */
            size_t p = pair_index(st, net->ci[c], net->cj[c]);
            if (p != SIZE_MAX) st->pflag[p] = 1;
        }
    } else {
        /* the changes since, in their order */
        for (uint64_t k = st->pflag_log; k < net->log_n; ++k) {
            const size_t e = (size_t)(k % ODHS__NET_LOG), i = net->log_i[e], j = net->log_j[e];
            if (j >= n) continue;
            size_t p = pair_index(st, i, j);
            if (p != SIZE_MAX) st->pflag[p] = net->log_add[e];
        }
    }
    st->pflag_log = net->log_n;
    st->pflag_state = 1;
    return 1;
}

/* ---- collision prediction ------------------------------------------------ */
/* earliest time in [0, horizon] at which a non-contact pair touches when
 * separations move as d + t (G d + vel_j - vel_i). A touching pair counts
 * when it approaches on the chord (current = 0), in the current velocities
 * (1), or in either (2: the caller's scheme repeats a step whose chord
 * disagrees with the current velocities). */
double odhs__st_predict(odhs_stepper *st, const double *G, const double *vel, double horizon, double vtol,
                        int moving, int current, size_t *pi, size_t *pj)
{
    const odhs_system *s = st->sys;
    int dim = st->dim;
    double best = horizon;
    *pi = *pj = SIZE_MAX;
    const unsigned char *contact = odhs__st_pair_flags(st) ? st->pflag : NULL;
    for (size_t p = 0; p < st->npairs; ++p) {
        if (contact && contact[p]) continue; /* in the network: skipped below too */
        size_t i = st->pi[p], j = st->pj[p];
        double d[3], gd[3] = {0, 0, 0}, w[3] = {0, 0, 0};
        odhs__st_min_sep(st, i, j, d);
        odhs__apply_G(G, dim, d, gd);
        double a = 0.0, b = 0.0, dd = 0.0;
        for (int k = 0; k < dim; ++k) {
            w[k] = gd[k] + vel[j * dim + k] - vel[i * dim + k];
            a += w[k] * w[k];
            b += d[k] * w[k];
            dd += d[k] * d[k];
        }
        if (b >= 0.0) continue; /* not approaching */
        double sig = s->r[i] + s->r[j];
        double c = dd - sig * sig;
        /* quick reject: cannot close the gap within the current best time */
        double gap = sqrt(dd) - sig;
        if (gap > 0.0 && gap > best * sqrt(a)) continue;
        if (odhs__net_find(st->net, i, j) != SIZE_MAX || odhs__same_body(st->net, i, j)) continue;
        double t;
        if (c <= 0.0) {
            /* touching (round-off): a collision now if really approaching */
            /* the approach of a touching pair is that of the current state
             * (the rewiring judges it by the same velocities), not the
             * chord's: else a pair could be added and removed forever */
            if (!current) {
                if (-b <= vtol * sqrt(dd)) continue;
            } else if (odhs__st_pair_velocity(st, i, j) >= -vtol) {
                /* current = 2 (a scheme with an `early` hook): separating
                 * now but closing along the chord is reported too, and the
                 * scheme shortens the step (heun_early) until the chord
                 * agrees; else it would overlap along the chord. */
                if (current < 2 || -b <= vtol * sqrt(dd)) continue;
            }
            t = 0.0;
        } else {
            double disc = b * b - a * c;
            if (disc < 0.0) continue;
            t = c / (-b + sqrt(disc));
        }
        if (t < best) {
            best = t;
            *pi = i;
            *pj = j;
        }
    }
    if (st->net->nwalls) best = predict_walls(st, G, vel, best, vtol, moving, current, pi, pj);
    return best;
}
