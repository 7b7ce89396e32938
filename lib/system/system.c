/* libodhs - the system handle: particles, radii, box, Lees-Edwards strain. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "system/system.h"

/* Overlaps smaller than this fraction of the pair's contact distance are
 * accepted as contacts (round-off in configurations written by the library). */
#define ODHS_OVERLAP_ACCEPT 1e-10

int odhs__syserr(const odhs_system *sys, int status, const char *fmt, ...)
{
    if (!sys) return status;
    va_list ap;
    va_start(ap, fmt);
    /* the message buffer is logically mutable state of the handle */
    odhs__verr(((odhs_system *)sys)->errmsg, status, fmt, ap);
    va_end(ap);
    return status;
}

static int system_create_impl(int dim, size_t n, odhs_system **out)
{
    if (!out) return odhs__create_err(ODHS_E_NULL, "odhs_system_create: out is NULL");
    *out = NULL;
    if (dim != 2 && dim != 3) return odhs__create_err(ODHS_E_DIM, "odhs_system_create: dimension %d is not 2 or 3", dim);
    if (n == 0) return odhs__create_err(ODHS_E_EMPTY, "odhs_system_create: N = 0 particles");
    if (n > SIZE_MAX / (3 * sizeof(double) + 32))
        return odhs__create_err(ODHS_E_NOMEM, "odhs_system_create: N = %zu is too large to allocate", n);
    odhs_system *s = odhs__calloc(1, sizeof *s);
    if (!s) return ODHS_E_NOMEM;
    s->dim = dim;
    s->n = n;
    s->L[0] = s->L[1] = s->L[2] = 1.0;
    s->x = odhs__calloc(n * (size_t)dim, sizeof(double));
    s->r = odhs__calloc(n, sizeof(double));
    s->species = odhs__calloc(n, sizeof *s->species);
    if (!s->x || !s->r || !s->species) {
        odhs_system_destroy(s);
        return ODHS_E_NOMEM;
    }
    for (size_t i = 0; i < n; ++i) strcpy(s->species[i], "A");
    *out = s;
    return ODHS_OK;
}

int odhs_system_create(int dim, size_t n, odhs_system **out)
{
    odhs__create_begin();
    return odhs__create_end(system_create_impl(dim, n, out));
}

void odhs_system_destroy(odhs_system *sys)
{
    if (!sys) return;
    odhs__free(sys->x);
    odhs__free(sys->r);
    odhs__free(sys->species);
    odhs__free(sys);
}

static int system_clone_impl(const odhs_system *sys, odhs_system **out)
{
    if (!out) return odhs__create_err(ODHS_E_NULL, "odhs_system_clone: out is NULL");
    *out = NULL;
    if (!sys) return odhs__create_err(ODHS_E_NULL, "odhs_system_clone: system is NULL");
    odhs_system *c;
    int st = odhs_system_create(sys->dim, sys->n, &c);
    if (st) return odhs__create_err(st, "odhs_system_clone: %s", odhs_strerror(st));
    memcpy(c->L, sys->L, sizeof c->L);
    c->gamma = sys->gamma;
    memcpy(c->x, sys->x, sys->n * (size_t)sys->dim * sizeof(double));
    memcpy(c->r, sys->r, sys->n * sizeof(double));
    memcpy(c->species, sys->species, sys->n * sizeof *sys->species);
    c->has_x = sys->has_x;
    c->has_r = sys->has_r;
    c->rmax = sys->rmax;
    *out = c;
    return ODHS_OK;
}

int odhs_system_clone(const odhs_system *sys, odhs_system **out)
{
    odhs__create_begin();
    return odhs__create_end(system_clone_impl(sys, out));
}

const char *odhs_system_errmsg(const odhs_system *sys) { return sys ? sys->errmsg : ""; }

int odhs_system_change_count(const odhs_system *sys, uint64_t *count)
{
    if (!sys) return ODHS_E_NULL;
    if (!count) return odhs__syserr(sys, ODHS_E_NULL, "output pointer is NULL");
    *count = sys->version;
    return ODHS_OK;
}
int odhs_system_dim(const odhs_system *sys) { return sys ? sys->dim : 0; }
size_t odhs_system_count(const odhs_system *sys) { return sys ? sys->n : 0; }
int odhs_system_is_ready(const odhs_system *sys) { return sys && sys->has_x && sys->has_r; }

