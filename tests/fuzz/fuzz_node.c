/*
 * fuzz_node.c - libFuzzer harness (a): the node of every product on a
 * simulated board, driven by an input that is a small program (the format
 * is in fuzz_format.h): frames biased to the node's own COB-IDs (NMT, SYNC,
 * SDO expedited, segmented and block, LSS, guarding and PDO remote
 * requests, other nodes' heartbeats, anything), time steps (also across
 * the 32-bit microsecond wrap), sensor inputs within the product's limits,
 * faults, CAN controller states, a full transmit queue, stores, power
 * cycles, power cuts during a save, EEPROM read failures and arbitrary
 * stored images at power-on.
 *
 * Invariants (a violation aborts with "fuzz invariant" and what broke;
 * ASan and UBSan abort on their own findings):
 *  1. Frames: DLC <= 8, 11-bit identifier, never a remote frame; nothing on
 *     a CiA 301 restricted COB-ID but the node's own services (SDO response
 *     0x580 + ID, boot-up / heartbeat / guarding 0x700 + ID, LSS response
 *     0x7E4 where the product is an LSS slave); a node without a node-ID
 *     sends only LSS responses; SDO and LSS responses are 8 bytes, NMT error
 *     control 1.
 *  2. Every boot-up (power-on, reset node or communication) is followed by
 *     a node that answers an expedited read of 0x1000 with its device type.
 *  3. Life guarding (the guard service's event, EMCY 8130h) never fires
 *     before guard time x life factor since the last guard request the
 *     node answered (the shortest non-zero product the two had since, when
 *     the master changed them in between).
 *  4. After a power cut during any frame's handling, every stored set
 *     (the RAM struct of classes PARA and LSS, byte for byte, after the
 *     restore at the next power-on) is the one before that frame or the
 *     one a completed handling stores.
 *  5. SDO: a request in pre-operational or operational gets exactly one
 *     answer (none to a client's abort; block transfers as CiA 301 says);
 *     none in stopped.
 *  6. co_node_poll never asks for a delay longer than the longest timer
 *     configured since power-on (a longer one is a wrapped time stamp), and
 *     never keeps asking to be called again at once (a busy loop).
 *  7. A node writes the EEPROM only inside its own area.
 *  8. Nothing is handed to the port while the node's controller is bus-off.
 *  9. An expedited SDO write the node confirmed reads back as written (but
 *     0x1010 and 0x1011, whose signatures read as 1).
 * 10. The LEDs never ask to be looked at again at once.
 *
 * The simulated board meets the stack's contract and no more: it polls at
 * the delays the node asks for (until a per-input budget is spent) and at
 * least every 2^30 us, samples every 5 ms (within a budget), and feeds
 * frames with poll before and after, as boards/common/mcu_main.c does.
 *
 * FUZZ_TRACE=1 in the environment prints every op and frame (to follow a
 * finding: build-fuzz/bin/fuzz_node FILE).
 *
 * White box: some invariants read the node's own state (the guard's event
 * and request, the SDO server's state from sdo_internal.h, the configured
 * timers), so a change of those fields must be followed here.
 */
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "co_filter.h"
#include "co_node.h"
#include "co_port.h"
#include "fuzz_format.h"
#include "fuzz_input.h"
#include "fuzz_products.h"
#include "product.h"
#include "product_registry.h"
#include "sdo_internal.h"

/* libFuzzer's entry points. */
int LLVMFuzzerInitialize(int *argc, char ***argv);
int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size);

#define NVM_SIZE (PRODUCT_MAX_NODES * CO_STORE_NVM_SIZE)
#define STORE_MAGIC 0x53506F43u /* "CoPS", the record format of co_store.h */
#define MAX_POLLS 4000u         /* polls at the node's deadlines, per input */
#define MAX_SAMPLES 2000u       /* sensor samples (10 s of them), per input */
#define MAX_GAP (1u << 30)      /* the board polls at least this often (us) */
#define FL_MAX 64u              /* frames one op may generate */

static int g_trace;

/* ---- failures --------------------------------------------------------- */

static const char *g_product = "?";
static unsigned g_op;

#define FZ_CHECK(cond, ...)                                                                        \
    do {                                                                                           \
        if (!(cond)) {                                                                             \
            fprintf(stderr, "fuzz invariant violated (%s, op %u): ", g_product, g_op);             \
            fprintf(stderr, __VA_ARGS__);                                                          \
            fprintf(stderr, "\n");                                                                 \
            abort();                                                                               \
        }                                                                                          \
    } while (0)

/* ---- the input -------------------------------------------------------- */

/* fz_t, u8(), u16(), u32(): fuzz_input.h */

/* ---- the simulated device --------------------------------------------- */

typedef struct dev dev_t;

typedef struct port {
    dev_t *dev;
    unsigned k;   /* the node it serves */
    bool tx_full; /* the transmit queue refuses frames */
} port_t;

/* What the invariants remember of one node. */
typedef struct watch {
    bool bootup;         /* a boot-up was sent: check invariant 2 */
    bool in_guard_rtr;   /* a guard request is being handled */
    bool guard_answered; /* some guard request was answered since power-on */
    bool guard_lost;     /* the guard event was active at the last look */
    uint64_t guard_at;   /* time of the last answered guard request */
    uint64_t guard_life; /* the shortest non-zero guard time x life factor since (us) */
    uint64_t bound;      /* longest timer configured since power-on (us) */
    unsigned sdo_count;  /* SDO responses during the current frame */
    co_frame_t sdo_last; /* the last of them */
    unsigned zero_polls; /* polls in a row that asked to be called again at once */
} watch_t;

struct dev {
    _Alignas(max_align_t) unsigned char mem[sizeof(product_any_t)];
    const product_t *prod;
    co_node_t *nodes[PRODUCT_MAX_NODES];
    unsigned nnodes;
    port_t port[PRODUCT_MAX_NODES];
    watch_t w[PRODUCT_MAX_NODES];
    uint8_t nvm[NVM_SIZE];
    long cut_after; /* EEPROM bytes that may still be written; -1: no cut */
    bool cut_hit;   /* a write was refused: the power is gone */
    bool nvm_read_fails;
    bool scratch;  /* a device booted only to see what a restore gives */
    bool checking; /* check_alive's own read is being delivered */
    uint64_t now;  /* virtual time, us (the node sees the low 32 bits) */
    uint64_t next_sample;
    unsigned polls, samples;
    int32_t truth[PRODUCT_MAX_INPUTS];
    uint32_t faults;
};

static dev_t g_dev;     /* the device under test */
static dev_t g_scratch; /* restores of an EEPROM image */
static dev_t g_snap;    /* the device before a frame handled during a power cut */

static uint32_t now32(const dev_t *d)
{
    return (uint32_t)d->now;
}

static uint64_t max64(uint64_t a, uint64_t b)
{
    return a > b ? a : b;
}

static uint64_t min64(uint64_t a, uint64_t b)
{
    return a < b ? a : b;
}

static void trace_frame(const char *what, unsigned k, const co_frame_t *f)
{
    if (!g_trace) {
        return;
    }
    fprintf(stderr, "  %-3s node%u %03X%s [%u]", what, k, f->id, f->rtr ? " RTR" : "", f->dlc);
    for (unsigned i = 0; i < f->dlc && i < 8u; i++) {
        fprintf(stderr, " %02X", f->data[i]);
    }
    fprintf(stderr, "\n");
}

/* A numeric entry's value as the bus sees it (0 where it does not exist). */
static uint32_t od_value(co_node_t *n, uint16_t index, uint8_t sub)
{
    const co_od_entry_t *e = co_node_entry(n, index, sub);
    uint32_t v = 0;
    if (e != NULL && e->type != CO_T_VSTR) {
        (void)co_od_get(n, e, &v);
    }
    return v;
}

/* Node life time: guard time (ms) x life time factor, in us. */
static uint64_t guard_life_us(co_node_t *n)
{
    return (uint64_t)od_value(n, 0x100C, 0) * od_value(n, 0x100D, 0) * 1000u;
}

