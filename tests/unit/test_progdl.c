/*
 * test_progdl.c - CiA 302-3 program download (co_progdl.h): the loader
 * side's state machine, every refusal with its 1F57h status and abort,
 * images over expedited, segmented and block SDO (CRC on and off) into
 * the fake port's program area (harness.c: pages erased before written,
 * failing calls, a power cut), the check from flash while 1F57h is busy,
 * start and stop after their answers; and the application side's answers.
 *
 * The node runs a product's dictionary with the loader's objects merged
 * in, as the Linux program's --program-download builds it (a config
 * derived at run time, h_dev_t.cfg): host only, the bare builds fix the
 * config at build time.
 */
#include "co_progdl.h"
#include "co_sdo.h"
#include "harness.h"
#include "product_registry.h"

#define COUNT(a) (sizeof(a) / sizeof((a)[0]))
#define BOARD 0x77u /* the fake port's board code */
#define PROG_ID 0x20250101u

/* ---- configs: a product's, with one side's objects merged in -------- */

typedef struct derived {
    co_node_cfg_t cfg;
    co_od_t od;
    co_od_entry_t entries[400];
    const co_service_t *services[8];
} derived_t;

static const co_od_entry_t loader_lines[] = {CO_PROGDL_LOADER_ENTRIES};
static const co_od_entry_t app_lines[] = {CO_PROGDL_APP_ENTRIES};

static void derive(derived_t *g, const co_node_cfg_t *base, bool loader)
{
    const co_od_entry_t *add = loader ? loader_lines : app_lines;
    unsigned nadd = loader ? (unsigned)COUNT(loader_lines) : (unsigned)COUNT(app_lines);
    const co_od_t *od = base->od;
    unsigned n = 0;
    bool put = false;
    CHECK(od->count + nadd <= COUNT(g->entries));
    for (unsigned i = 0; i <= od->count; i++) {
        const co_od_entry_t *e = i < od->count ? &od->entries[i] : NULL;
        if (!put && (e == NULL || e->index > 0x1F57u)) {
            memcpy(&g->entries[n], add, nadd * sizeof(*add));
            n += nadd;
            put = true;
        }
        if (e != NULL) {
            g->entries[n++] = *e;
        }
    }
    g->od.entries = g->entries;
    g->od.count = (uint16_t)n;
    g->cfg = *base;
    g->cfg.od = &g->od;
    if (loader) {
        unsigned s = 0;
        for (const co_service_t *const *sv = base->services; sv != NULL && *sv != NULL; sv++) {
            g->services[s++] = *sv;
        }
        g->services[s++] = &co_progdl_service;
        g->services[s] = NULL;
        g->cfg.services = g->services;
        g->cfg.sdo_segmented = co_sdo_segmented;
        g->cfg.sdo_block = co_sdo_block;
        g->cfg.sdo_domain = co_progdl_domain;
    }
}

static derived_t cfg_buf;
static co_progdl_t pd;
static h_dev_t dev;

/* The DST X730 +-30 deg with the loader side: state what the board found. */
static h_dev_t *boot_loader(uint8_t state, uint32_t id)
{
    h_dev_t *d = &dev;
    memset(d, 0, sizeof(*d));
    fake_port_init(&d->port);
    d->now = 1000000u;
    derive(&cfg_buf, dst_x730_xy30.cfg, true);
    d->cfg = &cfg_buf.cfg;
    co_progdl_init(&pd, state, id);
    d->port.prog.pd = &pd;
    d->port.prog.board = BOARD;
    d->port.prog.id = "dst-x730-xy30";
    h_boot(d, &dst_x730_xy30, true);
    h_drain(d);
    return d;
}

/* ---- an image of the DST X730 +-30 deg ------------------------------- */

typedef struct img {
    uint8_t b[FAKE_PROG_SIZE + 64u];
    uint32_t len;
} img_t;

static void put32(uint8_t *p, uint32_t v)
{
    co_put_u32(p, v);
}

/* Recompute the CRC after a change of the header or payload. */
static void seal(img_t *m)
{
    put32(&m->b[12], co_crc32(0, &m->b[CO_IMAGE_CRC_FROM], m->len - CO_IMAGE_CRC_FROM));
}

/* A good image of len bytes: its payload a counting pattern. */
static void make_image(img_t *m, uint32_t len, uint32_t program_id)
{
    memset(m, 0, sizeof(*m));
    m->len = len;
    put32(&m->b[0], CO_IMAGE_MAGIC);
    co_put_u16(&m->b[4], CO_IMAGE_HDR_SIZE);
    co_put_u16(&m->b[6], CO_IMAGE_VERSION);
    put32(&m->b[8], len);
    put32(&m->b[16], BOARD);
    put32(&m->b[20], 0x0008019Au); /* the X730's 1000h */
    put32(&m->b[24], 0x00000093u); /* 1018h:1 */
    put32(&m->b[28], 0x00000064u); /* 1018h:2 */
    put32(&m->b[32], 0x00000001u);
    put32(&m->b[36], program_id);
    memcpy(&m->b[48], "dst-x730-xy30", 13);
    for (uint32_t i = CO_IMAGE_HDR_SIZE; i < len; i++) {
        m->b[i] = (uint8_t)(i * 7u + 3u);
    }
    seal(m);
}

/* ---- an SDO client ---------------------------------------------------- */

