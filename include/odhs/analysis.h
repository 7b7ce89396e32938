/*
 * libodhs - analysis.h: the analyses users run on every project (since
 * 0.2.7): time-series statistics with automatic error bars, histograms and
 * power-law exponents of small forces and gaps, the backbone's forces and
 * the gaps of nearly touching pairs with their roles, and the transverse
 * velocity correlation g_y(x) of a sheared packing (Olsson & Teitel; eq.
 * 4.23 of Vagberg's thesis).
 *
 * The calls work on plain arrays (a time series, samples, velocities) or on
 * the handles' current state (a system, a network); they never change their
 * inputs. Outputs go to caller-owned arrays whose sizes are stated per call.
 * Every call returns a status; errors leave the outputs as they were unless
 * stated, and a handle argument receives a message (odhs_*_errmsg); calls
 * without a handle put theirs in odhs_last_error() (common.h).
 */
#ifndef ODHS_ANALYSIS_H
#define ODHS_ANALYSIS_H

#include "odhs/network.h"
#include "odhs/system.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- time series ----------------------------------------------------------- */

/**
 * Statistics of a correlated time series (samples at equal spacing, e.g.
 * the stress every 0.01 strain). The caller sets `size` to
 * sizeof(odhs_series_stats); the library fills that many bytes.
 */
typedef struct odhs_series_stats {
    size_t size;     /* set by the caller: sizeof(odhs_series_stats)               */
    size_t n;        /* samples                                                    */
    double mean;     /* sample mean                                                */
    double variance; /* sample variance (n - 1 in the denominator)                 */
    double sem;      /* standard error of the mean from block averaging           */
    double sem_err;  /* ... its own uncertainty, sem / sqrt(2 (nblocks - 1))       */
    size_t block;    /* block length (samples) the error was read at               */
    size_t nblocks;  /* blocks of that length                                      */
    int plateau;     /* 1 if the blocked error reached a plateau (the error is
                      * trustworthy), 0 if the series is too short for its
                      * correlations: sem is then the largest blocked estimate,
                      * a lower bound                                            */
    double tau_int;  /* integrated autocorrelation time in samples,
                      * 1/2 + sum_{t=1}^{W} rho(t), Sokal's window W (the
                      * smallest W >= 5 tau_int(W)); 1/2 for white noise       */
    size_t window;   /* that window W                                              */
    double sem_tau;  /* sqrt(2 tau_int variance / n): the error from tau_int       */
} odhs_series_stats;

/**
 * Mean and error of x[0..n-1] (n >= 4). Block averaging (Flyvbjerg and
 * Petersen, J. Chem. Phys. 91, 461 (1989)): the series is halved by
 * averaging neighbours again and again; the error of the mean estimated
 * from blocks of length 2^k grows with k while blocks are correlated and
 * levels off once they are not. The plateau is the first level k whose
 * estimate agrees with the next level's within that one's uncertainty and
 * with the level after within twice its uncertainty, keeping at least 8
 * blocks. tau_int from the normalised
 * autocorrelation with Sokal's automatic window. Both errors are given:
 * they agree for long series (tested on AR(1) processes). Allocates O(n).
 * Errors: ODHS_E_NULL, ODHS_E_EMPTY (n < 4), ODHS_E_NONFINITE,
 * ODHS_E_INVALID (size too small), ODHS_E_NOMEM; message in
 * odhs_last_error().
 */
ODHS_API int odhs_series_stats_compute(const double *x, size_t n, odhs_series_stats *out);

/**
 * Normalised autocorrelation rho(t) = C(t)/C(0) of x[0..n-1] for lags
 * t = 0..maxlag (rho[0..maxlag], maxlag < n), C(t) = sum_i (x_i - m)(x_{i+t}
 * - m) / (n - t). A constant series gives rho = 1 at lag 0 and 0 beyond.
 * Errors as odhs_series_stats_compute (ODHS_E_RANGE for maxlag >= n).
 */
ODHS_API int odhs_series_autocorrelation(const double *x, size_t n, size_t maxlag, double *rho);

/**
 * Split an event-resolved signal into its jumps at events and its changes
 * between them (the paper's Fig. 4: the stress relaxes while a network
 * lasts and jumps up at collisions). Per step k = 0..n-1: before[k], the
 * value at the end of the step's motion before its events (e.g. a component
 * of odhs_stepper_pre_event_stress), after[k], the value after them
 * (odhs_stepper_stress), and at_event[k] nonzero for the steps to split at
 * (e.g. odhs_step_info.collisions > 0). Writes, in step order:
 *  - jumps[m] = after[k] - before[k] at the m-th marked step (*njumps of them);
 *  - drops[m] = after[k_m] - before[k_{m+1}] between the m-th and the next
 *    marked step: how far the signal fell from just after one event to just
 *    before the next (negative if it rose), including the changes at the
 *    unmarked steps between (*ndrops = *njumps - 1, or 0).
 * jumps and drops (room for n values) may be NULL to count only.
 * Errors: ODHS_E_NULL (before, after, at_event, njumps or ndrops NULL),
 * ODHS_E_EMPTY (n = 0), ODHS_E_NONFINITE; message in odhs_last_error().
 * Since 0.2.8.
 */
