/* libodhs - the stepper's checkpoint sections (include/odhs/checkpoint.h,
 * lib/io/ckpt.h): STP (settings, clock, counters, flow, velocities,
 * neighbour list) and NET (the contacts in their order, with forces). */
#include <math.h>
#include <string.h>

#include "io/ckpt.h"
#include "stepper/stepper.h"

void odhs__ckpt_write_stepper(odhs__wbuf *b, const odhs_stepper *st)
{
    odhs__put_tag(b, "STP ");
    odhs__put_f64(b, st->dt);
    odhs__put_u64(b, (uint64_t)st->integrator);
    odhs__put_f64(b, st->tol);
    odhs__put_f64(b, st->h);
    odhs__put_f64(b, st->lambda);
    odhs__put_u64(b, st->nrejected);
    odhs__put_u64(b, st->nsolves_pred);
    odhs__put_u64(b, st->corr_every);
    odhs__put_f64(b, st->contact_tol);
    odhs__put_f64(b, st->time);
    odhs__put_f64(b, st->strain);
    odhs__put_u64(b, st->nsteps);
    odhs__put_u64(b, st->ncoll);
    odhs__put_u64(b, st->nopen);
    odhs__put_f64(b, st->tau);
    odhs__put_f64s(b, st->G, 9);
    odhs__put_f64(b, st->kappa);
    odhs__put_u64(b, (uint64_t)st->jammed);
    odhs__put_f64s(b, st->U, st->nd);
    odhs__put_f64(b, st->skin);
    odhs__put_f64(b, st->rc);
    odhs__put_f64s(b, st->disp, st->nd);
    odhs__put_f64s(b, st->M, 9);
    odhs__put_u64(b, (uint64_t)st->nb_stale);
    odhs__put_u64(b, st->npairs);
    for (size_t p = 0; p < st->npairs; ++p) {
        odhs__put_u64(b, st->pi[p]);
        odhs__put_u64(b, st->pj[p]);
    }
}

/* the finite and positive values the setters accept */
static int check_stepper(odhs__ckpt_in *in, const odhs_stepper *st)
{
    const double sc[] = {st->dt,   st->tol,         st->h,    st->lambda, st->contact_tol, st->time,
                         st->strain, st->tau, st->kappa, st->skin,   st->rc};
    static const char *const scn[] = {"dt", "tol", "h", "lambda", "contact_tol", "time", "strain", "tau",
                                      "kappa", "skin", "rc"};
    for (size_t k = 0; k < sizeof sc / sizeof sc[0]; ++k)
        if (!isfinite(sc[k])) return odhs__ckpt_bad(in, "checkpoint: stepper value %s is not finite", scn[k]);
    size_t nd = st->nd;
    if (!odhs__finite_all(st->G, 9) || !odhs__finite_all(st->M, 9) || !odhs__finite_all(st->U, nd) ||
        !odhs__finite_all(st->disp, nd))
        return odhs__ckpt_bad(in, "checkpoint: non-finite number in the stepper section (%s)",
                              !odhs__finite_all(st->G, 9)    ? "velocity gradient"
                              : !odhs__finite_all(st->M, 9)  ? "cell matrix"
                              : !odhs__finite_all(st->U, nd) ? "velocities"
                                                             : "displacements");
    /* the shapes the stepper makes (odhs__flow_gradient, odhs__st_advance):
     * G = gdot e_x e_y^T - c (I on the dim axes), and the cell matrix a
     * product of (I + t G), so m (I on the dim axes) + b e_x e_y^T, with
     * m > 0 and 1 on an unused third axis. A file with anything else would
     * step with it (a 2D file with G_xz = -8e298: fuzz_checkpoint). */
    const int dim = st->dim;
    for (int a = 0; a < 3; ++a)
        for (int c = 0; c < 3; ++c) {
            const int k = 3 * a + c, diag = a == c && a < dim;
            if (a == 0 && c == 1) continue; /* the shear entry: any value */
            const char *bad = st->G[k] != (diag ? st->G[0] : 0.0)               ? "velocity gradient"
                              : st->M[k] != (diag ? st->M[0] : a == c ? 1.0 : 0.0) ? "cell matrix"
                                                                                  : NULL;
            if (bad) return odhs__ckpt_bad(in, "checkpoint: the stepper's %s has a foreign entry (%d,%d)", bad, a, c);
        }
    if (!(st->M[0] > 0.0)) return odhs__ckpt_bad(in, "checkpoint: the stepper's cell matrix is not positive");
    if (!(st->dt > 0) || !(st->tol > 0 && st->tol < 1) || !(st->h > 0) || !(st->tau > 0) || !(st->lambda > 0) ||
        !(st->skin > 0) || st->contact_tol < 0)
        return odhs__ckpt_bad(
            in, "checkpoint: invalid stepper values (dt %g, tol %g, h %g, tau %g, lambda %g, skin %g, contact_tol %g)",
            st->dt, st->tol, st->h, st->tau, st->lambda, st->skin, st->contact_tol);
    return ODHS_OK;
}

