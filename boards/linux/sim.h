/*
 * sim.h - the simulated physics, one command a line on standard input:
 *   set NAME=VALUE [NAME=VALUE...]   true value of inputs (product's names)
 *   fault NAME on|off                force a fault (product's names: sensor, ...)
 *   quit                             stop the program
 * A bad line gets a message on stderr and changes nothing.
 */
#ifndef LINUX_SIM_H
#define LINUX_SIM_H

#include <stdbool.h>
#include <stdint.h>

#include "product.h"

typedef struct sim {
    const product_t *prod;
    int32_t values[PRODUCT_MAX_INPUTS]; /* thousandths of the input's unit */
    uint32_t faults; /* bit i: the product's faults[i] is on */
    bool quit;
} sim_t;

/* Start with the product's initial input values, no fault. */
void sim_init(sim_t *s, const product_t *p);

/* Apply one line (without its newline). Returns false (and writes why to
 * err, errlen bytes) if the line was rejected; nothing changed then. */
bool sim_command(sim_t *s, const char *line, char *err, unsigned errlen);

#endif /* LINUX_SIM_H */
