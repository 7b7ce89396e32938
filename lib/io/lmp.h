/*
 * libodhs private header: the LAMMPS conventions shared by the data-file
 * reader and writer (lammps.c) and the dump writers (traj.c). Not installed.
 *
 * LAMMPS stores a sheared periodic cell as a triclinic box: edge vectors
 * a = (Lx,0,0), b = (xy,Ly,0), c = (0,0,Lz) with the origin at (0,0,0) here.
 * The Lees-Edwards image across y shifts x by gamma*Ly, and by any multiple of
 * Lx on top, so the tilt written is gamma*Ly reduced into [-Lx/2, Lx/2]
 * (what LAMMPS accepts without `box tilt large`), and positions are shifted
 * by multiples of Lx into that parallelogram, where LAMMPS does not remap them.
 * Atom types number the species labels 1, 2, ... in order of first appearance.
 */
#ifndef ODHS_IO_LMP_H
#define ODHS_IO_LMP_H

#include <stddef.h>

#include "system/system.h"

/* the tilt xy of the cell: gamma*Ly reduced by multiples of Lx into [-Lx/2, Lx/2] */
double odhs__lmp_tilt(double Lx, double Ly, double gamma);

/* *x shifted by a multiple of Lx so that 0 <= *x - xy*y/Ly < Lx */
void odhs__lmp_wrap(double *x, double y, double Lx, double Ly, double xy);

/* Number the species of sys: type[i] in 1..ntypes for every particle (N
 * entries), names[t-1] the label of type t (room for N labels). Returns the
 * number of types. */
size_t odhs__lmp_types(const odhs_system *sys, int *type, char (*names)[ODHS_SPECIES_MAX + 1]);

#endif /* ODHS_IO_LMP_H */
