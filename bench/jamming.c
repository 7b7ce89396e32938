/* bench/jamming - jammed packings by event-driven compression (Sect. IV D of
 * Lerner, During & Wyart 2013): phi_J statistics and the cost of a certified
 * packing.
 *
 * usage: jamming [CSV]
 *   CSV   also write every table row (and every run) to this file
 * environment:
 *   ODHS_BENCH_BUDGET   wall-clock budget in seconds (default 1200)
 *   ODHS_BENCH_JOBS     packings computed at the same time (default: the
 *                       number of online CPUs); each in its own process
 *   ODHS_BENCH_SOLVER   force a solver backend (default: the first of
 *                       cholmod-pcg, cholmod, spqr, dense that this library
 *                       provides: the sparse ones are the fast ones near
 *                       jamming, where cg stalls and dense costs O(Nc^3))
 *   ODHS_BENCH_N2, ODHS_BENCH_N3  force the sizes of table 1 (2D, 3D)
 *   ODHS_BENCH_CORRECTION  drift correction every K steps (default 1, as
 *                       examples/jam_packing: the contact gaps must be at
 *                       round-off when the packing jams)
 *   ODHS_BENCH_TABLES   the tables to run, e.g. "3" (default "123"); a table
 *                       left out is printed as skipped
 *   ODHS_BENCH_SOFT_SIZES  the starts of table 3 as dim:N pairs separated by
 *                       commas (default "2:256,2:1024,3:128", at most 8)
 *
 * Scene: 50:50 bidisperse discs/spheres, radii 0.5 and 0.7 (ratio 1.4), 3%
 * uniform polydispersity, random sequential placement at phi = 0.45 (2D) /
 * 0.30 (3D), then isotropic compression (rate 1, V_aff = -R) with the
 * library's default adaptive integrator (drift correction every step) until the
 * stepper returns ODHS_JAMMED (isostatic backbone, positive self-stress).
 * A packing is "certified" when its certificate has jammed = isostatic = 1,
 * force balance < 1e-12, contact gaps < 1e-13, overlaps <= 1e-14, smallest
 * backbone force > 0 and d(Nbar-1)+1 backbone contacts.
 *
 * Tables:
 *  1. phi_J over 20 seeds, 2D and 3D (mean, standard deviation, min, max,
 *     rattler fraction): the largest of N = 1024, 512, 256, 128, 64 (2D) and
 *     1000, 500, 250, 128, 64 (3D) whose estimated cost fits 35% of the
 *     budget each (estimated from a pilot run as t ~ N^3 with a sparse solver,
 *     N^4 with dense); the sizes skipped are printed.
 *  2. time to a certified packing for N = 256, 512, 1024, 4096 (2D) and 1000 (3D),
 *     each size run only if its estimated time fits the remaining budget.
 *  3. the soft-sphere route (harmonic repulsion, compress and minimise with
 *     FIRE, bisection on phi: O'Hern et al. 2003) from the same starts as the
 *     event-driven packings of 2D N = 256, 1024 and 3D N = 128 (seed 1):
 *     time, phi_J bracket, overlaps at jamming, against the event-driven
 *     packing (exact contacts, certified). ODHS_BENCH_SOFT_LIMIT (seconds,
 *     default 3600) bounds each of these runs.
 *  4. (not in the default "123") the routes side by side from the same
 *     starts, ODHS_BENCH_ROUTE_SEEDS seeds (default 5) from seed
 *     ODHS_BENCH_ROUTE_FIRST_SEED (default 1), sizes
 *     ODHS_BENCH_ROUTE_SIZES (default 2:256,2:1024,3:343,3:1000), routes
 *     ODHS_BENCH_ROUTES (default quench,lp,events,soft,lammps): the fast
 *     route from its quench start and from the configuration
 *     (odhs_stepper_jam_lp), the event-driven compression, the soft-sphere
 *     route of table 3, and LAMMPS (lmp, Debian package lammps) running the
 *     O'Hern protocol from an input this program writes; a route missing
 *     from the machine is reported as skipped. CPU seconds per packing and
 *     their ratio to the first route run. ODHS_BENCH_SOFT_LIMIT bounds each run.
 *     ODHS_BENCH_LP_TOL sets the chain's tolerance of the quench and lp
 *     routes (default the library's; a looser one leaves work to the end
 *     game) and ODHS_BENCH_LP_END=batched|own their end game (since 0.2.22;
 *     odhs_jam_lp_options.own_integrator); the work column adds the mean
 *     number of end-game steps.
 *
 * Every packing runs in a child process (fork), so a run that exceeds its
 * time limit is killed and reported instead of stalling the benchmark.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif
#include <errno.h>
#include <math.h>
#include <signal.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/resource.h>
#include <sys/stat.h>
#include <sys/utsname.h>
#include <sys/wait.h>
#include <time.h>
#include <unistd.h>

#include "bench.h"
#include "odhs.h"

#define N_SEEDS 20

/* ---- one packing ---------------------------------------------------------- */
typedef struct {
    int dim;
    size_t n;
    unsigned seed;
    int done;      /* 1: the child reported; 0: killed (time limit) or crashed */
    int rc;        /* final status of the run                                 */
    int certified; /* all certificate criteria met                            */
    double wall, cpu;
    uint64_t steps, collisions, openings;
    odhs_jam_certificate cert;
    double f0_diff; /* max |f0(LAPACK) - f0(solver route)|, NAN if not run    */
    /* soft: the soft-sphere route instead (table 3); its results */
    int soft;
    double s_phi_lo, s_phi_hi; /* last unjammed and first jammed phi        */
    double s_overlap, s_z, s_fres; /* at the first jammed state: largest
                                    * overlap / d_ij, z without rattlers,
                                    * largest residual force              */
    uint64_t s_mins, s_iters; /* minimisations and FIRE iterations           */
    /* table 4: lp = the fast route (odhs_stepper_jam_lp), lammps = LAMMPS
     * doing the soft-sphere route (s_phi_lo/hi, s_mins) */
    int lp, lammps; /* lp: 1 from the configuration, 2 from the quench start */
    odhs_jam_lp_report lprep;
} result;

static char solver_name[32] = "dense";
/* the fast route's settings (table 4): ODHS_BENCH_LP_TOL, the chain's
 * tolerance (default the library's, 1e-12; a looser one ends the chain
 * unjammed and shows the end game), ODHS_BENCH_LP_END=batched|own, its end
 * game (odhs_jam_lp_options.own_integrator; default batched since 0.2.22) */
static double lp_tol;
static int lp_own;
static unsigned correction = 1;

static int certified(const odhs_jam_certificate *c, int dim)
{
    return c->jammed == 1 && c->isostatic == 1 && c->force_balance < 1e-12 && c->gap_error < 1e-13 &&
           c->overlap <= 1e-14 && c->min_force > 0.0 && c->n_backbone > 0 &&
           c->n_contacts_backbone == (size_t)dim * (c->n_backbone - 1) + 1;
}

/* The soft-sphere route (O'Hern, Silbert, Liu & Nagel 2003) on the same
 * start: harmonic repulsion (k_e = 1), compress affinely by dphi, minimise
 * with FIRE to max |F| < SOFT_FTOL; the state is jammed when the energy per
 * particle exceeds SOFT_EJAM. A jammed state sends the system back to the
 * last unjammed one and halves dphi, until dphi < SOFT_DPHI_END: phi_J lies
 * between the last unjammed and the first jammed phi. */
