/*
 * libodhs private header: the driver handle: affine flow, external forces, self-propulsion
 * and gravity.
 * Not installed.
 */
#ifndef ODHS_DRIVER_DRIVER_H
#define ODHS_DRIVER_DRIVER_H

#include "system/system.h"

/* ---- driver ---------------------------------------------------------------- */
struct odhs_driver {
    double xi0;
    double gdot;       /* shear rate */
    double crate;      /* compression rate */
    int pressure_on;
    double p;
    double kappa_max;
    double p_jam;      /* jamming pressure (INFINITY: flow at every p) */
    double *F;         /* fixed forces or NULL */
    size_t Fn;
    int Fdim;
    odhs_force_fn fn;
    void *fn_ctx;
    double tau_user;   /* 0 = unset */
    int fn_missing;    /* read from a checkpoint of a run with a force callback:
                        * steppers refuse to step until the callback (or
                        * fixed forces) is set again */
    uint64_t version;  /* bumped by every setter: steppers re-solve on change */
    char errmsg[ODHS_ERRMSG_LEN];
    /* self-propulsion (Sect. V B); switches do not bump version: the stepper
     * applies them at the end of the step that reaches the switch time */
    int prop_on, prop_started;
    size_t pn;
    int pdim;
    double pfmin, pfmax, ptmin, ptmax;
    odhs_rng prng;
    double *pF;        /* pn*pdim current propulsion forces */
    double *pts;       /* pn switch times (before the start: persistence in units of tau_p) */
    odhs_rng prng_b;   /* copy for the stepper's rollback */
    int pstarted_b;
    double *pF_b, *pts_b;
    /* oscillatory shear (lib/driver/oscillation.c): shape 0 = off, else
     * ODHS_OSCILLATION_*; gdot then holds the peak rate */
    int osc_shape;
    double osc_amp, osc_period, osc_t0;
    /* gravity */
    int grav_on, gdim;
    double g[3];
    double *gw;        /* gwn weights, or NULL: (a_i/<a>)^d */
    size_t gwn;
};

/* record an error message on the driver (logically mutable) */
int odhs__drverr(const odhs_driver *d, int status, const char *fmt, ...) ODHS_PRINTF(3, 4);

/* The range of velocity scales the stepper computes with: velocities are
 * squared (collision prediction, error estimates, skins), so xi0 |F| and
 * rate * box edge must stay where squares neither over- nor underflow. */
#define ODHS_VMAX 1e150
#define ODHS_VMIN 1e-150
/* the largest rate of the affine flow (max |gammadot|, |c|); 0 without one */
static inline double odhs__flow_rate_scale(const odhs_driver *d) { return fmax(fabs(d->gdot), fabs(d->crate)); }
/* ODHS_OK, or ODHS_E_INVALID with a message in errbuf when a flow rate
 * times the box edge leaves [ODHS_VMIN, ODHS_VMAX] */
int odhs__driver_check_rates(const odhs_driver *d, const odhs_system *sys, char *errbuf);

/* propulsion and gravity (lib/driver/driver.c) */
double odhs__prop_fp(const odhs_driver *d);               /* sqrt(<|F_p|^2>) */
/* allocate the propulsion arrays for n particles in dim (frees old ones) */
int odhs__prop_alloc(odhs_driver *d, size_t n, int dim);
/* start the clock at time t (no-op when off or started) */
void odhs__prop_start(odhs_driver *d, double t, double lambda);
/* earliest switch time; INFINITY when off or not started */
double odhs__prop_next(const odhs_driver *d);
/* redraw every particle whose switch time is <= t, new switch at t + tau_p u */
void odhs__prop_switch(odhs_driver *d, double t, double lambda);
void odhs__prop_save(odhs_driver *d);
void odhs__prop_restore(odhs_driver *d);
/* settings consistent with a system of n particles in dim? ODHS_OK or ODHS_E_DIM */
int odhs__driver_check_extra(const odhs_driver *d, size_t n, int dim);
/* add propulsion and gravity to F (zeroed first when *has == 0; *has set when
 * anything was added). ODHS_E_DIM when the settings do not fit sys. */
int odhs__driver_extra_forces(const odhs_driver *d, const odhs_system *sys, double *F, int *has);

/* oscillatory shear (lib/driver/oscillation.c): the rate (side as for
 * odhs__flow_shear_rate), the strain gamma(t), the first reversal after t
 * (INFINITY for the sine) */
double odhs__osc_rate(const odhs_driver *d, double t, int side);
double odhs__osc_strain(const odhs_driver *d, double t);
double odhs__osc_next_switch(const odhs_driver *d, double t);

/* ---- the affine flow (lib/driver/flow.c) ----------------------------------
 * What the stepper needs of the driver's flow. Times are the stepper's. */
/* shear rate gammadot(t): side = +1 the rate from t on, side = -1 the rate
 * up to t (the end of a step; the two differ only where the rate jumps) */
double odhs__flow_shear_rate(const odhs_driver *d, double t, int side);
/* velocity gradient G (row-major 3x3) at time t: gammadot(t) e_x e_y^T -
 * c_eff I in dim dimensions (c_eff: the isotropic compression rate, which
 * the stepper sets from the compression rate or the pressure control) */
void odhs__flow_gradient(const odhs_driver *d, double t, int side, int dim, double c_eff, double *G);
/* accumulated shear strain over [t0, t0 + dt] */
double odhs__flow_strain_increment(const odhs_driver *d, double t0, double dt);
/* time from t (accumulated strain `strain`) to the strain target; 0 when
 * reached (to 1e-15 relative) or behind */
double odhs__flow_time_to_strain(const odhs_driver *d, double t, double strain, double target);
/* whether run-until-strain can be used with this driver (message into errbuf) */
int odhs__flow_check_strain_target(const odhs_driver *d, char *errbuf);
/* the earliest time at which the driving switches (a step ends exactly
 * there and the forces are re-evaluated): an overdue propulsion switch, or
 * else the first switch after t; INFINITY for none */
double odhs__driver_next_switch(const odhs_driver *d, double t);
/* the driver's settings consistent with a stepper of n particles in dim
 * with nwalls walls? ODHS_OK, or a status with its message in errbuf */
int odhs__driver_check(const odhs_driver *d, size_t n, int dim, size_t nwalls, char *errbuf);

#endif /* ODHS_DRIVER_DRIVER_H */
