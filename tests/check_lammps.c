/*
 * libodhs - tests for the LAMMPS data-file reader and writer (lammps.h).
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <check.h>
#include <dirent.h>
#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "odhs.h"
#include "odhs/lammps.h"
#include "internal.h"

/* ---- fixture: a private temporary directory per test (tmpfiles.h) ----- */
#include "tmpfiles.h"

static void lmp_setup(void) { tmpdir_make("lammps"); }

static void lmp_teardown(void) { tmpdir_remove(); }

static void write_str(const char *path, const char *text) { write_text(path, text, strlen(text)); }

/* Parse from an exact-size heap copy (no terminating NUL, so a reader that
 * runs past len is caught by ASan). */
static int parse_exact(const char *text, size_t len, odhs_system **out, char *err, size_t errlen)
{
    char *copy = malloc(len ? len : 1);
    ck_assert_ptr_nonnull(copy);
    if (len) memcpy(copy, text, len);
    int st = odhs_lammps_data_parse(copy, len, out, err, errlen);
    free(copy);
    return st;
}

static odhs_system *parse_ok(const char *text)
{
    odhs_system *sys = NULL;
    char err[ODHS_ERRMSG_LEN];
    int st = parse_exact(text, strlen(text), &sys, err, sizeof err);
    ck_assert_msg(st == ODHS_OK, "parse failed: %d %s\n--- input ---\n%s", st, err, text);
    ck_assert_ptr_nonnull(sys);
    ck_assert_str_eq(err, "");
    return sys;
}

static void expect_species(const odhs_system *sys, size_t i, const char *label)
{
    char b[ODHS_SPECIES_MAX + 1];
    ck_assert_int_eq(odhs_system_get_species(sys, i, b, sizeof b), ODHS_OK);
    ck_assert_str_eq(b, label);
}

/* ---- scenes ------------------------------------------------------------------ */

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static double urand(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) * 0x1.0p-53;
}

/*
 * A grid scene in a box of m x m' (x m) cells of side h (non-square: one more
 * cell along x), one jittered particle per cell with radius in [0.1h, 0.2h]
 * (no overlap under any shear), a few particles at the very edges of the box,
 * and species labels that need the title's type list.
 */
static odhs_system *make_scene(int dim, double gamma)
{
    const int mx = 6, m = 5;
    const double h = 2.0137;
    int mz = dim == 3 ? m : 1;
    size_t n = (size_t)(mx * m * mz);
    double L[3] = {mx * h, m * h, m * h};
    double *x = malloc(n * (size_t)dim * sizeof(double));
    double *r = malloc(n * sizeof(double));
    ck_assert_ptr_nonnull(x);
    ck_assert_ptr_nonnull(r);
    size_t i = 0;
    for (int a = 0; a < mx; a++)
        for (int b = 0; b < m; b++)
            for (int c = 0; c < mz; c++, i++) {
                int cell[3] = {a, b, c};
                for (int k = 0; k < dim; k++)
                    x[i * (size_t)dim + (size_t)k] = (cell[k] + 0.5 + 0.1 * (urand() - 0.5)) * h;
                r[i] = h * (0.1 + 0.1 * urand());
            }
#define IDX(a, b, c) ((size_t)(((a)*m + (b)) * mz + (c)))
    double *p = &x[IDX(0, 0, 0) * (size_t)dim]; /* the origin corner */
    p[0] = 0.0;
    p[1] = 0.0;
    p = &x[IDX(0, 3, 0) * (size_t)dim]; /* a tiny x: its shift by Lx rounds */
    p[0] = 1e-9;
    p = &x[IDX(mx - 1, 2, 0) * (size_t)dim]; /* right face */
    p[0] = nextafter(L[0], 0.0);
    p = &x[IDX(2, m - 1, 0) * (size_t)dim]; /* top face */
    p[1] = nextafter(L[1], 0.0);
    if (dim == 3) {
        p = &x[IDX(3, 2, m - 1) * (size_t)dim]; /* back face */
        p[2] = nextafter(L[2], 0.0);
    }
#undef IDX
    odhs_system *sys = NULL;
    ck_assert_int_eq(odhs_system_create(dim, n, &sys), ODHS_OK);
    int st = odhs_system_set_configuration(sys, L, gamma, r, x);
    ck_assert_msg(st == ODHS_OK, "set_configuration: %d %s", st, odhs_system_errmsg(sys));
    static const char *labels[] = {"A", "B", "Big", "ABCDEFGHIJKLMNO", "s_1", "Na+", "1", "#x"};
    for (i = 0; i < n; i++) ck_assert_int_eq(odhs_system_set_species(sys, i, labels[(i * 7) % 8]), ODHS_OK);
    free(x);
    free(r);
    return sys;
}

/* N bidisperse particles (species S and L) placed at random in a box of
 * aspect Lx:Ly(:Lz) = 1.25:1(:0.9), then sheared to gamma: place_random works
 * at strain 0, so seeds from seed on are tried until the sheared images do not
 * overlap (deterministic). */
static odhs_system *make_random(int dim, size_t n, double gamma, uint64_t seed)
{
    for (uint64_t s = seed; s < seed + 1000; s++) {
        odhs_system *sys = NULL;
        ck_assert_int_eq(odhs_system_create(dim, n, &sys), ODHS_OK);
        double L[3] = {1.25, 1.0, 0.9};
        ck_assert_int_eq(odhs_system_set_box(sys, L), ODHS_OK);
        ck_assert_int_eq(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.0, s), ODHS_OK);
        int st = odhs_system_place_random(sys, dim == 2 ? 0.3 : 0.15, s);
        ck_assert_msg(st == ODHS_OK, "place_random: %s", odhs_system_errmsg(sys));
        st = odhs_system_set_strain(sys, gamma);
        if (st == ODHS_OK) return sys;
        ck_assert_int_eq(st, ODHS_E_OVERLAP);
        odhs_system_destroy(sys);
    }
    ck_abort_msg("no random scene could be sheared");
    return NULL;
}

/* ---- comparisons --------------------------------------------------------------- */

typedef struct {
    int dim;
    size_t n;
    double L[3], gamma;
    double *x, *r;
    char (*sp)[ODHS_SPECIES_MAX + 1];
} state;

