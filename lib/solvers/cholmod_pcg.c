/*
 * libodhs - sparse solver for N = S S^T through CHOLMOD (SuiteSparse): the
 * backend "cholmod-pcg" ("cholmod" is in cholmod.c, what both share in
 * cholmod_common.c), compiled only when the Makefile finds SuiteSparse
 * (ODHS_HAVE_SUITESPARSE); otherwise this file defines nothing.
 *
 * "cholmod-pcg" (odhs_solver_type_cholmod_pcg): preconditioned conjugate
 *   gradients on N x = b (matrix free, as the "cg" backend) with a simplicial
 *   LDL' factor of a "slot" matrix M as the preconditioner, kept up to date
 *   through CHOLMOD's Modify module when contacts appear or disappear:
 *   - the factor has a fixed size cap >= Nc (cap = Nc + max(16, Nc/8) at each
 *     full factorisation); every contact pair occupies a stable slot, free
 *     slots are identity rows and columns of M. Contacts are found again by
 *     their pair (i,j) through the network's own pair hash (odhs__net_find),
 *     so the swap-removal that renumbers contacts does not matter: a contact
 *     -> slot map is rebuilt at each setup in O(cap).
 *   - a removed contact: cholmod_rowdel on its slot (row/column -> identity);
 *     an added contact: cholmod_rowadd with the full new row of M (the row of
 *     N for this contact against the contacts already in the factor, computed
 *     with the current normals, plus the diagonal 2|n|^2). Both work on the
 *     permuted factor, so slot s is row/column Pinv[s] of L and the entries of
 *     the new row are given at permuted positions. rowadd requires the row to
 *     be an identity row on input, which free slots are.
 *     (cholmod_updown was the alternative: N changes by a row and a column,
 *     which is a rank-2 symmetric change of M; rowadd/rowdel do exactly that
 *     change and keep the factor's dimension, so they are the natural fit.)
 *   - the backend remembers the normal each row of the factor was made with.
 *     While no normal of a contact in the factor has moved (e.g. inside the
 *     stepper's rewiring, which removes and re-adds contacts at a fixed
 *     geometry) the updated factor is the exact LDL' of N and PCG converges in
 *     one iteration. Once normals moved, the factor belongs to an older
 *     geometry and PCG makes up the difference (about 5 iterations at 1e-12
 *     after one step of a sheared packing).
 *   - full refactorisation (slots renumbered 0..Nc-1, new analysis unless
 *     only the geometry changed since the last one) after "refactor_every"
 *     geometry changes (setups at which some normal had moved since the
 *     previous setup; default 50; 0 = never for this reason), when the slot
 *     capacity would be exceeded, when many contacts changed at once (more
 *     than "update_max" (Nc + 64), default 1/8: cheaper than updates; the
 *     batched integrator lowers it while it changes many contacts per
 *     solve), when the updates have doubled the fill of L (checked after
 *     the updates; while they run, an allocation of L beyond 2.5 times the
 *     fresh factor's stops them unless packing L reclaims the holes that
 *     moved columns leave (pcg_reclaim; then beyond 4 times)), when an
 *     update leaves a D entry not
 *     above min_rcond * max(D) (a mixed-geometry matrix need not stay positive
 *     definite, and a new contact can make N singular), and inside solve when
 *     PCG with an aged factor needs more than "refactor_iterations" (default
 *     40) iterations or breaks down: the solve then goes on from its current
 *     iterate with the fresh factor. A fresh factor that fails is
 *     ODHS_E_SINGULAR, as for "cholmod".
 *   Parameters: "tol" (relative residual, default 1e-12), "maxiter" (default
 *   0 = 10*Nc + 100), "min_rcond" (1e-14), "refactor_every" (50),
 *   "refactor_iterations" (40), "update_max" (0.125, in [0, 1]; since
 *   0.2.14), "supernodal" (0: full factorisations by the simplicial LDL'
 *   the Modify module needs, the default up to 0.2.20; since 0.2.20 also 1:
 *   by supernodes, LL' in dense blocks, converted to that LDL' by
 *   cholmod_change_factor (packed, O(nnz(L))); -1: by supernodes where the
 *   analysis predicts at least "supernodal_switch" flops per entry of L,
 *   CHOLMOD_AUTO; the default since 0.2.21), "supernodal_switch" (since
 *   0.2.21; default 200, measured: PCG_SUPERNODAL_SWITCH; CHOLMOD's own is
 *   40, which 0.2.20's -1 used), "openmp" (since 0.2.21; 0, the default:
 *   the OpenMP loops of CHOLMOD's supernodal factorisation run on the
 *   calling thread; 1: on CHOLMOD's own threads; the same result:
 *   odhs__cm_factorize), "ordering" (since 0.2.23; -1 CHOLMOD's choice, the
 *   default; 0 AMD; 1 METIS) and "ordering_reuse" (since 0.2.23; -1, the
 *   default: PCG_ORDERING_REUSE after a fresh ordering that called METIS,
 *   else 0; 0: every analysis orders afresh; X >= 1: a new analysis carries
 *   the last ordering over to the changed contacts (pcg_carry: kept contacts
 *   keep their rank, new ones go last) while the
 *   fill per contact stays within X times the last fresh ordering's).
 *   Statistics: "iterations" (of the
 *   last solve), "updates" (rowadd + rowdel calls), "packs" (the factor's
 *   columns packed to reclaim the holes that moved columns leave; since
 *   0.2.19), "supernodal" (1 when the last full factorisation went by
 *   supernodes; since 0.2.20), "factorizations",
 *   "analyses", "rcond" (of the last full factorisation), "nnz_L" (current),
 *   "flops" and "lnz" (since 0.2.21: the flops and entries of L that the
 *   last analysis predicts; their ratio decides "supernodal" = -1),
 *   "capacity" (slots), "orderings" (fresh orderings; since 0.2.23),
 *   "cholmod_status", and the parameters "tol", "update_max",
 *   "supernodal_switch", "openmp", "ordering", "ordering_reuse".
 *
 * As for both backends (cholmod_common.h): each state owns its own
 * cholmod_common, CHOLMOD never prints, and its int interface is used.
 *
 * Licence note: cholmod_rowadd/cholmod_rowdel belong to CHOLMOD's Modify
 * module, which is GPL-2.0+ (CHOLMOD's Core and Cholesky modules are
 * LGPL-2.1+). The "cholmod-pcg" backend therefore pulls GPL code into a
 * build that links it.
 */
