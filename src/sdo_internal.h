/*
 * sdo_internal.h - what the SDO server (sdo.c) shares with its
 * optional block transfer (sdo_block.c). Not part of the public API.
 */
#ifndef SDO_INTERNAL_H
#define SDO_INTERNAL_H

#include "co_node.h"

enum {
    SDO_IDLE = 0,
    SDO_DOWNLOAD,
    SDO_UPLOAD,
    SDO_BLK_DL,      /* block download: receiving segments */
    SDO_BLK_DL_END,  /* block download: waiting for the end request */
    SDO_BLK_UL_START, /* block upload: waiting for the start request */
    SDO_BLK_UL,      /* block upload: a block sent, waiting for its acknowledge */
    SDO_BLK_UL_END,  /* block upload: end sent, waiting for the client's end */
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

/* Answer, abort and bookkeeping helpers of the server. */
void co_sdo_reply(co_node_t *node, const uint8_t d[8]);
/* Send f as the server's answer: f->data filled by the caller, all 8 bytes. */
void co_sdo_send(co_node_t *node, co_frame_t *f);
void co_sdo_reply_head(co_node_t *node, uint8_t cmd, const uint8_t *req, uint32_t val);
void co_sdo_abort(co_node_t *node, const uint8_t *mux, co_res_t r);
void co_sdo_mux(const co_sdo_t *sdo, uint8_t mux[4]);
void co_sdo_restart(co_sdo_t *sdo);
const co_od_entry_t *co_sdo_find(co_node_t *node, const uint8_t *d);
const co_od_entry_t *co_sdo_download_target(co_node_t *node, const uint8_t *d, bool sized);

#endif /* SDO_INTERNAL_H */
