/** @file
 * co_led.h - status LED patterns (CiA 303-3 style), computed from the node
 * state and the time passed in; no state of its own, no pointer kept, may
 * be called from anywhere (pure functions of their arguments).
 */
#ifndef CO_LED_H
#define CO_LED_H

#include "co_common.h"

/** What an LED shows (CiA 303-3 patterns). */
typedef enum co_led_pattern {
    CO_LED_OFF = 0,
    CO_LED_ON,
    CO_LED_FLICKER, /**< on/off flicker_ms */
    CO_LED_BLINK,   /**< on/off blink_ms */
    CO_LED_FLASH1,  /**< flash_ms on, then pause_ms off */
    CO_LED_FLASH2,  /**< on, off, on (flash_ms each), then pause_ms */
} co_led_pattern_t;

/** Timings in ms; products adapt them to their manuals. */
typedef struct co_led_timing {
    uint16_t flicker_ms; /**< on, then off, of CO_LED_FLICKER */
    uint16_t blink_ms;   /**< on, then off, of CO_LED_BLINK */
    uint16_t flash_ms;   /**< each flash of CO_LED_FLASH1 and CO_LED_FLASH2 */
    uint16_t pause_ms;   /**< off after the flashes */
} co_led_timing_t;

/** CiA 303-3 timings: 50 ms flicker, 200 ms blink, 200 ms flash, 1000 ms pause. */
extern const co_led_timing_t co_led_cia303;

/**
 * Level of an LED showing pattern p at time now_us, and in *next_us the
 * delay until the level next changes (CO_NEVER for steady patterns).
 */
bool co_led_level(co_led_pattern_t p, const co_led_timing_t *t, uint32_t now_us, uint32_t *next_us);

#endif /* CO_LED_H */
