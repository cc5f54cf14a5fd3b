/** @file
 * co_guard.h - node guarding and life guarding (CiA 301 7.2.8.3.2.1).
 *
 * Active when the dictionary has 0x100C (guard time). A remote frame on
 * 0x700 + node-ID is answered with one byte: toggle bit 7 | NMT state;
 * the toggle starts at 0 after every reset and alternates. While the
 * heartbeat producer runs (0x1017 != 0) guard requests are not answered
 * (CiA 301: one error-control protocol at a time).
 * Life guarding: once the first request came, and while guard time
 * (0x100C, ms) and life time factor (0x100D) are both non-zero, a missing
 * request for guard time x factor is a life-guard event: EMCY 8130h in
 * the error table and, from operational, pre-operational. The next request
 * clears it (error reset EMCY when nothing else is active).
 * The life time reaches 65535 ms x 255 = 4.6 h, beyond the 71.6 min of the
 * wrapping microsecond clock (and the 35.8 min of co_time_before): it is
 * timed in laps of at most CO_GUARD_LAP_MS, exactly, whatever its length.
 * State: co_guard_t in the node; linked where a product lists
 * co_guard_service. It asks the heartbeat's period (co_hb_period_ms), it
 * does not read co_hb_t.
 */
#ifndef CO_GUARD_H
#define CO_GUARD_H

#include "co_common.h"

/** Longest lap of the life time: 1e9 us stays well inside co_time_before's
 * 2^31 us horizon, with room for a late poll. */
#define CO_GUARD_LAP_MS 1000000u

/** The node object (co_node.h). */
typedef struct co_node co_node_t;

/** Node and life guarding state in the node. */
typedef struct co_guard {
    bool enabled;      /**< the dictionary has guarding objects */
    uint8_t toggle;    /**< 0x00 or 0x80, the next answer's bit 7 */
    bool seen;         /**< a request came since the last reset */
    bool kick;         /**< a request came: restart the life time at next poll */
    bool lost;         /**< life-guard event active */
    uint32_t deadline; /**< end of the current lap of the life time */
    uint32_t left_ms;  /**< life time still to run after this lap */
} co_guard_t;

/** Reset communication: toggle 0, life guarding waits for the first request. */
void co_guard_reset(co_node_t *node);

/** Handle a remote frame on 0x700 + node-ID. Returns true if it was one. */
bool co_guard_receive(co_node_t *node, const co_frame_t *f);

/** The life time (co_service_t.poll): raises the life-guard event when it
 * ran out. Returns the delay (us) until it next needs to run, CO_NEVER
 * while life guarding is off or waits for its first request. */
uint32_t co_guard_poll(co_node_t *node, uint32_t now);

#endif /* CO_GUARD_H */
