/* libodhs - composite particles (Sect. V C of Lerner, During & Wyart 2013):
 * permanent contacts (bonds) between beads, rigid bodies and floppy chains,
 * added through the stepper that owns the contact network.
 *
 * A bond is an ordinary row of S that never opens and may carry a negative
 * force; its rest length replaces a_i + a_j in the gap, so the drift
 * correction of Sect. IV C holds it at that length. A rigid body of k beads
 * gets a minimal infinitesimally rigid set of bonds (Henneberg construction:
 * every new bead bonded to d earlier beads along independent directions,
 * 2k - 3 bonds in 2D, 3k - 6 in 3D), because any extra bond would be a
 * redundant constraint and make N = S S^T singular. Pairs of beads of one
 * rigid body never become temporary contacts. */
#include <math.h>
#include <string.h>

#include "stepper/stepper.h"

/* minimum-image separation j - i and its length */
static double separation(const odhs_system *s, size_t i, size_t j, double *d)
{
    int dim = s->dim;
    d[0] = d[1] = d[2] = 0.0;
    for (int k = 0; k < dim; ++k) d[k] = s->x[j * dim + k] - s->x[i * dim + k];
    odhs__min_image(dim, s->L, s->gamma, d, NULL);
    return sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]);
}

static double half_box(const odhs_system *s)
{
    double l = fmin(s->L[0], s->L[1]);
    if (s->dim == 3) l = fmin(l, s->L[2]);
    return 0.5 * l;
}

/* The bonds of one call are applied together or not at all: `undo` records,
 * for every bond made, whether it was a new contact (then removed on
 * failure) or a temporary contact turned permanent (then turned back). */
typedef struct {
    size_t i, j;
    int was_new;
} bond_rec;

static void undo_bonds(odhs_network *net, const bond_rec *rec, size_t m)
{
    while (m-- > 0) {
        size_t k = odhs__net_find(net, rec[m].i, rec[m].j);
        if (k == SIZE_MAX) continue;
        if (rec[m].was_new) {
            odhs__net_remove_at(net, k);
        } else {
            net->kind[k] = ODHS_CONTACT_TEMPORARY;
            net->rest[k] = NAN;
            net->nperm--;
            net->topo++;
        }
    }
}

static int make_bond(odhs_network *net, size_t i, size_t j, double rest, bond_rec *rec)
{
    rec->i = i < j ? i : j;
    rec->j = i < j ? j : i;
    rec->was_new = odhs__net_find(net, i, j) == SIZE_MAX;
    return odhs_network_add_bond(net, i, j, rest);
}

static int check_index(const odhs_stepper *st, size_t i)
{
    if (i >= st->n) return odhs__sterr(st, ODHS_E_RANGE, "particle index %zu out of range (N = %zu)", i, st->n);
    return ODHS_OK;
}

int odhs_stepper_add_bond(odhs_stepper *st, size_t i, size_t j, double rest)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    int s;
    if ((s = check_index(st, i)) || (s = check_index(st, j))) return s;
    if (i == j) return odhs__sterr(st, ODHS_E_INVALID, "a bond needs two different particles");
    if (!isfinite(rest)) return odhs__sterr(st, ODHS_E_NONFINITE, "rest length is not finite");
    if (rest < 0.0) return odhs__sterr(st, ODHS_E_INVALID, "rest length %g must be >= 0 (0: current distance)", rest);
    double d[3];
    double r = separation(st->sys, i, j, d);
    if (rest == 0.0) rest = r;
    if (!(rest > 0.0)) return odhs__sterr(st, ODHS_E_INVALID, "particles %zu and %zu are at the same position", i, j);
    if (rest >= half_box(st->sys))
        return odhs__sterr(st, ODHS_E_INVALID, "rest length %g is not below half the shortest box edge", rest);
    if (fabs(r - rest) > 0.5 * rest)
        return odhs__sterr(st, ODHS_E_INVALID,
                    "particles %zu and %zu are %g apart, too far from the rest length %g to be bonded", i, j, r,
                    rest);
    odhs_network *net = st->net;
    bond_rec rec;
    s = make_bond(net, i, j, rest, &rec);
    if (s) return odhs__sterr(st, s, "%s", net->errmsg);
    net->dist[odhs__net_find(net, i, j)] = r;
    st->ready = 0; /* forces and velocities are re-solved before the next step */
    return ODHS_OK;
}

