/* libodhs - drift correction (Sect. IV C of the paper). */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

/* gaps below CORR_ULPS * DBL_EPSILON * (longest box edge) are at round-off */
#define CORR_ULPS 2.0

/* Contacts the correction leaves out for a while (below): at most OUT_MAX */
#define OUT_MAX 8
typedef struct {
    size_t i[OUT_MAX], j[OUT_MAX];
    int kind[OUT_MAX];
    int n;
    /* pairs put back because the correction closed them: not again */
    size_t si[OUT_MAX], sj[OUT_MAX];
    int ns;
} out_set;

static int stays(const out_set *o, size_t i, size_t j)
{
    for (int a = 0; a < o->ns; ++a)
        if (o->si[a] == i && o->sj[a] == j) return 1;
    return 0;
}

/* Fixed pressure, one contact more than isostatic (a collision on a flowing
 * isostatic network, or a touching pair the correction's own motion closes):
 * the gaps can be corrected except along the zero-pressure self-stress h
 * (S^T h = 0, <r|h> = 0), which the rewiring opens next. The integration
 * error is mostly a uniform compression (gaps ~ -eps r), which h does not
 * see: the correction goes on without a contact k of large |h| (the rest
 * is isostatic, the volume goes with it), and k, put back at the end,
 * keeps only the residual <h|gap>/h_k (k chosen so that it is >= 0). Without this the error stayed on the
 * contacts until the next step, and on a contact the rewiring opened as an
 * overlap (up to 1e-10 of a diameter at p = 1e4 with the adaptive scheme).
 * 0 when a contact was left out; 1 when none can be (the rewiring handles
 * the network); or an error. */
static int leave_out(odhs_stepper *st, out_set *o)
{
    odhs_network *net = st->net;
    if (o->n == OUT_MAX || o->ns == OUT_MAX) return 1;
    double *h = st->cb; /* reserved for nc */
    int s = odhs__st_zero_pressure_stress(st, h);
    if (s) return s == ODHS_E_NOMEM ? s : 1;
    /* k keeps the gap <h|gap>/h_k: of the sign of <h|gap>, so that it is a
     * gap, not an overlap */
    size_t k = SIZE_MAX;
    double hmax = 0.0, hg = 0.0;
    for (size_t c = 0; c < net->nc; ++c) {
        hmax = fmax(hmax, fabs(h[c]));
        hg += h[c] * net->gap[c];
    }
    for (size_t c = 0; c < net->nc; ++c)
        if (odhs__can_open(net->kind[c]) && !stays(o, net->ci[c], net->cj[c]) && h[c] * hg >= 0.0 &&
            (k == SIZE_MAX || fabs(h[c]) > fabs(h[k])))
            k = c;
    /* a small |h_k| would leave a large residual <h|gap>/h_k */
    if (k == SIZE_MAX || !(fabs(h[k]) >= 0.1 * hmax)) return 1;
    o->i[o->n] = net->ci[k];
    o->j[o->n] = net->cj[k];
    o->kind[o->n] = net->kind[k];
    o->n++;
    odhs__net_remove_at(net, k);
    return ODHS_OK;
}

/* the left-out contacts back in (at the end, with force 0), except those
 * the correction met again; wanted is the pair met (SIZE_MAX: all) */
static int put_back(odhs_stepper *st, out_set *o, size_t wi, size_t wj)
{
    odhs_network *net = st->net;
    for (int a = o->n; a-- > 0;) {
        if (wi != SIZE_MAX && !(o->i[a] == wi && o->j[a] == wj)) continue;
        if (odhs__net_find(net, o->i[a], o->j[a]) == SIZE_MAX) {
            size_t c = odhs__net_add(net, o->i[a], o->j[a], o->kind[a]);
            if (c == SIZE_MAX) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
            net->f[c] = 0.0;
            odhs__st_contact_geometry(st, c);
        }
        if (wi != SIZE_MAX && o->ns < OUT_MAX) {
            o->si[o->ns] = wi;
            o->sj[o->ns] = wj;
            o->ns++;
        }
        o->i[a] = o->i[o->n - 1];
        o->j[a] = o->j[o->n - 1];
        o->kind[a] = o->kind[o->n - 1];
        o->n--;
        if (wi != SIZE_MAX) return 1;
    }
    return ODHS_OK;
}

