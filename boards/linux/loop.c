/*
 * loop.c - the event loop and the standard-input channel; see loop.h.
 */
#include "loop.h"

#include <errno.h>
#include <poll.h>
#include <signal.h>
#include <stdio.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/signalfd.h>
#include <time.h>
#include <unistd.h>

/* Rejected input lines: at most this many logged a second, the rest counted. */
#define IN_REJECT_LINES 5u

/* The loop wakes at least this often (a bound; something is always due sooner). */
#define LOOP_MAX_WAIT_US 1000000u

/* epoll's tags: a node's socket is tagged with the node's index. */
#define EV_SIGNAL 1000u
#define EV_STDIN 1001u
#define EV_CONTROL 1002u /* the control socket's listening socket */
#define EV_CLIENT 2000u  /* + slot: a control client */

/*
 * The products sample their inputs every CO_FILTER_PERIOD_US, on its
 * cadence (each sample's time is the last one's + the period), but a
 * sample may be taken up to half a period late, in the pass of another
 * timer that runs by then: alone, the samples were 200 wake-ups a second
 * of their own, a quarter of the process's CPU with 127 nodes
 * (tools/busbench). The simulated inputs are computed for the time the
 * sample is taken (motion included), so what the product sees is exact;
 * only the instant moves, by less than half a filter step.
 */
#define SAMPLE_SLACK_US (CO_FILTER_PERIOD_US / 2u)

uint32_t loop_now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint32_t)((uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u);
}

void loop_stop_signals(sigset_t *sigs)
{
    sigemptyset(sigs);
    sigaddset(sigs, SIGINT);
    sigaddset(sigs, SIGTERM);
    sigaddset(sigs, SIGHUP);
}

/* ---- Standard input ----------------------------------------------------- */

static void log_held_input(loop_t *l, uint32_t now)
{
    if (l->in_held != 0u && lp_rate_wait(&l->in_rate, now) == 0u) {
        lp_log("stdin: %lu more lines rejected (not shown)", l->in_held);
        fprintf(stderr, "canopen-sensor: %lu more lines rejected (not shown)\n", l->in_held);
        l->in_held = 0;
    }
}

/* A rejected line: stderr and the log, at most IN_REJECT_LINES a second. */
static void reject_input(loop_t *l, const char *error)
{
    uint32_t now = loop_now_us();
    log_held_input(l, now);
    if (lp_rate_allow(&l->in_rate, now, IN_REJECT_LINES)) {
        char buf[4u * CMD_REPLY_MAX + 8u];
        error = lp_shown(error, buf, sizeof(buf));
        fprintf(stderr, "canopen-sensor: %s\n", error);
        lp_log("stdin rejected: %s", error);
    } else {
        l->in_held++;
    }
}

/* An answer on standard output (the program writes nothing else there
 * while it runs), one line. Never waits: when standard output cannot take
 * the line at once (a pipe nobody reads), it is dropped and counted in
 * the log, and the nodes run on. */
static void answer_out(loop_t *l, const char *answer)
{
    char line[CMD_REPLY_MAX + 1u];
    size_t len = cmd_answer_line(answer, line);
    struct pollfd pf = {.fd = STDOUT_FILENO, .events = POLLOUT};
    /* A pipe with room takes a line of this size whole (atomic below PIPE_BUF). */
    if (poll(&pf, 1, 0) == 1 && (pf.revents & POLLOUT) != 0 &&
        write(STDOUT_FILENO, line, len) == (ssize_t)len) {
        return;
    }
    if (l->out_dropped++ % 100u == 0u) {
        lp_log("standard output cannot take the answer to get: dropped (%lu so far)",
               l->out_dropped);
    }
}

/* One line of standard input: served as the control socket serves it.
 * Blank lines and comments are skipped without an answer (a command file
 * may hold them); "ok" is logged, an error rejected (stderr, the log), any
 * other answer (get's) goes to standard output. */
