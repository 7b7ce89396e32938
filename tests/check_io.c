/*
 * libodhs - tests for the extended XYZ reader/writer (io.h).
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <check.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "odhs.h"
#include "internal.h"

/* ---- fixture: a private temporary directory per test (tmpfiles.h) ----- */
#include "tmpfiles.h"

static void io_setup(void) { tmpdir_make("io"); }

static void io_teardown(void) { tmpdir_remove(); }

/* Parse from an exact-size heap copy (no terminating NUL, so a reader that
 * runs past len is caught by ASan/valgrind). */
static int parse_exact(const char *text, size_t len, odhs_system **out, char *err, size_t errlen)
{
    char *copy = malloc(len ? len : 1);
    ck_assert_ptr_nonnull(copy);
    if (len) memcpy(copy, text, len);
    int st = odhs_xyz_parse(copy, len, out, err, errlen);
    free(copy);
    return st;
}

static int parse_str(const char *text, odhs_system **out, char *err, size_t errlen)
{
    return parse_exact(text, strlen(text), out, err, errlen);
}

/* ---- deterministic random numbers for the round-trip scenes ------------ */

static uint64_t rng_state = 0x9e3779b97f4a7c15ull;
static double urand(void)
{
    rng_state ^= rng_state << 13;
    rng_state ^= rng_state >> 7;
    rng_state ^= rng_state << 17;
    return (double)(rng_state >> 11) * 0x1.0p-53;
}

/*
 * A grid scene: one particle per cell of side h (n per edge), jittered by
 * +-0.05 h, radii in [0.1 h, 0.2 h] (no overlaps whatever the shear), plus a
 * few particles moved to the very edges of the box (inside their own cell,
 * in cells that are not neighbours of each other).
 */
static odhs_system *make_scene(int dim, double gamma)
{
    const int m = 5;
    const double h = 2.0137;
    size_t n = (size_t)(dim == 3 ? m * m * m : m * m);
    double L[3] = {m * h, m * h, m * h};
    double *x = malloc(n * (size_t)dim * sizeof(double));
    double *r = malloc(n * sizeof(double));
    ck_assert_ptr_nonnull(x);
    ck_assert_ptr_nonnull(r);
    size_t i = 0;
    for (int a = 0; a < m; a++)
        for (int b = 0; b < m; b++)
            for (int c = 0; c < (dim == 3 ? m : 1); c++, i++) {
                int cell[3] = {a, b, c};
                for (int k = 0; k < dim; k++)
                    x[i * (size_t)dim + (size_t)k] = (cell[k] + 0.5 + 0.1 * (urand() - 0.5)) * h;
                r[i] = h * (0.1 + 0.1 * urand());
            }
    /* edge particles; index of cell (a,b,c) is (a*m + b)*m + c in 3D,
     * a*m + b in 2D */
#define IDX(a, b, c) (dim == 3 ? (size_t)(((a)*m + (b)) * m + (c)) : (size_t)((a)*m + (b)))
    double *p;
    p = &x[IDX(0, 0, 0) * (size_t)dim]; /* the origin corner */
    p[0] = 0.0;
    p[1] = 0.0;
    if (dim == 3) p[2] = 4.9406564584124654e-324; /* smallest subnormal */
    p = &x[IDX(m - 1, 2, 2) * (size_t)dim]; /* right face */
    p[0] = nextafter(L[0], 0.0);
    /* top face (sheared boundary): the column is chosen so that no tested
     * strain brings its image next to the origin particle in 2D */
    p = &x[IDX(m - 1, m - 1, 2) * (size_t)dim];
    p[1] = nextafter(L[1], 0.0);
    if (dim == 3) {
        p = &x[IDX(2, 2, m - 1) * (size_t)dim]; /* back face */
        p[2] = nextafter(L[2], 0.0);
    }
    p = &x[IDX(2, 2, 0) * (size_t)dim]; /* a tiny x in an inner cell */
    p[0] = (2.0 + 1e-9) * h;
#undef IDX
    odhs_system *sys = NULL;
    ck_assert_int_eq(odhs_system_create(dim, n, &sys), ODHS_OK);
    int st = odhs_system_set_configuration(sys, L, gamma, r, x);
    ck_assert_msg(st == ODHS_OK, "set_configuration: %d %s", st, odhs_system_errmsg(sys));
    static const char *labels[] = {"A", "B", "Big", "ABCDEFGHIJKLMNO", "s_1", "Na+"};
    for (i = 0; i < n; i++)
        ck_assert_int_eq(odhs_system_set_species(sys, i, labels[i % 6]), ODHS_OK);
    free(x);
    free(r);
    return sys;
}

/* bit-exact comparison of two systems */
static void assert_same_system(const odhs_system *s1, const odhs_system *s2)
{
    int dim = odhs_system_dim(s1);
    size_t n = odhs_system_count(s1);
    ck_assert_int_eq(odhs_system_dim(s2), dim);
    ck_assert_uint_eq(odhs_system_count(s2), n);
    ck_assert_int_eq(odhs_system_is_ready(s2), 1);
    double L1[3] = {0}, L2[3] = {0}, g1 = 0, g2 = 0;
    ck_assert_int_eq(odhs_system_get_box(s1, L1), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_box(s2, L2), ODHS_OK);
    ck_assert(memcmp(L1, L2, (size_t)dim * sizeof(double)) == 0);
    ck_assert_int_eq(odhs_system_get_strain(s1, &g1), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_strain(s2, &g2), ODHS_OK);
    ck_assert_msg(memcmp(&g1, &g2, sizeof g1) == 0, "strain %.17g != %.17g", g1, g2);
    double *x1 = malloc(n * (size_t)dim * sizeof(double));
    double *x2 = malloc(n * (size_t)dim * sizeof(double));
    double *r1 = malloc(n * sizeof(double));
    double *r2 = malloc(n * sizeof(double));
    ck_assert_int_eq(odhs_system_get_positions(s1, x1), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_positions(s2, x2), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(s1, r1), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(s2, r2), ODHS_OK);
    for (size_t i = 0; i < n * (size_t)dim; i++)
        ck_assert_msg(memcmp(&x1[i], &x2[i], sizeof(double)) == 0,
                      "position component %zu: %.17g != %.17g", i, x1[i], x2[i]);
    ck_assert(memcmp(r1, r2, n * sizeof(double)) == 0);
    char a[ODHS_SPECIES_MAX + 1], b[ODHS_SPECIES_MAX + 1];
    for (size_t i = 0; i < n; i++) {
        ck_assert_int_eq(odhs_system_get_species(s1, i, a, sizeof a), ODHS_OK);
        ck_assert_int_eq(odhs_system_get_species(s2, i, b, sizeof b), ODHS_OK);
        ck_assert_str_eq(a, b);
    }
    free(x1);
    free(x2);
    free(r1);
    free(r2);
}

