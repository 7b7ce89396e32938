/* lammps_coupling - libodhs inside LAMMPS, through LAMMPS's C library interface.
 *
 * LAMMPS reads a data file (atom_style sphere) and owns the atoms: their ids,
 * types, radii and positions; it computes (the packing fraction from its own
 * radii and box, the rms of the velocities it is given) and dumps. libodhs
 * advances the atoms under simple shear (Lees-Edwards) between LAMMPS's
 * outputs and owns the box (the shear). At every output interval:
 *
 *   1. pull: the positions are gathered from LAMMPS by atom id
 *      (lammps_gather_atoms) and compared with the library's modulo the
 *      periodic lattice. When they agree to --sync-tol (LAMMPS's remapping into
 *      its triclinic box costs an ulp or so), the library keeps its own and its
 *      stepper goes on as if LAMMPS were not there; otherwise (a LAMMPS command
 *      or fix moved atoms) the library takes LAMMPS's positions and restarts
 *      its contact network from them (odhs_system_set_positions,
 *      odhs_stepper_reset);
 *   2. the library advances to the next strain (odhs_stepper_run_until_strain);
 *   3. push: the box (change_box: edges and the tilt xy of the Lees-Edwards
 *      strain), the positions and the non-affine velocities go back to LAMMPS
 *      (lammps_scatter_atoms);
 *   4. LAMMPS runs one step in which nothing moves (no time integration; the
 *      step length is the strain interval, so LAMMPS's time is the strain):
 *      it remaps the atoms into its box, evaluates its computes and writes the
 *      --dump frame.
 *
 * With the default --sync-tol the run is the run of shear_flow from the same
 * start, output for output (tests/lammps_coupling.sh compares them).
 *
 * Build (Debian: apt-get install liblammps-dev; `make examples` does it when
 * the LAMMPS headers are installed):
 *     cc lammps_coupling.c $(pkg-config --cflags --libs odhs liblammps) -lm -o lammps_coupling
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <lammps/library.h>
#include <odhs.h>

#include "cli.h"

#define PROG "lammps_coupling"
/* shear_flow's --series columns, then LAMMPS's and the synchronisation's */
#define SERIES                                                                                                       \
    "strain,shear_stress,pressure,z,events,phi,kappa,time,collisions,openings,dissipation,lmp_phi,lmp_dv_rms,sync,"  \
    "adopted"
#define UNITS                                                                                                        \
    "strain and time 1/gammadot; shear_stress, pressure gammadot/xi0 (2D per length, 3D per area); kappa "          \
    "compression rate/gammadot; dissipation lambda^2 gammadot^2/xi0 (lambda the small diameter); lmp_dv_rms "       \
    "length*gammadot; sync mean diameters; z, events, collisions, openings, phi, lmp_phi, adopted dimensionless"

/* ---- LAMMPS, and what is left to say when it ends the program ---------------- */

/* Debian's LAMMPS is built without C++ exceptions: an error in a command
 * prints its message to the screen and the log and calls exit(1). The screen
 * is off (LAMMPS's output would mix with the table), so an atexit handler
 * names the command and copies the ERROR lines from the log. */
static struct {
    void *lmp;         /* the LAMMPS instance (NULL: none open)                    */
    char cmd[1100];    /* the command LAMMPS is executing ("" between commands)    */
    char tmpdir[4096]; /* our temporary directory, removed at exit ("" none)       */
    char log[4200];    /* the LAMMPS log file                                       */
    char data[4200];   /* a temporary data file in tmpdir ("" none)                 */
    int own_log;       /* the log is in tmpdir                                      */
} G;

