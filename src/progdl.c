/*
 * progdl.c - CiA 302-3 program download, the loader side: 1F51h program
 * control, 1F56h and 1F57h, and the image streamed into 1F50h to the
 * board's program area. The state machine and the refusals are described
 * in co_progdl.h; the state is the board's co_progdl_t (co_port_progdl).
 */
#include "co_progdl.h"

#include <string.h>

#include "co_port.h"

/* Where the download is (co_progdl_t.phase). */
enum {
    PH_IDLE = 0, /* no download may begin: clear first */
    PH_CLEARED,  /* cleared: one download may begin */
    PH_WRITING,  /* a download has begun */
    PH_VERIFY,   /* the image is in: re-read from flash (1F57h busy) */
};

/* What waits for the answer to have gone out (co_progdl_t.pending). */
enum {
    PEND_NONE = 0,
    PEND_START,
    PEND_STOP,
};

void co_progdl_init(co_progdl_t *pd, uint8_t state, uint32_t program_id)
{
    memset(pd, 0, sizeof(*pd));
    if (!CO_CHECK(state == CO_PROGDL_STOPPED || state == CO_PROGDL_STARTED ||
                  state == CO_PROGDL_NO_PROGRAM)) {
        state = CO_PROGDL_NO_PROGRAM;
    }
    pd->state = state;
    pd->program_id = state == CO_PROGDL_NO_PROGRAM ? 0u : program_id;
    pd->status = state == CO_PROGDL_NO_PROGRAM ? CO_PROGDL_NO_VALID : CO_PROGDL_OK;
}

uint32_t co_progdl_flash_status(const co_progdl_t *pd)
{
    return ((uint32_t)pd->status << 1) | (pd->phase == PH_VERIFY ? 1u : 0u);
}

/* The board's state of this node's loader. */
static co_progdl_t *progdl(const co_node_t *node)
{
    return co_port_progdl(node->port);
}

/* An action that changes something is taken in pre-operational only (CiA
 * 302-3: the master updates a node it has not started), and not while the
 * check of a downloaded image runs. */
static bool can_act(const co_node_t *node, const co_progdl_t *pd)
{
    return node->nmt.state == CO_NMT_PREOP && pd->phase != PH_VERIFY;
}

/* A failure that leaves no program: the status says why; a new download
 * needs a clear. */
static co_res_t fail(co_progdl_t *pd, uint8_t status, co_res_t r)
{
    pd->status = status;
    pd->phase = PH_IDLE;
    pd->state = CO_PROGDL_NO_PROGRAM;
    pd->program_id = 0;
    return r;
}

co_res_t co_progdl_write_control(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    (void)e;
    co_progdl_t *pd = progdl(node);
    switch (value) {
    case CO_PROGDL_STOPPED: /* stop */
        if (pd->state != CO_PROGDL_STARTED) {
            return CO_OK; /* nothing runs */
        }
        if (node->nmt.state != CO_NMT_PREOP) {
            return CO_E_STATE;
        }
        pd->pending = PEND_STOP;
        break;
    case CO_PROGDL_STARTED: /* start */
        if (pd->state == CO_PROGDL_STARTED) {
            return CO_OK;
        }
        if (!can_act(node, pd) || pd->state != CO_PROGDL_STOPPED) {
            return CO_E_STATE; /* no verified program to start */
        }
        pd->pending = PEND_START;
        break;
    case 3u: /* clear */
        if (!can_act(node, pd) || pd->state == CO_PROGDL_STARTED) {
            return CO_E_STATE;
        }
        pd->pending = PEND_NONE; /* a start not yet done has nothing to start */
        if (!co_port_prog_clear(node->port)) {
            return fail(pd, CO_PROGDL_FLASH, CO_E_HW);
        }
        (void)fail(pd, CO_PROGDL_OK, CO_OK);
        pd->phase = PH_CLEARED;
        return CO_OK;
    default: /* 2, reset, and what CiA 302-3 does not define */
        return CO_E_VAL;
    }
    co_node_wake(node); /* the poll acts once the answer is out */
    return CO_OK;
}

