/*
 * libodhs - system.h: the system handle (particles, radii, periodic box with
 * Lees-Edwards strain), geometry queries, neighbour search and scene builders.
 *
 * Conventions (stated once, used everywhere):
 *  - Positions are lab-frame Cartesian coordinates, row-major: x[i*d + k].
 *  - The box is periodic with edge lengths L = (Lx, Ly[, Lz]). Simple shear acts
 *    in the x-y plane with Lees-Edwards boundaries: the periodic lattice is
 *    spanned by a = (Lx,0,0), b = (gamma*Ly, Ly, 0), c = (0,0,Lz). The strain
 *    gamma is kept in [-Lx/(2Ly), Lx/(2Ly)] (that is [-1/2, 1/2] for Lx = Ly) by
 *    the usual remapping b -> b -/+ a, which changes gamma by Lx/Ly and leaves
 *    the lattice, and so the physical configuration, unchanged.
 *  - Stored positions lie in the lab rectangle [0,Lx) x [0,Ly) [x [0,Lz)]; any
 *    position passed in is wrapped there (a position already inside is kept
 *    bit for bit).
 *  - Separations use the minimum image of the sheared lattice, which is exact
 *    for pairs closer than min(L)/2; boxes smaller than two largest diameters
 *    are rejected for that reason.
 *  - Particle indices are identities: the library never renumbers particles.
 *  - Overlap checks accept overlaps smaller than 1e-10 of the pair's contact
 *    distance r_i + r_j (round-off of contacts in files the library wrote);
 *    anything larger is ODHS_E_OVERLAP, naming the worst pair.
 */
#ifndef ODHS_SYSTEM_H
#define ODHS_SYSTEM_H

#include "odhs/common.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Opaque system handle. */
typedef struct odhs_system odhs_system;

/** Longest species label, without the terminating NUL. */
#define ODHS_SPECIES_MAX 15

/**
 * Create a system of n particles in dim (2 or 3) dimensions. The box is a unit
 * cube, strain 0, radii and positions unset (a system becomes usable once both
 * are set), species labels "A".
 * Errors: ODHS_E_NULL (out), ODHS_E_DIM, ODHS_E_EMPTY (n == 0), ODHS_E_NOMEM.
 */
ODHS_API int odhs_system_create(int dim, size_t n, odhs_system **out);
/** Destroy a system. NULL is a no-op. */
ODHS_API void odhs_system_destroy(odhs_system *sys);
/** Deep copy of a system (positions, radii, box, strain, species). */
ODHS_API int odhs_system_clone(const odhs_system *sys, odhs_system **out);
/** Last error message recorded on this handle ("" if none; never NULL). */
ODHS_API const char *odhs_system_errmsg(const odhs_system *sys);

/** Dimension (2 or 3); 0 if sys is NULL. */
ODHS_API int odhs_system_dim(const odhs_system *sys);
/** Number of particles; 0 if sys is NULL. */
ODHS_API size_t odhs_system_count(const odhs_system *sys);
/** Whether both radii and positions have been set (1) or not (0). */
ODHS_API int odhs_system_is_ready(const odhs_system *sys);

/** How many times the public setters (set_box, set_strain, set_radii,
 *  set_positions, set_configuration, scale_box, set_radii_bidisperse,
 *  place_random) changed the box, strain, radii or positions: a call that
 *  writes the values already held does not count. The stepper moves
 *  particles without counting; it remembers the count it last saw and
 *  refuses to step (ODHS_E_STATE) after a change behind its back until
 *  odhs_stepper_reset (stepper.h). Species labels do not count. Since 0.2.7. */
ODHS_API int odhs_system_change_count(const odhs_system *sys, uint64_t *count);

/**
 * Set the box edge lengths L[0..dim-1] (scales nothing: positions are wrapped
 * into the new box and checked for overlaps if radii and positions are set).
 * The stored strain representative (see odhs_system_get_strain) is kept and
 * remapped for the new edges.
 * Errors: ODHS_E_NONFINITE, ODHS_E_INVALID (L <= 0), and with radii and
 * positions set ODHS_E_BOX (an edge shorter than twice the largest diameter)
 * and ODHS_E_OVERLAP.
 */
ODHS_API int odhs_system_set_box(odhs_system *sys, const double *L);
/** Copy the box edge lengths into L[0..dim-1]. */
ODHS_API int odhs_system_get_box(const odhs_system *sys, double *L);
/** Box volume (area in 2D) into *vol. */
ODHS_API int odhs_system_volume(const odhs_system *sys, double *vol);

/**
 * Set the Lees-Edwards strain gamma (any finite value; it is remapped into
 * [-Lx/(2Ly), Lx/(2Ly)] as above). The positions are kept; the images of the
 * lattice change. Errors: ODHS_E_NONFINITE, ODHS_E_INVALID (|gamma| beyond
 * 2^50 Lx/Ly: cannot be remapped exactly), ODHS_E_OVERLAP (with particles
 * set, if the new images overlap).
 */
ODHS_API int odhs_system_set_strain(odhs_system *sys, double gamma);
/** Current (remapped) Lees-Edwards strain, in [-Lx/(2Ly), Lx/(2Ly)]. */
ODHS_API int odhs_system_get_strain(const odhs_system *sys, double *gamma);

/**
 * Set all radii r[0..n-1]. Errors: ODHS_E_NONFINITE, ODHS_E_INVALID (r <= 0),
 * and, only if positions are already set, ODHS_E_BOX and ODHS_E_OVERLAP (the
 * message names the pair). Before positions exist the box may be any size:
 * odhs_system_place_random chooses it.
 */
