/*
 * libodhs - LAMMPS data files, atom_style sphere: reader and writer (see
 * include/odhs/lammps.h; the LAMMPS conventions shared with the dump writers
 * are in lib/io/lmp.h).
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 *
 * Reader design (as the extended XYZ reader, lib/io/xyz.c):
 *  - The input is a byte buffer of known length that need not be NUL-ended;
 *    it is only ever accessed through (pointer, length) spans, and numbers are
 *    copied into a small NUL-ended scratch buffer before strtod sees them.
 *  - Pass 1 reads the title and the header, then walks the sections without
 *    allocating anything: it finds the Atoms section and makes sure it holds
 *    exactly N data lines (so an absurd N in the header costs nothing), and
 *    checks that every other line is a section keyword or a data line.
 *  - Pass 2 parses the Atoms lines into temporary arrays and validates them;
 *    the system is created only at the very end, so an error never leaves a
 *    half-filled system behind (*out stays NULL).
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

#include "io/lmp.h"
#include "io/text.h"
#include "odhs/lammps.h"

#define ODHS_LMP_OVERLAP_ACCEPT 1e-4 /* relative overlap accepted when reading (as XYZ) */

/* Largest atom count accepted from a file (keeps the arrays far from
 * overflow; the lines must also really be present). */
#define LMP_N_MAX ((size_t)100000000)
/* Largest number of atom types (no array depends on it; labels stay short). */
#define LMP_TYPES_MAX ((size_t)100000000)
/* Tolerance, relative to Lx, of the check that the title's strain describes
 * the same lattice as the tilt xy. */
#define LMP_STRAIN_TOL 1e-12

/* ---- small helpers (the reader accesses the input through spans only) ---- */

static int is_digit(char c)
{
    return c >= '0' && c <= '9';
}

static int is_letter(char c)
{
    return (c >= 'A' && c <= 'Z') || (c >= 'a' && c <= 'z');
}

/* the first character of a data line (a number) */
static int is_data_start(char c)
{
    return is_digit(c) || c == '-' || c == '+' || c == '.';
}

/* exact (case-sensitive, as LAMMPS) comparison of a span with a literal */
static int span_eq(span s, const char *lit)
{
    size_t k = strlen(lit);
    return s.n == k && memcmp(s.p, lit, k) == 0;
}

static int span_starts(span s, const char *lit)
{
    size_t k = strlen(lit);
    return s.n >= k && memcmp(s.p, lit, k) == 0;
}

/* Next line split at its first '#': the trimmed text before it in *body, the
 * trimmed text after it in *comment (empty without '#'). 0 at the end. */
static int next_content(reader *rd, span *body, span *comment)
{
    span line;
    if (!next_line(rd, &line)) return 0;
    const char *hash = memchr(line.p, '#', line.n);
    span b = line, c = {line.p + line.n, 0};
    if (hash) {
        b.n = (size_t)(hash - line.p);
        c.p = hash + 1;
        c.n = line.n - b.n - 1;
    }
    *body = trim(b);
    *comment = trim(c);
    return 1;
}

/* Whether a token is an integer: an optional sign and 1..20 digits. */
static int is_integer(span tok)
{
    size_t i = 0;
    if (tok.n > 0 && (tok.p[0] == '-' || tok.p[0] == '+')) i = 1;
    if (tok.n == i || tok.n - i > 20) return 0;
    for (; i < tok.n; i++)
        if (!is_digit(tok.p[i])) return 0;
    return 1;
}

/* A word (keyword) rather than a number: starts with a letter and is not
 * inf or nan (which strtod reads). */
static int is_word(span tok)
{
    double v;
    return tok.n > 0 && is_letter(tok.p[0]) && parse_double(tok, &v) != -2;
}

/* A section keyword line: its first word starts with a letter. */
static int is_section(span body)
{
    size_t i = 0;
    span tok;
    return next_token(body, &i, &tok) && is_word(tok);
}

static const char *num_problem(int rc)
{
    return rc == -2 ? "non-finite number" : "invalid number";
}

/* ---- line 1: the title ----------------------------------------------------- */

