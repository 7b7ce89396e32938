/*
 * libodhs - tests of the contact network (network.h): the operator S against a
 * hand-built dense matrix, S / S^T / N products and their adjointness, the
 * contact hash under thousands of random additions and removals, error codes
 * that leave the network unchanged, contact detection against brute force,
 * the coordination number and the constrained subset (eq. 29 of Lerner,
 * During & Wyart 2013) against a brute-force iterative removal.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <check.h>
#include <math.h>
#include <stdint.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "odhs.h"
#include "testutil.h"

/* ------------------------------------------------------------------------ */
/* helpers                                                                   */
/* ------------------------------------------------------------------------ */

static odhs_system *net_new_sys(int dim, size_t n)
{
    odhs_system *s = NULL;
    int st = odhs_system_create(dim, n, &s);
    ck_assert_msg(st == ODHS_OK, "odhs_system_create(%d, %zu) = %d", dim, n, st);
    return s;
}

static odhs_network *net_new(const odhs_system *sys)
{
    odhs_network *net = NULL;
    int st = odhs_network_create(sys, &net);
    ck_assert_msg(st == ODHS_OK, "odhs_network_create = %d", st);
    ck_assert_ptr_nonnull(net);
    return net;
}

/* A random non-overlapping configuration (radii log-uniform in [rmin,rmax],
 * positions by RSA under Lees-Edwards strain gamma). x, r receive the data the
 * system holds (positions read back after wrapping). */
static odhs_system *net_random_system(int dim, size_t n, const double *L, double gamma, double rmin,
                                      double rmax, uint64_t seed, double *x, double *r)
{
    tu_rng rng;
    tu_rng_seed(&rng, seed);
    tu_radii_loguniform(n, rmin, rmax, r, &rng);
    ck_assert_msg(tu_random_config(dim, n, L, gamma, r, 1e-9, x, &rng), "RSA failed");
    odhs_system *sys = net_new_sys(dim, n);
    int st = odhs_system_set_configuration(sys, L, gamma, r, x);
    ck_assert_msg(st == ODHS_OK, "set_configuration = %d (%s)", st, odhs_system_errmsg(sys));
    ck_assert_int_eq(odhs_system_get_positions(sys, x), ODHS_OK);
    ck_assert_int_eq(odhs_system_get_radii(sys, r), ODHS_OK);
    return sys;
}

/* Independent unit normal of the pair (i,j): minimum image by exhaustive
 * search; returns the distance. */
static double net_brute_normal(int dim, const double *L, double gamma, const double *x, size_t i, size_t j,
                               double *nrm)
{
    double d[3] = {0, 0, 0}, m[3] = {0, 0, 0};
    for (int k = 0; k < dim; ++k) d[k] = x[j * dim + k] - x[i * dim + k];
    double s2 = tu_min_image_brute(dim, L, gamma, d, m, NULL);
    double r = sqrt(s2);
    for (int k = 0; k < dim; ++k) nrm[k] = m[k] / r;
    return r;
}

/* Dense S (Nc x N*dim, row-major) built by hand from the contact list. */
static double *net_dense_S(const odhs_network *net, int dim, size_t n, const double *L, double gamma,
                           const double *x)
{
    size_t nc = odhs_network_count(net), nd = n * (size_t)dim;
    double *S = calloc(nc * nd + 1, sizeof *S);
    ck_assert_ptr_nonnull(S);
    for (size_t c = 0; c < nc; ++c) {
        size_t i, j;
        int kind;
        ck_assert_int_eq(odhs_network_get_contact(net, c, &i, &j, &kind), ODHS_OK);
        ck_assert_msg(i < j, "contact %zu is (%zu,%zu), not ordered i < j", c, i, j);
        double nrm[3];
        net_brute_normal(dim, L, gamma, x, i, j, nrm);
        for (int k = 0; k < dim; ++k) {
            S[c * nd + i * dim + k] = -nrm[k];
            S[c * nd + j * dim + k] = +nrm[k];
        }
    }
    return S;
}

/* Add every pair with gap <= maxgap (brute force) as a contact (random kind). */
static size_t net_add_near_pairs(odhs_network *net, int dim, size_t n, const double *x, const double *r,
                                 const double *L, double gamma, double maxgap, tu_rng *rng)
{
    tu_pairlist pl;
    tu_brute_pairs(dim, n, x, r, L, gamma, maxgap, &pl);
    ck_assert(!pl.alloc_failed);
    /* add in a random order, with random orientation (i,j) or (j,i) */
    for (size_t k = pl.n; k > 1; --k) {
        size_t m = tu_index(rng, k);
        tu_pair t = pl.p[k - 1];
        pl.p[k - 1] = pl.p[m];
        pl.p[m] = t;
    }
    for (size_t k = 0; k < pl.n; ++k) {
        size_t a = pl.p[k].i, b = pl.p[k].j;
        if (tu_uniform(rng) < 0.5) {
            size_t t = a;
            a = b;
            b = t;
        }
        int kind = tu_uniform(rng) < 0.2 ? ODHS_CONTACT_PERMANENT : ODHS_CONTACT_TEMPORARY;
        int st = odhs_network_add(net, a, b, kind);
        ck_assert_msg(st == ODHS_OK, "add(%zu,%zu) = %d", a, b, st);
    }
    size_t cnt = pl.n;
    tu_pairlist_free(&pl);
    return cnt;
}

static void net_random_vec(size_t n, double *v, tu_rng *rng)
{
    for (size_t k = 0; k < n; ++k) v[k] = tu_uniform_in(rng, -1.0, 1.0);
}

/* ------------------------------------------------------------------------ */
/* S in CSR form and the products S, S^T, N                                 */
/* ------------------------------------------------------------------------ */

