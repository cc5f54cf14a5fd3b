/** @file
 * co_common.h - types shared by every module of the CANopen slave stack.
 *
 * Conventions used throughout the stack:
 *  - Every state lives in a co_node_t the caller owns; nothing in src/ is a
 *    mutable file-level variable, so several nodes run in one process.
 *  - No heap. All storage is supplied by the caller.
 *  - Time is an argument: poll functions take the current time in
 *    microseconds (a free-running, wrapping uint32_t) and return the delay
 *    in microseconds until they next need to run (CO_NEVER: no deadline).
 *  - Results are co_res_t; each value maps one-to-one to a CiA 301 SDO
 *    abort code (co_res_abort_code()).
 */
#ifndef CO_COMMON_H
#define CO_COMMON_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

/** One classic CAN frame (11-bit identifier). Word aligned (still 12 bytes):
 * the compiler then copies a frame with three word loads and stores instead
 * of a call to memcpy, which the bare-metal images have as a byte loop
 * (libc_min.c): on the Cortex-M0 each frame handed to the port costs 77
 * instructions in that loop. */
typedef struct co_frame {
    _Alignas(4) uint16_t id; /**< 11-bit CAN identifier */
    uint8_t dlc;             /**< 0..8 */
    bool rtr;                /**< remote transmission request */
    uint8_t data[8];         /**< the data bytes, dlc of them used */
} co_frame_t;

/** State of the CAN controller as the board reports it. */
typedef enum co_can_state {
    CO_CAN_ACTIVE = 0,
    CO_CAN_WARNING, /**< an error counter reached the warning limit (96) */
    CO_CAN_PASSIVE,
    CO_CAN_BUSOFF,
} co_can_state_t;

/** Keep a function out of its callers: its locals then share the stack with
 * its siblings' instead of adding to the caller's frame (store.c). */
#if defined(__GNUC__)
#define CO_NOINLINE __attribute__((noinline))
#else
#define CO_NOINLINE
#endif

/** A word that may alias any object (GCC, clang): for the compare done a
 * word at a time on an object of another type (co_incl.h). Other
 * compilers take the memcmp path there. */
#if defined(__GNUC__)
typedef uint32_t __attribute__((may_alias)) co_word_t;
#endif

/**
 * Programming errors: a caller breaking a function's documented contract
 * (an index past a table, a size switch out of range is an `#error` instead).
 * CO_CHECK(cond) is cond, for an if that leaves the function the way its
 * header documents for the invalid argument (nothing done, or an error
 * result): defined behaviour in every build, no crash in an image. Where the
 * build defines CO_ASSERT_HOOK (the unit tests, the fuzzers) a false cond
 * also calls co_assert_failed(), which the test harness counts as a failed
 * check unless the test expects it (tests/unit/harness.h, h_expect_assert).
 *     if (!CO_CHECK(n < CO_TPDO_MAX)) { return CO_E_PARAM; }
 */
#ifdef CO_ASSERT_HOOK
/** Provided by the build that defines CO_ASSERT_HOOK (the unit tests'
 * harness, the fuzzers), never by the stack: a CO_CHECK failed, cond is its
 * text (static), file and line where. If it returns, the check's caller
 * leaves the way its header documents. */
void co_assert_failed(const char *cond, const char *file, int line);
#define CO_CHECK(cond) ((cond) ? true : (co_assert_failed(#cond, __FILE__, __LINE__), false))
#else
#define CO_CHECK(cond) ((cond) ? true : false)
#endif

/** The highest node-ID: CiA 301's node-IDs are 1..CO_NODE_ID_MAX. */
#define CO_NODE_ID_MAX 127u

/** "No deadline" returned by poll functions. */
#define CO_NEVER UINT32_MAX

/** Wrap-safe comparison of two microsecond time stamps: a is before b. */
static inline bool co_time_before(uint32_t a, uint32_t b)
{
    return (int32_t)(a - b) < 0;
}

