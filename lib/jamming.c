/* libodhs - jamming: the self-stress f0 of a potentially jammed network
 * (Sect. IV D of Lerner, During & Wyart 2013). */
#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "internal.h"

#define DENSE_MAX 600 /* subsets up to this many contacts use LAPACK */

/* contacts whose both particles are in the constrained subset */
static int subset_contacts(const odhs_network *net, size_t **idx, size_t *m)
{
    unsigned char *in = odhs__malloc_array(net->n, 1);
    size_t *list = odhs__malloc_array(net->nc ? net->nc : 1, sizeof *list);
    if (!in || !list) {
        odhs__free(in);
        odhs__free(list);
        return ODHS_E_NOMEM;
    }
    int st = odhs_network_constrained(net, NULL, NULL, in, NULL);
    if (st) {
        odhs__free(in);
        odhs__free(list);
        return st;
    }
    size_t k = 0;
    for (size_t c = 0; c < net->nc; ++c)
        if (in[net->ci[c]] && in[net->cj[c]]) list[k++] = c;
    odhs__free(in);
    *idx = list;
    *m = k;
    return ODHS_OK;
}

/* smallest eigenvector of N restricted to the contacts idx[0..m-1] */
static int null_dense(const odhs_network *net, const size_t *idx, size_t m, double *y)
{
    int d = net->dim;
    double *A = odhs__calloc(m * m, sizeof *A);
    double *z = odhs__malloc_array(2 * m, sizeof *z);
    double *w = odhs__malloc_array(m, sizeof *w); /* dsyevr uses all m entries */
    lapack_int *supp = odhs__malloc_array(4, sizeof *supp);
    if (!A || !z || !w || !supp) {
        odhs__free(A);
        odhs__free(z);
        odhs__free(w);
        odhs__free(supp);
        return ODHS_E_NOMEM;
    }
    /* N_ab = s_a . s_b: nonzero when contacts a and b share a particle */
    for (size_t a = 0; a < m; ++a)
        for (size_t b = a; b < m; ++b) {
            size_t ca = idx[a], cb = idx[b];
            double v = 0.0;
            const double *na = net->nrm + ca * d, *nb = net->nrm + cb * d;
            double dot = 0.0;
            for (int k = 0; k < d; ++k) dot += na[k] * nb[k];
            if (net->ci[ca] == net->ci[cb]) v += dot;
            if (net->cj[ca] == net->cj[cb]) v += dot;
            if (net->ci[ca] == net->cj[cb]) v -= dot;
            if (net->cj[ca] == net->ci[cb]) v -= dot;
            A[b * m + a] = v; /* lower triangle, column-major */
        }
    lapack_int found = 0;
    lapack_int mm = (lapack_int)m, iu = m >= 2 ? 2 : 1;
    lapack_int info = LAPACKE_dsyevr(LAPACK_COL_MAJOR, 'V', 'I', 'L', mm, A, mm, 0.0, 0.0, 1, iu, 0.0, &found,
                                     w, z, mm, supp);
    int st = ODHS_OK;
    if (info != 0 || found < 1) st = ODHS_E_INTERNAL;
    /* the kernel must be one-dimensional: the second eigenvalue clearly > 0
     * (the diagonal of N is 2, so eigenvalues are O(1) scaled) */
    else if (found >= 2 && !(w[1] > 1e-9)) st = ODHS_E_SINGULAR;
    else memcpy(y, z, m * sizeof *y);
    odhs__free(A);
    odhs__free(z);
    odhs__free(w);
    odhs__free(supp);
    return st;
}

