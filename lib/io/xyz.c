/*
 * libodhs - the extended XYZ reader (see include/odhs/io.h; the writer is
 * lib/io/xyz_write.c).
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 *
 * Reader design:
 *  - The input is a byte buffer of known length that need not be NUL-ended;
 *    it is only ever accessed through (pointer, length) spans, and numbers are
 *    copied into a small NUL-ended scratch buffer before strtod sees them.
 *  - Everything is parsed into temporary arrays and validated first; the
 *    system is created only at the very end, so an error never leaves a
 *    half-filled system behind (*out stays NULL).
 *  - Only the first frame is read. After the N particle lines, trailing blank
 *    lines are ignored; if more content follows it must look like the start of
 *    another frame (a line holding a positive integer), which is then ignored.
 *    Any other content is reported, because it usually means N is wrong.
 *  - Numbers are parsed with strtod in the current C locale ("C" assumed, as
 *    for the printf-based writer).
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "io/text.h"

#define ODHS_XYZ_OVERLAP_ACCEPT 1e-4 /* relative overlap accepted when reading */

/* Largest particle count accepted from a file (keeps n*dim*sizeof(double)
 * and friends far from overflow; the lines must also really be present). */
#define XYZ_N_MAX ((size_t)100000000)
/* Largest total number of columns in a Properties specification. */
#define XYZ_COLS_MAX ((size_t)100000)

/* ---- small helpers (the shared ones are in io/text.h) ----------------------- */

static char to_lower(char c)
{
    return (c >= 'A' && c <= 'Z') ? (char)(c - 'A' + 'a') : c;
}

/* case-insensitive comparison of a span with a NUL-ended literal */
static int span_ieq(span s, const char *lit)
{
    size_t k = strlen(lit);
    if (s.n != k) return 0;
    for (size_t i = 0; i < k; i++)
        if (to_lower(s.p[i]) != to_lower(lit[i])) return 0;
    return 1;
}

/* ---- the comment line ----------------------------------------------------- */

typedef struct {
    int dim;
    double L[3];
    double gamma;
    size_t ncols;    /* columns per particle line */
    size_t col_sp;   /* species column */
    size_t col_pos;  /* first of three position columns */
    size_t col_rad;  /* radius column */
} header;

/* Split a list value (Lattice) into numbers: separators are white space,
 * commas and brackets. Returns the count found (up to max stored), or -1 on a
 * bad number with *bad set to it. */
static long parse_number_list(span v, double *vals, size_t max, span *bad, int *nonfinite)
{
    size_t i = 0, cnt = 0;
    while (i < v.n) {
        char c = v.p[i];
        if (is_ws(c) || c == ',' || c == '[' || c == ']' || c == '{' || c == '}') {
            i++;
            continue;
        }
        size_t start = i;
        while (i < v.n) {
            c = v.p[i];
            if (is_ws(c) || c == ',' || c == '[' || c == ']' || c == '{' || c == '}') break;
            i++;
        }
        span tok = {v.p + start, i - start};
        double d = 0.0;
        int rc = parse_double(tok, &d);
        if (rc != 0) {
            *bad = tok;
            *nonfinite = (rc == -2);
            return -1;
        }
        if (cnt < max) vals[cnt] = d;
        cnt++;
    }
    return (long)cnt;
}

static int parse_flag(span t, int *flag)
{
    if (span_ieq(t, "t") || span_ieq(t, "true") || span_ieq(t, "1")) {
        *flag = 1;
        return 0;
    }
    if (span_ieq(t, "f") || span_ieq(t, "false") || span_ieq(t, "0")) {
        *flag = 0;
        return 0;
    }
    return -1;
}

/* Which of the columns species, pos and radius Properties has named. */
typedef struct {
    int sp, pos, rad, type; /* type: a type:S:1 column (the label when species is absent) */
    size_t col_type;
} props_seen;

/* The count of the column name:type:count that starts at column *col; the
 * columns species, pos and radius are checked and recorded in h. */
