/*
 * libodhs - traj.h: trajectories, one frame per call, in the formats that
 * OVITO, ASE and LAMMPS users read (since 0.2.6).
 *
 * A trajectory is a file opened once and appended to: odhs_traj_write adds
 * the state of a system (and of the stepper moving it) as one frame. Writing
 * a frame costs O(N), reads the state only, and never changes a trajectory.
 * Formats (odhs_traj_format_for picks one from the file name):
 *
 * ODHS_TRAJ_XYZ, multi-frame extended XYZ (.xyz, .extxyz): per frame
 *   line 1: N
 *   line 2: Lattice="Lx 0 0 bx Ly 0 0 0 Lz" Properties=type:S:1:pos:R:3:radius:R:1
 *           [:velo:R:3:nonaffine_velo:R:3:force_ext:R:3] pbc="T T T" dim=D
 *           strain=GAMMA frame=K phi=PHI [time=T shear_strain=G pressure=P
 *           shear_stress=S kappa=KAPPA z=Z]
 *   then N lines: label x y z radius [vx vy vz ux uy uz Fx Fy Fz]
 *   The lattice and strain (the cell's shear, bx = strain Ly) are those of
 *   odhs_xyz_write; shear_strain is the stepper's accumulated strain. With a
 *   stepper the frame has the velocities V (lab frame), the non-affine
 *   velocities U = V - V_aff and the external forces (odhs_stepper_velocities,
 *   _nonaffine_velocities, _external_forces), and the keys in brackets (the
 *   observables once the stepper has a state, odhs_stepper_reset). The label
 *   column is named type, not species: ASE reads species as chemical
 *   elements, and reads these files as they are (ase.io.read(path, ":"); the
 *   columns land in atoms.arrays, the keys in atoms.info). OVITO reads them,
 *   and so does odhs_xyz_read_frame (io.h). 2D: z = 0, pbc="T T F".
 *
 * ODHS_TRAJ_LAMMPS_DUMP, a LAMMPS custom dump (.dump, .lammpstrj), as
 *   `dump custom ... id type radius x y z vx vy vz` with `dump_modify time
 *   yes` writes it: ITEM: TIME, ITEM: TIMESTEP (the stepper's step count, or
 *   the frame number without a stepper), ITEM: NUMBER OF ATOMS, ITEM: BOX
 *   BOUNDS xy xz yz pp pp pp (a triclinic cell whose tilt xy is strain*Ly
 *   reduced by multiples of Lx into [-Lx/2, Lx/2], as LAMMPS keeps it), then
 *   ITEM: ATOMS id type radius x y z [vx vy vz ux uy uz fx fy fz]. Atom ids
 *   are 1 + the particle index; types number the species labels 1, 2, ... in
 *   order of first appearance (as odhs_lammps_data_write numbers them); x is
 *   shifted by a multiple of Lx into the tilted cell. 2D: z = 0, z bounds
 *   -0.5 0.5.
 *
 * ODHS_TRAJ_LAMMPS_LOCAL, the contact network of each frame as a LAMMPS
 *   "dump local" file, which OVITO loads as bonds next to a dump or XYZ
 *   trajectory (map batom1 and batom2 to the bond topology): ITEM: TIME,
 *   ITEM: TIMESTEP, ITEM: NUMBER OF ENTRIES, ITEM: BOX BOUNDS (as above),
 *   ITEM: ENTRIES index batom1 batom2 kind force gap, one row per contact
 *   between two particles (atom ids 1 + index; kind ODHS_CONTACT_*). Contacts
 *   with walls are not bonds and are left out (odhs_contacts_write_csv lists
 *   them). Needs the stepper.
 *
 * Every number is written with 17 significant digits, so frames read back
 * bit for bit. Particle indices are the user's, in every format.
 */
#ifndef ODHS_TRAJ_H
#define ODHS_TRAJ_H

#include <stdint.h>

#include "odhs/stepper.h"
#include "odhs/system.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Trajectory formats (pinned values). */
enum odhs_traj_format {
    ODHS_TRAJ_XYZ = 0,          /* multi-frame extended XYZ                 */
    ODHS_TRAJ_LAMMPS_DUMP = 1,  /* LAMMPS custom dump                       */
    ODHS_TRAJ_LAMMPS_LOCAL = 2  /* contact networks as a LAMMPS dump local  */
};

typedef struct odhs_traj odhs_traj;

/**
 * The format for a file name: ODHS_TRAJ_LAMMPS_DUMP for names ending in
 * .dump or .lammpstrj, ODHS_TRAJ_XYZ for .xyz and .extxyz (any case).
 * Errors: ODHS_E_NULL, ODHS_E_INVALID (another ending; *format unchanged).
 */
ODHS_API int odhs_traj_format_for(const char *path, int *format);

/**
 * Create (or truncate) the file at path and a trajectory handle writing
 * frames of the given format to it. On error *out is NULL and, if errbuf is
 * not NULL, a message is copied into it. Errors: ODHS_E_NULL, ODHS_E_INVALID
 * (unknown format), ODHS_E_IO, ODHS_E_NOMEM.
 */
ODHS_API int odhs_traj_open(const char *path, int format, odhs_traj **out, char *errbuf, size_t errlen);

/**
 * Append one frame: the system sys and, when st is not NULL, the stepper
 * moving it (st must have been created on sys). The frame is formatted in
 * memory first and written in one piece: on any error nothing is added to
 * the file and the handle is as it was. Errors: ODHS_E_NULL (tr, sys; st for
 * ODHS_TRAJ_LAMMPS_LOCAL), ODHS_E_INVALID (st moves another system),
 * ODHS_E_STATE (radii or positions unset), ODHS_E_NOMEM, ODHS_E_IO, with the
 * message in odhs_traj_errmsg.
 */
ODHS_API int odhs_traj_write(odhs_traj *tr, const odhs_system *sys, const odhs_stepper *st);

/** The number of frames written so far. Errors: ODHS_E_NULL. */
ODHS_API int odhs_traj_frames(const odhs_traj *tr, uint64_t *count);

/** The message of the handle's last error ("" if none); "" for NULL. */
ODHS_API const char *odhs_traj_errmsg(const odhs_traj *tr);

/**
 * Flush and close the file and free the handle (NULL: nothing, ODHS_OK).
 * Returns ODHS_E_IO when the last data could not be written (the handle is
 * freed all the same).
 */
ODHS_API int odhs_traj_close(odhs_traj *tr);

#ifdef __cplusplus
}
#endif
#endif /* ODHS_TRAJ_H */
