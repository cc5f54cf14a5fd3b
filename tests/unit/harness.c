/*
 * harness.c - see harness.h.
 */
#include "harness.h"

#include <stdlib.h>

#include "co_filter.h"
#include "co_port.h"
#include "co_progdl.h"

/* ---- the fake port ------------------------------------------------- */

void fake_port_init(fake_port_t *p)
{
    memset(p, 0, sizeof(*p));
    memset(p->nvm, 0xFF, sizeof(p->nvm));
    p->cut_after = -1;
    p->reads_left = -1;
    memset(p->prog.area, 0xFF, sizeof(p->prog.area));
    p->prog.limit = FAKE_PROG_SIZE;
    p->prog.cut_after = -1;
    p->prog.flip_at = -1;
}

bool co_port_can_bitrate(void *port, uint16_t kbps)
{
    fake_port_t *p = port;
    p->kbps = kbps;
    p->bitrate_calls++;
    return kbps != 0u;
}

bool co_port_can_send(void *port, const co_frame_t *frame)
{
    fake_port_t *p = port;
    if (p->tx_full) {
        return false;
    }
    if (p->ntx - p->rd >= FAKE_TX_MAX) {
        /* The oldest unread frame would be overwritten: a harness limit. */
        h_failures++;
        fprintf(stderr,
                "fake port: more than %u frames sent and not read; "
                "drain in the test or raise FAKE_TX_MAX\n",
                FAKE_TX_MAX);
        p->rd++;
    }
    p->tx[p->ntx++ % FAKE_TX_MAX] = *frame;
    if (p->ntx - p->rd > h_tx_high_water) {
        h_tx_high_water = p->ntx - p->rd;
    }
    return true;
}

bool co_port_nvm_read(void *port, uint32_t addr, void *buf, uint32_t len)
{
    fake_port_t *p = port;
    if (p->reads_left == 0) {
        p->read_faults++;
        return false;
    }
    if (p->nvm_read_fails || addr + len > FAKE_NVM_SIZE) {
        return false;
    }
    if (p->reads_left > 0) {
        p->reads_left--;
    }
    memcpy(buf, &p->nvm[addr], len);
    return true;
}

bool co_port_nvm_write(void *port, uint32_t addr, const void *buf, uint32_t len)
{
    fake_port_t *p = port;
    if (addr + len > FAKE_NVM_SIZE) {
        return false;
    }
    if (p->fail_writes > 0u) {
        p->fail_writes--;
        return false; /* a write the EEPROM refuses; the next may work */
    }
    const uint8_t *b = buf;
    for (uint32_t i = 0; i < len; i++) {
        if (p->cut_after == 0) {
            return false; /* power is gone: nothing more reaches the EEPROM */
        }
        if (p->cut_after > 0) {
            p->cut_after--;
        }
        p->nvm[addr + i] = b[i];
    }
    p->nvm_writes++;
    return true;
}

/* As a flash board erases ahead: the slot's bytes read as erased after,
 * so a test sees a prepare of a slot whose record was still needed. */
void co_port_nvm_prepare(void *port, uint32_t addr, uint32_t len)
{
    fake_port_t *p = port;
    p->prepares++;
    p->prepared_addr = addr;
    p->prepared_at = p->clock != NULL ? *p->clock : 0u;
    if (addr <= FAKE_NVM_SIZE && len <= FAKE_NVM_SIZE - addr) {
        memset(&p->nvm[addr], 0xFF, len);
    }
}

/* ---- program download (co_port.h) ---------------------------------- */

struct co_progdl *co_port_progdl(void *port)
{
    fake_port_t *p = port;
    if (p->prog.pd == NULL) {
        h_failures++;
        fprintf(stderr, "fake port: program download without a co_progdl_t (fake_prog_t.pd)\n");
        abort();
    }
    return p->prog.pd;
}

uint8_t co_port_prog_check(void *port, const co_image_hdr_t *h)
{
    fake_prog_t *g = &((fake_port_t *)port)->prog;
    if (h->board != g->board || g->id == NULL || strcmp(h->id, g->id) != 0) {
        return CO_PROGDL_FORMAT;
    }
    if (h->length > g->limit || h->load_addr != 0u) {
        return CO_PROGDL_ADDRESS;
    }
    g->accepted = h->length;
    return CO_PROGDL_OK;
}

/* As a bootloader's: the header's page erased, so no image is found. */
bool co_port_prog_clear(void *port)
{
    fake_prog_t *g = &((fake_port_t *)port)->prog;
    g->clears++;
    if (g->fail_clear) {
        return false;
    }
    memset(g->area, 0xFF, FAKE_PROG_PAGE);
    g->erases++;
    g->erased_to = 1;
    g->accepted = 0; /* no header checked since */
    return true;
}

