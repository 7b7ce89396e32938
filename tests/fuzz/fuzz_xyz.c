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
    fz_compare(sys, back, 0);

    odhs_system_destroy(back);
    odhs_system_destroy(sys);
    remove(path);
    return 0;
}