#ifdef ODHS_HAVE_SUITESPARSE

#include <math.h>
#include <string.h>

#include "solvers/cholmod_common.h"

ODHS_API extern const odhs_solver_type odhs_solver_type_cholmod_pcg;

#define NO_SLOT SIZE_MAX

typedef struct {
    size_t i, j; /* a contact's pair */
    int rank;    /* its place in the analysis's ordering */
} pcg_ord;

typedef struct {
    cholmod_common c;
    cholmod_sparse *A;        /* [S | E] of the last full factorisation */
    cholmod_factor *L;        /* simplicial LDL' of the slot matrix M */
    cholmod_factor *Ls;       /* supernodal symbolic analysis, or NULL (simplicial route) */
    cholmod_sparse *R;        /* cap x 1: new row for rowadd */
    cholmod_dense *work[4]; /* cholmod_solve2: B (right-hand side), X (solution), Y, E */
    size_t cap;               /* slots = dimension of L */
    size_t *si, *sj;          /* pair held by each slot, NO_SLOT if free */
    size_t *freel, nfree;     /* stack of free slots */
    int *pinv;                /* slot -> row of the permuted factor */
    size_t slotcap;           /* allocated length of si, sj, freel, pinv, dels */
    size_t *dels;             /* slots to delete (setup workspace) */
    size_t *c2s, c2scap;      /* contact -> slot for the last setup */
    uint32_t *seen, stamp;    /* per slot: matched in the setup with this stamp */
    size_t seencap;
    size_t nc;                /* contacts at the last setup */
    size_t n;
    int dim;
    size_t *cnt, *start, *inc; /* particle -> incident contacts */
    size_t cntcap, startcap, inccap;
    double *w;
    size_t wcap;
    int valid;                /* factor and slot map describe the last setup */
    double *snrm;             /* cap*dim: normal each slot's row was made with */
    double *lnrm;             /* cap*dim: normal of each slot at the last setup */
    size_t snrmcap, lnrmcap;
    int fresh;                /* the factor is exact for the current N */
    size_t since;             /* geometry changes since the last full factorisation */
    size_t updates_since_analysis;
    double nnz0;              /* nnz(L) right after the last full factorisation */
    double nzmax0;            /* and its allocation (L->nzmax) */
    double nzmax_packed;      /* the allocation when L was last packed */
    /* parameters */
    double tol, maxiter, min_rcond, refactor_every, refactor_iterations, update_max;
    /* statistics */
    double iterations, updates, factorizations, analyses, rcond, status, packs;
    double super_last;        /* the last full factorisation was supernodal */
    int openmp;               /* CHOLMOD's OpenMP threads in supernodal factorisations */
    int ordering;             /* "ordering": -1 CHOLMOD's choice, 0 AMD, 1 METIS */
    double reuse;             /* "ordering_reuse": -1 automatic, 0 off, else the fill growth that ends a reuse */
    int fresh_nd;             /* the last fresh ordering called METIS */
    pcg_ord *ord;             /* the last analysis's contacts and their ranks */
    size_t ordcap, on;        /* allocation; contacts held (0: no ordering to carry) */
    double fresh_lnz;         /* lnz per contact of the last fresh ordering */
    double orderings;         /* fresh orderings (statistics) */
    int *cperm;               /* slot ordering handed to cholmod_analyze_p */
    size_t cpermcap;
    int reanalyse;            /* the route or the ordering changed ("supernodal",
                               * "supernodal_switch", "ordering"): the current factor
                               * serves until the next setup, which analyses and
                               * factorises afresh */
} pcg_state;

/* "supernodal_switch": the flops per entry of L from which the full
 * factorisations go by supernodes under "supernodal" = -1 (the default since
 * 0.2.21). Measured with batched shear (docs/performance.md, 0.2.21), CPU
 * time by supernodes over simplicial: 1.9x at 53 (2D N = 4096), 1.4x at 100
 * (2D N = 16384), 1.12x at 192 (2D N = 65536, tiled), 1.05-1.4x at 90 (3D
 * N = 300); 0.6x at 165 (3D N = 600), 0.5x at 220 (3D N = 1000), 0.4x at
 * 410 (3D N = 2000). 200 keeps every measured 2D network simplicial, at the
 * price of 3D networks between about 500 and 900 particles. CHOLMOD's own
 * switch is 40. */
#define PCG_SUPERNODAL_SWITCH 200.0
/* past PCG_NZMAX_GROWTH times the fresh factor's allocation the factor is
 * packed (pcg_reclaim); insertions stop (and setup refactors) past
 * PCG_NZMAX_HARD times, or when the fill has doubled */
#define PCG_NZMAX_GROWTH 2.5
#define PCG_NZMAX_HARD 4.0
/* "ordering_reuse" = -1 (the default): after a fresh ordering that called
 * METIS (CHOLMOD's choice does when AMD's factor has at least 500 flops per
 * entry and 5 times the entries of M, i.e. on large 3D networks), the
 * orderings are carried over while the fill per contact stays within this
 * factor of the fresh one's. Measured with batched shear (docs/performance.md,
 * 0.2.23): 3D N = 4096, 1.6x cheaper (1.05 - 1.3 within 10 % of each other);
 * where AMD alone orders (2D, 3D N = 1000) carrying was 5 - 10 % dearer. */
