/* libodhs - contact network: the constrained subset (the (d+1)-core of the
 * contact graph, kept up to date incrementally), its body-level form with
 * permanent contacts, rattlers and the excess of constraints. */
#include <limits.h>
#include <string.h>

#include "network/network.h"

/* ---- the constrained subset, incrementally -------------------------------
 * The constrained subset of Sect. IV D is the (d+1)-core of the contact graph:
 * the largest set of particles each with at least d+1 contacts inside it. It
 * only grows when a contact is added and only shrinks when one is removed.
 * Invariant: cdeg[x] = number of partners of x in the core, for every x. */

/* peel core members whose core degree fell below d+1, starting from queue */
static void core_peel(odhs_network *net, size_t qt)
{
    size_t need = (size_t)net->dim + 1, qh = 0, *q = net->work;
    while (qh < qt) {
        size_t x = q[qh++];
        if (x >= net->n || !net->core[x] || net->cdeg[x] >= need) continue; /* walls stay */
        net->core[x] = 0;
        net->nbar--;
        for (uint32_t k = 0; k < net->adjn[x]; ++k) {
            size_t y = net->adj[x][k];
            net->cdeg[y]--;
            if (net->core[y]) {
                net->ncon--;
                /* pushed once, when its core degree first drops below d+1:
                 * with the two seeds the queue holds at most n + 2 */
                if (net->cdeg[y] == need - 1) q[qt++] = y;
            }
        }
    }
}

/* A contact added outside the core can only make the core grow. The growth
 * is not searched for here: a search from the new contact walks the whole
 * non-core cluster (O(N) per contact, O(N^2) for a network built contact by
 * contact). The core is marked stale instead and rebuilt once, in O(N + Nc),
 * by the next query (core_ensure). The stale core stays a valid set (every
 * member keeps d+1 partners inside it), so removals keep updating it. */
void odhs__net_core_added(odhs_network *net, size_t i, size_t j)
{
    size_t need = (size_t)net->dim + 1;
    if (net->core[i] && net->core[j]) {
        net->cdeg[i]++;
        net->cdeg[j]++;
        net->ncon++;
        return;
    }
    if (net->core[i]) net->cdeg[j]++;
    if (net->core[j]) net->cdeg[i]++;
    if ((!net->core[i] && net->adjn[i] >= need) || (!net->core[j] && net->adjn[j] >= need)) net->core_stale = 1;
}

/* rebuild the core from scratch: every node in, then peel (O(N + Nc)) */
static void core_ensure(const odhs_network *cnet)
{
    odhs_network *net = (odhs_network *)cnet; /* a cache: the set is a function of the contacts */
    if (!net->core_stale) return;
    size_t need = (size_t)net->dim + 1, nn = net->n + net->nwalls, qt = 0;
    for (size_t x = 0; x < nn; ++x) {
        net->core[x] = 1;
        net->cdeg[x] = net->adjn[x];
        if (x < net->n && net->cdeg[x] < need) net->work[qt++] = x;
    }
    net->nbar = net->n;
    net->ncon = net->nc;
    core_peel(net, qt);
    net->core_stale = 0;
}

void odhs__net_core_removed(odhs_network *net, size_t i, size_t j)
{
    if (net->core[i] && net->core[j]) {
        net->ncon--;
        net->cdeg[i]--;
        net->cdeg[j]--;
        net->work[0] = i;
        net->work[1] = j;
        core_peel(net, 2);
        return;
    }
    if (net->core[i]) net->cdeg[j]--;
    if (net->core[j]) net->cdeg[i]--;
}

/* the body-level subset's arrays, allocated once, with the first bond */
int odhs__net_body_reserve(odhs_network *net)
{
    size_t n = net->n ? net->n : 1;
    if (!net->bcore && !(net->bcore = odhs__malloc_array(n, 1))) return ODHS_E_NOMEM;
    if (!net->bc_in && !(net->bc_in = odhs__malloc_array(n, 1))) return ODHS_E_NOMEM;
    if (!net->bc_mem && !(net->bc_mem = odhs__malloc_array(8 * n + 2, sizeof *net->bc_mem))) return ODHS_E_NOMEM;
    return ODHS_OK;
}

