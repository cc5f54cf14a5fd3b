/*
 * sdo.c - SDO server: expedited transfer, segmented downloads of up to 4
 * bytes where sdo_segment.c is not linked, the dispatch to the
 * optional segmented (sdo_segment.c) and block (sdo_block.c) protocols,
 * their timeout. See co_sdo.h.
 */
#include "co_sdo.h"

#include <string.h>

#include "co_node.h"
#include "sdo_internal.h"

void co_sdo_init(co_sdo_t *sdo)
{
    memset(sdo, 0, sizeof(*sdo));
}

/* The answers are built in the frame itself, every field set once: the
 * frame's initialiser was a memset and the data a memcpy from an array,
 * 103 of the expedited read's instructions on the Cortex-M0 (byte loops,
 * libc_min.c); now about 20. */
void sdo_send(co_node_t *node, co_frame_t *f)
{
    f->id = (uint16_t)(0x580u + node->node_id);
    f->dlc = 8;
    f->rtr = false;
    (void)co_node_send(node, f);
}

void sdo_reply(co_node_t *node, const uint8_t d[8])
{
    co_frame_t f;
    memcpy(f.data, d, 8);
    sdo_send(node, &f);
}

void sdo_reply_head(co_node_t *node, uint8_t cmd, const uint8_t *req, uint32_t val)
{
    co_frame_t f;
    f.data[0] = cmd;
    f.data[1] = req[1];
    f.data[2] = req[2];
    f.data[3] = req[3];
    co_put_u32(&f.data[4], val);
    sdo_send(node, &f);
}

void sdo_abort(co_node_t *node, const uint8_t *mux, co_res_t r)
{
    uint8_t m[4] = {0, 0, 0, 0};
    if (mux == NULL) {
        if (node->sdo.state != SDO_IDLE) {
            sdo_mux(&node->sdo, m);
        }
        mux = m;
    }
    node->sdo.state = SDO_IDLE;
    sdo_reply_head(node, 0x80, mux, co_res_abort_code(r));
}

/* Command byte placeholder and multiplexer of the transfer in progress,
 * laid out like a request so that abort replies can echo it. */
void sdo_mux(const co_sdo_t *sdo, uint8_t mux[4])
{
    mux[0] = 0;
    mux[1] = (uint8_t)sdo->e->index;
    mux[2] = (uint8_t)(sdo->e->index >> 8);
    mux[3] = sdo->e->sub;
}

void sdo_restart(co_sdo_t *sdo)
{
    sdo->restart = true;
}

/* The object a request's multiplexer names, or NULL after the abort. */
const co_od_entry_t *sdo_find(co_node_t *node, const uint8_t *d)
{
    co_res_t r;
    const co_od_entry_t *e = co_od_find(co_cfg(node)->od, co_get_u16(&d[1]), d[3], &r);
    if (e == NULL) {
        sdo_abort(node, d, r);
    }
    return e;
}

/*
 * The object a download initiate (segmented or block) names: it must exist,
 * be writable, fit the buffer, and match an indicated size; a DOMAIN, which
 * streams through the buffer, must be taken by its handler (a size
 * indicated is the handler's to check against what arrives). NULL after
 * answering with the abort.
 */
const co_od_entry_t *sdo_download_target(co_node_t *node, const uint8_t *d, bool sized)
{
    const co_od_entry_t *e = sdo_find(node, d);
    if (e == NULL) {
        return NULL;
    }
    uint32_t size = co_get_u32(&d[4]);
    co_res_t r = (e->attr & CO_A_W) == 0u        ? CO_E_RO
                 : e->type == CO_T_DOMAIN        ? sdo_domain_begin(node, e)
                 : sized && size > co_od_size(e) ? CO_E_LEN_HIGH
                 : sized && size < co_od_size(e) ? CO_E_LEN_LOW
                 : co_od_size(e) > CO_SDO_BUF    ? CO_E_OOM
                                                 : CO_OK;
    if (r != CO_OK) {
        sdo_abort(node, d, r);
        return NULL;
    }
    return e;
}

/*
 * A download initiate: expedited, or segmented where the product links no
 * segmented protocol (sdo_segment.c). Every object of such a product fits
 * 4 bytes (the DSTs), and CiA 301 lets a client send any object segmented,
 * so the server takes it here: 0x60, then segments of at most 4 bytes in
 * all into sdo->buf (short_segment), written as one expedited request
 * would be. A size indicated is checked against the object's at once, as
 * sdo_segment.c does (06070012h / 06070013h); the bytes received are then
 * checked by the write itself, against the same size, with the same codes.
 */
