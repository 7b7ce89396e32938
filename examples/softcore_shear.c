/* softcore_shear - simple shear of soft discs/spheres with the soft-core
 * reference models of libodhs (Vagberg's thesis, ch. 4).
 *
 * With no arguments: builds the same scene as shear_flow (N = 256 discs,
 * 50:50 bidisperse radii 0.5/0.7 with 3% polydispersity, phi = 0.80, by
 * event-driven compression), shears it with RD0 at gammadot tau_e = 1e-5 to
 * a strain of 0.02, and prints strain, shear stress, pressure, energy, z and
 * the largest overlap.
 *
 * Build against an installed libodhs:
 *     cc softcore_shear.c $(pkg-config --cflags --libs odhs) -lm -o softcore_shear
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <odhs.h>

#include "cli.h"

/* the --series columns */
#define SERIES "strain,shear_stress,pressure,energy,z,max_overlap"

#define CHECK(call)                                                                             \
    do {                                                                                        \
        int rc_ = (call);                                                                       \
        if (rc_ < 0) {                                                                          \
            fprintf(stderr, "softcore_shear: %s failed: %s\n", #call, odhs_strerror(rc_));      \
            return 1;                                                                           \
        }                                                                                       \
    } while (0)

static int build_scene(int dim, unsigned long n, double phi, unsigned long seed, int quiet, odhs_system **out)
{
    odhs_system *sys = NULL;
    double phi0 = dim == 2 ? 0.45 : 0.3;
    if (phi < phi0) phi0 = phi;
    int rc = cli_scene(dim, n, seed, phi, &sys);
    if (rc) {
        fprintf(stderr, "softcore_shear: %s\n", sys ? odhs_system_errmsg(sys) : odhs_strerror(rc));
        return 1;
    }
    if (phi > phi0) {
        odhs_driver *drv;
        odhs_stepper *st;
        odhs_solver *solver;
        CHECK(odhs_solver_create_by_name(CLI_DEFAULT_SOLVER, &solver));
        CHECK(odhs_driver_create(&drv));
        CHECK(odhs_driver_set_compression_rate(drv, 1.0));
        CHECK(odhs_stepper_create(sys, drv, solver, &st));
        if (!quiet) fprintf(stderr, "softcore_shear: compressing from phi = %.3f to %.3f\n", phi0, phi);
        rc = odhs_stepper_run_until_packing_fraction(st, phi);
        if (rc) {
            fprintf(stderr, "softcore_shear: compression stopped: %s (%s)\n", odhs_strerror(rc),
                    odhs_stepper_errmsg(st));
            return 1;
        }
        odhs_stepper_destroy(st);
        odhs_driver_destroy(drv);
        odhs_solver_destroy(solver);
    }
    *out = sys;
    return 0;
}

/* --model: the names, and the models by the same index */
static const char *const model_names[] = {"rd0", "cd0", "qs-sd", "qs-fire", "qs-cg", "rd", "cd", "cdn", "cdt", NULL};
static const struct {
    int model, qs, minimiser;
} models[] = {
    {ODHS_SOFTCORE_RD0, 0, 0},
    {ODHS_SOFTCORE_CD0, 0, 0},
    {ODHS_SOFTCORE_RD0, 1, ODHS_SOFTCORE_SD},
    {ODHS_SOFTCORE_RD0, 1, ODHS_SOFTCORE_FIRE},
    {ODHS_SOFTCORE_RD0, 1, ODHS_SOFTCORE_CG},
    {ODHS_SOFTCORE_RD, 0, 0},
    {ODHS_SOFTCORE_CD, 0, 0},
    {ODHS_SOFTCORE_CDN, 0, 0},
    {ODHS_SOFTCORE_CDT, 0, 0},
};
_Static_assert(sizeof models / sizeof models[0] + 1 == sizeof model_names / sizeof model_names[0],
               "one name per model");

/* --integrator, indexed by the enum */
static const char *const integrators[] = {"fixed", "adaptive", NULL};
_Static_assert(ODHS_SOFTCORE_FIXED == 0 && ODHS_SOFTCORE_ADAPTIVE == 1, "integrators is indexed by the enum");

int main(int argc, char **argv)
{
    const char *in = NULL, *outpath = NULL, *series = NULL;
    double rate = 1e-5, dgamma = 1e-4, strain = 0.02, every = 0.002, alpha = 2.0, kd = 1.0, k0 = 1e-3;
    double mass = 1.0, dt = 0.1, tol = -1.0, phi = 0.80;
    unsigned long n = 256, seed = 1;
    int mi = 0, integrator = ODHS_SOFTCORE_FIXED, dim = 2, quiet = 0;
    const cli_opt opts[] = {
        CLI_OPT_LIST("--model", &mi, "NAME",
                     "rd0, cd0 (overdamped), qs-sd, qs-fire, qs-cg (quasistatic: strain step + steepest descent / "
                     "FIRE / Polak-Ribiere CG), rd, cd, cdn, cdt (massive, SLLOD)",
                     model_names, CLI_ANY),
        CLI_OPT_DOUBLE("--rate", &rate, "X",
                       "shear rate in units of 1/tau_e, tau_e = k_d d_min^2/k_e (time-stepped models)", CLI_POSITIVE),
        CLI_OPT_DOUBLE("--dgamma", &dgamma, "X", "quasistatic strain step", CLI_ABOVE_ATMOST(0, 0.1)),
        CLI_STRAIN(&strain),
        CLI_EVERY(&every, "strain"),
        CLI_IN(&in),
        CLI_OUT(&outpath),
        CLI_SERIES(&series, SERIES),
        CLI_OPT_DOUBLE("--alpha", &alpha, "A", "potential exponent: 2 harmonic, 2.5 Hertzian", CLI_ABOVE_ATMOST(1, 10)),
        CLI_OPT_DOUBLE("--kd", &kd, "X", "drag coefficient k_d", CLI_POSITIVE),
        CLI_OPT_DOUBLE("--k0", &k0, "X", "CD0 substrate drag k_0", CLI_NONNEGATIVE),
        CLI_OPT_DOUBLE("--mass", &mass, "X", "particle mass of the massive models", CLI_POSITIVE),
        CLI_OPT_DOUBLE("--dt", &dt, "X", "step factor (fraction of tau_e or tau_m)", CLI_ABOVE_ATMOST(0, 10)),
        CLI_OPT_LIST("--integrator", &integrator, "NAME", "fixed or adaptive (overdamped models)", integrators, CLI_ANY),
        CLI_OPT_DOUBLE("--tol", &tol, "X",
                       "adaptive: error per step / mean diameter (default 1e-6); quasistatic: largest force at the "
                       "minimum (default 1e-9)",
                       CLI_POSITIVE, .deftext = ""),
        CLI_PHI(&phi),
        CLI_SCENE(&n, &dim, &seed),
        CLI_QUIET(&quiet),
        CLI_END,
    };
    const cli_spec cli = {
        "softcore_shear", NULL, opts,
        "The final configuration (--out) may overlap.\n"
        "Units: k_e = 1 (energy), small diameter 1 (length), k_d (drag): stresses are\n"
        "in k_e per area (2D) or volume (3D); the quasistatic models print the\n"
        "relaxation stress (1/dgamma) integral sigma dt (qs-sd) in k_d units, which\n"
        "is the hard-sphere stress at unit shear rate.\n",
        0};
    int rc = cli_parse(&cli, argc, argv);
    if (rc != CLI_GO) return rc;
    int qs = models[mi].qs;

    odhs_system *sys = NULL;
    if (in ? cli_read_xyz(cli.prog, in, &sys) : build_scene(dim, n, phi, seed, quiet, &sys)) return 1;
    n = odhs_system_count(sys);
    double phi_now, r_min = INFINITY;
    CHECK(odhs_system_packing_fraction(sys, &phi_now));
    {
        double *r = malloc(n * sizeof *r);
        if (!r) return 1;
        CHECK(odhs_system_get_radii(sys, r));
        for (size_t i = 0; i < n; ++i) r_min = fmin(r_min, r[i]);
        free(r);
    }
    double tau_e = kd * 4.0 * r_min * r_min; /* k_e = 1 */

    odhs_softcore *sc;
    CHECK(odhs_softcore_create(sys, &sc));
    CHECK(odhs_softcore_set_model(sc, models[mi].model));
    CHECK(odhs_softcore_set_potential(sc, alpha, 1.0));
    CHECK(odhs_softcore_set_drag(sc, kd));
    CHECK(odhs_softcore_set_substrate(sc, k0));
    CHECK(odhs_softcore_set_mass(sc, mass));
    CHECK(odhs_softcore_set_dt(sc, dt));
    CHECK(odhs_softcore_set_integrator(sc, integrator));
    if (qs) {
        CHECK(odhs_softcore_set_minimiser(sc, models[mi].minimiser));
        CHECK(odhs_softcore_set_min_tolerance(sc, tol > 0 ? tol : 1e-9, 100000000u));
    } else {
        if (tol > 0) {
            if (tol >= 1) {
                fprintf(stderr, "softcore_shear: bad value for --tol: %g\n", tol);
                return 2;
            }
            CHECK(odhs_softcore_set_tolerance(sc, tol));
        }
        CHECK(odhs_softcore_set_shear_rate(sc, rate / tau_e));
    }
    if (!quiet)
        fprintf(stderr, "softcore_shear: N = %lu, d = %d, phi = %.6f, model %s, %s %g\n", n, odhs_system_dim(sys),
                phi_now, model_names[mi], qs ? "dgamma" : "gammadot tau_e", qs ? dgamma : rate);

    FILE *csv;
    if (cli_series(cli.prog, series, SERIES, &csv)) return 1;
    printf("%12s %14s %14s %14s %8s %12s\n", "strain", qs ? "relax_stress" : "shear_stress", "pressure", "energy",
           "z", "max_overlap");
    long nout = (long)ceil(strain / every - 1e-9);
    double done = 0.0;
    rc = ODHS_OK;
    for (long k = 0; k <= nout; ++k) {
        double target = fmin(k * every, strain);
        if (qs) {
            while (done < target - 1e-12 && rc == ODHS_OK) {
                double step = fmin(dgamma, target - done);
                rc = odhs_softcore_quasistatic_step(sc, step, NULL);
                if (rc == ODHS_OK) done += step;
            }
        } else if (k > 0) {
            rc = odhs_softcore_run_until_strain(sc, target);
        }
        if (rc) {
            fprintf(stderr, "softcore_shear: stopped at strain %.6g: %s (%s)\n", target, odhs_strerror(rc),
                    odhs_softcore_errmsg(sc));
            break;
        }
        double sig[9], s, p, U, z, ov;
        CHECK(odhs_softcore_stress(sc, ODHS_SOFTCORE_STRESS_TOTAL, sig));
        s = sig[1];
        if (qs) {
            s = NAN;
            if (models[mi].minimiser == ODHS_SOFTCORE_SD && k > 0 && odhs_softcore_relaxation_stress(sc, sig) == ODHS_OK)
                s = sig[1];
        }
        CHECK(odhs_softcore_pressure(sc, &p));
        CHECK(odhs_softcore_energy(sc, &U));
        CHECK(odhs_softcore_coordination(sc, 0, &z));
        CHECK(odhs_softcore_max_overlap(sc, &ov));
        printf("%12.6f %14.6e %14.6e %14.6e %8.4f %12.4e\n", target, s, p, U, z, ov);
        if (csv) fprintf(csv, "%.10g,%.10g,%.10g,%.10g,%.6f,%.6g\n", target, s, p, U, z, ov);
    }
    if (csv && fclose(csv)) {
        fprintf(stderr, "softcore_shear: error writing %s\n", series);
        return 1;
    }
    if (outpath && cli_write_config(cli.prog, sys, outpath)) return 1;
    uint64_t steps, fe, mit;
    odhs_softcore_counts(sc, &steps, &fe, &mit);
    if (!quiet)
        fprintf(stderr, "softcore_shear: %llu steps, %llu force evaluations, %llu minimiser iterations\n",
                (unsigned long long)steps, (unsigned long long)fe, (unsigned long long)mit);
    odhs_softcore_destroy(sc);
    odhs_system_destroy(sys);
    return rc < 0 ? 1 : 0;
}