static int parse_column(span name, span type, span f, size_t lineno, props_seen *have,
                        size_t *col, header *h, char *msg)
{
    size_t count = 0;
    int rc = parse_count(f, XYZ_COLS_MAX, &count);
    if (rc != 0 || count == 0)
        return odhs__err(msg, ODHS_E_FORMAT,
                         "line %zu: Properties: column '%.*s' has invalid count '%.*s'",
                         lineno, show_len(name), name.p, show_len(f), f.p);
    if (count > XYZ_COLS_MAX - *col)
        return odhs__err(msg, ODHS_E_FORMAT,
                         "line %zu: Properties: too many columns", lineno);
    char t = to_lower(type.p[0]);
    if (span_ieq(name, "species")) {
        if (have->sp)
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: Properties: duplicate column 'species'", lineno);
        if (t != 's' || count != 1)
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: Properties: 'species' must be S:1", lineno);
        have->sp = 1;
        h->col_sp = *col;
    } else if (span_ieq(name, "pos")) {
        if (have->pos)
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: Properties: duplicate column 'pos'", lineno);
        if (t != 'r' || count != 3)
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: Properties: 'pos' must be R:3", lineno);
        have->pos = 1;
        h->col_pos = *col;
    } else if (span_ieq(name, "radius")) {
        if (have->rad)
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: Properties: duplicate column 'radius'", lineno);
        if (t != 'r' || count != 1)
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: Properties: 'radius' must be R:1", lineno);
        have->rad = 1;
        h->col_rad = *col;
    } else if (span_ieq(name, "type") && t == 's' && count == 1 && !have->type) {
        /* trajectories (odhs_traj) name the label column type, so that ASE,
         * which takes species for chemical symbols, reads them */
        have->type = 1;
        have->col_type = *col;
    }
    *col += count;
    return ODHS_OK;
}

/* Properties=name:type:count:... -> columns of species, pos, radius. */
static int parse_properties(span v, size_t lineno, header *h, char *msg)
{
    size_t i = 0, field = 0, col = 0;
    span name = {NULL, 0}, type = {NULL, 0};
    props_seen have = {0, 0, 0, 0, 0};
    for (;;) {
        size_t start = i;
        while (i < v.n && v.p[i] != ':') i++;
        span f = {v.p + start, i - start};
        int last = (i >= v.n);
        switch (field % 3) {
        case 0:
            if (f.n == 0)
                return odhs__err(msg, ODHS_E_FORMAT,
                                 "line %zu: Properties: empty column name", lineno);
            name = f;
            break;
        case 1:
            if (!(f.n == 1 && (span_ieq(f, "s") || span_ieq(f, "r") || span_ieq(f, "i") ||
                               span_ieq(f, "l"))))
                return odhs__err(msg, ODHS_E_FORMAT,
                                 "line %zu: Properties: column '%.*s' has unknown type "
                                 "'%.*s' (expected S, R, I or L)",
                                 lineno, show_len(name), name.p, show_len(f), f.p);
            type = f;
            break;
        default: {
            int st = parse_column(name, type, f, lineno, &have, &col, h, msg);
            if (st < 0) return st;
            break;
        }
        }
        field++;
        if (last) break;
        i++; /* skip ':' */
    }
    if (field % 3 != 0)
        return odhs__err(msg, ODHS_E_FORMAT,
                         "line %zu: Properties: expected name:type:count triplets", lineno);
    if (!have.sp && have.type) {
        have.sp = 1;
        h->col_sp = have.col_type;
    }
    if (!have.sp || !have.pos || !have.rad)
        return odhs__err(msg, ODHS_E_FORMAT,
                         "line %zu: Properties must contain species:S:1 (or type:S:1), pos:R:3 and "
                         "radius:R:1 (missing %s)",
                         lineno, !have.sp ? "species" : !have.pos ? "pos" : "radius");
    h->ncols = col;
    return ODHS_OK;
}

enum { K_LATTICE, K_PROPERTIES, K_PBC, K_DIM, K_STRAIN, K_COUNT };
static const char *const key_names[K_COUNT] = {"Lattice", "Properties", "pbc", "dim", "strain"};

/* Split the comment line into key[=value] items: the value of each known
 * key in val[], have[] set for those present; other keys are ignored. */
