/*
 * uid_serial.h - a unit's serial number (0x1018 sub 4, the last part of its
 * LSS address, CiA 305) from its chip's unique ID, for the MCU boards'
 * board_serial() (board.h). Static inline: one use per image.
 */
#ifndef UID_SERIAL_H
#define UID_SERIAL_H

#include "co_common.h"
#include "product.h"

/* Bit 1 of a serial number is the node of the device (below). */
_Static_assert(PRODUCT_MAX_NODES <= 2u, "one bit of the serial number names the node");

/* The chip's unique ID words are folded into one by XOR (h = w0 ^ w1 ^ ...,
 * read by the board): the bits that tell two chips apart (wafer position,
 * wafer and lot numbers) stay, at a few bytes of flash, which the Cortex-M0
 * images count. */
/*
 * The serial number of node `node` (0 or 1) from the folded ID h: its low
 * 30 bits in bits 31..2, the node in bit 1, bit 0 set. So it is never 0,
 * the two nodes of one device (the redundant GSH-A) always differ, and
 * two chips whose folds differ in their low 30 bits differ. Cannot fail.
 */
static inline uint32_t board_uid_serial(uint32_t h, unsigned node)
{
    return (h << 2) | ((node & 1u) << 1) | 1u;
}

#endif /* UID_SERIAL_H */