/* The server's next answer (other traffic skipped), or NULL. */
static const co_frame_t *answer(h_dev_t *d)
{
    const co_frame_t *r;
    while ((r = h_next(d)) != NULL && r->id != 0x580u + d->node->node_id) {
    }
    return r;
}

static void send(h_dev_t *d, const uint8_t data[8])
{
    co_frame_t f = {.id = (uint16_t)(0x600u + d->node->node_id), .dlc = 8};
    memcpy(f.data, data, 8);
    h_rx_frame(d, &f);
}

/* An answer's abort code, 0 for none, 1 for no answer at all. */
static uint32_t abort_of(const co_frame_t *r)
{
    if (r == NULL) {
        return 1u;
    }
    return r->data[0] == 0x80u ? co_get_u32(&r->data[4]) : 0u;
}

/* Expedited upload: the abort code, the value in *v. */
static uint32_t upload(h_dev_t *d, uint16_t index, uint8_t sub, uint32_t *v)
{
    h_drain(d);
    uint8_t q[8] = {0x40, (uint8_t)index, (uint8_t)(index >> 8), sub, 0, 0, 0, 0};
    send(d, q);
    const co_frame_t *r = answer(d);
    uint32_t a = abort_of(r);
    if (a == 0u) {
        *v = co_get_u32(&r->data[4]) & (0xFFFFFFFFu >> (8u * ((r->data[0] >> 2) & 3u)));
    }
    return a;
}

static uint32_t read_obj(h_dev_t *d, uint16_t index, uint8_t sub)
{
    uint32_t v = 0xDEADBEEFu;
    CHECK_EQ(upload(d, index, sub, &v), 0);
    return v;
}

/* Expedited download of n (1..4) bytes of v: the abort code. */
static uint32_t download(h_dev_t *d, uint16_t index, uint8_t sub, uint32_t v, unsigned n)
{
    h_drain(d);
    uint8_t q[8] = {
        (uint8_t)(0x23u | ((4u - n) << 2)), (uint8_t)index, (uint8_t)(index >> 8), sub, 0, 0, 0, 0};
    co_put_u32(&q[4], v);
    send(d, q);
    return abort_of(answer(d));
}

/* Segmented download of the n bytes at b to 1F50h:1: the abort code. */
static uint32_t seg_download(h_dev_t *d, const uint8_t *b, uint32_t n)
{
    h_drain(d);
    uint8_t q[8] = {0x21, 0x50, 0x1F, 1, 0, 0, 0, 0};
    co_put_u32(&q[4], n);
    send(d, q);
    uint32_t a = abort_of(answer(d));
    if (a != 0u) {
        return a;
    }
    uint8_t toggle = 0;
    for (uint32_t at = 0;;) {
        uint32_t k = co_min_u32(7u, n - at);
        bool last = at + k >= n;
        uint8_t s[8] = {(uint8_t)(toggle | ((7u - k) << 1) | (last ? 1u : 0u))};
        memcpy(&s[1], &b[at], k);
        send(d, s);
        const co_frame_t *r = answer(d);
        a = abort_of(r);
        if (a != 0u) {
            return a;
        }
        CHECK_EQ(r->data[0], 0x20u | toggle);
        toggle ^= 0x10u;
        at += k;
        if (last) {
            return 0;
        }
    }
}

/* Blocks the last block download sent. */
static unsigned blocks_seen;

/* Block download of the n bytes at b to 1F50h:1, with or without the
 * CRC (bad_crc: a wrong one): the abort code. Checks that the server says
 * nothing inside a block and that its blocks fill its pieces. */
static uint32_t blk_download(h_dev_t *d, const uint8_t *b, uint32_t n, bool crc, bool bad_crc)
{
    h_drain(d);
    uint8_t q[8] = {(uint8_t)(crc ? 0xC6u : 0xC2u), 0x50, 0x1F, 1, 0, 0, 0, 0};
    co_put_u32(&q[4], n);
    send(d, q);
    const co_frame_t *r = answer(d);
    uint32_t a = abort_of(r);
    if (a != 0u) {
        return a;
    }
    CHECK_EQ(r->data[0], 0xA4u);
    blocks_seen = 0;
    uint32_t blksize = r->data[4];
    CHECK(blksize >= 1u && blksize <= 127u);
    uint32_t at = 0;
    bool done = false;
    while (!done) {
        uint32_t start = at;
        uint8_t seq = 0;
        while (seq < blksize && !done) {
            uint32_t k = co_min_u32(7u, n - at);
            done = at + k >= n;
            uint8_t s[8] = {(uint8_t)(++seq | (done ? 0x80u : 0u))};
            memcpy(&s[1], &b[at], k);
            at += k;
            send(d, s);
            if (seq < blksize && !done) {
                r = answer(d);
                if (r != NULL) {
                    return abort_of(r); /* an abort inside the block */
                }
            }
        }
        r = answer(d);
        a = abort_of(r);
        if (a != 0u) {
            return a;
        }
        CHECK_EQ(r->data[0], 0xA2u);
        CHECK_EQ(r->data[1], seq);
        blocks_seen++;
        if (!done) {
            CHECK_EQ(at - start, 7u * seq); /* a whole block */
        }
        blksize = r->data[2];
    }
    uint32_t unused = (7u - n % 7u) % 7u;
    uint8_t e[8] = {(uint8_t)(0xC1u | (unused << 2)), 0, 0, 0, 0, 0, 0, 0};
    uint16_t c = co_crc16_ccitt(0, b, n);
    co_put_u16(&e[1], crc ? (uint16_t)(c ^ (bad_crc ? 1u : 0u)) : 0u);
    send(d, e);
    r = answer(d);
    a = abort_of(r);
    if (a == 0u) {
        CHECK_EQ(r->data[0], 0xA1u);
    }
    return a;
}

