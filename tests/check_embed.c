/*
 * libodhs - a framework drives the library (suite "embed", issue 19): each
 * finding of the embedding review as a test that failed on 0.2.6.
 *
 *  1. run loops end: an empty driver or uniform gravity on equal discs makes
 *     run_events return ODHS_E_STALLED at once; a step below the time's
 *     resolution stalls run_until_time after the stall limit; the user's
 *     step cap returns ODHS_STEP_LIMIT and the run goes on from there.
 *  2. forces of 1e200 give a finite time unit (0 on 0.2.6) and a clear
 *     refusal to step (velocities whose squares overflow); 1e100 runs; a
 *     target 1e15 steps away is refused; 1e-310 and a rate of 1e-300 too.
 *  3. a checkpoint of a callback-driven run restores a stepper that refuses
 *     to step until the callback is set again, then continues bit for bit.
 *  4. odhs_driver_set_time_unit(1) makes dt physical with fixed forces and
 *     flows (ignored on 0.2.6); steps that do not advance the time say so.
 *  5. failed creates leave a message (odhs_last_error); solver names listed.
 *  6. a successful call clears the handle's message.
 *  7. odhs_step_info: an old, smaller struct is filled only up to its size.
 *  8. the force callback is called at the step's end time on the step's end
 *     positions (and with Heun at the predictor): a pure function works.
 *  9. a system changed behind the stepper's back is refused until reset.
 * 10. bulk contacts and external forces equal the one-at-a-time calls.
 * 11. the pre-event stress (0.2.8): a run is bit-identical with and without
 *     the record; without events the record equals the stress after the
 *     step; at fixed volume the shear stress never jumps down at a
 *     collision (a new constraint cannot lower the least dissipation), and
 *     jumps up at most of them; states without a record say why.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <check.h>
#include <float.h>
#include <math.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "odhs.h"

/* ---- scenes -------------------------------------------------------------- */
/* n bidisperse discs (radii 0.5, 0.7) placed at random at packing fraction
 * phi; equal = 1: all radii 0.5 */
