/*
 * libodhs private header: checkpoint sections (format: include/odhs/checkpoint.h).
 * lib/io/checkpoint.c writes and reads the file (magic, format version, order
 * of the sections, checksum, atomic write, the checks that span modules);
 * each module writes and reads its own sections with the byte buffers below:
 * SYS in lib/system/, DRV and the driver's optional sections in lib/driver/,
 * WAL and CMP in lib/scene/, STP and NET in lib/stepper/.
 * Not installed.
 */
#ifndef ODHS_IO_CKPT_H
#define ODHS_IO_CKPT_H

#include <string.h>

#include "base/base.h"

/* ---- byte buffers: little-endian 64-bit integers and doubles, 4-byte tags -- */
typedef struct {
    unsigned char *p;
    size_t len, cap;
    int nomem; /* an allocation failed: later writes are dropped */
} odhs__wbuf;

/* append len bytes (lib/io/checkpoint.c) */
void odhs__put(odhs__wbuf *b, const void *src, size_t len);

static inline void odhs__le64(unsigned char c[8], uint64_t v)
{
    for (int k = 0; k < 8; ++k) c[k] = (unsigned char)(v >> (8 * k));
}

static inline void odhs__put_u64(odhs__wbuf *b, uint64_t v)
{
    unsigned char c[8];
    odhs__le64(c, v);
    odhs__put(b, c, 8);
}

static inline void odhs__put_f64(odhs__wbuf *b, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    odhs__put_u64(b, u);
}

static inline void odhs__put_f64s(odhs__wbuf *b, const double *v, size_t n)
{
    for (size_t k = 0; k < n; ++k) odhs__put_f64(b, v[k]);
}

static inline void odhs__put_tag(odhs__wbuf *b, const char *tag) { odhs__put(b, tag, 4); }

typedef struct {
    const unsigned char *p;
    size_t len, pos;
    int bad; /* read past the end or a wrong tag: every later read gives 0 */
} odhs__rbuf;

/* take len bytes into dst (may be NULL: skip); -1 and dst zeroed when fewer
 * remain or the buffer is already bad (lib/io/checkpoint.c) */
int odhs__get(odhs__rbuf *b, void *dst, size_t len);

static inline uint64_t odhs__get_u64(odhs__rbuf *b)
{
    unsigned char c[8];
    if (odhs__get(b, c, 8)) return 0;
    uint64_t v = 0;
    for (int k = 7; k >= 0; --k) v = (v << 8) | c[k];
    return v;
}

static inline double odhs__get_f64(odhs__rbuf *b)
{
    uint64_t u = odhs__get_u64(b);
    double v;
    memcpy(&v, &u, 8);
    return v;
}

static inline void odhs__get_f64s(odhs__rbuf *b, double *v, size_t n)
{
    for (size_t k = 0; k < n; ++k) v[k] = odhs__get_f64(b);
}

/* take the tag t; -1 (and the buffer bad) when the next 4 bytes are not t */
static inline int odhs__get_tag(odhs__rbuf *b, const char *t)
{
    char c[4];
    if (odhs__get(b, c, 4)) return -1;
    if (memcmp(c, t, 4)) {
        b->bad = 1;
        return -1;
    }
    return 0;
}

/* whether the next section is t (nothing consumed) */
static inline int odhs__peek_tag(const odhs__rbuf *b, const char *t)
{
    return !b->bad && b->len - b->pos >= 4 && !memcmp(b->p + b->pos, t, 4);
}

static inline int odhs__finite_all(const double *v, size_t n)
{
    for (size_t k = 0; k < n; ++k)
        if (!isfinite(v[k])) return 0;
    return 1;
}

/* ---- what the sections are written from and read into --------------------- */
typedef struct {
    const odhs_system *sys;
    const odhs_driver *drv;
    const odhs_stepper *st;
    int drv_stale; /* the driver changed after the forces were solved (DRVC) */
} odhs__ckpt_out;

typedef struct {
    odhs__rbuf b;        /* the sections, without END and the checksum */
    size_t size;         /* length of the whole file */
    uint64_t version;    /* format version */
    odhs_solver *solver; /* borrowed by the restored stepper */
    /* handles, created by the readers of SYS, DRV and STP (NULL before) */
    odhs_system *sys;
    odhs_driver *drv;
    odhs_stepper *st;
    int drv_changed;     /* DRVC was read: the next step re-solves the forces */
    char msg[ODHS_ERRMSG_LEN];
} odhs__ckpt_in;

