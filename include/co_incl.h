/** @file
 * co_incl.h - CiA 410 inclinometer profile logic, one module for every
 * inclinometer of the tree.
 *
 * Objects: 0x6000 resolution (units of 0.001 deg per LSB), and per axis
 * (X/longitudinal = axis 0 at 0x6010.., Y/lateral = axis 1 at 0x6020..):
 * slope (computed), operating parameter (bit0 invert, bit1 scaling),
 * preset, offset (= preset - measured at the preset instant) and
 * differential offset. Angles enter as millidegrees.
 *
 *   m     = measured angle / resolution, rounded half away from zero
 *   slope = s*m + offset + differential offset   (scaling on)
 *         = s*m                                  (scaling off)
 *   with s = -1 when the invert bit is set; saturated to the object's
 *   type (INTEGER16, or INTEGER32 for the 32-bit slopes 0x6110/0x6120).
 *
 * Circular outputs (a full-turn sensor whose outputs are 0..359.9 deg):
 * with F = one turn in resolution units, a1 = (F - m) mod F when inverted,
 *   slope = (a1 + offset + differential offset) mod F   (scaling on)
 *   preset P: offset = (P - a1 - differential offset) mod F, in [0, F) or,
 *   centred, in (-F/2, F/2]
 *
 * Two layers:
 *  - the arithmetic of one output (co_incl_output, co_incl_preset_offset,
 *    co_incl_meas_t, co_incl_wrap180, co_incl_mod): for a product whose
 *    objects are its own (the ifm JD: a 16- and a 32-bit slope per axis,
 *    each with its own operating parameter and offsets, one preset), which
 *    keeps its parameters where its table has them;
 *  - co_incl_t: one INTEGER16 slope set per axis in a co_incl_para_t, the
 *    angle filter, the limit and the wrap at +-180 deg, the outputs made
 *    once per sample by the same arithmetic (Danfoss DST, P+F, Gefran).
 */
#ifndef CO_INCL_H
#define CO_INCL_H

#include <string.h>

#include "co_common.h"
#include "co_filter.h"

/** Operating parameter bits (0x6011, 0x6021): invert the output; scaling (offsets added). @{ */
#define CO_INCL_OP_INVERT 0x01u
#define CO_INCL_OP_SCALING 0x02u
/** @} */

/** The most axes a device has: axis arguments are below it (CO_CHECK). */
#define CO_INCL_AXES 2u

/** One full turn in millidegrees. */
#define CO_INCL_TURN_MDEG 360000

/** Circular outputs (0 to one turn - 1 LSB: the P+F, GSH-A and ifm JD1 mode).
 * An MCU image of a product without them sets 0 (its family.cmake SIZES):
 * the mode's code is left out, a product that sets incl.circular does not
 * build, and a co_incl_fit_t's turn is not read (every output linear). */
#ifndef CO_INCL_CIRCULAR
#define CO_INCL_CIRCULAR 1
#endif
#if CO_INCL_CIRCULAR != 0 && CO_INCL_CIRCULAR != 1
#error "CO_INCL_CIRCULAR must be 0 or 1 (circular outputs left out or built in)"
#endif

/* ---- The arithmetic of one output ------------------------------------ */

/** The functions of a slope read (every PDO) are inlined also at -Os, where
 * gcc calls them with the co_incl_fit_t on the stack, which makes the ifm
 * JD2's SYNC in tools/bench a fifth slower (the JD image is 350 bytes
 * larger for it; no DST image calls them twice). */
#if defined(__GNUC__)
#define CO_INCL_INLINE static inline __attribute__((always_inline))
#else
#define CO_INCL_INLINE static inline
#endif

/** Round a / b to nearest, halves away from zero (any a). b must be above
 * 0: b <= 0 breaks the contract, CO_CHECK fails and the result is 0. */
int32_t co_div_round(int32_t a, int32_t b);

/** An angle in [-180000, 180000) millidegrees (any a; a few turns take one
 * pass each: no division, which an MCU image has as a helper). */
int32_t co_incl_wrap180(int32_t a);

/** Non-negative a mod m, in [0, m) (any a). Within one m either side of 0,
 * where the terms of a circular output are, without a division. m must be
 * above 0: m <= 0 breaks the contract, CO_CHECK fails and the result is 0. */
static inline int32_t co_incl_mod(int32_t a, int32_t m)
{
    if (!CO_CHECK(m > 0)) {
        return 0;
    }
    if (a >= -m && a < m) {
        return a < 0 ? a + m : a;
    }
    int32_t r = a % m;
    return r < 0 ? r + m : r;
}

