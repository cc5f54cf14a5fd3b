/*
 * boot_main.c - the bootloader of the MCU boards (boot.h): decide at reset
 * whether the application runs, and otherwise take a new image over CiA
 * 302-3 program download into the board's application area.
 *
 * At reset, before any peripheral is touched (so that the application
 * starts from the state a reset leaves): without a hand-over block in RAM,
 * an application whose header and CRC check runs at once. Otherwise the
 * bootloader stays: identity from the hand-over (written to the boot-info
 * page when that holds another), else from the boot-info page, else the
 * defaults (boot.h); then it boots up and answers with the product's
 * 1000h and 1018h, 1F51h:1 reading 0 (stopped: a valid program is
 * installed) or 3 (none), 1F57h status 0 or 1 ("no valid program").
 *
 * Not the stack's node: a Cortex-M0 bootloader has 4 KiB, and the stack's
 * node with its SDO server and the loader service (src/progdl.c, which the
 * Linux program runs) measures over 13 KB there. This is the part of
 * CiA 301 and 302-3 a loader needs, written for size, with the same
 * states, answers and aborts as progdl.c (co_progdl.h) so that a master
 * sees one behaviour on every target:
 *  - NMT: start, stop, enter pre-operational, reset communication (the
 *    boot-up again, 1017h back to 0, a transfer dropped), reset node (the
 *    device reset: a valid application then runs, the hand-over taken).
 *    Frames of DLC 2 only, as the stack's NMT slave.
 *  - Heartbeat: 1017h (0 at every boot: the bootloader stores nothing).
 *  - SDO server, frames of DLC 8 in pre-operational and operational:
 *    expedited upload of every readable object (none is longer than 4
 *    bytes, so no segmented or block upload: 05040001h); expedited,
 *    segmented and block download. A block download's answer says the
 *    server computes no CRC (CiA 301's sc bit 0, which every client
 *    takes): the image carries its CRC-32 end to end, checked before it
 *    is installed and at every reset. A segmented or block download
 *    of an object other than the DOMAIN 1F50h:1 is refused with
 *    06070010h; a transfer idle for 1 s is aborted with 05040000h.
 *  - Dictionary: 1000h, 1001h (0), 1017h, 1018h:0-4, 1F50h-1F51h,
 *    1F56h-1F57h (sub 0 const 1), as the loader side's table lines.
 *
 * The image is written as it streams in: the first write into a page
 * erases it, and a block is programmed before its acknowledge (18
 * segments, 126 bytes), so no SDO answer waits for more than one page
 * erase and a block's bytes. A clear erases the first page alone, which
 * holds the header: from then on the area holds no valid program, and a
 * power cut before the new image is whole leaves a bootloader that stays.
 * A start resets the device once its answer is on the bus: the
 * application then runs from the reset, its image checked again.
 *
 * The board's state lives here, in static storage (board code, not the
 * stack: the stack holds no globals).
 */
#include "board.h"
#include "boot.h"
#include "co_image.h"
#include "co_progdl.h"

#include <string.h>

#define NMT_STOPPED 4u
#define NMT_OP 5u
#define NMT_PREOP 0x7Fu

#define BLK_SEGS 18u              /* segments of a block */
#define BLK_BYTES (BLK_SEGS * 7u) /* 126 */
#define SDO_IDLE_US 1000000u      /* a transfer's timeout */
#define POLL_US 10000u            /* the loop's longest sleep */

/* Where the download is (progdl.c's phases). */
enum { PH_IDLE = 0, PH_CLEARED, PH_WRITING, PH_VERIFY };

/* The SDO transfer under way. */
enum { SDO_NONE = 0, SDO_SEG, SDO_BLK, SDO_BLK_END };

/* Its byte fields first: Thumb-1 loads a byte at an offset below 32 from
 * the base in one instruction (a word below 128), which keeps the 4 KiB
 * Cortex-M0 bootloader within its flash. */
