/* libodhs - the fast route to a certified jammed packing (issue 22): a chain
 * of linear programmes brings the configuration to a jammed packing, and the
 * stepper's exact end game (rewiring, self-stress, polish, pivots:
 * lib/stepper/endgame.c) certifies it.
 *
 * Each programme linearises the contact constraints around the current
 * configuration x (the idea of Torquato & Jiao, PRE 82, 061302 (2010), and
 * of CALiPPSO, Artiaco, Diaz Hernandez Rojas, Parisi & Ricci-Tersenghi, PRE
 * 106, 055310 (2022)): with displacements s_i and a growth factor Gamma of
 * the squared contact distances,
 *
 *     maximise Gamma  subject to  |r_ij|^2 + 2 r_ij.(s_j - s_i) >= Gamma sigma_ij^2
 *                                 for every pair closer than the cut-off,
 *                                 |s_i,a| <= ell, s_0 = 0 (no translation).
 *
 * |r + ds|^2 = |r|^2 + 2 r.ds + |ds|^2 exceeds its linearisation, so a
 * solution never overlaps: the configuration moves by s and then grows by
 * the largest factor the real pairs allow (the box shrinks by 1/sqrt of
 * it). The cut-off makes every pair left out unable to touch: with
 * |s_i,a| <= ell a pair approaches by at most 2 ell sqrt(d), and Gamma is
 * bounded by (1 + 2 ell/sigma_min)^2. The chain ends when sqrt(Gamma) - 1 <
 * tol: the packing is then jammed to that precision (the programme's vertex
 * is the isostatic network, its dual the contact forces), and the stepper's
 * reset under compression takes the touching pairs as its network and
 * finishes exactly as a compression run ends.
 *
 * The programmes are solved by COIN-OR CLP's dual simplex, each one warm
 * started from the basis of the one before (pairs keep their status).
 */
#include <float.h>
#include <limits.h>
#include <stddef.h>
#include <math.h>
#include <stdlib.h>
#include <string.h>

#include "odhs/softcore.h"

#include "geom/geom.h"
#include "stepper/stepper.h"
#include "system/system.h"

#if ODHS_HAVE_CLP
#include <coin/Clp_C_Interface.h>
#endif

#define LP_TRUST 0.1        /* default bound on a displacement component, mean diameters */
#define LP_TOL 1e-12        /* default: the chain ends at sqrt(Gamma) - 1 below this */
#define LP_MAX 10000        /* default: programmes at most */
#define LP_STEPS 100000     /* default: event-driven steps of the end game at most */
#define LP_FEAS 1e-10       /* CLP's primal and dual feasibility tolerances */
#define LP_SHAKES 3         /* shakes of a degenerate packing at most */
#define LP_MIN_FORCE 1e-9   /* a backbone force below this (relative to the mean) is degenerate */
#define LP_GAP 5e-14        /* contact gaps (relative) above this get another polish ... */
#define LP_POLISHES 2       /* ... at most this many */
#define LP_QUENCH_PHI_2D 0.86 /* default packing fraction of the quench start, 2D */
#define LP_QUENCH_PHI_3D 0.66 /* ... and 3D */
#define LP_QUENCH_FORCE 1e-9  /* the quench's FIRE stops at this largest force ... */
#define LP_QUENCH_ITER 1000000 /* ... or after this many iterations */
#define LP_QUENCH_STEPS 20     /* rescalings of the quench toward phi_J at most ... */
#define LP_QUENCH_OVERLAP 3e-6 /* ... until the contacts' mean overlap (relative) is below this */
#define LP_QUENCH_FREL 1e-3    /* a relaxation after a rescaling stops at this fraction of the
                                * mean contact force, or at LP_QUENCH_FORCE if that is larger */

/* the fields of the options and the report the caller's size must cover */
#define LP_OPT_MIN (offsetof(odhs_jam_lp_options, max_steps) + sizeof(size_t))
#define LP_REP_MIN (offsetof(odhs_jam_lp_report, end_steps) + sizeof(uint64_t))

