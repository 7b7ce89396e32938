/*
 * libodhs private header: self-stress (null vectors), polishing and the pair self-stress
 * of jammed packings (Sect. IV D).
 * Not installed.
 */
#ifndef ODHS_JAMMING_JAMMING_H
#define ODHS_JAMMING_JAMMING_H

#include "solvers/solvers.h"

int odhs__jam_polish(odhs_system *sys, odhs_network *net, odhs_solver *sol, const double *f0);
/* the self-stress h of an isostatic network plus a pair (i, j) outside it,
 * h = 1 on the pair, <h|r> = 0 (lib/jamming.c) */
int odhs__jam_pair_stress(const odhs_network *net, odhs_solver *sol, const double *f0, size_t i, size_t j,
                          const double *nrm, double dist, double *h);
int odhs__null_vector(const odhs_network *net, odhs_solver *solver, double *f0, double *residual);
/* the same; refine = 1: one step of iterative refinement of the sparse
 * solve (the final f0 of a jammed packing) */
int odhs__null_vector_ex(const odhs_network *net, odhs_solver *solver, double *f0, double *residual, int refine);
/* fixed pressure: the kernel vector fs of S^T with <r|fs> = 0 (the volume as
 * one more column of S) on a constrained subset with d(Nbar - 1) + 2
 * contacts, max |fs| = 1, sign undetermined; by the SVD of that matrix
 * (lib/jamming.c) */
int odhs__null_vector_volume(const odhs_network *net, double *fs);
/* the right singular vector of S^T (constrained subset) for its smallest
 * singular value, with max |y| = 1, whether or not the contact count shows a
 * self-stress: the near-kernel of a network whose N is singular or nearly so
 * (the dense SVD, always; a rare fallback). ODHS_E_SINGULAR when that
 * singular value is not separated from the next. */
int odhs__null_vector_any(const odhs_network *net, double *y);

#endif /* ODHS_JAMMING_JAMMING_H */
