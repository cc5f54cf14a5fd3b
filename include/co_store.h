/** @file
 * co_store.h - the parameter store: 0x1010 "save", 0x1011 "load", and the
 * non-volatile image in the board's EEPROM emulation (co_port_nvm_*).
 *
 * Each stored class (PARA, LSS) has two slots. A record is
 *   header { magic, layout hash, sequence, write count, length, flags }
 *   data   (the class's RAM struct, byte for byte)
 *   CRC-32 over header and data.
 * A save writes the slot that does not hold the newest valid record, with
 * sequence + 1, so a power cut at any point of a save leaves the previous
 * complete record valid. A restore first verifies both slots (reading from
 * NVM only), and only then copies the newest valid one into RAM; live
 * values are never touched by unverified data.
 * The layout hash is computed from the dictionary (index, sub-index, size
 * and offset of every entry of the class), so a firmware whose layout
 * differs treats an old image as invalid instead of misreading it.
 *
 * No SDO answer waits for a flash erase. The slot a save writes next holds
 * only what nothing reads again (the record the newest replaced, or a save
 * cut short), so the store offers it to the board to erase ahead
 * (co_port_nvm_prepare) while no answer is due: at power-on before the
 * boot-up, and after a save once no SDO or LSS request came for
 * CO_STORE_QUIET_US (co_store_poll; to any node of the same flash:
 * co_store_share_pause). A save's answer then waits for programming only. A
 * product that stores every write on its own (cfg->autosave) answers the
 * write when taken and stores it after that pause (co_node_write), one
 * record for a burst of writes. A request that arrives while such work
 * runs waits for it: the pause keeps a master's burst clear of it.
 *
 * Ownership and errors: the records live in the board's EEPROM from the
 * node's nvm_base on (CO_STORE_NVM_SIZE bytes: co_port.h), the live values
 * in the product's class structs; state is co_store_t in the node. Every
 * call is synchronous (the board's writes return when durable) and runs
 * in the main loop, never from an interrupt; only an autosave is put off
 * (co_store_poll), never a save a master asked for. A failed NVM access is never
 * retried: a read makes the class CO_STORE_HW (defaults in use), a write
 * answers CO_E_HW; a refused save (signature, write-cycle limit) answers
 * CO_E_STORE. cls must be CO_CLS_PARA or CO_CLS_LSS, and a class the
 * product stores (cfg->ram_size): another is answered CO_E_STORE (save) or
 * CO_STORE_BLANK (restore), nothing touched.
 */
#ifndef CO_STORE_H
#define CO_STORE_H

#include "co_common.h"
#include "co_image.h" /* co_crc32: a record's CRC is the program image's */
#include "co_od.h"

/** Bytes of one slot in NVM; a class's RAM struct must fit with the header. @{ */
#define CO_STORE_SLOT 192u
#define CO_STORE_HDR 24u
#define CO_STORE_MAX_DATA (CO_STORE_SLOT - CO_STORE_HDR - 4u)
/** @} */
/** NVM bytes one node needs (2 classes x 2 slots). */
#define CO_STORE_NVM_SIZE (4u * CO_STORE_SLOT)
/* Fixed sizes, not switches; what a change must keep: the header's 20
 * bytes (store.c writes magic .. class at its bytes 0..19), an even header
 * and slot (the flash EEPROM programs half-words from a slot's start,
 * flash_ee.h), room for data and the CRC, and a slot in the 1 KiB page of
 * the smallest flash (STM32F042: one slot a page). */
#if CO_STORE_HDR < 20 || CO_STORE_HDR % 2 != 0 || CO_STORE_SLOT % 2 != 0 ||                        \
    CO_STORE_SLOT < CO_STORE_HDR + 4 + 2 || CO_STORE_SLOT > 1024
#error "CO_STORE_HDR must be even and >= 20, CO_STORE_SLOT even, above header + CRC, <= 1024"
#endif

/** "save" and "load" signatures (CiA 301). @{ */
#define CO_SIG_SAVE 0x65766173u
#define CO_SIG_LOAD 0x64616F6Cu
/** @} */

