/* libodhs - contact network: the handle, its pair hash, adding and removing
 * contacts, geometry and detection, the operator S (S, S^T, N), bonds and
 * walls. The constrained subset is in core.c. */
#include <math.h>
#include <string.h>

#include "network/network.h"

int odhs__neterr(const odhs_network *net, int status, const char *fmt, ...)
{
    if (!net) return status;
    va_list ap;
    va_start(ap, fmt);
    odhs__verr(((odhs_network *)net)->errmsg, status, fmt, ap);
    va_end(ap);
    return status;
}

static inline uint64_t pair_key(const odhs_network *net, size_t i, size_t j)
{
    if (j >= net->n) /* wall contact (i, n + w): a key range of its own */
        return ((uint64_t)1 << 62) + (uint64_t)(j - net->n) * (uint64_t)net->n + (uint64_t)i + 1u;
    return (uint64_t)i * (uint64_t)net->n + (uint64_t)j + 1u;
}

static inline size_t hash_slot(uint64_t key, size_t mask)
{
    key ^= key >> 33;
    key *= 0xff51afd7ed558ccdULL;
    key ^= key >> 33;
    return (size_t)key & mask;
}

static int hash_resize(odhs_network *net, size_t hcap)
{
    uint64_t *k = odhs__calloc(hcap, sizeof *k);
    size_t *v = odhs__malloc_array(hcap, sizeof *v);
    if (!k || !v) {
        odhs__free(k);
        odhs__free(v);
        return ODHS_E_NOMEM;
    }
    size_t mask = hcap - 1;
    for (size_t c = 0; c < net->nc; ++c) {
        uint64_t key = pair_key(net, net->ci[c], net->cj[c]);
        size_t s = hash_slot(key, mask);
        while (k[s]) s = (s + 1) & mask;
        k[s] = key;
        v[s] = c;
    }
    odhs__free(net->hkey);
    odhs__free(net->hval);
    net->hkey = k;
    net->hval = v;
    net->hcap = hcap;
    return ODHS_OK;
}

static int grow(odhs_network *net)
{
    size_t cap = net->cap ? 2 * net->cap : 64;
    int d = net->dim;
    size_t *ci = odhs__realloc(net->ci, cap * sizeof *ci);
    if (ci) net->ci = ci;
    size_t *cj = odhs__realloc(net->cj, cap * sizeof *cj);
    if (cj) net->cj = cj;
    int *kind = odhs__realloc(net->kind, cap * sizeof *kind);
    if (kind) net->kind = kind;
    double *nrm = odhs__realloc(net->nrm, cap * d * sizeof *nrm);
    if (nrm) net->nrm = nrm;
    double *dist = odhs__realloc(net->dist, cap * sizeof *dist);
    if (dist) net->dist = dist;
    double *gap = odhs__realloc(net->gap, cap * sizeof *gap);
    if (gap) net->gap = gap;
    double *f = odhs__realloc(net->f, cap * sizeof *f);
    if (f) net->f = f;
    double *rest = odhs__realloc(net->rest, cap * sizeof *rest);
    if (rest) net->rest = rest;
    if (!ci || !cj || !kind || !nrm || !dist || !gap || !f || !rest) return ODHS_E_NOMEM;
    /* the capacity counts only once the hash table fits it too: a full
     * table would make every lookup probe forever */
    if (net->hcap < 2 * cap) {
        int st = hash_resize(net, 4 * cap);
        if (st) return st;
    }
    net->cap = cap;
    return ODHS_OK;
}

odhs_network *odhs__net_new(int dim, size_t n)
{
    odhs_network *net = odhs__calloc(1, sizeof *net);
    if (!net) return NULL;
    net->dim = dim;
    net->n = n;
    net->free_modes = (size_t)dim;
    net->adj = odhs__calloc(n, sizeof *net->adj);
    net->adjn = odhs__calloc(n, sizeof *net->adjn);
    net->adjcap = odhs__calloc(n, sizeof *net->adjcap);
    net->core = odhs__calloc(n, 1);
    net->cdeg = odhs__calloc(n, sizeof *net->cdeg);
    net->work = odhs__calloc(2 * n + 2, sizeof *net->work);
    if (!net->adj || !net->adjn || !net->adjcap || !net->core || !net->cdeg || !net->work ||
        grow(net)) {
        odhs_network_destroy(net);
        return NULL;
    }
    return net;
}

