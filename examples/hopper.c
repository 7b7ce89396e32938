/* hopper - hard discs falling through a 2D funnel under gravity, with libodhs.
 *
 * With no arguments: 300 bidisperse discs (radii 0.5 and 0.7, 50:50) start
 * at random above a funnel of two segment walls (45 degrees) with an outlet
 * of width 3.2 (in units of the small diameter), and fall under gravity (a
 * weight proportional to the disc area). The box is periodic: discs that
 * leave through the outlet fall on and re-enter at the top, so the hopper
 * keeps discharging until an arch of discs clogs the outlet (the scene of
 * Fig. 2.1 of Vagberg's thesis). The program reports the discharge, whether
 * and when the outlet clogs, and draws the final state with the arch in dark
 * red (--svg).
 *
 * Build against an installed libodhs:
 *     cc hopper.c $(pkg-config --cflags --libs odhs) -lm -o hopper
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <odhs.h>

#include "cli.h"

/* the --series columns */
#define SERIES "time,discharged,mean_speed,z,events"

#define CHECK(call)                                                                             \
    do {                                                                                        \
        int rc_ = (call);                                                                       \
        if (rc_ < 0) {                                                                          \
            fprintf(stderr, "hopper: %s failed: %s\n", #call, odhs_strerror(rc_));              \
            return 1;                                                                           \
        }                                                                                       \
    } while (0)

/* the arch: the lowest chain of contacts from a disc touching the left funnel
 * wall to one touching the right wall (Dijkstra, cost of a disc = its height
 * above the outlet + 1) */
static size_t find_arch(const odhs_network *net, size_t n, const double *x, double yout, unsigned char *mark)
{
    size_t nc = odhs_network_count(net);
    size_t *deg = calloc(n + 1, sizeof *deg), *adj = malloc(2 * nc * sizeof *adj + 1);
    double *cost = malloc(n * sizeof *cost);
    size_t *prev = malloc(n * sizeof *prev);
    unsigned char *done = calloc(n, 1), *left = calloc(n, 1), *right = calloc(n, 1);
    size_t found = 0;
    if (!deg || !adj || !cost || !prev || !done || !left || !right) goto out;
    for (size_t c = 0; c < nc; ++c) {
        size_t i, j;
        int kind;
        odhs_network_get_contact(net, c, &i, &j, &kind);
        if (j == n + 0) left[i] = 1;
        else if (j == n + 1) right[i] = 1;
        else if (j < n) {
            deg[i + 1]++;
            deg[j + 1]++;
        }
    }
    for (size_t i = 0; i < n; ++i) deg[i + 1] += deg[i];
    size_t *fill = calloc(n, sizeof *fill);
    if (!fill) goto out;
    for (size_t c = 0; c < nc; ++c) {
        size_t i, j;
        odhs_network_get_contact(net, c, &i, &j, NULL);
        if (j >= n) continue;
        adj[deg[i] + fill[i]++] = j;
        adj[deg[j] + fill[j]++] = i;
    }
    free(fill);
    for (size_t i = 0; i < n; ++i) {
        /* only discs near the outlet can take part */
        double h = x[2 * i + 1] - yout;
        cost[i] = left[i] && h < 6.0 ? h + 1.0 : INFINITY;
        prev[i] = SIZE_MAX;
    }
    for (;;) {
        size_t u = SIZE_MAX;
        for (size_t i = 0; i < n; ++i)
            if (!done[i] && isfinite(cost[i]) && (u == SIZE_MAX || cost[i] < cost[u])) u = i;
        if (u == SIZE_MAX) break;
        done[u] = 1;
        if (right[u]) {
            for (size_t v = u; v != SIZE_MAX; v = prev[v]) {
                mark[v] = 2;
                found++;
            }
            break;
        }
        for (size_t k = deg[u]; k < deg[u + 1]; ++k) {
            size_t v = adj[k];
            double h = x[2 * v + 1] - yout;
            if (done[v] || h > 6.0) continue;
            if (cost[u] + h + 1.0 < cost[v]) {
                cost[v] = cost[u] + h + 1.0;
                prev[v] = u;
            }
        }
    }
out:
    free(deg);
    free(adj);
    free(cost);
    free(prev);
    free(done);
    free(left);
    free(right);
    return found;
}

int main(int argc, char **argv)
{
    const char *series = NULL, *plot = NULL, *svg = NULL, *outpath = NULL, *solver_name = CLI_DEFAULT_SOLVER;
    const char *traj = NULL, *traj_contacts = NULL;
    double outlet = 3.2, width = 24.0, tmax = 400.0, every = 1.0, tol = 0.0, traj_every = 0.0;
    unsigned long n = 300, seed = 1;
    int integrator = CLI_DEFAULT_INTEGRATOR, quiet = 0;
    const cli_opt opts[] = {
        CLI_OPT_ULONG("--n", &n, "N", "number of discs, radii 0.5 and 0.7 +-5%", CLI_ATLEAST(1)),
        CLI_OPT_DOUBLE("--outlet", &outlet, "D", "outlet width in small diameters", CLI_ABOVE(1)),
        CLI_OPT_DOUBLE("--width", &width, "W", "box width", CLI_ATLEAST(8)),
        CLI_TIME(&tmax),
        CLI_EVERY(&every, "tau"),
        CLI_SEED(&seed),
        CLI_INTEGRATOR(&integrator),
        CLI_TOL(&tol),
        CLI_SOLVER(&solver_name),
        CLI_SERIES(&series, SERIES),
        CLI_PLOT(&plot),
        CLI_SVG(&svg),
        CLI_OUT(&outpath),
        CLI_TRAJ(&traj),
        CLI_TRAJ_EVERY(&traj_every, "tau"),
        CLI_TRAJ_CONTACTS(&traj_contacts),
        CLI_QUIET(&quiet),
        CLI_END,
    };
    const cli_spec cli = {"hopper", NULL, opts,
                          "The run ends early when the outlet clogs. The picture (--svg) draws the walls\n"
                          "grey and the arch dark red.\n"
                          "Time in units of tau = lambda/(xi0 f_rms) (lambda the mean diameter, f_rms the\n"
                          "rms weight); the weight of a disc is proportional to its area.\n"
                          "Defaults are the library's (adaptive Heun, the auto solver); paper mode:\n"
                          "--integrator euler --solver cg. --tol 1e-3 runs the default scene in 50 s\n"
                          "instead of 82 s (clogging is chaotic: the discharge count changes with it).\n"
                          "The step (--dt elsewhere) is 0.05 tau, at most with heun.\n"
                          "Exit status 0 whether or not the outlet clogged (stdout says which).\n",
                          0};
    int rc = cli_parse(&cli, argc, argv);
    if (rc != CLI_GO) return rc;
    if (outlet >= width - 2.0) {
        fprintf(stderr, "hopper: the outlet must be narrower than the box\n");
        return 2;
    }
    /* geometry: outlet at height yout, funnel walls at 45 degrees up to the
     * box edges, discs placed above the funnel, room below for the falling
     * ones; the box height makes the recycled discs land on the pile */
    double yout = 12.0, ytop = yout + 0.5 * (width - outlet);
    double area = 0.0;
    double *r = malloc(n * sizeof *r), *x = malloc(2 * n * sizeof *x), *F = malloc(2 * n * sizeof *F);
    if (!r || !x || !F) return 1;
    /* 5% polydispersity: identical discs sliding in lockstep along a wall
     * would form exactly degenerate (redundant) contact geometries */
    srand((unsigned)seed);
    for (size_t i = 0; i < n; ++i) {
        r[i] = (i % 2 ? 0.7 : 0.5) * (1.0 + 0.05 * (2.0 * rand() / ((double)RAND_MAX + 1.0) - 1.0));
        area += 3.14159265358979323846 * r[i] * r[i];
    }
    double ystart = ytop + 1.0, hfill = 2.2 * area / width + 4.0;
    double L[2] = {width, ystart + hfill + 4.0 + yout};
    for (size_t i = 0; i < n; ++i) {
        int ok = 0;
        for (int tries = 0; tries < 100000 && !ok; ++tries) {
            x[2 * i] = width * (rand() / ((double)RAND_MAX + 1.0));
            x[2 * i + 1] = ystart + r[i] + (hfill - 2 * r[i]) * (rand() / ((double)RAND_MAX + 1.0));
            ok = 1;
            for (size_t j = 0; j < i && ok; ++j) {
                double dx = x[2 * i] - x[2 * j], dy = x[2 * i + 1] - x[2 * j + 1];
                dx -= width * nearbyint(dx / width);
                ok = dx * dx + dy * dy > (r[i] + r[j]) * (r[i] + r[j]) * 1.0001;
            }
        }
        if (!ok) {
            fprintf(stderr, "hopper: cannot place %lu discs above the funnel\n", n);
            return 1;
        }
        F[2 * i] = 0.0;
        F[2 * i + 1] = -(r[i] / 0.5) * (r[i] / 0.5); /* weight ~ area */
    }
    odhs_system *sys;
    CHECK(odhs_system_create(2, n, &sys));
    rc = odhs_system_set_configuration(sys, L, 0.0, r, x);
    if (rc) {
        fprintf(stderr, "hopper: %s\n", odhs_system_errmsg(sys));
        return 1;
    }
    odhs_solver *solver;
    if ((rc = cli_solver(cli.prog, solver_name, &solver))) return rc;
    odhs_driver *drv;
    odhs_stepper *st;
    CHECK(odhs_driver_create(&drv));
    CHECK(odhs_driver_set_forces(drv, n, 2, F));
    CHECK(odhs_stepper_create(sys, drv, solver, &st));
    double a0[2] = {0.0, ytop}, b0[2] = {0.5 * (width - outlet), yout};
    double a1[2] = {0.5 * (width + outlet), yout}, b1[2] = {width, ytop};
    CHECK(odhs_stepper_add_wall_segment(st, a0, b0, NULL)); /* wall 0: left  */
    CHECK(odhs_stepper_add_wall_segment(st, a1, b1, NULL)); /* wall 1: right */
    CHECK(odhs_stepper_set_integrator(st, integrator));
    CHECK(cli_set_tolerance(st, tol));
    CHECK(odhs_stepper_set_dt(st, 0.05));
    double tau;
    CHECK(odhs_driver_time_unit(drv, sys, &tau));
    if (!quiet)
        fprintf(stderr, "hopper: N = %lu, outlet %.2f, box %.1f x %.1f, %s, solver %s, tau = %.4g\n", n, outlet,
                L[0], L[1], cli_integrators[integrator], odhs_solver_name(solver), tau);

    FILE *csv;
    if (cli_series(cli.prog, series, SERIES, &csv)) return 1;
    double *xp = malloc(2 * n * sizeof *xp), *V = malloc(2 * n * sizeof *V);
    if (!xp || !V) return 1;
    odhs_system_get_positions(sys, xp);
    unsigned long discharged = 0;
    double t = 0.0, t_last = -1.0, t_clog = -1.0, vfree = 2.0; /* speed of a free large disc */
    cli_progress prog;
    cli_traj tr;
    cli_plot pl;
    cli_plot_init(&pl, plot, "discharge of a hopper", SERIES);
    cli_progress_init(&prog, cli.prog, quiet);
    if (cli_traj_open(&tr, cli.prog, traj, traj_contacts, traj_every)) return 1;
    /* the first frame, at the start: the state the first step would make
     * (a failure here recurs at the first step, which reports it) */
    odhs_stepper_reset(st);
    if (cli_traj_output(&tr, sys, st, 0.0)) return 1;
    printf("%10s %11s %12s %8s %10s\n", "time/tau", "discharged", "mean_speed", "z", "events");
    long nout = (long)ceil(tmax / every - 1e-9);
    for (long q = 1; q <= nout; ++q) {
        rc = odhs_stepper_run_until_time(st, fmin(q * every, tmax) * tau);
        if (rc) {
            cli_progress_break(&prog);
            fprintf(stderr, "hopper: stopped: %s (%s)\n", odhs_strerror(rc), odhs_stepper_errmsg(st));
            break;
        }
        odhs_stepper_time(st, &t);
        odhs_system_get_positions(sys, x);
        for (size_t i = 0; i < n; ++i)
            if (x[2 * i + 1] - xp[2 * i + 1] > 0.5 * L[1]) { /* wrapped: left through the bottom */
                discharged++;
                t_last = t / tau;
            }
        memcpy(xp, x, 2 * n * sizeof *x);
        odhs_stepper_velocities(st, V);
        double vmean = 0.0, vmax = 0.0, z;
        for (size_t i = 0; i < n; ++i) {
            double v = hypot(V[2 * i], V[2 * i + 1]);
            vmean += v / (double)n;
            vmax = fmax(vmax, v);
        }
        uint64_t nc, no;
        odhs_stepper_counts(st, NULL, &nc, &no);
        odhs_stepper_coordination(st, &z);
        printf("%10.2f %11lu %12.4e %8.4f %10llu\n", t / tau, discharged, vmean, z, (unsigned long long)(nc + no));
        if (csv)
            fprintf(csv, "%.6g,%lu,%.6e,%.6f,%llu\n", t / tau, discharged, vmean, z, (unsigned long long)(nc + no));
        cli_plot_row(&pl, (double[]){t / tau, (double)discharged, vmean, z, (double)(nc + no)});
        if (cli_traj_output(&tr, sys, st, t / tau)) return 1;
        int clogged = vmax < 1e-9 * vfree; /* everything at rest: the outlet is clogged */
        cli_progress_show(&prog, t / tau, tmax, q == nout || clogged, "t = %.1f tau, %lu discharged, mean speed %.3g",
                          t / tau, discharged, vmean);
        if (clogged) {
            t_clog = t / tau;
            break;
        }
    }
    unsigned char *mark = calloc(n, 1);
    size_t arch = 0;
    if (t_clog >= 0.0 && mark) arch = find_arch(odhs_stepper_network(st), n, x, yout, mark);
    if (t_clog >= 0.0)
        printf("clogged: yes, at rest by t = %.2f tau; last disc out at t = %.2f tau; %lu discharged; arch of %zu "
               "discs\n",
               t_clog, t_last, discharged, arch);
    else
        printf("clogged: no within %.1f tau; %lu discharged (%.3f per tau)\n", t / tau, discharged,
               discharged / (t / tau));
    if (csv && fclose(csv)) {
        fprintf(stderr, "hopper: error writing %s\n", series);
        return 1;
    }
    if (cli_plot_write(&pl, cli.prog, plot)) return 1;
    if (svg && odhs_svg_write(sys, odhs_stepper_network(st), mark, svg)) {
        fprintf(stderr, "hopper: cannot write %s: %s\n", svg, odhs_system_errmsg(sys));
        return 1;
    }
    if (cli_traj_close(&tr)) return 1;
    if (outpath && cli_write_config(cli.prog, sys, outpath)) return 1;
    free(mark);
    free(xp);
    free(V);
    free(r);
    free(x);
    free(F);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(solver);
    odhs_system_destroy(sys);
    return rc < 0 ? 1 : 0;
}
