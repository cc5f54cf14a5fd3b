/*
 * co_sdo.h - SDO server (CiA 301 7.2.4): expedited and segmented upload and
 * download, toggle check, timeout, abort codes from co_res_t.
 * Block transfer is answered with "command specifier not valid".
 */
#ifndef CO_SDO_H
#define CO_SDO_H

#include "co_common.h"
#include "co_od.h"

/* Largest object a segmented download can write (bytes). */
#define CO_SDO_BUF 32u
/* Default SDO timeout between segments (CiA 301 leaves it to the device). */
#define CO_SDO_TIMEOUT_US 1000000u

typedef struct co_sdo {
    uint8_t state;  /* idle / segmented download / segmented upload */
    uint8_t toggle; /* expected toggle bit of the next segment (0 or 0x10) */
    bool restart;   /* a segment arrived: the timeout restarts at next poll */
    const co_od_entry_t *e;
    uint32_t size;  /* bytes of the transfer */
    uint32_t pos;   /* bytes done */
    uint32_t deadline;
    uint8_t buf[CO_SDO_BUF];
} co_sdo_t;

/* Forget any transfer in progress (reset communication). */
void co_sdo_init(co_sdo_t *sdo);

/*
 * Handle one frame on 0x600 + node-ID. Frames that are not 8 bytes long
 * are ignored. Answers on 0x580 + node-ID through co_port_can_send().
 * Returns true if the frame was an SDO request to this node.
 */
bool co_sdo_receive(co_node_t *node, const co_frame_t *f);

/* Timeout of a segmented transfer; returns the delay until it next matters. */
uint32_t co_sdo_poll(co_node_t *node, uint32_t now);

#endif /* CO_SDO_H */
