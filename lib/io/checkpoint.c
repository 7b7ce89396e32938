/* libodhs - checkpoints: the whole simulation state in a versioned, checksummed
 * binary file (see include/odhs/checkpoint.h). */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include "stepper/stepper.h"

static const char MAGIC[8] = {'O', 'D', 'H', 'S', 'C', 'K', 'P', 'T'};

/* largest |gap| / (a_i + a_j) of a contact in a readable checkpoint: far above
 * any drift between corrections (about 1e-4 at dt = 1e-3, see
 * docs/reliability.md), far below gaps that are not contacts */
#define CKPT_MAX_CONTACT_GAP 0.1

/* ---- byte buffer (writer) ------------------------------------------------ */
typedef struct {
    unsigned char *p;
    size_t len, cap;
    int nomem;
} wbuf;

static void put(wbuf *b, const void *src, size_t len)
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

static void put_u64(wbuf *b, uint64_t v)
{
    unsigned char c[8];
    for (int k = 0; k < 8; ++k) c[k] = (unsigned char)(v >> (8 * k));
    put(b, c, 8);
}

static void put_f64(wbuf *b, double v)
{
    uint64_t u;
    memcpy(&u, &v, 8);
    put_u64(b, u);
}

static void put_f64s(wbuf *b, const double *v, size_t n)
{
    for (size_t k = 0; k < n; ++k) put_f64(b, v[k]);
}

static void put_tag(wbuf *b, const char *tag) { put(b, tag, 4); }

static uint64_t fnv1a(const unsigned char *p, size_t len)
{
    uint64_t h = 1469598103934665603ULL;
    for (size_t k = 0; k < len; ++k) {
        h ^= p[k];
        h *= 1099511628211ULL;
    }
    return h;
}