static void stdin_line(loop_t *l)
{
    char err[64];
    const char *line = cmd_lines_take(&l->in, err, sizeof(err));
    if (line == NULL) {
        reject_input(l, err);
        return;
    }
    size_t i = strspn(line, " \t\r");
    if (line[i] == '\0' || line[i] == '#') {
        return;
    }
    char reply[CMD_REPLY_MAX + 1u];
    cmd_line(l->app, CMD_STDIN, line, loop_now_us(), reply, sizeof(reply));
    if (strncmp(reply, "error: ", 7) == 0) {
        reject_input(l, reply + 7);
        return;
    }
    char buf[4u * CMD_LINE_MAX + 8u];
    lp_log("stdin: %s", lp_shown(line, buf, sizeof(buf)));
    if (strcmp(reply, "ok") != 0) {
        answer_out(l, reply);
    }
}

static void end_of_input(loop_t *l)
{
    if (cmd_lines_pending(&l->in)) {
        stdin_line(l); /* a last line without its newline counts */
    }
    if (l->quit_on_eof) {
        lp_log("end of standard input: stopping (--on-eof quit)");
        l->app->quit = true;
    } else {
        lp_log("end of standard input: running until a signal (--on-eof run)");
    }
}

/* Read what stdin has; returns false at end of input (or a read error). */
static bool read_stdin(loop_t *l)
{
    char buf[512];
    ssize_t n = read(STDIN_FILENO, buf, sizeof(buf));
    if (n < 0 && (errno == EAGAIN || errno == EINTR)) {
        return true;
    }
    if (n < 0) {
        lp_log("standard input: %s: treated as its end", strerror(errno));
    }
    if (n <= 0) {
        end_of_input(l);
        return false;
    }
    for (ssize_t i = 0; i < n; i++) {
        if (cmd_lines_put(&l->in, buf[i])) {
            stdin_line(l);
        }
    }
    return true;
}

/* ---- Control socket ----------------------------------------------------- */

/* ctl_line_fn of the socket: the line's answer with every byte that is
 * not printable ASCII as \xNN (lp_shown), so that a client's escape
 * sequences never come back raw to its terminal; an answer that grows
 * past len is cut short. */
static void control_line(void *ctx, const char *line, char *reply, size_t len)
{
    loop_t *l = ctx;
    char raw[CMD_REPLY_MAX + 1u];
    cmd_line(l->app, CMD_CONTROL, line, loop_now_us(), raw, len < sizeof(raw) ? len : sizeof(raw));
    (void)lp_shown(raw, reply, len);
}

/* ---- Set-up ------------------------------------------------------------- */

int loop_open(loop_t *l, app_t *a, const char *control, bool quit_on_eof, char *err, size_t errlen)
{
    memset(l, 0, sizeof(*l));
    l->app = a;
    l->quit_on_eof = quit_on_eof;
    l->ctl.fd = -1;
    l->sfd = -1;
    l->ep = -1;
    sigset_t sigs;
    loop_stop_signals(&sigs); /* blocked since main()'s first line */
    l->sfd = signalfd(-1, &sigs, SFD_CLOEXEC | SFD_NONBLOCK);
    l->ep = epoll_create1(EPOLL_CLOEXEC);
    if (l->sfd < 0 || l->ep < 0) {
        snprintf(err, errlen, "epoll/signalfd: %s", strerror(errno));
        return -1;
    }
    struct epoll_event ev = {.events = EPOLLIN};
    ev.data.u32 = EV_SIGNAL;
    epoll_ctl(l->ep, EPOLL_CTL_ADD, l->sfd, &ev);
    ev.data.u32 = EV_STDIN;
    /* A pipe or terminal is polled; a regular file or /dev/null cannot be
     * (EPERM): it never blocks, and is read a block at a time in the loop. */
    l->stdin_polled = epoll_ctl(l->ep, EPOLL_CTL_ADD, STDIN_FILENO, &ev) == 0;
    l->stdin_errno = l->stdin_polled ? 0 : errno;
    for (unsigned i = 0; i < a->nnodes; i++) {
        ev.data.u32 = i;
        epoll_ctl(l->ep, EPOLL_CTL_ADD, a->ports[i].fd, &ev);
    }
    if (control != NULL) {
        int r = ctl_open(&l->ctl, control, err, errlen);
        if (r != 0) {
            return r;
        }
        ev.data.u32 = EV_CONTROL;
        epoll_ctl(l->ep, EPOLL_CTL_ADD, ctl_fd(&l->ctl), &ev);
        lp_log("control: listening on %s", control);
    }
    return 0;
}

