/** @file
 * co_image.h - the program image that CiA 302-3 program download carries
 * (co_progdl.h) and that tools/mkimage makes: one format for every board,
 * the Linux program's products included.
 *
 * An image is a 64-byte header followed by the payload, the program as it
 * lies in the board's flash from load_addr on (nothing for the Linux
 * program, which keeps the whole image as its record of what it runs).
 * Every field is little-endian, read byte by byte (no struct overlay: the
 * header arrives in SDO segments at any alignment):
 *
 * | offset | size | field |
 * |---|---|---|
 * | 0 | 4 | magic, CO_IMAGE_MAGIC ("COIM") |
 * | 4 | 2 | header size, CO_IMAGE_HDR_SIZE |
 * | 6 | 2 | format version, CO_IMAGE_VERSION |
 * | 8 | 4 | length of the whole image, header included |
 * | 12 | 4 | CRC-32 of bytes 16 .. length - 1 (co_crc32) |
 * | 16 | 4 | board (CO_IMAGE_BOARD_*) |
 * | 20 | 4 | 1000h, device type, the program runs as |
 * | 24 | 4 | 1018h:1, vendor-ID |
 * | 28 | 4 | 1018h:2, product code |
 * | 32 | 4 | 1018h:3, revision number |
 * | 36 | 4 | 1F56h:1, program identification |
 * | 40 | 4 | load address of the payload's first byte (0: Linux) |
 * | 44 | 4 | reserved, 0 |
 * | 48 | 16 | product ID ("dst-x730-xy30"), NUL-padded, no NUL when 16 long |
 *
 * The CRC starts after its own field, so a loader computes it while the
 * image streams in, the header's first 16 bytes aside, and tools check it
 * with any CRC-32 library over the file from byte 16.
 *
 * Ownership: nothing here keeps state or allocates; every function may run
 * anywhere (no node, no port).
 */
#ifndef CO_IMAGE_H
#define CO_IMAGE_H

#include "co_common.h"

#define CO_IMAGE_MAGIC 0x4D494F43u /**< "COIM" as little-endian bytes */
#define CO_IMAGE_HDR_SIZE 64u      /**< bytes of the header */
#define CO_IMAGE_VERSION 1u        /**< the format this header describes */
#define CO_IMAGE_CRC_FROM 16u      /**< the CRC covers the image from this byte on */
#define CO_IMAGE_ID_LEN 16u        /**< bytes of the product ID field */

/** Boards an image is built for (the header's board field). @{ */
#define CO_IMAGE_BOARD_NUCLEO_F042K6 1u
#define CO_IMAGE_BOARD_MICROBIT 2u
#define CO_IMAGE_BOARD_RV32_VIRT 3u
#define CO_IMAGE_BOARD_LINUX 0x100u
/** @} */

/** A header, decoded (co_image_parse). */
typedef struct co_image_hdr {
    uint32_t length;               /**< bytes of the whole image, header included */
    uint32_t crc;                  /**< CRC-32 of bytes CO_IMAGE_CRC_FROM .. length - 1 */
    uint32_t board;                /**< CO_IMAGE_BOARD_* */
    uint32_t device_type;          /**< 1000h */
    uint32_t vendor;               /**< 1018h:1 */
    uint32_t product;              /**< 1018h:2 */
    uint32_t revision;             /**< 1018h:3 */
    uint32_t program_id;           /**< 1F56h:1 */
    uint32_t load_addr;            /**< where the payload's first byte runs from (0: Linux) */
    char id[CO_IMAGE_ID_LEN + 1u]; /**< product ID, NUL-terminated here */
} co_image_hdr_t;

/**
 * Decode the CO_IMAGE_HDR_SIZE bytes at b into h. Returns true when they
 * are a header of this format: the magic, the header size, the version,
 * a length of at least the header, a reserved field of 0 and a product ID
 * of printable ASCII NUL-padded. False: h is undefined, and the data is
 * not an image this firmware reads (1F57h status "unknown data format").
 * The CRC is not checked here (co_crc32 over the rest).
 */
bool co_image_parse(const uint8_t b[CO_IMAGE_HDR_SIZE], co_image_hdr_t *h);

/**
 * CRC-32 of IEEE 802.3 (reflected polynomial 0xEDB88320, initial value and
 * final XOR 0xFFFFFFFF, as zlib's crc32()) continued over len bytes:
 * start with crc 0 and hand each call the previous result, in any
 * pieces. Bitwise, no table (flash before speed: about 8 instructions a
 * bit). data: len readable bytes (NULL only with len 0), not kept. The
 * stored parameter records (co_store.h) use the same CRC.
 */
uint32_t co_crc32(uint32_t crc, const void *data, uint32_t len);

#endif /* CO_IMAGE_H */
