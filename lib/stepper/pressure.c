/* libodhs - pressure control (Sect. II C of the paper): the forces and the
 * compression rate kappa at fixed pressure, on hypostatic and on isostatic
 * networks, and the drift correction of a flowing isostatic network.
 *
 * The equations (docs/guide.md section 6): N f = b + a r, <r|f> = P, with
 * N = S S^T, b the affine right-hand side without the pressure part, r the
 * contact distances, a = gdot kappa / xi0 and P = p V d. On a hypostatic
 * network N is invertible and f = N^-1 b + a N^-1 r (eq. 25 of the paper).
 * On an isostatic one (one self-stress f0) N is singular but the bordered
 * matrix [N -r; r^T 0] is not (<r|f0> != 0), and the network still flows:
 * the volume is the extra degree of freedom. Both are solved here exactly,
 * without ever factorising the singular N, through the network N_k without
 * one contact k (pressure_bordered). */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

/* scratch vectors of st->fpj, nc each: f0 and freg in the network's order
 * (freg[k] = 0), then u, y_b, y_r, w, rhs in the order of N_k */
enum { FPJ_F0, FPJ_FREG, FPJ_U, FPJ_YB, FPJ_YR, FPJ_W, FPJ_RHS, FPJ_VECTORS };
/* the bordered route replaces eq. 25 when |a| max|N^-1 r| exceeds this many
 * times max|f| (digits lost to cancellation near an isostatic network) */
#define CANCEL_MAX 1e4

static double *fpj_vec(const odhs_stepper *st, int which) { return st->fpj + (size_t)which * st->net->nc; }

/* room for the scratch vectors, the residual (nd) and its scratch (nd) */
static int fpj_reserve(odhs_stepper *st)
{
    size_t need = FPJ_VECTORS * (st->net->nc + 1);
    if (odhs__reserve((void **)&st->fpj, &st->fpjcap, need, sizeof *st->fpj) ||
        odhs__reserve((void **)&st->pj_res, &st->pj_rescap, 2 * st->nd, sizeof *st->pj_res))
        return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    return ODHS_OK;
}

/* st->iso_sub: the network without contact k, rebuilt when the network or
 * k changed */
static int sub_for(odhs_stepper *st, size_t k)
{
    odhs_network *net = st->net;
    if (st->iso_sub && st->iso_sub_version == net->version && st->iso_k == k) return ODHS_OK;
    odhs_network_destroy(st->iso_sub);
    st->iso_sub = odhs__net_subnet(net, NULL, net->nc, k);
    if (!st->iso_sub) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    st->iso_sub_version = net->version;
    st->iso_k = k;
    st->iso_ci = net->ci[k];
    st->iso_cj = net->cj[k];
    return ODHS_OK;
}

/* N_k x = rhs (both in the order of N_k). The sub-network is a scratch
 * network: reuse 0, so that the solver checks the operator itself (a new
 * one may have the address and version of an old one). */
static int sub_solve(odhs_stepper *st, const double *rhs, double *x, double tol)
{
    memset(x, 0, (st->net->nc - 1) * sizeof *x);
    int s = tol > 0.0 ? odhs__solver_solve_relaxed(st->sol, st->iso_sub, rhs, x, tol, 0)
                      : odhs__solver_solve(st->sol, st->iso_sub, rhs, x, 0);
    if (s) return odhs__sterr(st, s, "force solve without contact %zu-%zu: %s", st->iso_ci, st->iso_cj,
                              odhs_solver_errmsg(st->sol));
    return ODHS_OK;
}

/* v (nc, the network's order) without entry k into out (nc - 1) */
static void drop_k(const double *v, size_t nc, size_t k, double *out)
{
    memcpy(out, v, k * sizeof *out);
    memcpy(out + k, v + k + 1, (nc - 1 - k) * sizeof *out);
}

/* The basis of the bordered solve for contact k: N_k, u = S_k s_k^T, w =
 * N_k^-1 u and the residual res = s_k^T - S_k^T w (st->pj_res, nd), whose
 * squared norm q = |s_k|^2 - u.w is the part of row k of S outside the span
 * of the others: 0 on an isostatic network with f0[k] != 0, where
 * f0 = (-w, 1) up to scale. Kept while the network and k are unchanged. */
