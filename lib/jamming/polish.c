/* libodhs - jamming: polishing a jammed packing to round-off and the pair
 * self-stress of the final pivots (Sect. IV D of Lerner, During & Wyart 2013). */
#include <math.h>
#include <string.h>

#include "jamming/jamming.h"

/* ---- polishing a jammed packing ------------------------------------------ */
/* Contact gaps to round-off on an isostatic network with self-stress f0: the
 * gap component along f0 cannot be removed by moving particles (S dR is
 * orthogonal to f0), but an isotropic rescaling changes every gap by -eps*r:
 * eps = <f0|gap>/<f0|r>. The remaining gaps are in the range of S and are
 * removed by dR = -S'^T N'^-1 gap' on the network without one contact k
 * (f0_k != 0): the rows of S are dependent only through f0, so row k follows. */
int odhs__jam_polish(odhs_system *sys, odhs_network *net, odhs_solver *sol, const double *f0)
{
    int d = net->dim, st = ODHS_OK;
    size_t nc = net->nc, nd = net->n * (size_t)d;
    if (nc == 0) return ODHS_OK;
    size_t k = 0;
    for (size_t c = 1; c < nc; ++c)
        if (fabs(f0[c]) > fabs(f0[k])) k = c;
    odhs_network *sub = odhs__net_subnet(net, NULL, nc, k);
    double *y = odhs__calloc(nc, sizeof *y), *dR = odhs__calloc(nd, sizeof *dR);
    if (!sub || !y || !dR) {
        st = ODHS_E_NOMEM;
        goto done;
    }
    double prev = INFINITY;
    for (int pass = 0; pass < 12; ++pass) {
        odhs__net_geometry(net, sys);
        double gmax = 0.0, fg = 0.0, fr = 0.0;
        for (size_t c = 0; c < nc; ++c) {
            gmax = fmax(gmax, fabs(net->gap[c]) / odhs__net_sigma(net, sys, c));
            fg += f0[c] * net->gap[c];
            fr += f0[c] * net->dist[c];
        }
        if (gmax <= 2e-16 || !(gmax < 0.5 * prev)) break;
        prev = gmax;
        /* affine part: rescale box and positions about the origin (not
         * with walls, which do not scale: that gap component then stays) */
        double s = net->nwalls ? 1.0 : 1.0 - fg / fr;
        for (int a = 0; a < d; ++a) sys->L[a] *= s;
        for (size_t q = 0; q < nd; ++q) sys->x[q] *= s;
        odhs__net_geometry(net, sys);
        /* non-affine part on the reduced network */
        odhs__net_geometry(sub, sys);
        double *gap = odhs__malloc_array(sub->nc ? sub->nc : 1, sizeof *gap);
        if (!gap) {
            st = ODHS_E_NOMEM;
            goto done;
        }
        /* the target is the gaps without their f0 component, which no
         * displacement changes (<f0|S dR> = 0): the reduced network would
         * put it all on contact k. What the rescaling leaves of it is the
         * round-off of every rescaled position, summed (1e-12 at 2D
         * N = 4096, which made contact k's gap 1.7e-13); left in place, it
         * is shared by every contact in proportion to f0 */
        double ff = 0.0, fg2 = 0.0;
        for (size_t c = 0; c < nc; ++c) {
            ff += f0[c] * f0[c];
            fg2 += f0[c] * net->gap[c];
        }
        for (size_t c = 0, q = 0; c < nc; ++c)
            if (c != k) gap[q++] = net->gap[c] - (ff > 0.0 ? f0[c] * fg2 / ff : 0.0);
        memset(y, 0, nc * sizeof *y);
        st = odhs_solver_solve(sol, sub, gap, y);
        odhs__free(gap);
        if (st) goto done;
        odhs__net_ST(sub, y, dR);
        for (size_t q = 0; q < nd; ++q) sys->x[q] -= dR[q];
        for (size_t i = 0; i < net->n; ++i) odhs__wrap(d, sys->L, sys->gamma, sys->x + i * d);
    }
    odhs__net_geometry(net, sys);
done:
    odhs_network_destroy(sub);
    odhs__free(y);
    odhs__free(dR);
    return st;
}

/* The pivot that takes a pair p = (i, j) outside an isostatic network C
 * (self-stress f0, <f0|r> != 0) into it: the self-stress h of C + p with
 * h_p = 1 and <h|r> = 0 (r: contact distances, the response of the gaps to
 * an isotropic compression), h on C returned in h[0..nc-1]: h_C solves
 * S_C'^T h = -s_p^T on C' = C without its contact of largest |f0| (full
 * column rank), plus the multiple of f0 that sets <h|r> + r_p = 0. On C's
 * constrained subset S_C^T has the range of every balanced force; a rattler
 * in p needs d independent contacts of its own. ODHS_E_SINGULAR when the
 * balance is not exact (h does not exist). nrm is the unit vector from i to
 * j, dist |R_ij|. */
int odhs__jam_pair_stress(const odhs_network *net, odhs_solver *sol, const double *f0, size_t i, size_t j,
                          const double *nrm, double dist, double *h)
{
    int d = net->dim, st = ODHS_OK;
    size_t nc = net->nc, nd = net->n * (size_t)d, k0 = 0;
    if (nc < 2) return ODHS_E_STATE;
    for (size_t c = 1; c < nc; ++c)
        if (fabs(f0[c]) > fabs(f0[k0])) k0 = c;
    odhs_network *sub = odhs__net_subnet(net, NULL, nc, k0);
    double *g = odhs__calloc(nd, sizeof *g), *x = odhs__calloc(nc, sizeof *x), *F = odhs__calloc(nd, sizeof *F);
    if (!sub || !g || !x || !F) {
        st = ODHS_E_NOMEM;
        goto done;
    }
    double gn = 0.0;
    for (int a = 0; a < d; ++a) {
        g[i * d + a] = nrm[a];
        g[j * d + a] = -nrm[a];
        gn += nrm[a] * nrm[a];
    }
    if ((st = odhs_solver_solve_ls(sol, sub, g, x))) goto done;
    for (size_t c = 0, q = 0; c < nc; ++c) h[c] = c == k0 ? 0.0 : x[q++];
    /* accept only an exact balance: S_C^T h = -s_p^T */
    odhs__net_ST(net, h, F);
    double res = 0.0, hmax = 1.0;
    for (size_t q = 0; q < nd; ++q) res = fmax(res, fabs(F[q] - g[q]));
    for (size_t c = 0; c < nc; ++c) hmax = fmax(hmax, fabs(h[c]));
    if (!(res <= 1e-9 * hmax * sqrt(gn))) {
        st = ODHS_E_SINGULAR;
        goto done;
    }
    double hr = dist, fr = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        hr += h[c] * net->dist[c];
        fr += f0[c] * net->dist[c];
    }
    if (!(fabs(fr) > 0.0)) {
        st = ODHS_E_SINGULAR;
        goto done;
    }
    for (size_t c = 0; c < nc; ++c) h[c] -= hr / fr * f0[c];
done:
    odhs_network_destroy(sub);
    odhs__free(g);
    odhs__free(x);
    odhs__free(F);
    return st;
}
