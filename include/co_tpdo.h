/*
 * co_tpdo.h - transmit PDOs (CiA 301 7.2.2).
 *
 * Communication parameters (0x1800 + n) and mapping (0x1A00 + n) are read
 * from the dictionary when a TPDO is configured (reset, or a write to one
 * of them through co_tpdo_write_hook) and cached here, with the mapped
 * entries resolved to table pointers so that sending is a straight copy.
 * Transmission types: 1..240 every n-th SYNC; 254/255 event-driven with the
 * event timer (ms) and inhibit time (100 us, or the product's unit). Others are refused by the
 * dictionary's limits or the product's write hooks.
 */
#ifndef CO_TPDO_H
#define CO_TPDO_H

#include "co_common.h"
#include "co_od.h"

#define CO_TPDO_MAX 2u
#define CO_PDO_MAP_MAX 8u

typedef struct co_tpdo {
    bool valid;          /* exists, COB-ID bit 31 clear, mapping usable */
    uint8_t type;        /* transmission type */
    uint8_t nmap;
    uint8_t sync_count;  /* SYNCs since the last synchronous send */
    bool timer_armed;    /* event timer running (operational, type 254/255) */
    bool inhibited;      /* waiting for the inhibit time to pass */
    uint16_t cob_id;
    uint16_t event_ms;
    uint16_t inhibit;      /* inhibit time, in the product's unit (co_node_cfg_t) */
    uint32_t next_event;   /* time of the next event-timer send */
    uint32_t inhibit_end;  /* earliest time of the next send */
    const co_od_entry_t *map[CO_PDO_MAP_MAX];
    uint8_t map_bytes[CO_PDO_MAP_MAX];
    uint8_t len;           /* mapped bytes */
} co_tpdo_t;

/* Re-read parameters and mapping of TPDO n (0-based) from the dictionary. */
void co_tpdo_reconfig(co_node_t *node, unsigned n);

/* Start (entering operational) or stop every TPDO. */
void co_tpdo_start(co_node_t *node);
void co_tpdo_stop(co_node_t *node);

/* One SYNC received in operational. */
void co_tpdo_sync(co_node_t *node);

/* Event-driven sends; returns the delay until the next one. */
uint32_t co_tpdo_poll(co_node_t *node, uint32_t now);

/* Build TPDO n into f (exposed for tests and RTR). */
void co_tpdo_build(co_node_t *node, unsigned n, co_frame_t *f);

/* Write hook for 0x1800..0x1803 sub-entries: store, then reconfigure. */
co_res_t co_tpdo_write_hook(co_node_t *node, const co_od_entry_t *e, uint32_t value);

#endif /* CO_TPDO_H */
