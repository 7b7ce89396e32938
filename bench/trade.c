/* bench/trade - the speed/accuracy trade of the integrators (issue "Sparse
 * direct solvers, adaptive integration": benchmark 2 and 3).
 *
 * One start: 2D 50:50 bidisperse discs (radii 0.5/0.7, 3% polydispersity),
 * random placement at phi = 0.45, compression to phi = 0.80, drift
 * correction. Every setting shears the same start to strain GAMMA at fixed
 * volume. Errors are measured against a tight reference (adaptive Heun,
 * tol = 1e-12, correction every step): rms and max position difference at the
 * end (minimum image, in mean diameters), worst contact-gap error over the
 * run, and the max difference of the shear-stress series sampled every
 * GAMMA/20 (relative to the mean |stress|).
 *
 * The paper's settings always use CG (the paper's solver); the adaptive
 * settings use SOLVER.
 *
 * Times: wall seconds and CPU seconds of the process (the machine may be
 * shared: the ratios use CPU time). The summary compares, for each paper
 * setting, the fastest other setting that is at least as accurate in all
 * three errors (rms position, worst gap, stress series).
 *
 * usage: trade [N] [GAMMA] [SOLVER] [CSV] [SVG]   (defaults 1000, 0.01, cg,
 *        no CSV, trade.svg: rms position error against CPU time)
 *        trade --plot CSV SVG [N] [GAMMA] [SOLVER]   the plot again from a CSV
 * environment: ODHS_TRADE_PAPER_1E7=1 adds paper mode at dt 1e-7 (~10 CPU
 *        minutes at N = 1000)
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"
#include "odhs.h"
#include "../examples/plot.h"

#define NSAMP 20

typedef struct {
    const char *label;
    int integrator;
    double dt, tol;
    unsigned corr;
    int defaults; /* 1: the library's default settings (no set_* call) */
} setting;

typedef struct {
    double seconds, cpu, rms, maxdx, gap, stress_err;
    uint64_t steps, events, rejected;
    double stress[NSAMP + 1];
    double *x;
    int rc;
} result;

static int run(const odhs_system *start, const char *solver, const setting *s, double gamma, result *r)
{
    if (s->integrator == ODHS_INTEGRATOR_EULER && !strncmp(s->label, "paper", 5)) solver = "cg";
    odhs_system *sys;
    odhs_solver *sol;
    odhs_driver *drv;
    odhs_stepper *st;
    odhs_system_clone(start, &sys);
    if (odhs_solver_create_by_name(solver, &sol)) return -1;
    odhs_driver_create(&drv);
    odhs_driver_set_shear_rate(drv, 1.0);
    odhs_stepper_create(sys, drv, sol, &st);
    if (!s->defaults) {
        odhs_stepper_set_integrator(st, s->integrator);
        odhs_stepper_set_dt(st, s->dt);
        if (s->tol > 0) odhs_stepper_set_tolerance(st, s->tol);
        odhs_stepper_set_correction_interval(st, s->corr);
    }
    r->gap = 0.0;
    r->rc = 0;
    double t0 = bench_wall(), c0 = bench_cpu();
    r->rc = odhs_stepper_reset(st);
    for (int k = 0; k <= NSAMP && !r->rc; ++k) {
        if (k) r->rc = odhs_stepper_run_until_strain(st, gamma * k / NSAMP);
        double g;
        odhs_stepper_errors(st, &g, NULL);
        r->gap = fmax(r->gap, g);
        odhs_stepper_shear_stress(st, &r->stress[k]);
    }
    r->seconds = bench_wall() - t0;
    r->cpu = bench_cpu() - c0;
    uint64_t nc, no;
    odhs_stepper_counts(st, &r->steps, &nc, &no);
    odhs_stepper_adaptive_stats(st, &r->rejected, NULL);
    r->events = nc + no;
    size_t nd = odhs_system_count(sys) * (size_t)odhs_system_dim(sys);
    r->x = malloc(nd * sizeof *r->x);
    odhs_system_get_positions(sys, r->x);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
    return r->rc;
}

/* the main plot: rms position error against CPU time, one family per kind
 * of setting (from its label); settings with the same error as the previous
 * one of their family share its label */
