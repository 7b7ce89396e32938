/* libodhs - the stepper's forces and velocities on the current network:
 * external forces, the right-hand side of the affine flow, the force solve
 * (eqs. 11-12 and 18-19 of the paper) and pair velocities. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

void odhs__st_set_gradient(odhs_stepper *st, double c_eff)
{
    odhs__flow_gradient(st->drv, st->time, st->flow_end ? -1 : +1, st->dim, c_eff, st->G);
}

int odhs__st_add_contact(odhs_stepper *st, size_t i, size_t j, size_t *c)
{
    /* a particle meeting wall j - n makes a wall contact */
    *c = odhs__net_add(st->net, i, j, j >= st->n ? ODHS_CONTACT_WALL : ODHS_CONTACT_TEMPORARY);
    if (*c == SIZE_MAX || odhs__st_record_change(st, i, j, +1)) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    return ODHS_OK;
}

int odhs__st_reserve_contacts(odhs_stepper *st, size_t nc)
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

/* ---- external forces ---------------------------------------------------- */
int odhs__st_external_forces(odhs_stepper *st)
{
    odhs_driver *d = st->drv;
    if (d->fn) {
        memset(st->F, 0, st->nd * sizeof *st->F);
        if (d->fn(st->time, st->sys, st->F, d->fn_ctx))
            return odhs__sterr(st, ODHS_E_CALLBACK, "force callback failed at t = %.17g", st->time);
        for (size_t k = 0; k < st->nd; ++k)
            if (!isfinite(st->F[k]))
                return odhs__sterr(st, ODHS_E_CALLBACK, "force callback returned a non-finite value for particle %zu",
                             k / st->dim);
        st->has_F = 1;
    } else if (d->F) {
        if (d->Fn != st->n || d->Fdim != st->dim)
            return odhs__sterr(st, ODHS_E_DIM, "driver forces are for N = %zu, d = %d", d->Fn, d->Fdim);
        memcpy(st->F, d->F, st->nd * sizeof *st->F);
        st->has_F = 1;
    } else {
        st->has_F = 0;
    }
    /* self-propulsion and gravity add to the above */
    if ((d->prop_on || d->grav_on) && odhs__driver_extra_forces(d, st->sys, st->F, &st->has_F))
        return odhs__sterr(st, ODHS_E_DIM, "self-propulsion or gravity settings do not fit N = %zu, d = %d", st->n,
                     st->dim);
    if (st->has_F) {
        /* velocities xi0 F are squared throughout (collision prediction,
         * error estimates, skins): keep them where squares neither over-
         * nor underflow */
        double fm = 0.0;
        for (size_t k = 0; k < st->nd; ++k) fm = fmax(fm, fabs(st->F[k]));
        double v = d->xi0 * fm;
        if (v > ODHS_VMAX || (v > 0.0 && v < ODHS_VMIN && !(odhs__flow_rate_scale(d) > 0.0)))
            return odhs__sterr(st, d->fn ? ODHS_E_CALLBACK : ODHS_E_INVALID,
                               "external forces up to %g (xi0 %g): velocities outside [%g, %g], where their squares "
                               "over- or underflow; change the units (e.g. forces in units of their rms)",
                               fm, d->xi0, ODHS_VMIN, ODHS_VMAX);
    }
    return ODHS_OK;
}

/* ---- forces and velocities on the current network ---------------------- */
int odhs__st_solve(odhs_stepper *st, const double *b, double *x)
{
    int s = odhs__solver_solve(st->sol, st->net, b, x, 1);
    if (s) return odhs__sterr(st, s, "force solve: %s", odhs_solver_errmsg(st->sol));
    return ODHS_OK;
}

/* b = -S (V_aff + xi0 F) / xi0 on the current network (st->cb has room),
 * with the pressure part of V_aff left out (and, in a batched step's
 * contact problem, - gap / (bh xi0)) */
double odhs__st_affine_rate(const odhs_stepper *st, const double *G, size_t c)
{
    const odhs_network *net = st->net;
    int dim = st->dim;
    const double *n = net->nrm + c * dim;
    double v = 0.0;
    if (net->nwalls && net->cj[c] >= st->n) {
        /* wall: (S V_aff)_c + w_c = n.(v_wall - G x_i) */
        const odhs_wall *w = &net->walls[net->cj[c] - st->n];
        double gx[3];
        odhs__apply_G(G, dim, st->sys->x + net->ci[c] * dim, gx);
        for (int k = 0; k < dim; ++k) v += (w->v[k] - gx[k]) * n[k];
        return v;
    }
    double d[3] = {0, 0, 0}, gd[3];
    for (int k = 0; k < dim; ++k) d[k] = n[k] * net->dist[c];
    odhs__apply_G(G, dim, d, gd);
    for (int k = 0; k < dim; ++k) v += gd[k] * n[k];
    return v;
}

void odhs__st_affine_rhs(odhs_stepper *st, double *b)
{
    const odhs_network *net = st->net;
    const odhs_driver *drv = st->drv;
    int dim = st->dim;
    double xi0 = drv->xi0;
    double G0[9];
    memcpy(G0, st->G, sizeof G0);
    if (drv->pressure_on) {
        memset(G0, 0, sizeof G0);
        G0[3 * (0) + (1)] = odhs__st_shear_rate(st);
    }
    for (size_t c = 0; c < net->nc; ++c) {
        const double *n = net->nrm + c * dim;
        double v = odhs__st_affine_rate(st, G0, c);
        if (st->has_F && net->nwalls && net->cj[c] >= st->n) { /* S F = -n.F_i */
            for (int k = 0; k < dim; ++k) v -= xi0 * st->F[net->ci[c] * dim + k] * n[k];
        } else if (st->has_F) {
            const double *Fi = st->F + net->ci[c] * dim, *Fj = st->F + net->cj[c] * dim;
            for (int k = 0; k < dim; ++k) v += xi0 * (Fj[k] - Fi[k]) * n[k];
        }
        /* the batched step's contact problem (batched.c): the gap closes
         * over the step bh, gap rate -gap / bh instead of 0 */
        if (st->bh > 0.0) v += net->gap[c] / st->bh;
        b[c] = -v / xi0;
    }
}

