/** @file
 * co_node.h - the node object: one CANopen slave, all of its state.
 *
 * The contract between a product (od/), a board (boards/) and the stack.
 * co_node_t is visible so that its owner can allocate it (no heap); its
 * fields are the stack's. A product or a board reads and changes a node
 * only through the functions below and the modules' headers:
 *  - Ownership. The caller owns the node, the config (const, shared by
 *    every node of a product), the class RAM structs and the board and
 *    product contexts; all of them outlive the node. The stack holds
 *    pointers to them and never frees anything.
 *  - Read, at any time (static inline, free): co_node_app(),
 *    co_node_id(), co_node_serial(), co_node_bitrate(), co_node_nmt_state(),
 *    co_node_can_state(), co_node_can_kbps(), co_node_tx_dropped(),
 *    co_node_store_status();
 *    dictionary values through co_node_entry() and co_od_get();
 *    co_store_limit_reached(); co_od_checking() in a write hook.
 *  - Change, from the product's reset hook only (co_node_ops_t.reset):
 *    the node-ID (co_node_set_id), the bit-rate code (co_node_set_bitrate)
 *    and the automatic start (co_node_set_autostart). Elsewhere they are a
 *    broken contract (CO_CHECK, co_common.h) and change nothing.
 *  - Change, from any hook, the product's poll or its sample function:
 *    its own dictionary values (co_od_store() in a write hook), the byte
 *    order of a TPDO (co_tpdo_set_msb_first), TPDO events
 *    (co_tpdo_event), the NMT state (co_nmt_enter), errors (co_emcy_*),
 *    the store (co_store_save, co_store_mark_corrupt,
 *    co_store_report_emcy), a reset after the current answer
 *    (co_node_request_reset), and co_node_wake() after a new sample.
 *  - A board calls co_node_init/start/receive/poll, co_node_set_can_state
 *    and co_node_leds, and provides co_port.h.
 *  - Invalid arguments: an index or a value outside what a function's
 *    comment allows is a programming error, checked with CO_CHECK (no
 *    crash, nothing changed, reported in the unit tests). Results that a
 *    master causes are co_res_t (SDO abort codes), never a CO_CHECK.
 *
 * Typical main loop (boards/common/mcu_main.c, boards/linux/main.c):
 *     co_node_init(&node, &cfg, port, app, ram, nvm_base);
 *     co_node_start(&node, now());
 *     for (;;) {
 *         wait for a frame or for the delay co_node_poll() returned;
 *         while (frame received) co_node_receive(&node, &frame, now());
 *         co_node_poll(&node, now());          // timers, and what frames left to do
 *     }
 * Not reentrant for one node; separate nodes are independent. Never call
 * from an interrupt: a receive interrupt queues frames, the loop feeds them.
 *
 * Layering of src/ (no include or call cycle but through this object):
 *   node        owns every module's state; dispatches frames, polls, resets
 *     -> nmt, sdo, sync, tpdo, hb, emcy, store, the optional services
 *        (guard, hbc, lss, rtr, progdl): the protocol modules
 *          -> od (the dictionary), image (program images), common: the leaves
 *   incl (CiA 410), filter, led: libraries the products (led: the node)
 *   call, calling no other module but filter
 * A protocol module reaches another only downwards (sync -> tpdo at a
 * SYNC, nmt -> tpdo at a state change, store -> emcy for 6300h, lss ->
 * store, sdo -> nmt (SDO allowed in this state), guard and hbc -> nmt and
 * emcy (their timeouts), guard asks hb through co_hb_period_ms(); the SDO
 * server hands a DOMAIN's bytes to the config's handler, progdl's, through
 * co_node_cfg_t.sdo_domain, a pointer), and everything may call
 * back into the node (co_node_send, co_node_entry, co_node_reset, the NMT
 * state in node->nmt). The dictionary calls no protocol module: a write
 * hook of a product table (co_store_write_save, co_tpdo_write_comm, ...) is
 * named by the table, not by od.c, and a product's autosave is
 * co_node_write()'s, not co_od_write()'s.
 */
#ifndef CO_NODE_H
#define CO_NODE_H

#include "co_common.h"
#include "co_emcy.h"
#include "co_guard.h"
#include "co_hb.h"
#include "co_hbc.h"
#include "co_led.h"
#include "co_lss.h"
#include "co_nmt.h"
#include "co_od.h"
#include "co_port.h"
#include "co_sdo.h"
#include "co_store.h"
#include "co_sync.h"
#include "co_tpdo.h"

