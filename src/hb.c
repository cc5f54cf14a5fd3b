/*
 * hb.c - heartbeat producer and boot-up. See co_hb.h.
 */
#include "co_hb.h"

#include "co_node.h"

void co_hb_reconfig(co_node_t *node)
{
    uint32_t v = 0;
    const co_od_entry_t *e = co_node_entry(node, 0x1017, 0);
    if (e != NULL) {
        (void)co_od_get(node, e, &v);
    }
    node->hb.period_ms = (uint16_t)v;
    node->hb.restart = true;
}

uint16_t co_hb_period_ms(const co_node_t *node)
{
    return node->hb.period_ms;
}

co_res_t co_hb_write_hook(co_node_t *node, const co_od_entry_t *e, uint32_t value)
{
    co_res_t r = co_od_store(node, e, value);
    if (r == CO_OK) {
        co_hb_reconfig(node);
    }
    return r;
}

static void send_state(co_node_t *node, uint8_t state)
{
    co_frame_t f = {.id = (uint16_t)(0x700u + node->node_id), .dlc = 1, .data = {state}};
    (void)co_node_send(node, &f);
}

void co_hb_bootup(co_node_t *node)
{
    send_state(node, 0x00);
}

uint32_t co_hb_poll(co_node_t *node, uint32_t now)
{
    co_hb_t *hb = &node->hb;
    if (hb->period_ms == 0u || node->nmt.state == CO_NMT_INIT) {
        return CO_NEVER;
    }
    /* u16 ms x 1000 <= 65 535 000 us: no overflow, and far inside
     * co_time_before's 2^31 us horizon. */
    uint32_t period = (uint32_t)hb->period_ms * 1000u;
    if (hb->restart) {
        hb->restart = false;
        hb->next = now + period;
    }
    if (!co_time_before(now, hb->next)) {
        send_state(node, node->nmt.state);
        hb->next += period;
        if (!co_time_before(now, hb->next)) {
            hb->next = now + period; /* we were late by a period or more: no burst */
        }
    }
    return hb->next - now;
}
