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
#ifdef CO_FIXED_CFG
static int h_not_applicable;
#ifdef HARNESS_BARE
typedef void *h_jmp_t[5]; /* no C library: the compiler's own setjmp */
#define H_SETJMP(b) __builtin_setjmp(b)
#define H_LONGJMP(b) __builtin_longjmp((b), 1)
#else
#include <setjmp.h>
typedef jmp_buf h_jmp_t;
#define H_SETJMP(b) setjmp(b)
#define H_LONGJMP(b) longjmp((b), 1)
#endif
static h_jmp_t foreign_jmp;
static const char *foreign; /* product booted of another config, or NULL */
static unsigned own_boots;  /* boots of this config's products in the running test */

void h_own_boot(void)
{
    own_boots++;
}

void h_foreign_boot(const char *id)
{
    foreign = id != NULL ? id : "a product";
    H_LONGJMP(foreign_jmp);
}

/* Separate from h_run, so that its locals need not survive the jump. */
static bool run_until_foreign(void (*fn)(void))
{
    foreign = NULL;
    own_boots = 0;
    if (H_SETJMP(foreign_jmp) == 0) {
        fn();
    }
    return foreign != NULL;
}
#endif

void h_run(void (*fn)(void), const char *name)
{
    int before = h_failures;
    const char *note = "";
#ifdef CO_FIXED_CFG
    if (run_until_foreign(fn)) {
        if (own_boots == 0u && h_failures == before) {
            printf("n/a  %s (boots %s, not of this build's fixed config)\n", name, foreign);
            h_not_applicable++;
            return;
        }
        note = " (up to its boot of a product of another config)";
    }
#else
    fn();
#endif
    printf("%s %s%s\n", h_failures == before ? "ok  " : "FAIL", name, note);
    h_tests++;
    if (h_failures != before) {
        h_failed_tests++;
    }
}

unsigned h_asserts;
static unsigned asserts_expected;

void h_expect_assert(unsigned n)
{
    asserts_expected = n;
}

void co_assert_failed(const char *cond, const char *file, int line)
{
    h_asserts++;
    if (asserts_expected > 0u) {
        asserts_expected--;
        return;
    }
    h_checks++;
    h_failures++;
    fprintf(stderr, "%s:%d: stack contract broken: %s\n", file, line, cond);
}

int h_finish(void)
{
    printf("%d checks, at most %u sent frames unread\n", h_checks, h_tx_high_water);
    printf("%d passed, %d failed", h_tests - h_failed_tests, h_failed_tests);
#ifdef CO_FIXED_CFG
#define H_STR(x) #x
#define H_XSTR(x) H_STR(x)
    printf(", %d not applicable to the fixed config " H_XSTR(CO_FIXED_CFG), h_not_applicable);
    if (h_tests == 0) {
        printf("\nno test booted a product of this config: every product row of a family "
               "needs a test that boots it (the family's TESTS), and its create() must "
               "start the node with the product's own config (p->cfg)\n");
        return 1;
    }
#endif
    printf("\n");
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