static uint32_t status_of(h_dev_t *d)
{
    return read_obj(d, 0x1F57, 1);
}

/* Run the node until 1F57h is no longer busy; the polls it took. */
static unsigned until_idle(h_dev_t *d)
{
    unsigned polls = 0;
    while ((status_of(d) & 1u) != 0u && polls < 1000u) {
        h_advance(d, 1);
        polls++;
    }
    CHECK((status_of(d) & 1u) == 0u);
    return polls;
}

/* Clear (1F51h:1 = 3), answered OK. */
static void clear(h_dev_t *d)
{
    CHECK_EQ(download(d, 0x1F51, 1, 3, 1), 0);
}

/* The area holds m's bytes. */
static bool area_holds(const h_dev_t *d, const img_t *m)
{
    return memcmp(d->port.prog.area, m->b, m->len) == 0;
}

#define E_STATE 0x08000022u
#define E_DATA 0x08000020u
#define E_HW 0x06060000u

/* ---- the objects ------------------------------------------------------ */

static void test_loader_objects(void)
{
    h_dev_t *d = boot_loader(CO_PROGDL_STARTED, PROG_ID);
    for (uint16_t idx = 0x1F50; idx <= 0x1F57; idx++) {
        if (idx == 0x1F50 || idx == 0x1F51 || idx == 0x1F56 || idx == 0x1F57) {
            CHECK_EQ(read_obj(d, idx, 0), 1);
        }
    }
    CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_STARTED);
    CHECK_EQ(read_obj(d, 0x1F56, 1), PROG_ID);
    CHECK_EQ(status_of(d), 0);
    uint32_t v;
    CHECK_EQ(upload(d, 0x1F50, 1, &v), 0x06010001u); /* write-only */
    CHECK_EQ(download(d, 0x1F56, 1, 5, 4), 0x06010002u);
    CHECK_EQ(download(d, 0x1F57, 1, 0, 4), 0x06010002u);
    CHECK_EQ(download(d, 0x1F51, 1, 2, 1), 0x06090030u); /* reset: refused */
    CHECK_EQ(download(d, 0x1F51, 1, 4, 1), 0x06090030u);
    CHECK_EQ(download(d, 0x1F51, 1, 255, 1), 0x06090030u);
    CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_STARTED);
    CHECK_EQ(d->port.prog.starts + d->port.prog.stops + d->port.prog.clears, 0);
}

/* A board with no program: 1F51h reads 3, 1F56h 0, status 1. */
static void test_loader_no_program(void)
{
    h_dev_t *d = boot_loader(CO_PROGDL_NO_PROGRAM, PROG_ID);
    CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_NO_PROGRAM);
    CHECK_EQ(read_obj(d, 0x1F56, 1), 0);
    CHECK_EQ(status_of(d), CO_PROGDL_NO_VALID << 1);
    CHECK_EQ(download(d, 0x1F51, 1, 1, 1), E_STATE); /* nothing to start */
    CHECK_EQ(d->port.prog.starts, 0);
    CHECK_EQ(download(d, 0x1F51, 1, 0, 1), 0); /* stop: nothing runs */
    h_advance(d, 1000);
    CHECK_EQ(d->port.prog.stops, 0);
    h_expect_assert(1);
    co_progdl_init(&pd, 7, 1); /* not a state: no program */
    CHECK_EQ(co_progdl_state(&pd), CO_PROGDL_NO_PROGRAM);
}

/* ---- the whole update ------------------------------------------------- */

/* Stop, clear, download, busy until checked, start: each after its answer. */
static void update(bool block, bool crc)
{
    h_dev_t *d = boot_loader(CO_PROGDL_STARTED, PROG_ID);
    static img_t m;
    make_image(&m, 3000, PROG_ID + 1u);
    /* Stop: the port's stop after the answer went out. */
    unsigned before = d->port.ntx;
    CHECK_EQ(download(d, 0x1F51, 1, 0, 1), 0);
    h_advance(d, 1);
    CHECK_EQ(d->port.prog.stops, 1);
    CHECK(d->port.prog.stop_ntx > before); /* the answer had gone out */
    CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_STOPPED);
    CHECK_EQ(read_obj(d, 0x1F56, 1), PROG_ID); /* still installed */
    clear(d);
    CHECK_EQ(d->port.prog.clears, 1);
    CHECK_EQ(d->port.prog.erases, 1); /* one page: the answer is due within 100 ms */
    CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_NO_PROGRAM);
    CHECK_EQ(read_obj(d, 0x1F56, 1), 0);
    CHECK_EQ(status_of(d), 0);
    uint32_t a = block ? blk_download(d, m.b, m.len, crc, false) : seg_download(d, m.b, m.len);
    CHECK_EQ(a, 0);
    /* Each page erased once, by the first write into it. */
    CHECK_EQ(d->port.prog.erases, (m.len + FAKE_PROG_PAGE - 1u) / FAKE_PROG_PAGE);
    CHECK(area_holds(d, &m));
    /* Checked from flash after the answer: busy, then not. */
    CHECK_EQ(status_of(d), 1);
    CHECK_EQ(d->port.prog.commits, 0);
    unsigned polls = until_idle(d);
    CHECK(polls >= 1u);
    CHECK_EQ(d->port.prog.commits, 1);
    CHECK_EQ(d->port.prog.committed_id, PROG_ID + 1u);
    CHECK_EQ(status_of(d), 0);
    CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_STOPPED);
    CHECK_EQ(read_obj(d, 0x1F56, 1), PROG_ID + 1u); /* before the start (CiA 302-2) */
    /* Start, after its answer. */
    before = d->port.ntx;
    CHECK_EQ(download(d, 0x1F51, 1, 1, 1), 0);
    h_advance(d, 1);
    CHECK_EQ(d->port.prog.starts, 1);
    CHECK(d->port.prog.start_ntx > before);
    CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_STARTED);
    /* Started again: 1 is OK and does nothing. */
    CHECK_EQ(download(d, 0x1F51, 1, 1, 1), 0);
    h_advance(d, 1);
    CHECK_EQ(d->port.prog.starts, 1);
}

