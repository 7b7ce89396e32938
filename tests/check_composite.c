/*
 * libodhs - Check suite "composite": permanent contacts (bonds), rigid bodies
 * and chains (Sect. V C of Lerner, During & Wyart 2013).
 *
 *  - a rigid dimer in simple shear rotates as cot(theta) = cot(theta0) +
 *    gammadot t (its bond removes the extensional part of the affine flow),
 *    with the bond force -gammadot l sin(theta) cos(theta) / (2 xi0), negative
 *    (tension) in the extensional quadrant;
 *  - trimers (Fig. 9) sheared to a strain of 1 keep every bond length to 1e-12,
 *    never overlap, temporary forces stay >= 0, and power equals dissipation;
 *  - the body-level constrained subset on hand-built networks (2D and 3D);
 *  - rigid-body bond sets: 2k-3 in 2D, 3k-6 in 3D, collinear beads refused;
 *    touching beads of one body never become contacts;
 *  - checkpoints restore bonds and bodies: bit-identical continuation.
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

#define CHECK_OK(expr)                                                              \
    do {                                                                            \
        int rc_ = (expr);                                                           \
        ck_assert_msg(rc_ == ODHS_OK, "%s returned %d (%s)", #expr, rc_, odhs_strerror(rc_)); \
    } while (0)

typedef struct {
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
} scene;

static void scene_free(scene *s)
{
    odhs_stepper_destroy(s->st);
    odhs_solver_destroy(s->sol);
    odhs_driver_destroy(s->drv);
    odhs_system_destroy(s->sys);
    memset(s, 0, sizeof *s);
}

static void scene_make(scene *s, int dim, size_t n, const double *L, const double *r, const double *x,
                       double gdot, const char *solver)
{
    memset(s, 0, sizeof *s);
    CHECK_OK(odhs_system_create(dim, n, &s->sys));
    CHECK_OK(odhs_system_set_configuration(s->sys, L, 0.0, r, x));
    CHECK_OK(odhs_driver_create(&s->drv));
    CHECK_OK(odhs_driver_set_shear_rate(s->drv, gdot));
    CHECK_OK(odhs_solver_create_by_name(solver, &s->sol));
    CHECK_OK(odhs_stepper_create(s->sys, s->drv, s->sol, &s->st));
}

static double bead_distance(const odhs_system *sys, size_t i, size_t j)
{
    double d[3];
    CHECK_OK(odhs_system_separation(sys, i, j, d, NULL, NULL));
    return sqrt(d[0] * d[0] + d[1] * d[1] + (odhs_system_dim(sys) == 3 ? d[2] * d[2] : 0.0));
}

/* ---- a rigid dimer in simple shear ---------------------------------------- */
START_TEST(test_dimer_jeffery)
{
    const double l = 1.0, th0 = 0.3, gdot = 0.7;
    double L[2] = {20.0, 20.0}, r[2] = {0.5, 0.5};
    double x[4] = {10.0, 10.0, 10.0 + l * cos(th0), 10.0 + l * sin(th0)};
    scene s;
    scene_make(&s, 2, 2, L, r, x, gdot, "dense");
    CHECK_OK(odhs_stepper_add_bond(s.st, 0, 1, 0.0));
    size_t nb = 0;
    CHECK_OK(odhs_stepper_bond_count(s.st, &nb));
    ck_assert_uint_eq(nb, 1);
    CHECK_OK(odhs_stepper_reset(s.st));
    /* bond force at theta0: -gdot l sin cos / (2 xi0): tension */
    double f;
    const odhs_network *net = odhs_stepper_network(s.st);
    ck_assert_uint_eq(odhs_network_count(net), 1);
    CHECK_OK(odhs_network_get_forces(net, &f));
    double fexp = -gdot * l * sin(th0) * cos(th0) / 2.0;
    ck_assert_msg(fabs(f - fexp) < 1e-14 * fabs(fexp), "bond force %.17g, expected %.17g", f, fexp);
    ck_assert(f < 0.0);
    /* rotation: cot(theta) = cot(theta0) + strain; adaptive Heun at a tight
     * tolerance, drift correction every step */
    CHECK_OK(odhs_stepper_set_integrator(s.st, ODHS_INTEGRATOR_HEUN));
    CHECK_OK(odhs_stepper_set_tolerance(s.st, 1e-11));
    CHECK_OK(odhs_stepper_set_dt(s.st, 1e-2));
    CHECK_OK(odhs_stepper_set_correction_interval(s.st, 1));
    const double strains[] = {0.5, 1.0, 2.0, 4.0};
    double worst = 0.0;
    for (size_t k = 0; k < sizeof strains / sizeof strains[0]; ++k) {
        CHECK_OK(odhs_stepper_run_until_strain(s.st, strains[k]));
        double d[3];
        CHECK_OK(odhs_system_separation(s.sys, 0, 1, d, NULL, NULL));
        double th = atan2(d[1], d[0]);
        double th_exp = atan2(1.0, 1.0 / tan(th0) + strains[k]);
        worst = fmax(worst, fabs(th - th_exp));
        ck_assert_msg(fabs(hypot(d[0], d[1]) - l) < 1e-13, "bond length %.17g", hypot(d[0], d[1]));
        /* the force follows the angle */
        CHECK_OK(odhs_network_get_forces(odhs_stepper_network(s.st), &f));
        double fe = -gdot * l * sin(th) * cos(th) / 2.0;
        ck_assert_msg(fabs(f - fe) < 1e-9 * gdot * l, "strain %g: force %.17g expected %.17g", strains[k], f, fe);
    }
    ck_assert_msg(worst < 1e-9, "angle error %.3g against the analytic rotation", worst);
    fprintf(stderr, "[composite] dimer in shear: worst angle error %.2e rad over strain 4\n", worst);
    scene_free(&s);
}
END_TEST

