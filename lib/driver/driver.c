/* libodhs - drivers: affine flow (shear, compression, fixed pressure), forces. */
#include <float.h>
#include <math.h>
#include <string.h>

#include "driver/driver.h"

int odhs__drverr(const odhs_driver *d, int status, const char *fmt, ...)
{
    if (!d) return status;
    va_list ap;
    va_start(ap, fmt);
    odhs__verr(((odhs_driver *)d)->errmsg, status, fmt, ap);
    va_end(ap);
    return status;
}

static double prop_f2(const odhs_driver *d);
static double grav_weight(const odhs_driver *d, const odhs_system *sys, size_t i, double amean);

static int driver_create_impl(odhs_driver **out)
{
    if (!out) return odhs__create_err(ODHS_E_NULL, "odhs_driver_create: out is NULL");
    odhs_driver *d = odhs__calloc(1, sizeof *d);
    *out = d;
    if (!d) return odhs__create_err(ODHS_E_NOMEM, "odhs_driver_create: out of memory");
    d->xi0 = 1.0;
    d->kappa_max = 100.0;
    d->p_jam = INFINITY;
    return ODHS_OK;
}

int odhs_driver_create(odhs_driver **out)
{
    odhs__create_begin();
    return odhs__create_end(driver_create_impl(out));
}

void odhs_driver_destroy(odhs_driver *drv)
{
    if (!drv) return;
    odhs__free(drv->F);
    odhs__free(drv->pF);
    odhs__free(drv->pts);
    odhs__free(drv->pF_b);
    odhs__free(drv->pts_b);
    odhs__free(drv->gw);
    odhs__free(drv);
}

const char *odhs_driver_errmsg(const odhs_driver *drv) { return drv ? drv->errmsg : ""; }

int odhs_driver_set_mobility(odhs_driver *drv, double xi0)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(xi0)) return odhs__drverr(drv, ODHS_E_NONFINITE, "mobility is not finite");
    if (!(xi0 > 0.0)) return odhs__drverr(drv, ODHS_E_INVALID, "mobility %g must be > 0", xi0);
    drv->xi0 = xi0;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_shear_rate(odhs_driver *drv, double gammadot)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(gammadot)) return odhs__drverr(drv, ODHS_E_NONFINITE, "shear rate is not finite");
    drv->gdot = gammadot;
    drv->osc_shape = 0; /* a constant rate replaces an oscillation */
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_compression_rate(odhs_driver *drv, double c)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(c)) return odhs__drverr(drv, ODHS_E_NONFINITE, "compression rate is not finite");
    drv->crate = c;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_pressure(odhs_driver *drv, double p)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(p)) return odhs__drverr(drv, ODHS_E_NONFINITE, "pressure is not finite");
    if (!(p > 0.0)) return odhs__drverr(drv, ODHS_E_INVALID, "pressure %g must be > 0", p);
    drv->p = p;
    drv->pressure_on = 1;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_clear_pressure(odhs_driver *drv)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    drv->pressure_on = 0;
    drv->p = 0.0;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_kappa_max(odhs_driver *drv, double kappa_max)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(kappa_max)) return odhs__drverr(drv, ODHS_E_NONFINITE, "kappa_max is not finite");
    if (!(kappa_max > 0.0)) return odhs__drverr(drv, ODHS_E_INVALID, "kappa_max must be > 0");
    drv->kappa_max = kappa_max;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_jamming_pressure(odhs_driver *drv, double p_jam)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (isnan(p_jam)) return odhs__drverr(drv, ODHS_E_NONFINITE, "jamming pressure is NaN");
    if (!(p_jam >= 0.0)) return odhs__drverr(drv, ODHS_E_INVALID, "jamming pressure must be >= 0");
    drv->p_jam = p_jam;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_get_jamming_pressure(const odhs_driver *drv, double *p_jam)
{
    if (!drv) return ODHS_E_NULL;
    if (!p_jam) return odhs__drverr(drv, ODHS_E_NULL, "NULL argument");
    *p_jam = drv->p_jam;
    return ODHS_OK;
}

