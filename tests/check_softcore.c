/*
 * libodhs - tests of the soft-core reference models (suite "softcore").
 *
 *  - "fd": elastic forces are minus the finite-difference gradient of the
 *    energy, and sigma_xy^el Omega is the derivative of the energy under an
 *    affine shear (a quasistatic step with no minimisation), for alpha = 2
 *    and 5/2, polydisperse radii, nonzero Lees-Edwards strain, 2D and 3D.
 *  - "sd": steepest descent lowers the energy at every iteration (RD0
 *    steps at zero shear rate are the same gradient-flow iterations), and
 *    odhs_softcore_minimise(SD) after k iterations equals k such steps.
 *  - "minimisers": FIRE and Polak-Ribiere CG reach max |grad U| < tol and an
 *    energy not above the start.
 *  - "sllod": without dissipation and shear the massive models conserve
 *    K + U within the velocity-Verlet error (O(h^2), checked by halving h);
 *    under shear the energy balance dH/dt = gammadot Omega sigma_xy holds.
 *  - "cd0": for an isolated pair CD0 with (k_d, k_0) equals RD0 with drag
 *    2 k_d + k_0 (exact); with k_d -> 0 CD0 equals RD0 with drag k_0.
 *  - "hs_limit": RD0 at gammadot tau_e = 1e-7 reproduces the event-driven
 *    shear stress within 1% and the positions within 1e-3 mean diameters on
 *    N = 32 discs at phi = 0.80 after a strain of 0.002; the quasistatic
 *    steepest-descent route (dgamma = 1e-5) does the same for the stress
 *    (relaxation stress) and positions.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "testutil.h"

#define CHECK_OK(call)                                                                         \
    do {                                                                                       \
        int rc_ = (call);                                                                      \
        ck_assert_msg(rc_ == ODHS_OK, "%s returned %d (%s)", #call, rc_, odhs_strerror(rc_)); \
    } while (0)

/* a random polydisperse system with overlaps: RSA at phi0, a nonzero
 * Lees-Edwards strain, then random displacements of up to `shake` */
static odhs_system *overlapped(int dim, size_t n, double phi0, double shake, uint64_t seed, odhs_softcore **sc)
{
    odhs_system *sys;
    CHECK_OK(odhs_system_create(dim, n, &sys));
    CHECK_OK(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.1, seed));
    CHECK_OK(odhs_system_place_random(sys, phi0, seed));
    CHECK_OK(odhs_softcore_create(sys, sc));
    /* Lees-Edwards strain 0.3 by affine shear (no minimisation) */
    CHECK_OK(odhs_softcore_set_min_tolerance(*sc, 1e300, 1));
    for (int k = 0; k < 3; ++k) CHECK_OK(odhs_softcore_quasistatic_step(*sc, 0.1, NULL));
    CHECK_OK(odhs_softcore_set_min_tolerance(*sc, 1e-9, 100000000));
    double g;
    CHECK_OK(odhs_system_get_strain(sys, &g));
    ck_assert(fabs(g - 0.3) < 1e-12);
    double *x = malloc(n * dim * sizeof *x);
    CHECK_OK(odhs_system_get_positions(sys, x));
    tu_rng r;
    tu_rng_seed(&r, seed);
    for (size_t k = 0; k < n * dim; ++k) x[k] += tu_uniform_in(&r, -shake, shake);
    CHECK_OK(odhs_softcore_set_positions(*sc, x));
    free(x);
    return sys;
}

static double energy(odhs_softcore *sc)
{
    double U;
    CHECK_OK(odhs_softcore_energy(sc, &U));
    return U;
}

/* odhs_softcore_scale_box: an affine isotropic compression into overlap. Two
 * discs of radius 0.5 touching along x in a 4 x 4 box, scaled by s: the
 * separation becomes s, the harmonic energy (1/2)(1 - s)^2 (k_e = 1), the
 * overlap 1 - s, the box s L and phi phi0 / s^2, exactly; positions scale
 * about the origin. A factor that would make the box too small is refused
 * with the system unchanged bit for bit. */