/** Stored node-ID and bit rate: the RAM struct of class LSS. */
typedef struct co_lss_para {
    uint8_t node_id; /**< stored node-ID */
    uint8_t bitrate; /**< product's code */
} co_lss_para_t;

/** Product hooks; every one is optional (NULL). */
typedef struct co_node_ops {
    /** After the stack reloaded parameters for a reset; before boot-up. */
    void (*reset)(co_node_t *node, co_reset_t kind);
    /** After every NMT state change, boot-up included (old = INIT). */
    void (*state)(co_node_t *node, co_nmt_state_t old_state);
    /** The CAN controller's state changed (co_emcy_can_state reports it by EMCY). */
    void (*can_state)(co_node_t *node, co_can_state_t old_state);
    /** After 0x1010 "save" or 0x1011 "load" succeeded. */
    void (*stored)(co_node_t *node, uint32_t signature);
    /** Product work; returns the delay until it next needs to run. */
    uint32_t (*poll)(co_node_t *node, uint32_t now);
    /** Complete a TPDO after its mapped bytes (fixed layouts, counters, checksums). */
    void (*tpdo_fill)(co_node_t *node, unsigned n, co_frame_t *f);
    /**
     * LSS "store configuration": keep node-ID id and CiA 305 bit-timing
     * index br (0xFF: unchanged). Returns the LSS error code (0 ok,
     * 1 not supported, 2 storage error). NULL: the LSS class is stored.
     */
    uint8_t (*lss_store)(co_node_t *node, uint8_t id, uint8_t br);
    /** LED patterns; when NULL the CiA 303-3 mapping of co_node_leds() holds. */
    void (*leds)(co_node_t *node, co_led_pattern_t *green, co_led_pattern_t *red);
} co_node_ops_t;

/**
 * An optional service: linked into an image only when a product's config
 * lists it (a feature is left out by not linking its file, not by `#if`).
 * The core (NMT, SDO, SYNC, heartbeat, TPDO, EMCY, store) is always there.
 */
typedef struct co_service {
    bool (*receive)(co_node_t *node, const co_frame_t *f); /**< true: consumed */
    uint32_t (*poll)(co_node_t *node, uint32_t now);       /**< next deadline */
    void (*reset)(co_node_t *node);                        /**< at reset communication */
    bool always; /**< receives in every state, and without a node-ID (LSS) */
} co_service_t;

extern const co_service_t co_guard_service; /**< node and life guarding (co_guard.h) */
extern const co_service_t co_hbc_service;   /**< heartbeat consumer (co_hbc.h) */
extern const co_service_t co_lss_service;   /**< LSS slave (co_lss.h) */
extern const co_service_t co_rtr_service;   /**< TPDOs on remote request (co_tpdo.h) */

/** What a product type is; const, shared by every node of that product. */
typedef struct co_node_cfg {
    const co_od_t *od;                   /**< the dictionary */
    const co_node_ops_t *ops;            /**< the product's hooks, or NULL: none */
    const co_led_timing_t *led;          /**< LED timings (co_led_cia303, or the manual's) */
    const co_service_t *const *services; /**< optional services, NULL-ended (may be NULL) */
    /** SDO segmented (co_sdo_segmented) and block (co_sdo_block) transfer,
     * or NULL: not offered, such requests are aborted with 0x05040001. @{ */
    co_sdo_proto_fn sdo_segmented;
    co_sdo_proto_fn sdo_block;
    /** @} */
    /** Downloads of the table's DOMAIN entries (co_sdo_domain_fn), or NULL:
     * refused with 0x08000022. */
    co_sdo_domain_fn sdo_domain;
    uint16_t ram_size[CO_CLS_COUNT]; /**< sizeof each class struct (0: none) */
    uint8_t default_node_id;         /**< what a blank EEPROM boots with (co_node_set_factory_id) */
    uint8_t default_bitrate;         /**< product's code for its default bit rate */
    uint8_t tpdo_dlc;                /**< 0: DLC = mapped bytes; 8: pad with zeros */
    uint16_t inhibit_unit_us;        /**< unit of 0x1800+n sub 3; 0: CiA 301's 100 us; at most
                                      * 1000, so that 65535 units stay inside the 2^31 us a
                                      * wrapping deadline can span (a larger one counts as 1000) */
    uint32_t store_write_limit;      /**< 0: unlimited */
    bool autosave;                   /**< every SDO write to a stored entry is stored on its own,
                                      * after the SDO server's pause (co_store_poll) */
    bool load_keeps_lss;             /**< 0x1011 "load" leaves node-ID and bit rate alone */
    bool comm_reset_applies_id;      /**< reset communication also activates a new node-ID */
    bool save_includes_lss;          /**< 0x1010 "save" stores the node-ID / bit-rate set too */
    uint16_t lss_bitrates;           /**< CiA 305 bit-timing indices supported (bit n = index n) */
    uint8_t id_offset;    /**< id_index holds the node-ID minus this (the JD's 3000h: 1) */
    uint16_t id_index;    /**< 0, or a product's own U8 object (sub 0) of the PARA class
                           * holding the node-ID (minus id_offset): where a factory
                           * node-ID (co_node_set_factory_id) goes when its defaults are
                           * loaded. A node-ID in the LSS class needs none. */
    const uint16_t *kbps; /**< kbit/s of each bit-rate code (16 codes; 0: unused), or NULL */
} co_node_cfg_t;