int odhs_driver_set_forces(odhs_driver *drv, size_t n, int dim, const double *F)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!F) {
        odhs__free(drv->F);
        drv->F = NULL;
        drv->Fn = 0;
        drv->version++;
        return ODHS_OK;
    }
    if (dim != 2 && dim != 3) return odhs__drverr(drv, ODHS_E_DIM, "dimension %d must be 2 or 3", dim);
    if (n == 0) return odhs__drverr(drv, ODHS_E_EMPTY, "no particles");
    size_t nd = n * (size_t)dim;
    for (size_t k = 0; k < nd; ++k)
        if (!isfinite(F[k])) return odhs__drverr(drv, ODHS_E_NONFINITE, "force component %zu is not finite", k);
    double *c = odhs__malloc_array(nd, sizeof *c);
    if (!c) return odhs__drverr(drv, ODHS_E_NOMEM, "out of memory");
    memcpy(c, F, nd * sizeof *c);
    odhs__free(drv->F);
    drv->F = c;
    drv->Fn = n;
    drv->Fdim = dim;
    drv->fn = NULL;
    drv->fn_ctx = NULL;
    drv->fn_missing = 0; /* fixed forces replace the callback of a checkpoint */
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_force_callback(odhs_driver *drv, odhs_force_fn fn, void *ctx)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    drv->fn = fn;
    drv->fn_ctx = fn ? ctx : NULL;
    drv->fn_missing = 0; /* set (or explicitly removed) after a checkpoint */
    if (fn) {
        odhs__free(drv->F);
        drv->F = NULL;
        drv->Fn = 0;
    }
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_time_unit(odhs_driver *drv, double tau)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(tau)) return odhs__drverr(drv, ODHS_E_NONFINITE, "time unit is not finite");
    if (!(tau > 0.0)) return odhs__drverr(drv, ODHS_E_INVALID, "time unit must be > 0");
    drv->tau_user = tau;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_clear_time_unit(odhs_driver *drv)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (drv->tau_user != 0.0) drv->version++;
    drv->tau_user = 0.0;
    return ODHS_OK;
}



int odhs_driver_get_shear_rate(const odhs_driver *drv, double *g)
{
    if (!drv) return ODHS_E_NULL;
    if (!g) return odhs__drverr(drv, ODHS_E_NULL, "output pointer is NULL");
    *g = drv->gdot;
    return ODHS_OK;
}

int odhs_driver_get_compression_rate(const odhs_driver *drv, double *c)
{
    if (!drv) return ODHS_E_NULL;
    if (!c) return odhs__drverr(drv, ODHS_E_NULL, "output pointer is NULL");
    *c = drv->crate;
    return ODHS_OK;
}

int odhs_driver_get_mobility(const odhs_driver *drv, double *xi0)
{
    if (!drv) return ODHS_E_NULL;
    if (!xi0) return odhs__drverr(drv, ODHS_E_NULL, "output pointer is NULL");
    *xi0 = drv->xi0;
    return ODHS_OK;
}

int odhs_driver_get_pressure(const odhs_driver *drv, double *p, int *enabled)
{
    if (!drv) return ODHS_E_NULL;
    if (!p || !enabled) return odhs__drverr(drv, ODHS_E_NULL, "output pointer is NULL");
    *p = drv->p;
    *enabled = drv->pressure_on;
    return ODHS_OK;
}

/* the natural time unit (see driver.h), or 0 when the forces set none.
 * The force scale f_ext = sqrt(<F_d|F_d>/N + <|F_p|^2>) is summed as in
 * 0.2.6 (bit for bit) while the sum of squares is a normal double, else
 * again with scaling, so that forces of 1e200 or 1e-200 give their time
 * unit instead of 0 or infinity. */
