/* bench/soak - long-run soak test (issue "Reliability", long runs).
 *
 * 2D 50:50 bidisperse discs (radii 0.5/0.7, 3% polydispersity), random
 * placement at phi = 0.45, compression to PHI (default 0.80), drift
 * correction, then simple shear at fixed volume (gammadot = 1, Euler, dt =
 * 1e-3 tau, drift correction every 10 steps, the library's defaults) until
 * EVENTS collisions + openings have happened. After EVERY step (so after
 * every event) the invariants are checked:
 *   - overlap: the largest overlap -gap/(a_i+a_j) over all pairs
 *     (odhs_stepper_errors, cell lists over all pairs);
 *   - contact gap drift: the largest |gap|/(a_i+a_j) over the contacts, which
 *     grows between drift corrections (Sect. IV C);
 *   - forces: the most negative contact force relative to the largest one
 *     (the valid network has f >= 0);
 *   - power balance: dissipation D = xi0^-1 sum |V - V_aff|^2 against the
 *     power of the driver P (odhs_stepper_power) and against
 *     sigma_xy gammadot Omega, relative to max(|D|, |P|);
 *   - every status is ODHS_OK and every number finite.
 * A violation beyond the tolerances (overlap 1e-9, contact gap 1e-2 (a sanity bound: the Euler drift between corrections is O(dt^2 |U|^2)), force
 * -1e-9, power 1e-8) stops the run with exit status 1. The worst values are
 * reported for each tenth of the run, which shows whether anything drifts.
 *
 * usage: soak [EVENTS] [N] [SOLVER] [PHI]   (defaults 1000000, 128, cholmod
 *        when built with SuiteSparse else dense, 0.80)
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>

#include "bench.h"
#include "odhs.h"

#define TOL_OVERLAP 1e-9
#define TOL_GAP 1e-2
#define TOL_NEGF 1e-9
#define TOL_POWER 1e-8
#define NSLICE 10

#define OK(call)                                                                                 \
    do {                                                                                         \
        int rc_ = (call);                                                                        \
        if (rc_ != ODHS_OK) {                                                                    \
            fprintf(stderr, "soak: %s -> %d (%s)\n", #call, rc_, odhs_strerror(rc_));            \
            exit(1);                                                                             \
        }                                                                                        \
    } while (0)

typedef struct {
    double overlap, gap, negf, power, power_s, zmin, zmax, sxy_sum;
    uint64_t events, steps;
    double t0, t1;
} slice;

static uint64_t nevents;
static int count_event(const odhs_event *ev, void *ctx)
{
    (void)ev;
    (void)ctx;
    ++nevents;
    return 0;
}

int main(int argc, char **argv)
{
    uint64_t target = argc > 1 ? strtoull(argv[1], NULL, 10) : 1000000u;
    size_t n = argc > 2 ? (size_t)strtoul(argv[2], NULL, 10) : 128;
    const char *solver = "cholmod"; /* "dense" when not built in */
    if (argc > 3) solver = argv[3];
    double phi = argc > 4 ? atof(argv[4]) : 0.80;
    if (target == 0 || n < 2 || !(phi > 0.0 && phi < 0.9)) {
        fprintf(stderr, "usage: soak [EVENTS] [N] [SOLVER] [PHI]\n");
        return 2;
    }
    odhs_solver *sol;
    int rc = odhs_solver_create_by_name(solver, &sol);
    if (rc == ODHS_E_NOTINSTALLED && argc <= 3) {
        solver = "dense";
        rc = odhs_solver_create_by_name(solver, &sol);
    }
    if (rc) {
        fprintf(stderr, "soak: solver %s: %s\n", solver, odhs_strerror(rc));
        return 2;
    }
    char cpu[256];
    bench_cpu_model(cpu, sizeof cpu);
    printf("# soak: %s, libodhs %s\n", cpu, odhs_version_string());
    printf("# 2D bidisperse N=%zu phi=%.4f, shear gdot=1, Euler dt=1e-3, correction every 10 steps, solver %s\n", n,
           phi, solver);
    printf("# target %llu events; invariants checked after every step\n", (unsigned long long)target);

    odhs_system *sys;
    odhs_driver *drv;
    odhs_stepper *st;
    OK(odhs_system_create(2, n, &sys));
    OK(odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, 42));
    OK(odhs_system_place_random(sys, 0.45, 43));
    OK(odhs_driver_create(&drv));
    OK(odhs_driver_set_compression_rate(drv, 1.0));
    OK(odhs_stepper_create(sys, drv, sol, &st));
    OK(odhs_stepper_run_until_packing_fraction(st, phi));
    OK(odhs_stepper_correct(st));
    OK(odhs_driver_set_compression_rate(drv, 0.0));
    OK(odhs_driver_set_shear_rate(drv, 1.0));
    OK(odhs_stepper_reset(st));
    OK(odhs_stepper_set_event_callback(st, count_event, NULL));
    uint64_t ns0, nco0, nop0;
    OK(odhs_stepper_counts(st, &ns0, &nco0, &nop0));
    double phi_now, vol;
    OK(odhs_system_packing_fraction(sys, &phi_now));
    OK(odhs_system_volume(sys, &vol));

    slice sl[NSLICE];
    memset(sl, 0, sizeof sl);
    for (int k = 0; k < NSLICE; ++k) sl[k].zmin = INFINITY;
    double *f = NULL;
    size_t fcap = 0;
    uint64_t steps = 0;
    double t_start = bench_wall();
    int cur = 0;
    sl[0].t0 = t_start;
    nevents = 0;
    while (nevents < target) {
        rc = odhs_stepper_step(st, NULL);
        if (rc != ODHS_OK) {
            fprintf(stderr, "soak: step %llu after %llu events: %d (%s): %s\n", (unsigned long long)steps,
                    (unsigned long long)nevents, rc, odhs_strerror(rc), odhs_stepper_errmsg(st));
            return 1;
        }
        ++steps;
        int k = (int)((double)nevents * NSLICE / (double)target);
        if (k >= NSLICE) k = NSLICE - 1;
        if (k != cur) {
            sl[cur].t1 = bench_wall();
            sl[k].t0 = sl[cur].t1;
            cur = k;
        }
        slice *s = &sl[k];
        s->steps++;
        /* invariants */
        double cgap, ov, D, P, sxy, z;
        OK(odhs_stepper_errors(st, &cgap, &ov));
        OK(odhs_stepper_dissipation(st, &D));
        OK(odhs_stepper_power(st, &P));
        OK(odhs_stepper_shear_stress(st, &sxy));
        OK(odhs_stepper_coordination(st, &z));
        const odhs_network *net = odhs_stepper_network(st);
        size_t nc = odhs_network_count(net);
        if (nc + 1 > fcap) {
            fcap = 2 * (nc + 1);
            f = realloc(f, fcap * sizeof *f);
            if (!f) return 1;
        }
        OK(odhs_network_get_forces(net, f));
        double flo = 0.0, fmaxv = 0.0;
        for (size_t c = 0; c < nc; ++c) {
            if (!isfinite(f[c])) {
                fprintf(stderr, "soak: non-finite force\n");
                return 1;
            }
            flo = flo < f[c] ? flo : f[c];
            fmaxv = fmaxv > f[c] ? fmaxv : f[c];
        }
        double negf = fmaxv > 0.0 ? fmax(0.0, -flo / fmaxv) : 0.0;
        double Ps = sxy * 1.0 * vol;
        double sc = fmax(fabs(D), fabs(P));
        double pe = sc > 0.0 ? fabs(D - P) / sc : 0.0, pes = sc > 0.0 ? fabs(D - Ps) / sc : 0.0;
        if (!isfinite(cgap) || !isfinite(ov) || !isfinite(D) || !isfinite(P) || !isfinite(sxy)) {
            fprintf(stderr, "soak: non-finite observable at step %llu\n", (unsigned long long)steps);
            return 1;
        }
        s->overlap = fmax(s->overlap, ov);
        s->gap = fmax(s->gap, cgap);
        s->negf = fmax(s->negf, negf);
        s->power = fmax(s->power, pe);
        s->power_s = fmax(s->power_s, pes);
        s->zmin = fmin(s->zmin, z);
        s->zmax = fmax(s->zmax, z);
        s->sxy_sum += sxy;
        if (ov > TOL_OVERLAP || cgap > TOL_GAP || negf > TOL_NEGF || pe > TOL_POWER || pes > TOL_POWER) {
            fprintf(stderr,
                    "soak: invariant violated at step %llu, event %llu: overlap %.3g gap %.3g negf %.3g power %.3g "
                    "%.3g\n",
                    (unsigned long long)steps, (unsigned long long)nevents, ov, cgap, negf, pe, pes);
            return 1;
        }
    }
    double t_end = bench_wall();
    sl[cur].t1 = t_end;
    /* events per slice from the event counter is not kept per slice: the
     * slice boundaries are event counts, so each slice holds target/NSLICE */
    uint64_t ns, nco, nop;
    OK(odhs_stepper_counts(st, &ns, &nco, &nop));
    double strain, phi_end;
    OK(odhs_stepper_strain(st, &strain));
    OK(odhs_system_packing_fraction(sys, &phi_end));
    printf("# slice = one tenth of the events; worst values in the slice\n");
    printf("%5s %9s %10s %10s %10s %10s %10s %6s %6s %11s %9s\n", "slice", "steps", "overlap", "contact_gap",
           "neg_force", "D-P", "D-sxy*g*V", "zmin", "zmax", "<sigma_xy>", "events/s");
    slice tot;
    memset(&tot, 0, sizeof tot);
    tot.zmin = INFINITY;
    for (int k = 0; k < NSLICE; ++k) {
        slice *s = &sl[k];
        double dt = s->t1 - s->t0;
        printf("%5d %9llu %10.2e %10.2e %10.2e %10.2e %10.2e %6.3f %6.3f %11.4e %9.0f\n", k,
               (unsigned long long)s->steps, s->overlap, s->gap, s->negf, s->power, s->power_s, s->zmin, s->zmax,
               s->steps ? s->sxy_sum / (double)s->steps : 0.0, dt > 0 ? (double)target / NSLICE / dt : 0.0);
        tot.overlap = fmax(tot.overlap, s->overlap);
        tot.gap = fmax(tot.gap, s->gap);
        tot.negf = fmax(tot.negf, s->negf);
        tot.power = fmax(tot.power, s->power);
        tot.power_s = fmax(tot.power_s, s->power_s);
        tot.zmin = fmin(tot.zmin, s->zmin);
        tot.zmax = fmax(tot.zmax, s->zmax);
        tot.sxy_sum += s->sxy_sum;
        tot.steps += s->steps;
    }
    printf("%5s %9llu %10.2e %10.2e %10.2e %10.2e %10.2e %6.3f %6.3f %11.4e %9.0f\n", "all", (unsigned long long)steps,
           tot.overlap, tot.gap, tot.negf, tot.power, tot.power_s, tot.zmin, tot.zmax, tot.sxy_sum / (double)steps,
           (double)nevents / (t_end - t_start));
    printf("# shear: events %llu (collisions %llu, openings %llu), steps %llu, strain %.6g, phi start %.12f end %.12f "
           "(drift %.2e), wall %.1f s\n",
           (unsigned long long)nevents, (unsigned long long)(nco - nco0), (unsigned long long)(nop - nop0),
           (unsigned long long)(ns - ns0), strain,
           phi_now, phi_end, phi_end - phi_now, t_end - t_start);
    printf("# tolerances: overlap %.0e, contact gap %.0e, negative force %.0e, power %.0e: all held\n", TOL_OVERLAP,
           TOL_GAP, TOL_NEGF, TOL_POWER);
    free(f);
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    odhs_solver_destroy(sol);
    return 0;
}
