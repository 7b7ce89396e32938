/*
 * libodhs - jamming.h: certified jammed packings (Sect. IV D of the paper).
 *
 * A stepper whose rewiring meets a potentially jammed network (the
 * constrained subset has exactly d(Nbar-1)+1 contacts, eq. 29) computes the
 * self-stress f0 (S^T f0 = 0, see odhs_network_null_vector). If every
 * component is positive the packing is jammed: the stepper polishes the
 * contacts (the gap component along f0 is removed by a tiny isotropic
 * rescaling, the rest by non-affine displacements), stores f0 scaled to unit
 * pressure as the contact forces, and returns ODHS_JAMMED. Otherwise the most
 * negative contact is removed and the rewiring goes on, exactly as Sect. IV D
 * describes.
 *
 * Since 0.2.3 the polish is followed by a check of every pair outside the
 * network: a pair that the polished geometry leaves overlapping (by more
 * than 4e-15 of its contact distance; it touched the packing to within the
 * precision of the integration), of two backbone particles or of one and a
 * rattler with d contacts of its own, is taken into the
 * network, and the contact that the dual simplex ratio test picks leaves it
 * (the self-stress of the network plus the pair, kept positive, with the
 * pressure fixed), then the packing is polished again; at most 64 such
 * pivots. The certificate's n_pivots counts them. Scenes with walls skip it.
 * A rattler left overlapping (it has too few contacts to be pivoted in) is
 * moved out of the overlap, and its force-free contacts open (not with bonds
 * or walls).
 *
 * Since 0.2.3 f0 must also be positive on the final (polished) geometry. A
 * polish that starts from large contact gaps (a coarse integration with a
 * sparse drift correction, such as the paper's Euler scheme with correction
 * every 10 steps) can change its signs; then the packing is not jammed, the
 * step returns ODHS_POTENTIALLY_JAMMED with a message, and it is not taken
 * (the state stays as before the step). Version 0.2.2 returned ODHS_JAMMED
 * there, and only the certificate showed it.
 */
#ifndef ODHS_JAMMING_H
#define ODHS_JAMMING_H

#include "odhs/io.h"
#include "odhs/stepper.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Certificate of a packing. Set `size` to sizeof(odhs_jam_certificate)
 * before the call: fields beyond it (added in later versions) are not written.
 * Forces are relative to the mean force on the backbone (the constrained
 * subset); gaps and overlaps relative to the pair's contact distance.
 */
typedef struct odhs_jam_certificate {
    size_t size;                 /* in: sizeof(odhs_jam_certificate)            */
    int jammed;                  /* 1: the stepper found the packing jammed     */
    int isostatic;               /* backbone contacts == d(Nbar-1)+1            */
    double phi;                  /* packing fraction                             */
    double pressure;             /* <f|r>/(Omega d) of the stored forces          */
    size_t n_particles;
    size_t n_rattlers;           /* particles outside the backbone               */
    size_t n_backbone;           /* Nbar                                         */
    size_t n_contacts;           /* all contacts                                 */
    size_t n_contacts_backbone;  /* contacts inside the backbone                 */
    size_t n_contacts_isostatic; /* d(Nbar-1)+1                                  */
    double z;                    /* 2 Nc / N                                     */
    double z_backbone;           /* 2 Nc_backbone / Nbar                         */
    double force_balance;        /* max over backbone particles |sum_c f_c n_c| / mean f */
    double gap_error;            /* max over contacts |gap| / (a_i + a_j)        */
    double overlap;              /* max over non-contact pairs of overlap/(a_i+a_j), 0 if none */
    double min_force;            /* smallest backbone force / mean f             */
    /* since 0.2.3: pairs that the final pivots took into the network when
     * this stepper found the packing (see above; 0 after a restore from a
     * checkpoint, which does not store it) */
    size_t n_pivots;
} odhs_jam_certificate;

/** Fill a certificate for the stepper's current state (jammed or not). */
ODHS_API int odhs_stepper_certificate(const odhs_stepper *st, odhs_jam_certificate *cert);

/* ---- the fast route (since 0.2.9) ----------------------------------------- */

/**
 * Settings of odhs_stepper_jam_lp. Set `size` to sizeof(odhs_jam_lp_options);
 * a field left 0 takes its default.
 */
