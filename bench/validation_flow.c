/* bench/validation_flow - the paper's Figs. 4 and 5 for docs/validation.md
 * (issue 21): the event-resolved stress signal of 2D shear flow at fixed
 * volume, its jumps at collisions and its relaxation between them, the
 * stress autocorrelation, and a picture of the force network.
 *
 * usage: validation_flow N PHI TRANSIENT WINDOW SEED PREFIX [SEGMENT [SOLVER [INTEGRATOR]]]
 *   N bidisperse discs (radii 0.5 and 0.7, 50:50, 3% polydispersity) at
 *   packing fraction PHI, sheared at rate 1 for TRANSIENT strain (not
 *   measured), then for WINDOW strain with the pre-event stress recorded
 *   (odhs_stepper_set_pre_event_stress) at every step. SEGMENT (default
 *   0.002) is the strain drawn in the signal plot. SOLVER (default auto)
 *   and INTEGRATOR (heun, the default, or euler: the paper's fixed step
 *   1e-3 without drift correction) change the library's defaults.
 * Writes PREFIX_signal.svg (sigma_xy against strain over the segment: the
 * relaxation while a network lasts and the jump at each step's events),
 * PREFIX_dist.svg (distributions of the jumps at collisions and of the
 * drops between collisions, odhs_series_event_split; the autocorrelation
 * of sigma_xy against strain), PREFIX_network.svg (the force network at the
 * end, odhs_svg_write) and PREFIX_steps.csv (one row per step), and prints
 * the table of docs/validation.md.
 *
 * Library defaults: adaptive Heun (tolerance 1e-6, drift correction every
 * step), the auto solver; the scene is compressed from random placement at
 * phi = 0.45 at rate 1 to PHI first.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "bench.h"
#include "../examples/plot.h"

#define CHECK(call)                                                                                  \
    do {                                                                                             \
        int rc_ = (call);                                                                            \
        if (rc_ < 0) {                                                                               \
            fprintf(stderr, "validation_flow: %s: %s (%s)\n", #call, odhs_strerror(rc_),             \
                    st ? odhs_stepper_errmsg(st) : odhs_last_error());                               \
            return 1;                                                                                \
        }                                                                                            \
    } while (0)

typedef struct {
    double g0, g1;       /* strain at the start and end of the step */
    double before, after; /* sigma_xy before and after its events */
    unsigned coll, open;
} step_row;

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return x < y ? -1 : x > y;
}

/* the positive entries of x[0..n-1], divided by scale, into out; returns
 * their number */
static size_t positive_scaled(const double *x, size_t n, double scale, double *out)
{
    size_t m = 0;
    for (size_t k = 0; k < n; ++k)
        if (x[k] > 0.0) out[m++] = x[k] / scale;
    return m;
}

static void add_density(pl_plot *p, int series, const double *x, size_t n, size_t total)
{
    double edges[49], dens[48];
    if (n == 0 || odhs_histogram(x, n, 1e-8, 1.0, 48, 1, edges, dens, NULL, NULL)) return;
    for (int b = 0; b < 48; ++b)
        if (dens[b] > 0.0) pl_point(p, series, sqrt(edges[b] * edges[b + 1]), dens[b] * (double)n / (double)total);
}

