/* bench/validation_gy - the thesis' Fig. 4.8 for docs/validation.md
 * (issue 21): the transverse velocity correlation g_y(x) (thesis eq. 4.23,
 * odhs_velocity_correlation) of the soft-core RD0 and CD0 models in steady
 * shear at several rates, and the position of its minimum
 * (odhs_correlation_minimum), which the thesis uses as the correlation
 * length of RD0 and which CD0 lacks.
 *
 * usage: validation_gy MODEL N PHI SEED TRANSIENT MEASURE SAMPLES PREFIX RATE...
 *   MODEL rd0 or cd0; N bidisperse discs (radii 0.5 and 0.7, 50:50, the
 *   thesis' mixture) at packing fraction PHI; each RATE (gammadot tau_e)
 *   starts from the same configuration, is sheared for TRANSIENT strain,
 *   then for MEASURE strain while g_y is accumulated from SAMPLES equally
 *   spaced snapshots (strips of width 1, 64 bins over [0, L_x/2]).
 * Writes PREFIX.csv (x and g_y per rate) and PREFIX.svg, and prints one
 * row per rate: the minimum's position and value, sigma_xy / gammadot, CPU.
 *
 * Settings: harmonic potential, k_e = k_d = 1 (tau_e = d_min^2), CD0
 * substrate drag k_0 = 1e-3 (the library's default), fixed Euler step
 * 0.1 tau_e. The start is made by event-driven compression at rate 1 from
 * random placement at phi = 0.45 (as examples/softcore_shear does).
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "bench.h"
#include "scene.h"
#include "../examples/plot.h"

#define NBINS 64

static int fail(const char *what, const char *msg)
{
    fprintf(stderr, "validation_gy: %s: %s\n", what, msg);
    return 1;
}

int main(int argc, char **argv)
{
    if (argc < 10) {
        fprintf(stderr, "usage: %s MODEL N PHI SEED TRANSIENT MEASURE SAMPLES PREFIX RATE...\n", argv[0]);
        return 2;
    }
    int model = !strcmp(argv[1], "rd0") ? ODHS_SOFTCORE_RD0 : !strcmp(argv[1], "cd0") ? ODHS_SOFTCORE_CD0 : -1;
    size_t n = (size_t)atol(argv[2]);
    double phi = atof(argv[3]), transient = atof(argv[5]), measure = atof(argv[6]);
    unsigned seed = (unsigned)atoi(argv[4]);
    int samples = atoi(argv[7]), nrates = argc - 9;
    const char *prefix = argv[8];
    if (model < 0 || n < 16 || !(phi > 0.3 && phi < 0.95) || !(transient >= 0) || !(measure > 0) || samples < 1)
        return fail("arguments", "bad value");
    char cpu[128];
    bench_cpu_model(cpu, sizeof cpu);
    printf("# validation_gy: %s, 2D bidisperse 1:1.4, N = %zu, phi = %.3f, seed %u, transient %g, measure %g "
           "(%d snapshots)\n# harmonic, k_e = k_d = 1, k_0 = 1e-3, Euler dt = 0.1 tau_e; machine: %s, "
           "OPENBLAS_NUM_THREADS=%s\n",
           argv[1], n, phi, seed, transient, measure, samples, cpu,
           getenv("OPENBLAS_NUM_THREADS") ? getenv("OPENBLAS_NUM_THREADS") : "unset");
    /* the start */
    odhs_system *base;
    if (bench_disc_scene(n, 0.0, seed, phi, &base)) return 1;

    double L[9];
    odhs_system_get_box(base, L);
    double dx = L[0] / (2.0 * NBINS);
    printf("%10s %9s %9s %12s %8s %10s\n", "rate", "x_min", "g_min", "sigma/rate", "z", "cpu_s");
    char path[1024];
    snprintf(path, sizeof path, "%s.csv", prefix);
    FILE *csv = fopen(path, "w");
    if (!csv) return fail(path, "cannot write");
    fprintf(csv, "rate,x,g_y,pairs\n");
    pl_plot p;
    char title[160];
    snprintf(title, sizeof title, "g_y(x), %s, N = %zu, phi = %.2f (thesis Fig. 4.8)", model ? "CD0" : "RD0", n, phi);
    pl_init(&p, title, "x (small-particle diameters)", "g_y(x)", 0, 0);
    double *u = malloc(2 * n * sizeof *u);
    for (int r = 0; r < nrates; ++r) {
        double rate = atof(argv[9 + r]), c0 = bench_cpu();
        odhs_system *sys;
        odhs_softcore *sc;
        if (odhs_system_clone(base, &sys) || odhs_softcore_create(sys, &sc)) return fail("softcore", odhs_last_error());
        if (odhs_softcore_set_model(sc, model) || odhs_softcore_set_shear_rate(sc, rate))
            return fail("softcore settings", odhs_softcore_errmsg(sc));
        if (odhs_softcore_run_until_strain(sc, transient)) return fail("transient", odhs_softcore_errmsg(sc));
        double gsum[NBINS] = {0}, g[NBINS], sig = 0.0, z = 0.0;
        uint64_t psum[NBINS] = {0}, pairs[NBINS];
        for (int k = 1; k <= samples; ++k) {
            double s[4], zz;
            if (odhs_softcore_run_until_strain(sc, transient + measure * k / samples) ||
                odhs_softcore_velocities(sc, u) || odhs_softcore_stress(sc, ODHS_SOFTCORE_STRESS_TOTAL, s) ||
                odhs_softcore_coordination(sc, 0, &zz))
                return fail("measure", odhs_softcore_errmsg(sc));
            if (odhs_velocity_correlation(sys, u, 1.0, NBINS, g, pairs)) return fail("g_y", odhs_last_error());
            for (int b = 0; b < NBINS; ++b)
                if (pairs[b]) {
                    gsum[b] += g[b] * (double)pairs[b];
                    psum[b] += pairs[b];
                }
            sig += s[1] / samples;
            z += zz / samples;
        }
        char name[64];
        snprintf(name, sizeof name, "rate %g", rate);
        int sr = pl_series_add(&p, name, r, 0, 0);
        for (int b = 0; b < NBINS; ++b) {
            g[b] = psum[b] ? gsum[b] / (double)psum[b] : NAN;
            fprintf(csv, "%g,%.6f,%.6f,%llu\n", rate, (b + 0.5) * dx, g[b], (unsigned long long)psum[b]);
            pl_point(&p, sr, (b + 0.5) * dx, g[b]);
        }
        double xm = NAN, gm = NAN;
        if (odhs_correlation_minimum(g, NBINS, &xm, &gm) == ODHS_OK) xm *= dx;
        printf("%10.1e %9.3f %9.4f %12.4e %8.4f %10.1f\n", rate, xm, gm, sig / rate, z, bench_cpu() - c0);
        fflush(stdout);
        odhs_softcore_destroy(sc);
        odhs_system_destroy(sys);
    }
    char note[200];
    snprintf(note, sizeof note, "bench/validation_gy %s %zu %g %u %g %g %d; %.80s", argv[1], n, phi, seed, transient,
             measure, samples, cpu);
    pl_note(&p, note);
    snprintf(path, sizeof path, "%s.svg", prefix);
    pl_write_svg(&p, path);
    pl_free(&p);
    fclose(csv);
    free(u);
    odhs_system_destroy(base);
    return 0;
}
