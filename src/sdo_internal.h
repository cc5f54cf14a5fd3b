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

/* ---- DOMAIN downloads (co_node_cfg_t.sdo_domain, sdo_domain.c) ----
 * The bytes collect in sdo->buf and go to the handler a piece at a time,
 * sdo->done counting what it has; sdo->pos is what the buffer holds. */

/* Bytes of a piece: the largest multiple of 28 (4 segments of 7 bytes)
 * within the buffer, so that a block of SDO_DOMAIN_BLKSIZE segments fills
 * one piece exactly and every piece but the last is a multiple of 4 bytes
 * long and starts at a multiple of 4 (a flash written in words). A
 * buffer below 28 bytes takes no DOMAIN download (CO_E_OOM). */
#define SDO_DOMAIN_PIECE (CO_SDO_BUF / 28u * 28u)
#define SDO_DOMAIN_BLKSIZE (SDO_DOMAIN_PIECE / 7u)

/* A download of the DOMAIN e begins: the handler's answer (it may refuse
 * it), 08000022h without a handler (the application side of program
 * download), 05040005h with a buffer too small for a piece. Inline: where
 * the config is fixed without a handler (CO_FIXED_CFG), it is the
 * constant abort. */
static inline co_res_t sdo_domain_begin(co_node_t *node, const co_od_entry_t *e)
{
    co_sdo_domain_fn fn = co_cfg(node)->sdo_domain;
    if (fn == NULL) {
        return CO_E_STATE;
    }
    if (SDO_DOMAIN_PIECE == 0u) {
        return CO_E_OOM;
    }
    node->sdo.pos = 0;
    node->sdo.done = 0;
    return fn(node, e, 0, NULL, 0, false);
}
/* Take the n bytes at src: a full buffer goes to the handler first, so
 * that what it gets is never the download's end, which only the caller
 * knows. A refusal is the handler's code. */
co_res_t sdo_domain_take(co_node_t *node, const uint8_t *src, uint32_t n);
/* Hand what the buffer holds to the handler (end: the download's last
 * bytes); the buffer is empty after it. */
co_res_t sdo_domain_hand(co_node_t *node, bool end);

#endif /* SDO_INTERNAL_H */
