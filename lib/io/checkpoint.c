/* libodhs - checkpoints: the whole simulation state in a versioned, checksummed
 * binary file (see include/odhs/checkpoint.h). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "io/ckpt.h"
#include "stepper/stepper.h"

static const char MAGIC[8] = {'O', 'D', 'H', 'S', 'C', 'K', 'P', 'T'};

/* largest |gap| / (a_i + a_j) of a contact in a readable checkpoint: far above
 * any drift between corrections (about 1e-4 at dt = 1e-3, see
 * docs/reliability.md), far below gaps that are not contacts */
#define CKPT_MAX_CONTACT_GAP 0.1

/* ---- byte buffers (lib/io/ckpt.h) ----------------------------------------- */
void odhs__put(odhs__wbuf *b, const void *src, size_t len)
{
    if (b->nomem) return;
    if (b->len + len > b->cap) {
        size_t cap = b->cap ? b->cap : 4096;
        while (cap < b->len + len) cap *= 2;
        unsigned char *q = odhs__realloc(b->p, cap);
        if (!q) {
            b->nomem = 1;
            return;
        }
        b->p = q;
        b->cap = cap;
    }
    memcpy(b->p + b->len, src, len);
    b->len += len;
}

int odhs__get(odhs__rbuf *b, void *dst, size_t len)
{
    if (b->bad || len > b->len - b->pos) {
        b->bad = 1;
        if (dst) memset(dst, 0, len);
        return -1;
    }
    if (dst) memcpy(dst, b->p + b->pos, len);
    b->pos += len;
    return 0;
}

int odhs__ckpt_bad(odhs__ckpt_in *in, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    odhs__verr(in->msg, ODHS_E_FORMAT, fmt, ap);
    va_end(ap);
    return ODHS_E_FORMAT;
}

static uint64_t fnv1a(const unsigned char *p, size_t len)
{
    uint64_t h = 1469598103934665603ULL;
    for (size_t k = 0; k < len; ++k) {
        h ^= p[k];
        h *= 1099511628211ULL;
    }
    return h;
}

/* the optional sections after NET: each module's hooks, driver first */
static const struct {
    unsigned (*write)(odhs__wbuf *b, const odhs__ckpt_out *o);
    int (*read)(odhs__ckpt_in *in, const char *tag);
} tails[] = {
    {odhs__ckpt_write_driver_tail, odhs__ckpt_read_driver_tail},
    {odhs__ckpt_write_scene_tail, odhs__ckpt_read_scene_tail},
    {odhs__ckpt_write_stepper_tail, odhs__ckpt_read_stepper_tail},
    {odhs__ckpt_write_system_tail, odhs__ckpt_read_system_tail},
};
#define NTAILS (sizeof tails / sizeof tails[0])

/* a contact is a pair at contact distance, up to the integrator's drift: the
 * first contact farther than that, or SIZE_MAX */
static size_t far_contact(const odhs_network *net, const odhs_system *sys)
{
    for (size_t c = 0; c < net->nc; ++c)
        if (!(fabs(net->gap[c]) <= CKPT_MAX_CONTACT_GAP * odhs__net_sigma(net, sys, c))) return c;
    return SIZE_MAX;
}

/* ---- writer ----------------------------------------------------------------- */
/* the whole file: magic, format version, sections, END and the checksum */
static void serialize(odhs__wbuf *b, const odhs_stepper *st)
{
    /* the driver changed after the forces were solved: the next step
     * re-solves them first (section DRVC, since 0.2.2) */
    odhs__ckpt_out o = {st->sys, st->drv, st, st->drv_version != st->drv->version};
    odhs__put(b, MAGIC, 8);
    /* version 1 unless a section of version 2 is written, so that files
     * without them stay readable by older releases: set below */
    odhs__put_u64(b, 1u);
    unsigned version = 1, v;
    odhs__ckpt_write_system(b, st->sys);
    odhs__ckpt_write_driver(b, st->drv, st->sys);
    odhs__ckpt_write_stepper(b, st);
    /* walls before the contacts that refer to them */
    if ((v = odhs__ckpt_write_walls(b, st->net)) > version) version = v;
    odhs__ckpt_write_network(b, st->net);
    if ((v = odhs__ckpt_write_composites(b, st->net)) > version) version = v;
    for (size_t k = 0; k < NTAILS; ++k)
        if ((v = tails[k].write(b, &o)) > version) version = v;
    if (!b->nomem) odhs__le64(b->p + 8, version);
    odhs__put_tag(b, "END ");
    odhs__put_u64(b, b->nomem ? 0 : fnv1a(b->p, b->len));
}

