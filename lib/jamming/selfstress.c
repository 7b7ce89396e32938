/* libodhs - jamming: the self-stress f0 of a potentially jammed network
 * (Sect. IV D of Lerner, During & Wyart 2013). */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "jamming/jamming.h"

#define DENSE_MAX 600 /* subsets up to this many contacts use LAPACK (SVD) */

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
        if (in[net->ci[c]] && (net->cj[c] >= net->n || in[net->cj[c]])) list[k++] = c;
    odhs__free(in);
    *idx = list;
    *m = k;
    return ODHS_OK;
}

/* The kernel vector of S^T restricted to the contacts idx[0..m-1] (with the
 * extra row r^T, rv[a] = r of contact idx[a], when rv is not NULL: the
 * volume as one more column of S under fixed pressure), from the SVD of that
 * dense matrix (LAPACK dgesdd, dgesvd if it fails): the right singular vector of the smallest
 * singular value. Working on S^T itself, not on N = S S^T, keeps the
 * accuracy at eps sigma_max / sigma_2 instead of its square. The kernel must
 * be one-dimensional: the next singular value clearly > 0 (columns of S^T
 * have norm sqrt 2, so singular values are O(1) scaled). */
/* S^T on the contacts idx[0..m-1] (and the row r^T when rv is given) into
 * the R x m column-major A, rows of particle i at row[i] * d: column a =
 * s_a^T, -n on i's rows, +n on j's (a wall has no block) */
static void fill_ST(const odhs_network *net, const size_t *idx, size_t m, const double *rv, const size_t *row,
                    size_t R, double *A)
{
    int d = net->dim;
    memset(A, 0, R * m * sizeof *A);
    for (size_t a = 0; a < m; ++a) {
        size_t c = idx[a];
        const double *nc = net->nrm + c * d;
        for (int k = 0; k < d; ++k) {
            A[a * R + row[net->ci[c]] * d + k] = -nc[k];
            if (net->cj[c] < net->n) A[a * R + row[net->cj[c]] * d + k] = nc[k];
        }
        if (rv) A[a * R + R - 1] = rv[a];
    }
}

static int null_dense(const odhs_network *net, const size_t *idx, size_t m, const double *rv, double *y)
{
    int d = net->dim;
    size_t n = net->n, nr = 0;
    size_t *row = odhs__malloc_array(n ? n : 1, sizeof *row);
    if (!row) return ODHS_E_NOMEM;
    for (size_t i = 0; i < n; ++i) row[i] = SIZE_MAX;
    for (size_t a = 0; a < m; ++a) {
        size_t c = idx[a];
        if (row[net->ci[c]] == SIZE_MAX) row[net->ci[c]] = nr++;
        if (net->cj[c] < n && row[net->cj[c]] == SIZE_MAX) row[net->cj[c]] = nr++;
    }
    size_t R = nr * (size_t)d + (rv ? 1 : 0), ns = R < m ? R : m;
    double *A = odhs__malloc_array(R * m + 1, sizeof *A);
    /* dgesdd (below) for small subsets only: its workspace grows as m^2 */
    const int dc = m <= DENSE_MAX;
    double *U = odhs__malloc_array(dc ? R * (m <= R ? m : R) + 1 : 1, sizeof *U);
    double *vt = odhs__malloc_array(m * m + 1, sizeof *vt);
    double *sv = odhs__malloc_array(ns + 1, sizeof *sv);
    double *sup = odhs__malloc_array(ns + 1, sizeof *sup);
    int st = ODHS_OK;
    if (!A || !U || !vt || !sv || !sup) {
        st = ODHS_E_NOMEM;
        goto done;
    }
    if (m < 2 || m > R + 1) {
        st = ODHS_E_SINGULAR; /* no kernel, or more than a one-dimensional one */
        goto done;
    }
    /* up to DENSE_MAX contacts divide and conquer (dgesdd) first: 2.2
     * times faster than dgesvd at m = 500 (its left vectors are computed but
     * not used); dgesvd takes over, on a fresh A, if it fails. All m right
     * vectors: jobz 'S' gives min(R, m) */
    lapack_int info = 1;
    fill_ST(net, idx, m, rv, row, R, A);
    if (dc) {
        info = LAPACKE_dgesdd(LAPACK_COL_MAJOR, m <= R ? 'S' : 'A', (lapack_int)R, (lapack_int)m, A, (lapack_int)R, sv,
                              U, (lapack_int)R, vt, (lapack_int)m);
        if (info != 0) fill_ST(net, idx, m, rv, row, R, A);
    }
    if (info != 0)
        info = LAPACKE_dgesvd(LAPACK_COL_MAJOR, 'N', 'A', (lapack_int)R, (lapack_int)m, A, (lapack_int)R, sv, NULL, 1,
                              vt, (lapack_int)m, sup);
    if (info != 0) {
        st = ODHS_E_INTERNAL;
        goto done;
    }
    /* the next-smallest singular value: sv[m-2] when the smallest, sv[m-1],
     * is the kernel's; sv[R-1] when m = R + 1 (the kernel is not in sv) */
    double next = m <= R ? sv[m - 2] : sv[R - 1];
    if (!(next * next > 1e-9)) {
        st = ODHS_E_SINGULAR;
        goto done;
    }
    for (size_t a = 0; a < m; ++a) y[a] = vt[a * m + (m - 1)]; /* row m-1 of V^T */
done:
    odhs__free(row);
    odhs__free(A);
    odhs__free(U);
    odhs__free(vt);
    odhs__free(sv);
    odhs__free(sup);
    return st;
}