static int network_create_impl(const odhs_system *sys, odhs_network **out)
{
    if (!out) return odhs__create_err(ODHS_E_NULL, "odhs_network_create: out is NULL");
    *out = NULL;
    if (!sys) return odhs__create_err(ODHS_E_NULL, "odhs_network_create: system is NULL");
    *out = odhs__net_new(sys->dim, sys->n);
    return *out ? ODHS_OK : odhs__create_err(ODHS_E_NOMEM, "odhs_network_create: out of memory (N = %zu)", sys->n);
}

int odhs_network_create(const odhs_system *sys, odhs_network **out)
{
    odhs__create_begin();
    return odhs__create_end(network_create_impl(sys, out));
}

void odhs_network_destroy(odhs_network *net)
{
    if (!net) return;
    odhs__free(net->ci);
    odhs__free(net->cj);
    odhs__free(net->kind);
    odhs__free(net->nrm);
    odhs__free(net->dist);
    odhs__free(net->gap);
    odhs__free(net->f);
    odhs__free(net->rest);
    odhs__free(net->rbody);
    odhs__free(net->bcore);
    odhs__free(net->bc_mem);
    odhs__free(net->bc_in);
    odhs__free(net->hkey);
    odhs__free(net->hval);
    if (net->adj)
        for (size_t i = 0; i < net->n + net->nwalls; ++i) odhs__free(net->adj[i]);
    odhs__free(net->walls);
    odhs__free(net->adj);
    odhs__free(net->adjn);
    odhs__free(net->adjcap);
    odhs__free(net->core);
    odhs__free(net->cdeg);
    odhs__free(net->work);
    odhs__free(net);
}

const char *odhs_network_errmsg(const odhs_network *net) { return net ? net->errmsg : ""; }
size_t odhs_network_count(const odhs_network *net) { return net ? net->nc : 0; }
size_t odhs_network_particles(const odhs_network *net) { return net ? net->n : 0; }
int odhs_network_dim(const odhs_network *net) { return net ? net->dim : 0; }

size_t odhs__net_find(const odhs_network *net, size_t i, size_t j)
{
    if (i > j) {
        size_t t = i;
        i = j;
        j = t;
    }
    uint64_t key = pair_key(net, i, j);
    size_t mask = net->hcap - 1, s = hash_slot(key, mask);
    while (net->hkey[s]) {
        if (net->hkey[s] == key) return net->hval[s];
        s = (s + 1) & mask;
    }
    return SIZE_MAX;
}

/* ---- adjacency lists (partners of every particle and wall) ---------------- */
static int adj_reserve(odhs_network *net, size_t i)
{
    if (net->adjn[i] < net->adjcap[i]) return ODHS_OK;
    uint32_t cap = net->adjcap[i] ? 2 * net->adjcap[i] : 8;
    size_t *a = odhs__realloc(net->adj[i], cap * sizeof *a);
    if (!a) return ODHS_E_NOMEM;
    net->adj[i] = a;
    net->adjcap[i] = cap;
    return ODHS_OK;
}

static void adj_remove(odhs_network *net, size_t i, size_t j)
{
    for (uint32_t k = 0; k < net->adjn[i]; ++k)
        if (net->adj[i][k] == j) {
            net->adj[i][k] = net->adj[i][--net->adjn[i]];
            return;
        }
}

/* one contact change into the network's log (network.h) */
static void net_log(odhs_network *net, size_t i, size_t j, int add)
{
    const size_t k = (size_t)(net->log_n % ODHS__NET_LOG);
    net->log_i[k] = i;
    net->log_j[k] = j;
    net->log_add[k] = (unsigned char)add;
    net->log_n++;
}