static void state_get(const odhs_system *sys, state *s)
{
    memset(s, 0, sizeof *s);
    s->dim = odhs_system_dim(sys);
    s->n = odhs_system_count(sys);
    s->L[2] = 1.0;
    ck_assert_int_eq(odhs_system_get_box(sys, s->L), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_strain(sys, &s->gamma), ODHS_OK);
    s->x = malloc(s->n * (size_t)s->dim * sizeof(double));
    s->r = malloc(s->n * sizeof(double));
    s->sp = malloc(s->n * sizeof *s->sp);
    ck_assert(s->x && s->r && s->sp);
    ck_assert_int_eq(odhs_system_get_positions(sys, s->x), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(sys, s->r), ODHS_OK);
    for (size_t i = 0; i < s->n; i++)
        ck_assert_int_eq(odhs_system_get_species(sys, i, s->sp[i], sizeof s->sp[i]), ODHS_OK);
}

static void state_free(state *s)
{
    free(s->x);
    free(s->r);
    free(s->sp);
}

/*
 * The library's own round trip: box, strain, radii, species, y and z bit for
 * bit; x modulo Lx, bit for bit when exact_x, else up to one rounding of the
 * writer's shift by Lx (an ulp of Lx). Returns how many x differ from the
 * original by a nonzero multiple of Lx.
 */
static size_t assert_same_mod_x(const odhs_system *s1, const odhs_system *s2, int exact_x)
{
    state a, b;
    state_get(s1, &a);
    state_get(s2, &b);
    ck_assert_int_eq(a.dim, b.dim);
    ck_assert_uint_eq(a.n, b.n);
    ck_assert_msg(memcmp(a.L, b.L, (size_t)a.dim * sizeof(double)) == 0, "box differs");
    ck_assert_msg(memcmp(&a.gamma, &b.gamma, sizeof a.gamma) == 0, "strain %.17g != %.17g", a.gamma, b.gamma);
    ck_assert_msg(memcmp(a.r, b.r, a.n * sizeof(double)) == 0, "radii differ");
    size_t shifted = 0;
    int dim = a.dim;
    double Lx = a.L[0];
    for (size_t i = 0; i < a.n; i++) {
        ck_assert_str_eq(a.sp[i], b.sp[i]);
        for (int k = 1; k < dim; k++) {
            size_t c = i * (size_t)dim + (size_t)k;
            ck_assert_msg(memcmp(&a.x[c], &b.x[c], sizeof(double)) == 0, "particle %zu coordinate %d: %.17g != %.17g",
                          i, k, a.x[c], b.x[c]);
        }
        double x1 = a.x[i * (size_t)dim], x2 = b.x[i * (size_t)dim];
        if (memcmp(&x1, &x2, sizeof x1) == 0) continue;
        ck_assert_msg(!exact_x, "particle %zu: x %.17g != %.17g", i, x1, x2);
        double d = x2 - x1, k = nearbyint(d / Lx);
        ck_assert_msg(fabs(d - k * Lx) <= DBL_EPSILON * Lx, "particle %zu: x %.17g != %.17g modulo Lx = %.17g", i,
                      x1, x2, Lx);
        if (k != 0.0) shifted++;
    }
    state_free(&a);
    state_free(&b);
    return shifted;
}

/* ---- round trips ----------------------------------------------------------------- */

static const double rt_strains[] = {0.0, 0.3, -0.45, 0.123456789012345678, 0.6};

static void roundtrip(int dim, double gamma)
{
    odhs_system *sys = make_scene(dim, gamma);
    char path[1024], err[ODHS_ERRMSG_LEN];
    tmppath(path, sizeof path, "rt.data");
    int st = odhs_lammps_data_write(sys, path);
    ck_assert_msg(st == ODHS_OK, "write: %d %s", st, odhs_system_errmsg(sys));
    ck_assert_int_eq(count_dir_entries(), 1); /* no temporary file left */
    odhs_system *back = NULL;
    st = odhs_lammps_data_read(path, &back, err, sizeof err);
    ck_assert_msg(st == ODHS_OK, "read: %d %s", st, err);
    double g = 0.0;
    ck_assert_int_eq(odhs_system_get_strain(sys, &g), ODHS_OK);
    assert_same_mod_x(sys, back, g == 0.0);

    /* the file itself: x inside LAMMPS's parallelogram, tilt in [-Lx/2, Lx/2] */
    char *t = slurp(path, NULL);
    double L[3] = {0, 0, 1};
    ck_assert_int_eq(odhs_system_get_box(sys, L), ODHS_OK);
    const char *p = strstr(t, " xy xz yz\n");
    ck_assert_ptr_nonnull(p);
    while (p > t && p[-1] != '\n') p--;
    double xy = 0, xz = 1, yz = 1;
    ck_assert_int_eq(sscanf(p, "%lf %lf %lf", &xy, &xz, &yz), 3);
    ck_assert(fabs(xy) <= L[0] / 2 && xz == 0.0 && yz == 0.0);
    p = strstr(t, "Atoms # sphere\n\n");
    ck_assert_ptr_nonnull(p);
    p += strlen("Atoms # sphere\n\n");
    size_t n = odhs_system_count(sys), lines = 0;
    for (; *p; lines++) {
        unsigned long id;
        int type;
        double d, rho, x, y, z;
        ck_assert_int_eq(sscanf(p, "%lu %d %lf %lf %lf %lf %lf", &id, &type, &d, &rho, &x, &y, &z), 7);
        ck_assert_uint_eq(id, lines + 1);
        ck_assert(rho == 1.0);
        double s = x - xy * y / L[1];
        ck_assert_msg(s >= 0.0 && s < L[0], "atom %lu outside the parallelogram", id);
        if (dim == 2) ck_assert(z == 0.0);
        p = strchr(p, '\n');
        ck_assert_ptr_nonnull(p);
        p++;
    }
    ck_assert_uint_eq(lines, n);
    free(t);
    odhs_system_destroy(back);
    odhs_system_destroy(sys);
}

START_TEST(test_roundtrip_2d)
{
    roundtrip(2, rt_strains[_i]);
}
END_TEST

START_TEST(test_roundtrip_3d)
{
    roundtrip(3, rt_strains[_i]);
}
END_TEST

/* A random bidisperse system (species S and L) through write and parse. */
START_TEST(test_roundtrip_random)
{
    int dim = 2 + _i % 2;
    double gamma = _i < 2 ? 0.3 : -0.45;
    odhs_system *sys = make_random(dim, 64, gamma, 17 + (uint64_t)_i);
    char path[1024], err[ODHS_ERRMSG_LEN];
    tmppath(path, sizeof path, "random.data");
    ck_assert_int_eq(odhs_lammps_data_write(sys, path), ODHS_OK);
    char *t = slurp(path, NULL);
    ck_assert_ptr_nonnull(strstr(t, "types: 1=S 2=L\n"));
    odhs_system *back = NULL;
    ck_assert_int_eq(parse_exact(t, strlen(t), &back, err, sizeof err), ODHS_OK);
    size_t shifted = assert_same_mod_x(sys, back, 0);
    (void)shifted;
    free(t);
    odhs_system_destroy(back);
    odhs_system_destroy(sys);
}
END_TEST

