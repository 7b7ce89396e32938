/* libodhs - the driver's affine flow: the one place that says what a driver's
 * shear means for the stepper (velocity gradient at a time, strain increment
 * over a step, the time to a target strain, switch times, consistency checks).
 * The stepper reads the flow only through these calls, so a new driver shape
 * touches the driver files only. */
#include <math.h>
#include <string.h>

#include "driver/driver.h"

double odhs__flow_shear_rate(const odhs_driver *d, double t, int side)
{
    return d->osc_shape ? odhs__osc_rate(d, t, side) : d->gdot;
}

void odhs__flow_gradient(const odhs_driver *d, double t, int side, int dim, double c_eff, double *G)
{
    memset(G, 0, 9 * sizeof *G);
    G[3 * (0) + (1)] = odhs__flow_shear_rate(d, t, side);
    for (int a = 0; a < dim; ++a) G[3 * (a) + (a)] = -c_eff;
}

double odhs__flow_strain_increment(const odhs_driver *d, double t0, double dt)
{
    if (d->osc_shape) return odhs__osc_strain(d, t0 + dt) - odhs__osc_strain(d, t0);
    return dt * d->gdot;
}

double odhs__flow_time_to_strain(const odhs_driver *d, double t, double strain, double target)
{
    (void)t; /* a constant rate (oscillatory shear has no strain target) */
    double left = (target - strain) / d->gdot;
    return fabs(target - strain) > 1e-15 * fmax(fabs(target), 1e-300) && left > 0.0 ? left : 0.0;
}

int odhs__flow_check_strain_target(const odhs_driver *d, char *errbuf)
{
    if (d->osc_shape)
        return odhs__err(errbuf, ODHS_E_UNSUPPORTED,
                         "run_until_strain with oscillatory shear: the strain is not monotonic (use run_until_time)");
    if (d->gdot == 0.0) return odhs__err(errbuf, ODHS_E_STATE, "run_until_strain needs a nonzero shear rate");
    return ODHS_OK;
}

double odhs__driver_next_switch(const odhs_driver *d, double t)
{
    double tp = odhs__prop_next(d);
    return d->osc_shape ? fmin(tp, odhs__osc_next_switch(d, t)) : tp;
}

int odhs__driver_check(const odhs_driver *d, size_t n, int dim, size_t nwalls, char *errbuf)
{
    if (d->pressure_on && d->osc_shape)
        return odhs__err(errbuf, ODHS_E_UNSUPPORTED, "fixed pressure with oscillatory shear is not supported");
    if (d->pressure_on && d->gdot == 0.0)
        return odhs__err(errbuf, ODHS_E_UNSUPPORTED, "fixed pressure needs a nonzero shear rate");
    if (d->pressure_on && nwalls)
        return odhs__err(errbuf, ODHS_E_UNSUPPORTED, "fixed pressure with walls is not supported");
    if (d->pressure_on && d->crate != 0.0)
        return odhs__err(errbuf, ODHS_E_UNSUPPORTED, "fixed pressure and a compression rate cannot be combined");
    if (d->F && (d->Fn != n || d->Fdim != dim))
        return odhs__err(errbuf, ODHS_E_DIM, "driver forces are for N = %zu, d = %d, the system has N = %zu, d = %d",
                         d->Fn, d->Fdim, n, dim);
    if (odhs__driver_check_extra(d, n, dim))
        return odhs__err(errbuf, ODHS_E_DIM, "self-propulsion or gravity settings do not fit N = %zu, d = %d", n,
                         dim);
    return ODHS_OK;
}
