/*
 * libodhs - bad input everywhere (suite "badinput").
 *
 * Every function declared in the public headers (include/odhs/<module>.h)
 * is called with NULL handles, NULL outputs, out-of-range indices,
 * non-finite numbers, zero sizes, inconsistent dimensions and in the wrong
 * order. Each case is one row of a
 * table (one Check loop iteration, so a crash or failure names its row):
 *
 *   X(id, function, expected status, alternative status or NOALT,
 *     handle that must hold a message or H_NONE, flags, body...)
 *
 * For every row a "world" of handles (systems, networks, driver, solvers,
 * steppers) is built twice, identically. The body makes the bad call on the
 * first world and returns its status; then
 *   1. the status must be the documented one (a row may allow a second code
 *      where the documentation leaves the choice open: see NOALT);
 *   2. a handle the call was given must hold a non-empty message;
 *   3. every handle of the first world must equal, bit for bit, the same
 *      handle of the untouched second world (an error leaves the handle as it
 *      was: common.h), and valid calls on both - getters, a solve with each
 *      solver, one step of each stepper - must succeed with identical results.
 * Bodies may check post-conditions themselves (outputs set to NULL on error,
 * buffers untouched...) and then return post(...) with a message.
 *
 * Rows in REGRESSION_CASES are bugs these tests and the XYZ fuzzer found
 * (fixed since): far-away coordinates wrapped to NaN or outside the box, a
 * strain remap that was not idempotent or wrong for huge strains, a step that
 * "succeeded" with non-finite positions, stepper messages written to the
 * network, a NaN initial guess reported as a convergence failure. The test
 * "coverage" reads the public headers and fails if any declared function has
 * no row.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <check.h>
#include <dirent.h>
#include <limits.h>
#include <math.h>
#include <stdarg.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "odhs.h"
#include "testutil.h"

#define NOALT 0x7fff0000       /* no alternative status allowed */
#define POST_FAIL 0x7fff0001   /* a body's own post-condition failed */

/* flags */
#define F_NOPROBE 1u /* the call legitimately changes state: skip the comparison */

static char post_msg[512];

