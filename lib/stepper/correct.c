/* libodhs - drift correction (Sect. IV C of the paper). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

int odhs__st_correct(odhs_stepper *st, int *added)
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
        if ((s = odhs__st_reserve_contacts(st, nc))) return odhs__sterr(st, s, "out of memory");
        double gmax = 0.0;
        for (size_t c = 0; c < nc; ++c)
            gmax = fmax(gmax, fabs(net->gap[c]) / odhs__net_sigma(net, sys, c));
        if (gmax <= 4e-16) return ODHS_OK;            /* at round-off */
        if (!(gmax < 0.5 * prev)) return ODHS_OK;     /* no further progress */
        long excess;
        if ((s = odhs__net_excess(net, &excess))) return odhs__sterr(st, s, "%s", net->errmsg);
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
            s = odhs__st_correct_isostatic(st, Z);
        } else {
            /* the gaps are small: a relative residual of 1e-7 removes them to
             * round-off in one pass (a further pass follows if not) */
            s = odhs__solver_solve_relaxed(st->sol, net, net->gap, st->cx, 1e-7, 1);
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
        size_t pi, pj;
        double t = odhs__st_predict(st, Z, st->tmp, 1.0, 0.0, 0, 0, &pi, &pj);
        odhs__st_advance(st, Z, st->tmp, t);
        if (pi != SIZE_MAX) {
            size_t c;
            if ((s = odhs__st_add_contact(st, pi, pj, &c))) return s;
            *added = 1;
            prev = INFINITY; /* new contact: a new problem */
        }
    }
    odhs__net_geometry(net, sys);
    return ODHS_OK;
}
