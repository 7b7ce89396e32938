/* libodhs - pressure control (Sect. II C of the paper): the forces and the
 * compression rate kappa at fixed pressure, on general and on isostatic
 * networks, and the drift correction of a flowing isostatic network. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

/* N x = rhs on an isostatic network, rhs orthogonal to its self-stress f0:
 * solved on the network without the contact k of largest |f0|, whose row of
 * S (and equation) follows from the others through f0; x[k] = 0. rhs and x
 * hold nc values (rhs is used as scratch); tol > 0: relaxed residual. */
int odhs__st_solve_isostatic(odhs_stepper *st, const double *f0, double *rhs, double *x, double tol)
{
    const odhs_network *net = st->net;
    size_t nc = net->nc, k = 0;
    for (size_t c = 1; c < nc; ++c)
        if (fabs(f0[c]) > fabs(f0[k])) k = c;
    memmove(rhs + k, rhs + k + 1, (nc - 1 - k) * sizeof *rhs);
    odhs_network *sub = odhs__net_subnet(net, NULL, nc, k);
    if (!sub) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    memset(x, 0, nc * sizeof *x);
    /* sub is a scratch network: never reuse a setup by its address (reuse 0) */
    int s = tol > 0.0 ? odhs__solver_solve_relaxed(st->sol, sub, rhs, x, tol, 0)
                      : odhs__solver_solve(st->sol, sub, rhs, x, 0);
    odhs_network_destroy(sub);
    if (s) return odhs__sterr(st, s, "force solve on the isostatic network: %s", odhs_solver_errmsg(st->sol));
    memmove(x + k + 1, x + k, (nc - 1 - k) * sizeof *x);
    x[k] = 0.0;
    return ODHS_OK;
}

/* f0 of the current (isostatic) network into st->fpj (room for 2 nc), kept
 * while the network's version is unchanged */