int main(int argc, char **argv)
{
    odhs_stepper *st = NULL;
    if (argc < 7) {
        fprintf(stderr, "usage: %s N PHI TRANSIENT WINDOW SEED PREFIX [SEGMENT]\n", argv[0]);
        return 2;
    }
    size_t n = (size_t)atol(argv[1]);
    double phi = atof(argv[2]), transient = atof(argv[3]), window = atof(argv[4]);
    unsigned seed = (unsigned)atoi(argv[5]);
    const char *prefix = argv[6];
    double segment = argc > 7 ? atof(argv[7]) : 0.002;
    const char *solver = argc > 8 ? argv[8] : "auto", *integ = argc > 9 ? argv[9] : "heun";
    int euler = !strcmp(integ, "euler");
    if (!euler && strcmp(integ, "heun")) {
        fprintf(stderr, "validation_flow: integrator heun or euler\n");
        return 2;
    }
    if (n < 16 || !(phi > 0.5 && phi < 0.9) || !(transient >= 0) || !(window > 0) || !(segment > 0)) {
        fprintf(stderr, "validation_flow: bad arguments\n");
        return 2;
    }
    char cpu[128], path[1024];
    bench_cpu_model(cpu, sizeof cpu);
    printf("# validation_flow: 2D bidisperse 1:1.4, N = %zu, phi = %.4f, seed %u, transient %g, window %g\n"
           "# solver %s, integrator %s; machine: %s, OPENBLAS_NUM_THREADS=%s\n",
           n, phi, seed, transient, window, solver, euler ? "euler dt 1e-3, no drift correction" : "adaptive heun", cpu,
           getenv("OPENBLAS_NUM_THREADS") ? getenv("OPENBLAS_NUM_THREADS") : "unset");
    double c0 = bench_cpu();
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    CHECK(odhs_system_create(2, n, &sys));
    CHECK(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, seed));
    CHECK(odhs_system_place_random(sys, 0.45, seed));
    CHECK(odhs_driver_create(&drv));
    CHECK(odhs_solver_create_by_name(solver, &sol));
    CHECK(odhs_driver_set_compression_rate(drv, 1.0));
    CHECK(odhs_stepper_create(sys, drv, sol, &st));
    CHECK(odhs_stepper_run_until_packing_fraction(st, phi));
    CHECK(odhs_driver_set_compression_rate(drv, 0.0));
    CHECK(odhs_driver_set_shear_rate(drv, 1.0));
    if (euler) {
        CHECK(odhs_stepper_set_integrator(st, ODHS_INTEGRATOR_EULER));
        CHECK(odhs_stepper_set_dt(st, 1e-3));
        CHECK(odhs_stepper_set_correction_interval(st, 0));
    }
    double c1 = bench_cpu();
    CHECK(odhs_stepper_run_until_strain(st, transient));
    double c2 = bench_cpu(), g_start;
    CHECK(odhs_stepper_strain(st, &g_start));
    CHECK(odhs_stepper_set_pre_event_stress(st, 1));

    size_t cap = 1 << 16, ns = 0;
    step_row *rows = malloc(cap * sizeof *rows);
    double sig[4], pre[4], g = g_start, sig0;
    CHECK(odhs_stepper_shear_stress(st, &sig0));
    uint64_t coll0, open0, steps0;
    CHECK(odhs_stepper_counts(st, &steps0, &coll0, &open0));
    size_t worst_k = 0;
    double worst_down = 0.0;
    while (g < g_start + window) {
        odhs_step_info info = {.size = sizeof info};
        CHECK(odhs_stepper_step_ex(st, &info));
        if (!info.advanced) continue;
        CHECK(odhs_stepper_stress(st, sig));
        if (odhs_stepper_pre_event_stress(st, pre) != ODHS_OK) {
            fprintf(stderr, "validation_flow: no pre-event stress: %s\n", odhs_stepper_errmsg(st));
            return 1;
        }
        if (ns == cap) rows = realloc(rows, (cap *= 2) * sizeof *rows);
        rows[ns] = (step_row){info.strain_start, info.strain_end, pre[1], sig[1], (unsigned)info.collisions,
                              (unsigned)info.openings};
        if (info.collisions && !info.openings && pre[1] - sig[1] > worst_down * fabs(sig[1])) {
            worst_down = (pre[1] - sig[1]) / fabs(sig[1]);
            worst_k = ns;
        }
        ns++;
        g = info.strain_end;
    }
    double c3 = bench_cpu();
    uint64_t coll1, open1, steps1;
    CHECK(odhs_stepper_counts(st, &steps1, &coll1, &open1));

    /* the per-step table */
    snprintf(path, sizeof path, "%s_steps.csv", prefix);
    FILE *f = fopen(path, "w");
    if (!f) {
        perror(path);
        return 1;
    }
    fprintf(f, "strain_start,strain_end,sigma_before,sigma_after,collisions,openings\n");
    for (size_t k = 0; k < ns; ++k)
        fprintf(f, "%.17g,%.17g,%.17g,%.17g,%u,%u\n", rows[k].g0, rows[k].g1, rows[k].before, rows[k].after,
                rows[k].coll, rows[k].open);
    fclose(f);

    /* jumps at collision steps and drops between them */
    double *bef = malloc(ns * sizeof *bef), *aft = malloc(ns * sizeof *aft), *jumps = malloc(ns * sizeof *jumps),
           *drops = malloc(ns * sizeof *drops), *tmp = malloc(ns * sizeof *tmp), *gaps = malloc(ns * sizeof *gaps);
    unsigned char *ev = malloc(ns);
    size_t nj, nd, ngap = 0;
    double last_g = NAN;
    for (size_t k = 0; k < ns; ++k) {
        bef[k] = rows[k].before;
        aft[k] = rows[k].after;
        ev[k] = rows[k].coll > 0;
        if (ev[k]) {
            if (isfinite(last_g)) gaps[ngap++] = rows[k].g1 - last_g;
            last_g = rows[k].g1;
        }
    }
    if (odhs_series_event_split(bef, aft, ev, ns, jumps, &nj, drops, &nd) || nj < 10) {
        fprintf(stderr, "validation_flow: %zu collision steps: %s\n", nj, odhs_last_error());
        return 1;
    }
    /* sigma_xy on a strain grid: the value after the last step ending at
     * or before each grid point */
    const double dg = 1e-4;
    size_t ngrid = (size_t)(window / dg);
    double *grid = malloc((ngrid + 1) * sizeof *grid);
    size_t k = 0;
    double cur = sig0;
    for (size_t m = 0; m < ngrid; ++m) {
        double gm = g_start + (double)(m + 1) * dg;
        while (k < ns && rows[k].g1 <= gm) cur = rows[k++].after;
        grid[m] = cur;
    }
    odhs_series_stats stats = {.size = sizeof stats};
    if (odhs_series_stats_compute(grid, ngrid, &stats)) {
        fprintf(stderr, "validation_flow: %s\n", odhs_last_error());
        return 1;
    }
    size_t maxlag = ngrid / 4 < 500 ? ngrid / 4 : 500;
    double *rho = malloc((maxlag + 1) * sizeof *rho);
    odhs_series_autocorrelation(grid, ngrid, maxlag, rho);
    double mean = stats.mean;

    /* summary */
    size_t npos_j = 0, npos_d = 0;
    double sum_j = 0.0, sum_d = 0.0;
    for (size_t m = 0; m < nj; ++m) {
        npos_j += jumps[m] > 0.0;
        sum_j += jumps[m];
    }
    for (size_t m = 0; m < nd; ++m) {
        npos_d += drops[m] > 0.0;
        sum_d += drops[m];
    }
    memcpy(tmp, jumps, nj * sizeof *tmp);
    qsort(tmp, nj, sizeof *tmp, cmp_double);
    double med_j = tmp[nj / 2];
    memcpy(tmp, drops, nd * sizeof *tmp);
    qsort(tmp, nd, sizeof *tmp, cmp_double);
    double med_d = nd ? tmp[nd / 2] : NAN;
    double mean_gap = 0.0;
    for (size_t m = 0; m < ngap; ++m) mean_gap += gaps[m] / (double)ngap;
    printf("steps in the window              %zu (%llu collisions, %llu openings)\n", ns,
           (unsigned long long)(coll1 - coll0), (unsigned long long)(open1 - open0));
    printf("collisions per unit strain       %.0f\n", (double)(coll1 - coll0) / window);
    printf("sigma_xy                         %.4f +- %.4f (block averaging, plateau %d)\n", mean,
           stats.sem, stats.plateau);
    printf("correlation strain (tau_int dg)  %.2e\n", stats.tau_int * dg);
    printf("collision steps                  %zu, jump > 0 in %zu (%.4f); largest fall %.2e of sigma (step %zu)\n",
           nj, npos_j, (double)npos_j / (double)nj, worst_down, worst_k);
    printf("jump / <sigma>                   mean %.3e, median %.3e\n", sum_j / (double)nj / mean, med_j / mean);
    printf("drop / <sigma> between collisions mean %.3e, median %.3e, positive in %.4f\n",
           nd ? sum_d / (double)nd / mean : NAN, med_d / mean, nd ? (double)npos_d / (double)nd : NAN);
    {
        /* the small jumps: p(x) ~ x^a below 1e-4 of the mean stress */
        size_t mj = positive_scaled(jumps, nj, mean, tmp), used = 0;
        double a = NAN, ae = NAN;
        if (odhs_power_law_exponent(tmp, mj, 1e-4, &a, &ae, &used)) a = ae = NAN;
        printf("small jumps (x = jump/<sigma> <= 1e-4) p(x) ~ x^a, a = %.3f +- %.3f (%zu jumps)\n", a, ae, used);
    }
    memcpy(tmp, gaps, ngap * sizeof *tmp);
    qsort(tmp, ngap, sizeof *tmp, cmp_double);
    printf("strain between collisions        mean %.3e, median %.3e (N x mean = %.3f)\n", mean_gap,
           ngap ? tmp[ngap / 2] : NAN, (double)n * mean_gap);
    printf("CPU s                            compression %.1f, transient %.1f, window %.1f (%.0f per unit strain "
           "with the record)\n",
           c1 - c0, c2 - c1, c3 - c2, (c3 - c2) / window);

    /* the signal over the segment */
    pl_plot p;
    char title[200];
    snprintf(title, sizeof title, "Stress against strain, 2D N = %zu, phi = %.3f (the paper's Fig. 4)", n, phi);
    pl_init(&p, title, "strain", "shear stress sigma_xy (gammadot/xi0)", 0, 0);
    int s_sig = pl_series_add(&p, "sigma_xy", 0, 0, 0);
    int s_col = pl_series_add(&p, "collision", 1, 0, 1);
    pl_point(&p, s_sig, g_start, sig0);
    for (size_t m = 0; m < ns && rows[m].g1 <= g_start + segment; ++m) {
        pl_point(&p, s_sig, rows[m].g1, rows[m].before);
        pl_point(&p, s_sig, rows[m].g1, rows[m].after);
        if (rows[m].coll) pl_point(&p, s_col, rows[m].g1, rows[m].after);
    }
    p.s[s_col].lines = 0;
    char note[200];
    snprintf(note, sizeof note, "bench/validation_flow %zu %g %g %g %u; %s, %s; %.60s", n, phi, transient, window, seed,
             solver, integ, cpu);
    pl_note(&p, note);
    snprintf(path, sizeof path, "%s_signal.svg", prefix);
    pl_write_svg(&p, path);
    pl_free(&p);

    /* the distributions and the autocorrelation */
    pl_plot q, r;
    snprintf(title, sizeof title, "Stress jumps at collisions and drops between them, N = %zu, phi = %.3f", n, phi);
    pl_init(&q, title, "|change| / <sigma_xy>", "probability density", 1, 1);
    int s_j = pl_series_add(&q, "jumps at collisions", 1, 0, 1);
    int s_d = pl_series_add(&q, "drops between collisions", 0, 0, 2);
    size_t m1 = positive_scaled(jumps, nj, mean, tmp);
    add_density(&q, s_j, tmp, m1, nj);
    size_t m2 = positive_scaled(drops, nd, mean, tmp);
    add_density(&q, s_d, tmp, m2, nd);
    pl_note(&q, note);
    pl_init(&r, "Autocorrelation of sigma_xy", "strain lag", "rho", 0, 0);
    int s_r = pl_series_add(&r, "rho(strain lag)", 0, 0, 0);
    for (size_t m = 0; m <= maxlag; ++m) pl_point(&r, s_r, (double)m * dg, rho[m]);
    const pl_plot *panels[2] = {&q, &r};
    snprintf(path, sizeof path, "%s_dist.svg", prefix);
    pl_write_svg_panels(panels, 2, path);
    pl_free(&q);
    pl_free(&r);

    /* the force network (Fig. 5) */
    snprintf(path, sizeof path, "%s_network.svg", prefix);
    CHECK(odhs_svg_write(sys, odhs_stepper_network(st), NULL, path));

    free(rows), free(bef), free(aft), free(jumps), free(drops), free(tmp), free(gaps), free(ev), free(grid),
        free(rho);
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    return 0;
}