/* Fixed pressure under the batched integrator, a network below isostatic:
 * the volume is free, so the gaps are corrected with the least non-affine
 * motion that an isotropic rescaling allows. With N x2 = gap (in st->cx)
 * and N x1 = r, the contact forces x2 - eps x1 and the gradient -eps I
 * close the same gaps for every eps (N cx + eps r = gap), and eps =
 * <r|x2> / <r|x1> minimises the motion cx.N cx. The batched step leaves
 * gaps of ~1e-4 of a diameter, and near isostatic N is nearly singular
 * along the soft mode that carries the pressure: the motion at fixed volume
 * was up to 2500 times the gaps (2D N = 256, p = 1000: 0.2 diameters),
 * its chord closed dozens of pairs and the rewiring could not order the
 * self-stresses that made. The exact schemes' gaps (1e-11) keep the fixed-
 * volume correction, and their trajectories. x1 goes into st->cb. */
static int correct_volume(odhs_stepper *st, double *Z)
{
    odhs_network *net = st->net;
    size_t nc = net->nc;
    double *x1 = st->cb, rx1 = 0.0, rx2 = 0.0;
    memset(x1, 0, nc * sizeof *x1);
    int s = odhs__solver_solve_relaxed(st->sol, net, net->dist, x1, 1e-12, 1);
    if (s) return s;
    for (size_t c = 0; c < nc; ++c) {
        rx1 += net->dist[c] * x1[c];
        rx2 += net->dist[c] * st->cx[c];
    }
    const double eps = rx2 / rx1;
    if (!(rx1 > 0.0) || !isfinite(eps)) return ODHS_OK; /* keep the fixed-volume correction */
    for (size_t c = 0; c < nc; ++c) st->cx[c] -= eps * x1[c];
    for (int a = 0; a < st->dim; ++a) Z[3 * a + a] = -eps;
    return ODHS_OK;
}

