/* jam_packing - certified jammed packings of hard discs/spheres with libodhs
 * (Sect. IV D of Lerner, During & Wyart 2013).
 *
 * Builds (or reads) a scene, drives it until the event-driven rewiring finds
 * an isostatic backbone with positive self-stress, and prints the certificate.
 *
 *     cc jam_packing.c $(pkg-config --cflags --libs odhs) -lm -o jam_packing
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>

#include <odhs.h>

#include "cli.h"

/* --protocol */
enum { COMPRESS, SHEAR, SHEAR_COMPRESS, PRESSURE };
static const char *const protocols[] = {"compress", "shear", "shear+compress", "pressure", NULL};
/* --method */
enum { EVENTS, LP, QUENCH_LP };
static const char *const methods[] = {"events", "lp", "quench+lp", NULL};
/* --end-game: how odhs_stepper_jam_lp steps where its chain leaves the packing unjammed */
static const char *const end_games[] = {"batched", "own", NULL};

/* the integration settings of the options */
static int configure(odhs_stepper *st, int integrator, double dt, double tol, unsigned long corr)
{
    int rc = odhs_stepper_set_integrator(st, integrator);
    if (!rc) rc = cli_set_dt(st, dt);
    if (!rc && integrator != ODHS_INTEGRATOR_EULER) rc = cli_set_tolerance(st, tol);
    if (!rc) rc = odhs_stepper_set_correction_interval(st, (unsigned)corr);
    return rc;
}

/* --traj: a frame at the first event after each --traj-every of packing
 * fraction (compress) or strain (the shear protocols), from the event
 * callback, so that frames never add stopping points to the run */
typedef struct {
    cli_traj traj;
    const odhs_system *sys;
    const odhs_stepper *st;
    int shear, failed;
} frames;

static int on_event(const odhs_event *ev, void *ctx)
{
    frames *fr = ctx;
    double phi = 0.0;
    if (!fr->shear) odhs_system_packing_fraction(fr->sys, &phi);
    if (!fr->failed && cli_traj_output(&fr->traj, fr->sys, fr->st, fr->shear ? ev->strain : phi)) fr->failed = 1;
    return fr->failed; /* stop the run after a write error */
}

/* drive with the given driver until jammed (or failure / strain budget) */
static int drive(odhs_stepper *st, odhs_driver *drv, int shear, int pressure, double max_strain)
{
    int rc;
    if (!shear) return odhs_stepper_run_until_packing_fraction(st, 0.999);
    double g0;
    odhs_stepper_strain(st, &g0);
    double p = 1.0;
    for (double g = g0; g < g0 + max_strain;) {
        g += 0.05;
        rc = odhs_stepper_run_until_strain(st, g);
        if (rc) return rc;
        if (pressure) {
            p *= 2.0;
            odhs_driver_set_pressure(drv, p);
        }
    }
    return ODHS_OK;
}

/* --method lp: the chain of linear programmes (--lp-tol) and the end game (--end-game) */
static int jam_lp(odhs_stepper *st, double trust, double lp_tol, int quench, double quench_phi, int own, int quiet)
{
    odhs_jam_lp_options o = {.size = sizeof o,
                             .trust = trust,
                             .tol = lp_tol,
                             .quench = quench,
                             .quench_phi = quench_phi,
                             .own_integrator = own};
    odhs_jam_lp_report r = {.size = sizeof r};
    int rc = odhs_stepper_jam_lp(st, &o, &r);
    if (!quiet && rc == ODHS_JAMMED && quench)
        fprintf(stderr, "jam_packing: quench: %llu FIRE iterations, %zu rescalings; the chain started at phi = %.6f\n",
                (unsigned long long)r.quench_iterations, r.quench_steps, r.phi_start);
    if (!quiet && rc == ODHS_JAMMED)
        fprintf(stderr,
                "jam_packing: %zu linear programmes (%llu simplex iterations, at most %zu pairs), phi = %.12f; "
                "end game: %llu event-driven steps; %zu degenerate packings shaken, %zu extra polishes\n",
                r.n_lps, (unsigned long long)r.simplex_iterations, r.rows_max, r.phi_lp,
                (unsigned long long)r.end_steps, r.shakes, r.polishes);
    return rc;
}

