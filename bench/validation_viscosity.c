/* bench/validation_viscosity - the viscosity divergence of the event-driven
 * hard-sphere flow for docs/validation.md (issue 21): eta = sigma_xy /
 * gammadot against phi at fixed volume, and the fit
 *     eta = A (phi_c - phi)^(-beta)
 * over the points with phi >= PHI_MIN, for each N.
 *
 * usage: validation_viscosity TRANSIENT PHI_MIN PREFIX [-f PHI_C] DIR...
 *   DIR: output directories of examples/sweep_serial or sweep_mpi (shear at
 *   fixed volume, gammadot = 1, xi0 = 1); the runs are read from
 *   DIR/campaign.txt and DIR/runs/run_NNNN/series.csv. Each run's
 *   shear_stress after TRANSIENT strain gives a mean and a block-averaged
 *   error (odhs_series_stats_compute); the seeds of one (N, phi) are
 *   averaged (error: the larger of the propagated errors and the seeds'
 *   standard error).
 * The fit: for each trial phi_c (grid of 1e-5 above the largest phi) a
 * weighted straight line of ln eta against ln(phi_c - phi); the phi_c of
 * least chi^2, and errors of phi_c and beta from chi^2 = min + 1 (scaled by
 * chi^2/dof when that exceeds 1); with -f also beta at the given phi_c
 * (e.g. a published phi_J). Prints the table and the fit per N and
 * writes PREFIX.svg (eta against phi_c - phi, log-log, with the fits).
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "bench.h"
#include "../examples/plot.h"

#define MAXP 256

typedef struct {
    size_t n;
    double phi, sum, sem2sum, *means;
    int seeds, cap;
} point;

static point pts[MAXP];
static int npts;

static point *find_point(size_t n, double phi)
{
    for (int k = 0; k < npts; ++k)
        if (pts[k].n == n && fabs(pts[k].phi - phi) < 1e-9) return &pts[k];
    if (npts == MAXP) return NULL;
    pts[npts] = (point){n, phi, 0, 0, NULL, 0, 0};
    return &pts[npts++];
}

/* mean and block-averaged error of the shear stress after the transient */
static int run_stats(const char *path, double transient, double *mean, double *sem, double *last)
{
    FILE *f = fopen(path, "r");
    if (!f) return -1;
    char line[4096];
    int col_g = -1, col_s = -1;
    size_t cap = 1024, m = 0;
    double *x = malloc(cap * sizeof *x);
    while (fgets(line, sizeof line, f)) {
        if (line[0] == '#') continue;
        if (col_g < 0) { /* header */
            int c = 0;
            for (char *t = strtok(line, ",\n"); t; t = strtok(NULL, ",\n"), ++c) {
                if (!strcmp(t, "strain")) col_g = c;
                if (!strcmp(t, "shear_stress")) col_s = c;
            }
            if (col_g < 0 || col_s < 0) break;
            continue;
        }
        double g = NAN, s = NAN;
        int c = 0;
        for (char *t = strtok(line, ",\n"); t; t = strtok(NULL, ",\n"), ++c) {
            if (c == col_g) g = atof(t);
            if (c == col_s) s = atof(t);
        }
        if (isfinite(g)) *last = g;
        if (!(g > transient) || !isfinite(s)) continue;
        if (m == cap) x = realloc(x, (cap *= 2) * sizeof *x);
        x[m++] = s;
    }
    fclose(f);
    odhs_series_stats st = {.size = sizeof st};
    int rc = m >= 16 ? odhs_series_stats_compute(x, m, &st) : -1;
    free(x);
    if (rc) return -1;
    *mean = st.mean;
    *sem = st.sem;
    return 0;
}

