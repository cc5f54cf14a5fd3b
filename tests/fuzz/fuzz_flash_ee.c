/*
 * fuzz_flash_ee.c - libFuzzer harness (b): the MCU boards' flash EEPROM
 * emulation (boards/common/flash_ee.c) under the parameter store of any
 * product, on a simulated flash that enforces page erase and
 * erase-before-write, as tests/unit/test_flash_ee.c drives it; here with a
 * page size, a page count and flash contents at power-on taken from the
 * input, and a power cut at every flash step of a store.
 *
 * Input (little-endian, zeros past the end):
 *   product u8 (index into product_list[]), page size u8 (modulo 8: 64,
 *   128, ..., 4096 bytes, or 7: u16, any size up to 4096), pages u8 (1 +
 *   modulo PAGES_MAX), contents u8 (modulo 4: erased; u16 count of bytes
 *   from the input; records a store wrote, then u8 count of (u16 offset,
 *   u8 xor) changes; programmed zeros), then ops until the input ends:
 *     0  an SDO write of a stored entry: u8 entry, u32 value
 *     1  a store (u8 kind, see store_frames) with a power cut at every
 *        flash step in turn (at most MAX_CUTS of them, evenly spread)
 *     2  a store with a power cut at step u16
 *     3  a store without a cut; after a full "save", a power cycle
 *     4  a power cycle
 *     5  the emulation's own API: u8 (bit 0 write), u16 address, u8
 *        length, bytes
 *
 * Invariants (abort with "fuzz invariant"; ASan and UBSan on their own):
 *  1. The emulation touches only its pages: every erase is of a whole page
 *     of its area, every program a half-word inside it, every read too.
 *  2. It never programs a half-word that is not erased.
 *  3. After a power cut at any step, each node's stored sets (PARA, LSS)
 *     restore to the old or the new set, byte for byte.
 *  4. A completed "save all" comes back at the next power-on, byte for byte.
 *  5. Its API keeps its contract: a write is refused unless even in address
 *     and length and inside one slot of the emulated size; an accepted
 *     write reads back; a read beyond the size is refused.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "co_node.h"
#include "co_port.h"
#include "flash_ee.h"
#include "fuzz_format.h"
#include "fuzz_input.h"
#include "fuzz_products.h"
#include "product.h"
#include "product_registry.h"

int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define PAGE_MAX 4096u
#define PAGES_MAX 10u
#define FLASH_BASE 0x08000000u /* where the simulated flash starts (an STM32's) */
#define FLASH_SIZE ((PAGES_MAX + 2u) * PAGE_MAX)
#define MAX_CUTS 160u
#define MAX_OPS 24u

static const char *g_product = "?";

#define FZ_CHECK(cond, ...)                                                                        \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "fuzz invariant violated (%s, page %u x %u): ", g_product,             \
                    g_flash.page, g_flash.pages);                                                  \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fprintf(stderr, "\n");                                                                 \
            abort();                                                                               \
        }                                                                                          \
    } while (0)

/* ---- the input ------------------------------------------------------- */

/* fz_t, u8(), u16(), u32(): fuzz_input.h */

/* ---- the simulated flash -------------------------------------------------- */

typedef struct sim {
    uint8_t mem[FLASH_SIZE]; /* from FLASH_BASE; the emulation's area starts one page in */
    uint32_t page;           /* page size */
    uint32_t pages;          /* pages given to the emulation */
    long steps_left;         /* flash operations before the power fails; -1: never */
    unsigned steps;          /* operations done */
} sim_t;

static sim_t g_flash;
static bool g_api; /* the API op is writing, not the store */

/* Invariant 1: [addr, addr + len) lies in the emulation's pages. */
static uint32_t area_offset(uint32_t addr, uint32_t len, const char *what)
{
    uint32_t lo = FLASH_BASE + g_flash.page;
    uint32_t hi = lo + g_flash.pages * g_flash.page;
    FZ_CHECK(addr >= lo && addr <= hi && len <= hi - addr,
             "%s of %u bytes at %08X outside the pages", what, len, addr);
    return addr - FLASH_BASE;
}

static bool power_ok(void)
{
    g_flash.steps++;
    if (g_flash.steps_left == 0) {
        return false;
    }
    if (g_flash.steps_left > 0) {
        g_flash.steps_left--;
    }
    return true;
}

