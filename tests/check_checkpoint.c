/* Check suite "checkpoint": save/restore of a whole simulation. */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "odhs.h"
#include "geom/geom.h" /* odhs__remap_strain, odhs__wrap */

static char dir[64];

static void setup(void)
{
    snprintf(dir, sizeof dir, "/tmp/odhs_ckpt_XXXXXX");
    ck_assert_ptr_nonnull(mkdtemp(dir));
}

static void teardown(void)
{
    char cmd[128];
    snprintf(cmd, sizeof cmd, "rm -rf %s", dir);
    if (system(cmd)) { /* best effort */
    }
}

static odhs_system *scene(int dim, size_t n, double phi, unsigned seed)
{
    odhs_system *sys;
    odhs_solver *sol;
    odhs_driver *drv;
    odhs_stepper *st;
    ck_assert_int_eq(odhs_system_create(dim, n, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, seed), ODHS_OK);
    ck_assert_int_eq(odhs_system_place_random(sys, dim == 2 ? 0.45 : 0.3, seed + 1), ODHS_OK);
    ck_assert_int_eq(odhs_solver_create_by_name("dense", &sol), ODHS_OK);
    ck_assert_int_eq(odhs_driver_create(&drv), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_compression_rate(drv, 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_create(sys, drv, sol, &st), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_run_until_packing_fraction(st, phi), ODHS_OK);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    return sys;
}

typedef struct {
    double t[4096];
    size_t i[4096], j[4096];
    int kind[4096];
    size_t n;
} evlog;

static int log_event(const odhs_event *ev, void *ctx)
{
    evlog *l = ctx;
    if (l->n < 4096) {
        l->t[l->n] = ev->time;
        l->i[l->n] = ev->i;
        l->j[l->n] = ev->j;
        l->kind[l->n] = ev->kind;
        l->n++;
    }
    return 0;
}

/* final state fingerprint */
typedef struct {
    double *x, *f;
    size_t nc;
    double t, g;
    uint64_t steps, ncoll, nopen;
} state;

static void grab(odhs_stepper *st, odhs_system *sys, state *s)
{
    size_t nd = odhs_system_count(sys) * (size_t)odhs_system_dim(sys);
    s->x = malloc(nd * sizeof *s->x);
    ck_assert_int_eq(odhs_system_get_positions(sys, s->x), ODHS_OK);
    const odhs_network *net = odhs_stepper_network(st);
    s->nc = odhs_network_count(net);
    s->f = malloc((s->nc + 1) * sizeof *s->f);
    ck_assert_int_eq(odhs_network_get_forces(net, s->f), ODHS_OK);
    odhs_stepper_time(st, &s->t);
    odhs_stepper_strain(st, &s->g);
    odhs_stepper_counts(st, &s->steps, &s->ncoll, &s->nopen);
}

/* flags for run_and_compare */
#define RC_PRESSURE 1
#define RC_PROPULSION 2
#define RC_GRAVITY 4
#define RC_NOSHEAR 8
#define RC_DRVCHANGE 16 /* change the driver just before writing */

static void run_and_compare(int dim, int integrator, const char *solver, int flags)
{
    int pressure = flags & RC_PRESSURE;
    odhs_system *base = scene(dim, dim == 2 ? 48 : 40, dim == 2 ? 0.74 : 0.5, 9);
    char path[128];
    snprintf(path, sizeof path, "%s/run.ckpt", dir);
    /* uninterrupted run A, with a checkpoint written half-way */
    odhs_system *sa;
    odhs_solver *sol;
    odhs_driver *da;
    odhs_stepper *a;
    ck_assert_int_eq(odhs_system_clone(base, &sa), ODHS_OK);
    ck_assert_int_eq(odhs_solver_create_by_name(solver, &sol), ODHS_OK);
    ck_assert_int_eq(odhs_driver_create(&da), ODHS_OK);
    if (!(flags & RC_NOSHEAR)) ck_assert_int_eq(odhs_driver_set_shear_rate(da, 1.0), ODHS_OK);
    if (pressure) ck_assert_int_eq(odhs_driver_set_pressure(da, 2.0), ODHS_OK);
    size_t np = odhs_system_count(sa);
    /* short persistence: many switches inside the 120 steps */
    if (flags & RC_PROPULSION)
        ck_assert_int_eq(odhs_driver_set_self_propulsion(da, np, dim, 0.5, 1.5, 0.0, 0.05, 17), ODHS_OK);
    if (flags & RC_GRAVITY) {
        double g[3] = {0.1, -0.4, 0.2}, *wt = malloc(np * sizeof *wt);
        ck_assert_int_eq(odhs_driver_set_gravity(da, dim, g), ODHS_OK);
        for (size_t i = 0; i < np; ++i) wt[i] = 1.0 + 0.25 * (double)(i % 3);
        if (flags & RC_PROPULSION) ck_assert_int_eq(odhs_driver_set_gravity_weights(da, np, wt), ODHS_OK);
        free(wt);
    }
    ck_assert_int_eq(odhs_stepper_create(sa, da, sol, &a), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_set_integrator(a, integrator), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_set_correction_interval(a, 7), ODHS_OK);
    evlog *la = calloc(1, sizeof *la), *lb = calloc(1, sizeof *lb);
    ck_assert_int_eq(odhs_stepper_set_event_callback(a, log_event, la), ODHS_OK);
    for (int k = 0; k < 60; ++k) ck_assert_int_eq(odhs_stepper_step(a, NULL), ODHS_OK);
    if (flags & RC_DRVCHANGE) {
        /* written after a driver change and before the step that re-solves
         * the forces for it: the restored run must re-solve too */
        if (pressure) ck_assert_int_eq(odhs_driver_set_pressure(da, 4.0), ODHS_OK);
        else ck_assert_int_eq(odhs_driver_set_shear_rate(da, 1.7), ODHS_OK);
    }
    ck_assert_int_eq(odhs_checkpoint_write(a, path), ODHS_OK);
    size_t mark = la->n;
    for (int k = 0; k < 60; ++k) ck_assert_int_eq(odhs_stepper_step(a, NULL), ODHS_OK);
    state A;
    grab(a, sa, &A);
    /* run B: restored from the checkpoint */
    odhs_system *sb;
    odhs_driver *db;
    odhs_stepper *b;
    char err[256];
    int rc = odhs_checkpoint_read(path, sol, &sb, &db, &b, err, sizeof err);
    ck_assert_msg(rc == ODHS_OK, "read: %s", err);
    ck_assert_int_eq(odhs_stepper_set_event_callback(b, log_event, lb), ODHS_OK);
    for (int k = 0; k < 60; ++k) ck_assert_int_eq(odhs_stepper_step(b, NULL), ODHS_OK);
    state B;
    grab(b, sb, &B);
    odhs_system *sb2;
    odhs_driver *db2;
    odhs_stepper *b2;
    size_t nd = odhs_system_count(sa) * (size_t)dim;
    ck_assert_msg(!memcmp(A.x, B.x, nd * sizeof *A.x), "positions differ after restore");
    ck_assert_uint_eq(A.nc, B.nc);
    ck_assert_msg(!memcmp(A.f, B.f, A.nc * sizeof *A.f), "forces differ after restore");
    ck_assert_msg(A.t == B.t && A.g == B.g, "time/strain differ");
    ck_assert(A.steps == B.steps && A.ncoll == B.ncoll && A.nopen == B.nopen);
    ck_assert_uint_eq(la->n - mark, lb->n);
    for (size_t e = 0; e < lb->n; ++e) {
        ck_assert(la->t[mark + e] == lb->t[e]);
        ck_assert(la->i[mark + e] == lb->i[e] && la->j[mark + e] == lb->j[e] && la->kind[mark + e] == lb->kind[e]);
    }
    ck_assert_msg(lb->n > 0, "no events in the second half: the test would not exercise rewiring");
    if (flags & RC_PROPULSION) {
        /* the propulsion state (forces, switch times, random numbers) too */
        size_t np = odhs_system_count(sa);
        double *Fa = malloc(nd * sizeof *Fa), *Fb = malloc(nd * sizeof *Fb);
        double *ta = malloc(np * sizeof *ta), *tb = malloc(np * sizeof *tb);
        ck_assert_int_eq(odhs_driver_get_propulsion(da, Fa, ta), ODHS_OK);
        ck_assert_int_eq(odhs_driver_get_propulsion(db, Fb, tb), ODHS_OK);
        ck_assert(!memcmp(Fa, Fb, nd * sizeof *Fa) && !memcmp(ta, tb, np * sizeof *ta));
        /* and it switched during the compared half */
        ck_assert(ta[0] > 0.0);
        double t0;
        ck_assert_int_eq(odhs_checkpoint_read(path, sol, &sb2, &db2, &b2, NULL, 0), ODHS_OK);
        odhs_stepper_time(b2, &t0);
        double *t2 = malloc(np * sizeof *t2);
        ck_assert_int_eq(odhs_driver_get_propulsion(db2, NULL, t2), ODHS_OK);
        size_t switched = 0;
        for (size_t i = 0; i < np; ++i) switched += t2[i] != tb[i];
        ck_assert_uint_gt(switched, np / 4);
        free(t2);
        odhs_stepper_destroy(b2);
        odhs_driver_destroy(db2);
        odhs_system_destroy(sb2);
        free(Fa);
        free(Fb);
        free(ta);
        free(tb);
    }
    free(A.x);
    free(A.f);
    free(B.x);
    free(B.f);
    free(la);
    free(lb);
    odhs_stepper_destroy(a);
    odhs_stepper_destroy(b);
    odhs_driver_destroy(da);
    odhs_driver_destroy(db);
    odhs_system_destroy(sa);
    odhs_system_destroy(sb);
    odhs_solver_destroy(sol);
    odhs_system_destroy(base);
}

START_TEST(test_bit_identical_euler_2d) { run_and_compare(2, ODHS_INTEGRATOR_EULER, "cg", 0); }
END_TEST
START_TEST(test_bit_identical_heun_2d) { run_and_compare(2, ODHS_INTEGRATOR_HEUN, "dense", 0); }
END_TEST
START_TEST(test_bit_identical_pressure_2d) { run_and_compare(2, ODHS_INTEGRATOR_EULER, "dense", 1); }
END_TEST
START_TEST(test_bit_identical_3d) { run_and_compare(3, ODHS_INTEGRATOR_EULER, "cg", 0); }
END_TEST
START_TEST(test_bit_identical_propulsion_2d) { run_and_compare(2, ODHS_INTEGRATOR_EULER, "cg", RC_PROPULSION); }
END_TEST
START_TEST(test_bit_identical_propulsion_gravity_heun_2d)
{
    run_and_compare(2, ODHS_INTEGRATOR_HEUN, "dense", RC_PROPULSION | RC_GRAVITY | RC_NOSHEAR);
}
END_TEST
START_TEST(test_bit_identical_propulsion_3d)
{
    run_and_compare(3, ODHS_INTEGRATOR_EULER, "dense", RC_PROPULSION | RC_NOSHEAR);
}
END_TEST
START_TEST(test_bit_identical_driver_changed)
{
    /* 0.2.1 restored the stale forces as current: pressure doubled before
     * writing gave velocities 1e-2 off in the restored run */
    run_and_compare(2, ODHS_INTEGRATOR_HEUN, "dense", RC_PRESSURE | RC_DRVCHANGE);
    run_and_compare(2, ODHS_INTEGRATOR_EULER, "dense", RC_DRVCHANGE);
}
END_TEST

/* the batched integrator: its step size and tolerance come back with the
 * file (fixed volume, fixed pressure with a driver change, 3D) */
START_TEST(test_bit_identical_batched)
{
    run_and_compare(2, ODHS_INTEGRATOR_BATCHED, "dense", 0);
    run_and_compare(2, ODHS_INTEGRATOR_BATCHED, "dense", RC_PRESSURE | RC_DRVCHANGE);
    run_and_compare(3, ODHS_INTEGRATOR_BATCHED, "cg", 0);
}
END_TEST

START_TEST(test_bit_identical_gravity_shear_2d) { run_and_compare(2, ODHS_INTEGRATOR_EULER, "dense", RC_GRAVITY); }
END_TEST

/* the bytes of the file at path (malloc'ed) */
static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    unsigned char *buf = malloc(1 << 20);
    *len = fread(buf, 1, 1 << 20, f);
    fclose(f);
    return buf;
}

