/* libodhs - analysis (include/odhs/analysis.h): time-series statistics,
 * histograms, power-law exponents, backbone forces, gaps of nearly touching
 * pairs, the transverse velocity correlation. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "network/network.h"
#include "system/system.h"

/* ---- time series --------------------------------------------------------------- */
static int finite_all(const double *x, size_t n, const char *who)
{
    for (size_t k = 0; k < n; ++k)
        if (!isfinite(x[k])) return odhs__create_err(ODHS_E_NONFINITE, "%s: sample %zu is not finite", who, k);
    return ODHS_OK;
}

/* mean and the sum of squared deviations, two passes */
static void mean_ss(const double *x, size_t n, double *mean, double *ss)
{
    double m = 0.0;
    for (size_t k = 0; k < n; ++k) m += x[k];
    m /= (double)n;
    double s = 0.0, c = 0.0;
    for (size_t k = 0; k < n; ++k) {
        double d = x[k] - m;
        s += d * d;
        c += d;
    }
    *mean = m;
    *ss = s - c * c / (double)n; /* corrected two-pass */
}

/* autocovariance C(t) / C(0) for t = 0..maxlag into rho */
static void autocorr(const double *x, size_t n, double m, size_t maxlag, double *rho)
{
    double c0 = 0.0;
    for (size_t k = 0; k < n; ++k) c0 += (x[k] - m) * (x[k] - m);
    c0 /= (double)n;
    rho[0] = 1.0;
    for (size_t t = 1; t <= maxlag; ++t) {
        double c = 0.0;
        for (size_t k = 0; k + t < n; ++k) c += (x[k] - m) * (x[k + t] - m);
        c /= (double)(n - t);
        rho[t] = c0 > 0.0 ? c / c0 : 0.0;
    }
}

int odhs_series_event_split(const double *before, const double *after, const unsigned char *at_event, size_t n,
                            double *jumps, size_t *njumps, double *drops, size_t *ndrops)
{
    odhs__create_begin();
    if (!before || !after || !at_event || !njumps || !ndrops)
        return odhs__create_err(ODHS_E_NULL, "odhs_series_event_split: NULL argument");
    if (n == 0) return odhs__create_err(ODHS_E_EMPTY, "odhs_series_event_split: no samples");
    int s = finite_all(before, n, "odhs_series_event_split (before)");
    if (!s) s = finite_all(after, n, "odhs_series_event_split (after)");
    if (s) return s;
    size_t nj = 0, nd = 0, last = SIZE_MAX;
    for (size_t k = 0; k < n; ++k) {
        if (!at_event[k]) continue;
        if (jumps) jumps[nj] = after[k] - before[k];
        nj++;
        if (last != SIZE_MAX) {
            if (drops) drops[nd] = after[last] - before[k];
            nd++;
        }
        last = k;
    }
    *njumps = nj;
    *ndrops = nd;
    return ODHS_OK;
}

int odhs_series_autocorrelation(const double *x, size_t n, size_t maxlag, double *rho)
{
    odhs__create_begin();
    if (!x || !rho) return odhs__create_err(ODHS_E_NULL, "odhs_series_autocorrelation: NULL argument");
    if (n < 2) return odhs__create_err(ODHS_E_EMPTY, "odhs_series_autocorrelation: %zu samples (need 2)", n);
    if (maxlag >= n)
        return odhs__create_err(ODHS_E_RANGE, "odhs_series_autocorrelation: lag %zu >= n = %zu", maxlag, n);
    int s = finite_all(x, n, "odhs_series_autocorrelation");
    if (s) return s;
    double m, ss;
    mean_ss(x, n, &m, &ss);
    autocorr(x, n, m, maxlag, rho);
    return ODHS_OK;
}

/* Sokal's automatic window: tau(W) = 1/2 + sum_{t=1}^{W} rho(t) with the
 * smallest W >= c tau(W), c = 5; lags computed in growing chunks */
