/** @file
 * co_nmt.h - NMT slave (CiA 301 7.2.8): states, the five commands, boot-up.
 *
 * State: co_nmt_t in the node; a product reads it with co_node_nmt_state()
 * and changes it with co_nmt_enter() (its error behaviour), never from an
 * interrupt. The reset commands run co_node_reset() before returning.
 */
#ifndef CO_NMT_H
#define CO_NMT_H

#include "co_common.h"

/** The node object (co_node.h). */
typedef struct co_node co_node_t;

/** NMT states, valued as they appear in the heartbeat byte. */
typedef enum co_nmt_state {
    CO_NMT_INIT = 0x00,
    CO_NMT_STOPPED = 0x04,
    CO_NMT_OPERATIONAL = 0x05,
    CO_NMT_PREOP = 0x7F,
} co_nmt_state_t;

/** What a reset reloads (NMT commands, co_node_request_reset). */
typedef enum co_reset {
    CO_RESET_COMM = 1, /**< reload communication parameters (0x1000-0x1FFF) */
    CO_RESET_NODE = 2, /**< reload everything; power-on is one too */
} co_reset_t;

/** NMT state in the node (co_node_nmt_state() reads it). */
typedef struct co_nmt {
    uint8_t state; /**< co_nmt_state_t */
} co_nmt_t;

/**
 * Handle one NMT frame (COB-ID 0x000). Frames with DLC != 2 or addressed to
 * another node are ignored (CiA 301). Returns true if the frame was an NMT
 * frame (whether or not it was for this node).
 */
bool co_nmt_receive(co_node_t *node, const co_frame_t *f);

/**
 * Enter a state, starting or stopping the services it allows
 * (TPDOs start on entering operational). No-op if already in it.
 */
void co_nmt_enter(co_node_t *node, co_nmt_state_t state);

/** Whether SDO is served in NMT state state (pre-operational, operational). */
static inline bool co_nmt_sdo_allowed(uint8_t state)
{
    return state == CO_NMT_PREOP || state == CO_NMT_OPERATIONAL;
}

#endif /* CO_NMT_H */
