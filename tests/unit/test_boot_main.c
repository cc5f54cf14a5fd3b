/*
 * test_boot_main.c - the MCU bootloader (boards/common/boot_main.c) on the
 * host, on a fake board: its flash pages in RAM (failures on demand), a
 * frame queue, a clock the test moves. Its main() runs as boot_main()
 * until the loop has nothing left to do (board_sleep with an empty queue
 * returns here), a reset (board_reset) or the application's entry
 * (board_boot_app); each power-on zeroes its state as the start-up code
 * does. What the emulated boards' integration tests cannot reach quickly
 * is here: every refusal and abort code, lost block segments, the
 * timeout, NMT, the heartbeat, a flash that fails.
 */
int boot_main(void);
#define main boot_main
#include "../../boards/common/boot_main.c"
#undef main

#include <setjmp.h>
#include <stdio.h>

#include "harness.h"

/* ---- the fake board ---------------------------------------------------------- */

#define PAGE 256u
#define PAGES 40u
#define LOAD 0x20000u
#define NODE 0x7Fu

static uint8_t area_mem[PAGE * PAGES];
static _Alignas(4) uint8_t info_mem[PAGE];
static int erase_fail_at = -1; /* erase number that fails (-1: none) */
static int erases;

typedef struct fake_flash {
    uint8_t *mem;
    uint32_t size;
} fake_flash_t;

static fake_flash_t area_ctx = {area_mem, sizeof area_mem};
static fake_flash_t info_ctx = {info_mem, sizeof info_mem};

static bool f_erase(void *ctx, uint32_t page)
{
    fake_flash_t *f = ctx;
    if (erases++ == erase_fail_at || page + PAGE > f->size) {
        return false;
    }
    memset(&f->mem[page], 0xFF, PAGE);
    return true;
}

static bool f_program16(void *ctx, uint32_t addr, uint16_t v)
{
    fake_flash_t *f = ctx;
    if (addr + 2u > f->size || co_get_u16(&f->mem[addr]) != 0xFFFFu) {
        return false; /* erase before write */
    }
    co_put_u16(&f->mem[addr], v);
    return true;
}

static void f_read(void *ctx, uint32_t addr, void *buf, uint32_t len)
{
    const fake_flash_t *f = ctx;
    memcpy(buf, &f->mem[addr], len);
}

static const flash_ops_t f_ops = {.erase = f_erase, .program16 = f_program16, .read = f_read};
static const flash_ee_t area_fe = {
    .ops = &f_ops, .ctx = &area_ctx, .base = 0, .page_size = PAGE, .pages = PAGES};
static const flash_ee_t info_fe = {
    .ops = &f_ops, .ctx = &info_ctx, .base = 0, .page_size = PAGE, .pages = 1};

boot_handover_t boot_handover_block;

/* Frames in (the test's), frames out (the bootloader's). */
#define QMAX 400u
static co_frame_t in_q[QMAX];
static unsigned in_n, in_at;
static co_frame_t out_q[QMAX];
static unsigned out_n;
static uint32_t clock_us;
static uint32_t idle_us; /* the time each idle pass of the loop takes */
static jmp_buf back;

enum { BACK_IDLE = 1, BACK_RESET, BACK_APP };

const flash_ee_t *board_boot_area(void)
{
    return &area_fe;
}

const flash_ee_t *board_boot_info(void)
{
    return &info_fe;
}

uint8_t board_boot_check(const co_image_hdr_t *h)
{
    if (h->board != CO_IMAGE_BOARD_RV32_VIRT) {
        return CO_PROGDL_FORMAT;
    }
    return h->load_addr == LOAD && h->length <= sizeof area_mem ? CO_PROGDL_OK : CO_PROGDL_ADDRESS;
}

void board_boot_app(const co_image_hdr_t *h)
{
    (void)h;
    longjmp(back, BACK_APP);
}

void board_reset(void)
{
    longjmp(back, BACK_RESET);
}

bool board_init(void)
{
    return true;
}

bool board_can_bitrate(uint16_t kbps)
{
    return kbps == 250u || kbps == 500u;
}