typedef struct odhs_jam_lp_options {
    size_t size;      /* in: sizeof(odhs_jam_lp_options)                           */
    double trust;     /* bound on each displacement component per programme, in
                       * mean diameters, in (0, 0.5] (default 0.1)                  */
    double tol;       /* the chain ends when sqrt(Gamma) - 1 < tol (default 1e-12)  */
    size_t max_lps;   /* programmes at most (default 10000)                         */
    size_t max_steps; /* event-driven steps of the end game at most (default 1e5)   */
    /* since 0.2.10: the quench start (see below) */
    int quench;        /* 1: start from a soft-sphere quench; 0: from the configuration */
    double quench_phi; /* the quench's packing fraction, in (0, 1) (default 0.86 in 2D,
                        * 0.66 in 3D: above phi_J of common mixtures)                */
    /* since 0.2.22: how the end game steps (see below) */
    int own_integrator; /* 0 (default): batched-event steps (ODHS_INTEGRATOR_BATCHED
                         * at its default tolerance and dt), the stepper's own
                         * settings put back on return; 1: the stepper's own
                         * integrator and settings, as up to 0.2.21           */
} odhs_jam_lp_options;

/** What odhs_stepper_jam_lp did. Set `size` to sizeof(odhs_jam_lp_report). */
typedef struct odhs_jam_lp_report {
    size_t size;                 /* in: sizeof(odhs_jam_lp_report)               */
    size_t n_lps;                /* linear programmes solved                      */
    uint64_t simplex_iterations; /* simplex iterations over all of them (primal
                                  * for the first programme of the chain, dual
                                  * for the others and after a shake)           */
    size_t rows_max;             /* largest number of pair constraints            */
    double phi_lp;               /* packing fraction at the end of the chain      */
    double growth_last;          /* sqrt(Gamma) - 1 of the last programme         */
    uint64_t end_steps;          /* event-driven steps of the end game (usually 0) */
    size_t shakes;               /* degenerate packings shaken and jammed again    */
    size_t polishes;             /* extra polishes of the packing's contact gaps   */
    /* since 0.2.10 */
    uint64_t quench_iterations;  /* FIRE iterations of the quench (0 without)     */
    double phi_start;            /* packing fraction where the chain started      */
    /* since 0.2.11 */
    size_t quench_steps;         /* rescalings of the quench toward phi_J         */
} odhs_jam_lp_report;

