/*
 * libodhs - Check suite "walls": hard walls as constraints in S.
 *
 *  - a disc pushed onto a floor: it lands at the analytic time and height,
 *    slides on at xi0 F_parallel, and the floor carries exactly F_normal;
 *  - a column of discs under gravity on a floor: contact k carries the
 *    weight above it, the floor the whole weight, nothing moves;
 *  - a disc sliding down a segment wall at xi0 (F.t) t, then off its end;
 *  - discs pushed into a circular container come to rest with the container
 *    carrying the total external force;
 *  - a piston compressing discs in a channel: power balance including the
 *    piston's work, no particle crosses a wall, backends agree, checkpoints
 *    restore walls bit-identically;
 *  - walls cost nothing in scenes without them (feature counters).
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "odhs.h"
#include "testutil.h"

#define CHECK_OK(expr)                                                                              \
    do {                                                                                            \
        int rc_ = (expr);                                                                           \
        ck_assert_msg(rc_ == ODHS_OK, "%s returned %d (%s)", #expr, rc_, odhs_strerror(rc_));       \
    } while (0)

typedef struct {
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
} scene;

static void scene_make(scene *s, int dim, size_t n, const double *L, const double *r, const double *x,
                       const double *F, const char *solver)
{
    memset(s, 0, sizeof *s);
    CHECK_OK(odhs_system_create(dim, n, &s->sys));
    CHECK_OK(odhs_system_set_configuration(s->sys, L, 0.0, r, x));
    CHECK_OK(odhs_driver_create(&s->drv));
    if (F) CHECK_OK(odhs_driver_set_forces(s->drv, n, dim, F));
    CHECK_OK(odhs_solver_create_by_name(solver, &s->sol));
    CHECK_OK(odhs_stepper_create(s->sys, s->drv, s->sol, &s->st));
}

static void scene_free(scene *s)
{
    odhs_stepper_destroy(s->st);
    odhs_solver_destroy(s->sol);
    odhs_driver_destroy(s->drv);
    odhs_system_destroy(s->sys);
}

/* ---- a disc pushed onto a floor --------------------------------------------- */
typedef struct {
    double t;
    size_t i, j;
    int kind, n;
} first_event;

static int on_event(const odhs_event *e, void *ctx)
{
    first_event *f = ctx;
    if (f->n++ == 0) {
        f->t = e->time;
        f->i = e->i;
        f->j = e->j;
        f->kind = e->kind;
    }
    return 0;
}

START_TEST(test_plane_landing)
{
    double L[2] = {10, 10}, r[1] = {0.5}, x[2] = {5.0, 3.0}, F[2] = {0.3, -2.0};
    scene s;
    scene_make(&s, 2, 1, L, r, x, F, "dense");
    double nrm[2] = {0.0, 1.0};
    size_t id;
    CHECK_OK(odhs_stepper_add_wall_plane(s.st, nrm, 1.0, &id)); /* y >= 1 + a */
    ck_assert_uint_eq(id, 0);
    first_event fe = {0, 0, 0, 0, 0};
    CHECK_OK(odhs_stepper_set_event_callback(s.st, on_event, &fe));
    CHECK_OK(odhs_stepper_run_until_time(s.st, 2.0));
    /* lands after falling 1.5 at speed 2 */
    ck_assert_int_eq(fe.kind, ODHS_EVENT_COLLISION);
    ck_assert_uint_eq(fe.i, 0);
    ck_assert_uint_eq(fe.j, 1); /* N + wall 0 */
    ck_assert_msg(fabs(fe.t - 0.75) < 1e-12, "landing at t = %.17g, expected 0.75", fe.t);
    double xe[2], V[2], Fw[2];
    CHECK_OK(odhs_system_get_positions(s.sys, xe));
    CHECK_OK(odhs_stepper_velocities(s.st, V));
    CHECK_OK(odhs_stepper_wall_force(s.st, 0, Fw));
    ck_assert_msg(fabs(xe[1] - 1.5) < 1e-12, "height %.17g", xe[1]);
    ck_assert_msg(fabs(xe[0] - (5.0 + 0.3 * 2.0)) < 1e-12, "x %.17g", xe[0]);
    ck_assert_msg(fabs(V[0] - 0.3) < 1e-14 && fabs(V[1]) < 1e-14, "V = (%g, %g)", V[0], V[1]);
    ck_assert_msg(fabs(Fw[0]) < 1e-14 && fabs(Fw[1] + 2.0) < 1e-14, "wall force (%g, %g)", Fw[0], Fw[1]);
    double P, D;
    CHECK_OK(odhs_stepper_power(s.st, &P));
    CHECK_OK(odhs_stepper_dissipation(s.st, &D));
    ck_assert_msg(fabs(P - D) < 1e-14, "power %g dissipation %g", P, D);
    /* pulling it up again opens the wall contact */
    double Fup[2] = {0.0, 1.0};
    CHECK_OK(odhs_driver_set_forces(s.drv, 1, 2, Fup));
    CHECK_OK(odhs_stepper_run_until_time(s.st, 3.0));
    ck_assert_uint_eq(odhs_network_count(odhs_stepper_network(s.st)), 0);
    CHECK_OK(odhs_system_get_positions(s.sys, xe));
    ck_assert_msg(fabs(xe[1] - 2.5) < 1e-12, "height after lifting %.17g", xe[1]);
    scene_free(&s);
}
END_TEST