START_TEST(test_scale_box)
{
    odhs_system *sys;
    odhs_softcore *sc;
    CHECK_OK(odhs_system_create(2, 2, &sys));
    double L[3] = {4.0, 4.0, 1.0}, r[2] = {0.5, 0.5}, x[4] = {1.5, 2.0, 2.5, 2.0};
    CHECK_OK(odhs_system_set_box(sys, L));
    CHECK_OK(odhs_system_set_radii(sys, r));
    CHECK_OK(odhs_system_set_positions(sys, x));
    CHECK_OK(odhs_softcore_create(sys, &sc));
    CHECK_OK(odhs_softcore_set_potential(sc, 2.0, 1.0));
    double phi0, phi, U, ov, L2[3], x2[4];
    CHECK_OK(odhs_system_packing_fraction(sys, &phi0));
    ck_assert(fabs(energy(sc)) == 0.0);
    const double s = 0.875; /* exact in binary */
    CHECK_OK(odhs_softcore_scale_box(sc, s));
    CHECK_OK(odhs_system_get_box(sys, L2));
    CHECK_OK(odhs_system_get_positions(sys, x2));
    CHECK_OK(odhs_system_packing_fraction(sys, &phi));
    U = energy(sc);
    CHECK_OK(odhs_softcore_max_overlap(sc, &ov));
    ck_assert_msg(L2[0] == s * L[0] && L2[1] == s * L[1], "box %.17g %.17g", L2[0], L2[1]);
    for (int k = 0; k < 4; ++k) ck_assert_msg(x2[k] == s * x[k], "x[%d] = %.17g", k, x2[k]);
    ck_assert_msg(fabs(phi - phi0 / (s * s)) <= 1e-15 * phi, "phi %.17g, expected %.17g", phi, phi0 / (s * s));
    ck_assert_msg(fabs(U - 0.5 * (1.0 - s) * (1.0 - s)) <= 1e-15, "energy %.17g", U);
    ck_assert_msg(fabs(ov - (1.0 - s)) <= 1e-15, "overlap %.17g", ov);
    /* and back: no overlap, no energy */
    CHECK_OK(odhs_softcore_scale_box(sc, 1.0 / s));
    ck_assert_msg(fabs(energy(sc)) <= 1e-30, "energy after dilation %.3g", energy(sc));
    /* refused: edge 4 * 0.2 = 0.8 < 2 largest diameters; nothing changes */
    double L3[3], x3[4];
    CHECK_OK(odhs_system_get_box(sys, L2));
    CHECK_OK(odhs_system_get_positions(sys, x2));
    ck_assert_int_eq(odhs_softcore_scale_box(sc, 0.2), ODHS_E_BOX);
    ck_assert(strstr(odhs_softcore_errmsg(sc), "box edge") != NULL);
    CHECK_OK(odhs_system_get_box(sys, L3));
    CHECK_OK(odhs_system_get_positions(sys, x3));
    ck_assert(memcmp(L2, L3, 2 * sizeof(double)) == 0 && memcmp(x2, x3, sizeof x2) == 0);
    odhs_softcore_destroy(sc);
    odhs_system_destroy(sys);
}
END_TEST