uint32_t board_now_us(void)
{
    return clock_us;
}

bool board_can_receive(co_frame_t *f)
{
    if (in_at == in_n) {
        return false;
    }
    *f = in_q[in_at++];
    clock_us += 100u;
    return true;
}

/* Passes of the loop in a row with work to do at once: bounded, so that
 * a bootloader that never finishes its work fails the test, not hangs it. */
static unsigned busy;

void board_sleep(uint32_t us)
{
    if (us == 0u && ++busy < 100000u) {
        return; /* work to do at once (the check after a download) */
    }
    CHECK(busy < 100000u);
    busy = 0;
    if (in_at == in_n && idle_us == 0u) {
        longjmp(back, BACK_IDLE);
    }
    clock_us += idle_us;
}

void board_leds(bool green, bool red)
{
    (void)green;
    (void)red;
}

uint32_t board_serial(unsigned node)
{
    return 0x5E000000u + node;
}

bool co_port_can_send(void *port, const co_frame_t *f)
{
    (void)port;
    if (out_n < QMAX) {
        out_q[out_n++] = *f;
    }
    return true;
}

/* ---- helpers ------------------------------------------------------------------- */

static const char product_id[] = "dst-x730-xy30";
static const uint32_t ident[4] = {0x0008019Au, 0x93u, 0x64u, 0x10003u}; /* 1000h, 1018h:1-3 */

/* An image of n bytes (header included) for the fake board. */
static uint8_t img[4096];
static uint32_t make_image(uint32_t n, uint32_t program_id, const char *id)
{
    memset(img, 0, CO_IMAGE_HDR_SIZE);
    co_put_u32(&img[0], CO_IMAGE_MAGIC);
    co_put_u16(&img[4], CO_IMAGE_HDR_SIZE);
    co_put_u16(&img[6], CO_IMAGE_VERSION);
    co_put_u32(&img[8], n);
    co_put_u32(&img[16], CO_IMAGE_BOARD_RV32_VIRT);
    for (unsigned i = 0; i < 4u; i++) {
        co_put_u32(&img[20u + 4u * i], ident[i]);
    }
    co_put_u32(&img[36], program_id);
    co_put_u32(&img[40], LOAD);
    memcpy(&img[48], id, strlen(id));
    for (uint32_t i = CO_IMAGE_HDR_SIZE; i < n; i++) {
        img[i] = (uint8_t)(i * 7u + program_id);
    }
    co_put_u32(&img[12], co_crc32(0, &img[CO_IMAGE_CRC_FROM], n - CO_IMAGE_CRC_FROM));
    return n;
}

static void put(uint16_t id, uint8_t dlc, const uint8_t *d)
{
    co_frame_t f = {.id = id, .dlc = dlc};
    memcpy(f.data, d, dlc);
    if (in_n < QMAX) {
        in_q[in_n++] = f;
    }
}

static void sdo(uint8_t c, uint16_t index, uint8_t sub, uint32_t v)
{
    uint8_t d[8] = {c, (uint8_t)index, (uint8_t)(index >> 8), sub};
    co_put_u32(&d[4], v);
    put(0x600u + NODE, 8, d);
}

static void nmt(uint8_t cs, uint8_t node)
{
    uint8_t d[2] = {cs, node};
    put(0, 2, d);
}

/* Run the bootloader on what is queued: from a power-on (its state
 * zeroed) or on from where it stopped. Returns BACK_*. */
static int run(bool power_on)
{
    out_n = 0;
    int r = setjmp(back);
    if (r == 0) {
        if (power_on) {
            memset(&boot, 0, sizeof boot);
            (void)boot_main();
        } else {
            for (;;) { /* the loop's body, from where it stopped */
                co_frame_t f;
                while (board_can_receive(&f)) {
                    rx(&boot, &f, clock_us);
                }
                board_sleep(poll(&boot, clock_us));
            }
        }
    }
    in_n = in_at = 0;
    return r;
}

