/* libodhs - the stepper's neighbour list (a Verlet list with a skin over the
 * cell search of lib/geom) and its check on a restored state. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

/* ---- neighbour list ----------------------------------------------------- */
int odhs__st_build_neighbours(odhs_stepper *st)
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
        return odhs__sterr(st, ODHS_E_BOX,
                     "box too small for the neighbour search: shortest edge %.6g, largest diameter %.6g",
                     Lmin, 2.0 * s->rmax);
    st->skin = skin;
    st->rc = 2.0 * s->rmax + skin;
    st->pflag_state = 0; /* new pairs (also if the search fails): the contact flags are built anew */
    if (odhs__pair_list(st->dim, st->n, s->x, s->r, s->rmax, s->L, s->gamma, skin, &st->pi, &st->pj, &st->npairs,
                        &st->pcap))
        return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
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
double odhs__st_skin_used(const odhs_stepper *st)
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
    double room = st->skin - odhs__st_skin_used(st);
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
double odhs__st_skin_rate(const odhs_stepper *st, const double *G, const double *vel)
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