/* Solve for the contact forces (into net->f) and kappa under pressure control. */
int odhs__st_compute_forces(odhs_stepper *st)
{
    odhs_network *net = st->net;
    odhs_driver *drv = st->drv;
    int s;
    st->pj_bordered = 0;
    if ((s = odhs__st_reserve_contacts(st, net->nc))) return odhs__sterr(st, s, "out of memory");
    if (drv->pressure_on) return odhs__st_pressure_forces(st);
    double gd = odhs__st_shear_rate(st);
    odhs__st_set_gradient(st, drv->crate);
    st->kappa = gd != 0.0 ? drv->crate / gd : drv->crate;
    /* a subnormal shear rate overflows the ratio (found by fuzzing the
     * checkpoint reader): report c as without shear, never inf */
    if (!isfinite(st->kappa)) st->kappa = drv->crate;
    if (net->nc == 0) return ODHS_OK;
    odhs__st_affine_rhs(st, st->cb);
    return odhs__st_solve(st, st->cb, net->f);
}

void odhs__st_compute_velocities(odhs_stepper *st)
{
    double xi0 = st->drv->xi0;
    /* bordered (pressure.c): S^T f = S^T freg + f_k res exactly, without the
     * cancellation of a huge f_k against the rest */
    odhs__net_ST(st->net, st->pj_bordered ? st->fpj + st->net->nc : st->net->f, st->U);
    if (st->pj_bordered)
        for (size_t k = 0; k < st->nd; ++k) st->U[k] += st->pj_alpha * st->pj_res[k];
    for (size_t k = 0; k < st->nd; ++k) st->U[k] = xi0 * (st->U[k] + (st->has_F ? st->F[k] : 0.0));
}

double odhs__st_velocity_scale(const odhs_stepper *st)
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
double odhs__st_pair_velocity(const odhs_stepper *st, size_t i, size_t j)
{
    int dim = st->dim;
    double d[3], gd[3];
    if (j >= st->n) { /* a wall: rate of the gap, n.(v_wall - V_i) */
        const odhs_wall *w = &st->net->walls[j - st->n];
        double nrm[3], gx[3], xi[3], v = 0.0;
        odhs__wall_geom(w, dim, st->sys->L, st->sys->gamma, st->sys->x + i * dim, nrm, xi);
        odhs__apply_G(st->G, dim, xi, gx);
        for (int k = 0; k < dim; ++k) v += nrm[k] * (w->v[k] - gx[k] - st->U[i * dim + k]);
        return v;
    }
    odhs__st_min_sep(st, i, j, d);
    odhs__apply_G(st->G, dim, d, gd);
    double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), v = 0.0;
    for (int k = 0; k < dim; ++k) v += (gd[k] + st->U[j * dim + k] - st->U[i * dim + k]) * d[k];
    return v / r;
}

void odhs__st_contact_geometry(odhs_stepper *st, size_t c)
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
    odhs__st_min_sep(st, net->ci[c], net->cj[c], d);
    double r = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    net->dist[c] = r;
    net->gap[c] = r - odhs__net_sigma(net, st->sys, c);
    for (int k = 0; k < dim; ++k) net->nrm[c * dim + k] = d[k] / r;
    net->version++;
}

/* ---- the stress before the step's events (odhs_stepper_pre_event_stress) --- */
/* The contact forces on the current network (the step's start network) at
 * the current configuration and time, solved as odhs__st_compute_forces
 * does at fixed volume but into the record's own arrays: the step's state
 * (forces, gradient, kappa) is untouched. A failed solve is recorded, not
 * returned: only running out of memory fails the step. */
int odhs__st_pre_event_record(odhs_stepper *st)
{
    odhs_network *net = st->net;
    if (st->drv->pressure_on) {
        st->pre_pend_state = ODHS__PRE_PRESSURE;
        return ODHS_OK;
    }
    if (odhs__reserve((void **)&st->pre_b, &st->pre_bcap, net->nc, sizeof *st->pre_b) ||
        odhs__reserve((void **)&st->pre_f, &st->pre_fcap, net->nc, sizeof *st->pre_f))
        return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    odhs__net_geometry(net, st->sys);
    int s = ODHS_OK;
    if (net->nc) {
        /* the flow at the end of the motion: its left limit in time (a
         * triangle wave reverses at the step's end) */
        double G[9];
        const int fe = st->flow_end;
        memcpy(G, st->G, sizeof G);
        st->flow_end = 1;
        odhs__st_set_gradient(st, st->drv->crate);
        odhs__st_affine_rhs(st, st->pre_b);
        st->flow_end = fe;
        memcpy(st->G, G, sizeof G);
        s = odhs__solver_solve(st->sol, net, st->pre_b, st->pre_f, 1);
    }
    if (s == ODHS_E_NOMEM) return odhs__sterr(st, s, "force solve: %s", odhs_solver_errmsg(st->sol));
    st->pre_pend_state = s ? ODHS__PRE_SOLVE : ODHS__PRE_OK;
    if (!s) odhs__st_stress_of(st, st->pre_f, st->pre_pend);
    return ODHS_OK;
}
