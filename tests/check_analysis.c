/*
 * libodhs - the analysis calls (analysis.h) against analytic cases:
 *  - series statistics of AR(1) processes (known tau_int = (1+p)/(2(1-p)) and
 *    error of the mean) and of white noise; the autocorrelation p^t;
 *  - histograms of uniform and log-uniform samples (densities, edges, counts
 *    outside), power-law exponents recovered from synthetic samples within
 *    their stated errors;
 *  - backbone forces on a hand-made network (a rattler's contacts, bonds and
 *    walls left out), and on a jammed packing against its certificate;
 *  - gaps of nearly touching pairs against a brute-force pair loop, with
 *    their roles;
 *  - the velocity correlation of the field v_y = cos(2 pi x / L_x) on a
 *    lattice (g_y(x) = cos(2 pi x / L_x) exactly), under Lees-Edwards
 *    strain, and the minimum of a parabola.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "testutil.h"

/* a standard normal from two uniforms (Box-Muller) */
static double normal(tu_rng *r)
{
    double u = tu_uniform(r), v = tu_uniform(r);
    return sqrt(-2.0 * log(u > 0.0 ? u : 1e-300)) * cos(2.0 * TU_PI * v);
}

/* AR(1) x_t = p x_{t-1} + e_t, unit-variance noise, started stationary */
static double *ar1(size_t n, double p, uint64_t seed)
{
    tu_rng r;
    tu_rng_seed(&r, seed);
    double *x = malloc(n * sizeof *x);
    ck_assert_ptr_nonnull(x);
    x[0] = normal(&r) / sqrt(1.0 - p * p);
    for (size_t t = 1; t < n; ++t) x[t] = p * x[t - 1] + normal(&r);
    return x;
}

START_TEST(test_series_ar1)
{
    const double ps[] = {0.0, 0.5, 0.9, 0.98};
    const size_t n = (size_t)1 << 18;
    for (int k = 0; k < 4; ++k) {
        double p = ps[k];
        double *x = ar1(n, p, 11 + (uint64_t)k);
        odhs_series_stats s;
        memset(&s, 0, sizeof s);
        s.size = sizeof s;
        ck_assert_msg(odhs_series_stats_compute(x, n, &s) == ODHS_OK, "%s", odhs_last_error());
        double var = 1.0 / (1.0 - p * p), tau = 0.5 * (1.0 + p) / (1.0 - p), sem = sqrt(2.0 * tau * var / (double)n);
        printf("[analysis] AR(1) p = %.2f, n = 2^18: tau_int %.3f (exact %.3f, window %zu), sem block %.4e +- %.1e "
               "(block %zu, plateau %d), sem tau %.4e, exact %.4e\n",
               p, s.tau_int, tau, s.window, s.sem, s.sem_err, s.block, s.plateau, s.sem_tau, sem);
        ck_assert_uint_eq(s.n, n);
        ck_assert_msg(fabs(s.variance / var - 1.0) < 0.05 + 0.1 * p, "variance %g vs %g", s.variance, var);
        ck_assert_msg(fabs(s.tau_int / tau - 1.0) < 0.1, "tau_int %g vs %g", s.tau_int, tau);
        ck_assert_msg(s.plateau == 1, "no plateau at p = %g", p);
        ck_assert_msg(fabs(s.sem / sem - 1.0) < 0.15, "blocked sem %g vs exact %g", s.sem, sem);
        ck_assert_msg(fabs(s.sem_tau / sem - 1.0) < 0.1, "tau sem %g vs exact %g", s.sem_tau, sem);
        ck_assert_msg(fabs(s.mean) < 5.0 * sem, "mean %g, sem %g", s.mean, sem);
        /* the autocorrelation p^t */
        double rho[11];
        ck_assert_int_eq(odhs_series_autocorrelation(x, n, 10, rho), ODHS_OK);
        ck_assert(rho[0] == 1.0);
        for (int t = 1; t <= 10; ++t)
            ck_assert_msg(fabs(rho[t] - pow(p, t)) < 0.02 + 0.05 * p, "rho(%d) %g vs %g", t, rho[t], pow(p, t));
        free(x);
    }
}
END_TEST

