/*
 * libodhs - composite.h: composite particles (Sect. V C of Lerner, During &
 * Wyart 2013): bonds, floppy chains and rigid bodies built from the stepper's
 * particles. (Declared in odhs/stepper.h before 0.2.4, which still includes
 * this header.)
 */
#ifndef ODHS_COMPOSITE_H
#define ODHS_COMPOSITE_H

#include "odhs/stepper.h"

#ifdef __cplusplus
extern "C" {
#endif

/* ---- composite particles (Sect. V C) ------------------------------------
 * Bonds are permanent contacts: rows of S that never open and may carry a
 * negative force, held at a rest length by the same drift correction as the
 * contacts. Adding bonds invalidates the current forces: the next step (or
 * odhs_stepper_reset) re-solves them. On any error nothing is added. */

/** Bond particles i and j at centre distance `rest` (> 0), or at their current
 *  distance when rest == 0. The pair must be within half a rest length of rest
 *  and closer than half the shortest box edge. A temporary contact (i,j)
 *  becomes the bond. Errors: ODHS_E_RANGE, ODHS_E_INVALID (i == j, already
 *  bonded, too far), ODHS_E_NONFINITE. */
ODHS_API int odhs_stepper_add_bond(odhs_stepper *st, size_t i, size_t j, double rest);
/** A floppy chain: bonds between consecutive beads[0..k-1] (k >= 2) at their
 *  current distances. */
ODHS_API int odhs_stepper_add_chain(odhs_stepper *st, size_t k, const size_t *beads);
/**
 * A rigid body of the k >= 2 particles beads[] at their current relative
 * positions: a minimal infinitesimally rigid set of bonds (each bead bonded to
 * d earlier ones along independent directions: 2k-3 bonds in 2D, 3k-6 in 3D,
 * one for a dimer), since any further bond would be redundant and make N
 * singular. Pairs of beads of one rigid body never become temporary contacts
 * and never collide. ODHS_E_INVALID if a bead already belongs to a rigid body
 * or the beads are (nearly) collinear (2D) or coplanar (3D, k >= 4): distance
 * constraints cannot make a straight rod of 3 or more beads rigid (use a
 * dimer, a chain, or beads off one line).
 */
ODHS_API int odhs_stepper_add_rigid_body(odhs_stepper *st, size_t k, const size_t *beads);
/** Number of permanent contacts (bonds). */
ODHS_API int odhs_stepper_bond_count(const odhs_stepper *st, size_t *count);

#ifdef __cplusplus
}
#endif
#endif /* ODHS_COMPOSITE_H */