static int split_items(span line, size_t lineno, span *val, int *have, char *msg)
{
    size_t i = 0;
    for (;;) {
        while (i < line.n && is_ws(line.p[i])) i++;
        if (i >= line.n) break;
        size_t start = i;
        while (i < line.n && !is_ws(line.p[i]) && line.p[i] != '=') i++;
        span key = {line.p + start, i - start};
        if (key.n == 0)
            return odhs__err(msg, ODHS_E_FORMAT, "line %zu: '=' without a key", lineno);
        size_t j = i;
        while (j < line.n && is_ws(line.p[j])) j++;
        span v = {line.p + i, 0};
        int has_value = 0;
        if (j < line.n && line.p[j] == '=') {
            has_value = 1;
            i = j + 1;
            while (i < line.n && is_ws(line.p[i])) i++;
            if (i < line.n && (line.p[i] == '"' || line.p[i] == '{' || line.p[i] == '[')) {
                char close = line.p[i] == '"' ? '"' : line.p[i] == '{' ? '}' : ']';
                i++;
                size_t vs = i;
                while (i < line.n && line.p[i] != close) {
                    if (close == '"' && line.p[i] == '\\' && i + 1 < line.n)
                        i += 2;
                    else
                        i++;
                }
                if (i >= line.n)
                    return odhs__err(msg, ODHS_E_FORMAT,
                                     "line %zu: unterminated value of key '%.*s'", lineno,
                                     show_len(key), key.p);
                v.p = line.p + vs;
                v.n = i - vs;
                i++; /* closing character */
            } else {
                size_t vs = i;
                while (i < line.n && !is_ws(line.p[i])) i++;
                v.p = line.p + vs;
                v.n = i - vs;
            }
        }
        for (int k = 0; k < K_COUNT; k++) {
            if (!span_ieq(key, key_names[k])) continue;
            if (!has_value)
                return odhs__err(msg, ODHS_E_FORMAT, "line %zu: key '%s' has no value", lineno,
                                 key_names[k]);
            if (have[k])
                return odhs__err(msg, ODHS_E_FORMAT, "line %zu: duplicate key '%s'", lineno,
                                 key_names[k]);
            have[k] = 1;
            val[k] = v;
        }
        /* any other key (with or without value) is ignored */
    }
    return ODHS_OK;
}

/* The dimension from the keys pbc and dim (3 without either). */
static int parse_dim(const span *val, const int *have, size_t lineno, int *out, char *msg)
{
    int dim = 3;
    if (have[K_PBC]) {
        int flags[3] = {1, 1, 1};
        size_t k = 0, nf = 0;
        span t;
        while (next_token(val[K_PBC], &k, &t)) {
            if (nf >= 3 || parse_flag(t, &flags[nf]) != 0)
                return odhs__err(msg, ODHS_E_FORMAT,
                                 "line %zu: pbc must be three flags T or F, got \"%.*s\"", lineno,
                                 show_len(val[K_PBC]), val[K_PBC].p);
            nf++;
        }
        if (nf != 3)
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: pbc must be three flags T or F, got \"%.*s\"", lineno,
                             show_len(val[K_PBC]), val[K_PBC].p);
        if (!flags[2]) dim = 2;
    }
    if (have[K_DIM]) {
        span d = trim(val[K_DIM]);
        if (span_ieq(d, "2"))
            dim = 2;
        else if (span_ieq(d, "3"))
            dim = 3;
        else
            return odhs__err(msg, ODHS_E_FORMAT, "line %zu: dim must be 2 or 3, got '%.*s'",
                             lineno, show_len(d), d.p);
    }
    *out = dim;
    return ODHS_OK;
}

/* Lattice: the box edges into h->L, the shear component b_x into *bx. */
static int parse_lattice(span value, int dim, size_t lineno, header *h, double *bx_out, char *msg)
{
    double lat[9];
    span bad = {NULL, 0};
    int nonfinite = 0;
    long cnt = parse_number_list(value, lat, 9, &bad, &nonfinite);
    if (cnt < 0)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: Lattice: %s '%.*s'", lineno,
                         nonfinite ? "non-finite number" : "invalid number", show_len(bad),
                         bad.p);
    if (cnt != 9)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: Lattice: expected 9 numbers, found %ld",
                         lineno, cnt);
    double Lx = lat[0], bx = lat[3], Ly = lat[4], Lz = lat[8];
    double scale = fabs(Lx) + fabs(Ly) + fabs(Lz);
    double tol = 1e-12 * scale;
    int ok = Lx > 0.0 && Ly > 0.0 && fabs(lat[1]) <= tol && fabs(lat[2]) <= tol &&
             fabs(lat[5]) <= tol && fabs(lat[6]) <= tol && fabs(lat[7]) <= tol &&
             (dim == 2 ? Lz >= 0.0 : Lz > 0.0);
    if (!ok)
        return odhs__err(msg, ODHS_E_FORMAT,
                         "line %zu: Lattice: only orthogonal cells with x-y shear supported "
                         "(need a=(Lx,0,0), b=(bx,Ly,0), c=(0,0,Lz) with Lx, Ly, Lz > 0)",
                         lineno);
    h->L[0] = Lx;
    h->L[1] = Ly;
    h->L[2] = dim == 3 ? Lz : 1.0;
    *bx_out = bx;
    return ODHS_OK;
}