typedef struct {
    int dim;        /* from dim=D; 0 if absent */
    int has_strain; /* strain=G present */
    double strain;
    int has_types;  /* "types:" present */
    span types;     /* its T=LABEL words */
} title_info;

/* T=LABEL word: digits, then '=' (the rest is checked later) */
static int is_type_word(span t)
{
    size_t i = 0;
    while (i < t.n && is_digit(t.p[i])) i++;
    return i > 0 && i < t.n && t.p[i] == '=';
}

static int parse_title(span line, title_info *ti, char *msg)
{
    size_t i = 0;
    span tok;
    int in_types = 0;
    while (next_token(line, &i, &tok)) {
        if (in_types) {
            if (is_type_word(tok)) {
                ti->types.n = (size_t)(tok.p + tok.n - ti->types.p);
                continue;
            }
            in_types = 0;
        }
        if (span_starts(tok, "dim=")) {
            if (ti->dim)
                return odhs__err(msg, ODHS_E_FORMAT, "line 1: duplicate dim= in the title");
            span v = {tok.p + 4, tok.n - 4};
            if (span_eq(v, "2"))
                ti->dim = 2;
            else if (span_eq(v, "3"))
                ti->dim = 3;
            else
                return odhs__err(msg, ODHS_E_FORMAT, "line 1: dim must be 2 or 3, got '%.*s'",
                                 show_len(v), v.p);
        } else if (span_starts(tok, "strain=")) {
            if (ti->has_strain)
                return odhs__err(msg, ODHS_E_FORMAT, "line 1: duplicate strain= in the title");
            span v = {tok.p + 7, tok.n - 7};
            int rc = parse_double(v, &ti->strain);
            if (rc != 0)
                return odhs__err(msg, ODHS_E_FORMAT, "line 1: strain: %s '%.*s'", num_problem(rc),
                                 show_len(v), v.p);
            ti->has_strain = 1;
        } else if (span_eq(tok, "types:")) {
            if (ti->has_types)
                return odhs__err(msg, ODHS_E_FORMAT, "line 1: duplicate types: in the title");
            ti->has_types = 1;
            ti->types.p = tok.p + tok.n;
            ti->types.n = 0;
            in_types = 1;
        }
    }
    return ODHS_OK;
}

/* The title's type labels, sorted by type. */
typedef struct {
    size_t type;
    char label[ODHS_SPECIES_MAX + 1];
} type_label;

static int cmp_type_label(const void *a, const void *b)
{
    const type_label *p = a, *q = b;
    return p->type < q->type ? -1 : p->type > q->type;
}

/* The T=LABEL words of the title into a sorted array (*out, *count; NULL
 * and 0 when there are none). */
static int parse_type_labels(span list, size_t ntypes, type_label **out, size_t *count, char *msg)
{
    *out = NULL;
    *count = 0;
    size_t nw = count_tokens(list);
    if (nw == 0) return ODHS_OK;
    type_label *tl = odhs__malloc_array(nw, sizeof *tl);
    if (!tl) return odhs__err(msg, ODHS_E_NOMEM, "out of memory reading %zu type labels", nw);
    size_t i = 0, k = 0;
    span tok;
    while (next_token(list, &i, &tok)) {
        size_t d = 0;
        while (d < tok.n && is_digit(tok.p[d])) d++; /* a T=LABEL word: stops at '=' */
        span num = {tok.p, d}, lab = {tok.p + d + 1, tok.n - d - 1};
        size_t t = 0;
        if (parse_count(num, ntypes, &t) != 0 || t == 0) {
            odhs__free(tl);
            return odhs__err(msg, ODHS_E_FORMAT, "line 1: types: type '%.*s' is not in 1..%zu",
                             show_len(num), num.p, ntypes);
        }
        if (!valid_label(lab)) {
            odhs__free(tl);
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line 1: types: invalid species label '%.*s' for type %zu (1..%d "
                             "printable characters, no blanks, quotes or '=')",
                             show_len(lab), lab.p, t, ODHS_SPECIES_MAX);
        }
        tl[k].type = t;
        memcpy(tl[k].label, lab.p, lab.n);
        tl[k].label[lab.n] = '\0';
        k++;
    }
    qsort(tl, k, sizeof *tl, cmp_type_label);
    for (size_t j = 1; j < k; j++)
        if (tl[j].type == tl[j - 1].type) {
            size_t t = tl[j].type;
            odhs__free(tl);
            return odhs__err(msg, ODHS_E_FORMAT, "line 1: types: type %zu labelled twice", t);
        }
    *out = tl;
    *count = k;
    return ODHS_OK;
}