/* ---- a column under gravity ------------------------------------------------- */
START_TEST(test_gravity_column)
{
    enum { K = 6 };
    double L[2] = {10, 20}, r[K], x[2 * K], F[2 * K];
    double y = 1.0;
    for (int k = 0; k < K; ++k) {
        r[k] = k % 2 ? 0.7 : 0.5;
        y += (k ? r[k - 1] : 0.0) + r[k];
        x[2 * k] = 5.0;
        x[2 * k + 1] = y;
        /* weight proportional to the area */
        F[2 * k] = 0.0;
        F[2 * k + 1] = -r[k] * r[k] / 0.25;
    }
    scene s;
    scene_make(&s, 2, K, L, r, x, F, "dense");
    double nrm[2] = {0.0, 1.0};
    CHECK_OK(odhs_stepper_add_wall_plane(s.st, nrm, 1.0, NULL));
    CHECK_OK(odhs_stepper_reset(s.st));
    const odhs_network *net = odhs_stepper_network(s.st);
    ck_assert_uint_eq(odhs_network_count(net), K);
    double f[K];
    CHECK_OK(odhs_network_get_forces(net, f));
    for (size_t c = 0; c < K; ++c) {
        size_t i, j;
        int kind;
        CHECK_OK(odhs_network_get_contact(net, c, &i, &j, &kind));
        /* contact below particle `top` carries the weight of top..K-1 */
        size_t top = kind == ODHS_CONTACT_WALL ? 0 : j;
        double w = 0.0;
        for (size_t k = top; k < K; ++k) w -= F[2 * k + 1];
        ck_assert_msg(fabs(f[c] - w) < 1e-13 * w, "contact (%zu,%zu): force %.17g, weight above %.17g", i, j, f[c], w);
    }
    double Fw[2], V[2 * K], Wtot = 0.0;
    for (int k = 0; k < K; ++k) Wtot -= F[2 * k + 1];
    CHECK_OK(odhs_stepper_wall_force(s.st, 0, Fw));
    ck_assert_msg(fabs(Fw[1] + Wtot) < 1e-13 * Wtot, "floor carries %.17g of %.17g", -Fw[1], Wtot);
    CHECK_OK(odhs_stepper_velocities(s.st, V));
    for (int k = 0; k < 2 * K; ++k) ck_assert_msg(fabs(V[k]) < 1e-14, "V[%d] = %g", k, V[k]);
    scene_free(&s);
}
END_TEST

