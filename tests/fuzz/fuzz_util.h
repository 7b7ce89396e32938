/*
 * libodhs - what the file-format fuzz targets share: a private directory
 * for this process under $TMPDIR (or /tmp), removed at a normal exit, with
 * one file in it (removed after every input by the target); a check that
 * aborts with a message (libFuzzer reports it as a crash with the input);
 * a bit-exact comparison of arrays of doubles.
 *
 * Define FZ_NAME ("fuzz_xyz") and FZ_FILE ("roundtrip.xyz") before including.
 * Include after _POSIX_C_SOURCE (mkdtemp).
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#ifndef ODHS_FUZZ_UTIL_H
#define ODHS_FUZZ_UTIL_H

#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

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

#endif /* ODHS_FUZZ_UTIL_H */
