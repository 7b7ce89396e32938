/*
 * libodhs - lammps.h: LAMMPS data files (atom_style sphere). Since 0.2.6.
 *
 * Format written (LAMMPS "read_data" syntax, atom_style sphere):
 *
 *   LAMMPS data file written by libodhs VERSION: dim=D strain=GAMMA types: 1=S 2=L
 *
 *   N atoms
 *   NT atom types
 *
 *   0 Lx xlo xhi
 *   0 Ly ylo yhi
 *   ZLO ZHI zlo zhi          (3D: 0 Lz; 2D: -0.5 0.5)
 *   XY 0 0 xy xz yz
 *
 *   Atoms # sphere
 *
 *   id type diameter density x y z
 *
 * with one Atoms line per particle: id = i+1 in the library's particle order,
 * type numbering the species labels 1, 2, ... in order of first appearance
 * (the title lists them), diameter = 2 r, density 1, z = 0 in 2D. The cell is
 * LAMMPS's triclinic box a = (Lx,0,0), b = (xy,Ly,0), c = (0,0,Lz) with the
 * tilt xy = gamma*Ly reduced by multiples of Lx into [-Lx/2, Lx/2] (what LAMMPS
 * accepts without `box tilt large`; the xy line is written even when xy = 0),
 * and x is shifted by a multiple of Lx into that parallelogram, so that LAMMPS
 * keeps every atom where it is. Numbers have 17 significant digits: box,
 * strain (from the title), radii, y and z read back bit for bit; x reads back
 * modulo Lx, exactly unless the shift was x + Lx, whose rounding can move it by
 * up to an ulp of Lx (never at strain 0, where no shift is needed).
 *
 * The reader accepts these files and those of LAMMPS's own write_data:
 *  - line 1 is the title. When it holds the words dim=D (2 or 3), strain=G
 *    or "types:" followed by T=LABEL words, they are used (in any title; a
 *    malformed value is an error on line 1);
 *  - header lines "<numbers> <keywords>" up to the first section: "atoms",
 *    "atom types", "xlo xhi", "ylo yhi", "zlo zhi" (default -0.5 0.5, as in
 *    LAMMPS) and "xy xz yz" (default 0 0 0) are used, any other header line
 *    that ends in keywords ("0 bonds", ...) is ignored; "atoms", "atom types",
 *    "xlo xhi" and "ylo yhi" are required;
 *  - sections: a line starting with a letter is a section keyword, optionally
 *    followed by a "# style" comment; its data lines start with a number.
 *    Exactly one "Atoms" section is required; if it carries a style comment
 *    it must be "sphere". Every other section (Velocities, Masses, ...) is
 *    skipped. The Atoms section holds exactly N lines
 *    "id type diameter density x y z" with optional image flags "ix iy iz"
 *    (ignored), in any id order; ids are exactly 1..N, each once (atom id k
 *    becomes particle k-1), types lie in 1..ntypes, diameters and densities
 *    are positive (LAMMPS's point particles, diameter 0, are refused);
 *  - '#' starts a comment on every line but the title; blank lines are
 *    ignored; lines may end in CRLF; tokens are separated by blanks or tabs;
 *  - dimension: dim=D from the title when present, otherwise 2 when every z
 *    is exactly 0 and zlo < 0 < zhi, else 3 (so a 3D monolayer at z = 0
 *    written by LAMMPS reads as 2D). With dim=2 every z must be 0;
 *  - box: Lx = xhi-xlo, Ly = yhi-ylo, Lz = zhi-zlo (3D), positions taken
 *    relative to (xlo, ylo, zlo); xz and yz must be 0 (only x-y shear);
 *  - strain: xy/Ly, except that when the title holds strain=G and G*Ly - xy
 *    is a multiple of Lx (within 1e-12 Lx), G is used (the same lattice; an
 *    exact round trip of the library's strain);
 *  - species: the label of type T is the title's T=LABEL when given (a
 *    species label: 1..ODHS_SPECIES_MAX printable characters, no blanks,
 *    quotes or '='), otherwise T as a decimal number ("1", "2", ...).
 * Malformed input gives ODHS_E_FORMAT with a message naming the line, and
 * never a half-filled system. Overlaps up to 1e-4 of the contact distance
 * are accepted on reading, as for the XYZ reader (io.h).
 */
#ifndef ODHS_LAMMPS_H
#define ODHS_LAMMPS_H

#include "odhs/system.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Write the system to path as a LAMMPS data file in the format above (the file
 * is written to a temporary name in the same directory and renamed, so a
 * failed write leaves any old file intact). The message of an error is
 * recorded on the handle (odhs_system_errmsg). Errors: ODHS_E_NULL,
 * ODHS_E_STATE (radii or positions unset), ODHS_E_NOMEM, ODHS_E_IO.
 * Since 0.2.6.
 */
ODHS_API int odhs_lammps_data_write(const odhs_system *sys, const char *path);

/**
 * Read a LAMMPS data file (atom_style sphere; see above) into a new system
 * (*out). On error *out is NULL and, if errbuf is not NULL, a message (naming
 * the line for malformed input) is copied into errbuf (errlen bytes, always
 * NUL-terminated; "" on success). Errors: ODHS_E_NULL, ODHS_E_IO,
 * ODHS_E_FORMAT, ODHS_E_NOMEM and the validation errors of
 * odhs_system_set_configuration (ODHS_E_OVERLAP, ODHS_E_BOX, ...).
 * Since 0.2.6.
 */
ODHS_API int odhs_lammps_data_read(const char *path, odhs_system **out, char *errbuf, size_t errlen);

/** As odhs_lammps_data_read, from a memory buffer of len bytes (need not be
 *  NUL-ended). Since 0.2.6. */
ODHS_API int odhs_lammps_data_parse(const char *buf, size_t len, odhs_system **out, char *errbuf,
                                    size_t errlen);

#ifdef __cplusplus
}
#endif
#endif /* ODHS_LAMMPS_H */