size_t odhs__net_add(odhs_network *net, size_t i, size_t j, int kind)
{
    if (kind == ODHS_CONTACT_PERMANENT && odhs__net_body_reserve(net)) return SIZE_MAX;
    if (i > j) {
        size_t t = i;
        i = j;
        j = t;
    }
    if (net->nc == net->cap && grow(net)) return SIZE_MAX;
    if (adj_reserve(net, i) || adj_reserve(net, j)) return SIZE_MAX;
    size_t c = net->nc++;
    net->ci[c] = i;
    net->cj[c] = j;
    net->kind[c] = kind;
    for (int k = 0; k < net->dim; ++k) net->nrm[c * net->dim + k] = 0.0;
    net->dist[c] = net->gap[c] = net->f[c] = 0.0;
    net->rest[c] = NAN;
    if (kind == ODHS_CONTACT_PERMANENT) net->nperm++;
    uint64_t key = pair_key(net, i, j);
    size_t mask = net->hcap - 1, s = hash_slot(key, mask);
    while (net->hkey[s]) s = (s + 1) & mask;
    net->hkey[s] = key;
    net->hval[s] = c;
    net->adj[i][net->adjn[i]++] = j;
    net->adj[j][net->adjn[j]++] = i;
    odhs__net_core_added(net, i, j);
    net_log(net, i, j, 1);
    net->version++;
    net->topo++;
    return c;
}

/* delete key from the linear-probing table (backward-shift deletion) */
static void hash_delete(odhs_network *net, uint64_t key)
{
    size_t mask = net->hcap - 1, s = hash_slot(key, mask);
    while (net->hkey[s] != key) s = (s + 1) & mask;
    size_t hole = s;
    for (;;) {
        s = (s + 1) & mask;
        if (!net->hkey[s]) break;
        size_t home = hash_slot(net->hkey[s], mask);
        /* can the entry at s move into the hole? (home not in (hole, s]) */
        int move = (hole <= s) ? (home <= hole || home > s) : (home <= hole && home > s);
        if (move) {
            net->hkey[hole] = net->hkey[s];
            net->hval[hole] = net->hval[s];
            hole = s;
        }
    }
    net->hkey[hole] = 0;
}

static void hash_set(odhs_network *net, uint64_t key, size_t val)
{
    size_t mask = net->hcap - 1, s = hash_slot(key, mask);
    while (net->hkey[s] != key) s = (s + 1) & mask;
    net->hval[s] = val;
}

void odhs__net_remove_at(odhs_network *net, size_t k)
{
    net_log(net, net->ci[k], net->cj[k], 0);
    hash_delete(net, pair_key(net, net->ci[k], net->cj[k]));
    adj_remove(net, net->ci[k], net->cj[k]);
    adj_remove(net, net->cj[k], net->ci[k]);
    odhs__net_core_removed(net, net->ci[k], net->cj[k]);
    if (net->kind[k] == ODHS_CONTACT_PERMANENT) net->nperm--;
    size_t last = net->nc - 1;
    if (k != last) {
        int d = net->dim;
        net->ci[k] = net->ci[last];
        net->cj[k] = net->cj[last];
        net->kind[k] = net->kind[last];
        memcpy(net->nrm + k * d, net->nrm + last * d, (size_t)d * sizeof(double));
        net->dist[k] = net->dist[last];
        net->gap[k] = net->gap[last];
        net->f[k] = net->f[last];
        net->rest[k] = net->rest[last];
        hash_set(net, pair_key(net, net->ci[k], net->cj[k]), k);
    }
    net->nc--;
    net->version++;
    net->topo++;
}

int odhs_network_add(odhs_network *net, size_t i, size_t j, int kind)
{
    if (!net) return ODHS_E_NULL;
    net->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (i >= net->n || j >= net->n)
        return odhs__neterr(net, ODHS_E_RANGE, "particle index out of range (N = %zu)", net->n);
    if (i == j) return odhs__neterr(net, ODHS_E_INVALID, "a contact needs two different particles");
    if (kind != ODHS_CONTACT_TEMPORARY && kind != ODHS_CONTACT_PERMANENT)
        return odhs__neterr(net, ODHS_E_INVALID, "unknown contact kind %d", kind);
    if (odhs__net_find(net, i, j) != SIZE_MAX)
        return odhs__neterr(net, ODHS_E_INVALID, "contact (%zu,%zu) already present", i, j);
    if (odhs__net_add(net, i, j, kind) == SIZE_MAX) return odhs__neterr(net, ODHS_E_NOMEM, "out of memory");
    return ODHS_OK;
}

