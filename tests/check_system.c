/*
 * libodhs - tests of the system handle (system.h, common.h): status codes,
 * version, creation, validation errors, Lees-Edwards minimum image and
 * wrapping, neighbour search against brute force, scene builders, clone.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <check.h>
#include <float.h>
#include <limits.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "testutil.h"

/* ------------------------------------------------------------------------ */
/* helpers                                                                   */
/* ------------------------------------------------------------------------ */

static odhs_system *new_sys(int dim, size_t n)
{
    odhs_system *s = NULL;
    int st = odhs_system_create(dim, n, &s);
    ck_assert_msg(st == ODHS_OK, "odhs_system_create(%d, %zu) = %d", dim, n, st);
    ck_assert_ptr_nonnull(s);
    return s;
}

static double min_edge(int dim, const double *L)
{
    double m = L[0] < L[1] ? L[0] : L[1];
    if (dim == 3 && L[2] < m) m = L[2];
    return m;
}

/* A call that must fail with `code`, record a message and leave `sys` exactly
 * as it was (box, strain, radii, positions, species, readiness, bit for bit). */
#define EXPECT_FAIL(sys, code, call)                                                          \
    do {                                                                                      \
        tu_snapshot snap_;                                                                    \
        tu_snapshot_take((sys), &snap_);                                                      \
        int st_ = (call);                                                                     \
        ck_assert_msg(st_ == (code), "%s returned %d (%s), expected %d (%s)", #call, st_,    \
                      odhs_strerror(st_), (int)(code), odhs_strerror(code));                  \
        ck_assert_msg(odhs_system_errmsg(sys) != NULL && odhs_system_errmsg(sys)[0] != '\0', \
                      "%s: empty error message", #call);                                      \
        ck_assert_msg(tu_snapshot_matches((sys), &snap_), "%s changed the handle", #call);   \
        tu_snapshot_free(&snap_);                                                             \
    } while (0)

/* Random non-overlapping polydisperse system: radii log-uniform in
 * [rmin, rmax] (r[0] = rmax, r[1] = rmin), positions by RSA under strain. */
static odhs_system *make_random_system(int dim, size_t n, const double *L, double gamma, double rmin,
                                       double rmax, uint64_t seed)
{
    tu_rng rng;
    tu_rng_seed(&rng, seed);
    double *r = malloc(n * sizeof *r);
    double *x = malloc(n * (size_t)dim * sizeof *x);
    ck_assert(r && x);
    tu_radii_loguniform(n, rmin, rmax, r, &rng);
    ck_assert_msg(tu_random_config(dim, n, L, gamma, r, 0.0, x, &rng),
                  "test scene generator could not place %zu particles", n);
    odhs_system *s = new_sys(dim, n);
    int st = odhs_system_set_configuration(s, L, gamma, r, x);
    ck_assert_msg(st == ODHS_OK, "set_configuration of a generated scene: %d (%s)", st,
                  odhs_system_errmsg(s));
    free(r);
    free(x);
    return s;
}

/* get positions/radii/box/strain into fresh arrays */
typedef struct {
    int dim;
    size_t n;
    double L[3], gamma;
    double *x, *r;
} state;

static void state_get(const odhs_system *s, state *o)
{
    o->dim = odhs_system_dim(s);
    o->n = odhs_system_count(s);
    o->L[0] = o->L[1] = o->L[2] = 1.0;
    ck_assert_int_eq(odhs_system_get_box(s, o->L), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_strain(s, &o->gamma), ODHS_OK);
    o->x = malloc(o->n * (size_t)o->dim * sizeof(double));
    o->r = malloc(o->n * sizeof(double));
    ck_assert(o->x && o->r);
    ck_assert_int_eq(odhs_system_get_positions(s, o->x), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(s, o->r), ODHS_OK);
}

static void state_free(state *o)
{
    free(o->x);
    free(o->r);
}

/* Compare odhs_system_for_each_pair at max_gap with the brute-force list
 * `all` (pairs within some larger gap, sorted), filtered to max_gap. */
static void compare_pairs_with(const odhs_system *s, const state *op, const tu_pairlist *all,
                               double max_gap, const char *what)
{
    const state o = *op;
    tu_pairlist got, want;
    tu_pairlist_init(&got, o.dim);
    int st = odhs_system_for_each_pair(s, max_gap, tu_pair_collect, &got);
    ck_assert_msg(st == ODHS_OK, "%s max_gap %g: for_each_pair = %d (%s)", what, max_gap, st,
                  odhs_system_errmsg(s));
    ck_assert(!got.alloc_failed);
    ck_assert_msg(got.bad_order == 0, "%s max_gap %g: %zu pairs reported with i >= j", what, max_gap,
                  got.bad_order);
    ck_assert_uint_eq(got.calls, got.n);
    tu_pairlist_sort(&got);
    ck_assert_msg(tu_pairlist_duplicates(&got) == 0, "%s max_gap %g: %zu pairs reported twice", what,
                  max_gap, tu_pairlist_duplicates(&got));
    tu_pairlist_init(&want, o.dim);
    for (size_t k = 0; k < all->n; ++k)
        if (all->p[k].gap <= max_gap)
            tu_pairlist_push(&want, all->p[k].i, all->p[k].j, all->p[k].rij, all->p[k].gap);
    ck_assert(!want.alloc_failed);
    size_t a = 0, b = 0;
    for (; a < got.n && b < want.n; ++a, ++b) {
        const tu_pair *p = &got.p[a], *q = &want.p[b];
        int c = tu_pair_cmp(p, q);
        if (c > 0)
            ck_abort_msg("%s max_gap %g: pair (%zu,%zu) gap %.17g missed by for_each_pair "
                         "(found %zu pairs, brute force %zu)",
                         what, max_gap, q->i, q->j, q->gap, got.n, want.n);
        if (c < 0)
            ck_abort_msg("%s max_gap %g: pair (%zu,%zu) gap %.17g reported but beyond max_gap by "
                         "brute force (found %zu pairs, brute force %zu)",
                         what, max_gap, p->i, p->j, p->gap, got.n, want.n);
        ck_assert_msg(fabs(p->gap - q->gap) <= 1e-12, "%s: pair (%zu,%zu) gap %.17g vs brute %.17g", what,
                      p->i, p->j, p->gap, q->gap);
        for (int k = 0; k < o.dim; ++k)
            ck_assert_msg(fabs(p->rij[k] - q->rij[k]) <= 1e-12,
                          "%s: pair (%zu,%zu) rij[%d] %.17g vs brute %.17g", what, p->i, p->j, k,
                          p->rij[k], q->rij[k]);
    }
    if (a < got.n)
        ck_abort_msg("%s max_gap %g: pair (%zu,%zu) gap %.17g reported but beyond max_gap by brute "
                     "force (found %zu pairs, brute force %zu)",
                     what, max_gap, got.p[a].i, got.p[a].j, got.p[a].gap, got.n, want.n);
    if (b < want.n)
        ck_abort_msg("%s max_gap %g: pair (%zu,%zu) gap %.17g missed by for_each_pair (found %zu "
                     "pairs, brute force %zu)",
                     what, max_gap, want.p[b].i, want.p[b].j, want.p[b].gap, got.n, want.n);
    ck_assert_uint_eq(got.n, want.n);
    /* the callback separation agrees with odhs_system_separation */
    for (size_t k = 0; k < got.n; k += 1 + got.n / 50) {
        double rij[3], dist;
        ck_assert_int_eq(odhs_system_separation(s, got.p[k].i, got.p[k].j, rij, &dist, NULL), ODHS_OK);
        for (int d = 0; d < o.dim; ++d) ck_assert_double_eq_tol(rij[d], got.p[k].rij[d], 1e-12);
        ck_assert_double_eq_tol(dist - (o.r[got.p[k].i] + o.r[got.p[k].j]), got.p[k].gap, 1e-12);
    }
    tu_pairlist_free(&got);
    tu_pairlist_free(&want);
}

/* Compare odhs_system_for_each_pair with brute force at each of the gaps. */
static void compare_pairs_n(const odhs_system *s, const double *gaps, int ngaps, const char *what)
{
    state o;
    state_get(s, &o);
    double gmax = 0.0;
    for (int k = 0; k < ngaps; ++k) gmax = fmax(gmax, gaps[k]);
    tu_pairlist all;
    tu_brute_pairs(o.dim, o.n, o.x, o.r, o.L, o.gamma, gmax, &all);
    ck_assert(!all.alloc_failed);
    for (int k = 0; k < ngaps; ++k) compare_pairs_with(s, &o, &all, gaps[k], what);
    tu_pairlist_free(&all);
    state_free(&o);
}

static void compare_pairs(const odhs_system *s, double max_gap, const char *what)
{
    compare_pairs_n(s, &max_gap, 1, what);
}

/* ------------------------------------------------------------------------ */
/* version and status codes                                                  */
/* ------------------------------------------------------------------------ */

START_TEST(test_version)
{
    ck_assert_int_eq(odhs_version_number(), ODHS_VERSION_NUMBER);
    ck_assert_int_eq(ODHS_VERSION_NUMBER,
                     ODHS_VERSION_MAJOR * 10000 + ODHS_VERSION_MINOR * 100 + ODHS_VERSION_PATCH);
    ck_assert_ptr_nonnull(odhs_version_string());
    ck_assert_str_eq(odhs_version_string(), ODHS_VERSION_STRING);
    char buf[64];
    snprintf(buf, sizeof buf, "%d.%d.%d", ODHS_VERSION_MAJOR, ODHS_VERSION_MINOR, ODHS_VERSION_PATCH);
    ck_assert_str_eq(ODHS_VERSION_STRING, buf);
}
END_TEST

START_TEST(test_strerror)
{
    /* the numeric values are pinned */
    ck_assert_int_eq(ODHS_OK, 0);
    ck_assert_int_eq(ODHS_STOPPED, 1);
    ck_assert_int_eq(ODHS_POTENTIALLY_JAMMED, 2);
    ck_assert_int_eq(ODHS_E_NULL, -1);
    ck_assert_int_eq(ODHS_E_INVALID, -2);
    ck_assert_int_eq(ODHS_E_NOMEM, -3);
    ck_assert_int_eq(ODHS_E_DIM, -4);
    ck_assert_int_eq(ODHS_E_RANGE, -5);
    ck_assert_int_eq(ODHS_E_NONFINITE, -6);
    ck_assert_int_eq(ODHS_E_OVERLAP, -7);
    ck_assert_int_eq(ODHS_E_BOX, -8);
    ck_assert_int_eq(ODHS_E_EMPTY, -9);
    ck_assert_int_eq(ODHS_E_IO, -10);
    ck_assert_int_eq(ODHS_E_FORMAT, -11);
    ck_assert_int_eq(ODHS_E_STATE, -12);
    ck_assert_int_eq(ODHS_E_SINGULAR, -13);
    ck_assert_int_eq(ODHS_E_NOCONV, -14);
    ck_assert_int_eq(ODHS_E_NOTINSTALLED, -15);
    ck_assert_int_eq(ODHS_E_REWIRE, -16);
    ck_assert_int_eq(ODHS_E_CALLBACK, -17);
    ck_assert_int_eq(ODHS_E_UNSUPPORTED, -18);
    ck_assert_int_eq(ODHS_E_TOODENSE, -19);
    ck_assert_int_eq(ODHS_E_INTERNAL, -20);

    const int lo = ODHS_E_INTERNAL, hi = ODHS_POTENTIALLY_JAMMED;
    const char *unknown = odhs_strerror(12345);
    ck_assert_ptr_nonnull(unknown);
    ck_assert(unknown[0] != '\0');
    for (int c = lo; c <= hi; ++c) {
        const char *s = odhs_strerror(c);
        ck_assert_msg(s != NULL && s[0] != '\0', "odhs_strerror(%d) is empty", c);
        ck_assert_msg(strcmp(s, unknown) != 0, "odhs_strerror(%d) is the unknown-code text", c);
        for (int d = lo; d < c; ++d)
            ck_assert_msg(strcmp(s, odhs_strerror(d)) != 0, "odhs_strerror(%d) == odhs_strerror(%d)", c,
                          d);
    }
    const int odd[] = {3, -21, 100, -1000, INT_MAX, INT_MIN};
    for (size_t k = 0; k < sizeof odd / sizeof odd[0]; ++k) {
        const char *s = odhs_strerror(odd[k]);
        ck_assert_ptr_nonnull(s);
        ck_assert(s[0] != '\0');
    }
}
END_TEST

/* ------------------------------------------------------------------------ */
/* creation, defaults, NULL handling, state and range errors                 */
/* ------------------------------------------------------------------------ */

START_TEST(test_create_errors)
{
    odhs_system *s = NULL;
    const int bad_dims[] = {1, 4, 0, -1, 2147483647};
    for (size_t k = 0; k < sizeof bad_dims / sizeof bad_dims[0]; ++k) {
        s = (odhs_system *)&s; /* garbage, must be overwritten with NULL */
        ck_assert_int_eq(odhs_system_create(bad_dims[k], 10, &s), ODHS_E_DIM);
        ck_assert_ptr_null(s);
    }
    s = (odhs_system *)&s;
    ck_assert_int_eq(odhs_system_create(2, 0, &s), ODHS_E_EMPTY);
    ck_assert_ptr_null(s);
    s = (odhs_system *)&s;
    ck_assert_int_eq(odhs_system_create(3, 0, &s), ODHS_E_EMPTY);
    ck_assert_ptr_null(s);
    ck_assert_int_eq(odhs_system_create(2, 10, NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_create(1, 0, NULL), ODHS_E_NULL);
    s = (odhs_system *)&s;
    ck_assert_int_eq(odhs_system_create(3, SIZE_MAX, &s), ODHS_E_NOMEM);
    ck_assert_ptr_null(s);
}
END_TEST

START_TEST(test_create_defaults)
{
    for (int dim = 2; dim <= 3; ++dim) {
        odhs_system *s = new_sys(dim, 7);
        ck_assert_int_eq(odhs_system_dim(s), dim);
        ck_assert_uint_eq(odhs_system_count(s), 7);
        ck_assert_int_eq(odhs_system_is_ready(s), 0);
        ck_assert_ptr_nonnull(odhs_system_errmsg(s));
        ck_assert_str_eq(odhs_system_errmsg(s), "");
        double L[3] = {-1, -1, -1}, g = -1, vol = -1;
        ck_assert_int_eq(odhs_system_get_box(s, L), ODHS_OK);
        for (int k = 0; k < dim; ++k) ck_assert(L[k] == 1.0);
        if (dim == 2) ck_assert(L[2] == -1.0); /* only dim entries written */
        ck_assert_int_eq(odhs_system_get_strain(s, &g), ODHS_OK);
        ck_assert(g == 0.0);
        ck_assert_int_eq(odhs_system_volume(s, &vol), ODHS_OK);
        ck_assert(vol == 1.0);
        char buf[ODHS_SPECIES_MAX + 1];
        for (size_t i = 0; i < 7; ++i) {
            ck_assert_int_eq(odhs_system_get_species(s, i, buf, sizeof buf), ODHS_OK);
            ck_assert_str_eq(buf, "A");
        }
        odhs_system_destroy(s);
    }
}
END_TEST

START_TEST(test_null_handle)
{
    double L[3] = {5, 5, 5}, r[2] = {0.1, 0.1}, x[6] = {1, 1, 1, 2, 2, 2}, v = 0;
    int img[3];
    char buf[32];
    odhs_system *c = (odhs_system *)&c;

    odhs_system_destroy(NULL); /* no-op */
    ck_assert_int_eq(odhs_system_clone(NULL, &c), ODHS_E_NULL);
    ck_assert_ptr_null(c);
    ck_assert_ptr_nonnull(odhs_system_errmsg(NULL));
    ck_assert_int_eq(odhs_system_dim(NULL), 0);
    ck_assert_uint_eq(odhs_system_count(NULL), 0);
    ck_assert_int_eq(odhs_system_is_ready(NULL), 0);
    ck_assert_int_eq(odhs_system_set_box(NULL, L), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_get_box(NULL, L), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_volume(NULL, &v), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_set_strain(NULL, 0.1), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_get_strain(NULL, &v), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_set_radii(NULL, r), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_get_radii(NULL, r), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_set_positions(NULL, x), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_get_positions(NULL, x), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_set_configuration(NULL, L, 0.0, r, x), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_set_species(NULL, 0, "B"), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_get_species(NULL, 0, buf, sizeof buf), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_scale_box(NULL, 1.1), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_packing_fraction(NULL, &v), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_separation(NULL, 0, 1, x, &v, img), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_validate(NULL, 0.0), ODHS_E_NULL);
    tu_pairlist pl;
    tu_pairlist_init(&pl, 3);
    ck_assert_int_eq(odhs_system_for_each_pair(NULL, 0.1, tu_pair_collect, &pl), ODHS_E_NULL);
    ck_assert_uint_eq(pl.calls, 0);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(NULL, 0.5, 1.4, 0.0, 1), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_place_random(NULL, 0.3, 1), ODHS_E_NULL);
    /* argument errors come after the handle check */
    ck_assert_int_eq(odhs_system_set_strain(NULL, NAN), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_scale_box(NULL, -1.0), ODHS_E_NULL);
    ck_assert_int_eq(odhs_system_set_box(NULL, NULL), ODHS_E_NULL);
}
END_TEST

START_TEST(test_null_arguments)
{
    odhs_system *s = new_sys(3, 2);
    const double L[3] = {5, 5, 5}, r[2] = {0.1, 0.2}, x[6] = {1, 1, 1, 2, 2, 2};
    ck_assert_int_eq(odhs_system_set_configuration(s, L, 0.1, r, x), ODHS_OK);
    double v;
    char buf[32];
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_set_box(s, NULL));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_get_box(s, NULL));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_volume(s, NULL));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_get_strain(s, NULL));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_set_radii(s, NULL));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_get_radii(s, NULL));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_set_positions(s, NULL));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_get_positions(s, NULL));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_set_configuration(s, NULL, 0.0, r, x));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_set_configuration(s, L, 0.0, NULL, x));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_set_configuration(s, L, 0.0, r, NULL));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_set_species(s, 0, NULL));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_get_species(s, 0, NULL, 16));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_packing_fraction(s, NULL));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_separation(s, 0, 1, NULL, &v, NULL));
    EXPECT_FAIL(s, ODHS_E_NULL, odhs_system_for_each_pair(s, 0.1, NULL, NULL));
    ck_assert_int_eq(odhs_system_clone(s, NULL), ODHS_E_NULL);
    /* optional outputs may be NULL */
    double rij[3];
    ck_assert_int_eq(odhs_system_separation(s, 0, 1, rij, NULL, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_species(s, 1, buf, sizeof buf), ODHS_OK);
    odhs_system_destroy(s);
}
END_TEST

