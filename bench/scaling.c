/* bench/scaling - benchmark 4 of the sparse-direct-solver issue: cost per
 * unit strain against N at phi = 0.80 (2D), with a least-squares fitted
 * exponent, and the peak memory per N.
 *
 * Start per N: 50:50 bidisperse discs (radii 0.5/0.7, 3% polydispersity),
 * random placement at phi = 0.45, compression at rate 1 to phi = 0.80
 * (solver "auto", Euler dt 1e-3), drift correction. With ODHS_SCALING_TILE=1
 * in the environment N = 10000 is a 2x2 periodic tiling of a compressed
 * N = 2500 packing instead (the copies start identical up to round-off and
 * then shear as one system of 10000; this was needed while the constrained
 * core was updated by a search per added contact, which made compressing
 * 10000 discs slower than the whole benchmark).
 * Shear at rate 1 and fixed volume: first a warm-up to strain 2 W(N) with the
 * default settings (not timed; it leaves the compression transient), then
 * from that state every setting shears over the window W(N) = K / N (K = 10
 * by default: about the same number of events for every N). Cost per unit
 * strain = CPU seconds of the process / W (CPU time, not wall time: the
 * machine is shared; wall time is printed too).
 *
 * Settings measured in the same run, from the same warmed-up state:
 *   default   the library's default settings (adaptive Heun, tol 1e-6,
 *             drift correction after every step, dt 1e-3 as the largest step),
 *             solver "auto" (cholmod-pcg with SuiteSparse)
 *   paper     Euler dt 1e-5, correction every 10 steps, cg (the paper's
 *             scheme); skipped above PAPER_NMAX (argument)
 * Every N runs in its own forked process: the peak resident set size of that
 * process (wait4 ru_maxrss: compression, warm-up and runs) is its memory.
 *
 * usage: scaling [NLIST] [K] [SVG] [CSV] [PAPER_NMAX]
 *        defaults 100,316,1000,3162,10000  10  scaling.svg  (none)  10000
 *        scaling --plot SVG CSV...   fit and plot rows of earlier runs' CSVs
 *        (e.g. sizes measured in separate processes)
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
#include <time.h>
#include <unistd.h>

#include "bench.h"
#include "odhs.h"
#include "../examples/plot.h"

enum { S_DEFAULT, S_PAPER, S_COUNT };
static const char *const sname[S_COUNT] = {"default (library defaults, auto)", "paper (euler 1e-5, cg)"};

typedef struct {
    size_t n, nc;
    int rc[S_COUNT];
    double window, wall[S_COUNT], cpu[S_COUNT];
    uint64_t steps[S_COUNT], events[S_COUNT];
    double phi, build_s;
    char backend[32];
    int tiled;
} result;

/* compressed packing of n discs at phi 0.80 */
static int compress(size_t n, odhs_system **out)
{
    odhs_system *sys;
    odhs_solver *sol;
    odhs_driver *drv;
    odhs_stepper *st;
    int rc = odhs_system_create(2, n, &sys);
    if (rc) return rc;
    odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, 11 + n);
    odhs_system_place_random(sys, 0.45, 12 + n);
    odhs_solver_create_by_name("auto", &sol);
    odhs_driver_create(&drv);
    odhs_driver_set_compression_rate(drv, 1.0);
    odhs_stepper_create(sys, drv, sol, &st);
    odhs_stepper_set_integrator(st, ODHS_INTEGRATOR_EULER); /* dt 1e-3, correction every 10 */
    rc = odhs_stepper_run_until_packing_fraction(st, 0.80);
    if (!rc) rc = odhs_stepper_correct(st);
    if (rc) fprintf(stderr, "scaling: compression of N=%zu failed: %s\n", n, odhs_stepper_errmsg(st));
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    if (rc) odhs_system_destroy(sys);
    else *out = sys;
    return rc;
}

/* 2x2 tiling of a (sheared) periodic 2D system: lattice a = (Lx, 0),
 * b = (gamma Ly, Ly); the big box has the same strain */
static int tile(const odhs_system *base, odhs_system **out)
{
    size_t n = odhs_system_count(base);
    double L[3], g, *x = malloc(2 * n * sizeof *x), *r = malloc(n * sizeof *r);
    double *X = malloc(8 * n * sizeof *X), *R = malloc(4 * n * sizeof *R);
    odhs_system_get_box(base, L);
    odhs_system_get_strain(base, &g);
    odhs_system_get_positions(base, x);
    odhs_system_get_radii(base, r);
    size_t k = 0;
    for (int i = 0; i < 2; ++i)
        for (int j = 0; j < 2; ++j)
            for (size_t p = 0; p < n; ++p, ++k) {
                X[2 * k] = x[2 * p] + i * L[0] + j * g * L[1];
                X[2 * k + 1] = x[2 * p + 1] + j * L[1];
                R[k] = r[p];
            }
    double L2[3] = {2 * L[0], 2 * L[1], 1.0};
    int rc = odhs_system_create(2, 4 * n, out);
    if (!rc) rc = odhs_system_set_configuration(*out, L2, g, R, X);
    free(x);
    free(r);
    free(X);
    free(R);
    return rc;
}

