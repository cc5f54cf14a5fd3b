/** @file
 * co_emcy.h - EMCY producer (CiA 301 7.2.7): the raw frame, and an error
 * table for products that follow CiA 301's error model (error register
 * 0x1001 as the OR of the active errors' bits, an error-reset EMCY when the
 * last one clears, the pre-defined error field 0x1003).
 *
 * State: co_emcy_t in the node (the active errors, the history); nothing
 * else is kept, no pointer is held. Frames go out through co_node_send(),
 * never in stopped nor while 0x1014 bit 31 is set; a frame the board cannot
 * queue is counted (co_node_tx_dropped) and not retried. A full error table
 * (CO_EMCY_ACTIVE_MAX codes) takes no new code (co_emcy_error returns
 * false); the history keeps the newest CO_EMCY_HIST_MAX entries.
 */
#ifndef CO_EMCY_H
#define CO_EMCY_H

#include "co_common.h"
#include "co_od.h"

/** The node object (co_node.h). */
typedef struct co_node co_node_t;

/** CiA 301 emergency error codes used by the products. */
enum {
    CO_EMCY_NO_ERROR = 0x0000,
    CO_EMCY_GENERIC = 0x1000,
    CO_EMCY_VOLTAGE_LOW = 0x3100,
    CO_EMCY_DATA_SET = 0x6300,
    CO_EMCY_LIFE_GUARD = 0x8130, /**< life guard or heartbeat consumer event */
};

/** Error register (0x1001) bits. */
enum {
    CO_ER_GENERIC = 0x01,
    CO_ER_CURRENT = 0x02,
    CO_ER_VOLTAGE = 0x04,
    CO_ER_TEMPERATURE = 0x08,
    CO_ER_COMM = 0x10,
    CO_ER_PROFILE = 0x20,
    CO_ER_MANUFACTURER = 0x80,
};

/** Active errors and 0x1003 history depth a node has room for; an MCU image
 * may set less (its table sizes in `od/<family>/family.cmake`). History depth
 * 0: no history is kept, and the 0x1003 hooks do not exist (a product with
 * 0x1003 does not link).
 * CO_EMCY_ACTIVE_MAX 1..255: at least one (the table needs a member, and a
 * product that raises an error needs a place for it), at most what the
 * count co_emcy_t.nactive (a byte) holds.
 * CO_EMCY_HIST_MAX 0..254: 0x1003 sub 0 is the UNSIGNED8 count of
 * subs 1..254 (CiA 301). @{ */
#ifndef CO_EMCY_ACTIVE_MAX
#define CO_EMCY_ACTIVE_MAX 8u
#endif
#if CO_EMCY_ACTIVE_MAX < 1 || CO_EMCY_ACTIVE_MAX > 255
#error "CO_EMCY_ACTIVE_MAX must be 1..255 (at least one active error; counted in a byte)"
#endif
#ifndef CO_EMCY_HIST_MAX
#define CO_EMCY_HIST_MAX 8u
#endif
#if CO_EMCY_HIST_MAX < 0 || CO_EMCY_HIST_MAX > 254
#error "CO_EMCY_HIST_MAX must be 0..254 (CiA 301: 0x1003 subs 1..254; 0 keeps no history)"
#endif
/** @} */

/** EMCY state in the node: the error table and the 0x1003 history. */
typedef struct co_emcy {
    uint8_t nactive;                   /**< active errors: the first entries of code[] and bits[] */
    uint16_t code[CO_EMCY_ACTIVE_MAX]; /**< their emergency error codes */
    uint8_t bits[CO_EMCY_ACTIVE_MAX];  /**< their error register bits */
#if CO_EMCY_HIST_MAX > 0
    uint8_t nhist;                   /**< entries in hist, newest first */
    uint32_t hist[CO_EMCY_HIST_MAX]; /**< 0x1003: code | additional info << 16 */
#endif
} co_emcy_t;

/**
 * Send an EMCY frame: COB-ID from 0x1014 (nothing is sent while its bit 31
 * is set), bytes 0-1 code, byte 2 error register, bytes 3-7 manufacturer
 * bytes (msef may be NULL: zeros). Only in pre-operational and operational
 * (CiA 301: not in stopped). A non-zero code is entered in the 0x1003
 * history. Returns true if a frame was queued.
 */
bool co_emcy_send(co_node_t *node, uint16_t code, uint8_t er, const uint8_t msef[5]);

/**
 * Raise (active) or clear an error of the error table. Raising a new code
 * sends its EMCY with the updated error register; clearing the last one
 * sends the error-reset EMCY (code 0, register 0). Raising an active code
 * again or clearing an inactive one does nothing. Returns true if the
 * error table changed.
 */
bool co_emcy_error(co_node_t *node, uint16_t code, uint8_t er_bits, bool active,
                   const uint8_t msef[5]);

/** Error register from the error table: OR of the bits, bit 0 while any is active. */
uint8_t co_emcy_register(const co_node_t *node);

/** Whether an error code is active. */
bool co_emcy_active(const co_node_t *node, uint16_t code);

/**
 * A node op (co_node_ops_t.can_state) reporting CAN errors by EMCY: 8120h
 * while error passive, 8140h once back from bus-off (CiA 301 codes).
 */
void co_emcy_can_state(co_node_t *node, co_can_state_t old_state);

/** Read hook for 0x1001 (error register from the error table). */
co_res_t co_emcy_read_register(co_node_t *node, const co_od_entry_t *e, uint32_t *value);
#if CO_EMCY_HIST_MAX > 0
/** Read hook for 0x1003 (pre-defined error field): sub 0 the number of
 * entries, sub n the n-th newest (code | additional information << 16);
 * a sub-index beyond the entries held reads CO_E_NO_DATA (0x08000024). */
co_res_t co_emcy_read_hist(co_node_t *node, const co_od_entry_t *e, uint32_t *value);
/** Write hook for 0x1003 sub 0: 0 clears the history; any other value is
 * CO_E_VAL (0x06090030, CiA 301), another sub-index CO_E_RO. */
co_res_t co_emcy_write_hist(co_node_t *node, const co_od_entry_t *e, uint32_t value);
#endif
/** Write hook for 0x1014: CiA 301 rules (bits 30..11 zero, CAN-ID changes
 * only while bit 31 is set). */
co_res_t co_emcy_write_cobid(co_node_t *node, const co_od_entry_t *e, uint32_t value);

#endif /* CO_EMCY_H */