static double natural_time_unit(const odhs_driver *drv, const odhs_system *sys, double lam)
{
    double rate = fmax(fabs(drv->gdot), fabs(drv->crate));
    if (rate > 0.0) return 1.0 / rate;
    int dim = sys->dim;
    int grav = drv->grav_on && odhs__driver_check_extra(drv, sys->n, sys->dim) == ODHS_OK;
    if (!grav && !drv->F && !drv->prop_on) return 0.0;
    int fixed = grav ? drv->F && drv->Fn == sys->n && drv->Fdim == dim : drv->F != NULL;
    size_t n = grav ? sys->n : drv->F ? drv->Fn : sys->n;
    int fd_dim = grav ? dim : drv->F ? drv->Fdim : dim;
    double amean = 0.5 * lam, amax = 0.0, s = 0.0, ss = 0.0;
    for (int pass = 0; pass < 2; ++pass)
        for (size_t i = 0; i < n && (grav || fixed); ++i) {
            double w = grav ? grav_weight(drv, sys, i, amean) : 0.0;
            for (int k = 0; k < fd_dim; ++k) {
                double f = (grav ? w * drv->g[k] : 0.0) + (fixed ? drv->F[i * fd_dim + k] : 0.0);
                if (pass == 0) {
                    amax = fmax(amax, fabs(f));
                    s += f * f;
                } else {
                    ss += (f / amax) * (f / amax);
                }
            }
            if (pass == 1 && !(amax > 0.0)) break;
        }
    double f2p = drv->prop_on ? prop_f2(drv) : 0.0;
    double f2 = s / (double)n + f2p;
    if (isfinite(f2) && (f2 >= 0x1p-900 || amax == 0.0) && f2 > 0.0) return lam / (drv->xi0 * sqrt(f2));
    /* the scaled route: fd the rms of the deterministic forces */
    double fd = amax > 0.0 ? amax * sqrt(ss / (double)n) : 0.0;
    double fp = drv->prop_on ? odhs__prop_fp(drv) : 0.0;
    double fm = fmax(fd, fp);
    if (!(fm > 0.0)) return 0.0;
    double fext = fm * sqrt((fd / fm) * (fd / fm) + (fp / fm) * (fp / fm));
    return lam / (drv->xi0 * fext);
}

int odhs__driver_check_rates(const odhs_driver *d, const odhs_system *sys, char *errbuf)
{
    double rate = odhs__flow_rate_scale(d);
    if (!(rate > 0.0)) return ODHS_OK;
    double L = fmax(sys->L[0], fmax(sys->L[1], sys->dim == 3 ? sys->L[2] : 0.0)), v = rate * L;
    if (v <= ODHS_VMAX && v >= ODHS_VMIN) return ODHS_OK;
    return odhs__err(errbuf, ODHS_E_INVALID,
                     "flow rate %g over a box edge %g: affine velocities outside [%g, %g], where their squares over- "
                     "or underflow; change the units of time",
                     rate, L, ODHS_VMIN, ODHS_VMAX);
}

int odhs_driver_time_unit(const odhs_driver *drv, const odhs_system *sys, double *tau)
{
    if (!drv) return ODHS_E_NULL;
    if (!sys || !tau) return odhs__drverr(drv, ODHS_E_NULL, "NULL argument");
    if (!sys->has_r) return odhs__drverr(drv, ODHS_E_STATE, "system radii are not set");
    double lam = 0.0;
    for (size_t i = 0; i < sys->n; ++i) lam += 2.0 * sys->r[i];
    lam /= (double)sys->n;
    double t = drv->tau_user > 0.0 ? drv->tau_user : natural_time_unit(drv, sys, lam);
    if (t == 0.0) t = lam / drv->xi0; /* nothing sets a scale: unit force */
    /* a unit of time that is 0, subnormal or infinite cannot time steps */
    if (!(t >= DBL_MIN) || !(t <= DBL_MAX))
        return odhs__drverr(drv, ODHS_E_INVALID,
                            "the time unit %g (lambda %g / (xi0 %g * force scale)) is out of the range of doubles: "
                            "rescale the forces or the mobility, or set a time unit (odhs_driver_set_time_unit)",
                            t, lam, drv->xi0);
    *tau = t;
    return ODHS_OK;
}

