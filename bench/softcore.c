/* bench/softcore - the soft-core reference models against the event-driven
 * core (issue "Soft-core reference models of the thesis").
 *
 * One start: N = 100 2D 50:50 bidisperse discs (radii 0.5/0.7, no
 * polydispersity), random placement at phi = 0.45, event-driven compression
 * to phi = 0.82, drift correction. Units: k_e = 1, k_d = 1 = 1/xi0, small
 * diameter 1, so tau_e = k_d d_min^2 / k_e = 1 and the event-driven stress
 * at unit shear rate is directly comparable with sigma_soft / gammadot.
 *
 *  A. The paper's Fig. 6 protocol: quasistatic shear with strain steps
 *     DGA (1e-6) and steepest descent to max |grad U| < 1e-9, against the
 *     event-driven trajectory (adaptive Heun, tol 1e-10, dense solver) up to
 *     strain GA: rms position difference and relative stress difference
 *     against strain. The same with FIRE and CG as minimisers (the inertial
 *     path question), and steepest descent with dgamma = 1e-5.
 *  B. RD0 at gammadot tau_e = 1e-4 ... 1e-8 up to strain GB: position
 *     difference relative to the rms non-affine displacement of the
 *     event-driven trajectory, and the stress difference.
 *  C. Cost at equal accuracy: wall time of the event-driven core (Euler,
 *     the paper's scheme, at several dt), RD0 and quasistatic SD to strain GB
 *     with their errors; ratios at the 1% accuracy level.
 *  D. Viscosities sigma_xy / gammadot of RD0 and CD0 (k_0 = 1e-3) below
 *     jamming (phi = 0.78) against rate, and of the massive CD_n model
 *     (m = 1): Newtonian (sigma ~ gammadot) against Bagnold (sigma ~
 *     gammadot^2).
 *
 *  A2 ("softcore inertial" runs only this): one affine strain step, then
 *     SD, FIRE and CG from the same overlapped state; distance between the
 *     minima relative to the SD relaxation displacement.
 *
 * Writes SVG plots into OUTDIR (default docs/results).
 *
 * usage: softcore [GA] [GB] [OUTDIR]   (defaults 0.002, 0.005, docs/results)
 *        softcore inertial
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"
#include "odhs.h"

#define N 100
#define NS 10 /* samples along a trajectory */

