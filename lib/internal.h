/*
 * libodhs internal declarations shared by the implementation files.
 * Not installed; tests may include it (they link the static library).
 */
#ifndef ODHS_INTERNAL_H
#define ODHS_INTERNAL_H

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

/* ---- random numbers: xoshiro256** seeded by splitmix64 --------------- */
typedef struct {
    uint64_t s[4];
} odhs_rng;
void odhs__rng_seed(odhs_rng *r, uint64_t seed);
uint64_t odhs__rng_next(odhs_rng *r);
/* uniform in [0,1) with 53 random bits */
double odhs__rng_uniform(odhs_rng *r);

/* ---- the system -------------------------------------------------------- */
struct odhs_system {
    int dim;
    size_t n;
    double L[3];    /* box edges (L[2] = 1 in 2D) */
    double gamma;   /* Lees-Edwards strain in [-1/2, 1/2] */
    double *x;      /* n*dim lab-frame positions in [0,L) */
    double *r;      /* n radii */
    char (*species)[ODHS_SPECIES_MAX + 1];
    int has_x, has_r;
    double rmax;    /* largest radius (0 if unset) */
    double overlap_accept; /* relative overlap accepted by the setters (0: 1e-10) */
    char errmsg[ODHS_ERRMSG_LEN];
};

/* record an error message on a (logically mutable) handle */
int odhs__syserr(const odhs_system *sys, int status, const char *fmt, ...) ODHS_PRINTF(3, 4);

/* Lees-Edwards remapping: replace b by b -/+ a until |gamma*Ly| <= Lx/2; the
 * lattice (and so the physical configuration) is unchanged. */
static inline double odhs__remap_strain(double gamma, const double *L)
{
    double u = L[0] / L[1];
    double g = gamma - nearbyint(gamma / u) * u;
    /* rounding can leave |g| a hair above u/2 */
    if (g > 0.5 * u) g -= u;
    else if (g < -0.5 * u) g += u;
    return g;
}

/* Wrap one position (dim entries) into the primary lab rectangle, given box
 * and strain. A position already inside is left untouched bit for bit. */
void odhs__wrap(int dim, const double *L, double gamma, double *x);
/* Minimum image of a raw difference d (in place). image (may be NULL)
 * receives the lattice shift that was ADDED, i.e. d_new = d + n0 a + n1 b + n2 c. */
void odhs__min_image(int dim, const double *L, double gamma, double *d, int *image);

/* ---- cell lists -------------------------------------------------------- */
/* Enumerate pairs with centre distance < rcut_pair(i,j) = r_i + r_j + max_gap.
 * Works on raw arrays so the stepper can use it with its own state. */
int odhs__pairs(int dim, size_t n, const double *x, const double *r, double rmax,
                const double *L, double gamma, double max_gap, odhs_pair_fn fn, void *ctx);

#endif /* ODHS_INTERNAL_H */

/* ---- hard walls ------------------------------------------------------------ */
typedef struct {
    int type;     /* ODHS_WALL_* */
    double n[3];  /* plane: unit normal into the allowed side; segment: unit normal of the line */
    double h;     /* plane: particles where n.x >= h */
    double c[3];  /* sphere: centre; segment: end a */
    double b[3];  /* segment: end b */
    double R;     /* sphere: radius (particles inside) */
    double v[3];  /* velocity (translation) */
    double disp[3]; /* displacement since creation */
} odhs_wall;

/* Distance from a particle centre x to the wall surface (positive on the
 * allowed side) and the unit contact normal nrm from the particle towards
 * the wall. Walls are not periodic: for a sphere or a segment the particle
 * is taken at its periodic image nearest to the centre or the middle, so a
 * particle touching it may cross the box boundary; a plane sees the position
 * in the primary cell. The position used goes to ximg when not NULL. */
