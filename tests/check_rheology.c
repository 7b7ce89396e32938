/*
 * libodhs - shear at fixed pressure flows at every finite pressure (the
 * mu(I_v) rheology of docs/rheology.md; issue 17).
 *
 * With the volume free, an isostatic network whose self-stress f0 is
 * positive is not jammed: it dilates (or compacts) with kappa set by the
 * geometry, <f0|b + a r> = 0, and its forces f = f_reg + alpha f0 carry the
 * pressure. Before 0.2.5 the stepper stopped there as "jammed", so at
 * p = 1000 every 2D N = 64 seed stopped below strain 0.05.
 *
 *  - "matrix": 2D N = 64 (seeds 1-6) and 3D N = 48 (seeds 1-3) at
 *    p = 10, 100, 1000, 1e4, sheared to ODHS_RHEO_STRAIN (default 0.1, to
 *    keep `make check` short; `make check-rheology` runs 2), with both
 *    integrators. Every step is
 *    checked independently through the public API: the pressure <f|r>/(Omega
 *    d) = p to 1e-9; forces >= 0 (-1e-12 of the largest); overlap <= 1e-12
 *    at the end of every step;
 *    every contact rigid, (S U)_c + (S V_aff)_c = 0 with the stepper's kappa,
 *    and the power balance D = Omega gdot (sigma_xy + d p kappa) (shear work
 *    plus the work of the pressure on the volume change), both to 1e-7 (they
 *    lose digits as p cond(N)). No step ends on a network with one contact
 *    more than isostatic; at p >= 1000 the runs visit isostatic networks and
 *    collisions on them answered by one opening.
 *  - "solvers": one scene at p = 1000 with every solver and both schemes.
 *  - "pjam": the jamming pressure: below it the isostatic network flows,
 *    at or above it the run ends ODHS_JAMMED with a certificate.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#define _POSIX_C_SOURCE 200809L
#include <check.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <unistd.h>

#include <odhs.h>

#define OK(call)                                                                                                   \
    do {                                                                                                           \
        int rc_ = (call);                                                                                          \
        ck_assert_msg(rc_ == ODHS_OK, "%s = %d (%s)", #call, rc_, odhs_strerror(rc_));                             \
    } while (0)

static void *xcalloc(size_t n, size_t s)
{
    void *p = calloc(n ? n : 1, s);
    ck_assert(p != NULL);
    return p;
}

typedef struct {
    int dim;
    size_t n;
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol, *fb;
    odhs_stepper *st;
} rscene;

/* the shear_flow scene: 50:50 bidisperse (1 : 1.4, 3 % polydisperse),
 * random at low density, compressed to phi0, then sheared at rate 1 and
 * fixed pressure p */
static void rscene_make(rscene *s, int dim, size_t n, uint64_t seed, const char *solver, int integrator, double p)
{
    memset(s, 0, sizeof *s);
    s->dim = dim;
    s->n = n;
    OK(odhs_system_create(dim, n, &s->sys));
    OK(odhs_system_set_radii_bidisperse(s->sys, 0.5, 1.4, 0.03, seed));
    OK(odhs_system_place_random(s->sys, dim == 2 ? 0.45 : 0.30, seed + 1));
    OK(odhs_solver_create_by_name(solver, &s->sol));
    if (!strcmp(solver, "cg")) {
        /* CG alone does not converge on the nearly singular networks of
         * p >= 1000: the documented remedy is a direct fallback */
        OK(odhs_solver_create_by_name("dense", &s->fb));
        OK(odhs_solver_set_fallback(s->sol, s->fb));
    }
    OK(odhs_driver_create(&s->drv));
    OK(odhs_driver_set_compression_rate(s->drv, 1.0));
    OK(odhs_stepper_create(s->sys, s->drv, s->sol, &s->st));
    OK(odhs_stepper_set_integrator(s->st, integrator));
    OK(odhs_stepper_run_until_packing_fraction(s->st, dim == 2 ? 0.80 : 0.60));
    OK(odhs_driver_set_compression_rate(s->drv, 0.0));
    OK(odhs_driver_set_shear_rate(s->drv, 1.0));
    OK(odhs_driver_set_pressure(s->drv, p));
}

