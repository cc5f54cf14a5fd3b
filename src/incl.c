/*
 * incl.c - CiA 410 inclinometer profile logic. See co_incl.h.
 */
#include "co_incl.h"

#include <string.h>

int32_t co_div_round(int32_t a, int32_t b)
{
    if (!CO_CHECK(b > 0)) {
        return 0;
    }
    /* Half away from zero, in unsigned arithmetic so that no a overflows
     * (|a| <= 2^31, |a| + b/2 < 2^32). The result for INT32_MIN / 1 is
     * converted back modulo 2^32 (gcc and clang define it). */
    uint32_t m = a >= 0 ? (uint32_t)a : 0u - (uint32_t)a;
    uint32_t q = (m + (uint32_t)b / 2u) / (uint32_t)b;
    return a >= 0 ? (int32_t)q : (int32_t)(0u - q);
}

void co_incl_init(co_incl_t *incl, co_incl_para_t *p, uint8_t axes, int32_t limit_mdeg, bool wrap)
{
    if (!CO_CHECK(axes <= CO_INCL_AXES)) {
        axes = CO_INCL_AXES;
    }
    memset(incl, 0, sizeof(*incl));
    incl->p = p;
    incl->axes = axes;
    incl->limit_mdeg = limit_mdeg;
    incl->wrap = wrap;
    incl->shift = co_filter_shift(0); /* the filters unprimed: zeroed above */
}

static void refresh(co_incl_t *incl);

/* By whole turns, not by a division: the angles here are a few turns at
 * most (the filter's input bound, co_filter.h; the board inputs'
 * PRODUCT_ANGLE_LIMIT), one pass a turn; and no signed division helper in
 * an MCU image. */
CO_NOINLINE int32_t co_incl_wrap180(int32_t a)
{
    while (a >= CO_INCL_TURN_MDEG / 2) {
        a -= CO_INCL_TURN_MDEG;
    }
    while (a < -CO_INCL_TURN_MDEG / 2) {
        a += CO_INCL_TURN_MDEG;
    }
    return a;
}

int32_t co_incl_preset_offset(int32_t preset, int32_t m, uint8_t op, int32_t diff,
                              co_incl_fit_t fit)
{
    if (CO_INCL_CIRCULAR && fit.turn > 0) {
        int32_t t = fit.turn;
        /* a1 as co_incl_output makes it; every term in [0, t): the
         * difference is in (-2t, t), one co_incl_mod. */
        int32_t a1 = co_incl_output(m, (uint8_t)(op & CO_INCL_OP_INVERT), 0, 0, fit);
        int32_t r = co_incl_mod(co_incl_mod(preset, t) - a1 - co_incl_mod(diff, t), t);
        return fit.centred && r > t / 2 ? r - t : r;
    }
    bool inv = (op & CO_INCL_OP_INVERT) != 0u;
    if (!fit.wide) {
        /* 32 bits, as co_incl_output's INTEGER16 sum. */
        uint32_t sm = inv ? 0u - (uint32_t)m : (uint32_t)m;
        return co_incl_sat16((uint32_t)preset - sm - (uint32_t)diff);
    }
    int64_t sm = inv ? -(int64_t)m : (int64_t)m;
    return co_incl_saturate((int64_t)preset - sm - diff, true);
}

void co_incl_remeasure(co_incl_meas_t *c, const int32_t mdeg[CO_INCL_AXES], uint16_t res)
{
    c->res = res;
    c->turn = 0;
    for (unsigned a = 0; a < CO_INCL_AXES; a++) {
        c->m[a] = 0;
    }
    if (res == 0u) {
        return;
    }
    c->turn = CO_INCL_TURN_MDEG / (int32_t)res;
    for (unsigned a = 0; a < CO_INCL_AXES; a++) {
        c->m[a] = co_div_round(mdeg[a], (int32_t)res);
    }
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
                *u = co_incl_wrap180(x);
            } else {
                *u += co_incl_wrap180(x - *u);
            }
            int32_t y = co_filter_step(&incl->f[a], *u, incl->shift);
            int32_t w = co_incl_wrap180(y);
            /* Keep the filter state near the [-180, 180) window. */
            if (w != y) {
                int32_t d = w - y;
                for (unsigned i = 0; i < CO_FILTER_STAGES; i++) {
                    incl->f[a].s[i] += d * 256;
                }
                *u += d;
            }
            incl->angle[a] = w; /* never beyond: no limit (beyond[] stays 0 from init) */
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

/* How the outputs fit their INTEGER16 objects: linear, or circular (one
 * turn in resolution units). A resolution of 0 (a stored set from before
 * its check) counts as 1. */
static co_incl_fit_t fit_of(const co_incl_t *incl)
{
    co_incl_fit_t fit = {.turn = 0, .wide = false, .centred = false};
#if CO_INCL_CIRCULAR
    if (incl->circular) {
        int32_t res = incl->p->resolution != 0u ? (int32_t)incl->p->resolution : 1;
        fit.turn = CO_INCL_TURN_MDEG / res;
    }
#else
    (void)incl;
#endif
    return fit;
}

/* s*m: axis axis's measured angle in resolution units (circular: the
 * angle taken within one turn first), the sign of the invert bit applied.
 * Out of line, and the sign here rather than in co_incl_output (which is
 * then given the operating parameter without the bit: the same result,
 * (-m) mod F = (F - m) mod F): one copy for the outputs and the preset,
 * for the DST X730's 10 KB image. */
static CO_NOINLINE int32_t signed_measure(const co_incl_t *incl, unsigned axis)
{
    int32_t res = incl->p->resolution != 0u ? (int32_t)incl->p->resolution : 1;
    int32_t a = incl->angle[axis];
#if CO_INCL_CIRCULAR
    if (incl->circular) {
        a = co_incl_mod(a, CO_INCL_TURN_MDEG);
    }
#endif
    int32_t m = co_div_round(a, res);
    return (incl->p->op[axis] & CO_INCL_OP_INVERT) != 0u ? -m : m;
}

/* The operating parameter as co_incl_output takes it after signed_measure. */
#define SIGNED_OP(op) ((uint8_t)((op) & ~CO_INCL_OP_INVERT))

static int16_t compute_slope(const co_incl_t *incl, unsigned axis)
{
    const co_incl_para_t *p = incl->p;
    /* A circular output is in 0..F-1: above 32767 (F = 36000 at 0.01 deg)
     * it is read as UNSIGNED16 (Gefran) through this cast. */
    return (int16_t)co_incl_output(signed_measure(incl, axis), SIGNED_OP(p->op[axis]),
                                   p->offset[axis], p->diff[axis], fit_of(incl));
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
    co_incl_fit_t fit = fit_of(incl);
    int32_t sm = signed_measure(incl, axis);
    co_incl_para_t *p = incl->p;
    /* Circular (P+F, Gefran): the output reads the preset, the
     * differential offset taken in; linear (DST, CiA 410): preset - s*m,
     * the output reads preset + differential offset. */
    int32_t diff = fit.turn > 0 ? p->diff[axis] : 0;
    p->preset[axis] = preset;
    p->offset[axis] = (int16_t)co_incl_preset_offset(preset, sm, SIGNED_OP(p->op[axis]), diff, fit);
}