/* write atomically: temporary file in the same directory, sync, rename */
static int write_file(const odhs__wbuf *b, const char *path, char *errmsg)
{
    size_t plen = strlen(path);
    char *tmp = odhs__malloc(plen + 16);
    if (!tmp) return odhs__err(errmsg, ODHS_E_NOMEM, "checkpoint: out of memory");
    snprintf(tmp, plen + 16, "%s.tmpXXXXXX", path);
    int fd = mkstemp(tmp);
    int ok = fd >= 0;
    FILE *f = ok ? fdopen(fd, "wb") : NULL;
    if (ok && !f) {
        close(fd);
        ok = 0;
    }
    int err = 0;
    if (ok) {
        ok = fwrite(b->p, 1, b->len, f) == b->len && fflush(f) == 0 && fsync(fileno(f)) == 0;
        if (!ok) err = errno;
        if (fclose(f) != 0 && ok) {
            ok = 0;
            err = errno;
        }
        if (ok && rename(tmp, path) != 0) {
            ok = 0;
            err = errno;
        }
        if (!ok) remove(tmp);
    } else {
        err = errno;
    }
    int status = ok ? ODHS_OK : odhs__err(errmsg, ODHS_E_IO, "checkpoint: cannot write %s: %s", path, strerror(err));
    odhs__free(tmp);
    return status;
}

int odhs_checkpoint_write(const odhs_stepper *st, const char *path)
{
    if (!st) return ODHS_E_NULL;
    odhs_stepper *mst = (odhs_stepper *)st; /* error message buffer only */
    if (!path) return odhs__err(mst->errmsg, ODHS_E_NULL, "path is NULL");
    if (!st->ready) return odhs__err(mst->errmsg, ODHS_E_STATE, "checkpoint: the stepper has no state yet");
    /* never write what the reader refuses */
    const odhs_network *net = st->net;
    size_t c = far_contact(net, st->sys);
    if (c != SIZE_MAX)
        return odhs__err(mst->errmsg, ODHS_E_STATE,
                         "checkpoint: contact (%zu,%zu) has a gap of %.3g contact distances: not a valid state",
                         net->ci[c], net->cj[c], net->gap[c] / odhs__net_sigma(net, st->sys, c));
    odhs__wbuf b = {NULL, 0, 0, 0};
    serialize(&b, st);
    int status = b.nomem ? odhs__err(mst->errmsg, ODHS_E_NOMEM, "checkpoint: out of memory")
                         : write_file(&b, path, mst->errmsg);
    odhs__free(b.p);
    return status;
}

/* ---- reader --------------------------------------------------------------- */
/* magic, checksum (nothing is trusted before it matches) and format version */
static int open_file(odhs__ckpt_in *in, const unsigned char *p, size_t len)
{
    if (len < 8 + 8 + 4 + 8 || memcmp(p, MAGIC, 8)) return odhs__ckpt_bad(in, "checkpoint: not a libodhs checkpoint");
    odhs__rbuf t = {p, len, len - 8, 0};
    uint64_t sum = odhs__get_u64(&t);
    if (memcmp(p + len - 12, "END ", 4) || sum != fnv1a(p, len - 8))
        return odhs__ckpt_bad(in, "checkpoint: checksum mismatch (truncated or corrupted file)");
    in->b = (odhs__rbuf){p, len - 12, 8, 0};
    in->size = len;
    in->version = odhs__get_u64(&in->b);
    if (in->version < 1 || in->version > ODHS_CHECKPOINT_VERSION)
        return odhs__ckpt_bad(in, "checkpoint: format version %llu not supported (this library reads 1 to %d)",
                              (unsigned long long)in->version, ODHS_CHECKPOINT_VERSION);
    return ODHS_OK;
}

/* the sections in their order; an optional section after NET goes to the
 * first module that claims its tag */
static int read_sections(odhs__ckpt_in *in)
{
    int s;
    int v2 = in->version >= 2;
    if ((s = odhs__ckpt_read_system(in)) || (s = odhs__ckpt_read_driver(in)) || (s = odhs__ckpt_read_stepper(in)) ||
        (v2 && (s = odhs__ckpt_read_walls(in))) || (s = odhs__ckpt_read_network(in)) ||
        (v2 && (s = odhs__ckpt_read_composites(in))))
        return s;
    odhs__rbuf *b = &in->b;
    while (v2 && b->pos < b->len && !b->bad) {
        char t4[4];
        odhs__get(b, t4, 4);
        int claimed = 0;
        for (size_t k = 0; !claimed && k < NTAILS; ++k) claimed = tails[k].read(in, t4);
        if (claimed < 0) return claimed;
        if (!claimed) return odhs__ckpt_bad(in, "checkpoint: unknown or repeated section");
    }
    if (b->pos != b->len) return odhs__ckpt_bad(in, "checkpoint: unexpected trailing data");
    return ODHS_OK;
}

