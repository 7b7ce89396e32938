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

/* the --series columns (columns are only ever added, at the end) */
#define SERIES "strain,shear_stress,pressure,z,events,phi,kappa,time,collisions,openings,dissipation"
/* ... with --oscillate, and the --strobe columns */
#define SERIES_OSC "time,strain,shear_stress,pressure,z,events,phi,kappa,collisions,openings,dissipation"
#define STROBE "cycle,strobe_rms,from_start,events"
#define UNITS                                                                                                        \
    "strain and time 1/gammadot; shear_stress, pressure gammadot/xi0 (2D per length, 3D per area); kappa "          \
    "compression rate/gammadot; dissipation lambda^2 gammadot^2/xi0 (lambda the small diameter); z, events, "       \
    "collisions, openings, phi dimensionless"

/* what the outputs share: the series file, the progress line, the
 * trajectory and the plot's points */
typedef struct {
    FILE *csv;
    cli_progress prog;
    cli_traj traj;
    pl_plot panel[4]; /* stresses, z, and under pressure phi and kappa */
    int npanel;
    int fixed_p;
} outputs;

/* one output row: the table on stdout, the series row, a trajectory frame
 * when due, the plot's points; x is the strain (or the time of an
 * oscillation); 0, or 1 after an error (reported) */
static int output(outputs *o, odhs_stepper *st, odhs_system *sys, double x, double g, double t, int osc)
{
    double s, p, z, kappa, phi, D = NAN;
    uint64_t steps, nc, no;
    odhs_stepper_shear_stress(st, &s);
    odhs_stepper_pressure(st, &p);
    odhs_stepper_coordination(st, &z);
    odhs_stepper_kappa(st, &kappa);
    odhs_stepper_dissipation(st, &D);
    odhs_stepper_counts(st, &steps, &nc, &no);
    odhs_system_packing_fraction(sys, &phi);
    unsigned long long ev = (unsigned long long)(nc + no);
    if (osc) printf("%12.6f %12.6f %14.6e %14.6e %8.4f %10llu\n", t, g, s, p, z, ev);
    else if (o->fixed_p) printf("%12.6f %14.6e %14.6e %8.4f %10llu %10.6f %14.6e\n", g, s, p, z, ev, phi, kappa);
    else printf("%12.6f %14.6e %14.6e %8.4f %10llu\n", g, s, p, z, ev);
    if (o->csv && osc)
        fprintf(o->csv, "%.10g,%.10g,%.10g,%.10g,%.6f,%llu,%.10g,%.10g,%llu,%llu,%.10g\n", t, g, s, p, z, ev, phi,
                kappa, (unsigned long long)nc, (unsigned long long)no, D);
    else if (o->csv)
        fprintf(o->csv, "%.10g,%.10g,%.10g,%.6f,%llu,%.10g,%.10g,%.10g,%llu,%llu,%.10g\n", g, s, p, z, ev, phi, kappa,
                t, (unsigned long long)nc, (unsigned long long)no, D);
    if (o->npanel) {
        pl_point(&o->panel[0], 0, x, s);
        pl_point(&o->panel[0], 1, x, p);
        pl_point(&o->panel[1], 0, x, z);
        if (o->npanel > 2) {
            pl_point(&o->panel[2], 0, x, phi);
            pl_point(&o->panel[3], 0, x, kappa);
        }
    }
    return cli_traj_output(&o->traj, sys, st, x);
}

