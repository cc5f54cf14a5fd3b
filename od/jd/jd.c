/*
 * jd.c - behaviour of the ifm JD1xxx / JD2xxx (shared/specs/ifm-jd.md).
 * Integer arithmetic only (the target MCUs have no FPU).
 */
#include "jd.h"

#include <string.h>

#include "co_incl.h"

#define TURN 360000 /* mdeg */

static jd_dev_t *dev_of(co_node_t *n)
{
    return co_node_app(n);
}

/* sin(deg) x 1000, one entry a degree over a quarter turn. */
static const int16_t sin_q[91] = {
    0,   17,  35,  52,  70,  87,  105, 122, 139, 156, 174, 191, 208, 225, 242, 259,
    276, 292, 309, 326, 342, 358, 375, 391, 407, 423, 438, 454, 469, 485, 500, 515,
    530, 545, 559, 574, 588, 602, 616, 629, 643, 656, 669, 682, 695, 707, 719, 731,
    743, 755, 766, 777, 788, 799, 809, 819, 829, 839, 848, 857, 866, 875, 883, 891,
    899, 906, 914, 921, 927, 934, 940, 946, 951, 956, 961, 966, 970, 974, 978, 982,
    985, 988, 990, 993, 995, 996, 998, 999, 999, 1000, 1000};

static int32_t wrap180(int32_t a)
{
    a %= TURN;
    if (a >= TURN / 2) {
        a -= TURN;
    } else if (a < -TURN / 2) {
        a += TURN;
    }
    return a;
}

