/** @file
 * co_progdl.h - CiA 302-3 program download: the objects 1F50h (program
 * data), 1F51h (program control), 1F56h (program identification) and
 * 1F57h (flash status), each an ARRAY with sub 0 = 1 and sub 1.
 *
 * Two sides, one object set; a product's table names one of them:
 *  - The loader side (CO_PROGDL_LOADER_ENTRIES): takes an image
 *    (co_image.h) over 1F50h:1 and writes it to the board's program area
 *    as it streams in, never whole in RAM. The bootloaders and the Linux
 *    program run it. It is an optional service (co_progdl_service) with
 *    co_node_cfg_t.sdo_domain = co_progdl_domain; its state is a
 *    co_progdl_t that the board owns and returns from co_port_progdl()
 *    (no field in co_node_t: an image without the loader pays no RAM).
 *  - The application side (CO_PROGDL_APP_ENTRIES): a product image that
 *    runs under a bootloader. No state, no service: 1F51h:1 reads 1
 *    (started), 1F56h:1 is CO_PROGRAM_ID, 1F57h:1 is 0; writing 0 to
 *    1F51h:1 hands over to the bootloader (co_port_prog_handover).
 *
 * The loader's state machine (1F51h:1 read: 0 stopped, 1 started, 3 no
 * program; 1F51h:1 write: 0 stop, 1 start, 3 clear; 2, reset, is refused
 * with 06090030h, as is any other value):
 *
 *     started --0--> stopped --3--> cleared --1F50h--> writing --end-->
 *     verifying (busy) --> verified (stopped) --1--> started
 *
 *  - Stop (0) while started: after its answer co_port_prog_stop(). While
 *    not started: nothing to do, answered OK.
 *  - Clear (3) only while not started and not busy, else 08000022h:
 *    co_port_prog_clear() invalidates the installed program (1F56h:1
 *    reads 0, 1F51h:1 reads 3, 1F57h status 0); its failure is 06060000h
 *    and status 5.
 *  - A download of 1F50h:1 only right after a clear (one download a
 *    clear: the pages it wrote must be erased again), else 08000022h and
 *    status 4 ("not cleared before write") where nothing was cleared;
 *    while started or busy 08000022h, the status untouched. The header
 *    is checked as soon as its CO_IMAGE_HDR_SIZE bytes are in: the format
 *    (co_image_parse, else status 2), the product and the board
 *    (co_port_prog_check: status 3 or 6), 1000h and 1018h:1-2 against the
 *    node's own dictionary (status 3), and the image's length against the
 *    bytes that arrive. Each refusal aborts the download with 08000020h;
 *    a flash write that fails with 06060000h and status 5. The CRC-32 is
 *    computed as the bytes stream: a mismatch at the end is 08000020h
 *    and status 3. Nothing installed is touched by a refusal (the clear
 *    did that already).
 *  - After the last byte's answer 1F57h is busy while the service
 *    re-reads the image from flash (co_port_prog_read) and checks its CRC
 *    again: a few co_node_poll()s, CO_PROGDL_VERIFY_STEP bytes each, so
 *    busy always ends. Then co_port_prog_commit() makes it the installed
 *    program: 1F56h:1 reads its program identification, 1F51h:1 reads 0
 *    (stopped), status 0. A mismatch, or a failure of either, is status 5
 *    and leaves no program (1F51h:1 reads 3).
 *  - Start (1) only with a verified program and not busy, else 08000022h
 *    (1F57h unchanged): after its answer co_port_prog_start(). While
 *    started: nothing to do, answered OK.
 * "After its answer": the write marks the action, co_node_poll() (the
 * service's poll) calls the port once the answer has gone out, as a reset
 * request does.
 *
 * Threading: main loop only, like the node (co_node.h).
 */
#ifndef CO_PROGDL_H
#define CO_PROGDL_H

#include "co_common.h"
#include "co_image.h"
#include "co_node.h"

/** The program identification an application image reports in 1F56h:1:
 * its build sets it (-DCO_PROGRAM_ID=...), the same number tools/mkimage
 * writes into the image's header. */