static void rscene_free(rscene *s)
{
    odhs_stepper_destroy(s->st);
    odhs_driver_destroy(s->drv);
    odhs_solver_destroy(s->sol);
    odhs_solver_destroy(s->fb);
    odhs_system_destroy(s->sys);
}

/* network excess Ncon - d(Nbar - 1) of the constrained subset (1: isostatic) */
static long excess_of(const odhs_network *net, int dim)
{
    size_t nbar, ncon;
    OK(odhs_network_constrained(net, &nbar, &ncon, NULL, NULL));
    return nbar ? (long)ncon - (long)dim * ((long)nbar - 1) : 0;
}

typedef struct {
    long steps, iso_steps, over_steps, over_opened;
    double worst_p, worst_rig, worst_pow, fneg, overlap;
    double phi_min, phi_max, kappa_min, kappa_max;
    double strain;
    int rc;
    char msg[256];
} rstats;

/* the identities of one step (see the header) */
static void check_step(rscene *s, double p, rstats *r, double *U, double *rad)
{
    const odhs_network *net = odhs_stepper_network(s->st);
    int dim = s->dim;
    size_t m = odhs_network_count(net);
    double *f = xcalloc(m, sizeof *f), *gap = xcalloc(m, sizeof *gap), *nrm = xcalloc(3 * m, sizeof *nrm);
    OK(odhs_network_get_forces(net, f));
    OK(odhs_network_get_gaps(net, gap));
    OK(odhs_network_get_normals(net, nrm));
    OK(odhs_stepper_nonaffine_velocities(s->st, U));
    double kappa, vol, sxy, D, phi;
    OK(odhs_stepper_kappa(s->st, &kappa));
    OK(odhs_system_volume(s->sys, &vol));
    OK(odhs_stepper_shear_stress(s->st, &sxy));
    OK(odhs_stepper_dissipation(s->st, &D));
    OK(odhs_system_packing_fraction(s->sys, &phi));
    double fr = 0.0, fbig = 0.0, umax = 0.0;
    for (size_t c = 0; c < m; ++c) fbig = fmax(fbig, fabs(f[c]));
    for (size_t k = 0; k < s->n * (size_t)dim; ++k) umax = fmax(umax, fabs(U[k]));
    double vs = umax + (1.0 + fabs(kappa)) * 2.0 * 0.7;
    for (size_t c = 0; c < m; ++c) {
        size_t i, j;
        OK(odhs_network_get_contact(net, c, &i, &j, NULL));
        double dist = gap[c] + rad[i] + rad[j], su = 0.0;
        const double *nc = nrm + c * dim;
        fr += f[c] * dist;
        for (int k = 0; k < dim; ++k) su += (U[j * dim + k] - U[i * dim + k]) * nc[k];
        /* V_aff = G R, G = gdot (e_x e_y^T - kappa I): (S V_aff)_c = dist n.G n */
        double aff = dist * (nc[0] * nc[1] - kappa);
        r->worst_rig = fmax(r->worst_rig, fabs(su + aff) / vs);
        if (fbig > 0.0) r->fneg = fmin(r->fneg, f[c] / fbig);
    }
    if (m) r->worst_p = fmax(r->worst_p, fabs(fr / (dim * vol) - p) / p);
    /* shear and compression work against the dissipation */
    double W = vol * (sxy + dim * p * kappa), scale = vol * (fabs(sxy) + dim * p * fabs(kappa)) + D;
    if (m) r->worst_pow = fmax(r->worst_pow, fabs(W - D) / scale);
    r->phi_min = fmin(r->phi_min, phi);
    r->phi_max = fmax(r->phi_max, phi);
    r->kappa_min = fmin(r->kappa_min, kappa);
    r->kappa_max = fmax(r->kappa_max, kappa);
    free(f);
    free(gap);
    free(nrm);
}

