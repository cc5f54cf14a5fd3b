/*
 * node.c - the node object: reset sequence, frame dispatch, timers, LEDs.
 * See co_node.h.
 */
#include "co_node.h"

#include <string.h>

#include "co_port.h"

void co_node_init(co_node_t *node, const co_node_cfg_t *cfg, void *port, void *app,
                  void *const ram[CO_CLS_COUNT], uint32_t nvm_base)
{
    memset(node, 0, sizeof(*node)); /* the NMT state too: CO_NMT_INIT is 0 */
    node->cfg = cfg;
    node->port = port;
    node->app = app;
    for (unsigned i = 0; i < CO_CLS_COUNT; i++) {
        node->ram[i] = ram[i];
    }
    node->nvm_base = nvm_base;
    node->node_id = cfg->default_node_id;
}

const co_od_entry_t *co_node_entry(const co_node_t *node, uint16_t index, uint8_t sub)
{
    return co_od_find(co_cfg(node)->od, index, sub, NULL);
}

/* co_node_send (co_node.h): a controller in bus-off transmits nothing until
 * it has seen 128 x 11 recessive bits and is error active again (ISO
 * 11898-1; the board reports it): what falls due meanwhile is dropped, not
 * queued for a burst on recovery. */
bool co_node_tx_drop(co_node_t *node)
{
    node->tx_dropped++;
    return false;
}

/*
 * A write the product stores on its own (cfg->autosave, CiA 301 0x1010
 * bit 1): the value is taken and answered at once; its class is stored
 * when the SDO server has been quiet for a while (co_store_poll), so that
 * no answer waits for the flash and a master's burst of writes costs one
 * record. A reset stores it first (co_node_reset), and so does a board's
 * orderly stop (co_store_flush). A power cut before that loses the writes
 * since the last record, which stays whole; a store that fails then is
 * reported as the product's data-set error (co_store_poll), the value
 * staying in use.
 */
co_res_t co_node_write(co_node_t *node, const co_od_entry_t *e, const uint8_t *buf, uint32_t len)
{
    co_res_t r = co_od_write(node, e, buf, len);
    if (r == CO_OK && co_cfg(node)->autosave && (e->cls == CO_CLS_PARA || e->cls == CO_CLS_LSS)) {
        co_store_t *s = &node->store;
        if ((s->due & (CO_STORE_DUE_SAVE(CO_CLS_PARA) | CO_STORE_DUE_SAVE(CO_CLS_LSS))) == 0u) {
            s->due_at = node->now; /* the oldest write waiting */
        }
        s->due |= (uint8_t)CO_STORE_DUE_SAVE(e->cls);
    }
    return r;
}

/* A restore, and the check of a record's values (co_store.h). */
static void restore(co_node_t *node, co_cls_t cls, uint16_t lo, uint16_t hi)
{
    if (co_store_restore(node, cls, lo, hi) == CO_STORE_OK) {
        co_store_validate(node, cls);
    }
}

