/*
 * libodhs - small shared helpers for the Check tests (header only).
 *
 * Everything here is independent of the library's own geometry code, so that
 * the tests compare the library against a second implementation:
 *   - tu_rng:            splitmix64 random numbers (not the library's RNG)
 *   - tu_lattice_shift:  n0 a + n1 b + n2 c of the sheared lattice
 *   - tu_min_image_brute: minimum image by exhaustive search over images
 *   - tu_brute_pairs:    all pairs with gap <= max_gap, O(N^2)
 *   - tu_pairlist + tu_pair_collect: collect pairs from odhs_system_for_each_pair
 *   - tu_random_config:  non-overlapping random positions under any strain
 *   - tu_snapshot:       bit-for-bit snapshot of a handle's public state
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#ifndef ODHS_TESTUTIL_H
#define ODHS_TESTUTIL_H

#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"

#define TU_PI 3.14159265358979323846

/* ---- random numbers (splitmix64) ---------------------------------------- */
typedef struct {
    uint64_t s;
} tu_rng;

static inline void tu_rng_seed(tu_rng *r, uint64_t seed) { r->s = seed ^ 0x5851f42d4c957f2dULL; }

static inline uint64_t tu_rng_next(tu_rng *r)
{
    uint64_t z = (r->s += 0x9e3779b97f4a7c15ULL);
    z = (z ^ (z >> 30)) * 0xbf58476d1ce4e5b9ULL;
    z = (z ^ (z >> 27)) * 0x94d049bb133111ebULL;
    return z ^ (z >> 31);
}

/* uniform in [0,1) */
static inline double tu_uniform(tu_rng *r) { return (double)(tu_rng_next(r) >> 11) * 0x1.0p-53; }

/* uniform in [a,b) */
static inline double tu_uniform_in(tu_rng *r, double a, double b) { return a + (b - a) * tu_uniform(r); }

/* log-uniform in [a,b] */
static inline double tu_loguniform(tu_rng *r, double a, double b)
{
    return exp(log(a) + (log(b) - log(a)) * tu_uniform(r));
}

/* uniform integer in [0,n) */
static inline size_t tu_index(tu_rng *r, size_t n) { return (size_t)(tu_rng_next(r) % (uint64_t)n); }

/* ---- lattice ----------------------------------------------------------------
 * a = (Lx,0,0), b = (gamma*Ly, Ly, 0), c = (0,0,Lz).                        */
static inline void tu_lattice_shift(int dim, const double *L, double gamma, const int *n, double *out)
{
    out[0] = n[0] * L[0] + n[1] * gamma * L[1];
    out[1] = n[1] * L[1];
    if (dim == 3) out[2] = n[2] * L[2];
}

static inline double tu_norm2(int dim, const double *v)
{
    double s = 0.0;
    for (int k = 0; k < dim; ++k) s += v[k] * v[k];
    return s;
}

/* Largest |n0| searched by tu_min_image_brute: 2 plus enough to undo any
 * x shift that a b-image with |n1| <= 2 can introduce. */
static inline int tu_brute_n0max(const double *L, double gamma)
{
    return 2 + (int)ceil(2.0 * fabs(gamma) * L[1] / L[0]);
}

/* Minimum image of the raw difference d (dim entries) by exhaustive search over
 * n1, n2 in [-2,2] and n0 in [-K,K] (K = tu_brute_n0max >= 2; this contains
 * every image with |n| <= 2). out = d + n0 a + n1 b + n2 c of smallest norm,
 * img = n (3 entries, img[2] = 0 in 2D). Returns |out|^2. */
static inline double tu_min_image_brute(int dim, const double *L, double gamma, const double *d,
                                        double *out, int *img)
{
    int K = tu_brute_n0max(L, gamma);
    int m2 = dim == 3 ? 2 : 0;
    double best = INFINITY;
    int bn[3] = {0, 0, 0};
    for (int n2 = -m2; n2 <= m2; ++n2)
        for (int n1 = -2; n1 <= 2; ++n1)
            for (int n0 = -K; n0 <= K; ++n0) {
                int n[3] = {n0, n1, n2};
                double sh[3] = {0, 0, 0}, v[3] = {0, 0, 0};
                tu_lattice_shift(dim, L, gamma, n, sh);
                for (int k = 0; k < dim; ++k) v[k] = d[k] + sh[k];
                double s2 = tu_norm2(dim, v);
                if (s2 < best) {
                    best = s2;
                    bn[0] = n0;
                    bn[1] = n1;
                    bn[2] = n2;
                }
            }
    double sh[3] = {0, 0, 0};
    tu_lattice_shift(dim, L, gamma, bn, sh);
    if (out)
        for (int k = 0; k < dim; ++k) out[k] = d[k] + sh[k];
    if (img)
        for (int k = 0; k < 3; ++k) img[k] = bn[k];
    return best;
}

/* Quick minimum image (y, z, then x nearest integer); exact for pairs closer
 * than half the shortest edge when |gamma| <= 1/2. Used only by the scene
 * generator below, whose output the library validates anyway. */
