/*
 * boot_main.c - the bootloader of the MCU boards (boot.h): decide at reset
 * whether the application runs, and otherwise be a node of this stack that
 * takes a new image over CiA 302-3 program download (co_progdl.h, the
 * loader side) into the board's application area.
 *
 * At reset, before any peripheral is touched (so that the application
 * starts from the state a reset leaves): without a hand-over block in RAM,
 * an application whose header and CRC check runs at once. Otherwise the
 * bootloader stays: identity from the hand-over (written to the boot-info
 * page when that holds another), else from the boot-info page, else the
 * defaults (boot.h); then the node boots up and answers with the
 * product's 1000h and 1018h, 1F51h:1 reading 0 (stopped: a valid program
 * is installed) or 3 (none), 1F57h status 0 or 1 ("no valid program").
 *
 * The image is written as it streams in (co_port_prog_write below): the
 * first write into a page erases it, so no SDO answer waits for more than
 * one page erase; a clear erases the first page alone, which holds the
 * header: from then on the area holds no valid program, and a power cut
 * before the new image is whole leaves a bootloader that stays. A start
 * resets the device: the application then runs from the reset, its image
 * checked again.
 *
 * The board's state lives here, in static storage (board code, not the
 * stack: the stack holds no globals).
 */
#include "board.h"
#include "boot.h"
#include "co_image.h"
#include "co_node.h"
#include "co_progdl.h"

#include <string.h>

/* Where the application writes its hand-over (each board's link scripts). */
extern boot_handover_t boot_handover_block;

static bool boot_ident_valid(const boot_ident_t *b)
{
    return b->magic == BOOT_INFO_MAGIC &&
           b->crc == co_crc32(0, (const uint8_t *)b, BOOT_IDENT_CRC_LEN) && b->node_id >= 1u &&
           b->node_id <= CO_NODE_ID_MAX && b->kbps != 0u;
}

typedef struct boot_para {
    uint16_t hb_ms; /* 1017h */
} boot_para_t;

/* The bootloader: its node, the loader's state, what it runs as, and the
 * download's progress in flash. */
typedef struct boot {
    co_node_t node;
    co_progdl_t pd;
    boot_ident_t id;
    boot_para_t para;
    const flash_ee_t *area;
    uint32_t length; /* of the image being written, from its header */
    uint32_t erased; /* offsets below this were erased by this clear */
    uint8_t odd;     /* the byte at the last odd-ended write's end, waiting for its pair */
    bool running;    /* the node has booted up: a reset node now resets the device */
} boot_t;

static boot_t boot;

/* ---- the application area ---------------------------------------------------- */

/* The image in the area: its header decoded into h when it parses, is for
 * this board, and its CRC checks over the whole length. */
static bool app_valid(const flash_ee_t *a, co_image_hdr_t *h)
{
    uint8_t b[CO_IMAGE_HDR_SIZE];
    if (a == NULL) {
        return false;
    }
    a->ops->read(a->ctx, a->base, b, sizeof b);
    if (!co_image_parse(b, h) || board_boot_check(h) != CO_PROGDL_OK) {
        return false;
    }
    uint32_t crc = co_crc32(0, &b[CO_IMAGE_CRC_FROM], CO_IMAGE_HDR_SIZE - CO_IMAGE_CRC_FROM);
    for (uint32_t at = CO_IMAGE_HDR_SIZE; at < h->length; at += sizeof b) {
        uint32_t n = h->length - at < sizeof b ? h->length - at : sizeof b;
        a->ops->read(a->ctx, a->base + at, b, n);
        crc = co_crc32(crc, b, n);
    }
    return crc == h->crc;
}

/* Keep identity id (a hand-over's) in the boot-info page, unless it holds
 * it already: before anything of the application is erased, so that a
 * power cut during the update leaves a bootloader with the product's
 * identity. A failure leaves the old record or none (a cut erase): the
 * bootloader runs on from RAM meanwhile. */
static void keep_info(const boot_ident_t *id)
{
    const flash_ee_t *f = board_boot_info();
    boot_ident_t old;
    if (f == NULL) {
        return;
    }
    f->ops->read(f->ctx, f->base, &old, sizeof old);
    if (boot_ident_valid(&old) && memcmp(&old, id, sizeof old) == 0) {
        return;
    }
    if (!f->ops->erase(f->ctx, f->base)) {
        return;
    }
    const uint8_t *p = (const uint8_t *)id;
    for (uint32_t i = 0; i < sizeof *id; i += 2u) {
        if (!f->ops->program16(f->ctx, f->base + i,
                               (uint16_t)(p[i] | (uint16_t)(p[i + 1u] << 8)))) {
            return;
        }
    }
}

/* What the bootloader runs as (boot.h: hand-over, boot-info, defaults).
 * With a hand-over: its node-ID and bit rate, the identity of the
 * installed image's header h (valid), else of the boot-info record. */