/* the neighbour list: npairs pairs i < j < n */
static int read_pairs(odhs__ckpt_in *in, odhs_stepper *st, uint64_t npairs)
{
    st->pflag_state = 0; /* new pairs (also if they fail): the contact flags are built anew */
    if (npairs) {
        size_t *a = odhs__realloc(st->pi, (size_t)npairs * sizeof *a);
        if (a) st->pi = a;
        size_t *c = odhs__realloc(st->pj, (size_t)npairs * sizeof *c);
        if (c) st->pj = c;
        if (!a || !c) return odhs__ckpt_nomem(in);
        st->pcap = (size_t)npairs;
    }
    for (size_t q = 0; q < npairs; ++q) {
        uint64_t i = odhs__get_u64(&in->b), j = odhs__get_u64(&in->b);
        if (in->b.bad || i >= j || j >= st->n) return odhs__ckpt_bad(in, "checkpoint: bad neighbour pair");
        st->pi[q] = (size_t)i;
        st->pj[q] = (size_t)j;
    }
    st->npairs = (size_t)npairs;
    return ODHS_OK;
}

int odhs__ckpt_read_stepper(odhs__ckpt_in *in)
{
    odhs__rbuf *b = &in->b;
    if (odhs__get_tag(b, "STP ")) return odhs__ckpt_bad(in, "checkpoint: stepper section missing");
    int s = odhs_stepper_create(in->sys, in->drv, in->solver, &in->st);
    if (s) return odhs__ckpt_status(in, s);
    odhs_stepper *st = in->st;
    st->dt = odhs__get_f64(b);
    uint64_t integ = odhs__get_u64(b);
    st->tol = odhs__get_f64(b);
    st->h = odhs__get_f64(b);
    st->lambda = odhs__get_f64(b);
    st->nrejected = odhs__get_u64(b);
    st->nsolves_pred = odhs__get_u64(b);
    uint64_t corr = odhs__get_u64(b);
    st->contact_tol = odhs__get_f64(b);
    st->time = odhs__get_f64(b);
    st->strain = odhs__get_f64(b);
    st->nsteps = odhs__get_u64(b);
    st->ncoll = odhs__get_u64(b);
    st->nopen = odhs__get_u64(b);
    st->tau = odhs__get_f64(b);
    odhs__get_f64s(b, st->G, 9);
    st->kappa = odhs__get_f64(b);
    uint64_t jam = odhs__get_u64(b);
    odhs__get_f64s(b, st->U, st->nd);
    st->skin = odhs__get_f64(b);
    st->rc = odhs__get_f64(b);
    odhs__get_f64s(b, st->disp, st->nd);
    odhs__get_f64s(b, st->M, 9);
    uint64_t stale = odhs__get_u64(b);
    uint64_t npairs = odhs__get_u64(b);
    if (b->bad || integ > ODHS_INTEGRATOR_BATCHED || corr > 0xffffffffu || jam > 1 || stale > 1 ||
        npairs > (b->len - b->pos) / 16)
        return odhs__ckpt_bad(in, "checkpoint: stepper section malformed");
    st->integrator = (int)integ;
    st->corr_every = (unsigned)corr;
    st->corr_user = 1; /* the file's interval is kept by set_integrator */
    st->tol_user = 1;  /* and so are its tolerance */
    st->dt_user = 1;   /* and dt */
    st->jammed = (int)jam;
    st->nb_stale = (int)stale;
    if ((s = check_stepper(in, st))) return s;
    return read_pairs(in, st, npairs);
}

void odhs__ckpt_write_network(odhs__wbuf *b, const odhs_network *net)
{
    odhs__put_tag(b, "NET ");
    odhs__put_u64(b, net->nc);
    for (size_t c = 0; c < net->nc; ++c) {
        odhs__put_u64(b, net->ci[c]);
        odhs__put_u64(b, net->cj[c]);
        odhs__put_u64(b, (uint64_t)net->kind[c]);
        odhs__put_f64(b, net->f[c]);
    }
}

int odhs__ckpt_read_network(odhs__ckpt_in *in)
{
    odhs__rbuf *b = &in->b;
    odhs_network *net = in->st->net;
    size_t n = net->n;
    if (odhs__get_tag(b, "NET ")) return odhs__ckpt_bad(in, "checkpoint: network section missing");
    uint64_t nc = odhs__get_u64(b);
    if (b->bad || nc > (b->len - b->pos) / 32) return odhs__ckpt_bad(in, "checkpoint: bad contact count");
    for (size_t c = 0; c < nc; ++c) {
        uint64_t i = odhs__get_u64(b), j = odhs__get_u64(b), kind = odhs__get_u64(b);
        double f = odhs__get_f64(b);
        int wall = j >= n;
        if (b->bad || i >= j || i >= n || j >= n + net->nwalls || kind > ODHS_CONTACT_WALL ||
            (kind == ODHS_CONTACT_WALL) != wall || !isfinite(f))
            return odhs__ckpt_bad(in, "checkpoint: bad contact %zu", c);
        if (odhs__net_find(net, (size_t)i, (size_t)j) != SIZE_MAX)
            return odhs__ckpt_bad(in, "checkpoint: duplicate contact (%llu,%llu)", (unsigned long long)i,
                                  (unsigned long long)j);
        size_t k = odhs__net_add(net, (size_t)i, (size_t)j, (int)kind);
        if (k == SIZE_MAX) return odhs__ckpt_nomem(in);
        net->f[k] = f;
    }
    return ODHS_OK;
}

/* no optional sections of the stepper after the contacts yet (lib/io/ckpt.h) */
unsigned odhs__ckpt_write_stepper_tail(odhs__wbuf *b, const odhs__ckpt_out *o) { (void)b, (void)o; return 1; }
int odhs__ckpt_read_stepper_tail(odhs__ckpt_in *in, const char *tag) { (void)in, (void)tag; return 0; }
