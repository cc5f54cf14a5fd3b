/*
 * test_div.c - the Cortex-M0 division helpers (boards/common/aeabi_div.c).
 * On the host they are plain functions compared with the compiler's own
 * division; under qemu they are also what every '/' of every test calls,
 * so the checks there use the defining identities instead (n = q * d + r,
 * |r| < |d|, r has the sign of n), which need no division.
 */
#include <stdint.h>

#include "aeabi_div.h"
#include "harness.h"

static uint32_t rng = 0x12345678u;

static uint32_t next(void) /* xorshift32: the same sequence everywhere */
{
    rng ^= rng << 13;
    rng ^= rng >> 17;
    rng ^= rng << 5;
    return rng;
}

/* A divisor or dividend of every magnitude, not only huge ones. */
static uint32_t any_width(void)
{
    return next() >> (next() % 32u);
}

static bool unsigned_ok(uint32_t n, uint32_t d)
{
    uint32_t q = __aeabi_uidiv(n, d);
    uint64_t qr = __aeabi_uidivmod(n, d);
    uint32_t q2 = (uint32_t)qr, r = (uint32_t)(qr >> 32);
    bool ok = q == q2 && r < d && (uint64_t)q * d + r == n;
#ifndef HARNESS_BARE
    ok = ok && q == n / d && r == n % d;
#endif
    if (!ok) {
        fprintf(stderr, "uidiv %lu / %lu: q %lu, q2 %lu, r %lu\n", (unsigned long)n,
                (unsigned long)d, (unsigned long)q, (unsigned long)q2, (unsigned long)r);
    }
    return ok;
}

static uint32_t mag(int32_t v)
{
    return v < 0 ? 0u - (uint32_t)v : (uint32_t)v;
}

static bool signed_ok(int32_t n, int32_t d)
{
    int32_t q = __aeabi_idiv(n, d);
    uint64_t qr = __aeabi_idivmod(n, d);
    int32_t q2 = (int32_t)(uint32_t)qr, r = (int32_t)(uint32_t)(qr >> 32);
    bool ok = q == q2 && mag(r) < mag(d) && (r == 0 || (r < 0) == (n < 0)) &&
              (int64_t)q * d + r == n;
#ifndef HARNESS_BARE
    ok = ok && q == n / d && r == n % d;
#endif
    if (!ok) {
        fprintf(stderr, "idiv %ld / %ld: q %ld, q2 %ld, r %ld\n", (long)n, (long)d, (long)q,
                (long)q2, (long)r);
    }
    return ok;
}

static void test_unsigned_edges(void)
{
    static const uint32_t v[] = {1u,          2u,          3u,          7u,
                                 10u,         1000u,       0x7FFFFFFFu, 0x80000000u,
                                 0x80000001u, 0xFFFFFFFEu, 0xFFFFFFFFu};
    for (unsigned i = 0; i < sizeof(v) / sizeof(v[0]); i++) {
        CHECK(unsigned_ok(0, v[i]));
        for (unsigned j = 0; j < sizeof(v) / sizeof(v[0]); j++) {
            CHECK(unsigned_ok(v[i], v[j]));
        }
    }
    CHECK_EQ(__aeabi_uidiv(0xFFFFFFFFu, 1u), 0xFFFFFFFFu);
    CHECK_EQ(__aeabi_uidiv(100u, 7u), 14);
    CHECK_EQ((uint32_t)(__aeabi_uidivmod(100u, 7u) >> 32), 2);
}

static void test_signed_edges(void)
{
    static const int32_t v[] = {
        1, -1, 2, -2, 3, -3, 7, -7, 1000, -1000, INT32_MAX, INT32_MIN + 1, INT32_MIN};
    for (unsigned i = 0; i < sizeof(v) / sizeof(v[0]); i++) {
        CHECK(signed_ok(0, v[i]));
        for (unsigned j = 0; j < sizeof(v) / sizeof(v[0]); j++) {
            if (v[i] == INT32_MIN && v[j] == -1) {
                continue; /* overflows in C; checked below */
            }
            CHECK(signed_ok(v[i], v[j]));
        }
    }
    /* Truncation toward zero, remainder with the dividend's sign (C99). */
    CHECK_EQ(__aeabi_idiv(-7, 2), -3);
    CHECK_EQ((int32_t)(uint32_t)(__aeabi_idivmod(-7, 2) >> 32), -1);
    CHECK_EQ(__aeabi_idiv(7, -2), -3);
    CHECK_EQ((int32_t)(uint32_t)(__aeabi_idivmod(7, -2) >> 32), 1);
    CHECK_EQ(__aeabi_idiv(INT32_MIN, -1), INT32_MIN);
    CHECK_EQ(__aeabi_idivmod(INT32_MIN, -1) >> 32, 0);
}

static void test_by_zero(void)
{
    /* Documented in aeabi_div.h: quotient and remainder 0. */
    CHECK_EQ(__aeabi_uidiv(12345u, 0), 0);
    CHECK_EQ(__aeabi_uidivmod(12345u, 0), 0);
    CHECK_EQ(__aeabi_idiv(-12345, 0), 0);
    CHECK_EQ(__aeabi_idivmod(-12345, 0), 0);
}

static void test_random(void)
{
    unsigned bad = 0;
    for (unsigned i = 0; i < 20000u; i++) {
        uint32_t n = any_width(), d = any_width();
        if (d == 0u) {
            d = 1u;
        }
        bad += !unsigned_ok(n, d);
        /* Two's complement negation of the bits, INT32_MIN included. */
        int32_t sn = (int32_t)(next() & 1u ? n : 0u - n);
        int32_t sd = (int32_t)(next() & 1u ? d : 0u - d);
        if (sn == INT32_MIN && sd == -1) {
            continue;
        }
        bad += !signed_ok(sn, sd);
    }
    CHECK_EQ(bad, 0);
}

int main(void)
{
    RUN(test_unsigned_edges);
    RUN(test_signed_edges);
    RUN(test_by_zero);
    RUN(test_random);
    return h_finish();
}