co_res_t co_progdl_read_control(co_node_t *node, const co_od_entry_t *e, uint32_t *value)
{
    (void)e;
    *value = progdl(node)->state;
    return CO_OK;
}

co_res_t co_progdl_read_id(co_node_t *node, const co_od_entry_t *e, uint32_t *value)
{
    (void)e;
    *value = progdl(node)->program_id;
    return CO_OK;
}

co_res_t co_progdl_read_status(co_node_t *node, const co_od_entry_t *e, uint32_t *value)
{
    (void)e;
    *value = co_progdl_flash_status(progdl(node));
    return CO_OK;
}

/* The node's own value of (index, sub), what a master reads there. */
static uint32_t own(co_node_t *node, uint16_t index, uint8_t sub)
{
    uint32_t v = 0;
    const co_od_entry_t *x = co_node_entry(node, index, sub);
    if (x != NULL) {
        (void)co_od_get(node, x, &v);
    }
    return v;
}

/* The header is in (pd->raw): the 1F57h status it earns. */
static uint8_t check_header(co_node_t *node, co_progdl_t *pd)
{
    co_image_hdr_t *h = &pd->hdr;
    if (!co_image_parse(pd->raw, h)) {
        return CO_PROGDL_UNKNOWN;
    }
    if (h->device_type != own(node, 0x1000, 0) || h->vendor != own(node, 0x1018, 1) ||
        h->product != own(node, 0x1018, 2)) {
        return CO_PROGDL_FORMAT; /* another device's image */
    }
    return co_port_prog_check(node->port, h);
}

/* Write the n bytes at b, image offset at, to the board's area. */
static co_res_t put(co_node_t *node, co_progdl_t *pd, uint32_t at, const uint8_t *b, uint32_t n)
{
    if (n == 0u) {
        return CO_OK;
    }
    if (at + n > pd->hdr.length) {
        return fail(pd, CO_PROGDL_FORMAT, CO_E_STORE); /* longer than its header says */
    }
    if (!co_port_prog_write(node->port, at, b, n)) {
        return fail(pd, CO_PROGDL_FLASH, CO_E_HW);
    }
    pd->crc = co_crc32(pd->crc, b, n);
    return CO_OK;
}

/* The n bytes at b of the image, from pd->pos on. The header's bytes wait
 * in pd->raw until it is whole and checked: nothing of an image refused
 * reaches the flash. */
static co_res_t take(co_node_t *node, co_progdl_t *pd, const uint8_t *b, uint32_t n)
{
    if (pd->pos < CO_IMAGE_HDR_SIZE) {
        uint32_t k = co_min_u32(n, CO_IMAGE_HDR_SIZE - pd->pos);
        memcpy(&pd->raw[pd->pos], b, k);
        pd->pos += k;
        b += k;
        n -= k;
        if (pd->pos < CO_IMAGE_HDR_SIZE) {
            return CO_OK;
        }
        uint8_t status = check_header(node, pd);
        if (status != CO_PROGDL_OK) {
            return fail(pd, status, CO_E_STORE);
        }
        /* The CRC starts after its own field (co_image.h). */
        if (!co_port_prog_write(node->port, 0, pd->raw, CO_IMAGE_HDR_SIZE)) {
            return fail(pd, CO_PROGDL_FLASH, CO_E_HW);
        }
        pd->crc = co_crc32(0, &pd->raw[CO_IMAGE_CRC_FROM], CO_IMAGE_HDR_SIZE - CO_IMAGE_CRC_FROM);
    }
    co_res_t r = put(node, pd, pd->pos, b, n);
    pd->pos += n;
    return r;
}

