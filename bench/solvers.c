/* bench/solvers - benchmark 1 of the sparse-direct-solver issue: time and
 * relative residual per force solve N f = b (N = S S^T) for the linear solver
 * backends on compressed bidisperse packings.
 *
 * Scenes: 50:50 bidisperse radii 0.5/0.7 (3% polydispersity,
 * odhs_system_set_radii_bidisperse(0.5, 1.4, 0.03, seed)), random placement at
 * phi = 0.45 (2D) / 0.30 (3D), event-driven compression at rate 1 to the target
 * packing fraction (odhs_stepper_run_until_packing_fraction) with the
 * cholmod-pcg backend, then odhs_stepper_correct. 2D: N = 100, 316, 1000, 3162,
 * 10000 at phi = 0.70 and 0.80. 3D: N = 100, 316, 1000, 3000 at phi = 0.55 and
 * 0.58 (phi = 0.70/0.80 lie beyond random close packing in 3D, phi_J ~ 0.64
 * for this mixture; 0.55/0.58 are at a similar distance below jamming as the
 * 2D values). The largest sizes (2D N = 10000, 3D N = 3000) are 2x2 (2x2x2)
 * periodic tilings of a compressed packing of N/4 (N/8) particles: compressing
 * them directly would take more than the whole time budget. The contact
 * network is the stepper's (copied; for tilings replicated through the
 * minimum image).
 *
 * Right-hand side: the simple-shear one, b_c = -n_cx n_cy |R_c| (gammadot = 1,
 * xi0 = 1).
 *
 * Modes (column "mode"):
 *   cold      cg from a zero guess (tol 1e-12)
 *   fresh     a new handle per solve: analysis + factorisation + solve
 *             (cholmod, dense)
 *   refactor  one cholmod handle; between solves every particle moves by up to
 *             2e-5 (after a 1e-4 dilation, so nothing overlaps): the contact
 *             list is the same, so only the numeric factorisation is redone
 *   stepper   solver time (setup + solve, measured inside the backend by a
 *             forwarding user backend) per force solve while the stepper
 *             continues the compression (rate 1, dt = 1e-3) for up to 100
 *             steps or about 3 s of solver time: every step moves all normals,
 *             collisions add contacts and the rewiring removes and re-adds
 *             them. cg is warm-started by the stepper, cholmod reuses its
 *             analysis while the contact list is unchanged, cholmod-pcg
 *             updates its factor (refactor after 50 geometry changes), dense
 *             only for Nc <= 1000. (A sheared run is not used: below jamming
 *             most contacts of the compressed packing open at once under
 *             shear, so its networks would be much smaller than the scene's.)
 * Every solve goes through odhs_solver_solve (the library's result check and,
 * for direct backends, its iterative refinement are included). "residual" is
 * the relative residual |N f - b| / |b| (largest over the stepper run).
 * "ratio" is ms/solve over the cg row of the same scene and mode class
 * (cold for the static modes, stepper for stepper).
 *
 * Times are CPU seconds of the process (the machine may be shared).
 * Plots: PREFIX_2d.svg and PREFIX_3d.svg, ms per solve against N in stepper
 * mode (every backend and packing fraction) and fresh mode (cholmod, spqr,
 * dense; cold cg).
 *
 * usage: solvers [CSV-PATH] [PREFIX]  (the table also goes to CSV-PATH if
 *        given and not ""; PREFIX default "solvers")
 * environment: ODHS_BENCH_BUDGET  seconds (default 540): rows that would start
 *              after it are skipped (and say so);
 *              ODHS_BENCH_CACHE   directory for compressed scenes (default
 *              build/bench/scenes; "" disables): a second run skips the
 *              compressions.
 */
#define _POSIX_C_SOURCE 200809L
#include <errno.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <sys/utsname.h>
#include <time.h>

#include "bench.h"
#include "odhs.h"
#include "../examples/plot.h"

#ifdef ODHS_HAVE_SUITESPARSE
#if defined(__GNUC__)
#pragma GCC diagnostic push
#pragma GCC diagnostic ignored "-Wpedantic"
#endif
#include <cholmod.h>
#if defined(__GNUC__)
#pragma GCC diagnostic pop
#endif
/* declared here until solver.h carries them */
ODHS_API extern const odhs_solver_type odhs_solver_type_cholmod;
ODHS_API extern const odhs_solver_type odhs_solver_type_cholmod_pcg;
ODHS_API extern const odhs_solver_type odhs_solver_type_spqr;
#endif

/* ---- utilities ------------------------------------------------------------ */

static double t_start, budget = 540.0;
static FILE *csv;