/* fix f0 at contact idx[kk] to 1, least squares for the others */
static int null_sparse(const odhs_network *net, odhs_solver *solver, const size_t *idx, size_t m, size_t kk,
                       double *y)
{
    int d = net->dim;
    odhs_network *sub = odhs__net_new(d, net->n);
    double *g = odhs__calloc(net->n * (size_t)d, sizeof *g);
    double *x = odhs__calloc(m, sizeof *x);
    int st = ODHS_OK;
    if (!sub || !g || !x) {
        st = ODHS_E_NOMEM;
        goto done;
    }
    for (size_t a = 0; a < m; ++a) {
        if (a == kk) continue;
        size_t c = idx[a];
        size_t s = odhs__net_add(sub, net->ci[c], net->cj[c], net->kind[c]);
        if (s == SIZE_MAX) {
            st = ODHS_E_NOMEM;
            goto done;
        }
        memcpy(sub->nrm + s * d, net->nrm + c * d, (size_t)d * sizeof(double));
        sub->dist[s] = net->dist[c];
        sub->gap[s] = net->gap[c];
    }
    sub->version++;
    /* S'^T y = -s_k^T: s_k has -n on i and +n on j */
    size_t ck = idx[kk];
    for (int k = 0; k < d; ++k) {
        g[net->ci[ck] * d + k] = net->nrm[ck * d + k];
        g[net->cj[ck] * d + k] = -net->nrm[ck * d + k];
    }
    st = odhs_solver_solve_ls(solver, sub, g, x);
    if (st) goto done;
    /* sub's contacts are in the order added: idx without kk */
    for (size_t a = 0, s = 0; a < m; ++a) y[a] = a == kk ? 1.0 : x[s++];
done:
    odhs_network_destroy(sub);
    odhs__free(g);
    odhs__free(x);
    return st;
}

int odhs__null_vector(const odhs_network *net, odhs_solver *solver, double *f0, double *residual)
{
    int flag = 0, st = odhs_network_potentially_jammed(net, &flag);
    if (st) return st;
    if (!flag) return odhs__neterr(net, ODHS_E_STATE, "the network is not potentially jammed");
    size_t *idx = NULL, m = 0;
    if ((st = subset_contacts(net, &idx, &m))) return odhs__neterr(net, st, "out of memory");
    double *y = odhs__malloc_array(m, sizeof *y);
    double *F = odhs__malloc_array(net->n * (size_t)net->dim, sizeof *F);
    double *full = odhs__calloc(net->nc, sizeof *full);
    if (!y || !F || !full) {
        st = odhs__neterr(net, ODHS_E_NOMEM, "out of memory");
        goto done;
    }
    if (!solver || m <= DENSE_MAX) {
        st = null_dense(net, idx, m, y);
    } else {
        /* try the most recently added contacts first: removing the contact
         * that made the subset isostatic leaves a full-rank network */
        st = ODHS_E_SINGULAR;
        for (size_t t = 0; t < 6 && t < m && st; ++t) st = null_sparse(net, solver, idx, m, m - 1 - t, y);
    }
    if (st) {
        st = odhs__neterr(net, st, "self-stress f0: %s", odhs_strerror(st));
        goto done;
    }
    double sum = 0.0;
    for (size_t a = 0; a < m; ++a) sum += y[a];
    if (!(fabs(sum) > 0.0)) {
        st = odhs__neterr(net, ODHS_E_SINGULAR, "self-stress f0 sums to zero");
        goto done;
    }
    double scale = (double)m / sum; /* sign: sum f0 > 0; mean 1 */
    for (size_t a = 0; a < m; ++a) full[idx[a]] = y[a] * scale;
    odhs__net_ST(net, full, F);
    double rmax = 0.0;
    for (size_t k = 0; k < net->n * (size_t)net->dim; ++k) rmax = fmax(rmax, fabs(F[k]));
    if (residual) *residual = rmax;
    memcpy(f0, full, net->nc * sizeof *f0);
done:
    odhs__free(idx);
    odhs__free(y);
    odhs__free(F);
    odhs__free(full);
    return st;
}

int odhs_network_null_vector(const odhs_network *net, odhs_solver *solver, double *f0, double *residual)
{
    if (!net) return ODHS_E_NULL;
    if (!f0 && net->nc) return odhs__neterr(net, ODHS_E_NULL, "output pointer is NULL");
    return odhs__null_vector(net, solver, f0, residual);
}
