/*
 * aeabi_div.h - compact integer division for cores without a divide
 * instruction (Cortex-M0): the ARM run-time ABI helpers the compiler calls
 * for '/' and '%' on 32-bit integers (RTABI section 4.3.1). Linked into the
 * Cortex-M0 images and the qemu unit tests; unit-tested on the host too
 * (tests/unit/test_div.c), where the compiler never calls them itself.
 *
 * Division by zero returns quotient 0 and remainder 0 (the ABI would call
 * __aeabi_idiv0, which may return anything; the stack never divides by
 * zero). INT32_MIN / -1 wraps to INT32_MIN, remainder 0.
 */
#ifndef AEABI_DIV_H
#define AEABI_DIV_H

#include <stdint.h>

uint32_t __aeabi_uidiv(uint32_t n, uint32_t d);
/* Quotient in the low word (r0), remainder in the high word (r1). */
uint64_t __aeabi_uidivmod(uint32_t n, uint32_t d);
int32_t __aeabi_idiv(int32_t n, int32_t d);
uint64_t __aeabi_idivmod(int32_t n, int32_t d);

#endif /* AEABI_DIV_H */