static inline double tu_min_image_fast(int dim, const double *L, double gamma, double *d)
{
    double ny = nearbyint(d[1] / L[1]);
    d[1] -= ny * L[1];
    d[0] -= ny * gamma * L[1];
    if (dim == 3) d[2] -= nearbyint(d[2] / L[2]) * L[2];
    d[0] -= nearbyint(d[0] / L[0]) * L[0];
    return tu_norm2(dim, d);
}

/* ---- pair lists ---------------------------------------------------------- */
typedef struct {
    size_t i, j;
    double gap;
    double rij[3];
} tu_pair;

typedef struct {
    int dim;
    tu_pair *p;
    size_t n, cap;
    size_t bad_order; /* callbacks with i >= j */
    size_t calls;     /* callbacks received */
    size_t stop_after; /* return nonzero on this call (1-based); 0 never */
    int alloc_failed;
} tu_pairlist;

static inline void tu_pairlist_init(tu_pairlist *pl, int dim)
{
    memset(pl, 0, sizeof *pl);
    pl->dim = dim;
}

static inline void tu_pairlist_free(tu_pairlist *pl)
{
    free(pl->p);
    pl->p = NULL;
    pl->n = pl->cap = 0;
}

static inline void tu_pairlist_push(tu_pairlist *pl, size_t i, size_t j, const double *rij, double gap)
{
    if (pl->n == pl->cap) {
        size_t nc = pl->cap ? 2 * pl->cap : 64;
        tu_pair *np = realloc(pl->p, nc * sizeof *np);
        if (!np) {
            pl->alloc_failed = 1;
            return;
        }
        pl->p = np;
        pl->cap = nc;
    }
    tu_pair *q = &pl->p[pl->n++];
    q->i = i;
    q->j = j;
    q->gap = gap;
    q->rij[0] = q->rij[1] = q->rij[2] = 0.0;
    for (int k = 0; k < pl->dim; ++k) q->rij[k] = rij[k];
}

/* odhs_pair_fn that appends to a tu_pairlist (ctx) */
static inline int tu_pair_collect(size_t i, size_t j, const double *rij, double gap, void *ctx)
{
    tu_pairlist *pl = ctx;
    pl->calls++;
    if (i >= j) pl->bad_order++;
    tu_pairlist_push(pl, i, j, rij, gap);
    return pl->stop_after && pl->calls >= pl->stop_after;
}

static inline int tu_pair_cmp(const void *a, const void *b)
{
    const tu_pair *p = a, *q = b;
    if (p->i != q->i) return p->i < q->i ? -1 : 1;
    if (p->j != q->j) return p->j < q->j ? -1 : 1;
    return 0;
}

static inline void tu_pairlist_sort(tu_pairlist *pl)
{
    if (pl->n > 1) qsort(pl->p, pl->n, sizeof *pl->p, tu_pair_cmp);
}

/* number of adjacent duplicates in a sorted list */
static inline size_t tu_pairlist_duplicates(const tu_pairlist *pl)
{
    size_t d = 0;
    for (size_t k = 1; k < pl->n; ++k)
        if (tu_pair_cmp(&pl->p[k - 1], &pl->p[k]) == 0) d++;
    return d;
}

/* Brute force: every pair i<j with |R_ij| - (r_i + r_j) <= max_gap, with the
 * exhaustive minimum image. Output sorted by (i,j). */
static inline void tu_brute_pairs(int dim, size_t n, const double *x, const double *r, const double *L,
                                  double gamma, double max_gap, tu_pairlist *out)
{
    tu_pairlist_init(out, dim);
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 1; j < n; ++j) {
            double d[3] = {0, 0, 0}, m[3] = {0, 0, 0};
            for (int k = 0; k < dim; ++k) d[k] = x[j * dim + k] - x[i * dim + k];
            double s2 = tu_min_image_brute(dim, L, gamma, d, m, NULL);
            double gap = sqrt(s2) - (r[i] + r[j]);
            if (gap <= max_gap) tu_pairlist_push(out, i, j, m, gap);
        }
}

/* ---- scenes --------------------------------------------------------------- */

/* n radii log-uniform in [rmin, rmax]; r[0] = rmax and r[1] = rmin exactly
 * (n >= 2) so that the size ratio is exactly rmax/rmin. */
static inline void tu_radii_loguniform(size_t n, double rmin, double rmax, double *r, tu_rng *rng)
{
    for (size_t i = 0; i < n; ++i) r[i] = tu_loguniform(rng, rmin, rmax);
    if (n >= 1) r[0] = rmax;
    if (n >= 2) r[1] = rmin;
}

/* Random sequential addition (in index order) of non-overlapping particles in
 * the lab rectangle [0,L) with strain gamma (|gamma| <= 1/2); every pair keeps
 * a gap of at least min_gap. Returns 1 on success, 0 if a particle could not be
 * placed in max_tries attempts. O(N^2) per attempt: for tests only. */
