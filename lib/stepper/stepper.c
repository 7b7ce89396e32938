/* libodhs - the event-driven stepper (Sect. IV of Lerner, During & Wyart 2013).
 *
 * State between steps: a valid contact network (all temporary contacts carry
 * f >= 0, removed pairs separate), its forces, and the non-affine velocities
 * U = V - V_aff = xi0 (F_ext + S^T f). A step moves every particle on a straight
 * line, x += tau (G x + U), and deforms the box with the same G, so every pair
 * separation is linear in time and collision times are exact roots of a
 * quadratic. */
#include <float.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

#define EPS_F 1e-12 /* relative threshold for negative forces   */
#define EPS_V 1e-12 /* relative threshold for approaching pairs */
/* default drift-correction intervals: the paper's 10 steps with its Euler
 * scheme (whose straight chords only open contact gaps, by O(dt^2)); every
 * step with the adaptive scheme, whose chord errors (O(h^3), either sign)
 * would otherwise leave overlaps of ~1e-11 at tol 1e-6 (docs/accuracy.md) */
#define CORR_DEFAULT_EULER 10u
#define CORR_DEFAULT_HEUN 1u

static int sterr(const odhs_stepper *st, int status, const char *fmt, ...) ODHS_PRINTF(3, 4);
static int sterr(const odhs_stepper *st, int status, const char *fmt, ...)
{
    if (!st) return status;
    va_list ap;
    va_start(ap, fmt);
    odhs__verr(((odhs_stepper *)st)->errmsg, status, fmt, ap);
    va_end(ap);
    return status;
}

/* ---- small helpers ------------------------------------------------------ */
static int reserve(void **p, size_t *cap, size_t need, size_t elem)
{
    if (*cap >= need) return ODHS_OK;
    size_t c = *cap ? *cap : 16;
    while (c < need) c *= 2;
    void *q = odhs__realloc(*p, c * elem);
    if (!q) return ODHS_E_NOMEM;
    *p = q;
    *cap = c;
    return ODHS_OK;
}

static int reserve_contacts(odhs_stepper *st, size_t nc)
{
    if (st->ccap >= nc) return ODHS_OK;
    size_t c = st->ccap ? st->ccap : 64;
    while (c < nc) c *= 2;
    double *b = odhs__realloc(st->cb, c * sizeof *b);
    if (b) st->cb = b;
    double *x = odhs__realloc(st->cx, c * sizeof *x);
    if (x) st->cx = x;
    if (!b || !x) return ODHS_E_NOMEM;
    st->ccap = c;
    return ODHS_OK;
}

static void min_sep(const odhs_stepper *st, size_t i, size_t j, double *d)
{
    const odhs_system *s = st->sys;
    int dim = st->dim;
    d[0] = d[1] = d[2] = 0.0;
    for (int k = 0; k < dim; ++k) d[k] = s->x[j * dim + k] - s->x[i * dim + k];
    odhs__min_image(dim, s->L, s->gamma, d, NULL);
}

/* G d (affine relative velocity of a separation d) */
static inline void apply_G(const double *G, int dim, const double *d, double *out)
{
    for (int a = 0; a < dim; ++a) {
        double s = 0.0;
        for (int b = 0; b < dim; ++b) s += G[3 * (a) + (b)] * d[b];
        out[a] = s;
    }
}

static void set_gradient(odhs_stepper *st, double c_eff)
{
    memset(st->G, 0, sizeof st->G);
    st->G[3 * (0) + (1)] = st->drv->gdot;
    for (int a = 0; a < st->dim; ++a) st->G[3 * (a) + (a)] = -c_eff;
}

static int record_change(odhs_stepper *st, size_t i, size_t j, int delta)
{
    if (reserve((void **)&st->chg, &st->chgcap, st->nchg + 1, sizeof *st->chg)) return ODHS_E_NOMEM;
    st->chg[st->nchg].i = i < j ? i : j;
    st->chg[st->nchg].j = i < j ? j : i;
    st->chg[st->nchg].delta = delta;
    st->nchg++;
    return ODHS_OK;
}

/* ---- external forces ---------------------------------------------------- */
static int eval_forces(odhs_stepper *st)
{
    odhs_driver *d = st->drv;
    if (d->fn) {
        memset(st->F, 0, st->nd * sizeof *st->F);
        if (d->fn(st->time, st->sys, st->F, d->fn_ctx))
            return sterr(st, ODHS_E_CALLBACK, "force callback failed at t = %.17g", st->time);
        for (size_t k = 0; k < st->nd; ++k)
            if (!isfinite(st->F[k]))
                return sterr(st, ODHS_E_CALLBACK, "force callback returned a non-finite value for particle %zu",
                             k / st->dim);
        st->has_F = 1;
    } else if (d->F) {
        if (d->Fn != st->n || d->Fdim != st->dim)
            return sterr(st, ODHS_E_DIM, "driver forces are for N = %zu, d = %d", d->Fn, d->Fdim);
        memcpy(st->F, d->F, st->nd * sizeof *st->F);
        st->has_F = 1;
    } else {
        st->has_F = 0;
    }
    /* self-propulsion and gravity add to the above */
    if ((d->prop_on || d->grav_on) && odhs__driver_extra_forces(d, st->sys, st->F, &st->has_F))
        return sterr(st, ODHS_E_DIM, "self-propulsion or gravity settings do not fit N = %zu, d = %d", st->n,
                     st->dim);
    return ODHS_OK;
}

/* ---- forces and velocities on the current network ---------------------- */
static int solve(odhs_stepper *st, const double *b, double *x)
{
    int s = odhs__solver_solve(st->sol, st->net, b, x, 1);
    if (s) return sterr(st, s, "force solve: %s", odhs_solver_errmsg(st->sol));
    return ODHS_OK;
}

/* b = -S (V_aff + xi0 F) / xi0 on the current network (st->cb has room),
 * with the pressure part of V_aff left out */
static void affine_rhs(odhs_stepper *st, double *b)
{
    const odhs_network *net = st->net;
    const odhs_driver *drv = st->drv;
    size_t nc = net->nc;
    int dim = st->dim;
    double xi0 = drv->xi0;
    double G0[9];
    memcpy(G0, st->G, sizeof G0);
    if (drv->pressure_on) {
        memset(G0, 0, sizeof G0);
        G0[3 * (0) + (1)] = drv->gdot;
    }
    for (size_t c = 0; c < nc; ++c) {
        const double *n = net->nrm + c * dim;
        if (net->nwalls && net->cj[c] >= st->n) {
            /* wall: (S V_aff)_c + w_c = n.(v_wall - G0 x_i), S F = -n.F_i */
            const odhs_wall *w = &net->walls[net->cj[c] - st->n];
            const double *xi = st->sys->x + net->ci[c] * dim;
            double gx[3], v = 0.0;
            apply_G(G0, dim, xi, gx);
            for (int k = 0; k < dim; ++k) v += (w->v[k] - gx[k]) * n[k];
            if (st->has_F)
                for (int k = 0; k < dim; ++k) v -= xi0 * st->F[net->ci[c] * dim + k] * n[k];
            b[c] = -v / xi0;
            continue;
        }
        double d[3] = {0, 0, 0}, gd[3];
        for (int k = 0; k < dim; ++k) d[k] = n[k] * net->dist[c];
        apply_G(G0, dim, d, gd);
        double v = 0.0;
        for (int k = 0; k < dim; ++k) v += gd[k] * n[k];
        if (st->has_F) {
            const double *Fi = st->F + net->ci[c] * dim, *Fj = st->F + net->cj[c] * dim;
            for (int k = 0; k < dim; ++k) v += xi0 * (Fj[k] - Fi[k]) * n[k];
        }
        b[c] = -v / xi0;
    }
}

/* N x = rhs on an isostatic network, rhs orthogonal to its self-stress f0:
 * solved on the network without the contact k of largest |f0|, whose row of
 * S (and equation) follows from the others through f0; x[k] = 0. rhs and x
 * hold nc values (rhs is used as scratch); tol > 0: relaxed residual. */
static int solve_isostatic(odhs_stepper *st, const double *f0, double *rhs, double *x, double tol)
{
    const odhs_network *net = st->net;
    size_t nc = net->nc, k = 0;
    for (size_t c = 1; c < nc; ++c)
        if (fabs(f0[c]) > fabs(f0[k])) k = c;
    memmove(rhs + k, rhs + k + 1, (nc - 1 - k) * sizeof *rhs);
    odhs_network *sub = odhs__net_subnet(net, NULL, nc, k);
    if (!sub) return sterr(st, ODHS_E_NOMEM, "out of memory");
    memset(x, 0, nc * sizeof *x);
    int s = tol > 0.0 ? odhs__solver_solve_relaxed(st->sol, sub, rhs, x, tol)
                      : odhs__solver_solve(st->sol, sub, rhs, x, 1);
    odhs_network_destroy(sub);
    if (s) return sterr(st, s, "force solve on the isostatic network: %s", odhs_solver_errmsg(st->sol));
    memmove(x + k + 1, x + k, (nc - 1 - k) * sizeof *x);
    x[k] = 0.0;
    return ODHS_OK;
}

/* f0 of the current (isostatic) network into st->fpj (room for 2 nc), kept
 * while the network's version is unchanged */
static int isostatic_f0(odhs_stepper *st)
{
    odhs_network *net = st->net;
    if (st->fpj_version == net->version && st->fpjcap >= 2 * net->nc) return ODHS_OK;
    if (reserve((void **)&st->fpj, &st->fpjcap, 2 * net->nc, sizeof *st->fpj))
        return sterr(st, ODHS_E_NOMEM, "out of memory");
    int s = odhs__null_vector(net, st->sol, st->fpj, NULL);
    if (s)
        return sterr(st, s == ODHS_E_NOMEM ? s : ODHS_POTENTIALLY_JAMMED, "isostatic network at t = %.17g: %s",
                     st->time, net->errmsg);
    st->fpj_version = net->version;
    return ODHS_OK;
}