static int over_budget(void) { return bench_wall() - t_start > budget; }

static void machine(void)
{
    struct utsname u;
    char model[256];
    int ncpu = bench_cpu_model(model, sizeof model);
    uname(&u);
    const char *obt = getenv("OPENBLAS_NUM_THREADS");
    printf("# machine: %s (%d logical CPUs), %s %s %s\n", model, ncpu, u.sysname, u.release, u.machine);
    printf("# libodhs %s", odhs_version_string());
#ifdef ODHS_HAVE_SUITESPARSE
    printf(", CHOLMOD %d.%d.%d (SuiteSparse %d.%d.%d)", CHOLMOD_MAIN_VERSION, CHOLMOD_SUB_VERSION,
           CHOLMOD_SUBSUB_VERSION, SUITESPARSE_MAIN_VERSION, SUITESPARSE_SUB_VERSION, SUITESPARSE_SUBSUB_VERSION);
#else
    printf(", built without SuiteSparse (cholmod rows absent)");
#endif
    printf(", OPENBLAS_NUM_THREADS=%s\n", obt ? obt : "(unset)");
}

/* ---- table ------------------------------------------------------------------ */

typedef struct {
    size_t n;
    int dim;
    double phi;
    size_t nc;
    const char *solver, *mode;
    double ms, res, iters;
    int reps;
    double ratio; /* NAN: none */
    char note[256];
} row;

static void print_header(void)
{
    printf("%6s %3s %5s %6s %-12s %-9s %10s %9s %8s %5s %7s  %s\n", "N", "dim", "phi", "Nc", "solver", "mode",
           "ms/solve", "residual", "iters", "reps", "ratio", "note");
    if (csv) fprintf(csv, "N,dim,phi,Nc,solver,mode,ms_per_solve,residual,iterations,reps,ratio_to_cg,note\n");
}

#define MAXROWS 512
static row rows[MAXROWS];
static size_t nrows;

static void print_row(const row *r)
{
    if (nrows < MAXROWS) rows[nrows++] = *r;
    char ms[32], res[32], it[32], ratio[32];
    if (isnan(r->ms)) snprintf(ms, sizeof ms, "-");
    else snprintf(ms, sizeof ms, "%.3f", r->ms);
    if (isnan(r->res)) snprintf(res, sizeof res, "-");
    else snprintf(res, sizeof res, "%.1e", r->res);
    if (isnan(r->iters)) snprintf(it, sizeof it, "-");
    else snprintf(it, sizeof it, "%.1f", r->iters);
    if (isnan(r->ratio)) snprintf(ratio, sizeof ratio, "-");
    else snprintf(ratio, sizeof ratio, "%.3f", r->ratio);
    printf("%6zu %3d %5.2f %6zu %-12s %-9s %10s %9s %8s %5d %7s  %s\n", r->n, r->dim, r->phi, r->nc, r->solver,
           r->mode, ms, res, it, r->reps, ratio, r->note);
    fflush(stdout);
    if (csv) {
        fprintf(csv, "%zu,%d,%.2f,%zu,%s,%s,%s,%s,%s,%d,%s,\"%s\"\n", r->n, r->dim, r->phi, r->nc, r->solver, r->mode,
                ms, res, it, r->reps, ratio, r->note);
        fflush(csv);
    }
}

/* ---- solvers ---------------------------------------------------------------- */

static const odhs_solver_type *type_by_name(const char *name)
{
    if (!strcmp(name, "cg")) return &odhs_solver_type_cg;
    if (!strcmp(name, "dense")) return &odhs_solver_type_dense;
    if (!strcmp(name, "auto")) return &odhs_solver_type_auto;
#ifdef ODHS_HAVE_SUITESPARSE
    if (!strcmp(name, "spqr")) return &odhs_solver_type_spqr;
    if (!strcmp(name, "cholmod")) return &odhs_solver_type_cholmod;
    if (!strcmp(name, "cholmod-pcg")) return &odhs_solver_type_cholmod_pcg;
#endif
    return NULL;
}

/* A timing wrapper: a user backend that forwards to another backend and
 * measures the time spent in its setup and solve. */
static const odhs_solver_type *tw_inner;

typedef struct {
    const odhs_solver_type *inner;
    void *st;
    double t;        /* seconds in setup + solve */
    double maxres;   /* largest relative residual of the backend's solves */
    double ncsum, ncalls; /* contacts summed over solve calls, calls */
    double *Nx, *work;
    size_t cap, wcap;
} tw_state;

static tw_state *tw_live; /* the wrapper instance of the current run (one at a time) */