START_TEST(test_state_errors)
{
    double L[2] = {10, 10}, r[4] = {0.5, 0.5, 0.5, 0.5}, x[8] = {1, 1, 3, 1, 1, 3, 3, 3};
    double buf[8], v, rij[2];
    tu_pairlist pl;
    tu_pairlist_init(&pl, 2);

    odhs_system *s = new_sys(2, 4);
    ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_get_radii(s, buf));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_get_positions(s, buf));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_packing_fraction(s, &v));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_separation(s, 0, 1, rij, &v, NULL));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_validate(s, 0.0));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_for_each_pair(s, 0.0, tu_pair_collect, &pl));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_place_random(s, 0.3, 1));
    ck_assert_uint_eq(pl.calls, 0);

    /* radii only */
    ck_assert_int_eq(odhs_system_set_radii(s, r), ODHS_OK);
    ck_assert_int_eq(odhs_system_is_ready(s), 0);
    ck_assert_int_eq(odhs_system_get_radii(s, buf), ODHS_OK);
    ck_assert_mem_eq(buf, r, sizeof r);
    ck_assert_int_eq(odhs_system_packing_fraction(s, &v), ODHS_OK);
    ck_assert(tu_close(v, 4 * TU_PI * 0.25 / 100.0, 1e-14));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_get_positions(s, buf));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_separation(s, 0, 1, rij, &v, NULL));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_validate(s, 0.0));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_for_each_pair(s, 0.0, tu_pair_collect, &pl));
    ck_assert_uint_eq(pl.calls, 0);
    ck_assert_int_eq(odhs_system_set_positions(s, x), ODHS_OK);
    ck_assert_int_eq(odhs_system_is_ready(s), 1);
    ck_assert_int_eq(odhs_system_validate(s, 0.0), ODHS_OK);
    odhs_system_destroy(s);

    /* positions only */
    s = new_sys(2, 4);
    ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_positions(s, x), ODHS_OK);
    ck_assert_int_eq(odhs_system_is_ready(s), 0);
    ck_assert_int_eq(odhs_system_get_positions(s, buf), ODHS_OK);
    ck_assert_mem_eq(buf, x, sizeof x);
    ck_assert_int_eq(odhs_system_separation(s, 0, 3, rij, &v, NULL), ODHS_OK);
    ck_assert_double_eq_tol(rij[0], 2.0, 1e-15);
    ck_assert_double_eq_tol(rij[1], 2.0, 1e-15);
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_get_radii(s, buf));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_packing_fraction(s, &v));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_validate(s, 0.0));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_for_each_pair(s, 0.0, tu_pair_collect, &pl));
    EXPECT_FAIL(s, ODHS_E_STATE, odhs_system_place_random(s, 0.3, 1));
    ck_assert_uint_eq(pl.calls, 0);
    ck_assert_int_eq(odhs_system_set_radii(s, r), ODHS_OK);
    ck_assert_int_eq(odhs_system_is_ready(s), 1);
    odhs_system_destroy(s);
}
END_TEST