/* The longest timer of the node's present configuration (us). */
static uint64_t config_bound(co_node_t *n)
{
    uint64_t b = CO_SDO_TIMEOUT_US;
    b = max64(b, CO_STORE_QUIET_US); /* the store's pause (co_store_poll) */
    b = max64(b, (uint64_t)n->hb.period_ms * 1000u);
    for (unsigned j = 0; j < CO_TPDO_MAX; j++) {
        b = max64(b, (uint64_t)n->tpdo[j].event_ms * 1000u);
        b = max64(b, n->tpdo[j].inhibit_us);
    }
    b = max64(b, guard_life_us(n));
    b = max64(b, (uint64_t)n->hbc.time_ms * 1000u);
    return b;
}

/* CiA 301 7.3.5 restricted CAN-IDs, written out independently of
 * co_cobid_restricted() (LLVMFuzzerInitialize compares the two). */
static bool restricted(uint32_t id)
{
    return id == 0x000u || (id >= 0x001u && id <= 0x07Fu) || (id >= 0x101u && id <= 0x180u) ||
           (id >= 0x581u && id <= 0x5FFu) || (id >= 0x601u && id <= 0x67Fu) ||
           (id >= 0x6E0u && id <= 0x6FFu) || (id >= 0x701u && id <= 0x77Fu) ||
           (id >= 0x780u && id <= 0x7FFu);
}

static bool has_id(const co_node_t *n)
{
    return n->node_id >= 1u && n->node_id <= 127u;
}

/* A guard request was answered now: invariant 3 counts from here. */
static void guard_answered(const dev_t *d, watch_t *w)
{
    w->guard_answered = true;
    w->guard_at = d->now;
    w->guard_life = UINT64_MAX;
}

/* Invariant 1, on every frame a node hands to the port. */
static void check_frame(dev_t *d, unsigned k, const co_frame_t *f)
{
    co_node_t *n = d->nodes[k];
    watch_t *w = &d->w[k];
    trace_frame(d->scratch ? "tx'" : "tx", k, f);
    FZ_CHECK(f->dlc <= 8u, "frame %03X with DLC %u", f->id, f->dlc);
    FZ_CHECK(f->id <= 0x7FFu, "frame identifier %X beyond 11 bits", f->id);
    FZ_CHECK(!f->rtr, "remote frame %03X sent", f->id);
    FZ_CHECK(n->can_state != CO_CAN_BUSOFF, "frame %03X handed to the port while bus-off", f->id);
    bool id_ok = has_id(n);
    bool sdo = id_ok && f->id == 0x580u + n->node_id;
    bool ec = id_ok && f->id == 0x700u + n->node_id;
    bool lss = co_cfg_has_service(co_cfg(n), &co_lss_service) && f->id == 0x7E4u;
    FZ_CHECK(id_ok || lss, "frame %03X from a node without node-ID (%02X)", f->id, n->node_id);
    FZ_CHECK(!restricted(f->id) || sdo || ec || lss, "frame on restricted COB-ID %03X (node-ID %u)",
             f->id, n->node_id);
    if (sdo) {
        FZ_CHECK(f->dlc == 8u, "SDO response with DLC %u", f->dlc);
        w->sdo_count++;
        w->sdo_last = *f;
    }
    if (lss) {
        FZ_CHECK(f->dlc == 8u, "LSS response with DLC %u", f->dlc);
    }
    if (ec) {
        FZ_CHECK(f->dlc == 1u, "NMT error control frame with DLC %u", f->dlc);
        if (f->data[0] == 0u) {
            w->bootup = true;
        }
        if (w->in_guard_rtr) {
            guard_answered(d, w);
        }
    }
}

/* ---- the port (co_port.h) --------------------------------------------- */

/* No controller here: every bit rate is taken. */
bool co_port_can_bitrate(void *port, uint16_t kbps)
{
    (void)port;
    (void)kbps;
    return true;
}

bool co_port_can_send(void *port, const co_frame_t *frame)
{
    port_t *p = port;
    check_frame(p->dev, p->k, frame);
    return !p->tx_full;
}

bool co_port_nvm_read(void *port, uint32_t addr, void *buf, uint32_t len)
{
    port_t *p = port;
    dev_t *d = p->dev;
    if (d->nvm_read_fails || addr > NVM_SIZE || len > NVM_SIZE - addr) {
        return false;
    }
    memcpy(buf, &d->nvm[addr], len);
    return true;
}

/* Invariant 7: node k's records live in [k, k + 1) x CO_STORE_NVM_SIZE;
 * what names the access (writes, erases) for the report. */
static void check_area(const port_t *p, uint32_t addr, uint32_t len, const char *what)
{
    uint32_t base = p->k * CO_STORE_NVM_SIZE;
    FZ_CHECK(addr >= base && addr <= base + CO_STORE_NVM_SIZE &&
                 len <= base + CO_STORE_NVM_SIZE - addr,
             "node %u %s EEPROM bytes %u..%u outside its area", p->k, what, addr, addr + len);
}

bool co_port_nvm_write(void *port, uint32_t addr, const void *buf, uint32_t len)
{
    port_t *p = port;
    dev_t *d = p->dev;
    check_area(p, addr, len, "writes");
    const uint8_t *b = buf;
    for (uint32_t i = 0; i < len; i++) {
        if (d->cut_after == 0) {
            d->cut_hit = true;
            return false; /* the power is gone: nothing more reaches the EEPROM */
        }
        if (d->cut_after > 0) {
            d->cut_after--;
        }
        d->nvm[addr + i] = b[i];
    }
    return true;
}

/* An erase ahead: the bytes read as erased, as on a flash board, so that
 * erasing a slot whose record a restore still needs breaks invariant 4.
 * Within the node's area (invariant 7); nothing once the power is gone. */
void co_port_nvm_prepare(void *port, uint32_t addr, uint32_t len)
{
    port_t *p = port;
    dev_t *d = p->dev;
    check_area(p, addr, len, "erases");
    if (d->cut_after == 0) {
        d->cut_hit = true;
        return;
    }
    memset(&d->nvm[addr], 0xFF, len);
}

/* ---- driving the nodes ------------------------------------------------- */

static void check_alive(dev_t *d, unsigned k);

/* After each call into node k: invariant 3 and the timer bound. */
static void after_node(dev_t *d, unsigned k)
{
    co_node_t *n = d->nodes[k];
    watch_t *w = &d->w[k];
    w->bound = max64(w->bound, config_bound(n));
    /* The master may change guard time and life factor after a request;
     * the node may then use any of the values it had since (the life time
     * it had at the request, or when it was set): the shortest counts. */
    uint64_t life = guard_life_us(n);
    if (life != 0u) {
        w->guard_life = min64(w->guard_life, life);
    }
    bool lost = n->guard.lost;
    if (lost && !w->guard_lost) {
        FZ_CHECK(w->guard_answered, "life guarding event with no guard request ever answered");
        FZ_CHECK(d->now - w->guard_at >= w->guard_life,
                 "life guarding event %llu us after the last guard request; life time %llu us "
                 "(the shortest since: %llu us)",
                 (unsigned long long)(d->now - w->guard_at), (unsigned long long)life,
                 (unsigned long long)w->guard_life);
    }
    w->guard_lost = lost;
}

/* Poll node k; invariant 6 on what it asks for. */
static uint32_t poll_one(dev_t *d, unsigned k)
{
    uint32_t delay = co_node_poll(d->nodes[k], now32(d));
    after_node(d, k);
    watch_t *w = &d->w[k];
    FZ_CHECK(delay == CO_NEVER || delay <= w->bound,
             "poll asks for a delay of %u us, the longest timer configured is %llu us", delay,
             (unsigned long long)w->bound);
    w->zero_polls = delay == 0u ? w->zero_polls + 1u : 0u;
    FZ_CHECK(w->zero_polls <= 4u, "poll keeps asking to be called again at once");
    return delay;
}

static uint32_t poll_all(dev_t *d)
{
    uint32_t m = CO_NEVER;
    for (unsigned k = 0; k < d->nnodes; k++) {
        m = co_min_u32(m, poll_one(d, k));
    }
    return m;
}

static void alive_checks(dev_t *d)
{
    for (unsigned k = 0; k < d->nnodes; k++) {
        if (d->w[k].bootup) {
            check_alive(d, k);
        }
    }
}

/* What an SDO request found in node k before it was handled. */
typedef struct pre {
    uint8_t node_id, state, sdo_state, can_state;
} pre_t;

