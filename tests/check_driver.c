/*
 * libodhs - tests of the driver (driver.h): defaults, validation of every
 * setter (the handle is unchanged on error), fixed forces (copied, cleared,
 * replaced by a callback and vice versa), the natural time unit tau, the
 * affine flow and forces as seen by a stepper (V = V_aff + xi0 F for free
 * particles), pressure control preconditions, failing force callbacks
 * (ODHS_E_CALLBACK with the step rolled back) and forces of the wrong size.
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

/* ------------------------------------------------------------------------ */
/* helpers                                                                   */
/* ------------------------------------------------------------------------ */

#define DN 4
/* four free discs (no contacts) in a 10 x 10 box; mean diameter 0.9 */
static const double drv_r[DN] = {0.3, 0.5, 0.4, 0.6};
static const double drv_x[2 * DN] = {2.0, 2.0, 7.0, 2.5, 2.5, 7.0, 7.5, 6.5};
static const double drv_lambda = 0.9;

static odhs_system *drv_sys(void)
{
    odhs_system *s = NULL;
    ck_assert_int_eq(odhs_system_create(2, DN, &s), ODHS_OK);
    double L[2] = {10.0, 10.0};
    ck_assert_int_eq(odhs_system_set_configuration(s, L, 0.0, drv_r, drv_x), ODHS_OK);
    return s;
}

static odhs_driver *drv_new(void)
{
    odhs_driver *d = NULL;
    ck_assert_int_eq(odhs_driver_create(&d), ODHS_OK);
    ck_assert_ptr_nonnull(d);
    return d;
}

typedef struct {
    double xi0, gdot, c, p;
    int pon;
} drv_state;

static drv_state drv_get(const odhs_driver *d)
{
    drv_state s;
    ck_assert_int_eq(odhs_driver_get_mobility(d, &s.xi0), ODHS_OK);
    ck_assert_int_eq(odhs_driver_get_shear_rate(d, &s.gdot), ODHS_OK);
    ck_assert_int_eq(odhs_driver_get_compression_rate(d, &s.c), ODHS_OK);
    ck_assert_int_eq(odhs_driver_get_pressure(d, &s.p, &s.pon), ODHS_OK);
    return s;
}

static int drv_state_eq(drv_state a, drv_state b)
{
    return !memcmp(&a.xi0, &b.xi0, sizeof a.xi0) && !memcmp(&a.gdot, &b.gdot, sizeof a.gdot) &&
           !memcmp(&a.c, &b.c, sizeof a.c) && !memcmp(&a.p, &b.p, sizeof a.p) && a.pon == b.pon;
}

static double drv_tau(const odhs_driver *d, const odhs_system *sys)
{
    double tau = NAN;
    int st = odhs_driver_time_unit(d, sys, &tau);
    ck_assert_msg(st == ODHS_OK, "time_unit = %d (%s)", st, odhs_driver_errmsg(d));
    ck_assert_msg(isfinite(tau) && tau > 0.0, "tau = %g", tau);
    return tau;
}

/* A call that must fail with `code`, leave an error message and change none
 * of the getters' values nor the time unit on sys. */