START_TEST(test_range_errors)
{
    odhs_system *s = new_sys(3, 5);
    double L[3] = {6, 6, 6}, r[5] = {0.2, 0.2, 0.2, 0.2, 0.2};
    double x[15] = {1, 1, 1, 2, 2, 2, 3, 3, 3, 4, 4, 4, 5, 5, 5};
    ck_assert_int_eq(odhs_system_set_configuration(s, L, 0.0, r, x), ODHS_OK);
    double rij[3], d;
    int img[3];
    char buf[32];
    EXPECT_FAIL(s, ODHS_E_RANGE, odhs_system_separation(s, 5, 0, rij, &d, img));
    EXPECT_FAIL(s, ODHS_E_RANGE, odhs_system_separation(s, 0, 5, rij, &d, img));
    EXPECT_FAIL(s, ODHS_E_RANGE, odhs_system_separation(s, SIZE_MAX, 1, rij, &d, img));
    EXPECT_FAIL(s, ODHS_E_RANGE, odhs_system_set_species(s, 5, "B"));
    EXPECT_FAIL(s, ODHS_E_RANGE, odhs_system_set_species(s, SIZE_MAX, "B"));
    EXPECT_FAIL(s, ODHS_E_RANGE, odhs_system_get_species(s, 5, buf, sizeof buf));
    /* the last valid index works */
    ck_assert_int_eq(odhs_system_separation(s, 4, 0, rij, &d, img), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_species(s, 4, "B"), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_species(s, 4, buf, sizeof buf), ODHS_OK);
    ck_assert_str_eq(buf, "B");
    odhs_system_destroy(s);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* minimum image and wrapping under Lees-Edwards strain                      */
/* ------------------------------------------------------------------------ */

static const double le_strains[] = {0.0, 0.3, 0.5, -0.5};
static const double le_boxes[][3] = {{2.0, 2.0, 2.0}, {3.0, 1.5, 2.2}, {1.5, 3.0, 1.8}};

/* Check every ordered pair of s against the exhaustive image search on the
 * lattice with strain gamma_lat (which may differ from the stored strain by an
 * integer: the same lattice). Returns the number of pairs closer than half the
 * shortest edge. */
static size_t check_separations(const odhs_system *s, double gamma_lat, const char *what)
{
    int dim = odhs_system_dim(s);
    size_t n = odhs_system_count(s);
    double L[3] = {1, 1, 1}, g;
    ck_assert_int_eq(odhs_system_get_box(s, L), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_strain(s, &g), ODHS_OK);
    double *x = malloc(n * (size_t)dim * sizeof *x);
    ck_assert_ptr_nonnull(x);
    ck_assert_int_eq(odhs_system_get_positions(s, x), ODHS_OK);
    double half = 0.5 * min_edge(dim, L);
    size_t close = 0;
    for (size_t i = 0; i < n; ++i)
        for (size_t j = 0; j < n; ++j) {
            double rij[3] = {0, 0, 0}, dist = -1, raw[3] = {0, 0, 0}, bf[3] = {0, 0, 0};
            int img[3] = {99, 99, 99}, bimg[3];
            int st = odhs_system_separation(s, i, j, rij, &dist, img);
            ck_assert_int_eq(st, ODHS_OK);
            for (int k = 0; k < dim; ++k) raw[k] = x[j * dim + k] - x[i * dim + k];
            /* the image reproduces rij on the current (remapped) lattice */
            double sh[3] = {0, 0, 0};
            tu_lattice_shift(dim, L, g, img, sh);
            for (int k = 0; k < dim; ++k)
                ck_assert_msg(fabs(raw[k] + sh[k] - rij[k]) <= 1e-12,
                              "%s: pair (%zu,%zu): x_j - x_i + n.lattice = %.17g != rij[%d] = %.17g "
                              "(n = %d %d %d)",
                              what, i, j, raw[k] + sh[k], k, rij[k], img[0], img[1], dim == 3 ? img[2] : 0);
            ck_assert_double_eq_tol(dist, sqrt(tu_norm2(dim, rij)), 1e-12);
            double b2 = tu_min_image_brute(dim, L, gamma_lat, raw, bf, bimg);
            if (i == j) {
                for (int k = 0; k < dim; ++k) ck_assert(rij[k] == 0.0);
                ck_assert(dist == 0.0);
            }
            if (sqrt(b2) < half * (1.0 - 1e-9)) {
                ++close;
                for (int k = 0; k < dim; ++k)
                    ck_assert_msg(fabs(rij[k] - bf[k]) <= 1e-12,
                                  "%s: pair (%zu,%zu) rij[%d] = %.17g, brute force %.17g", what, i, j, k,
                                  rij[k], bf[k]);
                ck_assert_double_eq_tol(dist, sqrt(b2), 1e-12);
                if (gamma_lat == g)
                    for (int k = 0; k < dim; ++k)
                        ck_assert_msg(img[k] == bimg[k], "%s: pair (%zu,%zu) image[%d] = %d, brute %d",
                                      what, i, j, k, img[k], bimg[k]);
                /* antisymmetry */
                double rji[3];
                ck_assert_int_eq(odhs_system_separation(s, j, i, rji, NULL, NULL), ODHS_OK);
                for (int k = 0; k < dim; ++k) ck_assert_double_eq_tol(rji[k], -rij[k], 1e-12);
            }
        }
    free(x);
    return close;
}

START_TEST(test_min_image)
{
    int dim = 2 + _i; /* loop 0..1 */
    tu_rng rng;
    tu_rng_seed(&rng, 1000 + (uint64_t)dim);
    const size_t n = 40;
    double *x = malloc(n * (size_t)dim * sizeof *x);
    ck_assert_ptr_nonnull(x);
    for (size_t bx = 0; bx < sizeof le_boxes / sizeof le_boxes[0]; ++bx)
        for (size_t sg = 0; sg < sizeof le_strains / sizeof le_strains[0]; ++sg) {
            const double *L = le_boxes[bx];
            double gamma = le_strains[sg], g;
            odhs_system *s = new_sys(dim, n);
            ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
            ck_assert_int_eq(odhs_system_set_strain(s, gamma), ODHS_OK);
            ck_assert_int_eq(odhs_system_get_strain(s, &g), ODHS_OK);
            /* stored strain: the same lattice, remapped by multiples of Lx/Ly */
            {
                double u = L[0] / L[1], k = nearbyint((gamma - g) / u);
                ck_assert_msg(fabs(gamma - g - k * u) <= 1e-14 && fabs(g) <= 0.5 * u * (1 + 1e-14),
                              "strain %g stored as %.17g (Lx/Ly = %g)", gamma, g, u);
            }
            for (size_t k = 0; k < n * (size_t)dim; ++k) x[k] = tu_uniform(&rng) * L[k % dim];
            ck_assert_int_eq(odhs_system_set_positions(s, x), ODHS_OK);
            char what[96];
            snprintf(what, sizeof what, "%dD box %zu strain %g", dim, bx, gamma);
            size_t close = check_separations(s, gamma, what);
            ck_assert_msg(close > n * n / 8, "%s: only %zu close pairs tested", what, close);
            odhs_system_destroy(s);
        }
    free(x);
}
END_TEST

START_TEST(test_min_image_le_boundary)
{
    /* i just below the top edge, j just above the bottom edge but shifted by
     * the Lees-Edwards offset: they are neighbours only through the sheared
     * boundary (n = (-1, 1, 0)). */
    for (int dim = 2; dim <= 3; ++dim) {
        double L[3] = {5, 5, 5}, gamma = 0.37, r[6];
        double off[3] = {0.15, 0.2, dim == 3 ? -0.1 : 0.0};
        double xi[3] = {1.0, 4.95, 2.5};
        double x[18] = {0};
        /* j = i + off - b + a */
        double xj[3] = {xi[0] + off[0] - gamma * L[1] + L[0], xi[1] + off[1] - L[1], xi[2] + off[2]};
        for (int k = 0; k < dim; ++k) {
            x[0 * dim + k] = xi[k];
            x[1 * dim + k] = xj[k];
        }
        /* some far-away particles so that there are several cells */
        const double far[4][3] = {{2.5, 2.5, 4.0}, {4.0, 1.5, 1.0}, {0.5, 2.0, 0.5}, {3.5, 3.5, 3.5}};
        for (int p = 0; p < 4; ++p)
            for (int k = 0; k < dim; ++k) x[(2 + p) * dim + k] = far[p][k];
        for (int p = 0; p < 6; ++p) r[p] = 0.1;
        odhs_system *s = new_sys(dim, 6);
        ck_assert_int_eq(odhs_system_set_configuration(s, L, gamma, r, x), ODHS_OK);
        double rij[3], dist;
        int img[3];
        ck_assert_int_eq(odhs_system_separation(s, 0, 1, rij, &dist, img), ODHS_OK);
        for (int k = 0; k < dim; ++k) ck_assert_double_eq_tol(rij[k], off[k], 1e-12);
        ck_assert_int_eq(img[0], -1);
        ck_assert_int_eq(img[1], 1);
        if (dim == 3) ck_assert_int_eq(img[2], 0);
        tu_pairlist pl;
        tu_pairlist_init(&pl, dim);
        ck_assert_int_eq(odhs_system_for_each_pair(s, 0.1, tu_pair_collect, &pl), ODHS_OK);
        ck_assert_uint_eq(pl.n, 1);
        ck_assert_uint_eq(pl.p[0].i, 0);
        ck_assert_uint_eq(pl.p[0].j, 1);
        ck_assert_double_eq_tol(pl.p[0].gap, sqrt(tu_norm2(dim, off)) - 0.2, 1e-12);
        tu_pairlist_free(&pl);
        compare_pairs(s, 0.1, "LE boundary");
        /* without strain the two are far apart */
        ck_assert_int_eq(odhs_system_set_strain(s, 0.0), ODHS_OK);
        ck_assert_int_eq(odhs_system_separation(s, 0, 1, rij, &dist, img), ODHS_OK);
        ck_assert(dist > 1.0);
        tu_pairlist_init(&pl, dim);
        ck_assert_int_eq(odhs_system_for_each_pair(s, 0.1, tu_pair_collect, &pl), ODHS_OK);
        ck_assert_uint_eq(pl.n, 0);
        tu_pairlist_free(&pl);
        odhs_system_destroy(s);
    }
}
END_TEST

START_TEST(test_strain_remap)
{
    int dim = 2 + _i;
    tu_rng rng;
    tu_rng_seed(&rng, 77 + (uint64_t)dim);
    const size_t n = 40;
    const double L[3] = {2.5, 2.5, 2.0}; /* Lx = Ly: b -> b - a is gamma -> gamma - 1 */
    double *x = malloc(n * (size_t)dim * sizeof *x), *x2 = malloc(n * (size_t)dim * sizeof *x2);
    ck_assert(x && x2);
    for (size_t k = 0; k < n * (size_t)dim; ++k) x[k] = tu_uniform(&rng) * L[k % dim];
    odhs_system *s = new_sys(dim, n);
    ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_positions(s, x), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_strain(s, 0.7), ODHS_OK);
    double g;
    ck_assert_int_eq(odhs_system_get_strain(s, &g), ODHS_OK);
    ck_assert_msg(fabs(g - (-0.3)) <= 1e-15, "strain 0.7 remapped to %.17g, expected -0.3", g);
    /* physical positions kept (they are inside the box) */
    ck_assert_int_eq(odhs_system_get_positions(s, x2), ODHS_OK);
    ck_assert_mem_eq(x, x2, n * (size_t)dim * sizeof *x);
    /* same separations as the lattice with gamma = 0.7 itself */
    size_t close = check_separations(s, 0.7, "strain 0.7 vs lattice 0.7");
    ck_assert(close > n * n / 8);
    check_separations(s, g, "strain 0.7 vs remapped lattice");

    /* more remappings: result in [-1/2, 1/2], differs by an integer */
    const double in[] = {1.0, -0.7, 2.3, -1.5, 1.5, 0.5, -0.5, 1e6 + 0.25, -3.49, 0.2, -0.0};
    for (size_t k = 0; k < sizeof in / sizeof in[0]; ++k) {
        ck_assert_int_eq(odhs_system_set_strain(s, in[k]), ODHS_OK);
        ck_assert_int_eq(odhs_system_get_strain(s, &g), ODHS_OK);
        ck_assert_msg(g >= -0.5 && g <= 0.5, "strain %g remapped to %.17g", in[k], g);
        double m = in[k] - g;
        ck_assert_msg(fabs(m - nearbyint(m)) <= 1e-9, "strain %g remapped to %.17g", in[k], g);
        if (fabs(in[k]) <= 0.5) ck_assert_msg(g == in[k], "strain %g in range changed to %.17g", in[k], g);
        ck_assert_int_eq(odhs_system_get_positions(s, x2), ODHS_OK);
        ck_assert_mem_eq(x, x2, n * (size_t)dim * sizeof *x);
    }
    ck_assert_int_eq(odhs_system_set_strain(s, -0.7), ODHS_OK);
    check_separations(s, -0.7, "strain -0.7 vs lattice -0.7");
    odhs_system_destroy(s);
    free(x);
    free(x2);
}
END_TEST

/* Lx != Ly: the lattice is unchanged only if the strain moves by a multiple of
 * Lx/Ly (b -> b -/+ a). Whatever value is stored, the physical separations must
 * be those of the lattice with the strain that was asked for. */
START_TEST(test_strain_remap_nonsquare)
{
    int dim = 2 + _i % 2;
    const double boxes[2][3] = {{3.0, 2.0, 2.5}, {2.0, 4.0, 2.5}};
    const double *L = boxes[_i / 2];
    tu_rng rng;
    tu_rng_seed(&rng, 177 + (uint64_t)_i);
    const size_t n = 40;
    double *x = malloc(n * (size_t)dim * sizeof *x);
    ck_assert_ptr_nonnull(x);
    for (size_t k = 0; k < n * (size_t)dim; ++k) x[k] = tu_uniform(&rng) * L[k % dim];
    odhs_system *s = new_sys(dim, n);
    ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_positions(s, x), ODHS_OK);
    const double in[] = {0.7, -0.7, 1.0, 0.45, -1.3, 2.6};
    for (size_t k = 0; k < sizeof in / sizeof in[0]; ++k) {
        ck_assert_int_eq(odhs_system_set_strain(s, in[k]), ODHS_OK);
        double g;
        ck_assert_int_eq(odhs_system_get_strain(s, &g), ODHS_OK);
        char what[128];
        snprintf(what, sizeof what, "%dD box %gx%g: set_strain(%g) stored %.17g", dim, L[0], L[1], in[k], g);
        double m = (in[k] - g) * L[1] / L[0];
        ck_assert_msg(fabs(m - nearbyint(m)) <= 1e-9,
                      "%s: the lattice changed (strain moved by %.17g, not a multiple of Lx/Ly = %g)",
                      what, in[k] - g, L[0] / L[1]);
        check_separations(s, in[k], what);
    }
    odhs_system_destroy(s);
    free(x);
}
END_TEST

