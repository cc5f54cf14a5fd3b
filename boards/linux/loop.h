/*
 * loop.h - the event loop: one epoll over the event sources (the nodes'
 * CAN sockets, standard input, the control socket and its clients, a
 * signalfd for SIGINT, SIGTERM and SIGHUP), a timeout from the earliest
 * deadline the nodes, the ports (link watch, simulated bus-off), the
 * sensor sampling and the LEDs ask for, served on a grid of
 * LOOP_GRID_US, and the dispatch of what arrives. Standard input is one
 * of the line language's channels (cmd.h): its lines are served here.
 * Everything runs in one thread; nothing blocks.
 */
#ifndef LINUX_LOOP_H
#define LINUX_LOOP_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "app.h"
#include "cmd.h"
#include "control.h"
#include "log.h"

/* Timers are served on a grid of this many microseconds of the clock. */
#define LOOP_GRID_US 250u

/* A pass of the loop longer than this is logged (loop_run): a fifth of
 * the shortest heartbeat or event-timer period the products are run at. */
#define LOOP_LONG_PASS_US 2000u

typedef struct loop {
    app_t *app;
    ctl_t ctl;                 /* --control (ctl.fd -1: none) */
    int sfd;                   /* signalfd: SIGINT, SIGTERM, SIGHUP */
    int ep;                    /* epoll over the sources */
    bool quit_on_eof;          /* --on-eof quit */
    bool stdin_polled;         /* standard input is in the epoll set */
    int stdin_errno;           /* why it could not be added */
    bool stdin_file;           /* cannot be polled: read a block a pass */
    cmd_lines_t in;            /* standard input's line being assembled */
    lp_rate_t in_rate;         /* rejected lines logged per second */
    unsigned long in_held;     /* rejected lines not logged yet */
    unsigned long out_dropped; /* answers to get that standard output could not take */
    uint32_t next_sample;      /* when the products sample their inputs next */
    bool no_pwait2;            /* the kernel has no epoll_pwait2: epoll_wait */
    uint32_t pass_max_us;      /* the longest pass of the loop's own work */
    uint32_t pass_logged_us;   /* the longest one the log has named so far */
} loop_t;

/* The stop signals (SIGINT, SIGTERM, SIGHUP), for main() to block first. */
void loop_stop_signals(sigset_t *sigs);

/*
 * Set up the event sources for app a (its ports open): the signalfd,
 * epoll, standard input, the nodes' sockets and, with control not NULL,
 * the control socket (control.h's spec). Returns 0; -2 with the cause in
 * err for a control spec that cannot be used (a usage error); -1 with
 * the cause for another failure.
 */
int loop_open(loop_t *l, app_t *a, const char *control, bool quit_on_eof, char *err, size_t errlen);

/* After the nodes' start at time t: standard input that cannot be polled
 * is read a block a pass (a file) or taken as ended; the first sample. */
void loop_start(loop_t *l, uint32_t t);

/* Run until app->quit (a command, the end of input, a signal). Returns 0,
 * or 1 when epoll fails. A pass is the loop's own work between two waits
 * for events, by its clock (loop_now_us): every timer waits as long as
 * it takes. A pass longer than LOOP_LONG_PASS_US and longer than any the
 * log has named is logged ("loop: a pass took ..."), and at the end the
 * longest ("loop: the longest pass took ..."): how the tests judge that
 * the program kept its timers (docs/testing.md, "Bounds and timing"). */
int loop_run(loop_t *l);

/* Close the control socket and the loop's descriptors. */
void loop_close(loop_t *l);

/* The process's clock: microseconds, monotonic, wrapping. */
uint32_t loop_now_us(void);

#endif /* LINUX_LOOP_H */