static void test_update_segmented(void)
{
    update(false, false);
}

static void test_update_block_crc(void)
{
    update(true, true);
}

static void test_update_block_no_crc(void)
{
    update(true, false);
}

/* Sizes around the pieces and the header: every byte arrives, once. */
static void test_update_lengths(void)
{
    static const uint32_t lens[] = {64, 65, 111, 112, 113, 1023, 1024, 1025, 4096};
    for (unsigned i = 0; i < COUNT(lens); i++) {
        for (unsigned block = 0; block < 2u; block++) {
            h_dev_t *d = boot_loader(CO_PROGDL_NO_PROGRAM, 0);
            static img_t m;
            make_image(&m, lens[i], 9);
            clear(d);
            uint32_t a = block != 0u ? blk_download(d, m.b, m.len, true, false)
                                     : seg_download(d, m.b, m.len);
            CHECK_EQ(a, 0);
            CHECK(area_holds(d, &m));
            until_idle(d);
            CHECK_EQ(read_obj(d, 0x1F56, 1), 9);
            if (a != 0u || read_obj(d, 0x1F56, 1) != 9u) {
                fprintf(stderr, "    length %u, %s\n", (unsigned)lens[i],
                        block != 0u ? "block" : "segmented");
            }
        }
    }
}

/* What the server hands the loader (co_sdo_domain_fn), seen on the way. */
static struct {
    uint32_t next_at; /* where the next piece must start */
    uint32_t max_len; /* the longest piece */
    unsigned pieces, bad;
} seen;

static co_res_t watch(co_node_t *node, const co_od_entry_t *e, uint32_t at, const uint8_t *buf,
                      uint32_t len, bool end)
{
    if (len == 0u && !end) {
        seen.next_at = 0;
    } else {
        seen.pieces++;
        /* In order, none over the buffer, all but the last a multiple of 4. */
        if (at != seen.next_at || len > CO_SDO_BUF || (!end && len % 4u != 0u)) {
            seen.bad++;
        }
        seen.next_at = at + len;
        seen.max_len = len > seen.max_len ? len : seen.max_len;
    }
    return co_progdl_domain(node, e, at, buf, len, end);
}

/* The pieces: the largest multiple of 28 bytes within the buffer (56 of
 * 64), in order; a block fills one piece (the acknowledge follows it). */
/* Segments of a piece: what a block the server asks for at most has. */
#define SDO_PIECE_SEGMENTS (CO_SDO_BUF / 28u * 4u)

static void test_pieces(void)
{
    static img_t m;
    make_image(&m, 3000, 4);
    for (unsigned block = 0; block < 2u; block++) {
        h_dev_t *d = boot_loader(CO_PROGDL_NO_PROGRAM, 0);
        cfg_buf.cfg.sdo_domain = watch;
        memset(&seen, 0, sizeof(seen));
        clear(d);
        uint32_t a = block != 0u ? blk_download(d, m.b, m.len, true, false)
                                 : seg_download(d, m.b, m.len);
        CHECK_EQ(a, 0);
        CHECK_EQ(seen.bad, 0);
        CHECK_EQ(seen.next_at, 3000);
        CHECK_EQ(seen.max_len, CO_SDO_BUF / 28u * 28u);
        CHECK_EQ(seen.pieces, (3000u + seen.max_len - 1u) / seen.max_len);
        if (block != 0u) {
            /* The server asked for blocks of one piece each. */
            CHECK_EQ(blocks_seen, seen.pieces);
        }
    }
}

/* A block download that loses segment `lost` of every block once: the
 * server acknowledges what came in order, the client sends the rest
 * again, and the next block is sized to what the piece lacks, so that
 * every piece still goes whole before an acknowledge. */