START_TEST(test_series_short)
{
    /* a series shorter than its correlations: no plateau, sem a lower bound */
    const size_t n = 256;
    double *x = ar1(n, 0.995, 3);
    odhs_series_stats s;
    memset(&s, 0, sizeof s);
    s.size = sizeof s;
    ck_assert_int_eq(odhs_series_stats_compute(x, n, &s), ODHS_OK);
    ck_assert_msg(s.plateau == 0, "plateau claimed for a series of 256 with tau 200 (block %zu)", s.block);
    free(x);
    /* a constant series: zero error, tau 1/2 */
    double c[16];
    for (int k = 0; k < 16; ++k) c[k] = 2.5;
    ck_assert_int_eq(odhs_series_stats_compute(c, 16, &s), ODHS_OK);
    ck_assert(s.mean == 2.5 && s.variance == 0.0 && s.sem == 0.0 && s.tau_int == 0.5);
    /* a smaller, older struct is filled up to its size only */
    unsigned char buf[64];
    memset(buf, 0xee, sizeof buf);
    size_t sz = offsetof(odhs_series_stats, variance);
    memcpy(buf, &sz, sizeof sz);
    ck_assert_int_eq(odhs_series_stats_compute(c, 16, (odhs_series_stats *)(void *)buf), ODHS_OK);
    for (size_t b = sz; b < sizeof buf; ++b) ck_assert_msg(buf[b] == 0xee, "byte %zu written", b);
    double m;
    memcpy(&m, buf + offsetof(odhs_series_stats, mean), sizeof m);
    ck_assert(m == 2.5);
}
END_TEST

START_TEST(test_event_split)
{
    /* an exact sawtooth: the signal falls by 0.1 per step, events at steps
     * 2, 3 and 7 raise it by 1, 2 and 3; step 5 (unmarked) by 0.5 */
    const size_t n = 9;
    double before[9], after[9], v = 10.0;
    unsigned char ev[9] = {0, 0, 1, 1, 0, 0, 0, 1, 0};
    const double up[9] = {0, 0, 1, 2, 0, 0.5, 0, 3, 0};
    for (size_t k = 0; k < n; ++k) {
        v -= 0.1;
        before[k] = v;
        v += up[k];
        after[k] = v;
    }
    double jumps[9], drops[9];
    size_t nj = 99, nd = 99;
    ck_assert_int_eq(odhs_series_event_split(before, after, ev, n, jumps, &nj, drops, &nd), ODHS_OK);
    ck_assert(nj == 3 && nd == 2);
    const double ej[3] = {1, 2, 3}, ed[2] = {0.1, 4 * 0.1 - 0.5};
    for (int m = 0; m < 3; ++m) ck_assert_msg(fabs(jumps[m] - ej[m]) < 1e-12, "jump %d = %g", m, jumps[m]);
    for (int m = 0; m < 2; ++m) ck_assert_msg(fabs(drops[m] - ed[m]) < 1e-12, "drop %d = %g", m, drops[m]);
    /* the signal's change from after the first event to after the last is
     * the later jumps minus the drops */
    ck_assert(fabs((after[7] - after[2]) - (jumps[1] + jumps[2] - drops[0] - drops[1])) < 1e-12);
    /* counts only; no marked step; one marked step */
    ck_assert_int_eq(odhs_series_event_split(before, after, ev, n, NULL, &nj, NULL, &nd), ODHS_OK);
    ck_assert(nj == 3 && nd == 2);
    unsigned char none[9] = {0}, one[9] = {0, 0, 0, 0, 1, 0, 0, 0, 0};
    ck_assert_int_eq(odhs_series_event_split(before, after, none, n, jumps, &nj, drops, &nd), ODHS_OK);
    ck_assert(nj == 0 && nd == 0);
    ck_assert_int_eq(odhs_series_event_split(before, after, one, n, jumps, &nj, drops, &nd), ODHS_OK);
    ck_assert(nj == 1 && nd == 0 && fabs(jumps[0]) < 1e-15);
}
END_TEST