static int bordered_basis(odhs_stepper *st, size_t k)
{
    odhs_network *net = st->net;
    int s, dim = st->dim;
    if (st->iso_basis_version == net->version && st->iso_sub && st->iso_k == k) return ODHS_OK;
    st->iso_basis_version = 0;
    if ((s = sub_for(st, k))) return s;
    double *g = st->pj_res, *u = fpj_vec(st, FPJ_U), *w = fpj_vec(st, FPJ_W);
    memset(g, 0, st->nd * sizeof *g);
    const double *n = net->nrm + k * dim;
    for (int a = 0; a < dim; ++a) {
        g[net->ci[k] * dim + a] = -n[a];
        if (net->cj[k] < st->n) g[net->cj[k] * dim + a] = n[a];
    }
    odhs__net_S(st->iso_sub, g, u);
    if ((s = sub_solve(st, u, w, 0.0))) return s;
    double *sw = st->pj_res + st->nd;
    odhs__net_ST(st->iso_sub, w, sw);
    for (size_t a = 0; a < st->nd; ++a) g[a] -= sw[a];
    st->iso_basis_version = net->version;
    return ODHS_OK;
}

/* Fixed pressure through N_k (k: a contact whose removal leaves N_k
 * invertible). With f = (f_rest, f_k), f_rest = y_b + a y_r - f_k w
 * (y_b = N_k^-1 b_rest, y_r = N_k^-1 r_rest), row k and <r|f> = P leave
 *     [ q  -c ] [f_k]   [ b_k - u.y_b ]
 *     [ c   s ] [ a ] = [ P - r.y_b   ],   c = r_k - r.w,  s = r.y_r > 0,
 * with determinant q s + c^2 > 0 (c = <r|f0>/f0_k on an isostatic network,
 * q > 0 otherwise). The velocities are S^T freg + f_k res (freg = (y_b +
 * a y_r, 0)), exact without the cancellation of a huge f_k against S^T w. */
static int pressure_bordered(odhs_stepper *st, const double *b, double gd, size_t k)
{
    odhs_network *net = st->net;
    odhs_driver *drv = st->drv;
    size_t nc = net->nc, m = nc - 1;
    int s;
    if ((s = bordered_basis(st, k))) return s;
    double *u = fpj_vec(st, FPJ_U), *w = fpj_vec(st, FPJ_W), *yb = fpj_vec(st, FPJ_YB), *yr = fpj_vec(st, FPJ_YR);
    double *rhs = fpj_vec(st, FPJ_RHS), *freg = fpj_vec(st, FPJ_FREG);
    drop_k(b, nc, k, rhs);
    if ((s = sub_solve(st, rhs, yb, 0.0))) return s;
    drop_k(net->dist, nc, k, rhs);
    if ((s = sub_solve(st, rhs, yr, 0.0))) return s;
    double q = 0.0, c = net->dist[k], sr = 0.0, uyb = 0.0, ryb = 0.0, vol;
    for (size_t a = 0; a < st->nd; ++a) q += st->pj_res[a] * st->pj_res[a];
    for (size_t a = 0; a < m; ++a) {
        c -= rhs[a] * w[a];
        sr += rhs[a] * yr[a];
        uyb += u[a] * yb[a];
        ryb += rhs[a] * yb[a];
    }
    odhs_system_volume(st->sys, &vol);
    double P = drv->p * vol * st->dim, r1 = b[k] - uyb, r2 = P - ryb, det = q * sr + c * c;
    if (!(det > 0.0) || !isfinite(det))
        return odhs__sterr(st, ODHS_E_SINGULAR, "fixed pressure at t = %.17g: the contacts cannot carry the pressure",
                           st->time);
    double fk = (r1 * sr + c * r2) / det, a = (q * r2 - c * r1) / det;
    for (size_t x = 0; x < m; ++x) {
        size_t cn = x < k ? x : x + 1;
        freg[cn] = yb[x] + a * yr[x];
        net->f[cn] = freg[cn] - fk * w[x];
    }
    freg[k] = 0.0;
    net->f[k] = fk;
    st->pj_alpha = fk;
    double ceff = a * drv->xi0;
    st->kappa = ceff / gd;
    if (!isfinite(st->kappa)) st->kappa = ceff;
    odhs__st_set_gradient(st, ceff);
    st->pj_bordered = 1;
    return ODHS_OK;
}

