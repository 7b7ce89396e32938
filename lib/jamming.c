/* libodhs - jamming: the self-stress f0 of a potentially jammed network
 * (Sect. IV D of Lerner, During & Wyart 2013). */
#include <lapacke.h>
#include <math.h>
#include <stdio.h>
#include <string.h>

#include "internal.h"

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
 * dense matrix (LAPACK dgesvd): the right singular vector of the smallest
 * singular value. Working on S^T itself, not on N = S S^T, keeps the
 * accuracy at eps sigma_max / sigma_2 instead of its square. The kernel must
 * be one-dimensional: the next singular value clearly > 0 (columns of S^T
 * have norm sqrt 2, so singular values are O(1) scaled). */
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
    double *A = odhs__calloc(R * m + 1, sizeof *A);
    double *vt = odhs__malloc_array(m * m + 1, sizeof *vt);
    double *sv = odhs__malloc_array(ns + 1, sizeof *sv);
    double *sup = odhs__malloc_array(ns + 1, sizeof *sup);
    int st = ODHS_OK;
    if (!A || !vt || !sv || !sup) {
        st = ODHS_E_NOMEM;
        goto done;
    }
    /* column a = s_a^T: -n on i's rows, +n on j's (a wall has no block) */
    for (size_t a = 0; a < m; ++a) {
        size_t c = idx[a];
        const double *nc = net->nrm + c * d;
        for (int k = 0; k < d; ++k) {
            A[a * R + row[net->ci[c]] * d + k] = -nc[k];
            if (net->cj[c] < n) A[a * R + row[net->cj[c]] * d + k] = nc[k];
        }
        if (rv) A[a * R + R - 1] = rv[a];
    }
    if (m < 2 || m > R + 1) {
        st = ODHS_E_SINGULAR; /* no kernel, or more than a one-dimensional one */
        goto done;
    }
    lapack_int info = LAPACKE_dgesvd(LAPACK_COL_MAJOR, 'N', 'A', (lapack_int)R, (lapack_int)m, A, (lapack_int)R, sv,
                                     NULL, 1, vt, (lapack_int)m, sup);
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
    odhs__free(vt);
    odhs__free(sv);
    odhs__free(sup);
    return st;
}

odhs_network *odhs__net_subnet(const odhs_network *net, const size_t *idx, size_t m, size_t skip)
{
    int d = net->dim;
    odhs_network *sub = odhs__net_new(d, net->n);
    if (!sub || odhs__net_copy_walls(sub, net)) goto fail;
    if (!idx) m = net->nc;
    for (size_t a = 0; a < m; ++a) {
        if (a == skip) continue;
        size_t c = idx ? idx[a] : a;
        size_t s = odhs__net_add(sub, net->ci[c], net->cj[c], net->kind[c]);
        if (s == SIZE_MAX) goto fail;
        memcpy(sub->nrm + s * d, net->nrm + c * d, (size_t)d * sizeof(double));
        sub->rest[s] = net->rest[c];
        sub->dist[s] = net->dist[c];
        sub->gap[s] = net->gap[c];
    }
    sub->version++;
    return sub;
fail:
    odhs_network_destroy(sub);
    return NULL;
}

/* f0 fixed to 1 on contact idx[k1], least squares S'^T x = -s_k1^T for the
 * others on sub, the network of idx without k1; g (n d) and x (m) are
 * scratch */
static int kernel_fixed(const odhs_network *net, odhs_solver *solver, odhs_network *sub, const size_t *idx,
                        size_t m, size_t k1, double *g, double *x, double *y)
{
    int d = net->dim;
    size_t ck = idx[k1];
    memset(g, 0, net->n * (size_t)d * sizeof *g);
    for (int k = 0; k < d; ++k) {
        g[net->ci[ck] * d + k] = net->nrm[ck * d + k];
        if (net->cj[ck] < net->n) g[net->cj[ck] * d + k] = -net->nrm[ck * d + k];
    }
    int st = odhs_solver_solve_ls(solver, sub, g, x);
    if (st) return st;
    /* sub's contacts are in the order added: idx without k1 */
    for (size_t a = 0, q = 0; a < m; ++a) y[a] = a == k1 ? 1.0 : x[q++];
    return ODHS_OK;
}

