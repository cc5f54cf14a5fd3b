/*
 * fuzz_format.h - the input format of the node harness (fuzz_node.c), shared
 * with the seed writer (fuzz_seeds.c).
 *
 * An input is a small program for a simulated board, read byte by byte;
 * multi-byte numbers are little-endian, and reading past the end gives
 * zeros (so every byte string is a valid input):
 *
 *   product   u8   index into product_list[], modulo its length
 *   clock     u8   start time: 0 = 1 s; 1 = 2^32 - u16 ms (just before the
 *                  32-bit microsecond wrap); 2 = u32 us; 3 = 2^31 - u16 ms
 *   images    u8   stored records in the EEPROM at power-on (modulo 9),
 *                  each: u8 what (bit 0 node, bit 1 LSS class, bit 2 slot,
 *                  bits 3.. kind), u8 sequence number, u8 write count
 *                  selector, then the kind's bytes (fuzz_node.c, put_image)
 *   ops...         until the input ends (at most FZ_MAX_OPS):
 *                  u8 op: bits 0..6 the FZ_OP_ code (modulo FZ_OP_COUNT),
 *                  bit 7 the node it addresses (the redundant GSH-A has two),
 *                  then the op's own bytes (fuzz_node.c, run_op)
 *
 * Frames always go to every node of the product (one bus).
 */
#ifndef FUZZ_FORMAT_H
#define FUZZ_FORMAT_H

/* The products the seed corpus was written for, by their selector byte
 * (an input's first byte): the harnesses take them by ID, in this order,
 * then every other product of the registry (fuzz_products.h), so the seeds
 * survive a new family; a product dropped from the registry stops them
 * (rewrite the seeds: tools/fuzz --seeds). */
#define FZ_PRODUCT_IDS                                                                             \
    "dst-x730-xy10", "dst-x730-xy15", "dst-x730-xy20", "dst-x730-xy30", "dst-x730-xy45",           \
        "dst-x730-xy60", "dst-x730-xy90", "dst-x730-z360", "dst-x710-xy10", "dst-x710-xy15",       \
        "dst-x710-xy20", "dst-x710-xy30", "dst-x710-xy45", "dst-x710-xy60", "dst-x710-xy90",       \
        "dst-x710-z360", "gsh-a", "gsh-a-redundant", "jd1xxx", "jd2xxx", "inx360d", "iny360d"
#define FZ_PRODUCT_COUNT 22u

#define FZ_MAX_OPS 512u
#define FZ_MAX_IMAGES 9u

/* Kinds of a stored record at power-on (bits 3.. of its first byte, modulo FZ_IMG_COUNT). */
enum {
    FZ_IMG_ENTRIES = 0, /* the defaults with some entries set (entry, value) x u8 % 4: valid CRC */
    FZ_IMG_BYTES,       /* the defaults with some bytes set (offset, byte) x u8 % 4: valid CRC */
    FZ_IMG_FLIPPED,     /* like FZ_IMG_ENTRIES, then one byte flipped (offset, xor) */
    FZ_IMG_DEFAULTS,    /* a "load" record (restore defaults) */
    FZ_IMG_RAW,         /* u8 length, then that many raw bytes from the slot's start */
    FZ_IMG_COUNT,
};

/* Ops (the byte after each name says what follows it). */
enum {
    FZ_OP_SDO_WRITE = 0, /* expedited download: target, value, command selector */
    FZ_OP_SDO_READ,      /* expedited upload request: target */
    FZ_OP_SDO_RAW,       /* u8 DLC selector, 8 bytes to the node's SDO server */
    FZ_OP_SDO_SEG_WRITE, /* segmented download: target, value, u8 sizes, u8 length, bytes, mangles
                          */
    FZ_OP_SDO_SEG_READ,  /* segmented upload: target, u8 segments, u8 mangle */
    FZ_OP_SDO_BLK_WRITE, /* block download: target, value, u8 flags, u8 length, bytes, u8 mangle */
    FZ_OP_SDO_BLK_READ,  /* block upload: target, u8 flags, u8 blksize, u8 rounds, per round 2 x u8
                          */
    FZ_OP_NMT,           /* u8 command selector, u8 target selector, [u8 DLC] */
    FZ_OP_SYNC,          /* u8 selector, u8 counter */
    FZ_OP_GUARD_RTR,     /* u8 DLC selector */
    FZ_OP_PDO_RTR,       /* u8 selector */
    FZ_OP_LSS,           /* u8 command selector, then the command's bytes */
    FZ_OP_LSS_SEQUENCE,  /* u8 kind, u8 node-ID selector, u8 bit timing */
    FZ_OP_HEARTBEAT,     /* another node's heartbeat: u8 producer, u8 state */
    FZ_OP_FRAME,         /* u16 id, u8 flags (bit 0 RTR, bits 1.. DLC % 9, bit 7 own id), 8 bytes */
    FZ_OP_STORE,         /* u8 kind (save, load, save-reset, node-ID or bit-rate commit), value */
    FZ_OP_ADVANCE,       /* u16 count, u8 unit: time passes, sampled every 5 ms */
    FZ_OP_ADVANCE_LONG,  /* u32 count, u8 unit: time passes, no samples (up to 2^34 us) */
    FZ_OP_INPUTS,        /* per input: u8 selector [u32 value] */
    FZ_OP_FAULTS,        /* u8 fault bits */
    FZ_OP_CAN_STATE,     /* u8 state (active, warning, passive, bus-off) */
    FZ_OP_TX_FULL,       /* u8 bit 0: the port's transmit queue refuses frames */
    FZ_OP_POWER_CYCLE,   /* power off and on (the EEPROM stays) */
    FZ_OP_POWER_CUT,     /* u16 bytes the EEPROM may still take, then the next op */
    FZ_OP_NVM_READ_FAIL, /* u8 bit 0: EEPROM reads fail (hardware error) */
    FZ_OP_COUNT,
};

/* Target of an SDO op: u8 entry number in the product's dictionary, or
 * 0xFF followed by u16 index and u8 sub-index. */
#define FZ_TARGET_RAW 0xFFu

/* Value selectors (u8, modulo FZ_VAL_COUNT), then the selector's bytes. */
enum {
    FZ_VAL_U32 = 0,        /* u32 */
    FZ_VAL_U8,             /* u8 */
    FZ_VAL_LIMIT,          /* the entry's min (bit 4 of the selector: max) + u8 % 5 - 2 */
    FZ_VAL_DEFAULT,        /* the entry's default */
    FZ_VAL_COBID,          /* u8 base, u8 CAN-ID part, u8 flag bits 29..31 */
    FZ_VAL_SIGNATURE,      /* u8: "save", "load", the JD's save-reset code, 0 */
    FZ_VAL_EXTREME,        /* u8: 0, 1, 0x7F, ... 0xFFFFFFFF */
    FZ_VAL_SMALL_NEGATIVE, /* u8 as int8 */
    FZ_VAL_NEAR,           /* the entry's current value + u8 as int8 */
    FZ_VAL_U16,            /* u16 */
    FZ_VAL_COUNT,
};

#endif /* FUZZ_FORMAT_H */
