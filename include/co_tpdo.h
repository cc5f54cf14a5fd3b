/** @file
 * co_tpdo.h - transmit PDOs (CiA 301 7.2.2).
 *
 * Communication parameters (0x1800 + n) and mapping (0x1A00 + n) are read
 * from the dictionary when a TPDO is configured (reset, or a write through
 * one of the hooks below) and cached here, with the mapped entries
 * resolved to table pointers so that sending is a straight copy.
 *
 * Transmission types:
 *   0        acyclic synchronous: at a SYNC, if the data changed since the
 *            last transmission
 *   1..240   every n-th SYNC
 *   252      sampled at SYNC, sent on a remote request (RTR)
 *   253      sent on a remote request, with data of that moment
 *   254, 255 event-driven: the event timer (ms) and application events
 *            (co_tpdo_event), never closer than the inhibit time (100 us,
 *            or the product's unit); an event inside the inhibit time is
 *            sent once when it ends.
 * A remote request on the COB-ID (bit 30 of sub 1 clear) sends any valid
 * TPDO in operational.
 *
 * State: co_tpdo_t in the node, CO_TPDO_MAX of them; the mapped entries
 * point into the product's const table. Frames go out through
 * co_node_send(): one the board cannot queue is counted and lost. A
 * TPDO number n a product passes must be below CO_TPDO_MAX: beyond it
 * co_tpdo_reconfig, co_tpdo_set_msb_first, co_tpdo_event and
 * co_tpdo_changed take it as a broken contract (CO_CHECK): nothing changes,
 * co_tpdo_changed answers false. Values a master writes are judged by the
 * write hooks below, which answer SDO abort codes.
 */
#ifndef CO_TPDO_H
#define CO_TPDO_H

#include "co_common.h"
#include "co_od.h"

/** TPDOs a node has room for (0x1800 + n for n below it). An MCU image of
 * one product may set fewer (its table sizes in `od/<family>/family.cmake`).
 * 1..512: at least one (the table needs a member; every product has a
 * TPDO), at most CiA 301's 512 (0x1800..0x19FF, the 9 bits of the index
 * that tpdo.c takes as the number). */
#ifndef CO_TPDO_MAX
#define CO_TPDO_MAX 2u
#endif
#if CO_TPDO_MAX < 1 || CO_TPDO_MAX > 512
#error "CO_TPDO_MAX must be 1..512 (CiA 301: TPDOs 0x1800..0x19FF; at least one)"
#endif
/** Entries a TPDO's mapping holds (0x1A00 + n, subs 1..8). */
#define CO_PDO_MAP_MAX 8u

/** One TPDO: its parameters, cached from the dictionary, and its state. */
typedef struct co_tpdo {
    bool valid;           /**< exists, COB-ID bit 31 clear, mapping usable */
    bool rtr_allowed;     /**< COB-ID bit 30 clear */
    uint8_t type;         /**< transmission type */
    uint8_t nmap;         /**< entries in map[] */
    uint8_t sync_count;   /**< SYNCs since the last synchronous send */
    bool timer_armed;     /**< event timer running (type 254/255; read only while operational) */
    bool pending;         /**< an application event waits for the inhibit time (operational) */
    bool have_last;       /**< last[] holds the last data sent (type 0) or sampled (252) */
    uint16_t cob_id;      /**< the CAN-ID it is sent on */
    uint16_t event_ms;    /**< event timer (ms; 0: off) */
    uint32_t inhibit_us;  /**< inhibit time (us; in the dictionary in the product's unit) */
    uint32_t next_event;  /**< time of the next event-timer send */
    uint32_t inhibit_end; /**< earliest time of the next event-driven send */
    const co_od_entry_t *map[CO_PDO_MAP_MAX]; /**< mapped entries */
    uint8_t map_drop[CO_PDO_MAP_MAX];         /**< 32 - bits of each: the high bits not sent */
    uint8_t len;                              /**< mapped bytes */
    uint8_t dlc;    /**< of its frames: len, or 8 where the product pads */
    bool msb_first; /**< mapped values big-endian (the product's choice, DST 0x5001 = 0):
                     * co_tpdo_set_msb_first(); kept by co_tpdo_reconfig() */
    _Alignas(4) uint8_t last[8]; /**< word aligned: copied in words (tpdo.c) */
} co_tpdo_t;

