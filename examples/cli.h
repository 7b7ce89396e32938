/* cli.h - small helpers shared by the example programs: number parsing and
 * the built-in scene (header-only, so each example stays one file to build:
 * cc example.c $(pkg-config --cflags --libs odhs) -lm). */
#ifndef ODHS_EXAMPLES_CLI_H
#define ODHS_EXAMPLES_CLI_H

#include <errno.h>
#include <math.h>
#include <stdlib.h>

#include <odhs.h>

/* a finite double taking the whole string; 0 on success */
static inline int cli_double(const char *s, double *out)
{
    char *end;
    errno = 0;
    double v = strtod(s, &end);
    if (errno || end == s || *end || !isfinite(v)) return -1;
    *out = v;
    return 0;
}

/* a non-negative integer taking the whole string; 0 on success */
static inline int cli_ulong(const char *s, unsigned long *out)
{
    char *end;
    errno = 0;
    unsigned long v = strtoul(s, &end, 10);
    if (errno || end == s || *end || s[0] == '-') return -1;
    *out = v;
    return 0;
}

/* The examples' built-in scene: 50:50 bidisperse radii 0.5/0.7 with 3%
 * polydispersity, placed at random at phi = 0.45 (2D) or 0.30 (3D), or at
 * phi_max if that is lower. Returns ODHS_OK or an error (the message is in
 * the system handle when *out is not NULL). */
static inline int cli_scene(int dim, unsigned long n, unsigned long seed, double phi_max, odhs_system **out)
{
    double phi0 = dim == 2 ? 0.45 : 0.30;
    if (phi_max < phi0) phi0 = phi_max;
    int rc = odhs_system_create(dim, n, out);
    if (rc) return rc;
    if ((rc = odhs_system_set_radii_bidisperse(*out, 0.5, 1.4, 0.03, seed))) return rc;
    return odhs_system_place_random(*out, phi0, seed + 1);
}

/* The solver the examples use close to jamming: CHOLMOD as a preconditioner
 * for CG when the library has it, else dense Cholesky for small systems and
 * CG for large ones (CG alone stalls close to jamming). */
static inline const char *cli_default_solver(size_t n)
{
    odhs_solver *s;
    if (odhs_solver_create_by_name("cholmod-pcg", &s) == ODHS_OK) {
        odhs_solver_destroy(s);
        return "cholmod-pcg";
    }
    return n <= 2000 ? "dense" : "cg";
}

#endif /* ODHS_EXAMPLES_CLI_H */
