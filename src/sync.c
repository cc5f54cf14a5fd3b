/*
 * sync.c - SYNC consumer. See co_sync.h.
 */
#include "co_sync.h"

#include "co_node.h"
#include "co_od.h"

void co_sync_reconfig(co_node_t *node)
{
    uint32_t cob = 0x80u;
    const co_od_entry_t *e = co_node_entry(node, 0x1005, 0);
    if (e != NULL) {
        (void)co_od_get(node, e, &cob);
    }
    node->sync.cob_id = (uint16_t)(cob & 0x7FFu);
}

co_res_t co_sync_write_cobid(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    /* 11-bit IDs only; bit 30 (this node generates SYNC) refused: no
     * product produces SYNC (0x06090030, value out of range); bit 31 means nothing
     * to a consumer; never a restricted CAN-ID (co_node_receive relies on
     * it for SDO frames). */
    co_res_t c = co_cobid_check(value, false, false);
    if (c != CO_OK) {
        return c;
    }
    co_res_t r = co_od_store(node, e, value);
    if (r == CO_OK) {
        co_sync_reconfig(node);
    }
    return r;
}

bool co_sync_receive(co_node_t *node, const co_frame_t *f)
{
    if (f->id != node->sync.cob_id || f->rtr) {
        return false;
    }
    /* CiA 301: a SYNC has no data, or a one-byte counter. */
    if (f->dlc <= 1u && node->nmt.state == CO_NMT_OPERATIONAL) {
        co_tpdo_sync(node);
    }
    return true;
}