/* ---- trimers under shear (Fig. 9) ------------------------------------------ */
#define NT_X 5
#define NT_Y 6
#define NTRI (NT_X * NT_Y)

/* equal touching beads (radius a) at the corners of a triangle centred at c,
 * rotated by phi; half the trimers are 1.2 times larger */
static void trimer_scene(scene *s, const char *solver, uint64_t seed)
{
    size_t n = 3 * NTRI;
    /* staggered rows: neighbours 2.64 apart, more than the largest pair of
     * enclosing radii (2.59), so no overlap at any orientation */
    double spx = 2.6, spy = 2.3;
    double L[2] = {NT_X * spx, NT_Y * spy};
    double *r = malloc(n * sizeof *r), *x = malloc(2 * n * sizeof *x);
    tu_rng rng;
    tu_rng_seed(&rng, seed);
    for (size_t t = 0; t < NTRI; ++t) {
        double a = (t % 2) ? 0.5 : 0.6, R = 2.0 * a / sqrt(3.0);
        size_t row = t / NT_X;
        double cx = ((double)(t % NT_X) + 0.5 * (double)(row % 2) + 0.25) * spx, cy = ((double)row + 0.5) * spy;
        double phi = 2.0 * TU_PI * tu_uniform(&rng);
        for (int b = 0; b < 3; ++b) {
            r[3 * t + b] = a;
            x[2 * (3 * t + b)] = cx + R * cos(phi + 2.0 * TU_PI * b / 3.0);
            x[2 * (3 * t + b) + 1] = cy + R * sin(phi + 2.0 * TU_PI * b / 3.0);
        }
    }
    scene_make(s, 2, n, L, r, x, 1.0, solver);
    for (size_t t = 0; t < NTRI; ++t) {
        size_t beads[3] = {3 * t, 3 * t + 1, 3 * t + 2};
        CHECK_OK(odhs_stepper_add_rigid_body(s->st, 3, beads));
    }
    /* compress the sheared suspension from phi = 0.48 to 0.70: many
     * collisions, then shear at fixed volume */
    CHECK_OK(odhs_driver_set_compression_rate(s->drv, 0.5));
    CHECK_OK(odhs_stepper_run_until_packing_fraction(s->st, 0.70));
    CHECK_OK(odhs_driver_set_compression_rate(s->drv, 0.0));
    free(r);
    free(x);
}

