/*
 * libodhs private header: allocation, error messages, random numbers, small helpers shared by every module.
 * Not installed.
 */
#ifndef ODHS_BASE_BASE_H
#define ODHS_BASE_BASE_H

#include <math.h>
#include <stdarg.h>
#include <stddef.h>
#include <stdint.h>

#include "odhs.h"

#define ODHS_ERRMSG_LEN 512
#define ODHS_PI 3.14159265358979323846

#if defined(__GNUC__)
#define ODHS_PRINTF(a, b) __attribute__((format(printf, a, b)))
#else
#define ODHS_PRINTF(a, b)
#endif

/* ---- allocation (every allocation goes through these) ---------------- */
void *odhs__malloc(size_t size);
void *odhs__calloc(size_t n, size_t size);
void *odhs__realloc(void *p, size_t size);
void odhs__free(void *p);
/* malloc of n*size with overflow check */
void *odhs__malloc_array(size_t n, size_t size);

#ifdef ODHS_FAULT_INJECTION
/* Allocation-failure injection, compiled in only with -DODHS_FAULT_INJECTION
 * (the `make check-allocfail` build; never in normal builds). Per thread:
 * every odhs__malloc/calloc/realloc (and so malloc_array) counts as one
 * allocation. odhs__fault_arm(n, sticky) resets the count and makes the
 * n-th allocation from now on return NULL (n = 0: count only), and with
 * sticky != 0 every later one too;
 * odhs__fault_disarm() stops failing (counting goes on);
 * odhs__fault_count() is the number of allocations since the last arm;
 * odhs__fault_fired() whether the armed failure has happened;
 * odhs__fault_live() the number of blocks this thread allocated through
 * odhs__* and has not freed yet (a cheap leak check between two points). */
void odhs__fault_arm(uint64_t n, int sticky);
void odhs__fault_disarm(void);
uint64_t odhs__fault_count(void);
int odhs__fault_fired(void);
int64_t odhs__fault_live(void);
#endif

/* ---- error messages ---------------------------------------------------- */
/* Format into buf (ODHS_ERRMSG_LEN) and return status. */
int odhs__err(char *buf, int status, const char *fmt, ...) ODHS_PRINTF(3, 4);
int odhs__verr(char *buf, int status, const char *fmt, va_list ap);
/* set the thread's odhs_last_error() message and return status */
int odhs__create_err(int status, const char *fmt, ...) ODHS_PRINTF(2, 3);
/* a create function's bracket: begin clears odhs_last_error(); end returns
 * status, clearing the message on ODHS_OK and, on failure, setting
 * odhs_strerror(status) unless the call set a message (odhs__create_err) */
void odhs__create_begin(void);
int odhs__create_end(int status);

/* ---- random numbers: xoshiro256** seeded by splitmix64 --------------- */
typedef struct {
    uint64_t s[4];
} odhs_rng;
void odhs__rng_seed(odhs_rng *r, uint64_t seed);
uint64_t odhs__rng_next(odhs_rng *r);
/* uniform in [0,1) with 53 random bits */
double odhs__rng_uniform(odhs_rng *r);

/* ---- growable arrays ------------------------------------------------------- */
/* Make room for `need` elements of size elem in *p (capacity *cap, doubled
 * from 16); ODHS_OK or ODHS_E_NOMEM, leaving *p and *cap as they were. */
int odhs__reserve(void **p, size_t *cap, size_t need, size_t elem);

#endif /* ODHS_BASE_BASE_H */