/* f0 (normalised: max |f0| = 1, sum > 0) into the FPJ_F0 vector */
static void f0_normalise(odhs_stepper *st)
{
    double *f0 = fpj_vec(st, FPJ_F0), big = 0.0, sum = 0.0;
    for (size_t c = 0; c < st->net->nc; ++c) {
        big = fmax(big, fabs(f0[c]));
        sum += f0[c];
    }
    double sc = (sum < 0.0 ? -1.0 : 1.0) / big;
    for (size_t c = 0; c < st->net->nc; ++c) f0[c] *= sc;
}

/* f0 from the basis of contact k: (-w, 1); 0 when it is a true kernel
 * vector of S^T (residual |res| <= 1e-9 max |f0|) with f0[k] not small
 * (>= 1e-3 max|f0|: N_k well conditioned), else ODHS_E_SINGULAR */
static int f0_from_basis(odhs_stepper *st, size_t k)
{
    size_t nc = st->net->nc;
    double *w = fpj_vec(st, FPJ_W), big = 1.0, rmax = 0.0;
    for (size_t x = 0; x < nc - 1; ++x) big = fmax(big, fabs(w[x]));
    for (size_t a = 0; a < st->nd; ++a) rmax = fmax(rmax, fabs(st->pj_res[a]));
    if (!(rmax <= 1e-9 * big) || !(big <= 1e3)) return ODHS_E_SINGULAR;
    double *f0 = fpj_vec(st, FPJ_F0);
    for (size_t x = 0; x < nc - 1; ++x) f0[x < k ? x : x + 1] = -w[x];
    f0[k] = 1.0;
    f0_normalise(st);
    return ODHS_OK;
}

/* The self-stress f0 of the current isostatic network into FPJ_F0 and the
 * bordered basis for its largest contact, kept while the network's version
 * is unchanged. One sparse solve: on N without the contact of the last f0's
 * largest entry (or the newest contact), which stays in the support of f0
 * from one event to the next; the dense SVD (odhs__null_vector) when that
 * contact has left it. */
int odhs__st_isostatic_f0(odhs_stepper *st)
{
    odhs_network *net = st->net;
    size_t nc = net->nc;
    int s;
    if (st->fpj_version == net->version && st->iso_sub && st->iso_basis_version == net->version) return ODHS_OK;
    if (nc < 2) return odhs__sterr(st, ODHS_POTENTIALLY_JAMMED, "isostatic network with %zu contact(s)", nc);
    if ((s = fpj_reserve(st))) return s;
    size_t k = st->iso_ci == SIZE_MAX ? SIZE_MAX : odhs__net_find(net, st->iso_ci, st->iso_cj);
    if (k == SIZE_MAX) k = nc - 1;
    s = bordered_basis(st, k);
    if (s == ODHS_E_NOMEM) return s;
    int from_k = !s && !f0_from_basis(st, k); /* f0 is the basis of k's */
    if (!from_k) {
        if ((s = odhs__null_vector(net, st->sol, fpj_vec(st, FPJ_F0), NULL)))
            return odhs__sterr(st, s == ODHS_E_NOMEM ? s : ODHS_POTENTIALLY_JAMMED,
                               "isostatic network at t = %.17g: %s", st->time, net->errmsg);
        f0_normalise(st);
    }
    /* the basis of the largest |f0| (the best conditioned N_k), and f0 from
     * that basis: the result does not depend on the guess (a restored
     * checkpoint, which has none, continues bit for bit) */
    const double *f0 = fpj_vec(st, FPJ_F0);
    for (int it = 0; it < 3; ++it) {
        size_t kmax = 0;
        for (size_t c = 1; c < nc; ++c)
            if (fabs(f0[c]) > fabs(f0[kmax])) kmax = c;
        if (from_k && kmax == k) break;
        if ((s = bordered_basis(st, kmax))) return s;
        k = kmax;
        if (!(from_k = !f0_from_basis(st, k))) break; /* keep the f0 we have */
    }
    st->fpj_version = net->version;
    return ODHS_OK;
}