/* Invariant 5: the answers node k gave to frame f. */
static void check_sdo_answers(const dev_t *d, unsigned k, const pre_t *pre, const co_frame_t *f)
{
    unsigned count = d->w[k].sdo_count;
    if (f->rtr || f->dlc != 8u || pre->node_id < 1u || pre->node_id > 127u ||
        f->id != 0x600u + pre->node_id || pre->can_state == CO_CAN_BUSOFF) {
        return;
    }
    if (pre->state != CO_NMT_PREOP && pre->state != CO_NMT_OPERATIONAL) {
        FZ_CHECK(count == 0u, "SDO answered in NMT state %02X", pre->state);
        return;
    }
    unsigned ccs = f->data[0] >> 5;
    unsigned lo = 1;
    unsigned hi = 1;
    switch (pre->sdo_state) {
    case SDO_BLK_DL: /* a sub-block segment: acknowledged at the block's end */
        lo = 0;
        hi = f->data[0] == 0x80u ? 0u : 1u;
        break;
    case SDO_BLK_UL_START:
    case SDO_BLK_UL: /* the server sends a block of segments */
        lo = ccs == CCS_ABORT ? 0u : 1u;
        hi = ccs == CCS_ABORT ? 0u : 128u;
        break;
    case SDO_BLK_UL_END: /* the client's end needs no answer */
        if (ccs == CCS_ABORT || (ccs == CCS_BLOCK_UPLOAD && (f->data[0] & 0x03u) == 1u)) {
            lo = hi = 0;
        }
        break;
    default:
        if (ccs == CCS_ABORT) {
            lo = hi = 0;
        }
        break;
    }
    FZ_CHECK(count >= lo && count <= hi,
             "SDO request %02X %02X %02X %02X (server state %u) got %u answers, expected %u..%u",
             f->data[0], f->data[1], f->data[2], f->data[3], pre->sdo_state, count, lo, hi);
}

/* An expedited SDO write to node k, before it is handled: its entry, or NULL. */
static const co_od_entry_t *expedited_write(co_node_t *n, const co_frame_t *f)
{
    if (f->rtr || f->dlc != 8u || !has_id(n) || f->id != 0x600u + n->node_id ||
        (f->data[0] & 0xE2u) != 0x22u) {
        return NULL;
    }
    const co_od_entry_t *e = co_node_entry(n, co_get_u16(&f->data[1]), f->data[3]);
    if (e == NULL || e->type == CO_T_VSTR || (e->attr & CO_A_R) == 0u || e->size > 4u ||
        e->index == 0x1010u || e->index == 0x1011u) {
        return NULL; /* "save" and "load" read 1, not their signatures (CiA 301) */
    }
    return e;
}

/* Invariant 9: a confirmed expedited write reads back as written. */
static void check_read_back(dev_t *d, unsigned k, const co_od_entry_t *e, const co_frame_t *f)
{
    const co_frame_t *r = &d->w[k].sdo_last;
    if (d->w[k].sdo_count != 1u || r->data[0] != 0x60u ||
        memcmp(&r->data[1], &f->data[1], 3) != 0) {
        return; /* refused (or not answered: invariant 5) */
    }
    uint32_t mask = e->size >= 4u ? 0xFFFFFFFFu : (1u << (8u * e->size)) - 1u;
    uint32_t v = 0;
    (void)co_od_get(d->nodes[k], e, &v);
    FZ_CHECK((v & mask) == (co_get_u32(&f->data[4]) & mask),
             "%04X sub %u written %08X reads back %08X", e->index, e->sub,
             co_get_u32(&f->data[4]) & mask, v & mask);
}

/* One frame on the bus, as a board feeds it: poll, receive, poll. */
static void deliver(dev_t *d, const co_frame_t *f)
{
    trace_frame("rx", 0, f);
    for (unsigned k = 0; k < d->nnodes; k++) {
        (void)poll_one(d, k);
    }
    for (unsigned k = 0; k < d->nnodes; k++) {
        co_node_t *n = d->nodes[k];
        watch_t *w = &d->w[k];
        pre_t pre = {n->node_id, n->nmt.state, n->sdo.state, n->can_state};
        w->in_guard_rtr = f->rtr && has_id(n) && f->id == 0x700u + n->node_id;
        w->sdo_count = 0;
        const co_od_entry_t *written = expedited_write(n, f);
        co_node_receive(n, f, now32(d));
        if (written != NULL) {
            check_read_back(d, k, written, f);
        }
        if (w->in_guard_rtr && n->can_state == CO_CAN_BUSOFF && n->guard.kick &&
            n->guard.deadline == now32(d)) {
            guard_answered(d, w); /* taken, though the answer was not sent (bus-off) */
        }
        w->in_guard_rtr = false;
        after_node(d, k);
        check_sdo_answers(d, k, &pre, f);
    }
    for (unsigned k = 0; k < d->nnodes; k++) {
        (void)poll_one(d, k);
    }
    if (!d->scratch && !d->checking) {
        alive_checks(d);
    }
}

/* Invariant 2: after a boot-up node k answers an expedited read of 0x1000. */
static void check_alive(dev_t *d, unsigned k)
{
    co_node_t *n = d->nodes[k];
    d->w[k].bootup = false;
    (void)poll_all(d); /* first what the boot leads to (an error behaviour may stop it) */
    if (!has_id(n) || n->can_state == CO_CAN_BUSOFF ||
        (n->nmt.state != CO_NMT_PREOP && n->nmt.state != CO_NMT_OPERATIONAL)) {
        return; /* no node-ID, off the bus, or stopped by its error behaviour */
    }
    bool full = d->port[k].tx_full;
    d->port[k].tx_full = false;
    co_frame_t f = {
        .id = (uint16_t)(0x600u + n->node_id), .dlc = 8, .data = {0x40, 0x00, 0x10, 0x00}};
    d->checking = true; /* the other nodes' checks come after this one */
    deliver(d, &f);
    d->checking = false;
    d->port[k].tx_full = full;
    const co_frame_t *r = &d->w[k].sdo_last;
    uint32_t devtype = od_value(n, 0x1000, 0);
    FZ_CHECK(
        d->w[k].sdo_count == 1u && r->data[0] == 0x43u && r->data[1] == 0x00u &&
            r->data[2] == 0x10u && r->data[3] == 0x00u && co_get_u32(&r->data[4]) == devtype,
        "after a boot-up node-ID %u does not answer a read of 0x1000 (%u answers, last %02X %02X "
        "%02X %02X %08X)",
        n->node_id, d->w[k].sdo_count, r->data[0], r->data[1], r->data[2], r->data[3],
        co_get_u32(&r->data[4]));
}

static void sample(dev_t *d)
{
    d->prod->sample(d->mem, d->truth, d->faults);
}

/* Create the product in d->mem and power it on with d->nvm as it is. */
static void boot(dev_t *d)
{
    void *ports[PRODUCT_MAX_NODES];
    for (unsigned k = 0; k < PRODUCT_MAX_NODES; k++) {
        d->port[k].dev = d;
        d->port[k].k = k;
        d->port[k].tx_full = false;
        ports[k] = &d->port[k];
    }
    memset(d->w, 0, sizeof(d->w));
    d->cut_after = -1;
    d->cut_hit = false;
    d->prod->create(d->prod, d->mem, ports, d->nodes);
    d->nnodes = d->prod->nodes;
    sample(d); /* a board reads its sensor before booting */
    for (unsigned k = 0; k < d->nnodes; k++) {
        co_node_start(d->nodes[k], now32(d));
        after_node(d, k);
    }
    d->next_sample = d->now + CO_FILTER_PERIOD_US;
    if (!d->scratch) {
        alive_checks(d);
    }
}

static void power_cycle(dev_t *d)
{
    if (g_trace) {
        fprintf(stderr, "power cycle\n");
    }
    d->now += 1000000u; /* a second without power */
    boot(d);
}

/*
 * Time passes: us microseconds, the node polled at the delays it asks for
 * (until the input's poll budget is spent) and at least every MAX_GAP, the
 * sensor sampled every 5 ms when sampled (until the sample budget is).
 */