/* stored position p is in [0,L) and p - q is a lattice vector */
static void check_same_lattice_point(int dim, const double *L, double gamma, const double *q,
                                     const double *p, const char *what)
{
    for (int k = 0; k < dim; ++k)
        ck_assert_msg(p[k] >= 0.0 && p[k] < L[k], "%s: coordinate %d = %.17g not in [0, %.17g)", what, k,
                      p[k], L[k]);
    double d[3] = {0, 0, 0};
    for (int k = 0; k < dim; ++k) d[k] = p[k] - q[k];
    double scale = 1.0;
    for (int k = 0; k < dim; ++k) scale = fmax(scale, fabs(q[k]));
    double tol = 1e-12 * scale;
    double n1 = nearbyint(d[1] / L[1]);
    ck_assert_msg(fabs(d[1] - n1 * L[1]) <= tol, "%s: dy = %.17g not a multiple of Ly", what, d[1]);
    if (dim == 3) {
        double n2 = nearbyint(d[2] / L[2]);
        ck_assert_msg(fabs(d[2] - n2 * L[2]) <= tol, "%s: dz = %.17g not a multiple of Lz", what, d[2]);
    }
    double rx = d[0] - n1 * gamma * L[1];
    double n0 = nearbyint(rx / L[0]);
    ck_assert_msg(fabs(rx - n0 * L[0]) <= tol,
                  "%s: dx - n1 gamma Ly = %.17g not a multiple of Lx (n1 = %g, gamma = %g)", what, rx, n1,
                  gamma);
}

START_TEST(test_wrap_outside)
{
    int dim = 2 + _i;
    const double L[3] = {2.0, 3.0, 1.5};
    const double strains[] = {0.0, 0.3, -0.5, 0.5, 0.37};
    tu_rng rng;
    tu_rng_seed(&rng, 4242 + (uint64_t)dim);
    enum { NR = 60, NS = 12 };
    const size_t n = NR + NS;
    double x[(NR + NS) * 3], in[(NR + NS) * 3], q[(NR + NS) * 3], out[(NR + NS) * 3];
    for (size_t sg = 0; sg < sizeof strains / sizeof strains[0]; ++sg) {
        double gamma = strains[sg];
        /* random interior points moved by random lattice vectors */
        for (size_t i = 0; i < NR; ++i) {
            int nn[3] = {(int)tu_index(&rng, 11) - 5, (int)tu_index(&rng, 11) - 5, (int)tu_index(&rng, 11) - 5};
            double sh[3] = {0, 0, 0};
            tu_lattice_shift(dim, L, gamma, nn, sh);
            for (int k = 0; k < dim; ++k) {
                x[i * dim + k] = tu_uniform_in(&rng, 0.01, 0.99) * L[k];
                in[i * dim + k] = x[i * dim + k] + sh[k];
            }
        }
        /* special points: on the upper faces, tiny negatives, far away */
        const double sp[NS][3] = {{L[0], 1.0, 0.5},        {0.5, L[1], 0.5},     {L[0], L[1], L[2]},
                                  {-1e-300, 1.0, 0.5},     {0.5, -1e-300, 0.5},  {1.0, -1e-17, -1e-17},
                                  {-0.1, 1.0, 0.5},        {0.5, -0.1, 0.5},     {0.5, 1.0, -0.1},
                                  {57.3 * L[0], -31.7 * L[1], 12.2 * L[2]},      {-4.0, 7.0, 3.0},
                                  {0.0, 3.0 * L[1], -L[2]}};
        for (size_t i = 0; i < NS; ++i)
            for (int k = 0; k < dim; ++k) in[(NR + i) * dim + k] = sp[i][k];
        memcpy(q, in, sizeof q);

        odhs_system *s = new_sys(dim, n);
        ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
        ck_assert_int_eq(odhs_system_set_strain(s, gamma), ODHS_OK);
        ck_assert_int_eq(odhs_system_set_positions(s, in), ODHS_OK);
        ck_assert_mem_eq(in, q, n * (size_t)dim * sizeof(double)); /* input not modified */
        ck_assert_int_eq(odhs_system_get_positions(s, out), ODHS_OK);
        for (size_t i = 0; i < n; ++i) {
            char what[96];
            snprintf(what, sizeof what, "%dD strain %g particle %zu", dim, gamma, i);
            check_same_lattice_point(dim, L, gamma, in + i * dim, out + i * dim, what);
            if (i < NR)
                for (int k = 0; k < dim; ++k)
                    ck_assert_msg(fabs(out[i * dim + k] - x[i * dim + k]) <= 1e-12,
                                  "%s: wrapped to %.17g, expected %.17g", what, out[i * dim + k],
                                  x[i * dim + k]);
        }
        odhs_system_destroy(s);
    }
}
END_TEST

START_TEST(test_wrap_on_set_box)
{
    /* shrinking the box (no scaling) wraps the positions into the new box:
     * each stays the same point of the new sheared lattice */
    int dim = 2 + _i;
    const double L[3] = {4.0, 5.0, 3.0}, Ln[3] = {2.5, 3.2, 1.9};
    tu_rng rng;
    tu_rng_seed(&rng, 31 + (uint64_t)dim);
    const size_t n = 50;
    double x[150], out[150];
    for (size_t k = 0; k < n * (size_t)dim; ++k) x[k] = tu_uniform(&rng) * L[k % dim];
    odhs_system *s = new_sys(dim, n);
    ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_strain(s, 0.41), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_positions(s, x), ODHS_OK);
    /* the strain is defined modulo Lx/Ly of the box it was set in: set_box
     * keeps the stored representative, which defines the new lattice */
    double gs;
    ck_assert_int_eq(odhs_system_get_strain(s, &gs), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_box(s, Ln), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_positions(s, out), ODHS_OK);
    size_t moved = 0;
    for (size_t i = 0; i < n; ++i) {
        char what[64];
        snprintf(what, sizeof what, "%dD set_box particle %zu", dim, i);
        check_same_lattice_point(dim, Ln, gs, x + i * dim, out + i * dim, what);
        moved += memcmp(x + i * dim, out + i * dim, (size_t)dim * sizeof(double)) != 0;
    }
    ck_assert(moved > n / 4);
    odhs_system_destroy(s);
}
END_TEST

