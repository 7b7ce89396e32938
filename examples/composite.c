/* composite - rigid composite particles under shear flow (Fig. 9 of Lerner,
 * During & Wyart 2013) with libodhs.
 *
 * With no arguments: 100 rigid trimers (three touching beads each; half the
 * trimers with bead radius 0.5, half 0.7) are placed at random, compressed to
 * a bead packing fraction of 0.70 and sheared to a strain of 1 at fixed
 * volume. Bonds are permanent contacts: they never open and carry negative
 * (tensile) forces as well as positive ones. Progress goes to stderr, a table
 * of strain, shear stress, pressure, z and events to stdout.
 *
 * Build against an installed libodhs:
 *     cc composite.c $(pkg-config --cflags --libs odhs) -lm -o composite
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <odhs.h>

#include "cli.h"

/* the --series columns */
#define SERIES "strain,shear_stress,pressure,z,events,bond_error"

#define CHECK(call)                                                                             \
    do {                                                                                        \
        int rc_ = (call);                                                                       \
        if (rc_ < 0) {                                                                          \
            fprintf(stderr, "composite: %s failed: %s\n", #call, odhs_strerror(rc_));           \
            return 1;                                                                           \
        }                                                                                       \
    } while (0)

/* Bodies: random sequential placement of their enclosing discs at phi 0.45,
 * then K touching beads (K = 2 or 3) around each centre, randomly oriented. */
static int build(unsigned long nb, int k, unsigned long seed, odhs_system **out)
{
    /* enclosing radius over bead radius */
    double enc = k == 3 ? 1.0 + 2.0 / sqrt(3.0) : 2.0;
    odhs_system *tmp = NULL, *sys = NULL;
    int rc = odhs_system_create(2, nb, &tmp);
    if (!rc) rc = odhs_system_set_radii_bidisperse(tmp, 0.5 * enc, 1.4, 0.0, seed);
    if (!rc) rc = odhs_system_place_random(tmp, 0.45, seed + 1);
    if (rc) {
        fprintf(stderr, "composite: placing the bodies: %s\n", tmp ? odhs_system_errmsg(tmp) : odhs_strerror(rc));
        odhs_system_destroy(tmp);
        return 1;
    }
    size_t n = nb * (size_t)k;
    double *c = malloc(2 * nb * sizeof *c), *R = malloc(nb * sizeof *R);
    double *x = malloc(2 * n * sizeof *x), *r = malloc(n * sizeof *r), L[2];
    if (!c || !R || !x || !r) {
        fprintf(stderr, "composite: out of memory\n");
        return 1;
    }
    odhs_system_get_positions(tmp, c);
    odhs_system_get_radii(tmp, R);
    odhs_system_get_box(tmp, L);
    srand((unsigned)seed);
    for (size_t b = 0; b < nb; ++b) {
        double a = R[b] / enc, ang = 2.0 * 3.14159265358979323846 * rand() / ((double)RAND_MAX + 1.0);
        double d = k == 3 ? 2.0 * a / sqrt(3.0) : a; /* centre to bead */
        for (int q = 0; q < k; ++q) {
            double t = ang + 2.0 * 3.14159265358979323846 * q / k;
            size_t i = b * (size_t)k + (size_t)q;
            r[i] = a;
            x[2 * i] = fmod(c[2 * b] + d * cos(t) + L[0], L[0]);
            x[2 * i + 1] = fmod(c[2 * b + 1] + d * sin(t) + L[1], L[1]);
        }
    }
    rc = odhs_system_create(2, n, &sys);
    if (!rc) rc = odhs_system_set_configuration(sys, L, 0.0, r, x);
    if (rc) fprintf(stderr, "composite: %s\n", sys ? odhs_system_errmsg(sys) : odhs_strerror(rc));
    free(c);
    free(R);
    free(x);
    free(r);
    odhs_system_destroy(tmp);
    if (rc) {
        odhs_system_destroy(sys);
        return 1;
    }
    *out = sys;
    return 0;
}

int main(int argc, char **argv)
{
    const char *series = NULL, *plot = NULL, *svg = NULL, *outpath = NULL, *solver_name = CLI_DEFAULT_SOLVER;
    const char *traj = NULL, *traj_contacts = NULL;
    double phi = 0.70, strain = 1.0, every = 0.05, tol = 0.0, traj_every = 0.0;
    unsigned long nb = 100, k = 3, seed = 1;
    int integrator = CLI_DEFAULT_INTEGRATOR, quiet = 0;
    const cli_opt opts[] = {
        CLI_OPT_ULONG("--bodies", &nb, "N", "number of composite particles", CLI_ATLEAST(2)),
        CLI_OPT_ULONG("--beads", &k, "K", "beads per body: 2 (dimers) or 3 (trimers)", CLI_BETWEEN(2, 3)),
        CLI_OPT_DOUBLE("--phi", &phi, "X", "bead packing fraction to compress to", CLI_OPEN(0, 1)),
        CLI_STRAIN(&strain),
        CLI_EVERY(&every, "strain"),
        CLI_SEED(&seed),
        CLI_INTEGRATOR(&integrator),
        CLI_TOL(&tol),
        CLI_SOLVER(&solver_name),
        CLI_SERIES(&series, SERIES),
        CLI_PLOT(&plot),
        CLI_SVG(&svg),
        CLI_OUT(&outpath),
        CLI_TRAJ(&traj),
        CLI_TRAJ_EVERY(&traj_every, "strain"),
        CLI_TRAJ_CONTACTS(&traj_contacts),
        CLI_QUIET(&quiet),
        CLI_END,
    };
    const cli_spec cli = {"composite", NULL, opts,
                          "The shear starts after the compression. The picture (--svg) draws the bonds\n"
                          "as thin dark-blue lines.\n"
                          "Stresses in units of gammadot/xi0 (per length, 2D).\n"
                          "Defaults are the library's (adaptive Heun, the auto solver); paper mode:\n"
                          "--integrator euler --solver cg. The drift correction runs after every step\n"
                          "with either integrator, not every 10 as in the paper: the bodies stay rigid\n"
                          "to round-off at every output (bond_error).\n",
                          0};
    int rc = cli_parse(&cli, argc, argv);
    if (rc != CLI_GO) return rc;
    odhs_system *sys;
    if (build(nb, (int)k, seed, &sys)) return 1;
    size_t n = odhs_system_count(sys);
    odhs_solver *solver;
    if ((rc = cli_solver(cli.prog, solver_name, &solver))) return rc;
    odhs_driver *drv;
    odhs_stepper *st;
    CHECK(odhs_driver_create(&drv));
    CHECK(odhs_stepper_create(sys, drv, solver, &st));
    CHECK(odhs_stepper_set_integrator(st, integrator));
    CHECK(cli_set_tolerance(st, tol));
    /* drift correction after every step: bodies rigid to round-off at every
     * output (bond_error column), at the price of one extra solve per step.
     * Set explicitly, so it stays 1 with --integrator euler too (whose own
     * interval, the paper's, is 10): this setting differs from paper mode on
     * purpose. */
    CHECK(odhs_stepper_set_correction_interval(st, 1));
    for (size_t b = 0; b < nb; ++b) {
        size_t beads[3] = {b * k, b * k + 1, b * k + 2};
        rc = odhs_stepper_add_rigid_body(st, (size_t)k, beads);
        if (rc) {
            fprintf(stderr, "composite: body %zu: %s\n", b, odhs_stepper_errmsg(st));
            return 1;
        }
    }
    size_t nbonds;
    CHECK(odhs_stepper_bond_count(st, &nbonds));
    double phi_now;
    CHECK(odhs_system_packing_fraction(sys, &phi_now));
    if (!quiet)
        fprintf(stderr, "composite: %lu %s of %lu beads (%zu bonds), N = %zu beads, phi = %.3f, %s, solver %s\n",
                nb, k == 3 ? "trimers" : "dimers", k, nbonds, n, phi_now, cli_integrators[integrator],
                odhs_solver_name(solver));

    /* compression to phi */
    if (phi > phi_now) {
        if (!quiet) fprintf(stderr, "composite: compressing to phi = %.3f\n", phi);
        CHECK(odhs_driver_set_compression_rate(drv, 1.0));
        rc = odhs_stepper_run_until_packing_fraction(st, phi);
        if (rc) {
            fprintf(stderr, "composite: compression stopped: %s (%s)\n", odhs_strerror(rc), odhs_stepper_errmsg(st));
            return 1;
        }
        CHECK(odhs_driver_set_compression_rate(drv, 0.0));
    }
    CHECK(odhs_driver_set_shear_rate(drv, 1.0));
    CHECK(odhs_stepper_correct(st));

    FILE *csv;
    if (cli_series(cli.prog, series, SERIES, &csv)) return 1;
    cli_progress prog;
    cli_traj tr;
    cli_plot pl;
    cli_plot_init(&pl, plot, "composite particles under shear", SERIES);
    cli_progress_init(&prog, cli.prog, quiet);
    if (cli_traj_open(&tr, cli.prog, traj, traj_contacts, traj_every)) return 1;
    printf("%10s %14s %14s %8s %10s %11s\n", "strain", "shear_stress", "pressure", "z", "events", "bond_error");
    double g0;
    CHECK(odhs_stepper_strain(st, &g0));
    long nout = (long)ceil(strain / every - 1e-9);
    for (long q = 0; q <= nout; ++q) {
        if (q > 0) {
            rc = odhs_stepper_run_until_strain(st, g0 + fmin(q * every, strain));
            if (rc) {
                cli_progress_break(&prog);
                fprintf(stderr, "composite: stopped: %s (%s)\n", odhs_strerror(rc), odhs_stepper_errmsg(st));
                break;
            }
        }
        double g, s, p, z, gap;
        uint64_t steps, nc, no;
        odhs_stepper_strain(st, &g);
        odhs_stepper_shear_stress(st, &s);
        odhs_stepper_pressure(st, &p);
        odhs_stepper_coordination(st, &z);
        odhs_stepper_counts(st, &steps, &nc, &no);
        odhs_stepper_errors(st, &gap, NULL);
        printf("%10.4f %14.6e %14.6e %8.4f %10llu %11.2e\n", g - g0, s, p, z, (unsigned long long)(nc + no), gap);
        if (csv)
            fprintf(csv, "%.10g,%.10g,%.10g,%.6f,%llu,%.3e\n", g - g0, s, p, z, (unsigned long long)(nc + no), gap);
        cli_plot_row(&pl, (double[]){g - g0, s, p, z, (double)(nc + no), gap});
        if (cli_traj_output(&tr, sys, st, g - g0)) return 1;
        cli_progress_show(&prog, g - g0, strain, q == nout, "strain %.3f / %.3f, %llu steps, %llu events", g - g0,
                          strain, (unsigned long long)steps, (unsigned long long)(nc + no));
    }
    if (csv && fclose(csv)) {
        fprintf(stderr, "composite: error writing %s\n", series);
        return 1;
    }
    if (cli_plot_write(&pl, cli.prog, plot)) return 1;
    if (svg && odhs_svg_write(sys, odhs_stepper_network(st), NULL, svg)) {
        fprintf(stderr, "composite: cannot write %s: %s\n", svg, odhs_system_errmsg(sys));
        return 1;
    }
    if (cli_traj_close(&tr)) return 1;
    if (outpath && cli_write_config(cli.prog, sys, outpath)) return 1;
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(solver);
    odhs_system_destroy(sys);
    return rc < 0 ? 1 : 0;
}