int main(int argc, char **argv)
{
    const char *in = NULL, *outpath = NULL, *contacts = NULL, *svg = NULL, *solver_name = CLI_DEFAULT_SOLVER;
    const char *traj = NULL, *traj_contacts = NULL;
    double dt = 0.0, max_strain = 20.0, tol = 0.0, p_jam = 0.0, traj_every = 0.01, trust = 0.1, quench_phi = 0.0,
           lp_tol = 0.0;
    int protocol = COMPRESS, method = EVENTS, integrator = CLI_DEFAULT_INTEGRATOR, dim = 2, quiet = 0, end_game = 0;
    unsigned long corr = 1;
    unsigned long n = 256, seed = 1;
    const cli_opt opts[] = {
        CLI_OPT_LIST("--protocol", &protocol, "P", "compress | shear | shear+compress | pressure", protocols, CLI_ANY),
        CLI_OPT_LIST("--method", &method, "M",
                     "how the compression stage (compress, shear) jams: events = the event-driven compression; lp = "
                     "a chain of linear programmes, then the same exact end game (odhs_stepper_jam_lp; needs a "
                     "library built with COIN-OR CLP); quench+lp = the fastest: a soft-sphere quench to "
                     "--quench-phi, dilated until no pair overlaps, then lp (a quench protocol, not a compression)",
                     methods, CLI_ANY),
        CLI_OPT_DOUBLE("--trust", &trust, "X",
                       "--method lp, quench+lp: bound on each displacement per programme, in mean diameters (at "
                       "most 0.5)",
                       CLI_POSITIVE),
        CLI_OPT_DOUBLE("--lp-tol", &lp_tol, "X",
                       "--method lp, quench+lp: the chain ends when its growth sqrt(Gamma) - 1 falls below X "
                       "(default: the library's, 1e-12; a looser one leaves more to the end game)",
                       CLI_POSITIVE),
        CLI_OPT_LIST("--end-game", &end_game, "E",
                     "--method lp, quench+lp: how the end game steps where the chain leaves the packing unjammed: "
                     "batched = batched-event steps, several events per solve (since 0.2.22); own = the steps of "
                     "--integrator, one event at a time, as up to 0.2.21",
                     end_games, CLI_ANY),
        CLI_OPT_DOUBLE("--quench-phi", &quench_phi, "X",
                       "--method quench+lp: packing fraction of the quench, below 1 (default: the library's, 0.86 "
                       "in 2D and 0.66 in 3D)",
                       CLI_POSITIVE),
        CLI_IN(&in),
        CLI_OUT(&outpath),
        CLI_CONTACTS(&contacts),
        CLI_SVG(&svg),
        CLI_OPT_STRING("--traj", &traj, "FILE",
                       "write a trajectory: extended XYZ (.xyz, for OVITO and ASE) or a LAMMPS custom dump (.dump, "
                       ".lammpstrj): the start, a frame at the first event after each --traj-every, the packing",
                       CLI_ANY),
        CLI_TRAJ_EVERY(&traj_every, "packing fraction (compress) or strain (the shear protocols)"),
        CLI_TRAJ_CONTACTS(&traj_contacts),
        CLI_SCENE(&n, &dim, &seed),
        CLI_SOLVER(&solver_name),
        CLI_INTEGRATOR(&integrator),
        CLI_TOL(&tol),
        CLI_DT(&dt, "natural units"),
        CLI_OPT_DOUBLE("--max-strain", &max_strain, "X", "shear protocols: give up after this strain", CLI_POSITIVE),
        CLI_OPT_DOUBLE("--jam-pressure", &p_jam, "P",
                       "pressure protocol: a network with positive self-stress is jammed once the pressure is >= P "
                       "(0: as soon as it appears; below P it flows by dilating)",
                       CLI_NONNEGATIVE),
        CLI_OPT_ULONG("--correction", &corr, "K",
                      "drift correction every K steps; certified packings need contact gaps at round-off when they "
                      "jam",
                      CLI_ATMOST(1000000)),
        CLI_QUIET(&quiet),
        CLI_END,
    };
    const cli_spec cli = {
        "jam_packing", NULL, opts,
        "The picture (--svg) marks the rattlers.\n"
        "Protocols: compress = isotropic compression; shear = compress to jamming,\n"
        "dilate by 0.2% and shear at fixed volume until arrest; shear+compress =\n"
        "shear with compression at 1/5 of the shear rate; pressure = shear at fixed\n"
        "pressure, doubled every 0.05 strain (towards zero strain rate); at a finite\n"
        "pressure the flow would go on, so the run stops at the first network with\n"
        "positive self-stress once p >= --jam-pressure (default 0: at once).\n"
        "Defaults are the library's (adaptive Heun, the auto solver); paper mode:\n"
        "--integrator euler --solver cg.\n"
        "Exit status: 0 jammed and certified, 1 error, 2 bad arguments, 3 not jammed\n"
        "or not certified (force balance < 1e-12, gaps < 1e-13, no overlap, all\n"
        "backbone forces > 0, isostatic).\n",
        0};
    int rc = cli_parse(&cli, argc, argv);
    if (rc != CLI_GO) return rc;
    if (method != EVENTS && (protocol == SHEAR_COMPRESS || protocol == PRESSURE)) {
        fprintf(stderr, "jam_packing: --method %s replaces an isotropic compression to jamming: protocols compress "
                        "and shear only\n", methods[method]);
        return 2;
    }
    if (quench_phi >= 1.0) {
        fprintf(stderr, "jam_packing: --quench-phi %g: must be below 1\n", quench_phi);
        return 2;
    }
    if (trust > 0.5) {
        fprintf(stderr, "jam_packing: --trust %g: at most 0.5\n", trust);
        return 2;
    }

    odhs_system *sys = NULL;
    if (cli_start(cli.prog, in, dim, n, seed, 1.0, &sys)) return 1;
    n = odhs_system_count(sys);
    odhs_solver *solver;
    if ((rc = cli_solver(cli.prog, solver_name, &solver))) return rc;
    odhs_driver *drv;
    odhs_stepper *st;
    if (odhs_driver_create(&drv) || odhs_stepper_create(sys, drv, solver, &st) ||
        configure(st, integrator, dt, tol, corr)) {
        fprintf(stderr, "jam_packing: setup failed\n");
        return 1;
    }
    if (!quiet)
        fprintf(stderr, "jam_packing: N = %lu, d = %d, protocol %s, method %s, solver %s, %s\n", n,
                odhs_system_dim(sys), protocols[protocol], methods[method], solver_name, cli_integrators[integrator]);
    frames fr = {.sys = sys, .st = st, .shear = protocol == SHEAR || protocol == PRESSURE};
    if ((rc = cli_traj_open(&fr.traj, cli.prog, traj, traj_contacts, traj_every))) return rc;
    if (traj || traj_contacts) {
        double phi0;
        odhs_system_packing_fraction(sys, &phi0);
        if (odhs_stepper_reset(st) || cli_traj_output(&fr.traj, sys, st, fr.shear ? 0.0 : phi0)) return 1;
        odhs_stepper_set_event_callback(st, on_event, &fr);
    }

    if (protocol == COMPRESS) {
        odhs_driver_set_compression_rate(drv, 1.0);
        rc = method != EVENTS ? jam_lp(st, trust, lp_tol, method == QUENCH_LP, quench_phi, end_game, quiet) : drive(st, drv, 0, 0, 0);
    } else if (protocol == SHEAR) {
        odhs_driver_set_compression_rate(drv, 1.0);
        rc = method != EVENTS ? jam_lp(st, trust, lp_tol, method == QUENCH_LP, quench_phi, end_game, quiet) : drive(st, drv, 0, 0, 0);
        if (rc == ODHS_JAMMED) {
            /* dilate slightly (all contacts open) and shear at fixed volume */
            double phi;
            odhs_system_packing_fraction(sys, &phi);
            odhs_stepper_destroy(st);
            odhs_system_scale_box(sys, pow(1.002, 1.0 / odhs_system_dim(sys)));
            odhs_driver_set_compression_rate(drv, 0.0);
            odhs_driver_set_shear_rate(drv, 1.0);
            if (odhs_stepper_create(sys, drv, solver, &st) || configure(st, integrator, dt, tol, corr))
                return 1;
            fr.st = st;
            if (traj || traj_contacts) odhs_stepper_set_event_callback(st, on_event, &fr);
            if (!quiet)
                fprintf(stderr, "jam_packing: compression jammed at phi = %.6f; shearing at phi = %.6f\n", phi,
                        phi / 1.002);
            rc = drive(st, drv, 1, 0, max_strain);
        }
    } else if (protocol == SHEAR_COMPRESS) {
        odhs_driver_set_shear_rate(drv, 1.0);
        odhs_driver_set_compression_rate(drv, 0.2);
        rc = drive(st, drv, 0, 0, 0);
    } else { /* pressure */
        odhs_driver_set_shear_rate(drv, 1.0);
        odhs_driver_set_pressure(drv, 1.0);
        odhs_driver_set_jamming_pressure(drv, p_jam);
        rc = drive(st, drv, 1, 1, max_strain);
    }
    int status = 0;
    if (fr.failed) {
        status = 1;
    } else if (rc == ODHS_JAMMED) {
        if (!quiet) fprintf(stderr, "jam_packing: jammed\n");
    } else if (rc == ODHS_OK) {
        fprintf(stderr, "jam_packing: did not jam within the strain budget\n");
        status = 3;
    } else {
        fprintf(stderr, "jam_packing: stopped: %s (%s)\n", odhs_strerror(rc), odhs_stepper_errmsg(st));
        status = rc > 0 ? 3 : 1;
    }

    odhs_jam_certificate c;
    c.size = sizeof c;
    if (odhs_stepper_certificate(st, &c) == ODHS_OK) {
        double strain, t;
        odhs_stepper_strain(st, &strain);
        odhs_stepper_time(st, &t);
        printf("jammed                 %s\n", c.jammed ? "yes" : "no");
        printf("phi_J                  %.15f\n", c.phi);
        printf("strain                 %.6f\n", strain);
        printf("particles              %zu (backbone %zu, rattlers %zu = %.2f%%)\n", c.n_particles, c.n_backbone,
               c.n_rattlers, 100.0 * (double)c.n_rattlers / (double)c.n_particles);
        printf("contacts               %zu (backbone %zu, isostatic count d(Nbar-1)+1 = %zu)\n", c.n_contacts,
               c.n_contacts_backbone, c.n_contacts_isostatic);
        printf("z, z_backbone          %.6f, %.6f\n", c.z, c.z_backbone);
        printf("pressure               %.6g\n", c.pressure);
        printf("force balance residual %.3e (relative to the mean force)\n", c.force_balance);
        printf("worst contact gap      %.3e (relative to the contact distance)\n", c.gap_error);
        printf("worst overlap          %.3e\n", c.overlap);
        printf("smallest force         %.3e (relative to the mean force)\n", c.min_force);
        printf("final pivots           %zu\n", c.n_pivots);
        int certified = c.jammed && c.isostatic && c.force_balance < 1e-12 && c.gap_error < 1e-13 &&
                        c.overlap <= 1e-14 && c.min_force > 0.0;
        printf("certified              %s\n", certified ? "yes" : "no");
        if (status == 0 && !certified) {
            fprintf(stderr, "jam_packing: jammed, but the certificate fails (see above)\n");
            status = 3;
        }
    }
    const odhs_network *net = odhs_stepper_network(st);
    /* the packing as the last frame */
    fr.traj.every = 0.0;
    if (cli_traj_output(&fr.traj, sys, st, INFINITY) || cli_traj_close(&fr.traj)) status = 1;
    if (outpath && cli_write_config(cli.prog, sys, outpath)) status = 1;
    if (contacts && odhs_contacts_write_csv(net, sys, contacts)) {
        fprintf(stderr, "jam_packing: cannot write %s: %s\n", contacts, odhs_network_errmsg(net));
        status = 1;
    }
    if (svg) {
        unsigned char *mark = malloc(n);
        if (mark) odhs_network_rattlers(net, mark, NULL);
        if (odhs_svg_write(sys, net, mark, svg)) {
            fprintf(stderr, "jam_packing: cannot write %s: %s\n", svg, odhs_system_errmsg(sys));
            status = 1;
        }
        free(mark);
    }
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(solver);
    odhs_system_destroy(sys);
    return status;
}
