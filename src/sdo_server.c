/*
 * sdo_server.c - SDO server, expedited and segmented. See co_sdo.h.
 */
#include "co_sdo.h"

#include <string.h>

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

void co_sdo_init(co_sdo_t *sdo)
{
    memset(sdo, 0, sizeof(*sdo));
}

static void reply(co_node_t *node, const uint8_t d[8])
{
    co_frame_t f = {.id = (uint16_t)(0x580u + node->node_id), .dlc = 8};
    memcpy(f.data, d, 8);
    (void)co_node_send(node, &f);
}

static void reply_head(co_node_t *node, uint8_t cmd, const uint8_t *req, uint32_t val)
{
    uint8_t d[8] = {cmd, req[1], req[2], req[3], 0, 0, 0, 0};
    co_put_u32(&d[4], val);
    reply(node, d);
}

static void sdo_abort(co_node_t *node, const uint8_t *mux, co_res_t r)
{
    node->sdo.state = SDO_IDLE;
    reply_head(node, 0x80, mux, co_res_abort_code(r));
}

/* Command byte placeholder and multiplexer of the transfer in progress,
 * laid out like a request so that abort replies can echo it. */
static void transfer_mux(const co_sdo_t *sdo, uint8_t mux[4])
{
    mux[0] = 0;
    mux[1] = (uint8_t)sdo->e->index;
    mux[2] = (uint8_t)(sdo->e->index >> 8);
    mux[3] = sdo->e->sub;
}

static void start_timer(co_sdo_t *sdo)
{
    sdo->restart = true;
}

/*
 * The object a download initiate (segmented or block) names: it must exist,
 * be writable, fit the buffer, and match an indicated size. NULL after
 * answering with the abort.
 */
static const co_od_entry_t *download_target(co_node_t *node, const uint8_t *d, bool sized)
{
    co_res_t r;
    const co_od_entry_t *e = co_od_find(node->cfg->od, co_get_u16(&d[1]), d[3], &r);
    if (e == NULL) {
        sdo_abort(node, d, r);
        return NULL;
    }
    uint32_t size = co_get_u32(&d[4]);
    r = (e->attr & CO_A_W) == 0u           ? CO_E_RO
        : sized && size > co_od_size(e)    ? CO_E_LEN_HIGH
        : sized && size < co_od_size(e)    ? CO_E_LEN_LOW
        : co_od_size(e) > CO_SDO_BUF       ? CO_E_OOM
                                           : CO_OK;
    if (r != CO_OK) {
        sdo_abort(node, d, r);
        return NULL;
    }
    return e;
}

static void initiate_download(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    bool expedited = (d[0] & 0x02u) != 0u;
    bool sized = (d[0] & 0x01u) != 0u;
    if (expedited) {
        co_res_t r;
        const co_od_entry_t *e = co_od_find(node->cfg->od, co_get_u16(&d[1]), d[3], &r);
        if (e != NULL && (e->attr & CO_A_W) == 0u) {
            r = CO_E_RO;
            e = NULL;
        }
        if (e == NULL) {
            sdo_abort(node, d, r);
            return;
        }
        /* Size not indicated (0x22): the object's own size, at most 4. */
        uint32_t len = sized ? 4u - ((d[0] >> 2) & 0x03u) : co_min_u32(co_od_size(e), 4u);
        r = co_od_write(node, e, &d[4], len);
        if (r != CO_OK) {
            sdo_abort(node, d, r);
        } else {
            reply_head(node, 0x60, d, 0);
        }
        return;
    }
    const co_od_entry_t *e = download_target(node, d, sized);
    if (e == NULL) {
        return;
    }
    sdo->state = SDO_DOWNLOAD;
    sdo->e = e;
    sdo->size = co_od_size(e);
    sdo->pos = 0;
    sdo->toggle = 0;
    start_timer(sdo);
    reply_head(node, 0x60, d, 0);
}

static void download_segment(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    uint8_t mux[4];
    transfer_mux(sdo, mux);
    if ((d[0] & 0x10u) != sdo->toggle) {
        sdo_abort(node, mux, CO_E_TOGGLE);
        return;
    }
    uint32_t n = 7u - ((d[0] >> 1) & 0x07u);
    if (sdo->pos + n > sdo->size) {
        sdo_abort(node, mux, CO_E_LEN_HIGH);
        return;
    }
    memcpy(&sdo->buf[sdo->pos], &d[1], n);
    sdo->pos += n;
    uint8_t ack[8] = {(uint8_t)(0x20u | sdo->toggle), 0, 0, 0, 0, 0, 0, 0};
    sdo->toggle ^= 0x10u;
    if ((d[0] & 0x01u) == 0u) { /* more segments follow */
        start_timer(sdo);
        reply(node, ack);
        return;
    }
    sdo->state = SDO_IDLE;
    if (sdo->pos != sdo->size) {
        sdo_abort(node, mux, sdo->pos < sdo->size ? CO_E_LEN_LOW : CO_E_LEN_HIGH);
        return;
    }
    co_res_t r = co_od_write(node, sdo->e, sdo->buf, sdo->pos);
    if (r != CO_OK) {
        sdo_abort(node, mux, r);
        return;
    }
    reply(node, ack);
}

