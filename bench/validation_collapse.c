/* bench/validation_collapse - the thesis' Fig. 5.1 for docs/validation.md
 * (issue 21): flow curves of the soft-core RD0 model around jamming and
 * their scaling collapse (odhs_collapse_fit, thesis eq. 5.2).
 *
 * usage: validation_collapse N SEED TRANSIENT MEASURE PREFIX PHI,PHI,... RATE,RATE,...
 *   N bidisperse discs (radii 0.5 and 0.7, 50:50) in 2D. Each PHI starts
 *   from one configuration (event-driven compression to phi = 0.78, then an
 *   affine soft compression to PHI and a FIRE minimisation), and is
 *   sheared at each RATE (gammadot tau_e) in the order given (list them
 *   from fast to slow: each rate continues from the last one's state) for
 *   TRANSIENT strain, then MEASURE strain with sigma_xy and p sampled 200
 *   times (block-averaged errors, odhs_series_stats_compute).
 * Writes PREFIX.csv (phi,rate,shear_stress,shear_stress_err,pressure,
 * pressure_err,z,cpu_s: the input of examples/collapse) and prints the
 * table and the collapse fits of p and sigma_xy (polynomial degree 3,
 * start at the thesis' phi_J = 0.8433, y = 1.1, z nu = 3.5).
 *
 * Settings: harmonic potential, k_e = k_d = 1 (tau_e = d_min^2), fixed
 * Euler step 0.1 tau_e; stresses in k_e per area.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "bench.h"
#include "scene.h"

#define NSAMP 200

static int fail(const char *what, const char *msg)
{
    fprintf(stderr, "validation_collapse: %s: %s\n", what, msg);
    return 1;
}

static int parse_list(const char *s, double *out, int cap)
{
    int n = 0;
    char *buf = strdup(s), *save = NULL;
    for (char *t = strtok_r(buf, ",", &save); t && n < cap; t = strtok_r(NULL, ",", &save)) out[n++] = atof(t);
    free(buf);
    return n;
}

static void fit(const char *name, const double *phi, const double *rate, const double *v, const double *e, size_t n)
{
    odhs_collapse c = {.size = sizeof c};
    double guess[3] = {0.8433, 1.1, 3.5};
    int s = odhs_collapse_fit(phi, rate, v, e, n, 3, guess, &c);
    if (s) {
        printf("collapse of %s: %s (%s)\n", name, odhs_strerror(s), odhs_last_error());
        return;
    }
    printf("collapse of %-8s phi_J = %.4f +- %.4f, y = %.3f +- %.3f, z nu = %.2f +- %.2f, chi2/dof = %.2f (%zu dof)\n",
           name, c.phi_j, c.phi_j_err, c.y, c.y_err, c.znu, c.znu_err, c.chi2 / (double)c.dof, c.dof);
}

int main(int argc, char **argv)
{
    if (argc < 8) {
        fprintf(stderr, "usage: %s N SEED TRANSIENT MEASURE PREFIX PHI,PHI,... RATE,RATE,...\n", argv[0]);
        return 2;
    }
    size_t n = (size_t)atol(argv[1]);
    unsigned seed = (unsigned)atoi(argv[2]);
    double transient = atof(argv[3]), measure = atof(argv[4]);
    const char *prefix = argv[5];
    double phis[64], rates[16];
    int nphi = parse_list(argv[6], phis, 64), nrate = parse_list(argv[7], rates, 16);
    if (n < 16 || !(transient >= 0) || !(measure > 0) || nphi < 1 || nrate < 1) return fail("arguments", "bad value");
    char cpu[128];
    bench_cpu_model(cpu, sizeof cpu);
    printf("# validation_collapse: RD0, 2D bidisperse 1:1.4, N = %zu, seed %u, transient %g, measure %g per rate\n"
           "# harmonic, k_e = k_d = 1, Euler dt = 0.1 tau_e; machine: %s, OPENBLAS_NUM_THREADS=%s\n",
           n, seed, transient, measure, cpu, getenv("OPENBLAS_NUM_THREADS") ? getenv("OPENBLAS_NUM_THREADS") : "unset");
    const double phi0 = 0.78;
    odhs_system *base;
    if (bench_disc_scene(n, 0.0, seed, phi0, &base)) return 1;

    char path[1024];
    snprintf(path, sizeof path, "%s.csv", prefix);
    FILE *csv = fopen(path, "w");
    if (!csv) return fail(path, "cannot write");
    fprintf(csv, "phi,rate,shear_stress,shear_stress_err,pressure,pressure_err,z,cpu_s\n");
    printf("%7s %9s %12s %10s %12s %10s %7s %8s\n", "phi", "rate", "sigma_xy", "+-", "p", "+-", "z", "cpu_s");
    size_t np = (size_t)(nphi * nrate), k = 0;
    double *P = malloc(np * sizeof *P), *R = malloc(np * sizeof *R), *S = malloc(np * sizeof *S),
           *SE = malloc(np * sizeof *SE), *Pp = malloc(np * sizeof *Pp), *PE = malloc(np * sizeof *PE);
    for (int a = 0; a < nphi; ++a) {
        odhs_system *sys;
        odhs_softcore *sc;
        if (odhs_system_clone(base, &sys) || odhs_softcore_create(sys, &sc)) return fail("softcore", odhs_last_error());
        if (odhs_softcore_scale_box(sc, sqrt(phi0 / phis[a])) || odhs_softcore_set_minimiser(sc, ODHS_SOFTCORE_FIRE) ||
            odhs_softcore_set_min_tolerance(sc, 1e-8, 100000000) || odhs_softcore_minimise(sc, NULL))
            return fail("soft compression", odhs_softcore_errmsg(sc));
        for (int b = 0; b < nrate; ++b) {
            double c0 = bench_cpu(), g0, sig[NSAMP], pr[NSAMP], z = 0.0;
            if (odhs_softcore_set_shear_rate(sc, rates[b]) || odhs_softcore_strain(sc, &g0) ||
                odhs_softcore_run_until_strain(sc, g0 + transient))
                return fail("transient", odhs_softcore_errmsg(sc));
            for (int m = 0; m < NSAMP; ++m) {
                double s4[4], zz;
                if (odhs_softcore_run_until_strain(sc, g0 + transient + measure * (m + 1) / NSAMP) ||
                    odhs_softcore_stress(sc, ODHS_SOFTCORE_STRESS_TOTAL, s4) || odhs_softcore_pressure(sc, &pr[m]) ||
                    odhs_softcore_coordination(sc, 0, &zz))
                    return fail("measure", odhs_softcore_errmsg(sc));
                sig[m] = s4[1];
                z += zz / NSAMP;
            }
            odhs_series_stats ss = {.size = sizeof ss}, sp = {.size = sizeof sp};
            if (odhs_series_stats_compute(sig, NSAMP, &ss) || odhs_series_stats_compute(pr, NSAMP, &sp))
                return fail("statistics", odhs_last_error());
            double cpus = bench_cpu() - c0;
            printf("%7.4f %9.1e %12.5e %10.3e %12.5e %10.3e %7.4f %8.1f%s\n", phis[a], rates[b], ss.mean, ss.sem,
                   sp.mean, sp.sem, z, cpus, ss.plateau && sp.plateau ? "" : "  (no plateau: error a lower bound)");
            fflush(stdout);
            fprintf(csv, "%.6f,%.6g,%.10g,%.6g,%.10g,%.6g,%.6f,%.2f\n", phis[a], rates[b], ss.mean, ss.sem, sp.mean,
                    sp.sem, z, cpus);
            fflush(csv);
            P[k] = phis[a];
            R[k] = rates[b];
            S[k] = ss.mean;
            SE[k] = fmax(ss.sem / ss.mean, 0.01); /* at least 1 %: the fit's default */
            Pp[k] = sp.mean;
            PE[k] = fmax(sp.sem / sp.mean, 0.01);
            k++;
        }
        odhs_softcore_destroy(sc);
        odhs_system_destroy(sys);
    }
    fclose(csv);
    fit("pressure", P, R, Pp, PE, k);
    fit("sigma_xy", P, R, S, SE, k);
    free(P), free(R), free(S), free(SE), free(Pp), free(PE);
    odhs_system_destroy(base);
    return 0;
}
