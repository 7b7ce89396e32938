/*
 * libodhs - libFuzzer target for the run loops (stepper.h): no input hangs.
 *
 * Each input is read as a little program: a scene (dimension, N, packing
 * fraction, size ratio, seed), a driver (mobility, shear and compression
 * rates, pressure, fixed forces of any scale from 1e-320 to 1e300 or zero,
 * a force callback, gravity, self-propulsion, a time unit), stepper settings
 * (integrator, dt from 1e-300 to 1e3, tolerance, run limits) and up to 8
 * run calls (run_until_time, _strain, _packing_fraction, run_events, step,
 * step_ex, correct, reset) with targets a bounded number of largest steps
 * away, with driver changes between them. Every call must return a
 * documented status; after a run returns the time must not have gone back,
 * a successful run_until_time must have landed on its target (to the
 * 1e-15 relative tolerance of the run loop), and the
 * stepper must still answer queries. The time bound per input is libFuzzer's
 * -timeout (make fuzz-ci: FUZZ_UNIT_TIMEOUT = 25 s). Every run is capped at
 * FUZZ_MAX_STEPS steps (odhs_stepper_set_run_limits), since a run that
 * progresses may legitimately be long; a run that reaches the cap must have
 * progressed (time, strain or events): one that does not is ended earlier by
 * the stall guard, with ODHS_E_STALLED, which is what this target checks.
 *
 * Build and run: `make fuzz`, then build-fuzz/fuzz_run DIR; `make fuzz-ci`.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"

typedef struct {
    const uint8_t *p;
    size_t n, pos;
} rd;

static unsigned u8(rd *r) { return r->pos < r->n ? r->p[r->pos++] : 0u; }
static unsigned u16(rd *r) { return u8(r) | (u8(r) << 8); }
/* a value in [0, 1) */
static double unit(rd *r) { return u16(r) / 65536.0; }
/* 10^(lo + (hi - lo) u) */
static double logval(rd *r, double lo, double hi) { return pow(10.0, lo + (hi - lo) * unit(r)); }

/* every run call is capped (the step limit): a run that progresses may
 * legitimately take long (a strain of 1e11 to reach a packing fraction under
 * a shear rate of 1e14); one that does not must be ended by the stall guard
 * (stall_steps <= 400 < FUZZ_MAX_STEPS) or the no-event check */
#define FUZZ_MAX_STEPS 500

#define FAIL(...)                                                                                                    \
    do {                                                                                                             \
        fprintf(stderr, "fuzz_run: " __VA_ARGS__);                                                                   \
        fprintf(stderr, "\n");                                                                                       \
        abort();                                                                                                     \
    } while (0)

static int documented(int s)
{
    switch (s) {
    case ODHS_OK: case ODHS_STOPPED: case ODHS_POTENTIALLY_JAMMED: case ODHS_JAMMED: case ODHS_STEP_LIMIT:
    case ODHS_E_INVALID: case ODHS_E_NOMEM: case ODHS_E_NONFINITE: case ODHS_E_STATE: case ODHS_E_SINGULAR:
    case ODHS_E_NOCONV: case ODHS_E_REWIRE: case ODHS_E_CALLBACK: case ODHS_E_UNSUPPORTED: case ODHS_E_STALLED:
    case ODHS_E_DIM: case ODHS_E_BOX: /* a box compressed below two diameters */
        return 1;
    default:
        return 0;
    }
}

