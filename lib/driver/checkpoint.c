/* libodhs - the driver's checkpoint sections (include/odhs/checkpoint.h,
 * lib/io/ckpt.h): DRV (flow, pressure, fixed forces), and after the contacts
 * the optional PROP (self-propulsion), GRAV (gravity), DRVC (the driver
 * changed after the forces were solved), OSC (oscillatory shear), PJAM
 * (a finite jamming pressure) and FCB (a force callback was set: since 0.2.7).
 *
 * A new optional section of the driver: write it in
 * odhs__ckpt_write_driver_tail (returning 2, the format version it needs) and
 * add its tag and reader to `tail` below. */
#include <math.h>
#include <string.h>

#include "driver/driver.h"
#include "io/ckpt.h"

void odhs__ckpt_write_driver(odhs__wbuf *b, const odhs_driver *drv, const odhs_system *sys)
{
    odhs__put_tag(b, "DRV ");
    odhs__put_f64(b, drv->xi0);
    odhs__put_f64(b, drv->gdot);
    odhs__put_f64(b, drv->crate);
    odhs__put_u64(b, (uint64_t)drv->pressure_on);
    odhs__put_f64(b, drv->p);
    odhs__put_f64(b, drv->kappa_max);
    odhs__put_f64(b, drv->tau_user);
    odhs__put_u64(b, drv->F ? 1u : 0u);
    if (drv->F) odhs__put_f64s(b, drv->F, sys->n * (size_t)sys->dim); /* as many as the reader takes */
}

/* n finite doubles from the buffer into *out (allocated; NULL on error) */
static int read_array(odhs__ckpt_in *in, size_t n, double **out, const char *what)
{
    *out = odhs__malloc_array(n, sizeof **out);
    if (!*out) return odhs__ckpt_nomem(in);
    odhs__get_f64s(&in->b, *out, n);
    if (!in->b.bad && odhs__finite_all(*out, n)) return ODHS_OK;
    odhs__free(*out);
    *out = NULL;
    return odhs__ckpt_bad(in, "checkpoint: bad %s", what);
}

int odhs__ckpt_read_driver(odhs__ckpt_in *in)
{
    odhs__rbuf *b = &in->b;
    if (odhs__get_tag(b, "DRV ")) return odhs__ckpt_bad(in, "checkpoint: driver section missing");
    int s = odhs_driver_create(&in->drv);
    if (s) return odhs__ckpt_status(in, s);
    odhs_driver *drv = in->drv;
    drv->xi0 = odhs__get_f64(b);
    drv->gdot = odhs__get_f64(b);
    drv->crate = odhs__get_f64(b);
    uint64_t pon = odhs__get_u64(b);
    drv->p = odhs__get_f64(b);
    drv->kappa_max = odhs__get_f64(b);
    drv->tau_user = odhs__get_f64(b);
    uint64_t hasF = odhs__get_u64(b);
    if (b->bad || pon > 1 || hasF > 1) return odhs__ckpt_bad(in, "checkpoint: driver section malformed");
    drv->pressure_on = (int)pon;
    if (!(drv->xi0 > 0.0) || !isfinite(drv->xi0) || !isfinite(drv->gdot) || !isfinite(drv->crate) ||
        !isfinite(drv->p) || !(drv->kappa_max > 0.0) || !isfinite(drv->kappa_max) || !isfinite(drv->tau_user) ||
        drv->tau_user < 0.0 || (pon && !(drv->p > 0.0)))
        return odhs__ckpt_bad(in, "checkpoint: invalid driver settings");
    if (!hasF) return ODHS_OK;
    size_t n = in->sys->n;
    int dim = in->sys->dim;
    double *F;
    if ((s = read_array(in, n * (size_t)dim, &F, "driver forces"))) return s;
    s = odhs_driver_set_forces(drv, n, dim, F);
    odhs__free(F);
    return s ? odhs__ckpt_status(in, s) : ODHS_OK;
}