/* Fixed pressure on a potentially jammed network (d(Nbar - 1) + 1 contacts in
 * the constrained subset): N is singular with the kernel f0, but the volume is
 * one more degree of freedom, so the network is not jammed. N f = b + a r
 * (a = gdot kappa / xi0) has a solution only for a = -<f0|b>/<f0|r>: kappa
 * follows from the geometry. f = freg + alpha f0, with freg solved on the
 * network without the contact k of largest |f0| (its row of S follows from
 * the others through f0, and so does its equation), and alpha sets the
 * pressure. The velocities see freg only (S^T f0 = 0). */
static int pressure_isostatic_forces(odhs_stepper *st, const double *b)
{
    odhs_network *net = st->net;
    odhs_driver *drv = st->drv;
    size_t nc = net->nc;
    int s;
    if ((s = isostatic_f0(st))) return s;
    double *f0 = st->fpj, *freg = st->fpj + nc, *rhs = st->cx;
    double fb = 0.0, fr = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        fb += f0[c] * b[c];
        fr += f0[c] * net->dist[c];
    }
    if (!(fabs(fr) > 0.0))
        return sterr(st, ODHS_E_SINGULAR, "fixed pressure, isostatic network: the self-stress carries no pressure");
    double a = -fb / fr;
    for (size_t c = 0; c < nc; ++c) rhs[c] = b[c] + a * net->dist[c];
    if ((s = solve_isostatic(st, f0, rhs, freg, 0.0))) return s;
    double vol, rf = 0.0;
    odhs_system_volume(st->sys, &vol);
    for (size_t c = 0; c < nc; ++c) rf += net->dist[c] * freg[c];
    double alpha = (drv->p * vol * st->dim - rf) / fr;
    for (size_t c = 0; c < nc; ++c) net->f[c] = freg[c] + alpha * f0[c];
    st->kappa = a * drv->xi0 / drv->gdot;
    set_gradient(st, drv->gdot * st->kappa);
    st->pj_bordered = 1;
    return ODHS_OK;
}

/* Solve for the contact forces (into net->f) and kappa under pressure control. */
static int compute_forces(odhs_stepper *st)
{
    odhs_network *net = st->net;
    odhs_driver *drv = st->drv;
    size_t nc = net->nc;
    int dim = st->dim, s;
    double xi0 = drv->xi0;
    st->pj_bordered = 0;
    if ((s = reserve_contacts(st, nc))) return sterr(st, s, "out of memory");
    if (!drv->pressure_on) {
        set_gradient(st, drv->crate);
        st->kappa = drv->gdot != 0.0 ? drv->crate / drv->gdot : drv->crate;
        /* a subnormal shear rate overflows the ratio (found by fuzzing the
         * checkpoint reader): report c as without shear, never inf */
        if (!isfinite(st->kappa)) st->kappa = drv->crate;
    }
    if (nc == 0) {
        if (drv->pressure_on) {
            st->kappa = drv->kappa_max * (drv->gdot > 0 ? 1.0 : -1.0);
            set_gradient(st, drv->gdot * st->kappa);
        }
        return ODHS_OK;
    }
    double *b = st->cb;
    affine_rhs(st, b);
    if (!drv->pressure_on) return solve(st, b, net->f);

    /* fixed pressure: f = x2 + (gdot kappa / xi0) x1 with N x2 = b, N x1 = r */
    st->work_pressure++;
    long excess;
    if ((s = odhs__net_excess(net, &excess))) return sterr(st, s, "%s", net->errmsg);
    if (excess == 1) return pressure_isostatic_forces(st, b);
    double *x1 = st->cx;
    if ((s = solve(st, b, net->f))) return s;
    memset(x1, 0, nc * sizeof *x1);
    if ((s = solve(st, net->dist, x1))) return s;
    double rx1 = 0.0, rx2 = 0.0, vol;
    for (size_t c = 0; c < nc; ++c) {
        rx1 += net->dist[c] * x1[c];
        rx2 += net->dist[c] * net->f[c];
    }
    odhs_system_volume(st->sys, &vol);
    double kappa;
    double gd = drv->gdot;
    if (rx1 > 0.0) kappa = xi0 * (drv->p * vol * dim - rx2) / (gd * rx1);
    else kappa = drv->kappa_max * (gd > 0 ? 1.0 : -1.0);
    if (!isfinite(kappa) || kappa > drv->kappa_max) kappa = drv->kappa_max;
    if (kappa < -drv->kappa_max) kappa = -drv->kappa_max;
    st->kappa = kappa;
    double a = gd * kappa / xi0;
    for (size_t c = 0; c < nc; ++c) net->f[c] += a * x1[c];
    set_gradient(st, gd * kappa);
    return ODHS_OK;
}

static void compute_velocities(odhs_stepper *st)
{
    double xi0 = st->drv->xi0;
    /* freg: alpha f0 is a self-stress, and alpha may be huge */
    odhs__net_ST(st->net, st->pj_bordered ? st->fpj + st->net->nc : st->net->f, st->U);
    for (size_t k = 0; k < st->nd; ++k) st->U[k] = xi0 * (st->U[k] + (st->has_F ? st->F[k] : 0.0));
}

static double velocity_scale(const odhs_stepper *st)
{
    double umax = 0.0, g = 0.0;
    for (size_t k = 0; k < st->nd; ++k) umax = fmax(umax, fabs(st->U[k]));
    for (size_t w = 0; w < st->net->nwalls; ++w)
        for (int k = 0; k < st->dim; ++k) umax = fmax(umax, fabs(st->net->walls[w].v[k]));
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) g += st->G[3 * (a) + (b)] * st->G[3 * (a) + (b)];
    return umax + sqrt(g) * 2.0 * st->sys->rmax;
}

/* relative normal velocity of a pair that is not (necessarily) a contact */
static double pair_velocity(const odhs_stepper *st, size_t i, size_t j)
{
    int dim = st->dim;
    double d[3], gd[3];
    if (j >= st->n) { /* a wall: rate of the gap, n.(v_wall - V_i) */
        const odhs_wall *w = &st->net->walls[j - st->n];
        double nrm[3], gx[3], xi[3], v = 0.0;
        odhs__wall_geom(w, dim, st->sys->L, st->sys->gamma, st->sys->x + i * dim, nrm, xi);
        apply_G(st->G, dim, xi, gx);
        for (int k = 0; k < dim; ++k) v += nrm[k] * (w->v[k] - gx[k] - st->U[i * dim + k]);
        return v;
    }
    min_sep(st, i, j, d);
    apply_G(st->G, dim, d, gd);
    double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), v = 0.0;
    for (int k = 0; k < dim; ++k) v += (gd[k] + st->U[j * dim + k] - st->U[i * dim + k]) * d[k];
    return v / r;
}

static void contact_geometry(odhs_stepper *st, size_t c)
{
    odhs_network *net = st->net;
    int dim = st->dim;
    if (net->cj[c] >= st->n) {
        size_t i = net->ci[c];
        double r = odhs__wall_geom(&net->walls[net->cj[c] - st->n], dim, st->sys->L, st->sys->gamma, st->sys->x + i * dim,
                                   net->nrm + c * dim, NULL);
        net->dist[c] = r;
        net->gap[c] = r - st->sys->r[i];
        net->version++;
        return;
    }
    double d[3];
    min_sep(st, net->ci[c], net->cj[c], d);
    double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    net->dist[c] = r;
    net->gap[c] = r - odhs__net_sigma(net, st->sys, c);
    for (int k = 0; k < dim; ++k) net->nrm[c * dim + k] = d[k] / r;
    net->version++;
}

/* Forces for the rewiring: on a potentially jammed network (*pj = 1 on
 * return) the self-stress f0 (Sect. IV D); under fixed pressure, where the
 * volume can still change, f0 only when it is positive (jammed at this
 * volume), else the forces of the flowing isostatic network (*pj = 0). A
 * failed f0 is ODHS_POTENTIALLY_JAMMED (or ODHS_E_NOMEM). */
static int rewire_forces(odhs_stepper *st, int *pj)
{
    odhs_network *net = st->net;
    int s;
    long excess;
    st->pj_bordered = 0;
    if ((s = odhs__net_excess(net, &excess))) return sterr(st, s, "%s", net->errmsg);
    *pj = excess >= 1;
    if (!*pj) return compute_forces(st);
    if (st->drv->pressure_on && excess == 2) {
        /* fixed pressure, one contact more than isostatic: the forces
         * diverge along the self-stress fs at zero pressure, with the sign
         * that resists the driving (<fs|b> > 0); its most negative contact
         * opens (fs has both signs, since <fs|r> = 0) */
        st->work_pressure++;
        if ((s = reserve_contacts(st, net->nc))) return sterr(st, s, "out of memory");
        affine_rhs(st, st->cb);
        if ((s = odhs__null_vector_volume(net, net->f)))
            return sterr(st, s == ODHS_E_NOMEM ? s : ODHS_POTENTIALLY_JAMMED, "fixed pressure at t = %.17g: %s",
                         st->time, net->errmsg);
        double fb = 0.0, fmin = 0.0;
        for (size_t c = 0; c < net->nc; ++c) fb += net->f[c] * st->cb[c];
        for (size_t c = 0; c < net->nc; ++c) {
            if (fb < 0.0) net->f[c] = -net->f[c];
            if (odhs__can_open(net->kind[c])) fmin = fmin < net->f[c] ? fmin : net->f[c];
        }
        if (!(fmin < -EPS_F))
            return sterr(st, ODHS_POTENTIALLY_JAMMED,
                         "fixed pressure at t = %.17g: the self-stress at zero pressure opens no contact", st->time);
        return ODHS_OK;
    }
    if (!st->drv->pressure_on) {
        if ((s = odhs__null_vector(net, st->sol, net->f, NULL)))
            return sterr(st, s == ODHS_E_NOMEM ? s : ODHS_POTENTIALLY_JAMMED, "potentially jammed at t = %.17g: %s",
                         st->time, net->errmsg);
        return ODHS_OK;
    }
    /* kept in st->fpj for the forces of the flowing network below */
    if ((s = isostatic_f0(st))) return s;
    memcpy(net->f, st->fpj, net->nc * sizeof *net->f);
    double fmax = 0.0;
    for (size_t c = 0; c < net->nc; ++c) fmax = fmax > fabs(net->f[c]) ? fmax : fabs(net->f[c]);
    for (size_t c = 0; c < net->nc; ++c)
        if (odhs__can_open(net->kind[c]) && net->f[c] < -EPS_F * fmax) {
            *pj = 0;
            return compute_forces(st);
        }
    return ODHS_OK;
}