/* a small valid checkpoint in memory */
static unsigned char *make_ckpt_ex(size_t *len, odhs_solver **solp, int propulsion)
{
    odhs_system *sys = scene(2, 16, 0.6, 3);
    odhs_solver *sol;
    odhs_driver *drv;
    odhs_stepper *st;
    double F[32];
    for (int k = 0; k < 32; ++k) F[k] = 0.1 * sin(k);
    ck_assert_int_eq(odhs_solver_create_by_name("dense", &sol), ODHS_OK);
    ck_assert_int_eq(odhs_driver_create(&drv), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_shear_rate(drv, 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_forces(drv, 16, 2, F), ODHS_OK);
    if (propulsion) {
        double g[2] = {0.0, -0.3}, wt[16];
        for (int k = 0; k < 16; ++k) wt[k] = 1.0 + 0.1 * k;
        ck_assert_int_eq(odhs_driver_set_self_propulsion(drv, 16, 2, 0.1, 0.2, 0.0, 1.0, 5), ODHS_OK);
        ck_assert_int_eq(odhs_driver_set_gravity(drv, 2, g), ODHS_OK);
        ck_assert_int_eq(odhs_driver_set_gravity_weights(drv, 16, wt), ODHS_OK);
    }
    ck_assert_int_eq(odhs_stepper_create(sys, drv, sol, &st), ODHS_OK);
    for (int k = 0; k < 10; ++k) ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_OK);
    char path[128];
    snprintf(path, sizeof path, "%s/small.ckpt", dir);
    ck_assert_int_eq(odhs_checkpoint_write(st, path), ODHS_OK);
    unsigned char *buf = slurp(path, len);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    *solp = sol;
    return buf;
}