/** v saturated to INTEGER32 (wide) or INTEGER16. */
static inline int32_t co_incl_saturate(int64_t v, bool wide)
{
    int32_t hi = wide ? INT32_MAX : INT16_MAX;
    int32_t lo = wide ? INT32_MIN : INT16_MIN;
    return v > hi ? hi : (v < lo ? lo : (int32_t)v);
}

/**
 * How a slope object holds its value, an option of each output:
 *   turn > 0: circular, modulo one turn (turn = 360 deg in resolution
 *             units): outputs 0..turn-1, whatever the offsets hold;
 *             centred: offsets made by a preset lie in (-turn/2, turn/2]
 *             (a signed object, ifm JD1), else in [0, turn) (P+F,
 *             Gefran);
 *   turn = 0: linear, the exact sum saturated to INTEGER32 (wide) or
 *             INTEGER16, never wrapped (CiA 410, ifm JD2).
 */
typedef struct co_incl_fit {
    int32_t turn; /**< one turn in resolution units: circular; 0: linear */
    bool wide;    /**< linear: INTEGER32, else INTEGER16 */
    bool centred; /**< circular: preset offsets in (-turn/2, turn/2] */
} co_incl_fit_t;

/** A 32-bit sum wrapped modulo 2^32 (no overflow trap), saturated to
 * INTEGER16: exact while the true sum is within +-2^31. */
CO_INCL_INLINE int32_t co_incl_sat16(uint32_t sum)
{
    int32_t v = (int32_t)sum; /* modulo 2^32: gcc and clang define it */
    return v > INT16_MAX ? INT16_MAX : (v < INT16_MIN ? INT16_MIN : v);
}

/**
 * The CiA 410 formula above for one output: m the measured angle in
 * resolution units, op the object's operating parameter, offset and diff
 * its offset and differential offset (read only with the scaling bit).
 * Defined for any values; exact: circular, each term reduced first; wide,
 * summed in 64 bits; INTEGER16, summed in 32 bits (modulo 2^32), exact
 * while |m| + |offset| + |diff| < 2^31, which INTEGER16 offsets and any
 * angle a board gives keep (a 64-bit sum on the Cortex-M0 cost the DST
 * X730's 10 KB image 140 bytes). Cannot fail; no state.
 */
CO_INCL_INLINE int32_t co_incl_output(int32_t m, uint8_t op, int32_t offset, int32_t diff,
                                      co_incl_fit_t fit)
{
    if (CO_INCL_CIRCULAR && fit.turn > 0) {
        int32_t t = fit.turn;
        int32_t a1 = co_incl_mod(m, t);
        if ((op & CO_INCL_OP_INVERT) != 0u && a1 != 0) {
            a1 = t - a1;
        }
        if ((op & CO_INCL_OP_SCALING) != 0u) {
            /* Below 3t: at most two passes, no division. */
            a1 += co_incl_mod(offset, t) + co_incl_mod(diff, t);
            while (a1 >= t) {
                a1 -= t;
            }
        }
        return a1;
    }
    if (!fit.wide) {
        uint32_t u = (op & CO_INCL_OP_INVERT) != 0u ? 0u - (uint32_t)m : (uint32_t)m;
        if ((op & CO_INCL_OP_SCALING) != 0u) {
            u += (uint32_t)offset + (uint32_t)diff;
        }
        return co_incl_sat16(u);
    }
    int64_t v = (op & CO_INCL_OP_INVERT) != 0u ? -(int64_t)m : (int64_t)m;
    if ((op & CO_INCL_OP_SCALING) != 0u) {
        v += (int64_t)offset + diff;
    }
    return co_incl_saturate(v, true);
}

/** The offset that makes the output read preset now, at measured angle m:
 * preset - s*m - diff, fitted as fit says (circular: into its window;
 * linear: saturated to the type). diff: the differential offset where the
 * product's offset takes it in (the output then reads preset), 0 where it
 * does not (the output reads preset + diff). Defined for any values;
 * exact as co_incl_output (INTEGER16: |preset| < 2^30 too). Cannot fail. */
int32_t co_incl_preset_offset(int32_t preset, int32_t m, uint8_t op, int32_t diff,
                              co_incl_fit_t fit);

/**
 * Measured angles in resolution units, for a product that computes its
 * outputs at each read: divided once per sample and once per change of
 * 0x6000, never per read (a division is a helper call on the Cortex-M0:
 * with one per read, half of the ifm JD2's SYNC goes to it).
 * 0x6000 reaches the parameters through its hook, a restore and a load
 * alike, so a read compares the resolution rather than rely on every
 * writer telling it. The caller owns it and the angles it is given.
 */