/* ---- validation of a candidate configuration ----------------------------- */
typedef struct {
    const double *r;
    double worst;   /* most negative relative gap */
    size_t wi, wj;
    double wgap;
    double tol_abs; /* absolute tolerance, < 0: use relative acceptance */
    double rel;     /* relative acceptance */
} overlap_ctx;

static int overlap_cb(size_t i, size_t j, const double *rij, double gap, void *vctx)
{
    (void)rij;
    overlap_ctx *c = vctx;
    double dsum = c->r[i] + c->r[j];
    double lim = c->tol_abs >= 0.0 ? -c->tol_abs : -c->rel * dsum;
    if (gap < lim && gap / dsum < c->worst) {
        c->worst = gap / dsum;
        c->wi = i;
        c->wj = j;
        c->wgap = gap;
    }
    return 0;
}

static int check_box(const odhs_system *sys, const double *L, double rmax)
{
    {
        /* the Lees-Edwards remapping works with Lx/Ly: it must be representable */
        double u = L[0] / L[1];
        if (isfinite(L[0]) && isfinite(L[1]) && L[0] > 0.0 && L[1] > 0.0 &&
            !(u > 0.0 && isfinite(u) && u > 1e-100 && u < 1e100))
            return odhs__syserr(sys, ODHS_E_INVALID, "box aspect ratio Lx/Ly = %g is out of range [1e-100, 1e100]",
                                u);
    }
    for (int k = 0; k < sys->dim; ++k) {
        if (!isfinite(L[k])) return odhs__syserr(sys, ODHS_E_NONFINITE, "box edge %d is not finite", k);
        if (!(L[k] > 0.0))
            return odhs__syserr(sys, ODHS_E_INVALID, "box edge %d = %g is not positive", k, L[k]);
        if (L[k] < 4.0 * rmax)
            return odhs__syserr(sys, ODHS_E_BOX,
                                "box edge %d = %.17g is shorter than two largest diameters (%.17g)", k,
                                L[k], 4.0 * rmax);
    }
    return ODHS_OK;
}

static int check_radii(const odhs_system *sys, const double *r, double *rmax)
{
    double m = 0.0;
    for (size_t i = 0; i < sys->n; ++i) {
        if (!isfinite(r[i])) return odhs__syserr(sys, ODHS_E_NONFINITE, "radius of particle %zu is not finite", i);
        if (!(r[i] > 0.0))
            return odhs__syserr(sys, ODHS_E_INVALID, "radius of particle %zu = %g is not positive", i, r[i]);
        if (r[i] > m) m = r[i];
    }
    *rmax = m;
    return ODHS_OK;
}

static int check_positions(const odhs_system *sys, const double *L, const double *x)
{
    size_t nd = sys->n * (size_t)sys->dim;
    for (size_t k = 0; k < nd; ++k) {
        if (!isfinite(x[k]))
            return odhs__syserr(sys, ODHS_E_NONFINITE, "coordinate %d of particle %zu is not finite",
                                (int)(k % sys->dim), k / sys->dim);
        /* beyond 2^50 box lengths the periodic image cannot be found exactly */
        if (fabs(x[k]) > 0x1p50 * L[k % sys->dim])
            return odhs__syserr(sys, ODHS_E_INVALID,
                                "coordinate %d of particle %zu = %g is too far outside the box to wrap exactly",
                                (int)(k % sys->dim), k / sys->dim, x[k]);
    }
    return ODHS_OK;
}

static int check_overlaps(const odhs_system *sys, const double *L, double gamma, const double *r,
                          double rmax, const double *x, double tol_abs)
{
    overlap_ctx c = {r, 0.0, 0, 0, 0.0, tol_abs, sys->overlap_accept > 0.0 ? sys->overlap_accept : ODHS_OVERLAP_ACCEPT};
    int st = odhs__pairs(sys->dim, sys->n, x, r, rmax, L, gamma, 0.0, overlap_cb, &c);
    if (st == ODHS_E_NOMEM) return odhs__syserr(sys, st, "out of memory in overlap check");
    if (c.worst < 0.0)
        return odhs__syserr(sys, ODHS_E_OVERLAP,
                            "particles %zu and %zu overlap by %.6g (%.3g of their contact distance)",
                            c.wi, c.wj, -c.wgap, -c.worst);
    return ODHS_OK;
}