/* a pure force callback: a shear-like swirl of amplitude *ctx */
static int swirl(double t, const odhs_system *sys, double *F, void *ctx)
{
    double a = *(const double *)ctx, x[3 * 16], L[3];
    size_t n = odhs_system_count(sys);
    int dim = odhs_system_dim(sys);
    odhs_system_get_positions(sys, x);
    odhs_system_get_box(sys, L);
    for (size_t i = 0; i < n; ++i)
        for (int k = 0; k < dim; ++k)
            F[i * dim + k] = a * sin(6.283185307179586 * x[i * dim + (k + 1) % dim] / L[(k + 1) % dim] + 0.1 * t);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    rd r = {data, size, 0};
    int dim = 2 + (u8(&r) & 1);
    size_t n = 2 + u8(&r) % 15;
    double phi = 0.05 + 0.6 * unit(&r) * (dim == 2 ? 1.0 : 0.8);
    double ratio = 1.0 + 2.0 * unit(&r);
    uint64_t seed = u16(&r);
    odhs_system *sys = NULL;
    odhs_driver *drv = NULL;
    odhs_solver *sol = NULL;
    odhs_stepper *st = NULL;
    if (odhs_system_create(dim, n, &sys)) FAIL("system_create");
    if (odhs_system_set_radii_bidisperse(sys, 0.5, ratio, 0.0, seed) ||
        odhs_system_place_random(sys, phi, seed) != ODHS_OK)
        goto done; /* too dense for random placement: not this target's business */
    if (odhs_driver_create(&drv) || odhs_solver_create_by_name((u8(&r) & 1) ? "dense" : "auto", &sol) ||
        odhs_stepper_create(sys, drv, sol, &st))
        FAIL("create: %s", odhs_last_error());
    double amp = 0.0, F[3 * 16];
    unsigned flags = u16(&r);
    if (flags & 1) odhs_driver_set_mobility(drv, logval(&r, -3, 3));
    if (flags & 2) odhs_driver_set_shear_rate(drv, (flags & 4) ? logval(&r, -300, 300) : unit(&r) - 0.5);
    if (flags & 8) odhs_driver_set_compression_rate(drv, logval(&r, -8, 2));
    if (flags & 16) odhs_driver_set_pressure(drv, logval(&r, -3, 4));
    if (flags & 32) {
        double scale = (flags & 64) ? logval(&r, -320, 300) : 0.0;
        for (size_t k = 0; k < n * (size_t)dim; ++k) F[k] = scale * (unit(&r) - 0.5);
        odhs_driver_set_forces(drv, n, dim, F);
    }
    if (flags & 128) {
        amp = logval(&r, -6, 6);
        odhs_driver_set_force_callback(drv, swirl, &amp);
    }
    if (flags & 256) {
        double g[3] = {0.0, -logval(&r, -6, 6), 0.0};
        odhs_driver_set_gravity(drv, dim, g);
    }
    if (flags & 512) odhs_driver_set_self_propulsion(drv, n, dim, 0.0, logval(&r, -3, 3), 0.1, 1.0, seed);
    if (flags & 1024) odhs_driver_set_time_unit(drv, logval(&r, -300, 300));
    odhs_stepper_set_integrator(st, (flags & 2048) ? ODHS_INTEGRATOR_EULER : ODHS_INTEGRATOR_HEUN);
    if (flags & 4096) odhs_stepper_set_dt(st, logval(&r, -300, 3));
    if (flags & 8192) odhs_stepper_set_tolerance(st, logval(&r, -12, -1));
    uint64_t stall = (flags & 16384) ? 1 + u8(&r) : 400; /* below FUZZ_MAX_STEPS */
    odhs_stepper_set_run_limits(st, FUZZ_MAX_STEPS, stall);

    int ncalls = 1 + u8(&r) % 8;
    for (int c = 0; c < ncalls && r.pos < r.n; ++c) {
        unsigned op = u8(&r) % 9;
        double t0, t1, g0, g1, step, dt, tau = 1.0;
        uint64_t c0, o0, c1, o1, n0, n1;
        odhs_stepper_counts(st, &n0, &c0, &o0);
        const uint64_t ev0 = c0 + o0;
        odhs_stepper_time(st, &t0);
        odhs_stepper_strain(st, &g0);
        odhs_stepper_get_settings(st, NULL, &dt, NULL, NULL);
        odhs_driver_time_unit(drv, sys, &tau);
        step = dt * tau;
        uint64_t k = 1 + u8(&r); /* targets at most 256 largest steps away */
        int s = ODHS_OK;
        double target = NAN;
        switch (op) {
        case 0: target = t0 + (double)k * step; s = odhs_stepper_run_until_time(st, target); break;
        case 1: s = odhs_stepper_run_until_strain(st, g0 + 1e-3 * (double)k); break;
        case 2: {
            double p;
            odhs_system_packing_fraction(sys, &p);
            s = odhs_stepper_run_until_packing_fraction(st, fmin(0.95, p * (1.0 + 1e-3 * (double)k)));
            break;
        }
        case 3:
            s = odhs_stepper_run_events(st, 1 + k % 8);
            break;
        case 4: s = odhs_stepper_step(st, NULL); break;
        case 5: {
            odhs_step_info in;
            memset(&in, 0, sizeof in);
            in.size = sizeof in;
            s = odhs_stepper_step_ex(st, &in);
            if (s >= 0 && (in.time_end < in.time_start || in.advanced != (in.time_end > in.time_start)))
                FAIL("step_ex: times %g -> %g, advanced %d", in.time_start, in.time_end, in.advanced);
            break;
        }
        case 6: s = odhs_stepper_correct(st); break;
        case 7: s = odhs_stepper_reset(st); break;
        default: /* the framework changes the driving */
            odhs_driver_set_shear_rate(drv, unit(&r) - 0.5);
            if (u8(&r) & 1) odhs_driver_clear_time_unit(drv);
            break;
        }
        if (!documented(s)) FAIL("op %u returned %d (%s): %s", op, s, odhs_strerror(s), odhs_stepper_errmsg(st));
        if (s < 0 && !odhs_stepper_errmsg(st)[0] && s != ODHS_E_NOMEM)
            FAIL("op %u returned %d with no message", op, s);
        odhs_stepper_time(st, &t1);
        odhs_stepper_strain(st, &g1);
        odhs_stepper_counts(st, &n1, &c1, &o1);
        const uint64_t ev1 = c1 + o1;
        /* a run capped by the step limit made progress on its way: without
         * progress the stall guard (stall < FUZZ_MAX_STEPS) ends it first */
        if (s == ODHS_STEP_LIMIT && !(t1 > t0 || g1 != g0 || ev1 != ev0))
            FAIL("op %u took %llu steps without progress and was not stalled", op, (unsigned long long)(n1 - n0));
        if (!(t1 >= t0)) FAIL("op %u: time went back from %.17g to %.17g", op, t0, t1);
        /* landed on the target to the run's 1e-15 relative tolerance */
        if (op == 0 && s == ODHS_OK && !(fabs(t1 - target) <= 2e-15 * fabs(target)))
            FAIL("run_until_time(%.17g) returned OK at t = %.17g", target, t1);
        if (!isfinite(t1) || !isfinite(g1)) FAIL("op %u: time %g strain %g", op, t1, g1);
        if (s == ODHS_JAMMED || s == ODHS_POTENTIALLY_JAMMED) break;
    }
done:
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    return 0;
}