int odhs_network_remove(odhs_network *net, size_t i, size_t j)
{
    if (!net) return ODHS_E_NULL;
    net->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (i >= net->n || j >= net->n)
        return odhs__neterr(net, ODHS_E_RANGE, "particle index out of range (N = %zu)", net->n);
    size_t k = odhs__net_find(net, i, j);
    if (k == SIZE_MAX) return odhs__neterr(net, ODHS_E_INVALID, "no contact (%zu,%zu)", i, j);
    odhs__net_remove_at(net, k);
    return ODHS_OK;
}

int odhs_network_clear(odhs_network *net)
{
    if (!net) return ODHS_E_NULL;
    net->errmsg[0] = '\0'; /* a successful call leaves no message */
    while (net->nc) odhs__net_remove_at(net, net->nc - 1);
    return ODHS_OK;
}

int odhs_network_find(const odhs_network *net, size_t i, size_t j, size_t *index)
{
    if (!net) return ODHS_E_NULL;
    if (!index) return odhs__neterr(net, ODHS_E_NULL, "output pointer is NULL");
    if (i >= net->n || j >= net->n)
        return odhs__neterr(net, ODHS_E_RANGE, "particle index out of range (N = %zu)", net->n);
    *index = odhs__net_find(net, i, j);
    return ODHS_OK;
}

void odhs__net_geometry(odhs_network *net, const odhs_system *sys)
{
    int d = net->dim;
    if (net->nperm) net->work_composite++; /* rest lengths of bonds */
    for (size_t c = 0; c < net->nc; ++c) {
        size_t i = net->ci[c], j = net->cj[c];
        if (j >= net->n) {
            double r = odhs__wall_geom(&net->walls[j - net->n], d, sys->L, sys->gamma, sys->x + i * d, net->nrm + c * d, NULL);
            net->dist[c] = r;
            net->gap[c] = r - sys->r[i];
            continue;
        }
        double v[3] = {0, 0, 0};
        for (int k = 0; k < d; ++k) v[k] = sys->x[j * d + k] - sys->x[i * d + k];
        odhs__min_image(d, sys->L, sys->gamma, v, NULL);
        double r = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
        net->dist[c] = r;
        net->gap[c] = r - odhs__net_sigma(net, sys, c);
        for (int k = 0; k < d; ++k) net->nrm[c * d + k] = v[k] / r;
    }
    net->version++;
}

static int check_sys(const odhs_network *net, const odhs_system *sys)
{
    if (!sys) return odhs__neterr(net, ODHS_E_NULL, "system is NULL");
    if (sys->n != net->n || sys->dim != net->dim)
        return odhs__neterr(net, ODHS_E_DIM, "system does not match the network (N or dimension)");
    if (!sys->has_x || !sys->has_r)
        return odhs__neterr(net, ODHS_E_STATE, "system radii and positions must be set");
    return ODHS_OK;
}

int odhs_network_update_geometry(odhs_network *net, const odhs_system *sys)
{
    if (!net) return ODHS_E_NULL;
    net->errmsg[0] = '\0'; /* a successful call leaves no message */
    int st = check_sys(net, sys);
    if (st) return st;
    odhs__net_geometry(net, sys);
    return ODHS_OK;
}

typedef struct {
    odhs_network *net;
    const double *r;
    double tol;
    int status;
} detect_ctx;

static int detect_cb(size_t i, size_t j, const double *rij, double gap, void *vctx)
{
    (void)rij;
    detect_ctx *c = vctx;
    if (gap <= c->tol * (c->r[i] + c->r[j]) && !odhs__same_body(c->net, i, j) &&
        odhs__net_find(c->net, i, j) == SIZE_MAX) {
        if (odhs__net_add(c->net, i, j, ODHS_CONTACT_TEMPORARY) == SIZE_MAX) {
            c->status = ODHS_E_NOMEM;
            return 1;
        }
    }
    return 0;
}

/* particle i already touches another wall with this normal (two segments
 * sharing an end): a second contact there would be redundant */