/* shear s to `strain` at pressure p, step by step with the checks */
static void rscene_run(rscene *s, double p, double strain, rstats *r)
{
    memset(r, 0, sizeof *r);
    r->phi_min = r->kappa_min = INFINITY;
    r->phi_max = r->kappa_max = -INFINITY;
    size_t n = s->n;
    double *U = xcalloc(n * (size_t)s->dim, sizeof *U), *rad = xcalloc(n, sizeof *rad);
    OK(odhs_system_get_radii(s->sys, rad));
    double g0, g = 0.0;
    OK(odhs_stepper_strain(s->st, &g0));
    r->rc = ODHS_OK;
    long ex_before = excess_of(odhs_stepper_network(s->st), s->dim);
    while (g - g0 < strain) {
        uint64_t c0, o0, c1, o1, st0;
        OK(odhs_stepper_counts(s->st, &st0, &c0, &o0));
        r->rc = odhs_stepper_step(s->st, NULL);
        if (r->rc) {
            snprintf(r->msg, sizeof r->msg, "%s", odhs_stepper_errmsg(s->st));
            break;
        }
        r->steps++;
        OK(odhs_stepper_counts(s->st, &st0, &c1, &o1));
        long ex = excess_of(odhs_stepper_network(s->st), s->dim);
        if (ex == 1) r->iso_steps++;
        /* an isostatic network meeting one more contact is over-constrained
         * (it cannot flow at a finite rate): no step may end there, and the
         * typical case is one collision answered by exactly one opening */
        if (ex_before == 1 && c1 == c0 + 1) {
            r->over_steps++;
            if (o1 == o0 + 1 && ex == 1) r->over_opened++;
        }
        ck_assert_msg(ex <= 1, "step %ld ends with excess %ld", r->steps, ex);
        ex_before = ex;
        check_step(s, p, r, U, rad);
        double gap, ov;
        OK(odhs_stepper_errors(s->st, &gap, &ov));
        r->overlap = fmax(r->overlap, ov);
        OK(odhs_stepper_strain(s->st, &g));
    }
    r->strain = g - g0;
    free(U);
    free(rad);
}

static double rheo_strain(void)
{
    const char *e = getenv("ODHS_RHEO_STRAIN");
    double v = e ? atof(e) : 0.1;
    return v > 0.0 ? v : 0.1;
}

static const char *direct_solver(void)
{
    odhs_solver *probe = NULL;
    const char *name = odhs_solver_create_by_name("cholmod", &probe) == ODHS_OK ? "cholmod" : "dense";
    odhs_solver_destroy(probe);
    return name;
}

static void assert_flow(const rstats *r, const char *head, double strain, double p)
{
    fprintf(stderr,
            "[rheology] %s: strain %.3f, %ld steps (%ld isostatic; %ld collisions on one, %ld of them opened one), phi "
            "%.4f-%.4f, kappa %.3g..%.3g; pressure %.1e, rigidity %.1e, power %.1e, fneg %.1e, overlap %.1e\n",
            head, r->strain, r->steps, r->iso_steps, r->over_steps, r->over_opened, r->phi_min, r->phi_max,
            r->kappa_min, r->kappa_max, r->worst_p, r->worst_rig, r->worst_pow, r->fneg, r->overlap);
    ck_assert_msg(r->rc == ODHS_OK, "%s (p = %g): stopped at strain %.4f with %d (%s)", head, p, r->strain, r->rc,
                  r->msg);
    ck_assert_msg(r->strain >= strain, "%s: strain %.4f < %.4f", head, r->strain, strain);
    ck_assert_msg(r->worst_p <= 1e-9, "%s: pressure off by %.3g", head, r->worst_p);
    /* both lose digits as p cond(N): 5.5e-8 measured at p = 1e4 over strain 2 */
    ck_assert_msg(r->worst_rig <= 1e-7, "%s: contact rigidity off by %.3g", head, r->worst_rig);
    ck_assert_msg(r->worst_pow <= 1e-7, "%s: power balance off by %.3g", head, r->worst_pow);
    ck_assert_msg(r->fneg >= -1e-12, "%s: negative force %.3g", head, r->fneg);
    ck_assert_msg(r->overlap <= 1e-12, "%s: overlap %.3g", head, r->overlap);
    if (p >= 1000.0 && strain >= 0.1)
        ck_assert_msg(r->iso_steps > 0 && r->over_opened > 0,
                      "%s: %ld isostatic steps, %ld collision-opening pairs on them: the case is not exercised", head,
                      r->iso_steps, r->over_opened);
}