static int lp_settings(odhs_stepper *st, const odhs_jam_lp_options *opt, odhs_jam_lp_options *o)
{
    memset(o, 0, sizeof *o);
    if (opt) {
        if (opt->size < LP_OPT_MIN)
            return odhs__sterr(st, ODHS_E_INVALID,
                               "odhs_jam_lp_options.size = %zu: set it to sizeof(odhs_jam_lp_options) (at least %zu)",
                               opt->size, (size_t)LP_OPT_MIN);
        memcpy(o, opt, opt->size < sizeof *o ? opt->size : sizeof *o);
    }
    if (!isfinite(o->trust) || !isfinite(o->tol))
        return odhs__sterr(st, ODHS_E_NONFINITE, "jam_lp options: trust and tol must be finite");
    if (o->trust < 0.0 || o->tol < 0.0)
        return odhs__sterr(st, ODHS_E_INVALID, "jam_lp options: trust (%g) and tol (%g) must be >= 0 (0: default)",
                           o->trust, o->tol);
    if (o->trust > 0.5)
        return odhs__sterr(st, ODHS_E_INVALID,
                           "jam_lp options: trust %g is more than half a mean diameter per programme", o->trust);
    if (o->quench != 0 && o->quench != 1)
        return odhs__sterr(st, ODHS_E_INVALID, "jam_lp options: quench = %d (0: no quench, 1: quench start)", o->quench);
    if (!isfinite(o->quench_phi))
        return odhs__sterr(st, ODHS_E_NONFINITE, "jam_lp options: quench_phi must be finite");
    if (o->quench_phi < 0.0 || o->quench_phi >= 1.0)
        return odhs__sterr(st, ODHS_E_INVALID, "jam_lp options: quench_phi = %g must be in (0, 1) (0: default)",
                           o->quench_phi);
    if (o->own_integrator != 0 && o->own_integrator != 1)
        return odhs__sterr(st, ODHS_E_INVALID,
                           "jam_lp options: own_integrator = %d (0: batched steps in the end game, 1: the stepper's own)",
                           o->own_integrator);
    if (o->quench_phi == 0.0) o->quench_phi = st->dim == 2 ? LP_QUENCH_PHI_2D : LP_QUENCH_PHI_3D;
    if (o->trust == 0.0) o->trust = LP_TRUST;
    if (o->tol == 0.0) o->tol = LP_TOL;
    if (o->max_lps == 0) o->max_lps = LP_MAX;
    if (o->max_steps == 0) o->max_steps = LP_STEPS;
    return ODHS_OK;
}

#if ODHS_HAVE_CLP
/* The end game's integrator (odhs_jam_lp_options.own_integrator = 0): the
 * batched-event step at its own defaults, the stepper's settings kept here
 * and put back when the call returns. Near jamming a chain's packing that
 * is not yet jammed at the reset meets many openings and closings; the
 * exact schemes take them one solve (and one event-driven step) at a time,
 * the batched step several per solve (3D N = 1000 with the chain stopped at
 * tol 1e-8: 161 steps against 722 and 3.3 times less CPU, the same
 * packing; docs/jamming.md), and hands the potentially jammed network to
 * the exact scheme, which decides. */
typedef struct {
    int saved, integrator;
    double dt, tol, h;
    unsigned corr_every;
} lp_integ;

static void lp_integ_batched(odhs_stepper *st, lp_integ *keep)
{
    const odhs__step_type *b = odhs__step_type_find(ODHS_INTEGRATOR_BATCHED);
    *keep = (lp_integ){1, st->integrator, st->dt, st->tol, st->h, st->corr_every};
    st->integrator = ODHS_INTEGRATOR_BATCHED;
    st->dt = b->dt_default;
    st->tol = b->tol_default;
    st->h = st->dt * b->h_first;
    st->corr_every = b->corr_default;
    /* the steps it hands to the exact scheme near jamming keep the exact
     * scheme's accuracy (batched.c, exact_step): the stepper's own Heun
     * tolerance, or Heun's default (at the batched tolerance, 1e-3, a Heun
     * step's error left a rattler overlapping a neighbour by 3e-11 at 3D
     * N = 1000, above the certificate thresholds' 1e-14) */
    st->tol_exact = keep->integrator == ODHS_INTEGRATOR_HEUN ? keep->tol
                                                             : odhs__step_type_find(ODHS_INTEGRATOR_HEUN)->tol_default;
}

static void lp_integ_restore(odhs_stepper *st, const lp_integ *keep)
{
    if (!keep->saved) return;
    st->integrator = keep->integrator;
    st->dt = keep->dt;
    st->tol = keep->tol;
    st->h = keep->h;
    st->corr_every = keep->corr_every;
    st->tol_exact = 0.0;
}
#endif /* ODHS_HAVE_CLP */

/* what the fast route cannot do: it moves particles freely and grows them,
 * so the driving must be a plain compression and the scene plain spheres */
static int lp_check_scene(odhs_stepper *st)
{
    const odhs_driver *d = st->drv;
    if (st->net->nwalls || st->net->nperm)
        return odhs__sterr(st, ODHS_E_UNSUPPORTED,
                           "jam_lp: the scene has walls or bonds (composites); the linear programmes know free "
                           "particles only: use odhs_stepper_step");
    if (!(d->crate > 0.0) || d->gdot != 0.0 || d->pressure_on || d->osc_shape || d->fn || d->F || d->prop_on ||
        d->grav_on)
        return odhs__sterr(st, ODHS_E_STATE,
                           "jam_lp needs a driver with isotropic compression only (compression rate > 0; no shear, "
                           "pressure, forces, callback, propulsion or gravity)");
    return ODHS_OK;
}

#if ODHS_HAVE_CLP

typedef struct {
    size_t *i, *j;
    double *rij; /* 3 per pair */
    size_t m, cap_i, cap_j, cap_r;
    int dim, nomem;
} lp_pairs;