/* The last frame out with identifier id, or NULL. */
static const co_frame_t *last(uint16_t id)
{
    for (unsigned i = out_n; i > 0u; i--) {
        if (out_q[i - 1u].id == id) {
            return &out_q[i - 1u];
        }
    }
    return NULL;
}

/* The answer to the one request queued: its 8 bytes. */
static const uint8_t *answer_of(void)
{
    CHECK_EQ(run(false), BACK_IDLE);
    const co_frame_t *f = last(0x580u + NODE);
    static const uint8_t none[8] = {0xEE};
    CHECK(f != NULL);
    return f != NULL ? f->data : none;
}

static uint32_t read32(uint16_t index, uint8_t sub)
{
    sdo(0x40, index, sub, 0);
    const uint8_t *a = answer_of();
    CHECK_EQ(a[0] & 0xF3u, 0x43u);
    return co_get_u32(&a[4]);
}

/* The abort code of the answer (0 for a non-abort). */
static uint32_t abort_of(const uint8_t *a)
{
    return a[0] == 0x80u ? co_get_u32(&a[4]) : 0u;
}

static uint32_t write8(uint16_t index, uint8_t sub, uint8_t v)
{
    sdo(0x2F, index, sub, v);
    return abort_of(answer_of());
}

/* A segmented download of the n bytes at p to 1F50h:1: 0 or the first
 * abort code. */
static uint32_t seg_download(const uint8_t *p, uint32_t n)
{
    sdo(0x21, 0x1F50, 1, n);
    const uint8_t *a = answer_of();
    if (a[0] != 0x60u) {
        return abort_of(a);
    }
    uint8_t t = 0;
    for (uint32_t at = 0; at < n; at += 7u) {
        uint32_t k = co_min_u32(7u, n - at);
        uint8_t d[8] = {(uint8_t)(t | ((7u - k) << 1) | (at + k == n ? 1u : 0u))};
        memcpy(&d[1], &p[at], k);
        put(0x600u + NODE, 8, d);
        a = answer_of();
        if (a[0] != (0x20u | t)) {
            return abort_of(a);
        }
        t ^= 0x10u;
    }
    return 0;
}

/* A block download of n bytes, segments listed in lose (their numbers in
 * the first block) not delivered once: 0 or the first abort code. */
static uint32_t blk_download(const uint8_t *p, uint32_t n, uint8_t lose)
{
    sdo(0xC6, 0x1F50, 1, n); /* size indicated, client CRC */
    const uint8_t *a = answer_of();
    if ((a[0] & 0xE3u) != 0xA0u) {
        return abort_of(a);
    }
    CHECK_EQ(a[0], 0xA0); /* no server CRC */
    uint8_t blksize = a[4];
    CHECK_EQ(blksize, BLK_SEGS);
    uint32_t at = 0;
    bool lost = false;
    while (at < n) {
        uint32_t start = at;
        uint8_t seq = 0;
        while (seq < blksize && at < n) {
            uint32_t k = co_min_u32(7u, n - at);
            seq++;
            uint8_t d[8] = {(uint8_t)(seq | (at + k == n ? 0x80u : 0u))};
            memcpy(&d[1], &p[at], k);
            if (!lost && seq == lose) {
                lost = true; /* this one never arrives */
            } else {
                put(0x600u + NODE, 8, d);
            }
            at += k;
        }
        a = answer_of();
        if (a[0] != 0xA2u) {
            return abort_of(a);
        }
        at = start + 7u * a[1]; /* from the first not acknowledged */
        if (at >= n && a[1] == seq) {
            at = n;
        }
    }
    uint8_t unused = (uint8_t)((7u - n % 7u) % 7u);
    uint8_t d[8] = {(uint8_t)(0xC1u | ((uint32_t)unused << 2))};
    put(0x600u + NODE, 8, d);
    a = answer_of();
    return a[0] == 0xA1u ? 0u : abort_of(a);
}

/* The bootloader with no program, the product's identity in its boot-info
 * page, booted up. */