static unsigned char *make_ckpt(size_t *len, odhs_solver **solp) { return make_ckpt_ex(len, solp, 0); }

static uint64_t fnv1a(const unsigned char *p, size_t len)
{
    uint64_t h = 1469598103934665603ULL;
    for (size_t k = 0; k < len; ++k) {
        h ^= p[k];
        h *= 1099511628211ULL;
    }
    return h;
}

/* little-endian u64 at p */
static uint64_t rd64(const unsigned char *p)
{
    uint64_t v = 0;
    for (int k = 7; k >= 0; --k) v = (v << 8) | p[k];
    return v;
}

static void wr64(unsigned char *p, uint64_t v)
{
    for (int k = 0; k < 8; ++k) p[k] = (unsigned char)(v >> (8 * k));
}

/* set the version field and fix the checksum */
static void set_version(unsigned char *buf, size_t len, uint64_t v)
{
    wr64(buf + 8, v);
    wr64(buf + len - 8, fnv1a(buf, len - 8));
}

START_TEST(test_versions)
{
    /* without propulsion or gravity the file is version 1 (what older
     * releases read); with them, version 2 */
    size_t len1, len2;
    odhs_solver *sol1, *sol2;
    unsigned char *b1 = make_ckpt_ex(&len1, &sol1, 0), *b2 = make_ckpt_ex(&len2, &sol2, 1);
    ck_assert_uint_eq(rd64(b1 + 8), 1);
    ck_assert_uint_eq(rd64(b2 + 8), 2);
    ck_assert_int_eq(ODHS_CHECKPOINT_VERSION, 2);
    odhs_system *s;
    odhs_driver *d;
    odhs_stepper *st;
    char err[256];
    /* a version-1 file read as version 2 (same sections) loads */
    set_version(b1, len1, 2);
    ck_assert_int_eq(odhs_checkpoint_parse(b1, len1, sol1, &s, &d, &st, err, sizeof err), ODHS_OK);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(d);
    odhs_system_destroy(s);
    /* version-2 sections in a file that claims version 1: rejected */
    set_version(b2, len2, 1);
    ck_assert_int_eq(odhs_checkpoint_parse(b2, len2, sol2, &s, &d, &st, err, sizeof err), ODHS_E_FORMAT);
    ck_assert(s == NULL && d == NULL && st == NULL);
    /* a future version: rejected */
    set_version(b2, len2, 3);
    ck_assert_int_eq(odhs_checkpoint_parse(b2, len2, sol2, &s, &d, &st, err, sizeof err), ODHS_E_FORMAT);
    ck_assert(strstr(err, "version") != NULL);
    set_version(b2, len2, 2);
    ck_assert_int_eq(odhs_checkpoint_parse(b2, len2, sol2, &s, &d, &st, err, sizeof err), ODHS_OK);
    /* the propulsion and gravity settings came back */
    double F[32], ts[16], tn;
    ck_assert_int_eq(odhs_driver_get_propulsion(d, F, ts), ODHS_OK);
    ck_assert_int_eq(odhs_driver_next_switch(d, &tn), ODHS_OK);
    for (int i = 0; i < 16; ++i) {
        ck_assert(ts[i] >= tn);
        double m = hypot(F[2 * i], F[2 * i + 1]);
        ck_assert(m >= 0.1 * (1 - 1e-15) && m <= 0.2 * (1 + 1e-15));
    }
    odhs_stepper_destroy(st);
    odhs_driver_destroy(d);
    odhs_system_destroy(s);
    /* every truncation and single-byte corruption of a version-2 file fails */
    for (size_t cut = 0; cut < len2; cut += 41) {
        ck_assert_int_eq(odhs_checkpoint_parse(b2, cut, sol2, &s, &d, &st, err, sizeof err), ODHS_E_FORMAT);
        ck_assert(s == NULL && d == NULL && st == NULL);
    }
    for (size_t k = 0; k < len2; k += 29) {
        b2[k] ^= 0x21;
        ck_assert_int_eq(odhs_checkpoint_parse(b2, len2, sol2, &s, &d, &st, err, sizeof err), ODHS_E_FORMAT);
        b2[k] ^= 0x21;
    }
    free(b1);
    free(b2);
    odhs_solver_destroy(sol1);
    odhs_solver_destroy(sol2);
}
END_TEST

