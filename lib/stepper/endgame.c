/* libodhs - the jamming end-game (Sect. IV D of the paper): polish, final
 * pivots, rattlers out of overlaps, f0 on the final geometry. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

/* Pairs outside the network overlapping by more than this (relative to the
 * contact distance) after a polish are taken into the network by a pivot;
 * the polish leaves contact gaps of ~2e-16, the certificate's bound is 1e-14 */
#define JAM_OVERLAP 4e-15

/* pivots at most per jammed packing */
#define JAM_PIVOTS 64

typedef struct {
    const odhs_network *net;
    const unsigned char *in;
    const double *r;
    int dim;
    double worst[2]; /* [0]: both in the backbone, [1]: one a rattler */
    size_t i[2], j[2];
    double v[2][3];
} jam_ov_ctx;

/* the most overlapping pairs outside the network with a backbone particle */
static int jam_ov_cb(size_t i, size_t j, const double *rij, double gap, void *vctx)
{
    jam_ov_ctx *c = vctx;
    int w = !(c->in[i] && c->in[j]);
    double rel = -gap / (c->r[i] + c->r[j]);
    if (!(rel > c->worst[w]) || (!c->in[i] && !c->in[j])) return 0;
    if (odhs__net_find(c->net, i, j) != SIZE_MAX || odhs__same_body(c->net, i, j)) return 0;
    c->worst[w] = rel;
    c->i[w] = i;
    c->j[w] = j;
    for (int a = 0; a < c->dim; ++a) c->v[w][a] = rij[a];
    return 0;
}

/* backbone (constrained subset) flags of the network, n entries; *in is
 * NULL after an error (the stepper's message is set) */
static int jam_backbone(odhs_stepper *st, unsigned char **in)
{
    size_t nbar = 0, ncon = 0;
    *in = odhs__malloc_array(st->n, 1);
    if (!*in) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    int s = odhs_network_constrained(st->net, &nbar, &ncon, *in, NULL);
    if (s) {
        odhs__free(*in);
        *in = NULL;
        return odhs__sterr(st, s, "%s", st->net->errmsg);
    }
    return ODHS_OK;
}

/* the most negative force on an openable backbone contact (0 if none) and
 * the largest |f| and the mean f over the backbone contacts */
static double jam_backbone_low(const odhs_stepper *st, const unsigned char *in, double *big, double *mean)
{
    const odhs_network *net = st->net;
    double low = 0.0, sum = 0.0;
    size_t m = 0;
    *big = 0.0;
    for (size_t c = 0; c < net->nc; ++c) {
        if (!in[net->ci[c]] || (net->cj[c] < st->n && !in[net->cj[c]])) continue;
        *big = fmax(*big, fabs(net->f[c]));
        sum += net->f[c];
        m++;
        if (odhs__can_open(net->kind[c])) low = fmin(low, net->f[c]);
    }
    *mean = m ? sum / (double)m : 0.0;
    return low;
}

/* One pivot of the jammed packing, a dual simplex step of the linear
 * programme "largest isotropic compression with every gap >= 0" around the
 * current geometry, whose vertex is the isostatic network C with self-stress
 * f0 > 0 (dual feasible). A backbone pair p outside C that the polish left
 * overlapping by delta violates the programme: its exact packing needs p in
 * the network. The self-stress h of C + p with h_p = 1 and <h|r> = 0 (the
 * dual direction) moves the forces f0/<f0|r> + t h until a contact k of C
 * reaches zero (the ratio test); k leaves, p enters with force t > 0. The sum
 * of h_c gap_c is invariant under every displacement and compression, so
 * after the next polish k is open by delta / |h_k| > 0. *pivoted = 0 when
 * there is nothing to do (or the pivot cannot be computed: the packing is
 * then left as it is, and its certificate tells). */