static bool sim_erase(void *ctx, uint32_t addr)
{
    (void)ctx;
    uint32_t at = area_offset(addr, g_flash.page, "erase");
    FZ_CHECK(at % g_flash.page == 0u, "erase at %08X, not a page start", addr);
    if (!power_ok()) {
        /* Cut during the erase: the page is left in an undefined state. */
        for (uint32_t i = 0; i < g_flash.page; i++) {
            g_flash.mem[at + i] = (uint8_t)(i * 37u + 11u);
        }
        return false;
    }
    memset(&g_flash.mem[at], 0xFF, g_flash.page);
    return true;
}

static bool sim_program16(void *ctx, uint32_t addr, uint16_t v)
{
    (void)ctx;
    uint32_t at = area_offset(addr, 2, "program");
    FZ_CHECK((addr & 1u) == 0u, "program at odd address %08X", addr);
    /* Invariant 2, for the store's use of the emulation; a driver refuses
     * such a program (test_flash_ee.c's does), a real cell would corrupt. */
    bool erased = g_flash.mem[at] == 0xFFu && g_flash.mem[at + 1u] == 0xFFu;
    FZ_CHECK(erased || g_api, "program of a half-word that is not erased at %08X", addr);
    if (!erased) {
        return false;
    }
    if (!power_ok()) {
        return false;
    }
    g_flash.mem[at] = (uint8_t)v;
    g_flash.mem[at + 1u] = (uint8_t)(v >> 8);
    return true;
}

static void sim_read(void *ctx, uint32_t addr, void *buf, uint32_t len)
{
    (void)ctx;
    memcpy(buf, &g_flash.mem[area_offset(addr, len, "read")], len);
}

static const flash_ops_t sim_ops = {
    .erase = sim_erase, .program16 = sim_program16, .read = sim_read};
static flash_ee_t g_fe = {.ops = &sim_ops, .ctx = NULL};

/* ---- the device ------------------------------------------------------------ */

typedef struct dev {
    _Alignas(max_align_t) unsigned char mem[sizeof(product_any_t)];
    co_node_t *nodes[PRODUCT_MAX_NODES];
    unsigned nnodes;
    uint32_t now;
    co_frame_t last_sdo; /* the last SDO response of node 0 */
} dev_t;

static const product_t *g_prod;
static dev_t g_dev, g_scratch, g_snap;
static int g_port[PRODUCT_MAX_NODES]; /* each node's port: its number */

/* No controller here: every bit rate is taken. */
bool co_port_can_bitrate(void *port, uint16_t kbps)
{
    (void)port;
    (void)kbps;
    return true;
}

bool co_port_can_send(void *port, const co_frame_t *frame)
{
    if (port == &g_port[0] && frame->id == 0x580u + g_dev.nodes[0]->node_id) {
        g_dev.last_sdo = *frame;
    }
    return true;
}

bool co_port_nvm_read(void *port, uint32_t addr, void *buf, uint32_t len)
{
    (void)port;
    return flash_ee_read(&g_fe, addr, buf, len);
}

bool co_port_nvm_write(void *port, uint32_t addr, const void *buf, uint32_t len)
{
    (void)port;
    return flash_ee_write(&g_fe, addr, buf, len);
}

void co_port_nvm_prepare(void *port, uint32_t addr, uint32_t len)
{
    (void)port;
    (void)len;
    flash_ee_prepare(&g_fe, addr);
}

/* Power on: the product built afresh on the flash as it is. */
static void boot(dev_t *d)
{
    void *ports[PRODUCT_MAX_NODES] = {&g_port[0], &g_port[1]};
    g_flash.steps_left = -1;
    g_prod->create(g_prod, d->mem, ports, d->nodes);
    d->nnodes = g_prod->nodes;
    int32_t values[PRODUCT_MAX_INPUTS] = {0};
    g_prod->sample(d->mem, values, 0);
    d->now += 1000000u;
    for (unsigned k = 0; k < d->nnodes; k++) {
        co_node_start(d->nodes[k], d->now);
    }
}