static int read_dir(const char *dir, double transient)
{
    char path[2048], line[1024];
    snprintf(path, sizeof path, "%s/campaign.txt", dir);
    FILE *f = fopen(path, "r");
    if (!f) return -1;
    int in = 0, header = 0, run = 0, cn = -1, cphi = -1, cstrain = -1;
    while (fgets(line, sizeof line, f)) {
        if (!in) {
            in = !strncmp(line, "--- campaign ---", 16);
            continue;
        }
        if (line[0] == '#' || line[0] == '\n') continue;
        if (!header) {
            int c = 0;
            for (char *t = strtok(line, ",\n"); t; t = strtok(NULL, ",\n"), ++c) {
                if (!strcmp(t, "n")) cn = c;
                if (!strcmp(t, "phi")) cphi = c;
                if (!strcmp(t, "strain")) cstrain = c;
            }
            header = 1;
            continue;
        }
        /* empty fields: parse by hand */
        size_t n = 0;
        double phi = NAN, strain = 0.0;
        int c = 0;
        for (char *p = line, *q; p; p = q ? q + 1 : NULL, ++c) {
            q = strchr(p, ',');
            if (c == cn) n = (size_t)atol(p);
            if (c == cphi) phi = atof(p);
            if (c == cstrain) strain = atof(p);
        }
        double mean, sem, last = 0.0;
        snprintf(path, sizeof path, "%s/runs/run_%04d/series.csv", dir, run++);
        if (run_stats(path, transient, &mean, &sem, &last)) {
            fprintf(stderr, "validation_viscosity: %s: no usable series (run not finished?)\n", path);
            continue;
        }
        if (last < strain - 1e-6) { /* a run still going (or stopped): only finished runs count */
            fprintf(stderr, "validation_viscosity: %s: at strain %g of %g, not finished: left out\n", path, last,
                    strain);
            continue;
        }
        point *p = find_point(n, phi);
        if (!p) break;
        if (p->seeds == p->cap) p->means = realloc(p->means, (p->cap = 2 * p->cap + 4) * sizeof *p->means);
        p->means[p->seeds++] = mean;
        p->sum += mean;
        p->sem2sum += sem * sem;
    }
    fclose(f);
    return 0;
}

static int cmp_point(const void *a, const void *b)
{
    const point *x = a, *y = b;
    if (x->n != y->n) return x->n < y->n ? -1 : 1;
    return x->phi < y->phi ? -1 : x->phi > y->phi;
}

/* weighted line ln eta = a - beta ln(phic - phi); returns chi^2 */
static double line_fit(const double *phi, const double *eta, const double *rel, int m, double phic, double *a,
                       double *beta)
{
    double S = 0, Sx = 0, Sy = 0, Sxx = 0, Sxy = 0;
    for (int k = 0; k < m; ++k) {
        double w = 1.0 / (rel[k] * rel[k]), x = log(phic - phi[k]), y = log(eta[k]);
        S += w, Sx += w * x, Sy += w * y, Sxx += w * x * x, Sxy += w * x * y;
    }
    double d = S * Sxx - Sx * Sx, slope = (S * Sxy - Sx * Sy) / d;
    *a = (Sy - slope * Sx) / S;
    *beta = -slope;
    double chi2 = 0;
    for (int k = 0; k < m; ++k) {
        double r = (log(eta[k]) - (*a + slope * log(phic - phi[k]))) / rel[k];
        chi2 += r * r;
    }
    return chi2;
}

