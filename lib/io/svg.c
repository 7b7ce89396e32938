/* libodhs - SVG pictures of configurations and force networks. */
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "network/network.h"

static int cmp_double(const void *a, const void *b)
{
    double x = *(const double *)a, y = *(const double *)b;
    return (x > y) - (x < y);
}

/* lab -> picture coordinates (y up) */
typedef struct {
    double s, ox, oy, h;
} view;

static double px(const view *v, double x) { return v->ox + v->s * x; }
static double py(const view *v, double y) { return v->h - (v->oy + v->s * y); }

/* 800 px across the sheared cell plus a margin */
static view svg_view(double Lx, double Ly, double g, double W)
{
    double xmin = fmin(0.0, g * Ly), xmax = fmax(Lx, Lx + g * Ly);
    double margin = 10.0;
    view v;
    v.s = (W - 2 * margin) / (xmax - xmin);
    v.ox = margin - v.s * xmin;
    v.oy = margin;
    v.h = v.s * Ly + 2 * margin;
    return v;
}

/* the median radius, and whether the radii take more than one value */
static int median_radius(const odhs_system *sys, double *rmed, int *bidisperse)
{
    size_t n = sys->n;
    double *rs = odhs__malloc_array(n, sizeof *rs);
    if (!rs) return odhs__syserr(sys, ODHS_E_NOMEM, "out of memory");
    memcpy(rs, sys->r, n * sizeof *rs);
    qsort(rs, n, sizeof *rs, cmp_double);
    *rmed = rs[n / 2];
    *bidisperse = rs[0] < *rmed || rs[n - 1] > *rmed;
    odhs__free(rs);
    return ODHS_OK;
}

/* the corners of the periodic cell, as the points of a polygon */
static int svg_cell_points(FILE *f, const view *v, double Lx, double Ly, double g)
{
    int ok = 1;
    double cx[4] = {0, Lx, Lx + g * Ly, g * Ly}, cy[4] = {0, 0, Ly, Ly};
    for (int k = 0; k < 4; ++k) ok &= fprintf(f, "%.3f,%.3f ", px(v, cx[k]), py(v, cy[k])) > 0;
    return ok;
}

/* discs, with the periodic images that reach into the cell */
static int svg_discs(FILE *f, const odhs_system *sys, const view *v, const unsigned char *mark, double rmed,
                     int bidisperse, int ok)
{
    int d = sys->dim;
    size_t n = sys->n;
    double Lx = sys->L[0], Ly = sys->L[1], g = sys->gamma;
    for (size_t i = 0; i < n && ok; ++i) {
        const double *x = sys->x + i * d;
        double r = sys->r[i];
        const char *fill = !bidisperse ? "#9ecae1" : (r < rmed ? "#9ecae1" : "#fdae6b");
        const char *stroke = "#444444";
        double sw = 0.6;
        if (mark && mark[i] == 1) {
            fill = "#d9d9d9";
            stroke = "#cb181d";
            sw = 2.0;
        } else if (mark && mark[i] == 2) {
            fill = "#a50f15";
        }
        for (int iy = -1; iy <= 1; ++iy)
            for (int ix = -2; ix <= 2; ++ix) {
                double X = x[0] + ix * Lx + iy * g * Ly, Y = x[1] + iy * Ly;
                /* skip images that cannot touch the cell */
                if (Y + r < 0 || Y - r > Ly) continue;
                double xl = g * Y; /* left edge of the sheared cell at height Y: x' = x - gamma*y */
                if (X - g * Y + r < 0 || X - g * Y - r > Lx) continue;
                (void)xl;
                ok &= fprintf(f,
                              "<circle cx=\"%.3f\" cy=\"%.3f\" r=\"%.3f\" fill=\"%s\" stroke=\"%s\" "
                              "stroke-width=\"%.2f\"/>\n",
                              px(v, X), py(v, Y), v->s * r, fill, stroke, sw) > 0;
            }
    }
    return ok;
}