static void advance(dev_t *d, uint64_t us, bool sampled)
{
    if (g_trace) {
        fprintf(stderr, "advance %llu us%s\n", (unsigned long long)us,
                sampled ? "" : " (no samples)");
    }
    uint64_t end = d->now + us;
    for (;;) {
        uint32_t delay = poll_all(d);
        bool sampling = sampled && d->samples < MAX_SAMPLES;
        if (sampling && d->now >= d->next_sample) {
            sample(d);
            d->samples++;
            d->next_sample += CO_FILTER_PERIOD_US;
            continue;
        }
        if (delay == 0u) {
            continue; /* called again at once, as a board does (invariant 6 bounds it) */
        }
        if (d->now >= end) {
            break;
        }
        uint64_t next = end;
        if (sampling) {
            next = min64(next, d->next_sample);
        }
        if (delay != CO_NEVER && d->polls < MAX_POLLS) {
            next = min64(next, d->now + delay);
        }
        d->now = min64(next, d->now + MAX_GAP);
        d->polls++;
    }
    if (!sampled || d->samples >= MAX_SAMPLES) {
        d->next_sample = d->now + CO_FILTER_PERIOD_US; /* sampling restarts from now */
    }
}

/* ---- stored sets: images at power-on, power cuts ------------------------ */

static bool stored_class(co_node_t *n, co_cls_t cls)
{
    return co_cfg(n)->ram_size[cls] != 0u && n->ram[cls] != NULL;
}

static uint32_t slot_addr(co_node_t *n, co_cls_t cls, unsigned slot)
{
    return n->nvm_base + ((cls == CO_CLS_PARA ? 0u : 2u) + slot) * CO_STORE_SLOT;
}

/* Every node's stored sets as a restore from nvm leaves them in RAM:
 * out[k][c] for class PARA (c = 0) and LSS (c = 1). */
typedef uint8_t sets_t[PRODUCT_MAX_NODES][2][CO_STORE_MAX_DATA];

static void restored_sets(const uint8_t *nvm, bool read_fails, sets_t out)
{
    dev_t *s = &g_scratch;
    s->prod = g_dev.prod;
    s->scratch = true;
    s->now = g_dev.now;
    s->nvm_read_fails = read_fails;
    memcpy(s->truth, g_dev.truth, sizeof(s->truth));
    s->faults = g_dev.faults;
    memcpy(s->nvm, nvm, NVM_SIZE);
    boot(s);
    memset(out, 0, sizeof(sets_t));
    for (unsigned k = 0; k < s->nnodes; k++) {
        for (unsigned c = 0; c < 2u; c++) {
            co_cls_t cls = c == 0u ? CO_CLS_PARA : CO_CLS_LSS;
            co_node_t *n = s->nodes[k];
            if (stored_class(n, cls)) {
                memcpy(out[k][c], n->ram[cls], co_cfg(n)->ram_size[cls]);
            }
        }
    }
}

static void dump(const char *what, const uint8_t *p, unsigned len)
{
    fprintf(stderr, "  %-4s", what);
    for (unsigned i = 0; i < len; i++) {
        fprintf(stderr, " %02X", p[i]);
    }
    fprintf(stderr, "\n");
}

/* Invariant 4: the device, just powered on after a cut, holds old or new. */
static void check_sets_after_cut(dev_t *d, sets_t old, sets_t new_)
{
    for (unsigned k = 0; k < d->nnodes; k++) {
        for (unsigned c = 0; c < 2u; c++) {
            co_cls_t cls = c == 0u ? CO_CLS_PARA : CO_CLS_LSS;
            co_node_t *n = d->nodes[k];
            if (!stored_class(n, cls)) {
                continue;
            }
            unsigned len = co_cfg(n)->ram_size[cls];
            const uint8_t *now = n->ram[cls];
            if (memcmp(now, old[k][c], len) != 0 && memcmp(now, new_[k][c], len) != 0) {
                dump("old", old[k][c], len);
                dump("new", new_[k][c], len);
                dump("now", now, len);
                FZ_CHECK(false,
                         "node %u class %s after a power cut is neither the old nor the new set", k,
                         c == 0u ? "PARA" : "LSS");
            }
        }
    }
}

/*
 * Power-on image of one slot: a record of the format co_store.h gives
 * (header, data, CRC-32), or raw bytes. defs holds every node's default sets.
 */
static void put_image(fz_t *in, dev_t *d, sets_t defs)
{
    uint8_t what = u8(in);
    uint32_t seq = u8(in);
    uint8_t wsel = u8(in);
    unsigned k = (what & 1u) % d->nnodes;
    co_cls_t cls = (what & 2u) != 0u ? CO_CLS_LSS : CO_CLS_PARA;
    unsigned slot = (what >> 2) & 1u;
    unsigned kind = (unsigned)(what >> 3) % FZ_IMG_COUNT;
    co_node_t *n = d->nodes[k];
    uint8_t *p = &d->nvm[slot_addr(n, cls, slot)];
    if (kind == FZ_IMG_RAW || !stored_class(n, cls)) {
        unsigned len = u8(in) % (CO_STORE_SLOT + 1u);
        for (unsigned i = 0; i < len; i++) {
            p[i] = u8(in);
        }
        return;
    }
    uint32_t len = kind == FZ_IMG_DEFAULTS ? 0u : co_cfg(n)->ram_size[cls];
    uint8_t data[CO_STORE_MAX_DATA];
    memcpy(data, defs[k][cls == CO_CLS_PARA ? 0 : 1], sizeof(data));
    if (kind == FZ_IMG_BYTES) {
        for (unsigned m = u8(in) % 4u; m > 0u; m--) {
            uint8_t off = u8(in);
            data[off % len] = u8(in);
        }
    } else if (kind == FZ_IMG_ENTRIES || kind == FZ_IMG_FLIPPED) {
        const co_od_t *od = co_cfg(n)->od;
        for (unsigned m = u8(in) % 4u; m > 0u; m--) {
            /* The m-th entry of the class from the one the input names. */
            unsigned start = u8(in);
            uint32_t v = u32(in);
            for (unsigned i = 0; i < od->count; i++) {
                const co_od_entry_t *e = &od->entries[(start + i) % od->count];
                if (e->cls == cls && e->type != CO_T_VSTR) {
                    co_od_native(e, v, &data[e->off]);
                    break;
                }
            }
        }
    }
    static const uint32_t writes_sel[4] = {1u, 99999u, 100000u, 0xFFFFFFFFu};
    uint32_t writes = (wsel & 0x80u) != 0u ? writes_sel[wsel & 3u] : seq;
    co_put_u32(&p[0], STORE_MAGIC);
    co_put_u32(&p[4], co_store_layout_hash(n, cls));
    co_put_u32(&p[8], seq);
    co_put_u32(&p[12], writes);
    co_put_u16(&p[16], (uint16_t)len);
    p[18] = kind == FZ_IMG_DEFAULTS ? 0x01u : 0x00u;
    p[19] = (uint8_t)cls;
    p[20] = p[21] = p[22] = p[23] = 0;
    memcpy(&p[CO_STORE_HDR], data, len);
    co_put_u32(&p[CO_STORE_HDR + len], co_crc32(0, p, CO_STORE_HDR + len));
    if (kind == FZ_IMG_FLIPPED) {
        uint8_t at = u8(in);
        p[at % (CO_STORE_HDR + len + 4u)] ^= (uint8_t)(u8(in) | 1u);
    }
}

/* ---- frames an op generates --------------------------------------------- */

typedef struct flist {
    co_frame_t f[FL_MAX];
    unsigned n;
} flist_t;

static co_frame_t *add(flist_t *l, uint32_t id, uint8_t dlc)
{
    static co_frame_t overflow;
    co_frame_t *f = l->n < FL_MAX ? &l->f[l->n++] : &overflow;
    memset(f, 0, sizeof(*f));
    f->id = (uint16_t)(id & 0x7FFu);
    f->dlc = dlc;
    return f;
}

typedef struct target {
    uint16_t index;
    uint8_t sub;
    const co_od_entry_t *e; /* NULL: no such entry */
} target_t;

static target_t pick_target(fz_t *in, co_node_t *n)
{
    const co_od_t *od = co_cfg(n)->od;
    target_t t;
    uint8_t b = u8(in);
    if (b == FZ_TARGET_RAW) {
        t.index = u16(in);
        t.sub = u8(in);
        t.e = co_od_find(od, t.index, t.sub, NULL);
    } else {
        t.e = &od->entries[b % od->count];
        t.index = t.e->index;
        t.sub = t.e->sub;
    }
    return t;
}