static void test_block_lost_segments(void)
{
    static img_t m;
    make_image(&m, 1500, 8);
    for (unsigned lost = 1; lost <= 8u; lost += 3u) {
        h_dev_t *d = boot_loader(CO_PROGDL_NO_PROGRAM, 0);
        cfg_buf.cfg.sdo_domain = watch;
        memset(&seen, 0, sizeof(seen));
        clear(d);
        uint8_t q[8] = {0xC6, 0x50, 0x1F, 1, 0, 0, 0, 0};
        co_put_u32(&q[4], m.len);
        send(d, q);
        const co_frame_t *r = answer(d);
        CHECK_EQ(abort_of(r), 0);
        uint32_t blksize = r->data[4];
        uint32_t at = 0;
        uint32_t dropped_at = UINT32_MAX; /* a block's start: its loss is sent again */
        unsigned short_blocks = 0;
        while (at < m.len) {
            uint32_t start = at;
            bool done = false;
            for (uint8_t seq = 1; seq <= blksize && !done; seq++) {
                uint32_t k = co_min_u32(7u, m.len - start - 7u * (seq - 1u));
                done = start + 7u * (seq - 1u) + k >= m.len;
                uint8_t f[8] = {(uint8_t)(seq | (done ? 0x80u : 0u))};
                memcpy(&f[1], &m.b[start + 7u * (seq - 1u)], k);
                if (seq == lost && dropped_at != start && !done) {
                    dropped_at = start; /* this one never arrives; once from here */
                    continue;
                }
                send(d, f);
            }
            r = answer(d);
            CHECK_EQ(abort_of(r), 0);
            if (r == NULL || abort_of(r) != 0u) {
                return;
            }
            CHECK_EQ(r->data[0], 0xA2u);
            uint32_t acked = r->data[1];
            at = co_min_u32(start + 7u * acked, m.len);
            short_blocks += r->data[2] < SDO_PIECE_SEGMENTS ? 1u : 0u;
            blksize = r->data[2];
            if (done && acked * 7u >= m.len - start) {
                break;
            }
        }
        uint32_t unused = (7u - m.len % 7u) % 7u;
        uint8_t e[8] = {(uint8_t)(0xC1u | (unused << 2)), 0, 0, 0, 0, 0, 0, 0};
        co_put_u16(&e[1], co_crc16_ccitt(0, m.b, m.len));
        send(d, e);
        CHECK_EQ(abort_of(answer(d)), 0);
        /* Segments after the first lost: the server asked for the rest of a piece. */
        CHECK(lost == 1u || short_blocks > 0u);
        CHECK_EQ(seen.bad, 0);
        CHECK_EQ(seen.max_len, CO_SDO_BUF / 28u * 28u);
        CHECK(area_holds(d, &m));
        until_idle(d);
        CHECK_EQ(read_obj(d, 0x1F56, 1), 8);
    }
}

/* A download cut short (the client's abort, the SDO timeout, a new
 * request): no program, and the next needs a clear. */
static void test_interrupted(void)
{
    static img_t m;
    make_image(&m, 900, 6);
    for (unsigned how = 0; how < 3u; how++) {
        h_dev_t *d = boot_loader(CO_PROGDL_NO_PROGRAM, 0);
        clear(d);
        uint8_t q[8] = {0x21, 0x50, 0x1F, 1, 0, 0, 0, 0};
        co_put_u32(&q[4], m.len);
        send(d, q);
        CHECK_EQ(abort_of(answer(d)), 0);
        for (uint8_t i = 0; i < 20u; i++) { /* 140 bytes, the header among them */
            uint8_t f[8] = {(uint8_t)((i & 1u) != 0u ? 0x10u : 0u)};
            memcpy(&f[1], &m.b[7u * i], 7);
            send(d, f);
            CHECK_EQ(abort_of(answer(d)), 0);
        }
        if (how == 0u) {
            uint8_t a[8] = {0x80, 0x50, 0x1F, 1, 0, 0, 0x04, 0x05};
            send(d, a);
        } else if (how == 1u) {
            h_advance(d, CO_SDO_TIMEOUT_US + 1000u);
            CHECK_EQ(abort_of(answer(d)), 0x05040000u);
        } else {
            CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_NO_PROGRAM);
        }
        h_advance(d, 10000);
        CHECK_EQ(d->port.prog.commits, 0);
        CHECK_EQ(download(d, 0x1F51, 1, 1, 1), E_STATE);
        CHECK_EQ(seg_download(d, m.b, m.len), E_STATE);
        CHECK_EQ(status_of(d), CO_PROGDL_NOT_CLEARED << 1);
        clear(d);
        CHECK_EQ(seg_download(d, m.b, m.len), 0);
        until_idle(d);
        CHECK_EQ(read_obj(d, 0x1F56, 1), 6);
    }
}

/* ---- refusals ----------------------------------------------------------- */

/* A download of img, its abort and status; the area's state after it:
 * nothing installed (clear did that), no commit. */
static void refused(const img_t *m, bool block, uint32_t want_abort, uint32_t want_status)
{
    h_dev_t *d = boot_loader(CO_PROGDL_STOPPED, PROG_ID);
    clear(d);
    uint32_t a = block ? blk_download(d, m->b, m->len, true, false) : seg_download(d, m->b, m->len);
    CHECK_EQ(a, want_abort);
    CHECK_EQ(status_of(d), want_status << 1);
    h_advance(d, 10000);
    CHECK_EQ(d->port.prog.commits, 0);
    CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_NO_PROGRAM);
    CHECK_EQ(read_obj(d, 0x1F56, 1), 0);
    CHECK_EQ(download(d, 0x1F51, 1, 1, 1), E_STATE); /* no start without a checked image */
    /* A second download needs a clear first: then it completes. */
    static img_t good;
    make_image(&good, 500, 3);
    CHECK_EQ(seg_download(d, good.b, good.len), E_STATE);
    CHECK_EQ(status_of(d), CO_PROGDL_NOT_CLEARED << 1);
    clear(d);
    CHECK_EQ(seg_download(d, good.b, good.len), 0);
    until_idle(d);
    CHECK_EQ(read_obj(d, 0x1F56, 1), 3);
    CHECK_EQ(status_of(d), 0);
}