/* ---- self-propulsion ------------------------------------------------------ */
static double prop_f2(const odhs_driver *d)
{
    return (d->pfmin * d->pfmin + d->pfmin * d->pfmax + d->pfmax * d->pfmax) / 3.0;
}

double odhs__prop_fp(const odhs_driver *d) { return sqrt(prop_f2(d)); }

static double prop_tau(const odhs_driver *d, double lambda) { return lambda / (d->xi0 * odhs__prop_fp(d)); }

/* force of particle i: direction uniform, magnitude uniform in [fmin, fmax] */
static void prop_draw_force(odhs_driver *d, size_t i)
{
    double *F = d->pF + i * (size_t)d->pdim, e[3];
    if (d->pdim == 2) {
        double phi = 2.0 * ODHS_PI * odhs__rng_uniform(&d->prng);
        e[0] = cos(phi);
        e[1] = sin(phi);
    } else {
        double z = 2.0 * odhs__rng_uniform(&d->prng) - 1.0;
        double phi = 2.0 * ODHS_PI * odhs__rng_uniform(&d->prng);
        double rho = sqrt(fmax(0.0, 1.0 - z * z));
        e[0] = rho * cos(phi);
        e[1] = rho * sin(phi);
        e[2] = z;
    }
    double f = d->pfmin + (d->pfmax - d->pfmin) * odhs__rng_uniform(&d->prng);
    for (int k = 0; k < d->pdim; ++k) F[k] = f * e[k];
}

/* persistence in units of tau_p */
static double prop_draw_time(odhs_driver *d)
{
    return d->ptmin + (d->ptmax - d->ptmin) * odhs__rng_uniform(&d->prng);
}

static void prop_free(odhs_driver *d)
{
    odhs__free(d->pF);
    odhs__free(d->pts);
    odhs__free(d->pF_b);
    odhs__free(d->pts_b);
    d->pF = d->pts = d->pF_b = d->pts_b = NULL;
    d->prop_on = d->prop_started = 0;
    d->pn = 0;
}

int odhs__prop_alloc(odhs_driver *d, size_t n, int dim)
{
    size_t nd = n * (size_t)dim;
    double *F = odhs__malloc_array(nd, sizeof *F), *Fb = odhs__malloc_array(nd, sizeof *Fb);
    double *t = odhs__malloc_array(n, sizeof *t), *tb = odhs__malloc_array(n, sizeof *tb);
    if (!F || !Fb || !t || !tb) {
        odhs__free(F);
        odhs__free(Fb);
        odhs__free(t);
        odhs__free(tb);
        return ODHS_E_NOMEM;
    }
    prop_free(d);
    d->pF = F;
    d->pF_b = Fb;
    d->pts = t;
    d->pts_b = tb;
    d->pn = n;
    d->pdim = dim;
    d->prop_on = 1;
    return ODHS_OK;
}

