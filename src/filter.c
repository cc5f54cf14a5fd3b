/*
 * filter.c - integer low-pass filter for angles. See co_filter.h.
 */
#include "co_filter.h"

uint8_t co_filter_shift(uint8_t speed)
{
    static const uint8_t shifts[3] = {5, 3, 2}; /* slow, medium, fast */
    return shifts[speed < 3u ? speed : 0u];
}

void co_filter_reset(co_filter_t *f)
{
    f->primed = false;
}

int32_t co_filter_step(co_filter_t *f, int32_t x_mdeg, uint8_t shift)
{
    /* Safe by construction: x in [-2^22, 2^22 - 1] (CO_FILTER_IN_MAX) gives
     * v in [-2^30, 2^30 - 256] in Q8; every stage is a weighted mean of
     * such values and stays in that range too, so v - s stays within
     * +-(2^31 - 256), and v + 128 cannot overflow either. The inputs of
     * every product are far smaller (product.h asserts it); a larger one
     * saturates instead of overflowing: x >> 22 is 0 or -1 exactly inside
     * the range (arithmetic shifts, as below). */
    if ((x_mdeg >> 22) != (x_mdeg >> 31)) {
        x_mdeg = (x_mdeg >> 31) ^ CO_FILTER_IN_MAX; /* 2^22 - 1, or -2^22 */
    }
    int32_t v = x_mdeg * 256; /* Q8 */
    if (!f->primed) {
        for (unsigned i = 0; i < CO_FILTER_STAGES; i++) {
            f->s[i] = v;
        }
        f->primed = true;
    }
    for (unsigned i = 0; i < CO_FILTER_STAGES; i++) {
        /* Arithmetic shift of a signed value: floor division, the same on
         * every compiler this stack supports (gcc, clang: documented). */
        f->s[i] += (v - f->s[i]) >> shift;
        v = f->s[i];
    }
    /* Back to millidegrees, rounded to nearest. */
    return (v + 128) >> 8;
}