START_TEST(test_truncated_and_corrupted)
{
    size_t len;
    odhs_solver *sol;
    unsigned char *buf = make_ckpt(&len, &sol);
    odhs_system *s;
    odhs_driver *d;
    odhs_stepper *st;
    char err[256];
    ck_assert_int_eq(odhs_checkpoint_parse(buf, len, sol, &s, &d, &st, err, sizeof err), ODHS_OK);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(d);
    odhs_system_destroy(s);
    /* every truncation is rejected, with no handle */
    for (size_t cut = 0; cut < len; cut += (cut < 64 ? 1 : 37)) {
        int rc = odhs_checkpoint_parse(buf, cut, sol, &s, &d, &st, err, sizeof err);
        ck_assert_msg(rc == ODHS_E_FORMAT, "truncated to %zu: %d", cut, rc);
        ck_assert(s == NULL && d == NULL && st == NULL);
        ck_assert_str_ne(err, "");
    }
    /* every single-byte corruption is caught by the checksum */
    for (size_t k = 0; k < len; k += 13) {
        buf[k] ^= 0x5a;
        int rc = odhs_checkpoint_parse(buf, len, sol, &s, &d, &st, err, sizeof err);
        ck_assert_msg(rc == ODHS_E_FORMAT, "corrupted byte %zu accepted", k);
        ck_assert(s == NULL && d == NULL && st == NULL);
        buf[k] ^= 0x5a;
    }
    /* NULL arguments */
    ck_assert_int_eq(odhs_checkpoint_parse(NULL, len, sol, &s, &d, &st, err, sizeof err), ODHS_E_NULL);
    ck_assert_int_eq(odhs_checkpoint_parse(buf, len, NULL, &s, &d, &st, NULL, 0), ODHS_E_NULL);
    ck_assert_int_eq(odhs_checkpoint_read(NULL, sol, &s, &d, &st, err, sizeof err), ODHS_E_NULL);
    char path[128];
    snprintf(path, sizeof path, "%s/missing.ckpt", dir);
    ck_assert_int_eq(odhs_checkpoint_read(path, sol, &s, &d, &st, err, sizeof err), ODHS_E_IO);
    ck_assert(strstr(err, "missing.ckpt") != NULL);
    free(buf);
    odhs_solver_destroy(sol);
}
END_TEST

START_TEST(test_atomic_write)
{
    size_t len;
    odhs_solver *sol;
    unsigned char *buf = make_ckpt(&len, &sol);
    odhs_system *s;
    odhs_driver *d;
    odhs_stepper *st;
    ck_assert_int_eq(odhs_checkpoint_parse(buf, len, sol, &s, &d, &st, NULL, 0), ODHS_OK);
    /* a write that cannot happen leaves no file and an error */
    ck_assert_int_eq(odhs_checkpoint_write(st, "/nonexistent-dir/x.ckpt"), ODHS_E_IO);
    ck_assert_str_ne(odhs_stepper_errmsg(st), "");
    /* overwriting an existing checkpoint replaces it whole; no temporary is left */
    char path[128];
    snprintf(path, sizeof path, "%s/small.ckpt", dir);
    ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_checkpoint_write(st, path), ODHS_OK);
    odhs_system *s2;
    odhs_driver *d2;
    odhs_stepper *st2;
    ck_assert_int_eq(odhs_checkpoint_read(path, sol, &s2, &d2, &st2, NULL, 0), ODHS_OK);
    double t1, t2;
    odhs_stepper_time(st, &t1);
    odhs_stepper_time(st2, &t2);
    ck_assert(t1 == t2);
    char cmd[256];
    snprintf(cmd, sizeof cmd, "ls %s | grep -q tmp", dir);
    ck_assert_msg(system(cmd) != 0, "a temporary file was left behind");
    /* a stepper without state cannot be saved */
    odhs_stepper *fresh;
    ck_assert_int_eq(odhs_stepper_create(s2, d2, sol, &fresh), ODHS_OK);
    ck_assert_int_eq(odhs_checkpoint_write(fresh, path), ODHS_E_STATE);
    ck_assert_int_eq(odhs_checkpoint_write(NULL, path), ODHS_E_NULL);
    ck_assert_int_eq(odhs_checkpoint_write(st, NULL), ODHS_E_NULL);
    odhs_stepper_destroy(fresh);
    odhs_stepper_destroy(st2);
    odhs_driver_destroy(d2);
    odhs_system_destroy(s2);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(d);
    odhs_system_destroy(s);
    free(buf);
    odhs_solver_destroy(sol);
}
END_TEST

