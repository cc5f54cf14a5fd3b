/*
 * sdo_block.c - SDO block upload and download (CiA 301 7.2.4.3.9-), with
 * the CRC-16-CCITT check. A product offers it by setting
 * co_node_cfg_t.sdo_block = co_sdo_block; images of products that do not
 * leave this file out.
 */
#include <string.h>

#include "co_sdo.h"
#include "sdo_internal.h"

/* Segments per block this server asks for: one block holds any object. */
#define BLKSIZE ((CO_SDO_BUF + 6u) / 7u)

uint16_t co_crc16_ccitt(uint16_t crc, const uint8_t *data, uint32_t len)
{
    uint32_t c = crc;
    for (uint32_t i = 0; i < len; i++) {
        c ^= (uint32_t)data[i] << 8;
        for (unsigned b = 0; b < 8u; b++) {
            c = (c & 0x8000u) != 0u ? (c << 1) ^ 0x1021u : c << 1;
        }
    }
    return (uint16_t)c;
}

/* ---- block download ------------------------------------------------- */

static void block_download_initiate(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    sdo->sized = (d[0] & 0x02u) != 0u;
    const co_od_entry_t *e = sdo_download_target(node, d, sdo->sized);
    if (e == NULL) {
        return;
    }
    sdo->state = SDO_BLK_DL;
    sdo->e = e;
    sdo->size = co_od_size(e);
    sdo->pos = 0;
    sdo->seq = 0;
    sdo->crc = (d[0] & 0x04u) != 0u;
    /* A DOMAIN's blocks fill a piece each (sdo_internal.h). */
    sdo->blksize = (uint8_t)(e->type == CO_T_DOMAIN ? SDO_DOMAIN_BLKSIZE : BLKSIZE);
    sdo_restart(sdo);
    uint8_t out[8] = {0xA4, d[1], d[2], d[3], sdo->blksize, 0, 0, 0}; /* CRC supported */
    sdo_reply(node, out);
}

static void block_download_segment(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    uint8_t seqno = d[0] & 0x7Fu;
    bool c = (d[0] & 0x80u) != 0u;
    bool last = c;
    sdo_restart(sdo);
    bool domain = sdo->e->type == CO_T_DOMAIN;
    if (seqno == (uint8_t)(sdo->seq + 1u) && domain) {
        /* Never more than the piece: a block is sized to what it lacks. */
        (void)sdo_domain_take(node, &d[1], 7u);
        sdo->seq = seqno;
    } else if (seqno == (uint8_t)(sdo->seq + 1u)) {
        if (sdo->pos > CO_SDO_BUF) { /* earlier segments brought more than the buffer */
            uint8_t mux[4];
            sdo_mux(sdo, mux);
            sdo_abort(node, mux, CO_E_LEN_HIGH);
            return;
        }
        /* Keep at most the buffer (pos <= CO_SDO_BUF here); bytes past it
         * make the end check fail. */
        memcpy(&sdo->buf[sdo->pos], &d[1], co_min_u32(7u, CO_SDO_BUF - sdo->pos));
        sdo->pos += 7u;
        sdo->seq = seqno;
    } else {
        last = false; /* out of sequence: ignored; the acknowledge says what came */
    }
    if (c || seqno >= sdo->blksize) {
        if (domain && !last) {
            /* A full piece goes to the handler before the acknowledge: the
             * client waits for it, so a flash erase there loses no frame.
             * The next block is what the piece lacks (all of it when one
             * went). */
            if (sdo->pos == SDO_DOMAIN_PIECE) {
                sdo->crc16 = co_crc16_ccitt((uint16_t)sdo->crc16, sdo->buf, sdo->pos);
                co_res_t r = sdo_domain_hand(node, false);
                if (r != CO_OK) {
                    uint8_t mux[4];
                    sdo_mux(sdo, mux);
                    sdo_abort(node, mux, r);
                    return;
                }
            }
            sdo->blksize = (uint8_t)((SDO_DOMAIN_PIECE - sdo->pos) / 7u);
        }
        uint8_t ack[8] = {0xA2, sdo->seq, sdo->blksize, 0, 0, 0, 0, 0};
        sdo_reply(node, ack);
        if (last) {
            sdo->state = SDO_BLK_DL_END;
        }
        sdo->seq = 0;
    }
}

/* The end of a DOMAIN's block download: the last segment's unused bytes
 * dropped, the CRC of the whole checked (its earlier pieces' part kept in
 * crc16), the rest handed over before the answer. */
static void domain_end(co_node_t *node, const uint8_t *d, const uint8_t mux[4], uint32_t unused)
{
    co_sdo_t *sdo = &node->sdo;
    sdo->state = SDO_IDLE;
    if (unused > sdo->pos) {
        sdo_abort(node, mux, CO_E_LEN);
        return;
    }
    sdo->pos -= unused;
    if (sdo->crc && co_crc16_ccitt((uint16_t)sdo->crc16, sdo->buf, sdo->pos) != co_get_u16(&d[1])) {
        sdo_abort(node, mux, CO_E_CRC);
        return;
    }
    co_res_t r = sdo_domain_hand(node, true);
    if (r != CO_OK) {
        sdo_abort(node, mux, r);
        return;
    }
    uint8_t out[8] = {0xA1, 0, 0, 0, 0, 0, 0, 0};
    sdo_reply(node, out);
}