typedef struct co_incl_meas {
    int32_t m[CO_INCL_AXES]; /**< angle / resolution, rounded */
    int32_t turn;            /**< one turn in resolution units */
    uint16_t res;            /**< the resolution m and turn hold; 0: none */
} co_incl_meas_t;

/** Recompute *c from angles mdeg[0..CO_INCL_AXES-1] (mdeg, any values) at
 * resolution res. res 0 (no parameters loaded yet): every m and the turn
 * are 0, until a resolution comes. Cannot fail. */
void co_incl_remeasure(co_incl_meas_t *c, const int32_t mdeg[CO_INCL_AXES], uint16_t res);

/** *c at resolution res: recomputed from mdeg (the angles it was last
 * given) when res changed, as it is when read. Call it before reading
 * c->m[] and c->turn; at the start of a read, where little else is live
 * across the rare call (the Cortex-M0 then spills nothing). */
CO_INCL_INLINE const co_incl_meas_t *co_incl_meas_at(co_incl_meas_t *c,
                                                     const int32_t mdeg[CO_INCL_AXES], uint16_t res)
{
    if (c->res != res) {
        co_incl_remeasure(c, mdeg, res);
    }
    return c;
}

/* ---- co_incl_t: one INTEGER16 slope set per axis ----------------------- */

/** Stored parameters; products embed this in their PARA struct. Word
 * aligned (16 bytes, no padding): the slope cache compares it with four
 * word loads (co_incl_para_same). The products' PARA structs already had
 * it at a multiple of 4, so no stored layout moved. */
typedef struct co_incl_para {
    _Alignas(4) uint16_t resolution; /**< 0x6000 */
    uint8_t op[2];                   /**< per axis: operating parameter (0x6011, 0x6021) */
    int16_t preset[2];               /**< per axis: preset (0x6012, 0x6022) */
    int16_t offset[2];               /**< per axis: offset (0x6013, 0x6023) */
    int16_t diff[2];                 /**< per axis: differential offset (0x6014, 0x6024) */
} co_incl_para_t;

/** The CiA 410 logic of one inclinometer; the caller's (co_incl_init). */
typedef struct co_incl {
    co_incl_para_t *p; /**< its stored parameters (the caller's) */
    uint8_t axes;      /**< 1 (single axis) or 2 */
    bool wrap;         /**< full turn: the angle wraps at +-180 deg */
#if CO_INCL_CIRCULAR
    bool circular; /**< outputs 0..full turn - 1 LSB, modulo a full turn (P+F) */
#endif
    bool fault;                  /**< sensor element error: outputs hold */
    int32_t limit_mdeg;          /**< output stops here, error beyond it; 0: none */
    uint8_t shift;               /**< active filter shift */
    bool beyond[CO_INCL_AXES];   /**< measured angle strictly beyond the limit */
    int32_t angle[CO_INCL_AXES]; /**< filtered, saturated angle (mdeg) */
    /** Wrap mode: each axis' own continuous input to its filter (one value
     * for both makes the second axis follow the first's turns). */
    int32_t unwrapped[CO_INCL_AXES];
    co_filter_t f[CO_INCL_AXES]; /**< each axis' angle filter */
    /** The slope outputs, computed once per sample rather than per read
     * (SDO, every PDO): valid while *p still equals seen. */
    int16_t out[CO_INCL_AXES];
    co_incl_para_t seen; /**< the parameters out[] was computed with */
} co_incl_t;

/**
 * Set incl up for a device of axes axes (1 or 2; CO_INCL_AXES at most)
 * whose parameters are *p: no sample yet (outputs 0), the filter at its
 * slow speed (set incl->shift to change it; 0 passes samples through),
 * linear outputs (set incl->circular for circular ones). limit_mdeg: the
 * output stops there and co_incl_beyond() reports beyond it (0: no
 * limit); wrap: a full-turn sensor, angles wrap at +-180 deg (no limit).
 * p is owned by the caller and must outlive incl; incl is the caller's
 * too (no heap). axes above CO_INCL_AXES break the contract: CO_CHECK
 * fails and CO_INCL_AXES are set up (0 axes: every output reads 0).
 */
void co_incl_init(co_incl_t *incl, co_incl_para_t *p, uint8_t axes, int32_t limit_mdeg, bool wrap);