ODHS_API int odhs_series_event_split(const double *before, const double *after, const unsigned char *at_event,
                                     size_t n, double *jumps, size_t *njumps, double *drops, size_t *ndrops);

/* ---- distributions --------------------------------------------------------- */

/**
 * Histogram of x[0..n-1] on [lo, hi] with nbins bins, equal in x
 * (log_bins = 0) or in log x (log_bins = 1: needs lo > 0). edges[0..nbins]
 * receives the bin edges, density[0..nbins-1] the probability density
 * count / (n * width): samples outside [lo, hi] count in n but in no bin, so
 * the density integrates to the fraction inside. counts (may be NULL)
 * receives the counts, *outside (may be NULL) the samples outside.
 * Non-finite samples are errors. Errors: ODHS_E_NULL, ODHS_E_EMPTY (n = 0
 * or nbins = 0), ODHS_E_INVALID (hi <= lo, lo <= 0 with log bins),
 * ODHS_E_NONFINITE.
 */
ODHS_API int odhs_histogram(const double *x, size_t n, double lo, double hi, size_t nbins, int log_bins,
                            double *edges, double *density, uint64_t *counts, size_t *outside);

/**
 * The exponent a of a density p(x) ~ x^a at small x (a > -1), from the
 * samples of x[0..n-1] in (0, xmax] by maximum likelihood for the density
 * (a + 1) x^a / xmax^(a+1) on (0, xmax] (Hill's estimator):
 *     a + 1 = m / sum_i log(xmax / x_i),  m the samples used,
 * with the standard error (a + 1) / sqrt(m). For the small-force exponent
 * theta of jammed packings, P(f) ~ f^theta, pass the backbone forces
 * divided by their mean and a cut-off well inside the power-law regime;
 * for the gap exponent gamma, g(h) ~ h^-gamma, pass the gaps: a = -gamma.
 * *used (may be NULL) receives m. Errors: ODHS_E_NULL, ODHS_E_INVALID
 * (xmax <= 0), ODHS_E_EMPTY (fewer than 2 samples in (0, xmax]),
 * ODHS_E_NONFINITE.
 */
ODHS_API int odhs_power_law_exponent(const double *x, size_t n, double xmax, double *a, double *err, size_t *used);

/* ---- forces and gaps of a packing ------------------------------------------- */

/** Roles of a nearly touching pair (odhs_packing_gaps). */
enum {
    ODHS_GAP_BACKBONE = 0, /* both particles on the backbone (not rattlers)   */
    ODHS_GAP_ONE_RATTLER = 1, /* one of them a rattler                       */
    ODHS_GAP_RATTLERS = 2  /* both rattlers                                   */
};

/**
 * The forces of the contacts between backbone particles: net's particle
 * contacts whose two particles are not rattlers (odhs_network_rattlers:
 * fewer than d + 1 contacts, applied recursively). f (room for cap) gets the
 * forces in contact order, *n their number (also when cap is too small:
 * then ODHS_E_RANGE and nothing is written; cap = 0 asks for the size).
 * Wall contacts and bonds are not particle contacts and are left out.
 * Errors: ODHS_E_NULL, ODHS_E_RANGE, ODHS_E_NOMEM (message on net).
 */
ODHS_API int odhs_backbone_forces(const odhs_network *net, size_t cap, size_t *n, double *f);

/**
 * The gaps of the nearly touching pairs of a packing: pairs not in net
 * whose relative gap h = r / (a_i + a_j) - 1 is in (0, max_gap] (or
 * [-tiny, max_gap] for pairs at round-off contact that are not in the
 * network), with their role (ODHS_GAP_*). Arrays of room cap (any may be
 * NULL): i[k] < j[k], gap[k] = h, role[k]. *n the number of such pairs; cap
 * too small: ODHS_E_RANGE and nothing written (cap = 0 asks the size).
 * net must be a network of sys (same N and dimension). Errors:
 * ODHS_E_NULL, ODHS_E_STATE (system not ready), ODHS_E_DIM (network of
 * another system), ODHS_E_INVALID (max_gap not in (0, 1]), ODHS_E_RANGE,
 * ODHS_E_NOMEM (message on sys).
 */
ODHS_API int odhs_packing_gaps(const odhs_system *sys, const odhs_network *net, double max_gap, size_t cap, size_t *n,
                               size_t *i, size_t *j, double *gap, int *role);

/* ---- velocity correlation ----------------------------------------------------- */

