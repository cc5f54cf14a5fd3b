/*
 * boot_ident.c - the identity record that the application hands over to
 * the bootloader and the bootloader keeps in flash (boot.h); linked into
 * both.
 */
#include "boot.h"

/* Where the hand-over block lies (each board's link scripts). */
extern boot_ident_t _boot_handover;

bool boot_ident_valid(const boot_ident_t *b, uint32_t magic)
{
    return b->magic == magic && b->crc == co_crc32(0, (const uint8_t *)b, BOOT_IDENT_CRC_LEN) &&
           b->node_id >= 1u && b->node_id <= CO_NODE_ID_MAX && b->kbps != 0u;
}

void boot_ident_seal(boot_ident_t *b, uint32_t magic)
{
    b->magic = magic;
    b->crc = co_crc32(0, (const uint8_t *)b, BOOT_IDENT_CRC_LEN);
}

void boot_handover(const boot_ident_t *b)
{
    boot_ident_t h = *b; /* b may lie where the block goes */
    boot_ident_seal(&h, BOOT_HANDOVER_MAGIC);
    _boot_handover = h;
    board_reset();
}
