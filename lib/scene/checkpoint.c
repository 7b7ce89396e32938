/* libodhs - the scene's checkpoint sections (include/odhs/checkpoint.h,
 * lib/io/ckpt.h): WAL (hard walls, before the contacts that refer to them)
 * and CMP (rest lengths of the bonds, rigid-body labels, after them). */
#include <math.h>
#include <string.h>

#include "io/ckpt.h"
#include "stepper/stepper.h"

unsigned odhs__ckpt_write_walls(odhs__wbuf *b, const odhs_network *net)
{
    if (!net->nwalls) return 1;
    odhs__put_tag(b, "WAL ");
    odhs__put_u64(b, net->nwalls);
    for (size_t w = 0; w < net->nwalls; ++w) {
        const odhs_wall *wl = &net->walls[w];
        odhs__put_u64(b, (uint64_t)wl->type);
        odhs__put_f64s(b, wl->n, 3);
        odhs__put_f64(b, wl->h);
        odhs__put_f64s(b, wl->c, 3);
        odhs__put_f64s(b, wl->b, 3);
        odhs__put_f64(b, wl->R);
        odhs__put_f64s(b, wl->v, 3);
        odhs__put_f64s(b, wl->disp, 3);
    }
    return 2;
}

int odhs__ckpt_read_walls(odhs__ckpt_in *in)
{
    odhs__rbuf *b = &in->b;
    if (!odhs__peek_tag(b, "WAL ")) return ODHS_OK;
    odhs__get_tag(b, "WAL ");
    uint64_t nw = odhs__get_u64(b);
    if (b->bad || nw > (b->len - b->pos) / 8) return odhs__ckpt_bad(in, "checkpoint: bad wall count");
    for (uint64_t w = 0; w < nw; ++w) {
        odhs_wall wl;
        memset(&wl, 0, sizeof wl);
        uint64_t type = odhs__get_u64(b);
        odhs__get_f64s(b, wl.n, 3);
        wl.h = odhs__get_f64(b);
        odhs__get_f64s(b, wl.c, 3);
        odhs__get_f64s(b, wl.b, 3);
        wl.R = odhs__get_f64(b);
        odhs__get_f64s(b, wl.v, 3);
        odhs__get_f64s(b, wl.disp, 3);
        if (b->bad || type > ODHS_WALL_SEGMENT || !odhs__finite_all(wl.n, 3) || !isfinite(wl.h) ||
            !odhs__finite_all(wl.c, 3) || !odhs__finite_all(wl.b, 3) || !isfinite(wl.R) ||
            !odhs__finite_all(wl.v, 3) || !odhs__finite_all(wl.disp, 3) ||
            (type == ODHS_WALL_SPHERE && !(wl.R > 0.0)) || (type == ODHS_WALL_SEGMENT && in->sys->dim != 2))
            return odhs__ckpt_bad(in, "checkpoint: bad wall %llu", (unsigned long long)w);
        wl.type = (int)type;
        if (odhs__net_add_wall(in->st->net, &wl)) return odhs__ckpt_nomem(in);
    }
    return ODHS_OK;
}

unsigned odhs__ckpt_write_composites(odhs__wbuf *b, const odhs_network *net)
{
    if (!net->nperm && !net->rbody) return 1;
    odhs__put_tag(b, "CMP ");
    odhs__put_u64(b, net->nperm);
    for (size_t c = 0; c < net->nc; ++c)
        if (net->kind[c] == ODHS_CONTACT_PERMANENT) {
            odhs__put_u64(b, c);
            odhs__put_f64(b, net->rest[c]);
        }
    odhs__put_u64(b, net->rbody ? 1u : 0u);
    if (net->rbody)
        for (size_t i = 0; i < net->n; ++i)
            odhs__put_u64(b, net->rbody[i] == SIZE_MAX ? UINT64_MAX : net->rbody[i]);
    return 2;
}

static int read_bodies(odhs__ckpt_in *in, odhs_network *net)
{
    odhs__rbuf *b = &in->b;
    size_t n = net->n;
    uint64_t has_rb = odhs__get_u64(b);
    if (b->bad || has_rb > 1) return odhs__ckpt_bad(in, "checkpoint: bad rigid-body flag");
    if (!has_rb) return ODHS_OK;
    if (n > (b->len - b->pos) / 8) return odhs__ckpt_bad(in, "checkpoint: truncated rigid-body labels");
    net->rbody = odhs__malloc_array(n, sizeof *net->rbody);
    if (!net->rbody) return odhs__ckpt_nomem(in);
    for (size_t i = 0; i < n; ++i) {
        uint64_t l = odhs__get_u64(b);
        if (l != UINT64_MAX && l >= n) return odhs__ckpt_bad(in, "checkpoint: bad rigid-body label");
        net->rbody[i] = l == UINT64_MAX ? SIZE_MAX : (size_t)l;
    }
    return ODHS_OK;
}

int odhs__ckpt_read_composites(odhs__ckpt_in *in)
{
    odhs__rbuf *b = &in->b;
    odhs_network *net = in->st->net;
    if (!odhs__peek_tag(b, "CMP ")) return ODHS_OK;
    odhs__get_tag(b, "CMP ");
    uint64_t np = odhs__get_u64(b);
    if (b->bad || np != net->nperm) return odhs__ckpt_bad(in, "checkpoint: bad bond count");
    for (uint64_t q = 0; q < np; ++q) {
        uint64_t c = odhs__get_u64(b);
        double rest = odhs__get_f64(b);
        /* NaN: the bond's rest length is a_i + a_j (odhs_network_add) */
        if (b->bad || c >= net->nc || net->kind[c] != ODHS_CONTACT_PERMANENT ||
            (!isnan(rest) && (!(rest > 0.0) || !isfinite(rest))))
            return odhs__ckpt_bad(in, "checkpoint: bad bond %llu", (unsigned long long)q);
        net->rest[c] = rest;
    }
    return read_bodies(in, net);
}

/* no optional sections of the scene after the contacts yet (lib/io/ckpt.h) */
unsigned odhs__ckpt_write_scene_tail(odhs__wbuf *b, const odhs__ckpt_out *o) { (void)b, (void)o; return 1; }
int odhs__ckpt_read_scene_tail(odhs__ckpt_in *in, const char *tag) { (void)in, (void)tag; return 0; }