/* A refused header: none of it reaches the flash. */
static void header_refused(img_t *m, uint32_t want_status)
{
    for (unsigned block = 0; block < 2u; block++) {
        h_dev_t *d = boot_loader(CO_PROGDL_NO_PROGRAM, 0);
        clear(d);
        unsigned writes = d->port.prog.writes;
        uint32_t a = block != 0u ? blk_download(d, m->b, m->len, true, false)
                                 : seg_download(d, m->b, m->len);
        CHECK_EQ(a, E_DATA);
        CHECK_EQ(status_of(d), want_status << 1);
        CHECK_EQ(d->port.prog.writes, writes);
        refused(m, block != 0u, E_DATA, want_status);
    }
}

static void test_refuse_magic(void)
{
    static img_t m;
    make_image(&m, 700, 5);
    m.b[0] ^= 1u;
    header_refused(&m, CO_PROGDL_UNKNOWN);
    make_image(&m, 700, 5);
    m.b[6] = 2; /* another format version */
    header_refused(&m, CO_PROGDL_UNKNOWN);
}

static void test_refuse_identity(void)
{
    static img_t m;
    static const unsigned fields[] = {20, 24, 28}; /* 1000h, 1018h:1, 1018h:2 */
    for (unsigned i = 0; i < COUNT(fields); i++) {
        make_image(&m, 700, 5);
        m.b[fields[i]] ^= 0x10u;
        seal(&m);
        header_refused(&m, CO_PROGDL_FORMAT);
    }
    /* 1018h:3, the revision, may differ: a new program's. */
    make_image(&m, 700, 5);
    m.b[32] = 7;
    seal(&m);
    h_dev_t *d = boot_loader(CO_PROGDL_NO_PROGRAM, 0);
    clear(d);
    CHECK_EQ(seg_download(d, m.b, m.len), 0);
}

static void test_refuse_product_board(void)
{
    static img_t m;
    make_image(&m, 700, 5);
    memcpy(&m.b[48], "dst-x730-xy10", 13);
    seal(&m);
    header_refused(&m, CO_PROGDL_FORMAT);
    make_image(&m, 700, 5);
    put32(&m.b[16], BOARD + 1u);
    seal(&m);
    header_refused(&m, CO_PROGDL_FORMAT);
}

/* Longer than the board's area: the address error. */
static void test_refuse_too_long(void)
{
    static img_t m;
    make_image(&m, FAKE_PROG_SIZE + 8u, 5);
    header_refused(&m, CO_PROGDL_ADDRESS);
}

static void test_refuse_crc_and_length(void)
{
    static img_t m;
    /* A payload byte changed after the CRC was made: refused at the end. */
    for (unsigned block = 0; block < 2u; block++) {
        make_image(&m, 1500, 5);
        m.b[1200] ^= 0x40u;
        refused(&m, block != 0u, E_DATA, CO_PROGDL_FORMAT);
    }
    /* Truncated: fewer bytes than its header says. */
    make_image(&m, 1500, 5);
    m.len = 1400;
    refused(&m, false, E_DATA, CO_PROGDL_FORMAT);
    /* Longer than its header says. */
    make_image(&m, 1500, 5);
    m.len = 1501;
    refused(&m, true, E_DATA, CO_PROGDL_FORMAT);
    /* Fewer bytes than a header, expedited. */
    h_dev_t *d = boot_loader(CO_PROGDL_NO_PROGRAM, 0);
    clear(d);
    CHECK_EQ(download(d, 0x1F50, 1, 0x4D494F43u, 4), E_DATA);
    CHECK_EQ(status_of(d), CO_PROGDL_FORMAT << 1);
}

/* The block transfer's own CRC-16 wrong: 05040004h, nothing installed. */
static void test_refuse_block_crc(void)
{
    h_dev_t *d = boot_loader(CO_PROGDL_NO_PROGRAM, 0);
    static img_t m;
    make_image(&m, 900, 5);
    clear(d);
    CHECK_EQ(blk_download(d, m.b, m.len, true, true), 0x05040004u);
    h_advance(d, 10000);
    CHECK_EQ(d->port.prog.commits, 0);
    CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_NO_PROGRAM);
    CHECK_EQ(download(d, 0x1F51, 1, 1, 1), E_STATE);
}

/* Not cleared: status 4, 08000022h; what is installed stays, untouched. */
static void test_refuse_not_cleared(void)
{
    h_dev_t *d = boot_loader(CO_PROGDL_STOPPED, PROG_ID);
    static img_t m;
    make_image(&m, 900, 5);
    memset(d->port.prog.area, 0x5A, sizeof(d->port.prog.area));
    CHECK_EQ(seg_download(d, m.b, m.len), E_STATE);
    CHECK_EQ(blk_download(d, m.b, m.len, true, false), E_STATE);
    CHECK_EQ(download(d, 0x1F50, 1, 1, 4), E_STATE);
    CHECK_EQ(status_of(d), CO_PROGDL_NOT_CLEARED << 1);
    CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_STOPPED);
    CHECK_EQ(read_obj(d, 0x1F56, 1), PROG_ID);
    CHECK_EQ(d->port.prog.writes, 0);
    CHECK_EQ(d->port.prog.area[100], 0x5A);
    /* It starts still. */
    CHECK_EQ(download(d, 0x1F51, 1, 1, 1), 0);
    h_advance(d, 1);
    CHECK_EQ(d->port.prog.starts, 1);
}

