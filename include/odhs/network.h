/*
 * libodhs - network.h: the contact network and the operator S.
 *
 * A contact c joins particles i < j (ordered so) along the minimum-image
 * separation R_ij = R_j - R_i with unit normal n_c = R_ij / r_ij. Its row of the
 * operator S (Nc x N*dim) holds -n_c on particle i's block and +n_c on j's, so
 * (S V)_c = (V_j - V_i).n_c is the rate of change of r_ij and (S^T f) is the
 * contact force on every particle (eqs. 1-8 of Lerner, During & Wyart 2013).
 * N = S S^T. Forces f_c > 0 are repulsive.
 *
 * Kinds: ODHS_CONTACT_TEMPORARY contacts open when their force would turn
 * negative; ODHS_CONTACT_PERMANENT contacts (bonds of composite particles)
 * never open and may carry negative force.
 *
 * ODHS_CONTACT_WALL contacts join particle i to hard wall w and are reported as
 * the pair (i, N + w); their row of S holds -n_c on particle i's block only,
 * with n_c the unit normal from the particle towards the wall; they open like
 * temporary contacts.
 *
 * Contact indices (0..Nc-1) are positions in the current list and change when
 * contacts are added or removed; pairs (i,j) are the stable identities.
 */
#ifndef ODHS_NETWORK_H
#define ODHS_NETWORK_H

#include "odhs/system.h"