co_res_t co_progdl_domain(co_node_t *node, const co_od_entry_t *e, uint32_t at, const uint8_t *buf,
                          uint32_t len, bool end)
{
    (void)e;
    co_progdl_t *pd = progdl(node);
    if (len == 0u && !end) { /* a download begins */
        if (!can_act(node, pd) || pd->state == CO_PROGDL_STARTED) {
            return CO_E_STATE;
        }
        if (pd->phase != PH_CLEARED) {
            pd->status = CO_PROGDL_NOT_CLEARED;
            return CO_E_STATE;
        }
        pd->phase = PH_WRITING;
        pd->pos = 0;
        pd->crc = 0;
        return CO_OK;
    }
    /* The server hands the pieces in order (co_sdo_domain_fn): at is pos. */
    if (pd->phase != PH_WRITING || at != pd->pos) {
        return fail(pd, CO_PROGDL_UNSPECIFIED, CO_E_STATE);
    }
    co_res_t r = take(node, pd, buf, len);
    if (r != CO_OK || !end) {
        return r;
    }
    if (pd->pos < CO_IMAGE_HDR_SIZE || pd->pos != pd->hdr.length) {
        return fail(pd, CO_PROGDL_FORMAT, CO_E_STORE); /* truncated */
    }
    if (pd->crc != pd->hdr.crc) {
        return fail(pd, CO_PROGDL_FORMAT, CO_E_STORE);
    }
    /* Whole and its CRC right as it came: now as the flash holds it. */
    pd->phase = PH_VERIFY;
    pd->pos = 0;
    pd->crc = 0;
    co_node_wake(node);
    return CO_OK;
}

/* One step of the check after the download: CO_PROGDL_VERIFY_STEP bytes
 * re-read, the header's against what came, the rest into the CRC; at the
 * end the image becomes the installed program. */
static void verify_step(co_node_t *node, co_progdl_t *pd)
{
    uint8_t b[CO_PROGDL_VERIFY_STEP];
    uint32_t n = co_min_u32(CO_PROGDL_VERIFY_STEP, pd->hdr.length - pd->pos);
    if (!co_port_prog_read(node->port, pd->pos, b, n)) {
        (void)fail(pd, CO_PROGDL_FLASH, CO_E_HW);
        return;
    }
    uint32_t hdr = pd->pos < CO_IMAGE_HDR_SIZE ? co_min_u32(n, CO_IMAGE_HDR_SIZE - pd->pos) : 0u;
    /* Past the header hdr is 0, and so is the comparison: raw is not
     * indexed there (its address past the end was undefined behaviour,
     * caught by UBSan in the clang build). */
    if (hdr != 0u && memcmp(b, &pd->raw[pd->pos], hdr) != 0) {
        (void)fail(pd, CO_PROGDL_FLASH, CO_E_HW); /* the header is not what came */
        return;
    }
    /* The CRC from its start on (co_image.h). */
    uint32_t skip = pd->pos < CO_IMAGE_CRC_FROM ? co_min_u32(n, CO_IMAGE_CRC_FROM - pd->pos) : 0u;
    pd->crc = co_crc32(pd->crc, &b[skip], n - skip);
    pd->pos += n;
    if (pd->pos < pd->hdr.length) {
        return;
    }
    if (pd->crc != pd->hdr.crc || !co_port_prog_commit(node->port, &pd->hdr)) {
        (void)fail(pd, CO_PROGDL_FLASH, CO_E_HW);
        return;
    }
    pd->phase = PH_IDLE;
    pd->state = CO_PROGDL_STOPPED;
    pd->program_id = pd->hdr.program_id;
    pd->status = CO_PROGDL_OK;
}

/* The service's poll: what the answers left to do. */
static uint32_t progdl_poll(co_node_t *node, uint32_t now)
{
    (void)now;
    co_progdl_t *pd = progdl(node);
    uint8_t p = pd->pending;
    pd->pending = PEND_NONE;
    if (p == PEND_START) {
        pd->state = CO_PROGDL_STARTED;
        co_port_prog_start(node->port);
    } else if (p == PEND_STOP) {
        pd->state = CO_PROGDL_STOPPED;
        co_port_prog_stop(node->port);
    }
    if (pd->phase == PH_VERIFY) {
        verify_step(node, pd);
        return pd->phase == PH_VERIFY ? 0u : CO_NEVER; /* the next step at once */
    }
    return CO_NEVER;
}

const co_service_t co_progdl_service = {
    .receive = NULL,
    .poll = progdl_poll,
    .reset = NULL,
    .always = false,
};
