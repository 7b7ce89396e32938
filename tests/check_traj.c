/*
 * libodhs tests - trajectories (traj.h), multi-frame XYZ reading
 * (odhs_xyz_read_frame), the contacts CSV and the external-force accessor.
 *
 * Every frame read back is compared bit for bit with the state the writer
 * saw; the trajectory must not change the run; a failed write adds nothing.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <dirent.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "odhs.h"

#include "tmpfiles.h"

static void tr_setup(void) { tmpdir_make("traj"); }

static void tr_teardown(void) { tmpdir_remove(); }

static const char *path_of(const char *name)
{
    static char buf[256];
    snprintf(buf, sizeof buf, "%s/%s", tmpdir, name);
    return buf;
}

static long file_size(const char *path)
{
    struct stat sb;
    return stat(path, &sb) ? -1 : (long)sb.st_size;
}

/* a sheared scene: N bidisperse particles at phi, a stepper (dense solver) */
typedef struct {
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *solver;
    odhs_stepper *st;
} scene;

static void scene_make(scene *s, int dim, size_t n, double phi, uint64_t seed)
{
    ck_assert_int_eq(odhs_system_create(dim, n, &s->sys), 0);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(s->sys, 0.5, 1.4, 0.03, seed), 0);
    ck_assert_int_eq(odhs_system_place_random(s->sys, phi, seed + 1), 0);
    ck_assert_int_eq(odhs_driver_create(&s->drv), 0);
    ck_assert_int_eq(odhs_driver_set_shear_rate(s->drv, 1.0), 0);
    ck_assert_int_eq(odhs_solver_create_by_name("dense", &s->solver), 0);
    ck_assert_int_eq(odhs_stepper_create(s->sys, s->drv, s->solver, &s->st), 0);
}

static void scene_free(scene *s)
{
    odhs_stepper_destroy(s->st);
    odhs_solver_destroy(s->solver);
    odhs_driver_destroy(s->drv);
    odhs_system_destroy(s->sys);
}

#define NFR 6
/* positions, radii and strain of the frames written */
typedef struct {
    double *x[NFR], *r[NFR], *v[NFR], gamma[NFR];
} saved;

static void save_state(saved *sv, int k, const scene *s)
{
    size_t n = odhs_system_count(s->sys), nd = n * (size_t)odhs_system_dim(s->sys);
    sv->x[k] = malloc(nd * sizeof(double));
    sv->r[k] = malloc(n * sizeof(double));
    sv->v[k] = malloc(nd * sizeof(double));
    odhs_system_get_positions(s->sys, sv->x[k]);
    odhs_system_get_radii(s->sys, sv->r[k]);
    odhs_system_get_strain(s->sys, &sv->gamma[k]);
    ck_assert_int_eq(odhs_stepper_velocities(s->st, sv->v[k]), 0);
}

static void saved_free(saved *sv)
{
    for (int k = 0; k < NFR; ++k) {
        free(sv->x[k]);
        free(sv->r[k]);
        free(sv->v[k]);
    }
}

/* the trajectory of a shear run, NFR frames 0.01 of strain apart */
static void write_run(scene *s, const char *path, int format, saved *sv)
{
    odhs_traj *tr = NULL;
    char err[256];
    if (path) ck_assert_int_eq(odhs_traj_open(path, format, &tr, err, sizeof err), 0);
    ck_assert_int_eq(odhs_stepper_reset(s->st), 0);
    for (int k = 0; k < NFR; ++k) {
        if (k) ck_assert_int_eq(odhs_stepper_run_until_strain(s->st, 0.01 * k), 0);
        if (sv) save_state(sv, k, s);
        if (tr) ck_assert_int_eq(odhs_traj_write(tr, s->sys, s->st), 0);
    }
    uint64_t nf = 0;
    if (tr) {
        ck_assert_int_eq(odhs_traj_frames(tr, &nf), 0);
        ck_assert_uint_eq(nf, NFR);
    }
    ck_assert_int_eq(odhs_traj_close(tr), 0);
}

