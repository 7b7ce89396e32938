/* bench/rheology.c - the flow curve of frictionless hard discs/spheres at
 * fixed pressure: the friction coefficient mu = sigma_xy / p and the packing
 * fraction phi against the viscous number I_v = xi0 gdot / p (= 1/p in the
 * library's units, gdot = xi0 = 1), with events and CPU time per unit
 * strain; and the paper's Fig. 7 signals (shear stress, phi, kappa against
 * strain) at p = 10.
 *
 *   build/bench/rheology [DIM] [N] [SEEDS] [STRAIN] [PMAX] [TRANSIENT] [PMIN] [euler|heun]
 *       defaults 2 256 2 1.0 1e4 0.3 10 euler
 *
 * Each seed: the bidisperse scene of the examples (50:50, size ratio 1.4,
 * 3 % polydisperse), random at low density, compressed to phi = 0.80 (2D) or
 * 0.60 (3D), then sheared at p = PMIN, 10 PMIN, ... up to PMAX with the paper's
 * scheme (Euler, dt = 1e-3, drift correction every 10 steps; or the adaptive
 * scheme, tolerance 1e-6, correction every step) and the auto solver. The first TRANSIENT of strain is discarded; mu and phi are sampled
 * every 0.01 of strain and averaged in blocks of 0.1 strain: the error bar is
 * the standard error of the block means (all seeds pooled). Events and CPU
 * time are per unit strain of the steady part.
 *
 * Writes rheology_mu.svg, rheology_phi.svg, rheology_fig7.svg and a table
 * (stdout).
 */
#define _POSIX_C_SOURCE 200809L
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