/* ---- round trips ---------------------------------------------------------- */

static const double rt_strains[] = {0.0, 0.5, -0.37, 0.123456789012345678};

static void roundtrip(int dim, double gamma)
{
    odhs_system *sys = make_scene(dim, gamma);
    char path[256], path2[256], err[ODHS_ERRMSG_LEN];
    tmppath(path, sizeof path, "rt.xyz");
    tmppath(path2, sizeof path2, "rt2.xyz");
    int st = odhs_xyz_write(sys, path);
    ck_assert_msg(st == ODHS_OK, "write: %d %s", st, odhs_system_errmsg(sys));
    odhs_system *back = NULL;
    st = odhs_xyz_read(path, &back, err, sizeof err);
    ck_assert_msg(st == ODHS_OK, "read: %d %s", st, err);
    ck_assert_ptr_nonnull(back);
    assert_same_system(sys, back);
    /* and writing the read system again gives the very same bytes */
    ck_assert_int_eq(odhs_xyz_write(back, path2), ODHS_OK);
    size_t l1, l2;
    char *t1 = slurp(path, &l1), *t2 = slurp(path2, &l2);
    ck_assert_uint_eq(l1, l2);
    ck_assert(memcmp(t1, t2, l1) == 0);
    /* the same through odhs_xyz_parse */
    odhs_system *back2 = NULL;
    ck_assert_int_eq(parse_exact(t1, l1, &back2, err, sizeof err), ODHS_OK);
    assert_same_system(sys, back2);
    /* no temporary files left behind */
    ck_assert_int_eq(count_dir_entries(), 2);
    free(t1);
    free(t2);
    odhs_system_destroy(back2);
    odhs_system_destroy(back);
    odhs_system_destroy(sys);
}

START_TEST(test_roundtrip_3d)
{
    roundtrip(3, rt_strains[_i]);
}
END_TEST

START_TEST(test_roundtrip_2d)
{
    roundtrip(2, rt_strains[_i]);
}
END_TEST