static int tau_integrated(const double *x, size_t n, double m, double *tau, size_t *window)
{
    size_t cap = n / 2 > 0 ? n / 2 : 1, have = 0;
    double *rho = NULL;
    double t = 0.5;
    for (size_t w = 1; w < cap; ++w) {
        if (w > have) { /* the next chunk of lags */
            size_t want = have ? 2 * have : 64;
            if (want >= cap) want = cap - 1;
            double *q = odhs__realloc(rho, (want + 1) * sizeof *q);
            if (!q) {
                odhs__free(rho);
                return odhs__create_err(ODHS_E_NOMEM, "odhs_series_stats_compute: out of memory");
            }
            rho = q;
            autocorr(x, n, m, want, rho);
            have = want;
        }
        t += rho[w];
        if ((double)w >= 5.0 * t) {
            *tau = t > 0.5 ? t : 0.5;
            *window = w;
            odhs__free(rho);
            return ODHS_OK;
        }
    }
    odhs__free(rho);
    *tau = t > 0.5 ? t : 0.5; /* no window fits: the series is too short */
    *window = cap - 1;
    return ODHS_OK;
}

int odhs_series_stats_compute(const double *x, size_t n, odhs_series_stats *out)
{
    odhs__create_begin();
    if (!x || !out) return odhs__create_err(ODHS_E_NULL, "odhs_series_stats_compute: NULL argument");
    size_t size = out->size;
    if (size < offsetof(odhs_series_stats, mean) + sizeof(double))
        return odhs__create_err(ODHS_E_INVALID, "odhs_series_stats_compute: out->size = %zu: set it to sizeof", size);
    if (n < 4) return odhs__create_err(ODHS_E_EMPTY, "odhs_series_stats_compute: %zu samples (need 4)", n);
    int s = finite_all(x, n, "odhs_series_stats_compute");
    if (s) return s;
    odhs_series_stats r;
    memset(&r, 0, sizeof r);
    r.size = size;
    r.n = n;
    double ss;
    mean_ss(x, n, &r.mean, &ss);
    r.variance = ss / (double)(n - 1);
    /* block averaging: level k has blocks of 2^k samples */
    double *b = odhs__malloc_array(n, sizeof *b);
    if (!b) return odhs__create_err(ODHS_E_NOMEM, "odhs_series_stats_compute: out of memory");
    memcpy(b, x, n * sizeof *b);
    enum { MAXLEV = 64 };
    double sem[MAXLEV], err[MAXLEV];
    size_t nb[MAXLEV];
    int nlev = 0;
    for (size_t m = n; m >= 2 && nlev < MAXLEV; m /= 2) {
        double mm, sk;
        mean_ss(b, m, &mm, &sk);
        sem[nlev] = sqrt(sk / ((double)m * (double)(m - 1)));
        err[nlev] = sem[nlev] / sqrt(2.0 * (double)(m - 1));
        nb[nlev] = m;
        nlev++;
        for (size_t k = 0; k < m / 2; ++k) b[k] = 0.5 * (b[2 * k] + b[2 * k + 1]);
    }
    odhs__free(b);
    /* the plateau: the first level (with >= 8 blocks) whose estimate agrees
     * with the next level's within that level's uncertainty and with the
     * level after within twice its uncertainty (on AR(1) series: a
     * plateau in 30 of 30 series of 2^16 with tau 1.5 and 9.5, errors
     * 2-4 % low on average; none in series shorter than their
     * correlations) */
    int best = -1, largest = 0;
    for (int k = 0; k < nlev && nb[k] >= 8; ++k) {
        if (sem[k] > sem[largest]) largest = k;
        if (k + 2 < nlev && nb[k + 2] >= 8 && fabs(sem[k + 1] - sem[k]) <= err[k + 1] &&
            fabs(sem[k + 2] - sem[k]) <= 2.0 * err[k + 2]) {
            best = k;
            break;
        }
    }
    int k = best >= 0 ? best : largest;
    r.plateau = best >= 0;
    r.sem = sem[k];
    r.sem_err = err[k];
    r.block = (size_t)1 << k;
    r.nblocks = nb[k];
    if ((s = tau_integrated(x, n, r.mean, &r.tau_int, &r.window))) return s;
    r.sem_tau = sqrt(2.0 * r.tau_int * r.variance / (double)n);
    memcpy(out, &r, size < sizeof r ? size : sizeof r);
    return ODHS_OK;
}

