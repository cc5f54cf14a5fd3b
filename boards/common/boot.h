/*
 * boot.h - the bootloader of the MCU boards and its hand-over with the
 * application (docs/program-download.md, "Bootloaders and flash layouts").
 *
 * The bootloader (boot_main.c) speaks NMT, heartbeat, SDO and the loader
 * side of program download only, with progdl.c's answers, in the 4 KiB
 * of a Cortex-M0. It runs
 * under the installed product's node-ID, bit rate and identity, which it
 * takes, best first, from:
 *  1. the hand-over block (boot_handover_t): RAM at a fixed address (each
 *     board's link scripts name it boot_handover_block), written by the
 *     application just before it resets into the bootloader on
 *     1F51h:1 = 0 (stop): its node-ID and bit rate. The identity (1000h,
 *     1018h:1-3, the product ID) is the installed image's header's, which
 *     the download checked against the application's own dictionary, and
 *     1018h:4 is the board's serial number (board_serial): the block
 *     carries no more, so that the application pays little flash for it;
 *  2. the boot-info record (boot_ident_t), one flash page of its own,
 *     which the bootloader writes from a hand-over whose identity it does
 *     not hold yet, before anything of the application is erased: a power
 *     cut in the middle of an update leaves a bootloader that still
 *     answers with the product's 1000h and 1018h, as a CiA 302-2 master
 *     wants before it downloads again;
 *  3. neither (a board that was never updated and holds no valid
 *     application): node-ID BOOT_DEFAULT_ID at BOOT_DEFAULT_KBPS, identity
 *     0.
 * Each carries a magic (the boot-info record also a CRC-32), so that RAM
 * left from a power-on or a page half written reads as none.
 */
#ifndef BOOT_H
#define BOOT_H

#include <stddef.h>

#include "co_common.h"
#include "co_image.h"
#include "co_node.h"
#include "flash_ee.h"

#define BOOT_HANDOVER_MAGIC 0x4F564448u /* "HDVO": the hand-over block */
#define BOOT_INFO_MAGIC 0x464E4942u     /* "BINF": the boot-info record */
#define BOOT_DEFAULT_ID 127u            /* a blank board's node-ID (CiA 301's last) */
#define BOOT_DEFAULT_KBPS 250u          /* and bit rate (CiA 301's default) */

/* The hand-over block: what the application leaves in RAM for the
 * bootloader (boot_handover_poll). */
typedef struct boot_handover {
    uint32_t magic;  /* BOOT_HANDOVER_MAGIC */
    uint8_t node_id; /* the active node-ID, 1..127 */
    uint8_t pad;     /* 0 */
    uint16_t kbps;   /* the active bit rate, kbit/s */
} boot_handover_t;

/* Where the application writes its hand-over and the bootloader reads
 * it: RAM at a fixed address (each board's link scripts place it; the
 * host's unit tests define it). */
extern boot_handover_t boot_handover_block;

/* Whether h holds a hand-over: the magic, a node-ID of 1..127 and a bit
 * rate. No check word: RAM that a power-on left holds the 32-bit magic
 * by chance once in 2^32, and the block is written whole right before
 * the reset (its flash cost counts in the DST X730's budget). */
bool boot_handover_valid(const boot_handover_t *h);

/* What the bootloader runs as, kept in its boot-info page (boot_main.c).
 * Little-endian words, 4-aligned. */
typedef struct boot_ident {
    uint32_t magic;           /* BOOT_HANDOVER_MAGIC or BOOT_INFO_MAGIC */
    uint32_t device_type;     /* 1000h */
    uint32_t vendor;          /* 1018h:1 */
    uint32_t product;         /* 1018h:2 */
    uint32_t revision;        /* 1018h:3 */
    uint32_t serial;          /* 1018h:4 */
    uint8_t node_id;          /* the active node-ID, 1..127 */
    uint8_t pad;              /* 0 */
    uint16_t kbps;            /* the active bit rate, kbit/s */
    char id[CO_IMAGE_ID_LEN]; /* product ID, from the installed image's header */
    uint32_t crc;             /* co_crc32 of the bytes before it */
} boot_ident_t;

/* Bytes of boot_ident_t covered by its CRC. */
#define BOOT_IDENT_CRC_LEN ((uint32_t)offsetof(boot_ident_t, crc))

/* ---- What a board provides to the bootloader -------------------------------
 * One line each; none is called from an interrupt. */

/* The application area: an image (header, then payload) from its base,
 * erased a page at a time, pages the pages of the area (flash_ee.h's
 * description reused: ops, ctx, base, page_size, pages). NULL: the board
 * has no flash for it (the bootloader then holds no program). */
const flash_ee_t *board_boot_area(void);
/* The boot-info page: its first page only. NULL: none. */
const flash_ee_t *board_boot_info(void);
/* Whether h (an image header, its format checked) is for this board:
 * CO_PROGDL_OK; CO_PROGDL_FORMAT for another board's code;
 * CO_PROGDL_ADDRESS for a load address the board does not run from or a
 * length beyond the area. */
uint8_t board_boot_check(const co_image_hdr_t *h);
/* Run the application whose image h describes (checked whole): never
 * returns. The board makes the payload runnable (rv32-virt copies it to
 * its load address) and enters it as its reset would. */
_Noreturn void board_boot_app(const co_image_hdr_t *h);
/* Reset the device, the CPU and the peripherals (RAM keeps its contents,
 * as after a warm reset): never returns. */
_Noreturn void board_reset(void);

/* ---- The application's side (boot_ident.c) ---------------------------------- */

/* The main loop's call after each pass (mcu_main.c): when a stop asked
 * for it (co_port_prog_handover), write the hand-over block with node's
 * node-ID and the bit rate it runs at (co_node_can_kbps) and reset into
 * the bootloader (board_reset): it does not return then. The block may
 * lie over the application's own memory: nothing of it is used after. A
 * node without a node-ID (LSS unconfigured) or a bit rate hands over a
 * block the bootloader does not take: it boots the application again. */
void boot_handover_poll(co_node_t *node);

#endif /* BOOT_H */
