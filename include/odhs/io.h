/*
 * libodhs - io.h: configuration files (extended XYZ).
 *
 * Format written (one frame):
 *   line 1: N
 *   line 2: Lattice="ax ay az bx by bz cx cy cz" Properties=species:S:1:pos:R:3:radius:R:1
 *           pbc="T T T" dim=D strain=GAMMA
 *   then N lines: species x y z radius
 * with a = (Lx,0,0), b = (gamma*Ly, Ly, 0), c = (0,0,Lz) the sheared cell. In 2D
 * z = 0, c = (0,0,1) and pbc="T T F". Numbers are written with 17 significant
 * digits, so a write/read round trip is bit-exact. OVITO reads these files
 * directly; ASE reads them only when every species label is a chemical
 * symbol (it takes the species column for elements): the trajectories of
 * traj.h name the label column type instead, and ASE reads them as they are.
 *
 * The reader accepts any extended XYZ frame whose Properties contain species
 * (S:1; or type S:1 when there is no species column), pos (R:3) and radius
 * (R:1) columns in any order, with other columns
 * ignored; keys may appear in any order; dim defaults to 3, or 2 when pbc's
 * third flag is F; strain defaults to bx/Ly. Orthogonal-cell lattices only
 * (apart from the x-y shear). Malformed input gives ODHS_E_FORMAT with a message
 * naming the line, and never a half-filled system. Overlaps up to 1e-4 of the
 * contact distance are accepted on reading (the drift of contact gaps between
 * two drift corrections, so that any state the stepper reaches reads back);
 * the system setters accept 1e-10.
 */
#ifndef ODHS_IO_H
#define ODHS_IO_H

#include "odhs/system.h"

#ifdef __cplusplus
extern "C" {
#endif

/**
 * Read an extended XYZ file into a new system (*out). On error *out is NULL and,
 * if errbuf is not NULL, a message (naming the line) is copied into errbuf.
 * Errors: ODHS_E_NULL, ODHS_E_IO, ODHS_E_FORMAT, ODHS_E_NOMEM and the validation
 * errors of odhs_system_set_configuration (ODHS_E_OVERLAP, ODHS_E_BOX, ...).
 */
ODHS_API int odhs_xyz_read(const char *path, odhs_system **out, char *errbuf, size_t errlen);

/** As odhs_xyz_read, from a memory buffer of len bytes (need not be NUL-ended). */
ODHS_API int odhs_xyz_parse(const char *buf, size_t len, odhs_system **out, char *errbuf,
                            size_t errlen);

/**
 * Read frame `frame` (0 = the first; negative counts from the end, -1 = the
 * last) of a multi-frame extended XYZ file such as a trajectory of
 * odhs_traj (traj.h), whose label column is named type instead of species.
 * *nframes (may be NULL) receives the number of frames in the file. Frames
 * follow each other, each a count line and N + 1 more lines; blank lines
 * between frames are skipped. Errors: as odhs_xyz_read (messages name the
 * frame and its first line), and ODHS_E_RANGE when the file has no such
 * frame. Since 0.2.6.
 */
ODHS_API int odhs_xyz_read_frame(const char *path, long frame, odhs_system **out, long *nframes,
                                 char *errbuf, size_t errlen);

/**
 * Write the system to path in the format above (the file is written to a
 * temporary name and renamed, so a failed write leaves any old file intact).
 * Errors: ODHS_E_NULL, ODHS_E_STATE (radii/positions unset), ODHS_E_IO.
 */
ODHS_API int odhs_xyz_write(const odhs_system *sys, const char *path);

struct odhs_network; /* see network.h */

/**
 * Draw the configuration as an SVG picture in the style of the paper's figures:
 * discs coloured by size (below/above the median radius; 3D systems are
 * projected on the x-y plane), the periodic (sheared) cell, and, when net is
 * not NULL, every contact as a line from centre to centre whose width is
 * proportional to its force, and every permanent contact (bond) as a thin
 * dark-blue line of fixed width.
 * mark (N flags, may be NULL) highlights particles: 1 = grey with a red ring
 * (rattlers), 2 = dark red (e.g. a clogging arch). The file is written to a
 * temporary name and renamed. Errors: ODHS_E_NULL, ODHS_E_STATE, ODHS_E_DIM,
 * ODHS_E_IO.
 */
ODHS_API int odhs_svg_write(const odhs_system *sys, const struct odhs_network *net,
                            const unsigned char *mark, const char *path);

/**
 * Write the contacts of a network to a text file: comment lines starting with
 * '#' (N, dim, Nc and the column names), then one line per contact
 * "i j s0 s1 [s2] force gap" with the lattice image shift s such that the
 * contact vector is R_ij = x_j - x_i + s0 a + s1 b + s2 c (system.h), the
 * force and the gap, numbers with 17 significant digits (a contact with wall w
 * is "i N+w 0 0 [0] force gap"). Written atomically
 * (temporary file, then rename). Errors: ODHS_E_NULL, ODHS_E_DIM (system and
 * network differ), ODHS_E_IO. (Declared in odhs/jamming.h before 0.2.4, which still includes
 * this header.)
 */
ODHS_API int odhs_contacts_write(const struct odhs_network *net, const odhs_system *sys, const char *path);

/**
 * Write the contacts of a network as CSV that numpy.genfromtxt(names=True)
 * and pandas.read_csv read as they are: the header row "i,j,kind,force,gap",
 * then one row per contact with the particles i < j (user order; a contact
 * with wall w has j = N + w), its kind (ODHS_CONTACT_TEMPORARY 0, PERMANENT 1,
 * WALL 2), the force and the gap (17 significant digits). No comment lines.
 * Written atomically. Errors: as odhs_contacts_write. Since 0.2.6.
 */
ODHS_API int odhs_contacts_write_csv(const struct odhs_network *net, const odhs_system *sys,
                                     const char *path);

#ifdef __cplusplus
}
#endif
#endif /* ODHS_IO_H */
