/*
 * boot_ident.c - the identity record that the application hands over to
 * the bootloader and the bootloader keeps in flash (boot.h); linked into
 * both.
 */
#include "boot.h"

#include <string.h>

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

/* The application side of program download (co_progdl.h): a stop
 * (1F51h:1 = 0) asks for the hand-over, which boot_handover_poll makes
 * once the answer has gone out. Board state, not the stack's. */
static bool handover_due;

void co_port_prog_handover(void *port)
{
    (void)port;
    handover_due = true;
}

void boot_handover_poll(co_node_t *node, const product_t *p)
{
    if (!handover_due) {
        return;
    }
    boot_ident_t b;
    memset(&b, 0, sizeof b);
    uint32_t *w = &b.device_type; /* 1000h, then 1018h:1..4 */
    for (uint8_t i = 0; i < 5u; i++) {
        const co_od_entry_t *e = co_node_entry(node, i == 0u ? 0x1000u : 0x1018u, i);
        if (e != NULL) {
            (void)co_od_get(node, e, &w[i]);
        }
    }
    b.node_id = co_node_id(node);
    b.kbps = product_kbps(p, co_node_bitrate(node));
    boot_handover(&b);
}
