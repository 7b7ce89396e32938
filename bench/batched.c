/* bench/batched - the batched-event integrator against the exact one:
 * cost per unit strain against N (issue "Beyond one step per event").
 *
 * Scene per N: 50:50 bidisperse discs (radii 0.5/0.7, 3% polydispersity) at
 * phi = 0.80 in 2D, or spheres at phi = 0.60 in 3D: random placement (0.45
 * in 2D, 0.30 in 3D), compression at rate 1 with the batched integrator
 * (solver auto), drift correction. Above NBUILD (default 16384) the start is
 * a periodic 2^d tiling of the packing of N / 2^d (repeated): the copies
 * start identical and part by round-off and chaos under shear.
 * Warm-up: shear at rate 1 to strain 0.3 (ODHS_BENCH_WARMUP: another) with
 * the batched integrator (not timed); 0.3 leaves the packing in the
 * transient from the compression, where the exact scheme costs about twice
 * its steady-state figure at N = 4096: use 1 or more for steady-state costs. Then from that state, each setting in its own process (its peak
 * resident set size is its memory):
 *   exact      the library's defaults (adaptive Heun, tol 1e-6), solver auto,
 *              over the strain that holds EVENTS events (default 1000; from
 *              the warm-up's event rate); skipped above EXACT_NMAX
 *   batched    ODHS_INTEGRATOR_BATCHED with its defaults (tol 1e-3, dt 5e-2:
 *              steps set by the tolerance), over strain 0.3
 *   tight      the same at tol 1e-4 (ODHS_BENCH_TIGHT_TOL: another)
 * ODHS_BENCH_SUPERNODAL=-1|0|1 sets the "supernodal" parameter of auto's
 * cholmod-pcg (0.2.20; 0 is the simplicial route; -1, by supernodes from
 * "supernodal_switch" flops per entry of L, the default since 0.2.21),
 * ODHS_BENCH_SUPERNODAL_SWITCH=X that switch (default 200) and
 * ODHS_BENCH_OPENMP=0|1 auto's "openmp" (0.2.21; 1: CHOLMOD's own threads
 * in supernodal factorisations, 0 the calling thread alone, the default).
 * Cost per unit strain = CPU seconds of the process / strain. Fitted
 * exponents (least squares of log cost on log N) and an SVG plot.
 *
 * usage: batched [DIM] [NLIST] [SVG] [EXACT_NMAX] [EVENTS] [NBUILD]
 *        defaults 2  1024,4096,16384,65536  batched_2d.svg  16384  1000  16384
 *        batched --plot TABLE SVG: fits and plot of a table printed by an
 *          earlier run (one cut short included)
 *        batched --memory DIM N [NBUILD [STEPS]]: STEPS (default 5) batched
 *          steps at N (tiled from N / 2^DIM ... down to NBUILD), peak RSS;
 *          ODHS_BENCH_SAVE_START=FILE.ckpt writes the start (for --from)
 *        batched --accuracy DIM N SEEDS STRAIN: steady-state sxy, p, z and
 *          collisions per unit strain of exact and batched runs (block
 *          means, SEEDS starts, over STRAIN each), and the convergence of
 *          a trajectory over strain 0.01 as the tolerance and the step fall
 *          (ODHS_BENCH_FIRST_SEED=K: seeds K .. K+SEEDS-1, the trajectory
 *          only with seed 0; ODHS_BENCH_SKIP_TRAJECTORY=1 skips it;
 *          ODHS_BENCH_SETTINGS=exact,batched,tight or a subset)
 *        batched --from FILE STRAIN [exact|batched|tight]: one setting
 *          over STRAIN from a saved start (FILE.xyz, or FILE.ckpt: the
 *          system of a checkpoint): CPU time, steps, events, solves,
 *          drift-correction passes, factorisations (for profiles)
 *        batched --paired DIM N STARTS WINDOW [STRIDE]: from STARTS states
 *          of one batched run (STRIDE apart, default 0.2; seed
 *          ODHS_BENCH_FIRST_SEED), the exact defaults, Heun at tol 1e-9 and
 *          the batched step at tol 1e-2 .. 1e-6 over the same window of
 *          strain WINDOW: the paired differences of the window means of
 *          sxy, p, z and collisions per unit strain (the batched bias of
 *          one stretch of trajectory, without the noise of separate runs);
 *          ODHS_BENCH_PAIRED_SETTINGS=1e-3,1e-4 (or heun, ...) runs only
 *          those besides the exact defaults, ODHS_BENCH_PAIRED_SUB=L adds
 *          the paired differences per sub-window of strain L
 *        batched --pool-paired FILE...: the same summary over the starts
 *          of several --paired outputs (ODHS_BENCH_PAIRED_SETTINGS: the
 *          settings a start must have)
 *        batched --pool FILE...: the pooled lines over the seed rows of
 *          several --accuracy outputs (seeds split across processes)
 *        batched --rd0 DIM N SEEDS STRAIN [RATES]: the same starts sheared
 *          by the hard-sphere settings and by the library's RD0 at each
 *          rate (default 1e-3,3e-4,1e-4,3e-5,1e-5): stress per unit rate
 *          against the exact scheme's, cost per unit strain against the
 *          batched default's (issue 18's RD0 comparison)
 */
#define _GNU_SOURCE
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/types.h>
#include <sys/wait.h>
#include <unistd.h>

#include "bench.h"
#include "odhs.h"
#include "../examples/plot.h"

enum { S_EXACT, S_BATCHED, S_TIGHT, S_COUNT };
/* ODHS_BENCH_SUPERNODAL: the "supernodal" parameter of auto's cholmod-pcg
 * (-1 = the default since 0.2.21, 0, 1) for the shear and compression runs;
 * ODHS_BENCH_SUPERNODAL_SWITCH and ODHS_BENCH_OPENMP: "supernodal_switch"
 * (negative: the default) and "openmp" */
static double pcg_supernodal = -1.0, pcg_switch = -1.0, cm_openmp = 0.0, pcg_ordering = NAN, pcg_reuse = NAN;
static int auto_solver(odhs_solver **sol)
{
    int rc = odhs_solver_create_by_name("auto", sol);
    if (!rc && pcg_supernodal != -1.0) rc = odhs_solver_set_param(*sol, "supernodal", pcg_supernodal);
    if (!rc && pcg_switch >= 0.0) rc = odhs_solver_set_param(*sol, "supernodal_switch", pcg_switch);
    if (!rc && cm_openmp != 0.0) rc = odhs_solver_set_param(*sol, "openmp", cm_openmp);
    if (!rc && !isnan(pcg_ordering)) rc = odhs_solver_set_param(*sol, "ordering", pcg_ordering);
    if (!rc && !isnan(pcg_reuse)) rc = odhs_solver_set_param(*sol, "ordering_reuse", pcg_reuse);
    return rc;
}
/* strain of the scan's warm-up (batched): ODHS_BENCH_WARMUP, default 0.3.
 * The exact setting's cost is measured right after it, over ~1000 events:
 * after 0.3 the packing is still in the transient from the compression
 * (stress ~25 % above the steady state at N = 4096, events per strain and
 * cost per event higher), so its cost is high; 1 or more gives the
 * steady-state cost (since 0.2.16). */
static double warmup = 0.3;
#define WINDOW 0.3 /* strain of a batched run */
static const char *sname[S_COUNT] = {"exact (defaults)", "batched tol 1e-3", "batched tol 1e-4"};
/* the tight setting's tolerance: ODHS_BENCH_TIGHT_TOL (default 1e-4), which
 * also names it ("batched tol 1e-2") */
static double tight_tol = 1e-4;
static char tight_name[32];

typedef struct {
    int rc;
    double strain, cpu, wall;
    uint64_t steps, events, nbatched, nexact;
    double sxy, p, z;
} run_result;

/* a packing of n particles at phi by batched compression */
static int compress_seed(int dim, size_t n, double phi, unsigned seed, odhs_system **out)
{
    odhs_system *sys;
    odhs_solver *sol = NULL;
    odhs_driver *drv = NULL;
    odhs_stepper *st = NULL;
    int rc = odhs_system_create(dim, n, &sys);
    if (!rc) rc = odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, seed);
    if (!rc) rc = odhs_system_place_random(sys, dim == 2 ? 0.45 : 0.30, seed + 1);
    if (!rc) rc = auto_solver(&sol);
    if (!rc) rc = odhs_driver_create(&drv);
    if (!rc) rc = odhs_driver_set_compression_rate(drv, 1.0);
    if (!rc) rc = odhs_stepper_create(sys, drv, sol, &st);
    if (!rc) rc = odhs_stepper_set_integrator(st, ODHS_INTEGRATOR_BATCHED);
    if (!rc) rc = odhs_stepper_run_until_packing_fraction(st, phi);
    if (!rc) rc = odhs_stepper_correct(st);
    if (rc) fprintf(stderr, "batched: compression of N = %zu failed: %s\n", n, st ? odhs_stepper_errmsg(st) : "");
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    if (rc) odhs_system_destroy(sys);
    else *out = sys;
    return rc;
}

static int compress(int dim, size_t n, double phi, odhs_system **out)
{
    return compress_seed(dim, n, phi, (unsigned)(11 + n), out);
}

