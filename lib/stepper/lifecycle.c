/* libodhs - the stepper handle: create, destroy, settings and reset. */
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

int odhs__sterr(const odhs_stepper *st, int status, const char *fmt, ...)
{
    if (!st) return status;
    va_list ap;
    va_start(ap, fmt);
    odhs__verr(((odhs_stepper *)st)->errmsg, status, fmt, ap);
    va_end(ap);
    return status;
}

/* ---- lifecycle ------------------------------------------------------------- */
static int stepper_create_impl(odhs_system *sys, odhs_driver *drv, odhs_solver *solver, odhs_stepper **out)
{
    if (!out) return odhs__create_err(ODHS_E_NULL, "odhs_stepper_create: out is NULL");
    *out = NULL;
    if (!sys || !drv || !solver)
        return odhs__create_err(ODHS_E_NULL, "odhs_stepper_create: the %s is NULL", !sys ? "system" : !drv ? "driver" : "solver");
    if (!sys->has_r || !sys->has_x) {
        odhs__syserr(sys, ODHS_E_STATE, "set radii and positions first");
        return odhs__create_err(ODHS_E_STATE, "odhs_stepper_create: the system has no %s: set radii and positions first",
                   !sys->has_r && !sys->has_x ? "radii and positions" : !sys->has_r ? "radii" : "positions");
    }
    odhs_stepper *st = odhs__calloc(1, sizeof *st);
    if (!st) return odhs__create_err(ODHS_E_NOMEM, "odhs_stepper_create: out of memory");
    st->sys = sys;
    st->drv = drv;
    st->sol = solver;
    st->dim = sys->dim;
    st->n = sys->n;
    st->nd = sys->n * (size_t)sys->dim;
    st->dt = 1e-3;
    st->integrator = ODHS_INTEGRATOR_HEUN;
    st->tol = 1e-6;
    st->h = st->dt;
    st->corr_every = odhs__step_heun.corr_default;
    st->contact_tol = 1e-9;
    st->stall_steps = ODHS_STALL_STEPS_DEFAULT;
    st->iso_ci = st->iso_cj = SIZE_MAX;
    st->F = odhs__calloc(st->nd, sizeof(double));
    st->U = odhs__calloc(st->nd, sizeof(double));
    st->tmp = odhs__calloc(st->nd, sizeof(double));
    st->disp = odhs__calloc(st->nd, sizeof(double));
    st->xs = odhs__calloc(3 * st->nd, sizeof(double));
    if (st->xs) {
        st->Us = st->xs + st->nd;
        st->Fs = st->xs + 2 * st->nd;
    }
    st->U0 = odhs__calloc(st->nd, sizeof(double));
    st->Ua = odhs__calloc(st->nd, sizeof(double));
    st->Up = odhs__calloc(st->nd, sizeof(double));
    st->disps = odhs__calloc(st->nd, sizeof(double));
    int s = odhs_network_create(sys, &st->net);
    if (!st->F || !st->U || !st->tmp || !st->disp || !st->xs || !st->U0 || !st->Ua || !st->Up || !st->disps || s) {
        odhs_stepper_destroy(st);
        return odhs__create_err(ODHS_E_NOMEM, "odhs_stepper_create: out of memory (N = %zu)", sys->n);
    }
    *out = st;
    return ODHS_OK;
}

int odhs_stepper_create(odhs_system *sys, odhs_driver *drv, odhs_solver *solver, odhs_stepper **out)
{
    odhs__create_begin();
    return odhs__create_end(stepper_create_impl(sys, drv, solver, out));
}

void odhs_stepper_destroy(odhs_stepper *st)
{
    if (!st) return;
    odhs_network_destroy(st->net);
    odhs_network_destroy(st->iso_sub);
    void *arrays[] = {st->disps, st->U0,  st->Ua,    st->Up, st->F,  st->U,     st->tmp,   st->cb,
                      st->cx,    st->pi,  st->pj,    st->disp, st->rem, st->fpj,  st->pj_res, st->chg,
                      st->xs,    st->sci, st->scj,   st->skind, st->sf, st->fr,   st->srest, st->ev,
                      st->wsnap, st->pre_b, st->pre_f, st->bviol, st->pflag, st->ppart, st->pidx};
    for (size_t k = 0; k < sizeof arrays / sizeof arrays[0]; ++k) odhs__free(arrays[k]);
    odhs__free(st);
}

