/*
 * libodhs - checkpoint.h: save and restore a whole simulation.
 *
 * A checkpoint holds everything a stepper needs to continue exactly as if it
 * had not stopped: the system (positions, radii, species, box, strain), the
 * driver settings (mobility, rates, pressure, fixed forces, gravity,
 * self-propulsion with its random-number state), the stepper's
 * settings and state (time, strain, counters, integrator and adaptive step,
 * the contact network in its order with its forces, velocities, neighbour
 * list and its bookkeeping). Continuing from a checkpoint is bit-identical to
 * the uninterrupted run for the stateless solvers (cg, dense, cholmod, spqr),
 * whose answer depends only on the network and the right-hand side. It is
 * not for "cholmod-pcg" and "auto" (primary cholmod-pcg): cholmod-pcg
 * preconditions with a factor of an older network updated contact by
 * contact and refactorised on a schedule, a history the checkpoint does not
 * hold; the restored solver starts from a fresh factor, its iterates differ
 * at its tolerance (1e-12) and the order of nearly simultaneous events can
 * change after some steps. Choose "cholmod" for bit-identical restarts.
 * Not saved (they are code, not data): force and event callbacks, and the
 * solver itself: set them again on the restored handles. That a force
 * callback was set is saved (section FCB, since 0.2.7): the restored
 * stepper refuses to step (ODHS_E_STATE) until odhs_driver_set_force_callback
 * (or odhs_driver_set_forces) is called on the restored driver.
 *
 * Format: little-endian binary; magic "ODHSCKPT", a format version, then
 * tagged sections, then a 64-bit FNV-1a checksum of all preceding bytes.
 * Version 1: sections SYS, DRV, STP, NET. Version 2 adds optional sections:
 * WAL before NET (hard walls: shape, position, velocity, displacement), and
 * after NET, each at most once, CMP (rest lengths of bonds, rigid-body
 * labels), PROP (self-propulsion: settings, whether its clock runs, the
 * xoshiro256** state, current forces and switch times) and GRAV (gravity
 * field and weights), and since 0.2.2 DRVC (the driver was changed after
 * the forces were solved: the restored stepper re-solves them at its next
 * step, as the original would have), and since 0.2.4 OSC (oscillatory shear:
 * shape, amplitude, period, phase origin), and since 0.2.5 PJAM (a finite
 * jamming pressure, odhs_driver_set_jamming_pressure), and since 0.2.7 FCB (a
 * force callback was set). A checkpoint that needs none of
 * them is still written as version 1, so older releases read it; this library
 * reads both.
 * Writes go to a temporary file in the same directory that is flushed, synced
 * and renamed over the target, so a crash mid-write leaves any previous
 * checkpoint intact. A truncated, corrupted or foreign file gives
 * ODHS_E_FORMAT and no handle.
 */
#ifndef ODHS_CHECKPOINT_H
#define ODHS_CHECKPOINT_H

#include "odhs/stepper.h"

#ifdef __cplusplus
extern "C" {
#endif

/** Current checkpoint format version. */
#define ODHS_CHECKPOINT_VERSION 2

/**
 * Save the stepper's simulation to path (atomically). The stepper must be
 * ready (it has taken a step or been reset) and its contacts at contact
 * distance up to 10% (far beyond any integration drift; the reader refuses
 * more). Errors: ODHS_E_NULL, ODHS_E_STATE, ODHS_E_NOMEM, ODHS_E_IO.
 */
ODHS_API int odhs_checkpoint_write(const odhs_stepper *st, const char *path);

/**
 * Restore a checkpoint: creates a new system, driver and stepper (the stepper
 * borrows the other two and the given solver; destroy the stepper first).
 * On error all outputs are NULL and errbuf (may be NULL) holds a message;
 * on success errbuf holds "" (empty string).
 * Errors: ODHS_E_NULL, ODHS_E_IO, ODHS_E_FORMAT (bad magic, version,
 * checksum, sizes or values: non-finite numbers, positions outside the box,
 * box edges or aspect ratio that odhs_system_set_box refuses,
 * species labels that odhs_system_set_species refuses, contacts farther than
 * 10% from contact distance, duplicated contacts), ODHS_E_NOMEM. A stored
 * neighbour list that misses a close pair is not trusted: it is rebuilt
 * before the next step.
 */
ODHS_API int odhs_checkpoint_read(const char *path, odhs_solver *solver, odhs_system **sys,
                                  odhs_driver **drv, odhs_stepper **st, char *errbuf, size_t errlen);

/** As odhs_checkpoint_read, from a memory buffer of len bytes. */
ODHS_API int odhs_checkpoint_parse(const void *buf, size_t len, odhs_solver *solver, odhs_system **sys,
                                   odhs_driver **drv, odhs_stepper **st, char *errbuf, size_t errlen);

#ifdef __cplusplus
}
#endif
#endif /* ODHS_CHECKPOINT_H */