static uint32_t pick_value(fz_t *in, co_node_t *n, const co_od_entry_t *e)
{
    static const uint32_t extremes[16] = {0u,          1u,          0x7Fu,       0x80u,
                                          0xFFu,       0x100u,      0x7FFFu,     0x8000u,
                                          0xFFFFu,     0x10000u,    0x7FFFFFFFu, 0x80000000u,
                                          0xFFFFFFFFu, 0xFFFFFFFEu, 0x40000000u, 0x20000000u};
    static const uint32_t signatures[4] = {CO_SIG_SAVE, CO_SIG_LOAD, 0x55AAAA55u, 0u};
    static const uint16_t bases[17] = {0x000, 0x080, 0x100, 0x180, 0x200, 0x280,
                                       0x300, 0x380, 0x400, 0x480, 0x500, 0x580,
                                       0x600, 0x6E0, 0x700, 0x7E4, 0x7E5};
    uint8_t s = u8(in);
    bool numeric = e != NULL && e->type != CO_T_VSTR;
    switch (s % FZ_VAL_COUNT) {
    case FZ_VAL_U32:
        return u32(in);
    case FZ_VAL_U8:
        return u8(in);
    case FZ_VAL_LIMIT: {
        int32_t lim = 0;
        if (e != NULL && e->ext != NULL && e->ext->min != e->ext->max) {
            lim = (s & 0x10u) != 0u ? e->ext->max : e->ext->min;
        }
        return (uint32_t)lim + (uint32_t)(u8(in) % 5u) - 2u;
    }
    case FZ_VAL_DEFAULT:
        return numeric ? e->def : 0u;
    case FZ_VAL_COBID: {
        uint32_t base = bases[u8(in) % 17u];
        uint8_t part = u8(in);
        uint8_t flags = u8(in);
        uint32_t v = base + ((part & 0x80u) != 0u ? n->node_id : (part & 0x7Fu));
        return v | ((uint32_t)(flags & 0x07u) << 29);
    }
    case FZ_VAL_SIGNATURE:
        return signatures[u8(in) % 4u];
    case FZ_VAL_EXTREME:
        return extremes[u8(in) % 16u];
    case FZ_VAL_SMALL_NEGATIVE:
        return (uint32_t)(int32_t)(int8_t)u8(in);
    case FZ_VAL_NEAR: {
        uint32_t v = 0;
        if (numeric) {
            (void)co_od_get(n, e, &v);
        }
        return v + (uint32_t)(int32_t)(int8_t)u8(in);
    }
    default:
        return u16(in);
    }
}

static uint32_t sdo_id(co_node_t *n)
{
    return 0x600u + n->node_id;
}

static void put_mux(co_frame_t *f, const target_t *t)
{
    f->data[1] = (uint8_t)t->index;
    f->data[2] = (uint8_t)(t->index >> 8);
    f->data[3] = t->sub;
}

static unsigned entry_size(const co_od_entry_t *e)
{
    return e != NULL ? e->size : 4u;
}

static void gen_sdo_write(fz_t *in, co_node_t *n, flist_t *l)
{
    target_t t = pick_target(in, n);
    uint32_t v = pick_value(in, n, t.e);
    uint8_t c = u8(in);
    unsigned size = entry_size(t.e);
    size = size >= 1u && size <= 4u ? size : 4u;
    uint8_t cmd;
    switch (c % 8u) {
    case 5:
        cmd = 0x22; /* size not indicated */
        break;
    case 6:
        cmd = (uint8_t)(0x23u | (((unsigned)c >> 3) & 3u) << 2); /* any size */
        break;
    case 7:
        cmd = (uint8_t)(0x20u | (c >> 3)); /* any bits */
        break;
    default:
        cmd = (uint8_t)(0x23u | (4u - size) << 2);
        break;
    }
    co_frame_t *f = add(l, sdo_id(n), 8);
    f->data[0] = cmd;
    put_mux(f, &t);
    co_put_u32(&f->data[4], v);
}

/* An expedited write of a known object (store ops). */
static void sdo_write(flist_t *l, co_node_t *n, uint16_t index, uint8_t sub, uint32_t v)
{
    const co_od_entry_t *e = co_node_entry(n, index, sub);
    unsigned size = entry_size(e);
    size = size >= 1u && size <= 4u ? size : 4u;
    co_frame_t *f = add(l, sdo_id(n), 8);
    f->data[0] = (uint8_t)(0x23u | (4u - size) << 2);
    f->data[1] = (uint8_t)index;
    f->data[2] = (uint8_t)(index >> 8);
    f->data[3] = sub;
    co_put_u32(&f->data[4], v);
}

static void gen_sdo_read(fz_t *in, co_node_t *n, flist_t *l)
{
    target_t t = pick_target(in, n);
    co_frame_t *f = add(l, sdo_id(n), 8);
    f->data[0] = 0x40;
    put_mux(f, &t);
}

static void gen_sdo_raw(fz_t *in, co_node_t *n, flist_t *l)
{
    uint8_t dlc = u8(in);
    co_frame_t *f = add(l, sdo_id(n), (dlc & 0xF0u) == 0xF0u ? (uint8_t)(dlc % 9u) : 8u);
    for (unsigned i = 0; i < 8u; i++) {
        f->data[i] = u8(in);
    }
}

/* The bytes a download sends: the value, then bytes from the input. */
static unsigned payload(fz_t *in, uint32_t v, unsigned size_sel, const co_od_entry_t *e,
                        uint8_t *buf, unsigned cap)
{
    unsigned len = (size_sel & 0x80u) != 0u ? size_sel % (cap + 1u) : entry_size(e);
    len = len > cap ? cap : len;
    for (unsigned i = 0; i < len; i++) {
        buf[i] = i < 4u ? (uint8_t)(v >> (8u * i)) : u8(in);
    }
    return len;
}

static void gen_sdo_seg_write(fz_t *in, co_node_t *n, flist_t *l)
{
    target_t t = pick_target(in, n);
    uint32_t v = pick_value(in, n, t.e);
    uint8_t sizes = u8(in);
    uint8_t buf[80];
    unsigned len = payload(in, v, u8(in), t.e, buf, sizeof(buf));
    co_frame_t *f = add(l, sdo_id(n), 8);
    bool sized = (sizes & 1u) == 0u;
    f->data[0] = sized ? 0x21u : 0x20u;
    put_mux(f, &t);
    co_put_u32(&f->data[4],
               (sizes & 0x80u) != 0u ? sizes : len); /* the indicated size, maybe wrong */
    unsigned toggle = 0;
    unsigned pos = 0;
    do {
        unsigned m = len - pos < 7u ? len - pos : 7u;
        bool last = pos + m >= len;
        uint8_t mangle = u8(in);
        co_frame_t *s = add(l, sdo_id(n), 8);
        s->data[0] = (uint8_t)(toggle | ((7u - m) << 1) | (last ? 1u : 0u));
        if (mangle == 1u) {
            s->data[0] ^= 0x10u; /* wrong toggle */
        } else if (mangle == 2u) {
            s->data[0] = u8(in); /* any command */
        }
        memcpy(&s->data[1], &buf[pos], m);
        pos += m;
        toggle ^= 0x10u;
    } while (pos < len && l->n < FL_MAX);
}

static void gen_sdo_seg_read(fz_t *in, co_node_t *n, flist_t *l)
{
    target_t t = pick_target(in, n);
    unsigned segs = u8(in) % 12u;
    uint8_t mangle = u8(in);
    co_frame_t *f = add(l, sdo_id(n), 8);
    f->data[0] = 0x40;
    put_mux(f, &t);
    unsigned toggle = 0;
    for (unsigned i = 0; i < segs; i++) {
        co_frame_t *s = add(l, sdo_id(n), 8);
        s->data[0] = (uint8_t)(0x60u | toggle);
        if (mangle != 0u && i == mangle % segs) {
            s->data[0] ^= (mangle & 0x80u) != 0u ? 0x10u : 0x40u; /* wrong toggle or direction */
        }
        toggle ^= 0x10u;
    }
}