/* ODHS_E_FORMAT with the message (lib/io/checkpoint.c) */
int odhs__ckpt_bad(odhs__ckpt_in *in, const char *fmt, ...) ODHS_PRINTF(2, 3);

/* status with "checkpoint: <odhs_strerror(status)>" */
static inline int odhs__ckpt_status(odhs__ckpt_in *in, int status)
{
    return odhs__err(in->msg, status, "checkpoint: %s", odhs_strerror(status));
}

static inline int odhs__ckpt_nomem(odhs__ckpt_in *in)
{
    return odhs__err(in->msg, ODHS_E_NOMEM, "checkpoint: out of memory");
}

/* ---- the sections, in the order of the file ----------------------------------
 * Readers return ODHS_OK or an error status with in->msg set; the handle a
 * reader creates is stored in `in` at once (destroyed by the caller on error). */
/* SYS: creates in->sys (lib/system/checkpoint.c) */
void odhs__ckpt_write_system(odhs__wbuf *b, const odhs_system *sys);
int odhs__ckpt_read_system(odhs__ckpt_in *in);
/* DRV, its fixed forces for the particles of sys: creates in->drv
 * (lib/driver/checkpoint.c) */
void odhs__ckpt_write_driver(odhs__wbuf *b, const odhs_driver *drv, const odhs_system *sys);
int odhs__ckpt_read_driver(odhs__ckpt_in *in);
/* STP: creates in->st (lib/stepper/checkpoint.c) */
void odhs__ckpt_write_stepper(odhs__wbuf *b, const odhs_stepper *st);
int odhs__ckpt_read_stepper(odhs__ckpt_in *in);
/* WAL (format version 2), only with walls: the writer returns the format
 * version it needs; the reader reads nothing without the tag
 * (lib/scene/checkpoint.c) */
unsigned odhs__ckpt_write_walls(odhs__wbuf *b, const odhs_network *net);
int odhs__ckpt_read_walls(odhs__ckpt_in *in);
/* NET: the contacts in their order, with forces (lib/stepper/checkpoint.c) */
void odhs__ckpt_write_network(odhs__wbuf *b, const odhs_network *net);
int odhs__ckpt_read_network(odhs__ckpt_in *in);
/* CMP (format version 2), only with bonds or rigid bodies, as WAL
 * (lib/scene/checkpoint.c) */
unsigned odhs__ckpt_write_composites(odhs__wbuf *b, const odhs_network *net);
int odhs__ckpt_read_composites(odhs__ckpt_in *in);

/* ---- optional sections after NET (format version 2) --------------------------
 * Each at most once, in any order. Every module with sections has a pair of
 * hooks, called in this order (driver first): write_*_tail appends the
 * module's optional sections and returns the format version they need (1 when
 * it wrote none); read_*_tail gets a tag just taken from in->b and returns 1
 * when it read that section, 0 when the tag is not one of the module's or the
 * section was read before, or an error status with in->msg set. A module adds
 * an optional section in its own hooks, lib/io/checkpoint.c is not changed.
 * Today: PROP, GRAV and DRVC of the driver (lib/driver/checkpoint.c). */
unsigned odhs__ckpt_write_driver_tail(odhs__wbuf *b, const odhs__ckpt_out *o);
int odhs__ckpt_read_driver_tail(odhs__ckpt_in *in, const char *tag);
unsigned odhs__ckpt_write_scene_tail(odhs__wbuf *b, const odhs__ckpt_out *o);
int odhs__ckpt_read_scene_tail(odhs__ckpt_in *in, const char *tag);
unsigned odhs__ckpt_write_stepper_tail(odhs__wbuf *b, const odhs__ckpt_out *o);
int odhs__ckpt_read_stepper_tail(odhs__ckpt_in *in, const char *tag);
unsigned odhs__ckpt_write_system_tail(odhs__wbuf *b, const odhs__ckpt_out *o);
int odhs__ckpt_read_system_tail(odhs__ckpt_in *in, const char *tag);

#endif /* ODHS_IO_CKPT_H */