static void initiate_upload(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    co_res_t r;
    const co_od_entry_t *e = co_od_find(node->cfg->od, co_get_u16(&d[1]), d[3], &r);
    if (e == NULL) {
        sdo_abort(node, d, r);
        return;
    }
    uint8_t out[8] = {0, d[1], d[2], d[3], 0, 0, 0, 0};
    uint32_t len;
    r = co_od_read(node, e, 0, &out[4], 4, &len);
    if (r != CO_OK) {
        sdo_abort(node, d, r);
        return;
    }
    uint32_t size = co_od_size(e);
    if (size <= 4u) {
        /* Expedited, size indicated: 0x4F / 0x4B / 0x47 / 0x43. */
        out[0] = (uint8_t)(0x43u | ((4u - size) << 2));
        reply(node, out);
        return;
    }
    sdo->state = SDO_UPLOAD;
    sdo->e = e;
    sdo->size = size;
    sdo->pos = 0;
    sdo->toggle = 0;
    start_timer(sdo);
    reply_head(node, 0x41, d, size);
}

static void upload_segment(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    uint8_t mux[4];
    transfer_mux(sdo, mux);
    if ((d[0] & 0x10u) != sdo->toggle) {
        sdo_abort(node, mux, CO_E_TOGGLE);
        return;
    }
    uint8_t out[8] = {0, 0, 0, 0, 0, 0, 0, 0};
    uint32_t n;
    co_res_t r = co_od_read(node, sdo->e, sdo->pos, &out[1], 7, &n);
    if (r != CO_OK) {
        sdo_abort(node, mux, r);
        return;
    }
    sdo->pos += n;
    bool last = sdo->pos >= sdo->size;
    out[0] = (uint8_t)(sdo->toggle | ((7u - n) << 1) | (last ? 1u : 0u));
    sdo->toggle ^= 0x10u;
    if (last) {
        sdo->state = SDO_IDLE;
    } else {
        start_timer(sdo);
    }
    reply(node, out);
}


/* ---- block download ------------------------------------------------- */

static void block_download_initiate(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    sdo->sized = (d[0] & 0x02u) != 0u;
    const co_od_entry_t *e = download_target(node, d, sdo->sized);
    if (e == NULL) {
        return;
    }
    sdo->state = SDO_BLK_DL;
    sdo->e = e;
    sdo->size = co_od_size(e);
    sdo->pos = 0;
    sdo->seq = 0;
    sdo->crc = (d[0] & 0x04u) != 0u;
    sdo->blksize = (uint8_t)BLKSIZE;
    start_timer(sdo);
    uint8_t out[8] = {0xA4, d[1], d[2], d[3], sdo->blksize, 0, 0, 0}; /* CRC supported */
    reply(node, out);
}

static void block_download_segment(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    uint8_t seqno = d[0] & 0x7Fu;
    bool c = (d[0] & 0x80u) != 0u;
    bool last = c;
    start_timer(sdo);
    if (seqno == (uint8_t)(sdo->seq + 1u)) {
        if (sdo->pos + 7u > CO_SDO_BUF + 7u) {
            uint8_t mux[4];
            transfer_mux(sdo, mux);
            sdo_abort(node, mux, CO_E_LEN_HIGH);
            return;
        }
        /* Keep at most the buffer; bytes past it make the end check fail. */
        uint32_t room = sdo->pos < CO_SDO_BUF ? CO_SDO_BUF - sdo->pos : 0u;
        memcpy(&sdo->buf[sdo->pos], &d[1], co_min_u32(7u, room));
        sdo->pos += 7u;
        sdo->seq = seqno;
    } else {
        last = false; /* out of sequence: ignored; the acknowledge says what came */
    }
    if (c || seqno >= sdo->blksize) {
        uint8_t ack[8] = {0xA2, sdo->seq, sdo->blksize, 0, 0, 0, 0, 0};
        reply(node, ack);
        if (last) {
            sdo->state = SDO_BLK_DL_END;
        }
        sdo->seq = 0;
    }
}

static void block_download_end(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    uint8_t mux[4];
    transfer_mux(sdo, mux);
    if (d[0] >> 5 != CCS_BLOCK_DOWNLOAD || (d[0] & 0x01u) == 0u) {
        sdo_abort(node, mux, CO_E_CMD);
        return;
    }
    uint32_t unused = (d[0] >> 2) & 0x07u;
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
    co_res_t r = co_od_write(node, sdo->e, sdo->buf, len);
    if (r != CO_OK) {
        sdo_abort(node, mux, r);
        return;
    }
    uint8_t out[8] = {0xA1, 0, 0, 0, 0, 0, 0, 0};
    reply(node, out);
}

