/*
 * libodhs - allocation-failure tests (issue "Reliability").
 *
 * Built for real only with -DODHS_FAULT_INJECTION (`make check-allocfail`,
 * which also turns on ASan/UBSan and LeakSanitizer). The library then counts
 * its allocations per thread and can make the n-th one fail, once or from
 * then on (lib/util.c, odhs__fault_* in lib/internal.h). For every scenario
 * below (a list of operations on handles):
 *
 *   1. a reference run with counting only gives N_alloc, the status of every
 *      operation and the public state after each one;
 *   2. for n = 1..N_alloc, first failing allocation n only ("one-shot"),
 *      then n and every later one ("sticky": memory stays short, so error
 *      paths must not need any): fresh fixture, arm, run the operations
 *      until one returns an error, disarm, then check that
 *        - the failure fired and the failing operation returned ODHS_E_NOMEM
 *          (every operation before it returned what it did in the reference:
 *          no failure may hide behind a warning);
 *        - the public state of every handle is what it was before the failing
 *          operation (positions, box, strain, radii, species, contacts with
 *          their order, forces, gaps, normals, constrained subset, stepper
 *          time, strain, counters, kappa, velocities; files in the output
 *          directory): an error changes nothing, a failed stepper step is
 *          rolled back to the start of the step;
 *        - the handles still work: the failed operation and the rest of the
 *          scenario run again and give the reference statuses and, after
 *          every operation, the reference state bit for bit; then the
 *          network's index agrees with odhs_network_find and its constrained
 *          subset with one rebuilt from scratch, the system validates, the
 *          stepper steps on;
 *        - after destroying everything, every block the library allocated is
 *          freed (a per-thread live-block counter in the hook, checked after
 *          every n, so a leak names the scenario and n); LeakSanitizer also
 *          checks the whole heap after each scenario and at exit.
 *      A run in which the library absorbs the failed allocation (an optional
 *      buffer) is counted as "absorbed" and must still match the reference.
 *
 * In builds without the hook the suite holds one test that says so.
 *
 * Environment: ODHS_ALLOCFAIL_VERBOSE=1 prints every failing n;
 * ODHS_ALLOCFAIL_ONLY=name[,name...] walks only the scenarios named;
 * ODHS_ALLOCFAIL_N=n fails only allocation n (for a debugger).
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <check.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "internal.h"

#ifndef ODHS_FAULT_INJECTION

START_TEST(test_hook_not_built)
{
    /* The allocation-failure hook only exists in the test build made by
     * `make check-allocfail` (-DODHS_FAULT_INJECTION); nothing to walk here. */
    ck_assert(1);
}
END_TEST

Suite *make_allocfail_suite(void)
{
    Suite *s = suite_create("allocfail");
    TCase *tc = tcase_create("hook_not_built");
    tcase_add_test(tc, test_hook_not_built);
    suite_add_tcase(s, tc);
    return s;
}

#else /* ODHS_FAULT_INJECTION */

/* Assertions that talk to Check only when they fail: ck_assert_* records a
 * location message on every call, which a no-fork run replays at the end of
 * the test (quadratically); these helpers run millions of checks. */
#define AF_ASSERT(c)                                                                                         \
    do {                                                                                                     \
        if (!(c)) ck_abort_msg("%s:%d: assertion failed: %s", __FILE__, __LINE__, #c);                       \
    } while (0)
#define AF_MSG(c, ...)                                                                                       \
    do {                                                                                                     \
        if (!(c)) ck_abort_msg(__VA_ARGS__);                                                                 \
    } while (0)
#define AF_OK(expr)                                                                                          \
    do {                                                                                                     \
        int af_s_ = (expr);                                                                                  \
        if (af_s_ != ODHS_OK)                                                                                \
            ck_abort_msg("%s:%d: %s returned %d (%s)", __FILE__, __LINE__, #expr, af_s_,                     \
                         odhs_strerror(af_s_));                                                              \
    } while (0)

#include <dirent.h>
#include <math.h>
#include <time.h>
#include <unistd.h>

#if defined(__SANITIZE_ADDRESS__)
#define AF_LSAN 1
#elif defined(__has_feature)
#if __has_feature(address_sanitizer)
#define AF_LSAN 1
#endif
#endif
#ifdef AF_LSAN
#include <sanitizer/lsan_interface.h>
#endif

/* ---- byte buffer of typed records (a handle's public state) --------------- */
typedef struct {
    unsigned char *p;
    size_t n, cap;
} af_buf;

static void buf_put(af_buf *b, const void *src, size_t n)
{
    if (b->n + n > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->n + n) cap *= 2;
        unsigned char *q = realloc(b->p, cap);
        AF_ASSERT(q);
        b->p = q;
        b->cap = cap;
    }
    if (n) memcpy(b->p + b->n, src, n);
    b->n += n;
}

typedef struct {
    char tag[24];
    char type; /* 'd' doubles, 'z' size_t, 'i' int, 'u' uint64, 'c' bytes */
    size_t count;
} af_rec;

static void rec(af_buf *b, const char *tag, char type, const void *data, size_t count)
{
    af_rec r;
    memset(&r, 0, sizeof r);
    snprintf(r.tag, sizeof r.tag, "%s", tag);
    r.type = type;
    r.count = count;
    size_t es = type == 'd'   ? sizeof(double)
                : type == 'z' ? sizeof(size_t)
                : type == 'i' ? sizeof(int)
                : type == 'u' ? sizeof(uint64_t)
                              : 1;
    buf_put(b, &r, sizeof r);
    buf_put(b, data, es * count);
}

static void rec_i(af_buf *b, const char *tag, int v) { rec(b, tag, 'i', &v, 1); }
static void rec_z(af_buf *b, const char *tag, size_t v) { rec(b, tag, 'z', &v, 1); }
static void rec_d(af_buf *b, const char *tag, double v) { rec(b, tag, 'd', &v, 1); }

/* NULL if equal, else the tag of the first difference (static storage) */
static const char *buf_diff(const af_buf *a, const af_buf *b)
{
    static char where[64];
    size_t pa = 0, pb = 0;
    while (pa < a->n && pb < b->n) {
        af_rec ra, rb;
        memcpy(&ra, a->p + pa, sizeof ra);
        memcpy(&rb, b->p + pb, sizeof rb);
        if (strcmp(ra.tag, rb.tag) || ra.type != rb.type || ra.count != rb.count) {
            snprintf(where, sizeof where, "%s/%s (layout)", ra.tag, rb.tag);
            return where;
        }
        size_t es = ra.type == 'd'   ? sizeof(double)
                    : ra.type == 'z' ? sizeof(size_t)
                    : ra.type == 'i' ? sizeof(int)
                    : ra.type == 'u' ? sizeof(uint64_t)
                                     : 1;
        pa += sizeof ra;
        pb += sizeof rb;
        if (memcmp(a->p + pa, b->p + pb, es * ra.count)) {
            snprintf(where, sizeof where, "%s", ra.tag);
            return where;
        }
        pa += es * ra.count;
        pb += es * rb.count;
    }
    if (pa != a->n || pb != b->n) return "length";
    return NULL;
}

/* ---- public-state records of each handle kind ----------------------------- */
static void rec_system(af_buf *b, const char *tag, const odhs_system *s)
{
    char t[24];
    snprintf(t, sizeof t, "%s", tag);
    if (!s) {
        rec_i(b, t, -1);
        return;
    }
    int dim = odhs_system_dim(s);
    size_t n = odhs_system_count(s);
    rec_i(b, t, dim);
    rec_z(b, "n", n);
    double L[3] = {0, 0, 0}, g = 0.0;
    odhs_system_get_box(s, L);
    odhs_system_get_strain(s, &g);
    rec(b, "L", 'd', L, 3);
    rec_d(b, "gamma", g);
    double *v = malloc((n * 3 + 1) * sizeof *v);
    AF_ASSERT(v);
    int st = odhs_system_get_radii(s, v);
    rec_i(b, "has_r", st == ODHS_OK);
    if (st == ODHS_OK) rec(b, "r", 'd', v, n);
    st = odhs_system_get_positions(s, v);
    rec_i(b, "has_x", st == ODHS_OK);
    if (st == ODHS_OK) rec(b, "x", 'd', v, n * (size_t)dim);
    free(v);
    char(*lab)[ODHS_SPECIES_MAX + 1] = calloc(n, sizeof *lab);
    AF_ASSERT(lab);
    for (size_t i = 0; i < n; ++i) odhs_system_get_species(s, i, lab[i], sizeof lab[i]);
    rec(b, "species", 'c', lab, n * sizeof *lab);
    free(lab);
}

static void rec_network(af_buf *b, const char *tag, const odhs_network *net)
{
    if (!net) {
        rec_i(b, tag, -1);
        return;
    }
    size_t nc = odhs_network_count(net), n = odhs_network_particles(net);
    int dim = odhs_network_dim(net);
    rec_i(b, tag, dim);
    rec_z(b, "nc", nc);
    size_t *ij = malloc((2 * nc + 1) * sizeof *ij);
    int *kind = malloc((nc + 1) * sizeof *kind);
    AF_ASSERT(ij && kind);
    for (size_t k = 0; k < nc; ++k)
        AF_OK(odhs_network_get_contact(net, k, &ij[2 * k], &ij[2 * k + 1], &kind[k]));
    rec(b, "pairs", 'z', ij, 2 * nc);
    rec(b, "kinds", 'i', kind, nc);
    free(ij);
    free(kind);
    double *v = malloc((nc * 3 + 1) * sizeof *v);
    AF_ASSERT(v);
    odhs_network_get_forces(net, v);
    rec(b, "f", 'd', v, nc);
    odhs_network_get_gaps(net, v);
    rec(b, "gap", 'd', v, nc);
    odhs_network_get_normals(net, v);
    rec(b, "nrm", 'd', v, nc * (size_t)dim);
    free(v);
    size_t nbar = 0, ncon = 0;
    unsigned char *in = malloc(n + 1);
    AF_ASSERT(in);
    odhs_network_constrained(net, &nbar, &ncon, in, NULL);
    rec_z(b, "nbar", nbar);
    rec_z(b, "ncon", ncon);
    rec(b, "core", 'c', in, n);
    free(in);
}