static void gen_sdo_blk_write(fz_t *in, co_node_t *n, flist_t *l)
{
    target_t t = pick_target(in, n);
    uint32_t v = pick_value(in, n, t.e);
    uint8_t flags = u8(in);
    uint8_t buf[80];
    unsigned len = payload(in, v, u8(in), t.e, buf, sizeof(buf));
    uint8_t mangle = u8(in);
    bool crc = (flags & 1u) == 0u;
    bool sized = (flags & 2u) == 0u;
    co_frame_t *f = add(l, sdo_id(n), 8);
    f->data[0] = (uint8_t)(0xC0u | (crc ? 0x04u : 0u) | (sized ? 0x02u : 0u));
    put_mux(f, &t);
    co_put_u32(&f->data[4], (flags & 0x80u) != 0u ? u8(in) : len);
    /* Sub-blocks of the server's block size, sequence numbers from 1. */
    const unsigned blk = (CO_SDO_BUF + 6u) / 7u;
    unsigned segs = (len + 6u) / 7u;
    segs = segs == 0u ? 1u : segs;
    for (unsigned i = 0; i < segs; i++) {
        co_frame_t *s = add(l, sdo_id(n), 8);
        s->data[0] = (uint8_t)((i % blk) + 1u);
        if (i + 1u == segs) {
            s->data[0] |= 0x80u;
        }
        if (mangle == 1u && i == 0u) {
            s->data[0] = (uint8_t)(s->data[0] + 1u); /* out of sequence */
        }
        for (unsigned j = 0; j < 7u && 7u * i + j < len; j++) {
            s->data[1 + j] = buf[7u * i + j];
        }
    }
    unsigned unused = (7u - len % 7u) % 7u;
    co_frame_t *e = add(l, sdo_id(n), 8);
    e->data[0] = (uint8_t)(0xC1u | (unused << 2));
    co_put_u16(&e->data[1], co_crc16_ccitt(0, buf, len));
    if (mangle == 2u) {
        e->data[1] ^= 0x01u; /* wrong CRC */
    } else if (mangle == 3u) {
        e->data[0] = (uint8_t)(0xC1u | (u8(in) & 0x1Cu)); /* any count of unused bytes */
    }
}

static void gen_sdo_blk_read(fz_t *in, co_node_t *n, flist_t *l)
{
    target_t t = pick_target(in, n);
    uint8_t flags = u8(in);
    uint8_t blksize = u8(in);
    unsigned rounds = u8(in) % 4u;
    co_frame_t *f = add(l, sdo_id(n), 8);
    f->data[0] = (uint8_t)(0xA0u | ((flags & 1u) != 0u ? 0u : 0x04u));
    put_mux(f, &t);
    f->data[4] = (flags & 0x80u) != 0u ? blksize : (uint8_t)(blksize % 127u + 1u);
    f->data[5] = 0;
    add(l, sdo_id(n), 8)->data[0] = 0xA3; /* start */
    unsigned segs = (entry_size(t.e) + 6u) / 7u;
    for (unsigned r = 0; r < rounds; r++) {
        uint8_t ack = u8(in);
        uint8_t next = u8(in);
        co_frame_t *a = add(l, sdo_id(n), 8);
        a->data[0] = 0xA2;
        a->data[1] = (ack & 0x80u) != 0u ? (uint8_t)(ack & 0x7Fu)
                                         : (uint8_t)(segs < f->data[4] ? segs : f->data[4]);
        a->data[2] = (next & 0x80u) != 0u ? next : (uint8_t)(next % 127u + 1u);
    }
    add(l, sdo_id(n), 8)->data[0] = (flags & 0x40u) != 0u ? u8(in) : 0xA1u; /* the client's end */
}

static uint8_t other_id(const dev_t *d, unsigned k)
{
    return d->nodes[(k + 1u) % d->nnodes]->node_id;
}

static void gen_nmt(fz_t *in, const dev_t *d, unsigned k, flist_t *l)
{
    static const uint8_t cmds[5] = {0x01, 0x02, 0x80, 0x81, 0x82};
    uint8_t c = u8(in);
    uint8_t t = u8(in);
    uint8_t dlc = (t & 0x80u) != 0u ? (uint8_t)(u8(in) % 9u) : 2u;
    co_frame_t *f = add(l, 0x000, dlc);
    f->data[0] = c < 0xF0u ? cmds[c % 5u] : c;
    switch (t % 4u) {
    case 0:
        f->data[1] = 0; /* all nodes */
        break;
    case 1:
        f->data[1] = d->nodes[k]->node_id;
        break;
    case 2:
        f->data[1] = other_id(d, k);
        break;
    default:
        f->data[1] = (uint8_t)(t >> 2);
        break;
    }
}

static void gen_sync(fz_t *in, co_node_t *n, flist_t *l)
{
    uint8_t s = u8(in);
    uint8_t counter = u8(in);
    co_frame_t *f = add(l, (s & 0x80u) != 0u ? 0x080u : n->sync.cob_id, (uint8_t)(s % 3u));
    f->data[0] = counter;
    f->data[1] = counter;
}

static void gen_guard_rtr(fz_t *in, co_node_t *n, flist_t *l)
{
    uint8_t s = u8(in);
    co_frame_t *f = add(l, 0x700u + n->node_id,
                        (s & 0x80u) != 0u ? (uint8_t)(s % 9u) : (uint8_t)(s & 1u));
    f->rtr = true;
}

static void gen_pdo_rtr(fz_t *in, co_node_t *n, flist_t *l)
{
    uint8_t s = u8(in);
    unsigned j = s % (CO_TPDO_MAX + 2u);
    uint32_t id = j < CO_TPDO_MAX ? n->tpdo[j].cob_id
                                  : 0x180u + 0x100u * (j - CO_TPDO_MAX) + n->node_id;
    co_frame_t *f = add(l, id, (uint8_t)((s >> 4) % 9u));
    f->rtr = true;
}

/* LSS address part i (vendor, product, revision, serial: 0x1018 sub 1..4). */
static uint32_t lss_address(co_node_t *n, unsigned i)
{
    return od_value(n, 0x1018, (uint8_t)(i + 1u));
}

static uint8_t pick_node_id(uint8_t s)
{
    static const uint8_t ids[6] = {1, 127, 0xFF, 0, 128, 10};
    return (s & 0x80u) != 0u ? ids[s % 6u] : (uint8_t)(s & 0x7Fu);
}

static co_frame_t *lss(flist_t *l, uint8_t cs)
{
    co_frame_t *f = add(l, 0x7E5, 8);
    f->data[0] = cs;
    return f;
}

static co_frame_t *lss_u32(flist_t *l, uint8_t cs, uint32_t v)
{
    co_frame_t *f = lss(l, cs);
    co_put_u32(&f->data[1], v);
    return f;
}

static void gen_lss(fz_t *in, co_node_t *n, flist_t *l)
{
    static const uint8_t cs_list[22] = {0x04, 0x11, 0x13, 0x15, 0x17, 0x40, 0x41, 0x42,
                                        0x43, 0x46, 0x47, 0x48, 0x49, 0x4A, 0x4B, 0x4C,
                                        0x51, 0x5A, 0x5B, 0x5C, 0x5D, 0x5E};
    uint8_t c = u8(in);
    uint8_t cs = c < 0xF0u ? cs_list[c % 22u] : u8(in);
    co_frame_t *f;
    if (cs >= 0x40u && cs <= 0x4Bu && cs != 0x44u && cs != 0x45u) {
        /* An address part: ours, one either side of it, or anything. */
        unsigned part = cs <= 0x43u ? cs - 0x40u : (cs - 0x46u + 1u) / 2u;
        uint8_t s = u8(in);
        uint32_t a = lss_address(n, part > 3u ? 3u : part);
        uint32_t v = s % 4u == 0u ? a : s % 4u == 1u ? a - 1u : s % 4u == 2u ? a + 1u : u32(in);
        (void)lss_u32(l, cs, v);
        return;
    }
    if (cs == 0x51u) { /* Fastscan */
        uint8_t part = u8(in);
        uint8_t bit = u8(in);
        uint32_t a = lss_address(n, part % 4u);
        f = lss_u32(l, cs, (bit & 0x40u) != 0u ? u32(in) : a);
        f->data[5] = (bit & 0x80u) != 0u ? 0x80u : (uint8_t)(bit % 33u);
        f->data[6] = (uint8_t)(part % 5u);
        f->data[7] = (uint8_t)((part >> 4) % 5u);
        return;
    }
    f = lss(l, cs);
    switch (cs) {
    case 0x04:
        f->data[1] = u8(in) % 3u;
        break;
    case 0x11:
        f->data[1] = pick_node_id(u8(in));
        break;
    case 0x13: {
        uint8_t s = u8(in);
        f->data[1] = (s & 0x80u) != 0u ? 1u : 0u;
        f->data[2] = (uint8_t)(s % 17u);
        break;
    }
    default:
        for (unsigned i = 1; i < 8u; i++) {
            f->data[i] = u8(in);
        }
        break;
    }
}