static int jam_pivot(odhs_stepper *st, int *pivoted)
{
    odhs_network *net = st->net;
    size_t nc = net->nc;
    *pivoted = 0;
    unsigned char *in = NULL;
    double *h = NULL;
    int s = jam_backbone(st, &in);
    if (s) goto done;
    if (!(h = odhs__calloc(nc + 1, sizeof *h))) {
        s = odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
        goto done;
    }
    /* only from a dual feasible vertex: f0 >= 0 on the backbone (a negative
     * f0 after the polish is jam_check_f0's) */
    double f0max, f0mean;
    if (jam_backbone_low(st, in, &f0max, &f0mean) < -EPS_F * f0max) goto done;
    jam_ov_ctx oc = {net, in, st->sys->r, st->dim, {JAM_OVERLAP, JAM_OVERLAP}, {SIZE_MAX, SIZE_MAX},
                     {SIZE_MAX, SIZE_MAX}, {{0, 0, 0}, {0, 0, 0}}};
    s = odhs__pairs(st->dim, st->n, st->sys->x, st->sys->r, st->sys->rmax, st->sys->L, st->sys->gamma, 0.0, jam_ov_cb,
                    &oc);
    if (s == ODHS_E_NOMEM) {
        s = odhs__sterr(st, s, "out of memory");
        goto done;
    }
    s = ODHS_OK;
    /* a pair of backbone particles first; a pair with a rattler enters only
     * if the rattler has contacts enough to balance it (else odhs__st_jam_rattlers) */
    int e = ODHS_E_STATE;
    size_t pi = SIZE_MAX, pj = SIZE_MAX;
    for (int w = 0; w < 2 && e; ++w) {
        if (oc.i[w] == SIZE_MAX) continue;
        double dist = sqrt(oc.v[w][0] * oc.v[w][0] + oc.v[w][1] * oc.v[w][1] + oc.v[w][2] * oc.v[w][2]);
        double nrm[3] = {0, 0, 0};
        for (int a = 0; a < st->dim; ++a) nrm[a] = oc.v[w][a] / dist;
        e = odhs__jam_pair_stress(net, st->sol, net->f, oc.i[w], oc.j[w], nrm, dist, h);
        if (e == ODHS_E_NOMEM) {
            s = odhs__sterr(st, e, "out of memory");
            goto done;
        }
        pi = oc.i[w];
        pj = oc.j[w];
    }
    if (e) goto done;
    double fr = 0.0, hmax = 0.0, t = INFINITY;
    size_t k = SIZE_MAX;
    for (size_t c = 0; c < nc; ++c) {
        fr += net->f[c] * net->dist[c];
        hmax = fmax(hmax, fabs(h[c]));
    }
    for (size_t c = 0; c < nc; ++c) {
        if (!odhs__can_open(net->kind[c]) || !(h[c] < -EPS_F * hmax)) continue;
        double tc = net->f[c] / fr / -h[c];
        if (tc < t) {
            t = tc;
            k = c;
        }
    }
    if (k == SIZE_MAX) goto done;
    for (size_t c = 0; c < nc; ++c) net->f[c] = c == k ? 0.0 : fmax(net->f[c] / fr + t * h[c], 0.0);
    size_t cp;
    if ((s = odhs__st_add_contact(st, pi, pj, &cp))) goto done;
    odhs__st_contact_geometry(st, cp);
    net->f[cp] = t;
    if ((s = odhs__st_open_contact(st, k, NULL))) goto done;
    st->njam_pivots++;
    *pivoted = 1;
done:
    odhs__free(in);
    odhs__free(h);
    return s;
}

/* rattlers are moved out of overlaps by this margin (relative to the pair's
 * contact distance), at most this many sweeps */
#define JAM_RATTLER_MARGIN 4e-15

#define JAM_RATTLER_SWEEPS 200
/* a sweep takes the pairs closer than this (relative), and passes over them
 * at most this many times */
#define JAM_RATTLER_NEAR 1e-9
#define JAM_RATTLER_PASSES 20000

typedef struct {
    const odhs_network *net;
    const unsigned char *in;
    const double *r;
    int dim;
    size_t m, cap;
    struct jam_push {
        size_t i, j;
        double v[3], sig; /* the vector from i to j at the search; the contact distance */
    } *list;
    size_t over;
    int nomem;
} jam_push_ctx;

/* pairs outside the network with a rattler in them, overlapping or closer
 * than JAM_RATTLER_NEAR (c->over counts the overlapping ones) */