/* Validate and commit a full candidate (arrays are taken over on success). */
static int commit(odhs_system *sys, const double *L, double gamma, double *r, int has_r, double *x,
                  int has_x)
{
    int st;
    double rmax = 0.0;
    if (!isfinite(gamma)) return odhs__syserr(sys, ODHS_E_NONFINITE, "strain is not finite");
    if (has_r && (st = check_radii(sys, r, &rmax))) return st;
    /* the box must hold two largest diameters once particles are placed */
    if ((st = check_box(sys, L, (has_r && has_x) ? rmax : 0.0))) return st;
    if (fabs(gamma) > 0x1p50 * (L[0] / L[1]))
        return odhs__syserr(sys, ODHS_E_INVALID, "strain %g is too large to remap exactly", gamma);
    gamma = odhs__remap_strain(gamma, L);
    if (has_x) {
        if ((st = check_positions(sys, L, x))) return st;
        for (size_t i = 0; i < sys->n; ++i) odhs__wrap(sys->dim, L, gamma, x + i * sys->dim);
    }
    if (has_r && has_x && (st = check_overlaps(sys, L, gamma, r, rmax, x, -1.0))) return st;
    /* the change counter counts changes: writing the values it holds is none */
    size_t nd = sys->n * (size_t)sys->dim;
    if (memcmp(sys->L, L, (size_t)sys->dim * sizeof(double)) || memcmp(&sys->gamma, &gamma, sizeof gamma) ||
        has_r != sys->has_r || has_x != sys->has_x || (r != sys->r && memcmp(sys->r, r, sys->n * sizeof(double))) ||
        (x != sys->x && memcmp(sys->x, x, nd * sizeof(double))))
        sys->version++;
    memcpy(sys->L, L, (size_t)sys->dim * sizeof(double));
    sys->gamma = gamma;
    if (r != sys->r) memcpy(sys->r, r, sys->n * sizeof(double));
    if (x != sys->x) memcpy(sys->x, x, sys->n * (size_t)sys->dim * sizeof(double));
    sys->has_r = has_r;
    sys->has_x = has_x;
    sys->rmax = rmax;
    sys->errmsg[0] = '\0';
    return ODHS_OK;
}

/* Run commit on copies so that a failure leaves the handle untouched. */
static int commit_copy(odhs_system *sys, const double *L, double gamma, const double *r, int has_r,
                       const double *x, int has_x)
{
    size_t nd = sys->n * (size_t)sys->dim;
    double *rc = odhs__malloc_array(sys->n, sizeof(double));
    double *xc = odhs__malloc_array(nd, sizeof(double));
    if (!rc || !xc) {
        odhs__free(rc);
        odhs__free(xc);
        return odhs__syserr(sys, ODHS_E_NOMEM, "out of memory");
    }
    memcpy(rc, r, sys->n * sizeof(double));
    memcpy(xc, x, nd * sizeof(double));
    int st = commit(sys, L, gamma, rc, has_r, xc, has_x);
    odhs__free(rc);
    odhs__free(xc);
    return st;
}

int odhs_system_set_box(odhs_system *sys, const double *L)
{
    if (!sys) return ODHS_E_NULL;
    sys->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!L) return odhs__syserr(sys, ODHS_E_NULL, "box lengths pointer is NULL");
    double LL[3] = {sys->L[0], sys->L[1], sys->L[2]};
    memcpy(LL, L, (size_t)sys->dim * sizeof(double));
    return commit_copy(sys, LL, sys->gamma, sys->r, sys->has_r, sys->x, sys->has_x);
}

int odhs_system_get_box(const odhs_system *sys, double *L)
{
    if (!sys) return ODHS_E_NULL;
    if (!L) return odhs__syserr(sys, ODHS_E_NULL, "output pointer is NULL");
    memcpy(L, sys->L, (size_t)sys->dim * sizeof(double));
    return ODHS_OK;
}