/* ---- sliding down a segment ---------------------------------------------------- */
START_TEST(test_segment_slide)
{
    double L[2] = {20, 20}, r[1] = {0.5}, F[2] = {0.0, -1.0};
    /* segment from (4, 9) down to (12, 5): slope -1/2 */
    double a[2] = {4.0, 9.0}, b[2] = {12.0, 5.0};
    double tx = 2.0 / sqrt(5.0), ty = -1.0 / sqrt(5.0); /* unit tangent, downhill */
    double mx = 1.0 / sqrt(5.0), my = 2.0 / sqrt(5.0);  /* unit normal, up */
    /* start above the point at parameter 0.25 */
    double p0[2] = {a[0] + 0.25 * (b[0] - a[0]), a[1] + 0.25 * (b[1] - a[1])};
    double x[2] = {p0[0] + 2.0 * mx, p0[1] + 2.0 * my};
    scene s;
    scene_make(&s, 2, 1, L, r, x, F, "dense");
    CHECK_OK(odhs_stepper_add_wall_segment(s.st, a, b, NULL));
    first_event fe = {0, 0, 0, 0, 0};
    CHECK_OK(odhs_stepper_set_event_callback(s.st, on_event, &fe));
    /* lands when the normal distance 2 has shrunk to a = 0.5 at speed F.m */
    CHECK_OK(odhs_stepper_run_until_time(s.st, 2.0));
    double tland = (2.0 - 0.5) / (-(F[1] * my));
    ck_assert_msg(fe.n >= 1 && fabs(fe.t - tland) < 1e-12, "landing at %.17g, expected %.17g", fe.t, tland);
    double V[2];
    CHECK_OK(odhs_stepper_velocities(s.st, V));
    double vt = F[0] * tx + F[1] * ty; /* xi0 F.t */
    ck_assert_msg(fabs(V[0] - vt * tx) < 1e-13 && fabs(V[1] - vt * ty) < 1e-13, "sliding V = (%.17g, %.17g)", V[0],
                  V[1]);
    double Fw[2];
    CHECK_OK(odhs_stepper_wall_force(s.st, 0, Fw));
    ck_assert_msg(fabs(Fw[0] + mx * (-(F[1] * my))) < 1e-13, "segment force x %.17g", Fw[0]);
    /* slide off the lower end, round its corner, fall free */
    CHECK_OK(odhs_stepper_run_until_time(s.st, 30.0));
    CHECK_OK(odhs_stepper_velocities(s.st, V));
    ck_assert_msg(fabs(V[0]) < 1e-13 && fabs(V[1] + 1.0) < 1e-13, "free fall V = (%g, %g)", V[0], V[1]);
    ck_assert_uint_eq(odhs_network_count(odhs_stepper_network(s.st)), 0);
    double ov;
    CHECK_OK(odhs_stepper_errors(s.st, NULL, &ov));
    ck_assert(ov < 1e-12);
    scene_free(&s);
}
END_TEST

/* ---- a circular container -------------------------------------------------------- */
START_TEST(test_circle_container)
{
    enum { M = 12 };
    double L[2] = {30, 30}, r[M], x[2 * M], F[2 * M];
    tu_rng rng;
    tu_rng_seed(&rng, 9);
    for (int k = 0; k < M; ++k) {
        r[k] = k % 2 ? 0.7 : 0.5;
        /* on a coarse grid inside the circle of radius 6 about (15, 15) */
        x[2 * k] = 12.0 + 2.0 * (k % 4) + 0.1 * tu_uniform(&rng);
        x[2 * k + 1] = 12.5 + 2.0 * (k / 4) + 0.1 * tu_uniform(&rng);
        F[2 * k] = 1.0;
        F[2 * k + 1] = 0.4;
    }
    scene s;
    scene_make(&s, 2, M, L, r, x, F, "dense");
    double c[2] = {15.0, 15.0};
    CHECK_OK(odhs_stepper_add_wall_sphere(s.st, c, 6.0, NULL));
    CHECK_OK(odhs_stepper_set_correction_interval(s.st, 1));
    /* at every time: sum_i V_i / xi0 = sum_i F_i - F_wall (contact forces
     * between particles cancel); at long times the pile comes to rest (on a
     * curved wall only exponentially) and the container carries sum F */
    const double times[] = {5.0, 20.0, 60.0, 150.0};
    double vmax = 0.0, Fw[2], ov;
    for (size_t q = 0; q < sizeof times / sizeof times[0]; ++q) {
        CHECK_OK(odhs_stepper_run_until_time(s.st, times[q]));
        double V[2 * M], sv[2] = {0, 0};
        CHECK_OK(odhs_stepper_velocities(s.st, V));
        CHECK_OK(odhs_stepper_wall_force(s.st, 0, Fw));
        vmax = 0.0;
        for (int k = 0; k < M; ++k) {
            sv[0] += V[2 * k];
            sv[1] += V[2 * k + 1];
            vmax = fmax(vmax, hypot(V[2 * k], V[2 * k + 1]));
        }
        ck_assert_msg(fabs(sv[0] - (M * 1.0 - Fw[0])) < 1e-12 && fabs(sv[1] - (M * 0.4 - Fw[1])) < 1e-12,
                      "t = %g: momentum balance off by (%.3g, %.3g)", times[q], sv[0] - (M * 1.0 - Fw[0]),
                      sv[1] - (M * 0.4 - Fw[1]));
    }
    CHECK_OK(odhs_stepper_errors(s.st, NULL, &ov));
    uint64_t coll;
    CHECK_OK(odhs_stepper_counts(s.st, NULL, &coll, NULL));
    fprintf(stderr, "[walls] container: %llu collisions, max |V| %.2e at t = 150, wall force (%.15f, %.15f)\n",
            (unsigned long long)coll, vmax, Fw[0], Fw[1]);
    ck_assert(coll > 10);
    ck_assert_msg(vmax < 1e-8, "still moving: max |V| = %g", vmax);
    ck_assert_msg(fabs(Fw[0] - M * 1.0) < 1e-7 && fabs(Fw[1] - M * 0.4) < 1e-7, "wall force (%.17g, %.17g)", Fw[0],
                  Fw[1]);
    ck_assert(ov < 1e-12);
    scene_free(&s);
}
END_TEST

