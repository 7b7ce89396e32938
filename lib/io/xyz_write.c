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

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/text.h"

typedef struct {
    const odhs_system *sys;
    int dim;
    size_t n;
    const double *L, *x, *r;
    double gamma;
} body_in;

static int write_body(FILE *f, const void *ctx)
{
    const body_in *in = ctx;
    const odhs_system *sys = in->sys;
    int dim = in->dim;
    size_t n = in->n;
    const double *L = in->L, *x = in->x, *r = in->r;
    double gamma = in->gamma;
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
    if (!x || !r) {
        st = odhs__syserr(sys, ODHS_E_NOMEM, "out of memory writing '%s'", path);
        goto done;
    }
    if ((st = odhs_system_get_positions(sys, x)) < 0 || (st = odhs_system_get_radii(sys, r)) < 0) goto done;
    body_in in = {sys, dim, n, L, x, r, gamma};
    char msg[ODHS_ERRMSG_LEN];
    st = odhs__write_atomic(path, write_body, &in, msg);
    if (st < 0) odhs__syserr(sys, st, "%s", msg);

done:
    odhs__free(x);
    odhs__free(r);
    return st;
}