static int correct_passes(odhs_stepper *st, int *added, out_set *o)
{
    odhs_network *net = st->net;
    const odhs_system *sys = st->sys;
    const int vol_free = st->drv->pressure_on && odhs__step_type_find(st->integrator)->block_rewire;
    int s;
    double Z[9] = {0};
    double prev = INFINITY;
    /* Newton-like passes: each removes the gaps to first order (the residual
     * is second order), so a few passes reach round-off; a pass cut short by a
     * collision adds that contact and starts again. */
    for (int pass = 0; pass < 60; ++pass) {
        size_t nc = net->nc;
        if (nc == 0) return ODHS_OK;
        odhs__net_geometry(net, sys);
        if ((s = odhs__st_reserve_contacts(st, nc))) return odhs__sterr(st, s, "out of memory");
        /* at round-off: every gap within 4e-16 of its contact distance or
         * within the precision of the coordinates, a few ulps of the box
         * edge (the minimum images are differences of wrapped positions).
         * At 2D N = 10^4 (edges of 100 diameters) a pass left gaps of
         * 1e-14 and the next pass solved again for no progress: half the
         * correction's solves and collision sweeps went to round-off. */
        double gmax = 0.0, lmax = sys->L[0], floor_abs;
        int at_floor = 1;
        for (int a = 1; a < st->dim; ++a) lmax = fmax(lmax, sys->L[a]);
        floor_abs = CORR_ULPS * DBL_EPSILON * lmax;
        for (size_t c = 0; c < nc; ++c) {
            const double sig = odhs__net_sigma(net, sys, c), g = fabs(net->gap[c]);
            gmax = fmax(gmax, g / sig);
            if (at_floor && g > floor_abs && g > 4e-16 * sig) at_floor = 0;
        }
        if (at_floor) return ODHS_OK;
        if (!(gmax < 0.5 * prev)) return ODHS_OK;     /* no further progress */
        long excess;
        if ((s = odhs__net_excess(net, &excess))) return odhs__sterr(st, s, "%s", net->errmsg);
        /* only for gaps at the level an adaptive step leaves (1e-11): the
         * paper's scheme opens gaps of up to 1e-5 between corrections, and
         * leaving a contact out with such gaps made degenerate networks
         * (2D N = 64 seed 3, p = 1e4: no unique self-stress after it) */
        if (excess == 2 && st->drv->pressure_on && gmax <= 1e-8) {
            if ((s = leave_out(st, o)) < 0) return s;
            if (s == 0) {
                --pass; /* the same gaps on the smaller network */
                continue;
            }
        }
        if (excess >= 1 && !(excess == 1 && st->drv->pressure_on)) {
            /* N singular: the rewiring handles it (f0) */
            st->corr_skipped = 1;
            return ODHS_OK;
        }
        prev = gmax;
        memset(st->cx, 0, nc * sizeof *st->cx);
        memset(Z, 0, sizeof Z);
        st->ncorr_passes++;
        if (excess == 1) {
            /* fixed pressure, flowing on an isostatic network: N is singular,
             * but the volume is free. The gap component along f0 goes with an
             * isotropic rescaling (gradient Z = -eps I over the unit
             * correction time, eps = <f0|gap>/<f0|r>), the rest on the network
             * without the contact k of largest |f0| (its row of S follows
             * from the others through f0), as when a packing is polished */
            s = odhs__st_correct_isostatic(st, Z);
        } else {
            /* the gaps are small: a relative residual of 1e-7 removes them to
             * round-off in one pass (a further pass follows if not) */
            s = odhs__solver_solve_relaxed(st->sol, net, net->gap, st->cx, 1e-7, 1);
            if (!s && vol_free) s = correct_volume(st, Z);
            if (s) s = odhs__sterr(st, s, "force solve: %s", odhs_solver_errmsg(st->sol));
        }
        if (s) {
            /* a (nearly) redundant contact makes N singular for this
             * right-hand side: the correction waits for the next interval */
            if (s == ODHS_E_SINGULAR || s == ODHS_E_NOCONV || s == ODHS_POTENTIALLY_JAMMED) {
                odhs__solver_invalidate(st->sol); /* its failed setup is not reusable */
                return ODHS_OK;
            }
            return s;
        }
        odhs__net_ST(net, st->cx, st->tmp);
        for (size_t k = 0; k < st->nd; ++k) st->tmp[k] = -st->tmp[k];
        size_t pi, pj, nv = 0;
        double t = odhs__st_predict(st, Z, st->tmp, 1.0, 0.0, 0, 0, &pi, &pj);
        /* a step type whose end works in blocks (batched): every pair the
         * chord closes joins at once, unless the first is a wall or
         * contacts are left out */
        const int block = pi != SIZE_MAX && pj < st->n && o->n == 0 &&
                          odhs__step_type_find(st->integrator)->block_rewire;
        if (block && (s = odhs__st_batched_chord_pairs(st, Z, st->tmp, &nv))) return s;
        odhs__st_advance(st, Z, st->tmp, t);
        if (nv) {
            /* no further than the rewiring can take: one contact beyond
             * isostatic (under fixed pressure two), where the next pass
             * stops. Without the cap a long chord closed every pair on its
             * way at once (2D N = 256, p = 1000, before correct_volume:
             * from excess -5 to 86), and the rewiring cannot order the
             * self-stresses of such a network. The pairs left out are no
             * closer than the first collision, where the chord stopped. */
            const long cap = st->drv->pressure_on ? 2 : 1;
            for (size_t q = 0; q < nv; ++q) {
                size_t c;
                long ex;
                if ((s = odhs__st_add_contact(st, st->bviol[q].i, st->bviol[q].j, &c))) return s;
                st->ncorr_closed++;
                if ((s = odhs__net_excess(net, &ex))) return odhs__sterr(st, s, "%s", net->errmsg);
                if (ex >= cap) break;
            }
            *added = 1;
            prev = INFINITY;
        } else if (pi != SIZE_MAX) {
            /* a left-out contact met again goes back in (it is no event) */
            if ((s = put_back(st, o, pi, pj)) < 0) return s;
            size_t c;
            if (s == 0) {
                if ((s = odhs__st_add_contact(st, pi, pj, &c))) return s;
                st->ncorr_closed++;
                *added = 1;
            }
            prev = INFINITY; /* new contact: a new problem */
        }
    }
    odhs__net_geometry(net, sys);
    return ODHS_OK;
}

int odhs__st_correct(odhs_stepper *st, int *added)
{
    out_set o = {.n = 0, .ns = 0};
    st->ncorr++;
    int s = correct_passes(st, added, &o);
    if (o.n) {
        st->corr_skipped = 1; /* the rest after the rewiring (step.c) */
        int b = put_back(st, &o, SIZE_MAX, SIZE_MAX);
        if (!s) s = b;
    }
    /* a force callback sees the corrected positions (since 0.2.7): the
     * forces then belong to the state the observables and a checkpoint
     * describe, so a restored run re-evaluates the same forces */
    if (!s && st->drv->fn) s = odhs__st_external_forces(st);
    return s;
}