static odhs_system *scene(size_t n, double phi, int equal, uint64_t seed)
{
    odhs_system *sys = NULL;
    ck_assert_int_eq(odhs_system_create(2, n, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(sys, 0.5, equal ? 1.0 : 1.4, 0.0, seed), ODHS_OK);
    ck_assert_int_eq(odhs_system_place_random(sys, phi < 0.5 ? phi : 0.45, seed), ODHS_OK);
    if (phi > 0.5) { /* random placement stops near 0.55: compress there */
        odhs_driver *d;
        odhs_solver *sol;
        odhs_stepper *st;
        ck_assert_int_eq(odhs_driver_create(&d), ODHS_OK);
        ck_assert_int_eq(odhs_driver_set_compression_rate(d, 1.0), ODHS_OK);
        ck_assert_int_eq(odhs_solver_create_by_name("cholmod", &sol), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_create(sys, d, sol, &st), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_run_until_packing_fraction(st, phi), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_correct(st), ODHS_OK);
        odhs_stepper_destroy(st);
        odhs_solver_destroy(sol);
        odhs_driver_destroy(d);
    }
    return sys;
}

static odhs_solver *solver(const char *name)
{
    odhs_solver *s = NULL;
    ck_assert_msg(odhs_solver_create_by_name(name, &s) == ODHS_OK, "%s: %s", name, odhs_last_error());
    return s;
}

typedef struct {
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
} rig;

static rig rig_new(odhs_system *sys)
{
    rig r = {sys, NULL, solver("cholmod"), NULL};
    ck_assert_int_eq(odhs_driver_create(&r.drv), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_create(r.sys, r.drv, r.sol, &r.st), ODHS_OK);
    return r;
}

static void rig_free(rig *r)
{
    odhs_stepper_destroy(r->st);
    odhs_solver_destroy(r->sol);
    odhs_driver_destroy(r->drv);
    odhs_system_destroy(r->sys);
}

/* random forces of scale f (fixed seed) */
static void random_forces(size_t n, double f, uint64_t seed, double *F)
{
    uint64_t s = seed * 0x9e3779b97f4a7c15ULL + 1;
    for (size_t k = 0; k < 2 * n; ++k) {
        s ^= s << 13;
        s ^= s >> 7;
        s ^= s << 17;
        F[k] = f * ((double)(s >> 11) * 0x1.0p-53 - 0.5);
    }
}

/* ---- 1. run loops end ---------------------------------------------------- */
START_TEST(test_stall_empty_driver)
{
    rig r = rig_new(scene(32, 0.4, 0, 1));
    int s = odhs_stepper_run_events(r.st, 1);
    ck_assert_msg(s == ODHS_E_STALLED, "run_events with nothing set: %d (%s)", s, odhs_stepper_errmsg(r.st));
    ck_assert_msg(strstr(odhs_stepper_errmsg(r.st), "no event can happen"), "%s", odhs_stepper_errmsg(r.st));
    uint64_t steps;
    ck_assert_int_eq(odhs_stepper_counts(r.st, &steps, NULL, NULL), ODHS_OK);
    ck_assert_msg(steps == 0, "%llu steps taken before stalling", (unsigned long long)steps);
    rig_free(&r);
}
END_TEST

START_TEST(test_stall_uniform_gravity)
{
    rig r = rig_new(scene(32, 0.4, 1, 2));
    double g[2] = {0.0, -1.0};
    ck_assert_int_eq(odhs_driver_set_gravity(r.drv, 2, g), ODHS_OK);
    int s = odhs_stepper_run_events(r.st, 1);
    ck_assert_msg(s == ODHS_E_STALLED, "uniform gravity: %d (%s)", s, odhs_stepper_errmsg(r.st));
    /* unequal discs fall at different speeds: events come */
    rig q = rig_new(scene(32, 0.4, 0, 2));
    ck_assert_int_eq(odhs_driver_set_gravity(q.drv, 2, g), ODHS_OK);
    s = odhs_stepper_run_events(q.st, 1);
    ck_assert_msg(s == ODHS_OK, "bidisperse gravity: %d (%s)", s, odhs_stepper_errmsg(q.st));
    rig_free(&q);
    rig_free(&r);
}
END_TEST

START_TEST(test_stall_time_resolution)
{
    rig r = rig_new(scene(16, 0.3, 0, 3));
    /* bring the clock to 1e10 with large steps (nothing moves) */
    ck_assert_int_eq(odhs_driver_set_time_unit(r.drv, 1e9), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_time(r.st, 1e10), ODHS_OK);
    /* a step of 1e-9 is below the resolution of 1e10 (ulp 1.9e-6): time
     * cannot move, however many steps are taken */
    ck_assert_int_eq(odhs_driver_set_time_unit(r.drv, 1e-6), ODHS_OK);
    double t1 = 1e10 + 1e-4; /* above the 1e-15 relative landing tolerance */
    int s = odhs_stepper_run_until_time(r.st, t1);
    ck_assert_msg(s == ODHS_E_STALLED, "run_until_time below resolution: %d (%s)", s, odhs_stepper_errmsg(r.st));
    uint64_t steps, stall;
    ck_assert_int_eq(odhs_stepper_get_run_limits(r.st, NULL, &stall), ODHS_OK);
    ck_assert_int_eq(stall, 1000);
    /* the stall limit is the user's: 10 steps */
    ck_assert_int_eq(odhs_stepper_counts(r.st, &steps, NULL, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_set_run_limits(r.st, 0, 10), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_time(r.st, t1), ODHS_E_STALLED);
    uint64_t steps2;
    ck_assert_int_eq(odhs_stepper_counts(r.st, &steps2, NULL, NULL), ODHS_OK);
    ck_assert_msg(steps2 - steps == 10, "%llu steps with a stall limit of 10", (unsigned long long)(steps2 - steps));
    rig_free(&r);
}
END_TEST

START_TEST(test_step_cap)
{
    /* a shear run capped at 25 steps per call, resumed to the target: the
     * same end state as one uncapped run */
    rig a = rig_new(scene(64, 0.6, 0, 4)), b = rig_new(scene(64, 0.6, 0, 4));
    ck_assert_int_eq(odhs_driver_set_shear_rate(a.drv, 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_shear_rate(b.drv, 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_strain(a.st, 0.05), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_set_run_limits(b.st, 25, 1000), ODHS_OK);
    int s, calls = 0;
    uint64_t last = 0;
    while ((s = odhs_stepper_run_until_strain(b.st, 0.05)) == ODHS_STEP_LIMIT) {
        uint64_t steps;
        odhs_stepper_counts(b.st, &steps, NULL, NULL);
        ck_assert_msg(steps - last == 25, "a capped call took %llu steps", (unsigned long long)(steps - last));
        last = steps;
        calls++;
    }
    ck_assert_int_eq(s, ODHS_OK);
    ck_assert_msg(calls >= 2, "only %d capped calls", calls);
    double xa[128], xb[128];
    odhs_system_get_positions(a.sys, xa);
    odhs_system_get_positions(b.sys, xb);
    ck_assert_msg(!memcmp(xa, xb, sizeof xa), "capped run differs from the uncapped one");
    rig_free(&a);
    rig_free(&b);
}
END_TEST

/* ---- 2. huge and tiny forces ---------------------------------------------- */
START_TEST(test_huge_forces)
{
    rig r = rig_new(scene(32, 0.5, 0, 5));
    double F[64], tau;
    /* forces of 1e200: the time unit is computed without overflow (0.2.6:
     * 0, and steps that never moved time), and the step refuses velocities
     * whose squares overflow, with a message */
    random_forces(32, 1e200, 7, F);
    ck_assert_int_eq(odhs_driver_set_forces(r.drv, 32, 2, F), ODHS_OK);
    ck_assert_int_eq(odhs_driver_time_unit(r.drv, r.sys, &tau), ODHS_OK);
    double s = 0.0, lam = 0.0, rr[32];
    for (int k = 0; k < 64; ++k) s += (F[k] / 1e200) * (F[k] / 1e200);
    odhs_system_get_radii(r.sys, rr);
    for (int i = 0; i < 32; ++i) lam += 2.0 * rr[i] / 32.0;
    double expect = lam / (1e200 * sqrt(s / 32.0));
    ck_assert_msg(isfinite(tau) && tau > 0.0 && fabs(tau / expect - 1.0) < 1e-14, "tau %g, expected %g", tau, expect);
    int st = odhs_stepper_run_until_time(r.st, 1e-202);
    ck_assert_msg(st == ODHS_E_INVALID && strstr(odhs_stepper_errmsg(r.st), "velocities outside"), "%d (%s)", st,
                  odhs_stepper_errmsg(r.st));
    /* forces of 1e100: computable; a target 1e15 largest steps away is
     * refused, a reachable one is reached with finite velocities */
    random_forces(32, 1e100, 7, F);
    ck_assert_int_eq(odhs_driver_set_forces(r.drv, 32, 2, F), ODHS_OK);
    ck_assert_int_eq(odhs_driver_time_unit(r.drv, r.sys, &tau), ODHS_OK);
    st = odhs_stepper_run_until_time(r.st, 1.0);
    ck_assert_msg(st == ODHS_E_INVALID && strstr(odhs_stepper_errmsg(r.st), "1e15"),
                  "run_until_time(1) with tau %g: %d (%s)", tau, st, odhs_stepper_errmsg(r.st));
    double t;
    odhs_stepper_time(r.st, &t);
    ck_assert(t == 0.0);
    st = odhs_stepper_run_until_time(r.st, 20e-3 * tau);
    ck_assert_msg(st == ODHS_OK, "%d (%s)", st, odhs_stepper_errmsg(r.st));
    odhs_stepper_time(r.st, &t);
    ck_assert_msg(t == 20e-3 * tau, "t = %g", t);
    double V[64], gap, ov;
    ck_assert_int_eq(odhs_stepper_velocities(r.st, V), ODHS_OK);
    for (int k = 0; k < 64; ++k) ck_assert(isfinite(V[k]));
    ck_assert_int_eq(odhs_stepper_errors(r.st, &gap, &ov), ODHS_OK);
    ck_assert_msg(ov < 1e-9, "overlap %g", ov);
    /* forces whose time unit leaves the doubles are refused with a message */
    random_forces(32, 1e-310, 7, F);
    ck_assert_int_eq(odhs_driver_set_forces(r.drv, 32, 2, F), ODHS_OK);
    st = odhs_driver_time_unit(r.drv, r.sys, &tau);
    ck_assert_msg(st == ODHS_E_INVALID, "time unit of 1e-310 forces: %d, %g", st, tau);
    st = odhs_stepper_step(r.st, NULL);
    ck_assert_msg(st == ODHS_E_INVALID && strstr(odhs_stepper_errmsg(r.st), "time unit"), "step: %d (%s)", st,
                  odhs_stepper_errmsg(r.st));
    /* a shear rate of 1e-300 likewise */
    ck_assert_int_eq(odhs_driver_set_forces(r.drv, 0, 0, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_shear_rate(r.drv, 1e-300), ODHS_OK);
    st = odhs_stepper_step(r.st, NULL);
    ck_assert_msg(st == ODHS_E_INVALID && strstr(odhs_stepper_errmsg(r.st), "flow rate"), "step: %d (%s)", st,
                  odhs_stepper_errmsg(r.st));
    rig_free(&r);
}
END_TEST

/* ---- 3. and 8. the force callback ----------------------------------------- */
typedef struct {
    double t_last;
    double x_last[128];
    size_t n, calls;
} cb_rec;

/* a pure function of t and the positions: a swirl plus a drift */
static int swirl(double t, const odhs_system *sys, double *F, void *ctx)
{
    cb_rec *rec = ctx;
    size_t n = odhs_system_count(sys);
    double x[128], L[2];
    odhs_system_get_positions(sys, x);
    odhs_system_get_box(sys, L);
    for (size_t i = 0; i < n; ++i) {
        double u = 6.283185307179586 * x[2 * i] / L[0], v = 6.283185307179586 * x[2 * i + 1] / L[1];
        F[2 * i] = sin(v) + 0.3 * cos(t);
        F[2 * i + 1] = -sin(u) + 0.2;
    }
    if (rec) {
        rec->t_last = t;
        memcpy(rec->x_last, x, 2 * n * sizeof *x);
        rec->calls++;
    }
    return 0;
}

START_TEST(test_callback_checkpoint)
{
    char dir[] = "/tmp/odhs_embed_XXXXXX";
    ck_assert_ptr_nonnull(mkdtemp(dir));
    char path[256];
    snprintf(path, sizeof path, "%s/cb.ckpt", dir);
    rig a = rig_new(scene(48, 0.7, 0, 6));
    ck_assert_int_eq(odhs_driver_set_force_callback(a.drv, swirl, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_time(a.st, 0.5), ODHS_OK);
    ck_assert_int_eq(odhs_checkpoint_write(a.st, path), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_time(a.st, 1.0), ODHS_OK);

    odhs_solver *sol = solver("cholmod");
    odhs_system *sys;
    odhs_driver *drv;
    odhs_stepper *st;
    char err[256];
    ck_assert_msg(odhs_checkpoint_read(path, sol, &sys, &drv, &st, err, sizeof err) == ODHS_OK, "%s", err);
    int s = odhs_stepper_run_until_time(st, 1.0);
    ck_assert_msg(s == ODHS_E_STATE && strstr(odhs_stepper_errmsg(st), "force callback"), "no callback: %d (%s)", s,
                  odhs_stepper_errmsg(st));
    ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_E_STATE);
    ck_assert_int_eq(odhs_stepper_reset(st), ODHS_E_STATE);
    double t;
    odhs_stepper_time(st, &t);
    ck_assert(t == 0.5);
    ck_assert_int_eq(odhs_driver_set_force_callback(drv, swirl, NULL), ODHS_OK);
    s = odhs_stepper_run_until_time(st, 1.0);
    ck_assert_msg(s == ODHS_OK, "%d (%s)", s, odhs_stepper_errmsg(st));
    double xa[96], xb[96];
    odhs_system_get_positions(a.sys, xa);
    odhs_system_get_positions(sys, xb);
    ck_assert_msg(!memcmp(xa, xb, sizeof xa), "restored callback run differs from the uninterrupted one");
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    odhs_solver_destroy(sol);
    rig_free(&a);
    unlink(path);
    rmdir(dir);
}
END_TEST

START_TEST(test_callback_timing)
{
    for (int integ = 0; integ < 2; ++integ) {
        rig r = rig_new(scene(48, 0.7, 0, 8));
        cb_rec rec = {0};
        ck_assert_int_eq(odhs_stepper_set_integrator(r.st, integ), ODHS_OK);
        ck_assert_int_eq(odhs_driver_set_force_callback(r.drv, swirl, &rec), ODHS_OK);
        for (int k = 0; k < 200; ++k) {
            odhs_step_info in;
            memset(&in, 0, sizeof in);
            in.size = sizeof in;
            size_t c0 = rec.calls;
            ck_assert_int_eq(odhs_stepper_step_ex(r.st, &in), ODHS_OK);
            if (!in.advanced) continue;
            /* the last call was at the step's end, on its end positions */
            double x[96];
            odhs_system_get_positions(r.sys, x);
            ck_assert_msg(rec.t_last == in.time_end, "%s step %d: last call at t = %.17g, step ends at %.17g",
                          integ ? "heun" : "euler", k, rec.t_last, in.time_end);
            ck_assert_msg(!memcmp(rec.x_last, x, sizeof x), "last call not on the end positions");
            ck_assert_msg(rec.calls - c0 >= (size_t)(integ ? 2 : 1), "%zu calls in a %s step", rec.calls - c0,
                          integ ? "Heun" : "Euler");
            /* the forces the observables use are the callback's there */
            double F[96], G[96];
            swirl(in.time_end, r.sys, G, NULL);
            ck_assert_int_eq(odhs_stepper_external_forces(r.st, F), ODHS_OK);
            ck_assert_msg(!memcmp(F, G, sizeof F), "external forces differ from the callback at the end");
        }
        rig_free(&r);
    }
}
END_TEST

/* ---- 4. physical time ------------------------------------------------------ */
START_TEST(test_physical_time)
{
    rig r = rig_new(scene(48, 0.7, 0, 9));
    double F[96], tau;
    random_forces(48, 3.0, 11, F);
    ck_assert_int_eq(odhs_driver_set_forces(r.drv, 48, 2, F), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_time_unit(r.drv, 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_driver_time_unit(r.drv, r.sys, &tau), ODHS_OK);
    ck_assert_msg(tau == 1.0, "time unit %g with fixed forces after set_time_unit(1)", tau);
    ck_assert_int_eq(odhs_stepper_set_integrator(r.st, ODHS_INTEGRATOR_EULER), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_set_dt(r.st, 0.01), ODHS_OK);
    int still = 0, driver_steps = 0;
    for (int k = 0; k < 300; ++k) {
        if (k % 10 == 0) { /* a framework sets new forces, 0.01x to 1x */
            random_forces(48, pow(10.0, (k / 10) % 3 - 2.0), 11 + (uint64_t)k, F);
            ck_assert_int_eq(odhs_driver_set_forces(r.drv, 48, 2, F), ODHS_OK);
        }
        odhs_step_info in;
        memset(&in, 0, sizeof in);
        in.size = sizeof in;
        int s = odhs_stepper_step_ex(r.st, &in);
        ck_assert_msg(s == ODHS_OK, "%d (%s)", s, odhs_stepper_errmsg(r.st));
        double h = in.time_end - in.time_start;
        ck_assert_msg(in.advanced == (h > 0.0), "advanced %d with h %g", in.advanced, h);
        if (in.driver_change) {
            ck_assert_msg(!in.advanced && in.collisions + in.openings > 0, "driver-change step moved");
            driver_steps++;
        }
        if (!in.advanced) still++;
        /* Euler: dt in physical time whatever the forces (0.2.6: dt tau, tau
         * following the forces), shorter only at a collision */
        if (in.kind != ODHS_EVENT_COLLISION && in.advanced)
            ck_assert_msg(fabs(h - 0.01) < 1e-15, "step %d: h = %.17g, not dt = 0.01", k, h);
        else
            ck_assert(h <= 0.01 + 1e-15);
    }
    ck_assert_msg(driver_steps > 0, "no step applied a driver change alone (%d still steps)", still);
    /* with a flow too */
    ck_assert_int_eq(odhs_driver_set_forces(r.drv, 0, 0, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_shear_rate(r.drv, 5.0), ODHS_OK);
    ck_assert_int_eq(odhs_driver_time_unit(r.drv, r.sys, &tau), ODHS_OK);
    ck_assert_msg(tau == 1.0, "time unit %g with shear after set_time_unit(1)", tau);
    ck_assert_int_eq(odhs_driver_clear_time_unit(r.drv), ODHS_OK);
    ck_assert_int_eq(odhs_driver_time_unit(r.drv, r.sys, &tau), ODHS_OK);
    ck_assert_msg(tau == 0.2, "natural time unit %g, expected 1/5", tau);
    rig_free(&r);
}
END_TEST

/* ---- 5. and 6. messages ---------------------------------------------------- */
static int no_create(void **state)
{
    (void)state;
    return 0;
}
static void no_destroy(void *state) { (void)state; }

START_TEST(test_create_messages)
{
    odhs_solver *s = NULL;
    ck_assert_int_eq(odhs_solver_create_by_name("CG", &s), ODHS_E_INVALID);
    ck_assert_msg(strstr(odhs_last_error(), "\"CG\"") && strstr(odhs_last_error(), "cg"), "%s", odhs_last_error());
    /* every listed, installed name creates; the list ends with ODHS_E_RANGE */
    const char *name;
    int inst, n = 0;
    for (size_t k = 0; odhs_solver_list(k, &name, &inst) == ODHS_OK; ++k, ++n) {
        int rc = odhs_solver_create_by_name(name, &s);
        ck_assert_msg(inst ? rc == ODHS_OK : rc == ODHS_E_NOTINSTALLED, "%s: %d", name, rc);
        if (inst) {
            ck_assert_str_eq(odhs_solver_name(s), name);
            ck_assert_str_eq(odhs_last_error(), "");
        } else {
            ck_assert_msg(strstr(odhs_last_error(), "not built"), "%s", odhs_last_error());
        }
        odhs_solver_destroy(s);
    }
    ck_assert_int_eq(n, 6);
    /* malformed tables say what is wrong */
    odhs_solver_type t = odhs_solver_type_cg;
    t.version = 99;
    ck_assert_int_eq(odhs_solver_create(&t, &s), ODHS_E_INVALID);
    ck_assert_msg(strstr(odhs_last_error(), "version 99"), "%s", odhs_last_error());
    t = odhs_solver_type_cg;
    t.solve = NULL;
    ck_assert_int_eq(odhs_solver_create(&t, &s), ODHS_E_INVALID);
    ck_assert_msg(strstr(odhs_last_error(), "no solve"), "%s", odhs_last_error());
    t = odhs_solver_type_cg;
    t.name = NULL;
    t.create = no_create;
    t.destroy = no_destroy;
    ck_assert_int_eq(odhs_solver_create(&t, &s), ODHS_E_INVALID);
    ck_assert_msg(strstr(odhs_last_error(), "no name"), "%s", odhs_last_error());
    /* a stepper on a system without radii */
    odhs_system *bare;
    odhs_driver *d;
    odhs_stepper *st = NULL;
    ck_assert_int_eq(odhs_system_create(2, 4, &bare), ODHS_OK);
    ck_assert_int_eq(odhs_driver_create(&d), ODHS_OK);
    s = solver("cg");
    ck_assert_int_eq(odhs_stepper_create(bare, d, s, &st), ODHS_E_STATE);
    ck_assert_msg(strstr(odhs_last_error(), "radii"), "%s", odhs_last_error());
    ck_assert_int_eq(odhs_system_create(4, 4, (odhs_system **)&st), ODHS_E_DIM);
    ck_assert_msg(strstr(odhs_last_error(), "dimension 4"), "%s", odhs_last_error());
    odhs_solver_destroy(s);
    odhs_driver_destroy(d);
    odhs_system_destroy(bare);
}
END_TEST

START_TEST(test_message_cleared)
{
    rig r = rig_new(scene(16, 0.3, 0, 12));
    ck_assert_int_eq(odhs_stepper_set_dt(r.st, NAN), ODHS_E_NONFINITE);
    ck_assert_str_ne(odhs_stepper_errmsg(r.st), "");
    ck_assert_int_eq(odhs_stepper_set_dt(r.st, 1e-300), ODHS_OK);
    ck_assert_str_eq(odhs_stepper_errmsg(r.st), "");
    ck_assert_int_eq(odhs_driver_set_mobility(r.drv, -1.0), ODHS_E_INVALID);
    ck_assert_str_ne(odhs_driver_errmsg(r.drv), "");
    ck_assert_int_eq(odhs_driver_set_mobility(r.drv, 2.0), ODHS_OK);
    ck_assert_str_eq(odhs_driver_errmsg(r.drv), "");
    ck_assert_int_eq(odhs_solver_set_param(r.sol, "no-such-key", 1.0), ODHS_E_INVALID);
    ck_assert_str_ne(odhs_solver_errmsg(r.sol), "");
    ck_assert_int_eq(odhs_solver_set_check_tolerance(r.sol, 1e-6), ODHS_OK);
    ck_assert_str_eq(odhs_solver_errmsg(r.sol), "");
    ck_assert_int_eq(odhs_system_scale_box(r.sys, -1.0), ODHS_E_INVALID);
    ck_assert_str_ne(odhs_system_errmsg(r.sys), "");
    ck_assert_int_eq(odhs_system_set_species(r.sys, 0, "A"), ODHS_OK);
    ck_assert_str_eq(odhs_system_errmsg(r.sys), "");
    rig_free(&r);
}
END_TEST

/* ---- 7. the step info's size ---------------------------------------------- */
/* the layout an older program may have been built with: the first fields */
struct old_info {
    size_t size;
    int kind;
    size_t i, j;
    double event_time;
};

START_TEST(test_step_info_size)
{
    rig r = rig_new(scene(48, 0.7, 0, 13));
    ck_assert_int_eq(odhs_driver_set_shear_rate(r.drv, 1.0), ODHS_OK);
    unsigned char buf[sizeof(struct old_info) + 64];
    for (int k = 0; k < 400; ++k) {
        memset(buf, 0xcd, sizeof buf);
        struct old_info o;
        o.size = sizeof o;
        memcpy(buf, &o, sizeof o.size);
        ck_assert_int_eq(odhs_stepper_step_ex(r.st, (odhs_step_info *)(void *)buf), ODHS_OK);
        for (size_t b = sizeof(struct old_info); b < sizeof buf; ++b)
            ck_assert_msg(buf[b] == 0xcd, "byte %zu past the old struct written", b);
        memcpy(&o, buf, sizeof o);
        ck_assert_msg(o.size == sizeof o, "size changed to %zu", o.size);
        ck_assert(o.kind == ODHS_EVENT_NONE || o.kind == ODHS_EVENT_COLLISION || o.kind == ODHS_EVENT_OPENING);
        if (o.kind != ODHS_EVENT_NONE) {
            double t;
            odhs_stepper_time(r.st, &t);
            ck_assert(o.i < o.j && o.j < 48 && o.event_time <= t);
        }
    }
    /* a newer caller's larger struct: the tail is left as set */
    struct {
        odhs_step_info in;
        double future[4];
    } big;
    memset(&big, 0, sizeof big);
    big.in.size = sizeof big;
    big.future[3] = 42.0;
    ck_assert_int_eq(odhs_stepper_step_ex(r.st, &big.in), ODHS_OK);
    ck_assert(big.future[3] == 42.0 && big.in.size == sizeof big);
    rig_free(&r);
}
END_TEST

/* ---- 9. the system changed behind the stepper ------------------------------ */
START_TEST(test_system_changed)
{
    rig r = rig_new(scene(48, 0.6, 0, 14));
    ck_assert_int_eq(odhs_driver_set_shear_rate(r.drv, 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_strain(r.st, 0.02), ODHS_OK);
    uint64_t c0, c1;
    ck_assert_int_eq(odhs_system_change_count(r.sys, &c0), ODHS_OK);
    /* the stepper's own motion does not count; writing the same positions neither */
    double x[96];
    odhs_system_get_positions(r.sys, x);
    ck_assert_int_eq(odhs_system_set_positions(r.sys, x), ODHS_OK);
    ck_assert_int_eq(odhs_system_change_count(r.sys, &c1), ODHS_OK);
    ck_assert(c1 == c0);
    ck_assert_int_eq(odhs_stepper_step(r.st, NULL), ODHS_OK);
    /* scale_box behind its back: refused until reset */
    ck_assert_int_eq(odhs_system_scale_box(r.sys, 1.05), ODHS_OK);
    int s = odhs_stepper_step(r.st, NULL);
    ck_assert_msg(s == ODHS_E_STATE && strstr(odhs_stepper_errmsg(r.st), "odhs_stepper_reset"), "%d (%s)", s,
                  odhs_stepper_errmsg(r.st));
    ck_assert_int_eq(odhs_stepper_run_until_strain(r.st, 0.03), ODHS_E_STATE);
    ck_assert_int_eq(odhs_stepper_correct(r.st), ODHS_E_STATE);
    ck_assert_int_eq(odhs_stepper_reset(r.st), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_strain(r.st, 0.03), ODHS_OK);
    double gap, ov;
    ck_assert_int_eq(odhs_stepper_errors(r.st, &gap, &ov), ODHS_OK);
    ck_assert_msg(gap < 1e-9 && ov < 1e-9, "after reset: gap %g overlap %g", gap, ov);
    /* radii too */
    double rr[48];
    odhs_system_get_radii(r.sys, rr);
    for (int i = 0; i < 48; ++i) rr[i] *= 0.99;
    ck_assert_int_eq(odhs_system_set_radii(r.sys, rr), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_step(r.st, NULL), ODHS_E_STATE);
    rig_free(&r);
}
END_TEST

/* ---- 10. bulk accessors ------------------------------------------------------ */
START_TEST(test_bulk_contacts)
{
    rig r = rig_new(scene(64, 0.78, 0, 15));
    ck_assert_int_eq(odhs_driver_set_shear_rate(r.drv, 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_strain(r.st, 0.05), ODHS_OK);
    size_t nc = 0;
    ck_assert_int_eq(odhs_stepper_contacts(r.st, 0, &nc, NULL, NULL, NULL, NULL, NULL),
                     nc ? ODHS_E_RANGE : ODHS_OK);
    const odhs_network *net = odhs_stepper_network(r.st);
    ck_assert_msg(nc > 10 && nc == odhs_network_count(net), "nc %zu", nc);
    size_t *ci = malloc(nc * sizeof *ci), *cj = malloc(nc * sizeof *cj), *ni = malloc(nc * sizeof *ni);
    int *kind = malloc(nc * sizeof *kind);
    double *f = malloc(nc * sizeof *f), *gap = malloc(nc * sizeof *gap), *f2 = malloc(nc * sizeof *f2),
           *g2 = malloc(nc * sizeof *g2);
    size_t n2;
    ck_assert_int_eq(odhs_stepper_contacts(r.st, nc, &n2, ci, cj, kind, f, gap), ODHS_OK);
    ck_assert_int_eq(n2, nc);
    odhs_network_get_forces(net, f2);
    odhs_network_get_gaps(net, g2);
    ck_assert_int_eq(odhs_network_get_contacts(net, ni, NULL, NULL), ODHS_OK);
    for (size_t k = 0; k < nc; ++k) {
        size_t i, j;
        int kd;
        ck_assert_int_eq(odhs_network_get_contact(net, k, &i, &j, &kd), ODHS_OK);
        ck_assert(i == ci[k] && j == cj[k] && kd == kind[k] && ni[k] == i);
        ck_assert(f[k] == f2[k] && gap[k] == g2[k] && f[k] >= 0.0 && fabs(gap[k]) < 1e-9);
    }
    free(ci), free(cj), free(ni), free(kind), free(f), free(gap), free(f2), free(g2);
    rig_free(&r);
}
END_TEST

/* ---- 11. the pre-event stress ---------------------------------------------- */
START_TEST(test_pre_event_stress)
{
    odhs_system *base = scene(64, 0.80, 0, 3);
    odhs_system *copy = NULL;
    ck_assert_int_eq(odhs_system_clone(base, &copy), ODHS_OK);
    rig a = rig_new(base), b = rig_new(copy);
    rig *rs[2] = {&a, &b};
    for (int k = 0; k < 2; ++k) {
        ck_assert_int_eq(odhs_driver_set_shear_rate(rs[k]->drv, 1.0), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_set_integrator(rs[k]->st, ODHS_INTEGRATOR_EULER), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_set_dt(rs[k]->st, 1e-3), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_set_correction_interval(rs[k]->st, 0), ODHS_OK);
    }
    double sig[4], pre[4], prev[4];
    /* off: no record, and the reason */
    ck_assert_int_eq(odhs_stepper_pre_event_stress(a.st, pre), ODHS_E_STATE);
    ck_assert_msg(strstr(odhs_stepper_errmsg(a.st), "not recorded"), "%s", odhs_stepper_errmsg(a.st));
    ck_assert_int_eq(odhs_stepper_set_pre_event_stress(a.st, 2), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_stepper_set_pre_event_stress(a.st, 1), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_pre_event_stress(a.st, pre), ODHS_E_STATE);
    ck_assert_msg(strstr(odhs_stepper_errmsg(a.st), "no step taken"), "%s", odhs_stepper_errmsg(a.st));
    ck_assert_int_eq(odhs_stepper_reset(a.st), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_stress(a.st, prev), ODHS_OK);
    size_t quiet = 0, colls = 0, up = 0;
    double worst_quiet = 0.0, worst_down = 0.0, scale = 0.0;
    for (int step = 0; step < 600; ++step) {
        odhs_step_info ia = {.size = sizeof ia}, ib = {.size = sizeof ib};
        ck_assert_int_eq(odhs_stepper_step_ex(a.st, &ia), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_step_ex(b.st, &ib), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_stress(a.st, sig), ODHS_OK);
        ck_assert_msg(odhs_stepper_pre_event_stress(a.st, pre) == ODHS_OK, "step %d: %s", step,
                      odhs_stepper_errmsg(a.st));
        scale = fmax(scale, fabs(sig[1]));
        if (ia.collisions == 0 && ia.openings == 0) {
            /* same network, same geometry: the same solve */
            quiet++;
            for (int c = 0; c < 4; ++c) worst_quiet = fmax(worst_quiet, fabs(sig[c] - pre[c]));
        } else if (ia.openings == 0) {
            colls++;
            double jump = sig[1] - pre[1];
            if (jump > 1e-6 * fabs(sig[1])) up++;
            worst_down = fmax(worst_down, -jump / fabs(sig[1]));
        }
        /* the continuous part moves the stress from the last step's value */
        ck_assert_msg(pre[1] != prev[1] || !ia.advanced, "step %d: the record is the start's stress", step);
        memcpy(prev, sig, sizeof prev);
    }
    ck_assert_msg(quiet > 50 && colls > 50, "%zu steps without events, %zu collision steps", quiet, colls);
    ck_assert_msg(worst_quiet == 0.0, "record and stress differ by %g on steps without events", worst_quiet);
    ck_assert_msg(worst_down < 1e-9, "the shear stress fell by %g (relative) at a collision", worst_down);
    ck_assert_msg(up > colls / 2, "only %zu of %zu collisions raised the stress", up, colls);
    /* the record changes nothing else (cholmod keeps no state) */
    double xa[128], xb[128], sb[4];
    ck_assert_int_eq(odhs_system_get_positions(a.sys, xa), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_positions(b.sys, xb), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_stress(b.st, sb), ODHS_OK);
    ck_assert_msg(memcmp(xa, xb, sizeof xa) == 0 && memcmp(sig, sb, sizeof sb) == 0,
                  "a run with the record differs from one without");
    /* at a reversal of a triangle wave the record is the stress under the
     * old direction (the flow's left limit): positive like the stress just
     * before, while the reversed flow opens the network */
    {
        odhs_system *s3 = scene(64, 0.80, 0, 4);
        rig c = rig_new(s3);
        double t0;
        ck_assert_int_eq(odhs_stepper_set_integrator(c.st, ODHS_INTEGRATOR_EULER), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_set_dt(c.st, 1e-3), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_set_correction_interval(c.st, 0), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_time(c.st, &t0), ODHS_OK);
        ck_assert_int_eq(odhs_driver_set_oscillatory_shear(c.drv, ODHS_OSCILLATION_TRIANGLE, 0.05, 0.2, t0), ODHS_OK);
        ck_assert_int_eq(odhs_stepper_set_pre_event_stress(c.st, 1), ODHS_OK);
        double last = 0.0;
        int seen = 0;
        for (int k = 0; k < 20000 && !seen; ++k) {
            odhs_step_info in = {.size = sizeof in};
            ck_assert_int_eq(odhs_stepper_step_ex(c.st, &in), ODHS_OK);
            if (!in.advanced) continue;
            ck_assert_int_eq(odhs_stepper_pre_event_stress(c.st, pre), ODHS_OK);
            if (in.time_end == t0 + 0.05) { /* the first reversal, t0 + T/4 */
                seen = 1;
                ck_assert_msg(last > 0.0 && pre[1] > 0.5 * last, "pre-event %g at the reversal, %g before", pre[1],
                              last);
            }
            ck_assert_int_eq(odhs_stepper_stress(c.st, sig), ODHS_OK);
            last = sig[1];
        }
        ck_assert_msg(seen, "no step ended at the reversal");
        rig_free(&c);
    }
    /* a driver change with no motion has no record; pressure control none */
    ck_assert_int_eq(odhs_driver_set_shear_rate(a.drv, 2.0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_step(a.st, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_pressure(a.drv, 10.0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_step(a.st, NULL), ODHS_OK);
    int s = odhs_stepper_pre_event_stress(a.st, pre);
    ck_assert_msg(s == ODHS_E_STATE && (strstr(odhs_stepper_errmsg(a.st), "pressure") ||
                                        strstr(odhs_stepper_errmsg(a.st), "driver")),
                  "%d: %s", s, odhs_stepper_errmsg(a.st));
    /* switching off clears it */
    ck_assert_int_eq(odhs_stepper_set_pre_event_stress(a.st, 0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_pre_event_stress(a.st, pre), ODHS_E_STATE);
    ck_assert_int_eq(odhs_stepper_pre_event_stress(NULL, pre), ODHS_E_NULL);
    ck_assert_int_eq(odhs_stepper_pre_event_stress(a.st, NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_stepper_set_pre_event_stress(NULL, 1), ODHS_E_NULL);
    rig_free(&a);
    rig_free(&b);
}
END_TEST

Suite *make_embed_suite(void)
{
    Suite *s = suite_create("embed");
    TCase *tc = tcase_create("embed");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_stall_empty_driver);
    tcase_add_test(tc, test_stall_uniform_gravity);
    tcase_add_test(tc, test_stall_time_resolution);
    tcase_add_test(tc, test_step_cap);
    tcase_add_test(tc, test_huge_forces);
    tcase_add_test(tc, test_callback_checkpoint);
    tcase_add_test(tc, test_callback_timing);
    tcase_add_test(tc, test_physical_time);
    tcase_add_test(tc, test_create_messages);
    tcase_add_test(tc, test_message_cleared);
    tcase_add_test(tc, test_step_info_size);
    tcase_add_test(tc, test_system_changed);
    tcase_add_test(tc, test_bulk_contacts);
    tcase_add_test(tc, test_pre_event_stress);
    suite_add_tcase(s, tc);
    return s;
}
