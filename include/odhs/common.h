/*
 * libodhs - event-driven overdamped frictionless hard spheres.
 * common.h: export macro, version, status codes, memory helpers.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#ifndef ODHS_COMMON_H
#define ODHS_COMMON_H

#include <stddef.h>
#include <stdint.h>

#ifdef __cplusplus
extern "C" {
#endif

/* ODHS_API marks every exported symbol; the shared object is built with
 * -fvisibility=hidden so nothing else leaks out. */
#if defined(_WIN32) && defined(ODHS_BUILDING_DLL)
#define ODHS_API __declspec(dllexport)
#elif defined(__GNUC__) && __GNUC__ >= 4
#define ODHS_API __attribute__((visibility("default")))
#else
#define ODHS_API
#endif

/* ---- version ------------------------------------------------------------ */
#define ODHS_VERSION_MAJOR 0
#define ODHS_VERSION_MINOR 2
#define ODHS_VERSION_PATCH 24
/* MAJOR*10000 + MINOR*100 + PATCH */
#define ODHS_VERSION_NUMBER \
    (ODHS_VERSION_MAJOR * 10000 + ODHS_VERSION_MINOR * 100 + ODHS_VERSION_PATCH)
#define ODHS_STRINGIFY_(x) #x
#define ODHS_STRINGIFY(x) ODHS_STRINGIFY_(x)
#define ODHS_VERSION_STRING                                                   \
    ODHS_STRINGIFY(ODHS_VERSION_MAJOR) "." ODHS_STRINGIFY(ODHS_VERSION_MINOR) \
        "." ODHS_STRINGIFY(ODHS_VERSION_PATCH)

/** Run-time version of the linked library, "MAJOR.MINOR.PATCH". */
ODHS_API const char *odhs_version_string(void);
/** Run-time version number of the linked library (see ODHS_VERSION_NUMBER). */
ODHS_API int odhs_version_number(void);

/* ---- status codes --------------------------------------------------------
 * Every call that can fail returns one of these. 0 is success, negative
 * values are errors (the handle is left as it was before the call), positive
 * values are warnings or informative stops (the call did its work).
 * The numeric values are pinned forever: new codes are only ever appended. */
enum {
    ODHS_OK = 0,

    /* warnings / informative stops (> 0) */
    ODHS_STOPPED = 1,          /* a user callback asked to stop the run      */
    ODHS_POTENTIALLY_JAMMED = 2, /* constrained subset isostatic and its
                                  self-stress f0 could not be used (fixed
                                  pressure, or f0 not computable, or since
                                  0.2.3 not positive on the polished
                                  geometry: see jamming.h); the run
                                  stopped                                    */
    ODHS_JAMMED = 3,           /* jammed: the constrained subset is isostatic
                                  and its self-stress f0 is positive; the
                                  run stopped (Sect. IV D)                   */
    ODHS_STEP_LIMIT = 4,       /* a run call took the number of steps set
                                  with odhs_stepper_set_run_limits and
                                  returned before its target (since 0.2.7;
                                  the state is valid: call again to go on)   */

    /* errors (< 0) */
    ODHS_E_NULL = -1,          /* a required pointer argument was NULL       */
    ODHS_E_INVALID = -2,       /* an argument has an invalid value           */
    ODHS_E_NOMEM = -3,         /* memory allocation failed                   */
    ODHS_E_DIM = -4,           /* dimension not 2 or 3, or inconsistent      */
    ODHS_E_RANGE = -5,         /* an index is out of range                   */
    ODHS_E_NONFINITE = -6,     /* a NaN or infinite number was given/found   */
    ODHS_E_OVERLAP = -7,       /* two particles overlap                      */
    ODHS_E_BOX = -8,           /* box edge too small (< 2 largest diameters) */
    ODHS_E_EMPTY = -9,         /* empty system (N = 0) or nothing to do      */
    ODHS_E_IO = -10,           /* a file could not be opened/read/written    */
    ODHS_E_FORMAT = -11,       /* a file is malformed                        */
    ODHS_E_STATE = -12,        /* call made in the wrong order / state       */
    ODHS_E_SINGULAR = -13,     /* singular or indefinite matrix              */
    ODHS_E_NOCONV = -14,       /* an iterative solver did not converge       */
    ODHS_E_NOTINSTALLED = -15, /* feature/backend not built into this library*/
    ODHS_E_REWIRE = -16,       /* rewiring did not reach a valid network     */
    ODHS_E_CALLBACK = -17,     /* a user callback failed or returned NaN     */
    ODHS_E_UNSUPPORTED = -18,  /* combination of settings not supported      */
    ODHS_E_TOODENSE = -19,     /* random placement could not reach the
                                  requested packing fraction                 */
    ODHS_E_INTERNAL = -20,     /* internal inconsistency (a bug: report it)  */
    ODHS_E_STALLED = -21       /* no progress: a run's target (time, strain,
                                  packing fraction, events) did not advance
                                  over the stall limit of steps, or no event
                                  can ever happen (since 0.2.7)              */
};

/** Static English description of a status code (never NULL). */
ODHS_API const char *odhs_strerror(int status);

/**
 * The message of the last failed call in the calling thread that had no
 * handle to keep it: the create functions (odhs_system_create,
 * odhs_system_clone, odhs_driver_create, odhs_network_create,
 * odhs_solver_create, odhs_solver_create_by_name, odhs_stepper_create,
 * odhs_softcore_create). Each of them sets it on failure and clears it ("")
 * on success; other calls leave it alone (they report through their
 * handle's errmsg, or the readers through their errbuf argument). The text lives in
 * thread-local storage: separate threads never see each other's messages,
 * and the pointer stays valid until the thread's next such call. Never NULL.
 * Since 0.2.7.
 */
ODHS_API const char *odhs_last_error(void);

/** Free memory that the library allocated and handed to the caller
 *  (documented per function). NULL is a no-op. */
ODHS_API void odhs_free(void *p);

#ifdef __cplusplus
}
#endif
#endif /* ODHS_COMMON_H */