/* 2^dim periodic tiling of an unsheared box */
static int tile(const odhs_system *base, odhs_system **out)
{
    int dim = odhs_system_dim(base);
    size_t n = odhs_system_count(base), m = n << dim, k = 0;
    double L[3] = {1, 1, 1}, *x = malloc(n * dim * sizeof *x), *r = malloc(n * sizeof *r);
    double *X = malloc(m * dim * sizeof *X), *R = malloc(m * sizeof *R);
    int rc = !x || !r || !X || !R ? ODHS_E_NOMEM : ODHS_OK;
    if (!rc) rc = odhs_system_get_box(base, L);
    if (!rc) rc = odhs_system_get_positions(base, x);
    if (!rc) rc = odhs_system_get_radii(base, r);
    for (int c = 0; !rc && c < (1 << dim); ++c)
        for (size_t p = 0; p < n; ++p, ++k) {
            for (int a = 0; a < dim; ++a) X[k * dim + a] = x[p * dim + a] + ((c >> a) & 1) * L[a];
            R[k] = r[p];
        }
    double L2[3] = {2 * L[0], 2 * L[1], 2 * L[2]};
    if (!rc) rc = odhs_system_create(dim, m, out);
    if (!rc) rc = odhs_system_set_configuration(*out, L2, 0.0, R, X);
    free(x);
    free(r);
    free(X);
    free(R);
    return rc;
}

/* the start of N: built, or tiled from N / 2^dim */
static int start_of(int dim, size_t n, size_t nbuild, odhs_system **out)
{
    double phi = dim == 2 ? 0.80 : 0.60;
    if (n <= nbuild || n % ((size_t)1 << dim)) return compress(dim, n, phi, out);
    odhs_system *base;
    int rc = start_of(dim, n >> dim, nbuild, &base);
    if (rc) return rc;
    rc = tile(base, out);
    odhs_system_destroy(base);
    return rc;
}

static odhs_stepper *shear_stepper(odhs_system *sys, int setting, odhs_solver **sol, odhs_driver **drv)
{
    odhs_stepper *st = NULL;
    auto_solver(sol);
    odhs_driver_create(drv);
    odhs_driver_set_shear_rate(*drv, 1.0);
    odhs_stepper_create(sys, *drv, *sol, &st);
    if (setting != S_EXACT) odhs_stepper_set_integrator(st, ODHS_INTEGRATOR_BATCHED);
    if (setting == S_TIGHT) odhs_stepper_set_tolerance(st, tight_tol);
    return st;
}

/* shear sys over strain w with a setting; the result */
static void run(odhs_system *sys, int setting, double w, run_result *r)
{
    odhs_solver *sol;
    odhs_driver *drv;
    odhs_stepper *st = shear_stepper(sys, setting, &sol, &drv);
    memset(r, 0, sizeof *r);
    double w0 = bench_wall(), c0 = bench_cpu();
    r->rc = odhs_stepper_reset(st);
    if (!r->rc) r->rc = odhs_stepper_run_until_strain(st, w);
    r->cpu = bench_cpu() - c0;
    r->wall = bench_wall() - w0;
    if (r->rc) fprintf(stderr, "batched: %s failed: %s\n", sname[setting], odhs_stepper_errmsg(st));
    uint64_t co = 0, op = 0;
    odhs_stepper_counts(st, &r->steps, &co, &op);
    odhs_stepper_batched_stats(st, &r->nbatched, &r->nexact, NULL);
    odhs_stepper_shear_stress(st, &r->sxy);
    odhs_stepper_pressure(st, &r->p);
    odhs_stepper_coordination(st, &r->z);
    r->events = co + op;
    r->strain = w;
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
}

/* run fn in a child process: its result through a pipe, its peak RSS */
typedef void (*child_fn)(void *arg, void *out);
static int in_child(child_fn fn, void *arg, void *out, size_t size, double *rss_mib)
{
    int pfd[2];
    if (pipe(pfd)) return 1;
    pid_t pid = fork();
    if (pid == 0) {
        close(pfd[0]);
        fn(arg, out);
        ssize_t w = write(pfd[1], out, size);
        _exit(w == (ssize_t)size ? 0 : 1);
    }
    close(pfd[1]);
    ssize_t got = read(pfd[0], out, size);
    close(pfd[0]);
    struct rusage ru;
    int status = 0;
    wait4(pid, &status, 0, &ru);
    *rss_mib = ru.ru_maxrss / 1024.0;
    return got != (ssize_t)size;
}

typedef struct {
    int dim;
    size_t n, nbuild;
    const char *path; /* the warmed-up start, as a checkpoint */
    int setting;
    double w;
} job;

typedef struct {
    int rc;
    size_t nc;
    double phi, build_s, events_per_strain;
} built;

/* child: build, warm up, write the start */
static void build_child(void *arg, void *out)
{
    const job *j = arg;
    built *b = out;
    memset(b, 0, sizeof *b);
    double t0 = bench_wall();
    odhs_system *sys;
    if ((b->rc = start_of(j->dim, j->n, j->nbuild, &sys))) return;
    odhs_solver *sol;
    odhs_driver *drv;
    odhs_stepper *st = shear_stepper(sys, S_BATCHED, &sol, &drv);
    b->rc = odhs_stepper_reset(st);
    if (!b->rc) b->rc = odhs_stepper_run_until_strain(st, warmup);
    if (!b->rc) b->rc = odhs_stepper_correct(st);
    uint64_t co = 0, op = 0;
    odhs_stepper_counts(st, NULL, &co, &op);
    b->events_per_strain = (double)(co + op) / warmup;
    b->nc = odhs_network_count(odhs_stepper_network(st));
    odhs_system_packing_fraction(sys, &b->phi);
    if (!b->rc) b->rc = odhs_checkpoint_write(st, j->path);
    if (b->rc) fprintf(stderr, "batched: start N = %zu failed (%d): %s\n", j->n, b->rc, odhs_stepper_errmsg(st));
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
    b->build_s = bench_wall() - t0;
}

/* child: one setting from the start */
static void run_child(void *arg, void *out)
{
    const job *j = arg;
    run_result *r = out;
    memset(r, 0, sizeof *r);
    odhs_solver *sol;
    odhs_system *sys;
    odhs_driver *drv;
    odhs_stepper *st;
    odhs_solver_create_by_name("auto", &sol);
    if ((r->rc = odhs_checkpoint_read(j->path, sol, &sys, &drv, &st, NULL, 0))) {
        odhs_solver_destroy(sol);
        return;
    }
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    run(sys, j->setting, j->w, r);
    odhs_system_destroy(sys);
}

/* --memory: a few batched steps at N */
static int memory(int dim, size_t n, size_t nbuild, int nsteps)
{
    odhs_system *sys;
    double t0 = bench_wall();
    if (start_of(dim, n, nbuild, &sys)) return 1;
    double tb = bench_wall() - t0, c0 = bench_cpu();
    odhs_solver *sol;
    odhs_driver *drv;
    odhs_stepper *st = shear_stepper(sys, S_BATCHED, &sol, &drv);
    int rc = odhs_stepper_reset(st);
    const char *save = getenv("ODHS_BENCH_SAVE_START");
    if (!rc && save && *save) rc = odhs_checkpoint_write(st, save);
    double cs = bench_cpu();
    {
        struct rusage r0;
        getrusage(RUSAGE_SELF, &r0);
        printf("# %dD N = %zu: start built in %.0f s wall, reset: status %d, peak RSS %.1f MiB\n", dim, n, tb, rc,
               r0.ru_maxrss / 1024.0);
        fflush(stdout);
    }
    double g0 = 0.0;
    odhs_stepper_strain(st, &g0);
    for (int k = 0; k < nsteps && !rc; ++k) {
        rc = odhs_stepper_step(st, NULL);
        struct rusage rk;
        getrusage(RUSAGE_SELF, &rk);
        double g = 0.0;
        uint64_t ck = 0;
        odhs_stepper_strain(st, &g);
        odhs_stepper_counts(st, NULL, &ck, NULL);
        printf("# step %d: status %d, %.1f CPU s, strain %.3e, %llu collisions, peak RSS %.1f MiB\n", k + 1, rc,
               bench_cpu() - cs, g - g0, (unsigned long long)ck, rk.ru_maxrss / 1024.0);
        fflush(stdout);
    }
    uint64_t co = 0;
    odhs_stepper_counts(st, NULL, &co, NULL);
    struct rusage ru;
    getrusage(RUSAGE_SELF, &ru);
    double g1 = 0.0;
    odhs_stepper_strain(st, &g1);
    printf("# memory: %dD N = %zu (start %.0f s wall), %d batched steps: status %d (%s), strain %.3e, %llu collisions, "
           "%.1f CPU s, peak RSS %.1f MiB\n",
           dim, n, tb, nsteps, rc, rc ? odhs_stepper_errmsg(st) : "ok", g1 - g0, (unsigned long long)co,
           bench_cpu() - c0, ru.ru_maxrss / 1024.0);
    double fa = NAN, an = NAN, ord = NAN, lnz = NAN;
    odhs_solver_get_stat(sol, "factorizations", &fa);
    odhs_solver_get_stat(sol, "analyses", &an);
    odhs_solver_get_stat(sol, "orderings", &ord);
    odhs_solver_get_stat(sol, "lnz", &lnz);
    printf("# solver: %.0f factorizations, %.0f analyses, %.0f orderings, lnz %.0f\n", fa, an, ord, lnz);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
    return rc != 0;
}