START_TEST(test_wrap_inside_bitwise)
{
    int dim = 2 + _i;
    const double L[3] = {2.5, 3.0, 2.2};
    const double strains[] = {0.0, 0.37, -0.5, 0.5};
    tu_rng rng;
    tu_rng_seed(&rng, 99 + (uint64_t)dim);
    const size_t n = 30;
    double x[30 * 3], out[30 * 3];
    for (size_t sg = 0; sg < sizeof strains / sizeof strains[0]; ++sg) {
        for (size_t k = 0; k < n * (size_t)dim; ++k) x[k] = tu_uniform(&rng) * L[k % dim];
        /* edge values that are inside */
        for (int k = 0; k < dim; ++k) {
            x[0 * dim + k] = 0.0;
            x[1 * dim + k] = nextafter(L[k], 0.0);
            x[2 * dim + k] = 1e-300;
            x[3 * dim + k] = DBL_MIN / 4; /* subnormal */
        }
        odhs_system *s = new_sys(dim, n);
        ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
        ck_assert_int_eq(odhs_system_set_strain(s, strains[sg]), ODHS_OK);
        ck_assert_int_eq(odhs_system_set_positions(s, x), ODHS_OK);
        ck_assert_int_eq(odhs_system_get_positions(s, out), ODHS_OK);
        ck_assert_mem_eq(out, x, n * (size_t)dim * sizeof(double));
        /* a larger box and another strain keep inside positions as they are */
        double L2[3] = {L[0] * 1.5, L[1] * 1.25, L[2] * 2.0};
        ck_assert_int_eq(odhs_system_set_box(s, L2), ODHS_OK);
        ck_assert_int_eq(odhs_system_set_strain(s, -strains[sg] + 0.1), ODHS_OK);
        ck_assert_int_eq(odhs_system_get_positions(s, out), ODHS_OK);
        ck_assert_mem_eq(out, x, n * (size_t)dim * sizeof(double));
        odhs_system_destroy(s);
    }
    /* with radii, through set_configuration */
    double Lr[3] = {6.0, 5.0, 5.5};
    tu_rng_seed(&rng, 5);
    double r[30];
    tu_radii_loguniform(n, 0.05, 0.5, r, &rng);
    ck_assert(tu_random_config(dim, n, Lr, 0.37, r, 0.0, x, &rng));
    odhs_system *s = new_sys(dim, n);
    ck_assert_int_eq(odhs_system_set_configuration(s, Lr, 0.37, r, x), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_positions(s, out), ODHS_OK);
    ck_assert_mem_eq(out, x, n * (size_t)dim * sizeof(double));
    double r2[30];
    ck_assert_int_eq(odhs_system_get_radii(s, r2), ODHS_OK);
    ck_assert_mem_eq(r2, r, n * sizeof(double));
    odhs_system_destroy(s);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* neighbour search against brute force                                      */
/* ------------------------------------------------------------------------ */

typedef struct {
    int dim;
    size_t n;
    double L[3];
    double gamma;
    uint64_t seed;
    const char *name;
    double rmin; /* smallest radius (the largest is 0.5) */
} pair_case;

static const pair_case pair_cases[] = {
    {2, 120, {8, 8, 0}, 0.0, 11, "2D cubic", 0.05},
    {2, 120, {8, 8, 0}, 0.5, 12, "2D strain 0.5", 0.05},
    {2, 120, {8, 8, 0}, -0.5, 13, "2D strain -0.5", 0.05},
    {2, 120, {8, 8, 0}, 0.37, 14, "2D strain 0.37", 0.05},
    {2, 150, {12, 6, 0}, 0.37, 15, "2D Lx=2Ly strain 0.37", 0.05},
    {2, 150, {6, 12, 0}, -0.37, 16, "2D Lx=Ly/2 strain -0.37", 0.05},
    {2, 150, {12, 6, 0}, -0.5, 17, "2D Lx=2Ly strain -0.5", 0.05},
    {2, 10, {2.6, 2.6, 0}, 0.5, 18, "2D small box strain 0.5", 0.05},
    {2, 14, {3.3, 2.7, 0}, -0.37, 19, "2D small box strain -0.37", 0.05},
    {2, 12, {2.1, 4.5, 0}, 0.0, 20, "2D small Lx", 0.05},
    {2, 200, {60, 60, 0}, 0.37, 21, "2D large sparse strain 0.37", 0.05},
    {3, 350, {5, 5, 5}, 0.0, 31, "3D cubic", 0.05},
    {3, 350, {5, 5, 5}, 0.5, 32, "3D strain 0.5", 0.05},
    {3, 350, {5, 5, 5}, -0.5, 33, "3D strain -0.5", 0.05},
    {3, 400, {8, 4, 5}, 0.37, 34, "3D Lx=2Ly strain 0.37", 0.05},
    {3, 300, {4, 8, 5}, -0.37, 35, "3D Lx=Ly/2 strain -0.37", 0.05},
    {3, 20, {2.5, 2.5, 2.5}, -0.5, 36, "3D small box strain -0.5", 0.05},
    {3, 12, {2.2, 2.4, 2.3}, 0.37, 37, "3D small box strain 0.37", 0.05},
    {3, 300, {30, 30, 30}, 0.37, 38, "3D large sparse strain 0.37", 0.05},
    /* nearly monodisperse: many pairs close to the pair range 2 rmax + max_gap */
    {2, 95, {12, 12, 0}, 0.5, 41, "2D near-monodisperse strain 0.5", 0.4},
    {2, 95, {12, 12, 0}, -0.37, 42, "2D near-monodisperse strain -0.37", 0.4},
    {3, 150, {6, 6, 6}, -0.5, 43, "3D near-monodisperse strain -0.5", 0.4},
    {3, 150, {6, 6, 6}, 0.37, 44, "3D near-monodisperse strain 0.37", 0.4},
};
#define N_PAIR_CASES ((int)(sizeof pair_cases / sizeof pair_cases[0]))

START_TEST(test_pairs_brute)
{
    const pair_case *pc = &pair_cases[_i];
    odhs_system *s = make_random_system(pc->dim, pc->n, pc->L, pc->gamma, pc->rmin, 0.5, pc->seed);
    double limit = 0.5 * min_edge(pc->dim, pc->L) - 2.0 * 0.5; /* max_gap must stay below */
    ck_assert(limit > 0.0);
    const double fr[] = {0.0, 0.1, 0.3, 0.6, 0.99};
    double gaps[7] = {0.0, 0.01};
    for (int k = 0; k < 5; ++k) gaps[2 + k] = fr[k] * limit;
    compare_pairs_n(s, gaps, 7, pc->name);
    odhs_system_destroy(s);
}
END_TEST

/* Pairs oriented along the direction that maximises the sheared-frame
 * distance |dx - gamma dy| = |d| sqrt(1 + gamma^2): a cell list whose cells in
 * x' = x - gamma y are only rc wide (ignoring the shear) misses some of them.
 * Many tiny fillers keep the cell grid fine. */
START_TEST(test_pairs_shear_direction)
{
    const double strains[] = {0.5, -0.5, 0.37};
    int dim = 2 + _i / 3;
    double gamma = strains[_i % 3];
    const double rb = 0.5, rf = 0.01, gap = 0.01;
    const double rc = 2 * rb + gap;
    const size_t npair = 60, nfill = dim == 2 ? 260 : 560;
    const size_t n = 2 * npair + nfill;
    double Lv = (dim == 2 ? 19.0 : 11.0) * rc * 1.0001; /* Lv / rc just above an integer */
    double L[3] = {Lv, Lv, Lv};
    double *x = malloc(n * (size_t)dim * sizeof *x), *r = malloc(n * sizeof *r);
    ck_assert(x && r);
    /* d along (1, -gamma): dx - gamma dy = |d| sqrt(1 + gamma^2) */
    double dir[3] = {1.0, -gamma, 0.0};
    double nd = sqrt(1.0 + gamma * gamma);
    dir[0] /= nd;
    dir[1] /= nd;
    tu_rng rng;
    tu_rng_seed(&rng, 555 + (uint64_t)_i);
    for (size_t i = 0; i < n; ++i) r[i] = i < 2 * npair ? rb : rf;
    size_t placed = 0;
    for (int tries = 0; placed < n && tries < 2000000; ++tries) {
        int is_pair = placed < 2 * npair;
        double a[3] = {0, 0, 0}, b[3] = {0, 0, 0};
        for (int k = 0; k < dim; ++k) a[k] = tu_uniform(&rng) * L[k];
        size_t cnt = is_pair ? 2 : 1;
        if (is_pair) {
            /* may lie outside the box: the library wraps it */
            for (int k = 0; k < dim; ++k) b[k] = a[k] + (2 * rb + 0.9 * gap) * dir[k];
        }
        int ok = 1;
        for (size_t c = 0; c < cnt && ok; ++c) {
            const double *p = c == 0 ? a : b;
            double rp = r[placed + c];
            for (size_t j = 0; j < placed && ok; ++j) {
                double d[3] = {0, 0, 0};
                for (int k = 0; k < dim; ++k) d[k] = x[j * dim + k] - p[k];
                double s2 = tu_min_image_fast(dim, L, gamma, d);
                double lim = rp + r[j] + 0.05;
                if (s2 < lim * lim) ok = 0;
            }
        }
        if (!ok) continue;
        for (int k = 0; k < dim; ++k) {
            x[placed * dim + k] = a[k];
            if (is_pair) x[(placed + 1) * dim + k] = b[k];
        }
        placed += cnt;
    }
    ck_assert_uint_eq(placed, n);
    odhs_system *s = new_sys(dim, n);
    int st = odhs_system_set_configuration(s, L, gamma, r, x);
    ck_assert_msg(st == ODHS_OK, "%s", odhs_system_errmsg(s));
    /* every designed pair is found */
    tu_pairlist pl;
    tu_pairlist_init(&pl, dim);
    ck_assert_int_eq(odhs_system_for_each_pair(s, gap, tu_pair_collect, &pl), ODHS_OK);
    size_t found = 0;
    for (size_t k = 0; k < pl.n; ++k)
        if (pl.p[k].i < 2 * npair && pl.p[k].j == pl.p[k].i + 1 && pl.p[k].i % 2 == 0) ++found;
    ck_assert_msg(found == npair, "%dD strain %g: found %zu of %zu pairs oriented along the shear", dim,
                  gamma, found, npair);
    tu_pairlist_free(&pl);
    compare_pairs(s, gap, "shear direction");
    odhs_system_destroy(s);
    free(x);
    free(r);
}
END_TEST

START_TEST(test_pairs_after_scale_box)
{
    const int cases[] = {3, 4, 5, 12, 15, 17};
    for (size_t c = 0; c < sizeof cases / sizeof cases[0]; ++c) {
        const pair_case *pc = &pair_cases[cases[c]];
        odhs_system *s = make_random_system(pc->dim, pc->n, pc->L, pc->gamma, pc->rmin, 0.5, pc->seed);
        state a, b;
        state_get(s, &a);
        double phi0, phi1;
        ck_assert_int_eq(odhs_system_packing_fraction(s, &phi0), ODHS_OK);
        const double fac[] = {1.3, 0.9};
        double tot = 1.0;
        for (int f = 0; f < 2; ++f) {
            double sf = fac[f];
            state before;
            state_get(s, &before);
            ck_assert_int_eq(odhs_system_scale_box(s, sf), ODHS_OK);
            tot *= sf;
            state_get(s, &b);
            for (int k = 0; k < pc->dim; ++k) ck_assert(b.L[k] == before.L[k] * sf);
            ck_assert(b.gamma == before.gamma);
            ck_assert_mem_eq(b.r, before.r, pc->n * sizeof(double));
            for (size_t k = 0; k < pc->n * (size_t)pc->dim; ++k)
                ck_assert_msg(fabs(b.x[k] - before.x[k] * sf) <= 1e-12 * b.L[k % pc->dim] ||
                                  fabs(fabs(b.x[k] - before.x[k] * sf) - b.L[k % pc->dim]) <= 1e-12,
                              "%s: coordinate %zu not scaled", pc->name, k);
            ck_assert_int_eq(odhs_system_packing_fraction(s, &phi1), ODHS_OK);
            ck_assert_msg(tu_close(phi1, phi0 / pow(tot, pc->dim), 1e-12), "phi %.17g vs %.17g", phi1,
                          phi0 / pow(tot, pc->dim));
            ck_assert_int_eq(odhs_system_validate(s, 0.0), ODHS_OK);
            double limit = 0.5 * min_edge(pc->dim, b.L) - 1.0;
            const double g3[3] = {0.0, 0.05, 0.5 * limit};
            compare_pairs_n(s, g3, 3, pc->name);
            state_free(&b);
            state_free(&before);
        }
        /* a strong compression overlaps (or makes the box too small): rejected,
         * nothing changes */
        if (0.55 * tot * min_edge(pc->dim, pc->L) >= 2.0) {
            EXPECT_FAIL(s, ODHS_E_OVERLAP, odhs_system_scale_box(s, 0.55));
            ck_assert(strstr(odhs_system_errmsg(s), "overlap") != NULL);
        } else {
            EXPECT_FAIL(s, ODHS_E_BOX, odhs_system_scale_box(s, 0.55));
        }
        state_free(&a);
        odhs_system_destroy(s);
    }
}
END_TEST

START_TEST(test_pairs_stop)
{
    const pair_case *pc = &pair_cases[3];
    odhs_system *s = make_random_system(pc->dim, pc->n, pc->L, pc->gamma, pc->rmin, 0.5, pc->seed);
    tu_pairlist pl;
    tu_pairlist_init(&pl, pc->dim);
    ck_assert_int_eq(odhs_system_for_each_pair(s, 0.5, tu_pair_collect, &pl), ODHS_OK);
    size_t total = pl.calls;
    tu_pairlist_free(&pl);
    ck_assert(total > 20);
    const size_t stops[] = {1, 2, 7, total - 1, total};
    for (size_t k = 0; k < sizeof stops / sizeof stops[0]; ++k) {
        tu_pairlist_init(&pl, pc->dim);
        pl.stop_after = stops[k];
        int st = odhs_system_for_each_pair(s, 0.5, tu_pair_collect, &pl);
        ck_assert_msg(st == ODHS_STOPPED, "stop after %zu: status %d", stops[k], st);
        ck_assert_msg(pl.calls == stops[k], "callback asked to stop after %zu calls, got %zu calls", stops[k],
                      pl.calls);
        tu_pairlist_free(&pl);
    }
    tu_pairlist_init(&pl, pc->dim);
    pl.stop_after = total + 1;
    ck_assert_int_eq(odhs_system_for_each_pair(s, 0.5, tu_pair_collect, &pl), ODHS_OK);
    ck_assert_uint_eq(pl.calls, total);
    tu_pairlist_free(&pl);
    odhs_system_destroy(s);
}
END_TEST

START_TEST(test_pairs_invalid_gap)
{
    for (int c = 0; c < N_PAIR_CASES; c += 6) {
        const pair_case *pc = &pair_cases[c];
        odhs_system *s = make_random_system(pc->dim, pc->n, pc->L, pc->gamma, pc->rmin, 0.5, pc->seed);
        double limit = 0.5 * min_edge(pc->dim, pc->L) - 1.0;
        tu_pairlist pl;
        tu_pairlist_init(&pl, pc->dim);
        EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_for_each_pair(s, limit, tu_pair_collect, &pl));
        EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_for_each_pair(s, 2.0 * limit + 1.0, tu_pair_collect, &pl));
        EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_for_each_pair(s, 1e300, tu_pair_collect, &pl));
        EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_for_each_pair(s, -0.01, tu_pair_collect, &pl));
        EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_for_each_pair(s, -1e-300, tu_pair_collect, &pl));
        int st = odhs_system_for_each_pair(s, NAN, tu_pair_collect, &pl);
        ck_assert_msg(st == ODHS_E_INVALID || st == ODHS_E_NONFINITE, "max_gap NaN: %d", st);
        st = odhs_system_for_each_pair(s, INFINITY, tu_pair_collect, &pl);
        ck_assert_msg(st == ODHS_E_INVALID || st == ODHS_E_NONFINITE, "max_gap inf: %d", st);
        ck_assert_uint_eq(pl.calls, 0);
        /* just below the limit is fine */
        ck_assert_int_eq(odhs_system_for_each_pair(s, limit * (1 - 1e-9), tu_pair_collect, &pl), ODHS_OK);
        tu_pairlist_free(&pl);
        odhs_system_destroy(s);
    }
}
END_TEST

START_TEST(test_pairs_single_particle)
{
    for (int dim = 2; dim <= 3; ++dim) {
        odhs_system *s = new_sys(dim, 1);
        double L[3] = {3, 3, 3}, r = 0.5, x[3] = {4.0, -1.0, 0.5};
        ck_assert_int_eq(odhs_system_set_configuration(s, L, 0.3, &r, x), ODHS_OK);
        tu_pairlist pl;
        tu_pairlist_init(&pl, dim);
        ck_assert_int_eq(odhs_system_for_each_pair(s, 0.4, tu_pair_collect, &pl), ODHS_OK);
        ck_assert_uint_eq(pl.calls, 0);
        ck_assert_int_eq(odhs_system_validate(s, 0.0), ODHS_OK);
        double rij[3], d;
        int img[3];
        ck_assert_int_eq(odhs_system_separation(s, 0, 0, rij, &d, img), ODHS_OK);
        ck_assert(d == 0.0);
        odhs_system_destroy(s);
    }
}
END_TEST

/* ------------------------------------------------------------------------ */
/* scene builders                                                            */
/* ------------------------------------------------------------------------ */