static int same_normal_wall(const odhs_network *net, const odhs_system *sys, size_t i, size_t w, const double *nw)
{
    int d = net->dim;
    for (uint32_t k = 0; k < net->adjn[i]; ++k) {
        size_t o = net->adj[i][k];
        if (o < net->n || o - net->n == w) continue;
        double no[3], dot = 0.0;
        odhs__wall_geom(&net->walls[o - net->n], d, sys->L, sys->gamma, sys->x + i * d, no, NULL);
        for (int a = 0; a < d; ++a) dot += nw[a] * no[a];
        if (dot > 1.0 - 1e-9) return 1;
    }
    return 0;
}

int odhs_network_detect(odhs_network *net, const odhs_system *sys, double tol)
{
    if (!net) return ODHS_E_NULL;
    net->errmsg[0] = '\0'; /* a successful call leaves no message */
    int st = check_sys(net, sys);
    if (st) return st;
    if (!isfinite(tol) || tol < 0.0) return odhs__neterr(net, ODHS_E_INVALID, "tolerance must be >= 0");
    detect_ctx c = {net, sys->r, tol, ODHS_OK};
    size_t nc0 = net->nc;
    st = odhs__pairs(sys->dim, sys->n, sys->x, sys->r, sys->rmax, sys->L, sys->gamma,
                     tol * 2.0 * sys->rmax, detect_cb, &c);
    if (st == ODHS_E_NOMEM || c.status) {
        /* leave the network as it was: drop the contacts added so far (they
         * are the last ones; removing the newest first restores everything) */
        while (net->nc > nc0) odhs__net_remove_at(net, net->nc - 1);
        return odhs__neterr(net, ODHS_E_NOMEM, "out of memory");
    }
    for (size_t w = 0; w < net->nwalls; ++w)
        for (size_t i = 0; i < sys->n; ++i) {
            double nrm[3];
            double g = odhs__wall_geom(&net->walls[w], sys->dim, sys->L, sys->gamma, sys->x + i * sys->dim, nrm, NULL) - sys->r[i];
            if (g <= tol * 2.0 * sys->r[i] && odhs__net_find(net, i, sys->n + w) == SIZE_MAX &&
                !same_normal_wall(net, sys, i, w, nrm) &&
                odhs__net_add(net, i, sys->n + w, ODHS_CONTACT_WALL) == SIZE_MAX) {
                while (net->nc > nc0) odhs__net_remove_at(net, net->nc - 1);
                return odhs__neterr(net, ODHS_E_NOMEM, "out of memory");
            }
        }
    odhs__net_geometry(net, sys);
    return ODHS_OK;
}

int odhs_network_get_contact(const odhs_network *net, size_t k, size_t *i, size_t *j, int *kind)
{
    if (!net) return ODHS_E_NULL;
    if (k >= net->nc) return odhs__neterr(net, ODHS_E_RANGE, "contact index %zu >= Nc = %zu", k, net->nc);
    if (i) *i = net->ci[k];
    if (j) *j = net->cj[k];
    if (kind) *kind = net->kind[k];
    return ODHS_OK;
}

int odhs_network_get_contacts(const odhs_network *net, size_t *i, size_t *j, int *kind)
{
    if (!net) return ODHS_E_NULL;
    if (!i && !j && !kind) return odhs__neterr(net, ODHS_E_NULL, "every output pointer is NULL");
    if (i && net->nc) memcpy(i, net->ci, net->nc * sizeof *i);
    if (j && net->nc) memcpy(j, net->cj, net->nc * sizeof *j);
    for (size_t k = 0; kind && k < net->nc; ++k) kind[k] = net->kind[k];
    return ODHS_OK;
}

static int copy_out(const odhs_network *net, const double *src, double *dst, size_t count)
{
    if (!net) return ODHS_E_NULL;
    if (!dst) return odhs__neterr(net, ODHS_E_NULL, "output pointer is NULL");
    if (count) memcpy(dst, src, count * sizeof(double));
    return ODHS_OK;
}

int odhs_network_get_forces(const odhs_network *net, double *f)
{
    return copy_out(net, net ? net->f : NULL, f, net ? net->nc : 0);
}
int odhs_network_get_gaps(const odhs_network *net, double *gap)
{
    return copy_out(net, net ? net->gap : NULL, gap, net ? net->nc : 0);
}
int odhs_network_get_normals(const odhs_network *net, double *n)
{
    return copy_out(net, net ? net->nrm : NULL, n, net ? net->nc * (size_t)net->dim : 0);
}