typedef struct boot {
    uint8_t node;   /* the node-ID (id.node_id) */
    uint8_t nmt;    /* NMT state, as the heartbeat says it */
    uint8_t state;  /* 1F51h:1 read */
    uint8_t err;    /* 1001h: always 0 */
    uint8_t phase;  /* PH_* */
    uint8_t sdo;    /* SDO_* */
    uint8_t toggle; /* segmented: the next segment's toggle bit */
    uint8_t seq;    /* block: segments of this block in order */
    uint8_t odd;    /* the byte waiting for its half-word's pair */
    bool last;      /* block: the last segment came */
    bool reset_due;
    uint16_t hb_ms;      /* 1017h */
    uint32_t program_id; /* 1F56h:1 */
    uint32_t flash;      /* 1F57h:1: status << 1, bit 0 busy (verifying) */
    uint32_t mux;        /* the transfer's index and sub (bytes 1-3) */
    uint32_t pos;        /* image bytes taken (verifying: re-read) */
    uint32_t crc;        /* co_crc32 of bytes CO_IMAGE_CRC_FROM .. pos - 1 */
    uint32_t erased;     /* offsets below this were erased by this clear */
    uint32_t hb_at;      /* the next heartbeat */
    uint32_t sdo_at;     /* the transfer's deadline */
    uint32_t reset_at;   /* a reset due */
    const flash_ee_t *area;
    co_image_hdr_t hdr;             /* the image's header, once whole and checked */
    boot_ident_t id;                /* 1000h, 1018h:1-4 (its words in that order) */
    uint8_t raw[CO_IMAGE_HDR_SIZE]; /* its bytes as they came */
    uint8_t buf[BLK_BYTES];         /* a block's segments */
    uint8_t hold[7];                /* block: the last segment, until the end says its length */
} boot_t;

static boot_t boot;

/* ---- frames ------------------------------------------------------------------ */

static void send(uint16_t id, const uint8_t *d, uint8_t dlc)
{
    co_frame_t f = {.id = id, .dlc = dlc};
    memcpy(f.data, d, dlc);
    (void)co_port_can_send(NULL, &f);
}

/* An SDO answer: command c, then bytes 1-3 (the object, or a block's
 * acknowledge), then v. */
static void sdo_send(const boot_t *b, uint8_t c, uint32_t w, uint32_t v)
{
    uint8_t d[8];
    co_put_u32(d, c | (w << 8));
    co_put_u32(&d[4], v);
    send((uint16_t)(0x580u + b->node), d, 8u);
}

/* The boot-up (and a reset communication's): pre-operational, 1017h 0,
 * no transfer. */
static CO_NOINLINE void boot_up(boot_t *b)
{
    b->nmt = NMT_PREOP;
    b->hb_ms = 0;
    b->sdo = SDO_NONE;
    send((uint16_t)(0x700u + b->node), &b->err, 1u);
}

/* ---- the image in the application area (progdl.c's rules) --------------------- */

/* The download's status (1F57h), busy cleared. Returns abort code r. */
static uint32_t status(boot_t *b, uint8_t st, uint32_t r)
{
    b->flash = (uint32_t)st << 1;
    return r;
}

/* A failure that leaves no program: the status says why; a new download
 * needs a clear. Returns abort code r. */
static CO_NOINLINE uint32_t fail(boot_t *b, uint8_t st, uint32_t r)
{
    b->phase = PH_IDLE;
    b->state = CO_PROGDL_NO_PROGRAM;
    b->program_id = 0;
    return status(b, st, r);
}

/* The byte v of the image at offset at into the flash, a half-word at a
 * time; the first write into a page erases it (the image comes in
 * order). */
static bool put8(boot_t *b, uint32_t at, uint8_t v)
{
    const flash_ee_t *a = b->area;
    if ((at & 1u) == 0u) {
        b->odd = v;
        if (at + 1u != b->hdr.length) {
            return true;
        }
        v = 0xFF; /* the image's last byte, alone in its half-word */
        at++;
    }
    if (at >= b->erased) {
        if (!a->ops->erase(a->ctx, a->base + b->erased)) {
            return false;
        }
        b->erased += a->page_size;
    }
    return a->ops->program16(a->ctx, a->base + at - 1u, (uint16_t)(b->odd | (uint16_t)(v << 8)));
}