/* The strain: the key strain (NULL if absent), which must agree with the
 * Lattice's bx = strain * Ly, else bx / Ly. */
static int parse_strain(const span *value, double bx, double Ly, size_t lineno, header *h,
                        char *msg)
{
    if (value) {
        double g = 0.0;
        span s = trim(*value);
        int rc = parse_double(s, &g);
        if (rc != 0)
            return odhs__err(msg, ODHS_E_FORMAT, "line %zu: strain: %s '%.*s'", lineno,
                             rc == -2 ? "non-finite number" : "invalid number", show_len(s), s.p);
        if (!(fabs(bx - g * Ly) <= 1e-9 * Ly))
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: strain=%.17g disagrees with the Lattice "
                             "(bx = %.17g, expected strain*Ly = %.17g)",
                             lineno, g, bx, g * Ly);
        h->gamma = g;
    } else {
        h->gamma = bx / Ly;
        if (!isfinite(h->gamma))
            return odhs__err(msg, ODHS_E_FORMAT, "line %zu: Lattice: strain bx/Ly not finite",
                             lineno);
    }
    return ODHS_OK;
}

static int parse_header(span line, size_t lineno, header *h, char *msg)
{
    span val[K_COUNT];
    int have[K_COUNT] = {0};

    /* 1. split into key[=value] items */
    int st = split_items(line, lineno, val, have, msg);
    if (st < 0) return st;

    /* 2. interpret */
    if (!have[K_LATTICE])
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: missing Lattice key", lineno);
    if (!have[K_PROPERTIES])
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: missing Properties key", lineno);

    st = parse_properties(val[K_PROPERTIES], lineno, h, msg);
    if (st < 0) return st;

    int dim = 3;
    st = parse_dim(val, have, lineno, &dim, msg);
    if (st < 0) return st;
    h->dim = dim;

    double bx = 0.0;
    st = parse_lattice(val[K_LATTICE], dim, lineno, h, &bx, msg);
    if (st < 0) return st;
    return parse_strain(have[K_STRAIN] ? &val[K_STRAIN] : NULL, bx, h->L[1], lineno, h, msg);
}

/* ---- particle lines --------------------------------------------------------- */

static int parse_particle(span line, size_t lineno, const header *h, double *x, double *r,
                          char *label, char *msg)
{
    size_t ncol = count_tokens(line);
    if (ncol != h->ncols)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: expected %zu columns, found %zu", lineno,
                         h->ncols, ncol);
    size_t i = 0, c = 0;
    span tok;
    while (next_token(line, &i, &tok)) {
        double *dst = NULL;
        const char *what = NULL;
        double zdummy = 0.0;
        if (c == h->col_sp) {
            if (!valid_label(tok))
                return odhs__err(msg, ODHS_E_FORMAT,
                                 "line %zu: invalid species label '%.*s' (1..%d printable "
                                 "characters, no white space or quotes)",
                                 lineno, show_len(tok), tok.p, ODHS_SPECIES_MAX);
            memcpy(label, tok.p, tok.n);
            label[tok.n] = '\0';
        } else if (c >= h->col_pos && c < h->col_pos + 3) {
            size_t k = c - h->col_pos;
            what = "pos";
            dst = (k < (size_t)h->dim) ? &x[k] : &zdummy;
        } else if (c == h->col_rad) {
            what = "radius";
            dst = r;
        }
        if (dst) {
            int rc = parse_double(tok, dst);
            if (rc != 0)
                return odhs__err(msg, ODHS_E_FORMAT, "line %zu: column %zu (%s): %s '%.*s'",
                                 lineno, c + 1, what,
                                 rc == -2 ? "non-finite number" : "invalid number",
                                 show_len(tok), tok.p);
        }
        c++;
    }
    if (!(*r > 0.0))
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: radius must be positive, got %.17g",
                         lineno, *r);
    return ODHS_OK;
}