static void identity(boot_ident_t *id, bool handed, bool valid, const co_image_hdr_t *h)
{
    const flash_ee_t *f = board_boot_info();
    boot_ident_t info;
    memset(&info, 0, sizeof info);
    if (f != NULL) {
        f->ops->read(f->ctx, f->base, &info, sizeof info);
    }
    bool have_info = boot_ident_valid(&info);
    memset(id, 0, sizeof *id);
    if (handed && valid) {
        id->device_type = h->device_type;
        id->vendor = h->vendor;
        id->product = h->product;
        id->revision = h->revision;
        memcpy(id->id, h->id, sizeof id->id);
    } else if (have_info) {
        *id = info;
    }
    id->serial = board_serial(0);
    if (handed) {
        id->node_id = boot_handover_block.node_id;
        id->kbps = boot_handover_block.kbps;
        id->magic = BOOT_INFO_MAGIC;
        id->crc = co_crc32(0, (const uint8_t *)id, BOOT_IDENT_CRC_LEN);
        keep_info(id);
    } else if (!have_info) {
        id->node_id = BOOT_DEFAULT_ID;
        id->kbps = BOOT_DEFAULT_KBPS;
    }
    /* Taken: a reset from here on (a start, NMT reset node, a cut) sees
     * no hand-over. */
    boot_handover_block.magic = 0;
}

/* ---- the stack's port: program download's loader side ------------------------ */

struct co_progdl *co_port_progdl(void *port)
{
    (void)port;
    return &boot.pd;
}

uint8_t co_port_prog_check(void *port, const co_image_hdr_t *h)
{
    (void)port;
    if (memcmp(h->id, boot.id.id, CO_IMAGE_ID_LEN) != 0) {
        return CO_PROGDL_FORMAT; /* another product's */
    }
    uint8_t r = boot.area != NULL ? board_boot_check(h) : CO_PROGDL_ADDRESS;
    boot.length = h->length;
    return r;
}

bool co_port_prog_clear(void *port)
{
    (void)port;
    const flash_ee_t *a = boot.area;
    boot.erased = 0;
    if (a == NULL || !a->ops->erase(a->ctx, a->base)) {
        return false;
    }
    boot.erased = a->page_size;
    return true;
}

/* Program the half-word v at offset at, erasing its page first when this
 * download has not erased it yet (pieces come in order: at most one page
 * a piece, since pages are larger than the SDO buffer). */
static bool put16(const flash_ee_t *a, uint32_t at, uint16_t v)
{
    if (at >= boot.erased) {
        if (!a->ops->erase(a->ctx, a->base + boot.erased)) {
            return false;
        }
        boot.erased += a->page_size;
    }
    return a->ops->program16(a->ctx, a->base + at, v);
}

bool co_port_prog_write(void *port, uint32_t at, const void *buf, uint32_t len)
{
    (void)port;
    const flash_ee_t *a = boot.area;
    const uint8_t *b = buf;
    if (a == NULL) {
        return false;
    }
    for (uint32_t i = 0; i < len; i++, at++) {
        if ((at & 1u) == 0u) {
            boot.odd = b[i];
            if (at + 1u == boot.length && !put16(a, at, (uint16_t)(b[i] | 0xFF00u))) {
                return false; /* the image's last byte, alone in its half-word */
            }
        } else if (!put16(a, at - 1u, (uint16_t)(boot.odd | (uint16_t)(b[i] << 8)))) {
            return false;
        }
    }
    return true;
}

bool co_port_prog_read(void *port, uint32_t at, void *buf, uint32_t len)
{
    (void)port;
    const flash_ee_t *a = boot.area;
    if (a == NULL) {
        return false;
    }
    a->ops->read(a->ctx, a->base + at, buf, len);
    return true;
}

/* The bootloader boots whatever image checks: nothing to mark. */
bool co_port_prog_commit(void *port, const co_image_hdr_t *h)
{
    (void)port;
    (void)h;
    return true;
}

/* Start: a reset, after which the application runs if its image checks
 * (no hand-over any more). */
void co_port_prog_start(void *port)
{
    (void)port;
    board_reset();
}

/* Never started here (the bootloader runs no program): a reset, as start. */
void co_port_prog_stop(void *port)
{
    (void)port;
    board_reset();
}

/* The bit rate the bootloader runs at is the one it was given (boot.h),
 * whatever code the stack asks for: its table has none. */
bool co_port_can_bitrate(void *port, uint16_t kbps)
{
    (void)port;
    (void)kbps;
    return board_can_bitrate(boot.id.kbps);
}

/* ---- the bootloader's dictionary --------------------------------------------- */

/* 1000h and 1018h:1-4: what the bootloader runs as. */
static co_res_t read_ident(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    const boot_t *b = co_node_app(n);
    const uint32_t *w = &b->id.device_type; /* 1000h, then 1018h:1..4 */
    *v = w[e->index == 0x1000u ? 0u : e->sub];
    return CO_OK;
}