int odhs_stepper_add_chain(odhs_stepper *st, size_t k, const size_t *beads)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!beads) return odhs__sterr(st, ODHS_E_NULL, "beads pointer is NULL");
    if (k < 2) return odhs__sterr(st, ODHS_E_INVALID, "a chain needs at least 2 beads (got %zu)", k);
    int s;
    for (size_t a = 0; a < k; ++a) {
        if ((s = check_index(st, beads[a]))) return s;
        for (size_t b = 0; b < a; ++b)
            if (beads[a] == beads[b]) return odhs__sterr(st, ODHS_E_INVALID, "bead %zu listed twice", beads[a]);
    }
    odhs_network *net = st->net;
    double hb = half_box(st->sys), d[3];
    for (size_t a = 0; a + 1 < k; ++a) {
        double r = separation(st->sys, beads[a], beads[a + 1], d);
        if (!(r > 0.0) || r >= hb)
            return odhs__sterr(st, ODHS_E_INVALID, "beads %zu and %zu are %g apart: cannot bond them", beads[a],
                        beads[a + 1], r);
        size_t c = odhs__net_find(net, beads[a], beads[a + 1]);
        if (c != SIZE_MAX && net->kind[c] == ODHS_CONTACT_PERMANENT)
            return odhs__sterr(st, ODHS_E_INVALID, "beads %zu and %zu are already bonded", beads[a], beads[a + 1]);
    }
    bond_rec *rec = odhs__malloc_array(k, sizeof *rec);
    if (!rec) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
    size_t m = 0;
    for (size_t a = 0; a + 1 < k; ++a) {
        double r = separation(st->sys, beads[a], beads[a + 1], d);
        if ((s = make_bond(net, beads[a], beads[a + 1], r, &rec[m]))) {
            undo_bonds(net, rec, m);
            odhs__free(rec);
            return odhs__sterr(st, s, "%s", net->errmsg);
        }
        net->dist[odhs__net_find(net, beads[a], beads[a + 1])] = r;
        m++;
    }
    odhs__free(rec);
    st->ready = 0;
    return ODHS_OK;
}

/* |det| of the unit directions from bead p to the anchors a[0..d-1]: the
 * bonds of a new bead are independent constraints when it is not small */
static double independence(const odhs_system *s, size_t p, const size_t *a, int na)
{
    double u[3][3] = {{0}};
    for (int q = 0; q < na; ++q) {
        double r = separation(s, p, a[q], u[q]);
        for (int k = 0; k < 3; ++k) u[q][k] /= r;
    }
    if (na == 1) return 1.0;
    if (na == 2) {
        /* 2D: |u0 x u1|; 3D: length of the cross product */
        double c0 = u[0][1] * u[1][2] - u[0][2] * u[1][1];
        double c1 = u[0][2] * u[1][0] - u[0][0] * u[1][2];
        double c2 = u[0][0] * u[1][1] - u[0][1] * u[1][0];
        return sqrt(c0 * c0 + c1 * c1 + c2 * c2);
    }
    return fabs(u[0][0] * (u[1][1] * u[2][2] - u[1][2] * u[2][1]) -
                u[0][1] * (u[1][0] * u[2][2] - u[1][2] * u[2][0]) +
                u[0][2] * (u[1][0] * u[2][1] - u[1][1] * u[2][0]));
}

#define INDEP_MIN 1e-3 /* smallest |sin| / |det| accepted between bond directions */

/* the beads of a new rigid body: valid, distinct, in no other body and at
 * distinct positions */
