/** @file
 * co_od.h - the object dictionary.
 *
 * A product's dictionary is a const table of co_od_entry_t sorted by
 * (index, sub-index); it lives in flash. Values live in RAM structs that the
 * product owns, one struct per storage class (co_cls_t). An entry names its
 * class and the byte offset of its value in that struct, so the same const
 * table serves any number of nodes: each node carries its own struct
 * pointers (co_node_t.ram).
 *
 * An entry without RAM (CO_CLS_NONE) is a constant: its value is .def, or
 * the bytes at .cdata for strings, unless a read hook computes it.
 *
 * Every function returns a co_res_t whose value is the SDO abort code.
 *
 * Ownership: the tables and their ext and string data are const and
 * outlive every node using them; entries returned by co_od_find() point
 * into them. The RAM structs are the product's (co_node_init). Nothing
 * here keeps state of its own, allocates or blocks; the functions taking
 * a node must not run from an interrupt. An entry pointer must come from
 * the node's own table (co_od_find, co_node_entry): the functions trust
 * its class, offset and size. Table sizes and offsets are checked when the
 * table is compiled (CO_AT: an offset over 255 does not build).
 * The dictionary calls no protocol module: the hooks a table names do
 * (co_node.h, the layering).
 */
#ifndef CO_OD_H
#define CO_OD_H

#include "co_common.h"

/** The node object (co_node.h). */
typedef struct co_node co_node_t;
/** One entry of a dictionary table (struct co_od_entry). */
typedef struct co_od_entry co_od_entry_t;

/** CiA 301 data type indices (as used in EDS files). */
typedef enum co_type {
    CO_T_BOOL = 0x01,
    CO_T_I8 = 0x02,
    CO_T_I16 = 0x03,
    CO_T_I32 = 0x04,
    CO_T_U8 = 0x05,
    CO_T_U16 = 0x06,
    CO_T_U32 = 0x07,
    CO_T_VSTR = 0x09,
    CO_T_DOMAIN = 0x0F, /**< bytes of any length, streamed (co_node_cfg_t.sdo_domain) */
} co_type_t;

/** Attribute bits of an entry. */
enum {
    CO_A_R = 0x01, /**< readable */
    CO_A_W = 0x02, /**< writable */
    CO_A_RW = 0x03,
    CO_A_CONST = 0x04,  /**< never changes (EDS "const"); combine with CO_A_R */
    CO_A_PDO = 0x08,    /**< may be mapped into a TPDO */
    CO_A_NODEID = 0x10, /**< a COB-ID whose default follows the node-ID (below) */
    CO_A_SERIAL = 0x20, /**< 0x1018 sub 4: the unit's serial (co_node_set_serial; .def 0) */
};

/** Storage classes: which RAM struct holds the value, and what stores it. */
typedef enum co_cls {
    CO_CLS_NONE = 0, /**< no RAM: constant or computed by a read hook */
    CO_CLS_VOL = 1,  /**< RAM only, back to its default at every reset */
    CO_CLS_PARA = 2, /**< stored by 0x1010 "save", restored by 0x1011 "load" */
    CO_CLS_LSS = 3,  /**< node-ID / bit rate: stored by the product itself */
    CO_CLS_COUNT = 4,
} co_cls_t;

/**
 * Write hook: called instead of the plain store after access, length and
 * range checks passed. It may validate further, act, and call co_od_store()
 * to keep the value. A hook of a stored entry (class PARA or LSS) also
 * serves co_od_validate(), which hands it the value the entry holds
 * already: while co_od_checking(node), co_od_store() stores nothing, and
 * the hook must return (CO_OK or the abort code) before any rule of
 * sequence ("invalidate the PDO first") and any action that is not a mere
 * repetition (re-reading a configuration from RAM is one; a preset that
 * computes an offset from the measurement is not). Read hook: computes
 * the value of a numeric entry.
 *
 * How hooks are named, everywhere (stack and products):
 *  - a dictionary hook is `<module>_write_<object>` or `<module>_read_<object>`:
 *    the access, then the object it serves (co_tpdo_write_map for 0x1A00,
 *    co_hb_write_time for 0x1017, co_emcy_read_hist, dst_read_slope);
 *  - a function that implements a field of co_node_ops_t or co_service_t
 *    is `<module>_<field>`, a qualifier after it where the module has two
 *    (dst_reset, jd_lss_store, co_guard_poll, co_hbc_reset,
 *    co_tpdo_receive_rtr), and a product_t's are `<family>_create` and
 *    `<family>_sample`. @{
 */
