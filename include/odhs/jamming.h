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

/* odhs_contacts_write (the contacts file) is declared in odhs/io.h. */

#ifdef __cplusplus
}
#endif
#endif /* ODHS_JAMMING_H */