/* wall contact c: from the centre to the contact point */
static int svg_wall_contact(FILE *f, const odhs_system *sys, const odhs_network *net, const view *v, size_t c,
                            double fmax, double wmax)
{
    int d = sys->dim;
    size_t i = net->ci[c];
    const double *a = sys->x + i * d, *nr = net->nrm + c * d;
    double w = fmax > 0.0 ? wmax * fabs(net->f[c]) / fmax : 1.0;
    if (w < 0.4) w = 0.4;
    return fprintf(f,
                   "<line x1=\"%.3f\" y1=\"%.3f\" x2=\"%.3f\" y2=\"%.3f\" stroke=\"#000000\" "
                   "stroke-width=\"%.2f\" stroke-linecap=\"round\"/>\n",
                   px(v, a[0]), py(v, a[1]), px(v, a[0] + net->dist[c] * nr[0]),
                   py(v, a[1] + net->dist[c] * nr[1]), w) > 0;
}

/* contact c between two particles: a half line from each end, with the
 * periodic images near the cell, so contacts across the boundary show twice */
static int svg_pair_contact(FILE *f, const odhs_system *sys, const odhs_network *net, const view *v, size_t c,
                            double fmax, double wmax)
{
    int d = sys->dim, ok = 1;
    double Lx = sys->L[0], Ly = sys->L[1], g = sys->gamma;
    size_t i = net->ci[c], j = net->cj[c];
    double dv[3] = {0, 0, 0};
    for (int a = 0; a < d; ++a) dv[a] = sys->x[j * d + a] - sys->x[i * d + a];
    odhs__min_image(d, sys->L, g, dv, NULL);
    int bond = net->kind[c] == ODHS_CONTACT_PERMANENT;
    double w = fmax > 0.0 ? wmax * fabs(net->f[c]) / fmax : 1.0;
    if (w < 0.4) w = 0.4;
    if (bond) w = 0.25 * wmax > 0.8 ? 0.25 * wmax : 0.8; /* bonds: fixed width, the body's skeleton */
    const char *dash = !bond && net->f[c] < 0.0 ? " stroke-dasharray=\"3,2\"" : "";
    const char *col = net->kind[c] == ODHS_CONTACT_PERMANENT ? "#08306b" : "#000000";
    /* draw from both ends so contacts across the boundary show twice */
    for (int side = 0; side < 2; ++side) {
        const double *a = sys->x + (side ? j : i) * d;
        double sgn = side ? -1.0 : 1.0;
        for (int iy = -1; iy <= 1; ++iy)
            for (int ix = -1; ix <= 1; ++ix) {
                double X = a[0] + ix * Lx + iy * g * Ly, Y = a[1] + iy * Ly;
                if (Y < -Ly * 0.5 || Y > Ly * 1.5) continue;
                if (ix || iy) {
                    double xs = X - g * Y;
                    double ext = 2.5 * sys->rmax;
                    if (Y < -ext || Y > Ly + ext || xs < -ext || xs > Lx + ext) continue;
                }
                ok &= fprintf(f,
                              "<line x1=\"%.3f\" y1=\"%.3f\" x2=\"%.3f\" y2=\"%.3f\" stroke=\"%s\" "
                              "stroke-width=\"%.2f\" stroke-linecap=\"round\"%s/>\n",
                              px(v, X), py(v, Y), px(v, X + 0.5 * sgn * dv[0]),
                              py(v, Y + 0.5 * sgn * dv[1]), col, w, dash) > 0;
            }
    }
    return ok;
}

/* force chains: line widths scale with |f| */
static int svg_forces(FILE *f, const odhs_system *sys, const odhs_network *net, const view *v, int ok)
{
    double fmax = 0.0;
    for (size_t c = 0; c < net->nc; ++c)
        if (odhs__can_open(net->kind[c])) fmax = fmax > fabs(net->f[c]) ? fmax : fabs(net->f[c]);
    double wmax = 0.3 * v->s * sys->rmax;
    for (size_t c = 0; c < net->nc && ok; ++c) {
        if (net->cj[c] >= sys->n)
            ok &= svg_wall_contact(f, sys, net, v, c, fmax, wmax);
        else
            ok &= svg_pair_contact(f, sys, net, v, c, fmax, wmax);
    }
    return ok;
}