static int lp_pair_cb(size_t i, size_t j, const double *rij, double gap, void *vctx)
{
    (void)gap;
    lp_pairs *p = vctx;
    if (odhs__reserve((void **)&p->i, &p->cap_i, p->m + 1, sizeof *p->i) ||
        odhs__reserve((void **)&p->j, &p->cap_j, p->m + 1, sizeof *p->j) ||
        odhs__reserve((void **)&p->rij, &p->cap_r, 3 * (p->m + 1), sizeof *p->rij)) {
        p->nomem = 1;
        return 1;
    }
    p->i[p->m] = i < j ? i : j;
    p->j[p->m] = i < j ? j : i;
    for (int a = 0; a < 3; ++a) p->rij[3 * p->m + a] = a < p->dim ? (i < j ? rij[a] : -rij[a]) : 0.0;
    p->m++;
    return 0;
}

/* a pair's status in the basis of the programme before (sorted by key) */
typedef struct {
    unsigned long long key;
    unsigned char status;
} lp_basis;

static int lp_basis_cmp(const void *a, const void *b)
{
    unsigned long long x = ((const lp_basis *)a)->key, y = ((const lp_basis *)b)->key;
    return x < y ? -1 : x > y;
}

/* the work of one chain (freed by lp_free) */
typedef struct {
    lp_pairs pr;
    int *start, *row;
    double *val, *rlo, *rup, *clo, *cup, *obj, *xc, *s;
    double Lc[3]; /* the chain's configuration: positions xc, box Lc */
    double *xq, Lq[3]; /* the quench start (NULL: none) */
    unsigned char *status;
    lp_basis *basis;
    size_t *added; /* pairs of the last programme made contacts before the reset */
    size_t nbasis, cap_start, cap_row, cap_val, cap_rlo, cap_rup, cap_status, cap_basis, cap_added, nadded;
    double smin; /* the smallest diameter */
    int shake;   /* the chain's shake (0: the first chain) */
} lp_work;

static void lp_free(lp_work *w)
{
    odhs__free(w->pr.i);
    odhs__free(w->pr.j);
    odhs__free(w->pr.rij);
    odhs__free(w->start);
    odhs__free(w->row);
    odhs__free(w->val);
    odhs__free(w->rlo);
    odhs__free(w->rup);
    odhs__free(w->clo);
    odhs__free(w->cup);
    odhs__free(w->obj);
    odhs__free(w->xc);
    odhs__free(w->s);
    odhs__free(w->status);
    odhs__free(w->basis);
    odhs__free(w->added);
    odhs__free(w->xq);
}

/* One programme around the current configuration; *g receives the growth
 * of the squared contact distances that the displacements w->s allow on
 * the real (not linearised) pairs. */