/* sin of an angle in mdeg, x 1000, linear between whole degrees. */
static int32_t isin(int32_t mdeg)
{
    int32_t a = wrap180(mdeg);
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

/* Non-negative a mod m (m > 0). Within one turn either side, which is
 * where a slope's terms are (normalised offsets, a measured angle of
 * 0..N), without a division: the JD1's slope read (every PDO) divided
 * three times before. */
static int32_t mod_pos(int32_t a, int32_t m)
{
    if (a >= -m && a < m) {
        return a < 0 ? a + m : a;
    }
    int32_t r = a % m;
    return r < 0 ? r + m : r;
}

/* The angles in resolution units and one turn in them: divided once per
 * sample (jd_sample) and once per change of 0x6000, never per read. A
 * SYNC with both JD2 TPDOs read four slopes and divided four times: 1,284
 * of its 2,465 instructions on the Cortex-M0 went to the division helper;
 * with the division here the SYNC took 1,117 (issue 11).
 * The resolution the figures hold is kept with them: 0x6000 reaches the
 * parameters through its hook, a restore and a load alike, so a read
 * compares rather than relies on every writer telling us. */
static void remeasure(jd_dev_t *d)
{
    int32_t res = (int32_t)d->para.resolution;
    d->meas_res = d->para.resolution;
    d->meas_turn = TURN / res;
    for (unsigned a = 0; a < 2u; a++) {
        d->meas[a] = co_div_round(d->raw[a], res); /* rounded (R57) */
    }
}

/* One turn in resolution units (JD1 wrap). */
static int32_t turn_lsb(jd_dev_t *d)
{
    if (d->meas_res != d->para.resolution) {
        remeasure(d);
    }
    return d->meas_turn;
}

/* Physical angle in resolution units, rounded (R57). */
static int32_t measure(jd_dev_t *d, unsigned axis)
{
    if (d->meas_res != d->para.resolution) {
        remeasure(d);
    }
    return d->meas[axis];
}

/* JD1 offsets live in (-N/2, N/2] (R54). */
static int32_t norm_offset(jd_dev_t *d, int32_t off)
{
    if (d->axes != 1u) {
        return off;
    }
    int32_t n = turn_lsb(d);
    int32_t r = mod_pos(off, n);
    return r > n / 2 ? r - n : r;
}

static int32_t clamp16(int32_t v)
{
    return v > INT16_MAX ? INT16_MAX : (v < INT16_MIN ? INT16_MIN : v);
}

static int32_t clamp32(int64_t v)
{
    return v > INT32_MAX ? INT32_MAX : (v < INT32_MIN ? INT32_MIN : (int32_t)v);
}

/* The largest differential offset, in resolution units: JD1 (-N/2, N/2]
 * (6114h: -17999..18000 at 0.01 deg, L1783-1791), JD2 +-90 deg (the
 * spec's recommendation; the manual gives none). Beyond: 0x06090030. */
static bool diff_ok(jd_dev_t *d, int32_t v)
{
    if (d->axes == 1u) {
        int32_t half = turn_lsb(d) / 2;
        return v > -half && v <= half;
    }
    int32_t lim = 90000 / (int32_t)d->para.resolution;
    return v >= -lim && v <= lim;
}

/* The slope of one axis, 16- or 32-bit flavour (R51, R53, R54, R56). */
static int32_t slope(jd_dev_t *d, unsigned axis, bool wide)
{
    if (axis >= d->axes) {
        return 0; /* JD1: 6020h / 6120h read 0 (L1671) */
    }
    const jd_para_t *p = &d->para;
    uint8_t op = wide ? p->op32[axis] : p->op16[axis];
    int32_t v = measure(d, axis);
    if ((op & CO_INCL_OP_INVERT) != 0u) {
        v = -v;
    }
    int32_t off = 0;
    int32_t diff = 0;
    if ((op & CO_INCL_OP_SCALING) != 0u) {
        off = wide ? p->off32[axis] : p->off16[axis];
        diff = wide ? p->diff32[axis] : p->diff16[axis];
    }
    if (d->axes == 1u) {
        /* 0..N-1: each term reduced first, so the sum never overflows
         * whatever a stored offset holds (N <= 36000). */
        int32_t n = turn_lsb(d);
        int32_t sum = mod_pos(v, n) + mod_pos(off, n) + mod_pos(diff, n);
        while (sum >= n) { /* below 3N: at most two passes, no division */
            sum -= n;
        }
        return sum;
    }
    /* Saturated, never wrapped: the output stops at the type's end (R53:
     * "clamp only to the data type's range"). */
    int32_t sum = clamp32((int64_t)v + off + diff);
    return wide ? sum : clamp16(sum);
}

/* ---- dictionary hooks ------------------------------------------------ */

co_res_t jd_read_slope(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    unsigned axis = (e->index & 0x00F0u) == 0x0020u ? 1u : 0u;
    bool wide = (e->index & 0x0100u) != 0u;
    *v = (uint32_t)slope(dev_of(n), axis, wide);
    return CO_OK;
}

co_res_t jd_read_preset(co_node_t *n, const co_od_entry_t *e, uint32_t *v)
{
    /* 0x2600/0x2601 and 0x6012/0x6022 show the one preset (L1121, L1141). */
    unsigned axis = (e->index == 0x2601u || e->index == 0x6022u) ? 1u : 0u;
    *v = (uint32_t)dev_of(n)->para.preset[axis];
    return CO_OK;
}

co_res_t jd_write_preset(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    jd_dev_t *d = dev_of(n);
    unsigned axis = (e->index == 0x2601u || e->index == 0x6022u || e->index == 0x6122u) ? 1u : 0u;
    int32_t p = e->size == 2u ? (int32_t)(int16_t)v : (int32_t)v;
    int32_t lim = 90000 / (int32_t)d->para.resolution;
    if (d->axes == 1u) {
        if (e->size == 2u) {
            p = (int32_t)(uint16_t)v; /* 0..N-1, an unsigned bit pattern (2600h) */
        }
        if (p < 0 || p >= turn_lsb(d)) {
            return CO_E_VAL;
        }
    } else if (p < -lim || p > lim) {
        return CO_E_VAL; /* +-90 deg (C7, C8) */
    }
    if (co_od_checking(n)) {
        return CO_OK;
    }
    int32_t m = measure(d, axis);
    int32_t m16 = (d->para.op16[axis] & CO_INCL_OP_INVERT) != 0u ? -m : m;
    int32_t m32 = (d->para.op32[axis] & CO_INCL_OP_INVERT) != 0u ? -m : m;
    d->para.preset[axis] = p;
    d->para.off16[axis] = (int16_t)clamp16(norm_offset(d, p - m16));
    d->para.off32[axis] = norm_offset(d, p - m32);
    return CO_OK;
}

co_res_t jd_write_diff(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    int32_t x = e->size == 2u ? (int32_t)(int16_t)v : (int32_t)v;
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
    return clamp32((int64_t)v * k);
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
    /* Every preset and offset follows into the new unit (R55). */
    for (unsigned a = 0; a < 2u; a++) {
        p->preset[a] = rescale(p->preset[a], old, now);
        p->off16[a] = (int16_t)clamp16(rescale(p->off16[a], old, now));
        p->off32[a] = rescale(p->off32[a], old, now);
        p->diff16[a] = (int16_t)clamp16(rescale(p->diff16[a], old, now));
        p->diff32[a] = rescale(p->diff32[a], old, now);
    }
    p->resolution = (uint16_t)v;
    return CO_OK;
}

co_res_t jd_write_event(co_node_t *n, const co_od_entry_t *e, uint32_t v)
{
    /* 0x1800:05, 0x1801:05 and 0x2200 are one value (R20). */
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
        return CO_E_VAL; /* only while the PDO is invalid (R21) */
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
        co_node_request_reset(n, CO_RESET_NODE); /* after the confirmation (R38) */
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
        co_node_set_id(n, (uint8_t)(d->para.node_number + 1u)); /* 3000h + 1 (R41) */
    }
    if (kind == CO_RESET_NODE) {
        co_node_set_bitrate(n, d->para.bitrate); /* 3001h, read at power-on and reset node */
    }
    co_node_set_autostart(n, d->para.autostart == 1u); /* 3005h, after every boot-up (C33) */
}