typedef struct {
    const odhs_stepper *st;
    double worst_bond, worst_overlap, worst_neg, worst_power;
    size_t events;
} tri_watch;

static void tri_check(tri_watch *w)
{
    const odhs_network *net = odhs_stepper_network(w->st);
    size_t nc = odhs_network_count(net);
    double *f = malloc((nc + 1) * sizeof *f), *g = malloc((nc + 1) * sizeof *g);
    CHECK_OK(odhs_network_get_forces(net, f));
    CHECK_OK(odhs_network_get_gaps(net, g));
    double fbig = 0.0;
    for (size_t c = 0; c < nc; ++c) fbig = fmax(fbig, fabs(f[c]));
    for (size_t c = 0; c < nc; ++c) {
        int kind;
        size_t i, j;
        CHECK_OK(odhs_network_get_contact(net, c, &i, &j, &kind));
        if (kind == ODHS_CONTACT_PERMANENT) {
            ck_assert_msg(i / 3 == j / 3, "bond (%zu,%zu) joins two trimers", i, j);
            w->worst_bond = fmax(w->worst_bond, fabs(g[c]));
        } else {
            ck_assert_msg(i / 3 != j / 3, "temporary contact inside trimer %zu", i / 3);
            w->worst_neg = fmax(w->worst_neg, -f[c] / fbig);
        }
    }
    double ov, P, D;
    CHECK_OK(odhs_stepper_errors(w->st, NULL, &ov));
    w->worst_overlap = fmax(w->worst_overlap, ov);
    CHECK_OK(odhs_stepper_power(w->st, &P));
    CHECK_OK(odhs_stepper_dissipation(w->st, &D));
    w->worst_power = fmax(w->worst_power, fabs(P - D) / fmax(fabs(D), 1e-300));
    free(f);
    free(g);
}

START_TEST(test_trimers_shear)
{
    scene s;
    trimer_scene(&s, "cg", 11);
    size_t nb;
    CHECK_OK(odhs_stepper_bond_count(s.st, &nb));
    ck_assert_uint_eq(nb, 3 * NTRI);
    CHECK_OK(odhs_stepper_set_dt(s.st, 2e-3));
    CHECK_OK(odhs_stepper_set_correction_interval(s.st, 1));
    tri_watch w = {s.st, 0, 0, 0, 0, 0};
    CHECK_OK(odhs_stepper_reset(s.st));
    double strain = 0.0;
    uint64_t steps = 0;
    while (strain < 1.0) {
        odhs_event ev;
        CHECK_OK(odhs_stepper_step(s.st, &ev));
        CHECK_OK(odhs_stepper_strain(s.st, &strain));
        tri_check(&w);
        steps++;
    }
    uint64_t nst, ncoll, nopen;
    CHECK_OK(odhs_stepper_counts(s.st, &nst, &ncoll, &nopen));
    fprintf(stderr,
            "[composite] %d trimers to strain 1: %llu steps, %llu collisions, %llu openings; worst bond-length "
            "error %.2e, overlap %.2e, negative contact force %.2e, |P-D|/D %.2e\n",
            NTRI, (unsigned long long)nst, (unsigned long long)ncoll, (unsigned long long)nopen, w.worst_bond,
            w.worst_overlap, w.worst_neg, w.worst_power);
    ck_assert_msg(ncoll > 50, "only %llu collisions: the test does not exercise contacts", (unsigned long long)ncoll);
    ck_assert_msg(w.worst_bond < 1e-12, "bond length drifted by %.3g", w.worst_bond);
    ck_assert_msg(w.worst_overlap < 1e-12, "overlap %.3g", w.worst_overlap);
    ck_assert_msg(w.worst_neg < 1e-9, "negative temporary force %.3g", w.worst_neg);
    ck_assert_msg(w.worst_power < 1e-9, "power balance %.3g", w.worst_power);
    /* the shape of every trimer: all three internal distances = 2a */
    double r[3 * NTRI];
    CHECK_OK(odhs_system_get_radii(s.sys, r));
    for (size_t t = 0; t < NTRI; ++t)
        for (int a = 0; a < 3; ++a)
            for (int b = a + 1; b < 3; ++b) {
                double dd = bead_distance(s.sys, 3 * t + a, 3 * t + b);
                ck_assert_msg(fabs(dd - 2.0 * r[3 * t]) < 1e-12, "trimer %zu: distance %.17g", t, dd);
            }
    scene_free(&s);
}
END_TEST

