/*
 * fuzz_assert.c - a broken stack contract (CO_CHECK, co_common.h) is a
 * finding: abort, so libFuzzer keeps the input that reached it.
 */
#include <stdio.h>
#include <stdlib.h>

#include "co_common.h"

/* Here it never returns (the unit tests' one does: co_common.h's
 * declaration cannot say _Noreturn). */
_Noreturn void co_assert_failed(const char *cond, const char *file, int line)
{
    fprintf(stderr, "%s:%d: stack contract broken: %s\n", file, line, cond);
    abort();
}
