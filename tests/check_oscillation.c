/* Check suite "oscillation": oscillatory simple shear (odhs_driver_set_oscillatory_shear). */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "odhs.h"

#define PI 3.14159265358979323846

typedef struct {
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
} run;

/* 2D bidisperse scene: RSA at phi0, then (phi > phi0) compressed to phi */
static odhs_system *scene(size_t n, double phi0, double phi, unsigned seed)
{
    odhs_system *sys;
    ck_assert_int_eq(odhs_system_create(2, n, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, seed), ODHS_OK);
    ck_assert_int_eq(odhs_system_place_random(sys, phi0, seed + 1), ODHS_OK);
    if (phi > phi0) {
        odhs_solver *sol;
        odhs_driver *drv;
        odhs_stepper *st;
        ck_assert_int_eq(odhs_solver_create_by_name("dense", &sol), ODHS_OK);
        ck_assert_int_eq(odhs_driver_create(&drv), ODHS_OK);
        ck_assert_int_eq(odhs_driver_set_compression_rate(drv, 1.0), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_create(sys, drv, sol, &st), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_run_until_packing_fraction(st, phi), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_correct(st), ODHS_OK);
        odhs_stepper_destroy(st);
        odhs_driver_destroy(drv);
        odhs_solver_destroy(sol);
    }
    return sys;
}

/* a stepper on a clone of start under oscillatory shear */
static run start_run(const odhs_system *start, int shape, double amp, double period, const char *solver)
{
    run r;
    ck_assert_int_eq(odhs_system_clone(start, &r.sys), ODHS_OK);
    ck_assert_int_eq(odhs_driver_create(&r.drv), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_oscillatory_shear(r.drv, shape, amp, period, 0.0), ODHS_OK);
    ck_assert_int_eq(odhs_solver_create_by_name(solver, &r.sol), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_create(r.sys, r.drv, r.sol, &r.st), ODHS_OK);
    return r;
}

static void end_run(run *r)
{
    odhs_stepper_destroy(r->st);
    odhs_solver_destroy(r->sol);
    odhs_driver_destroy(r->drv);
    odhs_system_destroy(r->sys);
}

/* rms over particles of the minimum-image displacement between a and b */
static double rms_displacement(const odhs_system *sys, const double *a, const double *b)
{
    size_t n = odhs_system_count(sys);
    int dim = odhs_system_dim(sys);
    double L[3], g, s = 0.0;
    odhs_system_get_box(sys, L);
    odhs_system_get_strain(sys, &g);
    for (size_t i = 0; i < n; ++i) {
        double d[3] = {0, 0, 0};
        for (int k = 0; k < dim; ++k) d[k] = b[i * dim + k] - a[i * dim + k];
        /* Lees-Edwards minimum image of d (small displacements) */
        double ny = nearbyint(d[1] / L[1]);
        d[1] -= ny * L[1];
        d[0] -= ny * g * L[1];
        d[0] -= nearbyint(d[0] / L[0]) * L[0];
        for (int k = 0; k < dim; ++k) s += d[k] * d[k];
    }
    return sqrt(s / (double)n);
}

static double triangle(double amp, double period, double t)
{
    double x = t / period - floor(t / period); /* phase in [0, 1) */
    if (x < 0.25) return 4.0 * amp * x;
    if (x < 0.75) return amp * (2.0 - 4.0 * x);
    return 4.0 * amp * (x - 1.0);
}

/* No contacts: the motion is affine. The triangle's chords carry a constant
 * rate, so the strain and the box tilt follow gamma(t) to round-off, steps
 * end exactly at the reversals, and after a period the particles are back. */
