/*
 * libodhs - the extended XYZ writer (see include/odhs/io.h; the reader is
 * lib/io/xyz.c).
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "system/system.h"

/* Makes temporary names unique within the process ("wx" below refuses to
 * open an existing file anyway, so a collision only costs a retry). */
#if defined(__STDC_NO_ATOMICS__)
static unsigned long tmp_counter;
#else
static _Atomic unsigned long tmp_counter;
#endif

static int write_body(FILE *f, const odhs_system *sys, int dim, size_t n, const double *L,
                      double gamma, const double *x, const double *r)
{
    double Lz = dim == 3 ? L[2] : 1.0;
    if (fprintf(f, "%zu\n", n) < 0) return -1;
    if (fprintf(f,
                "Lattice=\"%.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g %.17g\" "
                "Properties=species:S:1:pos:R:3:radius:R:1 pbc=\"%s\" dim=%d strain=%.17g\n",
                L[0], 0.0, 0.0, gamma * L[1], L[1], 0.0, 0.0, 0.0, Lz,
                dim == 3 ? "T T T" : "T T F", dim, gamma) < 0)
        return -1;
    char label[ODHS_SPECIES_MAX + 1];
    for (size_t i = 0; i < n; i++) {
        if (odhs_system_get_species(sys, i, label, sizeof label) < 0) return -2;
        const double *xi = &x[i * (size_t)dim];
        if (fprintf(f, "%s %.17g %.17g %.17g %.17g\n", label, xi[0], xi[1],
                    dim == 3 ? xi[2] : 0.0, r[i]) < 0)
            return -1;
    }
    return 0;
}

int odhs_xyz_write(const odhs_system *sys, const char *path)
{
    if (!sys) return ODHS_E_NULL;
    if (!path) return odhs__syserr(sys, ODHS_E_NULL, "path is NULL");
    if (!odhs_system_is_ready(sys))
        return odhs__syserr(sys, ODHS_E_STATE, "radii or positions not set");

    int dim = odhs_system_dim(sys);
    size_t n = odhs_system_count(sys);
    double L[3] = {1.0, 1.0, 1.0}, gamma = 0.0;
    int st = odhs_system_get_box(sys, L);
    if (st < 0) return st;
    st = odhs_system_get_strain(sys, &gamma);
    if (st < 0) return st;

    double *x = odhs__malloc_array(n, (size_t)dim * sizeof(double));
    double *r = odhs__malloc_array(n, sizeof(double));
    size_t plen = strlen(path);
    char *tmp = (plen < ((size_t)-1) - 64) ? odhs__malloc(plen + 64) : NULL;
    FILE *f = NULL;
    if (!x || !r || !tmp) {
        st = odhs__syserr(sys, ODHS_E_NOMEM, "out of memory writing '%s'", path);
        goto done;
    }
    if ((st = odhs_system_get_positions(sys, x)) < 0 || (st = odhs_system_get_radii(sys, r)) < 0)
        goto done;

    /* unique temporary name in the same directory, then rename() over path */
    for (int attempt = 0;; attempt++) {
        unsigned long k = tmp_counter++;
        snprintf(tmp, plen + 64, "%s.tmp.%ld.%lu", path, (long)getpid(), k);
        errno = 0;
        f = fopen(tmp, "wx");
        if (f || errno != EEXIST || attempt >= 100) break;
    }
    if (!f) {
        int e = errno;
        st = odhs__syserr(sys, ODHS_E_IO, "cannot write '%s': %s", path,
                          e ? strerror(e) : "cannot create temporary file");
        goto done;
    }
    errno = 0;
    int wr = write_body(f, sys, dim, n, L, gamma, x, r);
    int e = errno;
    if (wr == 0 && fflush(f) != 0) {
        wr = -1;
        e = errno;
    }
    if (wr == 0 && ferror(f)) wr = -1;
    int cl = fclose(f);
    if (wr == 0 && cl != 0) {
        wr = -1;
        e = errno;
    }
    f = NULL;
    if (wr != 0) {
        remove(tmp);
        st = odhs__syserr(sys, wr == -2 ? ODHS_E_INTERNAL : ODHS_E_IO,
                          "cannot write '%s': %s", path,
                          wr == -2 ? "species lookup failed" : e ? strerror(e) : "write error");
        goto done;
    }
    errno = 0;
    if (rename(tmp, path) != 0) {
        e = errno;
        remove(tmp);
        st = odhs__syserr(sys, ODHS_E_IO, "cannot rename '%s' to '%s': %s", tmp, path,
                          e ? strerror(e) : "rename failed");
        goto done;
    }
    st = ODHS_OK;

done:
    odhs__free(x);
    odhs__free(r);
    odhs__free(tmp);
    return st;
}