static void rec_stepper(af_buf *b, const odhs_stepper *st)
{
    if (!st) {
        rec_i(b, "stepper", -1);
        return;
    }
    rec_i(b, "stepper", 1);
    double t = 0, g = 0, kappa = 0;
    odhs_stepper_time(st, &t);
    odhs_stepper_strain(st, &g);
    odhs_stepper_kappa(st, &kappa);
    rec_d(b, "time", t);
    rec_d(b, "strain", g);
    rec_d(b, "kappa", kappa);
    uint64_t c[4] = {0, 0, 0, 0};
    double h = 0.0;
    odhs_stepper_counts(st, &c[0], &c[1], &c[2]);
    odhs_stepper_adaptive_stats(st, &c[3], &h);
    rec(b, "counts", 'u', c, 4);
    rec_d(b, "h", h);
    const odhs_network *net = odhs_stepper_network(st);
    size_t nd = odhs_network_particles(net) * (size_t)odhs_network_dim(net);
    double *U = malloc((nd + 1) * sizeof *U);
    AF_ASSERT(U);
    int s = odhs_stepper_nonaffine_velocities(st, U);
    rec_i(b, "ready", s == ODHS_OK);
    if (s == ODHS_OK) rec(b, "U", 'd', U, nd);
    free(U);
    rec_network(b, "st.net", net);
}

static void rec_vec(af_buf *b, const char *tag, const double *v, size_t n)
{
    rec_i(b, tag, v != NULL);
    if (v) rec(b, "v", 'd', v, n);
}

/* sorted names in a directory */
static int cmp_str(const void *a, const void *b) { return strcmp(*(char *const *)a, *(char *const *)b); }

static void rec_dir(af_buf *b, const char *dir)
{
    char *names[64];
    size_t k = 0;
    DIR *d = opendir(dir);
    AF_ASSERT(d);
    struct dirent *e;
    while ((e = readdir(d)) != NULL) {
        if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
        AF_ASSERT(k < 64);
        names[k++] = strdup(e->d_name);
    }
    closedir(d);
    qsort(names, k, sizeof *names, cmp_str);
    rec_z(b, "dir", k);
    for (size_t i = 0; i < k; ++i) {
        rec(b, "name", 'c', names[i], strlen(names[i]) + 1);
        free(names[i]);
    }
}

static void rec_file(af_buf *b, const char *tag, const char *path)
{
    FILE *f = fopen(path, "rb");
    rec_i(b, tag, f != NULL);
    if (!f) return;
    af_buf c = {0};
    char chunk[4096];
    size_t got;
    while ((got = fread(chunk, 1, sizeof chunk, f)) > 0) buf_put(&c, chunk, got);
    fclose(f);
    rec(b, "bytes", 'c', c.p, c.n);
    free(c.p);
}

/* ---- consistency checks that hold after any failure -------------------- */
/* the pair index agrees with the contact list, and the incrementally kept
 * constrained subset with one computed on a network rebuilt from scratch */
static void check_network(const odhs_network *net, const char *what)
{
    size_t n = odhs_network_particles(net), nc = odhs_network_count(net), found = 0;
    for (size_t k = 0; k < nc; ++k) {
        size_t i, j, idx;
        AF_OK(odhs_network_get_contact(net, k, &i, &j, NULL));
        AF_OK(odhs_network_find(net, i, j, &idx));
        AF_MSG(idx == k, "%s: contact %zu (%zu,%zu) found at %zu", what, k, i, j, idx);
    }
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 1; j < n; ++j) {
            size_t idx;
            AF_OK(odhs_network_find(net, i, j, &idx));
            if (idx != SIZE_MAX) {
                AF_ASSERT(idx < nc);
                found++;
            }
        }
    AF_MSG(found == nc, "%s: %zu pairs found, Nc = %zu", what, found, nc);
    /* the constrained subset from scratch (this allocates: not armed here) */
    odhs_network *ref = odhs__net_new(odhs_network_dim(net), n);
    AF_ASSERT(ref);
    for (size_t k = 0; k < nc; ++k) {
        size_t i, j;
        int kind;
        odhs_network_get_contact(net, k, &i, &j, &kind);
        AF_OK(odhs_network_add(ref, i, j, kind));
    }
    size_t nb1, nc1, nb2, nc2;
    unsigned char *in1 = malloc(n), *in2 = malloc(n);
    AF_ASSERT(in1 && in2);
    odhs_network_constrained(net, &nb1, &nc1, in1, NULL);
    odhs_network_constrained(ref, &nb2, &nc2, in2, NULL);
    AF_MSG(nb1 == nb2 && nc1 == nc2 && !memcmp(in1, in2, n),
           "%s: constrained subset (%zu, %zu) differs from a rebuilt one (%zu, %zu)", what, nb1, nc1, nb2,
           nc2);
    free(in1);
    free(in2);
    odhs_network_destroy(ref);
}

/* ---- fixture and scenarios ------------------------------------------------ */
typedef struct {
    int dim;
    size_t n;
    double L[3], gamma;
    double *r, *x;
} af_config;

static void config_save(af_config *c, const odhs_system *s)
{
    c->dim = odhs_system_dim(s);
    c->n = odhs_system_count(s);
    c->L[0] = c->L[1] = c->L[2] = 1.0;
    odhs_system_get_box(s, c->L);
    odhs_system_get_strain(s, &c->gamma);
    c->r = malloc(c->n * sizeof *c->r);
    c->x = malloc(c->n * (size_t)c->dim * sizeof *c->x);
    AF_ASSERT(c->r && c->x);
    AF_OK(odhs_system_get_radii(s, c->r));
    AF_OK(odhs_system_get_positions(s, c->x));
}

static odhs_system *config_system(const af_config *c)
{
    odhs_system *s = NULL;
    AF_OK(odhs_system_create(c->dim, c->n, &s));
    AF_OK(odhs_system_set_configuration(s, c->L, c->gamma, c->r, c->x));
    return s;
}

typedef struct {
    odhs_system *sys, *sys2, *clone;
    odhs_network *net;
    odhs_solver *sol, *sol2;
    odhs_driver *drv, *drv2;
    odhs_stepper *st, *st2;
    odhs_softcore *soft;
    odhs_traj *tr;
    double *b, *g, *x1, *x2, *x3, *x4; /* libc memory, not counted */
    size_t nc;
    unsigned char mark[64];
    odhs_jam_certificate cert;
    double errs[2];
    size_t ci[256], cj[256]; /* odhs_stepper_contacts (shear_callback) */
    double cf[256];
    /* the analysis scenario's outputs */
    odhs_series_stats stats;
    double an_e[9], an_d[8], an_g[8], an_gap[256], an_series[512], an_V[64];
    size_t an_n[2];
    odhs_collapse coll;
    char dir[64], path1[128], path2[128], path3[128];
} af_fix;

struct af_scenario;
typedef struct af_scenario {
    const char *name;
    int nops; /* number of operations (0: ask probe) */
    int variant;
    void (*setup)(af_fix *f, const struct af_scenario *sc);
    /* number of operations when nops == 0 (an unarmed probe run) */
    int (*probe)(const struct af_scenario *sc);
    /* run operation k (0-based); its status */
    int (*op)(af_fix *f, const struct af_scenario *sc, int k);
    /* public state; op = the operation about to run (its failure must not
     * change what is recorded), or -1 for the final state */
    void (*capture)(const af_fix *f, const struct af_scenario *sc, int op, af_buf *b);
    /* checks on the final state (handles still work) */
    void (*final)(af_fix *f, const struct af_scenario *sc);
} af_scenario;

static void fix_init(af_fix *f)
{
    memset(f, 0, sizeof *f);
    strcpy(f->dir, "/tmp/odhs-allocfail-XXXXXX");
    AF_ASSERT(mkdtemp(f->dir));
    snprintf(f->path1, sizeof f->path1, "%s/one", f->dir);
    snprintf(f->path2, sizeof f->path2, "%s/two", f->dir);
    snprintf(f->path3, sizeof f->path3, "%s/three.xyz", f->dir);
}

static void fix_destroy(af_fix *f)
{
    odhs_traj_close(f->tr);
    odhs_softcore_destroy(f->soft);
    odhs_stepper_destroy(f->st2);
    odhs_stepper_destroy(f->st);
    odhs_network_destroy(f->net);
    odhs_solver_destroy(f->sol);
    odhs_solver_destroy(f->sol2);
    odhs_driver_destroy(f->drv);
    odhs_driver_destroy(f->drv2);
    odhs_system_destroy(f->sys);
    odhs_system_destroy(f->sys2);
    odhs_system_destroy(f->clone);
    free(f->b);
    free(f->g);
    free(f->x1);
    free(f->x2);
    free(f->x3);
    free(f->x4);
    DIR *d = opendir(f->dir);
    if (d) {
        struct dirent *e;
        char p[512];
        while ((e = readdir(d)) != NULL) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
            snprintf(p, sizeof p, "%s/%s", f->dir, e->d_name);
            remove(p);
        }
        closedir(d);
    }
    rmdir(f->dir);
    memset(f, 0, sizeof *f);
}

