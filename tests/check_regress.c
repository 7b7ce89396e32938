/*
 * libodhs - Check suite "regress": a regression corpus of small scenes.
 *
 * What it is for: every scene below builds a small simulation with the public
 * API only (odhs.h, testutil.h), runs it, and writes what it produced as text,
 * one `key value value ...` line each (numbers with %.17g): the events (up to
 * EV_CAP, then the totals), status codes of the run calls, final positions,
 * velocities, box and Lees-Edwards strain, observables, counters, contact
 * forces, jamming certificates, and the length and 64-bit FNV-1a hash of the
 * checkpoints written mid-run and at the end (a mid-run checkpoint is also
 * restored into a fresh stepper, whose continued run is recorded under "ck.").
 * The test compares that text with tests/data/regress/<scene>.txt (directory
 * ODHS_TEST_DATA, default tests/data, relative to the working directory) line
 * by line, bit for bit, and reports the scene, the line number and both lines
 * of the first difference. It pins the results of the library so that a
 * refactoring (e.g. of the stepper) can be shown not to change them.
 *
 * Re-recording (writes tests/data/regress/<scene>.txt instead of comparing):
 *     ODHS_REGRESS_RECORD=tests/data/regress CK_RUN_SUITE=regress make check-run
 * Re-record only for a deliberate change of results, and give the reason in
 * the commit message. One scene alone: CK_RUN_CASE=<scene>.
 *
 * Exceptions: a table entry with rel_tol > 0 compares numeric tokens with
 * |a - b| <= rel_tol max(|a|, |b|) (absolute floor 1e-300), other tokens
 * exactly, and skips the checkpoint hash lines. All entries are 0 (exact).
 *
 * Other BLAS: the scenes call BLAS and LAPACK (CHOLMOD's supernodal kernels,
 * the dense solvers), whose rounding depends on the build and on the kernels
 * it picks for the CPU (OpenBLAS uses its SkylakeX kernels on Intel AVX-512
 * and its Haswell/Zen ones on AMD EPYC: the scenes then differ in the last
 * bits). Recording also writes regress/blas.txt, a fingerprint of the
 * rounding of a fixed set of LAPACK calls (blas_fingerprint), and refuses to
 * add scenes to a corpus recorded with another fingerprint. When the
 * fingerprint now differs from the recorded one, every scene is compared in
 * the "other BLAS" mode, announced on stderr: numeric tokens agree when
 * |a - b| <= OTHER_REL max(|a|, |b|) + OTHER_ABS max(1, largest |number| of
 * the two lines); the step counts and the step size of adaptive steppers
 * (keys counts and adaptive), which rounding steers, within OTHER_LOOSE
 * relative; hashes of checkpoints are skipped; other tokens, the keys and
 * the number of lines are still exact. ODHS_REGRESS_EXACT=1 forbids this
 * mode (any difference of fingerprint then fails).
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <errno.h>
#include <inttypes.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include <lapacke.h>

#include "odhs.h"
#include "testutil.h"

#define OK(expr)                                                                                          \
    do {                                                                                                  \
        int rc_ = (expr);                                                                                 \
        ck_assert_msg(rc_ == ODHS_OK, "%s: %s returned %d (%s)", cur_name, #expr, rc_, odhs_strerror(rc_)); \
    } while (0)

#define EV_CAP 300
#define EULER ODHS_INTEGRATOR_EULER
#define HEUN (-1) /* the library's default: no set_integrator call */

static const char *cur_name = "";

/* ---- the record: a growing text ----------------------------------------- */
static char *T;
static size_t T_len, T_cap;

static void line(const char *fmt, ...)
{
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        int k = vsnprintf(T + T_len, T_cap - T_len, fmt, ap);
        va_end(ap);
        ck_assert(k >= 0);
        if ((size_t)k + 2 <= T_cap - T_len) {
            T_len += (size_t)k;
            T[T_len++] = '\n';
            T[T_len] = '\0';
            return;
        }
        T_cap = 2 * T_cap + (size_t)k + 64;
        T = realloc(T, T_cap);
        ck_assert(T != NULL);
    }
}

/* ---- a simulation and its event log ------------------------------------- */
typedef struct {
    int kind;
    size_t i, j;
    double t, g;
} evrec;

typedef struct sim {
    const char *pfx;    /* key prefix: "" or "ck." for the restored run */
    const char *solver; /* backend name */
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
    odhs_force_fn ffn; /* force callback, set again after a restore */
    void *fctx;
    int jam;       /* record the jamming certificate */
    double target; /* of the phase after a mid-run checkpoint */
    uint64_t nev, ncol, nopen;
    evrec ev[EV_CAP];
} sim;

static int on_event(const odhs_event *e, void *ctx)
{
    sim *s = ctx;
    if (s->nev < EV_CAP) {
        evrec r = {e->kind, e->i, e->j, e->time, e->strain};
        s->ev[s->nev] = r;
    }
    s->nev++;
    s->ncol += e->kind == ODHS_EVENT_COLLISION;
    s->nopen += e->kind == ODHS_EVENT_OPENING;
    return 0;
}

static void vec(const sim *s, const char *key, size_t n, const double *v)
{
    char buf[1024];
    size_t k = 0;
    for (size_t q = 0; q < n && k < sizeof buf - 32; ++q) k += (size_t)snprintf(buf + k, sizeof buf - k, " %.17g", v[q]);
    line("%s%s%s", s->pfx, key, buf);
}

/* an observable: its values, or "err <status>" */
static void obs(const sim *s, const char *key, int rc, size_t n, const double *v)
{
    if (rc) line("%s%s err %d", s->pfx, key, rc);
    else vec(s, key, n, v);
}

/* status of a run call, with its argument */
static int rcl(sim *s, const char *what, double arg, int rc)
{
    line("%src %s %.17g %d", s->pfx, what, arg, rc);
    if (rc < 0)
        fprintf(stderr, "[regress] %s: %s%s(%g): %s (%s)\n", cur_name, s->pfx, what, arg, odhs_strerror(rc),
                odhs_stepper_errmsg(s->st));
    return rc;
}

static int to_phi(sim *s, double phi) { return rcl(s, "phi", phi, odhs_stepper_run_until_packing_fraction(s->st, phi)); }
static int to_strain(sim *s, double g) { return rcl(s, "strain", g, odhs_stepper_run_until_strain(s->st, g)); }
static int to_events(sim *s, uint64_t k) { return rcl(s, "events", (double)k, odhs_stepper_run_events(s->st, k)); }
/* shear by dg more */
static int more_strain(sim *s, double dg)
{
    double g;
    OK(odhs_stepper_strain(s->st, &g));
    return to_strain(s, g + dg);
}
static int reset(sim *s) { return rcl(s, "reset", 0, odhs_stepper_reset(s->st)); }
static int correct(sim *s) { return rcl(s, "correct", 0, odhs_stepper_correct(s->st)); }

/* run until time T in units of the driver's tau */
static int to_time(sim *s, double T_tau)
{
    double tau;
    OK(odhs_driver_time_unit(s->drv, s->sys, &tau));
    return rcl(s, "time", T_tau * tau, odhs_stepper_run_until_time(s->st, T_tau * tau));
}

/* run for dT more, in units of tau */
static int more_time(sim *s, double dT_tau)
{
    double tau, t;
    OK(odhs_driver_time_unit(s->drv, s->sys, &tau));
    OK(odhs_stepper_time(s->st, &t));
    return rcl(s, "time", t + dT_tau * tau, odhs_stepper_run_until_time(s->st, t + dT_tau * tau));
}

/* k single steps (stops at the first nonzero status) */
static int steps(sim *s, int k)
{
    int rc = ODHS_OK;
    for (int q = 0; q < k && rc == ODHS_OK; ++q) rc = odhs_stepper_step(s->st, NULL);
    return rcl(s, "steps", k, rc);
}

/* compress at rate c to phi, then no compression */
static int compress(sim *s, double c, double phi)
{
    OK(odhs_driver_set_compression_rate(s->drv, c));
    int rc = to_phi(s, phi);
    OK(odhs_driver_set_compression_rate(s->drv, 0.0));
    return rc;
}

