/*
 * libodhs private header: the system handle (positions, radii, box).
 * Not installed.
 */
#ifndef ODHS_SYSTEM_SYSTEM_H
#define ODHS_SYSTEM_SYSTEM_H

#include "geom/geom.h"

/* ---- the system -------------------------------------------------------- */
struct odhs_system {
    int dim;
    size_t n;
    double L[3];    /* box edges (L[2] = 1 in 2D) */
    double gamma;   /* Lees-Edwards strain in [-1/2, 1/2] */
    double *x;      /* n*dim lab-frame positions in [0,L) */
    double *r;      /* n radii */
    char (*species)[ODHS_SPECIES_MAX + 1];
    int has_x, has_r;
    double rmax;    /* largest radius (0 if unset) */
    double overlap_accept; /* relative overlap accepted by the setters (0: 1e-10) */
    uint64_t version; /* changes through the public setters (odhs_system_change_count) */
    char errmsg[ODHS_ERRMSG_LEN];
};

/* record an error message on a (logically mutable) handle */
int odhs__syserr(const odhs_system *sys, int status, const char *fmt, ...) ODHS_PRINTF(3, 4);

#endif /* ODHS_SYSTEM_SYSTEM_H */