ODHS_API int odhs_system_set_radii(odhs_system *sys, const double *r);
/** Copy the radii into r[0..n-1]. ODHS_E_STATE if radii were never set. */
ODHS_API int odhs_system_get_radii(const odhs_system *sys, double *r);

/**
 * Set all positions x[0..n*dim-1] (lab frame; wrapped into the box).
 * Errors: ODHS_E_NONFINITE, ODHS_E_INVALID (a coordinate more than 2^50 box
 * lengths away: its image cannot be found exactly), ODHS_E_OVERLAP (if radii
 * are set; the message names the pair and the overlap).
 */
ODHS_API int odhs_system_set_positions(odhs_system *sys, const double *x);
/** Copy the (wrapped, lab-frame) positions into x[0..n*dim-1].
 *  ODHS_E_STATE if positions were never set. Functions that need both radii
 *  and positions (separation, validate, for_each_pair, packing_fraction needs
 *  radii) return ODHS_E_STATE before they are set. */
ODHS_API int odhs_system_get_positions(const odhs_system *sys, double *x);

/**
 * Set box, strain, radii and positions at once and validate the whole; on any
 * error nothing changes. L has dim entries, r n entries, x n*dim entries.
 */
ODHS_API int odhs_system_set_configuration(odhs_system *sys, const double *L, double gamma,
                                           const double *r, const double *x);

/** Set the species label of particle i (1..ODHS_SPECIES_MAX printable
 *  characters, no white space or quotes). */
ODHS_API int odhs_system_set_species(odhs_system *sys, size_t i, const char *label);
/** Copy the species label of particle i into buf (size >= ODHS_SPECIES_MAX+1). */
ODHS_API int odhs_system_get_species(const odhs_system *sys, size_t i, char *buf, size_t size);

/**
 * Scale the box and all positions isotropically by factor s (> 0): an affine
 * compression (s < 1) or dilation (s > 1). Errors: ODHS_E_INVALID,
 * ODHS_E_NONFINITE, ODHS_E_BOX, ODHS_E_OVERLAP (compression into overlap).
 */
ODHS_API int odhs_system_scale_box(odhs_system *sys, double s);

/** Packing fraction sum(particle volumes) / box volume. */
ODHS_API int odhs_system_packing_fraction(const odhs_system *sys, double *phi);

/**
 * Minimum-image separation R_ij = R_j - R_i (lab frame) into rij[0..dim-1];
 * optional: dist (|R_ij|) and image (integer lattice shift n such that
 * R_ij = x_j - x_i + n0 a + n1 b + n2 c; may be NULL). Valid for pairs closer
 * than half the shortest box edge.
 */
ODHS_API int odhs_system_separation(const odhs_system *sys, size_t i, size_t j, double *rij,
                                    double *dist, int *image);

/**
 * Check the whole configuration: finite values, positive radii, box at least
 * two largest diameters, no overlaps beyond tol (absolute length; 0 means
 * any overlap counts). ODHS_OK if valid, else the error with a message.
 */
ODHS_API int odhs_system_validate(const odhs_system *sys, double tol);

/**
 * Callback for pair enumeration: i < j, rij the minimum-image separation
 * (dim entries), gap = |rij| - (r_i + r_j). Return 0 to go on, nonzero to stop
 * (the enumeration then returns ODHS_STOPPED).
 */
typedef int (*odhs_pair_fn)(size_t i, size_t j, const double *rij, double gap, void *ctx);

/**
 * Visit every pair with gap <= max_gap (max_gap >= 0, absolute length and less
 * than half the shortest box edge minus the largest diameter) in O(N) time with
 * cell lists valid under any Lees-Edwards strain and polydispersity. The order
 * of visits is unspecified.
 */
ODHS_API int odhs_system_for_each_pair(const odhs_system *sys, double max_gap, odhs_pair_fn fn,
                                       void *ctx);

/* ---- scene builders ------------------------------------------------------- */

/**
 * Radii of a 50:50 bidisperse mixture: particles 0,2,4,... small (r_small),
 * 1,3,5,... large (r_small*ratio), each multiplied by an independent factor
 * uniform in [1-poly, 1+poly] (poly in [0,1); 0 for none). Species S and L.
 * Random numbers: xoshiro256** seeded through splitmix64(seed).
 */
ODHS_API int odhs_system_set_radii_bidisperse(odhs_system *sys, double r_small, double ratio,
                                              double poly, uint64_t seed);

/**
 * Place all particles at random without overlap at packing fraction phi by
 * random sequential addition (largest particles first), after setting the box
 * so that the packing fraction is phi. The box keeps the aspect ratios of the
 * current box edges and strain 0. Radii must be set. Reproducible from seed
 * (xoshiro256**, splitmix64 seeding; the same seed gives the same scene on
 * every platform with IEEE doubles).
 * With the largest particles placed first RSA reaches about phi = 0.55-0.6 in
 * 2D and 0.4-0.45 in 3D for a 1.4 bidisperse mixture (less for monodisperse
 * particles); beyond its limit (2e6 failed attempts for one particle) the call fails with ODHS_E_TOODENSE and leaves the
 * system unchanged. Denser states are reached by compression (see stepper.h).
 */
ODHS_API int odhs_system_place_random(odhs_system *sys, double phi, uint64_t seed);

#ifdef __cplusplus
}
#endif
#endif /* ODHS_SYSTEM_H */