static int open_contact(odhs_stepper *st, size_t k, double *x);

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
    if (!*in) return sterr(st, ODHS_E_NOMEM, "out of memory");
    int s = odhs_network_constrained(st->net, &nbar, &ncon, *in, NULL);
    if (s) {
        odhs__free(*in);
        *in = NULL;
        return sterr(st, s, "%s", st->net->errmsg);
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
        s = sterr(st, ODHS_E_NOMEM, "out of memory");
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
        s = sterr(st, s, "out of memory");
        goto done;
    }
    s = ODHS_OK;
    /* a pair of backbone particles first; a pair with a rattler enters only
     * if the rattler has contacts enough to balance it (else jam_rattlers) */
    int e = ODHS_E_STATE;
    size_t pi = SIZE_MAX, pj = SIZE_MAX;
    for (int w = 0; w < 2 && e; ++w) {
        if (oc.i[w] == SIZE_MAX) continue;
        double dist = sqrt(oc.v[w][0] * oc.v[w][0] + oc.v[w][1] * oc.v[w][1] + oc.v[w][2] * oc.v[w][2]);
        double nrm[3] = {0, 0, 0};
        for (int a = 0; a < st->dim; ++a) nrm[a] = oc.v[w][a] / dist;
        e = odhs__jam_pair_stress(net, st->sol, net->f, oc.i[w], oc.j[w], nrm, dist, h);
        if (e == ODHS_E_NOMEM) {
            s = sterr(st, e, "out of memory");
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
    size_t cp = odhs__net_add(net, pi, pj, ODHS_CONTACT_TEMPORARY);
    if (cp == SIZE_MAX || record_change(st, pi, pj, +1)) {
        s = sterr(st, ODHS_E_NOMEM, "out of memory");
        goto done;
    }
    contact_geometry(st, cp);
    net->f[cp] = t;
    if ((s = open_contact(st, k, NULL))) goto done;
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

typedef struct {
    const odhs_network *net;
    const unsigned char *in;
    const double *r;
    int dim;
    size_t m, cap;
    struct jam_push {
        size_t i, j;
        double v[3], dist, need;
    } *list;
    int nomem;
} jam_push_ctx;

/* overlapping pairs outside the network with a rattler in them */
static int jam_push_cb(size_t i, size_t j, const double *rij, double gap, void *vctx)
{
    jam_push_ctx *c = vctx;
    double sig = c->r[i] + c->r[j];
    if (!(gap < -1e-15 * sig) || (c->in[i] && c->in[j])) return 0;
    if (odhs__net_find(c->net, i, j) != SIZE_MAX || odhs__same_body(c->net, i, j)) return 0;
    if (reserve((void **)&c->list, &c->cap, c->m + 1, sizeof *c->list)) {
        c->nomem = 1;
        return 1;
    }
    struct jam_push *p = &c->list[c->m++];
    p->i = i;
    p->j = j;
    p->dist = 0.0;
    for (int a = 0; a < c->dim; ++a) {
        p->v[a] = rij[a];
        p->dist += rij[a] * rij[a];
    }
    p->dist = sqrt(p->dist);
    p->need = -gap + JAM_RATTLER_MARGIN * sig;
    return 0;
}

/* Rattlers carry no force, so the polish (which moves the backbone, and the
 * rattlers only with their own contacts) can leave a rattler overlapping the
 * packing by as much as it moved the backbone. Such a rattler is moved out
 * along the pair normals (split between two rattlers), sweep after sweep,
 * and its force-free contacts open. Not with bonds or walls. */
static int jam_rattlers(odhs_stepper *st)
{
    odhs_network *net = st->net;
    odhs_system *sys = st->sys;
    int d = st->dim;
    if (net->nperm || net->nwalls) return ODHS_OK;
    unsigned char *in = NULL, *moved = NULL;
    int s = jam_backbone(st, &in);
    jam_push_ctx pc = {net, in, sys->r, d, 0, 0, NULL, 0};
    if (s) goto done;
    if (!(moved = odhs__calloc(st->n, 1))) {
        s = sterr(st, ODHS_E_NOMEM, "out of memory");
        goto done;
    }
    if (!memchr(in, 0, st->n)) goto done; /* no rattlers */
    for (int sweep = 0; sweep < JAM_RATTLER_SWEEPS; ++sweep) {
        pc.m = 0;
        s = odhs__pairs(d, st->n, sys->x, sys->r, sys->rmax, sys->L, sys->gamma, 0.0, jam_push_cb, &pc);
        if (pc.nomem || s == ODHS_E_NOMEM) {
            s = sterr(st, ODHS_E_NOMEM, "out of memory");
            goto done;
        }
        s = ODHS_OK;
        if (pc.m == 0) break;
        for (size_t q = 0; q < pc.m; ++q) {
            struct jam_push *p = &pc.list[q];
            size_t ends[2] = {p->i, p->j};
            double share = in[p->i] || in[p->j] ? 1.0 : 0.5;
            for (int e = 0; e < 2; ++e) {
                size_t i = ends[e];
                if (in[i]) continue;
                if (!moved[i]) { /* its contacts carry no force: they open */
                    moved[i] = 1;
                    for (size_t c = net->nc; c-- > 0;)
                        if ((net->ci[c] == i || net->cj[c] == i) && odhs__can_open(net->kind[c]))
                            if ((s = open_contact(st, c, NULL))) goto done;
                }
                double sgn = e == 0 ? -1.0 : 1.0;
                for (int a = 0; a < d; ++a) sys->x[i * d + a] += sgn * share * p->need * p->v[a] / p->dist;
            }
        }
        for (size_t i = 0; i < st->n; ++i)
            if (moved[i]) odhs__wrap(d, sys->L, sys->gamma, sys->x + i * d);
    }
    odhs__net_geometry(net, sys);
done:
    odhs__free(in);
    odhs__free(moved);
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
        return sterr(st, ODHS_POTENTIALLY_JAMMED,
                     "potentially jammed at t = %.17g: after the polish the self-stress has a negative component "
                     "(%.3g of the mean force), so the packing is not jammed; the step was not taken (a drift "
                     "correction before it gives the polish a closer start)",
                     st->time, mean > 0.0 ? low / mean : low);
    return ODHS_OK;
}

/* The end of a rewiring on a jammed network (positive self-stress): polish
 * the contacts to round-off, take in any pair that the polish left
 * overlapping (jam_pivot) and polish again, move overlapping rattlers out
 * (jam_rattlers), check f0 on the final geometry (jam_check_f0) and scale it
 * to unit pressure; nothing can move under this driving. */
static int jam_finish(odhs_stepper *st)
{
    odhs_network *net = st->net;
    int s;
    st->njam_pivots = 0;
    for (int piv = 0;; ++piv) {
        if ((s = odhs__jam_polish(st->sys, net, st->sol, net->f)))
            return sterr(st, s, "polishing the jammed packing: %s", odhs_strerror(s));
        if ((s = odhs__null_vector(net, st->sol, net->f, NULL)))
            return sterr(st, s == ODHS_E_NOMEM ? s : ODHS_POTENTIALLY_JAMMED, "jammed packing: %s", net->errmsg);
        int pivoted = 0;
        if (piv == JAM_PIVOTS || net->nwalls || (s = jam_pivot(st, &pivoted)) || !pivoted) break;
    }
    if (s || (s = jam_rattlers(st))) return s;
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

/* Open contact k: into the removed pairs, out of the network (the last
 * contact takes its place, in net->f and, when given, in x). */
static int open_contact(odhs_stepper *st, size_t k, double *x)
{
    odhs_network *net = st->net;
    size_t i = net->ci[k], j = net->cj[k];
    if (reserve((void **)&st->rem, &st->remcap, st->nrem + 1, sizeof *st->rem))
        return sterr(st, ODHS_E_NOMEM, "out of memory");
    st->rem[st->nrem].i = i;
    st->rem[st->nrem].j = j;
    st->nrem++;
    if (x) x[k] = x[net->nc - 1];
    odhs__net_remove_at(net, k);
    if (record_change(st, i, j, -1)) return sterr(st, ODHS_E_NOMEM, "out of memory");
    return ODHS_OK;
}

/* Re-connect the most approaching removed pair (velocities computed on the
 * current network); *added = 0 when none approaches. The new contact is the
 * network's last, with force 0. */
static int close_pair(odhs_stepper *st, int *added)
{
    odhs_network *net = st->net;
    *added = 0;
    if (st->nrem == 0) return ODHS_OK;
    double vs = velocity_scale(st), vmin = 0.0;
    size_t rmin = SIZE_MAX;
    for (size_t q = 0; q < st->nrem; ++q) {
        double v = pair_velocity(st, st->rem[q].i, st->rem[q].j);
        if (v < vmin) {
            vmin = v;
            rmin = q;
        }
    }
    if (rmin == SIZE_MAX || vmin >= -EPS_V * vs) return ODHS_OK;
    size_t i = st->rem[rmin].i, j = st->rem[rmin].j;
    st->rem[rmin] = st->rem[st->nrem - 1];
    st->nrem--;
    size_t c = odhs__net_add(net, i, j, ODHS_CONTACT_TEMPORARY);
    if (c == SIZE_MAX || record_change(st, i, j, +1)) return sterr(st, ODHS_E_NOMEM, "out of memory");
    contact_geometry(st, c);
    *added = 1;
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
    if (!x) return sterr(st, ODHS_E_NOMEM, "out of memory");
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
            s = sterr(st, ODHS_E_REWIRE, "anti-cycling rewiring did not terminate after %zu iterations", maxit);
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
            s = jam_finish(st);
            break;
        }
        if (!neg) {
            /* a solution on this network: the new feasible point */
            for (size_t c = 0; c < nc; ++c) x[c] = odhs__can_open(net->kind[c]) ? fmax(z[c], 0.0) : z[c];
            compute_velocities(st);
            int added = 0;
            if ((s = close_pair(st, &added)) || !added) break;
            x[net->nc - 1] = 0.0;
            continue;
        }
        if (pj && !drv->pressure_on) {
            /* descend along f0: b.f0 > 0 */
            if ((s = reserve_contacts(st, nc))) {
                s = sterr(st, s, "out of memory");
                break;
            }
            affine_rhs(st, st->cb);
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
                if ((s = open_contact(st, c, x))) goto done;
    }
done:
    free(x);
    return s;
}

/* Rewiring (Sect. IV B): remove the most negative force until none is left,
 * then re-connect the most approaching removed pair, and repeat. The rule
 * can cycle near jamming: after a bounded number of iterations (or always,
 * st->rewire_mode == 1) the anti-cycling method above takes over from the
 * network reached so far. */
static int rewire(odhs_stepper *st)
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
            if ((s = open_contact(st, kmin, NULL))) return s;
            continue;
        }
        if (pj) return jam_finish(st);
        compute_velocities(st);
        int added = 0;
        if ((s = close_pair(st, &added)) || !added) return s;
    }
}