/* one pressure, all seeds: the block means */
static point measure(int dim, size_t n, int seeds, double strain, double transient, double p, pl_plot *fig7)
{
    point pt;
    memset(&pt, 0, sizeof pt);
    pt.p = p;
    int maxb = seeds * (int)(strain / (SAMPLE * BLOCK) + 2);
    double *bmu = calloc((size_t)maxb, sizeof *bmu), *bphi = calloc((size_t)maxb, sizeof *bphi);
    double zsum = 0.0, k2 = 0.0, cpu = 0.0, steady = 0.0;
    long nz = 0;
    uint64_t events = 0, steps = 0;
    int sm = -1, sp = -1, sk = -1;
    if (fig7) {
        sm = pl_series_add(fig7, "shear stress / p", 0, 0, 0);
        sp = pl_series_add(fig7, dim == 2 ? "(phi - 0.8) x 10" : "(phi - 0.6) x 10", 1, 0, 0);
        sk = pl_series_add(fig7, "kappa", 2, 1, 0);
    }
    for (int s = 0; s < seeds; ++s) {
        run r = start(dim, n, (unsigned)(11 + 7 * s), p);
        double g0, acc_mu = 0.0, acc_phi = 0.0;
        int in_block = 0;
        CHECK(odhs_stepper_strain(r.st, &g0));
        long nsamp = (long)floor(strain / SAMPLE + 0.5);
        uint64_t st0 = 0, c0 = 0, o0 = 0;
        double cpu0 = 0.0;
        for (long q = 1; q <= nsamp; ++q) {
            double g = q * SAMPLE;
            int rc = odhs_stepper_run_until_strain(r.st, g0 + g);
            if (rc) {
                fprintf(stderr, "rheology: p = %g seed %d stopped at strain %.3f: %s (%s)\n", p, s, g,
                        odhs_strerror(rc), odhs_stepper_errmsg(r.st));
                pt.stopped = 1;
                break;
            }
            double sxy, phi, kap, z;
            CHECK(odhs_stepper_shear_stress(r.st, &sxy));
            CHECK(odhs_system_packing_fraction(r.sys, &phi));
            CHECK(odhs_stepper_kappa(r.st, &kap));
            CHECK(odhs_stepper_coordination(r.st, &z));
            if (fig7 && s == 0) {
                pl_point(fig7, sm, g, sxy / p);
                pl_point(fig7, sp, g, (phi - (dim == 2 ? 0.8 : 0.6)) * 10.0);
                pl_point(fig7, sk, g, kap);
            }
            if (g < transient - 1e-9) continue;
            if (fabs(g - transient) < 0.5 * SAMPLE) { /* the steady part starts */
                CHECK(odhs_stepper_counts(r.st, &st0, &c0, &o0));
                cpu0 = bench_cpu();
                continue;
            }
            acc_mu += sxy / p;
            acc_phi += phi;
            zsum += z;
            k2 += kap * kap;
            nz++;
            if (++in_block == BLOCK) {
                bmu[pt.nblocks] = acc_mu / BLOCK;
                bphi[pt.nblocks] = acc_phi / BLOCK;
                pt.nblocks++;
                acc_mu = acc_phi = 0.0;
                in_block = 0;
            }
        }
        uint64_t st1, c1, o1;
        CHECK(odhs_stepper_counts(r.st, &st1, &c1, &o1));
        if (cpu0 > 0.0) {
            double gend;
            CHECK(odhs_stepper_strain(r.st, &gend));
            cpu += bench_cpu() - cpu0;
            steady += gend - g0 - transient;
            events += (c1 + o1) - (c0 + o0);
            steps += st1 - st0;
        }
        finish(&r);
    }
    mean_err(bmu, pt.nblocks, &pt.mu, &pt.mu_err);
    mean_err(bphi, pt.nblocks, &pt.phi, &pt.phi_err);
    pt.z = nz ? zsum / nz : NAN;
    pt.kappa_rms = nz ? sqrt(k2 / nz) : NAN;
    pt.ev_per_strain = steady > 0 ? events / steady : NAN;
    pt.steps_per_strain = steady > 0 ? steps / steady : NAN;
    pt.cpu_per_strain = steady > 0 ? cpu / steady : NAN;
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
    if (argc > 8) integrator = !strcmp(argv[8], "heun") ? ODHS_INTEGRATOR_HEUN : !strcmp(argv[8], "euler") ? 0 : -1;
    if ((dim != 2 && dim != 3) || n < 8 || seeds < 1 || !(strain > transient) || !(pmin > 0.0) || !(pmax >= pmin) ||
        integrator < 0) {
        fprintf(stderr, "usage: rheology [DIM] [N] [SEEDS] [STRAIN] [PMAX] [TRANSIENT] [PMIN] [euler|heun]\n");
        return 2;
    }
    char cpu[128], tag[64];
    int ncpu = bench_cpu_model(cpu, sizeof cpu);
    snprintf(tag, sizeof tag, "%dd_n%zu%s", dim, n, integrator == ODHS_INTEGRATOR_HEUN ? "_heun" : "");
    printf("# rheology: %dD N = %zu, %d seed(s), strain %.2f (first %.2f discarded), %s, auto solver\n", dim, n,
           seeds, strain, transient, integrator == ODHS_INTEGRATOR_HEUN ? "adaptive Heun tol 1e-6" : "Euler dt = 1e-3");
    printf("# machine: %s (%d CPUs listed), libodhs %s, OPENBLAS_NUM_THREADS=%s\n", cpu, ncpu, odhs_version_string(),
           getenv("OPENBLAS_NUM_THREADS") ? getenv("OPENBLAS_NUM_THREADS") : "unset");
    printf("# mu = sigma_xy/p, I_v = xi0 gdot/p; +- the standard error of block means (0.1 strain)\n");
    printf("%10s %10s %18s %20s %7s %10s %11s %11s %11s %6s\n", "p", "I_v", "mu", "phi", "z", "kappa_rms",
           "events/str", "steps/str", "cpu_s/str", "blocks");
    point pts[MAXP];
    int np = 0;
    pl_plot fig7;
    char title[160];
    snprintf(title, sizeof title, "Shear at fixed pressure p = 10 (Fig. 7 of the paper), %dD N = %zu, seed 11", dim, n);
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