static odhs_stepper *shear_stepper(odhs_system *sys, int setting, odhs_solver **sol, odhs_driver **drv)
{
    odhs_stepper *st = NULL;
    odhs_solver_create_by_name(setting == S_PAPER ? "cg" : "auto", sol);
    odhs_driver_create(drv);
    odhs_driver_set_shear_rate(*drv, 1.0);
    odhs_stepper_create(sys, *drv, *sol, &st);
    if (setting == S_PAPER) {
        odhs_stepper_set_integrator(st, ODHS_INTEGRATOR_EULER);
        odhs_stepper_set_dt(st, 1e-5);
        odhs_stepper_set_correction_interval(st, 10);
    } /* else: the library's default settings */
    return st;
}

static void measure(size_t n, double K, size_t paper_nmax, result *res)
{
    memset(res, 0, sizeof *res);
    res->n = n;
    res->window = K / (double)n;
    double t0 = bench_wall();
    odhs_system *start = NULL;
    int rc;
    if (n == 10000 && getenv("ODHS_SCALING_TILE") && atoi(getenv("ODHS_SCALING_TILE")) > 0) {
        odhs_system *base;
        rc = compress(2500, &base);
        if (!rc) {
            rc = tile(base, &start);
            odhs_system_destroy(base);
        }
        res->tiled = 1;
    } else {
        rc = compress(n, &start);
    }
    if (rc) {
        for (int s = 0; s < S_COUNT; ++s) res->rc[s] = rc;
        return;
    }
    /* warm-up shear (default settings) */
    {
        odhs_solver *sol;
        odhs_driver *drv;
        odhs_stepper *st = shear_stepper(start, S_DEFAULT, &sol, &drv);
        rc = odhs_stepper_reset(st);
        if (!rc) rc = odhs_stepper_run_until_strain(st, 2.0 * res->window);
        if (!rc) rc = odhs_stepper_correct(st);
        if (rc) fprintf(stderr, "scaling: warm-up N=%zu failed: %s\n", n, odhs_stepper_errmsg(st));
        res->nc = odhs_network_count(odhs_stepper_network(st));
        odhs_stepper_destroy(st);
        odhs_driver_destroy(drv);
        odhs_solver_destroy(sol);
    }
    odhs_system_packing_fraction(start, &res->phi);
    res->build_s = bench_wall() - t0;
    for (int s = 0; s < S_COUNT; ++s) {
        if (rc || (s == S_PAPER && n > paper_nmax)) {
            res->rc[s] = rc ? rc : 1;
            continue;
        }
        odhs_system *sys;
        odhs_system_clone(start, &sys);
        odhs_solver *sol;
        odhs_driver *drv;
        odhs_stepper *st = shear_stepper(sys, s, &sol, &drv);
        double w0 = bench_wall(), c0 = bench_cpu();
        res->rc[s] = odhs_stepper_reset(st);
        if (!res->rc[s]) res->rc[s] = odhs_stepper_run_until_strain(st, res->window);
        res->cpu[s] = bench_cpu() - c0;
        res->wall[s] = bench_wall() - w0;
        if (res->rc[s]) fprintf(stderr, "scaling: N=%zu %s failed: %s\n", n, sname[s], odhs_stepper_errmsg(st));
        uint64_t co = 0, op = 0;
        odhs_stepper_counts(st, &res->steps[s], &co, &op);
        res->events[s] = co + op;
        if (s == S_DEFAULT) {
            const char *b = "?";
            odhs_solver_backend_name(sol, &b, NULL);
            snprintf(res->backend, sizeof res->backend, "%s", b);
        }
        odhs_stepper_destroy(st);
        odhs_driver_destroy(drv);
        odhs_solver_destroy(sol);
        odhs_system_destroy(sys);
    }
    odhs_system_destroy(start);
}

