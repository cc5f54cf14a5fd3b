/*
 * jd.c - behaviour of the ifm JD1xxx / JD2xxx, after their operating
 * instructions ("the manual", cited by section). Where the manual is
 * silent, the choice is written down as a decision next to the code.
 * Integer arithmetic only (the target MCUs have no FPU).
 * The CiA 410 arithmetic (slopes, presets, wrap, measured angles) is the
 * shared module's (co_incl.h); here is what the JD's objects and manual
 * add: a 16- and a 32-bit slope object per axis with one preset, the
 * JD1's unsigned 16-bit preset, the ranges, the rescale of 0x6000, the
 * moving average (3100h), the fold at +-90 deg.
 */
#include "jd.h"

#include <string.h>

#define TURN CO_INCL_TURN_MDEG

static jd_dev_t *dev_of(co_node_t *n)
{
    return co_node_app(n);
}

/* sin(deg) x 1000, one entry a degree over a quarter turn. */
static const int16_t sin_q[91] = {
    0,   17,  35,  52,  70,  87,  105, 122, 139, 156, 174, 191, 208, 225,  242, 259, 276, 292, 309,
    326, 342, 358, 375, 391, 407, 423, 438, 454, 469, 485, 500, 515, 530,  545, 559, 574, 588, 602,
    616, 629, 643, 656, 669, 682, 695, 707, 719, 731, 743, 755, 766, 777,  788, 799, 809, 819, 829,
    839, 848, 857, 866, 875, 883, 891, 899, 906, 914, 921, 927, 934, 940,  946, 951, 956, 961, 966,
    970, 974, 978, 982, 985, 988, 990, 993, 995, 996, 998, 999, 999, 1000, 1000};

/* sin of an angle in mdeg, x 1000, linear between whole degrees. */
static int32_t isin(int32_t mdeg)
{
    int32_t a = co_incl_wrap180(mdeg);
    int32_t sign = a < 0 ? -1 : 1;
    a = a < 0 ? -a : a;
    if (a > 90000) {
        a = 180000 - a;
    }
    int32_t d = a / 1000;
    int32_t f = a % 1000;
    int32_t lo = sin_q[d];
    int32_t hi = sin_q[d < 90 ? d + 1 : 90];
    return sign * (lo + (hi - lo) * f / 1000);
}

/* The angles in resolution units and one turn in them at the present
 * 0x6000 (co_incl_meas_t: divided once per sample and once per change of
 * 0x6000, never per read; with a division per read a SYNC with both JD2
 * TPDOs spends half its time in the division helper). */
CO_INCL_INLINE const co_incl_meas_t *meas(jd_dev_t *d)
{
    return co_incl_meas_at(&d->meas, d->raw, d->para.resolution);
}

/* How the slope objects hold their values (co_incl_fit_t): JD1 modulo a
 * turn, 0..N-1, its offsets in (-N/2, N/2] (decision: the manual does not
 * say how the JD1 wraps); JD2 saturated to the object's type, never
 * wrapped (an offset shifts the output window: manual, section 13.2). */
CO_INCL_INLINE co_incl_fit_t fit(jd_dev_t *d, const co_incl_meas_t *c, bool wide)
{
    co_incl_fit_t f = {.turn = d->axes == 1u ? c->turn : 0, .wide = wide, .centred = true};
    return f;
}

/* The largest differential offset, in resolution units: JD1 (-N/2, N/2]
 * (6114h: -17999..18000 at 0.01 deg, manual section 9.46), JD2 +-90 deg
 * (decision: the manual gives none). Beyond: 0x06090030. */
static bool diff_ok(jd_dev_t *d, int32_t v)
{
    if (d->axes == 1u) {
        int32_t half = meas(d)->turn / 2;
        return v > -half && v <= half;
    }
    int32_t lim = 90000 / (int32_t)d->para.resolution;
    return v >= -lim && v <= lim;
}

