/*
 * incl.c - CiA 410 inclinometer profile logic. See co_incl.h.
 */
#include "co_incl.h"

#include <string.h>

#define FULL_TURN_MDEG 360000

int32_t co_div_round(int32_t a, int32_t b)
{
    /* Half away from zero, in unsigned arithmetic so that no a overflows
     * (|a| <= 2^31, |a| + b/2 < 2^32). The result for INT32_MIN / 1 is
     * converted back modulo 2^32 (gcc and clang define it). */
    uint32_t m = a >= 0 ? (uint32_t)a : 0u - (uint32_t)a;
    uint32_t q = (m + (uint32_t)b / 2u) / (uint32_t)b;
    return a >= 0 ? (int32_t)q : (int32_t)(0u - q);
}

void co_incl_init(co_incl_t *incl, co_incl_para_t *p, uint8_t axes, int32_t limit_mdeg, bool wrap)
{
    memset(incl, 0, sizeof(*incl));
    incl->p = p;
    incl->axes = axes;
    incl->limit_mdeg = limit_mdeg;
    incl->wrap = wrap;
    incl->shift = co_filter_shift(0);
    co_filter_reset(&incl->f[0]);
    co_filter_reset(&incl->f[1]);
}

static void refresh(co_incl_t *incl);

/* Angle in [-180000, 180000) millidegrees. By whole turns, not by a
 * division: the angles here are a few turns at most (the filter's input
 * bound, co_filter.h), one or two passes; and no signed division helper
 * in an MCU image. */
static CO_NOINLINE int32_t wrap180(int32_t a)
{
    while (a >= FULL_TURN_MDEG / 2) {
        a -= FULL_TURN_MDEG;
    }
    while (a < -FULL_TURN_MDEG / 2) {
        a += FULL_TURN_MDEG;
    }
    return a;
}

void co_incl_sample(co_incl_t *incl, const int32_t mdeg[2])
{
    if (incl->fault) {
        return; /* no valid reading: the outputs hold their last value */
    }
    for (unsigned a = 0; a < incl->axes; a++) {
        int32_t x = mdeg[a];
        if (incl->wrap) {
            /* Feed the filter a continuous angle so that crossing +-180
             * does not sweep the output through zero. */
            int32_t *u = &incl->unwrapped[a];
            if (!incl->f[a].primed) {
                *u = wrap180(x);
            } else {
                *u += wrap180(x - *u);
            }
            int32_t y = co_filter_step(&incl->f[a], *u, incl->shift);
            int32_t w = wrap180(y);
            /* Keep the filter state near the [-180, 180) window. */
            if (w != y) {
                int32_t d = w - y;
                for (unsigned i = 0; i < CO_FILTER_STAGES; i++) {
                    incl->f[a].s[i] += d * 256;
                }
                *u += d;
            }
            incl->angle[a] = w;
            incl->beyond[a] = false;
            continue;
        }
        int32_t y = co_filter_step(&incl->f[a], x, incl->shift);
        int32_t lim = incl->limit_mdeg;
        incl->beyond[a] = lim != 0 && (y > lim || y < -lim);
        if (lim != 0 && y > lim) {
            y = lim;
        } else if (lim != 0 && y < -lim) {
            y = -lim;
        }
        incl->angle[a] = y;
    }
    refresh(incl);
}

bool co_incl_beyond(const co_incl_t *incl)
{
    return incl->beyond[0] || incl->beyond[1];
}

/* s*m: the measured angle in resolution units with the sign applied. */
static int32_t signed_measure(const co_incl_t *incl, unsigned axis)
{
    int32_t res = incl->p->resolution != 0u ? (int32_t)incl->p->resolution : 1;
    int32_t m = co_div_round(incl->angle[axis], res);
    return (incl->p->op[axis] & CO_INCL_OP_INVERT) != 0u ? -m : m;
}

#if CO_INCL_CIRCULAR
/* Non-negative a mod m (m > 0). */
static int32_t mod_pos(int32_t a, int32_t m)
{
    int32_t r = a % m;
    return r < 0 ? r + m : r;
}

/* Circular mode: one turn in LSB, and the direction-corrected angle a1. */
static int32_t turn(const co_incl_t *incl)
{
    int32_t res = incl->p->resolution != 0u ? (int32_t)incl->p->resolution : 1;
    return FULL_TURN_MDEG / res;
}

