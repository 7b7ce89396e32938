/* bench/shear_solvers - cost of paper-mode event-driven shear against N for the
 * built-in linear solvers (CG and dense LAPACK Cholesky), measured in one run.
 *
 * Scene: 2D 50:50 bidisperse discs (radii 0.5/0.7, 3% polydispersity), random
 * placement at phi = 0.45, event-driven compression to phi = 0.80, drift
 * correction; then simple shear at fixed volume to strain GAMMA (default 0.05)
 * with dt = 1e-3 (strain units), correction every 10 steps.
 *
 * usage: shear_solvers [GAMMA] [NMAX]
 * Prints a table: N, solver, wall seconds, steps, events, seconds per unit
 * strain, microseconds per event, and the ratio dense/CG for equal N.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/utsname.h>
#include <time.h>

#include "bench.h"
#include "odhs.h"

static void machine(void)
{
    struct utsname u;
    char model[256];
    bench_cpu_model(model, sizeof model);
    uname(&u);
    printf("# machine: %s, %s %s, libodhs %s\n", model, u.sysname, u.machine, odhs_version_string());
}

static odhs_system *scene(size_t n, unsigned seed)
{
    odhs_system *sys;
    odhs_solver *cg;
    odhs_driver *drv;
    odhs_stepper *st;
    if (odhs_system_create(2, n, &sys) || odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, seed) ||
        odhs_system_place_random(sys, 0.45, seed + 1))
        return NULL;
    odhs_solver_create_by_name("cg", &cg);
    odhs_driver_create(&drv);
    odhs_driver_set_compression_rate(drv, 1.0);
    odhs_stepper_create(sys, drv, cg, &st);
    int rc = odhs_stepper_run_until_packing_fraction(st, 0.80);
    if (rc == ODHS_OK) rc = odhs_stepper_correct(st);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(cg);
    if (rc) {
        odhs_system_destroy(sys);
        return NULL;
    }
    return sys;
}

int main(int argc, char **argv)
{
    double gamma = argc > 1 ? atof(argv[1]) : 0.05;
    size_t nmax = argc > 2 ? (size_t)atol(argv[2]) : 1024;
    machine();
    printf("# 2D bidisperse discs, phi = 0.80, shear to strain %g, dt = 1e-3, correction every 10 steps\n",
           gamma);
    printf("%6s %7s %9s %8s %8s %12s %12s %9s\n", "N", "solver", "seconds", "steps", "events", "s/strain",
           "us/event", "dense/cg");
    const char *solvers[2] = {"cg", "dense"};
    for (size_t n = 64; n <= nmax; n *= 2) {
        odhs_system *base = scene(n, 3);
        if (!base) {
            printf("%6zu scene construction failed\n", n);
            continue;
        }
        double tcg = 0.0;
        for (int s = 0; s < 2; ++s) {
            if (s == 1 && n > 512) continue; /* dense O(Nc^3) per solve */
            odhs_system *sys;
            odhs_solver *sol;
            odhs_driver *drv;
            odhs_stepper *st;
            odhs_system_clone(base, &sys);
            odhs_solver_create_by_name(solvers[s], &sol);
            odhs_driver_create(&drv);
            odhs_driver_set_shear_rate(drv, 1.0);
            odhs_stepper_create(sys, drv, sol, &st);
            double t0 = bench_wall();
            int rc = odhs_stepper_run_until_strain(st, gamma);
            double t = bench_wall() - t0;
            uint64_t steps, nc, no;
            odhs_stepper_counts(st, &steps, &nc, &no);
            if (s == 0) tcg = t;
            printf("%6zu %7s %9.3f %8llu %8llu %12.3f %12.1f", n, solvers[s], t, (unsigned long long)steps,
                   (unsigned long long)(nc + no), t / gamma, 1e6 * t / (double)(nc + no ? nc + no : 1));
            if (s == 1) printf(" %9.2f", t / tcg);
            if (rc) printf("  (%s)", odhs_strerror(rc));
            printf("\n");
            fflush(stdout);
            odhs_stepper_destroy(st);
            odhs_driver_destroy(drv);
            odhs_solver_destroy(sol);
            odhs_system_destroy(sys);
        }
        odhs_system_destroy(base);
    }
    return 0;
}