/* configurations shared by several scenarios (made once, unarmed) */
static af_config cfg_dense;  /* N = 32, 2D, compressed to phi = 0.75 */
static af_config cfg_prejam; /* the same compression continued to phi = 0.79 */
static af_config cfg_big;    /* N = 1500, 2D, random at phi = 0.4: a file > 64 KiB */

static void make_configs(void)
{
    if (cfg_dense.r) return;
    odhs__fault_disarm();
    odhs_system *s;
    odhs_driver *d;
    odhs_solver *so;
    odhs_stepper *st;
    AF_OK(odhs_system_create(2, 32, &s));
    AF_OK(odhs_system_set_radii_bidisperse(s, 0.5, 1.4, 0.0, 3));
    AF_OK(odhs_system_place_random(s, 0.5, 4));
    AF_OK(odhs_driver_create(&d));
    AF_OK(odhs_driver_set_compression_rate(d, 1.0));
    AF_OK(odhs_solver_create_by_name("dense", &so));
    AF_OK(odhs_stepper_create(s, d, so, &st));
    AF_OK(odhs_stepper_set_dt(st, 0.01));
    AF_OK(odhs_stepper_run_until_packing_fraction(st, 0.75));
    config_save(&cfg_dense, s);
    AF_OK(odhs_stepper_run_until_packing_fraction(st, 0.79));
    config_save(&cfg_prejam, s);
    odhs_stepper_destroy(st);
    odhs_solver_destroy(so);
    odhs_driver_destroy(d);
    odhs_system_destroy(s);
    AF_OK(odhs_system_create(2, 1500, &s));
    AF_OK(odhs_system_set_radii_bidisperse(s, 0.5, 1.4, 0.05, 5));
    AF_OK(odhs_system_place_random(s, 0.4, 6));
    config_save(&cfg_big, s);
    odhs_system_destroy(s);
}

static int count_pair(size_t i, size_t j, const double *rij, double gap, void *ctx)
{
    (void)i;
    (void)j;
    (void)rij;
    (void)gap;
    ++*(size_t *)ctx;
    return 0;
}

static void build_setup_none(af_fix *f, const af_scenario *sc)
{
    (void)f;
    (void)sc;
}

/* -- build: create, bidisperse radii, random placement, clone, scale, box,
 *    validate, pair enumeration; variants: 0 2D N = 32, 1 3D N = 16 ------- */
static int build_op(af_fix *f, const af_scenario *sc, int k)
{
    int dim = sc->variant ? 3 : 2;
    size_t n = sc->variant ? 16 : 32;
    switch (k) {
    case 0: return odhs_system_create(dim, n, &f->sys);
    case 1: return odhs_system_set_radii_bidisperse(f->sys, 0.5, 1.4, 0.1, 7);
    case 2: return odhs_system_place_random(f->sys, dim == 2 ? 0.5 : 0.3, 11);
    case 3: return odhs_system_clone(f->sys, &f->clone);
    case 4: return odhs_system_scale_box(f->sys, 1.01);
    case 5: {
        double L[3] = {1, 1, 1};
        odhs_system_get_box(f->sys, L);
        for (int a = 0; a < 3; ++a) L[a] *= 1.02;
        return odhs_system_set_box(f->sys, L);
    }
    case 6: return odhs_system_validate(f->sys, 0.0);
    case 7: f->nc = 0; return odhs_system_for_each_pair(f->sys, 0.1, count_pair, &f->nc);
    }
    return ODHS_E_INTERNAL;
}

static void build_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    (void)sc;
    rec_system(b, "sys", f->sys);
    rec_system(b, "clone", f->clone);
    if (op < 0) rec_z(b, "pairs", f->nc);
}

static void build_final(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    AF_OK(odhs_system_validate(f->sys, 0.0));
    AF_OK(odhs_system_validate(f->clone, 0.0));
}

/* -- xyz: write, read back, write the copy (N = 1500) ----------------------- */
static void xyz_setup(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    f->sys = config_system(&cfg_big);
    AF_OK(odhs_system_set_species(f->sys, 3, "Big"));
}

static int xyz_op(af_fix *f, const af_scenario *sc, int k)
{
    (void)sc;
    char err[256];
    switch (k) {
    case 0: return odhs_xyz_write(f->sys, f->path1);
    case 1: return odhs_xyz_read(f->path1, &f->sys2, err, sizeof err);
    case 2: return odhs_xyz_write(f->sys2, f->path2);
    }
    return ODHS_E_INTERNAL;
}

static void xyz_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    (void)sc;
    rec_system(b, "sys", f->sys);
    rec_system(b, "sys2", f->sys2);
    rec_dir(b, f->dir);
    if (op < 0) {
        rec_file(b, "file1", f->path1);
        rec_file(b, "file2", f->path2);
    }
}

static void xyz_final(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    af_buf a = {0}, c = {0};
    rec_system(&a, "system", f->sys);
    rec_system(&c, "system", f->sys2);
    const char *d = buf_diff(&a, &c);
    AF_MSG(d == NULL, "xyz round trip differs in %s", d);
    free(a.p);
    free(c.p);
}

/* -- network: detect, solve with cg and dense (N x = b and least squares) --- */
static void net_setup(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    f->sys = config_system(&cfg_dense);
}

static void net_vectors(af_fix *f)
{
    if (f->b) return;
    size_t nc = odhs_network_count(f->net), nd = odhs_system_count(f->sys) * (size_t)odhs_system_dim(f->sys);
    f->nc = nc;
    f->b = malloc((nc + 1) * sizeof *f->b);
    f->g = malloc((nd + 1) * sizeof *f->g);
    f->x1 = calloc(nc + 1, sizeof *f->x1);
    f->x2 = calloc(nc + 1, sizeof *f->x2);
    f->x3 = calloc(nc + 1, sizeof *f->x3);
    f->x4 = calloc(nc + 1, sizeof *f->x4);
    AF_ASSERT(f->b && f->g && f->x1 && f->x2 && f->x3 && f->x4);
    for (size_t c = 0; c < nc; ++c) f->b[c] = 1.0 + 0.25 * sin((double)c);
    for (size_t k = 0; k < nd; ++k) f->g[k] = cos(0.7 * (double)k);
}

static int net_op(af_fix *f, const af_scenario *sc, int k)
{
    (void)sc;
    if (k >= 3) net_vectors(f);
    switch (k) {
    case 0: return odhs_network_create(f->sys, &f->net);
    case 1: return odhs_network_detect(f->net, f->sys, 1e-3);
    case 2: return odhs_solver_create_by_name("cg", &f->sol);
    case 3: memset(f->x1, 0, f->nc * sizeof *f->x1); return odhs_solver_solve(f->sol, f->net, f->b, f->x1);
    case 4: return odhs_solver_create_by_name("dense", &f->sol2);
    case 5: return odhs_solver_solve(f->sol2, f->net, f->b, f->x2);
    case 6: return odhs_solver_solve_ls(f->sol2, f->net, f->g, f->x3);
    case 7: return odhs_network_apply_N(f->net, f->x2, f->x4, NULL);
    }
    return ODHS_E_INTERNAL;
}

static void net_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    (void)sc;
    rec_system(b, "sys", f->sys);
    rec_network(b, "net", f->net);
    rec_i(b, "solvers", (f->sol != NULL) + 2 * (f->sol2 != NULL));
    if (op < 0) {
        rec_vec(b, "x1", f->x1, f->nc);
        rec_vec(b, "x2", f->x2, f->nc);
        rec_vec(b, "x3", f->x3, f->nc);
        rec_vec(b, "x4", f->x4, f->nc);
    }
}

static void net_final(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    check_network(f->net, "network");
    AF_ASSERT(odhs_network_count(f->net) > 20);
    double *x = calloc(f->nc + 1, sizeof *x);
    AF_ASSERT(x);
    AF_OK(odhs_solver_solve(f->sol, f->net, f->b, x));
    AF_OK(odhs_solver_solve(f->sol2, f->net, f->b, x));
    free(x);
}

/* -- edit: a network built and taken apart by hand, large enough to grow
 *    its arrays, hash table and adjacency lists several times ------------- */
enum {
    ED_ADD = 1,
    ED_NADD = 260,
    ED_DETECT = ED_ADD + ED_NADD,
    ED_REMOVE,
    ED_NREMOVE = 60,
    ED_CLEAR = ED_REMOVE + ED_NREMOVE,
    ED_READD,
    ED_NOPS = ED_READD + 10
};

static void edit_pair(int p, size_t *i, size_t *j)
{
    *i = (size_t)(p % 32);
    *j = (size_t)((p % 32 + 1 + p / 32) % 32); /* distinct pairs for p < 480 */
}