/* Whole LSS dialogues that a random frame stream would rarely complete. */
static void gen_lss_sequence(fz_t *in, co_node_t *n, flist_t *l)
{
    uint8_t kind = u8(in);
    uint8_t id = pick_node_id(u8(in));
    uint8_t bt = u8(in);
    switch (kind % 4u) {
    case 0: /* switch selective, configure the node-ID, store, back to waiting */
        for (unsigned i = 0; i < 4u; i++) {
            (void)lss_u32(l, (uint8_t)(0x40u + i), lss_address(n, i));
        }
        lss(l, 0x11)->data[1] = id;
        (void)lss(l, 0x17);
        (void)lss(l, 0x04);
        break;
    case 1: /* Fastscan down to this node, then the same */
        lss(l, 0x51)->data[5] = 0x80;
        for (unsigned i = 0; i < 4u; i++) {
            co_frame_t *f = lss_u32(l, 0x51, lss_address(n, i));
            f->data[5] = 0;
            f->data[6] = (uint8_t)i;
            f->data[7] = (uint8_t)((i + 1u) % 4u);
        }
        lss(l, 0x11)->data[1] = id;
        (void)lss(l, 0x17);
        (void)lss(l, 0x04);
        break;
    case 2: { /* configuration state: bit timing, activate, inquiries */
        lss(l, 0x04)->data[1] = 1;
        co_frame_t *f = lss(l, 0x13);
        f->data[2] = (uint8_t)(bt % 10u);
        lss(l, 0x15)->data[1] = bt;
        for (uint8_t cs = 0x5A; cs <= 0x5E; cs++) {
            (void)lss(l, cs);
        }
        (void)lss(l, 0x17);
        (void)lss(l, 0x04);
        break;
    }
    default: /* identify remote slave, identify non-configured slave */
        (void)lss_u32(l, 0x46, lss_address(n, 0));
        (void)lss_u32(l, 0x47, lss_address(n, 1));
        (void)lss_u32(l, 0x48, lss_address(n, 2) - (bt & 1u));
        (void)lss_u32(l, 0x49, lss_address(n, 2) + (bt & 2u));
        (void)lss_u32(l, 0x4A, lss_address(n, 3));
        (void)lss_u32(l, 0x4B, lss_address(n, 3));
        (void)lss(l, 0x4C);
        break;
    }
}

static void gen_heartbeat(fz_t *in, co_node_t *n, flist_t *l)
{
    static const uint8_t states[4] = {0x00, 0x04, 0x05, 0x7F};
    uint8_t p = u8(in);
    uint8_t s = u8(in);
    uint32_t producer = (p & 0x80u) != 0u ? (p & 0x7Fu) : n->hbc.node_id;
    co_frame_t *f = add(l, 0x700u + producer, (s & 0x80u) != 0u ? (uint8_t)(s % 9u) : 1u);
    f->data[0] = (s & 0x40u) != 0u ? u8(in) : states[s % 4u];
}

static void gen_frame(fz_t *in, co_node_t *n, flist_t *l)
{
    uint16_t id = u16(in);
    uint8_t flags = u8(in);
    if ((flags & 0x80u) != 0u) {
        /* One of the node's own services' identifiers. */
        const uint32_t own[7] = {0x000u, 0x080u,         sdo_id(n),        0x700u + n->node_id,
                                 0x7E5u, n->sync.cob_id, n->tpdo[0].cob_id};
        id = (uint16_t)own[id % 7u];
    }
    co_frame_t *f = add(l, id, (uint8_t)(((unsigned)flags >> 1) % 9u));
    f->rtr = (flags & 1u) != 0u;
    for (unsigned i = 0; i < 8u; i++) {
        f->data[i] = u8(in);
    }
}

static void gen_store(fz_t *in, co_node_t *n, flist_t *l)
{
    uint8_t s = u8(in);
    uint8_t sub = (s & 0x80u) != 0u ? (uint8_t)(u8(in) % 6u) : 1u;
    switch (s % 6u) {
    case 0:
        sdo_write(l, n, 0x1010, sub, (s & 0x40u) != 0u ? u32(in) : CO_SIG_SAVE);
        break;
    case 1:
        sdo_write(l, n, 0x1011, sub, (s & 0x40u) != 0u ? u32(in) : CO_SIG_LOAD);
        break;
    case 2:
        sdo_write(l, n, 0x2300, 0, 0x55AAAA55u); /* the JD's save with reset */
        break;
    case 3: { /* the DSTs' node-ID, both copies */
        uint8_t id = pick_node_id(u8(in));
        sdo_write(l, n, 0x20F0, 0, id);
        sdo_write(l, n, 0x20F1, 0, id);
        break;
    }
    case 4: { /* the DSTs' bit rate, both copies */
        uint8_t br = u8(in) % 9u;
        sdo_write(l, n, 0x20F2, 0, br);
        sdo_write(l, n, 0x20F3, 0, br);
        break;
    }
    default: { /* any stored entry (the P+F stores every write) */
        const co_od_t *od = co_cfg(n)->od;
        unsigned start = u8(in);
        for (unsigned i = 0; i < od->count; i++) {
            const co_od_entry_t *e = &od->entries[(start + i) % od->count];
            if ((e->cls == CO_CLS_PARA || e->cls == CO_CLS_LSS) && (e->attr & CO_A_W) != 0u) {
                sdo_write(l, n, e->index, e->sub, pick_value(in, n, e));
                break;
            }
        }
        break;
    }
    }
}

/* The frames of a frame op; false for any other op. */
static bool gen_frames(fz_t *in, dev_t *d, unsigned op, unsigned k, flist_t *l)
{
    co_node_t *n = d->nodes[k];
    l->n = 0;
    switch (op) {
    case FZ_OP_SDO_WRITE:
        gen_sdo_write(in, n, l);
        return true;
    case FZ_OP_SDO_READ:
        gen_sdo_read(in, n, l);
        return true;
    case FZ_OP_SDO_RAW:
        gen_sdo_raw(in, n, l);
        return true;
    case FZ_OP_SDO_SEG_WRITE:
        gen_sdo_seg_write(in, n, l);
        return true;
    case FZ_OP_SDO_SEG_READ:
        gen_sdo_seg_read(in, n, l);
        return true;
    case FZ_OP_SDO_BLK_WRITE:
        gen_sdo_blk_write(in, n, l);
        return true;
    case FZ_OP_SDO_BLK_READ:
        gen_sdo_blk_read(in, n, l);
        return true;
    case FZ_OP_NMT:
        gen_nmt(in, d, k, l);
        return true;
    case FZ_OP_SYNC:
        gen_sync(in, n, l);
        return true;
    case FZ_OP_GUARD_RTR:
        gen_guard_rtr(in, n, l);
        return true;
    case FZ_OP_PDO_RTR:
        gen_pdo_rtr(in, n, l);
        return true;
    case FZ_OP_LSS:
        gen_lss(in, n, l);
        return true;
    case FZ_OP_LSS_SEQUENCE:
        gen_lss_sequence(in, n, l);
        return true;
    case FZ_OP_HEARTBEAT:
        gen_heartbeat(in, n, l);
        return true;
    case FZ_OP_FRAME:
        gen_frame(in, n, l);
        return true;
    case FZ_OP_STORE:
        gen_store(in, n, l);
        return true;
    default:
        return false;
    }
}

