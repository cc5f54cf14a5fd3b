/*
 * sdo.c - SDO server: expedited transfer, the dispatch to the
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
 * be writable, fit the buffer, and match an indicated size. NULL after
 * answering with the abort.
 */
const co_od_entry_t *sdo_download_target(co_node_t *node, const uint8_t *d, bool sized)
{
    const co_od_entry_t *e = sdo_find(node, d);
    if (e == NULL) {
        return NULL;
    }
    uint32_t size = co_get_u32(&d[4]);
    co_res_t r = (e->attr & CO_A_W) == 0u           ? CO_E_RO
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

static void download_expedited(co_node_t *node, const uint8_t *d)
{
    const co_od_entry_t *e = sdo_find(node, d);
    if (e == NULL) {
        return;
    }
    if ((e->attr & CO_A_W) == 0u) {
        sdo_abort(node, d, CO_E_RO);
        return;
    }
    /* Size not indicated (0x22): the object's own size, at most 4. */
    uint32_t len = (d[0] & 0x01u) != 0u ? 4u - ((d[0] >> 2) & 0x03u)
                                         : co_min_u32(co_od_size(e), 4u);
    co_res_t r = co_node_write(node, e, &d[4], len);
    if (r != CO_OK) {
        sdo_abort(node, d, r);
    } else {
        sdo_reply_head(node, 0x60, d, 0);
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

/* The optional protocols (segmented, block) where the product links them. */
static void optional(co_node_t *node, const uint8_t *d, co_sdo_proto_fn proto)
{
    if (proto == NULL || !proto(node, d)) {
        sdo_abort(node, d, CO_E_CMD);
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
    switch (d[0] >> 5) {
    case CCS_DOWNLOAD_INITIATE:
        sdo->state = SDO_IDLE; /* a new request replaces an unfinished one */
        if ((d[0] & 0x02u) != 0u) {
            download_expedited(node, d);
        } else {
            optional(node, d, co_cfg(node)->sdo_segmented);
        }
        break;
    case CCS_UPLOAD_INITIATE: {
        sdo->state = SDO_IDLE;
        const co_od_entry_t *e = sdo_find(node, d);
        if (e != NULL && !upload_expedited(node, d, e)) {
            optional(node, d, co_cfg(node)->sdo_segmented);
        }
        break;
    }
    case CCS_DOWNLOAD_SEGMENT:
    case CCS_UPLOAD_SEGMENT:
        optional(node, d, co_cfg(node)->sdo_segmented);
        break;
    case CCS_BLOCK_DOWNLOAD:
    case CCS_BLOCK_UPLOAD:
        optional(node, d, co_cfg(node)->sdo_block);
        break;
    default:
        sdo_abort(node, d, CO_E_CMD); /* reserved command specifier */
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
        uint8_t mux[4];
        sdo_mux(sdo, mux);
        sdo_abort(node, mux, CO_E_TIMEOUT);
        return CO_NEVER;
    }
    return sdo->deadline - now;
}
