/** @file
 * co_filter.h - the angle low-pass filter: three cascaded first-order
 * stages y += (x - y) >> k in Q8 millidegrees. Integer only (no FPU on the
 * target MCUs), no multiplication. At the 5 ms sample period the settling
 * time to within 0.01 deg after a 90 deg step is about 2.2 s (k = 5),
 * 0.52 s (k = 3) and 0.24 s (k = 2); tests/unit/test_profile.c measures it.
 */
#ifndef CO_FILTER_H
#define CO_FILTER_H

#include "co_common.h"

/** Cascaded first-order stages. */
#define CO_FILTER_STAGES 3u
/** Largest input (mdeg, about 4194 deg; the smallest is -CO_FILTER_IN_MAX - 1):
 * beyond it an input saturates, so that the Q8 arithmetic cannot overflow
 * (filter.c). */
#define CO_FILTER_IN_MAX 4194303

/** Sample period the shifts are tuned for. */
#define CO_FILTER_PERIOD_US 5000u

/** One angle's filter; the caller's (no heap). */
typedef struct co_filter {
    int32_t s[CO_FILTER_STAGES]; /**< Q8 millidegrees */
    bool primed;                 /**< s[] holds a sample (false after co_filter_reset) */
} co_filter_t;

/** Stage shift k for the three speeds (0 slow, 1 medium, 2 fast). */
uint8_t co_filter_shift(uint8_t speed);

/** Forget the history; the next sample primes every stage. */
void co_filter_reset(co_filter_t *f);

/**
 * One sample in (millidegrees; beyond CO_FILTER_IN_MAX either way it saturates),
 * filtered value out.
 * The first sample after a reset passes through unchanged.
 */
int32_t co_filter_step(co_filter_t *f, int32_t x_mdeg, uint8_t shift);

#endif /* CO_FILTER_H */
