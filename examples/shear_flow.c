/* shear_flow - simple shear of overdamped hard discs/spheres with libodhs.
 *
 * With no arguments: builds the paper's scene (N = 256 discs, 50:50 bidisperse
 * radii 0.5/0.7 with 3% polydispersity, phi = 0.80), shears it to a strain of
 * 0.2 at fixed volume, prints progress to stderr and a table of strain, shear
 * stress, pressure, z and events to stdout.
 *
 * --oscillate A,T[,SHAPE] shears back and forth instead: strain amplitude A,
 * period T (time; the rate scale is the peak rate), SHAPE sine (default) or
 * triangle (a constant rate reversing every half period), for --cycles
 * periods with --per-cycle outputs each (time, strain, stress, ...), and
 * after every cycle the stroboscopic displacement: the rms distance of the
 * particles from where they were one period before (and from the start),
 * the reversibility measure of periodically sheared suspensions.
 *
 * Build against an installed libodhs:
 *     cc shear_flow.c $(pkg-config --cflags --libs odhs) -lm -o shear_flow
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <odhs.h>

#include "cli.h"

/* the --series columns */
#define SERIES "strain,shear_stress,pressure,z,events"
/* ... at fixed pressure: the two panels of the paper's Fig. 7 as well */
#define SERIES_P "strain,shear_stress,pressure,z,events,phi,kappa"
/* ... with --oscillate, and the --strobe columns */
#define SERIES_OSC "time,strain,shear_stress,pressure,z,events"
#define STROBE "cycle,strobe_rms,from_start,events"

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

/* --oscillate A,T[,sine|triangle]; 0 on success */
static int parse_oscillate(const char *arg, double *amp, double *period, int *shape)
{
    char buf[128], *save = NULL;
    if (strlen(arg) >= sizeof buf) return -1;
    strcpy(buf, arg);
    char *a = strtok_r(buf, ",", &save), *t = strtok_r(NULL, ",", &save), *sh = strtok_r(NULL, ",", &save);
    if (!a || !t || strtok_r(NULL, ",", &save)) return -1;
    if (cli_double(a, amp) || cli_double(t, period) || !(*amp > 0.0) || !(*period > 0.0)) return -1;
    *shape = ODHS_OSCILLATION_SINE;
    if (sh && !strcmp(sh, "triangle")) *shape = ODHS_OSCILLATION_TRIANGLE;
    else if (sh && strcmp(sh, "sine")) return -1;
    return 0;
}

/* rms over particles of the minimum-image displacement from a to b */
static double rms_displacement(const odhs_system *sys, const double *a, const double *b)
{
    size_t n = odhs_system_count(sys);
    int dim = odhs_system_dim(sys);
    double L[3], g, s = 0.0;
    odhs_system_get_box(sys, L);
    odhs_system_get_strain(sys, &g);
    for (size_t i = 0; i < n; ++i) {
        double d[3] = {0, 0, 0};
        for (int k = 0; k < dim; ++k) d[k] = b[i * dim + k] - a[i * dim + k];
        double ny = nearbyint(d[1] / L[1]); /* Lees-Edwards: an image in y shifts x by g Ly */
        d[1] -= ny * L[1];
        d[0] -= ny * g * L[1];
        d[0] -= nearbyint(d[0] / L[0]) * L[0];
        if (dim == 3) d[2] -= nearbyint(d[2] / L[2]) * L[2];
        for (int k = 0; k < dim; ++k) s += d[k] * d[k];
    }
    return sqrt(s / (double)n);
}

typedef struct {
    double amp, period;
    unsigned long cycles, per_cycle;
    const char *strobe;
} oscillation;

/* the oscillatory run: outputs per cycle, stroboscopic displacement after
 * each; 0, or 1 after an error (reported) */