int main(int argc, char **argv)
{
    if (argc < 5) {
        fprintf(stderr, "usage: %s TRANSIENT PHI_MIN PREFIX DIR...\n", argv[0]);
        return 2;
    }
    double transient = atof(argv[1]), phimin = atof(argv[2]);
    const char *prefix = argv[3];
    int first = 4;
    double phic_fixed = NAN;
    if (argc > 6 && !strcmp(argv[4], "-f")) {
        phic_fixed = atof(argv[5]);
        first = 6;
    }
    for (int a = first; a < argc; ++a)
        if (read_dir(argv[a], transient)) fprintf(stderr, "validation_viscosity: %s: no campaign.txt\n", argv[a]);
    if (npts == 0) return 1;
    qsort(pts, (size_t)npts, sizeof *pts, cmp_point);
    printf("# validation_viscosity: eta = sigma_xy / gammadot of the event-driven flow at fixed volume; transient %g;"
           " fit over phi >= %g\n",
           transient, phimin);
    printf("%6s %8s %5s %12s %10s\n", "N", "phi", "seeds", "eta", "+-");
    double eta[MAXP], err[MAXP];
    for (int k = 0; k < npts; ++k) {
        point *p = &pts[k];
        double m = p->sum / p->seeds, e = sqrt(p->sem2sum) / p->seeds;
        if (p->seeds > 1) {
            double v = 0;
            for (int s = 0; s < p->seeds; ++s) v += (p->means[s] - m) * (p->means[s] - m);
            e = fmax(e, sqrt(v / (p->seeds - 1) / p->seeds));
        }
        eta[k] = m;
        err[k] = e;
        printf("%6zu %8.4f %5d %12.5g %10.3g\n", p->n, p->phi, p->seeds, m, e);
    }
    pl_plot pl;
    pl_init(&pl, "Viscosity of the event-driven flow at fixed volume", "phi_c - phi", "eta = sigma_xy / gammadot", 1,
            1);
    for (int k0 = 0, color = 0; k0 < npts; ++color) {
        int k1 = k0;
        while (k1 < npts && pts[k1].n == pts[k0].n) k1++;
        double ph[MAXP], et[MAXP], rel[MAXP];
        int m = 0;
        for (int k = k0; k < k1; ++k)
            if (pts[k].phi >= phimin) {
                ph[m] = pts[k].phi;
                et[m] = eta[k];
                rel[m] = fmax(err[k] / eta[k], 1e-3);
                m++;
            }
        if (m >= 4) {
            double best = INFINITY, bphi = NAN, ba = NAN, bb = NAN, a, b;
            double lo = ph[m - 1] + 1e-5;
            for (double pc = lo; pc < ph[m - 1] + 0.06; pc += 1e-5) {
                double c2 = line_fit(ph, et, rel, m, pc, &a, &b);
                if (c2 < best) best = c2, bphi = pc, ba = a, bb = b;
            }
            int dof = m - 3;
            double scale = dof > 0 && best / dof > 1 ? best / dof : 1.0;
            /* profile errors: the range of phi_c (and beta) with chi^2 <= min + scale */
            double pmin = bphi, pmax = bphi, bmin = bb, bmax = bb;
            for (double pc = lo; pc < ph[m - 1] + 0.06; pc += 1e-5) {
                double c2 = line_fit(ph, et, rel, m, pc, &a, &b);
                if (c2 <= best + scale) {
                    pmin = fmin(pmin, pc), pmax = fmax(pmax, pc);
                    bmin = fmin(bmin, b), bmax = fmax(bmax, b);
                }
            }
            printf("N = %zu: phi_c = %.4f (+%.4f -%.4f), beta = %.2f (+%.2f -%.2f), chi2/dof = %.2f (%d points)%s\n",
                   pts[k0].n, bphi, pmax - bphi, bphi - pmin, bb, bmax - bb, bb - bmin, dof > 0 ? best / dof : NAN,
                   m, pmin <= lo + 1e-9 ? " (phi_c at the edge: the largest phi bounds it)" : "");
            if (phic_fixed > ph[m - 1]) {
                /* beta at a given phi_c */
                double a0, b0, c0 = line_fit(ph, et, rel, m, phic_fixed, &a0, &b0);
                /* the slope's error of a weighted line: sqrt(S / det) */
                double S = 0, Sx = 0, Sxx = 0;
                for (int k = 0; k < m; ++k) {
                    double w = 1.0 / (rel[k] * rel[k]), x = log(phic_fixed - ph[k]);
                    S += w, Sx += w * x, Sxx += w * x * x;
                }
                int dof1 = m - 2;
                double sc = dof1 > 0 && c0 / dof1 > 1 ? c0 / dof1 : 1.0;
                printf("N = %zu, phi_c fixed at %.4f: beta = %.2f +- %.2f, chi2/dof = %.2f\n", pts[k0].n, phic_fixed,
                       b0, sqrt(sc * S / (S * Sxx - Sx * Sx)), dof1 > 0 ? c0 / dof1 : NAN);
            }
            char name[96];
            snprintf(name, sizeof name, "N = %zu (phi >= %g)", pts[k0].n, phimin);
            int s = pl_series_add(&pl, name, color, 0, 1);
            for (int k = 0; k < m; ++k) pl_point(&pl, s, bphi - ph[k], et[k]);
            pl.s[s].lines = 0;
            snprintf(name, sizeof name, "fit: beta = %.2f, phi_c = %.4f", bb, bphi);
            int sf = pl_series_add(&pl, name, color, 1, 0);
            for (int k = 0; k <= 40; ++k) {
                double x = (bphi - ph[0]) * pow((bphi - ph[m - 1]) / (bphi - ph[0]), k / 40.0);
                pl_point(&pl, sf, x, exp(ba - bb * log(x)));
            }
        } else {
            printf("N = %zu: %d points with phi >= %g: no fit\n", pts[k0].n, m, phimin);
        }
        k0 = k1;
    }
    char path[1024];
    snprintf(path, sizeof path, "%s.svg", prefix);
    pl_note(&pl, "bench/validation_viscosity; runs of examples/sweep_serial (library defaults, cholmod)");
    pl_write_svg(&pl, path);
    pl_free(&pl);
    for (int k = 0; k < npts; ++k) free(pts[k].means);
    return 0;
}