START_TEST(test_triangle_affine)
{
    odhs_system *start = scene(16, 0.05, 0.0, 3);
    size_t nd = 32;
    double x0[32], x[32];
    odhs_system_get_positions(start, x0);
    run r = start_run(start, ODHS_OSCILLATION_TRIANGLE, 0.3, 2.0, "dense");
    int hit[2] = {0, 0};
    double t = 0.0;
    while (t < 2.0) {
        ck_assert_int_eq(odhs_stepper_step(r.st, NULL), ODHS_OK);
        odhs_stepper_time(r.st, &t);
        if (t == 0.5) hit[0] = 1; /* the reversals at T/4 and 3T/4 */
        if (t == 1.5) hit[1] = 1;
        if (t > 2.0) break;
        double g, gbox;
        odhs_stepper_strain(r.st, &g);
        odhs_system_get_strain(r.sys, &gbox);
        ck_assert_msg(fabs(g - triangle(0.3, 2.0, t)) < 1e-14, "strain %.17g at t = %.17g, want %.17g", g, t,
                      triangle(0.3, 2.0, t));
        ck_assert_msg(fabs(gbox - g) < 1e-13, "box tilt %.17g against strain %.17g", gbox, g);
    }
    ck_assert_msg(hit[0] && hit[1], "no step ended at a reversal (%d %d)", hit[0], hit[1]);
    ck_assert_int_eq(odhs_stepper_run_until_time(r.st, 4.0), ODHS_OK);
    double g, gbox;
    odhs_stepper_strain(r.st, &g);
    odhs_system_get_strain(r.sys, &gbox);
    odhs_system_get_positions(r.sys, x);
    ck_assert_msg(fabs(g) < 1e-14 && fabs(gbox) < 1e-14, "after two periods strain %g, box %g", g, gbox);
    double d = rms_displacement(r.sys, x0, x);
    ck_assert_msg(d < 1e-13, "affine displacement over two cycles %g", d);
    uint64_t coll;
    odhs_stepper_counts(r.st, NULL, &coll, NULL);
    ck_assert_int_eq(coll, 0);
    (void)nd;
    end_run(&r);
    odhs_system_destroy(start);
}
END_TEST

/* The sine: the accumulated strain is gamma(t) exactly, the box tilt to the
 * integrator's accuracy, and both come back after a period. */
START_TEST(test_sine_affine)
{
    odhs_system *start = scene(16, 0.05, 0.0, 5);
    double x0[32], x[32], worst[2] = {0, 0}, back[2];
    odhs_system_get_positions(start, x0);
    const double tols[2] = {1e-6, 1e-10};
    for (int a = 0; a < 2; ++a) {
        run r = start_run(start, ODHS_OSCILLATION_SINE, 0.2, 1.0, "dense");
        ck_assert_int_eq(odhs_stepper_set_tolerance(r.st, tols[a]), ODHS_OK);
        for (int k = 1; k <= 8; ++k) {
            double t = k / 8.0, g, gbox;
            ck_assert_int_eq(odhs_stepper_run_until_time(r.st, t), ODHS_OK);
            odhs_stepper_strain(r.st, &g);
            odhs_system_get_strain(r.sys, &gbox);
            ck_assert_msg(fabs(g - 0.2 * sin(2.0 * PI * t)) < 1e-14, "strain %.17g at t = %g", g, t);
            worst[a] = fmax(worst[a], fabs(gbox - g));
        }
        odhs_system_get_positions(r.sys, x);
        back[a] = rms_displacement(r.sys, x0, x);
        end_run(&r);
    }
    printf("[oscillation] sine, box tilt against gamma(t): %.3g at tol 1e-6, %.3g at tol 1e-10; back after a cycle to "
           "%.3g and %.3g\n",
           worst[0], worst[1], back[0], back[1]);
    /* the box follows the chords: to the integrator's accuracy, converging */
    ck_assert_msg(worst[0] < 1e-6 && worst[1] < 1e-2 * worst[0], "box tilt errors %g, %g", worst[0], worst[1]);
    /* over a whole cycle the chord errors cancel (the sine is odd about T/2) */
    ck_assert_msg(back[0] < 1e-9 && back[1] < 1e-9, "displacement over a cycle %g, %g", back[0], back[1]);
    odhs_system_destroy(start);
}
END_TEST