/* ---- the matrix ------------------------------------------------------------ */
static const struct {
    int dim;
    size_t n;
    uint64_t seed;
} mcases[] = {{2, 64, 1}, {2, 64, 2}, {2, 64, 3}, {2, 64, 4}, {2, 64, 5}, {2, 64, 6},
              {3, 48, 1}, {3, 48, 2}, {3, 48, 3}};
static const double mpress[] = {10.0, 100.0, 1000.0, 1e4};
#define NMP (sizeof mpress / sizeof mpress[0])

START_TEST(test_flow_matrix)
{
    int ci = _i / (int)NMP, pi = _i % (int)NMP;
    double p = mpress[pi], strain = rheo_strain();
    /* odd seeds: the paper's scheme; even seeds: the adaptive one */
    int integ = mcases[ci].seed % 2 ? ODHS_INTEGRATOR_EULER : ODHS_INTEGRATOR_HEUN;
    rscene s;
    rscene_make(&s, mcases[ci].dim, mcases[ci].n, mcases[ci].seed, direct_solver(), integ, p);
    rstats r;
    rscene_run(&s, p, strain, &r);
    char head[128];
    snprintf(head, sizeof head, "%dD N = %zu seed %llu p = %g %s", mcases[ci].dim, mcases[ci].n,
             (unsigned long long)mcases[ci].seed, p, integ == ODHS_INTEGRATOR_EULER ? "euler" : "heun");
    rscene_free(&s);
    assert_flow(&r, head, strain, p);
}
END_TEST

/* ---- every solver ------------------------------------------------------------ */
static const char *const solvers[] = {"dense", "cholmod", "spqr", "auto", "cg"};
#define NSOL (sizeof solvers / sizeof solvers[0])

START_TEST(test_every_solver)
{
    const char *name = solvers[_i / 2];
    int integ = _i % 2 ? ODHS_INTEGRATOR_HEUN : ODHS_INTEGRATOR_EULER;
    odhs_solver *probe = NULL;
    if (odhs_solver_create_by_name(name, &probe) != ODHS_OK) {
        fprintf(stderr, "[rheology] solver %s not built: skipped\n", name);
        return;
    }
    odhs_solver_destroy(probe);
    rscene s;
    rscene_make(&s, 2, 64, 3, name, integ, 1000.0);
    rstats r;
    double strain = fmin(0.1, rheo_strain()); /* shorter under the sanitizers */
    rscene_run(&s, 1000.0, strain, &r);
    char head[96];
    snprintf(head, sizeof head, "2D N = 64 seed 3 p = 1000 %s %s", name,
             integ == ODHS_INTEGRATOR_EULER ? "euler" : "heun");
    rscene_free(&s);
    assert_flow(&r, head, strain, 1000.0);
}
END_TEST

/* ---- the jamming pressure ------------------------------------------------------ */
/* The same scene and pressure twice: with p_jam = +inf (the default) it
 * flows through isostatic networks with positive f0; with p_jam <= p it
 * stops at the first one as ODHS_JAMMED, with a passing certificate, and
 * with p_jam > p it flows exactly as with +inf (identical strain, stress). */