/* read buf, write it again: the bytes of expect (len of them) */
static void assert_rewrites(const unsigned char *buf, size_t len, const unsigned char *expect, odhs_solver *sol)
{
    odhs_system *s;
    odhs_driver *d;
    odhs_stepper *st;
    char err[256], path[128];
    ck_assert_msg(odhs_checkpoint_parse(buf, len, sol, &s, &d, &st, err, sizeof err) == ODHS_OK, "%s", err);
    snprintf(path, sizeof path, "%s/again.ckpt", dir);
    ck_assert_int_eq(odhs_checkpoint_write(st, path), ODHS_OK);
    size_t len2;
    unsigned char *buf2 = slurp(path, &len2);
    ck_assert_msg(len2 == len && !memcmp(expect, buf2, len), "read and written again, the file differs");
    free(buf2);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(d);
    odhs_system_destroy(s);
}

/* offset of the last occurrence of tag in buf[0..end) */
static size_t last_tag(const unsigned char *buf, size_t end, const char *tag)
{
    for (size_t k = end - 4; k > 0; --k)
        if (!memcmp(buf + k, tag, 4)) return k;
    ck_abort_msg("section %s not found", tag);
    return 0;
}

/* every section (WAL, CMP, PROP, GRAV, DRVC): each module writes its own,
 * and reading and writing again gives the same bytes; the optional sections
 * after the contacts are read in any order, each once */
START_TEST(test_sections_round_trip)
{
    double L[2] = {10, 10}, r[6] = {0.5, 0.5, 0.5, 0.6, 0.6, 0.6}, x[12], cx[2] = {3, 7}, cy[2] = {4, 6};
    for (int t = 0; t < 2; ++t)
        for (int q = 0; q < 3; ++q) {
            double R = 2 * r[3 * t] / sqrt(3.0), a = 2 * 3.14159265358979323846 * q / 3;
            x[2 * (3 * t + q)] = cx[t] + R * cos(a);
            x[2 * (3 * t + q) + 1] = cy[t] + R * sin(a);
        }
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
    ck_assert_int_eq(odhs_system_create(2, 6, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0, r, x), ODHS_OK);
    ck_assert_int_eq(odhs_solver_create_by_name("dense", &sol), ODHS_OK);
    ck_assert_int_eq(odhs_driver_create(&drv), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_shear_rate(drv, 0.5), ODHS_OK);
    double g[2] = {0.0, -0.3}, up[2] = {0.0, 1.0};
    ck_assert_int_eq(odhs_driver_set_self_propulsion(drv, 6, 2, 0.1, 0.2, 0.0, 1.0, 5), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_gravity(drv, 2, g), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_create(sys, drv, sol, &st), ODHS_OK);
    size_t b0[3] = {0, 1, 2}, b1[3] = {3, 4, 5};
    ck_assert_int_eq(odhs_stepper_add_rigid_body(st, 3, b0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_add_chain(st, 3, b1), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_add_wall_plane(st, up, 0.5, NULL), ODHS_OK);
    for (int k = 0; k < 10; ++k) ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_shear_rate(drv, 0.7), ODHS_OK); /* DRVC */
    char path[128];
    snprintf(path, sizeof path, "%s/all.ckpt", dir);
    ck_assert_int_eq(odhs_checkpoint_write(st, path), ODHS_OK);
    size_t len;
    unsigned char *buf = slurp(path, &len);
    /* the sections in the order of the format */
    static const char *const order[] = {"SYS ", "DRV ", "STP ", "WAL ", "NET ", "CMP ", "PROP", "GRAV", "DRVC", "END "};
    for (size_t k = 0, at = 16; k < sizeof order / sizeof order[0]; ++k) {
        size_t t = last_tag(buf, len, order[k]);
        ck_assert_msg(t >= at, "section %s out of order", order[k]);
        at = t;
    }
    ck_assert_uint_eq(rd64(buf + 8), 2);
    assert_rewrites(buf, len, buf, sol);
    /* the optional sections in another order (GRAV, PROP, DRVC): the same
     * state, written in the order of the format */
    size_t p = last_tag(buf, len, "PROP"), q = last_tag(buf, len, "GRAV");
    unsigned char *alt = malloc(len + 12);
    memcpy(alt, buf, p);
    memcpy(alt + p, buf + q, len - 12 - q - 12); /* GRAV, without DRVC */
    memcpy(alt + p + (len - 24 - q), buf + p, q - p);
    memcpy(alt + len - 24, buf + len - 24, 24); /* DRVC, END, checksum */
    wr64(alt + len - 8, fnv1a(alt, len - 8));
    assert_rewrites(alt, len, buf, sol);
    /* a repeated and an unknown section are refused */
    odhs_system *s2;
    odhs_driver *d2;
    odhs_stepper *st2;
    char err[256];
    static const char *const extra[] = {"DRVC", "ABCD"};
    for (int k = 0; k < 2; ++k) {
        memcpy(alt, buf, len - 12);
        memcpy(alt + len - 12, extra[k], 4);
        wr64(alt + len - 8, 1);
        memcpy(alt + len, buf + len - 12, 4);
        wr64(alt + len + 4, fnv1a(alt, len + 4));
        ck_assert_int_eq(odhs_checkpoint_parse(alt, len + 12, sol, &s2, &d2, &st2, err, sizeof err), ODHS_E_FORMAT);
        ck_assert_str_eq(err, "checkpoint: unknown or repeated section");
    }
    free(alt);
    free(buf);
    /* version 1 files (no optional section) and fixed forces */
    odhs_solver *sol1;
    buf = make_ckpt_ex(&len, &sol1, 0);
    ck_assert_uint_eq(rd64(buf + 8), 1);
    assert_rewrites(buf, len, buf, sol1);
    free(buf);
    odhs_solver_destroy(sol1);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    odhs_solver_destroy(sol);
}
END_TEST

