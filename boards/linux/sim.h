/*
 * sim.h - the simulated physics, one command a line on standard input:
 *   set NAME=VALUE [NAME=VALUE...]   true value of inputs (product's names)
 *   fault NAME on|off                force a fault (product's names: sensor, ...)
 *   can bus-off [SECONDS]            the CAN controller goes bus-off; the bus
 *                                    stays unusable SECONDS (default 0), then
 *                                    the controller is back after 128 x 11 bits
 *   can passive|warning|active       the controller's error state
 *   quit                             stop the program
 * A bad line is rejected whole: nothing of it changes anything.
 */
#ifndef LINUX_SIM_H
#define LINUX_SIM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "product.h"

/* Longest line accepted, without its newline. */
#define SIM_LINE_MAX 255u

typedef struct sim {
    const product_t *prod;
    int32_t values[PRODUCT_MAX_INPUTS]; /* thousandths of the input's unit */
    uint32_t faults; /* bit i: the product's faults[i] is on */
    bool quit;
    /* A `can` command for the board to apply (to every node), then clear. */
    bool can_request;
    co_can_state_t can_state;
    uint32_t can_hold_ms; /* bus-off: how long the bus stays unusable */
    /* The standard input line being assembled (sim_feed). */
    char line[SIM_LINE_MAX + 1u];
    size_t len;
    bool overflow; /* longer than SIM_LINE_MAX: rejected at its end */
    bool nul;      /* holds a NUL byte: rejected at its end */
} sim_t;

/* Start with the product's initial input values, no fault. */
void sim_init(sim_t *s, const product_t *p);

/* Apply one line (without its newline). Returns false (and writes why to
 * err, errlen bytes) if the line was rejected; nothing changed then. */
bool sim_command(sim_t *s, const char *line, char *err, unsigned errlen);

/*
 * What became of one input line: error NULL when it was applied (line is
 * then the command; empty lines and comments are not reported), else why
 * it was rejected (line: what of it can be shown, maybe "").
 */
typedef void (*sim_report_fn)(void *ctx, const char *line, const char *error);

/*
 * Feed n bytes of standard input (any bytes): every complete line is
 * applied with sim_command() and reported. A line that holds a NUL byte or
 * is longer than SIM_LINE_MAX is rejected whole, never cut short.
 */
void sim_feed(sim_t *s, const char *data, size_t n, sim_report_fn report, void *ctx);

/* End of input: a last line without its newline is applied like any other. */
void sim_feed_end(sim_t *s, sim_report_fn report, void *ctx);

/* One line for --help: the product's `set` inputs and `fault` names. */
void sim_describe(const product_t *p, char *buf, size_t len);

#endif /* LINUX_SIM_H */