/* The zero-amplitude limit: below any contact change the response is linear
 * in the amplitude: non-affine displacement and stress over gamma0 converge
 * as gamma0 -> 0 (differences O(gamma0)). */
START_TEST(test_zero_amplitude_limit)
{
    odhs_system *start = scene(64, 0.45, 0.80, 7);
    double x0[128], x1[128], x2[128], sig[2];
    odhs_system_get_positions(start, x0);
    const double amps[2] = {1e-6, 2e-6};
    for (int a = 0; a < 2; ++a) {
        run r = start_run(start, ODHS_OSCILLATION_TRIANGLE, amps[a], 1.0, "dense");
        ck_assert_int_eq(odhs_stepper_run_until_time(r.st, 0.125), ODHS_OK);
        uint64_t coll, open;
        odhs_stepper_counts(r.st, NULL, &coll, &open);
        ck_assert_msg(coll == 0 && open == 0, "contact changes at amplitude %g: %llu %llu", amps[a],
                      (unsigned long long)coll, (unsigned long long)open);
        ck_assert_int_eq(odhs_stepper_shear_stress(r.st, &sig[a]), ODHS_OK);
        sig[a] /= 4.0 * amps[a]; /* stress over the rate */
        odhs_system_get_positions(r.sys, a ? x2 : x1);
        end_run(&r);
    }
    ck_assert_msg(sig[0] > 0.0 && fabs(sig[1] / sig[0] - 1.0) < 1e-4, "sigma/rate %.12g and %.12g", sig[0], sig[1]);
    /* displacements (non-affine and affine alike) scale with the amplitude */
    double s1 = 0.0, s12 = 0.0;
    for (size_t k = 0; k < 128; ++k) {
        double d1 = x1[k] - x0[k], d2 = x2[k] - x0[k];
        s1 += d1 * d1;
        s12 += (d2 - 2.0 * d1) * (d2 - 2.0 * d1);
    }
    ck_assert_msg(s1 > 0.0 && sqrt(s12 / s1) < 1e-4, "displacements not linear in the amplitude: %g", sqrt(s12 / s1));
    odhs_system_destroy(start);
}
END_TEST

/* Power balance at every step over a cycle of a dense suspension, with the
 * rate of the moment: dissipation = power of the flow = sigma_xy gdot(t) V. */
START_TEST(test_power_balance)
{
    odhs_system *start = scene(64, 0.45, 0.80, 11);
    const int shapes[2] = {ODHS_OSCILLATION_SINE, ODHS_OSCILLATION_TRIANGLE};
    for (int k = 0; k < 2; ++k) {
        run r = start_run(start, shapes[k], 0.1, 1.0, "dense");
        double t = 0.0, worst = 0.0;
        size_t checked = 0;
        while (t < 1.0) {
            ck_assert_int_eq(odhs_stepper_step(r.st, NULL), ODHS_OK);
            odhs_stepper_time(r.st, &t);
            double D, P, sxy, vol;
            odhs_stepper_dissipation(r.st, &D);
            odhs_stepper_power(r.st, &P);
            odhs_stepper_shear_stress(r.st, &sxy);
            odhs_system_volume(r.sys, &vol);
            if (!(D > 1e-12)) continue;
            double rate = shapes[k] == ODHS_OSCILLATION_SINE ? 0.2 * PI * cos(2.0 * PI * t) : 0.0;
            worst = fmax(worst, fabs(P - D) / D);
            if (shapes[k] == ODHS_OSCILLATION_SINE)
                ck_assert_msg(fabs(sxy * rate * vol - D) <= 1e-9 * D, "sigma gdot V %.12g, D %.12g at t = %g",
                              sxy * rate * vol, D, t);
            checked++;
        }
        ck_assert_msg(checked > 20 && worst < 1e-9, "power balance %g over %zu steps", worst, checked);
        uint64_t coll;
        odhs_stepper_counts(r.st, NULL, &coll, NULL);
        ck_assert_msg(coll > 0, "no collisions in a dense cycle");
        end_run(&r);
    }
    odhs_system_destroy(start);
}
END_TEST