#ifdef __cplusplus
extern "C" {
#endif

typedef struct odhs_network odhs_network;

enum {
    ODHS_CONTACT_TEMPORARY = 0,
    ODHS_CONTACT_PERMANENT = 1,
    ODHS_CONTACT_WALL = 2 /* particle i against wall j - N (see walls.h) */
};

/** Create an empty network for the particles of sys (the network remembers N
 *  and the dimension; geometry is read from a system on update). */
ODHS_API int odhs_network_create(const odhs_system *sys, odhs_network **out);
/** Destroy a network; NULL is a no-op. */
ODHS_API void odhs_network_destroy(odhs_network *net);
/** Last error message on this handle ("" if none). */
ODHS_API const char *odhs_network_errmsg(const odhs_network *net);

/** Add the contact (i,j) of the given kind (ODHS_CONTACT_*). Errors:
 *  ODHS_E_RANGE, ODHS_E_INVALID (i == j, bad kind, already present). */
ODHS_API int odhs_network_add(odhs_network *net, size_t i, size_t j, int kind);
/**
 * Add a permanent contact (a bond of a composite particle, Sect. V C) between
 * i and j held at the centre distance `rest` (> 0) instead of a_i + a_j, so
 * that beads may overlap or stand apart. If (i,j) is a temporary contact it
 * becomes permanent. Errors: ODHS_E_RANGE, ODHS_E_INVALID (i == j, already
 * bonded, rest <= 0), ODHS_E_NONFINITE. Permanent contacts added with
 * odhs_network_add keep the rest length a_i + a_j.
 */
ODHS_API int odhs_network_add_bond(odhs_network *net, size_t i, size_t j, double rest);
/** Target distance of contact k: its rest length for a bond, else a_i + a_j
 *  (radii read from sys). */
ODHS_API int odhs_network_get_rest_length(const odhs_network *net, const odhs_system *sys, size_t k,
                                          double *rest);
/** Remove the contact (i,j). ODHS_E_INVALID if absent. */
ODHS_API int odhs_network_remove(odhs_network *net, size_t i, size_t j);
/** Remove every contact. */
ODHS_API int odhs_network_clear(odhs_network *net);
/** Whether (i,j) is a contact: *index receives its index or SIZE_MAX. */
ODHS_API int odhs_network_find(const odhs_network *net, size_t i, size_t j, size_t *index);

/**
 * Add, as temporary contacts, all pairs of sys whose gap |r_ij| - (a_i + a_j)
 * is at most tol * (a_i + a_j) (tol >= 0), then update the geometry.
 */
ODHS_API int odhs_network_detect(odhs_network *net, const odhs_system *sys, double tol);
/** Recompute normals, distances and gaps of all contacts from sys. */
ODHS_API int odhs_network_update_geometry(odhs_network *net, const odhs_system *sys);

/** Number of contacts Nc. */
ODHS_API size_t odhs_network_count(const odhs_network *net);
/** Number of particles N and dimension d the network was made for. */
ODHS_API size_t odhs_network_particles(const odhs_network *net);
ODHS_API int odhs_network_dim(const odhs_network *net);

/** Contact k: particles (*i < *j), kind; any output may be NULL. */
ODHS_API int odhs_network_get_contact(const odhs_network *net, size_t k, size_t *i, size_t *j,
                                      int *kind);
/** Every contact at once: i[k] < j[k] and kind[k] for k < Nc (caller's
 *  arrays of Nc entries; any may be NULL, not all). Walls: j = N + wall
 *  index, as odhs_network_get_contact. Since 0.2.7. */
ODHS_API int odhs_network_get_contacts(const odhs_network *net, size_t *i, size_t *j, int *kind);
/** Copy per-contact data (Nc entries; normals Nc*dim) as of the last geometry
 *  update / force computation. */
ODHS_API int odhs_network_get_forces(const odhs_network *net, double *f);
ODHS_API int odhs_network_get_gaps(const odhs_network *net, double *gap);
ODHS_API int odhs_network_get_normals(const odhs_network *net, double *n);
/** Set the forces (Nc entries), e.g. from a user solve. */
ODHS_API int odhs_network_set_forces(odhs_network *net, const double *f);

/** out(Nc) = S v, v of length N*dim. */
ODHS_API int odhs_network_apply_S(const odhs_network *net, const double *v, double *out);
/** out(N*dim) = S^T f. */
ODHS_API int odhs_network_apply_ST(const odhs_network *net, const double *f, double *out);
/** out(Nc) = N x = S S^T x; work must hold N*dim doubles (or be NULL: then the
 *  call allocates). */
ODHS_API int odhs_network_apply_N(const odhs_network *net, const double *x, double *out,
                                  double *work);
/** Number of nonzeros of S (2*dim per contact). */
ODHS_API size_t odhs_network_nnz(const odhs_network *net);
/** S in compressed sparse row form: rowptr[Nc+1], col[nnz], val[nnz]. */
ODHS_API int odhs_network_get_S_csr(const odhs_network *net, size_t *rowptr, size_t *col,
                                    double *val);

/** Mean coordination z = 2 Nc / N. */
ODHS_API int odhs_network_coordination(const odhs_network *net, double *z);

/**
 * Constrained subset (Sect. IV D): particles with at least d+1 contacts to
 * other particles of the subset, found by iterative removal (integer
 * arithmetic). With permanent contacts the unit is a body (a connected
 * component of the permanent contacts): a body of k beads with p internal
 * contacts has dof = d k - p degrees of freedom (at least d for a particle, 3
 * in 2D, 5 for a dimer and 6 otherwise in 3D) and stays in the subset with at
 * least dof + 1 contacts to other bodies of the subset; its beads are in or out
 * together and its internal contacts count in Ncon. Outputs (any may be NULL): *nbar its size, *ncon the number of
 * contacts inside it, in_subset[N] flags (1 = constrained), and *zbar_num,
 * the numerator 2(d-1) + sum_i zbar_i of eq. (29) so that zbar = zbar_num/nbar.
 * Particles outside the subset are the rattlers (and loosely connected ones).
 */
ODHS_API int odhs_network_constrained(const odhs_network *net, size_t *nbar, size_t *ncon,
                                      unsigned char *in_subset, long *zbar_num);
/**
 * Rattlers: particles outside the constrained subset (fewer than d+1 contacts
 * with constrained particles after iterative removal). is_rattler[N] (may be
 * NULL) receives 1 for rattlers, *count (may be NULL) their number.
 */
ODHS_API int odhs_network_rattlers(const odhs_network *net, unsigned char *is_rattler, size_t *count);

/**
 * Whether the constrained subset is potentially jammed: Ncon >= d(Nbar-1)+1
 * (equivalently zbar >= 2d, eq. 29, in integers). *flag = 1 or 0.
 */
ODHS_API int odhs_network_potentially_jammed(const odhs_network *net, int *flag);

struct odhs_solver; /* see solver.h */

/**
 * The self-stress f0 of a potentially jammed network (Sect. IV D): the nonzero
 * solution of S^T f0 = 0 on the constrained subset (zero on every other
 * contact), with the sign fixed so that sum f0 > 0 and scaled to mean 1 over
 * the subset's contacts. f0 has Nc entries. The network must be potentially
 * jammed (else ODHS_E_STATE). Method: with solver == NULL, or a subset of at
 * most 600 contacts, the right singular vector of the smallest singular value
 * of S^T on the subset (LAPACK dgesvd; since 0.2.1); otherwise one contact k is fixed to f0_k = 1 and the
 * rest solve S'^T y = -s_k^T in the least-squares sense with the solver on the
 * remaining contacts (other k are tried if that network is singular).
 * *residual (may be NULL) receives max_i |(S^T f0)_i| / mean f0.
 * ODHS_E_SINGULAR when the kernel is not one-dimensional.
 */
ODHS_API int odhs_network_null_vector(const odhs_network *net, struct odhs_solver *solver, double *f0,
                                      double *residual);

#ifdef __cplusplus
}
#endif
#endif /* ODHS_NETWORK_H */
