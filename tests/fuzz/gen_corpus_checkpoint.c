/*
 * libodhs - generator of the seed corpus of fuzz_checkpoint
 * (tests/fuzz/corpus_checkpoint/). Not built by `make fuzz`; regenerate with
 *
 *   make all
 *   cc -std=c11 -Iinclude tests/fuzz/gen_corpus_checkpoint.c lib/libodhs.a \
 *      -llapacke -llapack -lblas -lm $(SuiteSparse libs if built with them) \
 *      -o build/gen_corpus_checkpoint
 *   build/gen_corpus_checkpoint tests/fuzz/corpus_checkpoint
 *
 * Valid seeds are real checkpoints of small runs (2D and 3D, Euler and Heun,
 * shear, compression, fixed pressure, external forces, N = 2 to 16); invalid
 * seeds are a truncated file, a flipped byte and a future format version.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"

#define OK(call)                                                                 \
    do {                                                                         \
        int rc_ = (call);                                                        \
        if (rc_ < 0) {                                                           \
            fprintf(stderr, "%s:%d: %s -> %d (%s)\n", __FILE__, __LINE__, #call, \
                    rc_, odhs_strerror(rc_));                                    \
            exit(1);                                                             \
        }                                                                        \
    } while (0)

typedef struct {
    const char *name;
    int dim;
    size_t n;
    double ratio, phi;
    int integrator, pressure, forces, compress;
    int steps;
} seed;

static void make(const char *dir, const seed *sd, odhs_solver *sol)
{
    odhs_system *sys;
    odhs_driver *drv;
    odhs_stepper *st;
    OK(odhs_system_create(sd->dim, sd->n, &sys));
    OK(odhs_system_set_radii_bidisperse(sys, 0.5, sd->ratio, 0.0, 7));
    OK(odhs_system_place_random(sys, sd->phi, 11));
    OK(odhs_driver_create(&drv));
    if (sd->compress) OK(odhs_driver_set_compression_rate(drv, 1.0));
    else OK(odhs_driver_set_shear_rate(drv, 1.0));
    if (sd->pressure) OK(odhs_driver_set_pressure(drv, 0.5));
    if (sd->forces) {
        double F[64 * 3] = {0};
        for (size_t k = 0; k < sd->n * (size_t)sd->dim; ++k) F[k] = (k % 3 == 0) ? 0.25 : -0.125;
        OK(odhs_driver_set_forces(drv, sd->n, sd->dim, F));
    }
    OK(odhs_stepper_create(sys, drv, sol, &st));
    OK(odhs_stepper_set_integrator(st, sd->integrator));
    OK(odhs_stepper_set_correction_interval(st, 3));
    OK(odhs_stepper_set_dt(st, 0.01));
    for (int k = 0; k < sd->steps; ++k) OK(odhs_stepper_step(st, NULL));
    char path[512];
    snprintf(path, sizeof path, "%s/%s.ckpt", dir, sd->name);
    OK(odhs_checkpoint_write(st, path));
    printf("%s\n", path);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
}

static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    if (!f) exit(1);
    fseek(f, 0, SEEK_END);
    long n = ftell(f);
    rewind(f);
    unsigned char *p = malloc((size_t)n);
    if (!p || fread(p, 1, (size_t)n, f) != (size_t)n) exit(1);
    fclose(f);
    *len = (size_t)n;
    return p;
}

static void put(const char *dir, const char *name, const unsigned char *p, size_t len)
{
    char path[512];
    snprintf(path, sizeof path, "%s/%s", dir, name);
    FILE *f = fopen(path, "wb");
    if (!f || fwrite(p, 1, len, f) != len || fclose(f)) exit(1);
    printf("%s\n", path);
}

int main(int argc, char **argv)
{
    if (argc != 2) {
        fprintf(stderr, "usage: %s DIR\n", argv[0]);
        return 2;
    }
    odhs_solver *sol;
    OK(odhs_solver_create_by_name("dense", &sol));
    static const seed seeds[] = {
        {"shear2d_n8_euler", 2, 8, 1.4, 0.55, ODHS_INTEGRATOR_EULER, 0, 0, 0, 40},
        {"shear2d_n12_heun_pressure", 2, 12, 1.4, 0.55, ODHS_INTEGRATOR_HEUN, 1, 0, 0, 25},
        {"compress2d_n10_forces", 2, 10, 1.4, 0.50, ODHS_INTEGRATOR_EULER, 0, 1, 1, 30},
        {"shear2d_n2", 2, 2, 1.0, 0.30, ODHS_INTEGRATOR_EULER, 0, 0, 0, 5},
        {"shear3d_n16_euler", 3, 16, 1.2, 0.35, ODHS_INTEGRATOR_EULER, 0, 0, 0, 30},
        {"compress3d_n16_heun", 3, 16, 1.2, 0.30, ODHS_INTEGRATOR_HEUN, 0, 0, 1, 20},
    };
    for (size_t k = 0; k < sizeof seeds / sizeof seeds[0]; ++k) make(argv[1], &seeds[k], sol);
    /* invalid seeds, derived from the first one */
    char path[512];
    snprintf(path, sizeof path, "%s/%s.ckpt", argv[1], seeds[0].name);
    size_t len;
    unsigned char *p = slurp(path, &len);
    put(argv[1], "bad_truncated.ckpt", p, len / 2);
    p[len / 3] ^= 0x10;
    put(argv[1], "bad_flipped_byte.ckpt", p, len);
    p[len / 3] ^= 0x10;
    p[8] = 2; /* format version 2: not readable by version 1 */
    put(argv[1], "bad_version.ckpt", p, len);
    free(p);
    odhs_solver_destroy(sol);
    return 0;
}
