/*
 * harness_checks.c - the check counters of harness.h, apart from the fake
 * port so that tests of a real port can use them too.
 */
#include "harness.h"

int h_failures;
int h_checks;
int h_tests;
int h_failed_tests;

int h_finish(void)
{
    printf("%d checks\n", h_checks);
    printf("%d passed, %d failed\n", h_tests - h_failed_tests, h_failed_tests);
    return h_failures == 0 ? 0 : 1;
}