static void blank_with_identity(void)
{
    memset(area_mem, 0xFF, sizeof area_mem);
    memset(info_mem, 0xFF, sizeof info_mem);
    boot_ident_t rec = {.magic = BOOT_INFO_MAGIC, .node_id = NODE, .kbps = 250};
    memcpy(&rec.device_type, ident, sizeof ident); /* 1000h, 1018h:1-3 in a row */
    memcpy(rec.id, product_id, strlen(product_id));
    rec.crc = co_crc32(0, &rec, BOOT_IDENT_CRC_LEN);
    memcpy(info_mem, &rec, sizeof rec);
    memset(&boot_handover_block, 0, sizeof boot_handover_block);
    erase_fail_at = -1;
    erases = 0;
    idle_us = 0;
    CHECK_EQ(run(true), BACK_IDLE);
    const co_frame_t *up = last(0x700u + NODE);
    CHECK(up != NULL && up->dlc == 1u && up->data[0] == 0u);
}

/* ---- tests ------------------------------------------------------------------------ */

static void test_identity_and_state_without_a_program(void)
{
    blank_with_identity();
    CHECK_EQ(read32(0x1000, 0), ident[0]);
    CHECK_EQ(read32(0x1018, 0), 4);
    CHECK_EQ(read32(0x1018, 1), ident[1]);
    CHECK_EQ(read32(0x1018, 3), ident[3]);
    CHECK_EQ(read32(0x1018, 4), 0x5E000000u);
    CHECK_EQ(read32(0x1001, 0), 0);
    CHECK_EQ(read32(0x1F51, 1), CO_PROGDL_NO_PROGRAM);
    CHECK_EQ(read32(0x1F57, 1), CO_PROGDL_NO_VALID << 1);
    CHECK_EQ(read32(0x1F56, 1), 0);
    CHECK_EQ(read32(0x1F50, 0), 1);
    CHECK_EQ(read32(0x1F57, 0), 1);
    /* An upload answers with the object's size: 1F51h:1 one byte. */
    sdo(0x40, 0x1F51, 1, 0);
    CHECK_EQ(answer_of()[0], 0x4F);
    sdo(0x40, 0x1017, 0, 0);
    CHECK_EQ(answer_of()[0], 0x4B);
}

static void test_dictionary_refusals(void)
{
    blank_with_identity();
    struct {
        uint8_t c;
        uint16_t index;
        uint8_t sub;
        uint32_t v;
        uint32_t code;
    } cases[] = {
        {0x40, 0x2000, 0, 0, CO_E_NO_OBJ},   {0x40, 0x1018, 5, 0, CO_E_NO_SUB},
        {0x40, 0x1000, 1, 0, CO_E_NO_SUB},   {0x40, 0x1F50, 1, 0, CO_E_WO},
        {0x2B, 0x1000, 0, 1, CO_E_RO},       {0x2F, 0x1F56, 0, 1, CO_E_RO},
        {0x23, 0x1F51, 1, 3, CO_E_LEN_HIGH}, {0x2F, 0x1017, 0, 1, CO_E_LEN_LOW},
        {0x21, 0x1017, 0, 2, CO_E_LEN},      {0xC2, 0x1F51, 1, 1, CO_E_LEN},
        {0x2F, 0x1F51, 1, 2, CO_E_VAL},      {0x2F, 0x1F51, 1, 9, CO_E_VAL},
        {0x2F, 0x1F51, 1, 1, CO_E_STATE},    {0x00, 0x1000, 0, 0, CO_E_CMD},
        {0x60, 0x1000, 0, 0, CO_E_CMD},      {0xA0, 0x1000, 0, 0, CO_E_CMD},
        {0xE0, 0x1000, 0, 0, CO_E_CMD},      {0xC1, 0x1F50, 1, 0, CO_E_CMD},
        {0x21, 0x1F50, 1, 100, CO_E_STATE}, /* not cleared */
    };
    for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        sdo(cases[i].c, cases[i].index, cases[i].sub, cases[i].v);
        const uint8_t *a = answer_of();
        if (abort_of(a) != cases[i].code) {
            printf("case %u: %02X %04X:%u answered %08X\n", i, cases[i].c, cases[i].index,
                   cases[i].sub, (unsigned)abort_of(a));
        }
        CHECK_EQ(abort_of(a), cases[i].code);
        /* The abort names the request's object. */
        CHECK_EQ(co_get_u16(&a[1]), cases[i].index);
        CHECK_EQ(a[3], cases[i].sub);
    }
    CHECK_EQ(read32(0x1F57, 1), CO_PROGDL_NOT_CLEARED << 1);
    /* An abort from the client, of nothing: no answer. */
    sdo(0x80, 0x1000, 0, 0);
    CHECK_EQ(run(false), BACK_IDLE);
    CHECK_EQ(out_n, 0);
    /* Not the bootloader's: another node's request, a short frame, RTR. */
    uint8_t d[8] = {0x40, 0x00, 0x10};
    put(0x600u + NODE - 1u, 8, d);
    put(0x600u + NODE, 7, d);
    in_q[in_n] = (co_frame_t){.id = 0x600u + NODE, .dlc = 8, .rtr = true};
    in_n++;
    CHECK_EQ(run(false), BACK_IDLE);
    CHECK_EQ(out_n, 0);
}