/** Whether cfg lists service sv (a node is an LSS slave when it lists
 * co_lss_service: the list is the one place that says so). */
static inline bool co_cfg_has_service(const co_node_cfg_t *cfg, const co_service_t *sv)
{
    for (const co_service_t *const *s = cfg->services; s != NULL && *s != NULL; s++) {
        if (*s == sv) {
            return true;
        }
    }
    return false;
}

/** The node's state. Its fields are the stack's: the accessors below and
 * the modules' functions are the product's and the board's way in. */
struct co_node {
    /* Bytes first: on a Cortex-M0 a byte field is one load only within the
     * first 32 bytes of the struct (words: 128), so the hot ones go here. */
    uint8_t node_id;             /**< active node-ID */
    uint8_t bitrate;             /**< active bit-rate code (the product's table) */
    uint8_t can_state;           /**< co_can_state_t */
    bool autostart;              /**< set by the reset op: go operational after boot-up */
    uint8_t reset_request;       /**< co_reset_t to perform at the next poll (0: none) */
    bool dirty;                  /**< something happened since the last full poll */
    bool due_never;              /**< the last full poll found no deadline at all */
    bool od_checking;            /**< write hooks only validate (co_od_validate) */
    uint8_t factory_id;          /**< co_node_set_factory_id(); 0: the config's default */
    co_nmt_t nmt;                /**< NMT (co_nmt.h) */
    uint16_t can_kbps;           /**< bit rate the board was last asked for (co_port_can_bitrate);
                                  * here, in what was padding before cfg */
    const co_node_cfg_t *cfg;    /**< the config co_node_init() got (read it with co_cfg()) */
    void *port;                  /**< board context for co_port_* */
    void *app;                   /**< product context for its hooks */
    void *ram[CO_CLS_COUNT];     /**< the class structs, owned by the caller */
    uint32_t nvm_base;           /**< where this node's records start in NVM */
    uint32_t now;                /**< time of the latest co_node_poll() or co_node_receive() */
    uint32_t due;                /**< not dirty: no service needs to run before this time */
    uint32_t tx_dropped;         /**< frames the board could not queue */
    co_sync_t sync;              /**< SYNC consumer (co_sync.h) */
    co_hb_t hb;                  /**< heartbeat producer (co_hb.h) */
    co_store_t store;            /**< parameter store (co_store.h) */
    co_sdo_t sdo;                /**< SDO server (co_sdo.h) */
    co_tpdo_t tpdo[CO_TPDO_MAX]; /**< TPDOs (co_tpdo.h) */
    co_emcy_t emcy;              /**< EMCY producer (co_emcy.h) */
    co_guard_t guard;            /**< node and life guarding (co_guard.h) */
    co_lss_t lss;                /**< LSS slave (co_lss.h) */
    co_hbc_t hbc;                /**< heartbeat consumer (co_hbc.h) */
    uint32_t serial;             /**< co_node_set_serial(); 0: none given. Last: read
                                  * once a boot, it shifts no hot field's offset (Cortex-M0 bytes) */
};

/**
 * The node's config. An MCU image of one product may fix it at build time
 * (`-DCO_FIXED_CFG=<config symbol>`): every flag and hook of the config is
 * then a constant to the compiler, which drops the code that product never
 * runs. co_node_init() must then be given that same config.
 */