/* a body's post-condition failed: remember why */
#if defined(__GNUC__)
static int post(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
#endif
static int post(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(post_msg, sizeof post_msg, fmt, ap);
    va_end(ap);
    return POST_FAIL;
}

/* ---- the world of handles ----------------------------------------------------
 * sys2  2D, N = 16, ready (random placement, phi 0.5)
 * sys3  3D, N = 12, ready
 * sys8  2D, N = 8, ready (same dimension as sys2, other N)
 * bare  2D, N = 16, nothing set
 * net2  network of sys2 with the pairs of gap <= 0.3 (a_i + a_j)
 * net3  empty network of sys3
 * drv   shear rate 1; the driver of st
 * cg, dense   free solver handles
 * st    stepper on sys2 / drv / stsol ("cg"), never stepped
 * run   stepper on sysr (2D, N = 16, compressed to phi 0.7) / drvr (shear) /
 *       solr ("dense"), 3 steps taken: ready, with contacts
 * dir   a private directory for files
 */
typedef struct {
    odhs_system *sys2, *sys3, *sys8, *bare, *sysr;
    odhs_network *net2, *net3;
    odhs_driver *drv, *drvr;
    odhs_solver *cg, *dense, *stsol, *solr;
    odhs_stepper *st, *run;
    double x0[64], d0; /* scratch outputs of the softcore rows */
    char dir[64];
    int ok;
    char why[256];
} world;

enum {
    H_NONE = 0,
    H_SYS2, H_SYS3, H_SYS8, H_BARE, H_SYSR,
    H_NET2, H_NET3,
    H_DRV, H_DRVR,
    H_CG, H_DENSE, H_STSOL, H_SOLR,
    H_ST, H_RUN
};

static const char *handle_errmsg(const world *w, int h)
{
    switch (h) {
    case H_SYS2: return odhs_system_errmsg(w->sys2);
    case H_SYS3: return odhs_system_errmsg(w->sys3);
    case H_SYS8: return odhs_system_errmsg(w->sys8);
    case H_BARE: return odhs_system_errmsg(w->bare);
    case H_SYSR: return odhs_system_errmsg(w->sysr);
    case H_NET2: return odhs_network_errmsg(w->net2);
    case H_NET3: return odhs_network_errmsg(w->net3);
    case H_DRV: return odhs_driver_errmsg(w->drv);
    case H_DRVR: return odhs_driver_errmsg(w->drvr);
    case H_CG: return odhs_solver_errmsg(w->cg);
    case H_DENSE: return odhs_solver_errmsg(w->dense);
    case H_STSOL: return odhs_solver_errmsg(w->stsol);
    case H_SOLR: return odhs_solver_errmsg(w->solr);
    case H_ST: return odhs_stepper_errmsg(w->st);
    case H_RUN: return odhs_stepper_errmsg(w->run);
    default: return NULL;
    }
}

#define WB(expr)                                                                             \
    do {                                                                                     \
        int wb_rc_ = (expr);                                                                 \
        if (wb_rc_ < 0) {                                                                    \
            snprintf(w->why, sizeof w->why, "%s -> %d (%s)", #expr, wb_rc_, odhs_strerror(wb_rc_)); \
            return;                                                                          \
        }                                                                                    \
    } while (0)

static void world_build(world *w)
{
    memset(w, 0, sizeof *w);
    strcpy(w->dir, "/tmp/odhs-badinput-XXXXXX");
    if (!mkdtemp(w->dir)) {
        w->dir[0] = '\0';
        snprintf(w->why, sizeof w->why, "mkdtemp failed");
        return;
    }
    WB(odhs_system_create(2, 16, &w->sys2));
    WB(odhs_system_set_radii_bidisperse(w->sys2, 0.5, 1.4, 0.03, 21));
    WB(odhs_system_place_random(w->sys2, 0.5, 21));
    WB(odhs_system_create(3, 12, &w->sys3));
    WB(odhs_system_set_radii_bidisperse(w->sys3, 0.5, 1.4, 0.03, 22));
    WB(odhs_system_place_random(w->sys3, 0.3, 22));
    WB(odhs_system_create(2, 8, &w->sys8));
    WB(odhs_system_set_radii_bidisperse(w->sys8, 0.5, 1.4, 0.0, 23));
    WB(odhs_system_place_random(w->sys8, 0.3, 23));
    WB(odhs_system_create(2, 16, &w->bare));
    WB(odhs_network_create(w->sys2, &w->net2));
    WB(odhs_network_detect(w->net2, w->sys2, 0.3));
    WB(odhs_network_create(w->sys3, &w->net3));
    WB(odhs_driver_create(&w->drv));
    WB(odhs_driver_set_shear_rate(w->drv, 1.0));
    WB(odhs_solver_create_by_name("cg", &w->cg));
    WB(odhs_solver_create_by_name("dense", &w->dense));
    WB(odhs_solver_create_by_name("cg", &w->stsol));
    WB(odhs_stepper_create(w->sys2, w->drv, w->stsol, &w->st));
    /* the ready stepper: compress, then shear 3 steps */
    WB(odhs_system_create(2, 16, &w->sysr));
    WB(odhs_system_set_radii_bidisperse(w->sysr, 0.5, 1.4, 0.03, 24));
    WB(odhs_system_place_random(w->sysr, 0.5, 24));
    WB(odhs_driver_create(&w->drvr));
    WB(odhs_driver_set_compression_rate(w->drvr, 1.0));
    WB(odhs_solver_create_by_name("dense", &w->solr));
    WB(odhs_stepper_create(w->sysr, w->drvr, w->solr, &w->run));
    WB(odhs_stepper_run_until_packing_fraction(w->run, 0.7));
    WB(odhs_driver_set_compression_rate(w->drvr, 0.0));
    WB(odhs_driver_set_shear_rate(w->drvr, 1.0));
    for (int k = 0; k < 3; ++k) WB(odhs_stepper_step(w->run, NULL));
    if (odhs_network_count(odhs_stepper_network(w->run)) == 0) {
        snprintf(w->why, sizeof w->why, "the ready stepper has no contacts");
        return;
    }
    if (odhs_network_count(w->net2) == 0) {
        snprintf(w->why, sizeof w->why, "net2 has no contacts");
        return;
    }
    w->ok = 1;
}

static void world_free(world *w)
{
    odhs_stepper_destroy(w->run);
    odhs_stepper_destroy(w->st);
    odhs_solver_destroy(w->solr);
    odhs_solver_destroy(w->stsol);
    odhs_solver_destroy(w->dense);
    odhs_solver_destroy(w->cg);
    odhs_driver_destroy(w->drvr);
    odhs_driver_destroy(w->drv);
    odhs_network_destroy(w->net3);
    odhs_network_destroy(w->net2);
    odhs_system_destroy(w->sysr);
    odhs_system_destroy(w->bare);
    odhs_system_destroy(w->sys8);
    odhs_system_destroy(w->sys3);
    odhs_system_destroy(w->sys2);
    if (w->dir[0]) {
        DIR *d = opendir(w->dir);
        if (d) {
            struct dirent *e;
            char p[600];
            while ((e = readdir(d)) != NULL) {
                if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
                snprintf(p, sizeof p, "%s/%s", w->dir, e->d_name);
                remove(p);
            }
            closedir(d);
        }
        rmdir(w->dir);
    }
    memset(w, 0, sizeof *w);
}

/* a path inside the world's directory (static buffer, one at a time per slot) */
static const char *wpath(const world *w, const char *name)
{
    static char buf[4][160];
    static int slot;
    slot = (slot + 1) % 4;
    snprintf(buf[slot], sizeof buf[slot], "%s/%s", w->dir, name);
    return buf[slot];
}

#define NOWHERE "/nonexistent-odhs-badinput-dir/file"

/* ---- probes: compare a used world with a fresh one --------------------------- */
static int bits_eq(const void *a, const void *b, size_t n) { return n == 0 || memcmp(a, b, n) == 0; }

static const char *probe_system(const odhs_system *a, const odhs_system *b, const char *name)
{
    static char msg[128];
    tu_snapshot sa, sb;
    tu_snapshot_take(a, &sa);
    tu_snapshot_take(b, &sb);
    int eq = tu_snapshot_equal(&sa, &sb);
    tu_snapshot_free(&sa);
    tu_snapshot_free(&sb);
    if (!eq) {
        snprintf(msg, sizeof msg, "system %s changed", name);
        return msg;
    }
    double va, vb;
    if (odhs_system_volume(a, &va) != ODHS_OK || odhs_system_volume(b, &vb) != ODHS_OK || !bits_eq(&va, &vb, sizeof va)) {
        snprintf(msg, sizeof msg, "system %s: volume differs", name);
        return msg;
    }
    if (odhs_system_is_ready(a)) {
        double pa, pb;
        double ra[3], rb[3];
        if (odhs_system_packing_fraction(a, &pa) != ODHS_OK || odhs_system_packing_fraction(b, &pb) != ODHS_OK ||
            !bits_eq(&pa, &pb, sizeof pa) || odhs_system_separation(a, 0, 1, ra, NULL, NULL) != ODHS_OK ||
            odhs_system_separation(b, 0, 1, rb, NULL, NULL) != ODHS_OK ||
            !bits_eq(ra, rb, (size_t)odhs_system_dim(a) * sizeof(double)) || odhs_system_validate(a, 1e-9) != ODHS_OK) {
            snprintf(msg, sizeof msg, "system %s: valid calls fail or differ", name);
            return msg;
        }
    }
    return NULL;
}

static const char *probe_network(const odhs_network *a, const odhs_network *b, const char *name)
{
    static char msg[128];
    size_t nc = odhs_network_count(a);
    if (nc != odhs_network_count(b) || odhs_network_particles(a) != odhs_network_particles(b) ||
        odhs_network_dim(a) != odhs_network_dim(b) || odhs_network_nnz(a) != odhs_network_nnz(b)) {
        snprintf(msg, sizeof msg, "network %s: size changed", name);
        return msg;
    }
    int d = odhs_network_dim(a);
    size_t cap = nc ? nc : 1;
    double *fa = calloc(cap * 3, sizeof *fa), *fb = calloc(cap * 3, sizeof *fb);
    const char *bad = NULL;
    for (size_t c = 0; c < nc && !bad; ++c) {
        size_t ia, ja, ib, jb;
        int ka, kb;
        if (odhs_network_get_contact(a, c, &ia, &ja, &ka) != ODHS_OK ||
            odhs_network_get_contact(b, c, &ib, &jb, &kb) != ODHS_OK || ia != ib || ja != jb || ka != kb)
            bad = "contacts";
    }
    if (!bad && (odhs_network_get_forces(a, fa) || odhs_network_get_forces(b, fb) || !bits_eq(fa, fb, nc * sizeof *fa)))
        bad = "forces";
    if (!bad && (odhs_network_get_gaps(a, fa) || odhs_network_get_gaps(b, fb) || !bits_eq(fa, fb, nc * sizeof *fa)))
        bad = "gaps";
    if (!bad && (odhs_network_get_normals(a, fa) || odhs_network_get_normals(b, fb) ||
                 !bits_eq(fa, fb, nc * (size_t)d * sizeof *fa)))
        bad = "normals";
    double za, zb;
    size_t nba, nbb, nca, ncb;
    if (!bad && (odhs_network_coordination(a, &za) || odhs_network_coordination(b, &zb) || !bits_eq(&za, &zb, sizeof za)))
        bad = "coordination";
    if (!bad && (odhs_network_constrained(a, &nba, &nca, NULL, NULL) ||
                 odhs_network_constrained(b, &nbb, &ncb, NULL, NULL) || nba != nbb || nca != ncb))
        bad = "constrained subset";
    free(fa);
    free(fb);
    if (bad) {
        snprintf(msg, sizeof msg, "network %s: %s differ", name, bad);
        return msg;
    }
    return NULL;
}

static const char *probe_driver(const odhs_driver *a, const odhs_driver *b, const odhs_system *sys, const char *name)
{
    static char msg[128];
    double va[6], vb[6];
    int ea, eb;
    memset(va, 0, sizeof va);
    memset(vb, 0, sizeof vb);
    if (odhs_driver_get_shear_rate(a, &va[0]) || odhs_driver_get_shear_rate(b, &vb[0]) ||
        odhs_driver_get_compression_rate(a, &va[1]) || odhs_driver_get_compression_rate(b, &vb[1]) ||
        odhs_driver_get_mobility(a, &va[2]) || odhs_driver_get_mobility(b, &vb[2]) ||
        odhs_driver_get_pressure(a, &va[3], &ea) || odhs_driver_get_pressure(b, &vb[3], &eb) ||
        odhs_driver_time_unit(a, sys, &va[4]) || odhs_driver_time_unit(b, sys, &vb[4]) ||
        odhs_driver_get_jamming_pressure(a, &va[5]) || odhs_driver_get_jamming_pressure(b, &vb[5]) || ea != eb ||
        !bits_eq(va, vb, sizeof va)) {
        snprintf(msg, sizeof msg, "driver %s: settings changed or getters fail", name);
        return msg;
    }
    return NULL;
}

/* solve N x = b on the ready stepper's network with both solvers */
static const char *probe_solver(odhs_solver *a, odhs_solver *b, const world *wa, const world *wb, const char *name)
{
    static char msg[160];
    const odhs_network *na = odhs_stepper_network(wa->run), *nb = odhs_stepper_network(wb->run);
    size_t nc = odhs_network_count(na);
    double *rhs = calloc(nc + 1, sizeof *rhs), *xa = calloc(nc + 1, sizeof *xa), *xb = calloc(nc + 1, sizeof *xb);
    for (size_t c = 0; c < nc; ++c) rhs[c] = 1.0 + 0.01 * (double)c;
    int ra = odhs_solver_solve(a, na, rhs, xa), rb = odhs_solver_solve(b, nb, rhs, xb);
    double resa = -1, resb = -2;
    odhs_solver_get_stat(a, "residual", &resa);
    odhs_solver_get_stat(b, "residual", &resb);
    const char *bad = NULL;
    if (ra != ODHS_OK || rb != ODHS_OK) {
        snprintf(msg, sizeof msg, "solver %s: solve fails afterwards (%d, fresh %d): %s", name, ra, rb,
                 odhs_solver_errmsg(a));
        bad = msg;
    } else if (!bits_eq(xa, xb, nc * sizeof *xa) || !bits_eq(&resa, &resb, sizeof resa)) {
        snprintf(msg, sizeof msg, "solver %s: solution differs from a fresh handle's", name);
        bad = msg;
    } else if (strcmp(odhs_solver_name(a), odhs_solver_name(b)) != 0) {
        snprintf(msg, sizeof msg, "solver %s: name changed", name);
        bad = msg;
    }
    free(rhs);
    free(xa);
    free(xb);
    return bad;
}

static const char *probe_stepper(odhs_stepper *a, odhs_stepper *b, const odhs_system *sa, const odhs_system *sb,
                                 const char *name)
{
    static char msg[200];
    double ta0, tb0;
    uint64_t ca[3], cb[3];
    if (odhs_stepper_time(a, &ta0) || odhs_stepper_time(b, &tb0) || !bits_eq(&ta0, &tb0, sizeof ta0) ||
        odhs_stepper_counts(a, &ca[0], &ca[1], &ca[2]) || odhs_stepper_counts(b, &cb[0], &cb[1], &cb[2]) ||
        memcmp(ca, cb, sizeof ca) != 0) {
        snprintf(msg, sizeof msg, "stepper %s: time or counters changed", name);
        return msg;
    }
    odhs_event ea, eb;
    int ra = odhs_stepper_step(a, &ea), rb = odhs_stepper_step(b, &eb);
    if (ra != rb || ra < 0) {
        snprintf(msg, sizeof msg, "stepper %s: step afterwards gives %d (fresh %d): %s", name, ra, rb,
                 odhs_stepper_errmsg(a));
        return msg;
    }
    if (ea.kind != eb.kind || ea.i != eb.i || ea.j != eb.j || !bits_eq(&ea.time, &eb.time, sizeof ea.time)) {
        snprintf(msg, sizeof msg, "stepper %s: the next step's event differs", name);
        return msg;
    }
    double ta, tb, pa = 0, pb = 0;
    odhs_stepper_time(a, &ta);
    odhs_stepper_time(b, &tb);
    int pra = odhs_stepper_pressure(a, &pa), prb = odhs_stepper_pressure(b, &pb);
    if (!bits_eq(&ta, &tb, sizeof ta) || pra != prb || !bits_eq(&pa, &pb, sizeof pa)) {
        snprintf(msg, sizeof msg, "stepper %s: time or pressure after a step differ", name);
        return msg;
    }
    const char *s = probe_system(sa, sb, name);
    if (s) {
        snprintf(msg, sizeof msg, "stepper %s: configuration after a step differs (%s)", name, s);
        return msg;
    }
    return NULL;
}

/* everything in a against everything in b */
static const char *probe_world(world *a, world *b)
{
    const char *m;
    if ((m = probe_system(a->sys2, b->sys2, "sys2"))) return m;
    if ((m = probe_system(a->sys3, b->sys3, "sys3"))) return m;
    if ((m = probe_system(a->sys8, b->sys8, "sys8"))) return m;
    if ((m = probe_system(a->bare, b->bare, "bare"))) return m;
    if ((m = probe_system(a->sysr, b->sysr, "sysr"))) return m;
    if ((m = probe_network(a->net2, b->net2, "net2"))) return m;
    if ((m = probe_network(a->net3, b->net3, "net3"))) return m;
    if ((m = probe_network(odhs_stepper_network(a->run), odhs_stepper_network(b->run), "of run"))) return m;
    if ((m = probe_driver(a->drv, b->drv, a->sys2, "drv"))) return m;
    if ((m = probe_driver(a->drvr, b->drvr, a->sysr, "drvr"))) return m;
    if ((m = probe_solver(a->cg, b->cg, a, b, "cg"))) return m;
    if ((m = probe_solver(a->dense, b->dense, a, b, "dense"))) return m;
    if ((m = probe_stepper(a->st, b->st, a->sys2, b->sys2, "st"))) return m;
    if ((m = probe_stepper(a->run, b->run, a->sysr, b->sysr, "run"))) return m;
    return NULL;
}

/* ---- helpers for bodies ---------------------------------------------------------- */
#define POISON_PTR(T) ((T *)(uintptr_t)0x1)

/* a callback that is never expected to run */
static int never_pair(size_t i, size_t j, const double *rij, double gap, void *ctx)
{
    (void)i, (void)j, (void)rij, (void)gap, (void)ctx;
    return 0;
}

static int force_nan(double t, const odhs_system *sys, double *F, void *ctx)
{
    (void)t, (void)ctx;
    size_t nd = odhs_system_count(sys) * (size_t)odhs_system_dim(sys);
    for (size_t k = 0; k < nd; ++k) F[k] = 0.0;
    F[nd / 2] = NAN;
    return 0;
}

static int force_fail(double t, const odhs_system *sys, double *F, void *ctx)
{
    (void)t, (void)sys, (void)F, (void)ctx;
    return 1;
}

/* whole file into malloc'ed memory; NULL on failure */
static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    size_t cap = 1 << 16, n = 0, got;
    unsigned char *b = malloc(cap);
    while (b && (got = fread(b + n, 1, cap - n, f)) > 0) {
        n += got;
        if (n == cap) {
            unsigned char *q = realloc(b, cap *= 2);
            if (!q) {
                free(b);
                b = NULL;
            } else {
                b = q;
            }
        }
    }
    fclose(f);
    *len = n;
    return b;
}

/* a custom backend for odhs_solver_create: tables made malformed per case */
static int ub_create_ok(void **state)
{
    *state = malloc(1);
    return *state ? ODHS_OK : ODHS_E_NOMEM;
}
static int ub_create_nomem(void **state)
{
    *state = NULL;
    return ODHS_E_NOMEM;
}
static int ub_create_positive(void **state)
{
    *state = NULL;
    return 7;
}
static void ub_destroy(void *state) { free(state); }
static int ub_solve(void *state, const odhs_network *net, const double *b, double *x)
{
    (void)state;
    size_t nc = odhs_network_count(net);
    for (size_t c = 0; c < nc; ++c) x[c] = b[c];
    return ODHS_OK;
}

static int try_type(odhs_solver_type t)
{
    odhs_solver *s = POISON_PTR(odhs_solver);
    int rc = odhs_solver_create(&t, &s);
    if (rc < 0 && s != NULL) return post("failed odhs_solver_create left *out = %p", (void *)s);
    odhs_solver_destroy(rc == ODHS_OK ? s : NULL);
    return rc;
}

/* a well-formed version-2 table; rows break one field of a copy */
static odhs_solver_type ub_type(void)
{
    odhs_solver_type t = {.version = 2, .name = "user", .flags = ODHS_SOLVER_DIRECT,
                          .create = ub_create_ok, .destroy = ub_destroy, .solve = ub_solve};
    return t;
}

/* try_type on ub_type() with one field changed */
#define UB_TRY(field, value)                  \
    do {                                      \
        odhs_solver_type ub_t_ = ub_type();   \
        ub_t_.field = value;                  \
        return try_type(ub_t_);               \
    } while (0)

/* a system out pointer that must be NULL after a failed create */
static int sys_create_expect_null(int dim, size_t n)
{
    odhs_system *s = POISON_PTR(odhs_system);
    int rc = odhs_system_create(dim, n, &s);
    if (rc < 0 && s != NULL) return post("failed odhs_system_create left *out = %p", (void *)s);
    if (rc == ODHS_OK) odhs_system_destroy(s);
    return rc;
}

static int xyz_parse_str(const char *text, size_t len)
{
    odhs_system *s = POISON_PTR(odhs_system);
    char err[256] = "";
    int rc = odhs_xyz_parse(text, len, &s, err, sizeof err);
    if (rc < 0 && s != NULL) return post("failed parse left *out = %p", (void *)s);
    if (rc < 0 && err[0] == '\0') return post("failed parse left no message in errbuf");
    if (rc == ODHS_OK) odhs_system_destroy(s);
    return rc;
}

static int ckpt_parse_expect_null(const void *buf, size_t len, odhs_solver *sol, int null_out)
{
    odhs_system *s = POISON_PTR(odhs_system);
    odhs_driver *d = POISON_PTR(odhs_driver);
    odhs_stepper *t = POISON_PTR(odhs_stepper);
    char err[256] = "";
    int rc = odhs_checkpoint_parse(buf, len, sol, null_out == 1 ? NULL : &s, null_out == 2 ? NULL : &d,
                                   null_out == 3 ? NULL : &t, err, sizeof err);
    if (rc < 0) {
        if ((null_out != 1 && s) || (null_out != 2 && d) || (null_out != 3 && t))
            return post("failed checkpoint parse left an output set");
        if (!err[0]) return post("failed checkpoint parse left no message in errbuf");
    } else {
        odhs_stepper_destroy(t);
        odhs_driver_destroy(d);
        odhs_system_destroy(s);
    }
    return rc;
}

/* a valid checkpoint of the ready stepper, in memory */
static unsigned char *ckpt_bytes(world *w, size_t *len)
{
    const char *p = wpath(w, "valid.ckpt");
    if (odhs_checkpoint_write(w->run, p) != ODHS_OK) return NULL;
    return slurp(p, len);
}

static int ckpt_parse_mutated(world *w, int how)
{
    size_t len = 0;
    unsigned char *b = ckpt_bytes(w, &len);
    if (!b) return post("could not write a valid checkpoint: %s", odhs_stepper_errmsg(w->run));
    if (how == 0) len = len / 2;     /* truncated */
    else if (how == 1) b[len / 2] ^= 0x40; /* one bit flipped */
    else if (how == 2) memcpy(b, "ODHSCKPX", 8); /* wrong magic */
    int rc = ckpt_parse_expect_null(b, len, w->cg, 0);
    free(b);
    return rc;
}


/* ---- bodies of the longer rows ------------------------------------------------ */
static int wrap_far_cases(void)
{
    static const struct {
        double L, gamma, x0, y0;
    } cs[] = {
        {1e-10, 0.0, 1e300, 1e300},  /* x/L overflows: NaN */
        {3.7, 0.3, -1e17, -1e17},    /* x ends at 4.3 > Lx */
        {3.7, 0.0, 1e17, -1.7e308},  /* y ends at 2e292 */
        {1.0, 0.3, -1.7e308, 1e308}, /* NaN through the sheared image */
        {3.7, 0.3, -0x1p49 * 3.7, 0x1p49 * 3.7 + 0.1}, /* within 2^50 box lengths: accepted */
        {0.7, -0.5, 0x1p50 * 0.7 * 0.999, -123456789.25},
    };
    for (size_t k = 0; k < sizeof cs / sizeof cs[0]; ++k) {
        /* one particle: with two, the NaN reaches a float-to-int conversion in the
         * cell list (undefined behaviour, see lib/cells.c) */
        odhs_system *s = NULL;
        const double L[2] = {cs[k].L, cs[k].L}, r[1] = {0.1 * cs[k].L};
        const double x[2] = {cs[k].x0, cs[k].y0};
        int rc = odhs_system_create(2, 1, &s);
        if (rc) return post("create %d", rc);
        rc = odhs_system_set_configuration(s, L, cs[k].gamma, r, x);
        double y[2] = {0, 0};
        int msg = odhs_system_errmsg(s)[0] != '\0';
        if (rc == ODHS_OK) odhs_system_get_positions(s, y);
        odhs_system_destroy(s);
        if (rc < 0 && !msg) return post("case %zu: error %d without a message", k, rc);
        if (rc < 0 && rc != ODHS_E_INVALID) return post("case %zu: error %d, system.h documents ODHS_E_INVALID", k, rc);
        for (int c = 0; rc == ODHS_OK && c < 2; ++c)
            if (!(y[c] >= 0.0 && y[c] < cs[k].L))
                return post("case %zu: (%g, %g) in a box of %g at strain %g accepted, wrapped to (%.17g, %.17g)", k,
                            cs[k].x0, cs[k].y0, cs[k].L, cs[k].gamma, y[0], y[1]);
    }
    return ODHS_OK;
}

/* a box whose aspect ratio Lx/Ly underflows or overflows: the strain must stay
 * finite (and in range) or the box be refused with a message */
static int aspect_cases(void)
{
    static const double cs[][3] = {{1e-300, 3e30, 0.0}, {1e300, 1e-300, 0.0}, {1e-200, 1e200, 0.25}};
    for (size_t k = 0; k < sizeof cs / sizeof cs[0]; ++k) {
        odhs_system *s = NULL;
        int rc = odhs_system_create(2, 1, &s);
        if (rc) return post("create %d", rc);
        rc = odhs_system_set_box(s, cs[k]);
        if (rc == ODHS_OK) rc = odhs_system_set_strain(s, cs[k][2]);
        double g = 0.0;
        odhs_system_get_strain(s, &g);
        int msg = odhs_system_errmsg(s)[0] != '\0';
        odhs_system_destroy(s);
        if (rc < 0 && !msg) return post("case %zu: error %d without a message", k, rc);
        if (!isfinite(g) || fabs(g) > 0.5 * (cs[k][0] / cs[k][1]))
            return post("case %zu: box %g x %g, strain %g: status %d and the stored strain is %g", k, cs[k][0],
                        cs[k][1], cs[k][2], rc, g);
    }
    return ODHS_OK;
}

static int strain_remap_cases(void)
{
    static const struct {
        double Lx, Ly, gamma;
    } cs[] = {
        {1.7, 1.0, 4.25},    /* lands just outside: 0.85000000000000009 > 0.85 */
        {10.0, 3.0, -5.0},   /* 1.666666666666667 > 5/3 */
        {8.0, 40.0, 2.5e306} /* a huge strain: -3.1e290 */
    };
    for (size_t k = 0; k < sizeof cs / sizeof cs[0]; ++k) {
        odhs_system *s = NULL;
        const double L[2] = {cs[k].Lx, cs[k].Ly};
        double half = 0.5 * cs[k].Lx / cs[k].Ly, g1 = 0.0, g2 = 0.0;
        int rc = odhs_system_create(2, 4, &s);
        if (!rc) rc = odhs_system_set_box(s, L);
        if (rc) {
            odhs_system_destroy(s);
            return post("case %zu: setup %d", k, rc);
        }
        rc = odhs_system_set_strain(s, cs[k].gamma);
        int msg = odhs_system_errmsg(s)[0] != '\0';
        odhs_system_get_strain(s, &g1);
        if (!rc) rc = odhs_system_set_strain(s, g1);
        odhs_system_get_strain(s, &g2);
        odhs_system_destroy(s);
        /* system.h: |gamma| beyond 2^50 Lx/Ly is refused */
        if (rc == ODHS_E_INVALID && fabs(cs[k].gamma) > 0x1p50 * cs[k].Lx / cs[k].Ly) {
            if (!msg) return post("case %zu: refused without a message", k);
            if (g1 != 0.0) return post("case %zu: refused but the strain changed to %.17g", k, g1);
            continue;
        }
        if (rc) return post("case %zu: status %d", k, rc);
        if (fabs(g1) > half)
            return post("case %zu: strain %.17g on a %g x %g box stored as %.17g, outside [-%.17g, %.17g]", k,
                        cs[k].gamma, cs[k].Lx, cs[k].Ly, g1, half, half);
        if (g1 != g2) return post("case %zu: setting the strain %.17g it reported gives %.17g", k, g1, g2);
    }
    return ODHS_OK;
}

static int huge_rate_case(void)
{
    odhs_system *s = NULL;
    odhs_driver *d = NULL;
    odhs_solver *so = NULL;
    odhs_stepper *st = NULL;
    int rc = odhs_system_create(2, 16, &s);
    if (!rc) rc = odhs_system_set_radii_bidisperse(s, 0.5, 1.4, 0.03, 3);
    if (!rc) rc = odhs_system_place_random(s, 0.6, 3);
    if (!rc) rc = odhs_driver_create(&d);
    if (!rc) rc = odhs_driver_set_shear_rate(d, 1e308);
    if (!rc) rc = odhs_solver_create_by_name("cg", &so);
    if (!rc) rc = odhs_stepper_create(s, d, so, &st);
    double x0[32], x1[32];
    if (!rc) rc = odhs_system_get_positions(s, x0);
    if (rc) {
        rc = post("setup: %d", rc);
    } else {
        rc = odhs_stepper_step(st, NULL);
        odhs_system_get_positions(s, x1);
        int finite = 1;
        for (int k = 0; k < 32; ++k) finite &= isfinite(x1[k]) != 0;
        if (rc >= 0 && !finite) rc = post("step returned %d with non-finite positions", rc);
        else if (rc < 0 && memcmp(x0, x1, sizeof x0) != 0) rc = post("failed step %d not rolled back", rc);
        else if (rc < 0 && !odhs_stepper_errmsg(st)[0]) rc = post("failed step %d without a message", rc);
        else if (rc < 0) rc = ODHS_OK; /* refused, rolled back, explained: fine */
    }
    odhs_stepper_destroy(st);
    odhs_solver_destroy(so);
    odhs_driver_destroy(d);
    odhs_system_destroy(s);
    return rc;
}

/* ======================================================================
 * The tables. X(id, function, expect, alt, errmsg handle, flags, body)
 * ====================================================================== */

#define NAN_ NAN
#define INF_ INFINITY

/* ---- common.h ---------------------------------------------------------------- */
#define COMMON_CASES(X)                                                                                         \
    X(version_string, odhs_version_string, ODHS_OK, NOALT, H_NONE, 0,                                           \
      const char *v = odhs_version_string();                                                                    \
      return v && strcmp(v, ODHS_VERSION_STRING) == 0 ? ODHS_OK : post("version string '%s'", v ? v : "(null)");) \
    X(version_number, odhs_version_number, ODHS_OK, NOALT, H_NONE, 0,                                           \
      return odhs_version_number() == ODHS_VERSION_NUMBER ? ODHS_OK : post("version number");)                  \
    X(strerror_unknown, odhs_strerror, ODHS_OK, NOALT, H_NONE, 0,                                               \
      const int codes[] = {INT_MIN, -1000, -21, 4, 999, INT_MAX};                                               \
      for (size_t k = 0; k < sizeof codes / sizeof codes[0]; ++k) {                                             \
          const char *s = odhs_strerror(codes[k]);                                                              \
          if (!s || !s[0]) return post("odhs_strerror(%d) is empty", codes[k]);                                 \
      } return ODHS_OK;)                                                                                        \
    X(strerror_known_distinct, odhs_strerror, ODHS_OK, NOALT, H_NONE, 0,                                        \
      for (int a = -20; a <= 3; ++a) for (int b = a + 1; b <= 3; ++b)                                           \
          if (!strcmp(odhs_strerror(a), odhs_strerror(b))) return post("codes %d and %d share a text", a, b);   \
      if (!strcmp(odhs_strerror(-20), odhs_strerror(-21))) return post("-20 has the unknown-code text");        \
      return ODHS_OK;)                                                                                          \
    X(free_null, odhs_free, ODHS_OK, NOALT, H_NONE, 0, odhs_free(NULL); return ODHS_OK;)

/* ---- system.h ------------------------------------------------------------------ */
#define SYSTEM_CASES(X)                                                                                        \
    X(create_out_null, odhs_system_create, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_system_create(2, 4, NULL);) \
    X(create_dim0, odhs_system_create, ODHS_E_DIM, NOALT, H_NONE, 0, return sys_create_expect_null(0, 4);)      \
    X(create_dim1, odhs_system_create, ODHS_E_DIM, NOALT, H_NONE, 0, return sys_create_expect_null(1, 4);)      \
    X(create_dim4, odhs_system_create, ODHS_E_DIM, NOALT, H_NONE, 0, return sys_create_expect_null(4, 4);)      \
    X(create_dim_neg, odhs_system_create, ODHS_E_DIM, NOALT, H_NONE, 0, return sys_create_expect_null(-3, 4);)  \
    X(create_n0, odhs_system_create, ODHS_E_EMPTY, NOALT, H_NONE, 0, return sys_create_expect_null(2, 0);)      \
    X(create_n_huge, odhs_system_create, ODHS_E_NOMEM, NOALT, H_NONE, 0,                                       \
      return sys_create_expect_null(3, SIZE_MAX);)                                                             \
    X(create_n_half, odhs_system_create, ODHS_E_NOMEM, NOALT, H_NONE, 0,                                       \
      return sys_create_expect_null(2, SIZE_MAX / 2);)                                                         \
    X(destroy_null, odhs_system_destroy, ODHS_OK, NOALT, H_NONE, 0, odhs_system_destroy(NULL); return ODHS_OK;) \
    X(clone_null_sys, odhs_system_clone, ODHS_E_NULL, NOALT, H_NONE, 0,                                        \
      odhs_system *c = POISON_PTR(odhs_system); int rc = odhs_system_clone(NULL, &c);                          \
      return c ? post("*out not NULL") : rc;)                                                                  \
    X(clone_null_out, odhs_system_clone, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_system_clone(w->sys2, NULL);) \
    X(clone_bare, odhs_system_clone, ODHS_OK, NOALT, H_NONE, 0,                                                 \
      odhs_system *c = NULL; int rc = odhs_system_clone(w->bare, &c);                                          \
      if (rc == ODHS_OK && odhs_system_is_ready(c)) rc = post("clone of a bare system is ready");               \
      double r[16];                                                                                            \
      if (rc == ODHS_OK && odhs_system_get_radii(c, r) != ODHS_E_STATE) rc = post("clone has radii");          \
      odhs_system_destroy(c); return rc;)                                                                      \
    X(errmsg_null, odhs_system_errmsg, ODHS_OK, NOALT, H_NONE, 0,                                              \
      const char *m = odhs_system_errmsg(NULL); return m && !m[0] ? ODHS_OK : post("errmsg(NULL) not \"\"");)  \
    X(errmsg_fresh, odhs_system_errmsg, ODHS_OK, NOALT, H_NONE, 0,                                             \
      return odhs_system_errmsg(w->sys2)[0] == '\0' ? ODHS_OK : post("fresh handle has a message");)           \
    X(dim_null, odhs_system_dim, ODHS_OK, NOALT, H_NONE, 0,                                                    \
      return odhs_system_dim(NULL) == 0 ? ODHS_OK : post("dim(NULL) != 0");)                                   \
    X(count_null, odhs_system_count, ODHS_OK, NOALT, H_NONE, 0,                                                \
      return odhs_system_count(NULL) == 0 ? ODHS_OK : post("count(NULL) != 0");)                               \
    X(is_ready_null, odhs_system_is_ready, ODHS_OK, NOALT, H_NONE, 0,                                          \
      return odhs_system_is_ready(NULL) == 0 && odhs_system_is_ready(w->bare) == 0 ? ODHS_OK                   \
                                                                                    : post("is_ready wrong");) \
    X(set_box_null_sys, odhs_system_set_box, ODHS_E_NULL, NOALT, H_NONE, 0,                                    \
      const double L[3] = {9, 9, 9}; return odhs_system_set_box(NULL, L);)                                     \
    X(set_box_null_L, odhs_system_set_box, ODHS_E_NULL, NOALT, H_SYS2, 0, return odhs_system_set_box(w->sys2, NULL);) \
    X(set_box_nan, odhs_system_set_box, ODHS_E_NONFINITE, NOALT, H_SYS2, 0,                                    \
      const double L[2] = {NAN_, 20}; return odhs_system_set_box(w->sys2, L);)                                 \
    X(set_box_inf, odhs_system_set_box, ODHS_E_NONFINITE, NOALT, H_SYS3, 0,                                    \
      const double L[3] = {20, 20, INF_}; return odhs_system_set_box(w->sys3, L);)                             \
    X(set_box_zero, odhs_system_set_box, ODHS_E_INVALID, NOALT, H_BARE, 0,                                     \
      const double L[2] = {0.0, 1.0}; return odhs_system_set_box(w->bare, L);)                                 \
    X(set_box_negative, odhs_system_set_box, ODHS_E_INVALID, NOALT, H_SYS2, 0,                                 \
      const double L[2] = {20, -20}; return odhs_system_set_box(w->sys2, L);)                                  \
    X(set_box_too_small, odhs_system_set_box, ODHS_E_BOX, NOALT, H_SYS2, 0,                                    \
      const double L[2] = {2.0, 2.0}; return odhs_system_set_box(w->sys2, L);)                                 \
    X(set_box_overlap, odhs_system_set_box, ODHS_E_OVERLAP, NOALT, H_SYS2, 0,                                  \
      double L[2]; odhs_system_get_box(w->sys2, L); L[0] *= 0.6; L[1] *= 0.6;                                  \
      return odhs_system_set_box(w->sys2, L);)                                                                 \
    X(set_box_extreme_aspect, odhs_system_set_box, ODHS_OK, NOALT, H_NONE, 0,                                  \
      /* Lx/Ly under- or overflowing must not make the strain NaN (0/0 in the remap) */                        \
      return aspect_cases();)                                                                                  \
    X(get_box_null_sys, odhs_system_get_box, ODHS_E_NULL, NOALT, H_NONE, 0,                                    \
      double L[3]; return odhs_system_get_box(NULL, L);)                                                       \
    X(get_box_null_out, odhs_system_get_box, ODHS_E_NULL, NOALT, H_SYS2, 0, return odhs_system_get_box(w->sys2, NULL);) \
    X(volume_null_sys, odhs_system_volume, ODHS_E_NULL, NOALT, H_NONE, 0,                                      \
      double v; return odhs_system_volume(NULL, &v);)                                                          \
    X(volume_null_out, odhs_system_volume, ODHS_E_NULL, NOALT, H_SYS3, 0, return odhs_system_volume(w->sys3, NULL);) \
    X(set_strain_null, odhs_system_set_strain, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_system_set_strain(NULL, 0.1);) \
    X(set_strain_nan, odhs_system_set_strain, ODHS_E_NONFINITE, NOALT, H_SYS2, 0,                              \
      return odhs_system_set_strain(w->sys2, NAN_);)                                                           \
    X(set_strain_inf, odhs_system_set_strain, ODHS_E_NONFINITE, NOALT, H_BARE, 0,                              \
      return odhs_system_set_strain(w->bare, -INF_);)                                                          \
    X(set_strain_overlap, odhs_system_set_strain, ODHS_E_OVERLAP, NOALT, H_NONE, 0,                            \
      /* A at (1,0.5), B at (3,3.5), r = 0.6, L = 4: apart at strain 0, overlapping through the sheared     \
       * boundary at strain 0.5 (separation (0,-1) < 1.2) */                                                  \
      odhs_system *s = NULL; const double L[2] = {4, 4}, r[2] = {0.6, 0.6}, x[4] = {1, 0.5, 3, 3.5};          \
      int rc = odhs_system_create(2, 2, &s);                                                                   \
      if (!rc) rc = odhs_system_set_configuration(s, L, 0.0, r, x);                                            \
      if (rc) { odhs_system_destroy(s); return post("setup: %d", rc); }                                        \
      rc = odhs_system_set_strain(s, 0.5); double g = -1;                                                      \
      odhs_system_get_strain(s, &g);                                                                           \
      if (rc < 0 && !odhs_system_errmsg(s)[0]) rc = post("no message");                                        \
      else if (rc < 0 && g != 0.0) rc = post("strain changed to %g by the failed call", g);                    \
      odhs_system_destroy(s); return rc;)                                                                      \
    X(get_strain_null_sys, odhs_system_get_strain, ODHS_E_NULL, NOALT, H_NONE, 0,                              \
      double g; return odhs_system_get_strain(NULL, &g);)                                                      \
    X(get_strain_null_out, odhs_system_get_strain, ODHS_E_NULL, NOALT, H_SYS2, 0,                              \
      return odhs_system_get_strain(w->sys2, NULL);)                                                           \
    X(set_radii_null_sys, odhs_system_set_radii, ODHS_E_NULL, NOALT, H_NONE, 0,                                \
      double r[16] = {0}; return odhs_system_set_radii(NULL, r);)                                              \
    X(set_radii_null_r, odhs_system_set_radii, ODHS_E_NULL, NOALT, H_BARE, 0, return odhs_system_set_radii(w->bare, NULL);) \
    X(set_radii_nan, odhs_system_set_radii, ODHS_E_NONFINITE, NOALT, H_BARE, 0,                                \
      double r[16]; for (int i = 0; i < 16; ++i) r[i] = 0.5; r[7] = NAN_; return odhs_system_set_radii(w->bare, r);) \
    X(set_radii_inf, odhs_system_set_radii, ODHS_E_NONFINITE, NOALT, H_SYS2, 0,                                \
      double r[16]; odhs_system_get_radii(w->sys2, r); r[15] = INF_; return odhs_system_set_radii(w->sys2, r);) \
    X(set_radii_zero, odhs_system_set_radii, ODHS_E_INVALID, NOALT, H_BARE, 0,                                 \
      double r[16]; for (int i = 0; i < 16; ++i) r[i] = 0.5; r[3] = 0.0; return odhs_system_set_radii(w->bare, r);) \
    X(set_radii_negative, odhs_system_set_radii, ODHS_E_INVALID, NOALT, H_SYS2, 0,                             \
      double r[16]; odhs_system_get_radii(w->sys2, r); r[0] = -0.5; return odhs_system_set_radii(w->sys2, r);) \
    X(set_radii_box, odhs_system_set_radii, ODHS_E_BOX, NOALT, H_SYS2, 0,                                      \
      double r[16], L[2]; odhs_system_get_radii(w->sys2, r); odhs_system_get_box(w->sys2, L);                  \
      r[5] = 0.3 * L[0]; return odhs_system_set_radii(w->sys2, r);)                                            \
    X(set_radii_overlap, odhs_system_set_radii, ODHS_E_OVERLAP, NOALT, H_SYS2, 0,                              \
      double r[16]; odhs_system_get_radii(w->sys2, r); for (int i = 0; i < 16; ++i) r[i] *= 1.5;               \
      return odhs_system_set_radii(w->sys2, r);)                                                               \
    X(get_radii_null_sys, odhs_system_get_radii, ODHS_E_NULL, NOALT, H_NONE, 0,                                \
      double r[16]; return odhs_system_get_radii(NULL, r);)                                                    \
    X(get_radii_null_out, odhs_system_get_radii, ODHS_E_NULL, NOALT, H_SYS2, 0, return odhs_system_get_radii(w->sys2, NULL);) \
    X(get_radii_unset, odhs_system_get_radii, ODHS_E_STATE, NOALT, H_BARE, 0,                                  \
      double r[16]; for (int i = 0; i < 16; ++i) r[i] = -7.0; int rc = odhs_system_get_radii(w->bare, r);      \
      for (int i = 0; i < 16; ++i) if (r[i] != -7.0) return post("output written on error");                   \
      return rc;)                                                                                              \
    X(set_positions_null_sys, odhs_system_set_positions, ODHS_E_NULL, NOALT, H_NONE, 0,                        \
      double x[32] = {0}; return odhs_system_set_positions(NULL, x);)                                          \
    X(set_positions_null_x, odhs_system_set_positions, ODHS_E_NULL, NOALT, H_SYS2, 0,                          \
      return odhs_system_set_positions(w->sys2, NULL);)                                                        \
    X(set_positions_nan, odhs_system_set_positions, ODHS_E_NONFINITE, NOALT, H_SYS2, 0,                        \
      double x[32]; odhs_system_get_positions(w->sys2, x); x[31] = NAN_; return odhs_system_set_positions(w->sys2, x);) \
    X(set_positions_inf, odhs_system_set_positions, ODHS_E_NONFINITE, NOALT, H_BARE, 0,                        \
      double x[32]; for (int k = 0; k < 32; ++k) x[k] = k; x[0] = -INF_; return odhs_system_set_positions(w->bare, x);) \
    X(set_positions_overlap, odhs_system_set_positions, ODHS_E_OVERLAP, NOALT, H_SYS2, 0,                      \
      double x[32]; odhs_system_get_positions(w->sys2, x); x[2] = x[0]; x[3] = x[1] + 0.1;                     \
      return odhs_system_set_positions(w->sys2, x);)                                                           \
    X(get_positions_null_sys, odhs_system_get_positions, ODHS_E_NULL, NOALT, H_NONE, 0,                        \
      double x[32]; return odhs_system_get_positions(NULL, x);)                                                \
    X(get_positions_null_out, odhs_system_get_positions, ODHS_E_NULL, NOALT, H_SYS3, 0,                        \
      return odhs_system_get_positions(w->sys3, NULL);)                                                        \
    X(get_positions_unset, odhs_system_get_positions, ODHS_E_STATE, NOALT, H_BARE, 0,                          \
      double x[32]; return odhs_system_get_positions(w->bare, x);)                                             \
    X(set_config_null_sys, odhs_system_set_configuration, ODHS_E_NULL, NOALT, H_NONE, 0,                       \
      double L[2] = {9, 9}, r[16] = {0}, x[32] = {0}; return odhs_system_set_configuration(NULL, L, 0, r, x);) \
    X(set_config_null_L, odhs_system_set_configuration, ODHS_E_NULL, NOALT, H_SYS2, 0,                         \
      double r[16], x[32]; odhs_system_get_radii(w->sys2, r); odhs_system_get_positions(w->sys2, x);           \
      return odhs_system_set_configuration(w->sys2, NULL, 0, r, x);)                                           \
    X(set_config_null_r, odhs_system_set_configuration, ODHS_E_NULL, NOALT, H_SYS2, 0,                         \
      double L[2], x[32]; odhs_system_get_box(w->sys2, L); odhs_system_get_positions(w->sys2, x);              \
      return odhs_system_set_configuration(w->sys2, L, 0, NULL, x);)                                           \
    X(set_config_null_x, odhs_system_set_configuration, ODHS_E_NULL, NOALT, H_BARE, 0,                         \
      double L[2] = {20, 20}, r[16]; for (int i = 0; i < 16; ++i) r[i] = 0.5;                                  \
      return odhs_system_set_configuration(w->bare, L, 0, r, NULL);)                                           \
    X(set_config_nan_gamma, odhs_system_set_configuration, ODHS_E_NONFINITE, NOALT, H_SYS2, 0,                 \
      double L[2], r[16], x[32]; odhs_system_get_box(w->sys2, L); odhs_system_get_radii(w->sys2, r);           \
      odhs_system_get_positions(w->sys2, x); return odhs_system_set_configuration(w->sys2, L, NAN_, r, x);)   \
    X(set_config_bad_radius, odhs_system_set_configuration, ODHS_E_INVALID, NOALT, H_SYS2, 0,                  \
      double L[2], r[16], x[32]; odhs_system_get_box(w->sys2, L); odhs_system_get_radii(w->sys2, r);           \
      odhs_system_get_positions(w->sys2, x); r[4] = 0.0; x[0] = 0.25;                                          \
      return odhs_system_set_configuration(w->sys2, L, 0.1, r, x);)                                            \
    X(set_config_overlap, odhs_system_set_configuration, ODHS_E_OVERLAP, NOALT, H_SYS2, 0,                     \
      double L[2], r[16], x[32]; odhs_system_get_box(w->sys2, L); odhs_system_get_radii(w->sys2, r);           \
      odhs_system_get_positions(w->sys2, x); x[4] = x[6]; x[5] = x[7];                                         \
      return odhs_system_set_configuration(w->sys2, L, 0.0, r, x);)                                            \
    X(set_config_box, odhs_system_set_configuration, ODHS_E_BOX, NOALT, H_BARE, 0,                             \
      double L[2] = {1.5, 30}, r[16], x[32]; for (int i = 0; i < 16; ++i) { r[i] = 0.5; x[2*i] = 0.7; x[2*i+1] = 1.5 * i; } \
      return odhs_system_set_configuration(w->bare, L, 0.0, r, x);)                                            \
    X(set_species_null_sys, odhs_system_set_species, ODHS_E_NULL, NOALT, H_NONE, 0,                            \
      return odhs_system_set_species(NULL, 0, "A");)                                                           \
    X(set_species_null_label, odhs_system_set_species, ODHS_E_NULL, NOALT, H_SYS2, 0,                          \
      return odhs_system_set_species(w->sys2, 0, NULL);)                                                       \
    X(set_species_range, odhs_system_set_species, ODHS_E_RANGE, NOALT, H_SYS2, 0,                             \
      return odhs_system_set_species(w->sys2, 16, "A");)                                                       \
    X(set_species_range_max, odhs_system_set_species, ODHS_E_RANGE, NOALT, H_BARE, 0,                          \
      return odhs_system_set_species(w->bare, SIZE_MAX, "A");)                                                 \
    X(set_species_empty, odhs_system_set_species, ODHS_E_INVALID, NOALT, H_SYS2, 0,                            \
      return odhs_system_set_species(w->sys2, 1, "");)                                                         \
    X(set_species_too_long, odhs_system_set_species, ODHS_E_INVALID, NOALT, H_SYS2, 0,                         \
      return odhs_system_set_species(w->sys2, 1, "ABCDEFGHIJKLMNOP");)                                         \
    X(set_species_blank, odhs_system_set_species, ODHS_E_INVALID, NOALT, H_SYS2, 0,                            \
      return odhs_system_set_species(w->sys2, 1, "A B");)                                                      \
    X(set_species_quote, odhs_system_set_species, ODHS_E_INVALID, NOALT, H_SYS2, 0,                            \
      return odhs_system_set_species(w->sys2, 2, "A\"");)                                                      \
    X(set_species_tab, odhs_system_set_species, ODHS_E_INVALID, NOALT, H_SYS2, 0,                              \
      return odhs_system_set_species(w->sys2, 2, "A\tB");)                                                     \
    X(set_species_nonascii, odhs_system_set_species, ODHS_E_INVALID, NOALT, H_SYS2, 0,                         \
      return odhs_system_set_species(w->sys2, 2, "\xc3\xa9t\xc3\xa9");)                                        \
    X(get_species_null_sys, odhs_system_get_species, ODHS_E_NULL, NOALT, H_NONE, 0,                            \
      char b[16]; return odhs_system_get_species(NULL, 0, b, sizeof b);)                                       \
    X(get_species_null_buf, odhs_system_get_species, ODHS_E_NULL, NOALT, H_SYS2, 0,                            \
      return odhs_system_get_species(w->sys2, 0, NULL, 16);)                                                   \
    X(get_species_range, odhs_system_get_species, ODHS_E_RANGE, NOALT, H_SYS3, 0,                              \
      char b[16]; return odhs_system_get_species(w->sys3, 12, b, sizeof b);)                                   \
    X(get_species_size0, odhs_system_get_species, ODHS_E_INVALID, NOALT, H_SYS2, 0,                            \
      char b[4] = "zzz"; int rc = odhs_system_get_species(w->sys2, 0, b, 0);                                   \
      return strcmp(b, "zzz") ? post("buffer written with size 0") : rc;)                                      \
    X(get_species_size1, odhs_system_get_species, ODHS_E_INVALID, NOALT, H_SYS2, 0,                            \
      char b[4] = "zzz"; int rc = odhs_system_get_species(w->sys2, 0, b, 1);                                   \
      return strcmp(b, "zzz") ? post("buffer written with size 1") : rc;)                                      \
    X(scale_null, odhs_system_scale_box, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_system_scale_box(NULL, 1.1);) \
    X(scale_nan, odhs_system_scale_box, ODHS_E_NONFINITE, NOALT, H_SYS2, 0, return odhs_system_scale_box(w->sys2, NAN_);) \
    X(scale_inf, odhs_system_scale_box, ODHS_E_NONFINITE, NOALT, H_SYS2, 0, return odhs_system_scale_box(w->sys2, INF_);) \
    X(scale_zero, odhs_system_scale_box, ODHS_E_INVALID, NOALT, H_SYS3, 0, return odhs_system_scale_box(w->sys3, 0.0);) \
    X(scale_negative, odhs_system_scale_box, ODHS_E_INVALID, NOALT, H_SYS2, 0, return odhs_system_scale_box(w->sys2, -1.0);) \
    X(scale_overlap, odhs_system_scale_box, ODHS_E_OVERLAP, NOALT, H_SYS2, 0, return odhs_system_scale_box(w->sys2, 0.7);) \
    X(scale_box_small, odhs_system_scale_box, ODHS_E_BOX, NOALT, H_SYS2, 0, return odhs_system_scale_box(w->sys2, 1e-3);) \
    X(phi_null_sys, odhs_system_packing_fraction, ODHS_E_NULL, NOALT, H_NONE, 0,                               \
      double p; return odhs_system_packing_fraction(NULL, &p);)                                                \
    X(phi_null_out, odhs_system_packing_fraction, ODHS_E_NULL, NOALT, H_SYS2, 0,                               \
      return odhs_system_packing_fraction(w->sys2, NULL);)                                                     \
    X(phi_unset, odhs_system_packing_fraction, ODHS_E_STATE, NOALT, H_BARE, 0,                                 \
      double p; return odhs_system_packing_fraction(w->bare, &p);)                                             \
    X(sep_null_sys, odhs_system_separation, ODHS_E_NULL, NOALT, H_NONE, 0,                                     \
      double r[3]; return odhs_system_separation(NULL, 0, 1, r, NULL, NULL);)                                  \
    X(sep_null_out, odhs_system_separation, ODHS_E_NULL, NOALT, H_SYS2, 0,                                     \
      double d; int im[3]; return odhs_system_separation(w->sys2, 0, 1, NULL, &d, im);)                        \
    X(sep_range_i, odhs_system_separation, ODHS_E_RANGE, NOALT, H_SYS2, 0,                                     \
      double r[3]; return odhs_system_separation(w->sys2, 16, 1, r, NULL, NULL);)                              \
    X(sep_range_j, odhs_system_separation, ODHS_E_RANGE, NOALT, H_SYS3, 0,                                     \
      double r[3]; return odhs_system_separation(w->sys3, 0, SIZE_MAX, r, NULL, NULL);)                        \
    X(sep_unset, odhs_system_separation, ODHS_E_STATE, NOALT, H_BARE, 0,                                       \
      double r[3]; return odhs_system_separation(w->bare, 0, 1, r, NULL, NULL);)                               \
    X(validate_null, odhs_system_validate, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_system_validate(NULL, 0.0);) \
    X(validate_unset, odhs_system_validate, ODHS_E_STATE, NOALT, H_BARE, 0, return odhs_system_validate(w->bare, 0.0);) \
    X(validate_tol_negative, odhs_system_validate, ODHS_E_INVALID, NOALT, H_SYS2, 0,                           \
      return odhs_system_validate(w->sys2, -1e-3);)                                                            \
    X(validate_tol_nan, odhs_system_validate, ODHS_E_NONFINITE, ODHS_E_INVALID, H_SYS2, 0,                     \
      return odhs_system_validate(w->sys2, NAN_);)                                                             \
    X(pairs_null_sys, odhs_system_for_each_pair, ODHS_E_NULL, NOALT, H_NONE, 0,                                \
      return odhs_system_for_each_pair(NULL, 0.1, never_pair, NULL);)                                          \
    X(pairs_null_fn, odhs_system_for_each_pair, ODHS_E_NULL, NOALT, H_SYS2, 0,                                 \
      return odhs_system_for_each_pair(w->sys2, 0.1, NULL, NULL);)                                             \
    X(pairs_unset, odhs_system_for_each_pair, ODHS_E_STATE, NOALT, H_BARE, 0,                                  \
      return odhs_system_for_each_pair(w->bare, 0.1, never_pair, NULL);)                                       \
    X(pairs_gap_negative, odhs_system_for_each_pair, ODHS_E_INVALID, NOALT, H_SYS2, 0,                         \
      return odhs_system_for_each_pair(w->sys2, -0.1, never_pair, NULL);)                                      \
    X(pairs_gap_nan, odhs_system_for_each_pair, ODHS_E_NONFINITE, ODHS_E_INVALID, H_SYS2, 0,                   \
      return odhs_system_for_each_pair(w->sys2, NAN_, never_pair, NULL);)                                      \
    X(pairs_gap_inf, odhs_system_for_each_pair, ODHS_E_NONFINITE, ODHS_E_INVALID, H_SYS3, 0,                   \
      return odhs_system_for_each_pair(w->sys3, INF_, never_pair, NULL);)                                      \
    X(pairs_gap_too_large, odhs_system_for_each_pair, ODHS_E_INVALID, NOALT, H_SYS2, 0,                        \
      double L[2]; odhs_system_get_box(w->sys2, L); return odhs_system_for_each_pair(w->sys2, L[0], never_pair, NULL);) \
    X(bidisperse_null, odhs_system_set_radii_bidisperse, ODHS_E_NULL, NOALT, H_NONE, 0,                        \
      return odhs_system_set_radii_bidisperse(NULL, 0.5, 1.4, 0.0, 1);)                                        \
    X(bidisperse_nan, odhs_system_set_radii_bidisperse, ODHS_E_NONFINITE, NOALT, H_BARE, 0,                    \
      return odhs_system_set_radii_bidisperse(w->bare, NAN_, 1.4, 0.0, 1);)                                    \
    X(bidisperse_inf_ratio, odhs_system_set_radii_bidisperse, ODHS_E_NONFINITE, NOALT, H_SYS2, 0,              \
      return odhs_system_set_radii_bidisperse(w->sys2, 0.5, INF_, 0.0, 1);)                                    \
    X(bidisperse_nan_poly, odhs_system_set_radii_bidisperse, ODHS_E_NONFINITE, NOALT, H_SYS2, 0,               \
      return odhs_system_set_radii_bidisperse(w->sys2, 0.5, 1.4, NAN_, 1);)                                    \
    X(bidisperse_r0, odhs_system_set_radii_bidisperse, ODHS_E_INVALID, NOALT, H_BARE, 0,                       \
      return odhs_system_set_radii_bidisperse(w->bare, 0.0, 1.4, 0.0, 1);)                                     \
    X(bidisperse_ratio_neg, odhs_system_set_radii_bidisperse, ODHS_E_INVALID, NOALT, H_BARE, 0,                \
      return odhs_system_set_radii_bidisperse(w->bare, 0.5, -1.4, 0.0, 1);)                                    \
    X(bidisperse_poly_neg, odhs_system_set_radii_bidisperse, ODHS_E_INVALID, NOALT, H_BARE, 0,                 \
      return odhs_system_set_radii_bidisperse(w->bare, 0.5, 1.4, -0.1, 1);)                                    \
    X(bidisperse_poly_one, odhs_system_set_radii_bidisperse, ODHS_E_INVALID, NOALT, H_BARE, 0,                 \
      return odhs_system_set_radii_bidisperse(w->bare, 0.5, 1.4, 1.0, 1);)                                     \
    X(bidisperse_overlap, odhs_system_set_radii_bidisperse, ODHS_E_OVERLAP, NOALT, H_SYS2, 0,                  \
      return odhs_system_set_radii_bidisperse(w->sys2, 0.8, 1.4, 0.0, 1);)                                     \
    X(bidisperse_box, odhs_system_set_radii_bidisperse, ODHS_E_BOX, NOALT, H_SYS2, 0,                          \
      return odhs_system_set_radii_bidisperse(w->sys2, 5.0, 1.4, 0.0, 1);)                                     \
    X(place_null, odhs_system_place_random, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_system_place_random(NULL, 0.3, 1);) \
    X(place_nan, odhs_system_place_random, ODHS_E_NONFINITE, NOALT, H_SYS2, 0,                                 \
      return odhs_system_place_random(w->sys2, NAN_, 1);)                                                      \
    X(place_zero, odhs_system_place_random, ODHS_E_INVALID, NOALT, H_SYS2, 0,                                  \
      return odhs_system_place_random(w->sys2, 0.0, 1);)                                                       \
    X(place_one, odhs_system_place_random, ODHS_E_INVALID, NOALT, H_SYS3, 0,                                   \
      return odhs_system_place_random(w->sys3, 1.0, 1);)                                                       \
    X(place_no_radii, odhs_system_place_random, ODHS_E_STATE, NOALT, H_BARE, 0,                                \
      return odhs_system_place_random(w->bare, 0.3, 1);)                                                       \
    X(place_too_dense, odhs_system_place_random, ODHS_E_TOODENSE, NOALT, H_SYS8, 0,                            \
      return odhs_system_place_random(w->sys8, 0.9, 1);)                                                       \
    X(place_box_small, odhs_system_place_random, ODHS_E_BOX, NOALT, H_NONE, 0,                                 \
      /* two discs at phi 0.5 need a box smaller than two diameters */                                         \
      odhs_system *s = NULL; double r[2] = {0.5, 0.5};                                                        \
      int rc = odhs_system_create(2, 2, &s); if (!rc) rc = odhs_system_set_radii(s, r);                        \
      if (rc) { odhs_system_destroy(s); return post("setup %d", rc); }                                         \
      rc = odhs_system_place_random(s, 0.5, 1);                                                                \
      if (rc < 0 && !odhs_system_errmsg(s)[0]) rc = post("no message");                                        \
      else if (rc < 0 && odhs_system_is_ready(s)) rc = post("failed placement set positions");                 \
      odhs_system_destroy(s); return rc;)

/* ---- io.h -------------------------------------------------------------------- */
#define IO_CASES(X)                                                                                            \
    X(xyz_read_null_path, odhs_xyz_read, ODHS_E_NULL, NOALT, H_NONE, 0,                                        \
      odhs_system *s = POISON_PTR(odhs_system); char e[64] = "";                                               \
      int rc = odhs_xyz_read(NULL, &s, e, sizeof e);                                                           \
      return s ? post("*out not NULL") : !e[0] ? post("no message") : rc;)                                     \
    X(xyz_read_null_out, odhs_xyz_read, ODHS_E_NULL, NOALT, H_NONE, 0,                                         \
      return odhs_xyz_read(wpath(w, "a.xyz"), NULL, NULL, 0);)                                                 \
    X(xyz_read_missing, odhs_xyz_read, ODHS_E_IO, NOALT, H_NONE, 0,                                            \
      odhs_system *s = POISON_PTR(odhs_system); char e[128] = "";                                              \
      int rc = odhs_xyz_read(wpath(w, "missing.xyz"), &s, e, sizeof e);                                        \
      return s ? post("*out not NULL") : !e[0] ? post("no message") : rc;)                                     \
    X(xyz_read_directory, odhs_xyz_read, ODHS_E_IO, NOALT, H_NONE, 0,                                          \
      odhs_system *s = POISON_PTR(odhs_system); int rc = odhs_xyz_read(w->dir, &s, NULL, 0);                   \
      return s ? post("*out not NULL") : rc;)                                                                  \
    X(xyz_read_errlen0, odhs_xyz_read, ODHS_E_IO, NOALT, H_NONE, 0,                                            \
      odhs_system *s = NULL; char e[8] = "zzzzzzz";                                                            \
      int rc = odhs_xyz_read(wpath(w, "missing.xyz"), &s, e, 0);                                               \
      return strcmp(e, "zzzzzzz") ? post("errbuf written with errlen 0") : rc;)                                \
    X(xyz_read_errlen1, odhs_xyz_read, ODHS_E_IO, NOALT, H_NONE, 0,                                            \
      odhs_system *s = NULL; char e[8] = "zzzzzzz";                                                            \
      int rc = odhs_xyz_read(wpath(w, "missing.xyz"), &s, e, 1);                                               \
      return e[0] != '\0' || strcmp(e + 1, "zzzzzz") ? post("errbuf overrun with errlen 1") : rc;)             \
    X(xyz_parse_null_buf, odhs_xyz_parse, ODHS_E_NULL, NOALT, H_NONE, 0,                                       \
      odhs_system *s = POISON_PTR(odhs_system); char e[64] = "";                                               \
      int rc = odhs_xyz_parse(NULL, 10, &s, e, sizeof e);                                                      \
      return s ? post("*out not NULL") : !e[0] ? post("no message") : rc;)                                     \
    X(xyz_parse_null_out, odhs_xyz_parse, ODHS_E_NULL, NOALT, H_NONE, 0,                                       \
      return odhs_xyz_parse("1\n", 2, NULL, NULL, 0);)                                                         \
    X(xyz_parse_len0, odhs_xyz_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0, return xyz_parse_str("", 0);)           \
    X(xyz_parse_len0_nonempty, odhs_xyz_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                                \
      return xyz_parse_str("1\nLattice=\"4 0 0 0 4 0 0 0 4\" Properties=species:S:1:pos:R:3:radius:R:1\nA 1 1 1 0.5\n", 0);) \
    X(xyz_parse_garbage, odhs_xyz_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                                      \
      return xyz_parse_str("\x01\x02\xff\xfe garbage", 12);)                                                   \
    X(xyz_parse_embedded_nul, odhs_xyz_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                                 \
      static const char t[] = "1\nLattice=\"4 0 0 0 4 0 0 0 4\" Properties=species:S:1:pos:R:3:radius:R:1\nA 1\0 1 1 0.5\n"; \
      return xyz_parse_str(t, sizeof t - 1);)                                                                  \
    X(xyz_parse_nan, odhs_xyz_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                                          \
      return xyz_parse_str("1\nLattice=\"4 0 0 0 4 0 0 0 4\" Properties=species:S:1:pos:R:3:radius:R:1\nA nan 1 1 0.5\n", 200);) \
    X(xyz_parse_inf_lattice, odhs_xyz_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                                  \
      const char *t = "1\nLattice=\"inf 0 0 0 4 0 0 0 4\" Properties=species:S:1:pos:R:3:radius:R:1\nA 1 1 1 0.5\n"; \
      return xyz_parse_str(t, strlen(t));)                                                                     \
    X(xyz_parse_zero_radius, odhs_xyz_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                                  \
      const char *t = "1\nLattice=\"4 0 0 0 4 0 0 0 4\" Properties=species:S:1:pos:R:3:radius:R:1\nA 1 1 1 0\n"; \
      return xyz_parse_str(t, strlen(t));)                                                                     \
    X(xyz_parse_overlap, odhs_xyz_parse, ODHS_E_OVERLAP, NOALT, H_NONE, 0,                                     \
      const char *t = "2\nLattice=\"4 0 0 0 4 0 0 0 4\" Properties=species:S:1:pos:R:3:radius:R:1\nA 1 1 1 0.5\nA 1.5 1 1 0.5\n"; \
      return xyz_parse_str(t, strlen(t));)                                                                     \
    X(xyz_parse_box, odhs_xyz_parse, ODHS_E_BOX, NOALT, H_NONE, 0,                                             \
      const char *t = "1\nLattice=\"1 0 0 0 1 0 0 0 1\" Properties=species:S:1:pos:R:3:radius:R:1\nA 0.5 0.5 0.5 0.4\n"; \
      return xyz_parse_str(t, strlen(t));)                                                                     \
    X(xyz_parse_n0, odhs_xyz_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                                           \
      const char *t = "0\nLattice=\"4 0 0 0 4 0 0 0 4\" Properties=species:S:1:pos:R:3:radius:R:1\n";          \
      return xyz_parse_str(t, strlen(t));)                                                                     \
    X(xyz_parse_n_huge, odhs_xyz_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                                       \
      const char *t = "99999999999999999999999\nLattice=\"4 0 0 0 4 0 0 0 4\" Properties=species:S:1:pos:R:3:radius:R:1\n"; \
      return xyz_parse_str(t, strlen(t));)                                                                     \
    X(xyz_write_null_sys, odhs_xyz_write, ODHS_E_NULL, NOALT, H_NONE, 0,                                       \
      return odhs_xyz_write(NULL, wpath(w, "a.xyz"));)                                                         \
    X(xyz_write_null_path, odhs_xyz_write, ODHS_E_NULL, NOALT, H_SYS2, 0, return odhs_xyz_write(w->sys2, NULL);) \
    X(xyz_write_unset, odhs_xyz_write, ODHS_E_STATE, NOALT, H_BARE, 0,                                         \
      int rc = odhs_xyz_write(w->bare, wpath(w, "bare.xyz"));                                                  \
      return access(wpath(w, "bare.xyz"), F_OK) == 0 ? post("file created on error") : rc;)                    \
    X(xyz_write_nowhere, odhs_xyz_write, ODHS_E_IO, NOALT, H_SYS2, 0, return odhs_xyz_write(w->sys2, NOWHERE);) \
    X(xyz_write_directory, odhs_xyz_write, ODHS_E_IO, NOALT, H_SYS3, 0, return odhs_xyz_write(w->sys3, w->dir);) \
    X(xyz_write_keeps_old, odhs_xyz_write, ODHS_E_IO, NOALT, H_SYS2, 0,                                        \
      /* a failed write (target is a directory) leaves the directory and no temporary behind */                \
      char sub[200]; snprintf(sub, sizeof sub, "%s/sub", w->dir);                                              \
      if (mkdir_p(sub)) return post("mkdir");                                                                  \
      int rc = odhs_xyz_write(w->sys2, sub); size_t nfiles = count_files(w->dir);                              \
      rmdir(sub);                                                                                              \
      return nfiles != 1 ? post("%zu entries left in the directory", nfiles) : rc;)                            \
    X(svg_null_sys, odhs_svg_write, ODHS_E_NULL, NOALT, H_NONE, 0,                                             \
      return odhs_svg_write(NULL, NULL, NULL, wpath(w, "a.svg"));)                                             \
    X(svg_null_path, odhs_svg_write, ODHS_E_NULL, NOALT, H_SYS2, 0, return odhs_svg_write(w->sys2, w->net2, NULL, NULL);) \
    X(svg_unset, odhs_svg_write, ODHS_E_STATE, NOALT, H_BARE, 0,                                               \
      return odhs_svg_write(w->bare, NULL, NULL, wpath(w, "a.svg"));)                                          \
    X(svg_dim_mismatch, odhs_svg_write, ODHS_E_DIM, NOALT, H_SYS3, 0,                                          \
      return odhs_svg_write(w->sys3, w->net2, NULL, wpath(w, "a.svg"));)                                       \
    X(svg_n_mismatch, odhs_svg_write, ODHS_E_DIM, NOALT, H_SYS8, 0,                                            \
      return odhs_svg_write(w->sys8, w->net2, NULL, wpath(w, "a.svg"));)                                       \
    X(svg_nowhere, odhs_svg_write, ODHS_E_IO, NOALT, H_SYS2, 0, return odhs_svg_write(w->sys2, NULL, NULL, NOWHERE);)

/* ---- network.h --------------------------------------------------------------- */
#define NETWORK_CASES(X)                                                                                       \
    X(net_create_null_out, odhs_network_create, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_network_create(w->sys2, NULL);) \
    X(net_create_null_sys, odhs_network_create, ODHS_E_NULL, NOALT, H_NONE, 0,                                 \
      odhs_network *n = POISON_PTR(odhs_network); int rc = odhs_network_create(NULL, &n);                      \
      return n ? post("*out not NULL") : rc;)                                                                  \
    X(net_destroy_null, odhs_network_destroy, ODHS_OK, NOALT, H_NONE, 0, odhs_network_destroy(NULL); return ODHS_OK;) \
    X(net_errmsg_null, odhs_network_errmsg, ODHS_OK, NOALT, H_NONE, 0,                                         \
      const char *m = odhs_network_errmsg(NULL); return m && !m[0] ? ODHS_OK : post("errmsg(NULL)");)          \
    X(net_add_null, odhs_network_add, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_network_add(NULL, 0, 1, 0);)  \
    X(net_bond_null, odhs_network_add_bond, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_network_add_bond(NULL, 0, 1, 1.0);) \
    X(net_bond_range, odhs_network_add_bond, ODHS_E_RANGE, NOALT, H_NET2, 0,                                   \
      return odhs_network_add_bond(w->net2, 0, 16, 1.0);)                                                      \
    X(net_bond_self, odhs_network_add_bond, ODHS_E_INVALID, NOALT, H_NET2, 0,                                  \
      return odhs_network_add_bond(w->net2, 1, 1, 1.0);)                                                       \
    X(net_bond_zero, odhs_network_add_bond, ODHS_E_INVALID, NOALT, H_NET3, 0,                                  \
      return odhs_network_add_bond(w->net3, 0, 1, 0.0);)                                                       \
    X(net_bond_nan, odhs_network_add_bond, ODHS_E_NONFINITE, NOALT, H_NET3, 0,                                 \
      return odhs_network_add_bond(w->net3, 0, 1, NAN_);)                                                      \
    X(net_bond_inf, odhs_network_add_bond, ODHS_E_NONFINITE, NOALT, H_NET3, 0,                                 \
      return odhs_network_add_bond(w->net3, 0, 1, INF_);)                                                      \
    X(net_rest_null, odhs_network_get_rest_length, ODHS_E_NULL, NOALT, H_NONE, 0,                              \
      double v; return odhs_network_get_rest_length(NULL, w->sys2, 0, &v);)                                    \
    X(net_rest_null_out, odhs_network_get_rest_length, ODHS_E_NULL, NOALT, H_NET2, 0,                          \
      return odhs_network_get_rest_length(w->net2, w->sys2, 0, NULL);)                                         \
    X(net_rest_null_sys, odhs_network_get_rest_length, ODHS_E_NULL, NOALT, H_NET2, 0,                          \
      double v; return odhs_network_get_rest_length(w->net2, NULL, 0, &v);)                                    \
    X(net_rest_range, odhs_network_get_rest_length, ODHS_E_RANGE, NOALT, H_NET2, 0,                            \
      double v; return odhs_network_get_rest_length(w->net2, w->sys2, 100000, &v);)                            \
    X(net_rest_dim, odhs_network_get_rest_length, ODHS_E_DIM, NOALT, H_NET2, 0,                                \
      double v; return odhs_network_get_rest_length(w->net2, w->sys3, 0, &v);)                                 \
    X(net_add_range_i, odhs_network_add, ODHS_E_RANGE, NOALT, H_NET2, 0, return odhs_network_add(w->net2, 16, 1, 0);) \
    X(net_add_range_j, odhs_network_add, ODHS_E_RANGE, NOALT, H_NET3, 0, return odhs_network_add(w->net3, 0, SIZE_MAX, 0);) \
    X(net_add_self, odhs_network_add, ODHS_E_INVALID, NOALT, H_NET2, 0, return odhs_network_add(w->net2, 3, 3, 0);) \
    X(net_add_bad_kind, odhs_network_add, ODHS_E_INVALID, NOALT, H_NET3, 0, return odhs_network_add(w->net3, 0, 1, 2);) \
    X(net_add_neg_kind, odhs_network_add, ODHS_E_INVALID, NOALT, H_NET3, 0, return odhs_network_add(w->net3, 0, 1, -1);) \
    X(net_add_duplicate, odhs_network_add, ODHS_E_INVALID, NOALT, H_NET2, 0,                                   \
      size_t i, j; odhs_network_get_contact(w->net2, 0, &i, &j, NULL); return odhs_network_add(w->net2, i, j, 0);) \
    X(net_add_duplicate_swapped, odhs_network_add, ODHS_E_INVALID, NOALT, H_NET2, 0,                           \
      size_t i, j; odhs_network_get_contact(w->net2, 0, &i, &j, NULL); return odhs_network_add(w->net2, j, i, 1);) \
    X(net_remove_null, odhs_network_remove, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_network_remove(NULL, 0, 1);) \
    X(net_remove_range, odhs_network_remove, ODHS_E_RANGE, NOALT, H_NET2, 0, return odhs_network_remove(w->net2, 0, 16);) \
    X(net_remove_absent, odhs_network_remove, ODHS_E_INVALID, NOALT, H_NET3, 0, return odhs_network_remove(w->net3, 0, 1);) \
    X(net_remove_self, odhs_network_remove, ODHS_E_INVALID, NOALT, H_NET2, 0, return odhs_network_remove(w->net2, 2, 2);) \
    X(net_clear_null, odhs_network_clear, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_network_clear(NULL);)     \
    X(net_clear_empty, odhs_network_clear, ODHS_OK, NOALT, H_NONE, 0, return odhs_network_clear(w->net3);)     \
    X(net_find_null, odhs_network_find, ODHS_E_NULL, NOALT, H_NONE, 0,                                         \
      size_t k; return odhs_network_find(NULL, 0, 1, &k);)                                                     \
    X(net_find_null_out, odhs_network_find, ODHS_E_NULL, NOALT, H_NET2, 0, return odhs_network_find(w->net2, 0, 1, NULL);) \
    X(net_find_range, odhs_network_find, ODHS_E_RANGE, NOALT, H_NET2, 0,                                       \
      size_t k = 7; int rc = odhs_network_find(w->net2, 99, 1, &k); return k != 7 ? post("output written") : rc;) \
    X(net_detect_null, odhs_network_detect, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_network_detect(NULL, w->sys2, 0.1);) \
    X(net_detect_null_sys, odhs_network_detect, ODHS_E_NULL, NOALT, H_NET2, 0, return odhs_network_detect(w->net2, NULL, 0.1);) \
    X(net_detect_dim_mismatch, odhs_network_detect, ODHS_E_DIM, NOALT, H_NET2, 0,                              \
      return odhs_network_detect(w->net2, w->sys3, 0.1);)                                                      \
    X(net_detect_dim_mismatch3, odhs_network_detect, ODHS_E_DIM, NOALT, H_NET3, 0,                             \
      return odhs_network_detect(w->net3, w->sys2, 0.1);)                                                      \
    X(net_detect_n_mismatch, odhs_network_detect, ODHS_E_DIM, NOALT, H_NET2, 0,                                \
      return odhs_network_detect(w->net2, w->sys8, 0.1);)                                                      \
    X(net_detect_unset, odhs_network_detect, ODHS_E_STATE, NOALT, H_NET2, 0,                                   \
      return odhs_network_detect(w->net2, w->bare, 0.1);)                                                      \
    X(net_detect_tol_negative, odhs_network_detect, ODHS_E_INVALID, NOALT, H_NET2, 0,                          \
      return odhs_network_detect(w->net2, w->sys2, -0.1);)                                                     \
    X(net_detect_tol_nan, odhs_network_detect, ODHS_E_NONFINITE, ODHS_E_INVALID, H_NET2, 0,                    \
      return odhs_network_detect(w->net2, w->sys2, NAN_);)                                                     \
    X(net_detect_tol_inf, odhs_network_detect, ODHS_E_NONFINITE, ODHS_E_INVALID, H_NET3, 0,                    \
      return odhs_network_detect(w->net3, w->sys3, INF_);)                                                     \
    X(net_geom_null, odhs_network_update_geometry, ODHS_E_NULL, NOALT, H_NONE, 0,                              \
      return odhs_network_update_geometry(NULL, w->sys2);)                                                     \
    X(net_geom_null_sys, odhs_network_update_geometry, ODHS_E_NULL, NOALT, H_NET2, 0,                          \
      return odhs_network_update_geometry(w->net2, NULL);)                                                     \
    X(net_geom_dim_mismatch, odhs_network_update_geometry, ODHS_E_DIM, NOALT, H_NET2, 0,                       \
      return odhs_network_update_geometry(w->net2, w->sys3);)                                                  \
    X(net_geom_n_mismatch, odhs_network_update_geometry, ODHS_E_DIM, NOALT, H_NET2, 0,                         \
      return odhs_network_update_geometry(w->net2, w->sys8);)                                                  \
    X(net_geom_unset, odhs_network_update_geometry, ODHS_E_STATE, NOALT, H_NET2, 0,                            \
      return odhs_network_update_geometry(w->net2, w->bare);)                                                  \
    X(net_count_null, odhs_network_count, ODHS_OK, NOALT, H_NONE, 0,                                           \
      return odhs_network_count(NULL) == 0 ? ODHS_OK : post("count(NULL)");)                                   \
    X(net_particles_null, odhs_network_particles, ODHS_OK, NOALT, H_NONE, 0,                                   \
      return odhs_network_particles(NULL) == 0 ? ODHS_OK : post("particles(NULL)");)                           \
    X(net_dim_null, odhs_network_dim, ODHS_OK, NOALT, H_NONE, 0,                                               \
      return odhs_network_dim(NULL) == 0 ? ODHS_OK : post("dim(NULL)");)                                       \
    X(net_contact_null, odhs_network_get_contact, ODHS_E_NULL, NOALT, H_NONE, 0,                               \
      size_t i, j; int k; return odhs_network_get_contact(NULL, 0, &i, &j, &k);)                               \
    X(net_contact_range, odhs_network_get_contact, ODHS_E_RANGE, NOALT, H_NET2, 0,                             \
      size_t i = 5; int rc = odhs_network_get_contact(w->net2, odhs_network_count(w->net2), &i, NULL, NULL);   \
      return i != 5 ? post("output written") : rc;)                                                            \
    X(net_contact_empty, odhs_network_get_contact, ODHS_E_RANGE, NOALT, H_NET3, 0,                             \
      return odhs_network_get_contact(w->net3, 0, NULL, NULL, NULL);)                                          \
    X(net_forces_null, odhs_network_get_forces, ODHS_E_NULL, NOALT, H_NONE, 0,                                 \
      double f[64]; return odhs_network_get_forces(NULL, f);)                                                  \
    X(net_forces_null_out, odhs_network_get_forces, ODHS_E_NULL, NOALT, H_NET2, 0,                             \
      return odhs_network_get_forces(w->net2, NULL);)                                                          \
    X(net_gaps_null, odhs_network_get_gaps, ODHS_E_NULL, NOALT, H_NONE, 0,                                     \
      double g[64]; return odhs_network_get_gaps(NULL, g);)                                                    \
    X(net_gaps_null_out, odhs_network_get_gaps, ODHS_E_NULL, NOALT, H_NET2, 0, return odhs_network_get_gaps(w->net2, NULL);) \
    X(net_normals_null, odhs_network_get_normals, ODHS_E_NULL, NOALT, H_NONE, 0,                               \
      double n[200]; return odhs_network_get_normals(NULL, n);)                                                \
    X(net_normals_null_out, odhs_network_get_normals, ODHS_E_NULL, NOALT, H_NET2, 0,                           \
      return odhs_network_get_normals(w->net2, NULL);)                                                         \
    X(net_set_forces_null, odhs_network_set_forces, ODHS_E_NULL, NOALT, H_NONE, 0,                             \
      double f[64] = {0}; return odhs_network_set_forces(NULL, f);)                                            \
    X(net_set_forces_null_f, odhs_network_set_forces, ODHS_E_NULL, NOALT, H_NET2, 0,                           \
      return odhs_network_set_forces(w->net2, NULL);)                                                          \
    X(net_set_forces_nan, odhs_network_set_forces, ODHS_E_NONFINITE, NOALT, H_NET2, 0,                         \
      double f[256]; for (int c = 0; c < 256; ++c) f[c] = 1.0;                                                 \
      f[odhs_network_count(w->net2) - 1] = NAN_; return odhs_network_set_forces(w->net2, f);)                  \
    X(net_set_forces_inf, odhs_network_set_forces, ODHS_E_NONFINITE, NOALT, H_NET2, 0,                         \
      double f[256]; for (int c = 0; c < 256; ++c) f[c] = -INF_; return odhs_network_set_forces(w->net2, f);)  \
    X(net_S_null, odhs_network_apply_S, ODHS_E_NULL, NOALT, H_NONE, 0,                                         \
      double v[32] = {0}, o[64]; return odhs_network_apply_S(NULL, v, o);)                                     \
    X(net_S_null_v, odhs_network_apply_S, ODHS_E_NULL, NOALT, H_NET2, 0,                                       \
      double o[256]; return odhs_network_apply_S(w->net2, NULL, o);)                                           \
    X(net_S_null_out, odhs_network_apply_S, ODHS_E_NULL, NOALT, H_NET2, 0,                                     \
      double v[32] = {0}; return odhs_network_apply_S(w->net2, v, NULL);)                                      \
    X(net_ST_null, odhs_network_apply_ST, ODHS_E_NULL, NOALT, H_NONE, 0,                                       \
      double f[64] = {0}, o[32]; return odhs_network_apply_ST(NULL, f, o);)                                    \
    X(net_ST_null_f, odhs_network_apply_ST, ODHS_E_NULL, NOALT, H_NET2, 0,                                     \
      double o[32]; return odhs_network_apply_ST(w->net2, NULL, o);)                                           \
    X(net_ST_null_out, odhs_network_apply_ST, ODHS_E_NULL, NOALT, H_NET2, 0,                                   \
      double f[256] = {0}; return odhs_network_apply_ST(w->net2, f, NULL);)                                    \
    X(net_N_null, odhs_network_apply_N, ODHS_E_NULL, NOALT, H_NONE, 0,                                         \
      double x[64] = {0}, o[64]; return odhs_network_apply_N(NULL, x, o, NULL);)                               \
    X(net_N_null_x, odhs_network_apply_N, ODHS_E_NULL, NOALT, H_NET2, 0,                                       \
      double o[256]; return odhs_network_apply_N(w->net2, NULL, o, NULL);)                                     \
    X(net_N_null_out, odhs_network_apply_N, ODHS_E_NULL, NOALT, H_NET2, 0,                                     \
      double x[256] = {0}; return odhs_network_apply_N(w->net2, x, NULL, NULL);)                               \
    X(net_nnz_null, odhs_network_nnz, ODHS_OK, NOALT, H_NONE, 0,                                               \
      return odhs_network_nnz(NULL) == 0 ? ODHS_OK : post("nnz(NULL)");)                                       \
    X(net_csr_null, odhs_network_get_S_csr, ODHS_E_NULL, NOALT, H_NONE, 0,                                     \
      size_t rp[300], c[2000]; double v[2000]; return odhs_network_get_S_csr(NULL, rp, c, v);)                 \
    X(net_csr_null_rowptr, odhs_network_get_S_csr, ODHS_E_NULL, NOALT, H_NET2, 0,                              \
      size_t c[2000]; double v[2000]; return odhs_network_get_S_csr(w->net2, NULL, c, v);)                     \
    X(net_csr_null_col, odhs_network_get_S_csr, ODHS_E_NULL, NOALT, H_NET2, 0,                                 \
      size_t rp[300]; double v[2000]; return odhs_network_get_S_csr(w->net2, rp, NULL, v);)                    \
    X(net_csr_null_val, odhs_network_get_S_csr, ODHS_E_NULL, NOALT, H_NET2, 0,                                 \
      size_t rp[300], c[2000]; return odhs_network_get_S_csr(w->net2, rp, c, NULL);)                           \
    X(net_z_null, odhs_network_coordination, ODHS_E_NULL, NOALT, H_NONE, 0,                                    \
      double z; return odhs_network_coordination(NULL, &z);)                                                   \
    X(net_z_null_out, odhs_network_coordination, ODHS_E_NULL, NOALT, H_NET2, 0,                                \
      return odhs_network_coordination(w->net2, NULL);)                                                        \
    X(net_constrained_null, odhs_network_constrained, ODHS_E_NULL, NOALT, H_NONE, 0,                           \
      size_t a, b; return odhs_network_constrained(NULL, &a, &b, NULL, NULL);)                                 \
    X(net_constrained_all_null, odhs_network_constrained, ODHS_OK, NOALT, H_NONE, 0,                           \
      return odhs_network_constrained(w->net2, NULL, NULL, NULL, NULL);)                                       \
    X(net_rattlers_null, odhs_network_rattlers, ODHS_E_NULL, NOALT, H_NONE, 0,                                 \
      size_t c; return odhs_network_rattlers(NULL, NULL, &c);)                                                 \
    X(net_rattlers_all_null, odhs_network_rattlers, ODHS_OK, NOALT, H_NONE, 0,                                 \
      return odhs_network_rattlers(w->net2, NULL, NULL);)                                                      \
    X(net_pj_null, odhs_network_potentially_jammed, ODHS_E_NULL, NOALT, H_NONE, 0,                             \
      int f; return odhs_network_potentially_jammed(NULL, &f);)                                                \
    X(net_pj_null_out, odhs_network_potentially_jammed, ODHS_E_NULL, NOALT, H_NET2, 0,                         \
      return odhs_network_potentially_jammed(w->net2, NULL);)                                                  \
    X(net_null_vector_null, odhs_network_null_vector, ODHS_E_NULL, NOALT, H_NONE, 0,                           \
      double f[64]; return odhs_network_null_vector(NULL, NULL, f, NULL);)                                     \
    X(net_null_vector_null_out, odhs_network_null_vector, ODHS_E_NULL, NOALT, H_NET2, 0,                       \
      return odhs_network_null_vector(w->net2, w->cg, NULL, NULL);)                                            \
    X(net_null_vector_not_jammed, odhs_network_null_vector, ODHS_E_STATE, NOALT, H_NET2, 0,                    \
      double f[256]; double res = -5; int rc = odhs_network_null_vector(w->net2, NULL, f, &res);               \
      return res != -5 ? post("residual written on error") : rc;)                                              \
    X(net_null_vector_empty, odhs_network_null_vector, ODHS_E_STATE, NOALT, H_NET3, 0,                         \
      double f[1]; return odhs_network_null_vector(w->net3, w->dense, f, NULL);)

/* ---- solver.h ----------------------------------------------------------------- */
#define SOLVER_CASES(X)                                                                                        \
    X(sol_create_null_out, odhs_solver_create, ODHS_E_NULL, NOALT, H_NONE, 0,                                  \
      return odhs_solver_create(&odhs_solver_type_cg, NULL);)                                                  \
    X(sol_create_null_type, odhs_solver_create, ODHS_E_NULL, NOALT, H_NONE, 0,                                 \
      odhs_solver *s = POISON_PTR(odhs_solver); int rc = odhs_solver_create(NULL, &s);                         \
      return s ? post("*out not NULL") : rc;)                                                                  \
    X(sol_create_version0, odhs_solver_create, ODHS_E_INVALID, NOALT, H_NONE, 0, UB_TRY(version, 0);) \
    X(sol_create_version_future, odhs_solver_create, ODHS_E_INVALID, NOALT, H_NONE, 0,                         \
      UB_TRY(version, ODHS_SOLVER_TYPE_VERSION + 1);)                                      \
    X(sol_create_no_name, odhs_solver_create, ODHS_E_INVALID, NOALT, H_NONE, 0, UB_TRY(name, NULL);) \
    X(sol_create_no_create, odhs_solver_create, ODHS_E_INVALID, NOALT, H_NONE, 0, UB_TRY(create, NULL);) \
    X(sol_create_no_destroy, odhs_solver_create, ODHS_E_INVALID, NOALT, H_NONE, 0, UB_TRY(destroy, NULL);) \
    X(sol_create_no_solve, odhs_solver_create, ODHS_E_INVALID, NOALT, H_NONE, 0, UB_TRY(solve, NULL);) \
    X(sol_create_backend_nomem, odhs_solver_create, ODHS_E_NOMEM, NOALT, H_NONE, 0,                            \
      UB_TRY(create, ub_create_nomem);)                                                    \
    X(sol_create_backend_positive, odhs_solver_create, ODHS_E_INTERNAL, NOALT, H_NONE, 0,                      \
      UB_TRY(create, ub_create_positive);)                                                 \
    X(sol_create_v1_ok, odhs_solver_create, ODHS_OK, NOALT, H_NONE, 0, UB_TRY(version, 1);) \
    X(sol_by_name_null_name, odhs_solver_create_by_name, ODHS_E_NULL, NOALT, H_NONE, 0,                        \
      odhs_solver *s = POISON_PTR(odhs_solver); int rc = odhs_solver_create_by_name(NULL, &s);                 \
      return s ? post("*out not NULL") : rc;)                                                                  \
    X(sol_by_name_null_out, odhs_solver_create_by_name, ODHS_E_NULL, NOALT, H_NONE, 0,                         \
      return odhs_solver_create_by_name("cg", NULL);)                                                          \
    X(sol_by_name_empty, odhs_solver_create_by_name, ODHS_E_INVALID, NOALT, H_NONE, 0,                         \
      odhs_solver *s = POISON_PTR(odhs_solver); int rc = odhs_solver_create_by_name("", &s);                   \
      return s ? post("*out not NULL") : rc;)                                                                  \
    X(sol_by_name_unknown, odhs_solver_create_by_name, ODHS_E_INVALID, NOALT, H_NONE, 0,                       \
      odhs_solver *s = POISON_PTR(odhs_solver); int rc = odhs_solver_create_by_name("no-such-solver", &s);     \
      return s ? post("*out not NULL") : rc;)                                                                  \
    X(sol_by_name_prefix, odhs_solver_create_by_name, ODHS_E_INVALID, NOALT, H_NONE, 0,                        \
      odhs_solver *s = NULL; int rc = odhs_solver_create_by_name("cg ", &s); odhs_solver_destroy(s); return rc;) \
    X(sol_destroy_null, odhs_solver_destroy, ODHS_OK, NOALT, H_NONE, 0, odhs_solver_destroy(NULL); return ODHS_OK;) \
    X(sol_errmsg_null, odhs_solver_errmsg, ODHS_OK, NOALT, H_NONE, 0,                                          \
      const char *m = odhs_solver_errmsg(NULL); return m && !m[0] ? ODHS_OK : post("errmsg(NULL)");)           \
    X(sol_name_null, odhs_solver_name, ODHS_OK, NOALT, H_NONE, 0,                                              \
      const char *m = odhs_solver_name(NULL); return m ? ODHS_OK : post("name(NULL) is NULL");)                \
    X(sol_backend_null, odhs_solver_backend_name, ODHS_E_NULL, NOALT, H_NONE, 0,                               \
      const char *nm = NULL; return odhs_solver_backend_name(NULL, &nm, NULL);)                                 \
    X(sol_backend_null_name, odhs_solver_backend_name, ODHS_E_NULL, NOALT, H_CG, 0,                            \
      const char *why = NULL; return odhs_solver_backend_name(w->cg, NULL, &why);)                              \
    X(sol_backend_auto_param, odhs_solver_set_param, ODHS_E_INVALID, NOALT, H_NONE, 0,                         \
      odhs_solver *s = NULL; int rc = odhs_solver_create_by_name("auto", &s); if (rc) return post("create %d", rc); \
      rc = odhs_solver_set_param(s, "prefer", 2.0); const char *nm = NULL;                                     \
      if (odhs_solver_backend_name(s, &nm, NULL) || strcmp(nm, "auto")) rc = post("backend name changed");     \
      odhs_solver_destroy(s); return rc;)                                                                      \
    X(sol_param_null, odhs_solver_set_param, ODHS_E_NULL, NOALT, H_NONE, 0,                                    \
      return odhs_solver_set_param(NULL, "tol", 1e-10);)                                                       \
    X(sol_param_null_key, odhs_solver_set_param, ODHS_E_NULL, NOALT, H_CG, 0,                                  \
      return odhs_solver_set_param(w->cg, NULL, 1e-10);)                                                       \
    X(sol_param_unknown, odhs_solver_set_param, ODHS_E_INVALID, NOALT, H_CG, 0,                                \
      return odhs_solver_set_param(w->cg, "no-such-param", 1.0);)                                              \
    X(sol_param_nan, odhs_solver_set_param, ODHS_E_NONFINITE, NOALT, H_CG, 0,                                  \
      return odhs_solver_set_param(w->cg, "tol", NAN_);)                                                       \
    X(sol_param_inf, odhs_solver_set_param, ODHS_E_NONFINITE, NOALT, H_DENSE, 0,                               \
      return odhs_solver_set_param(w->dense, "min_rcond", INF_);)                                              \
    X(sol_param_bad_value, odhs_solver_set_param, ODHS_E_INVALID, NOALT, H_CG, 0,                              \
      return odhs_solver_set_param(w->cg, "tol", -1.0);)                                                       \
    X(sol_param_bad_value_dense, odhs_solver_set_param, ODHS_E_INVALID, NOALT, H_DENSE, 0,                     \
      return odhs_solver_set_param(w->dense, "min_rcond", 2.0);)                                               \
    X(sol_param_no_params, odhs_solver_set_param, ODHS_E_INVALID, NOALT, H_NONE, 0,                            \
      odhs_solver_type t = ub_type(); odhs_solver *s = NULL;                                       \
      int rc = odhs_solver_create(&t, &s); if (rc) return post("create %d", rc);                               \
      rc = odhs_solver_set_param(s, "tol", 1.0);                                                               \
      if (rc < 0 && !odhs_solver_errmsg(s)[0]) rc = post("no message");                                        \
      odhs_solver_destroy(s); return rc;)                                                                      \
    X(sol_stat_null, odhs_solver_get_stat, ODHS_E_NULL, NOALT, H_NONE, 0,                                      \
      double v; return odhs_solver_get_stat(NULL, "solves", &v);)                                              \
    X(sol_stat_null_key, odhs_solver_get_stat, ODHS_E_NULL, NOALT, H_CG, 0,                                    \
      double v; return odhs_solver_get_stat(w->cg, NULL, &v);)                                                 \
    X(sol_stat_null_out, odhs_solver_get_stat, ODHS_E_NULL, NOALT, H_DENSE, 0,                                 \
      return odhs_solver_get_stat(w->dense, "solves", NULL);)                                                  \
    X(sol_stat_unknown, odhs_solver_get_stat, ODHS_E_INVALID, NOALT, H_CG, 0,                                  \
      double v = 3; int rc = odhs_solver_get_stat(w->cg, "no-such-stat", &v);                                  \
      return v != 3 ? post("output written") : rc;)                                                            \
    X(sol_checktol_null, odhs_solver_set_check_tolerance, ODHS_E_NULL, NOALT, H_NONE, 0,                       \
      return odhs_solver_set_check_tolerance(NULL, 1e-6);)                                                     \
    X(sol_checktol_zero, odhs_solver_set_check_tolerance, ODHS_E_INVALID, NOALT, H_CG, 0,                      \
      return odhs_solver_set_check_tolerance(w->cg, 0.0);)                                                     \
    X(sol_checktol_negative, odhs_solver_set_check_tolerance, ODHS_E_INVALID, NOALT, H_DENSE, 0,               \
      return odhs_solver_set_check_tolerance(w->dense, -1e-6);)                                                \
    X(sol_checktol_nan, odhs_solver_set_check_tolerance, ODHS_E_NONFINITE, ODHS_E_INVALID, H_CG, 0,            \
      return odhs_solver_set_check_tolerance(w->cg, NAN_);)                                                    \
    X(sol_checktol_inf, odhs_solver_set_check_tolerance, ODHS_E_NONFINITE, ODHS_E_INVALID, H_CG, 0,            \
      return odhs_solver_set_check_tolerance(w->cg, INF_);)                                                    \
    X(sol_refine_null, odhs_solver_set_refinement, ODHS_E_NULL, NOALT, H_NONE, 0,                              \
      return odhs_solver_set_refinement(NULL, 2);)                                                             \
    X(sol_refine_negative, odhs_solver_set_refinement, ODHS_E_INVALID, NOALT, H_DENSE, 0,                      \
      return odhs_solver_set_refinement(w->dense, -1);)                                                        \
    X(sol_refine_huge, odhs_solver_set_refinement, ODHS_E_INVALID, NOALT, H_DENSE, 0,                          \
      return odhs_solver_set_refinement(w->dense, INT_MAX);)                                                   \
    X(sol_fallback_null, odhs_solver_set_fallback, ODHS_E_NULL, NOALT, H_NONE, 0,                              \
      return odhs_solver_set_fallback(NULL, w->dense);)                                                        \
    X(sol_fallback_self, odhs_solver_set_fallback, ODHS_E_INVALID, NOALT, H_CG, 0,                             \
      return odhs_solver_set_fallback(w->cg, w->cg);)                                                          \
    X(sol_fallback_cycle, odhs_solver_set_fallback, ODHS_E_INVALID, NOALT, H_DENSE, 0,                         \
      odhs_solver *a_ = NULL; int rc = odhs_solver_create_by_name("cg", &a_); if (rc) return rc;                \
      rc = odhs_solver_set_fallback(a_, w->dense); if (rc == ODHS_OK) rc = odhs_solver_set_fallback(w->dense, a_); \
      if (rc < 0 && !odhs_solver_errmsg(w->dense)[0]) rc = post("no message");                                 \
      odhs_solver_destroy(a_); return rc;)                                                                     \
    X(sol_solve_null, odhs_solver_solve, ODHS_E_NULL, NOALT, H_NONE, 0,                                        \
      double b[256] = {1}, x[256] = {0}; return odhs_solver_solve(NULL, odhs_stepper_network(w->run), b, x);)  \
    X(sol_solve_null_net, odhs_solver_solve, ODHS_E_NULL, NOALT, H_CG, 0,                                      \
      double b[256] = {1}, x[256] = {0}; return odhs_solver_solve(w->cg, NULL, b, x);)                         \
    X(sol_solve_null_b, odhs_solver_solve, ODHS_E_NULL, NOALT, H_DENSE, 0,                                     \
      double x[256] = {0}; return odhs_solver_solve(w->dense, odhs_stepper_network(w->run), NULL, x);)         \
    X(sol_solve_null_x, odhs_solver_solve, ODHS_E_NULL, NOALT, H_CG, 0,                                        \
      double b[256] = {1}; return odhs_solver_solve(w->cg, odhs_stepper_network(w->run), b, NULL);)            \
    X(sol_solve_nan_b, odhs_solver_solve, ODHS_E_NONFINITE, NOALT, H_DENSE, 0,                                 \
      double b[256], x[256] = {0}; for (int c = 0; c < 256; ++c) b[c] = 1.0; b[0] = NAN_;                      \
      return odhs_solver_solve(w->dense, odhs_stepper_network(w->run), b, x);)                                 \
    X(sol_solve_inf_b, odhs_solver_solve, ODHS_E_NONFINITE, NOALT, H_CG, 0,                                    \
      double b[256], x[256] = {0}; for (int c = 0; c < 256; ++c) b[c] = 1.0;                                   \
      b[odhs_network_count(odhs_stepper_network(w->run)) - 1] = INF_;                                          \
      return odhs_solver_solve(w->cg, odhs_stepper_network(w->run), b, x);)                                    \
    X(sol_ls_null, odhs_solver_solve_ls, ODHS_E_NULL, NOALT, H_NONE, 0,                                        \
      double g[64] = {0}, x[256]; return odhs_solver_solve_ls(NULL, odhs_stepper_network(w->run), g, x);)      \
    X(sol_ls_null_net, odhs_solver_solve_ls, ODHS_E_NULL, NOALT, H_CG, 0,                                      \
      double g[64] = {0}, x[256]; return odhs_solver_solve_ls(w->cg, NULL, g, x);)                             \
    X(sol_ls_null_g, odhs_solver_solve_ls, ODHS_E_NULL, NOALT, H_DENSE, 0,                                     \
      double x[256]; return odhs_solver_solve_ls(w->dense, odhs_stepper_network(w->run), NULL, x);)            \
    X(sol_ls_null_x, odhs_solver_solve_ls, ODHS_E_NULL, NOALT, H_CG, 0,                                        \
      double g[64] = {0}; return odhs_solver_solve_ls(w->cg, odhs_stepper_network(w->run), g, NULL);)          \
    X(sol_ls_nan_g, odhs_solver_solve_ls, ODHS_E_NONFINITE, NOALT, H_DENSE, 0,                                 \
      double g[64], x[256]; for (int k = 0; k < 64; ++k) g[k] = 0.1 * k; g[31] = NAN_;                         \
      return odhs_solver_solve_ls(w->dense, odhs_stepper_network(w->run), g, x);)

/* ---- driver.h ----------------------------------------------------------------- */
#define DRIVER_CASES(X)                                                                                        \
    X(drv_create_null, odhs_driver_create, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_driver_create(NULL);)    \
    X(drv_destroy_null, odhs_driver_destroy, ODHS_OK, NOALT, H_NONE, 0, odhs_driver_destroy(NULL); return ODHS_OK;) \
    X(drv_errmsg_null, odhs_driver_errmsg, ODHS_OK, NOALT, H_NONE, 0,                                          \
      const char *m = odhs_driver_errmsg(NULL); return m && !m[0] ? ODHS_OK : post("errmsg(NULL)");)           \
    X(drv_mobility_null, odhs_driver_set_mobility, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_driver_set_mobility(NULL, 1.0);) \
    X(drv_mobility_nan, odhs_driver_set_mobility, ODHS_E_NONFINITE, NOALT, H_DRV, 0,                           \
      return odhs_driver_set_mobility(w->drv, NAN_);)                                                          \
    X(drv_mobility_inf, odhs_driver_set_mobility, ODHS_E_NONFINITE, NOALT, H_DRV, 0,                           \
      return odhs_driver_set_mobility(w->drv, INF_);)                                                          \
    X(drv_mobility_zero, odhs_driver_set_mobility, ODHS_E_INVALID, NOALT, H_DRV, 0,                            \
      return odhs_driver_set_mobility(w->drv, 0.0);)                                                           \
    X(drv_mobility_negative, odhs_driver_set_mobility, ODHS_E_INVALID, NOALT, H_DRVR, 0,                       \
      return odhs_driver_set_mobility(w->drvr, -2.0);)                                                         \
    X(drv_shear_null, odhs_driver_set_shear_rate, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_driver_set_shear_rate(NULL, 1.0);) \
    X(drv_shear_nan, odhs_driver_set_shear_rate, ODHS_E_NONFINITE, NOALT, H_DRV, 0,                            \
      return odhs_driver_set_shear_rate(w->drv, NAN_);)                                                        \
    X(drv_shear_inf, odhs_driver_set_shear_rate, ODHS_E_NONFINITE, NOALT, H_DRVR, 0,                           \
      return odhs_driver_set_shear_rate(w->drvr, -INF_);)                                                      \
    X(drv_comp_null, odhs_driver_set_compression_rate, ODHS_E_NULL, NOALT, H_NONE, 0,                          \
      return odhs_driver_set_compression_rate(NULL, 1.0);)                                                     \
    X(drv_comp_nan, odhs_driver_set_compression_rate, ODHS_E_NONFINITE, NOALT, H_DRV, 0,                       \
      return odhs_driver_set_compression_rate(w->drv, NAN_);)                                                  \
    X(drv_comp_inf, odhs_driver_set_compression_rate, ODHS_E_NONFINITE, NOALT, H_DRV, 0,                       \
      return odhs_driver_set_compression_rate(w->drv, INF_);)                                                  \
    X(drv_pressure_null, odhs_driver_set_pressure, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_driver_set_pressure(NULL, 1.0);) \
    X(drv_pressure_nan, odhs_driver_set_pressure, ODHS_E_NONFINITE, NOALT, H_DRV, 0,                           \
      return odhs_driver_set_pressure(w->drv, NAN_);)                                                          \
    X(drv_pressure_zero, odhs_driver_set_pressure, ODHS_E_INVALID, NOALT, H_DRV, 0,                            \
      return odhs_driver_set_pressure(w->drv, 0.0);)                                                           \
    X(drv_pressure_negative, odhs_driver_set_pressure, ODHS_E_INVALID, NOALT, H_DRVR, 0,                       \
      return odhs_driver_set_pressure(w->drvr, -1.0);)                                                         \
    X(drv_clear_pressure_null, odhs_driver_clear_pressure, ODHS_E_NULL, NOALT, H_NONE, 0,                      \
      return odhs_driver_clear_pressure(NULL);)                                                                \
    X(drv_clear_pressure_off, odhs_driver_clear_pressure, ODHS_OK, NOALT, H_NONE, 0,                           \
      return odhs_driver_clear_pressure(w->drv);)                                                              \
    X(drv_kmax_null, odhs_driver_set_kappa_max, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_driver_set_kappa_max(NULL, 10.0);) \
    X(drv_kmax_nan, odhs_driver_set_kappa_max, ODHS_E_NONFINITE, NOALT, H_DRV, 0,                              \
      return odhs_driver_set_kappa_max(w->drv, NAN_);)                                                         \
    X(drv_kmax_zero, odhs_driver_set_kappa_max, ODHS_E_INVALID, NOALT, H_DRV, 0,                               \
      return odhs_driver_set_kappa_max(w->drv, 0.0);)                                                          \
    X(drv_pjam_null, odhs_driver_set_jamming_pressure, ODHS_E_NULL, NOALT, H_NONE, 0,                          \
      return odhs_driver_set_jamming_pressure(NULL, 1.0);)                                                     \
    X(drv_pjam_nan, odhs_driver_set_jamming_pressure, ODHS_E_NONFINITE, NOALT, H_DRV, 0,                       \
      return odhs_driver_set_jamming_pressure(w->drv, NAN_);)                                                  \
    X(drv_pjam_negative, odhs_driver_set_jamming_pressure, ODHS_E_INVALID, NOALT, H_DRV, 0,                    \
      return odhs_driver_set_jamming_pressure(w->drv, -1.0);)                                                  \
    X(drv_get_pjam_null, odhs_driver_get_jamming_pressure, ODHS_E_NULL, NOALT, H_NONE, 0,                      \
      double v; return odhs_driver_get_jamming_pressure(NULL, &v);)                                            \
    X(drv_get_pjam_null_out, odhs_driver_get_jamming_pressure, ODHS_E_NULL, NOALT, H_DRV, 0,                   \
      return odhs_driver_get_jamming_pressure(w->drv, NULL);)                                                  \
    X(drv_forces_null, odhs_driver_set_forces, ODHS_E_NULL, NOALT, H_NONE, 0,                                  \
      double F[32] = {0}; return odhs_driver_set_forces(NULL, 16, 2, F);)                                      \
    X(drv_forces_dim1, odhs_driver_set_forces, ODHS_E_DIM, NOALT, H_DRV, 0,                                    \
      double F[32] = {0}; return odhs_driver_set_forces(w->drv, 16, 1, F);)                                    \
    X(drv_forces_dim4, odhs_driver_set_forces, ODHS_E_DIM, NOALT, H_DRV, 0,                                    \
      double F[64] = {0}; return odhs_driver_set_forces(w->drv, 16, 4, F);)                                    \
    X(drv_forces_n0, odhs_driver_set_forces, ODHS_E_EMPTY, NOALT, H_DRV, 0,                                    \
      double F[2] = {0}; return odhs_driver_set_forces(w->drv, 0, 2, F);)                                      \
    X(drv_forces_nan, odhs_driver_set_forces, ODHS_E_NONFINITE, NOALT, H_DRV, 0,                               \
      double F[32] = {0}; F[17] = NAN_; return odhs_driver_set_forces(w->drv, 16, 2, F);)                      \
    X(drv_forces_inf, odhs_driver_set_forces, ODHS_E_NONFINITE, NOALT, H_DRVR, 0,                              \
      double F[32] = {0}; F[0] = INF_; return odhs_driver_set_forces(w->drvr, 16, 2, F);)                      \
    X(drv_forces_remove_none, odhs_driver_set_forces, ODHS_OK, NOALT, H_NONE, 0,                               \
      return odhs_driver_set_forces(w->drv, 0, 0, NULL);)                                                      \
    X(drv_forces_wrong_n_for_stepper, odhs_driver_set_forces, ODHS_E_DIM, NOALT, H_ST, 0,                      \
      /* forces for another N are accepted by the driver and rejected by the stepper */                        \
      double F[24] = {0}; F[0] = 1.0; int rc = odhs_driver_set_forces(w->drv, 12, 2, F);                       \
      if (rc) return post("set_forces %d", rc);                                                                \
      rc = odhs_stepper_reset(w->st); odhs_driver_set_forces(w->drv, 0, 0, NULL); return rc;)                  \
    X(drv_forces_wrong_dim_for_stepper, odhs_driver_set_forces, ODHS_E_DIM, NOALT, H_ST, 0,                    \
      double F[48] = {0}; F[0] = 1.0; int rc = odhs_driver_set_forces(w->drv, 16, 3, F);                       \
      if (rc) return post("set_forces %d", rc);                                                                \
      rc = odhs_stepper_step(w->st, NULL); odhs_driver_set_forces(w->drv, 0, 0, NULL); return rc;)             \
    X(drv_callback_null, odhs_driver_set_force_callback, ODHS_E_NULL, NOALT, H_NONE, 0,                        \
      return odhs_driver_set_force_callback(NULL, force_nan, NULL);)                                           \
    X(drv_callback_remove_none, odhs_driver_set_force_callback, ODHS_OK, NOALT, H_NONE, 0,                     \
      return odhs_driver_set_force_callback(w->drv, NULL, NULL);)                                              \
    X(drv_callback_nan, odhs_driver_set_force_callback, ODHS_E_CALLBACK, NOALT, H_RUN, 0,                      \
      /* a callback returning NaN fails the step, which is rolled back */                                      \
      int rc = odhs_driver_set_force_callback(w->drvr, force_nan, NULL);                                       \
      if (rc) return post("set callback %d", rc);                                                              \
      rc = odhs_stepper_step(w->run, NULL); odhs_driver_set_force_callback(w->drvr, NULL, NULL); return rc;)   \
    X(drv_callback_fail, odhs_driver_set_force_callback, ODHS_E_CALLBACK, NOALT, H_RUN, 0,                     \
      int rc = odhs_driver_set_force_callback(w->drvr, force_fail, NULL);                                      \
      if (rc) return post("set callback %d", rc);                                                              \
      rc = odhs_stepper_run_until_time(w->run, 1.0); odhs_driver_set_force_callback(w->drvr, NULL, NULL); return rc;) \
    X(drv_tau_null, odhs_driver_set_time_unit, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_driver_set_time_unit(NULL, 1.0);) \
    X(drv_tau_nan, odhs_driver_set_time_unit, ODHS_E_NONFINITE, NOALT, H_DRV, 0,                               \
      return odhs_driver_set_time_unit(w->drv, NAN_);)                                                         \
    X(drv_tau_zero, odhs_driver_set_time_unit, ODHS_E_INVALID, NOALT, H_DRV, 0,                                \
      return odhs_driver_set_time_unit(w->drv, 0.0);)                                                          \
    X(drv_tau_negative, odhs_driver_set_time_unit, ODHS_E_INVALID, NOALT, H_DRV, 0,                            \
      return odhs_driver_set_time_unit(w->drv, -1.0);)                                                         \
    X(drv_get_shear_null, odhs_driver_get_shear_rate, ODHS_E_NULL, NOALT, H_NONE, 0,                           \
      double g; return odhs_driver_get_shear_rate(NULL, &g);)                                                  \
    X(drv_get_shear_null_out, odhs_driver_get_shear_rate, ODHS_E_NULL, NOALT, H_DRV, 0,                        \
      return odhs_driver_get_shear_rate(w->drv, NULL);)                                                        \
    X(drv_get_comp_null, odhs_driver_get_compression_rate, ODHS_E_NULL, NOALT, H_NONE, 0,                      \
      double c; return odhs_driver_get_compression_rate(NULL, &c);)                                            \
    X(drv_get_comp_null_out, odhs_driver_get_compression_rate, ODHS_E_NULL, NOALT, H_DRV, 0,                   \
      return odhs_driver_get_compression_rate(w->drv, NULL);)                                                  \
    X(drv_get_mob_null, odhs_driver_get_mobility, ODHS_E_NULL, NOALT, H_NONE, 0,                               \
      double m; return odhs_driver_get_mobility(NULL, &m);)                                                    \
    X(drv_get_mob_null_out, odhs_driver_get_mobility, ODHS_E_NULL, NOALT, H_DRVR, 0,                           \
      return odhs_driver_get_mobility(w->drvr, NULL);)                                                         \
    X(drv_get_p_null, odhs_driver_get_pressure, ODHS_E_NULL, NOALT, H_NONE, 0,                                 \
      double p; int e; return odhs_driver_get_pressure(NULL, &p, &e);)                                         \
    X(drv_get_p_null_p, odhs_driver_get_pressure, ODHS_E_NULL, NOALT, H_DRV, 0,                                \
      int e; return odhs_driver_get_pressure(w->drv, NULL, &e);)                                               \
    X(drv_get_p_null_enabled, odhs_driver_get_pressure, ODHS_E_NULL, NOALT, H_DRV, 0,                          \
      double p; return odhs_driver_get_pressure(w->drv, &p, NULL);)                                            \
    X(drv_time_unit_null, odhs_driver_time_unit, ODHS_E_NULL, NOALT, H_NONE, 0,                                \
      double t; return odhs_driver_time_unit(NULL, w->sys2, &t);)                                              \
    X(drv_time_unit_null_sys, odhs_driver_time_unit, ODHS_E_NULL, NOALT, H_DRV, 0,                             \
      double t; return odhs_driver_time_unit(w->drv, NULL, &t);)                                               \
    X(drv_time_unit_null_out, odhs_driver_time_unit, ODHS_E_NULL, NOALT, H_DRV, 0,                             \
      return odhs_driver_time_unit(w->drv, w->sys2, NULL);)                                                    \
    X(drv_time_unit_unset, odhs_driver_time_unit, ODHS_E_STATE, NOALT, H_DRV, 0,                               \
      double t = 5; int rc = odhs_driver_time_unit(w->drv, w->bare, &t);                                       \
      return t != 5 ? post("output written") : rc;)                                                            \
    X(sp_null, odhs_driver_set_self_propulsion, ODHS_E_NULL, NOALT, H_NONE, 0,                                 \
      return odhs_driver_set_self_propulsion(NULL, 16, 2, 0.5, 1.0, 0.0, 1.0, 1);)                             \
    X(sp_dim1, odhs_driver_set_self_propulsion, ODHS_E_DIM, NOALT, H_DRV, 0,                                   \
      return odhs_driver_set_self_propulsion(w->drv, 16, 1, 0.5, 1.0, 0.0, 1.0, 1);)                           \
    X(sp_dim4, odhs_driver_set_self_propulsion, ODHS_E_DIM, NOALT, H_DRV, 0,                                   \
      return odhs_driver_set_self_propulsion(w->drv, 16, 4, 0.5, 1.0, 0.0, 1.0, 1);)                           \
    X(sp_n0, odhs_driver_set_self_propulsion, ODHS_E_EMPTY, NOALT, H_DRV, 0,                                   \
      return odhs_driver_set_self_propulsion(w->drv, 0, 2, 0.5, 1.0, 0.0, 1.0, 1);)                            \
    X(sp_fmin_nan, odhs_driver_set_self_propulsion, ODHS_E_NONFINITE, NOALT, H_DRV, 0,                         \
      return odhs_driver_set_self_propulsion(w->drv, 16, 2, NAN_, 1.0, 0.0, 1.0, 1);)                          \
    X(sp_tmax_inf, odhs_driver_set_self_propulsion, ODHS_E_NONFINITE, NOALT, H_DRVR, 0,                        \
      return odhs_driver_set_self_propulsion(w->drvr, 16, 2, 0.5, 1.0, 0.0, INF_, 1);)                         \
    X(sp_fmax_zero, odhs_driver_set_self_propulsion, ODHS_E_INVALID, NOALT, H_DRV, 0,                          \
      return odhs_driver_set_self_propulsion(w->drv, 16, 2, 0.0, 0.0, 0.0, 1.0, 1);)                           \
    X(sp_fmin_negative, odhs_driver_set_self_propulsion, ODHS_E_INVALID, NOALT, H_DRV, 0,                      \
      return odhs_driver_set_self_propulsion(w->drv, 16, 2, -0.1, 1.0, 0.0, 1.0, 1);)                          \
    X(sp_fmin_above_fmax, odhs_driver_set_self_propulsion, ODHS_E_INVALID, NOALT, H_DRV, 0,                    \
      return odhs_driver_set_self_propulsion(w->drv, 16, 2, 2.0, 1.0, 0.0, 1.0, 1);)                           \
    X(sp_tmax_zero, odhs_driver_set_self_propulsion, ODHS_E_INVALID, NOALT, H_DRV, 0,                          \
      return odhs_driver_set_self_propulsion(w->drv, 16, 2, 0.5, 1.0, 0.0, 0.0, 1);)                           \
    X(sp_tmin_negative, odhs_driver_set_self_propulsion, ODHS_E_INVALID, NOALT, H_DRV, 0,                      \
      return odhs_driver_set_self_propulsion(w->drv, 16, 2, 0.5, 1.0, -1.0, 1.0, 1);)                          \
    X(sp_tmin_above_tmax, odhs_driver_set_self_propulsion, ODHS_E_INVALID, NOALT, H_DRVR, 0,                   \
      return odhs_driver_set_self_propulsion(w->drvr, 16, 2, 0.5, 1.0, 3.0, 1.0, 1);)                          \
    X(sp_wrong_n_for_stepper, odhs_driver_set_self_propulsion, ODHS_E_DIM, NOALT, H_ST, 0,                     \
      /* propulsion for another N: accepted by the driver, rejected by the stepper */                          \
      int rc = odhs_driver_set_self_propulsion(w->drv, 12, 2, 0.5, 1.0, 0.0, 1.0, 1);                          \
      if (rc) return post("set_self_propulsion %d", rc);                                                       \
      rc = odhs_stepper_reset(w->st); odhs_driver_clear_self_propulsion(w->drv); return rc;)                   \
    X(sp_wrong_dim_for_running_stepper, odhs_driver_set_self_propulsion, ODHS_E_DIM, NOALT, H_RUN, 0,          \
      int rc = odhs_driver_set_self_propulsion(w->drvr, 16, 3, 0.5, 1.0, 0.0, 1.0, 1);                         \
      if (rc) return post("set_self_propulsion %d", rc);                                                       \
      rc = odhs_stepper_step(w->run, NULL); odhs_driver_clear_self_propulsion(w->drvr); return rc;)            \
    X(sp_clear_null, odhs_driver_clear_self_propulsion, ODHS_E_NULL, NOALT, H_NONE, 0,                         \
      return odhs_driver_clear_self_propulsion(NULL);)                                                         \
    X(sp_clear_off, odhs_driver_clear_self_propulsion, ODHS_OK, NOALT, H_NONE, 0,                              \
      return odhs_driver_clear_self_propulsion(w->drv);)                                                       \
    X(sp_get_null, odhs_driver_get_propulsion, ODHS_E_NULL, NOALT, H_NONE, 0,                                  \
      double F[32]; return odhs_driver_get_propulsion(NULL, F, NULL);)                                         \
    X(sp_get_null_outputs, odhs_driver_get_propulsion, ODHS_E_NULL, NOALT, H_DRV, 0,                           \
      return odhs_driver_get_propulsion(w->drv, NULL, NULL);)                                                  \
    X(sp_get_off, odhs_driver_get_propulsion, ODHS_E_STATE, NOALT, H_DRV, 0,                                   \
      double F[32] = {0}; F[3] = 7.0; int rc = odhs_driver_get_propulsion(w->drv, F, NULL);                    \
      return F[3] != 7.0 ? post("output written") : rc;)                                                       \
    X(sp_get_not_started, odhs_driver_get_propulsion, ODHS_E_STATE, NOALT, H_NONE, 0,                           \
      /* forces exist at once, switch times only when a stepper starts the clock */                            \
      double F[32], ts[16] = {0}; ts[0] = 7.0;                                                                 \
      int rc = odhs_driver_set_self_propulsion(w->drv, 16, 2, 0.5, 1.0, 0.0, 1.0, 1);                          \
      if (rc) return post("set_self_propulsion %d", rc);                                                       \
      if ((rc = odhs_driver_get_propulsion(w->drv, F, NULL))) return post("forces: %d", rc);                   \
      rc = odhs_driver_get_propulsion(w->drv, F, ts);                                                          \
      int has_msg = odhs_driver_errmsg(w->drv)[0] != '\0';                                                   \
      odhs_driver_clear_self_propulsion(w->drv); /* clears the message: a successful call */                   \
      return ts[0] != 7.0 ? post("output written") : !has_msg ? post("no message") : rc;)                     \
    X(sp_next_null, odhs_driver_next_switch, ODHS_E_NULL, NOALT, H_NONE, 0,                                    \
      double t; return odhs_driver_next_switch(NULL, &t);)                                                     \
    X(sp_next_null_out, odhs_driver_next_switch, ODHS_E_NULL, NOALT, H_DRV, 0,                                 \
      return odhs_driver_next_switch(w->drv, NULL);)                                                           \
    X(sp_next_off, odhs_driver_next_switch, ODHS_E_STATE, NOALT, H_DRVR, 0,                                    \
      double t = 5; int rc = odhs_driver_next_switch(w->drvr, &t);                                             \
      return t != 5 ? post("output written") : rc;)                                                            \
    X(osc_null, odhs_driver_set_oscillatory_shear, ODHS_E_NULL, NOALT, H_NONE, 0,                             \
      return odhs_driver_set_oscillatory_shear(NULL, ODHS_OSCILLATION_SINE, 0.1, 1.0, 0.0);)                    \
    X(osc_shape, odhs_driver_set_oscillatory_shear, ODHS_E_INVALID, NOALT, H_DRV, 0,                           \
      return odhs_driver_set_oscillatory_shear(w->drv, 7, 0.1, 1.0, 0.0);)                                      \
    X(osc_amp0, odhs_driver_set_oscillatory_shear, ODHS_E_INVALID, NOALT, H_DRV, 0,                            \
      return odhs_driver_set_oscillatory_shear(w->drv, ODHS_OSCILLATION_TRIANGLE, 0.0, 1.0, 0.0);)              \
    X(osc_period_neg, odhs_driver_set_oscillatory_shear, ODHS_E_INVALID, NOALT, H_DRV, 0,                      \
      return odhs_driver_set_oscillatory_shear(w->drv, ODHS_OSCILLATION_SINE, 0.1, -1.0, 0.0);)                 \
    X(osc_nan, odhs_driver_set_oscillatory_shear, ODHS_E_NONFINITE, NOALT, H_DRV, 0,                           \
      return odhs_driver_set_oscillatory_shear(w->drv, ODHS_OSCILLATION_SINE, NAN_, 1.0, 0.0);)                 \
    X(osc_peak_overflow, odhs_driver_set_oscillatory_shear, ODHS_E_RANGE, NOALT, H_DRV, 0,                     \
      return odhs_driver_set_oscillatory_shear(w->drv, ODHS_OSCILLATION_SINE, 1e300, 1e-300, 0.0);)             \
    X(osc_with_pressure, odhs_driver_set_oscillatory_shear, ODHS_E_UNSUPPORTED, NOALT, H_RUN, 0,               \
      int rc = odhs_driver_set_oscillatory_shear(w->drvr, ODHS_OSCILLATION_SINE, 0.1, 1.0, 0.0);                \
      if (!rc) rc = odhs_driver_set_pressure(w->drvr, 1.0);                                                    \
      if (rc) return post("setting up %d", rc);                                                                \
      rc = odhs_stepper_step(w->run, NULL);                                                                    \
      odhs_driver_clear_pressure(w->drvr);                                                                     \
      odhs_driver_set_shear_rate(w->drvr, 1.0);                                                                \
      return rc;)                                                                                              \
    X(osc_get_null, odhs_driver_get_oscillatory_shear, ODHS_E_NULL, NOALT, H_NONE, 0,                          \
      int sh; return odhs_driver_get_oscillatory_shear(NULL, &sh, NULL, NULL, NULL);)                           \
    X(osc_get_off, odhs_driver_get_oscillatory_shear, ODHS_OK, NOALT, H_NONE, 0,                               \
      int sh = 5; double a = 5; int rc = odhs_driver_get_oscillatory_shear(w->drv, &sh, &a, NULL, NULL);       \
      return sh != 0 || a != 0.0 ? post("settings of no oscillation: %d %g", sh, a) : rc;)                     \
    X(grav_null, odhs_driver_set_gravity, ODHS_E_NULL, NOALT, H_NONE, 0,                                       \
      double g[2] = {0, -1}; return odhs_driver_set_gravity(NULL, 2, g);)                                      \
    X(grav_dim1, odhs_driver_set_gravity, ODHS_E_DIM, NOALT, H_DRV, 0,                                         \
      double g[2] = {0, -1}; return odhs_driver_set_gravity(w->drv, 1, g);)                                    \
    X(grav_nan, odhs_driver_set_gravity, ODHS_E_NONFINITE, NOALT, H_DRV, 0,                                    \
      double g[3] = {0, -1, NAN_}; return odhs_driver_set_gravity(w->drv, 3, g);)                              \
    X(grav_remove_none, odhs_driver_set_gravity, ODHS_OK, NOALT, H_NONE, 0,                                    \
      return odhs_driver_set_gravity(w->drv, 2, NULL);)                                                        \
    X(grav_wrong_dim_for_stepper, odhs_driver_set_gravity, ODHS_E_DIM, NOALT, H_RUN, 0,                        \
      double g[3] = {0, -1, 0}; int rc = odhs_driver_set_gravity(w->drvr, 3, g);                               \
      if (rc) return post("set_gravity %d", rc);                                                               \
      rc = odhs_stepper_step(w->run, NULL); odhs_driver_set_gravity(w->drvr, 3, NULL); return rc;)             \
    X(gw_null, odhs_driver_set_gravity_weights, ODHS_E_NULL, NOALT, H_NONE, 0,                                 \
      double wt[16] = {0}; return odhs_driver_set_gravity_weights(NULL, 16, wt);)                              \
    X(gw_n0, odhs_driver_set_gravity_weights, ODHS_E_EMPTY, NOALT, H_DRV, 0,                                   \
      double wt[1] = {1}; return odhs_driver_set_gravity_weights(w->drv, 0, wt);)                              \
    X(gw_nan, odhs_driver_set_gravity_weights, ODHS_E_NONFINITE, NOALT, H_DRVR, 0,                             \
      double wt[16] = {0}; wt[9] = NAN_; return odhs_driver_set_gravity_weights(w->drvr, 16, wt);)             \
    X(gw_wrong_n_for_stepper, odhs_driver_set_gravity_weights, ODHS_E_DIM, NOALT, H_ST, 0,                     \
      double g[2] = {0, -1}, wt[12] = {0}; int rc = odhs_driver_set_gravity(w->drv, 2, g);                     \
      if (!rc) rc = odhs_driver_set_gravity_weights(w->drv, 12, wt);                                           \
      if (rc) return post("set gravity %d", rc);                                                               \
      rc = odhs_stepper_reset(w->st); odhs_driver_set_gravity(w->drv, 2, NULL);                                \
      odhs_driver_set_gravity_weights(w->drv, 0, NULL); return rc;)

/* ---- stepper.h ----------------------------------------------------------------- */
#define STEPPER_OBS(X, id, fn, T, n)                                                                           \
    X(id##_null, fn, ODHS_E_NULL, NOALT, H_NONE, 0, T v[n]; return fn(NULL, v);)                               \
    X(id##_null_out, fn, ODHS_E_NULL, NOALT, H_RUN, 0, return fn(w->run, NULL);)

#define STEPPER_OBS_STATE(X, id, fn, n)                                                                        \
    STEPPER_OBS(X, id, fn, double, n)                                                                          \
    X(id##_before_step, fn, ODHS_E_STATE, NOALT, H_ST, 0,                                                      \
      double v[n]; for (int k = 0; k < n; ++k) v[k] = -9.0; int rc = fn(w->st, v);                            \
      for (int k = 0; k < n; ++k) if (v[k] != -9.0) return post("output written on error");                   \
      return rc;)

#define STEPPER_CASES(X)                                                                                       \
    X(st_create_null_out, odhs_stepper_create, ODHS_E_NULL, NOALT, H_NONE, 0,                                  \
      return odhs_stepper_create(w->sys2, w->drv, w->cg, NULL);)                                               \
    X(st_create_null_sys, odhs_stepper_create, ODHS_E_NULL, NOALT, H_NONE, 0,                                  \
      odhs_stepper *s = POISON_PTR(odhs_stepper); int rc = odhs_stepper_create(NULL, w->drv, w->cg, &s);       \
      return s ? post("*out not NULL") : rc;)                                                                  \
    X(st_create_null_drv, odhs_stepper_create, ODHS_E_NULL, NOALT, H_NONE, 0,                                  \
      odhs_stepper *s = POISON_PTR(odhs_stepper); int rc = odhs_stepper_create(w->sys2, NULL, w->cg, &s);      \
      return s ? post("*out not NULL") : rc;)                                                                  \
    X(st_create_null_solver, odhs_stepper_create, ODHS_E_NULL, NOALT, H_NONE, 0,                               \
      odhs_stepper *s = POISON_PTR(odhs_stepper); int rc = odhs_stepper_create(w->sys2, w->drv, NULL, &s);     \
      return s ? post("*out not NULL") : rc;)                                                                  \
    X(st_create_unset, odhs_stepper_create, ODHS_E_STATE, NOALT, H_BARE, 0,                                    \
      odhs_stepper *s = POISON_PTR(odhs_stepper); int rc = odhs_stepper_create(w->bare, w->drv, w->cg, &s);    \
      return s ? post("*out not NULL") : rc;)                                                                  \
    X(st_destroy_null, odhs_stepper_destroy, ODHS_OK, NOALT, H_NONE, 0, odhs_stepper_destroy(NULL); return ODHS_OK;) \
    X(st_errmsg_null, odhs_stepper_errmsg, ODHS_OK, NOALT, H_NONE, 0,                                          \
      const char *m = odhs_stepper_errmsg(NULL); return m && !m[0] ? ODHS_OK : post("errmsg(NULL)");)          \
    X(st_dt_null, odhs_stepper_set_dt, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_stepper_set_dt(NULL, 1e-3);) \
    X(st_dt_nan, odhs_stepper_set_dt, ODHS_E_NONFINITE, NOALT, H_ST, 0, return odhs_stepper_set_dt(w->st, NAN_);) \
    X(st_dt_inf, odhs_stepper_set_dt, ODHS_E_NONFINITE, NOALT, H_RUN, 0, return odhs_stepper_set_dt(w->run, INF_);) \
    X(st_dt_zero, odhs_stepper_set_dt, ODHS_E_INVALID, NOALT, H_ST, 0, return odhs_stepper_set_dt(w->st, 0.0);) \
    X(st_dt_negative, odhs_stepper_set_dt, ODHS_E_INVALID, NOALT, H_RUN, 0, return odhs_stepper_set_dt(w->run, -1e-3);) \
    X(st_integrator_null, odhs_stepper_set_integrator, ODHS_E_NULL, NOALT, H_NONE, 0,                          \
      return odhs_stepper_set_integrator(NULL, ODHS_INTEGRATOR_HEUN);)                                         \
    X(st_integrator_bad, odhs_stepper_set_integrator, ODHS_E_INVALID, NOALT, H_ST, 0,                          \
      return odhs_stepper_set_integrator(w->st, 3);)                                                           \
    X(st_integrator_negative, odhs_stepper_set_integrator, ODHS_E_INVALID, NOALT, H_RUN, 0,                    \
      return odhs_stepper_set_integrator(w->run, -1);)                                                         \
    X(st_tol_null, odhs_stepper_set_tolerance, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_stepper_set_tolerance(NULL, 1e-6);) \
    X(st_tol_zero, odhs_stepper_set_tolerance, ODHS_E_INVALID, NOALT, H_ST, 0, return odhs_stepper_set_tolerance(w->st, 0.0);) \
    X(st_tol_one, odhs_stepper_set_tolerance, ODHS_E_INVALID, NOALT, H_ST, 0, return odhs_stepper_set_tolerance(w->st, 1.0);) \
    X(st_tol_nan, odhs_stepper_set_tolerance, ODHS_E_NONFINITE, ODHS_E_INVALID, H_RUN, 0,                      \
      return odhs_stepper_set_tolerance(w->run, NAN_);)                                                        \
    X(st_corr_null, odhs_stepper_set_correction_interval, ODHS_E_NULL, NOALT, H_NONE, 0,                       \
      return odhs_stepper_set_correction_interval(NULL, 5);)                                                   \
    X(st_bond_null, odhs_stepper_add_bond, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_stepper_add_bond(NULL, 0, 1, 0.0);) \
    X(st_bond_range, odhs_stepper_add_bond, ODHS_E_RANGE, NOALT, H_RUN, 0, return odhs_stepper_add_bond(w->run, 0, 16, 0.0);) \
    X(st_bond_self, odhs_stepper_add_bond, ODHS_E_INVALID, NOALT, H_RUN, 0, return odhs_stepper_add_bond(w->run, 2, 2, 0.0);) \
    X(st_bond_negative, odhs_stepper_add_bond, ODHS_E_INVALID, NOALT, H_RUN, 0,                                \
      return odhs_stepper_add_bond(w->run, 0, 1, -1.0);)                                                       \
    X(st_bond_nan, odhs_stepper_add_bond, ODHS_E_NONFINITE, NOALT, H_RUN, 0,                                   \
      return odhs_stepper_add_bond(w->run, 0, 1, NAN_);)                                                       \
    X(st_bond_far, odhs_stepper_add_bond, ODHS_E_INVALID, NOALT, H_RUN, 0,                                     \
      return odhs_stepper_add_bond(w->run, 0, 1, 1e6);)                                                        \
    X(st_chain_null, odhs_stepper_add_chain, ODHS_E_NULL, NOALT, H_NONE, 0,                                    \
      size_t b[2] = {0, 1}; return odhs_stepper_add_chain(NULL, 2, b);)                                        \
    X(st_chain_null_beads, odhs_stepper_add_chain, ODHS_E_NULL, NOALT, H_RUN, 0,                               \
      return odhs_stepper_add_chain(w->run, 2, NULL);)                                                         \
    X(st_chain_short, odhs_stepper_add_chain, ODHS_E_INVALID, NOALT, H_RUN, 0,                                 \
      size_t b[1] = {0}; return odhs_stepper_add_chain(w->run, 1, b);)                                         \
    X(st_chain_range, odhs_stepper_add_chain, ODHS_E_RANGE, NOALT, H_RUN, 0,                                   \
      size_t b[3] = {0, 1, 99}; return odhs_stepper_add_chain(w->run, 3, b);)                                  \
    X(st_chain_repeat, odhs_stepper_add_chain, ODHS_E_INVALID, NOALT, H_RUN, 0,                                \
      size_t b[3] = {0, 1, 0}; return odhs_stepper_add_chain(w->run, 3, b);)                                   \
    X(st_body_null, odhs_stepper_add_rigid_body, ODHS_E_NULL, NOALT, H_NONE, 0,                                \
      size_t b[2] = {0, 1}; return odhs_stepper_add_rigid_body(NULL, 2, b);)                                   \
    X(st_body_null_beads, odhs_stepper_add_rigid_body, ODHS_E_NULL, NOALT, H_RUN, 0,                           \
      return odhs_stepper_add_rigid_body(w->run, 3, NULL);)                                                    \
    X(st_body_short, odhs_stepper_add_rigid_body, ODHS_E_INVALID, NOALT, H_RUN, 0,                             \
      size_t b[1] = {0}; return odhs_stepper_add_rigid_body(w->run, 1, b);)                                    \
    X(st_body_range, odhs_stepper_add_rigid_body, ODHS_E_RANGE, NOALT, H_RUN, 0,                               \
      size_t b[2] = {SIZE_MAX, 1}; return odhs_stepper_add_rigid_body(w->run, 2, b);)                          \
    X(st_body_repeat, odhs_stepper_add_rigid_body, ODHS_E_INVALID, NOALT, H_RUN, 0,                            \
      size_t b[3] = {4, 5, 4}; return odhs_stepper_add_rigid_body(w->run, 3, b);)                              \
    X(st_feature_null, odhs_stepper_feature_work, ODHS_E_NULL, NOALT, H_NONE, 0,                               \
      uint64_t c; return odhs_stepper_feature_work(NULL, ODHS_FEATURE_PRESSURE, &c);)                          \
    X(st_feature_null_out, odhs_stepper_feature_work, ODHS_E_NULL, NOALT, H_RUN, 0,                            \
      return odhs_stepper_feature_work(w->run, ODHS_FEATURE_PRESSURE, NULL);)                                  \
    X(st_feature_unknown, odhs_stepper_feature_work, ODHS_E_INVALID, NOALT, H_RUN, 0,                          \
      uint64_t c; return odhs_stepper_feature_work(w->run, 0, &c);)                                            \
    X(st_wplane_null, odhs_stepper_add_wall_plane, ODHS_E_NULL, NOALT, H_NONE, 0,                              \
      double nv[2] = {0, 1}; return odhs_stepper_add_wall_plane(NULL, nv, 0.0, NULL);)                         \
    X(st_wplane_null_normal, odhs_stepper_add_wall_plane, ODHS_E_NULL, NOALT, H_RUN, 0,                        \
      return odhs_stepper_add_wall_plane(w->run, NULL, 0.0, NULL);)                                            \
    X(st_wplane_zero, odhs_stepper_add_wall_plane, ODHS_E_INVALID, NOALT, H_RUN, 0,                            \
      double nv[2] = {0, 0}; return odhs_stepper_add_wall_plane(w->run, nv, 0.0, NULL);)                       \
    X(st_wplane_nan, odhs_stepper_add_wall_plane, ODHS_E_NONFINITE, NOALT, H_RUN, 0,                           \
      double nv[2] = {0, 1}; return odhs_stepper_add_wall_plane(w->run, nv, NAN_, NULL);)                      \
    X(st_wplane_overlap, odhs_stepper_add_wall_plane, ODHS_E_OVERLAP, NOALT, H_RUN, 0,                         \
      double nv[2] = {0, 1}; return odhs_stepper_add_wall_plane(w->run, nv, 1e6, NULL);)                       \
    X(st_wsphere_null, odhs_stepper_add_wall_sphere, ODHS_E_NULL, NOALT, H_NONE, 0,                            \
      double c[2] = {0, 0}; return odhs_stepper_add_wall_sphere(NULL, c, 1.0, NULL);)                          \
    X(st_wsphere_null_centre, odhs_stepper_add_wall_sphere, ODHS_E_NULL, NOALT, H_RUN, 0,                      \
      return odhs_stepper_add_wall_sphere(w->run, NULL, 1.0, NULL);)                                           \
    X(st_wsphere_radius, odhs_stepper_add_wall_sphere, ODHS_E_INVALID, NOALT, H_RUN, 0,                        \
      double c[2] = {0, 0}; return odhs_stepper_add_wall_sphere(w->run, c, 0.0, NULL);)                        \
    X(st_wsphere_inf, odhs_stepper_add_wall_sphere, ODHS_E_NONFINITE, NOALT, H_RUN, 0,                         \
      double c[2] = {0, INF_}; return odhs_stepper_add_wall_sphere(w->run, c, 1.0, NULL);)                     \
    X(st_wsphere_overlap, odhs_stepper_add_wall_sphere, ODHS_E_OVERLAP, NOALT, H_RUN, 0,                       \
      double c[2] = {-1e3, -1e3}; return odhs_stepper_add_wall_sphere(w->run, c, 1.0, NULL);)                  \
    X(st_wseg_null, odhs_stepper_add_wall_segment, ODHS_E_NULL, NOALT, H_NONE, 0,                              \
      double a[2] = {0, 0}, b[2] = {1, 0}; return odhs_stepper_add_wall_segment(NULL, a, b, NULL);)            \
    X(st_wseg_null_end, odhs_stepper_add_wall_segment, ODHS_E_NULL, NOALT, H_RUN, 0,                           \
      double a[2] = {0, 0}; return odhs_stepper_add_wall_segment(w->run, a, NULL, NULL);)                      \
    X(st_wseg_degenerate, odhs_stepper_add_wall_segment, ODHS_E_INVALID, NOALT, H_RUN, 0,                      \
      double a[2] = {-5, -5}; return odhs_stepper_add_wall_segment(w->run, a, a, NULL);)                       \
    X(st_wseg_nan, odhs_stepper_add_wall_segment, ODHS_E_NONFINITE, NOALT, H_RUN, 0,                           \
      double a[2] = {0, NAN_}, b[2] = {1, 0}; return odhs_stepper_add_wall_segment(w->run, a, b, NULL);)       \
    X(st_wvel_null, odhs_stepper_set_wall_velocity, ODHS_E_NULL, NOALT, H_NONE, 0,                             \
      double v[2] = {0, 0}; return odhs_stepper_set_wall_velocity(NULL, 0, v);)                                \
    X(st_wvel_range, odhs_stepper_set_wall_velocity, ODHS_E_RANGE, NOALT, H_RUN, 0,                            \
      double v[2] = {0, 0}; return odhs_stepper_set_wall_velocity(w->run, 0, v);)                              \
    X(st_wcount_null, odhs_stepper_wall_count, ODHS_E_NULL, NOALT, H_NONE, 0,                                  \
      size_t c; return odhs_stepper_wall_count(NULL, &c);)                                                     \
    X(st_wcount_null_out, odhs_stepper_wall_count, ODHS_E_NULL, NOALT, H_RUN, 0,                               \
      return odhs_stepper_wall_count(w->run, NULL);)                                                           \
    X(st_wforce_null, odhs_stepper_wall_force, ODHS_E_NULL, NOALT, H_NONE, 0,                                  \
      double f[2]; return odhs_stepper_wall_force(NULL, 0, f);)                                                \
    X(st_wforce_range, odhs_stepper_wall_force, ODHS_E_RANGE, NOALT, H_RUN, 0,                                 \
      double f[2]; return odhs_stepper_wall_force(w->run, 3, f);)                                              \
    X(st_wforce_null_out, odhs_stepper_wall_force, ODHS_E_NULL, NOALT, H_RUN, 0,                               \
      return odhs_stepper_wall_force(w->run, 0, NULL);)                                                        \
    X(st_wdisp_null, odhs_stepper_wall_displacement, ODHS_E_NULL, NOALT, H_NONE, 0,                            \
      double f[2]; return odhs_stepper_wall_displacement(NULL, 0, f);)                                         \
    X(st_wdisp_range, odhs_stepper_wall_displacement, ODHS_E_RANGE, NOALT, H_RUN, 0,                           \
      double f[2]; return odhs_stepper_wall_displacement(w->run, 0, f);)                                       \
    X(st_bondcount_null, odhs_stepper_bond_count, ODHS_E_NULL, NOALT, H_NONE, 0,                               \
      size_t c; return odhs_stepper_bond_count(NULL, &c);)                                                     \
    X(st_bondcount_null_out, odhs_stepper_bond_count, ODHS_E_NULL, NOALT, H_RUN, 0,                            \
      return odhs_stepper_bond_count(w->run, NULL);)                                                           \
    X(st_ctol_null, odhs_stepper_set_contact_tolerance, ODHS_E_NULL, NOALT, H_NONE, 0,                         \
      return odhs_stepper_set_contact_tolerance(NULL, 1e-9);)                                                  \
    X(st_ctol_negative, odhs_stepper_set_contact_tolerance, ODHS_E_INVALID, NOALT, H_ST, 0,                    \
      return odhs_stepper_set_contact_tolerance(w->st, -1e-9);)                                                \
    X(st_ctol_nan, odhs_stepper_set_contact_tolerance, ODHS_E_NONFINITE, ODHS_E_INVALID, H_ST, 0,              \
      return odhs_stepper_set_contact_tolerance(w->st, NAN_);)                                                 \
    X(st_ctol_inf, odhs_stepper_set_contact_tolerance, ODHS_E_NONFINITE, ODHS_E_INVALID, H_RUN, 0,             \
      return odhs_stepper_set_contact_tolerance(w->run, INF_);)                                                \
    X(st_evcb_null, odhs_stepper_set_event_callback, ODHS_E_NULL, NOALT, H_NONE, 0,                            \
      return odhs_stepper_set_event_callback(NULL, NULL, NULL);)                                               \
    X(st_evcb_remove_none, odhs_stepper_set_event_callback, ODHS_OK, NOALT, H_NONE, 0,                         \
      return odhs_stepper_set_event_callback(w->run, NULL, NULL);)                                             \
    X(st_reset_null, odhs_stepper_reset, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_stepper_reset(NULL);)      \
    X(st_reset_pressure_no_shear, odhs_stepper_reset, ODHS_E_UNSUPPORTED, NOALT, H_ST, 0,                      \
      odhs_driver_set_shear_rate(w->drv, 0.0); odhs_driver_set_pressure(w->drv, 1.0);                          \
      int rc = odhs_stepper_reset(w->st);                                                                      \
      odhs_driver_clear_pressure(w->drv); odhs_driver_set_shear_rate(w->drv, 1.0); return rc;)                 \
    X(st_reset_pressure_and_compression, odhs_stepper_reset, ODHS_E_UNSUPPORTED, NOALT, H_ST, 0,               \
      odhs_driver_set_compression_rate(w->drv, 1.0); odhs_driver_set_pressure(w->drv, 1.0);                    \
      int rc = odhs_stepper_reset(w->st);                                                                      \
      odhs_driver_clear_pressure(w->drv); odhs_driver_set_compression_rate(w->drv, 0.0); return rc;)           \
    X(st_step_pressure_no_shear, odhs_stepper_step, ODHS_E_UNSUPPORTED, NOALT, H_RUN, 0,                       \
      /* a driver made invalid between steps: the ready stepper refuses and is rolled back */                  \
      odhs_driver_set_shear_rate(w->drvr, 0.0); odhs_driver_set_pressure(w->drvr, 1.0);                        \
      odhs_event ev; int rc = odhs_stepper_step(w->run, &ev);                                                  \
      odhs_driver_clear_pressure(w->drvr); odhs_driver_set_shear_rate(w->drvr, 1.0);                           \
      if (rc < 0 && ev.kind != ODHS_EVENT_NONE) return post("event reported by a failed step");                \
      return rc;)                                                                                              \
    X(st_correct_null, odhs_stepper_correct, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_stepper_correct(NULL);) \
    X(st_step_null, odhs_stepper_step, ODHS_E_NULL, NOALT, H_NONE, 0,                                          \
      odhs_event ev; return odhs_stepper_step(NULL, &ev);)                                                     \
    X(st_run_time_null, odhs_stepper_run_until_time, ODHS_E_NULL, NOALT, H_NONE, 0,                            \
      return odhs_stepper_run_until_time(NULL, 1.0);)                                                          \
    X(st_run_time_nan, odhs_stepper_run_until_time, ODHS_E_NONFINITE, NOALT, H_RUN, 0,                         \
      return odhs_stepper_run_until_time(w->run, NAN_);)                                                       \
    X(st_run_time_inf, odhs_stepper_run_until_time, ODHS_E_NONFINITE, NOALT, H_ST, 0,                          \
      return odhs_stepper_run_until_time(w->st, INF_);)                                                        \
    X(st_run_time_past, odhs_stepper_run_until_time, ODHS_OK, NOALT, H_NONE, 0,                                \
      return odhs_stepper_run_until_time(w->run, -1.0);)                                                       \
    X(st_run_strain_null, odhs_stepper_run_until_strain, ODHS_E_NULL, NOALT, H_NONE, 0,                        \
      return odhs_stepper_run_until_strain(NULL, 1.0);)                                                        \
    X(st_run_strain_nan, odhs_stepper_run_until_strain, ODHS_E_NONFINITE, NOALT, H_RUN, 0,                     \
      return odhs_stepper_run_until_strain(w->run, NAN_);)                                                     \
    X(st_run_strain_no_shear, odhs_stepper_run_until_strain, ODHS_E_STATE, NOALT, H_RUN, 0,                    \
      odhs_driver_set_shear_rate(w->drvr, 0.0); int rc = odhs_stepper_run_until_strain(w->run, 1.0);           \
      odhs_driver_set_shear_rate(w->drvr, 1.0); return rc;)                                                    \
    X(st_run_events_null, odhs_stepper_run_events, ODHS_E_NULL, NOALT, H_NONE, 0,                              \
      return odhs_stepper_run_events(NULL, 1);)                                                                \
    X(st_run_events_zero, odhs_stepper_run_events, ODHS_OK, NOALT, H_NONE, 0,                                  \
      return odhs_stepper_run_events(w->run, 0);)                                                              \
    X(st_run_phi_null, odhs_stepper_run_until_packing_fraction, ODHS_E_NULL, NOALT, H_NONE, 0,                 \
      return odhs_stepper_run_until_packing_fraction(NULL, 0.8);)                                              \
    X(st_run_phi_nan, odhs_stepper_run_until_packing_fraction, ODHS_E_NONFINITE, NOALT, H_RUN, 0,              \
      return odhs_stepper_run_until_packing_fraction(w->run, NAN_);)                                           \
    X(st_run_phi_zero, odhs_stepper_run_until_packing_fraction, ODHS_E_INVALID, NOALT, H_RUN, 0,               \
      return odhs_stepper_run_until_packing_fraction(w->run, 0.0);)                                            \
    X(st_run_phi_one, odhs_stepper_run_until_packing_fraction, ODHS_E_INVALID, NOALT, H_ST, 0,                 \
      return odhs_stepper_run_until_packing_fraction(w->st, 1.0);)                                             \
    X(st_run_phi_no_compression, odhs_stepper_run_until_packing_fraction, ODHS_E_STATE, NOALT, H_RUN, 0,       \
      return odhs_stepper_run_until_packing_fraction(w->run, 0.8);)                                            \
    STEPPER_OBS(X, st_time, odhs_stepper_time, double, 1)                                                      \
    STEPPER_OBS(X, st_strain, odhs_stepper_strain, double, 1)                                                  \
    STEPPER_OBS(X, st_kappa, odhs_stepper_kappa, double, 1)                                                    \
    STEPPER_OBS(X, st_z, odhs_stepper_coordination, double, 1)                                                 \
    STEPPER_OBS_STATE(X, st_stress, odhs_stepper_stress, 9)                                                    \
    STEPPER_OBS_STATE(X, st_shear_stress, odhs_stepper_shear_stress, 1)                                        \
    STEPPER_OBS_STATE(X, st_pressure, odhs_stepper_pressure, 1)                                                \
    STEPPER_OBS_STATE(X, st_dissipation, odhs_stepper_dissipation, 1)                                          \
    STEPPER_OBS_STATE(X, st_power, odhs_stepper_power, 1)                                                      \
    STEPPER_OBS_STATE(X, st_velocities, odhs_stepper_velocities, 32)                                           \
    STEPPER_OBS_STATE(X, st_nonaffine, odhs_stepper_nonaffine_velocities, 32)                                  \
    X(st_time_before_step, odhs_stepper_time, ODHS_OK, NOALT, H_NONE, 0,                                       \
      double t = -1; int rc = odhs_stepper_time(w->st, &t); return rc == ODHS_OK && t != 0.0 ? post("t = %g", t) : rc;) \
    X(st_z_before_step, odhs_stepper_coordination, ODHS_OK, NOALT, H_NONE, 0,                                  \
      double z = -1; int rc = odhs_stepper_coordination(w->st, &z); return rc == ODHS_OK && z != 0.0 ? post("z = %g", z) : rc;) \
    X(st_settings_null, odhs_stepper_get_settings, ODHS_E_NULL, NOALT, H_NONE, 0,                              \
      int i; double a; unsigned k; return odhs_stepper_get_settings(NULL, &i, &a, &a, &k);)                    \
    X(st_settings_all_null, odhs_stepper_get_settings, ODHS_OK, NOALT, H_NONE, 0,                              \
      return odhs_stepper_get_settings(w->st, NULL, NULL, NULL, NULL);)                                        \
    X(st_adaptive_null, odhs_stepper_adaptive_stats, ODHS_E_NULL, NOALT, H_NONE, 0,                            \
      uint64_t r; double h; return odhs_stepper_adaptive_stats(NULL, &r, &h);)                                 \
    X(st_adaptive_all_null, odhs_stepper_adaptive_stats, ODHS_OK, NOALT, H_NONE, 0,                            \
      return odhs_stepper_adaptive_stats(w->run, NULL, NULL);)                                                 \
    X(st_batched_stats_null, odhs_stepper_batched_stats, ODHS_E_NULL, NOALT, H_NONE, 0,                        \
      uint64_t a; return odhs_stepper_batched_stats(NULL, &a, &a, &a);)                                        \
    X(st_batched_stats_all_null, odhs_stepper_batched_stats, ODHS_OK, NOALT, H_NONE, 0,                        \
      return odhs_stepper_batched_stats(w->run, NULL, NULL, NULL);)                                            \
    X(st_correction_stats_null, odhs_stepper_correction_stats, ODHS_E_NULL, NOALT, H_NONE, 0,                  \
      uint64_t a; return odhs_stepper_correction_stats(NULL, &a, &a, &a);)                                     \
    X(st_correction_stats_all_null, odhs_stepper_correction_stats, ODHS_OK, NOALT, H_NONE, 0,                  \
      return odhs_stepper_correction_stats(w->run, NULL, NULL, NULL);)                                         \
    X(st_rewire_stats_null, odhs_stepper_rewire_stats, ODHS_E_NULL, NOALT, H_NONE, 0,                          \
      uint64_t c; return odhs_stepper_rewire_stats(NULL, &c);)                                                 \
    X(st_rewire_stats_out_null, odhs_stepper_rewire_stats, ODHS_E_NULL, NOALT, H_NONE, 0,                      \
      return odhs_stepper_rewire_stats(w->run, NULL);)                                                         \
    X(st_counts_null, odhs_stepper_counts, ODHS_E_NULL, NOALT, H_NONE, 0,                                      \
      uint64_t a; return odhs_stepper_counts(NULL, &a, &a, &a);)                                               \
    X(st_counts_all_null, odhs_stepper_counts, ODHS_OK, NOALT, H_NONE, 0,                                      \
      return odhs_stepper_counts(w->st, NULL, NULL, NULL);)                                                    \
    X(st_network_null, odhs_stepper_network, ODHS_OK, NOALT, H_NONE, 0,                                        \
      return odhs_stepper_network(NULL) == NULL ? ODHS_OK : post("network(NULL) not NULL");)                   \
    X(st_errors_null, odhs_stepper_errors, ODHS_E_NULL, NOALT, H_NONE, 0,                                      \
      double g, o; return odhs_stepper_errors(NULL, &g, &o);)                                                  \
    X(st_errors_all_null, odhs_stepper_errors, ODHS_OK, NOALT, H_NONE, 0,                                      \
      return odhs_stepper_errors(w->run, NULL, NULL);)

/* ---- jamming.h ----------------------------------------------------------------- */
#define JAMMING_CASES(X)                                                                                       \
    X(cert_null, odhs_stepper_certificate, ODHS_E_NULL, NOALT, H_NONE, 0,                                      \
      odhs_jam_certificate c = {.size = sizeof c}; return odhs_stepper_certificate(NULL, &c);)                 \
    X(cert_partial_size, odhs_stepper_certificate, ODHS_OK, NOALT, H_NONE, 0,                                  \
      /* fields beyond size are not written */                                                                 \
      unsigned char buf[sizeof(odhs_jam_certificate)]; memset(buf, 0xAB, sizeof buf);                          \
      odhs_jam_certificate c; memcpy(&c, buf, sizeof c);                                                       \
      c.size = offsetof(odhs_jam_certificate, phi);                                                            \
      int rc = odhs_stepper_certificate(w->run, &c); unsigned char out[sizeof c]; memcpy(out, &c, sizeof c);   \
      for (size_t k = offsetof(odhs_jam_certificate, phi); k < sizeof c; ++k)                                  \
          if (out[k] != 0xAB) return post("byte %zu beyond size written", k);                                  \
      return rc;)                                                                                              \
    X(contacts_null_net, odhs_contacts_write, ODHS_E_NULL, NOALT, H_NONE, 0,                                   \
      return odhs_contacts_write(NULL, w->sys2, wpath(w, "c.txt"));)                                           \
    X(contacts_null_sys, odhs_contacts_write, ODHS_E_NULL, NOALT, H_NET2, 0,                                   \
      return odhs_contacts_write(w->net2, NULL, wpath(w, "c.txt"));)                                           \
    X(contacts_null_path, odhs_contacts_write, ODHS_E_NULL, NOALT, H_NET2, 0,                                  \
      return odhs_contacts_write(w->net2, w->sys2, NULL);)                                                     \
    X(contacts_dim_mismatch, odhs_contacts_write, ODHS_E_DIM, NOALT, H_NET2, 0,                                \
      return odhs_contacts_write(w->net2, w->sys3, wpath(w, "c.txt"));)                                        \
    X(contacts_n_mismatch, odhs_contacts_write, ODHS_E_DIM, NOALT, H_NET2, 0,                                  \
      return odhs_contacts_write(w->net2, w->sys8, wpath(w, "c.txt"));)                                        \
    X(contacts_unset, odhs_contacts_write, ODHS_E_STATE, NOALT, H_NET2, 0,                                     \
      return odhs_contacts_write(w->net2, w->bare, wpath(w, "c.txt"));)                                        \
    X(contacts_nowhere, odhs_contacts_write, ODHS_E_IO, NOALT, H_NET2, 0,                                      \
      return odhs_contacts_write(w->net2, w->sys2, NOWHERE);)                                                  \
    X(jam_lp_null, odhs_stepper_jam_lp, ODHS_E_NULL, NOALT, H_NONE, 0,                                         \
      return odhs_stepper_jam_lp(NULL, NULL, NULL);)                                                           \
    X(jam_lp_shear_driver, odhs_stepper_jam_lp, ODHS_E_STATE, NOALT, H_RUN, 0,                                 \
      /* the run's driver shears: the fast route compresses only */ return odhs_stepper_jam_lp(w->run,         \
      NULL, NULL);)                                                                                            \
    X(jam_lp_never_stepped, odhs_stepper_jam_lp, ODHS_E_STATE, NOALT, H_ST, 0,                                 \
      /* refused before the stepper is reset */ return odhs_stepper_jam_lp(w->st, NULL, NULL);)                \
    X(jam_lp_opt_size0, odhs_stepper_jam_lp, ODHS_E_INVALID, NOALT, H_RUN, 0,                                  \
      odhs_jam_lp_options o; memset(&o, 0, sizeof o); return odhs_stepper_jam_lp(w->run, &o, NULL);)           \
    X(jam_lp_rep_size0, odhs_stepper_jam_lp, ODHS_E_INVALID, NOALT, H_RUN, 0,                                  \
      odhs_jam_lp_report r; memset(&r, 0, sizeof r); return odhs_stepper_jam_lp(w->run, NULL, &r);)            \
    X(jam_lp_trust_nan, odhs_stepper_jam_lp, ODHS_E_NONFINITE, NOALT, H_RUN, 0,                                \
      odhs_jam_lp_options o = {.size = sizeof o, .trust = NAN_}; return odhs_stepper_jam_lp(w->run, &o,        \
      NULL);)                                                                                                  \
    X(jam_lp_trust_big, odhs_stepper_jam_lp, ODHS_E_INVALID, NOALT, H_RUN, 0,                                  \
      odhs_jam_lp_options o = {.size = sizeof o, .trust = 0.9}; return odhs_stepper_jam_lp(w->run, &o,         \
      NULL);)                                                                                                  \
    X(jam_lp_tol_negative, odhs_stepper_jam_lp, ODHS_E_INVALID, NOALT, H_RUN, 0,                               \
      odhs_jam_lp_options o = {.size = sizeof o, .tol = -1e-12}; return odhs_stepper_jam_lp(w->run, &o,        \
      NULL);)                                                                                                  \
    X(jam_lp_quench_flag, odhs_stepper_jam_lp, ODHS_E_INVALID, NOALT, H_RUN, 0,                                \
      odhs_jam_lp_options o = {.size = sizeof o, .quench = 2}; return odhs_stepper_jam_lp(w->run, &o, NULL);)  \
    X(jam_lp_quench_phi_one, odhs_stepper_jam_lp, ODHS_E_INVALID, NOALT, H_RUN, 0,                             \
      odhs_jam_lp_options o = {.size = sizeof o, .quench = 1, .quench_phi = 1.0};                              \
      return odhs_stepper_jam_lp(w->run, &o, NULL);)                                                           \
    X(jam_lp_quench_phi_negative, odhs_stepper_jam_lp, ODHS_E_INVALID, NOALT, H_RUN, 0,                        \
      odhs_jam_lp_options o = {.size = sizeof o, .quench = 1, .quench_phi = -0.5};                             \
      return odhs_stepper_jam_lp(w->run, &o, NULL);)                                                           \
    X(jam_lp_quench_phi_nan, odhs_stepper_jam_lp, ODHS_E_NONFINITE, NOALT, H_RUN, 0,                           \
      odhs_jam_lp_options o = {.size = sizeof o, .quench = 1, .quench_phi = NAN_};                             \
      return odhs_stepper_jam_lp(w->run, &o, NULL);)                                                           \
    X(jam_lp_own_integrator_two, odhs_stepper_jam_lp, ODHS_E_INVALID, NOALT, H_RUN, 0,                         \
      odhs_jam_lp_options o = {.size = sizeof o, .own_integrator = 2};                                         \
      return odhs_stepper_jam_lp(w->run, &o, NULL);)

/* ---- traj.h, lammps.h and the outputs of 0.2.6 in io.h and stepper.h ------------------ */
/* a trajectory of the given format in the world's directory (NULL: none) */
static odhs_traj *open_traj(const world *w, int format)
{
    odhs_traj *tr = NULL;
    return odhs_traj_open(wpath(w, "t.xyz"), format, &tr, NULL, 0) ? NULL : tr;
}

/* status rc of a call on trajectory tr, which must then hold a message; tr closed */
static int traj_status(odhs_traj *tr, int rc)
{
    int empty = !tr || !odhs_traj_errmsg(tr)[0];
    odhs_traj_close(tr);
    return !tr ? post("cannot open the trajectory") : empty ? post("no message") : rc;
}

#define OUTPUT_CASES(X)                                                                                        \
    STEPPER_OBS_STATE(X, st_external_forces, odhs_stepper_external_forces, 32)                                 \
    X(contacts_csv_null_net, odhs_contacts_write_csv, ODHS_E_NULL, NOALT, H_NONE, 0,                           \
      return odhs_contacts_write_csv(NULL, w->sys2, wpath(w, "c.csv"));)                                       \
    X(contacts_csv_null_sys, odhs_contacts_write_csv, ODHS_E_NULL, NOALT, H_NET2, 0,                           \
      return odhs_contacts_write_csv(w->net2, NULL, wpath(w, "c.csv"));)                                       \
    X(contacts_csv_null_path, odhs_contacts_write_csv, ODHS_E_NULL, NOALT, H_NET2, 0,                          \
      return odhs_contacts_write_csv(w->net2, w->sys2, NULL);)                                                 \
    X(contacts_csv_dim_mismatch, odhs_contacts_write_csv, ODHS_E_DIM, NOALT, H_NET2, 0,                        \
      return odhs_contacts_write_csv(w->net2, w->sys3, wpath(w, "c.csv"));)                                    \
    X(contacts_csv_unset, odhs_contacts_write_csv, ODHS_E_STATE, NOALT, H_NET2, 0,                             \
      return odhs_contacts_write_csv(w->net2, w->bare, wpath(w, "c.csv"));)                                    \
    X(contacts_csv_nowhere, odhs_contacts_write_csv, ODHS_E_IO, NOALT, H_NET2, 0,                              \
      return odhs_contacts_write_csv(w->net2, w->sys2, NOWHERE);)                                              \
    X(xyz_frame_null_path, odhs_xyz_read_frame, ODHS_E_NULL, NOALT, H_NONE, 0,                                 \
      odhs_system *s = POISON_PTR(odhs_system); char e[64] = "";                                               \
      int rc = odhs_xyz_read_frame(NULL, 0, &s, NULL, e, sizeof e);                                            \
      return s ? post("*out not NULL") : !e[0] ? post("no message") : rc;)                                     \
    X(xyz_frame_null_out, odhs_xyz_read_frame, ODHS_E_NULL, NOALT, H_NONE, 0,                                  \
      return odhs_xyz_read_frame(wpath(w, "a.xyz"), 0, NULL, NULL, NULL, 0);)                                  \
    X(xyz_frame_missing, odhs_xyz_read_frame, ODHS_E_IO, NOALT, H_NONE, 0,                                     \
      odhs_system *s = POISON_PTR(odhs_system); char e[64] = "";                                               \
      int rc = odhs_xyz_read_frame(wpath(w, "missing.xyz"), -1, &s, NULL, e, sizeof e);                        \
      return s ? post("*out not NULL") : !e[0] ? post("no message") : rc;)                                     \
    X(xyz_frame_range, odhs_xyz_read_frame, ODHS_E_RANGE, NOALT, H_NONE, 0,                                    \
      if (odhs_xyz_write(w->sys2, wpath(w, "f.xyz"))) return post("cannot write the frame");                  \
      odhs_system *s = POISON_PTR(odhs_system); char e[128] = ""; long nf = -7;                                \
      int rc = odhs_xyz_read_frame(wpath(w, "f.xyz"), 1, &s, &nf, e, sizeof e);                               \
      return s ? post("*out not NULL") : !strstr(e, "1 frame") ? post("message '%s'", e)                     \
             : nf != -7 ? post("*nframes written on error") : rc;)                                            \
    X(xyz_frame_range_negative, odhs_xyz_read_frame, ODHS_E_RANGE, NOALT, H_NONE, 0,                           \
      if (odhs_xyz_write(w->sys2, wpath(w, "f.xyz"))) return post("cannot write the frame");                  \
      odhs_system *s = POISON_PTR(odhs_system);                                                                \
      int rc = odhs_xyz_read_frame(wpath(w, "f.xyz"), -2, &s, NULL, NULL, 0);                                  \
      return s ? post("*out not NULL") : rc;)                                                                  \
    X(traj_format_null, odhs_traj_format_for, ODHS_E_NULL, NOALT, H_NONE, 0,                                   \
      int f = 0; return odhs_traj_format_for(NULL, &f);)                                                       \
    X(traj_format_null_out, odhs_traj_format_for, ODHS_E_NULL, NOALT, H_NONE, 0,                               \
      return odhs_traj_format_for("a.xyz", NULL);)                                                             \
    X(traj_format_unknown, odhs_traj_format_for, ODHS_E_INVALID, NOALT, H_NONE, 0,                             \
      int f = -5; int rc = odhs_traj_format_for("a.xyz.txt", &f);                                              \
      return f != -5 ? post("*format written on error") : rc;)                                                 \
    X(traj_open_null_out, odhs_traj_open, ODHS_E_NULL, NOALT, H_NONE, 0,                                       \
      return odhs_traj_open(wpath(w, "t.xyz"), ODHS_TRAJ_XYZ, NULL, NULL, 0);)                                 \
    X(traj_open_null_path, odhs_traj_open, ODHS_E_NULL, NOALT, H_NONE, 0,                                      \
      odhs_traj *t = POISON_PTR(odhs_traj); char e[64] = "";                                                   \
      int rc = odhs_traj_open(NULL, ODHS_TRAJ_XYZ, &t, e, sizeof e);                                           \
      return t ? post("*out not NULL") : !e[0] ? post("no message") : rc;)                                     \
    X(traj_open_bad_format, odhs_traj_open, ODHS_E_INVALID, NOALT, H_NONE, 0,                                  \
      odhs_traj *t = POISON_PTR(odhs_traj); char e[64] = "";                                                   \
      int rc = odhs_traj_open(wpath(w, "t.xyz"), 3, &t, e, sizeof e);                                          \
      return t ? post("*out not NULL") : !e[0] ? post("no message")                                          \
             : access(wpath(w, "t.xyz"), F_OK) == 0 ? post("file created on error") : rc;)                    \
    X(traj_open_nowhere, odhs_traj_open, ODHS_E_IO, NOALT, H_NONE, 0,                                          \
      odhs_traj *t = POISON_PTR(odhs_traj); char e[128] = "";                                                  \
      int rc = odhs_traj_open(NOWHERE, ODHS_TRAJ_LAMMPS_DUMP, &t, e, sizeof e);                                \
      return t ? post("*out not NULL") : !strstr(e, NOWHERE) ? post("message '%s'", e) : rc;)                \
    X(traj_write_null, odhs_traj_write, ODHS_E_NULL, NOALT, H_NONE, 0,                                         \
      return odhs_traj_write(NULL, w->sys2, NULL);)                                                            \
    X(traj_write_null_sys, odhs_traj_write, ODHS_E_NULL, NOALT, H_NONE, 0,                                     \
      odhs_traj *t = open_traj(w, ODHS_TRAJ_XYZ); return traj_status(t, t ? odhs_traj_write(t, NULL, NULL) : 0);) \
    X(traj_write_other_system, odhs_traj_write, ODHS_E_INVALID, NOALT, H_NONE, 0,                              \
      odhs_traj *t = open_traj(w, ODHS_TRAJ_XYZ);                                                              \
      return traj_status(t, t ? odhs_traj_write(t, w->sys3, w->st) : 0);)                                      \
    X(traj_write_unset, odhs_traj_write, ODHS_E_STATE, NOALT, H_NONE, 0,                                       \
      odhs_traj *t = open_traj(w, ODHS_TRAJ_LAMMPS_DUMP);                                                      \
      return traj_status(t, t ? odhs_traj_write(t, w->bare, NULL) : 0);)                                       \
    X(traj_write_local_no_stepper, odhs_traj_write, ODHS_E_NULL, NOALT, H_NONE, 0,                             \
      odhs_traj *t = open_traj(w, ODHS_TRAJ_LAMMPS_LOCAL);                                                     \
      return traj_status(t, t ? odhs_traj_write(t, w->sys2, NULL) : 0);)                                       \
    X(traj_frames_null, odhs_traj_frames, ODHS_E_NULL, NOALT, H_NONE, 0,                                       \
      uint64_t c = 0; return odhs_traj_frames(NULL, &c);)                                                      \
    X(traj_frames_null_out, odhs_traj_frames, ODHS_E_NULL, NOALT, H_NONE, 0,                                   \
      odhs_traj *t = open_traj(w, ODHS_TRAJ_XYZ); int rc = odhs_traj_frames(t, NULL);                          \
      odhs_traj_close(t); return t ? rc : post("cannot open the trajectory");)                                 \
    X(traj_errmsg_null, odhs_traj_errmsg, ODHS_OK, NOALT, H_NONE, 0,                                           \
      const char *m = odhs_traj_errmsg(NULL); return m && !m[0] ? ODHS_OK : post("not an empty string");)     \
    X(traj_close_null, odhs_traj_close, ODHS_OK, NOALT, H_NONE, 0, return odhs_traj_close(NULL);)              \
    X(lammps_write_null_sys, odhs_lammps_data_write, ODHS_E_NULL, NOALT, H_NONE, 0,                            \
      return odhs_lammps_data_write(NULL, wpath(w, "a.data"));)                                                \
    X(lammps_write_null_path, odhs_lammps_data_write, ODHS_E_NULL, NOALT, H_SYS2, 0,                           \
      return odhs_lammps_data_write(w->sys2, NULL);)                                                           \
    X(lammps_write_unset, odhs_lammps_data_write, ODHS_E_STATE, NOALT, H_BARE, 0,                              \
      int rc = odhs_lammps_data_write(w->bare, wpath(w, "bare.data"));                                         \
      return access(wpath(w, "bare.data"), F_OK) == 0 ? post("file written on error") : rc;)                  \
    X(lammps_write_nowhere, odhs_lammps_data_write, ODHS_E_IO, NOALT, H_SYS2, 0,                               \
      return odhs_lammps_data_write(w->sys2, NOWHERE);)                                                        \
    X(lammps_read_null_path, odhs_lammps_data_read, ODHS_E_NULL, NOALT, H_NONE, 0,                             \
      odhs_system *s = POISON_PTR(odhs_system); char e[64] = "";                                               \
      int rc = odhs_lammps_data_read(NULL, &s, e, sizeof e);                                                   \
      return s ? post("*out not NULL") : !e[0] ? post("no message") : rc;)                                     \
    X(lammps_read_null_out, odhs_lammps_data_read, ODHS_E_NULL, NOALT, H_NONE, 0,                              \
      return odhs_lammps_data_read(wpath(w, "a.data"), NULL, NULL, 0);)                                        \
    X(lammps_read_missing, odhs_lammps_data_read, ODHS_E_IO, NOALT, H_NONE, 0,                                 \
      odhs_system *s = POISON_PTR(odhs_system); char e[64] = "";                                               \
      int rc = odhs_lammps_data_read(wpath(w, "missing.data"), &s, e, sizeof e);                               \
      return s ? post("*out not NULL") : !e[0] ? post("no message") : rc;)                                     \
    X(lammps_parse_null_buf, odhs_lammps_data_parse, ODHS_E_NULL, NOALT, H_NONE, 0,                            \
      odhs_system *s = POISON_PTR(odhs_system); int rc = odhs_lammps_data_parse(NULL, 0, &s, NULL, 0);         \
      return s ? post("*out not NULL") : rc;)                                                                  \
    X(lammps_parse_null_out, odhs_lammps_data_parse, ODHS_E_NULL, NOALT, H_NONE, 0,                            \
      return odhs_lammps_data_parse("x", 1, NULL, NULL, 0);)                                                   \
    X(lammps_parse_empty, odhs_lammps_data_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                             \
      odhs_system *s = POISON_PTR(odhs_system); char e[64] = "";                                               \
      int rc = odhs_lammps_data_parse("", 0, &s, e, sizeof e);                                                 \
      return s ? post("*out not NULL") : !strstr(e, "line 1") ? post("message '%s'", e) : rc;)

/* ---- checkpoint.h ------------------------------------------------------------------ */
#define CHECKPOINT_CASES(X)                                                                                    \
    X(ckpt_write_null, odhs_checkpoint_write, ODHS_E_NULL, NOALT, H_NONE, 0,                                   \
      return odhs_checkpoint_write(NULL, wpath(w, "a.ckpt"));)                                                 \
    X(ckpt_write_null_path, odhs_checkpoint_write, ODHS_E_NULL, NOALT, H_RUN, 0,                               \
      return odhs_checkpoint_write(w->run, NULL);)                                                             \
    X(ckpt_write_before_step, odhs_checkpoint_write, ODHS_E_STATE, NOALT, H_ST, 0,                             \
      int rc = odhs_checkpoint_write(w->st, wpath(w, "a.ckpt"));                                               \
      return access(wpath(w, "a.ckpt"), F_OK) == 0 ? post("file written on error") : rc;)                      \
    X(ckpt_write_nowhere, odhs_checkpoint_write, ODHS_E_IO, NOALT, H_RUN, 0,                                   \
      return odhs_checkpoint_write(w->run, NOWHERE);)                                                          \
    X(ckpt_write_directory, odhs_checkpoint_write, ODHS_E_IO, NOALT, H_RUN, 0,                                 \
      return odhs_checkpoint_write(w->run, w->dir);)                                                           \
    X(ckpt_read_null_path, odhs_checkpoint_read, ODHS_E_NULL, NOALT, H_NONE, 0,                                \
      odhs_system *s = POISON_PTR(odhs_system); odhs_driver *d = POISON_PTR(odhs_driver);                      \
      odhs_stepper *t = POISON_PTR(odhs_stepper); char e[128] = "";                                            \
      int rc = odhs_checkpoint_read(NULL, w->cg, &s, &d, &t, e, sizeof e);                                     \
      return s || d || t ? post("outputs not NULL") : !e[0] ? post("no message") : rc;)                        \
    X(ckpt_read_null_outputs, odhs_checkpoint_read, ODHS_E_NULL, NOALT, H_NONE, 0,                             \
      const char *p = wpath(w, "b.ckpt"); if (odhs_checkpoint_write(w->run, p)) return post("write");          \
      odhs_driver *d = POISON_PTR(odhs_driver); odhs_stepper *t = POISON_PTR(odhs_stepper);                    \
      int rc = odhs_checkpoint_read(p, w->cg, NULL, &d, &t, NULL, 0);                                          \
      return d || t ? post("outputs not NULL") : rc;)                                                          \
    X(ckpt_read_null_solver, odhs_checkpoint_read, ODHS_E_NULL, NOALT, H_NONE, 0,                             \
      const char *p = wpath(w, "b.ckpt"); if (odhs_checkpoint_write(w->run, p)) return post("write");          \
      odhs_system *s = POISON_PTR(odhs_system); odhs_driver *d = POISON_PTR(odhs_driver);                      \
      odhs_stepper *t = POISON_PTR(odhs_stepper);                                                              \
      int rc = odhs_checkpoint_read(p, NULL, &s, &d, &t, NULL, 0);                                             \
      return s || d || t ? post("outputs not NULL") : rc;)                                                     \
    X(ckpt_read_missing, odhs_checkpoint_read, ODHS_E_IO, NOALT, H_NONE, 0,                                    \
      odhs_system *s = POISON_PTR(odhs_system); odhs_driver *d = POISON_PTR(odhs_driver);                      \
      odhs_stepper *t = POISON_PTR(odhs_stepper); char e[256] = "";                                            \
      int rc = odhs_checkpoint_read(wpath(w, "missing.ckpt"), w->cg, &s, &d, &t, e, sizeof e);                 \
      return s || d || t ? post("outputs not NULL") : !e[0] ? post("no message") : rc;)                        \
    X(ckpt_read_xyz_file, odhs_checkpoint_read, ODHS_E_FORMAT, NOALT, H_NONE, 0,                               \
      const char *p = wpath(w, "c.xyz"); if (odhs_xyz_write(w->sys2, p)) return post("write");                 \
      odhs_system *s = POISON_PTR(odhs_system); odhs_driver *d = POISON_PTR(odhs_driver);                      \
      odhs_stepper *t = POISON_PTR(odhs_stepper);                                                              \
      int rc = odhs_checkpoint_read(p, w->dense, &s, &d, &t, NULL, 0);                                         \
      return s || d || t ? post("outputs not NULL") : rc;)                                                     \
    X(ckpt_parse_null_buf, odhs_checkpoint_parse, ODHS_E_NULL, NOALT, H_NONE, 0,                               \
      return ckpt_parse_expect_null(NULL, 100, w->cg, 0);)                                                     \
    X(ckpt_parse_null_sys_out, odhs_checkpoint_parse, ODHS_E_NULL, NOALT, H_NONE, 0,                           \
      size_t n = 0; unsigned char *b = ckpt_bytes(w, &n); if (!b) return post("write");                        \
      int rc = ckpt_parse_expect_null(b, n, w->cg, 1); free(b); return rc;)                                    \
    X(ckpt_parse_null_drv_out, odhs_checkpoint_parse, ODHS_E_NULL, NOALT, H_NONE, 0,                           \
      size_t n = 0; unsigned char *b = ckpt_bytes(w, &n); if (!b) return post("write");                        \
      int rc = ckpt_parse_expect_null(b, n, w->cg, 2); free(b); return rc;)                                    \
    X(ckpt_parse_null_st_out, odhs_checkpoint_parse, ODHS_E_NULL, NOALT, H_NONE, 0,                            \
      size_t n = 0; unsigned char *b = ckpt_bytes(w, &n); if (!b) return post("write");                        \
      int rc = ckpt_parse_expect_null(b, n, w->cg, 3); free(b); return rc;)                                    \
    X(ckpt_parse_len0, odhs_checkpoint_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                                 \
      return ckpt_parse_expect_null("ODHSCKPT", 0, w->cg, 0);)                                                 \
    X(ckpt_parse_garbage, odhs_checkpoint_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                              \
      unsigned char g[300]; for (int k = 0; k < 300; ++k) g[k] = (unsigned char)(k * 37 + 11);                 \
      return ckpt_parse_expect_null(g, sizeof g, w->cg, 0);)                                                   \
    X(ckpt_parse_truncated, odhs_checkpoint_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                            \
      return ckpt_parse_mutated(w, 0);)                                                                        \
    X(ckpt_parse_bitflip, odhs_checkpoint_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                              \
      return ckpt_parse_mutated(w, 1);)                                                                        \
    X(ckpt_parse_bad_magic, odhs_checkpoint_parse, ODHS_E_FORMAT, NOALT, H_NONE, 0,                            \
      return ckpt_parse_mutated(w, 2);)

/* ---- regressions: bugs found by these rows and by fuzz_xyz ------------------- */
#define SOFTCORE_CASES(X) \
    X(sc_create_null_out, odhs_softcore_create, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_create(w->sys2, NULL);) \
    X(sc_create_null_sys, odhs_softcore_create, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *s = POISON_PTR(odhs_softcore); int rc = odhs_softcore_create(NULL, &s); return s ? post("*out not NULL") : rc;) \
    X(sc_create_unset, odhs_softcore_create, ODHS_E_STATE, NOALT, H_BARE, 0, odhs_softcore *s = POISON_PTR(odhs_softcore); int rc = odhs_softcore_create(w->bare, &s); return s ? post("*out not NULL") : rc;) \
    X(sc_destroy_null, odhs_softcore_destroy, ODHS_OK, NOALT, H_NONE, 0, odhs_softcore_destroy(NULL); return ODHS_OK;) \
    X(sc_errmsg_null, odhs_softcore_errmsg, ODHS_OK, NOALT, H_NONE, 0, const char *m = odhs_softcore_errmsg(NULL); return m && !m[0] ? ODHS_OK : post("errmsg(NULL)");) \
    X(sc_set_model_null, odhs_softcore_set_model, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_model(NULL, ODHS_SOFTCORE_CD0);) \
    X(sc_set_potential_null, odhs_softcore_set_potential, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_potential(NULL, 2.0, 1.0);) \
    X(sc_set_drag_null, odhs_softcore_set_drag, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_drag(NULL, 1.0);) \
    X(sc_set_substrate_null, odhs_softcore_set_substrate, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_substrate(NULL, 1.0);) \
    X(sc_set_mass_null, odhs_softcore_set_mass, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_mass(NULL, 1.0);) \
    X(sc_set_shear_rate_null, odhs_softcore_set_shear_rate, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_shear_rate(NULL, 1.0);) \
    X(sc_set_integrator_null, odhs_softcore_set_integrator, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_integrator(NULL, ODHS_SOFTCORE_FIXED);) \
    X(sc_set_dt_null, odhs_softcore_set_dt, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_dt(NULL, 0.1);) \
    X(sc_set_tolerance_null, odhs_softcore_set_tolerance, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_tolerance(NULL, 1e-6);) \
    X(sc_set_minimiser_null, odhs_softcore_set_minimiser, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_minimiser(NULL, ODHS_SOFTCORE_SD);) \
    X(sc_set_min_tolerance_null, odhs_softcore_set_min_tolerance, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_min_tolerance(NULL, 1e-9, 10);) \
    X(sc_set_linear_tolerance_null, odhs_softcore_set_linear_tolerance, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_linear_tolerance(NULL, 1e-10);) \
    X(sc_set_positions_null, odhs_softcore_set_positions, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_positions(NULL, w->x0);) \
    X(sc_scale_box_null, odhs_softcore_scale_box, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_scale_box(NULL, 0.9);) \
    X(sc_set_velocities_null, odhs_softcore_set_velocities, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_set_velocities(NULL, w->x0);) \
    X(sc_reset_null, odhs_softcore_reset, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_reset(NULL);) \
    X(sc_step_null, odhs_softcore_step, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_step(NULL);) \
    X(sc_run_until_strain_null, odhs_softcore_run_until_strain, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_run_until_strain(NULL, 0.1);) \
    X(sc_run_until_time_null, odhs_softcore_run_until_time, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_run_until_time(NULL, 1.0);) \
    X(sc_minimise_null, odhs_softcore_minimise, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_minimise(NULL, NULL);) \
    X(sc_quasistatic_step_null, odhs_softcore_quasistatic_step, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_quasistatic_step(NULL, 1e-3, NULL);) \
    X(sc_time_null, odhs_softcore_time, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_time(NULL, &w->d0);) \
    X(sc_strain_null, odhs_softcore_strain, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_strain(NULL, &w->d0);) \
    X(sc_counts_null, odhs_softcore_counts, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_counts(NULL, NULL, NULL, NULL);) \
    X(sc_step_size_null, odhs_softcore_step_size, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_step_size(NULL, &w->d0);) \
    X(sc_energy_null, odhs_softcore_energy, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_energy(NULL, &w->d0);) \
    X(sc_kinetic_energy_null, odhs_softcore_kinetic_energy, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_kinetic_energy(NULL, &w->d0);) \
    X(sc_forces_null, odhs_softcore_forces, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_forces(NULL, w->x0);) \
    X(sc_max_force_null, odhs_softcore_max_force, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_max_force(NULL, &w->d0);) \
    X(sc_velocities_null, odhs_softcore_velocities, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_velocities(NULL, w->x0);) \
    X(sc_stress_null, odhs_softcore_stress, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_stress(NULL, ODHS_SOFTCORE_STRESS_TOTAL, w->x0);) \
    X(sc_pressure_null, odhs_softcore_pressure, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_pressure(NULL, &w->d0);) \
    X(sc_max_overlap_null, odhs_softcore_max_overlap, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_max_overlap(NULL, &w->d0);) \
    X(sc_coordination_null, odhs_softcore_coordination, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_coordination(NULL, 0, &w->d0);) \
    X(sc_relaxation_stress_null, odhs_softcore_relaxation_stress, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_softcore_relaxation_stress(NULL, w->x0);) \
    X(sc_model_bad, odhs_softcore_set_model, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_model(sc, 6));) \
    X(sc_model_neg, odhs_softcore_set_model, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_model(sc, -1));) \
    X(sc_pot_alpha, odhs_softcore_set_potential, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_potential(sc, 1.0, 1.0));) \
    X(sc_pot_ke, odhs_softcore_set_potential, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_potential(sc, 2.0, 0.0));) \
    X(sc_pot_nan, odhs_softcore_set_potential, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_potential(sc, NAN_, 1.0));) \
    X(sc_drag_neg, odhs_softcore_set_drag, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_drag(sc, -1.0));) \
    X(sc_drag_inf, odhs_softcore_set_drag, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_drag(sc, INF_));) \
    X(sc_sub_neg, odhs_softcore_set_substrate, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_substrate(sc, -1e-3));) \
    X(sc_sub_nan, odhs_softcore_set_substrate, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_substrate(sc, NAN_));) \
    X(sc_mass_zero, odhs_softcore_set_mass, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_mass(sc, 0.0));) \
    X(sc_mass_nan, odhs_softcore_set_mass, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_mass(sc, NAN_));) \
    X(sc_rate_nan, odhs_softcore_set_shear_rate, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_shear_rate(sc, NAN_));) \
    X(sc_rate_huge, odhs_softcore_set_shear_rate, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_shear_rate(sc, 1e308));) \
    X(sc_integ_bad, odhs_softcore_set_integrator, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_integrator(sc, 2));) \
    X(sc_dt_zero, odhs_softcore_set_dt, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_dt(sc, 0.0));) \
    X(sc_dt_big, odhs_softcore_set_dt, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_dt(sc, 11.0));) \
    X(sc_dt_nan, odhs_softcore_set_dt, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_dt(sc, NAN_));) \
    X(sc_tol_one, odhs_softcore_set_tolerance, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_tolerance(sc, 1.0));) \
    X(sc_tol_nan, odhs_softcore_set_tolerance, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_tolerance(sc, NAN_));) \
    X(sc_min_bad, odhs_softcore_set_minimiser, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_minimiser(sc, 3));) \
    X(sc_mintol_zero, odhs_softcore_set_min_tolerance, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_min_tolerance(sc, 0.0, 10));) \
    X(sc_mintol_iter, odhs_softcore_set_min_tolerance, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_min_tolerance(sc, 1e-9, 0));) \
    X(sc_mintol_nan, odhs_softcore_set_min_tolerance, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_min_tolerance(sc, NAN_, 10));) \
    X(sc_ltol_zero, odhs_softcore_set_linear_tolerance, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_linear_tolerance(sc, 0.0));) \
    X(sc_ltol_nan, odhs_softcore_set_linear_tolerance, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_linear_tolerance(sc, NAN_));) \
    X(sc_pos_nullx, odhs_softcore_set_positions, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_positions(sc, NULL));) \
    X(sc_pos_nan, odhs_softcore_set_positions, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, sc_pos_nan(w, sc));) \
    X(sc_pos_far, odhs_softcore_set_positions, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, sc_pos_far(w, sc));) \
    X(sc_scale_zero, odhs_softcore_scale_box, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_scale_box(sc, 0.0));) \
    X(sc_scale_neg, odhs_softcore_scale_box, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_scale_box(sc, -0.5));) \
    X(sc_scale_nan, odhs_softcore_scale_box, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_scale_box(sc, NAN_));) \
    X(sc_scale_inf, odhs_softcore_scale_box, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_scale_box(sc, 1.0 / 0.0));) \
    X(sc_scale_huge, odhs_softcore_scale_box, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_scale_box(sc, 1e308));) \
    X(sc_scale_tiny, odhs_softcore_scale_box, ODHS_E_BOX, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_scale_box(sc, 1e-3));) \
    X(sc_vel_nullu, odhs_softcore_set_velocities, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_set_velocities(sc, NULL));) \
    X(sc_vel_nan, odhs_softcore_set_velocities, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, sc_vel_nan(sc));) \
    X(sc_step_rd0_nodrag, odhs_softcore_step, ODHS_E_UNSUPPORTED, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, (odhs_softcore_set_drag(sc, 0.0), odhs_softcore_step(sc)));) \
    X(sc_step_cd0_nok0, odhs_softcore_step, ODHS_E_UNSUPPORTED, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, (odhs_softcore_set_model(sc, ODHS_SOFTCORE_CD0), odhs_softcore_set_substrate(sc, 0.0), odhs_softcore_step(sc)));) \
    X(sc_strain_norate, odhs_softcore_run_until_strain, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_run_until_strain(sc, 0.1));) \
    X(sc_strain_behind, odhs_softcore_run_until_strain, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, (odhs_softcore_set_shear_rate(sc, 1.0), odhs_softcore_run_until_strain(sc, -0.1)));) \
    X(sc_strain_nan, odhs_softcore_run_until_strain, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_run_until_strain(sc, NAN_));) \
    X(sc_time_behind, odhs_softcore_run_until_time, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_run_until_time(sc, -1.0));) \
    X(sc_time_nan, odhs_softcore_run_until_time, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_run_until_time(sc, NAN_));) \
    X(sc_minimise_noconv, odhs_softcore_minimise, ODHS_E_NOCONV, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, sc_noconv(w, sc));) \
    X(sc_minimise_nodrag, odhs_softcore_minimise, ODHS_E_UNSUPPORTED, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, (odhs_softcore_set_drag(sc, 0.0), sc_noconv(w, sc)));) \
    X(sc_qs_zero, odhs_softcore_quasistatic_step, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_quasistatic_step(sc, 0.0, NULL));) \
    X(sc_qs_big, odhs_softcore_quasistatic_step, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_quasistatic_step(sc, 0.2, NULL));) \
    X(sc_qs_nan, odhs_softcore_quasistatic_step, ODHS_E_NONFINITE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_quasistatic_step(sc, NAN_, NULL));) \
    X(sc_time_nullout, odhs_softcore_time, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_time(sc, NULL));) \
    X(sc_strain_nullout, odhs_softcore_strain, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_strain(sc, NULL));) \
    X(sc_step_size_nullout, odhs_softcore_step_size, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_step_size(sc, NULL));) \
    X(sc_energy_nullout, odhs_softcore_energy, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_energy(sc, NULL));) \
    X(sc_kinetic_energy_nullout, odhs_softcore_kinetic_energy, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_kinetic_energy(sc, NULL));) \
    X(sc_max_force_nullout, odhs_softcore_max_force, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_max_force(sc, NULL));) \
    X(sc_pressure_nullout, odhs_softcore_pressure, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_pressure(sc, NULL));) \
    X(sc_max_overlap_nullout, odhs_softcore_max_overlap, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_max_overlap(sc, NULL));) \
    X(sc_forces_nullout, odhs_softcore_forces, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_forces(sc, NULL));) \
    X(sc_vels_nullout, odhs_softcore_velocities, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_velocities(sc, NULL));) \
    X(sc_stress_nullout, odhs_softcore_stress, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_stress(sc, ODHS_SOFTCORE_STRESS_TOTAL, NULL));) \
    X(sc_stress_part, odhs_softcore_stress, ODHS_E_INVALID, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_stress(sc, 4, w->x0));) \
    X(sc_coord_nullout, odhs_softcore_coordination, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_coordination(sc, 1, NULL));) \
    X(sc_relax_state, odhs_softcore_relaxation_stress, ODHS_E_STATE, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_relaxation_stress(sc, w->x0));) \
    X(sc_relax_nullout, odhs_softcore_relaxation_stress, ODHS_E_NULL, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_relaxation_stress(sc, NULL));) \
    X(sc_reset_ok, odhs_softcore_reset, ODHS_OK, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, odhs_softcore_reset(sc));) \
    X(sc_counts_ok, odhs_softcore_counts, ODHS_OK, NOALT, H_NONE, 0, odhs_softcore *sc = sc_new(w); if (!sc) return post("create"); return sc_done(sc, sc_counts(sc));)