/* ---- the header -------------------------------------------------------------- */

typedef struct {
    size_t n, ntypes;
    double lo[3], hi[3];
    double tilt[3]; /* xy xz yz */
    /* line numbers of the header lines (0: absent) */
    size_t line_n, line_ntypes, line_box[3], line_tilt;
} header;

static int parse_box_line(const span *num, int k, size_t lineno, header *h, char *msg)
{
    static const char *const names[3][2] = {{"xlo", "xhi"}, {"ylo", "yhi"}, {"zlo", "zhi"}};
    if (h->line_box[k])
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: duplicate '%s %s' line (first on line %zu)",
                         lineno, names[k][0], names[k][1], h->line_box[k]);
    double v[2];
    for (int j = 0; j < 2; j++) {
        int rc = parse_double(num[j], &v[j]);
        if (rc != 0)
            return odhs__err(msg, ODHS_E_FORMAT, "line %zu: %s: %s '%.*s'", lineno, names[k][j],
                             num_problem(rc), show_len(num[j]), num[j].p);
    }
    double len = v[1] - v[0];
    if (!(len > 0.0) || !isfinite(len))
        return odhs__err(msg, ODHS_E_FORMAT,
                         "line %zu: %s = %.17g must be greater than %s = %.17g (by a finite length)",
                         lineno, names[k][1], v[1], names[k][0], v[0]);
    h->lo[k] = v[0];
    h->hi[k] = v[1];
    h->line_box[k] = lineno;
    return ODHS_OK;
}

static int parse_tilt_line(const span *num, size_t lineno, header *h, char *msg)
{
    static const char *const names[3] = {"xy", "xz", "yz"};
    if (h->line_tilt)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: duplicate 'xy xz yz' line (first on line %zu)",
                         lineno, h->line_tilt);
    for (int j = 0; j < 3; j++) {
        int rc = parse_double(num[j], &h->tilt[j]);
        if (rc != 0)
            return odhs__err(msg, ODHS_E_FORMAT, "line %zu: %s: %s '%.*s'", lineno, names[j],
                             num_problem(rc), show_len(num[j]), num[j].p);
    }
    if (h->tilt[1] != 0.0 || h->tilt[2] != 0.0)
        return odhs__err(msg, ODHS_E_FORMAT,
                         "line %zu: xz = %.17g and yz = %.17g must be 0 (only x-y shear is supported)",
                         lineno, h->tilt[1], h->tilt[2]);
    h->line_tilt = lineno;
    return ODHS_OK;
}

/* "N atoms" or "N atom types" */
static int parse_count_line(span num, size_t lineno, int types, header *h, char *msg)
{
    const char *what = types ? "atom types" : "atoms";
    size_t *dst = types ? &h->ntypes : &h->n;
    size_t *line = types ? &h->line_ntypes : &h->line_n;
    size_t max = types ? LMP_TYPES_MAX : LMP_N_MAX;
    if (*line)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: duplicate '%s' line (first on line %zu)", lineno,
                         what, *line);
    int rc = parse_count(num, max, dst);
    if (rc == -2)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: too many %s (at most %zu)", lineno, what, max);
    if (rc != 0)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: invalid number of %s '%.*s'", lineno, what,
                         show_len(num), num.p);
    if (*dst == 0)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: the number of %s must be positive", lineno, what);
    *line = lineno;
    return ODHS_OK;
}