#ifdef CO_FIXED_CFG
extern const co_node_cfg_t CO_FIXED_CFG;
#define co_cfg(node) ((void)(node), &CO_FIXED_CFG)
#else
#define co_cfg(node) ((node)->cfg)
#endif

/**
 * Prepare a node; nothing is sent, the board is not called. cfg, port, app
 * and the ram structs are owned by the caller and must outlive the node;
 * ram (copied) has CO_CLS_COUNT entries, NULL where cfg->ram_size is 0.
 * nvm_base: where the node's records start in the board's EEPROM (each
 * node of a device its own CO_STORE_NVM_SIZE bytes). Cannot fail.
 */
void co_node_init(co_node_t *node, const co_node_cfg_t *cfg, void *port, void *app,
                  void *const ram[CO_CLS_COUNT], uint32_t nvm_base);

/** Power-on at time now: reset node (restore the stored sets, ask the
 * board for the bit rate, boot-up, pre-operational or, with autostart,
 * operational). A stored set that cannot be used is reported, never
 * fatal: co_node_store_status(). */
void co_node_start(co_node_t *node, uint32_t now);

/**
 * Tell the node that something its services look at changed outside a
 * received frame (a sensor sample, a fault): the next co_node_poll() runs
 * every service instead of returning at once because nothing is due.
 */
static inline void co_node_wake(co_node_t *node)
{
    node->dirty = true;
}

/** A write hook runs for co_od_validate(): check the value held, store nothing (co_od_write_fn). */
static inline bool co_od_checking(const co_node_t *node)
{
    return node->od_checking;
}

/* ---- The product's and the board's view of the node (the contract above).
 * Static inline: each is the one load or store it replaces, free in an
 * image. */

/** The product context given to co_node_init() (the product's instance). */
static inline void *co_node_app(const co_node_t *node)
{
    return node->app;
}

/** The active node-ID: 1..127, or CO_LSS_UNCONFIGURED (0xFF: none yet, LSS). */
static inline uint8_t co_node_id(const co_node_t *node)
{
    return node->node_id;
}

/** The active bit-rate code (the product's table, co_node_cfg_t.kbps). */
static inline uint8_t co_node_bitrate(const co_node_t *node)
{
    return node->bitrate;
}

/** The NMT state (CO_NMT_INIT while a reset runs). */
static inline co_nmt_state_t co_node_nmt_state(const co_node_t *node)
{
    return (co_nmt_state_t)node->nmt.state;
}

/** The bit rate (kbit/s) the board was last asked for
 * (co_port_can_bitrate): the one the node runs at, LSS "activate bit
 * timing" included; 0 when its code names none, 0xFFFF before the first
 * reset. A bootloader's hand-over reads it (boards/common/boot.h). */
static inline uint16_t co_node_can_kbps(const co_node_t *node)
{
    return node->can_kbps;
}

/** The CAN controller's state as the board last reported it. */
static inline co_can_state_t co_node_can_state(const co_node_t *node)
{
    return (co_can_state_t)node->can_state;
}

/** Frames the board could not queue or that fell due while bus-off. */
static inline uint32_t co_node_tx_dropped(const co_node_t *node)
{
    return node->tx_dropped;
}

/**
 * What the last restore of class cls (CO_CLS_PARA, CO_CLS_LSS) found, as
 * updated since (co_store.h: a full save makes a corrupt set sound again).
 * Another cls: a broken contract (CO_CHECK), CO_STORE_BLANK.
 */
static inline co_store_status_t co_node_store_status(const co_node_t *node, co_cls_t cls)
{
    if (!CO_CHECK(cls == CO_CLS_PARA || cls == CO_CLS_LSS)) {
        return CO_STORE_BLANK;
    }
    return (co_store_status_t)node->store.status[cls];
}

/* The node-ID, bit rate and automatic start are set by the stack at every
 * reset (from the LSS set, else the config's defaults; autostart off) and
 * then by the product's reset hook, if it has one: only there may a
 * product change them (the NMT state is CO_NMT_INIT then). Anywhere else
 * a call is a broken contract (CO_CHECK) and changes nothing. */

/** Node-ID id (1..127, or CO_LSS_UNCONFIGURED) from the next boot-up on:
 * a product that keeps it in its own object (the JD's 3000h). Another id:
 * a broken contract (CO_CHECK), nothing changes. */