static void block_download_end(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    uint8_t mux[4];
    sdo_mux(sdo, mux);
    if (d[0] >> 5 != CCS_BLOCK_DOWNLOAD || (d[0] & 0x01u) == 0u) {
        sdo_abort(node, mux, CO_E_CMD);
        return;
    }
    uint32_t unused = (d[0] >> 2) & 0x07u;
    if (sdo->e->type == CO_T_DOMAIN) {
        domain_end(node, d, mux, unused);
        return;
    }
    uint32_t len = sdo->pos - unused;
    sdo->state = SDO_IDLE;
    if (len > CO_SDO_BUF || (sdo->sized && len != sdo->size)) {
        sdo_abort(node, mux, CO_E_LEN);
        return;
    }
    if (sdo->crc && co_crc16_ccitt(0, sdo->buf, len) != co_get_u16(&d[1])) {
        sdo_abort(node, mux, CO_E_CRC);
        return;
    }
    co_res_t r = co_node_write(node, sdo->e, sdo->buf, len);
    if (r != CO_OK) {
        sdo_abort(node, mux, r);
        return;
    }
    uint8_t out[8] = {0xA1, 0, 0, 0, 0, 0, 0, 0};
    sdo_reply(node, out);
}

/* ---- block upload ----------------------------------------------------- */

static void block_upload_initiate(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    const co_od_entry_t *e = sdo_find(node, d);
    if (e == NULL) {
        return;
    }
    if ((e->attr & CO_A_R) == 0u) {
        sdo_abort(node, d, CO_E_WO);
        return;
    }
    if (d[4] < 1u || d[4] > 127u) {
        sdo_abort(node, d, CO_E_BLKSIZE);
        return;
    }
    if (co_od_size(e) > CO_SDO_BUF) {
        sdo_abort(node, d, CO_E_OOM); /* never cut an object short */
        return;
    }
    uint32_t len;
    co_res_t r = co_od_read(node, e, 0, sdo->buf, CO_SDO_BUF, &len);
    if (r != CO_OK) {
        sdo_abort(node, d, r);
        return;
    }
    sdo->state = SDO_BLK_UL_START;
    sdo->e = e;
    sdo->size = len;
    sdo->blk_start = 0;
    sdo->crc = (d[0] & 0x04u) != 0u;
    sdo->blksize = d[4];
    sdo_restart(sdo);
    sdo_reply_head(node, 0xC6, d, len); /* CRC supported, size indicated */
}

static void block_upload_send(co_node_t *node)
{
    co_sdo_t *sdo = &node->sdo;
    sdo->seq = 0;
    uint32_t pos = sdo->blk_start;
    while (sdo->seq < sdo->blksize) {
        uint8_t out[8] = {0};
        uint32_t n = co_min_u32(7u, sdo->size - pos);
        memcpy(&out[1], &sdo->buf[pos], n);
        pos += n;
        sdo->seq++;
        bool last = pos >= sdo->size;
        out[0] = (uint8_t)(sdo->seq | (last ? 0x80u : 0u));
        sdo_reply(node, out);
        if (last) {
            break;
        }
    }
    sdo->state = SDO_BLK_UL;
    sdo_restart(sdo);
}

static void block_upload_client(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    uint8_t mux[4];
    sdo_mux(sdo, mux);
    uint8_t cs = d[0] & 0x03u;
    if (d[0] >> 5 != CCS_BLOCK_UPLOAD) {
        sdo_abort(node, mux, CO_E_CMD);
        return;
    }
    if (sdo->state == SDO_BLK_UL_START && cs == 3u) {
        block_upload_send(node);
    } else if (sdo->state == SDO_BLK_UL && cs == 2u) {
        if (d[1] > sdo->seq || d[2] < 1u || d[2] > 127u) {
            sdo_abort(node, mux, d[1] > sdo->seq ? CO_E_SEQNO : CO_E_BLKSIZE);
            return;
        }
        sdo->blk_start = co_min_u32(sdo->blk_start + 7u * d[1], sdo->size);
        sdo->blksize = d[2];
        if (sdo->blk_start >= sdo->size) {
            uint32_t unused = (7u - sdo->size % 7u) % 7u;
            uint8_t out[8] = {(uint8_t)(0xC1u | (unused << 2)), 0, 0, 0, 0, 0, 0, 0};
            if (sdo->crc) {
                co_put_u16(&out[1], co_crc16_ccitt(0, sdo->buf, sdo->size));
            }
            sdo->state = SDO_BLK_UL_END;
            sdo_restart(sdo);
            sdo_reply(node, out);
        } else {
            block_upload_send(node); /* the next block, or the rest of this one */
        }
    } else if (sdo->state == SDO_BLK_UL_END && cs == 1u) {
        sdo->state = SDO_IDLE; /* done; the client's end needs no answer */
    } else {
        sdo_abort(node, mux, CO_E_CMD);
    }
}

/* Entry point: an initiate request (ccs 5 or 6), or any frame of a block
 * transfer in progress. Returns false for a request it does not handle. */
bool co_sdo_block(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    switch (sdo->state) {
    case SDO_BLK_DL:
        block_download_segment(node, d);
        return true;
    case SDO_BLK_DL_END:
        block_download_end(node, d);
        return true;
    case SDO_BLK_UL_START:
    case SDO_BLK_UL:
    case SDO_BLK_UL_END:
        block_upload_client(node, d);
        return true;
    default:
        break;
    }
    if ((d[0] >> 5) == CCS_BLOCK_DOWNLOAD && (d[0] & 0x01u) == 0u) {
        block_download_initiate(node, d);
        return true;
    }
    if ((d[0] >> 5) == CCS_BLOCK_UPLOAD && (d[0] & 0x03u) == 0u) {
        block_upload_initiate(node, d);
        return true;
    }
    return false;
}