/* ---- neighbour list ----------------------------------------------------- */
typedef struct {
    odhs_stepper *st;
    int status;
} nb_ctx;

static int nb_cb(size_t i, size_t j, const double *rij, double gap, void *vctx)
{
    (void)rij;
    (void)gap;
    nb_ctx *c = vctx;
    odhs_stepper *st = c->st;
    if (st->npairs == st->pcap) {
        size_t cap = st->pcap ? 2 * st->pcap : 1024;
        size_t *a = odhs__realloc(st->pi, cap * sizeof *a);
        if (a) st->pi = a;
        size_t *b = odhs__realloc(st->pj, cap * sizeof *b);
        if (b) st->pj = b;
        if (!a || !b) {
            c->status = ODHS_E_NOMEM;
            return 1;
        }
        st->pcap = cap;
    }
    st->pi[st->npairs] = i;
    st->pj[st->npairs] = j;
    st->npairs++;
    return 0;
}

static int build_neighbours(odhs_stepper *st)
{
    odhs_system *s = st->sys;
    double Lmin = fmin(s->L[0], s->L[1]);
    if (st->dim == 3) Lmin = fmin(Lmin, s->L[2]);
    double rmean = 0.0;
    for (size_t i = 0; i < st->n; ++i) rmean += s->r[i];
    rmean /= (double)st->n;
    double skin = 0.5 * rmean;
    double room = 0.5 * Lmin - 2.0 * s->rmax; /* pair range must stay below L/2 */
    if (skin > 0.9 * room) skin = 0.9 * room;
    if (!(skin > 1e-3 * rmean))
        return sterr(st, ODHS_E_BOX,
                     "box too small for the neighbour search: shortest edge %.6g, largest diameter %.6g",
                     Lmin, 2.0 * s->rmax);
    st->skin = skin;
    st->rc = 2.0 * s->rmax + skin;
    st->npairs = 0;
    nb_ctx c = {st, ODHS_OK};
    int r = odhs__pairs(st->dim, st->n, s->x, s->r, s->rmax, s->L, s->gamma, skin, nb_cb, &c);
    if (r == ODHS_E_NOMEM || c.status) return sterr(st, ODHS_E_NOMEM, "out of memory");
    memset(st->disp, 0, st->nd * sizeof *st->disp);
    memset(st->M, 0, sizeof st->M);
    for (int a = 0; a < 3; ++a) st->M[3 * (a) + (a)] = 1.0;
    return ODHS_OK;
}

static double frob(const double *A)
{
    double s = 0.0;
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) s += A[3 * (a) + (b)] * A[3 * (a) + (b)];
    return sqrt(s);
}

/* bound on how much any pair separation changed since the list was built */
static double skin_used(const odhs_stepper *st)
{
    double dmax = 0.0;
    int dim = st->dim;
    for (size_t i = 0; i < st->n; ++i) {
        double s = 0.0;
        for (int k = 0; k < dim; ++k) s += st->disp[i * dim + k] * st->disp[i * dim + k];
        dmax = fmax(dmax, s);
    }
    double MI[9];
    memcpy(MI, st->M, sizeof MI);
    for (int a = 0; a < 3; ++a) MI[3 * (a) + (a)] -= 1.0;
    return 2.0 * sqrt(dmax) + frob(MI) * st->rc;
}

/* ---- neighbour list of a restored state ------------------------------------
 * A checkpoint stores the neighbour list and its bookkeeping so that a
 * continued run is bit-identical. A list that misses a pair closer than the
 * unused skin (a corrupted file: found by fuzz_checkpoint, which then stepped
 * particles deep into each other) is not trusted: the list is marked stale and
 * rebuilt before the next step. */
typedef struct {
    const size_t *keys; /* sorted i * n + j of the stored pairs */
    size_t nkeys, n;
    int missing;
} nbcheck_ctx;

static int cmp_size(const void *a, const void *b)
{
    size_t x = *(const size_t *)a, y = *(const size_t *)b;
    return x < y ? -1 : x > y;
}

static int nbcheck_cb(size_t i, size_t j, const double *rij, double gap, void *vctx)
{
    (void)rij;
    (void)gap;
    nbcheck_ctx *c = vctx;
    size_t key = (i < j ? i : j) * c->n + (i < j ? j : i);
    if (!bsearch(&key, c->keys, c->nkeys, sizeof key, cmp_size)) {
        c->missing = 1;
        return 1;
    }
    return 0;
}

int odhs__stepper_check_neighbours(odhs_stepper *st)
{
    if (st->nb_stale) return ODHS_OK;
    odhs_system *s = st->sys;
    double room = st->skin - skin_used(st);
    /* rc as build_neighbours sets it; the list must hold every pair closer
     * than the skin not used up yet */
    if (!(st->rc == 2.0 * s->rmax + st->skin) || !isfinite(room)) {
        st->nb_stale = 1;
        return ODHS_OK;
    }
    if (room <= 0.0) return ODHS_OK; /* the next step rebuilds it anyway */
    size_t *keys = odhs__malloc_array(st->npairs ? st->npairs : 1, sizeof *keys);
    if (!keys) return ODHS_E_NOMEM;
    for (size_t p = 0; p < st->npairs; ++p) keys[p] = st->pi[p] * st->n + st->pj[p];
    qsort(keys, st->npairs, sizeof *keys, cmp_size);
    nbcheck_ctx c = {keys, st->npairs, st->n, 0};
    int r = odhs__pairs(st->dim, st->n, s->x, s->r, s->rmax, s->L, s->gamma, room * (1.0 - 1e-9), nbcheck_cb, &c);
    odhs__free(keys);
    if (r == ODHS_E_NOMEM) return ODHS_E_NOMEM;
    if (r || c.missing) st->nb_stale = 1;
    return ODHS_OK;
}

/* rate at which skin_used can grow while moving with velocity field (G, vel) */
static double skin_rate(const odhs_stepper *st, const double *G, const double *vel)
{
    double umax = 0.0;
    int dim = st->dim;
    for (size_t i = 0; i < st->n; ++i) {
        double s = 0.0;
        for (int k = 0; k < dim; ++k) s += vel[i * dim + k] * vel[i * dim + k];
        umax = fmax(umax, s);
    }
    return 2.0 * sqrt(umax) + frob(G) * frob(st->M) * st->rc;
}

static double predict_walls(const odhs_stepper *st, const double *G, const double *vel, double best, double vtol,
                            int moving, int current, size_t *pi, size_t *pj);
static double pair_velocity(const odhs_stepper *st, size_t i, size_t j);

/* ---- collision prediction ------------------------------------------------ */
/* earliest time in [0, horizon] at which a non-contact pair touches when
 * separations move as d + t (G d + vel_j - vel_i) */