#define CHECK(call)                                                                             \
    do {                                                                                        \
        int rc_ = (call);                                                                       \
        if (rc_ < 0) {                                                                          \
            fprintf(stderr, "shear_flow: %s failed: %s\n", #call, odhs_strerror(rc_));          \
            return 1;                                                                           \
        }                                                                                       \
    } while (0)

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
static int run_oscillation(odhs_stepper *st, odhs_system *sys, const oscillation *o, outputs *out)
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
                cli_progress_break(&out->prog);
                fprintf(stderr, "shear_flow: stopped at time %.6g: %s (%s)\n", t, odhs_strerror(s),
                        odhs_stepper_errmsg(st));
                rc = 1;
                break;
            }
            double g;
            uint64_t steps, nc, no;
            odhs_stepper_strain(st, &g);
            odhs_stepper_counts(st, &steps, &nc, &no);
            if (output(out, st, sys, t, g, t, 1)) {
                rc = 1;
                break;
            }
            double total = o->period * (double)o->cycles;
            cli_progress_show(&out->prog, t, total, 0, "cycle %lu / %lu, %llu steps, %llu events", c + 1, o->cycles,
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
    if (!rc) cli_progress_show(&out->prog, 1, 1, 1, "%lu cycles done", o->cycles);
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
static int run_strain(odhs_stepper *st, odhs_system *sys, double strain, double every, outputs *o)
{
    int failed = 0;
    printf("%12s %14s %14s %8s %10s%s\n", "strain", "shear_stress", "pressure", "z", "events",
           o->fixed_p ? "        phi          kappa" : "");
    double g0, t;
    odhs_stepper_strain(st, &g0);
    long nout = (long)ceil(strain / every - 1e-9);
    for (long k = 0; k <= nout && !failed; ++k) {
        double target = g0 + fmin(k * every, strain);
        if (k > 0) {
            int rc = odhs_stepper_run_until_strain(st, target);
            if (rc) {
                double g;
                odhs_stepper_strain(st, &g);
                cli_progress_break(&o->prog);
                fprintf(stderr, "shear_flow: stopped at strain %.6g of %.6g: %s (%s)\n", g - g0, strain,
                        odhs_strerror(rc), odhs_stepper_errmsg(st));
                failed = rc < 0 ? 1 : 3;
                break;
            }
        }
        double g;
        uint64_t steps, nc, no;
        odhs_stepper_strain(st, &g);
        odhs_stepper_time(st, &t);
        odhs_stepper_counts(st, &steps, &nc, &no);
        if (output(o, st, sys, g - g0, g - g0, t, 0)) failed = 1;
        cli_progress_show(&o->prog, g - g0, strain, k == nout, "strain %.4f / %.4f, %llu steps, %llu events", g - g0,
                          strain, (unsigned long long)steps, (unsigned long long)(nc + no));
    }
    return failed;
}

/* the --plot panels: stresses and z against x, under pressure phi and kappa
 * too (the paper's Figs. 4 and 7) */
static void plot_init(outputs *o, const char *xlabel, int dim, size_t n, double pressure)
{
    char title[160];
    snprintf(title, sizeof title, "%dD, N = %zu, %s", dim, n, pressure > 0 ? "fixed pressure" : "fixed volume");
    if (pressure > 0) snprintf(title + strlen(title), sizeof title - strlen(title), " p = %g", pressure);
    pl_init(&o->panel[0], title, xlabel, "stress (gammadot/xi0)", 0, 0);
    pl_series_add(&o->panel[0], "shear stress", 0, 0, 0);
    pl_series_add(&o->panel[0], "pressure", 1, 0, 0);
    pl_init(&o->panel[1], "", xlabel, "coordination z", 0, 0);
    pl_series_add(&o->panel[1], "z", 2, 0, 0);
    o->npanel = 2;
    if (pressure > 0) {
        pl_init(&o->panel[2], "", xlabel, "packing fraction", 0, 0);
        pl_series_add(&o->panel[2], "phi", 3, 0, 0);
        pl_init(&o->panel[3], "", xlabel, "kappa (compression rate / gammadot)", 0, 0);
        pl_series_add(&o->panel[3], "kappa", 4, 0, 0);
        o->npanel = 4;
    }
}

int main(int argc, char **argv)
{
    const char *in = NULL, *outpath = NULL, *series = NULL, *svg = NULL, *solver_name = CLI_DEFAULT_SOLVER;
    const char *traj = NULL, *traj_contacts = NULL, *plot = NULL, *contacts = NULL;
    double strain = 0.2, every = 0.01, dt = 0.0, pressure = 0.0, phi = 0.80, tol = 0.0, traj_every = 0.0;
    unsigned long n = 256, seed = 1;
    int dim = 2, integrator = CLI_DEFAULT_INTEGRATOR, shape = 0, quiet = 0;
    const char *oscillate = NULL;
    oscillation osc = {0, 0, 4, 40, NULL};
    const cli_opt opts[] = {
        CLI_IN(&in),
        CLI_STRAIN(&strain),
        CLI_OUT(&outpath),
        CLI_SVG(&svg),
        CLI_OPT_STRING("--series", &series, "FILE.csv", "write a CSV row per output (the columns below)", CLI_ANY),
        CLI_OPT_STRING("--plot", &plot, "FILE.svg",
                       "plot the outputs: stresses and z against strain (time with --oscillate), with --pressure phi "
                       "and kappa too",
                       CLI_ANY),
        CLI_EVERY(&every, "strain"),
        CLI_TRAJ(&traj),
        CLI_TRAJ_EVERY(&traj_every, "strain (time with --oscillate)"),
        CLI_TRAJ_CONTACTS(&traj_contacts),
        CLI_CONTACTS(&contacts),
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
        CLI_QUIET(&quiet),
        CLI_END,
    };
    const cli_spec cli = {"shear_flow", NULL, opts,
                          "Series columns: strain, shear_stress, pressure, z, events, phi, kappa, time,\n"
                          "collisions, openings, dissipation (with --oscillate: time first, then strain,\n"
                          "...; no second time), after the header a \"# units\" comment line.\n"
                          "The defaults are the library's (adaptive Heun, the auto solver); paper mode,\n"
                          "the paper's fixed-step scheme and solver: --integrator euler --solver cg.\n"
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
    if (in ? cli_read_xyz(cli.prog, in, &sys) : cli_compressed_scene(cli.prog, dim, n, phi, seed, solver, quiet, &sys)) return 1;
    double phi_now;
    CHECK(odhs_system_packing_fraction(sys, &phi_now));
    n = odhs_system_count(sys);
    if (!quiet)
        fprintf(stderr, "shear_flow: N = %lu, d = %d, phi = %.6f, %s, solver %s%s\n", n, odhs_system_dim(sys),
                phi_now, cli_integrators[integrator], odhs_solver_name(solver),
                pressure > 0 ? ", fixed pressure" : ", fixed volume");

    odhs_driver *drv;
    odhs_stepper *st;
    CHECK(odhs_driver_create(&drv));
    if (oscillate) CHECK(odhs_driver_set_oscillatory_shear(drv, shape, osc.amp, osc.period, 0.0));
    else CHECK(odhs_driver_set_shear_rate(drv, 1.0));
    if (pressure > 0) CHECK(odhs_driver_set_pressure(drv, pressure));
    CHECK(odhs_stepper_create(sys, drv, solver, &st));
    CHECK(cli_set_dt(st, dt));
    CHECK(odhs_stepper_set_integrator(st, integrator));
    CHECK(cli_set_tolerance(st, tol));
    rc = odhs_stepper_reset(st);
    if (rc) {
        fprintf(stderr, "shear_flow: %s\n", odhs_stepper_errmsg(st));
        return 1;
    }

    FILE *csv;
    if (cli_series_units(cli.prog, series, oscillate ? SERIES_OSC : SERIES, UNITS, &csv)) return 1;
    outputs out = {.csv = csv, .fixed_p = pressure > 0};
    cli_progress_init(&out.prog, cli.prog, quiet);
    if ((rc = cli_traj_open(&out.traj, cli.prog, traj, traj_contacts, traj_every))) return rc;
    if (plot) plot_init(&out, oscillate ? "time (1/gammadot)" : "strain", odhs_system_dim(sys), n, pressure);
    int failed = oscillate ? run_oscillation(st, sys, &osc, &out) : run_strain(st, sys, strain, every, &out);
    double gap, ov;
    odhs_stepper_errors(st, &gap, &ov);
    if (!quiet)
        fprintf(stderr, "shear_flow: worst contact gap %.3g, worst overlap %.3g (relative to contact distance)\n",
                gap, ov);
    if (csv && fclose(csv)) {
        fprintf(stderr, "shear_flow: error writing %s\n", series);
        return 1;
    }
    if (cli_traj_close(&out.traj)) return 1;
    if (plot) {
        const pl_plot *panels[4] = {&out.panel[0], &out.panel[1], &out.panel[2], &out.panel[3]};
        int bad = pl_write_svg_panels(panels, out.npanel, plot);
        for (int k = 0; k < out.npanel; ++k) pl_free(&out.panel[k]);
        if (bad) {
            fprintf(stderr, "shear_flow: cannot write %s\n", plot);
            return 1;
        }
    }
    if (contacts && odhs_contacts_write_csv(odhs_stepper_network(st), sys, contacts)) {
        fprintf(stderr, "shear_flow: cannot write %s: %s\n", contacts, odhs_network_errmsg(odhs_stepper_network(st)));
        return 1;
    }
    if (svg) {
        int w = odhs_svg_write(sys, odhs_stepper_network(st), NULL, svg);
        if (w) {
            fprintf(stderr, "shear_flow: cannot write %s: %s\n", svg, odhs_system_errmsg(sys));
            return 1;
        }
    }
    if (outpath && cli_write_config(cli.prog, sys, outpath)) return 1;
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(solver);
    odhs_solver_destroy(rescue);
    odhs_system_destroy(sys);
    return failed ? failed : rc < 0 ? 1 : 0;
}
