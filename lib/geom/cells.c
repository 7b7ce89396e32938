/* libodhs - O(N) pair enumeration with cell lists, valid under Lees-Edwards
 * strain (|gamma| <= 1/2), box scaling and any polydispersity.
 *
 * Cells live in the sheared coordinates x' = x - gamma*y (a rectangular torus),
 * so the grid never needs shifting across the sheared boundary. A lab-frame
 * separation with |dx|,|dy| <= rc has |dx'| <= rc (1 + |gamma|), so cells of
 * width >= rc (1 + |gamma|) in x' and >= rc in y, z see all neighbours within
 * one cell. */
#include <math.h>
#include <string.h>

#include "geom/geom.h"

/* a residual x still >= L after the subtraction of floor(x/L) L and one
 * more L, or below -L: the coordinate was many box lengths out (an extreme
 * box or a wild step; fuzz_checkpoint, finding 14), where that product is
 * rounded. The exact remainder fmod puts it in [0, L); returns the image
 * count removed. Never taken for a coordinate a few box lengths out, whose
 * arithmetic (and bits) stay as they were, nor for a box edge that is not
 * positive (a trial motion can scale the box through zero; the step is then
 * refused by its caller, and the old arithmetic must stay: 0.2.13's first
 * version broke a fixed-pressure run of the Python tests there). */
static double wrap_far(double *x, double L)
{
    double r = fmod(*x, L);
    if (r < 0.0) r += L;
    if (r >= L) r = 0.0;
    double m = (*x - r) / L;
    *x = r;
    return m;
}

void odhs__wrap(int dim, const double *L, double gamma, double *x)
{
    if (x[1] < 0.0 || x[1] >= L[1]) {
        double ny = floor(x[1] / L[1]);
        x[1] -= ny * L[1];
        x[0] -= ny * gamma * L[1];
        if (x[1] >= L[1]) { /* rounding of a tiny negative y */
            x[1] -= L[1];
            x[0] -= gamma * L[1];
        }
        if (L[1] > 0.0 && (x[1] >= L[1] || x[1] < -L[1])) x[0] -= wrap_far(&x[1], L[1]) * gamma * L[1];
        if (x[1] < 0.0) x[1] = 0.0;
    }
    for (int k = 0; k < dim; k += (k == 0 ? 2 : 1)) { /* k = 0, then 2 */
        if (x[k] < 0.0 || x[k] >= L[k]) {
            double m = floor(x[k] / L[k]);
            x[k] -= m * L[k];
            if (x[k] >= L[k]) x[k] -= L[k];
            if (L[k] > 0.0 && (x[k] >= L[k] || x[k] < -L[k])) wrap_far(&x[k], L[k]);
            if (x[k] < 0.0) x[k] = 0.0;
        }
    }
}

void odhs__min_image(int dim, const double *L, double gamma, double *d, int *image)
{
    double ny = nearbyint(d[1] / L[1]);
    d[1] -= ny * L[1];
    d[0] -= ny * gamma * L[1];
    double nz = 0.0;
    if (dim == 3) {
        nz = nearbyint(d[2] / L[2]);
        d[2] -= nz * L[2];
    }
    double nx = nearbyint(d[0] / L[0]);
    d[0] -= nx * L[0];
    if (image) {
        image[0] = -(int)nx;
        image[1] = -(int)ny;
        image[2] = -(int)nz;
    }
}

/* offsets to visit in one direction with nc cells: each neighbour cell once */
static int stencil(int nc, int *off)
{
    if (nc >= 3) {
        off[0] = -1; off[1] = 0; off[2] = 1;
        return 3;
    }
    if (nc == 2) {
        off[0] = 0; off[1] = 1;
        return 2;
    }
    off[0] = 0;
    return 1;
}

/* cell counts nc[] and widths w[]: cells at least rc (1 + |gamma|) wide in
 * x' and rc in y, z, O(N) of them; returns the number of cells */
static size_t cell_grid(int dim, size_t n, const double *L, double gamma, double rc, int *nc, double *w)
{
    double ext[3] = {rc * (1.0 + fabs(gamma)), rc, rc};
    for (int k = 0; k < dim; ++k) {
        double m = floor(L[k] / ext[k]);
        if (m > 1e6) m = 1e6;
        nc[k] = m < 1.0 ? 1 : (int)m;
    }
    /* keep the number of cells O(N): coarsen uniformly when the box is huge */
    double total = (double)nc[0] * nc[1] * nc[2];
    double cap = 2.0 * (double)n + 8.0;
    while (total > cap) {
        for (int k = 0; k < dim; ++k) nc[k] = nc[k] > 1 ? (nc[k] + 1) / 2 : 1;
        total = (double)nc[0] * nc[1] * nc[2];
    }
    for (int k = 0; k < dim; ++k) w[k] = L[k] / nc[k];
    return (size_t)nc[0] * nc[1] * nc[2];
}

/* counting sort of the particles by cell: cell c holds order[start[c]] to
 * order[start[c + 1] - 1]; start[] comes zeroed */
