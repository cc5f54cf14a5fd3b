/*
 * harness_checks.c - the check counters of harness.h, apart from the fake
 * port so that tests of a real port can use them too.
 */
#include "harness.h"

#include <stdlib.h>

int h_failures;
int h_checks;
int h_tests;
int h_failed_tests;
unsigned h_tx_high_water;

int h_finish(void)
{
    printf("%d checks, at most %u sent frames unread\n", h_checks, h_tx_high_water);
    printf("%d passed, %d failed\n", h_tests - h_failed_tests, h_failed_tests);
    return h_failures == 0 ? 0 : 1;
}

unsigned h_hex(const char *hex, uint8_t *out, unsigned cap)
{
    unsigned n = 0;
    while (*hex != '\0') {
        if (*hex == ' ') {
            hex++;
            continue;
        }
        char *end;
        unsigned long v = strtoul(hex, &end, 16);
        if (end == hex || n >= cap) {
            fprintf(stderr, "bad hex in test: %s\n", hex);
            abort();
        }
        out[n++] = (uint8_t)v;
        hex = end;
    }
    return n;
}