/* Whether a line holds just a positive integer (the start of another frame). */
static int is_frame_start(span line)
{
    span t = trim(line);
    size_t v = 0;
    return parse_count(t, XYZ_N_MAX, &v) == 0 && v > 0;
}

static int is_blank(span line)
{
    return trim(line).n == 0;
}

/* Line 1: the number of particles. */
static int parse_count_line(reader *rd, size_t *out, char *msg)
{
    span line;
    if (!next_line(rd, &line))
        return odhs__err(msg, ODHS_E_FORMAT, "line 1: empty file");
    span t = trim(line);
    size_t n = 0;
    int rc = parse_count(t, XYZ_N_MAX, &n);
    if (rc == -2)
        return odhs__err(msg, ODHS_E_FORMAT,
                         "line 1: number of particles too large (at most %zu)", XYZ_N_MAX);
    if (rc != 0 || n == 0)
        return odhs__err(msg, ODHS_E_FORMAT,
                         "line 1: expected the number of particles (a positive integer), "
                         "found '%.*s'",
                         show_len(t), t.p);
    *out = n;
    return ODHS_OK;
}

/* The n particle lines (known to exist) into x, r and sp, then what follows
 * them: first frame only, so skip blank lines, accept (and ignore) a
 * following frame, reject anything else (usually a wrong N). */
static int parse_body(reader *rd, size_t n, const header *h, double *x, double *r,
                      char (*sp)[ODHS_SPECIES_MAX + 1], char *msg)
{
    span line;
    int dim = h->dim;
    for (size_t i = 0; i < n; i++) {
        if (!next_line(rd, &line)) /* cannot happen after pass 1 */
            return odhs__err(msg, ODHS_E_INTERNAL, "line %zu: unexpected end of input",
                             rd->lineno + 1);
        int st = parse_particle(line, rd->lineno, h, &x[i * (size_t)dim], &r[i], sp[i], msg);
        if (st < 0) return st;
    }
    while (next_line(rd, &line)) {
        if (is_blank(line)) continue;
        if (!is_frame_start(line))
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: unexpected content after %zu particle lines "
                             "(is the particle count on line 1 right?)",
                             rd->lineno, n);
        break;
    }
    return ODHS_OK;
}

/* Build and validate the system; *out is set only on success. */
static int build_system(size_t n, const header *h, const double *x, const double *r,
                        char (*sp)[ODHS_SPECIES_MAX + 1], odhs_system **out, char *msg)
{
    odhs_system *sys = NULL;
    int st = odhs_system_create(h->dim, n, &sys);
    if (st < 0) {
        odhs__err(msg, st, "cannot create system: %s", odhs_strerror(st));
        return st;
    }
    /* a state written between two drift corrections holds contacts whose
     * gaps drift (up to ~1e-4 of the contact distance with the paper's
     * Euler steps): read such files back; real overlaps are still refused */
    sys->overlap_accept = ODHS_XYZ_OVERLAP_ACCEPT;
    st = odhs_system_set_configuration(sys, h->L, h->gamma, r, x);
    sys->overlap_accept = 0.0;
    if (st < 0) {
        odhs__err(msg, st, "file: %s", odhs_system_errmsg(sys));
        goto done;
    }
    for (size_t i = 0; i < n; i++) {
        st = odhs_system_set_species(sys, i, sp[i]);
        if (st < 0) {
            odhs__err(msg, ODHS_E_FORMAT, "line %zu: species '%s': %s", i + 3, sp[i],
                      odhs_system_errmsg(sys));
            st = ODHS_E_FORMAT;
            goto done;
        }
    }
    st = ODHS_OK;
    *out = sys;
    sys = NULL;

done:
    odhs_system_destroy(sys);
    return st;
}

