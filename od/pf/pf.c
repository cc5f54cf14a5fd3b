/*
 * pf.c - behaviour of the Pepperl+Fuchs INX360D / INY360D.
 *
 * After the INX360D/INY360D-F99-B16-V15 manual ("the manual", cited by
 * section). Its object chapter (section 8) is missing from the edition at
 * hand, so the dictionary is inferred from the other chapters; where the
 * manual is silent the choice is written down as a decision.
 */
#include "pf.h"

#include <string.h>

static pf_dev_t *dev_of(co_node_t *n)
{
    return co_node_app(n);
}

co_res_t pf_write_bitrate(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    /* 01h 125k, 02h 250k, 04h 500k, 08h 1M; others "not adopted" (manual,
     * section 6.3). */
    if (v != PF_BR_125K && v != PF_BR_250K && v != PF_BR_500K && v != PF_BR_1M) {
        return CO_E_VAL;
    }
    return co_od_store(n, e, v);
}

co_res_t pf_write_resolution(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    (void)n;
    (void)e;
    return v == 100u ? CO_OK : CO_E_VAL; /* fixed 0.1 deg (manual, section 7.3) */
}

co_res_t pf_write_preset(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    /* Zero point: the output equals the preset at once when scaling is on
     * (manual, section 7.3.2). */
    if (co_od_checking(n)) {
        return CO_OK;
    }
    co_incl_set_preset(&dev_of(n)->incl, e->index == 0x6012u ? 0u : 1u, (int16_t)v);
    return CO_OK;
}

co_res_t pf_read_slope(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    return co_incl_read(&dev_of(n)->incl, e->index == 0x6010u ? 0u : 1u, v);
}

static uint32_t pf_poll(co_node_t *n, uint32_t now)
{
    (void)now;
    pf_dev_t *d = dev_of(n);
    if (co_node_nmt_state(n) == CO_NMT_INIT || co_node_nmt_state(n) == CO_NMT_STOPPED) {
        return CO_NEVER; /* no EMCY in stopped: errors are raised when allowed */
    }
    /* Error register bits as the manual's only EMCY example (section
     * 7.2.1: 11h for 5010h); CiA 301's for the others. */
    (void)co_emcy_error(n, PF_EMCY_RANGE_X, CO_ER_COMM, (d->faults & PF_FAULT_RANGE_X) != 0u, NULL);
    if (d->incl.axes > 1u) {
        (void)co_emcy_error(n, PF_EMCY_RANGE_Y, CO_ER_COMM, (d->faults & PF_FAULT_RANGE_Y) != 0u,
                            NULL);
    }
    (void)co_emcy_error(n, CO_EMCY_VOLTAGE_LOW, CO_ER_VOLTAGE,
                        (d->faults & PF_FAULT_UNDERVOLTAGE) != 0u, NULL);
    co_store_report_emcy(n); /* 6300h: a corrupt stored set (decision, CiA 301) */
    return CO_NEVER;
}

static void pf_leds(co_node_t *n, co_led_pattern_t *run, co_led_pattern_t *err)
{
    /* run (yellow) follows the NMT state; err per the manual's table (section 5.3):
     * bus-off / undervoltage on, EEPROM error 2x flash, warning 1x flash. */
    pf_dev_t *d = dev_of(n);
    bool undervoltage = (d->faults & PF_FAULT_UNDERVOLTAGE) != 0u;
    if (co_node_can_state(n) == CO_CAN_BUSOFF || undervoltage) {
        *run = CO_LED_OFF;
        *err = CO_LED_ON;
    } else if (co_emcy_active(n, CO_EMCY_DATA_SET)) {
        *err = CO_LED_FLASH2;
    } else if (co_emcy_active(n, PF_EMCY_RANGE_X) || co_emcy_active(n, PF_EMCY_RANGE_Y)) {
        *err = CO_LED_FLASH1;
    }
}

/* A stored set that failed its checksum stays reported (6300h) until a
 * good store (decision; the manual gives no reaction to it): the poll
 * re-evaluates the error table every time. */
const co_node_ops_t pf_ops = {
    .poll = pf_poll,
    .leds = pf_leds,
};

void pf_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    pf_dev_t *d = mem;
    const pf_variant_t *v = p->variant;
    memset(d, 0, sizeof(*d));
    co_incl_init(&d->incl, &d->para.incl, v->axes, 0, true);
    d->incl.circular = true;
    d->incl.shift = 0; /* no filter (the manual has none): one sample, one calculation */
    void *const ram[CO_CLS_COUNT] = {[CO_CLS_PARA] = &d->para, [CO_CLS_LSS] = &d->lss};
    co_node_init(&d->node, v->cfg, ports[0], d, ram, 0);
    nodes[0] = &d->node;
}

void pf_sample(void *mem, const int32_t values[], uint32_t faults)
{
    pf_dev_t *d = mem;
    d->faults = faults;
    co_incl_sample(&d->incl, values);
    co_node_wake(&d->node); /* faults may have changed: pf_poll looks */
    /* Type 254/255: a PDO "after each calculation" (manual, section
     * 7.1.1), within the inhibit time. */
    co_tpdo_event(&d->node, 0);
}
