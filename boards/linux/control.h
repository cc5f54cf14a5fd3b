/*
 * control.h - the control socket (--control unix:PATH | tcp:PORT): clients
 * send the line language (cmd.h), one command a line, and get one
 * answer line for each ("ok ..." or "error: <cause>"). This module owns
 * the sockets and each client's buffers; lines are assembled as on every
 * channel (cmd.h, cmd_lines_t) and answered by the program (ctl_line_fn). Everything runs in the
 * program's one thread; nothing blocks: answers the kernel cannot take at once wait in the client's
 * buffer, and while it is full the client's further lines wait unread
 * (in the kernel), so a client that sends faster than it reads is slowed
 * down, never cut off, and one that stops reading only holds its slot.
 */
#ifndef LINUX_CONTROL_H
#define LINUX_CONTROL_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "cmd.h"

/* Clients at once; one more is accepted and told so, then closed, unless
 * a client has been silent for CTL_EVICT_US (ctl_accept). */
#define CTL_CLIENTS 16u
/* A client silent this long (no byte from it, none of its answers taken)
 * is told so and closed (ctl_expire): without it, 16 connections that say
 * nothing would lock every other client out for as long as they stay. A
 * minute: a test runner pauses for less between two commands; a person at
 * nc who pauses longer connects again. */
#define CTL_IDLE_US 60000000u
/* With every slot taken, a newcomer gets the slot of the client silent
 * longest if that one has been silent this long; a table full of clients
 * that talk refuses it. */
#define CTL_EVICT_US 5000000u
/* Answers waiting for the kernel, per client: lines are taken while one
 * more answer fits. */
#define CTL_OUT ((size_t)8 * (CMD_REPLY_MAX + 1u))
/* Bytes read from a client in one call. */
#define CTL_IN 512u

/* Answer one complete line (no newline): write the answer into reply
 * (len bytes) without its newline. */
typedef void (*ctl_line_fn)(void *ctx, const char *line, char *reply, size_t len);

typedef struct ctl_client {
    int fd;            /* -1: free */
    cmd_lines_t lines; /* the line being assembled (cmd.h) */
    char in[CTL_IN];   /* read, not looked at yet (the answers' buffer was full) */
    size_t ipos, ilen;
    char out[CTL_OUT]; /* answers the kernel has not taken yet */
    size_t olen;
    uint32_t events; /* epoll events registered for fd (the caller keeps it, ctl_events) */
    uint32_t last;   /* when it last sent a byte or took an answer (us, the loop's clock) */
} ctl_client_t;

typedef struct ctl {
    int fd;         /* listening socket, -1: none */
    char path[108]; /* unix socket path to remove at close, "" for tcp */
    ctl_client_t cl[CTL_CLIENTS];
} ctl_t;

/*
 * Listen on spec ("unix:PATH" or "tcp:PORT", 127.0.0.1 only). A unix PATH
 * that exists is refused, unless it is a socket nobody listens on (a stale
 * socket a killed run left: connect() refused), which is replaced.
 * Returns 0; -2 with a one-line cause in err for a spec that cannot be
 * used (wrong form, path exists, port in use); -1 for another failure.
 */
int ctl_open(ctl_t *c, const char *spec, char *err, size_t errlen);

/* Whether spec has one of ctl_open's forms (unix:PATH with a PATH that
 * fits a socket address, tcp:PORT with PORT 1..65535): checked with the
 * command line, before anything opens. false with the cause in err. */
bool ctl_spec_ok(const char *spec, char *err, size_t errlen);

/* The listening socket's fd (for epoll), -1 when closed. */
static inline int ctl_fd(const ctl_t *c)
{
    return c->fd;
}

/* Accept what waits on the listening socket at time now (us); returns the
 * new client's slot (its fd is c->cl[slot].fd, for epoll), or -1 when none
 * was added. With every slot taken, the client silent longest is told so
 * and closed if silent for CTL_EVICT_US (its fd leaves epoll with the
 * close), and the newcomer takes its slot; else the newcomer is told
 * "error: too many control clients" and closed. */
int ctl_accept(ctl_t *c, uint32_t now);

/* Serve client slot k (it is readable or writable) at time now (us): send
 * what waits, read and answer complete lines through fn while their
 * answers fit. Returns false when the client is gone (closed here; a
 * partial line is discarded). */
bool ctl_read(ctl_t *c, unsigned k, ctl_line_fn fn, void *ctx, uint32_t now);

/* Close the clients silent for CTL_IDLE_US at time now (us), each told
 * "error: silent for 60 s: closed" first if it can take the line (a half
 * line it sent is dropped). Returns the time until the next one would be
 * (UINT32_MAX: no client). */
uint32_t ctl_expire(ctl_t *c, uint32_t now);

/* The epoll events client k needs now: EPOLLIN while it may send more
 * lines, EPOLLOUT while answers wait for the kernel. */
uint32_t ctl_events(const ctl_t *c, unsigned k);

/* Close every client and the listening socket; a unix path is removed
 * when it still leads to this socket (a connection made through it
 * arrives here), never one another process bound there after ours was
 * removed;
 * nothing when ctl_open() was not called or failed (c->fd -1). */
void ctl_close(ctl_t *c);

#endif /* LINUX_CONTROL_H */
