/* bench/oscillation.c - oscillatory shear of the default scene (N = 256
 * bidisperse discs, phi = 0.80), the library's default integrator and solver:
 *  1. strain and shear stress against time over three periods, sine and
 *     triangle shapes of amplitude 0.1 (figure: oscillation.svg);
 *  2. the stroboscopic rms displacement (positions one period apart) over
 *     CYCLES periods for several amplitudes, with the collisions per period
 *     and the CPU time (table; figure oscillation_strobe.svg).
 *
 *   build/bench/oscillation [CYCLES] [N]      (defaults 8, 256)
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
            fprintf(stderr, "oscillation: %s: %s\n", #call, odhs_strerror(rc_));                             \
            exit(1);                                                                                         \
        }                                                                                                    \
    } while (0)

/* RSA at 0.45, compressed to phi with contacts corrected */
static odhs_system *scene(size_t n, double phi)
{
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
    CHECK(odhs_system_create(2, n, &sys));
    CHECK(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, 1));
    CHECK(odhs_system_place_random(sys, 0.45, 2));
    CHECK(odhs_driver_create(&drv));
    CHECK(odhs_driver_set_compression_rate(drv, 1.0));
    CHECK(odhs_solver_create_by_name("auto", &sol));
    CHECK(odhs_stepper_create(sys, drv, sol, &st));
    CHECK(odhs_stepper_run_until_packing_fraction(st, phi));
    CHECK(odhs_stepper_correct(st));
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_driver_destroy(drv);
    return sys;
}

typedef struct {
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
} run;

static run start(const odhs_system *s0, int shape, double amp)
{
    run r;
    CHECK(odhs_system_clone(s0, &r.sys));
    CHECK(odhs_driver_create(&r.drv));
    CHECK(odhs_driver_set_oscillatory_shear(r.drv, shape, amp, 1.0, 0.0));
    CHECK(odhs_solver_create_by_name("auto", &r.sol));
    CHECK(odhs_stepper_create(r.sys, r.drv, r.sol, &r.st));
    return r;
}

static void finish(run *r)
{
    odhs_stepper_destroy(r->st);
    odhs_solver_destroy(r->sol);
    odhs_driver_destroy(r->drv);
    odhs_system_destroy(r->sys);
}

static double rms_displacement(const odhs_system *sys, const double *a, const double *b)
{
    size_t n = odhs_system_count(sys);
    double L[3], g, s = 0.0;
    odhs_system_get_box(sys, L);
    odhs_system_get_strain(sys, &g);
    for (size_t i = 0; i < n; ++i) {
        double dx = b[2 * i] - a[2 * i], dy = b[2 * i + 1] - a[2 * i + 1];
        double ny = nearbyint(dy / L[1]);
        dy -= ny * L[1];
        dx -= ny * g * L[1];
        dx -= nearbyint(dx / L[0]) * L[0];
        s += dx * dx + dy * dy;
    }
    return sqrt(s / (double)n);
}

/* 1: strain and stress against time, both shapes, into one figure */
static void signals(const odhs_system *s0, double amp)
{
    pl_plot p;
    pl_init(&p, "Oscillatory shear, N = 256, phi = 0.80, amplitude 0.1", "time / period",
            "strain / amplitude, shear stress / its largest value", 0, 0);
    const int shapes[2] = {ODHS_OSCILLATION_SINE, ODHS_OSCILLATION_TRIANGLE};
    const char *names[2] = {"sine", "triangle"};
    for (int k = 0; k < 2; ++k) {
        run r = start(s0, shapes[k], amp);
        enum { M = 3 * 80 };
        double t[M + 1], g[M + 1], sig[M + 1], smax = 0.0;
        for (int q = 0; q <= M; ++q) {
            t[q] = 3.0 * q / M;
            if (q) CHECK(odhs_stepper_run_until_time(r.st, t[q]));
            else CHECK(odhs_stepper_reset(r.st));
            odhs_stepper_strain(r.st, &g[q]);
            odhs_stepper_shear_stress(r.st, &sig[q]);
            smax = fmax(smax, fabs(sig[q]));
        }
        char name[64];
        snprintf(name, sizeof name, "%s: strain", names[k]);
        int a = pl_series_add(&p, name, 2 * k, 0, 0);
        snprintf(name, sizeof name, "%s: shear stress", names[k]);
        int b = pl_series_add(&p, name, 2 * k + 1, 1, 0);
        for (int q = 0; q <= M; ++q) {
            pl_point(&p, a, t[q], g[q] / amp);
            pl_point(&p, b, t[q], sig[q] / smax);
        }
        printf("signals %-8s: largest |shear stress| %.4g (xi0 = 1, peak rate %.4g)\n", names[k], smax,
               (shapes[k] == ODHS_OSCILLATION_SINE ? 2.0 * 3.14159265358979323846 : 4.0) * amp);
        finish(&r);
    }
    pl_note(&p, "library defaults (adaptive Heun, auto solver); period 1; build/bench/oscillation");
    pl_write_svg(&p, "oscillation.svg");
    pl_free(&p);
}