static double predict(const odhs_stepper *st, const double *G, const double *vel, double horizon,
                      double vtol, int moving, int current, size_t *pi, size_t *pj)
{
    const odhs_system *s = st->sys;
    int dim = st->dim;
    double best = horizon;
    *pi = *pj = SIZE_MAX;
    for (size_t p = 0; p < st->npairs; ++p) {
        size_t i = st->pi[p], j = st->pj[p];
        double d[3], gd[3] = {0, 0, 0}, w[3] = {0, 0, 0};
        min_sep(st, i, j, d);
        apply_G(G, dim, d, gd);
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
            } else if (pair_velocity(st, i, j) >= -vtol) {
                continue;
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
            apply_G(G, dim, x, gx);
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
                if (current ? pair_velocity(st, i, st->n + w) < -vtol : un > vtol) t = 0.0;
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

/* move by t along (G, vel), deforming the box with G; walls translate with
 * their velocities when moving != 0 */
static void advance_walls(odhs_stepper *st, double t)
{
    for (size_t w = 0; w < st->net->nwalls; ++w) {
        odhs_wall *wl = &st->net->walls[w];
        double vn = 0.0;
        for (int k = 0; k < st->dim; ++k) {
            double dx = t * wl->v[k];
            wl->c[k] += dx;
            wl->b[k] += dx;
            wl->disp[k] += dx;
            vn += wl->n[k] * wl->v[k];
        }
        if (wl->type == ODHS_WALL_PLANE) wl->h += t * vn;
    }
}

static void advance(odhs_stepper *st, const double *G, const double *vel, double t)
{
    odhs_system *s = st->sys;
    int dim = st->dim;
    for (size_t i = 0; i < st->n; ++i) {
        double *x = s->x + i * dim, gx[3];
        apply_G(G, dim, x, gx);
        for (int k = 0; k < dim; ++k) {
            double dx = t * vel[i * dim + k];
            x[k] += t * gx[k] + dx;
            st->disp[i * dim + k] += dx;
        }
    }
    /* box: H' = (I + tG) H with G = gdot e_x e_y^T - c I */
    double scale = 1.0 + t * G[3 * (1) + (1)];
    double g = s->gamma + t * G[3 * (0) + (1)] / scale;
    for (int k = 0; k < dim; ++k) s->L[k] *= scale;
    g = odhs__remap_strain(g, s->L);
    s->gamma = g;
    double Mn[9];
    for (int a = 0; a < 3; ++a)
        for (int b = 0; b < 3; ++b) {
            double v = st->M[3 * (a) + (b)];
            for (int c = 0; c < 3; ++c) v += t * G[3 * (a) + (c)] * st->M[3 * (c) + (b)];
            Mn[3 * (a) + (b)] = v;
        }
    memcpy(st->M, Mn, sizeof Mn);
    for (size_t i = 0; i < st->n; ++i) odhs__wrap(dim, s->L, s->gamma, s->x + i * dim);
}

/* ---- snapshot / rollback ------------------------------------------------- */
static int snapshot(odhs_stepper *st)
{
    odhs_network *net = st->net;
    if (st->scap < net->nc) {
        size_t cap = net->cap;
        size_t *a = odhs__realloc(st->sci, cap * sizeof *a);
        if (a) st->sci = a;
        size_t *b = odhs__realloc(st->scj, cap * sizeof *b);
        if (b) st->scj = b;
        int *k = odhs__realloc(st->skind, cap * sizeof *k);
        if (k) st->skind = k;
        double *f = odhs__realloc(st->sf, cap * sizeof *f);
        if (f) st->sf = f;
        double *rs = odhs__realloc(st->srest, cap * sizeof *rs);
        if (rs) st->srest = rs;
        if (!a || !b || !k || !f || !rs) return sterr(st, ODHS_E_NOMEM, "out of memory");
        st->scap = cap;
    }
    if (net->nwalls) {
        if (st->wsnapcap < net->nwalls) {
            odhs_wall *w = odhs__realloc(st->wsnap, net->nwalls * sizeof *w);
            if (!w) return sterr(st, ODHS_E_NOMEM, "out of memory");
            st->wsnap = w;
            st->wsnapcap = net->nwalls;
        }
        memcpy(st->wsnap, net->walls, net->nwalls * sizeof *net->walls);
    }
    memcpy(st->xs, st->sys->x, st->nd * sizeof *st->xs);
    memcpy(st->Us, st->U, st->nd * sizeof *st->Us);
    memcpy(st->Fs, st->F, st->nd * sizeof *st->Fs);
    st->has_Fs = st->has_F;
    memcpy(st->Ls, st->sys->L, sizeof st->Ls);
    st->gammas = st->sys->gamma;
    st->times = st->time;
    st->strains = st->strain;
    st->nsteps_s = st->nsteps;
    st->snc = net->nc;
    if (net->nc == 0) {
        memcpy(st->Gs, st->G, sizeof st->Gs);
        st->kappas = st->kappa;
        return ODHS_OK;
    }
    memcpy(st->Gs, st->G, sizeof st->Gs);
    st->kappas = st->kappa;
    memcpy(st->sci, net->ci, net->nc * sizeof *st->sci);
    memcpy(st->scj, net->cj, net->nc * sizeof *st->scj);
    memcpy(st->skind, net->kind, net->nc * sizeof *st->skind);
    memcpy(st->sf, net->f, net->nc * sizeof *st->sf);
    if (net->nperm) memcpy(st->srest, net->rest, net->nc * sizeof *st->srest);
    return ODHS_OK;
}

static void rollback(odhs_stepper *st)
{
    odhs_network *net = st->net;
    memcpy(st->sys->x, st->xs, st->nd * sizeof *st->xs);
    if (net->nwalls) memcpy(net->walls, st->wsnap, net->nwalls * sizeof *net->walls);
    memcpy(st->sys->L, st->Ls, sizeof st->Ls);
    st->sys->gamma = st->gammas;
    st->time = st->times;
    st->strain = st->strains;
    st->nsteps = st->nsteps_s;
    odhs_network_clear(net);
    for (size_t c = 0; c < st->snc; ++c) {
        size_t k = odhs__net_add(net, st->sci[c], st->scj[c], st->skind[c]);
        if (k == SIZE_MAX) break; /* cannot happen: capacity is retained */
        net->f[k] = st->sf[c];
        if (st->skind[c] == ODHS_CONTACT_PERMANENT) net->rest[k] = st->srest[c];
    }
    odhs__net_geometry(net, st->sys);
    memcpy(st->G, st->Gs, sizeof st->G);
    st->kappa = st->kappas;
    /* velocities and external forces as they were (recomputing them from the
     * restored contact forces could call a failing force callback again, and
     * gave non-finite velocities for a restored checkpoint whose forces
     * overflow S^T f: found by fuzz_checkpoint) */
    memcpy(st->U, st->Us, st->nd * sizeof *st->U);
    memcpy(st->F, st->Fs, st->nd * sizeof *st->F);
    st->has_F = st->has_Fs;
    st->nb_stale = 1; /* rebuild the neighbour list before the next step */
    /* its displacement record may hold the failed step's motion (even a
     * non-finite one): the rebuild starts it afresh, so clear it now (a
     * checkpoint taken before the next step must not carry it) */
    memset(st->disp, 0, st->nd * sizeof *st->disp);
    memset(st->M, 0, sizeof st->M);
    for (int a = 0; a < 3; ++a) st->M[3 * (a) + (a)] = 1.0;
}

/* ---- lifecycle ------------------------------------------------------------- */
int odhs_stepper_create(odhs_system *sys, odhs_driver *drv, odhs_solver *solver, odhs_stepper **out)
{
    if (!out) return ODHS_E_NULL;
    *out = NULL;
    if (!sys || !drv || !solver) return ODHS_E_NULL;
    if (!sys->has_r || !sys->has_x) return odhs__syserr(sys, ODHS_E_STATE, "set radii and positions first");
    odhs_stepper *st = odhs__calloc(1, sizeof *st);
    if (!st) return ODHS_E_NOMEM;
    st->sys = sys;
    st->drv = drv;
    st->sol = solver;
    st->dim = sys->dim;
    st->n = sys->n;
    st->nd = sys->n * (size_t)sys->dim;
    st->dt = 1e-3;
    st->integrator = ODHS_INTEGRATOR_HEUN;
    st->tol = 1e-6;
    st->h = st->dt;
    st->corr_every = CORR_DEFAULT_HEUN;
    st->contact_tol = 1e-9;
    st->F = odhs__calloc(st->nd, sizeof(double));
    st->U = odhs__calloc(st->nd, sizeof(double));
    st->tmp = odhs__calloc(st->nd, sizeof(double));
    st->disp = odhs__calloc(st->nd, sizeof(double));
    st->xs = odhs__calloc(3 * st->nd, sizeof(double));
    if (st->xs) {
        st->Us = st->xs + st->nd;
        st->Fs = st->xs + 2 * st->nd;
    }
    st->U0 = odhs__calloc(st->nd, sizeof(double));
    st->Ua = odhs__calloc(st->nd, sizeof(double));
    st->Up = odhs__calloc(st->nd, sizeof(double));
    st->disps = odhs__calloc(st->nd, sizeof(double));
    int s = odhs_network_create(sys, &st->net);
    if (!st->F || !st->U || !st->tmp || !st->disp || !st->xs || !st->U0 || !st->Ua || !st->Up || !st->disps || s) {
        odhs_stepper_destroy(st);
        return ODHS_E_NOMEM;
    }
    *out = st;
    return ODHS_OK;
}

void odhs_stepper_destroy(odhs_stepper *st)
{
    if (!st) return;
    odhs_network_destroy(st->net);
    void *arrays[] = {st->disps, st->U0, st->Ua, st->Up, st->F,   st->U,   st->tmp, st->cb,  st->cx,    st->pi,  st->pj, st->disp,
                      st->rem, st->fpj, st->chg, st->xs, st->sci, st->scj, st->skind, st->sf, st->srest, st->ev, st->wsnap};
    for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; ++k) odhs__free(arrays[k]);
    odhs__free(st);
}

const char *odhs_stepper_errmsg(const odhs_stepper *st) { return st ? st->errmsg : ""; }

int odhs_stepper_set_dt(odhs_stepper *st, double dt)
{
    if (!st) return ODHS_E_NULL;
    if (!isfinite(dt)) return sterr(st, ODHS_E_NONFINITE, "dt is not finite");
    if (!(dt > 0.0)) return sterr(st, ODHS_E_INVALID, "dt = %g must be > 0", dt);
    st->dt = dt;
    st->h = dt;
    return ODHS_OK;
}

int odhs_stepper_set_integrator(odhs_stepper *st, int integrator)
{
    if (!st) return ODHS_E_NULL;
    if (integrator != ODHS_INTEGRATOR_EULER && integrator != ODHS_INTEGRATOR_HEUN)
        return sterr(st, ODHS_E_INVALID, "unknown integrator %d", integrator);
    st->integrator = integrator;
    st->h = st->dt;
    if (!st->corr_user) st->corr_every = integrator == ODHS_INTEGRATOR_HEUN ? CORR_DEFAULT_HEUN : CORR_DEFAULT_EULER;
    return ODHS_OK;
}

int odhs_stepper_set_tolerance(odhs_stepper *st, double tol)
{
    if (!st) return ODHS_E_NULL;
    if (!isfinite(tol) || !(tol > 0.0) || !(tol < 1.0))
        return sterr(st, ODHS_E_INVALID, "tolerance %g must be in (0, 1)", tol);
    st->tol = tol;
    return ODHS_OK;
}

int odhs_stepper_get_settings(const odhs_stepper *st, int *integrator, double *dt, double *tol,
                              unsigned *correction_interval)
{
    if (!st) return ODHS_E_NULL;
    if (integrator) *integrator = st->integrator;
    if (dt) *dt = st->dt;
    if (tol) *tol = st->tol;
    if (correction_interval) *correction_interval = st->corr_every;
    return ODHS_OK;
}

int odhs_stepper_rewire_stats(const odhs_stepper *st, uint64_t *count)
{
    if (!st || !count) return ODHS_E_NULL;
    *count = st->nrewire_monotone;
    return ODHS_OK;
}

int odhs__stepper_set_rewire_mode(odhs_stepper *st, int mode)
{
    if (!st) return ODHS_E_NULL;
    if (mode != 0 && mode != 1) return sterr(st, ODHS_E_INVALID, "rewire mode %d is not 0 or 1", mode);
    st->rewire_mode = mode;
    return ODHS_OK;
}

int odhs_stepper_adaptive_stats(const odhs_stepper *st, uint64_t *rejected, double *h)
{
    if (!st) return ODHS_E_NULL;
    if (rejected) *rejected = st->nrejected;
    if (h) *h = st->h;
    return ODHS_OK;
}

int odhs_stepper_set_correction_interval(odhs_stepper *st, unsigned k)
{
    if (!st) return ODHS_E_NULL;
    st->corr_every = k;
    st->corr_user = 1;
    return ODHS_OK;
}

int odhs_stepper_set_contact_tolerance(odhs_stepper *st, double tol)
{
    if (!st) return ODHS_E_NULL;
    if (!isfinite(tol) || tol < 0.0 || tol > 0.1)
        return sterr(st, ODHS_E_INVALID, "contact tolerance %g must be in [0, 0.1]", tol);
    st->contact_tol = tol;
    return ODHS_OK;
}

int odhs_stepper_set_event_callback(odhs_stepper *st, odhs_event_fn fn, void *ctx)
{
    if (!st) return ODHS_E_NULL;
    st->evfn = fn;
    st->evctx = ctx;
    return ODHS_OK;
}

static int check_driver(odhs_stepper *st)
{
    odhs_driver *d = st->drv;
    if (d->pressure_on && d->gdot == 0.0)
        return sterr(st, ODHS_E_UNSUPPORTED, "fixed pressure needs a nonzero shear rate");
    if (d->pressure_on && st->net->nwalls)
        return sterr(st, ODHS_E_UNSUPPORTED, "fixed pressure with walls is not supported");
    if (d->pressure_on && d->crate != 0.0)
        return sterr(st, ODHS_E_UNSUPPORTED, "fixed pressure and a compression rate cannot be combined");
    if (d->F && (d->Fn != st->n || d->Fdim != st->dim))
        return sterr(st, ODHS_E_DIM, "driver forces are for N = %zu, d = %d, the system has N = %zu, d = %d",
                     d->Fn, d->Fdim, st->n, st->dim);
    if (odhs__driver_check_extra(d, st->n, st->dim))
        return sterr(st, ODHS_E_DIM, "self-propulsion or gravity settings do not fit N = %zu, d = %d", st->n,
                     st->dim);
    return ODHS_OK;
}


int odhs_stepper_reset(odhs_stepper *st)
{
    if (!st) return ODHS_E_NULL;
    int s, psaved = 0;
    st->ready = 0;
    st->jammed = 0;
    odhs__solver_invalidate(st->sol); /* our network may reuse a freed address */
    if ((s = check_driver(st))) return s;
    if ((s = odhs_driver_time_unit(st->drv, st->sys, &st->tau))) return sterr(st, s, "%s", st->drv->errmsg);
    st->lambda = 0.0;
    for (size_t i = 0; i < st->n; ++i) st->lambda += 2.0 * st->sys->r[i];
    st->lambda /= (double)st->n;
    /* keep permanent contacts, rebuild the temporary ones; an error puts
     * the configuration and the network back as they were (rollback) */
    odhs_network *net = st->net;
    if ((s = snapshot(st))) return s;
    odhs__net_geometry(net, st->sys);
    for (size_t c = net->nc; c-- > 0;) {
        double sig = odhs__net_sigma(net, st->sys, c);
        if (odhs__can_open(net->kind[c]) &&
            (fabs(net->gap[c]) > fmax(1e-6, st->contact_tol) * sig || odhs__same_body(net, net->ci[c], net->cj[c])))
            odhs__net_remove_at(net, c);
    }
    if ((s = odhs_network_detect(net, st->sys, st->contact_tol))) {
        s = sterr(st, s, "%s", net->errmsg);
        goto fail;
    }
    if ((s = build_neighbours(st))) goto fail;
    odhs__prop_save(st->drv); /* an error leaves the propulsion clock as it was */
    psaved = 1;
    odhs__prop_start(st->drv, st->time, st->lambda);
    if ((s = eval_forces(st))) goto fail;
    st->nchg = 0;
    if ((s = rewire(st))) goto fail;
    st->nchg = 0;
    st->drv_version = st->drv->version;
    st->ready = 1;
    return ODHS_OK;
fail:
    if (psaved) odhs__prop_restore(st->drv);
    if (s < 0) rollback(st);
    st->nchg = 0;
    return s;
}

/* ---- drift correction (Sect. IV C) ------------------------------------- */
/* Drift correction of an isostatic network under fixed pressure (see
 * correct): fills Z with the isotropic gradient and st->cx with the
 * correction's contact forces (zero on contact k). */
static int correct_isostatic(odhs_stepper *st, double *Z)
{
    odhs_network *net = st->net;
    size_t nc = net->nc;
    int s;
    st->work_pressure++;
    if ((s = isostatic_f0(st))) return s;
    double *f0 = st->fpj, *rhs = st->fpj + nc;
    double fg = 0.0, fr = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        fg += f0[c] * net->gap[c];
        fr += f0[c] * net->dist[c];
    }
    double eps = fr != 0.0 ? fg / fr : 0.0;
    for (int a = 0; a < st->dim; ++a) Z[3 * a + a] = -eps;
    for (size_t c = 0; c < nc; ++c) rhs[c] = net->gap[c] - eps * net->dist[c];
    return solve_isostatic(st, f0, rhs, st->cx, 1e-7);
}