/* the analysis calls (analysis.h, 0.2.7) */
#define ANALYSIS_CASES(X)                                                                                      \
    X(an_stats_null, odhs_series_stats_compute, ODHS_E_NULL, NOALT, H_NONE, 0,                                 \
      double x[8] = {0}; (void)x; return odhs_series_stats_compute(x, 8, NULL);)                               \
    X(an_stats_short, odhs_series_stats_compute, ODHS_E_EMPTY, NOALT, H_NONE, 0,                               \
      double x[3] = {1, 2, 3}; odhs_series_stats o; memset(&o, 0, sizeof o); o.size = sizeof o;                \
      int rc = odhs_series_stats_compute(x, 3, &o);                                                            \
      return o.n != 0 ? post("output written") : !odhs_last_error()[0] ? post("no message") : rc;)             \
    X(an_stats_nan, odhs_series_stats_compute, ODHS_E_NONFINITE, NOALT, H_NONE, 0,                             \
      double x[6] = {1, 2, NAN_, 3, 4, 5}; odhs_series_stats o; memset(&o, 0, sizeof o); o.size = sizeof o;    \
      return odhs_series_stats_compute(x, 6, &o);)                                                             \
    X(an_stats_size0, odhs_series_stats_compute, ODHS_E_INVALID, NOALT, H_NONE, 0,                             \
      double x[6] = {1, 2, 3, 4, 5, 6}; odhs_series_stats o; memset(&o, 0, sizeof o);                          \
      return odhs_series_stats_compute(x, 6, &o);)                                                             \
    X(an_acf_lag, odhs_series_autocorrelation, ODHS_E_RANGE, NOALT, H_NONE, 0,                                 \
      double x[6] = {1, 2, 3, 4, 5, 6}, rho[8]; return odhs_series_autocorrelation(x, 6, 6, rho);)             \
    X(an_acf_null, odhs_series_autocorrelation, ODHS_E_NULL, NOALT, H_NONE, 0,                                 \
      double x[6] = {1, 2, 3, 4, 5, 6}; return odhs_series_autocorrelation(x, 6, 2, NULL);)                    \
    X(an_hist_range, odhs_histogram, ODHS_E_INVALID, NOALT, H_NONE, 0,                                         \
      double x[2] = {1, 2}, e[3], d[2]; return odhs_histogram(x, 2, 1.0, 1.0, 2, 0, e, d, NULL, NULL);)        \
    X(an_hist_log0, odhs_histogram, ODHS_E_INVALID, NOALT, H_NONE, 0,                                          \
      double x[2] = {1, 2}, e[3], d[2]; return odhs_histogram(x, 2, 0.0, 3.0, 2, 1, e, d, NULL, NULL);)        \
    X(an_hist_empty, odhs_histogram, ODHS_E_EMPTY, NOALT, H_NONE, 0,                                           \
      double x[2] = {1, 2}, e[3], d[2]; return odhs_histogram(x, 2, 0.0, 3.0, 0, 0, e, d, NULL, NULL);)        \
    X(an_hist_nan, odhs_histogram, ODHS_E_NONFINITE, NOALT, H_NONE, 0,                                         \
      double x[2] = {1, INF_}, e[3], d[2]; return odhs_histogram(x, 2, 0.0, 3.0, 2, 0, e, d, NULL, NULL);)     \
    X(an_hist_null, odhs_histogram, ODHS_E_NULL, NOALT, H_NONE, 0,                                             \
      double x[2] = {1, 2}, d[2]; return odhs_histogram(x, 2, 0.0, 3.0, 2, 0, NULL, d, NULL, NULL);)           \
    X(an_pow_xmax, odhs_power_law_exponent, ODHS_E_INVALID, NOALT, H_NONE, 0,                                  \
      double x[2] = {1, 2}, a; return odhs_power_law_exponent(x, 2, 0.0, &a, NULL, NULL);)                     \
    X(an_pow_few, odhs_power_law_exponent, ODHS_E_EMPTY, NOALT, H_NONE, 0,                                     \
      double x[3] = {0.5, 2, 3}, a = 7; int rc = odhs_power_law_exponent(x, 3, 1.0, &a, NULL, NULL);           \
      return a != 7 ? post("output written") : rc;)                                                            \
    X(an_pow_null, odhs_power_law_exponent, ODHS_E_NULL, NOALT, H_NONE, 0,                                     \
      double x[2] = {1, 2}; return odhs_power_law_exponent(x, 2, 1.0, NULL, NULL, NULL);)                      \
    X(an_backbone_null, odhs_backbone_forces, ODHS_E_NULL, NOALT, H_NONE, 0,                                   \
      size_t n; return odhs_backbone_forces(NULL, 0, &n, NULL);)                                               \
    X(an_backbone_null_n, odhs_backbone_forces, ODHS_E_NULL, NOALT, H_NET2, 0,                                 \
      return odhs_backbone_forces(w->net2, 0, NULL, NULL);)                                                    \
    X(an_gaps_null, odhs_packing_gaps, ODHS_E_NULL, NOALT, H_NONE, 0,                                          \
      size_t n; return odhs_packing_gaps(NULL, w->net2, 0.1, 0, &n, NULL, NULL, NULL, NULL);)                  \
    X(an_gaps_maxgap, odhs_packing_gaps, ODHS_E_INVALID, NOALT, H_SYS2, 0,                                     \
      size_t n = 5; int rc = odhs_packing_gaps(w->sys2, w->net2, 2.0, 0, &n, NULL, NULL, NULL, NULL);          \
      return n != 5 ? post("count written") : rc;)                                                             \
    X(an_gaps_other_net, odhs_packing_gaps, ODHS_E_DIM, NOALT, H_SYS3, 0,                                      \
      size_t n; return odhs_packing_gaps(w->sys3, w->net2, 0.1, 0, &n, NULL, NULL, NULL, NULL);)               \
    X(an_gaps_bare, odhs_packing_gaps, ODHS_E_STATE, NOALT, H_BARE, 0,                                         \
      size_t n; return odhs_packing_gaps(w->bare, w->net2, 0.1, 0, &n, NULL, NULL, NULL, NULL);)               \
    X(an_vcorr_null, odhs_velocity_correlation, ODHS_E_NULL, NOALT, H_SYS2, 0,                                 \
      double g[4]; return odhs_velocity_correlation(w->sys2, NULL, 0.5, 4, g, NULL);)                          \
    X(an_vcorr_width, odhs_velocity_correlation, ODHS_E_INVALID, NOALT, H_SYS2, 0,                             \
      double V[32] = {0}, g[4]; return odhs_velocity_correlation(w->sys2, V, -1.0, 4, g, NULL);)               \
    X(an_vcorr_zero, odhs_velocity_correlation, ODHS_E_EMPTY, NOALT, H_SYS2, 0,                                \
      double V[32] = {0}, g[4]; return odhs_velocity_correlation(w->sys2, V, 0.5, 4, g, NULL);)                \
    X(an_vcorr_nan, odhs_velocity_correlation, ODHS_E_NONFINITE, NOALT, H_SYS2, 0,                             \
      double V[32] = {0}, g[4]; V[3] = NAN_; return odhs_velocity_correlation(w->sys2, V, 0.5, 4, g, NULL);)   \
    X(an_min_null, odhs_correlation_minimum, ODHS_E_NULL, NOALT, H_NONE, 0,                                    \
      double g[3] = {1, 0, 1}; return odhs_correlation_minimum(g, 3, NULL, NULL);)                             \
    X(an_collapse_null, odhs_collapse_fit, ODHS_E_NULL, NOALT, H_NONE, 0,                                      \
      double a[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9}; return odhs_collapse_fit(a, a, a, NULL, 9, 3, NULL, NULL);)   \
    X(an_collapse_few, odhs_collapse_fit, ODHS_E_EMPTY, NOALT, H_NONE, 0,                                      \
      double a[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9}; odhs_collapse c; memset(&c, 0, sizeof c); c.size = sizeof c;  \
      int rc = odhs_collapse_fit(a, a, a, NULL, 7, 3, NULL, &c); return c.y != 0 ? post("written") : rc;)      \
    X(an_collapse_degree, odhs_collapse_fit, ODHS_E_INVALID, NOALT, H_NONE, 0,                                 \
      double a[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9}; odhs_collapse c; memset(&c, 0, sizeof c); c.size = sizeof c;  \
      return odhs_collapse_fit(a, a, a, NULL, 9, 8, NULL, &c);)                                                \
    X(an_collapse_rate, odhs_collapse_fit, ODHS_E_INVALID, NOALT, H_NONE, 0,                                   \
      double a[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9}, r[9] = {1, 2, 3, 4, 0, 6, 7, 8, 9};                            \
      odhs_collapse c; memset(&c, 0, sizeof c); c.size = sizeof c;                                             \
      return odhs_collapse_fit(a, r, a, NULL, 9, 3, NULL, &c);)                                                \
    X(an_collapse_nan, odhs_collapse_fit, ODHS_E_NONFINITE, NOALT, H_NONE, 0,                                  \
      double a[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9}, v[9] = {1, 2, 3, 4, NAN_, 6, 7, 8, 9};                         \
      odhs_collapse c; memset(&c, 0, sizeof c); c.size = sizeof c;                                             \
      return odhs_collapse_fit(a, a, v, NULL, 9, 3, NULL, &c);)                                                \
    X(an_collapse_size0, odhs_collapse_fit, ODHS_E_INVALID, NOALT, H_NONE, 0,                                  \
      double a[9] = {1, 2, 3, 4, 5, 6, 7, 8, 9}; odhs_collapse c; memset(&c, 0, sizeof c);                     \
      return odhs_collapse_fit(a, a, a, NULL, 9, 3, NULL, &c);)                                                \
    X(an_min_none, odhs_correlation_minimum, ODHS_E_EMPTY, NOALT, H_NONE, 0,                                   \
      double g[3] = {1, 0.5, 0.2}, x = 9; int rc = odhs_correlation_minimum(g, 3, &x, NULL);                   \
      return x != 9 ? post("output written") : rc;)