/* One header line "<numbers> <keywords>" (not a section keyword line). */
static int parse_header_line(span body, size_t lineno, header *h, char *msg)
{
    span num[3], kw[3];
    size_t nnum = 0, nkw = 0, i = 0;
    span tok;
    while (next_token(body, &i, &tok)) {
        if (is_word(tok)) {
            if (nkw < 3) kw[nkw] = tok;
            nkw++;
        } else {
            if (nkw > 0)
                return odhs__err(msg, ODHS_E_FORMAT,
                                 "line %zu: header line with '%.*s' after its keyword", lineno,
                                 show_len(tok), tok.p);
            if (nnum < 3) num[nnum] = tok;
            nnum++;
        }
    }
    if (nkw == 0)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: header line without a keyword: '%.*s'", lineno,
                         show_len(body), body.p);
    int which = -1; /* 0 atoms, 1 atom types, 2..4 box, 5 tilt */
    if (nkw == 1 && span_eq(kw[0], "atoms"))
        which = 0;
    else if (nkw == 2 && span_eq(kw[0], "atom") && span_eq(kw[1], "types"))
        which = 1;
    else if (nkw == 2 && span_eq(kw[0], "xlo") && span_eq(kw[1], "xhi"))
        which = 2;
    else if (nkw == 2 && span_eq(kw[0], "ylo") && span_eq(kw[1], "yhi"))
        which = 3;
    else if (nkw == 2 && span_eq(kw[0], "zlo") && span_eq(kw[1], "zhi"))
        which = 4;
    else if (nkw == 3 && span_eq(kw[0], "xy") && span_eq(kw[1], "xz") && span_eq(kw[2], "yz"))
        which = 5;
    if (which < 0) return ODHS_OK; /* bonds, ellipsoids, extra ... per atom: not used */
    static const size_t want[6] = {1, 1, 2, 2, 2, 3};
    static const char *const form[6] = {"<N> atoms", "<N> atom types", "<lo> <hi> xlo xhi", "<lo> <hi> ylo yhi",
                                        "<lo> <hi> zlo zhi", "<xy> <xz> <yz> xy xz yz"};
    if (nnum != want[which])
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: expected '%s', found %zu number%s", lineno,
                         form[which], nnum, nnum == 1 ? "" : "s");
    if (which <= 1) return parse_count_line(num[0], lineno, which, h, msg);
    if (which <= 4) return parse_box_line(num, which - 2, lineno, h, msg);
    return parse_tilt_line(num, lineno, h, msg);
}

/* The header must name the atoms, the atom types and the x and y extents. */
static int check_header(const header *h, size_t lineno, char *msg)
{
    const char *missing = !h->line_n        ? "<N> atoms"
                          : !h->line_ntypes ? "<N> atom types"
                          : !h->line_box[0] ? "<lo> <hi> xlo xhi"
                          : !h->line_box[1] ? "<lo> <hi> ylo yhi"
                                            : NULL;
    if (missing)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: the header (before this line) has no '%s' line",
                         lineno, missing);
    return ODHS_OK;
}

/* ---- sections (pass 1) ------------------------------------------------------ */

typedef struct {
    reader rd;   /* positioned after the Atoms keyword line */
    size_t line; /* the line of the keyword (0: not found) */
} atoms_loc;

/* The section keyword line (body, comment) at rd->lineno and its data lines;
 * on return *more says whether another keyword line was read into body and
 * comment. */
static int scan_section(reader *rd, span *body, span *comment, const header *h, atoms_loc *loc, int *more,
                        char *msg)
{
    size_t key_line = rd->lineno;
    int atoms = span_eq(*body, "Atoms");
    if (atoms) {
        if (loc->line)
            return odhs__err(msg, ODHS_E_FORMAT, "line %zu: a second Atoms section (the first is on line %zu)",
                             key_line, loc->line);
        span style = {comment->p, 0};
        size_t i = 0;
        if (next_token(*comment, &i, &style) && !span_eq(style, "sphere"))
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: Atoms section of style '%.*s': only atom_style sphere "
                             "(id type diameter density x y z) is supported",
                             key_line, show_len(style), style.p);
        loc->line = key_line;
        loc->rd = *rd;
    }
    size_t count = 0;
    *more = 0;
    while (next_content(rd, body, comment)) {
        if (body->n == 0) continue;
        if (is_section(*body)) {
            *more = 1;
            break;
        }
        if (!is_data_start(body->p[0]))
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: expected a section keyword or a data line, found '%.*s'",
                             rd->lineno, show_len(*body), body->p);
        if (atoms && ++count > h->n)
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: more than %zu lines in the Atoms section (line %zu; %zu atoms)",
                             rd->lineno, h->n, key_line, h->n);
    }
    if (atoms && count < h->n) {
        if (*more)
            return odhs__err(msg, ODHS_E_FORMAT,
                             "line %zu: the Atoms section (line %zu) ends after %zu of %zu atom lines",
                             rd->lineno, key_line, count, h->n);
        return odhs__err(msg, ODHS_E_FORMAT,
                         "line %zu: file ends after %zu of %zu lines of the Atoms section (line %zu)",
                         rd->lineno + 1, count, h->n, key_line);
    }
    return ODHS_OK;
}