static int edit_op(af_fix *f, const af_scenario *sc, int k)
{
    (void)sc;
    size_t i, j;
    if (k == 0) return odhs_network_create(f->sys, &f->net);
    if (k >= ED_ADD && k < ED_ADD + ED_NADD) {
        edit_pair(k - ED_ADD, &i, &j);
        return odhs_network_add(f->net, i, j, (k % 7) ? ODHS_CONTACT_TEMPORARY : ODHS_CONTACT_PERMANENT);
    }
    if (k == ED_DETECT) return odhs_network_detect(f->net, f->sys, 1e-3);
    if (k >= ED_REMOVE && k < ED_REMOVE + ED_NREMOVE) {
        edit_pair(2 * (k - ED_REMOVE), &i, &j);
        return odhs_network_remove(f->net, i, j);
    }
    if (k == ED_CLEAR) return odhs_network_clear(f->net);
    if (k >= ED_READD && k < ED_NOPS) {
        edit_pair(5 * (k - ED_READD), &i, &j);
        return odhs_network_add(f->net, i, j, ODHS_CONTACT_TEMPORARY);
    }
    return ODHS_E_INTERNAL;
}

static void edit_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    (void)sc;
    (void)op;
    rec_network(b, "net", f->net);
}

static void edit_final(af_fix *f, const af_scenario *sc) { check_network(f->net, sc->name); }

/* -- shear: stepper create, reset, 10 steps, shear reversed (contacts open
 *    at once), 5 steps, shear twice as fast (no event: the step goes on
 *    after re-solving), 5 steps, drift correction; variants: 0 Euler + cg,
 *    1 Heun + dense, 2 Euler + cg at fixed pressure, 3 Heun + dense with
 *    self-propulsion (short persistence: most steps end at a switch, whose
 *    redraw a failed step must undo) and gravity with weights, 4 Euler + cg
 *    capped at one iteration with a dense fallback (every solve goes through
 *    it), 5 Heun + dense at p = 1e4 (isostatic networks flow), 6 Heun +
 *    dense with a force callback in physical time, stepped with step_ex and
 *    read with odhs_stepper_contacts (0.2.7). The
 *    driver also carries (zero) external forces, so that their code paths
 *    run too. */
enum {
    SH_FORCES = 7,
    SH_RESET,
    SH_STEPS1,
    SH_REVERSE = SH_STEPS1 + 10,
    SH_STEPS2,
    SH_FASTER = SH_STEPS2 + 5,
    SH_STEPS3,
    SH_CORRECT = SH_STEPS3 + 5,
    SH_ERRORS,
    SH_NOPS
};

/* a pure force callback (shear_callback) */
static int af_swirl(double t, const odhs_system *sys, double *F, void *ctx)
{
    (void)ctx;
    double x[64];
    if (odhs_system_get_positions(sys, x)) return 1;
    for (int i = 0; i < 32; ++i) {
        F[2 * i] = 0.2 * sin(x[2 * i + 1] + t);
        F[2 * i + 1] = 0.2 * cos(x[2 * i]);
    }
    return 0;
}

static void shear_setup(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    f->sys = config_system(&cfg_dense);
}

static int shear_op(af_fix *f, const af_scenario *sc, int k)
{
    int v = sc->variant;
    if (k >= SH_STEPS1 && k < SH_REVERSE) return odhs_stepper_step(f->st, NULL);
    if (k >= SH_STEPS2 && k < SH_FASTER) return odhs_stepper_step(f->st, NULL);
    if (k >= SH_STEPS3 && k < SH_CORRECT) {
        if (v != 6) return odhs_stepper_step(f->st, NULL);
        odhs_step_info in; /* 6: the embedding calls of 0.2.7 */
        memset(&in, 0, sizeof in);
        in.size = sizeof in;
        int s = odhs_stepper_step_ex(f->st, &in);
        size_t nc;
        if (s >= 0) s = odhs_stepper_contacts(f->st, 256, &nc, f->ci, f->cj, NULL, f->cf, NULL);
        double pre[4];
        if (s >= 0 && in.advanced) s = odhs_stepper_pre_event_stress(f->st, pre);
        return s;
    }
    switch (k) {
    case 0: return odhs_driver_create(&f->drv);
    case 1: {
        int s = odhs_driver_set_shear_rate(f->drv, 1.0);
        if (!s && (v == 2 || v == 8)) s = odhs_driver_set_pressure(f->drv, 0.05);
        /* 5: a high pressure: isostatic networks flow (the bordered solve,
         * its sub-network, the sparse f0 and zero-pressure self-stress) */
        if (!s && v == 5) s = odhs_driver_set_pressure(f->drv, 1e4);
        return s;
    }
    case 2:
        if (v == 4) { /* cg that never converges, rescued by a dense fallback;
                       * all or nothing, like any other operation */
            odhs_solver *cg = NULL, *dn = NULL;
            int s = odhs_solver_create_by_name("cg", &cg);
            if (!s) s = odhs_solver_create_by_name("dense", &dn);
            if (!s) s = odhs_solver_set_param(cg, "maxiter", 1);
            if (!s) s = odhs_solver_set_fallback(cg, dn);
            if (s) {
                odhs_solver_destroy(cg);
                odhs_solver_destroy(dn);
                return s;
            }
            f->sol = cg;
            f->sol2 = dn;
            return ODHS_OK;
        }
        return odhs_solver_create_by_name(v == 1 || v == 3 || v >= 5 ? "dense" : "cg", &f->sol);
    case 3: return odhs_stepper_create(f->sys, f->drv, f->sol, &f->st);
    case 4: return odhs_stepper_set_dt(f->st, 0.02);
    case 5:
        /* 7, 8: the batched integrator (its contact problem, rejected steps
         * and exact fallbacks), at fixed volume and fixed pressure */
        if (v >= 7) return odhs_stepper_set_integrator(f->st, ODHS_INTEGRATOR_BATCHED);
        return odhs_stepper_set_integrator(f->st, v == 1 || v == 3 || v == 5 || v == 6 ? ODHS_INTEGRATOR_HEUN
                                                                             : ODHS_INTEGRATOR_EULER);
    case 6: {
        int s = odhs_stepper_set_contact_tolerance(f->st, 1e-2);
        /* 6: and the pre-event stress record of 0.2.8 (its own arrays) */
        if (!s && v == 6) s = odhs_stepper_set_pre_event_stress(f->st, 1);
        return s;
    }
    case SH_FORCES: {
        double F[64];
        memset(F, 0, sizeof F);
        int s = odhs_driver_set_forces(f->drv, 32, 2, F);
        /* 6: a force callback (re-evaluated after every drift correction) in
         * physical time */
        if (!s && v == 6) s = odhs_driver_set_force_callback(f->drv, af_swirl, NULL);
        if (!s && v == 6) s = odhs_driver_set_time_unit(f->drv, 1.0);
        if (!s && v == 3) {
            double g[2] = {0.0, -0.3}, w[32];
            for (int i = 0; i < 32; ++i) w[i] = 1.0 + 0.05 * i;
            s = odhs_driver_set_self_propulsion(f->drv, 32, 2, 0.5, 1.0, 0.0, 0.5, 9);
            if (!s) s = odhs_driver_set_gravity(f->drv, 2, g);
            if (!s) s = odhs_driver_set_gravity_weights(f->drv, 32, w);
        }
        return s;
    }
    case SH_RESET: return odhs_stepper_reset(f->st);
    case SH_REVERSE: return odhs_driver_set_shear_rate(f->drv, -1.0);
    case SH_FASTER: return odhs_driver_set_shear_rate(f->drv, -2.0);
    case SH_CORRECT: return odhs_stepper_correct(f->st);
    case SH_ERRORS: return odhs_stepper_errors(f->st, &f->errs[0], &f->errs[1]);
    }
    return ODHS_E_INTERNAL;
}

static void shear_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    rec_system(b, "sys", f->sys);
    rec_i(b, "handles", (f->drv != NULL) + 2 * (f->sol != NULL));
    rec_stepper(b, f->st);
    if (op < 0) rec(b, "errs", 'd', f->errs, 2);
    if (sc->variant == 3 && f->drv) {
        /* the propulsion state: forces, switch times (once started) */
        double F[64], ts[32];
        int s = odhs_driver_get_propulsion(f->drv, F, ts);
        rec_i(b, "prop", s);
        if (!s) {
            rec(b, "propF", 'd', F, 64);
            rec(b, "propT", 'd', ts, 32);
        }
    }
}

/* the network is consistent, the system valid (overlaps below tol, relative
 * to the pair's contact distance) */
static void stepper_final(af_fix *f, const char *what, double tol)
{
    check_network(odhs_stepper_network(f->st), what);
    double gap = 0, ov = 0;
    AF_OK(odhs_stepper_errors(f->st, &gap, &ov));
    AF_MSG(gap < tol && ov < tol, "%s: contact gap %g, overlap %g", what, gap, ov);
    AF_OK(odhs_system_validate(f->sys, 2.0 * tol));
}

static void shear_final(af_fix *f, const af_scenario *sc)
{
    stepper_final(f, sc->name, 1e-6);
    for (int k = 0; k < 2; ++k) AF_OK(odhs_stepper_step(f->st, NULL));
    check_network(odhs_stepper_network(f->st), sc->name);
}

/* -- jam: compression to jamming with the self-stress f0 (dense), then the
 *    certificate, f0 again and the contacts file ---------------------------- */
enum { JAM_RESET = 7, JAM_STEPS = 8 };
static int jam_steps; /* steps to jamming from cfg_prejam (probe) */