static int tw_create(void **state)
{
    tw_state *s = calloc(1, sizeof *s);
    if (!s) return ODHS_E_NOMEM;
    s->inner = tw_inner;
    int st = s->inner->create(&s->st);
    if (st) {
        free(s);
        return st;
    }
    *state = s;
    tw_live = s;
    return ODHS_OK;
}

static void tw_destroy(void *state)
{
    tw_state *s = state;
    if (!s) return;
    if (tw_live == s) tw_live = NULL;
    s->inner->destroy(s->st);
    free(s->Nx);
    free(s->work);
    free(s);
}

static int tw_setup(void *state, const odhs_network *net)
{
    tw_state *s = state;
    if (!s->inner->setup) return ODHS_OK;
    double t0 = bench_cpu();
    int st = s->inner->setup(s->st, net);
    s->t += bench_cpu() - t0;
    return st;
}

static int tw_solve(void *state, const odhs_network *net, const double *b, double *x)
{
    tw_state *s = state;
    double t0 = bench_cpu();
    int st = s->inner->solve(s->st, net, b, x);
    s->t += bench_cpu() - t0;
    s->ncsum += (double)odhs_network_count(net);
    s->ncalls += 1.0;
    /* residual outside the timed region */
    size_t nc = odhs_network_count(net), nd = odhs_network_particles(net) * (size_t)odhs_network_dim(net);
    if (s->cap < nc) {
        free(s->Nx);
        s->Nx = malloc(nc * sizeof *s->Nx);
        s->cap = s->Nx ? nc : 0;
    }
    if (s->wcap < nd) {
        free(s->work);
        s->work = malloc(nd * sizeof *s->work);
        s->wcap = s->work ? nd : 0;
    }
    if (st == ODHS_OK && s->Nx && s->work && odhs_network_apply_N(net, x, s->Nx, s->work) == ODHS_OK) {
        double rn = 0.0, bn = 0.0;
        for (size_t c = 0; c < nc; ++c) {
            rn += (s->Nx[c] - b[c]) * (s->Nx[c] - b[c]);
            bn += b[c] * b[c];
        }
        double r = bn > 0.0 ? sqrt(rn / bn) : sqrt(rn);
        if (r > s->maxres) s->maxres = r;
    }
    return st;
}

static int tw_set_param(void *state, const char *key, double v)
{
    tw_state *s = state;
    return s->inner->set_param ? s->inner->set_param(s->st, key, v) : ODHS_E_INVALID;
}

static int tw_get_stat(void *state, const char *key, double *v)
{
    tw_state *s = state;
    return s->inner->get_stat ? s->inner->get_stat(s->st, key, v) : ODHS_E_INVALID;
}

static odhs_solver_type tw_type = {
    .version = ODHS_SOLVER_TYPE_VERSION,
    .name = "timed",
    .create = tw_create,
    .destroy = tw_destroy,
    .setup = tw_setup,
    .solve = tw_solve,
    .set_param = tw_set_param,
    .get_stat = tw_get_stat,
};

/* ---- scenes ------------------------------------------------------------------ */

typedef struct {
    size_t i, j;
} pair;

typedef struct {
    odhs_system *sys;
    pair *c;
    size_t nc;
    char note[96];
} scene;

static void scene_free(scene *s)
{
    odhs_system_destroy(s->sys);
    free(s->c);
    memset(s, 0, sizeof *s);
}

static const char *cache_dir(void)
{
    const char *d = getenv("ODHS_BENCH_CACHE");
    return d ? d : "build/bench/scenes";
}

static void cache_paths(int dim, size_t n, double phi, char *xyz, char *con, size_t len)
{
    snprintf(xyz, len, "%s/packing_d%d_n%zu_phi%.2f.xyz", cache_dir(), dim, n, phi);
    snprintf(con, len, "%s/packing_d%d_n%zu_phi%.2f.contacts", cache_dir(), dim, n, phi);
}

static int cache_load(int dim, size_t n, double phi, scene *out)
{
    if (!*cache_dir()) return 0;
    char xyz[512], con[512];
    cache_paths(dim, n, phi, xyz, con, sizeof xyz);
    FILE *f = fopen(con, "r");
    if (!f) return 0;
    odhs_system *sys = NULL;
    if (odhs_xyz_read(xyz, &sys, NULL, 0) || odhs_system_count(sys) != n || odhs_system_dim(sys) != dim) {
        odhs_system_destroy(sys);
        fclose(f);
        return 0;
    }
    size_t nc = 0, cap = 1024;
    pair *c = malloc(cap * sizeof *c);
    size_t i, j;
    while (c && fscanf(f, "%zu %zu", &i, &j) == 2) {
        if (nc == cap) {
            pair *q = realloc(c, 2 * cap * sizeof *c);
            if (!q) break;
            c = q;
            cap *= 2;
        }
        c[nc].i = i;
        c[nc].j = j;
        nc++;
    }
    fclose(f);
    if (!c || nc == 0) {
        free(c);
        odhs_system_destroy(sys);
        return 0;
    }
    out->sys = sys;
    out->c = c;
    out->nc = nc;
    snprintf(out->note, sizeof out->note, "scene from cache");
    return 1;
}