START_TEST(test_histogram)
{
    tu_rng r;
    tu_rng_seed(&r, 5);
    const size_t n = 200000;
    double *x = malloc(n * sizeof *x);
    for (size_t k = 0; k < n; ++k) x[k] = 2.0 * tu_uniform(&r) - 0.5; /* uniform on [-0.5, 1.5) */
    double edges[11], dens[10];
    uint64_t counts[10];
    size_t out;
    ck_assert_int_eq(odhs_histogram(x, n, 0.0, 1.0, 10, 0, edges, dens, counts, &out), ODHS_OK);
    uint64_t total = out;
    for (int b = 0; b < 10; ++b) {
        ck_assert_msg(fabs(edges[b] - 0.1 * b) < 1e-15, "edge %d = %.17g", b, edges[b]);
        ck_assert_msg(fabs(dens[b] - 0.5) < 0.02, "density %g in bin %d (expected 0.5)", dens[b], b);
        total += counts[b];
    }
    ck_assert(edges[10] == 1.0 && total == n);
    ck_assert_msg(fabs((double)out / (double)n - 0.5) < 0.01, "outside %zu", out);
    /* log bins: x = 10^u, u uniform on [0, 3): equal counts per decade bin,
     * density 1 / (x ln(1000)) */
    for (size_t k = 0; k < n; ++k) x[k] = pow(10.0, 3.0 * tu_uniform(&r));
    ck_assert_int_eq(odhs_histogram(x, n, 1.0, 1000.0, 3, 1, edges, dens, counts, &out), ODHS_OK);
    ck_assert(out == 0);
    for (int b = 0; b < 3; ++b) {
        ck_assert_msg(fabs(edges[b] / pow(10.0, b) - 1.0) < 1e-14, "log edge %d = %.17g", b, edges[b]);
        double expect = (1.0 / 3.0) / (edges[b + 1] - edges[b]);
        ck_assert_msg(fabs(dens[b] / expect - 1.0) < 0.02, "log density %g vs %g", dens[b], expect);
    }
    free(x);
}
END_TEST

START_TEST(test_power_law)
{
    /* p(x) = (a+1) x^a on (0, 1]: x = u^(1/(a+1)); a = 0.4 (small forces),
     * a = -0.4 (gaps, gamma = 0.4) */
    const double as[] = {0.4, -0.4, 0.0};
    tu_rng r;
    tu_rng_seed(&r, 9);
    for (int k = 0; k < 3; ++k) {
        const size_t n = 20000;
        double *x = malloc(n * sizeof *x);
        for (size_t i = 0; i < n; ++i) x[i] = 2.0 * pow(tu_uniform(&r), 1.0 / (as[k] + 1.0)); /* on (0, 2] */
        double a, err;
        size_t used;
        /* the cut-off at 1: the law holds there too (same exponent) */
        ck_assert_int_eq(odhs_power_law_exponent(x, n, 1.0, &a, &err, &used), ODHS_OK);
        printf("[analysis] power law a = %+.2f: %.4f +- %.4f from %zu samples\n", as[k], a, err, used);
        ck_assert_msg(fabs(a - as[k]) < 3.5 * err, "exponent %g +- %g, expected %g", a, err, as[k]);
        ck_assert_msg(fabs(err - (as[k] + 1.0) / sqrt((double)used)) < 0.1 * err, "error %g", err);
        free(x);
    }
}
END_TEST