static void fd_case(int dim, double alpha)
{
    odhs_softcore *sc;
    size_t n = dim == 2 ? 24 : 20;
    odhs_system *sys = overlapped(dim, n, dim == 2 ? 0.6 : 0.4, 0.25, 11 + dim, &sc);
    CHECK_OK(odhs_softcore_set_potential(sc, alpha, 3.0));
    double *x = malloc(n * dim * sizeof *x), *F = malloc(n * dim * sizeof *F), *xp = malloc(n * dim * sizeof *xp);
    CHECK_OK(odhs_system_get_positions(sys, x));
    CHECK_OK(odhs_softcore_forces(sc, F));
    double U0 = energy(sc), fbig = 0.0, err = 0.0;
    ck_assert_msg(U0 > 0.0, "no overlaps in the test state");
    double ov;
    CHECK_OK(odhs_softcore_max_overlap(sc, &ov));
    ck_assert(ov > 0.01);
    const double h = 1e-6;
    for (size_t k = 0; k < n * dim; ++k) {
        memcpy(xp, x, n * dim * sizeof *xp);
        xp[k] = x[k] + h;
        CHECK_OK(odhs_softcore_set_positions(sc, xp));
        double Up = energy(sc);
        xp[k] = x[k] - h;
        CHECK_OK(odhs_softcore_set_positions(sc, xp));
        double Um = energy(sc);
        double g = (Up - Um) / (2 * h);
        err = fmax(err, fabs(g + F[k]));
        fbig = fmax(fbig, fabs(F[k]));
    }
    ck_assert_msg(err < 1e-6 * fbig, "dim %d alpha %g: |F + grad U| = %.3g (max |F| %.3g)", dim, alpha, err, fbig);
    /* stress: Omega sigma_xy = dU/dgamma under affine shear */
    CHECK_OK(odhs_softcore_set_positions(sc, x));
    double sig[9], vol;
    CHECK_OK(odhs_softcore_stress(sc, ODHS_SOFTCORE_STRESS_ELASTIC, sig));
    CHECK_OK(odhs_system_volume(sys, &vol));
    CHECK_OK(odhs_softcore_set_min_tolerance(sc, 1e300, 1));
    CHECK_OK(odhs_softcore_quasistatic_step(sc, h, NULL));
    double Up = energy(sc);
    CHECK_OK(odhs_softcore_quasistatic_step(sc, -2 * h, NULL));
    double Um = energy(sc);
    double dUdg = (Up - Um) / (2 * h);
    ck_assert_msg(fabs(dUdg - vol * sig[1]) < 1e-6 * fabs(dUdg) + 1e-9,
                  "dim %d alpha %g: dU/dgamma %.10g vs Omega sigma_xy %.10g", dim, alpha, dUdg, vol * sig[1]);
    /* pressure = -tr sigma / d; for RD0 the total equals the elastic part */
    double p;
    CHECK_OK(odhs_softcore_pressure(sc, &p));
    ck_assert(p > 0.0);
    free(x);
    free(F);
    free(xp);
    odhs_softcore_destroy(sc);
    odhs_system_destroy(sys);
}

START_TEST(test_fd)
{
    fd_case(2, 2.0);
    fd_case(2, 2.5);
    fd_case(3, 2.0);
    fd_case(3, 2.5);
}
END_TEST

START_TEST(test_sd)
{
    odhs_softcore *sc;
    size_t n = 32;
    odhs_system *sys = overlapped(2, n, 0.6, 0.2, 5, &sc);
    odhs_system *copy;
    CHECK_OK(odhs_system_clone(sys, &copy));
    double U = energy(sc);
    for (int k = 0; k < 300; ++k) {
        CHECK_OK(odhs_softcore_step(sc));
        double U2 = energy(sc);
        ck_assert_msg(U2 <= U, "energy rose at step %d: %.17g -> %.17g", k, U, U2);
        U = U2;
    }
    /* the minimiser's iterations are these steps */
    odhs_softcore *sd;
    CHECK_OK(odhs_softcore_create(copy, &sd));
    CHECK_OK(odhs_softcore_set_min_tolerance(sd, 1e-300, 300));
    ck_assert_int_eq(odhs_softcore_minimise(sd, NULL), ODHS_E_NOCONV);
    /* rolled back: the copy still has the start; now stop at the force reached */
    double fm;
    CHECK_OK(odhs_softcore_max_force(sc, &fm));
    CHECK_OK(odhs_softcore_set_min_tolerance(sd, fm * (1 + 1e-9), 100000));
    uint64_t it;
    CHECK_OK(odhs_softcore_minimise(sd, &it));
    ck_assert_msg(it >= 295 && it <= 300, "minimise took %llu iterations", (unsigned long long)it);
    odhs_softcore_destroy(sd);
    odhs_system_destroy(copy);
    /* and it converges to the tolerance */
    CHECK_OK(odhs_softcore_set_min_tolerance(sc, 1e-10, 10000000));
    CHECK_OK(odhs_softcore_minimise(sc, &it));
    CHECK_OK(odhs_softcore_max_force(sc, &fm));
    ck_assert(fm < 1e-10);
    ck_assert(energy(sc) <= U);
    odhs_softcore_destroy(sc);
    odhs_system_destroy(sys);
}
END_TEST