/* The writer produces exactly the documented format. */
START_TEST(test_write_format)
{
    char path[1024], expect[2048];
    tmppath(path, sizeof path, "fmt.data");
    odhs_system *sys = NULL;

    /* 2D, sheared: xy = 0.125 * 8 = 1; particle 2 at (0.25, 4) lies left of the
     * parallelogram (0.25 - 1 * 4/8 < 0) and is written at x + Lx */
    double L2[2] = {4.0, 8.0}, r2[2] = {0.5, 0.25}, x2[4] = {1.5, 6, 0.25, 4};
    ck_assert_int_eq(odhs_system_create(2, 2, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_configuration(sys, L2, 0.125, r2, x2), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_species(sys, 0, "S"), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_species(sys, 1, "L"), ODHS_OK);
    ck_assert_int_eq(odhs_lammps_data_write(sys, path), ODHS_OK);
    char *t = slurp(path, NULL);
    snprintf(expect, sizeof expect,
             "LAMMPS data file written by libodhs %s: dim=2 strain=0.125 types: 1=S 2=L\n"
             "\n"
             "2 atoms\n"
             "2 atom types\n"
             "\n"
             "0 4 xlo xhi\n"
             "0 8 ylo yhi\n"
             "-0.5 0.5 zlo zhi\n"
             "1 0 0 xy xz yz\n"
             "\n"
             "Atoms # sphere\n"
             "\n"
             "1 1 1 1 1.5 6 0\n"
             "2 2 0.5 1 4.25 4 0\n",
             odhs_version_string());
    ck_assert_str_eq(t, expect);
    free(t);
    odhs_system_destroy(sys);

    /* 3D, unsheared (the tilt line is still written), one species */
    double L3[3] = {4.0, 5.0, 6.0}, r3[2] = {0.5, 0.1}, x3[6] = {1, 2, 3, 3, 4, 5};
    ck_assert_int_eq(odhs_system_create(3, 2, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_configuration(sys, L3, 0.0, r3, x3), ODHS_OK);
    ck_assert_int_eq(odhs_lammps_data_write(sys, path), ODHS_OK);
    t = slurp(path, NULL);
    snprintf(expect, sizeof expect,
             "LAMMPS data file written by libodhs %s: dim=3 strain=0 types: 1=A\n"
             "\n"
             "2 atoms\n"
             "1 atom types\n"
             "\n"
             "0 4 xlo xhi\n"
             "0 5 ylo yhi\n"
             "0 6 zlo zhi\n"
             "0 0 0 xy xz yz\n"
             "\n"
             "Atoms # sphere\n"
             "\n"
             "1 1 1 1 1 2 3\n"
             "2 1 0.20000000000000001 1 3 4 5\n",
             odhs_version_string());
    ck_assert_str_eq(t, expect);
    free(t);
    ck_assert_int_eq(count_dir_entries(), 1);
    odhs_system_destroy(sys);
}
END_TEST

/* ---- hand-written files ------------------------------------------------------------ */

/* As LAMMPS's write_data writes it, with more: other header lines, a Masses
 * section, image flags, ids out of order, a Velocities section, comments. */
static const char *lammps_style =
    "LAMMPS data file via write_data, version 29 Sep 2021, timestep = 1000\n"
    "\n"
    "4 atoms\n"
    "2 atom types\n"
    "0 bonds\n"
    "0 extra bond per atom\n"
    "\n"
    "-5 5 xlo xhi\n"
    "-4 4 ylo yhi\n"
    "-0.5 0.5 zlo zhi\n"
    "1.5 0 0 xy xz yz\n"
    "\n"
    "Masses\n"
    "\n"
    "1 0.785\n"
    "2 1.54\n"
    "\n"
    "Atoms # sphere\n"
    "\n"
    "3 2 1.4 1 1.5 2 0 0 0 0\n"
    "1 1 1 1 -4 -3 0 1 -1 0\n"
    "4 1 1 2.5 4.5 3.5 0 -1 0 0\n"
    "2 2 1.4 1 0 0 0 0 0 0\n"
    "\n"
    "Velocities\n"
    "\n"
    "1 0.1 0.2 0 0 0 0.3\n"
    "3 0 0 0 0 0 0\n"
    "2 0 0 0 0 0 0\n"
    "4 0 0 0 0 0 0\n";

static void check_lammps_style(const odhs_system *sys)
{
    ck_assert_int_eq(odhs_system_dim(sys), 2);
    ck_assert_uint_eq(odhs_system_count(sys), 4);
    double L[2], g, x[8], r[4];
    ck_assert_int_eq(odhs_system_get_box(sys, L), ODHS_OK);
    ck_assert(L[0] == 10.0 && L[1] == 8.0);
    ck_assert_int_eq(odhs_system_get_strain(sys, &g), ODHS_OK);
    ck_assert(g == 1.5 / 8.0);
    ck_assert_int_eq(odhs_system_get_positions(sys, x), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(sys, r), ODHS_OK);
    const double xe[8] = {1, 1, 5, 4, 6.5, 6, 9.5, 7.5}; /* relative to (xlo, ylo), by id */
    const double re[4] = {0.5, 0.7, 0.7, 0.5};
    for (int k = 0; k < 8; k++) ck_assert_msg(x[k] == xe[k], "x[%d] = %.17g, expected %g", k, x[k], xe[k]);
    for (int k = 0; k < 4; k++) ck_assert(r[k] == re[k]);
    expect_species(sys, 0, "1");
    expect_species(sys, 1, "2");
    expect_species(sys, 2, "2");
    expect_species(sys, 3, "1");
}

START_TEST(test_read_lammps_style)
{
    odhs_system *sys = parse_ok(lammps_style);
    check_lammps_style(sys);
    odhs_system_destroy(sys);

    /* the same with CRLF line ends, no final newline, tabs and comments */
    size_t len = strlen(lammps_style);
    char *crlf = malloc(2 * len + 64);
    ck_assert_ptr_nonnull(crlf);
    size_t k = 0;
    for (size_t i = 0; i < len; i++) {
        if (lammps_style[i] == '\n') {
            if (i + 1 == len) break;
            if (lammps_style[i - 1] != '\n' && lammps_style[i - 1] != 's' && lammps_style[i - 1] != 'e') {
                memcpy(crlf + k, "\t# c", 4); /* a comment after data lines */
                k += 4;
            }
            crlf[k++] = '\r';
        }
        crlf[k++] = lammps_style[i] == ' ' && i % 3 == 0 ? '\t' : lammps_style[i];
    }
    crlf[k] = '\0';
    sys = parse_ok(crlf);
    check_lammps_style(sys);
    odhs_system_destroy(sys);
    free(crlf);
}
END_TEST

START_TEST(test_read_title_keys)
{
    /* title labels, dim and a strain whose product with Ly is not exactly xy */
    const char *text = "title dim=2 strain=0.1 types: 1=Small 2=Large\n"
                       "\n"
                       "2 atoms\n"
                       "2 atom types\n"
                       "0 4 xlo xhi\n"
                       "0 3 ylo yhi\n"
                       "0.30000000000000004 0 0 xy xz yz\n"
                       "Atoms\n"
                       "1 2 1 1 1 1 0\n"
                       "2 1 0.5 1 3 2 0\n";
    odhs_system *sys = parse_ok(text);
    double g = 0;
    ck_assert_int_eq(odhs_system_get_strain(sys, &g), ODHS_OK);
    ck_assert(g == 0.1);
    ck_assert(0.30000000000000004 / 3.0 != 0.1); /* the title's strain made the difference */
    expect_species(sys, 0, "Large");
    expect_species(sys, 1, "Small");
    odhs_system_destroy(sys);

    /* the title's strain describes another lattice: xy/Ly is used */
    sys = parse_ok("strain=0.2\n2 atoms\n1 atom types\n0 4 xlo xhi\n0 3 ylo yhi\n"
                   "0.30000000000000004 0 0 xy xz yz\nAtoms # sphere\n1 1 1 1 1 1 0\n2 1 1 1 3 2 0\n");
    ck_assert_int_eq(odhs_system_get_strain(sys, &g), ODHS_OK);
    ck_assert(g == 0.30000000000000004 / 3.0);
    odhs_system_destroy(sys);

    /* ... but one that differs by a whole Lx from xy is kept (the same lattice) */
    sys = parse_ok("strain=0.1 and more words\n2 atoms\n1 atom types\n0 4 xlo xhi\n0 3 ylo yhi\n"
                   "-3.7 0 0 xy xz yz\nAtoms # sphere\n1 1 1 1 1 1 0\n2 1 1 1 3 2 0\n");
    ck_assert_int_eq(odhs_system_get_strain(sys, &g), ODHS_OK);
    ck_assert(g == 0.1);
    odhs_system_destroy(sys);

    /* a partial type list: the others are numbered */
    sys = parse_ok("types: 2=B\n3 atoms\n3 atom types\n0 9 xlo xhi\n0 9 ylo yhi\nAtoms\n"
                   "1 1 1 1 1 1 0\n2 2 1 1 4 4 0\n3 3 1 1 7 7 0\n");
    expect_species(sys, 0, "1");
    expect_species(sys, 1, "B");
    expect_species(sys, 2, "3");
    odhs_system_destroy(sys);
}
END_TEST

/* dim from the title, else 2 iff every z is 0 and zlo < 0 < zhi */
START_TEST(test_read_dimension)
{
    const char *body = "\n2 atoms\n1 atom types\n-2 6 xlo xhi\n0 8 ylo yhi\n%s\nAtoms # sphere\n\n"
                       "1 1 0.4 1 1 1 %s\n2 1 0.4 1 5 5 %s\n";
    struct {
        const char *title, *zline, *z1, *z2;
        int dim;
        double Lz, z0; /* 3D: the box edge and particle 0's z - zlo */
    } cases[] = {
        {"monolayer", "-1 1 zlo zhi", "0", "0", 2, 0, 0},
        {"no z line", "", "0", "-0", 2, 0, 0},
        {"z from 0", "0 5 zlo zhi", "0", "0", 3, 5, 0},
        {"z not 0", "-1 1 zlo zhi", "0", "0.5", 3, 2, 1},
        {"x dim=3", "-1 1 zlo zhi", "0", "0", 3, 2, 1},
        {"x dim=3 (LAMMPS's default z)", "", "0", "0", 3, 1, 0.5},
        {"dim=2", "0 5 zlo zhi", "0", "0", 2, 0, 0},
    };
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        char text[512];
        int len = snprintf(text, sizeof text, "%s", cases[c].title);
        snprintf(text + len, sizeof text - (size_t)len, body, cases[c].zline, cases[c].z1, cases[c].z2);
        odhs_system *sys = parse_ok(text);
        ck_assert_msg(odhs_system_dim(sys) == cases[c].dim, "case %zu: dim %d", c, odhs_system_dim(sys));
        double L[3], x[6];
        ck_assert_int_eq(odhs_system_get_box(sys, L), ODHS_OK);
        ck_assert(L[0] == 8.0 && L[1] == 8.0);
        ck_assert_int_eq(odhs_system_get_positions(sys, x), ODHS_OK);
        ck_assert(x[0] == 3.0 && x[1] == 1.0); /* relative to xlo = -2 */
        if (cases[c].dim == 3) {
            ck_assert_msg(L[2] == cases[c].Lz, "case %zu: Lz %g", c, L[2]);
            ck_assert_msg(x[2] == cases[c].z0, "case %zu: z %g", c, x[2]);
        }
        odhs_system_destroy(sys);
    }
}
END_TEST

/* ---- malformed input ------------------------------------------------------------------ */

#define HDR_BODY                                                                                \
    "\n3 atoms\n2 atom types\n0 10 xlo xhi\n0 10 ylo yhi\n-0.5 0.5 zlo zhi\n0 0 0 xy xz yz\n\n" \
    "Atoms # sphere\n\n"
#define HDR "t\n" HDR_BODY
/* HDR ends on line 11; the atoms are on lines 12, 13, 14 */
#define A1 "1 1 1 1 1 1 0\n"
#define A2 "2 2 1 1 4 4 0\n"
#define A3 "3 1 1 1 7 7 0\n"

typedef struct {
    const char *name, *text;
    int code;
    size_t line; /* the message names it (0: no line expected) */
    const char *needle; /* and contains this */
} bad_case;

static const bad_case bad_cases[] = {
    {"empty", "", ODHS_E_FORMAT, 1, "empty"},
    {"no Atoms section", "t\n\n3 atoms\n2 atom types\n0 10 xlo xhi\n0 10 ylo yhi\n\nVelocities\n\n1 0 0 0 0 0 0\n",
     ODHS_E_FORMAT, 11, "Atoms"},
    {"header only", "t\n3 atoms\n2 atom types\n0 10 xlo xhi\n0 10 ylo yhi\n", ODHS_E_FORMAT, 6, "Atoms"},
    {"duplicate id", HDR A1 A2 "2 1 1 1 7 7 0\n", ODHS_E_FORMAT, 14, "duplicate atom id 2 (first on line 13)"},
    {"id out of range", HDR A1 A2 "4 1 1 1 7 7 0\n", ODHS_E_FORMAT, 14, "not in 1..3"},
    {"id 0", HDR "0 1 1 1 1 1 0\n" A2 A3, ODHS_E_FORMAT, 12, "not in 1..3"},
    {"id negative", HDR "-1 1 1 1 1 1 0\n" A2 A3, ODHS_E_FORMAT, 12, "invalid atom id"},
    {"type out of range", HDR A1 "2 3 1 1 4 4 0\n" A3, ODHS_E_FORMAT, 13, "type 3 is not in 1..2"},
    {"type 0", HDR A1 "2 0 1 1 4 4 0\n" A3, ODHS_E_FORMAT, 13, "not in 1..2"},
    {"type label", HDR A1 "2 S 1 1 4 4 0\n" A3, ODHS_E_FORMAT, 13, "invalid atom type"},
    {"non-numeric x", HDR A1 A2 "3 1 1 1 7x 7 0\n", ODHS_E_FORMAT, 14, "column 5 (x): invalid number '7x'"},
    {"non-numeric diameter", HDR A1 "2 2 abc 1 4 4 0\n" A3, ODHS_E_FORMAT, 13, "diameter"},
    {"nan y", HDR A1 A2 "3 1 1 1 7 nan 0\n", ODHS_E_FORMAT, 14, "non-finite"},
    {"too few columns", HDR A1 "2 2 1 1 4 4\n" A3, ODHS_E_FORMAT, 13, "found 6"},
    {"8 columns", HDR A1 "2 2 1 1 4 4 0 0\n" A3, ODHS_E_FORMAT, 13, "found 8"},
    {"image flag", HDR A1 "2 2 1 1 4 4 0 0 0.5 0\n" A3, ODHS_E_FORMAT, 13, "image flag"},
    {"nonzero xz", "t\n3 atoms\n2 atom types\n0 10 xlo xhi\n0 10 ylo yhi\n1 0.5 0 xy xz yz\nAtoms\n" A1 A2 A3,
     ODHS_E_FORMAT, 6, "xz"},
    {"nonzero yz", "t\n3 atoms\n2 atom types\n0 10 xlo xhi\n0 10 ylo yhi\n1 0 -1e-300 xy xz yz\nAtoms\n" A1 A2 A3,
     ODHS_E_FORMAT, 6, "only x-y shear"},
    {"negative diameter", HDR A1 "2 2 -1 1 4 4 0\n" A3, ODHS_E_FORMAT, 13, "diameter must be positive"},
    {"zero diameter", HDR A1 "2 2 0 1 4 4 0\n" A3, ODHS_E_FORMAT, 13, "point particles"},
    {"subnormal diameter", HDR A1 "2 2 4.9406564584124654e-324 1 4 4 0\n" A3, ODHS_E_FORMAT, 13, "too small"},
    {"zero density", HDR A1 "2 2 1 0 4 4 0\n" A3, ODHS_E_FORMAT, 13, "density"},
    {"atomic style", "t\n3 atoms\n2 atom types\n0 10 xlo xhi\n0 10 ylo yhi\n\nAtoms # atomic\n\n1 1 1 1 0\n",
     ODHS_E_FORMAT, 7, "'atomic'"},
    {"truncated", HDR A1 A2, ODHS_E_FORMAT, 14, "file ends after 2 of 3"},
    {"truncated mid-line", HDR A1 A2 "3 1 1 1 7", ODHS_E_FORMAT, 14, "found 5"},
    {"short section", HDR A1 A2 "\nVelocities\n\n1 0 0 0 0 0 0\n", ODHS_E_FORMAT, 15, "ends after 2 of 3"},
    {"long section", HDR A1 A2 A3 "4 1 1 1 9 9 0\n", ODHS_E_FORMAT, 15, "more than 3"},
    {"N = 0", "t\n0 atoms\n1 atom types\n0 10 xlo xhi\n0 10 ylo yhi\nAtoms\n", ODHS_E_FORMAT, 2, "positive"},
    {"huge N", "t\n1000000000000000000000 atoms\n1 atom types\n", ODHS_E_FORMAT, 2, "too many atoms"},
    {"large N, few lines", "t\n99999999 atoms\n1 atom types\n0 10 xlo xhi\n0 10 ylo yhi\nAtoms\n" A1,
     ODHS_E_FORMAT, 8, "file ends after 1 of 99999999"},
    {"no atoms line", "t\n1 atom types\n0 10 xlo xhi\n0 10 ylo yhi\nAtoms\n" A1, ODHS_E_FORMAT, 5, "<N> atoms"},
    {"no ylo line", "t\n1 atoms\n1 atom types\n0 10 xlo xhi\nAtoms\n" A1, ODHS_E_FORMAT, 5, "ylo yhi"},
    {"0 atom types", "t\n1 atoms\n0 atom types\n", ODHS_E_FORMAT, 3, "positive"},
    {"xhi <= xlo", "t\n1 atoms\n1 atom types\n10 10 xlo xhi\n", ODHS_E_FORMAT, 4, "greater"},
    {"inf box", "t\n1 atoms\n1 atom types\n0 inf xlo xhi\n", ODHS_E_FORMAT, 4, "xhi: non-finite"},
    {"nan tilt", "t\n1 atoms\n1 atom types\nnan 0 0 xy xz yz\n", ODHS_E_FORMAT, 4, "xy: non-finite"},
    {"huge box", "t\n1 atoms\n1 atom types\n-1e308 1e308 xlo xhi\n", ODHS_E_FORMAT, 4, "finite"},
    {"box numbers", "t\n1 atoms\n1 atom types\n0 1 2 xlo xhi\n", ODHS_E_FORMAT, 4, "found 3 numbers"},
    {"no keyword", "t\n1 atoms\n1 atom types\n3 4\n", ODHS_E_FORMAT, 4, "without a keyword"},
    {"number after keyword", "t\n1 atoms\n1 atom types\n3 bonds 4\n", ODHS_E_FORMAT, 4, "after its keyword"},
    {"duplicate atoms line", "t\n1 atoms\n2 atoms\n", ODHS_E_FORMAT, 3, "duplicate"},
    {"atoms count", "t\n1.5 atoms\n", ODHS_E_FORMAT, 2, "invalid number of atoms"},
    {"garbage line", HDR A1 A2 A3 "\n@@@\n", ODHS_E_FORMAT, 16, "'@@@'"},
    {"second Atoms", HDR A1 A2 A3 "\nAtoms\n\n" A1 A2 A3, ODHS_E_FORMAT, 16, "second Atoms"},
    {"dim=4", "x dim=4\n", ODHS_E_FORMAT, 1, "dim"},
    {"bad strain", "strain=abc\n", ODHS_E_FORMAT, 1, "strain"},
    {"type label out of range", "t types: 1=A 3=C\n" HDR_BODY A1 A2 A3, ODHS_E_FORMAT, 1, "type '3'"},
    {"type label invalid", "t types: 1=A 2=ABCDEFGHIJKLMNOP\n" HDR_BODY A1 A2 A3, ODHS_E_FORMAT, 1, "label"},
    {"type label twice", "t types: 1=A 1=B\n" HDR_BODY A1 A2 A3, ODHS_E_FORMAT, 1, "twice"},
    {"dim=2, z != 0", "t dim=2\n" HDR_BODY A1 A2 "3 1 1 1 7 7 0.5\n", ODHS_E_FORMAT, 14, "z = 0.5"},
    {"overlap", HDR A1 A2 "3 1 1 1 4.5 4 0\n", ODHS_E_OVERLAP, 0, "overlap"},
    {"box too small", "t\n1 atoms\n1 atom types\n0 1.5 xlo xhi\n0 1.5 ylo yhi\nAtoms\n" A1, ODHS_E_BOX, 0, ""},
};

START_TEST(test_malformed)
{
    const bad_case *bc = &bad_cases[_i];
    odhs_system *sys = (odhs_system *)&sys; /* must become NULL */
    char err[ODHS_ERRMSG_LEN];
    int st = parse_exact(bc->text, strlen(bc->text), &sys, err, sizeof err);
    ck_assert_msg(st == bc->code, "%s: status %d (%s), expected %d; message: %s", bc->name, st, odhs_strerror(st),
                  bc->code, err);
    ck_assert_msg(sys == NULL, "%s: *out not NULL", bc->name);
    ck_assert_msg(err[0] != '\0', "%s: no message", bc->name);
    if (bc->line) {
        char want[32];
        snprintf(want, sizeof want, "line %zu:", bc->line);
        ck_assert_msg(strncmp(err, want, strlen(want)) == 0, "%s: message '%s' does not start with '%s'", bc->name,
                      err, want);
    }
    ck_assert_msg(strstr(err, bc->needle) != NULL, "%s: message '%s' lacks '%s'", bc->name, err, bc->needle);

    /* the same through a file */
    char path[1024];
    tmppath(path, sizeof path, "bad.data");
    write_str(path, bc->text);
    sys = (odhs_system *)&sys;
    char err2[ODHS_ERRMSG_LEN];
    ck_assert_int_eq(odhs_lammps_data_read(path, &sys, err2, sizeof err2), bc->code);
    ck_assert_ptr_null(sys);
    ck_assert_str_eq(err, err2);
}
END_TEST

/* Random mutations of a valid file: never a crash, a status with a message or a
 * ready system. */
START_TEST(test_mutations)
{
    char path[1024];
    tmppath(path, sizeof path, "seed.data");
    odhs_system *seed = make_scene(2, 0.3);
    ck_assert_int_eq(odhs_lammps_data_write(seed, path), ODHS_OK);
    odhs_system_destroy(seed);
    char *orig = slurp(path, NULL);
    size_t len = strlen(orig);
    char *buf = malloc(len + 16);
    ck_assert_ptr_nonnull(buf);
    static const char alphabet[] = "0123456789 \n\r#-+.eE:=xyzAaS";
    size_t ok = 0;
    for (int it = 0; it < 400; it++) {
        memcpy(buf, orig, len);
        size_t n = len;
        int edits = 1 + (int)(urand() * 4);
        for (int e = 0; e < edits; e++) {
            size_t at = (size_t)(urand() * (double)n);
            double u = urand();
            if (u < 0.5)
                buf[at] = alphabet[(size_t)(urand() * (sizeof alphabet - 1))];
            else if (u < 0.8 && n > 1) {
                memmove(buf + at, buf + at + 1, n - at - 1);
                n--;
            } else
                n = at; /* truncate */
        }
        odhs_system *sys = (odhs_system *)&sys;
        char err[64];
        int st = odhs_lammps_data_parse(buf, n, &sys, err, sizeof err);
        if (st == ODHS_OK) {
            ck_assert(sys != NULL && odhs_system_is_ready(sys));
            ck_assert_str_eq(err, "");
            ok++;
        } else {
            ck_assert_ptr_null(sys);
            ck_assert(err[0] != '\0');
        }
        odhs_system_destroy(st == ODHS_OK ? sys : NULL);
    }
    ck_assert_uint_lt(ok, 400);
    free(buf);
    free(orig);
}
END_TEST

/* ---- errors ------------------------------------------------------------------------------ */

START_TEST(test_null_args)
{
    odhs_system *sys = (odhs_system *)&sys;
    char err[ODHS_ERRMSG_LEN];
    ck_assert_int_eq(odhs_lammps_data_read(NULL, &sys, err, sizeof err), ODHS_E_NULL);
    ck_assert_ptr_null(sys);
    ck_assert(err[0] != '\0');
    ck_assert_int_eq(odhs_lammps_data_read("/tmp/whatever.data", NULL, err, sizeof err), ODHS_E_NULL);
    sys = (odhs_system *)&sys;
    ck_assert_int_eq(odhs_lammps_data_parse(NULL, 10, &sys, err, sizeof err), ODHS_E_NULL);
    ck_assert_ptr_null(sys);
    ck_assert_int_eq(odhs_lammps_data_parse("t\n", 2, NULL, NULL, 0), ODHS_E_NULL);
    ck_assert_int_eq(odhs_lammps_data_write(NULL, "/tmp/whatever.data"), ODHS_E_NULL);

    ck_assert_int_eq(odhs_system_create(3, 2, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_lammps_data_write(sys, NULL), ODHS_E_NULL);
    char path[1024];
    tmppath(path, sizeof path, "unset.data");
    ck_assert_int_eq(odhs_lammps_data_write(sys, path), ODHS_E_STATE); /* radii and positions unset */
    ck_assert(strstr(odhs_system_errmsg(sys), "not set") != NULL);
    ck_assert_int_eq(access(path, F_OK), -1);
    odhs_system_destroy(sys);

    /* a NULL errbuf is allowed; a tiny one is filled without overflow */
    sys = (odhs_system *)&sys;
    ck_assert_int_eq(odhs_lammps_data_parse("", 0, &sys, NULL, 0), ODHS_E_FORMAT);
    ck_assert_ptr_null(sys);
    char small[8];
    memset(small, 'x', sizeof small);
    ck_assert_int_eq(odhs_lammps_data_parse("", 0, &sys, small, 5), ODHS_E_FORMAT);
    ck_assert_str_eq(small, "line");
    ck_assert_int_eq(small[5], 'x');
}
END_TEST

START_TEST(test_io_errors)
{
    odhs_system *sys = (odhs_system *)&sys;
    char err[ODHS_ERRMSG_LEN], path[1024];
    tmppath(path, sizeof path, "does-not-exist.data");
    ck_assert_int_eq(odhs_lammps_data_read(path, &sys, err, sizeof err), ODHS_E_IO);
    ck_assert_ptr_null(sys);
    ck_assert_ptr_nonnull(strstr(err, "does-not-exist.data"));
    sys = (odhs_system *)&sys;
    ck_assert_int_eq(odhs_lammps_data_read(tmpdir, &sys, err, sizeof err), ODHS_E_IO); /* a directory */
    ck_assert_ptr_null(sys);

    /* writing into a missing directory, or over a directory: ODHS_E_IO, message
     * on the handle, nothing left behind */
    sys = make_scene(2, 0.3);
    tmppath(path, sizeof path, "no-such-dir/out.data");
    ck_assert_int_eq(odhs_lammps_data_write(sys, path), ODHS_E_IO);
    ck_assert_ptr_nonnull(strstr(odhs_system_errmsg(sys), "no-such-dir"));
    tmppath(path, sizeof path, "a-directory");
    ck_assert_int_eq(mkdir(path, 0700), 0);
    ck_assert_int_eq(odhs_lammps_data_write(sys, path), ODHS_E_IO);
    ck_assert_int_eq(count_dir_entries(), 1);
    ck_assert_int_eq(rmdir(path), 0);

    /* an existing file is replaced as a whole */
    tmppath(path, sizeof path, "old.data");
    write_str(path, "old contents that are much longer than nothing at all\n");
    ck_assert_int_eq(odhs_lammps_data_write(sys, path), ODHS_OK);
    odhs_system *back = NULL;
    ck_assert_int_eq(odhs_lammps_data_read(path, &back, err, sizeof err), ODHS_OK);
    assert_same_mod_x(sys, back, 0);
    ck_assert_int_eq(count_dir_entries(), 1);
    odhs_system_destroy(back);
    odhs_system_destroy(sys);
}
END_TEST

/* ---- allocation failures (only in the -DODHS_FAULT_INJECTION build) ------------------ */

#ifdef ODHS_FAULT_INJECTION
/* Fail allocation k = 1, 2, ... of op (once, then sticky) until op no longer
 * allocates that many: every failure must give ODHS_E_NOMEM, no system and no
 * leak. */
typedef int (*alloc_op)(void *ctx, odhs_system **out);

static void walk_allocations(alloc_op op, void *ctx, const char *name)
{
    for (int sticky = 0; sticky <= 1; sticky++) {
        for (uint64_t k = 1;; k++) {
            int64_t live = odhs__fault_live();
            odhs_system *out = (odhs_system *)&out; /* poison: must become NULL or a system */
            odhs__fault_arm(k, sticky);
            int st = op(ctx, &out);
            int fired = odhs__fault_fired();
            odhs__fault_disarm();
            if (!fired || st == ODHS_OK) { /* past the last allocation, or a failure absorbed */
                ck_assert_msg(st == ODHS_OK, "%s: status %d without a failure", name, st);
                odhs_system_destroy(out);
                ck_assert_int_eq(odhs__fault_live(), live);
                if (!fired) {
                    ck_assert_uint_gt(k, 1);
                    break;
                }
                continue;
            }
            ck_assert_msg(st == ODHS_E_NOMEM, "%s: allocation %llu failed: status %d", name, (unsigned long long)k,
                          st);
            ck_assert_msg(out == NULL, "%s: a system after a failure", name);
            ck_assert_msg(odhs__fault_live() == live, "%s: leak after failing allocation %llu", name,
                          (unsigned long long)k);
        }
    }
}

static int op_parse(void *ctx, odhs_system **out)
{
    char err[ODHS_ERRMSG_LEN];
    return odhs_lammps_data_parse(ctx, strlen(ctx), out, err, sizeof err);
}

static int op_read(void *ctx, odhs_system **out)
{
    char err[ODHS_ERRMSG_LEN];
    return odhs_lammps_data_read(ctx, out, err, sizeof err);
}

typedef struct {
    odhs_system *sys;
    const char *path;
} write_ctx;

static int op_write(void *ctx, odhs_system **out)
{
    write_ctx *w = ctx;
    *out = NULL;
    return odhs_lammps_data_write(w->sys, w->path);
}

START_TEST(test_allocation_failures)
{
    char path[1024], wpath[1024];
    tmppath(path, sizeof path, "af.data");
    tmppath(wpath, sizeof wpath, "af-write.data");
    odhs_system *sys = make_scene(2, 0.3);
    ck_assert_int_eq(odhs_lammps_data_write(sys, path), ODHS_OK);
    char *text = slurp(path, NULL);
    walk_allocations(op_parse, text, "parse");
    walk_allocations(op_read, path, "read");
    write_ctx w = {sys, wpath};
    walk_allocations(op_write, &w, "write");
    ck_assert_int_eq(count_dir_entries(), 2); /* no temporary file left behind */
    free(text);
    odhs_system_destroy(sys);
}
END_TEST
#endif

/* ---- through LAMMPS itself -------------------------------------------------------------- */

/* The path of an executable `lmp` in PATH into buf, or 0. */
static int find_lmp(char *buf, size_t size)
{
    const char *path = getenv("PATH");
    if (!path) return 0;
    while (*path) {
        const char *colon = strchr(path, ':');
        size_t len = colon ? (size_t)(colon - path) : strlen(path);
        if (len > 0 && len + 5 < size) {
            memcpy(buf, path, len);
            memcpy(buf + len, "/lmp", 5);
            if (access(buf, X_OK) == 0) return 1;
        }
        if (!colon) break;
        path = colon + 1;
    }
    return 0;
}

/* Write sys, let LAMMPS read it and write it again, read that back. */
static odhs_system *through_lammps(const char *lmp, const odhs_system *sys)
{
    char in[1024], out[1024], script[1024], log[1024], cmd[4096];
    tmppath(in, sizeof in, "in.data");
    tmppath(out, sizeof out, "out.data");
    tmppath(script, sizeof script, "in.lmp");
    tmppath(log, sizeof log, "lmp.out");
    ck_assert(!strchr(tmpdir, '\'') && !strchr(lmp, '\''));
    ck_assert_int_eq(odhs_lammps_data_write(sys, in), ODHS_OK);
    FILE *f = fopen(script, "w");
    ck_assert_ptr_nonnull(f);
    fprintf(f,
            "units lj\n"
            "dimension %d\n"
            "boundary p p p\n"
            "atom_style sphere\n"
            "read_data '%s'\n"
            "write_data '%s'\n",
            odhs_system_dim(sys), in, out);
    ck_assert_int_eq(fclose(f), 0);
    snprintf(cmd, sizeof cmd, "cd '%s' && '%s' -log none -screen none -in '%s' > '%s' 2>&1", tmpdir, lmp, script,
             log);
    int rc = system(cmd);
    if (rc != 0) {
        char *t = access(log, R_OK) == 0 ? slurp(log, NULL) : NULL;
        ck_abort_msg("lmp failed (%d): %s", rc, t ? t : "(no output)");
    }
    odhs_system *back = NULL;
    char err[ODHS_ERRMSG_LEN];
    int st = odhs_lammps_data_read(out, &back, err, sizeof err);
    ck_assert_msg(st == ODHS_OK, "reading LAMMPS's file: %d %s", st, err);
    remove(in);
    remove(out);
    remove(script);
    remove(log);
    return back;
}

/* positions modulo the sheared lattice, radii, box and strain within 1e-15 */
static void assert_close_lattice(const odhs_system *s1, const odhs_system *s2)
{
    state a, b;
    state_get(s1, &a);
    state_get(s2, &b);
    const double tol = 1e-15;
    ck_assert_int_eq(a.dim, b.dim);
    ck_assert_uint_eq(a.n, b.n);
    int dim = a.dim;
    for (int k = 0; k < dim; k++)
        ck_assert_msg(fabs(a.L[k] - b.L[k]) <= tol * a.L[k], "L[%d] %.17g != %.17g", k, a.L[k], b.L[k]);
    ck_assert_msg(fabs(a.gamma - b.gamma) * a.L[1] <= tol * a.L[0], "strain %.17g != %.17g", a.gamma, b.gamma);
    /* the types keep the species apart: S -> 1, L -> 2 (order of appearance) */
    for (size_t i = 0; i < a.n; i++) {
        ck_assert_msg(fabs(a.r[i] - b.r[i]) <= tol * a.r[i], "radius %zu: %.17g != %.17g", i, a.r[i], b.r[i]);
        ck_assert_str_eq(b.sp[i], strcmp(a.sp[i], a.sp[0]) == 0 ? "1" : "2");
        double d[3] = {0, 0, 0};
        for (int k = 0; k < dim; k++) d[k] = b.x[i * (size_t)dim + (size_t)k] - a.x[i * (size_t)dim + (size_t)k];
        double ny = nearbyint(d[1] / a.L[1]);
        d[1] -= ny * a.L[1];
        d[0] -= ny * a.gamma * a.L[1];
        d[0] -= nearbyint(d[0] / a.L[0]) * a.L[0];
        if (dim == 3) d[2] -= nearbyint(d[2] / a.L[2]) * a.L[2];
        for (int k = 0; k < dim; k++)
            ck_assert_msg(fabs(d[k]) <= tol * a.L[k], "particle %zu coordinate %d: off by %.3g (L = %.17g)", i, k,
                          d[k], a.L[k]);
    }
    state_free(&a);
    state_free(&b);
}

START_TEST(test_lammps_roundtrip)
{
    char lmp[1024];
    if (!find_lmp(lmp, sizeof lmp)) {
        printf("lammps: LAMMPS round trip skipped: lmp not found in PATH\n");
        return;
    }
    struct {
        int dim;
        double gamma;
        uint64_t seed;
    } cases[] = {{2, 0.3, 5}, {3, 0.3, 6}, {2, -0.45, 7}, {3, 0.0, 8}};
    for (size_t c = 0; c < sizeof cases / sizeof *cases; c++) {
        odhs_system *sys = make_random(cases[c].dim, 64, cases[c].gamma, cases[c].seed);
        odhs_system *back = through_lammps(lmp, sys);
        assert_close_lattice(sys, back);
        odhs_system_destroy(back);
        odhs_system_destroy(sys);
    }
    /* the edge particles of the grid scene too */
    odhs_system *sys = make_scene(2, 0.3);
    for (size_t i = 0; i < odhs_system_count(sys); i++)
        ck_assert_int_eq(odhs_system_set_species(sys, i, i % 2 ? "L" : "S"), ODHS_OK);
    odhs_system *back = through_lammps(lmp, sys);
    assert_close_lattice(sys, back);
    odhs_system_destroy(back);
    odhs_system_destroy(sys);
    ck_assert_int_eq(count_dir_entries(), 0);
}
END_TEST

Suite *make_lammps_suite(void)
{
    Suite *s = suite_create("lammps");
    TCase *tc;

    tc = tcase_create("roundtrip");
    tcase_add_checked_fixture(tc, lmp_setup, lmp_teardown);
    tcase_add_loop_test(tc, test_roundtrip_2d, 0, (int)(sizeof rt_strains / sizeof *rt_strains));
    tcase_add_loop_test(tc, test_roundtrip_3d, 0, (int)(sizeof rt_strains / sizeof *rt_strains));
    tcase_add_loop_test(tc, test_roundtrip_random, 0, 4);
    tcase_add_test(tc, test_write_format);
    suite_add_tcase(s, tc);

    tc = tcase_create("read");
    tcase_add_checked_fixture(tc, lmp_setup, lmp_teardown);
    tcase_add_test(tc, test_read_lammps_style);
    tcase_add_test(tc, test_read_title_keys);
    tcase_add_test(tc, test_read_dimension);
    suite_add_tcase(s, tc);

    tc = tcase_create("malformed");
    tcase_add_checked_fixture(tc, lmp_setup, lmp_teardown);
    tcase_add_loop_test(tc, test_malformed, 0, (int)(sizeof bad_cases / sizeof *bad_cases));
    tcase_add_test(tc, test_mutations);
    suite_add_tcase(s, tc);

    tc = tcase_create("errors");
    tcase_add_checked_fixture(tc, lmp_setup, lmp_teardown);
    tcase_add_test(tc, test_null_args);
    tcase_add_test(tc, test_io_errors);
#ifdef ODHS_FAULT_INJECTION
    tcase_add_test(tc, test_allocation_failures);
#endif
    suite_add_tcase(s, tc);

    tc = tcase_create("lammps");
    tcase_add_checked_fixture(tc, lmp_setup, lmp_teardown);
    tcase_add_test(tc, test_lammps_roundtrip);
    tcase_set_timeout(tc, 120);
    suite_add_tcase(s, tc);

    return s;
}