void co_node_reset(co_node_t *node, co_reset_t kind)
{
    co_node_wake(node);
    co_store_flush(node); /* what the restore below reads must hold the writes taken */
    /* Silent while re-initialising: no state hook for INIT. */
    node->nmt.state = CO_NMT_INIT;
    if (kind == CO_RESET_NODE) {
        co_od_defaults(node, CO_CLS_VOL, 0x0000, 0xFFFF);
        restore(node, CO_CLS_PARA, 0x0000, 0xFFFF);
        restore(node, CO_CLS_LSS, 0x0000, 0xFFFF);
    } else {
        co_od_defaults(node, CO_CLS_VOL, 0x1000, 0x1FFF);
        restore(node, CO_CLS_PARA, 0x1000, 0x1FFF);
        if (co_cfg(node)->comm_reset_applies_id) {
            restore(node, CO_CLS_LSS, 0x0000, 0xFFFF);
        }
    }
    const co_lss_para_t *lss = node->ram[CO_CLS_LSS];
    if (kind == CO_RESET_NODE || co_cfg(node)->comm_reset_applies_id) {
        bool id_ok = lss != NULL && lss->node_id >= 1u && lss->node_id <= CO_NODE_ID_MAX;
        if (lss != NULL && !id_ok) {
            /* Defaults always hold a good one: a stored node-ID out of 1..127. */
            co_store_mark_corrupt(node, CO_CLS_LSS);
        }
        node->node_id = id_ok ? lss->node_id : co_node_factory_id(node);
        node->bitrate = lss != NULL ? lss->bitrate : co_cfg(node)->default_bitrate;
    }
    co_sdo_init(&node->sdo);
    node->autostart = false;
    if (co_cfg(node)->ops != NULL && co_cfg(node)->ops->reset != NULL) {
        co_cfg(node)->ops->reset(node, kind); /* may set the node-ID from its own objects */
    }
    if (co_cfg_has_service(co_cfg(node), &co_lss_service) && node->lss.pending_id != 0u) {
        /* CiA 305: an LSS-configured node-ID is active from reset communication on. */
        node->node_id = node->lss.pending_id;
        node->lss.pending_id = 0;
    }
    for (const co_service_t *const *sv = co_cfg(node)->services; sv != NULL && *sv != NULL; sv++) {
        if ((*sv)->reset != NULL) {
            (*sv)->reset(node);
        }
    }
    /* The active bit-rate code reaches the controller: at start, and after
     * a reset that activates codes (reset node; reset communication where
     * it applies the node-ID set) and activated another one (an unusable
     * code: 0 kbit/s, the board's default; a config without a table: 0
     * too). Any other reset communication leaves the rate alone: an LSS
     * "activate bit timing" holds until then (CiA 305). Codes are 0..15
     * (co_node_cfg_t.kbps): stored ones are range-checked on restore. */
    const uint16_t *table = co_cfg(node)->kbps;
    uint16_t kbps = table != NULL ? table[node->bitrate & 15u] : 0u; /* 16 codes */
    if ((kind == CO_RESET_NODE || co_cfg(node)->comm_reset_applies_id) && kbps != node->can_kbps) {
        node->can_kbps = kbps;
        (void)co_port_can_bitrate(node->port, kbps);
    }
    if (node->node_id == CO_LSS_UNCONFIGURED) {
        return; /* no node-ID: silent but for LSS until one is configured */
    }
    co_hb_reconfig(node);
    co_sync_reconfig(node);
    for (unsigned n = 0; n < CO_TPDO_MAX; n++) {
        co_tpdo_reconfig(node, n);
    }
    co_hb_bootup(node);
    co_nmt_enter(node, CO_NMT_PREOP);
    if (node->autostart) {
        co_nmt_enter(node, CO_NMT_OPERATIONAL);
    }
}

void co_node_start(co_node_t *node, uint32_t now)
{
    node->now = now;
    node->can_kbps = 0xFFFFu; /* none yet: the reset tells the board */
    co_store_init(node);
    co_node_reset(node, CO_RESET_NODE);
}

/* Offer f to the optional services of the given kind (always or not). */
static bool services_receive(co_node_t *node, const co_frame_t *f, bool always)
{
    for (const co_service_t *const *sv = co_cfg(node)->services; sv != NULL && *sv != NULL; sv++) {
        if ((*sv)->always == always && (*sv)->receive != NULL && (*sv)->receive(node, f)) {
            return true;
        }
    }
    return false;
}

void co_node_receive(co_node_t *node, const co_frame_t *f, uint32_t now)
{
    node->now = now;
    co_node_wake(node);
    /* The frame a slave gets most, straight to its server: no other
     * service may use an SDO CAN-ID (restricted, CiA 301 7.3.5). */
    if (f->id == 0x600u + node->node_id && node->nmt.state != CO_NMT_INIT) {
        co_sdo_receive(node, f);
        return;
    }
    /* An SDO request was served above: nothing else is on its CAN-ID.
     * NMT and SYNC next, the frames a slave gets most after SDO: their
     * CAN-IDs (0, a SYNC COB-ID that is never restricted) are no LSS
     * frame's (0x7E5), so they go before the services that run in every
     * state (SYNC on the JD2: 20 instructions less). */
    bool init = node->nmt.state == CO_NMT_INIT;
    if (!init && (co_nmt_receive(node, f) || co_sync_receive(node, f))) {
        return;
    }
    if (services_receive(node, f, true)) {
        return; /* LSS works in every state, and without a node-ID */
    }
    if (init || services_receive(node, f, false)) {
        return;
    }
    /* Anything else (other nodes' traffic, RTRs nobody serves) is ignored. */
}