static void at_exit(void)
{
    if (G.lmp && !G.cmd[0]) { /* an early return of ours: close LAMMPS and MPI */
        lammps_close(G.lmp);
        G.lmp = NULL;
        lammps_mpi_finalize();
    }
    if (G.cmd[0]) {
        fprintf(stderr, "%s: LAMMPS ended the program in the command: %s\n", PROG, G.cmd);
        FILE *f = G.log[0] ? fopen(G.log, "r") : NULL;
        char line[1024];
        int said = 0;
        while (f && fgets(line, sizeof line, f))
            if (!strncmp(line, "ERROR", 5)) {
                fprintf(stderr, "%s: LAMMPS said: %s", PROG, line);
                said = 1;
            }
        if (f) fclose(f);
        if (!said) fprintf(stderr, "%s: (no ERROR line in the LAMMPS log %s)\n", PROG, G.log);
    }
    if (G.data[0]) remove(G.data);
    if (G.own_log) remove(G.log);
    if (G.tmpdir[0]) rmdir(G.tmpdir);
}

/* run one LAMMPS command (printf-style); 0, or 1 with a message (LAMMPS
 * builds with exceptions report errors here; others exit, see at_exit) */
static int lmp_do(const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int len = vsnprintf(G.cmd, sizeof G.cmd, fmt, ap);
    va_end(ap);
    if (len < 0 || (size_t)len >= sizeof G.cmd) {
        fprintf(stderr, "%s: LAMMPS command too long\n", PROG);
        G.cmd[0] = 0;
        return 1;
    }
    lammps_command(G.lmp, G.cmd);
    if (lammps_has_error(G.lmp)) {
        char msg[1024] = "";
        lammps_get_last_error_message(G.lmp, msg, sizeof msg);
        fprintf(stderr, "%s: LAMMPS command '%s' failed: %s\n", PROG, G.cmd, msg);
        G.cmd[0] = 0;
        return 1;
    }
    G.cmd[0] = 0;
    return 0;
}

/* value k of the global vector of the LAMMPS fix id (a copy LAMMPS allocates) */
static double lmp_fix_value(const char *id, int k)
{
    double *v = lammps_extract_fix(G.lmp, id, LMP_STYLE_GLOBAL, LMP_TYPE_VECTOR, k, 0);
    double x = v ? *v : NAN;
    lammps_free(v);
    return x;
}

/* LAMMPS splits commands at blanks and reads quotes, '#' and '$' itself:
 * file names given to its commands must not hold them */
static int lmp_safe_name(const char *what, const char *path)
{
    if (!path || !strpbrk(path, " \t\n\r\"'#$&")) return 0;
    fprintf(stderr, "%s: %s '%s': LAMMPS cannot take a file name with blanks, quotes, '#', '$' or '&'\n", PROG,
            what, path);
    return 1;
}

/* ---- the coupling -------------------------------------------------------------- */

typedef struct {
    odhs_system *sys;
    odhs_stepper *st;
    size_t n;
    int dim;
    double lo[3];   /* LAMMPS's box origin: LAMMPS position = library position + lo */
    double *x;      /* n*3: LAMMPS's layout (ordered by atom id, z = 0 in 2D)      */
    double *xl;     /* n*dim: the library's positions                              */
    double *u;      /* n*dim: non-affine velocities                                */
    double L[3];    /* the library's box as last given to LAMMPS                     */
    double lambda;  /* mean diameter                                               */
    double sync_tol;
    double sync, sync_max; /* the last pull's distance, the largest                 */
    int adopted;           /* whether the last pull took LAMMPS's positions         */
    unsigned long nadopt, npull;
} coupling;

/* the largest distance between LAMMPS's positions (c->x, ordered by id) and
 * the library's (c->xl), modulo the sheared lattice, in mean diameters */
static double distance(coupling *c)
{
    double L[3] = {1, 1, 1}, g, worst = 0.0;
    odhs_system_get_box(c->sys, L);
    odhs_system_get_strain(c->sys, &g);
    for (size_t i = 0; i < c->n; ++i) {
        double d[3] = {0, 0, 0};
        for (int k = 0; k < c->dim; ++k) d[k] = c->x[3 * i + k] - c->lo[k] - c->xl[i * c->dim + k];
        double ny = nearbyint(d[1] / L[1]); /* an image in y shifts x by g Ly */
        d[1] -= ny * L[1];
        d[0] -= ny * g * L[1];
        d[0] -= nearbyint(d[0] / L[0]) * L[0];
        if (c->dim == 3) d[2] -= nearbyint(d[2] / L[2]) * L[2];
        double s = sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
        if (!(s <= worst)) worst = s; /* NaN wins */
    }
    return worst / c->lambda;
}