/* ---- the Atoms lines (pass 2) -------------------------------------------------- */

typedef struct {
    double *x3;      /* 3 coordinates per atom, by id */
    double *r;       /* radii */
    size_t *type;    /* types */
    size_t *line_of; /* line of each id (0: not seen yet) */
} atoms_tmp;

static int parse_atom(span body, size_t lineno, const header *h, int dim, atoms_tmp *a, char *msg)
{
    static const char *const names[5] = {"diameter", "density", "x", "y", "z"};
    span tok[10];
    size_t nc = 0, i = 0;
    span t;
    while (next_token(body, &i, &t)) {
        if (nc < 10) tok[nc] = t;
        nc++;
    }
    if (nc != 7 && nc != 10)
        return odhs__err(msg, ODHS_E_FORMAT,
                         "line %zu: expected 7 columns (id type diameter density x y z) or 10 (and the "
                         "image flags ix iy iz), found %zu",
                         lineno, nc);
    size_t id = 0, type = 0;
    int rc = parse_count(tok[0], h->n, &id);
    if (rc == -1)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: column 1: invalid atom id '%.*s'", lineno,
                         show_len(tok[0]), tok[0].p);
    if (rc != 0 || id == 0)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: atom id %.*s is not in 1..%zu", lineno,
                         show_len(tok[0]), tok[0].p, h->n);
    if (a->line_of[id - 1])
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: duplicate atom id %zu (first on line %zu)", lineno,
                         id, a->line_of[id - 1]);
    rc = parse_count(tok[1], h->ntypes, &type);
    if (rc == -1)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: column 2: invalid atom type '%.*s'", lineno,
                         show_len(tok[1]), tok[1].p);
    if (rc != 0 || type == 0)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: atom type %.*s is not in 1..%zu", lineno,
                         show_len(tok[1]), tok[1].p, h->ntypes);
    double v[5];
    for (int k = 0; k < 5; k++) {
        rc = parse_double(tok[2 + k], &v[k]);
        if (rc != 0)
            return odhs__err(msg, ODHS_E_FORMAT, "line %zu: column %d (%s): %s '%.*s'", lineno, 3 + k,
                             names[k], num_problem(rc), show_len(tok[2 + k]), tok[2 + k].p);
    }
    if (!(v[0] > 0.0))
        return odhs__err(msg, ODHS_E_FORMAT,
                         "line %zu: diameter must be positive, got %.17g (point particles are not supported)",
                         lineno, v[0]);
    double rad = v[0] / 2.0;
    if (!(rad > 0.0))
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: diameter %.17g is too small to halve", lineno, v[0]);
    if (!(v[1] > 0.0))
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: density must be positive, got %.17g", lineno, v[1]);
    for (size_t k = 7; k < nc; k++)
        if (!is_integer(tok[k]))
            return odhs__err(msg, ODHS_E_FORMAT, "line %zu: column %zu (image flag): invalid integer '%.*s'",
                             lineno, k + 1, show_len(tok[k]), tok[k].p);
    if (dim == 2 && v[4] != 0.0)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: z = %.17g, but a 2D file (dim=2) needs z = 0", lineno,
                         v[4]);
    double *x = &a->x3[(id - 1) * 3];
    x[0] = v[2];
    x[1] = v[3];
    x[2] = v[4];
    a->r[id - 1] = rad;
    a->type[id - 1] = type;
    a->line_of[id - 1] = lineno;
    return ODHS_OK;
}

