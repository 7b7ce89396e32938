/*
 * libodhs tests - a private temporary directory per test and small file
 * helpers, for the suites that write files (io, lammps, traj). Header only;
 * include it after defining _POSIX_C_SOURCE (mkdtemp, opendir, chmod).
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#ifndef ODHS_TESTS_TMPFILES_H
#define ODHS_TESTS_TMPFILES_H

#include <check.h>
#include <dirent.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static char tmpdir[200];

/* $TMPDIR (or /tmp)/odhs-<name>-XXXXXX, made for the test */
static inline void tmpdir_make(const char *name)
{
    const char *base = getenv("TMPDIR");
    if (!base || !*base || strlen(base) > 120) base = "/tmp";
    snprintf(tmpdir, sizeof tmpdir, "%.120s/odhs-%.40s-XXXXXX", base, name);
    ck_assert_ptr_nonnull(mkdtemp(tmpdir));
}

/* the directory and what the test left in it (files, or empty directories) */
static inline void tmpdir_remove(void)
{
    DIR *d = opendir(tmpdir);
    if (d) {
        struct dirent *e;
        char p[1024];
        while ((e = readdir(d)) != NULL) {
            if (!strcmp(e->d_name, ".") || !strcmp(e->d_name, "..")) continue;
            snprintf(p, sizeof p, "%s/%s", tmpdir, e->d_name);
            chmod(p, 0700);
            if (remove(p) != 0) rmdir(p);
        }
        closedir(d);
    }
    chmod(tmpdir, 0700);
    rmdir(tmpdir);
}

/* tmpdir/name (names up to 50 characters) */
static inline void tmppath(char *buf, size_t size, const char *name) { snprintf(buf, size, "%s/%.50s", tmpdir, name); }

static inline void write_text(const char *path, const char *text, size_t len)
{
    FILE *f = fopen(path, "wb");
    ck_assert_ptr_nonnull(f);
    ck_assert_uint_eq(fwrite(text, 1, len, f), len);
    ck_assert_int_eq(fclose(f), 0);
}

/* whole file into a malloc'ed NUL-ended buffer (*len: its length, may be NULL) */
static inline char *slurp(const char *path, size_t *len)
{
    FILE *f = fopen(path, "rb");
    ck_assert_ptr_nonnull(f);
    size_t cap = 1 << 16, n = 0;
    char *b = malloc(cap);
    ck_assert_ptr_nonnull(b);
    size_t got;
    while ((got = fread(b + n, 1, cap - n - 1, f)) > 0) {
        n += got;
        if (cap - n - 1 == 0) {
            cap *= 2;
            b = realloc(b, cap);
            ck_assert_ptr_nonnull(b);
        }
    }
    fclose(f);
    b[n] = '\0';
    if (len) *len = n;
    return b;
}

static inline int count_dir_entries(void)
{
    DIR *d = opendir(tmpdir);
    ck_assert_ptr_nonnull(d);
    int c = 0;
    struct dirent *e;
    while ((e = readdir(d)) != NULL)
        if (strcmp(e->d_name, ".") && strcmp(e->d_name, "..")) c++;
    closedir(d);
    return c;
}

#endif /* ODHS_TESTS_TMPFILES_H */
