/* examples/plot.h - a small header-only SVG line/scatter plotter shared by the
 * examples (--plot) and the benchmarks: panels with linear or logarithmic
 * axes, ticks and grid, series with markers and/or lines, a legend to the
 * right, an optional footnote (machine, settings); several panels stack in
 * one picture (pl_write_svg_panels). Not installed; not part of the library.
 *
 *   pl_plot p;
 *   pl_init(&p, "title", "x label", "y label", 1, 1);       // log x, log y
 *   int s = pl_series_add(&p, "cg", 0, 0, 1);                // color, dash, marker
 *   pl_point(&p, s, x, y);                                    // repeated
 *   pl_note(&p, "machine ...");
 *   pl_write_svg(&p, "out.svg");
 *   pl_free(&p);
 *
 * Points that are not finite, or not positive on a log axis, are dropped.
 * Lines join a series' points in the order given (lines = 1).
 */
#ifndef ODHS_EXAMPLES_PLOT_H
#define ODHS_EXAMPLES_PLOT_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#define PL_MAXS 24

typedef struct {
    char name[96];
    int color, dash, marker, lines;
    size_t n, cap;
    double *x, *y;
    char (*lab)[24]; /* optional point labels ("" = none) */
} pl_series;

typedef struct {
    char title[160], xlabel[96], ylabel[96];
    char note[3][200];
    int nnotes;
    int logx, logy;
    pl_series s[PL_MAXS];
    int ns;
} pl_plot;

static const char *const pl_colors[] = {"#1f77b4", "#d62728", "#2ca02c", "#ff7f0e", "#9467bd",
                                        "#8c564b", "#e377c2", "#7f7f7f", "#bcbd22", "#17becf"};

static inline void pl_init(pl_plot *p, const char *title, const char *xl, const char *yl, int logx, int logy)
{
    memset(p, 0, sizeof *p);
    snprintf(p->title, sizeof p->title, "%.159s", title);
    snprintf(p->xlabel, sizeof p->xlabel, "%.95s", xl);
    snprintf(p->ylabel, sizeof p->ylabel, "%.95s", yl);
    p->logx = logx;
    p->logy = logy;
}

/* marker: 0 none, 1 circle, 2 square, 3 triangle, 4 diamond, 5 cross */
static inline int pl_series_add(pl_plot *p, const char *name, int color, int dash, int marker)
{
    if (p->ns >= PL_MAXS) return PL_MAXS - 1;
    pl_series *s = &p->s[p->ns];
    memset(s, 0, sizeof *s);
    snprintf(s->name, sizeof s->name, "%.95s", name);
    s->color = color;
    s->dash = dash;
    s->marker = marker;
    s->lines = 1;
    return p->ns++;
}

static inline void pl_point(pl_plot *p, int k, double x, double y)
{
    if (k < 0 || k >= p->ns || !isfinite(x) || !isfinite(y)) return;
    if ((p->logx && !(x > 0)) || (p->logy && !(y > 0))) return;
    pl_series *s = &p->s[k];
    if (s->n == s->cap) {
        size_t c = s->cap ? 2 * s->cap : 16;
        double *nx = realloc(s->x, c * sizeof *nx);
        if (!nx) return;
        s->x = nx;
        double *ny = realloc(s->y, c * sizeof *ny);
        if (!ny) return;
        s->y = ny;
        char(*nl)[24] = realloc(s->lab, c * sizeof *nl);
        if (!nl) return;
        s->lab = nl;
        s->cap = c;
    }
    s->x[s->n] = x;
    s->y[s->n] = y;
    s->lab[s->n][0] = '\0';
    s->n++;
}

/* a point with a small text label next to it */
static inline void pl_point_label(pl_plot *p, int k, double x, double y, const char *label)
{
    if (k < 0 || k >= p->ns) return;
    size_t before = p->s[k].n;
    pl_point(p, k, x, y);
    if (p->s[k].n > before) snprintf(p->s[k].lab[before], sizeof p->s[k].lab[0], "%.23s", label);
}

static inline void pl_note(pl_plot *p, const char *text)
{
    if (p->nnotes < 3) snprintf(p->note[p->nnotes++], sizeof p->note[0], "%.199s", text);
}