/* ---- distributions ---------------------------------------------------------------- */
int odhs_histogram(const double *x, size_t n, double lo, double hi, size_t nbins, int log_bins, double *edges,
                   double *density, uint64_t *counts, size_t *outside)
{
    odhs__create_begin();
    if (!x || !edges || !density) return odhs__create_err(ODHS_E_NULL, "odhs_histogram: NULL argument");
    if (n == 0 || nbins == 0) return odhs__create_err(ODHS_E_EMPTY, "odhs_histogram: %zu samples, %zu bins", n, nbins);
    if (!isfinite(lo) || !isfinite(hi) || !(hi > lo) || (log_bins && !(lo > 0.0)) || (log_bins != 0 && log_bins != 1))
        return odhs__create_err(ODHS_E_INVALID, "odhs_histogram: range [%g, %g] with log_bins %d", lo, hi, log_bins);
    int s = finite_all(x, n, "odhs_histogram");
    if (s) return s;
    uint64_t *c = odhs__calloc(nbins, sizeof *c);
    if (!c) return odhs__create_err(ODHS_E_NOMEM, "odhs_histogram: out of memory");
    double a = log_bins ? log(lo) : lo, w = ((log_bins ? log(hi) : hi) - a) / (double)nbins;
    size_t out = 0;
    for (size_t k = 0; k < n; ++k) {
        if (!(x[k] >= lo) || !(x[k] <= hi)) {
            out++;
            continue;
        }
        double u = ((log_bins ? log(x[k]) : x[k]) - a) / w;
        size_t b = u >= (double)nbins ? nbins - 1 : (size_t)u;
        c[b]++;
    }
    for (size_t b = 0; b <= nbins; ++b)
        edges[b] = b == nbins ? hi : log_bins ? exp(a + w * (double)b) : lo + w * (double)b;
    edges[0] = lo;
    for (size_t b = 0; b < nbins; ++b) {
        density[b] = (double)c[b] / ((double)n * (edges[b + 1] - edges[b]));
        if (counts) counts[b] = c[b];
    }
    if (outside) *outside = out;
    odhs__free(c);
    return ODHS_OK;
}

int odhs_power_law_exponent(const double *x, size_t n, double xmax, double *a, double *err, size_t *used)
{
    odhs__create_begin();
    if (!x || !a) return odhs__create_err(ODHS_E_NULL, "odhs_power_law_exponent: NULL argument");
    if (!isfinite(xmax) || !(xmax > 0.0))
        return odhs__create_err(ODHS_E_INVALID, "odhs_power_law_exponent: xmax = %g must be > 0", xmax);
    int s = finite_all(x, n, "odhs_power_law_exponent");
    if (s) return s;
    double sum = 0.0;
    size_t m = 0;
    for (size_t k = 0; k < n; ++k)
        if (x[k] > 0.0 && x[k] <= xmax) {
            sum += log(xmax / x[k]);
            m++;
        }
    if (m < 2 || !(sum > 0.0))
        return odhs__create_err(ODHS_E_EMPTY, "odhs_power_law_exponent: %zu samples in (0, %g]", m, xmax);
    double ap1 = (double)m / sum;
    *a = ap1 - 1.0;
    if (err) *err = ap1 / sqrt((double)m);
    if (used) *used = m;
    return ODHS_OK;
}

/* ---- forces and gaps of a packing ---------------------------------------------------- */
int odhs_backbone_forces(const odhs_network *net, size_t cap, size_t *n, double *f)
{
    if (!net) return ODHS_E_NULL;
    if (!n || (cap && !f)) return odhs__neterr(net, ODHS_E_NULL, "odhs_backbone_forces: NULL output");
    unsigned char *rat = odhs__malloc_array(net->n ? net->n : 1, 1);
    if (!rat) return odhs__neterr(net, ODHS_E_NOMEM, "odhs_backbone_forces: out of memory");
    int s = odhs_network_rattlers(net, rat, NULL);
    if (s) {
        odhs__free(rat);
        return s;
    }
    size_t m = 0;
    for (size_t c = 0; c < net->nc; ++c)
        if (net->kind[c] == ODHS_CONTACT_TEMPORARY && net->cj[c] < net->n && !rat[net->ci[c]] && !rat[net->cj[c]]) m++;
    *n = m;
    if (cap < m) {
        odhs__free(rat);
        return odhs__neterr(net, ODHS_E_RANGE, "odhs_backbone_forces: room for %zu forces, the backbone has %zu", cap,
                            m);
    }
    size_t k = 0;
    for (size_t c = 0; c < net->nc; ++c)
        if (net->kind[c] == ODHS_CONTACT_TEMPORARY && net->cj[c] < net->n && !rat[net->ci[c]] && !rat[net->cj[c]])
            f[k++] = net->f[c];
    odhs__free(rat);
    return ODHS_OK;
}