static void cache_store(int dim, size_t n, double phi, const scene *s)
{
    const char *d = cache_dir();
    if (!*d) return;
    char path[512];
    snprintf(path, sizeof path, "%s", d);
    for (char *p = path + 1; *p; ++p)
        if (*p == '/') {
            *p = 0;
            mkdir(path, 0777);
            *p = '/';
        }
    if (mkdir(path, 0777) && errno != EEXIST) return;
    char xyz[512], con[512];
    cache_paths(dim, n, phi, xyz, con, sizeof xyz);
    if (odhs_xyz_write(s->sys, xyz)) return;
    FILE *f = fopen(con, "w");
    if (!f) return;
    for (size_t c = 0; c < s->nc; ++c) fprintf(f, "%zu %zu\n", s->c[c].i, s->c[c].j);
    fclose(f);
}

/* compress a random placement to phi; the contact list of the final network */
static int compress_scene(int dim, size_t n, double phi, uint64_t seed, scene *out)
{
    memset(out, 0, sizeof *out);
    odhs_system *sys = NULL;
    odhs_solver *sol = NULL;
    odhs_driver *drv = NULL;
    odhs_stepper *st = NULL;
    int rc = odhs_system_create(dim, n, &sys);
    if (!rc) rc = odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, seed);
    if (!rc) rc = odhs_system_place_random(sys, dim == 2 ? 0.45 : 0.30, seed + 1);
    const char *cname = "cholmod-pcg";
    const odhs_solver_type *ct = type_by_name(cname);
    if (!ct) {
        cname = "cg";
        ct = &odhs_solver_type_cg;
    }
    if (!rc) rc = odhs_solver_create(ct, &sol);
    if (!rc) rc = odhs_driver_create(&drv);
    if (!rc) rc = odhs_driver_set_compression_rate(drv, 1.0);
    if (!rc) rc = odhs_stepper_create(sys, drv, sol, &st);
    double t0 = bench_wall();
    if (!rc) rc = odhs_stepper_run_until_packing_fraction(st, phi);
    if (!rc) rc = odhs_stepper_correct(st);
    if (!rc) {
        const odhs_network *net = odhs_stepper_network(st);
        out->nc = odhs_network_count(net);
        out->c = malloc((out->nc + 1) * sizeof *out->c);
        if (!out->c) rc = ODHS_E_NOMEM;
        for (size_t c = 0; !rc && c < out->nc; ++c)
            rc = odhs_network_get_contact(net, c, &out->c[c].i, &out->c[c].j, NULL);
    }
    uint64_t steps = 0, co = 0, op = 0;
    if (st) odhs_stepper_counts(st, &steps, &co, &op);
    snprintf(out->note, sizeof out->note, "compressed in %.1f s (%s, %llu events)", bench_wall() - t0, cname,
             (unsigned long long)(co + op));
    odhs_stepper_destroy(st);
    odhs_driver_destroy(drv);
    odhs_solver_destroy(sol);
    if (rc) {
        fprintf(stderr, "compression of N=%zu dim %d to phi %.2f failed: %s\n", n, dim, phi, odhs_strerror(rc));
        odhs_system_destroy(sys);
        free(out->c);
        memset(out, 0, sizeof *out);
        return rc;
    }
    out->sys = sys;
    return ODHS_OK;
}

/* T = 2^dim periodic copies of base (strain 0) in a box of twice the edges;
 * every base contact (i,j) becomes T contacts, the partner copy of j being
 * the one at the base separation from the copy of i */