/* The header in raw, parsed into hdr, for this board: the 1F57h status
 * it earns (progdl.c's and the board's). Not inlined: the reset's check
 * and the download's share it. */
static CO_NOINLINE uint8_t header(boot_t *b)
{
    return co_image_parse(b->raw, &b->hdr) ? board_boot_check(&b->hdr) : CO_PROGDL_UNKNOWN;
}

/* The header of a download is in: the status it earns, its identity too
 * (progdl.c's check_header, and the product ID). */
static uint8_t check_header(boot_t *b)
{
    const co_image_hdr_t *h = &b->hdr;
    uint8_t st = header(b);
    if (st == CO_PROGDL_OK &&
        (h->device_type != b->id.device_type || h->vendor != b->id.vendor ||
         h->product != b->id.product || memcmp(h->id, b->id.id, CO_IMAGE_ID_LEN) != 0)) {
        st = CO_PROGDL_FORMAT; /* another device's or product's image */
    }
    return st;
}

/* A download of 1F50h:1 begins: 0 or the abort code. */
static uint32_t dom_begin(boot_t *b)
{
    if (b->nmt != NMT_PREOP || b->phase == PH_VERIFY) {
        return CO_E_STATE;
    }
    if (b->phase != PH_CLEARED) {
        return status(b, CO_PROGDL_NOT_CLEARED, CO_E_STATE);
    }
    b->phase = PH_WRITING;
    b->pos = 0;
    b->crc = 0;
    return 0;
}

/* The n bytes at p of the image, from pos on: 0 or the abort code. The
 * header waits in raw until it is whole and checked: nothing of an image
 * refused reaches the flash. */
static CO_NOINLINE uint32_t dom_take(boot_t *b, const uint8_t *p, uint32_t n)
{
    if (b->phase != PH_WRITING) {
        return CO_E_STATE; /* failed before: the transfer ends */
    }
    for (uint32_t i = 0; i < n; i++) {
        uint32_t at = b->pos++;
        if (at >= CO_IMAGE_CRC_FROM) { /* the CRC starts after its own field */
            b->crc = co_crc32(b->crc, &p[i], 1u);
        }
        if (at < CO_IMAGE_HDR_SIZE) {
            b->raw[at] = p[i];
            if (at + 1u < CO_IMAGE_HDR_SIZE) {
                continue;
            }
            uint8_t st = check_header(b);
            if (st != CO_PROGDL_OK) {
                return fail(b, st, CO_E_STORE);
            }
            for (at = 0; at < CO_IMAGE_HDR_SIZE; at++) {
                if (!put8(b, at, b->raw[at])) {
                    return fail(b, CO_PROGDL_FLASH, CO_E_HW);
                }
            }
        } else if (at >= b->hdr.length) {
            return fail(b, CO_PROGDL_FORMAT, CO_E_STORE); /* longer than its header says */
        } else if (!put8(b, at, p[i])) {
            return fail(b, CO_PROGDL_FLASH, CO_E_HW);
        }
    }
    return 0;
}

/* The download's end: whole, its CRC right as it came; then re-read from
 * flash in the loop (verify, 1F57h busy). */
static uint32_t dom_end(boot_t *b)
{
    if (b->phase != PH_WRITING) {
        return CO_E_STATE;
    }
    if (b->pos < CO_IMAGE_HDR_SIZE || b->pos != b->hdr.length || b->crc != b->hdr.crc) {
        return fail(b, CO_PROGDL_FORMAT, CO_E_STORE); /* truncated, or its CRC wrong */
    }
    b->phase = PH_VERIFY;
    b->flash = 1u;
    b->pos = 0;
    b->crc = 0;
    return 0;
}

/* One step of the check of the image in the area (after a download, and
 * at reset): 64 bytes re-read into the CRC; at the end the image is the
 * installed program, or none. The header's first 16 bytes, which the CRC
 * does not cover, are parsed again at every reset before the image runs. */