static void test_update_segmented_then_start(void)
{
    blank_with_identity();
    uint32_t n = make_image(1000, 0x10007, product_id);
    CHECK_EQ(write8(0x1F51, 1, 3), 0);
    CHECK_EQ(read32(0x1F57, 1), 0);
    CHECK_EQ(seg_download(img, n), 0);
    /* Verified from flash in the loop: 1F57h not busy once answered. */
    CHECK_EQ(read32(0x1F57, 1), 0);
    CHECK_EQ(read32(0x1F56, 1), 0x10007);
    CHECK_EQ(read32(0x1F51, 1), CO_PROGDL_STOPPED);
    CHECK(memcmp(area_mem, img, n) == 0);
    /* Start: answered, then the reset once the answer is on the bus. */
    sdo(0x2F, 0x1F51, 1, 1);
    idle_us = 1000;
    uint32_t t0 = clock_us;
    CHECK_EQ(run(false), BACK_RESET);
    CHECK(clock_us - t0 >= 20000u); /* a frame's time at 10 kbit/s first */
    CHECK_EQ(out_n, 1);
    CHECK_EQ(out_q[0].data[0], 0x60);
    idle_us = 0;
    /* The reset: no hand-over, a valid program: it runs. */
    CHECK_EQ(run(true), BACK_APP);
    CHECK_EQ(out_n, 0);
}

static void test_update_by_block_with_lost_segments(void)
{
    static const uint8_t lose[] = {0, 1, 5, 17};
    for (unsigned i = 0; i < sizeof lose; i++) {
        blank_with_identity();
        uint32_t n = make_image(1003u + i, 0x20000u + i, product_id);
        CHECK_EQ(write8(0x1F51, 1, 3), 0);
        CHECK_EQ(blk_download(img, n, lose[i]), 0);
        CHECK_EQ(read32(0x1F56, 1), 0x20000u + i);
        CHECK_EQ(read32(0x1F57, 1), 0);
        CHECK(memcmp(area_mem, img, n) == 0);
        CHECK_EQ(run(true), BACK_APP);
    }
}

