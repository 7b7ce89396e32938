/*
 * libodhs private header: the contact network handle, its kernels (S, S^T, N) and the
 * constrained subset.
 * Not installed.
 */
#ifndef ODHS_NETWORK_NETWORK_H
#define ODHS_NETWORK_NETWORK_H

#include "system/system.h"

#define ODHS__NET_LOG 256

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
    /* the last ODHS__NET_LOG contact changes, for caches that follow the
     * network (the stepper's contact flags of its neighbour pairs,
     * predict.c): change k (counted from 0 since the handle was made) is
     * pair log_i < log_j at k % ODHS__NET_LOG, log_add 1 if it was added and
     * 0 if removed; log_n counts every change. A cache behind by more than
     * ODHS__NET_LOG changes rebuilds. */
    size_t log_i[ODHS__NET_LOG], log_j[ODHS__NET_LOG];
    unsigned char log_add[ODHS__NET_LOG];
    uint64_t log_n;
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
 * of memory */
odhs_network *odhs__net_subnet(const odhs_network *net, const size_t *idx, size_t m, size_t skip);
/* whether particles i and j belong to the same rigid body */
static inline int odhs__same_body(const odhs_network *net, size_t i, size_t j)
{
    return net->rbody && net->rbody[i] != SIZE_MAX && net->rbody[i] == net->rbody[j];
}
/* body-aware constrained subset (only when nperm > 0): fills bcore, bnbar, bncon */
int odhs__net_body_core(const odhs_network *net);
/* the constrained subset after contact (i, j) was added to / removed from
 * the adjacency lists (lib/network/core.c) */
void odhs__net_core_added(odhs_network *net, size_t i, size_t j);
void odhs__net_core_removed(odhs_network *net, size_t i, size_t j);
/* the body-level subset's scratch, allocated once, with the first bond */
int odhs__net_body_reserve(odhs_network *net);

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

/* *excess = constraints in the constrained subset minus its degrees of
 * freedom: 1 for an isostatic subset (potentially jammed), 2 with one more
 * contact; LONG_MIN for an empty subset */
int odhs__net_excess(const odhs_network *net, long *excess);

#endif /* ODHS_NETWORK_NETWORK_H */