static void verify(boot_t *b)
{
    uint8_t d[64];
    const flash_ee_t *a = b->area;
    uint32_t n = co_min_u32(sizeof d, b->hdr.length - b->pos);
    a->ops->read(a->ctx, a->base + b->pos, d, n);
    uint32_t skip = b->pos == 0u ? CO_IMAGE_CRC_FROM : 0u;
    b->crc = co_crc32(b->crc, &d[skip], n - skip);
    b->pos += n;
    if (b->pos < b->hdr.length) {
        return;
    }
    if (b->crc != b->hdr.crc) {
        (void)fail(b, CO_PROGDL_FLASH, 0);
        return;
    }
    b->phase = PH_IDLE;
    b->state = CO_PROGDL_STOPPED;
    b->program_id = b->hdr.program_id;
    (void)status(b, CO_PROGDL_OK, 0);
}

/* 1F51h:1 written (co_progdl.h): 0 or the abort code. */
static uint32_t control(boot_t *b, uint8_t v, uint32_t now)
{
    const flash_ee_t *a = b->area;
    if (v == CO_PROGDL_STOPPED) {
        return 0; /* nothing runs */
    }
    if (v != CO_PROGDL_STARTED && v != 3u) {
        return CO_E_VAL; /* 2, reset, and what CiA 302-3 does not define */
    }
    if (b->nmt != NMT_PREOP || b->phase == PH_VERIFY ||
        (v == CO_PROGDL_STARTED && b->state != CO_PROGDL_STOPPED)) {
        return CO_E_STATE; /* no verified program to start */
    }
    if (v == CO_PROGDL_STARTED) {
        b->reset_due = true; /* once the answer is on the bus: a frame at 10 kbit/s */
        b->reset_at = now + 20000u;
        return 0;
    }
    /* Clear: the page with the header erased. */
    b->erased = 0;
    if (a == NULL || !a->ops->erase(a->ctx, a->base)) {
        return fail(b, CO_PROGDL_FLASH, CO_E_HW);
    }
    b->erased = a->page_size;
    b->phase = PH_CLEARED;
    b->state = CO_PROGDL_NO_PROGRAM;
    b->program_id = 0;
    return status(b, CO_PROGDL_OK, 0);
}

/* ---- the dictionary -------------------------------------------------------------- */

#define ACC_R 0x10u
#define ACC_W 0x20u

/* An object: its highest sub-index (0: a variable), access and size of
 * its value (0: the DOMAIN), where the value is in boot_t: sub s of an
 * array at offset + 4 (s - 1). */
typedef struct obj {
    uint16_t index;
    uint8_t subs;
    uint8_t acc;
    uint16_t offset;
} obj_t;

static const obj_t dict[] = {
    {0x1000, 0, ACC_R | 4u, offsetof(boot_t, id.device_type)},
    {0x1001, 0, ACC_R | 1u, offsetof(boot_t, err)},
    {0x1017, 0, ACC_R | ACC_W | 2u, offsetof(boot_t, hb_ms)},
    {0x1018, 4, ACC_R | 4u, offsetof(boot_t, id.vendor)},
    {0x1F50, 1, ACC_W, 0},
    {0x1F51, 1, ACC_R | ACC_W | 1u, offsetof(boot_t, state)},
    {0x1F56, 1, ACC_R | 4u, offsetof(boot_t, program_id)},
    {0x1F57, 1, ACC_R | 4u, offsetof(boot_t, flash)},
};

/* ---- the SDO server ---------------------------------------------------------------- */

