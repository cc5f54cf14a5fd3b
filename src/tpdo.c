/*
 * tpdo.c - transmit PDOs. See co_tpdo.h.
 */
#include "co_tpdo.h"

#include <string.h>

#include "co_node.h"

static uint32_t get_or(co_node_t *node, uint16_t index, uint8_t sub, uint32_t dflt)
{
    const co_od_entry_t *e = co_node_entry(node, index, sub);
    uint32_t v = dflt;
    if (e != NULL) {
        (void)co_od_get(node, e, &v);
    }
    return v;
}

static bool event_driven(const co_tpdo_t *t)
{
    return t->type >= 254u;
}

static void start_one(co_node_t *node, co_tpdo_t *t)
{
    t->sync_count = 0;
    t->inhibited = false;
    /* The first event-driven PDO goes out at the next poll. */
    t->timer_armed = t->valid && event_driven(t) && t->event_ms != 0u;
    t->next_event = node->now;
}

void co_tpdo_reconfig(co_node_t *node, unsigned n)
{
    co_tpdo_t *t = &node->tpdo[n];
    memset(t, 0, sizeof(*t));
    uint16_t comm = (uint16_t)(0x1800u + n);
    uint16_t mapi = (uint16_t)(0x1A00u + n);
    if (co_node_entry(node, comm, 1) == NULL) {
        return;
    }
    uint32_t cob = get_or(node, comm, 1, 0x80000000u);
    t->type = (uint8_t)get_or(node, comm, 2, 254);
    t->inhibit = (uint16_t)get_or(node, comm, 3, 0);
    t->event_ms = (uint16_t)get_or(node, comm, 5, 0);
    t->cob_id = (uint16_t)(cob & 0x7FFu);
    uint32_t count = get_or(node, mapi, 0, 0);
    if (count > CO_PDO_MAP_MAX) {
        return;
    }
    uint32_t len = 0;
    for (uint8_t i = 0; i < count; i++) {
        uint32_t m = get_or(node, mapi, (uint8_t)(i + 1u), 0);
        const co_od_entry_t *e = co_node_entry(node, (uint16_t)(m >> 16), (uint8_t)(m >> 8));
        uint32_t bits = m & 0xFFu;
        if (e == NULL || (e->attr & CO_A_PDO) == 0u || bits == 0u || (bits % 8u) != 0u ||
            bits / 8u > co_od_size(e)) {
            return; /* unusable mapping: the PDO stays invalid */
        }
        t->map[i] = e;
        t->map_bytes[i] = (uint8_t)(bits / 8u);
        len += bits / 8u;
    }
    if (len > 8u) {
        return;
    }
    t->nmap = (uint8_t)count;
    t->len = (uint8_t)len;
    t->valid = (cob & 0x80000000u) == 0u;
    if (node->nmt.state == CO_NMT_OPERATIONAL) {
        start_one(node, t); /* a parameter changed while operational: apply it now */
    }
}

co_res_t co_tpdo_write_hook(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    co_res_t r = co_od_store(node, e, value);
    if (r == CO_OK) {
        unsigned n = (unsigned)(e->index & 0x1FFu);
        if (n < CO_TPDO_MAX) {
            co_tpdo_reconfig(node, n);
        }
    }
    return r;
}

void co_tpdo_start(co_node_t *node)
{
    for (unsigned n = 0; n < CO_TPDO_MAX; n++) {
        start_one(node, &node->tpdo[n]);
    }
}

void co_tpdo_stop(co_node_t *node)
{
    for (unsigned n = 0; n < CO_TPDO_MAX; n++) {
        node->tpdo[n].timer_armed = false;
        node->tpdo[n].inhibited = false;
    }
}

void co_tpdo_build(co_node_t *node, unsigned n, co_frame_t *f)
{
    const co_tpdo_t *t = &node->tpdo[n];
    memset(f, 0, sizeof(*f));
    f->id = t->cob_id;
    uint8_t pos = 0;
    for (uint8_t i = 0; i < t->nmap; i++) {
        uint32_t v = 0;
        (void)co_od_get(node, t->map[i], &v);
        uint8_t nb = t->map_bytes[i];
        for (uint8_t b = 0; b < nb; b++) {
            uint8_t shift = node->pdo_msb_first ? (uint8_t)(nb - 1u - b) : b;
            f->data[pos + b] = (uint8_t)(v >> (8u * shift));
        }
        pos = (uint8_t)(pos + nb);
    }
    f->dlc = node->cfg->tpdo_dlc != 0u ? node->cfg->tpdo_dlc : t->len;
}

static void send(co_node_t *node, unsigned n)
{
    co_frame_t f;
    co_tpdo_build(node, n, &f);
    (void)co_node_send(node, &f);
}

void co_tpdo_sync(co_node_t *node)
{
    for (unsigned n = 0; n < CO_TPDO_MAX; n++) {
        co_tpdo_t *t = &node->tpdo[n];
        if (!t->valid || t->type == 0u || t->type > 240u) {
            continue;
        }
        if (++t->sync_count >= t->type) {
            t->sync_count = 0;
            send(node, n);
        }
    }
}

uint32_t co_tpdo_poll(co_node_t *node, uint32_t now)
{
    uint32_t next = CO_NEVER;
    if (node->nmt.state != CO_NMT_OPERATIONAL) {
        return next;
    }
    for (unsigned n = 0; n < CO_TPDO_MAX; n++) {
        co_tpdo_t *t = &node->tpdo[n];
        if (!t->timer_armed) {
            continue;
        }
        uint32_t period = (uint32_t)t->event_ms * 1000u;
        if (!co_time_before(now, t->next_event)) {
            if (t->inhibited && co_time_before(now, t->inhibit_end)) {
                next = co_min_u32(next, t->inhibit_end - now);
                continue;
            }
            send(node, n);
            t->inhibited = t->inhibit != 0u;
            uint32_t unit = node->cfg->inhibit_unit_us != 0u ? node->cfg->inhibit_unit_us : 100u;
            t->inhibit_end = now + (uint32_t)t->inhibit * unit;
            t->next_event += period;
            if (!co_time_before(now, t->next_event)) {
                t->next_event = now + period; /* late by a period: no burst */
            }
        }
        next = co_min_u32(next, t->next_event - now);
    }
    return next;
}