/* the particle lines of frame k: column col (0-based) of particle i */
static double column_of(const char *path, int k, size_t i, int col)
{
    FILE *f = fopen(path, "r");
    ck_assert_ptr_nonnull(f);
    char line[4096];
    int frame = -1;
    size_t n = 0, row = 0;
    double v = NAN;
    while (fgets(line, sizeof line, f)) {
        if (frame < 0 || row == n + 1) { /* a count line */
            n = strtoul(line, NULL, 10);
            frame++;
            row = 0;
            continue;
        }
        if (frame == k && row == i + 1) {
            char *p = line;
            for (int c = 0; c <= col; ++c) {
                p += strspn(p, " ");
                if (c == col) v = strtod(p, NULL);
                p += strcspn(p, " ");
            }
            break;
        }
        row++;
    }
    fclose(f);
    return v;
}

static void check_frames(int dim)
{
    scene s;
    saved sv;
    memset(&sv, 0, sizeof sv);
    scene_make(&s, dim, dim == 2 ? 32 : 24, dim == 2 ? 0.6 : 0.35, 5);
    const char *p = path_of("t.xyz");
    write_run(&s, p, ODHS_TRAJ_XYZ, &sv);
    size_t n = odhs_system_count(s.sys);
    for (int k = -1; k < NFR; ++k) {
        odhs_system *r = NULL;
        long nf = 0;
        char err[256];
        ck_assert_msg(odhs_xyz_read_frame(p, k, &r, &nf, err, sizeof err) == 0, "frame %d: %s", k, err);
        int kk = k < 0 ? NFR - 1 : k;
        ck_assert_int_eq(nf, NFR);
        ck_assert_int_eq(odhs_system_dim(r), dim);
        double *x = malloc(n * dim * sizeof *x), *rad = malloc(n * sizeof *rad), g;
        odhs_system_get_positions(r, x);
        odhs_system_get_radii(r, rad);
        odhs_system_get_strain(r, &g);
        ck_assert_mem_eq(x, sv.x[kk], n * dim * sizeof *x);
        ck_assert_mem_eq(rad, sv.r[kk], n * sizeof *rad);
        ck_assert_double_eq(g, sv.gamma[kk]);
        char lab[ODHS_SPECIES_MAX + 1], want[ODHS_SPECIES_MAX + 1];
        odhs_system_get_species(r, 3, lab, sizeof lab);
        odhs_system_get_species(s.sys, 3, want, sizeof want);
        ck_assert_str_eq(lab, want);
        /* the velocity columns hold V exactly (columns 5.. after label, pos, radius) */
        for (int a = 0; a < dim; ++a) ck_assert_double_eq(column_of(p, kk, 7, 5 + a), sv.v[kk][7 * dim + a]);
        free(x);
        free(rad);
        odhs_system_destroy(r);
    }
    odhs_system *r = NULL;
    char err[256];
    ck_assert_int_eq(odhs_xyz_read_frame(p, NFR, &r, NULL, err, sizeof err), ODHS_E_RANGE);
    ck_assert_ptr_null(r);
    ck_assert_ptr_nonnull(strstr(err, "6 frames"));
    ck_assert_int_eq(odhs_xyz_read_frame(p, -NFR - 1, &r, NULL, err, sizeof err), ODHS_E_RANGE);
    /* a frame cut short is reported with its number */
    FILE *f = fopen(p, "a");
    fprintf(f, "%zu\nLattice=\"1 0 0 0 1 0 0 0 1\" Properties=species:S:1:pos:R:3:radius:R:1\nA 0 0 0 0.1\n", n);
    fclose(f);
    ck_assert_int_eq(odhs_xyz_read_frame(p, 0, &r, NULL, err, sizeof err), ODHS_E_FORMAT);
    ck_assert_ptr_nonnull(strstr(err, "frame 6"));
    /* the plain reader reads the first frame of a trajectory */
    ck_assert_int_eq(odhs_xyz_read(path_of("t.xyz"), &r, err, sizeof err), 0);
    odhs_system_destroy(r);
    saved_free(&sv);
    scene_free(&s);
}

START_TEST(test_xyz_frames_2d) { check_frames(2); }
END_TEST

START_TEST(test_xyz_frames_3d) { check_frames(3); }
END_TEST

