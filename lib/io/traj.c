/*
 * libodhs - trajectories (include/odhs/traj.h): extended XYZ, LAMMPS custom
 * dumps and LAMMPS dump-local contact networks, one frame per call.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 *
 * A frame is formatted into the handle's buffer and written with one fwrite
 * and fflush; if that fails the file is truncated back to its length before
 * the frame, so a failed call adds nothing.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <ctype.h>
#include <errno.h>
#include <stdarg.h>
#include <stdio.h>
#include <string.h>
#include <sys/types.h>
#include <unistd.h>

#include "io/lmp.h"
#include "stepper/stepper.h"

struct odhs_traj {
    FILE *f;
    int format;
    uint64_t frames;
    long long bytes;          /* length of the file after the last frame */
    char *buf;                /* the frame being formatted */
    size_t len, cap;
    int oom;                  /* an append ran out of memory */
    double *v;                /* 3 nd: velocities, non-affine velocities, forces */
    size_t vcap;
    int *type;                /* LAMMPS types (N) */
    char (*names)[ODHS_SPECIES_MAX + 1];
    size_t tcap;
    char errmsg[ODHS_ERRMSG_LEN];
};

static int trerr(odhs_traj *tr, int status, const char *fmt, ...) ODHS_PRINTF(3, 4);
static int trerr(odhs_traj *tr, int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    odhs__verr(tr->errmsg, status, fmt, ap);
    va_end(ap);
    return status;
}

/* append printf-style text to the frame buffer (tr->oom on failure) */
static void put(odhs_traj *tr, const char *fmt, ...) ODHS_PRINTF(2, 3);
static void put(odhs_traj *tr, const char *fmt, ...)
{
    if (tr->oom) return;
    for (;;) {
        va_list ap;
        va_start(ap, fmt);
        size_t room = tr->cap - tr->len;
        int n = vsnprintf(tr->buf ? tr->buf + tr->len : NULL, room, fmt, ap);
        va_end(ap);
        if (n < 0) {
            tr->oom = 1;
            return;
        }
        if ((size_t)n < room) {
            tr->len += (size_t)n;
            return;
        }
        if (odhs__reserve((void **)&tr->buf, &tr->cap, tr->len + (size_t)n + 1 + tr->cap, 1)) {
            tr->oom = 1;
            return;
        }
    }
}

int odhs_traj_format_for(const char *path, int *format)
{
    if (!path || !format) return ODHS_E_NULL;
    static const struct {
        const char *ext;
        int format;
    } ends[] = {{".xyz", ODHS_TRAJ_XYZ},
                {".extxyz", ODHS_TRAJ_XYZ},
                {".dump", ODHS_TRAJ_LAMMPS_DUMP},
                {".lammpstrj", ODHS_TRAJ_LAMMPS_DUMP}};
    size_t n = strlen(path);
    for (size_t k = 0; k < sizeof ends / sizeof ends[0]; ++k) {
        size_t m = strlen(ends[k].ext);
        if (n <= m) continue;
        size_t i = 0;
        while (i < m && tolower((unsigned char)path[n - m + i]) == ends[k].ext[i]) ++i;
        if (i == m) {
            *format = ends[k].format;
            return ODHS_OK;
        }
    }
    return ODHS_E_INVALID;
}

int odhs_traj_open(const char *path, int format, odhs_traj **out, char *errbuf, size_t errlen)
{
    char msg[ODHS_ERRMSG_LEN];
    int st = ODHS_OK;
    msg[0] = '\0';
    if (out) *out = NULL;
    if (!out || !path) st = odhs__err(msg, ODHS_E_NULL, "%s is NULL", !out ? "out" : "path");
    else if (format < ODHS_TRAJ_XYZ || format > ODHS_TRAJ_LAMMPS_LOCAL)
        st = odhs__err(msg, ODHS_E_INVALID, "unknown trajectory format %d", format);
    odhs_traj *tr = NULL;
    if (!st && !(tr = odhs__calloc(1, sizeof *tr))) st = odhs__err(msg, ODHS_E_NOMEM, "out of memory");
    if (!st) {
        errno = 0;
        tr->f = fopen(path, "w");
        if (!tr->f) {
            int e = errno;
            st = odhs__err(msg, ODHS_E_IO, "cannot write '%s': %s", path, e ? strerror(e) : "open failed");
            odhs__free(tr);
        }
    }
    if (st) {
        if (errbuf && errlen) snprintf(errbuf, errlen, "%s", msg);
        return st;
    }
    if (errbuf && errlen) errbuf[0] = '\0';
    tr->format = format;
    *out = tr;
    return ODHS_OK;
}