static void deliver(dev_t *d, const co_frame_t *f)
{
    for (unsigned k = 0; k < d->nnodes; k++) {
        (void)co_node_poll(d->nodes[k], d->now);
        co_node_receive(d->nodes[k], f, d->now);
        (void)co_node_poll(d->nodes[k], d->now); /* a reset it asked for (the JD's save-reset) */
    }
}

/* Each node's stored sets as RAM holds them: [node][0 PARA, 1 LSS]. */
typedef uint8_t sets_t[PRODUCT_MAX_NODES][2][CO_STORE_MAX_DATA];

static bool stored_class(co_node_t *n, co_cls_t cls)
{
    return co_cfg(n)->ram_size[cls] != 0u && n->ram[cls] != NULL;
}

static void ram_sets(dev_t *d, sets_t out)
{
    memset(out, 0, sizeof(sets_t));
    for (unsigned k = 0; k < d->nnodes; k++) {
        for (unsigned c = 0; c < 2u; c++) {
            co_cls_t cls = c == 0u ? CO_CLS_PARA : CO_CLS_LSS;
            co_node_t *n = d->nodes[k];
            if (stored_class(n, cls)) {
                memcpy(out[k][c], n->ram[cls], co_cfg(n)->ram_size[cls]);
            }
        }
    }
}

/* What a power-on restores from the flash as it is now (the flash unchanged). */
static void restored_sets(sets_t out)
{
    static uint8_t keep[FLASH_SIZE];
    memcpy(keep, g_flash.mem, FLASH_SIZE);
    boot(&g_scratch);
    ram_sets(&g_scratch, out);
    memcpy(g_flash.mem, keep, FLASH_SIZE);
}

static void dump(const char *what, const uint8_t *p, unsigned len)
{
    fprintf(stderr, "  %-4s", what);
    for (unsigned i = 0; i < len; i++) {
        fprintf(stderr, " %02X", p[i]);
    }
    fprintf(stderr, "\n");
}

/* Invariants 3 and 4: now equals one of the sets allowed. */
static void compare_sets(sets_t now, sets_t a, sets_t b, const char *what)
{
    for (unsigned k = 0; k < g_dev.nnodes; k++) {
        for (unsigned c = 0; c < 2u; c++) {
            co_node_t *n = g_dev.nodes[k];
            co_cls_t cls = c == 0u ? CO_CLS_PARA : CO_CLS_LSS;
            if (!stored_class(n, cls)) {
                continue;
            }
            unsigned len = co_cfg(n)->ram_size[cls];
            if (memcmp(now[k][c], a[k][c], len) != 0 && memcmp(now[k][c], b[k][c], len) != 0) {
                dump("want", a[k][c], len);
                dump("or", b[k][c], len);
                dump("got", now[k][c], len);
                FZ_CHECK(false, "node %u class %s: %s", k, c == 0u ? "PARA" : "LSS", what);
            }
        }
    }
}

/* ---- stores ------------------------------------------------------------ */

static co_frame_t sdo_frame(co_node_t *n, uint16_t index, uint8_t sub, uint32_t v)
{
    const co_od_entry_t *e = co_node_entry(n, index, sub);
    unsigned size = e != NULL && e->size >= 1u && e->size <= 4u ? e->size : 4u;
    co_frame_t f = {.id = (uint16_t)(0x600u + n->node_id), .dlc = 8};
    f.data[0] = (uint8_t)(0x23u | (4u - size) << 2);
    f.data[1] = (uint8_t)index;
    f.data[2] = (uint8_t)(index >> 8);
    f.data[3] = sub;
    co_put_u32(&f.data[4], v);
    return f;
}

/* A write of a stored entry: the m-th from the one the input names. */
static co_frame_t entry_write(co_node_t *n, uint8_t start, uint32_t v)
{
    const co_od_t *od = co_cfg(n)->od;
    for (unsigned i = 0; i < od->count; i++) {
        const co_od_entry_t *e = &od->entries[(start + i) % od->count];
        if ((e->cls == CO_CLS_PARA || e->cls == CO_CLS_LSS) && (e->attr & CO_A_W) != 0u) {
            return sdo_frame(n, e->index, e->sub, v);
        }
    }
    return sdo_frame(n, 0x1017, 0, v);
}

/* The frames of a store of the given kind; returns how many (at most 2).
 * Only the last of them writes the flash. */