/* walls (3D: planes seen edge-on and spheres, projected on x-y) */
static int svg_walls(FILE *f, const odhs_system *sys, const odhs_network *net, const view *v, int ok)
{
    int d = sys->dim;
    double Lx = sys->L[0], Ly = sys->L[1];
    for (size_t w = 0; net && w < net->nwalls && ok; ++w) {
        const odhs_wall *wl = &net->walls[w];
        const char *st = "stroke=\"#4d4d4d\" stroke-width=\"4\" stroke-linecap=\"round\" fill=\"none\"";
        if (wl->type == ODHS_WALL_SPHERE) {
            ok &= fprintf(f, "<circle cx=\"%.3f\" cy=\"%.3f\" r=\"%.3f\" %s/>\n", px(v, wl->c[0]), py(v, wl->c[1]),
                          v->s * wl->R, st) > 0;
        } else if (wl->type == ODHS_WALL_SEGMENT) {
            ok &= fprintf(f, "<line x1=\"%.3f\" y1=\"%.3f\" x2=\"%.3f\" y2=\"%.3f\" %s/>\n", px(v, wl->c[0]),
                          py(v, wl->c[1]), px(v, wl->b[0]), py(v, wl->b[1]), st) > 0;
        } else if (d == 2 || fabs(wl->n[2]) < 1e-12) {
            double big = 4.0 * (Lx + Ly), o[2] = {wl->h * wl->n[0], wl->h * wl->n[1]}, t[2] = {-wl->n[1], wl->n[0]};
            ok &= fprintf(f, "<line x1=\"%.3f\" y1=\"%.3f\" x2=\"%.3f\" y2=\"%.3f\" %s/>\n",
                          px(v, o[0] - big * t[0]), py(v, o[1] - big * t[1]), px(v, o[0] + big * t[0]),
                          py(v, o[1] + big * t[1]), st) > 0;
        }
    }
    return ok;
}

int odhs_svg_write(const odhs_system *sys, const odhs_network *net, const unsigned char *mark, const char *path)
{
    if (!sys) return ODHS_E_NULL;
    if (!path) return odhs__syserr(sys, ODHS_E_NULL, "path is NULL");
    if (!sys->has_x || !sys->has_r) return odhs__syserr(sys, ODHS_E_STATE, "radii and positions must be set");
    if (net && (net->n != sys->n || net->dim != sys->dim))
        return odhs__syserr(sys, ODHS_E_DIM, "network does not match the system");
    double Lx = sys->L[0], Ly = sys->L[1], g = sys->gamma;
    double W = 800.0;
    view v = svg_view(Lx, Ly, g, W);
    double rmed = 0.0;
    int bidisperse = 0;
    int st = median_radius(sys, &rmed, &bidisperse);
    if (st) return st;

    size_t len = strlen(path);
    char *tmp = odhs__malloc(len + 8);
    if (!tmp) return odhs__syserr(sys, ODHS_E_NOMEM, "out of memory");
    snprintf(tmp, len + 8, "%s.tmp", path);
    FILE *f = fopen(tmp, "w");
    if (!f) {
        odhs__free(tmp);
        return odhs__syserr(sys, ODHS_E_IO, "cannot write %s.tmp", path);
    }
    int ok = 1;
    ok &= fprintf(f,
                  "<svg xmlns=\"http://www.w3.org/2000/svg\" width=\"%.0f\" height=\"%.0f\" "
                  "viewBox=\"0 0 %.3f %.3f\">\n<rect width=\"100%%\" height=\"100%%\" fill=\"white\"/>\n",
                  W, v.h, W, v.h) > 0;
    /* the periodic cell as a clip path and outline */
    ok &= fprintf(f, "<defs><clipPath id=\"cell\"><polygon points=\"") > 0;
    ok &= svg_cell_points(f, &v, Lx, Ly, g);
    ok &= fprintf(f, "\"/></clipPath></defs>\n<g clip-path=\"url(#cell)\">\n") > 0;
    ok = svg_discs(f, sys, &v, mark, rmed, bidisperse, ok);
    if (net && net->nc) ok = svg_forces(f, sys, net, &v, ok);
    ok = svg_walls(f, sys, net, &v, ok);
    ok &= fprintf(f, "</g>\n<polygon points=\"") > 0;
    ok &= svg_cell_points(f, &v, Lx, Ly, g);
    ok &= fprintf(f, "\" fill=\"none\" stroke=\"#252525\" stroke-width=\"1.5\"/>\n</svg>\n") > 0;
    ok &= fflush(f) == 0;
    ok &= fclose(f) == 0;
    st = ODHS_OK;
    if (!ok || rename(tmp, path) != 0) {
        remove(tmp);
        st = odhs__syserr(sys, ODHS_E_IO, "error writing %s", path);
    }
    odhs__free(tmp);
    return st;
}
