/*
 * libodhs private header: box geometry (wrap, minimum image, Lees-Edwards remapping), hard-wall
 * geometry and the cell search.
 * Not installed.
 */
#ifndef ODHS_GEOM_GEOM_H
#define ODHS_GEOM_GEOM_H

#include "base/base.h"

/* Lees-Edwards remapping: replace b by b -/+ a until |gamma*Ly| <= Lx/2; the
 * lattice (and so the physical configuration) is unchanged. */
static inline double odhs__remap_strain(double gamma, const double *L)
{
    double u = L[0] / L[1];
    double g = gamma - nearbyint(gamma / u) * u;
    /* gamma / u beyond 2^53 (a box of aspect ratio 1e-78 sheared by 5e-23:
     * fuzz_checkpoint): the product above cancels to a multiple of ulp(gamma)
     * far outside the range. fmod is exact, and so is the shift by u after
     * it; only then, so that every other remap stays bit for bit. */
    if (!(fabs(g) <= u)) g = fmod(gamma, u);
    /* rounding can leave |g| a hair above u/2 */
    if (g > 0.5 * u) g -= u;
    else if (g < -0.5 * u) g += u;
    return g;
}

/* Wrap one position (dim entries) into the primary lab rectangle, given box
 * and strain. A position already inside is left untouched bit for bit. */
void odhs__wrap(int dim, const double *L, double gamma, double *x);
/* Minimum image of a raw difference d (in place). image (may be NULL)
 * receives the lattice shift that was ADDED, i.e. d_new = d + n0 a + n1 b + n2 c. */
void odhs__min_image(int dim, const double *L, double gamma, double *d, int *image);

/* ---- cell lists -------------------------------------------------------- */
/* Enumerate pairs with centre distance < rcut_pair(i,j) = r_i + r_j + max_gap.
 * Works on raw arrays so the stepper can use it with its own state. */
int odhs__pairs(int dim, size_t n, const double *x, const double *r, double rmax,
                const double *L, double gamma, double max_gap, odhs_pair_fn fn, void *ctx);
/* The same pairs collected into the growable arrays *pi, *pj (capacity *cap,
 * count *np; a Verlet list: the stepper's and the soft-core models'). Arrays
 * keep what they held on error. ODHS_OK or ODHS_E_NOMEM. */
int odhs__pair_list(int dim, size_t n, const double *x, const double *r, double rmax, const double *L, double gamma,
                    double max_gap, size_t **pi, size_t **pj, size_t *np, size_t *cap);

/* ---- hard walls ------------------------------------------------------------ */
typedef struct {
    int type;     /* ODHS_WALL_* */
    double n[3];  /* plane: unit normal into the allowed side; segment: unit normal of the line */
    double h;     /* plane: particles where n.x >= h */
    double c[3];  /* sphere: centre; segment: end a */
    double b[3];  /* segment: end b */
    double R;     /* sphere: radius (particles inside) */
    double v[3];  /* velocity (translation) */
    double disp[3]; /* displacement since creation */
} odhs_wall;

/* Distance from a particle centre x to the wall surface (positive on the
 * allowed side) and the unit contact normal nrm from the particle towards
 * the wall. Walls are not periodic: for a sphere or a segment the particle
 * is taken at its periodic image nearest to the centre or the middle, so a
 * particle touching it may cross the box boundary; a plane sees the position
 * in the primary cell. The position used goes to ximg when not NULL. */
static inline double odhs__wall_geom(const odhs_wall *w, int dim, const double *L, double gamma, const double *x0,
                                     double *nrm, double *ximg)
{
    double ref[3] = {0, 0, 0}, x[3] = {0, 0, 0};
    for (int k = 0; k < dim; ++k) x[k] = x0[k];
    if (w->type != ODHS_WALL_PLANE) { /* a plane is unbounded: the primary cell's position */
        for (int k = 0; k < dim; ++k) {
            ref[k] = w->type == ODHS_WALL_SPHERE ? w->c[k] : 0.5 * (w->c[k] + w->b[k]);
            x[k] = x0[k] - ref[k];
        }
        odhs__min_image(dim, L, gamma, x, NULL);
        for (int k = 0; k < dim; ++k) x[k] += ref[k];
    }
    if (ximg)
        for (int k = 0; k < dim; ++k) ximg[k] = x[k];
    if (w->type == ODHS_WALL_PLANE) {
        double s = -w->h;
        for (int k = 0; k < dim; ++k) {
            s += w->n[k] * x[k];
            nrm[k] = -w->n[k];
        }
        return s;
    }
    double p[3] = {0, 0, 0};
    if (w->type == ODHS_WALL_SPHERE) {
        double r2 = 0.0;
        for (int k = 0; k < dim; ++k) {
            p[k] = x[k] - w->c[k];
            r2 += p[k] * p[k];
        }
        double r = sqrt(r2);
        for (int k = 0; k < dim; ++k) nrm[k] = r > 0.0 ? p[k] / r : (k == 0 ? 1.0 : 0.0);
        return w->R - r;
    }
    /* segment: closest point q = a + t (b - a), t in [0,1] */
    double ab[3] = {0, 0, 0}, ax[3] = {0, 0, 0}, l2 = 0.0, t = 0.0;
    for (int k = 0; k < dim; ++k) {
        ab[k] = w->b[k] - w->c[k];
        ax[k] = x[k] - w->c[k];
        l2 += ab[k] * ab[k];
        t += ab[k] * ax[k];
    }
    t = l2 > 0.0 ? t / l2 : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    double r2 = 0.0;
    for (int k = 0; k < dim; ++k) {
        p[k] = w->c[k] + t * ab[k] - x[k];
        r2 += p[k] * p[k];
    }
    double r = sqrt(r2);
    for (int k = 0; k < dim; ++k) nrm[k] = r > 0.0 ? p[k] / r : 0.0;
    return r;
}

/* ---- contact network ----------------------------------------------------- */

/* G d: the affine relative velocity of a separation d under the velocity
 * gradient G (row-major 3x3) */
static inline void odhs__apply_G(const double *G, int dim, const double *d, double *out)
{
    for (int a = 0; a < dim; ++a) {
        double s = 0.0;
        for (int b = 0; b < dim; ++b) s += G[3 * (a) + (b)] * d[b];
        out[a] = s;
    }
}

#endif /* ODHS_GEOM_GEOM_H */