START_TEST(test_bidisperse)
{
    const size_t n = 101;
    odhs_system *s = new_sys(2, n);
    double L[2] = {100, 100}, r[101], r2[101];
    ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
    const double rs = 0.5, ratio = 1.4, poly = 0.1;
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(s, rs, ratio, poly, 42), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(s, r), ODHS_OK);
    size_t nS = 0, nL = 0;
    double fsum = 0.0, f2sum = 0.0;
    char buf[ODHS_SPECIES_MAX + 1];
    for (size_t i = 0; i < n; ++i) {
        double base = i % 2 == 0 ? rs : rs * ratio;
        double f = r[i] / base - 1.0;
        ck_assert_msg(fabs(f) <= poly * (1 + 1e-12), "radius %zu = %g outside poly range", i, r[i]);
        fsum += f;
        f2sum += f * f;
        ck_assert_int_eq(odhs_system_get_species(s, i, buf, sizeof buf), ODHS_OK);
        if (i % 2 == 0) {
            ck_assert_str_eq(buf, "S");
            ++nS;
        } else {
            ck_assert_str_eq(buf, "L");
            ++nL;
        }
    }
    ck_assert_uint_eq(nS, 51);
    ck_assert_uint_eq(nL, 50);
    double mean = fsum / n, sd = sqrt(f2sum / n - mean * mean);
    ck_assert_msg(fabs(mean) < 0.03, "mean poly factor %g", mean);
    ck_assert_msg(sd > 0.7 * poly / sqrt(3.0) && sd < 1.3 * poly / sqrt(3.0), "poly spread %g", sd);

    /* reproducible from the seed, different seeds differ */
    odhs_system *t = new_sys(2, n);
    ck_assert_int_eq(odhs_system_set_box(t, L), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(t, rs, ratio, poly, 42), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(t, r2), ODHS_OK);
    ck_assert_mem_eq(r, r2, sizeof r);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(t, rs, ratio, poly, 43), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(t, r2), ODHS_OK);
    size_t ndiff = 0;
    for (size_t i = 0; i < n; ++i) ndiff += r[i] != r2[i];
    ck_assert_msg(ndiff > n / 2, "seeds 42 and 43 give %zu different radii of %zu", ndiff, n);

    /* no polydispersity: exactly two sizes */
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(t, rs, ratio, 0.0, 7), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(t, r2), ODHS_OK);
    for (size_t i = 0; i < n; ++i) ck_assert(r2[i] == (i % 2 == 0 ? rs : rs * ratio));

    /* argument errors: nothing changes (radii, species) */
    ck_assert_int_eq(odhs_system_set_species(t, 3, "Q"), ODHS_OK);
    EXPECT_FAIL(t, ODHS_E_INVALID, odhs_system_set_radii_bidisperse(t, 0.0, ratio, poly, 1));
    EXPECT_FAIL(t, ODHS_E_INVALID, odhs_system_set_radii_bidisperse(t, -0.5, ratio, poly, 1));
    EXPECT_FAIL(t, ODHS_E_INVALID, odhs_system_set_radii_bidisperse(t, rs, 0.0, poly, 1));
    EXPECT_FAIL(t, ODHS_E_INVALID, odhs_system_set_radii_bidisperse(t, rs, -1.4, poly, 1));
    EXPECT_FAIL(t, ODHS_E_INVALID, odhs_system_set_radii_bidisperse(t, rs, ratio, -0.1, 1));
    EXPECT_FAIL(t, ODHS_E_INVALID, odhs_system_set_radii_bidisperse(t, rs, ratio, 1.0, 1));
    EXPECT_FAIL(t, ODHS_E_NONFINITE, odhs_system_set_radii_bidisperse(t, NAN, ratio, poly, 1));
    EXPECT_FAIL(t, ODHS_E_NONFINITE, odhs_system_set_radii_bidisperse(t, rs, INFINITY, poly, 1));
    EXPECT_FAIL(t, ODHS_E_NONFINITE, odhs_system_set_radii_bidisperse(t, rs, ratio, NAN, 1));
    ck_assert_int_eq(odhs_system_get_species(t, 3, buf, sizeof buf), ODHS_OK);
    ck_assert_str_eq(buf, "Q");

    /* radii only in the default unit box: the box is only checked once the
     * particles are placed, so the usual recipe works: radii, then place_random */
    odhs_system *u = new_sys(3, 10);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(u, 0.5, 1.4, 0.0, 1), ODHS_OK);
    ck_assert_int_eq(odhs_system_place_random(u, 0.1, 3), ODHS_OK);
    ck_assert_int_eq(odhs_system_validate(u, 0.0), ODHS_OK);
    odhs_system_destroy(u);
    u = new_sys(3, 10);

    /* with positions set, radii that overlap are rejected (species unchanged) */
    double Lu[3] = {10, 10, 10};
    double xu[30];
    for (size_t i = 0; i < 10; ++i) {
        xu[3 * i] = 1.0 + (double)i * 0.8; /* spacing 0.8 along x */
        xu[3 * i + 1] = xu[3 * i + 2] = 5.0;
    }
    ck_assert_int_eq(odhs_system_set_box(u, Lu), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_positions(u, xu), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(u, 0.3, 1.2, 0.0, 1), ODHS_OK); /* 0.3+0.36 < 0.8 */
    EXPECT_FAIL(u, ODHS_E_OVERLAP, odhs_system_set_radii_bidisperse(u, 0.35, 1.4, 0.0, 1));
    /* with positions set, radii too large for the box */
    EXPECT_FAIL(u, ODHS_E_BOX, odhs_system_set_radii_bidisperse(u, 2.0, 1.4, 0.0, 1));
    odhs_system_destroy(u);
    odhs_system_destroy(t);
    odhs_system_destroy(s);
}
END_TEST

typedef struct {
    int dim;
    size_t n;
    double phi;
} place_case;

static const place_case place_cases[] = {
    {2, 256, 0.3}, {2, 256, 0.45}, {3, 216, 0.2}, {3, 216, 0.3}};

static odhs_system *make_placed(const place_case *pc, uint64_t seed, int *status)
{
    odhs_system *s = new_sys(pc->dim, pc->n);
    const double L[3] = {40.0, 20.0, 10.0}; /* aspect 4:2:1 */
    ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_strain(s, 0.3), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(s, 0.5, 1.4, 0.05, 7), ODHS_OK);
    *status = odhs_system_place_random(s, pc->phi, seed);
    return s;
}

START_TEST(test_place_random)
{
    const place_case *pc = &place_cases[_i];
    int dim = pc->dim, st;
    size_t n = pc->n;
    double r0[256];
    odhs_system *s = make_placed(pc, 1234, &st);
    ck_assert_msg(st == ODHS_OK, "place_random(%dD, phi %g) = %d: %s", dim, pc->phi, st,
                  odhs_system_errmsg(s));
    ck_assert_int_eq(odhs_system_is_ready(s), 1);
    double phi;
    ck_assert_int_eq(odhs_system_packing_fraction(s, &phi), ODHS_OK);
    ck_assert_msg(fabs(phi - pc->phi) <= 1e-12 * pc->phi, "phi = %.17g, requested %g", phi, pc->phi);
    ck_assert_int_eq(odhs_system_validate(s, 0.0), ODHS_OK);
    state a;
    state_get(s, &a);
    ck_assert_msg(a.gamma == 0.0, "strain after place_random: %g", a.gamma);
    ck_assert(tu_close(a.L[0] / a.L[1], 2.0, 1e-14));
    if (dim == 3) ck_assert(tu_close(a.L[1] / a.L[2], 2.0, 1e-14));
    /* independently recomputed packing fraction */
    double vp = 0.0, vol = a.L[0] * a.L[1] * (dim == 3 ? a.L[2] : 1.0);
    for (size_t i = 0; i < n; ++i)
        vp += dim == 2 ? TU_PI * a.r[i] * a.r[i] : 4.0 / 3.0 * TU_PI * a.r[i] * a.r[i] * a.r[i];
    ck_assert(tu_close(vp / vol, pc->phi, 1e-12));
    /* radii untouched */
    odhs_system *ref = new_sys(dim, n);
    double big[3] = {100, 100, 100};
    ck_assert_int_eq(odhs_system_set_box(ref, big), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(ref, 0.5, 1.4, 0.05, 7), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(ref, r0), ODHS_OK);
    ck_assert_mem_eq(a.r, r0, n * sizeof(double));
    odhs_system_destroy(ref);
    /* inside the box, spread over it, no overlaps by brute force */
    double mean[3] = {0, 0, 0};
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < dim; ++k) {
            double v = a.x[i * dim + k];
            ck_assert(v >= 0.0 && v < a.L[k]);
            mean[k] += v / (double)n;
        }
    for (int k = 0; k < dim; ++k)
        ck_assert_msg(fabs(mean[k] / a.L[k] - 0.5) < 0.1, "mean coordinate %d = %g of L = %g", k, mean[k],
                      a.L[k]);
    tu_pairlist bf;
    tu_brute_pairs(dim, n, a.x, a.r, a.L, 0.0, 0.0, &bf);
    for (size_t k = 0; k < bf.n; ++k)
        ck_assert_msg(bf.p[k].gap >= 0.0, "particles %zu and %zu overlap by %g", bf.p[k].i, bf.p[k].j,
                      -bf.p[k].gap);
    tu_pairlist_free(&bf);

    /* reproducible: same seed gives the same scene bit for bit */
    odhs_system *t = make_placed(pc, 1234, &st);
    ck_assert_int_eq(st, ODHS_OK);
    state b;
    state_get(t, &b);
    ck_assert_mem_eq(a.L, b.L, sizeof a.L);
    ck_assert_mem_eq(a.x, b.x, n * (size_t)dim * sizeof(double));
    state_free(&b);
    odhs_system_destroy(t);
    /* a different seed gives a different scene, same box */
    t = make_placed(pc, 1235, &st);
    ck_assert_int_eq(st, ODHS_OK);
    state_get(t, &b);
    ck_assert_mem_eq(a.L, b.L, sizeof a.L);
    size_t ndiff = 0;
    for (size_t k = 0; k < n * (size_t)dim; ++k) ndiff += a.x[k] != b.x[k];
    ck_assert_msg(ndiff > n, "seeds 1234 and 1235: only %zu coordinates differ", ndiff);
    state_free(&b);
    odhs_system_destroy(t);

    /* placing again on a ready system replaces the scene */
    ck_assert_int_eq(odhs_system_place_random(s, pc->phi * 0.5, 99), ODHS_OK);
    ck_assert_int_eq(odhs_system_packing_fraction(s, &phi), ODHS_OK);
    ck_assert(tu_close(phi, pc->phi * 0.5, 1e-12));
    ck_assert_int_eq(odhs_system_validate(s, 0.0), ODHS_OK);
    state_free(&a);
    odhs_system_destroy(s);
}
END_TEST

START_TEST(test_place_random_errors)
{
    odhs_system *s = new_sys(2, 64);
    double L[2] = {20, 20};
    ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(s, 0.5, 1.4, 0.0, 1), ODHS_OK);
    /* radii only: a too-dense request leaves the system unplaced */
    EXPECT_FAIL(s, ODHS_E_TOODENSE, odhs_system_place_random(s, 0.8, 9));
    ck_assert_int_eq(odhs_system_is_ready(s), 0);
    ck_assert_int_eq(odhs_system_place_random(s, 0.3, 5), ODHS_OK);
    int st = odhs_system_set_strain(s, 0.25);
    ck_assert(st == ODHS_OK || st == ODHS_E_OVERLAP);
    ck_assert_int_eq(odhs_system_set_species(s, 5, "Z"), ODHS_OK);
    /* too dense: ODHS_E_TOODENSE, positions and box bit-identical */
    EXPECT_FAIL(s, ODHS_E_TOODENSE, odhs_system_place_random(s, 0.8, 9));
    EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_place_random(s, 0.0, 9));
    EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_place_random(s, -0.2, 9));
    EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_place_random(s, 1.0, 9));
    EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_place_random(s, 1.5, 9));
    EXPECT_FAIL(s, ODHS_E_NONFINITE, odhs_system_place_random(s, NAN, 9));
    EXPECT_FAIL(s, ODHS_E_NONFINITE, odhs_system_place_random(s, INFINITY, 9));
    odhs_system_destroy(s);

    /* the box at the requested phi would be shorter than two diameters */
    odhs_system *t = new_sys(2, 2);
    double r[2] = {0.5, 0.5};
    double Lt[2] = {10, 10};
    ck_assert_int_eq(odhs_system_set_box(t, Lt), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii(t, r), ODHS_OK);
    EXPECT_FAIL(t, ODHS_E_BOX, odhs_system_place_random(t, 0.45, 1));
    ck_assert_int_eq(odhs_system_place_random(t, 0.1, 1), ODHS_OK);
    odhs_system_destroy(t);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* validation errors                                                         */
/* ------------------------------------------------------------------------ */

/* n = side^dim particles of radius rad on a square/cubic grid, spacing h */
static void grid_positions(int dim, int side, double h, double *x)
{
    size_t i = 0;
    for (int a = 0; a < side; ++a)
        for (int b = 0; b < side; ++b)
            for (int c = 0; c < (dim == 3 ? side : 1); ++c, ++i) {
                x[i * dim + 0] = 0.3 + a * h;
                x[i * dim + 1] = 0.3 + b * h;
                if (dim == 3) x[i * dim + 2] = 0.3 + c * h;
            }
}