/* A request that begins a transfer: 0 (answered) or the abort code. */
static uint32_t request(boot_t *b, const uint8_t *d, uint32_t now)
{
    uint8_t c = d[0];
    uint8_t ccs = c >> 5;
    b->mux = co_get_u32(d) >> 8;
    uint16_t index = (uint16_t)b->mux;
    uint8_t sub = d[3];
    if ((ccs != 1u && ccs != 2u && ccs != 6u) || (ccs == 6u && (c & 1u) != 0u)) {
        return CO_E_CMD; /* a segment or a block's end of no transfer, a block upload, 7 */
    }
    const obj_t *o = dict;
    while (o->index != index) {
        if (++o == &dict[sizeof dict / sizeof dict[0]]) {
            return CO_E_NO_OBJ;
        }
    }
    if (sub > o->subs) {
        return CO_E_NO_SUB;
    }
    uint8_t acc = o->acc;
    const uint8_t *p = (const uint8_t *)b + o->offset + (sub != 0u ? 4u * (sub - 1u) : 0u);
    if (sub == 0u && o->subs != 0u) { /* an array's count: const */
        acc = ACC_R | 1u;
        p = &o->subs;
    }
    uint32_t size = acc & 7u;
    uint32_t v = co_get_u32(p) & (size == 4u ? 0xFFFFFFFFu : (1u << (8u * size)) - 1u);
    if (ccs == 2u) { /* upload: expedited, 4 - size bytes unused */
        if ((acc & ACC_R) == 0u) {
            return CO_E_WO;
        }
        sdo_send(b, (uint8_t)(0x43u | ((4u - size) << 2)), b->mux, v);
        return 0;
    }
    if ((acc & ACC_W) == 0u) {
        return CO_E_RO;
    }
    bool expedited = ccs == 1u && (c & 2u) != 0u;
    uint32_t r;
    if (size == 0u) { /* 1F50h:1 */
        r = dom_begin(b);
        if (r == 0u && expedited) {
            r = fail(b, CO_PROGDL_FORMAT, CO_E_STORE); /* 4 bytes: shorter than a header */
        }
    } else if (!expedited) {
        return CO_E_LEN; /* a basic type's value comes expedited */
    } else {
        uint32_t n = (c & 1u) != 0u ? 4u - ((c >> 2) & 3u) : size;
        if (n != size) {
            return n > size ? CO_E_LEN_HIGH : CO_E_LEN_LOW;
        }
        r = 0;
        if (index == 0x1017u) {
            b->hb_ms = co_get_u16(&d[4]);
            b->hb_at = now;
        } else {
            r = control(b, d[4], now);
        }
    }
    if (r != 0u) {
        return r;
    }
    if (ccs == 6u) { /* block: BLK_SEGS segments a block, no CRC (sc 0) */
        b->sdo = SDO_BLK;
        b->seq = 0;
        b->last = false;
        sdo_send(b, 0xA0u, b->mux, BLK_SEGS);
    } else {
        b->sdo = expedited ? SDO_NONE : SDO_SEG;
        b->toggle = 0;
        sdo_send(b, 0x60u, b->mux, 0);
    }
    return 0;
}

/* An SDO request (CiA 301), with the transfer under way or none: the
 * answer, nothing (an abort, a segment of a block), or an abort. */
