/** @file
 * co_hb.h - heartbeat producer (0x1017) and boot-up message.
 *
 * State: co_hb_t in the node. Frames go out through co_node_send(); one
 * the board cannot queue is counted and not repeated.
 */
#ifndef CO_HB_H
#define CO_HB_H

#include "co_common.h"
#include "co_od.h"

/** The node object (co_node.h). */
typedef struct co_node co_node_t;

/** Heartbeat producer state in the node. */
typedef struct co_hb {
    uint16_t period_ms; /**< 0x1017 as last applied; 0 = off */
    bool restart;       /**< period changed: next heartbeat one period from now */
    uint32_t next;      /**< time of the next heartbeat */
} co_hb_t;

/** Re-read 0x1017 and restart the period (call after a write or a reset). */
void co_hb_reconfig(co_node_t *node);

/**
 * The heartbeat period in use (ms, 0x1017 as last applied; 0: no
 * heartbeat). Node guarding asks it: while the heartbeat runs, guard
 * requests go unanswered (CiA 301: one error-control protocol at a time).
 */
uint16_t co_hb_period_ms(const co_node_t *node);

/** Send the boot-up message (0x700 + node-ID, one byte 0x00). */
void co_hb_bootup(co_node_t *node);

/** Send the heartbeat (0x700 + node-ID, the NMT state) when its period
 * ran out, one period after the last (no burst after a late poll). Returns
 * the delay (us) until the next one, CO_NEVER while 0x1017 is 0 or the
 * node initialises. */
uint32_t co_hb_poll(co_node_t *node, uint32_t now);

/**
 * Standard write hook for 0x1017: stores the value and restarts the period.
 * Products with extra rules (the DST's "1..19 not accepted") validate first.
 */
co_res_t co_hb_write_time(co_node_t *node, const co_od_entry_t *e, uint32_t value);

#endif /* CO_HB_H */