/* ---- optional sections --------------------------------------------------- */
unsigned odhs__ckpt_write_driver_tail(odhs__wbuf *b, const odhs__ckpt_out *o)
{
    const odhs_driver *drv = o->drv;
    if (drv->prop_on) {
        odhs__put_tag(b, "PROP");
        odhs__put_u64(b, drv->pn);
        odhs__put_u64(b, (uint64_t)drv->pdim);
        odhs__put_f64(b, drv->pfmin);
        odhs__put_f64(b, drv->pfmax);
        odhs__put_f64(b, drv->ptmin);
        odhs__put_f64(b, drv->ptmax);
        odhs__put_u64(b, (uint64_t)drv->prop_started);
        for (int k = 0; k < 4; ++k) odhs__put_u64(b, drv->prng.s[k]);
        odhs__put_f64s(b, drv->pF, drv->pn * (size_t)drv->pdim);
        odhs__put_f64s(b, drv->pts, drv->pn);
    }
    if (drv->grav_on) {
        odhs__put_tag(b, "GRAV");
        odhs__put_u64(b, (uint64_t)drv->gdim);
        odhs__put_f64s(b, drv->g, 3);
        odhs__put_u64(b, drv->gw ? drv->gwn : 0u);
        if (drv->gw) odhs__put_f64s(b, drv->gw, drv->gwn);
    }
    if (o->drv_stale) {
        odhs__put_tag(b, "DRVC");
        odhs__put_u64(b, 1u);
    }
    if (drv->osc_shape) {
        odhs__put_tag(b, "OSC ");
        odhs__put_u64(b, (uint64_t)drv->osc_shape);
        odhs__put_f64(b, drv->osc_amp);
        odhs__put_f64(b, drv->osc_period);
        odhs__put_f64(b, drv->osc_t0);
    }
    int pjam = !isinf(drv->p_jam); /* the default +INFINITY writes nothing */
    if (pjam) {
        odhs__put_tag(b, "PJAM");
        odhs__put_f64(b, drv->p_jam);
    }
    /* a force callback is code: it is not saved, but that it was set is, so
     * that the restored stepper cannot continue silently without it */
    if (drv->fn || drv->fn_missing) {
        odhs__put_tag(b, "FCB ");
        odhs__put_u64(b, 1u);
    }
    return drv->prop_on || drv->grav_on || o->drv_stale || drv->osc_shape || pjam || drv->fn || drv->fn_missing ? 2u
                                                                                                                 : 1u;
}

/* the readers of the optional sections: 1 read, 0 read before, or an error */
static int read_prop(odhs__ckpt_in *in)
{
    odhs__rbuf *b = &in->b;
    odhs_driver *drv = in->drv;
    if (drv->prop_on) return 0;
    uint64_t pn = odhs__get_u64(b), pdim = odhs__get_u64(b);
    double fmin = odhs__get_f64(b), fmax = odhs__get_f64(b), tmin = odhs__get_f64(b), tmax = odhs__get_f64(b);
    uint64_t started = odhs__get_u64(b);
    odhs_rng rng;
    for (int k = 0; k < 4; ++k) rng.s[k] = odhs__get_u64(b);
    if (b->bad || (pdim != 2 && pdim != 3) || pn == 0 || pn > (b->len - b->pos) / 8 / (pdim + 1) || started > 1 ||
        !isfinite(fmin) || !isfinite(fmax) || !isfinite(tmin) || !isfinite(tmax) || !(fmin >= 0.0) ||
        !(fmax > 0.0) || fmin > fmax || !(tmin >= 0.0) || !(tmax > 0.0) || tmin > tmax ||
        (rng.s[0] | rng.s[1] | rng.s[2] | rng.s[3]) == 0)
        return odhs__ckpt_bad(in, "checkpoint: self-propulsion section malformed");
    if (odhs__prop_alloc(drv, (size_t)pn, (int)pdim)) return odhs__ckpt_nomem(in);
    drv->pfmin = fmin;
    drv->pfmax = fmax;
    drv->ptmin = tmin;
    drv->ptmax = tmax;
    drv->prop_started = (int)started;
    drv->prng = rng;
    size_t npf = (size_t)pn * (size_t)pdim;
    odhs__get_f64s(b, drv->pF, npf);
    odhs__get_f64s(b, drv->pts, (size_t)pn);
    if (b->bad || !odhs__finite_all(drv->pF, npf) || !odhs__finite_all(drv->pts, (size_t)pn))
        return odhs__ckpt_bad(in, "checkpoint: bad self-propulsion state");
    return 1;
}