#define SOFT_FTOL 1e-14
#define SOFT_EJAM 1e-16
#define SOFT_DPHI0 1e-3
#define SOFT_DPHI_END 1e-9
static void run_soft(result *r)
{
    double t0 = bench_wall(), c0 = bench_cpu();
    odhs_system *sys = NULL;
    odhs_softcore *sc = NULL;
    int d = r->dim;
    size_t nd = r->n * (size_t)d;
    double *xs = malloc(nd * sizeof *xs);
    r->rc = xs ? odhs_system_create(d, r->n, &sys) : ODHS_E_NOMEM;
    if (!r->rc) r->rc = odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, r->seed);
    if (!r->rc) r->rc = odhs_system_place_random(sys, d == 2 ? 0.45 : 0.30, r->seed + 1);
    if (!r->rc) r->rc = odhs_softcore_create(sys, &sc);
    if (!r->rc) r->rc = odhs_softcore_set_potential(sc, 2.0, 1.0);
    if (!r->rc) r->rc = odhs_softcore_set_minimiser(sc, ODHS_SOFTCORE_FIRE);
    if (!r->rc) r->rc = odhs_softcore_set_min_tolerance(sc, SOFT_FTOL, 100000000);
    double phi = 0.0, dphi = SOFT_DPHI0;
    if (!r->rc) r->rc = odhs_system_packing_fraction(sys, &phi);
    r->s_phi_hi = NAN;
    while (!r->rc && dphi >= SOFT_DPHI_END * phi) {
        odhs_system_get_positions(sys, xs);
        double s = pow(phi / (phi + dphi), 1.0 / d), U = 0.0;
        uint64_t it = 0;
        if ((r->rc = odhs_softcore_scale_box(sc, s))) break;
        int m = odhs_softcore_minimise(sc, &it);
        r->s_mins++;
        r->s_iters += it;
        if (m && m != ODHS_E_NOCONV) {
            r->rc = m;
            break;
        }
        odhs_softcore_energy(sc, &U);
        if (m == ODHS_E_NOCONV || U / (double)r->n > SOFT_EJAM) {
            /* jammed (or not relaxed): note it, back to the last unjammed state */
            r->s_phi_hi = phi + dphi;
            odhs_softcore_max_overlap(sc, &r->s_overlap);
            odhs_softcore_coordination(sc, 1, &r->s_z);
            odhs_softcore_max_force(sc, &r->s_fres);
            if ((r->rc = odhs_softcore_scale_box(sc, 1.0 / s))) break;
            if ((r->rc = odhs_softcore_set_positions(sc, xs))) break;
            dphi *= 0.5;
        } else {
            phi += dphi;
        }
    }
    r->s_phi_lo = phi;
    r->cert.phi = phi;
    r->certified = 0;
    r->wall = bench_wall() - t0;
    r->cpu = bench_cpu() - c0;
    r->done = 1;
    odhs_softcore_destroy(sc);
    odhs_system_destroy(sys);
    free(xs);
}

/* ---- LAMMPS (Debian package lammps, binary lmp) doing the soft-sphere route ---- */
/* The O'Hern protocol as a LAMMPS input: harmonic repulsion (pair granular,
 * hooke, k_n = 1, no damping, no tangential force), the start compressed
 * affinely to phi = 0.70 (2D; 0.50 in 3D), FIRE to |F| < 1e-14 (LAMMPS's ftol: the 2-norm of
 * the global force vector), then steps of dphi = 1e-3 halved from the last
 * unjammed state whenever the largest pair force after the minimisation
 * exceeds 1e-10 (jammed; a minimisation that stops at its 1e5 iterations
 * has not relaxed its overlaps, so it counts as jammed, as in run_soft),
 * until dphi < 1e-6 phi. FIRE's time step 0.2 (masses pi/6 rho d^3 with
 * rho = 1, k_n = 1). Prints "phi_unjammed
 * phi_jammed minimisations" to the file ${out}. */
static const char lammps_input[] =
    "units lj\n"
    "dimension ${dim}\n"
    "boundary p p p\n"
    "atom_style sphere\n"
    "atom_modify map array\n"
    "comm_modify vel yes\n"
    "newton off\n"
    "read_data ${data}\n"
    "pair_style granular\n"
    "pair_coeff * * hooke 1.0 0.0 tangential linear_nohistory 0.0 0.0\n"
    "neighbor 0.3 bin\n"
    "neigh_modify delay 0 every 1 check yes\n"
    "timestep 0.2\n"
    "compute rad all property/atom radius\n"
    "variable va atom ${vfac}*c_rad^${dim}\n"
    "compute sa all reduce sum v_va\n"
    "variable phi equal c_sa/vol\n"
    "compute pf all pair/local force\n"
    "compute fm all reduce max c_pf\n"
    "thermo_style custom step c_fm c_sa\n"
    "thermo 1000000000\n"
    "min_style fire\n"
    "run 0 post no\n"
    "variable s0 equal $((v_phi/v_phi0)^(1.0/v_dim))\n"
    "change_box all @S0@ remap\n"
    "minimize 0.0 1e-14 100000 1000000\n"
    "run 0 post no\n"
    "variable phiu equal $(v_phi)\n"
    "variable phih equal 1.0\n"
    "variable dphi equal 1e-3\n"
    "variable nmin equal 1\n"
    "reset_timestep 0\n"
    "write_dump all custom ${dump} id @XYZ@ modify sort id format float %.17g\n"
    "label loop\n"
    "variable s equal $((v_phiu/(v_phiu+v_dphi))^(1.0/v_dim))\n"
    "change_box all @S@ remap\n"
    "minimize 0.0 1e-14 100000 1000000\n"
    "run 0 post no\n"
    "variable nmin equal $(v_nmin+1)\n"
    "if \"$(c_fm) > 1e-10\" then \"variable phih equal $(v_phi)\" "
    "\"read_dump ${dump} 0 @XYZ@ box yes replace yes\" \"variable dphi equal $(v_dphi*0.5)\" "
    "else \"variable phiu equal $(v_phi)\" \"reset_timestep 0\" "
    "\"write_dump all custom ${dump} id @XYZ@ modify sort id format float %.17g\"\n"
    "if \"$(v_dphi) < $(1e-6*v_phiu)\" then \"jump SELF done\"\n"
    "jump SELF loop\n"
    "label done\n"
    "print \"$(v_phiu:%.12f) $(v_phih:%.12f) $(v_nmin)\" file ${out}\n";