/* the cell as LAMMPS boxes hold it: BOX BOUNDS lines, with the tilt *xy */
static void lammps_box(odhs_traj *tr, const odhs_system *sys, double *xy)
{
    const double *L = sys->L;
    *xy = odhs__lmp_tilt(L[0], L[1], sys->gamma);
    double zlo = sys->dim == 3 ? 0.0 : -0.5, zhi = sys->dim == 3 ? L[2] : 0.5;
    put(tr, "ITEM: BOX BOUNDS xy xz yz pp pp pp\n%.17g %.17g %.17g\n%.17g %.17g 0\n%.17g %.17g 0\n",
        *xy < 0.0 ? *xy : 0.0, L[0] + (*xy > 0.0 ? *xy : 0.0), *xy, 0.0, L[1], zlo, zhi);
}

/* ITEM: TIME and ITEM: TIMESTEP */
static void lammps_head(odhs_traj *tr, const odhs_stepper *st)
{
    put(tr, "ITEM: TIME\n%.17g\nITEM: TIMESTEP\n%llu\n", st ? st->time : 0.0,
        (unsigned long long)(st ? st->nsteps : tr->frames));
}

static void frame_xyz(odhs_traj *tr, const odhs_system *sys, const odhs_stepper *st, const double *v)
{
    int dim = sys->dim;
    size_t n = sys->n, nd = n * (size_t)dim;
    const double *L = sys->L;
    double phi = 0.0;
    odhs_system_packing_fraction(sys, &phi);
    put(tr, "%zu\n", n);
    put(tr,
        "Lattice=\"%.17g 0 0 %.17g %.17g 0 0 0 %.17g\" Properties=type:S:1:pos:R:3:radius:R:1%s pbc=\"%s\" dim=%d "
        "strain=%.17g frame=%llu phi=%.17g",
        L[0], sys->gamma * L[1], L[1], dim == 3 ? L[2] : 1.0,
        v ? ":velo:R:3:nonaffine_velo:R:3:force_ext:R:3" : "", dim == 3 ? "T T T" : "T T F", dim, sys->gamma,
        (unsigned long long)tr->frames, phi);
    if (st) put(tr, " time=%.17g shear_strain=%.17g", st->time, st->strain);
    if (st && st->ready) {
        double p, s, z;
        odhs_stepper_pressure(st, &p);
        odhs_stepper_shear_stress(st, &s);
        odhs_stepper_coordination(st, &z);
        put(tr, " pressure=%.17g shear_stress=%.17g kappa=%.17g z=%.17g", p, s, st->kappa, z);
    }
    put(tr, "\n");
    for (size_t i = 0; i < n && !tr->oom; ++i) {
        const double *x = sys->x + i * dim;
        put(tr, "%s %.17g %.17g %.17g %.17g", sys->species[i], x[0], x[1], dim == 3 ? x[2] : 0.0, sys->r[i]);
        for (int a = 0; v && a < 3; ++a) {
            const double *w = v + (size_t)a * nd + i * dim;
            put(tr, " %.17g %.17g %.17g", w[0], w[1], dim == 3 ? w[2] : 0.0);
        }
        put(tr, "\n");
    }
}

static void frame_dump(odhs_traj *tr, const odhs_system *sys, const odhs_stepper *st, const double *v)
{
    int dim = sys->dim;
    size_t n = sys->n, nd = n * (size_t)dim;
    double xy;
    lammps_head(tr, st);
    put(tr, "ITEM: NUMBER OF ATOMS\n%zu\n", n);
    lammps_box(tr, sys, &xy);
    odhs__lmp_types(sys, tr->type, tr->names);
    put(tr, "ITEM: ATOMS id type radius x y z%s\n", v ? " vx vy vz ux uy uz fx fy fz" : "");
    for (size_t i = 0; i < n && !tr->oom; ++i) {
        const double *x = sys->x + i * dim;
        double x0 = x[0];
        odhs__lmp_wrap(&x0, x[1], sys->L[0], sys->L[1], xy);
        put(tr, "%zu %d %.17g %.17g %.17g %.17g", i + 1, tr->type[i], sys->r[i], x0, x[1], dim == 3 ? x[2] : 0.0);
        for (int a = 0; v && a < 3; ++a) {
            const double *w = v + (size_t)a * nd + i * dim;
            put(tr, " %.17g %.17g %.17g", w[0], w[1], dim == 3 ? w[2] : 0.0);
        }
        put(tr, "\n");
    }
}