static int jam_op(af_fix *f, const af_scenario *sc, int k)
{
    (void)sc;
    if (k >= JAM_STEPS && k < JAM_STEPS + jam_steps) return odhs_stepper_step(f->st, NULL);
    switch (k) {
    case 0: return odhs_driver_create(&f->drv);
    case 1: return odhs_driver_set_compression_rate(f->drv, 1.0);
    case 2: return odhs_solver_create_by_name("dense", &f->sol);
    case 3: return odhs_stepper_create(f->sys, f->drv, f->sol, &f->st);
    case 4: return odhs_stepper_set_dt(f->st, 0.01);
    case 5: return odhs_stepper_set_contact_tolerance(f->st, 1e-6);
    /* the paper's Euler scheme at dt = 0.01 jams in some 15 steps; the
     * default adaptive scheme takes ~2000 (the Heun allocations are walked
     * by shear_heun_dense) */
    case 6: return odhs_stepper_set_integrator(f->st, ODHS_INTEGRATOR_EULER);
    case JAM_RESET: return odhs_stepper_reset(f->st);
    }
    k -= JAM_STEPS + jam_steps;
    switch (k) {
    case 0: f->cert.size = sizeof f->cert; return odhs_stepper_certificate(f->st, &f->cert);
    case 1: {
        const odhs_network *net = odhs_stepper_network(f->st);
        if (!f->x1) {
            f->nc = odhs_network_count(net);
            f->x1 = calloc(f->nc + 1, sizeof *f->x1);
            AF_ASSERT(f->x1);
        }
        return odhs_network_null_vector(net, f->sol, f->x1, &f->errs[0]);
    }
    case 2: return odhs_contacts_write(odhs_stepper_network(f->st), f->sys, f->path1);
    }
    return ODHS_E_INTERNAL;
}

static void jam_setup(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    f->sys = config_system(&cfg_prejam);
}

static int jam_probe(const af_scenario *sc)
{
    af_fix f;
    fix_init(&f);
    jam_setup(&f, sc);
    jam_steps = 0;
    for (int k = 0; k < JAM_STEPS; ++k) AF_OK(jam_op(&f, sc, k));
    int s = ODHS_OK;
    /* a fresh stepper on cfg_prejam jams after some 15 steps; many more
     * would make the walk slow (then choose a denser cfg_prejam) */
    while (s == ODHS_OK && jam_steps < 300) {
        s = odhs_stepper_step(f.st, NULL);
        jam_steps++;
    }
    AF_MSG(s == ODHS_JAMMED, "compression did not jam: %d after %d steps (%s)", s, jam_steps,
           odhs_stepper_errmsg(f.st));
    fix_destroy(&f);
    return JAM_STEPS + jam_steps + 3;
}

static void jam_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    (void)sc;
    rec_system(b, "sys", f->sys);
    rec_i(b, "handles", (f->drv != NULL) + 2 * (f->sol != NULL));
    rec_stepper(b, f->st);
    rec_dir(b, f->dir);
    if (op < 0) {
        rec(b, "cert", 'c', &f->cert, sizeof f->cert);
        rec_vec(b, "f0", f->x1, f->nc);
        rec_d(b, "f0res", f->errs[0]);
        rec_file(b, "contacts", f->path1);
    }
}

static void jam_final(af_fix *f, const af_scenario *sc)
{
    /* compression with dt = 0.01 lets contact gaps drift by up to ~1e-2 of
     * a diameter, which the final isotropic polish turns into overlaps of
     * that order: a property of the run, not of this test */
    stepper_final(f, sc->name, 2e-2);
    AF_ASSERT(f->cert.jammed == 1);
    AF_ASSERT(f->cert.isostatic == 1);
    /* jammed: further steps say so and change nothing */
    AF_ASSERT(odhs_stepper_step(f->st, NULL) == ODHS_JAMMED);
}

/* -- jam_lp: the fast route (odhs_stepper_jam_lp) from cfg_dense: the chain
 *    of programmes (only the library's own allocations are walked, not CLP's),
 *    the reset on the packing, the certificate ---------------------------- */
#if ODHS_HAVE_CLP
static int jam_lp_op(af_fix *f, const af_scenario *sc, int k)
{
    switch (k) {
    case 0: return odhs_driver_create(&f->drv);
    case 1: return odhs_driver_set_compression_rate(f->drv, 1.0);
    case 2: return odhs_solver_create_by_name("dense", &f->sol);
    case 3: return odhs_stepper_create(f->sys, f->drv, f->sol, &f->st);
    case 4: return odhs_stepper_reset(f->st);
    case 5: { /* variant 1: the quench start (a system copy, the soft-core minimiser) */
        odhs_jam_lp_options o = {.size = sizeof o, .quench = sc->variant};
        return odhs_stepper_jam_lp(f->st, &o, NULL);
    }
    case 6: f->cert.size = sizeof f->cert; return odhs_stepper_certificate(f->st, &f->cert);
    }
    return ODHS_E_INTERNAL;
}

static void jam_lp_setup(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    f->sys = config_system(&cfg_dense);
}

static void jam_lp_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    (void)sc;
    rec_system(b, "sys", f->sys);
    rec_i(b, "handles", (f->drv != NULL) + 2 * (f->sol != NULL));
    rec_stepper(b, f->st);
    if (op < 0) rec(b, "cert", 'c', &f->cert, sizeof f->cert);
}

static void jam_lp_final(af_fix *f, const af_scenario *sc)
{
    stepper_final(f, sc->name, 1e-12);
    AF_ASSERT(f->cert.jammed == 1 && f->cert.isostatic == 1 && f->cert.min_force > 0.0);
    AF_ASSERT(odhs_stepper_step(f->st, NULL) == ODHS_JAMMED);
}
#endif

/* -- files: contacts file and SVG picture ----------------------------------- */
static void files_setup(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    f->sys = config_system(&cfg_dense);
    AF_OK(odhs_network_create(f->sys, &f->net));
    AF_OK(odhs_network_detect(f->net, f->sys, 1e-3));
    size_t nc = odhs_network_count(f->net);
    double *fc = malloc((nc + 1) * sizeof *fc);
    AF_ASSERT(fc);
    for (size_t c = 0; c < nc; ++c) fc[c] = 1.0 + 0.1 * (double)c;
    AF_OK(odhs_network_set_forces(f->net, fc));
    free(fc);
    AF_OK(odhs_network_rattlers(f->net, f->mark, NULL));
}

static int files_op(af_fix *f, const af_scenario *sc, int k)
{
    (void)sc;
    switch (k) {
    case 0: return odhs_contacts_write(f->net, f->sys, f->path1);
    case 1: return odhs_svg_write(f->sys, f->net, f->mark, f->path2);
    }
    return ODHS_E_INTERNAL;
}

static void files_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    (void)sc;
    rec_system(b, "sys", f->sys);
    rec_network(b, "net", f->net);
    rec_dir(b, f->dir);
    if (op < 0) {
        rec_file(b, "contacts", f->path1);
        rec_file(b, "svg", f->path2);
    }
}

static void files_final(af_fix *f, const af_scenario *sc) { check_network(f->net, sc->name); }

/* the system of the lsq and pcg_ordering scenarios: 16 discs of diameter 1
 * on a periodic 4 x 4 square lattice, all touching their four neighbours,
 * and an empty network */
static void lattice16(af_fix *f)
{
    double L[2] = {4.0, 4.0}, r[16], x[32];
    for (int i = 0; i < 16; ++i) {
        r[i] = 0.5;
        x[2 * i] = 0.5 + (i % 4);
        x[2 * i + 1] = 0.5 + (i / 4);
    }
    AF_OK(odhs_system_create(2, 16, &f->sys));
    AF_OK(odhs_system_set_configuration(f->sys, L, 0.0, r, x));
    AF_OK(odhs_network_create(f->sys, &f->net));
}

/* -- lsq: auto's least-squares routes on a hyperstatic network (a periodic
 * 4 x 4 square lattice: 32 contacts, rank 24) with lsq_dense_max = 0, so
 * that SuiteSparse builds answer with lsq-pcg (lsq-cg absorbs its
 * failures), twice: its first setup and a solve on the kept handle -------- */
static void lsq_setup(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    lattice16(f);
    AF_OK(odhs_network_detect(f->net, f->sys, 1e-9));
    f->nc = odhs_network_count(f->net);
    AF_ASSERT(f->nc == 32);
    AF_OK(odhs_solver_create_by_name("auto", &f->sol));
    AF_OK(odhs_solver_set_param(f->sol, "lsq_dense_max", 0.0));
    f->g = malloc(32 * sizeof *f->g);
    f->b = malloc(f->nc * sizeof *f->b);
    f->x1 = calloc(f->nc, sizeof *f->x1);
    AF_ASSERT(f->g && f->b && f->x1);
    for (int k = 0; k < 32; ++k) f->g[k] = sin(1.0 + 0.7 * k); /* generic: not in a symmetry subspace */
    AF_OK(odhs_network_apply_S(f->net, f->g, f->b));
}

static int lsq_op(af_fix *f, const af_scenario *sc, int k)
{
    (void)sc;
    memset(f->x1, 0, f->nc * sizeof *f->x1);
    return k == 0 ? odhs_solver_solve(f->sol, f->net, f->b, f->x1) : odhs_solver_solve_ls(f->sol, f->net, f->g, f->x1);
}

static void lsq_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    (void)sc;
    (void)op;
    rec_system(b, "sys", f->sys);
    rec_network(b, "net", f->net);
}

