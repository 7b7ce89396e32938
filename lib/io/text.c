/*
 * libodhs - what the text-file readers and writers share (io/text.h): the
 * entries of the readers and the atomic write.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#if !defined(_POSIX_C_SOURCE) || _POSIX_C_SOURCE < 200809L
#undef _POSIX_C_SOURCE
#define _POSIX_C_SOURCE 200809L
#endif

#include <errno.h>
#include <stdio.h>
#include <string.h>
#include <unistd.h>

#include "io/text.h"

static void copy_msg(char *errbuf, size_t errlen, const char *msg)
{
    if (errbuf && errlen > 0) snprintf(errbuf, errlen, "%s", msg);
}

int odhs__parse_entry(const char *buf, size_t len, odhs_system **out, char *errbuf, size_t errlen,
                      odhs__parse_fn parse, void *ctx)
{
    char msg[ODHS_ERRMSG_LEN];
    msg[0] = '\0';
    if (errbuf && errlen > 0) errbuf[0] = '\0';
    if (out) *out = NULL;
    if (!out || !buf) {
        int st = odhs__err(msg, ODHS_E_NULL, "%s is NULL", !out ? "out" : "buf");
        copy_msg(errbuf, errlen, msg);
        return st;
    }
    int st = parse(buf, len, out, msg, ctx);
    if (st < 0) {
        *out = NULL;
        copy_msg(errbuf, errlen, msg);
    }
    return st;
}

/* The whole file into a new buffer (*data, odhs__free it); 0 or an error
 * with the message in msg. */
static int read_file(const char *path, char **data_out, size_t *len_out, char *msg)
{
    errno = 0;
    FILE *f = fopen(path, "rb");
    if (!f) {
        int e = errno;
        return odhs__err(msg, ODHS_E_IO, "cannot open '%s': %s", path, e ? strerror(e) : "unknown error");
    }
    size_t cap = 65536, len = 0;
    char *data = odhs__malloc(cap);
    int st = ODHS_OK;
    if (!data) {
        st = odhs__err(msg, ODHS_E_NOMEM, "out of memory reading '%s'", path);
        goto fail;
    }
    for (;;) {
        if (len == cap) {
            char *bigger = cap > ((size_t)-1) / 2 ? NULL : odhs__realloc(data, cap * 2);
            if (!bigger) {
                st = odhs__err(msg, ODHS_E_NOMEM,
                               cap > ((size_t)-1) / 2 ? "'%s' is too large" : "out of memory reading '%s'", path);
                goto fail;
            }
            data = bigger;
            cap *= 2;
        }
        errno = 0;
        size_t got = fread(data + len, 1, cap - len, f);
        len += got;
        if (got == 0) break;
    }
    if (ferror(f)) {
        int e = errno;
        st = odhs__err(msg, ODHS_E_IO, "cannot read '%s': %s", path, e ? strerror(e) : "read error");
        goto fail;
    }
    fclose(f);
    *data_out = data;
    *len_out = len;
    return ODHS_OK;

fail:
    fclose(f);
    odhs__free(data);
    return st;
}

int odhs__read_entry(const char *path, odhs_system **out, char *errbuf, size_t errlen, odhs__parse_fn parse,
                     void *ctx)
{
    char msg[ODHS_ERRMSG_LEN];
    msg[0] = '\0';
    if (errbuf && errlen > 0) errbuf[0] = '\0';
    if (out) *out = NULL;
    if (!out || !path) {
        int st = odhs__err(msg, ODHS_E_NULL, "%s is NULL", !out ? "out" : "path");
        copy_msg(errbuf, errlen, msg);
        return st;
    }
    char *data = NULL;
    size_t len = 0;
    int st = read_file(path, &data, &len, msg);
    if (st >= 0) {
        st = parse(data, len, out, msg, ctx);
        odhs__free(data);
    }
    if (st < 0) {
        *out = NULL;
        copy_msg(errbuf, errlen, msg);
    }
    return st;
}

/* Makes temporary names unique within the process ("wx" below refuses to
 * open an existing file anyway, so a collision only costs a retry). */
#if defined(__STDC_NO_ATOMICS__)
static unsigned long tmp_counter;
#else
static _Atomic unsigned long tmp_counter;
#endif

int odhs__write_atomic(const char *path, odhs__body_fn body, const void *ctx, char *msg)
{
    size_t plen = strlen(path);
    char *tmp = (plen < ((size_t)-1) - 64) ? odhs__malloc(plen + 64) : NULL;
    if (!tmp) return odhs__err(msg, ODHS_E_NOMEM, "out of memory writing '%s'", path);
    FILE *f = NULL;
    /* unique temporary name in the same directory, then rename() over path */
    for (int attempt = 0;; attempt++) {
        unsigned long k = tmp_counter++;
        snprintf(tmp, plen + 64, "%s.tmp.%ld.%lu", path, (long)getpid(), k);
        errno = 0;
        f = fopen(tmp, "wx");
        if (f || errno != EEXIST || attempt >= 100) break;
    }
    int st = ODHS_OK;
    if (!f) {
        int e = errno;
        st = odhs__err(msg, ODHS_E_IO, "cannot write '%s': %s", path, e ? strerror(e) : "cannot create temporary file");
        goto done;
    }
    errno = 0;
    int wr = body(f, ctx);
    int e = errno;
    if (wr == 0 && fflush(f) != 0) {
        wr = -1;
        e = errno;
    }
    if (wr == 0 && ferror(f)) wr = -1;
    int cl = fclose(f);
    if (wr == 0 && cl != 0) {
        wr = -1;
        e = errno;
    }
    if (wr != 0) {
        remove(tmp);
        st = odhs__err(msg, wr == -2 ? ODHS_E_INTERNAL : ODHS_E_IO, "cannot write '%s': %s", path,
                       wr == -2 ? "species lookup failed" : e ? strerror(e) : "write error");
        goto done;
    }
    errno = 0;
    if (rename(tmp, path) != 0) {
        e = errno;
        remove(tmp);
        st = odhs__err(msg, ODHS_E_IO, "cannot rename '%s' to '%s': %s", tmp, path, e ? strerror(e) : "rename failed");
    }

done:
    odhs__free(tmp);
    return st;
}