/* gather LAMMPS's positions into c->x (by atom id); 0, or 1 with a message */
static int gather(coupling *c)
{
    double natoms = lammps_get_natoms(G.lmp);
    if (natoms != (double)c->n) { /* (and the gather would overrun c->x) */
        fprintf(stderr, "%s: LAMMPS now has %.0f atoms, the library %zu: atoms cannot be created or deleted\n", PROG,
                natoms, c->n);
        return 1;
    }
    for (size_t i = 0; i < 3 * c->n; ++i) c->x[i] = NAN; /* a failed gather leaves them */
    lammps_gather_atoms(G.lmp, "x", 1, 3, c->x);
    for (size_t i = 0; i < 3 * c->n; ++i)
        if (!isfinite(c->x[i])) {
            fprintf(stderr, "%s: LAMMPS did not hand over the positions (atom ids must be 1..N)\n", PROG);
            return 1;
        }
    return 0;
}

/* 1. pull LAMMPS's positions; adopt them (and restart the stepper's contact
 * network) when they differ from the library's beyond the tolerance; 0, or 1
 * with a message */
static int pull(coupling *c)
{
    if (gather(c)) return 1;
    odhs_system_get_positions(c->sys, c->xl);
    c->sync = distance(c);
    c->adopted = 0;
    c->npull++;
    if (!(c->sync <= c->sync_max)) c->sync_max = c->sync;
    if (c->sync <= c->sync_tol) return 0;
    for (size_t i = 0; i < c->n; ++i)
        for (int k = 0; k < c->dim; ++k) c->xl[i * c->dim + k] = c->x[3 * i + k] - c->lo[k];
    int rc = odhs_system_set_positions(c->sys, c->xl);
    if (rc) {
        fprintf(stderr, "%s: the library cannot take LAMMPS's positions: %s\n", PROG, odhs_system_errmsg(c->sys));
        return 1;
    }
    if ((rc = odhs_stepper_reset(c->st))) {
        fprintf(stderr, "%s: restarting from LAMMPS's positions: %s\n", PROG, odhs_stepper_errmsg(c->st));
        return 1;
    }
    c->adopted = 1;
    c->nadopt++;
    return 0;
}

/* the LAMMPS tilt of the library's strain: xy = gamma Ly reduced by
 * multiples of Lx until LAMMPS accepts it (|xy/Lx| <= 1/2), as the data
 * file writer does */
static double tilt(double gamma, const double *L)
{
    double xy = gamma * L[1];
    while (xy / L[0] > 0.5) xy -= L[0];
    while (xy / L[0] < -0.5) xy += L[0];
    return xy;
}

/* 3. push the box, the positions and the non-affine velocities to LAMMPS;
 * 0, or 1 with a message */