#define DRV_EXPECT_FAIL(d, sys, code, call)                                                       \
    do {                                                                                          \
        drv_state before_ = drv_get(d);                                                           \
        double tau_ = drv_tau((d), (sys));                                                        \
        int st_ = (call);                                                                         \
        ck_assert_msg(st_ == (code), "%s returned %d (%s), expected %d (%s)", #call, st_,        \
                      odhs_strerror(st_), (int)(code), odhs_strerror(code));                      \
        ck_assert_msg(odhs_driver_errmsg(d)[0] != '\0', "%s: empty error message", #call);       \
        ck_assert_msg(drv_state_eq(before_, drv_get(d)), "%s changed the driver", #call);        \
        ck_assert_msg(tau_ == drv_tau((d), (sys)), "%s changed the time unit", #call);           \
    } while (0)

static odhs_stepper *drv_stepper(odhs_system *sys, odhs_driver *d, odhs_solver **sol)
{
    ck_assert_int_eq(odhs_solver_create_by_name("cg", sol), ODHS_OK);
    odhs_stepper *st = NULL;
    ck_assert_int_eq(odhs_stepper_create(sys, d, *sol, &st), ODHS_OK);
    return st;
}

/* velocities of free particles after a reset */
static void drv_velocities(odhs_stepper *st, double *V)
{
    int s = odhs_stepper_reset(st);
    ck_assert_msg(s == ODHS_OK, "reset = %d (%s)", s, odhs_stepper_errmsg(st));
    ck_assert_int_eq(odhs_stepper_velocities(st, V), ODHS_OK);
}

/* force callback: F_i = (a + i, b - i) scaled; fails / writes NaN on request */
typedef struct {
    int calls;
    int fail;      /* 1: return nonzero when t > 0; 2: write NaN when t > 0;
                      3: always return nonzero */
    double scale;
    double last_t;
} cb_ctx;

static int drv_cb(double t, const odhs_system *sys, double *F, void *vctx)
{
    cb_ctx *c = vctx;
    c->calls++;
    c->last_t = t;
    size_t n = odhs_system_count(sys);
    for (size_t i = 0; i < n; ++i) {
        F[2 * i] = c->scale * (0.5 + (double)i);
        F[2 * i + 1] = c->scale * (1.0 - 0.75 * (double)i);
    }
    if (c->fail == 3) return 1;
    if (t > 0.0 && c->fail == 1) return -1;
    if (t > 0.0 && c->fail == 2) F[3] = NAN;
    return 0;
}

static void drv_cb_forces(double scale, double *F)
{
    for (size_t i = 0; i < DN; ++i) {
        F[2 * i] = scale * (0.5 + (double)i);
        F[2 * i + 1] = scale * (1.0 - 0.75 * (double)i);
    }
}

static double frms_of(const double *F, size_t n, int dim)
{
    double s = 0.0;
    for (size_t k = 0; k < n * (size_t)dim; ++k) s += F[k] * F[k];
    return sqrt(s / (double)n);
}

/* ------------------------------------------------------------------------ */
/* defaults and setters                                                      */
/* ------------------------------------------------------------------------ */

START_TEST(test_defaults)
{
    odhs_driver *d = drv_new();
    odhs_system *sys = drv_sys();
    drv_state s = drv_get(d);
    ck_assert(s.xi0 == 1.0);
    ck_assert(s.gdot == 0.0);
    ck_assert(s.c == 0.0);
    ck_assert_int_eq(s.pon, 0);
    ck_assert_str_eq(odhs_driver_errmsg(d), "");
    /* no flow, no forces: lambda / xi0 (unit force) */
    ck_assert_double_eq_tol(drv_tau(d, sys), drv_lambda, 1e-15);
    /* a stepper on the default driver: nothing moves */
    odhs_solver *sol;
    odhs_stepper *st = drv_stepper(sys, d, &sol);
    double V[2 * DN];
    drv_velocities(st, V);
    for (int k = 0; k < 2 * DN; ++k) ck_assert(V[k] == 0.0);
    double kappa = -1;
    ck_assert_int_eq(odhs_stepper_kappa(st, &kappa), ODHS_OK);
    ck_assert(kappa == 0.0);
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    /* NULL handling */
    odhs_driver *o = d;
    ck_assert_int_eq(odhs_driver_create(NULL), ODHS_E_NULL);
    ck_assert_ptr_eq(o, d);
    double v;
    int en;
    ck_assert_int_eq(odhs_driver_get_mobility(NULL, &v), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_get_mobility(d, NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_get_shear_rate(d, NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_get_compression_rate(d, NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_get_pressure(d, NULL, &en), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_get_pressure(d, &v, NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_set_mobility(NULL, 1.0), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_set_shear_rate(NULL, 1.0), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_set_compression_rate(NULL, 1.0), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_set_pressure(NULL, 1.0), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_clear_pressure(NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_set_kappa_max(NULL, 1.0), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_set_forces(NULL, 0, 2, NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_set_force_callback(NULL, drv_cb, NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_set_time_unit(NULL, 1.0), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_time_unit(NULL, sys, &v), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_time_unit(d, NULL, &v), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_time_unit(d, sys, NULL), ODHS_E_NULL);
    ck_assert_str_eq(odhs_driver_errmsg(NULL), "");
    odhs_driver_destroy(NULL);
    /* time unit needs radii */
    odhs_system *bare = NULL;
    ck_assert_int_eq(odhs_system_create(2, 3, &bare), ODHS_OK);
    ck_assert_int_eq(odhs_driver_time_unit(d, bare, &v), ODHS_E_STATE);
    odhs_system_destroy(bare);
    odhs_system_destroy(sys);
    odhs_driver_destroy(d);
}
END_TEST

START_TEST(test_setters_validate)
{
    odhs_driver *d = drv_new();
    odhs_system *sys = drv_sys();
    const double bad_nf[3] = {NAN, INFINITY, -INFINITY};
    for (int round = 0; round < 2; ++round) {
        if (round == 1) {
            /* the same from a non-default state */
            ck_assert_int_eq(odhs_driver_set_mobility(d, 2.5), ODHS_OK);
            ck_assert_int_eq(odhs_driver_set_shear_rate(d, -0.3), ODHS_OK);
            ck_assert_int_eq(odhs_driver_set_compression_rate(d, 0.05), ODHS_OK);
            ck_assert_int_eq(odhs_driver_set_pressure(d, 1.75), ODHS_OK);
        }
        for (int k = 0; k < 3; ++k) {
            double b = bad_nf[k];
            DRV_EXPECT_FAIL(d, sys, ODHS_E_NONFINITE, odhs_driver_set_mobility(d, b));
            DRV_EXPECT_FAIL(d, sys, ODHS_E_NONFINITE, odhs_driver_set_shear_rate(d, b));
            DRV_EXPECT_FAIL(d, sys, ODHS_E_NONFINITE, odhs_driver_set_compression_rate(d, b));
            DRV_EXPECT_FAIL(d, sys, ODHS_E_NONFINITE, odhs_driver_set_pressure(d, b));
            DRV_EXPECT_FAIL(d, sys, ODHS_E_NONFINITE, odhs_driver_set_kappa_max(d, b));
            DRV_EXPECT_FAIL(d, sys, ODHS_E_NONFINITE, odhs_driver_set_time_unit(d, b));
        }
        const double bad_pos[3] = {0.0, -0.0, -1.5};
        for (int k = 0; k < 3; ++k) {
            double b = bad_pos[k];
            DRV_EXPECT_FAIL(d, sys, ODHS_E_INVALID, odhs_driver_set_mobility(d, b));
            DRV_EXPECT_FAIL(d, sys, ODHS_E_INVALID, odhs_driver_set_pressure(d, b));
            DRV_EXPECT_FAIL(d, sys, ODHS_E_INVALID, odhs_driver_set_kappa_max(d, b));
            DRV_EXPECT_FAIL(d, sys, ODHS_E_INVALID, odhs_driver_set_time_unit(d, b));
        }
    }
    /* the non-default state survived all that */
    drv_state s = drv_get(d);
    ck_assert(s.xi0 == 2.5 && s.gdot == -0.3 && s.c == 0.05 && s.p == 1.75 && s.pon == 1);
    /* valid settings take effect; any finite rate is allowed, 0 turns off */
    ck_assert_int_eq(odhs_driver_set_shear_rate(d, 0.0), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_compression_rate(d, -0.2), ODHS_OK); /* dilation */
    ck_assert_int_eq(odhs_driver_set_mobility(d, 1e-3), ODHS_OK);
    ck_assert_int_eq(odhs_driver_clear_pressure(d), ODHS_OK);
    s = drv_get(d);
    ck_assert(s.xi0 == 1e-3 && s.gdot == 0.0 && s.c == -0.2 && s.pon == 0);
    ck_assert_int_eq(odhs_driver_set_pressure(d, 3.0), ODHS_OK);
    s = drv_get(d);
    ck_assert(s.p == 3.0 && s.pon == 1);

    /* fixed forces: bad dimension / non-finite entries rejected, the previous
     * forces kept (seen through the time unit lambda / (xi0 f_rms)) */
    ck_assert_int_eq(odhs_driver_set_compression_rate(d, 0.0), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_mobility(d, 2.0), ODHS_OK);
    double F[2 * DN] = {1, 0, 0, 1, -1, 0, 0, -1}; /* f_rms = 1 */
    ck_assert_int_eq(odhs_driver_set_forces(d, DN, 2, F), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), drv_lambda / 2.0, 1e-15);
    double G[3 * DN];
    for (int k = 0; k < 3 * DN; ++k) G[k] = 5.0;
    DRV_EXPECT_FAIL(d, sys, ODHS_E_DIM, odhs_driver_set_forces(d, DN, 1, G));
    DRV_EXPECT_FAIL(d, sys, ODHS_E_DIM, odhs_driver_set_forces(d, DN, 4, G));
    G[5] = NAN;
    DRV_EXPECT_FAIL(d, sys, ODHS_E_NONFINITE, odhs_driver_set_forces(d, DN, 3, G));
    G[5] = -INFINITY;
    DRV_EXPECT_FAIL(d, sys, ODHS_E_NONFINITE, odhs_driver_set_forces(d, DN, 2, G));
    {
        drv_state before = drv_get(d);
        double tau0 = drv_tau(d, sys);
        int st = odhs_driver_set_forces(d, 0, 2, G);
        ck_assert_msg(st < 0, "set_forces with n = 0 returned %d", st);
        ck_assert(drv_state_eq(before, drv_get(d)));
        ck_assert(tau0 == drv_tau(d, sys));
    }
    ck_assert_double_eq_tol(drv_tau(d, sys), drv_lambda / 2.0, 1e-15);
    odhs_system_destroy(sys);
    odhs_driver_destroy(d);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* the natural time unit                                                     */
/* ------------------------------------------------------------------------ */

START_TEST(test_time_unit)
{
    odhs_driver *d = drv_new();
    odhs_system *sys = drv_sys();
    /* shear: 1/|gammadot| */
    ck_assert_int_eq(odhs_driver_set_shear_rate(d, -4.0), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), 0.25, 1e-15);
    /* shear and compression: 1/max(|gammadot|, |c|) */
    ck_assert_int_eq(odhs_driver_set_compression_rate(d, 8.0), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), 0.125, 1e-15);
    ck_assert_int_eq(odhs_driver_set_compression_rate(d, -1.0), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), 0.25, 1e-15);
    /* compression alone, either sign: 1/|c| */
    ck_assert_int_eq(odhs_driver_set_shear_rate(d, 0.0), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_compression_rate(d, -0.5), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), 2.0, 1e-15);
    ck_assert_int_eq(odhs_driver_set_compression_rate(d, 0.02), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), 50.0, 1e-13);
    /* the flow wins over forces */
    double F[2 * DN] = {3, -1, 0.5, 2, -2, 0, 1, 1};
    ck_assert_int_eq(odhs_driver_set_forces(d, DN, 2, F), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), 50.0, 1e-13);
    /* fixed forces alone: lambda / (xi0 f_rms), lambda = mean diameter,
     * f_rms = sqrt(<F|F>/N); independent of the mobility's default */
    ck_assert_int_eq(odhs_driver_set_compression_rate(d, 0.0), ODHS_OK);
    double frms = frms_of(F, DN, 2);
    ck_assert_double_eq_tol(drv_tau(d, sys), drv_lambda / frms, 1e-14);
    ck_assert_int_eq(odhs_driver_set_mobility(d, 2.5), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), drv_lambda / (2.5 * frms), 1e-14);
    /* doubling the forces halves tau (rate invariance, Sect. II D) */
    for (int k = 0; k < 2 * DN; ++k) F[k] *= 2.0;
    ck_assert_int_eq(odhs_driver_set_forces(d, DN, 2, F), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), drv_lambda / (2.5 * 2.0 * frms), 1e-14);
    /* a user time unit overrides the fixed-force unit (since 0.2.7: it was
     * ignored there before, issue 19), and clearing it brings that back */
    ck_assert_int_eq(odhs_driver_set_time_unit(d, 0.7), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), 0.7, 1e-15);
    ck_assert_int_eq(odhs_driver_clear_time_unit(d), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), drv_lambda / (2.5 * 2.0 * frms), 1e-14);
    ck_assert_int_eq(odhs_driver_set_time_unit(d, 0.7), ODHS_OK);
    /* a callback: the user value */
    cb_ctx ctx = {0, 0, 1.0, 0.0};
    ck_assert_int_eq(odhs_driver_set_force_callback(d, drv_cb, &ctx), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), 0.7, 1e-15);
    ck_assert_int_eq(odhs_driver_set_time_unit(d, 3.25), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), 3.25, 1e-15);
    /* ... and with a flow (since 0.2.7), whose unit comes back when cleared */
    ck_assert_int_eq(odhs_driver_set_shear_rate(d, 0.1), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), 3.25, 1e-15);
    ck_assert_int_eq(odhs_driver_clear_time_unit(d), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), 10.0, 1e-14);
    /* a callback without a user time unit: lambda / xi0 */
    odhs_driver *d2 = drv_new();
    ck_assert_int_eq(odhs_driver_set_mobility(d2, 4.0), ODHS_OK);
    /* (forces set and cleared again leave lambda / xi0 too) */
    ck_assert_int_eq(odhs_driver_set_forces(d2, DN, 2, F), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d2, sys), drv_lambda / (4.0 * 2.0 * frms), 1e-14);
    ck_assert_int_eq(odhs_driver_set_forces(d2, DN, 2, NULL), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d2, sys), drv_lambda / 4.0, 1e-15);
    ck_assert_int_eq(odhs_driver_set_force_callback(d2, drv_cb, &ctx), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d2, sys), drv_lambda / 4.0, 1e-15);
    odhs_driver_destroy(d2);
    odhs_system_destroy(sys);
    odhs_driver_destroy(d);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* forces: copied, cleared, replaced                                         */