/* the embedding calls of 0.2.7 (issue 19): messages of failed creates,
 * solver names, the system's change counter, step info with a size, run
 * limits, bulk contacts */
#define EMBED_CASES(X)                                                                                         \
    X(last_error_create, odhs_last_error, ODHS_OK, NOALT, H_NONE, 0,                                           \
      odhs_solver *q = NULL; int rc = odhs_solver_create_by_name("bogus", &q);                                 \
      if (rc != ODHS_E_INVALID || q) return post("create_by_name(bogus) -> %d", rc);                           \
      if (!strstr(odhs_last_error(), "bogus") || !strstr(odhs_last_error(), "cholmod"))                        \
          return post("last_error \"%s\" names neither the name nor the valid ones", odhs_last_error());       \
      if (odhs_solver_create_by_name("cg", &q) != ODHS_OK) return post("cg not created");                      \
      odhs_solver_destroy(q);                                                                                  \
      return odhs_last_error()[0] ? post("last_error \"%s\" after a success", odhs_last_error()) : ODHS_OK;)   \
    X(solver_list_null, odhs_solver_list, ODHS_E_NULL, NOALT, H_NONE, 0, return odhs_solver_list(0, NULL, NULL);) \
    X(solver_list_end, odhs_solver_list, ODHS_E_RANGE, NOALT, H_NONE, 0,                                       \
      const char *nm = "x"; int rc = odhs_solver_list(1000, &nm, NULL);                                        \
      return nm ? post("name not NULL past the end") : rc;)                                                    \
    X(sys_change_count_null, odhs_system_change_count, ODHS_E_NULL, NOALT, H_NONE, 0,                          \
      uint64_t c; return odhs_system_change_count(NULL, &c);)                                                  \
    X(sys_change_count_null_out, odhs_system_change_count, ODHS_E_NULL, NOALT, H_SYS2, 0,                      \
      return odhs_system_change_count(w->sys2, NULL);)                                                         \
    X(drv_clear_time_unit_null, odhs_driver_clear_time_unit, ODHS_E_NULL, NOALT, H_NONE, 0,                    \
      return odhs_driver_clear_time_unit(NULL);)                                                               \
    X(st_step_ex_null, odhs_stepper_step_ex, ODHS_E_NULL, NOALT, H_NONE, 0,                                    \
      odhs_step_info in = {sizeof in, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0, 0};                                  \
      return odhs_stepper_step_ex(NULL, &in);)                                                                 \
    X(st_step_ex_null_info, odhs_stepper_step_ex, ODHS_E_NULL, NOALT, H_ST, 0,                                 \
      return odhs_stepper_step_ex(w->st, NULL);)                                                               \
    X(st_step_ex_size0, odhs_stepper_step_ex, ODHS_E_INVALID, NOALT, H_RUN, 0,                                 \
      odhs_step_info in; memset(&in, 0xab, sizeof in); in.size = 0;                                            \
      int rc = odhs_stepper_step_ex(w->run, &in);                                                              \
      return in.kind != (int)0xabababab ? post("info written on error") : rc;)                                 \
    X(st_set_run_limits_null, odhs_stepper_set_run_limits, ODHS_E_NULL, NOALT, H_NONE, 0,                      \
      return odhs_stepper_set_run_limits(NULL, 0, 0);)                                                         \
    X(st_get_run_limits_null, odhs_stepper_get_run_limits, ODHS_E_NULL, NOALT, H_NONE, 0,                      \
      uint64_t a, b; return odhs_stepper_get_run_limits(NULL, &a, &b);)                                        \
    X(st_contacts_null, odhs_stepper_contacts, ODHS_E_NULL, NOALT, H_NONE, 0,                                  \
      size_t nc; return odhs_stepper_contacts(NULL, 0, &nc, NULL, NULL, NULL, NULL, NULL);)                    \
    X(st_contacts_null_nc, odhs_stepper_contacts, ODHS_E_NULL, NOALT, H_RUN, 0,                                \
      return odhs_stepper_contacts(w->run, 0, NULL, NULL, NULL, NULL, NULL, NULL);)                            \
    X(st_contacts_not_ready, odhs_stepper_contacts, ODHS_E_STATE, NOALT, H_ST, 0,                              \
      size_t nc = 7; return odhs_stepper_contacts(w->st, 0, &nc, NULL, NULL, NULL, NULL, NULL);)               \
    X(net_get_contacts_null, odhs_network_get_contacts, ODHS_E_NULL, NOALT, H_NONE, 0,                         \
      size_t i[4]; return odhs_network_get_contacts(NULL, i, NULL, NULL);)                                     \
    X(net_get_contacts_no_out, odhs_network_get_contacts, ODHS_E_NULL, NOALT, H_NET2, 0,                       \
      return odhs_network_get_contacts(w->net2, NULL, NULL, NULL);)                                            \
    X(st_set_pre_event_null, odhs_stepper_set_pre_event_stress, ODHS_E_NULL, NOALT, H_NONE, 0,                 \
      return odhs_stepper_set_pre_event_stress(NULL, 1);)                                                      \
    X(st_set_pre_event_two, odhs_stepper_set_pre_event_stress, ODHS_E_INVALID, NOALT, H_RUN, 0,                \
      return odhs_stepper_set_pre_event_stress(w->run, 2);)                                                    \
    X(st_pre_event_null, odhs_stepper_pre_event_stress, ODHS_E_NULL, NOALT, H_NONE, 0,                         \
      double sg[9]; return odhs_stepper_pre_event_stress(NULL, sg);)                                           \
    X(st_pre_event_null_out, odhs_stepper_pre_event_stress, ODHS_E_NULL, NOALT, H_RUN, 0,                      \
      return odhs_stepper_pre_event_stress(w->run, NULL);)                                                     \
    X(st_pre_event_off, odhs_stepper_pre_event_stress, ODHS_E_STATE, NOALT, H_RUN, 0,                          \
      double sg[9]; return odhs_stepper_pre_event_stress(w->run, sg);)                                         \
    X(an_split_null, odhs_series_event_split, ODHS_E_NULL, NOALT, H_NONE, 0,                                   \
      double b[2] = {1, 2}; size_t nj, nd; return odhs_series_event_split(b, NULL, NULL, 2, NULL, &nj, NULL, &nd);) \
    X(an_split_empty, odhs_series_event_split, ODHS_E_EMPTY, NOALT, H_NONE, 0,                                 \
      double b[2] = {1, 2}; unsigned char e[2] = {1, 1}; size_t nj, nd;                                       \
      return odhs_series_event_split(b, b, e, 0, NULL, &nj, NULL, &nd);)                                       \
    X(an_split_nan, odhs_series_event_split, ODHS_E_NONFINITE, NOALT, H_NONE, 0,                               \
      double b[2] = {1, 2}, a[2] = {NAN_, 2}; unsigned char e[2] = {1, 1}; size_t nj, nd;                     \
      return odhs_series_event_split(b, a, e, 2, NULL, &nj, NULL, &nd);)