static int jam_push_cb(size_t i, size_t j, const double *rij, double gap, void *vctx)
{
    jam_push_ctx *c = vctx;
    double sig = c->r[i] + c->r[j];
    if (!(gap < JAM_RATTLER_NEAR * sig) || (c->in[i] && c->in[j])) return 0;
    if (odhs__net_find(c->net, i, j) != SIZE_MAX || odhs__same_body(c->net, i, j)) return 0;
    if (odhs__reserve((void **)&c->list, &c->cap, c->m + 1, sizeof *c->list)) {
        c->nomem = 1;
        return 1;
    }
    struct jam_push *p = &c->list[c->m++];
    p->i = i;
    p->j = j;
    for (int a = 0; a < c->dim; ++a) p->v[a] = rij[a];
    p->sig = sig;
    if (gap < -1e-15 * sig) c->over++;
    return 0;
}

/* Rattlers carry no force, so the polish (which moves the backbone, and the
 * rattlers only with their own contacts) can leave a rattler overlapping the
 * packing by as much as it moved the backbone. Such a rattler is moved out
 * along the pair normals (split between two rattlers), sweep after sweep,
 * and its force-free contacts open. Not with bonds or walls.
 *
 * Since 0.2.24 a sweep takes every such pair closer than JAM_RATTLER_NEAR
 * and passes over them until none is closer than the margin (at most
 * JAM_RATTLER_PASSES times), each push on the current positions: the
 * projections onto the pairs' half-spaces in turn, which reach a point of
 * their intersection where one exists. Up to 0.2.23 a sweep pushed once per
 * overlapping pair, each push computed from the positions at the start of
 * the sweep, and the next sweep searched the whole packing again: two
 * neighbouring rattlers without contacts wedged in a narrow cage (3D
 * N = 8000 from the chain; a placement with 6e-12 of room exists 1e-10
 * away, along the wedge) were pushed back and forth across it and kept
 * 5.2e-14 of overlap after the 200 sweeps, above the certificate's 1e-14. */
int odhs__st_jam_rattlers(odhs_stepper *st)
{
    odhs_network *net = st->net;
    odhs_system *sys = st->sys;
    int d = st->dim;
    if (net->nperm || net->nwalls) return ODHS_OK;
    unsigned char *in = NULL, *moved = NULL;
    double *dx = NULL;
    int s = jam_backbone(st, &in);
    jam_push_ctx pc = {net, in, sys->r, d, 0, 0, NULL, 0, 0};
    if (s) goto done;
    if (!(moved = odhs__calloc(st->n, 1)) || !(dx = odhs__calloc(st->nd, sizeof *dx))) {
        s = odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
        goto done;
    }
    if (!memchr(in, 0, st->n)) goto done; /* no rattlers */
    for (int sweep = 0; sweep < JAM_RATTLER_SWEEPS; ++sweep) {
        pc.m = 0;
        pc.over = 0;
        s = odhs__pairs(d, st->n, sys->x, sys->r, sys->rmax, sys->L, sys->gamma,
                        JAM_RATTLER_NEAR * 2.0 * sys->rmax, jam_push_cb, &pc);
        if (pc.nomem || s == ODHS_E_NOMEM) {
            s = odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
            goto done;
        }
        s = ODHS_OK;
        if (pc.over == 0) break;
        for (int pass = 0, pushed = 1; pushed && pass < JAM_RATTLER_PASSES; ++pass) {
            pushed = 0;
            for (size_t q = 0; q < pc.m; ++q) {
                struct jam_push *p = &pc.list[q];
                /* the pair on the current positions */
                double v[3] = {0.0, 0.0, 0.0}, dist = 0.0;
                for (int a = 0; a < d; ++a) {
                    v[a] = p->v[a] + dx[p->j * d + a] - dx[p->i * d + a];
                    dist += v[a] * v[a];
                }
                dist = sqrt(dist);
                double need = (1.0 + JAM_RATTLER_MARGIN) * p->sig - dist;
                if (!(need > 0.5 * JAM_RATTLER_MARGIN * p->sig) || !(dist > 0.0)) continue;
                pushed = 1;
                size_t ends[2] = {p->i, p->j};
                double share = in[p->i] || in[p->j] ? 1.0 : 0.5;
                for (int e = 0; e < 2; ++e) {
                    size_t i = ends[e];
                    if (in[i]) continue;
                    if (!moved[i]) { /* its contacts carry no force: they open */
                        moved[i] = 1;
                        for (size_t c = net->nc; c-- > 0;)
                            if ((net->ci[c] == i || net->cj[c] == i) && odhs__can_open(net->kind[c]))
                                if ((s = odhs__st_open_contact(st, c, NULL))) goto done;
                    }
                    double sgn = e == 0 ? -1.0 : 1.0;
                    for (int a = 0; a < d; ++a) dx[i * d + a] += sgn * share * need * v[a] / dist;
                }
            }
        }
        /* the sweep's displacements, added once (added push by push, the
         * positions' round-off would build up over the passes) */
        for (size_t i = 0; i < st->n; ++i) {
            if (!moved[i]) continue;
            for (int a = 0; a < d; ++a) {
                sys->x[i * d + a] += dx[i * d + a];
                dx[i * d + a] = 0.0;
            }
            odhs__wrap(d, sys->L, sys->gamma, sys->x + i * d);
        }
    }
    odhs__net_geometry(net, sys);
done:
    odhs__free(in);
    odhs__free(moved);
    odhs__free(dx);
    odhs__free(pc.list);
    return s;
}