typedef struct {
    const odhs_system *sys;
    const odhs_network *net;
    const unsigned char *rat;
    double max_gap;
    size_t cap, n;
    size_t *i, *j;
    double *gap;
    int *role;
} gaps_ctx;

static int gap_visit(size_t i, size_t j, const double *rij, double gap, void *p)
{
    gaps_ctx *g = p;
    (void)rij;
    double sig = g->sys->r[i] + g->sys->r[j], h = gap / sig;
    if (!(h <= g->max_gap) || h < -1e-9) return 0;
    if (odhs__net_find(g->net, i, j) != SIZE_MAX) return 0;
    if (g->n < g->cap) {
        size_t k = g->n;
        if (g->i) g->i[k] = i;
        if (g->j) g->j[k] = j;
        if (g->gap) g->gap[k] = h;
        if (g->role) g->role[k] = (int)g->rat[i] + (int)g->rat[j];
    }
    g->n++;
    return 0;
}

int odhs_packing_gaps(const odhs_system *sys, const odhs_network *net, double max_gap, size_t cap, size_t *n,
                      size_t *i, size_t *j, double *gap, int *role)
{
    if (!sys) return ODHS_E_NULL;
    if (!net || !n) return odhs__syserr(sys, ODHS_E_NULL, "odhs_packing_gaps: NULL argument");
    if (!sys->has_x || !sys->has_r) return odhs__syserr(sys, ODHS_E_STATE, "odhs_packing_gaps: system not ready");
    if (net->n != sys->n || net->dim != sys->dim)
        return odhs__syserr(sys, ODHS_E_DIM, "odhs_packing_gaps: the network is for N = %zu, d = %d", net->n, net->dim);
    if (!isfinite(max_gap) || !(max_gap > 0.0) || max_gap > 1.0)
        return odhs__syserr(sys, ODHS_E_INVALID, "odhs_packing_gaps: max_gap = %g must be in (0, 1]", max_gap);
    unsigned char *rat = odhs__malloc_array(sys->n, 1);
    if (!rat) return odhs__syserr(sys, ODHS_E_NOMEM, "odhs_packing_gaps: out of memory");
    int s = odhs_network_rattlers(net, rat, NULL);
    if (s) {
        odhs__free(rat);
        return odhs__syserr(sys, s, "odhs_packing_gaps: %s", odhs_network_errmsg(net));
    }
    /* first count (nothing written), then fill when there is room */
    gaps_ctx g = {sys, net, rat, max_gap, 0, 0, NULL, NULL, NULL, NULL};
    s = odhs_system_for_each_pair(sys, max_gap * 2.0 * sys->rmax, gap_visit, &g);
    if (!s && g.n <= cap && cap) {
        gaps_ctx h = {sys, net, rat, max_gap, cap, 0, i, j, gap, role};
        s = odhs_system_for_each_pair(sys, max_gap * 2.0 * sys->rmax, gap_visit, &h);
    }
    odhs__free(rat);
    if (s) return s;
    *n = g.n;
    if (cap < g.n)
        return odhs__syserr(sys, ODHS_E_RANGE, "odhs_packing_gaps: room for %zu pairs, there are %zu", cap, g.n);
    return ODHS_OK;
}