/**
 * The fast route to a certified jammed packing: compress the stepper's
 * system to jamming by a chain of linear programmes, then finish with the
 * stepper's exact end game, and return ODHS_JAMMED with the packing in the
 * stepper (its network, forces and odhs_stepper_certificate exactly as after
 * a compression run that returned ODHS_JAMMED).
 *
 * Each programme maximises the growth Gamma of the squared contact
 * distances over displacements s (|s_i,a| <= trust mean diameters) subject
 * to the contact constraints linearised around the configuration,
 * |r_ij|^2 + 2 r_ij.(s_j - s_i) >= Gamma sigma_ij^2 for every pair that
 * could touch (sequential linear programming: Torquato & Jiao 2010;
 * CALiPPSO, Artiaco et al. 2022). The linearisation underestimates the real
 * distances, so no step overlaps; the configuration moves by s and the box
 * shrinks by the growth the real pairs allow. At the end (sqrt(Gamma) - 1 <
 * tol) the programme's active pairs are the jammed network: the stepper is
 * reset on the configuration, takes the touching pairs (its contact
 * tolerance) and, since 0.2.12, the last programme's active pairs with a gap
 * below 1e-6 of their contact distance as its network, and steps under the
 * compression until ODHS_JAMMED (normally at once), with the rewiring,
 * self-stress, polish and final pivots of a compression run. (The active
 * pairs' gaps are second order in the last displacements, up to about 1e-8
 * at 3D N = 8000, above the contact tolerance of 1e-9: without them the
 * network could be short of contacts and the end game stepped.)
 *
 * Since 0.2.22 these steps are batched-event steps by default
 * (opt.own_integrator = 0; the reset then rewires in blocks, as that
 * integrator's does): where the chain's packing is not yet jammed at the
 * reset, they take the many openings and closings near jamming several per
 * solve, and the step that reaches a potentially jammed network is taken
 * by the exact scheme, whose rewiring and self-stress decide jamming as
 * before. The packing is certified exactly as before; measured in
 * docs/jamming.md (3D N = 1000, a chain stopped at tol 1e-8: 1.3-5 times
 * fewer steps, the same packings, up to 3.3 times less CPU). The exact
 * steps run at the stepper's own Heun tolerance (Heun's default, 1e-6,
 * when its integrator is another). The stepper's integrator, tolerance,
 * dt, step and correction interval are put back before the call returns,
 * whatever it returns; the batched steps count in
 * odhs_stepper_batched_stats. During the call the stepper shows the
 * batched settings (odhs_stepper_get_settings from an event callback, a
 * checkpoint written there), and settings changed from a callback are
 * replaced by the saved ones on return.
 *
 * The chain ends with contact gaps up to the LP solver's tolerance; when
 * the end game's polish leaves gaps above 5e-14 (relative; 1e-14 up to
 * 0.2.9, below the round-off of large packings), the end game runs again
 * on the packing, at most twice (report.polishes).
 *
 * The quench start (opt.quench = 1; since 0.2.10) is much faster near and
 * at large N: the start is compressed affinely to quench_phi and its soft
 * (harmonic) energy minimised by FIRE (O'Hern et al.'s quench, on a copy of
 * the system, to a largest force of 1e-9, at most 1e6 iterations: an
 * unfinished minimisation is used as it is). Since 0.2.11 the soft packing
 * is then brought toward phi_J: while the mean relative overlap of its
 * contacts is above 3e-6 (3e-4 up to 0.2.23), the box grows by that overlap
 * and FIRE relaxes again (at most 20 times, 4 up to 0.2.23;
 * report.quench_steps), since 0.2.24 to a largest force of 1e-3 of the
 * mean contact force (or 1e-9, the larger). The result is dilated until
 * no pair overlaps; the chain starts there, since 0.2.24 within about
 * 1e-5 of its phi_J (3D N = 8000: a first programme 11 times as cheap).
 * Above phi_J the minimised soft packing is jammed, and its structure is
 * close to a hard jammed packing: the chain then needs tens of programmes
 * where a start far below jamming needs hundreds, each also cheaper (measured in
 * docs/jamming.md: 3D N = 1000 in about 10 CPU s against 3 CPU min). It is the
 * protocol of an infinitely fast quench, not a compression: its packings
 * are denser (2D N = 256, the same 12 starts: phi_J = 0.8434 +- 0.0016
 * against 0.8377 +- 0.0031 for the event-driven compression at rate 1,
 * standard deviations).
 *
 * A packing whose smallest backbone force is below 1e-9 of the mean (a
 * degenerate vertex of the last programme: a contact that carries no force
 * and can still open) is not returned: the configuration is dilated by
 * 1e-5, each coordinate moved by a deterministic noise of 1e-7 mean
 * diameters, and the chain runs again (at most 3 times; report.shakes).
 * Since 0.2.24 the same is done when the reset on the chain's packing finds
 * a potentially jammed network whose self-stress turns negative after the
 * polish (ODHS_POTENTIALLY_JAMMED from the reset; a nearly force-free
 * contact of such a vertex): the chain's packing is shaken and the chain
 * runs again, where up to 0.2.23 the call returned that status.
 *
 * A different protocol from the event-driven compression: the programmes
 * move particles by up to `trust` at a time, not along the overdamped
 * dynamics, so from the same start the two give different packings (and
 * different phi_J within their spread). The stepper's time advances only
 * by the end game's steps. Programmes are solved by COIN-OR CLP's dual
 * simplex (a build without it returns ODHS_E_NOTINSTALLED), each warm
 * started from the basis of the one before; CLP's own allocations are not
 * the library's (an allocation failure inside CLP is not reported as
 * ODHS_E_NOMEM).
 *
 * Requirements: the driver compresses only (compression rate > 0; no
 * shear, pressure, forces, callback, propulsion or gravity: ODHS_E_STATE
 * otherwise), the scene has no walls or bonds (ODHS_E_UNSUPPORTED), and the
 * stepper is not jammed (ODHS_JAMMED with a message). A stepper that needs a
 * reset is reset first, as odhs_stepper_step does. opt may be NULL (all
 * defaults), rep may be NULL (it is filled when the call gets to the end
 * game).
 *
 * Errors: the programmes run on private copies of the configuration, so an
 * error there (ODHS_E_NOMEM; ODHS_E_NOCONV when the LP solver stops without
 * an optimum; ODHS_E_BOX when the box is too small for the cut-off) and a
 * failed reset on the packing leave the stepper and its system as they were.
 * The end game's steps are steps: one that fails is undone, the ones before
 * it stay (as in odhs_stepper_run_until_*), and ODHS_E_STALLED after
 * max_steps leaves the state reached. The checks on the jammed packing
 * (another polish, a shake) are skipped when memory runs out: the packing
 * is then returned as the end game made it.
 */
ODHS_API int odhs_stepper_jam_lp(odhs_stepper *st, const odhs_jam_lp_options *opt, odhs_jam_lp_report *rep);

/* odhs_contacts_write (the contacts file) is declared in odhs/io.h. */

#ifdef __cplusplus
}
#endif
#endif /* ODHS_JAMMING_H */