static int tile_scene(const scene *base, scene *out)
{
    memset(out, 0, sizeof *out);
    odhs_system *b = base->sys;
    int dim = odhs_system_dim(b);
    size_t n = odhs_system_count(b), T = dim == 2 ? 4 : 8, N = n * T;
    double L[3] = {1, 1, 1}, gamma;
    odhs_system_get_box(b, L);
    odhs_system_get_strain(b, &gamma);
    if (gamma != 0.0) return ODHS_E_UNSUPPORTED;
    double *x = malloc(n * dim * sizeof *x), *r = malloc(n * sizeof *r);
    double *X = malloc(N * dim * sizeof *X), *R = malloc(N * sizeof *R);
    int rc = (x && r && X && R) ? ODHS_OK : ODHS_E_NOMEM;
    if (!rc) rc = odhs_system_get_positions(b, x);
    if (!rc) rc = odhs_system_get_radii(b, r);
    for (size_t t = 0; !rc && t < T; ++t)
        for (size_t i = 0; i < n; ++i) {
            R[t * n + i] = r[i];
            for (int k = 0; k < dim; ++k) X[(t * n + i) * dim + k] = x[i * dim + k] + L[k] * (double)((t >> k) & 1);
        }
    double L2[3] = {2 * L[0], 2 * L[1], 2 * L[2]};
    if (!rc) rc = odhs_system_create(dim, N, &out->sys);
    if (!rc) rc = odhs_system_set_configuration(out->sys, L2, 0.0, R, X);
    if (!rc) {
        out->c = malloc(base->nc * T * sizeof *out->c);
        if (!out->c) rc = ODHS_E_NOMEM;
    }
    for (size_t c = 0; !rc && c < base->nc; ++c) {
        double d0;
        rc = odhs_system_separation(b, base->c[c].i, base->c[c].j, (double[3]){0, 0, 0}, &d0, NULL);
        for (size_t t = 0; !rc && t < T; ++t) {
            size_t i = t * n + base->c[c].i, best = SIZE_MAX;
            double bd = INFINITY;
            for (size_t u = 0; !rc && u < T; ++u) {
                size_t j = u * n + base->c[c].j;
                double rij[3], d;
                rc = odhs_system_separation(out->sys, i, j, rij, &d, NULL);
                if (!rc && fabs(d - d0) < bd) {
                    bd = fabs(d - d0);
                    best = j;
                }
            }
            if (!rc && bd > 1e-9) rc = ODHS_E_INTERNAL;
            if (!rc) {
                out->c[out->nc].i = i < best ? i : best;
                out->c[out->nc].j = i < best ? best : i;
                out->nc++;
            }
        }
    }
    free(x);
    free(r);
    free(X);
    free(R);
    if (rc) {
        scene_free(out);
        return rc;
    }
    snprintf(out->note, sizeof out->note, "%dx%s tiling of N=%zu", 2, dim == 2 ? "2" : "2x2", n);
    return ODHS_OK;
}

static int get_scene(int dim, size_t n, double phi, uint64_t seed, scene *out)
{
    if (cache_load(dim, n, phi, out)) return ODHS_OK;
    int tiled = (dim == 2 && n == 10000) || (dim == 3 && n == 3000);
    int rc;
    if (tiled) {
        scene base;
        size_t nb = n / (dim == 2 ? 4 : 8);
        if ((rc = get_scene(dim, nb, phi, seed, &base))) return rc;
        rc = tile_scene(&base, out);
        scene_free(&base);
    } else {
        rc = compress_scene(dim, n, phi, seed, out);
    }
    if (!rc) cache_store(dim, n, phi, out);
    return rc;
}

static int make_network(const scene *s, odhs_network **net)
{
    int rc = odhs_network_create(s->sys, net);
    for (size_t c = 0; !rc && c < s->nc; ++c) rc = odhs_network_add(*net, s->c[c].i, s->c[c].j, ODHS_CONTACT_TEMPORARY);
    if (!rc) rc = odhs_network_update_geometry(*net, s->sys);
    return rc;
}

/* the shear right-hand side b_c = -n_cx n_cy |R_c| */
static int shear_rhs(const odhs_system *sys, const odhs_network *net, double *b)
{
    size_t nc = odhs_network_count(net);
    for (size_t c = 0; c < nc; ++c) {
        size_t i, j;
        double rij[3] = {0, 0, 0}, d;
        int rc = odhs_network_get_contact(net, c, &i, &j, NULL);
        if (!rc) rc = odhs_system_separation(sys, i, j, rij, &d, NULL);
        if (rc) return rc;
        b[c] = -rij[0] * rij[1] / d;
    }
    return ODHS_OK;
}

/* ---- measurements ---------------------------------------------------------- */

#define STATIC_SECONDS 1.0
#define STATIC_MAXREPS 20
#define STEPPER_SECONDS 3.0
#define STEPPER_MAXSTEPS 100

/* static modes on the scene's network: cold (cg), fresh (cholmod, dense),
 * refactor (cholmod); fills ms, res, iters, reps */