int odhs_network_set_forces(odhs_network *net, const double *f)
{
    if (!net) return ODHS_E_NULL;
    net->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!f && net->nc) return odhs__neterr(net, ODHS_E_NULL, "forces pointer is NULL");
    for (size_t c = 0; c < net->nc; ++c)
        if (!isfinite(f[c])) return odhs__neterr(net, ODHS_E_NONFINITE, "force %zu is not finite", c);
    if (net->nc) memcpy(net->f, f, net->nc * sizeof(double));
    return ODHS_OK;
}

/* ---- S, S^T, N -------------------------------------------------------------- */
void odhs__net_S(const odhs_network *net, const double *v, double *out)
{
    const int d = net->dim;
    if (net->nwalls) {
        for (size_t c = 0; c < net->nc; ++c) {
            const double *n = net->nrm + c * d;
            const double *vi = v + net->ci[c] * d;
            double s = 0.0;
            if (net->cj[c] < net->n) {
                const double *vj = v + net->cj[c] * d;
                for (int k = 0; k < d; ++k) s += vj[k] * n[k];
            }
            for (int k = 0; k < d; ++k) s -= vi[k] * n[k];
            out[c] = s;
        }
        return;
    }
    for (size_t c = 0; c < net->nc; ++c) {
        const double *n = net->nrm + c * d;
        const double *vi = v + net->ci[c] * d, *vj = v + net->cj[c] * d;
        double s = 0.0;
        for (int k = 0; k < d; ++k) s += (vj[k] - vi[k]) * n[k];
        out[c] = s;
    }
}

void odhs__net_ST(const odhs_network *net, const double *f, double *out)
{
    const int d = net->dim;
    memset(out, 0, net->n * (size_t)d * sizeof(double));
    if (net->nwalls) {
        for (size_t c = 0; c < net->nc; ++c) {
            const double *n = net->nrm + c * d;
            double *oi = out + net->ci[c] * d;
            for (int k = 0; k < d; ++k) oi[k] -= f[c] * n[k];
            if (net->cj[c] < net->n) {
                double *oj = out + net->cj[c] * d;
                for (int k = 0; k < d; ++k) oj[k] += f[c] * n[k];
            }
        }
        return;
    }
    for (size_t c = 0; c < net->nc; ++c) {
        const double *n = net->nrm + c * d;
        double *oi = out + net->ci[c] * d, *oj = out + net->cj[c] * d;
        for (int k = 0; k < d; ++k) {
            oi[k] -= f[c] * n[k];
            oj[k] += f[c] * n[k];
        }
    }
}

void odhs__net_N(const odhs_network *net, const double *x, double *out, double *work)
{
    odhs__net_ST(net, x, work);
    odhs__net_S(net, work, out);
}

int odhs_network_apply_S(const odhs_network *net, const double *v, double *out)
{
    if (!net) return ODHS_E_NULL;
    if (!v || !out) return odhs__neterr(net, ODHS_E_NULL, "vector pointer is NULL");
    odhs__net_S(net, v, out);
    return ODHS_OK;
}

int odhs_network_apply_ST(const odhs_network *net, const double *f, double *out)
{
    if (!net) return ODHS_E_NULL;
    if ((!f && net->nc) || !out) return odhs__neterr(net, ODHS_E_NULL, "vector pointer is NULL");
    odhs__net_ST(net, f, out);
    return ODHS_OK;
}

int odhs_network_apply_N(const odhs_network *net, const double *x, double *out, double *work)
{
    if (!net) return ODHS_E_NULL;
    if ((!x || !out) && net->nc) return odhs__neterr(net, ODHS_E_NULL, "vector pointer is NULL");
    double *w = work;
    if (!w) {
        w = odhs__malloc_array(net->n * (size_t)net->dim, sizeof(double));
        if (!w) return odhs__neterr(net, ODHS_E_NOMEM, "out of memory");
    }
    odhs__net_N(net, x, out, w);
    if (!work) odhs__free(w);
    return ODHS_OK;
}

size_t odhs_network_nnz(const odhs_network *net)
{
    if (!net) return 0;
    size_t rows = 2u * net->nc;
    if (net->nwalls)
        for (size_t c = 0; c < net->nc; ++c) rows -= net->cj[c] >= net->n;
    return rows * (size_t)net->dim;
}