static int lp_solve(odhs_stepper *st, lp_work *w, double ell, odhs_jam_lp_report *rep, double *g)
{
    odhs_system *sys = st->sys;
    const int d = st->dim;
    const size_t n = st->n, nd = st->nd;
    const double smin = w->smin, smax = 2.0 * sys->rmax;
    const double groot = 1.0 + 2.0 * ell / smin; /* bound on sqrt(Gamma) */
    const double cut = 2.0 * sqrt((double)d) * ell + (groot - 1.0) * smax;
    w->pr.m = 0;
    w->pr.dim = d;
    w->pr.nomem = 0;
    int s = odhs__pairs(d, n, w->xc, sys->r, sys->rmax, w->Lc, sys->gamma, cut, lp_pair_cb, &w->pr);
    if (w->pr.nomem || s == ODHS_E_NOMEM) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    if (s) return odhs__sterr(st, s, "jam_lp: pair search failed");
    const size_t m = w->pr.m, nc = nd + 1;
    if (m > (size_t)INT_MAX / 8 || nc > (size_t)INT_MAX / 8)
        return odhs__sterr(st, ODHS_E_UNSUPPORTED, "jam_lp: %zu pairs are too many for the LP solver", m);
    /* the constraint matrix by columns: coordinate a of particle k, then Gamma */
    size_t nnz = m * (2 * (size_t)d + 1);
    if (odhs__reserve((void **)&w->start, &w->cap_start, nc + 1, sizeof *w->start) ||
        odhs__reserve((void **)&w->row, &w->cap_row, nnz, sizeof *w->row) ||
        odhs__reserve((void **)&w->val, &w->cap_val, nnz, sizeof *w->val) ||
        odhs__reserve((void **)&w->rlo, &w->cap_rlo, m + 1, sizeof *w->rlo) ||
        odhs__reserve((void **)&w->rup, &w->cap_rup, m + 1, sizeof *w->rup) ||
        odhs__reserve((void **)&w->status, &w->cap_status, nc + m, 1))
        return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    int *start = w->start;
    memset(start, 0, (nc + 1) * sizeof *start);
    for (size_t q = 0; q < m; ++q) {
        for (int a = 0; a < d; ++a) {
            start[w->pr.i[q] * (size_t)d + (size_t)a + 1]++;
            start[w->pr.j[q] * (size_t)d + (size_t)a + 1]++;
        }
        start[nc]++;
    }
    for (size_t c = 0; c < nc; ++c) start[c + 1] += start[c];
    for (size_t q = 0; q < m; ++q) {
        size_t i = w->pr.i[q], j = w->pr.j[q];
        const double *v = w->pr.rij + 3 * q;
        double sig2 = (sys->r[i] + sys->r[j]) * (sys->r[i] + sys->r[j]), r2 = 0.0;
        for (int a = 0; a < d; ++a) {
            r2 += v[a] * v[a];
            size_t ci = i * (size_t)d + (size_t)a, cj = j * (size_t)d + (size_t)a;
            w->row[start[ci]] = (int)q;
            w->val[start[ci]++] = -2.0 * v[a] / sig2;
            w->row[start[cj]] = (int)q;
            w->val[start[cj]++] = 2.0 * v[a] / sig2;
        }
        w->row[start[nc - 1]] = (int)q;
        w->val[start[nc - 1]++] = -1.0;
        w->rlo[q] = -r2 / sig2;
        w->rup[q] = DBL_MAX;
    }
    for (size_t c = nc; c-- > 0;) start[c + 1] = start[c]; /* the fill moved each start one column on */
    start[0] = 0;
    for (size_t c = 0; c < nd; ++c) {
        w->clo[c] = c < (size_t)d ? 0.0 : -ell;
        w->cup[c] = c < (size_t)d ? 0.0 : ell;
        w->obj[c] = 0.0;
    }
    w->clo[nd] = 0.0;
    w->cup[nd] = groot * groot;
    w->obj[nd] = 1.0;

    Clp_Simplex *M = Clp_newModel();
    if (!M) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory (LP solver)");
    Clp_setLogLevel(M, 0);
    Clp_loadProblem(M, (int)nc, (int)m, start, w->row, w->val, w->clo, w->cup, w->obj, w->rlo, w->rup);
    Clp_setObjSense(M, -1.0);
    Clp_setPrimalTolerance(M, LP_FEAS);
    Clp_setDualTolerance(M, LP_FEAS);
    if (w->nbasis) { /* warm start: columns as before, pairs as before (new ones basic) */
        for (size_t q = 0; q < m; ++q) {
            lp_basis key = {(unsigned long long)w->pr.i[q] * n + w->pr.j[q], 1};
            const lp_basis *f = bsearch(&key, w->basis, w->nbasis, sizeof *w->basis, lp_basis_cmp);
            w->status[nc + q] = f ? f->status : 1;
        }
        Clp_copyinStatus(M, w->status);
        Clp_dual(M, 0);
    } else if (st->lp_cold_dual || w->shake) {
        /* after a shake, the dual simplex from the slack basis (as up to
         * 0.2.10): its path leaves a degenerate vertex that the primal start
         * returns to (2D N = 256, seed 8: three shakes with the primal start
         * end at the same zero force, and so do the primal and dual taken
         * in turn; with the dual, the second shake ends at a smallest force
         * of 0.0085 of the mean). It costs more at large N (2D N = 4096,
         * seed 1, one shake: 113 CPU s in all, 41 with the primal start) */
        Clp_dual(M, 0);
    } else {
        /* The first programme of a chain: the primal simplex from the
         * feasible point s = 0, Gamma = the smallest r^2/sigma^2 (a values
         * pass). From the quench start it needs 1.8-3.2x fewer pivots than
         * the dual simplex from the slack basis, whose start puts every
         * displacement at a bound of the trust region (test_lp_primal_start
         * in tests/check_jamming.c). */
        double *x0 = Clp_primalColumnSolution(M), gmin = groot * groot;
        for (size_t q = 0; q < m; ++q) gmin = fmin(gmin, -w->rlo[q]);
        memset(x0, 0, nd * sizeof *x0);
        x0[nd] = gmin;
        Clp_primal(M, 1);
    }
    int lps = Clp_status(M);
    rep->simplex_iterations += (uint64_t)Clp_numberIterations(M);
    if (lps != 0) {
        Clp_deleteModel(M);
        return odhs__sterr(st, ODHS_E_NOCONV, "jam_lp: the LP solver stopped with status %d (%s)", lps,
                           lps == 1   ? "primal infeasible"
                           : lps == 2 ? "dual infeasible"
                           : lps == 3 ? "iteration limit"
                                      : "numerical difficulties");
    }
    const double *cs = Clp_getColSolution(M);
    memcpy(w->s, cs, nd * sizeof *w->s);
    memcpy(w->status, Clp_statusArray(M), nc + m);
    Clp_deleteModel(M);
    /* the basis of this programme, for the next one */
    if (odhs__reserve((void **)&w->basis, &w->cap_basis, m + 1, sizeof *w->basis))
        return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    for (size_t q = 0; q < m; ++q) {
        w->basis[q].key = (unsigned long long)w->pr.i[q] * n + w->pr.j[q];
        w->basis[q].status = w->status[nc + q];
    }
    w->nbasis = m;
    qsort(w->basis, m, sizeof *w->basis, lp_basis_cmp);
    if (m > rep->rows_max) rep->rows_max = m;
    /* the growth the real pairs allow */
    double gr = groot * groot;
    for (size_t q = 0; q < m; ++q) {
        size_t i = w->pr.i[q], j = w->pr.j[q];
        const double *v = w->pr.rij + 3 * q;
        double sig = sys->r[i] + sys->r[j], r2 = 0.0;
        for (int a = 0; a < d; ++a) {
            double e = v[a] + w->s[j * (size_t)d + (size_t)a] - w->s[i * (size_t)d + (size_t)a];
            r2 += e * e;
        }
        gr = fmin(gr, r2 / (sig * sig));
    }
    *g = gr;
    return ODHS_OK;
}

