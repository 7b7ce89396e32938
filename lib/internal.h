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
    /* constrained subset (the (d+1)-core of the contact graph), maintained
     * incrementally on every add/remove, in integers */
    size_t **adj;          /* per particle: partners */
    uint32_t *adjn, *adjcap;
    unsigned char *core;   /* 1 = in the constrained subset */
    size_t *cdeg;          /* number of neighbours in the core */
    size_t nbar, ncon;     /* core size, contacts inside the core */
    size_t *work;          /* scratch: queue (n) */
    unsigned char *mark;   /* scratch flags (n) */
    char errmsg[ODHS_ERRMSG_LEN];
};

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
void odhs__solver_invalidate(odhs_solver *s);
int odhs__jam_polish(odhs_system *sys, odhs_network *net, odhs_solver *sol, const double *f0);
int odhs__null_vector(const odhs_network *net, odhs_solver *solver, double *f0, double *residual);

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
};

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
    double *disps;    /* adaptive: displacement record at the start (nd) */
    double Ms[9];
    uint64_t nrejected, nsolves_pred;
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
    size_t snc, scap;
    /* events of the last step */
    odhs_event *ev;
    size_t nev, evcap;
    char errmsg[ODHS_ERRMSG_LEN];
};