START_TEST(test_minimisers)
{
    int mins[2] = {ODHS_SOFTCORE_FIRE, ODHS_SOFTCORE_CG};
    for (int m = 0; m < 2; ++m)
        for (int jammed = 0; jammed < 2; ++jammed) { /* two starts */
            odhs_softcore *sc;
            odhs_system *sys = overlapped(2, 40, jammed ? 0.6 : 0.5, jammed ? 0.35 : 0.2, 7, &sc);
            double U0 = energy(sc);
            CHECK_OK(odhs_softcore_set_minimiser(sc, mins[m]));
            CHECK_OK(odhs_softcore_set_min_tolerance(sc, 1e-11, 10000000));
            uint64_t it;
            CHECK_OK(odhs_softcore_minimise(sc, &it));
            double fm;
            CHECK_OK(odhs_softcore_max_force(sc, &fm));
            ck_assert_msg(fm < 1e-11, "minimiser %d: max force %.3g", mins[m], fm);
            ck_assert(energy(sc) <= U0);
            ck_assert(it > 0);
            odhs_softcore_destroy(sc);
            odhs_system_destroy(sys);
        }
}
END_TEST

/* SLLOD energy drift over a fixed time with step factor c */
static double sllod_drift(int model, double c, double gdot, double *balance)
{
    odhs_softcore *sc;
    size_t n = 32;
    odhs_system *sys = overlapped(2, n, 0.55, 0.2, 9, &sc);
    CHECK_OK(odhs_softcore_set_model(sc, model));
    CHECK_OK(odhs_softcore_set_drag(sc, 0.0));
    CHECK_OK(odhs_softcore_set_mass(sc, 2.0));
    CHECK_OK(odhs_softcore_set_shear_rate(sc, gdot));
    CHECK_OK(odhs_softcore_set_dt(sc, c));
    double u[64];
    tu_rng r;
    tu_rng_seed(&r, 3);
    for (int k = 0; k < 64; ++k) u[k] = tu_uniform_in(&r, -0.05, 0.05);
    CHECK_OK(odhs_softcore_set_velocities(sc, u));
    double vol;
    CHECK_OK(odhs_system_volume(sys, &vol));
    double K, U, sig[4];
    CHECK_OK(odhs_softcore_kinetic_energy(sc, &K));
    U = energy(sc);
    double H0 = K + U, work = 0.0, t = 0.0, drift = 0.0;
    CHECK_OK(odhs_softcore_stress(sc, ODHS_SOFTCORE_STRESS_TOTAL, sig));
    double p_prev = gdot * vol * sig[1];
    while (t < 20.0) {
        CHECK_OK(odhs_softcore_step(sc));
        double t2;
        CHECK_OK(odhs_softcore_time(sc, &t2));
        CHECK_OK(odhs_softcore_stress(sc, ODHS_SOFTCORE_STRESS_TOTAL, sig));
        double p = gdot * vol * sig[1];
        work += 0.5 * (p + p_prev) * (t2 - t);
        p_prev = p;
        t = t2;
        CHECK_OK(odhs_softcore_kinetic_energy(sc, &K));
        U = energy(sc);
        drift = fmax(drift, fabs(K + U - H0 - work));
    }
    if (balance) *balance = fabs(work);
    odhs_softcore_destroy(sc);
    odhs_system_destroy(sys);
    return drift / H0;
}

START_TEST(test_sllod)
{
    int models[3] = {ODHS_SOFTCORE_RD, ODHS_SOFTCORE_CD, ODHS_SOFTCORE_CDN};
    for (int m = 0; m < 3; ++m) {
        double d1 = sllod_drift(models[m], 0.05, 0.0, NULL);
        double d2 = sllod_drift(models[m], 0.025, 0.0, NULL);
        ck_assert_msg(d1 < 1e-3, "model %d: relative energy drift %.3g", models[m], d1);
        ck_assert_msg(d2 < 0.35 * d1, "model %d: drift %.3g -> %.3g on halving h (not O(h^2))", models[m], d1, d2);
    }
    double work;
    double d = sllod_drift(ODHS_SOFTCORE_CD, 0.025, 0.02, &work);
    ck_assert_msg(work > 0.0, "no work done by the shear");
    ck_assert_msg(d < 1e-3, "energy balance under shear: %.3g", d);
}
END_TEST