static void check_operator_case(int dim, uint64_t seed)
{
    const size_t n = dim == 2 ? 36 : 50;
    double L[3] = {6.5, 6.0, 6.8};
    if (dim == 2) {
        L[0] = 12.0;
        L[1] = 10.0;
    }
    const double gamma = dim == 2 ? 0.31 : -0.27;
    double *x = malloc(n * dim * sizeof *x), *r = malloc(n * sizeof *r);
    ck_assert(x && r);
    odhs_system *sys = net_random_system(dim, n, L, gamma, 0.45, 0.8, seed, x, r);
    odhs_network *net = net_new(sys);
    tu_rng rng;
    tu_rng_seed(&rng, seed * 7 + 3);
    size_t added = net_add_near_pairs(net, dim, n, x, r, L, gamma, 0.6, &rng);
    ck_assert_msg(added >= n / 2, "only %zu near pairs: the test would be vacuous", added);
    ck_assert_int_eq(odhs_network_update_geometry(net, sys), ODHS_OK);
    size_t nc = odhs_network_count(net), nd = n * (size_t)dim;
    ck_assert_uint_eq(nc, added);

    double *S = net_dense_S(net, dim, n, L, gamma, x);

    /* normals and gaps as stored */
    double *nrm = malloc(nc * dim * sizeof *nrm), *gap = malloc(nc * sizeof *gap);
    ck_assert(nrm && gap);
    ck_assert_int_eq(odhs_network_get_normals(net, nrm), ODHS_OK);
    ck_assert_int_eq(odhs_network_get_gaps(net, gap), ODHS_OK);
    for (size_t c = 0; c < nc; ++c) {
        size_t i, j;
        odhs_network_get_contact(net, c, &i, &j, NULL);
        double bn[3];
        double dist = net_brute_normal(dim, L, gamma, x, i, j, bn);
        for (int k = 0; k < dim; ++k)
            ck_assert_msg(fabs(nrm[c * dim + k] - bn[k]) <= 1e-14, "normal %zu[%d]: %.17g vs %.17g", c, k,
                          nrm[c * dim + k], bn[k]);
        ck_assert_msg(fabs(gap[c] - (dist - r[i] - r[j])) <= 1e-13, "gap %zu: %.17g vs %.17g", c, gap[c],
                      dist - r[i] - r[j]);
        ck_assert_msg(gap[c] <= 0.6 + 1e-12 && gap[c] >= -1e-12, "gap %zu = %g outside [0, 0.6]", c, gap[c]);
    }

    /* CSR against the dense hand-built S */
    size_t nnz = odhs_network_nnz(net);
    ck_assert_uint_eq(nnz, nc * 2u * (size_t)dim);
    size_t *rowptr = malloc((nc + 1) * sizeof *rowptr), *col = malloc(nnz * sizeof *col);
    double *val = malloc(nnz * sizeof *val);
    ck_assert(rowptr && col && val);
    ck_assert_int_eq(odhs_network_get_S_csr(net, rowptr, col, val), ODHS_OK);
    ck_assert_uint_eq(rowptr[0], 0);
    ck_assert_uint_eq(rowptr[nc], nnz);
    double *Sc = calloc(nc * nd + 1, sizeof *Sc);
    ck_assert_ptr_nonnull(Sc);
    for (size_t c = 0; c < nc; ++c) {
        ck_assert_uint_eq(rowptr[c + 1] - rowptr[c], 2u * (size_t)dim);
        for (size_t p = rowptr[c]; p < rowptr[c + 1]; ++p) {
            ck_assert_msg(col[p] < nd, "column %zu out of range", col[p]);
            if (p > rowptr[c]) ck_assert_msg(col[p] > col[p - 1], "row %zu: columns not increasing", c);
            Sc[c * nd + col[p]] += val[p];
        }
    }
    for (size_t e = 0; e < nc * nd; ++e)
        ck_assert_msg(fabs(Sc[e] - S[e]) <= 1e-14, "S[%zu][%zu]: csr %.17g, dense %.17g", e / nd, e % nd, Sc[e],
                      S[e]);
    /* each row: -n on i, +n on j, |n| = 1 */
    for (size_t c = 0; c < nc; ++c) {
        double rs[3] = {0, 0, 0}, n2 = 0.0;
        for (size_t q = 0; q < nd; ++q) rs[q % dim] += Sc[c * nd + q];
        for (int k = 0; k < dim; ++k) {
            ck_assert_msg(fabs(rs[k]) <= 1e-15, "row %zu does not sum to zero", c);
            n2 += val[rowptr[c] + dim + k] * val[rowptr[c] + dim + k];
        }
        ck_assert_msg(fabs(n2 - 1.0) <= 1e-14, "row %zu: |n|^2 = %.17g", c, n2);
    }

    /* products against dense ones, several random vectors */
    double *v = malloc(nd * sizeof *v), *f = malloc(nc * sizeof *f), *Sv = malloc(nc * sizeof *Sv);
    double *STf = malloc(nd * sizeof *STf), *Nf = malloc(nc * sizeof *Nf), *Nf2 = malloc(nc * sizeof *Nf2);
    double *work = malloc(nd * sizeof *work), *tmp = malloc(nd * sizeof *tmp);
    ck_assert(v && f && Sv && STf && Nf && Nf2 && work && tmp);
    for (int rep = 0; rep < 5; ++rep) {
        net_random_vec(nd, v, &rng);
        net_random_vec(nc, f, &rng);
        ck_assert_int_eq(odhs_network_apply_S(net, v, Sv), ODHS_OK);
        ck_assert_int_eq(odhs_network_apply_ST(net, f, STf), ODHS_OK);
        ck_assert_int_eq(odhs_network_apply_N(net, f, Nf, work), ODHS_OK);
        ck_assert_int_eq(odhs_network_apply_N(net, f, Nf2, NULL), ODHS_OK);
        for (size_t c = 0; c < nc; ++c) {
            double s = 0.0, sc = 0.0;
            for (size_t q = 0; q < nd; ++q) {
                s += S[c * nd + q] * v[q];
                sc += fabs(S[c * nd + q] * v[q]);
            }
            ck_assert_msg(fabs(Sv[c] - s) <= 1e-14 * (1.0 + sc), "(S v)_%zu: %.17g vs dense %.17g", c, Sv[c], s);
        }
        for (size_t q = 0; q < nd; ++q) {
            double s = 0.0, sc = 0.0;
            for (size_t c = 0; c < nc; ++c) {
                s += S[c * nd + q] * f[c];
                sc += fabs(S[c * nd + q] * f[c]);
            }
            tmp[q] = s;
            ck_assert_msg(fabs(STf[q] - s) <= 1e-14 * (1.0 + sc), "(S^T f)_%zu: %.17g vs dense %.17g", q, STf[q],
                          s);
        }
        /* N f = S (S^T f) with the dense N = S S^T */
        for (size_t c = 0; c < nc; ++c) {
            double s = 0.0, sc = 0.0;
            for (size_t b = 0; b < nc; ++b) {
                double Ncb = 0.0;
                for (size_t q = 0; q < nd; ++q) Ncb += S[c * nd + q] * S[b * nd + q];
                s += Ncb * f[b];
                sc += fabs(Ncb * f[b]);
            }
            ck_assert_msg(fabs(Nf[c] - s) <= 1e-14 * (1.0 + sc), "(N f)_%zu: %.17g vs dense %.17g", c, Nf[c], s);
            ck_assert_msg(Nf[c] == Nf2[c], "apply_N with and without work differ at %zu", c);
        }
        /* adjointness <f|S v> = <S^T f|v>, and <f|N f> = |S^T f|^2 >= 0 */
        double a = 0.0, b = 0.0, sa = 0.0, fNf = 0.0, st2 = 0.0;
        for (size_t c = 0; c < nc; ++c) {
            a += f[c] * Sv[c];
            sa += fabs(f[c] * Sv[c]);
            fNf += f[c] * Nf[c];
        }
        for (size_t q = 0; q < nd; ++q) {
            b += STf[q] * v[q];
            st2 += STf[q] * STf[q];
        }
        ck_assert_msg(fabs(a - b) <= 1e-13 * (1.0 + sa), "<f|Sv> = %.17g, <S^T f|v> = %.17g", a, b);
        ck_assert_msg(fabs(fNf - st2) <= 1e-13 * (1.0 + st2), "<f|Nf> = %.17g, |S^T f|^2 = %.17g", fNf, st2);
        /* S annihilates rigid translations */
        for (int k = 0; k < dim; ++k) {
            for (size_t q = 0; q < nd; ++q) v[q] = (q % dim == (size_t)k) ? 1.7 : 0.0;
            ck_assert_int_eq(odhs_network_apply_S(net, v, Sv), ODHS_OK);
            for (size_t c = 0; c < nc; ++c) ck_assert_msg(fabs(Sv[c]) <= 1e-14, "S (translation) != 0");
        }
    }

    free(v);
    free(f);
    free(Sv);
    free(STf);
    free(Nf);
    free(Nf2);
    free(work);
    free(tmp);
    free(rowptr);
    free(col);
    free(val);
    free(Sc);
    free(S);
    free(nrm);
    free(gap);
    free(x);
    free(r);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}

START_TEST(test_S_dense_2d)
{
    for (uint64_t seed = 1; seed <= 4; ++seed) check_operator_case(2, seed);
}
END_TEST

START_TEST(test_S_dense_3d)
{
    for (uint64_t seed = 11; seed <= 13; ++seed) check_operator_case(3, seed);
}
END_TEST