/* ---- a piston ---------------------------------------------------------------------- */
#define NP 40
static void piston_scene(scene *s, const char *solver)
{
    double L[2] = {12, 30}, r[NP], x[2 * NP];
    for (int k = 0; k < NP; ++k) {
        r[k] = k % 2 ? 0.7 : 0.5;
        x[2 * k] = 1.0 + 2.0 * (k % 6) + 0.3 * ((k / 6) % 2);
        x[2 * k + 1] = 3.0 + 2.5 * (k / 6);
    }
    scene_make(s, 2, NP, L, r, x, NULL, solver);
    double up[2] = {0.0, 1.0}, down[2] = {0.0, -1.0}, v[2] = {0.0, -1.0};
    size_t piston;
    CHECK_OK(odhs_stepper_add_wall_plane(s->st, up, 1.0, NULL));         /* floor: y >= 1 */
    CHECK_OK(odhs_stepper_add_wall_plane(s->st, down, -20.0, &piston));  /* ceiling: y <= 20 */
    CHECK_OK(odhs_stepper_set_wall_velocity(s->st, piston, v));
    CHECK_OK(odhs_driver_set_time_unit(s->drv, 1.0));
    CHECK_OK(odhs_stepper_set_dt(s->st, 2e-3));
}

START_TEST(test_piston)
{
    scene s;
    piston_scene(&s, "dense");
    double worst_pd = 0.0, worst_ov = 0.0, worst_mom = 0.0, t = 0.0;
    while (t < 6.0) {
        CHECK_OK(odhs_stepper_step(s.st, NULL));
        CHECK_OK(odhs_stepper_time(s.st, &t));
        double P, D, ov, V[2 * NP], F0[2], F1[2], sv[2] = {0, 0};
        CHECK_OK(odhs_stepper_power(s.st, &P));
        CHECK_OK(odhs_stepper_dissipation(s.st, &D));
        CHECK_OK(odhs_stepper_errors(s.st, NULL, &ov));
        worst_pd = fmax(worst_pd, fabs(P - D) / fmax(D, 1e-300));
        worst_ov = fmax(worst_ov, ov);
        /* no external force: sum V / xi0 = -(force on the floor + on the piston) */
        CHECK_OK(odhs_stepper_velocities(s.st, V));
        CHECK_OK(odhs_stepper_wall_force(s.st, 0, F0));
        CHECK_OK(odhs_stepper_wall_force(s.st, 1, F1));
        for (int k = 0; k < NP; ++k) {
            sv[0] += V[2 * k];
            sv[1] += V[2 * k + 1];
        }
        worst_mom = fmax(worst_mom, fmax(fabs(sv[0] + F0[0] + F1[0]), fabs(sv[1] + F0[1] + F1[1])));
    }
    double disp[2], Fp[2], Ff[2];
    CHECK_OK(odhs_stepper_wall_displacement(s.st, 1, disp));
    CHECK_OK(odhs_stepper_wall_force(s.st, 1, Fp));
    CHECK_OK(odhs_stepper_wall_force(s.st, 0, Ff));
    uint64_t coll;
    CHECK_OK(odhs_stepper_counts(s.st, NULL, &coll, NULL));
    fprintf(stderr,
            "[walls] piston: moved %.6f, %llu collisions, force on piston %.6g, on floor %.6g, |P-D|/D %.2e, "
            "overlap %.2e, momentum balance %.2e\n",
            disp[1], (unsigned long long)coll, Fp[1], Ff[1], worst_pd, worst_ov, worst_mom);
    ck_assert_msg(fabs(disp[1] + t) < 1e-10, "piston displacement %.17g after time %.17g", disp[1], t);
    ck_assert(coll > 20);
    ck_assert_msg(worst_pd < 1e-10, "power balance %.3g", worst_pd);
    ck_assert_msg(worst_ov < 1e-12, "overlap %.3g", worst_ov);
    ck_assert_msg(worst_mom < 1e-12, "momentum balance %.3g", worst_mom);
    ck_assert(Fp[1] > 0.0); /* the particles push the piston up */
    scene_free(&s);
}
END_TEST

