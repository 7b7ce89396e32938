/*
 * libodhs - the LAMMPS conventions shared by lammps.c and traj.c (lmp.h).
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <math.h>
#include <string.h>

#include "io/lmp.h"

double odhs__lmp_tilt(double Lx, double Ly, double gamma)
{
    double xy = gamma * Ly;
    xy -= Lx * nearbyint(xy / Lx);
    return xy;
}

void odhs__lmp_wrap(double *x, double y, double Lx, double Ly, double xy)
{
    double s = *x - xy * y / Ly;
    double k = floor(s / Lx);
    if (k != 0.0) *x -= k * Lx;
    /* rounding can leave s a hair outside [0, Lx): one more shift */
    s = *x - xy * y / Ly;
    if (s < 0.0) *x += Lx;
    else if (s >= Lx) *x -= Lx;
}

size_t odhs__lmp_types(const odhs_system *sys, int *type, char (*names)[ODHS_SPECIES_MAX + 1])
{
    size_t nt = 0;
    for (size_t i = 0; i < sys->n; ++i) {
        size_t t = 0;
        /* species are few in practice; a scan of the types seen so far */
        while (t < nt && strcmp(names[t], sys->species[i])) ++t;
        if (t == nt) strcpy(names[nt++], sys->species[i]);
        type[i] = (int)t + 1;
    }
    return nt;
}