int odhs_system_volume(const odhs_system *sys, double *vol)
{
    if (!sys) return ODHS_E_NULL;
    if (!vol) return odhs__syserr(sys, ODHS_E_NULL, "output pointer is NULL");
    *vol = sys->L[0] * sys->L[1] * (sys->dim == 3 ? sys->L[2] : 1.0);
    return ODHS_OK;
}

int odhs_system_set_strain(odhs_system *sys, double gamma)
{
    if (!sys) return ODHS_E_NULL;
    sys->errmsg[0] = '\0'; /* a successful call leaves no message */
    return commit_copy(sys, sys->L, gamma, sys->r, sys->has_r, sys->x, sys->has_x);
}

int odhs_system_get_strain(const odhs_system *sys, double *gamma)
{
    if (!sys) return ODHS_E_NULL;
    if (!gamma) return odhs__syserr(sys, ODHS_E_NULL, "output pointer is NULL");
    *gamma = sys->gamma;
    return ODHS_OK;
}

int odhs_system_set_radii(odhs_system *sys, const double *r)
{
    if (!sys) return ODHS_E_NULL;
    sys->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!r) return odhs__syserr(sys, ODHS_E_NULL, "radii pointer is NULL");
    return commit_copy(sys, sys->L, sys->gamma, r, 1, sys->x, sys->has_x);
}

int odhs_system_get_radii(const odhs_system *sys, double *r)
{
    if (!sys) return ODHS_E_NULL;
    if (!r) return odhs__syserr(sys, ODHS_E_NULL, "output pointer is NULL");
    if (!sys->has_r) return odhs__syserr(sys, ODHS_E_STATE, "radii have not been set");
    memcpy(r, sys->r, sys->n * sizeof(double));
    return ODHS_OK;
}

int odhs_system_set_positions(odhs_system *sys, const double *x)
{
    if (!sys) return ODHS_E_NULL;
    sys->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!x) return odhs__syserr(sys, ODHS_E_NULL, "positions pointer is NULL");
    return commit_copy(sys, sys->L, sys->gamma, sys->r, sys->has_r, x, 1);
}

int odhs_system_get_positions(const odhs_system *sys, double *x)
{
    if (!sys) return ODHS_E_NULL;
    if (!x) return odhs__syserr(sys, ODHS_E_NULL, "output pointer is NULL");
    if (!sys->has_x) return odhs__syserr(sys, ODHS_E_STATE, "positions have not been set");
    memcpy(x, sys->x, sys->n * (size_t)sys->dim * sizeof(double));
    return ODHS_OK;
}

int odhs_system_set_configuration(odhs_system *sys, const double *L, double gamma, const double *r,
                                  const double *x)
{
    if (!sys) return ODHS_E_NULL;
    sys->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!L || !r || !x) return odhs__syserr(sys, ODHS_E_NULL, "a configuration pointer is NULL");
    double LL[3] = {1.0, 1.0, 1.0};
    memcpy(LL, L, (size_t)sys->dim * sizeof(double));
    return commit_copy(sys, LL, gamma, r, 1, x, 1);
}

static int valid_label(const char *s)
{
    size_t len = strlen(s);
    if (len == 0 || len > ODHS_SPECIES_MAX) return 0;
    for (size_t k = 0; k < len; ++k) {
        unsigned char c = (unsigned char)s[k];
        if (c <= 32 || c >= 127 || c == '"' || c == '\'' || c == '=') return 0;
    }
    return 1;
}

int odhs_system_set_species(odhs_system *sys, size_t i, const char *label)
{
    if (!sys) return ODHS_E_NULL;
    sys->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!label) return odhs__syserr(sys, ODHS_E_NULL, "label is NULL");
    if (i >= sys->n) return odhs__syserr(sys, ODHS_E_RANGE, "particle index %zu >= N = %zu", i, sys->n);
    if (!valid_label(label))
        return odhs__syserr(sys, ODHS_E_INVALID,
                            "species label must be 1..%d printable characters without blanks or quotes",
                            ODHS_SPECIES_MAX);
    strcpy(sys->species[i], label);
    return ODHS_OK;
}