/** What the last restore of a class found (co_store_restore, co_node_store_status). */
typedef enum co_store_status {
    CO_STORE_OK = 0,   /**< a valid record was applied */
    CO_STORE_BLANK,    /**< nothing ever stored: defaults */
    CO_STORE_DEFAULTS, /**< "load" was requested: defaults */
    CO_STORE_CORRUPT,  /**< the slots hold something (not erased) but no valid record:
                        * defaults; or the newest record passed its CRC but some
                        * values failed validation (co_od_validate): those are
                        * defaults. Stays until the next full save */
    CO_STORE_HW,       /**< NVM read failed: defaults */
} co_store_status_t;

/** How long the SDO server must have been quiet (no request) before the
 * store does work that can take a flash erase (co_store_poll): a master's
 * burst of requests, even one slowed by a loaded host, has shorter gaps,
 * so its answers never wait for the flash. */
#define CO_STORE_QUIET_US 200000u
/** The longest an autosaved write waits for a quiet SDO server: a master
 * that polls faster than CO_STORE_QUIET_US for longer than this gets one
 * answer late rather than the write left unstored. */
#define CO_STORE_DEFER_MAX_US 2000000u

/** Parameter store state in the node. */
typedef struct co_store {
    uint32_t writes;              /**< save cycles so far (from the newest record) */
    uint32_t sdo_at;              /**< time of the latest SDO or LSS request (co_node_receive) */
    uint32_t due_at;              /**< time the oldest autosaved write not yet stored was taken */
    uint8_t status[CO_CLS_COUNT]; /**< co_store_status_t of the last restore */
    uint8_t due;                  /**< work put off (CO_STORE_DUE_SAVE, CO_STORE_DUE_SPARE) */
} co_store_t;

/** co_store_t.due: bit cls, an autosaved write of class cls waits to be
 * stored; bit cls + 4, the slot the next save of cls writes may hold an
 * old record (co_port_nvm_prepare). @{ */
#define CO_STORE_DUE_SAVE(cls) (1u << (cls))
#define CO_STORE_DUE_SPARE(cls) (16u << (cls))
/** @} */

/** Scan the NVM for the write count, and let the board erase ahead the
 * slot each class's next save writes (co_port_nvm_prepare). Call once, on
 * a node fresh from co_node_init(), before the first restore and before
 * the node is on the bus (co_node_start does): an erase there delays the
 * boot-up, never an answer. */
void co_store_init(co_node_t *node);

/**
 * The store's work put off until the SDO server has been quiet for
 * CO_STORE_QUIET_US (co_store_t.sdo_at): an autosaved write (co_node_write
 * on a product with cfg->autosave) stored, then the slot the next save of
 * a class writes offered to the board to erase ahead (co_port_nvm_prepare).
 * One step a call, so that a request received in between is answered
 * before the next. Returns the time until it wants to run again
 * (co_node_poll). A deferred save that fails leaves the value in use and
 * the class reported as CO_STORE_HW (the product's data-set error).
 */
uint32_t co_store_poll(co_node_t *node, uint32_t now);

/** Nodes that share one flash (the two nodes of a redundant device in one
 * image) share one pause: an erase ahead blocks the processor, so one
 * node's erase would delay the other node's answers. Call it, with every
 * such node, after a frame has been given to each of them and before any
 * is polled (boards/common/mcu_main.c): a request to one restarts the wait
 * of all. */
void co_store_share_pause(co_node_t *const nodes[], unsigned n);

/** Store now what co_store_poll() would store later (autosaved writes):
 * before a reset, which restores from the NVM, and at a board's orderly
 * stop. A power cut before it loses those writes; the stored sets stay
 * whole (the old ones). */
void co_store_flush(co_node_t *node);

/**
 * Restore the entries of class cls with index in [lo, hi] from the newest
 * valid record, or set them to their defaults; [0, 0xFFFF] restores the
 * whole struct (the LSS struct has no dictionary entries of its own).
 * Returns and remembers why. A record passed its CRC (CO_STORE_OK): its
 * values must then pass co_store_validate() before anything uses them
 * (co_node_reset does it; two calls, so that the restore's frame is off
 * the stack while the write hooks run).
 */