/* The slope of one axis, 16- or 32-bit object (the manual's position
 * formula, sections 9.37 and 9.42; 6110h/6120h as 6010h/6020h): each
 * has its own operating parameter, offset and differential offset; c is
 * meas(d). */
CO_INCL_INLINE int32_t slope(jd_dev_t *d, const co_incl_meas_t *c, unsigned axis, bool wide)
{
    if (axis >= d->axes) {
        return 0; /* JD1: 6020h / 6120h read 0 (manual, section 9.41) */
    }
    int32_t m = c->m[axis];
    co_incl_fit_t f = fit(d, c, wide);
    const jd_para_t *p = &d->para;
    uint8_t op = wide ? p->op32[axis] : p->op16[axis];
    if ((op & CO_INCL_OP_SCALING) == 0u) {
        /* co_incl_output does not read the offsets then: not loaded
         * either (gcc loads arguments first, a twentieth of the JD2's
         * SYNC on the Cortex-M0). */
        return co_incl_output(m, op, 0, 0, f);
    }
    if (wide) {
        return co_incl_output(m, op, p->off32[axis], p->diff32[axis], f);
    }
    return co_incl_output(m, op, p->off16[axis], p->diff16[axis], f);
}

/* ---- dictionary hooks ------------------------------------------------ */

co_res_t jd_read_slope(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    jd_dev_t *d = dev_of(n);
    /* The angles first, while little is live across the rare remeasure
     * (a few Cortex-M0 instructions less on each JD2 SYNC). */
    const co_incl_meas_t *c = meas(d);
    unsigned axis = (e->index & 0x00F0u) == 0x0020u ? 1u : 0u;
    bool wide = (e->index & 0x0100u) != 0u;
    *v = (uint32_t)slope(d, c, axis, wide);
    return CO_OK;
}

co_res_t jd_read_preset(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    /* 0x2600/0x2601 and 0x6012/0x6022 show the one preset (manual,
     * sections 9.18 and 9.19). */
    unsigned axis = (e->index == 0x2601u || e->index == 0x6022u) ? 1u : 0u;
    *v = (uint32_t)dev_of(n)->para.preset[axis];
    return CO_OK;
}

co_res_t jd_write_preset(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    jd_dev_t *d = dev_of(n);
    unsigned axis = (e->index == 0x2601u || e->index == 0x6022u || e->index == 0x6122u) ? 1u : 0u;
    int32_t p = (int32_t)v; /* INTEGER16 comes sign-extended, as co_od_get gives it */
    int32_t lim = 90000 / (int32_t)d->para.resolution;
    if (d->axes == 1u) {
        if (e->size == 2u) {
            p = (int32_t)(uint16_t)v; /* 0..N-1, an unsigned bit pattern (2600h) */
        }
        if (p < 0 || p >= meas(d)->turn) {
            return CO_E_VAL;
        }
    } else if (p < -lim || p > lim) {
        /* +-90 deg: the JD2's range (the 6022h table's +-80 is taken for a
         * misprint, and 6012h's lacks the 0.01 deg row) */
        return CO_E_VAL;
    }
    if (co_od_checking(n)) {
        return CO_OK;
    }
    /* One preset, an offset per object: P - s*m with the object's own
     * sign (manual, sections 9.38 and 9.39.1); the differential offset
     * stays out of it. */
    const co_incl_meas_t *c = meas(d);
    d->para.preset[axis] = p;
    d->para.off16[axis] = (int16_t)co_incl_preset_offset(p, c->m[axis], d->para.op16[axis], 0,
                                                         fit(d, c, false));
    d->para.off32[axis] = co_incl_preset_offset(p, c->m[axis], d->para.op32[axis], 0,
                                                fit(d, c, true));
    return CO_OK;
}

co_res_t jd_write_diff(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    int32_t x = (int32_t)v; /* INTEGER16 comes sign-extended, as co_od_get gives it */
    if (!diff_ok(dev_of(n), x)) {
        return CO_E_VAL;
    }
    return co_od_store(n, e, v);
}