static unsigned store_frames(fz_t *in, co_node_t *n, co_frame_t f[2], bool *full_save)
{
    uint8_t kind = u8(in);
    *full_save = false;
    switch (kind % 7u) {
    case 0:
        *full_save = true;
        f[0] = sdo_frame(n, 0x1010, 1, CO_SIG_SAVE);
        return 1;
    case 1:
        f[0] = sdo_frame(n, 0x1010, (uint8_t)(2u + (kind >> 3) % 3u), CO_SIG_SAVE);
        return 1;
    case 2:
        f[0] = sdo_frame(n, 0x1011, 1, CO_SIG_LOAD);
        return 1;
    case 3:
        f[0] = sdo_frame(n, 0x1011, (uint8_t)(2u + (kind >> 3) % 3u), CO_SIG_LOAD);
        return 1;
    case 4:
        f[0] = sdo_frame(n, 0x2300, 0, 0x55AAAA55u); /* the JD's save with reset */
        return 1;
    case 5: { /* the DSTs' node-ID: the second copy commits it */
        uint8_t id = (uint8_t)(u8(in) % 127u + 1u);
        f[0] = sdo_frame(n, 0x20F0, 0, id);
        f[1] = sdo_frame(n, 0x20F1, 0, id);
        return 2;
    }
    default: { /* any stored entry (the P+F stores every write) */
        uint8_t start = u8(in);
        f[0] = entry_write(n, start, u32(in));
        return 1;
    }
    }
}

static void run_frames(const co_frame_t *f, unsigned nf)
{
    for (unsigned i = 0; i < nf; i++) {
        deliver(&g_dev, &f[i]);
    }
}

static uint8_t g_flash_snap[FLASH_SIZE];

/* A store with a power cut at each step in cuts (all of them when every). */
static void store_with_cuts(fz_t *in, bool every)
{
    static sets_t old, new_, now;
    static uint8_t flash_new[FLASH_SIZE];
    co_frame_t f[2];
    bool full;
    unsigned nf = store_frames(in, g_dev.nodes[0], f, &full);
    uint16_t at = every ? 0u : u16(in);
    /* Before: the flash and the device. */
    memcpy(g_flash_snap, g_flash.mem, FLASH_SIZE);
    memcpy(&g_snap, &g_dev, sizeof(g_dev));
    restored_sets(old);
    /* The store without a cut: its steps, and what it leaves. */
    g_flash.steps = 0;
    run_frames(f, nf);
    unsigned total = g_flash.steps;
    memcpy(flash_new, g_flash.mem, FLASH_SIZE);
    dev_t after;
    memcpy(&after, &g_dev, sizeof(g_dev));
    restored_sets(new_);
    unsigned first = every ? 0u : (total != 0u ? at % total : 0u);
    unsigned count = every ? total : (total != 0u ? 1u : 0u);
    unsigned stride = count > MAX_CUTS ? (count + MAX_CUTS - 1u) / MAX_CUTS : 1u;
    for (unsigned c = first; c < first + count; c += stride) {
        memcpy(g_flash.mem, g_flash_snap, FLASH_SIZE);
        memcpy(&g_dev, &g_snap, sizeof(g_dev));
        g_flash.steps_left = (long)c;
        run_frames(f, nf);
        boot(&g_dev); /* power back */
        ram_sets(&g_dev, now);
        char what[80];
        snprintf(what, sizeof(what),
                 "after a power cut at flash step %u of %u, neither old nor new", c, total);
        compare_sets(now, old, new_, what);
    }
    /* Go on from the completed store. */
    memcpy(g_flash.mem, flash_new, FLASH_SIZE);
    memcpy(&g_dev, &after, sizeof(g_dev));
    g_flash.steps_left = -1;
}

/* A store without a cut; a completed "save all" must come back (invariant 4). */
static void store_plain(fz_t *in)
{
    static sets_t before, now;
    co_frame_t f[2];
    bool full;
    unsigned nf = store_frames(in, g_dev.nodes[0], f, &full);
    memset(&g_dev.last_sdo, 0, sizeof(g_dev.last_sdo));
    run_frames(f, nf);
    if (!full || g_dev.last_sdo.data[0] != 0x60u) {
        return;
    }
    ram_sets(&g_dev, before);
    boot(&g_dev);
    ram_sets(&g_dev, now);
    /* Only PARA is saved by every product's "save all": LSS may differ. */
    for (unsigned k = 0; k < g_dev.nnodes; k++) {
        memcpy(before[k][1], now[k][1], CO_STORE_MAX_DATA);
    }
    compare_sets(now, before, before, "a completed save does not come back at power-on");
}

