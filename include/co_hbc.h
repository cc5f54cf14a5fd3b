/** @file
 * co_hbc.h - heartbeat consumer (CiA 301 0x1016, one monitored node).
 *
 * 0x1016 sub 1: bits 23..16 node-ID, bits 15..0 time in ms (0: off).
 * Monitoring starts with the first heartbeat from that node; a missing one
 * for longer than the time is a heartbeat event: EMCY 8130h in the error
 * table and, from operational, pre-operational. The next heartbeat clears it.
 * State: co_hbc_t in the node; linked where a product lists co_hbc_service.
 */
#ifndef CO_HBC_H
#define CO_HBC_H

#include "co_common.h"
#include "co_od.h"

/** The node object (co_node.h). */
typedef struct co_node co_node_t;

/** Heartbeat consumer state in the node. */
typedef struct co_hbc {
    uint8_t node_id;   /**< monitored node; 0: off */
    uint16_t time_ms;  /**< 0x1016 sub 1 bits 15..0 (ms; 0: off) */
    bool started;      /**< a heartbeat came since configuration */
    bool kick;         /**< one came: restart the time at the next poll */
    bool lost;         /**< heartbeat event active */
    uint32_t deadline; /**< when the monitored node's heartbeat is late */
} co_hbc_t;

/** Re-read 0x1016 sub 1 (after a reset or a write). */
void co_hbc_reset(co_node_t *node);

/** A frame on 0x700 + the monitored node-ID. Returns true if consumed. */
bool co_hbc_receive(co_node_t *node, const co_frame_t *f);

/** The monitored node's time (co_service_t.poll): raises the heartbeat
 * event when it ran out. Returns the delay (us) until it next needs to
 * run, CO_NEVER while off, not started or lost. */
uint32_t co_hbc_poll(co_node_t *node, uint32_t now);

/** Write hook for 0x1016 sub n: reserved bits 31..24 must be 0. */
co_res_t co_hbc_write_time(co_node_t *node, const co_od_entry_t *e, uint32_t value);

#endif /* CO_HBC_H */