const char *odhs_stepper_errmsg(const odhs_stepper *st) { return st ? st->errmsg : ""; }

int odhs_stepper_set_dt(odhs_stepper *st, double dt)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(dt)) return odhs__sterr(st, ODHS_E_NONFINITE, "dt is not finite");
    if (!(dt > 0.0)) return odhs__sterr(st, ODHS_E_INVALID, "dt = %g must be > 0", dt);
    st->dt = dt;
    st->h = dt * odhs__step_type_find(st->integrator)->h_first;
    st->dt_user = 1;
    return ODHS_OK;
}

int odhs_stepper_set_integrator(odhs_stepper *st, int integrator)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    const odhs__step_type *type = odhs__step_type_find(integrator);
    if (!type) return odhs__sterr(st, ODHS_E_INVALID, "unknown integrator %d", integrator);
    st->integrator = integrator;
    if (!st->dt_user) st->dt = type->dt_default;
    st->h = st->dt * type->h_first;
    if (!st->corr_user) st->corr_every = type->corr_default;
    if (!st->tol_user) st->tol = type->tol_default;
    return ODHS_OK;
}

int odhs_stepper_set_tolerance(odhs_stepper *st, double tol)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(tol) || !(tol > 0.0) || !(tol < 1.0))
        return odhs__sterr(st, ODHS_E_INVALID, "tolerance %g must be in (0, 1)", tol);
    st->tol = tol;
    st->tol_user = 1;
    return ODHS_OK;
}

int odhs_stepper_get_settings(const odhs_stepper *st, int *integrator, double *dt, double *tol,
                              unsigned *correction_interval)
{
    if (!st) return ODHS_E_NULL;
    if (integrator) *integrator = st->integrator;
    if (dt) *dt = st->dt;
    if (tol) *tol = st->tol;
    if (correction_interval) *correction_interval = st->corr_every;
    return ODHS_OK;
}

int odhs_stepper_rewire_stats(const odhs_stepper *st, uint64_t *count)
{
    if (!st || !count) return ODHS_E_NULL;
    *count = st->nrewire_monotone;
    return ODHS_OK;
}

int odhs__stepper_set_rewire_mode(odhs_stepper *st, int mode)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (mode != 0 && mode != 1) return odhs__sterr(st, ODHS_E_INVALID, "rewire mode %d is not 0 or 1", mode);
    st->rewire_mode = mode;
    return ODHS_OK;
}

int odhs_stepper_batched_stats(const odhs_stepper *st, uint64_t *batched_steps, uint64_t *exact_steps,
                               uint64_t *solves)
{
    if (!st) return ODHS_E_NULL;
    if (batched_steps) *batched_steps = st->nbatched;
    if (exact_steps) *exact_steps = st->nbatched_exact;
    if (solves) *solves = st->nbatched_solves;
    return ODHS_OK;
}

int odhs_stepper_correction_stats(const odhs_stepper *st, uint64_t *corrections, uint64_t *passes, uint64_t *closed)
{
    if (!st) return ODHS_E_NULL;
    if (corrections) *corrections = st->ncorr;
    if (passes) *passes = st->ncorr_passes;
    if (closed) *closed = st->ncorr_closed;
    return ODHS_OK;
}

int odhs_stepper_adaptive_stats(const odhs_stepper *st, uint64_t *rejected, double *h)
{
    if (!st) return ODHS_E_NULL;
    if (rejected) *rejected = st->nrejected;
    if (h) *h = st->h;
    return ODHS_OK;
}

int odhs_stepper_set_correction_interval(odhs_stepper *st, unsigned k)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    st->corr_every = k;
    st->corr_user = 1;
    return ODHS_OK;
}

int odhs_stepper_set_contact_tolerance(odhs_stepper *st, double tol)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(tol) || tol < 0.0 || tol > 0.1)
        return odhs__sterr(st, ODHS_E_INVALID, "contact tolerance %g must be in [0, 0.1]", tol);
    st->contact_tol = tol;
    return ODHS_OK;
}

int odhs_stepper_set_event_callback(odhs_stepper *st, odhs_event_fn fn, void *ctx)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    st->evfn = fn;
    st->evctx = ctx;
    return ODHS_OK;
}

int odhs_stepper_set_run_limits(odhs_stepper *st, uint64_t max_steps, uint64_t stall_steps)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    st->max_steps = max_steps;
    st->stall_steps = stall_steps;
    return ODHS_OK;
}

