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
    /* Safe by construction: |x| <= CO_FILTER_IN_MAX = 2^22 - 1 gives
     * |v| < 2^30 in Q8; every stage is a weighted mean of such values, so
     * |s| < 2^30 too, and v - s stays within +-2^31 - 1, as does v + 128.
     * The inputs of every product are far smaller (product.h asserts it);
     * a larger one saturates instead of overflowing. */
    if (x_mdeg > CO_FILTER_IN_MAX) {
        x_mdeg = CO_FILTER_IN_MAX;
    } else if (x_mdeg < -CO_FILTER_IN_MAX) {
        x_mdeg = -CO_FILTER_IN_MAX;
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