int odhs__st_isostatic_f0(odhs_stepper *st)
{
    odhs_network *net = st->net;
    if (st->fpj_version == net->version && st->fpjcap >= 2 * net->nc) return ODHS_OK;
    if (odhs__reserve((void **)&st->fpj, &st->fpjcap, 2 * net->nc, sizeof *st->fpj))
        return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    int s = odhs__null_vector(net, st->sol, st->fpj, NULL);
    if (s)
        return odhs__sterr(st, s == ODHS_E_NOMEM ? s : ODHS_POTENTIALLY_JAMMED, "isostatic network at t = %.17g: %s",
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
static int pressure_isostatic_forces(odhs_stepper *st, const double *b, double gdot)
{
    odhs_network *net = st->net;
    odhs_driver *drv = st->drv;
    size_t nc = net->nc;
    int s;
    if ((s = odhs__st_isostatic_f0(st))) return s;
    double *f0 = st->fpj, *freg = st->fpj + nc, *rhs = st->cx;
    double fb = 0.0, fr = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        fb += f0[c] * b[c];
        fr += f0[c] * net->dist[c];
    }
    if (!(fabs(fr) > 0.0))
        return odhs__sterr(st, ODHS_E_SINGULAR, "fixed pressure, isostatic network: the self-stress carries no pressure");
    double a = -fb / fr;
    for (size_t c = 0; c < nc; ++c) rhs[c] = b[c] + a * net->dist[c];
    if ((s = odhs__st_solve_isostatic(st, f0, rhs, freg, 0.0))) return s;
    double vol, rf = 0.0;
    odhs_system_volume(st->sys, &vol);
    for (size_t c = 0; c < nc; ++c) rf += net->dist[c] * freg[c];
    double alpha = (drv->p * vol * st->dim - rf) / fr;
    for (size_t c = 0; c < nc; ++c) net->f[c] = freg[c] + alpha * f0[c];
    st->kappa = a * drv->xi0 / gdot;
    odhs__st_set_gradient(st, gdot * st->kappa);
    st->pj_bordered = 1;
    return ODHS_OK;
}

/* ---- drift correction (Sect. IV C) ------------------------------------- */
/* Fixed pressure: f = x2 + (gdot kappa / xi0) x1 with N x2 = b, N x1 = r,
 * kappa from the pressure (eq. 25); on an isostatic network see
 * pressure_isostatic_forces. Forces into net->f, kappa and G set. */
int odhs__st_pressure_forces(odhs_stepper *st)
{
    odhs_network *net = st->net;
    odhs_driver *drv = st->drv;
    size_t nc = net->nc;
    int dim = st->dim, s;
    double xi0 = drv->xi0, gd = odhs__st_shear_rate(st);
    if (nc == 0) {
        st->kappa = drv->kappa_max * (gd > 0 ? 1.0 : -1.0);
        odhs__st_set_gradient(st, gd * st->kappa);
        return ODHS_OK;
    }
    double *b = st->cb;
    odhs__st_affine_rhs(st, b);
    st->work_pressure++;
    long excess;
    if ((s = odhs__net_excess(net, &excess))) return odhs__sterr(st, s, "%s", net->errmsg);
    if (excess == 1) return pressure_isostatic_forces(st, b, gd);
    double *x1 = st->cx;
    if ((s = odhs__st_solve(st, b, net->f))) return s;
    memset(x1, 0, nc * sizeof *x1);
    if ((s = odhs__st_solve(st, net->dist, x1))) return s;
    double rx1 = 0.0, rx2 = 0.0, vol;
    for (size_t c = 0; c < nc; ++c) {
        rx1 += net->dist[c] * x1[c];
        rx2 += net->dist[c] * net->f[c];
    }
    odhs_system_volume(st->sys, &vol);
    double kappa;
    if (rx1 > 0.0) kappa = xi0 * (drv->p * vol * dim - rx2) / (gd * rx1);
    else kappa = drv->kappa_max * (gd > 0 ? 1.0 : -1.0);
    if (!isfinite(kappa) || kappa > drv->kappa_max) kappa = drv->kappa_max;
    if (kappa < -drv->kappa_max) kappa = -drv->kappa_max;
    st->kappa = kappa;
    double a = gd * kappa / xi0;
    for (size_t c = 0; c < nc; ++c) net->f[c] += a * x1[c];
    odhs__st_set_gradient(st, gd * kappa);
    return ODHS_OK;
}

/* Fixed pressure, one contact more than isostatic: the forces diverge along
 * the self-stress fs at zero pressure, with the sign that resists the
 * driving (<fs|b> > 0); its most negative contact opens (fs has both signs,
 * since <fs|r> = 0). fs into net->f. */
int odhs__st_pressure_open_direction(odhs_stepper *st)
{
    odhs_network *net = st->net;
    int s;
    st->work_pressure++;
    if ((s = odhs__st_reserve_contacts(st, net->nc))) return odhs__sterr(st, s, "out of memory");
    odhs__st_affine_rhs(st, st->cb);
    if ((s = odhs__null_vector_volume(net, net->f)))
        return odhs__sterr(st, s == ODHS_E_NOMEM ? s : ODHS_POTENTIALLY_JAMMED, "fixed pressure at t = %.17g: %s",
                     st->time, net->errmsg);
    double fb = 0.0, fmin = 0.0;
    for (size_t c = 0; c < net->nc; ++c) fb += net->f[c] * st->cb[c];
    for (size_t c = 0; c < net->nc; ++c) {
        if (fb < 0.0) net->f[c] = -net->f[c];
        if (odhs__can_open(net->kind[c])) fmin = fmin < net->f[c] ? fmin : net->f[c];
    }
    if (!(fmin < -EPS_F))
        return odhs__sterr(st, ODHS_POTENTIALLY_JAMMED,
                     "fixed pressure at t = %.17g: the self-stress at zero pressure opens no contact", st->time);
    return ODHS_OK;
}

/* Drift correction of an isostatic network under fixed pressure (see
 * correct): fills Z with the isotropic gradient and st->cx with the
 * correction's contact forces (zero on contact k). */
int odhs__st_correct_isostatic(odhs_stepper *st, double *Z)
{
    odhs_network *net = st->net;
    size_t nc = net->nc;
    int s;
    st->work_pressure++;
    if ((s = odhs__st_isostatic_f0(st))) return s;
    double *f0 = st->fpj, *rhs = st->fpj + nc;
    double fg = 0.0, fr = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        fg += f0[c] * net->gap[c];
        fr += f0[c] * net->dist[c];
    }
    double eps = fr != 0.0 ? fg / fr : 0.0;
    for (int a = 0; a < st->dim; ++a) Z[3 * a + a] = -eps;
    for (size_t c = 0; c < nc; ++c) rhs[c] = net->gap[c] - eps * net->dist[c];
    return odhs__st_solve_isostatic(st, f0, rhs, st->cx, 1e-7);
}
