/* libodhs - one step (Sect. IV A of the paper) and the run loops. */
#include <math.h>
#include <stddef.h>
#include <stdlib.h>
#include <string.h>

#include "stepper/stepper.h"

/* the integrators (step types) the library has */
const odhs__step_type *odhs__step_type_find(int id)
{
    static const odhs__step_type *const types[] = {&odhs__step_euler, &odhs__step_heun, &odhs__step_batched};
    for (size_t k = 0; k < sizeof types / sizeof types[0]; ++k)
        if (types[k]->id == id) return types[k];
    return NULL;
}

/* ---- one step (Sect. IV A) ----------------------------------------------- */
/* What a failed step puts back besides the state saved by odhs__st_save. */
typedef struct {
    uint64_t drv_version, nrejected;
    double tau, h;
    int psaved; /* self-propulsion state saved (odhs__prop_save) */
} step_undo;

static int undo(odhs_stepper *st, const step_undo *u, int s)
{
    if (u->psaved) odhs__prop_restore(st->drv);
    odhs__st_rollback(st);
    /* the forces are again those of the start of the step: solved for the
     * driver as it was then (a changed driver is re-solved next time) */
    st->drv_version = u->drv_version;
    st->tau = u->tau;
    st->h = u->h;
    st->nrejected = u->nrejected;
    st->jammed = 0;
    st->nchg = 0;
    st->chg_mark = 0;
    return s;
}

/* The flow the force solve left: a velocity gradient or compression rate
 * that overflowed (a huge shear rate times a large kappa: fuzz_checkpoint,
 * finding 15) fails the step, which is rolled back, instead of being kept
 * and written into a checkpoint that the reader refuses. */
static int check_flow(odhs_stepper *st)
{
    int ok = isfinite(st->kappa);
    for (int k = 0; k < 9 && ok; ++k) ok = isfinite(st->G[k]);
    if (ok) return ODHS_OK;
    return odhs__sterr(st, ODHS_E_NONFINITE,
                       "non-finite flow after the force solve (kappa = %g; rates too large?)", st->kappa);
}

/* The driver changed since the forces were solved (or propulsion switches
 * are overdue, e.g. on a driver shared by steppers): re-solve. *done when the
 * new driving opened or closed contacts: that is this step's event, at the
 * current time and with no motion. */
static int driver_update(odhs_stepper *st, step_undo *u, odhs_event *first, int *stop, int *done)
{
    int s;
    *done = 0;
    if (st->drv_version == st->drv->version && !(odhs__driver_next_switch(st->drv, st->time) <= st->time)) return ODHS_OK;
    if ((s = odhs__st_check_driver(st))) return s;
    if ((s = odhs_driver_time_unit(st->drv, st->sys, &st->tau))) return odhs__sterr(st, s, "%s", st->drv->errmsg);
    odhs__prop_save(st->drv);
    u->psaved = 1;
    odhs__prop_start(st->drv, st->time, st->lambda);
    odhs__prop_switch(st->drv, st->time, st->lambda);
    if ((s = odhs__st_external_forces(st)) || (s = odhs__st_rewire(st)) || (s = check_flow(st))) return s;
    st->drv_version = st->drv->version;
    if (!st->nchg) return ODHS_OK;
    st->nsteps++;
    *done = 1;
    return odhs__st_emit_events(st, first, stop);
}

/* the chord must stay inside the neighbour list's skin: rebuild the list
 * when it would not, and shorten the chord to 0.9 of the new skin */
static int fit_neighbours(odhs_stepper *st, odhs__step_plan *p)
{
    double rate = odhs__st_skin_rate(st, p->G, p->vel);
    const double used = odhs__st_skin_used(st); /* a non-finite one rebuilds */
    if (!st->nb_stale && isfinite(used) && !(used + rate * p->tplan > st->skin)) return ODHS_OK;
    st->nb_stale = 0;
    int s = odhs__st_build_neighbours(st);
    if (s) return s;
    rate = odhs__st_skin_rate(st, p->G, p->vel);
    if (rate * p->tplan > 0.9 * st->skin) p->tplan = 0.9 * st->skin / rate;
    return ODHS_OK;
}