static void trade_plot(const char *svg, size_t n, double gamma, const char *solver, const char *const *lab,
                       const double *cpu, const double *rms, size_t m, const char *note)
{
    pl_plot pp;
    char title[160];
    snprintf(title, sizeof title, "Speed/accuracy trade, N = %zu, 2D, phi = 0.80, strain %g", n, gamma);
    pl_init(&pp, title, "CPU seconds", "rms position error (mean diameters)", 1, 1);
    int fam[4];
    char hl[64];
    fam[0] = pl_series_add(&pp, "paper: euler, cg, corr 10", 1, 0, 2);
    fam[1] = pl_series_add(&pp, "euler dt 1e-5, other corr", 3, 1, 3);
    snprintf(hl, sizeof hl, "heun (adaptive), %s, corr 10", solver);
    fam[2] = pl_series_add(&pp, hl, 0, 0, 1);
    fam[3] = pl_series_add(&pp, "heun, corr 1 or 100", 2, 1, 4);
    int famd = pl_series_add(&pp, "defaults: heun tol 1e-6, corr 1", 4, 0, 5);
    pp.s[famd].lines = 0;
    pp.s[fam[1]].lines = 0;
    pp.s[fam[3]].lines = 0;
    double last_rms[4] = {-1, -1, -1, -1};
    for (size_t k = 0; k < m; ++k) {
        const char *l = lab[k];
        if (!strcmp(l, "default settings")) {
            pl_point(&pp, famd, cpu[k], rms[k]); /* in the legend: no label over the heun points */
            continue;
        }
        int f = !strncmp(l, "paper", 5) ? 0 : !strncmp(l, "euler", 5) ? 1 : strstr(l, "corr") ? 3 : 2;
        char text[24] = "";
        /* "dt X", "corr K" or "tol X" from the label; the few "heun, other
         * corr" points are named in the legend (labels would overlap) */
        const char *v = f == 0 ? strstr(l, "dt ") : f == 1 ? strstr(l, "corr ") : f == 2 ? strstr(l, "tol ") : NULL;
        if (v) {
            size_t key = strcspn(v, " ") + 1;
            snprintf(text, sizeof text, "%.*s", (int)(key + strcspn(v + key, " ")), v);
        }
        if (last_rms[f] > 0 && fabs(rms[k] - last_rms[f]) <= 1e-3 * rms[k]) text[0] = 0; /* same point */
        last_rms[f] = rms[k];
        pl_point_label(&pp, fam[f], cpu[k], rms[k], text);
    }
    pl_note(&pp, note);
    if (pl_write_svg(&pp, svg)) fprintf(stderr, "trade: cannot write %s\n", svg);
    else printf("# plot: %s\n", svg);
    pl_free(&pp);
}

