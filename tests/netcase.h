/*
 * libodhs - tests/netcase.h: contact networks on random polydisperse
 * configurations for the solver suites (check_spqr.c, check_auto.c), header
 * only. Needs check.h, math.h, string.h and testutil.h first.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#ifndef ODHS_TESTS_NETCASE_H
#define ODHS_TESTS_NETCASE_H

#define CK_OK(call)                                                                \
    do {                                                                           \
        int ck_st_ = (call);                                                       \
        ck_assert_msg(ck_st_ == ODHS_OK, "%s = %d (%s)", #call, ck_st_, odhs_strerror(ck_st_)); \
    } while (0)

static inline void *xcalloc(size_t n, size_t size)
{
    void *p = calloc(n ? n : 1, size);
    ck_assert_ptr_nonnull(p);
    return p;
}

typedef struct {
    odhs_system *sys;
    odhs_network *net;
    size_t n, nc, nd;
    int dim;
} tu_netcase;

static inline void tu_netcase_free(tu_netcase *c)
{
    odhs_network_destroy(c->net);
    odhs_system_destroy(c->sys);
    memset(c, 0, sizeof *c);
}

static inline void tu_netcase_refresh(tu_netcase *c)
{
    c->nc = odhs_network_count(c->net);
    c->n = odhs_network_particles(c->net);
    c->dim = odhs_network_dim(c->net);
    c->nd = c->n * (size_t)c->dim;
}

/* a system from L, r, x and an empty network on it */
static inline tu_netcase tu_netcase_make(int dim, size_t n, const double *L, double gamma, const double *r, const double *x)
{
    tu_netcase c;
    memset(&c, 0, sizeof c);
    CK_OK(odhs_system_create(dim, n, &c.sys));
    CK_OK(odhs_system_set_configuration(c.sys, L, gamma, r, x));
    CK_OK(odhs_network_create(c.sys, &c.net));
    tu_netcase_refresh(&c);
    return c;
}

static inline size_t tu_uf_find(size_t *p, size_t i)
{
    while (p[i] != i) {
        p[i] = p[p[i]];
        i = p[i];
    }
    return i;
}

/* Random polydisperse configuration under Lees-Edwards strain; contacts = a
 * random spanning forest of the pairs with gap <= maxgap (independent rows of
 * S: peel the leaves) plus `extra` pairs closing cycles (generic positions
 * keep S of full row rank). With extra = SIZE_MAX every near pair is a
 * contact (over-constrained networks). gamma: the Lees-Edwards strain. */
static inline tu_netcase tu_netcase_random(int dim, size_t n, uint64_t seed, size_t extra, double maxgap,
                                           double gamma)
{
    tu_rng rng;
    tu_rng_seed(&rng, seed);
    double *r = xcalloc(n, sizeof *r), *x = xcalloc(n * dim, sizeof *x), L[3], vol = 0.0;
    tu_radii_loguniform(n, 0.4, 0.7, r, &rng);
    for (size_t i = 0; i < n; ++i) vol += dim == 2 ? TU_PI * r[i] * r[i] : 4.0 / 3.0 * TU_PI * pow(r[i], 3);
    double side = dim == 2 ? sqrt(vol / 0.35) : cbrt(vol / 0.2);
    for (int k = 0; k < dim; ++k) L[k] = side * (1.0 + 0.05 * k);
    ck_assert_msg(tu_random_config(dim, n, L, gamma, r, 1e-9, x, &rng), "RSA failed");
    tu_netcase c = tu_netcase_make(dim, n, L, gamma, r, x);
    tu_pairlist pl;
    tu_brute_pairs(dim, n, x, r, L, gamma, maxgap, &pl);
    for (size_t k = pl.n; k > 1; --k) {
        size_t m = tu_index(&rng, k);
        tu_pair t = pl.p[k - 1];
        pl.p[k - 1] = pl.p[m];
        pl.p[m] = t;
    }
    size_t *par = xcalloc(n, sizeof *par), added = 0;
    for (size_t i = 0; i < n; ++i) par[i] = i;
    for (size_t k = 0; k < pl.n; ++k) {
        size_t a = tu_uf_find(par, pl.p[k].i), b = tu_uf_find(par, pl.p[k].j);
        if (a != b) par[a] = b;
        else if (added < extra) added++;
        else continue;
        CK_OK(odhs_network_add(c.net, pl.p[k].i, pl.p[k].j, ODHS_CONTACT_TEMPORARY));
    }
    CK_OK(odhs_network_update_geometry(c.net, c.sys));
    tu_netcase_refresh(&c);
    tu_pairlist_free(&pl);
    free(par);
    free(r);
    free(x);
    return c;
}

/* n 50:50 bidisperse discs (ratio 1.4, 3% polydispersity) placed at random at
 * phi = 0.45, compressed to phi by the event-driven stepper (dense solver) and
 * drift-corrected: a dense start for the solver suites' stepper runs */
static inline odhs_system *tu_compressed_discs(size_t n, uint64_t seed, double phi)
{
    odhs_system *base;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_stepper *st;
    CK_OK(odhs_system_create(2, n, &base));
    CK_OK(odhs_system_set_radii_bidisperse(base, 0.5, 1.4, 0.03, seed));
    CK_OK(odhs_system_place_random(base, 0.45, seed));
    CK_OK(odhs_driver_create(&drv));
    CK_OK(odhs_driver_set_compression_rate(drv, 1.0));
    CK_OK(odhs_solver_create_by_name("dense", &sol));
    CK_OK(odhs_stepper_create(base, drv, sol, &st));
    CK_OK(odhs_stepper_run_until_packing_fraction(st, phi));
    CK_OK(odhs_stepper_correct(st));
    odhs_stepper_destroy(st);
    odhs_solver_destroy(sol);
    odhs_driver_destroy(drv);
    return base;
}

#endif /* ODHS_TESTS_NETCASE_H */