int odhs_system_get_species(const odhs_system *sys, size_t i, char *buf, size_t size)
{
    if (!sys) return ODHS_E_NULL;
    if (!buf) return odhs__syserr(sys, ODHS_E_NULL, "buffer is NULL");
    if (i >= sys->n) return odhs__syserr(sys, ODHS_E_RANGE, "particle index %zu >= N = %zu", i, sys->n);
    size_t len = strlen(sys->species[i]);
    if (size < len + 1) return odhs__syserr(sys, ODHS_E_INVALID, "buffer too small for species label");
    memcpy(buf, sys->species[i], len + 1);
    return ODHS_OK;
}

int odhs_system_scale_box(odhs_system *sys, double s)
{
    if (!sys) return ODHS_E_NULL;
    sys->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(s)) return odhs__syserr(sys, ODHS_E_NONFINITE, "scale factor is not finite");
    if (!(s > 0.0)) return odhs__syserr(sys, ODHS_E_INVALID, "scale factor %g is not positive", s);
    size_t nd = sys->n * (size_t)sys->dim;
    double LL[3] = {sys->L[0] * s, sys->L[1] * s, sys->dim == 3 ? sys->L[2] * s : 1.0};
    double *x = odhs__malloc_array(nd, sizeof(double));
    if (!x) return odhs__syserr(sys, ODHS_E_NOMEM, "out of memory");
    for (size_t k = 0; k < nd; ++k) x[k] = sys->x[k] * s;
    int st = commit_copy(sys, LL, sys->gamma, sys->r, sys->has_r, x, sys->has_x);
    odhs__free(x);
    return st;
}

static double particle_volume(int dim, double r)
{
    return dim == 2 ? ODHS_PI * r * r : 4.0 / 3.0 * ODHS_PI * r * r * r;
}

int odhs_system_packing_fraction(const odhs_system *sys, double *phi)
{
    if (!sys) return ODHS_E_NULL;
    if (!phi) return odhs__syserr(sys, ODHS_E_NULL, "output pointer is NULL");
    if (!sys->has_r) return odhs__syserr(sys, ODHS_E_STATE, "radii have not been set");
    double v = 0.0, vol;
    for (size_t i = 0; i < sys->n; ++i) v += particle_volume(sys->dim, sys->r[i]);
    odhs_system_volume(sys, &vol);
    *phi = v / vol;
    return ODHS_OK;
}

int odhs_system_separation(const odhs_system *sys, size_t i, size_t j, double *rij, double *dist,
                           int *image)
{
    if (!sys) return ODHS_E_NULL;
    if (!rij) return odhs__syserr(sys, ODHS_E_NULL, "output pointer is NULL");
    if (i >= sys->n || j >= sys->n)
        return odhs__syserr(sys, ODHS_E_RANGE, "particle index out of range (N = %zu)", sys->n);
    if (!sys->has_x) return odhs__syserr(sys, ODHS_E_STATE, "positions have not been set");
    double d[3] = {0, 0, 0};
    for (int k = 0; k < sys->dim; ++k) d[k] = sys->x[j * sys->dim + k] - sys->x[i * sys->dim + k];
    int img[3];
    odhs__min_image(sys->dim, sys->L, sys->gamma, d, img);
    memcpy(rij, d, (size_t)sys->dim * sizeof(double));
    if (dist) *dist = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
    if (image) memcpy(image, img, (size_t)sys->dim * sizeof(int));
    return ODHS_OK;
}

int odhs_system_validate(const odhs_system *sys, double tol)
{
    if (!sys) return ODHS_E_NULL;
    if (!sys->has_r || !sys->has_x)
        return odhs__syserr(sys, ODHS_E_STATE, "radii and positions must both be set");
    if (!isfinite(tol) || tol < 0.0)
        return odhs__syserr(sys, ODHS_E_INVALID, "tolerance must be finite and >= 0");
    double rmax;
    int st;
    if ((st = check_radii(sys, sys->r, &rmax))) return st;
    if ((st = check_box(sys, sys->L, rmax))) return st;
    if ((st = check_positions(sys, sys->L, sys->x))) return st;
    return check_overlaps(sys, sys->L, sys->gamma, sys->r, rmax, sys->x, tol);
}