static void download_initiate(co_node_t *node, const uint8_t *d)
{
    const co_od_entry_t *e = sdo_find(node, d);
    if (e == NULL) {
        return;
    }
    co_sdo_t *sdo = &node->sdo;
    sdo->e = e;
    uint32_t size = co_od_size(e);
    uint32_t given = co_get_u32(&d[4]);
    co_res_t r = (e->attr & CO_A_W) == 0u                   ? CO_E_RO
                 : e->type == CO_T_DOMAIN                   ? sdo_domain_begin(node, e)
                 : (d[0] & 0x03u) != 0x01u || given == size ? CO_OK
                 : given > size                             ? CO_E_LEN_HIGH
                                                            : CO_E_LEN_LOW;
    if (r != CO_OK) {
        sdo_abort(node, d, r);
    } else if ((d[0] & 0x02u) != 0u) {
        /* Size not indicated (0x22): the object's own size, at most 4. */
        uint32_t len = (d[0] & 0x01u) != 0u ? 4u - ((d[0] >> 2) & 0x03u) : co_min_u32(size, 4u);
        co_sdo_domain_fn fn = co_cfg(node)->sdo_domain;
        if (fn != NULL && e->type == CO_T_DOMAIN) {
            /* Begun above (sdo_domain_begin): these bytes are all of it; a
             * DOMAIN has no size of its own, so 4 where none is indicated. */
            r = fn(node, e, 0, &d[4], (d[0] & 0x01u) != 0u ? len : 4u, true);
        } else {
            r = co_node_write(node, e, &d[4], len);
        }
        if (r != CO_OK) {
            sdo_abort(node, d, r);
        } else {
            sdo_reply_head(node, 0x60, d, 0);
        }
    } else {
        sdo->state = SDO_DOWNLOAD;
        sdo->pos = 0;
        sdo->toggle = 0;
        sdo_restart(sdo);
        sdo_reply_head(node, 0x60, d, 0);
    }
}

/* The answer's bytes 1..3 after a download segment (reserved, 0). */
static const uint8_t no_mux[4] = {0, 0, 0, 0};

/*
 * A download segment of a transfer download_initiate() began. Toggle bit
 * wrong: 05030000h; more than 4 bytes in all: 06070012h, as an expedited
 * write of that length to any object of the product (none is longer).
 * The cost of this path and download_initiate's segmented branch: 268
 * bytes of the DST X730 image's flash on the Cortex-M0 (sdo_segment.c,
 * which would also bring upload, is 504).
 */
static void short_segment(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    uint8_t mux[4];
    sdo_mux(sdo, mux);
    uint32_t n = 7u - ((d[0] >> 1) & 0x07u);
    uint8_t ok = (uint8_t)(0x20u | sdo->toggle);
    sdo->toggle ^= 0x10u;
    sdo_restart(sdo);
    if ((d[0] & 0x10u) != (ok & 0x10u)) {
        sdo_abort(node, mux, CO_E_TOGGLE);
    } else if (sdo->pos + n > 4u) {
        sdo_abort(node, mux, CO_E_LEN_HIGH);
    } else {
        memcpy(&sdo->buf[sdo->pos], &d[1], n);
        sdo->pos += n;
        if ((d[0] & 0x01u) == 0u) { /* more follow */
            sdo_reply_head(node, ok, no_mux, 0);
            return;
        }
        sdo->state = SDO_IDLE;
        co_res_t r = co_node_write(node, sdo->e, sdo->buf, sdo->pos);
        if (r != CO_OK) {
            sdo_abort(node, mux, r);
        } else {
            sdo_reply_head(node, ok, no_mux, 0);
        }
    }
}