/* ---- scenes --------------------------------------------------------------- */
/* 50:50 bidisperse r = 0.5 / 0.7 with 3% polydispersity at random at phi */
static odhs_system *rand_sys(int dim, size_t n, double phi, uint64_t seed)
{
    odhs_system *sys;
    OK(odhs_system_create(dim, n, &sys));
    OK(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, seed));
    OK(odhs_system_place_random(sys, phi, seed + 1));
    return sys;
}

static void sim_make(sim *s, odhs_system *sys, const char *solver, int integrator)
{
    memset(s, 0, sizeof *s);
    s->pfx = "";
    s->solver = solver;
    s->sys = sys;
    OK(odhs_driver_create(&s->drv));
    OK(odhs_solver_create_by_name(solver, &s->sol));
    OK(odhs_stepper_create(sys, s->drv, s->sol, &s->st));
    OK(odhs_stepper_set_event_callback(s->st, on_event, s));
    if (integrator != HEUN) OK(odhs_stepper_set_integrator(s->st, integrator));
}

static void make(sim *s, int dim, size_t n, double phi, uint64_t seed, const char *solver, int integrator)
{
    sim_make(s, rand_sys(dim, n, phi, seed), solver, integrator);
}

static void sim_free(sim *s)
{
    odhs_stepper_destroy(s->st);
    odhs_solver_destroy(s->sol);
    odhs_driver_destroy(s->drv);
    odhs_system_destroy(s->sys);
}

static uint64_t fnv1a(const unsigned char *p, size_t n)
{
    uint64_t h = 0xcbf29ce484222325ULL;
    for (size_t k = 0; k < n; ++k) h = (h ^ p[k]) * 0x100000001b3ULL;
    return h;
}

/* the bytes of a checkpoint of st (through a temporary file); NULL on error */
static unsigned char *ckpt_bytes(const odhs_stepper *st, size_t *len, int *rc)
{
    const char *tmp = getenv("TMPDIR");
    char path[512];
    snprintf(path, sizeof path, "%s/odhs_regress_XXXXXX", tmp && *tmp ? tmp : "/tmp");
    int fd = mkstemp(path);
    ck_assert_msg(fd >= 0, "mkstemp %s: %s", path, strerror(errno));
    close(fd);
    unsigned char *buf = NULL;
    *len = 0;
    *rc = odhs_checkpoint_write(st, path);
    FILE *f = *rc ? NULL : fopen(path, "rb");
    if (f) {
        fseek(f, 0, SEEK_END);
        long n = ftell(f);
        fseek(f, 0, SEEK_SET);
        buf = malloc(n > 0 ? (size_t)n : 1);
        ck_assert(buf != NULL && n >= 0 && fread(buf, 1, (size_t)n, f) == (size_t)n);
        *len = (size_t)n;
        fclose(f);
    }
    remove(path);
    return buf;
}

/* record the state of s at the end of its run */
static void finish(sim *s)
{
    const char *p = s->pfx;
    int d = odhs_system_dim(s->sys);
    size_t n = odhs_system_count(s->sys), nd = n * (size_t)d;
    char key[64];
    for (uint64_t k = 0; k < s->nev && k < EV_CAP; ++k) {
        const evrec *e = &s->ev[k];
        line("%sev[%" PRIu64 "] %d %zu %zu %.17g %.17g", p, k, e->kind, e->i, e->j, e->t, e->g);
    }
    line("%sevents %" PRIu64 " %" PRIu64 " %" PRIu64, p, s->nev, s->ncol, s->nopen);
    double t = 0, g = 0, L[3] = {0, 0, 0}, le = 0, phi = 0, v9[9], z = 0, e2[2] = {0, 0};
    OK(odhs_stepper_time(s->st, &t));
    OK(odhs_stepper_strain(s->st, &g));
    line("%stime %.17g", p, t);
    line("%sstrain %.17g", p, g);
    OK(odhs_system_get_box(s->sys, L));
    vec(s, "box", (size_t)d, L);
    OK(odhs_system_get_strain(s->sys, &le));
    line("%sle_strain %.17g", p, le);
    OK(odhs_system_packing_fraction(s->sys, &phi));
    line("%sphi %.17g", p, phi);
    double *x = malloc(nd * sizeof *x), *V = malloc(nd * sizeof *V);
    ck_assert(x && V);
    OK(odhs_system_get_positions(s->sys, x));
    for (size_t i = 0; i < n; ++i) {
        snprintf(key, sizeof key, "x[%zu]", i);
        vec(s, key, (size_t)d, x + i * (size_t)d);
    }
    int rc = odhs_stepper_velocities(s->st, V);
    for (size_t i = 0; i < n; ++i) {
        snprintf(key, sizeof key, "v[%zu]", i);
        obs(s, key, rc, (size_t)d, V + i * (size_t)d);
    }
    free(V);
    obs(s, "stress", odhs_stepper_stress(s->st, v9), (size_t)(d * d), v9);
    obs(s, "pressure", odhs_stepper_pressure(s->st, v9), 1, v9);
    obs(s, "kappa", odhs_stepper_kappa(s->st, v9), 1, v9);
    obs(s, "dissipation", odhs_stepper_dissipation(s->st, v9), 1, v9);
    obs(s, "power", odhs_stepper_power(s->st, v9), 1, v9);
    OK(odhs_stepper_coordination(s->st, &z));
    line("%scoordination %.17g", p, z);
    uint64_t ns = 0, nc = 0, no = 0, rej = 0, rw = 0;
    double h = 0;
    OK(odhs_stepper_counts(s->st, &ns, &nc, &no));
    line("%scounts %" PRIu64 " %" PRIu64 " %" PRIu64, p, ns, nc, no);
    OK(odhs_stepper_errors(s->st, &e2[0], &e2[1]));
    vec(s, "errors", 2, e2);
    OK(odhs_stepper_adaptive_stats(s->st, &rej, &h));
    line("%sadaptive %" PRIu64 " %.17g", p, rej, h);
    OK(odhs_stepper_rewire_stats(s->st, &rw));
    line("%srewires %" PRIu64, p, rw);
    int integ;
    double dt, tol;
    unsigned corr;
    OK(odhs_stepper_get_settings(s->st, &integ, &dt, &tol, &corr));
    line("%ssettings %d %.17g %.17g %u", p, integ, dt, tol, corr);
    size_t nb = 0, nw = 0;
    OK(odhs_stepper_bond_count(s->st, &nb));
    OK(odhs_stepper_wall_count(s->st, &nw));
    line("%sbonds %zu", p, nb);
    line("%swalls %zu", p, nw);
    for (size_t w = 0; w < nw; ++w) {
        double fw[3], dw[3];
        OK(odhs_stepper_wall_force(s->st, w, fw));
        OK(odhs_stepper_wall_displacement(s->st, w, dw));
        snprintf(key, sizeof key, "wall_force[%zu]", w);
        vec(s, key, (size_t)d, fw);
        snprintf(key, sizeof key, "wall_disp[%zu]", w);
        vec(s, key, (size_t)d, dw);
    }
    const char *bname = "?";
    OK(odhs_solver_backend_name(s->sol, &bname, NULL));
    line("%sbackend %s", p, bname);
    const odhs_network *net = odhs_stepper_network(s->st);
    size_t ncon = odhs_network_count(net);
    double *f = malloc((ncon + 1) * sizeof *f);
    ck_assert(f != NULL);
    OK(odhs_network_get_forces(net, f));
    line("%scontacts %zu", p, ncon);
    for (size_t c = 0; c < ncon; ++c) {
        size_t i, j;
        int kind;
        OK(odhs_network_get_contact(net, c, &i, &j, &kind));
        line("%sc[%zu] %zu %zu %d %.17g", p, c, i, j, kind, f[c]);
    }
    free(f);
    if (s->jam) {
        odhs_jam_certificate c;
        memset(&c, 0, sizeof c);
        c.size = sizeof c;
        rc = odhs_stepper_certificate(s->st, &c);
        line("%scert %d %d %d", p, rc, c.jammed, c.isostatic);
        line("%scert.phi %.17g", p, c.phi);
        line("%scert.pressure %.17g", p, c.pressure);
        line("%scert.counts %zu %zu %zu %zu %zu %zu %zu", p, c.n_particles, c.n_rattlers, c.n_backbone, c.n_contacts,
             c.n_contacts_backbone, c.n_contacts_isostatic, c.n_pivots);
        line("%scert.z %.17g %.17g", p, c.z, c.z_backbone);
        line("%scert.errors %.17g %.17g %.17g %.17g", p, c.force_balance, c.gap_error, c.overlap, c.min_force);
    }
    /* the final checkpoint, and whether it reads back */
    size_t len;
    unsigned char *buf = ckpt_bytes(s->st, &len, &rc);
    int rc2 = ODHS_E_STATE;
    if (buf) {
        odhs_solver *sol;
        odhs_system *sys2 = NULL;
        odhs_driver *drv2 = NULL;
        odhs_stepper *st2 = NULL;
        OK(odhs_solver_create_by_name(s->solver, &sol));
        rc2 = odhs_checkpoint_parse(buf, len, sol, &sys2, &drv2, &st2, NULL, 0);
        odhs_stepper_destroy(st2);
        odhs_driver_destroy(drv2);
        odhs_system_destroy(sys2);
        odhs_solver_destroy(sol);
    }
    line("%sckpt_end %d %zu %016" PRIx64 " %d", p, rc, len, fnv1a(buf, len), rc2);
    free(buf);
    free(x);
}

