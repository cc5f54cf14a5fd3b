/*
 * guard.c - node guarding and life guarding. See co_guard.h.
 */
#include "co_guard.h"

#include "co_node.h"

static uint32_t get(co_node_t *node, uint16_t index)
{
    uint32_t v = 0;
    const co_od_entry_t *e = co_node_entry(node, index, 0);
    if (e != NULL) {
        (void)co_od_get(node, e, &v);
    }
    return v;
}

void co_guard_reset(co_node_t *node)
{
    co_guard_t *g = &node->guard;
    g->enabled = co_node_entry(node, 0x100C, 0) != NULL;
    g->toggle = 0;
    g->seen = false; /* kick counts only once a request is seen (receive sets both) */
    if (g->lost) {
        g->lost = false;
        (void)co_emcy_error(node, CO_EMCY_LIFE_GUARD, CO_ER_COMM, false, NULL);
    }
}

bool co_guard_receive(co_node_t *node, const co_frame_t *f)
{
    co_guard_t *g = &node->guard;
    if (!f->rtr || f->id != 0x700u + node->node_id) {
        return false;
    }
    if (!g->enabled || co_hb_period_ms(node) != 0u) {
        return true; /* not guarded, or the heartbeat is the protocol in use */
    }
    co_frame_t r = {.id = f->id, .dlc = 1, .data = {(uint8_t)(g->toggle | node->nmt.state)}};
    (void)co_node_send(node, &r);
    g->toggle ^= 0x80u;
    g->seen = true;
    g->kick = true;
    g->deadline = node->now; /* the life time runs from this request */
    if (g->lost) {
        g->lost = false;
        (void)co_emcy_error(node, CO_EMCY_LIFE_GUARD, CO_ER_COMM, false, NULL);
    }
    return true;
}

/* Start the next lap of the life time at 'from'. */
static void next_lap(co_guard_t *g, uint32_t from)
{
    uint32_t lap = co_min_u32(g->left_ms, CO_GUARD_LAP_MS);
    g->left_ms -= lap;
    g->deadline = from + lap * 1000u; /* <= 1e9 us: no overflow */
}

uint32_t co_guard_poll(co_node_t *node, uint32_t now)
{
    co_guard_t *g = &node->guard;
    if (!g->enabled || !g->seen || g->lost) {
        return CO_NEVER;
    }
    /* Life time = guard time x life time factor (CiA 301), up to
     * 65535 x 255 ms: 32 bits hold it in ms, not in us. */
    uint32_t life_ms = get(node, 0x100C) * get(node, 0x100D);
    if (life_ms == 0u || co_hb_period_ms(node) != 0u) {
        /* Life guarding is off (no life time, or the heartbeat is the
         * protocol in use): it starts again with the first request answered
         * after. Kept, the last request's time stamp would be stale by then:
         * more than 2^31 us old, it reads as ahead, and the event came up to
         * 36 min late (found by tests/fuzz/fuzz_node.c). */
        g->seen = false;
        return CO_NEVER;
    }
    if (g->kick) {
        /* The first lap starts at the request's time (receive set the
         * deadline to it, never ahead of now): the loop below starts it. */
        g->kick = false;
        g->left_ms = life_ms;
    }
    while (!co_time_before(now, g->deadline)) {
        if (g->left_ms == 0u) {
            g->lost = true;
            (void)co_emcy_error(node, CO_EMCY_LIFE_GUARD, CO_ER_COMM, true, NULL);
            if (node->nmt.state == CO_NMT_OPERATIONAL) {
                co_nmt_enter(node, CO_NMT_PREOP); /* CiA 301 default error behaviour */
            }
            return CO_NEVER;
        }
        next_lap(g, g->deadline); /* laps end to end: no drift */
    }
    return g->deadline - now;
}

const co_service_t co_guard_service = {
    .receive = co_guard_receive, .poll = co_guard_poll, .reset = co_guard_reset};