static void lsq_final(af_fix *f, const af_scenario *sc)
{
    /* the answer: a least-squares solution (S (S^T x - g) = 0 to 1e-8) */
    double *sx = malloc(32 * sizeof *sx), *res = malloc(f->nc * sizeof *res);
    AF_ASSERT(sx && res);
    AF_OK(odhs_network_apply_ST(f->net, f->x1, sx));
    for (int k = 0; k < 32; ++k) sx[k] -= f->g[k];
    AF_OK(odhs_network_apply_S(f->net, sx, res));
    double rn = 0.0;
    for (size_t c = 0; c < f->nc; ++c) rn += res[c] * res[c];
    AF_MSG(sqrt(rn) < 1e-8, "%s: |S (S^T x - g)| = %.3g", sc->name, sqrt(rn));
    free(sx);
    free(res);
}

#ifdef ODHS_HAVE_SUITESPARSE
/* -- pcg_ordering: cholmod-pcg carrying its ordering over to a changed
 * contact set (0.2.23; "ordering_reuse" forced, since the default carries
 * only after METIS, on networks far larger than this one; with any fill)
 * and every change refactorised ("update_max" 0). A spanning tree of a
 * 4 x 4 square lattice (15 contacts: rows but their last link, column 0 but
 * its last): solve; swap one row link for the missing one of its row
 * (another tree); the geometry; solve on the carried ordering ----------- */
static void pcgo_setup(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    lattice16(f);
    for (int row = 0; row < 4; ++row)
        for (int c = 0; c < 3; ++c)
            AF_OK(odhs_network_add(f->net, (size_t)(4 * row + c), (size_t)(4 * row + c + 1), ODHS_CONTACT_TEMPORARY));
    for (int row = 0; row < 3; ++row)
        AF_OK(odhs_network_add(f->net, (size_t)(4 * row), (size_t)(4 * row + 4), ODHS_CONTACT_TEMPORARY));
    AF_OK(odhs_network_update_geometry(f->net, f->sys));
    f->nc = odhs_network_count(f->net);
    AF_ASSERT(f->nc == 15);
    f->b = malloc(f->nc * sizeof *f->b);
    f->x1 = calloc(f->nc, sizeof *f->x1);
    AF_ASSERT(f->b && f->x1);
    for (size_t k = 0; k < f->nc; ++k) f->b[k] = 1.0 + 0.3 * sin(1.0 + (double)k);
}

static int pcgo_op(af_fix *f, const af_scenario *sc, int k)
{
    (void)sc;
    switch (k) {
    case 0: {
        int s = odhs_solver_create_by_name("cholmod-pcg", &f->sol);
        if (!s) s = odhs_solver_set_param(f->sol, "ordering_reuse", 1e6); /* whatever the fill */
        if (!s) s = odhs_solver_set_param(f->sol, "update_max", 0.0);
        return s;
    }
    case 1:
    case 4: memset(f->x1, 0, f->nc * sizeof *f->x1); return odhs_solver_solve(f->sol, f->net, f->b, f->x1);
    case 2: { /* row 1 swaps its link 5-6 for 7-4 (around the periodic box); all or nothing */
        int s = odhs_network_add(f->net, 7, 4, ODHS_CONTACT_TEMPORARY);
        if (!s) {
            s = odhs_network_remove(f->net, 5, 6);
            if (s) AF_OK(odhs_network_remove(f->net, 7, 4));
        }
        return s;
    }
    default: return odhs_network_update_geometry(f->net, f->sys);
    }
}

static void pcgo_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    (void)sc;
    (void)op;
    rec_system(b, "sys", f->sys);
    rec_network(b, "net", f->net);
}

static void pcgo_final(af_fix *f, const af_scenario *sc)
{
    /* the answer of the last solve: N x = b to 1e-10, on the carried ordering */
    double *y = malloc(f->nc * sizeof *y), *tmp = malloc(32 * sizeof *tmp);
    AF_ASSERT(y && tmp);
    AF_OK(odhs_network_apply_N(f->net, f->x1, y, tmp));
    double rn = 0.0, bn = 0.0;
    for (size_t c = 0; c < f->nc; ++c) {
        rn += (y[c] - f->b[c]) * (y[c] - f->b[c]);
        bn += f->b[c] * f->b[c];
    }
    AF_MSG(sqrt(rn) < 1e-10 * sqrt(bn), "%s: |N x - b| = %.3g", sc->name, sqrt(rn));
    /* two analyses; the second carried the first's ordering, unless a failed
     * allocation while keeping it was absorbed (then it ordered afresh) */
    double ord = 0.0, an = 0.0;
    AF_OK(odhs_solver_get_stat(f->sol, "orderings", &ord));
    AF_OK(odhs_solver_get_stat(f->sol, "analyses", &an));
    AF_MSG(an >= 2.0 && ord >= 1.0 && ord <= an, "%s: %g orderings for %g analyses", sc->name, ord, an);
    free(y);
    free(tmp);
}
#endif

/* -- outputs: contacts CSV, LAMMPS data file written and read, a trajectory
 * of two frames with velocities, read back ----------------------------------- */
static void outputs_setup(af_fix *f, const af_scenario *sc)
{
    files_setup(f, sc);
    AF_OK(odhs_solver_create_by_name("dense", &f->sol));
    AF_OK(odhs_driver_create(&f->drv));
    AF_OK(odhs_driver_set_shear_rate(f->drv, 1.0));
    AF_OK(odhs_stepper_create(f->sys, f->drv, f->sol, &f->st));
    AF_OK(odhs_stepper_reset(f->st));
}

static int outputs_op(af_fix *f, const af_scenario *sc, int k)
{
    (void)sc;
    int s;
    switch (k) {
    case 0: return odhs_contacts_write_csv(f->net, f->sys, f->path1);
    case 1: return odhs_lammps_data_write(f->sys, f->path2);
    case 2: return odhs_lammps_data_read(f->path2, &f->clone, NULL, 0);
    case 3: return odhs_traj_open(f->path3, ODHS_TRAJ_XYZ, &f->tr, NULL, 0);
    case 4:
    case 5: return odhs_traj_write(f->tr, f->sys, f->st);
    case 6:
        s = odhs_traj_close(f->tr);
        f->tr = NULL;
        return s;
    case 7: return odhs_xyz_read_frame(f->path3, -1, &f->sys2, NULL, NULL, 0);
    }
    return ODHS_E_INTERNAL;
}

static void outputs_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    (void)sc;
    (void)op;
    rec_system(b, "sys", f->sys);
    rec_system(b, "data", f->clone);
    rec_system(b, "frame", f->sys2);
    rec_dir(b, f->dir);
    rec_file(b, "csv", f->path1);
    rec_file(b, "lammps", f->path2);
    rec_file(b, "traj", f->path3);
}

static void outputs_final(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    uint64_t bad = 0;
    double x[64], y[64];
    AF_ASSERT(f->sys2 && f->clone);
    odhs_system_get_positions(f->sys, x);
    odhs_system_get_positions(f->sys2, y);
    for (int k = 0; k < 64; ++k) bad += x[k] != y[k];
    AF_ASSERT(bad == 0);
}

/* -- checkpoint: save a running stepper, restore it, step both -------------- */
static void ckpt_setup(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    f->sys = config_system(&cfg_dense);
    AF_OK(odhs_driver_create(&f->drv));
    AF_OK(odhs_driver_set_shear_rate(f->drv, 1.0));
    AF_OK(odhs_solver_create_by_name("cg", &f->sol));
    AF_OK(odhs_stepper_create(f->sys, f->drv, f->sol, &f->st));
    AF_OK(odhs_stepper_set_dt(f->st, 0.02));
    for (int k = 0; k < 5; ++k) AF_OK(odhs_stepper_step(f->st, NULL));
}

static int ckpt_op(af_fix *f, const af_scenario *sc, int k)
{
    (void)sc;
    char err[256];
    switch (k) {
    case 0: return odhs_checkpoint_write(f->st, f->path1);
    case 1: return odhs_checkpoint_read(f->path1, f->sol, &f->sys2, &f->drv2, &f->st2, err, sizeof err);
    case 2: return odhs_stepper_step(f->st2, NULL);
    }
    return ODHS_E_INTERNAL;
}

static void ckpt_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    (void)sc;
    rec_system(b, "sys", f->sys);
    rec_stepper(b, f->st);
    rec_system(b, "sys2", f->sys2);
    rec_i(b, "drv2", f->drv2 != NULL);
    rec_stepper(b, f->st2);
    rec_dir(b, f->dir);
    if (op < 0) rec_file(b, "checkpoint", f->path1);
}

static void ckpt_final(af_fix *f, const af_scenario *sc)
{
    /* the restored run continues exactly like the original */
    AF_OK(odhs_stepper_step(f->st, NULL));
    af_buf a = {0}, c = {0};
    rec_system(&a, "system", f->sys);
    rec_stepper(&a, f->st);
    rec_system(&c, "system", f->sys2);
    rec_stepper(&c, f->st2);
    const char *d = buf_diff(&a, &c);
    AF_MSG(d == NULL, "%s: restored run differs in %s", sc->name, d);
    free(a.p);
    free(c.p);
    stepper_final(f, sc->name, 1e-6);
}

/* ---- the walk ------------------------------------------------------------------ */
static int verbose(void)
{
    const char *e = getenv("ODHS_ALLOCFAIL_VERBOSE");
    return e && *e && strcmp(e, "0");
}

#define AF_MAXOPS 1024

/* problems are listed (all of them, not only the first) and counted; the
 * walk fails at its end if there was any */