#define REGRESSION_CASES(X)                                                                             \
    X(reg_wrap_far_positions, odhs_system_set_configuration, ODHS_OK, NOALT, H_NONE, F_NOPROBE,                \
      /* system.h: positions passed in are wrapped into [0,Lx) x [0,Ly); coordinates more than 2^50 box     \
       * lengths away are refused (ODHS_E_INVALID). The wrap used to leave NaN (x/L overflows) or values     \
       * many box lengths outside (floor(x/L)*L rounding) */                                                  \
      return wrap_far_cases();)                                                                                \
    X(reg_strain_remap_range, odhs_system_set_strain, ODHS_OK, NOALT, H_NONE, F_NOPROBE,                        \
      /* system.h: the strain is kept in [-Lx/(2Ly), Lx/(2Ly)] and get_strain returns a value there; setting  \
       * the value it returns must not change it (io.h's bit-exact XYZ round trip depends on it); beyond     \
       * 2^50 Lx/Ly it is refused (ODHS_E_INVALID). It used to land a hair outside, or at -3e290 */           \
      return strain_remap_cases();)                                                                            \
    X(reg_stepper_huge_rate, odhs_stepper_step, ODHS_OK, NOALT, H_NONE, F_NOPROBE,                              \
      /* driver.h: any finite shear rate. stepper.h: a step succeeds, or fails with the configuration rolled  \
       * back and a message. A rate of 1e308 used to "succeed" with non-finite positions */                   \
      return huge_rate_case();)                                                                                \
    X(reg_cert_null_message, odhs_stepper_certificate, ODHS_E_NULL, NOALT, H_RUN, 0,                            \
      /* the message of a failed stepper call belongs on the stepper (docs/guide.md: each handle keeps a    \
       * specific message); it used to be written on the stepper's network */                                 \
      return odhs_stepper_certificate(w->run, NULL);)                                                          \
    X(reg_cert_size0_message, odhs_stepper_certificate, ODHS_E_INVALID, NOALT, H_RUN, 0,                        \
      odhs_jam_certificate c; memset(&c, 0, sizeof c); c.size = 0; return odhs_stepper_certificate(w->run, &c);) \
    X(reg_solve_nan_guess, odhs_solver_solve, ODHS_E_NONFINITE, ODHS_OK, H_CG, 0,                               \
      /* common.h: ODHS_E_NONFINITE when a NaN is given; a NaN initial guess (cg uses x on input) used to   \
       * end as ODHS_E_NOCONV. Now the guess is replaced by zeros: OK with a finite solution */               \
      double b[256], x[256]; for (int c = 0; c < 256; ++c) { b[c] = 1.0; x[c] = 0.0; } x[0] = NAN_;           \
      int rc = odhs_solver_solve(w->cg, odhs_stepper_network(w->run), b, x);                                   \
      for (size_t c = 0; rc == ODHS_OK && c < odhs_network_count(odhs_stepper_network(w->run)); ++c)           \
          if (!isfinite(x[c])) return post("OK with a non-finite solution");                                   \
      return rc;)