/* Stroboscopic displacement: a dilute suspension without collisions comes
 * back to round-off; a dense one is rearranged by its collisions. */
START_TEST(test_reversibility)
{
    odhs_system *dilute = scene(32, 0.2, 0.0, 13), *dense = scene(64, 0.45, 0.80, 17);
    odhs_system *starts[2] = {dilute, dense};
    const double amps[2] = {0.02, 0.5};
    for (int k = 0; k < 2; ++k) {
        size_t nd = 2 * odhs_system_count(starts[k]);
        double *x0 = malloc(nd * sizeof *x0), *x1 = malloc(nd * sizeof *x1);
        odhs_system_get_positions(starts[k], x0);
        run r = start_run(starts[k], ODHS_OSCILLATION_TRIANGLE, amps[k], 1.0, "dense");
        ck_assert_int_eq(odhs_stepper_run_until_time(r.st, 1.0), ODHS_OK);
        odhs_system_get_positions(r.sys, x1);
        double d = rms_displacement(r.sys, x0, x1);
        uint64_t coll;
        odhs_stepper_counts(r.st, NULL, &coll, NULL);
        printf("[oscillation] %s, amplitude %g: %llu collisions, stroboscopic rms displacement %.3g\n",
               k ? "dense phi 0.80" : "dilute phi 0.20", amps[k], (unsigned long long)coll, d);
        if (k == 0) ck_assert_msg(coll == 0 && d < 1e-13, "dilute: %llu collisions, displacement %g",
                                  (unsigned long long)coll, d);
        else ck_assert_msg(coll > 0 && d > 1e-3, "dense: %llu collisions, displacement %g", (unsigned long long)coll, d);
        end_run(&r);
        free(x0);
        free(x1);
    }
    odhs_system_destroy(dilute);
    odhs_system_destroy(dense);
}
END_TEST

/* A checkpoint carries the oscillation (section OSC): the restored run
 * continues bit for bit, across reversals. */
START_TEST(test_checkpoint)
{
    odhs_system *start = scene(48, 0.45, 0.78, 23);
    const int shapes[2] = {ODHS_OSCILLATION_SINE, ODHS_OSCILLATION_TRIANGLE};
    for (int k = 0; k < 2; ++k) {
        run r = start_run(start, shapes[k], 0.2, 1.0, "dense");
        ck_assert_int_eq(odhs_stepper_run_until_time(r.st, 0.3), ODHS_OK);
        char path[] = "/tmp/odhs_osc_ckpt_XXXXXX";
        int fd = mkstemp(path);
        ck_assert(fd >= 0);
        close(fd);
        ck_assert_int_eq(odhs_checkpoint_write(r.st, path), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_run_until_time(r.st, 1.2), ODHS_OK);
        odhs_solver *sol;
        odhs_system *sys;
        odhs_driver *drv;
        odhs_stepper *st;
        char err[256];
        ck_assert_int_eq(odhs_solver_create_by_name("dense", &sol), ODHS_OK);
        ck_assert_msg(odhs_checkpoint_read(path, sol, &sys, &drv, &st, err, sizeof err) == ODHS_OK, "%s", err);
        int shape;
        double amp, period, t0;
        ck_assert_int_eq(odhs_driver_get_oscillatory_shear(drv, &shape, &amp, &period, &t0), ODHS_OK);
        ck_assert(shape == shapes[k] && amp == 0.2 && period == 1.0 && t0 == 0.0);
        ck_assert_int_eq(odhs_stepper_run_until_time(st, 1.2), ODHS_OK);
        double xa[96], xb[96], ga, gb;
        odhs_system_get_positions(r.sys, xa);
        odhs_system_get_positions(sys, xb);
        odhs_stepper_strain(r.st, &ga);
        odhs_stepper_strain(st, &gb);
        ck_assert_msg(!memcmp(xa, xb, sizeof xa) && ga == gb, "shape %d: continuation not bit-identical", shapes[k]);
        odhs_stepper_destroy(st);
        odhs_driver_destroy(drv);
        odhs_system_destroy(sys);
        odhs_solver_destroy(sol);
        end_run(&r);
        remove(path);
    }
    odhs_system_destroy(start);
}
END_TEST