static CO_NOINLINE void sdo_rx(boot_t *b, const uint8_t *d, uint32_t now)
{
    uint8_t c = d[0];
    uint8_t mode = b->sdo;
    uint32_t r = 0;
    b->sdo = SDO_NONE; /* ended unless it goes on */
    b->sdo_at = now + SDO_IDLE_US;
    if (mode == SDO_BLK) {
        uint8_t seqno = c & 0x7Fu;
        if (c == 0x80u) {
            return; /* the client's abort (no segment has number 0) */
        }
        b->sdo = SDO_BLK;
        if (seqno == b->seq + 1u && seqno <= BLK_SEGS) {
            memcpy(&b->buf[b->seq * 7u], &d[1], 7u);
            b->seq = seqno;
            b->last = c > 0x80u;
        }
        if (c < 0x80u && seqno < BLK_SEGS) {
            return;
        }
        /* The block's end (its last number, or the transfer's last
         * segment): the segments that came in order into the flash, then
         * acknowledged; the last segment's bytes wait for the end, which
         * says how many of them count. */
        uint32_t n = b->seq * 7u - (b->last ? 7u : 0u);
        r = dom_take(b, b->buf, n);
        if (b->last) {
            memcpy(b->hold, &b->buf[n], 7u);
            b->sdo = SDO_BLK_END;
        }
        if (r == 0u) {
            sdo_send(b, 0xA2u, b->seq | (BLK_SEGS << 8), 0);
            b->seq = 0;
        }
    } else if ((c >> 5) == 4u) {
        return; /* the client's abort (of a transfer, or of none) */
    } else if (mode == SDO_BLK_END) {
        r = (c & 0xE3u) != 0xC1u ? CO_E_CMD : dom_take(b, b->hold, 7u - ((c >> 2) & 7u));
        r = r != 0u ? r : dom_end(b);
        if (r == 0u) {
            sdo_send(b, 0xA1u, 0, 0);
        }
    } else if (mode == SDO_SEG && (c >> 5) == 0u) {
        if (((c >> 4) & 1u) != b->toggle) {
            r = CO_E_TOGGLE;
        } else {
            r = dom_take(b, &d[1], 7u - ((c >> 1) & 7u));
        }
        if (r == 0u && (c & 1u) != 0u) {
            r = dom_end(b);
        } else {
            b->sdo = SDO_SEG;
        }
        if (r == 0u) {
            sdo_send(b, (uint8_t)(0x20u | ((uint32_t)b->toggle << 4)), 0, 0);
            b->toggle ^= 1u;
        }
    } else {
        r = request(b, d, now); /* a new request ends a segmented download */
    }
    if (r != 0u) {
        b->sdo = SDO_NONE;
        sdo_send(b, 0x80u, b->mux, r);
    }
}

/* ---- identity ---------------------------------------------------------------- */

/* What the bootloader runs as (boot.h: hand-over, boot-info, defaults),
 * into b->id. With a hand-over: its node-ID and bit rate, the identity of
 * the installed image's header (valid), else of the boot-info record, and
 * the record is written unless it holds that already: before anything of
 * the application is erased, so that a power cut during the update leaves
 * a bootloader with the product's identity. A failed write leaves the old
 * record or none (a cut erase): the bootloader runs on from RAM. */
static void identity(boot_t *b, bool handed, bool valid)
{
    const flash_ee_t *f = board_boot_info();
    boot_ident_t *id = &b->id;
    boot_ident_t info = {0};
    if (f != NULL) {
        f->ops->read(f->ctx, f->base, &info, sizeof info);
    }
    /* The record: the bootloader's own, from a hand-over it checked. */
    *id = info;
    if (info.magic != BOOT_INFO_MAGIC ||
        info.crc != co_crc32(0, (const uint8_t *)&info, BOOT_IDENT_CRC_LEN)) {
        *id = (boot_ident_t){.node_id = BOOT_DEFAULT_ID, .kbps = BOOT_DEFAULT_KBPS};
    }
    if (handed && valid) { /* 1000h and 1018h:1-3 follow each other in both */
        memcpy((uint8_t *)id + offsetof(boot_ident_t, device_type),
               (const uint8_t *)&b->hdr + offsetof(co_image_hdr_t, device_type), 16u);
        memcpy(id->id, b->hdr.id, sizeof id->id);
    }
    id->serial = board_serial(0);
    if (handed) {
        id->node_id = boot_handover_block.node_id;
        id->kbps = boot_handover_block.kbps;
        id->magic = BOOT_INFO_MAGIC;
        id->crc = co_crc32(0, (const uint8_t *)id, BOOT_IDENT_CRC_LEN);
        if (f != NULL && memcmp(&info, id, sizeof info) != 0 && f->ops->erase(f->ctx, f->base)) {
            const uint8_t *p = (const uint8_t *)id;
            for (uint32_t i = 0;
                 i < sizeof *id && f->ops->program16(f->ctx, f->base + i, co_get_u16(&p[i]));
                 i += 2u) {
            }
        }
    }
    /* Taken: a reset from here on (a start, NMT reset node, a cut) sees
     * no hand-over. */
    boot_handover_block.magic = 0;
}