static inline void pl_free(pl_plot *p)
{
    for (int k = 0; k < p->ns; ++k) {
        free(p->s[k].x);
        free(p->s[k].y);
        free(p->s[k].lab);
    }
    p->ns = 0;
}

static inline void pl_esc(FILE *f, const char *t)
{
    for (; *t; ++t) {
        if (*t == '<') fputs("&lt;", f);
        else if (*t == '>') fputs("&gt;", f);
        else if (*t == '&') fputs("&amp;", f);
        else fputc(*t, f);
    }
}

/* axis range: data range padded; log axes snap to decades */
static inline void pl_range(const pl_plot *p, int axis, double *lo, double *hi)
{
    int lg = axis ? p->logy : p->logx;
    double a = INFINITY, b = -INFINITY;
    for (int k = 0; k < p->ns; ++k)
        for (size_t i = 0; i < p->s[k].n; ++i) {
            double v = axis ? p->s[k].y[i] : p->s[k].x[i];
            if (lg) v = log10(v);
            a = fmin(a, v);
            b = fmax(b, v);
        }
    if (!isfinite(a)) a = 0, b = 1;
    if (lg) {
        /* at least one decade, padded by 4% so that markers on the edge show */
        if (b - a < 1.0) {
            double m = 0.5 * (a + b);
            a = m - 0.5;
            b = m + 0.5;
        }
        double pad = 0.04 * (b - a);
        a -= pad;
        b += pad;
    } else {
        double pad = (b - a) * 0.05;
        if (pad == 0) pad = fabs(a) > 0 ? 0.1 * fabs(a) : 1.0;
        a -= pad;
        b += pad;
    }
    *lo = a;
    *hi = b;
}

static inline void pl_fmt(char *buf, size_t len, double v, int lg)
{
    if (lg) {
        int e = (int)lrint(v);
        if (e >= -2 && e <= 3) snprintf(buf, len, "%g", pow(10.0, e));
        else snprintf(buf, len, "1e%d", e);
    } else {
        snprintf(buf, len, "%g", fabs(v) < 1e-12 ? 0.0 : v);
    }
}

static inline void pl_marker(FILE *f, int m, double x, double y, const char *c)
{
    switch (m) {
    case 1: fprintf(f, "<circle cx='%.1f' cy='%.1f' r='3.5' fill='%s'/>\n", x, y, c); break;
    case 2: fprintf(f, "<rect x='%.1f' y='%.1f' width='7' height='7' fill='%s'/>\n", x - 3.5, y - 3.5, c); break;
    case 3:
        fprintf(f, "<polygon points='%.1f,%.1f %.1f,%.1f %.1f,%.1f' fill='%s'/>\n", x, y - 4.5, x - 4, y + 3, x + 4,
                y + 3, c);
        break;
    case 4:
        fprintf(f, "<polygon points='%.1f,%.1f %.1f,%.1f %.1f,%.1f %.1f,%.1f' fill='%s'/>\n", x, y - 4.5, x + 4.5, y,
                x, y + 4.5, x - 4.5, y, c);
        break;
    case 5:
        fprintf(f,
                "<path d='M%.1f,%.1f L%.1f,%.1f M%.1f,%.1f L%.1f,%.1f' stroke='%s' stroke-width='2' fill='none'/>\n",
                x - 4, y - 4, x + 4, y + 4, x - 4, y + 4, x + 4, y - 4, c);
        break;
    default: break;
    }
}

#define PL_W 860.0 /* size of one panel */
#define PL_H 520.0

