/* collapse - fit the scaling collapse of flow curves near jamming with libodhs
 * (odhs_collapse_fit, analysis.h):
 *     O(phi, rate) = rate^(y / z nu) F((phi - phi_J) / rate^(1 / z nu)),
 * eq. (5.2) of Vagberg's thesis, from a CSV file with columns phi, rate, the
 * observable (default column "shear_stress"; --value NAME) and, if present,
 * its relative error (column "<NAME>_err", else --rel-err; with --err-absolute
 * the column holds absolute errors, as sweep summaries and the benchmarks'
 * tables do). Prints phi_J, y,
 * z nu with their errors and chi2 per degree of freedom; --plot draws the
 * collapsed data (each rate its colour) on the fitted master curve.
 *
 *     cc collapse.c $(pkg-config --cflags --libs odhs) -lm -o collapse
 *     collapse --data flow.csv --guess 0.843,1.1,3.5 --plot collapse.svg
 */
#define _POSIX_C_SOURCE 200809L
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include <odhs.h>

#include "cli.h"
#include "plot.h"

#define MAXCOLS 32

/* the index of name in the header's comma-separated fields, or -1 */
static int column(char *header, const char *name)
{
    int k = 0;
    for (char *tok = strtok(header, ",\r\n"); tok; tok = strtok(NULL, ",\r\n"), ++k)
        if (!strcmp(tok, name)) return k;
    return -1;
}

typedef struct {
    double *phi, *rate, *val, *err;
    size_t n, cap;
} data;

/* read the CSV: 0, or 1 with a message */
static int read_csv(const char *path, const char *value, double rel_err, int err_abs, data *d)
{
    FILE *f = fopen(path, "r");
    if (!f) {
        perror(path);
        return 1;
    }
    char line[4096], hdr[4096], errname[128];
    snprintf(errname, sizeof errname, "%s_err", value);
    if (!fgets(line, sizeof line, f)) {
        fprintf(stderr, "collapse: %s is empty\n", path);
        fclose(f);
        return 1;
    }
    int cp, cr, cv, ce;
    strcpy(hdr, line);
    cp = column(hdr, "phi");
    strcpy(hdr, line);
    cr = column(hdr, "rate");
    strcpy(hdr, line);
    cv = column(hdr, value);
    strcpy(hdr, line);
    ce = column(hdr, errname);
    if (cp < 0 || cr < 0 || cv < 0) {
        fprintf(stderr, "collapse: %s: the header needs the columns phi, rate and %s\n", path, value);
        fclose(f);
        return 1;
    }
    size_t lineno = 1;
    while (fgets(line, sizeof line, f)) {
        ++lineno;
        if (line[0] == '#' || line[0] == '\n') continue;
        double v[MAXCOLS];
        int nv = 0;
        for (char *tok = strtok(line, ",\r\n"); tok && nv < MAXCOLS; tok = strtok(NULL, ",\r\n")) {
            char *end;
            v[nv++] = strtod(tok, &end);
            if (end == tok) v[nv - 1] = NAN;
        }
        if (nv <= cp || nv <= cr || nv <= cv || (ce >= 0 && nv <= ce)) {
            fprintf(stderr, "collapse: %s:%zu: too few fields\n", path, lineno);
            fclose(f);
            return 1;
        }
        if (d->n == d->cap) {
            d->cap = d->cap ? 2 * d->cap : 64;
            d->phi = realloc(d->phi, d->cap * sizeof *d->phi);
            d->rate = realloc(d->rate, d->cap * sizeof *d->rate);
            d->val = realloc(d->val, d->cap * sizeof *d->val);
            d->err = realloc(d->err, d->cap * sizeof *d->err);
            if (!d->phi || !d->rate || !d->val || !d->err) {
                fprintf(stderr, "collapse: out of memory\n");
                fclose(f);
                return 1;
            }
        }
        d->phi[d->n] = v[cp];
        d->rate[d->n] = v[cr];
        d->val[d->n] = v[cv];
        d->err[d->n] = ce < 0 ? rel_err : err_abs ? fabs(v[ce] / v[cv]) : v[ce];
        d->n++;
    }
    fclose(f);
    return 0;
}

