/*
 * libodhs - libFuzzer target for the checkpoint reader (checkpoint.h).
 *
 * A checkpoint ends with a 64-bit FNV-1a checksum, so almost every mutation
 * of a valid file is rejected at the first check. Each input is therefore
 * parsed twice with odhs_checkpoint_parse:
 *   1. as it is (the checksum gate, magic and size checks);
 *   2. a copy whose last 8 bytes are replaced by the correct checksum of the
 *      bytes before them, so that the mutations reach the section parsers.
 * On failure all three outputs must be NULL and errbuf must hold a message.
 * On success the restored handles are exercised, to catch half-loaded states:
 *   - every observable of the stepper is queried (status codes only: a valid
 *     file may hold any finite numbers);
 *   - the restored system is written as XYZ and must read back (a restored
 *     system obeys the same rules as one built with the setters), except
 *     for overlaps above the XYZ reader's 1e-10 that the stepper reports;
 *   - the state is written with odhs_checkpoint_write, read back with
 *     odhs_checkpoint_read, written again: the two files must be identical
 *     byte for byte (the reader keeps everything the writer saves);
 *   - a few steps are taken with the dense solver: each must return a
 *     documented status, and after an error the handle must still answer
 *     queries and be writable (rolled back to a consistent state).
 * Any violation aborts, which libFuzzer reports as a crash with the input.
 *
 * Build and run: `make fuzz` (binaries in build-fuzz/), `make fuzz-ci`, or by
 * hand: build-fuzz/fuzz_checkpoint -dict=tests/fuzz/fuzz_checkpoint.dict DIR
 * Seeds: tests/fuzz/corpus_checkpoint/, made by gen_corpus_checkpoint.c.
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

/* ---- a private directory for this process under $TMPDIR (or /tmp), removed
 * at a normal exit; its files are removed after every input -------------- */
static char fz_dir[320];
static char fz_path[3][400];

static void fz_cleanup(void)
{
    if (!fz_dir[0]) return;
    remove(fz_path[0]);
    remove(fz_path[1]);
    remove(fz_path[2]);
    rmdir(fz_dir);
}

static void fz_init(void)
{
    if (fz_dir[0]) return;
    const char *base = getenv("TMPDIR");
    if (!base || !*base || strlen(base) > 256) base = "/tmp";
    snprintf(fz_dir, sizeof fz_dir, "%s/odhs-fuzz-ckpt-XXXXXX", base);
    if (!mkdtemp(fz_dir)) {
        perror("fuzz_checkpoint: mkdtemp");
        abort();
    }
    snprintf(fz_path[0], sizeof fz_path[0], "%s/a.ckpt", fz_dir);
    snprintf(fz_path[1], sizeof fz_path[1], "%s/b.ckpt", fz_dir);
    snprintf(fz_path[2], sizeof fz_path[2], "%s/c.xyz", fz_dir);
    atexit(fz_cleanup);
}

#define FZ_CHECK(cond, ...)                                                    \
    do {                                                                       \
        if (!(cond)) {                                                         \
            fprintf(stderr, "fuzz_checkpoint: check failed: %s\n  ", #cond);  \
            fprintf(stderr, __VA_ARGS__);                                      \
            fputc('\n', stderr);                                               \
            abort();                                                           \
        }                                                                      \
    } while (0)

/* the library's checksum, written independently */
static uint64_t fnv1a(const unsigned char *p, size_t len)
{
    uint64_t h = 1469598103934665603ULL;
    for (size_t k = 0; k < len; ++k) {
        h ^= p[k];
        h *= 1099511628211ULL;
    }
    return h;
}

static int is_status(int rc)
{
    return (rc >= ODHS_E_STALLED && rc <= ODHS_STEP_LIMIT);
}

static unsigned char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    FZ_CHECK(f != NULL, "cannot open %s", path);
    FZ_CHECK(fseek(f, 0, SEEK_END) == 0, "seek");
    long n = ftell(f);
    FZ_CHECK(n >= 0, "ftell");
    rewind(f);
    unsigned char *p = malloc((size_t)n + 1);
    FZ_CHECK(p != NULL, "out of memory");
    FZ_CHECK(fread(p, 1, (size_t)n, f) == (size_t)n, "short read of %s", path);
    fclose(f);
    *len = (size_t)n;
    return p;
}