static int af_failures;
#define AF_EXPECT(cond, ...)                                                                                 \
    do {                                                                                                     \
        if (!(cond)) {                                                                                       \
            if (af_failures++ < 100) {                                                                       \
                fprintf(stderr, "allocfail: FAIL: " __VA_ARGS__);                                            \
                fputc('\n', stderr);                                                                         \
            }                                                                                                \
            ok = 0;                                                                                          \
        }                                                                                                    \
    } while (0)

#ifdef AF_LSAN
/* after a leak report every later check would repeat it: report once */
static int lsan_reported;
#endif

static int leaks_now(void)
{
#ifdef AF_LSAN
    if (lsan_reported) return 0;
    if (__lsan_do_recoverable_leak_check()) {
        lsan_reported = 1;
        fprintf(stderr, "allocfail: leak report above; further leak checks are off\n");
        return 1;
    }
#endif
    return 0;
}

static void walk(const af_scenario *sc)
{
    const char *only = getenv("ODHS_ALLOCFAIL_ONLY");
    if (only && *only && !strstr(only, sc->name)) return;
    /* no fork, so no Check timeout: a hang (say, a lookup probing a full
     * hash table forever) ends the run instead of stalling it */
    alarm(600);
    make_configs();
    struct timespec t0, t1;
    clock_gettime(CLOCK_MONOTONIC, &t0);
    int nops = sc->nops ? sc->nops : sc->probe(sc);
    AF_ASSERT(nops <= AF_MAXOPS);
    static int ref_status[AF_MAXOPS];
    static af_buf ref_after[AF_MAXOPS]; /* reference state after each operation */
    af_buf ref = {0}, before = {0}, after = {0};
    af_fix f;
    af_failures = 0;

    /* reference: count the allocations */
    int64_t live0 = odhs__fault_live();
    fix_init(&f);
    sc->setup(&f, sc);
    odhs__fault_arm(0, 0);
    for (int k = 0; k < nops; ++k) {
        ref_status[k] = sc->op(&f, sc, k);
        AF_MSG(ref_status[k] >= 0, "%s: reference operation %d failed: %s", sc->name, k,
               odhs_strerror(ref_status[k]));
        uint64_t c = odhs__fault_count();
        ref_after[k].n = 0;
        sc->capture(&f, sc, -1, &ref_after[k]);
        /* captures must not allocate through the library (they run armed) */
        AF_ASSERT(odhs__fault_count() == c);
    }
    uint64_t nalloc = odhs__fault_count();
    odhs__fault_disarm();
    sc->capture(&f, sc, -1, &ref);
    sc->final(&f, sc);
    fix_destroy(&f);
    AF_MSG(odhs__fault_live() == live0, "%s: the reference run leaked %lld blocks", sc->name,
           (long long)(odhs__fault_live() - live0));
    AF_MSG(!leaks_now(), "%s: the reference run leaked (report above)", sc->name);
    AF_ASSERT(nalloc > 0);

    uint64_t n_nomem = 0, n_absorbed = 0;
    const char *only_n = getenv("ODHS_ALLOCFAIL_N");
    uint64_t n_first = 1, n_last = nalloc;
    if (only_n && *only_n) n_first = n_last = strtoull(only_n, NULL, 10);
    /* one-shot: only allocation n fails; sticky: n and every later one
     * (memory stays short, so error paths must not need any) */
    for (int sticky = 0; sticky < 2; ++sticky)
        for (uint64_t n = n_first; n <= n_last; ++n) {
            int ok = 1;
            unsigned long long nn = (unsigned long long)n;
            const char *mode = sticky ? "sticky" : "one-shot";
            fix_init(&f);
            sc->setup(&f, sc);
            odhs__fault_arm(n, sticky);
            int k, s = ODHS_OK;
            for (k = 0; k < nops; ++k) {
                before.n = 0;
                sc->capture(&f, sc, k, &before);
                s = sc->op(&f, sc, k);
                if (s < 0) break;
                /* a warning (> 0) must not stand for a failed allocation */
                AF_EXPECT(s == ref_status[k],
                          "%s (%s): allocation %llu failed, operation %d returned %d, not %d (%s)", sc->name,
                          mode, nn, k, s, ref_status[k], odhs_strerror(s));
                if (!ok) break;
            }
            int fired = odhs__fault_fired();
            odhs__fault_disarm();
            AF_EXPECT(fired, "%s (%s): allocation %llu of %llu never happened", sc->name, mode, nn,
                      (unsigned long long)nalloc);
            if (!ok) {
                /* reported above */
            } else if (k < nops) {
                if (verbose())
                    fprintf(stderr, "allocfail %s (%s): n=%llu op %d -> %s\n", sc->name, mode, nn, k,
                            odhs_strerror(s));
                AF_EXPECT(s == ODHS_E_NOMEM,
                          "%s (%s): allocation %llu failed in operation %d, which returned %d (%s)", sc->name,
                          mode, nn, k, s, odhs_strerror(s));
                n_nomem++;
                /* nothing changed */
                after.n = 0;
                sc->capture(&f, sc, k, &after);
                const char *d = buf_diff(&before, &after);
                AF_EXPECT(d == NULL, "%s (%s): allocation %llu failed in operation %d, which changed %s",
                          sc->name, mode, nn, k, d);
                /* the handles work: the rest of the scenario as in the reference */
                for (; k < nops && ok; ++k) {
                    s = sc->op(&f, sc, k);
                    AF_EXPECT(s == ref_status[k],
                              "%s (%s): after allocation %llu failed, operation %d returned %d, not %d (%s)",
                              sc->name, mode, nn, k, s, ref_status[k], odhs_strerror(s));
                    after.n = 0;
                    sc->capture(&f, sc, -1, &after);
                    const char *d = buf_diff(&ref_after[k], &after);
                    AF_EXPECT(
                        d == NULL,
                        "%s (%s): after allocation %llu failed, the state after operation %d differs in %s",
                        sc->name, mode, nn, k, d);
                }
            } else {
                n_absorbed++;
                if (verbose()) fprintf(stderr, "allocfail %s (%s): n=%llu absorbed\n", sc->name, mode, nn);
            }
            if (ok) {
                after.n = 0;
                sc->capture(&f, sc, -1, &after);
                const char *d = buf_diff(&ref, &after);
                AF_EXPECT(d == NULL, "%s (%s): after allocation %llu failed, the final state differs in %s",
                          sc->name, mode, nn, d);
            }
            if (ok) sc->final(&f, sc);
            fix_destroy(&f);
            /* every block the library allocated is freed again (LeakSanitizer
             * checks the rest, once per scenario below and at exit) */
            int64_t leaked = odhs__fault_live() - live0;
            AF_EXPECT(leaked == 0, "%s (%s): %lld blocks leaked when allocation %llu failed", sc->name, mode,
                      (long long)leaked, nn);
            live0 += leaked; /* report each leak once */
        }
    {
        int ok = 1;
        AF_EXPECT(!leaks_now(), "%s: LeakSanitizer found leaks (report above)", sc->name);
        (void)ok;
    }
    clock_gettime(CLOCK_MONOTONIC, &t1);
    double secs = (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec);
    fprintf(stderr,
            "allocfail %-16s %3d operations, %4llu allocations; failing each (one-shot, then sticky): "
            "%4llu ODHS_E_NOMEM, %llu absorbed, %.1f s\n",
            sc->name, nops, (unsigned long long)nalloc, (unsigned long long)n_nomem,
            (unsigned long long)n_absorbed, secs);
    free(ref.p);
    free(before.p);
    free(after.p);
    alarm(0);
    AF_MSG(af_failures == 0, "%s: %d failures (listed on stderr)", sc->name, af_failures);
}

/* -- softcore: RD0, CD0 and CD_n steps, a quasistatic SD step, observables --- */
enum { SC_STEPS1 = 2, SC_CD0 = SC_STEPS1 + 4, SC_STEPS2, SC_MINTOL = SC_STEPS2 + 3, SC_QS, SC_CDN, SC_STEPS3,
       SC_ENERGY = SC_STEPS3 + 3, SC_STRESS, SC_NOPS };

static void soft_setup(af_fix *f, const af_scenario *sc)
{
    (void)sc;
    f->sys = config_system(&cfg_dense);
}

static int soft_op(af_fix *f, const af_scenario *sc, int k)
{
    (void)sc;
    if ((k >= SC_STEPS1 && k < SC_CD0) || (k >= SC_STEPS2 && k < SC_MINTOL) || (k >= SC_STEPS3 && k < SC_ENERGY))
        return odhs_softcore_step(f->soft);
    switch (k) {
    case 0: return odhs_softcore_create(f->sys, &f->soft);
    case 1: return odhs_softcore_set_shear_rate(f->soft, 1e-2);
    case SC_CD0: return odhs_softcore_set_model(f->soft, ODHS_SOFTCORE_CD0);
    case SC_MINTOL: return odhs_softcore_set_min_tolerance(f->soft, 1e-6, 1000000);
    case SC_QS: return odhs_softcore_quasistatic_step(f->soft, 1e-3, NULL);
    case SC_CDN: return odhs_softcore_set_model(f->soft, ODHS_SOFTCORE_CDN);
    case SC_ENERGY: return odhs_softcore_energy(f->soft, &f->errs[0]);
    case SC_STRESS: {
        double sig[4];
        int s = odhs_softcore_stress(f->soft, ODHS_SOFTCORE_STRESS_TOTAL, sig);
        if (!s) f->errs[1] = sig[1];
        return s;
    }
    }
    return ODHS_E_INTERNAL;
}