static inline double odhs__wall_geom(const odhs_wall *w, int dim, const double *L, double gamma, const double *x0,
                                     double *nrm, double *ximg)
{
    double ref[3] = {0, 0, 0}, x[3] = {0, 0, 0};
    for (int k = 0; k < dim; ++k) x[k] = x0[k];
    if (w->type != ODHS_WALL_PLANE) { /* a plane is unbounded: the primary cell's position */
        for (int k = 0; k < dim; ++k) {
            ref[k] = w->type == ODHS_WALL_SPHERE ? w->c[k] : 0.5 * (w->c[k] + w->b[k]);
            x[k] = x0[k] - ref[k];
        }
        odhs__min_image(dim, L, gamma, x, NULL);
        for (int k = 0; k < dim; ++k) x[k] += ref[k];
    }
    if (ximg)
        for (int k = 0; k < dim; ++k) ximg[k] = x[k];
    if (w->type == ODHS_WALL_PLANE) {
        double s = -w->h;
        for (int k = 0; k < dim; ++k) {
            s += w->n[k] * x[k];
            nrm[k] = -w->n[k];
        }
        return s;
    }
    double p[3] = {0, 0, 0};
    if (w->type == ODHS_WALL_SPHERE) {
        double r2 = 0.0;
        for (int k = 0; k < dim; ++k) {
            p[k] = x[k] - w->c[k];
            r2 += p[k] * p[k];
        }
        double r = sqrt(r2);
        for (int k = 0; k < dim; ++k) nrm[k] = r > 0.0 ? p[k] / r : (k == 0 ? 1.0 : 0.0);
        return w->R - r;
    }
    /* segment: closest point q = a + t (b - a), t in [0,1] */
    double ab[3] = {0, 0, 0}, ax[3] = {0, 0, 0}, l2 = 0.0, t = 0.0;
    for (int k = 0; k < dim; ++k) {
        ab[k] = w->b[k] - w->c[k];
        ax[k] = x[k] - w->c[k];
        l2 += ab[k] * ab[k];
        t += ab[k] * ax[k];
    }
    t = l2 > 0.0 ? t / l2 : 0.0;
    t = t < 0.0 ? 0.0 : (t > 1.0 ? 1.0 : t);
    double r2 = 0.0;
    for (int k = 0; k < dim; ++k) {
        p[k] = w->c[k] + t * ab[k] - x[k];
        r2 += p[k] * p[k];
    }
    double r = sqrt(r2);
    for (int k = 0; k < dim; ++k) nrm[k] = r > 0.0 ? p[k] / r : 0.0;
    return r;
}

/* ---- contact network ----------------------------------------------------- */
struct odhs_network {
    int dim;
    size_t n;        /* particles */
    size_t nc, cap;  /* contacts, capacity */
    size_t *ci, *cj; /* pair, ci < cj */
    int *kind;
    double *nrm;     /* cap*dim unit normals i -> j */
    double *dist;    /* |R_ij| */
    double *gap;     /* |R_ij| - (a_i + a_j) */
    double *f;       /* forces */
    size_t hcap;     /* hash: power of two, linear probing */
    uint64_t *hkey;  /* 0 = empty, else i*n + j + 1 */
    size_t *hval;
    uint64_t version; /* bumped on every change of contacts or geometry */
    /* constrained subset (the (d+1)-core of the contact graph), in integers:
     * peeled incrementally on every removal, rebuilt lazily after additions */
    size_t **adj;          /* per particle: partners */
    uint32_t *adjn, *adjcap;
    unsigned char *core;   /* 1 = in the constrained subset */
    size_t *cdeg;          /* number of neighbours in the core */
    size_t nbar, ncon;     /* core size, contacts inside the core */
    int core_stale;        /* contacts added since: the core may have grown (rebuilt on query) */
    size_t *work;          /* scratch: queue (n) */
    /* composites (Sect. V C); untouched by scenes without permanent contacts */
    double *rest;          /* cap: rest length of each permanent contact (NAN: a_i + a_j) */
    size_t nperm;          /* number of permanent contacts */
    size_t *rbody;         /* NULL, or n rigid-body labels (SIZE_MAX: not in a rigid body) */
    /* constrained subset on bodies (connected components of the permanent
     * contacts), recomputed on demand when nperm > 0; cached by version */
    uint64_t topo;         /* bumped when contacts are added, removed or change kind */
    uint64_t work_composite; /* passes of composite-only code (odhs_stepper_feature_work) */
    /* hard walls: contacts (i, n + w) of kind ODHS_CONTACT_WALL; the per-node
     * arrays (adj, core, cdeg, work) have room for n + nwalls nodes and
     * wall nodes are always in the constrained subset */
    odhs_wall *walls;
    size_t nwalls;
    size_t free_modes;       /* global zero modes: d without walls */
    uint64_t work_walls;     /* passes of wall-only code */
    int bc_valid;
    uint64_t bc_topo;
    unsigned char *bcore;  /* n flags */
    size_t *bc_mem;        /* scratch of the body-level subset (8n + 2), allocated with the first bond */
    unsigned char *bc_in;  /* scratch (n) */
    size_t bnbar, bncon;
    char errmsg[ODHS_ERRMSG_LEN];
};