static void measure_static(const scene *s, const char *solver, const char *mode, row *r)
{
    odhs_system *sys = NULL;
    odhs_network *net = NULL;
    double *b = NULL, *x = NULL, *x0 = NULL, *xp = NULL;
    odhs_solver *sol = NULL;
    int rc = odhs_system_clone(s->sys, &sys);
    int dim = odhs_system_dim(s->sys);
    size_t n = odhs_system_count(s->sys), nc = s->nc;
    int refactor = !strcmp(mode, "refactor"), fresh = !strcmp(mode, "fresh");
    if (!rc && refactor) rc = odhs_system_scale_box(sys, 1.0 + 1e-4);
    if (!rc) rc = make_network(s, &net);
    b = malloc(nc * sizeof *b);
    x = malloc(nc * sizeof *x);
    x0 = malloc(n * dim * sizeof *x0);
    xp = malloc(n * dim * sizeof *xp);
    if (!b || !x || !x0 || !xp) rc = ODHS_E_NOMEM;
    if (!rc) rc = shear_rhs(sys, net, b);
    if (!rc) rc = odhs_system_get_positions(sys, x0);
    const odhs_solver_type *type = type_by_name(solver);
    if (!rc && !fresh) rc = odhs_solver_create(type, &sol);
    if (!rc && refactor) { /* the first setup (with its analysis) untimed */
        memset(x, 0, nc * sizeof *x);
        rc = odhs_solver_solve(sol, net, b, x);
    }
    uint64_t rng = 12345;
    double tsum = 0.0, res = 0.0, its = 0.0;
    int reps = 0;
    while (!rc && reps < STATIC_MAXREPS && (reps == 0 || tsum < STATIC_SECONDS)) {
        if (refactor) {
            for (size_t k = 0; k < n * (size_t)dim; ++k) {
                rng = rng * 6364136223846793005ULL + 1442695040888963407ULL;
                xp[k] = x0[k] + 2e-5 * (2.0 * (double)(rng >> 11) * 0x1.0p-53 - 1.0);
            }
            rc = odhs_system_set_positions(sys, xp);
            if (!rc) rc = odhs_network_update_geometry(net, sys);
            if (rc) break;
        }
        memset(x, 0, nc * sizeof *x);
        double t0 = bench_cpu();
        if (fresh) {
            rc = odhs_solver_create(type, &sol);
            if (!rc) rc = odhs_solver_solve(sol, net, b, x);
        } else {
            rc = odhs_solver_solve(sol, net, b, x);
        }
        tsum += bench_cpu() - t0;
        double v = 0.0;
        odhs_solver_get_stat(sol, "residual", &v);
        res = fmax(res, v);
        if (odhs_solver_get_stat(sol, "iterations", &v) == ODHS_OK) its += v;
        if (fresh) {
            odhs_solver_destroy(sol);
            sol = NULL;
        }
        reps++;
    }
    if (rc) snprintf(r->note, sizeof r->note, "failed: %s", odhs_strerror(rc));
    r->ms = reps ? 1e3 * tsum / reps : NAN;
    r->res = reps ? res : NAN;
    r->iters = reps ? its / reps : NAN;
    r->reps = reps;
    odhs_solver_destroy(sol);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
    free(b);
    free(x);
    free(x0);
    free(xp);
}

