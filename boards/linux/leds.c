/*
 * leds.c - see leds.h.
 */
#include "leds.h"

#include <errno.h>
#include <stdio.h>
#include <string.h>

#include "log.h"

#if defined(HAVE_GPIOD) && HAVE_GPIOD
#include <gpiod.h>
#endif

int leds_open(leds_t *l, const char *chip, int green_line, int red_line, char *err, unsigned errlen)
{
    memset(l, 0, sizeof(*l));
    l->g = l->r = -1;
    l->gp = l->rp = -1;
    if (chip == NULL) {
        return 0;
    }
#if defined(HAVE_GPIOD) && HAVE_GPIOD
    struct gpiod_chip *c = gpiod_chip_open_lookup(chip);
    if (c == NULL) {
        snprintf(err, errlen, "--led-chip %s: %s", chip, strerror(errno));
        return -1;
    }
    struct gpiod_line *g = gpiod_chip_get_line(c, (unsigned)green_line);
    struct gpiod_line *r = gpiod_chip_get_line(c, (unsigned)red_line);
    if (g == NULL || r == NULL || gpiod_line_request_output(g, "canopen-sensor", 0) < 0 ||
        gpiod_line_request_output(r, "canopen-sensor", 0) < 0) {
        snprintf(err, errlen, "GPIO lines %d/%d on %s: %s", green_line, red_line, chip,
                 strerror(errno));
        gpiod_chip_close(c);
        return -1;
    }
    l->chip = c;
    l->green = g;
    l->red = r;
    lp_log("LEDs on %s lines %d (green) and %d (red)", chip, green_line, red_line);
    return 0;
#else
    (void)green_line;
    (void)red_line;
    snprintf(err, errlen, "--led-chip given but this build has no libgpiod");
    return -1;
#endif
}

void leds_set(leds_t *l, unsigned node, bool green, bool red, co_led_pattern_t gp,
              co_led_pattern_t rp)
{
    if ((int)gp != l->gp || (int)rp != l->rp) {
        lp_log("node %u: LED green %s, red %s", node, co_led_pattern_name(gp),
               co_led_pattern_name(rp));
        l->gp = (int)gp;
        l->rp = (int)rp;
    }
#if defined(HAVE_GPIOD) && HAVE_GPIOD
    if (l->chip != NULL && ((int)green != l->g || (int)red != l->r)) {
        (void)gpiod_line_set_value(l->green, green);
        (void)gpiod_line_set_value(l->red, red);
    }
#endif
    l->g = green;
    l->r = red;
}

void leds_close(leds_t *l, unsigned node)
{
    leds_set(l, node, false, false, CO_LED_OFF, CO_LED_OFF);
#if defined(HAVE_GPIOD) && HAVE_GPIOD
    if (l->chip != NULL) {
        gpiod_chip_close(l->chip);
    }
#endif
    l->chip = NULL;
}