/* ---- the constrained subset with composite bodies -------------------------
 * With permanent contacts the unit of the (d+1)-core is a body: a connected
 * component of the permanent-contact graph (a single particle otherwise). A
 * body of k beads held by p permanent (and q internal temporary) contacts has
 * dof = d k - p - q degrees of freedom (at least those of a rigid body: d for a
 * single particle, 3 in 2D and 5 (dimer) or 6 in 3D otherwise) and needs dof + 1
 * contacts with other constrained bodies; a particle is the case k = 1, dof =
 * d. Removal is iterated to a fixed point as for particles. Counts in integers.
 * Recomputed from scratch (O(N + Nc)) when the network changed: only scenes
 * with permanent contacts pay for it. */
static size_t uf_find(size_t *parent, size_t x)
{
    while (parent[x] != x) {
        parent[x] = parent[parent[x]];
        x = parent[x];
    }
    return x;
}

/* views into the body-level subset's scratch (bc_mem, bc_in) */
typedef struct {
    size_t *parent, *bid, *start, *beads, *kb, *dof, *cnt, *q;
    unsigned char *in;
    size_t nb; /* number of bodies */
} body_work;

/* bodies: connected components of the permanent contacts, labelled 0..nb-1
 * in bid (parent: union-find forest) */
static void body_label(const odhs_network *net, body_work *w)
{
    size_t n = net->n, *parent = w->parent, *bid = w->bid;
    for (size_t i = 0; i < n; ++i) parent[i] = i;
    for (size_t c = 0; c < net->nc; ++c)
        if (net->kind[c] == ODHS_CONTACT_PERMANENT) {
            size_t a = uf_find(parent, net->ci[c]), b = uf_find(parent, net->cj[c]);
            if (a != b) parent[a < b ? b : a] = a < b ? a : b;
        }
    size_t nb = 0;
    for (size_t i = 0; i < n; ++i) {
        size_t r = uf_find(parent, i);
        bid[i] = r == i ? nb++ : bid[r]; /* roots are the smallest index of their body */
    }
    w->nb = nb;
}

/* members of every body (CSR in start/beads, kb beads each) and its degrees
 * of freedom (dof), contacts to other bodies in cnt */
static void body_members(const odhs_network *net, body_work *w)
{
    size_t n = net->n, d = (size_t)net->dim, nb = w->nb;
    size_t *bid = w->bid, *start = w->start, *beads = w->beads, *kb = w->kb, *dof = w->dof, *cnt = w->cnt;
    for (size_t b = 0; b <= nb; ++b) start[b] = 0;
    for (size_t b = 0; b < nb; ++b) kb[b] = dof[b] = cnt[b] = 0;
    for (size_t i = 0; i < n; ++i) start[bid[i] + 1]++;
    for (size_t b = 0; b < nb; ++b) start[b + 1] += start[b];
    for (size_t i = 0; i < n; ++i) beads[start[bid[i]] + kb[bid[i]]++] = i;
    /* constraints inside each body (permanent + internal temporary) and
     * contacts to other bodies */
    size_t *inner = w->q; /* reused as the queue afterwards */
    for (size_t b = 0; b < nb; ++b) inner[b] = 0;
    for (size_t c = 0; c < net->nc; ++c) {
        if (net->cj[c] >= n) { /* a wall: never leaves the subset */
            cnt[bid[net->ci[c]]]++;
            continue;
        }
        size_t a = bid[net->ci[c]], b = bid[net->cj[c]];
        if (a == b) inner[a]++;
        else {
            cnt[a]++;
            cnt[b]++;
        }
    }
    for (size_t b = 0; b < nb; ++b) {
        size_t k = kb[b], lo = k == 1 ? d : (d == 2 ? 3 : (k == 2 ? 5 : 6));
        size_t f = d * k > inner[b] ? d * k - inner[b] : 0;
        dof[b] = f > lo ? f : lo;
    }
}

/* remove bodies with fewer than dof + 1 contacts to bodies still in, to a
 * fixed point: in[b] = 1 for the bodies left */
static void body_peel(const odhs_network *net, body_work *w)
{
    size_t n = net->n, nb = w->nb;
    size_t *bid = w->bid, *start = w->start, *beads = w->beads, *dof = w->dof, *cnt = w->cnt, *q = w->q;
    unsigned char *in = w->in;
    size_t qt = 0, qh = 0;
    for (size_t b = 0; b < nb; ++b) {
        in[b] = 1;
        if (cnt[b] < dof[b] + 1) {
            in[b] = 2; /* queued */
            q[qt++] = b;
        }
    }
    while (qh < qt) {
        size_t b = q[qh++];
        in[b] = 0;
        for (size_t p = start[b]; p < start[b + 1]; ++p) {
            size_t x = beads[p];
            for (uint32_t k = 0; k < net->adjn[x]; ++k) {
                if (net->adj[x][k] >= n) continue; /* walls */
                size_t o = bid[net->adj[x][k]];
                if (o == b || in[o] != 1) continue;
                if (--cnt[o] < dof[o] + 1) {
                    in[o] = 2;
                    q[qt++] = o;
                }
            }
        }
    }
}