START_TEST(test_piston_solvers_agree)
{
    const char *names[] = {"dense", "cg", "cholmod", "spqr"};
    double x0[2 * NP];
    for (size_t q = 0; q < sizeof names / sizeof names[0]; ++q) {
        odhs_solver *probe;
        if (odhs_solver_create_by_name(names[q], &probe) != ODHS_OK) continue; /* not installed */
        odhs_solver_destroy(probe);
        scene s;
        piston_scene(&s, names[q]);
        CHECK_OK(odhs_stepper_run_until_time(s.st, 4.0));
        double xq[2 * NP];
        CHECK_OK(odhs_system_get_positions(s.sys, xq));
        if (q == 0) memcpy(x0, xq, sizeof x0);
        double worst = 0.0;
        for (int k = 0; k < 2 * NP; ++k) worst = fmax(worst, fabs(xq[k] - x0[k]));
        ck_assert_msg(worst < 1e-9, "%s differs from dense by %.3g", names[q], worst);
        scene_free(&s);
    }
}
END_TEST

/* Write a checkpoint of a at its time, run a to t_end, read the checkpoint
 * into b (solver "cg") and run it to t_end: both must end bit for bit at the
 * same positions. */
static void checkpoint_continue(scene *a, double t_end, scene *b, const char *what)
{
    char path[] = "/tmp/odhs_walls_ckpt_XXXXXX";
    int fd = mkstemp(path);
    ck_assert(fd >= 0);
    close(fd);
    CHECK_OK(odhs_checkpoint_write(a->st, path));
    CHECK_OK(odhs_stepper_run_until_time(a->st, t_end));
    char err[256];
    memset(b, 0, sizeof *b);
    CHECK_OK(odhs_solver_create_by_name("cg", &b->sol));
    ck_assert_msg(odhs_checkpoint_read(path, b->sol, &b->sys, &b->drv, &b->st, err, sizeof err) == ODHS_OK, "%s",
                  err);
    remove(path);
    CHECK_OK(odhs_stepper_run_until_time(b->st, t_end));
    double xa[2 * NP], xb[2 * NP];
    CHECK_OK(odhs_system_get_positions(a->sys, xa));
    CHECK_OK(odhs_system_get_positions(b->sys, xb));
    ck_assert_msg(!memcmp(xa, xb, sizeof xa), "%s is not bit-identical", what);
}

START_TEST(test_walls_checkpoint)
{
    scene a, b;
    piston_scene(&a, "cg");
    CHECK_OK(odhs_stepper_run_until_time(a.st, 1.0));
    checkpoint_continue(&a, 3.0, &b, "continuation with walls");
    size_t nw;
    CHECK_OK(odhs_stepper_wall_count(b.st, &nw));
    ck_assert_uint_eq(nw, 2);
    double da[2], db[2];
    CHECK_OK(odhs_stepper_wall_displacement(a.st, 1, da));
    CHECK_OK(odhs_stepper_wall_displacement(b.st, 1, db));
    ck_assert(!memcmp(da, db, sizeof da));
    scene_free(&b);
    scene_free(&a);
}
END_TEST

/* Contacts with walls made by collisions are of kind ODHS_CONTACT_WALL (0.2.3
 * stored them as temporary, so a checkpoint taken after a particle met a
 * wall was refused on reading), and a run with them continues bit for bit. */