/* softcore rows: a handle on sys2 made for the row; the bad call must leave a
 * message on it; create/destroy do not change sys2 */
static odhs_softcore *sc_new(world *w)
{
    odhs_softcore *sc = NULL;
    return odhs_softcore_create(w->sys2, &sc) == ODHS_OK ? sc : NULL;
}
static int sc_done(odhs_softcore *sc, int rc)
{
    int msg = odhs_softcore_errmsg(sc)[0] != '\0';
    odhs_softcore_destroy(sc);
    if (rc < 0 && !msg) return post("error %d without a message on the softcore handle", rc);
    return rc;
}
static int sc_pos_nan(world *w, odhs_softcore *sc)
{
    odhs_system_get_positions(w->sys2, w->x0);
    w->x0[5] = NAN_;
    return odhs_softcore_set_positions(sc, w->x0);
}
static int sc_pos_far(world *w, odhs_softcore *sc)
{
    odhs_system_get_positions(w->sys2, w->x0);
    w->x0[3] = 1e300;
    return odhs_softcore_set_positions(sc, w->x0);
}
static int sc_vel_nan(odhs_softcore *sc)
{
    double u[32] = {0};
    u[7] = INF_;
    return odhs_softcore_set_velocities(sc, u);
}
/* a minimisation that cannot converge in one iteration: overlaps made by an
 * affine shear of the handle's own copy of the state; rolled back, so the
 * system (sys2) is unchanged */