co_store_status_t co_store_restore(co_node_t *node, co_cls_t cls, uint16_t lo, uint16_t hi);

/**
 * Run every value of class cls through co_od_validate(), as an SDO write of it
 * would be checked; one that fails takes its default, and the set is
 * reported as corrupt (status CO_STORE_CORRUPT) until the next full save.
 */
void co_store_validate(co_node_t *node, co_cls_t cls);

/**
 * Save the RAM struct of class cls. Returns CO_OK, CO_E_STORE when the
 * write-cycle limit is reached, CO_E_HW when the NVM write failed.
 */
co_res_t co_store_save(co_node_t *node, co_cls_t cls);

/**
 * Save one CiA 301 group of class cls: entries with index in [lo, hi] from
 * RAM (defaults = false) or as their defaults (true: a group "load"); the
 * class's other entries keep their stored values. Same results as
 * co_store_save(). Used by 0x1010 / 0x1011 sub 2 (0x1000-0x1FFF), sub 3
 * (0x6000-0x9FFF) and sub 4 (0x2000-0x5FFF).
 */
co_res_t co_store_save_group(co_node_t *node, co_cls_t cls, uint16_t lo, uint16_t hi,
                             bool defaults);

/**
 * A value of the restored set of cls that only the product can judge (the
 * DST's bit-rate code, kept without a dictionary entry) failed: the product
 * set it to its default; the set is reported as corrupt, like one whose
 * values fail co_od_validate(), until the next full save. cls must be
 * CO_CLS_PARA or CO_CLS_LSS: another is a broken contract (CO_CHECK) and
 * changes nothing.
 */
void co_store_mark_corrupt(co_node_t *node, co_cls_t cls);

/**
 * Keep EMCY 6300h ("data set", CiA 301) active in the error table while the
 * last restore of PARA or LSS found a corrupt set or could not read the
 * NVM, and clear it once a full save made the set sound again. For the
 * products whose manuals name no other report of their own (the DST has
 * 0x4001): call it from the product's poll hook; it only acts while EMCY
 * may be sent (pre-operational, operational), so no report is lost.
 */
void co_store_report_emcy(co_node_t *node);

/** Make the next restore of cls use defaults (0x1011 "load"). */
co_res_t co_store_request_defaults(co_node_t *node, co_cls_t cls);

/** Write-cycle limit reached: further saves are refused. */
bool co_store_limit_reached(const co_node_t *node);

/** Layout hash of class cls in the node's dictionary. */
uint32_t co_store_layout_hash(const co_node_t *node, co_cls_t cls);

/**
 * Write hook for 0x1010 sub 1 "save all parameters": value must be the
 * signature "save" (CO_SIG_SAVE), else CO_E_STORE. Stores PARA, and LSS
 * where cfg->save_includes_lss and it changed; results of co_store_save().
 * On success the product's stored hook (co_node_ops_t.stored) runs.
 */
co_res_t co_store_write_save(co_node_t *node, const co_od_entry_t *e, uint32_t value);
/**
 * Write hook for 0x1011 sub 1 "restore default parameters": value must be
 * "load" (CO_SIG_LOAD), else CO_E_STORE. Makes the next restore of PARA
 * (and of LSS, unless cfg->load_keeps_lss) use defaults: the values in use
 * stay until the next reset. Then the stored hook, as for "save".
 */
co_res_t co_store_write_load(co_node_t *node, const co_od_entry_t *e, uint32_t value);
/** Write hook for 0x1010 sub 2..4: "save" of one CiA 301 group
 * (co_store_save_group; LSS too where cfg->save_includes_lss). Another
 * signature, or another sub-index: CO_E_STORE. */
co_res_t co_store_write_group_save(co_node_t *node, const co_od_entry_t *e, uint32_t value);
/** Write hook for 0x1011 sub 2..4: "load" of one group: its entries are
 * stored as their defaults, the others keep their stored values. Same
 * errors as the group save. */
co_res_t co_store_write_group_load(co_node_t *node, const co_od_entry_t *e, uint32_t value);

#endif /* CO_STORE_H */