START_TEST(test_jamming_pressure)
{
    const double p = 1000.0;
    double pj;
    rscene a, b, c;
    rscene_make(&a, 2, 64, 1, direct_solver(), ODHS_INTEGRATOR_EULER, p);
    OK(odhs_driver_get_jamming_pressure(a.drv, &pj));
    ck_assert_msg(isinf(pj) && pj > 0, "default jamming pressure %g", pj);
    rscene_make(&b, 2, 64, 1, direct_solver(), ODHS_INTEGRATOR_EULER, p);
    OK(odhs_driver_set_jamming_pressure(b.drv, p));
    rscene_make(&c, 2, 64, 1, direct_solver(), ODHS_INTEGRATOR_EULER, p);
    OK(odhs_driver_set_jamming_pressure(c.drv, 2.0 * p));
    rstats ra, rb, rc;
    rscene_run(&a, p, 0.2, &ra);
    rscene_run(&b, p, 0.2, &rb);
    rscene_run(&c, p, 0.2, &rc);
    double sa, sc;
    OK(odhs_stepper_shear_stress(a.st, &sa));
    OK(odhs_stepper_shear_stress(c.st, &sc));
    int cert_ok = 0;
    if (rb.rc == ODHS_JAMMED) {
        odhs_jam_certificate cert;
        cert.size = sizeof cert;
        OK(odhs_stepper_certificate(b.st, &cert));
        cert_ok = cert.isostatic && cert.min_force > 0.0 && cert.force_balance < 1e-10;
    }
    fprintf(stderr, "[rheology] p_jam: +inf flows to strain %.3f (%ld isostatic steps); p_jam = p stops at %.4f "
                    "with %d; p_jam = 2p flows to %.3f\n",
            ra.strain, ra.iso_steps, rb.strain, rb.rc, rc.strain);
    rscene_free(&a);
    rscene_free(&b);
    rscene_free(&c);
    assert_flow(&ra, "p_jam = inf", 0.2, p);
    ck_assert_msg(ra.iso_steps > 0, "no isostatic network visited: the test does not exercise the case");
    ck_assert_msg(rb.rc == ODHS_JAMMED, "p_jam = p: ended with %d (%s) at strain %.4f", rb.rc, rb.msg, rb.strain);
    ck_assert_msg(cert_ok, "p_jam = p: the certificate does not pass");
    ck_assert_msg(rc.rc == ODHS_OK && rc.strain == ra.strain && sc == sa,
                  "p_jam = 2p differs from +inf: strain %.17g vs %.17g, stress %.17g vs %.17g", rc.strain, ra.strain,
                  sc, sa);
}
END_TEST

/* bad input: NaN and negative jamming pressures are refused, the value kept */
START_TEST(test_jamming_pressure_input)
{
    odhs_driver *d;
    double v;
    OK(odhs_driver_create(&d));
    ck_assert_int_eq(odhs_driver_set_jamming_pressure(NULL, 1.0), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_get_jamming_pressure(NULL, &v), ODHS_E_NULL);
    ck_assert_int_eq(odhs_driver_get_jamming_pressure(d, NULL), ODHS_E_NULL);
    OK(odhs_driver_set_jamming_pressure(d, 5.0));
    ck_assert_int_eq(odhs_driver_set_jamming_pressure(d, NAN), ODHS_E_NONFINITE);
    ck_assert_int_eq(odhs_driver_set_jamming_pressure(d, -1.0), ODHS_E_INVALID);
    OK(odhs_driver_get_jamming_pressure(d, &v));
    ck_assert(v == 5.0);
    OK(odhs_driver_set_jamming_pressure(d, INFINITY));
    OK(odhs_driver_get_jamming_pressure(d, &v));
    ck_assert(isinf(v));
    odhs_driver_destroy(d);
}
END_TEST

/* the jamming pressure survives a checkpoint (section PJAM); the default
 * +inf writes no section, so such a checkpoint stays format version 1 */
START_TEST(test_jamming_pressure_checkpoint)
{
    char path[] = "/tmp/odhs_pjam_XXXXXX";
    int fd = mkstemp(path);
    ck_assert(fd >= 0);
    close(fd);
    const double values[] = {INFINITY, 0.0, 12.5};
    for (int k = 0; k < 3; ++k) {
        rscene s;
        rscene_make(&s, 2, 16, 7, "dense", ODHS_INTEGRATOR_EULER, 1.0);
        OK(odhs_driver_set_jamming_pressure(s.drv, values[k]));
        OK(odhs_stepper_run_until_strain(s.st, 0.01));
        OK(odhs_checkpoint_write(s.st, path));
        FILE *f = fopen(path, "rb");
        ck_assert(f != NULL);
        unsigned char head[12];
        ck_assert(fread(head, 1, sizeof head, f) == sizeof head);
        fclose(f);
        unsigned version = head[8] | (unsigned)head[9] << 8;
        odhs_system *sys2;
        odhs_driver *drv2;
        odhs_stepper *st2;
        char err[256];
        OK(odhs_checkpoint_read(path, s.sol, &sys2, &drv2, &st2, err, sizeof err));
        double v;
        OK(odhs_driver_get_jamming_pressure(drv2, &v));
        ck_assert_msg(v == values[k] || (isinf(v) && isinf(values[k])), "p_jam %g read back as %g", values[k], v);
        ck_assert_msg(isinf(values[k]) ? version == 1 : version == 2, "p_jam %g: format version %u", values[k],
                      version);
        odhs_stepper_destroy(st2);
        odhs_driver_destroy(drv2);
        odhs_system_destroy(sys2);
        rscene_free(&s);
    }
    remove(path);
}
END_TEST