static int sc_noconv(world *w, odhs_softcore *sc)
{
    double x[32], y[32];
    odhs_system_get_positions(w->sys2, x);
    memcpy(y, x, sizeof y);
    y[2] = x[0] + 0.3; /* particle 1 onto particle 0: a large overlap */
    y[3] = x[1];
    odhs_softcore_set_min_tolerance(sc, 1e-300, 1);
    odhs_softcore_set_positions(sc, y);
    int rc = odhs_softcore_minimise(sc, NULL);
    /* sys2 back bit for bit, through the system: a successful call on the
     * softcore handle would clear the message sc_done checks */
    odhs_system_set_positions(w->sys2, x);
    return rc;
}
static int sc_counts(odhs_softcore *sc)
{
    uint64_t a = 1, b = 1, c = 1;
    int rc = odhs_softcore_counts(sc, &a, &b, &c);
    return rc == ODHS_OK && a == 0 && c == 0 ? ODHS_OK : post("counts of a new handle not zero");
}

/* ---- table machinery ------------------------------------------------------------ */
typedef int (*bad_fn)(world *w);

typedef struct {
    const char *func; /* the public function exercised */
    const char *id;
    bad_fn call;
    int expect, alt;
    int errh;
    unsigned flags;
} bad_case;

/* helpers used by some bodies (declared before the bodies are expanded) */
static int mkdir_p(const char *p);
static size_t count_files(const char *dir);