static void soft_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    (void)sc;
    rec_system(b, "sys", f->sys);
    rec_i(b, "handle", f->soft != NULL);
    if (f->soft) {
        double v[5];
        uint64_t c[3];
        odhs_softcore_time(f->soft, &v[0]);
        odhs_softcore_strain(f->soft, &v[1]);
        odhs_softcore_step_size(f->soft, &v[2]);
        odhs_softcore_kinetic_energy(f->soft, &v[3]);
        v[4] = 0.0;
        rec(b, "soft", 'd', v, 5);
        odhs_softcore_counts(f->soft, &c[0], &c[1], &c[2]);
        double cd[3] = {(double)c[0], (double)c[1], (double)c[2]};
        rec(b, "counts", 'd', cd, 3);
    }
    if (op < 0) rec(b, "errs", 'd', f->errs, 2);
}

static void soft_final(af_fix *f, const af_scenario *sc)
{
    AF_MSG(f->soft != NULL, "%s: no handle", sc->name);
    for (int k = 0; k < 2; ++k) AF_OK(odhs_softcore_step(f->soft));
    double U;
    AF_OK(odhs_softcore_energy(f->soft, &U));
    AF_MSG(U >= 0.0, "%s: energy %g", sc->name, U);
}

/* -- analysis: series statistics, a histogram of the forces, the backbone's
 *    forces, the gaps of nearly touching pairs, the velocity correlation, a
 *    scaling collapse ------------------------------------------------------- */
static void analysis_setup(af_fix *f, const af_scenario *sc)
{
    files_setup(f, sc);
    for (int k = 0; k < 512; ++k) f->an_series[k] = sin(0.37 * k) + 0.01 * (k % 7);
    for (int k = 0; k < 64; ++k) f->an_V[k] = cos(0.9 * k);
    f->stats.size = sizeof f->stats;
    f->coll.size = sizeof f->coll;
}
static int analysis_op(af_fix *f, const af_scenario *sc, int k)
{
    (void)sc;
    switch (k) {
    case 0: return odhs_series_stats_compute(f->an_series, 512, &f->stats);
    case 1: return odhs_histogram(f->an_series, 512, -1.0, 1.0, 8, 0, f->an_e, f->an_d, NULL, NULL);
    case 2: return odhs_backbone_forces(f->net, 256, &f->an_n[0], f->cf);
    case 3: return odhs_packing_gaps(f->sys, f->net, 0.3, 256, &f->an_n[1], NULL, NULL, f->an_gap, NULL);
    case 4: return odhs_velocity_correlation(f->sys, f->an_V, 1.0, 8, f->an_g, NULL);
    case 5: { /* a collapse of a synthetic flow curve (exponents 0.84, 1, 3) */
        double phi[24], rate[24], v[24];
        for (int k = 0; k < 24; ++k) {
            phi[k] = 0.82 + 0.005 * (k % 8);
            rate[k] = pow(10.0, -6.0 + k / 8);
            double x = (phi[k] - 0.84) / pow(rate[k], 1.0 / 3.0);
            v[k] = pow(rate[k], 1.0 / 3.0) * exp(0.2 + x + 0.05 * x * x);
        }
        const double guess[3] = {0.835, 0.9, 3.2};
        return odhs_collapse_fit(phi, rate, v, NULL, 24, 2, guess, &f->coll);
    }
    }
    return ODHS_E_INTERNAL;
}
static void analysis_capture(const af_fix *f, const af_scenario *sc, int op, af_buf *b)
{
    (void)sc;
    (void)op;
    rec_system(b, "sys", f->sys);
    rec_network(b, "net", f->net);
    rec(b, "stats", 'c', &f->stats, sizeof f->stats);
    rec(b, "hist", 'd', f->an_e, 9);
    rec(b, "dens", 'd', f->an_d, 8);
    rec(b, "counts", 'z', f->an_n, 2);
    rec(b, "backbone", 'd', f->cf, 256);
    rec(b, "vcorr", 'd', f->an_g, 8);
    rec(b, "collapse", 'c', &f->coll, sizeof f->coll);
}

static const af_scenario scenarios[] = {
    {"build_2d", 8, 0, build_setup_none, NULL, build_op, build_capture, build_final},
    {"build_3d", 8, 1, build_setup_none, NULL, build_op, build_capture, build_final},
    {"xyz", 3, 0, xyz_setup, NULL, xyz_op, xyz_capture, xyz_final},
    {"network", 8, 0, net_setup, NULL, net_op, net_capture, net_final},
    {"network_edit", ED_NOPS, 0, net_setup, NULL, edit_op, edit_capture, edit_final},
    {"shear_euler_cg", SH_NOPS, 0, shear_setup, NULL, shear_op, shear_capture, shear_final},
    {"shear_heun_dense", SH_NOPS, 1, shear_setup, NULL, shear_op, shear_capture, shear_final},
    {"shear_pressure", SH_NOPS, 2, shear_setup, NULL, shear_op, shear_capture, shear_final},
    {"shear_propulsion", SH_NOPS, 3, shear_setup, NULL, shear_op, shear_capture, shear_final},
    {"shear_cg_fallback", SH_NOPS, 4, shear_setup, NULL, shear_op, shear_capture, shear_final},
    {"shear_pressure_high", SH_NOPS, 5, shear_setup, NULL, shear_op, shear_capture, shear_final},
    {"shear_callback", SH_NOPS, 6, shear_setup, NULL, shear_op, shear_capture, shear_final},
    {"shear_batched", SH_NOPS, 7, shear_setup, NULL, shear_op, shear_capture, shear_final},
    {"shear_batched_pressure", SH_NOPS, 8, shear_setup, NULL, shear_op, shear_capture, shear_final},
    {"jam", 0, 0, jam_setup, jam_probe, jam_op, jam_capture, jam_final},
#if ODHS_HAVE_CLP
    {"jam_lp", 7, 0, jam_lp_setup, NULL, jam_lp_op, jam_lp_capture, jam_lp_final},
    {"jam_quench", 7, 1, jam_lp_setup, NULL, jam_lp_op, jam_lp_capture, jam_lp_final},
#endif
    {"lsq", 2, 0, lsq_setup, NULL, lsq_op, lsq_capture, lsq_final},
#ifdef ODHS_HAVE_SUITESPARSE
    {"pcg_ordering", 5, 0, pcgo_setup, NULL, pcgo_op, pcgo_capture, pcgo_final},
#endif
    {"files", 2, 0, files_setup, NULL, files_op, files_capture, files_final},
    {"analysis", 6, 0, analysis_setup, NULL, analysis_op, analysis_capture, files_final},
    {"outputs", 8, 0, outputs_setup, NULL, outputs_op, outputs_capture, outputs_final},
    {"checkpoint", 3, 0, ckpt_setup, NULL, ckpt_op, ckpt_capture, ckpt_final},
    {"softcore", SC_NOPS, 0, soft_setup, NULL, soft_op, soft_capture, soft_final},
};
#define AF_NSCEN ((int)(sizeof scenarios / sizeof scenarios[0]))

START_TEST(test_walk) { walk(&scenarios[_i]); }
END_TEST

/* the counter and the trigger themselves */
START_TEST(test_hook)
{
    odhs_system *s = NULL;
    odhs__fault_arm(0, 0);
    ck_assert_int_eq(odhs_system_create(2, 4, &s), ODHS_OK);
    uint64_t n = odhs__fault_count();
    ck_assert_uint_eq(n, 4); /* handle, x, r, species */
    ck_assert(!odhs__fault_fired());
    odhs_system_destroy(s);
    s = NULL;
    int64_t live = odhs__fault_live();
    odhs__fault_arm(2, 0);
    ck_assert_int_eq(odhs_system_create(2, 4, &s), ODHS_E_NOMEM);
    ck_assert_ptr_null(s);
    ck_assert(odhs__fault_fired());
    ck_assert_uint_eq(odhs__fault_count(), 4);
    ck_assert_int_eq(odhs__fault_live(), live); /* the two that succeeded were freed */
    /* one-shot: the next call succeeds */
    ck_assert_int_eq(odhs_system_create(2, 4, &s), ODHS_OK);
    ck_assert_int_eq(odhs__fault_live(), live + 4);
    odhs_system_destroy(s);
    s = NULL;
    /* sticky: everything from the 2nd allocation on fails */
    odhs__fault_arm(2, 1);
    ck_assert_int_eq(odhs_system_create(2, 4, &s), ODHS_E_NOMEM);
    ck_assert_int_eq(odhs_system_create(2, 4, &s), ODHS_E_NOMEM);
    ck_assert_int_eq(odhs__fault_live(), live);
    odhs__fault_disarm();
    ck_assert(odhs__fault_fired());
    ck_assert_int_eq(odhs_system_create(2, 4, &s), ODHS_OK);
    odhs_system_destroy(s);
    ck_assert_int_eq(odhs__fault_live(), live);
    ck_assert(!leaks_now());
}
END_TEST

Suite *make_allocfail_suite(void)
{
    Suite *s = suite_create("allocfail");
    TCase *tc = tcase_create("hook");
    tcase_add_test(tc, test_hook);
    suite_add_tcase(s, tc);
    tc = tcase_create("walk");
    tcase_set_timeout(tc, 1200);
    tcase_add_loop_test(tc, test_walk, 0, AF_NSCEN);
    suite_add_tcase(s, tc);
    return s;
}

#endif /* ODHS_FAULT_INJECTION */