static int correct(odhs_stepper *st, int *added)
{
    odhs_network *net = st->net;
    const odhs_system *sys = st->sys;
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
        if ((s = reserve_contacts(st, nc))) return sterr(st, s, "out of memory");
        double gmax = 0.0;
        for (size_t c = 0; c < nc; ++c)
            gmax = fmax(gmax, fabs(net->gap[c]) / odhs__net_sigma(net, sys, c));
        if (gmax <= 4e-16) return ODHS_OK;            /* at round-off */
        if (!(gmax < 0.5 * prev)) return ODHS_OK;     /* no further progress */
        long excess;
        if ((s = odhs__net_excess(net, &excess))) return sterr(st, s, "%s", net->errmsg);
        if (excess >= 1 && !(excess == 1 && st->drv->pressure_on))
            return ODHS_OK; /* N singular: the rewiring handles it (f0) */
        prev = gmax;
        memset(st->cx, 0, nc * sizeof *st->cx);
        memset(Z, 0, sizeof Z);
        if (excess == 1) {
            /* fixed pressure, flowing on an isostatic network: N is singular,
             * but the volume is free. The gap component along f0 goes with an
             * isotropic rescaling (gradient Z = -eps I over the unit
             * correction time, eps = <f0|gap>/<f0|r>), the rest on the network
             * without the contact k of largest |f0| (its row of S follows
             * from the others through f0), as when a packing is polished */
            s = correct_isostatic(st, Z);
        } else {
            /* the gaps are small: a relative residual of 1e-7 removes them to
             * round-off in one pass (a further pass follows if not) */
            s = odhs__solver_solve_relaxed(st->sol, net, net->gap, st->cx, 1e-7);
            if (s) s = sterr(st, s, "force solve: %s", odhs_solver_errmsg(st->sol));
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
        size_t pi, pj;
        double t = predict(st, Z, st->tmp, 1.0, 0.0, 0, 0, &pi, &pj);
        advance(st, Z, st->tmp, t);
        if (pi != SIZE_MAX) {
            size_t c = odhs__net_add(net, pi, pj, ODHS_CONTACT_TEMPORARY);
            if (c == SIZE_MAX || record_change(st, pi, pj, +1)) return sterr(st, ODHS_E_NOMEM, "out of memory");
            *added = 1;
            prev = INFINITY; /* new contact: a new problem */
        }
    }
    odhs__net_geometry(net, sys);
    return ODHS_OK;
}

/* ---- events ------------------------------------------------------------------ */
static int cmp_change(const void *a, const void *b)
{
    const odhs_change *x = a, *y = b;
    if (x->i != y->i) return x->i < y->i ? -1 : 1;
    if (x->j != y->j) return x->j < y->j ? -1 : 1;
    return 0;
}

/* turn the step's recorded changes into net events */
static int collect_events(odhs_stepper *st)
{
    st->nev = 0;
    if (st->nchg == 0) return ODHS_OK;
    qsort(st->chg, st->nchg, sizeof *st->chg, cmp_change);
    for (size_t a = 0; a < st->nchg;) {
        size_t b = a;
        int sum = 0;
        while (b < st->nchg && st->chg[b].i == st->chg[a].i && st->chg[b].j == st->chg[a].j) sum += st->chg[b++].delta;
        if (sum != 0) {
            if (reserve((void **)&st->ev, &st->evcap, st->nev + 1, sizeof *st->ev))
                return sterr(st, ODHS_E_NOMEM, "out of memory");
            odhs_event *e = &st->ev[st->nev++];
            e->kind = sum > 0 ? ODHS_EVENT_COLLISION : ODHS_EVENT_OPENING;
            e->i = st->chg[a].i;
            e->j = st->chg[a].j;
            e->time = st->time;
            e->strain = st->strain;
        }
        a = b;
    }
    st->nchg = 0;
    return ODHS_OK;
}

static int emit_events(odhs_stepper *st, odhs_event *first, int *stop);

/* back to the start of the current step before any contact changed (used by
 * the adaptive integrator to repeat a step with a shorter length) */
static int restart_step(odhs_stepper *st)
{
    odhs_network *net = st->net;
    memcpy(st->sys->x, st->xs, st->nd * sizeof *st->xs);
    if (net->nwalls) memcpy(net->walls, st->wsnap, net->nwalls * sizeof *net->walls);
    memcpy(st->sys->L, st->Ls, sizeof st->Ls);
    st->sys->gamma = st->gammas;
    st->time = st->times;
    st->strain = st->strains;
    st->nsteps = st->nsteps_s;
    memcpy(st->disp, st->disps, st->nd * sizeof *st->disp);
    memcpy(st->M, st->Ms, sizeof st->M);
    if (st->snc) memcpy(net->f, st->sf, st->snc * sizeof *net->f);
    memcpy(st->G, st->Gs, sizeof st->G);
    st->kappa = st->kappas;
    odhs__net_geometry(net, st->sys);
    return eval_forces(st);
}