uint32_t co_node_poll(co_node_t *node, uint32_t now)
{
    node->now = now;
    if (!node->dirty && co_time_before(now, node->due)) {
        return node->due_never ? CO_NEVER : node->due - now; /* the idle poll */
    }
    node->dirty = false;
    if (node->reset_request != 0u) {
        co_reset_t kind = (co_reset_t)node->reset_request;
        node->reset_request = 0;
        co_node_reset(node, kind);
    }
    uint32_t next = co_sdo_poll(node, now);
    next = co_min_u32(next, co_hb_poll(node, now));
    for (const co_service_t *const *sv = co_cfg(node)->services; sv != NULL && *sv != NULL; sv++) {
        if ((*sv)->poll != NULL) {
            next = co_min_u32(next, (*sv)->poll(node, now));
        }
    }
    if (co_cfg(node)->ops != NULL && co_cfg(node)->ops->poll != NULL) {
        next = co_min_u32(next, co_cfg(node)->ops->poll(node, now));
    }
    next = co_min_u32(next, co_tpdo_poll(node, now));
    next = co_min_u32(next, co_store_poll(node, now));
    /* Nothing can fall due before next unless something happens first.
     * No deadline at all: look again after half the clock's range. */
    node->due_never = next == CO_NEVER;
    node->due = now + co_min_u32(next, 0x7FFFFFFFu);
    return next;
}

void co_node_set_can_state(co_node_t *node, co_can_state_t s)
{
    co_can_state_t old = (co_can_state_t)node->can_state;
    if (old == s) {
        return;
    }
    node->can_state = (uint8_t)s;
    co_node_wake(node);
    if (co_cfg(node)->ops != NULL && co_cfg(node)->ops->can_state != NULL) {
        co_cfg(node)->ops->can_state(node, old);
    }
}

void co_node_led_patterns(co_node_t *node, co_led_pattern_t *green, co_led_pattern_t *red)
{
    co_led_pattern_t g;
    co_led_pattern_t r;
    switch (node->nmt.state) {
    case CO_NMT_OPERATIONAL:
        g = CO_LED_ON;
        break;
    case CO_NMT_STOPPED:
        g = CO_LED_FLASH1;
        break;
    case CO_NMT_PREOP:
        g = CO_LED_BLINK;
        break;
    default:
        g = CO_LED_OFF;
        break;
    }
    switch ((co_can_state_t)node->can_state) {
    case CO_CAN_BUSOFF:
        r = CO_LED_ON;
        break;
    case CO_CAN_WARNING:
    case CO_CAN_PASSIVE:
        r = CO_LED_FLASH1;
        break;
    case CO_CAN_ACTIVE:
    default:
        r = CO_LED_OFF;
        break;
    }
    if (co_cfg(node)->ops != NULL && co_cfg(node)->ops->leds != NULL) {
        co_cfg(node)->ops->leds(node, &g, &r);
    }
    *green = g;
    *red = r;
}

const char *co_led_pattern_name(co_led_pattern_t p)
{
    switch (p) {
    case CO_LED_OFF:
        return "off";
    case CO_LED_ON:
        return "on";
    case CO_LED_FLICKER:
        return "flickering";
    case CO_LED_BLINK:
        return "blinking";
    case CO_LED_FLASH1:
        return "single flash";
    case CO_LED_FLASH2:
        return "double flash";
    default:
        return "?";
    }
}

void co_node_leds(co_node_t *node, uint32_t now, bool *green, bool *red, uint32_t *next_us)
{
    co_led_pattern_t g;
    co_led_pattern_t r;
    co_node_led_patterns(node, &g, &r);
    const co_led_timing_t *t = co_cfg(node)->led != NULL ? co_cfg(node)->led : &co_led_cia303;
    uint32_t ng;
    uint32_t nr;
    *green = co_led_level(g, t, now, &ng);
    *red = co_led_level(r, t, now, &nr);
    *next_us = co_min_u32(ng, nr);
}