/* move by p->t along the chord; the clock follows */
int odhs__st_move(odhs_stepper *st, odhs__step_plan *p)
{
    odhs__st_advance(st, p->G, p->vel, p->t);
    if (st->net->nwalls) odhs__st_advance_walls(st, p->t);
    for (size_t k = 0; k < st->nd; ++k)
        if (!isfinite(st->sys->x[k]))
            return odhs__sterr(st, ODHS_E_NONFINITE, "non-finite positions after a step of %g (rates too large?)",
                               p->t);
    if (!isfinite(st->sys->L[0]) || !(st->sys->L[0] > 0.0) || !isfinite(st->sys->gamma))
        return odhs__sterr(st, ODHS_E_NONFINITE, "the box became degenerate after a step of %g", p->t);
    p->at_switch = p->ci == SIZE_MAX && p->t == p->dsw; /* the step reached the switch time */
    const double t0 = st->time;
    st->time = p->at_switch ? p->tsw : t0 + p->t;
    st->strain += odhs__flow_strain_increment(st->drv, t0, p->t);
    st->nsteps++;
    return ODHS_OK;
}

/* a scheme's hook that may repeat the step: *again = 1 to plan it anew */
static int repeat(odhs_stepper *st, int (*hook)(odhs_stepper *, odhs__step_plan *, int *), odhs__step_plan *p,
                  int *again)
{
    *again = 0;
    return hook ? hook(st, p, again) : ODHS_OK;
}

/* Sect. IV A (i)-(ii): the chord, the first collision on it, the motion to
 * it, the new contact and the external forces at the step's end; the scheme
 * may repeat the step shorter (a collision or an opening inside it) */
int odhs__st_advance_exact(odhs_stepper *st, const odhs__step_type *type, odhs__step_plan *p)
{
    int s, again;
    for (;;) {
        if ((s = type->chord(st, p)) || (s = fit_neighbours(st, p))) return s;
        p->t = odhs__st_predict(st, p->G, p->vel, p->tplan, EPS_V * odhs__st_velocity_scale(st), 1,
                                type->early ? 2 : 1, &p->ci, &p->cj);
        if (type->early && type->early(st, p)) continue;
        if ((s = odhs__st_move(st, p)) || (s = repeat(st, type->at_collision, p, &again))) return s;
        if (again) continue;
        /* the external forces at the end time do not depend on the network:
         * evaluated before the new contact, so that the pre-event record
         * solves on the start network with them */
        if ((s = odhs__st_external_forces(st))) return s;
        if (st->pre_on && (s = odhs__st_pre_event_record(st))) return s;
        size_t c;
        if (p->ci != SIZE_MAX && (s = odhs__st_add_contact(st, p->ci, p->cj, &c))) return s;
        odhs__net_geometry(st->net, st->sys);
        if ((s = repeat(st, type->at_opening, p, &again))) return s;
        if (!again) return ODHS_OK;
    }
}

/* Sect. IV A (iii)-(iv) and IV C: new forces of the driver at a switch time,
 * drift correction (before the rewiring: its solve is then that of the
 * corrected geometry, and contacts the correction adds are rewired with the
 * step's events), rewiring; the events follow (do_step) */
static int end_step(odhs_stepper *st, const odhs__step_type *type, const odhs__step_plan *p, step_undo *u)
{
    int (*rewire)(odhs_stepper *) = type->block_rewire && !p->exact ? odhs__st_rewire_block : odhs__st_rewire;
    int s;
    if (p->at_switch) {
        if (!u->psaved) odhs__prop_save(st->drv);
        u->psaved = 1;
        odhs__prop_switch(st->drv, st->time, st->lambda);
        if ((s = odhs__st_external_forces(st))) return s;
    }
    st->corr_skipped = 0;
    if (st->corr_every && st->nsteps % st->corr_every == 0) {
        int added = 0;
        if ((s = odhs__st_correct(st, &added))) return s;
    }
    if ((s = rewire(st))) return s;
    if (st->corr_skipped && st->drv->pressure_on && !st->jammed) {
        /* a collision made the network over-constrained (excess 2), so the
         * correction waited for the rewiring to open a contact: correct
         * now, else the step's integration error (~1e-11 of a diameter
         * after a Heun step cut at the collision) stays on the contacts
         * for a step, and rewire the corrected geometry */
        int added = 0;
        st->corr_skipped = 0;
        if ((s = odhs__st_correct(st, &added)) || (s = odhs__st_rewire(st))) return s;
    }
    return check_flow(st);
}