static int push(coupling *c)
{
    double L[3] = {1, 1, 1}, g;
    odhs_system_get_box(c->sys, L);
    odhs_system_get_strain(c->sys, &g);
    double blo[3], bhi[3], xy, yz, xz;
    int pflags[3], boxflag;
    lammps_extract_box(G.lmp, blo, bhi, &xy, &yz, &xz, pflags, &boxflag);
    double nxy = tilt(g, L);
    if (L[0] != c->L[0] || L[1] != c->L[1] || L[2] != c->L[2]) {
        /* new edges (at fixed pressure): through a zero tilt, so that LAMMPS,
         * which checks the box after each change, never sees the old tilt
         * on the new edges */
        char z[128] = "";
        if (c->dim == 3) snprintf(z, sizeof z, " z final %.17g %.17g", c->lo[2], c->lo[2] + L[2]);
        if (lmp_do("change_box all xy final 0 x final %.17g %.17g y final %.17g %.17g%s xy final %.17g units box",
                   c->lo[0], c->lo[0] + L[0], c->lo[1], c->lo[1] + L[1], z, nxy))
            return 1;
        memcpy(c->L, L, sizeof L);
    } else if (nxy != xy && lmp_do("change_box all xy final %.17g units box", nxy)) {
        return 1;
    }
    odhs_system_get_positions(c->sys, c->xl);
    odhs_stepper_nonaffine_velocities(c->st, c->u);
    double *v = malloc(3 * c->n * sizeof *v);
    if (!v) {
        fprintf(stderr, "%s: out of memory\n", PROG);
        return 1;
    }
    for (size_t i = 0; i < c->n; ++i)
        for (int k = 0; k < 3; ++k) {
            c->x[3 * i + k] = k < c->dim ? c->xl[i * c->dim + k] + c->lo[k] : 0.0;
            v[3 * i + k] = k < c->dim ? c->u[i * c->dim + k] : 0.0;
        }
    lammps_scatter_atoms(G.lmp, "x", 1, 3, c->x);
    lammps_scatter_atoms(G.lmp, "v", 1, 3, v);
    free(v);
    return 0;
}

/* 4. LAMMPS's step: nothing moves (no time integration fix); it remaps the
 * atoms into its box, evaluates its computes and writes its dump frame. The
 * first output is LAMMPS's step 0 (run 0); output k is step k, of length the
 * strain since output k-1 (so LAMMPS's time is the strain). 0, or 1 */
static int lammps_step(int k, double dstrain)
{
    if (k == 0) return lmp_do("run 0");
    return lmp_do("timestep %.17g", dstrain) || lmp_do("run 1");
}

