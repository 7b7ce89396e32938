/* libodhs - jamming: the certificate of a jammed packing, recomputed from the
 * stepper's public state. */
#include <math.h>
#include <string.h>

#include "stepper/stepper.h"
/* ---- certificate ---------------------------------------------------------- */
typedef struct {
    const odhs_network *net;
    const double *r;
    double worst;
} cert_ov_ctx;

static int cert_ov_cb(size_t i, size_t j, const double *rij, double gap, void *vctx)
{
    (void)rij;
    cert_ov_ctx *c = vctx;
    if (odhs__net_find(c->net, i, j) != SIZE_MAX || odhs__same_body(c->net, i, j)) return 0;
    double rel = -gap / (c->r[i] + c->r[j]);
    if (rel > c->worst) c->worst = rel;
    return 0;
}

int odhs_stepper_certificate(const odhs_stepper *st, odhs_jam_certificate *cert)
{
    if (!st) return ODHS_E_NULL;
    char *msg = ((odhs_stepper *)st)->errmsg; /* logically mutable */
    if (!cert) return odhs__err(msg, ODHS_E_NULL, "certificate pointer is NULL");
    if (cert->size < sizeof(size_t))
        return odhs__err(msg, ODHS_E_INVALID, "certificate size %zu: set size = sizeof(odhs_jam_certificate)",
                         cert->size);
    const odhs_system *sys = st->sys;
    const odhs_network *net = st->net;
    odhs_jam_certificate c;
    memset(&c, 0, sizeof c);
    c.size = cert->size < sizeof c ? cert->size : sizeof c;
    int d = net->dim, s;
    size_t n = net->n, nd = n * (size_t)d;
    unsigned char *in = odhs__malloc_array(n, 1);
    double *F = odhs__calloc(nd, sizeof *F);
    if (!in || !F) {
        odhs__free(in);
        odhs__free(F);
        return ODHS_E_NOMEM;
    }
    size_t nbar = 0, ncon = 0;
    if ((s = odhs_network_constrained(net, &nbar, &ncon, in, NULL))) {
        odhs__free(in);
        odhs__free(F);
        return s;
    }
    c.jammed = st->jammed;
    c.n_pivots = (size_t)st->njam_pivots;
    odhs_system_packing_fraction(sys, &c.phi);
    c.n_particles = n;
    c.n_backbone = nbar;
    c.n_rattlers = n - nbar;
    c.n_contacts = net->nc;
    c.n_contacts_backbone = ncon;
    c.n_contacts_isostatic = nbar ? (size_t)d * (nbar - 1) + 1 : 0;
    c.isostatic = nbar > 0 && ncon == c.n_contacts_isostatic;
    c.z = 2.0 * (double)net->nc / (double)n;
    c.z_backbone = nbar ? 2.0 * (double)ncon / (double)nbar : 0.0;
    double vol, fr = 0.0, fsum = 0.0, fmin = INFINITY;
    odhs_system_volume(sys, &vol);
    for (size_t k = 0; k < net->nc; ++k) {
        fr += net->f[k] * net->dist[k];
        c.gap_error = fmax(c.gap_error, fabs(net->gap[k]) / odhs__net_sigma(net, sys, k));
        if (in[net->ci[k]] && (net->cj[k] >= n || in[net->cj[k]])) {
            fsum += net->f[k];
            /* bonds may carry any sign: the smallest force is over contacts */
            if (odhs__can_open(net->kind[k])) fmin = fmin < net->f[k] ? fmin : net->f[k];
        }
    }
    c.pressure = fr / (vol * d);
    double fmean = ncon ? fsum / (double)ncon : 1.0;
    c.min_force = ncon ? fmin / fmean : 0.0;
    odhs__net_ST(net, net->f, F);
    for (size_t i = 0; i < n; ++i) {
        if (!in[i]) continue;
        double s2 = 0.0;
        for (int a = 0; a < d; ++a) s2 += F[i * d + a] * F[i * d + a];
        c.force_balance = fmax(c.force_balance, sqrt(s2) / fabs(fmean));
    }
    cert_ov_ctx oc = {net, sys->r, 0.0};
    s = odhs__pairs(d, n, sys->x, sys->r, sys->rmax, sys->L, sys->gamma, 0.0, cert_ov_cb, &oc);
    c.overlap = oc.worst;
    odhs__free(in);
    odhs__free(F);
    if (s == ODHS_E_NOMEM) return s;
    memcpy(cert, &c, c.size);
    return ODHS_OK;
}