#define C(x)                                                                                   \
    do {                                                                                       \
        int r_ = (x);                                                                          \
        if (r_ < 0) {                                                                          \
            fprintf(stderr, "%s:%d: %s -> %d (%s)\n", __FILE__, __LINE__, #x, r_, odhs_strerror(r_)); \
            exit(1);                                                                           \
        }                                                                                      \
    } while (0)

/* ---- a tiny SVG line plot ------------------------------------------------------ */
typedef struct {
    const char *label;
    const double *x, *y;
    int n;
} series;

static void svg_plot(const char *path, const char *title, const char *xl, const char *yl, int logx, int logy,
                     const series *s, int ns)
{
    FILE *f = fopen(path, "w");
    if (!f) return;
    const double W = 640, H = 420, ml = 80, mr = 170, mt = 40, mb = 60;
    double x0 = INFINITY, x1 = -INFINITY, y0 = INFINITY, y1 = -INFINITY;
    for (int k = 0; k < ns; ++k)
        for (int i = 0; i < s[k].n; ++i) {
            double x = logx ? log10(s[k].x[i]) : s[k].x[i], y = logy ? log10(s[k].y[i]) : s[k].y[i];
            if (!isfinite(x) || !isfinite(y)) continue;
            x0 = fmin(x0, x);
            x1 = fmax(x1, x);
            y0 = fmin(y0, y);
            y1 = fmax(y1, y);
        }
    if (!(x1 > x0)) x1 = x0 + 1;
    if (!(y1 > y0)) y1 = y0 + 1;
    double py = 0.05 * (y1 - y0);
    y0 -= py;
    y1 += py;
    fprintf(f, "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%g\" height=\"%g\" font-family=\"sans-serif\" font-size=\"12\">\n", W, H);
    fprintf(f, "<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n");
    fprintf(f, "<text x=\"%g\" y=\"22\" text-anchor=\"middle\" font-size=\"14\">%s</text>\n", (W - mr + ml) / 2, title);
    double pw = W - ml - mr, ph = H - mt - mb;
    fprintf(f, "<rect x=\"%g\" y=\"%g\" width=\"%g\" height=\"%g\" fill=\"none\" stroke=\"black\"/>\n", ml, mt, pw, ph);
    for (int t = 0; t <= 4; ++t) {
        double fx = x0 + (x1 - x0) * t / 4, fy = y0 + (y1 - y0) * t / 4;
        double X = ml + pw * t / 4, Y = mt + ph - ph * t / 4;
        fprintf(f, "<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"#ddd\"/>\n", X, mt, X, mt + ph);
        fprintf(f, "<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"#ddd\"/>\n", ml, Y, ml + pw, Y);
        fprintf(f, "<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">%.3g</text>\n", X, mt + ph + 16, logx ? pow(10, fx) : fx);
        fprintf(f, "<text x=\"%g\" y=\"%g\" text-anchor=\"end\">%.3g</text>\n", ml - 4, Y + 4, logy ? pow(10, fy) : fy);
    }
    fprintf(f, "<text x=\"%g\" y=\"%g\" text-anchor=\"middle\">%s</text>\n", ml + pw / 2, H - 18, xl);
    fprintf(f, "<text x=\"16\" y=\"%g\" text-anchor=\"middle\" transform=\"rotate(-90 16 %g)\">%s</text>\n", mt + ph / 2,
            mt + ph / 2, yl);
    const char *col[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd", "#8c564b", "#e377c2"};
    for (int k = 0; k < ns; ++k) {
        fprintf(f, "<polyline fill=\"none\" stroke=\"%s\" stroke-width=\"1.8\" points=\"", col[k % 7]);
        for (int i = 0; i < s[k].n; ++i) {
            double x = logx ? log10(s[k].x[i]) : s[k].x[i], y = logy ? log10(s[k].y[i]) : s[k].y[i];
            if (!isfinite(x) || !isfinite(y)) continue;
            fprintf(f, "%.2f,%.2f ", ml + pw * (x - x0) / (x1 - x0), mt + ph - ph * (y - y0) / (y1 - y0));
        }
        fprintf(f, "\"/>\n");
        for (int i = 0; i < s[k].n; ++i) {
            double x = logx ? log10(s[k].x[i]) : s[k].x[i], y = logy ? log10(s[k].y[i]) : s[k].y[i];
            if (!isfinite(x) || !isfinite(y)) continue;
            fprintf(f, "<circle cx=\"%.2f\" cy=\"%.2f\" r=\"2.5\" fill=\"%s\"/>\n", ml + pw * (x - x0) / (x1 - x0),
                    mt + ph - ph * (y - y0) / (y1 - y0), col[k % 7]);
        }
        fprintf(f, "<line x1=\"%g\" y1=\"%g\" x2=\"%g\" y2=\"%g\" stroke=\"%s\" stroke-width=\"2\"/>\n", W - mr + 10,
                mt + 10 + 18 * k, W - mr + 30, mt + 10 + 18 * k, col[k % 7]);
        fprintf(f, "<text x=\"%g\" y=\"%g\">%s</text>\n", W - mr + 35, mt + 14 + 18 * k, s[k].label);
    }
    fprintf(f, "</svg>\n");
    fclose(f);
}

/* ---- geometry helpers --------------------------------------------------------------- */
static void min_image(const double *L, double g, double *d)
{
    double ny = nearbyint(d[1] / L[1]);
    d[1] -= ny * L[1];
    d[0] -= ny * g * L[1];
    d[0] -= nearbyint(d[0] / L[0]) * L[0];
}

/* rms minimum-image difference of two position sets in the box of sys */
static double rms_diff(const odhs_system *sys, const double *a, const double *b)
{
    double L[2], g, s = 0.0;
    odhs_system_get_box(sys, L);
    odhs_system_get_strain(sys, &g);
    for (int i = 0; i < N; ++i) {
        double d[2] = {b[2 * i] - a[2 * i], b[2 * i + 1] - a[2 * i + 1]};
        min_image(L, g, d);
        s += d[0] * d[0] + d[1] * d[1];
    }
    return sqrt(s / N);
}

/* rms non-affine displacement of x (at accumulated strain gam) from x0 */
static double rms_nonaffine(const odhs_system *sys, const double *x0, const double *x, double gam)
{
    double L[2], g, s = 0.0;
    odhs_system_get_box(sys, L);
    odhs_system_get_strain(sys, &g);
    for (int i = 0; i < N; ++i) {
        double d[2] = {x[2 * i] - x0[2 * i] - gam * x0[2 * i + 1], x[2 * i + 1] - x0[2 * i + 1]};
        min_image(L, g, d);
        s += d[0] * d[0] + d[1] * d[1];
    }
    return sqrt(s / N);
}

static odhs_system *start_state(double phi, uint64_t seed)
{
    odhs_system *sys;
    C(odhs_system_create(2, N, &sys));
    C(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.0, seed));
    C(odhs_system_place_random(sys, 0.45, seed));
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
    C(odhs_driver_create(&drv));
    C(odhs_driver_set_compression_rate(drv, 1.0));
    C(odhs_solver_create_by_name("dense", &sol));
    C(odhs_stepper_create(sys, drv, sol, &st));
    C(odhs_stepper_run_until_packing_fraction(st, phi));
    C(odhs_stepper_correct(st));
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_driver_destroy(drv);
    return sys;
}

/* event-driven run from start to NS sample strains in (0, G]: positions and
 * sigma_xy at each; returns wall time */
static double run_ed(const odhs_system *start, double G, int integ, double dt, double tol, double *X, double *S,
                     uint64_t *events)
{
    odhs_system *sys;
    C(odhs_system_clone(start, &sys));
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
    C(odhs_driver_create(&drv));
    C(odhs_driver_set_shear_rate(drv, 1.0));
    C(odhs_solver_create_by_name("dense", &sol));
    C(odhs_stepper_create(sys, drv, sol, &st));
    C(odhs_stepper_set_integrator(st, integ));
    C(odhs_stepper_set_dt(st, dt));
    if (integ == ODHS_INTEGRATOR_HEUN) {
        C(odhs_stepper_set_tolerance(st, tol));
        C(odhs_stepper_set_correction_interval(st, 1));
    }
    double t = bench_wall();
    for (int k = 1; k <= NS; ++k) {
        C(odhs_stepper_run_until_strain(st, G * k / NS));
        double sig[4];
        C(odhs_stepper_stress(st, sig));
        S[k - 1] = sig[1];
        C(odhs_system_get_positions(sys, X + (size_t)(k - 1) * 2 * N));
    }
    t = bench_wall() - t;
    uint64_t nc, no;
    odhs_stepper_counts(st, NULL, &nc, &no);
    if (events) *events = nc + no;
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    return t;
}

/* soft-core run: qs = 0 time stepping at rate, else quasistatic steps dg */
static double run_soft(const odhs_system *start, double G, int model, int qs, int minimiser, double rate, double dg,
                       double *X, double *S, uint64_t *work)
{
    odhs_system *sys;
    C(odhs_system_clone(start, &sys));
    odhs_softcore *sc;
    C(odhs_softcore_create(sys, &sc));
    C(odhs_softcore_set_model(sc, model));
    C(odhs_softcore_set_minimiser(sc, minimiser));
    C(odhs_softcore_set_min_tolerance(sc, 1e-9, 1000000000u));
    if (!qs) C(odhs_softcore_set_shear_rate(sc, rate));
    double t = bench_wall(), done = 0.0;
    for (int k = 1; k <= NS; ++k) {
        double target = G * k / NS, sig[4];
        if (qs) {
            while (done < target - 1e-12) {
                double step = fmin(dg, target - done);
                C(odhs_softcore_quasistatic_step(sc, step, NULL));
                done += step;
            }
            if (minimiser == ODHS_SOFTCORE_SD) {
                C(odhs_softcore_relaxation_stress(sc, sig));
                S[k - 1] = sig[1];
            } else {
                S[k - 1] = NAN;
            }
        } else {
            C(odhs_softcore_run_until_strain(sc, target));
            C(odhs_softcore_stress(sc, ODHS_SOFTCORE_STRESS_TOTAL, sig));
            S[k - 1] = sig[1] / rate;
        }
        C(odhs_system_get_positions(sys, X + (size_t)(k - 1) * 2 * N));
    }
    t = bench_wall() - t;
    uint64_t steps, fe, mi;
    odhs_softcore_counts(sc, &steps, &fe, &mi);
    if (work) *work = fe;
    odhs_softcore_destroy(sc);
    odhs_system_destroy(sys);
    return t;
}

/* errors of a run against the reference: max over samples of the rms
 * position difference divided by the rms non-affine displacement of the
 * reference at the end, and the max relative stress difference */
static void errors(const odhs_system *start, double G, const double *Xr, const double *Sr, const double *X,
                   const double *S, double *perr, double *serr, double *pabs, double *pos_k, double *str_k)
{
    double x0[2 * N];
    C(odhs_system_get_positions(start, x0));
    double pe = 0.0, se = 0.0, pa = 0.0, L[2], na_end = 1.0;
    C(odhs_system_get_box(start, L));
    for (int k = 0; k < NS; ++k) {
        /* the box strain at sample k for the minimum image */
        double gam = G * (k + 1) / NS;
        /* a particle-free system of the same box carries the strain */
        odhs_system *bare;
        C(odhs_system_create(2, 1, &bare));
        C(odhs_system_set_box(bare, L));
        C(odhs_system_set_strain(bare, gam));
        double na = rms_nonaffine(bare, x0, Xr + (size_t)k * 2 * N, gam);
        double d = rms_diff(bare, Xr + (size_t)k * 2 * N, X + (size_t)k * 2 * N);
        odhs_system_destroy(bare);
        if (pos_k) pos_k[k] = d;
        if (k == NS - 1) na_end = na;
        if (d > pe) pe = d;
        if (d > pa) pa = d;
        double sr = isfinite(S[k]) ? fabs(S[k] - Sr[k]) / fabs(Sr[k]) : NAN;
        if (str_k) str_k[k] = sr;
        if (isfinite(sr) && sr > se) se = sr;
    }
    *perr = pe / na_end;
    *serr = se;
    if (pabs) *pabs = pa;
}

/* average sigma_xy/gammadot over strain [0.4 G, G] of a soft-core run */
static double viscosity(const odhs_system *start, int model, double rate, double G, double *secs)
{
    odhs_system *sys;
    C(odhs_system_clone(start, &sys));
    odhs_softcore *sc;
    C(odhs_softcore_create(sys, &sc));
    C(odhs_softcore_set_model(sc, model));
    C(odhs_softcore_set_shear_rate(sc, rate));
    double t = bench_wall(), sum = 0.0;
    int cnt = 0;
    const int K = 60;
    for (int k = 1; k <= K; ++k) {
        C(odhs_softcore_run_until_strain(sc, G * k / K));
        if (k > 0.4 * K) {
            double sig[4];
            C(odhs_softcore_stress(sc, ODHS_SOFTCORE_STRESS_TOTAL, sig));
            sum += sig[1];
            cnt++;
        }
    }
    if (secs) *secs = bench_wall() - t;
    odhs_softcore_destroy(sc);
    odhs_system_destroy(sys);
    return sum / cnt / rate;
}

/* A2: one affine step dg from the start, then SD, FIRE and CG from the same
 * overlapped state: how far apart do the minima lie, relative to the
 * steepest-descent (overdamped) relaxation displacement? */
static void inertial_paths(const odhs_system *start)
{
    printf("\n## A2. one strain step dgamma, then minimisation to max|grad U| < 1e-9 from the same state\n");
    printf("%-10s %12s %12s %14s %14s %10s %10s %10s\n", "dgamma", "rms_relax_SD", "rms_FIRE-SD", "FIRE-SD/relax",
           "CG-SD/relax", "t_SD_s", "t_FIRE_s", "t_CG_s");
    double dgs[3] = {1e-5, 1e-4, 1e-3};
    int mins[3] = {ODHS_SOFTCORE_SD, ODHS_SOFTCORE_FIRE, ODHS_SOFTCORE_CG};
    for (int q = 0; q < 3; ++q) {
        double X[3][2 * N], Xa[2 * N], t[3];
        for (int m = 0; m < 3; ++m) {
            odhs_system *sys;
            C(odhs_system_clone(start, &sys));
            odhs_softcore *sc;
            C(odhs_softcore_create(sys, &sc));
            C(odhs_softcore_set_min_tolerance(sc, 1e300, 1)); /* affine only */
            C(odhs_softcore_quasistatic_step(sc, dgs[q], NULL));
            if (m == 0) C(odhs_system_get_positions(sys, Xa));
            C(odhs_softcore_set_minimiser(sc, mins[m]));
            C(odhs_softcore_set_min_tolerance(sc, 1e-9, 1000000000u));
            double t0 = bench_wall();
            C(odhs_softcore_minimise(sc, NULL));
            t[m] = bench_wall() - t0;
            C(odhs_system_get_positions(sys, X[m]));
            odhs_softcore_destroy(sc);
            odhs_system_destroy(sys);
        }
        odhs_system *bare;
        double L[2];
        C(odhs_system_get_box(start, L));
        C(odhs_system_create(2, 1, &bare));
        C(odhs_system_set_box(bare, L));
        C(odhs_system_set_strain(bare, dgs[q]));
        double relax = rms_diff(bare, Xa, X[0]), df = rms_diff(bare, X[0], X[1]), dc = rms_diff(bare, X[0], X[2]);
        odhs_system_destroy(bare);
        printf("%-10.0e %12.3e %12.3e %14.3e %14.3e %10.2f %10.2f %10.2f\n", dgs[q], relax, df, df / relax, dc / relax,
               t[0], t[1], t[2]);
    }
}

int main(int argc, char **argv)
{
    if (argc > 1 && !strcmp(argv[1], "inertial")) {
        setvbuf(stdout, NULL, _IONBF, 0);
        odhs_system *s = start_state(0.82, 7);
        inertial_paths(s);
        odhs_system_destroy(s);
        return 0;
    }
    double GA = argc > 1 ? atof(argv[1]) : 0.002, GB = argc > 2 ? atof(argv[2]) : 0.005;
    const char *outdir = argc > 3 ? argv[3] : "docs/results";
    char cpu[256], path[512];
    bench_cpu_model(cpu, sizeof cpu);
    setvbuf(stdout, NULL, _IONBF, 0);
    printf("# bench/softcore  machine: %s (2 cores shared with other jobs: timings under load)\n", cpu);
    printf("# N = %d 2D bidisperse 1:1.4, phi = 0.82, k_e = k_d = 1 (tau_e = 1), GA = %g, GB = %g\n", N, GA, GB);
    odhs_system *start = start_state(0.82, 7);
    static double Xr[NS * 2 * N], Sr[NS], X[NS * 2 * N], S[NS];
    double strain_k[NS];
    for (int k = 0; k < NS; ++k) strain_k[k] = GA * (k + 1) / NS;

    /* ---- A: Fig. 6 protocol ---- */
    uint64_t ev;
    double ted = run_ed(start, GA, ODHS_INTEGRATOR_HEUN, 1e-3, 1e-10, Xr, Sr, &ev);
    printf("\n## A. quasistatic shear against the event-driven trajectory, strain 0..%g\n", GA);
    printf("event-driven reference (Heun tol 1e-10, dense): %.2f s, %llu events\n", ted, (unsigned long long)ev);
    printf("%-22s %10s %12s %14s %14s %12s\n", "route", "wall_s", "force_evals", "max_rms_dx", "dx/nonaffine",
           "max_dsigma");
    struct {
        const char *label;
        int minimiser;
        double dg;
    } qa[] = {{"SD dgamma=1e-6", ODHS_SOFTCORE_SD, 1e-6},
              {"SD dgamma=1e-5", ODHS_SOFTCORE_SD, 1e-5},
              {"FIRE dgamma=1e-6", ODHS_SOFTCORE_FIRE, 1e-6},
              {"CG dgamma=1e-6", ODHS_SOFTCORE_CG, 1e-6}};
    static double posA[4][NS], strA[4][NS];
    double t_sd6 = 0.0;
    for (int q = 0; q < 4; ++q) {
        uint64_t w;
        double t = run_soft(start, GA, ODHS_SOFTCORE_RD0, 1, qa[q].minimiser, 0.0, qa[q].dg, X, S, &w);
        if (q == 0) t_sd6 = t;
        double pe, se, pa;
        errors(start, GA, Xr, Sr, X, S, &pe, &se, &pa, posA[q], strA[q]);
        printf("%-22s %10.2f %12llu %14.3e %14.3e %12.3e\n", qa[q].label, t, (unsigned long long)w, pa, pe, se);
    }
    printf("per-sample (strain, rms dx SD 1e-6, rel dsigma SD 1e-6, rms dx FIRE, rms dx CG, ED sigma_xy):\n");
    for (int k = 0; k < NS; ++k)
        printf("  %.5f %.3e %.3e %.3e %.3e %.6f\n", strain_k[k], posA[0][k], strA[0][k], posA[2][k], posA[3][k], Sr[k]);
    {
        series s[4];
        for (int q = 0; q < 4; ++q) s[q] = (series){qa[q].label, strain_k, posA[q], NS};
        snprintf(path, sizeof path, "%s/softcore_fig6_positions.svg", outdir);
        svg_plot(path, "Quasistatic vs event-driven: positions", "strain", "rms position difference (d_small)", 0, 1, s, 4);
        series t2[2] = {{"SD dgamma=1e-6", strain_k, strA[0], NS}, {"SD dgamma=1e-5", strain_k, strA[1], NS}};
        snprintf(path, sizeof path, "%s/softcore_fig6_stress.svg", outdir);
        svg_plot(path, "Quasistatic SD vs event-driven: stress", "strain", "|sigma_SD - sigma_ED| / sigma_ED", 0, 1, t2, 2);
    }

    /* ---- B and C ---- */
    static double XrB[NS * 2 * N], SrB[NS];
    double tref = run_ed(start, GB, ODHS_INTEGRATOR_HEUN, 1e-3, 1e-10, XrB, SrB, &ev);
    printf("\n## B. RD0 against the event-driven trajectory, strain 0..%g (reference %.2f s, %llu events)\n", GB, tref,
           (unsigned long long)ev);
    printf("%-12s %10s %12s %14s %14s %12s\n", "rate*tau_e", "wall_s", "steps", "max_rms_dx", "dx/nonaffine",
           "max_dsigma");
    double rates[5] = {1e-4, 1e-5, 1e-6, 1e-7, 1e-8}, rpe[5], rse[5], rt[5];
    for (int q = 0; q < 5; ++q) {
        uint64_t w;
        rt[q] = run_soft(start, GB, ODHS_SOFTCORE_RD0, 0, 0, rates[q], 0, X, S, &w);
        double pa;
        errors(start, GB, XrB, SrB, X, S, &rpe[q], &rse[q], &pa, NULL, NULL);
        printf("%-12.0e %10.2f %12llu %14.3e %14.3e %12.3e\n", rates[q], rt[q], (unsigned long long)w, pa, rpe[q], rse[q]);
    }
    /* rate for 1% and 0.1% of the non-affine displacement (log-log interpolation) */
    for (int lev = 0; lev < 2; ++lev) {
        double target = lev ? 1e-3 : 1e-2, r = NAN;
        for (int q = 0; q + 1 < 5; ++q)
            if (rpe[q] > target && rpe[q + 1] <= target) {
                double a = log(rpe[q]), b = log(rpe[q + 1]);
                double f = (log(target) - a) / (b - a);
                r = exp(log(rates[q]) + f * (log(rates[q + 1]) - log(rates[q])));
            }
        printf("RD0 matches the event-driven positions to %g of the non-affine displacement at rate*tau_e ~ %.2g\n",
               target, r);
    }
    {
        series s[2] = {{"positions/nonaffine", rates, rpe, 5}, {"stress (rel.)", rates, rse, 5}};
        snprintf(path, sizeof path, "%s/softcore_rd0_convergence.svg", outdir);
        svg_plot(path, "RD0 -> event-driven as the rate decreases", "gammadot tau_e", "max relative difference", 1, 1, s, 2);
    }

    printf("\n## C. cost at equal accuracy, strain 0..%g\n", GB);
    printf("%-26s %10s %14s %12s\n", "route", "wall_s", "dx/nonaffine", "max_dsigma");
    double edt[3] = {1e-2, 1e-3, 1e-4}, t_ed1 = NAN, e_ed1 = NAN;
    for (int q = 0; q < 3; ++q) {
        double t = run_ed(start, GB, ODHS_INTEGRATOR_EULER, edt[q], 0, X, S, NULL), pe, se;
        errors(start, GB, XrB, SrB, X, S, &pe, &se, NULL, NULL, NULL);
        printf("event-driven Euler dt=%-5.0e %10.3f %14.3e %12.3e\n", edt[q], t, pe, se);
        if (pe <= 1e-2 && isnan(t_ed1)) {
            t_ed1 = t;
            e_ed1 = pe;
        }
    }
    double t_rd1 = NAN, e_rd1 = NAN;
    for (int q = 0; q < 5; ++q)
        if (rpe[q] <= 1e-2 && isnan(t_rd1)) {
            t_rd1 = rt[q];
            e_rd1 = rpe[q];
            printf("RD0 rate*tau_e=%-11.0e %10.3f %14.3e %12.3e\n", rates[q], rt[q], rpe[q], rse[q]);
        }
    double t_qs1 = NAN, e_qs1 = NAN;
    double qdg[2] = {1e-4, 1e-5};
    for (int q = 0; q < 2; ++q) {
        double t = run_soft(start, GB, ODHS_SOFTCORE_RD0, 1, ODHS_SOFTCORE_SD, 0, qdg[q], X, S, NULL), pe, se;
        errors(start, GB, XrB, SrB, X, S, &pe, &se, NULL, NULL, NULL);
        printf("quasistatic SD dgamma=%-4.0e %10.3f %14.3e %12.3e\n", qdg[q], t, pe, se);
        if (pe <= 1e-2 && isnan(t_qs1)) {
            t_qs1 = t;
            e_qs1 = pe;
        }
    }
    printf("quasistatic SD dgamma=1e-6 (Fig. 6 setting), extrapolated from A: %.1f s for strain %g\n", t_sd6 * GB / GA, GB);
    printf("at <= 1%% of the non-affine displacement: event-driven %.3f s (err %.2g), RD0 %.3f s (err %.2g), "
           "QS-SD %.3f s (err %.2g)\n",
           t_ed1, e_ed1, t_rd1, e_rd1, t_qs1, e_qs1);
    printf("ratios: RD0/ED = %.3g, QS-SD/ED = %.3g, QS-SD(1e-6, Fig. 6 setting)/ED = %.3g\n", t_rd1 / t_ed1,
           t_qs1 / t_ed1, t_sd6 * GB / GA / t_ed1);

    /* ---- D: viscosities ---- */
    printf("\n## D. viscosity sigma_xy/gammadot (strain 0..0.05, average over 0.02..0.05), phi = 0.78\n");
    odhs_system *s78 = start_state(0.78, 11);
    double vr[4] = {1e-2, 1e-3, 1e-4, 1e-5}, eta_rd[4], eta_cd[4];
    printf("%-12s %12s %12s %10s %10s\n", "rate*tau_e", "eta_RD0", "eta_CD0", "t_RD0_s", "t_CD0_s");
    for (int q = 0; q < 4; ++q) {
        double t1, t2;
        eta_rd[q] = viscosity(s78, ODHS_SOFTCORE_RD0, vr[q], 0.05, &t1);
        eta_cd[q] = viscosity(s78, ODHS_SOFTCORE_CD0, vr[q], 0.05, &t2);
        printf("%-12.0e %12.4f %12.4f %10.2f %10.2f\n", vr[q], eta_rd[q], eta_cd[q], t1, t2);
    }
    double mr[8] = {1e-1, 3e-2, 1e-2, 3e-3, 1e-3, 3e-4, 1e-4, 3e-5}, eta_cdn[8];
    printf("CD_n (m = 1, k_d = 1: damping time m/k_d = tau_e):\n%-12s %12s %12s %10s\n", "rate*tau_e", "eta_CDn",
           "sigma_xy", "t_s");
    for (int q = 0; q < 8; ++q) {
        double t;
        eta_cdn[q] = viscosity(s78, ODHS_SOFTCORE_CDN, mr[q], 0.05, &t);
        printf("%-12.0e %12.4f %12.4e %10.2f\n", mr[q], eta_cdn[q], eta_cdn[q] * mr[q], t);
    }
    {
        series s[2] = {{"RD0", vr, eta_rd, 4}, {"CD0 (k0=1e-3)", vr, eta_cd, 4}};
        snprintf(path, sizeof path, "%s/softcore_viscosity.svg", outdir);
        svg_plot(path, "Overdamped viscosity, phi = 0.78", "gammadot tau_e", "sigma_xy / gammadot", 1, 1, s, 2);
        series t[1] = {{"CD_n, m = 1", mr, eta_cdn, 8}};
        snprintf(path, sizeof path, "%s/softcore_cdn.svg", outdir);
        svg_plot(path, "CD_n: sigma/gammadot against rate, phi = 0.78", "gammadot tau_e", "sigma_xy / gammadot", 1, 1, t, 1);
    }
    odhs_system_destroy(s78);
    odhs_system_destroy(start);
    return 0;
}