#define PCG_ORDERING_REUSE 1.1

static int pcg_create(void **state)
{
    pcg_state *s = odhs__calloc(1, sizeof *s);
    if (!s) return ODHS_E_NOMEM;
    odhs__cm_start(&s->c);
    /* the route of the full factorisations ("supernodal"): the Modify module
     * needs a simplicial LDL', which a supernodal LL' is converted to */
    s->c.supernodal = CHOLMOD_AUTO;
    s->c.supernodal_switch = PCG_SUPERNODAL_SWITCH;
    s->c.final_ll = 0;
    s->tol = 1e-12;
    s->min_rcond = 1e-14;
    s->refactor_every = 50;
    s->refactor_iterations = 40;
    s->update_max = 0.125;
    s->ordering = -1;
    s->reuse = -1.0;
    *state = s;
    return ODHS_OK;
}

static void pcg_destroy(void *state)
{
    pcg_state *s = state;
    if (!s) return;
    cholmod_free_factor(&s->Ls, &s->c);
    odhs__cm_release(&s->c, &s->L, &s->A, s->work);
    cholmod_free_sparse(&s->R, &s->c);
    odhs__free(s->si);
    odhs__free(s->sj);
    odhs__free(s->freel);
    odhs__free(s->pinv);
    odhs__free(s->dels);
    odhs__free(s->snrm);
    odhs__free(s->lnrm);
    odhs__free(s->c2s);
    odhs__free(s->seen);
    odhs__free(s->cnt);
    odhs__free(s->start);
    odhs__free(s->inc);
    odhs__free(s->w);
    odhs__free(s->ord);
    odhs__free(s->cperm);
    odhs__free(s);
}

static int pcg_set_param(void *state, const char *key, double v)
{
    pcg_state *s = state;
    if (!strcmp(key, "tol") && v > 0.0 && v < 1.0) s->tol = v;
    else if (!strcmp(key, "maxiter") && v >= 0.0) s->maxiter = floor(v);
    else if (!strcmp(key, "min_rcond") && v >= 0.0 && v < 1.0) s->min_rcond = v;
    else if (!strcmp(key, "refactor_every") && v >= 0.0) s->refactor_every = floor(v);
    else if (!strcmp(key, "refactor_iterations") && v >= 1.0) s->refactor_iterations = floor(v);
    else if (!strcmp(key, "update_max") && v >= 0.0 && v <= 1.0) s->update_max = v;
    else if (!strcmp(key, "supernodal") && (v == -1.0 || v == 0.0 || v == 1.0)) {
        int mode = v == 1.0 ? CHOLMOD_SUPERNODAL : v == -1.0 ? CHOLMOD_AUTO : CHOLMOD_SIMPLICIAL;
        if (mode != s->c.supernodal) s->reanalyse = 1;
        s->c.supernodal = mode;
    } else if (!strcmp(key, "supernodal_switch") && v >= 0.0 && v <= 1e300) {
        if (v != s->c.supernodal_switch && s->c.supernodal == CHOLMOD_AUTO) s->reanalyse = 1;
        s->c.supernodal_switch = v;
    } else if (!strcmp(key, "openmp") && (v == 0.0 || v == 1.0)) s->openmp = (int)v;
    else if (!strcmp(key, "ordering") && (v == -1.0 || v == 0.0 || v == 1.0)) {
        if ((int)v != s->ordering) {
            s->reanalyse = 1;
            s->on = 0; /* the next analysis orders afresh */
        }
        s->ordering = (int)v;
    } else if (!strcmp(key, "ordering_reuse") && (v == -1.0 || v == 0.0 || (v >= 1.0 && v <= 1e300))) s->reuse = v;
    else return ODHS_E_INVALID;
    return ODHS_OK;
}

static int pcg_get_stat(void *state, const char *key, double *v)
{
    pcg_state *s = state;
    if (!strcmp(key, "iterations")) *v = s->iterations;
    else if (!strcmp(key, "updates")) *v = s->updates;
    else if (!strcmp(key, "packs")) *v = s->packs;
    else if (!strcmp(key, "factorizations")) *v = s->factorizations;
    else if (!strcmp(key, "analyses")) *v = s->analyses;
    else if (!strcmp(key, "rcond")) *v = s->rcond;
    else if (!strcmp(key, "nnz_L")) *v = odhs__cm_factor_nnz(s->L, &s->c);
    else if (!strcmp(key, "flops")) *v = s->L ? s->c.fl : 0.0;
    else if (!strcmp(key, "lnz")) *v = s->L ? s->c.lnz : 0.0;
    else if (!strcmp(key, "capacity")) *v = (double)s->cap;
    else if (!strcmp(key, "supernodal")) *v = s->super_last;
    else if (!strcmp(key, "supernodal_switch")) *v = s->c.supernodal_switch;
    else if (!strcmp(key, "openmp")) *v = (double)s->openmp;
    else if (!strcmp(key, "ordering")) *v = (double)s->ordering;
    else if (!strcmp(key, "ordering_reuse")) *v = s->reuse;
    else if (!strcmp(key, "orderings")) *v = s->orderings;
    else if (!strcmp(key, "cholmod_status")) *v = s->status;
    else if (!strcmp(key, "tol")) *v = s->tol;
    else if (!strcmp(key, "update_max")) *v = s->update_max;
    else return ODHS_E_INVALID;
    return ODHS_OK;
}

static size_t pcg_extra(size_t nc) { return nc / 8 > 16 ? nc / 8 : 16; }