static void run_lammps(result *r)
{
    double t0 = bench_wall();
    struct rusage ru0, ru1;
    getrusage(RUSAGE_CHILDREN, &ru0);
    char dir[] = "/tmp/odhs_bench_lmp_XXXXXX", data[96], in[96], out[96], dump[96];
    odhs_system *sys = NULL;
    r->rc = mkdtemp(dir) ? odhs_system_create(r->dim, r->n, &sys) : ODHS_E_IO;
    snprintf(data, sizeof data, "%s/start.data", dir);
    snprintf(in, sizeof in, "%s/in.ohern", dir);
    snprintf(out, sizeof out, "%s/result.txt", dir);
    snprintf(dump, sizeof dump, "%s/unjammed.dump", dir);
    if (!r->rc) r->rc = odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, r->seed);
    if (!r->rc) r->rc = odhs_system_place_random(sys, r->dim == 2 ? 0.45 : 0.30, r->seed + 1);
    if (!r->rc) r->rc = odhs_lammps_data_write(sys, data);
    /* the input with the dimension's scalings and coordinates filled in */
    FILE *f = r->rc ? NULL : fopen(in, "w");
    if (!r->rc && !f) r->rc = ODHS_E_IO;
    for (const char *c = lammps_input; f && *c; ++c) {
        const char *sub = NULL;
        size_t skip = 0;
        if (!strncmp(c, "@S0@", 4)) {
            sub = r->dim == 2 ? "x scale ${s0} y scale ${s0}" : "x scale ${s0} y scale ${s0} z scale ${s0}";
            skip = 4;
        } else if (!strncmp(c, "@S@", 3)) {
            sub = r->dim == 2 ? "x scale ${s} y scale ${s}" : "x scale ${s} y scale ${s} z scale ${s}";
            skip = 3;
        } else if (!strncmp(c, "@XYZ@", 5)) {
            sub = r->dim == 2 ? "x y" : "x y z";
            skip = 5;
        }
        if (sub) {
            fputs(sub, f);
            c += skip - 1;
        } else {
            fputc(*c, f);
        }
    }
    if (f && (ferror(f) | fclose(f))) r->rc = ODHS_E_IO;
    if (!r->rc) {
        const int d = r->dim;
        pid_t pid = fork();
        if (pid == 0) {
            char sdim[8], vfac[32];
            snprintf(sdim, sizeof sdim, "%d", d);
            snprintf(vfac, sizeof vfac, "%.17g", d == 2 ? 3.14159265358979323846 : 4.0 * 3.14159265358979323846 / 3.0);
            execlp("lmp", "lmp", "-var", "dim", sdim, "-var", "phi0", d == 2 ? "0.70" : "0.50", "-var", "vfac", vfac, "-var", "data", data, "-var", "out", out,
                   "-var", "dump", dump, "-in", in, "-log", "none", "-screen", "none", (char *)NULL);
            _exit(127);
        }
        int status = 0;
        if (pid < 0 || waitpid(pid, &status, 0) != pid) r->rc = ODHS_E_INTERNAL;
        else if (WIFEXITED(status) && WEXITSTATUS(status) == 127) r->rc = ODHS_E_NOTINSTALLED;
        else if (!WIFEXITED(status) || WEXITSTATUS(status) != 0) r->rc = ODHS_E_CALLBACK;
        FILE *g = r->rc ? NULL : fopen(out, "r");
        unsigned long long nmin = 0;
        if (!r->rc && (!g || fscanf(g, "%lf %lf %llu", &r->s_phi_lo, &r->s_phi_hi, &nmin) != 3)) r->rc = ODHS_E_FORMAT;
        if (g) fclose(g);
        r->s_mins = nmin;
    }
    getrusage(RUSAGE_CHILDREN, &ru1);
    r->cpu = (double)(ru1.ru_utime.tv_sec - ru0.ru_utime.tv_sec + ru1.ru_stime.tv_sec - ru0.ru_stime.tv_sec) +
             1e-6 * (double)(ru1.ru_utime.tv_usec - ru0.ru_utime.tv_usec + ru1.ru_stime.tv_usec - ru0.ru_stime.tv_usec);
    r->wall = bench_wall() - t0;
    r->cert.phi = r->s_phi_lo;
    r->certified = 0;
    r->done = 1;
    remove(data);
    remove(in);
    remove(out);
    remove(dump);
    rmdir(dir);
    odhs_system_destroy(sys);
}

/* the packing itself (runs in the child) */
static void run_packing(result *r, int f0_check)
{
    if (r->soft) {
        run_soft(r);
        return;
    }
    if (r->lammps) {
        run_lammps(r);
        return;
    }
    double t0 = bench_wall(), c0 = bench_cpu();
    odhs_system *sys = NULL;
    odhs_solver *sol = NULL;
    odhs_driver *drv = NULL;
    odhs_stepper *st = NULL;
    r->f0_diff = NAN;
    r->rc = odhs_system_create(r->dim, r->n, &sys);
    if (!r->rc) r->rc = odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, r->seed);
    if (!r->rc) r->rc = odhs_system_place_random(sys, r->dim == 2 ? 0.45 : 0.30, r->seed + 1);
    if (!r->rc) r->rc = odhs_solver_create_by_name(solver_name, &sol);
    if (!r->rc) r->rc = odhs_driver_create(&drv);
    if (!r->rc) r->rc = odhs_driver_set_compression_rate(drv, 1.0);
    if (!r->rc) r->rc = odhs_stepper_create(sys, drv, sol, &st);
    if (!r->rc) r->rc = odhs_stepper_set_correction_interval(st, correction);
    r->lprep.size = sizeof r->lprep;
    odhs_jam_lp_options lo = {.size = sizeof lo, .quench = r->lp == 2, .tol = lp_tol, .own_integrator = lp_own};
    if (!r->rc) r->rc = r->lp ? odhs_stepper_jam_lp(st, &lo, &r->lprep) : odhs_stepper_run_until_packing_fraction(st, 0.999);
    r->wall = bench_wall() - t0;
    r->cpu = bench_cpu() - c0;
    if (st) {
        odhs_stepper_counts(st, &r->steps, &r->collisions, &r->openings);
        r->cert.size = sizeof r->cert;
        if (odhs_stepper_certificate(st, &r->cert) == ODHS_OK)
            r->certified = r->rc == ODHS_JAMMED && certified(&r->cert, r->dim);
        /* LAPACK route against the solver route on large backbones */
        const odhs_network *net = odhs_stepper_network(st);
        int pj = 0;
        if (f0_check && r->rc == ODHS_JAMMED && odhs_network_potentially_jammed(net, &pj) == ODHS_OK && pj &&
            r->cert.n_contacts_backbone > 600) {
            size_t m = odhs_network_count(net);
            double *a = calloc(m, sizeof *a), *b = calloc(m, sizeof *b);
            if (a && b && odhs_network_null_vector(net, NULL, a, NULL) == ODHS_OK &&
                odhs_network_null_vector(net, sol, b, NULL) == ODHS_OK) {
                double e = 0.0;
                for (size_t k = 0; k < m; ++k) e = fmax(e, fabs(a[k] - b[k]));
                r->f0_diff = e;
            }
            free(a);
            free(b);
        }
    }
    r->done = 1;
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    odhs_system_destroy(sys);
}

/* ---- a pool of child processes ---------------------------------------------- */
typedef struct {
    pid_t pid;
    int fd;
    size_t job;
    double start;
} child;

/* Run jobs[0..njobs-1] with at most `workers` at a time. No new job starts
 * after `stop_at` (absolute time); a job running longer than `job_limit`
 * seconds is killed. Jobs never started keep done = 0 and wall = -1. */