int odhs_stepper_set_pre_event_stress(odhs_stepper *st, int on)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (on != 0 && on != 1) return odhs__sterr(st, ODHS_E_INVALID, "on = %d must be 0 or 1", on);
    if (on != st->pre_on) st->pre_state = ODHS__PRE_NONE;
    st->pre_on = on;
    return ODHS_OK;
}

int odhs_stepper_get_run_limits(const odhs_stepper *st, uint64_t *max_steps, uint64_t *stall_steps)
{
    if (!st) return ODHS_E_NULL;
    if (max_steps) *max_steps = st->max_steps;
    if (stall_steps) *stall_steps = st->stall_steps;
    return ODHS_OK;
}

/* the handles behind the stepper are as its state expects: the force
 * callback of a checkpointed run is set again, the system was not changed
 * by its setters since the stepper last saw it */
int odhs__st_check_handles(odhs_stepper *st)
{
    if (st->drv->fn_missing)
        return odhs__sterr(st, ODHS_E_STATE,
                           "the checkpointed run had a force callback: set it again on the restored driver "
                           "(odhs_driver_set_force_callback; or odhs_driver_set_forces) before stepping");
    if (st->ready && st->sys->version != st->sys_version)
        return odhs__sterr(st, ODHS_E_STATE,
                           "the system was changed behind the stepper's back (its setters were called since the "
                           "last step): call odhs_stepper_reset to start from the changed system");
    return ODHS_OK;
}

int odhs__st_check_driver(odhs_stepper *st)
{
    int s = odhs__driver_check(st->drv, st->n, st->dim, st->net->nwalls, st->errmsg);
    return s ? s : odhs__driver_check_rates(st->drv, st->sys, st->errmsg);
}

int odhs_stepper_reset(odhs_stepper *st)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    int s, psaved = 0;
    if (st->drv->fn_missing) return odhs__st_check_handles(st);
    st->ready = 0;
    st->jammed = 0;
    st->pre_state = ODHS__PRE_NONE;
    odhs__solver_invalidate(st->sol); /* our network may reuse a freed address */
    if ((s = odhs__st_check_driver(st))) return s;
    if ((s = odhs_driver_time_unit(st->drv, st->sys, &st->tau))) return odhs__sterr(st, s, "%s", st->drv->errmsg);
    st->lambda = 0.0;
    for (size_t i = 0; i < st->n; ++i) st->lambda += 2.0 * st->sys->r[i];
    st->lambda /= (double)st->n;
    /* keep permanent contacts, rebuild the temporary ones; an error puts
     * the configuration and the network back as they were (rollback) */
    odhs_network *net = st->net;
    if ((s = odhs__st_save(st))) return s;
    odhs__net_geometry(net, st->sys);
    for (size_t c = net->nc; c-- > 0;) {
        double sig = odhs__net_sigma(net, st->sys, c);
        if (odhs__can_open(net->kind[c]) &&
            (fabs(net->gap[c]) > fmax(1e-6, st->contact_tol) * sig || odhs__same_body(net, net->ci[c], net->cj[c])))
            odhs__net_remove_at(net, c);
    }
    if ((s = odhs_network_detect(net, st->sys, st->contact_tol))) {
        s = odhs__sterr(st, s, "%s", net->errmsg);
        goto fail;
    }
    if ((s = odhs__st_build_neighbours(st))) goto fail;
    odhs__prop_save(st->drv); /* an error leaves the propulsion clock as it was */
    psaved = 1;
    odhs__prop_start(st->drv, st->time, st->lambda);
    if ((s = odhs__st_external_forces(st))) goto fail;
    st->nchg = 0;
    st->chg_mark = 0;
    /* a step type that rewires in blocks does so from the detected network
     * too: at large N a start (a tiled packing, a file) can hold thousands
     * of tensile contacts, and one solve per event grows like N^2 */
    if ((s = odhs__step_type_find(st->integrator)->block_rewire ? odhs__st_rewire_block(st) : odhs__st_rewire(st)))
        goto fail;
    st->nchg = 0;
    st->chg_mark = 0;
    st->drv_version = st->drv->version;
    st->sys_version = st->sys->version;
    st->ready = 1;
    return ODHS_OK;
fail:
    if (psaved) odhs__prop_restore(st->drv);
    if (s < 0) odhs__st_rollback(st);
    st->nchg = 0;
    st->chg_mark = 0;
    return s;
}