/* slot arrays (si, sj, freel, pinv, dels) for at least cap slots */
static int pcg_slot_arrays(pcg_state *s, size_t cap)
{
    if (s->slotcap >= cap) return ODHS_OK;
    size_t nc = cap + cap / 4;
    void *a = odhs__realloc(s->si, nc * sizeof *s->si);
    if (a) s->si = a;
    void *b = odhs__realloc(s->sj, nc * sizeof *s->sj);
    if (b) s->sj = b;
    void *c = odhs__realloc(s->freel, nc * sizeof *s->freel);
    if (c) s->freel = c;
    void *d = odhs__realloc(s->pinv, nc * sizeof *s->pinv);
    if (d) s->pinv = d;
    void *e = odhs__realloc(s->dels, nc * sizeof *s->dels);
    if (e) s->dels = e;
    if (!a || !b || !c || !d || !e) return ODHS_E_NOMEM;
    s->slotcap = nc;
    return ODHS_OK;
}

typedef struct {
    double key;
    size_t c;
} pcg_key;

static int pcg_key_cmp(const void *a, const void *b)
{
    const pcg_key *x = a, *y = b;
    if (x->key != y->key) return x->key < y->key ? -1 : 1;
    return x->c < y->c ? -1 : x->c > y->c;
}

/* The last analysis's ordering carried over to the network's contacts
 * (cperm, cap slots): a contact of the last analysis keeps its rank, new
 * ones go after all of them (in network order), free slots last. Removing
 * contacts from a nested dissection leaves one; a new contact at the end
 * adds one row to L. (Ranking a new contact right after its latest
 * neighbour instead couples subtrees early: on a 3D packing of 200 spheres
 * with a tenth of its contacts new, 1.39 times the fresh ordering's fill
 * against 1.17 at the end.) */
static int pcg_carry(pcg_state *s, const odhs_network *net, size_t cap)
{
    size_t nc = net->nc;
    int st;
    if ((st = odhs__reserve((void **)&s->cperm, &s->cpermcap, cap, sizeof *s->cperm))) return st;
    pcg_key *kv = odhs__malloc((nc ? nc : 1) * sizeof *kv);
    if (!kv) return ODHS_E_NOMEM;
    for (size_t c = 0; c < nc; ++c) {
        kv[c].key = HUGE_VAL;
        kv[c].c = c;
    }
    for (size_t q = 0; q < s->on; ++q) {
        size_t k = odhs__net_find(net, s->ord[q].i, s->ord[q].j);
        if (k != SIZE_MAX) kv[k].key = (double)s->ord[q].rank;
    }
    qsort(kv, nc, sizeof *kv, pcg_key_cmp);
    for (size_t c = 0; c < nc; ++c) s->cperm[c] = (int)kv[c].c;
    odhs__free(kv);
    for (size_t t = nc; t < cap; ++t) s->cperm[t] = (int)t;
    return ODHS_OK;
}

/* remember the ordering of the analysis just made (s->L; slots 0..Nc-1 =
 * the network's contacts) for pcg_carry; without memory for it, the next
 * analysis orders afresh */
static void pcg_keep_order(pcg_state *s, const odhs_network *net)
{
    size_t nc = net->nc;
    s->on = 0;
    if (odhs__reserve((void **)&s->ord, &s->ordcap, nc, sizeof *s->ord)) return;
    const int *perm = s->L->Perm;
    for (size_t k = 0; k < s->L->n; ++k)
        if ((size_t)perm[k] < nc) s->ord[perm[k]].rank = (int)k; /* free slots have no pair */
    for (size_t c = 0; c < nc; ++c) {
        s->ord[c].i = net->ci[c];
        s->ord[c].j = net->cj[c];
    }
    s->on = nc;
}

/* cholmod_analyze_p of s->A by one method (CHOLMOD_GIVEN with perm, AMD
 * or METIS), or by CHOLMOD's own choice (method < 0); the common's
 * settings as they were afterwards */
static int pcg_cm_analyze(pcg_state *s, int *perm, int method)
{
    int nm = s->c.nmethods, om = s->c.method[0].ordering;
    if (method >= 0) {
        s->c.nmethods = 1;
        s->c.method[0].ordering = method;
    }
    s->L = cholmod_analyze_p(s->A, perm, NULL, 0, &s->c);
    s->c.nmethods = nm;
    s->c.method[0].ordering = om;
    s->status = s->c.status;
    return s->L ? ODHS_OK : odhs__cm_error(&s->c);
}

/* Symbolic analysis of the slot matrix (s->A, cap slots): by "ordering",
 * or, under "ordering_reuse", on the last ordering carried over to the new
 * contacts while its fill per contact stays within "ordering_reuse" times
 * that of the last fresh ordering */
static int pcg_analyze(pcg_state *s, const odhs_network *net, size_t cap)
{
    int st;
    double nc = net->nc ? (double)net->nc : 1.0;
    double bound = s->reuse > 0.0 ? s->reuse : s->reuse < 0.0 && s->fresh_nd ? PCG_ORDERING_REUSE : 0.0;
    if (bound > 0.0 && s->on > 0) {
        if ((st = pcg_carry(s, net, cap)) || (st = pcg_cm_analyze(s, s->cperm, CHOLMOD_GIVEN))) return st;
        if (s->c.lnz / nc <= bound * s->fresh_lnz) {
            pcg_keep_order(s, net);
            return ODHS_OK;
        }
        cholmod_free_factor(&s->L, &s->c); /* grown stale: order afresh */
        s->analyses += 1.0;                 /* the rejected one counts too */
    }
    if ((st = pcg_cm_analyze(s, NULL, s->ordering < 0 ? -1 : s->ordering == 0 ? CHOLMOD_AMD : CHOLMOD_METIS)))
        return st;
    s->orderings += 1.0;
    s->fresh_lnz = s->c.lnz / nc;
    s->fresh_nd = s->c.called_nd;
    if (s->reuse > 0.0 || (s->reuse < 0.0 && s->fresh_nd)) pcg_keep_order(s, net);
    else s->on = 0;
    return ODHS_OK;
}