START_TEST(test_overlap_named)
{
    int dim = 2 + _i;
    int side = dim == 2 ? 8 : 4;
    size_t n = dim == 2 ? 64 : 64;
    double h = 1.25, L[3] = {side * h, side * h, side * h};
    double x[64 * 3], x2[64 * 3], r[64];
    for (size_t i = 0; i < n; ++i) r[i] = 0.1;
    grid_positions(dim, side, h, x);
    odhs_system *s = new_sys(dim, n);
    ck_assert_int_eq(odhs_system_set_configuration(s, L, 0.0, r, x), ODHS_OK);
    const size_t I = 12, J = 57;

    /* move J next to I: overlap 0.05 */
    memcpy(x2, x, sizeof x);
    for (int k = 0; k < dim; ++k) x2[J * dim + k] = x[I * dim + k];
    x2[J * dim + 0] += 0.15;
    EXPECT_FAIL(s, ODHS_E_OVERLAP, odhs_system_set_positions(s, x2));
    const char *m = odhs_system_errmsg(s);
    ck_assert_msg(tu_msg_has_index(m, I) && tu_msg_has_index(m, J), "message does not name 12 and 57: %s",
                  m);
    /* a second, smaller overlap elsewhere: the worst pair is named */
    for (int k = 0; k < dim; ++k) x2[30 * dim + k] = x[3 * dim + k];
    x2[30 * dim + 1] += 0.199;
    EXPECT_FAIL(s, ODHS_E_OVERLAP, odhs_system_set_positions(s, x2));
    m = odhs_system_errmsg(s);
    ck_assert_msg(tu_msg_has_index(m, I) && tu_msg_has_index(m, J), "message does not name 12 and 57: %s",
                  m);
    EXPECT_FAIL(s, ODHS_E_OVERLAP, odhs_system_set_configuration(s, L, 0.0, r, x2));
    m = odhs_system_errmsg(s);
    ck_assert(tu_msg_has_index(m, I) && tu_msg_has_index(m, J));

    /* overlap through the periodic boundary */
    memcpy(x2, x, sizeof x);
    x2[5 * dim + 0] = 0.05;
    x2[5 * dim + 1] = 0.9;
    x2[40 * dim + 0] = L[0] - 0.08;
    x2[40 * dim + 1] = 0.9;
    if (dim == 3) x2[5 * dim + 2] = x2[40 * dim + 2] = 0.9;
    EXPECT_FAIL(s, ODHS_E_OVERLAP, odhs_system_set_positions(s, x2));
    m = odhs_system_errmsg(s);
    ck_assert_msg(tu_msg_has_index(m, 5) && tu_msg_has_index(m, 40), "message does not name 5 and 40: %s", m);

    /* overlap created by new radii */
    memcpy(x2, x, sizeof x);
    for (int k = 0; k < dim; ++k) x2[J * dim + k] = x[I * dim + k];
    x2[J * dim + 0] += 0.3;
    ck_assert_int_eq(odhs_system_set_positions(s, x2), ODHS_OK);
    double r2[64];
    memcpy(r2, r, sizeof r);
    r2[J] = 0.25;
    EXPECT_FAIL(s, ODHS_E_OVERLAP, odhs_system_set_radii(s, r2));
    m = odhs_system_errmsg(s);
    ck_assert(tu_msg_has_index(m, I) && tu_msg_has_index(m, J));
    ck_assert_int_eq(odhs_system_set_positions(s, x), ODHS_OK);

    /* overlap created by shrinking the box without scaling (wrapping) */
    memcpy(x2, x, sizeof x);
    x2[7 * dim + 0] = 2.0;
    x2[7 * dim + 1] = L[1] - 0.2; /* top */
    x2[9 * dim + 0] = 2.0;
    x2[9 * dim + 1] = 0.1; /* bottom: distance 0.3 through the boundary */
    if (dim == 3) x2[7 * dim + 2] = x2[9 * dim + 2] = 0.9;
    ck_assert_int_eq(odhs_system_set_positions(s, x2), ODHS_OK);
    double Ls[3] = {L[0], L[1] - 0.15, L[2]};
    EXPECT_FAIL(s, ODHS_E_OVERLAP, odhs_system_set_box(s, Ls));
    m = odhs_system_errmsg(s);
    ck_assert_msg(tu_msg_has_index(m, 7) && tu_msg_has_index(m, 9), "message does not name 7 and 9: %s", m);
    odhs_system_destroy(s);
}
END_TEST

START_TEST(test_overlap_strain)
{
    /* i at the top edge, j at the bottom: far apart at zero strain, overlapping
     * through the sheared boundary at strain 0.3 */
    for (int dim = 2; dim <= 3; ++dim) {
        double L[3] = {10, 10, 10}, r[3] = {0.1, 0.1, 0.1};
        double x[9] = {0};
        double p[3][3] = {{1.0, 9.95, 5.0}, {8.0, 0.05, 5.0}, {5.0, 5.0, 5.0}};
        for (int i = 0; i < 3; ++i)
            for (int k = 0; k < dim; ++k) x[i * dim + k] = p[i][k];
        odhs_system *s = new_sys(dim, 3);
        ck_assert_int_eq(odhs_system_set_configuration(s, L, 0.0, r, x), ODHS_OK);
        EXPECT_FAIL(s, ODHS_E_OVERLAP, odhs_system_set_strain(s, 0.3));
        const char *m = odhs_system_errmsg(s);
        ck_assert(tu_msg_has_index(m, 0) && tu_msg_has_index(m, 1));
        EXPECT_FAIL(s, ODHS_E_OVERLAP, odhs_system_set_strain(s, 1.3)); /* same lattice */
        ck_assert_int_eq(odhs_system_set_strain(s, 0.2), ODHS_OK);
        EXPECT_FAIL(s, ODHS_E_OVERLAP, odhs_system_set_configuration(s, L, 0.3, r, x));
        odhs_system_destroy(s);
    }
}
END_TEST

START_TEST(test_overlap_tolerance)
{
    for (int dim = 2; dim <= 3; ++dim) {
        double L[3] = {4, 4, 4}, r[2] = {0.25, 0.25};
        double d = 0.5 * (1.0 - 1e-12); /* overlap 5e-13: below 1e-10 of the contact distance */
        double x[6] = {0};
        for (int k = 0; k < dim; ++k) x[k] = x[dim + k] = 2.0;
        x[dim] += d;
        odhs_system *s = new_sys(dim, 2);
        ck_assert_int_eq(odhs_system_set_configuration(s, L, 0.0, r, x), ODHS_OK);
        EXPECT_FAIL(s, ODHS_E_OVERLAP, odhs_system_validate(s, 0.0));
        ck_assert_int_eq(odhs_system_validate(s, 1e-9), ODHS_OK);
        int st = odhs_system_validate(s, NAN);
        ck_assert(st < 0);
        st = odhs_system_validate(s, -1.0);
        ck_assert(st < 0);
        /* a real overlap is refused */
        x[dim] = 2.0 + 0.5 * (1.0 - 1e-8);
        EXPECT_FAIL(s, ODHS_E_OVERLAP, odhs_system_set_positions(s, x));
        /* exact contact is fine */
        x[dim] = 2.5; /* exactly representable: gap exactly 0 */
        ck_assert_int_eq(odhs_system_set_positions(s, x), ODHS_OK);
        ck_assert_int_eq(odhs_system_validate(s, 0.0), ODHS_OK);
        tu_pairlist pl;
        tu_pairlist_init(&pl, dim);
        ck_assert_int_eq(odhs_system_for_each_pair(s, 0.0, tu_pair_collect, &pl), ODHS_OK);
        ck_assert_uint_eq(pl.n, 1);
        ck_assert(pl.p[0].gap == 0.0);
        tu_pairlist_free(&pl);
        odhs_system_destroy(s);
    }
}
END_TEST

START_TEST(test_nonfinite)
{
    const double bad[] = {NAN, INFINITY, -INFINITY};
    for (int dim = 2; dim <= 3; ++dim) {
        const size_t n = 8;
        double L[3] = {6, 6, 6}, r[8], x[24], x2[24], r2[8], L2[3];
        for (size_t i = 0; i < n; ++i) {
            r[i] = 0.2;
            for (int k = 0; k < dim; ++k) x[i * dim + k] = 0.5 + 0.7 * (double)i + 0.1 * k;
        }
        odhs_system *s = new_sys(dim, n);
        ck_assert_int_eq(odhs_system_set_configuration(s, L, 0.2, r, x), ODHS_OK);
        for (size_t b = 0; b < 3; ++b) {
            memcpy(x2, x, sizeof x);
            x2[5 * dim + 1] = bad[b];
            EXPECT_FAIL(s, ODHS_E_NONFINITE, odhs_system_set_positions(s, x2));
            EXPECT_FAIL(s, ODHS_E_NONFINITE, odhs_system_set_configuration(s, L, 0.2, r, x2));
            memcpy(r2, r, sizeof r);
            r2[3] = bad[b];
            EXPECT_FAIL(s, ODHS_E_NONFINITE, odhs_system_set_radii(s, r2));
            EXPECT_FAIL(s, ODHS_E_NONFINITE, odhs_system_set_configuration(s, L, 0.2, r2, x));
            memcpy(L2, L, sizeof L);
            L2[dim - 1] = bad[b];
            EXPECT_FAIL(s, ODHS_E_NONFINITE, odhs_system_set_box(s, L2));
            EXPECT_FAIL(s, ODHS_E_NONFINITE, odhs_system_set_configuration(s, L2, 0.2, r, x));
            EXPECT_FAIL(s, ODHS_E_NONFINITE, odhs_system_set_strain(s, bad[b]));
            EXPECT_FAIL(s, ODHS_E_NONFINITE, odhs_system_set_configuration(s, L, bad[b], r, x));
            EXPECT_FAIL(s, ODHS_E_NONFINITE, odhs_system_scale_box(s, bad[b]));
        }
        odhs_system_destroy(s);
        /* positions only, radii only */
        s = new_sys(dim, n);
        ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
        x2[0] = NAN;
        EXPECT_FAIL(s, ODHS_E_NONFINITE, odhs_system_set_positions(s, x2));
        r2[0] = INFINITY;
        EXPECT_FAIL(s, ODHS_E_NONFINITE, odhs_system_set_radii(s, r2));
        ck_assert_int_eq(odhs_system_is_ready(s), 0);
        odhs_system_destroy(s);
    }
}
END_TEST

START_TEST(test_nonpositive_radii_and_box)
{
    for (int dim = 2; dim <= 3; ++dim) {
        const size_t n = 4;
        double L[3] = {4, 4, 4}, r[4] = {0.2, 0.2, 0.3, 0.2}, x[12], r2[4], L2[3];
        for (size_t i = 0; i < n; ++i)
            for (int k = 0; k < dim; ++k) x[i * dim + k] = 0.5 + (double)i + 0.1 * k;
        odhs_system *s = new_sys(dim, n);
        ck_assert_int_eq(odhs_system_set_configuration(s, L, -0.4, r, x), ODHS_OK);
        const double badr[] = {0.0, -0.0, -0.1, -INFINITY};
        for (size_t b = 0; b < 4; ++b) {
            memcpy(r2, r, sizeof r);
            r2[2] = badr[b];
            int code = isfinite(badr[b]) ? ODHS_E_INVALID : ODHS_E_NONFINITE;
            EXPECT_FAIL(s, code, odhs_system_set_radii(s, r2));
            EXPECT_FAIL(s, code, odhs_system_set_configuration(s, L, 0.0, r2, x));
        }
        const double badL[] = {0.0, -0.0, -4.0};
        for (size_t b = 0; b < 3; ++b) {
            memcpy(L2, L, sizeof L);
            L2[0] = badL[b];
            EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_set_box(s, L2));
            EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_set_configuration(s, L2, 0.0, r, x));
        }
        /* box shorter than two largest diameters (4 * 0.3 = 1.2) */
        memcpy(L2, L, sizeof L);
        L2[dim - 1] = 1.19;
        EXPECT_FAIL(s, ODHS_E_BOX, odhs_system_set_box(s, L2));
        EXPECT_FAIL(s, ODHS_E_BOX, odhs_system_set_configuration(s, L2, 0.0, r, x));
        memcpy(r2, r, sizeof r);
        r2[1] = 1.01; /* 4 r > L */
        EXPECT_FAIL(s, ODHS_E_BOX, odhs_system_set_radii(s, r2));
        EXPECT_FAIL(s, ODHS_E_BOX, odhs_system_scale_box(s, 0.29));
        EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_scale_box(s, 0.0));
        EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_scale_box(s, -1.0));
        odhs_system_destroy(s);

        /* radii only: the box is checked once positions arrive */
        s = new_sys(dim, n);
        ck_assert_int_eq(odhs_system_set_radii(s, r), ODHS_OK);
        double Ls[3] = {1.0, 1.0, 1.0};
        ck_assert_int_eq(odhs_system_set_box(s, Ls), ODHS_OK);
        EXPECT_FAIL(s, ODHS_E_BOX, odhs_system_set_positions(s, x));
        ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
        ck_assert_int_eq(odhs_system_set_positions(s, x), ODHS_OK);
        odhs_system_destroy(s);

        /* exactly two diameters is allowed */
        s = new_sys(dim, 1);
        double one = 0.25, x1[3] = {0.5, 0.5, 0.5}, Lb[3] = {1.0, 1.0, 1.0};
        ck_assert_int_eq(odhs_system_set_configuration(s, Lb, 0.0, &one, x1), ODHS_OK);
        double big = 0.25000001;
        EXPECT_FAIL(s, ODHS_E_BOX, odhs_system_set_radii(s, &big));
        Lb[dim - 1] = 0.999;
        EXPECT_FAIL(s, ODHS_E_BOX, odhs_system_set_box(s, Lb));
        odhs_system_destroy(s);
    }
}
END_TEST