/* the stepper's velocity gradient G and cell matrix M have the shapes the
 * stepper makes: a file with a foreign entry is refused (fuzz_checkpoint: a
 * 2D file with G_xz = -8e298 stepped into a NaN cell matrix, which the writer
 * then saved and the reader refused); a huge shear entry of M is a valid
 * shape: the neighbour list is rebuilt and the run goes on */
static double rdf(const unsigned char *p)
{
    uint64_t v = rd64(p);
    double x;
    memcpy(&x, &v, sizeof x);
    return x;
}

static void wrf(unsigned char *p, double x)
{
    uint64_t v;
    memcpy(&v, &x, sizeof v);
    wr64(p, v);
}

START_TEST(test_stepper_shapes)
{
    size_t len;
    odhs_solver *sol;
    unsigned char *buf = make_ckpt(&len, &sol); /* 2D, N = 16, shear rate 1 */
    const size_t nd = 32, stp = last_tag(buf, last_tag(buf, len, "NET "), "STP ");
    const size_t g = stp + 4 + 15 * 8, m = g + 9 * 8 + 8 + 8 + nd * 8 + 8 + 8 + nd * 8;
    /* the layout: G_xy is the shear rate, M_zz = 1 in 2D, M_xx = M_yy = 1 */
    ck_assert_double_eq(rdf(buf + g + 8), 1.0);
    ck_assert_double_eq(rdf(buf + m + 8 * 8), 1.0);
    ck_assert_double_eq(rdf(buf + m), 1.0);
    ck_assert_double_eq(rdf(buf + m + 4 * 8), 1.0);
    unsigned char *alt = malloc(len);
    odhs_system *s;
    odhs_driver *d;
    odhs_stepper *st;
    char err[256];
    static const struct {
        int in_m, k;
        double v;
        const char *what;
    } bad[] = {
        {0, 2, -8e298, "velocity gradient"}, {0, 3, 8e-317, "velocity gradient"},
        {0, 4, -0.5, "velocity gradient"},   {0, 8, -0.5, "velocity gradient"},
        {1, 6, 4e-310, "cell matrix"},       {1, 4, 0.99, "cell matrix"},
        {1, 8, 0.99, "cell matrix"},         {1, 3, 1e-3, "cell matrix"},
    };
    for (size_t c = 0; c < sizeof bad / sizeof bad[0]; ++c) {
        memcpy(alt, buf, len);
        wrf(alt + (bad[c].in_m ? m : g) + 8 * (size_t)bad[c].k, bad[c].v);
        wr64(alt + len - 8, fnv1a(alt, len - 8));
        int rc = odhs_checkpoint_parse(alt, len, sol, &s, &d, &st, err, sizeof err);
        ck_assert_msg(rc == ODHS_E_FORMAT, "case %zu accepted (%d)", c, rc);
        ck_assert_msg(strstr(err, bad[c].what) != NULL, "case %zu: %s", c, err);
        ck_assert(s == NULL && d == NULL && st == NULL);
    }
    /* a negative scale of the cell (both diagonal entries) */
    memcpy(alt, buf, len);
    wrf(alt + m, -1.0);
    wrf(alt + m + 4 * 8, -1.0);
    wr64(alt + len - 8, fnv1a(alt, len - 8));
    ck_assert_int_eq(odhs_checkpoint_parse(alt, len, sol, &s, &d, &st, err, sizeof err), ODHS_E_FORMAT);
    ck_assert(strstr(err, "not positive") != NULL);
    /* a compressing cell (equal diagonal) and a huge shear entry: valid; the
     * steps rebuild the list, and what they leave is written and read back */
    memcpy(alt, buf, len);
    wrf(alt + m, 0.975);
    wrf(alt + m + 4 * 8, 0.975);
    wrf(alt + m + 8, 1.7e147);
    wr64(alt + len - 8, fnv1a(alt, len - 8));
    ck_assert_int_eq(odhs_checkpoint_parse(alt, len, sol, &s, &d, &st, err, sizeof err), ODHS_OK);
    for (int k = 0; k < 3; ++k) ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_OK);
    char path[128];
    snprintf(path, sizeof path, "%s/shapes.ckpt", dir);
    ck_assert_int_eq(odhs_checkpoint_write(st, path), ODHS_OK);
    odhs_system *s2;
    odhs_driver *d2;
    odhs_stepper *st2;
    ck_assert_int_eq(odhs_checkpoint_read(path, sol, &s2, &d2, &st2, err, sizeof err), ODHS_OK);
    odhs_stepper_destroy(st2);
    odhs_driver_destroy(d2);
    odhs_system_destroy(s2);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(d);
    odhs_system_destroy(s);
    free(alt);
    free(buf);
    odhs_solver_destroy(sol);
}
END_TEST