int odhs__net_body_core(const odhs_network *cnet)
{
    odhs_network *net = (odhs_network *)cnet; /* cache only */
    if (net->bc_valid && net->bc_topo == net->topo) return ODHS_OK;
    net->work_composite++;
    size_t n = net->n;
    /* scratch allocated with the first bond (odhs__net_body_reserve), so that
     * queries never allocate: parent, bid, start (n+1), beads, kb, dof, cnt,
     * queue */
    if (!net->bcore || !net->bc_mem || !net->bc_in) return ODHS_E_INTERNAL;
    size_t *mem = net->bc_mem;
    body_work w = {.parent = mem, .bid = mem + n, .start = mem + 2 * n, .beads = mem + 3 * n + 1,
                   .kb = mem + 4 * n + 1, .dof = mem + 5 * n + 1, .cnt = mem + 6 * n + 1, .q = mem + 7 * n + 1,
                   .in = net->bc_in, .nb = 0};
    body_label(net, &w);
    body_members(net, &w);
    body_peel(net, &w);
    size_t nbar = 0, ncon = 0;
    for (size_t i = 0; i < n; ++i) {
        net->bcore[i] = w.in[w.bid[i]] == 1;
        nbar += net->bcore[i];
    }
    for (size_t c = 0; c < net->nc; ++c)
        ncon += net->bcore[net->ci[c]] && (net->cj[c] >= n || net->bcore[net->cj[c]]);
    net->bnbar = nbar;
    net->bncon = ncon;
    net->bc_valid = 1;
    net->bc_topo = net->topo;
    return ODHS_OK;
}

int odhs_network_constrained(const odhs_network *net, size_t *nbar, size_t *ncon,
                             unsigned char *in_subset, long *zbar_num)
{
    if (!net) return ODHS_E_NULL;
    core_ensure(net);
    size_t nb = net->nbar, nk = net->ncon;
    const unsigned char *core = net->core;
    if (net->nperm) {
        int st = odhs__net_body_core(net);
        if (st) return odhs__neterr(net, st, "out of memory");
        nb = net->bnbar;
        nk = net->bncon;
        core = net->bcore;
    }
    if (nbar) *nbar = nb;
    if (ncon) *ncon = nk;
    if (zbar_num) *zbar_num = nb ? 2L * (net->dim - 1) + 2L * (long)nk : 0;
    if (in_subset) memcpy(in_subset, core, net->n);
    return ODHS_OK;
}

int odhs_network_rattlers(const odhs_network *net, unsigned char *is_rattler, size_t *count)
{
    if (!net) return ODHS_E_NULL;
    size_t nbar;
    int st = odhs_network_constrained(net, &nbar, NULL, is_rattler, NULL);
    if (st) return st;
    if (is_rattler)
        for (size_t i = 0; i < net->n; ++i) is_rattler[i] = !is_rattler[i];
    if (count) *count = net->n - nbar;
    return ODHS_OK;
}

int odhs__net_excess(const odhs_network *net, long *excess)
{
    core_ensure(net);
    size_t nb = net->nbar, nk = net->ncon;
    if (net->nperm) {
        int st = odhs_network_constrained(net, &nb, &nk, NULL, NULL);
        if (st) return st;
    }
    /* isostatic: d Nbar - (global zero modes) constraints; one more is a
     * self-stress. Without walls the zero modes are the d translations. */
    *excess = nb == 0 ? LONG_MIN : (long)(nk + net->free_modes) - (long)((size_t)net->dim * nb);
    return ODHS_OK;
}

int odhs_network_potentially_jammed(const odhs_network *net, int *flag)
{
    if (!net) return ODHS_E_NULL;
    if (!flag) return odhs__neterr(net, ODHS_E_NULL, "output pointer is NULL");
    long e;
    int st = odhs__net_excess(net, &e);
    if (st) return st;
    *flag = e >= 1;
    return ODHS_OK;
}