/* Checkpoint s now, restore it into a fresh stepper c, run the phase on both,
 * record both (c under "ck."), and whether they end at the same positions. */
static void split(sim *s, int (*phase)(sim *))
{
    size_t len;
    int rc;
    unsigned char *buf = ckpt_bytes(s->st, &len, &rc);
    line("%sckpt_mid %d %zu %016" PRIx64, s->pfx, rc, len, fnv1a(buf, len));
    ck_assert_msg(rc == ODHS_OK, "%s: checkpoint_write: %s", cur_name, odhs_stepper_errmsg(s->st));
    sim *c = calloc(1, sizeof *c);
    ck_assert(c != NULL);
    c->pfx = "ck.";
    c->solver = s->solver;
    c->jam = s->jam;
    c->target = s->target;
    c->ffn = s->ffn;
    c->fctx = s->fctx;
    OK(odhs_solver_create_by_name(s->solver, &c->sol));
    char err[256];
    rc = odhs_checkpoint_parse(buf, len, c->sol, &c->sys, &c->drv, &c->st, err, sizeof err);
    line("ck.restore %d", rc);
    ck_assert_msg(rc == ODHS_OK, "%s: checkpoint_parse: %s", cur_name, err);
    free(buf);
    OK(odhs_stepper_set_event_callback(c->st, on_event, c));
    if (c->ffn) OK(odhs_driver_set_force_callback(c->drv, c->ffn, c->fctx));
    phase(s);
    finish(s);
    phase(c);
    finish(c);
    size_t nd = odhs_system_count(s->sys) * (size_t)odhs_system_dim(s->sys);
    double *xa = malloc(nd * sizeof *xa), *xb = malloc(nd * sizeof *xb);
    ck_assert(xa && xb);
    OK(odhs_system_get_positions(s->sys, xa));
    OK(odhs_system_get_positions(c->sys, xb));
    line("ck.same_positions %d", memcmp(xa, xb, nd * sizeof *xa) == 0);
    free(xa);
    free(xb);
    sim_free(c);
    free(c);
}

static int ph_strain(sim *s) { return to_strain(s, s->target); }
static int ph_time(sim *s) { return to_time(s, s->target); }
static int ph_phi(sim *s) { return to_phi(s, s->target); }

/* ---- scenes: fixed-volume shear (Lees-Edwards) ----------------------------- */
static void shear_scene(int dim, size_t n, uint64_t seed, const char *solver, int integ, double phi, double strain)
{
    sim s;
    make(&s, dim, n, dim == 2 ? 0.45 : 0.30, seed, solver, integ);
    compress(&s, 1.0, phi);
    OK(odhs_driver_set_shear_rate(s.drv, 1.0));
    to_strain(&s, strain);
    finish(&s);
    sim_free(&s);
}

static void sc_shear_2d_cg(void) { shear_scene(2, 32, 1, "cg", HEUN, 0.80, 0.3); }
static void sc_shear_2d_dense(void) { shear_scene(2, 32, 2, "dense", HEUN, 0.80, 0.3); }
static void sc_shear_2d_cholmod(void) { shear_scene(2, 32, 3, "cholmod", HEUN, 0.80, 0.3); }
static void sc_shear_2d_cholmod_pcg(void) { shear_scene(2, 32, 4, "cholmod-pcg", HEUN, 0.80, 0.3); }
static void sc_shear_2d_spqr(void) { shear_scene(2, 32, 5, "spqr", HEUN, 0.80, 0.3); }
static void sc_shear_2d_auto(void) { shear_scene(2, 48, 6, "auto", HEUN, 0.81, 0.3); }
static void sc_shear_3d_cg(void) { shear_scene(3, 32, 7, "cg", HEUN, 0.56, 0.2); }
static void sc_shear_3d_cholmod_pcg(void) { shear_scene(3, 32, 8, "cholmod-pcg", HEUN, 0.56, 0.2); }
static void sc_shear_3d_spqr(void) { shear_scene(3, 32, 9, "spqr", HEUN, 0.56, 0.2); }
static void sc_shear_3d_auto(void) { shear_scene(3, 40, 10, "auto", HEUN, 0.57, 0.2); }
/* the paper's scheme: explicit Euler, dt 1e-3, correction every 10 steps, CG */
static void sc_shear_2d_euler_cg(void) { shear_scene(2, 32, 11, "cg", EULER, 0.80, 0.2); }
static void sc_shear_3d_euler_dense(void) { shear_scene(3, 24, 12, "dense", EULER, 0.55, 0.15); }

/* negative shear past the Lees-Edwards remapping at -1/2, own Heun settings,
 * single steps, a run of events and a drift correction */
static void sc_shear_2d_remap(void)
{
    sim s;
    make(&s, 2, 24, 0.55, 13, "cholmod", HEUN);
    OK(odhs_stepper_set_tolerance(s.st, 1e-8));
    OK(odhs_stepper_set_dt(s.st, 1e-2));
    OK(odhs_driver_set_shear_rate(s.drv, -2.0));
    reset(&s);
    steps(&s, 40);
    to_events(&s, 60);
    correct(&s);
    to_strain(&s, -0.75);
    finish(&s);
    sim_free(&s);
}

/* compression, dilation (negative rate) under shear, then shear by events */
static void sc_dilate_2d(void)
{
    sim s;
    make(&s, 2, 32, 0.45, 14, "dense", HEUN);
    compress(&s, 1.0, 0.79);
    OK(odhs_driver_set_shear_rate(s.drv, 1.0));
    OK(odhs_driver_set_compression_rate(s.drv, -0.5));
    more_time(&s, 0.04); /* phi 0.79 -> 0.76 */
    OK(odhs_driver_set_compression_rate(s.drv, 0.0));
    to_events(&s, 60);
    finish(&s);
    sim_free(&s);
}

/* ---- fixed pressure -------------------------------------------------------- */
static void pressure_scene(int dim, size_t n, uint64_t seed, const char *solver, int integ, double phi, double strain,
                           int ckpt)
{
    sim s;
    make(&s, dim, n, dim == 2 ? 0.45 : 0.30, seed, solver, integ);
    compress(&s, 1.0, phi);
    OK(odhs_driver_set_shear_rate(s.drv, 1.0));
    steps(&s, 10);
    double p0;
    OK(odhs_stepper_pressure(s.st, &p0));
    line("p0 %.17g", p0);
    OK(odhs_driver_set_pressure(s.drv, 2.0 * p0));
    if (ckpt) {
        to_strain(&s, 0.5 * strain);
        s.target = strain;
        split(&s, ph_strain);
    } else {
        to_strain(&s, strain);
        finish(&s);
    }
    sim_free(&s);
}

static void sc_pressure_2d_cg(void) { pressure_scene(2, 32, 21, "cg", HEUN, 0.80, 0.2, 0); }
static void sc_pressure_3d_dense(void) { pressure_scene(3, 24, 22, "dense", HEUN, 0.55, 0.15, 0); }
static void sc_pressure_2d_euler_spqr(void) { pressure_scene(2, 32, 23, "spqr", EULER, 0.78, 0.15, 0); }
static void sc_pressure_2d_auto_ckpt(void) { pressure_scene(2, 32, 24, "auto", HEUN, 0.80, 0.2, 1); }