/* A hand-computable case: two discs along x, one along y. */
START_TEST(test_S_by_hand)
{
    odhs_system *sys = net_new_sys(2, 3);
    double L[2] = {10.0, 10.0}, r[3] = {0.5, 0.5, 0.5};
    /* 0 at (1,1); 1 at (2,1) (n01 = +x); 2 at (1, 9.5): the minimum image of
     * R_2 - R_0 is (0,-1.5) through the periodic y boundary (n02 = -y). */
    double x[6] = {1.0, 1.0, 2.0, 1.0, 1.0, 9.5};
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
    odhs_network *net = net_new(sys);
    ck_assert_int_eq(odhs_network_add(net, 2, 0, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    ck_assert_int_eq(odhs_network_add(net, 1, 0, ODHS_CONTACT_PERMANENT), ODHS_OK);
    ck_assert_int_eq(odhs_network_update_geometry(net, sys), ODHS_OK);
    size_t rowptr[3], col[8];
    double val[8];
    ck_assert_int_eq(odhs_network_get_S_csr(net, rowptr, col, val), ODHS_OK);
    /* contact 0 = (0,2): -n on 0, +n on 2, n = (0,-1) */
    size_t i, j;
    int kind;
    ck_assert_int_eq(odhs_network_get_contact(net, 0, &i, &j, &kind), ODHS_OK);
    ck_assert_uint_eq(i, 0);
    ck_assert_uint_eq(j, 2);
    ck_assert_int_eq(kind, ODHS_CONTACT_TEMPORARY);
    const size_t ecol0[4] = {0, 1, 4, 5};
    const double eval0[4] = {0.0, 1.0, 0.0, -1.0};
    for (int p = 0; p < 4; ++p) {
        ck_assert_uint_eq(col[p], ecol0[p]);
        ck_assert_double_eq_tol(val[p], eval0[p], 1e-15);
    }
    ck_assert_int_eq(odhs_network_get_contact(net, 1, &i, &j, &kind), ODHS_OK);
    ck_assert_uint_eq(i, 0);
    ck_assert_uint_eq(j, 1);
    ck_assert_int_eq(kind, ODHS_CONTACT_PERMANENT);
    const size_t ecol1[4] = {0, 1, 2, 3};
    const double eval1[4] = {-1.0, 0.0, 1.0, 0.0};
    for (int p = 0; p < 4; ++p) {
        ck_assert_uint_eq(col[4 + p], ecol1[p]);
        ck_assert_double_eq_tol(val[4 + p], eval1[p], 1e-15);
    }
    double gap[2];
    ck_assert_int_eq(odhs_network_get_gaps(net, gap), ODHS_OK);
    ck_assert_double_eq_tol(gap[0], 0.5, 1e-14);
    ck_assert_double_eq_tol(gap[1], 0.0, 1e-14);
    /* S V for V = velocities: 0 at rest, 1 moving +x (separating from 0), 2 moving -y */
    double V[6] = {0, 0, 3.0, 0, 0, -2.0}, out[2];
    ck_assert_int_eq(odhs_network_apply_S(net, V, out), ODHS_OK);
    ck_assert_double_eq_tol(out[0], 2.0, 1e-15); /* (V2-V0).n02 = (0,-2).(0,-1) */
    ck_assert_double_eq_tol(out[1], 3.0, 1e-15);
    /* S^T f: repulsive forces push 1 along +x and 2 along -y, 0 the other way */
    double fc[2] = {1.5, 2.0}, F[6];
    ck_assert_int_eq(odhs_network_apply_ST(net, fc, F), ODHS_OK);
    const double eF[6] = {-2.0, 1.5, 2.0, 0.0, 0.0, -1.5};
    for (int q = 0; q < 6; ++q) ck_assert_double_eq_tol(F[q], eF[q], 1e-15);
    /* N = [[2, n02.n01... ]]: N_01 = (+n02 on 0 block: -n02).(-n01) = n02.n01 = 0 */
    double Nout[2];
    ck_assert_int_eq(odhs_network_apply_N(net, fc, Nout, NULL), ODHS_OK);
    ck_assert_double_eq_tol(Nout[0], 3.0, 1e-15);
    ck_assert_double_eq_tol(Nout[1], 4.0, 1e-15);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* hash consistency under random add / remove                               */
/* ------------------------------------------------------------------------ */

/* state[i*n+j] (i<j): 0 absent, 1 temporary, 2 permanent */
static void hash_full_check(const odhs_network *net, const unsigned char *state, size_t n, size_t expect,
                            int sweep_all, tu_rng *rng)
{
    size_t nc = odhs_network_count(net);
    ck_assert_msg(nc == expect, "Nc = %zu, brute-force list has %zu", nc, expect);
    unsigned char *seen = calloc(n * n, 1);
    ck_assert_ptr_nonnull(seen);
    for (size_t k = 0; k < nc; ++k) {
        size_t i, j, idx;
        int kind;
        ck_assert_int_eq(odhs_network_get_contact(net, k, &i, &j, &kind), ODHS_OK);
        ck_assert_msg(i < j && j < n, "contact %zu = (%zu,%zu)", k, i, j);
        ck_assert_msg(state[i * n + j], "contact %zu = (%zu,%zu) is not in the brute-force list", k, i, j);
        ck_assert_msg(!seen[i * n + j], "contact (%zu,%zu) listed twice", i, j);
        seen[i * n + j] = 1;
        int ekind = state[i * n + j] == 2 ? ODHS_CONTACT_PERMANENT : ODHS_CONTACT_TEMPORARY;
        ck_assert_msg(kind == ekind, "contact (%zu,%zu): kind %d, expected %d", i, j, kind, ekind);
        ck_assert_int_eq(odhs_network_find(net, i, j, &idx), ODHS_OK);
        ck_assert_msg(idx == k, "find(%zu,%zu) = %zu, expected %zu", i, j, idx, k);
        ck_assert_int_eq(odhs_network_find(net, j, i, &idx), ODHS_OK);
        ck_assert_msg(idx == k, "find(%zu,%zu) = %zu, expected %zu", j, i, idx, k);
    }
    if (sweep_all) {
        for (size_t i = 0; i < n; ++i)
            for (size_t j = i + 1; j < n; ++j) {
                size_t idx;
                ck_assert_int_eq(odhs_network_find(net, i, j, &idx), ODHS_OK);
                if (state[i * n + j]) ck_assert_msg(idx < nc, "present (%zu,%zu) not found", i, j);
                else ck_assert_msg(idx == SIZE_MAX, "absent (%zu,%zu) found at %zu", i, j, idx);
            }
    } else {
        for (int t = 0; t < 2000; ++t) {
            size_t i = tu_index(rng, n), j = tu_index(rng, n), idx = 0;
            if (i == j) continue;
            ck_assert_int_eq(odhs_network_find(net, i, j, &idx), ODHS_OK);
            size_t a = i < j ? i : j, b = i < j ? j : i;
            if (state[a * n + b]) ck_assert_msg(idx < nc, "present (%zu,%zu) not found", i, j);
            else ck_assert_msg(idx == SIZE_MAX, "absent (%zu,%zu) found at %zu", i, j, idx);
        }
    }
    free(seen);
}

START_TEST(test_hash_stress)
{
    const size_t n = 500;
    odhs_system *sys = net_new_sys(2, n);
    odhs_network *net = net_new(sys);
    unsigned char *state = calloc(n * n, 1);
    ck_assert_ptr_nonnull(state);
    tu_rng rng;
    tu_rng_seed(&rng, 20260417);
    size_t count = 0;

    /* a pool of pairs: toggling within it makes many removals of present keys,
     * which exercises the backward-shift deletion of the linear probing */
    const size_t npool = 6000;
    size_t(*pool)[2] = malloc(npool * sizeof *pool);
    ck_assert_ptr_nonnull(pool);
    for (size_t p = 0; p < npool; ++p) {
        size_t i, j;
        do {
            i = tu_index(&rng, n);
            j = tu_index(&rng, n);
        } while (i == j);
        pool[p][0] = i;
        pool[p][1] = j;
    }

    /* phase 1: grow to several thousand contacts (resizes), phase 2: random
     * toggles, phase 3: remove everything in random order */
    for (int phase = 1; phase <= 2; ++phase) {
        size_t nops = phase == 1 ? 5000 : 30000;
        for (size_t op = 0; op < nops; ++op) {
            size_t p = tu_index(&rng, phase == 1 ? npool : npool / 2);
            size_t i = pool[p][0], j = pool[p][1];
            size_t a = i < j ? i : j, b = i < j ? j : i;
            unsigned char *s = &state[a * n + b];
            if (*s && (phase == 2 || tu_uniform(&rng) < 0.1)) {
                int st = odhs_network_remove(net, i, j);
                ck_assert_msg(st == ODHS_OK, "remove(%zu,%zu) = %d", i, j, st);
                *s = 0;
                count--;
                /* removing again fails */
                ck_assert_int_eq(odhs_network_remove(net, j, i), ODHS_E_INVALID);
            } else if (!*s) {
                int kind = tu_uniform(&rng) < 0.3 ? ODHS_CONTACT_PERMANENT : ODHS_CONTACT_TEMPORARY;
                int st = odhs_network_add(net, i, j, kind);
                ck_assert_msg(st == ODHS_OK, "add(%zu,%zu) = %d", i, j, st);
                *s = kind == ODHS_CONTACT_PERMANENT ? 2 : 1;
                count++;
                /* adding again (either order) fails */
                ck_assert_int_eq(odhs_network_add(net, j, i, ODHS_CONTACT_TEMPORARY), ODHS_E_INVALID);
            }
            ck_assert_uint_eq(odhs_network_count(net), count);
            if (op % 1000 == 999) hash_full_check(net, state, n, count, 0, &rng);
        }
        hash_full_check(net, state, n, count, 1, &rng);
        if (phase == 1) ck_assert_msg(count > 3000, "only %zu contacts after phase 1", count);
    }
    /* phase 3 */
    size_t(*list)[2] = malloc((count + 1) * sizeof *list);
    ck_assert_ptr_nonnull(list);
    size_t m = 0;
    for (size_t a = 0; a < n; ++a)
        for (size_t b = a + 1; b < n; ++b)
            if (state[a * n + b]) {
                list[m][0] = a;
                list[m][1] = b;
                m++;
            }
    ck_assert_uint_eq(m, count);
    for (size_t k = m; k > 1; --k) {
        size_t q = tu_index(&rng, k), t0 = list[k - 1][0], t1 = list[k - 1][1];
        list[k - 1][0] = list[q][0];
        list[k - 1][1] = list[q][1];
        list[q][0] = t0;
        list[q][1] = t1;
    }
    for (size_t k = 0; k < m; ++k) {
        size_t a = list[k][0], b = list[k][1];
        int st = (k % 2) ? odhs_network_remove(net, a, b) : odhs_network_remove(net, b, a);
        ck_assert_msg(st == ODHS_OK, "remove(%zu,%zu) = %d", a, b, st);
        state[a * n + b] = 0;
        count--;
        if (k % 500 == 0) hash_full_check(net, state, n, count, 0, &rng);
    }
    hash_full_check(net, state, n, 0, 1, &rng);

    /* clear after refilling */
    for (size_t k = 0; k < 300; ++k) {
        size_t a = list[k][0], b = list[k][1];
        ck_assert_int_eq(odhs_network_add(net, a, b, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    }
    ck_assert_uint_eq(odhs_network_count(net), 300);
    ck_assert_int_eq(odhs_network_clear(net), ODHS_OK);
    ck_assert_uint_eq(odhs_network_count(net), 0);
    for (size_t k = 0; k < 300; ++k) {
        size_t idx;
        ck_assert_int_eq(odhs_network_find(net, list[k][0], list[k][1], &idx), ODHS_OK);
        ck_assert_uint_eq(idx, SIZE_MAX);
    }
    free(list);
    free(pool);
    free(state);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* error codes leave the network unchanged                                  */
/* ------------------------------------------------------------------------ */

typedef struct {
    size_t nc;
    size_t *ci, *cj;
    int *kind;
    double *f, *gap, *nrm;
} net_snap;

static void net_snap_take(const odhs_network *net, net_snap *s)
{
    int d = odhs_network_dim(net);
    s->nc = odhs_network_count(net);
    s->ci = malloc((s->nc + 1) * sizeof *s->ci);
    s->cj = malloc((s->nc + 1) * sizeof *s->cj);
    s->kind = malloc((s->nc + 1) * sizeof *s->kind);
    s->f = malloc((s->nc + 1) * sizeof *s->f);
    s->gap = malloc((s->nc + 1) * sizeof *s->gap);
    s->nrm = malloc((s->nc + 1) * d * sizeof *s->nrm);
    ck_assert(s->ci && s->cj && s->kind && s->f && s->gap && s->nrm);
    for (size_t k = 0; k < s->nc; ++k)
        ck_assert_int_eq(odhs_network_get_contact(net, k, &s->ci[k], &s->cj[k], &s->kind[k]), ODHS_OK);
    ck_assert_int_eq(odhs_network_get_forces(net, s->f), ODHS_OK);
    ck_assert_int_eq(odhs_network_get_gaps(net, s->gap), ODHS_OK);
    ck_assert_int_eq(odhs_network_get_normals(net, s->nrm), ODHS_OK);
}

static void net_snap_free(net_snap *s)
{
    free(s->ci);
    free(s->cj);
    free(s->kind);
    free(s->f);
    free(s->gap);
    free(s->nrm);
}

static int net_snap_matches(const odhs_network *net, const net_snap *s)
{
    net_snap now;
    net_snap_take(net, &now);
    int d = odhs_network_dim(net);
    int eq = now.nc == s->nc && !memcmp(now.ci, s->ci, s->nc * sizeof *s->ci) &&
             !memcmp(now.cj, s->cj, s->nc * sizeof *s->cj) && !memcmp(now.kind, s->kind, s->nc * sizeof *s->kind) &&
             !memcmp(now.f, s->f, s->nc * sizeof *s->f) && !memcmp(now.gap, s->gap, s->nc * sizeof *s->gap) &&
             !memcmp(now.nrm, s->nrm, s->nc * d * sizeof *s->nrm);
    for (size_t k = 0; eq && k < s->nc; ++k) {
        size_t idx;
        eq = odhs_network_find(net, s->ci[k], s->cj[k], &idx) == ODHS_OK && idx == k;
    }
    net_snap_free(&now);
    return eq;
}

#define NET_EXPECT_FAIL(net, code, call)                                                             \
    do {                                                                                             \
        net_snap snap_;                                                                              \
        net_snap_take((net), &snap_);                                                                \
        int st_ = (call);                                                                            \
        ck_assert_msg(st_ == (code), "%s returned %d (%s), expected %d (%s)", #call, st_,           \
                      odhs_strerror(st_), (int)(code), odhs_strerror(code));                         \
        ck_assert_msg(odhs_network_errmsg(net)[0] != '\0', "%s: empty error message", #call);       \
        ck_assert_msg(net_snap_matches((net), &snap_), "%s changed the network", #call);            \
        net_snap_free(&snap_);                                                                       \
    } while (0)

START_TEST(test_errors_leave_unchanged)
{
    const size_t n = 6;
    odhs_system *sys = net_new_sys(3, n);
    double L[3] = {10, 10, 10}, r[6] = {0.5, 0.5, 0.5, 0.5, 0.5, 0.5};
    double x[18] = {1, 1, 1, 2, 1, 1, 1, 2, 1, 1, 1, 2, 5, 5, 5, 5, 6.1, 5};
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
    odhs_network *net = net_new(sys);
    ck_assert_str_eq(odhs_network_errmsg(net), "");
    ck_assert_uint_eq(odhs_network_particles(net), n);
    ck_assert_int_eq(odhs_network_dim(net), 3);
    ck_assert_int_eq(odhs_network_add(net, 0, 1, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    ck_assert_int_eq(odhs_network_add(net, 2, 0, ODHS_CONTACT_PERMANENT), ODHS_OK);
    ck_assert_int_eq(odhs_network_add(net, 0, 3, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    ck_assert_int_eq(odhs_network_add(net, 5, 4, ODHS_CONTACT_TEMPORARY), ODHS_OK);
    ck_assert_int_eq(odhs_network_update_geometry(net, sys), ODHS_OK);
    double f[4] = {1.0, -0.5, 2.0, 0.25};
    ck_assert_int_eq(odhs_network_set_forces(net, f), ODHS_OK);

    NET_EXPECT_FAIL(net, ODHS_E_INVALID, odhs_network_add(net, 0, 1, ODHS_CONTACT_TEMPORARY));
    NET_EXPECT_FAIL(net, ODHS_E_INVALID, odhs_network_add(net, 1, 0, ODHS_CONTACT_TEMPORARY));
    NET_EXPECT_FAIL(net, ODHS_E_INVALID, odhs_network_add(net, 0, 2, ODHS_CONTACT_TEMPORARY));
    NET_EXPECT_FAIL(net, ODHS_E_INVALID, odhs_network_add(net, 3, 3, ODHS_CONTACT_TEMPORARY));
    NET_EXPECT_FAIL(net, ODHS_E_RANGE, odhs_network_add(net, 6, 1, ODHS_CONTACT_TEMPORARY));
    NET_EXPECT_FAIL(net, ODHS_E_RANGE, odhs_network_add(net, 1, 6, ODHS_CONTACT_TEMPORARY));
    NET_EXPECT_FAIL(net, ODHS_E_RANGE, odhs_network_add(net, 1, SIZE_MAX, ODHS_CONTACT_TEMPORARY));
    NET_EXPECT_FAIL(net, ODHS_E_INVALID, odhs_network_add(net, 1, 2, 2));
    NET_EXPECT_FAIL(net, ODHS_E_INVALID, odhs_network_add(net, 1, 2, -1));
    NET_EXPECT_FAIL(net, ODHS_E_INVALID, odhs_network_remove(net, 1, 2));
    NET_EXPECT_FAIL(net, ODHS_E_INVALID, odhs_network_remove(net, 4, 4));
    NET_EXPECT_FAIL(net, ODHS_E_RANGE, odhs_network_remove(net, 0, 6));
    size_t idx = 7;
    NET_EXPECT_FAIL(net, ODHS_E_RANGE, odhs_network_find(net, 9, 0, &idx));
    NET_EXPECT_FAIL(net, ODHS_E_NULL, odhs_network_find(net, 0, 1, NULL));
    size_t ci, cj;
    NET_EXPECT_FAIL(net, ODHS_E_RANGE, odhs_network_get_contact(net, 4, &ci, &cj, NULL));
    double bad[4] = {1.0, NAN, 0.0, 0.0};
    NET_EXPECT_FAIL(net, ODHS_E_NONFINITE, odhs_network_set_forces(net, bad));
    NET_EXPECT_FAIL(net, ODHS_E_INVALID, odhs_network_detect(net, sys, -0.1));
    NET_EXPECT_FAIL(net, ODHS_E_INVALID, odhs_network_detect(net, sys, NAN));
    NET_EXPECT_FAIL(net, ODHS_E_NULL, odhs_network_detect(net, NULL, 0.1));
    NET_EXPECT_FAIL(net, ODHS_E_NULL, odhs_network_update_geometry(net, NULL));
    {
        /* a system of another size or dimension */
        odhs_system *other = net_new_sys(3, n + 1);
        NET_EXPECT_FAIL(net, ODHS_E_DIM, odhs_network_update_geometry(net, other));
        odhs_system_destroy(other);
        other = net_new_sys(2, n);
        NET_EXPECT_FAIL(net, ODHS_E_DIM, odhs_network_detect(net, other, 0.1));
        odhs_system_destroy(other);
        /* right size, positions unset */
        other = net_new_sys(3, n);
        NET_EXPECT_FAIL(net, ODHS_E_STATE, odhs_network_update_geometry(net, other));
        odhs_system_destroy(other);
    }

    /* NULL handles */
    ck_assert_int_eq(odhs_network_add(NULL, 0, 1, 0), ODHS_E_NULL);
    ck_assert_int_eq(odhs_network_remove(NULL, 0, 1), ODHS_E_NULL);
    ck_assert_int_eq(odhs_network_find(NULL, 0, 1, &idx), ODHS_E_NULL);
    ck_assert_int_eq(odhs_network_clear(NULL), ODHS_E_NULL);
    ck_assert_uint_eq(odhs_network_count(NULL), 0);
    ck_assert_str_eq(odhs_network_errmsg(NULL), "");
    odhs_network_destroy(NULL);
    odhs_network *o = (odhs_network *)&idx;
    ck_assert_int_eq(odhs_network_create(NULL, &o), ODHS_E_NULL);
    ck_assert_ptr_null(o);
    ck_assert_int_eq(odhs_network_create(sys, NULL), ODHS_E_NULL);

    /* the successful calls still work afterwards, kinds and forces kept */
    ck_assert_int_eq(odhs_network_find(net, 2, 0, &idx), ODHS_OK);
    ck_assert_uint_eq(idx, 1);
    int kind;
    ck_assert_int_eq(odhs_network_get_contact(net, idx, &ci, &cj, &kind), ODHS_OK);
    ck_assert_uint_eq(ci, 0);
    ck_assert_uint_eq(cj, 2);
    ck_assert_int_eq(kind, ODHS_CONTACT_PERMANENT);
    double fo[4];
    ck_assert_int_eq(odhs_network_get_forces(net, fo), ODHS_OK);
    for (int k = 0; k < 4; ++k) ck_assert(fo[k] == f[k]);
    /* removal moves the last contact into the hole; its force follows it */
    ck_assert_int_eq(odhs_network_remove(net, 0, 1), ODHS_OK);
    ck_assert_uint_eq(odhs_network_count(net), 3);
    ck_assert_int_eq(odhs_network_find(net, 4, 5, &idx), ODHS_OK);
    ck_assert_uint_lt(idx, 3);
    ck_assert_int_eq(odhs_network_get_forces(net, fo), ODHS_OK);
    ck_assert(fo[idx] == 0.25);
    ck_assert_int_eq(odhs_network_find(net, 0, 1, &idx), ODHS_OK);
    ck_assert_uint_eq(idx, SIZE_MAX);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* detection against brute force                                            */
/* ------------------------------------------------------------------------ */

static void check_detect_case(int dim, double gamma, uint64_t seed)
{
    const size_t n = dim == 2 ? 120 : 150;
    double L[3] = {8.5, 8.0, 7.5};
    if (dim == 2) {
        L[0] = 18.0;
        L[1] = 17.0;
    }
    double *x = malloc(n * dim * sizeof *x), *r = malloc(n * sizeof *r);
    ck_assert(x && r);
    odhs_system *sys = net_random_system(dim, n, L, gamma, 0.4, 0.75, seed, x, r);
    double *bgap = malloc(n * n * sizeof *bgap);
    ck_assert_ptr_nonnull(bgap);
    for (size_t i = 0; i < n; ++i)
        for (size_t j = i + 1; j < n; ++j) {
            double nrm[3];
            bgap[i * n + j] = net_brute_normal(dim, L, gamma, x, i, j, nrm) - (r[i] + r[j]);
        }
    odhs_network *net = net_new(sys);
    const double tols[4] = {0.01, 0.05, 0.2, 0.35};
    size_t prev = 0;
    for (int t = 0; t < 4; ++t) {
        double tol = tols[t];
        ck_assert_int_eq(odhs_network_detect(net, sys, tol), ODHS_OK);
        size_t nc = odhs_network_count(net), expect = 0, found = 0;
        ck_assert_msg(nc >= prev, "detect with a larger tolerance lost contacts");
        prev = nc;
        for (size_t i = 0; i < n; ++i)
            for (size_t j = i + 1; j < n; ++j) {
                double thr = tol * (r[i] + r[j]), g = bgap[i * n + j];
                size_t idx;
                ck_assert_int_eq(odhs_network_find(net, i, j, &idx), ODHS_OK);
                int in = idx != SIZE_MAX;
                found += in;
                if (fabs(g - thr) < 1e-12) continue; /* round-off decides */
                expect += g <= thr;
                ck_assert_msg(in == (g <= thr), "pair (%zu,%zu), gap %.17g, threshold %.17g: detected %d", i, j, g,
                              thr, in);
            }
        ck_assert_uint_eq(found, nc);
        ck_assert_msg(expect > 0 || t == 0, "no pairs within tol %g: vacuous", tol);
        if (t == 3) ck_assert_msg(expect > n / 2, "only %zu pairs at tol %g", expect, tol);
        /* geometry was updated: gaps match brute force */
        double *gap = malloc((nc + 1) * sizeof *gap);
        ck_assert_ptr_nonnull(gap);
        ck_assert_int_eq(odhs_network_get_gaps(net, gap), ODHS_OK);
        for (size_t k = 0; k < nc; ++k) {
            size_t i, j;
            int kind;
            odhs_network_get_contact(net, k, &i, &j, &kind);
            ck_assert_int_eq(kind, ODHS_CONTACT_TEMPORARY);
            ck_assert_msg(fabs(gap[k] - bgap[i * n + j]) <= 1e-12, "gap (%zu,%zu): %.17g vs %.17g", i, j, gap[k],
                          bgap[i * n + j]);
        }
        free(gap);
        /* coordination z = 2 Nc / N */
        double z = -1.0;
        ck_assert_int_eq(odhs_network_coordination(net, &z), ODHS_OK);
        ck_assert_msg(fabs(z - 2.0 * (double)nc / (double)n) <= 1e-15, "z = %.17g, 2Nc/N = %.17g", z,
                      2.0 * (double)nc / (double)n);
    }
    /* detecting again adds nothing; existing contacts (and their kind) survive
     * a detection with a smaller tolerance */
    size_t nc = odhs_network_count(net);
    ck_assert_int_eq(odhs_network_detect(net, sys, 0.35), ODHS_OK);
    ck_assert_uint_eq(odhs_network_count(net), nc);
    ck_assert_int_eq(odhs_network_detect(net, sys, 0.0), ODHS_OK);
    ck_assert_uint_eq(odhs_network_count(net), nc);
    /* a far-away permanent bond is kept and detect does not duplicate it */
    size_t fi = SIZE_MAX, fj = SIZE_MAX;
    for (size_t i = 0; i < n && fi == SIZE_MAX; ++i)
        for (size_t j = i + 1; j < n; ++j)
            if (bgap[i * n + j] > 1.0) {
                fi = i;
                fj = j;
                break;
            }
    ck_assert(fi != SIZE_MAX);
    ck_assert_int_eq(odhs_network_add(net, fi, fj, ODHS_CONTACT_PERMANENT), ODHS_OK);
    ck_assert_int_eq(odhs_network_detect(net, sys, 0.35), ODHS_OK);
    ck_assert_uint_eq(odhs_network_count(net), nc + 1);
    size_t idx;
    int kind;
    ck_assert_int_eq(odhs_network_find(net, fi, fj, &idx), ODHS_OK);
    ck_assert_int_eq(odhs_network_get_contact(net, idx, NULL, NULL, &kind), ODHS_OK);
    ck_assert_int_eq(kind, ODHS_CONTACT_PERMANENT);
    free(bgap);
    free(x);
    free(r);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}

START_TEST(test_detect_brute_2d)
{
    check_detect_case(2, 0.0, 101);
    check_detect_case(2, 0.37, 102);
    check_detect_case(2, -0.5, 103);
}
END_TEST

START_TEST(test_detect_brute_3d)
{
    check_detect_case(3, 0.0, 201);
    check_detect_case(3, 0.21, 202);
}
END_TEST

/* exactly touching pairs are contacts at tol = 0, also across the boundary */
START_TEST(test_detect_touching)
{
    odhs_system *sys = net_new_sys(2, 4);
    double L[2] = {8.0, 8.0}, r[4] = {0.5, 0.25, 0.5, 0.5};
    /* 0-1 touch (gap 0), 2 at x=0.5 touches 3 at x=7.5 through the boundary,
     * 0-2 are 0.5 apart */
    double x[8] = {2.0, 4.0, 2.75, 4.0, 0.5, 1.0, 7.5, 1.0};
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
    odhs_network *net = net_new(sys);
    ck_assert_int_eq(odhs_network_detect(net, sys, 0.0), ODHS_OK);
    ck_assert_uint_eq(odhs_network_count(net), 2);
    size_t idx;
    ck_assert_int_eq(odhs_network_find(net, 1, 0, &idx), ODHS_OK);
    ck_assert_uint_ne(idx, SIZE_MAX);
    ck_assert_int_eq(odhs_network_find(net, 3, 2, &idx), ODHS_OK);
    ck_assert_uint_ne(idx, SIZE_MAX);
    double nrm[4];
    ck_assert_int_eq(odhs_network_get_normals(net, nrm), ODHS_OK);
    /* n_23 = (R3 - R2)/r through the boundary = (-1, 0) */
    ck_assert_double_eq_tol(nrm[idx * 2 + 0], -1.0, 1e-15);
    ck_assert_double_eq_tol(nrm[idx * 2 + 1], 0.0, 1e-15);
    double z;
    ck_assert_int_eq(odhs_network_coordination(net, &z), ODHS_OK);
    ck_assert_double_eq_tol(z, 1.0, 1e-15);
    ck_assert_int_eq(odhs_network_coordination(net, NULL), ODHS_E_NULL);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* ------------------------------------------------------------------------ */
/* constrained subset                                                        */
/* ------------------------------------------------------------------------ */

/* Brute-force iterative removal on bodies: bodies are the connected
 * components of the permanent contacts (found by repeated relabelling), a
 * body of k particles with q internal contacts has dof = max(d k - q, lo)
 * (lo = d for k = 1, else 3 in 2D, 5 for a 3D dimer, 6 in 3D) and is dropped
 * while it has fewer than dof + 1 contacts to other surviving bodies; with no
 * permanent contact this is the (d+1)-core of the particles. */
static void brute_constrained(int dim, size_t n, size_t m, const size_t (*e)[2], const int *kind,
                              unsigned char *alive, size_t *nbar, size_t *ncon)
{
    size_t *lab = malloc(n * sizeof *lab), *kb = calloc(n, sizeof *kb), *inner = calloc(n, sizeof *inner);
    size_t *cnt = malloc(n * sizeof *cnt);
    ck_assert(lab && kb && inner && cnt);
    for (size_t i = 0; i < n; ++i) lab[i] = i;
    for (int changed = 1; changed;) {
        changed = 0;
        for (size_t k = 0; k < m; ++k) {
            if (kind[k] != ODHS_CONTACT_PERMANENT) continue;
            size_t a = lab[e[k][0]], b = lab[e[k][1]], lo = a < b ? a : b;
            for (size_t i = 0; i < n; ++i)
                if ((lab[i] == a || lab[i] == b) && lab[i] != lo) {
                    lab[i] = lo;
                    changed = 1;
                }
        }
    }
    for (size_t i = 0; i < n; ++i) kb[lab[i]]++;
    for (size_t k = 0; k < m; ++k)
        if (lab[e[k][0]] == lab[e[k][1]]) inner[lab[e[k][0]]]++;
    for (size_t i = 0; i < n; ++i) alive[i] = 1;
    int changed = 1;
    while (changed) {
        changed = 0;
        for (size_t i = 0; i < n; ++i) cnt[i] = 0;
        for (size_t k = 0; k < m; ++k) {
            size_t a = lab[e[k][0]], b = lab[e[k][1]];
            if (a != b && alive[e[k][0]] && alive[e[k][1]]) {
                cnt[a]++;
                cnt[b]++;
            }
        }
        for (size_t b = 0; b < n; ++b) {
            if (!kb[b] || !alive[b]) continue;
            size_t d = (size_t)dim, k = kb[b], lo = k == 1 ? d : (d == 2 ? 3 : (k == 2 ? 5 : 6));
            size_t f = d * k > inner[b] ? d * k - inner[b] : 0;
            if (f < lo) f = lo;
            if (cnt[b] < f + 1) {
                for (size_t i = 0; i < n; ++i)
                    if (lab[i] == b) alive[i] = 0;
                changed = 1;
            }
        }
    }
    *nbar = 0;
    *ncon = 0;
    for (size_t i = 0; i < n; ++i) *nbar += alive[i];
    for (size_t k = 0; k < m; ++k) *ncon += alive[e[k][0]] && alive[e[k][1]];
    free(lab);
    free(kb);
    free(inner);
    free(cnt);
}

/* compare the library with brute force on the network's own contacts;
 * returns nbar, stores ncon and the jammed flag */
static size_t check_constrained(const odhs_network *net, size_t *ncon_out, int *flag_out)
{
    size_t n = odhs_network_particles(net), nc = odhs_network_count(net);
    int d = odhs_network_dim(net);
    size_t(*e)[2] = malloc((nc + 1) * sizeof *e);
    int *kind = malloc((nc + 1) * sizeof *kind);
    unsigned char *alive = malloc(n), *lib = malloc(n);
    ck_assert(e && kind && alive && lib);
    for (size_t k = 0; k < nc; ++k)
        ck_assert_int_eq(odhs_network_get_contact(net, k, &e[k][0], &e[k][1], &kind[k]), 0);
    size_t nbar, ncon;
    brute_constrained(d, n, nc, (const size_t(*)[2])e, kind, alive, &nbar, &ncon);

    size_t lnbar = 12345, lncon = 12345;
    long zn = -12345;
    memset(lib, 7, n);
    ck_assert_int_eq(odhs_network_constrained(net, &lnbar, &lncon, lib, &zn), ODHS_OK);
    ck_assert_msg(lnbar == nbar, "Nbar = %zu, brute force %zu", lnbar, nbar);
    ck_assert_msg(lncon == ncon, "Ncon = %zu, brute force %zu", lncon, ncon);
    for (size_t i = 0; i < n; ++i)
        ck_assert_msg(lib[i] == alive[i], "particle %zu: in_subset = %d, brute force %d", i, lib[i], alive[i]);
    if (nbar > 0) {
        /* eq. (29): zbar * Nbar = 2(d-1) + sum_i zbar_i = 2(d-1) + 2 Ncon */
        ck_assert_msg(zn == 2L * (d - 1) + 2L * (long)ncon, "zbar_num = %ld, expected %ld", zn,
                      2L * (d - 1) + 2L * (long)ncon);
    } else {
        ck_assert_msg(zn == 0 || zn == 2L * (d - 1), "zbar_num = %ld for an empty subset", zn);
    }
    /* the outputs are optional */
    size_t only;
    ck_assert_int_eq(odhs_network_constrained(net, &only, NULL, NULL, NULL), ODHS_OK);
    ck_assert_uint_eq(only, nbar);
    ck_assert_int_eq(odhs_network_constrained(net, NULL, NULL, NULL, NULL), ODHS_OK);

    /* potentially jammed: Ncon >= d (Nbar - 1) + 1, integers, non-empty subset */
    int expect = nbar > 0 && ncon >= (size_t)d * (nbar - 1) + 1;
    int flag = -1;
    ck_assert_int_eq(odhs_network_potentially_jammed(net, &flag), ODHS_OK);
    ck_assert_msg(flag == expect, "potentially_jammed = %d, expected %d (Nbar %zu, Ncon %zu, d %d)", flag, expect,
                  nbar, ncon, d);
    if (nbar > 0) {
        /* the same in terms of zbar >= 2d */
        ck_assert_int_eq(flag, zn >= 2L * d * (long)nbar);
    }
    /* rattlers: exactly the particles outside the constrained subset */
    {
        unsigned char *rat = malloc(n);
        ck_assert_ptr_nonnull(rat);
        memset(rat, 7, n);
        size_t nrat = 12345;
        ck_assert_int_eq(odhs_network_rattlers(net, rat, &nrat), ODHS_OK);
        ck_assert_uint_eq(nrat, n - nbar);
        for (size_t i = 0; i < n; ++i)
            ck_assert_msg(rat[i] == !alive[i], "particle %zu: is_rattler = %d, in subset %d", i, rat[i], alive[i]);
        ck_assert_int_eq(odhs_network_rattlers(net, NULL, &nrat), ODHS_OK);
        ck_assert_uint_eq(nrat, n - nbar);
        ck_assert_int_eq(odhs_network_rattlers(net, rat, NULL), ODHS_OK);
        free(rat);
    }
    if (ncon_out) *ncon_out = ncon;
    if (flag_out) *flag_out = flag;
    free(e);
    free(kind);
    free(alive);
    free(lib);
    return nbar;
}

START_TEST(test_constrained_triangle)
{
    /* three touching discs: each has 2 < d+1 = 3 contacts */
    odhs_system *sys = net_new_sys(2, 3);
    double L[2] = {10, 10}, r[3] = {0.5, 0.5, 0.5};
    double x[6] = {5.0, 5.0, 6.0, 5.0, 5.5, 5.0 + sqrt(3.0) / 2.0};
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
    odhs_network *net = net_new(sys);
    ck_assert_int_eq(odhs_network_detect(net, sys, 1e-9), ODHS_OK);
    ck_assert_uint_eq(odhs_network_count(net), 3);
    size_t nbar = 99, ncon = 99;
    unsigned char in[3] = {1, 1, 1};
    ck_assert_int_eq(odhs_network_constrained(net, &nbar, &ncon, in, NULL), ODHS_OK);
    ck_assert_uint_eq(nbar, 0);
    ck_assert_uint_eq(ncon, 0);
    for (int i = 0; i < 3; ++i) ck_assert_uint_eq(in[i], 0);
    int flag = -1;
    ck_assert_int_eq(odhs_network_potentially_jammed(net, &flag), ODHS_OK);
    ck_assert_int_eq(flag, 0);
    check_constrained(net, NULL, NULL);
    ck_assert_int_eq(odhs_network_constrained(NULL, &nbar, NULL, NULL, NULL), ODHS_E_NULL);
    ck_assert_int_eq(odhs_network_potentially_jammed(NULL, &flag), ODHS_E_NULL);
    ck_assert_int_eq(odhs_network_potentially_jammed(net, NULL), ODHS_E_NULL);
    size_t nr = 0;
    ck_assert_int_eq(odhs_network_rattlers(NULL, in, &nr), ODHS_E_NULL);
    ck_assert_int_eq(odhs_network_rattlers(net, in, &nr), ODHS_OK);
    ck_assert_uint_eq(nr, 3); /* all three are rattlers */
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

START_TEST(test_constrained_star)
{
    /* particle 0 has 3 contacts in 2D, but its partners have only 1 each:
     * removing them leaves 0 with none. Also a 3D star with 4 arms. */
    for (int dim = 2; dim <= 3; ++dim) {
        size_t n = (size_t)dim + 2;
        odhs_system *sys = net_new_sys(dim, n);
        odhs_network *net = net_new(sys);
        for (size_t k = 1; k <= (size_t)dim + 1; ++k)
            ck_assert_int_eq(odhs_network_add(net, 0, k, ODHS_CONTACT_TEMPORARY), ODHS_OK);
        /* plus a chain among the leaves so that each leaf has 2 (< 3) in 2D */
        if (dim == 2) ck_assert_int_eq(odhs_network_add(net, 1, 2, ODHS_CONTACT_PERMANENT), ODHS_OK);
        size_t nbar = 99, ncon = 99;
        unsigned char in[5];
        memset(in, 1, sizeof in);
        ck_assert_int_eq(odhs_network_constrained(net, &nbar, &ncon, in, NULL), ODHS_OK);
        ck_assert_uint_eq(nbar, 0);
        ck_assert_uint_eq(ncon, 0);
        for (size_t i = 0; i < n; ++i) ck_assert_uint_eq(in[i], 0);
        check_constrained(net, NULL, NULL);
        odhs_network_destroy(net);
        odhs_system_destroy(sys);
    }
}
END_TEST

/* A hexagonal patch of 7 identical discs (each ring disc touches the centre
 * and two ring neighbours: 3 >= d+1 contacts inside), a disc touching two
 * ring discs from outside (loosely connected) and a rattler. */
START_TEST(test_constrained_hex_patch)
{
    const size_t n = 9;
    odhs_system *sys = net_new_sys(2, n);
    double L[2] = {12, 12}, r[9], x[18];
    for (size_t i = 0; i < n; ++i) r[i] = 0.5;
    x[0] = 6.0;
    x[1] = 6.0;
    for (int k = 0; k < 6; ++k) {
        x[2 * (k + 1)] = 6.0 + cos(k * TU_PI / 3.0);
        x[2 * (k + 1) + 1] = 6.0 + sin(k * TU_PI / 3.0);
    }
    /* outer disc at centre + e_0 + e_1: touches ring discs 1 and 2 */
    x[14] = 6.0 + 1.0 + cos(TU_PI / 3.0);
    x[15] = 6.0 + sin(TU_PI / 3.0);
    x[16] = 1.0; /* rattler */
    x[17] = 1.0;
    ck_assert_int_eq(odhs_system_set_configuration(sys, L, 0.0, r, x), ODHS_OK);
    odhs_network *net = net_new(sys);
    ck_assert_int_eq(odhs_network_detect(net, sys, 1e-9), ODHS_OK);
    ck_assert_uint_eq(odhs_network_count(net), 14);
    size_t nbar, ncon;
    long zn;
    unsigned char in[9];
    ck_assert_int_eq(odhs_network_constrained(net, &nbar, &ncon, in, &zn), ODHS_OK);
    ck_assert_uint_eq(nbar, 7);
    ck_assert_uint_eq(ncon, 12);
    ck_assert_int_eq(zn, 2 * 1 + 2 * 12); /* zbar = 26/7 < 2d = 4 */
    for (size_t i = 0; i < 7; ++i) ck_assert_uint_eq(in[i], 1);
    ck_assert_uint_eq(in[7], 0);
    ck_assert_uint_eq(in[8], 0);
    int flag = -1;
    ck_assert_int_eq(odhs_network_potentially_jammed(net, &flag), ODHS_OK);
    ck_assert_int_eq(flag, 0); /* 12 < d(Nbar-1)+1 = 13 */
    /* one more (permanent) bond inside the patch: Ncon = 13 = d(Nbar-1)+1 */
    ck_assert_int_eq(odhs_network_add(net, 1, 4, ODHS_CONTACT_PERMANENT), ODHS_OK);
    ck_assert_int_eq(odhs_network_potentially_jammed(net, &flag), ODHS_OK);
    ck_assert_int_eq(flag, 1);
    check_constrained(net, NULL, NULL);
    /* bonding the outer disc to a third patch disc brings it in */
    ck_assert_int_eq(odhs_network_add(net, 7, 0, ODHS_CONTACT_PERMANENT), ODHS_OK);
    ck_assert_int_eq(odhs_network_constrained(net, &nbar, &ncon, in, &zn), ODHS_OK);
    ck_assert_uint_eq(nbar, 8);
    ck_assert_uint_eq(ncon, 16);
    ck_assert_uint_eq(in[7], 1);
    ck_assert_uint_eq(in[8], 0);
    check_constrained(net, NULL, NULL);
    odhs_network_destroy(net);
    odhs_system_destroy(sys);
}
END_TEST

/* complete graphs with a few edges removed pin the jamming threshold:
 * 2D, Nbar = 5: jammed iff Ncon >= 9; 3D, Nbar = 7: jammed iff Ncon >= 19 */
START_TEST(test_constrained_threshold)
{
    for (int dim = 2; dim <= 3; ++dim) {
        size_t m = dim == 2 ? 5 : 7, full = m * (m - 1) / 2;
        size_t thr = (size_t)dim * (m - 1) + 1;
        for (size_t drop = 0; drop <= (dim == 2 ? 2u : 3u); ++drop) {
            odhs_system *sys = net_new_sys(dim, m + 1); /* + one isolated particle */
            odhs_network *net = net_new(sys);
            for (size_t i = 0; i < m; ++i)
                for (size_t j = i + 1; j < m; ++j) {
                    /* drop disjoint edges (0,1), (2,3), (4,5) */
                    if (j == i + 1 && i % 2 == 0 && i / 2 < drop) continue;
                    ck_assert_int_eq(odhs_network_add(net, i, j, ODHS_CONTACT_TEMPORARY), ODHS_OK);
                }
            size_t nc = odhs_network_count(net), ncon;
            int flag;
            ck_assert_uint_eq(nc, full - drop);
            size_t nbar = check_constrained(net, &ncon, &flag);
            ck_assert_uint_eq(nbar, m);
            ck_assert_uint_eq(ncon, nc);
            ck_assert_int_eq(flag, nc >= thr);
            odhs_network_destroy(net);
            odhs_system_destroy(sys);
        }
    }
}
END_TEST

START_TEST(test_constrained_random_graphs)
{
    const size_t n = 30;
    tu_rng rng;
    tu_rng_seed(&rng, 4242);
    size_t n_empty = 0, n_partial = 0, n_full = 0, n_jammed = 0, n_unjammed_nonempty = 0;
    for (int dim = 2; dim <= 3; ++dim) {
        odhs_system *sys = net_new_sys(dim, n);
        for (int g = 0; g < 300; ++g) {
            odhs_network *net = net_new(sys);
            size_t target = tu_index(&rng, 160);
            /* sometimes a dense core on the first 10-15 nodes plus sparse rest */
            int cored = g % 3 == 0;
            size_t core = 8 + tu_index(&rng, 8);
            for (size_t t = 0; t < 20 * target + 10 && odhs_network_count(net) < target; ++t) {
                size_t i = tu_index(&rng, n), j = tu_index(&rng, n);
                if (cored && tu_uniform(&rng) < 0.7) {
                    i = tu_index(&rng, core);
                    j = tu_index(&rng, core);
                }
                if (i == j) continue;
                size_t idx;
                odhs_network_find(net, i, j, &idx);
                if (idx != SIZE_MAX) continue;
                /* one graph in four has bonds (composite bodies), one bond
                 * per eight contacts: the body-level subset */
                int kind = (g % 4 == 3 && tu_index(&rng, 8) == 0) ? ODHS_CONTACT_PERMANENT
                                                                       : ODHS_CONTACT_TEMPORARY;
                ck_assert_int_eq(odhs_network_add(net, i, j, kind), ODHS_OK);
            }
            size_t ncon;
            int flag;
            size_t nbar = check_constrained(net, &ncon, &flag);
            if (nbar == 0) n_empty++;
            else if (nbar < n) n_partial++;
            else n_full++;
            if (flag) n_jammed++;
            else if (nbar) n_unjammed_nonempty++;
            /* remove some contacts at random and check again */
            size_t nc = odhs_network_count(net);
            for (size_t k = 0; k < nc / 4; ++k) {
                size_t c = tu_index(&rng, odhs_network_count(net)), i, j;
                odhs_network_get_contact(net, c, &i, &j, NULL);
                ck_assert_int_eq(odhs_network_remove(net, i, j), ODHS_OK);
            }
            check_constrained(net, NULL, NULL);
            odhs_network_destroy(net);
        }
        odhs_system_destroy(sys);
    }
    ck_assert_msg(n_empty > 10 && n_partial > 10 && n_full > 5 && n_jammed > 5 && n_unjammed_nonempty > 5,
                  "random graphs do not cover all cases: empty %zu, partial %zu, full %zu, jammed %zu, "
                  "unjammed non-empty %zu",
                  n_empty, n_partial, n_full, n_jammed, n_unjammed_nonempty);
}
END_TEST

/* ------------------------------------------------------------------------ */

Suite *make_network_suite(void)
{
    Suite *s = suite_create("network");
    TCase *tc = tcase_create("operator");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_S_by_hand);
    tcase_add_test(tc, test_S_dense_2d);
    tcase_add_test(tc, test_S_dense_3d);
    suite_add_tcase(s, tc);

    tc = tcase_create("contacts");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_hash_stress);
    tcase_add_test(tc, test_errors_leave_unchanged);
    tcase_add_test(tc, test_detect_brute_2d);
    tcase_add_test(tc, test_detect_brute_3d);
    tcase_add_test(tc, test_detect_touching);
    suite_add_tcase(s, tc);

    tc = tcase_create("constrained");
    tcase_set_timeout(tc, 60);
    tcase_add_test(tc, test_constrained_triangle);
    tcase_add_test(tc, test_constrained_star);
    tcase_add_test(tc, test_constrained_hex_patch);
    tcase_add_test(tc, test_constrained_threshold);
    tcase_add_test(tc, test_constrained_random_graphs);
    suite_add_tcase(s, tc);
    return s;
}