typedef co_res_t (*co_od_write_fn)(co_node_t *node, const co_od_entry_t *e, uint32_t value);
typedef co_res_t (*co_od_read_fn)(co_node_t *node, const co_od_entry_t *e, uint32_t *value);
/** @} */

/** What few entries have: limits and hooks. Behind one pointer so that the
 * many plain entries cost 16 bytes of flash each on a 32-bit MCU. */
typedef struct co_od_ext {
    /** Inclusive limits, checked when min != max. @{ */
    int32_t min, max;
    /** @} */
    co_od_write_fn write; /**< write hook, or NULL */
    co_od_read_fn read;   /**< read hook, or NULL */
} co_od_ext_t;

/** One object or sub-object of a dictionary: one line of a product's table. */
struct co_od_entry {
    uint16_t index; /**< object index */
    uint8_t sub;    /**< sub-index */
    uint8_t type;   /**< co_type_t */
    uint8_t attr;   /**< CO_A_* */
    uint8_t cls;    /**< co_cls_t */
    uint8_t size;   /**< bytes: 1, 2 or 4 for numbers, string length (< 256) */
    uint8_t off;    /**< offset of the value in the class's RAM struct (< 256) */
    union {
        uint32_t def;      /**< default / constant value (numbers) */
        const void *cdata; /**< constant bytes (strings) */
    };
    const co_od_ext_t *ext; /**< limits and hooks, NULL: none */
#ifndef CO_OD_NO_NAMES
    const char *name; /**< the manual's name, for people and EDS files */
#endif
};

/** An entry's write hook, NULL when it has none (no ext, or none there). */
static inline co_od_write_fn co_od_write_hook(const co_od_entry_t *e)
{
    return e->ext != NULL ? e->ext->write : NULL;
}

/** An entry's read hook, NULL when it has none. */
static inline co_od_read_fn co_od_read_hook(const co_od_entry_t *e)
{
    return e->ext != NULL ? e->ext->read : NULL;
}

/** A product's dictionary: the table and its length. */
typedef struct co_od {
    const co_od_entry_t *entries; /**< sorted by (index, sub-index) */
    uint16_t count;               /**< entries in the table */
} co_od_t;

/**
 * COB-IDs that follow the node-ID (CO_A_NODEID): the RAM value holds the
 * base (such as 0x80 for EMCY) while the CAN-ID part equals the base of the
 * default, and the node-ID is added on every read. A master writing
 * "base + current node-ID" is stored as the base again, so a saved default
 * COB-ID follows a later node-ID change (CiA 301 behaviour).
 * A master writing the base itself (0x80 for EMCY: a legal CAN-ID) means
 * that CAN-ID, not "follow the node-ID": it is kept with CO_COBID_ABS, a
 * bit no COB-ID write accepts (11-bit IDs: bits 11..28 are zero), so it
 * reads back and acts as written. Records stored before the flag existed
 * never hold it, and read as they always did.
 */
#define CO_COBID_ABS 0x10000000u

/** The COB-ID a CO_A_NODEID entry stands for: raw (the RAM value) with the
 * node-ID added while its CAN-ID part is the default's base, as written
 * (CO_COBID_ABS dropped) when it holds the flag, else raw itself. */
uint32_t co_cobid_resolve(uint32_t raw, uint32_t def, uint8_t node_id);

/** CiA 301 7.3.5 restricted CAN-IDs (NMT, SDO, LSS, NMT error control, ...):
 * no configurable COB-ID (SYNC, EMCY, PDO) may use one. */
bool co_cobid_restricted(uint32_t id);

/**
 * The value rules every COB-ID object shares (CiA 301 7.5.2): bit 29 (a
 * 29-bit frame) and bits 11..28 zero, since this stack speaks 11-bit CAN-IDs
 * only; bit 30 only where the object gives it a meaning this node supports
 * (bit30_ok: a TPDO's "no RTR"; never SYNC's "generate", nor EMCY's
 * reserved bit); and a CAN-ID that is not restricted, unless bit 31 marks
 * the object invalid (bit31_invalid: EMCY, PDO; SYNC's bit 31 means
 * nothing). CO_OK or CO_E_VAL (0x06090030).
 */
co_res_t co_cobid_check(uint32_t value, bool bit30_ok, bool bit31_invalid);