/* writing a trajectory never changes the run */
START_TEST(test_traj_does_not_change_run)
{
    scene a, b;
    scene_make(&a, 2, 48, 0.5, 9);
    scene_make(&b, 2, 48, 0.5, 9);
    write_run(&a, NULL, 0, NULL);
    write_run(&b, path_of("t.dump"), ODHS_TRAJ_LAMMPS_DUMP, NULL);
    size_t nd = 96;
    double xa[96], xb[96];
    odhs_system_get_positions(a.sys, xa);
    odhs_system_get_positions(b.sys, xb);
    ck_assert_mem_eq(xa, xb, nd * sizeof *xa);
    uint64_t sa, sb;
    odhs_stepper_counts(a.st, &sa, NULL, NULL);
    odhs_stepper_counts(b.st, &sb, NULL, NULL);
    ck_assert_uint_eq(sa, sb);
    scene_free(&a);
    scene_free(&b);
}
END_TEST

/* LAMMPS dump: items, ids, types, the tilted cell holding every atom */
START_TEST(test_lammps_dump)
{
    scene s;
    scene_make(&s, 2, 32, 0.6, 3);
    ck_assert_int_eq(odhs_driver_set_shear_rate(s.drv, 1.0), 0);
    const char *p = path_of("t.lammpstrj");
    odhs_traj *tr;
    ck_assert_int_eq(odhs_traj_open(p, ODHS_TRAJ_LAMMPS_DUMP, &tr, NULL, 0), 0);
    ck_assert_int_eq(odhs_traj_write(tr, s.sys, NULL), 0); /* positions only */
    ck_assert_int_eq(odhs_stepper_run_until_strain(s.st, 0.35), 0);
    ck_assert_int_eq(odhs_traj_write(tr, s.sys, s.st), 0);
    ck_assert_int_eq(odhs_traj_close(tr), 0);
    double L[3], g;
    odhs_system_get_box(s.sys, L);
    odhs_system_get_strain(s.sys, &g);
    FILE *f = fopen(p, "r");
    char line[4096];
    int frames = 0, atoms = 0, seen[32] = {0};
    double xy = NAN;
    while (fgets(line, sizeof line, f)) {
        if (!strncmp(line, "ITEM: TIMESTEP", 14)) frames++;
        if (!strncmp(line, "ITEM: BOX BOUNDS xy xz yz pp pp pp", 34)) {
            double lo, hi;
            ck_assert_ptr_nonnull(fgets(line, sizeof line, f));
            ck_assert_int_eq(sscanf(line, "%lf %lf %lf", &lo, &hi, &xy), 3);
            ck_assert(fabs(xy) <= 0.5 * L[0]);
            /* xy is gamma Ly up to a multiple of Lx (gamma 0 in the first frame) */
            double m = ((frames == 2 ? g : 0.0) * L[1] - xy) / L[0];
            ck_assert(fabs(m - nearbyint(m)) < 1e-12);
            ck_assert_double_eq(lo, fmin(0.0, xy));
            ck_assert_double_eq_tol(hi, L[0] + fmax(0.0, xy), 1e-12 * L[0]);
        }
        if (frames == 2 && !strncmp(line, "ITEM: ATOMS", 11)) {
            ck_assert_str_eq(line, "ITEM: ATOMS id type radius x y z vx vy vz ux uy uz fx fy fz\n");
            for (int i = 0; i < 32; ++i) {
                ck_assert_ptr_nonnull(fgets(line, sizeof line, f));
                int id, type;
                double r, x, y, z;
                ck_assert_int_eq(sscanf(line, "%d %d %lf %lf %lf %lf", &id, &type, &r, &x, &y, &z), 6);
                ck_assert(id >= 1 && id <= 32 && !seen[id - 1]);
                seen[id - 1] = 1;
                char lab[16];
                odhs_system_get_species(s.sys, (size_t)id - 1, lab, sizeof lab);
                ck_assert_int_eq(type, !strcmp(lab, "S") ? 1 : 2); /* particle 0 is S */
                double u = x - xy * y / L[1];
                ck_assert(u >= 0.0 && u < L[0]);
                ck_assert_double_eq(z, 0.0);
                atoms++;
            }
        }
    }
    fclose(f);
    ck_assert_int_eq(frames, 2);
    ck_assert_int_eq(atoms, 32);
    scene_free(&s);
}
END_TEST

