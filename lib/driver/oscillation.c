/* libodhs - oscillatory simple shear: gamma(t) = gamma0 sin(2 pi (t - t0)/T),
 * or the triangle wave of a constant rate 4 gamma0/T reversing every half
 * period (see include/odhs/driver.h). Only lib/driver/flow.c calls the shape
 * functions below. */
#include <math.h>

#include "driver/driver.h"

int odhs_driver_set_oscillatory_shear(odhs_driver *drv, int shape, double amplitude, double period, double t0)
{
    if (!drv) return ODHS_E_NULL;
    drv->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(amplitude) || !isfinite(period) || !isfinite(t0))
        return odhs__drverr(drv, ODHS_E_NONFINITE, "oscillatory shear: amplitude, period and phase origin must be finite");
    if (shape != ODHS_OSCILLATION_SINE && shape != ODHS_OSCILLATION_TRIANGLE)
        return odhs__drverr(drv, ODHS_E_INVALID, "oscillatory shear: unknown shape %d", shape);
    if (!(amplitude > 0.0)) return odhs__drverr(drv, ODHS_E_INVALID, "oscillatory shear: amplitude %g must be > 0", amplitude);
    if (!(period > 0.0)) return odhs__drverr(drv, ODHS_E_INVALID, "oscillatory shear: period %g must be > 0", period);
    double peak = (shape == ODHS_OSCILLATION_SINE ? 2.0 * ODHS_PI : 4.0) * amplitude / period;
    if (!isfinite(peak) || !(peak > 0.0))
        return odhs__drverr(drv, ODHS_E_RANGE, "oscillatory shear: the peak rate %g is not a finite positive number", peak);
    drv->osc_shape = shape;
    drv->osc_amp = amplitude;
    drv->osc_period = period;
    drv->osc_t0 = t0;
    drv->gdot = peak; /* the rate scale: the natural time unit is 1/peak */
    drv->version++;
    return ODHS_OK;
}

int odhs_driver_get_oscillatory_shear(const odhs_driver *drv, int *shape, double *amplitude, double *period,
                                      double *t0)
{
    if (!drv) return ODHS_E_NULL;
    if (shape) *shape = drv->osc_shape;
    if (amplitude) *amplitude = drv->osc_amp;
    if (period) *period = drv->osc_period;
    if (t0) *t0 = drv->osc_t0;
    return ODHS_OK;
}

/* ---- the triangle wave ------------------------------------------------------
 * Reversals at s_k = t0 + (1/4 + k/2) T. Interval k is [s_{k-1}, s_k) (with
 * side = -1, the flow up to t: (s_{k-1}, s_k]), with rate (-1)^k 4 gamma0/T
 * and gamma = (-1)^k (r (t - s_{k-1}) - gamma0): 0 at t0, gamma0 at s_0. The
 * interval is found by rounding and then fixed by comparing t with the
 * reversal times computed as the stepper's switch times are, so a step that
 * ends at a reversal sees the same interval on both sides. */
static double tri_switch(const odhs_driver *d, double k) { return d->osc_t0 + (0.25 + 0.5 * k) * d->osc_period; }

static double tri_interval(const odhs_driver *d, double t, int side)
{
    double k = floor((t - d->osc_t0) / (0.5 * d->osc_period) + 0.5);
    while (side > 0 ? t >= tri_switch(d, k) : t > tri_switch(d, k)) k += 1.0;
    while (side > 0 ? t < tri_switch(d, k - 1.0) : t <= tri_switch(d, k - 1.0)) k -= 1.0;
    return k;
}

static double tri_sign(double k) { return fmod(fabs(k), 2.0) == 0.0 ? 1.0 : -1.0; }

double odhs__osc_rate(const odhs_driver *d, double t, int side)
{
    if (d->osc_shape == ODHS_OSCILLATION_SINE)
        return 2.0 * ODHS_PI * d->osc_amp / d->osc_period * cos(2.0 * ODHS_PI * (t - d->osc_t0) / d->osc_period);
    return tri_sign(tri_interval(d, t, side)) * 4.0 * d->osc_amp / d->osc_period;
}

double odhs__osc_strain(const odhs_driver *d, double t)
{
    if (d->osc_shape == ODHS_OSCILLATION_SINE) return d->osc_amp * sin(2.0 * ODHS_PI * (t - d->osc_t0) / d->osc_period);
    double k = tri_interval(d, t, +1), r = 4.0 * d->osc_amp / d->osc_period;
    return tri_sign(k) * (r * (t - tri_switch(d, k - 1.0)) - d->osc_amp);
}

double odhs__osc_next_switch(const odhs_driver *d, double t)
{
    if (d->osc_shape != ODHS_OSCILLATION_TRIANGLE) return INFINITY;
    return tri_switch(d, tri_interval(d, t, +1));
}