int odhs_system_for_each_pair(const odhs_system *sys, double max_gap, odhs_pair_fn fn, void *ctx)
{
    if (!sys) return ODHS_E_NULL;
    if (!fn) return odhs__syserr(sys, ODHS_E_NULL, "callback is NULL");
    if (!sys->has_r || !sys->has_x)
        return odhs__syserr(sys, ODHS_E_STATE, "radii and positions must both be set");
    if (!isfinite(max_gap) || max_gap < 0.0)
        return odhs__syserr(sys, ODHS_E_INVALID, "max_gap must be finite and >= 0");
    double Lmin = sys->L[0] < sys->L[1] ? sys->L[0] : sys->L[1];
    if (sys->dim == 3 && sys->L[2] < Lmin) Lmin = sys->L[2];
    if (2.0 * sys->rmax + max_gap >= 0.5 * Lmin)
        return odhs__syserr(sys, ODHS_E_INVALID,
                            "max_gap %g too large for the box: pair range must stay below half the "
                            "shortest edge",
                            max_gap);
    int st = odhs__pairs(sys->dim, sys->n, sys->x, sys->r, sys->rmax, sys->L, sys->gamma, max_gap,
                         fn, ctx);
    if (st == ODHS_E_NOMEM) return odhs__syserr(sys, st, "out of memory");
    return st;
}

/* ---- builders --------------------------------------------------------------- */
int odhs_system_set_radii_bidisperse(odhs_system *sys, double r_small, double ratio, double poly,
                                     uint64_t seed)
{
    if (!sys) return ODHS_E_NULL;
    sys->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(r_small) || !isfinite(ratio) || !isfinite(poly))
        return odhs__syserr(sys, ODHS_E_NONFINITE, "bidisperse parameters must be finite");
    if (!(r_small > 0.0) || !(ratio > 0.0) || poly < 0.0 || poly >= 1.0)
        return odhs__syserr(sys, ODHS_E_INVALID,
                            "need r_small > 0, ratio > 0 and 0 <= poly < 1 (got %g, %g, %g)", r_small,
                            ratio, poly);
    double *r = odhs__malloc_array(sys->n, sizeof(double));
    if (!r) return odhs__syserr(sys, ODHS_E_NOMEM, "out of memory");
    odhs_rng rng;
    odhs__rng_seed(&rng, seed);
    for (size_t i = 0; i < sys->n; ++i) {
        double base = (i % 2 == 0) ? r_small : r_small * ratio;
        double u = odhs__rng_uniform(&rng);
        r[i] = base * (1.0 + poly * (2.0 * u - 1.0));
    }
    int st = commit_copy(sys, sys->L, sys->gamma, r, 1, sys->x, sys->has_x);
    odhs__free(r);
    if (st) return st;
    for (size_t i = 0; i < sys->n; ++i) strcpy(sys->species[i], (i % 2 == 0) ? "S" : "L");
    return ODHS_OK;
}

/* simple uniform grid for random sequential addition */
typedef struct {
    int dim, nc[3];
    double w[3];
    size_t *head, *next; /* linked lists, SIZE_MAX terminates */
    int noff[3], off[3][5]; /* neighbour cells to visit in each direction */
} rsa_grid;

static size_t rsa_cell(const rsa_grid *g, const double *x)
{
    size_t c = 0;
    for (int k = g->dim - 1; k >= 0; --k) {
        int ck = (int)floor(x[k] / g->w[k]);
        if (ck < 0) ck = 0;
        if (ck >= g->nc[k]) ck = g->nc[k] - 1;
        c = c * (size_t)g->nc[k] + (size_t)ck;
    }
    return c;
}

static int cmp_radius_desc(const void *a, const void *b, const double *r)
{
    size_t i = *(const size_t *)a, j = *(const size_t *)b;
    if (r[i] > r[j]) return -1;
    if (r[i] < r[j]) return 1;
    return (i > j) - (i < j);
}

