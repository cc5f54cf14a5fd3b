/** @file
 * co_sync.h - SYNC consumer (CiA 301 7.2.5). The COB-ID is 0x1005 when the
 * dictionary has it, 0x080 otherwise. State: co_sync_t in the node. A SYNC
 * in operational drives the synchronous TPDOs (co_tpdo_sync); elsewhere,
 * or with more than one data byte, it is consumed and does nothing.
 */
#ifndef CO_SYNC_H
#define CO_SYNC_H

#include "co_common.h"
#include "co_od.h"

/** The node object (co_node.h). */
typedef struct co_node co_node_t;

/** SYNC consumer state in the node. */
typedef struct co_sync {
    uint16_t cob_id; /**< the SYNC COB-ID in use */
} co_sync_t;

/** Re-read the SYNC COB-ID from 0x1005 (0x080 where the dictionary has
 * none): at every reset and after a write of 0x1005. */
void co_sync_reconfig(co_node_t *node);

/** Write hook for 0x1005: store and use the new COB-ID at once. */
co_res_t co_sync_write_cobid(co_node_t *node, const co_od_entry_t *e, uint32_t value);

/** Returns true if f was a SYNC; drives the synchronous TPDOs. */
bool co_sync_receive(co_node_t *node, const co_frame_t *f);

#endif /* CO_SYNC_H */
