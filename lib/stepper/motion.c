/* libodhs - moving along a chord: positions, box and walls. */
#include <math.h>
#include <string.h>

#include "stepper/stepper.h"

/* move by t along (G, vel), deforming the box with G; walls translate with
 * their velocities when moving != 0 */
void odhs__st_advance_walls(odhs_stepper *st, double t)
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

void odhs__st_advance(odhs_stepper *st, const double *G, const double *vel, double t)
{
    odhs_system *s = st->sys;
    int dim = st->dim;
    for (size_t i = 0; i < st->n; ++i) {
        double *x = s->x + i * dim, gx[3];
        odhs__apply_G(G, dim, x, gx);
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