/* One step: limit is the largest time to advance (INFINITY for none); *stop
 * is set by the event callback. A failed step leaves the state of its start. */
static int do_step(odhs_stepper *st, double limit, odhs_event *first, int *stop)
{
    int s, done = 0;
    if (first) {
        memset(first, 0, sizeof *first);
        first->kind = ODHS_EVENT_NONE;
    }
    st->last_driver_only = 0;
    if ((s = odhs__st_check_handles(st))) return s;
    if (!st->ready && (s = odhs_stepper_reset(st))) return s;
    if (st->jammed) return odhs__sterr(st, ODHS_JAMMED, "the packing is jammed: no further steps under this driving");
    if ((s = odhs__st_save(st))) return s;
    step_undo u = {st->drv_version, st->nrejected, st->tau, st->h, 0};
    st->nchg = 0;
    st->chg_mark = 0;
    if ((s = driver_update(st, &u, first, stop, &done))) return undo(st, &u, s);
    if (done) {
        st->last_driver_only = 1;
        if (st->pre_on) st->pre_state = ODHS__PRE_DRIVER;
        return ODHS_OK;
    }
    /* the step starts from the forces and flow now, re-solved if the driver
     * changed: a step the scheme repeats shorter returns to them, a failed
     * step to the state before the call */
    odhs__st_mark_start(st);
    const odhs__step_type *type = odhs__step_type_find(st->integrator);
    odhs__step_plan p = {0};
    st->pred_ok = 0;
    if (type->begin) type->begin(st);
    /* a step ends exactly at the driver's next switch time */
    p.tsw = odhs__driver_next_switch(st->drv, st->time);
    p.dsw = p.tsw - st->time;
    p.limit = p.dsw <= limit ? p.dsw : limit;
    st->pre_pend_state = ODHS__PRE_NONE;
    for (;;) {
        int again = 0;
        s = type->advance ? type->advance(st, &p) : odhs__st_advance_exact(st, type, &p);
        if (s || (s = end_step(st, type, &p, &u)) || (type->judge && (s = type->judge(st, &p, &again))))
            return undo(st, &u, s);
        if (!again) break;
        /* the scheme took the step back: anew, to the same limit */
        const double limit1 = p.limit, tsw = p.tsw, dsw = p.dsw;
        memset(&p, 0, sizeof p);
        p.limit = limit1;
        p.tsw = tsw;
        p.dsw = dsw;
    }
    if ((s = odhs__st_emit_events(st, first, stop))) return undo(st, &u, s);
    if (st->pre_on) {
        st->pre_state = st->pre_pend_state;
        memcpy(st->pre_sigma, st->pre_pend, sizeof st->pre_sigma);
    }
    if (st->jammed)
        return odhs__sterr(st, ODHS_JAMMED, "jammed at t = %.17g: isostatic constrained subset, positive self-stress",
                           st->time);
    return ODHS_OK;
}


int odhs_stepper_correct(odhs_stepper *st)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    int s, stop = 0, added = 0;
    if ((s = odhs__st_check_handles(st))) return s;
    if (!st->ready && (s = odhs_stepper_reset(st))) return s;
    if ((s = odhs__st_save(st))) return s;
    const int jammed0 = st->jammed;
    st->nchg = 0;
    st->chg_mark = 0;
    if ((s = odhs__st_correct(st, &added))) goto fail;
    if ((s = odhs__st_rewire(st)) || (s = check_flow(st))) goto fail;
    if ((s = odhs__st_emit_events(st, NULL, &stop))) goto fail;
    if (st->jammed) return ODHS_JAMMED;
    return stop ? ODHS_STOPPED : ODHS_OK;
