/*
 * led.c - LED patterns. See co_led.h.
 */
#include "co_led.h"

const co_led_timing_t co_led_cia303 = {
    .flicker_ms = 50, .blink_ms = 200, .flash_ms = 200, .pause_ms = 1000};

bool co_led_level(co_led_pattern_t p, const co_led_timing_t *t, uint32_t now_us, uint32_t *next_us)
{
    /* Each pattern is a cycle of on/off phases (ms), starting with on. */
    uint32_t ph[4];
    unsigned n;
    switch (p) {
    case CO_LED_ON:
    case CO_LED_OFF:
        *next_us = CO_NEVER;
        return p == CO_LED_ON;
    case CO_LED_FLICKER:
        ph[0] = ph[1] = t->flicker_ms;
        n = 2;
        break;
    case CO_LED_BLINK:
        ph[0] = ph[1] = t->blink_ms;
        n = 2;
        break;
    case CO_LED_FLASH1:
        ph[0] = t->flash_ms;
        ph[1] = t->pause_ms;
        n = 2;
        break;
    case CO_LED_FLASH2:
    default:
        ph[0] = ph[1] = ph[2] = t->flash_ms;
        ph[3] = t->pause_ms;
        n = 4;
        break;
    }
    uint32_t cycle = 0;
    for (unsigned i = 0; i < n; i++) {
        cycle += ph[i] * 1000u;
    }
    /* The pattern's phase follows the free-running clock; it wraps every
     * 71 minutes, which shifts the pattern once, harmlessly. */
    uint32_t at = now_us % cycle;
    for (unsigned i = 0; i < n; i++) {
        uint32_t len = ph[i] * 1000u;
        if (at < len) {
            *next_us = len - at;
            return (i % 2u) == 0u;
        }
        at -= len;
    }
    *next_us = 1000u; /* not reached */
    return false;
}