/* ---- jamming: the protocols of examples/jam_packing.c ------------------------ */
/* shear (at fixed pressure: doubled every 0.05) until jammed or max_strain */
static int jam_drive_shear(sim *s, int pressure, double max_strain)
{
    double g0, p = 1.0;
    int rc = ODHS_OK;
    OK(odhs_stepper_strain(s->st, &g0));
    for (double g = g0; g < g0 + max_strain && rc == ODHS_OK;) {
        g += 0.05;
        rc = odhs_stepper_run_until_strain(s->st, g);
        if (pressure) {
            p *= 2.0;
            OK(odhs_driver_set_pressure(s->drv, p));
        }
    }
    return rcl(s, "jam_shear", max_strain, rc);
}

/* JAM_PAPER: compression with the paper's Euler scheme as it is (correction
 * every 10 steps), which may stop at ODHS_POTENTIALLY_JAMMED (jamming.h) */
typedef enum { JAM_COMPRESS, JAM_SHEAR, JAM_SHEAR_COMPRESS, JAM_PRESSURE, JAM_PAPER } jam_protocol;

static void jam_scene(int dim, size_t n, uint64_t seed, const char *solver, int integ, jam_protocol proto, int ckpt)
{
    sim s;
    make(&s, dim, n, dim == 2 ? 0.45 : 0.30, seed, solver, integ);
    s.jam = 1;
    if (integ == EULER && proto != JAM_PAPER)
        OK(odhs_stepper_set_correction_interval(s.st, 1)); /* as jam_packing --integrator euler */
    switch (proto) {
    case JAM_COMPRESS:
    case JAM_PAPER:
        OK(odhs_driver_set_compression_rate(s.drv, 1.0));
        if (ckpt) {
            to_phi(&s, dim == 2 ? 0.75 : 0.55);
            s.target = 0.999;
            split(&s, ph_phi);
            sim_free(&s);
            return;
        }
        to_phi(&s, 0.999);
        break;
    case JAM_SHEAR:
        OK(odhs_driver_set_compression_rate(s.drv, 1.0));
        if (to_phi(&s, 0.999) == ODHS_JAMMED) {
            /* dilate by 0.2% (all contacts open) and shear at fixed volume */
            odhs_stepper_destroy(s.st);
            OK(odhs_system_scale_box(s.sys, pow(1.002, 1.0 / dim)));
            OK(odhs_driver_set_compression_rate(s.drv, 0.0));
            OK(odhs_driver_set_shear_rate(s.drv, 1.0));
            OK(odhs_stepper_create(s.sys, s.drv, s.sol, &s.st));
            OK(odhs_stepper_set_event_callback(s.st, on_event, &s));
            if (integ == EULER) {
                OK(odhs_stepper_set_integrator(s.st, EULER));
                OK(odhs_stepper_set_correction_interval(s.st, 1));
            }
            jam_drive_shear(&s, 0, 3.0);
        }
        break;
    case JAM_SHEAR_COMPRESS:
        OK(odhs_driver_set_shear_rate(s.drv, 1.0));
        OK(odhs_driver_set_compression_rate(s.drv, 0.2));
        to_phi(&s, 0.999);
        break;
    case JAM_PRESSURE:
        OK(odhs_driver_set_shear_rate(s.drv, 1.0));
        OK(odhs_driver_set_pressure(s.drv, 1.0));
        OK(odhs_driver_set_jamming_pressure(s.drv, 0.0)); /* jam_packing's default */
        jam_drive_shear(&s, 1, 3.0);
        break;
    }
    finish(&s);
    sim_free(&s);
}

static void sc_jam_compress_2d(void) { jam_scene(2, 32, 31, "cholmod-pcg", HEUN, JAM_COMPRESS, 0); }
static void sc_jam_compress_3d(void) { jam_scene(3, 24, 32, "cholmod-pcg", HEUN, JAM_COMPRESS, 0); }
static void sc_jam_shear_2d(void) { jam_scene(2, 32, 33, "cholmod-pcg", HEUN, JAM_SHEAR, 0); }
static void sc_jam_shear_compress_2d(void) { jam_scene(2, 32, 34, "cholmod-pcg", HEUN, JAM_SHEAR_COMPRESS, 0); }
static void sc_jam_pressure_2d(void) { jam_scene(2, 32, 35, "cholmod-pcg", HEUN, JAM_PRESSURE, 0); }
static void sc_jam_compress_2d_euler(void) { jam_scene(2, 32, 36, "dense", EULER, JAM_COMPRESS, 0); }
static void sc_jam_compress_2d_paper(void) { jam_scene(2, 32, 39, "dense", EULER, JAM_PAPER, 0); }
static void sc_jam_shear_compress_3d(void) { jam_scene(3, 24, 37, "dense", HEUN, JAM_SHEAR_COMPRESS, 0); }
static void sc_jam_compress_2d_ckpt(void) { jam_scene(2, 32, 38, "dense", HEUN, JAM_COMPRESS, 1); }

/* ---- hard walls -------------------------------------------------------------- */
/* a system from explicit radii and positions */
static odhs_system *conf_sys(int dim, size_t n, const double *L, const double *r, const double *x)
{
    odhs_system *sys;
    OK(odhs_system_create(dim, n, &sys));
    OK(odhs_system_set_configuration(sys, L, 0.0, r, x));
    return sys;
}

/* n discs in the rectangle [lo, hi] (per axis) at random without overlap,
 * radii 0.5 / 0.7 alternating; fills x, r */
static void place_in(int dim, size_t n, const double *lo, const double *hi, double *r, double *x, uint64_t seed)
{
    tu_rng rng;
    tu_rng_seed(&rng, seed);
    for (size_t i = 0; i < n; ++i) {
        r[i] = (i % 2 ? 0.7 : 0.5) * (1.0 + 0.05 * tu_uniform_in(&rng, -1.0, 1.0));
        int ok = 0;
        for (int t = 0; t < 100000 && !ok; ++t) {
            for (int k = 0; k < dim; ++k) x[i * dim + k] = tu_uniform_in(&rng, lo[k] + r[i], hi[k] - r[i]);
            ok = 1;
            for (size_t j = 0; j < i && ok; ++j) {
                double s2 = 0;
                for (int k = 0; k < dim; ++k) s2 += (x[i * dim + k] - x[j * dim + k]) * (x[i * dim + k] - x[j * dim + k]);
                ok = s2 > (r[i] + r[j]) * (r[i] + r[j]) * 1.0001;
            }
        }
        ck_assert_msg(ok, "%s: cannot place particle %zu", cur_name, i);
    }
}

/* a 2D channel between a floor and a ceiling, driven along x and down */
static void sc_walls_planes_2d(void)
{
    enum { N = 32 };
    double L[2] = {12, 14}, lo[2] = {0, 1.2}, hi[2] = {12, 12.8}, r[N], x[2 * N], F[2 * N];
    place_in(2, N, lo, hi, r, x, 41);
    for (int i = 0; i < N; ++i) {
        F[2 * i] = 0.5 + 0.1 * (i % 3);
        F[2 * i + 1] = -1.0 + 0.05 * (i % 5);
    }
    sim s;
    sim_make(&s, conf_sys(2, N, L, r, x), "dense", HEUN);
    OK(odhs_driver_set_forces(s.drv, N, 2, F));
    double up[2] = {0, 1}, down[2] = {0, -1};
    OK(odhs_stepper_add_wall_plane(s.st, up, 1.0, NULL));
    OK(odhs_stepper_add_wall_plane(s.st, down, -13.0, NULL));
    to_time(&s, 4.0);
    finish(&s);
    sim_free(&s);
}

/* 3D: a floor under gravity */
static void sc_walls_planes_3d(void)
{
    enum { N = 24 };
    double L[3] = {6, 6, 14}, lo[3] = {0, 0, 1.2}, hi[3] = {6, 6, 12}, r[N], x[3 * N];
    place_in(3, N, lo, hi, r, x, 42);
    sim s;
    sim_make(&s, conf_sys(3, N, L, r, x), "cholmod", HEUN);
    double gz[3] = {0.1, 0.0, -1.0}, up[3] = {0, 0, 1};
    OK(odhs_driver_set_gravity(s.drv, 3, gz));
    OK(odhs_stepper_add_wall_plane(s.st, up, 1.0, NULL));
    to_time(&s, 5.0);
    finish(&s);
    sim_free(&s);
}