fail:
    odhs__st_rollback(st);
    st->jammed = jammed0;
    st->nchg = 0;
    st->chg_mark = 0;
    return s;
}

int odhs_stepper_step(odhs_stepper *st, odhs_event *ev)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    int stop = 0;
    int s = do_step(st, INFINITY, ev, &stop);
    if (s) return s;
    st->errmsg[0] = '\0';
    return stop ? ODHS_STOPPED : ODHS_OK;
}

/* the fields of odhs_step_info the caller's size must at least cover */
#define STEP_INFO_MIN (offsetof(odhs_step_info, kind) + sizeof(int))

int odhs_stepper_step_ex(odhs_stepper *st, odhs_step_info *info)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!info) return odhs__sterr(st, ODHS_E_NULL, "step info pointer is NULL");
    size_t size = info->size;
    if (size < STEP_INFO_MIN)
        return odhs__sterr(st, ODHS_E_INVALID,
                           "odhs_step_info.size = %zu: set it to sizeof(odhs_step_info) (at least %zu)", size,
                           (size_t)STEP_INFO_MIN);
    odhs_step_info r;
    memset(&r, 0, sizeof r);
    odhs_event first;
    const double t0 = st->time, g0 = st->strain;
    const uint64_t c0 = st->ncoll, o0 = st->nopen;
    int stop = 0;
    int s = do_step(st, INFINITY, &first, &stop);
    if (s < 0) return s;
    r.size = size;
    r.kind = first.kind;
    r.i = first.i;
    r.j = first.j;
    r.event_time = first.time;
    r.event_strain = first.strain;
    r.collisions = st->ncoll - c0;
    r.openings = st->nopen - o0;
    r.time_start = t0;
    r.time_end = st->time;
    r.strain_start = g0;
    r.strain_end = st->strain;
    r.advanced = st->time != t0;
    r.driver_change = st->last_driver_only;
    /* only the bytes the caller's struct has: an older caller's smaller
     * struct is filled up to its size, a newer caller's tail left alone */
    memcpy(info, &r, size < sizeof r ? size : sizeof r);
    if (s) return s; /* ODHS_JAMMED, ODHS_POTENTIALLY_JAMMED: the step was taken */
    st->errmsg[0] = '\0';
    return stop ? ODHS_STOPPED : ODHS_OK;
}

/* No event can ever happen: nothing in the scene changes with time (no
 * flow, no pressure control, no callback, no self-propulsion) and every
 * particle moves with the same velocity (or none, with walls): the
 * configuration only translates, so no gap ever changes. */
static int no_event_possible(const odhs_stepper *st)
{
    const odhs_driver *d = st->drv;
    if (d->gdot != 0.0 || d->crate != 0.0 || d->pressure_on || d->osc_shape || d->fn || d->prop_on) return 0;
    int dim = st->dim;
    for (size_t i = 1; i < st->n; ++i)
        for (int k = 0; k < dim; ++k)
            if (st->U[i * dim + k] != st->U[k]) return 0;
    if (st->net->nwalls)
        for (int k = 0; k < dim; ++k)
            if (st->U[k] != 0.0) return 0;
    return 1;
}

/* generic run loop: remaining() gives the time left to the target (<= 0:
 * done); max_events > 0 runs for that many events. Guards: the user's step
 * cap (ODHS_STEP_LIMIT), a target too many steps away (ODHS_E_INVALID), no
 * progress (ODHS_E_STALLED): stall_steps steps in a row that move neither
 * the time, the strain nor the event count, or, for an event count, a scene
 * in which no event can happen. */
typedef double (*remaining_fn)(const odhs_stepper *st, const void *arg);