void loop_start(loop_t *l, uint32_t t)
{
    /* A regular file or a device never blocks: read one block a pass of the
     * loop, at most one a millisecond, so that the nodes run and signals
     * are heard however long (/dev/zero: endless) it is. */
    l->stdin_file = !l->stdin_polled && l->stdin_errno == EPERM;
    if (!l->stdin_polled) {
        if (l->stdin_file) {
            lp_log("standard input is a file or device: read a block a millisecond");
        } else {
            lp_log("standard input cannot be polled (%s)", strerror(l->stdin_errno));
            end_of_input(l);
        }
    }
    l->next_sample = t + CO_FILTER_PERIOD_US;
}

void loop_close(loop_t *l)
{
    ctl_close(&l->ctl);
    if (l->sfd >= 0) {
        close(l->sfd);
    }
    if (l->ep >= 0) {
        close(l->ep);
    }
}

/* ---- Dispatch ----------------------------------------------------------- */

/* What epoll reported for src (EV_SIGNAL, EV_STDIN, the control socket, a
 * client, or a node's socket). */
static void handle_event(loop_t *l, uint32_t src, uint32_t t)
{
    app_t *a = l->app;
    if (src == EV_SIGNAL) {
        struct signalfd_siginfo si;
        if (read(l->sfd, &si, sizeof(si)) == (ssize_t)sizeof(si)) {
            lp_log("signal %u (%s): stopping", si.ssi_signo, strsignal((int)si.ssi_signo));
            a->quit = true;
        }
    } else if (src == EV_STDIN) {
        if (!read_stdin(l)) {
            epoll_ctl(l->ep, EPOLL_CTL_DEL, STDIN_FILENO, NULL);
        }
    } else if (src == EV_CONTROL) {
        int k = ctl_accept(&l->ctl, t);
        if (k >= 0) {
            struct epoll_event ev = {.events = EPOLLIN};
            ev.data.u32 = EV_CLIENT + (uint32_t)k;
            epoll_ctl(l->ep, EPOLL_CTL_ADD, l->ctl.cl[k].fd, &ev);
            l->ctl.cl[k].events = EPOLLIN;
        }
    } else if (src >= EV_CLIENT && src < EV_CLIENT + CTL_CLIENTS) {
        unsigned k = src - EV_CLIENT;
        if (ctl_read(&l->ctl, k, control_line, l, t)) { /* a closed fd leaves epoll */
            /* Reading waits while answers wait (control.h). */
            uint32_t want = ctl_events(&l->ctl, k);
            if (want != l->ctl.cl[k].events) {
                struct epoll_event ev = {.events = want};
                ev.data.u32 = src;
                epoll_ctl(l->ep, EPOLL_CTL_MOD, l->ctl.cl[k].fd, &ev);
                l->ctl.cl[k].events = want;
            }
        }
    } else if (src < a->nnodes && a->ports[src].udp) {
        app_udp_receive(a, src, t);
    } else if (src < a->nnodes) {
        co_frame_t f;
        /* At most 64 frames, then the timers again: a flooded bus must
         * not starve the heartbeat (the rest stay queued in the socket;
         * epoll reports them at once). */
        for (int m = 0; m < 64; m++) {
            int rr = lp_read(&a->ports[src], &f, t);
            if (rr == 0) {
                break;
            }
            if (rr == 1) {
                co_node_receive(a->nodes[src], &f, t);
            }
        }
        app_sync_can_state(a, src);
    }
}

/*
 * The wait from t to the first timer (wait us), stretched to the next
 * point of the grid: the nodes' timers that fall into one grid step are
 * served in one pass, not one pass each. 127 nodes started by one NMT
 * command have their 10 ms TPDOs microseconds apart; waking for each made
 * 127 passes over all 127 nodes every period. A timer is late by less
 * than a step (0.25 ms), and keeps its cadence (the stack counts from
 * when it was due, not from when it ran).
 */
static uint32_t coalesce(uint32_t t, uint32_t wait)
{
    uint32_t due = t + wait;
    uint32_t late = (LOOP_GRID_US - due % LOOP_GRID_US) % LOOP_GRID_US;
    return wait > UINT32_MAX - late ? wait : wait + late;
}