static void test_images_refused(void)
{
    struct {
        const char *what;
        uint32_t status;
        uint32_t code;
    } cases[] = {
        {"another product", CO_PROGDL_FORMAT, CO_E_STORE},
        {"another device", CO_PROGDL_FORMAT, CO_E_STORE},
        {"not an image", CO_PROGDL_UNKNOWN, CO_E_STORE},
        {"too large for the area", CO_PROGDL_ADDRESS, CO_E_STORE},
        {"wrong CRC", CO_PROGDL_FORMAT, CO_E_STORE},
        {"longer than its header", CO_PROGDL_FORMAT, CO_E_STORE},
        {"shorter than its header", CO_PROGDL_FORMAT, CO_E_STORE},
    };
    for (unsigned i = 0; i < sizeof cases / sizeof cases[0]; i++) {
        blank_with_identity();
        uint32_t n = make_image(600, 0x30000u + i, i == 0u ? "dst-x710-xy30" : product_id);
        uint32_t send = n;
        if (i == 1u) {
            co_put_u32(&img[28], 0x65u); /* 1018h:2 */
        } else if (i == 2u) {
            img[0] ^= 1u;
        } else if (i == 3u) {
            co_put_u32(&img[8], sizeof area_mem + 2u);
        } else if (i == 4u) {
            img[300] ^= 0x40u;
        } else if (i == 5u) {
            send = n + 9u;
        } else if (i == 6u) {
            send = n - 9u;
        }
        if (i == 1u || i == 3u) {
            co_put_u32(&img[12], co_crc32(0, &img[CO_IMAGE_CRC_FROM], n - CO_IMAGE_CRC_FROM));
        }
        CHECK_EQ(write8(0x1F51, 1, 3), 0);
        uint32_t code = seg_download(img, send);
        if (code != cases[i].code) {
            printf("%s: %08X\n", cases[i].what, (unsigned)code);
        }
        CHECK_EQ(code, cases[i].code);
        CHECK_EQ(read32(0x1F57, 1), cases[i].status << 1);
        CHECK_EQ(read32(0x1F51, 1), CO_PROGDL_NO_PROGRAM);
        CHECK_EQ(read32(0x1F56, 1), 0);
        /* Nothing of a refused header reached the flash. */
        if (i <= 3u) {
            CHECK_EQ(area_mem[0], 0xFF);
        }
        /* Refused, the next download needs a clear; then it goes in. */
        n = make_image(600, 0x40000u + i, product_id);
        CHECK_EQ(seg_download(img, n), CO_E_STATE);
        CHECK_EQ(write8(0x1F51, 1, 3), 0);
        CHECK_EQ(blk_download(img, n, 0), 0);
        CHECK_EQ(read32(0x1F56, 1), 0x40000u + i);
    }
    /* An expedited download of 1F50h:1: shorter than any header. */
    blank_with_identity();
    CHECK_EQ(write8(0x1F51, 1, 3), 0);
    sdo(0x23, 0x1F50, 1, 0x12345678);
    CHECK_EQ(abort_of(answer_of()), CO_E_STORE);
    CHECK_EQ(read32(0x1F57, 1), CO_PROGDL_FORMAT << 1);
}

static void test_flash_failures(void)
{
    blank_with_identity();
    erase_fail_at = erases; /* the clear's */
    CHECK_EQ(write8(0x1F51, 1, 3), CO_E_HW);
    CHECK_EQ(read32(0x1F57, 1), CO_PROGDL_FLASH << 1);
    erase_fail_at = erases + 2; /* the clear's, the second page's, the third's */
    CHECK_EQ(write8(0x1F51, 1, 3), 0);
    uint32_t n = make_image(1000, 0x50000, product_id);
    CHECK_EQ(seg_download(img, n), CO_E_HW);
    CHECK_EQ(read32(0x1F57, 1), CO_PROGDL_FLASH << 1);
    CHECK_EQ(read32(0x1F51, 1), CO_PROGDL_NO_PROGRAM);
    /* A flash that reads back other than it took: the check after the
     * download finds it; nothing is installed. */
    erase_fail_at = -1;
    CHECK_EQ(write8(0x1F51, 1, 3), 0);
    sdo(0x21, 0x1F50, 1, n);
    CHECK_EQ(answer_of()[0], 0x60);
    uint8_t t = 0;
    for (uint32_t at = 0; at < n; at += 7u) {
        uint32_t k = co_min_u32(7u, n - at);
        uint8_t d[8] = {(uint8_t)(t | ((7u - k) << 1) | (at + k == n ? 1u : 0u))};
        memcpy(&d[1], &img[at], k);
        if (at + k == n) {
            area_mem[500] ^= 0x01u; /* a bit the flash lost */
        }
        put(0x600u + NODE, 8, d);
        CHECK_EQ(answer_of()[0], 0x20u | t);
        t ^= 0x10u;
    }
    CHECK_EQ(read32(0x1F57, 1), CO_PROGDL_FLASH << 1);
    CHECK_EQ(read32(0x1F51, 1), CO_PROGDL_NO_PROGRAM);
    CHECK_EQ(run(true), BACK_IDLE); /* and a reset stays in the bootloader */
}