/* discs pushed into a circular container */
static void sc_walls_circle_2d(void)
{
    enum { M = 16 };
    double L[2] = {30, 30}, r[M], x[2 * M], F[2 * M];
    tu_rng rng;
    tu_rng_seed(&rng, 43);
    for (int k = 0; k < M; ++k) {
        r[k] = k % 2 ? 0.7 : 0.5;
        x[2 * k] = 12.0 + 2.0 * (k % 4) + 0.1 * tu_uniform(&rng);
        x[2 * k + 1] = 11.5 + 2.0 * (k / 4) + 0.1 * tu_uniform(&rng);
        F[2 * k] = 1.0;
        F[2 * k + 1] = 0.4;
    }
    sim s;
    sim_make(&s, conf_sys(2, M, L, r, x), "spqr", HEUN);
    OK(odhs_driver_set_forces(s.drv, M, 2, F));
    double c[2] = {15.0, 15.0};
    OK(odhs_stepper_add_wall_sphere(s.st, c, 6.5, NULL));
    to_time(&s, 12.0);
    finish(&s);
    sim_free(&s);
}

/* 3D spherical container, particles pulled to one side */
static void sc_walls_sphere_3d(void)
{
    enum { N = 20 };
    double L[3] = {16, 16, 16}, lo[3] = {5.5, 5.5, 5.5}, hi[3] = {10.5, 10.5, 10.5}, r[N], x[3 * N], F[3 * N];
    place_in(3, N, lo, hi, r, x, 44);
    for (int i = 0; i < N; ++i) {
        F[3 * i] = 1.0;
        F[3 * i + 1] = -0.3;
        F[3 * i + 2] = 0.2 * (i % 3 - 1);
    }
    sim s;
    sim_make(&s, conf_sys(3, N, L, r, x), "cg", HEUN);
    OK(odhs_driver_set_forces(s.drv, N, 3, F));
    double c[3] = {8, 8, 8};
    OK(odhs_stepper_add_wall_sphere(s.st, c, 4.8, NULL));
    to_time(&s, 6.0);
    finish(&s);
    sim_free(&s);
}

/* a piston pushing discs onto a floor (as in check_walls.c) */
static void piston_sim(sim *s, const char *solver, int integ)
{
    enum { NP = 40 };
    double L[2] = {12, 30}, r[NP], x[2 * NP];
    for (int k = 0; k < NP; ++k) {
        r[k] = k % 2 ? 0.7 : 0.5;
        x[2 * k] = 1.0 + 2.0 * (k % 6) + 0.3 * ((k / 6) % 2);
        x[2 * k + 1] = 3.0 + 2.5 * (k / 6);
    }
    sim_make(s, conf_sys(2, NP, L, r, x), solver, integ);
    double up[2] = {0.0, 1.0}, down[2] = {0.0, -1.0}, v[2] = {0.0, -1.0};
    size_t piston;
    OK(odhs_stepper_add_wall_plane(s->st, up, 1.0, NULL));
    OK(odhs_stepper_add_wall_plane(s->st, down, -20.0, &piston));
    OK(odhs_stepper_set_wall_velocity(s->st, piston, v));
    OK(odhs_driver_set_time_unit(s->drv, 1.0));
    OK(odhs_stepper_set_dt(s->st, 2e-3));
}

static void sc_walls_piston_2d(void)
{
    sim s;
    piston_sim(&s, "dense", HEUN);
    to_time(&s, 6.0);
    finish(&s);
    sim_free(&s);
}

static void sc_walls_piston_ckpt(void)
{
    sim s;
    piston_sim(&s, "cg", EULER);
    to_time(&s, 1.0); /* before any wall contact: see the report of walls_piston_2d */
    s.target = 5.0;
    split(&s, ph_time);
    sim_free(&s);
}

/* a small hopper: two funnel segments, discs falling under gravity */
static void sc_hopper_2d(void)
{
    enum { N = 30 };
    double W = 12.0, outlet = 3.2, yout = 6.0, ytop = yout + 0.5 * (W - outlet);
    double L[2] = {W, 34.0}, lo[2] = {0.0, ytop + 1.0}, hi[2] = {W, 30.0}, r[N], x[2 * N];
    place_in(2, N, lo, hi, r, x, 45);
    sim s;
    sim_make(&s, conf_sys(2, N, L, r, x), "cholmod-pcg", HEUN);
    double g[2] = {0.0, -1.0};
    OK(odhs_driver_set_gravity(s.drv, 2, g));
    double a0[2] = {0.0, ytop}, b0[2] = {0.5 * (W - outlet), yout};
    double a1[2] = {0.5 * (W + outlet), yout}, b1[2] = {W, ytop};
    OK(odhs_stepper_add_wall_segment(s.st, a0, b0, NULL));
    OK(odhs_stepper_add_wall_segment(s.st, a1, b1, NULL));
    OK(odhs_stepper_set_tolerance(s.st, 1e-3));
    OK(odhs_stepper_set_dt(s.st, 0.05));
    to_time(&s, 14.0);
    finish(&s);
    sim_free(&s);
}

/* ---- composites ------------------------------------------------------------- */
/* nb bodies of k touching beads (k = 2, 3) around centres placed at random at
 * phi (of the enclosing discs/spheres), randomly oriented */
static odhs_system *bodies_sys(int dim, size_t nb, int k, double phi, uint64_t seed)
{
    double enc = k == 3 ? 1.0 + 2.0 / sqrt(3.0) : 2.0, Lb[3];
    odhs_system *tmp;
    OK(odhs_system_create(dim, nb, &tmp));
    OK(odhs_system_set_radii_bidisperse(tmp, 0.5 * enc, 1.4, 0.0, seed));
    OK(odhs_system_place_random(tmp, phi, seed + 1));
    size_t n = nb * (size_t)k;
    double *c = malloc(nb * dim * sizeof *c), *R = malloc(nb * sizeof *R), *x = malloc(n * dim * sizeof *x),
           *r = malloc(n * sizeof *r);
    ck_assert(c && R && x && r);
    OK(odhs_system_get_positions(tmp, c));
    OK(odhs_system_get_radii(tmp, R));
    OK(odhs_system_get_box(tmp, Lb));
    tu_rng rng;
    tu_rng_seed(&rng, seed);
    for (size_t b = 0; b < nb; ++b) {
        double a = R[b] / enc, dc = k == 3 ? 2.0 * a / sqrt(3.0) : a, u[3] = {0, 0, 0}, v[3] = {0, 0, 0};
        double th = 2.0 * TU_PI * tu_uniform(&rng);
        if (dim == 2) {
            u[0] = cos(th), u[1] = sin(th), v[0] = -u[1], v[1] = u[0];
        } else {
            double cz = tu_uniform_in(&rng, -1, 1), sz = sqrt(1 - cz * cz), w[3], wu = 0, wn = 0;
            u[0] = sz * cos(th), u[1] = sz * sin(th), u[2] = cz;
            w[0] = tu_uniform_in(&rng, -1, 1), w[1] = tu_uniform_in(&rng, -1, 1), w[2] = tu_uniform_in(&rng, -1, 1);
            for (int q = 0; q < 3; ++q) wu += w[q] * u[q];
            for (int q = 0; q < 3; ++q) v[q] = w[q] - wu * u[q], wn += v[q] * v[q];
            for (int q = 0; q < 3; ++q) v[q] /= sqrt(wn);
        }
        for (int q = 0; q < k; ++q) {
            double t = 2.0 * TU_PI * q / k;
            size_t i = b * (size_t)k + (size_t)q;
            r[i] = a;
            for (int e = 0; e < dim; ++e) x[i * dim + e] = c[b * dim + e] + dc * (cos(t) * u[e] + sin(t) * v[e]);
        }
    }
    odhs_system *sys = conf_sys(dim, n, Lb, r, x);
    free(c);
    free(R);
    free(x);
    free(r);
    odhs_system_destroy(tmp);
    return sys;
}

static void bodies_sim(sim *s, int dim, size_t nb, int k, uint64_t seed, const char *solver)
{
    sim_make(s, bodies_sys(dim, nb, k, dim == 2 ? 0.5 : 0.35, seed), solver, HEUN);
    for (size_t b = 0; b < nb; ++b) {
        size_t beads[3] = {b * k, b * k + 1, b * k + 2};
        OK(odhs_stepper_add_rigid_body(s->st, (size_t)k, beads));
    }
    OK(odhs_driver_set_shear_rate(s->drv, 1.0));
}