/* least-squares exponents and the log-log plot of cost per unit strain */
static void plot_and_fit(const result *all, size_t nn, double K, double load, const char *cpu, const char *svg)
{
    /* fits and plot */
    pl_plot p;
    pl_init(&p, "Cost per unit strain, 2D, phi = 0.80", "N", "CPU seconds per unit strain", 1, 1);
    for (int s = 0; s < S_COUNT; ++s) {
        double x[16], y[16];
        size_t m = 0;
        for (size_t q = 0; q < nn; ++q)
            if (!all[q].rc[s]) {
                x[m] = (double)all[q].n;
                y[m] = all[q].cpu[s] / all[q].window;
                m++;
            }
        double a = 0.0, e = pl_fit_loglog(x, y, m, &a);
        char lab[96];
        snprintf(lab, sizeof lab, "%s", s ? "paper: euler 1e-5, cg" : "library defaults, auto");
        int k = pl_series_add(&p, lab, s ? 1 : 0, 0, s ? 2 : 1);
        for (size_t i = 0; i < m; ++i) pl_point(&p, k, x[i], y[i]);
        if (m >= 2) {
            printf("# %s: cost per unit strain ~ N^%.2f (least-squares fit of log cost on log N, %zu sizes)\n",
                   sname[s], e, m);
            snprintf(lab, sizeof lab, "fit N^%.2f", e);
            int f = pl_series_add(&p, lab, s ? 1 : 0, 1, 0);
            pl_point(&p, f, x[0], exp(a) * pow(x[0], e));
            pl_point(&p, f, x[m - 1], exp(a) * pow(x[m - 1], e));
        }
    }
    /* the N^2 target line through the default's first point */
    if (!all[0].rc[S_DEFAULT]) {
        int t = pl_series_add(&p, "N^2 (target bound)", 7, 2, 0);
        double y0 = all[0].cpu[S_DEFAULT] / all[0].window;
        pl_point(&p, t, (double)all[0].n, y0);
        pl_point(&p, t, (double)all[nn - 1].n, y0 * pow((double)all[nn - 1].n / all[0].n, 2.0));
    }
    char note[400];
    if (isnan(load))
        snprintf(note, sizeof note, "%.120s, %ld CPUs, shared; window %g/N after warm-up 2W; rows from earlier runs",
                 cpu, sysconf(_SC_NPROCESSORS_ONLN), K);
    else
        snprintf(note, sizeof note, "%.120s, %ld CPUs, shared (load %.1f); window %g/N after warm-up 2W", cpu,
                 sysconf(_SC_NPROCESSORS_ONLN), load, K);
    pl_note(&p, note);
    if (pl_write_svg(&p, svg)) fprintf(stderr, "scaling: cannot write %s\n", svg);
    else printf("# plot: %s\n", svg);
    pl_free(&p);
}