START_TEST(test_cd0)
{
    /* an isolated overlapping pair */
    odhs_system *sys;
    CHECK_OK(odhs_system_create(2, 2, &sys));
    double L[2] = {10, 10}, r[2] = {0.5, 0.7}, x[4] = {3, 3, 4.3, 3.4};
    CHECK_OK(odhs_system_set_configuration(sys, L, 0.0, r, x));
    odhs_softcore *a, *b;
    CHECK_OK(odhs_softcore_create(sys, &a));
    CHECK_OK(odhs_softcore_create(sys, &b));
    double xo[4] = {3, 3, 4.0, 3.3};
    CHECK_OK(odhs_softcore_set_positions(a, xo));
    CHECK_OK(odhs_softcore_set_model(a, ODHS_SOFTCORE_CD0));
    CHECK_OK(odhs_softcore_set_drag(a, 1.5));
    CHECK_OK(odhs_softcore_set_substrate(a, 0.2));
    CHECK_OK(odhs_softcore_set_drag(b, 2 * 1.5 + 0.2));
    double ua[4], ub[4];
    CHECK_OK(odhs_softcore_velocities(a, ua));
    CHECK_OK(odhs_softcore_velocities(b, ub));
    for (int k = 0; k < 4; ++k) {
        ck_assert_msg(fabs(ua[k] - ub[k]) < 1e-12 * fabs(ub[k]) + 1e-15, "pair: %g vs %g", ua[k], ub[k]);
        ck_assert(fabs(ub[k]) > 1e-3);
    }
    odhs_softcore_destroy(a);
    odhs_softcore_destroy(b);
    odhs_system_destroy(sys);
    /* k_d -> 0: CD0 equals RD0 with drag k_0, also under shear */
    odhs_softcore *c, *d;
    odhs_system *s2 = overlapped(2, 40, 0.6, 0.2, 13, &c);
    CHECK_OK(odhs_softcore_create(s2, &d));
    CHECK_OK(odhs_softcore_set_model(c, ODHS_SOFTCORE_CD0));
    CHECK_OK(odhs_softcore_set_drag(c, 1e-9));
    CHECK_OK(odhs_softcore_set_substrate(c, 2.0));
    CHECK_OK(odhs_softcore_set_drag(d, 2.0));
    CHECK_OK(odhs_softcore_set_shear_rate(c, 0.01));
    CHECK_OK(odhs_softcore_set_shear_rate(d, 0.01));
    double uc[80], ud[80], um = 0.0, diff = 0.0;
    CHECK_OK(odhs_softcore_velocities(c, uc));
    CHECK_OK(odhs_softcore_velocities(d, ud));
    for (int k = 0; k < 80; ++k) {
        um = fmax(um, fabs(ud[k]));
        diff = fmax(diff, fabs(uc[k] - ud[k]));
    }
    ck_assert_msg(diff < 1e-7 * um, "k_d -> 0: |u_CD0 - u_RD0| = %.3g (max %.3g)", diff, um);
    /* CD0 dissipative stress: for k_d > 0 the total includes it */
    CHECK_OK(odhs_softcore_set_drag(c, 1.0));
    double st[4], se[4], sd[4];
    CHECK_OK(odhs_softcore_stress(c, ODHS_SOFTCORE_STRESS_TOTAL, st));
    CHECK_OK(odhs_softcore_stress(c, ODHS_SOFTCORE_STRESS_ELASTIC, se));
    CHECK_OK(odhs_softcore_stress(c, ODHS_SOFTCORE_STRESS_DISSIPATIVE, sd));
    for (int k = 0; k < 4; ++k) ck_assert(fabs(st[k] - se[k] - sd[k]) < 1e-12 * (fabs(st[k]) + fabs(se[k]) + 1e-300));
    odhs_softcore_destroy(c);
    odhs_softcore_destroy(d);
    odhs_system_destroy(s2);
}
END_TEST