/* target distance of contact c: a_i + a_j, or a permanent contact's rest length */
static inline double odhs__net_sigma(const odhs_network *net, const odhs_system *sys, size_t c)
{
    if (net->nwalls && net->cj[c] >= net->n) return sys->r[net->ci[c]];
    if (net->nperm && net->kind[c] == ODHS_CONTACT_PERMANENT && !isnan(net->rest[c])) return net->rest[c];
    return sys->r[net->ci[c]] + sys->r[net->cj[c]];
}
/* contacts that open when their force would be negative */
static inline int odhs__can_open(int kind) { return kind != ODHS_CONTACT_PERMANENT; }
/* add a wall to a network (grows the per-node arrays) */
int odhs__net_add_wall(odhs_network *net, const odhs_wall *w);
/* give a scratch copy `sub` of net's particles the same walls */
int odhs__net_copy_walls(odhs_network *sub, const odhs_network *net);
/* a scratch network with net's walls and its contacts idx[0..m-1] (every
 * contact if idx is NULL), leaving out position `skip` of that list
 * (SIZE_MAX: none), kinds, rest lengths and geometry copied; NULL when out
 * of memory (lib/jamming.c) */
odhs_network *odhs__net_subnet(const odhs_network *net, const size_t *idx, size_t m, size_t skip);
/* whether particles i and j belong to the same rigid body */
static inline int odhs__same_body(const odhs_network *net, size_t i, size_t j)
{
    return net->rbody && net->rbody[i] != SIZE_MAX && net->rbody[i] == net->rbody[j];
}
/* body-aware constrained subset (only when nperm > 0): fills bcore, bnbar, bncon */
int odhs__net_body_core(const odhs_network *net);

odhs_network *odhs__net_new(int dim, size_t n);
int odhs__neterr(const odhs_network *net, int status, const char *fmt, ...) ODHS_PRINTF(3, 4);
/* index of (i,j) (i<j) or SIZE_MAX */
size_t odhs__net_find(const odhs_network *net, size_t i, size_t j);
/* add without checks beyond capacity; returns index or SIZE_MAX on NOMEM */
size_t odhs__net_add(odhs_network *net, size_t i, size_t j, int kind);
/* remove contact at index k (last contact moves to k) */
void odhs__net_remove_at(odhs_network *net, size_t k);
/* geometry of contact k from raw state */
void odhs__net_geometry(odhs_network *net, const odhs_system *sys);
/* fast kernels */
void odhs__net_S(const odhs_network *net, const double *v, double *out);
void odhs__net_ST(const odhs_network *net, const double *f, double *out);
void odhs__net_N(const odhs_network *net, const double *x, double *out, double *work);

/* restored stepper: mark the neighbour list stale unless it holds every pair
 * closer than the unused skin (lib/stepper.c); ODHS_OK or ODHS_E_NOMEM */
int odhs__stepper_check_neighbours(odhs_stepper *st);
/* tests: 1 = always the anti-cycling rewiring, 0 = the paper's rule first */
int odhs__stepper_set_rewire_mode(odhs_stepper *st, int mode);

/* ---- solver handle ----------------------------------------------------------- */
struct odhs_solver {
    const odhs_solver_type *type;
    void *state;
    const odhs_network *last_net;
    uint64_t last_version;
    uint64_t last_sum; /* checksum of the operator last set up (public path) */
    int have_setup;
    double check_tol;
    int refine;        /* iterative refinement steps for direct backends */
    double last_residual;
    double last_backward; /* normwise backward error of the last solve */
    double nsolves;
    double *work;    /* residual check */
    size_t work_cap;
    /* fallback (odhs_solver_set_fallback): borrowed solver tried when a solve
     * fails with ODHS_E_NOCONV or ODHS_E_SINGULAR */
    struct odhs_solver *fallback;
    double nfallbacks, nrescued; /* solves handed over / rescued by it */
    int last_fallback;           /* the last solve was handed over */
    char errmsg[ODHS_ERRMSG_LEN];
};