/* ------------------------------------------------------------------------ */

START_TEST(test_forces_copy_clear_replace)
{
    odhs_driver *d = drv_new();
    odhs_system *sys = drv_sys();
    ck_assert_int_eq(odhs_driver_set_mobility(d, 2.5), ODHS_OK);
    odhs_solver *sol;
    odhs_stepper *st = drv_stepper(sys, d, &sol);
    double F[2 * DN] = {1.0, -2.0, 0.5, 0.25, -3.0, 1.0, 0.0, 2.0}, F0[2 * DN], V[2 * DN];
    memcpy(F0, F, sizeof F);
    ck_assert_int_eq(odhs_driver_set_forces(d, DN, 2, F), ODHS_OK);
    double tau = drv_tau(d, sys);
    /* the driver keeps its own copy */
    for (int k = 0; k < 2 * DN; ++k) F[k] = 100.0 + k;
    ck_assert_double_eq(drv_tau(d, sys), tau);
    /* free particles move with V = xi0 F (overdamped, no contacts) */
    drv_velocities(st, V);
    for (int k = 0; k < 2 * DN; ++k) ck_assert_msg(fabs(V[k] - 2.5 * F0[k]) <= 1e-14, "V[%d] = %g", k, V[k]);
    /* one step moves them by V t with t = dt tau */
    double x0[2 * DN], x1[2 * DN], t = 0.0;
    ck_assert_int_eq(odhs_system_get_positions(sys, x0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_set_dt(st, 1e-2), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_time(st, &t), ODHS_OK);
    ck_assert_msg(fabs(t - 1e-2 * tau) <= 1e-15 * tau, "time after one step %.17g, dt tau = %.17g", t, 1e-2 * tau);
    ck_assert_int_eq(odhs_system_get_positions(sys, x1), ODHS_OK);
    for (int k = 0; k < 2 * DN; ++k)
        ck_assert_msg(fabs(x1[k] - (x0[k] + 2.5 * F0[k] * t)) <= 1e-13, "x[%d]: %.17g vs %.17g", k, x1[k],
                      x0[k] + 2.5 * F0[k] * t);

    /* a callback replaces the fixed forces */
    cb_ctx ctx = {0, 0, 0.5, 0.0};
    double Fc[2 * DN];
    drv_cb_forces(0.5, Fc);
    ck_assert_int_eq(odhs_driver_set_force_callback(d, drv_cb, &ctx), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_time_unit(d, 0.125), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), 0.125, 1e-15);
    drv_velocities(st, V);
    ck_assert_msg(ctx.calls >= 1, "the callback was not called");
    for (int k = 0; k < 2 * DN; ++k) ck_assert_msg(fabs(V[k] - 2.5 * Fc[k]) <= 1e-14, "V[%d] = %g", k, V[k]);
    /* the callback sees the current time */
    double tnow;
    odhs_stepper_time(st, &tnow);
    ck_assert_double_eq(ctx.last_t, tnow);

    /* fixed forces replace the callback: it is not called any more */
    ck_assert_int_eq(odhs_driver_set_forces(d, DN, 2, F0), ODHS_OK);
    int calls = ctx.calls;
    drv_velocities(st, V);
    ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_OK);
    ck_assert_int_eq(ctx.calls, calls);
    ck_assert_int_eq(odhs_stepper_velocities(st, V), ODHS_OK);
    for (int k = 0; k < 2 * DN; ++k) ck_assert_msg(fabs(V[k] - 2.5 * F0[k]) <= 1e-14, "V[%d] = %g", k, V[k]);
    /* the user's unit set above stays (since 0.2.7); cleared, the forces' */
    ck_assert_double_eq_tol(drv_tau(d, sys), 0.125, 1e-15);
    ck_assert_int_eq(odhs_driver_clear_time_unit(d), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), tau, 1e-15);
    ck_assert_int_eq(odhs_driver_set_time_unit(d, 0.125), ODHS_OK);

    /* set_forces(NULL) clears: nothing moves, tau back to the user value
     * set above (it would be lambda / xi0 without one) */
    ck_assert_int_eq(odhs_driver_set_forces(d, 0, 0, NULL), ODHS_OK);
    ck_assert_double_eq_tol(drv_tau(d, sys), 0.125, 1e-15);
    /* the stepper notices the change on its next step (no reset needed) */
    ck_assert_int_eq(odhs_system_get_positions(sys, x0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_velocities(st, V), ODHS_OK);
    for (int k = 0; k < 2 * DN; ++k) ck_assert_msg(V[k] == 0.0, "V[%d] = %g without forces", k, V[k]);
    ck_assert_int_eq(odhs_system_get_positions(sys, x1), ODHS_OK);
    ck_assert(memcmp(x0, x1, sizeof x0) == 0);
    /* and a callback removed with NULL leaves no forces either */
    ck_assert_int_eq(odhs_driver_set_force_callback(d, drv_cb, &ctx), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_force_callback(d, NULL, NULL), ODHS_OK);
    calls = ctx.calls;
    drv_velocities(st, V);
    ck_assert_int_eq(ctx.calls, calls);
    for (int k = 0; k < 2 * DN; ++k) ck_assert(V[k] == 0.0);
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
    odhs_driver_destroy(d);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* the affine flow seen by free particles                                    */
/* ------------------------------------------------------------------------ */

/* V_aff = G R with G = gammadot e_x e_y^T - c I (R from the box origin) */
START_TEST(test_affine_flow)
{
    odhs_driver *d = drv_new();
    odhs_system *sys = drv_sys();
    odhs_solver *sol;
    odhs_stepper *st = drv_stepper(sys, d, &sol);
    double V[2 * DN], x[2 * DN];
    ck_assert_int_eq(odhs_system_get_positions(sys, x), ODHS_OK);
    const double gd[3] = {0.7, 0.0, -1.3}, cc[3] = {0.0, 0.4, 0.25};
    for (int k = 0; k < 3; ++k) {
        ck_assert_int_eq(odhs_driver_set_shear_rate(d, gd[k]), ODHS_OK);
        ck_assert_int_eq(odhs_driver_set_compression_rate(d, cc[k]), ODHS_OK);
        drv_velocities(st, V);
        for (size_t i = 0; i < DN; ++i) {
            double vx = gd[k] * x[2 * i + 1] - cc[k] * x[2 * i], vy = -cc[k] * x[2 * i + 1];
            ck_assert_msg(fabs(V[2 * i] - vx) <= 1e-13 && fabs(V[2 * i + 1] - vy) <= 1e-13,
                          "case %d particle %zu: V = (%g, %g), V_aff = (%g, %g)", k, i, V[2 * i], V[2 * i + 1], vx,
                          vy);
        }
        /* kappa = c / gammadot with shear, c without */
        double kappa;
        ck_assert_int_eq(odhs_stepper_kappa(st, &kappa), ODHS_OK);
        double ek = gd[k] != 0.0 ? cc[k] / gd[k] : cc[k];
        ck_assert_double_eq_tol(kappa, ek, 1e-15);
    }
    /* flow and forces combine: V = V_aff + xi0 F */
    double F[2 * DN] = {1, 2, 3, 4, -1, -2, -3, -4};
    ck_assert_int_eq(odhs_driver_set_forces(d, DN, 2, F), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_mobility(d, 0.5), ODHS_OK);
    drv_velocities(st, V);
    for (size_t i = 0; i < DN; ++i) {
        double vx = -1.3 * x[2 * i + 1] - 0.25 * x[2 * i] + 0.5 * F[2 * i], vy = -0.25 * x[2 * i + 1] + 0.5 * F[2 * i + 1];
        ck_assert(fabs(V[2 * i] - vx) <= 1e-13 && fabs(V[2 * i + 1] - vy) <= 1e-13);
    }
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
    odhs_driver_destroy(d);
}
END_TEST

/* two touching discs pushed together by opposite forces: the contact carries
 * the force (f = F, eq. 11: f = -N^{-1} S F) and nothing moves (eq. 12) */
START_TEST(test_forces_through_contact)
{
    odhs_system *sys = NULL;
    ck_assert_int_eq(odhs_system_create(2, 2, &sys), ODHS_OK);
    double L[2] = {10, 10}, r[2] = {0.5, 0.5}, x[4] = {4.0, 5.0, 5.0, 5.0};
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
    odhs_driver *d = drv_new();
    ck_assert_int_eq(odhs_driver_set_mobility(d, 3.0), ODHS_OK);
    double F[4] = {1.5, 0.2, -1.5, 0.2};
    ck_assert_int_eq(odhs_driver_set_forces(d, 2, 2, F), ODHS_OK);
    odhs_solver *sol;
    odhs_stepper *st = drv_stepper(sys, d, &sol);
    double V[4];
    ck_assert_int_eq(odhs_stepper_reset(st), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_velocities(st, V), ODHS_OK);
    /* normal components cancel, the common tangential force moves both */
    ck_assert_double_eq_tol(V[0], 0.0, 1e-13);
    ck_assert_double_eq_tol(V[2], 0.0, 1e-13);
    ck_assert_double_eq_tol(V[1], 3.0 * 0.2, 1e-13);
    ck_assert_double_eq_tol(V[3], 3.0 * 0.2, 1e-13);
    const odhs_network *net = odhs_stepper_network(st);
    ck_assert_uint_eq(odhs_network_count(net), 1);
    double f;
    ck_assert_int_eq(odhs_network_get_forces(net, &f), ODHS_OK);
    ck_assert_double_eq_tol(f, 1.5, 1e-13);
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
    odhs_driver_destroy(d);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* pressure control preconditions                                            */
/* ------------------------------------------------------------------------ */

START_TEST(test_pressure_preconditions)
{
    odhs_driver *d = drv_new();
    odhs_system *sys = drv_sys();
    odhs_solver *sol;
    odhs_stepper *st = drv_stepper(sys, d, &sol);
    double x0[2 * DN], x1[2 * DN];
    ck_assert_int_eq(odhs_system_get_positions(sys, x0), ODHS_OK);
    /* pressure without shear */
    ck_assert_int_eq(odhs_driver_set_pressure(d, 0.5), ODHS_OK);
    int s = odhs_stepper_reset(st);
    ck_assert_msg(s == ODHS_E_UNSUPPORTED, "pressure without shear: reset = %d", s);
    ck_assert_str_ne(odhs_stepper_errmsg(st), "");
    s = odhs_stepper_step(st, NULL);
    ck_assert_msg(s == ODHS_E_UNSUPPORTED, "pressure without shear: step = %d", s);
    ck_assert_int_eq(odhs_system_get_positions(sys, x1), ODHS_OK);
    ck_assert(memcmp(x0, x1, sizeof x0) == 0);
    /* pressure with shear and compression */
    ck_assert_int_eq(odhs_driver_set_shear_rate(d, 0.5), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_compression_rate(d, 0.1), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_reset(st), ODHS_E_UNSUPPORTED);
    /* pressure with shear only: fine. Without contacts the pressure cannot
     * be carried and kappa is clamped at +kappa_max (compression) */
    ck_assert_int_eq(odhs_driver_set_compression_rate(d, 0.0), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_kappa_max(d, 5.0), ODHS_OK);
    DRV_EXPECT_FAIL(d, sys, ODHS_E_INVALID, odhs_driver_set_kappa_max(d, -5.0));
    s = odhs_stepper_reset(st);
    ck_assert_msg(s == ODHS_OK, "pressure + shear: reset = %d (%s)", s, odhs_stepper_errmsg(st));
    double kappa, V[2 * DN];
    ck_assert_int_eq(odhs_stepper_kappa(st, &kappa), ODHS_OK);
    ck_assert_double_eq_tol(kappa, 5.0, 1e-15);
    /* V_aff = gammadot (R_y e_x - kappa R) */
    ck_assert_int_eq(odhs_stepper_velocities(st, V), ODHS_OK);
    for (size_t i = 0; i < DN; ++i) {
        ck_assert_double_eq_tol(V[2 * i], 0.5 * (x0[2 * i + 1] - 5.0 * x0[2 * i]), 1e-12);
        ck_assert_double_eq_tol(V[2 * i + 1], -0.5 * 5.0 * x0[2 * i + 1], 1e-12);
    }
    /* pressure off again: plain shear */
    ck_assert_int_eq(odhs_driver_clear_pressure(d), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_reset(st), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_kappa(st, &kappa), ODHS_OK);
    ck_assert(kappa == 0.0);
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
    odhs_driver_destroy(d);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* failing callbacks, wrong sizes: errors with the step rolled back          */
/* ------------------------------------------------------------------------ */

static void expect_rolled_back(odhs_stepper *st, odhs_system *sys, int code, const double *x0, double t0,
                               uint64_t steps0, const char *what)
{
    int s = odhs_stepper_step(st, NULL);
    ck_assert_msg(s == code, "%s: step returned %d (%s), expected %d", what, s, odhs_strerror(s), code);
    ck_assert_msg(odhs_stepper_errmsg(st)[0] != '\0', "%s: no error message", what);
    double x[2 * DN], t;
    uint64_t steps;
    ck_assert_int_eq(odhs_system_get_positions(sys, x), ODHS_OK);
    ck_assert_msg(memcmp(x, x0, sizeof x) == 0, "%s: positions changed by a failed step", what);
    ck_assert_int_eq(odhs_stepper_time(st, &t), ODHS_OK);
    ck_assert_msg(t == t0, "%s: time %.17g after a failed step, was %.17g", what, t, t0);
    ck_assert_int_eq(odhs_stepper_counts(st, &steps, NULL, NULL), ODHS_OK);
    ck_assert_msg(steps == steps0, "%s: step counter %llu, was %llu", what, (unsigned long long)steps,
                  (unsigned long long)steps0);
}

START_TEST(test_callback_failure)
{
    for (int mode = 1; mode <= 2; ++mode) {
        odhs_driver *d = drv_new();
        odhs_system *sys = drv_sys();
        odhs_solver *sol;
        odhs_stepper *st = drv_stepper(sys, d, &sol);
        cb_ctx ctx = {0, 0, 1.0, 0.0};
        ck_assert_int_eq(odhs_driver_set_force_callback(d, drv_cb, &ctx), ODHS_OK);
        ck_assert_int_eq(odhs_driver_set_time_unit(d, 1.0), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_set_dt(st, 0.01), ODHS_OK);
        /* two good steps */
        ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_OK);
        double x0[2 * DN], V0[2 * DN], V1[2 * DN], t0;
        uint64_t steps0;
        ck_assert_int_eq(odhs_system_get_positions(sys, x0), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_velocities(st, V0), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_time(st, &t0), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_counts(st, &steps0, NULL, NULL), ODHS_OK);
        ck_assert_uint_eq(steps0, 2);
        ck_assert(t0 > 0.0);
        /* now the callback fails (mode 1) or writes NaN (mode 2) */
        ctx.fail = mode;
        expect_rolled_back(st, sys, ODHS_E_CALLBACK, x0, t0, steps0, mode == 1 ? "callback error" : "callback NaN");
        /* again: still rolled back */
        expect_rolled_back(st, sys, ODHS_E_CALLBACK, x0, t0, steps0, "second failure");
        /* the state is still usable: velocities as before */
        ck_assert_int_eq(odhs_stepper_velocities(st, V1), ODHS_OK);
        for (int k = 0; k < 2 * DN; ++k) ck_assert_msg(fabs(V1[k] - V0[k]) <= 1e-14, "V[%d] after rollback", k);
        /* the callback recovers: stepping goes on from the same state */
        ctx.fail = 0;
        ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_OK);
        double x1[2 * DN], t1;
        ck_assert_int_eq(odhs_system_get_positions(sys, x1), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_time(st, &t1), ODHS_OK);
        ck_assert_double_eq_tol(t1 - t0, 0.01, 1e-14);
        for (int k = 0; k < 2 * DN; ++k) ck_assert_double_eq_tol(x1[k], x0[k] + V0[k] * (t1 - t0), 1e-12);
        odhs_stepper_destroy(st);
        odhs_solver_destroy(sol);
        odhs_system_destroy(sys);
        odhs_driver_destroy(d);
    }
}
END_TEST

/* a callback failing right away: the first step (which resets) fails */
START_TEST(test_callback_failure_at_start)
{
    odhs_driver *d = drv_new();
    odhs_system *sys = drv_sys();
    odhs_solver *sol;
    odhs_stepper *st = drv_stepper(sys, d, &sol);
    cb_ctx ctx = {0, 3, 1.0, 0.0};
    ck_assert_int_eq(odhs_driver_set_force_callback(d, drv_cb, &ctx), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_reset(st), ODHS_E_CALLBACK);
    expect_rolled_back(st, sys, ODHS_E_CALLBACK, drv_x, 0.0, 0, "callback failing at t = 0");
    ck_assert_msg(ctx.calls >= 2, "callback called %d times", ctx.calls);
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
    odhs_driver_destroy(d);
}
END_TEST

START_TEST(test_forces_wrong_size)
{
    odhs_driver *d = drv_new();
    odhs_system *sys = drv_sys();
    odhs_solver *sol;
    odhs_stepper *st = drv_stepper(sys, d, &sol);
    double F3[6] = {1, 0, 0, 1, 1, 1}; /* for N = 3 */
    ck_assert_int_eq(odhs_driver_set_forces(d, 3, 2, F3), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_reset(st), ODHS_E_DIM);
    ck_assert_str_ne(odhs_stepper_errmsg(st), "");
    expect_rolled_back(st, sys, ODHS_E_DIM, drv_x, 0.0, 0, "forces for N = 3 on N = 4");
    /* right N, wrong dimension */
    double F43[12] = {0};
    ck_assert_int_eq(odhs_driver_set_forces(d, DN, 3, F43), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_reset(st), ODHS_E_DIM);
    /* right size: fine */
    double F[2 * DN] = {1, 0, 0, 1, -1, 0, 0, -1};
    ck_assert_int_eq(odhs_driver_set_forces(d, DN, 2, F), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_reset(st), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_OK);
    /* wrong size set in the middle of a run, no reset: the next step fails
     * and leaves the configuration as it was */
    double x0[2 * DN], t0;
    uint64_t steps0;
    ck_assert_int_eq(odhs_system_get_positions(sys, x0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_time(st, &t0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_counts(st, &steps0, NULL, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_forces(d, 3, 2, F3), ODHS_OK);
    expect_rolled_back(st, sys, ODHS_E_DIM, x0, t0, steps0, "forces resized mid-run");
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
    odhs_driver_destroy(d);
}
END_TEST

Suite *make_driver_suite(void)
{
    Suite *s = suite_create("driver");
    TCase *tc = tcase_create("settings");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_defaults);
    tcase_add_test(tc, test_setters_validate);
    tcase_add_test(tc, test_time_unit);
    suite_add_tcase(s, tc);

    tc = tcase_create("forces");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_forces_copy_clear_replace);
    tcase_add_test(tc, test_affine_flow);
    tcase_add_test(tc, test_forces_through_contact);
    tcase_add_test(tc, test_pressure_preconditions);
    suite_add_tcase(s, tc);

    tc = tcase_create("failures");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_callback_failure);
    tcase_add_test(tc, test_callback_failure_at_start);
    tcase_add_test(tc, test_forces_wrong_size);
    suite_add_tcase(s, tc);
    return s;
}
