/* libodhs - scaling collapse of flow curves (include/odhs/analysis.h):
 * phi_J, y and z nu of O = rate^(y/z nu) F((phi - phi_J)/rate^(1/z nu)) by
 * least squares of ln O onto a polynomial master curve, minimised with
 * Nelder-Mead, errors from the Hessian of chi2. */
#include <lapacke.h>
#include <math.h>
#include <string.h>

#include "base/base.h"

#define MAXDEG 7

typedef struct {
    const double *phi, *lr, *lv, *w; /* phi, ln rate, ln value, 1 / relative error */
    size_t n;
    int deg;
    double *A, *b;                   /* n x (deg+1) design, n right-hand side (work) */
    unsigned evals;
    int nomem;
    /* the last fit */
    double coef[MAXDEG + 1], x0, xs;
} cfit;

/* chi2 of the parameters p = (phi_J, y, z nu); INFINITY where undefined */
static double chi2(cfit *c, const double *p)
{
    c->evals++;
    double phij = p[0], y = p[1], znu = p[2];
    if (!isfinite(phij) || !isfinite(y) || !isfinite(znu) || !(znu > 0.05) || !(znu < 100.0)) return INFINITY;
    double inv = 1.0 / znu, q = y / znu;
    size_t n = c->n;
    int m = c->deg + 1;
    double xmin = INFINITY, xmax = -INFINITY;
    for (size_t k = 0; k < n; ++k) {
        double x = (c->phi[k] - phij) * exp(-inv * c->lr[k]);
        if (!isfinite(x)) return INFINITY;
        c->b[k] = x; /* x first, in b */
        xmin = fmin(xmin, x);
        xmax = fmax(xmax, x);
    }
    double x0 = 0.5 * (xmin + xmax), xs = 0.5 * (xmax - xmin);
    if (!(xs > 0.0)) return INFINITY;
    /* column-major design, rows weighted */
    for (size_t k = 0; k < n; ++k) {
        double t = (c->b[k] - x0) / xs, tp = 1.0;
        for (int j = 0; j < m; ++j) {
            c->A[(size_t)j * n + k] = c->w[k] * tp;
            tp *= t;
        }
        c->b[k] = c->w[k] * (c->lv[k] - q * c->lr[k]);
    }
    lapack_int info = LAPACKE_dgels(LAPACK_COL_MAJOR, 'N', (lapack_int)n, m, 1, c->A, (lapack_int)n, c->b,
                                    (lapack_int)n);
    if (info < 0) {
        c->nomem = 1;
        return INFINITY;
    }
    if (info > 0) return INFINITY; /* rank deficient */
    /* the residual is the norm of b[m..n-1] */
    double s = 0.0;
    for (size_t k = (size_t)m; k < n; ++k) s += c->b[k] * c->b[k];
    for (int j = 0; j < m; ++j) c->coef[j] = c->b[j];
    c->x0 = x0;
    c->xs = xs;
    return s;
}

/* Nelder-Mead on 3 parameters from p with steps d; p receives the best */
static double nelder_mead(cfit *c, double *p, const double *d, unsigned maxeval)
{
    double v[4][3], f[4];
    for (int i = 0; i < 4; ++i) {
        memcpy(v[i], p, sizeof v[i]);
        if (i) v[i][i - 1] += d[i - 1];
        f[i] = chi2(c, v[i]);
    }
    for (unsigned it = 0; c->evals < maxeval; ++it) {
        /* order */
        for (int i = 1; i < 4; ++i)
            for (int j = i; j > 0 && f[j] < f[j - 1]; --j) {
                double t = f[j];
                f[j] = f[j - 1];
                f[j - 1] = t;
                double tv[3];
                memcpy(tv, v[j], sizeof tv);
                memcpy(v[j], v[j - 1], sizeof tv);
                memcpy(v[j - 1], tv, sizeof tv);
            }
        if (isfinite(f[3]) && fabs(f[3] - f[0]) <= 1e-12 * (fabs(f[0]) + 1e-30)) break;
        double cen[3] = {0, 0, 0};
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < 3; ++k) cen[k] += v[i][k] / 3.0;
        double xr[3], xe[3], xc[3];
        for (int k = 0; k < 3; ++k) xr[k] = cen[k] + (cen[k] - v[3][k]);
        double fr = chi2(c, xr);
        if (fr < f[0]) {
            for (int k = 0; k < 3; ++k) xe[k] = cen[k] + 2.0 * (cen[k] - v[3][k]);
            double fe = chi2(c, xe);
            if (fe < fr) {
                memcpy(v[3], xe, sizeof xe);
                f[3] = fe;
            } else {
                memcpy(v[3], xr, sizeof xr);
                f[3] = fr;
            }
        } else if (fr < f[2]) {
            memcpy(v[3], xr, sizeof xr);
            f[3] = fr;
        } else {
            int outside = fr < f[3];
            for (int k = 0; k < 3; ++k) xc[k] = outside ? cen[k] + 0.5 * (xr[k] - cen[k]) : cen[k] + 0.5 * (v[3][k] - cen[k]);
            double fc = chi2(c, xc);
            if (fc < (outside ? fr : f[3])) {
                memcpy(v[3], xc, sizeof xc);
                f[3] = fc;
            } else { /* shrink towards the best */
                for (int i = 1; i < 4; ++i) {
                    for (int k = 0; k < 3; ++k) v[i][k] = v[0][k] + 0.5 * (v[i][k] - v[0][k]);
                    f[i] = chi2(c, v[i]);
                }
            }
        }
        (void)it;
    }
    int b = 0;
    for (int i = 1; i < 4; ++i)
        if (f[i] < f[b]) b = i;
    memcpy(p, v[b], sizeof v[b]);
    return f[b];
}

