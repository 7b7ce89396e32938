/* bench/rheology.c - the flow curve of frictionless hard discs/spheres at
 * fixed pressure: the friction coefficient mu = sigma_xy / p and the packing
 * fraction phi against the viscous number I_v = xi0 gdot / p (= 1/p in the
 * library's units, gdot = xi0 = 1), with events and CPU time per unit
 * strain; and the paper's Fig. 7 signals (shear stress, phi, kappa against
 * strain) at p = 10.
 *
 *   build/bench/rheology [DIM] [N] [SEEDS] [STRAIN] [PMAX] [TRANSIENT] [PMIN] [euler|heun|batched[:TOL]]
 *       defaults 2 256 2 1.0 1e4 0.3 10 euler
 *
 * Each seed: the bidisperse scene of the examples (50:50, size ratio 1.4,
 * 3 % polydisperse), random at low density, compressed to phi = 0.80 (2D) or
 * 0.60 (3D), then sheared at p = PMIN, 10 PMIN, ... up to PMAX with the paper's
 * scheme (Euler, dt = 1e-3, drift correction every 10 steps; or the adaptive
 * scheme, tolerance 1e-6, correction every step; or the batched-event scheme
 * at its default tolerance 1e-3 or at TOL) and the auto solver. The first TRANSIENT of strain is discarded; mu and phi are sampled
 * every 0.01 of strain and averaged in blocks of 0.1 strain: the error bar is
 * the standard error of the block means (all seeds pooled). Events and CPU
 * time are per unit strain of the steady part.
 *
 * Writes rheology_mu.svg, rheology_phi.svg, rheology_fig7.svg and a table
 * (stdout), with every block mean on a "# block" line, so that runs of other
 * seeds in separate processes can be pooled. ODHS_BENCH_FIRST_SEED=K starts
 * at the K-th seed (0, the default, is seed 11; seed k is 11 + 7k).
 *
 * Runs at high p take CPU hours per unit strain. With ODHS_BENCH_STATE_DIR=D
 * every (p, seed) run saves its state in D after every sample (a library
 * checkpoint plus the accumulators) and a later process with the same
 * arguments resumes it where it stopped, CPU time and event counts included
 * (a finished run is read back, not rerun; a longer STRAIN extends it). The
 * continuation is the same trajectory: checkpoints restart bit for bit.
 */
#define _POSIX_C_SOURCE 200809L
#include <inttypes.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"

#include "bench.h"
#include "../examples/plot.h"