/* An upload; false when the object needs the segmented protocol. */
static bool upload_expedited(co_node_t *node, const uint8_t *d, const co_od_entry_t *e)
{
    uint32_t size = co_od_size(e);
    if (size > 4u) {
        return false;
    }
    uint32_t v = 0;
    co_res_t r;
    if (e->type == CO_T_VSTR) { /* a short string */
        uint8_t b[4] = {0, 0, 0, 0};
        uint32_t len;
        r = co_od_read(node, e, 0, b, 4, &len);
        v = co_get_u32(b);
    } else {
        r = (e->attr & CO_A_R) == 0u ? CO_E_WO : co_od_get(node, e, &v);
    }
    if (r != CO_OK) {
        sdo_abort(node, d, r);
        return true;
    }
    if (size < 4u) {
        v &= (1u << (8u * size)) - 1u; /* only the object's own bytes */
    }
    /* Expedited, size indicated (0x4F / 0x4B / 0x47 / 0x43). */
    sdo_reply_head(node, (uint8_t)(0x43u | ((4u - size) << 2)), d, v);
    return true;
}

/* The optional protocols (segmented, block) where the product links them.
 * A request none takes is aborted with mux: the request's own when it
 * names an object (an initiate), NULL when not (sdo_abort). */
static void optional(co_node_t *node, const uint8_t *d, co_sdo_proto_fn proto, const uint8_t *mux)
{
    if (proto == NULL || !proto(node, d)) {
        sdo_abort(node, mux, CO_E_CMD);
    }
}

/* Not inlined into co_node_receive, its one caller: there its frame and
 * saved registers cost every other frame too (the JD2 SYNC on the
 * Cortex-M0: 3 instructions). */
CO_NOINLINE void co_sdo_receive(co_node_t *node, const co_frame_t *f)
{
    /* The CAN-ID is the node's to check (co_node_receive), once. */
    if (f->rtr || f->dlc != 8u || !co_nmt_sdo_allowed(node->nmt.state)) {
        return; /* CiA 301: SDO frames are 8 bytes; no SDO in stopped */
    }
    node->store.sdo_at = node->now; /* the store's flash work waits for a pause (co_store_poll) */
    const uint8_t *d = f->data;
    co_sdo_t *sdo = &node->sdo;
    /* During a sub-block every frame is a segment: only 0x80 (sequence 0,
     * which no segment has) is the client's abort there. */
    bool abort = sdo->state == SDO_BLK_DL ? d[0] == 0x80u : (d[0] >> 5) == CCS_ABORT;
    if (abort) {
        sdo->state = SDO_IDLE; /* the client gave up; no answer */
        return;
    }
    if (sdo->state >= SDO_BLK_DL && co_cfg(node)->sdo_block != NULL) {
        (void)co_cfg(node)->sdo_block(node, d); /* a block transfer in progress */
        return;
    }
    co_sdo_proto_fn seg = co_cfg(node)->sdo_segmented;
    /* Before the switch: a case of its own for download segments cost a
     * jump table (20 bytes on the Cortex-M0), the check inside the shared
     * segment case 32; this one costs every request 2 instructions there. */
    if (seg == NULL && sdo->state == SDO_DOWNLOAD && (d[0] >> 5) == CCS_DOWNLOAD_SEGMENT) {
        short_segment(node, d); /* a transfer download_initiate() began */
        return;
    }
    switch (d[0] >> 5) {
    case CCS_DOWNLOAD_INITIATE:
        sdo->state = SDO_IDLE; /* a new request replaces an unfinished one */
        if ((d[0] & 0x02u) != 0u || seg == NULL) {
            download_initiate(node, d);
        } else {
            optional(node, d, seg, d);
        }
        break;
    case CCS_UPLOAD_INITIATE: {
        sdo->state = SDO_IDLE;
        const co_od_entry_t *e = sdo_find(node, d);
        if (e != NULL && !upload_expedited(node, d, e)) {
            optional(node, d, seg, d);
        }
        break;
    }
    case CCS_DOWNLOAD_SEGMENT:
    case CCS_UPLOAD_SEGMENT:
        optional(node, d, seg, NULL);
        break;
    case CCS_BLOCK_DOWNLOAD: /* its initiate has bit 0 clear */
    case CCS_BLOCK_UPLOAD:   /* its initiate has bits 1..0 clear */
        optional(node, d, co_cfg(node)->sdo_block,
                 (d[0] & ((d[0] >> 5) == CCS_BLOCK_UPLOAD ? 3u : 1u)) == 0u ? d : NULL);
        break;
    default:
        sdo_abort(node, NULL, CO_E_CMD); /* reserved command specifier */
        break;
    }
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
        sdo_abort(node, NULL, CO_E_TIMEOUT);
        return CO_NEVER;
    }
    return sdo->deadline - now;
}
