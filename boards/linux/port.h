/*
 * port.h - the Linux board: one SocketCAN raw socket per node, a file as
 * the EEPROM, and the log.
 */
#ifndef LINUX_PORT_H
#define LINUX_PORT_H

#include <stdio.h>

#include "co_node.h"

#define LP_TXQ 64u

/* The EEPROM: one file shared by the nodes of a product. */
typedef struct lp_nvm {
    const char *path;  /* NULL: RAM only, lost at exit */
    uint8_t *mem;      /* mirror of the file, size bytes (caller's storage) */
    uint32_t size;
    unsigned writes;   /* file commits, for diagnostics */
} lp_nvm_t;

typedef struct lp_port {
    int fd;               /* CAN_RAW socket, non-blocking */
    const char *iface;
    unsigned node;        /* index, for log lines */
    lp_nvm_t *nvm;
    co_frame_t txq[LP_TXQ]; /* frames the kernel could not take yet */
    unsigned txh, txn;
    unsigned long tx_lost;  /* frames dropped because txq was full */
    int can_state;          /* co_can_state_t */
} lp_port_t;

/* Log a line with a time stamp to the log (stderr or --log FILE). */
void lp_log(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void lp_log_open(FILE *f);

/* Open a non-blocking raw CAN socket on iface, error frames enabled. 0 or -1. */
int lp_open(lp_port_t *p, const char *iface, unsigned node, lp_nvm_t *nvm);

/* Try to hand queued frames to the kernel. Returns frames still queued. */
unsigned lp_flush(lp_port_t *p);

/*
 * Read one frame. Returns 1 with *f filled, 0 when nothing is pending,
 * 2 when an error frame changed *state (logged), -1 on a socket error.
 */
int lp_read(lp_port_t *p, co_frame_t *f, co_can_state_t *state);

/*
 * Open the EEPROM file: read it into mem (size bytes), or create it blank
 * (0xFF: every parameter at its default) when absent. 0 or -1 (logged).
 */
int lp_nvm_open(lp_nvm_t *n, const char *path, uint8_t *mem, uint32_t size);

#endif /* LINUX_PORT_H */