/* move by w->s and grow by g (the box shrinks by 1/sqrt(g)) */
static void lp_apply(odhs_stepper *st, lp_work *w, double g)
{
    const int d = st->dim;
    const double f = 1.0 / sqrt(g);
    for (size_t k = 0; k < st->nd; ++k) w->xc[k] += w->s[k];
    for (size_t i = 0; i < st->n; ++i) odhs__wrap(d, w->Lc, st->sys->gamma, w->xc + i * (size_t)d);
    for (size_t k = 0; k < st->nd; ++k) w->xc[k] *= f; /* still inside the shrunk box */
    for (int a = 0; a < d; ++a) w->Lc[a] *= f;
}

/* The quench start on a copy of the system: affine compression to
 * o->quench_phi, FIRE on the harmonic soft-sphere energy, rescalings toward
 * phi_J, and a dilation until no pair overlaps (w->xq, w->Lq). */
typedef struct {
    const double *r;
    double f;     /* the largest sigma / |r_ij| */
    double sum;   /* the sum of the relative overlaps 1 - |r_ij| / sigma ... */
    size_t count; /* ... over this many overlapping pairs */
} lp_dilate_ctx;

static int lp_dilate_cb(size_t i, size_t j, const double *rij, double gap, void *vctx)
{
    (void)gap;
    lp_dilate_ctx *c = vctx;
    double sig = c->r[i] + c->r[j], r = sqrt(rij[0] * rij[0] + rij[1] * rij[1] + rij[2] * rij[2]);
    if (sig > c->f * r) c->f = sig / r;
    if (r < sig) {
        c->sum += 1.0 - r / sig;
        c->count++;
    }
    return 0;
}

static int lp_quench(odhs_stepper *st, const odhs_jam_lp_options *o, lp_work *w, odhs_jam_lp_report *rep)
{
    odhs_system *tmp = NULL;
    odhs_softcore *sc = NULL;
    int s;
    if ((s = odhs_system_clone(st->sys, &tmp))) goto fail;
    if ((s = odhs_softcore_create(tmp, &sc)) || (s = odhs_softcore_set_minimiser(sc, ODHS_SOFTCORE_FIRE)) ||
        (s = odhs_softcore_set_min_tolerance(sc, LP_QUENCH_FORCE, LP_QUENCH_ITER)))
        goto fail;
    double phi;
    odhs_system_packing_fraction(tmp, &phi);
    if (o->quench_phi > phi && (s = odhs_softcore_scale_box(sc, pow(phi / o->quench_phi, 1.0 / st->dim)))) goto fail;
    /* FIRE, then rescalings toward phi_J (without bisection): each removes
     * the contacts' mean overlap and relaxes again, until it is below
     * LP_QUENCH_OVERLAP (or the packing unjams: no contact left). The
     * dilation below then opens far smaller gaps, and the chain starts
     * closer to jamming: 3D N = 1000 from phi = 0.643 after 3 rescalings,
     * against 0.613 without; its first programme needs 4x fewer pivots.
     * Since 0.2.24 the rescalings go on to a mean overlap of 3e-6 (3e-4
     * before: 3 or 4 rescalings), and each relaxation after a rescaling
     * stops at 1e-3 of the mean contact force instead of the fixed 1e-9,
     * which near phi_J would cost more FIRE iterations than the chain
     * saves. The chain then starts within about 1e-5 of its phi_J, and
     * its first programme is cheaper the larger the packing: 3D N = 3000
     * 9 690 pivots and 7.5 CPU s against 18 011 and 32 s; 3D N = 8000
     * 27 962 and 101 s against 77 088 and 1 142 s (docs/jamming.md). */
    lp_dilate_ctx c = {tmp->r, 1.0, 0.0, 0};
    for (int k = 0;; ++k) {
        uint64_t it = 0;
        s = odhs_softcore_minimise(sc, &it);
        /* unfinished: used as it is (rolled back to the start of this relaxation) */
        if (s == ODHS_E_NOCONV) s = ODHS_OK, it = LP_QUENCH_ITER;
        if (s) goto fail;
        rep->quench_iterations += it;
        c.f = 1.0;
        c.sum = 0.0;
        c.count = 0;
        s = odhs__pairs(st->dim, st->n, tmp->x, tmp->r, tmp->rmax, tmp->L, tmp->gamma, 0.0, lp_dilate_cb, &c);
        if (s) goto fail;
        if (!c.count || c.sum < LP_QUENCH_OVERLAP * (double)c.count || k == LP_QUENCH_STEPS) break;
        /* the harmonic pair force is (1 - r/sigma) / sigma: the mean
         * contact force is about the mean overlap over the mean diameter */
        const double mean = c.sum / (double)c.count;
        if ((s = odhs_softcore_set_min_tolerance(sc, fmax(LP_QUENCH_FORCE, LP_QUENCH_FREL * mean / st->lambda),
                                                 LP_QUENCH_ITER)) ||
            (s = odhs_softcore_scale_box(sc, 1.0 + mean)))
            goto fail;
        rep->quench_steps++;
    }
    odhs_softcore_destroy(sc);
    sc = NULL;
    const double f = c.f * (1.0 + 1e-12); /* a margin against the round-off of the scaling */
    if (!(w->xq = odhs__malloc_array(st->nd, sizeof *w->xq))) {
        s = ODHS_E_NOMEM;
        goto fail;
    }
    for (size_t k = 0; k < st->nd; ++k) w->xq[k] = tmp->x[k] * f;
    for (int a = 0; a < 3; ++a) w->Lq[a] = tmp->L[a] * (a < st->dim ? f : 1.0);
    odhs_system_destroy(tmp);
    return ODHS_OK;
fail:
    odhs_softcore_destroy(sc);
    odhs_system_destroy(tmp);
    return odhs__sterr(st, s, "jam_lp: the quench start failed: %s", odhs_strerror(s));
}