/* While started: clear and download 08000022h, the status untouched. */
static void test_refuse_started(void)
{
    h_dev_t *d = boot_loader(CO_PROGDL_STARTED, PROG_ID);
    static img_t m;
    make_image(&m, 900, 5);
    CHECK_EQ(download(d, 0x1F51, 1, 3, 1), E_STATE);
    CHECK_EQ(seg_download(d, m.b, m.len), E_STATE);
    CHECK_EQ(status_of(d), 0);
    CHECK_EQ(d->port.prog.clears + d->port.prog.writes, 0);
    CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_STARTED);
}

/* Not pre-operational: no change, 08000022h; stopped: SDO is silent. */
static void test_refuse_nmt_state(void)
{
    h_dev_t *d = boot_loader(CO_PROGDL_STOPPED, PROG_ID);
    static img_t m;
    make_image(&m, 900, 5);
    h_rx(d, 0x000, "01 7F"); /* operational */
    h_drain(d);
    CHECK_EQ(download(d, 0x1F51, 1, 3, 1), E_STATE);
    CHECK_EQ(download(d, 0x1F51, 1, 1, 1), E_STATE);
    CHECK_EQ(d->port.prog.clears, 0);
    h_rx(d, 0x000, "80 7F"); /* pre-operational */
    clear(d);
    h_rx(d, 0x000, "01 7F");
    CHECK_EQ(seg_download(d, m.b, m.len), E_STATE);
    h_rx(d, 0x000, "80 7F");
    CHECK_EQ(seg_download(d, m.b, m.len), 0);
    /* Busy: no clear, no start until the check ends. */
    CHECK_EQ(status_of(d), 1);
    CHECK_EQ(download(d, 0x1F51, 1, 3, 1), E_STATE);
    CHECK_EQ(download(d, 0x1F51, 1, 1, 1), E_STATE);
    until_idle(d);
    CHECK_EQ(download(d, 0x1F51, 1, 1, 1), 0);
    h_advance(d, 1);
    CHECK_EQ(d->port.prog.starts, 1);
    /* Started and operational: stop is refused too. */
    h_rx(d, 0x000, "01 7F");
    CHECK_EQ(download(d, 0x1F51, 1, 0, 1), E_STATE);
    h_advance(d, 1);
    CHECK_EQ(d->port.prog.stops, 0);
}

/* ---- the flash failing ------------------------------------------------- */

static void test_flash_failures(void)
{
    static img_t m;
    make_image(&m, 2000, 5);
    /* The clear. */
    h_dev_t *d = boot_loader(CO_PROGDL_STOPPED, PROG_ID);
    d->port.prog.fail_clear = true;
    CHECK_EQ(download(d, 0x1F51, 1, 3, 1), E_HW);
    CHECK_EQ(status_of(d), CO_PROGDL_FLASH << 1);
    CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_NO_PROGRAM);
    d->port.prog.fail_clear = false;
    clear(d);
    CHECK_EQ(status_of(d), 0);
    /* A write, in both transfers. */
    for (unsigned block = 0; block < 2u; block++) {
        d = boot_loader(CO_PROGDL_NO_PROGRAM, 0);
        clear(d);
        d->port.prog.fail_write = true;
        uint32_t a = block != 0u ? blk_download(d, m.b, m.len, true, false)
                                 : seg_download(d, m.b, m.len);
        CHECK_EQ(a, E_HW);
        CHECK_EQ(status_of(d), CO_PROGDL_FLASH << 1);
        d->port.prog.fail_write = false;
        clear(d);
        CHECK_EQ(seg_download(d, m.b, m.len), 0);
        until_idle(d);
        CHECK_EQ(status_of(d), 0);
    }
    /* The read-back, and the commit: busy ends, status 5, no program. */
    for (unsigned which = 0; which < 2u; which++) {
        d = boot_loader(CO_PROGDL_NO_PROGRAM, 0);
        clear(d);
        CHECK_EQ(seg_download(d, m.b, m.len), 0);
        d->port.prog.fail_read = which == 0u;
        d->port.prog.fail_commit = which == 1u;
        until_idle(d);
        CHECK_EQ(status_of(d), CO_PROGDL_FLASH << 1);
        CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_NO_PROGRAM);
        CHECK_EQ(read_obj(d, 0x1F56, 1), 0);
        CHECK_EQ(download(d, 0x1F51, 1, 1, 1), E_STATE);
    }
}

/* The flash holds what was not sent (a bit programmed wrong): the check
 * from flash finds it, status 5. */