/* contact networks: the dump local and the CSV list the network's contacts */
START_TEST(test_contacts_outputs)
{
    scene s;
    scene_make(&s, 2, 64, 0.5, 11);
    /* compress to phi = 0.8 first, then shear: a dense network */
    ck_assert_int_eq(odhs_driver_set_compression_rate(s.drv, 1.0), 0);
    ck_assert_int_eq(odhs_stepper_run_until_packing_fraction(s.st, 0.8), 0);
    ck_assert_int_eq(odhs_driver_set_compression_rate(s.drv, 0.0), 0);
    ck_assert_int_eq(odhs_stepper_run_until_strain(s.st, 0.05), 0);
    const odhs_network *net = odhs_stepper_network(s.st);
    size_t nc = odhs_network_count(net);
    ck_assert(nc > 20);
    double *fc = malloc(nc * sizeof *fc);
    odhs_network_get_forces(net, fc);
    const char *p = path_of("c.csv");
    ck_assert_int_eq(odhs_contacts_write_csv(net, s.sys, p), 0);
    FILE *f = fopen(p, "r");
    char line[512];
    ck_assert_ptr_nonnull(fgets(line, sizeof line, f));
    ck_assert_str_eq(line, "i,j,kind,force,gap\n");
    for (size_t c = 0; c < nc; ++c) {
        size_t i, j, ii, jj;
        int kind, kk;
        double force, gap;
        ck_assert_ptr_nonnull(fgets(line, sizeof line, f));
        ck_assert_int_eq(sscanf(line, "%zu,%zu,%d,%lf,%lf", &i, &j, &kind, &force, &gap), 5);
        odhs_network_get_contact(net, c, &ii, &jj, &kk);
        ck_assert(i == ii && j == jj && kind == kk);
        ck_assert_double_eq(force, fc[c]);
    }
    ck_assert_ptr_null(fgets(line, sizeof line, f));
    fclose(f);
    const char *q = path_of("c.bonds");
    odhs_traj *tr;
    ck_assert_int_eq(odhs_traj_open(q, ODHS_TRAJ_LAMMPS_LOCAL, &tr, NULL, 0), 0);
    ck_assert_int_eq(odhs_traj_write(tr, s.sys, NULL), ODHS_E_NULL); /* needs the stepper */
    ck_assert_ptr_nonnull(strstr(odhs_traj_errmsg(tr), "stepper"));
    ck_assert_int_eq(odhs_traj_write(tr, s.sys, s.st), 0);
    ck_assert_int_eq(odhs_traj_close(tr), 0);
    f = fopen(q, "r");
    size_t entries = 0, rows = 0;
    while (fgets(line, sizeof line, f)) {
        if (!strcmp(line, "ITEM: NUMBER OF ENTRIES\n")) ck_assert_int_eq(fscanf(f, "%zu\n", &entries), 1);
        if (!strcmp(line, "ITEM: ENTRIES index batom1 batom2 kind force gap\n")) {
            size_t k, a, b;
            int kind;
            double force, gap;
            while (fscanf(f, "%zu %zu %zu %d %lf %lf\n", &k, &a, &b, &kind, &force, &gap) == 6) {
                size_t ii, jj;
                odhs_network_get_contact(net, rows, &ii, &jj, NULL);
                ck_assert(k == rows + 1 && a == ii + 1 && b == jj + 1);
                ck_assert_double_eq(force, fc[rows]);
                rows++;
            }
        }
    }
    fclose(f);
    ck_assert_uint_eq(entries, nc);
    ck_assert_uint_eq(rows, nc);
    free(fc);
    scene_free(&s);
}
END_TEST

