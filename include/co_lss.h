/** @file
 * co_lss.h - LSS slave (CiA 305): layer setting services on 0x7E5 (master
 * to slave) and 0x7E4 (slave to master), 8-byte frames.
 *
 * Services: switch state global (04h) and selective (40h-43h -> 44h),
 * configure node-ID (11h) and bit timing (13h), activate bit timing (15h),
 * store configuration (17h: the configured bit rate becomes the product's
 * stored one), activate bit timing (15h: after the switch delay the board
 * runs at the configured rate, co_port_can_bitrate(), until a reset node
 * applies the stored one; the second delay, in which CiA 305 keeps the
 * slave from sending, is not enforced: a slave in configuration state has
 * only its heartbeat to send), inquire vendor / product / revision / serial /
 * node-ID (5Ah-5Eh), identify remote slave (46h-4Bh -> 4Fh), identify
 * non-configured slave (4Ch -> 50h) and Fastscan (51h -> 4Fh).
 *
 * The LSS address is 0x1018 sub 1..4. Node-ID 0xFF is "not configured": such
 * a node is silent but for LSS; when it gets a node-ID and is switched back
 * to waiting it resets communication with it (CiA 305). A configured
 * node-ID becomes active at the next reset communication; "store" keeps it
 * (and the bit rate) through the product's store hook, or the LSS class.
 * State: co_lss_t in the node; linked where a product lists
 * co_lss_service. Requests it does not know, or that arrive in the wrong
 * LSS state, go unanswered (CiA 305); answers go out through co_node_send().
 */
#ifndef CO_LSS_H
#define CO_LSS_H

#include "co_common.h"

/** The node object (co_node.h). */
typedef struct co_node co_node_t;

/** The node-ID of a node not configured (LSS): silent but for LSS. */
#define CO_LSS_UNCONFIGURED 0xFFu

/** LSS slave state in the node. */
typedef struct co_lss {
    uint8_t state;      /**< 0 waiting, 1 configuration */
    uint8_t selective;  /**< switch-state-selective progress (matched parts) */
    uint8_t pending_id; /**< node-ID for the next reset communication; 0: none */
    uint8_t pending_br; /**< CiA 305 bit-timing index configured; 0xFF: none */
    uint8_t identify;   /**< identify-remote-slave progress */
    uint8_t fs_sub;     /**< Fastscan: which LSS address part is checked next */
    bool fs_active;     /**< Fastscan: confirmed so far */
    bool switching;     /**< activate bit timing: the switch is due at switch_at */
    uint32_t switch_at; /**< (us) */
} co_lss_t;

/** Reset communication (co_service_t.reset): back to the waiting state, no
 * selective switch, identification or Fastscan in progress, a configured
 * bit timing forgotten; a configured node-ID stays pending (co_node_reset
 * applies it). */
void co_lss_reset(co_node_t *node);

/** Handle a frame on 0x7E5. Returns true if it was one. Works in every NMT
 * state, and while the node has no node-ID. */
bool co_lss_receive(co_node_t *node, const co_frame_t *f);

#endif /* CO_LSS_H */
