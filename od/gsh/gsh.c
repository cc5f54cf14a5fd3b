/*
 * gsh.c - behaviour of the Gefran GSH-A, after its manual ("CANopen
 * GSH-A", Cod. 80782). Where the manual is silent or contradicts itself,
 * the choice is written down as a decision next to the code.
 */
#include "gsh.h"

#include <string.h>

static gsh_chan_t *chan_of(co_node_t *n)
{
    return co_node_app(n);
}

uint8_t gsh_pdo_checksum(const uint8_t d[7])
{
    uint32_t s = 0;
    for (unsigned i = 0; i < 7u; i++) {
        s += d[i];
    }
    return (uint8_t)((s + 254u) % 255u);
}

co_res_t gsh_write_event(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    if (v >= 1u && v <= 3u) {
        /* 4..65535 ms (manual, section 11). Decision: 0 = off, since the
         * manual wants 0 in the EDS and a tool may download it. */
        return CO_E_VAL_LOW;
    }
    return co_tpdo_write_comm(n, e, v);
}

co_res_t gsh_read_position(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    (void)e;
    *v = chan_of(n)->position_mm;
    return CO_OK;
}

co_res_t gsh_read_angle(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    (void)e;
    *v = (uint16_t)co_incl_slope(&chan_of(n)->incl, 0);
    return CO_OK;
}

/* 0x2110: the alarm word, as the next PDO's bytes 5-6 carry it. */
co_res_t gsh_read_alarm(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    (void)e;
    *v = chan_of(n)->alarms;
    return CO_OK;
}

/* 0x2111: byte 7 of the last PDO sent. */
co_res_t gsh_read_counter(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    (void)e;
    *v = chan_of(n)->sent_counter;
    return CO_OK;
}

/* 0x2112: byte 8 of the last PDO sent. */
co_res_t gsh_read_checksum(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    (void)e;
    *v = chan_of(n)->sent_checksum;
    return CO_OK;
}

static void gsh_reset(co_node_t *n, co_reset_t kind)
{
    (void)kind;
    gsh_chan_t *c = chan_of(n);
    /* Decision: the counter starts from 0 at every boot-up (the manual
     * only names byte 7 "Counter"). */
    c->counter = 0;
    c->sent_counter = 0;
    c->sent_checksum = 0;
    /* Decision: auto-start after every boot-up, NMT resets included: the
     * manual ties it to the boot-up (section 1), and every reset boots up. */
    co_node_set_autostart(n, c->para.autostart == 1u);
}

static void gsh_tpdo_fill(co_node_t *n, unsigned pdo, co_frame_t *f)
{
    (void)pdo;
    gsh_chan_t *c = chan_of(n);
    /* Fixed 8-byte layout (manual, section 11 'PDO communication'):
     * position, angle and alarm word from the mapping, then the counter
     * and the checksum, which only the frame knows (the mapped
     * 0x2111/0x2112 give the last frame's). */
    f->data[6] = c->counter;
    f->data[7] = gsh_pdo_checksum(f->data);
    c->sent_counter = c->counter;
    c->sent_checksum = f->data[7];
    c->counter++; /* built only to be sent: type 254 is fixed */
}

/* Decision: a corrupt stored set gives the factory defaults (the manual
 * does not say). The GSH-A sends no EMCY at all (its manual has no EMCY
 * object, and 0x1001 is "Always 0") and describes no LED, so the node
 * itself reports nothing; the board logs it (the Linux program does). */
const co_node_ops_t gsh_ops = {
    .reset = gsh_reset,
    .tpdo_fill = gsh_tpdo_fill,
};

void gsh_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    gsh_dev_t *d = mem;
    memset(d, 0, sizeof(*d));
    static const co_node_cfg_t *const cfgs[2] = {&gsh_ch1_cfg, &gsh_ch2_cfg};
    unsigned nchan = CO_CHECK(p->nodes <= 2u) ? p->nodes : 2u; /* cfgs[]: two at most */
    d->nchan = nchan;
    for (unsigned i = 0; i < nchan; i++) {
        gsh_chan_t *c = &d->ch[i];
        c->incl_para.resolution = 100; /* 0x6800: 0.1 deg */
        /* Channel 2 counts backwards ("backward direction", manual section
         * 11): A2 = (3600 - A1) mod 3600. */
        c->incl_para.op[0] = (uint8_t)(i == 0u ? 0u : CO_INCL_OP_INVERT);
        co_incl_init(&c->incl, &c->incl_para, 1, 0, true);
        c->incl.circular = true;
        c->incl.shift = 0; /* the manual describes no filter */
        void *const ram[CO_CLS_COUNT] = {[CO_CLS_PARA] = &c->para, [CO_CLS_LSS] = &c->lss};
        co_node_init(&c->node, cfgs[i], ports[i], c, ram, i * CO_STORE_NVM_SIZE);
        nodes[i] = &c->node;
    }
}

void gsh_sample(void *mem, const int32_t values[], uint32_t faults)
{
    gsh_dev_t *d = mem;
    int32_t len_mm = co_div_round(values[GSH_IN_LENGTH], 1000);
    int32_t field = co_div_round(values[GSH_IN_FIELD], 1000);
    uint16_t alarms = 0;
    if (len_mm < 0) {
        alarms |= GSH_ALARM_UNDER_EXTENSION;
        len_mm = 0;
    } else if (len_mm > GSH_STROKE_MM) {
        alarms |= GSH_ALARM_OVER_EXTENSION;
        len_mm = GSH_STROKE_MM;
    }
    if (field < GSH_FIELD_LOW_PCT) {
        alarms |= GSH_ALARM_FIELD_LOW;
    } else if (field > GSH_FIELD_HIGH_PCT) {
        alarms |= GSH_ALARM_FIELD_HIGH;
    }
    if ((faults & GSH_FAULT_EXTENSION_ELEMENT) != 0u) {
        alarms |= GSH_ALARM_EXTENSION_ELEMENT;
    }
    if ((faults & GSH_FAULT_TILT_ELEMENT) != 0u) {
        alarms |= GSH_ALARM_TILT_ELEMENT;
    }
    int32_t angle[2] = {values[GSH_IN_ANGLE], 0};
    for (unsigned i = 0; i < d->nchan; i++) {
        gsh_chan_t *c = &d->ch[i];
        /* Decision: channel 2's "backward direction" is stroke - length;
         * the manual defines it for the angle only. */
        c->position_mm = (uint16_t)(i == 0u ? len_mm : GSH_STROKE_MM - len_mm);
        c->alarms = alarms;
        co_incl_sample(&c->incl, angle);
    }
}