int odhs_driver_set_self_propulsion(odhs_driver *drv, size_t n, int dim, double fmin, double fmax, double tmin,
                                    double tmax, uint64_t seed)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (dim != 2 && dim != 3) return odhs__drverr(drv, ODHS_E_DIM, "dimension %d must be 2 or 3", dim);
    if (n == 0) return odhs__drverr(drv, ODHS_E_EMPTY, "no particles");
    if (!isfinite(fmin) || !isfinite(fmax) || !isfinite(tmin) || !isfinite(tmax))
        return odhs__drverr(drv, ODHS_E_NONFINITE, "propulsion parameters must be finite");
    if (!(fmin >= 0.0) || !(fmax > 0.0) || fmin > fmax)
        return odhs__drverr(drv, ODHS_E_INVALID, "need 0 <= fmin <= fmax and fmax > 0 (got %g, %g)", fmin, fmax);
    if (!(tmin >= 0.0) || !(tmax > 0.0) || tmin > tmax)
        return odhs__drverr(drv, ODHS_E_INVALID, "need 0 <= tmin <= tmax and tmax > 0 (got %g, %g)", tmin, tmax);
    if (n > SIZE_MAX / 3 / sizeof(double)) return odhs__drverr(drv, ODHS_E_NOMEM, "out of memory");
    if (odhs__prop_alloc(drv, n, dim)) return odhs__drverr(drv, ODHS_E_NOMEM, "out of memory");
    drv->pfmin = fmin;
    drv->pfmax = fmax;
    drv->ptmin = tmin;
    drv->ptmax = tmax;
    odhs__rng_seed(&drv->prng, seed);
    for (size_t i = 0; i < n; ++i) {
        prop_draw_force(drv, i);
        drv->pts[i] = prop_draw_time(drv);
    }
    drv->prop_started = 0;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_clear_self_propulsion(odhs_driver *drv)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (drv->prop_on) {
        prop_free(drv);
        drv->version++;
    }
    return ODHS_OK;
}

int odhs_driver_get_propulsion(const odhs_driver *drv, double *F, double *tswitch)
{
    if (!drv) return ODHS_E_NULL;
    if (!F && !tswitch) return odhs__drverr(drv, ODHS_E_NULL, "both outputs are NULL");
    if (!drv->prop_on) return odhs__drverr(drv, ODHS_E_STATE, "self-propulsion is off");
    if (tswitch && !drv->prop_started)
        return odhs__drverr(drv, ODHS_E_STATE, "switch times are set when a stepper starts the propulsion clock");
    if (F) memcpy(F, drv->pF, drv->pn * (size_t)drv->pdim * sizeof *F);
    if (tswitch) memcpy(tswitch, drv->pts, drv->pn * sizeof *tswitch);
    return ODHS_OK;
}

int odhs_driver_next_switch(const odhs_driver *drv, double *t)
{
    if (!drv) return ODHS_E_NULL;
    if (!t) return odhs__drverr(drv, ODHS_E_NULL, "output pointer is NULL");
    if (!drv->prop_on) return odhs__drverr(drv, ODHS_E_STATE, "self-propulsion is off");
    if (!drv->prop_started)
        return odhs__drverr(drv, ODHS_E_STATE, "switch times are set when a stepper starts the propulsion clock");
    *t = odhs__prop_next(drv);
    return ODHS_OK;
}

void odhs__prop_start(odhs_driver *d, double t, double lambda)
{
    if (!d->prop_on || d->prop_started) return;
    double tau = prop_tau(d, lambda);
    for (size_t i = 0; i < d->pn; ++i) d->pts[i] = t + d->pts[i] * tau;
    d->prop_started = 1;
}

double odhs__prop_next(const odhs_driver *d)
{
    if (!d->prop_on || !d->prop_started) return INFINITY;
    double t = INFINITY;
    for (size_t i = 0; i < d->pn; ++i)
        if (d->pts[i] < t) t = d->pts[i];
    return t;
}

void odhs__prop_switch(odhs_driver *d, double t, double lambda)
{
    if (!d->prop_on || !d->prop_started) return;
    double tau = prop_tau(d, lambda);
    for (size_t i = 0; i < d->pn; ++i)
        while (d->pts[i] <= t) {
            prop_draw_force(d, i);
            d->pts[i] = t + prop_draw_time(d) * tau;
        }
}

void odhs__prop_save(odhs_driver *d)
{
    if (!d->prop_on) return;
    d->prng_b = d->prng;
    d->pstarted_b = d->prop_started;
    memcpy(d->pF_b, d->pF, d->pn * (size_t)d->pdim * sizeof *d->pF);
    memcpy(d->pts_b, d->pts, d->pn * sizeof *d->pts);
}