/* The chain on private copies of the configuration (w->xc, w->Lc): the
 * stepper and its system are not touched. It starts from the quench, the
 * system's configuration, or (from_chain) the last chain's packing, whose
 * reset failed (below). shake > 0: the start is first
 * dilated by LP_SHAKE_DILATE and every coordinate moved by a deterministic
 * noise of LP_SHAKE_NOISE mean diameters (round shake), far less than the
 * gaps the dilation opens, so no pair overlaps. */
#define LP_SHAKE_DILATE 1e-5
#define LP_SHAKE_NOISE 1e-7
static int lp_chain(odhs_stepper *st, const odhs_jam_lp_options *o, lp_work *w, odhs_jam_lp_report *rep, int shake,
                    int from_chain)
{
    const odhs_system *sys = st->sys;
    const int d = st->dim;
    const size_t nc = st->nd + 1;
    if (!w->s &&
        (!(w->clo = odhs__malloc_array(nc, sizeof *w->clo)) || !(w->cup = odhs__malloc_array(nc, sizeof *w->cup)) ||
         !(w->obj = odhs__malloc_array(nc, sizeof *w->obj)) || !(w->xc = odhs__malloc_array(st->nd, sizeof *w->xc)) ||
         !(w->s = odhs__malloc_array(st->nd, sizeof *w->s))))
        return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    const int q = w->xq && !shake; /* the first chain starts at the quench, if any */
    if (!from_chain) { /* from_chain: a shake of the last chain's packing, kept in w->xc */
        memcpy(w->xc, q ? w->xq : sys->x, st->nd * sizeof *w->xc);
        memcpy(w->Lc, q ? w->Lq : sys->L, sizeof w->Lc);
    }
    if (!shake) { /* the system's packing fraction, scaled to the start's volume */
        double phi, V = 1.0;
        odhs_system_packing_fraction(sys, &phi);
        for (int a = 0; a < d; ++a) V *= sys->L[a] / w->Lc[a];
        rep->phi_start = phi * V;
    }
    /* a new start, also after a shake: no warm start (from the basis of a
     * degenerate packing the chain returns to it: 2D N = 4096, seed 1) */
    w->nbasis = 0;
    w->shake = shake;
    if (shake) { /* the noise: the library's generator, seeded by the shake's number */
        odhs_rng rng;
        odhs__rng_seed(&rng, (uint64_t)shake);
        for (int a = 0; a < d; ++a) w->Lc[a] *= 1.0 + LP_SHAKE_DILATE;
        for (size_t k = 0; k < st->nd; ++k)
            w->xc[k] = w->xc[k] * (1.0 + LP_SHAKE_DILATE) +
                       LP_SHAKE_NOISE * st->lambda * (2.0 * odhs__rng_uniform(&rng) - 1.0);
        for (size_t i = 0; i < st->n; ++i) odhs__wrap(d, w->Lc, sys->gamma, w->xc + i * (size_t)d);
    }
    /* the trust region, and a cut-off the cell search allows (half the
     * shortest box edge minus the largest diameter) */
    w->smin = INFINITY;
    for (size_t i = 0; i < st->n; ++i) w->smin = fmin(w->smin, 2.0 * sys->r[i]);
    const double lam = st->lambda; /* the mean diameter (set by the reset) */
    const double ell = o->trust * lam, per_ell = 2.0 * sqrt((double)d) + 2.0 * sys->rmax / w->smin;
    int s;
    for (size_t k = 0; k < o->max_lps; ++k) {
        double lmin = fmin(w->Lc[0], w->Lc[1]);
        if (d == 3) lmin = fmin(lmin, w->Lc[2]);
        double e = fmin(ell, 0.9 * (0.5 * lmin - 2.0 * sys->rmax) / per_ell);
        if (!(e > 1e-6 * lam))
            return odhs__sterr(st, ODHS_E_BOX, "jam_lp: the box (shortest edge %g) is too small for the programmes",
                               lmin);
        double g = 1.0;
        if ((s = lp_solve(st, w, e, rep, &g))) return s;
        rep->n_lps++;
        rep->growth_last = sqrt(g) - 1.0;
        if (g > 1.0) lp_apply(st, w, g);
        if (!(sqrt(g) - 1.0 >= o->tol)) break;
    }
    return ODHS_OK;
}