/* ---- --accuracy: steady-state statistics and convergence ------------------ */
typedef struct {
    double mean[4], err[4]; /* sxy, p, z, collisions per unit strain */
    double cpu;
    uint64_t steps;
} stats;

/* mean and standard error of nb block means per quantity */
static void block_stats(double blk[][4], int nb, stats *out)
{
    for (int a = 0; a < 4; ++a) {
        double m = 0, v = 0;
        for (int b = 0; b < nb; ++b) m += blk[b][a] / nb;
        for (int b = 0; b < nb; ++b) v += (blk[b][a] - m) * (blk[b][a] - m);
        out->mean[a] = m;
        out->err[a] = sqrt(v / ((double)nb * (nb - 1)));
    }
}

/* pooled mean and standard error of got values */
static void pooled(const double *v, int got, double *m, double *e)
{
    *m = 0.0;
    *e = 0.0;
    for (int i = 0; i < got; ++i) *m += v[i] / got;
    for (int i = 0; i < got; ++i) *e += (v[i] - *m) * (v[i] - *m);
    *e = got > 1 ? sqrt(*e / ((double)got * (got - 1))) : NAN;
}

/* a route under sampling: advance to strain g past the window's start, then
 * the sampled sxy, p, z and the collisions so far into v */
typedef int (*advance_fn)(void *route, double g, double v[4]);

/* sample a route every 0.01 of strain over w in nb blocks: block means of
 * sxy, p, z and collisions per unit strain (from col0 at the start) -> mean
 * and standard error */
static int sample_blocks(advance_fn advance, void *route, double w, int nb, double col0, stats *out)
{
    double blk[64][4];
    int per = (int)lround(w / 0.01) / nb, rc = 0;
    for (int b = 0; b < nb && !rc; ++b) {
        double acc[3] = {0, 0, 0}, v[4] = {0, 0, 0, col0};
        for (int k = 0; k < per && !rc; ++k)
            if (!(rc = advance(route, 0.01 * (b * per + k + 1), v)))
                for (int a = 0; a < 3; ++a) acc[a] += v[a] / per;
        for (int a = 0; a < 3; ++a) blk[b][a] = acc[a];
        blk[b][3] = (v[3] - col0) / (0.01 * per);
        col0 = v[3];
    }
    if (!rc) block_stats(blk, nb, out);
    return rc;
}

typedef struct {
    odhs_stepper *st;
    double g0;
} hs_route;

static int hs_advance(void *route, double g, double v[4])
{
    hs_route *r = route;
    uint64_t col = 0;
    int rc = odhs_stepper_run_until_strain(r->st, r->g0 + g);
    odhs_stepper_shear_stress(r->st, &v[0]);
    odhs_stepper_pressure(r->st, &v[1]);
    odhs_stepper_coordination(r->st, &v[2]);
    odhs_stepper_counts(r->st, NULL, &col, NULL);
    v[3] = (double)col;
    return rc;
}

/* shear sys over strain w with a hard-sphere setting, sampled by
 * sample_blocks */