static void run_pool(result *jobs, size_t njobs, int workers, double stop_at, double job_limit, int f0_check)
{
    child *ch = calloc((size_t)workers, sizeof *ch);
    if (!ch) return;
    for (int w = 0; w < workers; ++w) ch[w].pid = -1;
    for (size_t k = 0; k < njobs; ++k) jobs[k].wall = -1.0;
    size_t next = 0;
    int running = 0;
    for (;;) {
        while (running < workers && next < njobs && bench_wall() < stop_at) {
            int w = 0;
            while (ch[w].pid != -1) w++;
            int p[2];
            if (pipe(p) != 0) {
                perror("pipe");
                exit(1);
            }
            fflush(stdout);
            pid_t pid = fork();
            if (pid < 0) {
                perror("fork");
                exit(1);
            }
            if (pid == 0) {
                close(p[0]);
                result r = jobs[next];
                run_packing(&r, f0_check);
                ssize_t wr = write(p[1], &r, sizeof r);
                _exit(wr == (ssize_t)sizeof r ? 0 : 1);
            }
            close(p[1]);
            ch[w].pid = pid;
            ch[w].fd = p[0];
            ch[w].job = next++;
            ch[w].start = bench_wall();
            running++;
        }
        if (running == 0) break;
        struct timespec ts = {0, 100000000};
        nanosleep(&ts, NULL);
        for (int w = 0; w < workers; ++w) {
            if (ch[w].pid == -1) continue;
            int status;
            pid_t g = waitpid(ch[w].pid, &status, WNOHANG);
            if (g == 0 && bench_wall() - ch[w].start > job_limit) {
                kill(ch[w].pid, SIGKILL);
                waitpid(ch[w].pid, &status, 0);
                jobs[ch[w].job].wall = bench_wall() - ch[w].start;
                jobs[ch[w].job].done = 0;
                fprintf(stderr, "  killed: %dD N = %zu seed %u after %.0f s (time limit)\n", jobs[ch[w].job].dim,
                        jobs[ch[w].job].n, jobs[ch[w].job].seed, jobs[ch[w].job].wall);
            } else if (g == ch[w].pid) {
                result r;
                ssize_t rd = read(ch[w].fd, &r, sizeof r);
                if (rd == (ssize_t)sizeof r) {
                    jobs[ch[w].job] = r;
                    fprintf(stderr, "  done: %dD N = %zu seed %u: rc %d, phi %.6f, %s, %.1f s\n", r.dim, r.n, r.seed,
                            r.rc, r.cert.phi, r.certified ? "certified" : "NOT certified", r.wall);
                } else {
                    jobs[ch[w].job].done = 0;
                    jobs[ch[w].job].wall = bench_wall() - ch[w].start;
                    fprintf(stderr, "  crashed: %dD N = %zu seed %u\n", jobs[ch[w].job].dim, jobs[ch[w].job].n,
                            jobs[ch[w].job].seed);
                }
            } else {
                continue;
            }
            close(ch[w].fd);
            ch[w].pid = -1;
            running--;
        }
    }
    free(ch);
}

/* ---- output -------------------------------------------------------------------- */
static FILE *csv;

static void machine(int workers, double budget)
{
    struct utsname u;
    char model[256];
    bench_cpu_model(model, sizeof model);
    uname(&u);
    const char *ob = getenv("OPENBLAS_NUM_THREADS");
    printf("# bench/jamming: jammed packings by event-driven compression\n");
    printf("# machine: %s, %ld online CPUs, %s %s %s\n", model, sysconf(_SC_NPROCESSORS_ONLN), u.sysname, u.release,
           u.machine);
    printf("# libodhs %s, compiler %s, solver %s, OPENBLAS_NUM_THREADS=%s\n", odhs_version_string(),
#ifdef __VERSION__
           __VERSION__,
#else
           "unknown",
#endif
           solver_name, ob ? ob : "(unset)");
    printf("# settings: bidisperse 50:50, radii 0.5/0.7, 3%% polydispersity, RSA at phi 0.45 (2D) / 0.30 (3D),\n"
           "#   compression rate 1, default adaptive integrator, drift correction every %u step(s), stop at ODHS_JAMMED;\n"
           "#   %d packings at a time (one process each), budget %.0f s\n",
           correction, workers, budget);
    if (csv) {
        fprintf(csv, "# machine,%s,%ld CPUs,%s %s,libodhs %s,solver %s\n", model, sysconf(_SC_NPROCESSORS_ONLN),
                u.sysname, u.release, odhs_version_string(), solver_name);
        fprintf(csv, "table,dim,N,seeds_run,jammed,certified,phi_mean,phi_sd,phi_min,phi_max,rattler_frac_mean,"
                     "z_backbone_mean,seconds_mean,seconds_max,steps_mean,worst_force_balance,worst_gap,"
                     "worst_overlap,min_force_min,f0_lapack_vs_solver,note\n");
    }
}

typedef struct {
    size_t runs, jammed, cert;
    double phi_mean, phi_sd, phi_min, phi_max, rat_mean, z_mean, sec_mean, sec_max, steps_mean;
    double fb, gap, ov, minf, f0d;
} summary;

/* statistics over the runs that ended jammed (certified or not) */
static summary summarize(const result *r, size_t n)
{
    summary s;
    memset(&s, 0, sizeof s);
    s.phi_min = INFINITY;
    s.phi_max = -INFINITY;
    s.minf = INFINITY;
    s.f0d = NAN;
    double sum = 0.0, sum2 = 0.0;
    for (size_t k = 0; k < n; ++k) {
        if (r[k].wall < 0) continue;
        s.runs++;
        s.sec_max = fmax(s.sec_max, r[k].wall);
        if (!r[k].done || r[k].rc != ODHS_JAMMED) continue;
        s.jammed++;
        s.cert += r[k].certified;
        double phi = r[k].cert.phi;
        sum += phi;
        sum2 += phi * phi;
        s.phi_min = fmin(s.phi_min, phi);
        s.phi_max = fmax(s.phi_max, phi);
        s.rat_mean += (double)r[k].cert.n_rattlers / (double)r[k].cert.n_particles;
        s.z_mean += r[k].cert.z_backbone;
        s.sec_mean += r[k].wall;
        s.steps_mean += (double)r[k].steps;
        s.fb = fmax(s.fb, r[k].cert.force_balance);
        s.gap = fmax(s.gap, r[k].cert.gap_error);
        s.ov = fmax(s.ov, r[k].cert.overlap);
        s.minf = fmin(s.minf, r[k].cert.min_force);
        if (!isnan(r[k].f0_diff)) s.f0d = isnan(s.f0d) ? r[k].f0_diff : fmax(s.f0d, r[k].f0_diff);
    }
    if (s.jammed) {
        double m = (double)s.jammed;
        s.phi_mean = sum / m;
        s.phi_sd = s.jammed > 1 ? sqrt(fmax(0.0, (sum2 - m * s.phi_mean * s.phi_mean) / (m - 1.0))) : 0.0;
        s.rat_mean /= m;
        s.z_mean /= m;
        s.sec_mean /= m;
        s.steps_mean /= m;
    }
    return s;
}

static void csv_row(const char *table, int dim, size_t n, const summary *s, const char *note)
{
    if (!csv) return;
    fprintf(csv, "%s,%d,%zu,%zu,%zu,%zu,%.9f,%.3e,%.9f,%.9f,%.5f,%.5f,%.2f,%.2f,%.0f,%.3e,%.3e,%.3e,%.3e,%.3e,%s\n",
            table, dim, n, s->runs, s->jammed, s->cert, s->phi_mean, s->phi_sd, s->phi_min, s->phi_max, s->rat_mean,
            s->z_mean, s->sec_mean, s->sec_max, s->steps_mean, s->fb, s->gap, s->ov, s->minf, s->f0d,
            note ? note : "");
}