#ifndef CO_PROGRAM_ID
#define CO_PROGRAM_ID 1u
#endif

/** 1F51h:1, program control, as read. @{ */
#define CO_PROGDL_STOPPED 0u    /**< a valid program, not running */
#define CO_PROGDL_STARTED 1u    /**< the program runs */
#define CO_PROGDL_NO_PROGRAM 3u /**< no valid program installed */
/** @} */

/** 1F57h:1 bits 1-7, the flash status (bit 0 is busy). @{ */
#define CO_PROGDL_OK 0u           /**< no error */
#define CO_PROGDL_NO_VALID 1u     /**< no valid program */
#define CO_PROGDL_UNKNOWN 2u      /**< unknown data format (not an image's header) */
#define CO_PROGDL_FORMAT 3u       /**< format or CRC error (another device's image too) */
#define CO_PROGDL_NOT_CLEARED 4u  /**< written without a clear before */
#define CO_PROGDL_FLASH 5u        /**< flash write error */
#define CO_PROGDL_ADDRESS 6u      /**< address error: the image does not fit the area */
#define CO_PROGDL_SECURED 7u      /**< the flash is secured */
#define CO_PROGDL_UNSPECIFIED 63u /**< unspecified error */
/** @} */

/** Bytes of the image one co_node_poll() re-reads while verifying. */
#define CO_PROGDL_VERIFY_STEP 64u

/**
 * The loader side's state, owned by the board (co_port_progdl): keep it
 * where the board's main loop keeps its node. Its fields are the
 * service's; a board sets it up with co_progdl_init() and reads it through
 * the accessors below.
 */
typedef struct co_progdl {
    uint8_t state;                  /**< CO_PROGDL_STOPPED, _STARTED, _NO_PROGRAM */
    uint8_t status;                 /**< 1F57h bits 1-7: CO_PROGDL_OK and the codes above */
    uint8_t phase;                  /**< where the download is (progdl.c) */
    uint8_t pending;                /**< start or stop due once the answer is out */
    uint32_t program_id;            /**< 1F56h:1 */
    uint32_t pos;                   /**< bytes of the image written (verifying: re-read) */
    uint32_t crc;                   /**< co_crc32 of bytes CO_IMAGE_CRC_FROM .. pos - 1 */
    co_image_hdr_t hdr;             /**< the header, decoded once complete */
    uint8_t raw[CO_IMAGE_HDR_SIZE]; /**< the header's bytes while they arrive */
} co_progdl_t;

/**
 * Set pd up at the board's start, before co_node_start(): state is what
 * the board found (CO_PROGDL_STARTED: it runs the installed program, the
 * Linux program; CO_PROGDL_STOPPED: a bootloader with a valid program it
 * did not start; CO_PROGDL_NO_PROGRAM: none, status "no valid program"),
 * program_id that program's 1F56h:1 (0 with none). Another state: a
 * broken contract (CO_CHECK), taken as CO_PROGDL_NO_PROGRAM.
 */
void co_progdl_init(co_progdl_t *pd, uint8_t state, uint32_t program_id);

/** What 1F51h:1 reads. */
static inline uint8_t co_progdl_state(const co_progdl_t *pd)
{
    return pd->state;
}

/** What 1F57h:1 reads: the status in bits 1-7, busy in bit 0. */
uint32_t co_progdl_flash_status(const co_progdl_t *pd);

/** The loader side: verifies the image and starts or stops a program
 * after the answer (its poll). List it in co_node_cfg_t.services. */
extern const co_service_t co_progdl_service;

/** The loader side's 1F50h:1 (co_node_cfg_t.sdo_domain): takes the image
 * as the SDO server streams it (co_sdo_domain_fn). */
co_res_t co_progdl_domain(co_node_t *node, const co_od_entry_t *e, uint32_t at, const uint8_t *buf,
                          uint32_t len, bool end);