/* 2: stroboscopic displacement per period against the cycle, by amplitude */
static void strobe(const odhs_system *s0, int cycles)
{
    const double amps[] = {0.02, 0.05, 0.1, 0.2, 0.5};
    const int na = (int)(sizeof amps / sizeof amps[0]);
    pl_plot p;
    pl_init(&p, "Stroboscopic rms displacement, triangle shape, N = 256, phi = 0.80", "cycle",
            "rms displacement over one period / small diameter", 0, 1);
    size_t nd = 2 * odhs_system_count(s0);
    double *xp = malloc(nd * sizeof *xp), *x = malloc(nd * sizeof *x);
    printf("\n%8s %6s %14s %14s %12s %10s\n", "amp", "cycle", "strobe_rms", "collisions", "cpu_s", "steps");
    for (int a = 0; a < na; ++a) {
        run r = start(s0, ODHS_OSCILLATION_TRIANGLE, amps[a]);
        char name[32];
        snprintf(name, sizeof name, "amplitude %g", amps[a]);
        int s = pl_series_add(&p, name, a, 0, 1);
        odhs_system_get_positions(r.sys, xp);
        uint64_t c0 = 0;
        for (int c = 1; c <= cycles; ++c) {
            double t0 = bench_cpu();
            CHECK(odhs_stepper_run_until_time(r.st, (double)c));
            double cpu = bench_cpu() - t0;
            odhs_system_get_positions(r.sys, x);
            double d = rms_displacement(r.sys, xp, x);
            uint64_t steps, coll;
            odhs_stepper_counts(r.st, &steps, &coll, NULL);
            printf("%8g %6d %14.6e %14llu %12.3f %10llu\n", amps[a], c, d, (unsigned long long)(coll - c0), cpu,
                   (unsigned long long)steps);
            pl_point(&p, s, c, d);
            c0 = coll;
            memcpy(xp, x, nd * sizeof *xp);
        }
        finish(&r);
    }
    pl_note(&p, "library defaults (adaptive Heun, auto solver); build/bench/oscillation");
    pl_write_svg(&p, "oscillation_strobe.svg");
    pl_free(&p);
    free(xp);
    free(x);
}

int main(int argc, char **argv)
{
    int cycles = argc > 1 ? atoi(argv[1]) : 8;
    size_t n = argc > 2 ? (size_t)atol(argv[2]) : 256;
    if (cycles < 1 || n < 4) {
        fprintf(stderr, "usage: oscillation [CYCLES >= 1] [N >= 4]\n");
        return 2;
    }
    char cpu[256];
    int nproc = bench_cpu_model(cpu, sizeof cpu);
    printf("# oscillatory shear: N = %zu, phi = 0.80, %d cycles; machine: %s, %d CPUs\n", n, cycles, cpu, nproc);
    odhs_system *s0 = scene(n, 0.80);
    double c0 = bench_cpu();
    signals(s0, 0.1);
    strobe(s0, cycles);
    printf("\ntotal CPU %.1f s; figures oscillation.svg, oscillation_strobe.svg\n", bench_cpu() - c0);
    odhs_system_destroy(s0);
    return 0;
}