static int run(odhs_stepper *st, remaining_fn rem, const void *arg, uint64_t max_events)
{
    int s;
    if ((s = odhs__st_check_handles(st))) return s;
    if (!st->ready && (s = odhs_stepper_reset(st))) return s;
    uint64_t ev0 = st->ncoll + st->nopen, nstep = 0, stalled = 0;
    if (rem) {
        double left = rem(st, arg), big = 1e15 * st->dt * st->tau;
        if (isfinite(left) && left > big)
            return odhs__sterr(st, ODHS_E_INVALID,
                               "the target is %g time units away, more than 1e15 of the largest steps (dt * tau = "
                               "%g): raise dt or set a time unit (odhs_driver_set_time_unit)",
                               left, st->dt * st->tau);
    }
    for (;;) {
        double left = rem ? rem(st, arg) : INFINITY;
        if (!(left > 0.0)) break;
        if (max_events && st->ncoll + st->nopen - ev0 >= max_events) break;
        if (max_events && !st->jammed && no_event_possible(st))
            return odhs__sterr(st, ODHS_E_STALLED,
                               "no event can happen: no flow, no pressure control, forces that do not change with "
                               "time, and every particle moving with the same velocity (%zu events of %llu taken)",
                               (size_t)(st->ncoll + st->nopen - ev0), (unsigned long long)max_events);
        if (st->max_steps && nstep >= st->max_steps)
            return odhs__sterr(st, ODHS_STEP_LIMIT, "the run took its limit of %llu steps before its target",
                               (unsigned long long)st->max_steps);
        const double t0 = st->time, g0 = st->strain;
        const uint64_t e0 = st->ncoll + st->nopen;
        int stop = 0;
        s = do_step(st, left, NULL, &stop);
        if (s) return s;
        nstep++;
        if (st->time != t0 || st->strain != g0 || st->ncoll + st->nopen != e0) stalled = 0;
        else if (st->stall_steps && ++stalled >= st->stall_steps)
            return odhs__sterr(st, ODHS_E_STALLED,
                               "no progress: %llu steps in a row moved neither the time (%.17g), the strain nor the "
                               "event count; the step dt * tau = %g is below the resolution of the time",
                               (unsigned long long)stalled, st->time, st->dt * st->tau);
        if (stop) return ODHS_STOPPED;
    }
    st->errmsg[0] = '\0';
    return ODHS_OK;
}

static double rem_time(const odhs_stepper *st, const void *arg)
{
    double t = *(const double *)arg;
    double left = t - st->time;
    return left > 1e-15 * fabs(t) ? left : 0.0;
}

int odhs_stepper_run_until_time(odhs_stepper *st, double t)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(t)) return odhs__sterr(st, ODHS_E_NONFINITE, "target time is not finite");
    return run(st, rem_time, &t, 0);
}

static double rem_strain(const odhs_stepper *st, const void *arg)
{
    return odhs__flow_time_to_strain(st->drv, st->time, st->strain, *(const double *)arg);
}

int odhs_stepper_run_until_strain(odhs_stepper *st, double gamma)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(gamma)) return odhs__sterr(st, ODHS_E_NONFINITE, "target strain is not finite");
    int s = odhs__flow_check_strain_target(st->drv, st->errmsg);
    if (s) return s;
    return run(st, rem_strain, &gamma, 0);
}

int odhs_stepper_run_events(odhs_stepper *st, uint64_t count)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (count == 0) return ODHS_OK;
    return run(st, NULL, NULL, count);
}

static double rem_phi(const odhs_stepper *st, const void *arg)
{
    double target = *(const double *)arg, phi;
    odhs_system_packing_fraction(st->sys, &phi);
    if (phi >= target * (1.0 - 1e-15)) return 0.0;
    double c = -st->G[3 * (1) + (1)]; /* current isotropic compression rate */
    if (!(c > 0.0)) return INFINITY;
    /* phi grows as (1 - c t)^(-d) over a straight step */
    return (1.0 - pow(phi / target, 1.0 / st->dim)) / c;
}

int odhs_stepper_run_until_packing_fraction(odhs_stepper *st, double phi)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!isfinite(phi)) return odhs__sterr(st, ODHS_E_NONFINITE, "target packing fraction is not finite");
    if (!(phi > 0.0) || phi >= 1.0) return odhs__sterr(st, ODHS_E_INVALID, "packing fraction must be in (0,1)");
    if (st->drv->crate <= 0.0 && !st->drv->pressure_on)
        return odhs__sterr(st, ODHS_E_STATE, "run_until_packing_fraction needs compression or pressure driving");
    return run(st, rem_phi, &phi, 0);
}