/** Dictionary hooks of the loader side (CO_PROGDL_LOADER_ENTRIES). @{ */
co_res_t co_progdl_write_control(co_node_t *node, const co_od_entry_t *e, uint32_t value);
co_res_t co_progdl_read_control(co_node_t *node, const co_od_entry_t *e, uint32_t *value);
co_res_t co_progdl_read_id(co_node_t *node, const co_od_entry_t *e, uint32_t *value);
co_res_t co_progdl_read_status(co_node_t *node, const co_od_entry_t *e, uint32_t *value);
/** @} */

/** The application side's 1F51h:1 write hook (CO_PROGDL_APP_ENTRIES): 0
 * hands over to the bootloader, 1 is OK (started already), 3 is
 * 08000022h, any other value 06090030h. */
co_res_t co_progdl_app_write_control(co_node_t *node, const co_od_entry_t *e, uint32_t value);

/**
 * The table lines, in index order (between 1F4xh and 1F8xh, or whatever a
 * table holds around them): a product's table puts one of these where
 * its 1F5xh objects go. Access: 1F50h:1 wo DOMAIN, 1F51h:1 rw U8, 1F56h:1
 * and 1F57h:1 ro U32. The loader side has every array's sub 0 (const U8
 * 1). The application side has sub 1 alone: the four sub 0 lines would
 * cost the DST X730 image 64 of the 192 bytes of flash the whole of its
 * side may take (tools/footprint.py), and no master reads them (CiA 302-2
 * names sub 1, the program's number, in every access); reading one is
 * 06090011h. @{
 */
/* clang-format off */
#define CO_PROGDL_SUB0_(idx, nm) \
    {.index = (idx), .sub = 0, CO_TYPE_U8, .attr = CO_A_R | CO_A_CONST, .def = 1, CO_NAME(nm)}
#define CO_PROGDL_APP_ENTRIES \
    {.index = 0x1F50, .sub = 1, CO_TYPE_DOMAIN, .attr = CO_A_W, CO_NAME("Program number 1")}, \
    {.index = 0x1F51, .sub = 1, CO_TYPE_U8, .attr = CO_A_RW, .def = CO_PROGDL_STARTED, \
     CO_EXT(.min = 0, .max = 3, .write = co_progdl_app_write_control), CO_NAME("Program number 1")}, \
    {.index = 0x1F56, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, .def = CO_PROGRAM_ID, \
     CO_NAME("Program number 1")}, \
    {.index = 0x1F57, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, .def = 0, CO_NAME("Program number 1")}
#define CO_PROGDL_LOADER_ENTRIES \
    CO_PROGDL_SUB0_(0x1F50, "Program data"), \
    {.index = 0x1F50, .sub = 1, CO_TYPE_DOMAIN, .attr = CO_A_W, CO_NAME("Program number 1")}, \
    CO_PROGDL_SUB0_(0x1F51, "Program control"), \
    {.index = 0x1F51, .sub = 1, CO_TYPE_U8, .attr = CO_A_RW, \
     CO_EXT(.write = co_progdl_write_control, .read = co_progdl_read_control), \
     CO_NAME("Program number 1")}, \
    CO_PROGDL_SUB0_(0x1F56, "Program software identification"), \
    {.index = 0x1F56, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, CO_EXT(.read = co_progdl_read_id), \
     CO_NAME("Program number 1")}, \
    CO_PROGDL_SUB0_(0x1F57, "Flash status identification"), \
    {.index = 0x1F57, .sub = 1, CO_TYPE_U32, .attr = CO_A_R, \
     CO_EXT(.read = co_progdl_read_status), CO_NAME("Program number 1")}
/* clang-format on */
/** @} */

/**
 * What a family's table puts where its 1F5xh objects go: the application
 * side in a product image for a board, which its bootloader runs (the MCU
 * images' build defines CO_PROGDL_APP: boards/CMakeLists.txt); nothing
 * elsewhere, so that the Linux program without its option, and the unit
 * tests of the manuals, keep exactly the manual's dictionary (the Linux
 * program adds the loader side at run time: boards/linux/prog.c). With a
 * trailing comma where it has lines.
 */
#ifdef CO_PROGDL_APP
#define CO_PROGDL_TABLE CO_PROGDL_APP_ENTRIES,
#else
#define CO_PROGDL_TABLE
#endif

#endif /* CO_PROGDL_H */
