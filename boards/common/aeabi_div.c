/*
 * aeabi_div.c - compact integer division for the Cortex-M0, which has no
 * divide instruction (aeabi_div.h). libgcc's versions are unrolled for
 * speed (about 730 bytes); the stack divides a few times per sensor sample,
 * so these shift-and-subtract loops (about 100 bytes, at most 32 steps,
 * a few hundred cycles) are the better trade. Built without LTO: the
 * compiler emits the calls to them after link-time optimisation.
 */
#include "aeabi_div.h"

typedef struct {
    uint32_t quot;
    uint32_t rem;
} udivmod_t;

static udivmod_t udivmod(uint32_t n, uint32_t d)
{
    udivmod_t r = {0, 0};
    if (d == 0u) {
        return r; /* see aeabi_div.h */
    }
    for (int bit = 31; bit >= 0; bit--) {
        r.rem = (r.rem << 1) | ((n >> bit) & 1u);
        if (r.rem >= d) {
            r.rem -= d;
            r.quot |= 1u << bit;
        }
    }
    return r;
}

uint32_t __aeabi_uidiv(uint32_t n, uint32_t d)
{
    return udivmod(n, d).quot;
}

/* Quotient in r0, remainder in r1: a 64-bit return value does exactly that. */
uint64_t __aeabi_uidivmod(uint32_t n, uint32_t d)
{
    udivmod_t r = udivmod(n, d);
    return (uint64_t)r.quot | ((uint64_t)r.rem << 32);
}

static uint32_t magnitude(int32_t v)
{
    return v < 0 ? 0u - (uint32_t)v : (uint32_t)v;
}

int32_t __aeabi_idiv(int32_t n, int32_t d)
{
    uint32_t q = udivmod(magnitude(n), magnitude(d)).quot;
    return (n < 0) != (d < 0) ? (int32_t)(0u - q) : (int32_t)q;
}

uint64_t __aeabi_idivmod(int32_t n, int32_t d)
{
    udivmod_t r = udivmod(magnitude(n), magnitude(d));
    uint32_t q = (n < 0) != (d < 0) ? 0u - r.quot : r.quot;
    uint32_t m = n < 0 ? 0u - r.rem : r.rem; /* the remainder has the dividend's sign */
    return (uint64_t)q | ((uint64_t)m << 32);
}