static inline void co_node_set_id(co_node_t *node, uint8_t id)
{
    if (CO_CHECK(node->nmt.state == CO_NMT_INIT) &&
        CO_CHECK((id >= 1u && id <= CO_NODE_ID_MAX) || id == CO_LSS_UNCONFIGURED)) {
        node->node_id = id;
    }
}

/** Bit-rate code (0..15, the product's table) activated by this reset: the
 * board is asked for its rate when the reset ends (co_port_can_bitrate).
 * Another code: a broken contract (CO_CHECK), nothing changes. */
static inline void co_node_set_bitrate(co_node_t *node, uint8_t code)
{
    if (CO_CHECK(node->nmt.state == CO_NMT_INIT) && CO_CHECK(code <= 15u)) {
        node->bitrate = code;
    }
}

/** Go operational by itself after this boot-up (the DST's 0x5000, ...). */
static inline void co_node_set_autostart(co_node_t *node, bool on)
{
    if (CO_CHECK(node->nmt.state == CO_NMT_INIT)) {
        node->autostart = on;
    }
}

/**
 * The factory node-ID of this node (1..127), instead of the config's
 * default_node_id, which all nodes of a product share: what a blank EEPROM
 * boots with and what "restore defaults" (0x1011, then a reset) returns
 * to. The stack puts it in the LSS set's defaults and, where the product
 * keeps its node-ID in its own object (co_node_cfg_t.id_index), in that
 * object's default. A board that runs several nodes of one product (the
 * Linux program's `--node PRODUCT@ID`) calls it after co_node_init() and
 * before co_node_start(). While the node runs (its NMT state is not
 * CO_NMT_INIT), or another id, it is a broken contract (CO_CHECK) and
 * changes nothing.
 */
static inline void co_node_set_factory_id(co_node_t *node, uint8_t id)
{
    if (CO_CHECK(node->nmt.state == CO_NMT_INIT) && CO_CHECK(id >= 1u && id <= CO_NODE_ID_MAX)) {
        node->factory_id = id;
        node->node_id = id;
    }
}

/**
 * The serial number of this unit (0x1018 sub 4, the last part of its LSS
 * address, CiA 305), which the const table cannot hold: every instance of
 * a product needs its own, or LSS cannot address one of them. A board
 * calls it after co_node_init() and before co_node_start(), with a value
 * from the unit itself (a chip's unique ID, the Linux program's command
 * line): each node of a device its own. The product's 0x1018 sub 4 entry
 * (attribute CO_A_SERIAL) reads it; 0 where none was given (unit tests).
 * While the node runs, or serial
 * 0 (no serial), it is a broken contract (CO_CHECK) and changes nothing.
 */
static inline void co_node_set_serial(co_node_t *node, uint32_t serial)
{
    if (CO_CHECK(node->nmt.state == CO_NMT_INIT) && CO_CHECK(serial != 0u)) {
        node->serial = serial;
    }
}

/** The serial number co_node_set_serial() gave, 0: none. */
static inline uint32_t co_node_serial(const co_node_t *node)
{
    return node->serial;
}

/** The node's factory node-ID: co_node_set_factory_id()'s, else the config's. */
static inline uint8_t co_node_factory_id(const co_node_t *node)
{
    return node->factory_id != 0u ? node->factory_id : co_cfg(node)->default_node_id;
}

/** Reset at the next poll, after the answer to the current request went out. */
static inline void co_node_request_reset(co_node_t *node, co_reset_t kind)
{
    node->reset_request = (uint8_t)kind;
    co_node_wake(node);
}

/** Reset node or communication now (what the NMT commands do): the
 * product's reset hook runs, the boot-up is sent. From a write hook use
 * co_node_request_reset() instead, so that the answer goes out first. */
void co_node_reset(co_node_t *node, co_reset_t kind);

/**
 * One received frame f (copied from where it is needed; the caller keeps
 * f), at time now (us, the clock co_node_poll() gets): the time stamp of
 * what the frame starts (a guard request's life time, a heartbeat
 * consumer's timeout, an LSS switch delay). Answers go out through
 * co_port_can_send() before it returns; what the frame leaves to do (a
 * reset it asked for, a TPDO event) runs at the next co_node_poll(), which
 * is due at once. Frames the node does not serve are ignored.
 */
void co_node_receive(co_node_t *node, const co_frame_t *f, uint32_t now);

/**
 * Run timers; returns the delay (us) until the next call is needed. When
 * nothing happened since the last poll (no frame, no co_node_wake(), no
 * CAN state change) and no deadline has come, it returns at once.
 */