/* the external forces the stepper used, and their column in the trajectory */
START_TEST(test_external_forces)
{
    scene s;
    scene_make(&s, 3, 16, 0.2, 4);
    double F[48], out[48];
    ck_assert_int_eq(odhs_stepper_external_forces(s.st, out), ODHS_E_STATE);
    ck_assert_int_eq(odhs_stepper_external_forces(s.st, NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_stepper_external_forces(NULL, out), ODHS_E_NULL);
    ck_assert_int_eq(odhs_stepper_reset(s.st), 0);
    ck_assert_int_eq(odhs_stepper_external_forces(s.st, out), 0);
    for (int k = 0; k < 48; ++k) ck_assert_double_eq(out[k], 0.0);
    for (int k = 0; k < 48; ++k) F[k] = 0.25 * sin(1.0 + k);
    ck_assert_int_eq(odhs_driver_set_forces(s.drv, 16, 3, F), 0);
    ck_assert_int_eq(odhs_stepper_run_until_strain(s.st, 0.01), 0);
    ck_assert_int_eq(odhs_stepper_external_forces(s.st, out), 0);
    ck_assert_mem_eq(out, F, sizeof F);
    const char *p = path_of("f.extxyz");
    odhs_traj *tr;
    ck_assert_int_eq(odhs_traj_open(p, ODHS_TRAJ_XYZ, &tr, NULL, 0), 0);
    ck_assert_int_eq(odhs_traj_write(tr, s.sys, s.st), 0);
    ck_assert_int_eq(odhs_traj_close(tr), 0);
    /* label, 3 pos, radius, 3 V, 3 U, then the 3 forces */
    for (int a = 0; a < 3; ++a) ck_assert_double_eq(column_of(p, 0, 5, 11 + a), F[15 + a]);
    scene_free(&s);
}
END_TEST

START_TEST(test_bad_input)
{
    int fmt = -7;
    ck_assert_int_eq(odhs_traj_format_for("a.XYZ", &fmt), 0);
    ck_assert_int_eq(fmt, ODHS_TRAJ_XYZ);
    ck_assert_int_eq(odhs_traj_format_for("run.lammpstrj", &fmt), 0);
    ck_assert_int_eq(fmt, ODHS_TRAJ_LAMMPS_DUMP);
    ck_assert_int_eq(odhs_traj_format_for("x.dump", &fmt), 0);
    ck_assert_int_eq(odhs_traj_format_for("x.extxyz", &fmt), 0);
    ck_assert_int_eq(fmt, ODHS_TRAJ_XYZ);
    ck_assert_int_eq(odhs_traj_format_for("x.txt", &fmt), ODHS_E_INVALID);
    ck_assert_int_eq(odhs_traj_format_for(".xyz", &fmt), ODHS_E_INVALID);
    ck_assert_int_eq(fmt, ODHS_TRAJ_XYZ);
    ck_assert_int_eq(odhs_traj_format_for(NULL, &fmt), ODHS_E_NULL);
    odhs_traj *tr = (odhs_traj *)&fmt;
    char err[256];
    ck_assert_int_eq(odhs_traj_open(path_of("a.xyz"), 3, &tr, err, sizeof err), ODHS_E_INVALID);
    ck_assert_ptr_null(tr);
    ck_assert_ptr_nonnull(strstr(err, "format"));
    ck_assert_int_eq(odhs_traj_open(NULL, 0, &tr, err, sizeof err), ODHS_E_NULL);
    ck_assert_int_eq(odhs_traj_open(path_of("no/dir/a.xyz"), 0, &tr, err, sizeof err), ODHS_E_IO);
    ck_assert_ptr_nonnull(strstr(err, "no/dir/a.xyz"));
    ck_assert_int_eq(odhs_traj_write(NULL, NULL, NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_traj_frames(NULL, NULL), ODHS_E_NULL);
    ck_assert_str_eq(odhs_traj_errmsg(NULL), "");
    ck_assert_int_eq(odhs_traj_close(NULL), 0);

    scene s, other;
    scene_make(&s, 2, 16, 0.5, 1);
    scene_make(&other, 2, 16, 0.5, 2);
    const char *p = path_of("a.xyz");
    ck_assert_int_eq(odhs_traj_open(p, ODHS_TRAJ_XYZ, &tr, err, sizeof err), 0);
    ck_assert_int_eq(odhs_traj_write(tr, s.sys, NULL), 0);
    long size = file_size(p);
    ck_assert_int_eq(odhs_traj_write(tr, NULL, NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_traj_write(tr, s.sys, other.st), ODHS_E_INVALID);
    ck_assert_ptr_nonnull(strstr(odhs_traj_errmsg(tr), "another system"));
    odhs_system *empty;
    ck_assert_int_eq(odhs_system_create(2, 4, &empty), 0);
    ck_assert_int_eq(odhs_traj_write(tr, empty, NULL), ODHS_E_STATE);
    odhs_system_destroy(empty);
    ck_assert_int_eq(file_size(p), size); /* nothing added */
    uint64_t nf;
    odhs_traj_frames(tr, &nf);
    ck_assert_uint_eq(nf, 1);
    ck_assert_int_eq(odhs_traj_write(tr, s.sys, NULL), 0);
    ck_assert_int_eq(odhs_traj_close(tr), 0);
    ck_assert_int_eq(file_size(p), 2 * size);
    /* a device that refuses every write: the error, and no frame counted */
    if (access("/dev/full", W_OK) == 0) {
        ck_assert_int_eq(odhs_traj_open("/dev/full", ODHS_TRAJ_XYZ, &tr, err, sizeof err), 0);
        ck_assert_int_eq(odhs_traj_write(tr, s.sys, NULL), ODHS_E_IO);
        ck_assert_ptr_nonnull(strstr(odhs_traj_errmsg(tr), "frame 0"));
        odhs_traj_frames(tr, &nf);
        ck_assert_uint_eq(nf, 0);
        odhs_traj_close(tr);
    }
    scene_free(&s);
    scene_free(&other);
}
END_TEST

/* the reader takes type:S:1 for the label only when species is absent */
START_TEST(test_type_column)
{
    const char *both = "2\nLattice=\"4 0 0 0 4 0 0 0 1\" Properties=type:S:1:pos:R:3:radius:R:1:species:S:1 dim=2\n"
                       "T1 0.5 0.5 0 0.4 S1\nT2 2.5 2.5 0 0.4 S2\n";
    const char *type = "2\nLattice=\"4 0 0 0 4 0 0 0 1\" Properties=type:S:1:pos:R:3:radius:R:1 dim=2\n"
                       "T1 0.5 0.5 0 0.4\nT2 2.5 2.5 0 0.4\n";
    const char *numeric = "2\nLattice=\"4 0 0 0 4 0 0 0 1\" Properties=type:I:1:pos:R:3:radius:R:1 dim=2\n"
                          "1 0.5 0.5 0 0.4\n2 2.5 2.5 0 0.4\n";
    odhs_system *sys;
    char lab[16], err[256];
    ck_assert_int_eq(odhs_xyz_parse(both, strlen(both), &sys, err, sizeof err), 0);
    odhs_system_get_species(sys, 1, lab, sizeof lab);
    ck_assert_str_eq(lab, "S2");
    odhs_system_destroy(sys);
    ck_assert_int_eq(odhs_xyz_parse(type, strlen(type), &sys, err, sizeof err), 0);
    odhs_system_get_species(sys, 1, lab, sizeof lab);
    ck_assert_str_eq(lab, "T2");
    odhs_system_destroy(sys);
    ck_assert_int_eq(odhs_xyz_parse(numeric, strlen(numeric), &sys, err, sizeof err), ODHS_E_FORMAT);
    ck_assert_ptr_nonnull(strstr(err, "species"));
}
END_TEST

Suite *make_traj_suite(void)
{
    Suite *s = suite_create("traj");
    TCase *tc = tcase_create("traj");
    tcase_set_timeout(tc, 120);
    tcase_add_checked_fixture(tc, tr_setup, tr_teardown);
    tcase_add_test(tc, test_xyz_frames_2d);
    tcase_add_test(tc, test_xyz_frames_3d);
    tcase_add_test(tc, test_traj_does_not_change_run);
    tcase_add_test(tc, test_lammps_dump);
    tcase_add_test(tc, test_contacts_outputs);
    tcase_add_test(tc, test_external_forces);
    tcase_add_test(tc, test_bad_input);
    tcase_add_test(tc, test_type_column);
    suite_add_tcase(s, tc);
    return s;
}