/* insertion-free merge sort of indices by radius, descending (stable) */
static void sort_by_radius(size_t *idx, size_t *tmp, size_t n, const double *r)
{
    if (n < 2) return;
    size_t h = n / 2;
    sort_by_radius(idx, tmp, h, r);
    sort_by_radius(idx + h, tmp, n - h, r);
    size_t a = 0, b = h, k = 0;
    while (a < h && b < n) tmp[k++] = cmp_radius_desc(&idx[b], &idx[a], r) < 0 ? idx[b++] : idx[a++];
    while (a < h) tmp[k++] = idx[a++];
    while (b < n) tmp[k++] = idx[b++];
    memcpy(idx, tmp, n * sizeof *idx);
}

/* cell counts and widths of the grid over the box L: cells at least
 * 2 rmax wide, O(n) of them; returns the number of cells */
static size_t rsa_grid_size(rsa_grid *g, const double *L, double rmax, size_t n)
{
    int dim = g->dim;
    double cw = 2.0 * rmax;
    size_t ncell = 1;
    for (int k = 0; k < dim; ++k) {
        double m = floor(L[k] / cw);
        if (m > 4096) m = 4096;
        g->nc[k] = m < 1 ? 1 : (int)m;
    }
    while ((double)g->nc[0] * g->nc[1] * g->nc[2] > 4.0 * (double)n + 64)
        for (int k = 0; k < dim; ++k) g->nc[k] = g->nc[k] > 1 ? (g->nc[k] + 1) / 2 : 1;
    for (int k = 0; k < dim; ++k) {
        g->w[k] = L[k] / g->nc[k];
        ncell *= (size_t)g->nc[k];
    }
    return ncell;
}

/* the cell offsets to visit around a cell, in each direction */
static void rsa_stencil(rsa_grid *g)
{
    for (int k = 0; k < 3; ++k) {
        g->noff[k] = 1;
        g->off[k][0] = 0;
    }
    for (int k = 0; k < g->dim; ++k) {
        /* a placed particle can reach one cell away when w >= 2 rmax; coarse
         * grids (few cells) visit every cell once */
        if (g->nc[k] >= 3) {
            g->noff[k] = 3;
            g->off[k][0] = -1; g->off[k][1] = 0; g->off[k][2] = 1;
        } else {
            g->noff[k] = g->nc[k];
            for (int m = 0; m < g->nc[k]; ++m) g->off[k][m] = m;
        }
    }
}

/* whether particle i, at its trial position in x, overlaps none of the
 * particles already in the grid */
static int rsa_fits(const rsa_grid *g, const double *L, const double *r, const double *x, size_t i)
{
    int dim = g->dim;
    const double *xi = x + i * dim;
    int ok = 1;
    int c0[3] = {0, 0, 0};
    for (int k = 0; k < dim; ++k) {
        c0[k] = (int)floor(xi[k] / g->w[k]);
        if (c0[k] >= g->nc[k]) c0[k] = g->nc[k] - 1;
    }
    for (int a = 0; a < g->noff[2] && ok; ++a)
        for (int b = 0; b < g->noff[1] && ok; ++b)
            for (int e = 0; e < g->noff[0] && ok; ++e) {
                int cc[3] = {c0[0] + g->off[0][e], c0[1] + g->off[1][b], c0[2] + g->off[2][a]};
                size_t c = 0;
                for (int k = dim - 1; k >= 0; --k) {
                    int ck = ((cc[k] % g->nc[k]) + g->nc[k]) % g->nc[k];
                    if (g->nc[k] < 3) ck = cc[k] - c0[k]; /* absolute cell index */
                    c = c * (size_t)g->nc[k] + (size_t)ck;
                }
                for (size_t j = g->head[c]; j != SIZE_MAX; j = g->next[j]) {
                    double d[3] = {0, 0, 0};
                    for (int k = 0; k < dim; ++k) d[k] = x[j * dim + k] - xi[k];
                    odhs__min_image(dim, L, 0.0, d, NULL);
                    double s2 = d[0] * d[0] + d[1] * d[1] + d[2] * d[2];
                    double dd = r[i] + r[j];
                    if (s2 < dd * dd) {
                        ok = 0;
                        break;
                    }
                }
            }
    return ok;
}

