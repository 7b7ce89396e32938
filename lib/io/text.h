/*
 * libodhs private header: what the text-file readers and writers share
 * (the extended XYZ reader and writer, the LAMMPS data file). Not installed.
 *
 * Readers see their input as a byte buffer of known length that need not be
 * NUL-ended, through (pointer, length) spans; numbers are copied into a
 * small NUL-ended buffer before strtod sees them. Writers write a temporary
 * file in the same directory and rename it over the target.
 */
#ifndef ODHS_IO_TEXT_H
#define ODHS_IO_TEXT_H

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "system/system.h"

#define ODHS_TEXT_NUM_MAX 255 /* longest numeric token accepted */

typedef struct {
    const char *p;
    size_t n;
} span;

typedef struct {
    const char *buf;
    size_t len;
    size_t pos;
    size_t lineno; /* 1-based number of the line last returned */
} reader;

static inline int is_ws(char c) { return c == ' ' || c == '\t' || c == '\r' || c == '\v' || c == '\f'; }

/* Next line (without '\n' and a trailing '\r'); 0 at the end of the buffer. */
static inline int next_line(reader *rd, span *line)
{
    if (rd->pos >= rd->len) return 0;
    const char *start = rd->buf + rd->pos;
    size_t rest = rd->len - rd->pos;
    const char *nl = memchr(start, '\n', rest);
    size_t n = nl ? (size_t)(nl - start) : rest;
    rd->pos += nl ? n + 1 : n;
    if (n > 0 && start[n - 1] == '\r') n--;
    line->p = start;
    line->n = n;
    rd->lineno++;
    return 1;
}

static inline span trim(span s)
{
    while (s.n > 0 && is_ws(s.p[0])) {
        s.p++;
        s.n--;
    }
    while (s.n > 0 && is_ws(s.p[s.n - 1])) s.n--;
    return s;
}

/* Next white-space separated token of s starting at *i; 0 if none left. */
static inline int next_token(span s, size_t *i, span *tok)
{
    size_t k = *i;
    while (k < s.n && is_ws(s.p[k])) k++;
    if (k >= s.n) {
        *i = k;
        return 0;
    }
    size_t start = k;
    while (k < s.n && !is_ws(s.p[k])) k++;
    tok->p = s.p + start;
    tok->n = k - start;
    *i = k;
    return 1;
}

static inline size_t count_tokens(span s)
{
    size_t i = 0, c = 0;
    span t;
    while (next_token(s, &i, &t)) c++;
    return c;
}

/* Length to print of a token in a message (tokens can be huge). */
static inline int show_len(span s) { return (int)(s.n > 40 ? 40 : s.n); }

/* Parse a whole token as a double. 0 ok, -1 not a number, -2 not finite. */
static inline int parse_double(span tok, double *out)
{
    char tmp[ODHS_TEXT_NUM_MAX + 1];
    if (tok.n == 0 || tok.n > ODHS_TEXT_NUM_MAX) return -1;
    memcpy(tmp, tok.p, tok.n);
    tmp[tok.n] = '\0';
    /* strtod would skip leading white space; tokens never have any, but a
     * value taken from a quoted string might. */
    if (is_ws(tmp[0]) || tmp[0] == '\n') return -1;
    char *end = NULL;
    double v = strtod(tmp, &end);
    if (end != tmp + tok.n) return -1;
    if (!isfinite(v)) return -2;
    *out = v;
    return 0;
}

/* Parse a token of decimal digits only as an unsigned count <= max.
 * 0 ok, -1 not a non-negative integer, -2 larger than max. */
static inline int parse_count(span tok, size_t max, size_t *out)
{
    if (tok.n == 0) return -1;
    size_t v = 0;
    int big = 0;
    for (size_t i = 0; i < tok.n; i++) {
        char c = tok.p[i];
        if (c < '0' || c > '9') return -1;
        if (!big) {
            v = v * 10 + (size_t)(c - '0');
            if (v > max) big = 1;
        }
    }
    if (big) return -2;
    *out = v;
    return 0;
}

/* A species label odhs_system_set_species accepts: 1..ODHS_SPECIES_MAX
 * printable ASCII characters without white space, quotes or '='. */
static inline int valid_label(span s)
{
    if (s.n < 1 || s.n > ODHS_SPECIES_MAX) return 0;
    for (size_t i = 0; i < s.n; i++) {
        unsigned char c = (unsigned char)s.p[i];
        if (c <= 0x20 || c >= 0x7f || c == '"' || c == '\'' || c == '=') return 0;
    }
    return 1;
}

/* A reader's parser: buf (len bytes) into a new system (*out only on
 * success); an error status with the message in msg (ODHS_ERRMSG_LEN). */
typedef int (*odhs__parse_fn)(const char *buf, size_t len, odhs_system **out, char *msg, void *ctx);

/* The public entry of a reader of a buffer: the NULL checks, parse, the
 * message copied into errbuf (errlen bytes; "" on success), *out NULL on
 * any error. */
int odhs__parse_entry(const char *buf, size_t len, odhs_system **out, char *errbuf, size_t errlen,
                      odhs__parse_fn parse, void *ctx);

/* The same for a file: the whole file is read into memory first (missing or
 * unreadable: ODHS_E_IO). */
int odhs__read_entry(const char *path, odhs_system **out, char *errbuf, size_t errlen, odhs__parse_fn parse,
                     void *ctx);

/* A writer's body: 0, -1 on a write error (errno set), -2 on an error of
 * its own (reported as ODHS_E_INTERNAL). */
typedef int (*odhs__body_fn)(FILE *f, const void *ctx);

/* Write path through body into a unique temporary file in the same
 * directory, renamed over path at the end, so that a failed write leaves an
 * old file intact. ODHS_OK, ODHS_E_NOMEM, ODHS_E_IO or ODHS_E_INTERNAL with
 * the message in msg. */
int odhs__write_atomic(const char *path, odhs__body_fn body, const void *ctx, char *msg);

#endif /* ODHS_IO_TEXT_H */