/* a box of aspect ratio 6.8e-79 sheared: the strain, 1e-4 after the first
 * steps, is gamma / (Lx/Ly) = 1e74 periods of the Lees-Edwards lattice; the
 * remap cancelled to a multiple of ulp(gamma) far outside [-Lx/2Ly, Lx/2Ly],
 * and the checkpoint written then could not be read back (fuzz_checkpoint,
 * 0.2.12) */
START_TEST(test_remap_extreme_aspect)
{
    const size_t n = 12;
    const double L[2] = {4.91, 7.25e78};
    double x[24], r[12];
    for (size_t i = 0; i < n; ++i) {
        x[2 * i] = 0.1 + 0.4 * (double)i;
        x[2 * i + 1] = 1.0 + 2.0 * (double)i;
        r[i] = 0.1;
    }
    odhs_system *sys;
    odhs_solver *sol;
    odhs_driver *drv;
    odhs_stepper *st;
    ck_assert_int_eq(odhs_system_create(2, n, &sys), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_box(sys, L), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_radii(sys, r), ODHS_OK);
    ck_assert_int_eq(odhs_system_set_positions(sys, x), ODHS_OK);
    ck_assert_int_eq(odhs_solver_create_by_name("dense", &sol), ODHS_OK);
    ck_assert_int_eq(odhs_driver_create(&drv), ODHS_OK);
    ck_assert_int_eq(odhs_driver_set_shear_rate(drv, 1.0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_create(sys, drv, sol, &st), ODHS_OK);
    double strain = 0.0, g = 0.0;
    /* the old remap failed for 141 of 1000 strains 1e-4 (1 + k 1e-3) on this
     * box: checked directly, and along 40 steps */
    size_t bad = 0;
    for (int k = 0; k < 1000; ++k) bad += !(fabs(odhs__remap_strain(1e-4 * (1 + k * 1e-3), L)) <= 0.5 * L[0] / L[1]);
    ck_assert_uint_eq(bad, 0);
    for (int k = 0; k < 40; ++k) {
        ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_OK);
        ck_assert_int_eq(odhs_system_get_strain(sys, &g), ODHS_OK);
        ck_assert_msg(fabs(g) <= 0.5 * L[0] / L[1], "step %d: remapped strain %g outside +-%g", k, g,
                      0.5 * L[0] / L[1]);
    }
    ck_assert_int_eq(odhs_stepper_strain(st, &strain), ODHS_OK);
    ck_assert(strain > 1e-6);
    char path[128], err[256];
    snprintf(path, sizeof path, "%s/aspect.ckpt", dir);
    ck_assert_int_eq(odhs_checkpoint_write(st, path), ODHS_OK);
    odhs_system *s2;
    odhs_driver *d2;
    odhs_stepper *st2;
    ck_assert_msg(odhs_checkpoint_read(path, sol, &s2, &d2, &st2, err, sizeof err) == ODHS_OK, "%s", err);
    odhs_stepper_destroy(st2);
    odhs_driver_destroy(d2);
    odhs_system_destroy(s2);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    odhs_solver_destroy(sol);
}
END_TEST

/* a coordinate 1e20 box lengths out: floor(x/L) L is rounded, and the old
 * wrap left 124 of 1000 such coordinates outside [0, L) (a 2D file of box
 * 4.9 x 7.3e78 at fixed pressure stepped a particle to x = 1.9e50; the
 * checkpoint written then could not be read back: fuzz_checkpoint, finding
 * 14, seed regress_wrap_far_coordinate.ckpt). Near coordinates keep their
 * old arithmetic bit for bit. */
START_TEST(test_wrap_far)
{
    const double L[3] = {4.9120538521719572, 7.2535731079894922e78, 3.0};
    size_t bad = 0;
    for (int k = 0; k < 1000; ++k) {
        for (int sgn = -1; sgn <= 1; sgn += 2) {
            double x[3] = {sgn * 1e20 * (1 + k * 1e-3), 1.0, sgn * 3e30 * (1 + k * 1e-3)};
            odhs__wrap(3, L, 0.25, x);
            bad += !(x[0] >= 0.0 && x[0] < L[0]) + !(x[2] >= 0.0 && x[2] < L[2]) + (x[1] != 1.0);
            /* y far out: x shifted by the image count, then wrapped */
            double y[3] = {1.0, sgn * 1e95 * (1 + k * 1e-3), 0.5};
            odhs__wrap(3, L, 0.25, y);
            bad += !(y[0] >= 0.0 && y[0] < L[0]) + !(y[1] >= 0.0 && y[1] < L[1]) + (y[2] != 0.5);
        }
    }
    ck_assert_uint_eq(bad, 0);
    /* near coordinates: the old arithmetic (x - floor(x/L) L, one more L for
     * a rounded-up residual, a rounded-down one at 0) */
    const double B[2] = {3.7, 2.9};
    for (int k = -400; k <= 400; ++k) {
        double v = 0.0173 * k + 1e-17 * (k % 3), x[2] = {v, 1.0}, y[2] = {1.0, v};
        odhs__wrap(2, B, -0.3, x);
        double m = floor(v / B[0]), want = v - m * B[0];
        if (want >= B[0]) want -= B[0];
        if (want < 0.0) want = 0.0;
        if (v >= 0.0 && v < B[0]) want = v;
        ck_assert_msg(x[0] == want && x[1] == 1.0, "x = %.17g: %.17g, want %.17g", v, x[0], want);
        odhs__wrap(2, B, -0.3, y);
        double ny = floor(v / B[1]), wy = v - ny * B[1], wx = 1.0 - ny * -0.3 * B[1];
        if (wy >= B[1]) {
            wy -= B[1];
            wx -= -0.3 * B[1];
        }
        if (wy < 0.0) wy = 0.0;
        if (v >= 0.0 && v < B[1]) wy = v, wx = 1.0;
        if (wx < 0.0 || wx >= B[0]) {
            double mx = floor(wx / B[0]);
            wx -= mx * B[0];
            if (wx >= B[0]) wx -= B[0];
            if (wx < 0.0) wx = 0.0;
        }
        ck_assert_msg(y[1] == wy && y[0] == wx, "y = %.17g: (%.17g, %.17g), want (%.17g, %.17g)", v, y[0], y[1],
                      wx, wy);
    }
    /* a box edge scaled through zero by a trial motion (refused by the
     * caller): the old arithmetic, not the fmod fallback (the first version
     * of the fallback took it there, and a fixed-pressure run of the Python
     * tests failed with a non-finite force right-hand side) */
    const double Bn[2] = {-0.39891220601691568, 3.0};
    for (int k = 0; k < 50; ++k) {
        double v = 0.0085 * k, x[2] = {v, 1.0};
        odhs__wrap(2, Bn, 0.1, x);
        double m = floor(v / Bn[0]), want = v - m * Bn[0];
        if (want >= Bn[0]) want -= Bn[0];
        if (want < 0.0) want = 0.0;
        ck_assert_msg(x[0] == want && x[1] == 1.0, "negative edge, x = %.17g: %.17g, want %.17g", v, x[0], want);
    }
}
END_TEST