/* ---- the forces ------------------------------------------------------------ */
/* Fixed pressure: f = x2 + a x1 with N x2 = b, N x1 = r and a from the
 * pressure (eq. 25) on a hypostatic network; the bordered solve on an
 * isostatic one, and on a hypostatic one where eq. 25 fails (an uncounted
 * self-stress makes N singular) or loses digits to cancellation (nearly
 * isostatic). Forces into net->f, kappa and G set. kappa is clamped to
 * kappa_max only where the contacts cannot carry the pressure (no contacts,
 * <r|N^-1 r> <= 0): elsewhere the clamp would break the pressure. */
int odhs__st_pressure_forces(odhs_stepper *st)
{
    odhs_network *net = st->net;
    odhs_driver *drv = st->drv;
    size_t nc = net->nc;
    int dim = st->dim, s;
    double xi0 = drv->xi0, gd = odhs__st_shear_rate(st);
    if (nc == 0) {
        st->kappa = drv->kappa_max * (gd > 0 ? 1.0 : -1.0);
        odhs__st_set_gradient(st, gd * st->kappa);
        return ODHS_OK;
    }
    double *b = st->cb;
    odhs__st_affine_rhs(st, b);
    st->work_pressure++;
    long excess;
    if ((s = odhs__net_excess(net, &excess))) return odhs__sterr(st, s, "%s", net->errmsg);
    if (excess == 1) {
        if ((s = odhs__st_isostatic_f0(st))) return s;
        return pressure_bordered(st, b, gd, st->iso_k);
    }
    double *x1 = st->cx;
    memset(x1, 0, nc * sizeof *x1);
    memset(net->f, 0, nc * sizeof *net->f);
    if ((s = odhs__st_solve(st, b, net->f)) || (s = odhs__st_solve(st, net->dist, x1))) {
        if (s != ODHS_E_SINGULAR && s != ODHS_E_NOCONV) return s;
        /* N singular (or so nearly that an iterative solver fails): a
         * self-stress the contact count does not show (next to a floppy
         * mode); remove its largest contact */
        if ((s = fpj_reserve(st))) return s;
        double *y = fpj_vec(st, FPJ_F0);
        if ((s = odhs__null_vector_any(net, y)))
            return odhs__sterr(st, s == ODHS_E_NOMEM ? s : ODHS_E_SINGULAR, "fixed pressure at t = %.17g: %s",
                               st->time, net->errmsg);
        st->fpj_version = 0;
        size_t k = 0;
        for (size_t c = 1; c < nc; ++c)
            if (fabs(y[c]) > fabs(y[k])) k = c;
        return pressure_bordered(st, b, gd, k);
    }
    double rx1 = 0.0, rx2 = 0.0, vol;
    for (size_t c = 0; c < nc; ++c) {
        rx1 += net->dist[c] * x1[c];
        rx2 += net->dist[c] * net->f[c];
    }
    odhs_system_volume(st->sys, &vol);
    double kappa = xi0 * (drv->p * vol * dim - rx2) / (gd * rx1);
    if (!(rx1 > 0.0) || !isfinite(kappa)) {
        /* the contacts cannot carry the pressure: compress at kappa_max */
        kappa = drv->kappa_max * (gd > 0 ? 1.0 : -1.0);
    } else {
        double a = gd * kappa / xi0, xmax = 0.0, fmaxv = 0.0;
        size_t kx = 0;
        for (size_t c = 0; c < nc; ++c) {
            if (fabs(x1[c]) > xmax) {
                xmax = fabs(x1[c]);
                kx = c;
            }
            fmaxv = fmax(fmaxv, fabs(net->f[c] + a * x1[c]));
        }
        if (fabs(a) * xmax > CANCEL_MAX * fmaxv && nc > 1) {
            if ((s = fpj_reserve(st))) return s;
            st->fpj_version = 0;
            return pressure_bordered(st, b, gd, kx);
        }
    }
    st->kappa = kappa;
    double a = gd * kappa / xi0;
    for (size_t c = 0; c < nc; ++c) net->f[c] += a * x1[c];
    odhs__st_set_gradient(st, gd * kappa);
    return ODHS_OK;
}

