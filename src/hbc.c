/*
 * hbc.c - heartbeat consumer. See co_hbc.h.
 */
#include "co_hbc.h"

#include "co_node.h"

void co_hbc_reset(co_node_t *node)
{
    co_hbc_t *c = &node->hbc;
    uint32_t v = 0;
    const co_od_entry_t *e = co_node_entry(node, 0x1016, 1);
    if (e != NULL) {
        (void)co_od_get(node, e, &v);
    }
    if (c->lost) {
        (void)co_emcy_error(node, CO_EMCY_LIFE_GUARD, CO_ER_COMM, false, NULL);
    }
    c->node_id = (uint8_t)(v >> 16);
    c->time_ms = (uint16_t)v;
    c->started = false; /* kick counts only once started (receive sets both) */
    c->lost = false;
}

co_res_t co_hbc_write_time(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    if ((value & 0xFF000000u) != 0u || ((value >> 16) & 0xFFu) > CO_NODE_ID_MAX) {
        return CO_E_VAL;
    }
    co_res_t r = co_od_store(node, e, value);
    if (r == CO_OK) {
        co_hbc_reset(node);
    }
    return r;
}

bool co_hbc_receive(co_node_t *node, const co_frame_t *f)
{
    co_hbc_t *c = &node->hbc;
    if (c->node_id == 0u || c->time_ms == 0u || f->rtr || f->dlc != 1u ||
        f->id != 0x700u + c->node_id) {
        return false;
    }
    c->started = true;
    c->kick = true;
    c->deadline = node->now; /* the time runs from this heartbeat */
    if (c->lost) {
        c->lost = false;
        (void)co_emcy_error(node, CO_EMCY_LIFE_GUARD, CO_ER_COMM, false, NULL);
    }
    return true;
}

uint32_t co_hbc_poll(co_node_t *node, uint32_t now)
{
    co_hbc_t *c = &node->hbc;
    if (!c->started || c->lost) { /* started: with a time (receive, reset) */
        return CO_NEVER;
    }
    if (c->kick) {
        c->kick = false;
        /* u16 ms x 1000 <= 65 535 000 us: far inside co_time_before's
         * 2^31 us horizon, no overflow. */
        c->deadline += (uint32_t)c->time_ms * 1000u;
    }
    if (co_time_before(now, c->deadline)) {
        return c->deadline - now;
    }
    c->lost = true;
    (void)co_emcy_error(node, CO_EMCY_LIFE_GUARD, CO_ER_COMM, true, NULL);
    if (node->nmt.state == CO_NMT_OPERATIONAL) {
        co_nmt_enter(node, CO_NMT_PREOP); /* CiA 301 default error behaviour */
    }
    return CO_NEVER;
}

const co_service_t co_hbc_service = {
    .receive = co_hbc_receive, .poll = co_hbc_poll, .reset = co_hbc_reset};