static int run_oscillation(odhs_stepper *st, odhs_system *sys, const oscillation *o, FILE *csv)
{
    size_t nd = odhs_system_count(sys) * (size_t)odhs_system_dim(sys);
    double *x0 = malloc(nd * sizeof *x0), *xp = malloc(nd * sizeof *xp), *x = malloc(nd * sizeof *x);
    FILE *sf = NULL;
    int rc = !x0 || !xp || !x;
    if (!rc && cli_series("shear_flow", o->strobe, STROBE, &sf)) rc = 1;
    if (!rc) {
        odhs_system_get_positions(sys, x0);
        memcpy(xp, x0, nd * sizeof *xp);
        printf("%12s %12s %14s %14s %8s %10s\n", "time", "strain", "shear_stress", "pressure", "z", "events");
    }
    for (unsigned long c = 0; !rc && c < o->cycles; ++c) {
        for (unsigned long k = c ? 1 : 0; k <= o->per_cycle; ++k) {
            double t = o->period * ((double)c + (double)k / (double)o->per_cycle);
            int s = odhs_stepper_run_until_time(st, t);
            if (s) {
                fprintf(stderr, "\nshear_flow: stopped at time %.6g: %s (%s)\n", t, odhs_strerror(s),
                        odhs_stepper_errmsg(st));
                rc = 1;
                break;
            }
            double g, sxy, p, z;
            uint64_t steps, nc, no;
            odhs_stepper_strain(st, &g);
            odhs_stepper_shear_stress(st, &sxy);
            odhs_stepper_pressure(st, &p);
            odhs_stepper_coordination(st, &z);
            odhs_stepper_counts(st, &steps, &nc, &no);
            printf("%12.6f %12.6f %14.6e %14.6e %8.4f %10llu\n", t, g, sxy, p, z, (unsigned long long)(nc + no));
            if (csv) fprintf(csv, "%.10g,%.10g,%.10g,%.10g,%.6f,%llu\n", t, g, sxy, p, z, (unsigned long long)(nc + no));
            fprintf(stderr, "\rshear_flow: cycle %lu / %lu, %llu steps, %llu events", c + 1, o->cycles,
                    (unsigned long long)steps, (unsigned long long)(nc + no));
        }
        if (rc) break;
        odhs_system_get_positions(sys, x);
        double d = rms_displacement(sys, xp, x), d0 = rms_displacement(sys, x0, x);
        uint64_t nc, no;
        odhs_stepper_counts(st, NULL, &nc, &no);
        printf("# cycle %lu: stroboscopic rms displacement %.6e, from the start %.6e\n", c + 1, d, d0);
        if (sf) fprintf(sf, "%lu,%.10g,%.10g,%llu\n", c + 1, d, d0, (unsigned long long)(nc + no));
        memcpy(xp, x, nd * sizeof *xp);
    }
    fprintf(stderr, "\n");
    if (sf && fclose(sf) && !rc) {
        fprintf(stderr, "shear_flow: error writing %s\n", o->strobe);
        rc = 1;
    }
    free(x0);
    free(xp);
    free(x);
    return rc;
}

/* the run at a constant rate to the strain target, an output every `every`;
 * 0 when it reached the target, 3 when it stopped before (jammed; the
 * reason is reported), 1 after an error (reported) */
static int run_strain(odhs_stepper *st, odhs_system *sys, double strain, double every, int fixed_p, FILE *csv)
{
    int failed = 0;
    printf("%12s %14s %14s %8s %10s%s\n", "strain", "shear_stress", "pressure", "z", "events",
           fixed_p ? "        phi          kappa" : "");
    double g0;
    odhs_stepper_strain(st, &g0);
    long nout = (long)ceil(strain / every - 1e-9);
    for (long k = 0; k <= nout; ++k) {
        double target = g0 + fmin(k * every, strain);
        if (k > 0) {
            int rc = odhs_stepper_run_until_strain(st, target);
            if (rc) {
                double g;
                odhs_stepper_strain(st, &g);
                fprintf(stderr, "\nshear_flow: stopped at strain %.6g of %.6g: %s (%s)\n", g - g0, strain,
                        odhs_strerror(rc), odhs_stepper_errmsg(st));
                failed = rc < 0 ? 1 : 3;
                break;
            }
        }
        double g, s, p, z, kappa;
        uint64_t steps, nc, no;
        odhs_stepper_strain(st, &g);
        odhs_stepper_shear_stress(st, &s);
        odhs_stepper_pressure(st, &p);
        odhs_stepper_coordination(st, &z);
        odhs_stepper_kappa(st, &kappa);
        odhs_stepper_counts(st, &steps, &nc, &no);
        double phi_now;
        odhs_system_packing_fraction(sys, &phi_now);
        unsigned long long ev = (unsigned long long)(nc + no);
        if (fixed_p) {
            printf("%12.6f %14.6e %14.6e %8.4f %10llu %10.6f %14.6e\n", g - g0, s, p, z, ev, phi_now, kappa);
            if (csv) fprintf(csv, "%.10g,%.10g,%.10g,%.6f,%llu,%.10g,%.10g\n", g - g0, s, p, z, ev, phi_now, kappa);
        } else {
            printf("%12.6f %14.6e %14.6e %8.4f %10llu\n", g - g0, s, p, z, ev);
            if (csv) fprintf(csv, "%.10g,%.10g,%.10g,%.6f,%llu\n", g - g0, s, p, z, ev);
        }
        fprintf(stderr, "\rshear_flow: strain %.4f / %.4f, %llu steps, %llu events", g - g0, strain,
                (unsigned long long)steps, ev);
    }
    fprintf(stderr, "\n");
    return failed;
}