/* Invariant 5: the emulation's API against its contract. */
static void api(fz_t *in)
{
    uint8_t kind = u8(in);
    uint32_t addr = u16(in);
    uint32_t len = u8(in);
    uint8_t buf[256];
    uint32_t size = flash_ee_size(&g_fe);
    if ((kind & 1u) == 0u) {
        bool ok = flash_ee_read(&g_fe, addr, buf, len);
        FZ_CHECK(len == 0u || ok == (addr + len <= size), "read of %u bytes at %u (size %u): %s",
                 len, addr, size, ok ? "accepted" : "refused");
        return;
    }
    for (uint32_t i = 0; i < len; i++) {
        buf[i] = u8(in);
    }
    bool inside = addr < size && len <= CO_STORE_SLOT - addr % CO_STORE_SLOT;
    g_api = true; /* the caller may program a cell twice: the driver refuses */
    bool ok = flash_ee_write(&g_fe, addr, buf, len);
    g_api = false;
    FZ_CHECK(!ok || ((addr & 1u) == 0u && (len & 1u) == 0u && inside),
             "write of %u bytes at %u accepted (size %u)", len, addr, size);
    if (ok) {
        uint8_t back[256];
        FZ_CHECK(flash_ee_read(&g_fe, addr, back, len) && memcmp(back, buf, len) == 0,
                 "%u bytes written at %u do not read back", len, addr);
    }
}

/* The products by selector byte (fuzz_products.h). */
static fz_products_t g_products;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fz_products_init(&g_products);
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_t in = {data, size};
    g_prod = fz_product(&g_products, u8(&in));
    g_product = g_prod->id;
    uint8_t ps = u8(&in);
    g_flash.page = ps % 8u < 7u ? 64u << (ps % 8u) : (uint32_t)(u16(&in) % PAGE_MAX) + 1u;
    g_flash.pages = 1u + u8(&in) % PAGES_MAX;
    g_fe.base = FLASH_BASE + g_flash.page;
    g_fe.page_size = g_flash.page;
    g_fe.pages = g_flash.pages;
    g_flash.steps_left = -1;
    memset(&g_dev, 0, sizeof(g_dev));
    memset(&g_scratch, 0, sizeof(g_scratch));
    memset(g_flash.mem, 0xFF, FLASH_SIZE);
    uint8_t *area = &g_flash.mem[g_flash.page];
    uint32_t area_len = g_flash.pages * g_flash.page;
    switch (u8(&in) % 4u) {
    case 0:
        break;
    case 1: {
        uint32_t n = u16(&in) % (area_len + 1u);
        for (uint32_t i = 0; i < n; i++) {
            area[i] = u8(&in);
        }
        break;
    }
    case 2: { /* records a store wrote, then changed */
        boot(&g_dev);
        co_frame_t f = sdo_frame(g_dev.nodes[0], 0x1010, 1, CO_SIG_SAVE);
        deliver(&g_dev, &f);
        deliver(&g_dev, &f); /* both slots */
        for (unsigned m = u8(&in) % 8u; m > 0u; m--) {
            uint32_t off = u16(&in) % area_len;
            area[off] ^= u8(&in);
        }
        break;
    }
    default:
        memset(area, 0x00, area_len);
        break;
    }
    boot(&g_dev);
    for (unsigned op = 0; op < MAX_OPS && in.n > 0u; op++) {
        switch (u8(&in) % 6u) {
        case 0: {
            uint8_t start = u8(&in);
            co_frame_t f = entry_write(g_dev.nodes[0], start, u32(&in));
            deliver(&g_dev, &f);
            break;
        }
        case 1:
            store_with_cuts(&in, true);
            break;
        case 2:
            store_with_cuts(&in, false);
            break;
        case 3:
            store_plain(&in);
            break;
        case 4:
            boot(&g_dev);
            break;
        default:
            api(&in);
            break;
        }
    }
    return 0;
}