/*
 * epoll for at most wait_us. epoll_pwait2 (Linux 5.11, glibc 2.35) takes
 * the time in nanoseconds; epoll_wait only in whole milliseconds, rounded
 * up here, which made every timer up to a millisecond late: a 10 ms TPDO
 * came 10 to 11 ms apart. Without epoll_pwait2 (an older kernel says
 * ENOSYS once) the milliseconds it is.
 */
static int wait_events(loop_t *l, struct epoll_event *evs, int max, uint32_t wait_us)
{
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 35))
    if (!l->no_pwait2) {
        struct timespec ts = {.tv_sec = (time_t)(wait_us / 1000000u),
                              .tv_nsec = (long)(wait_us % 1000000u) * 1000L};
        int n = epoll_pwait2(l->ep, evs, max, &ts, NULL);
        if (n >= 0 || errno != ENOSYS) {
            return n;
        }
        l->no_pwait2 = true;
    }
#endif
    return epoll_wait(l->ep, evs, max, (int)((wait_us + 999u) / 1000u));
}

/* A pass that took `took` us: the longest is kept, and one longer than
 * LOOP_LONG_PASS_US and than any logged before is logged (a few lines a
 * run at most: each one beats the last). */
static void pass_done(loop_t *l, uint32_t took)
{
    if (took > l->pass_max_us) {
        l->pass_max_us = took;
    }
    if (took > LOOP_LONG_PASS_US && took > l->pass_logged_us) {
        l->pass_logged_us = took;
        lp_log("loop: a pass took %lu.%03lu ms (the longest so far)", (unsigned long)took / 1000u,
               (unsigned long)took % 1000u);
    }
}

int loop_run(loop_t *l)
{
    app_t *a = l->app;
    uint32_t busy_from = loop_now_us(); /* the pass's start: the last wait's end */
    int rc = 0;
    while (!a->quit) {
        uint32_t t = loop_now_us();
        if (!co_time_before(t, l->next_sample)) {
            app_sample(a, t);
            l->next_sample += CO_FILTER_PERIOD_US;
            if (!co_time_before(t, l->next_sample)) {
                l->next_sample = t + CO_FILTER_PERIOD_US; /* we slept too long: no burst */
            }
        }
        bool backlog = false;
        uint32_t wait = app_poll(a, t, LOOP_MAX_WAIT_US, &backlog);
        app_log_states(a);
        log_held_input(l, t);
        if (l->in_held != 0u) {
            wait = co_min_u32(wait, lp_rate_wait(&l->in_rate, t));
        }
        if (backlog) {
            wait = co_min_u32(wait, 1000u); /* retry the kernel's full queue soon */
        }
        wait = co_min_u32(wait, ctl_expire(&l->ctl, t)); /* silent clients closed */
        if (l->stdin_file && !a->quit) {
            l->stdin_file = read_stdin(l);
            wait = l->stdin_file ? co_min_u32(wait, 1000u) : wait;
        }
        struct epoll_event evs[APP_MAX_NODES + 8u]; /* every socket at once: one t for all */
        /* The inputs' sample may wait for a pass that runs anyway (see
         * SAMPLE_SLACK_US); the rest is served on the grid. */
        uint32_t sample_wait = co_time_until(t, l->next_sample) + SAMPLE_SLACK_US;
        pass_done(l, loop_now_us() - busy_from);
        int n = wait_events(l, evs, (int)(APP_MAX_NODES + 8u),
                            co_min_u32(coalesce(t, wait), sample_wait));
        if (n < 0 && errno != EINTR) {
            lp_log("error: epoll_wait: %s", strerror(errno));
            rc = 1;
            break;
        }
        t = loop_now_us();
        busy_from = t;
        for (int k = 0; k < n; k++) {
            handle_event(l, evs[k].data.u32, t);
        }
    }
    pass_done(l, loop_now_us() - busy_from);
    lp_log("loop: the longest pass took %lu.%03lu ms", (unsigned long)l->pass_max_us / 1000u,
           (unsigned long)l->pass_max_us % 1000u);
    return rc;
}