/* ---- forces and gaps --------------------------------------------------------- */
START_TEST(test_backbone_by_hand)
{
    /* a triangular patch: every particle of a 6 x 6 triangular lattice at
     * contact has 6 contacts; strip particle 0 down to 2 contacts: it is a
     * rattler, its 2 contacts leave the backbone */
    const int m = 6;
    const size_t n = (size_t)m * m;
    odhs_system *sys;
    ck_assert_int_eq(odhs_system_create(2, n, &sys), ODHS_OK);
    double L[2] = {m * 1.0, m * sqrt(3.0) / 2.0}, *x = malloc(2 * n * sizeof *x), *r = malloc(n * sizeof *r);
    for (int row = 0; row < m; ++row)
        for (int col = 0; col < m; ++col) {
            size_t i = (size_t)(row * m + col);
            x[2 * i] = col + 0.5 * (row % 2) + 0.25;
            x[2 * i + 1] = (row + 0.5) * sqrt(3.0) / 2.0;
            r[i] = 0.5;
        }
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
    odhs_network *net;
    ck_assert_int_eq(odhs_network_create(sys, &net), ODHS_OK);
    ck_assert_int_eq(odhs_network_detect(net, sys, 1e-9), ODHS_OK);
    ck_assert_uint_eq(odhs_network_count(net), 3 * n);
    /* remove 4 of particle 0's 6 contacts */
    int removed = 0;
    for (size_t k = odhs_network_count(net); k-- > 0 && removed < 4;) {
        size_t i, j;
        odhs_network_get_contact(net, k, &i, &j, NULL);
        if (i == 0) {
            ck_assert_int_eq(odhs_network_remove(net, i, j), ODHS_OK);
            removed++;
        }
    }
    size_t nc = odhs_network_count(net);
    double *f = malloc(nc * sizeof *f), *g = malloc(nc * sizeof *g);
    for (size_t k = 0; k < nc; ++k) f[k] = 1.0 + (double)k;
    ck_assert_int_eq(odhs_network_set_forces(net, f), ODHS_OK);
    size_t nb = 0;
    ck_assert_int_eq(odhs_backbone_forces(net, 0, &nb, NULL), ODHS_E_RANGE);
    ck_assert_uint_eq(nb, nc - 2);
    ck_assert_int_eq(odhs_backbone_forces(net, nc, &nb, g), ODHS_OK);
    size_t k2 = 0;
    for (size_t k = 0; k < nc; ++k) {
        size_t i, j;
        odhs_network_get_contact(net, k, &i, &j, NULL);
        if (i == 0) continue;
        ck_assert_msg(g[k2] == f[k], "backbone force %zu: %g, expected %g", k2, g[k2], f[k]);
        k2++;
    }
    ck_assert_uint_eq(k2, nb);
    /* gaps: particle 0's 4 removed neighbours are at contact (h = 0) but
     * not in the network: pairs with one rattler; the next shell is at
     * h = sqrt(3) - 1 > 0.5: none */
    size_t ng = 0, gi[16], gj[16];
    double gh[16];
    int role[16];
    ck_assert_int_eq(odhs_packing_gaps(sys, net, 0.5, 16, &ng, gi, gj, gh, role), ODHS_OK);
    ck_assert_uint_eq(ng, 4);
    for (size_t k = 0; k < ng; ++k) {
        ck_assert(gi[k] == 0 && gj[k] > 0 && fabs(gh[k]) < 1e-12 && role[k] == ODHS_GAP_ONE_RATTLER);
    }
    free(f), free(g), free(x), free(r);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* brute force: pairs not in net with relative gap in [-1e-9, hmax] */
static size_t brute_gaps(const odhs_system *sys, const odhs_network *net, double hmax)
{
    size_t n = odhs_system_count(sys), cnt = 0, idx;
    double *r = malloc(n * sizeof *r);
    odhs_system_get_radii(sys, r);
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 1; j < n; ++j) {
            double d[3], dist;
            odhs_system_separation(sys, i, j, d, &dist, NULL);
            double h = dist / (r[i] + r[j]) - 1.0;
            odhs_network_find(net, i, j, &idx);
            if (h <= hmax && h >= -1e-9 && idx == SIZE_MAX) cnt++;
        }
    free(r);
    return cnt;
}

