/*
 * uid_serial.h - a unit's serial number (0x1018 sub 4, the last part of its
 * LSS address, CiA 305) from its chip's unique ID, for the MCU boards'
 * board_serial() (board.h). Static inline: one use per image.
 */
#ifndef UID_SERIAL_H
#define UID_SERIAL_H

#include "co_common.h"
#include "product.h"

/* Bit 0 of a serial number is the node of the device (below). */
_Static_assert(PRODUCT_MAX_NODES <= 2u, "one bit of the serial number names the node");

/*
 * The serial number of node `node` (0 or 1) of a device whose chip's
 * unique ID is the n words w[] (read by the caller): FNV-1a over the ID's
 * bytes, folded to 31 bits (0 taken as 1), shifted left by one, the node
 * in bit 0. So it is never 0, the two nodes of one device (the redundant
 * GSH-A) always differ, and two chips differ but for a 31-bit collision.
 * Cannot fail; O(n).
 */
static inline uint32_t board_uid_serial(const uint32_t *w, unsigned n, unsigned node)
{
    uint32_t h = 2166136261u;
    for (unsigned i = 0; i < n; i++) {
        for (unsigned b = 0; b < 32u; b += 8u) {
            h = (h ^ ((w[i] >> b) & 0xFFu)) * 16777619u;
        }
    }
    h ^= h >> 31; /* the bit the shift below drops, folded in */
    h &= 0x7FFFFFFFu;
    h += (uint32_t)(h == 0u); /* 0 taken as 1 */
    return (h << 1) | (node & 1u);
}

#endif /* UID_SERIAL_H */
