/* libodhs - the paper's scheme as a step type: explicit Euler with a fixed
 * step dt (in units of tau), the straight chord of the start velocities
 * truncated at the first collision (Sect. IV A). */
#include <string.h>

#include "stepper/stepper.h"

static int euler_plan(odhs_stepper *st, odhs__step_plan *p)
{
    p->tplan = st->dt * st->tau;
    if (p->limit < p->tplan) p->tplan = p->limit;
    memcpy(p->G, st->G, sizeof p->G);
    p->vel = st->U;
    return ODHS_OK;
}

/* default drift-correction interval: the paper's 10 steps (its straight
 * chords only open contact gaps, by O(dt^2)) */
const odhs__step_type odhs__step_euler = {ODHS_INTEGRATOR_EULER, "euler", 10u, NULL, euler_plan, NULL, NULL, NULL, NULL, NULL, 1e-6, 1e-3, 1.0, 0};