/* Its reset hook: the node-ID it was given. NMT reset node, once the
 * node runs, resets the device: a valid application then runs (the
 * hand-over is taken), as after a power cut; otherwise the bootloader is
 * back with the identity of its boot-info page. */
static void boot_reset(co_node_t *n, co_reset_t kind)
{
    const boot_t *b = co_node_app(n);
    if (kind == CO_RESET_NODE && b->running) {
        board_reset();
    }
    co_node_set_id(n, b->id.node_id);
}

static const co_node_ops_t boot_ops = {.reset = boot_reset};

/* clang-format off */
#define RO (CO_A_R)
#define IDENT CO_EXT(.read = read_ident)
static const co_od_entry_t boot_entries[] = {
    {.index = 0x1000, .sub = 0, CO_TYPE_U32, .attr = RO, IDENT, CO_NAME("Device type")},
    {.index = 0x1001, .sub = 0, CO_TYPE_U8, .attr = RO, CO_EXT(.read = co_emcy_read_register), CO_NAME("Error register")},
    {.index = 0x1017, .sub = 0, CO_TYPE_U16, .attr = CO_A_RW, CO_AT(CO_CLS_PARA, boot_para_t, hb_ms), .def = 0, CO_EXT(.write = co_hb_write_time), CO_NAME("Producer heartbeat time")},
    {.index = 0x1018, .sub = 0, CO_TYPE_U8, .attr = RO | CO_A_CONST, .def = 4, CO_NAME("Identity object")},
    {.index = 0x1018, .sub = 1, CO_TYPE_U32, .attr = RO, IDENT, CO_NAME("Vendor-ID")},
    {.index = 0x1018, .sub = 2, CO_TYPE_U32, .attr = RO, IDENT, CO_NAME("Product code")},
    {.index = 0x1018, .sub = 3, CO_TYPE_U32, .attr = RO, IDENT, CO_NAME("Revision number")},
    {.index = 0x1018, .sub = 4, CO_TYPE_U32, .attr = RO, IDENT, CO_NAME("Serial number")},
    CO_PROGDL_LOADER_ENTRIES,
};
/* clang-format on */

static const co_od_t boot_od = {.entries = boot_entries,
                                .count = sizeof(boot_entries) / sizeof(boot_entries[0])};

static const co_service_t *const boot_services[] = {&co_progdl_service, NULL};

/* No parameter store: the bootloader's node has no NVM of its own (its
 * records would lie beyond the board's EEPROM, nvm_base in main), so it
 * never reads or erases the application's. */
const co_node_cfg_t boot_cfg = {
    .od = &boot_od,
    .ops = &boot_ops,
    .services = boot_services,
    .sdo_segmented = co_sdo_segmented,
    .sdo_block = co_sdo_block,
    .sdo_domain = co_progdl_domain,
    .ram_size = {[CO_CLS_PARA] = sizeof(boot_para_t)},
    .default_node_id = BOOT_DEFAULT_ID,
};

/* The serial line's simulated inputs (the emulated boards): a bootloader
 * has none, so `set` and `fault` lines are answered with an error. */
static const product_t boot_product = {.nodes = 1};

int main(void)
{
    co_image_hdr_t h;
    bool handed = boot_handover_valid(&boot_handover_block);
    boot.area = board_boot_area();
    bool valid = app_valid(boot.area, &h);
    if (valid && !handed) {
        board_boot_app(&h);
    }
    identity(&boot.id, handed, valid, &h);
    if (!board_init()) {
        for (;;) {
            board_leds(false, true);
        }
    }
    co_progdl_init(&boot.pd, valid ? CO_PROGDL_STOPPED : CO_PROGDL_NO_PROGRAM,
                   valid ? h.program_id : 0u);
    void *const ram[CO_CLS_COUNT] = {[CO_CLS_PARA] = &boot.para};
    /* Records beyond any board's EEPROM: every store access fails (above). */
    co_node_init(&boot.node, &boot_cfg, NULL, &boot, ram, 0x80000000u);
    int32_t values[PRODUCT_MAX_INPUTS];
    uint32_t faults;
    board_sensor(&boot_product, values, &faults);
    uint32_t now = board_now_us();
    co_node_start(&boot.node, now);
    boot.running = true;
    for (;;) {
        now = board_now_us();
        co_frame_t f;
        while (board_can_receive(&f)) {
            co_node_receive(&boot.node, &f, now);
            (void)co_node_poll(&boot.node, now);
        }
#ifdef BOARD_RX_FILTER
        co_rx_id_t ids[CO_NODE_RX_IDS_MAX];
        board_can_filter(ids, co_node_rx_ids(&boot.node, ids, CO_NODE_RX_IDS_MAX));
#endif
        co_node_set_can_state(&boot.node, (co_can_state_t)board_can_state());
        uint32_t wait = co_node_poll(&boot.node, now);
        bool g;
        bool r;
        uint32_t next;
        co_node_leds(&boot.node, now, &g, &r, &next);
        board_leds(g, r);
        board_sleep(co_min_u32(wait, next));
    }
}