/* largest minimum-image distance between the positions of two systems */
static double max_diff(const odhs_system *sa, const odhs_system *sb)
{
    size_t n = odhs_system_count(sa);
    double *xa = malloc(2 * n * sizeof *xa), *xb = malloc(2 * n * sizeof *xb), L[2], g, err = 0.0;
    CHECK_OK(odhs_system_get_positions(sa, xa));
    CHECK_OK(odhs_system_get_positions(sb, xb));
    CHECK_OK(odhs_system_get_box(sa, L));
    CHECK_OK(odhs_system_get_strain(sa, &g));
    for (size_t i = 0; i < n; ++i) {
        double d[2] = {xb[2 * i] - xa[2 * i], xb[2 * i + 1] - xa[2 * i + 1]};
        double ny = nearbyint(d[1] / L[1]);
        d[1] -= ny * L[1];
        d[0] -= ny * g * L[1];
        d[0] -= nearbyint(d[0] / L[0]) * L[0];
        err = fmax(err, hypot(d[0], d[1]));
    }
    free(xa);
    free(xb);
    return err;
}

/* the adaptive integrator against fixed Euler steps, RD0 and CD0: with the
 * reference Euler c = 2e-4 (global error O(c)), Euler c = 2e-3 is about 10x
 * further from it, adaptive Heun at tol 1e-8 much closer */
START_TEST(test_adaptive)
{
    int models[2] = {ODHS_SOFTCORE_RD0, ODHS_SOFTCORE_CD0};
    for (int m = 0; m < 2; ++m) {
        odhs_softcore *h[3];
        odhs_system *s[3];
        s[0] = overlapped(2, 24, 0.55, 0.15, 17, &h[0]);
        double x[48];
        CHECK_OK(odhs_system_get_positions(s[0], x));
        for (int k = 1; k < 3; ++k) {
            CHECK_OK(odhs_system_clone(s[0], &s[k]));
            CHECK_OK(odhs_softcore_create(s[k], &h[k]));
        }
        for (int k = 0; k < 3; ++k) {
            CHECK_OK(odhs_softcore_set_model(h[k], models[m]));
            CHECK_OK(odhs_softcore_set_substrate(h[k], 0.5));
            CHECK_OK(odhs_softcore_set_shear_rate(h[k], 1e-2));
        }
        CHECK_OK(odhs_softcore_set_dt(h[0], 2e-4));
        CHECK_OK(odhs_softcore_set_dt(h[1], 2e-3));
        CHECK_OK(odhs_softcore_set_integrator(h[2], ODHS_SOFTCORE_ADAPTIVE));
        CHECK_OK(odhs_softcore_set_tolerance(h[2], 1e-8));
        for (int k = 0; k < 3; ++k) CHECK_OK(odhs_softcore_run_until_time(h[k], 2.0));
        double e_coarse = max_diff(s[0], s[1]), e_adapt = max_diff(s[0], s[2]);
        ck_assert_msg(e_coarse > 0.0 && e_adapt < 0.3 * e_coarse && e_adapt < 1e-3,
                      "model %d: Euler c=2e-3 %.3g, adaptive %.3g from Euler c=2e-4", models[m], e_coarse, e_adapt);
        for (int k = 0; k < 3; ++k) {
            odhs_softcore_destroy(h[k]);
            odhs_system_destroy(s[k]);
        }
    }
}
END_TEST

/* minimum-image rms difference of two systems' positions, in units of len */
static double rms_diff(const odhs_system *a, const odhs_system *b)
{
    size_t n = odhs_system_count(a);
    double *xa = malloc(2 * n * sizeof *xa), *xb = malloc(2 * n * sizeof *xb), s = 0.0;
    CHECK_OK(odhs_system_get_positions(a, xa));
    CHECK_OK(odhs_system_get_positions(b, xb));
    for (size_t i = 0; i < n; ++i) {
        double rij[2];
        (void)rij;
        double d[2] = {xb[2 * i] - xa[2 * i], xb[2 * i + 1] - xa[2 * i + 1]};
        double L[2], g;
        odhs_system_get_box(a, L);
        odhs_system_get_strain(a, &g);
        double ny = nearbyint(d[1] / L[1]);
        d[1] -= ny * L[1];
        d[0] -= ny * g * L[1];
        d[0] -= nearbyint(d[0] / L[0]) * L[0];
        s += d[0] * d[0] + d[1] * d[1];
    }
    free(xa);
    free(xb);
    return sqrt(s / n);
}