/* v in unit old, rounded into unit now (both 10, 100 or 1000): a division
 * by 10 or 100, or a saturated multiplication, so that any stored value
 * (offsets are not written by SDO) gives a defined result; no 64-bit
 * division on the MCU. */
static int32_t rescale(int32_t v, int32_t old, int32_t now)
{
    if (now >= old) {
        return co_div_round(v, now / old); /* any v: see co_div_round */
    }
    int32_t k = old / now;
    return co_incl_saturate((int64_t)v * k, true);
}

co_res_t jd_write_resolution(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    (void)e;
    if (v != 10u && v != 100u && v != 1000u) {
        return CO_E_VAL;
    }
    if (co_od_checking(n)) {
        return CO_OK;
    }
    jd_para_t *p = &dev_of(n)->para;
    int32_t old = (int32_t)p->resolution;
    int32_t now = (int32_t)v;
    /* Every preset and offset follows into the new unit (the manual's
     * "side effects" of a resolution change, section 9.37). */
    for (unsigned a = 0; a < 2u; a++) {
        p->preset[a] = rescale(p->preset[a], old, now);
        p->off16[a] = (int16_t)co_incl_saturate(rescale(p->off16[a], old, now), false);
        p->off32[a] = rescale(p->off32[a], old, now);
        p->diff16[a] = (int16_t)co_incl_saturate(rescale(p->diff16[a], old, now), false);
        p->diff32[a] = rescale(p->diff32[a], old, now);
    }
    p->resolution = (uint16_t)v;
    return CO_OK;
}

co_res_t jd_write_event(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    /* 0x1800:05, 0x1801:05 and 0x2200 are one value (manual, sections
     * 8.9.5, 8.9.6 and 9.16). */
    co_res_t r = co_od_store(n, e, v);
    co_tpdo_reconfig(n, 0);
    co_tpdo_reconfig(n, 1);
    return r;
}

co_res_t jd_write_inhibit(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    if (co_od_checking(n)) {
        return CO_OK; /* any value; the "only while invalid" rule is of sequence */
    }
    const co_od_entry_t *cob = co_node_entry(n, e->index, 1);
    uint32_t c = 0;
    (void)co_od_get(n, cob, &c);
    if ((c & 0x80000000u) == 0u) {
        return CO_E_VAL; /* only while the PDO is invalid (manual, section 8.9.4) */
    }
    return co_tpdo_write_comm(n, e, v);
}

co_res_t jd_write_save_reset(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    (void)e;
    if (v != JD_SAVE_RESET_CODE) {
        return CO_E_STORE;
    }
    co_res_t r = co_store_save(n, CO_CLS_PARA);
    if (r == CO_OK) {
        /* after the confirmation (manual, section 9.17) */
        co_node_request_reset(n, CO_RESET_NODE);
    }
    return r;
}

co_res_t jd_read_sensor(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    jd_dev_t *d = dev_of(n);
    if (e->index == 0x3411u) {
        *v = d->temp;
    } else if (e->index <= 0x3402u) {
        *v = (uint32_t)(int32_t)d->gyro[e->index - 0x3400u];
    } else {
        *v = (uint32_t)(int32_t)d->accel[e->index - 0x3403u];
    }
    return CO_OK;
}

/* ---- node ops --------------------------------------------------------- */

static void jd_reset(co_node_t *n, co_reset_t kind)
{
    jd_dev_t *d = dev_of(n);
    if (kind == CO_RESET_NODE && d->para.node_number <= 126u) {
        /* 3000h + 1 (manual, section 9.21) */
        co_node_set_id(n, (uint8_t)(d->para.node_number + 1u));
    }
    if (kind == CO_RESET_NODE) {
        co_node_set_bitrate(n, d->para.bitrate); /* 3001h, read at power-on and reset node */
    }
    /* 3005h. Decision: after every boot-up, NMT resets included (the
     * manual says "after power up"; every reset boots the same way). */
    co_node_set_autostart(n, d->para.autostart == 1u);
}

