/*
 * libodhs - walls.h: hard walls (containers, hoppers, pistons).
 *
 * A wall enters the contact network on an equal footing with the contacts
 * (Sect. VI of Lerner, During & Wyart 2013): a particle touching wall w is the
 * contact (i, N + w) of kind ODHS_CONTACT_WALL, a row of S with -n_c on particle
 * i's block only, where n_c is the unit normal from the particle towards the
 * wall. It carries a force f_c >= 0 (the wall pushes the particle along -n_c),
 * opens by the same rewiring as a contact, and its collisions are predicted
 * exactly. A moving wall (a piston) enters the right-hand side through its
 * velocity: the contact's gap changes at the rate n_c.(v_wall - V_i).
 *
 * Shapes: a plane (half-space n.x >= h), a sphere (a disc in 2D) that holds the
 * particles inside, and, in 2D, a segment of zero thickness that particles may
 * touch from either side or at its ends (funnel walls of a hopper).
 *
 * Walls live in the lab frame of the periodic box: the box stays periodic, and
 * a direction becomes non-periodic when walls keep the particles from
 * reaching across its boundary (leave at least the largest diameter between a
 * wall and the box edge behind it; wall geometry is not imaged). Walls are for
 * scenes without affine flow (no shear or compression rate: external forces,
 * moving walls); pressure control with walls is ODHS_E_UNSUPPORTED. The
 * stress tensor and pressure observables count particle contacts only; the
 * force on each wall is odhs_stepper_wall_force.
 *
 * Events with a wall report the pair (i, N + w).
 */
#ifndef ODHS_WALLS_H
#define ODHS_WALLS_H

#include "odhs/stepper.h"

#ifdef __cplusplus
extern "C" {
#endif


/** Wall shapes (pinned values). */
enum {
    ODHS_WALL_PLANE = 0,
    ODHS_WALL_SPHERE = 1,
    ODHS_WALL_SEGMENT = 2
};

/**
 * A plane wall: particles live where normal.x >= offset + a_i (normal has dim
 * entries, any nonzero length; it is normalised and offset scaled with it).
 * *id (may be NULL) receives the wall's index. Particles must not overlap the
 * new wall (ODHS_E_OVERLAP names the worst one; nothing is added). Adding a
 * wall invalidates the forces: the next step re-solves them.
 */
ODHS_API int odhs_stepper_add_wall_plane(odhs_stepper *st, const double *normal, double offset, size_t *id);
/** A spherical (circular in 2D) container of the given centre (dim entries)
 *  and radius > 0: particles stay inside. */
ODHS_API int odhs_stepper_add_wall_sphere(odhs_stepper *st, const double *centre, double radius,
                                          size_t *id);
/** A segment wall from a to b (2D only, ODHS_E_DIM otherwise), of zero
 *  thickness: particles touch it from either side or at its ends. */
ODHS_API int odhs_stepper_add_wall_segment(odhs_stepper *st, const double *a, const double *b, size_t *id);
/** Translate wall id at velocity v (dim entries, in lab units per unit time;
 *  zero stops it): a piston. */
ODHS_API int odhs_stepper_set_wall_velocity(odhs_stepper *st, size_t id, const double *v);
/** Number of walls. */
ODHS_API int odhs_stepper_wall_count(const odhs_stepper *st, size_t *count);
/** Force the particles exert on wall id (dim entries): sum of f_c n_c over its
 *  contacts. */
ODHS_API int odhs_stepper_wall_force(const odhs_stepper *st, size_t id, double *force);
/** Displacement of wall id since it was added (dim entries). */
ODHS_API int odhs_stepper_wall_displacement(const odhs_stepper *st, size_t id, double *disp);

#ifdef __cplusplus
}
#endif
#endif /* ODHS_WALLS_H */