/* the checks across sections, and the stepper's derived state */
static int finish(odhs__ckpt_in *in)
{
    odhs_system *sys = in->sys;
    odhs_driver *drv = in->drv;
    odhs_stepper *st = in->st;
    odhs__net_geometry(st->net, sys);
    st->has_F = 0;
    /* far-apart "contacts" act as rigid bonds and the drift correction would
     * move their particles into others (found by fuzz_checkpoint) */
    size_t c = far_contact(st->net, sys);
    if (c != SIZE_MAX)
        return odhs__ckpt_bad(in, "checkpoint: contact (%zu,%zu) has a gap of %.3g contact distances",
                              st->net->ci[c], st->net->cj[c],
                              st->net->gap[c] / odhs__net_sigma(st->net, sys, c)); /* a_i for walls */
    if (odhs__stepper_check_neighbours(st)) return odhs__ckpt_nomem(in);
    if (drv->F) {
        memcpy(st->F, drv->F, st->nd * sizeof *st->F);
        st->has_F = 1;
    }
    /* the forces as eval_forces computes them (a mismatch fails the next step) */
    odhs__driver_extra_forces(drv, sys, st->F, &st->has_F);
    /* a driver changed after the last solve is re-solved by the next step,
     * as it would have been without the checkpoint */
    st->drv_version = in->drv_changed ? drv->version - 1 : drv->version;
    st->sys_version = sys->version;
    st->ready = 1;
    return ODHS_OK;
}

int odhs_checkpoint_parse(const void *buf, size_t len, odhs_solver *solver, odhs_system **sys_out,
                          odhs_driver **drv_out, odhs_stepper **st_out, char *errbuf, size_t errlen)
{
    odhs__ckpt_in in;
    memset(&in, 0, sizeof in);
    if (errbuf && errlen) errbuf[0] = '\0'; /* "" on success, like the XYZ reader */
    if (sys_out) *sys_out = NULL;
    if (drv_out) *drv_out = NULL;
    if (st_out) *st_out = NULL;
    int status;
    if (!buf || !solver || !sys_out || !drv_out || !st_out) {
        status = odhs__err(in.msg, ODHS_E_NULL, "checkpoint: NULL argument");
    } else {
        in.solver = solver;
        status = open_file(&in, buf, len);
        if (!status) status = read_sections(&in);
        if (!status) status = finish(&in);
    }
    if (status) {
        odhs_stepper_destroy(in.st);
        odhs_driver_destroy(in.drv);
        odhs_system_destroy(in.sys);
        if (errbuf && errlen) snprintf(errbuf, errlen, "%s", in.msg);
        return status;
    }
    *sys_out = in.sys;
    *drv_out = in.drv;
    *st_out = in.st;
    return ODHS_OK;
}

int odhs_checkpoint_read(const char *path, odhs_solver *solver, odhs_system **sys, odhs_driver **drv,
                         odhs_stepper **st, char *errbuf, size_t errlen)
{
    if (sys) *sys = NULL;
    if (drv) *drv = NULL;
    if (st) *st = NULL;
    if (errbuf && errlen) errbuf[0] = '\0';
    if (!path) {
        if (errbuf && errlen) snprintf(errbuf, errlen, "checkpoint: path is NULL");
        return ODHS_E_NULL;
    }
    FILE *f = fopen(path, "rb");
    if (!f) {
        if (errbuf && errlen) snprintf(errbuf, errlen, "checkpoint: cannot open %s: %s", path, strerror(errno));
        return ODHS_E_IO;
    }
    size_t cap = 1 << 16, len = 0;
    unsigned char *buf = odhs__malloc(cap);
    int status = ODHS_OK;
    while (buf) {
        if (len == cap) {
            unsigned char *q = odhs__realloc(buf, cap * 2);
            if (!q) {
                odhs__free(buf);
                buf = NULL;
                break;
            }
            buf = q;
            cap *= 2;
        }
        size_t got = fread(buf + len, 1, cap - len, f);
        len += got;
        if (got == 0) break;
    }
    if (!buf) status = ODHS_E_NOMEM;
    else if (ferror(f)) status = ODHS_E_IO;
    fclose(f);
    if (status) {
        if (errbuf && errlen)
            snprintf(errbuf, errlen, "checkpoint: %s reading %s", status == ODHS_E_NOMEM ? "out of memory" : "I/O error",
                     path);
        odhs__free(buf);
        return status;
    }
    status = odhs_checkpoint_parse(buf, len, solver, sys, drv, st, errbuf, errlen);
    odhs__free(buf);
    return status;
}