/* ---- block upload ----------------------------------------------------- */

static void block_upload_initiate(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    co_res_t r;
    const co_od_entry_t *e = co_od_find(node->cfg->od, co_get_u16(&d[1]), d[3], &r);
    if (e == NULL) {
        sdo_abort(node, d, r);
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
    r = co_od_read(node, e, 0, sdo->buf, CO_SDO_BUF, &len);
    if (r != CO_OK) {
        sdo_abort(node, d, r);
        return;
    }
    sdo->state = SDO_BLK_UL_START;
    sdo->e = e;
    sdo->size = len;
    sdo->pos = 0;
    sdo->blk_start = 0;
    sdo->crc = (d[0] & 0x04u) != 0u;
    sdo->blksize = d[4];
    start_timer(sdo);
    reply_head(node, 0xC6, d, len); /* CRC supported, size indicated */
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
        reply(node, out);
        if (last) {
            break;
        }
    }
    sdo->state = SDO_BLK_UL;
    start_timer(sdo);
}

static void block_upload_client(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    uint8_t mux[4];
    transfer_mux(sdo, mux);
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
            if (sdo->size == 0u) {
                unused = 0;
            }
            uint8_t out[8] = {(uint8_t)(0xC1u | (unused << 2)), 0, 0, 0, 0, 0, 0, 0};
            if (sdo->crc) {
                co_put_u16(&out[1], co_crc16_ccitt(0, sdo->buf, sdo->size));
            }
            sdo->state = SDO_BLK_UL_END;
            start_timer(sdo);
            reply(node, out);
        } else {
            block_upload_send(node); /* the next block, or the rest of this one */
        }
    } else if (sdo->state == SDO_BLK_UL_END && cs == 1u) {
        sdo->state = SDO_IDLE; /* done; the client's end needs no answer */
    } else {
        sdo_abort(node, mux, CO_E_CMD);
    }
}

bool co_sdo_receive(co_node_t *node, const co_frame_t *f)
{
    if (f->id != 0x600u + node->node_id || f->rtr) {
        return false;
    }
    if (f->dlc != 8u || !co_nmt_sdo_allowed(node->nmt.state)) {
        return true; /* CiA 301: SDO frames are 8 bytes; no SDO in stopped */
    }
    const uint8_t *d = f->data;
    co_sdo_t *sdo = &node->sdo;
    /* During a sub-block every frame is a segment: only 0x80 (sequence 0,
     * which no segment has) is the client's abort there. */
    bool abort = sdo->state == SDO_BLK_DL ? d[0] == 0x80u : (d[0] >> 5) == CCS_ABORT;
    if (abort) {
        sdo->state = SDO_IDLE; /* the client gave up; no answer */
        return true;
    }
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
    switch (d[0] >> 5) {
    case CCS_DOWNLOAD_INITIATE:
        sdo->state = SDO_IDLE; /* a new request replaces an unfinished one */
        initiate_download(node, d);
        break;
    case CCS_UPLOAD_INITIATE:
        sdo->state = SDO_IDLE;
        initiate_upload(node, d);
        break;
    case CCS_DOWNLOAD_SEGMENT:
    case CCS_UPLOAD_SEGMENT: {
        /* A segment belongs to the transfer in progress, of the same direction. */
        bool download = (d[0] >> 5) == CCS_DOWNLOAD_SEGMENT;
        if (sdo->state != (download ? SDO_DOWNLOAD : SDO_UPLOAD)) {
            sdo_abort(node, d, CO_E_CMD);
        } else if (download) {
            download_segment(node, d);
        } else {
            upload_segment(node, d);
        }
        break;
    }
    case CCS_BLOCK_DOWNLOAD:
        if ((d[0] & 0x01u) == 0u) {
            block_download_initiate(node, d);
        } else {
            sdo_abort(node, d, CO_E_CMD); /* an end without a transfer */
        }
        break;
    case CCS_BLOCK_UPLOAD:
        if ((d[0] & 0x03u) == 0u) {
            block_upload_initiate(node, d);
        } else {
            sdo_abort(node, d, CO_E_CMD);
        }
        break;
    default:
        sdo_abort(node, d, CO_E_CMD); /* reserved command specifier */
        break;
    }
    return true;
}

uint32_t co_sdo_poll(co_node_t *node, uint32_t now)
{
    co_sdo_t *sdo = &node->sdo;
    if (sdo->state == SDO_IDLE) {
        return CO_NEVER;
    }
    if (sdo->restart) {
        sdo->restart = false;
        sdo->deadline = now + CO_SDO_TIMEOUT_US;
    }
    if (!co_time_before(now, sdo->deadline)) {
        uint8_t mux[4];
        transfer_mux(sdo, mux);
        sdo_abort(node, mux, CO_E_TIMEOUT);
        return CO_NEVER;
    }
    return sdo->deadline - now;
}
