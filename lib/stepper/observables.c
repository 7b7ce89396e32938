/* libodhs - observables of the stepper's state: stress (eq. 30), pressure
 * (eq. 24), power, velocities, counts, errors. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

/* ---- observables ------------------------------------------------------------- */
#define NEED(st, p)                                                          \
    do {                                                                     \
        if (!(st)) return ODHS_E_NULL;                                       \
        if (!(p)) return odhs__sterr((st), ODHS_E_NULL, "output pointer is NULL"); \
    } while (0)

int odhs_stepper_time(const odhs_stepper *st, double *t)
{
    NEED(st, t);
    *t = st->time;
    return ODHS_OK;
}

int odhs_stepper_strain(const odhs_stepper *st, double *g)
{
    NEED(st, g);
    *g = st->strain;
    return ODHS_OK;
}

int odhs_stepper_counts(const odhs_stepper *st, uint64_t *steps, uint64_t *coll, uint64_t *open)
{
    if (!st) return ODHS_E_NULL;
    if (steps) *steps = st->nsteps;
    if (coll) *coll = st->ncoll;
    if (open) *open = st->nopen;
    return ODHS_OK;
}

static int need_ready(const odhs_stepper *st)
{
    if (!st->ready) return odhs__sterr(st, ODHS_E_STATE, "no valid state yet: call odhs_stepper_reset or step first");
    return ODHS_OK;
}

int odhs_stepper_stress(const odhs_stepper *st, double *sigma)
{
    NEED(st, sigma);
    int s = need_ready(st);
    if (s) return s;
    odhs__st_stress_of(st, st->net->f, sigma);
    return ODHS_OK;
}

void odhs__st_stress_of(const odhs_stepper *st, const double *f, double *sigma)
{
    int dim = st->dim;
    const odhs_network *net = st->net;
    double vol;
    odhs_system_volume(st->sys, &vol);
    for (int a = 0; a < dim * dim; ++a) sigma[a] = 0.0;
    for (size_t c = 0; c < net->nc; ++c) {
        if (net->cj[c] >= st->n) continue; /* walls: see odhs_stepper_wall_force */
        const double *n = net->nrm + c * dim;
        double w = f[c] * net->dist[c];
        for (int a = 0; a < dim; ++a)
            for (int b = 0; b < dim; ++b) sigma[a * dim + b] -= w * n[a] * n[b];
    }
    for (int a = 0; a < dim * dim; ++a) sigma[a] /= vol;
}

int odhs_stepper_pre_event_stress(const odhs_stepper *st, double *sigma)
{
    NEED(st, sigma);
    switch (st->pre_state) {
    case ODHS__PRE_OK:
        memcpy(sigma, st->pre_sigma, (size_t)(st->dim * st->dim) * sizeof *sigma);
        return ODHS_OK;
    case ODHS__PRE_DRIVER:
        return odhs__sterr(st, ODHS_E_STATE, "the last step only applied a change of the driver: no motion, no record");
    case ODHS__PRE_PRESSURE:
        return odhs__sterr(st, ODHS_E_STATE, "the pre-event stress is not recorded under pressure control");
    case ODHS__PRE_BATCHED:
        return odhs__sterr(st, ODHS_E_STATE,
                           "the last step was a batched one (ODHS_INTEGRATOR_BATCHED): its events are spread over "
                           "it, no record");
    case ODHS__PRE_SOLVE:
        return odhs__sterr(st, ODHS_E_STATE,
                           "the force solve on the network of the last step's start failed at its end configuration");
    default:
        return odhs__sterr(st, ODHS_E_STATE,
                           st->pre_on ? "no step taken since the recording was switched on (or since a reset)"
                                      : "the pre-event stress is not recorded: odhs_stepper_set_pre_event_stress(st, 1)");
    }
}

int odhs_stepper_shear_stress(const odhs_stepper *st, double *sxy)
{
    NEED(st, sxy);
    double sig[9];
    int s = odhs_stepper_stress(st, sig);
    if (s) return s;
    *sxy = sig[1];
    return ODHS_OK;
}

int odhs_stepper_pressure(const odhs_stepper *st, double *p)
{
    NEED(st, p);
    int s = need_ready(st);
    if (s) return s;
    const odhs_network *net = st->net;
    double vol, fr = 0.0;
    odhs_system_volume(st->sys, &vol);
    for (size_t c = 0; c < net->nc; ++c)
        if (net->cj[c] < st->n) fr += net->f[c] * net->dist[c];
    *p = fr / (vol * st->dim);
    return ODHS_OK;
}

int odhs_stepper_kappa(const odhs_stepper *st, double *kappa)
{
    NEED(st, kappa);
    *kappa = st->kappa;
    return ODHS_OK;
}

int odhs_stepper_dissipation(const odhs_stepper *st, double *D)
{
    NEED(st, D);
    int s = need_ready(st);
    if (s) return s;
    double sum = 0.0;
    for (size_t k = 0; k < st->nd; ++k) sum += st->U[k] * st->U[k];
    *D = sum / st->drv->xi0;
    return ODHS_OK;
}