bool co_port_prog_write(void *port, uint32_t at, const void *buf, uint32_t len)
{
    fake_prog_t *g = &((fake_port_t *)port)->prog;
    g->writes++;
    if (at + len > g->accepted) {
        h_failures++; /* the stack broke co_port_prog_write's contract */
        fprintf(stderr, "fake port: image bytes %u..%u written, the header said %u\n", (unsigned)at,
                (unsigned)(at + len - 1u), (unsigned)g->accepted);
    }
    if (g->fail_write || at + len > FAKE_PROG_SIZE || len == 0u) {
        return false;
    }
    const uint8_t *b = buf;
    for (uint32_t i = 0; i < len; i++) {
        uint32_t page = (at + i) / FAKE_PROG_PAGE;
        if (page >= g->erased_to) { /* the first write into a page erases it */
            memset(&g->area[(size_t)page * FAKE_PROG_PAGE], 0xFF, FAKE_PROG_PAGE);
            g->erases++;
            g->erased_to = page + 1u;
        }
        if (g->cut_after == 0) {
            return false; /* power is gone */
        }
        if (g->cut_after > 0) {
            g->cut_after--;
        }
        g->area[at + i] &= (long)at + (long)i == g->flip_at ? (uint8_t)(b[i] ^ 1u) : b[i];
    }
    return true;
}

bool co_port_prog_read(void *port, uint32_t at, void *buf, uint32_t len)
{
    fake_prog_t *g = &((fake_port_t *)port)->prog;
    g->reads++;
    if (g->fail_read || at + len > FAKE_PROG_SIZE) {
        return false;
    }
    memcpy(buf, &g->area[at], len);
    return true;
}

bool co_port_prog_commit(void *port, const co_image_hdr_t *h)
{
    fake_prog_t *g = &((fake_port_t *)port)->prog;
    g->commits++;
    if (g->fail_commit) {
        return false;
    }
    g->committed_id = h->program_id;
    return true;
}

void co_port_prog_start(void *port)
{
    fake_port_t *p = port;
    p->prog.starts++;
    p->prog.start_ntx = p->ntx;
}

void co_port_prog_stop(void *port)
{
    fake_port_t *p = port;
    p->prog.stops++;
    p->prog.stop_ntx = p->ntx;
}

void co_port_prog_handover(void *port)
{
    fake_port_t *p = port;
    p->prog.handovers++;
    p->prog.handover_ntx = p->ntx;
}

/* ---- device under test --------------------------------------------- */

static void create(h_dev_t *d)
{
    d->port.clock = &d->now;
    void *ports[PRODUCT_MAX_NODES] = {&d->port, &d->port};
    d->prod->create(d->prod, d->mem, ports, d->nodes);
#ifdef CO_FIXED_CFG
    for (unsigned i = 0; i < d->prod->nodes; i++) {
        if (d->nodes[i]->cfg != &CO_FIXED_CFG) {
            h_foreign_boot(d->prod->id); /* nothing of it runs: back to h_run */
        }
    }
    h_own_boot();
#endif
    d->nnodes = d->prod->nodes;
    d->node = d->nodes[0];
    if (d->cfg != NULL) {
        d->node->cfg = d->cfg; /* co_node_init keeps the pointer alone; not started yet */
    }
    /* One sample before start, as a board reads its sensor before booting. */
    d->prod->sample(d->mem, d->truth, d->fault);
    for (unsigned i = 0; i < d->nnodes; i++) {
        if (d->factory_id[i] != 0u) {
            co_node_set_factory_id(d->nodes[i], d->factory_id[i]);
        }
        if (d->serial[i] != 0u) {
            co_node_set_serial(d->nodes[i], d->serial[i]);
        }
        co_node_start(d->nodes[i], d->now);
    }
    d->next_sample = d->now + CO_FILTER_PERIOD_US;
}

void h_boot(h_dev_t *d, const product_t *p, bool keep_nvm)
{
    if (!keep_nvm) {
        memset(d, 0, sizeof(*d));
        fake_port_init(&d->port);
        d->now = 1000000u;
        for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
            d->truth[i] = p->inputs[i].initial;
        }
    }
    d->prod = p;
    if (p->inst_size > sizeof(d->mem)) {
        fprintf(stderr, "%s needs %u instance bytes, the harness has %u (H_INST_MAX)\n", p->id,
                (unsigned)p->inst_size, (unsigned)sizeof(d->mem));
        abort();
    }
    create(d);
}

void h_boot_ids(h_dev_t *d, const product_t *p, const uint8_t ids[PRODUCT_MAX_NODES])
{
    memset(d, 0, sizeof(*d));
    fake_port_init(&d->port);
    d->now = 1000000u;
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        d->truth[i] = p->inputs[i].initial;
    }
    memcpy(d->factory_id, ids, sizeof(d->factory_id));
    h_boot(d, p, true);
}

void h_power_cycle(h_dev_t *d)
{
    d->port.ntx = 0;
    d->port.rd = 0;
    d->port.cut_after = -1;
    d->now += 1000000u;
    create(d);
}