/* the inverse of a symmetric positive definite 3x3 matrix; 0 if not */
static int inv3(double H[3][3], double Hi[3][3])
{
    double a = H[0][0], b = H[0][1], c = H[0][2], d = H[1][1], e = H[1][2], f = H[2][2];
    double A = d * f - e * e, B = c * e - b * f, C = b * e - c * d;
    double det = a * A + b * B + c * C;
    if (!(det > 0.0) || !(a > 0.0) || !(a * d - b * b > 0.0)) return 0;
    Hi[0][0] = A / det;
    Hi[0][1] = Hi[1][0] = B / det;
    Hi[0][2] = Hi[2][0] = C / det;
    Hi[1][1] = (a * f - c * c) / det;
    Hi[1][2] = Hi[2][1] = (b * c - a * e) / det;
    Hi[2][2] = (a * d - b * b) / det;
    return 1;
}

int odhs_collapse_fit(const double *phi, const double *rate, const double *value, const double *rel_err, size_t n,
                      int degree, const double *guess, odhs_collapse *out)
{
    odhs__create_begin();
    if (!phi || !rate || !value || !out) return odhs__create_err(ODHS_E_NULL, "odhs_collapse_fit: NULL argument");
    size_t size = out->size;
    if (size < offsetof(odhs_collapse, phi_j) + sizeof(double))
        return odhs__create_err(ODHS_E_INVALID, "odhs_collapse_fit: out->size = %zu: set it to sizeof", size);
    if (degree < 1 || degree > MAXDEG)
        return odhs__create_err(ODHS_E_INVALID, "odhs_collapse_fit: degree %d not in 1..%d", degree, MAXDEG);
    if (n < (size_t)degree + 5)
        return odhs__create_err(ODHS_E_EMPTY, "odhs_collapse_fit: %zu points for degree %d (need %d)", n, degree,
                                degree + 5);
    int two_rates = 0;
    for (size_t k = 0; k < n; ++k) {
        double e = rel_err ? rel_err[k] : 0.01;
        if (!isfinite(phi[k]) || !isfinite(rate[k]) || !isfinite(value[k]) || !isfinite(e))
            return odhs__create_err(ODHS_E_NONFINITE, "odhs_collapse_fit: point %zu is not finite", k);
        if (!(rate[k] > 0.0) || !(value[k] > 0.0) || !(e > 0.0))
            return odhs__create_err(ODHS_E_INVALID, "odhs_collapse_fit: point %zu: rate %g, value %g, error %g must be "
                                    "> 0", k, rate[k], value[k], e);
        if (rate[k] != rate[0]) two_rates = 1;
    }
    if (!two_rates) return odhs__create_err(ODHS_E_EMPTY, "odhs_collapse_fit: every point has the same rate");
    if (guess && (!isfinite(guess[0]) || !isfinite(guess[1]) || !isfinite(guess[2]) || !(guess[2] > 0.05)))
        return odhs__create_err(ODHS_E_INVALID, "odhs_collapse_fit: guess (%g, %g, %g): z nu must be > 0.05", guess[0],
                                guess[1], guess[2]);
    size_t m = (size_t)degree + 1;
    double *mem = odhs__malloc_array(n, (m + 5) * sizeof(double));
    if (!mem) return odhs__create_err(ODHS_E_NOMEM, "odhs_collapse_fit: out of memory");
    double *lr = mem, *lv = mem + n, *w = mem + 2 * n, *b = mem + 3 * n, *A = mem + 4 * n;
    for (size_t k = 0; k < n; ++k) {
        lr[k] = log(rate[k]);
        lv[k] = log(value[k]);
        w[k] = 1.0 / (rel_err ? rel_err[k] : 0.01);
    }
    cfit c = {phi, lr, lv, w, n, degree, A, b, 0, 0, {0}, 0, 0};
    double p[3];
    if (guess) memcpy(p, guess, sizeof p);
    else {
        double pm = phi[0];
        for (size_t k = 1; k < n; ++k) pm = fmax(pm, phi[k]);
        p[0] = pm;
        p[1] = 1.0;
        p[2] = 3.0;
    }
    const double step[3] = {0.005, 0.1, 0.3}, small[3] = {0.0005, 0.01, 0.03};
    double f = nelder_mead(&c, p, step, 20000);
    if (isfinite(f)) f = nelder_mead(&c, p, small, c.evals + 20000);
    int s = ODHS_OK;
    if (c.nomem) s = odhs__create_err(ODHS_E_NOMEM, "odhs_collapse_fit: out of memory in LAPACK");
    else if (!isfinite(f))
        s = odhs__create_err(ODHS_E_NOCONV, "odhs_collapse_fit: no finite minimum from the guess (%g, %g, %g)", p[0],
                             p[1], p[2]);
    odhs_collapse r;
    memset(&r, 0, sizeof r);
    if (!s) {
        /* the Hessian by central differences */
        const double h[3] = {1e-4 * fmax(fabs(p[0]), 1e-2), 1e-3 * fmax(fabs(p[1]), 0.1), 1e-3 * fmax(p[2], 0.1)};
        double H[3][3], Hi[3][3];
        for (int i = 0; i < 3; ++i)
            for (int j = i; j < 3; ++j) {
                double q[3], fpp, fpm, fmp, fmm;
                memcpy(q, p, sizeof q);
                q[i] += h[i];
                q[j] += h[j];
                fpp = chi2(&c, q);
                memcpy(q, p, sizeof q);
                q[i] += h[i];
                q[j] -= h[j];
                fpm = chi2(&c, q);
                memcpy(q, p, sizeof q);
                q[i] -= h[i];
                q[j] += h[j];
                fmp = chi2(&c, q);
                memcpy(q, p, sizeof q);
                q[i] -= h[i];
                q[j] -= h[j];
                fmm = chi2(&c, q);
                H[i][j] = H[j][i] = (fpp - fpm - fmp + fmm) / (4.0 * h[i] * h[j]);
            }
        f = chi2(&c, p); /* the fit at the minimum into c */
        size_t dof = n - m - 3;
        double scale = dof > 0 && f / (double)dof > 1.0 ? f / (double)dof : 1.0;
        if (!inv3(H, Hi) || !isfinite(Hi[0][0] + Hi[1][1] + Hi[2][2])) {
            s = odhs__create_err(ODHS_E_SINGULAR, "odhs_collapse_fit: chi2 is flat at (%g, %g, %g): an exponent is not "
                                 "determined by these data", p[0], p[1], p[2]);
        } else {
            r.phi_j = p[0];
            r.y = p[1];
            r.znu = p[2];
            r.phi_j_err = sqrt(2.0 * Hi[0][0] * scale);
            r.y_err = sqrt(2.0 * Hi[1][1] * scale);
            r.znu_err = sqrt(2.0 * Hi[2][2] * scale);
            r.q = p[1] / p[2];
            r.chi2 = f;
            r.dof = dof;
            r.degree = degree;
            memcpy(r.coef, c.coef, m * sizeof(double));
            r.x0 = c.x0;
            r.xs = c.xs;
            r.evaluations = c.evals;
            r.size = size;
        }
    }
    odhs__free(mem);
    if (s) return s;
    memcpy(out, &r, size < sizeof r ? size : sizeof r);
    return ODHS_OK;
}