#define CHECK(call)                                                                                                  \
    do {                                                                                                             \
        int rc_ = (call);                                                                                            \
        if (rc_ < 0) {                                                                                               \
            fprintf(stderr, PROG ": %s failed: %s\n", #call, odhs_strerror(rc_));                                    \
            return 1;                                                                                                \
        }                                                                                                            \
    } while (0)

/* one output: the table row on stdout and the --series row */
static void output(const coupling *c, FILE *csv, double g, double t, int fixed_p)
{
    double s, p, z, kappa, phi, D = NAN;
    uint64_t steps, nc, no;
    odhs_stepper_shear_stress(c->st, &s);
    odhs_stepper_pressure(c->st, &p);
    odhs_stepper_coordination(c->st, &z);
    odhs_stepper_kappa(c->st, &kappa);
    odhs_stepper_dissipation(c->st, &D);
    odhs_stepper_counts(c->st, &steps, &nc, &no);
    odhs_system_packing_fraction(c->sys, &phi);
    double lphi = lmp_fix_value("odhs_obs", 0), ldv = lmp_fix_value("odhs_obs", 1);
    unsigned long long ev = (unsigned long long)(nc + no);
    printf("%12.6f %14.6e %14.6e %8.4f %10llu", g, s, p, z, ev);
    if (fixed_p) printf(" %10.6f %14.6e", phi, kappa);
    printf(" %10.6f %14.6e %9.2e%s\n", lphi, ldv, c->sync, c->adopted ? "  adopted" : "");
    if (csv)
        fprintf(csv, "%.10g,%.10g,%.10g,%.6f,%llu,%.10g,%.10g,%.10g,%llu,%llu,%.10g,%.10g,%.10g,%.3g,%d\n", g, s, p, z,
                ev, phi, kappa, t, (unsigned long long)nc, (unsigned long long)no, D, lphi, ldv, c->sync, c->adopted);
}

/* check that LAMMPS holds the library's atoms: count, dimension, box, radii
 * (by id); 0, or 1 with a message */
static int check_atoms(coupling *c)
{
    double natoms = lammps_get_natoms(G.lmp);
    int dim = lammps_extract_setting(G.lmp, "dimension");
    if (natoms != (double)c->n || dim != c->dim) {
        fprintf(stderr, "%s: LAMMPS read %.0f atoms in %dD, the library %zu in %dD\n", PROG, natoms, dim, c->n,
                c->dim);
        return 1;
    }
    double hi[3], xy, yz, xz, L[3] = {1, 1, 1};
    int pflags[3], boxflag;
    lammps_extract_box(G.lmp, c->lo, hi, &xy, &yz, &xz, pflags, &boxflag);
    odhs_system_get_box(c->sys, L);
    for (int k = 0; k < c->dim; ++k)
        if (!(fabs(hi[k] - c->lo[k] - L[k]) <= 1e-12 * L[k])) {
            fprintf(stderr, "%s: LAMMPS's box edge %d is %.17g, the library's %.17g\n", PROG, k, hi[k] - c->lo[k],
                    L[k]);
            return 1;
        }
    double *rl = malloc(c->n * sizeof *rl), *r = malloc(c->n * sizeof *r);
    int bad = !rl || !r;
    if (bad) fprintf(stderr, "%s: out of memory\n", PROG);
    for (size_t i = 0; !bad && i < c->n; ++i) rl[i] = NAN;
    if (!bad) {
        lammps_gather_atoms(G.lmp, "radius", 1, 1, rl);
        odhs_system_get_radii(c->sys, r);
    }
    for (size_t i = 0; !bad && i < c->n; ++i)
        if (!(fabs(rl[i] - r[i]) <= 1e-15 * r[i])) {
            fprintf(stderr, "%s: atom %zu: LAMMPS's radius %.17g, the library's %.17g\n", PROG, i + 1, rl[i], r[i]);
            bad = 1;
        }
    free(rl);
    free(r);
    return bad;
}

int main(int argc, char **argv)
{
    const char *in = NULL, *outpath = NULL, *series = NULL, *solver_name = CLI_DEFAULT_SOLVER;
    const char *dump = NULL, *write_data = NULL, *lmp_input = NULL, *lmp_log = NULL;
    double strain = 0.2, every = 0.01, dt = 0.0, pressure = 0.0, phi = 0.80, tol = 0.0, sync_tol = 1e-12;
    unsigned long n = 256, seed = 1;
    int dim = 2, integrator = CLI_DEFAULT_INTEGRATOR, quiet = 0;
    const cli_opt opts[] = {
        CLI_IN(&in),
        CLI_STRAIN(&strain),
        CLI_OUT(&outpath),
        CLI_OPT_STRING("--series", &series, "FILE.csv", "write a CSV row per output (the columns below)", CLI_ANY),
        CLI_EVERY(&every, "strain"),
        CLI_OPT_STRING("--dump", &dump, "FILE",
                       "LAMMPS writes a custom dump, a frame per output: id type radius x y z vx vy vz (the "
                       "non-affine velocities), 17 digits, ITEM: TIME the strain",
                       CLI_ANY),
        CLI_OPT_STRING("--write-data", &write_data, "FILE.data",
                       "LAMMPS writes the final configuration with its write_data", CLI_ANY),
        CLI_OPT_STRING("--lammps-input", &lmp_input, "FILE",
                       "LAMMPS commands run once after read_data and the coupling's own set-up (computes, dumps, "
                       "fixes; atoms a command moves are handed to the library)",
                       CLI_ANY),
        CLI_OPT_STRING("--lammps-log", &lmp_log, "FILE", "LAMMPS's log file (commands, thermo output, errors)",
                       CLI_ANY, .deftext = "a temporary file, removed at exit"),
        CLI_OPT_DOUBLE("--sync-tol", &sync_tol, "X",
                       "the library keeps its own positions when LAMMPS's agree with them to X mean diameters "
                       "(modulo the periodic lattice); beyond X it takes LAMMPS's and restarts its contact "
                       "network (0: whenever they differ at all)",
                       CLI_NONNEGATIVE),
        CLI_DT(&dt, "strain units"),
        CLI_INTEGRATOR(&integrator),
        CLI_TOL(&tol),
        CLI_SOLVER(&solver_name),
        CLI_OPT_DOUBLE("--pressure", &pressure, "P", "shear at fixed pressure P instead of fixed volume", CLI_POSITIVE,
                       .deftext = ""),
        CLI_PHI(&phi),
        CLI_SCENE(&n, &dim, &seed),
        CLI_QUIET(&quiet),
        CLI_END,
    };
    const cli_spec cli = {PROG, NULL, opts,
                          "shear_flow's run (its options and defaults) with LAMMPS owning the atoms:\n"
                          "LAMMPS reads the data file (--in FILE.data, or the built-in scene written to\n"
                          "a temporary one); at every output the positions go from LAMMPS to the library\n"
                          "and back, and LAMMPS computes (lmp_phi: the packing fraction from its radii\n"
                          "and box; lmp_dv_rms: the rms of the non-affine velocities it is given) and\n"
                          "dumps. sync: the largest distance between LAMMPS's and the library's position\n"
                          "of an atom when LAMMPS handed them back, in mean diameters; adopted: 1 when\n"
                          "the library took them (beyond --sync-tol).\n"
                          "Series columns: strain, shear_stress, pressure, z, events, phi, kappa, time,\n"
                          "collisions, openings, dissipation (shear_flow's), lmp_phi, lmp_dv_rms, sync,\n"
                          "adopted, after the header a \"# units\" comment line.\n"
                          "The defaults are the library's (adaptive Heun, the auto solver); paper mode:\n"
                          "--integrator euler --solver cg. Exit status: 0 when the requested strain was\n"
                          "reached, 3 when the run stopped before it, 1 on error (LAMMPS's errors end the\n"
                          "program with the command and LAMMPS's message on stderr).\n",
                          0};
    int rc = cli_parse(&cli, argc, argv);
    if (rc != CLI_GO) return rc;
    if (lmp_safe_name("--dump", dump) || lmp_safe_name("--write-data", write_data)) return 2;

    odhs_solver *solver, *rescue = NULL;
    if ((rc = cli_solver(cli.prog, solver_name, &solver))) return rc;
    if (pressure > 0 && !strcmp(solver_name, "cg")) { /* as in shear_flow */
        CHECK(odhs_solver_create_by_name("auto", &rescue));
        CHECK(odhs_solver_set_fallback(solver, rescue));
    }
    odhs_system *sys = NULL;
    if (in ? cli_read_xyz(cli.prog, in, &sys) : cli_compressed_scene(cli.prog, dim, n, phi, seed, solver, quiet, &sys)) return 1;
    double phi_now;
    CHECK(odhs_system_packing_fraction(sys, &phi_now));
    n = odhs_system_count(sys);
    if (!quiet)
        fprintf(stderr, PROG ": N = %lu, d = %d, phi = %.6f, %s, solver %s%s\n", n, odhs_system_dim(sys), phi_now,
                cli_integrators[integrator], odhs_solver_name(solver),
                pressure > 0 ? ", fixed pressure" : ", fixed volume");

    odhs_driver *drv;
    odhs_stepper *st;
    CHECK(odhs_driver_create(&drv));
    CHECK(odhs_driver_set_shear_rate(drv, 1.0));
    if (pressure > 0) CHECK(odhs_driver_set_pressure(drv, pressure));
    CHECK(odhs_stepper_create(sys, drv, solver, &st));
    CHECK(cli_set_dt(st, dt));
    CHECK(odhs_stepper_set_integrator(st, integrator));
    CHECK(cli_set_tolerance(st, tol));
    if ((rc = odhs_stepper_reset(st))) {
        fprintf(stderr, PROG ": %s\n", odhs_stepper_errmsg(st));
        return 1;
    }

    /* ---- LAMMPS: a temporary directory for its log and (without a data
     * file from --in) the data file of the library's configuration */
    atexit(at_exit);
    const char *tmp = getenv("TMPDIR");
    snprintf(G.tmpdir, sizeof G.tmpdir, "%s/" PROG ".XXXXXX", tmp && *tmp ? tmp : "/tmp");
    if (!mkdtemp(G.tmpdir)) {
        fprintf(stderr, PROG ": cannot make a temporary directory %s: %s\n", G.tmpdir, strerror(errno));
        G.tmpdir[0] = 0;
        return 1;
    }
    const char *data = in;
    if (!in || !cli_is_lammps_data_(in)) {
        snprintf(G.data, sizeof G.data, "%s/start.data", G.tmpdir);
        if (odhs_lammps_data_write(sys, G.data)) {
            fprintf(stderr, PROG ": cannot write %s: %s\n", G.data, odhs_system_errmsg(sys));
            return 1;
        }
        data = G.data;
    }
    if (lmp_safe_name("the data file", data)) return 1;
    if (lmp_log) snprintf(G.log, sizeof G.log, "%s", lmp_log);
    else snprintf(G.log, sizeof G.log, "%s/log.lammps", G.tmpdir);
    G.own_log = !lmp_log;
    char *largs[] = {PROG, "-log", G.log, "-screen", "none", "-nocite", NULL};
    snprintf(G.cmd, sizeof G.cmd, "(starting LAMMPS)");
    G.lmp = lammps_open_no_mpi(6, largs, NULL);
    G.cmd[0] = 0;
    if (!G.lmp) {
        fprintf(stderr, PROG ": cannot start LAMMPS\n");
        return 1;
    }
    coupling c = {.sys = sys, .st = st, .n = n, .dim = odhs_system_dim(sys), .sync_tol = sync_tol};
    c.x = malloc(3 * n * sizeof *c.x);
    c.xl = malloc(n * (size_t)c.dim * sizeof *c.xl);
    c.u = malloc(n * (size_t)c.dim * sizeof *c.u);
    if (!c.x || !c.xl || !c.u) {
        fprintf(stderr, PROG ": out of memory\n");
        return 1;
    }
    double *r = c.u; /* the radii, for the mean diameter (c.u is free until the first push) */
    odhs_system_get_radii(sys, r);
    for (size_t i = 0; i < n; ++i) c.lambda += 2.0 * r[i] / (double)n;
    c.L[0] = c.L[1] = c.L[2] = 1.0;
    odhs_system_get_box(sys, c.L);
    /* LAMMPS reads the data file. The computes are LAMMPS's own (per-atom
     * volumes from its radii, reduced; the rms of its velocities), evaluated
     * at every step by a fix ave/time (whatever thermo output a --lammps-input
     * asks for) and read from it; thermo goes to the log only. */
    if (lmp_do("units lj") || lmp_do("dimension %d", c.dim) || lmp_do("atom_style sphere") ||
        lmp_do("boundary p p p") || lmp_do("atom_modify map yes") || lmp_do("read_data %s", data) ||
        lmp_do("compute odhs_radius all property/atom radius") ||
        lmp_do(c.dim == 2 ? "variable odhs_volume atom PI*c_odhs_radius^2"
                          : "variable odhs_volume atom 4.0/3.0*PI*c_odhs_radius^3") ||
        lmp_do("compute odhs_solid all reduce sum v_odhs_volume") ||
        lmp_do("variable odhs_phi equal c_odhs_solid/vol") ||
        lmp_do("variable odhs_v2 atom vx*vx+vy*vy+vz*vz") || lmp_do("compute odhs_v2 all reduce ave v_odhs_v2") ||
        lmp_do("variable odhs_dv_rms equal sqrt(c_odhs_v2)") ||
        lmp_do("fix odhs_obs all ave/time 1 1 1 v_odhs_phi v_odhs_dv_rms") ||
        lmp_do("thermo_style custom step time v_odhs_phi v_odhs_dv_rms xy") || lmp_do("thermo 1") ||
        lmp_do("thermo_modify warn ignore"))
        return 1;
    if (dump && (lmp_do("dump odhs all custom 1 %s id type radius x y z vx vy vz", dump) ||
                 lmp_do("dump_modify odhs sort id format float %%.17g time yes")))
        return 1;
    if (check_atoms(&c)) return 1;
    if (lmp_input) {
        if (access(lmp_input, R_OK)) {
            fprintf(stderr, PROG ": cannot read %s: %s\n", lmp_input, strerror(errno));
            return 1;
        }
        snprintf(G.cmd, sizeof G.cmd, "(the commands of %s)", lmp_input);
        lammps_file(G.lmp, lmp_input);
        if (lammps_has_error(G.lmp)) {
            char msg[1024] = "";
            lammps_get_last_error_message(G.lmp, msg, sizeof msg);
            fprintf(stderr, PROG ": LAMMPS input %s failed: %s\n", lmp_input, msg);
            return 1;
        }
        G.cmd[0] = 0;
    }
    if (!quiet) fprintf(stderr, PROG ": LAMMPS %d holds the atoms (read from %s)\n", lammps_version(G.lmp), data);
    if (G.data[0]) { /* LAMMPS has read it */
        remove(G.data);
        G.data[0] = 0;
    }

    FILE *csv;
    if (cli_series_units(cli.prog, series, SERIES, UNITS, &csv)) return 1;
    cli_progress prog;
    cli_progress_init(&prog, cli.prog, quiet);
    printf("%12s %14s %14s %8s %10s%s %10s %14s %9s\n", "strain", "shear_stress", "pressure", "z", "events",
           pressure > 0 ? "        phi          kappa" : "", "lmp_phi", "lmp_dv_rms", "sync");
    double g0, prev, t;
    odhs_stepper_strain(st, &g0);
    prev = g0;
    long nout = (long)ceil(strain / every - 1e-9);
    int failed = 0;
    for (long k = 0; k <= nout && !failed; ++k) {
        double target = g0 + fmin(k * every, strain), g;
        if (pull(&c)) { /* 1. */
            failed = 1;
            break;
        }
        if (k > 0 && (rc = odhs_stepper_run_until_strain(st, target))) { /* 2. */
            odhs_stepper_strain(st, &g);
            cli_progress_break(&prog);
            fprintf(stderr, PROG ": stopped at strain %.6g of %.6g: %s (%s)\n", g - g0, strain, odhs_strerror(rc),
                    odhs_stepper_errmsg(st));
            failed = rc < 0 ? 1 : 3;
            break;
        }
        odhs_stepper_strain(st, &g);
        if (push(&c) || lammps_step((int)k, g - prev)) { /* 3., 4. */
            failed = 1;
            break;
        }
        prev = g;
        uint64_t steps, nc, no;
        odhs_stepper_time(st, &t);
        odhs_stepper_counts(st, &steps, &nc, &no);
        output(&c, csv, g - g0, t, pressure > 0);
        cli_progress_show(&prog, g - g0, strain, k == nout, "strain %.4f / %.4f, %llu steps, %llu events", g - g0,
                          strain, (unsigned long long)steps, (unsigned long long)(nc + no));
    }
    /* where LAMMPS's atoms end, against the library's */
    double final = NAN;
    if (!failed && !gather(&c)) {
        odhs_system_get_positions(sys, c.xl);
        final = distance(&c);
    }
    if (csv && fclose(csv)) {
        fprintf(stderr, PROG ": error writing %s\n", series);
        return 1;
    }
    if (!quiet) {
        double gap, ov;
        odhs_stepper_errors(st, &gap, &ov);
        fprintf(stderr, PROG ": worst contact gap %.3g, worst overlap %.3g (relative to contact distance)\n", gap,
                ov);
        fprintf(stderr,
                PROG ": positions handed over %lu times, largest difference %.3g mean diameters, taken from "
                     "LAMMPS %lu times; at the end LAMMPS's differ by %.3g\n",
                c.npull, c.sync_max, c.nadopt, final);
    }
    if (write_data && lmp_do("write_data %s", write_data)) return 1;
    if (outpath && cli_write_config(cli.prog, sys, outpath)) return 1;
    lammps_close(G.lmp);
    G.lmp = NULL;
    lammps_mpi_finalize();
    free(c.x);
    free(c.xl);
    free(c.u);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(solver);
    odhs_solver_destroy(rescue);
    odhs_system_destroy(sys);
    return failed;
}
