/*
 * sdo_internal.h - what the SDO server (sdo.c) shares with its optional
 * segmented (sdo_segment.c) and block (sdo_block.c) transfers. Not part of
 * the public API: hence the prefix sdo_, not co_sdo_ (co_sdo.h).
 */
#ifndef SDO_INTERNAL_H
#define SDO_INTERNAL_H

#include "co_node.h"

enum {
    SDO_IDLE = 0,
    SDO_DOWNLOAD,
    SDO_UPLOAD,
    SDO_BLK_DL,       /* block download: receiving segments */
    SDO_BLK_DL_END,   /* block download: waiting for the end request */
    SDO_BLK_UL_START, /* block upload: waiting for the start request */
    SDO_BLK_UL,       /* block upload: a block sent, waiting for its acknowledge */
    SDO_BLK_UL_END,   /* block upload: end sent, waiting for the client's end */
};

/* Client command specifiers (byte 0 bits 7..5). */
enum {
    CCS_DOWNLOAD_SEGMENT = 0,
    CCS_DOWNLOAD_INITIATE = 1,
    CCS_UPLOAD_INITIATE = 2,
    CCS_UPLOAD_SEGMENT = 3,
    CCS_ABORT = 4,
    CCS_BLOCK_UPLOAD = 5,
    CCS_BLOCK_DOWNLOAD = 6,
};

/* Answer, abort and bookkeeping helpers of the server. Each answer goes
 * out on 0x580 + node-ID through co_node_send() before it returns. */

/* Send the 8 bytes d (copied) as the server's answer. */
void sdo_reply(co_node_t *node, const uint8_t d[8]);
/* Send f as the server's answer: f->data filled by the caller, all 8 bytes. */
void sdo_send(co_node_t *node, co_frame_t *f);
/* Answer cmd, the request req's multiplexer (bytes 1..3), val in bytes 4..7. */
void sdo_reply_head(co_node_t *node, uint8_t cmd, const uint8_t *req, uint32_t val);
/* End the transfer (idle) and answer abort code r for the multiplexer in
 * mux[1..3] (a request, or sdo_mux()'s). mux NULL: for a request that
 * names no object (a segment or a block sub-command outside its transfer,
 * a reserved command specifier, the timeout), CiA 301's choice: the
 * multiplexer of the transfer the abort ends, or 0000h sub 00h with none;
 * the request's bytes 1..3 are data there, never an object. */
void sdo_abort(co_node_t *node, const uint8_t *mux, co_res_t r);
/* The multiplexer of the transfer in progress (sdo->e set), laid out like
 * a request (mux[0] = 0) for sdo_abort(). */
void sdo_mux(const co_sdo_t *sdo, uint8_t mux[4]);
/* A segment arrived: the timeout restarts at the next co_sdo_poll(). */
void sdo_restart(co_sdo_t *sdo);
/* The entry request d names, or NULL after answering with the abort
 * (0x06020000 no object, 0x06090011 no sub-index). */
const co_od_entry_t *sdo_find(co_node_t *node, const uint8_t *d);
/* The entry a segmented or block download initiate d names, checked for
 * write access, the size d indicates (sized) and CO_SDO_BUF; NULL after
 * answering with the abort. */
const co_od_entry_t *sdo_download_target(co_node_t *node, const uint8_t *d, bool sized);

#endif /* SDO_INTERNAL_H */