START_TEST(test_bad_input)
{
    odhs_driver *drv;
    ck_assert_int_eq(odhs_driver_create(&drv), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_oscillatory_shear(NULL, ODHS_OSCILLATION_SINE, 1, 1, 0), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_set_oscillatory_shear(drv, 0, 1, 1, 0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_driver_set_oscillatory_shear(drv, 3, 1, 1, 0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_driver_set_oscillatory_shear(drv, ODHS_OSCILLATION_SINE, 0.0, 1, 0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_driver_set_oscillatory_shear(drv, ODHS_OSCILLATION_SINE, 1, -1, 0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_driver_set_oscillatory_shear(drv, ODHS_OSCILLATION_SINE, NAN, 1, 0), ODHS_E_NONFINITE);
    ck_assert_int_eq(odhs_driver_set_oscillatory_shear(drv, ODHS_OSCILLATION_SINE, 1, 1, INFINITY), ODHS_E_NONFINITE);
    ck_assert_int_eq(odhs_driver_set_oscillatory_shear(drv, ODHS_OSCILLATION_SINE, 1e300, 1e-300, 0), ODHS_E_RANGE);
    ck_assert_ptr_nonnull(strstr(odhs_driver_errmsg(drv), "peak rate"));
    int shape = -1;
    double g;
    ck_assert_int_eq(odhs_driver_get_oscillatory_shear(drv, &shape, NULL, NULL, NULL), ODHS_OK);
    ck_assert_int_eq(shape, 0); /* failed calls left it off */
    ck_assert_int_eq(odhs_driver_set_oscillatory_shear(drv, ODHS_OSCILLATION_TRIANGLE, 0.5, 2.0, 0), ODHS_OK);
    ck_assert_int_eq(odhs_driver_get_shear_rate(drv, &g), ODHS_OK);
    ck_assert_double_eq(g, 1.0); /* the peak rate 4 gamma0 / T */
    /* with a stepper: no fixed pressure, no strain target */
    odhs_system *start = scene(16, 0.3, 0.0, 19);
    odhs_solver *sol;
    odhs_stepper *st;
    ck_assert_int_eq(odhs_solver_create_by_name("dense", &sol), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_create(start, drv, sol, &st), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_strain(st, 0.1), ODHS_E_UNSUPPORTED);
    ck_assert_int_eq(odhs_driver_set_pressure(drv, 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_E_UNSUPPORTED);
    ck_assert_ptr_nonnull(strstr(odhs_stepper_errmsg(st), "oscillatory"));
    ck_assert_int_eq(odhs_driver_clear_pressure(drv), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_OK);
    /* a constant rate replaces the oscillation */
    ck_assert_int_eq(odhs_driver_set_shear_rate(drv, 2.0), ODHS_OK);
    ck_assert_int_eq(odhs_driver_get_oscillatory_shear(drv, &shape, NULL, NULL, NULL), ODHS_OK);
    ck_assert_int_eq(shape, 0);
    ck_assert_int_eq(odhs_stepper_run_until_strain(st, 0.05), ODHS_OK);
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_driver_destroy(drv);
    odhs_system_destroy(start);
}
END_TEST

Suite *make_oscillation_suite(void)
{
    Suite *s = suite_create("oscillation");
    TCase *tc = tcase_create("oscillation");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_triangle_affine);
    tcase_add_test(tc, test_sine_affine);
    tcase_add_test(tc, test_zero_amplitude_limit);
    tcase_add_test(tc, test_power_balance);
    tcase_add_test(tc, test_reversibility);
    tcase_add_test(tc, test_checkpoint);
    tcase_add_test(tc, test_bad_input);
    suite_add_tcase(s, tc);
    return s;
}
