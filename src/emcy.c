/*
 * emcy.c - EMCY producer. See co_emcy.h.
 */
#include "co_emcy.h"

#include <string.h>

#include "co_node.h"

bool co_emcy_send(co_node_t *node, uint16_t code, uint8_t er, const uint8_t msef[5])
{
    uint8_t st = node->nmt.state;
    if (st != CO_NMT_PREOP && st != CO_NMT_OPERATIONAL) {
        return false;
    }
    uint32_t cob = 0x80u + node->node_id;
    const co_od_entry_t *e = co_node_entry(node, 0x1014, 0);
    if (e != NULL) {
        (void)co_od_get(node, e, &cob);
    }
    if ((cob & 0x80000000u) != 0u) {
        return false; /* EMCY disabled */
    }
    co_frame_t f = {.id = (uint16_t)(cob & 0x7FFu), .dlc = 8};
    co_put_u16(&f.data[0], code);
    f.data[2] = er;
    if (msef != NULL) {
        memcpy(&f.data[3], msef, 5);
    }
    return co_node_send(node, &f);
}
