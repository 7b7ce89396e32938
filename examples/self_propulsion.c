/* self_propulsion - overdamped self-propelled hard discs (Sect. V B and
 * Fig. 8 of Lerner, During & Wyart 2013) with libodhs.
 *
 * With no arguments: N = 256 discs of mean diameter 1 with a uniform 3%
 * polydispersity, placed at random at phi = 0.5; every disc carries a
 * propulsion force of uniformly random direction and magnitude uniform in
 * [0, sqrt(3)] (so f_ext = sqrt(<F|F>/N) = 1 on average), redrawn after a
 * persistence time uniform in [0, 10] tau, tau = lambda/(f_ext xi0). Runs for
 * 20 tau, prints a table of time, mean speed, pressure, z and events to
 * stdout and progress to stderr; --svg draws the final state like Fig. 8
 * (discs coloured by size, contact forces as lines of width proportional to
 * the force, and the propulsion forces as arrows).
 *
 * Build against an installed libodhs:
 *     cc self_propulsion.c $(pkg-config --cflags --libs odhs) -lm -o self_propulsion
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <odhs.h>

#include "cli.h"

/* the --series columns */
#define SERIES "time,mean_speed,pressure,z,collisions,openings"

#define CHECK(call)                                                                             \
    do {                                                                                        \
        int rc_ = (call);                                                                       \
        if (rc_ < 0) {                                                                          \
            fprintf(stderr, "self_propulsion: %s failed: %s\n", #call, odhs_strerror(rc_));     \
            return 1;                                                                           \
        }                                                                                       \
    } while (0)

/* Add the propulsion forces as arrows to the picture odhs_svg_write made.
 * The mapping from box to picture coordinates is read from the cell outline
 * (the last polygon: corners (0,0), (Lx,0), (Lx+gamma Ly, Ly), (gamma Ly, Ly)). */
static int add_arrows(const char *path, const odhs_system *sys, const double *F, double lambda)
{
    FILE *f = fopen(path, "rb");
    if (!f) return -1;
    size_t cap = 1 << 20, len = 0;
    char *buf = malloc(cap + 1);
    while (buf) {
        size_t got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (len < cap) break;
        char *q = realloc(buf, 2 * cap + 1);
        if (!q) {
            free(buf);
            buf = NULL;
            break;
        }
        buf = q;
        cap *= 2;
    }
    fclose(f);
    if (!buf) return -1;
    buf[len] = '\0';
    char *poly = NULL, *p = buf;
    while ((p = strstr(p, "<polygon points=\"")) != NULL) poly = p++;
    char *end = poly ? strstr(poly, "</svg>") : NULL;
    double X[4], Y[4];
    if (!poly || !end ||
        sscanf(poly, "<polygon points=\"%lf,%lf %lf,%lf %lf,%lf %lf,%lf", &X[0], &Y[0], &X[1], &Y[1], &X[2], &Y[2],
               &X[3], &Y[3]) != 8) {
        free(buf);
        return -1;
    }
    double L[3], g;
    int dim = odhs_system_dim(sys);
    size_t n = odhs_system_count(sys);
    odhs_system_get_box(sys, L);
    odhs_system_get_strain(sys, &g);
    double s = (X[1] - X[0]) / L[0]; /* pixels per length */
    double *x = malloc(n * dim * sizeof *x);
    if (!x) {
        free(buf);
        return -1;
    }
    odhs_system_get_positions(sys, x);
    double fbig = 0.0;
    for (size_t i = 0; i < n; ++i) {
        double m = 0.0;
        for (int k = 0; k < 2; ++k) m += F[i * dim + k] * F[i * dim + k];
        fbig = fmax(fbig, sqrt(m));
    }
    f = fopen(path, "wb");
    if (!f) {
        free(x);
        free(buf);
        return -1;
    }
    int ok = fwrite(buf, 1, (size_t)(end - buf), f) == (size_t)(end - buf);
    ok &= fprintf(f, "<defs><marker id=\"head\" viewBox=\"0 0 10 10\" refX=\"9\" refY=\"5\" markerWidth=\"3.5\" "
                     "markerHeight=\"3.5\" orient=\"auto-start-reverse\"><path d=\"M 0 0 L 10 5 L 0 10 z\" "
                     "fill=\"#006d2c\"/></marker></defs>\n<g stroke=\"#006d2c\" stroke-width=\"%.2f\" "
                     "marker-end=\"url(#head)\">\n",
                  fmax(0.6, 0.05 * s * lambda)) > 0;
    for (size_t i = 0; i < n && ok && fbig > 0.0; ++i) {
        /* arrow from the centre, the largest force one diameter long */
        double x0 = X[0] + s * x[i * dim], y0 = Y[0] - s * x[i * dim + 1];
        double ax = s * lambda * F[i * dim] / fbig, ay = -s * lambda * F[i * dim + 1] / fbig;
        if (hypot(ax, ay) < 0.5) continue;
        ok &= fprintf(f, "<line x1=\"%.2f\" y1=\"%.2f\" x2=\"%.2f\" y2=\"%.2f\"/>\n", x0, y0, x0 + ax, y0 + ay) > 0;
    }
    ok &= fprintf(f, "</g>\n%s", end) > 0;
    ok &= fclose(f) == 0;
    free(x);
    free(buf);
    return ok ? 0 : -1;
}

int main(int argc, char **argv)
{
    const char *in = NULL, *outpath = NULL, *series = NULL, *plot = NULL;
    const char *svg = NULL, *solver_name = CLI_DEFAULT_SOLVER;
    const char *traj = NULL, *traj_contacts = NULL;
    double T = 20.0, tmax = 10.0, every = 1.0, dt = 1e-2, phi = 0.5, tol = 0.0, traj_every = 0.0;
    unsigned long n = 256, seed = 1;
    int dim = 2, integrator = CLI_DEFAULT_INTEGRATOR, quiet = 0;
    const cli_opt opts[] = {
        CLI_IN(&in),
        CLI_TIME(&T),
        CLI_OPT_DOUBLE("--tmax", &tmax, "X", "persistence times uniform in [0, X] tau", CLI_POSITIVE),
        CLI_EVERY(&every, "tau"),
        CLI_SERIES(&series, SERIES),
        CLI_PLOT(&plot),
        CLI_SVG(&svg),
        CLI_OUT(&outpath),
        CLI_TRAJ(&traj),
        CLI_TRAJ_EVERY(&traj_every, "tau"),
        CLI_TRAJ_CONTACTS(&traj_contacts),
        CLI_OPT_DOUBLE("--dt", &dt, "X", "step (heun, batched: largest step) in units of tau", CLI_POSITIVE),
        CLI_INTEGRATOR(&integrator),
        CLI_TOL(&tol),
        CLI_SOLVER(&solver_name),
        CLI_PHI(&phi),
        CLI_SCENE(&n, &dim, &seed),
        CLI_QUIET(&quiet),
        CLI_END,
    };
    const cli_spec cli = {
        "self_propulsion", NULL, opts,
        "The seed also draws the propulsion forces; steps also end at every switch of a\n"
        "propulsion force. The picture (--svg) is like Fig. 8 of the paper, with the\n"
        "propulsion forces as green arrows (2D).\n"
        "Lengths are in units of the mean diameter lambda, times in\n"
        "tau = lambda/(f_ext xi0), speeds in lambda/tau, pressure in f_ext/lambda^(d-1).\n"
        "Defaults are the library's (adaptive Heun, the auto solver); paper mode:\n"
        "--integrator euler --solver cg.\n",
        0};
    int rc = cli_parse(&cli, argc, argv);
    if (rc != CLI_GO) return rc;

    odhs_system *sys = NULL;
    if (in) {
        if (cli_read_xyz(cli.prog, in, &sys)) return 1;
    } else {
        /* uniform polydispersity: the "bidisperse" builder with ratio 1 */
        rc = odhs_system_create(dim, n, &sys);
        if (!rc) rc = odhs_system_set_radii_bidisperse(sys, 0.5, 1.0, 0.03, seed);
        if (!rc) rc = odhs_system_place_random(sys, phi, seed + 1);
        if (rc) {
            fprintf(stderr, "self_propulsion: building the scene: %s\n",
                    sys ? odhs_system_errmsg(sys) : odhs_strerror(rc));
            return 1;
        }
    }
    n = odhs_system_count(sys);
    int d = odhs_system_dim(sys);
    odhs_solver *solver;
    if ((rc = cli_solver(cli.prog, solver_name, &solver))) return rc;
    double phi_now, *r = malloc(n * sizeof *r), lambda = 0.0;
    CHECK(odhs_system_packing_fraction(sys, &phi_now));
    CHECK(odhs_system_get_radii(sys, r));
    for (size_t i = 0; i < n; ++i) lambda += 2.0 * r[i] / (double)n;
    free(r);

    odhs_driver *drv;
    odhs_stepper *st;
    CHECK(odhs_driver_create(&drv));
    /* magnitudes uniform in [0, sqrt(3)]: <|F|^2> = 1, so f_ext = 1 */
    CHECK(odhs_driver_set_self_propulsion(drv, n, d, 0.0, sqrt(3.0), 0.0, tmax, seed + 2));
    CHECK(odhs_stepper_create(sys, drv, solver, &st));
    CHECK(odhs_stepper_set_dt(st, dt));
    CHECK(odhs_stepper_set_integrator(st, integrator));
    CHECK(cli_set_tolerance(st, tol));
    double tau;
    CHECK(odhs_driver_time_unit(drv, sys, &tau));
    if (!quiet)
        fprintf(stderr, "self_propulsion: N = %lu, d = %d, phi = %.4f, persistence in [0, %g] tau, %s, solver %s\n",
                n, d, phi_now, tmax, cli_integrators[integrator], odhs_solver_name(solver));
    rc = odhs_stepper_reset(st);
    if (rc < 0) {
        fprintf(stderr, "self_propulsion: %s\n", odhs_stepper_errmsg(st));
        return 1;
    }

    FILE *csv;
    if (cli_series(cli.prog, series, SERIES, &csv)) return 1;
    cli_progress prog;
    cli_traj tr;
    cli_plot pl;
    cli_plot_init(&pl, plot, "self-propelled discs", SERIES);
    cli_progress_init(&prog, cli.prog, quiet);
    if (cli_traj_open(&tr, cli.prog, traj, traj_contacts, traj_every)) return 1;
    printf("%10s %12s %14s %8s %10s %10s\n", "time", "mean_speed", "pressure", "z", "collisions", "openings");
    double *V = malloc(n * d * sizeof *V);
    long nout = (long)ceil(T / every - 1e-9);
    rc = 0;
    for (long k = 0; k <= nout; ++k) {
        double target = fmin(k * every, T) * tau;
        if (k > 0) {
            rc = odhs_stepper_run_until_time(st, target);
            if (rc) {
                cli_progress_break(&prog);
                fprintf(stderr, "self_propulsion: stopped at t = %.6g tau: %s (%s)\n", target / tau,
                        odhs_strerror(rc), odhs_stepper_errmsg(st));
                break;
            }
        }
        double t, p, z, speed = 0.0;
        uint64_t steps, nc, no;
        odhs_stepper_time(st, &t);
        odhs_stepper_pressure(st, &p);
        odhs_stepper_coordination(st, &z);
        odhs_stepper_counts(st, &steps, &nc, &no);
        odhs_stepper_velocities(st, V);
        for (size_t i = 0; i < n; ++i) {
            double v2 = 0.0;
            for (int c = 0; c < d; ++c) v2 += V[i * d + c] * V[i * d + c];
            speed += sqrt(v2) / (double)n;
        }
        speed *= tau / lambda;
        p *= pow(lambda, d - 1); /* f_ext = 1 */
        printf("%10.3f %12.6f %14.6e %8.4f %10llu %10llu\n", t / tau, speed, p, z, (unsigned long long)nc,
               (unsigned long long)no);
        if (csv)
            fprintf(csv, "%.10g,%.10g,%.10g,%.6f,%llu,%llu\n", t / tau, speed, p, z, (unsigned long long)nc,
                    (unsigned long long)no);
        cli_plot_row(&pl, (double[]){t / tau, speed, p, z, (double)nc, (double)no});
        if (cli_traj_output(&tr, sys, st, t / tau)) return 1;
        cli_progress_show(&prog, t / tau, T, k == nout, "t = %.2f / %.2f tau, %llu steps, %llu events", t / tau, T,
                          (unsigned long long)steps, (unsigned long long)(nc + no));
    }
    free(V);
    /* contacts back to exact touching before the report and the pictures */
    if (rc == 0 && odhs_stepper_correct(st) < 0)
        fprintf(stderr, "self_propulsion: final correction failed: %s\n", odhs_stepper_errmsg(st));
    double gap, ov;
    odhs_stepper_errors(st, &gap, &ov);
    if (!quiet)
        fprintf(stderr, "self_propulsion: worst contact gap %.3g, worst overlap %.3g (relative to contact distance)\n",
                gap, ov);
    if (csv && fclose(csv)) {
        fprintf(stderr, "self_propulsion: error writing %s\n", series);
        return 1;
    }
    if (cli_plot_write(&pl, cli.prog, plot)) return 1;
    if (svg) {
        double *F = malloc(n * d * sizeof *F);
        int w = odhs_svg_write(sys, odhs_stepper_network(st), NULL, svg);
        if (!w) w = odhs_driver_get_propulsion(drv, F, NULL);
        if (!w && d == 2 && add_arrows(svg, sys, F, lambda)) w = ODHS_E_IO;
        free(F);
        if (w) {
            fprintf(stderr, "self_propulsion: cannot write %s: %s\n", svg, odhs_strerror(w));
            return 1;
        }
    }
    if (cli_traj_close(&tr)) return 1;
    if (outpath && cli_write_config(cli.prog, sys, outpath)) return 1;
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(solver);
    odhs_system_destroy(sys);
    return rc < 0 ? 1 : 0;
}
