/*
 * libodhs - libFuzzer target for the LAMMPS data-file reader (lammps.h).
 *
 * Every input is given to odhs_lammps_data_parse. On failure the call must
 * leave *out NULL and explain itself in errbuf (a malformed file names the
 * line: "line N: ..."). On success the system is written with
 * odhs_lammps_data_write to a file in a private per-process directory, read
 * back with odhs_lammps_data_read, and the two systems must agree as
 * lammps.h promises: dimension, N, box, strain, radii, species, y and z bit
 * for bit, x modulo Lx up to the rounding of the writer's shift by Lx (which
 * moves atoms into LAMMPS's parallelogram: at most an ulp of Lx). That
 * rounding can only turn a pair whose overlap is within a few ulps of Lx of
 * the accepted limit (1e-4 of the contact distance) into a refused one (the
 * fuzzer finds such pairs in boxes of aspect ratio 1e20, where an ulp of Lx
 * is larger than the particles): such an ODHS_E_OVERLAP on the read-back is
 * accepted, any other failure aborts.
 * Any violation aborts, which libFuzzer reports as a crash with the input.
 *
 * Build and run: `make fuzz` (binaries in build-fuzz/), `make fuzz-ci`, or by
 * hand: build-fuzz/fuzz_lammps -dict=tests/fuzz/fuzz_lammps.dict CORPUS_DIR
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <float.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "odhs.h"
#include "odhs/lammps.h"

#define FZ_NAME "fuzz_lammps"
#define FZ_FILE "roundtrip.data"
#include "fuzz_util.h"

/* Whether some pair of sys overlaps by nearly the accepted 1e-4 of its contact
 * distance, within a few ulps of Lx (the most the writer's shift moves x):
 * the read-back may then refuse it. All pairs (fuzz inputs are small);
 * overlapping pairs are closer than half the shortest edge, where
 * odhs_system_separation is exact. */
static int overlap_near_limit(const odhs_system *sys)
{
    size_t n = odhs_system_count(sys);
    double L[3] = {0, 0, 0};
    double *r = malloc(n * sizeof *r);
    FZ_CHECK(r != NULL, "out of memory");
    FZ_CHECK(odhs_system_get_radii(sys, r) == ODHS_OK && odhs_system_get_box(sys, L) == ODHS_OK, "radii/box");
    double margin = 4.0 * DBL_EPSILON * L[0];
    int found = 0;
    for (size_t i = 0; i < n && !found; ++i)
        for (size_t j = i + 1; j < n && !found; ++j) {
            double rij[3], dist = 0.0;
            FZ_CHECK(odhs_system_separation(sys, i, j, rij, &dist, NULL) == ODHS_OK, "separation");
            double c = r[i] + r[j];
            if (dist - c < -1e-4 * c + margin) found = 1;
        }
    free(r);
    return found;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    odhs_system *sys = (odhs_system *)&sys; /* poison: must become NULL or a handle */
    char err[256];
    memset(err, 'x', sizeof err);
    /* an empty input has data == NULL for some drivers: give a valid pointer */
    const char *buf = size ? (const char *)data : "";
    int rc = odhs_lammps_data_parse(buf, size, &sys, err, sizeof err);
    FZ_CHECK(memchr(err, '\0', sizeof err) != NULL, "errbuf not NUL-terminated");
    if (rc < 0) {
        FZ_CHECK(sys == NULL, "error %d (%s) but *out not NULL", rc, odhs_strerror(rc));
        FZ_CHECK(err[0] != '\0', "error %d (%s) without a message", rc, odhs_strerror(rc));
        FZ_CHECK(rc != ODHS_E_FORMAT || strncmp(err, "line ", 5) == 0, "format error without a line: %s", err);
        FZ_CHECK(rc != ODHS_E_INTERNAL, "internal error: %s", err);
        return 0;
    }
    FZ_CHECK(rc == ODHS_OK, "unexpected status %d", rc);
    FZ_CHECK(sys != NULL && odhs_system_is_ready(sys), "success without a ready system");
    FZ_CHECK(err[0] == '\0', "success with a message: %s", err);

    const char *path = fz_file();
    rc = odhs_lammps_data_write(sys, path);
    FZ_CHECK(rc == ODHS_OK, "odhs_lammps_data_write: %d (%s): %s", rc, odhs_strerror(rc), odhs_system_errmsg(sys));
    odhs_system *back = NULL;
    char err2[256];
    rc = odhs_lammps_data_read(path, &back, err2, sizeof err2);
    if (rc == ODHS_E_OVERLAP && overlap_near_limit(sys)) {
        FZ_CHECK(back == NULL, "error but a system");
    } else {
        FZ_CHECK(rc == ODHS_OK, "reading back what the library wrote: %d (%s): %s", rc, odhs_strerror(rc), err2);
        fz_compare(sys, back, 1);
    }
    odhs_system_destroy(back);
    odhs_system_destroy(sys);
    remove(path);
    return 0;
}
