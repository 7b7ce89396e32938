/* bench/nearjam - force solves close to jamming (benchmark 1, near-jamming
 * rows, and the near-jamming residual table of docs/accuracy.md).
 *
 * Scene: 50:50 bidisperse discs/spheres (radii 0.5/0.7, 3% polydispersity),
 * random placement at phi = 0.45 (2D) / 0.30 (3D), compression at rate 1
 * (cholmod-pcg, dt 1e-3, drift correction every step) until the stepper
 * certifies a jammed packing (ODHS_JAMMED, include/odhs/jamming.h): phi_J.
 * A snapshot (positions and the stepper's contact list) is kept after every
 * step; the states just below phi_J - delta are the test networks: delta =
 * 0.005 and 0.002 from this run; delta = 1e-3 ... 1e-6 from a second
 * approach started at phi_J - 0.003 with dt = 1e-6 (smaller steps get much
 * closer to jamming; that run jams at its own, slightly different phi_J,
 * against which its deltas are measured).
 *
 * On each network every backend solves N f = b once from a fresh handle
 * (setup included in the time), b the simple-shear right-hand side
 * b_c = -R_cx R_cy / |R_c|. Columns: ms per solve; relative residual
 * |N f - b| / |b| and normwise backward error (library statistics); forward
 * difference |f - f_qr| / |f_qr| to the spqr solution with iterative
 * refinement; rcond from dense (LAPACK dpocon) where dense runs. A failed
 * solve (the library rejects it) shows its status.
 *
 * usage: nearjam [SVG] [CSV]     (default nearjam.svg: residual against
 *        phi_J - phi for each backend)
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <time.h>
#include <unistd.h>

#include "bench.h"
#include "odhs.h"
#include "../examples/plot.h"

#define NSNAP 4000
#define NFINE 4000

typedef struct {
    odhs_system *sys;
    size_t nc, *ci, *cj;
    double phi;
} snap;

static void snap_free(snap *s)
{
    odhs_system_destroy(s->sys);
    free(s->ci);
    free(s->cj);
    memset(s, 0, sizeof *s);
}

static void snap_take(snap *s, const odhs_system *sys, const odhs_network *net)
{
    snap_free(s);
    odhs_system_clone(sys, &s->sys);
    s->nc = odhs_network_count(net);
    s->ci = malloc((s->nc + 1) * sizeof *s->ci);
    s->cj = malloc((s->nc + 1) * sizeof *s->cj);
    for (size_t c = 0; c < s->nc; ++c) odhs_network_get_contact(net, c, &s->ci[c], &s->cj[c], NULL);
    odhs_system_packing_fraction(sys, &s->phi);
}

static const char *const names[] = {"cg", "dense", "cholmod", "cholmod-pcg", "spqr", "auto"};
enum { NB = 6 };

int main(int argc, char **argv)
{
    const char *svg = argc > 1 ? argv[1] : "nearjam.svg";
    FILE *csv = argc > 2 ? fopen(argv[2], "w") : NULL;
    char cpu[256];
    bench_cpu_model(cpu, sizeof cpu);
    double la[3];
    bench_loadavg(la);
    printf("# near-jamming force solves; machine: %s; libodhs %s; load %.2f %.2f %.2f\n", cpu,
           odhs_version_string(), la[0], la[1], la[2]);
    printf("# b: simple-shear right-hand side; one solve per fresh handle (setup included); err = |f - f_spqr| / "
           "|f_spqr|\n");
    printf("%3s %5s %9s %8s %6s %-12s %9s %9s %9s %9s %9s  %s\n", "dim", "N", "phi_J", "phiJ-phi", "Nc", "solver",
           "ms", "residual", "backward", "err", "rcond", "note");
    if (csv) fprintf(csv, "dim,N,phi_J,delta,Nc,solver,ms,residual,backward,err,rcond,status\n");
    struct {
        int dim;
        size_t n;
        uint64_t seed;
    } sc[] = {{2, 64, 1}, {2, 128, 1}, {2, 256, 1}, {3, 64, 1}};
    const double deltas[] = {0.005, 0.002, 1e-3, 1e-4, 1e-5, 1e-6};
    pl_plot p;
    pl_init(&p, "Relative residual of N f = b below jamming (2D N = 128)", "phi_J - phi",
            "relative residual |N f - b| / |b|", 1, 1);
    int ser[NB];
    for (int k = 0; k < NB; ++k) ser[k] = pl_series_add(&p, names[k], k, 0, 1 + k % 5);
    for (size_t q = 0; q < sizeof sc / sizeof *sc; ++q) {
        odhs_system *sys;
        odhs_solver *sol;
        odhs_driver *drv;
        odhs_stepper *st;
        odhs_system_create(sc[q].dim, sc[q].n, &sys);
        odhs_system_set_radii_bidisperse(sys, 0.5, 1.4, 0.03, sc[q].seed);
        odhs_system_place_random(sys, sc[q].dim == 2 ? 0.45 : 0.30, sc[q].seed);
        if (odhs_solver_create_by_name("cholmod-pcg", &sol)) odhs_solver_create_by_name("dense", &sol);
        odhs_driver_create(&drv);
        odhs_driver_set_compression_rate(drv, 1.0);
        odhs_stepper_create(sys, drv, sol, &st);
        odhs_stepper_set_correction_interval(st, 1);
        /* first approach (dt 1e-3): a snapshot after every step */
        snap *ring = calloc(NSNAP, sizeof *ring), *fine = calloc(NFINE, sizeof *fine);
        size_t nsnap = 0, nfine = 0;
        double t0 = bench_cpu();
        int rc = odhs_stepper_run_until_packing_fraction(st, sc[q].dim == 2 ? 0.76 : 0.56);
        while (rc == ODHS_OK) {
            rc = odhs_stepper_step(st, NULL);
            if (rc == ODHS_OK) snap_take(&ring[nsnap++ % NSNAP], sys, odhs_stepper_network(st));
        }
        double phiJ = NAN;
        odhs_system_packing_fraction(sys, &phiJ);
        /* second approach from phi_J - 0.003 with dt 1e-6: states much
         * closer to jamming; its own phi_J (the path differs slightly) */
        snap *from = NULL;
        for (size_t k = 0; k < NSNAP && k < nsnap; ++k)
            if (ring[k].sys && ring[k].phi <= phiJ - 0.003 && (!from || ring[k].phi > from->phi)) from = &ring[k];
        double phiJ2 = NAN;
        int rc2 = -1;
        if (rc == ODHS_JAMMED && from) {
            odhs_system *s2;
            odhs_solver *so2;
            odhs_driver *dr2;
            odhs_stepper *st2;
            odhs_system_clone(from->sys, &s2);
            if (odhs_solver_create_by_name("cholmod-pcg", &so2)) odhs_solver_create_by_name("dense", &so2);
            odhs_driver_create(&dr2);
            odhs_driver_set_compression_rate(dr2, 1.0);
            odhs_stepper_create(s2, dr2, so2, &st2);
            odhs_stepper_set_correction_interval(st2, 1);
            odhs_stepper_set_dt(st2, 1e-6);
            rc2 = ODHS_OK;
            for (long k = 0; k < 200000 && rc2 == ODHS_OK; ++k) {
                rc2 = odhs_stepper_step(st2, NULL);
                if (rc2 == ODHS_OK) snap_take(&fine[nfine++ % NFINE], s2, odhs_stepper_network(st2));
            }
            odhs_system_packing_fraction(s2, &phiJ2);
            if (rc2 != ODHS_JAMMED)
                printf("# %dD N=%zu: second approach stopped (%d): %s\n", sc[q].dim, sc[q].n, rc2,
                       odhs_stepper_errmsg(st2));
            odhs_stepper_destroy(st2);
            odhs_driver_destroy(dr2);
            odhs_solver_destroy(so2);
            odhs_system_destroy(s2);
        }
        double tj = bench_cpu() - t0;
        if (rc != ODHS_JAMMED) {
            printf("%3d %5zu  compression stopped without jamming: %s\n", sc[q].dim, sc[q].n, odhs_stepper_errmsg(st));
        } else {
            printf("# %dD N=%zu: jammed at phi_J = %.6f (dt 1e-3); from phi_J - 0.003 with dt 1e-6: %s at %.9f; %.1f s "
                   "CPU\n", sc[q].dim, sc[q].n, phiJ, rc2 == ODHS_JAMMED ? "jammed" : "not jammed", phiJ2, tj);
        }
        for (size_t d = 0; d < sizeof deltas / sizeof *deltas && rc == ODHS_JAMMED; ++d) {
            /* the snapshot just below phi_J - delta: delta >= 0.002 from the
             * first approach, smaller ones from the second */
            int use_fine = deltas[d] < 0.0015;
            if (use_fine && rc2 != ODHS_JAMMED) continue;
            snap *rg = use_fine ? fine : ring, *best = NULL;
            size_t cnt = use_fine ? nfine : nsnap, cap = use_fine ? NFINE : NSNAP;
            double pj = use_fine ? phiJ2 : phiJ;
            for (size_t k = 0; k < cap && k < cnt; ++k)
                if (rg[k].sys && rg[k].phi <= pj - deltas[d] && (!best || rg[k].phi > best->phi)) best = &rg[k];
            if (!best) continue;
            odhs_network *net;
            odhs_network_create(best->sys, &net);
            for (size_t c = 0; c < best->nc; ++c) odhs_network_add(net, best->ci[c], best->cj[c], ODHS_CONTACT_TEMPORARY);
            odhs_network_update_geometry(net, best->sys);
            size_t nc = best->nc;
            double *b = calloc(nc + 1, sizeof *b), *xq = calloc(nc + 1, sizeof *xq), *x = calloc(nc + 1, sizeof *x);
            for (size_t c = 0; c < nc; ++c) {
                double rij[3] = {0, 0, 0}, dist;
                odhs_system_separation(best->sys, best->ci[c], best->cj[c], rij, &dist, NULL);
                b[c] = -rij[0] * rij[1] / dist;
            }
            /* reference: spqr with refinement */
            odhs_solver *ref = NULL;
            int have_ref = odhs_solver_create_by_name("spqr", &ref) == ODHS_OK &&
                           odhs_solver_solve(ref, net, b, xq) == ODHS_OK;
            odhs_solver_destroy(ref);
            double qn = 0.0, rcond = NAN;
            for (size_t c = 0; c < nc; ++c) qn += xq[c] * xq[c];
            for (int k = 0; k < NB; ++k) {
                odhs_solver *s = NULL;
                int cr = odhs_solver_create_by_name(names[k], &s);
                if (cr == ODHS_E_NOTINSTALLED) continue;
                memset(x, 0, nc * sizeof *x);
                double c0 = bench_cpu();
                int sr = odhs_solver_solve(s, net, b, x);
                double ms = 1e3 * (bench_cpu() - c0);
                double res = NAN, bw = NAN, e = 0.0;
                odhs_solver_get_stat(s, "residual", &res);
                odhs_solver_get_stat(s, "backward_error", &bw);
                if (!strcmp(names[k], "dense")) odhs_solver_get_stat(s, "rcond", &rcond);
                for (size_t c = 0; c < nc; ++c) e += (x[c] - xq[c]) * (x[c] - xq[c]);
                e = have_ref && qn > 0 ? sqrt(e / qn) : NAN;
                char note[160] = "";
                if (sr) snprintf(note, sizeof note, "rejected: %s", odhs_strerror(sr));
                if (!strcmp(names[k], "auto")) {
                    const char *bn = "?", *why = "";
                    odhs_solver_backend_name(s, &bn, &why);
                    size_t len = strlen(note);
                    snprintf(note + len, sizeof note - len, "%sbackend %s%s%.80s", len ? "; " : "", bn,
                             why[0] ? ": " : "", why);
                }
                printf("%3d %5zu %9.6f %8.1e %6zu %-12s %9.3f %9.1e %9.1e %9.1e %9.1e  %s\n", sc[q].dim, sc[q].n, pj,
                       pj - best->phi, nc, names[k], ms, res, bw, e, k == 1 ? rcond : NAN, note);
                if (csv)
                    fprintf(csv, "%d,%zu,%.9f,%.3e,%zu,%s,%.4f,%.3e,%.3e,%.3e,%.3e,%d\n", sc[q].dim, sc[q].n, pj,
                            pj - best->phi, nc, names[k], ms, res, bw, e, k == 1 ? rcond : NAN, sr);
                if (sc[q].dim == 2 && sc[q].n == 128) pl_point(&p, ser[k], pj - best->phi, res);
                odhs_solver_destroy(s);
            }
            fflush(stdout);
            free(b);
            free(x);
            free(xq);
            odhs_network_destroy(net);
        }
        for (size_t k = 0; k < NSNAP; ++k) snap_free(&ring[k]);
        for (size_t k = 0; k < NFINE; ++k) snap_free(&fine[k]);
        free(ring);
        free(fine);
        odhs_stepper_destroy(st);
        odhs_driver_destroy(drv);
        odhs_solver_destroy(sol);
        odhs_system_destroy(sys);
    }
    char note[300];
    snprintf(note, sizeof note, "%.120s, shared machine (load %.1f); one solve per fresh handle", cpu, la[0]);
    pl_note(&p, note);
    if (pl_write_svg(&p, svg) == 0) printf("# plot: %s\n", svg);
    pl_free(&p);
    if (csv) fclose(csv);
    return 0;
}