static void sc_comp_trimers_2d(void)
{
    sim s;
    bodies_sim(&s, 2, 12, 3, 51, "cg");
    compress(&s, 0.5, 0.62);
    more_strain(&s, 0.3);
    finish(&s);
    sim_free(&s);
}

static void sc_comp_dimers_2d(void)
{
    sim s;
    bodies_sim(&s, 2, 16, 2, 52, "dense");
    compress(&s, 0.5, 0.65);
    more_strain(&s, 0.3);
    finish(&s);
    sim_free(&s);
}

static void sc_comp_trimers_3d(void)
{
    sim s;
    bodies_sim(&s, 3, 10, 3, 53, "cholmod");
    compress(&s, 0.5, 0.40);
    more_strain(&s, 0.2);
    finish(&s);
    sim_free(&s);
}

static void sc_comp_dimers_3d_ckpt(void)
{
    sim s;
    bodies_sim(&s, 3, 14, 2, 54, "spqr");
    compress(&s, 0.5, 0.42);
    more_strain(&s, 0.1);
    double g;
    OK(odhs_stepper_strain(s.st, &g));
    s.target = g + 0.1;
    split(&s, ph_strain);
    sim_free(&s);
}

/* a floppy chain of 10 beads (nearest neighbours) and one bond with a rest
 * length of its own, in a suspension under shear and slow compression */
static void sc_comp_chain_2d(void)
{
    enum { N = 32, K = 10 };
    sim s;
    make(&s, 2, N, 0.5, 55, "auto", HEUN);
    size_t beads[K];
    unsigned char used[N] = {0};
    beads[0] = 0;
    used[0] = 1;
    for (int q = 1; q < K; ++q) {
        double best = INFINITY, dist, rij[2];
        for (size_t j = 0; j < N; ++j) {
            if (used[j]) continue;
            OK(odhs_system_separation(s.sys, beads[q - 1], j, rij, &dist, NULL));
            if (dist < best) best = dist, beads[q] = j;
        }
        used[beads[q]] = 1;
    }
    OK(odhs_stepper_add_chain(s.st, K, beads));
    size_t bi = 0, bj = 0;
    double best = INFINITY, dist, rij[2];
    for (size_t i = 0; i < N; ++i)
        for (size_t j = i + 1; j < N; ++j) {
            if (used[i] || used[j]) continue;
            OK(odhs_system_separation(s.sys, i, j, rij, &dist, NULL));
            if (dist < best) best = dist, bi = i, bj = j;
        }
    OK(odhs_stepper_add_bond(s.st, bi, bj, 1.05 * best));
    OK(odhs_driver_set_shear_rate(s.drv, 1.0));
    compress(&s, 0.2, 0.72);
    more_strain(&s, 0.2);
    finish(&s);
    sim_free(&s);
}

/* ---- external forces: propulsion, gravity, fixed forces, callback ---------- */
static void sc_prop_2d(void)
{
    sim s;
    make(&s, 2, 32, 0.5, 61, "dense", HEUN);
    OK(odhs_driver_set_self_propulsion(s.drv, 32, 2, 0.0, sqrt(3.0), 0.0, 2.0, 62));
    to_time(&s, 3.0);
    finish(&s);
    sim_free(&s);
}

static void sc_prop_3d(void)
{
    sim s;
    make(&s, 3, 32, 0.35, 63, "cg", HEUN);
    OK(odhs_driver_set_self_propulsion(s.drv, 32, 3, 0.5, 1.5, 0.5, 1.5, 64));
    to_time(&s, 3.0);
    finish(&s);
    sim_free(&s);
}

static void sc_prop_gravity_euler(void)
{
    sim s;
    make(&s, 2, 32, 0.55, 65, "cholmod", EULER);
    double g[2] = {0.3, -0.8};
    OK(odhs_driver_set_self_propulsion(s.drv, 32, 2, 0.5, 1.0, 0.0, 0.5, 66));
    OK(odhs_driver_set_gravity(s.drv, 2, g));
    to_time(&s, 1.0);
    finish(&s);
    sim_free(&s);
}

static void sc_prop_gravity_ckpt(void)
{
    enum { N = 32 };
    sim s;
    make(&s, 2, N, 0.55, 67, "spqr", HEUN);
    double g[2] = {0.0, -1.0}, w[N];
    for (int i = 0; i < N; ++i) w[i] = i % 7 == 3 ? -0.5 : 1.0 + 0.25 * (i % 3); /* some buoyant */
    OK(odhs_driver_set_self_propulsion(s.drv, N, 2, 0.5, 1.5, 0.0, 1.0, 68));
    OK(odhs_driver_set_gravity(s.drv, 2, g));
    OK(odhs_driver_set_gravity_weights(s.drv, N, w));
    to_time(&s, 1.5);
    s.target = 3.0;
    split(&s, ph_time);
    sim_free(&s);
}

/* sedimentation with volume weights in a periodic box */
static void sc_gravity_3d(void)
{
    sim s;
    make(&s, 3, 32, 0.4, 69, "cholmod-pcg", HEUN);
    double g[3] = {0.0, 0.0, -1.0};
    OK(odhs_driver_set_gravity(s.drv, 3, g));
    to_time(&s, 4.0);
    finish(&s);
    sim_free(&s);
}

static void fixed_forces(sim *s, uint64_t seed, double mean_x)
{
    size_t n = odhs_system_count(s->sys), nd = n * (size_t)odhs_system_dim(s->sys);
    double *F = malloc(nd * sizeof *F);
    ck_assert(F != NULL);
    tu_rng rng;
    tu_rng_seed(&rng, seed);
    for (size_t k = 0; k < nd; ++k) F[k] = tu_uniform_in(&rng, -1.0, 1.0) + (k % (nd / n) == 0 ? mean_x : 0.0);
    OK(odhs_driver_set_forces(s->drv, n, odhs_system_dim(s->sys), F));
    free(F);
}

static void sc_forces_2d(void)
{
    sim s;
    make(&s, 2, 32, 0.6, 71, "cg", HEUN);
    fixed_forces(&s, 72, 0.0);
    to_time(&s, 2.0);
    finish(&s);
    sim_free(&s);
}

static void sc_forces_shear_3d(void)
{
    sim s;
    make(&s, 3, 32, 0.4, 73, "auto", HEUN);
    fixed_forces(&s, 74, 0.3);
    OK(odhs_driver_set_shear_rate(s.drv, 1.0));
    compress(&s, 1.0, 0.5);
    more_strain(&s, 0.3);
    finish(&s);
    sim_free(&s);
}

/* a callback force field: a sinusoidal shear force depending on y and t */
static int field_force(double t, const odhs_system *sys, double *F, void *ctx)
{
    double amp = *(const double *)ctx, L[3], *x;
    size_t n = odhs_system_count(sys);
    int d = odhs_system_dim(sys);
    if (odhs_system_get_box(sys, L) || !(x = malloc(n * d * sizeof *x))) return 1;
    odhs_system_get_positions(sys, x);
    for (size_t i = 0; i < n; ++i) {
        F[i * d] = amp * sin(2.0 * TU_PI * x[i * d + 1] / L[1] + 0.5 * t);
        F[i * d + 1] = 0.3 * amp * cos(2.0 * TU_PI * x[i * d] / L[0]);
        if (d == 3) F[i * d + 2] = 0.0;
    }
    free(x);
    return 0;
}

static double field_amp = 1.5;

static void callback_sim(sim *s, uint64_t seed, const char *solver)
{
    make(s, 2, 32, 0.55, seed, solver, HEUN);
    s->ffn = field_force;
    s->fctx = &field_amp;
    OK(odhs_driver_set_force_callback(s->drv, field_force, &field_amp));
    OK(odhs_driver_set_time_unit(s->drv, 1.0));
}

static void sc_callback_2d(void)
{
    sim s;
    callback_sim(&s, 75, "dense");
    to_time(&s, 2.0);
    finish(&s);
    sim_free(&s);
}

static void sc_callback_ckpt(void)
{
    sim s;
    callback_sim(&s, 76, "cg");
    to_time(&s, 1.0);
    s.target = 2.0;
    split(&s, ph_time);
    sim_free(&s);
}

/* a shear run checkpointed right after a change of the shear rate (the
 * restored run must re-solve the forces at its next step) */
