/*
 * Check suite "numfail": numerical failure is detected, reported with a
 * specific code, rolled back, and recoverable with a solver fallback
 * (odhs_solver_set_fallback).
 *
 *   - cg_noconv_fallback_solve: "cg" capped at 1 iteration does not converge
 *     on a stiff network close to jamming (ODHS_E_NOCONV); with a "dense"
 *     fallback the same solve succeeds, gives the dense solution (N x = b to
 *     round-off, equal to a dense-only solve) and the statistics say so.
 *   - cg_noconv_stepper_rollback_and_recovery: the same cap inside a shear
 *     run: the step fails with ODHS_E_NOCONV and the configuration, time and
 *     counters are those before the step; after odhs_solver_set_fallback the
 *     run continues and follows the dense-only run step for step.
 *   - hyperstatic_crystal: a monodisperse triangular crystal patch in contact
 *     everywhere (z = 6 > 2d: N = S S^T singular): dense reports
 *     ODHS_E_SINGULAR, cg with the dense fallback reports the fallback's
 *     ODHS_E_SINGULAR with both messages, and "chain_rescued" stays 0.
 *   - duplicated_contact: a network with the same pair twice is refused.
 *   - fallback_chain: chains are followed, cycles refused.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"

#define OK(call)                                                                                 \
    do {                                                                                         \
        int rc_ = (call);                                                                        \
        ck_assert_msg(rc_ == ODHS_OK, "%s returned %d (%s)", #call, rc_, odhs_strerror(rc_));    \
    } while (0)

static double stat_of(const odhs_solver *s, const char *key)
{
    double v = -1.0;
    OK(odhs_solver_get_stat(s, key, &v));
    return v;
}

/* 2D bidisperse, compressed to phi and corrected: a stiff network */
static odhs_system *dense_packing(size_t n, double phi, uint64_t seed)
{
    odhs_system *sys;
    odhs_solver *sol;
    odhs_driver *drv;
    odhs_stepper *st;
    OK(odhs_system_create(2, n, &sys));
    OK(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, seed));
    OK(odhs_system_place_random(sys, 0.5, seed + 1));
    OK(odhs_solver_create_by_name("dense", &sol));
    OK(odhs_driver_create(&drv));
    OK(odhs_driver_set_compression_rate(drv, 1.0));
    OK(odhs_stepper_create(sys, drv, sol, &st));
    OK(odhs_stepper_run_until_packing_fraction(st, phi));
    OK(odhs_stepper_correct(st));
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    return sys;
}

/* shear stepper on a clone of base */
typedef struct {
    odhs_system *sys;
    odhs_driver *drv;
    odhs_stepper *st;
} run;

static void run_open(run *r, const odhs_system *base, odhs_solver *sol)
{
    OK(odhs_system_clone(base, &r->sys));
    OK(odhs_driver_create(&r->drv));
    OK(odhs_driver_set_shear_rate(r->drv, 1.0));
    OK(odhs_stepper_create(r->sys, r->drv, sol, &r->st));
}

static void run_close(run *r)
{
    odhs_stepper_destroy(r->st);
    odhs_driver_destroy(r->drv);
    odhs_system_destroy(r->sys);
}

