/* bench/validation_jamming - the jammed-packing numbers of docs/validation.md
 * (issue 21): phi_J, backbone coordination, rattler fraction, and the
 * small-force and small-gap exponents theta and gamma measured with the
 * analysis calls (analysis.h) on packings made by event-driven isotropic
 * compression to jamming (Sect. IV D of the paper).
 *
 * usage: validation_jamming DIM N SEEDS [FMAX HMAX]
 *   DIM 2 (bidisperse discs 1:1.4, 50:50) or 3 (monodisperse spheres, or
 *   bidisperse with DIM = -3), N particles, SEEDS packings (seeds 1..SEEDS);
 *   FMAX the cut-off of f/<f> for theta (default 0.1), HMAX the cut-off of
 *   the relative gap h for gamma (default 1e-2).
 * Output: one row per packing, then the means with standard errors over
 * seeds, and the exponents from the pooled samples (Hill's estimator, error
 * (a+1)/sqrt(m)) and as mean +- standard error of the per-packing values;
 * theta also separately for extended and localized contacts (a contact is
 * localized when one of its particles has exactly d + 1 backbone contacts).
 *
 * Scene: radii 0.5 (and 0.7) with 3% uniform polydispersity (as
 * bench/jamming; exactly equal radii make degenerate networks that slow the
 * solves down), random placement at
 * phi = 0.45 (2D) / 0.30 (3D), compression rate 1 with the library's
 * defaults (adaptive Heun, drift correction every step) and the auto
 * solver until ODHS_JAMMED. Gaps: pairs between backbone particles only
 * (ODHS_GAP_BACKBONE), h = r/(a_i + a_j) - 1.
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "bench.h"
#include "../examples/plot.h"

static double mean_sem(const double *x, int n, double *sem)
{
    double m = 0.0, s = 0.0;
    for (int k = 0; k < n; ++k) m += x[k] / n;
    for (int k = 0; k < n; ++k) s += (x[k] - m) * (x[k] - m);
    *sem = n > 1 ? sqrt(s / (n - 1) / n) : NAN;
    return m;
}

int main(int argc, char **argv)
{
    if (argc < 4) {
        fprintf(stderr, "usage: %s DIM N SEEDS [FMAX HMAX]\n", argv[0]);
        return 2;
    }
    int dimarg = atoi(argv[1]), dim = abs(dimarg), nseeds = atoi(argv[3]);
    size_t n = (size_t)atol(argv[2]);
    double fmax = argc > 4 ? atof(argv[4]) : 0.1, hmax = argc > 5 ? atof(argv[5]) : 1e-2;
    double ratio = dimarg == 3 ? 1.0 : 1.4;
    if ((dim != 2 && dim != 3) || n < 16 || nseeds < 1 || nseeds > 1000 || !(fmax > 0) || !(hmax > 0)) {
        fprintf(stderr, "validation_jamming: bad arguments\n");
        return 2;
    }
    char cpu[128];
    bench_cpu_model(cpu, sizeof cpu);
    printf("# validation_jamming: d = %d, N = %zu, size ratio %.1f, %d seeds; theta from f/<f> <= %g, gamma "
           "from backbone gaps h <= %g\n# machine: %s, OPENBLAS_NUM_THREADS=%s\n",
           dim, n, ratio, nseeds, fmax, hmax, cpu, getenv("OPENBLAS_NUM_THREADS") ? getenv("OPENBLAS_NUM_THREADS") : "unset");
    printf("%5s %9s %6s %8s %8s %7s %8s %7s %7s %8s\n", "seed", "phi_J", "Nbar", "z_bb", "rattl", "theta", "+-",
           "gamma", "+-", "cpu_s");
    double *phis = malloc(nseeds * sizeof *phis), *zs = malloc(nseeds * sizeof *zs),
           *rats = malloc(nseeds * sizeof *rats), *ths = malloc(nseeds * sizeof *ths),
           *gas = malloc(nseeds * sizeof *gas);
    size_t fcap = 0, fn = 0, hcap = 0, hn = 0, ecap = 0, en = 0, lcap = 0, ln = 0;
    double *fall = NULL, *hall = NULL, *fext = NULL, *floc = NULL;
    int good = 0;
    for (int seed = 1; seed <= nseeds; ++seed) {
        double t0 = bench_cpu();
        odhs_system *sys;
        odhs_driver *drv;
        odhs_solver *sol;
        odhs_stepper *st;
        if (odhs_system_create(dim, n, &sys) || odhs_system_set_radii_bidisperse(sys, 0.5, ratio, 0.03, seed) ||
            odhs_system_place_random(sys, dim == 2 ? 0.45 : 0.30, seed) || odhs_driver_create(&drv) ||
            odhs_driver_set_compression_rate(drv, 1.0) || odhs_solver_create_by_name("auto", &sol) ||
            odhs_stepper_create(sys, drv, sol, &st)) {
            fprintf(stderr, "validation_jamming: setup failed: %s\n", odhs_last_error());
            return 1;
        }
        int rc = odhs_stepper_run_until_packing_fraction(st, 0.99);
        odhs_jam_certificate c;
        memset(&c, 0, sizeof c);
        c.size = sizeof c;
        odhs_stepper_certificate(st, &c);
        if (rc != ODHS_JAMMED || !c.isostatic) {
            printf("%5d not certified (%s)\n", seed, odhs_strerror(rc));
            goto next;
        }
        const odhs_network *net = odhs_stepper_network(st);
        size_t nb = 0, ng = 0;
        odhs_backbone_forces(net, 0, &nb, NULL);
        if (fn + nb > fcap) fall = realloc(fall, (fcap = 2 * (fn + nb)) * sizeof *fall);
        odhs_backbone_forces(net, nb, &nb, fall + fn);
        double fm = 0.0;
        for (size_t k = 0; k < nb; ++k) fm += fall[fn + k] / (double)nb;
        for (size_t k = 0; k < nb; ++k) fall[fn + k] /= fm;
        {
            /* extended and localized contacts (Lerner, During and Wyart
             * 2013; Charbonneau et al. 2015): a backbone contact is
             * localized when one of its particles has exactly d + 1
             * backbone contacts (a buckler) */
            size_t nc = odhs_network_count(net), nrat = 0;
            size_t *ci = malloc((nc + 1) * sizeof *ci), *cj = malloc((nc + 1) * sizeof *cj);
            int *kind = malloc((nc + 1) * sizeof *kind);
            double *f = malloc((nc + 1) * sizeof *f);
            unsigned char *rat = malloc(n);
            unsigned *deg = calloc(n, sizeof *deg);
            odhs_network_get_contacts(net, ci, cj, kind);
            odhs_network_get_forces(net, f);
            odhs_network_rattlers(net, rat, &nrat);
            for (size_t k = 0; k < nc; ++k)
                if (kind[k] == ODHS_CONTACT_TEMPORARY && !rat[ci[k]] && !rat[cj[k]]) deg[ci[k]]++, deg[cj[k]]++;
            if (en + nc > ecap) fext = realloc(fext, (ecap = 2 * (en + nc)) * sizeof *fext);
            if (ln + nc > lcap) floc = realloc(floc, (lcap = 2 * (ln + nc)) * sizeof *floc);
            for (size_t k = 0; k < nc; ++k) {
                if (kind[k] != ODHS_CONTACT_TEMPORARY || rat[ci[k]] || rat[cj[k]]) continue;
                int loc = deg[ci[k]] == (unsigned)dim + 1 || deg[cj[k]] == (unsigned)dim + 1;
                if (loc) floc[ln++] = f[k] / fm;
                else fext[en++] = f[k] / fm;
            }
            free(ci), free(cj), free(kind), free(f), free(rat), free(deg);
        }
        odhs_packing_gaps(sys, net, 0.1, 0, &ng, NULL, NULL, NULL, NULL);
        double *h = malloc((ng + 1) * sizeof *h);
        int *role = malloc((ng + 1) * sizeof *role);
        odhs_packing_gaps(sys, net, 0.1, ng, &ng, NULL, NULL, h, role);
        if (hn + ng > hcap) hall = realloc(hall, (hcap = 2 * (hn + ng) + 16) * sizeof *hall);
        size_t hb = 0;
        for (size_t k = 0; k < ng; ++k)
            if (role[k] == ODHS_GAP_BACKBONE) hall[hn + hb++] = h[k];
        free(h);
        free(role);
        double th = NAN, the = NAN, ga = NAN, gae = NAN;
        if (odhs_power_law_exponent(fall + fn, nb, fmax, &th, &the, NULL)) th = the = NAN;
        if (odhs_power_law_exponent(hall + hn, hb, hmax, &ga, &gae, NULL)) ga = gae = NAN;
        fn += nb;
        hn += hb;
        phis[good] = c.phi;
        zs[good] = c.z_backbone;
        rats[good] = (double)c.n_rattlers / (double)c.n_particles;
        ths[good] = th;
        gas[good] = -ga;
        good++;
        printf("%5d %9.6f %6zu %8.4f %8.4f %7.3f %8.3f %7.3f %7.3f %8.1f\n", seed, c.phi, c.n_backbone, c.z_backbone,
               rats[good - 1], th, the, -ga, gae, bench_cpu() - t0);
        fflush(stdout);
    next:
        odhs_stepper_destroy(st);
        odhs_solver_destroy(sol);
        odhs_driver_destroy(drv);
        odhs_system_destroy(sys);
    }
    if (good < 2) return 1;
    double e1, e2, e3, e4, e5;
    double mphi = mean_sem(phis, good, &e1), mz = mean_sem(zs, good, &e2), mr = mean_sem(rats, good, &e3);
    double mth = mean_sem(ths, good, &e4), mga = mean_sem(gas, good, &e5);
    double pth, pthe, pga, pgae;
    size_t mth_n, mga_n;
    odhs_power_law_exponent(fall, fn, fmax, &pth, &pthe, &mth_n);
    odhs_power_law_exponent(hall, hn, hmax, &pga, &pgae, &mga_n);
    printf("# %d certified packings\n", good);
    printf("phi_J      %.5f +- %.5f (sd %.5f)\n", mphi, e1, e1 * sqrt(good));
    printf("z_backbone %.4f +- %.4f (isostatic 2d = %d, + O(1/N))\n", mz, e2, 2 * dim);
    printf("rattlers   %.4f +- %.4f\n", mr, e3);
    printf("theta      pooled %.3f +- %.3f (%zu forces <= %g <f>); per packing %.3f +- %.3f\n", pth, pthe, mth_n,
           fmax, mth, e4);
    printf("gamma      pooled %.3f +- %.3f (%zu backbone gaps <= %g); per packing %.3f +- %.3f\n", -pga, pgae, mga_n,
           hmax, mga, e5);
    {
        double te, tee, tl, tle;
        size_t ue = 0, ul = 0;
        if (odhs_power_law_exponent(fext, en, fmax, &te, &tee, &ue)) te = tee = NAN;
        if (odhs_power_law_exponent(floc, ln, fmax, &tl, &tle, &ul)) tl = tle = NAN;
        printf("theta_e    pooled %.3f +- %.3f (%zu of %zu extended contacts <= %g <f>)\n", te, tee, ue, en, fmax);
        printf("theta_l    pooled %.3f +- %.3f (%zu of %zu localized contacts <= %g <f>: a particle with d + 1 "
               "backbone contacts)\n",
               tl, tle, ul, ln, fmax);
    }
    /* the exponents against their cut-offs: a plateau shows the power-law
     * range; and the distributions, written to validation_jamming_<d>d_N<n>.svg */
    printf("cut-off scan (pooled): f/<f> <=");
    const double fc[6] = {0.02, 0.05, 0.1, 0.2, 0.3, 0.5}, hc[6] = {1e-4, 3e-4, 1e-3, 3e-3, 1e-2, 3e-2};
    for (int k = 0; k < 6; ++k) {
        double a, e;
        size_t u = 0;
        if (odhs_power_law_exponent(fall, fn, fc[k], &a, &e, &u)) a = e = NAN;
        printf("  %g: theta %.3f +- %.3f (%zu)", fc[k], a, e, u);
    }
    printf("\ncut-off scan (pooled): h <=");
    for (int k = 0; k < 6; ++k) {
        double a, e;
        size_t u = 0;
        if (odhs_power_law_exponent(hall, hn, hc[k], &a, &e, &u)) a = e = NAN;
        printf("  %g: gamma %.3f +- %.3f (%zu)", hc[k], -a, e, u);
    }
    printf("\n");
    {
        pl_plot pf, ph;
        char title[160], path[128], note[200];
        snprintf(title, sizeof title, "Backbone contact forces, %dD, N = %zu, %d packings", dim, n, good);
        pl_init(&pf, title, "f / <f>", "P(f / <f>)", 1, 1);
        snprintf(title, sizeof title, "Gaps of backbone pairs, %dD, N = %zu", dim, n);
        pl_init(&ph, title, "h = r / (a_i + a_j) - 1", "g(h)", 1, 1);
        double edges[31], dens[30];
        struct {
            pl_plot *p;
            const char *name;
            const double *x;
            size_t m;
            double lo, hi;
        } sets[4] = {{&pf, "all backbone contacts", fall, fn, 1e-4, 10.0},
                     {&pf, "extended", fext, en, 1e-4, 10.0},
                     {&pf, "localized (buckler)", floc, ln, 1e-4, 10.0},
                     {&ph, "backbone pairs", hall, hn, 1e-8, 0.1}};
        for (int k = 0; k < 4; ++k) {
            if (!sets[k].m || odhs_histogram(sets[k].x, sets[k].m, sets[k].lo, sets[k].hi, 30, 1, edges, dens, NULL, NULL))
                continue;
            int sr = pl_series_add(sets[k].p, sets[k].name, k, 0, 1);
            for (int b = 0; b < 30; ++b)
                if (dens[b] > 0) pl_point(sets[k].p, sr, sqrt(edges[b] * edges[b + 1]), dens[b]);
        }
        snprintf(note, sizeof note, "bench/validation_jamming %d %zu %d; theta %.2f, gamma %.2f (pooled Hill fits)",
                 dimarg, n, nseeds, pth, -pga);
        pl_note(&pf, note);
        pl_note(&ph, note);
        const pl_plot *panels[2] = {&pf, &ph};
        snprintf(path, sizeof path, "validation_jamming_%dd_N%zu.svg", dim, n);
        pl_write_svg_panels(panels, 2, path);
        pl_free(&pf);
        pl_free(&ph);
    }
    free(fext), free(floc);
    free(fall), free(hall), free(phis), free(zs), free(rats), free(ths), free(gas);
    return 0;
}
