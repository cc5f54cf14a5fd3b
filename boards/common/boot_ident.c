/*
 * boot_ident.c - the application's side of the hand-over to the
 * bootloader (boot.h): linked into every product image, and into the
 * bootloader, which reads the block.
 */
#include "boot.h"

bool boot_handover_valid(const boot_handover_t *h)
{
    return h->magic == BOOT_HANDOVER_MAGIC && h->node_id >= 1u && h->node_id <= CO_NODE_ID_MAX &&
           h->kbps != 0u;
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

void boot_handover_poll(co_node_t *node)
{
    if (!handover_due) {
        return;
    }
    boot_handover_block = (boot_handover_t){
        .magic = BOOT_HANDOVER_MAGIC, .node_id = co_node_id(node), .kbps = co_node_can_kbps(node)};
    board_reset();
}