#define CHECK(call)                                                                                          \
    do {                                                                                                     \
        int rc_ = (call);                                                                                    \
        if (rc_ < 0) {                                                                                       \
            fprintf(stderr, "rheology: %s: %s\n", #call, odhs_strerror(rc_));                                \
            exit(1);                                                                                         \
        }                                                                                                    \
    } while (0)

#define SAMPLE 0.01 /* strain between samples */
#define BLOCK 10    /* samples per block */
#define MAXP 8

typedef struct {
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
} run;

static int integrator = ODHS_INTEGRATOR_EULER;
static double batched_tol; /* batched:TOL (0: the integrator's default) */

/* the scheme's name in files and headers */
static const char *scheme_name(void)
{
    static char name[48]; /* main thread only */
    if (integrator == ODHS_INTEGRATOR_HEUN) return "heun";
    if (integrator != ODHS_INTEGRATOR_BATCHED) return "euler";
    if (batched_tol > 0.0)
        snprintf(name, sizeof name, "batched%g", batched_tol);
    else
        snprintf(name, sizeof name, "batched");
    return name;
}
static int first_seed; /* ODHS_BENCH_FIRST_SEED */

static run start(int dim, size_t n, unsigned seed, double p)
{
    run r;
    CHECK(odhs_system_create(dim, n, &r.sys));
    CHECK(odhs_system_set_radii_bidisperse(r.sys, 0.5, 1.4, 0.03, seed));
    CHECK(odhs_system_place_random(r.sys, dim == 2 ? 0.45 : 0.30, seed + 1));
    CHECK(odhs_solver_create_by_name("auto", &r.sol));
    CHECK(odhs_driver_create(&r.drv));
    CHECK(odhs_driver_set_compression_rate(r.drv, 1.0));
    CHECK(odhs_stepper_create(r.sys, r.drv, r.sol, &r.st));
    CHECK(odhs_stepper_set_integrator(r.st, integrator));
    if (integrator == ODHS_INTEGRATOR_BATCHED && batched_tol > 0.0) CHECK(odhs_stepper_set_tolerance(r.st, batched_tol));
    CHECK(odhs_stepper_run_until_packing_fraction(r.st, dim == 2 ? 0.80 : 0.60));
    CHECK(odhs_driver_set_compression_rate(r.drv, 0.0));
    CHECK(odhs_driver_set_shear_rate(r.drv, 1.0));
    CHECK(odhs_driver_set_pressure(r.drv, p));
    return r;
}

static void finish(run *r)
{
    odhs_stepper_destroy(r->st);
    odhs_solver_destroy(r->sol);
    odhs_driver_destroy(r->drv);
    odhs_system_destroy(r->sys);
}

/* mean and standard error of x[0..n-1] */
static void mean_err(const double *x, int n, double *m, double *e)
{
    double s = 0.0, q = 0.0;
    for (int k = 0; k < n; ++k) s += x[k];
    *m = n ? s / n : NAN;
    for (int k = 0; k < n; ++k) q += (x[k] - *m) * (x[k] - *m);
    *e = n > 1 ? sqrt(q / (n - 1) / n) : NAN;
}

typedef struct {
    double p, mu, mu_err, phi, phi_err, z, kappa_rms, ev_per_strain, cpu_per_strain, steps_per_strain;
    int nblocks, stopped;
} point;

/* one seed's run at one pressure: what the pooled figures need */
typedef struct {
    long q;                  /* samples taken (0.01 strain each)          */
    double g0;               /* strain at the start of the shear          */
    int in_block;            /* samples in the open block                 */
    double acc_mu, acc_phi;  /* their sums                                */
    double zsum, k2;         /* z and kappa^2 summed over steady samples  */
    long nz;                 /* steady samples                            */
    int steady;              /* the steady part has started               */
    uint64_t st0, c0, o0;    /* stepper counts at its start               */
    double cpu;              /* CPU s of the steady part in earlier processes */
    int nb, stopped;
    double bmu[4096], bphi[4096];
    /* results of the steady part, set when the run ends (not saved) */
    double steady_strain;
    uint64_t steps, events;
} seed_run;

static const char *state_dir; /* ODHS_BENCH_STATE_DIR: resumable runs */

/* the state of a resumable run: a library checkpoint (.ckpt) and the
 * accumulators (.acc, text); 1 when both were read */
static void state_paths(char *ck, char *acc, size_t len, int dim, size_t n, double p, unsigned seed,
                        double transient)
{
    snprintf(ck, len, "%s/rheology_%dd_n%zu_p%g_seed%u_tr%g_%s.ckpt", state_dir, dim, n, p, seed, transient,
             scheme_name());
    snprintf(acc, len, "%.*s.acc", (int)(strlen(ck) - 5), ck);
}

static int state_load(const char *acc, seed_run *sr)
{
    FILE *f = fopen(acc, "r");
    if (!f) return 0;
    int ok = fscanf(f, "rheology-state 1 q %ld g0 %lg in_block %d acc %lg %lg z %lg %lg %ld steady %d %" SCNu64
                       " %" SCNu64 " %" SCNu64 " cpu %lg stopped %d blocks %d",
                    &sr->q, &sr->g0, &sr->in_block, &sr->acc_mu, &sr->acc_phi, &sr->zsum, &sr->k2, &sr->nz,
                    &sr->steady, &sr->st0, &sr->c0, &sr->o0, &sr->cpu, &sr->stopped, &sr->nb) == 15 &&
             sr->nb >= 0 && sr->nb <= 4096;
    for (int b = 0; ok && b < sr->nb; ++b) ok = fscanf(f, "%lg %lg", &sr->bmu[b], &sr->bphi[b]) == 2;
    fclose(f);
    return ok;
}

static void state_save(const char *acc, const seed_run *sr)
{
    char tmp[600];
    snprintf(tmp, sizeof tmp, "%s.tmp", acc);
    FILE *f = fopen(tmp, "w");
    if (!f) return;
    fprintf(f,
            "rheology-state 1 q %ld g0 %.17g in_block %d acc %.17g %.17g z %.17g %.17g %ld steady %d %" PRIu64
            " %" PRIu64 " %" PRIu64 " cpu %.17g stopped %d blocks %d\n",
            sr->q, sr->g0, sr->in_block, sr->acc_mu, sr->acc_phi, sr->zsum, sr->k2, sr->nz, sr->steady, sr->st0,
            sr->c0, sr->o0, sr->cpu, sr->stopped, sr->nb);
    for (int b = 0; b < sr->nb; ++b) fprintf(f, "%.17g %.17g\n", sr->bmu[b], sr->bphi[b]);
    if (fclose(f) == 0) rename(tmp, acc);
}

/* one seed at pressure p up to nsamp samples; with ODHS_BENCH_STATE_DIR
 * it resumes from, and saves after every sample, its state (the checkpoint
 * is written first: a state whose .acc is newer than its .ckpt is never
 * left behind). The Fig. 7 run (fig7 != NULL) is never resumed. */
static void run_seed(int dim, size_t n, unsigned seed, double p, long nsamp, double transient, seed_run *sr,
                     pl_plot *fig7, int sm, int sp, int sk)
{
    memset(sr, 0, sizeof *sr);
    char ck[512] = "", acc[512] = "";
    run r;
    int resumed = 0;
    if (state_dir && !fig7) {
        state_paths(ck, acc, sizeof ck, dim, n, p, seed, transient);
        char err[256];
        if (state_load(acc, sr)) {
            CHECK(odhs_solver_create_by_name("auto", &r.sol));
            if (odhs_checkpoint_read(ck, r.sol, &r.sys, &r.drv, &r.st, err, sizeof err) == ODHS_OK) {
                resumed = 1;
                fprintf(stderr, "rheology: p = %g seed %u resumed at strain %.2f from %s\n", p, seed,
                        sr->q * SAMPLE, ck);
            } else {
                fprintf(stderr, "rheology: %s: %s; starting afresh\n", ck, err);
                odhs_solver_destroy(r.sol);
                memset(sr, 0, sizeof *sr);
            }
        }
    }
    if (!resumed) {
        r = start(dim, n, seed, p);
        CHECK(odhs_stepper_strain(r.st, &sr->g0));
    }
    double cpu0 = bench_cpu();
    while (sr->q < nsamp && !sr->stopped) {
        double g = (sr->q + 1) * SAMPLE;
        int rc = odhs_stepper_run_until_strain(r.st, sr->g0 + g);
        if (rc) {
            fprintf(stderr, "rheology: p = %g seed %u stopped at strain %.3f: %s (%s)\n", p, seed, g,
                    odhs_strerror(rc), odhs_stepper_errmsg(r.st));
            sr->stopped = 1;
            break;
        }
        sr->q++;
        double sxy, phi, kap, z;
        CHECK(odhs_stepper_shear_stress(r.st, &sxy));
        CHECK(odhs_system_packing_fraction(r.sys, &phi));
        CHECK(odhs_stepper_kappa(r.st, &kap));
        CHECK(odhs_stepper_coordination(r.st, &z));
        if (fig7) {
            pl_point(fig7, sm, g, sxy / p);
            pl_point(fig7, sp, g, (phi - (dim == 2 ? 0.8 : 0.6)) * 10.0);
            pl_point(fig7, sk, g, kap);
        }
        if (g < transient - 1e-9) {
        } else if (fabs(g - transient) < 0.5 * SAMPLE) { /* the steady part starts */
            CHECK(odhs_stepper_counts(r.st, &sr->st0, &sr->c0, &sr->o0));
            sr->steady = 1;
            sr->cpu = 0.0;
            cpu0 = bench_cpu();
        } else {
            sr->acc_mu += sxy / p;
            sr->acc_phi += phi;
            sr->zsum += z;
            sr->k2 += kap * kap;
            sr->nz++;
            if (++sr->in_block == BLOCK && sr->nb < 4096) {
                sr->bmu[sr->nb] = sr->acc_mu / BLOCK;
                sr->bphi[sr->nb] = sr->acc_phi / BLOCK;
                printf("# block p = %g seed %u strain %.2f: mu %.6f phi %.6f\n", p, seed, g, sr->bmu[sr->nb],
                       sr->bphi[sr->nb]);
                fflush(stdout);
                sr->nb++;
                sr->acc_mu = sr->acc_phi = 0.0;
                sr->in_block = 0;
            }
        }
        if (acc[0]) { /* the CPU of this process so far joins the saved figure */
            seed_run keep = *sr;
            if (keep.steady) keep.cpu += bench_cpu() - cpu0;
            if (odhs_checkpoint_write(r.st, ck) == ODHS_OK) state_save(acc, &keep);
        }
    }
    if (sr->steady) sr->cpu += bench_cpu() - cpu0;
    uint64_t st1, c1, o1;
    CHECK(odhs_stepper_counts(r.st, &st1, &c1, &o1));
    double gend;
    CHECK(odhs_stepper_strain(r.st, &gend));
    sr->steps = st1 - sr->st0;
    sr->events = (c1 + o1) - (sr->c0 + sr->o0);
    sr->steady_strain = sr->steady ? gend - sr->g0 - transient : 0.0;
    finish(&r);
}

/* one pressure, all seeds: the block means */
static point measure(int dim, size_t n, int seeds, double strain, double transient, double p, pl_plot *fig7)
{
    point pt;
    memset(&pt, 0, sizeof pt);
    pt.p = p;
    int maxb = seeds * 4096;
    double *bmu = calloc((size_t)maxb, sizeof *bmu), *bphi = calloc((size_t)maxb, sizeof *bphi);
    seed_run *sr = malloc(sizeof *sr);
    if (!bmu || !bphi || !sr) {
        fprintf(stderr, "rheology: out of memory\n");
        exit(1);
    }
    double zsum = 0.0, k2 = 0.0, cpu = 0.0, steady = 0.0;
    long nz = 0;
    uint64_t events = 0, steps = 0;
    int sm = -1, sp = -1, sk = -1;
    if (fig7) {
        sm = pl_series_add(fig7, "shear stress / p", 0, 0, 0);
        sp = pl_series_add(fig7, dim == 2 ? "(phi - 0.8) x 10" : "(phi - 0.6) x 10", 1, 0, 0);
        sk = pl_series_add(fig7, "kappa", 2, 1, 0);
    }
    long nsamp = (long)floor(strain / SAMPLE + 0.5);
    for (int s = 0; s < seeds; ++s) {
        unsigned seed = (unsigned)(11 + 7 * (first_seed + s));
        run_seed(dim, n, seed, p, nsamp, transient, sr, fig7 && s == 0 ? fig7 : NULL, sm, sp, sk);
        pt.stopped |= sr->stopped;
        for (int b = 0; b < sr->nb; ++b) {
            bmu[pt.nblocks] = sr->bmu[b];
            bphi[pt.nblocks] = sr->bphi[b];
            pt.nblocks++;
        }
        zsum += sr->zsum;
        k2 += sr->k2;
        nz += sr->nz;
        if (sr->steady) {
            cpu += sr->cpu;
            steady += sr->steady_strain;
            events += sr->events;
            steps += sr->steps;
        }
    }
    mean_err(bmu, pt.nblocks, &pt.mu, &pt.mu_err);
    mean_err(bphi, pt.nblocks, &pt.phi, &pt.phi_err);
    pt.z = nz ? zsum / nz : NAN;
    pt.kappa_rms = nz ? sqrt(k2 / nz) : NAN;
    pt.ev_per_strain = steady > 0 ? events / steady : NAN;
    pt.steps_per_strain = steady > 0 ? steps / steady : NAN;
    pt.cpu_per_strain = steady > 0 ? cpu / steady : NAN;
    free(sr);
    free(bmu);
    free(bphi);
    return pt;
}

int main(int argc, char **argv)
{
    int dim = argc > 1 ? atoi(argv[1]) : 2;
    size_t n = argc > 2 ? (size_t)atol(argv[2]) : 256;
    int seeds = argc > 3 ? atoi(argv[3]) : 2;
    double strain = argc > 4 ? atof(argv[4]) : 1.0;
    double pmax = argc > 5 ? atof(argv[5]) : 1e4;
    double transient = argc > 6 ? atof(argv[6]) : 0.3;
    double pmin = argc > 7 ? atof(argv[7]) : 10.0;
    const char *fs = getenv("ODHS_BENCH_FIRST_SEED");
    first_seed = fs ? atoi(fs) : 0;
    state_dir = getenv("ODHS_BENCH_STATE_DIR");
    if (state_dir && !*state_dir) state_dir = NULL;
    if (argc > 8) {
        integrator = !strcmp(argv[8], "heun") ? ODHS_INTEGRATOR_HEUN : !strcmp(argv[8], "euler") ? 0 : -1;
        if (!strncmp(argv[8], "batched", 7)) {
            integrator = ODHS_INTEGRATOR_BATCHED;
            if (argv[8][7] == ':') {
                char *end;
                batched_tol = strtod(argv[8] + 8, &end);
                if (*end || !(batched_tol > 0.0 && batched_tol < 1.0)) integrator = -1;
            } else if (argv[8][7]) {
                integrator = -1;
            }
        }
    }
    if ((dim != 2 && dim != 3) || n < 8 || seeds < 1 || !(strain > transient) || !(pmin > 0.0) || !(pmax >= pmin) ||
        integrator < 0 || first_seed < 0 || first_seed > 1000) {
        fprintf(stderr, "usage: rheology [DIM] [N] [SEEDS] [STRAIN] [PMAX] [TRANSIENT] [PMIN] [euler|heun|batched[:TOL]]\n");
        return 2;
    }
    char cpu[128], tag[96];
    int ncpu = bench_cpu_model(cpu, sizeof cpu);
    snprintf(tag, sizeof tag, "%dd_n%zu%s%s", dim, n, integrator == ODHS_INTEGRATOR_EULER ? "" : "_", integrator == ODHS_INTEGRATOR_EULER ? "" : scheme_name());
    printf("# rheology: %dD N = %zu, %d seed(s) from seed %d, strain %.2f (first %.2f discarded), %s, auto solver\n",
           dim, n, seeds, 11 + 7 * first_seed, strain, transient,
           integrator == ODHS_INTEGRATOR_HEUN      ? "adaptive Heun tol 1e-6"
           : integrator == ODHS_INTEGRATOR_BATCHED ? (batched_tol > 0.0 ? "batched events at the set tolerance" : "batched events, default tolerance 1e-3")
                                                   : "Euler dt = 1e-3");
    printf("# machine: %s (%d CPUs listed), libodhs %s, OPENBLAS_NUM_THREADS=%s\n", cpu, ncpu, odhs_version_string(),
           getenv("OPENBLAS_NUM_THREADS") ? getenv("OPENBLAS_NUM_THREADS") : "unset");
    printf("# mu = sigma_xy/p, I_v = xi0 gdot/p; +- the standard error of block means (0.1 strain)\n");
    printf("%10s %10s %18s %20s %7s %10s %11s %11s %11s %6s\n", "p", "I_v", "mu", "phi", "z", "kappa_rms",
           "events/str", "steps/str", "cpu_s/str", "blocks");
    point pts[MAXP];
    int np = 0;
    pl_plot fig7;
    char title[160];
    snprintf(title, sizeof title, "Shear at fixed pressure p = 10 (Fig. 7 of the paper), %dD N = %zu, seed %d", dim, n,
             11 + 7 * first_seed);
    pl_init(&fig7, title, "strain", "", 0, 0);
    for (double p = pmin; p <= pmax * (1 + 1e-9) && np < MAXP; p *= 10.0) {
        point pt = measure(dim, n, seeds, strain, transient, p, p == 10.0 ? &fig7 : NULL);
        pts[np++] = pt;
        printf("%10.0f %10.1e %9.5f +- %.5f %10.6f +- %.6f %7.4f %10.4f %11.0f %11.0f %11.2f %6d%s\n", pt.p, 1.0 / pt.p,
               pt.mu, pt.mu_err, pt.phi, pt.phi_err, pt.z, pt.kappa_rms, pt.ev_per_strain, pt.steps_per_strain,
               pt.cpu_per_strain, pt.nblocks, pt.stopped ? "  (a run stopped)" : "");
        fflush(stdout);
    }
    char note[320], path[128];
    snprintf(note, sizeof note, "build/bench/rheology %d %zu %d %g %g %g %g; %.100s", dim, n, seeds, strain, pmax,
             transient, pmin, cpu);
    pl_note(&fig7, note);
    snprintf(path, sizeof path, "rheology_fig7_%s.svg", tag);
    if (pmin <= 10.0) pl_write_svg(&fig7, path);
    pl_free(&fig7);

    const char *what[2] = {"mu = sigma_xy / p", "phi"};
    const char *file[2] = {"mu", "phi"};
    for (int f = 0; f < 2; ++f) {
        pl_plot pl;
        snprintf(title, sizeof title, "Frictionless %s, %dD N = %zu, fixed pressure: %s against I_v",
                 dim == 2 ? "discs" : "spheres", dim, n, what[f]);
        pl_init(&pl, title, "I_v = xi0 gdot / p", what[f], 1, 0);
        int s = pl_series_add(&pl, "libodhs (block means +- 1 s.e.)", 0, 0, 1);
        int lo = pl_series_add(&pl, "- 1 s.e.", 0, 2, 0), hi = pl_series_add(&pl, "+ 1 s.e.", 0, 2, 0);
        for (int k = 0; k < np; ++k) {
            double v = f ? pts[k].phi : pts[k].mu, e = f ? pts[k].phi_err : pts[k].mu_err;
            pl_point(&pl, s, 1.0 / pts[k].p, v);
            pl_point(&pl, lo, 1.0 / pts[k].p, v - e);
            pl_point(&pl, hi, 1.0 / pts[k].p, v + e);
        }
        pl_note(&pl, note);
        snprintf(path, sizeof path, "rheology_%s_%s.svg", file[f], tag);
        pl_write_svg(&pl, path);
        pl_free(&pl);
    }
    return 0;
}
