/** @file
 * co_sdo.h - SDO server (CiA 301 7.2.4): expedited, and where the product
 * links them segmented and block upload and download (block: CRC-16-CCITT
 * when the client wants it; one block carries any object, the
 * protocol-switch threshold is not used),
 * toggle and sequence checks, timeout, abort codes from co_res_t.
 *
 * State: co_sdo_t in the node, one transfer at a time (a new initiate
 * replaces an unfinished one); the buffer of segmented and block downloads
 * is its buf[CO_SDO_BUF]. The server reads and writes the dictionary
 * (co_od_read, co_node_write) and answers through co_node_send(); every
 * failure a client causes is answered with the abort code of its co_res_t
 * (co_common.h), never a crash. Not reentrant; main loop only.
 */
#ifndef CO_SDO_H
#define CO_SDO_H

#include "co_common.h"
#include "co_od.h"

/** The node object (co_node.h). */
typedef struct co_node co_node_t;

/** Largest object a segmented or block download can write, or a block
 * upload can read (bytes); the RAM cost of the SDO server is about this.
 * An MCU image may set less (its table sizes in `od/<family>/family.cmake`).
 * 4..889: at least an expedited transfer's 4 bytes (a product without
 * co_sdo_segmented, the DST, needs no more: its segmented downloads carry
 * at most 4 bytes), at most one block: 127
 * segments of 7 bytes (CiA 301's largest blksize; sdo_block.c sends a
 * buffer as one block of (CO_SDO_BUF + 6) / 7 segments). */
#ifndef CO_SDO_BUF
#define CO_SDO_BUF 64u
#endif
#if CO_SDO_BUF < 4 || CO_SDO_BUF > 889
#error "CO_SDO_BUF must be 4..889 (an expedited transfer's 4 bytes .. one block of 127 x 7 bytes)"
#endif
/** Default SDO timeout between segments (CiA 301 leaves it to the device). */
#define CO_SDO_TIMEOUT_US 1000000u

/** SDO server state in the node: one transfer at a time. */
typedef struct co_sdo {
    uint8_t state;          /**< idle / segmented download / segmented upload */
    uint8_t toggle;         /**< expected toggle bit of the next segment (0 or 0x10) */
    bool restart;           /**< a segment arrived: the timeout restarts at next poll */
    const co_od_entry_t *e; /**< the entry transferred */
    union {
        uint32_t size;  /**< bytes of the transfer */
        uint32_t crc16; /**< a DOMAIN's block download: CRC-16 of the bytes handed over */
    };
    uint32_t pos;      /**< bytes done */
    uint32_t deadline; /**< end of the timeout */
    uint8_t blksize;   /**< block transfer: segments per block */
    uint8_t seq;       /**< block download: last good seqno; upload: segments sent */
    bool crc;          /**< block transfer: both sides use the CRC */
    bool sized;        /**< block download: the client indicated the size */
    union {
        uint32_t blk_start; /**< block upload: byte position of the current block */
        uint32_t done;      /**< a DOMAIN's download: bytes handed over (co_sdo_domain_fn) */
    };
    uint8_t buf[CO_SDO_BUF]; /**< the data of a segmented or block download, a block upload */
} co_sdo_t;

/** An optional SDO protocol: handles the request d, or returns false when
 * it is none of its own (the server then aborts with 0x05040001). */
typedef bool (*co_sdo_proto_fn)(co_node_t *node, const uint8_t *d);

/**
 * Where a download of a DOMAIN entry e goes (co_node_cfg_t.sdo_domain): the
 * server holds no more than CO_SDO_BUF bytes of it and hands them over in
 * order, at = the offset of buf's first byte in the object. A download
 * begins with a call at 0 with no bytes (buf NULL, len 0, end false),
 * which may refuse it (the initiate is answered with the abort); then each
 * full piece (the largest multiple of 28 bytes within CO_SDO_BUF: 56 of
 * 64; a block download's blocks are sized to fill one each, and the piece
 * goes before the block's acknowledge); then the rest with end true, before the answer to the last
 * segment or the block end. Any result but CO_OK ends the transfer with
 * that abort code. A transfer that ends otherwise (the client's abort,
 * the timeout, a new request) is not reported: the next call at 0 begins
 * anew. An expedited download is a begin and an end. Without a function
 * (NULL) every download of a DOMAIN is refused with 08000022h (the
 * application side of program download, co_progdl.h).
 */
typedef co_res_t (*co_sdo_domain_fn)(co_node_t *node, const co_od_entry_t *e, uint32_t at,
                                     const uint8_t *buf, uint32_t len, bool end);

/** SDO segmented transfer (sdo_segment.c): set as co_node_cfg_t.sdo_segmented
 * to offer it. Needed by any product with an object of more than 4 bytes.
 * Without it the server still takes segmented downloads of at most 4 bytes
 * in all (sdo.c); segmented uploads are refused with 0x05040001. */
bool co_sdo_segmented(co_node_t *node, const uint8_t *d);

/** SDO block transfer (sdo_block.c): set as co_node_cfg_t.sdo_block to offer it. */
bool co_sdo_block(co_node_t *node, const uint8_t *d);

/** CRC-16-CCITT (polynomial 0x1021, initial 0), as SDO block transfer uses. */
uint16_t co_crc16_ccitt(uint16_t crc, const uint8_t *data, uint32_t len);

/** Forget any transfer in progress (reset communication). */
void co_sdo_init(co_sdo_t *sdo);

/**
 * Handle one frame on 0x600 + node-ID: co_node_receive() hands over every
 * frame on that CAN-ID and only those (the CAN-ID is not checked again).
 * Remote frames, frames that are not 8 bytes long and requests in stopped
 * are ignored; every other request gets one answer on 0x580 + node-ID
 * through co_port_can_send() before it returns (an abort with its
 * co_res_t code where it fails), or none during a block download's
 * sub-block and after a client's abort (CiA 301).
 */
void co_sdo_receive(co_node_t *node, const co_frame_t *f);

/** Timeout of a segmented transfer; returns the delay until it next matters. */
uint32_t co_sdo_poll(co_node_t *node, uint32_t now);

#endif /* CO_SDO_H */