static void test_transfers_cut_short(void)
{
    blank_with_identity();
    uint32_t n = make_image(700, 0x60000, product_id);
    CHECK_EQ(write8(0x1F51, 1, 3), 0);
    /* A wrong toggle bit: 05030000h. */
    sdo(0x21, 0x1F50, 1, n);
    CHECK_EQ(answer_of()[0], 0x60);
    uint8_t d[8] = {0x10};
    put(0x600u + NODE, 8, d);
    CHECK_EQ(abort_of(answer_of()), CO_E_TOGGLE);
    /* The next download needs a clear (the last one was cut). */
    CHECK_EQ(seg_download(img, n), CO_E_STATE);
    CHECK_EQ(write8(0x1F51, 1, 3), 0);
    /* A block download left idle: 05040000h after 1 s, not before. */
    sdo(0xC6, 0x1F50, 1, n);
    CHECK_EQ(answer_of()[0], 0xA0);
    clock_us += 900000u;
    CHECK_EQ(run(false), BACK_IDLE);
    CHECK(last(0x580u + NODE) == NULL);
    clock_us += 200000u;
    CHECK_EQ(run(false), BACK_IDLE);
    const co_frame_t *a = last(0x580u + NODE);
    CHECK(a != NULL && abort_of(a->data) == CO_E_TIMEOUT);
    /* NMT stop ends a transfer; SDO is not answered while stopped. */
    CHECK_EQ(write8(0x1F51, 1, 3), 0);
    sdo(0x21, 0x1F50, 1, n);
    CHECK_EQ(answer_of()[0], 0x60);
    nmt(0x02, NODE);
    sdo(0x40, 0x1000, 0, 0);
    CHECK_EQ(run(false), BACK_IDLE);
    CHECK(last(0x580u + NODE) == NULL);
    nmt(0x80, 0);
    uint8_t seg[8] = {0x00, 1, 2, 3, 4, 5, 6, 7};
    put(0x600u + NODE, 8, seg); /* the transfer ended with the stop: no segment of it */
    CHECK_EQ(abort_of(answer_of()), CO_E_CMD);
    CHECK_EQ(seg_download(img, n), CO_E_STATE); /* cut: a clear first */
    /* Operational: no clear, no download, no start (pre-operational only). */
    nmt(0x01, NODE);
    CHECK_EQ(run(false), BACK_IDLE);
    CHECK_EQ(write8(0x1F51, 1, 3), CO_E_STATE);
    CHECK_EQ(write8(0x1F51, 1, 0), 0); /* stop: nothing runs, OK */
    nmt(0x80, NODE);
    CHECK_EQ(run(false), BACK_IDLE);
    CHECK_EQ(write8(0x1F51, 1, 3), 0);
    CHECK_EQ(blk_download(img, n, 0), 0);
    nmt(0x01, 0);
    CHECK_EQ(run(false), BACK_IDLE);
    CHECK_EQ(write8(0x1F51, 1, 1), CO_E_STATE);
}

static void test_nmt_and_heartbeat(void)
{
    blank_with_identity();
    /* 1017h: a heartbeat every 50 ms, the NMT state in it. */
    sdo(0x2B, 0x1017, 0, 50);
    CHECK_EQ(answer_of()[0], 0x60);
    CHECK_EQ(read32(0x1017, 0), 50);
    /* Reset communication: the boot-up again, 1017h back to 0. */
    nmt(0x82, 0);
    CHECK_EQ(run(false), BACK_IDLE);
    const co_frame_t *up = last(0x700u + NODE);
    CHECK(up != NULL && up->data[0] == 0u);
    CHECK_EQ(read32(0x1017, 0), 0);
    /* Another node's command, a short one: nothing. */
    nmt(0x02, NODE - 1u);
    put(0, 1, (const uint8_t[]){0x02});
    sdo(0x40, 0x1000, 0, 0);
    CHECK_EQ(read32(0x1000, 0), ident[0]);
    /* Reset node: the device. */
    nmt(0x81, NODE);
    CHECK_EQ(run(false), BACK_RESET);
}