static void csv_runs(const char *table, const result *r, size_t n)
{
    if (!csv) return;
    for (size_t k = 0; k < n; ++k) {
        if (r[k].wall < 0) continue;
        fprintf(csv,
                "run:%s,%d,%zu,seed %u,rc %d,%d,%d,%.12f,,,%.5f,%.5f,%.2f,%.2f,%llu,%.3e,%.3e,%.3e,%.3e,%.3e,%s\n",
                table, r[k].dim, r[k].n, r[k].seed, r[k].rc, r[k].done && r[k].rc == ODHS_JAMMED, r[k].certified,
                r[k].cert.phi,
                r[k].cert.n_particles ? (double)r[k].cert.n_rattlers / (double)r[k].cert.n_particles : 0.0,
                r[k].cert.z_backbone, r[k].wall, r[k].cpu, (unsigned long long)r[k].steps, r[k].cert.force_balance,
                r[k].cert.gap_error, r[k].cert.overlap, r[k].cert.min_force, r[k].f0_diff,
                r[k].done ? "" : "killed at the time limit");
    }
}

/* ---- plan ------------------------------------------------------------------------ */
/* measured seconds of one packing at (dim, n0), used to estimate size n:
 * t ~ t0 (n/n0)^3 with a sparse solver (steps ~ N, and more of them per
 * event near jamming; cost per step ~ N^1.5-2), ~ (n/n0)^4 with dense LAPACK
 * (O(Nc^3) per step). Rough: the number of steps varies by a factor 2-4
 * between seeds. */
#define EXPONENT(dense) ((dense) ? 4.0 : 3.0)
static double estimate(double t0, size_t n0, size_t n, int dense)
{
    return t0 * pow((double)n / (double)n0, EXPONENT(dense));
}

/* dim:N pairs separated by commas from environment variable `name` into
 * sizes (at most 8); *ns keeps its value when the variable is unset or
 * empty. Returns 1 after a message on a malformed entry. */
typedef struct {
    int dim;
    size_t n;
} size_spec;

static int parse_sizes(const char *name, size_spec *sizes, int *ns)
{
    const char *env = getenv(name);
    if (!env || !*env) return 0;
    *ns = 0;
    for (const char *q = env; *q && *ns < 8;) {
        int dd = 0, used = 0;
        unsigned long nn = 0;
        if (sscanf(q, "%d:%lu%n", &dd, &nn, &used) != 2 || (dd != 2 && dd != 3) || nn < 2) {
            fprintf(stderr, "jamming: bad %s entry at \"%s\" (want dim:N,...)\n", name, q);
            return 1;
        }
        sizes[*ns].dim = dd;
        sizes[*ns].n = (size_t)nn;
        (*ns)++;
        q += used;
        if (*q == ',') q++;
    }
    return 0;
}

/* ---- table 4: the routes side by side (issue 22) ------------------------------------ */
/* ODHS_BENCH_ROUTE_SIZES (dim:N,...; default 2:256,2:1024,3:343,3:1000),
 * ODHS_BENCH_ROUTE_SEEDS (seeds 1..S, default 5) and ODHS_BENCH_ROUTES (a
 * comma list of quench, lp, events, soft, lammps; default all five). Every run of
 * a size starts from the same placements; LAMMPS is skipped (reported) when
 * lmp is not installed. */
enum { R_QUENCH, R_LP, R_EVENTS, R_SOFT, R_LAMMPS, R_N };
static const char *const route_names[R_N] = {"quench", "lp", "events", "soft", "lammps"};

static int table4(int workers, double limit)
{
    size_spec sizes[8] = {{2, 256}, {2, 1024}, {3, 343}, {3, 1000}};
    int ns = 4;
    if (parse_sizes("ODHS_BENCH_ROUTE_SIZES", sizes, &ns)) return 1;
    const char *se = getenv("ODHS_BENCH_ROUTE_SEEDS");
    int seeds = se && atoi(se) > 0 ? atoi(se) : 5;
    if (seeds > 50) seeds = 50;
    const char *fse = getenv("ODHS_BENCH_ROUTE_FIRST_SEED");
    int first = fse && atoi(fse) > 0 && atoi(fse) < 100000 ? atoi(fse) : 1;
    const char *re = getenv("ODHS_BENCH_ROUTES");
    int want[R_N] = {1, 1, 1, 1, 1};
    if (re && *re) /* whole names of the comma list */
        for (int k = 0; k < R_N; ++k) {
            size_t l = strlen(route_names[k]);
            want[k] = 0;
            for (const char *p = re; (p = strstr(p, route_names[k])) != NULL; p += l)
                if ((p == re || p[-1] == ',') && (p[l] == '\0' || p[l] == ',')) want[k] = 1;
        }
    result *runs = calloc((size_t)ns * R_N * (size_t)seeds, sizeof *runs);
    if (!runs) return 1;
    size_t nr = 0;
    for (int z = 0; z < ns; ++z)
        for (int k = 0; k < R_N; ++k)
            for (int q = 0; q < seeds; ++q) {
                result *r = &runs[nr++];
                r->dim = sizes[z].dim;
                r->n = sizes[z].n;
                r->seed = (unsigned)(first + q);
                r->lp = k == R_LP ? 1 : k == R_QUENCH ? 2 : 0;
                r->soft = k == R_SOFT;
                r->lammps = k == R_LAMMPS;
                if (!want[k]) r->wall = -2.0; /* not asked for */
            }
    /* the pool skips nothing by itself: run the wanted ones, size by size */
    for (size_t k = 0; k < nr; ++k) {
        if (runs[k].wall == -2.0) continue;
        size_t e = k;
        while (e < nr && runs[e].wall != -2.0 && runs[e].dim == runs[k].dim && runs[e].n == runs[k].n) e++;
        fprintf(stderr, "table 4: %dD N = %zu, %zu runs\n", runs[k].dim, runs[k].n, e - k);
        run_pool(runs + k, e - k, workers, INFINITY, limit, 0);
        k = e - 1;
    }
    printf("\n## Table 4: routes to a jammed packing side by side, the same %d starts per size (seeds %d-%d)\n"
           "##   quench = odhs_stepper_jam_lp from its quench start (soft-sphere quench to phi 0.86, 3D 0.66, then\n"
           "##   the chain), lp = odhs_stepper_jam_lp (chain of linear programmes + exact end game), events = event-driven\n"
           "##   compression, soft = the library's soft-sphere route (table 3), lammps = LAMMPS (lmp) doing the\n"
           "##   O'Hern protocol from phi 0.70 (3D: 0.50) (harmonic, FIRE to 1e-14, bisection to 1e-6). CPU s per packing;\n"
           "##   ratio = route CPU / CPU of the first route listed. phi_J: certified packings for quench, lp and\n"
           "##   events, the last unjammed phi for the soft routes. work: programmes and end-game steps (quench, lp),\n"
           "##   steps (events), minimisations (soft, lammps). Chain tolerance %g (0: the library's), end game %s\n"
           "##   (ODHS_BENCH_LP_TOL, ODHS_BENCH_LP_END).\n",
           seeds, first, first + seeds - 1, lp_tol, lp_own ? "own (Heun)" : "batched");
    printf("%-3s %6s %-7s %5s %9s %10s %10s %11s %9s %8s %s\n", "d", "N", "route", "runs", "certified", "cpu_s",
           "cpu_max", "phi_J", "phi_sd", "ratio", "work");
    for (int z = 0; z < ns; ++z) {
        double lp_cpu = NAN; /* the first route listed */
        for (int k = 0; k < R_N; ++k) {
            const result *rr = &runs[((size_t)z * R_N + (size_t)k) * (size_t)seeds];
            if (rr[0].wall == -2.0) continue;
            size_t run = 0, ok = 0, cert = 0;
            double cpu = 0.0, cmax = 0.0, ph = 0.0, ph2 = 0.0;
            unsigned long long work = 0, end_steps = 0;
            int missing = 0;
            for (int q = 0; q < seeds; ++q) {
                const result *r = &rr[q];
                if (r->wall < 0) continue;
                run++;
                if (r->lammps && r->rc == ODHS_E_NOTINSTALLED) missing = 1;
                int good = r->done && (k <= R_EVENTS ? r->rc == ODHS_JAMMED : r->rc == ODHS_OK);
                if (!good) continue;
                ok++;
                cert += (size_t)r->certified;
                cpu += r->cpu;
                cmax = fmax(cmax, r->cpu);
                ph += r->cert.phi;
                ph2 += r->cert.phi * r->cert.phi;
                if (k <= R_LP) end_steps += r->lprep.end_steps;
                work += k <= R_LP       ? r->lprep.n_lps
                        : k == R_EVENTS ? r->steps
                                        : r->s_mins;
            }
            if (missing) {
                printf("%-3d %6zu %-7s skipped: lmp (Debian package lammps) is not installed\n", sizes[z].dim,
                       sizes[z].n, route_names[k]);
                continue;
            }
            if (!ok) {
                printf("%-3d %6zu %-7s %5zu none finished (time limit %.0f s or failure)\n", sizes[z].dim, sizes[z].n,
                       route_names[k], run, limit);
                continue;
            }
            double m = (double)ok, mean = ph / m, sd = ok > 1 ? sqrt(fmax(0.0, (ph2 - m * mean * mean) / (m - 1))) : 0;
            cpu /= m;
            if (lp_cpu != lp_cpu) lp_cpu = cpu;
            char cs[16];
            if (k <= R_EVENTS) snprintf(cs, sizeof cs, "%zu/%zu", cert, run);
            else snprintf(cs, sizeof cs, "-");
            printf("%-3d %6zu %-7s %5zu %9s %10.2f %10.2f %11.6f %9.5f %8.2f %llu %s", sizes[z].dim, sizes[z].n,
                   route_names[k], run, cs, cpu, cmax, mean, sd, cpu / lp_cpu, work / (unsigned long long)ok,
                   k <= R_LP ? "programmes" : k == R_EVENTS ? "steps" : "minimisations");
            if (k <= R_LP) printf(", %.1f end-game steps", (double)end_steps / m);
            printf("\n");
            if (csv)
                fprintf(csv, "routes,%d,%zu,%zu,%zu,%zu,%.9f,%.3e,,,,,%.2f,%.2f,%llu,,,,,,%s\n", sizes[z].dim,
                        sizes[z].n, run, ok, cert, mean, sd, cpu, cmax, work / (unsigned long long)ok,
                        route_names[k]);
        }
    }
    if (csv)
        for (size_t k = 0; k < nr; ++k) {
            const result *r = &runs[k];
            if (r->wall < 0) continue;
            fprintf(csv, "run:routes,%d,%zu,seed %u,rc %d,%s,%d,%.12f,,,,,%.2f,%.2f,,,,,,,%s\n", r->dim, r->n, r->seed,
                    r->rc, r->lp == 2 ? "quench" : r->lp ? "lp" : r->soft ? "soft" : r->lammps ? "lammps" : "events", r->certified,
                    r->cert.phi, r->wall, r->cpu, r->done ? "" : "killed at the time limit");
        }
    free(runs);
    return 0;
}