/* stepper mode: the compression continued for a while, timed inside the backend */
static void measure_stepper(const odhs_system *base, const char *solver, row *r)
{
    odhs_system *sys = NULL;
    odhs_driver *drv = NULL;
    odhs_stepper *st = NULL;
    odhs_solver *sol = NULL;
    tw_inner = type_by_name(solver);
    tw_type.flags = tw_inner->flags;
    int rc = odhs_system_clone(base, &sys);
    if (!rc) rc = odhs_driver_create(&drv);
    if (!rc) rc = odhs_driver_set_compression_rate(drv, 1.0);
    if (!rc) rc = odhs_solver_create(&tw_type, &sol);
    if (!rc) rc = odhs_stepper_create(sys, drv, sol, &st);
    int steps = 0;
    while (!rc && steps < STEPPER_MAXSTEPS) {
        rc = odhs_stepper_step(st, NULL);
        if (rc) break;
        steps++;
        if (tw_live && tw_live->t > STEPPER_SECONDS) break;
    }
    double solves = 0.0;
    if (sol) odhs_solver_get_stat(sol, "solves", &solves);
    tw_state *ts = tw_live;
    r->ms = ts && solves > 0 ? 1e3 * ts->t / solves : NAN;
    r->res = ts ? ts->maxres : NAN;
    r->iters = NAN;
    r->reps = (int)solves;
    uint64_t nst = 0, co = 0, op = 0;
    if (st) odhs_stepper_counts(st, &nst, &co, &op);
    double phi = NAN;
    odhs_system_packing_fraction(sys, &phi);
    char extra[160] = "";
    if (ts && ts->ncalls > 0)
        snprintf(extra, sizeof extra, ", mean Nc %.0f, phi %.4f at the end", ts->ncsum / ts->ncalls, phi);
#ifdef ODHS_HAVE_SUITESPARSE
    double fa = 0, up = 0, an = 0;
    if (!strncmp(solver, "cholmod", 7) && sol) {
        odhs_solver_get_stat(sol, "factorizations", &fa);
        odhs_solver_get_stat(sol, "analyses", &an);
        odhs_solver_get_stat(sol, "updates", &up);
        size_t len = strlen(extra);
        snprintf(extra + len, sizeof extra - len, ", %g analyses, %g factorizations, %g updates", an, fa, up);
    }
#endif
    if (rc) snprintf(r->note, sizeof r->note, "%d steps, %llu events%s; stopped: %s", steps,
                     (unsigned long long)(co + op), extra, odhs_strerror(rc));
    else snprintf(r->note, sizeof r->note, "%d steps, %llu events%s", steps, (unsigned long long)(co + op), extra);
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_driver_destroy(drv);
    odhs_system_destroy(sys);
}