/* Full factorisation of M for the network's current contacts and geometry:
 * slots 0..Nc-1 hold the contacts in network order, the others are free.
 * The symbolic analysis is reused when nothing but the geometry changed
 * since it was made. */
static int pcg_full(pcg_state *s, const odhs_network *net)
{
    size_t nc = net->nc, n = net->n, extra = pcg_extra(nc), cap = nc + extra;
    size_t nd = n * (size_t)net->dim;
    int st;
    s->valid = 0;
    if (!odhs__cm_fits_int(net, extra)) return ODHS_E_NOMEM;
    if ((st = pcg_slot_arrays(s, cap))) return st;
    if ((st = odhs__reserve((void **)&s->c2s, &s->c2scap, nc, sizeof *s->c2s))) return st;
    if ((st = odhs__reserve((void **)&s->cnt, &s->cntcap, n + 1, sizeof *s->cnt))) return st;
    if ((st = odhs__reserve((void **)&s->snrm, &s->snrmcap, cap * (size_t)net->dim, sizeof *s->snrm)) ||
        (st = odhs__reserve((void **)&s->lnrm, &s->lnrmcap, cap * (size_t)net->dim, sizeof *s->lnrm)))
        return st;

    int numeric_only = !s->reanalyse && (s->L || s->Ls) && s->updates_since_analysis == 0 && s->cap == cap &&
                       s->n == n && s->dim == net->dim;
    for (size_t c = 0; numeric_only && c < nc; ++c)
        if (s->si[c] != net->ci[c] || s->sj[c] != net->cj[c]) numeric_only = 0;

    if ((st = odhs__cm_ensure_sparse(&s->A, cap, nd + extra, 2 * (size_t)net->dim * nc + extra, &s->c))) return st;
    odhs__cm_fill_S(net, extra, s->A, s->cnt);
    if (!numeric_only) {
        if (s->n != n || s->dim != net->dim) s->on = 0; /* another system: nothing to carry */
        cholmod_free_factor(&s->L, &s->c);
        cholmod_free_factor(&s->Ls, &s->c);
        if ((st = pcg_analyze(s, net, cap))) return st;
        if (s->L->is_super) { /* kept: each full factorisation starts from a copy */
            s->Ls = s->L;
            s->L = NULL;
        }
        s->analyses += 1.0;
        s->updates_since_analysis = 0;
        s->reanalyse = 0;
        const int *perm = (s->Ls ? s->Ls : s->L)->Perm;
        for (size_t k = 0; k < cap; ++k) s->pinv[perm[k]] = (int)k;
        /* slots: contacts in network order, the rest free */
        s->cap = cap;
        s->n = n;
        s->dim = net->dim;
        for (size_t c = 0; c < nc; ++c) {
            s->si[c] = net->ci[c];
            s->sj[c] = net->cj[c];
        }
        s->nfree = 0;
        for (size_t t = cap; t-- > nc;) {
            s->si[t] = s->sj[t] = NO_SLOT;
            s->freel[s->nfree++] = t;
        }
    }
    for (size_t c = 0; c < nc; ++c) s->c2s[c] = c;
    memcpy(s->snrm, net->nrm, nc * (size_t)net->dim * sizeof *s->snrm);
    memcpy(s->lnrm, net->nrm, nc * (size_t)net->dim * sizeof *s->lnrm);
    s->nc = nc;
    if (s->Ls) { /* the supernodal route: a fresh copy of the analysis */
        cholmod_free_factor(&s->L, &s->c);
        if (!(s->L = cholmod_copy_factor(s->Ls, &s->c))) return odhs__cm_error(&s->c);
    }
    int ok = odhs__cm_factorize(s->A, NULL, s->L, &s->c, s->openmp);
    if (ok && s->L->is_super && s->c.status == CHOLMOD_OK && s->L->minor == s->L->n)
        /* LL' by supernodes (dense blocks: faster in 3D, slower in 2D, see
         * docs/performance.md) into the simplicial LDL' that the Modify
         * module updates, packed: O(nnz(L)). A failed factorisation is not
         * converted: the check below reports it. */
        ok = cholmod_change_factor(CHOLMOD_REAL, 0, 0, 1, 1, s->L, &s->c);
    s->status = s->c.status;
    s->factorizations += 1.0;
    s->super_last = s->Ls ? 1.0 : 0.0;
    s->since = 0;
    if (!ok || s->c.status < 0) {
        st = odhs__cm_error(&s->c);
        cholmod_free_factor(&s->L, &s->c);
        return st;
    }
    if ((st = odhs__cm_check_factor(s->L, &s->c, s->min_rcond, &s->rcond))) return st;
    if (s->L->is_super || s->L->is_ll) return ODHS_E_INTERNAL; /* Modify needs LDL' */
    s->nnz0 = odhs__cm_factor_nnz(s->L, &s->c);
    s->nzmax0 = (double)s->L->nzmax;
    s->nzmax_packed = s->nzmax0;
    s->valid = 1;
    s->fresh = 1;
    return ODHS_OK;
}

/* particle -> incident contacts of the network (CSR in start/inc) */
static int pcg_incidence(pcg_state *s, const odhs_network *net)
{
    size_t n = net->n, nc = net->nc;
    int st;
    if ((st = odhs__reserve((void **)&s->start, &s->startcap, n + 1, sizeof *s->start)) ||
        (st = odhs__reserve((void **)&s->inc, &s->inccap, 2 * nc, sizeof *s->inc)))
        return st;
    size_t *start = s->start, *inc = s->inc;
    memset(start, 0, (n + 1) * sizeof *start);
    for (size_t c = 0; c < nc; ++c) {
        start[net->ci[c] + 1]++;
        if (net->cj[c] < n) start[net->cj[c] + 1]++;
    }
    for (size_t p = 0; p < n; ++p) start[p + 1] += start[p];
    for (size_t c = 0; c < nc; ++c) {
        inc[start[net->ci[c]]++] = c;
        if (net->cj[c] < n) inc[start[net->cj[c]]++] = c;
    }
    for (size_t p = n; p > 0; --p) start[p] = start[p - 1];
    start[0] = 0;
    return ODHS_OK;
}

