/* libodhs - I/O: the contacts file of a network, as text with image shifts
 * (odhs_contacts_write) or as CSV (odhs_contacts_write_csv). */
#include <stdio.h>
#include <string.h>

#include "io/text.h"
#include "network/network.h"

typedef struct {
    const odhs_network *net;
    const odhs_system *sys;
} body_in;

static int body_text(FILE *f, const void *ctx)
{
    const odhs_network *net = ((const body_in *)ctx)->net;
    const odhs_system *sys = ((const body_in *)ctx)->sys;
    int d = net->dim, ok = 1;
    ok &= fprintf(f, "# libodhs contacts N=%zu dim=%d Nc=%zu\n", net->n, d, net->nc) > 0;
    ok &= fprintf(f, "# i j %s force gap\n", d == 2 ? "s0 s1" : "s0 s1 s2") > 0;
    for (size_t c = 0; c < net->nc && ok; ++c) {
        size_t i = net->ci[c], j = net->cj[c];
        double v[3] = {0, 0, 0};
        int img[3] = {0, 0, 0};
        if (j < net->n) { /* walls (j = N + w) have no image shift */
            for (int a = 0; a < d; ++a) v[a] = sys->x[j * d + a] - sys->x[i * d + a];
            odhs__min_image(d, sys->L, sys->gamma, v, img);
        }
        if (d == 2)
            ok &= fprintf(f, "%zu %zu %d %d %.17g %.17g\n", i, j, img[0], img[1], net->f[c], net->gap[c]) > 0;
        else
            ok &= fprintf(f, "%zu %zu %d %d %d %.17g %.17g\n", i, j, img[0], img[1], img[2], net->f[c],
                          net->gap[c]) > 0;
    }
    return ok ? 0 : -1;
}

static int body_csv(FILE *f, const void *ctx)
{
    const odhs_network *net = ((const body_in *)ctx)->net;
    int ok = fprintf(f, "i,j,kind,force,gap\n") > 0;
    for (size_t c = 0; c < net->nc && ok; ++c)
        ok &= fprintf(f, "%zu,%zu,%d,%.17g,%.17g\n", net->ci[c], net->cj[c], (int)net->kind[c], net->f[c],
                      net->gap[c]) > 0;
    return ok ? 0 : -1;
}

/* the checks, then body into a temporary file renamed to path */
static int write_file(const odhs_network *net, const odhs_system *sys, const char *path, odhs__body_fn body)
{
    if (!net) return ODHS_E_NULL;
    if (!sys || !path) return odhs__neterr(net, ODHS_E_NULL, "NULL argument");
    if (sys->n != net->n || sys->dim != net->dim)
        return odhs__neterr(net, ODHS_E_DIM, "system and network differ in N or dimension");
    if (!sys->has_x || !sys->has_r) return odhs__neterr(net, ODHS_E_STATE, "system radii and positions unset");
    body_in in = {net, sys};
    char msg[ODHS_ERRMSG_LEN];
    int st = odhs__write_atomic(path, body, &in, msg);
    return st < 0 ? odhs__neterr(net, st, "%s", msg) : ODHS_OK;
}

int odhs_contacts_write(const odhs_network *net, const odhs_system *sys, const char *path)
{
    return write_file(net, sys, path, body_text);
}

int odhs_contacts_write_csv(const odhs_network *net, const odhs_system *sys, const char *path)
{
    return write_file(net, sys, path, body_csv);
}