static int parse_impl(const char *buf, size_t len, odhs_system **out, char *msg, void *ctx)
{
    (void)ctx;
    reader rd = {buf, len, 0, 0};
    span line;

    /* line 1: N */
    size_t n = 0;
    int st = parse_count_line(&rd, &n, msg);
    if (st < 0) return st;

    /* line 2: key=value pairs */
    if (!next_line(&rd, &line))
        return odhs__err(msg, ODHS_E_FORMAT, "line 2: file ends before the comment line");
    header h;
    memset(&h, 0, sizeof h);
    st = parse_header(line, rd.lineno, &h, msg);
    if (st < 0) return st;

    /* pass 1: make sure the N lines exist before allocating anything */
    reader body = rd;
    for (size_t i = 0; i < n; i++) {
        if (!next_line(&rd, &line))
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: file ends after %zu of %zu particle lines", rd.lineno + 1,
                             i, n);
    }

    /* pass 2: parse into temporary arrays, then build the system */
    int dim = h.dim;
    double *x = odhs__malloc_array(n, (size_t)dim * sizeof(double));
    double *r = odhs__malloc_array(n, sizeof(double));
    char(*sp)[ODHS_SPECIES_MAX + 1] = odhs__malloc_array(n, sizeof *sp);
    if (!x || !r || !sp) {
        st = odhs__err(msg, ODHS_E_NOMEM, "out of memory reading %zu particles", n);
        goto done;
    }
    rd = body;
    st = parse_body(&rd, n, &h, x, r, sp, msg);
    if (st < 0) goto done;
    st = build_system(n, &h, x, r, sp, out, msg);

done:
    odhs__free(x);
    odhs__free(r);
    odhs__free(sp);
    return st;
}

int odhs_xyz_parse(const char *buf, size_t len, odhs_system **out, char *errbuf, size_t errlen)
{
    return odhs__parse_entry(buf, len, out, errbuf, errlen, parse_impl, NULL);
}

int odhs_xyz_read(const char *path, odhs_system **out, char *errbuf, size_t errlen)
{
    return odhs__read_entry(path, out, errbuf, errlen, parse_impl, NULL);
}

/* The frames of a multi-frame file: each starts at a line holding its
 * particle count N and has N + 1 more lines; blank lines between frames are
 * skipped. Stores the byte offset and first line of frame `want` (of every
 * frame in turn when want < 0, so the last one stays); returns the count, or
 * an error (message in msg) when a frame is cut short or a count is missing. */
static long scan_frames(const char *buf, size_t len, long want, size_t *off_out, size_t *line_out, char *msg)
{
    reader rd = {buf, len, 0, 0};
    long k = 0;
    for (;;) {
        size_t off = rd.pos;
        span line;
        if (!next_line(&rd, &line)) break;
        if (is_blank(line)) continue;
        size_t n = 0;
        span t = trim(line);
        if (parse_count(t, XYZ_N_MAX, &n) != 0 || n == 0)
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: expected the particle count of frame %ld, found '%.*s'", rd.lineno, k,
                             show_len(t), t.p);
        size_t first = rd.lineno;
        if (k == want || want < 0) {
            *off_out = off;
            *line_out = first;
        }
        for (size_t i = 0; i < n + 1; ++i)
            if (!next_line(&rd, &line))
                return odhs__err(msg, ODHS_E_FORMAT, "frame %ld (line %zu): the file ends after %zu of its %zu lines",
                                 k, first, i, n + 1);
        ++k;
    }
    return k;
}

typedef struct {
    long frame, *nframes;
    const char *path;
} frame_req;

/* frame req->frame of the file in buf */
static int parse_frame(const char *buf, size_t len, odhs_system **out, char *msg, void *ctx)
{
    const frame_req *req = ctx;
    /* the first pass counts the frames; the second finds the one wanted */
    size_t off = 0, line = 0;
    long count = scan_frames(buf, len, -2, &off, &line, msg);
    if (count < 0) return (int)count;
    long k = req->frame < 0 ? count + req->frame : req->frame;
    if (k < 0 || k >= count)
        return odhs__err(msg, ODHS_E_RANGE, "'%s' holds %ld frame%s; frame %ld does not exist", req->path, count,
                         count == 1 ? "" : "s", req->frame);
    scan_frames(buf, len, k, &off, &line, msg);
    int st = parse_impl(buf + off, len - off, out, msg, NULL);
    if (st < 0) {
        char inner[ODHS_ERRMSG_LEN];
        memcpy(inner, msg, sizeof inner);
        return odhs__err(msg, st, "frame %ld (from line %zu): %s", k, line, inner);
    }
    if (req->nframes) *req->nframes = count;
    return st;
}

int odhs_xyz_read_frame(const char *path, long frame, odhs_system **out, long *nframes, char *errbuf,
                        size_t errlen)
{
    frame_req req = {frame, nframes, path};
    return odhs__read_entry(path, out, errbuf, errlen, parse_frame, &req);
}