/* Solve N x = b. reuse = 1: skip the backend setup when this network's
 * version is the one last set up (callers that own the network and call
 * odhs__solver_invalidate when it may have been replaced); reuse = 0: set up
 * whenever the backend has a setup. */
int odhs__solver_solve(odhs_solver *s, const odhs_network *net, const double *b, double *x, int reuse);
/* the same with a relative residual of rtol where the backend has a "tol" */
int odhs__solver_solve_relaxed(odhs_solver *s, const odhs_network *net, const double *b, double *x, double rtol);
void odhs__solver_invalidate(odhs_solver *s);
int odhs__jam_polish(odhs_system *sys, odhs_network *net, odhs_solver *sol, const double *f0);
/* the self-stress h of an isostatic network plus a pair (i, j) outside it,
 * h = 1 on the pair, <h|r> = 0 (lib/jamming.c) */
int odhs__jam_pair_stress(const odhs_network *net, odhs_solver *sol, const double *f0, size_t i, size_t j,
                          const double *nrm, double dist, double *h);
int odhs__null_vector(const odhs_network *net, odhs_solver *solver, double *f0, double *residual);
/* fixed pressure: the kernel vector fs of S^T with <r|fs> = 0 (the volume as
 * one more column of S) on a constrained subset with d(Nbar - 1) + 2
 * contacts, max |fs| = 1, sign undetermined; by the SVD of that matrix
 * (lib/jamming.c) */
int odhs__null_vector_volume(const odhs_network *net, double *fs);
/* *excess = constraints in the constrained subset minus its degrees of
 * freedom: 1 for an isostatic subset (potentially jammed), 2 with one more
 * contact; LONG_MIN for an empty subset */
int odhs__net_excess(const odhs_network *net, long *excess);

/* ---- driver ---------------------------------------------------------------- */
struct odhs_driver {
    double xi0;
    double gdot;       /* shear rate */
    double crate;      /* compression rate */
    int pressure_on;
    double p;
    double kappa_max;
    double *F;         /* fixed forces or NULL */
    size_t Fn;
    int Fdim;
    odhs_force_fn fn;
    void *fn_ctx;
    double tau_user;   /* 0 = unset */
    uint64_t version;  /* bumped by every setter: steppers re-solve on change */
    char errmsg[ODHS_ERRMSG_LEN];
    /* self-propulsion (Sect. V B); switches do not bump version: the stepper
     * applies them at the end of the step that reaches the switch time */
    int prop_on, prop_started;
    size_t pn;
    int pdim;
    double pfmin, pfmax, ptmin, ptmax;
    odhs_rng prng;
    double *pF;        /* pn*pdim current propulsion forces */
    double *pts;       /* pn switch times (before the start: persistence in units of tau_p) */
    odhs_rng prng_b;   /* copy for the stepper's rollback */
    int pstarted_b;
    double *pF_b, *pts_b;
    /* gravity */
    int grav_on, gdim;
    double g[3];
    double *gw;        /* gwn weights, or NULL: (a_i/<a>)^d */
    size_t gwn;
};

/* propulsion and gravity (lib/driver.c) */
double odhs__prop_fp(const odhs_driver *d);               /* sqrt(<|F_p|^2>) */
/* allocate the propulsion arrays for n particles in dim (frees old ones) */
int odhs__prop_alloc(odhs_driver *d, size_t n, int dim);
/* start the clock at time t (no-op when off or started) */
void odhs__prop_start(odhs_driver *d, double t, double lambda);
/* earliest switch time; INFINITY when off or not started */
double odhs__prop_next(const odhs_driver *d);
/* redraw every particle whose switch time is <= t, new switch at t + tau_p u */
void odhs__prop_switch(odhs_driver *d, double t, double lambda);
void odhs__prop_save(odhs_driver *d);
void odhs__prop_restore(odhs_driver *d);
/* settings consistent with a system of n particles in dim? ODHS_OK or ODHS_E_DIM */
int odhs__driver_check_extra(const odhs_driver *d, size_t n, int dim);
/* add propulsion and gravity to F (zeroed first when *has == 0; *has set when
 * anything was added). ODHS_E_DIM when the settings do not fit sys. */