/* CiA 305 bit-timing index to 0x3001 code (R46): 20k..1M are codes 0..7. */
static const uint8_t lss_to_code[8] = {7, 6, 5, 4, 3, 0xFF, 1, 0};

static uint8_t jd_lss_store(co_node_t *n, uint8_t id, uint8_t br)
{
    jd_dev_t *d = dev_of(n);
    if (id >= 1u && id <= 127u) {
        d->para.node_number = (uint8_t)(id - 1u);
    }
    if (br < 8u && lss_to_code[br] != 0xFFu) {
        d->para.bitrate = lss_to_code[br];
    }
    /* 3000h/3001h are manufacturer parameters (R47). */
    return co_store_save_group(n, CO_CLS_PARA, 0x2000, 0x5FFF, false) == CO_OK ? 0u : 2u;
}

static void jd_leds(co_node_t *n, co_led_pattern_t *g, co_led_pattern_t *r)
{
    /* Green: on in pre-operational, flashing in operational (C20). */
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
        *r = CO_LED_BLINK; /* general configuration error (R11) */
    }
    if (*r != CO_LED_OFF) {
        *g = CO_LED_OFF; /* "only red is shown" (L376-378) */
    }
}

static uint32_t jd_poll(co_node_t *n, uint32_t now)
{
    (void)now;
    /* A broken stored set: defaults and the red LED blinking (R11), and
     * CiA 301's EMCY 6300h, so that a master learns it too. */
    co_store_report_emcy(n);
    return CO_NEVER;
}

const co_node_ops_t jd_ops = {
    .reset = jd_reset,
    .poll = jd_poll,
    .can_state = co_emcy_can_state, /* 8120h, 8140h (R34) */
    .lss_store = jd_lss_store,
    .leds = jd_leds,
};

void jd_create(const product_t *p, void *mem, void *const ports[], co_node_t *nodes[])
{
    jd_dev_t *d = mem;
    memset(d, 0, sizeof(*d));
    d->axes = *(const uint8_t *)p->variant;
    void *const ram[CO_CLS_COUNT] = {NULL, NULL, &d->para, NULL};
    co_node_init(&d->node, p->cfg, ports[0], d, ram, 0);
    nodes[0] = &d->node;
}

/* Moving average over the last para.maf samples (R59), on continuous angles. */
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
        int32_t t = wrap180(values[a]);
        if (d->axes == 2u) {
            /* +-90 deg, folded back beyond: the output of a gravity sensor (R49). */
            if (t > 90000) {
                t = 180000 - t;
            } else if (t < -90000) {
                t = -180000 - t;
            }
        } else {
            t = mod_pos(t, TURN);
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
        int32_t shift = d->raw[0] - mod_pos(d->raw[0], TURN);
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
    d->meas_res = 0;
    if (d->para.resolution != 0u) {
        remeasure(d);
    }
    /* Rates (0.1 deg/s) from the 5 ms sample period, accelerations (mg). */
    int32_t x = values[0];
    int32_t y = d->axes == 2u ? values[1] : 0;
    for (unsigned a = 0; a < 2u; a++) {
        int32_t now = a == 0u ? x : y;
        int32_t rate = wrap180(now - d->prev[a]) * 2; /* mdeg per 5 ms -> 0.1 deg/s */
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
    /* Types 254/255: a PDO whenever its data changed (R18), within the inhibit time. */
    for (unsigned n = 0; n < 2u; n++) {
        if (co_tpdo_changed(&d->node, n)) {
            co_tpdo_event(&d->node, n);
        }
    }
    co_node_wake(&d->node); /* every product wakes its nodes on a sample */
}