/** Delay from now until deadline, 0 if it has passed. */
static inline uint32_t co_time_until(uint32_t now, uint32_t deadline)
{
    return co_time_before(now, deadline) ? deadline - now : 0u;
}

/** The smaller of a and b. */
static inline uint32_t co_min_u32(uint32_t a, uint32_t b)
{
    return a < b ? a : b;
}

/** @name Little-endian helpers
 * CANopen is little-endian on the bus; p points to 2 or 4 bytes, any
 * alignment. @{ */

/** The 16-bit value at p. */
static inline uint16_t co_get_u16(const uint8_t *p)
{
    return (uint16_t)(p[0] | (uint16_t)(p[1] << 8));
}

/** The 32-bit value at p. */
static inline uint32_t co_get_u32(const uint8_t *p)
{
    return (uint32_t)p[0] | ((uint32_t)p[1] << 8) | ((uint32_t)p[2] << 16) | ((uint32_t)p[3] << 24);
}

/** v into the 2 bytes at p. */
static inline void co_put_u16(uint8_t *p, uint16_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
}

/** v into the 4 bytes at p. */
static inline void co_put_u32(uint8_t *p, uint32_t v)
{
    p[0] = (uint8_t)v;
    p[1] = (uint8_t)(v >> 8);
    p[2] = (uint8_t)(v >> 16);
    p[3] = (uint8_t)(v >> 24);
}
/** @} */

/**
 * Result of an object-dictionary access or service call. The values are
 * the CiA 301 SDO abort codes themselves, so the mapping is one-to-one and
 * lives in exactly one place: this enum.
 */
typedef enum co_res {
    CO_OK = 0,
    CO_E_TOGGLE = 0x05030000,   /**< toggle bit not alternated */
    CO_E_TIMEOUT = 0x05040000,  /**< SDO protocol timed out */
    CO_E_CMD = 0x05040001,      /**< client/server command specifier invalid */
    CO_E_BLKSIZE = 0x05040002,  /**< invalid block size */
    CO_E_SEQNO = 0x05040003,    /**< invalid sequence number */
    CO_E_CRC = 0x05040004,      /**< CRC error (block mode) */
    CO_E_OOM = 0x05040005,      /**< out of memory */
    CO_E_UNSUPP = 0x06010000,   /**< unsupported access to an object */
    CO_E_WO = 0x06010001,       /**< attempt to read a write-only object */
    CO_E_RO = 0x06010002,       /**< attempt to write a read-only object */
    CO_E_NO_OBJ = 0x06020000,   /**< object does not exist */
    CO_E_NO_MAP = 0x06040041,   /**< object cannot be mapped to the PDO */
    CO_E_MAP_LEN = 0x06040042,  /**< mapped objects exceed PDO length */
    CO_E_PARAM = 0x06040043,    /**< general parameter incompatibility */
    CO_E_HW = 0x06060000,       /**< access failed due to a hardware error */
    CO_E_LEN = 0x06070010,      /**< data type / length does not match */
    CO_E_LEN_HIGH = 0x06070012, /**< length of service parameter too high */
    CO_E_LEN_LOW = 0x06070013,  /**< length of service parameter too low */
    CO_E_NO_SUB = 0x06090011,   /**< sub-index does not exist */
    CO_E_VAL = 0x06090030,      /**< invalid value for parameter */
    CO_E_VAL_HIGH = 0x06090031, /**< value of parameter written too high */
    CO_E_VAL_LOW = 0x06090032,  /**< value of parameter written too low */
    CO_E_GENERAL = 0x08000000,  /**< general error */
    CO_E_STORE = 0x08000020,    /**< data cannot be transferred or stored */
    CO_E_LOCAL = 0x08000021,    /**< ... because of local control */
    CO_E_STATE = 0x08000022,    /**< ... because of the present device state */
    CO_E_NO_DATA = 0x08000024,  /**< no data available */
} co_res_t;

/** The SDO abort code of a result (CO_OK gives 0). */
static inline uint32_t co_res_abort_code(co_res_t r)
{
    return (uint32_t)r;
}

#endif /* CO_COMMON_H */