START_TEST(cg_noconv_fallback_solve)
{
    odhs_system *sys = dense_packing(64, 0.82, 5);
    odhs_solver *ref, *cg, *dn;
    OK(odhs_solver_create_by_name("dense", &ref));
    run r;
    run_open(&r, sys, ref);
    OK(odhs_stepper_reset(r.st));
    const odhs_network *net = odhs_stepper_network(r.st);
    size_t nc = odhs_network_count(net);
    ck_assert_uint_gt(nc, 60);
    double *b = malloc(nc * sizeof *b), *x = calloc(nc, sizeof *x), *xr = calloc(nc, sizeof *xr),
           *Nx = malloc(nc * sizeof *Nx);
    for (size_t c = 0; c < nc; ++c) b[c] = 1.0 + 0.5 * sin((double)c);
    OK(odhs_solver_solve(ref, net, b, xr));

    OK(odhs_solver_create_by_name("cg", &cg));
    OK(odhs_solver_set_param(cg, "maxiter", 1));
    ck_assert_int_eq(odhs_solver_solve(cg, net, b, x), ODHS_E_NOCONV);
    ck_assert(odhs_solver_errmsg(cg)[0] != '\0');
    ck_assert(stat_of(cg, "chain_fallbacks") == 0.0 && stat_of(cg, "chain_last") == 0.0);
    double res_fail = stat_of(cg, "residual");
    ck_assert_msg(res_fail > 1e-3, "one CG iteration left a residual of only %g", res_fail);

    OK(odhs_solver_create_by_name("dense", &dn));
    OK(odhs_solver_set_fallback(cg, dn));
    memset(x, 0, nc * sizeof *x);
    OK(odhs_solver_solve(cg, net, b, x));
    ck_assert(stat_of(cg, "chain_fallbacks") == 1.0);
    ck_assert(stat_of(cg, "chain_rescued") == 1.0);
    ck_assert(stat_of(cg, "chain_last") == 1.0);
    ck_assert(stat_of(dn, "solves") >= 1.0);
    ck_assert_ptr_nonnull(strstr(odhs_solver_errmsg(cg), "fallback dense"));
    /* the fallback's answer: N x = b and the dense-only solution */
    OK(odhs_network_apply_N(net, x, Nx, NULL));
    double rn = 0.0, bn = 0.0, dx = 0.0, xn = 0.0;
    for (size_t c = 0; c < nc; ++c) {
        rn += (Nx[c] - b[c]) * (Nx[c] - b[c]);
        bn += b[c] * b[c];
        dx = fmax(dx, fabs(x[c] - xr[c]));
        xn = fmax(xn, fabs(xr[c]));
    }
    ck_assert_msg(stat_of(cg, "residual") == stat_of(dn, "residual"), "residual statistic not the fallback's");
    ck_assert_msg(sqrt(rn / bn) < 1e-8, "relative residual %g", sqrt(rn / bn));
    ck_assert_msg(dx <= 1e-12 * xn, "fallback solution differs from dense by %g (scale %g)", dx, xn);
    /* a solve that converges clears chain_last; removing the fallback works */
    OK(odhs_solver_set_param(cg, "maxiter", 0));
    OK(odhs_solver_solve(cg, net, b, x));
    ck_assert(stat_of(cg, "chain_last") == 0.0 && stat_of(cg, "chain_fallbacks") == 1.0);
    OK(odhs_solver_set_param(cg, "maxiter", 1));
    OK(odhs_solver_set_fallback(cg, NULL));
    memset(x, 0, nc * sizeof *x);
    ck_assert_int_eq(odhs_solver_solve(cg, net, b, x), ODHS_E_NOCONV);
    fprintf(stderr, "[numfail] cg(maxiter 1) on Nc = %zu: residual %.3g without fallback; with dense: %.3g\n", nc,
            res_fail, sqrt(rn / bn));
    free(b);
    free(x);
    free(xr);
    free(Nx);
    run_close(&r);
    odhs_solver_destroy(cg);
    odhs_solver_destroy(dn);
    odhs_solver_destroy(ref);
    odhs_system_destroy(sys);
}
END_TEST