static int check_body_beads(const odhs_stepper *st, size_t k, const size_t *beads)
{
    const odhs_network *net = st->net;
    const odhs_system *sys = st->sys;
    int s;
    for (size_t a = 0; a < k; ++a) {
        if ((s = check_index(st, beads[a]))) return s;
        for (size_t b = 0; b < a; ++b)
            if (beads[a] == beads[b]) return odhs__sterr(st, ODHS_E_INVALID, "bead %zu listed twice", beads[a]);
        if (net->rbody && net->rbody[beads[a]] != SIZE_MAX)
            return odhs__sterr(st, ODHS_E_INVALID, "bead %zu already belongs to a rigid body", beads[a]);
    }
    double d[3];
    for (size_t a = 0; a < k; ++a)
        for (size_t b = 0; b < a; ++b) {
            double r = separation(sys, beads[a], beads[b], d);
            if (!(r > 0.0)) return odhs__sterr(st, ODHS_E_INVALID, "beads %zu and %zu coincide", beads[a], beads[b]);
        }
    return ODHS_OK;
}

/* the `need` nearest placed beads (order[0..nplaced-1]) with independent
 * directions from bead p, chosen greedily by distance, into anc[]; returns
 * how many were found */
static int find_anchors(const odhs_system *sys, const size_t *beads, size_t p, const size_t *order,
                        size_t nplaced, int need, size_t *anc)
{
    double d[3];
    int na = 0;
    for (int round = 0; round < need; ++round) {
        double dbest = INFINITY;
        size_t qb = SIZE_MAX;
        for (size_t q = 0; q < nplaced; ++q) {
            size_t b = beads[order[q]];
            int skip = 0;
            for (int t = 0; t < na; ++t) skip |= anc[t] == b;
            if (skip) continue;
            anc[na] = b;
            if (independence(sys, beads[p], anc, na + 1) < INDEP_MIN) continue;
            double r = separation(sys, beads[p], b, d);
            if (r < dbest) {
                dbest = r;
                qb = q;
            }
        }
        if (qb == SIZE_MAX) break;
        anc[na++] = beads[order[qb]];
    }
    return na;
}

/* the unplaced bead whose `need` anchors are best conditioned, its anchors
 * in besta[]; SIZE_MAX if no bead has enough independent anchors */
static size_t next_bead(const odhs_system *sys, size_t k, const size_t *beads, const size_t *order, size_t nplaced,
                        const unsigned char *placed, int need, size_t *besta)
{
    double best = -1.0;
    size_t bestp = SIZE_MAX;
    for (size_t p = 0; p < k; ++p) {
        if (placed[p]) continue;
        size_t anc[3];
        int na = find_anchors(sys, beads, p, order, nplaced, need, anc);
        if (na < need) continue;
        double ind = independence(sys, beads[p], anc, na);
        if (ind > best) {
            best = ind;
            bestp = p;
            memcpy(besta, anc, sizeof anc);
        }
    }
    return bestp;
}

/* plan the bonds: order[] grows by the bead with the best-conditioned
 * anchors among the nearest placed beads; the new bonds go to bi[], bj[] */
static int plan_bonds(const odhs_stepper *st, size_t k, const size_t *beads, size_t *order, unsigned char *placed,
                      size_t *bi, size_t *bj, size_t *nb_out)
{
    const odhs_network *net = st->net;
    const odhs_system *sys = st->sys;
    int dim = st->dim;
    double hb = half_box(sys), d[3];
    size_t nplaced = 0, nb = 0;
    order[nplaced++] = 0;
    placed[0] = 1;
    while (nplaced < k) {
        int need = (int)(nplaced < (size_t)dim ? nplaced : (size_t)dim);
        size_t besta[3] = {0, 0, 0};
        size_t bestp = next_bead(sys, k, beads, order, nplaced, placed, need, besta);
        if (bestp == SIZE_MAX)
            return odhs__sterr(st, ODHS_E_INVALID,
                        "the beads are (nearly) %s: distance constraints cannot make them a rigid body "
                        "(use a chain, or beads off one %s)",
                        dim == 2 ? "collinear" : "coplanar or collinear", dim == 2 ? "line" : "plane");
        for (int t = 0; t < need; ++t) {
            double r = separation(sys, beads[bestp], besta[t], d);
            if (r >= hb)
                return odhs__sterr(st, ODHS_E_INVALID, "beads %zu and %zu are %g apart: not below half the box edge",
                            beads[bestp], besta[t], r);
            size_t c = odhs__net_find(net, beads[bestp], besta[t]);
            if (c != SIZE_MAX && net->kind[c] == ODHS_CONTACT_PERMANENT)
                continue; /* already bonded (e.g. by an earlier chain) */
            bi[nb] = beads[bestp];
            bj[nb++] = besta[t];
        }
        placed[bestp] = 1;
        order[nplaced++] = bestp;
    }
    *nb_out = nb;
    return ODHS_OK;
}