/* ---- writer ----------------------------------------------------------------- */
int odhs_checkpoint_write(const odhs_stepper *st, const char *path)
{
    if (!st) return ODHS_E_NULL;
    odhs_stepper *mst = (odhs_stepper *)st; /* error message buffer only */
    if (!path) return odhs__err(mst->errmsg, ODHS_E_NULL, "path is NULL");
    if (!st->ready) return odhs__err(mst->errmsg, ODHS_E_STATE, "checkpoint: the stepper has no state yet");
    const odhs_system *sys = st->sys;
    const odhs_driver *drv = st->drv;
    const odhs_network *net = st->net;
    size_t n = sys->n, nd = st->nd;
    /* never write what the reader refuses */
    for (size_t c = 0; c < net->nc; ++c) {
        size_t i = net->ci[c], j = net->cj[c];
        double sig = odhs__net_sigma(net, sys, c);
        if (!(fabs(net->gap[c]) <= CKPT_MAX_CONTACT_GAP * sig))
            return odhs__err(mst->errmsg, ODHS_E_STATE,
                             "checkpoint: contact (%zu,%zu) has a gap of %.3g contact distances: not a valid state", i,
                             j, net->gap[c] / sig);
    }
    wbuf b = {NULL, 0, 0, 0};
    put(&b, MAGIC, 8);
    /* version 1 unless a section of version 2 is needed, so that files
     * without them stay readable by older releases */
    /* the driver changed after the forces were solved: the next step
     * re-solves them first (section DRVC, since 0.2.2) */
    int stale = st->drv_version != drv->version;
    put_u64(&b, drv->prop_on || drv->grav_on || net->nwalls || net->nperm || net->rbody || stale ? 2u : 1u);
    /* system */
    put_tag(&b, "SYS ");
    put_u64(&b, (uint64_t)sys->dim);
    put_u64(&b, n);
    put_f64s(&b, sys->L, 3);
    put_f64(&b, sys->gamma);
    put_f64s(&b, sys->x, nd);
    put_f64s(&b, sys->r, n);
    put(&b, sys->species, n * sizeof *sys->species);
    /* driver */
    put_tag(&b, "DRV ");
    put_f64(&b, drv->xi0);
    put_f64(&b, drv->gdot);
    put_f64(&b, drv->crate);
    put_u64(&b, (uint64_t)drv->pressure_on);
    put_f64(&b, drv->p);
    put_f64(&b, drv->kappa_max);
    put_f64(&b, drv->tau_user);
    put_u64(&b, drv->F ? 1u : 0u);
    if (drv->F) put_f64s(&b, drv->F, nd);
    /* stepper */
    put_tag(&b, "STP ");
    put_f64(&b, st->dt);
    put_u64(&b, (uint64_t)st->integrator);
    put_f64(&b, st->tol);
    put_f64(&b, st->h);
    put_f64(&b, st->lambda);
    put_u64(&b, st->nrejected);
    put_u64(&b, st->nsolves_pred);
    put_u64(&b, st->corr_every);
    put_f64(&b, st->contact_tol);
    put_f64(&b, st->time);
    put_f64(&b, st->strain);
    put_u64(&b, st->nsteps);
    put_u64(&b, st->ncoll);
    put_u64(&b, st->nopen);
    put_f64(&b, st->tau);
    put_f64s(&b, st->G, 9);
    put_f64(&b, st->kappa);
    put_u64(&b, (uint64_t)st->jammed);
    put_f64s(&b, st->U, nd);
    put_f64(&b, st->skin);
    put_f64(&b, st->rc);
    put_f64s(&b, st->disp, nd);
    put_f64s(&b, st->M, 9);
    put_u64(&b, (uint64_t)st->nb_stale);
    put_u64(&b, st->npairs);
    for (size_t p = 0; p < st->npairs; ++p) {
        put_u64(&b, st->pi[p]);
        put_u64(&b, st->pj[p]);
    }
    /* optional: walls (before the contacts that refer to them) */
    if (net->nwalls) {
        put_tag(&b, "WAL ");
        put_u64(&b, net->nwalls);
        for (size_t w = 0; w < net->nwalls; ++w) {
            const odhs_wall *wl = &net->walls[w];
            put_u64(&b, (uint64_t)wl->type);
            put_f64s(&b, wl->n, 3);
            put_f64(&b, wl->h);
            put_f64s(&b, wl->c, 3);
            put_f64s(&b, wl->b, 3);
            put_f64(&b, wl->R);
            put_f64s(&b, wl->v, 3);
            put_f64s(&b, wl->disp, 3);
        }
    }
    /* network, in its order */
    put_tag(&b, "NET ");
    put_u64(&b, net->nc);
    for (size_t c = 0; c < net->nc; ++c) {
        put_u64(&b, net->ci[c]);
        put_u64(&b, net->cj[c]);
        put_u64(&b, (uint64_t)net->kind[c]);
        put_f64(&b, net->f[c]);
    }
    /* optional: composites (rest lengths of the bonds, rigid-body labels) */
    if (net->nperm || net->rbody) {
        put_tag(&b, "CMP ");
        put_u64(&b, net->nperm);
        for (size_t c = 0; c < net->nc; ++c)
            if (net->kind[c] == ODHS_CONTACT_PERMANENT) {
                put_u64(&b, c);
                put_f64(&b, net->rest[c]);
            }
        put_u64(&b, net->rbody ? 1u : 0u);
        if (net->rbody)
            for (size_t i = 0; i < n; ++i) put_u64(&b, net->rbody[i] == SIZE_MAX ? UINT64_MAX : net->rbody[i]);
    }
    /* optional sections (version 2) */
    if (drv->prop_on) {
        put_tag(&b, "PROP");
        put_u64(&b, drv->pn);
        put_u64(&b, (uint64_t)drv->pdim);
        put_f64(&b, drv->pfmin);
        put_f64(&b, drv->pfmax);
        put_f64(&b, drv->ptmin);
        put_f64(&b, drv->ptmax);
        put_u64(&b, (uint64_t)drv->prop_started);
        for (int k = 0; k < 4; ++k) put_u64(&b, drv->prng.s[k]);
        put_f64s(&b, drv->pF, drv->pn * (size_t)drv->pdim);
        put_f64s(&b, drv->pts, drv->pn);
    }
    if (drv->grav_on) {
        put_tag(&b, "GRAV");
        put_u64(&b, (uint64_t)drv->gdim);
        put_f64s(&b, drv->g, 3);
        put_u64(&b, drv->gw ? drv->gwn : 0u);
        if (drv->gw) put_f64s(&b, drv->gw, drv->gwn);
    }
    if (stale) {
        put_tag(&b, "DRVC");
        put_u64(&b, 1u);
    }
    put_tag(&b, "END ");
    put_u64(&b, b.nomem ? 0 : fnv1a(b.p, b.len));
    if (b.nomem) {
        odhs__free(b.p);
        return odhs__err(mst->errmsg, ODHS_E_NOMEM, "checkpoint: out of memory");
    }

    /* write atomically: temporary file in the same directory, sync, rename */
    size_t plen = strlen(path);
    char *tmp = odhs__malloc(plen + 16);
    if (!tmp) {
        odhs__free(b.p);
        return odhs__err(mst->errmsg, ODHS_E_NOMEM, "checkpoint: out of memory");
    }
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
        ok = fwrite(b.p, 1, b.len, f) == b.len && fflush(f) == 0 && fsync(fileno(f)) == 0;
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
    odhs__free(b.p);
    int st_code = ok ? ODHS_OK
                     : odhs__err(mst->errmsg, ODHS_E_IO, "checkpoint: cannot write %s: %s", path, strerror(err));
    odhs__free(tmp);
    return st_code;
}