/* every observable: a documented status, never a crash */
static void query_all(const odhs_stepper *st, const odhs_system *sys)
{
    size_t n = odhs_system_count(sys);
    int dim = odhs_system_dim(sys);
    FZ_CHECK(n > 0 && (dim == 2 || dim == 3), "restored system has N = %zu, dim = %d", n, dim);
    double v[9], *V = malloc(n * (size_t)dim * sizeof *V);
    FZ_CHECK(V != NULL, "out of memory");
    uint64_t a, b, c;
    int rc[16], k = 0;
    rc[k++] = odhs_stepper_time(st, v);
    rc[k++] = odhs_stepper_strain(st, v);
    rc[k++] = odhs_stepper_adaptive_stats(st, &a, v);
    rc[k++] = odhs_stepper_counts(st, &a, &b, &c);
    rc[k++] = odhs_stepper_stress(st, v);
    rc[k++] = odhs_stepper_shear_stress(st, v);
    rc[k++] = odhs_stepper_pressure(st, v);
    rc[k++] = odhs_stepper_kappa(st, v);
    rc[k++] = odhs_stepper_dissipation(st, v);
    rc[k++] = odhs_stepper_power(st, v);
    rc[k++] = odhs_stepper_velocities(st, V);
    rc[k++] = odhs_stepper_nonaffine_velocities(st, V);
    rc[k++] = odhs_stepper_coordination(st, v);
    rc[k++] = odhs_stepper_errors(st, v, v + 1);
    for (int q = 0; q < k; ++q) FZ_CHECK(is_status(rc[q]), "observable %d returned %d", q, rc[q]);
    const odhs_network *net = odhs_stepper_network(st);
    FZ_CHECK(net != NULL, "restored stepper without a network");
    FZ_CHECK(odhs_network_particles(net) == n, "network of %zu particles for N = %zu",
             odhs_network_particles(net), n);
    size_t nc = odhs_network_count(net);
    double *f = malloc((nc + 1) * sizeof *f);
    FZ_CHECK(f != NULL, "out of memory");
    FZ_CHECK(odhs_network_get_forces(net, f) == ODHS_OK, "network forces");
    FZ_CHECK(odhs_network_get_gaps(net, f) == ODHS_OK, "network gaps");
    for (size_t q = 0; q < nc; ++q) {
        size_t i, j;
        int kind;
        FZ_CHECK(odhs_network_get_contact(net, q, &i, &j, &kind) == ODHS_OK, "contact %zu", q);
        size_t nw = 0;
        FZ_CHECK(odhs_stepper_wall_count(st, &nw) == ODHS_OK, "wall count");
        FZ_CHECK(kind == ODHS_CONTACT_TEMPORARY || kind == ODHS_CONTACT_PERMANENT || kind == ODHS_CONTACT_WALL,
                 "contact kind %d", kind);
        /* a wall contact is (i, N + w) */
        FZ_CHECK(i < j && j < n + nw && (kind == ODHS_CONTACT_WALL) == (j >= n),
                 "contact %zu = (%zu,%zu) of kind %d with N = %zu, %zu walls", q, i, j, kind, n, nw);
    }
    free(f);
    free(V);
}