static void sc_shear_drvchange_ckpt(void)
{
    sim s;
    make(&s, 2, 32, 0.45, 81, "cholmod", HEUN);
    compress(&s, 1.0, 0.79);
    OK(odhs_driver_set_shear_rate(s.drv, 1.0));
    to_strain(&s, 0.1);
    OK(odhs_driver_set_shear_rate(s.drv, 1.7));
    s.target = 0.25;
    split(&s, ph_strain);
    sim_free(&s);
}

static void sc_shear_3d_ckpt(void)
{
    sim s;
    make(&s, 3, 32, 0.30, 82, "dense", EULER);
    compress(&s, 1.0, 0.55);
    OK(odhs_driver_set_shear_rate(s.drv, 1.0));
    to_strain(&s, 0.1);
    s.target = 0.2;
    split(&s, ph_strain);
    sim_free(&s);
}

/* ---- the table ----------------------------------------------------------------- */
typedef struct {
    const char *name;
    void (*fn)(void);
    double rel_tol; /* 0: bit-identical (see the top of the file) */
} scene_entry;

#define S(name) {#name, sc_##name, 0.0}
static const scene_entry scenes[] = {
    S(shear_2d_cg),          S(shear_2d_dense),         S(shear_2d_cholmod),       S(shear_2d_cholmod_pcg),
    S(shear_2d_spqr),        S(shear_2d_auto),          S(shear_3d_cg),            S(shear_3d_cholmod_pcg),
    S(shear_3d_spqr),        S(shear_3d_auto),          S(shear_2d_euler_cg),      S(shear_3d_euler_dense),
    S(shear_2d_remap),       S(dilate_2d),              S(pressure_2d_cg),         S(pressure_3d_dense),
    S(pressure_2d_euler_spqr), S(pressure_2d_auto_ckpt), S(jam_compress_2d),       S(jam_compress_3d),
    S(jam_shear_2d),         S(jam_shear_compress_2d),  S(jam_pressure_2d),        S(jam_compress_2d_euler), S(jam_compress_2d_paper),
    S(jam_shear_compress_3d), S(jam_compress_2d_ckpt),  S(walls_planes_2d),        S(walls_planes_3d),
    S(walls_circle_2d),      S(walls_sphere_3d),        S(walls_piston_2d),        S(walls_piston_ckpt),
    S(hopper_2d),            S(comp_trimers_2d),        S(comp_dimers_2d),         S(comp_trimers_3d),
    S(comp_dimers_3d_ckpt),  S(comp_chain_2d),          S(prop_2d),                S(prop_3d),
    S(prop_gravity_euler),   S(prop_gravity_ckpt),      S(gravity_3d),             S(forces_2d),
    S(forces_shear_3d),      S(callback_2d),            S(callback_ckpt),          S(shear_drvchange_ckpt),
    S(shear_3d_ckpt),
};
#undef S
#define NSCENES ((int)(sizeof scenes / sizeof scenes[0]))

/* ---- comparison ------------------------------------------------------------------ */
static int is_number(const char *tok, double *v)
{
    char *end;
    errno = 0;
    *v = strtod(tok, &end);
    return end != tok && *end == '\0';
}

#define OTHER_REL 1e-6
#define OTHER_ABS 1e-12
#define OTHER_LOOSE 0.05

/* 64-bit FNV-1a over the bits of the results of a fixed set of LAPACK calls
 * (Cholesky, LU and least squares of sizes past the kernels' blocking, on
 * fixed pseudo-random data): two BLAS/LAPACK builds or kernel choices that
 * round differently give different fingerprints. */
static uint64_t blas_fingerprint(void)
{
    enum { N = 150, M = 97 };
    static double a[N * N], b[N * N], c[M * M], r[M * 3];
    static lapack_int ipiv[M];
    uint64_t h = 1469598103934665603ULL, st = 88172645463325252ULL;
    for (int k = 0; k < N * N; ++k) {
        st ^= st << 13, st ^= st >> 7, st ^= st << 17;
        b[k] = (double)(st >> 11) * 0x1.0p-53 - 0.5;
    }
    for (int i = 0; i < N; ++i) /* a = b b^T + N I, symmetric positive definite */
        for (int j = 0; j < N; ++j) {
            double t = i == j ? (double)N : 0.0;
            for (int k = 0; k < N; ++k) t += b[i * N + k] * b[j * N + k];
            a[i * N + j] = t;
        }
    for (int k = 0; k < M * M; ++k) c[k] = b[k];
    for (int k = 0; k < M * 3; ++k) r[k] = b[N * N - 1 - k];
    int ok = LAPACKE_dpotrf(LAPACK_ROW_MAJOR, 'L', N, a, N) == 0 && LAPACKE_dgetrf(LAPACK_COL_MAJOR, M, M, c, M, ipiv) == 0;
    lapack_int rank = 0;
    double sv[M];
    ok = ok && LAPACKE_dgelsd(LAPACK_COL_MAJOR, M, M - 7, 3, b, M, r, M, sv, -1.0, &rank) == 0;
    ck_assert_msg(ok, "regress: the LAPACK calls of the BLAS fingerprint failed");
    const double *arr[3] = {a, c, r};
    const size_t len[3] = {(size_t)N * N, (size_t)M * M, (size_t)M * 3};
    for (int q = 0; q < 3; ++q)
        for (size_t k = 0; k < len[q]; ++k) {
            unsigned char by[sizeof(double)];
            memcpy(by, &arr[q][k], sizeof by);
            for (size_t t = 0; t < sizeof by; ++t) h = (h ^ by[t]) * 1099511628211ULL;
        }
    return h;
}

/* the largest magnitude of the numeric tokens of a line, at least 1 */
static double line_scale(const char *l)
{
    double m = 1.0, v;
    char *c = strdup(l), *sp;
    ck_assert(c != NULL);
    for (char *t = strtok_r(c, " ", &sp); t; t = strtok_r(NULL, " ", &sp))
        if (is_number(t, &v) && isfinite(v)) m = fmax(m, fabs(v));
    free(c);
    return m;
}

/* two lines (NUL-terminated) equal under rel_tol, or in the "other BLAS"
 * mode when other != 0 (see the top of the file) */
static int lines_match(const char *a, const char *b, double rel_tol, int other)
{
    if (strcmp(a, b) == 0) return 1;
    if (rel_tol <= 0.0 && !other) return 0;
    char *ca = strdup(a), *cb = strdup(b), *sa, *sb;
    ck_assert(ca && cb);
    char *ta = strtok_r(ca, " ", &sa), *tb = strtok_r(cb, " ", &sb);
    int eq = ta && tb && strcmp(ta, tb) == 0;
    if (eq && strstr(ta, "ckpt_")) { /* checkpoint hashes: skipped */
        free(ca);
        free(cb);
        return 1;
    }
    double rel = rel_tol, abs_tol = 1e-300;
    if (other && eq) {
        const char *key = strncmp(ta, "ck.", 3) == 0 ? ta + 3 : ta;
        int loose = strcmp(key, "counts") == 0 || strcmp(key, "adaptive") == 0;
        rel = fmax(rel, loose ? OTHER_LOOSE : OTHER_REL);
        abs_tol = OTHER_ABS * fmax(line_scale(a), line_scale(b));
    }
    while (eq) {
        ta = strtok_r(NULL, " ", &sa);
        tb = strtok_r(NULL, " ", &sb);
        if (!ta || !tb) {
            eq = !ta && !tb;
            break;
        }
        double x, y;
        if (is_number(ta, &x) && is_number(tb, &y)) {
            double m = fmax(fabs(x), fabs(y));
            eq = (isnan(x) && isnan(y)) || x == y || fabs(x - y) <= fmax(rel * m, abs_tol);
        } else {
            eq = strcmp(ta, tb) == 0;
        }
    }
    free(ca);
    free(cb);
    return eq;
}

static char *read_file(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) return NULL;
    size_t cap = 1 << 16, n = 0, k;
    char *b = malloc(cap + 1);
    ck_assert(b != NULL);
    while ((k = fread(b + n, 1, cap - n, f)) > 0) {
        n += k;
        if (n == cap) {
            cap *= 2;
            b = realloc(b, cap + 1);
            ck_assert(b != NULL);
        }
    }
    fclose(f);
    b[n] = '\0';
    *len = n;
    return b;
}