/* The writer produces exactly the documented format. */
START_TEST(test_write_format)
{
    odhs_system *sys = NULL;
    char path[256];
    tmppath(path, sizeof path, "fmt.xyz");

    double L3[3] = {4.0, 5.0, 6.0}, r3[2] = {0.5, 0.25}, x3[6] = {1, 2, 3, 3, 4, 5};
    ck_assert_int_eq(odhs_system_create(3, 2, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_configuration(sys, L3, 0.25, r3, x3), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_species(sys, 1, "B"), ODHS_OK);
    ck_assert_int_eq(odhs_xyz_write(sys, path), ODHS_OK);
    char *t = slurp(path, NULL);
    ck_assert_str_eq(t, "2\n"
                        "Lattice=\"4 0 0 1.25 5 0 0 0 6\" "
                        "Properties=species:S:1:pos:R:3:radius:R:1 pbc=\"T T T\" dim=3 "
                        "strain=0.25\n"
                        "A 1 2 3 0.5\n"
                        "B 3 4 5 0.25\n");
    free(t);
    odhs_system_destroy(sys);

    double L2[2] = {4.0, 8.0}, r2[2] = {0.5, 0.1}, x2[4] = {1.5, 2.25, 3, 7};
    ck_assert_int_eq(odhs_system_create(2, 2, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_configuration(sys, L2, -0.125, r2, x2), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_species(sys, 0, "S"), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_species(sys, 1, "L"), ODHS_OK);
    ck_assert_int_eq(odhs_xyz_write(sys, path), ODHS_OK);
    t = slurp(path, NULL);
    ck_assert_str_eq(t, "2\n"
                        "Lattice=\"4 0 0 -1 8 0 0 0 1\" "
                        "Properties=species:S:1:pos:R:3:radius:R:1 pbc=\"T T F\" dim=2 "
                        "strain=-0.125\n"
                        "S 1.5 2.25 0 0.5\n"
                        "L 3 7 0 0.10000000000000001\n");
    free(t);
    odhs_system_destroy(sys);
}
END_TEST

/* ---- reading hand-written files ------------------------------------------ */

static odhs_system *parse_ok(const char *text)
{
    odhs_system *sys = NULL;
    char err[ODHS_ERRMSG_LEN];
    int st = parse_str(text, &sys, err, sizeof err);
    ck_assert_msg(st == ODHS_OK, "parse failed: %d %s\n--- input ---\n%s", st, err, text);
    ck_assert_ptr_nonnull(sys);
    return sys;
}

static void expect_species(const odhs_system *sys, size_t i, const char *label)
{
    char b[ODHS_SPECIES_MAX + 1];
    ck_assert_int_eq(odhs_system_get_species(sys, i, b, sizeof b), ODHS_OK);
    ck_assert_str_eq(b, label);
}

START_TEST(test_read_handwritten_3d)
{
    const char *text = "3\n"
                       "Lattice=\"10 0 0 2.5 10 0 0 0 12\" "
                       "Properties=species:S:1:pos:R:3:radius:R:1 pbc=\"T T T\" dim=3 "
                       "strain=0.25\n"
                       "A 1 2 3 0.5\n"
                       "B 5.5 6.25 7.125 0.75\n"
                       "Big 9.875 0.125 11.5 1\n";
    odhs_system *sys = parse_ok(text);
    ck_assert_int_eq(odhs_system_dim(sys), 3);
    ck_assert_uint_eq(odhs_system_count(sys), 3);
    double L[3], g, x[9], r[3];
    ck_assert_int_eq(odhs_system_get_box(sys, L), ODHS_OK);
    ck_assert(L[0] == 10.0 && L[1] == 10.0 && L[2] == 12.0);
    ck_assert_int_eq(odhs_system_get_strain(sys, &g), ODHS_OK);
    ck_assert(g == 0.25);
    ck_assert_int_eq(odhs_system_get_positions(sys, x), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(sys, r), ODHS_OK);
    const double xe[9] = {1, 2, 3, 5.5, 6.25, 7.125, 9.875, 0.125, 11.5};
    const double re[3] = {0.5, 0.75, 1.0};
    ck_assert(memcmp(x, xe, sizeof xe) == 0);
    ck_assert(memcmp(r, re, sizeof re) == 0);
    expect_species(sys, 0, "A");
    expect_species(sys, 1, "B");
    expect_species(sys, 2, "Big");
    odhs_system_destroy(sys);
}
END_TEST

START_TEST(test_read_handwritten_2d)
{
    const char *text = "2\n"
                       "Lattice=\"8 0 0 -2 8 0 0 0 1\" "
                       "Properties=species:S:1:pos:R:3:radius:R:1 pbc=\"T T F\" dim=2 "
                       "strain=-0.25\n"
                       "S 1 2 0 0.5\n"
                       "L 4.5 6.5 0 1.5\n";
    odhs_system *sys = parse_ok(text);
    ck_assert_int_eq(odhs_system_dim(sys), 2);
    double L[2], g, x[4], r[2];
    ck_assert_int_eq(odhs_system_get_box(sys, L), ODHS_OK);
    ck_assert(L[0] == 8.0 && L[1] == 8.0);
    ck_assert_int_eq(odhs_system_get_strain(sys, &g), ODHS_OK);
    ck_assert(g == -0.25);
    ck_assert_int_eq(odhs_system_get_positions(sys, x), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(sys, r), ODHS_OK);
    ck_assert(x[0] == 1 && x[1] == 2 && x[2] == 4.5 && x[3] == 6.5);
    ck_assert(r[0] == 0.5 && r[1] == 1.5);
    expect_species(sys, 1, "L");
    odhs_system_destroy(sys);
}
END_TEST

/* Variations the reader must accept: key order and case, extra keys (with
 * and without values), no dim/strain keys, CRLF, tabs, no final newline,
 * trailing blank lines, a second frame. */
START_TEST(test_read_variants)
{
    odhs_system *sys;
    double L[3], g, x[6], r[2];

    /* dim from pbc, strain from bx/Ly, lower-case keys, extra keys, CRLF */
    sys = parse_ok("2\r\n"
                   "Time=1.5 pbc=\"T T F\" flag properties=species:S:1:pos:R:3:radius:R:1 "
                   "comment=\"a = b \\\" c\" lattice=\"4 0 0 1 4 0 0 0 0\"\r\n"
                   "A\t1 1 0\t0.5\r\n"
                   "B 3 3 -7.5 0.5\r\n");
    ck_assert_int_eq(odhs_system_dim(sys), 2);
    ck_assert_int_eq(odhs_system_get_strain(sys, &g), ODHS_OK);
    ck_assert(g == 0.25);
    ck_assert_int_eq(odhs_system_get_positions(sys, x), ODHS_OK);
    ck_assert(x[0] == 1 && x[1] == 1 && x[2] == 3 && x[3] == 3);
    odhs_system_destroy(sys);

    /* no pbc, no dim: 3D; no final newline; strain outside [-1/2,1/2] is
     * remapped by the library */
    sys = parse_ok("1\nLattice=\"5 0 0 6.25 5 0 0 0 5\" "
                   "Properties=species:S:1:pos:R:3:radius:R:1 strain=1.25\n"
                   "X 1 2 3 1");
    ck_assert_int_eq(odhs_system_dim(sys), 3);
    ck_assert_int_eq(odhs_system_get_strain(sys, &g), ODHS_OK);
    ck_assert(g == 0.25);
    ck_assert_int_eq(odhs_system_get_box(sys, L), ODHS_OK);
    ck_assert(L[0] == 5 && L[1] == 5 && L[2] == 5);
    odhs_system_destroy(sys);

    /* dim key wins over pbc; trailing blank lines; a second frame is ignored */
    sys = parse_ok("2\n"
                   "dim=3 Lattice=\"5 0 0 0 5 0 0 0 5\" pbc=\"T T F\" "
                   "Properties=species:S:1:pos:R:3:radius:R:1\n"
                   "A 1 1 1 0.5\n"
                   "A 3 3 3 0.5\n"
                   "\n   \n"
                   "1\nsecond frame header\nB 0 0 0 garbage\n");
    ck_assert_int_eq(odhs_system_dim(sys), 3);
    ck_assert_uint_eq(odhs_system_count(sys), 2);
    odhs_system_destroy(sys);

    /* trailing blank lines only, with CRLF */
    sys = parse_ok("1\r\nLattice=\"5 0 0 0 5 0 0 0 5\" "
                   "Properties=species:S:1:pos:R:3:radius:R:1\r\nA 1 1 1 0.5\r\n\r\n\r\n");
    odhs_system_destroy(sys);

    /* positions outside the box are wrapped; spaces around '=' */
    sys = parse_ok("1\nLattice = \"5 0 0 0 5 0 0 0 5\" "
                   "Properties = species:S:1:pos:R:3:radius:R:1\nA 6 -1 11 0.5\n");
    ck_assert_int_eq(odhs_system_get_positions(sys, x), ODHS_OK);
    ck_assert(x[0] == 1 && x[1] == 4 && x[2] == 1);
    odhs_system_destroy(sys);

    /* hexadecimal and exponent notation numbers */
    sys = parse_ok("1\nLattice=\"5e0 0 0 0 0x1.4p2 0 0 0 5.\" "
                   "Properties=species:S:1:pos:R:3:radius:R:1\nA 1e0 +2 .5 0x1p-1\n");
    ck_assert_int_eq(odhs_system_get_radii(sys, r), ODHS_OK);
    ck_assert(r[0] == 0.5);
    odhs_system_destroy(sys);
}
END_TEST

/* ASE-style files with extra columns of any type, in any order. */
START_TEST(test_read_extra_columns)
{
    odhs_system *sys;
    double x[6], r[2];
    sys = parse_ok("2\n"
                   "Lattice=\"10 0 0 0 10 0 0 0 10\" "
                   "Properties=species:S:1:pos:R:3:radius:R:1:velo:R:3:id:I:1 pbc=\"T T T\"\n"
                   "A 1 2 3 0.5 0.1 0.2 0.3 7\n"
                   "B 4 5 6 0.75 -1 -2 -3 8\n");
    ck_assert_int_eq(odhs_system_get_positions(sys, x), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(sys, r), ODHS_OK);
    ck_assert(x[0] == 1 && x[1] == 2 && x[2] == 3 && x[3] == 4 && x[4] == 5 && x[5] == 6);
    ck_assert(r[0] == 0.5 && r[1] == 0.75);
    odhs_system_destroy(sys);

    /* reordered, with string and logical columns mixed in */
    sys = parse_ok("2\n"
                   "Properties=id:I:1:radius:R:1:name:S:1:pos:R:3:fixed:L:1:species:S:1 "
                   "Lattice=\"10 0 0 0 10 0 0 0 10\"\n"
                   "7 0.5 foo 1 2 3 T Cu\n"
                   "8 0.75 bar 4 5 6 F Zn\n");
    ck_assert_int_eq(odhs_system_get_positions(sys, x), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(sys, r), ODHS_OK);
    ck_assert(x[0] == 1 && x[1] == 2 && x[2] == 3 && x[3] == 4 && x[4] == 5 && x[5] == 6);
    ck_assert(r[0] == 0.5 && r[1] == 0.75);
    expect_species(sys, 0, "Cu");
    expect_species(sys, 1, "Zn");
    odhs_system_destroy(sys);
}
END_TEST

/* ---- malformed input ------------------------------------------------------ */

#define HDR3 "Lattice=\"10 0 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:3:radius:R:1"
#define HDR2 HDR3 " pbc=\"T T F\""
#define P1 "A 1 1 1 0.5\n"
#define P2 "A 4 4 4 0.5\n"

typedef struct {
    const char *name;
    const char *text;
    int status;
    int line; /* > 0: the message must contain "line <line>" */
} bad_case;

static const bad_case bad_cases[] = {
    {"empty file", "", ODHS_E_FORMAT, 1},
    {"blank file", "\n\n  \n", ODHS_E_FORMAT, 1},
    {"N = 0", "0\n" HDR3 "\n", ODHS_E_FORMAT, 1},
    {"negative N", "-2\n" HDR3 "\n" P1 P2, ODHS_E_FORMAT, 1},
    {"garbage N", "abc\n" HDR3 "\n" P1 P2, ODHS_E_FORMAT, 1},
    {"N with junk", "2x\n" HDR3 "\n" P1 P2, ODHS_E_FORMAT, 1},
    {"two numbers on line 1", "2 3\n" HDR3 "\n" P1 P2, ODHS_E_FORMAT, 1},
    {"fractional N", "1.5\n" HDR3 "\n" P1 P2, ODHS_E_FORMAT, 1},
    {"N overflows", "99999999999999999999999999\n" HDR3 "\n" P1 P2, ODHS_E_FORMAT, 1},
    {"N above the cap", "100000001\n" HDR3 "\n" P1 P2, ODHS_E_FORMAT, 1},
    {"huge N, few lines", "100000000\n" HDR3 "\n" P1 P2, ODHS_E_FORMAT, 5},
    {"N larger than lines present", "3\n" HDR3 "\n" P1 P2, ODHS_E_FORMAT, 5},
    {"N smaller than lines present", "1\n" HDR3 "\n" P1 P2, ODHS_E_FORMAT, 4},
    {"no comment line", "2\n", ODHS_E_FORMAT, 2},
    {"missing Lattice",
     "2\nProperties=species:S:1:pos:R:3:radius:R:1\n" P1 P2, ODHS_E_FORMAT, 2},
    {"missing Properties", "2\nLattice=\"10 0 0 0 10 0 0 0 10\"\n" P1 P2, ODHS_E_FORMAT, 2},
    {"Properties without radius",
     "2\nLattice=\"10 0 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:3\nA 1 1 1\nA 4 4 4\n",
     ODHS_E_FORMAT, 2},
    {"Properties without species",
     "2\nLattice=\"10 0 0 0 10 0 0 0 10\" Properties=pos:R:3:radius:R:1\n1 1 1 .5\n4 4 4 .5\n",
     ODHS_E_FORMAT, 2},
    {"pos with 2 components",
     "2\nLattice=\"10 0 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:2:radius:R:1\n"
     "A 1 1 .5\nA 4 4 .5\n",
     ODHS_E_FORMAT, 2},
    {"radius of type I",
     "1\nLattice=\"10 0 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:3:radius:I:1\nA 1 1 1 1\n",
     ODHS_E_FORMAT, 2},
    {"Properties incomplete triplet",
     "1\nLattice=\"10 0 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:3:radius:R\nA 1 1 1 1\n",
     ODHS_E_FORMAT, 2},
    {"Properties unknown type",
     "1\nLattice=\"10 0 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:3:radius:R:1:q:X:1\n"
     "A 1 1 1 1 0\n",
     ODHS_E_FORMAT, 2},
    {"Properties garbage count",
     "1\nLattice=\"10 0 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:3:radius:R:1:v:R:x\n"
     "A 1 1 1 1 0\n",
     ODHS_E_FORMAT, 2},
    {"Properties zero count",
     "1\nLattice=\"10 0 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:3:radius:R:1:v:R:0\n"
     "A 1 1 1 1\n",
     ODHS_E_FORMAT, 2},
    {"Properties huge count",
     "1\nLattice=\"10 0 0 0 10 0 0 0 10\" "
     "Properties=species:S:1:pos:R:3:radius:R:1:v:R:99999999999999999999999\nA 1 1 1 1 0\n",
     ODHS_E_FORMAT, 2},
    {"duplicate pos column",
     "1\nLattice=\"10 0 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:3:radius:R:1:pos:R:3\n"
     "A 1 1 1 1 1 1 1\n",
     ODHS_E_FORMAT, 2},
    {"Lattice with 8 numbers",
     "1\nLattice=\"10 0 0 0 10 0 0 0\" Properties=species:S:1:pos:R:3:radius:R:1\n" P1,
     ODHS_E_FORMAT, 2},
    {"Lattice with 10 numbers",
     "1\nLattice=\"10 0 0 0 10 0 0 0 10 0\" Properties=species:S:1:pos:R:3:radius:R:1\n" P1,
     ODHS_E_FORMAT, 2},
    {"Lattice garbage",
     "1\nLattice=\"10 0 0 0 ten 0 0 0 10\" Properties=species:S:1:pos:R:3:radius:R:1\n" P1,
     ODHS_E_FORMAT, 2},
    {"Lattice NaN",
     "1\nLattice=\"10 0 0 0 nan 0 0 0 10\" Properties=species:S:1:pos:R:3:radius:R:1\n" P1,
     ODHS_E_FORMAT, 2},
    {"Lattice inf",
     "1\nLattice=\"inf 0 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:3:radius:R:1\n" P1,
     ODHS_E_FORMAT, 2},
    {"non-orthogonal a",
     "1\nLattice=\"10 1 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:3:radius:R:1\n" P1,
     ODHS_E_FORMAT, 2},
    {"tilted c",
     "1\nLattice=\"10 0 0 0 10 0 1 0 10\" Properties=species:S:1:pos:R:3:radius:R:1\n" P1,
     ODHS_E_FORMAT, 2},
    {"b with z component",
     "1\nLattice=\"10 0 0 0 10 2 0 0 10\" Properties=species:S:1:pos:R:3:radius:R:1\n" P1,
     ODHS_E_FORMAT, 2},
    {"negative Lx",
     "1\nLattice=\"-10 0 0 0 10 0 0 0 10\" Properties=species:S:1:pos:R:3:radius:R:1\n" P1,
     ODHS_E_FORMAT, 2},
    {"zero Lz in 3D",
     "1\nLattice=\"10 0 0 0 10 0 0 0 0\" Properties=species:S:1:pos:R:3:radius:R:1\n" P1,
     ODHS_E_FORMAT, 2},
    {"strain disagrees with Lattice",
     "1\nLattice=\"10 0 0 2 10 0 0 0 10\" Properties=species:S:1:pos:R:3:radius:R:1 "
     "strain=0.3\n" P1,
     ODHS_E_FORMAT, 2},
    {"strain garbage", "1\n" HDR3 " strain=abc\n" P1, ODHS_E_FORMAT, 2},
    {"strain NaN", "1\n" HDR3 " strain=nan\n" P1, ODHS_E_FORMAT, 2},
    {"dim = 4", "1\n" HDR3 " dim=4\n" P1, ODHS_E_FORMAT, 2},
    {"pbc with two flags", "1\n" HDR3 " pbc=\"T T\"\n" P1, ODHS_E_FORMAT, 2},
    {"pbc garbage", "1\n" HDR3 " pbc=\"T X T\"\n" P1, ODHS_E_FORMAT, 2},
    {"unterminated quote",
     "1\nLattice=\"10 0 0 0 10 0 0 0 10 Properties=species:S:1:pos:R:3:radius:R:1\n" P1,
     ODHS_E_FORMAT, 2},
    {"duplicate Lattice", "1\n" HDR3 " lattice=\"10 0 0 0 10 0 0 0 10\"\n" P1, ODHS_E_FORMAT, 2},
    {"Lattice without value", "1\nLattice " HDR3 "\n" P1, ODHS_E_FORMAT, 2},
    {"'=' without key", "1\n" HDR3 " =3\n" P1, ODHS_E_FORMAT, 2},
    {"garbage number", "2\n" HDR3 "\n" P1 "A 4 abc 4 0.5\n", ODHS_E_FORMAT, 4},
    {"number with junk", "2\n" HDR3 "\n" P1 "A 4 4.0x 4 0.5\n", ODHS_E_FORMAT, 4},
    {"garbage radius", "2\n" HDR3 "\n" P1 "A 4 4 4 big\n", ODHS_E_FORMAT, 4},
    {"too few columns", "2\n" HDR3 "\n" "A 1 1 0.5\n" P2, ODHS_E_FORMAT, 3},
    {"too many columns", "2\n" HDR3 "\n" P1 "A 4 4 4 0.5 9\n", ODHS_E_FORMAT, 4},
    {"extra columns with ASE spec",
     "1\nLattice=\"10 0 0 0 10 0 0 0 10\" "
     "Properties=species:S:1:pos:R:3:radius:R:1:velo:R:3\nA 1 1 1 0.5 0 0\n",
     ODHS_E_FORMAT, 3},
    {"blank particle line", "2\n" HDR3 "\n" P1 "\n" P2, ODHS_E_FORMAT, 4},
    {"truncated mid-line", "2\n" HDR3 "\n" P1 "A 4 4", ODHS_E_FORMAT, 4},
    {"truncated in comment line", "2\nLattice=\"10 0 0 0", ODHS_E_FORMAT, 2},
    {"NaN position", "2\n" HDR3 "\n" P1 "A NaN 4 4 0.5\n", ODHS_E_FORMAT, 4},
    {"inf position", "2\n" HDR3 "\n" "A 1 -inf 1 0.5\n" P2, ODHS_E_FORMAT, 3},
    {"overflowing position", "2\n" HDR3 "\n" "A 1 1e999 1 0.5\n" P2, ODHS_E_FORMAT, 3},
    {"inf radius", "2\n" HDR3 "\n" P1 "A 4 4 4 infinity\n", ODHS_E_FORMAT, 4},
    {"NaN z in 2D", "2\n" HDR2 "\n" "A 1 1 nan 0.5\nA 4 4 0 0.5\n", ODHS_E_FORMAT, 3},
    {"zero radius", "2\n" HDR3 "\n" P1 "A 4 4 4 0\n", ODHS_E_FORMAT, 4},
    {"negative radius", "2\n" HDR3 "\n" P1 "A 4 4 4 -0.5\n", ODHS_E_FORMAT, 4},
    {"species label too long", "2\n" HDR3 "\n" P1 "ABCDEFGHIJKLMNOP 4 4 4 0.5\n",
     ODHS_E_FORMAT, 4},
    {"species label with quote", "2\n" HDR3 "\n" P1 "A\"b 4 4 4 0.5\n", ODHS_E_FORMAT, 4},
    {"overlapping particles", "2\n" HDR3 "\n" P1 "A 1.5 1 1 0.5\n", ODHS_E_OVERLAP, 0},
    {"overlap across the boundary", "2\n" HDR3 "\n" "A 0.1 5 5 0.5\nA 9.5 5 5 0.5\n",
     ODHS_E_OVERLAP, 0},
    {"box too small", "2\n" HDR3 "\n" P1 "A 6 6 6 3\n", ODHS_E_BOX, 0},
};

START_TEST(test_malformed)
{
    const bad_case *c = &bad_cases[_i];
    char err[ODHS_ERRMSG_LEN];
    char want[32];
    odhs_system *sys = (odhs_system *)&err; /* junk: must be reset to NULL */
    memset(err, 'x', sizeof err);
    int st = parse_str(c->text, &sys, err, sizeof err);
    ck_assert_msg(st == c->status, "case '%s': status %d (%s), want %d; message: %s", c->name, st,
                  odhs_strerror(st), c->status, err);
    ck_assert_msg(sys == NULL, "case '%s': *out not NULL", c->name);
    ck_assert_msg(memchr(err, '\0', sizeof err) != NULL && err[0] != '\0',
                  "case '%s': no message", c->name);
    if (c->line > 0) {
        snprintf(want, sizeof want, "line %d", c->line);
        ck_assert_msg(strstr(err, want) != NULL, "case '%s': message '%s' does not name %s",
                      c->name, err, want);
    } else {
        ck_assert_msg(strncmp(err, "file: ", 6) == 0, "case '%s': message '%s' lacks 'file: '",
                      c->name, err);
    }

    /* the same through a file */
    char path[256];
    tmppath(path, sizeof path, "bad.xyz");
    write_text(path, c->text, strlen(c->text));
    sys = (odhs_system *)&err;
    char err2[ODHS_ERRMSG_LEN];
    st = odhs_xyz_read(path, &sys, err2, sizeof err2);
    ck_assert_int_eq(st, c->status);
    ck_assert_ptr_null(sys);
    ck_assert_str_eq(err, err2);

    /* and with no error buffer at all */
    sys = (odhs_system *)&err;
    ck_assert_int_eq(parse_str(c->text, &sys, NULL, 0), c->status);
    ck_assert_ptr_null(sys);
}
END_TEST

/* bytes that are not text: an embedded NUL inside a number, and a file whose
 * buffer is not NUL-terminated and ends right after a digit */
START_TEST(test_binary_garbage)
{
    static const char t1[] = "1\n" HDR3 "\nA 1\0 1 1 0.5\n";
    odhs_system *sys = NULL;
    char err[ODHS_ERRMSG_LEN];
    ck_assert_int_eq(parse_exact(t1, sizeof t1 - 1, &sys, err, sizeof err), ODHS_E_FORMAT);
    ck_assert_ptr_null(sys);
    ck_assert_ptr_nonnull(strstr(err, "line 3"));

    static const char t2[] = "1\0\n" HDR3 "\nA 1 1 1 0.5\n";
    ck_assert_int_eq(parse_exact(t2, sizeof t2 - 1, &sys, err, sizeof err), ODHS_E_FORMAT);
    ck_assert_ptr_null(sys);
    ck_assert_ptr_nonnull(strstr(err, "line 1"));

    /* a number longer than any sensible number */
    char *big = malloc(4096);
    strcpy(big, "1\n" HDR3 "\nA 1 1 1 0.");
    size_t l = strlen(big);
    memset(big + l, '5', 3000);
    strcpy(big + l + 3000, "\n");
    ck_assert_int_eq(parse_str(big, &sys, err, sizeof err), ODHS_E_FORMAT);
    ck_assert_ptr_null(sys);
    ck_assert_ptr_nonnull(strstr(err, "line 3"));
    free(big);
}
END_TEST

/* Every prefix of a valid file, and many randomly corrupted copies, parse
 * without crashing, and an error always comes with *out == NULL. */
START_TEST(test_fuzz)
{
    const char *good = "3\n"
                       "Lattice=\"10 0 0 2.5 10 0 0 0 12\" "
                       "Properties=species:S:1:pos:R:3:radius:R:1:id:I:1 pbc=\"T T T\" dim=3 "
                       "strain=0.25\r\n"
                       "A 1 2 3 0.5 1\n"
                       "B 5.5 6.25 7.125 0.75 2\n"
                       "Big 9.875 0.125 11.5 1 3\n";
    size_t len = strlen(good);
    char err[64];
    for (size_t k = 0; k <= len; k++) {
        odhs_system *sys = (odhs_system *)err;
        int st = parse_exact(good, k, &sys, err, sizeof err);
        if (st < 0) {
            ck_assert_ptr_null(sys);
            ck_assert(err[0] != '\0');
        } else {
            ck_assert_ptr_nonnull(sys);
            odhs_system_destroy(sys);
        }
    }
    char *buf = malloc(len);
    static const char alphabet[] = "0123456789 .-+eE\n\r\t\"=:ATFSRIxn\0";
    for (int trial = 0; trial < 3000; trial++) {
        memcpy(buf, good, len);
        int edits = 1 + (int)(urand() * 4);
        for (int e = 0; e < edits; e++) {
            size_t pos = (size_t)(urand() * (double)len);
            if (urand() < 0.5)
                buf[pos] = alphabet[(size_t)(urand() * (sizeof alphabet - 1))];
            else
                buf[pos] = (char)(urand() * 256);
        }
        size_t l = urand() < 0.2 ? (size_t)(urand() * (double)len) : len;
        odhs_system *sys = (odhs_system *)err;
        int st = parse_exact(buf, l, &sys, err, sizeof err);
        if (st < 0) {
            ck_assert_ptr_null(sys);
        } else {
            ck_assert_ptr_nonnull(sys);
            ck_assert_int_eq(odhs_system_validate(sys, 1e-6), ODHS_OK);
            odhs_system_destroy(sys);
        }
    }
    free(buf);
}
END_TEST

/* ---- argument and I/O errors ---------------------------------------------- */

START_TEST(test_null_args)
{
    odhs_system *sys = (odhs_system *)&sys;
    char err[ODHS_ERRMSG_LEN];
    ck_assert_int_eq(odhs_xyz_read(NULL, &sys, err, sizeof err), ODHS_E_NULL);
    ck_assert_ptr_null(sys);
    ck_assert_int_eq(odhs_xyz_read("/tmp/whatever.xyz", NULL, err, sizeof err), ODHS_E_NULL);
    sys = (odhs_system *)&sys;
    ck_assert_int_eq(odhs_xyz_parse(NULL, 10, &sys, err, sizeof err), ODHS_E_NULL);
    ck_assert_ptr_null(sys);
    ck_assert_int_eq(odhs_xyz_parse("1\n", 2, NULL, NULL, 0), ODHS_E_NULL);
    ck_assert_int_eq(odhs_xyz_write(NULL, "/tmp/whatever.xyz"), ODHS_E_NULL);

    ck_assert_int_eq(odhs_system_create(3, 2, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_xyz_write(sys, NULL), ODHS_E_NULL);
    /* radii and positions unset */
    char path[256];
    tmppath(path, sizeof path, "state.xyz");
    ck_assert_int_eq(odhs_xyz_write(sys, path), ODHS_E_STATE);
    ck_assert_int_eq(access(path, F_OK), -1);
    odhs_system_destroy(sys);
}
END_TEST

START_TEST(test_read_io_errors)
{
    odhs_system *sys = (odhs_system *)&sys;
    char err[ODHS_ERRMSG_LEN];
    char path[256];
    tmppath(path, sizeof path, "does-not-exist.xyz");
    ck_assert_int_eq(odhs_xyz_read(path, &sys, err, sizeof err), ODHS_E_IO);
    ck_assert_ptr_null(sys);
    ck_assert_ptr_nonnull(strstr(err, "does-not-exist.xyz"));
    /* a directory */
    sys = (odhs_system *)&sys;
    ck_assert_int_eq(odhs_xyz_read(tmpdir, &sys, err, sizeof err), ODHS_E_IO);
    ck_assert_ptr_null(sys);
    /* a tiny error buffer is filled without overflow */
    char small[8];
    memset(small, 'x', sizeof small);
    ck_assert_int_eq(odhs_xyz_read(path, &sys, small, 5), ODHS_E_IO);
    ck_assert_int_eq(small[4], '\0');
    ck_assert_int_eq(small[5], 'x');
}
END_TEST

START_TEST(test_write_unwritable)
{
    odhs_system *sys = make_scene(2, 0.1);
    int st = odhs_xyz_write(sys, "/nonexistent-dir/x.xyz");
    ck_assert_int_eq(st, ODHS_E_IO);
    ck_assert(odhs_system_errmsg(sys)[0] != '\0');
    ck_assert_int_eq(access("/nonexistent-dir", F_OK), -1);

    /* the target is a directory: the temporary file is written, the rename
     * fails, and nothing is left behind */
    char dir[256];
    tmppath(dir, sizeof dir, "subdir");
    ck_assert_int_eq(mkdir(dir, 0700), 0);
    ck_assert_int_eq(odhs_xyz_write(sys, dir), ODHS_E_IO);
    struct stat sb;
    ck_assert_int_eq(stat(dir, &sb), 0);
    ck_assert(S_ISDIR(sb.st_mode));
    ck_assert_int_eq(count_dir_entries(), 1);

    /* a read-only directory with an existing file: the write fails and the
     * old file is intact (not testable as root, who may write anyway) */
    if (geteuid() != 0) {
        char ro[256], old[300];
        tmppath(ro, sizeof ro, "ro");
        ck_assert_int_eq(mkdir(ro, 0700), 0);
        snprintf(old, sizeof old, "%s/old.xyz", ro);
        write_text(old, "old contents\n", 13);
        ck_assert_int_eq(chmod(ro, 0500), 0);
        ck_assert_int_eq(odhs_xyz_write(sys, old), ODHS_E_IO);
        char *t = slurp(old, NULL);
        ck_assert_str_eq(t, "old contents\n");
        free(t);
        ck_assert_int_eq(chmod(ro, 0700), 0);
        ck_assert_int_eq(remove(old), 0);
        ck_assert_int_eq(rmdir(ro), 0);
    }
    odhs_system_destroy(sys);
}
END_TEST

START_TEST(test_write_replaces_existing)
{
    char path[256], err[ODHS_ERRMSG_LEN];
    tmppath(path, sizeof path, "existing.xyz");
    /* an old file that is longer than the new one */
    size_t biglen = 200000;
    char *big = malloc(biglen);
    memset(big, '#', biglen);
    write_text(path, big, biglen);
    free(big);

    odhs_system *sys = make_scene(3, -0.37);
    ck_assert_int_eq(odhs_xyz_write(sys, path), ODHS_OK);
    odhs_system *back = NULL;
    int st = odhs_xyz_read(path, &back, err, sizeof err);
    ck_assert_msg(st == ODHS_OK, "%s", err);
    assert_same_system(sys, back);
    ck_assert_int_eq(count_dir_entries(), 1);

    /* overwrite again with a different (2D) system */
    odhs_system *sys2 = make_scene(2, 0.5);
    ck_assert_int_eq(odhs_xyz_write(sys2, path), ODHS_OK);
    odhs_system_destroy(back);
    back = NULL;
    ck_assert_int_eq(odhs_xyz_read(path, &back, err, sizeof err), ODHS_OK);
    assert_same_system(sys2, back);
    ck_assert_int_eq(count_dir_entries(), 1);

    odhs_system_destroy(back);
    odhs_system_destroy(sys2);
    odhs_system_destroy(sys);
}
END_TEST

/* A state written between two drift corrections reads back: contact gaps
 * drift to small negative values (overlaps up to ~1e-4 of the contact
 * distance with the paper's Euler steps); real overlaps are still refused,
 * and the setters keep their 1e-10 acceptance. */
START_TEST(test_read_drifted_contacts)
{
    const char *ok = "2\n" HDR3 "\nA 1 1 1 0.5\nA 1.99999 1 1 0.5\n";   /* overlap 1e-5 */
    const char *bad = "2\n" HDR3 "\nA 1 1 1 0.5\nA 1.9998 1 1 0.5\n";   /* overlap 2e-4 */
    odhs_system *sys = NULL;
    char err[256];
    ck_assert_int_eq(odhs_xyz_parse(ok, strlen(ok), &sys, err, sizeof err), ODHS_OK);
    double x[6];
    ck_assert_int_eq(odhs_system_get_positions(sys, x), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_positions(sys, x), ODHS_E_OVERLAP); /* the setters: 1e-10 */
    odhs_system_destroy(sys);
    sys = NULL;
    ck_assert_int_eq(odhs_xyz_parse(bad, strlen(bad), &sys, err, sizeof err), ODHS_E_OVERLAP);
    ck_assert_ptr_null(sys);
}
END_TEST

Suite *make_io_suite(void)
{
    Suite *s = suite_create("io");
    TCase *tc;

    tc = tcase_create("roundtrip");
    tcase_add_checked_fixture(tc, io_setup, io_teardown);
    tcase_add_loop_test(tc, test_roundtrip_3d, 0, (int)(sizeof rt_strains / sizeof *rt_strains));
    tcase_add_loop_test(tc, test_roundtrip_2d, 0, (int)(sizeof rt_strains / sizeof *rt_strains));
    tcase_add_test(tc, test_write_format);
    suite_add_tcase(s, tc);

    tc = tcase_create("read");
    tcase_add_checked_fixture(tc, io_setup, io_teardown);
    tcase_add_test(tc, test_read_handwritten_3d);
    tcase_add_test(tc, test_read_handwritten_2d);
    tcase_add_test(tc, test_read_variants);
    tcase_add_test(tc, test_read_extra_columns);
    tcase_add_test(tc, test_read_drifted_contacts);
    suite_add_tcase(s, tc);

    tc = tcase_create("malformed");
    tcase_add_checked_fixture(tc, io_setup, io_teardown);
    tcase_add_loop_test(tc, test_malformed, 0, (int)(sizeof bad_cases / sizeof *bad_cases));
    tcase_add_test(tc, test_binary_garbage);
    tcase_add_test(tc, test_fuzz);
    tcase_set_timeout(tc, 60);
    suite_add_tcase(s, tc);

    tc = tcase_create("errors");
    tcase_add_checked_fixture(tc, io_setup, io_teardown);
    tcase_add_test(tc, test_null_args);
    tcase_add_test(tc, test_read_io_errors);
    tcase_add_test(tc, test_write_unwritable);
    tcase_add_test(tc, test_write_replaces_existing);
    suite_add_tcase(s, tc);

    return s;
}