/**
 * Feed one sensor sample: mdeg[a] is axis a's angle in millidegrees
 * (entries from incl->axes on are not read). Filters it, applies the
 * limit or the wrap, and recomputes every slope output. While
 * incl->fault is set the sample is ignored and the outputs hold. Not
 * from an interrupt (it writes the state every read uses).
 */
void co_incl_sample(co_incl_t *incl, const int32_t mdeg[2]);

/**
 * co_incl_slope's slow path, for a parameter changed since the last
 * sample: recompute every output with *incl->p, return axis's. An axis
 * the device lacks (incl->axes <= axis < CO_INCL_AXES) reads 0. An axis
 * from CO_INCL_AXES on breaks the contract: CO_CHECK fails, 0 is
 * returned and nothing is recomputed.
 */
int16_t co_incl_refresh_slope(co_incl_t *incl, unsigned axis);

_Static_assert(sizeof(co_incl_para_t) == 16u, "co_incl_para_t: four words, no padding");

/** *a equals *b. On a 32-bit core four word compares, not memcmp: there
 * memcmp is libc_min.c's byte loop, 135 Cortex-M0 instructions per slope
 * read (each TPDO and slope SDO read has one), for 8 bytes of flash. */
static inline bool co_incl_para_same(const co_incl_para_t *a, const co_incl_para_t *b)
{
#if defined(__GNUC__) && UINTPTR_MAX <= 0xFFFFFFFFu
    const co_word_t *x = (const co_word_t *)(const void *)a;
    const co_word_t *y = (const co_word_t *)(const void *)b;
    for (unsigned i = 0; i < sizeof(*a) / 4u; i++) {
        if (x[i] != y[i]) {
            return false;
        }
    }
    return true;
#else
    /* 64-bit hosts: the compiler expands this memcmp into two 8-byte
     * compares (x86-64: 12 instructions, the word loop took 31). */
    return memcmp(a, b, sizeof(*a)) == 0;
#endif
}

/** The slope object (0x6010 axis 0, 0x6020 axis 1) in resolution units.
 * Recomputed only when a parameter changed since the last sample:
 * parameters reach p through plain dictionary writes and the store too,
 * so compare rather than rely on every writer telling us. An axis the
 * device lacks (a single-axis device's 0x6020) reads 0; from
 * CO_INCL_AXES on CO_CHECK fails too (0 all the same). */
static inline int16_t co_incl_slope(co_incl_t *incl, unsigned axis)
{
    if (axis >= incl->axes) {
        (void)CO_CHECK(axis < CO_INCL_AXES); /* no code in an image */
        return 0;
    }
    if (!co_incl_para_same(&incl->seen, incl->p)) {
        return co_incl_refresh_slope(incl, axis);
    }
    return incl->out[axis];
}

/** The same as a read hook's answer: the slope sign-extended into *v
 * (always CO_OK; an axis as co_incl_slope). The slow path is a tail call,
 * so the fast one needs no stack frame. co_incl_refresh_read is that
 * slow path (axes as co_incl_refresh_slope; *v = 0 for any other). @{ */
co_res_t co_incl_refresh_read(co_incl_t *incl, unsigned axis, uint32_t *v);
static inline co_res_t co_incl_read(co_incl_t *incl, unsigned axis, uint32_t *v)
{
    if (axis < incl->axes && co_incl_para_same(&incl->seen, incl->p)) {
        *v = (uint32_t)(int32_t)incl->out[axis];
        return CO_OK;
    }
    return co_incl_refresh_read(incl, axis, v);
}
/** @} */

/** Any axis beyond its limit at the last sample (never in wrap mode). */
bool co_incl_beyond(const co_incl_t *incl);

/**
 * Write the resolution (0x6000). Refused with CO_E_STATE unless the scaling
 * bit is set on every axis the device has (0x6011 and 0x6021). A changed
 * value clears every preset, offset and differential offset. The set of
 * allowed values is the product's to check before calling.
 */
co_res_t co_incl_set_resolution(co_incl_t *incl, uint16_t res);

/**
 * Write the preset (0x6012/0x6022): stores it and sets the offset so that
 * the output reads it now (linear: offset = preset - s*m, saturated to
 * INTEGER16; circular: offset = preset - a1 - differential offset, modulo
 * a turn). An axis the device lacks (incl->axes <= axis < CO_INCL_AXES)
 * is stored all the same, with a measured angle of 0 (its objects exist
 * in the shared tables). From CO_INCL_AXES on: CO_CHECK fails, nothing is
 * written. Range checks of the value are the product's, before calling.
 */
void co_incl_set_preset(co_incl_t *incl, unsigned axis, int16_t preset);

#endif /* CO_INCL_H */