START_TEST(test_hs_limit)
{
    odhs_system *sys;
    CHECK_OK(odhs_system_create(2, 32, &sys));
    CHECK_OK(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.0, 3));
    CHECK_OK(odhs_system_place_random(sys, 0.45, 3));
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
    CHECK_OK(odhs_driver_create(&drv));
    CHECK_OK(odhs_driver_set_compression_rate(drv, 1.0));
    CHECK_OK(odhs_solver_create_by_name("dense", &sol));
    CHECK_OK(odhs_stepper_create(sys, drv, sol, &st));
    CHECK_OK(odhs_stepper_run_until_packing_fraction(st, 0.80));
    ck_assert(odhs_stepper_correct(st) >= 0);
    odhs_stepper_destroy(st);
    odhs_system *ed, *rd, *qs;
    CHECK_OK(odhs_system_clone(sys, &ed));
    CHECK_OK(odhs_system_clone(sys, &rd));
    CHECK_OK(odhs_system_clone(sys, &qs));
    CHECK_OK(odhs_driver_set_compression_rate(drv, 0.0));
    CHECK_OK(odhs_driver_set_shear_rate(drv, 1.0));
    CHECK_OK(odhs_stepper_create(ed, drv, sol, &st));
    CHECK_OK(odhs_stepper_set_integrator(st, ODHS_INTEGRATOR_HEUN));
    CHECK_OK(odhs_stepper_set_tolerance(st, 1e-10));
    const double G = 0.002;
    CHECK_OK(odhs_stepper_run_until_strain(st, G));
    double sed[4];
    CHECK_OK(odhs_stepper_stress(st, sed));
    ck_assert(sed[1] > 0.0);
    /* RD0, gammadot tau_e = 1e-7 (tau_e = k_d d_min^2 / k_e = 1) */
    odhs_softcore *sc;
    CHECK_OK(odhs_softcore_create(rd, &sc));
    const double rate = 1e-7;
    CHECK_OK(odhs_softcore_set_shear_rate(sc, rate));
    CHECK_OK(odhs_softcore_run_until_strain(sc, G));
    double srd[4];
    CHECK_OK(odhs_softcore_stress(sc, ODHS_SOFTCORE_STRESS_TOTAL, srd));
    double rel = fabs(srd[1] / rate - sed[1]) / sed[1], dx = rms_diff(ed, rd);
    ck_assert_msg(rel < 0.01, "RD0 stress/rate %.6g vs event-driven %.6g (rel %.3g)", srd[1] / rate, sed[1], rel);
    ck_assert_msg(dx < 1e-3, "RD0 rms position difference %.3g", dx);
    odhs_softcore_destroy(sc);
    /* quasistatic steepest descent */
    CHECK_OK(odhs_softcore_create(qs, &sc));
    CHECK_OK(odhs_softcore_set_min_tolerance(sc, 1e-9, 100000000));
    for (int k = 0; k < 200; ++k) CHECK_OK(odhs_softcore_quasistatic_step(sc, G / 200, NULL));
    double sq[4];
    CHECK_OK(odhs_softcore_relaxation_stress(sc, sq));
    rel = fabs(sq[1] - sed[1]) / sed[1];
    dx = rms_diff(ed, qs);
    ck_assert_msg(rel < 0.01, "QS relaxation stress %.6g vs event-driven %.6g (rel %.3g)", sq[1], sed[1], rel);
    ck_assert_msg(dx < 1e-4, "QS rms position difference %.3g", dx);
    odhs_softcore_destroy(sc);
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_driver_destroy(drv);
    odhs_system_destroy(ed);
    odhs_system_destroy(rd);
    odhs_system_destroy(qs);
    odhs_system_destroy(sys);
}
END_TEST

Suite *make_softcore_suite(void)
{
    Suite *s = suite_create("softcore");
    TCase *tc = tcase_create("core");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_scale_box);
    tcase_add_test(tc, test_fd);
    tcase_add_test(tc, test_sd);
    tcase_add_test(tc, test_minimisers);
    tcase_add_test(tc, test_sllod);
    tcase_add_test(tc, test_cd0);
    tcase_add_test(tc, test_adaptive);
    tcase_add_test(tc, test_hs_limit);
    suite_add_tcase(s, tc);
    return s;
}