START_TEST(cg_noconv_stepper_rollback_and_recovery)
{
    odhs_system *base = dense_packing(64, 0.82, 7);
    size_t n = odhs_system_count(base), nd = 2 * n;
    odhs_solver *cg, *dn, *ref;
    OK(odhs_solver_create_by_name("cg", &cg));
    OK(odhs_solver_create_by_name("dense", &dn));
    OK(odhs_solver_create_by_name("dense", &ref));
    run a, b;
    run_open(&a, base, cg);
    run_open(&b, base, ref);
    /* a few good steps, then cap CG: the next step must fail and roll back */
    OK(odhs_stepper_set_event_callback(a.st, NULL, NULL));
    for (int k = 0; k < 5; ++k) {
        OK(odhs_stepper_step(a.st, NULL));
        OK(odhs_stepper_step(b.st, NULL));
    }
    OK(odhs_solver_set_param(cg, "maxiter", 1));
    double *x0 = malloc(nd * sizeof *x0), *x1 = malloc(nd * sizeof *x1), *xb = malloc(nd * sizeof *xb);
    OK(odhs_system_get_positions(a.sys, x0));
    double t0, t1;
    uint64_t s0, s1;
    OK(odhs_stepper_time(a.st, &t0));
    OK(odhs_stepper_counts(a.st, &s0, NULL, NULL));
    int rc = odhs_stepper_step(a.st, NULL);
    ck_assert_msg(rc == ODHS_E_NOCONV, "capped CG step returned %d (%s)", rc, odhs_strerror(rc));
    ck_assert(odhs_stepper_errmsg(a.st)[0] != '\0');
    OK(odhs_system_get_positions(a.sys, x1));
    OK(odhs_stepper_time(a.st, &t1));
    OK(odhs_stepper_counts(a.st, &s1, NULL, NULL));
    ck_assert_msg(memcmp(x0, x1, nd * sizeof *x0) == 0, "positions changed by the failed step");
    ck_assert(t0 == t1 && s0 == s1);
    /* recovery: the dense fallback takes over; the run follows the dense-only run */
    OK(odhs_solver_set_fallback(cg, dn));
    double worst = 0.0;
    for (int k = 0; k < 40; ++k) {
        OK(odhs_stepper_step(a.st, NULL));
        OK(odhs_stepper_step(b.st, NULL));
        OK(odhs_system_get_positions(a.sys, x1));
        OK(odhs_system_get_positions(b.sys, xb));
        for (size_t q = 0; q < nd; ++q) worst = fmax(worst, fabs(x1[q] - xb[q]));
        double ov;
        OK(odhs_stepper_errors(a.st, NULL, &ov));
        ck_assert_msg(ov <= 1e-12, "overlap %g after recovery", ov);
    }
    double nfb = stat_of(cg, "chain_fallbacks"), nres = stat_of(cg, "chain_rescued");
    ck_assert_msg(nfb >= 40 && nres == nfb, "fallbacks %g, rescued %g", nfb, nres);
    ck_assert_msg(worst <= 1e-9, "recovered run departs from the dense run by %g", worst);
    fprintf(stderr, "[numfail] stepper: capped cg rolled back; %g solves rescued by dense, max |dx| vs dense %.2e\n",
            nres, worst);
    free(x0);
    free(x1);
    free(xb);
    run_close(&a);
    run_close(&b);
    odhs_solver_destroy(cg);
    odhs_solver_destroy(dn);
    odhs_solver_destroy(ref);
    odhs_system_destroy(base);
}
END_TEST

/* monodisperse triangular crystal, 4 x 4, every neighbour pair at contact */
static odhs_system *crystal(void)
{
    const int nx = 4, ny = 4;
    size_t n = (size_t)(nx * ny);
    odhs_system *sys;
    OK(odhs_system_create(2, n, &sys));
    double L[2] = {nx * 1.0, ny * sqrt(3.0) / 2.0}, *r = malloc(n * sizeof *r), *x = malloc(2 * n * sizeof *x);
    for (int j = 0; j < ny; ++j)
        for (int i = 0; i < nx; ++i) {
            size_t k = (size_t)(j * nx + i);
            r[k] = 0.5;
            x[2 * k] = i + 0.5 * (j % 2) + 0.25;
            x[2 * k + 1] = j * sqrt(3.0) / 2.0 + 0.25;
        }
    OK(odhs_system_set_box(sys, L));
    OK(odhs_system_set_radii(sys, r));
    OK(odhs_system_set_positions(sys, x));
    free(r);
    free(x);
    return sys;
}