/**
 * Find (index, sub). Returns the entry, or NULL with *res set to
 * CO_E_NO_OBJ (no such index) or CO_E_NO_SUB (index exists, sub does not).
 * Binary search: O(log n). res may be NULL.
 */
const co_od_entry_t *co_od_find(const co_od_t *od, uint16_t index, uint8_t sub, co_res_t *res);

/**
 * Read a numeric entry's value (zero- or sign-extended to 32 bits) the way
 * the bus sees it, read hook and node-ID resolution included. Does not
 * check read access (the stack's own reads use it too).
 */
co_res_t co_od_get(co_node_t *node, const co_od_entry_t *e, uint32_t *value);

/**
 * Copy up to cap bytes of the entry's value, starting at byte offset 'at',
 * into buf (little-endian). *len receives the number of bytes copied.
 * Checks read access. Used by the SDO server for all sizes.
 */
co_res_t co_od_read(co_node_t *node, const co_od_entry_t *e, uint32_t at, uint8_t *buf,
                    uint32_t cap, uint32_t *len);

/**
 * Write len bytes (little-endian) to the entry as an SDO download does:
 * checks write access, length (too high / too low), limits, then calls the
 * write hook or stores the value.
 */
co_res_t co_od_write(co_node_t *node, const co_od_entry_t *e, const uint8_t *buf, uint32_t len);

/**
 * Check, without acting, that the value the numeric entry e holds in RAM
 * could be written to it by SDO: the limits, then the write hook in check
 * mode (see co_od_write_fn); a read-only entry's limits too, where it has
 * any. A value that fails is replaced by the entry's default, and false
 * returned; entries without RAM and strings pass. Every default of a
 * product's table must pass (tests/unit/test_hardening.c checks them
 * all). The parameter store runs every restored value through it
 * (co_store_validate).
 */
bool co_od_validate(co_node_t *node, const co_od_entry_t *e);

/** Plain store of a numeric value into the entry's RAM (no checks, no hook). */
co_res_t co_od_store(co_node_t *node, const co_od_entry_t *e, uint32_t value);

/** The RAM bytes (native order, e->size of them) of value for entry e. */
void co_od_native(const co_od_entry_t *e, uint32_t value, uint8_t *out);

/** Set every entry of class cls whose index is in [lo, hi] to its default. */
void co_od_defaults(co_node_t *node, co_cls_t cls, uint16_t lo, uint16_t hi);

/** Size in bytes of an entry's value as seen on the bus. */
static inline uint32_t co_od_size(const co_od_entry_t *e)
{
    return e->size;
}

/**
 * Table-building helpers for od/ files: one entry a line, designated
 * initializers, the manual's names. @{
 */
#define CO_TYPE_U8 .type = CO_T_U8, .size = 1
#define CO_TYPE_U16 .type = CO_T_U16, .size = 2
#define CO_TYPE_U32 .type = CO_T_U32, .size = 4
#define CO_TYPE_I8 .type = CO_T_I8, .size = 1
#define CO_TYPE_I16 .type = CO_T_I16, .size = 2
#define CO_TYPE_I32 .type = CO_T_I32, .size = 4
#define CO_TYPE_STR(s) .type = CO_T_VSTR, .size = sizeof(s) - 1u, .cdata = (s)
/** A DOMAIN: no value of its own; a download streams to co_node_cfg_t.sdo_domain. */
#define CO_TYPE_DOMAIN .type = CO_T_DOMAIN, .size = 0
/** @} */
/** The manual's name of an entry, always its last field. The names serve
 * people and EDS files; an MCU image that prints no EDS builds with
 * CO_OD_NO_NAMES, where entries have no name (about 30 bytes of flash less
 * per entry) and CO_NAME leaves a trailing comma. */
#ifdef CO_OD_NO_NAMES
#define CO_NAME(s)
#else
#define CO_NAME(s) .name = (s)
#endif
/** Value stored in field f of RAM struct T of class c. No cast: an offset
 * beyond 255 does not fit .off, which the compiler refuses (-Woverflow). */
#define CO_AT(c, T, f) .cls = (c), .off = offsetof(T, f)
/** Limits and hooks: CO_EXT(.min = 1, .max = 127, .write = fn). A compound
 * literal at file scope: a constant in flash next to the table. */
/* clang-format off */
#define CO_EXT(...) .ext = &(const co_od_ext_t){__VA_ARGS__}
/* clang-format on */

#endif /* CO_OD_H */