/* --plot: rows of earlier runs' CSV files (N,Nc,phi,window,setting,...,cpu_s,...) */
static int replot(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: scaling --plot SVG CSV...\n");
        return 2;
    }
    result all[16];
    size_t nn = 0;
    memset(all, 0, sizeof all);
    for (int a = 3; a < argc; ++a) {
        FILE *f = fopen(argv[a], "r");
        if (!f) {
            fprintf(stderr, "scaling: cannot open %s\n", argv[a]);
            return 1;
        }
        char line[512];
        while (fgets(line, sizeof line, f)) {
            size_t n, nc;
            double phi, w, wall, cpu_s;
            char set[32];
            unsigned long long steps, events;
            if (sscanf(line, "%zu,%zu,%lf,%lf,%31[^,],%llu,%llu,%lf,%lf", &n, &nc, &phi, &w, set, &steps, &events,
                       &wall, &cpu_s) != 9)
                continue;
            size_t q = 0;
            while (q < nn && all[q].n != n) ++q;
            if (q == nn) {
                if (nn == 16) continue;
                nn++;
                all[q].n = n;
                all[q].rc[0] = all[q].rc[1] = 1;
            }
            int s = strcmp(set, "paper") ? S_DEFAULT : S_PAPER;
            all[q].window = w;
            all[q].cpu[s] = cpu_s;
            all[q].rc[s] = 0;
        }
        fclose(f);
    }
    /* ascending N */
    for (size_t i = 1; i < nn; ++i)
        for (size_t j = i; j > 0 && all[j - 1].n > all[j].n; --j) {
            result t = all[j];
            all[j] = all[j - 1];
            all[j - 1] = t;
        }
    char cpu[256];
    bench_cpu_model(cpu, sizeof cpu);
    plot_and_fit(all, nn, all[0].window * (double)all[0].n, NAN, cpu, argv[2]);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--plot")) return replot(argc, argv);
    size_t ns[16], nn = 0;
    {
        char buf[256];
        snprintf(buf, sizeof buf, "%s", argc > 1 ? argv[1] : "100,316,1000,3162,10000");
        for (char *t = strtok(buf, ","); t && nn < 16; t = strtok(NULL, ",")) ns[nn++] = (size_t)atol(t);
    }
    double K = argc > 2 ? atof(argv[2]) : 10.0;
    const char *svg = argc > 3 ? argv[3] : "scaling.svg";
    FILE *csv = argc > 4 && argv[4][0] ? fopen(argv[4], "w") : NULL;
    size_t paper_nmax = argc > 5 ? (size_t)atol(argv[5]) : 10000;
    char cpu[256];
    bench_cpu_model(cpu, sizeof cpu);
    double la[3];
    bench_loadavg(la);
    printf("# benchmark 4: cost per unit strain against N, 2D bidisperse, phi = 0.80, shear rate 1\n");
    printf("# machine: %s (%ld logical CPUs); libodhs %s; load average at the start %.2f %.2f %.2f\n", cpu,
           sysconf(_SC_NPROCESSORS_ONLN), odhs_version_string(), la[0], la[1], la[2]);
    printf("# window W = %g / N after a warm-up to 2 W; cost = CPU s / W; every N in its own process\n", K);
    printf("# default: the library's default settings (heun tol 1e-6, correction every step), solver auto; paper: euler "
           "dt 1e-5, correction every 10, cg\n");
    printf("%6s %6s %6s %9s %-26s %8s %8s %8s %9s %12s %9s %8s  %s\n", "N", "Nc", "phi", "window", "setting", "steps",
           "events", "wall_s", "cpu_s", "cpu_s/strain", "ms/event", "rss_MiB", "note");
    if (csv) fprintf(csv, "N,Nc,phi,window,setting,steps,events,wall_s,cpu_s,cpu_per_strain,ms_per_event,rss_mib\n");
    fflush(stdout);
    result all[16];
    double rss[16];
    for (size_t q = 0; q < nn; ++q) {
        int pfd[2];
        if (pipe(pfd)) return 1;
        pid_t pid = fork();
        if (pid == 0) {
            close(pfd[0]);
            result r;
            measure(ns[q], K, paper_nmax, &r);
            ssize_t w = write(pfd[1], &r, sizeof r);
            _exit(w == (ssize_t)sizeof r ? 0 : 1);
        }
        close(pfd[1]);
        result *r = &all[q];
        ssize_t got = read(pfd[0], r, sizeof *r);
        close(pfd[0]);
        struct rusage ru;
        int status = 0;
        wait4(pid, &status, 0, &ru);
        rss[q] = ru.ru_maxrss / 1024.0;
        if (got != (ssize_t)sizeof *r) {
            memset(r, 0, sizeof *r);
            r->n = ns[q];
            r->rc[0] = r->rc[1] = -1;
        }
        for (int s = 0; s < S_COUNT; ++s) {
            char note[96] = "";
            if (s == S_DEFAULT) snprintf(note, sizeof note, "backend %s; start %.0f s%s", r->backend, r->build_s,
                                         r->tiled ? ", 2x2 tiling of N=2500" : "");
            if (r->rc[s] == 1 && s == S_PAPER) {
                printf("%6zu %6zu %6.4f %9.2e %-26s %8s %8s %8s %9s %12s %9s %8.1f  skipped (N > %zu)\n", r->n, r->nc,
                       r->phi, r->window, sname[s], "-", "-", "-", "-", "-", "-", rss[q], paper_nmax);
                continue;
            }
            if (r->rc[s]) {
                printf("%6zu %6zu %6.4f %9.2e %-26s failed (%d)\n", r->n, r->nc, r->phi, r->window, sname[s], r->rc[s]);
                continue;
            }
            double cps = r->cpu[s] / r->window, mpe = r->events[s] ? 1e3 * r->cpu[s] / r->events[s] : NAN;
            printf("%6zu %6zu %6.4f %9.2e %-26s %8llu %8llu %8.2f %9.2f %12.1f %9.2f %8.1f  %s\n", r->n, r->nc, r->phi,
                   r->window, sname[s], (unsigned long long)r->steps[s], (unsigned long long)r->events[s], r->wall[s],
                   r->cpu[s], cps, mpe, rss[q], note);
            if (csv)
                fprintf(csv, "%zu,%zu,%.5f,%.4e,%s,%llu,%llu,%.4f,%.4f,%.4f,%.4f,%.1f\n", r->n, r->nc, r->phi,
                        r->window, s ? "paper" : "default", (unsigned long long)r->steps[s],
                        (unsigned long long)r->events[s], r->wall[s], r->cpu[s], cps, mpe, rss[q]);
        }
        fflush(stdout);
    }
    plot_and_fit(all, nn, K, la[0], cpu, svg);
    for (size_t q = 0; q < nn; ++q) printf("# peak RSS N=%zu: %.1f MiB\n", all[q].n, rss[q]);
    if (csv) fclose(csv);
    return 0;
}