START_TEST(hyperstatic_crystal)
{
    odhs_system *sys = crystal();
    odhs_network *net;
    OK(odhs_network_create(sys, &net));
    OK(odhs_network_detect(net, sys, 1e-9));
    size_t nc = odhs_network_count(net), n = odhs_system_count(sys);
    ck_assert_uint_eq(nc, 3 * n); /* z = 6 */
    double *b = malloc(nc * sizeof *b), *x = calloc(nc, sizeof *x);
    for (size_t c = 0; c < nc; ++c) b[c] = 1.0 + 0.25 * cos(3.0 * (double)c);
    odhs_solver *dn, *cg;
    OK(odhs_solver_create_by_name("dense", &dn));
    OK(odhs_solver_create_by_name("cg", &cg));
    ck_assert_int_eq(odhs_solver_solve(dn, net, b, x), ODHS_E_SINGULAR);
    OK(odhs_solver_set_fallback(cg, dn));
    memset(x, 0, nc * sizeof *x);
    int rc = odhs_solver_solve(cg, net, b, x);
    ck_assert_msg(rc == ODHS_E_SINGULAR, "cg + dense fallback on a hyperstatic crystal: %d (%s)", rc,
                  odhs_strerror(rc));
    const char *m = odhs_solver_errmsg(cg);
    ck_assert_msg(strstr(m, "cg") && strstr(m, "fallback dense failed too"), "message: %s", m);
    ck_assert(stat_of(cg, "chain_fallbacks") == 1.0 && stat_of(cg, "chain_rescued") == 0.0);
    ck_assert(stat_of(cg, "chain_last") == 1.0);
    free(b);
    free(x);
    odhs_solver_destroy(cg);
    odhs_solver_destroy(dn);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

START_TEST(duplicated_contact)
{
    odhs_system *sys = crystal();
    odhs_network *net;
    OK(odhs_network_create(sys, &net));
    OK(odhs_network_add(net, 0, 1, ODHS_CONTACT_TEMPORARY));
    size_t nc = odhs_network_count(net);
    int rc = odhs_network_add(net, 0, 1, ODHS_CONTACT_TEMPORARY);
    ck_assert_msg(rc < 0, "duplicated contact accepted (%d)", rc);
    rc = odhs_network_add(net, 1, 0, ODHS_CONTACT_PERMANENT);
    ck_assert_msg(rc < 0, "duplicated contact (reversed) accepted (%d)", rc);
    ck_assert_uint_eq(odhs_network_count(net), nc);
    ck_assert(odhs_network_errmsg(net)[0] != '\0');
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

START_TEST(fallback_chain)
{
    odhs_system *sys = dense_packing(32, 0.80, 11);
    odhs_solver *a, *b2, *c;
    OK(odhs_solver_create_by_name("cg", &a));
    OK(odhs_solver_create_by_name("cg", &b2));
    OK(odhs_solver_create_by_name("dense", &c));
    OK(odhs_solver_set_param(a, "maxiter", 1));
    OK(odhs_solver_set_param(b2, "maxiter", 1));
    OK(odhs_solver_set_fallback(a, b2));
    OK(odhs_solver_set_fallback(b2, c));
    ck_assert_int_eq(odhs_solver_set_fallback(c, a), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_solver_set_fallback(a, a), ODHS_E_INVALID);
    ck_assert(odhs_solver_errmsg(a)[0] != '\0');
    odhs_solver *ref;
    OK(odhs_solver_create_by_name("dense", &ref));
    run r;
    run_open(&r, sys, ref);
    OK(odhs_stepper_reset(r.st));
    const odhs_network *net = odhs_stepper_network(r.st);
    size_t nc = odhs_network_count(net);
    ck_assert_uint_gt(nc, 10);
    double *bb = malloc(nc * sizeof *bb), *x = calloc(nc, sizeof *x);
    for (size_t k = 0; k < nc; ++k) bb[k] = 1.0;
    OK(odhs_solver_solve(a, net, bb, x));
    /* a -> b2 (fails too) -> c (solves) */
    ck_assert(stat_of(a, "chain_fallbacks") == 1.0 && stat_of(a, "chain_rescued") == 1.0);
    ck_assert(stat_of(b2, "chain_fallbacks") == 1.0 && stat_of(b2, "chain_rescued") == 1.0);
    ck_assert(stat_of(a, "residual") < 1e-8);
    free(bb);
    free(x);
    run_close(&r);
    odhs_solver_destroy(ref);
    odhs_solver_destroy(a);
    odhs_solver_destroy(b2);
    odhs_solver_destroy(c);
    odhs_system_destroy(sys);
}
END_TEST

Suite *make_numfail_suite(void)
{
    Suite *s = suite_create("numfail");
    TCase *tc = tcase_create("numfail");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, cg_noconv_fallback_solve);
    tcase_add_test(tc, cg_noconv_stepper_rollback_and_recovery);
    tcase_add_test(tc, hyperstatic_crystal);
    tcase_add_test(tc, duplicated_contact);
    tcase_add_test(tc, fallback_chain);
    suite_add_tcase(s, tc);
    return s;
}