uint32_t co_node_poll(co_node_t *node, uint32_t now);

/** co_node_send's cold half: count a frame not sent; returns false. */
bool co_node_tx_drop(co_node_t *node);

/** Send through the port, counting frames the board could not queue; nothing
 * is sent while the controller is bus-off (counted the same way). Inline,
 * the count out of line: the call and its frame cost x86-64 more than the
 * bus-off gate adds (inline keeps the SDO read and the TPDO within their
 * targets). */
static inline bool co_node_send(co_node_t *node, const co_frame_t *f)
{
    if (node->can_state != CO_CAN_BUSOFF && co_port_can_send(node->port, f)) {
        return true;
    }
    return co_node_tx_drop(node);
}

/** The board's view of the CAN controller (LEDs, diagnostics): call it
 * from the main loop when it changes (no-op when unchanged); while
 * CO_CAN_BUSOFF the node sends nothing. The product's can_state hook
 * runs. */
void co_node_set_can_state(co_node_t *node, co_can_state_t s);

/** The patterns the two LEDs show now (CiA 303-3 mapping, product hook). */
void co_node_led_patterns(co_node_t *node, co_led_pattern_t *green, co_led_pattern_t *red);

/** Name of a pattern, for logs. */
const char *co_led_pattern_name(co_led_pattern_t p);

/**
 * LED levels at time now; *next_us receives the delay until either changes.
 */
void co_node_leds(co_node_t *node, uint32_t now, bool *green, bool *red, uint32_t *next_us);

/**
 * Write len bytes (little-endian) to entry e of the node's dictionary as an
 * SDO download does: co_od_write() (access, length, limits, write hook),
 * then, where the product stores every change (cfg->autosave), a save of
 * the entry's class made due: co_store_poll() stores it once the SDO
 * server has paused (co_store.h), so that the answer never waits for the
 * flash. Returns co_od_write()'s result. The SDO server writes through it,
 * so that the dictionary never calls the store (see the layering above).
 */
co_res_t co_node_write(co_node_t *node, const co_od_entry_t *e, const uint8_t *buf, uint32_t len);

/** One CAN-ID a node consumes (co_node_rx_ids). */
typedef struct co_rx_id {
    uint16_t id; /**< 11-bit CAN-ID */
    bool rtr;    /**< true: remote frames on it serve the node; false: data frames do
                  * (every service that takes data frames ignores remote ones) */
} co_rx_id_t;

/** Entries co_node_rx_ids() may fill: NMT, SYNC, SDO, LSS, guarding,
 * one heartbeat consumed, and a remote request per TPDO. */
#define CO_NODE_RX_IDS_MAX (6u + CO_TPDO_MAX)

/**
 * The CAN-IDs the node consumes now, for a board that filters what it
 * receives (a SocketCAN CAN_RAW_FILTER, a controller's acceptance
 * filters): NMT (0x000), the SYNC COB-ID (0x1005), the SDO request
 * (0x600 + node-ID; none while unconfigured, CO_LSS_UNCONFIGURED), the LSS
 * master (0x7E5, products with LSS), node guarding (0x700 + node-ID,
 * remote frames, where guarding is enabled), the remote request on each
 * valid TPDO whose COB-ID allows it (products with co_rtr_service) and
 * the heartbeat consumed (0x1016 sub 1, while its time and node-ID are
 * set). A frame on any other CAN-ID is ignored by co_node_receive(), so a
 * board may drop it. The list follows every change of a COB-ID or the
 * node-ID (SDO write, reset, LSS): a board asks again after each
 * co_node_receive() or co_node_poll() and compares. Writes up to max
 * entries to ids (owned by the caller) in a fixed order, no duplicates
 * (a CAN-ID with a data and a remote use, say a heartbeat consumed from
 * the node's own guarding ID, is there twice, once per kind: a board can
 * match each exactly, which a SocketCAN filter does in constant time);
 * returns the count (at most CO_NODE_RX_IDS_MAX: more than max means
 * the list was cut at max). Reads the node only, never blocks. In its own
 * file (node_rx.c), so that an image that does not call it does not link it.
 */
unsigned co_node_rx_ids(const co_node_t *node, co_rx_id_t *ids, unsigned max);

/** Convenience: look up an entry in the node's dictionary (NULL if absent). */
const co_od_entry_t *co_node_entry(const co_node_t *node, uint16_t index, uint8_t sub);

#endif /* CO_NODE_H */