_Static_assert(offsetof(boot_ident_t, revision) - offsetof(boot_ident_t, device_type) == 12u &&
                   offsetof(co_image_hdr_t, revision) - offsetof(co_image_hdr_t, device_type) ==
                       12u,
               "1000h and 1018h:1-3 are four words in a row in both");

/* ---- the loop ---------------------------------------------------------------------- */

static void rx(boot_t *b, const co_frame_t *f, uint32_t now)
{
    if (f->rtr) {
        return;
    }
    if (f->id == 0u && f->dlc == 2u && (f->data[1] == 0u || f->data[1] == b->node)) {
        uint8_t cs = f->data[0];
        if (cs == 0x81u) {
            board_reset(); /* reset node: the device (a valid application then runs) */
        }
        if (cs == 0x82u) {
            boot_up(b);
        } else if (cs == 0x01u || cs == 0x02u || cs == 0x80u) {
            b->nmt = cs == 0x01u ? NMT_OP : cs == 0x02u ? NMT_STOPPED : NMT_PREOP;
            b->sdo = cs == 0x02u ? SDO_NONE : b->sdo; /* stopped: the transfer ends */
        }
    } else if (f->id == 0x600u + b->node && f->dlc == 8u && b->nmt != NMT_STOPPED) {
        sdo_rx(b, f->data, now);
    }
}

/* Timers and the check of a download: the time until the next call is
 * due. */
static uint32_t poll(boot_t *b, uint32_t now)
{
    if (b->reset_due && !co_time_before(now, b->reset_at)) {
        board_reset();
    }
    if (b->sdo != SDO_NONE && !co_time_before(now, b->sdo_at)) {
        b->sdo = SDO_NONE;
        sdo_send(b, 0x80u, b->mux, CO_E_TIMEOUT);
    }
    if (b->hb_ms != 0u && !co_time_before(now, b->hb_at)) {
        send((uint16_t)(0x700u + b->node), &b->nmt, 1u);
        b->hb_at = now + b->hb_ms * 1000u;
    }
    if (b->phase == PH_VERIFY) {
        verify(b);
        return 0;
    }
    return b->hb_ms != 0u ? co_min_u32(co_time_until(now, b->hb_at), POLL_US) : POLL_US;
}

int main(void)
{
    boot_t *b = &boot;
    bool handed = boot_handover_valid(&boot_handover_block);
    /* The installed image checked as after a download (verify). */
    const flash_ee_t *a = board_boot_area();
    b->area = a;
    b->state = CO_PROGDL_NO_PROGRAM; /* until verify says otherwise (STOPPED is 0) */
    if (a != NULL) {
        a->ops->read(a->ctx, a->base, b->raw, CO_IMAGE_HDR_SIZE);
        if (header(b) == CO_PROGDL_OK) {
            b->phase = PH_VERIFY;
        }
    }
    while (b->phase == PH_VERIFY) {
        verify(b);
    }
    bool valid = b->state == CO_PROGDL_STOPPED;
    if (valid && !handed) {
        board_boot_app(&b->hdr);
    }
    (void)status(b, (uint8_t)(valid ? CO_PROGDL_OK : CO_PROGDL_NO_VALID), 0);
    b->state = (uint8_t)(valid ? CO_PROGDL_STOPPED : CO_PROGDL_NO_PROGRAM);
    identity(b, handed, valid);
    b->node = b->id.node_id;
    if (!board_init() || !board_can_bitrate(b->id.kbps)) {
        for (;;) {
            board_leds(false, true);
        }
    }
    boot_up(b);
    for (;;) {
        uint32_t now = board_now_us();
        co_frame_t f;
        while (board_can_receive(&f)) {
            rx(b, &f, now);
        }
        uint32_t wait = poll(b, now);
        /* Green: on when operational, else blinking (262 ms on, 262 off:
         * CiA 303-3's 200 ms without a division, and no single flash for
         * stopped, in 4 KiB); red off. */
        board_leds(b->nmt == NMT_OP || ((now >> 18) & 1u) != 0u, false);
        board_sleep(wait);
    }
}
