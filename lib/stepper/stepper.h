/*
 * libodhs private header: the event stepper handle.
 * Not installed.
 */
#ifndef ODHS_STEPPER_STEPPER_H
#define ODHS_STEPPER_STEPPER_H

#include "driver/driver.h"
#include "jamming/jamming.h"

/* restored stepper: mark the neighbour list stale unless it holds every pair
 * closer than the unused skin (lib/stepper.c); ODHS_OK or ODHS_E_NOMEM */
int odhs__stepper_check_neighbours(odhs_stepper *st);
/* tests: 1 = always the anti-cycling rewiring, 0 = the paper's rule first */
int odhs__stepper_set_rewire_mode(odhs_stepper *st, int mode);

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

#endif /* ODHS_STEPPER_STEPPER_H */