static int sample_run(odhs_system *sys, int setting, double w, int nb, stats *out)
{
    odhs_solver *sol;
    odhs_driver *drv;
    hs_route r = {shear_stepper(sys, setting, &sol, &drv), 0.0};
    memset(out, 0, sizeof *out);
    int rc = odhs_stepper_reset(r.st);
    double c0 = bench_cpu();
    uint64_t col0 = 0;
    odhs_stepper_strain(r.st, &r.g0);
    odhs_stepper_counts(r.st, NULL, &col0, NULL);
    if (!rc) rc = sample_blocks(hs_advance, &r, w, nb, (double)col0, out);
    out->cpu = bench_cpu() - c0;
    odhs_stepper_counts(r.st, &out->steps, NULL, NULL);
    if (rc) fprintf(stderr, "batched: %s failed: %s\n", sname[setting], odhs_stepper_errmsg(r.st));
    odhs_stepper_destroy(r.st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    return rc;
}

/* rms minimum-image difference of positions a, b (same box, sheared) */
static double rms_diff(const odhs_system *sys, const double *a, const double *b)
{
    int dim = odhs_system_dim(sys);
    size_t n = odhs_system_count(sys);
    double L[3] = {1, 1, 1}, g = 0.0, s = 0.0;
    odhs_system_get_box(sys, L);
    odhs_system_get_strain(sys, &g);
    for (size_t i = 0; i < n; ++i) {
        double d[3] = {0, 0, 0};
        for (int k = 0; k < dim; ++k) d[k] = a[i * dim + k] - b[i * dim + k];
        double ny = nearbyint(d[1] / L[1]);
        d[1] -= ny * L[1];
        d[0] -= ny * g * L[1];
        for (int k = 0; k < dim; ++k)
            if (k != 1) d[k] -= nearbyint(d[k] / L[k]) * L[k];
        for (int k = 0; k < dim; ++k) s += d[k] * d[k];
    }
    return sqrt(s / (double)n);
}

/* positions after strain w from start with integrator/tol (tol 0: default) */
static int trajectory(const odhs_system *start, int integ, double tol, double dt, double w, double *x, double *cpu,
                      uint64_t *steps)
{
    odhs_system *sys;
    odhs_solver *sol;
    odhs_driver *drv;
    odhs_stepper *st;
    if (odhs_system_clone(start, &sys)) return 1;
    odhs_solver_create_by_name("auto", &sol);
    odhs_driver_create(&drv);
    odhs_driver_set_shear_rate(drv, 1.0);
    int rc = odhs_stepper_create(sys, drv, sol, &st);
    if (!rc) rc = odhs_stepper_set_integrator(st, integ);
    if (!rc && tol > 0) rc = odhs_stepper_set_tolerance(st, tol);
    if (!rc && dt > 0) rc = odhs_stepper_set_dt(st, dt);
    double c0 = bench_cpu();
    if (!rc) rc = odhs_stepper_run_until_strain(st, w);
    *cpu = bench_cpu() - c0;
    odhs_stepper_counts(st, steps, NULL, NULL);
    if (!rc) rc = odhs_system_get_positions(sys, x);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
    return rc;
}

/* seed k's start: batched compression, warm-up to strain 1 (batched) */
static int warmed_seed(int dim, size_t n, int k, odhs_system **out)
{
    odhs_system *sys;
    if (compress_seed(dim, n, dim == 2 ? 0.80 : 0.60, 101 + 7 * (unsigned)k, &sys)) return 1;
    odhs_solver *sol;
    odhs_driver *drv;
    odhs_stepper *st = shear_stepper(sys, S_BATCHED, &sol, &drv);
    int rc = odhs_stepper_reset(st);
    if (!rc) rc = odhs_stepper_run_until_strain(st, 1.0);
    if (!rc) rc = odhs_stepper_correct(st);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    if (rc) odhs_system_destroy(sys);
    else *out = sys;
    return rc != 0;
}

/* the pooled lines of per-seed means pool[setting][quantity][seed] */
static void print_pooled(double pool[S_COUNT][4][16], const int got[S_COUNT])
{
    printf("# pooled over seeds (mean +- standard error of the seed means); difference to exact in units of the "
           "combined error\n");
    for (int s = 0; s < S_COUNT; ++s) {
        if (got[s] < 2) continue;
        printf("%-17s", sname[s]);
        for (int a = 0; a < 4; ++a) {
            double m[S_COUNT] = {0}, e[S_COUNT] = {0};
            for (int q = 0; q < S_COUNT; ++q) {
                if (got[q] >= 2) pooled(pool[q][a], got[q], &m[q], &e[q]);
            }
            const char *name = a == 0 ? "sxy" : a == 1 ? "p" : a == 2 ? "z" : "coll/strain";
            if (got[S_EXACT] < 2) { /* no exact runs to compare with */
                printf("  %s %.4g+-%.2g", name, m[s], e[s]);
                continue;
            }
            double z = s == S_EXACT ? 0.0 : (m[s] - m[S_EXACT]) / sqrt(e[s] * e[s] + e[S_EXACT] * e[S_EXACT]);
            printf("  %s %.4g+-%.2g (%+.1f sigma)", name, m[s], e[s], z);
        }
        printf("\n");
    }
}

static int accuracy(int dim, size_t n, int seeds, double w)
{
    double phi = dim == 2 ? 0.80 : 0.60;
    printf("# accuracy of the batched integrator, %dD N = %zu, phi = %.2f, shear rate 1, solver auto; libodhs %s\n", dim,
           n, phi, odhs_version_string());
    printf("# (a) steady state: per seed, batched compression, warm-up to strain 1 (batched), then each setting over "
           "strain %g from that state; 10 block means -> mean +- standard error\n",
           w);
    printf("%4s %-17s %8s %9s %18s %18s %16s %20s\n", "seed", "setting", "steps", "cpu_s", "sxy", "p", "z",
           "collisions/strain");
    double pool[S_COUNT][4][16];
    int got[S_COUNT] = {0};
    double *x0 = NULL;
    odhs_system *first = NULL;
    const char *fs = getenv("ODHS_BENCH_FIRST_SEED"), *skip = getenv("ODHS_BENCH_SKIP_TRAJECTORY");
    const int k0 = fs ? atoi(fs) : 0, with_b = k0 == 0 && !(skip && *skip && strcmp(skip, "0"));
    /* ODHS_BENCH_SETTINGS: a subset of exact,batched,tight (default all) */
    const char *only = getenv("ODHS_BENCH_SETTINGS");
    int run_s[S_COUNT];
    for (int s = 0; s < S_COUNT; ++s) {
        static const char *const key[S_COUNT] = {"exact", "batched", "tight"};
        const char *hit = only ? strstr(only, key[s]) : NULL;
        size_t len = strlen(key[s]);
        run_s[s] = !only || (hit && (hit == only || hit[-1] == ',') && (hit[len] == ',' || hit[len] == 0));
    }
    if (k0 < 0 || seeds > 16) {
        fprintf(stderr, "batched --accuracy: ODHS_BENCH_FIRST_SEED must be >= 0 and SEEDS <= 16\n");
        return 2;
    }
    for (int k = k0; k < k0 + seeds; ++k) {
        odhs_system *sys;
        if (warmed_seed(dim, n, k, &sys)) return 1;
        if (k == 0 && with_b) odhs_system_clone(sys, &first);
        for (int s = 0; s < S_COUNT; ++s) {
            if (!run_s[s]) continue;
            odhs_system *c;
            odhs_system_clone(sys, &c);
            stats r;
            if (!sample_run(c, s, w, 10, &r)) {
                printf("%4d %-17s %8llu %9.1f %9.4f+-%7.4f %9.4f+-%7.4f %8.4f+-%6.4f %11.1f+-%7.1f\n", k,
                       sname[s], (unsigned long long)r.steps, r.cpu, r.mean[0], r.err[0], r.mean[1], r.err[1],
                       r.mean[2], r.err[2], r.mean[3], r.err[3]);
                for (int a = 0; a < 4; ++a) pool[s][a][got[s]] = r.mean[a];
                got[s]++;
            }
            fflush(stdout);
            odhs_system_destroy(c);
        }
        odhs_system_destroy(sys);
    }
    print_pooled(pool, got);
    if (!with_b) return 0;
    /* (b) convergence over strain 0.01 from the first seed's warmed-up state */
    size_t nd = n * (size_t)dim;
    double *xr = malloc(nd * sizeof *xr), *x = malloc(nd * sizeof *x), cpu;
    x0 = xr;
    uint64_t steps;
    printf("# (b) trajectory over strain 0.01 from seed 0's state: rms position difference to Heun tol 1e-11 (mean "
           "diameters)\n");
    if (!first || trajectory(first, ODHS_INTEGRATOR_HEUN, 1e-11, 0, 0.01, xr, &cpu, &steps)) return 1;
    printf("%-26s %8s %9s %12s %7s\n", "setting", "steps", "cpu_s", "rms_error", "order");
    const double tols[5] = {1e-2, 1e-3, 1e-4, 1e-5, 1e-6};
    double prev = NAN, prevt = NAN;
    for (int q = 0; q < 5; ++q) {
        if (trajectory(first, ODHS_INTEGRATOR_BATCHED, tols[q], 0, 0.01, x, &cpu, &steps)) continue;
        double e = rms_diff(first, x, xr) / 1.2; /* mean diameter 1.2 */
        char ord[16] = "-";
        if (isfinite(prev)) snprintf(ord, sizeof ord, "%.2f", log(prev / e) / log(prevt / tols[q]));
        printf("batched tol %-14.0e %8llu %9.2f %12.3e %7s\n", tols[q], (unsigned long long)steps, cpu, e, ord);
        prev = e;
        prevt = tols[q];
        fflush(stdout);
    }
    printf("# order: d log(error) / d log(tol); first order in h with h ~ tol^(1/2) gives 0.5 in tol\n");
    const double dts[4] = {4e-3, 2e-3, 1e-3, 5e-4};
    prev = NAN;
    for (int q = 0; q < 4; ++q) {
        if (trajectory(first, ODHS_INTEGRATOR_BATCHED, 0.999, dts[q], 0.01, x, &cpu, &steps)) continue;
        double e = rms_diff(first, x, xr) / 1.2;
        char ord[16] = "-";
        if (isfinite(prev)) snprintf(ord, sizeof ord, "%.2f", log(prev / e) / log(2.0));
        printf("batched fixed h = %-8.0e %8llu %9.2f %12.3e %7s\n", dts[q], (unsigned long long)steps, cpu, e, ord);
        prev = e;
        fflush(stdout);
    }
    printf("# order in h: log2(error(2h) / error(h))\n");
    free(x0);
    free(x);
    odhs_system_destroy(first);
    return 0;
}

/* --pool FILE...: the pooled lines over the per-seed rows of several
 * --accuracy outputs (seeds run in separate processes) */
static int pool_files(int nf, char **files)
{
    double pool[S_COUNT][4][16];
    int got[S_COUNT] = {0};
    for (int f = 0; f < nf; ++f) {
        FILE *in = fopen(files[f], "r");
        if (!in) {
            perror(files[f]);
            return 1;
        }
        char line[512];
        while (fgets(line, sizeof line, in)) {
            int seed, off = 0;
            if (line[0] == '#' || sscanf(line, "%d %n", &seed, &off) != 1) continue;
            for (int s = 0; s < S_COUNT; ++s) {
                size_t len = strlen(sname[s]);
                unsigned long long steps;
                double cpu, v[4], e[4];
                if (strncmp(line + off, sname[s], len)) continue;
                if (sscanf(line + off + len, "%llu %lf %lf+-%lf %lf+-%lf %lf+-%lf %lf+-%lf", &steps, &cpu, &v[0], &e[0],
                           &v[1], &e[1], &v[2], &e[2], &v[3], &e[3]) != 10 ||
                    got[s] >= 16) {
                    fprintf(stderr, "batched --pool: %s: unreadable row: %s", files[f], line);
                    fclose(in);
                    return 1;
                }
                for (int a = 0; a < 4; ++a) pool[s][a][got[s]] = v[a];
                got[s]++;
            }
        }
        fclose(in);
    }
    printf("# pooled over the seed rows of %d file(s): %d exact, %d batched, %d tight runs\n", nf, got[S_EXACT],
           got[S_BATCHED], got[S_TIGHT]);
    print_pooled(pool, got);
    /* nothing to pool: no setting with two seeds */
    return got[S_EXACT] < 2 && got[S_BATCHED] < 2 && got[S_TIGHT] < 2;
}

/* ---- --from: one setting over a window from a saved start ------------------ */
/* The cost of a window of strain w from the configuration in path (extended
 * XYZ or LAMMPS data) with one setting, and where it went: steps, events,
 * force solves of the contact problems, drift corrections (passes, pairs
 * closed), factorisations; the stress at the end. Profiles (perf) run this. */
static int from_file(const char *path, double w, const char *setting)
{
    int s = !strcmp(setting, "exact") ? S_EXACT : !strcmp(setting, "tight") ? S_TIGHT : S_BATCHED;
    odhs_system *sys;
    char eb[256];
    size_t pl = strlen(path);
    if (pl > 5 && !strcmp(path + pl - 5, ".ckpt")) { /* a checkpoint (the scan's start files): its system */
        odhs_solver *cs;
        odhs_driver *cd;
        odhs_stepper *cst;
        odhs_solver_create_by_name("auto", &cs);
        int rc = odhs_checkpoint_read(path, cs, &sys, &cd, &cst, NULL, 0);
        if (!rc) {
            odhs_stepper_destroy(cst);
            odhs_driver_destroy(cd);
        }
        odhs_solver_destroy(cs);
        if (rc) {
            fprintf(stderr, "batched --from: cannot read checkpoint %s (%d)\n", path, rc);
            return 1;
        }
    } else if (odhs_xyz_read(path, &sys, eb, sizeof eb)) {
        fprintf(stderr, "batched --from: %s\n", eb);
        return 1;
    }
    odhs_solver *sol;
    odhs_driver *drv;
    odhs_stepper *st = shear_stepper(sys, s, &sol, &drv);
    double c0 = bench_cpu(), g0 = 0.0, cr;
    int rc = odhs_stepper_reset(st);
    cr = bench_cpu() - c0;
    odhs_stepper_strain(st, &g0);
    if (!rc) rc = odhs_stepper_run_until_strain(st, g0 + w);
    double cpu = bench_cpu() - c0 - cr, sxy = NAN, fact = 0, analyses = 0;
    uint64_t steps = 0, col = 0, op = 0, bsol = 0, corr = 0, passes = 0, closed = 0;
    odhs_stepper_counts(st, &steps, &col, &op);
    uint64_t esteps = 0;
    odhs_stepper_batched_stats(st, NULL, &esteps, &bsol);
    odhs_stepper_correction_stats(st, &corr, &passes, &closed);
    odhs_solver_get_stat(sol, "factorizations", &fact);
    odhs_solver_get_stat(sol, "analyses", &analyses);
    double fb = NAN, rdef = NAN, fails = NAN;
    odhs_solver_get_stat(sol, "fallbacks", &fails);
    odhs_solver_get_stat(sol, "fallback_solves", &fb);
    odhs_solver_get_stat(sol, "rank_deficient", &rdef);
    double fl = NAN, lnz = NAN, orderings = NAN;
    odhs_solver_get_stat(sol, "orderings", &orderings);
    odhs_solver_get_stat(sol, "flops", &fl);
    odhs_solver_get_stat(sol, "lnz", &lnz);
    if (!rc) odhs_stepper_shear_stress(st, &sxy);
    printf("# libodhs %s, %s, N = %zu, strain %g from %s (status %d%s%s)\n", odhs_version_string(), sname[s],
           odhs_system_count(sys), w, path, rc, rc ? ": " : "", rc ? odhs_stepper_errmsg(st) : "");
    printf("cpu_s %.2f reset_s %.2f steps %llu exact_steps %llu collisions %llu openings %llu contact_problem_solves %llu "
           "corrections %llu correction_passes %llu correction_closed %llu factorizations %.0f analyses %.0f "
           "failed_attempts %.0f fallback_solves %.0f rank_deficient_solves %.0f sxy_end %.6f flops_per_lnz %.1f "
           "orderings %.0f lnz %.0f\n",
           cpu, cr, (unsigned long long)steps, (unsigned long long)esteps, (unsigned long long)col, (unsigned long long)op,
           (unsigned long long)bsol, (unsigned long long)corr, (unsigned long long)passes, (unsigned long long)closed,
           fact, analyses, fails, fb, rdef, sxy, fl / lnz, orderings, lnz);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
    return rc != 0;
}

/* ---- --paired: short windows from common starts ---------------------------- */
/* The batched bias, local or structural: from STARTS states of one steady
 * run (a batched carrier, its states STRIDE apart), every setting below over
 * the same window of strain W, sampled every 0.01 of strain as --accuracy
 * does; per setting the mean over starts of its window means minus the
 * exact defaults' (paired), with the standard error over starts. A bias set
 * by each step shows here over short windows; one the trajectory builds up
 * over strain does not. */
typedef struct {
    const char *name;
    int integ;
    double tol; /* 0: the integrator's default */
} psetting;

static const psetting pset[] = {
    {"exact (defaults)", -1, 0.0},           {"exact Heun tol 1e-9", ODHS_INTEGRATOR_HEUN, 1e-9},
    {"batched tol 1e-2", ODHS_INTEGRATOR_BATCHED, 1e-2}, {"batched tol 1e-3", ODHS_INTEGRATOR_BATCHED, 1e-3},
    {"batched tol 1e-4", ODHS_INTEGRATOR_BATCHED, 1e-4}, {"batched tol 1e-5", ODHS_INTEGRATOR_BATCHED, 1e-5},
    {"batched tol 1e-6", ODHS_INTEGRATOR_BATCHED, 1e-6},
};
#define NPSET ((int)(sizeof pset / sizeof pset[0]))

/* ODHS_BENCH_PAIRED_SETTINGS: a comma list of the settings to run besides
 * the exact defaults, each a whole word of a setting's name ("heun" or a
 * tolerance: "1e-3,1e-4"); default all. ODHS_BENCH_PAIRED_SUB=L: also the
 * means over the sub-windows of strain L (W / L of them), to see whether a
 * difference builds up along the window. */
static int pwant[NPSET];
static int psub_n;

static void paired_options(double w)
{
    const char *e = getenv("ODHS_BENCH_PAIRED_SETTINGS");
    for (int q = 0; q < NPSET; ++q) {
        pwant[q] = 1;
        if (q == 0 || !e || !*e) continue;
        /* the token the list names this setting by: its last word, or "heun" */
        const char *name = pset[q].integ == ODHS_INTEGRATOR_HEUN ? "heun" : strrchr(pset[q].name, ' ') + 1;
        size_t l = strlen(name);
        pwant[q] = 0;
        for (const char *p = e; (p = strstr(p, name)) != NULL; p += l)
            if ((p == e || p[-1] == ',') && (p[l] == '\0' || p[l] == ',')) pwant[q] = 1;
    }
    const char *sb = getenv("ODHS_BENCH_PAIRED_SUB");
    double sub = sb ? atof(sb) : 0.0;
    psub_n = sub >= 0.01 && sub < w ? (int)lround(w / sub) : 0;
    if (psub_n > 100) psub_n = 100;
}

/* one window of strain w of setting q from start: window means of sxy, p, z
 * and collisions per unit strain into v; steps, cpu */
static int paired_window(const odhs_system *start, int q, double w, double v[4], double *sub, uint64_t *steps,
                         double *cpu)
{
    odhs_system *sys;
    odhs_solver *sol;
    odhs_driver *drv;
    if (odhs_system_clone(start, &sys)) return 1;
    hs_route r = {shear_stepper(sys, S_EXACT, &sol, &drv), 0.0};
    int rc = pset[q].integ >= 0 ? odhs_stepper_set_integrator(r.st, pset[q].integ) : ODHS_OK;
    if (!rc && pset[q].tol > 0) rc = odhs_stepper_set_tolerance(r.st, pset[q].tol);
    if (!rc) rc = odhs_stepper_reset(r.st);
    double c0 = bench_cpu(), acc[3] = {0, 0, 0}, s[4] = {0, 0, 0, 0};
    uint64_t col0 = 0;
    odhs_stepper_strain(r.st, &r.g0);
    odhs_stepper_counts(r.st, NULL, &col0, NULL);
    const int per = (int)lround(w / 0.01);
    if (psub_n) memset(sub, 0, (size_t)psub_n * 3 * sizeof *sub);
    for (int k = 0; k < per && !rc; ++k)
        if (!(rc = hs_advance(&r, 0.01 * (k + 1), s)))
            for (int a = 0; a < 3; ++a) {
                acc[a] += s[a] / per;
                /* sample k in sub-window k * psub_n / per, each of per / psub_n samples */
                if (psub_n) sub[(k * psub_n / per) * 3 + a] += s[a] * psub_n / per;
            }
    for (int a = 0; a < 3; ++a) v[a] = acc[a];
    v[3] = (s[3] - (double)col0) / w;
    *cpu = bench_cpu() - c0;
    odhs_stepper_counts(r.st, steps, NULL, NULL);
    if (rc) fprintf(stderr, "batched --paired: %s failed: %s\n", pset[q].name, odhs_stepper_errmsg(r.st));
    odhs_stepper_destroy(r.st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
    return rc;
}

/* the summary of ok starts' window means val[start][setting][quantity]:
 * per setting the mean, and the paired difference to the exact defaults' */
static void paired_summary(double (*val)[NPSET][4], int ok)
{
    printf("# over %d starts: mean of each setting's window means, and its paired difference to the exact defaults' "
           "(mean +- standard error over starts; sxy and p in %%)\n",
           ok);
    printf("%-20s %10s %18s %18s %20s %22s\n", "setting", "sxy", "dsxy_%", "dp_%", "dz", "dcoll/strain");
    double *x = malloc((size_t)(ok > 1 ? ok : 1) * sizeof *x);
    for (int q = 0; q < NPSET && ok >= 2 && x; ++q) {
        if (!pwant[q]) continue;
        double m[4], e[4], d[4], de[4];
        for (int a = 0; a < 4; ++a) {
            for (int k = 0; k < ok; ++k) x[k] = val[k][q][a];
            pooled(x, ok, &m[a], &e[a]);
            for (int k = 0; k < ok; ++k)
                x[k] = a < 2 ? 100.0 * (val[k][q][a] / val[k][0][a] - 1.0) : val[k][q][a] - val[k][0][a];
            pooled(x, ok, &d[a], &de[a]);
        }
        printf("%-20s %10.5f %8.3f+-%7.3f %8.3f+-%7.3f %9.5f+-%8.5f %10.1f+-%9.1f\n", pset[q].name, m[0], d[0], de[0],
               d[1], de[1], d[2], de[2], d[3], de[3]);
    }
    free(x);
}

/* the paired differences per sub-window: does the bias build up along the
 * window (a structural drift) or is it there from the start (the step's
 * own)? subv[start][setting][sub][quantity] */
static void paired_sub_summary(const double *subv, int ok, double w)
{
    printf("# per sub-window of strain %g: paired difference to the exact defaults (mean +- standard error over %d "
           "starts; sxy in %%)\n",
           w / psub_n, ok);
    printf("%-20s %4s %8s %18s %20s\n", "setting", "sub", "strain", "dsxy_%", "dz");
    double *x = malloc((size_t)ok * sizeof *x), *y = malloc((size_t)ok * sizeof *y);
    for (int q = 1; q < NPSET && x && y; ++q) {
        if (!pwant[q]) continue;
        for (int j = 0; j < psub_n; ++j) {
            double m, e, mz, ez;
            for (int k = 0; k < ok; ++k) {
                const double *a = subv + (((size_t)k * NPSET + (size_t)q) * (size_t)psub_n + (size_t)j) * 3;
                const double *b = subv + (((size_t)k * NPSET) * (size_t)psub_n + (size_t)j) * 3;
                x[k] = 100.0 * (a[0] / b[0] - 1.0);
                y[k] = a[2] - b[2];
            }
            pooled(x, ok, &m, &e);
            pooled(y, ok, &mz, &ez);
            printf("%-20s %4d %8.3f %8.3f+-%7.3f %9.5f+-%8.5f\n", pset[q].name, j, w * (j + 0.5) / psub_n, m, e, mz,
                   ez);
        }
    }
    free(x);
    free(y);
}

/* --pool-paired FILE...: the summary over the start rows of several --paired
 * outputs (each file's starts are its own; a start needs every setting) */
static int pool_paired(int nf, char **files)
{
    int cap = 0, ok = 0, all = 0;
    paired_options(1.0);
    for (int q = 0; q < NPSET; ++q) all |= pwant[q] << q;
    double (*val)[NPSET][4] = NULL;
    for (int f = 0; f < nf; ++f) {
        FILE *in = fopen(files[f], "r");
        if (!in) {
            perror(files[f]);
            free(val);
            return 1;
        }
        char line[512];
        int cur = -1, seen = 0;
        while (fgets(line, sizeof line, in)) {
            int k, off = 0;
            if (line[0] == '#' || sscanf(line, "%d %n", &k, &off) != 1) continue;
            for (int q = 0; q < NPSET; ++q) {
                size_t len = strlen(pset[q].name);
                unsigned long long steps;
                double cpu, v[4];
                if (strncmp(line + off, pset[q].name, len) || (line[off + len] != ' ')) continue;
                if (sscanf(line + off + len, "%llu %lf %lf %lf %lf %lf", &steps, &cpu, &v[0], &v[1], &v[2], &v[3]) != 6) {
                    fprintf(stderr, "batched --pool-paired: %s: unreadable row: %s", files[f], line);
                    fclose(in);
                    free(val);
                    return 1;
                }
                if (k != cur) { /* a new start */
                    if (cur >= 0 && (seen & all) == all) ++ok;
                    cur = k;
                    seen = 0;
                    if (ok + 1 > cap) {
                        void *nv = realloc(val, (size_t)(cap = 2 * cap + 8) * sizeof *val);
                        if (!nv) {
                            fclose(in);
                            free(val);
                            return 1;
                        }
                        val = nv;
                    }
                }
                memcpy(val[ok][q], v, sizeof v);
                seen |= 1 << q;
            }
        }
        if (cur >= 0 && (seen & all) == all) ++ok;
        fclose(in);
    }
    printf("# pooled over the complete starts of %d file(s)\n", nf);
    if (ok >= 2) paired_summary(val, ok);
    free(val);
    return ok < 2;
}

static int paired(int dim, size_t n, int starts, double w, double stride)
{
    const char *fs = getenv("ODHS_BENCH_FIRST_SEED");
    const int seed = fs ? atoi(fs) : 0;
    if (starts < 2 || starts > 64 || !(w >= 0.01) || !(stride > 0) || seed < 0) {
        fprintf(stderr, "batched --paired: 2 <= STARTS <= 64, WINDOW >= 0.01, STRIDE > 0, ODHS_BENCH_FIRST_SEED >= 0\n");
        return 2;
    }
    printf("# paired windows, %dD N = %zu, phi = %.2f, shear rate 1, solver auto; libodhs %s\n", dim, n,
           dim == 2 ? 0.80 : 0.60, odhs_version_string());
    printf("# seed %d: batched compression, warm-up to strain 1 (batched); %d starts %g apart on a batched carrier; "
           "every setting over strain %g from each, sampled every 0.01\n",
           seed, starts, stride, w);
    paired_options(w);
    if (psub_n)
        printf("# sub-windows: %d of strain %g (rows '# sub START SETTING J sxy p z', summary at the end)\n", psub_n,
               w / psub_n);
    printf("%5s %-20s %8s %8s %10s %9s %8s %12s\n", "start", "setting", "steps", "cpu_s", "sxy", "p", "z",
           "coll/strain");
    odhs_system *sys;
    if (warmed_seed(dim, n, seed, &sys)) return 1;
    odhs_solver *sol;
    odhs_driver *drv;
    odhs_stepper *carrier = shear_stepper(sys, S_BATCHED, &sol, &drv);
    double (*val)[NPSET][4] = calloc((size_t)starts, sizeof *val);
    /* sub-window means: [start][setting][sub][quantity] */
    double *subv = calloc((size_t)starts * NPSET * (size_t)(psub_n ? psub_n : 1) * 3, sizeof *subv);
    int rc = !val || !subv || odhs_stepper_reset(carrier), ok = 0;
    for (int k = 0; k < starts && !rc; ++k) {
        double g;
        odhs_stepper_strain(carrier, &g);
        if ((rc = odhs_stepper_run_until_strain(carrier, g + stride)) || (rc = odhs_stepper_correct(carrier))) break;
        for (int q = 0; q < NPSET && !rc; ++q) {
            if (!pwant[q]) continue;
            uint64_t steps = 0;
            double cpu = 0, *sub = subv + ((size_t)k * NPSET + (size_t)q) * (size_t)psub_n * 3;
            rc = paired_window(sys, q, w, val[k][q], sub, &steps, &cpu);
            if (!rc)
                printf("%5d %-20s %8llu %8.1f %10.5f %9.4f %8.4f %12.1f\n", k, pset[q].name, (unsigned long long)steps,
                       cpu, val[k][q][0], val[k][q][1], val[k][q][2], val[k][q][3]);
            for (int j = 0; j < psub_n && !rc; ++j)
                printf("# sub %d %-20s %d %10.5f %9.4f %8.4f\n", k, pset[q].name, j, sub[3 * j], sub[3 * j + 1],
                       sub[3 * j + 2]);
            fflush(stdout);
        }
        if (!rc) ok = k + 1;
    }
    if (rc && carrier) fprintf(stderr, "batched --paired: %s\n", odhs_stepper_errmsg(carrier));
    paired_summary(val, ok);
    if (psub_n && ok >= 2) paired_sub_summary(subv, ok, w);
    free(val);
    free(subv);
    odhs_stepper_destroy(carrier);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
    return rc != 0 || ok < 2;
}

/* ---- --rd0: the soft-core route at equal stress ------------------------------ */
#define RD0_WARM 0.1 /* strain of RD0's own transient from the hard-sphere state */

typedef struct {
    odhs_softcore *sc;
    double rate;
} rd0_route;

/* RD0's stresses per unit rate; no collisions */
static int rd0_advance(void *route, double g, double v[4])
{
    rd0_route *r = route;
    double sig[9], p = 0, z = 0;
    int rc = odhs_softcore_run_until_strain(r->sc, RD0_WARM + g);
    if (!rc) rc = odhs_softcore_stress(r->sc, ODHS_SOFTCORE_STRESS_TOTAL, sig);
    if (!rc) rc = odhs_softcore_pressure(r->sc, &p);
    if (!rc) rc = odhs_softcore_coordination(r->sc, 0, &z);
    if (rc) return rc;
    v[0] = sig[1] / r->rate; /* sigma_xy: row 0, column 1 */
    v[1] = p / r->rate;
    v[2] = z;
    return ODHS_OK;
}

/* RD0 with the library's defaults (k_e = 1, k_d = 1 = 1/xi0, explicit Euler
 * at 0.1 tau_e) at shear rate `rate` from sys (moved in place): warm-up
 * RD0_WARM, then sampled by sample_blocks over w (z counts overlapping
 * neighbours); CPU and steps of the window */
static int rd0_sample(odhs_system *sys, double rate, double w, int nb, stats *out)
{
    rd0_route r = {NULL, rate};
    memset(out, 0, sizeof *out);
    int rc = odhs_softcore_create(sys, &r.sc);
    if (rc) return rc;
    rc = odhs_softcore_set_model(r.sc, ODHS_SOFTCORE_RD0);
    if (!rc) rc = odhs_softcore_set_shear_rate(r.sc, rate);
    if (!rc) rc = odhs_softcore_run_until_strain(r.sc, RD0_WARM);
    double c0 = bench_cpu();
    uint64_t s0 = 0;
    odhs_softcore_counts(r.sc, &s0, NULL, NULL);
    if (!rc) rc = sample_blocks(rd0_advance, &r, w, nb, 0.0, out);
    out->cpu = bench_cpu() - c0;
    odhs_softcore_counts(r.sc, &out->steps, NULL, NULL);
    out->steps -= s0;
    if (rc) fprintf(stderr, "batched: RD0 at rate %g failed: %s\n", rate, odhs_softcore_errmsg(r.sc));
    odhs_softcore_destroy(r.sc);
    return rc;
}

/* the hard-sphere settings and RD0 at each rate from the same warmed-up
 * starts: stress per unit rate, its difference to the exact scheme's, cost
 * per unit strain and its ratio to the batched default's */
static int rd0(int dim, size_t n, int seeds, double w, const char *rate_list)
{
    double rates[16];
    int nr = 0;
    char buf[256];
    snprintf(buf, sizeof buf, "%s", rate_list);
    for (char *t = strtok(buf, ","); t && nr < 16; t = strtok(NULL, ","))
        if (atof(t) > 0) rates[nr++] = atof(t);
    if (nr == 0 || seeds < 1 || seeds > 16 || !(w >= 0.1) || w > 100 || fabs(10 * w - nearbyint(10 * w)) > 1e-9) {
        fprintf(stderr, "usage: batched --rd0 DIM N SEEDS STRAIN [RATES] (STRAIN a multiple of 0.1: 10 blocks "
                        "sampled every 0.01)\n");
        return 2;
    }
    char cpu[256];
    bench_cpu_model(cpu, sizeof cpu);
    double la[3];
    bench_loadavg(la);
    printf("# hard spheres against RD0 at equal stress, %dD N = %zu, phi = %.2f; libodhs %s\n", dim, n,
           dim == 2 ? 0.80 : 0.60, odhs_version_string());
    printf("# machine: %s (%ld logical CPUs), load average at the start %.2f %.2f %.2f\n", cpu,
           sysconf(_SC_NPROCESSORS_ONLN), la[0], la[1], la[2]);
    printf("# per seed: batched compression, warm-up to strain 1 (batched); from that state each hard-sphere "
           "setting (shear rate 1, solver auto) and RD0 (k_e = 1, k_d = 1 = 1/xi0, Euler at 0.1 tau_e, after its "
           "own warm-up of strain %g) over strain %g, sampled every 0.01, 10 block means; stresses per unit "
           "shear rate\n",
           RD0_WARM, w);
    printf("%4s %-17s %10s %9s %9s %13s %18s %18s %9s\n", "seed", "setting", "rate", "steps", "cpu_s",
           "cpu_s/strain", "sxy/rate", "p/rate", "z");
    int ns = S_COUNT + nr;
    double val[32][3][16], cost[32][16];
    int got[32] = {0};
    double dmin = INFINITY;
    for (int k = 0; k < seeds; ++k) {
        odhs_system *sys;
        if (warmed_seed(dim, n, k, &sys)) return 1;
        if (k == 0) {
            double *r = malloc(n * sizeof *r);
            if (r && !odhs_system_get_radii(sys, r))
                for (size_t i = 0; i < n; ++i) dmin = fmin(dmin, 2 * r[i]);
            free(r);
        }
        for (int s = 0; s < ns; ++s) {
            odhs_system *c;
            stats r;
            double rate = s < S_COUNT ? 1.0 : rates[s - S_COUNT];
            if (odhs_system_clone(sys, &c)) return 1;
            int rc = s < S_COUNT ? sample_run(c, s, w, 10, &r) : rd0_sample(c, rate, w, 10, &r);
            odhs_system_destroy(c);
            if (rc) continue;
            char name[32];
            snprintf(name, sizeof name, "%s", s < S_COUNT ? sname[s] : "RD0");
            printf("%4d %-17s %10.1e %9llu %9.1f %13.1f %9.4f+-%7.4f %9.4f+-%7.4f %9.4f\n", k, name, rate,
                   (unsigned long long)r.steps, r.cpu, r.cpu / w, r.mean[0], r.err[0], r.mean[1], r.err[1],
                   r.mean[2]);
            fflush(stdout);
            for (int a = 0; a < 3; ++a) val[s][a][got[s]] = r.mean[a];
            cost[s][got[s]++] = r.cpu / w;
        }
        odhs_system_destroy(sys);
    }
    printf("# pooled over seeds: mean +- standard error of the seed means (one seed: no error); difference of "
           "sxy/rate to the exact scheme's in %% and in units of the combined error; cost per unit strain and its "
           "ratio to the batched default's; gammadot tau_e with tau_e = k_d d_min^2 / k_e = %.4f\n",
           dmin * dmin);
    printf("%-17s %10s %10s %18s %18s %9s %9s %13s %10s\n", "setting", "rate", "rate*tau_e", "sxy/rate",
           "p/rate", "dsxy_%", "dsxy/err", "cpu_s/strain", "/batched");
    double mx, ex, eb, cb;
    pooled(val[S_EXACT][0], got[S_EXACT], &mx, &ex);
    pooled(cost[S_BATCHED], got[S_BATCHED], &cb, &eb);
    for (int s = 0; s < ns; ++s) {
        if (!got[s]) continue;
        double m[2], e[2], c, ec;
        for (int a = 0; a < 2; ++a) pooled(val[s][a], got[s], &m[a], &e[a]);
        pooled(cost[s], got[s], &c, &ec);
        double rate = s < S_COUNT ? 1.0 : rates[s - S_COUNT];
        double d = got[S_EXACT] ? 100.0 * (m[0] / mx - 1.0) : NAN;
        double z = got[S_EXACT] && s != S_EXACT ? (m[0] - mx) / sqrt(e[0] * e[0] + ex * ex) : NAN;
        printf("%-17s %10.1e %10.2e %9.4f+-%7.4f %9.4f+-%7.4f %9.2f %9.1f %13.1f %10.2f\n",
               s < S_COUNT ? sname[s] : "RD0", rate, s < S_COUNT ? NAN : rate * dmin * dmin, m[0], e[0], m[1],
               e[1], d, z, c, got[S_BATCHED] ? c / cb : NAN);
    }
    printf("# RD0's cost per unit strain is that of 1 / (0.1 rate tau_e) Euler steps: it scales as 1 / rate\n");
    return 0;
}

/* the cost per unit strain of each setting against N: fitted exponents
 * (printed) and the SVG plot */
static void plot_costs(int dim, const size_t *ns, size_t nn, double cost[][16], int ok[][16], const char *note,
                       const char *svg)
{
    pl_plot p;
    char title[96];
    snprintf(title, sizeof title, "Cost per unit strain, %dD, phi = %.2f", dim, dim == 2 ? 0.80 : 0.60);
    pl_init(&p, title, "N", "CPU seconds per unit strain", 1, 1);
    for (int s = 0; s < S_COUNT; ++s) {
        double x[16], y[16];
        size_t m = 0;
        for (size_t q = 0; q < nn; ++q)
            if (ok[s][q]) {
                x[m] = (double)ns[q];
                y[m++] = cost[s][q];
            }
        if (!m) continue;
        int k = pl_series_add(&p, sname[s], s, 0, s + 1);
        for (size_t i = 0; i < m; ++i) pl_point(&p, k, x[i], y[i]);
        if (m >= 2) {
            double a = 0.0, e = pl_fit_loglog(x, y, m, &a);
            printf("# %s: cost per unit strain ~ N^%.2f (least-squares fit, %zu sizes, N = %zu..%zu)\n", sname[s], e,
                   m, (size_t)x[0], (size_t)x[m - 1]);
            char lab[64];
            snprintf(lab, sizeof lab, "fit N^%.2f", e);
            int f = pl_series_add(&p, lab, s, 1, 0);
            pl_point(&p, f, x[0], exp(a) * pow(x[0], e));
            pl_point(&p, f, x[m - 1], exp(a) * pow(x[m - 1], e));
        }
    }
    pl_note(&p, note);
    if (pl_write_svg(&p, svg)) fprintf(stderr, "batched: cannot write %s\n", svg);
    else printf("# plot: %s\n", svg);
    pl_free(&p);
}

/* --plot TABLE SVG: the fits and the plot of a table this program printed
 * (rows of a run cut short included) */
static int plot_table(const char *table, const char *svg)
{
    FILE *f = fopen(table, "r");
    if (!f) {
        fprintf(stderr, "batched: cannot read %s\n", table);
        return 1;
    }
    char line[512], note[300] = "", head[200] = "";
    size_t ns[16], nn = 0;
    double cost[S_COUNT][16];
    int ok[S_COUNT][16], dim = 2;
    memset(ok, 0, sizeof ok);
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#') {
            if (strstr(line, "3D bidisperse")) dim = 3;
            if (!strncmp(line, "# machine: ", 11)) snprintf(head, sizeof head, "%.*s", (int)strcspn(line + 11, ";\n"), line + 11);
            continue;
        }
        size_t n, nc;
        double phi;
        if (sscanf(line, "%zu %zu %lf", &n, &nc, &phi) != 3) continue;
        for (int s = 0; s < S_COUNT; ++s) {
            const char *t = strstr(line, sname[s]);
            double strain, cpu_s, per;
            unsigned long long steps, nex, ev;
            if (!t || sscanf(t + strlen(sname[s]), "%lf %llu %llu %llu %lf %lf", &strain, &steps, &nex, &ev, &cpu_s,
                              &per) != 6)
                continue;
            size_t q = 0;
            while (q < nn && ns[q] != n) ++q;
            if (q == nn) {
                if (nn == 16) break;
                ns[nn++] = n;
            }
            cost[s][q] = per;
            ok[s][q] = 1;
        }
    }
    fclose(f);
    if (!nn) {
        fprintf(stderr, "batched: no rows in %s\n", table);
        return 1;
    }
    snprintf(note, sizeof note, "%.160s; from %.100s", head, table);
    plot_costs(dim, ns, nn, cost, ok, note, svg);
    return 0;
}

