/* bench/scene.h - the 2D scene the validation benchmarks start from
 * (header-only, like bench.h; not installed): n discs of radii 0.5 and 0.7
 * (50:50, ratio 1.4) with uniform polydispersity poly, placed at random at
 * phi = 0.45 and compressed at rate 1 with the library's defaults (adaptive
 * Heun, the auto solver) to packing fraction phi.
 *
 *   odhs_system *sys;
 *   if (bench_disc_scene(1024, 0.03, seed, 0.83, &sys)) ...   // message on stderr
 *
 * Returns 0, or 1 after printing the library's message. */
#ifndef ODHS_BENCH_SCENE_H
#define ODHS_BENCH_SCENE_H

#include <stdio.h>

#include "odhs.h"

static inline int bench_disc_scene(size_t n, double poly, unsigned seed, double phi, odhs_system **out)
{
    odhs_system *sys = NULL;
    odhs_driver *drv = NULL;
    odhs_solver *sol = NULL;
    odhs_stepper *st = NULL;
    int rc = 1;
    *out = NULL;
    if (odhs_system_create(2, n, &sys) || odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, poly, seed) ||
        odhs_system_place_random(sys, 0.45, seed) || odhs_driver_create(&drv) ||
        odhs_driver_set_compression_rate(drv, 1.0) || odhs_solver_create_by_name("auto", &sol) ||
        odhs_stepper_create(sys, drv, sol, &st)) {
        fprintf(stderr, "scene: setup failed: %s\n", odhs_last_error());
    } else if (odhs_stepper_run_until_packing_fraction(st, phi) != ODHS_OK) {
        fprintf(stderr, "scene: compression to phi = %g failed: %s\n", phi, odhs_stepper_errmsg(st));
    } else {
        rc = 0;
    }
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_driver_destroy(drv);
    if (rc) odhs_system_destroy(sys);
    else *out = sys;
    return rc;
}

#endif