static inline int tu_random_config(int dim, size_t n, const double *L, double gamma, const double *r,
                                   double min_gap, double *x, tu_rng *rng)
{
    const int max_tries = 100000;
    for (size_t i = 0; i < n; ++i) {
        int t;
        for (t = 0; t < max_tries; ++t) {
            for (int k = 0; k < dim; ++k) x[i * dim + k] = tu_uniform(rng) * L[k];
            int ok = 1;
            for (size_t j = 0; j < i && ok; ++j) {
                double d[3] = {0, 0, 0};
                for (int k = 0; k < dim; ++k) d[k] = x[j * dim + k] - x[i * dim + k];
                double s2 = tu_min_image_fast(dim, L, gamma, d);
                double c = r[i] + r[j] + min_gap;
                if (s2 < c * c) ok = 0;
            }
            if (ok) break;
        }
        if (t == max_tries) return 0;
    }
    return 1;
}

/* ---- snapshots: the whole public state of a handle, bit for bit ---------- */
typedef struct {
    int dim;
    size_t n;
    double L[3];
    double gamma;
    int ready;
    int st_r, st_x; /* status of get_radii / get_positions */
    double *r, *x;
    char (*species)[ODHS_SPECIES_MAX + 1];
} tu_snapshot;

static inline void tu_snapshot_take(const odhs_system *sys, tu_snapshot *s)
{
    memset(s, 0, sizeof *s);
    s->dim = odhs_system_dim(sys);
    s->n = odhs_system_count(sys);
    s->L[0] = s->L[1] = s->L[2] = 0.0;
    odhs_system_get_box(sys, s->L);
    odhs_system_get_strain(sys, &s->gamma);
    s->ready = odhs_system_is_ready(sys);
    s->r = calloc(s->n ? s->n : 1, sizeof(double));
    s->x = calloc(s->n ? s->n * (size_t)s->dim : 1, sizeof(double));
    s->species = calloc(s->n ? s->n : 1, sizeof *s->species);
    if (!s->r || !s->x || !s->species) return;
    s->st_r = odhs_system_get_radii(sys, s->r);
    s->st_x = odhs_system_get_positions(sys, s->x);
    for (size_t i = 0; i < s->n; ++i) odhs_system_get_species(sys, i, s->species[i], sizeof s->species[i]);
}

static inline void tu_snapshot_free(tu_snapshot *s)
{
    free(s->r);
    free(s->x);
    free(s->species);
    s->r = s->x = NULL;
    s->species = NULL;
}

/* 1 if the two snapshots are identical bit for bit (radii/positions only
 * compared when they were readable in both). */
static inline int tu_snapshot_equal(const tu_snapshot *a, const tu_snapshot *b)
{
    if (a->dim != b->dim || a->n != b->n || a->ready != b->ready) return 0;
    if (a->st_r != b->st_r || a->st_x != b->st_x) return 0;
    if (!a->r || !b->r || !a->x || !b->x || !a->species || !b->species) return 0;
    if (memcmp(a->L, b->L, sizeof a->L) != 0) return 0;
    if (memcmp(&a->gamma, &b->gamma, sizeof a->gamma) != 0) return 0;
    if (a->st_r == ODHS_OK && memcmp(a->r, b->r, a->n * sizeof(double)) != 0) return 0;
    if (a->st_x == ODHS_OK && memcmp(a->x, b->x, a->n * (size_t)a->dim * sizeof(double)) != 0) return 0;
    for (size_t i = 0; i < a->n; ++i)
        if (strcmp(a->species[i], b->species[i]) != 0) return 0;
    return 1;
}

/* 1 if the handle's current state equals the snapshot bit for bit */
static inline int tu_snapshot_matches(const odhs_system *sys, const tu_snapshot *s)
{
    tu_snapshot now;
    tu_snapshot_take(sys, &now);
    int eq = tu_snapshot_equal(s, &now);
    tu_snapshot_free(&now);
    return eq;
}

/* 1 if the decimal number idx occurs in msg as a whole number (not part of a
 * longer digit string or a decimal fraction). */
static inline int tu_msg_has_index(const char *msg, size_t idx)
{
    char num[32];
    snprintf(num, sizeof num, "%zu", idx);
    size_t len = strlen(num);
    for (const char *p = strstr(msg, num); p; p = strstr(p + 1, num)) {
        int before_ok = p == msg || (!(p[-1] >= '0' && p[-1] <= '9') && p[-1] != '.');
        char c = p[len];
        int after_ok = !(c >= '0' && c <= '9') && !(c == '.' && p[len + 1] >= '0' && p[len + 1] <= '9');
        if (before_ok && after_ok) return 1;
    }
    return 0;
}

/* relative closeness |a-b| <= tol * max(1, |a|, |b|) */
static inline int tu_close(double a, double b, double tol)
{
    double s = fabs(a) > fabs(b) ? fabs(a) : fabs(b);
    if (s < 1.0) s = 1.0;
    return fabs(a - b) <= tol * s;
}

#endif /* ODHS_TESTUTIL_H */