/* ---- adaptive Heun --------------------------------------------------------
 * Predictor: move by tau*V0 (no collision checks: the configuration is only
 * used to evaluate velocities on the same network), solve there for V*. The
 * step uses the average velocity on a straight chord, so collisions are
 * still located exactly on the motion actually taken. Error estimate: the
 * difference between the Euler and Heun non-affine displacements,
 * tau/2 max_i |U*_i - U0_i|, relative to the mean diameter. On return *Ga, st->Ua
 * hold the chord's gradient and velocities and *tau the accepted step. */
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
        apply_G(Gs, dim, st->U0 + i * dim, gu);
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

static int heun(odhs_stepper *st, double limit, double *Ga, double *tau_out)
{
    odhs_system *sys = st->sys;
    odhs_network *net = st->net;
    size_t nd = st->nd;
    int s;
    double G0[9], M0[9], k0 = st->kappa;
    memcpy(G0, st->G, sizeof G0);
    memcpy(M0, st->M, sizeof M0);
    memcpy(st->U0, st->U, nd * sizeof *st->U0);
    st->pred_ok = 0;
    double *disp0 = st->Ua; /* borrow: disp is restored from it below */
    for (int attempt = 0;; ++attempt) {
        double tau = st->h * st->tau, truncated = 0;
        if (limit < tau) {
            tau = limit;
            truncated = 1;
        }
        memcpy(disp0, st->disp, nd * sizeof *disp0);
        double t0 = st->time;
        advance(st, G0, st->U0, tau);
        if (net->nwalls) advance_walls(st, tau);
        st->time = t0 + tau;
        odhs__net_geometry(net, sys);
        s = eval_forces(st);
        if (!s) s = compute_forces(st);
        st->time = t0;
        if (!s) compute_velocities(st); /* st->U = U*, st->G = G* */
        /* error estimate */
        double emax = 0.0;
        for (size_t i = 0; i < st->n && !s; ++i) {
            double e2 = 0.0, gu[3];
            /* k2 - k1 = U* - U0 + tau G* U0 (non-affine part) */
            apply_G(st->G, st->dim, st->U0 + i * st->dim, gu);
            for (int k = 0; k < st->dim; ++k) {
                double dv = st->U[i * st->dim + k] - st->U0[i * st->dim + k] + tau * gu[k];
                e2 += dv * dv;
            }
            emax = fmax(emax, e2);
        }
        double err = 0.5 * tau * sqrt(emax) / st->lambda;
        double Gs[9];
        memcpy(Gs, st->G, sizeof Gs);
        /* restore the start of the step (forces in net->f stay as a guess) */
        memcpy(sys->x, st->xs, nd * sizeof *sys->x);
        if (net->nwalls) memcpy(net->walls, st->wsnap, net->nwalls * sizeof *net->walls);
        memcpy(sys->L, st->Ls, sizeof st->Ls);
        sys->gamma = st->gammas;
        memcpy(st->M, M0, sizeof M0);
        memcpy(st->disp, disp0, nd * sizeof *disp0);
        odhs__net_geometry(net, sys);
        memcpy(st->G, G0, sizeof G0);
        st->kappa = k0;
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
            /* accepted: the chord of Heun's x1 = x0 + tau/2 (k1 + k2) */
            heun_chord(st, G0, Gs, st->U, tau, Ga);
            /* kept for a shorter chord of this step (heun_shorter) */
            memcpy(st->Up, st->U, nd * sizeof *st->Up);
            memcpy(st->Gp, Gs, sizeof Gs);
            st->taup = tau;
            st->pred_ok = 1;
            memcpy(st->U, st->U0, nd * sizeof *st->U);
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

/* ---- one step ----------------------------------------------------------------- */
/* limit: largest time to advance (INFINITY for none); *stop set by callbacks */
static int do_step(odhs_stepper *st, double limit, odhs_event *first, int *stop)
{
    int s;
    if (first) {
        memset(first, 0, sizeof *first);
        first->kind = ODHS_EVENT_NONE;
    }
    if (!st->ready && (s = odhs_stepper_reset(st))) return s;
    if (st->jammed) return sterr(st, ODHS_JAMMED, "the packing is jammed: no further steps under this driving");
    if ((s = snapshot(st))) return s;
    /* step bookkeeping that rollback() does not cover */
    const uint64_t drv_version0 = st->drv_version, nrejected0 = st->nrejected;
    const double tau0 = st->tau, h0 = st->h;
    int psaved = 0; /* self-propulsion state saved for the rollback */
    st->nchg = 0;
    if (st->drv_version != st->drv->version || odhs__prop_next(st->drv) <= st->time) {
        /* the driver changed since the forces were solved (or propulsion
         * switches are overdue, e.g. on a driver shared by steppers): re-solve */
        if ((s = check_driver(st))) goto fail;
        if ((s = odhs_driver_time_unit(st->drv, st->sys, &st->tau))) {
            s = sterr(st, s, "%s", st->drv->errmsg);
            goto fail;
        }
        odhs__prop_save(st->drv);
        psaved = 1;
        odhs__prop_start(st->drv, st->time, st->lambda);
        odhs__prop_switch(st->drv, st->time, st->lambda);
        if ((s = eval_forces(st)) || (s = rewire(st))) goto fail;
        st->drv_version = st->drv->version;
        if (st->nchg) {
            /* the new driving opened or closed contacts: that is this step's
             * event, at the current time and with no motion */
            st->nsteps++;
            if ((s = emit_events(st, first, stop))) goto fail;
            return ODHS_OK;
        }
    }
    int relocated = 0, nhalve = 0;
    st->pred_ok = 0;
    if (st->integrator == ODHS_INTEGRATOR_HEUN) {
        memcpy(st->disps, st->disp, st->nd * sizeof *st->disps);
        memcpy(st->Ms, st->M, sizeof st->Ms);
    }
    /* self-propulsion: a step ends exactly at the next switch time */
    const double tsw = odhs__prop_next(st->drv), dsw = tsw - st->time;
    if (dsw <= limit) limit = dsw;
again:;
    double tplan = st->dt * st->tau;
    if (limit < tplan) tplan = limit;
    /* the chord of this step: gradient G and velocities vel */
    double G[9];
    const double *vel = st->U;
    memcpy(G, st->G, sizeof G);
    if (st->integrator == ODHS_INTEGRATOR_HEUN) {
        if (relocated && st->pred_ok && limit < st->taup) {
            heun_shorter(st, limit, G);
            tplan = limit;
        } else if ((s = heun(st, limit, G, &tplan))) {
            goto fail;
        }
        vel = st->Ua;
    }

    /* neighbour-list validity over the step */
    double rate = skin_rate(st, G, vel);
    if (st->nb_stale || skin_used(st) + rate * tplan > st->skin) {
        st->nb_stale = 0;
        if ((s = build_neighbours(st))) goto fail;
        rate = skin_rate(st, G, vel);
        if (rate * tplan > 0.9 * st->skin) tplan = 0.9 * st->skin / rate;
    }
    size_t ci, cj;
    double t = predict(st, G, vel, tplan, EPS_V * velocity_scale(st), 1, 1, &ci, &cj);
    if (st->integrator == ODHS_INTEGRATOR_HEUN && ci != SIZE_MAX && !relocated && t < 1e-3 * tplan &&
        nhalve < 40 && pair_velocity(st, ci, cj) >= -EPS_V * velocity_scale(st)) {
        /* a collision at (almost) the start of the step of a pair that
         * separates with the start velocities: it approaches only on the
         * averaged chord. Added now, the rewiring would remove it again and
         * the next step repeat this (no progress): halve the step instead,
         * until the chord is close enough to the start velocities. */
        nhalve++;
        limit = 0.5 * tplan;
        goto again;
    }
    advance(st, G, vel, t);
    if (st->net->nwalls) advance_walls(st, t);
    for (size_t k = 0; k < st->nd; ++k)
        if (!isfinite(st->sys->x[k])) {
            s = sterr(st, ODHS_E_NONFINITE, "non-finite positions after a step of %g (rates too large?)", t);
            goto fail;
        }
    if (!isfinite(st->sys->L[0]) || !(st->sys->L[0] > 0.0) || !isfinite(st->sys->gamma)) {
        s = sterr(st, ODHS_E_NONFINITE, "the box became degenerate after a step of %g", t);
        goto fail;
    }
    const int at_switch = ci == SIZE_MAX && t == dsw; /* the step reached the switch time */
    st->time = at_switch ? tsw : st->time + t;
    st->strain += t * st->drv->gdot;
    st->nsteps++;
    odhs_network *net = st->net;
    if (st->integrator == ODHS_INTEGRATOR_HEUN && ci != SIZE_MAX && !relocated && t < 0.999 * tplan && t > 0.0) {
        /* the chord was the Heun average over the planned step; repeat the
         * step with the Heun chord of [0, t_collision] (second order) */
        if ((s = restart_step(st))) goto fail;
        relocated = 1;
        /* at least 1e-3 of the step: over [0, ~1e-17] the chord is the start
         * velocity, which may close the gap far slower than the averaged
         * chord did (a Zeno sequence of ~1e-17 steps otherwise) */
        limit = fmax(t * (1.0 + 1e-7), 1e-3 * tplan);
        goto again;
    }
    if (ci != SIZE_MAX) {
        size_t c = odhs__net_add(net, ci, cj, ODHS_CONTACT_TEMPORARY);
        if (c == SIZE_MAX || record_change(st, ci, cj, +1)) {
            s = sterr(st, ODHS_E_NOMEM, "out of memory");
            goto fail;
        }
    }
    odhs__net_geometry(net, st->sys);
    if ((s = eval_forces(st))) goto fail;
    if (st->integrator == ODHS_INTEGRATOR_HEUN && ci == SIZE_MAX && !relocated && net->nc == st->snc) {
        /* locate an opening inside the step: forces are smooth in time, so
         * the first zero crossing t* = t f0/(f0 - f1) (second-order accurate)
         * ends a repeated, shorter step, instead of the step's end */
        long excess = 0;
        odhs__net_excess(net, &excess);
        /* under fixed pressure an isostatic network still flows */
        int flows = excess < 1 || (st->drv->pressure_on && excess == 1);
        if (flows && (s = compute_forces(st)) == ODHS_OK) {
            double fbig = 0.0, tstar = INFINITY;
            for (size_t c = 0; c < net->nc; ++c) fbig = fmax(fbig, fabs(net->f[c]));
            for (size_t c = 0; c < net->nc; ++c) {
                double f0 = st->sf[c], f1 = net->f[c];
                /* f0 at round-off level: the contact opens now, at the
                 * step's end (relocating to t f0/(f0 - f1) ~ 1e-16 t would
                 * repeat forever, as the force stays at round-off) */
                if (!odhs__can_open(net->kind[c]) || !(f1 < -EPS_F * fbig) || !(f0 > EPS_F * fbig)) continue;
                tstar = fmin(tstar, t * f0 / (f0 - f1));
            }
            if (tstar < 0.999 * t) {
                if ((s = restart_step(st))) goto fail;
                relocated = 1;
                /* a force that starts at (almost) zero would give steps of
                 * no length forever: end the step a little later, where the
                 * force is negative and the rewiring opens the contact */
                limit = fmax(tstar * (1.0 + 1e-9), 1e-6 * t);
                goto again;
            }
        } else if (s == ODHS_E_SINGULAR || s == ODHS_E_NOCONV) {
            s = ODHS_OK; /* locating the opening is a probe: the rewiring below decides */
        } else if (s) {
            goto fail;
        }
    }
    if (at_switch) {
        /* new propulsion forces from the switch time on */
        if (!psaved) odhs__prop_save(st->drv);
        psaved = 1;
        odhs__prop_switch(st->drv, st->time, st->lambda);
        if ((s = eval_forces(st))) goto fail;
    }
    if (st->corr_every && st->nsteps % st->corr_every == 0) {
        /* drift correction before the rewiring: the rewiring's solve is then
         * that of the corrected geometry, and contacts the correction adds
         * (collisions on its path) are rewired with the step's events */
        int added = 0;
        if ((s = correct(st, &added))) goto fail;
    }
    if ((s = rewire(st))) goto fail;
    if ((s = emit_events(st, first, stop))) goto fail;
    if (st->jammed)
        return sterr(st, ODHS_JAMMED, "jammed at t = %.17g: isostatic constrained subset, positive self-stress",
                     st->time);
    return ODHS_OK;
fail:
    if (psaved) odhs__prop_restore(st->drv);
    rollback(st);
    /* the forces are again those of the start of the step: solved for the
     * driver as it was then (a changed driver is re-solved next time) */
    st->drv_version = drv_version0;
    st->tau = tau0;
    st->h = h0;
    st->nrejected = nrejected0;
    st->jammed = 0;
    st->nchg = 0;
    return s;
}

static int emit_events(odhs_stepper *st, odhs_event *first, int *stop)
{
    int s = collect_events(st);
    if (s) return s;
    for (size_t k = 0; k < st->nev; ++k) {
        if (st->ev[k].kind == ODHS_EVENT_COLLISION) st->ncoll++;
        else st->nopen++;
    }
    if (first && st->nev) *first = st->ev[0];
    if (st->evfn)
        for (size_t k = 0; k < st->nev; ++k)
            if (st->evfn(&st->ev[k], st->evctx)) *stop = 1;
    return ODHS_OK;
}

int odhs_stepper_correct(odhs_stepper *st)
{
    if (!st) return ODHS_E_NULL;
    int s, stop = 0, added = 0;
    if (!st->ready && (s = odhs_stepper_reset(st))) return s;
    if ((s = snapshot(st))) return s;
    const int jammed0 = st->jammed;
    st->nchg = 0;
    if ((s = correct(st, &added))) goto fail;
    if ((s = rewire(st))) goto fail;
    if ((s = emit_events(st, NULL, &stop))) goto fail;
    if (st->jammed) return ODHS_JAMMED;
    return stop ? ODHS_STOPPED : ODHS_OK;
fail:
    rollback(st);
    st->jammed = jammed0;
    st->nchg = 0;
    return s;
}

int odhs_stepper_step(odhs_stepper *st, odhs_event *ev)
{
    if (!st) return ODHS_E_NULL;
    int stop = 0;
    int s = do_step(st, INFINITY, ev, &stop);
    if (s) return s;
    return stop ? ODHS_STOPPED : ODHS_OK;
}

/* generic run loop: remaining() gives the time left to the target (<= 0: done) */
typedef double (*remaining_fn)(const odhs_stepper *st, const void *arg);

static int run(odhs_stepper *st, remaining_fn rem, const void *arg, uint64_t max_events)
{
    uint64_t ev0 = st->ncoll + st->nopen;
    for (;;) {
        double left = rem ? rem(st, arg) : INFINITY;
        if (!(left > 0.0)) return ODHS_OK;
        if (max_events && st->ncoll + st->nopen - ev0 >= max_events) return ODHS_OK;
        int stop = 0;
        int s = do_step(st, left, NULL, &stop);
        if (s) return s;
        if (stop) return ODHS_STOPPED;
    }
}

static double rem_time(const odhs_stepper *st, const void *arg)
{
    double t = *(const double *)arg;
    double left = t - st->time;
    return left > 1e-15 * fabs(t) ? left : 0.0;
}

int odhs_stepper_run_until_time(odhs_stepper *st, double t)
{
    if (!st) return ODHS_E_NULL;
    if (!isfinite(t)) return sterr(st, ODHS_E_NONFINITE, "target time is not finite");
    return run(st, rem_time, &t, 0);
}

static double rem_strain(const odhs_stepper *st, const void *arg)
{
    double g = *(const double *)arg, gd = st->drv->gdot;
    double left = (g - st->strain) / gd;
    return fabs(g - st->strain) > 1e-15 * fmax(fabs(g), 1e-300) && left > 0.0 ? left : 0.0;
}

int odhs_stepper_run_until_strain(odhs_stepper *st, double gamma)
{
    if (!st) return ODHS_E_NULL;
    if (!isfinite(gamma)) return sterr(st, ODHS_E_NONFINITE, "target strain is not finite");
    if (st->drv->gdot == 0.0) return sterr(st, ODHS_E_STATE, "run_until_strain needs a nonzero shear rate");
    return run(st, rem_strain, &gamma, 0);
}

int odhs_stepper_run_events(odhs_stepper *st, uint64_t count)
{
    if (!st) return ODHS_E_NULL;
    if (count == 0) return ODHS_OK;
    return run(st, NULL, NULL, count);
}

static double rem_phi(const odhs_stepper *st, const void *arg)
{
    double target = *(const double *)arg, phi;
    odhs_system_packing_fraction(st->sys, &phi);
    if (phi >= target * (1.0 - 1e-15)) return 0.0;
    double c = -st->G[3 * (1) + (1)]; /* current isotropic compression rate */
    if (!(c > 0.0)) return INFINITY;
    /* phi grows as (1 - c t)^(-d) over a straight step */
    return (1.0 - pow(phi / target, 1.0 / st->dim)) / c;
}

int odhs_stepper_run_until_packing_fraction(odhs_stepper *st, double phi)
{
    if (!st) return ODHS_E_NULL;
    if (!isfinite(phi)) return sterr(st, ODHS_E_NONFINITE, "target packing fraction is not finite");
    if (!(phi > 0.0) || phi >= 1.0) return sterr(st, ODHS_E_INVALID, "packing fraction must be in (0,1)");
    if (st->drv->crate <= 0.0 && !st->drv->pressure_on)
        return sterr(st, ODHS_E_STATE, "run_until_packing_fraction needs compression or pressure driving");
    return run(st, rem_phi, &phi, 0);
}

/* ---- observables ------------------------------------------------------------- */
#define NEED(st, p)                                                          \
    do {                                                                     \
        if (!(st)) return ODHS_E_NULL;                                       \
        if (!(p)) return sterr((st), ODHS_E_NULL, "output pointer is NULL"); \
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
    if (!st->ready) return sterr(st, ODHS_E_STATE, "no valid state yet: call odhs_stepper_reset or step first");
    return ODHS_OK;
}

int odhs_stepper_stress(const odhs_stepper *st, double *sigma)
{
    NEED(st, sigma);
    int s = need_ready(st);
    if (s) return s;
    int dim = st->dim;
    const odhs_network *net = st->net;
    double vol;
    odhs_system_volume(st->sys, &vol);
    for (int a = 0; a < dim * dim; ++a) sigma[a] = 0.0;
    for (size_t c = 0; c < net->nc; ++c) {
        if (net->cj[c] >= st->n) continue; /* walls: see odhs_stepper_wall_force */
        const double *n = net->nrm + c * dim;
        double w = net->f[c] * net->dist[c];
        for (int a = 0; a < dim; ++a)
            for (int b = 0; b < dim; ++b) sigma[a * dim + b] -= w * n[a] * n[b];
    }
    for (int a = 0; a < dim * dim; ++a) sigma[a] /= vol;
    return ODHS_OK;
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
    int dim = st->dim;
    double p = 0.0;
    for (size_t c = 0; c < net->nc; ++c) {
        const double *n = net->nrm + c * dim;
        double v = 0.0;
        if (net->cj[c] >= st->n) { /* wall: (S V_aff)_c + w_c = n.(v_wall - G x_i) */
            const odhs_wall *w = &net->walls[net->cj[c] - st->n];
            double gx[3];
            apply_G(st->G, dim, st->sys->x + net->ci[c] * dim, gx);
            for (int k = 0; k < dim; ++k) v += (w->v[k] - gx[k]) * n[k];
            p -= net->f[c] * v;
            continue;
        }
        double d[3] = {0, 0, 0}, gd[3];
        for (int k = 0; k < dim; ++k) d[k] = n[k] * net->dist[c];
        apply_G(st->G, dim, d, gd);
        for (int k = 0; k < dim; ++k) v += gd[k] * n[k];
        p -= net->f[c] * v;
    }
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
        apply_G(st->G, dim, st->sys->x + i * dim, gx);
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
    default: return sterr(st, ODHS_E_INVALID, "unknown feature %d", feature);
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
        if (r == ODHS_E_NOMEM) return sterr(st, r, "out of memory");
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