/* The self-stress at zero pressure h (S^T h = 0, <r|h> = 0, max |h| = 1) of a
 * network one contact above isostatic, by two sparse solves: without contact
 * k1 (the newest, which made it over-constrained) and k2 (the largest of the
 * isostatic network's f0 before it, iso_ci-iso_cj) the network N'' is
 * invertible and S^T has rank nc - 2 as before, so s_k1 and s_k2 are in the
 * span of the other rows: h = (-(w1 + t w2), 1, t) with N'' w_a = S'' s_ka^T
 * is a self-stress for every t, and <r|h> = 0 fixes t. Checked (S^T h and
 * <r|h> at 1e-9 of their scale); ODHS_E_SINGULAR when the choice does not
 * fit (the caller then takes the dense SVD). */
static int zero_pressure_sparse(odhs_stepper *st, double *h)
{
    odhs_network *net = st->net;
    size_t nc = net->nc, nd = st->nd, k1 = nc - 1, k2;
    int dim = st->dim, s = ODHS_OK;
    if (nc < 3 || st->iso_ci == SIZE_MAX) return ODHS_E_SINGULAR;
    k2 = odhs__net_find(net, st->iso_ci, st->iso_cj);
    if (k2 == SIZE_MAX || k2 == k1) return ODHS_E_SINGULAR;
    size_t m = nc - 2, *idx = odhs__malloc_array(m, sizeof *idx);
    double *g = odhs__calloc(3 * nd, sizeof *g), *u = odhs__calloc(4 * m, sizeof *u);
    odhs_network *sub = NULL;
    if (!idx || !g || !u) {
        s = ODHS_E_NOMEM;
        goto done;
    }
    for (size_t c = 0, q = 0; c < nc; ++c)
        if (c != k1 && c != k2) idx[q++] = c;
    if (!(sub = odhs__net_subnet(net, idx, m, SIZE_MAX))) {
        s = ODHS_E_NOMEM;
        goto done;
    }
    double *w1 = u + 2 * m, *w2 = u + 3 * m, *sw = g + 2 * nd;
    const size_t ks[2] = {k1, k2};
    for (int a = 0; a < 2; ++a) {
        double *ga = g + (size_t)a * nd;
        const double *n = net->nrm + ks[a] * dim;
        for (int b = 0; b < dim; ++b) {
            ga[net->ci[ks[a]] * dim + b] = -n[b];
            if (net->cj[ks[a]] < st->n) ga[net->cj[ks[a]] * dim + b] = n[b];
        }
        odhs__net_S(sub, ga, u + (size_t)a * m);
        if ((s = odhs__solver_solve(st->sol, sub, u + (size_t)a * m, a ? w2 : w1, 0))) goto done;
    }
    double rw1 = 0.0, rw2 = 0.0;
    for (size_t q = 0; q < m; ++q) {
        rw1 += net->dist[idx[q]] * w1[q];
        rw2 += net->dist[idx[q]] * w2[q];
    }
    double den = rw2 - net->dist[k2], t = (net->dist[k1] - rw1) / den;
    if (!(fabs(den) > 0.0) || !isfinite(t)) {
        s = ODHS_E_SINGULAR;
        goto done;
    }
    for (size_t q = 0; q < m; ++q) h[idx[q]] = -(w1[q] + t * w2[q]);
    h[k1] = 1.0;
    h[k2] = t;
    /* a true kernel vector of [S^T; r^T]? */
    double big = 0.0, rh = 0.0, rs = 0.0, res = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        big = fmax(big, fabs(h[c]));
        rh += net->dist[c] * h[c];
        rs += fabs(net->dist[c] * h[c]);
    }
    odhs__net_ST(net, h, sw);
    for (size_t k = 0; k < nd; ++k) res = fmax(res, fabs(sw[k]));
    if (!(res <= 1e-9 * big) || !(fabs(rh) <= 1e-9 * rs) || !(big <= 1e6)) {
        s = ODHS_E_SINGULAR;
        goto done;
    }
    for (size_t c = 0; c < nc; ++c) h[c] /= big;
