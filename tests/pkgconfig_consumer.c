/*
 * libodhs - minimal outside consumer, built against the staged install with
 * nothing but pkg-config (shared, static archive, fully static) and with the
 * link lines of docs/guide.md and README.md: see tests/link_check.sh
 * (`make check-link`, `make pkgconfig-test`).
 *
 * Checks that the header and the linked library agree, then shears a small
 * packing with every built-in solver backend, so that a static link has to
 * resolve LAPACKE and, in a SuiteSparse build, CHOLMOD and SPQR, and that
 * they run. A backend the library was built without (ODHS_E_NOTINSTALLED)
 * is reported and skipped.
 */
#include <odhs.h>

#include <stdio.h>
#include <string.h>

/* 48 discs at phi = 0.52 sheared to a strain of 0.05 with one backend, which
 * must have solved for contact forces at least once. */
static int shear_with(const char *backend)
{
    odhs_system *sys = NULL;
    odhs_driver *drv = NULL;
    odhs_solver *solver = NULL;
    odhs_stepper *st = NULL;
    double z = 0.0, solves = 0.0;
    int rc = odhs_solver_create_by_name(backend, &solver);
    if (rc == ODHS_E_NOTINSTALLED) {
        printf("  %-12s not in this build\n", backend);
        return 0;
    }
    if (rc == ODHS_OK) rc = odhs_system_create(2, 48, &sys);
    if (rc == ODHS_OK) rc = odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, 11);
    if (rc == ODHS_OK) rc = odhs_system_place_random(sys, 0.52, 11);
    if (rc == ODHS_OK) rc = odhs_driver_create(&drv);
    if (rc == ODHS_OK) rc = odhs_driver_set_shear_rate(drv, 1.0);
    if (rc == ODHS_OK) rc = odhs_stepper_create(sys, drv, solver, &st);
    if (rc == ODHS_OK) rc = odhs_stepper_run_until_strain(st, 0.05);
    if (rc >= 0) rc = odhs_stepper_coordination(st, &z);
    if (rc >= 0) rc = odhs_solver_get_stat(solver, "solves", &solves);
    printf("  %-12s %s, z = %g, %.0f solves\n", backend, odhs_strerror(rc), z, solves);
    odhs_stepper_destroy(st);
    odhs_solver_destroy(solver);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
    if (rc < 0) {
        fprintf(stderr, "pkgconfig_consumer: backend %s failed: %s\n", backend, odhs_strerror(rc));
        return 1;
    }
    if (!(solves > 0.0)) {
        fprintf(stderr, "pkgconfig_consumer: backend %s: no solve (no contact)\n", backend);
        return 1;
    }
    return 0;
}

int main(void)
{
    static const char *const backends[] = {"dense", "cg", "cholmod", "cholmod-pcg", "spqr", "auto"};
    const char *rt = odhs_version_string();
    int failed = 0;
    printf("libodhs run-time version %s, header version %s\n",
           rt ? rt : "(null)", ODHS_VERSION_STRING);
    if (rt == NULL || strcmp(rt, ODHS_VERSION_STRING) != 0) {
        fprintf(stderr, "pkgconfig_consumer: version mismatch\n");
        return 1;
    }
    if (odhs_version_number() != ODHS_VERSION_NUMBER) {
        fprintf(stderr, "pkgconfig_consumer: version number mismatch\n");
        return 1;
    }
    for (size_t i = 0; i < sizeof backends / sizeof backends[0]; i++)
        failed += shear_with(backends[i]);
    return failed != 0;
}
