/*
 * dst.c - behaviour shared by the Danfoss DST inclinometers.
 *
 * After the DST X730 and DST X710 operating guides ("the manual": the two
 * agree where this file cites them). Where the manual is silent or
 * contradicts itself, the choice is written down as a decision next to
 * the code; CiA 301/410 otherwise.
 */
#include "dst.h"

#include <string.h>

static dst_dev_t *dev_of(co_node_t *n)
{
    return co_node_app(n);
}

/* ---- dictionary hooks ---------------------------------------------- */

co_res_t dst_write_hb(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    if (v >= 1u && v <= 19u) {
        return CO_E_VAL; /* manual: "From 1 - 19 NOT ACCEPTED" */
    }
    return co_hb_write_time(n, e, v);
}

co_res_t dst_write_emcy_cobid(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    /* CiA 301: bits 30..29 must be 0 (no RTR, 11-bit); an 11-bit CAN-ID,
     * not a restricted one while valid. The manual sets no rule on when the
     * CAN-ID may change: any time. */
    co_res_t c = co_cobid_check(v, false, true);
    return c != CO_OK ? c : co_od_store(n, e, v);
}

co_res_t dst_write_tx_type(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    /* 1..240 every n-th SYNC, 254 event timer. 252, 253, 255 are "not
     * implemented" per the manual (section 12, 0x1800 sub 2).
     * Decision: 0 and 241..251, which it does not list, are refused too. */
    if (!((v >= 1u && v <= 240u) || v == 254u)) {
        return CO_E_VAL;
    }
    return co_tpdo_write_comm(n, e, v);
}

co_res_t dst_write_event(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    if (v >= 1u && v <= 3u) {
        /* 4..65535 ms (section 12); 0 = inactive (examples 12, 13) */
        return CO_E_VAL;
    }
    return co_tpdo_write_comm(n, e, v);
}

/* Node-ID / bit rate: a value is committed when both copies agree; the
 * committed pair is written to EEPROM at once (no "save": the manual's
 * node-ID example has no save step) and becomes active at the next reset. */
static co_res_t commit_pair(co_node_t *n, uint8_t *copies, unsigned which, uint8_t v,
                            uint8_t *committed)
{
    copies[which] = v;
    if (copies[0] != copies[1] || copies[0] == *committed) {
        return CO_OK;
    }
    uint8_t old = *committed;
    *committed = v;
    co_res_t r = co_store_save(n, CO_CLS_LSS);
    if (r != CO_OK) {
        *committed = old;
    }
    return r;
}

co_res_t dst_write_id(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    dst_dev_t *d = dev_of(n);
    return commit_pair(n, d->vol.id, e->index == 0x20F0u ? 0u : 1u, (uint8_t)v, &d->lss.node_id);
}

co_res_t dst_write_bitrate(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    dst_dev_t *d = dev_of(n);
    return commit_pair(n, d->vol.br, e->index == 0x20F2u ? 0u : 1u, (uint8_t)v, &d->lss.bitrate);
}

co_res_t dst_write_coding(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    co_res_t r = co_od_store(n, e, v);
    co_tpdo_set_msb_first(n, 0, dev_of(n)->para.pdo_coding == 0u); /* TPDO1, its only one */
    return r;
}

co_res_t dst_write_resolution(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    (void)e;
    if (v != 10u && v != 50u && v != 100u && v != 500u && v != 1000u) {
        return CO_E_VAL;
    }
    if (co_od_checking(n)) {
        return CO_OK;
    }
    return co_incl_set_resolution(&dev_of(n)->incl, (uint16_t)v);
}

co_res_t dst_write_preset(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    /* Immediate ("immediately corrects the measured value", manual,
     * section 15, example 7): the output equals the preset from now on. */
    if (co_od_checking(n)) {
        return CO_OK;
    }
    unsigned axis = e->index == 0x6012u ? 0u : 1u;
    co_incl_set_preset(&dev_of(n)->incl, axis, (int16_t)v);
    return CO_OK;
}

co_res_t dst_read_errors(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    (void)e;
    *v = dev_of(n)->errors;
    return CO_OK;
}

co_res_t dst_read_slope(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    return co_incl_read(&dev_of(n)->incl, e->index == 0x6010u ? 0u : 1u, v);
}

/* ---- node ops ------------------------------------------------------ */

static void apply_filter(dst_dev_t *d)
{
    d->filter_active = d->para.filter;
    d->incl.shift = co_filter_shift(d->filter_active);
}

static void dst_reset(co_node_t *n, co_reset_t kind)
{
    dst_dev_t *d = dev_of(n);
    (void)kind;
    if (d->lss.bitrate > 7u) {
        /* A stored code beyond the table (0..7, as 0x20F2 accepts): the
         * default, and the set reported as corrupt (0x4001 bit 6). */
        d->lss.bitrate = co_cfg(n)->default_bitrate;
        co_node_set_bitrate(n, d->lss.bitrate);
        co_store_mark_corrupt(n, CO_CLS_LSS);
    }
    /* Both copies read the active values after a reset (decision: the
     * manual only says that copies which differ leave the old node-ID). */
    d->vol.id[0] = d->vol.id[1] = co_node_id(n);
    d->vol.br[0] = d->vol.br[1] = d->lss.bitrate;
    /* Big-endian PDOs only where 0x5001 exists and says so (the X710 has none). */
    co_tpdo_set_msb_first(n, 0, co_node_entry(n, 0x5001, 0) != NULL && d->para.pdo_coding == 0u);
    co_node_set_autostart(n, d->para.autostart == 1u); /* decision: after any reset */
    apply_filter(d);
    /* Errors are re-evaluated and re-reported after every boot-up. */
    d->reported = 0;
}