/* one panel at the top left of f's current user space */
static inline void pl_panel_(const pl_plot *p, FILE *f)
{
    const double W = PL_W, H = PL_H, L = 80, R = 250, T = 40, B = 70 + 14 * p->nnotes;
    const double pw = W - L - R, ph = H - T - B;
    double x0, x1, y0, y1;
    pl_range(p, 0, &x0, &x1);
    pl_range(p, 1, &y0, &y1);
#define PL_X(v) (L + ((p->logx ? log10(v) : (v)) - x0) / (x1 - x0) * pw)
#define PL_Y(v) (T + ph - ((p->logy ? log10(v) : (v)) - y0) / (y1 - y0) * ph)
    fprintf(f, "<text x='%.1f' y='22' font-size='15' text-anchor='middle'>", L + pw / 2);
    pl_esc(f, p->title);
    fprintf(f, "</text>\n");
    /* ticks and grid */
    for (int axis = 0; axis < 2; ++axis) {
        int lg = axis ? p->logy : p->logx;
        double a = axis ? y0 : x0, b = axis ? y1 : x1;
        double step;
        if (lg) step = (b - a) > 10 ? 2.0 : 1.0;
        else {
            double raw = (b - a) / 6.0, mag = pow(10.0, floor(log10(raw))), q = raw / mag;
            step = (q < 1.5 ? 1 : q < 3.5 ? 2 : q < 7.5 ? 5 : 10) * mag;
        }
        double vstart = lg ? floor(a) : ceil(a / step - 1e-9) * step;
        for (double v = vstart; v <= b + 1e-9 * step; v += step) {
            double pos = axis ? T + ph - (v - a) / (b - a) * ph : L + (v - a) / (b - a) * pw;
            int major = v >= a - 1e-9;
            char lab[32];
            pl_fmt(lab, sizeof lab, v, lg);
            if (!major) {
                /* below the axis start: only its minor ticks (below) */
            } else if (axis) {
                fprintf(f, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='#ddd'/>\n", L, pos, L + pw, pos);
                fprintf(f, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='black'/>\n", L - 5, pos, L, pos);
                fprintf(f, "<text x='%.1f' y='%.1f' text-anchor='end'>%s</text>\n", L - 8, pos + 4, lab);
            } else {
                fprintf(f, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='#ddd'/>\n", pos, T, pos, T + ph);
                fprintf(f, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='black'/>\n", pos, T + ph, pos,
                        T + ph + 5);
                fprintf(f, "<text x='%.1f' y='%.1f' text-anchor='middle'>%s</text>\n", pos, T + ph + 19, lab);
            }
            /* minor ticks on log axes: 2..9 */
            if (lg && step == 1.0)
                for (int m = 2; m <= 9; ++m) {
                    double u = v + log10((double)m);
                    if (u > b) break;
                    if (u < a) continue;
                    double q = axis ? T + ph - (u - a) / (b - a) * ph : L + (u - a) / (b - a) * pw;
                    if (axis)
                        fprintf(f, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='black'/>\n", L - 3, q, L, q);
                    else
                        fprintf(f, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='black'/>\n", q, T + ph, q,
                                T + ph + 3);
                }
        }
    }
    fprintf(f, "<rect x='%.1f' y='%.1f' width='%.1f' height='%.1f' fill='none' stroke='black'/>\n", L, T, pw, ph);
    fprintf(f, "<text x='%.1f' y='%.1f' text-anchor='middle'>", L + pw / 2, T + ph + 40);
    pl_esc(f, p->xlabel);
    fprintf(f, "</text>\n<text transform='translate(%.1f,%.1f) rotate(-90)' text-anchor='middle'>", 22.0, T + ph / 2);
    pl_esc(f, p->ylabel);
    fprintf(f, "</text>\n");
    /* series */
    fprintf(f, "<svg x='%.1f' y='%.1f' width='%.1f' height='%.1f' viewBox='%.1f %.1f %.1f %.1f' overflow='hidden'>\n",
            L, T, pw, ph, L, T, pw, ph);
    for (int k = 0; k < p->ns; ++k) {
        const pl_series *s = &p->s[k];
        const char *c = pl_colors[s->color % 10];
        if (s->lines && s->n > 1) {
            fprintf(f, "<polyline fill='none' stroke='%s' stroke-width='1.6'%s points='", c,
                    s->dash == 1 ? " stroke-dasharray='6,4'" : s->dash == 2 ? " stroke-dasharray='2,3'" : "");
            for (size_t i = 0; i < s->n; ++i) fprintf(f, "%.1f,%.1f ", PL_X(s->x[i]), PL_Y(s->y[i]));
            fprintf(f, "'/>\n");
        }
        for (size_t i = 0; i < s->n; ++i) pl_marker(f, s->marker, PL_X(s->x[i]), PL_Y(s->y[i]), c);
    }
    fprintf(f, "</svg>\n");
    /* point labels (not clipped; to the left of points in the right tenth) */
    for (int k = 0; k < p->ns; ++k) {
        const pl_series *s = &p->s[k];
        for (size_t i = 0; i < s->n; ++i) {
            if (!s->lab[i][0]) continue;
            double px = PL_X(s->x[i]), py = PL_Y(s->y[i]);
            int left = px > L + 0.9 * pw;
            fprintf(f, "<text x='%.1f' y='%.1f' font-size='9' fill='%s'%s>", left ? px - 6 : px + 6, py - 5,
                    pl_colors[s->color % 10], left ? " text-anchor='end'" : "");
            pl_esc(f, s->lab[i]);
            fprintf(f, "</text>\n");
        }
    }
    /* legend */
    double ly = T + 10;
    for (int k = 0; k < p->ns; ++k) {
        const pl_series *s = &p->s[k];
        const char *c = pl_colors[s->color % 10];
        double lx = L + pw + 15;
        if (s->lines)
            fprintf(f, "<line x1='%.1f' y1='%.1f' x2='%.1f' y2='%.1f' stroke='%s' stroke-width='1.6'%s/>\n", lx, ly,
                    lx + 28, ly, c,
                    s->dash == 1 ? " stroke-dasharray='6,4'" : s->dash == 2 ? " stroke-dasharray='2,3'" : "");
        pl_marker(f, s->marker, lx + 14, ly, c);
        fprintf(f, "<text x='%.1f' y='%.1f'>", lx + 34, ly + 4);
        pl_esc(f, s->name);
        fprintf(f, "</text>\n");
        ly += 18;
    }
    for (int k = 0; k < p->nnotes; ++k) {
        fprintf(f, "<text x='10' y='%.1f' font-size='10' fill='#444'>", H - 10 - 14.0 * (p->nnotes - 1 - k));
        pl_esc(f, p->note[k]);
        fprintf(f, "</text>\n");
    }
#undef PL_X
#undef PL_Y
}

/* n panels stacked from top to bottom in one SVG picture; 0, or -1 when the
 * file cannot be written */
static inline int pl_write_svg_panels(const pl_plot *const *p, int n, const char *path)
{
    FILE *f = fopen(path, "w");
    if (!f) return -1;
    fprintf(f, "<?xml version='1.0' encoding='UTF-8'?>\n");
    fprintf(f, "<svg xmlns='http://www.w3.org/2000/svg' width='%.0f' height='%.0f' viewBox='0 0 %.0f %.0f' "
               "font-family='DejaVu Sans, Arial, sans-serif' font-size='12'>\n", PL_W, PL_H * n, PL_W, PL_H * n);
    fprintf(f, "<rect width='100%%' height='100%%' fill='white'/>\n");
    for (int k = 0; k < n; ++k) {
        fprintf(f, "<g transform='translate(0,%.0f)'>\n", PL_H * k);
        pl_panel_(p[k], f);
        fprintf(f, "</g>\n");
    }
    fprintf(f, "</svg>\n");
    return fclose(f) == 0 ? 0 : -1;
}

static inline int pl_write_svg(const pl_plot *p, const char *path) { return pl_write_svg_panels(&p, 1, path); }

/* least-squares fit of log y = a + e log x over a series' points; returns e */
static inline double pl_fit_loglog(const double *x, const double *y, size_t n, double *a)
{
    double sx = 0, sy = 0, sxx = 0, sxy = 0;
    size_t m = 0;
    for (size_t i = 0; i < n; ++i) {
        if (!(x[i] > 0) || !(y[i] > 0)) continue;
        double u = log(x[i]), v = log(y[i]);
        sx += u;
        sy += v;
        sxx += u * u;
        sxy += u * v;
        m++;
    }
    if (m < 2) return NAN;
    double e = (m * sxy - sx * sy) / (m * sxx - sx * sx);
    if (a) *a = (sy - e * sx) / m;
    return e;
}

#endif /* ODHS_BENCH_PLOT_H */