int odhs__driver_extra_forces(const odhs_driver *d, const odhs_system *sys, double *F, int *has);

/* ---- stepper ------------------------------------------------------------------ */
typedef struct {
    size_t i, j;
    int delta; /* +1 added, -1 removed */
} odhs_change;

struct odhs_stepper {
    odhs_system *sys;
    odhs_driver *drv;
    odhs_solver *sol;
    odhs_network *net;
    int dim;
    size_t n, nd;
    /* settings */
    double dt;
    int integrator;   /* ODHS_INTEGRATOR_* */
    double tol;       /* adaptive: error per step, relative to the mean diameter */
    double h;         /* adaptive: current step in units of tau */
    double lambda;    /* mean diameter */
    double *U0, *Ua;  /* adaptive: velocities at the start, averaged (nd) */
    double *Up;       /* adaptive: predictor velocities U* of the accepted step (nd) */
    double Gp[9], taup; /* ... its gradient and step length */
    int pred_ok;      /* Up, Gp, taup belong to the current step */
    int corr_user;    /* the correction interval was set (not the integrator's default) */
    double *disps;    /* adaptive: displacement record at the start (nd) */
    double Ms[9];
    uint64_t nrejected, nsolves_pred;
    uint64_t work_pressure; /* pressure-control solves (odhs_stepper_feature_work) */
    unsigned corr_every;
    double contact_tol;
    odhs_event_fn evfn;
    void *evctx;
    /* state */
    int ready, jammed;
    double time, strain;
    uint64_t nsteps, ncoll, nopen;
    double tau;       /* natural time unit */
    uint64_t drv_version; /* driver version the current forces were solved for */
    double G[9];      /* velocity gradient of the affine flow, row-major */
    double kappa;
    double *F;        /* external forces at the current time (nd) */
    int has_F;
    double *U;        /* non-affine velocities (nd) */
    double *tmp;      /* nd work */
    double *cb, *cx;  /* contact-space work */
    size_t ccap;
    /* neighbour list */
    size_t *pi, *pj;
    size_t npairs, pcap;
    double skin, rc;
    double *disp;     /* non-affine displacement since the last build (nd) */
    double M[9];      /* affine deformation since the last build */
    /* rewiring */
    odhs_change *rem; /* pairs removed during the current rewiring */
    size_t nrem, remcap;
    int rewire_mode;            /* 0: paper's rule, anti-cycling takeover; 1: anti-cycling only (tests) */
    uint64_t nrewire_monotone;  /* rewirings the anti-cycling method finished (not checkpointed) */
    uint64_t njam_pivots;       /* pivots of jam_finish on the final packing (not checkpointed) */
    /* fixed pressure on a potentially jammed network: net->f = freg + alpha f0
     * with f0 then freg in fpj (2 nc); pj_bordered while net->f is of that form */
    double *fpj;
    size_t fpjcap;
    uint64_t fpj_version; /* net->version of the f0 in fpj (0: none) */
    int pj_bordered;
    odhs_change *chg;
    size_t nchg, chgcap;
    /* rollback snapshot: xs holds 3 nd doubles, positions then Us, Fs */
    double *xs, *Us, *Fs; /* Us, Fs: velocities and external forces */
    int has_Fs;
    double Ls[3], gammas, times, strains, kappas;
    uint64_t nsteps_s;
    double Gs[9];
    int nb_stale;
    size_t *sci, *scj;
    int *skind;
    double *sf;
    double *srest;    /* rest lengths (copied only with permanent contacts) */
    odhs_wall *wsnap; /* walls at the snapshot */
    size_t wsnapcap;
    size_t snc, scap;
    /* events of the last step */
    odhs_event *ev;
    size_t nev, evcap;
    char errmsg[ODHS_ERRMSG_LEN];
};