int main(int argc, char **argv)
{
    t_start = bench_wall();
    const char *bs = getenv("ODHS_BENCH_BUDGET");
    if (bs && atof(bs) > 0) budget = atof(bs);
    if (argc > 1 && argv[1][0]) {
        csv = fopen(argv[1], "w");
        if (!csv) {
            fprintf(stderr, "cannot open %s\n", argv[1]);
            return 1;
        }
    }
    machine();
    printf("# benchmark 1: time and relative residual per force solve N f = b, b = shear right-hand side\n");
    printf("# scenes: bidisperse 0.5/0.7 (3%% poly), RSA at 0.45 (2D) / 0.30 (3D), compression at rate 1 with\n"
           "#   cholmod-pcg + drift correction; 2D N=10000 and 3D N=3000 are periodic tilings (see note)\n");
    printf("# cg: tol 1e-12 (cold: zero guess); cholmod: default settings (CHOLMOD picks simplicial or\n"
           "#   supernodal, default ordering); cholmod-pcg: tol 1e-12, refactor_every 50; dense: LAPACK dpotrf\n"
           "#   (Nc <= 3000 fresh, Nc <= 1000 stepper); the library's iterative refinement (3 steps) is on\n");
    double la[3];
    bench_loadavg(la);
    printf("# load average at the start: %.2f %.2f %.2f (other processes on the machine skew timings)\n", la[0], la[1],
           la[2]);
    printf("# budget %.0f s; static modes up to %d reps / %.1f s, stepper up to %d steps / %.1f s solver time\n",
           budget, STATIC_MAXREPS, STATIC_SECONDS, STEPPER_MAXSTEPS, STEPPER_SECONDS);
    print_header();

    struct {
        int dim;
        size_t n;
        double phi;
    } sc[] = {
        {2, 100, 0.70},  {2, 100, 0.80},  {2, 316, 0.70},   {2, 316, 0.80},   {2, 1000, 0.70},
        {2, 1000, 0.80}, {2, 3162, 0.70}, {2, 3162, 0.80},  {2, 10000, 0.70}, {2, 10000, 0.80},
        {3, 100, 0.55},  {3, 100, 0.58},  {3, 316, 0.55},   {3, 316, 0.58},   {3, 1000, 0.55},
        {3, 1000, 0.58}, {3, 3000, 0.55}, {3, 3000, 0.58},
    };
    const char *static_modes[][2] = {
        {"cg", "cold"}, {"cholmod", "fresh"}, {"cholmod", "refactor"}, {"spqr", "fresh"}, {"dense", "fresh"},
    };
    const char *stepper_solvers[] = {"cg", "cholmod", "cholmod-pcg", "auto", "dense"};
    for (size_t q = 0; q < sizeof sc / sizeof *sc; ++q) {
        row r;
        memset(&r, 0, sizeof r);
        r.n = sc[q].n;
        r.dim = sc[q].dim;
        r.phi = sc[q].phi;
        r.ratio = r.ms = r.res = r.iters = NAN;
        if (over_budget()) {
            r.solver = "-";
            r.mode = "-";
            snprintf(r.note, sizeof r.note, "scene skipped: time budget (%.0f s) used up", budget);
            print_row(&r);
            continue;
        }
        scene s;
        int rc = get_scene(sc[q].dim, sc[q].n, sc[q].phi, 1000 + q, &s);
        if (rc) {
            r.solver = "-";
            r.mode = "-";
            snprintf(r.note, sizeof r.note, "scene construction failed: %s", odhs_strerror(rc));
            print_row(&r);
            continue;
        }
        r.nc = s.nc;
        double cg_static = NAN, cg_step = NAN;
        for (size_t m = 0; m < sizeof static_modes / sizeof *static_modes; ++m) {
            row x = r;
            x.solver = static_modes[m][0];
            x.mode = static_modes[m][1];
            if (!type_by_name(x.solver)) continue;
            if (!strcmp(x.solver, "dense") && s.nc > 3000) {
                snprintf(x.note, sizeof x.note, "skipped: Nc > 3000 (O(Nc^3) per solve)");
            } else if (over_budget()) {
                snprintf(x.note, sizeof x.note, "skipped: time budget used up");
            } else {
                measure_static(&s, x.solver, x.mode, &x);
                if (!strcmp(x.solver, "cg")) cg_static = x.ms;
                x.ratio = x.ms / cg_static;
                if (m == 0 && !x.note[0]) snprintf(x.note, sizeof x.note, "%s", s.note);
            }
            print_row(&x);
        }
        for (size_t m = 0; m < sizeof stepper_solvers / sizeof *stepper_solvers; ++m) {
            row x = r;
            x.solver = stepper_solvers[m];
            x.mode = "stepper";
            if (!type_by_name(x.solver)) continue;
            if (!strcmp(x.solver, "dense") && s.nc > 1000) {
                snprintf(x.note, sizeof x.note, "skipped: Nc > 1000 in stepper mode");
            } else if (over_budget()) {
                snprintf(x.note, sizeof x.note, "skipped: time budget used up");
            } else {
                measure_stepper(s.sys, x.solver, &x);
                if (!strcmp(x.solver, "cg")) cg_step = x.ms;
                x.ratio = x.ms / cg_step;
            }
            print_row(&x);
        }
        scene_free(&s);
    }
    bench_loadavg(la);
    printf("# total wall time %.1f s; load average at the end: %.2f %.2f %.2f\n", bench_wall() - t_start, la[0], la[1], la[2]);
    /* plots: ms per solve against N, one file per dimension */
    const char *prefix = argc > 2 ? argv[2] : "solvers";
    const char *pnames[] = {"cg", "cholmod", "cholmod-pcg", "auto", "dense", "spqr"};
    for (int dim = 2; dim <= 3; ++dim) {
        pl_plot p;
        char title[128], path[512];
        snprintf(title, sizeof title, "Time per force solve, %dD (solid: stepper mode, dashed: fresh/cold)", dim);
        pl_init(&p, title, "N", "CPU ms per solve", 1, 1);
        double phis[2] = {dim == 2 ? 0.70 : 0.55, dim == 2 ? 0.80 : 0.58};
        for (int ph = 1; ph >= 0; --ph)
            for (int m = 0; m < 2; ++m)
                for (size_t k = 0; k < sizeof pnames / sizeof *pnames; ++k) {
                    int any = 0, ser = -1;
                    for (size_t q = 0; q < nrows; ++q) {
                        const row *r = &rows[q];
                        if (r->dim != dim || fabs(r->phi - phis[ph]) > 1e-9 || !r->solver ||
                            strcmp(r->solver, pnames[k]) || isnan(r->ms))
                            continue;
                        int stepper = !strcmp(r->mode, "stepper");
                        if (stepper != (m == 0) || !strcmp(r->mode, "refactor")) continue;
                        if (!any) {
                            char lab[64];
                            snprintf(lab, sizeof lab, "%s %s, phi %.2f", pnames[k], m == 0 ? "stepper" : r->mode,
                                     phis[ph]);
                            ser = pl_series_add(&p, lab, (int)k, m == 0 ? (ph ? 0 : 2) : 1, ph ? 1 : 2);
                            any = 1;
                        }
                        pl_point(&p, ser, (double)r->n, r->ms);
                    }
                }
        char note[300];
        snprintf(note, sizeof note, "CPU time per solve; shared machine; N = 10000 (2D) and 3000 (3D) are tilings");
        pl_note(&p, note);
        snprintf(path, sizeof path, "%s_%dd.svg", prefix, dim);
        if (p.ns && pl_write_svg(&p, path) == 0) printf("# plot: %s\n", path);
        pl_free(&p);
    }
    if (csv) fclose(csv);
    return 0;
}
