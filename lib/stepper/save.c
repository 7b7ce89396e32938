/* libodhs - one save of the state at the start of a step, and the two ways
 * back to it: the rollback of a failed step and the restart of a step the
 * integrator repeats shorter. */
#include <math.h>
#include <string.h>

#include "stepper/stepper.h"

/* ---- snapshot / rollback ------------------------------------------------- */
int odhs__st_save(odhs_stepper *st)
{
    odhs_network *net = st->net;
    if (st->scap < net->nc) {
        size_t cap = net->cap;
        size_t *a = odhs__realloc(st->sci, cap * sizeof *a);
        if (a) st->sci = a;
        size_t *b = odhs__realloc(st->scj, cap * sizeof *b);
        if (b) st->scj = b;
        int *k = odhs__realloc(st->skind, cap * sizeof *k);
        if (k) st->skind = k;
        double *f = odhs__realloc(st->sf, cap * sizeof *f);
        if (f) st->sf = f;
        double *rs = odhs__realloc(st->srest, cap * sizeof *rs);
        if (rs) st->srest = rs;
        double *fr = odhs__realloc(st->fr, cap * sizeof *fr);
        if (fr) st->fr = fr;
        if (!a || !b || !k || !f || !rs || !fr) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
        st->scap = cap;
    }
    if (net->nwalls) {
        if (st->wsnapcap < net->nwalls) {
            odhs_wall *w = odhs__realloc(st->wsnap, net->nwalls * sizeof *w);
            if (!w) return odhs__sterr(st, ODHS_E_NOMEM, "out of memory");
            st->wsnap = w;
            st->wsnapcap = net->nwalls;
        }
        memcpy(st->wsnap, net->walls, net->nwalls * sizeof *net->walls);
    }
    memcpy(st->xs, st->sys->x, st->nd * sizeof *st->xs);
    memcpy(st->Us, st->U, st->nd * sizeof *st->Us);
    memcpy(st->Fs, st->F, st->nd * sizeof *st->Fs);
    st->has_Fs = st->has_F;
    memcpy(st->Ls, st->sys->L, sizeof st->Ls);
    st->gammas = st->sys->gamma;
    st->times = st->time;
    st->strains = st->strain;
    st->nsteps_s = st->nsteps;
    st->snc = net->nc;
    if (net->nc == 0) {
        memcpy(st->Gs, st->G, sizeof st->Gs);
        st->kappas = st->kappa;
        return ODHS_OK;
    }
    memcpy(st->Gs, st->G, sizeof st->Gs);
    st->kappas = st->kappa;
    memcpy(st->sci, net->ci, net->nc * sizeof *st->sci);
    memcpy(st->scj, net->cj, net->nc * sizeof *st->scj);
    memcpy(st->skind, net->kind, net->nc * sizeof *st->skind);
    memcpy(st->sf, net->f, net->nc * sizeof *st->sf);
    if (net->nperm) memcpy(st->srest, net->rest, net->nc * sizeof *st->srest);
    return ODHS_OK;
}

void odhs__st_restore_motion(odhs_stepper *st)
{
    odhs_network *net = st->net;
    memcpy(st->sys->x, st->xs, st->nd * sizeof *st->xs);
    if (net->nwalls) memcpy(net->walls, st->wsnap, net->nwalls * sizeof *net->walls);
    memcpy(st->sys->L, st->Ls, sizeof st->Ls);
    st->sys->gamma = st->gammas;
}

static void restore_clock(odhs_stepper *st)
{
    st->time = st->times;
    st->strain = st->strains;
    st->nsteps = st->nsteps_s;
}

void odhs__st_restore_network(odhs_stepper *st)
{
    odhs_network *net = st->net;
    odhs_network_clear(net);
    for (size_t c = 0; c < st->snc; ++c) {
        size_t k = odhs__net_add(net, st->sci[c], st->scj[c], st->skind[c]);
        if (k == SIZE_MAX) break; /* cannot happen: capacity is retained */
        net->f[k] = st->sf[c];
        if (st->skind[c] == ODHS_CONTACT_PERMANENT) net->rest[k] = st->srest[c];
    }
    odhs__net_geometry(net, st->sys);
}

void odhs__st_rollback(odhs_stepper *st)
{
    odhs__st_restore_motion(st);
    restore_clock(st);
    odhs__st_restore_network(st);
    memcpy(st->G, st->Gs, sizeof st->G);
    st->kappa = st->kappas;
    /* velocities and external forces as they were (recomputing them from the
     * restored contact forces could call a failing force callback again, and
     * gave non-finite velocities for a restored checkpoint whose forces
     * overflow S^T f: found by fuzz_checkpoint) */
    memcpy(st->U, st->Us, st->nd * sizeof *st->U);
    memcpy(st->F, st->Fs, st->nd * sizeof *st->F);
    st->has_F = st->has_Fs;
    st->nb_stale = 1; /* rebuild the neighbour list before the next step */
    /* its displacement record may hold the failed step's motion (even a
     * non-finite one): the rebuild starts it afresh, so clear it now (a
     * checkpoint taken before the next step must not carry it) */
    memset(st->disp, 0, st->nd * sizeof *st->disp);
    memset(st->M, 0, sizeof st->M);
    for (int a = 0; a < 3; ++a) st->M[3 * (a) + (a)] = 1.0;
}

void odhs__st_mark_start(odhs_stepper *st)
{
    if (st->net->nc) memcpy(st->fr, st->net->f, st->net->nc * sizeof *st->fr);
    memcpy(st->Gr, st->G, sizeof st->Gr);
    st->kappar = st->kappa;
}

/* back to the start of the current step before any contact changed (used by
 * the adaptive integrator to repeat a step with a shorter length) */
int odhs__st_restart(odhs_stepper *st)
{
    odhs_network *net = st->net;
    odhs__st_restore_motion(st);
    restore_clock(st);
    memcpy(st->disp, st->disps, st->nd * sizeof *st->disp);
    memcpy(st->M, st->Ms, sizeof st->M);
    if (st->snc) memcpy(net->f, st->fr, st->snc * sizeof *net->f);
    memcpy(st->G, st->Gr, sizeof st->G);
    st->kappa = st->kappar;
    odhs__net_geometry(net, st->sys);
    return odhs__st_external_forces(st);
}
