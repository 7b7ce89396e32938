/* compress - isotropic event-driven compression of hard discs/spheres to a
 * target packing fraction, or until the contact network becomes potentially
 * jammed, with libodhs.
 *
 *     cc compress.c $(pkg-config --cflags --libs odhs) -lm -o compress
 */
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <odhs.h>

#include "cli.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: compress [options]\n"
            "  --in FILE.xyz      start from a configuration file (default: built-in scene)\n"
            "  --phi X            target packing fraction (default 0.80)\n"
            "  --jam              compress until the network is potentially jammed instead\n"
            "  --out FILE.xyz     write the final configuration\n"
            "  --series FILE.csv  write phi,pressure,z,events per output interval\n"
            "  --every X          output interval in packing fraction (default 0.01)\n"
            "  --dt X             step in units of 1/rate (default 1e-3)\n"
            "  --solver NAME      linear solver: cg, dense, cholmod, cholmod-pcg, spqr\n"
            "                     (default cholmod-pcg when built with SuiteSparse, else\n"
            "                     dense up to N = 2000 and cg above; CG alone stalls\n"
            "                     close to jamming)\n"
            "  --n N              built-in scene: number of particles (default 256)\n"
            "  --dim D            built-in scene: dimension 2 or 3 (default 2)\n"
            "  --seed S           built-in scene: random seed (default 1)\n"
            "  --help             this message\n"
            "The built-in scene is 50:50 bidisperse (radii 0.5/0.7, 3%% polydispersity) placed\n"
            "at random at phi = 0.45 (2D) or 0.30 (3D).\n");
}

int main(int argc, char **argv)
{
    const char *in = NULL, *outpath = NULL, *series = NULL, *solver_name = NULL;
    double phi_target = 0.80, every = 0.01, dt = 1e-3;
    unsigned long n = 256, seed = 1, dim = 2;
    int jam = 0;
    for (int a = 1; a < argc; ++a) {
        const char *o = argv[a];
        if (!strcmp(o, "--help") || !strcmp(o, "-h")) {
            usage(stdout);
            return 0;
        }
        if (!strcmp(o, "--jam")) {
            jam = 1;
            continue;
        }
        if (a + 1 >= argc) {
            fprintf(stderr, "compress: unknown option or missing value: %s\n", o);
            usage(stderr);
            return 2;
        }
        const char *v = argv[++a];
        int bad = 0;
        if (!strcmp(o, "--in")) in = v;
        else if (!strcmp(o, "--out")) outpath = v;
        else if (!strcmp(o, "--series")) series = v;
        else if (!strcmp(o, "--solver")) solver_name = v;
        else if (!strcmp(o, "--phi")) bad = cli_double(v, &phi_target) || phi_target <= 0 || phi_target >= 1;
        else if (!strcmp(o, "--every")) bad = cli_double(v, &every) || every <= 0;
        else if (!strcmp(o, "--dt")) bad = cli_double(v, &dt) || dt <= 0;
        else if (!strcmp(o, "--n")) bad = cli_ulong(v, &n) || n < 2;
        else if (!strcmp(o, "--seed")) bad = cli_ulong(v, &seed);
        else if (!strcmp(o, "--dim")) bad = cli_ulong(v, &dim) || (dim != 2 && dim != 3);
        else {
            fprintf(stderr, "compress: unknown option %s\n", o);
            usage(stderr);
            return 2;
        }
        if (bad) {
            fprintf(stderr, "compress: bad value for %s: %s\n", o, v);
            usage(stderr);
            return 2;
        }
    }
    if (jam) phi_target = 0.999;

    odhs_system *sys = NULL;
    int rc;
    if (in) {
        char err[512];
        rc = odhs_xyz_read(in, &sys, err, sizeof err);
        if (rc) {
            fprintf(stderr, "compress: cannot read %s: %s\n", in, err);
            return 1;
        }
    } else {
        if ((rc = cli_scene((int)dim, n, seed, 1.0, &sys))) {
            fprintf(stderr, "compress: building the scene: %s\n", sys ? odhs_system_errmsg(sys) : odhs_strerror(rc));
            return 1;
        }
    }
    if (!solver_name) solver_name = cli_default_solver(odhs_system_count(sys));
    odhs_solver *solver;
    rc = odhs_solver_create_by_name(solver_name, &solver);
    if (rc) {
        fprintf(stderr, "compress: solver %s: %s\n", solver_name, odhs_strerror(rc));
        return 2;
    }
    double phi;
    odhs_system_packing_fraction(sys, &phi);
    fprintf(stderr, "compress: N = %zu, d = %d, phi = %.6f -> %s\n", odhs_system_count(sys),
            odhs_system_dim(sys), phi, jam ? "jamming" : "target");

    odhs_driver *drv;
    odhs_stepper *st;
    if (odhs_driver_create(&drv) || odhs_driver_set_compression_rate(drv, 1.0) ||
        odhs_stepper_create(sys, drv, solver, &st) || odhs_stepper_set_dt(st, dt)) {
        fprintf(stderr, "compress: setup failed\n");
        return 1;
    }
    FILE *csv = NULL;
    if (series) {
        csv = fopen(series, "w");
        if (!csv) {
            fprintf(stderr, "compress: cannot write %s: %s\n", series, strerror(errno));
            return 1;
        }
        fprintf(csv, "phi,pressure,z,events\n");
    }
    printf("%10s %14s %8s %10s\n", "phi", "pressure", "z", "events");
    int status = 0;
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
        fprintf(stderr, "\rcompress: phi %.5f", phi);
        if (rc == ODHS_JAMMED) {
            fprintf(stderr, "\ncompress: jammed at phi = %.12f (z = %.4f; pressure normalised to 1)\n", phi, z);
            break;
        }
        if (rc == ODHS_POTENTIALLY_JAMMED) {
            fprintf(stderr, "\ncompress: potentially jammed at phi = %.10f (z = %.4f): %s\n", phi, z,
                    odhs_stepper_errmsg(st));
            break;
        }
        if (rc) {
            fprintf(stderr, "\ncompress: stopped: %s (%s)\n", odhs_strerror(rc), odhs_stepper_errmsg(st));
            status = 1;
            break;
        }
        if (phi >= phi_target * (1 - 1e-12)) {
            fprintf(stderr, "\n");
            break;
        }
    }
    if (!status && rc != ODHS_JAMMED) {
        rc = odhs_stepper_correct(st);
        if (rc < 0) fprintf(stderr, "compress: final correction: %s\n", odhs_stepper_errmsg(st));
    }
    if (csv) fclose(csv);
    if (outpath && odhs_xyz_write(sys, outpath)) {
        fprintf(stderr, "compress: cannot write %s: %s\n", outpath, odhs_system_errmsg(sys));
        status = 1;
    }
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(solver);
    odhs_system_destroy(sys);
    return status;
}