START_TEST(test_species_labels)
{
    odhs_system *s = new_sys(2, 3);
    char buf[ODHS_SPECIES_MAX + 1];
    const char *good[] = {"S", "Big_1", "ABCDEFGHIJKLMNO", "a-b.c+d", "~!@#$%^&*()"};
    for (size_t k = 0; k < sizeof good / sizeof good[0]; ++k) {
        ck_assert_int_eq(odhs_system_set_species(s, 1, good[k]), ODHS_OK);
        ck_assert_int_eq(odhs_system_get_species(s, 1, buf, sizeof buf), ODHS_OK);
        ck_assert_str_eq(buf, good[k]);
    }
    ck_assert_uint_eq(strlen("ABCDEFGHIJKLMNO"), ODHS_SPECIES_MAX);
    ck_assert_int_eq(odhs_system_set_species(s, 1, "Big"), ODHS_OK);
    const char *bad[] = {"", "ABCDEFGHIJKLMNOP", "a b", " a", "a\tb", "a\nb", "a\"b", "a'b", "\x7f",
                         "\xc3\xa9", "a\x01"};
    for (size_t k = 0; k < sizeof bad / sizeof bad[0]; ++k) {
        EXPECT_FAIL(s, ODHS_E_INVALID, odhs_system_set_species(s, 1, bad[k]));
        ck_assert_int_eq(odhs_system_get_species(s, 1, buf, sizeof buf), ODHS_OK);
        ck_assert_str_eq(buf, "Big");
    }
    /* other particles unaffected */
    ck_assert_int_eq(odhs_system_get_species(s, 0, buf, sizeof buf), ODHS_OK);
    ck_assert_str_eq(buf, "A");
    /* buffer too small */
    char small[3] = {'x', 'x', 'x'};
    int st = odhs_system_get_species(s, 1, small, 3);
    ck_assert_msg(st == ODHS_E_INVALID || st == ODHS_E_RANGE, "get_species with a short buffer: %d", st);
    ck_assert_int_eq(odhs_system_get_species(s, 1, small, 0), st);
    ck_assert_int_eq(odhs_system_get_species(s, 1, buf, sizeof buf), ODHS_OK);
    odhs_system_destroy(s);
}
END_TEST

START_TEST(test_scale_box)
{
    for (int dim = 2; dim <= 3; ++dim) {
        double L[3] = {10, 10, 10}, r[2] = {0.1, 0.1}, x[6] = {0};
        for (int k = 0; k < dim; ++k) {
            x[k] = 5.0;
            x[dim + k] = 5.0;
        }
        x[dim] += 0.25; /* gap 0.05 */
        odhs_system *s = new_sys(dim, 2);
        ck_assert_int_eq(odhs_system_set_configuration(s, L, 0.4, r, x), ODHS_OK);
        EXPECT_FAIL(s, ODHS_E_OVERLAP, odhs_system_scale_box(s, 0.7));
        const char *m = odhs_system_errmsg(s);
        ck_assert(tu_msg_has_index(m, 0) && tu_msg_has_index(m, 1));
        ck_assert_int_eq(odhs_system_scale_box(s, 0.81), ODHS_OK);
        double Lg[3], g, d, rij[3];
        ck_assert_int_eq(odhs_system_get_box(s, Lg), ODHS_OK);
        for (int k = 0; k < dim; ++k) ck_assert(Lg[k] == 10.0 * 0.81);
        ck_assert_int_eq(odhs_system_get_strain(s, &g), ODHS_OK);
        ck_assert(g == 0.4);
        ck_assert_int_eq(odhs_system_separation(s, 0, 1, rij, &d, NULL), ODHS_OK);
        ck_assert_double_eq_tol(d, 0.25 * 0.81, 1e-14);
        ck_assert_int_eq(odhs_system_scale_box(s, 2.0), ODHS_OK);
        ck_assert_int_eq(odhs_system_separation(s, 0, 1, rij, &d, NULL), ODHS_OK);
        ck_assert_double_eq_tol(d, 0.25 * 0.81 * 2.0, 1e-14);
        odhs_system_destroy(s);

        /* radii only: the box is scaled; positions only likewise */
        s = new_sys(dim, 2);
        ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
        ck_assert_int_eq(odhs_system_set_radii(s, r), ODHS_OK);
        ck_assert_int_eq(odhs_system_scale_box(s, 0.5), ODHS_OK);
        ck_assert_int_eq(odhs_system_get_box(s, Lg), ODHS_OK);
        ck_assert(Lg[0] == 5.0);
        ck_assert_int_eq(odhs_system_is_ready(s), 0);
        odhs_system_destroy(s);
        s = new_sys(dim, 2);
        ck_assert_int_eq(odhs_system_set_box(s, L), ODHS_OK);
        ck_assert_int_eq(odhs_system_set_positions(s, x), ODHS_OK);
        ck_assert_int_eq(odhs_system_scale_box(s, 0.5), ODHS_OK);
        double xg[6];
        ck_assert_int_eq(odhs_system_get_positions(s, xg), ODHS_OK);
        for (int k = 0; k < 2 * dim; ++k) ck_assert(xg[k] == x[k] * 0.5);
        ck_assert_int_eq(odhs_system_is_ready(s), 0);
        odhs_system_destroy(s);
    }
}
END_TEST

START_TEST(test_volume_packing_fraction)
{
    for (int dim = 2; dim <= 3; ++dim) {
        const pair_case *pc = &pair_cases[dim == 2 ? 4 : 14];
        odhs_system *s = make_random_system(pc->dim, pc->n, pc->L, pc->gamma, pc->rmin, 0.5, pc->seed);
        state a;
        state_get(s, &a);
        double vol, phi, v = 0.0;
        ck_assert_int_eq(odhs_system_volume(s, &vol), ODHS_OK);
        ck_assert(vol == (dim == 2 ? pc->L[0] * pc->L[1] : pc->L[0] * pc->L[1] * pc->L[2]));
        for (size_t i = 0; i < pc->n; ++i)
            v += dim == 2 ? TU_PI * a.r[i] * a.r[i] : 4.0 / 3.0 * TU_PI * pow(a.r[i], 3);
        ck_assert_int_eq(odhs_system_packing_fraction(s, &phi), ODHS_OK);
        ck_assert(tu_close(phi, v / vol, 1e-13));
        state_free(&a);
        odhs_system_destroy(s);
    }
}
END_TEST

/* ------------------------------------------------------------------------ */
/* clone                                                                      */
/* ------------------------------------------------------------------------ */

START_TEST(test_clone)
{
    const pair_case *pc = &pair_cases[15];
    odhs_system *s = make_random_system(pc->dim, pc->n, pc->L, pc->gamma, pc->rmin, 0.5, pc->seed);
    ck_assert_int_eq(odhs_system_set_species(s, 0, "Big"), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_species(s, 1, "Small"), ODHS_OK);
    odhs_system *c = NULL;
    ck_assert_int_eq(odhs_system_clone(s, &c), ODHS_OK);
    ck_assert_ptr_nonnull(c);
    ck_assert_ptr_ne(c, s);
    tu_snapshot ss, cs;
    tu_snapshot_take(s, &ss);
    tu_snapshot_take(c, &cs);
    ck_assert(ss.st_r == ODHS_OK && ss.st_x == ODHS_OK && ss.ready);
    ck_assert(tu_snapshot_equal(&ss, &cs));
    ck_assert_ptr_nonnull(odhs_system_errmsg(c));

    /* independent: changing the clone leaves the original alone */
    ck_assert_int_eq(odhs_system_scale_box(c, 1.2), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_species(c, 0, "Other"), ODHS_OK);
    double *r = malloc(pc->n * sizeof *r);
    ck_assert_ptr_nonnull(r);
    memcpy(r, ss.r, pc->n * sizeof *r);
    r[5] *= 0.5;
    ck_assert_int_eq(odhs_system_set_radii(c, r), ODHS_OK);
    ck_assert(tu_snapshot_matches(s, &ss));
    /* and the other way round */
    tu_snapshot cs2;
    tu_snapshot_take(c, &cs2);
    ck_assert_int_eq(odhs_system_scale_box(s, 1.1), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_species(s, 2, "X"), ODHS_OK);
    ck_assert(tu_snapshot_matches(c, &cs2));
    /* the clone survives the original */
    odhs_system_destroy(s);
    ck_assert(tu_snapshot_matches(c, &cs2));
    ck_assert_int_eq(odhs_system_validate(c, 0.0), ODHS_OK);
    compare_pairs(c, 0.2, "clone");
    odhs_system_destroy(c);
    tu_snapshot_free(&ss);
    tu_snapshot_free(&cs);
    tu_snapshot_free(&cs2);
    free(r);

    /* clone of a partially set system */
    s = new_sys(2, 3);
    double rr[3] = {0.1, 0.2, 0.1};
    ck_assert_int_eq(odhs_system_set_radii(s, rr), ODHS_OK);
    ck_assert_int_eq(odhs_system_clone(s, &c), ODHS_OK);
    tu_snapshot_take(s, &ss);
    tu_snapshot_take(c, &cs);
    ck_assert(tu_snapshot_equal(&ss, &cs));
    ck_assert_int_eq(cs.st_x, ODHS_E_STATE);
    ck_assert_int_eq(odhs_system_is_ready(c), 0);
    tu_snapshot_free(&ss);
    tu_snapshot_free(&cs);
    odhs_system_destroy(c);
    odhs_system_destroy(s);
}
END_TEST

/* ------------------------------------------------------------------------ */

Suite *make_system_suite(void)
{
    Suite *s = suite_create("system");
    TCase *tc;

    tc = tcase_create("status");
    tcase_add_test(tc, test_version);
    tcase_add_test(tc, test_strerror);
    suite_add_tcase(s, tc);

    tc = tcase_create("handle");
    tcase_add_test(tc, test_create_errors);
    tcase_add_test(tc, test_create_defaults);
    tcase_add_test(tc, test_null_handle);
    tcase_add_test(tc, test_null_arguments);
    tcase_add_test(tc, test_state_errors);
    tcase_add_test(tc, test_range_errors);
    tcase_add_test(tc, test_clone);
    suite_add_tcase(s, tc);

    tc = tcase_create("geometry");
    tcase_add_loop_test(tc, test_min_image, 0, 2);
    tcase_add_test(tc, test_min_image_le_boundary);
    tcase_add_loop_test(tc, test_strain_remap, 0, 2);
    tcase_add_loop_test(tc, test_strain_remap_nonsquare, 0, 4);
    tcase_add_loop_test(tc, test_wrap_outside, 0, 2);
    tcase_add_loop_test(tc, test_wrap_inside_bitwise, 0, 2);
    tcase_add_loop_test(tc, test_wrap_on_set_box, 0, 2);
    tcase_add_test(tc, test_volume_packing_fraction);
    suite_add_tcase(s, tc);

    tc = tcase_create("pairs");
    tcase_add_loop_test(tc, test_pairs_brute, 0, N_PAIR_CASES);
    tcase_add_loop_test(tc, test_pairs_shear_direction, 0, 6);
    tcase_add_test(tc, test_pairs_after_scale_box);
    tcase_add_test(tc, test_pairs_stop);
    tcase_add_test(tc, test_pairs_invalid_gap);
    tcase_add_test(tc, test_pairs_single_particle);
    suite_add_tcase(s, tc);

    tc = tcase_create("builders");
    tcase_add_test(tc, test_bidisperse);
    tcase_add_loop_test(tc, test_place_random, 0, (int)(sizeof place_cases / sizeof place_cases[0]));
    tcase_add_test(tc, test_place_random_errors);
    suite_add_tcase(s, tc);

    tc = tcase_create("validation");
    tcase_add_loop_test(tc, test_overlap_named, 0, 2);
    tcase_add_test(tc, test_overlap_strain);
    tcase_add_test(tc, test_overlap_tolerance);
    tcase_add_test(tc, test_nonfinite);
    tcase_add_test(tc, test_nonpositive_radii_and_box);
    tcase_add_test(tc, test_species_labels);
    tcase_add_test(tc, test_scale_box);
    suite_add_tcase(s, tc);

    return s;
}
