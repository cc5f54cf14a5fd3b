/*
 * nmt.c - NMT slave. See co_nmt.h.
 */
#include "co_nmt.h"

#include "co_node.h"

enum {
    NMT_START = 0x01,
    NMT_STOP = 0x02,
    NMT_PREOP = 0x80,
    NMT_RESET_NODE = 0x81,
    NMT_RESET_COMM = 0x82,
};

void co_nmt_enter(co_node_t *node, co_nmt_state_t state)
{
    uint8_t old = node->nmt.state;
    if (old == (uint8_t)state) {
        return;
    }
    node->nmt.state = (uint8_t)state;
    if (state == CO_NMT_OPERATIONAL) {
        co_tpdo_start(node);
    }
    if (co_cfg(node)->ops != NULL && co_cfg(node)->ops->state != NULL) {
        co_cfg(node)->ops->state(node, (co_nmt_state_t)old);
    }
}

bool co_nmt_receive(co_node_t *node, const co_frame_t *f)
{
    if (f->id != 0x000u) {
        return false;
    }
    if (f->rtr || f->dlc != 2u || (f->data[1] != 0u && f->data[1] != node->node_id)) {
        return true;
    }
    switch (f->data[0]) {
    case NMT_START:
        co_nmt_enter(node, CO_NMT_OPERATIONAL);
        break;
    case NMT_STOP:
        co_nmt_enter(node, CO_NMT_STOPPED);
        break;
    case NMT_PREOP:
        co_nmt_enter(node, CO_NMT_PREOP);
        break;
    case NMT_RESET_NODE:
        co_node_reset(node, CO_RESET_NODE);
        break;
    case NMT_RESET_COMM:
        co_node_reset(node, CO_RESET_COMM);
        break;
    default:
        break; /* unknown command: ignored (CiA 301) */
    }
    return true;
}
