/*
 * node_rx.c - the CAN-IDs a node consumes, for a board's receive filter.
 * See co_node_rx_ids() in co_node.h.
 *
 * Decision: the list is computed from the node's live state (the COB-IDs
 * its services cached at their last reconfig, the active node-ID), not
 * kept up to date by every write hook: nothing can change what the node
 * consumes without the list following, and no byte of co_node_t or
 * instruction of the receive path is spent on it. A board that filters
 * compares the list after each frame batch and poll (a few dozen
 * instructions) and reprograms its filter only when it changed. Its own
 * file, so that an MCU image that does not filter (every one today) does
 * not link it (a feature is left out by not linking its file).
 */
#include "co_node.h"

/* Append (id, rtr) unless it is there already; count grows beyond max
 * when the caller's array is full (the entry is then not written). */
static unsigned add(co_rx_id_t *ids, unsigned n, unsigned max, uint16_t id, bool rtr)
{
    for (unsigned k = 0; k < n && k < max; k++) {
        if (ids[k].id == id && ids[k].rtr == rtr) {
            return n;
        }
    }
    if (n < max) {
        ids[n].id = id;
        ids[n].rtr = rtr;
    }
    return n + 1u;
}

unsigned co_node_rx_ids(const co_node_t *node, co_rx_id_t *ids, unsigned max)
{
    unsigned n = 0;
    uint8_t id = node->node_id;
    bool configured = id >= 1u && id <= CO_NODE_ID_MAX;
    n = add(ids, n, max, 0x000u, false); /* NMT */
    n = add(ids, n, max, node->sync.cob_id, false);
    if (configured) {
        n = add(ids, n, max, (uint16_t)(0x600u + id), false);
    }
    if (co_cfg_has_service(co_cfg(node), &co_lss_service)) {
        n = add(ids, n, max, 0x7E5u, false);
    }
    if (configured && node->guard.enabled) {
        n = add(ids, n, max, (uint16_t)(0x700u + id), true);
    }
    if (node->hbc.node_id != 0u && node->hbc.time_ms != 0u) {
        n = add(ids, n, max, (uint16_t)(0x700u + node->hbc.node_id), false);
    }
    if (co_cfg_has_service(co_cfg(node), &co_rtr_service)) {
        for (unsigned k = 0; k < CO_TPDO_MAX; k++) {
            const co_tpdo_t *t = &node->tpdo[k];
            if (t->valid && t->rtr_allowed) {
                n = add(ids, n, max, t->cob_id, true);
            }
        }
    }
    return n;
}
