/*
 * libodhs - what the file-format fuzz targets share: a private directory
 * for this process under $TMPDIR (or /tmp), removed at a normal exit, with
 * one file in it (removed after every input by the target); a check that
 * aborts with a message (libFuzzer reports it as a crash with the input);
 * a bit-exact comparison of arrays of doubles, and of two systems.
 *
 * Define FZ_NAME ("fuzz_xyz") and FZ_FILE ("roundtrip.xyz") before including.
 * Include after _POSIX_C_SOURCE (mkdtemp).
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#ifndef ODHS_FUZZ_UTIL_H
#define ODHS_FUZZ_UTIL_H

#include <float.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "odhs.h"

static char fz_dir[320];
static char fz_path[400];

static void fz_cleanup(void)
{
    if (!fz_dir[0]) return;
    remove(fz_path);
    rmdir(fz_dir);
}

static const char *fz_file(void)
{
    if (!fz_dir[0]) {
        const char *base = getenv("TMPDIR");
        if (!base || !*base || strlen(base) > 256) base = "/tmp";
        snprintf(fz_dir, sizeof fz_dir, "%s/odhs-" FZ_NAME "-XXXXXX", base);
        if (!mkdtemp(fz_dir)) {
            perror(FZ_NAME ": mkdtemp");
            abort();
        }
        snprintf(fz_path, sizeof fz_path, "%s/" FZ_FILE, fz_dir);
        atexit(fz_cleanup);
    }
    return fz_path;
}

#define FZ_CHECK(cond, ...)                                                    \
    do {                                                                       \
        if (!(cond)) {                                                         \
            fprintf(stderr, FZ_NAME ": check failed: %s\n  ", #cond);          \
            fprintf(stderr, __VA_ARGS__);                                      \
            fputc('\n', stderr);                                               \
            abort();                                                           \
        }                                                                      \
    } while (0)

/* bit-exact comparison of two arrays of doubles; -1 if equal, else the index */
static long first_diff(const double *a, const double *b, size_t n)
{
    for (size_t k = 0; k < n; ++k)
        if (memcmp(&a[k], &b[k], sizeof(double)) != 0) return (long)k;
    return -1;
}

/* a and b agree bit for bit in dimension, N, box, strain, radii, positions
 * and species; with x_mod_lx, x only modulo Lx and up to 2 ulps of Lx (a
 * writer that shifts x by Lx rounds) */
static void fz_compare(const odhs_system *a, const odhs_system *b, int x_mod_lx)
{
    int dim = odhs_system_dim(a);
    size_t n = odhs_system_count(a);
    FZ_CHECK(odhs_system_dim(b) == dim, "dim %d != %d", odhs_system_dim(b), dim);
    FZ_CHECK(odhs_system_count(b) == n, "N %zu != %zu", odhs_system_count(b), n);
    FZ_CHECK(odhs_system_is_ready(a) && odhs_system_is_ready(b), "systems not ready");

    double La[3] = {0, 0, 0}, Lb[3] = {0, 0, 0}, ga = 0.0, gb = 0.0;
    FZ_CHECK(odhs_system_get_box(a, La) == ODHS_OK && odhs_system_get_box(b, Lb) == ODHS_OK, "get_box");
    long k = first_diff(La, Lb, (size_t)dim);
    FZ_CHECK(k < 0, "box edge %ld: %.17g != %.17g", k, k >= 0 ? La[k] : 0.0, k >= 0 ? Lb[k] : 0.0);
    FZ_CHECK(odhs_system_get_strain(a, &ga) == ODHS_OK && odhs_system_get_strain(b, &gb) == ODHS_OK,
             "get_strain");
    FZ_CHECK(memcmp(&ga, &gb, sizeof ga) == 0, "strain %.17g != %.17g (%a vs %a)", ga, gb, ga, gb);

    double *ra = malloc(n * sizeof *ra), *rb = malloc(n * sizeof *rb);
    double *xa = malloc(n * (size_t)dim * sizeof *xa), *xb = malloc(n * (size_t)dim * sizeof *xb);
    FZ_CHECK(ra && rb && xa && xb, "out of memory");
    FZ_CHECK(odhs_system_get_radii(a, ra) == ODHS_OK && odhs_system_get_radii(b, rb) == ODHS_OK, "radii");
    k = first_diff(ra, rb, n);
    FZ_CHECK(k < 0, "radius %ld: %.17g != %.17g", k, k >= 0 ? ra[k] : 0.0, k >= 0 ? rb[k] : 0.0);
    FZ_CHECK(odhs_system_get_positions(a, xa) == ODHS_OK && odhs_system_get_positions(b, xb) == ODHS_OK,
             "positions");
    double Lx = La[0];
    for (size_t i = 0; i < n; ++i) {
        for (int c = 0; c < dim; ++c) {
            size_t j = i * (size_t)dim + (size_t)c;
            if (c == 0 && x_mod_lx) {
                double d = xb[j] - xa[j];
                d -= nearbyint(d / Lx) * Lx;
                FZ_CHECK(fabs(d) <= 2.0 * DBL_EPSILON * Lx,
                         "particle %zu: x %.17g != %.17g modulo Lx = %.17g (%a vs %a)", i, xa[j], xb[j], Lx, xa[j],
                         xb[j]);
            } else {
                FZ_CHECK(memcmp(&xa[j], &xb[j], sizeof(double)) == 0,
                         "particle %zu coordinate %d: %.17g != %.17g (%a vs %a)", i, c, xa[j], xb[j], xa[j], xb[j]);
            }
        }
        char sa[ODHS_SPECIES_MAX + 1], sb[ODHS_SPECIES_MAX + 1];
        FZ_CHECK(odhs_system_get_species(a, i, sa, sizeof sa) == ODHS_OK &&
                     odhs_system_get_species(b, i, sb, sizeof sb) == ODHS_OK,
                 "species of %zu", i);
        FZ_CHECK(strcmp(sa, sb) == 0, "species of %zu: '%s' != '%s'", i, sa, sb);
    }
    free(ra);
    free(rb);
    free(xa);
    free(xb);
}

#endif /* ODHS_FUZZ_UTIL_H */