done:
    odhs_network_destroy(sub);
    odhs__free(idx);
    odhs__free(g);
    odhs__free(u);
    return s;
}

int odhs__st_zero_pressure_stress(odhs_stepper *st, double *h)
{
    int s = zero_pressure_sparse(st, h);
    if (s == ODHS_E_NOMEM) return odhs__sterr(st, s, "out of memory");
    if (!s) return ODHS_OK;
    if ((s = odhs__null_vector_volume(st->net, h)))
        return odhs__sterr(st, s == ODHS_E_NOMEM ? s : ODHS_POTENTIALLY_JAMMED, "fixed pressure at t = %.17g: %s",
                           st->time, st->net->errmsg);
    return ODHS_OK;
}

/* Fixed pressure, one contact more than isostatic: the forces diverge along
 * the self-stress fs at zero pressure, with the sign that resists the
 * driving (<fs|b> > 0); its most negative contact opens (fs has both signs,
 * since <fs|r> = 0). fs into net->f. */
int odhs__st_pressure_open_direction(odhs_stepper *st)
{
    odhs_network *net = st->net;
    int s;
    st->work_pressure++;
    if ((s = odhs__st_reserve_contacts(st, net->nc))) return odhs__sterr(st, s, "out of memory");
    odhs__st_affine_rhs(st, st->cb);
    if ((s = odhs__st_zero_pressure_stress(st, net->f))) return s;
    double fb = 0.0, fmin = 0.0;
    for (size_t c = 0; c < net->nc; ++c) fb += net->f[c] * st->cb[c];
    for (size_t c = 0; c < net->nc; ++c) {
        if (fb < 0.0) net->f[c] = -net->f[c];
        if (odhs__can_open(net->kind[c])) fmin = fmin < net->f[c] ? fmin : net->f[c];
    }
    if (!(fmin < -EPS_F))
        return odhs__sterr(st, ODHS_POTENTIALLY_JAMMED,
                     "fixed pressure at t = %.17g: the self-stress at zero pressure opens no contact", st->time);
    return ODHS_OK;
}

/* Drift correction of an isostatic network under fixed pressure (see
 * correct): fills Z with the isotropic gradient and st->cx with the
 * correction's contact forces. The gap component along f0 goes with an
 * isotropic rescaling; the rest is solved on N_k (the row k of S follows
 * from the others through f0, and so does its equation); x[k] = 0. */
int odhs__st_correct_isostatic(odhs_stepper *st, double *Z)
{
    odhs_network *net = st->net;
    size_t nc = net->nc, k;
    int s;
    st->work_pressure++;
    if ((s = odhs__st_isostatic_f0(st))) return s;
    k = st->iso_k;
    double *f0 = fpj_vec(st, FPJ_F0), *rhs = fpj_vec(st, FPJ_RHS), *x = fpj_vec(st, FPJ_YB);
    double fg = 0.0, fr = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        fg += f0[c] * net->gap[c];
        fr += f0[c] * net->dist[c];
    }
    double eps = fr != 0.0 ? fg / fr : 0.0;
    for (int a = 0; a < st->dim; ++a) Z[3 * a + a] = -eps;
    for (size_t c = 0, q = 0; c < nc; ++c)
        if (c != k) rhs[q++] = net->gap[c] - eps * net->dist[c];
    if ((s = sub_solve(st, rhs, x, 0.0))) return s;
    for (size_t c = 0, q = 0; c < nc; ++c) st->cx[c] = c == k ? 0.0 : x[q++];
    return ODHS_OK;
}