static void frame_local(odhs_traj *tr, const odhs_system *sys, const odhs_stepper *st)
{
    const odhs_network *net = st->net;
    size_t m = 0;
    for (size_t c = 0; c < net->nc; ++c) m += net->cj[c] < sys->n;
    double xy;
    lammps_head(tr, st);
    put(tr, "ITEM: NUMBER OF ENTRIES\n%zu\n", m);
    lammps_box(tr, sys, &xy);
    put(tr, "ITEM: ENTRIES index batom1 batom2 kind force gap\n");
    size_t k = 0;
    for (size_t c = 0; c < net->nc && !tr->oom; ++c)
        if (net->cj[c] < sys->n)
            put(tr, "%zu %zu %zu %d %.17g %.17g\n", ++k, net->ci[c] + 1, net->cj[c] + 1, net->kind[c], net->f[c],
                net->gap[c]);
}

/* the per-particle arrays of a frame: 0, or ODHS_E_NOMEM */
static int reserve_frame(odhs_traj *tr, const odhs_system *sys, int velocities)
{
    size_t n = sys->n, nd = n * (size_t)sys->dim;
    if (velocities && odhs__reserve((void **)&tr->v, &tr->vcap, 3 * nd, sizeof *tr->v)) return ODHS_E_NOMEM;
    if (tr->format == ODHS_TRAJ_LAMMPS_DUMP) {
        size_t cap = tr->tcap;
        if (n > cap) {
            int *t = odhs__malloc_array(n, sizeof *t);
            char(*names)[ODHS_SPECIES_MAX + 1] = odhs__malloc_array(n, sizeof *names);
            if (!t || !names) {
                odhs__free(t);
                odhs__free(names);
                return ODHS_E_NOMEM;
            }
            odhs__free(tr->type);
            odhs__free(tr->names);
            tr->type = t;
            tr->names = names;
            tr->tcap = n;
        }
    }
    return ODHS_OK;
}

int odhs_traj_write(odhs_traj *tr, const odhs_system *sys, const odhs_stepper *st)
{
    if (!tr) return ODHS_E_NULL;
    tr->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!sys) return trerr(tr, ODHS_E_NULL, "system is NULL");
    if (!st && tr->format == ODHS_TRAJ_LAMMPS_LOCAL)
        return trerr(tr, ODHS_E_NULL, "a contact-network trajectory needs the stepper");
    if (st && st->sys != sys) return trerr(tr, ODHS_E_INVALID, "the stepper moves another system");
    if (!odhs_system_is_ready(sys)) return trerr(tr, ODHS_E_STATE, "radii or positions not set");
    int velocities = st && st->ready && tr->format != ODHS_TRAJ_LAMMPS_LOCAL;
    if (reserve_frame(tr, sys, velocities)) return trerr(tr, ODHS_E_NOMEM, "out of memory for a frame");
    const double *v = NULL;
    if (velocities) {
        size_t nd = sys->n * (size_t)sys->dim;
        odhs_stepper_velocities(st, tr->v);
        odhs_stepper_nonaffine_velocities(st, tr->v + nd);
        odhs_stepper_external_forces(st, tr->v + 2 * nd);
        v = tr->v;
    }
    tr->len = 0;
    tr->oom = 0;
    if (tr->format == ODHS_TRAJ_XYZ) frame_xyz(tr, sys, st, v);
    else if (tr->format == ODHS_TRAJ_LAMMPS_DUMP) frame_dump(tr, sys, st, v);
    else frame_local(tr, sys, st);
    if (tr->oom) return trerr(tr, ODHS_E_NOMEM, "out of memory formatting frame %llu", (unsigned long long)tr->frames);
    errno = 0;
    int ok = fwrite(tr->buf, 1, tr->len, tr->f) == tr->len;
    ok = ok && fflush(tr->f) == 0;
    if (!ok) {
        int e = errno;
        /* put the file back as it was before the frame */
        clearerr(tr->f);
        if (ftruncate(fileno(tr->f), (off_t)tr->bytes) == 0) fseeko(tr->f, (off_t)tr->bytes, SEEK_SET);
        return trerr(tr, ODHS_E_IO, "cannot write frame %llu: %s", (unsigned long long)tr->frames,
                     e ? strerror(e) : "write error");
    }
    tr->bytes += (long long)tr->len;
    tr->frames++;
    return ODHS_OK;
}

int odhs_traj_frames(const odhs_traj *tr, uint64_t *count)
{
    if (!tr || !count) return ODHS_E_NULL;
    *count = tr->frames;
    return ODHS_OK;
}

const char *odhs_traj_errmsg(const odhs_traj *tr) { return tr ? tr->errmsg : ""; }

int odhs_traj_close(odhs_traj *tr)
{
    if (!tr) return ODHS_OK;
    int st = fclose(tr->f) == 0 ? ODHS_OK : ODHS_E_IO;
    odhs__free(tr->buf);
    odhs__free(tr->v);
    odhs__free(tr->type);
    odhs__free(tr->names);
    odhs__free(tr);
    return st;
}