START_TEST(test_jammed_packing)
{
    /* compress 2D N = 128 to jamming (cholmod), then: the backbone forces
     * are the certificate's backbone contacts, all > 0, mean-normalised
     * histogram integrates to 1; the gaps agree with a brute-force loop */
    odhs_system *sys;
    ck_assert_int_eq(odhs_system_create(2, 128, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.0, 21), ODHS_OK);
    ck_assert_int_eq(odhs_system_place_random(sys, 0.5, 21), ODHS_OK);
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
    ck_assert_int_eq(odhs_driver_create(&drv), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_compression_rate(drv, 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_create_by_name("cholmod", &sol), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_create(sys, drv, sol, &st), ODHS_OK);
    int s = odhs_stepper_run_until_packing_fraction(st, 0.9);
    ck_assert_msg(s == ODHS_JAMMED, "compression ended with %d (%s)", s, odhs_stepper_errmsg(st));
    odhs_jam_certificate cert;
    memset(&cert, 0, sizeof cert);
    cert.size = sizeof cert;
    ck_assert_int_eq(odhs_stepper_certificate(st, &cert), ODHS_OK);
    const odhs_network *net = odhs_stepper_network(st);
    size_t nb = 0;
    double f[512];
    ck_assert_int_eq(odhs_backbone_forces(net, 512, &nb, f), ODHS_OK);
    ck_assert_msg(nb == cert.n_contacts_backbone, "backbone forces %zu, certificate %zu", nb, cert.n_contacts_backbone);
    double mean = 0.0, fmin = INFINITY;
    for (size_t k = 0; k < nb; ++k) {
        mean += f[k] / (double)nb;
        fmin = fmin < f[k] ? fmin : f[k];
    }
    ck_assert_msg(fmin > 0.0 && fabs(fmin / mean - cert.min_force) < 1e-9, "min force %g, certificate %g",
                  fmin / mean, cert.min_force);
    for (size_t k = 0; k < nb; ++k) f[k] /= mean;
    double edges[21], dens[20];
    size_t out;
    ck_assert_int_eq(odhs_histogram(f, nb, 0.0, 4.0, 20, 0, edges, dens, NULL, &out), ODHS_OK);
    double integral = 0.0;
    for (int b = 0; b < 20; ++b) integral += dens[b] * (edges[b + 1] - edges[b]);
    ck_assert_msg(fabs(integral + (double)out / (double)nb - 1.0) < 1e-12, "integral %g", integral);
    size_t ng = 0;
    ck_assert_int_eq(odhs_packing_gaps(sys, net, 0.2, 0, &ng, NULL, NULL, NULL, NULL), ng ? ODHS_E_RANGE : ODHS_OK);
    size_t expect = brute_gaps(sys, net, 0.2);
    ck_assert_msg(ng == expect && ng > 0, "gaps %zu, brute force %zu", ng, expect);
    size_t *gi = malloc(ng * sizeof *gi), *gj = malloc(ng * sizeof *gj);
    double *gh = malloc(ng * sizeof *gh);
    int *role = malloc(ng * sizeof *role);
    unsigned char rat[128];
    ck_assert_int_eq(odhs_network_rattlers(net, rat, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_packing_gaps(sys, net, 0.2, ng, &ng, gi, gj, gh, role), ODHS_OK);
    size_t roles[3] = {0, 0, 0};
    for (size_t k = 0; k < ng; ++k) {
        ck_assert(gi[k] < gj[k] && gh[k] <= 0.2 && gh[k] >= -1e-9);
        ck_assert_int_eq(role[k], rat[gi[k]] + rat[gj[k]]);
        roles[role[k]]++;
    }
    printf("[analysis] jammed 2D N = 128: phi %.4f, %zu backbone contacts (%zu rattlers), min f/<f> %.3g, %zu gaps "
           "below 0.2 (%zu backbone, %zu with one rattler, %zu between rattlers)\n",
           cert.phi, nb, cert.n_rattlers, fmin / mean, ng, roles[0], roles[1], roles[2]);
    free(gi), free(gj), free(gh), free(role);
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
}
END_TEST

/* ---- velocity correlation --------------------------------------------------- */
START_TEST(test_velocity_correlation)
{
    /* a 16 x 8 square lattice of spacing 1 (discs of radius 0.3), v_y =
     * cos(2 pi x / 16): g_y(x) = cos(2 pi x / 16); 9 bins of width 8/9 hold
     * the separations 0..7 once each (none on a bin edge); under a
     * Lees-Edwards strain too */
    const int nx = 16, ny = 8;
    const size_t n = (size_t)nx * ny;
    for (int strained = 0; strained < 2; ++strained) {
        odhs_system *sys;
        ck_assert_int_eq(odhs_system_create(2, n, &sys), ODHS_OK);
        double L[2] = {nx, ny}, *x = malloc(2 * n * sizeof *x), *r = malloc(n * sizeof *r),
               *V = malloc(2 * n * sizeof *V);
        for (int a = 0; a < ny; ++a)
            for (int b = 0; b < nx; ++b) {
                size_t i = (size_t)(a * nx + b);
                x[2 * i] = b + 0.5;
                x[2 * i + 1] = a + 0.5;
                r[i] = 0.3;
                V[2 * i] = 0.7; /* v_x does not enter */
                V[2 * i + 1] = cos(2.0 * TU_PI * (b + 0.5) / nx);
            }
        ck_assert_int_eq(odhs_system_set_configuration(sys, L, strained ? 0.3 : 0.0, r, x), ODHS_OK);
        /* the stored positions (wrapped under the strain) are those set */
        double xs[2 * 128];
        odhs_system_get_positions(sys, xs);
        double g[9];
        uint64_t pairs[9];
        ck_assert_int_eq(odhs_velocity_correlation(sys, V, 0.5, 9, g, pairs), ODHS_OK);
        ck_assert_msg(isnan(g[8]) && pairs[8] == 0, "bin 8 (separation 8 = L_x / 2 is left out) not empty");
        for (int k = 0; k < 8; ++k) {
            /* bin k holds the separation m = k: 9 m / 8 in [k, k + 1) */
            int mm = k;
            double expect = cos(2.0 * TU_PI * mm / nx);
            uint64_t np = mm == 0 ? n : 2 * n; /* self pairs, or both signs of dx */
            ck_assert_msg(pairs[k] == np, "strain %d bin %d: %llu pairs, expected %llu", strained, k,
                          (unsigned long long)pairs[k], (unsigned long long)np);
            ck_assert_msg(fabs(g[k] - expect) < 1e-12, "strain %d bin %d: g = %.15g, expected %.15g", strained, k,
                          g[k], expect);
        }
        free(x), free(r), free(V);
        odhs_system_destroy(sys);
    }
}
END_TEST

START_TEST(test_correlation_minimum)
{
    /* g = (k + 0.5 - 3.3)^2 - 0.2 sampled at bin centres: minimum at 3.3, -0.2 */
    double g[10];
    for (int k = 0; k < 10; ++k) g[k] = (k + 0.5 - 3.3) * (k + 0.5 - 3.3) - 0.2;
    double x, gm;
    ck_assert_int_eq(odhs_correlation_minimum(g, 10, &x, &gm), ODHS_OK);
    ck_assert_msg(fabs(x - 3.3) < 1e-12 && fabs(gm + 0.2) < 1e-12, "minimum at %.15g, %.15g", x, gm);
    g[2] = NAN; /* a NaN bin is skipped: still a parabola through 1, 3, 4 */
    ck_assert_int_eq(odhs_correlation_minimum(g, 10, &x, &gm), ODHS_OK);
    ck_assert_msg(fabs(x - 3.3) < 1e-12, "minimum with a NaN bin at %.15g", x);
    for (int k = 0; k < 10; ++k) g[k] = exp(-0.3 * k); /* falls all the way */
    ck_assert_int_eq(odhs_correlation_minimum(g, 10, &x, &gm), ODHS_E_EMPTY);
    ck_assert_msg(strstr(odhs_last_error(), "no interior minimum"), "%s", odhs_last_error());
}
END_TEST

/* ---- scaling collapse ---------------------------------------------------------- */
START_TEST(test_collapse_synthetic)
{
    /* O = rate^(y/znu) exp(G(x)), x = (phi - phi_J)/rate^(1/znu), G a cubic,
     * with 1 % noise: phi_J = 0.8433, y = 1.1, z nu = 3.5 (the thesis' RD0
     * values) recovered within 3 errors; errors shrink with the noise */
    const double pj = 0.8433, y = 1.1, znu = 3.5;
    const double rates[] = {1e-7, 1e-6, 1e-5, 1e-4};
    enum { NPHI = 11, NR = 4, NP = NPHI * NR };
    double phi[NP], rate[NP], val[NP], err[NP];
    for (int noise = 0; noise < 2; ++noise) {
        tu_rng r;
        tu_rng_seed(&r, 77);
        for (int a = 0; a < NR; ++a)
            for (int b = 0; b < NPHI; ++b) {
                int k = a * NPHI + b;
                phi[k] = 0.83 + 0.003 * b;
                rate[k] = rates[a];
                double x = (phi[k] - pj) / pow(rate[k], 1.0 / znu);
                double G = 0.3 + 1.2 * x - 0.1 * x * x + 0.02 * x * x * x;
                double e = noise ? 0.01 : 1e-4;
                val[k] = pow(rate[k], y / znu) * exp(G) * (1.0 + e * normal(&r));
                err[k] = e;
            }
        odhs_collapse c;
        memset(&c, 0, sizeof c);
        c.size = sizeof c;
        const double guess[3] = {0.84, 1.0, 3.0};
        int s = odhs_collapse_fit(phi, rate, val, err, NP, 3, guess, &c);
        ck_assert_msg(s == ODHS_OK, "collapse: %d (%s)", s, odhs_last_error());
        printf("[analysis] collapse, %s noise: phi_J %.5f +- %.5f, y %.3f +- %.3f, z nu %.3f +- %.3f, chi2/dof %.2f "
               "(%u evaluations)\n",
               noise ? "1 %" : "0.01 %", c.phi_j, c.phi_j_err, c.y, c.y_err, c.znu, c.znu_err, c.chi2 / (double)c.dof,
               c.evaluations);
        ck_assert_msg(fabs(c.phi_j - pj) < 3.0 * c.phi_j_err + 1e-6, "phi_J %g +- %g", c.phi_j, c.phi_j_err);
        ck_assert_msg(fabs(c.y - y) < 3.0 * c.y_err + 1e-4, "y %g +- %g", c.y, c.y_err);
        ck_assert_msg(fabs(c.znu - znu) < 3.0 * c.znu_err + 1e-4, "z nu %g +- %g", c.znu, c.znu_err);
        ck_assert_msg(c.chi2 / (double)c.dof < 2.0, "chi2/dof %g", c.chi2 / (double)c.dof);
        ck_assert_msg(c.phi_j_err < (noise ? 2e-3 : 2e-5), "phi_J error %g", c.phi_j_err);
        ck_assert(c.dof == NP - 4 - 3 && c.degree == 3 && fabs(c.q - c.y / c.znu) < 1e-15);
    }
    /* one rate only: the exponents are not determined */
    odhs_collapse c;
    memset(&c, 0, sizeof c);
    c.size = sizeof c;
    ck_assert_int_eq(odhs_collapse_fit(phi, rate, val, err, NPHI, 3, NULL, &c), ODHS_E_EMPTY);
}
END_TEST

Suite *make_analysis_suite(void)
{
    Suite *s = suite_create("analysis");
    TCase *tc = tcase_create("analysis");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_series_ar1);
    tcase_add_test(tc, test_series_short);
    tcase_add_test(tc, test_histogram);
    tcase_add_test(tc, test_event_split);
    tcase_add_test(tc, test_power_law);
    tcase_add_test(tc, test_backbone_by_hand);
    tcase_add_test(tc, test_jammed_packing);
    tcase_add_test(tc, test_velocity_correlation);
    tcase_add_test(tc, test_correlation_minimum);
    tcase_add_test(tc, test_collapse_synthetic);
    suite_add_tcase(s, tc);
    return s;
}
