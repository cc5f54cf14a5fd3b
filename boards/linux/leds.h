/*
 * leds.h - the two status LEDs: GPIO lines through libgpiod when asked
 * for (--led-chip, --led-green, --led-red), and a log line per change.
 */
#ifndef LINUX_LEDS_H
#define LINUX_LEDS_H

#include <stdbool.h>

#include "co_node.h"

typedef struct leds {
    void *chip;  /* struct gpiod_chip *, NULL without GPIO */
    void *green; /* struct gpiod_line * */
    void *red;
    int g, r;   /* last levels, -1 unknown */
    int gp, rp; /* last patterns, -1 unknown */
} leds_t;

/* chip NULL: log only. Returns 0, or -1 with the cause in err (errlen bytes)
 * when the GPIO lines could not be had or libgpiod support was not built in. */
int leds_open(leds_t *l, const char *chip, int green_line, int red_line, char *err,
              unsigned errlen);
/* Drive the levels; log when a pattern changes. */
void leds_set(leds_t *l, unsigned node, bool green, bool red, co_led_pattern_t gp,
              co_led_pattern_t rp);
/* Both LEDs off (logged as a pattern change), then release the lines. */
void leds_close(leds_t *l, unsigned node);

#endif /* LINUX_LEDS_H */