/* random sequential addition into the box L, in the order idx, each
 * particle at the first of up to max_tries uniform positions that fits */
static int rsa_place(odhs_system *sys, rsa_grid *g, const double *L, const size_t *idx, double *x, double phi,
                     uint64_t seed)
{
    int dim = sys->dim;
    size_t n = sys->n;
    odhs_rng rng;
    odhs__rng_seed(&rng, seed);
    const uint64_t max_tries = 2000000; /* per particle */
    for (size_t p = 0; p < n; ++p) {
        size_t i = idx[p];
        double *xi = x + i * dim;
        uint64_t t;
        for (t = 0; t < max_tries; ++t) {
            for (int k = 0; k < dim; ++k) xi[k] = odhs__rng_uniform(&rng) * L[k];
            if (rsa_fits(g, L, sys->r, x, i)) break;
        }
        if (t == max_tries) {
            double vdone = 0.0, vol = L[0] * L[1] * (dim == 3 ? L[2] : 1.0);
            for (size_t q = 0; q < p; ++q) vdone += particle_volume(dim, sys->r[idx[q]]);
            return odhs__syserr(sys, ODHS_E_TOODENSE,
                                "random sequential addition stalled after placing %zu of %zu particles "
                                "(phi = %.4f of the requested %.4f)",
                                p, n, vdone / vol, phi);
        }
        size_t c = rsa_cell(g, xi);
        g->next[i] = g->head[c];
        g->head[c] = i;
    }
    return ODHS_OK;
}

int odhs_system_place_random(odhs_system *sys, double phi, uint64_t seed)
{
    if (!sys) return ODHS_E_NULL;
    sys->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(phi)) return odhs__syserr(sys, ODHS_E_NONFINITE, "packing fraction is not finite");
    if (!(phi > 0.0) || phi >= 1.0)
        return odhs__syserr(sys, ODHS_E_INVALID, "packing fraction %g must be in (0,1)", phi);
    if (!sys->has_r) return odhs__syserr(sys, ODHS_E_STATE, "set the radii before placing particles");
    int dim = sys->dim;
    size_t n = sys->n;
    double vp = 0.0;
    for (size_t i = 0; i < n; ++i) vp += particle_volume(dim, sys->r[i]);
    double vol0 = sys->L[0] * sys->L[1] * (dim == 3 ? sys->L[2] : 1.0);
    double s = pow(vp / phi / vol0, 1.0 / dim);
    double L[3] = {sys->L[0] * s, sys->L[1] * s, dim == 3 ? sys->L[2] * s : 1.0};
    int st = check_box(sys, L, sys->rmax);
    if (st) return st;

    size_t nd = n * (size_t)dim;
    double *x = odhs__malloc_array(nd, sizeof(double));
    size_t *idx = odhs__malloc_array(n, sizeof(size_t));
    size_t *tmp = odhs__malloc_array(n, sizeof(size_t));
    rsa_grid g = {dim, {1, 1, 1}, {1, 1, 1}, NULL, NULL, {1, 1, 1}, {{0}}};
    size_t ncell = rsa_grid_size(&g, L, sys->rmax, n);
    g.head = odhs__malloc_array(ncell, sizeof(size_t));
    g.next = odhs__malloc_array(n, sizeof(size_t));
    if (!x || !idx || !tmp || !g.head || !g.next) {
        st = odhs__syserr(sys, ODHS_E_NOMEM, "out of memory");
        goto done;
    }
    for (size_t c = 0; c < ncell; ++c) g.head[c] = SIZE_MAX;
    for (size_t i = 0; i < n; ++i) idx[i] = i;
    sort_by_radius(idx, tmp, n, sys->r);
    rsa_stencil(&g);
    st = rsa_place(sys, &g, L, idx, x, phi, seed);
    if (st == ODHS_OK) st = commit_copy(sys, L, 0.0, sys->r, 1, x, 1);
done:
    odhs__free(x);
    odhs__free(idx);
    odhs__free(tmp);
    odhs__free(g.head);
    odhs__free(g.next);
    return st;
}
