/* minimal - the twenty-line example of README.md (kept identical to it). */
#include <odhs.h>
#include <stdio.h>
#include <string.h>

int main(int argc, char **argv)
{
    if (argc > 1) {                    /* no options: only --help is known */
        printf("usage: %s\nshears 64 discs to a strain of 0.5\n", argv[0]);
        return strcmp(argv[1], "--help") && strcmp(argv[1], "-h") ? 2 : 0;
    }
    odhs_system *sys; odhs_driver *drv; odhs_solver *solver; odhs_stepper *st;
    odhs_system_create(2, 64, &sys);                          /* 64 discs in 2D    */
    odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, 7); /* 50:50, ratio 1.4  */
    odhs_system_place_random(sys, 0.45, 7);                   /* RSA at phi = 0.45 */
    odhs_driver_create(&drv);
    odhs_driver_set_shear_rate(drv, 1.0);                     /* Lees-Edwards shear */
    odhs_solver_create_by_name("auto", &solver);              /* automatic choice  */
    odhs_stepper_create(sys, drv, solver, &st);
    int rc = odhs_stepper_run_until_strain(st, 0.5);
    double sigma, p, z;
    odhs_stepper_shear_stress(st, &sigma); odhs_stepper_pressure(st, &p);
    odhs_stepper_coordination(st, &z);
    printf("%s: sigma = %g  p = %g  z = %g\n", odhs_strerror(rc), sigma, p, z);
    odhs_stepper_destroy(st); odhs_solver_destroy(solver);
    odhs_driver_destroy(drv); odhs_system_destroy(sys);
    return rc < 0;
}