void h_advance(h_dev_t *d, uint32_t us)
{
    uint32_t end = d->now + us;
    for (;;) {
        uint32_t delay = CO_NEVER;
        for (unsigned i = 0; i < d->nnodes; i++) {
            delay = co_min_u32(delay, co_node_poll(d->nodes[i], d->now));
        }
        uint32_t step = co_min_u32(co_time_until(d->now, end),
                                   co_time_until(d->now, d->next_sample));
        step = co_min_u32(step, delay);
        if (step == 0u && !co_time_before(d->now, d->next_sample)) {
            d->prod->sample(d->mem, d->truth, d->fault);
            d->next_sample += CO_FILTER_PERIOD_US;
            continue;
        }
        if (!co_time_before(d->now, end)) {
            break;
        }
        d->now += step == 0u ? 1u : step;
    }
}

/* As boards/common/mcu_main.c: the frame to every node, their shared
 * pause, then what it left to do. */
void h_rx_frame(h_dev_t *d, const co_frame_t *f)
{
    for (unsigned i = 0; i < d->nnodes; i++) {
        co_node_poll(d->nodes[i], d->now);
    }
    for (unsigned i = 0; i < d->nnodes; i++) {
        co_node_receive(d->nodes[i], f, d->now);
    }
    co_store_share_pause(d->nodes, d->nnodes);
    for (unsigned i = 0; i < d->nnodes; i++) {
        co_node_poll(d->nodes[i], d->now);
    }
}

void h_rx(h_dev_t *d, uint16_t id, const char *hex)
{
    co_frame_t f = {.id = id};
    f.dlc = (uint8_t)h_hex(hex, f.data, 8);
    h_rx_frame(d, &f);
}

const co_frame_t *h_next(h_dev_t *d)
{
    if (d->port.rd >= d->port.ntx) {
        return NULL;
    }
    return &d->port.tx[d->port.rd++ % FAKE_TX_MAX];
}

void h_drain(h_dev_t *d)
{
    d->port.rd = d->port.ntx;
}

unsigned h_pending(const h_dev_t *d)
{
    return d->port.ntx - d->port.rd;
}

static void print_frame(const char *what, const co_frame_t *f)
{
    fprintf(stderr, "    %s %03X [%u]", what, f->id, f->dlc);
    for (unsigned i = 0; i < f->dlc; i++) {
        fprintf(stderr, " %02X", f->data[i]);
    }
    fprintf(stderr, "\n");
}

void h_expect(h_dev_t *d, uint16_t id, const char *hex, const char *file, int line)
{
    co_frame_t want = {.id = id};
    want.dlc = (uint8_t)h_hex(hex, want.data, 8);
    const co_frame_t *got = h_next(d);
    h_checks++;
    if (got == NULL) {
        h_failures++;
        fprintf(stderr, "%s:%d: expected a frame, none was sent\n", file, line);
        print_frame("want", &want);
        return;
    }
    if (got->id != want.id || got->dlc != want.dlc || memcmp(got->data, want.data, want.dlc) != 0) {
        h_failures++;
        fprintf(stderr, "%s:%d: frame differs\n", file, line);
        print_frame("want", &want);
        print_frame("got ", got);
    }
}

void h_expect_none(h_dev_t *d, const char *file, int line)
{
    h_checks++;
    const co_frame_t *got = h_next(d);
    if (got != NULL) {
        h_failures++;
        fprintf(stderr, "%s:%d: expected no frame\n", file, line);
        print_frame("got ", got);
    }
}

void h_expect_id(h_dev_t *d, uint16_t id, const char *hex, const char *file, int line)
{
    /* Skip other traffic (PDOs of an operational node) up to the frame wanted. */
    while (d->port.rd < d->port.ntx && d->port.tx[d->port.rd % FAKE_TX_MAX].id != id) {
        d->port.rd++;
    }
    h_expect(d, id, hex, file, line);
}

void h_sdo(h_dev_t *d, const char *req, const char *resp, const char *file, int line)
{
    h_drain(d);
    h_rx(d, (uint16_t)(0x600u + d->node->node_id), req);
    h_expect_id(d, (uint16_t)(0x580u + d->node->node_id), resp, file, line);
}

long long h_read(h_dev_t *d, uint16_t index, uint8_t sub)
{
    h_drain(d);
    co_frame_t f = {.id = (uint16_t)(0x600u + d->node->node_id),
                    .dlc = 8,
                    .data = {0x40, (uint8_t)index, (uint8_t)(index >> 8), sub}};
    h_rx_frame(d, &f);
    const co_frame_t *r;
    while ((r = h_next(d)) != NULL && r->id != 0x580u + d->node->node_id) {
        /* other traffic (EMCY, PDO) sent at the same time */
    }
    if (r == NULL || r->data[0] == 0x80u) {
        return -1;
    }
    unsigned size = 4u - ((r->data[0] >> 2) & 3u);
    uint32_t v = co_get_u32(&r->data[4]);
    if (size < 4u) {
        v &= (1u << (8u * size)) - 1u;
    }
    return (long long)v;
}