/* All N Atoms lines (known to exist) from loc into a. */
static int parse_atoms(const atoms_loc *loc, const header *h, int dim, atoms_tmp *a, char *msg)
{
    reader rd = loc->rd;
    span body, comment;
    size_t done = 0;
    while (done < h->n) {
        if (!next_content(&rd, &body, &comment)) /* cannot happen after pass 1 */
            return odhs__err(msg, ODHS_E_INTERNAL, "line %zu: unexpected end of input", rd.lineno + 1);
        if (body.n == 0) continue;
        int st = parse_atom(body, rd.lineno, h, dim, a, msg);
        if (st < 0) return st;
        done++;
    }
    return ODHS_OK;
}

/* ---- building the system ------------------------------------------------------ */

/* The strain: xy/Ly, or the title's G when it gives the same lattice. */
static int find_strain(const header *h, const title_info *ti, double *gamma, char *msg)
{
    double Lx = h->hi[0] - h->lo[0], Ly = h->hi[1] - h->lo[1], xy = h->tilt[0];
    if (ti->has_strain) {
        double d = ti->strain * Ly - xy;
        double k = nearbyint(d / Lx);
        if (isfinite(d) && fabs(d - k * Lx) <= LMP_STRAIN_TOL * Lx) {
            *gamma = ti->strain;
            return ODHS_OK;
        }
    }
    *gamma = xy / Ly;
    if (!isfinite(*gamma))
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: the strain xy/Ly = %.17g/%.17g is not finite",
                         h->line_tilt ? h->line_tilt : h->line_box[1], xy, Ly);
    return ODHS_OK;
}

typedef struct {
    int dim;
    size_t n;
    double L[3];
    double gamma;
    const double *x; /* n*dim */
    const double *r;
    const size_t *type;
    const type_label *labels; /* sorted by type */
    size_t nlabels;
} build_in;

