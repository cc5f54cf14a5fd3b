/*
 * sdo_segment.c - SDO segmented transfer (CiA 301 7.2.4.3.3-7), optional:
 * linked where a product's config sets .sdo_segmented = co_sdo_segmented.
 * A product whose objects all fit 4 bytes may leave it out (the DSTs: the
 * manuals use expedited transfer only); the server then takes segmented
 * downloads of up to 4 bytes itself (sdo.c) and answers the other
 * segmented requests with abort 0x05040001.
 */
#include <string.h>

#include "co_sdo.h"
#include "sdo_internal.h"

/* A transfer of object e begins: the initiate request d is answered. */
static bool begin(co_node_t *node, const uint8_t *d, uint8_t state, const co_od_entry_t *e)
{
    co_sdo_t *sdo = &node->sdo;
    sdo->state = state;
    sdo->e = e;
    sdo->size = co_od_size(e);
    sdo->pos = 0;
    sdo->toggle = 0;
    sdo_restart(sdo);
    /* Download: 0x60; upload: 0x41 with the size indicated. */
    sdo_reply_head(node, state == SDO_DOWNLOAD ? 0x60 : 0x41, d,
                   state == SDO_DOWNLOAD ? 0u : sdo->size);
    return true;
}

static bool initiate_download(co_node_t *node, const uint8_t *d)
{
    const co_od_entry_t *e = sdo_download_target(node, d, (d[0] & 0x01u) != 0u);
    return e == NULL || begin(node, d, SDO_DOWNLOAD, e);
}

/* A segment of a DOMAIN's download (co_sdo_domain_fn), n bytes: the
 * handler has the last ones before the answer. */
static void domain_segment(co_node_t *node, const uint8_t *d, const uint8_t mux[4], uint32_t n)
{
    co_sdo_t *sdo = &node->sdo;
    bool last = (d[0] & 0x01u) != 0u;
    co_res_t r = sdo_domain_take(node, &d[1], n);
    if (r == CO_OK && last) {
        r = sdo_domain_hand(node, true);
    }
    if (r != CO_OK) {
        sdo_abort(node, mux, r);
        return;
    }
    uint8_t ack[8] = {(uint8_t)(0x20u | sdo->toggle), 0, 0, 0, 0, 0, 0, 0};
    sdo->toggle ^= 0x10u;
    if (last) {
        sdo->state = SDO_IDLE;
    } else {
        sdo_restart(sdo);
    }
    sdo_reply(node, ack);
}

/* A segment with the expected toggle bit; mux names the transfer. */
static void download_segment(co_node_t *node, const uint8_t *d, const uint8_t mux[4])
{
    co_sdo_t *sdo = &node->sdo;
    uint32_t n = 7u - ((d[0] >> 1) & 0x07u);
    if (sdo->e->type == CO_T_DOMAIN) {
        domain_segment(node, d, mux, n);
        return;
    }
    if (sdo->pos + n > sdo->size) {
        sdo_abort(node, mux, CO_E_LEN_HIGH);
        return;
    }
    memcpy(&sdo->buf[sdo->pos], &d[1], n);
    sdo->pos += n;
    uint8_t ack[8] = {(uint8_t)(0x20u | sdo->toggle), 0, 0, 0, 0, 0, 0, 0};
    sdo->toggle ^= 0x10u;
    if ((d[0] & 0x01u) == 0u) { /* more segments follow */
        sdo_restart(sdo);
        sdo_reply(node, ack);
        return;
    }
    sdo->state = SDO_IDLE;
    if (sdo->pos != sdo->size) {
        /* Fewer bytes than the object: more were refused segment by segment above. */
        sdo_abort(node, mux, CO_E_LEN_LOW);
        return;
    }
    co_res_t r = co_node_write(node, sdo->e, sdo->buf, sdo->pos);
    if (r != CO_OK) {
        sdo_abort(node, mux, r);
        return;
    }
    sdo_reply(node, ack);
}

/* An object of more than 4 bytes (the server answered the others). */
static bool initiate_upload(co_node_t *node, const uint8_t *d)
{
    const co_od_entry_t *e = sdo_find(node, d);
    if (e == NULL) {
        return true;
    }
    if ((e->attr & CO_A_R) == 0u) {
        sdo_abort(node, d, CO_E_WO);
        return true;
    }
    return begin(node, d, SDO_UPLOAD, e);
}

/* A segment with the expected toggle bit. The object is a readable string
 * (initiate_upload: numbers fit 4 bytes), whose read cannot fail. */
static void upload_segment(co_node_t *node)
{
    co_sdo_t *sdo = &node->sdo;
    co_frame_t f; /* the answer, built in place (sdo_send) */
    uint8_t *out = f.data;
    uint32_t n;
    (void)co_od_read(node, sdo->e, sdo->pos, &out[1], 7, &n);
    for (uint32_t k = 1u + n; k < 8u; k++) {
        out[k] = 0; /* unused bytes of a last segment (a memset of all 8 cost 45) */
    }
    sdo->pos += n;
    bool last = sdo->pos >= sdo->size;
    out[0] = (uint8_t)(sdo->toggle | ((7u - n) << 1) | (last ? 1u : 0u));
    sdo->toggle ^= 0x10u;
    if (last) {
        sdo->state = SDO_IDLE;
    } else {
        sdo_restart(sdo);
    }
    sdo_send(node, &f);
}

bool co_sdo_segmented(co_node_t *node, const uint8_t *d)
{
    co_sdo_t *sdo = &node->sdo;
    switch (d[0] >> 5) {
    case CCS_DOWNLOAD_INITIATE:
        return initiate_download(node, d);
    case CCS_UPLOAD_INITIATE:
        return initiate_upload(node, d);
    case CCS_DOWNLOAD_SEGMENT:
    case CCS_UPLOAD_SEGMENT: {
        /* A segment belongs to the transfer in progress, of the same direction. */
        bool download = (d[0] >> 5) == CCS_DOWNLOAD_SEGMENT;
        if (sdo->state != (download ? SDO_DOWNLOAD : SDO_UPLOAD)) {
            sdo_abort(node, NULL, CO_E_CMD);
            return true;
        }
        uint8_t mux[4];
        sdo_mux(sdo, mux);
        if ((d[0] & 0x10u) != sdo->toggle) {
            sdo_abort(node, mux, CO_E_TOGGLE);
        } else if (download) {
            download_segment(node, d, mux);
        } else {
            upload_segment(node);
        }
        return true;
    }
    default:
        return false;
    }
}