/* Frames with the EEPROM losing power after budget more bytes (invariant 4). */
static void deliver_with_cut(dev_t *d, const flist_t *l, long budget)
{
    static sets_t old;
    static sets_t new_;
    static uint8_t nvm_cut[NVM_SIZE];
    if (g_trace) {
        fprintf(stderr, "power cut after %ld more EEPROM bytes\n", budget);
    }
    d->cut_after = budget;
    for (unsigned i = 0; i < l->n; i++) {
        memcpy(&g_snap, d, sizeof(*d));
        deliver(d, &l->f[i]);
        if (!d->cut_hit) {
            continue;
        }
        /* The power failed during frame i: what a restore gives before it
         * and after it handled without a cut, then the device after the cut. */
        memcpy(nvm_cut, d->nvm, NVM_SIZE);
        restored_sets(g_snap.nvm, g_snap.nvm_read_fails, old);
        memcpy(d, &g_snap, sizeof(*d));
        d->cut_after = -1;
        deliver(d, &l->f[i]);
        restored_sets(d->nvm, d->nvm_read_fails, new_);
        memcpy(d->nvm, nvm_cut, NVM_SIZE);
        power_cycle(d);
        check_sets_after_cut(d, old, new_);
        return;
    }
    /* Then a pause on the same power: what the frames put off (the store
     * of an autosaved write, the erase ahead of the next save's slot) runs
     * in it, and may be cut the same way. */
    memcpy(&g_snap, d, sizeof(*d));
    advance(d, 2u * CO_STORE_QUIET_US, false);
    if (d->cut_hit) {
        memcpy(nvm_cut, d->nvm, NVM_SIZE);
        restored_sets(g_snap.nvm, g_snap.nvm_read_fails, old);
        memcpy(d, &g_snap, sizeof(*d));
        d->cut_after = -1;
        advance(d, 2u * CO_STORE_QUIET_US, false);
        restored_sets(d->nvm, d->nvm_read_fails, new_);
        memcpy(d->nvm, nvm_cut, NVM_SIZE);
        power_cycle(d);
        check_sets_after_cut(d, old, new_);
        return;
    }
    d->cut_after = -1;
}

static void set_inputs(fz_t *in, dev_t *d)
{
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && d->prod->inputs[i].name != NULL; i++) {
        int32_t lim = d->prod->inputs[i].limit * 1000;
        uint8_t s = u8(in);
        switch (s % 4u) {
        case 0:
            break; /* unchanged */
        case 1:
            d->truth[i] = (int32_t)(u32(in) % (2u * (uint32_t)lim + 1u)) - lim;
            break;
        case 2:
            d->truth[i] = (s & 0x80u) != 0u ? lim : -lim;
            break;
        default: {
            int32_t v = d->truth[i] + (int32_t)(int8_t)u8(in) * 100;
            d->truth[i] = v > lim ? lim : (v < -lim ? -lim : v);
            break;
        }
        }
    }
}

/* What a board does between ops: drive the LEDs (co_node_leds), which must
 * never ask to be looked at again at once. */
static void leds(dev_t *d)
{
    for (unsigned k = 0; k < d->nnodes; k++) {
        bool green;
        bool red;
        uint32_t next;
        co_node_leds(d->nodes[k], now32(d), &green, &red, &next);
        FZ_CHECK(next != 0u && (next == CO_NEVER || next <= 65535000u),
                 "the LEDs ask to be looked at again in %u us", next);
    }
}

static void run_op(fz_t *in, dev_t *d)
{
    static flist_t l;
    uint8_t b = u8(in);
    unsigned op = (b & 0x7Fu) % FZ_OP_COUNT;
    unsigned k = (unsigned)(b >> 7) % d->nnodes;
    if (g_trace) {
        fprintf(stderr, "op %u: %u node %u\n", g_op, op, k);
    }
    if (gen_frames(in, d, op, k, &l)) {
        for (unsigned i = 0; i < l.n; i++) {
            deliver(d, &l.f[i]);
        }
        return;
    }
    switch (op) {
    case FZ_OP_ADVANCE: {
        static const uint32_t unit[4] = {1u, 10u, 100u, 1000u};
        uint32_t count = u16(in);
        advance(d, (uint64_t)count * unit[u8(in) % 4u], true);
        break;
    }
    case FZ_OP_ADVANCE_LONG: {
        uint32_t count = u32(in);
        advance(d, (uint64_t)count * (1u + u8(in) % 4u), false);
        break;
    }
    case FZ_OP_INPUTS:
        set_inputs(in, d);
        break;
    case FZ_OP_FAULTS: {
        unsigned nf = 0;
        while (nf < PRODUCT_MAX_INPUTS && d->prod->faults[nf] != NULL) {
            nf++;
        }
        d->faults = u8(in) & ((1u << nf) - 1u);
        break;
    }
    case FZ_OP_CAN_STATE:
        co_node_set_can_state(d->nodes[k], (co_can_state_t)(u8(in) % 4u));
        after_node(d, k);
        (void)poll_one(d, k);
        break;
    case FZ_OP_TX_FULL:
        d->port[k].tx_full = (u8(in) & 1u) != 0u;
        break;
    case FZ_OP_POWER_CYCLE:
        power_cycle(d);
        break;
    case FZ_OP_POWER_CUT: {
        long budget = u16(in) % 1024u;
        uint8_t next = u8(in);
        unsigned op2 = (next & 0x7Fu) % FZ_OP_COUNT;
        unsigned k2 = (unsigned)(next >> 7) % d->nnodes;
        if (gen_frames(in, d, op2, k2, &l)) {
            deliver_with_cut(d, &l, budget);
        }
        break;
    }
    case FZ_OP_NVM_READ_FAIL:
        d->nvm_read_fails = (u8(in) & 1u) != 0u;
        break;
    default:
        break;
    }
}

/* The products by selector byte (fuzz_products.h). */
static fz_products_t g_products;

int LLVMFuzzerInitialize(int *argc, char ***argv)
{
    (void)argc;
    (void)argv;
    fz_products_init(&g_products);
    const char *t = getenv("FUZZ_TRACE");
    g_trace = t != NULL && t[0] == '1';
    /* The invariant's restricted set is the stack's own (CiA 301 7.3.5). */
    for (uint32_t id = 0; id <= 0x7FFu; id++) {
        FZ_CHECK(restricted(id) == co_cobid_restricted(id),
                 "co_cobid_restricted(0x%03X) disagrees with CiA 301", id);
    }
    return 0;
}

int LLVMFuzzerTestOneInput(const uint8_t *data, size_t size)
{
    fz_t in = {data, size};
    dev_t *d = &g_dev;
    memset(d, 0, sizeof(*d));
    d->prod = fz_product(&g_products, u8(&in));
    g_product = d->prod->id;
    g_op = 0;
    uint8_t clock = u8(&in);
    switch (clock % 4u) {
    case 0:
        d->now = 1000000u;
        break;
    case 1:
        d->now = 0x100000000ull - (uint64_t)u16(&in) * 1000u;
        break;
    case 2:
        d->now = u32(&in);
        break;
    default:
        d->now = 0x80000000ull - (uint64_t)u16(&in) * 1000u;
        break;
    }
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        d->truth[i] = d->prod->inputs[i].name != NULL ? d->prod->inputs[i].initial : 0;
    }
    memset(d->nvm, 0xFF, sizeof(d->nvm));
    if (g_trace) {
        fprintf(stderr, "product %s, time %llu us\n", g_product, (unsigned long long)d->now);
    }
    /* The EEPROM at power-on: records made from the defaults, changed. */
    unsigned images = u8(&in) % FZ_MAX_IMAGES;
    if (images > 0u) {
        static sets_t defs;
        restored_sets(d->nvm, false, defs);
        /* put_image needs the nodes for their layout hash and NVM base. */
        d->nnodes = d->prod->nodes;
        for (unsigned k = 0; k < d->nnodes; k++) {
            d->nodes[k] = g_scratch.nodes[k];
        }
        for (unsigned i = 0; i < images; i++) {
            put_image(&in, d, defs);
        }
    }
    boot(d);
    (void)product_kbps(d->prod, d->nodes[0]->bitrate); /* the bit rate a board would set */
    while (in.n > 0u && g_op < FZ_MAX_OPS) {
        run_op(&in, d);
        leds(d);
        g_op++;
    }
    /* Let the timers run out once more: deadlines the last op set. */
    advance(d, 2000000u, false);
    return 0;
}