/* ---- reader --------------------------------------------------------------- */
typedef struct {
    const unsigned char *p;
    size_t len, pos;
    int bad;
} rbuf;

static int get(rbuf *b, void *dst, size_t len)
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

static uint64_t get_u64(rbuf *b)
{
    unsigned char c[8];
    if (get(b, c, 8)) return 0;
    uint64_t v = 0;
    for (int k = 7; k >= 0; --k) v = (v << 8) | c[k];
    return v;
}

static double get_f64(rbuf *b)
{
    uint64_t u = get_u64(b);
    double v;
    memcpy(&v, &u, 8);
    return v;
}

static void get_f64s(rbuf *b, double *v, size_t n)
{
    for (size_t k = 0; k < n; ++k) v[k] = get_f64(b);
}

static int tag(rbuf *b, const char *t)
{
    char c[4];
    if (get(b, c, 4)) return -1;
    if (memcmp(c, t, 4)) {
        b->bad = 1;
        return -1;
    }
    return 0;
}

/* whether the next section is t (nothing consumed) */
static int peek_tag(const rbuf *b, const char *t)
{
    return !b->bad && b->len - b->pos >= 4 && !memcmp(b->p + b->pos, t, 4);
}

static int finite_all(const double *v, size_t n)
{
    for (size_t k = 0; k < n; ++k)
        if (!isfinite(v[k])) return 0;
    return 1;
}

#define FAIL(code, ...)                                          \
    do {                                                         \
        status = odhs__err(msg, (code), __VA_ARGS__);            \
        goto fail;                                               \
    } while (0)