static void dst_stored(co_node_t *n, uint32_t sig)
{
    /* The filter setting takes effect on "save" (manual, section 12,
     * 0x2001: "only accepted after a STORE command"). */
    if (sig == CO_SIG_SAVE) {
        apply_filter(dev_of(n));
    }
}

static uint8_t current_errors(dst_dev_t *d)
{
    co_node_t *n = &d->node;
    uint8_t e = 0;
    if (d->sensor_fault || co_incl_beyond(&d->incl)) {
        e |= DST_ERR_SENSOR;
    }
    if (co_store_limit_reached(n)) {
        e |= DST_ERR_FLASH;
    }
    /* The manual has one bit for stored-data checksums ("LSS parameter
     * checksum error"); a corrupt PARA set is reported with it too rather
     * than not at all. Defaults are in use until the next good save. */
    co_store_status_t lss = co_node_store_status(n, CO_CLS_LSS);
    co_store_status_t para = co_node_store_status(n, CO_CLS_PARA);
    if (lss == CO_STORE_CORRUPT || para == CO_STORE_CORRUPT || lss == CO_STORE_HW ||
        para == CO_STORE_HW) {
        e |= DST_ERR_CHECKSUM;
    }
    return e;
}

static uint32_t dst_poll(co_node_t *n, uint32_t now)
{
    (void)now;
    dst_dev_t *d = dev_of(n);
    d->errors = current_errors(d);
    if (d->errors == d->reported) {
        return CO_NEVER;
    }
    /* EMCY layout from the manual's table (section 9 'Error handling'),
     * which the text's "only the 1st byte" does not contradict: code,
     * 0x1001 ("Always ZERO"), 0x00, 0x4001, 0, 0, 0. Error reset: all zero
     * (CiA 301; the manual does not say). */
    uint8_t msef[5] = {0x00, d->errors, 0, 0, 0};
    uint16_t code = d->errors != 0u ? CO_EMCY_GENERIC : CO_EMCY_NO_ERROR;
    co_nmt_state_t st = co_node_nmt_state(n);
    if (st != CO_NMT_PREOP && st != CO_NMT_OPERATIONAL) {
        return CO_NEVER; /* no EMCY in stopped: reported when it is allowed again */
    }
    (void)co_emcy_send(n, code, 0x00, msef); /* may be disabled by 0x1014 bit 31 */
    bool new_error = d->reported == 0u && d->errors != 0u;
    d->reported = d->errors;
    if (new_error) {
        /* 0x4000: 0 pre-operational, 2 stopped, anything else no change.
         * Decision: on any error appearing, the angle limit included (the
         * manual's "serious device failure" is not defined). */
        if (d->para.err_behaviour == 0u && st == CO_NMT_OPERATIONAL) {
            co_nmt_enter(n, CO_NMT_PREOP);
        } else if (d->para.err_behaviour == 2u) {
            co_nmt_enter(n, CO_NMT_STOPPED);
        }
    }
    return CO_NEVER;
}

static void dst_leds(co_node_t *n, co_led_pattern_t *g, co_led_pattern_t *r)
{
    /* "Limit Angles reached": red and green both on (manual, section 13
     * 'Status LED'). */
    if (co_incl_beyond(&dev_of(n)->incl)) {
        *g = CO_LED_ON;
        *r = CO_LED_ON;
    }
}

const co_node_ops_t dst_ops = {
    .reset = dst_reset,
    .stored = dst_stored,
    .poll = dst_poll,
    .leds = dst_leds,
};

/* Green blinks 200/200 ms; "single flash" is 500 ms on / 500 ms off, as
 * the manual's legend says (section 13), not CiA 303-3's 200/1000 ms. */
const co_led_timing_t dst_led = {
    .flicker_ms = 50, .blink_ms = 200, .flash_ms = 500, .pause_ms = 500};

void dst_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    dst_dev_t *d = mem;
    const dst_variant_t *v = p->variant;
    memset(d, 0, sizeof(*d));
    co_incl_init(&d->incl, &d->para.incl, v->axes, v->limit_mdeg, v->wrap);
    void *const ram[CO_CLS_COUNT] = {
        [CO_CLS_VOL] = &d->vol, [CO_CLS_PARA] = &d->para, [CO_CLS_LSS] = &d->lss};
    co_node_init(&d->node, v->cfg, ports[0], d, ram, 0);
    nodes[0] = &d->node;
}

void dst_sample(void *mem, const int32_t values[], uint32_t faults)
{
    dst_dev_t *d = mem;
    bool fault = (faults & 1u) != 0u; /* "sensor" */
    d->sensor_fault = fault;
    d->incl.fault = fault;
    co_incl_sample(&d->incl, values);
    co_node_wake(&d->node); /* errors may have changed: dst_poll looks */
}
