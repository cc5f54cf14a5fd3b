/*
 * fuzz_input.h - reading a fuzz input, shared by the harnesses
 * (fuzz_node.c, fuzz_flash_ee.c): bytes in order, numbers little-endian,
 * zeros past the end, so that every byte string is a valid input.
 */
#ifndef FUZZ_INPUT_H
#define FUZZ_INPUT_H

#include <stddef.h>
#include <stdint.h>

typedef struct fz {
    const uint8_t *p;
    size_t n;
} fz_t;

static inline uint8_t u8(fz_t *in)
{
    if (in->n == 0u) {
        return 0;
    }
    in->n--;
    return *in->p++;
}

static inline uint16_t u16(fz_t *in)
{
    uint16_t lo = u8(in);
    return (uint16_t)(lo | (uint16_t)(u8(in) << 8));
}

static inline uint32_t u32(fz_t *in)
{
    uint32_t lo = u16(in);
    return lo | ((uint32_t)u16(in) << 16);
}

#endif /* FUZZ_INPUT_H */
