/* libodhs - version, status strings, allocation, error messages, RNG. */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "base/base.h"

const char *odhs_version_string(void) { return ODHS_VERSION_STRING; }
int odhs_version_number(void) { return ODHS_VERSION_NUMBER; }

const char *odhs_strerror(int status)
{
    switch (status) {
    case ODHS_OK: return "success";
    case ODHS_STOPPED: return "stopped by a user callback";
    case ODHS_POTENTIALLY_JAMMED: return "potentially jammed: the constrained subset is isostatic";
    case ODHS_JAMMED: return "jammed: isostatic constrained subset with positive self-stress";
    case ODHS_E_NULL: return "a required pointer argument is NULL";
    case ODHS_E_INVALID: return "invalid argument";
    case ODHS_E_NOMEM: return "out of memory";
    case ODHS_E_DIM: return "dimension must be 2 or 3 (or is inconsistent)";
    case ODHS_E_RANGE: return "index out of range";
    case ODHS_E_NONFINITE: return "non-finite number";
    case ODHS_E_OVERLAP: return "particles overlap";
    case ODHS_E_BOX: return "box edge shorter than two largest diameters";
    case ODHS_E_EMPTY: return "empty system";
    case ODHS_E_IO: return "input/output error";
    case ODHS_E_FORMAT: return "malformed file";
    case ODHS_E_STATE: return "call not valid in the current state";
    case ODHS_E_SINGULAR: return "singular or indefinite matrix";
    case ODHS_E_NOCONV: return "iterative solver did not converge";
    case ODHS_E_NOTINSTALLED: return "not installed (feature not built into this library)";
    case ODHS_E_REWIRE: return "rewiring did not reach a valid contact network";
    case ODHS_E_CALLBACK: return "user callback failed or returned non-finite values";
    case ODHS_E_UNSUPPORTED: return "unsupported combination of settings";
    case ODHS_E_TOODENSE: return "random placement cannot reach the requested packing fraction";
    case ODHS_E_INTERNAL: return "internal error";
    case ODHS_STEP_LIMIT: return "the run reached its step limit before the target";
    case ODHS_E_STALLED: return "no progress: the run's target does not advance";
    default: return "unknown status code";
    }
}

/* ---- allocation --------------------------------------------------------- */
#ifdef ODHS_FAULT_INJECTION
/* Test builds only (see internal.h): a per-thread allocation counter, a
 * "fail the n-th allocation (and, if sticky, every later one)" trigger and a
 * count of live blocks. Thread-local, so handles used in different threads
 * stay independent even in this build; normal builds have none of it. */
static _Thread_local uint64_t fault_count;  /* allocations since the last arm */
static _Thread_local uint64_t fault_target; /* 0 = count only */
static _Thread_local int fault_sticky;      /* fail every allocation from the target on */
static _Thread_local int fault_fired;
static _Thread_local int64_t fault_live;    /* allocated and not yet freed */

void odhs__fault_arm(uint64_t n, int sticky)
{
    fault_count = 0;
    fault_target = n;
    fault_sticky = sticky;
    fault_fired = 0;
}

void odhs__fault_disarm(void) { fault_target = 0; }
uint64_t odhs__fault_count(void) { return fault_count; }
int odhs__fault_fired(void) { return fault_fired; }
int64_t odhs__fault_live(void) { return fault_live; }

/* count one allocation attempt; 1 if it is to fail */
static int fault_hit(void)
{
    ++fault_count;
    if (!fault_target || fault_count < fault_target || (fault_count > fault_target && !fault_sticky)) return 0;
    fault_fired = 1;
    return 1;
}
/* count a new block (q != NULL that did not replace p) */
static void *fault_live_add(void *q, const void *p)
{
    if (q && !p) fault_live++;
    return q;
}
#define ODHS_FAULT_HIT() fault_hit()
#define ODHS_FAULT_LIVE(q, p) fault_live_add((q), (p))
#define ODHS_FAULT_FREE(p) (fault_live -= (p) != NULL)
#else
#define ODHS_FAULT_HIT() 0
#define ODHS_FAULT_LIVE(q, p) (q)
#define ODHS_FAULT_FREE(p) ((void)0)
#endif

void *odhs__malloc(size_t size)
{
    return ODHS_FAULT_HIT() ? NULL : ODHS_FAULT_LIVE(malloc(size ? size : 1), NULL);
}
void *odhs__calloc(size_t n, size_t size)
{
    return ODHS_FAULT_HIT() ? NULL : ODHS_FAULT_LIVE(calloc(n ? n : 1, size ? size : 1), NULL);
}
void *odhs__realloc(void *p, size_t size)
{
    return ODHS_FAULT_HIT() ? NULL : ODHS_FAULT_LIVE(realloc(p, size ? size : 1), p);
}
void odhs__free(void *p)
{
    ODHS_FAULT_FREE(p);
    free(p);
}
void *odhs__malloc_array(size_t n, size_t size)
{
    if (size && n > SIZE_MAX / size) return NULL;
    return odhs__malloc(n * size);
}
void odhs_free(void *p) { odhs__free(p); }

/* ---- errors --------------------------------------------------------------- */
int odhs__verr(char *buf, int status, const char *fmt, va_list ap)
{
    if (buf) vsnprintf(buf, ODHS_ERRMSG_LEN, fmt, ap);
    return status;
}

int odhs__err(char *buf, int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    odhs__verr(buf, status, fmt, ap);
    va_end(ap);
    return status;
}

/* ---- the last error of a call without a handle (create functions) ------
 * Thread-local, so separate threads (and their handles) stay independent. */
static _Thread_local char last_error[ODHS_ERRMSG_LEN];

const char *odhs_last_error(void) { return last_error; }

int odhs__create_err(int status, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    odhs__verr(last_error, status, fmt, ap);
    va_end(ap);
    return status;
}

void odhs__create_begin(void) { last_error[0] = '\0'; }

int odhs__create_end(int status)
{
    if (status == ODHS_OK) last_error[0] = '\0';
    else if (!last_error[0]) odhs__create_err(status, "%s", odhs_strerror(status));
    return status;
}

/* ---- xoshiro256** (Blackman & Vigna), seeded with splitmix64 ------------ */
static uint64_t splitmix64(uint64_t *x)
{
    uint64_t z = (*x += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

void odhs__rng_seed(odhs_rng *r, uint64_t seed)
{
    uint64_t x = seed;
    for (int k = 0; k < 4; ++k) r->s[k] = splitmix64(&x);
}

static inline uint64_t rotl(uint64_t x, int k) { return (x << k) | (x >> (64 - k)); }

uint64_t odhs__rng_next(odhs_rng *r)
{
    uint64_t *s = r->s;
    const uint64_t result = rotl(s[1] * 5, 7) * 9;
    const uint64_t t = s[1] << 17;
    s[2] ^= s[0];
    s[3] ^= s[1];
    s[1] ^= s[2];
    s[0] ^= s[3];
    s[2] ^= t;
    s[3] = rotl(s[3], 45);
    return result;
}

double odhs__rng_uniform(odhs_rng *r) { return (double)(odhs__rng_next(r) >> 11) * 0x1.0p-53; }

int odhs__reserve(void **p, size_t *cap, size_t need, size_t elem)
{
    if (*cap >= need) return ODHS_OK;
    size_t c = *cap ? *cap : 16;
    while (c < need) c *= 2;
    void *q = odhs__realloc(*p, c * elem);
    if (!q) return ODHS_E_NOMEM;
    *p = q;
    *cap = c;
    return ODHS_OK;
}