int main(int argc, char **argv)
{
    const char *in = NULL, *outpath = NULL, *series = NULL, *svg = NULL, *solver_name = "cg";
    double strain = 0.2, every = 0.01, dt = 1e-3, pressure = 0.0, phi = 0.80, tol = 1e-6;
    unsigned long n = 256, seed = 1;
    int dim = 2, integrator = ODHS_INTEGRATOR_EULER, shape = 0;
    const char *oscillate = NULL;
    oscillation osc = {0, 0, 4, 40, NULL};
    const cli_opt opts[] = {
        CLI_IN(&in),
        CLI_STRAIN(&strain),
        CLI_OUT(&outpath),
        CLI_SVG(&svg),
        CLI_SERIES(&series, SERIES "; with --pressure also phi,kappa"),
        CLI_EVERY(&every, "strain"),
        CLI_DT(&dt, "strain units"),
        CLI_INTEGRATOR(&integrator),
        CLI_TOL(&tol),
        CLI_SOLVER(&solver_name),
        CLI_OPT_DOUBLE("--pressure", &pressure, "P", "shear at fixed pressure P instead of fixed volume", CLI_POSITIVE,
                       .deftext = ""),
        CLI_OPT_STRING("--oscillate", &oscillate, "A,T[,SHAPE]",
                       "oscillatory shear of strain amplitude A and period T instead of --strain; SHAPE sine "
                       "(the default) or triangle (a constant rate reversing every half period)",
                       .deftext = ""),
        CLI_OPT_ULONG("--cycles", &osc.cycles, "C", "with --oscillate: number of periods", CLI_ATLEAST(1)),
        CLI_OPT_ULONG("--per-cycle", &osc.per_cycle, "K", "with --oscillate: outputs per period", CLI_ATLEAST(1)),
        CLI_OPT_STRING("--strobe", &osc.strobe, "FILE.csv",
                       "with --oscillate: write " STROBE " after every period", CLI_ANY),
        CLI_PHI(&phi),
        CLI_SCENE(&n, &dim, &seed),
        CLI_END,
    };
    const cli_spec cli = {"shear_flow", NULL, opts,
                          "The default solver and integrator, cg and euler, are the paper's choices.\n"
                          "Forces are in units of lambda*gammadot/xi0 with lambda the small diameter;\n"
                          "stresses in units of gammadot/xi0 (2D: per length, 3D: per area).\n"
                          "With --pressure P the volume follows the pressure (kappa: compression rate\n"
                          "over shear rate, < 0 dilating) and the flow never stops at a finite P; the\n"
                          "viscous number is I_v = 1/P. With --pressure, cg hands the solves it cannot\n"
                          "do (near isostatic networks) to auto. Exit status: 0 when the requested\n"
                          "strain was reached, 3 when the run stopped before it (the reason on stderr),\n"
                          "1 on error.\n",
                          0};
    int rc = cli_parse(&cli, argc, argv);
    if (rc != CLI_GO) return rc;
    if (oscillate && parse_oscillate(oscillate, &osc.amp, &osc.period, &shape)) {
        fprintf(stderr, "shear_flow: --oscillate wants A,T[,sine|triangle] with A > 0 and T > 0, got '%s'\n",
                oscillate);
        cli_usage(&cli, stderr);
        return 2;
    }
    if (oscillate && pressure > 0) {
        fprintf(stderr, "shear_flow: --oscillate and --pressure cannot be combined\n");
        return 2;
    }

    odhs_solver *solver, *rescue = NULL;
    if ((rc = cli_solver(cli.prog, solver_name, &solver))) return rc;
    if (pressure > 0 && !strcmp(solver_name, "cg")) {
        /* at fixed pressure the flow passes through (nearly) isostatic
         * networks, where CG alone does not converge: the solves it fails go
         * to the automatic choice (odhs_solver_set_fallback) */
        CHECK(odhs_solver_create_by_name("auto", &rescue));
        CHECK(odhs_solver_set_fallback(solver, rescue));
    }

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
    if (oscillate) CHECK(odhs_driver_set_oscillatory_shear(drv, shape, osc.amp, osc.period, 0.0));
    else CHECK(odhs_driver_set_shear_rate(drv, 1.0));
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
    if (cli_series(cli.prog, series, oscillate ? SERIES_OSC : pressure > 0 ? SERIES_P : SERIES, &csv)) return 1;
    int failed = oscillate ? run_oscillation(st, sys, &osc, csv) : run_strain(st, sys, strain, every, pressure > 0, csv);
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
    odhs_solver_destroy(rescue);
    odhs_system_destroy(sys);
    return failed ? failed : rc < 0 ? 1 : 0;
}