/* the same trajectory with the dense solver (an independent route) */
START_TEST(test_trimers_solvers_agree)
{
    scene a, b;
    trimer_scene(&a, "cg", 5);
    trimer_scene(&b, "dense", 5);
    CHECK_OK(odhs_stepper_run_until_strain(a.st, 0.2));
    CHECK_OK(odhs_stepper_run_until_strain(b.st, 0.2));
    size_t n = 3 * NTRI;
    double *xa = malloc(2 * n * sizeof *xa), *xb = malloc(2 * n * sizeof *xb);
    CHECK_OK(odhs_system_get_positions(a.sys, xa));
    CHECK_OK(odhs_system_get_positions(b.sys, xb));
    double worst = 0.0;
    for (size_t k = 0; k < 2 * n; ++k) worst = fmax(worst, fabs(xa[k] - xb[k]));
    ck_assert_msg(worst < 1e-8, "cg and dense trimer trajectories differ by %.3g", worst);
    uint64_t ca, cb;
    CHECK_OK(odhs_stepper_counts(a.st, NULL, &ca, NULL));
    CHECK_OK(odhs_stepper_counts(b.st, NULL, &cb, NULL));
    ck_assert_uint_eq(ca, cb);
    free(xa);
    free(xb);
    scene_free(&a);
    scene_free(&b);
}
END_TEST

/* ---- the constrained subset on bodies --------------------------------------- */
/* particles base..base+m-1 all connected to each other (a rigid clique) */
static void clique(odhs_network *net, size_t base, size_t m)
{
    for (size_t a = base; a < base + m; ++a)
        for (size_t b = a + 1; b < base + m; ++b) CHECK_OK(odhs_network_add(net, a, b, ODHS_CONTACT_TEMPORARY));
}