static void test_heartbeat_period(void)
{
    blank_with_identity();
    sdo(0x2B, 0x1017, 0, 50);
    CHECK_EQ(answer_of()[0], 0x60);
    nmt(0x02, 0); /* stopped: 4 in the heartbeat */
    CHECK_EQ(run(false), BACK_IDLE);
    unsigned beats = 0;
    uint8_t state = 0;
    for (unsigned k = 0; k < 100u; k++) {
        clock_us += 5000u; /* 500 ms in steps of 5 */
        CHECK_EQ(run(false), BACK_IDLE);
        const co_frame_t *hb = last(0x700u + NODE);
        if (hb != NULL) {
            beats++;
            state = hb->data[0];
        }
    }
    CHECK(beats >= 9u && beats <= 11u);
    CHECK_EQ(state, NMT_STOPPED);
}

static void test_hand_over_and_power_cut(void)
{
    /* A valid program installed, then the application's hand-over: the
     * bootloader stays, runs as the hand-over's node at its bit rate
     * with the image's identity, and keeps it in its boot-info page. */
    blank_with_identity();
    uint32_t n = make_image(800, 0x70000, product_id);
    CHECK_EQ(write8(0x1F51, 1, 3), 0);
    CHECK_EQ(seg_download(img, n), 0);
    memset(info_mem, 0xFF, sizeof info_mem); /* a board never updated before */
    boot_handover_block = (boot_handover_t){
        .magic = BOOT_HANDOVER_MAGIC, .node_id = NODE, .kbps = 500};
    CHECK_EQ(run(true), BACK_IDLE);
    CHECK_EQ(boot_handover_block.magic, 0); /* taken */
    CHECK_EQ(read32(0x1F51, 1), CO_PROGDL_STOPPED);
    CHECK_EQ(read32(0x1F56, 1), 0x70000);
    CHECK_EQ(read32(0x1018, 2), ident[2]);
    const boot_ident_t *rec = (const boot_ident_t *)(const void *)info_mem;
    CHECK_EQ(rec->magic, BOOT_INFO_MAGIC);
    CHECK_EQ(rec->kbps, 500);
    CHECK_EQ(rec->vendor, ident[1]);
    /* Clear, then a power cut: the identity from the page. */
    CHECK_EQ(write8(0x1F51, 1, 3), 0);
    CHECK_EQ(run(true), BACK_IDLE);
    CHECK_EQ(read32(0x1000, 0), ident[0]);
    CHECK_EQ(read32(0x1F51, 1), CO_PROGDL_NO_PROGRAM);
    /* A page that does not check (a cut write): the defaults, node 127 at
     * 250 kbit/s, identity 0. */
    info_mem[30] ^= 0x10u;
    CHECK_EQ(run(true), BACK_IDLE);
    CHECK_EQ(read32(0x1000, 0), 0);
    /* A hand-over block with no valid program: its node, the page's
     * identity (none here). */
    boot_handover_block = (boot_handover_t){
        .magic = BOOT_HANDOVER_MAGIC, .node_id = NODE, .kbps = 250};
    CHECK_EQ(run(true), BACK_IDLE);
    CHECK_EQ(read32(0x1000, 0), 0);
    /* A bit rate the board cannot: no boot-up (the red LED, for ever;
     * here the loop of board_leds never ends: not run). */
}

int main(void)
{
    RUN(test_identity_and_state_without_a_program);
    RUN(test_dictionary_refusals);
    RUN(test_update_segmented_then_start);
    RUN(test_update_by_block_with_lost_segments);
    RUN(test_images_refused);
    RUN(test_flash_failures);
    RUN(test_transfers_cut_short);
    RUN(test_nmt_and_heartbeat);
    RUN(test_heartbeat_period);
    RUN(test_hand_over_and_power_cut);
    return h_finish();
}