static int build_system(const build_in *in, odhs_system **out, char *msg)
{
    odhs_system *sys = NULL;
    int st = odhs_system_create(in->dim, in->n, &sys);
    if (st < 0) return odhs__err(msg, st, "cannot create system: %s", odhs_strerror(st));
    /* as for XYZ files: a state written between two drift corrections reads
     * back (contact gaps drift to ~ -1e-4 of the contact distance) */
    sys->overlap_accept = ODHS_LMP_OVERLAP_ACCEPT;
    st = odhs_system_set_configuration(sys, in->L, in->gamma, in->r, in->x);
    sys->overlap_accept = 0.0;
    if (st < 0) {
        odhs__err(msg, st, "data file: %s", odhs_system_errmsg(sys));
        goto done;
    }
    for (size_t i = 0; i < in->n; i++) {
        char num[32];
        const char *label = num;
        type_label key;
        key.type = in->type[i];
        const type_label *tl =
            in->nlabels ? bsearch(&key, in->labels, in->nlabels, sizeof key, cmp_type_label) : NULL;
        if (tl)
            label = tl->label;
        else
            snprintf(num, sizeof num, "%zu", in->type[i]);
        st = odhs_system_set_species(sys, i, label);
        if (st < 0) { /* cannot happen: the labels were checked */
            odhs__err(msg, ODHS_E_INTERNAL, "atom %zu: species '%s': %s", i + 1, label, odhs_system_errmsg(sys));
            st = ODHS_E_INTERNAL;
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

/* The dimension, then the positions relative to the box origin (n*dim). */
static int make_positions(const header *h, const title_info *ti, const atoms_tmp *a, int *dim_out, double *x,
                          char *msg)
{
    size_t n = h->n;
    int dim = ti->dim;
    if (!dim) {
        int flat = h->lo[2] < 0.0 && 0.0 < h->hi[2];
        for (size_t i = 0; i < n && flat; i++)
            if (a->x3[i * 3 + 2] != 0.0) flat = 0;
        dim = flat ? 2 : 3;
    }
    for (size_t i = 0; i < n; i++)
        for (int k = 0; k < dim; k++) {
            double v = a->x3[i * 3 + (size_t)k] - h->lo[k];
            if (!isfinite(v))
                return odhs__err(msg, ODHS_E_FORMAT,
                                 "line %zu: coordinate %d relative to the box origin is not finite",
                                 a->line_of[i], k + 1);
            x[i * (size_t)dim + (size_t)k] = v;
        }
    *dim_out = dim;
    return ODHS_OK;
}

static int parse_impl(const char *buf, size_t len, odhs_system **out, char *msg, void *ctx)
{
    (void)ctx;
    reader rd = {buf, len, 0, 0};
    span line, body, comment;

    /* line 1: the title */
    if (!next_line(&rd, &line)) return odhs__err(msg, ODHS_E_FORMAT, "line 1: empty file");
    title_info ti;
    memset(&ti, 0, sizeof ti);
    int st = parse_title(line, &ti, msg);
    if (st < 0) return st;

    /* the header, up to the first section keyword (a line starting with a letter) */
    header h;
    memset(&h, 0, sizeof h);
    h.lo[2] = -0.5; /* LAMMPS's defaults */
    h.hi[2] = 0.5;
    int more = 0;
    while (next_content(&rd, &body, &comment)) {
        if (body.n == 0) continue;
        if (is_section(body)) {
            more = 1;
            break;
        }
        st = parse_header_line(body, rd.lineno, &h, msg);
        if (st < 0) return st;
    }
    st = check_header(&h, more ? rd.lineno : rd.lineno + 1, msg);
    if (st < 0) return st;

    /* pass 1: the sections; the Atoms lines must all be there */
    atoms_loc loc;
    memset(&loc, 0, sizeof loc);
    while (more) {
        st = scan_section(&rd, &body, &comment, &h, &loc, &more, msg);
        if (st < 0) return st;
    }
    if (!loc.line)
        return odhs__err(msg, ODHS_E_FORMAT, "line %zu: end of file without an Atoms section", rd.lineno + 1);

    double gamma = 0.0;
    st = find_strain(&h, &ti, &gamma, msg);
    if (st < 0) return st;

    /* pass 2: parse into temporary arrays, then build the system */
    size_t n = h.n;
    atoms_tmp a;
    a.x3 = odhs__malloc_array(n, 3 * sizeof(double));
    a.r = odhs__malloc_array(n, sizeof(double));
    a.type = odhs__malloc_array(n, sizeof(size_t));
    a.line_of = odhs__calloc(n, sizeof(size_t));
    double *x = odhs__malloc_array(n, 3 * sizeof(double));
    type_label *labels = NULL;
    size_t nlabels = 0;
    if (!a.x3 || !a.r || !a.type || !a.line_of || !x) {
        st = odhs__err(msg, ODHS_E_NOMEM, "out of memory reading %zu atoms", n);
        goto done;
    }
    st = parse_atoms(&loc, &h, ti.dim, &a, msg);
    if (st < 0) goto done;
    int dim = 3;
    st = make_positions(&h, &ti, &a, &dim, x, msg);
    if (st < 0) goto done;
    st = parse_type_labels(ti.types, h.ntypes, &labels, &nlabels, msg);
    if (st < 0) goto done;

    build_in in = {dim, n, {h.hi[0] - h.lo[0], h.hi[1] - h.lo[1], 1.0}, gamma, x, a.r, a.type, labels, nlabels};
    if (dim == 3) in.L[2] = h.hi[2] - h.lo[2];
    st = build_system(&in, out, msg);

done:
    odhs__free(a.x3);
    odhs__free(a.r);
    odhs__free(a.type);
    odhs__free(a.line_of);
    odhs__free(x);
    odhs__free(labels);
    return st;
}

int odhs_lammps_data_parse(const char *buf, size_t len, odhs_system **out, char *errbuf, size_t errlen)
{
    return odhs__parse_entry(buf, len, out, errbuf, errlen, parse_impl, NULL);
}

int odhs_lammps_data_read(const char *path, odhs_system **out, char *errbuf, size_t errlen)
{
    return odhs__read_entry(path, out, errbuf, errlen, parse_impl, NULL);
}

/* ---- the writer ------------------------------------------------------------------ */

typedef struct {
    int dim;
    size_t n;
    double L[3];
    double gamma;
    const double *x, *r;
    const int *type;
    const char (*names)[ODHS_SPECIES_MAX + 1];
    size_t ntypes;
} write_in;

static int write_body(FILE *f, const void *ctx)
{
    const write_in *w = ctx;
    int dim = w->dim;
    const double *L = w->L;
    double xy = odhs__lmp_tilt(L[0], L[1], w->gamma);
    if (fprintf(f, "LAMMPS data file written by libodhs %s: dim=%d strain=%.17g types:", ODHS_VERSION_STRING,
                dim, w->gamma) < 0)
        return -1;
    for (size_t t = 0; t < w->ntypes; t++)
        if (fprintf(f, " %zu=%s", t + 1, w->names[t]) < 0) return -1;
    if (fprintf(f, "\n\n%zu atoms\n%zu atom types\n\n", w->n, w->ntypes) < 0) return -1;
    if (fprintf(f, "%.17g %.17g xlo xhi\n%.17g %.17g ylo yhi\n%.17g %.17g zlo zhi\n", 0.0, L[0], 0.0, L[1],
                dim == 3 ? 0.0 : -0.5, dim == 3 ? L[2] : 0.5) < 0)
        return -1;
    if (fprintf(f, "%.17g %.17g %.17g xy xz yz\n\nAtoms # sphere\n\n", xy, 0.0, 0.0) < 0) return -1;
    for (size_t i = 0; i < w->n; i++) {
        const double *xi = &w->x[i * (size_t)dim];
        double x0 = xi[0];
        odhs__lmp_wrap(&x0, xi[1], L[0], L[1], xy);
        if (fprintf(f, "%zu %d %.17g %.17g %.17g %.17g %.17g\n", i + 1, w->type[i], 2.0 * w->r[i], 1.0, x0, xi[1],
                    dim == 3 ? xi[2] : 0.0) < 0)
            return -1;
    }
    return 0;
}

int odhs_lammps_data_write(const odhs_system *sys, const char *path)
{
    if (!sys) return ODHS_E_NULL;
    if (!path) return odhs__syserr(sys, ODHS_E_NULL, "path is NULL");
    if (!odhs_system_is_ready(sys)) return odhs__syserr(sys, ODHS_E_STATE, "radii or positions not set");

    write_in w;
    memset(&w, 0, sizeof w);
    w.dim = odhs_system_dim(sys);
    w.n = odhs_system_count(sys);
    w.L[0] = w.L[1] = w.L[2] = 1.0;
    int st = odhs_system_get_box(sys, w.L);
    if (st < 0) return st;
    st = odhs_system_get_strain(sys, &w.gamma);
    if (st < 0) return st;

    size_t n = w.n;
    double *x = odhs__malloc_array(n, (size_t)w.dim * sizeof(double));
    double *r = odhs__malloc_array(n, sizeof(double));
    int *type = odhs__malloc_array(n, sizeof(int));
    char(*names)[ODHS_SPECIES_MAX + 1] = odhs__malloc_array(n, sizeof *names);
    if (!x || !r || !type || !names) {
        st = odhs__syserr(sys, ODHS_E_NOMEM, "out of memory writing '%s'", path);
        goto done;
    }
    if ((st = odhs_system_get_positions(sys, x)) < 0 || (st = odhs_system_get_radii(sys, r)) < 0) goto done;
    w.x = x;
    w.r = r;
    w.type = type;
    w.names = (const char(*)[ODHS_SPECIES_MAX + 1])names;
    w.ntypes = odhs__lmp_types(sys, type, names);
    char msg[ODHS_ERRMSG_LEN];
    st = odhs__write_atomic(path, write_body, &w, msg);
    if (st < 0) odhs__syserr(sys, st, "%s", msg);

done:
    odhs__free(x);
    odhs__free(r);
    odhs__free(type);
    odhs__free(names);
    return st;
}