/* CiA 305 bit-timing index to 0x3001 code: 20k..1M are codes 0..7. */
static const uint8_t lss_to_code[8] = {7, 6, 5, 4, 3, 0xFF, 1, 0};

static uint8_t jd_lss_store(co_node_t *n, uint8_t id, uint8_t br)
{
    jd_dev_t *d = dev_of(n);
    if (id >= 1u && id <= CO_NODE_ID_MAX) {
        d->para.node_number = (uint8_t)(id - 1u);
    }
    if (br < 8u && lss_to_code[br] != 0xFFu) {
        d->para.bitrate = lss_to_code[br];
    }
    /* Decision: LSS "store" saves 3000h/3001h, the manufacturer
     * parameters that hold the node-ID and bit rate. */
    return co_store_save_group(n, CO_CLS_PARA, 0x2000, 0x5FFF, false) == CO_OK ? 0u : 2u;
}

static void jd_leds(co_node_t *n, co_led_pattern_t *g, co_led_pattern_t *r)
{
    /* Green: on in pre-operational, flashing in operational, as the
     * manual's LED table says (section 7; CiA 303-3 has it the other way). */
    if (co_node_nmt_state(n) == CO_NMT_PREOP) {
        *g = CO_LED_ON;
    } else if (co_node_nmt_state(n) == CO_NMT_OPERATIONAL) {
        *g = CO_LED_BLINK;
    }
    if (co_node_can_state(n) == CO_CAN_BUSOFF) {
        *r = CO_LED_ON;
    } else if (co_emcy_active(n, CO_EMCY_LIFE_GUARD)) {
        *r = CO_LED_FLASH2; /* guard or heartbeat event */
    } else if (co_node_store_status(n, CO_CLS_PARA) == CO_STORE_CORRUPT) {
        *r = CO_LED_BLINK; /* "general configuration error" (manual, section 7) */
    }
    if (*r != CO_LED_OFF) {
        *g = CO_LED_OFF; /* "only red is shown" (manual, section 7) */
    }
}

static uint32_t jd_poll(co_node_t *n, uint32_t now)
{
    (void)now;
    /* Decision: a broken stored set gives the defaults and the red LED
     * blinking ("general configuration error", manual section 7), and
     * CiA 301's EMCY 6300h, so that a master learns it too. */
    co_store_report_emcy(n);
    return CO_NEVER;
}

const co_node_ops_t jd_ops = {
    .reset = jd_reset,
    .poll = jd_poll,
    .can_state = co_emcy_can_state, /* 8120h, 8140h (CiA 301; the manual lists no codes) */
    .lss_store = jd_lss_store,
    .leds = jd_leds,
};

void jd_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    jd_dev_t *d = mem;
    memset(d, 0, sizeof(*d));
    d->axes = *(const uint8_t *)p->variant;
    void *const ram[CO_CLS_COUNT] = {[CO_CLS_PARA] = &d->para};
    co_node_init(&d->node, p->cfg, ports[0], d, ram, 0);
    nodes[0] = &d->node;
}

/* Moving average over the last para.maf samples (manual, section 9.25),
 * on continuous angles. */
static void maf(jd_dev_t *d, const int32_t in[2])
{
    uint16_t len = d->para.maf <= JD_MAF_MAX ? d->para.maf : (uint16_t)JD_MAF_MAX;
    if (len != d->maf_len) {
        d->maf_len = len;
        d->maf_pos = 0;
        d->maf_fill = 0;
        d->maf_sum[0] = d->maf_sum[1] = 0;
    }
    for (unsigned a = 0; a < d->axes; a++) {
        if (len == 0u) {
            d->raw[a] = in[a];
            continue;
        }
        if (d->maf_fill == len) {
            d->maf_sum[a] -= d->maf_buf[a][d->maf_pos];
        }
        d->maf_buf[a][d->maf_pos] = in[a];
        d->maf_sum[a] += in[a];
        uint16_t n = d->maf_fill < len ? (uint16_t)(d->maf_fill + 1u) : len;
        d->raw[a] = d->maf_sum[a] / (int32_t)n;
    }
    if (len != 0u) {
        d->maf_pos = (uint16_t)((d->maf_pos + 1u) % len);
        if (d->maf_fill < len) {
            d->maf_fill++;
        }
    }
}