/* The last programme's active pairs (rows at their bound) are the contacts
 * of the chain's vertex. Their gaps are second order in that programme's
 * displacements (3D N = 8000: up to 2.8e-5 diameters, gaps up to about
 * 1e-8), above the reset's contact tolerance (1e-9), so the reset alone
 * can miss some and start the end game hypostatic (it then steps: 55
 * event-driven steps at 3D N = 343 with tol = 1e-8). Made temporary
 * contacts here, the reset keeps those within its keep distance (1e-6 of
 * the contact distance) and the polish closes them. w->added lists them
 * (pair indices), for lp_unmark_active after a failed reset. */
static size_t lp_net_find(const odhs_network *net, size_t i, size_t j)
{
    return i < j ? odhs__net_find(net, i, j) : odhs__net_find(net, j, i);
}

static int lp_mark_active(odhs_stepper *st, lp_work *w)
{
    const size_t nc = st->nd + 1, m = w->pr.m;
    w->nadded = 0;
    if (odhs__reserve((void **)&w->added, &w->cap_added, m + 1, sizeof *w->added))
        return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    for (size_t q = 0; q < m; ++q) {
        if ((w->status[nc + q] & 7) == 1) continue; /* basic: the pair is not tight */
        size_t i = w->pr.i[q], j = w->pr.j[q];
        if (i == j || lp_net_find(st->net, i, j) != SIZE_MAX) continue;
        if (odhs__net_add(st->net, i, j, ODHS_CONTACT_TEMPORARY) == SIZE_MAX)
            return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
        w->added[w->nadded++] = q;
    }
    return ODHS_OK;
}

/* undo lp_mark_active (the reset failed and the stepper is put back) */
static void lp_unmark_active(odhs_stepper *st, lp_work *w)
{
    for (size_t k = 0; k < w->nadded; ++k) {
        size_t q = w->added[k], i = w->pr.i[q], j = w->pr.j[q];
        size_t c = lp_net_find(st->net, i, j);
        if (c != SIZE_MAX && st->net->kind[c] == ODHS_CONTACT_TEMPORARY) odhs__net_remove_at(st->net, c);
    }
    w->nadded = 0;
}

#endif /* ODHS_HAVE_CLP */

void odhs__stepper_set_lp_min_force(odhs_stepper *st, double v)
{
    st->lp_min_force = v;
}

void odhs__stepper_set_lp_cold_dual(odhs_stepper *st, int v)
{
    st->lp_cold_dual = v;
}

void odhs__stepper_set_lp_reset_fail(odhs_stepper *st, int v)
{
    st->lp_reset_fail = v;
}

int odhs_stepper_jam_lp(odhs_stepper *st, const odhs_jam_lp_options *opt, odhs_jam_lp_report *rep)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    int s;
    if (rep && rep->size < LP_REP_MIN)
        return odhs__sterr(st, ODHS_E_INVALID,
                           "odhs_jam_lp_report.size = %zu: set it to sizeof(odhs_jam_lp_report) (at least %zu)",
                           rep->size, (size_t)LP_REP_MIN);
    odhs_jam_lp_options o;
    if ((s = lp_settings(st, opt, &o))) return s;
    if ((s = odhs__st_check_handles(st))) return s;
    if ((s = lp_check_scene(st))) return s;
    if (!st->ready && (s = odhs_stepper_reset(st))) return s;
    if (st->jammed) return odhs__sterr(st, ODHS_JAMMED, "the packing is jammed: nothing to compress");