#define X_DEFINE(id, func, expect, alt, errh, flags, ...) \
    static int bad_##id(world *w)                         \
    {                                                     \
        (void)w;                                          \
        __VA_ARGS__                                       \
    }
#define X_ROW(id, func, expect, alt, errh, flags, ...) {#func, #id, bad_##id, expect, alt, errh, flags},

COMMON_CASES(X_DEFINE)
SYSTEM_CASES(X_DEFINE)
IO_CASES(X_DEFINE)
NETWORK_CASES(X_DEFINE)
SOLVER_CASES(X_DEFINE)
DRIVER_CASES(X_DEFINE)
STEPPER_CASES(X_DEFINE)
JAMMING_CASES(X_DEFINE)
CHECKPOINT_CASES(X_DEFINE)
SOFTCORE_CASES(X_DEFINE)
OUTPUT_CASES(X_DEFINE)
EMBED_CASES(X_DEFINE)
ANALYSIS_CASES(X_DEFINE)
REGRESSION_CASES(X_DEFINE)

static const bad_case common_cases[] = {COMMON_CASES(X_ROW)};
static const bad_case system_cases[] = {SYSTEM_CASES(X_ROW)};
static const bad_case io_cases[] = {IO_CASES(X_ROW)};
static const bad_case network_cases[] = {NETWORK_CASES(X_ROW)};
static const bad_case solver_cases[] = {SOLVER_CASES(X_ROW)};
static const bad_case driver_cases[] = {DRIVER_CASES(X_ROW)};
static const bad_case stepper_cases[] = {STEPPER_CASES(X_ROW)};
static const bad_case jamming_cases[] = {JAMMING_CASES(X_ROW)};
static const bad_case checkpoint_cases[] = {CHECKPOINT_CASES(X_ROW)};
static const bad_case softcore_cases[] = {SOFTCORE_CASES(X_ROW)};
static const bad_case output_cases[] = {OUTPUT_CASES(X_ROW)};
static const bad_case embed_cases[] = {EMBED_CASES(X_ROW)};
static const bad_case analysis_cases[] = {ANALYSIS_CASES(X_ROW)};
static const bad_case regression_cases[] = {REGRESSION_CASES(X_ROW)};

#define NROWS(t) ((int)(sizeof t / sizeof t[0]))

static const struct {
    const bad_case *rows;
    int n;
} all_tables[] = {
    {common_cases, NROWS(common_cases)},   {system_cases, NROWS(system_cases)},
    {io_cases, NROWS(io_cases)},           {network_cases, NROWS(network_cases)},
    {solver_cases, NROWS(solver_cases)},   {driver_cases, NROWS(driver_cases)},
    {stepper_cases, NROWS(stepper_cases)}, {jamming_cases, NROWS(jamming_cases)},
    {checkpoint_cases, NROWS(checkpoint_cases)}, {softcore_cases, NROWS(softcore_cases)},
    {output_cases, NROWS(output_cases)},   {embed_cases, NROWS(embed_cases)},
    {analysis_cases, NROWS(analysis_cases)},
    {regression_cases, NROWS(regression_cases)},
};

static int mkdir_p(const char *p)
{
    return mkdir(p, 0700) == 0 ? 0 : -1;
}

static size_t count_files(const char *dir)
{
    DIR *d = opendir(dir);
    size_t n = 0;
    if (!d) return 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) n++;
    closedir(d);
    return n;
}

/* run one row: the checks of the file comment. The worlds are freed before
 * any assertion (Check's no-fork mode leaves a test by longjmp). */
static void run_row(const bad_case *c)
{
    world w, fresh;
    char fail[700] = "";
    world_build(&w);
    world_build(&fresh);
    if (!w.ok || !fresh.ok) {
        snprintf(fail, sizeof fail, "%s: could not build the world: %s", c->id, w.ok ? fresh.why : w.why);
        goto done;
    }
    post_msg[0] = '\0';
    int rc = c->call(&w);
    if (rc == POST_FAIL) {
        snprintf(fail, sizeof fail, "%s (%s): %s", c->id, c->func, post_msg);
        goto done;
    }
    if (!(rc == c->expect || (c->alt != NOALT && rc == c->alt))) {
        snprintf(fail, sizeof fail, "%s (%s): returned %d (%s), expected %d (%s)%s", c->id, c->func, rc,
                 odhs_strerror(rc), c->expect, odhs_strerror(c->expect),
                 c->alt != NOALT ? " or the alternative" : "");
        goto done;
    }
    if (c->errh != H_NONE && rc < 0) {
        const char *m = handle_errmsg(&w, c->errh);
        if (m == NULL || m[0] == '\0') {
            snprintf(fail, sizeof fail, "%s (%s): error %d but the handle's message is empty", c->id, c->func, rc);
            goto done;
        }
    }
    if (!(c->flags & F_NOPROBE)) {
        const char *diff = probe_world(&w, &fresh);
        if (diff) snprintf(fail, sizeof fail, "%s (%s): afterwards %s", c->id, c->func, diff);
    }
done:
    world_free(&w);
    world_free(&fresh);
    ck_assert_msg(fail[0] == '\0', "%s", fail);
}

#define TABLE_TEST(name, table)            \
    START_TEST(name) { run_row(&table[_i]); } \
    END_TEST

TABLE_TEST(test_common, common_cases)
TABLE_TEST(test_system, system_cases)
TABLE_TEST(test_io, io_cases)
TABLE_TEST(test_network, network_cases)
TABLE_TEST(test_solver, solver_cases)
TABLE_TEST(test_driver, driver_cases)
TABLE_TEST(test_stepper, stepper_cases)
TABLE_TEST(test_jamming, jamming_cases)
TABLE_TEST(test_checkpoint, checkpoint_cases)
TABLE_TEST(test_softcore, softcore_cases)
TABLE_TEST(test_output, output_cases)
TABLE_TEST(test_embed, embed_cases)
TABLE_TEST(test_analysis, analysis_cases)
TABLE_TEST(test_regression, regression_cases)

/* ---- coverage: every function declared in the public headers has a row ----- */
static int covered(const char *name)
{
    for (size_t t = 0; t < sizeof all_tables / sizeof all_tables[0]; ++t)
        for (int k = 0; k < all_tables[t].n; ++k)
            if (!strcmp(all_tables[t].rows[k].func, name)) return 1;
    return 0;
}

/* names of the functions declared (ODHS_API ... name(...);) in one header */
static size_t header_functions(const char *path, char names[][64], size_t max, size_t n)
{
    FILE *f = fopen(path, "r");
    if (!f) return n;
    static char text[1 << 18];
    size_t len = fread(text, 1, sizeof text - 1, f);
    fclose(f);
    text[len] = '\0';
    for (char *p = strstr(text, "ODHS_API"); p; p = strstr(p + 8, "ODHS_API")) {
        char *ls = p;
        while (ls > text && ls[-1] != '\n') ls--;
        while (*ls == ' ' || *ls == '\t') ls++;
        if (*ls == '#') continue; /* the macro's own definition */
        char *semi = strchr(p, ';'), *paren = strchr(p, '(');
        if (!semi || !paren || paren > semi) continue; /* a variable, e.g. a solver type */
        char *e = paren;
        while (e > p && (e[-1] == ' ' || e[-1] == '\n')) e--;
        char *s = e;
        while (s > p && (s[-1] == '_' || (s[-1] >= 'a' && s[-1] <= 'z') || (s[-1] >= 'A' && s[-1] <= 'Z') ||
                         (s[-1] >= '0' && s[-1] <= '9')))
            s--;
        if (e - s <= 0 || e - s >= 64 || n >= max) continue;
        memcpy(names[n], s, (size_t)(e - s));
        names[n][e - s] = '\0';
        n++;
    }
    return n;
}

START_TEST(test_coverage)
{
    static char names[1024][64];
    const char *dirs[] = {"include/odhs", "../include/odhs", "../../include/odhs"};
    const char *dir = NULL;
    DIR *d = NULL;
    for (size_t k = 0; k < 3 && !d; ++k)
        if ((d = opendir(dirs[k])) != NULL) dir = dirs[k];
    if (!d) {
        fprintf(stderr, "[badinput] coverage: include/odhs not found from the working directory: skipped\n");
        return;
    }
    size_t n = 0, nheaders = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        size_t l = strlen(e->d_name);
        if (l < 3 || strcmp(e->d_name + l - 2, ".h") != 0) continue;
        char p[512];
        snprintf(p, sizeof p, "%s/%s", dir, e->d_name);
        n = header_functions(p, names, 1024, n);
        nheaders++;
    }
    closedir(d);
    ck_assert_msg(n > 50, "only %zu functions found in %zu headers under %s", n, nheaders, dir);
    char missing[2048] = "";
    size_t nmiss = 0;
    for (size_t k = 0; k < n; ++k)
        if (!covered(names[k])) {
            nmiss++;
            if (strlen(missing) + strlen(names[k]) + 2 < sizeof missing) {
                strcat(missing, " ");
                strcat(missing, names[k]);
            }
        }
    size_t rows = 0;
    for (size_t t = 0; t < sizeof all_tables / sizeof all_tables[0]; ++t) rows += (size_t)all_tables[t].n;
    fprintf(stderr, "[badinput] %zu public functions in %zu headers, %zu rows, %zu functions without a row\n", n,
            nheaders, rows, nmiss);
    ck_assert_msg(nmiss == 0, "%zu public functions have no bad-input row:%s", nmiss, missing);
}
END_TEST

/* ========================================================================== */
Suite *make_badinput_suite(void)
{
    Suite *s = suite_create("badinput");
    struct {
        const char *name;
        const TTest *test;
        int n;
    } tcs[] = {
        {"common", test_common, NROWS(common_cases)},       {"system", test_system, NROWS(system_cases)},
        {"io", test_io, NROWS(io_cases)},                   {"network", test_network, NROWS(network_cases)},
        {"solver", test_solver, NROWS(solver_cases)},       {"driver", test_driver, NROWS(driver_cases)},
        {"stepper", test_stepper, NROWS(stepper_cases)},    {"jamming", test_jamming, NROWS(jamming_cases)},
        {"checkpoint", test_checkpoint, NROWS(checkpoint_cases)},
        {"softcore", test_softcore, NROWS(softcore_cases)},
        {"output", test_output, NROWS(output_cases)},
        {"embed", test_embed, NROWS(embed_cases)},
        {"analysis", test_analysis, NROWS(analysis_cases)},
        {"regression", test_regression, NROWS(regression_cases)},
    };
    for (size_t k = 0; k < sizeof tcs / sizeof tcs[0]; ++k) {
        TCase *tc = tcase_create(tcs[k].name);
        tcase_set_timeout(tc, 600);
        tcase_add_loop_test(tc, tcs[k].test, 0, tcs[k].n);
        suite_add_tcase(s, tc);
    }
    TCase *tc = tcase_create("coverage");
    tcase_add_test(tc, test_coverage);
    suite_add_tcase(s, tc);
    return s;
}