static void exercise(odhs_system *sys, odhs_driver *drv, odhs_stepper *st, odhs_solver *sol)
{
    fz_init();
    query_all(st, sys);
    /* the restored system is a valid system: its XYZ file reads back */
    {
        int r1 = odhs_xyz_write(sys, fz_path[2]);
        FZ_CHECK(r1 == ODHS_OK, "XYZ write of a restored system: %d: %s", r1, odhs_system_errmsg(sys));
        odhs_system *back = NULL;
        char e2[256];
        r1 = odhs_xyz_read(fz_path[2], &back, e2, sizeof e2);
        /* the XYZ reader refuses overlaps beyond 1e-4 of the contact
         * distance, which a checkpoint may hold (its contacts may be up to
         * 10% off); bonded beads may overlap by their rest lengths, which an
         * XYZ file cannot express */
        double ov = 0.0;
        size_t nbonds = 0;
        FZ_CHECK(odhs_stepper_errors(st, NULL, &ov) == ODHS_OK, "errors");
        FZ_CHECK(odhs_stepper_bond_count(st, &nbonds) == ODHS_OK, "bond count");
        if (r1 == ODHS_E_OVERLAP)
            FZ_CHECK(ov > 1e-4 * (1.0 - 1e-6) || nbonds > 0, "XYZ reader: %s, stepper overlap only %.3g", e2, ov);
        else
            FZ_CHECK(r1 == ODHS_OK, "XYZ file of a restored system does not read back: %d (%s): %s", r1,
                     odhs_strerror(r1), e2);
        odhs_system_destroy(back);
        remove(fz_path[2]);
    }
    /* write, read back, write again: identical bytes */
    int rc = odhs_checkpoint_write(st, fz_path[0]);
    FZ_CHECK(rc == ODHS_OK, "writing a restored state: %d (%s): %s", rc, odhs_strerror(rc), odhs_stepper_errmsg(st));
    odhs_system *s2 = NULL;
    odhs_driver *d2 = NULL;
    odhs_stepper *t2 = NULL;
    char err[256];
    rc = odhs_checkpoint_read(fz_path[0], sol, &s2, &d2, &t2, err, sizeof err);
    FZ_CHECK(rc == ODHS_OK, "reading back what the library wrote: %d (%s): %s", rc, odhs_strerror(rc), err);
    rc = odhs_checkpoint_write(t2, fz_path[1]);
    FZ_CHECK(rc == ODHS_OK, "second write: %d: %s", rc, odhs_stepper_errmsg(t2));
    size_t la, lb;
    unsigned char *A = slurp(fz_path[0], &la), *B = slurp(fz_path[1], &lb);
    FZ_CHECK(la == lb && memcmp(A, B, la) == 0, "write/read/write not idempotent (%zu vs %zu bytes)", la, lb);
    free(A);
    free(B);
    odhs_stepper_destroy(t2);
    odhs_driver_destroy(d2);
    odhs_system_destroy(s2);

    /* a few steps: documented statuses; after an error the handle still works */
    for (int k = 0; k < 3; ++k) {
        odhs_event ev;
        rc = odhs_stepper_step(st, &ev);
        FZ_CHECK(is_status(rc), "step returned %d", rc);
        if (rc < 0) FZ_CHECK(odhs_stepper_errmsg(st)[0] != '\0', "step error %d without a message", rc);
        query_all(st, sys);
        if (rc != ODHS_OK) break;
        FZ_CHECK(ev.kind >= ODHS_EVENT_NONE && ev.kind <= ODHS_EVENT_OPENING, "event kind %d", ev.kind);
        if (ev.kind != ODHS_EVENT_NONE)
            FZ_CHECK(ev.i < ev.j && ev.j < odhs_system_count(sys), "event pair (%zu,%zu)", ev.i, ev.j);
    }
    rc = odhs_checkpoint_write(st, fz_path[0]);
    if (rc == ODHS_E_STATE) {
        /* a restored state whose contacts are up to 10% off contact distance
         * may drift further; the writer then refuses (never writes what the
         * reader refuses), and the stepper reports the same gap */
        double cgap = 0.0;
        FZ_CHECK(odhs_stepper_errors(st, &cgap, NULL) == ODHS_OK, "errors");
        FZ_CHECK(cgap > 0.1, "write refused (%s) with a largest contact gap of %.3g", odhs_stepper_errmsg(st), cgap);
        remove(fz_path[1]);
        return;
    }
    FZ_CHECK(rc == ODHS_OK, "writing after the steps: %d (%s): %s", rc, odhs_strerror(rc), odhs_stepper_errmsg(st));
    rc = odhs_checkpoint_read(fz_path[0], sol, &s2, &d2, &t2, err, sizeof err);
    FZ_CHECK(rc == ODHS_OK, "reading the state after the steps: %d (%s): %s", rc, odhs_strerror(rc), err);
    odhs_stepper_destroy(t2);
    odhs_driver_destroy(d2);
    odhs_system_destroy(s2);
    remove(fz_path[0]);
    remove(fz_path[1]);
    (void)drv;
}

static void one(const unsigned char *buf, size_t size, odhs_solver *sol)
{
    /* poison: each output must become NULL or a handle */
    odhs_system *sys = (odhs_system *)&sys;
    odhs_driver *drv = (odhs_driver *)&drv;
    odhs_stepper *st = (odhs_stepper *)&st;
    char err[256];
    memset(err, 'x', sizeof err);
    int rc = odhs_checkpoint_parse(buf, size, sol, &sys, &drv, &st, err, sizeof err);
    FZ_CHECK(memchr(err, '\0', sizeof err) != NULL, "errbuf not NUL-terminated");
    if (rc < 0) {
        FZ_CHECK(sys == NULL && drv == NULL && st == NULL, "error %d (%s) but an output is not NULL", rc,
                 odhs_strerror(rc));
        FZ_CHECK(err[0] != '\0', "error %d (%s) without a message", rc, odhs_strerror(rc));
        FZ_CHECK(rc == ODHS_E_FORMAT || rc == ODHS_E_NOMEM, "unexpected error %d (%s): %s", rc, odhs_strerror(rc),
                 err);
        return;
    }
    FZ_CHECK(rc == ODHS_OK, "unexpected status %d", rc);
    FZ_CHECK(sys && drv && st, "success with a NULL output");
    FZ_CHECK(odhs_system_is_ready(sys), "success without a ready system");
    exercise(sys, drv, st, sol);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    static odhs_solver *sol;
    if (!sol) {
        FZ_CHECK(odhs_solver_create_by_name("dense", &sol) == ODHS_OK, "dense solver");
    }
    /* an empty input has data == NULL for some drivers: give a valid pointer */
    const unsigned char *buf = size ? data : (const unsigned char *)"";
    one(buf, size, sol);
    if (size >= 8 + 8) {
        unsigned char *copy = malloc(size);
        FZ_CHECK(copy != NULL, "out of memory");
        memcpy(copy, buf, size);
        uint64_t h = fnv1a(copy, size - 8);
        for (int k = 0; k < 8; ++k) copy[size - 8 + (size_t)k] = (unsigned char)(h >> (8 * k));
        one(copy, size, sol);
        free(copy);
    }
    return 0;
}