#if ODHS_HAVE_CLP
    odhs_jam_lp_report r;
    memset(&r, 0, sizeof r);
    odhs_system *sys = st->sys;
    lp_work w;
    memset(&w, 0, sizeof w);
    lp_integ keep = {0};
    double *x0 = odhs__malloc_array(st->nd, sizeof *x0);
    if (!x0) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    /* a packing with a backbone contact of zero force (a degenerate vertex of
     * the last programme: seen at 2D N = 4096) can still be compressed: it
     * is shaken (LP_SHAKE_*) and the chain runs again, at most LP_SHAKES
     * times */
    if (o.quench && (s = lp_quench(st, &o, &w, &r))) goto done;
    for (int shake = 0, from_chain = 0;; ++shake) {
        if ((s = lp_chain(st, &o, &w, &r, shake, from_chain))) goto done;
        from_chain = 0;
        /* commit: the stepper moves its system (as a step does) and is reset
         * on the packing; a failed reset puts both back */
        double L0[3];
        memcpy(x0, sys->x, st->nd * sizeof *x0);
        memcpy(L0, sys->L, sizeof L0);
        memcpy(sys->x, w.xc, st->nd * sizeof *w.xc);
        memcpy(sys->L, w.Lc, sizeof w.Lc);
        const int pre0 = st->pre_state, jammed0 = st->jammed;
        /* the end game's integrator, from the reset on (its rewiring) */
        if (!o.own_integrator && !keep.saved) lp_integ_batched(st, &keep);
        if (!(s = lp_mark_active(st, &w)) && !(s = odhs_stepper_reset(st)) && st->lp_reset_fail > 0) {
            st->lp_reset_fail--; /* tests: the reset refused, as below */
            s = odhs__sterr(st, ODHS_POTENTIALLY_JAMMED, "jam_lp: the reset refused (test hook)");
        }
        if (s) {
            char msg[ODHS_ERRMSG_LEN];
            memcpy(msg, st->errmsg, sizeof msg);
            memcpy(sys->x, x0, st->nd * sizeof *x0);
            memcpy(sys->L, L0, sizeof L0);
            lp_unmark_active(st, &w);
            odhs__net_geometry(st->net, sys); /* the gaps and normals of the start */
            st->ready = 1;
            st->jammed = jammed0;
            st->pre_state = pre0;
            memcpy(st->errmsg, msg, sizeof msg);
            /* Since 0.2.24: a reset whose network is potentially jammed but
             * whose self-stress turns negative after the polish (a contact
             * of nearly zero force at a degenerate vertex: 2D N = 16384,
             * seed 1, -2.6e-4 of the mean force) is a degenerate packing
             * too: the chain's packing is shaken and the chain runs again
             * (up to 0.2.23 the call returned ODHS_POTENTIALLY_JAMMED) */
            if (s == ODHS_POTENTIALLY_JAMMED && shake < LP_SHAKES) {
                r.shakes++;
                from_chain = 1;
                st->errmsg[0] = '\0';
                continue;
            }
            goto done;
        }
        odhs_system_packing_fraction(sys, &r.phi_lp);
        /* the end game: normally jammed at the reset */
        while (!st->jammed && r.end_steps < o.max_steps) {
            s = odhs_stepper_step(st, NULL);
            if (s == ODHS_OK || s == ODHS_STOPPED || s == ODHS_JAMMED) r.end_steps++;
            if (s != ODHS_OK && s != ODHS_STOPPED) break;
        }
        if (!st->jammed) break;
        /* The checks below improve a packing that is already jammed; out of
         * memory they are skipped (the packing is returned as the end game
         * made it), since the stepper has moved on and cannot go back. */
        odhs_jam_certificate c;
        c.size = sizeof c;
        int e = odhs_stepper_certificate(st, &c);
        if (e == ODHS_E_NOMEM) break;
        if (e) {
            s = e;
            goto done;
        }
        /* the chain ends with contact gaps up to CLP's feasibility tolerance,
         * which one polish normally brings to round-off (1.5e-14 at 2D
         * N = 4096, the floor of its coordinates; LP_GAP is above it): a
         * packing left above LP_GAP is polished again (the end game once
         * more: polish, f0, pivots, rattlers, f0 check); a failed polish is
         * undone */
        for (int k = 0; k < LP_POLISHES && c.gap_error > LP_GAP; ++k) {
            const uint64_t piv0 = st->njam_pivots;
            if ((e = odhs__st_save(st))) break;
            if (odhs__st_jam_finish(st)) { /* any failure: keep the packing before it */
                odhs__st_rollback(st);
                st->jammed = 1;
                st->njam_pivots = piv0;
                st->errmsg[0] = '\0';
                break;
            }
            r.polishes++;
            if ((e = odhs_stepper_certificate(st, &c))) break;
        }
        if (e && e != ODHS_E_NOMEM) {
            s = e;
            goto done;
        }
        if (e || shake == LP_SHAKES) break;
        if (c.min_force > (st->lp_min_force > 0.0 ? st->lp_min_force : LP_MIN_FORCE)) break;
        r.shakes++;
    }
    if (st->jammed) {
        s = odhs__sterr(st, ODHS_JAMMED, "jammed by %zu linear programmes and %llu event-driven steps at phi = %.15g",
                        r.n_lps, (unsigned long long)r.end_steps, r.phi_lp);
    } else if (s == ODHS_OK || s == ODHS_STOPPED) {
        s = odhs__sterr(st, ODHS_E_STALLED,
                        "jam_lp: not jammed after %zu event-driven steps of the end game (phi = %.15g after %zu "
                        "programmes)",
                        o.max_steps, r.phi_lp, r.n_lps);
    }
    if (rep) {
        size_t size = rep->size;
        r.size = size;
        memcpy(rep, &r, size < sizeof r ? size : sizeof r);
    }
done:
    lp_integ_restore(st, &keep);
    lp_free(&w);
    odhs__free(x0);
    return s;
#else
    (void)o;
    return odhs__sterr(st, ODHS_E_NOTINSTALLED,
                       "jam_lp: this libodhs was built without an LP solver (COIN-OR CLP: Debian coinor-libclp-dev)");
#endif
}