static int read_grav(odhs__ckpt_in *in)
{
    odhs__rbuf *b = &in->b;
    odhs_driver *drv = in->drv;
    if (drv->grav_on) return 0;
    uint64_t gdim = odhs__get_u64(b);
    double g[3];
    odhs__get_f64s(b, g, 3);
    uint64_t nw = odhs__get_u64(b);
    if (b->bad || (gdim != 2 && gdim != 3) || !odhs__finite_all(g, 3) || nw > (b->len - b->pos) / 8)
        return odhs__ckpt_bad(in, "checkpoint: gravity section malformed");
    int s = odhs_driver_set_gravity(drv, (int)gdim, g);
    if (s) return odhs__ckpt_status(in, s);
    if (!nw) return 1;
    double *w;
    if ((s = read_array(in, (size_t)nw, &w, "gravity weights"))) return s;
    s = odhs_driver_set_gravity_weights(drv, (size_t)nw, w);
    odhs__free(w);
    return s ? odhs__ckpt_status(in, s) : 1;
}

static int read_drvc(odhs__ckpt_in *in)
{
    if (in->drv_changed) return 0;
    if (odhs__get_u64(&in->b) != 1u || in->b.bad)
        return odhs__ckpt_bad(in, "checkpoint: driver-change section malformed");
    in->drv_changed = 1;
    return 1;
}

/* oscillatory shear: the settings as odhs_driver_set_oscillatory_shear
 * checks them; the peak rate is DRV's shear rate */
static int read_osc(odhs__ckpt_in *in)
{
    odhs__rbuf *b = &in->b;
    odhs_driver *drv = in->drv;
    if (drv->osc_shape) return 0;
    uint64_t shape = odhs__get_u64(b);
    double amp = odhs__get_f64(b), period = odhs__get_f64(b), t0 = odhs__get_f64(b);
    if (b->bad || (shape != ODHS_OSCILLATION_SINE && shape != ODHS_OSCILLATION_TRIANGLE) || !isfinite(amp) ||
        !isfinite(period) || !isfinite(t0) || !(amp > 0.0) || !(period > 0.0) || !(drv->gdot > 0.0))
        return odhs__ckpt_bad(in, "checkpoint: oscillatory shear section malformed");
    drv->osc_shape = (int)shape;
    drv->osc_amp = amp;
    drv->osc_period = period;
    drv->osc_t0 = t0;
    return 1;
}

/* the jamming pressure: >= 0 and finite (the default, +INFINITY, is not
 * written) */
static int read_pjam(odhs__ckpt_in *in)
{
    odhs_driver *drv = in->drv;
    if (!isinf(drv->p_jam)) return 0;
    double pj = odhs__get_f64(&in->b);
    if (in->b.bad || !isfinite(pj) || !(pj >= 0.0))
        return odhs__ckpt_bad(in, "checkpoint: jamming pressure section malformed");
    drv->p_jam = pj;
    return 1;
}

/* the run had a force callback: the restored driver needs it set again */
static int read_fcb(odhs__ckpt_in *in)
{
    if (in->drv->fn_missing) return 0;
    if (odhs__get_u64(&in->b) != 1u || in->b.bad)
        return odhs__ckpt_bad(in, "checkpoint: force-callback section malformed");
    in->drv->fn_missing = 1;
    return 1;
}

static const struct {
    char tag[5];
    int (*read)(odhs__ckpt_in *in);
} tail[] = {{"PROP", read_prop}, {"GRAV", read_grav}, {"DRVC", read_drvc}, {"OSC ", read_osc}, {"PJAM", read_pjam},
          {"FCB ", read_fcb}};

int odhs__ckpt_read_driver_tail(odhs__ckpt_in *in, const char *tag)
{
    for (size_t k = 0; k < sizeof tail / sizeof tail[0]; ++k)
        if (!memcmp(tag, tail[k].tag, 4)) return tail[k].read(in);
    return 0;
}