int odhs_stepper_power(const odhs_stepper *st, double *P)
{
    NEED(st, P);
    int s = need_ready(st);
    if (s) return s;
    const odhs_network *net = st->net;
    double p = 0.0;
    for (size_t c = 0; c < net->nc; ++c) p -= net->f[c] * odhs__st_affine_rate(st, st->G, c);
    if (st->has_F)
        for (size_t k = 0; k < st->nd; ++k) p += st->F[k] * st->U[k];
    *P = p;
    return ODHS_OK;
}

int odhs_stepper_velocities(const odhs_stepper *st, double *V)
{
    NEED(st, V);
    int s = need_ready(st);
    if (s) return s;
    int dim = st->dim;
    for (size_t i = 0; i < st->n; ++i) {
        double gx[3];
        odhs__apply_G(st->G, dim, st->sys->x + i * dim, gx);
        for (int k = 0; k < dim; ++k) V[i * dim + k] = gx[k] + st->U[i * dim + k];
    }
    return ODHS_OK;
}

int odhs_stepper_nonaffine_velocities(const odhs_stepper *st, double *U)
{
    NEED(st, U);
    int s = need_ready(st);
    if (s) return s;
    memcpy(U, st->U, st->nd * sizeof *U);
    return ODHS_OK;
}

int odhs_stepper_external_forces(const odhs_stepper *st, double *F)
{
    NEED(st, F);
    int s = need_ready(st);
    if (s) return s;
    if (st->has_F) memcpy(F, st->F, st->nd * sizeof *F);
    else memset(F, 0, st->nd * sizeof *F);
    return ODHS_OK;
}

int odhs_stepper_coordination(const odhs_stepper *st, double *z)
{
    NEED(st, z);
    return odhs_network_coordination(st->net, z);
}

const odhs_network *odhs_stepper_network(const odhs_stepper *st) { return st ? st->net : NULL; }

int odhs_stepper_feature_work(const odhs_stepper *st, int feature, uint64_t *count)
{
    NEED(st, count);
    switch (feature) {
    case ODHS_FEATURE_PRESSURE: *count = st->work_pressure; return ODHS_OK;
    case ODHS_FEATURE_COMPOSITE: *count = st->net->work_composite; return ODHS_OK;
    case ODHS_FEATURE_WALLS: *count = st->net->work_walls; return ODHS_OK;
    default: return odhs__sterr(st, ODHS_E_INVALID, "unknown feature %d", feature);
    }
}

typedef struct {
    const double *r;
    double worst;
    const odhs_network *net;
} ov_ctx;

static int ov_cb(size_t i, size_t j, const double *rij, double gap, void *vctx)
{
    (void)rij;
    ov_ctx *c = vctx;
    /* beads of a composite may overlap by design */
    if (c->net->nperm) {
        if (odhs__same_body(c->net, i, j)) return 0;
        size_t k = odhs__net_find(c->net, i, j);
        if (k != SIZE_MAX && c->net->kind[k] == ODHS_CONTACT_PERMANENT) return 0;
    }
    double rel = -gap / (c->r[i] + c->r[j]);
    if (rel > c->worst) c->worst = rel;
    return 0;
}

int odhs_stepper_errors(const odhs_stepper *st, double *contact_gap, double *overlap)
{
    if (!st) return ODHS_E_NULL;
    const odhs_system *s = st->sys;
    const odhs_network *net = st->net;
    if (contact_gap) {
        double g = 0.0;
        for (size_t c = 0; c < net->nc; ++c)
            g = fmax(g, fabs(net->gap[c]) / odhs__net_sigma(net, s, c));
        *contact_gap = g;
    }
    if (overlap) {
        ov_ctx c = {s->r, -INFINITY, net};
        int r = odhs__pairs(s->dim, s->n, s->x, s->r, s->rmax, s->L, s->gamma, 0.0, ov_cb, &c);
        if (r == ODHS_E_NOMEM) return odhs__sterr(st, r, "out of memory");
        for (size_t w = 0; w < net->nwalls; ++w)
            for (size_t i = 0; i < s->n; ++i) {
                double nrm[3];
                double g = odhs__wall_geom(&net->walls[w], s->dim, s->L, s->gamma, s->x + i * s->dim, nrm, NULL) - s->r[i];
                c.worst = fmax(c.worst, -g / s->r[i]);
            }
        *overlap = c.worst > 0.0 ? c.worst : 0.0;
    }
    return ODHS_OK;
}

int odhs_stepper_contacts(const odhs_stepper *st, size_t cap, size_t *nc, size_t *i, size_t *j, int *kind, double *f,
                          double *gap)
{
    if (!st) return ODHS_E_NULL;
    if (!nc) return odhs__sterr(st, ODHS_E_NULL, "nc pointer is NULL");
    if (!st->ready) return odhs__sterr(st, ODHS_E_STATE, "no contact network yet: reset or step first");
    const odhs_network *net = st->net;
    *nc = net->nc;
    if (cap < net->nc)
        return odhs__sterr(st, ODHS_E_RANGE, "room for %zu contacts, the network has %zu", cap, net->nc);
    for (size_t k = 0; k < net->nc; ++k) {
        if (i) i[k] = net->ci[k];
        if (j) j[k] = net->cj[k];
        if (kind) kind[k] = net->kind[k];
        if (f) f[k] = net->f[k];
        if (gap) gap[k] = net->gap[k];
    }
    return ODHS_OK;
}
