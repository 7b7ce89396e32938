/*
 * libodhs - the single Check test runner.
 *
 * Every tests/check_<module>.c defines `Suite *make_<module>_suite(void);`.
 * The Makefile writes build/tests/suites.inc with one line
 * `ODHS_SUITE(make_<module>_suite)` per such file; it is included twice
 * below, once to declare the functions and once to add the suites.
 *
 * Environment (read by Check itself): CK_RUN_SUITE, CK_RUN_CASE (run one
 * suite / test case by name), CK_FORK=no (no fork, e.g. under ASan or gdb),
 * CK_DEFAULT_TIMEOUT, CK_VERBOSITY (silent|minimal|normal|verbose; default
 * normal), CK_TAP_LOG_FILE_NAME, CK_XML_LOG_FILE_NAME.
 *
 * Exit status: 0 when every test passed, 1 otherwise.
 *
 * Copyright (C) 2026 the libodhs authors. LGPL-2.1-or-later, see LICENSE.
 */
#include <check.h>
#include <stdio.h>
#include <stdlib.h>

/* 1. prototypes */
#define ODHS_SUITE(fn) Suite *fn(void);
#include "suites.inc"
#undef ODHS_SUITE

int main(void)
{
    SRunner *sr = srunner_create(NULL);
    int n_suites = 0;

    /* 2. registration, in the (sorted) order of the generated list */
#define ODHS_SUITE(fn) \
    do { srunner_add_suite(sr, fn()); n_suites++; } while (0);
#include "suites.inc"
#undef ODHS_SUITE

    if (n_suites == 0)
        fprintf(stderr, "check_main: no test suites (no tests/check_<module>.c)\n");

    /* CK_ENV: the verbosity comes from CK_VERBOSITY, CK_NORMAL if unset. */
    srunner_run_all(sr, CK_ENV);

    int n_run = srunner_ntests_run(sr);
    int n_failed = srunner_ntests_failed(sr);
    srunner_free(sr);

    /* A mistyped CK_RUN_SUITE/CK_RUN_CASE silently runs nothing: say so. */
    if (n_run == 0 && n_suites > 0 &&
        (getenv("CK_RUN_SUITE") != NULL || getenv("CK_RUN_CASE") != NULL)) {
        fprintf(stderr, "check_main: CK_RUN_SUITE/CK_RUN_CASE matched no test\n");
        return EXIT_FAILURE;
    }
    return n_failed == 0 ? EXIT_SUCCESS : EXIT_FAILURE;
}