/* ---- velocity correlation ---------------------------------------------------------- */
int odhs_velocity_correlation(const odhs_system *sys, const double *V, double width, size_t nbins, double *g,
                              uint64_t *pairs)
{
    if (!sys) return ODHS_E_NULL;
    if (!V || !g) return odhs__syserr(sys, ODHS_E_NULL, "odhs_velocity_correlation: NULL argument");
    if (!sys->has_x || !sys->has_r) return odhs__syserr(sys, ODHS_E_STATE, "odhs_velocity_correlation: system not ready");
    int dim = sys->dim;
    if (!isfinite(width) || !(width > 0.0) || width > sys->L[1] || nbins == 0)
        return odhs__syserr(sys, ODHS_E_INVALID, "odhs_velocity_correlation: strip width %g (L_y %g), %zu bins", width,
                            sys->L[1], nbins);
    size_t nd = sys->n * (size_t)dim;
    double vv = 0.0;
    for (size_t k = 0; k < nd; ++k)
        if (!isfinite(V[k])) return odhs__syserr(sys, ODHS_E_NONFINITE, "odhs_velocity_correlation: V[%zu] not finite", k);
    for (size_t i = 0; i < sys->n; ++i) vv += V[i * dim + 1] * V[i * dim + 1];
    vv /= (double)sys->n;
    if (!(vv > 0.0)) return odhs__syserr(sys, ODHS_E_EMPTY, "odhs_velocity_correlation: every v_y is 0");
    double *sum = odhs__calloc(nbins, sizeof *sum);
    uint64_t *cnt = odhs__calloc(nbins, sizeof *cnt);
    if (!sum || !cnt) {
        odhs__free(sum);
        odhs__free(cnt);
        return odhs__syserr(sys, ODHS_E_NOMEM, "odhs_velocity_correlation: out of memory");
    }
    const double half = 0.5 * width, bw = 0.5 * sys->L[0] / (double)nbins;
    for (size_t i = 0; i < sys->n; ++i) {
        /* the pair (i, i) is the first bin's x = 0 */
        sum[0] += V[i * dim + 1] * V[i * dim + 1];
        cnt[0]++;
        for (size_t j = i + 1; j < sys->n; ++j) {
            double d[3] = {0.0, 0.0, 0.0};
            for (int k = 0; k < dim; ++k) d[k] = sys->x[j * dim + k] - sys->x[i * dim + k];
            odhs__min_image(dim, sys->L, sys->gamma, d, NULL);
            if (fabs(d[1]) > half || (dim == 3 && fabs(d[2]) > half)) continue;
            size_t b = (size_t)(fabs(d[0]) / bw);
            if (b >= nbins) continue; /* |dx| = L_x / 2 exactly */
            sum[b] += 2.0 * V[i * dim + 1] * V[j * dim + 1]; /* (i, j) and (j, i) */
            cnt[b] += 2;
        }
    }
    for (size_t b = 0; b < nbins; ++b) {
        g[b] = cnt[b] ? sum[b] / (double)cnt[b] / vv : NAN;
        if (pairs) pairs[b] = cnt[b];
    }
    odhs__free(sum);
    odhs__free(cnt);
    return ODHS_OK;
}

int odhs_correlation_minimum(const double *g, size_t nbins, double *x, double *gmin)
{
    odhs__create_begin();
    if (!g || !x) return odhs__create_err(ODHS_E_NULL, "odhs_correlation_minimum: NULL argument");
    /* the lowest finite bin, then its finite neighbours on both sides */
    size_t lo = SIZE_MAX;
    for (size_t k = 0; k < nbins; ++k)
        if (isfinite(g[k]) && (lo == SIZE_MAX || g[k] < g[lo])) lo = k;
    size_t prev = SIZE_MAX, next = SIZE_MAX;
    for (size_t k = lo; lo != SIZE_MAX && k-- > 0;)
        if (isfinite(g[k])) {
            prev = k;
            break;
        }
    for (size_t k = lo + 1; lo != SIZE_MAX && k < nbins; ++k)
        if (isfinite(g[k])) {
            next = k;
            break;
        }
    if (prev == SIZE_MAX || next == SIZE_MAX)
        return odhs__create_err(ODHS_E_EMPTY, "odhs_correlation_minimum: no interior minimum in %zu bins", nbins);
    /* a parabola through (prev, lo, next) */
    double x0 = (double)prev, x1 = (double)lo, x2 = (double)next;
    double y0 = g[prev], y1 = g[lo], y2 = g[next];
    double d = (x0 - x1) * (x0 - x2) * (x1 - x2);
    double A = (x2 * (y1 - y0) + x1 * (y0 - y2) + x0 * (y2 - y1)) / d;
    double B = (x2 * x2 * (y0 - y1) + x1 * x1 * (y2 - y0) + x0 * x0 * (y1 - y2)) / d;
    double C = (x1 * x2 * (x1 - x2) * y0 + x2 * x0 * (x2 - x0) * y1 + x0 * x1 * (x0 - x1) * y2) / d;
    double xv = A > 0.0 ? -B / (2.0 * A) : x1;
    if (!(xv >= x0 && xv <= x2)) xv = x1;
    *x = xv + 0.5; /* bin centres are at k + 1/2 */
    if (gmin) *gmin = A > 0.0 ? C + xv * (B + A * xv) : y1;
    return ODHS_OK;
}