/* one step of iterative refinement of the least-squares solution x (m - 1
 * entries) of S'^T x = g on sub, on the residual g - S'^T x, kept when it
 * lowers the residual (the jammed packing's f0: with cholmod-pcg the force
 * balance was 1.2e-12 of the mean force at 3D N = 1000, 2.2e-15 after it).
 * ODHS_OK, kept or not, or ODHS_E_NOMEM. */
static int refine_once(const odhs_network *net, odhs_solver *solver, odhs_network *sub, size_t m, const double *g,
                       double *x)
{
    const size_t nd = net->n * (size_t)net->dim;
    double *r = odhs__malloc_array(nd, sizeof *r), *dx = odhs__calloc(m ? m : 1, sizeof *dx);
    int st = r && dx ? ODHS_OK : ODHS_E_NOMEM;
    if (st == ODHS_OK) {
        odhs__net_ST(sub, x, r);
        double r0 = 0.0, r1 = 0.0;
        for (size_t q = 0; q < nd; ++q) {
            r[q] = g[q] - r[q];
            r0 = fmax(r0, fabs(r[q]));
        }
        if (r0 > 0.0 && (st = odhs_solver_solve_ls(solver, sub, r, dx)) == ODHS_OK) {
            for (size_t q = 0; q + 1 < m; ++q) dx[q] += x[q];
            odhs__net_ST(sub, dx, r);
            for (size_t q = 0; q < nd; ++q) r1 = fmax(r1, fabs(g[q] - r[q]));
            if (r1 < r0) memcpy(x, dx, (m - 1) * sizeof *x);
        }
    }
    odhs__free(r);
    odhs__free(dx);
    return st == ODHS_E_NOMEM ? st : ODHS_OK;
}

/* f0 fixed to 1 on contact idx[k1], least squares S'^T x = -s_k1^T for the
 * others on sub, the network of idx without k1 (refined once when asked);
 * g (n d) and x (m) are scratch */
static int kernel_fixed(const odhs_network *net, odhs_solver *solver, odhs_network *sub, const size_t *idx,
                        size_t m, size_t k1, double *g, double *x, double *y, int refine)
{
    int d = net->dim;
    size_t ck = idx[k1];
    memset(g, 0, net->n * (size_t)d * sizeof *g);
    for (int k = 0; k < d; ++k) {
        g[net->ci[ck] * d + k] = net->nrm[ck * d + k];
        if (net->cj[ck] < net->n) g[net->cj[ck] * d + k] = -net->nrm[ck * d + k];
    }
    int st = odhs_solver_solve_ls(solver, sub, g, x);
    if (!st && refine) st = refine_once(net, solver, sub, m, g, x);
    if (st) return st;
    /* sub's contacts are in the order added: idx without k1 */
    for (size_t a = 0, q = 0; a < m; ++a) y[a] = a == k1 ? 1.0 : x[q++];
    return ODHS_OK;
}

/* fix f0 at contact idx[kk] to 1, least squares for the others */
static int null_sparse(const odhs_network *net, odhs_solver *solver, const size_t *idx, size_t m, size_t kk,
                       double *y, int refine)
{
    odhs_network *sub = odhs__net_subnet(net, idx, m, kk);
    double *g = odhs__calloc(net->n * (size_t)net->dim, sizeof *g);
    double *x = odhs__calloc(m, sizeof *x);
    int st = sub && g && x ? kernel_fixed(net, solver, sub, idx, m, kk, g, x, y, refine) : ODHS_E_NOMEM;
    odhs_network_destroy(sub);
    odhs__free(g);
    odhs__free(x);
    return st;
}

int odhs__null_vector(const odhs_network *net, odhs_solver *solver, double *f0, double *residual)
{
    return odhs__null_vector_ex(net, solver, f0, residual, 0);
}