int odhs_network_get_S_csr(const odhs_network *net, size_t *rowptr, size_t *col, double *val)
{
    if (!net) return ODHS_E_NULL;
    if (!rowptr || ((!col || !val) && net->nc)) return odhs__neterr(net, ODHS_E_NULL, "output pointer is NULL");
    const int d = net->dim;
    size_t p = 0;
    rowptr[0] = 0;
    for (size_t c = 0; c < net->nc; ++c) {
        size_t a = net->ci[c], b = net->cj[c]; /* a < b: columns in increasing order */
        for (int k = 0; k < d; ++k) {
            col[p] = a * d + k;
            val[p++] = -net->nrm[c * d + k];
        }
        for (int k = 0; k < d && b < net->n; ++k) {
            col[p] = b * d + k;
            val[p++] = net->nrm[c * d + k];
        }
        rowptr[c + 1] = p;
    }
    return ODHS_OK;
}

int odhs_network_coordination(const odhs_network *net, double *z)
{
    if (!net) return ODHS_E_NULL;
    if (!z) return odhs__neterr(net, ODHS_E_NULL, "output pointer is NULL");
    *z = 2.0 * (double)net->nc / (double)net->n;
    return ODHS_OK;
}

/* ---- permanent contacts with a rest length ---------------------------------- */
int odhs_network_add_bond(odhs_network *net, size_t i, size_t j, double rest)
{
    if (!net) return ODHS_E_NULL;
    net->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (i >= net->n || j >= net->n)
        return odhs__neterr(net, ODHS_E_RANGE, "particle index out of range (N = %zu)", net->n);
    if (i == j) return odhs__neterr(net, ODHS_E_INVALID, "a bond needs two different particles");
    if (isnan(rest) || isinf(rest)) return odhs__neterr(net, ODHS_E_NONFINITE, "rest length is not finite");
    if (!(rest > 0.0)) return odhs__neterr(net, ODHS_E_INVALID, "rest length %g must be > 0", rest);
    size_t k = odhs__net_find(net, i, j);
    if (k != SIZE_MAX && net->kind[k] == ODHS_CONTACT_PERMANENT)
        return odhs__neterr(net, ODHS_E_INVALID, "particles %zu and %zu are already bonded", i, j);
    if (k == SIZE_MAX && (k = odhs__net_add(net, i, j, ODHS_CONTACT_PERMANENT)) == SIZE_MAX)
        return odhs__neterr(net, ODHS_E_NOMEM, "out of memory");
    if (net->kind[k] != ODHS_CONTACT_PERMANENT) {
        if (odhs__net_body_reserve(net)) return odhs__neterr(net, ODHS_E_NOMEM, "out of memory");
        /* a temporary contact becomes a bond: same constraint, new kind */
        net->kind[k] = ODHS_CONTACT_PERMANENT;
        net->nperm++;
        net->topo++;
    }
    net->rest[k] = rest;
    net->gap[k] = net->dist[k] > 0.0 ? net->dist[k] - rest : 0.0;
    net->version++;
    return ODHS_OK;
}

int odhs_network_get_rest_length(const odhs_network *net, const odhs_system *sys, size_t k, double *rest)
{
    if (!net) return ODHS_E_NULL;
    if (!rest) return odhs__neterr(net, ODHS_E_NULL, "output pointer is NULL");
    int st = check_sys(net, sys);
    if (st) return st;
    if (k >= net->nc) return odhs__neterr(net, ODHS_E_RANGE, "contact index %zu >= Nc = %zu", k, net->nc);
    *rest = odhs__net_sigma(net, sys, k);
    return ODHS_OK;
}

/* ---- walls ------------------------------------------------------------------- */
/* Global zero modes of the particles with these walls: translations along
 * directions no wall normal constrains, plus rigid rotations when every wall
 * is a sphere about one centre (nothing else breaks the rotation). */