/* Add contact c into the free slot t: R = row of M for c against the contacts
 * already in the factor (c2s != NO_SLOT), at permuted positions. */
static int pcg_rowadd(pcg_state *s, const odhs_network *net, size_t c, size_t t)
{
    int d = net->dim;
    const double *nc_ = net->nrm + c * d;
    int *Ri = s->R->i, *Rp = s->R->p;
    double *Rx = s->R->x;
    size_t nz = 0;
    double dd = 0.0;
    for (int k = 0; k < d; ++k) dd += nc_[k] * nc_[k];
    Ri[nz] = s->pinv[t];
    Rx[nz++] = (net->cj[c] < net->n ? 2.0 : 1.0) * dd; /* a wall contact has one block */
    size_t ends[2] = {net->ci[c], net->cj[c]};
    for (int e = 0; e < 2; ++e) {
        size_t p = ends[e];
        if (p >= net->n) continue; /* a wall */
        double sc = p == net->ci[c] ? -1.0 : 1.0;
        for (size_t u = s->start[p]; u < s->start[p + 1]; ++u) {
            size_t c2 = s->inc[u];
            if (c2 == c || s->c2s[c2] == NO_SLOT) continue;
            double s2 = p == net->ci[c2] ? -1.0 : 1.0;
            const double *n2 = net->nrm + c2 * d;
            double dot = 0.0;
            for (int k = 0; k < d; ++k) dot += nc_[k] * n2[k];
            Ri[nz] = s->pinv[s->c2s[c2]];
            Rx[nz++] = sc * s2 * dot;
        }
    }
    Rp[0] = 0;
    Rp[1] = (int)nz;
    s->R->sorted = 0;
    memcpy(s->snrm + t * d, nc_, (size_t)d * sizeof *nc_);
    memcpy(s->lnrm + t * d, nc_, (size_t)d * sizeof *nc_);
    int ok = cholmod_rowadd((size_t)s->pinv[t], s->R, s->L, &s->c);
    s->status = s->c.status;
    s->updates += 1.0;
    s->updates_since_analysis++;
    return ok && s->c.status >= 0 ? ODHS_OK : odhs__cm_error(&s->c);
}

/* per-slot stamps for this setup: seen[t] == stamp marks a matched slot */
static int pcg_stamp(pcg_state *s)
{
    if (s->seencap < s->cap) {
        uint32_t *m = odhs__calloc(s->cap, sizeof *m);
        if (!m) return ODHS_E_NOMEM;
        odhs__free(s->seen);
        s->seen = m;
        s->seencap = s->cap;
        s->stamp = 0;
    }
    if (++s->stamp == 0) {
        memset(s->seen, 0, s->seencap * sizeof *s->seen);
        s->stamp = 1;
    }
    return ODHS_OK;
}

/* Match slots to contacts by their pair: c2s for every contact (NO_SLOT: not
 * in the factor yet), the slots of contacts that are gone into dels; returns
 * their number. A contact keeps its index unless a removal moved the last one
 * into its place, so the slot of the last setup is checked first (a
 * sequential pass); only the slots left over are looked up in the network's
 * pair hash (random access, which costs cache misses once the table outgrows
 * the cache: at N ~ 3000 a lookup per slot and setup took 12% of a shear
 * run). */
static size_t pcg_match(pcg_state *s, const odhs_network *net)
{
    size_t nc = net->nc, pnc = s->nc;
    for (size_t c = 0; c < nc; ++c) {
        size_t t = c < pnc ? s->c2s[c] : NO_SLOT;
        if (t != NO_SLOT && t < s->cap && s->si[t] == net->ci[c] && s->sj[t] == net->cj[c]) s->seen[t] = s->stamp;
        else s->c2s[c] = NO_SLOT;
    }
    size_t ndel = 0;
    for (size_t t = 0; t < s->cap; ++t) {
        if (s->si[t] == NO_SLOT || s->seen[t] == s->stamp) continue;
        size_t k = odhs__net_find(net, s->si[t], s->sj[t]);
        if (k == SIZE_MAX) {
            s->dels[ndel++] = t;
            continue;
        }
        s->c2s[k] = t;
    }
    return ndel;
}

/* did normals move since the last setup (*moved; lnrm is brought up to
 * date), and since their rows went into the factor (*aged)? */
static void pcg_normals(pcg_state *s, const odhs_network *net, int *moved, int *aged)
{
    int d = net->dim, mv = 0, ag = 0;
    size_t bytes = (size_t)d * sizeof *net->nrm;
    for (size_t c = 0; c < net->nc; ++c) {
        size_t t = s->c2s[c];
        if (t == NO_SLOT) continue;
        const double *nk = net->nrm + c * d;
        if (memcmp(s->lnrm + t * d, nk, bytes)) {
            mv = 1;
            memcpy(s->lnrm + t * d, nk, bytes);
        }
        if (!ag && memcmp(s->snrm + t * d, nk, bytes)) ag = 1;
    }
    *moved = mv;
    *aged = ag;
}

/* cholmod_rowdel of the ndel slots in dels, which become free; 1 when an
 * update failed (the caller refactors), else 0 */
