/*
 * co_incl.h - CiA 410 inclinometer profile logic.
 *
 * Objects: 0x6000 resolution (units of 0.001 deg per LSB), and per axis
 * (X/longitudinal = axis 0 at 0x6010.., Y/lateral = axis 1 at 0x6020..):
 * slope (computed), operating parameter (bit0 invert, bit1 scaling),
 * preset, offset (= preset - measured at the preset instant) and
 * differential offset. Angles enter as millidegrees through the filter.
 *
 *   m     = measured angle / resolution, rounded half away from zero
 *   slope = s*m + offset + differential offset   (scaling on)
 *         = s*m                                  (scaling off)
 *   with s = -1 when the invert bit is set; clamped to INTEGER16.
 *
 * Circular mode (a full-turn sensor whose outputs are 0..359.9 deg): with
 * F = one turn in resolution units, a1 = (F - m) mod F when inverted, and
 *   slope = (a1 + offset + differential offset) mod F   (scaling on)
 *   preset P: offset = (P - a1 - differential offset) mod F
 */
#ifndef CO_INCL_H
#define CO_INCL_H

#include <string.h>

#include "co_common.h"
#include "co_filter.h"

#define CO_INCL_OP_INVERT 0x01u
#define CO_INCL_OP_SCALING 0x02u

/* The most axes a device has: axis arguments are below it (CO_CHECK). */
#define CO_INCL_AXES 2u

/* Stored parameters; products embed this in their PARA struct. Word
 * aligned (16 bytes, no padding): the slope cache compares it with four
 * word loads (co_incl_para_same). The products' PARA structs already had
 * it at a multiple of 4, so no stored layout moved. */
typedef struct co_incl_para {
    _Alignas(4) uint16_t resolution;
    uint8_t op[2];
    int16_t preset[2];
    int16_t offset[2];
    int16_t diff[2];
} co_incl_para_t;

/* Circular outputs (0 .. one turn - 1 LSB, the P+F and GSH-A mode). An MCU
 * image of a product without them sets 0 (boards/CMakeLists.txt): the mode's
 * code is left out, and a product that sets incl.circular does not build. */
#ifndef CO_INCL_CIRCULAR
#define CO_INCL_CIRCULAR 1
#endif

typedef struct co_incl {
    co_incl_para_t *p;
    uint8_t axes;        /* 1 (single axis) or 2 */
    bool wrap;           /* full turn: the angle wraps at +-180 deg */
#if CO_INCL_CIRCULAR
    bool circular;       /* outputs 0..full turn - 1 LSB, modulo a full turn (P+F) */
#endif
    bool fault;          /* sensor element error: outputs hold */
    int32_t limit_mdeg;  /* output stops here, error beyond it; 0: none */
    uint8_t shift;       /* active filter shift */
    bool beyond[CO_INCL_AXES];      /* measured angle strictly beyond the limit */
    int32_t angle[CO_INCL_AXES];    /* filtered, saturated angle (mdeg) */
    int32_t unwrapped[CO_INCL_AXES]; /* wrap mode: each axis' continuous input to its filter */
    co_filter_t f[CO_INCL_AXES];
    /* The slope outputs, computed once per sample rather than per read
     * (SDO, every PDO): valid while *p still equals seen. */
    int16_t out[CO_INCL_AXES];
    co_incl_para_t seen;
} co_incl_t;

/*
 * Set incl up for a device of axes axes (1 or 2; CO_INCL_AXES at most)
 * whose parameters are *p: no sample yet (outputs 0), the filter at its
 * slow speed (set incl->shift to change it; 0 passes samples through),
 * linear outputs (set incl->circular for circular ones). limit_mdeg: the
 * output stops there and co_incl_beyond() reports beyond it (0: no
 * limit); wrap: a full-turn sensor, angles wrap at +-180 deg (no limit).
 * p is owned by the caller and must outlive incl; incl is the caller's
 * too (no heap). Cannot fail.
 */
void co_incl_init(co_incl_t *incl, co_incl_para_t *p, uint8_t axes, int32_t limit_mdeg, bool wrap);

/*
 * Feed one sensor sample: mdeg[a] is axis a's angle in millidegrees
 * (entries from incl->axes on are not read). Filters it, applies the
 * limit or the wrap, and recomputes every slope output. While
 * incl->fault is set the sample is ignored and the outputs hold. Not
 * from an interrupt (it writes the state every read uses).
 */
void co_incl_sample(co_incl_t *incl, const int32_t mdeg[2]);

/*
 * co_incl_slope's slow path, for a parameter changed since the last
 * sample: recompute every output with *incl->p, return axis's. An axis
 * the device lacks (incl->axes <= axis < CO_INCL_AXES) reads 0. An axis
 * from CO_INCL_AXES on breaks the contract: CO_CHECK fails, 0 is
 * returned and nothing is recomputed.
 */
int16_t co_incl_refresh_slope(co_incl_t *incl, unsigned axis);

_Static_assert(sizeof(co_incl_para_t) == 16u, "co_incl_para_t: four words, no padding");

/* *a equals *b. On a 32-bit core four word compares, not memcmp: there
 * memcmp is libc_min.c's byte loop, 135 Cortex-M0 instructions per slope
 * read; the words brought the DST TPDO from 605 to 391 instructions and the
 * expedited SDO read from 633 to 526 (issue 11), for 8 bytes of flash. */
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

/* The slope object (0x6010 axis 0, 0x6020 axis 1) in resolution units.
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

/* The same as a read hook's answer: the slope sign-extended into *v
 * (always CO_OK; an axis as co_incl_slope). The slow path is a tail call,
 * so the fast one needs no stack frame. co_incl_refresh_read is that
 * slow path (axes as co_incl_refresh_slope; *v = 0 for any other). */
co_res_t co_incl_refresh_read(co_incl_t *incl, unsigned axis, uint32_t *v);
static inline co_res_t co_incl_read(co_incl_t *incl, unsigned axis, uint32_t *v)
{
    if (axis < incl->axes && co_incl_para_same(&incl->seen, incl->p)) {
        *v = (uint32_t)(int32_t)incl->out[axis];
        return CO_OK;
    }
    return co_incl_refresh_read(incl, axis, v);
}

/* Any axis beyond its limit at the last sample (never in wrap mode). */
bool co_incl_beyond(const co_incl_t *incl);

/*
 * Write the resolution (0x6000). Refused with CO_E_STATE unless the scaling
 * bit is set on every axis the device has (0x6011 and 0x6021). A changed
 * value clears every preset, offset and differential offset. The set of
 * allowed values is the product's to check before calling.
 */
co_res_t co_incl_set_resolution(co_incl_t *incl, uint16_t res);

/*
 * Write the preset (0x6012/0x6022): stores it and sets the offset so that
 * the output reads it now (linear: offset = preset - s*m, saturated to
 * INTEGER16; circular: offset = preset - a1 - differential offset, modulo
 * a turn). An axis the device lacks (incl->axes <= axis < CO_INCL_AXES)
 * is stored all the same, with a measured angle of 0 (its objects exist
 * in the shared tables). From CO_INCL_AXES on: CO_CHECK fails, nothing is
 * written. Range checks of the value are the product's, before calling.
 */
void co_incl_set_preset(co_incl_t *incl, unsigned axis, int16_t preset);

/* Round a / b to nearest, halves away from zero (b > 0). */
int32_t co_div_round(int32_t a, int32_t b);

#endif /* CO_INCL_H */