/* the bonds bi[b]-bj[b] at their current lengths, all or none */
static int make_body_bonds(odhs_stepper *st, const size_t *bi, const size_t *bj, size_t nb, bond_rec *rec)
{
    odhs_network *net = st->net;
    const odhs_system *sys = st->sys;
    double d[3];
    int s;
    size_t m = 0;
    for (size_t b = 0; b < nb; ++b) {
        double r = separation(sys, bi[b], bj[b], d);
        if ((s = make_bond(net, bi[b], bj[b], r, &rec[m]))) {
            undo_bonds(net, rec, m);
            return odhs__sterr(st, s, "%s", net->errmsg);
        }
        net->dist[odhs__net_find(net, bi[b], bj[b])] = r;
        m++;
    }
    return ODHS_OK;
}

int odhs_stepper_add_rigid_body(odhs_stepper *st, size_t k, const size_t *beads)
{
    if (!st) return ODHS_E_NULL;
    st->errmsg[0] = '\0'; /* a successful call leaves no message */
    if (!beads) return odhs__sterr(st, ODHS_E_NULL, "beads pointer is NULL");
    if (k < 2) return odhs__sterr(st, ODHS_E_INVALID, "a rigid body needs at least 2 beads (got %zu)", k);
    odhs_network *net = st->net;
    int dim = st->dim;
    int s = check_body_beads(st, k, beads);
    if (s) return s;
    size_t *order = odhs__malloc_array(k, sizeof *order);
    size_t nbmax = k * (size_t)dim;
    size_t *bi = odhs__malloc_array(nbmax, sizeof *bi), *bj = odhs__malloc_array(nbmax, sizeof *bj);
    bond_rec *rec = odhs__malloc_array(nbmax, sizeof *rec);
    unsigned char *placed = odhs__calloc(k, 1);
    if (!order || !bi || !bj || !rec || !placed) {
        s = odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
        goto done;
    }
    size_t nb = 0;
    if ((s = plan_bonds(st, k, beads, order, placed, bi, bj, &nb))) goto done;
    if (!net->rbody) {
        net->rbody = odhs__malloc_array(st->n, sizeof *net->rbody);
        if (!net->rbody) {
            s = odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
            goto done;
        }
        for (size_t i = 0; i < st->n; ++i) net->rbody[i] = SIZE_MAX;
    }
    if ((s = make_body_bonds(st, bi, bj, nb, rec))) goto done;
    /* label: the smallest bead index; other contacts inside the body go */
    size_t label = beads[0];
    for (size_t a = 1; a < k; ++a) label = beads[a] < label ? beads[a] : label;
    for (size_t a = 0; a < k; ++a) net->rbody[beads[a]] = label;
    for (size_t c = net->nc; c-- > 0;)
        if (net->kind[c] == ODHS_CONTACT_TEMPORARY && odhs__same_body(net, net->ci[c], net->cj[c]))
            odhs__net_remove_at(net, c);
    st->ready = 0;
    s = ODHS_OK;
done:
    odhs__free(order);
    odhs__free(bi);
    odhs__free(bj);
    odhs__free(rec);
    odhs__free(placed);
    return s;
}

int odhs_stepper_bond_count(const odhs_stepper *st, size_t *count)
{
    if (!st) return ODHS_E_NULL;
    if (!count) return odhs__sterr(st, ODHS_E_NULL, "output pointer is NULL");
    *count = st->net->nperm;
    return ODHS_OK;
}