/**
 * Re-read the communication parameters (0x1800 + n) and the mapping
 * (0x1A00 + n) of TPDO n (0-based) from the dictionary: the stack calls it
 * at every reset and from the write hooks below; a product calls it after
 * changing those values itself. A TPDO whose parameters are missing or
 * whose mapping is unusable stays invalid (sends nothing). While
 * operational, its timers restart now. n must be below CO_TPDO_MAX: a
 * larger n is a broken contract (CO_CHECK, co_common.h) and changes
 * nothing.
 */
void co_tpdo_reconfig(co_node_t *node, unsigned n);

/**
 * The byte order of TPDO n's mapped values: little-endian as CiA 301 has
 * it (false, the default after co_node_init()), or each value big-endian
 * (true: the DST's 0x5001 "PDO coding" = 0). A property of the TPDO, kept
 * across co_tpdo_reconfig() and resets: the product sets it, typically
 * from its reset hook and the write hook of its own object. n must be
 * below CO_TPDO_MAX: a larger n is a broken contract (CO_CHECK) and
 * changes nothing.
 */
void co_tpdo_set_msb_first(co_node_t *node, unsigned n, bool msb_first);

/** Entering operational: every TPDO starts afresh (SYNC count 0, no data
 * sent yet, no event pending, the event timer's first send at the next
 * poll). Outside operational nothing is sent and no event is taken (the
 * poll, SYNC, RTR and event functions check the state), so leaving it
 * needs no call: what the timers held is set afresh here. */
void co_tpdo_start(co_node_t *node);

/** One SYNC received in operational. */
void co_tpdo_sync(co_node_t *node);

/** A remote frame: sends the TPDO it asks for. Returns true if it was one. */
bool co_tpdo_receive_rtr(co_node_t *node, const co_frame_t *f);

/**
 * An application event for TPDO n (new value, change of state): types
 * 254/255 send it now or when the inhibit time ends. Other types ignore it.
 */
void co_tpdo_event(co_node_t *node, unsigned n);

/**
 * Change of state: whether event-driven TPDO n's mapped data differ from
 * what it last sent (true before its first send). No side effects.
 */
bool co_tpdo_changed(co_node_t *node, unsigned n);

/** Event-driven sends; returns the delay until the next one. */
uint32_t co_tpdo_poll(co_node_t *node, uint32_t now);

/** Build TPDO n into f (exposed for tests). */
void co_tpdo_build(co_node_t *node, unsigned n, co_frame_t *f);

/**
 * Write hook for 0x1800 + n sub-entries: store, then reconfigure. Checks
 * only what every product shares: transmission types 241..251 are invalid.
 */
co_res_t co_tpdo_write_comm(co_node_t *node, const co_od_entry_t *e, uint32_t value);

/**
 * Stricter write hook for a writable COB-ID (sub 1), CiA 301: bits 29 and
 * 11..28 zero, the CAN-ID changes only while the PDO is invalid (bit 31),
 * and a valid one not to a restricted CAN-ID. Abort 0x06090030 otherwise.
 */
co_res_t co_tpdo_write_cobid(co_node_t *node, const co_od_entry_t *e, uint32_t value);

/**
 * Write hook for a writable mapping (0x1A00 + n), CiA 301 dynamic mapping:
 * sub 0 only while the PDO is invalid (0x06010000), at most as many
 * entries as the table has, at most 64 bits (0x06040042); sub 1..8 only
 * while sub 0 is 0 (0x06010000), naming an existing (0x06020000) mappable
 * (0x06040041) object.
 */
co_res_t co_tpdo_write_map(co_node_t *node, const co_od_entry_t *e, uint32_t value);

#endif /* CO_TPDO_H */