void jd_sample(void *mem, const int32_t values[], uint32_t faults)
{
    (void)faults;
    jd_dev_t *d = mem;
    int32_t in[2] = {0, 0};
    for (unsigned a = 0; a < d->axes; a++) {
        int32_t t = co_incl_wrap180(values[a]);
        if (d->axes == 2u) {
            /* +-90 deg, folded back beyond: the output of a gravity sensor
             * (manual, section 13.2). */
            if (t > 90000) {
                t = 180000 - t;
            } else if (t < -90000) {
                t = -180000 - t;
            }
        } else {
            t = co_incl_mod(t, TURN);
            /* Average across 0/360 on the side of the last value. */
            if (d->maf_fill > 0u && t - d->raw[0] > TURN / 2) {
                t -= TURN;
            } else if (d->maf_fill > 0u && d->raw[0] - t > TURN / 2) {
                t += TURN;
            }
        }
        in[a] = t;
    }
    maf(d, in);
    if (d->axes == 1u) {
        /* Back into 0..360 deg, and the averaged inputs with it: the next
         * input is put on the side of raw[0], so the window must stay in
         * raw[0]'s frame (else a turn's worth of offset enters the mean and
         * sticks: 1 deg read as 271 after crossing 0). Inputs then stay
         * within half a turn of [0, 360): the sum is bounded. */
        int32_t shift = d->raw[0] - co_incl_mod(d->raw[0], TURN);
        if (shift != 0) {
            for (unsigned i = 0; i < d->maf_fill; i++) {
                d->maf_buf[0][i] -= shift;
            }
            d->maf_sum[0] -= shift * (int32_t)d->maf_fill;
            d->raw[0] -= shift;
        }
    }
    /* A board samples once before the node's first reset loads the
     * parameters (resolution 0 then): the first read after it computes. */
    co_incl_remeasure(&d->meas, d->raw, d->para.resolution);
    /* Rates (0.1 deg/s) from the 5 ms sample period, accelerations (mg). */
    int32_t x = values[0];
    int32_t y = d->axes == 2u ? values[1] : 0;
    for (unsigned a = 0; a < 2u; a++) {
        int32_t now = a == 0u ? x : y;
        int32_t rate = co_incl_wrap180(now - d->prev[a]) * 2; /* mdeg per 5 ms -> 0.1 deg/s */
        rate = rate > 5000 ? 5000 : (rate < -5000 ? -5000 : rate);
        d->prev[a] = now;
        if (d->axes == 2u) {
            d->gyro[a] = (int16_t)rate;
        } else if (a == 0u) {
            d->gyro[2] = (int16_t)rate; /* JD1 turns about Z */
        }
    }
    if (d->axes == 2u) {
        d->accel[0] = (int16_t)isin(x);
        d->accel[1] = (int16_t)isin(y);
        d->accel[2] = (int16_t)(isin(x + 90000) * isin(y + 90000) / 1000);
    } else {
        d->accel[0] = (int16_t)isin(x);
        d->accel[1] = (int16_t)(-isin(x + 90000));
        d->accel[2] = 0;
    }
    int32_t temp = values[d->axes]; /* the input after the angles: degC x 1000 */
    d->temp = (uint16_t)(int16_t)co_div_round(temp, 100);
    /* Types 254/255: "Send PDO on event" (manual, section 8.9.3); the
     * event is a change of its data (decision), within the inhibit time. */
    for (unsigned n = 0; n < 2u; n++) {
        if (co_tpdo_changed(&d->node, n)) {
            co_tpdo_event(&d->node, n); /* wakes the node */
        }
    }
}
