/* compress - isotropic event-driven compression of hard discs/spheres to a
 * target packing fraction, or until the contact network becomes potentially
 * jammed, with libodhs.
 *
 *     cc compress.c $(pkg-config --cflags --libs odhs) -lm -o compress
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>

#include <odhs.h>

#include "cli.h"

/* the --series columns */
#define SERIES "phi,pressure,z,events"

int main(int argc, char **argv)
{
    const char *in = NULL, *outpath = NULL, *series = NULL, *plot = NULL, *solver_name = CLI_DEFAULT_SOLVER;
    const char *traj = NULL, *traj_contacts = NULL;
    double phi_target = 0.80, every = 0.01, dt = 0.0, tol = 0.0, traj_every = 0.0;
    unsigned long n = 256, seed = 1;
    int dim = 2, jam = 0, integrator = CLI_DEFAULT_INTEGRATOR, quiet = 0;
    const cli_opt opts[] = {
        CLI_IN(&in),
        CLI_OPT_DOUBLE("--phi", &phi_target, "X", "target packing fraction", CLI_OPEN(0, 1)),
        CLI_OPT_FLAG("--jam", &jam, "compress until the network is potentially jammed instead"),
        CLI_OUT(&outpath),
        CLI_SERIES(&series, SERIES),
        CLI_PLOT(&plot),
        CLI_EVERY(&every, "packing fraction"),
        CLI_TRAJ(&traj),
        CLI_TRAJ_EVERY(&traj_every, "packing fraction"),
        CLI_TRAJ_CONTACTS(&traj_contacts),
        CLI_DT(&dt, "units of 1/rate"),
        CLI_INTEGRATOR(&integrator),
        CLI_TOL(&tol),
        CLI_SOLVER(&solver_name),
        CLI_SCENE(&n, &dim, &seed),
        CLI_QUIET(&quiet),
        CLI_END,
    };
    const cli_spec cli = {"compress", NULL, opts,
                          "The built-in scene is 50:50 bidisperse (radii 0.5/0.7, 3% polydispersity) placed\n"
                          "at random at phi = 0.45 (2D) or 0.30 (3D). CG alone stalls close to jamming.\n"
                          "Defaults are the library's (adaptive Heun, the auto solver); paper mode:\n"
                          "--integrator euler --solver cg.\n",
                          0};
    int rc = cli_parse(&cli, argc, argv);
    if (rc != CLI_GO) return rc;
    if (jam) phi_target = 0.999;

    odhs_system *sys = NULL;
    if (cli_start(cli.prog, in, dim, n, seed, 1.0, &sys)) return 1;
    odhs_solver *solver;
    if ((rc = cli_solver(cli.prog, solver_name, &solver))) return rc;
    double phi;
    odhs_system_packing_fraction(sys, &phi);
    if (!quiet)
        fprintf(stderr, "compress: N = %zu, d = %d, phi = %.6f -> %s, %s, solver %s\n", odhs_system_count(sys),
                odhs_system_dim(sys), phi, jam ? "jamming" : "target", cli_integrators[integrator], solver_name);

    odhs_driver *drv;
    odhs_stepper *st;
    if (odhs_driver_create(&drv) || odhs_driver_set_compression_rate(drv, 1.0) ||
        odhs_stepper_create(sys, drv, solver, &st) || cli_set_dt(st, dt) ||
        odhs_stepper_set_integrator(st, integrator) || cli_set_tolerance(st, tol)) {
        fprintf(stderr, "compress: setup failed\n");
        return 1;
    }
    FILE *csv;
    if (cli_series(cli.prog, series, SERIES, &csv)) return 1;
    cli_progress prog;
    cli_traj tr;
    cli_plot pl;
    cli_plot_init(&pl, plot, "compression at rate 1", SERIES);
    cli_progress_init(&prog, cli.prog, quiet);
    if (cli_traj_open(&tr, cli.prog, traj, traj_contacts, traj_every)) return 1;
    /* the first frame, at the start: the state the first step would make
     * (a failure here recurs at the first step, which reports it) */
    odhs_stepper_reset(st);
    if (cli_traj_output(&tr, sys, st, phi)) return 1;
    printf("%10s %14s %8s %10s\n", "phi", "pressure", "z", "events");
    int status = 0;
    const double phi0 = phi;
    for (;;) {
        double next = fmin(phi_target, (floor(phi / every + 1e-9) + 1.0) * every);
        rc = odhs_stepper_run_until_packing_fraction(st, next);
        odhs_system_packing_fraction(sys, &phi);
        double p = 0, z = 0;
        uint64_t nc = 0, no = 0;
        odhs_stepper_pressure(st, &p);
        odhs_stepper_coordination(st, &z);
        odhs_stepper_counts(st, NULL, &nc, &no);
        printf("%10.6f %14.6e %8.4f %10llu\n", phi, p, z, (unsigned long long)(nc + no));
        if (csv) fprintf(csv, "%.12g,%.10g,%.6f,%llu\n", phi, p, z, (unsigned long long)(nc + no));
        cli_plot_row(&pl, (double[]){phi, p, z, (double)(nc + no)});
        if (cli_traj_output(&tr, sys, st, phi)) {
            status = 1;
            break;
        }
        int jammed = rc == ODHS_JAMMED || rc == ODHS_POTENTIALLY_JAMMED;
        if (rc && !jammed) {
            cli_progress_break(&prog);
            fprintf(stderr, "compress: stopped: %s (%s)\n", odhs_strerror(rc), odhs_stepper_errmsg(st));
            status = 1;
            break;
        }
        int last = jammed || phi >= phi_target * (1 - 1e-12);
        cli_progress_show(&prog, phi - phi0, phi_target - phi0, last, "phi %.5f", phi);
        if (rc == ODHS_JAMMED) {
            if (!quiet)
                fprintf(stderr, "compress: jammed at phi = %.12f (z = %.4f; pressure normalised to 1)\n", phi, z);
            break;
        }
        if (rc == ODHS_POTENTIALLY_JAMMED) {
            if (!quiet)
                fprintf(stderr, "compress: potentially jammed at phi = %.10f (z = %.4f): %s\n", phi, z,
                        odhs_stepper_errmsg(st));
            break;
        }
        if (last) break;
    }
    if (!status && rc != ODHS_JAMMED) {
        rc = odhs_stepper_correct(st);
        if (rc < 0) fprintf(stderr, "compress: final correction: %s\n", odhs_stepper_errmsg(st));
    }
    if (csv) fclose(csv);
    if (cli_traj_close(&tr) || cli_plot_write(&pl, cli.prog, plot)) status = 1;
    if (outpath && cli_write_config(cli.prog, sys, outpath)) status = 1;
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(solver);
    odhs_system_destroy(sys);
    return status;
}