/* A run split by a checkpoint continues bit for bit at p = 1000, through
 * flowing isostatic networks (the sparse f0 must not depend on the previous
 * step's choice of contact, which the checkpoint does not hold) */
START_TEST(test_checkpoint_continues)
{
    char path[] = "/tmp/odhs_rheo_ckpt_XXXXXX";
    int fd = mkstemp(path);
    ck_assert(fd >= 0);
    close(fd);
    rscene a;
    rscene_make(&a, 2, 64, 1, direct_solver(), ODHS_INTEGRATOR_EULER, 1000.0);
    double g0;
    OK(odhs_stepper_strain(a.st, &g0));
    OK(odhs_stepper_run_until_strain(a.st, g0 + 0.05));
    OK(odhs_checkpoint_write(a.st, path));
    odhs_solver *sol2;
    odhs_system *sys2;
    odhs_driver *drv2;
    odhs_stepper *st2;
    char err[256];
    OK(odhs_solver_create_by_name(direct_solver(), &sol2));
    OK(odhs_checkpoint_read(path, sol2, &sys2, &drv2, &st2, err, sizeof err));
    rstats r;
    rscene_run(&a, 1000.0, 0.1, &r);
    OK(odhs_stepper_run_until_strain(st2, g0 + 0.05 + r.strain));
    size_t n = 64;
    double *x1 = xcalloc(2 * n, sizeof *x1), *x2 = xcalloc(2 * n, sizeof *x2);
    OK(odhs_system_get_positions(a.sys, x1));
    OK(odhs_system_get_positions(sys2, x2));
    uint64_t s1, c1, o1, s2, c2, o2;
    OK(odhs_stepper_counts(a.st, &s1, &c1, &o1));
    OK(odhs_stepper_counts(st2, &s2, &c2, &o2));
    int same = !memcmp(x1, x2, 2 * n * sizeof *x1);
    fprintf(stderr,
            "[rheology] checkpoint at p = 1000: %ld steps after it (%ld isostatic), positions %s, events %llu / %llu\n",
            r.steps, r.iso_steps, same ? "bit-identical" : "DIFFER", (unsigned long long)(c1 + o1),
            (unsigned long long)(c2 + o2));
    free(x1);
    free(x2);
    odhs_stepper_destroy(st2);
    odhs_driver_destroy(drv2);
    odhs_system_destroy(sys2);
    odhs_solver_destroy(sol2);
    rscene_free(&a);
    remove(path);
    ck_assert_msg(r.rc == ODHS_OK && r.iso_steps > 0, "the run after the checkpoint: %d, %ld isostatic steps", r.rc,
                  r.iso_steps);
    ck_assert_msg(same && s1 == s2 && c1 == c2 && o1 == o2, "the restored run differs from the uninterrupted one");
}
END_TEST

Suite *make_rheology_suite(void)
{
    Suite *s = suite_create("rheology");
    TCase *tc = tcase_create("matrix");
    tcase_set_timeout(tc, 3600);
    tcase_add_loop_test(tc, test_flow_matrix, 0, (int)(NMP * (sizeof mcases / sizeof mcases[0])));
    suite_add_tcase(s, tc);
    tc = tcase_create("solvers");
    tcase_set_timeout(tc, 600);
    tcase_add_loop_test(tc, test_every_solver, 0, (int)(2 * NSOL));
    suite_add_tcase(s, tc);
    tc = tcase_create("pjam");
    tcase_set_timeout(tc, 600);
    tcase_add_test(tc, test_jamming_pressure);
    tcase_add_test(tc, test_jamming_pressure_input);
    tcase_add_test(tc, test_jamming_pressure_checkpoint);
    tcase_add_test(tc, test_checkpoint_continues);
    suite_add_tcase(s, tc);
    return s;
}