static int32_t circular_a1(const co_incl_t *incl, unsigned axis)
{
    int32_t res = incl->p->resolution != 0u ? (int32_t)incl->p->resolution : 1;
    int32_t f = turn(incl);
    int32_t m = mod_pos(co_div_round(mod_pos(incl->angle[axis], FULL_TURN_MDEG), res), f);
    return (incl->p->op[axis] & CO_INCL_OP_INVERT) != 0u ? mod_pos(f - m, f) : m;
}

#endif

static int16_t compute_slope(const co_incl_t *incl, unsigned axis)
{
#if CO_INCL_CIRCULAR
    if (incl->circular) {
        int32_t a1 = circular_a1(incl, axis);
        if ((incl->p->op[axis] & CO_INCL_OP_SCALING) != 0u) {
            a1 = mod_pos(a1 + incl->p->offset[axis] + incl->p->diff[axis], turn(incl));
        }
        return (int16_t)a1;
    }
#endif
    int32_t v = signed_measure(incl, axis);
    if ((incl->p->op[axis] & CO_INCL_OP_SCALING) != 0u) {
        v += incl->p->offset[axis] + incl->p->diff[axis];
    }
    if (v > INT16_MAX) {
        v = INT16_MAX;
    } else if (v < INT16_MIN) {
        v = INT16_MIN;
    }
    return (int16_t)v;
}

/* Recompute the outputs and remember the parameters they were made with. */
static void refresh(co_incl_t *incl)
{
    incl->seen = *incl->p;
    for (unsigned a = 0; a < incl->axes; a++) {
        incl->out[a] = compute_slope(incl, a);
    }
}

int16_t co_incl_refresh_slope(co_incl_t *incl, unsigned axis)
{
    if (!CO_CHECK(axis < CO_INCL_AXES)) {
        return 0;
    }
    refresh(incl);
    return incl->out[axis]; /* 0 on an axis the device lacks: never computed */
}

co_res_t co_incl_refresh_read(co_incl_t *incl, unsigned axis, uint32_t *v)
{
    if (axis >= incl->axes) {
        (void)CO_CHECK(axis < CO_INCL_AXES); /* no code in an image */
        *v = 0;
        return CO_OK;
    }
    *v = (uint32_t)(int32_t)co_incl_refresh_slope(incl, axis);
    return CO_OK;
}

co_res_t co_incl_set_resolution(co_incl_t *incl, uint16_t res)
{
    co_incl_para_t *p = incl->p;
    /* Both operating parameters are checked even on a single-axis device:
     * 0x6021 exists there too and the manuals require its bit. */
    if ((p->op[0] & CO_INCL_OP_SCALING) == 0u || (p->op[1] & CO_INCL_OP_SCALING) == 0u) {
        return CO_E_STATE;
    }
    if (res != p->resolution) {
        p->resolution = res;
        /* Presets, offsets and differential offsets: one run of int16_t. */
        _Static_assert(offsetof(co_incl_para_t, diff) + sizeof(p->diff) -
                               offsetof(co_incl_para_t, preset) ==
                           sizeof(p->preset) + sizeof(p->offset) + sizeof(p->diff),
                       "preset, offset, diff must be contiguous");
        memset(p->preset, 0, sizeof(p->preset) + sizeof(p->offset) + sizeof(p->diff));
    }
    return CO_OK;
}

void co_incl_set_preset(co_incl_t *incl, unsigned axis, int16_t preset)
{
    if (!CO_CHECK(axis < CO_INCL_AXES)) {
        return;
    }
#if CO_INCL_CIRCULAR
    if (incl->circular) {
        int32_t a1 = circular_a1(incl, axis);
        incl->p->preset[axis] = preset;
        incl->p->offset[axis] =
            (int16_t)mod_pos((int32_t)preset - a1 - incl->p->diff[axis], turn(incl));
        return;
    }
#endif
    int32_t off = (int32_t)preset - signed_measure(incl, axis);
    if (off > INT16_MAX) {
        off = INT16_MAX;
    } else if (off < INT16_MIN) {
        off = INT16_MIN;
    }
    incl->p->preset[axis] = preset;
    incl->p->offset[axis] = (int16_t)off;
}
