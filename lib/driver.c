/* libodhs - drivers: affine flow (shear, compression, fixed pressure), forces. */
#include <math.h>
#include <string.h>

#include "internal.h"

static int drverr(const odhs_driver *d, int status, const char *fmt, ...) ODHS_PRINTF(3, 4);
static int drverr(const odhs_driver *d, int status, const char *fmt, ...)
{
    if (!d) return status;
    va_list ap;
    va_start(ap, fmt);
    odhs__verr(((odhs_driver *)d)->errmsg, status, fmt, ap);
    va_end(ap);
    return status;
}

int odhs_driver_create(odhs_driver **out)
{
    if (!out) return ODHS_E_NULL;
    odhs_driver *d = odhs__calloc(1, sizeof *d);
    *out = d;
    if (!d) return ODHS_E_NOMEM;
    d->xi0 = 1.0;
    d->kappa_max = 100.0;
    return ODHS_OK;
}

void odhs_driver_destroy(odhs_driver *drv)
{
    if (!drv) return;
    odhs__free(drv->F);
    odhs__free(drv);
}

const char *odhs_driver_errmsg(const odhs_driver *drv) { return drv ? drv->errmsg : ""; }

int odhs_driver_set_mobility(odhs_driver *drv, double xi0)
{
    if (!drv) return ODHS_E_NULL;
    if (!isfinite(xi0)) return drverr(drv, ODHS_E_NONFINITE, "mobility is not finite");
    if (!(xi0 > 0.0)) return drverr(drv, ODHS_E_INVALID, "mobility %g must be > 0", xi0);
    drv->xi0 = xi0;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_shear_rate(odhs_driver *drv, double gammadot)
{
    if (!drv) return ODHS_E_NULL;
    if (!isfinite(gammadot)) return drverr(drv, ODHS_E_NONFINITE, "shear rate is not finite");
    drv->gdot = gammadot;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_compression_rate(odhs_driver *drv, double c)
{
    if (!drv) return ODHS_E_NULL;
    if (!isfinite(c)) return drverr(drv, ODHS_E_NONFINITE, "compression rate is not finite");
    drv->crate = c;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_pressure(odhs_driver *drv, double p)
{
    if (!drv) return ODHS_E_NULL;
    if (!isfinite(p)) return drverr(drv, ODHS_E_NONFINITE, "pressure is not finite");
    if (!(p > 0.0)) return drverr(drv, ODHS_E_INVALID, "pressure %g must be > 0", p);
    drv->p = p;
    drv->pressure_on = 1;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_clear_pressure(odhs_driver *drv)
{
    if (!drv) return ODHS_E_NULL;
    drv->pressure_on = 0;
    drv->p = 0.0;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_kappa_max(odhs_driver *drv, double kappa_max)
{
    if (!drv) return ODHS_E_NULL;
    if (!isfinite(kappa_max)) return drverr(drv, ODHS_E_NONFINITE, "kappa_max is not finite");
    if (!(kappa_max > 0.0)) return drverr(drv, ODHS_E_INVALID, "kappa_max must be > 0");
    drv->kappa_max = kappa_max;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_forces(odhs_driver *drv, size_t n, int dim, const double *F)
{
    if (!drv) return ODHS_E_NULL;
    if (!F) {
        odhs__free(drv->F);
        drv->F = NULL;
        drv->Fn = 0;
        drv->version++;
        return ODHS_OK;
    }
    if (dim != 2 && dim != 3) return drverr(drv, ODHS_E_DIM, "dimension %d must be 2 or 3", dim);
    if (n == 0) return drverr(drv, ODHS_E_EMPTY, "no particles");
    size_t nd = n * (size_t)dim;
    for (size_t k = 0; k < nd; ++k)
        if (!isfinite(F[k])) return drverr(drv, ODHS_E_NONFINITE, "force component %zu is not finite", k);
    double *c = odhs__malloc_array(nd, sizeof *c);
    if (!c) return drverr(drv, ODHS_E_NOMEM, "out of memory");
    memcpy(c, F, nd * sizeof *c);
    odhs__free(drv->F);
    drv->F = c;
    drv->Fn = n;
    drv->Fdim = dim;
    drv->fn = NULL;
    drv->fn_ctx = NULL;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_set_force_callback(odhs_driver *drv, odhs_force_fn fn, void *ctx)
{
    if (!drv) return ODHS_E_NULL;
    drv->fn = fn;
    drv->fn_ctx = fn ? ctx : NULL;
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
    if (!isfinite(tau)) return drverr(drv, ODHS_E_NONFINITE, "time unit is not finite");
    if (!(tau > 0.0)) return drverr(drv, ODHS_E_INVALID, "time unit must be > 0");
    drv->tau_user = tau;
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_get_shear_rate(const odhs_driver *drv, double *g)
{
    if (!drv) return ODHS_E_NULL;
    if (!g) return drverr(drv, ODHS_E_NULL, "output pointer is NULL");
    *g = drv->gdot;
    return ODHS_OK;
}

int odhs_driver_get_compression_rate(const odhs_driver *drv, double *c)
{
    if (!drv) return ODHS_E_NULL;
    if (!c) return drverr(drv, ODHS_E_NULL, "output pointer is NULL");
    *c = drv->crate;
    return ODHS_OK;
}

int odhs_driver_get_mobility(const odhs_driver *drv, double *xi0)
{
    if (!drv) return ODHS_E_NULL;
    if (!xi0) return drverr(drv, ODHS_E_NULL, "output pointer is NULL");
    *xi0 = drv->xi0;
    return ODHS_OK;
}

int odhs_driver_get_pressure(const odhs_driver *drv, double *p, int *enabled)
{
    if (!drv) return ODHS_E_NULL;
    if (!p || !enabled) return drverr(drv, ODHS_E_NULL, "output pointer is NULL");
    *p = drv->p;
    *enabled = drv->pressure_on;
    return ODHS_OK;
}

int odhs_driver_time_unit(const odhs_driver *drv, const odhs_system *sys, double *tau)
{
    if (!drv) return ODHS_E_NULL;
    if (!sys || !tau) return drverr(drv, ODHS_E_NULL, "NULL argument");
    if (!sys->has_r) return drverr(drv, ODHS_E_STATE, "system radii are not set");
    double rate = fmax(fabs(drv->gdot), fabs(drv->crate));
    if (rate > 0.0) {
        *tau = 1.0 / rate;
        return ODHS_OK;
    }
    double lam = 0.0;
    for (size_t i = 0; i < sys->n; ++i) lam += 2.0 * sys->r[i];
    lam /= (double)sys->n;
    if (drv->F) {
        double s = 0.0;
        size_t nd = drv->Fn * (size_t)drv->Fdim;
        for (size_t k = 0; k < nd; ++k) s += drv->F[k] * drv->F[k];
        double frms = sqrt(s / (double)drv->Fn);
        if (frms > 0.0) {
            *tau = lam / (drv->xi0 * frms);
            return ODHS_OK;
        }
    }
    *tau = drv->tau_user > 0.0 ? drv->tau_user : lam / drv->xi0;
    return ODHS_OK;
}
