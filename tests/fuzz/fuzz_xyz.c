/*
 * libodhs - libFuzzer target for the extended XYZ reader (io.h).
 *
 * Every input is given to odhs_xyz_parse. On success the system is written
 * with odhs_xyz_write to a file in a private per-process directory, read back
 * with odhs_xyz_read, and the two systems must agree bit for bit (dimension,
 * N, box, strain, radii, positions, species): io.h promises a bit-exact round
 * trip. On failure the call must leave *out NULL and explain itself in errbuf.
 * Any violation aborts, which libFuzzer reports as a crash with the input.
 *
 * Build and run: `make fuzz` (binaries in build-fuzz/), `make fuzz-ci`, or by
 * hand: build-fuzz/fuzz_xyz -dict=tests/fuzz/fuzz_xyz.dict CORPUS_DIR
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "odhs.h"

#define FZ_NAME "fuzz_xyz"
#define FZ_FILE "roundtrip.xyz"
#include "fuzz_util.h"

static void compare_systems(const odhs_system *a, const odhs_system *b)
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
    k = first_diff(xa, xb, n * (size_t)dim);
    FZ_CHECK(k < 0, "coordinate %ld (particle %ld): %.17g != %.17g (%a vs %a)", k, k / dim,
             k >= 0 ? xa[k] : 0.0, k >= 0 ? xb[k] : 0.0, k >= 0 ? xa[k] : 0.0, k >= 0 ? xb[k] : 0.0);
    for (size_t i = 0; i < n; ++i) {
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

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    odhs_system *sys = (odhs_system *)&sys; /* poison: must become NULL or a handle */
    char err[256];
    memset(err, 'x', sizeof err);
    /* an empty input has data == NULL for some drivers: give a valid pointer */
    const char *buf = size ? (const char *)data : "";
    int rc = odhs_xyz_parse(buf, size, &sys, err, sizeof err);
    FZ_CHECK(memchr(err, '\0', sizeof err) != NULL, "errbuf not NUL-terminated");
    if (rc < 0) {
        FZ_CHECK(sys == NULL, "error %d (%s) but *out not NULL", rc, odhs_strerror(rc));
        FZ_CHECK(err[0] != '\0', "error %d (%s) without a message", rc, odhs_strerror(rc));
        return 0;
    }
    FZ_CHECK(rc == ODHS_OK, "unexpected status %d", rc);
    FZ_CHECK(sys != NULL && odhs_system_is_ready(sys), "success without a ready system");

    const char *path = fz_file();
    rc = odhs_xyz_write(sys, path);
    FZ_CHECK(rc == ODHS_OK, "odhs_xyz_write: %d (%s): %s", rc, odhs_strerror(rc), odhs_system_errmsg(sys));
    odhs_system *back = NULL;
    char err2[256];
    rc = odhs_xyz_read(path, &back, err2, sizeof err2);
    FZ_CHECK(rc == ODHS_OK, "reading back what the library wrote: %d (%s): %s", rc, odhs_strerror(rc), err2);
    compare_systems(sys, back);

    odhs_system_destroy(back);
    odhs_system_destroy(sys);
    remove(path);
    return 0;
}