/* Sect. IV D on the final geometry: a jammed packing needs f0 > 0 on the
 * backbone after the polish too. A polish that starts from large contact gaps
 * (a coarse integration without drift correction) moves the backbone enough
 * to change the signs; then the packing is not jammed, and the step is not
 * taken (ODHS_POTENTIALLY_JAMMED, rolled back by the caller). */
static int jam_check_f0(odhs_stepper *st)
{
    unsigned char *in = NULL;
    int s = jam_backbone(st, &in);
    if (s) return s;
    double big, mean, low = jam_backbone_low(st, in, &big, &mean);
    odhs__free(in);
    if (low < -EPS_F * big)
        return odhs__sterr(st, ODHS_POTENTIALLY_JAMMED,
                     "potentially jammed at t = %.17g: after the polish the self-stress has a negative component "
                     "(%.3g of the mean force), so the packing is not jammed; the step was not taken (a drift "
                     "correction before it gives the polish a closer start)",
                     st->time, mean > 0.0 ? low / mean : low);
    return ODHS_OK;
}

/* The end of a rewiring on a jammed network (positive self-stress): polish
 * the contacts to round-off, take in any pair that the polish left
 * overlapping (jam_pivot) and polish again, move overlapping rattlers out
 * (odhs__st_jam_rattlers), check f0 on the final geometry (jam_check_f0) and scale it
 * to unit pressure; nothing can move under this driving. */
int odhs__st_jam_finish(odhs_stepper *st)
{
    odhs_network *net = st->net;
    int s;
    st->njam_pivots = 0;
    for (int piv = 0;; ++piv) {
        if ((s = odhs__jam_polish(st->sys, net, st->sol, net->f)))
            return odhs__sterr(st, s, "polishing the jammed packing: %s", odhs_strerror(s));
        if ((s = odhs__null_vector_ex(net, st->sol, net->f, NULL, 1)))
            return odhs__sterr(st, s == ODHS_E_NOMEM ? s : ODHS_POTENTIALLY_JAMMED, "jammed packing: %s", net->errmsg);
        int pivoted = 0;
        if (piv == JAM_PIVOTS || net->nwalls || (s = jam_pivot(st, &pivoted)) || !pivoted) break;
    }
    if (s || (s = odhs__st_jam_rattlers(st))) return s;
    if ((s = jam_check_f0(st))) return s;
    double fr = 0.0, vol;
    for (size_t c = 0; c < net->nc; ++c) fr += net->f[c] * net->dist[c];
    odhs_system_volume(st->sys, &vol);
    double scale = vol * st->dim / fr;
    for (size_t c = 0; c < net->nc; ++c) net->f[c] *= scale;
    memset(st->U, 0, st->nd * sizeof *st->U);
    st->jammed = 1;
    return ODHS_OK;
}
