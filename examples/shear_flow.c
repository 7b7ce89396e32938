/* shear_flow - simple shear of overdamped hard discs/spheres with libodhs.
 *
 * With no arguments: builds the paper's scene (N = 256 discs, 50:50 bidisperse
 * radii 0.5/0.7 with 3% polydispersity, phi = 0.80), shears it to a strain of
 * 0.2 at fixed volume, prints progress to stderr and a table of strain, shear
 * stress, pressure, z and events to stdout.
 *
 * Build against an installed libodhs:
 *     cc shear_flow.c $(pkg-config --cflags --libs odhs) -lm -o shear_flow
 */
#include <math.h>
#include <stdio.h>

#include <odhs.h>

#include "cli.h"

/* the --series columns */
#define SERIES "strain,shear_stress,pressure,z,events"

#define CHECK(call)                                                                             \
    do {                                                                                        \
        int rc_ = (call);                                                                       \
        if (rc_ < 0) {                                                                          \
            fprintf(stderr, "shear_flow: %s failed: %s\n", #call, odhs_strerror(rc_));          \
            return 1;                                                                           \
        }                                                                                       \
    } while (0)

/* Build the default scene: RSA at a low packing fraction, then event-driven
 * isotropic compression to phi. */
static int build_scene(int dim, unsigned long n, double phi, unsigned long seed, odhs_solver *solver,
                       odhs_system **out)
{
    odhs_system *sys = NULL;
    double phi0 = dim == 2 ? 0.45 : 0.3;
    if (phi < phi0) phi0 = phi;
    int rc = cli_scene(dim, n, seed, phi, &sys);
    if (rc) {
        fprintf(stderr, "shear_flow: %s\n", sys ? odhs_system_errmsg(sys) : odhs_strerror(rc));
        return 1;
    }
    if (phi > phi0) {
        odhs_driver *drv;
        odhs_stepper *st;
        CHECK(odhs_driver_create(&drv));
        CHECK(odhs_driver_set_compression_rate(drv, 1.0));
        CHECK(odhs_stepper_create(sys, drv, solver, &st));
        CHECK(odhs_stepper_set_dt(st, 1e-3));
        fprintf(stderr, "shear_flow: compressing from phi = %.3f to %.3f\n", phi0, phi);
        rc = odhs_stepper_run_until_packing_fraction(st, phi);
        if (rc) {
            fprintf(stderr, "shear_flow: compression stopped: %s (%s)\n", odhs_strerror(rc),
                    odhs_stepper_errmsg(st));
            return 1;
        }
        /* contacts back to exact touching, so the shear run starts from them */
        rc = odhs_stepper_correct(st);
        if (rc < 0) {
            fprintf(stderr, "shear_flow: %s\n", odhs_stepper_errmsg(st));
            return 1;
        }
        odhs_stepper_destroy(st);
        odhs_driver_destroy(drv);
    }
    *out = sys;
    return 0;
}

int main(int argc, char **argv)
{
    const char *in = NULL, *outpath = NULL, *series = NULL, *svg = NULL, *solver_name = "cg";
    double strain = 0.2, every = 0.01, dt = 1e-3, pressure = 0.0, phi = 0.80, tol = 1e-6;
    unsigned long n = 256, seed = 1;
    int dim = 2, integrator = ODHS_INTEGRATOR_EULER;
    const cli_opt opts[] = {
        CLI_IN(&in),
        CLI_STRAIN(&strain),
        CLI_OUT(&outpath),
        CLI_SVG(&svg),
        CLI_SERIES(&series, SERIES),
        CLI_EVERY(&every, "strain"),
        CLI_DT(&dt, "strain units"),
        CLI_INTEGRATOR(&integrator),
        CLI_TOL(&tol),
        CLI_SOLVER(&solver_name),
        CLI_OPT_DOUBLE("--pressure", &pressure, "P", "shear at fixed pressure P instead of fixed volume", CLI_POSITIVE,
                       .deftext = ""),
        CLI_PHI(&phi),
        CLI_SCENE(&n, &dim, &seed),
        CLI_END,
    };
    const cli_spec cli = {"shear_flow", NULL, opts,
                          "The default solver and integrator, cg and euler, are the paper's choices.\n"
                          "Forces are in units of lambda*gammadot/xi0 with lambda the small diameter;\n"
                          "stresses in units of gammadot/xi0 (2D: per length, 3D: per area).\n",
                          0};
    int rc = cli_parse(&cli, argc, argv);
    if (rc != CLI_GO) return rc;

    odhs_solver *solver;
    if ((rc = cli_solver(cli.prog, solver_name, &solver))) return rc;

    odhs_system *sys = NULL;
    if (in ? cli_read_xyz(cli.prog, in, &sys) : build_scene(dim, n, phi, seed, solver, &sys)) return 1;
    double phi_now;
    CHECK(odhs_system_packing_fraction(sys, &phi_now));
    n = odhs_system_count(sys);
    fprintf(stderr, "shear_flow: N = %lu, d = %d, phi = %.6f, solver %s%s\n", n, odhs_system_dim(sys),
            phi_now, odhs_solver_name(solver), pressure > 0 ? ", fixed pressure" : ", fixed volume");

    odhs_driver *drv;
    odhs_stepper *st;
    CHECK(odhs_driver_create(&drv));
    CHECK(odhs_driver_set_shear_rate(drv, 1.0));
    if (pressure > 0) CHECK(odhs_driver_set_pressure(drv, pressure));
    CHECK(odhs_stepper_create(sys, drv, solver, &st));
    CHECK(odhs_stepper_set_dt(st, dt));
    CHECK(odhs_stepper_set_integrator(st, integrator));
    CHECK(odhs_stepper_set_tolerance(st, tol));
    rc = odhs_stepper_reset(st);
    if (rc) {
        fprintf(stderr, "shear_flow: %s\n", odhs_stepper_errmsg(st));
        return 1;
    }

    FILE *csv;
    if (cli_series(cli.prog, series, SERIES, &csv)) return 1;
    printf("%12s %14s %14s %8s %10s%s\n", "strain", "shear_stress", "pressure", "z", "events",
           pressure > 0 ? "        phi" : "");
    double g0;
    odhs_stepper_strain(st, &g0);
    long nout = (long)ceil(strain / every - 1e-9);
    for (long k = 0; k <= nout; ++k) {
        double target = g0 + fmin(k * every, strain);
        if (k > 0) {
            rc = odhs_stepper_run_until_strain(st, target);
            if (rc) {
                fprintf(stderr, "shear_flow: stopped at strain %.6g: %s (%s)\n", target, odhs_strerror(rc),
                        odhs_stepper_errmsg(st));
                break;
            }
        }
        double g, s, p, z;
        uint64_t steps, nc, no;
        odhs_stepper_strain(st, &g);
        odhs_stepper_shear_stress(st, &s);
        odhs_stepper_pressure(st, &p);
        odhs_stepper_coordination(st, &z);
        odhs_stepper_counts(st, &steps, &nc, &no);
        odhs_system_packing_fraction(sys, &phi_now);
        if (pressure > 0)
            printf("%12.6f %14.6e %14.6e %8.4f %10llu %10.6f\n", g - g0, s, p, z,
                   (unsigned long long)(nc + no), phi_now);
        else
            printf("%12.6f %14.6e %14.6e %8.4f %10llu\n", g - g0, s, p, z, (unsigned long long)(nc + no));
        if (csv) fprintf(csv, "%.10g,%.10g,%.10g,%.6f,%llu\n", g - g0, s, p, z, (unsigned long long)(nc + no));
        fprintf(stderr, "\rshear_flow: strain %.4f / %.4f, %llu steps, %llu events", g - g0, strain,
                (unsigned long long)steps, (unsigned long long)(nc + no));
    }
    fprintf(stderr, "\n");
    double gap, ov;
    odhs_stepper_errors(st, &gap, &ov);
    fprintf(stderr, "shear_flow: worst contact gap %.3g, worst overlap %.3g (relative to contact distance)\n",
            gap, ov);
    if (csv && fclose(csv)) {
        fprintf(stderr, "shear_flow: error writing %s\n", series);
        return 1;
    }
    if (svg) {
        int w = odhs_svg_write(sys, odhs_stepper_network(st), NULL, svg);
        if (w) {
            fprintf(stderr, "shear_flow: cannot write %s: %s\n", svg, odhs_system_errmsg(sys));
            return 1;
        }
    }
    if (outpath) {
        rc = odhs_xyz_write(sys, outpath);
        if (rc) {
            fprintf(stderr, "shear_flow: cannot write %s: %s\n", outpath, odhs_system_errmsg(sys));
            return 1;
        }
    }
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(solver);
    odhs_system_destroy(sys);
    return rc < 0 ? 1 : 0;
}