/**
 * The transverse velocity correlation along the flow (Olsson and Teitel,
 * PRL 99, 178001 (2007); eq. 4.23 of Vagberg's thesis):
 *     g_y(x) = < v_y(x_i, y_i) v_y(x_i + x, y_i) > / < v_y^2 >
 * over pairs of particles in the same horizontal strip, |y_i - y_j| <=
 * width/2 (and |z_i - z_j| <= width/2 in 3D; minimum image, Lees-Edwards
 * shift included), with their
 * separation |x_i - x_j| binned in nbins bins of [0, L_x / 2]; V the
 * velocities (N*d, e.g. odhs_stepper_nonaffine_velocities: v_y carries no
 * affine part in simple shear along x). g[0..nbins-1] receives g_y at the
 * bin centres (bin k covers [k, k+1) L_x / (2 nbins)); pairs[k] (may be
 * NULL) the pairs per bin; an empty bin gets NaN. g_y(0) is 1 in the limit
 * of a vanishing first bin; the position of the minimum of g_y is the
 * correlation length of the RD0 model. O(N^2) pairs (N = 10^4: 5e7 pairs,
 * a second or so). Errors: ODHS_E_NULL, ODHS_E_STATE (not ready),
 * ODHS_E_INVALID (width <= 0 or > L_y, nbins = 0), ODHS_E_NONFINITE,
 * ODHS_E_EMPTY (all v_y = 0), ODHS_E_NOMEM (messages on sys).
 */
ODHS_API int odhs_velocity_correlation(const odhs_system *sys, const double *V, double width, size_t nbins, double *g,
                                       uint64_t *pairs);

/**
 * The minimum of a correlation function g[0..nbins-1] (NaN bins skipped):
 * the lowest bin, refined by a parabola through it and its neighbours; *x
 * its position in units of the bin width, from 0 (bin k's centre is at
 * k + 1/2), *gmin (may be NULL) its value. The lowest bin must be interior
 * (a g that still falls at the last bin, or rises from the first, has no
 * minimum: ODHS_E_EMPTY). Average g over many configurations first: the
 * lowest bin of a noisy single g can be anywhere. Errors: ODHS_E_NULL,
 * ODHS_E_EMPTY.
 */
ODHS_API int odhs_correlation_minimum(const double *g, size_t nbins, double *x, double *gmin);

/* ---- scaling collapse of flow curves ------------------------------------------ */

/**
 * Result of odhs_collapse_fit (set `size` = sizeof before the call). The
 * scaling form of an observable O (shear stress, pressure) near jamming,
 * eq. (5.2) of Vagberg's thesis (Olsson and Teitel 2007):
 *     O(phi, rate) = rate^(y / z nu) F((phi - phi_J) / rate^(1 / z nu)),
 * fitted with ln F a polynomial of the given degree in the scaled variable.
 */
typedef struct odhs_collapse {
    size_t size;             /* set by the caller                                   */
    double phi_j, phi_j_err; /* the jamming packing fraction                        */
    double y, y_err;         /* the observable's exponent y                         */
    double znu, znu_err;     /* z nu                                                */
    double q;                /* y / (z nu): O ~ rate^q at phi_J                      */
    double chi2;             /* sum of squared, weighted residuals of ln O           */
    size_t dof;              /* points - polynomial coefficients - 3                 */
    int degree;              /* the polynomial's degree                             */
    double coef[8];          /* ln F(x) = sum_k coef[k] ((x - x0) / xs)^k ...        */
    double x0, xs;           /* ... with the centre and half-width of the data's x   */
    unsigned evaluations;    /* evaluations of chi2 the minimisation took            */
} odhs_collapse;

/**
 * Fit phi_J, y and z nu to n points (phi[k], rate[k] > 0, value[k] > 0)
 * with relative errors rel_err[k] of the values (NULL: 1 % each): minimise
 * chi2 = sum_k ((ln value_k - q ln rate_k - P(x_k)) / rel_err_k)^2 over the
 * three exponents (Nelder-Mead from guess[3] = {phi_J, y, z nu}, or from
 * {max phi, 1, 3} when NULL, restarted at its minimum), P the weighted
 * least-squares polynomial of the given degree (1..7) in x_k = (phi_k -
 * phi_J) / rate_k^(1 / z nu). Errors are the square roots of the diagonal
 * of 2 H^-1 (H the finite-difference Hessian of chi2 at the minimum),
 * scaled by chi2/dof when that exceeds 1. Needs n >= degree + 5 points
 * over at least two rates. Errors: ODHS_E_NULL, ODHS_E_EMPTY (too few
 * points), ODHS_E_INVALID (a rate, value or error <= 0, degree, size),
 * ODHS_E_NONFINITE, ODHS_E_NOCONV (no finite minimum: try another guess),
 * ODHS_E_SINGULAR (flat chi2: an exponent is not determined by the data),
 * ODHS_E_NOMEM; message in odhs_last_error().
 */
ODHS_API int odhs_collapse_fit(const double *phi, const double *rate, const double *value, const double *rel_err,
                               size_t n, int degree, const double *guess, odhs_collapse *out);

#ifdef __cplusplus
}
#endif
#endif /* ODHS_ANALYSIS_H */