START_TEST(test_body_core_2d)
{
    odhs_system *sys;
    CHECK_OK(odhs_system_create(2, 9, &sys));
    odhs_network *net;
    CHECK_OK(odhs_network_create(sys, &net));
    clique(net, 3, 6); /* 3..8: 15 contacts, degree 5 each */
    /* dimer 0-1 with three contacts to the clique: 3 dof need 4 contacts */
    CHECK_OK(odhs_network_add(net, 0, 1, ODHS_CONTACT_PERMANENT));
    CHECK_OK(odhs_network_add(net, 0, 3, ODHS_CONTACT_TEMPORARY));
    CHECK_OK(odhs_network_add(net, 0, 4, ODHS_CONTACT_TEMPORARY));
    CHECK_OK(odhs_network_add(net, 1, 5, ODHS_CONTACT_TEMPORARY));
    size_t nbar, ncon;
    unsigned char in[9];
    CHECK_OK(odhs_network_constrained(net, &nbar, &ncon, in, NULL));
    ck_assert_uint_eq(nbar, 6);
    ck_assert_uint_eq(ncon, 15);
    ck_assert(!in[0] && !in[1] && !in[2] && in[3]);
    /* (a particle-level (d+1)-core would keep bead 0: two contacts + bond) */
    CHECK_OK(odhs_network_add(net, 1, 6, ODHS_CONTACT_TEMPORARY));
    CHECK_OK(odhs_network_constrained(net, &nbar, &ncon, in, NULL));
    ck_assert_uint_eq(nbar, 8);
    ck_assert_uint_eq(ncon, 15 + 4 + 1);
    ck_assert(in[0] && in[1] && !in[2]);
    size_t nr;
    CHECK_OK(odhs_network_rattlers(net, NULL, &nr));
    ck_assert_uint_eq(nr, 1);
    /* removing the bond: bead 0 and 1 are discs again, 2 contacts each */
    CHECK_OK(odhs_network_remove(net, 0, 1));
    CHECK_OK(odhs_network_constrained(net, &nbar, &ncon, in, NULL));
    ck_assert_uint_eq(nbar, 6);
    /* a trimer 0,1,2 (triangle: dof 3) with 4 contacts spread over its beads */
    CHECK_OK(odhs_network_add(net, 0, 1, ODHS_CONTACT_PERMANENT));
    CHECK_OK(odhs_network_add(net, 1, 2, ODHS_CONTACT_PERMANENT));
    CHECK_OK(odhs_network_add(net, 0, 2, ODHS_CONTACT_PERMANENT));
    CHECK_OK(odhs_network_constrained(net, &nbar, &ncon, in, NULL));
    ck_assert_uint_eq(nbar, 9);
    ck_assert_uint_eq(ncon, 15 + 4 + 3);
    int pj;
    CHECK_OK(odhs_network_potentially_jammed(net, &pj));
    ck_assert_int_eq(pj, 22 >= 2 * (9 - 1) + 1); /* 22 >= 17 */
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

START_TEST(test_body_core_3d)
{
    odhs_system *sys;
    CHECK_OK(odhs_system_create(3, 10, &sys));
    odhs_network *net;
    CHECK_OK(odhs_network_create(sys, &net));
    clique(net, 2, 8);
    /* 3D dimer: 5 dof, needs 6 contacts */
    CHECK_OK(odhs_network_add(net, 0, 1, ODHS_CONTACT_PERMANENT));
    for (size_t k = 0; k < 5; ++k) CHECK_OK(odhs_network_add(net, k % 2, 2 + k, ODHS_CONTACT_TEMPORARY));
    size_t nbar, ncon;
    CHECK_OK(odhs_network_constrained(net, &nbar, &ncon, NULL, NULL));
    ck_assert_uint_eq(nbar, 8);
    ck_assert_uint_eq(ncon, 28);
    CHECK_OK(odhs_network_add(net, 1, 9, ODHS_CONTACT_TEMPORARY));
    CHECK_OK(odhs_network_constrained(net, &nbar, &ncon, NULL, NULL));
    ck_assert_uint_eq(nbar, 10);
    ck_assert_uint_eq(ncon, 28 + 6 + 1);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* ---- rigid-body bond sets ----------------------------------------------------- */
START_TEST(test_rigid_body_bonds)
{
    /* 2D: a flower of 7 touching beads (hexagon + centre): 12 touching
     * pairs, 2k-3 = 11 bonds; the 12th pair must never become a contact */
    double L[2] = {30.0, 30.0}, r[7], x[14];
    for (int k = 0; k < 7; ++k) r[k] = 0.5;
    x[0] = 15.0;
    x[1] = 15.0;
    for (int k = 0; k < 6; ++k) {
        x[2 + 2 * k] = 15.0 + cos(TU_PI * k / 3.0);
        x[3 + 2 * k] = 15.0 + sin(TU_PI * k / 3.0);
    }
    scene s;
    scene_make(&s, 2, 7, L, r, x, 1.0, "dense");
    size_t beads[7] = {0, 1, 2, 3, 4, 5, 6};
    CHECK_OK(odhs_stepper_add_rigid_body(s.st, 7, beads));
    size_t nb;
    CHECK_OK(odhs_stepper_bond_count(s.st, &nb));
    ck_assert_uint_eq(nb, 11);
    CHECK_OK(odhs_stepper_reset(s.st));
    ck_assert_uint_eq(odhs_network_count(odhs_stepper_network(s.st)), 11);
    /* rotate it by shearing: every one of the 21 distances holds */
    double d0[7][7];
    for (int a = 0; a < 7; ++a)
        for (int b = 0; b < 7; ++b) d0[a][b] = a == b ? 0.0 : bead_distance(s.sys, (size_t)a, (size_t)b);
    CHECK_OK(odhs_stepper_set_correction_interval(s.st, 1));
    CHECK_OK(odhs_stepper_run_until_strain(s.st, 3.0));
    double worst = 0.0;
    for (int a = 0; a < 7; ++a)
        for (int b = a + 1; b < 7; ++b) worst = fmax(worst, fabs(bead_distance(s.sys, (size_t)a, (size_t)b) - d0[a][b]));
    ck_assert_msg(worst < 1e-12, "flower distance changed by %.3g", worst);
    uint64_t coll;
    CHECK_OK(odhs_stepper_counts(s.st, NULL, &coll, NULL));
    ck_assert_uint_eq(coll, 0);
    /* a bead of a body cannot join a second one; errors leave no bond */
    size_t two[2] = {0, 1};
    ck_assert_int_eq(odhs_stepper_add_rigid_body(s.st, 2, two), ODHS_E_INVALID);
    CHECK_OK(odhs_stepper_bond_count(s.st, &nb));
    ck_assert_uint_eq(nb, 11);
    scene_free(&s);

    /* collinear beads: refused, nothing added */
    double xl[6] = {10, 10, 11, 10, 12, 10}, rl[3] = {0.5, 0.5, 0.5};
    scene_make(&s, 2, 3, L, rl, xl, 1.0, "dense");
    size_t three[3] = {0, 1, 2};
    ck_assert_int_eq(odhs_stepper_add_rigid_body(s.st, 3, three), ODHS_E_INVALID);
    CHECK_OK(odhs_stepper_bond_count(s.st, &nb));
    ck_assert_uint_eq(nb, 0);
    ck_assert_uint_eq(odhs_network_count(odhs_stepper_network(s.st)), 0);
    /* ... but a chain of them is fine */
    CHECK_OK(odhs_stepper_add_chain(s.st, 3, three));
    CHECK_OK(odhs_stepper_bond_count(s.st, &nb));
    ck_assert_uint_eq(nb, 2);
    scene_free(&s);

    /* 3D: tetrahedron (6 bonds) and a triangular bipyramid (3k-6 = 9) */
    double L3[3] = {20, 20, 20}, r3[5] = {0.5, 0.5, 0.5, 0.5, 0.5};
    double h = sqrt(2.0 / 3.0);
    double x3[15] = {10, 10, 10, 11, 10, 10, 10.5, 10 + sqrt(3.0) / 2, 10, 10.5, 10 + sqrt(3.0) / 6, 10 + h,
                     10.5, 10 + sqrt(3.0) / 6, 10 - h};
    scene_make(&s, 3, 5, L3, r3, x3, 1.0, "dense");
    size_t five[5] = {0, 1, 2, 3, 4};
    CHECK_OK(odhs_stepper_add_rigid_body(s.st, 5, five));
    CHECK_OK(odhs_stepper_bond_count(s.st, &nb));
    ck_assert_uint_eq(nb, 9);
    double d34 = bead_distance(s.sys, 3, 4);
    CHECK_OK(odhs_stepper_set_correction_interval(s.st, 1));
    CHECK_OK(odhs_stepper_run_until_strain(s.st, 2.0));
    ck_assert_msg(fabs(bead_distance(s.sys, 3, 4) - d34) < 1e-12, "unbonded distance 3-4 changed by %.3g",
                  fabs(bead_distance(s.sys, 3, 4) - d34));
    scene_free(&s);
}
END_TEST

/* bonds with a rest length: beads standing apart (a bent "rod" of 3 beads) */
START_TEST(test_bond_rest_length)
{
    double L[2] = {20.0, 20.0}, r[3] = {0.5, 0.5, 0.5};
    double x[6] = {10.0, 10.0, 11.2, 10.0, 12.2, 10.75};
    scene s;
    scene_make(&s, 2, 3, L, r, x, 1.0, "dense");
    size_t three[3] = {0, 1, 2};
    CHECK_OK(odhs_stepper_add_rigid_body(s.st, 3, three));
    CHECK_OK(odhs_stepper_set_correction_interval(s.st, 1));
    CHECK_OK(odhs_stepper_run_until_strain(s.st, 1.0));
    double ov;
    CHECK_OK(odhs_stepper_errors(s.st, NULL, &ov));
    ck_assert_msg(ov == 0.0, "beads of one body reported as overlapping (%g)", ov);
    ck_assert_msg(fabs(bead_distance(s.sys, 0, 1) - 1.2) < 1e-12, "rest length not kept");
    /* network-level rest length query */
    const odhs_network *net = odhs_stepper_network(s.st);
    size_t k;
    CHECK_OK(odhs_network_find(net, 0, 1, &k));
    double rest;
    CHECK_OK(odhs_network_get_rest_length(net, s.sys, k, &rest));
    ck_assert_msg(fabs(rest - 1.2) < 1e-14, "rest %.17g", rest);
    /* an explicit rest length far from the distance is refused */
    ck_assert_int_eq(odhs_stepper_add_bond(s.st, 0, 2, 5.0), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_stepper_add_bond(s.st, 0, 1, 0.0), ODHS_E_INVALID); /* already bonded */
    scene_free(&s);
}
END_TEST

/* ---- checkpoints carry bonds and bodies -------------------------------------- */
START_TEST(test_composite_checkpoint)
{
    scene a;
    trimer_scene(&a, "cg", 3);
    CHECK_OK(odhs_stepper_run_events(a.st, 40));
    char path[] = "/tmp/odhs_composite_ckpt_XXXXXX";
    int fd = mkstemp(path);
    ck_assert(fd >= 0);
    close(fd);
    CHECK_OK(odhs_checkpoint_write(a.st, path));
    CHECK_OK(odhs_stepper_run_events(a.st, 60));
    odhs_solver *sol;
    odhs_system *sys;
    odhs_driver *drv;
    odhs_stepper *st;
    char err[256];
    CHECK_OK(odhs_solver_create_by_name("cg", &sol));
    CHECK_OK(odhs_checkpoint_read(path, sol, &sys, &drv, &st, err, sizeof err));
    size_t nb;
    CHECK_OK(odhs_stepper_bond_count(st, &nb));
    ck_assert_uint_eq(nb, 3 * NTRI);
    CHECK_OK(odhs_stepper_run_events(st, 60));
    size_t n = 3 * NTRI;
    double *xa = malloc(2 * n * sizeof *xa), *xb = malloc(2 * n * sizeof *xb);
    CHECK_OK(odhs_system_get_positions(a.sys, xa));
    CHECK_OK(odhs_system_get_positions(sys, xb));
    ck_assert_msg(!memcmp(xa, xb, 2 * n * sizeof *xa), "continuation from the checkpoint is not bit-identical");
    /* the rigid bodies came back: a bead cannot join another body */
    size_t two[2] = {0, 1};
    ck_assert_int_eq(odhs_stepper_add_rigid_body(st, 2, two), ODHS_E_INVALID);
    free(xa);
    free(xb);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    odhs_solver_destroy(sol);
    scene_free(&a);
    remove(path);
}
END_TEST

/* ---- a scene pays only for what it uses ------------------------------------- */
START_TEST(test_feature_cost)
{
    /* a plain periodic shear scene: no pressure, no composite code runs */
    odhs_system *sys;
    CHECK_OK(odhs_system_create(2, 64, &sys));
    CHECK_OK(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.0, 3));
    CHECK_OK(odhs_system_place_random(sys, 0.5, 4));
    scene s;
    memset(&s, 0, sizeof s);
    s.sys = sys;
    CHECK_OK(odhs_driver_create(&s.drv));
    CHECK_OK(odhs_driver_set_compression_rate(s.drv, 1.0));
    CHECK_OK(odhs_solver_create_by_name("cg", &s.sol));
    CHECK_OK(odhs_stepper_create(s.sys, s.drv, s.sol, &s.st));
    CHECK_OK(odhs_stepper_run_until_packing_fraction(s.st, 0.78));
    CHECK_OK(odhs_driver_set_compression_rate(s.drv, 0.0));
    CHECK_OK(odhs_driver_set_shear_rate(s.drv, 1.0));
    CHECK_OK(odhs_stepper_run_until_strain(s.st, 0.1));
    uint64_t ev, wp, wc;
    CHECK_OK(odhs_stepper_counts(s.st, NULL, &ev, NULL));
    ck_assert(ev > 100);
    CHECK_OK(odhs_stepper_feature_work(s.st, ODHS_FEATURE_PRESSURE, &wp));
    CHECK_OK(odhs_stepper_feature_work(s.st, ODHS_FEATURE_COMPOSITE, &wc));
    ck_assert_msg(wp == 0 && wc == 0, "plain shear ran pressure code %llu times, composite code %llu times",
                  (unsigned long long)wp, (unsigned long long)wc);
    /* the same scene at fixed pressure runs the pressure code, not the composite one */
    CHECK_OK(odhs_driver_set_pressure(s.drv, 1.0));
    CHECK_OK(odhs_stepper_run_until_strain(s.st, 0.15));
    CHECK_OK(odhs_stepper_feature_work(s.st, ODHS_FEATURE_PRESSURE, &wp));
    CHECK_OK(odhs_stepper_feature_work(s.st, ODHS_FEATURE_COMPOSITE, &wc));
    ck_assert(wp > 0 && wc == 0);
    scene_free(&s);
    /* trimers run the composite code, not the pressure code */
    trimer_scene(&s, "cg", 2);
    CHECK_OK(odhs_stepper_run_until_strain(s.st, 0.05));
    CHECK_OK(odhs_stepper_feature_work(s.st, ODHS_FEATURE_PRESSURE, &wp));
    CHECK_OK(odhs_stepper_feature_work(s.st, ODHS_FEATURE_COMPOSITE, &wc));
    ck_assert(wp == 0 && wc > 0);
    fprintf(stderr, "[composite] feature work: plain shear 0/0, trimers composite passes %llu\n",
            (unsigned long long)wc);
    scene_free(&s);
}
END_TEST

Suite *make_composite_suite(void)
{
    Suite *s = suite_create("composite");
    TCase *tc = tcase_create("bonds");
    tcase_set_timeout(tc, 120);
    tcase_add_test(tc, test_dimer_jeffery);
    tcase_add_test(tc, test_body_core_2d);
    tcase_add_test(tc, test_body_core_3d);
    tcase_add_test(tc, test_rigid_body_bonds);
    tcase_add_test(tc, test_bond_rest_length);
    suite_add_tcase(s, tc);
    TCase *tr = tcase_create("trimers");
    tcase_set_timeout(tr, 300);
    tcase_add_test(tr, test_trimers_shear);
    tcase_add_test(tr, test_trimers_solvers_agree);
    tcase_add_test(tr, test_composite_checkpoint);
    tcase_add_test(tr, test_feature_cost);
    suite_add_tcase(s, tr);
    return s;
}