static void test_flash_readback_differs(void)
{
    static img_t m;
    make_image(&m, 2000, 5);
    for (unsigned where = 0; where < 2u; where++) {
        h_dev_t *d = boot_loader(CO_PROGDL_NO_PROGRAM, 0);
        clear(d);
        d->port.prog.flip_at = where == 0u ? 5 : 1500; /* in the header, in the payload */
        CHECK_EQ(seg_download(d, m.b, m.len), 0);
        until_idle(d);
        CHECK_EQ(status_of(d), CO_PROGDL_FLASH << 1);
        CHECK_EQ(d->port.prog.commits, 0);
    }
}

/* ---- power cuts ---------------------------------------------------------- */

/* The bootloader's view after a reset: an image whose header and CRC check. */
static bool area_valid(const h_dev_t *d, uint32_t *id)
{
    co_image_hdr_t h;
    const uint8_t *a = d->port.prog.area;
    if (!co_image_parse(a, &h) || h.length > FAKE_PROG_SIZE) {
        return false;
    }
    *id = h.program_id;
    return co_crc32(0, &a[CO_IMAGE_CRC_FROM], h.length - CO_IMAGE_CRC_FROM) == h.crc;
}

/* Power gone after k image bytes written, at many k: the device comes
 * back with no valid program and takes the next download whole. */
static void test_power_cut(void)
{
    static img_t m;
    make_image(&m, 2500, 11);
    for (long k = 0; k < 2500; k += 97) {
        h_dev_t *d = boot_loader(CO_PROGDL_STOPPED, PROG_ID);
        clear(d);
        d->port.prog.cut_after = k;
        CHECK_EQ(seg_download(d, m.b, m.len), E_HW);
        /* Power back: what the area holds is no program. */
        uint32_t id = 0;
        CHECK(!area_valid(d, &id));
        fake_prog_t keep = d->port.prog;
        d = boot_loader(CO_PROGDL_NO_PROGRAM, 0);
        d->port.prog = keep;
        d->port.prog.pd = &pd;
        d->port.prog.cut_after = -1;
        clear(d);
        CHECK_EQ(blk_download(d, m.b, m.len, true, false), 0);
        until_idle(d);
        CHECK(area_valid(d, &id));
        CHECK_EQ(id, 11);
    }
}

/* ---- the application side ------------------------------------------------ */

static void test_app_side(void)
{
    h_dev_t *d = &dev;
    memset(d, 0, sizeof(*d));
    fake_port_init(&d->port);
    d->now = 1000000u;
    derive(&cfg_buf, dst_x730_xy30.cfg, false);
    d->cfg = &cfg_buf.cfg;
    h_boot(d, &dst_x730_xy30, true);
    h_drain(d);
    CHECK_EQ(read_obj(d, 0x1F51, 1), CO_PROGDL_STARTED);
    CHECK_EQ(read_obj(d, 0x1F56, 1), CO_PROGRAM_ID);
    CHECK_EQ(read_obj(d, 0x1F57, 1), 0);
    uint32_t v;
    CHECK_EQ(upload(d, 0x1F50, 1, &v), 0x06010001u);
    CHECK_EQ(upload(d, 0x1F56, 0, &v), 0x06090011u); /* sub 0: the loader's only */
    /* A download: not now (the bootloader takes it). */
    CHECK_EQ(download(d, 0x1F50, 1, 0x4D494F43u, 4), E_STATE);
    h_drain(d);
    uint8_t q[8] = {0x21, 0x50, 0x1F, 1, 0x00, 0x10, 0, 0}; /* segmented, 4096 bytes */
    send(d, q);
    CHECK_EQ(abort_of(answer(d)), E_STATE);
    /* Started already; clear and reset are the bootloader's; limits. */
    CHECK_EQ(download(d, 0x1F51, 1, 1, 1), 0);
    CHECK_EQ(download(d, 0x1F51, 1, 3, 1), E_STATE);
    CHECK_EQ(download(d, 0x1F51, 1, 2, 1), E_STATE);
    CHECK_EQ(download(d, 0x1F51, 1, 4, 1), 0x06090031u);
    CHECK_EQ(download(d, 0x1F56, 1, 4, 4), 0x06010002u);
    CHECK_EQ(download(d, 0x1F57, 1, 4, 4), 0x06010002u);
    CHECK_EQ(d->port.prog.handovers, 0);
    /* Stop: the hand-over asked for while the answer is made; the board
     * resets once it has left. */
    unsigned before = d->port.ntx;
    CHECK_EQ(download(d, 0x1F51, 1, 0, 1), 0);
    CHECK_EQ(d->port.prog.handovers, 1);
    CHECK_EQ(d->port.prog.handover_ntx, before);
    CHECK_EQ(d->port.ntx, before + 1u);
}

int main(void)
{
    RUN(test_loader_objects);
    RUN(test_loader_no_program);
    RUN(test_update_segmented);
    RUN(test_update_block_crc);
    RUN(test_update_block_no_crc);
    RUN(test_update_lengths);
    RUN(test_pieces);
    RUN(test_block_lost_segments);
    RUN(test_interrupted);
    RUN(test_refuse_magic);
    RUN(test_refuse_identity);
    RUN(test_refuse_product_board);
    RUN(test_refuse_too_long);
    RUN(test_refuse_crc_and_length);
    RUN(test_refuse_block_crc);
    RUN(test_refuse_not_cleared);
    RUN(test_refuse_started);
    RUN(test_refuse_nmt_state);
    RUN(test_flash_failures);
    RUN(test_flash_readback_differs);
    RUN(test_power_cut);
    RUN(test_app_side);
    return h_finish();
}