int main(int argc, char **argv)
{
    const char *path = NULL, *value = "shear_stress", *guess_s = NULL, *plot = NULL;
    double rel_err = 0.01;
    int degree = 3, quiet = 0, err_abs = 0;
    const cli_opt opts[] = {
        CLI_OPT_STRING("--data", &path, "FILE.csv", "the flow curves: a header line naming phi, rate, the value",
                       CLI_ANY),
        CLI_OPT_STRING("--value", &value, "NAME", "the observable's column (its error: NAME_err)", CLI_ANY),
        CLI_OPT_DOUBLE("--rel-err", &rel_err, "E", "relative error of each value without a NAME_err column",
                       CLI_POSITIVE),
        CLI_OPT_FLAG("--err-absolute", &err_abs, "the NAME_err column holds absolute errors (default: relative)"),
        CLI_OPT_INT("--degree", &degree, "K", "degree of the master curve's polynomial in ln F", CLI_BETWEEN(1, 7)),
        CLI_OPT_STRING("--guess", &guess_s, "PHIJ,Y,ZNU", "starting point (default: the largest phi, 1, 3)", CLI_ANY),
        CLI_OPT_STRING("--plot", &plot, "FILE.svg", "draw the collapse: ln(O / rate^q) against x", CLI_ANY),
        CLI_QUIET(&quiet),
        CLI_END,
    };
    const cli_spec cli = {"collapse", NULL, opts,
                          "Fits phi_J, y and z nu of O = rate^(y/z nu) F((phi - phi_J)/rate^(1/z nu)) (Olsson and\n"
                          "Teitel 2007; eq. 5.2 of Vagberg's thesis) to flow curves at several rates.\n",
                          0};
    int rc = cli_parse(&cli, argc, argv);
    if (rc != CLI_GO) return rc;
    if (!path) {
        fprintf(stderr, "collapse: --data FILE.csv is required\n");
        cli_usage(&cli, stderr);
        return 2;
    }
    double guess[3];
    if (guess_s && sscanf(guess_s, "%lf,%lf,%lf", &guess[0], &guess[1], &guess[2]) != 3) {
        fprintf(stderr, "collapse: --guess %s: expected PHIJ,Y,ZNU\n", guess_s);
        return 2;
    }
    data d = {0};
    if (read_csv(path, value, rel_err, err_abs, &d)) return 1;
    odhs_collapse c;
    memset(&c, 0, sizeof c);
    c.size = sizeof c;
    rc = odhs_collapse_fit(d.phi, d.rate, d.val, d.err, d.n, degree, guess_s ? guess : NULL, &c);
    if (rc) {
        fprintf(stderr, "collapse: %s\n", odhs_last_error());
        return 1;
    }
    if (!quiet) fprintf(stderr, "collapse: %zu points from %s, degree %d\n", d.n, path, degree);
    printf("phi_J = %.5f +- %.5f\ny     = %.4f +- %.4f\nz nu  = %.4f +- %.4f\n", c.phi_j, c.phi_j_err, c.y, c.y_err,
           c.znu, c.znu_err);
    printf("q = y / z nu = %.4f; chi2 / dof = %.3f / %zu = %.3f\n", c.q, c.chi2, c.dof,
           c.chi2 / (double)(c.dof ? c.dof : 1));
    if (plot) {
        pl_plot p;
        char title[200];
        snprintf(title, sizeof title, "collapse of %s: phi_J = %.4f, y = %.3f, z nu = %.3f", value, c.phi_j, c.y,
                 c.znu);
        pl_init(&p, title, "x = (phi - phi_J) / rate^(1/z nu)", "ln(O / rate^(y/z nu))", 0, 0);
        /* one series per rate, in the order met */
        double rates[PL_MAXS - 1];
        int nr = 0;
        for (size_t k = 0; k < d.n; ++k) {
            int r = 0;
            while (r < nr && rates[r] != d.rate[k]) ++r;
            if (r == nr && nr < PL_MAXS - 1) {
                char nm[64];
                snprintf(nm, sizeof nm, "rate %.3g", d.rate[k]);
                rates[nr++] = d.rate[k];
                int s = pl_series_add(&p, nm, r % 10, 0, 1 + r % 5);
                p.s[s].lines = 0;
            }
            if (r < nr) {
                double x = (d.phi[k] - c.phi_j) / pow(d.rate[k], 1.0 / c.znu);
                pl_point(&p, r, x, log(d.val[k]) - c.q * log(d.rate[k]));
            }
        }
        int m = pl_series_add(&p, "master curve", 7, 0, 0);
        for (int k = 0; k <= 200; ++k) {
            double t = -1.0 + 2.0 * k / 200.0, v = 0.0, tp = 1.0;
            for (int j = 0; j <= c.degree; ++j) {
                v += c.coef[j] * tp;
                tp *= t;
            }
            pl_point(&p, m, c.x0 + c.xs * t, v);
        }
        rc = pl_write_svg(&p, plot);
        pl_free(&p);
        if (rc) {
            fprintf(stderr, "collapse: cannot write %s\n", plot);
            return 1;
        }
    }
    free(d.phi), free(d.rate), free(d.val), free(d.err);
    return 0;
}