/* next line of a buffer: NUL-terminates it in place, advances *p */
static char *next_line(char **p)
{
    if (!*p || !**p) return NULL;
    char *s = *p, *e = strchr(s, '\n');
    if (e) {
        *e = '\0';
        *p = e + 1;
    } else {
        *p = s + strlen(s);
    }
    return s;
}

/* 1 when the BLAS fingerprint differs from the one recorded beside the scenes
 * in dir (announced on stderr if verbose, with the file that lacks or holds
 * it; each scene runs in its own process, the first one announces) */
static int other_blas(const char *dir, int verbose)
{
    char path[1100], *rec;
    size_t len;
    snprintf(path, sizeof path, "%s/blas.txt", dir);
    uint64_t now = blas_fingerprint(), was = 0;
    rec = read_file(path, &len);
    int same = rec && sscanf(rec, "blas %" SCNx64, &was) == 1 && was == now;
    free(rec);
    if (same) return 0;
    const char *ex = getenv("ODHS_REGRESS_EXACT");
    ck_assert_msg(!(ex && *ex && strcmp(ex, "0") != 0),
                  "regress: BLAS fingerprint %016" PRIx64 " differs from %s (%016" PRIx64
                  ") and ODHS_REGRESS_EXACT forbids the other-BLAS comparison",
                  now, path, was);
    if (verbose)
        fprintf(stderr,
            "[regress] BLAS fingerprint %016" PRIx64 " differs from %s (%016" PRIx64
            "): other-BLAS comparison (numbers within %.0e relative + %.0e of the line's scale; counts, adaptive "
            "within %.0e)\n",
            now, path, was, OTHER_REL, OTHER_ABS, OTHER_LOOSE);
    return 1;
}

static void compare(const scene_entry *e, const char *path, char *got, int other)
{
    size_t len;
    char *want = read_file(path, &len);
    ck_assert_msg(want != NULL,
                  "regress scene %s: cannot read %s (%s); record with ODHS_REGRESS_RECORD=tests/data/regress "
                  "CK_RUN_SUITE=regress make check-run",
                  e->name, path, strerror(errno));
    char *pw = want, *pg = got, *lw, *lg;
    size_t ln = 0, ndiff = 0, first = 0;
    char *fw = NULL, *fg = NULL;
    for (;;) {
        lw = next_line(&pw);
        lg = next_line(&pg);
        if (!lw && !lg) break;
        ++ln;
        if (lw && lg && lines_match(lw, lg, e->rel_tol, other)) continue;
        if (ndiff++ == 0) {
            first = ln;
            fw = lw;
            fg = lg;
        }
    }
    ck_assert_msg(ndiff == 0,
                  "regress scene %s: line %zu of %s differs (%zu differing lines%s)\n  recorded: %s\n  now:      %s",
                  e->name, first, path, ndiff, other ? ", other-BLAS comparison" : "", fw ? fw : "<end of file>", fg ? fg : "<end of run>");
    free(want);
}

START_TEST(test_scene)
{
    const scene_entry *e = &scenes[_i];
    cur_name = e->name;
    T_cap = 1 << 16;
    T_len = 0;
    T = malloc(T_cap);
    ck_assert(T != NULL);
    T[0] = '\0';
    /* CPU time of the scene (bench/regress_timing.sh compares it across
     * versions; the machine may be shared) */
    struct timespec t0, t1;
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t0);
    line("scene %s", e->name);
    e->fn();
    clock_gettime(CLOCK_PROCESS_CPUTIME_ID, &t1);
    fprintf(stderr, "[regress] %-26s %8.4f cpu s\n", e->name,
            (double)(t1.tv_sec - t0.tv_sec) + 1e-9 * (double)(t1.tv_nsec - t0.tv_nsec));
    const char *rec = getenv("ODHS_REGRESS_RECORD");
    char path[1024];
    if (rec && *rec) {
        if (mkdir(rec, 0777) != 0) ck_assert_msg(errno == EEXIST, "mkdir %s: %s", rec, strerror(errno));
        snprintf(path, sizeof path, "%s/%s.txt", rec, e->name);
        FILE *f = fopen(path, "wb");
        ck_assert_msg(f != NULL, "cannot write %s: %s", path, strerror(errno));
        ck_assert(fwrite(T, 1, T_len, f) == T_len);
        ck_assert(fclose(f) == 0);
        /* one corpus, one BLAS: scenes of another BLAS are not mixed in */
        snprintf(path, sizeof path, "%s/blas.txt", rec);
        size_t len;
        char *old = read_file(path, &len);
        uint64_t now = blas_fingerprint(), was = 0;
        int mixed = old && !(sscanf(old, "blas %" SCNx64, &was) == 1 && was == now);
        free(old);
        ck_assert_msg(!mixed,
                      "regress: %s holds another BLAS fingerprint (%016" PRIx64 ", now %016" PRIx64
                      "): delete it to re-record the whole corpus",
                      path, was, now);
        f = fopen(path, "wb");
        ck_assert_msg(f != NULL, "cannot write %s: %s", path, strerror(errno));
        ck_assert(fprintf(f, "blas %016" PRIx64 "\n", now) > 0);
        ck_assert(fclose(f) == 0);
    } else {
        const char *dir = getenv("ODHS_TEST_DATA");
        char rdir[900];
        snprintf(rdir, sizeof rdir, "%s/regress", dir && *dir ? dir : "tests/data");
        snprintf(path, sizeof path, "%s/%s.txt", rdir, e->name);
        compare(e, path, T, other_blas(rdir, _i == 0));
    }
    free(T);
    T = NULL;
}
END_TEST

/* the comparator itself: exact by default, the other-BLAS mode tolerates
 * rounding but not a change of result */
START_TEST(test_compare_modes)
{
    static const struct {
        const char *a, *b;
        int exact, other;
    } c[] = {
        {"time 0.37438118649003815", "time 0.37438118649003815", 1, 1},
        {"time 0.37438118649003815", "time 0.37438118649003799", 0, 1},
        {"time 0.37438118649003815", "time 0.37439", 0, 0},
        {"v[4] 0.61149325267004428 -1.1102230246251565e-16", "v[4] 0.61149325267004428 1.1102230246251565e-16", 0, 1},
        {"v[4] 0.61149325267004428 -1.1e-16", "v[4] 0.61149325267004428 1.1e-9", 0, 0},
        {"errors 6.5802252477761472e-16 5.4506347783352239e-16", "errors 7.59e-16 7.59e-16", 0, 1},
        {"errors 6.58e-16 5.45e-16", "errors 6.58e-16 2.0e-11", 0, 0},
        {"counts 1112 72 35", "counts 1097 72 35", 0, 1},
        {"counts 1112 72 35", "counts 1300 72 35", 0, 0},
        {"ck.adaptive 7 0.00052391809329790137", "ck.adaptive 7 0.00052392384396663641", 0, 1},
        {"ev[12] 1 8 12 0.098474895287852471 0", "ev[12] 1 8 13 0.098474895287852471 0", 0, 0},
        {"backend cholmod-pcg", "backend spqr", 0, 0},
        {"time 0.5", "strain 0.5", 0, 0},
        {"ckpt_mid 0 5388 de32622d20038c80", "ckpt_mid 0 5388 ea167cf7f45e596c", 0, 1},
        {"pressure 0.16545948232447544", "pressure 0.16545948232447544 1", 0, 0},
    };
    for (size_t k = 0; k < sizeof c / sizeof c[0]; ++k) {
        ck_assert_msg(lines_match(c[k].a, c[k].b, 0.0, 0) == c[k].exact, "exact: '%s' vs '%s'", c[k].a, c[k].b);
        ck_assert_msg(lines_match(c[k].a, c[k].b, 0.0, 1) == c[k].other, "other BLAS: '%s' vs '%s'", c[k].a,
                      c[k].b);
    }
    /* the fingerprint is a function of the BLAS: the same in one process */
    ck_assert(blas_fingerprint() == blas_fingerprint());
}
END_TEST

Suite *make_regress_suite(void)
{
    Suite *s = suite_create("regress");
    TCase *tcm = tcase_create("compare");
    tcase_add_test(tcm, test_compare_modes);
    suite_add_tcase(s, tcm);
    for (int k = 0; k < NSCENES; ++k) {
        TCase *tc = tcase_create(scenes[k].name);
        tcase_set_timeout(tc, 600);
        tcase_add_loop_test(tc, test_scene, k, k + 1);
        suite_add_tcase(s, tc);
    }
    return s;
}