/* trade --plot CSV SVG [N] [GAMMA] [SOLVER]: the plot again from a CSV of a run */
static int replot(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: trade --plot CSV SVG [N] [GAMMA] [SOLVER]\n");
        return 2;
    }
    FILE *f = fopen(argv[2], "r");
    if (!f) {
        fprintf(stderr, "trade: cannot read %s\n", argv[2]);
        return 1;
    }
    static char labs[32][64];
    const char *lp[32];
    double cpu[32], rms[32];
    size_t m = 0;
    char line[512];
    while (m < 32 && fgets(line, sizeof line, f)) {
        char *c1 = strchr(line, ',');
        if (!c1 || !strncmp(line, "setting,", 8)) continue;
        *c1 = 0;
        double wall, c, st, ev, rej, r;
        if (sscanf(c1 + 1, "%lf,%lf,%lf,%lf,%lf,%lf", &wall, &c, &st, &ev, &rej, &r) != 6) continue;
        snprintf(labs[m], sizeof labs[m], "%.63s", line);
        lp[m] = labs[m];
        cpu[m] = c;
        rms[m++] = r;
    }
    fclose(f);
    size_t n = argc > 4 ? (size_t)atol(argv[4]) : 1000;
    double gamma = argc > 5 ? atof(argv[5]) : 0.01;
    char model[256], note[400];
    bench_cpu_model(model, sizeof model);
    snprintf(note, sizeof note, "%.120s; replotted from %.200s (times: see the run's output)", model, argv[2]);
    trade_plot(argv[3], n, gamma, argc > 6 ? argv[6] : "auto", lp, cpu, rms, m, note);
    return 0;
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "--plot")) return replot(argc, argv);
    size_t n = argc > 1 ? (size_t)atol(argv[1]) : 1000;
    double gamma = argc > 2 ? atof(argv[2]) : 0.01;
    const char *solver = argc > 3 ? argv[3] : "cg";
    FILE *csv = argc > 4 && argv[4][0] ? fopen(argv[4], "w") : NULL;
    const char *svg = argc > 5 ? argv[5] : "trade.svg";
    char cpu[256];
    bench_cpu_model(cpu, sizeof cpu);

    odhs_system *sys;
    odhs_solver *cg;
    odhs_driver *drv;
    odhs_stepper *st;
    odhs_system_create(2, n, &sys);
    odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, 11);
    odhs_system_place_random(sys, 0.45, 12);
    odhs_solver_create_by_name("cg", &cg);
    odhs_driver_create(&drv);
    odhs_driver_set_compression_rate(drv, 1.0);
    odhs_stepper_create(sys, drv, cg, &st);
    odhs_stepper_set_integrator(st, ODHS_INTEGRATOR_EULER); /* the start: Euler dt 1e-3, correction every 10 */
    if (odhs_stepper_run_until_packing_fraction(st, 0.80) || odhs_stepper_correct(st)) {
        fprintf(stderr, "trade: building the start failed: %s\n", odhs_stepper_errmsg(st));
        return 1;
    }
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(cg);

    double la[3];
    bench_loadavg(la);
    printf("# machine: %s; libodhs %s; load average at the start %.2f %.2f %.2f (shared machine: ratios use CPU "
           "time)\n", cpu, odhs_version_string(), la[0], la[1], la[2]);
    printf("# N = %zu 2D bidisperse, phi = 0.80, shear to strain %g; paper settings: cg, others: %s\n", n,
           gamma, solver);
    setting ref = {"reference heun tol 1e-11, corr 1", ODHS_INTEGRATOR_HEUN, 1e-3, 1e-11, 1, 0};
    setting set[] = {
        {"paper euler dt 1e-4 corr 10", ODHS_INTEGRATOR_EULER, 1e-4, 0, 10, 0},
        {"paper euler dt 1e-5 corr 10", ODHS_INTEGRATOR_EULER, 1e-5, 0, 10, 0},
        {"paper euler dt 1e-6 corr 10", ODHS_INTEGRATOR_EULER, 1e-6, 0, 10, 0},
        {"paper euler dt 1e-7 corr 10", ODHS_INTEGRATOR_EULER, 1e-7, 0, 10, 0},
        {"default settings", ODHS_INTEGRATOR_HEUN, 0, 0, 0, 1},
        {"euler dt 1e-5 corr 1", ODHS_INTEGRATOR_EULER, 1e-5, 0, 1, 0},
        {"euler dt 1e-5 corr 100", ODHS_INTEGRATOR_EULER, 1e-5, 0, 100, 0},
        {"heun tol 1e-3", ODHS_INTEGRATOR_HEUN, 1e-2, 1e-3, 10, 0},
        {"heun tol 1e-3 corr 1", ODHS_INTEGRATOR_HEUN, 1e-2, 1e-3, 1, 0},
        {"heun tol 1e-4", ODHS_INTEGRATOR_HEUN, 1e-2, 1e-4, 10, 0},
        {"heun tol 1e-5", ODHS_INTEGRATOR_HEUN, 1e-2, 1e-5, 10, 0},
        {"heun tol 1e-6", ODHS_INTEGRATOR_HEUN, 1e-2, 1e-6, 10, 0},
        {"heun tol 1e-7", ODHS_INTEGRATOR_HEUN, 1e-2, 1e-7, 10, 0},
        {"heun tol 1e-8", ODHS_INTEGRATOR_HEUN, 1e-2, 1e-8, 10, 0},
        {"heun tol 1e-9", ODHS_INTEGRATOR_HEUN, 1e-2, 1e-9, 10, 0},
        {"heun tol 1e-10", ODHS_INTEGRATOR_HEUN, 1e-2, 1e-10, 10, 0},
        {"heun tol 1e-8 corr 100", ODHS_INTEGRATOR_HEUN, 1e-2, 1e-8, 100, 0},
    };
    size_t nset = sizeof set / sizeof set[0];
    /* paper dt 1e-7 costs ~10 minutes at N = 1000: only with ODHS_TRADE_PAPER_1E7=1 */
    const char *p7 = getenv("ODHS_TRADE_PAPER_1E7");
    int with_p7 = p7 && atoi(p7) > 0;
    result R;
    if (run(sys, solver, &ref, gamma, &R)) {
        fprintf(stderr, "trade: reference run failed (%d)\n", R.rc);
        return 1;
    }
    double smean = 0.0;
    for (int k = 0; k <= NSAMP; ++k) smean += fabs(R.stress[k]) / (NSAMP + 1);
    printf("# reference: %.2f s wall, %.2f s CPU, %llu steps, %llu events, worst gap %.2e\n", R.seconds, R.cpu,
           (unsigned long long)R.steps, (unsigned long long)R.events, R.gap);
    printf("%-34s %9s %9s %9s %8s %8s %10s %10s %10s %10s %9s\n", "setting", "wall_s", "cpu_s", "steps", "events",
           "rejected", "rms_dx", "max_dx", "worst_gap", "stress_err", "vs_e1e-5");
    if (csv) fprintf(csv, "setting,wall_s,cpu_s,steps,events,rejected,rms_dx,max_dx,worst_gap,stress_err\n");
    double t_paper5 = 0.0;
    result keep[32];
    double L[3];
    odhs_system_get_box(sys, L);
    double gref;
    odhs_system_get_strain(sys, &gref);
    double lam = 0.0, *rad = malloc(n * sizeof *rad);
    odhs_system_get_radii(sys, rad);
    for (size_t i = 0; i < n; ++i) lam += 2.0 * rad[i] / n;
    for (size_t k = 0; k < nset; ++k) {
        result r;
        memset(&r, 0, sizeof r);
        if (set[k].dt == 1e-7 && !with_p7) {
            r.rc = 1; /* skipped, not failed */
            keep[k] = r;
            continue;
        }
        int rc = run(sys, solver, &set[k], gamma, &r);
        if (k == 1) t_paper5 = r.cpu;
        double s2 = 0.0, mx = 0.0, serr = 0.0;
        if (!rc) {
            /* the final box is the same (fixed volume, same strain): compare by
             * minimum image in the final sheared cell */
            double g = fmod(gamma + gref, 1.0);
            for (size_t i = 0; i < n; ++i) {
                double dy = r.x[2 * i + 1] - R.x[2 * i + 1], dx = r.x[2 * i] - R.x[2 * i];
                double ny = nearbyint(dy / L[1]);
                dy -= ny * L[1];
                dx -= ny * g * L[1];
                dx -= nearbyint(dx / L[0]) * L[0];
                double d2 = (dx * dx + dy * dy) / (lam * lam);
                s2 += d2 / n;
                mx = fmax(mx, sqrt(d2));
            }
            for (int q = 0; q <= NSAMP; ++q) serr = fmax(serr, fabs(r.stress[q] - R.stress[q]) / smean);
        }
        printf("%-34s %9.3f %9.3f %9llu %8llu %8llu %10.2e %10.2e %10.2e %10.2e %9.2f%s\n", set[k].label,
               r.seconds, r.cpu, (unsigned long long)r.steps, (unsigned long long)r.events,
               (unsigned long long)r.rejected, sqrt(s2), mx, r.gap, serr, t_paper5 > 0 ? t_paper5 / r.cpu : 0.0,
               rc ? "  FAILED" : "");
        if (csv)
            fprintf(csv, "%s,%.6f,%.6f,%llu,%llu,%llu,%.6e,%.6e,%.6e,%.6e\n", set[k].label, r.seconds, r.cpu,
                    (unsigned long long)r.steps, (unsigned long long)r.events, (unsigned long long)r.rejected,
                    sqrt(s2), mx, r.gap, serr);
        fflush(stdout);
        free(r.x);
        r.x = NULL;
        r.rms = sqrt(s2);
        r.maxdx = mx;
        r.stress_err = serr;
        keep[k] = r;
    }
    /* summary: for each paper setting the fastest setting at least as accurate */
    for (size_t p = 0; p < nset; ++p) {
        if (strncmp(set[p].label, "paper", 5) || keep[p].rc) continue;
        size_t best = nset;
        for (size_t k = 0; k < nset; ++k) {
            if (k == p || !strncmp(set[k].label, "paper", 5) || keep[k].rc) continue;
            if (keep[k].rms <= keep[p].rms && keep[k].gap <= keep[p].gap && keep[k].stress_err <= keep[p].stress_err &&
                (best == nset || keep[k].cpu < keep[best].cpu))
                best = k;
        }
        if (best == nset) printf("# %s: no other setting is at least as accurate in all three errors\n", set[p].label);
        else
            printf("# %s (%.2f s CPU): fastest at least as accurate: %s, %.2f s CPU, speed ratio %.1f\n",
                   set[p].label, keep[p].cpu, set[best].label, keep[best].cpu, keep[p].cpu / keep[best].cpu);
    }
    /* the library's default settings against paper mode at equal or better
     * accuracy: a paper setting that is no more accurate than the defaults in
     * any of the three errors gives a measured lower bound of the ratio at
     * equal accuracy (paper mode would need a smaller dt, hence more time, to
     * match); the dt at which paper mode would match, from power laws fitted
     * to the paper rows (error ~ dt^a, time ~ dt^-b), gives an estimate */
    size_t kd = nset;
    for (size_t k = 0; k < nset; ++k)
        if (set[k].defaults && !keep[k].rc) kd = k;
    if (kd < nset) {
        const result *D = &keep[kd];
        printf("# default settings (heun tol 1e-6, correction every step, dt 1e-3, solver %s): %.2f s CPU; "
               "rms %.2e, gap %.2e, stress %.2e\n", solver, D->cpu, D->rms, D->gap, D->stress_err);
        double best_lb = 0.0;
        size_t kb = nset;
        double lx[4], le[3][4], lt[4];
        int np = 0;
        for (size_t p = 0; p < nset; ++p) {
            if (strncmp(set[p].label, "paper", 5) || keep[p].rc) continue;
            const result *P = &keep[p];
            int worse = P->rms >= D->rms && P->gap >= D->gap && P->stress_err >= D->stress_err;
            printf("#   vs %s (%.2f s CPU): %.1fx faster; paper/default errors: rms %.3g, gap %.3g, stress %.3g; %s\n",
                   set[p].label, P->cpu, P->cpu / D->cpu, P->rms / D->rms, P->gap / D->gap,
                   P->stress_err / D->stress_err,
                   worse ? "defaults at least as accurate in all three" : "paper more accurate in some error");
            if (worse && P->cpu / D->cpu > best_lb) {
                best_lb = P->cpu / D->cpu;
                kb = p;
            }
            if (np < 4) {
                lx[np] = log(set[p].dt);
                le[0][np] = log(P->rms);
                le[1][np] = log(P->gap);
                le[2][np] = log(P->stress_err);
                lt[np] = log(P->cpu);
                np++;
            }
        }
        if (kb < nset)
            printf("# equal or better accuracy: the defaults are at least as accurate as %s and %.1fx faster (measured "
                   "lower bound of the ratio at equal accuracy)\n", set[kb].label, best_lb);
        if (np >= 2) {
            /* least-squares lines in log-log; dt* = the largest dt at which all
             * three fitted paper errors are <= the defaults' */
            double ldt = INFINITY;
            for (int e = 0; e < 3; ++e) {
                double mx = 0, my = 0, sxx = 0, sxy = 0;
                for (int q = 0; q < np; ++q) mx += lx[q] / np, my += le[e][q] / np;
                for (int q = 0; q < np; ++q) sxx += (lx[q] - mx) * (lx[q] - mx), sxy += (lx[q] - mx) * (le[e][q] - my);
                double a = sxy / sxx, c = my - a * mx;
                double target = log(e == 0 ? D->rms : e == 1 ? D->gap : D->stress_err);
                if (a > 0) ldt = fmin(ldt, (target - c) / a);
            }
            double mx = 0, my = 0, sxx = 0, sxy = 0;
            for (int q = 0; q < np; ++q) mx += lx[q] / np, my += lt[q] / np;
            for (int q = 0; q < np; ++q) sxx += (lx[q] - mx) * (lx[q] - mx), sxy += (lx[q] - mx) * (lt[q] - my);
            double b = sxy / sxx, c = my - b * mx;
            if (isfinite(ldt))
                printf("# paper mode would match the defaults in all three errors at dt ~ %.2g (fit of %d paper rows): "
                       "~%.3g s CPU (fit time ~ dt^%.2f), ~%.0fx the defaults (extrapolated)\n", exp(ldt), np,
                       exp(c + b * ldt), b, exp(c + b * ldt) / D->cpu);
        }
    }
    /* plot: rms position error against CPU time */
    {
        const char *labs[32];
        double cpus[32], rmss[32];
        size_t m = 0;
        for (size_t k = 0; k < nset; ++k) {
            if (keep[k].rc) continue;
            labs[m] = set[k].label;
            cpus[m] = keep[k].cpu;
            rmss[m++] = keep[k].rms;
        }
        char note[300];
        snprintf(note, sizeof note, "%.120s; shared machine (load %.1f); reference heun tol 1e-11, corr 1", cpu, la[0]);
        trade_plot(svg, n, gamma, solver, labs, cpus, rmss, m, note);
    }
    if (csv) fclose(csv);
    free(R.x);
    free(rad);
    odhs_system_destroy(sys);
    return 0;
}