static int pcg_delete(pcg_state *s, size_t ndel)
{
    for (size_t q = 0; q < ndel; ++q) {
        size_t t = s->dels[q];
        int ok = cholmod_rowdel((size_t)s->pinv[t], NULL, s->L, &s->c);
        s->status = s->c.status;
        s->updates += 1.0;
        s->updates_since_analysis++;
        if (!ok || s->c.status < 0) return 1;
        s->si[t] = s->sj[t] = NO_SLOT;
        s->freel[s->nfree++] = t;
    }
    return 0;
}

/* The allocation of L passed PCG_NZMAX_GROWTH times the fresh factor's:
 * 1 when the updates must stop (the caller refactors), 0 when they go on.
 * A column of L that outgrows its room moves to the end of the factor and
 * leaves a hole, so the allocation grows faster than the fill: at 2D N = 10^4
 * and 3D N = 8000 it reached 3 times the fresh factor's at a fill (nnz) of
 * 1.3 - 1.55 times, and that bound caused 15 of 18 full factorisations of a
 * 3D shear run (each half a second to two seconds there). Packing the
 * columns (once per growth of the allocation) gathers the holes at the end,
 * where the next columns that grow find room. The updates stop when the
 * fill has doubled (the bound setup also checks afterwards) or when the
 * allocation passes PCG_NZMAX_HARD times the fresh one (the memory bound). */
static int pcg_reclaim(pcg_state *s)
{
    const double nzmax = (double)s->L->nzmax;
    if (nzmax > PCG_NZMAX_HARD * s->nzmax0 + 4096.0) return 1;
    if (!(nzmax > s->nzmax_packed)) return 0;
    if (odhs__cm_factor_nnz(s->L, &s->c) > 2.0 * s->nnz0 + 1000.0) return 1;
    if (!cholmod_pack_factor(s->L, &s->c)) return 1;
    s->packs += 1.0;
    s->nzmax_packed = nzmax;
    return 0;
}

/* cholmod_rowadd of every contact without a slot into a free one: ODHS_OK
 * (*refactor = 1 when an update failed: the caller refactors) or an error */
static int pcg_insert(pcg_state *s, const odhs_network *net, int *refactor)
{
    int st;
    if ((st = pcg_incidence(s, net))) return st;
    if (!s->R || s->R->nrow != s->cap) {
        cholmod_free_sparse(&s->R, &s->c);
        s->R = cholmod_allocate_sparse(s->cap, 1, s->cap, 0, 1, 0, CHOLMOD_REAL, &s->c);
        if (!s->R) return odhs__cm_error(&s->c);
    }
    for (size_t c = 0; c < net->nc; ++c) {
        if (s->c2s[c] != NO_SLOT) continue;
        /* a free slot sits where the last analysis put it, blind to the
         * contact it will hold: many insertions can fill L far beyond the
         * fresh factor. Its allocation (nzmax, O(1) to read) bounds them
         * while they run; setup checks the fill itself afterwards */
        if ((double)s->L->nzmax > PCG_NZMAX_GROWTH * s->nzmax0 + 4096.0 && pcg_reclaim(s)) {
            *refactor = 1;
            return ODHS_OK;
        }
        size_t t = s->freel[--s->nfree];
        if (pcg_rowadd(s, net, c, t)) {
            *refactor = 1;
            return ODHS_OK;
        }
        s->c2s[c] = t;
        s->si[t] = net->ci[c];
        s->sj[t] = net->cj[c];
    }
    return ODHS_OK;
}

static int pcg_setup(void *state, const odhs_network *net)
{
    pcg_state *s = state;
    size_t nc = net->nc;
    int st;
    if (s->reanalyse || !s->valid || !s->L || s->n != net->n || s->dim != net->dim) return pcg_full(s, net);
    if ((st = odhs__reserve((void **)&s->c2s, &s->c2scap, nc, sizeof *s->c2s))) return st;
    if ((st = pcg_stamp(s))) return st;
    s->valid = 0; /* c2s is rewritten: until this setup went through */
    size_t ndel = pcg_match(s, net);
    int moved, aged;
    pcg_normals(s, net, &moved, &aged);
    /* an aged factor is a preconditioner only; count the geometry changes */
    if (aged) s->fresh = 0;
    if (moved) {
        s->since++;
        if (s->refactor_every > 0 && (double)s->since >= s->refactor_every) return pcg_full(s, net);
    }
    size_t nadd = 0;
    for (size_t c = 0; c < nc; ++c) nadd += s->c2s[c] == NO_SLOT;
    if (nadd > s->nfree + ndel || (double)(nadd + ndel) > s->update_max * (double)(nc + 64)) return pcg_full(s, net);
    if (pcg_delete(s, ndel)) return pcg_full(s, net);
    if (nadd) {
        int refactor = 0;
        if ((st = pcg_insert(s, net, &refactor))) return st;
        if (refactor) return pcg_full(s, net);
    }
    s->nc = nc;
    if (ndel + nadd) {
        /* an updated factor of a mixed-geometry (or singular) matrix may have
         * lost definiteness: then start afresh (which also decides whether N
         * itself is singular); likewise when the updates doubled the fill */
        double dmin, dmax;
        if (!odhs__cm_simplicial_pivots(s->L, &dmin, &dmax) || !(dmin > s->min_rcond * dmax)) return pcg_full(s, net);
        if (odhs__cm_factor_nnz(s->L, &s->c) > 2.0 * s->nnz0 + 1000.0) return pcg_full(s, net);
    }
    s->valid = 1;
    return ODHS_OK;
}

/* z = M^{-1} r through the slots */
static int pcg_precond(pcg_state *s, size_t nc, const double *r, double *z)
{
    /* a refactorisation inside the solve may have grown the slot capacity */
    int st = odhs__cm_ensure_dense(&s->work[0], s->cap, &s->c);
    if (st) return st;
    double *bx = s->work[0]->x;
    memset(bx, 0, s->cap * sizeof *bx);
    for (size_t c = 0; c < nc; ++c) bx[s->c2s[c]] = r[c];
    if (!cholmod_solve2(CHOLMOD_A, s->L, s->work[0], NULL, &s->work[1], NULL, &s->work[2], &s->work[3], &s->c))
        return odhs__cm_error(&s->c);
    const double *xx = s->work[1]->x;
    for (size_t c = 0; c < nc; ++c) z[c] = xx[s->c2s[c]];
    return ODHS_OK;
}