int main(int argc, char **argv)
{
    double t_start = bench_wall();
    const char *b = getenv("ODHS_BENCH_BUDGET"), *j = getenv("ODHS_BENCH_JOBS"), *fs = getenv("ODHS_BENCH_SOLVER");
    double budget = b ? atof(b) : 1200.0;
    if (!(budget > 0)) budget = 1200.0;
    const char *sl = getenv("ODHS_BENCH_SOFT_LIMIT");
    double soft_limit = sl && atof(sl) > 0 ? atof(sl) : 3600.0;
    long cpus = sysconf(_SC_NPROCESSORS_ONLN);
    int workers = j ? atoi(j) : (int)(cpus > 0 ? cpus : 1);
    if (workers < 1) workers = 1;
    if (argc > 1) {
        csv = fopen(argv[1], "w");
        if (!csv) {
            fprintf(stderr, "jamming: cannot write %s\n", argv[1]);
            return 1;
        }
    }
    /* solver: the first backend this library provides */
    const char *prefs[] = {"cholmod-pcg", "cholmod", "spqr", "dense"};
    const char *lt = getenv("ODHS_BENCH_LP_TOL"), *le = getenv("ODHS_BENCH_LP_END");
    if (lt && !(atof(lt) > 0.0 && atof(lt) < 1.0)) {
        fprintf(stderr, "jamming: ODHS_BENCH_LP_TOL=%s: a tolerance in (0, 1)\n", lt);
        return 2;
    }
    if (lt) lp_tol = atof(lt);
    if (le && strcmp(le, "own") && strcmp(le, "batched")) {
        fprintf(stderr, "jamming: ODHS_BENCH_LP_END=%s: batched or own\n", le);
        return 2;
    }
    lp_own = le && !strcmp(le, "own");
    const char *cs = getenv("ODHS_BENCH_CORRECTION");
    if (cs && atoi(cs) >= 0) correction = (unsigned)atoi(cs);
    char why[256] = "";
    if (fs) {
        snprintf(solver_name, sizeof solver_name, "%s", fs);
        snprintf(why, sizeof why, "forced by ODHS_BENCH_SOLVER");
    } else {
        for (int k = 0; k < 4; ++k) {
            odhs_solver *s;
            int rc = odhs_solver_create_by_name(prefs[k], &s);
            size_t l = strlen(why);
            if (rc == ODHS_OK) {
                odhs_solver_destroy(s);
                snprintf(solver_name, sizeof solver_name, "%s", prefs[k]);
                snprintf(why + l, sizeof why - l, "%s: available", prefs[k]);
                break;
            }
            snprintf(why + l, sizeof why - l, "%s: %s; ", prefs[k], odhs_strerror(rc));
        }
    }
    odhs_solver *probe;
    if (odhs_solver_create_by_name(solver_name, &probe) != ODHS_OK) {
        fprintf(stderr, "jamming: solver %s not available\n", solver_name);
        return 1;
    }
    odhs_solver_destroy(probe);
    int have_cholmod = !strncmp(solver_name, "cholmod", 7);
    int dense = !strcmp(solver_name, "dense");
    machine(workers, budget);
    printf("# solver choice: %s\n", why);
    const char *tabs = getenv("ODHS_BENCH_TABLES");
    if (!tabs || !*tabs) tabs = "123";
    int do1 = strchr(tabs, '1') != NULL, do2 = strchr(tabs, '2') != NULL, do3 = strchr(tabs, '3') != NULL;
    int do4 = strchr(tabs, '4') != NULL;
    printf("# tables: %s%s%s%s (ODHS_BENCH_TABLES)\n", do1 ? "1 " : "", do2 ? "2 " : "", do3 ? "3 " : "",
           do4 ? "4" : "");

    /* ---- pilot: one small packing per dimension, to size the plan ---------- */
    result pilot[2];
    memset(pilot, 0, sizeof pilot);
    pilot[0].dim = 2;
    pilot[0].n = 128;
    pilot[0].seed = 1;
    pilot[1].dim = 3;
    pilot[1].n = 64;
    pilot[1].seed = 1;
    run_pool(pilot, 2, workers, INFINITY, 600.0, 0);
    double t2 = pilot[0].done ? fmax(pilot[0].wall, 0.1) : 600.0, t3 = pilot[1].done ? fmax(pilot[1].wall, 0.1) : 600.0;
    printf("# pilot: 2D N = 128 %.1f s, 3D N = 64 %.1f s (used to estimate larger sizes as t ~ N^%.0f)\n", t2, t3,
           EXPONENT(dense));

    /* ---- table 1: phi_J statistics -------------------------------------------- */
    /* share of the budget: 35% each dimension's statistics, 30% timings */
    double share = 0.35 * budget;
    size_t cand2[] = {1024, 512, 256, 128, 64}, cand3[] = {1000, 500, 250, 128, 64};
    size_t n2 = 64, n3 = 64;
    char skipped[1024] = "";
    for (int k = 0; k < 5; ++k) {
        double est = estimate(t2, 128, cand2[k], dense) * N_SEEDS / workers;
        if (est <= share || k == 4) {
            n2 = cand2[k];
            break;
        }
        size_t l = strlen(skipped);
        snprintf(skipped + l, sizeof skipped - l, "  2D N = %zu x %d seeds: estimated %.0f s > %.0f s\n", cand2[k],
                 N_SEEDS, est, share);
    }
    for (int k = 0; k < 5; ++k) {
        double est = estimate(t3, 64, cand3[k], dense) * N_SEEDS / workers;
        if (est <= share || k == 4) {
            n3 = cand3[k];
            break;
        }
        size_t l = strlen(skipped);
        snprintf(skipped + l, sizeof skipped - l, "  3D N = %zu x %d seeds: estimated %.0f s > %.0f s\n", cand3[k],
                 N_SEEDS, est, share);
    }
    /* sizes forced from the environment (the estimate above is rough) */
    const char *fn2 = getenv("ODHS_BENCH_N2"), *fn3 = getenv("ODHS_BENCH_N3");
    if (fn2 && atol(fn2) >= 2) n2 = (size_t)atol(fn2), skipped[0] = '\0';
    if (fn3 && atol(fn3) >= 2) n3 = (size_t)atol(fn3), skipped[0] = '\0';
    if (skipped[0]) printf("# phi_J statistics: skipped (budget, solver %s%s):\n%s", solver_name,
                           have_cholmod ? "" : ", no CHOLMOD backend", skipped);

    result st2[N_SEEDS], st3[N_SEEDS];
    memset(st2, 0, sizeof st2);
    memset(st3, 0, sizeof st3);
    for (int k = 0; k < N_SEEDS; ++k) {
        st2[k].dim = 2;
        st2[k].n = n2;
        st2[k].seed = (unsigned)(k + 1);
        st3[k].dim = 3;
        st3[k].n = n3;
        st3[k].seed = (unsigned)(k + 1);
    }
    double limit2 = fmax(120.0, 5.0 * estimate(t2, 128, n2, dense));
    double limit3 = fmax(120.0, 5.0 * estimate(t3, 64, n3, dense));
    if (!do1) {
        for (int k = 0; k < N_SEEDS; ++k) st2[k].wall = st3[k].wall = -1.0; /* not run */
        printf("\n## Table 1: skipped (ODHS_BENCH_TABLES)\n");
    } else {
        fprintf(stderr, "phi_J statistics: 2D N = %zu, %d seeds\n", n2, N_SEEDS);
        run_pool(st2, N_SEEDS, workers, bench_wall() + share, limit2, 0);
        fprintf(stderr, "phi_J statistics: 3D N = %zu, %d seeds\n", n3, N_SEEDS);
        run_pool(st3, N_SEEDS, workers, bench_wall() + share, limit3, 0);
        summary s2 = summarize(st2, N_SEEDS), s3 = summarize(st3, N_SEEDS);

        printf("\n## Table 1: phi_J by compression (statistics over the runs that ended jammed)\n");
        printf("%-3s %6s %5s %6s %9s %9s %10s %9s %9s %13s %10s %9s\n", "d", "N", "runs", "jammed", "certified",
               "phi_mean", "phi_sd", "phi_min", "phi_max", "rattler_frac", "z_backbone", "s/packing");
        const summary *ss[2] = {&s2, &s3};
        size_t nn[2] = {n2, n3};
        for (int d = 0; d < 2; ++d) {
            const summary *s = ss[d];
            printf("%-3d %6zu %5zu %6zu %9zu %9.5f %10.2e %9.5f %9.5f %13.4f %10.4f %9.1f\n", d + 2, nn[d], s->runs,
                   s->jammed, s->cert, s->phi_mean, s->phi_sd, s->phi_min, s->phi_max, s->rat_mean, s->z_mean,
                   s->sec_mean);
            csv_row("phiJ", d + 2, nn[d], s, have_cholmod ? "" : "reduced size: no CHOLMOD backend");
        }
        printf("worst certificate numbers over the jammed runs (2D | 3D): force balance %.1e | %.1e, gap %.1e | %.1e,\n"
               "  overlap %.1e | %.1e, smallest force %.1e | %.1e\n",
               s2.fb, s3.fb, s2.gap, s3.gap, s2.ov, s3.ov, s2.minf, s3.minf);
        for (int d = 0; d < 2; ++d) {
            const result *r = d ? st3 : st2;
            int first = 1;
            for (int k = 0; k < N_SEEDS; ++k) {
                if (r[k].wall < 0 || (r[k].done && r[k].certified)) continue;
                if (first) printf("not certified (%dD):", d + 2);
                first = 0;
                if (r[k].wall < 0) continue;
                if (!r[k].done) printf(" seed %u killed;", r[k].seed);
                else if (r[k].rc != ODHS_JAMMED)
                    printf(" seed %u rc %d (%s);", r[k].seed, r[k].rc, odhs_strerror(r[k].rc));
                else
                    printf(" seed %u overlap %.1e min_force %.1e;", r[k].seed, r[k].cert.overlap, r[k].cert.min_force);
            }
            size_t notrun = 0;
            for (int k = 0; k < N_SEEDS; ++k) notrun += r[k].wall < 0;
            if (!first) printf("\n");
            if (notrun) printf("(%dD: %zu seeds not run: budget)\n", d + 2, notrun);
        }
        csv_runs("phiJ", st2, N_SEEDS);
        csv_runs("phiJ", st3, N_SEEDS);
    }

    /* ---- table 2: time to a certified packing ------------------------------------ */
    struct {
        int dim;
        size_t n;
    } sizes[] = {{2, 256}, {2, 512}, {2, 1024}, {2, 4096}, {3, 1000}};
    enum { NT = sizeof sizes / sizeof sizes[0] };
    result tr[NT];
    memset(tr, 0, sizeof tr);
    for (int k = 0; k < NT; ++k) {
        tr[k].dim = sizes[k].dim;
        tr[k].n = sizes[k].n;
        tr[k].wall = -1.0; /* not run (yet) */
    }
    if (!do2) {
        printf("\n## Table 2: skipped (ODHS_BENCH_TABLES)\n");
    } else {
        printf("\n## Table 2: time to a certified packing (seed 1, one packing per row, run alone)\n");
        printf("%-3s %6s %9s %10s %10s %8s %9s %9s %9s %9s %9s %9s %10s\n", "d", "N", "seconds", "cpu_s", "steps",
               "jammed", "certified", "phi_J", "f_bal", "gap", "overlap", "min_f", "f0_LvsS");
    }
    for (int k = 0; k < NT && do2; ++k) {
        tr[k].wall = 0.0;
        tr[k].seed = 1;
        double est = sizes[k].dim == 2 ? estimate(t2, 128, sizes[k].n, dense) : estimate(t3, 64, sizes[k].n, dense);
        double left = budget - (bench_wall() - t_start);
        /* a statistics run at this size already measured it: reuse seed 1 */
        const result *reuse = NULL;
        if (sizes[k].dim == 2 && sizes[k].n == n2 && st2[0].wall >= 0) reuse = &st2[0];
        if (sizes[k].dim == 3 && sizes[k].n == n3 && st3[0].wall >= 0) reuse = &st3[0];
        char note[160] = "";
        if (reuse) {
            tr[k] = *reuse;
            snprintf(note, sizeof note, "(from table 1, run alongside %d others)", workers - 1);
        } else if (est > left) {
            printf("%-3d %6zu skipped: estimated %.0f s > %.0f s left of the budget (solver %s)\n", sizes[k].dim,
                   sizes[k].n, est, left > 0 ? left : 0.0, solver_name);
            summary e;
            memset(&e, 0, sizeof e);
            char why2[128];
            snprintf(why2, sizeof why2, "skipped: estimated %.0f s > %.0f s left", est, left > 0 ? left : 0.0);
            csv_row("timing", sizes[k].dim, sizes[k].n, &e, why2);
            continue;
        } else {
            fprintf(stderr, "timing: %dD N = %zu (estimated %.0f s)\n", sizes[k].dim, sizes[k].n, est);
            run_pool(&tr[k], 1, 1, INFINITY, fmax(60.0, fmin(left, 3.0 * est)), 1);
        }
        const result *r = &tr[k];
        if (!r->done) {
            printf("%-3d %6zu killed after %.0f s (time limit)\n", r->dim, r->n, r->wall);
            continue;
        }
        printf("%-3d %6zu %9.1f %10.1f %10llu %8s %9s %9.6f %9.1e %9.1e %9.1e %9.1e %10.1e %s\n", r->dim, r->n,
               r->wall, r->cpu, (unsigned long long)r->steps, r->rc == ODHS_JAMMED ? "yes" : "no",
               r->certified ? "yes" : "NO", r->cert.phi, r->cert.force_balance, r->cert.gap_error, r->cert.overlap,
               r->cert.min_force, r->f0_diff, note);
        if (r->rc != ODHS_JAMMED) printf("    run ended with %d (%s)\n", r->rc, odhs_strerror(r->rc));
        summary e = summarize(r, 1);
        csv_row("timing", r->dim, r->n, &e, note);
    }
    if (do2) csv_runs("timing", tr, NT);

    /* ---- table 3: the soft-sphere route on the same starts ------------------------ */
    size_spec soft_sizes[8] = {{2, 256}, {2, 1024}, {3, 128}};
    int NS = do3 ? 3 : 0;
    if (do3 && parse_sizes("ODHS_BENCH_SOFT_SIZES", soft_sizes, &NS)) return 2;
    result sr[8], er[8];
    memset(sr, 0, sizeof sr);
    memset(er, 0, sizeof er);
    int have_er[8] = {0};
    if (!do3) printf("\n## Table 3: skipped (ODHS_BENCH_TABLES)\n");
    for (int k = 0; k < NS; ++k) {
        sr[k].dim = er[k].dim = soft_sizes[k].dim;
        sr[k].n = er[k].n = soft_sizes[k].n;
        sr[k].seed = er[k].seed = 1;
        sr[k].soft = 1;
        /* the event-driven packing of this start, if a table above made it */
        const result *pools[3] = {st2, st3, tr};
        size_t np[3] = {N_SEEDS, N_SEEDS, NT};
        for (int q = 0; q < 3 && !have_er[k]; ++q)
            for (size_t j = 0; j < np[q]; ++j)
                if (pools[q][j].dim == er[k].dim && pools[q][j].n == er[k].n && pools[q][j].seed == 1 &&
                    pools[q][j].done && pools[q][j].wall >= 0) {
                    er[k] = pools[q][j];
                    have_er[k] = 1;
                    break;
                }
    }
    if (NS) {
        fprintf(stderr, "soft-sphere route: %d starts\n", NS);
        run_pool(sr, NS, workers, INFINITY, soft_limit, 0);
        for (int k = 0; k < NS; ++k)
            if (!have_er[k]) run_pool(&er[k], 1, 1, INFINITY, soft_limit, 0);
        printf("\n## Table 3: soft-sphere route (harmonic, FIRE to max|F| < %.0e, jammed when U/N > %.0e,\n"
               "##   compression steps from %.0e halved to %.0e relative) against the event-driven packing, same start\n",
               SOFT_FTOL, SOFT_EJAM, SOFT_DPHI0, SOFT_DPHI_END);
        printf("%-3s %6s %-13s %9s %9s %14s %14s %10s %10s %10s %8s %12s\n", "d", "N", "route", "seconds", "cpu_s",
               "phi_J", "phi_J upper", "overlap", "gap", "resid_F", "z_bb", "work");
        for (int k = 0; k < NS; ++k) {
            const result *e = &er[k], *q = &sr[k];
            if (e->done)
                printf("%-3d %6zu %-13s %9.1f %9.1f %14.10f %14s %10.1e %10.1e %10.1e %8.4f %9llu st\n", e->dim, e->n,
                       "event-driven", e->wall, e->cpu, e->cert.phi, "(exact)", e->cert.overlap, e->cert.gap_error,
                       e->cert.force_balance, e->cert.z_backbone, (unsigned long long)e->steps);
            else
                printf("%-3d %6zu %-13s killed after %.0f s\n", e->dim, e->n, "event-driven", e->wall);
            if (q->done && !q->rc)
                printf("%-3d %6zu %-13s %9.1f %9.1f %14.10f %14.10f %10.1e %10s %10.1e %8.4f %6llu/%llu min/it\n",
                       q->dim, q->n, "soft-sphere", q->wall, q->cpu, q->s_phi_lo, q->s_phi_hi, q->s_overlap, "-",
                       q->s_fres, q->s_z, (unsigned long long)q->s_mins, (unsigned long long)q->s_iters);
            else if (q->done)
                printf("%-3d %6zu %-13s failed: %d (%s)\n", q->dim, q->n, "soft-sphere", q->rc, odhs_strerror(q->rc));
            else
                printf("%-3d %6zu %-13s killed after %.0f s\n", q->dim, q->n, "soft-sphere", q->wall);
            if (e->done && q->done && !q->rc)
                printf("    time soft/event-driven %.2f; phi_J difference (soft lower bound - event-driven) %+.2e\n",
                       q->wall / e->wall, q->s_phi_lo - e->cert.phi);
            if (csv && q->done)
                fprintf(csv, "softsphere,%d,%zu,1,,,%.12f,%.12f,,,,%.5f,%.2f,%.2f,%llu,%.3e,,%.3e,,,%s\n", q->dim, q->n,
                        q->s_phi_lo, q->s_phi_hi, q->s_z, q->wall, q->cpu, (unsigned long long)q->s_iters, q->s_fres,
                        q->s_overlap, q->rc ? odhs_strerror(q->rc) : "");
        }
    }
    if (do4 && table4(workers, soft_limit)) return 2;
    if (csv) fclose(csv);
    printf("\n# total %.0f s\n", bench_wall() - t_start);
    return 0;
}