static size_t wall_free_modes(const odhs_network *net)
{
    int d = net->dim;
    double basis[3][3];
    int rank = 0, spheres_only = 1, same_centre = 1;
    for (size_t w = 0; w < net->nwalls; ++w) {
        const odhs_wall *wl = &net->walls[w];
        double cand[3][3];
        int nc = 0;
        if (wl->type == ODHS_WALL_SPHERE) {
            for (int a = 0; a < d; ++a)
                for (int b = 0; b < 3; ++b) cand[a][b] = a == b;
            nc = d;
            for (int k = 0; k < d; ++k) same_centre &= wl->c[k] == net->walls[0].c[k];
        } else {
            spheres_only = 0;
            for (int b = 0; b < 3; ++b) cand[0][b] = wl->n[b];
            nc = 1;
        }
        for (int q = 0; q < nc && rank < d; ++q) {
            double v[3] = {cand[q][0], cand[q][1], cand[q][2]};
            for (int r = 0; r < rank; ++r) {
                double dot = 0.0;
                for (int k = 0; k < 3; ++k) dot += v[k] * basis[r][k];
                for (int k = 0; k < 3; ++k) v[k] -= dot * basis[r][k];
            }
            double nv = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
            if (nv > 1e-9) {
                for (int k = 0; k < 3; ++k) basis[rank][k] = v[k] / nv;
                rank++;
            }
        }
    }
    size_t modes = (size_t)(d - rank);
    if (net->nwalls && spheres_only && same_centre) modes += d == 2 ? 1u : 3u;
    return modes;
}

int odhs__net_add_wall(odhs_network *net, const odhs_wall *w)
{
    size_t nn = net->n + net->nwalls + 1; /* nodes after the addition */
    odhs_wall *wl = odhs__realloc(net->walls, (net->nwalls + 1) * sizeof *wl);
    if (!wl) return ODHS_E_NOMEM;
    net->walls = wl;
    size_t **adj = odhs__realloc(net->adj, nn * sizeof *adj);
    if (adj) net->adj = adj;
    uint32_t *adjn = odhs__realloc(net->adjn, nn * sizeof *adjn);
    if (adjn) net->adjn = adjn;
    uint32_t *adjcap = odhs__realloc(net->adjcap, nn * sizeof *adjcap);
    if (adjcap) net->adjcap = adjcap;
    unsigned char *core = odhs__realloc(net->core, nn);
    if (core) net->core = core;
    size_t *cdeg = odhs__realloc(net->cdeg, nn * sizeof *cdeg);
    if (cdeg) net->cdeg = cdeg;
    size_t *work = odhs__realloc(net->work, (2 * nn + 2) * sizeof *work);
    if (work) net->work = work;
    if (!adj || !adjn || !adjcap || !core || !cdeg || !work) return ODHS_E_NOMEM;
    size_t node = nn - 1;
    adj[node] = NULL;
    adjn[node] = adjcap[node] = 0;
    core[node] = 1; /* a wall never leaves the constrained subset */
    cdeg[node] = 0;
    net->walls[net->nwalls++] = *w;
    net->free_modes = wall_free_modes(net);
    net->version++;
    net->topo++;
    return ODHS_OK;
}

int odhs__net_copy_walls(odhs_network *sub, const odhs_network *net)
{
    for (size_t w = sub->nwalls; w < net->nwalls; ++w) {
        int st = odhs__net_add_wall(sub, &net->walls[w]);
        if (st) return st;
    }
    return ODHS_OK;
}

/* ---- scratch copies ------------------------------------------------------------ */
odhs_network *odhs__net_subnet(const odhs_network *net, const size_t *idx, size_t m, size_t skip)
{
    int d = net->dim;
    odhs_network *sub = odhs__net_new(d, net->n);
    if (!sub || odhs__net_copy_walls(sub, net)) goto fail;
    if (!idx) m = net->nc;
    for (size_t a = 0; a < m; ++a) {
        if (a == skip) continue;
        size_t c = idx ? idx[a] : a;
        size_t s = odhs__net_add(sub, net->ci[c], net->cj[c], net->kind[c]);
        if (s == SIZE_MAX) goto fail;
        memcpy(sub->nrm + s * d, net->nrm + c * d, (size_t)d * sizeof(double));
        sub->rest[s] = net->rest[c];
        sub->dist[s] = net->dist[c];
        sub->gap[s] = net->gap[c];
    }
    sub->version++;
    return sub;
fail:
    odhs_network_destroy(sub);
    return NULL;
}