int odhs_checkpoint_parse(const void *buf, size_t len, odhs_solver *solver, odhs_system **sys_out,
                          odhs_driver **drv_out, odhs_stepper **st_out, char *errbuf, size_t errlen)
{
    char msg[ODHS_ERRMSG_LEN] = "";
    int status = ODHS_OK;
    odhs_system *sys = NULL;
    odhs_driver *drv = NULL;
    odhs_stepper *st = NULL;
    double *tmpF = NULL;
    if (errbuf && errlen) errbuf[0] = '\0'; /* "" on success, like the XYZ reader */
    if (sys_out) *sys_out = NULL;
    if (drv_out) *drv_out = NULL;
    if (st_out) *st_out = NULL;
    if (!buf || !solver || !sys_out || !drv_out || !st_out) {
        status = odhs__err(msg, ODHS_E_NULL, "checkpoint: NULL argument");
        goto fail;
    }
    const unsigned char *p = buf;
    if (len < 8 + 8 + 4 + 8 || memcmp(p, MAGIC, 8)) FAIL(ODHS_E_FORMAT, "checkpoint: not a libodhs checkpoint");
    /* checksum first: nothing is trusted before it matches */
    {
        rbuf t = {p, len, len - 8, 0};
        uint64_t sum = get_u64(&t);
        if (memcmp(p + len - 12, "END ", 4) || sum != fnv1a(p, len - 8))
            FAIL(ODHS_E_FORMAT, "checkpoint: checksum mismatch (truncated or corrupted file)");
    }
    rbuf b = {p, len - 12, 8, 0};
    uint64_t version = get_u64(&b);
    if (version < 1 || version > ODHS_CHECKPOINT_VERSION)
        FAIL(ODHS_E_FORMAT, "checkpoint: format version %llu not supported (this library reads 1 to %d)",
             (unsigned long long)version, ODHS_CHECKPOINT_VERSION);
    /* system */
    if (tag(&b, "SYS ")) FAIL(ODHS_E_FORMAT, "checkpoint: system section missing");
    uint64_t dim = get_u64(&b), n = get_u64(&b);
    if (b.bad || (dim != 2 && dim != 3) || n == 0 || n > (len / 8) / (dim + 1))
        FAIL(ODHS_E_FORMAT, "checkpoint: bad dimension or particle count");
    size_t nd = (size_t)n * (size_t)dim;
    int s = odhs_system_create((int)dim, (size_t)n, &sys);
    if (s) FAIL(s, "checkpoint: %s", odhs_strerror(s));
    get_f64s(&b, sys->L, 3);
    sys->gamma = get_f64(&b);
    get_f64s(&b, sys->x, nd);
    get_f64s(&b, sys->r, (size_t)n);
    get(&b, sys->species, (size_t)n * sizeof *sys->species);
    if (b.bad) FAIL(ODHS_E_FORMAT, "checkpoint: system section truncated");
    if (!finite_all(sys->L, 3) || !isfinite(sys->gamma) || !finite_all(sys->x, nd) || !finite_all(sys->r, (size_t)n))
        FAIL(ODHS_E_FORMAT, "checkpoint: non-finite number in the system section");
    double rmax = 0.0;
    for (size_t i = 0; i < n; ++i) {
        if (!(sys->r[i] > 0.0)) FAIL(ODHS_E_FORMAT, "checkpoint: radius %zu is not positive", i);
        rmax = fmax(rmax, sys->r[i]);
        sys->species[i][ODHS_SPECIES_MAX] = '\0';
    }
    for (size_t k = 0; k < dim; ++k)
        if (!(sys->L[k] >= 4.0 * rmax)) FAIL(ODHS_E_FORMAT, "checkpoint: box edge %zu too small", k);
    /* the aspect-ratio rule of the system setters (lib/system.c, check_box):
     * an XYZ file of a box outside it could not be read back (found by
     * fuzz_checkpoint) */
    if (!(sys->L[0] / sys->L[1] > 1e-100 && sys->L[0] / sys->L[1] < 1e100))
        FAIL(ODHS_E_FORMAT, "checkpoint: box aspect ratio Lx/Ly = %g out of range [1e-100, 1e100]",
             sys->L[0] / sys->L[1]);
    if (fabs(sys->gamma) > 0.5 * sys->L[0] / sys->L[1] * (1 + 1e-12))
        FAIL(ODHS_E_FORMAT, "checkpoint: strain outside its remapped range");
    for (size_t i = 0; i < nd; ++i)
        if (sys->x[i] < 0.0 || sys->x[i] >= sys->L[i % dim]) FAIL(ODHS_E_FORMAT, "checkpoint: position outside the box");
    /* species labels as odhs_system_set_species accepts them (an empty or
     * blank label made an XYZ file that could not be read back: found by
     * fuzz_checkpoint); the bytes after the terminator are kept */
    for (size_t i = 0; i < n; ++i) {
        char lab[ODHS_SPECIES_MAX + 1];
        memcpy(lab, sys->species[i], sizeof lab);
        if (odhs_system_set_species(sys, i, lab))
            FAIL(ODHS_E_FORMAT, "checkpoint: species label of particle %zu is not valid", i);
    }
    sys->rmax = rmax;
    sys->has_r = sys->has_x = 1;
    /* driver */
    if (tag(&b, "DRV ")) FAIL(ODHS_E_FORMAT, "checkpoint: driver section missing");
    if ((s = odhs_driver_create(&drv))) FAIL(s, "checkpoint: %s", odhs_strerror(s));
    drv->xi0 = get_f64(&b);
    drv->gdot = get_f64(&b);
    drv->crate = get_f64(&b);
    uint64_t pon = get_u64(&b);
    drv->p = get_f64(&b);
    drv->kappa_max = get_f64(&b);
    drv->tau_user = get_f64(&b);
    uint64_t hasF = get_u64(&b);
    if (b.bad || pon > 1 || hasF > 1) FAIL(ODHS_E_FORMAT, "checkpoint: driver section malformed");
    drv->pressure_on = (int)pon;
    if (!(drv->xi0 > 0.0) || !isfinite(drv->xi0) || !isfinite(drv->gdot) || !isfinite(drv->crate) ||
        !isfinite(drv->p) || !(drv->kappa_max > 0.0) || !isfinite(drv->kappa_max) || !isfinite(drv->tau_user) ||
        drv->tau_user < 0.0 || (pon && !(drv->p > 0.0)))
        FAIL(ODHS_E_FORMAT, "checkpoint: invalid driver settings");
    if (hasF) {
        tmpF = odhs__malloc_array(nd, sizeof *tmpF);
        if (!tmpF) FAIL(ODHS_E_NOMEM, "checkpoint: out of memory");
        get_f64s(&b, tmpF, nd);
        if (b.bad || !finite_all(tmpF, nd)) FAIL(ODHS_E_FORMAT, "checkpoint: bad driver forces");
        if ((s = odhs_driver_set_forces(drv, (size_t)n, (int)dim, tmpF))) FAIL(s, "checkpoint: %s", odhs_strerror(s));
    }
    /* stepper */
    if (tag(&b, "STP ")) FAIL(ODHS_E_FORMAT, "checkpoint: stepper section missing");
    if ((s = odhs_stepper_create(sys, drv, solver, &st))) FAIL(s, "checkpoint: %s", odhs_strerror(s));
    st->dt = get_f64(&b);
    uint64_t integ = get_u64(&b);
    st->tol = get_f64(&b);
    st->h = get_f64(&b);
    st->lambda = get_f64(&b);
    st->nrejected = get_u64(&b);
    st->nsolves_pred = get_u64(&b);
    uint64_t corr = get_u64(&b);
    st->contact_tol = get_f64(&b);
    st->time = get_f64(&b);
    st->strain = get_f64(&b);
    st->nsteps = get_u64(&b);
    st->ncoll = get_u64(&b);
    st->nopen = get_u64(&b);
    st->tau = get_f64(&b);
    get_f64s(&b, st->G, 9);
    st->kappa = get_f64(&b);
    uint64_t jam = get_u64(&b);
    get_f64s(&b, st->U, nd);
    st->skin = get_f64(&b);
    st->rc = get_f64(&b);
    get_f64s(&b, st->disp, nd);
    get_f64s(&b, st->M, 9);
    uint64_t stale = get_u64(&b);
    uint64_t npairs = get_u64(&b);
    if (b.bad || integ > ODHS_INTEGRATOR_HEUN || corr > 0xffffffffu || jam > 1 || stale > 1 ||
        npairs > (b.len - b.pos) / 16)
        FAIL(ODHS_E_FORMAT, "checkpoint: stepper section malformed");
    st->integrator = (int)integ;
    st->corr_every = (unsigned)corr;
    st->corr_user = 1; /* the file's interval is kept by set_integrator */
    st->jammed = (int)jam;
    st->nb_stale = (int)stale;
    double sc[] = {st->dt, st->tol, st->h, st->lambda, st->contact_tol, st->time, st->strain, st->tau,
                   st->kappa, st->skin, st->rc};
    static const char *const scn[] = {"dt", "tol", "h", "lambda", "contact_tol", "time", "strain", "tau",
                                      "kappa", "skin", "rc"};
    for (size_t k = 0; k < sizeof sc / sizeof sc[0]; ++k)
        if (!isfinite(sc[k])) FAIL(ODHS_E_FORMAT, "checkpoint: stepper value %s is not finite", scn[k]);
    if (!finite_all(st->G, 9) || !finite_all(st->M, 9) || !finite_all(st->U, nd) || !finite_all(st->disp, nd))
        FAIL(ODHS_E_FORMAT, "checkpoint: non-finite number in the stepper section (%s)",
             !finite_all(st->G, 9) ? "velocity gradient" : !finite_all(st->M, 9) ? "cell matrix"
             : !finite_all(st->U, nd) ? "velocities" : "displacements");
    if (!(st->dt > 0) || !(st->tol > 0 && st->tol < 1) || !(st->h > 0) || !(st->tau > 0) || !(st->lambda > 0) ||
        !(st->skin > 0) || st->contact_tol < 0)
        FAIL(ODHS_E_FORMAT,
             "checkpoint: invalid stepper values (dt %g, tol %g, h %g, tau %g, lambda %g, skin %g, contact_tol %g)",
             st->dt, st->tol, st->h, st->tau, st->lambda, st->skin, st->contact_tol);
    if (npairs) {
        size_t *a = odhs__realloc(st->pi, (size_t)npairs * sizeof *a);
        if (a) st->pi = a;
        size_t *c = odhs__realloc(st->pj, (size_t)npairs * sizeof *c);
        if (c) st->pj = c;
        if (!a || !c) FAIL(ODHS_E_NOMEM, "checkpoint: out of memory");
        st->pcap = (size_t)npairs;
    }
    for (size_t q = 0; q < npairs; ++q) {
        uint64_t i = get_u64(&b), j = get_u64(&b);
        if (b.bad || i >= j || j >= n) FAIL(ODHS_E_FORMAT, "checkpoint: bad neighbour pair");
        st->pi[q] = (size_t)i;
        st->pj[q] = (size_t)j;
    }
    st->npairs = (size_t)npairs;
    /* walls (version 2) */
    if (version >= 2 && peek_tag(&b, "WAL ")) {
        tag(&b, "WAL ");
        uint64_t nw = get_u64(&b);
        if (b.bad || nw > (b.len - b.pos) / 8) FAIL(ODHS_E_FORMAT, "checkpoint: bad wall count");
        for (uint64_t w = 0; w < nw; ++w) {
            odhs_wall wl;
            memset(&wl, 0, sizeof wl);
            uint64_t type = get_u64(&b);
            get_f64s(&b, wl.n, 3);
            wl.h = get_f64(&b);
            get_f64s(&b, wl.c, 3);
            get_f64s(&b, wl.b, 3);
            wl.R = get_f64(&b);
            get_f64s(&b, wl.v, 3);
            get_f64s(&b, wl.disp, 3);
            if (b.bad || type > ODHS_WALL_SEGMENT || !finite_all(wl.n, 3) || !isfinite(wl.h) ||
                !finite_all(wl.c, 3) || !finite_all(wl.b, 3) || !isfinite(wl.R) || !finite_all(wl.v, 3) ||
                !finite_all(wl.disp, 3) || (type == ODHS_WALL_SPHERE && !(wl.R > 0.0)) ||
                (type == ODHS_WALL_SEGMENT && dim != 2))
                FAIL(ODHS_E_FORMAT, "checkpoint: bad wall %llu", (unsigned long long)w);
            wl.type = (int)type;
            if (odhs__net_add_wall(st->net, &wl)) FAIL(ODHS_E_NOMEM, "checkpoint: out of memory");
        }
    }
    /* network */
    if (tag(&b, "NET ")) FAIL(ODHS_E_FORMAT, "checkpoint: network section missing");
    uint64_t nc = get_u64(&b);
    if (b.bad || nc > (b.len - b.pos) / 32) FAIL(ODHS_E_FORMAT, "checkpoint: bad contact count");
    for (size_t c = 0; c < nc; ++c) {
        uint64_t i = get_u64(&b), j = get_u64(&b), kind = get_u64(&b);
        double f = get_f64(&b);
        int wall = j >= n;
        if (b.bad || i >= j || i >= n || j >= n + st->net->nwalls || kind > ODHS_CONTACT_WALL ||
            (kind == ODHS_CONTACT_WALL) != wall || !isfinite(f))
            FAIL(ODHS_E_FORMAT, "checkpoint: bad contact %zu", c);
        if (odhs__net_find(st->net, (size_t)i, (size_t)j) != SIZE_MAX)
            FAIL(ODHS_E_FORMAT, "checkpoint: duplicate contact (%llu,%llu)", (unsigned long long)i,
                 (unsigned long long)j);
        size_t k = odhs__net_add(st->net, (size_t)i, (size_t)j, (int)kind);
        if (k == SIZE_MAX) FAIL(ODHS_E_NOMEM, "checkpoint: out of memory");
        st->net->f[k] = f;
    }
    if (version >= 2 && peek_tag(&b, "CMP ")) {
        odhs_network *net = st->net;
        tag(&b, "CMP ");
        uint64_t np = get_u64(&b);
        if (b.bad || np != net->nperm) FAIL(ODHS_E_FORMAT, "checkpoint: bad bond count");
        for (uint64_t q = 0; q < np; ++q) {
            uint64_t c = get_u64(&b);
            double rest = get_f64(&b);
            /* NaN: the bond's rest length is a_i + a_j (odhs_network_add) */
            if (b.bad || c >= net->nc || net->kind[c] != ODHS_CONTACT_PERMANENT ||
                (!isnan(rest) && (!(rest > 0.0) || !isfinite(rest))))
                FAIL(ODHS_E_FORMAT, "checkpoint: bad bond %llu", (unsigned long long)q);
            net->rest[c] = rest;
        }
        uint64_t has_rb = get_u64(&b);
        if (b.bad || has_rb > 1) FAIL(ODHS_E_FORMAT, "checkpoint: bad rigid-body flag");
        if (has_rb) {
            if (n > (b.len - b.pos) / 8) FAIL(ODHS_E_FORMAT, "checkpoint: truncated rigid-body labels");
            net->rbody = odhs__malloc_array(n, sizeof *net->rbody);
            if (!net->rbody) FAIL(ODHS_E_NOMEM, "checkpoint: out of memory");
            for (size_t i = 0; i < n; ++i) {
                uint64_t l = get_u64(&b);
                if (l != UINT64_MAX && l >= n) FAIL(ODHS_E_FORMAT, "checkpoint: bad rigid-body label");
                net->rbody[i] = l == UINT64_MAX ? SIZE_MAX : (size_t)l;
            }
        }
    }
    /* optional sections of version 2, each at most once, in any order */
    int drv_changed = 0;
    while (version >= 2 && b.pos < b.len && !b.bad) {
        char t4[4];
        get(&b, t4, 4);
        if (!memcmp(t4, "PROP", 4) && !drv->prop_on) {
            uint64_t pn = get_u64(&b), pdim = get_u64(&b);
            double fmin = get_f64(&b), fmax = get_f64(&b), tmin = get_f64(&b), tmax = get_f64(&b);
            uint64_t started = get_u64(&b);
            odhs_rng rng;
            for (int k = 0; k < 4; ++k) rng.s[k] = get_u64(&b);
            if (b.bad || (pdim != 2 && pdim != 3) || pn == 0 || pn > (b.len - b.pos) / 8 / (pdim + 1) ||
                started > 1 || !isfinite(fmin) || !isfinite(fmax) || !isfinite(tmin) || !isfinite(tmax) ||
                !(fmin >= 0.0) || !(fmax > 0.0) || fmin > fmax || !(tmin >= 0.0) || !(tmax > 0.0) || tmin > tmax ||
                (rng.s[0] | rng.s[1] | rng.s[2] | rng.s[3]) == 0)
                FAIL(ODHS_E_FORMAT, "checkpoint: self-propulsion section malformed");
            if (odhs__prop_alloc(drv, (size_t)pn, (int)pdim)) FAIL(ODHS_E_NOMEM, "checkpoint: out of memory");
            drv->pfmin = fmin;
            drv->pfmax = fmax;
            drv->ptmin = tmin;
            drv->ptmax = tmax;
            drv->prop_started = (int)started;
            drv->prng = rng;
            get_f64s(&b, drv->pF, (size_t)pn * (size_t)pdim);
            get_f64s(&b, drv->pts, (size_t)pn);
            if (b.bad || !finite_all(drv->pF, (size_t)pn * (size_t)pdim) || !finite_all(drv->pts, (size_t)pn))
                FAIL(ODHS_E_FORMAT, "checkpoint: bad self-propulsion state");
        } else if (!memcmp(t4, "GRAV", 4) && !drv->grav_on) {
            uint64_t gdim = get_u64(&b);
            double g[3];
            get_f64s(&b, g, 3);
            uint64_t nw = get_u64(&b);
            if (b.bad || (gdim != 2 && gdim != 3) || !finite_all(g, 3) || nw > (b.len - b.pos) / 8)
                FAIL(ODHS_E_FORMAT, "checkpoint: gravity section malformed");
            if ((s = odhs_driver_set_gravity(drv, (int)gdim, g))) FAIL(s, "checkpoint: %s", odhs_strerror(s));
            if (nw) {
                odhs__free(tmpF);
                tmpF = odhs__malloc_array((size_t)nw, sizeof *tmpF);
                if (!tmpF) FAIL(ODHS_E_NOMEM, "checkpoint: out of memory");
                get_f64s(&b, tmpF, (size_t)nw);
                if (b.bad || !finite_all(tmpF, (size_t)nw)) FAIL(ODHS_E_FORMAT, "checkpoint: bad gravity weights");
                if ((s = odhs_driver_set_gravity_weights(drv, (size_t)nw, tmpF)))
                    FAIL(s, "checkpoint: %s", odhs_strerror(s));
            }
        } else if (!memcmp(t4, "DRVC", 4) && !drv_changed) {
            if (get_u64(&b) != 1u || b.bad) FAIL(ODHS_E_FORMAT, "checkpoint: driver-change section malformed");
            drv_changed = 1;
        } else {
            FAIL(ODHS_E_FORMAT, "checkpoint: unknown or repeated section");
        }
    }
    if (b.pos != b.len) FAIL(ODHS_E_FORMAT, "checkpoint: unexpected trailing data");
    odhs__net_geometry(st->net, sys);
    st->has_F = 0;
    /* a contact is a pair at contact distance, up to the integrator's drift:
     * far-apart "contacts" act as rigid bonds and the drift correction would
     * move their particles into others (found by fuzz_checkpoint) */
    for (size_t c = 0; c < st->net->nc; ++c) {
        size_t i = st->net->ci[c], j = st->net->cj[c];
        double sig = odhs__net_sigma(st->net, sys, c); /* rest length of bonds, a_i for walls */
        if (!(fabs(st->net->gap[c]) <= CKPT_MAX_CONTACT_GAP * sig))
            FAIL(ODHS_E_FORMAT, "checkpoint: contact (%zu,%zu) has a gap of %.3g contact distances", i, j,
                 st->net->gap[c] / sig);
    }
    if (odhs__stepper_check_neighbours(st)) FAIL(ODHS_E_NOMEM, "checkpoint: out of memory");
    if (drv->F) {
        memcpy(st->F, drv->F, nd * sizeof *st->F);
        st->has_F = 1;
    }
    /* the forces as eval_forces computes them (a mismatch fails the next step) */
    odhs__driver_extra_forces(drv, sys, st->F, &st->has_F);
    /* a driver changed after the last solve is re-solved by the next step,
     * as it would have been without the checkpoint */
    st->drv_version = drv_changed ? drv->version - 1 : drv->version;
    st->ready = 1;
    odhs__free(tmpF);
    *sys_out = sys;
    *drv_out = drv;
    *st_out = st;
    return ODHS_OK;
fail:
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    odhs__free(tmpF);
    if (errbuf && errlen) snprintf(errbuf, errlen, "%s", msg);
    return status;
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
