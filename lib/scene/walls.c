/* libodhs - hard walls: planes, spherical containers and 2D segments, entered
 * into the contact network as one-sided contacts (walls.h). */
#include <math.h>
#include <string.h>

#include "stepper/stepper.h"

static int finite_vec(const double *v, int dim)
{
    for (int k = 0; k < dim; ++k)
        if (!isfinite(v[k])) return 0;
    return 1;
}

/* check that no particle overlaps w, then add it */
static int add_wall(odhs_stepper *st, odhs_wall *w, size_t *id)
{
    const odhs_system *sys = st->sys;
    int dim = st->dim;
    double worst = 0.0;
    size_t wi = SIZE_MAX;
    for (size_t i = 0; i < st->n; ++i) {
        double nrm[3];
        double g = odhs__wall_geom(w, dim, sys->L, sys->gamma, sys->x + i * dim, nrm, NULL) - sys->r[i];
        if (g < -1e-9 * sys->r[i] && -g > worst) {
            worst = -g;
            wi = i;
        }
    }
    if (wi != SIZE_MAX)
        return odhs__sterr(st, ODHS_E_OVERLAP, "particle %zu overlaps the new wall by %.6g", wi, worst);
    if (odhs__net_add_wall(st->net, w)) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    if (id) *id = st->net->nwalls - 1;
    st->ready = 0; /* the next step (or reset) finds the wall contacts and re-solves */
    return ODHS_OK;
}

int odhs_stepper_add_wall_plane(odhs_stepper *st, const double *normal, double offset, size_t *id)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!normal) return odhs__sterr(st, ODHS_E_NULL, "normal is NULL");
    int dim = st->dim;
    if (!finite_vec(normal, dim) || !isfinite(offset)) return odhs__sterr(st, ODHS_E_NONFINITE, "wall plane is not finite");
    double nn = 0.0;
    for (int k = 0; k < dim; ++k) nn += normal[k] * normal[k];
    nn = sqrt(nn);
    if (!(nn > 0.0) || !isfinite(nn)) return odhs__sterr(st, ODHS_E_INVALID, "the plane's normal is zero");
    odhs_wall w;
    memset(&w, 0, sizeof w);
    w.type = ODHS_WALL_PLANE;
    for (int k = 0; k < dim; ++k) w.n[k] = normal[k] / nn;
    w.h = offset / nn;
    return add_wall(st, &w, id);
}

int odhs_stepper_add_wall_sphere(odhs_stepper *st, const double *centre, double radius, size_t *id)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!centre) return odhs__sterr(st, ODHS_E_NULL, "centre is NULL");
    int dim = st->dim;
    if (!finite_vec(centre, dim) || !isfinite(radius)) return odhs__sterr(st, ODHS_E_NONFINITE, "wall sphere is not finite");
    if (!(radius > 0.0)) return odhs__sterr(st, ODHS_E_INVALID, "radius %g must be > 0", radius);
    odhs_wall w;
    memset(&w, 0, sizeof w);
    w.type = ODHS_WALL_SPHERE;
    for (int k = 0; k < dim; ++k) w.c[k] = centre[k];
    w.R = radius;
    return add_wall(st, &w, id);
}

int odhs_stepper_add_wall_segment(odhs_stepper *st, const double *a, const double *b, size_t *id)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!a || !b) return odhs__sterr(st, ODHS_E_NULL, "segment end is NULL");
    if (st->dim != 2) return odhs__sterr(st, ODHS_E_DIM, "segment walls are 2D only");
    if (!finite_vec(a, 2) || !finite_vec(b, 2)) return odhs__sterr(st, ODHS_E_NONFINITE, "segment is not finite");
    double l = hypot(b[0] - a[0], b[1] - a[1]);
    if (!(l > 0.0)) return odhs__sterr(st, ODHS_E_INVALID, "the segment's ends coincide");
    odhs_wall w;
    memset(&w, 0, sizeof w);
    w.type = ODHS_WALL_SEGMENT;
    w.c[0] = a[0];
    w.c[1] = a[1];
    w.b[0] = b[0];
    w.b[1] = b[1];
    w.n[0] = -(b[1] - a[1]) / l; /* normal of the line (for the zero-mode count) */
    w.n[1] = (b[0] - a[0]) / l;
    return add_wall(st, &w, id);
}

static int check_id(const odhs_stepper *st, size_t id)
{
    if (id >= st->net->nwalls)
        return odhs__sterr(st, ODHS_E_RANGE, "wall %zu does not exist (%zu walls)", id, st->net->nwalls);
    return ODHS_OK;
}

int odhs_stepper_set_wall_velocity(odhs_stepper *st, size_t id, const double *v)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    int s = check_id(st, id);
    if (s) return s;
    if (!v) return odhs__sterr(st, ODHS_E_NULL, "velocity is NULL");
    if (!finite_vec(v, st->dim)) return odhs__sterr(st, ODHS_E_NONFINITE, "wall velocity is not finite");
    odhs_wall *w = &st->net->walls[id];
    for (int k = 0; k < st->dim; ++k) w->v[k] = v[k];
    /* the forces depend on the wall velocity: re-solve before the next step,
     * keeping the network (like a change of the driver) */
    st->drv_version = st->drv->version - 1;
    return ODHS_OK;
}

int odhs_stepper_wall_count(const odhs_stepper *st, size_t *count)
{
    if (!st) return ODHS_E_NULL;
    if (!count) return odhs__sterr(st, ODHS_E_NULL, "output pointer is NULL");
    *count = st->net->nwalls;
    return ODHS_OK;
}

int odhs_stepper_wall_force(const odhs_stepper *st, size_t id, double *force)
{
    if (!st) return ODHS_E_NULL;
    if (!force) return odhs__sterr(st, ODHS_E_NULL, "output pointer is NULL");
    int s = check_id(st, id);
    if (s) return s;
    const odhs_network *net = st->net;
    int dim = st->dim;
    for (int k = 0; k < dim; ++k) force[k] = 0.0;
    for (size_t c = 0; c < net->nc; ++c)
        if (net->cj[c] == st->n + id)
            for (int k = 0; k < dim; ++k) force[k] += net->f[c] * net->nrm[c * dim + k];
    return ODHS_OK;
}

int odhs_stepper_wall_displacement(const odhs_stepper *st, size_t id, double *disp)
{
    if (!st) return ODHS_E_NULL;
    if (!disp) return odhs__sterr(st, ODHS_E_NULL, "output pointer is NULL");
    int s = check_id(st, id);
    if (s) return s;
    for (int k = 0; k < st->dim; ++k) disp[k] = st->net->walls[id].disp[k];
    return ODHS_OK;
}
