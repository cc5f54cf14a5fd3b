/*
 * co_emcy.h - EMCY producer (CiA 301 7.2.7).
 */
#ifndef CO_EMCY_H
#define CO_EMCY_H

#include "co_common.h"

typedef struct co_node co_node_t;

/* CiA 301 emergency error codes used by the products. */
enum {
    CO_EMCY_NO_ERROR = 0x0000,
    CO_EMCY_GENERIC = 0x1000,
};

/*
 * Send an EMCY frame: COB-ID from 0x1014 (nothing is sent while its bit 31
 * is set), bytes 0-1 code, byte 2 error register, bytes 3-7 manufacturer
 * bytes (msef may be NULL: zeros). Only in pre-operational and operational
 * (CiA 301: not in stopped). Returns true if a frame was queued.
 */
bool co_emcy_send(co_node_t *node, uint16_t code, uint8_t er, const uint8_t msef[5]);

#endif /* CO_EMCY_H */