/* a fuzzed 2D file at fixed pressure with a shear rate of 5.3e269: its first
 * step's force solve gave kappa = 3.7e54, so the compression rate
 * c = kappa * gammadot overflowed and the velocity gradient's diagonal was
 * -inf; the step returned ODHS_OK, and the checkpoint written after it could
 * not be read back (fuzz_checkpoint, finding 15; the reproducer is the seed
 * tests/fuzz/corpus_checkpoint/regress_flow_overflow.ckpt). Now the step
 * fails with ODHS_E_NONFINITE and is rolled back. */
START_TEST(test_flow_overflow)
{
    const char *data = getenv("ODHS_TEST_DATA");
    char path[512], err[256];
    snprintf(path, sizeof path, "%s/../fuzz/corpus_checkpoint/regress_flow_overflow.ckpt",
             data && *data ? data : "tests/data");
    size_t len = 0;
    unsigned char *buf = slurp(path, &len);
    ck_assert_msg(buf != NULL && len > 16, "cannot read %s", path);
    wr64(buf + len - 8, fnv1a(buf, len - 8)); /* the fuzzer repairs the checksum */
    odhs_solver *sol;
    odhs_system *s;
    odhs_driver *d;
    odhs_stepper *st;
    ck_assert_int_eq(odhs_solver_create_by_name("dense", &sol), ODHS_OK);
    ck_assert_msg(odhs_checkpoint_parse(buf, len, sol, &s, &d, &st, err, sizeof err) == ODHS_OK, "%s", err);
    double t0, t1;
    ck_assert_int_eq(odhs_stepper_time(st, &t0), ODHS_OK);
    ck_assert_int_eq(odhs_stepper_step(st, NULL), ODHS_E_NONFINITE);
    ck_assert(strstr(odhs_stepper_errmsg(st), "non-finite flow") != NULL);
    ck_assert_int_eq(odhs_stepper_time(st, &t1), ODHS_OK);
    ck_assert(t1 == t0); /* rolled back */
    char out[128];
    snprintf(out, sizeof out, "%s/flow_overflow.ckpt", dir);
    ck_assert_int_eq(odhs_checkpoint_write(st, out), ODHS_OK);
    odhs_system *s2;
    odhs_driver *d2;
    odhs_stepper *st2;
    ck_assert_msg(odhs_checkpoint_read(out, sol, &s2, &d2, &st2, err, sizeof err) == ODHS_OK, "%s", err);
    odhs_stepper_destroy(st2);
    odhs_driver_destroy(d2);
    odhs_system_destroy(s2);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(d);
    odhs_system_destroy(s);
    odhs_solver_destroy(sol);
    free(buf);
}
END_TEST

Suite *make_checkpoint_suite(void)
{
    Suite *s = suite_create("checkpoint");
    TCase *tc = tcase_create("checkpoint");
    tcase_add_checked_fixture(tc, setup, teardown);
    tcase_set_timeout(tc, 300);
    tcase_add_test(tc, test_bit_identical_euler_2d);
    tcase_add_test(tc, test_bit_identical_heun_2d);
    tcase_add_test(tc, test_bit_identical_batched);
    tcase_add_test(tc, test_bit_identical_pressure_2d);
    tcase_add_test(tc, test_bit_identical_3d);
    tcase_add_test(tc, test_bit_identical_propulsion_2d);
    tcase_add_test(tc, test_bit_identical_propulsion_gravity_heun_2d);
    tcase_add_test(tc, test_bit_identical_propulsion_3d);
    tcase_add_test(tc, test_bit_identical_gravity_shear_2d);
    tcase_add_test(tc, test_bit_identical_driver_changed);
    tcase_add_test(tc, test_versions);
    tcase_add_test(tc, test_truncated_and_corrupted);
    tcase_add_test(tc, test_atomic_write);
    tcase_add_test(tc, test_sections_round_trip);
    tcase_add_test(tc, test_stepper_shapes);
    tcase_add_test(tc, test_remap_extreme_aspect);
    tcase_add_test(tc, test_wrap_far);
    tcase_add_test(tc, test_flow_overflow);
    suite_add_tcase(s, tc);
    return s;
}