START_TEST(test_wall_contact_kind)
{
    scene a, b;
    piston_scene(&a, "cg");
    CHECK_OK(odhs_stepper_run_until_time(a.st, 3.0));
    const odhs_network *net = odhs_stepper_network(a.st);
    size_t nwall = 0;
    for (size_t k = 0; k < odhs_network_count(net); ++k) {
        size_t i, j;
        int kind;
        CHECK_OK(odhs_network_get_contact(net, k, &i, &j, &kind));
        ck_assert_msg((j >= NP) == (kind == ODHS_CONTACT_WALL), "contact (%zu,%zu) of kind %d", i, j, kind);
        nwall += j >= NP;
    }
    ck_assert_msg(nwall > 0, "no wall contact at t = 3");
    checkpoint_continue(&a, 5.0, &b, "continuation after wall contacts");
    scene_free(&b);
    scene_free(&a);
}
END_TEST

START_TEST(test_wall_errors)
{
    double L[2] = {10, 10}, r[2] = {0.5, 0.5}, x[4] = {2, 2, 5, 5};
    scene s;
    scene_make(&s, 2, 2, L, r, x, NULL, "dense");
    double up[2] = {0.0, 1.0}, zero[2] = {0.0, 0.0};
    ck_assert_int_eq(odhs_stepper_add_wall_plane(s.st, up, 1.8, NULL), ODHS_E_OVERLAP); /* particle 0 at y=2 */
    ck_assert_int_eq(odhs_stepper_add_wall_plane(s.st, zero, 0.0, NULL), ODHS_E_INVALID);
    size_t nw;
    CHECK_OK(odhs_stepper_wall_count(s.st, &nw));
    ck_assert_uint_eq(nw, 0);
    double c[2] = {5, 5};
    ck_assert_int_eq(odhs_stepper_add_wall_sphere(s.st, c, 2.0, NULL), ODHS_E_OVERLAP); /* particle 0 outside */
    ck_assert_int_eq(odhs_stepper_add_wall_sphere(s.st, c, -1.0, NULL), ODHS_E_INVALID);
    double v[2] = {1, 0};
    ck_assert_int_eq(odhs_stepper_set_wall_velocity(s.st, 0, v), ODHS_E_RANGE);
    scene_free(&s);
    /* segments are 2D only */
    double L3[3] = {10, 10, 10}, x3[6] = {2, 2, 2, 5, 5, 5}, a3[3] = {0, 0, 0}, b3[3] = {1, 1, 1};
    scene_make(&s, 3, 2, L3, r, x3, NULL, "dense");
    ck_assert_int_eq(odhs_stepper_add_wall_segment(s.st, a3, b3, NULL), ODHS_E_DIM);
    scene_free(&s);
}
END_TEST

START_TEST(test_walls_feature_cost)
{
    scene s;
    piston_scene(&s, "cg");
    CHECK_OK(odhs_stepper_run_until_time(s.st, 0.5));
    uint64_t w;
    CHECK_OK(odhs_stepper_feature_work(s.st, ODHS_FEATURE_WALLS, &w));
    ck_assert(w > 0);
    scene_free(&s);
    /* the same particles without walls (a plain periodic box) */
    double L[2] = {12, 30}, r[NP], x[2 * NP], F[2 * NP];
    for (int k = 0; k < NP; ++k) {
        r[k] = k % 2 ? 0.7 : 0.5;
        x[2 * k] = 1.0 + 2.0 * (k % 6) + 0.3 * ((k / 6) % 2);
        x[2 * k + 1] = 3.0 + 2.5 * (k / 6);
        F[2 * k] = 0.0;
        F[2 * k + 1] = -1.0;
    }
    scene_make(&s, 2, NP, L, r, x, F, "cg");
    CHECK_OK(odhs_stepper_run_until_time(s.st, 2.0));
    CHECK_OK(odhs_stepper_feature_work(s.st, ODHS_FEATURE_WALLS, &w));
    ck_assert_uint_eq(w, 0);
    scene_free(&s);
}
END_TEST

Suite *make_walls_suite(void)
{
    Suite *s = suite_create("walls");
    TCase *tc = tcase_create("walls");
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_plane_landing);
    tcase_add_test(tc, test_gravity_column);
    tcase_add_test(tc, test_segment_slide);
    tcase_add_test(tc, test_circle_container);
    tcase_add_test(tc, test_piston);
    tcase_add_test(tc, test_piston_solvers_agree);
    tcase_add_test(tc, test_walls_checkpoint);
    tcase_add_test(tc, test_wall_contact_kind);
    tcase_add_test(tc, test_wall_errors);
    tcase_add_test(tc, test_walls_feature_cost);
    suite_add_tcase(s, tc);
    return s;
}