static int bin_particles(int dim, size_t n, const double *x, const double *L, double gamma, const int *nc,
                         const double *w, size_t ncell, size_t *cell, size_t *start, size_t *order)
{
    for (size_t i = 0; i < n; ++i) {
        const double *xi = x + i * dim;
        double xs = xi[0] - gamma * xi[1];
        xs -= floor(xs / L[0]) * L[0];
        int c[3] = {0, 0, 0};
        double pos[3] = {xs, xi[1], dim == 3 ? xi[2] : 0.0};
        for (int k = 0; k < dim; ++k) {
            int ck = (int)floor(pos[k] / w[k]);
            if (ck < 0) ck = 0;
            if (ck >= nc[k]) ck = nc[k] - 1;
            c[k] = ck;
        }
        cell[i] = ((size_t)c[2] * nc[1] + c[1]) * nc[0] + c[0];
        start[cell[i] + 1]++;
    }
    for (size_t c = 0; c < ncell; ++c) start[c + 1] += start[c];
    size_t *fill = odhs__malloc_array(ncell, sizeof *fill);
    if (!fill) return ODHS_E_NOMEM;
    memcpy(fill, start, ncell * sizeof *fill);
    for (size_t i = 0; i < n; ++i) order[fill[cell[i]]++] = i;
    odhs__free(fill);
    return ODHS_OK;
}

int odhs__pairs(int dim, size_t n, const double *x, const double *r, double rmax,
                const double *L, double gamma, double max_gap, odhs_pair_fn fn, void *ctx)
{
    if (n < 2) return ODHS_OK;
    double rc = 2.0 * rmax + max_gap;
    if (!(rc > 0.0)) rc = 1e-300;
    int nc[3] = {1, 1, 1};
    double w[3];
    size_t ncell = cell_grid(dim, n, L, gamma, rc, nc, w);

    size_t *cell = odhs__malloc_array(n, sizeof *cell);
    size_t *start = odhs__calloc(ncell + 1, sizeof *start);
    size_t *order = odhs__malloc_array(n, sizeof *order);
    if (!cell || !start || !order || bin_particles(dim, n, x, L, gamma, nc, w, ncell, cell, start, order)) {
        odhs__free(cell);
        odhs__free(start);
        odhs__free(order);
        return ODHS_E_NOMEM;
    }

    int off[3][3], noff[3] = {1, 1, 1};
    off[2][0] = 0;
    for (int k = 0; k < dim; ++k) noff[k] = stencil(nc[k], off[k]);

    int status = ODHS_OK;
    for (int cz = 0; cz < nc[2] && status == ODHS_OK; ++cz)
        for (int cy = 0; cy < nc[1] && status == ODHS_OK; ++cy)
            for (int cx = 0; cx < nc[0] && status == ODHS_OK; ++cx) {
                size_t c0 = ((size_t)cz * nc[1] + cy) * nc[0] + cx;
                for (int a = 0; a < noff[2] && status == ODHS_OK; ++a)
                    for (int b = 0; b < noff[1] && status == ODHS_OK; ++b)
                        for (int e = 0; e < noff[0] && status == ODHS_OK; ++e) {
                            int ox = (cx + off[0][e] + nc[0]) % nc[0];
                            int oy = (cy + off[1][b] + nc[1]) % nc[1];
                            int oz = (cz + off[2][a] + nc[2]) % nc[2];
                            size_t c1 = ((size_t)oz * nc[1] + oy) * nc[0] + ox;
                            for (size_t p = start[c0]; p < start[c0 + 1] && status == ODHS_OK; ++p) {
                                size_t i = order[p];
                                for (size_t q = start[c1]; q < start[c1 + 1]; ++q) {
                                    size_t j = order[q];
                                    if (j <= i) continue;
                                    double d[3] = {0, 0, 0};
                                    for (int k = 0; k < dim; ++k) d[k] = x[j * dim + k] - x[i * dim + k];
                                    odhs__min_image(dim, L, gamma, d, NULL);
                                    double s2 = 0.0;
                                    for (int k = 0; k < dim; ++k) s2 += d[k] * d[k];
                                    double cut = r[i] + r[j] + max_gap;
                                    if (s2 <= cut * cut) {
                                        double gap = sqrt(s2) - (r[i] + r[j]);
                                        if (gap <= max_gap && fn(i, j, d, gap, ctx)) {
                                            status = ODHS_STOPPED;
                                            break;
                                        }
                                    }
                                }
                            }
                        }
            }
    odhs__free(cell);
    odhs__free(start);
    odhs__free(order);
    return status;
}

typedef struct {
    size_t **pi, **pj, *np, *cap;
    int nomem;
} pair_list_ctx;

static int pair_list_cb(size_t i, size_t j, const double *rij, double gap, void *vctx)
{
    (void)rij;
    (void)gap;
    pair_list_ctx *c = vctx;
    if (*c->np == *c->cap) {
        size_t cap = *c->cap ? 2 * *c->cap : 64;
        size_t *a = odhs__realloc(*c->pi, cap * sizeof *a);
        if (a) *c->pi = a;
        size_t *b = a ? odhs__realloc(*c->pj, cap * sizeof *b) : NULL;
        if (b) *c->pj = b;
        if (!a || !b) {
            c->nomem = 1;
            return 1;
        }
        *c->cap = cap;
    }
    (*c->pi)[*c->np] = i;
    (*c->pj)[*c->np] = j;
    (*c->np)++;
    return 0;
}

int odhs__pair_list(int dim, size_t n, const double *x, const double *r, double rmax, const double *L, double gamma,
                    double max_gap, size_t **pi, size_t **pj, size_t *np, size_t *cap)
{
    pair_list_ctx c = {pi, pj, np, cap, 0};
    *np = 0;
    int s = odhs__pairs(dim, n, x, r, rmax, L, gamma, max_gap, pair_list_cb, &c);
    return c.nomem || s == ODHS_E_NOMEM ? ODHS_E_NOMEM : ODHS_OK;
}