/* fix f0 at contact idx[kk] to 1, least squares for the others */
static int null_sparse(const odhs_network *net, odhs_solver *solver, const size_t *idx, size_t m, size_t kk,
                       double *y)
{
    odhs_network *sub = odhs__net_subnet(net, idx, m, kk);
    double *g = odhs__calloc(net->n * (size_t)net->dim, sizeof *g);
    double *x = odhs__calloc(m, sizeof *x);
    int st = sub && g && x ? kernel_fixed(net, solver, sub, idx, m, kk, g, x, y) : ODHS_E_NOMEM;
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
        st = null_dense(net, idx, m, NULL, y);
    } else {
        /* try the most recently added contacts first: removing the contact
         * that made the subset isostatic leaves a full-rank network */
        st = ODHS_E_SINGULAR;
        for (size_t t = 0; t < 24 && t < m && st; ++t) {
            st = null_sparse(net, solver, idx, m, m - 1 - t, y);
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

int odhs_network_null_vector(const odhs_network *net, odhs_solver *solver, double *f0, double *residual)
{
    if (!net) return ODHS_E_NULL;
    if (!f0 && net->nc) return odhs__neterr(net, ODHS_E_NULL, "output pointer is NULL");
    return odhs__null_vector(net, solver, f0, residual);
}

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
        for (size_t c = 0; c < sub->nc; ++c) gap[c] = sub->gap[c];
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

/* ---- certificate ---------------------------------------------------------- */
typedef struct {
    const odhs_network *net;
    const double *r;
    double worst;
} cert_ov_ctx;

static int cert_ov_cb(size_t i, size_t j, const double *rij, double gap, void *vctx)
{
    (void)rij;
    cert_ov_ctx *c = vctx;
    if (odhs__net_find(c->net, i, j) != SIZE_MAX || odhs__same_body(c->net, i, j)) return 0;
    double rel = -gap / (c->r[i] + c->r[j]);
    if (rel > c->worst) c->worst = rel;
    return 0;
}

int odhs_stepper_certificate(const odhs_stepper *st, odhs_jam_certificate *cert)
{
    if (!st) return ODHS_E_NULL;
    char *msg = ((odhs_stepper *)st)->errmsg; /* logically mutable */
    if (!cert) return odhs__err(msg, ODHS_E_NULL, "certificate pointer is NULL");
    if (cert->size < sizeof(size_t))
        return odhs__err(msg, ODHS_E_INVALID, "certificate size %zu: set size = sizeof(odhs_jam_certificate)",
                         cert->size);
    const odhs_system *sys = st->sys;
    const odhs_network *net = st->net;
    odhs_jam_certificate c;
    memset(&c, 0, sizeof c);
    c.size = cert->size < sizeof c ? cert->size : sizeof c;
    int d = net->dim, s;
    size_t n = net->n, nd = n * (size_t)d;
    unsigned char *in = odhs__malloc_array(n, 1);
    double *F = odhs__calloc(nd, sizeof *F);
    if (!in || !F) {
        odhs__free(in);
        odhs__free(F);
        return ODHS_E_NOMEM;
    }
    size_t nbar = 0, ncon = 0;
    if ((s = odhs_network_constrained(net, &nbar, &ncon, in, NULL))) {
        odhs__free(in);
        odhs__free(F);
        return s;
    }
    c.jammed = st->jammed;
    c.n_pivots = (size_t)st->njam_pivots;
    odhs_system_packing_fraction(sys, &c.phi);
    c.n_particles = n;
    c.n_backbone = nbar;
    c.n_rattlers = n - nbar;
    c.n_contacts = net->nc;
    c.n_contacts_backbone = ncon;
    c.n_contacts_isostatic = nbar ? (size_t)d * (nbar - 1) + 1 : 0;
    c.isostatic = nbar > 0 && ncon == c.n_contacts_isostatic;
    c.z = 2.0 * (double)net->nc / (double)n;
    c.z_backbone = nbar ? 2.0 * (double)ncon / (double)nbar : 0.0;
    double vol, fr = 0.0, fsum = 0.0, fmin = INFINITY;
    odhs_system_volume(sys, &vol);
    for (size_t k = 0; k < net->nc; ++k) {
        fr += net->f[k] * net->dist[k];
        c.gap_error = fmax(c.gap_error, fabs(net->gap[k]) / odhs__net_sigma(net, sys, k));
        if (in[net->ci[k]] && (net->cj[k] >= n || in[net->cj[k]])) {
            fsum += net->f[k];
            /* bonds may carry any sign: the smallest force is over contacts */
            if (odhs__can_open(net->kind[k])) fmin = fmin < net->f[k] ? fmin : net->f[k];
        }
    }
    c.pressure = fr / (vol * d);
    double fmean = ncon ? fsum / (double)ncon : 1.0;
    c.min_force = ncon ? fmin / fmean : 0.0;
    odhs__net_ST(net, net->f, F);
    for (size_t i = 0; i < n; ++i) {
        if (!in[i]) continue;
        double s2 = 0.0;
        for (int a = 0; a < d; ++a) s2 += F[i * d + a] * F[i * d + a];
        c.force_balance = fmax(c.force_balance, sqrt(s2) / fabs(fmean));
    }
    cert_ov_ctx oc = {net, sys->r, 0.0};
    s = odhs__pairs(d, n, sys->x, sys->r, sys->rmax, sys->L, sys->gamma, 0.0, cert_ov_cb, &oc);
    c.overlap = oc.worst;
    odhs__free(in);
    odhs__free(F);
    if (s == ODHS_E_NOMEM) return s;
    memcpy(cert, &c, c.size);
    return ODHS_OK;
}

/* ---- contacts file -------------------------------------------------------- */
int odhs_contacts_write(const odhs_network *net, const odhs_system *sys, const char *path)
{
    if (!net) return ODHS_E_NULL;
    if (!sys || !path) return odhs__neterr(net, ODHS_E_NULL, "NULL argument");
    if (sys->n != net->n || sys->dim != net->dim)
        return odhs__neterr(net, ODHS_E_DIM, "system and network differ in N or dimension");
    if (!sys->has_x || !sys->has_r) return odhs__neterr(net, ODHS_E_STATE, "system radii and positions unset");
    size_t len = strlen(path);
    char *tmp = odhs__malloc(len + 32);
    if (!tmp) return odhs__neterr(net, ODHS_E_NOMEM, "out of memory");
    snprintf(tmp, len + 32, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (!f) {
        int e = odhs__neterr(net, ODHS_E_IO, "cannot write %s", tmp);
        odhs__free(tmp);
        return e;
    }
    int d = net->dim, ok = 1;
    ok &= fprintf(f, "# libodhs contacts N=%zu dim=%d Nc=%zu\n", net->n, d, net->nc) > 0;
    ok &= fprintf(f, "# i j %s force gap\n", d == 2 ? "s0 s1" : "s0 s1 s2") > 0;
    for (size_t c = 0; c < net->nc && ok; ++c) {
        size_t i = net->ci[c], j = net->cj[c];
        double v[3] = {0, 0, 0};
        int img[3] = {0, 0, 0};
        if (j < net->n) { /* walls (j = N + w) have no image shift */
            for (int a = 0; a < d; ++a) v[a] = sys->x[j * d + a] - sys->x[i * d + a];
            odhs__min_image(d, sys->L, sys->gamma, v, img);
        }
        if (d == 2)
            ok &= fprintf(f, "%zu %zu %d %d %.17g %.17g\n", i, j, img[0], img[1], net->f[c], net->gap[c]) > 0;
        else
            ok &= fprintf(f, "%zu %zu %d %d %d %.17g %.17g\n", i, j, img[0], img[1], img[2], net->f[c],
                          net->gap[c]) > 0;
    }
    ok &= fflush(f) == 0;
    ok &= fclose(f) == 0;
    if (!ok || rename(tmp, path) != 0) {
        remove(tmp);
        int e = odhs__neterr(net, ODHS_E_IO, "error writing %s", path);
        odhs__free(tmp);
        return e;
    }
    odhs__free(tmp);
    return ODHS_OK;
}
