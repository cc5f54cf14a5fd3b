/*
 * setup.h - the start: from a checked command line (cli.h) to running
 * instances, in the order a failure must be reported: the log, the
 * --nvm-dir, the instances (created, not started), the node-ID clash
 * check, the EEPROM files (read and held), the CAN sockets and LEDs, the
 * sending socket, the event sources (loop.h); then, once nothing can fail
 * any more, the EEPROM files' former names renamed, the first sample and
 * the nodes' start.
 */
#ifndef LINUX_SETUP_H
#define LINUX_SETUP_H

#include "app.h"
#include "cli.h"
#include "loop.h"

/* Set up a and l from o. Returns CLI_GO_ON, or the exit status of a
 * failure at start (reported on stderr and in the log). */
int setup_run(app_t *a, loop_t *l, const options_t *o);

#endif /* LINUX_SETUP_H */