int odhs__null_vector_ex(const odhs_network *net, odhs_solver *solver, double *f0, double *residual, int refine)
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
        st = null_dense(net, idx, m, NULL, y);
    } else {
        /* try the most recently added contacts first: removing the contact
         * that made the subset isostatic leaves a full-rank network */
        st = ODHS_E_SINGULAR;
        for (size_t t = 0; t < 24 && t < m && st; ++t) {
            st = null_sparse(net, solver, idx, m, m - 1 - t, y, refine);
            if (st) continue;
            /* if f0 vanishes on the fixed contact, the rest is still singular
             * and the solve is not unique: accept only a true null vector */
            memset(full, 0, net->nc * sizeof *full);
            double mean = 0.0;
            for (size_t a = 0; a < m; ++a) {
                full[idx[a]] = y[a];
                mean += fabs(y[a]) / (double)m;
            }
            odhs__net_ST(net, full, F);
            double rmax = 0.0;
            for (size_t k = 0; k < net->n * (size_t)net->dim; ++k) rmax = fmax(rmax, fabs(F[k]));
            if (!(rmax <= 1e-8 * mean)) st = ODHS_E_SINGULAR;
        }
        memset(full, 0, net->nc * sizeof *full);
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

int odhs__null_vector_volume(const odhs_network *net, double *fs)
{
    size_t *idx = NULL, m = 0;
    int st = subset_contacts(net, &idx, &m);
    if (st) return odhs__neterr(net, st, "out of memory");
    double *y = odhs__malloc_array(m + 1, sizeof *y);
    double *rv = odhs__malloc_array(m + 1, sizeof *rv);
    double *F = odhs__malloc_array(net->n * (size_t)net->dim, sizeof *F);
    double *full = odhs__calloc(net->nc + 1, sizeof *full);
    if (!y || !rv || !F || !full) {
        st = odhs__neterr(net, ODHS_E_NOMEM, "out of memory");
        goto done;
    }
    for (size_t a = 0; a < m; ++a) rv[a] = net->dist[idx[a]];
    if (m < 2) {
        st = odhs__neterr(net, ODHS_E_STATE, "too few contacts for a self-stress at zero pressure");
        goto done;
    }
    /* always the SVD: this case (one contact above isostatic under fixed
     * pressure) is rare, and a solver route would need two contacts whose
     * removal leaves a full-rank network, which the newest ones need not be */
    st = null_dense(net, idx, m, rv, y);
    if (st) {
        st = odhs__neterr(net, st == ODHS_E_NOMEM ? st : ODHS_E_SINGULAR, "self-stress at zero pressure: %s",
                          odhs_strerror(st));
        goto done;
    }
    double big = 0.0;
    for (size_t a = 0; a < m; ++a) big = fmax(big, fabs(y[a]));
    if (!(big > 0.0)) {
        st = odhs__neterr(net, ODHS_E_SINGULAR, "self-stress at zero pressure vanishes");
        goto done;
    }
    for (size_t a = 0; a < m; ++a) full[idx[a]] = y[a] / big;
    /* accept only a true kernel vector: S^T fs = 0 and <r|fs> = 0 */
    odhs__net_ST(net, full, F);
    double rmax = 0.0, rf = 0.0, rs = 0.0;
    for (size_t k = 0; k < net->n * (size_t)net->dim; ++k) rmax = fmax(rmax, fabs(F[k]));
    for (size_t a = 0; a < m; ++a) {
        rf += rv[a] * full[idx[a]];
        rs += fabs(rv[a] * full[idx[a]]);
    }
    if (!(rmax <= 1e-8) || !(fabs(rf) <= 1e-8 * rs)) {
        st = odhs__neterr(net, ODHS_E_SINGULAR, "self-stress at zero pressure: residual %.3g, pressure %.3g", rmax,
                          rf / rs);
        goto done;
    }
    memcpy(fs, full, net->nc * sizeof *fs);
done:
    odhs__free(idx);
    odhs__free(y);
    odhs__free(rv);
    odhs__free(F);
    odhs__free(full);
    return st;
}

int odhs__null_vector_any(const odhs_network *net, double *out)
{
    size_t *idx = NULL, m = 0;
    int st = subset_contacts(net, &idx, &m);
    if (st) return odhs__neterr(net, st, "out of memory");
    double *y = odhs__malloc_array(m + 1, sizeof *y);
    if (!y) {
        odhs__free(idx);
        return odhs__neterr(net, ODHS_E_NOMEM, "out of memory");
    }
    st = m < 2 ? ODHS_E_SINGULAR : null_dense(net, idx, m, NULL, y);
    double big = 0.0;
    if (!st) {
        for (size_t a = 0; a < m; ++a) big = fmax(big, fabs(y[a]));
        if (!(big > 0.0)) st = ODHS_E_SINGULAR;
    }
    if (!st) {
        memset(out, 0, net->nc * sizeof *out);
        for (size_t a = 0; a < m; ++a) out[idx[a]] = y[a] / big;
    } else {
        st = odhs__neterr(net, st, "near-kernel of S^T: %s", odhs_strerror(st));
    }
    odhs__free(idx);
    odhs__free(y);
    return st;
}