void odhs__prop_restore(odhs_driver *d)
{
    if (!d->prop_on) return;
    d->prng = d->prng_b;
    d->prop_started = d->pstarted_b;
    memcpy(d->pF, d->pF_b, d->pn * (size_t)d->pdim * sizeof *d->pF);
    memcpy(d->pts, d->pts_b, d->pn * sizeof *d->pts);
}

/* ---- gravity ------------------------------------------------------------------ */
int odhs_driver_set_gravity(odhs_driver *drv, int dim, const double *g)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!g) {
        if (drv->grav_on) drv->version++;
        drv->grav_on = 0;
        memset(drv->g, 0, sizeof drv->g);
        return ODHS_OK;
    }
    if (dim != 2 && dim != 3) return odhs__drverr(drv, ODHS_E_DIM, "dimension %d must be 2 or 3", dim);
    for (int k = 0; k < dim; ++k)
        if (!isfinite(g[k])) return odhs__drverr(drv, ODHS_E_NONFINITE, "gravity component %d is not finite", k);
    memset(drv->g, 0, sizeof drv->g);
    memcpy(drv->g, g, (size_t)dim * sizeof *g);
    drv->gdim = dim;
    drv->grav_on = 1;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_gravity_weights(odhs_driver *drv, size_t n, const double *w)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!w) {
        odhs__free(drv->gw);
        drv->gw = NULL;
        drv->gwn = 0;
        drv->version++;
        return ODHS_OK;
    }
    if (n == 0) return odhs__drverr(drv, ODHS_E_EMPTY, "no particles");
    for (size_t i = 0; i < n; ++i)
        if (!isfinite(w[i])) return odhs__drverr(drv, ODHS_E_NONFINITE, "weight %zu is not finite", i);
    double *c = odhs__malloc_array(n, sizeof *c);
    if (!c) return odhs__drverr(drv, ODHS_E_NOMEM, "out of memory");
    memcpy(c, w, n * sizeof *c);
    odhs__free(drv->gw);
    drv->gw = c;
    drv->gwn = n;
    drv->version++;
    return ODHS_OK;
}

static double grav_weight(const odhs_driver *d, const odhs_system *sys, size_t i, double amean)
{
    if (d->gw) return d->gw[i];
    double q = sys->r[i] / amean;
    return sys->dim == 2 ? q * q : q * q * q;
}

int odhs__driver_check_extra(const odhs_driver *d, size_t n, int dim)
{
    if (d->prop_on && (d->pn != n || d->pdim != dim)) return ODHS_E_DIM;
    if (d->grav_on && (d->gdim != dim || (d->gw && d->gwn != n))) return ODHS_E_DIM;
    return ODHS_OK;
}

int odhs__driver_extra_forces(const odhs_driver *d, const odhs_system *sys, double *F, int *has)
{
    if (!d->prop_on && !d->grav_on) return ODHS_OK;
    size_t n = sys->n;
    int dim = sys->dim;
    size_t nd = n * (size_t)dim;
    if (odhs__driver_check_extra(d, n, dim)) return ODHS_E_DIM;
    if (!*has) memset(F, 0, nd * sizeof *F);
    *has = 1;
    if (d->prop_on)
        for (size_t k = 0; k < nd; ++k) F[k] += d->pF[k];
    if (d->grav_on) {
        double amean = 0.0;
        if (!d->gw) {
            for (size_t i = 0; i < n; ++i) amean += sys->r[i];
            amean /= (double)n;
        }
        for (size_t i = 0; i < n; ++i) {
            double w = grav_weight(d, sys, i, amean);
            for (int k = 0; k < dim; ++k) F[i * dim + k] += w * d->g[k];
        }
    }
    return ODHS_OK;
}