/* PCG from the iterate x, at most limit iterations (counted in *it).
 * ODHS_OK, ODHS_E_NOCONV, ODHS_E_SINGULAR (breakdown) or an error. */
static int pcg_run(pcg_state *s, const odhs_network *net, const double *b, double *x, double bn,
                   size_t limit, size_t *it)
{
    size_t nc = net->nc;
    double *r = s->w, *z = r + nc, *p = z + nc, *q = p + nc, *tmp = q + nc;
    double target = s->tol * bn;
    int st;
    for (int restart = 0; restart < 3; ++restart) {
        odhs__net_N(net, x, q, tmp);
        double rn = 0.0;
        for (size_t c = 0; c < nc; ++c) {
            r[c] = b[c] - q[c];
            rn += r[c] * r[c];
        }
        if (sqrt(rn) <= target) return ODHS_OK;
        if ((st = pcg_precond(s, nc, r, z))) return st;
        double rz = 0.0;
        for (size_t c = 0; c < nc; ++c) {
            p[c] = z[c];
            rz += r[c] * z[c];
        }
        if (!(rz > 0.0)) return ODHS_E_SINGULAR;
        size_t k = 0;
        while (sqrt(rn) > target) {
            if (*it >= limit) return ODHS_E_NOCONV;
            odhs__net_N(net, p, q, tmp);
            double pq = 0.0;
            for (size_t c = 0; c < nc; ++c) pq += p[c] * q[c];
            if (!(pq > 0.0)) return ODHS_E_SINGULAR;
            double alpha = rz / pq;
            rn = 0.0;
            for (size_t c = 0; c < nc; ++c) {
                x[c] += alpha * p[c];
                r[c] -= alpha * q[c];
                rn += r[c] * r[c];
            }
            ++*it;
            ++k;
            if (k % 50 == 0) { /* refresh the recursive residual */
                odhs__net_N(net, x, q, tmp);
                rn = 0.0;
                for (size_t c = 0; c < nc; ++c) {
                    r[c] = b[c] - q[c];
                    rn += r[c] * r[c];
                }
            }
            if (sqrt(rn) <= target) break;
            if ((st = pcg_precond(s, nc, r, z))) return st;
            double rz_new = 0.0;
            for (size_t c = 0; c < nc; ++c) rz_new += r[c] * z[c];
            if (!(rz_new > 0.0)) return ODHS_E_SINGULAR;
            double beta = rz_new / rz;
            rz = rz_new;
            for (size_t c = 0; c < nc; ++c) p[c] = z[c] + beta * p[c];
        }
        /* converged on the recursive residual: confirm on the true one (the
         * loop start), restarting from x when they differ */
    }
    return ODHS_OK;
}

static int pcg_solve(void *state, const odhs_network *net, const double *b, double *x)
{
    pcg_state *s = state;
    size_t nc = net->nc, nd = net->n * (size_t)net->dim;
    int st;
    s->iterations = 0.0;
    if (!s->valid || !s->L || s->nc != nc) return ODHS_E_STATE;
    if ((st = odhs__reserve((void **)&s->w, &s->wcap, 4 * nc + nd, sizeof *s->w))) return st;
    if ((st = odhs__cm_ensure_dense(&s->work[0], s->cap, &s->c))) return st;
    double bn = 0.0;
    for (size_t c = 0; c < nc; ++c) bn += b[c] * b[c];
    bn = sqrt(bn);
    if (bn == 0.0) {
        memset(x, 0, nc * sizeof *x);
        return ODHS_OK;
    }
    for (size_t c = 0; c < nc; ++c) /* an unusable guess: start from zero */
        if (!isfinite(x[c])) {
            memset(x, 0, nc * sizeof *x);
            break;
        }
    size_t maxit = s->maxiter > 0 ? (size_t)s->maxiter : 10 * nc + 100, it = 0;
    size_t limit = maxit;
    if (!s->fresh && (double)limit > s->refactor_iterations) limit = (size_t)s->refactor_iterations;
    st = pcg_run(s, net, b, x, bn, limit, &it);
    if (st == ODHS_E_NOCONV || st == ODHS_E_SINGULAR) {
        if (!s->fresh) {
            /* the aged preconditioner is not good enough: refactor at the
             * current geometry and go on from the current iterate */
            for (size_t c = 0; c < nc; ++c)
                if (!isfinite(x[c])) {
                    memset(x, 0, nc * sizeof *x);
                    break;
                }
            int fs = pcg_full(s, net);
            if (fs) {
                s->iterations = (double)it;
                return fs;
            }
            st = pcg_run(s, net, b, x, bn, maxit, &it);
        }
    }
    s->iterations = (double)it;
    return st;
}

ODHS_API const odhs_solver_type odhs_solver_type_cholmod_pcg = {
    .version = ODHS_SOLVER_TYPE_VERSION,
    .name = "cholmod-pcg",
    .flags = ODHS_SOLVER_ITERATIVE | ODHS_SOLVER_USES_GUESS,
    .create = pcg_create,
    .destroy = pcg_destroy,
    .setup = pcg_setup,
    .solve = pcg_solve,
    .set_param = pcg_set_param,
    .get_stat = pcg_get_stat,
    .solve_ls = NULL,
};

#else /* !ODHS_HAVE_SUITESPARSE */

/* ISO C forbids an empty translation unit */
typedef int odhs__cholmod_pcg_not_built;

#endif /* ODHS_HAVE_SUITESPARSE */