int main(int argc, char **argv)
{
    const char *tt = getenv("ODHS_BENCH_TIGHT_TOL");
    if (tt) {
        tight_tol = atof(tt);
        if (!(tight_tol > 0.0 && tight_tol < 1.0)) {
            fprintf(stderr, "batched: ODHS_BENCH_TIGHT_TOL must be in (0, 1)\n");
            return 2;
        }
        snprintf(tight_name, sizeof tight_name, "batched tol %.0e", tight_tol);
        sname[S_TIGHT] = tight_name;
    }
    const char *sn = getenv("ODHS_BENCH_SUPERNODAL");
    if (sn) {
        pcg_supernodal = atof(sn);
        if (pcg_supernodal != -1.0 && pcg_supernodal != 0.0 && pcg_supernodal != 1.0) {
            fprintf(stderr, "batched: ODHS_BENCH_SUPERNODAL must be -1, 0 or 1\n");
            return 2;
        }
    }
    const char *sw = getenv("ODHS_BENCH_SUPERNODAL_SWITCH");
    if (sw) {
        pcg_switch = atof(sw);
        if (!(pcg_switch >= 0.0)) {
            fprintf(stderr, "batched: ODHS_BENCH_SUPERNODAL_SWITCH must be >= 0\n");
            return 2;
        }
    }
    const char *ordv = getenv("ODHS_BENCH_ORDERING");
    if (ordv) {
        pcg_ordering = atof(ordv);
        if (pcg_ordering != -1.0 && pcg_ordering != 0.0 && pcg_ordering != 1.0) {
            fprintf(stderr, "batched: ODHS_BENCH_ORDERING must be -1, 0 or 1\n");
            return 2;
        }
    }
    const char *reu = getenv("ODHS_BENCH_ORDERING_REUSE");
    if (reu) {
        pcg_reuse = atof(reu);
        if (!(pcg_reuse == -1.0 || pcg_reuse == 0.0 || pcg_reuse >= 1.0)) {
            fprintf(stderr, "batched: ODHS_BENCH_ORDERING_REUSE must be -1, 0 or >= 1\n");
            return 2;
        }
    }
    const char *om = getenv("ODHS_BENCH_OPENMP");
    if (om) {
        cm_openmp = atof(om);
        if (cm_openmp != 0.0 && cm_openmp != 1.0) {
            fprintf(stderr, "batched: ODHS_BENCH_OPENMP must be 0 or 1\n");
            return 2;
        }
    }
    const char *wu = getenv("ODHS_BENCH_WARMUP");
    if (wu) {
        warmup = atof(wu);
        if (!(warmup >= 0.01 && warmup <= 100.0)) {
            fprintf(stderr, "batched: ODHS_BENCH_WARMUP must be in [0.01, 100]\n");
            return 2;
        }
    }
    if (argc > 5 && !strcmp(argv[1], "--accuracy"))
        return accuracy(atoi(argv[2]), (size_t)atol(argv[3]), atoi(argv[4]), atof(argv[5]));
    if (argc > 5 && !strcmp(argv[1], "--rd0"))
        return rd0(atoi(argv[2]), (size_t)atol(argv[3]), atoi(argv[4]), atof(argv[5]),
                   argc > 6 ? argv[6] : "1e-3,3e-4,1e-4,3e-5,1e-5");
    if (argc > 5 && !strcmp(argv[1], "--paired"))
        return paired(atoi(argv[2]), (size_t)atol(argv[3]), atoi(argv[4]), atof(argv[5]),
                      argc > 6 ? atof(argv[6]) : 0.2);
    if (argc > 3 && !strcmp(argv[1], "--plot")) return plot_table(argv[2], argv[3]);
    if (argc > 2 && !strcmp(argv[1], "--pool-paired")) return pool_paired(argc - 2, argv + 2);
    if (argc > 2 && !strcmp(argv[1], "--pool")) return pool_files(argc - 2, argv + 2);
    if (argc > 3 && !strcmp(argv[1], "--from")) return from_file(argv[2], atof(argv[3]), argc > 4 ? argv[4] : "batched");
    if (argc > 3 && !strcmp(argv[1], "--memory"))
        return memory(atoi(argv[2]), (size_t)atol(argv[3]), argc > 4 ? (size_t)atol(argv[4]) : 16384,
                      argc > 5 ? atoi(argv[5]) : 5);
    int dim = argc > 1 ? atoi(argv[1]) : 2;
    size_t ns[16], nn = 0;
    {
        char buf[256];
        snprintf(buf, sizeof buf, "%s", argc > 2 ? argv[2] : "1024,4096,16384,65536");
        for (char *t = strtok(buf, ","); t && nn < 16; t = strtok(NULL, ",")) ns[nn++] = (size_t)atol(t);
    }
    const char *svg = argc > 3 ? argv[3] : (dim == 2 ? "batched_2d.svg" : "batched_3d.svg");
    size_t exact_nmax = argc > 4 ? (size_t)atol(argv[4]) : 16384;
    double events = argc > 5 ? atof(argv[5]) : 1000.0;
    size_t nbuild = argc > 6 ? (size_t)atol(argv[6]) : 16384;
    if ((dim != 2 && dim != 3) || nn == 0) {
        fprintf(stderr, "usage: batched [DIM] [NLIST] [SVG] [EXACT_NMAX] [EVENTS] [NBUILD]\n");
        return 2;
    }
    char cpu[256], path[64];
    bench_cpu_model(cpu, sizeof cpu);
    double la[3];
    bench_loadavg(la);
    snprintf(path, sizeof path, "/tmp/odhs_bench_batched_%ld.ckpt", (long)getpid());
    printf("# batched-event integrator against the exact one: cost per unit strain against N, %dD bidisperse, phi = "
           "%.2f, shear rate 1\n",
           dim, dim == 2 ? 0.80 : 0.60);
    printf("# machine: %s (%ld logical CPUs); libodhs %s; load average at the start %.2f %.2f %.2f\n", cpu,
           sysconf(_SC_NPROCESSORS_ONLN), odhs_version_string(), la[0], la[1], la[2]);
    printf("# start: batched compression (tiled above N = %zu), warm-up to strain %g (batched); solver auto\n",
           nbuild, warmup);
    printf("# exact: library defaults over %g events (from the warm-up's rate), skipped above N = %zu; batched: "
           "strain 0.3, its defaults (dt 5e-2); every setting in its own process\n",
           events, exact_nmax);
    printf("%6s %6s %6s %-17s %9s %7s %8s %8s %9s %12s %11s %8s %7s %7s %6s %8s\n", "N", "Nc", "phi", "setting",
           "strain", "steps", "exact", "events", "cpu_s", "cpu_s/strain", "ev/strain", "speedup", "sxy", "p", "z",
           "rss_MiB");
    fflush(stdout);
    double cost[S_COUNT][16];
    int ok[S_COUNT][16];
    memset(ok, 0, sizeof ok);
    for (size_t q = 0; q < nn; ++q) {
        job j = {dim, ns[q], nbuild, path, 0, 0.0};
        built b;
        double rss;
        if (in_child(build_child, &j, &b, sizeof b, &rss) || b.rc) {
            printf("%6zu start failed\n", ns[q]);
            continue;
        }
        for (int s = 0; s < S_COUNT; ++s) {
            if (s == S_EXACT && ns[q] > exact_nmax) {
                printf("%6zu %6zu %6.4f %-17s skipped (N > %zu)\n", ns[q], b.nc, b.phi, sname[s], exact_nmax);
                continue;
            }
            j.setting = s;
            j.w = s == S_EXACT ? fmin(WINDOW, fmax(1e-4, events / fmax(b.events_per_strain, 1.0))) : WINDOW;
            run_result r;
            if (in_child(run_child, &j, &r, sizeof r, &rss) || r.rc) {
                printf("%6zu %6zu %6.4f %-17s failed (%d)\n", ns[q], b.nc, b.phi, sname[s], r.rc);
                continue;
            }
            cost[s][q] = r.cpu / r.strain;
            ok[s][q] = 1;
            char sp[16] = "-";
            if (s != S_EXACT && ok[S_EXACT][q]) snprintf(sp, sizeof sp, "%.1fx", cost[S_EXACT][q] / cost[s][q]);
            printf("%6zu %6zu %6.4f %-17s %9.2e %7llu %8llu %8llu %9.2f %12.1f %11.3g %8s %7.4f %7.4f %6.3f %8.1f\n",
                   ns[q], b.nc, b.phi, sname[s], r.strain, (unsigned long long)r.steps,
                   (unsigned long long)r.nexact, (unsigned long long)r.events, r.cpu, cost[s][q],
                   (double)r.events / r.strain, sp, r.sxy, r.p, r.z, rss);
            fflush(stdout);
        }
        printf("# N = %zu: start %.0f s wall%s\n", ns[q], b.build_s, ns[q] > nbuild ? " (tiled)" : "");
    }
    remove(path);
    char note[300];
    snprintf(note, sizeof note, "%.120s, %ld CPUs (load %.1f); exact over %g events, batched over strain 0.3", cpu,
             sysconf(_SC_NPROCESSORS_ONLN), la[0], events);
    plot_costs(dim, ns, nn, cost, ok, note, svg);
    return 0;
}
