/*
 * main.c - canopen-sensor: runs products of od/ as a process on SocketCAN
 * interfaces: one (--product) or many instances (--node), each with its
 * own nodes, inputs and EEPROM file. One event loop (epoll) over the CAN sockets,
 * standard input (the simulated physics) and a signalfd; the timeout is
 * the earliest deadline the nodes, the ports (link watch, simulated
 * bus-off), the sensor sampling and the LEDs ask for.
 *
 * Exit status: 0 after a clean stop (quit, end of input with --on-eof
 * quit, SIGINT, SIGTERM, SIGHUP, also while starting: main()); 1 when
 * something the command line names fails at start (no such CAN interface,
 * not CAN, no CAN in the kernel, an EEPROM file that cannot be read, GPIO)
 * or the event loop fails, or --eds / --list-products / --help cannot
 * write; 2 for a wrong command line (including an option given twice, an
 * --nvm that is not a regular file or is in a missing directory, an EEPROM file another
 * user holds, a node-ID clash on one interface, more than 127 nodes, a
 * --control path that exists and is no stale socket, a directory as
 * standard input). Once running, nothing on the bus or the interface ends
 * the process: a lost interface is a cable pull.
 */
#include <errno.h>
#include <getopt.h>
#include <poll.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/signalfd.h>
#include <sys/stat.h>
#include <time.h>
#include <unistd.h>

#include "co_filter.h"
#include "control.h"
#include "eds.h"
#include "leds.h"
#include "port.h"
#include "product.h"
#include "products_json.h"
#include "product_registry.h"
#include "sim.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: canopen-sensor --product ID --iface IFACE [options]\n"
            "       canopen-sensor --node PRODUCT[@NODEID][/IFACE] ... [--iface IFACE] [options]\n"
            "       canopen-sensor --product ID --eds\n"
            "       canopen-sensor --list-products [--json] [--product ID]\n"
            "\n"
            "Runs a simulated CANopen sensor on a SocketCAN interface.\n"
            "\n"
            "  --product ID       product to run (see --list-products)\n"
            "  --iface IFACE      CAN interface, e.g. vcan0; A,B gives a two-node product\n"
            "                     one interface per node\n"
            "  --node PRODUCT[@NODEID][/IFACE]\n"
            "                     one more product instance in this process (repeat it; with\n"
            "                     --product, that one is the first). NODEID (0x21 or 33) is its\n"
            "                     factory node-ID: a blank EEPROM boots with it and restore\n"
            "                     defaults (0x1011) returns to it; a two-node product's second\n"
            "                     node takes NODEID+1. Without it: the product's default.\n"
            "                     IFACE: its interface(s) (A or A,B), else --iface's first.\n"
            "                     127 nodes at most; one factory node-ID twice on one\n"
            "                     interface is refused\n"
            "  --nvm-dir DIR      an EEPROM file per instance: DIR/PRODUCT-0xNN-IFACE.nvm\n"
            "                     (NN: the factory node-ID of its first node, IFACE its\n"
            "                     interface; a two-node product's nodes share one file);\n"
            "                     --nvm, if given, stays --product's\n"
            "  --control unix:PATH|tcp:PORT\n"
            "                     take the standard-input commands from clients of a unix\n"
            "                     socket or a TCP port on 127.0.0.1 too; each line may begin\n"
            "                     with a node selector: 0xNN or NN (the node with that active\n"
            "                     node-ID), @N (node index N, command-line order from 0), @all\n"
            "                     (every instance); none: the first instance. Every line is\n"
            "                     answered: ok, or error: <cause>. get answers the node's true\n"
            "                     inputs and NMT state: ok x=10.000 y=0.000 nmt=operational.\n"
            "                     PATH must not exist, or be a stale socket (replaced)\n"
            "  --nvm FILE         EEPROM file (a regular file, or a new one in an existing\n"
            "                     directory): parameters survive restarts (a restart is a\n"
            "                     power cycle); the first save creates it\n"
            "  --log FILE         write the log there instead of stderr\n"
            "  --log-time start|wall\n"
            "                     the log's time stamps: seconds since the start (the\n"
            "                     default, [  12.345]) or the UTC wall clock\n"
            "                     ([2026-11-25 01:05:12.345])\n"
            "  --on-eof quit|run  at the end of standard input (Ctrl-D, the parent's pipe\n"
            "                     closed): stop (quit, the default) or run on until a signal\n"
            "  --led-chip CHIP    drive the LEDs on this GPIO chip (libgpiod), with\n"
            "  --led-green LINE   the green (run) LED line (default 0) and\n"
            "  --led-red LINE     the red (error) LED line (default 1); without --led-chip\n"
            "                     LED changes are logged\n"
            "  --seed N           seed of the simulated noise (default 1): the same\n"
            "                     commands at the same times give the same values\n"
            "  --serial N         serial number (0x1018 sub 4, the LSS address's last part)\n"
            "                     of the first node; node i of the process (command-line\n"
            "                     order from 0) gets N+i. 1..0xFFFFFFFF (decimal or 0x\n"
            "                     hex). Without it each node's is derived from its product,\n"
            "                     interface and factory node-ID: one per node, never 0, the\n"
            "                     same at every start\n"
            "  --eds              print the product's EDS (CiA 306) and exit\n"
            "  --list-products    print every product ID with a description (with\n"
            "                     --product: that one only)\n"
            "  --json             with --list-products: a JSON array instead, one object a\n"
            "                     product: id, family, summary, vendor, nodes,\n"
            "                     default_node_ids (one per node), default_bitrate_kbps,\n"
            "                     lss, inputs (name, unit, limit, initial), faults\n"
            "  --help             this text\n"
            "\n");
    /* Two literals: C11 compilers need take only 4095 characters in one. */
    fprintf(f,
            "Standard input, one command a line (a bad line is rejected whole; set and\n"
            "fault act on the first instance, or on the nodes a selector at the line's\n"
            "start names, as on --control: 0xNN, NN, @N, @all):\n"
            "  set NAME=VALUE ...         true value of the product's inputs (below)\n"
            "  ramp NAME=VALUE in DUR     linear from the value now to VALUE over DUR\n"
            "                             (e.g. 5s, 250ms), then held\n"
            "  sine NAME amp=A period=DUR around the value now, starting there going up\n"
            "  noise NAME sd=S            Gaussian noise (S in the input's unit) on top of\n"
            "                             the motion; sd=0 stops it\n"
            "  replay FILE.csv            header t,NAME,... then rows SECONDS,VALUE,...\n"
            "                             from now: linear between rows, last row held\n"
            "    set/ramp/sine/replay replace an input's motion, noise stays; values\n"
            "    beyond an input's limit are refused, noise is saturated at it\n"
            "  fault NAME on|off          force one of the product's faults (below)\n"
            "  can bus-off [SECONDS]      the CAN controller goes bus-off: nothing sent; the\n"
            "                             bus stays unusable SECONDS (default 0), then it\n"
            "                             is back after 128 x 11 bits at its bit rate\n"
            "  can passive|warning|active the controller's error state\n"
            "  quit                       stop\n"
            "  get                        true inputs and NMT state (on standard input:\n"
            "                             the first node's, answered on standard output)\n"
            "\n"
            "Exit status: 0 clean stop (quit, end of input, SIGINT, SIGTERM, SIGHUP, also\n"
            "while starting); 1 failure at start (interface, EEPROM read, GPIO), of the\n"
            "event loop or of the output; 2 wrong command line (an option twice: only\n"
            "--node repeats; an EEPROM file another process holds).\n"
            "\n"
            "Products, their inputs and faults:\n");
    for (size_t i = 0; product_list[i] != NULL; i++) {
        char d[256];
        sim_describe(product_list[i], d, sizeof(d));
        fprintf(f, "  %-16s %s\n", product_list[i]->id, d);
    }
}

/* Standard output flushed after what option opt printed (--help,
 * --list-products, --eds): 0, or 1 with one line on stderr when it could
 * not be written (a full disk, a closed pipe), so that a caller never
 * takes a cut list for a whole one. */
static int stdout_done(const char *opt)
{
    if (fflush(stdout) != 0 || ferror(stdout)) {
        fprintf(stderr, "canopen-sensor: %s: standard output: %s\n", opt, strerror(errno));
        return 1;
    }
    return 0;
}

/* A wrong command line: one line with the cause on stderr. */
static void usage_print(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
static void usage_print(const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof(msg), fmt, ap);
    va_end(ap);
    fprintf(stderr, "canopen-sensor: %s (see --help)\n", msg);
}

/* usage_print(), then exit status 2: a macro, so that the status is seen
 * where it is returned (clang's analyzer does not follow a variadic call,
 * and would take a wrong command line for one that goes on). */
#define USAGE_ERROR(...) ((void)usage_print(__VA_ARGS__), 2)

/* A failure at start: one line on stderr, and in the log when it is a file. */
static int start_failure(bool log_file, int rc, const char *msg)
{
    fprintf(stderr, "canopen-sensor: %s\n", msg);
    if (log_file) {
        lp_log("error: %s", msg);
    }
    return rc;
}

static uint32_t now_us(void)
{
    struct timespec ts;
    clock_gettime(CLOCK_MONOTONIC, &ts);
    return (uint32_t)((uint64_t)ts.tv_sec * 1000000u + (uint64_t)ts.tv_nsec / 1000u);
}

/*
 * A number as the command line and the control lines write it: decimal
 * digits ("33", "033" is 33 too: no octal), or 0x and hex digits ("0x21").
 * No sign, no blanks. True with *out (at most max), false otherwise.
 */
static bool parse_number(const char *s, long max, long *out)
{
    bool hex = s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
    const char *d = hex ? s + 2 : s;
    size_t n = strspn(d, hex ? "0123456789abcdefABCDEF" : "0123456789");
    if (n == 0u || d[n] != '\0' || n > 9u) {
        return false;
    }
    long v = strtol(d, NULL, hex ? 16 : 10);
    if (v > max) {
        return false;
    }
    *out = v;
    return true;
}

/* --serial: decimal or 0x hex as parse_number, 1..0xFFFFFFFF (0 is no serial). */
static bool parse_serial(const char *s, uint32_t *out)
{
    bool hex = s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
    const char *d = hex ? s + 2 : s;
    size_t n = strspn(d, hex ? "0123456789abcdefABCDEF" : "0123456789");
    if (n == 0u || d[n] != '\0' || n > 10u) {
        return false;
    }
    unsigned long long v = strtoull(d, NULL, hex ? 16 : 10);
    if (v == 0u || v > 0xFFFFFFFFu) {
        return false;
    }
    *out = (uint32_t)v;
    return true;
}

/*
 * The serial number of a node without --serial: FNV-1a over its product ID,
 * interface and factory node-ID (all three fixed by the command line, so
 * the same at every start), 0 taken as 1. Two nodes of one process differ
 * in one of them (one factory node-ID twice on one interface is refused),
 * so their LSS addresses differ but for a 32-bit hash collision.
 */
static uint32_t derived_serial(const char *product, const char *iface, uint8_t id)
{
    uint32_t h = 2166136261u;
    const char *parts[2] = {product, iface};
    for (unsigned k = 0; k < 2u; k++) {
        for (const char *c = parts[k]; *c != '\0'; c++) {
            h = (h ^ (uint8_t)*c) * 16777619u;
        }
        h *= 16777619u; /* a separator: "ab"+"c" is not "a"+"bc" */
    }
    h = (h ^ id) * 16777619u;
    return h != 0u ? h : 1u;
}

static int parse_int(const char *s, int *out)
{
    long v;
    if (!parse_number(s, 4096, &v)) {
        return -1;
    }
    *out = (int)v;
    return 0;
}

/* Rejected input lines: at most this many logged a second, the rest counted. */
#define IN_REJECT_LINES 5u

/* Nodes in one process at most: one bus holds 127 node-IDs. */
#define APP_MAX_NODES 127u

/* epoll's tags: a node's socket is tagged with the node's index. */
#define EV_SIGNAL 1000u
#define EV_STDIN 1001u
#define EV_CONTROL 1002u /* the control socket's listening socket */
#define EV_CLIENT 2000u  /* + slot: a control client */

/* One product instance (--product, or one --node): its nodes are
 * app_t.nodes[first .. first + prod->nodes - 1]; its own inputs (sim), its
 * own EEPROM file (both nodes of a two-node product share it, as they
 * share the device). */
typedef struct app_inst {
    const product_t *prod;
    unsigned first;
    sim_t sim;
    lp_nvm_t nvm;
    uint8_t nvm_mem[PRODUCT_MAX_NODES * CO_STORE_NVM_SIZE];
    _Alignas(max_align_t) unsigned char mem[sizeof(product_any_t)];
} app_inst_t;

typedef struct app {
    const product_t *prod; /* the first instance's */
    unsigned nnodes;
    unsigned ninst;
    uint8_t node_inst[APP_MAX_NODES]; /* each node's instance */
    co_node_t *nodes[APP_MAX_NODES];
    lp_port_t ports[APP_MAX_NODES];
    leds_t leds[APP_MAX_NODES];
    uint8_t last_state[APP_MAX_NODES];
    uint8_t last_id[APP_MAX_NODES]; /* active node-IDs last looked at (log_states) */
    const char *ifn[APP_MAX_NODES]; /* each node's interface */
    app_inst_t inst[APP_MAX_NODES];
    sim_t sim; /* standard input's line assembly, quit and `can`; its
                * set/fault lines go to the first instance (copied) */
    bool quit_on_eof;
    lp_rate_t in_rate;
    unsigned long in_held; /* rejected lines not logged yet */
    /* Set up by set_up(), used by the loop: */
    int sfd;               /* signalfd: SIGINT, SIGTERM, SIGHUP */
    int ep;                /* epoll over sfd, stdin and the CAN sockets */
    bool stdin_file;       /* stdin cannot be polled: read a block a pass */
    uint32_t next_sample;  /* when the products sample their inputs next */
    ctl_t ctl;             /* --control (ctl.fd -1: none) */
    lp_tx_t tx;            /* the one sending socket (port.h) */
    sim_replay_t replay;   /* a control line's replay table (control_replay) */
    unsigned long out_dropped; /* answers to get that standard output could not take */
    bool stdin_line;       /* control_line serves a line of standard input (it logs it not) */
    bool no_pwait2;        /* the kernel has no epoll_pwait2: epoll_wait */
} app_t;

/* The node sees the CAN state its port shows (link, error frames, simulator). */
static void sync_can_state(app_t *a, unsigned i)
{
    co_can_state_t s = lp_can_state(&a->ports[i]);
    if (s != co_node_can_state(a->nodes[i])) {
        co_node_set_can_state(a->nodes[i], s);
    }
}

/* A `can` command of sim sm: the simulated controllers of nodes
 * [first, end) (standard input: every node; control: the selected). */
static void apply_can_nodes(app_t *a, sim_t *sm, unsigned first, unsigned end, uint32_t now)
{
    if (!sm->can_request) {
        return;
    }
    sm->can_request = false;
    for (unsigned i = first; i < end; i++) {
        uint32_t kbps = a->ports[i].kbps;
        if (kbps == 0u) {
            kbps = 125u; /* a code the product does not define: the usual default */
        }
        /* 128 x 11 recessive bits at the node's bit rate, rounded up */
        uint32_t recovery_us = (LP_BUSOFF_RECOVERY_BITS * 1000u + kbps - 1u) / kbps;
        lp_sim_can(&a->ports[i], sm->can_state, now, sm->can_hold_ms * 1000u, recovery_us);
        sync_can_state(a, i);
    }
}

/* A `can` command from standard input: every node's simulated controller. */
static void apply_can_command(app_t *a, uint32_t now)
{
    apply_can_nodes(a, &a->sim, 0, a->nnodes, now);
}

static void log_held_input(app_t *a, uint32_t now)
{
    if (a->in_held != 0u && lp_rate_wait(&a->in_rate, now) == 0u) {
        lp_log("stdin: %lu more lines rejected (not shown)", a->in_held);
        fprintf(stderr, "canopen-sensor: %lu more lines rejected (not shown)\n", a->in_held);
        a->in_held = 0;
    }
}

static void control_get(app_t *a, unsigned node, char *reply, size_t len);
static void control_line(void *ctx, const char *line, char *reply, size_t len);

/* A `get` on standard input: the first node's answer, as the control
 * socket gives it, on standard output (the program writes nothing else
 * there while it runs), one line. Never waits: when standard output
 * cannot take the line at once (a pipe nobody reads), the answer is
 * dropped and counted in the log, and the nodes run on. */
static void answer_line(app_t *a, char *reply);

static void answer_get(app_t *a)
{
    if (!a->sim.get_request) {
        return;
    }
    a->sim.get_request = false;
    char reply[CTL_REPLY_MAX + 2u];
    control_get(a, 0, reply, sizeof(reply) - 1u);
    answer_line(a, reply);
}

/* One answer line (reply: CTL_REPLY_MAX + 2 bytes, room for the newline)
 * on standard output, or dropped and counted. */
static void answer_line(app_t *a, char *reply)
{
    size_t n = strlen(reply);
    reply[n++] = '\n';
    struct pollfd pf = {.fd = STDOUT_FILENO, .events = POLLOUT};
    /* A pipe with room takes a line of this size whole (atomic below PIPE_BUF). */
    if (poll(&pf, 1, 0) == 1 && (pf.revents & POLLOUT) != 0 &&
        write(STDOUT_FILENO, reply, n) == (ssize_t)n) {
        return;
    }
    if (a->out_dropped++ % 100u == 0u) {
        lp_log("standard output cannot take the answer to get: dropped (%lu so far)",
               a->out_dropped);
    }
}

/* text as the log shows it: a byte that is not printable ASCII (control
 * characters, binary input, also UTF-8) as \xNN, so that what standard
 * input holds never reaches the log or a terminal raw. */
static const char *shown(const char *text, char *out, size_t len)
{
    size_t at = 0;
    for (const unsigned char *c = (const unsigned char *)text; *c != '\0' && at + 5u < len; c++) {
        if (*c >= 0x20u && *c < 0x7Fu && *c != '\\') {
            out[at++] = (char)*c;
        } else {
            at += (size_t)snprintf(out + at, len - at, "\\x%02X", *c);
        }
    }
    out[at] = '\0';
    return out;
}

/*
 * sim_t.route of standard input: a line that begins with a node selector
 * (0xNN, NN, @N, @all: control.h) is served as the control socket serves
 * it; its error comes back as a rejection (stderr, the log), the answer to
 * a selected `get` goes to standard output. Other lines stay standard
 * input's own (the first instance, as before).
 */
static bool route_selected(void *ctx, const char *line, char *err, unsigned errlen)
{
    app_t *a = ctx;
    const char *p = line + strspn(line, " \t");
    if (p[0] != '@' && (p[0] < '0' || p[0] > '9')) {
        return false;
    }
    char reply[CTL_REPLY_MAX + 2u];
    a->stdin_line = true;
    control_line(a, line, reply, CTL_REPLY_MAX + 1u);
    a->stdin_line = false;
    err[0] = '\0';
    if (strncmp(reply, "error: ", 7) == 0) {
        snprintf(err, errlen, "%s", reply + 7);
    } else if (strcmp(reply, "ok") != 0) {
        answer_line(a, reply); /* get */
    }
    return true;
}

/* sim_report_fn: the log (and stderr for rejections, rate-limited). */
static void report_line(void *ctx, const char *line, const char *error)
{
    app_t *a = ctx;
    char buf[4u * SIM_LINE_MAX + 300u];
    if (error == NULL) {
        lp_log("stdin: %s", shown(line, buf, sizeof(buf)));
        apply_can_command(a, now_us()); /* each `can` line when it comes */
        answer_get(a);
        return;
    }
    uint32_t now = now_us();
    log_held_input(a, now);
    if (lp_rate_allow(&a->in_rate, now, IN_REJECT_LINES)) {
        error = shown(error, buf, sizeof(buf));
        fprintf(stderr, "canopen-sensor: %s\n", error);
        lp_log("stdin rejected: %s", error);
    } else {
        a->in_held++;
    }
}

static void end_of_input(app_t *a)
{
    sim_feed_end(&a->sim, report_line, a);
    if (a->quit_on_eof) {
        lp_log("end of standard input: stopping (--on-eof quit)");
        a->sim.quit = true;
    } else {
        lp_log("end of standard input: running until a signal (--on-eof run)");
    }
}

/* Read what stdin has; returns false at end of input (or a read error). */
static bool read_stdin(app_t *a)
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
        end_of_input(a);
        return false;
    }
    sim_feed(&a->sim, buf, (size_t)n, report_line, a);
    return true;
}

static const char *nmt_name(uint8_t s)
{
    static const char *const names[] = {[0x00] = "initialising", [0x04] = "stopped",
                                        [0x05] = "operational", [0x7F] = "pre-operational"};
    return (s < sizeof(names) / sizeof(names[0]) && names[s]) ? names[s] : "?";
}

/*
 * Two nodes of this process with one active node-ID on one interface:
 * logged (a warning each time the node-IDs change into a clash), nothing
 * else. The command line's factory node-IDs are checked at start (exit
 * 2), but a stored node-ID, an SDO write or LSS can make a clash later;
 * the nodes run on, as real devices would, and their frames collide on
 * the bus: the log says why.
 */
static void log_id_clashes(const app_t *a)
{
    for (unsigned i = 0; i < a->nnodes; i++) {
        uint8_t id = co_node_id(a->nodes[i]);
        for (unsigned j = 0; j < i && id >= 1u && id <= 127u; j++) {
            if (co_node_id(a->nodes[j]) == id && strcmp(a->ifn[i], a->ifn[j]) == 0) {
                lp_log("warning: node %u (%s) and node %u (%s) both have node-ID 0x%02X on %s: "
                       "their frames collide", j, a->inst[a->node_inst[j]].prod->id, i,
                       a->inst[a->node_inst[i]].prod->id, id, a->ifn[i]);
            }
        }
    }
}

/* NMT state changes in the log; node-ID changes checked for clashes. */
static void log_states(app_t *a)
{
    bool ids_changed = false;
    for (unsigned i = 0; i < a->nnodes; i++) {
        uint8_t s = (uint8_t)co_node_nmt_state(a->nodes[i]);
        if (s != a->last_state[i]) {
            const char *name = nmt_name(s);
            lp_log("node %u (ID 0x%02X): NMT %s", i, co_node_id(a->nodes[i]), name);
            a->last_state[i] = s;
        }
        uint8_t id = co_node_id(a->nodes[i]);
        if (id != a->last_id[i]) {
            a->last_id[i] = id;
            ids_changed = true;
        }
    }
    if (ids_changed) {
        log_id_clashes(a);
    }
}

/* After the start: say which stored sets could not be used (the stack
 * flags them over CAN too, per product: 0x4001, EMCY, LEDs). */
static void log_store_status(app_t *a)
{
    static const struct {
        co_cls_t cls;
        const char *what;
    } sets[] = {{CO_CLS_PARA, "parameters"}, {CO_CLS_LSS, "node-ID and bit rate"}};
    for (unsigned i = 0; i < a->nnodes; i++) {
        const lp_nvm_t *nvm = &a->inst[a->node_inst[i]].nvm;
        const char *file = nvm->path != NULL ? nvm->real : "(RAM)";
        for (unsigned k = 0; k < sizeof(sets) / sizeof(sets[0]); k++) {
            if (co_cfg(a->nodes[i])->ram_size[sets[k].cls] == 0u) {
                continue;
            }
            co_store_status_t st = co_node_store_status(a->nodes[i], sets[k].cls);
            if (st == CO_STORE_CORRUPT || st == CO_STORE_HW) {
                lp_log("node %u: EEPROM file %s: stored %s %s: factory defaults in use until "
                       "the next save (the file is left as it is until then)",
                       i, file, sets[k].what,
                       st == CO_STORE_CORRUPT ? "corrupt (neither blank nor a valid record)"
                                              : "unreadable (read error)");
            }
        }
    }
}

/* The command line, as parse_options() leaves it. */
/* One product instance the command line asks for (--product, --node). */
typedef struct node_spec {
    const product_t *prod;
    uint8_t id;        /* factory node-ID of its first node (the next one +1), 0: product's */
    const char *iface; /* its interfaces ("A" or "A,B"), NULL: --iface's first */
    const char *arg;   /* the option's text, for messages */
    /* the interfaces split at their commas (split_ifaces); ifn[] points into ifbuf */
    char ifbuf[PRODUCT_MAX_NODES * IFNAMSIZ + 8];
    const char *ifn[PRODUCT_MAX_NODES];
} node_spec_t;

typedef struct options {
    const product_t *prod;
    const char *iface;
    const char *nvm_path;
    const char *nvm_dir;
    const char *control; /* --control unix:PATH | tcp:PORT, or NULL */
    node_spec_t spec[APP_MAX_NODES]; /* --product first (if given), then each --node */
    unsigned nspec;
    unsigned nnodes_total;
    const char *log_path;
    const char *led_chip;
    const char *led_line_opt; /* the last --led-green/--led-red given, or NULL */
    int led_green;
    int led_red;
    bool eds;
    bool quit_on_eof;
    uint64_t seed; /* --seed: the simulator's noise (instance k: seed + k) */
    uint32_t serial; /* --serial: node i's 0x1018 sub 4 is serial + i; 0: derived */
} options_t;

/* Not an exit status: go on (parse_options, set_up). */
#define GO_ON (-1)

/* --iface: one interface for all nodes, or one per node ("A,B"). Returns
 * GO_ON or the exit status of a wrong command line. */
static int split_ifaces(node_spec_t *o)
{
    const product_t *prod = o->prod;
    const char *iface = o->iface;
    if (snprintf(o->ifbuf, sizeof(o->ifbuf), "%s", iface) >= (int)sizeof(o->ifbuf)) {
        return USAGE_ERROR("--iface %s: too long", iface);
    }
    unsigned nif = 0;
    for (char *s = o->ifbuf, *comma;; s = comma + 1) {
        comma = strchr(s, ',');
        if (comma != NULL) {
            *comma = '\0';
        }
        if (s[0] == '\0' || strlen(s) >= IFNAMSIZ) {
            return USAGE_ERROR("--iface %s: '%s' is not an interface name", iface, s);
        }
        if (nif == prod->nodes) {
            return prod->nodes == 1u
                       ? USAGE_ERROR("%s has one node: give one interface, not '%s'", prod->id,
                                     iface)
                       : USAGE_ERROR("%s has %u nodes: give one interface, or one per node "
                                     "(A,B), not '%s'", prod->id, prod->nodes, iface);
        }
        o->ifn[nif++] = s;
        if (comma == NULL) {
            break;
        }
    }
    for (unsigned i = nif; i < prod->nodes; i++) {
        o->ifn[i] = o->ifn[0];
    }
    return GO_ON;
}

/* --node PRODUCT[@NODEID][/IFACE] into the next spec. Returns GO_ON or 2. */
static int parse_node(options_t *o, const char *arg)
{
    if (o->nspec == APP_MAX_NODES) {
        return USAGE_ERROR("more than %u nodes in one process", APP_MAX_NODES);
    }
    node_spec_t *n = &o->spec[o->nspec];
    char name[64];
    const char *slash = strchr(arg, '/');
    size_t len = slash != NULL ? (size_t)(slash - arg) : strlen(arg);
    if (len >= sizeof(name)) {
        return USAGE_ERROR("--node %s: unknown product (see --list-products)", arg);
    }
    memcpy(name, arg, len);
    name[len] = '\0';
    char *at = strchr(name, '@');
    if (at != NULL) {
        *at = '\0';
        long id = 0;
        if (!parse_number(at + 1, 127, &id) || id < 1) {
            return USAGE_ERROR("--node %s: node-ID '%s' is not 1..127 (e.g. 0x21 or 33)", arg,
                               at + 1);
        }
        n->id = (uint8_t)id;
    }
    n->prod = product_find(name);
    if (n->prod == NULL) {
        return USAGE_ERROR("--node %s: unknown product '%s' (see --list-products)", arg, name);
    }
    if (n->id != 0u && n->id + n->prod->nodes - 1u > 127u) {
        return USAGE_ERROR("--node %s: %s has %u nodes, node-IDs 0x%02X to 0x%02X: the last "
                           "passes 127 (give at most 0x%02X)", arg, n->prod->id, n->prod->nodes,
                           n->id, n->id + n->prod->nodes - 1u, 128u - n->prod->nodes);
    }
    n->iface = slash != NULL ? slash + 1 : NULL;
    n->arg = arg;
    o->nspec++;
    return GO_ON;
}

/* The specs' interfaces and node count, checked after the options. */
static int check_specs(options_t *o)
{
    o->nnodes_total = 0;
    for (unsigned k = 0; k < o->nspec; k++) {
        node_spec_t *n = &o->spec[k];
        if (n->iface == NULL) {
            if (o->iface == NULL) {
                return USAGE_ERROR("--node %s: no interface (give /IFACE or --iface)", n->arg);
            }
            size_t l = strcspn(o->iface, ",");
            if (l >= IFNAMSIZ) {
                return USAGE_ERROR("--iface %s: too long", o->iface);
            }
            memcpy(n->ifbuf, o->iface, l); /* the first of --iface's */
            n->ifbuf[l] = '\0';
            for (unsigned i = 0; i < PRODUCT_MAX_NODES; i++) {
                n->ifn[i] = n->ifbuf;
            }
        } else {
            int rc = split_ifaces(n);
            if (rc != GO_ON) {
                return rc;
            }
        }
        o->nnodes_total += n->prod->nodes;
    }
    if (o->nnodes_total > APP_MAX_NODES) {
        return USAGE_ERROR("%u nodes: at most %u in one process", o->nnodes_total, APP_MAX_NODES);
    }
    if (o->serial != 0u && o->serial > 0xFFFFFFFFu - (o->nnodes_total - 1u)) {
        return USAGE_ERROR("--serial 0x%08lX: %u nodes take 0x%08lX..0x%08lX, past 0xFFFFFFFF",
                           (unsigned long)o->serial, o->nnodes_total, (unsigned long)o->serial,
                           (unsigned long)o->serial + o->nnodes_total - 1u);
    }
    return GO_ON;
}

/* The command line into *o, checked: returns GO_ON, 0 after --help or
 * --list-products (printed; 1 when they could not be), or 2 for a wrong
 * command line (one line on stderr). With --eds only the product is checked. Nothing is opened. */
static int parse_options(int argc, char **argv, options_t *o)
{
    memset(o, 0, sizeof(*o));
    const char *product = NULL;
    bool list = false;
    bool json = false;
    o->led_green = 0;
    o->led_red = 1;
    /* --on-eof quit by default: standard input is the sensor's tie to whoever
     * started it. A CI job whose parent exits or dies closes the pipe, and
     * the sensor leaves the bus instead of running on as an orphan; Ctrl-D
     * stops it too. No PR_SET_PDEATHSIG: it fires when the parent *thread*
     * ends (a Python thread that started the sensor, the process living on)
     * and would kill a sensor a script starts in the background on purpose.
     * --on-eof run is for input that ends at once (/dev/null, a daemon, a
     * file of commands, tools/vcan-run). */
    o->quit_on_eof = true;
    o->seed = SIM_SEED_DEFAULT;
    static const struct option opts[] = {
        {"product", required_argument, NULL, 'p'}, {"iface", required_argument, NULL, 'i'},
        {"nvm", required_argument, NULL, 'n'},     {"log", required_argument, NULL, 'l'},
        {"led-chip", required_argument, NULL, 'c'}, {"led-green", required_argument, NULL, 'g'},
        {"led-red", required_argument, NULL, 'r'}, {"list-products", no_argument, NULL, 'L'},
        {"eds", no_argument, NULL, 'E'},           {"on-eof", required_argument, NULL, 'o'},
        {"seed", required_argument, NULL, 's'},
        {"help", no_argument, NULL, 'h'},          {"json", no_argument, NULL, 'J'},
        {"node", required_argument, NULL, 'N'},
        {"nvm-dir", required_argument, NULL, 'D'}, {"control", required_argument, NULL, 'C'},
        {"log-time", required_argument, NULL, 'T'}, {"serial", required_argument, NULL, 'S'},
        {NULL, 0, NULL, 0},
    };
    opterr = 0; /* our own one-line messages */
    /* One rule for every option: each is given once, but --node, which
     * adds an instance each time. A second --iface, --nvm, --seed, ... is
     * a wrong command line (exit 2) rather than the last one silently
     * winning, so that a script that adds an option to a command line it
     * was given does not change what runs without a word. */
    bool seen[sizeof(opts) / sizeof(opts[0])] = {false};
    int c;
    int li = -1;
    while ((c = getopt_long(argc, argv, ":", opts, &li)) != -1) {
        if (c != ':' && c != '?' && li >= 0 && opts[li].val != 'N') {
            if (seen[li]) {
                return USAGE_ERROR("--%s given twice (every option but --node at most once)",
                                   opts[li].name);
            }
            seen[li] = true;
        }
        li = -1;
        switch (c) {
        case 'p': product = optarg; break;
        case 'i': o->iface = optarg; break;
        case 'n': o->nvm_path = optarg; break;
        case 'D': o->nvm_dir = optarg; break;
        case 'C': o->control = optarg; break;
        case 'N': {
            int rc = parse_node(o, optarg);
            if (rc != GO_ON) {
                return rc;
            }
            break;
        }
        case 'l': o->log_path = optarg; break;
        case 'c': o->led_chip = optarg; break;
        case 'g':
        case 'r':
            if (parse_int(optarg, c == 'g' ? &o->led_green : &o->led_red) != 0) {
                return USAGE_ERROR("bad GPIO line '%s'", optarg);
            }
            o->led_line_opt = c == 'g' ? "--led-green" : "--led-red";
            break;
        case 'T':
            if (strcmp(optarg, "start") != 0 && strcmp(optarg, "wall") != 0) {
                return USAGE_ERROR("--log-time takes start or wall, not '%s'", optarg);
            }
            lp_log_clock(strcmp(optarg, "wall") == 0);
            break;
        case 'o':
            if (strcmp(optarg, "quit") != 0 && strcmp(optarg, "run") != 0) {
                return USAGE_ERROR("--on-eof takes quit or run, not '%s'", optarg);
            }
            o->quit_on_eof = strcmp(optarg, "quit") == 0;
            break;
        case 's': {
            char *end;
            errno = 0;
            o->seed = strtoull(optarg, &end, 10);
            if (end == optarg || *end != '\0' || errno != 0 || optarg[0] == '-') {
                return USAGE_ERROR("--seed takes a number 0..2^64-1, not '%s'", optarg);
            }
            break;
        }
        case 'S':
            if (!parse_serial(optarg, &o->serial)) {
                return USAGE_ERROR("--serial takes a serial number 1..0xFFFFFFFF (decimal or 0x "
                                   "hex), not '%s'", optarg);
            }
            break;
        case 'E':
            o->eds = true;
            break;
        case 'L':
            list = true;
            break;
        case 'J':
            json = true;
            break;
        case 'h':
            usage(stdout);
            return stdout_done("--help");
        case ':':
            return USAGE_ERROR("option %s needs a value", argv[optind - 1]);
        default:
            return USAGE_ERROR("unknown option '%s'", argv[optind - 1]);
        }
    }
    if (optind != argc) {
        return USAGE_ERROR("unexpected argument '%s'", argv[optind]);
    }
    if (json && !list) {
        return USAGE_ERROR("--json goes with --list-products");
    }
    if (list) {
        /* With --product: that product alone (to ask about one). */
        const product_t *only = product != NULL ? product_find(product) : NULL;
        if (product != NULL && only == NULL) {
            return USAGE_ERROR("unknown product '%s' (see --list-products)", product);
        }
        if (json) {
            if (products_json(stdout, only) != 0) {
                fprintf(stderr, "canopen-sensor: --list-products: standard output: %s\n",
                        strerror(errno));
                return 1;
            }
            return 0;
        }
        for (size_t i = 0; product_list[i] != NULL; i++) {
            if (only == NULL || product_list[i] == only) {
                printf("%-18s %s\n", product_list[i]->id, product_list[i]->summary);
            }
        }
        return stdout_done("--list-products");
    }
    if (product == NULL && (o->nspec == 0u || o->eds)) {
        return USAGE_ERROR("--product is missing");
    }
    if (product != NULL) {
        o->prod = product_find(product);
        if (o->prod == NULL) {
            return USAGE_ERROR("unknown product '%s' (see --list-products)", product);
        }
    }
    if (o->eds) {
        return GO_ON;
    }
    if (o->iface == NULL && o->nspec == 0u) {
        return USAGE_ERROR("--iface is missing");
    }
    if (o->nvm_path != NULL && o->prod == NULL) {
        return USAGE_ERROR("--nvm is the --product node's EEPROM file: use --nvm-dir with --node");
    }
    if (o->led_line_opt != NULL && o->led_chip == NULL) {
        return USAGE_ERROR("%s needs --led-chip", o->led_line_opt);
    }
    if (o->led_chip != NULL && o->led_green == o->led_red) {
        return USAGE_ERROR("--led-green and --led-red are the same line (%d)", o->led_green);
    }
    if (o->prod != NULL) { /* --product (and --iface "A,B") first: node 0 as before */
        if (o->nspec == APP_MAX_NODES) {
            return USAGE_ERROR("more than %u nodes in one process", APP_MAX_NODES);
        }
        memmove(&o->spec[1], &o->spec[0], o->nspec * sizeof(o->spec[0]));
        memset(&o->spec[0], 0, sizeof(o->spec[0]));
        o->spec[0].prod = o->prod;
        o->spec[0].iface = o->iface;
        o->spec[0].arg = o->prod->id;
        o->nspec++;
    }
    return check_specs(o);
}

/* --eds: the product's EDS on stdout; returns the exit status. */
static int print_eds(const product_t *prod)
{
    if (eds_write(stdout, prod) != 0) {
        fprintf(stderr, "canopen-sensor: %s: EDS overrides that apply to no entry\n", prod->id);
        return 1;
    }
    return stdout_done("--eds");
}

/* The EEPROM file of instance k: --nvm for the --product instance, else
 * DIR/PRODUCT-0xID-IFACE.nvm with --nvm-dir (ID: the factory node-ID of
 * the instance's first node, from the command line or the product's
 * default; IFACE: its interface; a two-node product's both nodes share
 * its file, as they share the device), else none (RAM). Returns 0, or -1
 * when the name is too long. */
static int nvm_file(const options_t *o, unsigned k, uint8_t id, char *buf, size_t len,
                    const char **path)
{
    *path = NULL;
    if (k == 0u && o->prod != NULL && o->nvm_path != NULL) {
        *path = o->nvm_path;
    } else if (o->nvm_dir != NULL) {
        /* The interface is in the name: the same product at the same
         * node-ID on two buses is two devices, two files. */
        if (snprintf(buf, len, "%s/%s-0x%02X-%s.nvm", o->nvm_dir, o->spec[k].prod->id, id,
                     o->spec[k].ifn[0]) >= (int)len) {
            return -1;
        }
        *path = buf;
    }
    return 0;
}

/* Two nodes with one factory node-ID on one interface: a usage error
 * (checked before any node starts). Returns GO_ON or 2. */
static int check_clashes(const app_t *a)
{
    for (unsigned i = 0; i < a->nnodes; i++) {
        for (unsigned j = 0; j < i; j++) {
            if (strcmp(a->ifn[i], a->ifn[j]) == 0 &&
                co_node_factory_id(a->nodes[i]) == co_node_factory_id(a->nodes[j])) {
                return USAGE_ERROR("node-ID 0x%02X twice on %s (%s and %s): give each node its "
                                   "own with --node PRODUCT@ID",
                                   co_node_factory_id(a->nodes[i]), a->ifn[i],
                                   a->inst[a->node_inst[j]].prod->id,
                                   a->inst[a->node_inst[i]].prod->id);
            }
        }
    }
    return GO_ON;
}

/* Create instance k and give its nodes their factory node-IDs (not
 * started). Returns GO_ON or an exit status. */
static int set_up_inst(app_t *a, const options_t *o, unsigned k, bool logf)
{
    const node_spec_t *n = &o->spec[k];
    app_inst_t *in = &a->inst[k];
    in->prod = n->prod;
    in->first = a->nnodes;
    sim_init(&in->sim, in->prod);
    if (in->prod->inst_size > sizeof(in->mem)) {
        return start_failure(logf, 1, "product instance too large");
    }
    void *ports[PRODUCT_MAX_NODES];
    for (unsigned i = 0; i < in->prod->nodes; i++) {
        unsigned g = in->first + i;
        a->node_inst[g] = (uint8_t)k;
        a->ifn[g] = n->ifn[i];
        ports[i] = &a->ports[g];
    }
    /* create() only keeps the port pointers (co_node_init calls no board
     * function): the factory node-IDs are checked for clashes and name the
     * EEPROM files, which are looked at before any socket opens (a FIFO
     * must not hang the start). */
    in->prod->create(in->prod, in->mem, ports, &a->nodes[in->first]);
    a->nnodes += in->prod->nodes;
    for (unsigned i = 0; i < in->prod->nodes && n->id != 0u; i++) {
        co_node_set_factory_id(a->nodes[in->first + i], (uint8_t)(n->id + i));
    }
    /* Each node its own serial number, so that LSS can address it (CiA 305). */
    for (unsigned i = 0; i < in->prod->nodes; i++) {
        unsigned g = in->first + i;
        co_node_set_serial(a->nodes[g], o->serial != 0u ? o->serial + g
                                                        : derived_serial(in->prod->id, a->ifn[g],
                                                                         co_node_factory_id(a->nodes[g])));
    }
    return GO_ON;
}

/* The name instance k's --nvm-dir file had before the interface was in
 * it (DIR/PRODUCT-0xID.nvm), into buf; false when it does not apply. */
static bool former_nvm_name(const options_t *o, unsigned k, uint8_t id, char *buf, size_t len)
{
    return o->nvm_dir != NULL && !(k == 0u && o->prod != NULL && o->nvm_path != NULL) &&
           snprintf(buf, len, "%s/%s-0x%02X.nvm", o->nvm_dir, o->spec[k].prod->id, id) <
               (int)len;
}

/*
 * Open instance k's EEPROM file (read only: nothing on disk changes) and
 * hold it (port.h, lp_nvm_lock: one file, one user, also when --nvm and
 * --nvm-dir name it both). Returns GO_ON or an exit status.
 * The name before the interface was in it (DIR/PRODUCT-0xID.nvm) is
 * taken over when the new name does not exist yet, so that a stored set
 * saved by an earlier version is not silently left behind: read from
 * there now, renamed by rename_former_nvm() once the whole start has
 * worked (a failed start changes nothing on disk). *former tells.
 */
static int open_inst_nvm(app_t *a, const options_t *o, unsigned k, bool logf, bool *former)
{
    app_inst_t *in = &a->inst[k];
    char err[600];
    char file[4096];
    const char *path;
    uint8_t id = co_node_factory_id(a->nodes[in->first]);
    if (nvm_file(o, k, id, file, sizeof(file), &path) != 0) {
        return USAGE_ERROR("--nvm-dir %s: too long", o->nvm_dir);
    }
    /* Messages name the option: "--nvm F: ..." or "--nvm-dir D: D/NAME: ..." */
    char opt[4200];
    if (path == file) {
        snprintf(opt, sizeof(opt), "--nvm-dir %s:", o->nvm_dir);
    } else {
        snprintf(opt, sizeof(opt), "--nvm");
    }
    char old[4096];
    struct stat st;
    *former = path == file && lstat(file, &st) != 0 && errno == ENOENT &&
              former_nvm_name(o, k, id, old, sizeof(old)) && lstat(old, &st) == 0;
    if (*former) {
        if (!S_ISREG(st.st_mode)) { /* a link too: renamed, it would point elsewhere */
            return USAGE_ERROR("--nvm-dir %s: %s (the former name of %s) is not a regular "
                               "file: move it away", o->nvm_dir, old, file);
        }
        path = old;
    }
    int r = lp_nvm_open(&in->nvm, opt, path, in->nvm_mem,
                        (uint32_t)(in->prod->nodes * CO_STORE_NVM_SIZE), err, sizeof(err));
    if (r != 0) {
        return start_failure(logf, r == -2 ? 2 : 1, err);
    }
    if (*former) { /* held and saved under the new name from now (same directory) */
        char *slash = strrchr(in->nvm.real, '/');
        const char *base = strrchr(file, '/');
        if (slash == NULL || base == NULL ||
            (size_t)(slash - in->nvm.real) + strlen(base) >= sizeof(in->nvm.real)) {
            return USAGE_ERROR("--nvm-dir %s: too long", o->nvm_dir);
        }
        memcpy(slash, base, strlen(base) + 1u);
    }
    for (unsigned j = 0; j < k && in->nvm.path != NULL; j++) {
        const lp_nvm_t *other = &a->inst[j].nvm;
        if (other->path != NULL && strcmp(other->real, in->nvm.real) == 0) {
            return USAGE_ERROR("%s %s: the EEPROM file of %s too (one file, one instance)", opt,
                               path, o->spec[j].arg);
        }
    }
    r = lp_nvm_lock(&in->nvm, opt, path, err, sizeof(err));
    if (r != 0) {
        return start_failure(logf, r == -2 ? 2 : 1, err);
    }
    return GO_ON;
}

/* After a start that worked: instance k's file under its former name
 * (open_inst_nvm) gets its new name. A failure is logged; the set read
 * from the former name is in use, and the first save writes the new name. */
static void rename_former_nvm(const options_t *o, unsigned k, uint8_t id)
{
    char old[4096];
    char file[4096];
    const char *path;
    if (!former_nvm_name(o, k, id, old, sizeof(old)) ||
        nvm_file(o, k, id, file, sizeof(file), &path) != 0) {
        return;
    }
    if (rename(old, file) != 0) {
        lp_log("warning: EEPROM file %s (the former name) not renamed %s: %s: its set is in use; "
               "the first save writes the new name", old, file, strerror(errno));
        return;
    }
    lp_log("EEPROM file %s renamed %s (the interface is in the name now)", old, file);
}

/* Open the sockets and LEDs of instance k's nodes. Returns GO_ON or 1. */
static int open_inst_ports(app_t *a, const options_t *o, unsigned k, bool logf, uint32_t t)
{
    app_inst_t *in = &a->inst[k];
    char err[600];
    for (unsigned i = 0; i < in->prod->nodes; i++) {
        unsigned g = in->first + i;
        if (lp_open(&a->ports[g], a->ifn[g], g, &in->nvm, t, err, sizeof(err)) != 0) {
            /* The option that named the interface: --node P/IFACE, or --iface */
            const node_spec_t *n = &o->spec[k];
            bool node_opt = n->iface != NULL && !(k == 0u && o->prod != NULL);
            const char *given = node_opt ? n->iface : o->iface;
            char msg[sizeof(err) + 300];
            if (node_opt) {
                snprintf(msg, sizeof(msg), "--node %s: %s: %s", n->arg, a->ifn[g], err);
            } else if (strcmp(given, a->ifn[g]) == 0) {
                snprintf(msg, sizeof(msg), "--iface %s: %s", given, err);
            } else {
                snprintf(msg, sizeof(msg), "--iface %s: %s: %s", given, a->ifn[g], err);
            }
            return start_failure(logf, 1, msg);
        }
        if (leds_open(&a->leds[g], g == 0 ? o->led_chip : NULL, o->led_green, o->led_red, err,
                      sizeof(err)) != 0) {
            return start_failure(logf, 1, err);
        }
    }
    return GO_ON;
}

/* The sim whose inputs instance k samples: standard input's for the
 * first, each other its own. */
static sim_t *inst_sim(app_t *a, unsigned k)
{
    return k == 0u ? &a->sim : &a->inst[k].sim;
}

/* Every instance's motion advances to t (sim_step), then it samples its inputs. */
static void sample_all(app_t *a, uint32_t t)
{
    for (unsigned k = 0; k < a->ninst; k++) {
        sim_t *sm = inst_sim(a, k);
        sim_step(sm, t);
        a->inst[k].prod->sample(a->inst[k].mem, sm->values, sm->faults);
    }
}

/* The signals that stop the program cleanly (SIGINT, SIGTERM, SIGHUP). */
static void stop_signals(sigset_t *sigs)
{
    sigemptyset(sigs);
    sigaddset(sigs, SIGINT);
    sigaddset(sigs, SIGTERM);
    sigaddset(sigs, SIGHUP);
}

/* Everything the loop needs, in the order a failure must be reported:
 * the log, the --nvm-dir, then per instance the CAN sockets and LEDs, the
 * instance and its EEPROM file; the node-ID clash check; the signals and
 * epoll; the first sample and the nodes' start.
 * Returns GO_ON, or the exit status of a failure at start (reported). */
static int set_up(app_t *a, const options_t *o)
{
    memset(a, 0, sizeof(*a));
    a->prod = o->spec[0].prod;
    a->quit_on_eof = o->quit_on_eof;
    if (o->log_path != NULL) {
        FILE *lf = fopen(o->log_path, "a");
        if (lf == NULL) {
            return USAGE_ERROR("--log %s: %s", o->log_path, strerror(errno));
        }
        lp_log_open(lf);
    }
    bool logf = o->log_path != NULL;
    struct stat in_st;
    if (fstat(STDIN_FILENO, &in_st) == 0 && S_ISDIR(in_st.st_mode)) {
        /* read() would fail (EISDIR) at once: an end of input nobody meant */
        return USAGE_ERROR("standard input is a directory (give the commands on a pipe, a "
                           "terminal or a file, or < /dev/null)");
    }
    sim_init(&a->sim, a->prod);
    a->sim.route = route_selected;
    a->sim.route_ctx = a;
    if (o->nvm_dir != NULL) {
        struct stat st;
        if (stat(o->nvm_dir, &st) != 0 || !S_ISDIR(st.st_mode)) {
            return USAGE_ERROR("--nvm-dir %s: not a directory", o->nvm_dir);
        }
    }
    char err[600];
    for (unsigned k = 0; k < o->nspec; k++) {
        a->ninst = k + 1u;
        int r = set_up_inst(a, o, k, logf);
        if (r != GO_ON) {
            return r;
        }
        sim_seed(inst_sim(a, k), o->seed + k); /* each instance its own noise */
    }
    int rc = check_clashes(a);
    if (rc != GO_ON) {
        return rc;
    }
    bool former[APP_MAX_NODES] = {false};
    for (unsigned k = 0; k < a->ninst; k++) {
        rc = open_inst_nvm(a, o, k, logf, &former[k]);
        if (rc != GO_ON) {
            return rc;
        }
    }
    uint32_t t = now_us();
    for (unsigned k = 0; k < a->ninst; k++) {
        rc = open_inst_ports(a, o, k, logf, t);
        if (rc != GO_ON) {
            return rc;
        }
    }
    /* Every node sends through one socket (port.h, lp_tx_t). */
    a->tx.fd = -1;
    if (lp_tx_open(&a->tx, err, sizeof(err)) != 0) {
        return start_failure(logf, 1, err);
    }

    sigset_t sigs;
    stop_signals(&sigs); /* blocked since main()'s first line */
    a->sfd = signalfd(-1, &sigs, SFD_CLOEXEC | SFD_NONBLOCK);
    a->ep = epoll_create1(EPOLL_CLOEXEC);
    if (a->sfd < 0 || a->ep < 0) {
        snprintf(err, sizeof(err), "epoll/signalfd: %s", strerror(errno));
        return start_failure(logf, 1, err);
    }
    struct epoll_event ev = {.events = EPOLLIN};
    ev.data.u32 = EV_SIGNAL;
    epoll_ctl(a->ep, EPOLL_CTL_ADD, a->sfd, &ev);
    ev.data.u32 = EV_STDIN;
    /* A pipe or terminal is polled; a regular file or /dev/null cannot be
     * (EPERM): it never blocks, and is read a block at a time in the loop. */
    bool stdin_polled = epoll_ctl(a->ep, EPOLL_CTL_ADD, STDIN_FILENO, &ev) == 0;
    int stdin_errno = stdin_polled ? 0 : errno;
    for (unsigned i = 0; i < a->nnodes; i++) {
        ev.data.u32 = i;
        epoll_ctl(a->ep, EPOLL_CTL_ADD, a->ports[i].fd, &ev);
    }

    a->ctl.fd = -1;
    if (o->control != NULL) {
        int r = ctl_open(&a->ctl, o->control, err, sizeof(err));
        if (r != 0) {
            return r == -2 ? USAGE_ERROR("%s", err) : start_failure(logf, 1, err);
        }
        ev.data.u32 = EV_CONTROL;
        epoll_ctl(a->ep, EPOLL_CTL_ADD, ctl_fd(&a->ctl), &ev);
        lp_log("control: listening on %s", o->control);
    }

    /* Nothing can fail the start any more: the former names go now. */
    for (unsigned k = 0; k < a->ninst; k++) {
        if (former[k]) {
            rename_former_nvm(o, k, co_node_factory_id(a->nodes[a->inst[k].first]));
        }
    }
    sample_all(a, t);
    t = now_us();
    for (unsigned i = 0; i < a->nnodes; i++) {
        const product_t *prod = a->inst[a->node_inst[i]].prod;
        co_node_start(a->nodes[i], t);
        lp_log("node %u: %s, node-ID 0x%02X on %s, bit-rate code %u = %u kbit/s (vcan ignores "
               "it); factory node-ID 0x%02X, serial 0x%08lX",
               i, prod->id, co_node_id(a->nodes[i]), a->ifn[i], co_node_bitrate(a->nodes[i]),
               product_kbps(prod, co_node_bitrate(a->nodes[i])), co_node_factory_id(a->nodes[i]),
               (unsigned long)co_node_serial(a->nodes[i]));
    }
    log_store_status(a);
    /* A regular file or a device never blocks: read one block a pass of the
     * loop, at most one a millisecond, so that the nodes run and signals
     * are heard however long (/dev/zero: endless) it is. */
    a->stdin_file = !stdin_polled && stdin_errno == EPERM;
    if (!stdin_polled) {
        if (a->stdin_file) {
            lp_log("standard input is a file or device: read a block a millisecond");
        } else {
            lp_log("standard input cannot be polled (%s)", strerror(stdin_errno));
            end_of_input(a);
        }
    }
    a->next_sample = t + CO_FILTER_PERIOD_US;
    return GO_ON;
}

/* One pass over the nodes at time t: ports, CAN state, the node's timers,
 * LEDs, the transmit queue. Returns the delay until one of them needs the
 * next pass; *backlog tells that a port kept frames the kernel refused. */
static uint32_t poll_nodes(app_t *a, uint32_t t, uint32_t wait, bool *backlog)
{
    for (unsigned i = 0; i < a->nnodes; i++) {
        wait = co_min_u32(wait, lp_poll(&a->ports[i], t));
        sync_can_state(a, i);
        wait = co_min_u32(wait, co_node_poll(a->nodes[i], t));
        lp_filter(&a->ports[i], a->nodes[i]); /* the CAN-IDs it consumes now (port.h) */
        bool g;
        bool rd;
        uint32_t led_next;
        co_led_pattern_t gp;
        co_led_pattern_t rp;
        co_node_leds(a->nodes[i], t, &g, &rd, &led_next);
        co_node_led_patterns(a->nodes[i], &gp, &rp);
        leds_set(&a->leds[i], i, g, rd, gp, rp);
        wait = co_min_u32(wait, led_next);
    }
    /* What the nodes sent in this pass and before it (answers to frames
     * received since the last pass), in one go. */
    *backlog = lp_tx_flush(&a->tx, a->ports, a->nnodes) > 0u;
    for (unsigned i = 0; i < a->nnodes; i++) {
        sync_can_state(a, i); /* a write may have found the link gone */
    }
    return wait;
}

/* The nodes a control line's selector names (control.h, README):
 * none: the first instance; "@all": every instance; "@N": node index N
 * (command-line order, from 0); a number (0x21, 33): the node whose active
 * node-ID it is. Sets *first and *end to a node range ([0, nnodes) for @all)
 * and returns the rest of the line, or NULL with the cause in err. */
static const char *select_nodes(app_t *a, const char *line, unsigned *first, unsigned *end,
                                char *err, size_t errlen)
{
    const char *p = line + strspn(line, " \t");
    size_t n = strcspn(p, " \t");
    char tok[32];
    if (n == 0u || n >= sizeof(tok) || (p[0] != '@' && (p[0] < '0' || p[0] > '9'))) {
        const app_inst_t *in = &a->inst[0];
        *first = in->first;
        *end = in->first + in->prod->nodes;
        return p; /* no selector */
    }
    memcpy(tok, p, n);
    tok[n] = '\0';
    const char *rest = p + n;
    if (strcmp(tok, "@all") == 0) {
        *first = 0;
        *end = a->nnodes;
        return rest;
    }
    long v = -1;
    bool num = parse_number(tok[0] == '@' ? tok + 1 : tok, 100000, &v);
    if (tok[0] == '@') {
        if (!num || v >= (long)a->nnodes) {
            snprintf(err, errlen, "no node %s (@0..@%u, or @all)", tok, a->nnodes - 1u);
            return NULL;
        }
        *first = (unsigned)v;
        *end = *first + 1u;
        return rest;
    }
    if (!num || v < 1 || v > 127) {
        /* An LSS-unconfigured node has none (it reads 0xFF): @N names it. */
        snprintf(err, errlen, "'%s': not a node-ID 1..127 (a node without one: select it by "
                 "index, @N)", tok);
        return NULL;
    }
    unsigned found = 0;
    for (unsigned i = 0; i < a->nnodes; i++) {
        if (co_node_id(a->nodes[i]) == v) {
            *first = i;
            found++;
        }
    }
    if (found != 1u) {
        snprintf(err, errlen, found == 0u ? "no node with node-ID %s" :
                 "node-ID %s is held by more than one node (several interfaces, or a clash): "
                 "select it by index (@N)", tok);
        return NULL;
    }
    *end = *first + 1u;
    return rest;
}

/* `get`: one node's true inputs (its instance's) and NMT state. */
static void control_get(app_t *a, unsigned node, char *reply, size_t len)
{
    unsigned k = a->node_inst[node];
    const sim_t *sm = inst_sim(a, k);
    const product_t *prod = a->inst[k].prod;
    size_t at = (size_t)snprintf(reply, len, "ok");
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && prod->inputs[i].name != NULL && at < len; i++) {
        int32_t v = sm->values[i];
        uint32_t m = v < 0 ? (uint32_t)0 - (uint32_t)v : (uint32_t)v;
        at += (size_t)snprintf(reply + at, len - at, " %s=%s%u.%03u", prod->inputs[i].name,
                               v < 0 ? "-" : "", m / 1000u, m % 1000u);
    }
    if (at < len) {
        snprintf(reply + at, len - at, " nmt=%s",
                 nmt_name((uint8_t)co_node_nmt_state(a->nodes[node])));
    }
}

/* `replay FILE` for instances k0..k1: the file is read once per product
 * (not once to check and once to apply per instance: @all on 127 nodes
 * read it 254 times, 0.1-0.2 s with every node held up), checked for all
 * before any starts it. */
static void control_replay(app_t *a, const char *args, unsigned k0, unsigned k1,
                           const char *line, char *reply, size_t len)
{
    const char *p = args + strspn(args, " \t\r");
    size_t n = strcspn(p, " \t\r");
    if (n == 0u || n > SIM_LINE_MAX || p[n + strspn(p + n, " \t\r")] != '\0') {
        snprintf(reply, len, "error: usage: replay FILE.csv (no spaces in FILE)");
        return;
    }
    char file[SIM_LINE_MAX + 1u];
    memcpy(file, p, n);
    file[n] = '\0';
    char err[256];
    const product_t *loaded = NULL;
    for (int pass = 0; pass < 2; pass++) { /* 0: load and check; 1: start */
        for (unsigned k = k0; k <= k1; k++) {
            const product_t *prod = a->inst[k].prod;
            if (prod != loaded) {
                if (!sim_replay_load(prod, file, &a->replay, err, sizeof(err))) {
                    snprintf(reply, len, "error: %s%s%s%s", k1 > k0 ? prod->id : "",
                             k1 > k0 ? ": " : "", err,
                             pass == 1 ? " (it changed meanwhile: the instances before took the "
                                         "former)" : "");
                    return;
                }
                loaded = prod;
            }
            if (pass == 1) {
                sim_replay_start(inst_sim(a, k), &a->replay);
            }
        }
    }
    if (!a->stdin_line) {
        char shown_line[4u * CTL_LINE_MAX + 8u];
        lp_log("control: %s", shown(line, shown_line, sizeof(shown_line)));
    }
    snprintf(reply, len, "ok");
}

/* Whether the line's first word is word. */
static bool is_command(const char *cmd, const char *word)
{
    size_t n = strlen(word);
    return strncmp(cmd, word, n) == 0 && (cmd[n] == '\0' || strchr(" \t\r", cmd[n]) != NULL);
}

/* ctl_line_fn: one control line, answered "ok ..." or "error: <cause>". A
 * line for several instances is checked on copies first and applied to
 * all or none (a bad line changes nothing, as on standard input). */
static void control_line(void *ctx, const char *line, char *reply, size_t len)
{
    app_t *a = ctx;
    char err[256];
    unsigned first = 0;
    unsigned end = 0;
    const char *cmd = select_nodes(a, line, &first, &end, err, sizeof(err));
    if (cmd == NULL) {
        snprintf(reply, len, "error: %s", err);
        return;
    }
    cmd += strspn(cmd, " \t");
    if (is_command(cmd, "get")) {
        if (cmd[3 + strspn(cmd + 3, " \t\r")] != '\0') {
            snprintf(reply, len, "error: get takes nothing after it");
        } else if (end - first != 1u && a->inst[a->node_inst[first]].prod->nodes != end - first) {
            snprintf(reply, len, "error: get needs one node (select it: 0xID or @N)");
        } else {
            control_get(a, first, reply, len);
        }
        return;
    }
    if (cmd[0] == '\0' || cmd[0] == '#') {
        snprintf(reply, len, "error: no command (" SIM_VERBS ")");
        return;
    }
    unsigned k0 = a->node_inst[first];
    unsigned k1 = a->node_inst[end - 1u];
    if (is_command(cmd, "replay")) {
        control_replay(a, cmd + 6, k0, k1, line, reply, len);
        return;
    }
    for (unsigned k = k0; k <= k1; k++) {
        sim_t trial = *inst_sim(a, k); /* checked on a copy first */
        if (!sim_command(&trial, cmd, err, sizeof(err))) {
            if (k1 > k0) {
                snprintf(reply, len, "error: %s: %s", a->inst[k].prod->id, err);
            } else {
                snprintf(reply, len, "error: %s", err);
            }
            return;
        }
    }
    uint32_t now = now_us();
    for (unsigned k = k0; k <= k1; k++) {
        sim_t *sm = inst_sim(a, k);
        (void)sim_command(sm, cmd, err, sizeof(err)); /* as on the copy: it succeeds */
        const app_inst_t *in = &a->inst[k];
        unsigned lo = first > in->first ? first : in->first;
        unsigned hi = co_min_u32(end, in->first + in->prod->nodes);
        apply_can_nodes(a, sm, lo, hi, now);
        if (sm->quit) {
            a->sim.quit = true;
        }
    }
    if (!a->stdin_line) { /* standard input's are logged as such (report_line) */
        char shown_line[4u * CTL_LINE_MAX + 8u];
        lp_log("control: %s", shown(line, shown_line, sizeof(shown_line)));
    }
    snprintf(reply, len, "ok");
}

/* ctl_line_fn of the socket: control_line's answer with every byte that
 * is not printable ASCII as \xNN (shown(), as standard input's rejections
 * are), so that a client's escape sequences never come back raw to its
 * terminal; an answer that grows past len is cut short. */
static void control_socket_line(void *ctx, const char *line, char *reply, size_t len)
{
    char raw[CTL_REPLY_MAX + 1u];
    control_line(ctx, line, raw, len < sizeof(raw) ? len : sizeof(raw));
    (void)shown(raw, reply, len);
}

/* What epoll reported for src (EV_SIGNAL, EV_STDIN, or a node's socket). */
static void handle_event(app_t *a, uint32_t src, uint32_t t)
{
    if (src == EV_SIGNAL) {
        struct signalfd_siginfo si;
        if (read(a->sfd, &si, sizeof(si)) == (ssize_t)sizeof(si)) {
            lp_log("signal %u (%s): stopping", si.ssi_signo, strsignal((int)si.ssi_signo));
            a->sim.quit = true;
        }
    } else if (src == EV_STDIN) {
        if (!read_stdin(a)) {
            epoll_ctl(a->ep, EPOLL_CTL_DEL, STDIN_FILENO, NULL);
        }
    } else if (src == EV_CONTROL) {
        int k = ctl_accept(&a->ctl);
        if (k >= 0) {
            struct epoll_event ev = {.events = EPOLLIN};
            ev.data.u32 = EV_CLIENT + (uint32_t)k;
            epoll_ctl(a->ep, EPOLL_CTL_ADD, a->ctl.cl[k].fd, &ev);
            a->ctl.cl[k].events = EPOLLIN;
        }
    } else if (src >= EV_CLIENT && src < EV_CLIENT + CTL_CLIENTS) {
        unsigned k = src - EV_CLIENT;
        if (ctl_read(&a->ctl, k, control_socket_line, a)) { /* a closed fd leaves epoll */
            /* Reading waits while answers wait (control.h). */
            uint32_t want = ctl_events(&a->ctl, k);
            if (want != a->ctl.cl[k].events) {
                struct epoll_event ev = {.events = want};
                ev.data.u32 = src;
                epoll_ctl(a->ep, EPOLL_CTL_MOD, a->ctl.cl[k].fd, &ev);
                a->ctl.cl[k].events = want;
            }
        }
    } else if (src < a->nnodes) {
        co_frame_t f;
        /* At most 64 frames, then the timers again: a flooded bus
         * must not starve the heartbeat (the rest stay queued in
         * the socket; epoll reports them at once). */
        for (int m = 0; m < 64; m++) {
            int rr = lp_read(&a->ports[src], &f, t);
            if (rr == 0) {
                break;
            }
            if (rr == 1) {
                co_node_receive(a->nodes[src], &f, t);
            }
        }
        sync_can_state(a, src);
    }
}

/* Timers are served on a grid of this many microseconds of the clock. */
#define WAKE_GRID_US 250u

/* The loop wakes at least this often (a bound; something is always due sooner). */
#define LOOP_MAX_WAIT_US 1000000u

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
    uint32_t late = (WAKE_GRID_US - due % WAKE_GRID_US) % WAKE_GRID_US;
    return wait > UINT32_MAX - late ? wait : wait + late;
}

/*
 * epoll for at most wait_us. epoll_pwait2 (Linux 5.11, glibc 2.35) takes
 * the time in nanoseconds; epoll_wait only in whole milliseconds, rounded
 * up here, which made every timer up to a millisecond late: a 10 ms TPDO
 * came 10 to 11 ms apart. Without epoll_pwait2 (an older kernel says
 * ENOSYS once) the milliseconds it is.
 */
static int wait_events(app_t *a, struct epoll_event *evs, int max, uint32_t wait_us)
{
#if defined(__GLIBC__) && (__GLIBC__ > 2 || (__GLIBC__ == 2 && __GLIBC_MINOR__ >= 35))
    if (!a->no_pwait2) {
        struct timespec ts = {.tv_sec = (time_t)(wait_us / 1000000u),
                              .tv_nsec = (long)(wait_us % 1000000u) * 1000L};
        int n = epoll_pwait2(a->ep, evs, max, &ts, NULL);
        if (n >= 0 || errno != ENOSYS) {
            return n;
        }
        a->no_pwait2 = true;
    }
#endif
    return epoll_wait(a->ep, evs, max, (int)((wait_us + 999u) / 1000u));
}

/* The event loop, until quit (a command, the end of input, a signal).
 * Returns 0, or 1 when epoll fails. */
static int run(app_t *a)
{
    while (!a->sim.quit) {
        uint32_t t = now_us();
        if (!co_time_before(t, a->next_sample)) {
            sample_all(a, t);
            a->next_sample += CO_FILTER_PERIOD_US;
            if (!co_time_before(t, a->next_sample)) {
                a->next_sample = t + CO_FILTER_PERIOD_US; /* we slept too long: no burst */
            }
        }
        bool backlog = false;
        uint32_t wait = poll_nodes(a, t, LOOP_MAX_WAIT_US, &backlog);
        log_states(a);
        log_held_input(a, t);
        if (a->in_held != 0u) {
            wait = co_min_u32(wait, lp_rate_wait(&a->in_rate, t));
        }
        if (backlog) {
            wait = co_min_u32(wait, 1000u); /* retry the kernel's full queue soon */
        }
        if (a->stdin_file && !a->sim.quit) {
            a->stdin_file = read_stdin(a);
            wait = a->stdin_file ? co_min_u32(wait, 1000u) : wait;
        }
        struct epoll_event evs[APP_MAX_NODES + 8u]; /* every socket at once: one t for all */
        /* The inputs' sample may wait for a pass that runs anyway (see
         * SAMPLE_SLACK_US); the rest is served on the grid. */
        uint32_t sample_wait = co_time_until(t, a->next_sample) + SAMPLE_SLACK_US;
        int n = wait_events(a, evs, (int)(APP_MAX_NODES + 8u),
                            co_min_u32(coalesce(t, wait), sample_wait));
        if (n < 0 && errno != EINTR) {
            lp_log("error: epoll_wait: %s", strerror(errno));
            return 1;
        }
        t = now_us();
        for (int k = 0; k < n; k++) {
            handle_event(a, evs[k].data.u32, t);
        }
    }
    return 0;
}

/* After the loop: send what is queued, LEDs off, the counts in the log. */
static void shut_down(app_t *a)
{
    if (a->tx.fd >= 0) {
        (void)lp_tx_flush(&a->tx, a->ports, a->nnodes);
        lp_log("%lu frames sent in %lu system calls", a->tx.frames, a->tx.calls);
    }
    for (unsigned i = 0; i < a->nnodes; i++) {
        lp_port_t *p = &a->ports[i];
        leds_close(&a->leds[i], i); /* both LEDs off */
        lp_report_drops(p);
        lp_log("node %u: %lu frames received, %lu dropped by the kernel (receive queue full)", i,
               p->rx_frames, p->rx_dropped);
        if (co_node_tx_dropped(a->nodes[i]) != 0u) {
            lp_log("node %u: %u frames could not be sent (%lu while off the bus)", i,
                   co_node_tx_dropped(a->nodes[i]), p->tx_off);
        }
        lp_close(p);
    }
    ctl_close(&a->ctl);
    lp_tx_close(&a->tx);
    lp_log("stopped");
}

int main(int argc, char **argv)
{
    /* Before anything else: the stop signals are blocked from the first
     * instruction of main, and wait in the kernel until the loop reads
     * them (signalfd), so that a SIGTERM while the program starts (the
     * sockets, the EEPROM files) is a clean stop (exit 0) like one a
     * minute later, not the default action (killed, 143). One during a
     * failing start is dropped with the process (the failure's status).
     * Only a signal before main (exec and the dynamic loader: about 1 ms
     * on a PC, up to 20 ms under User-Mode Linux) meets the default
     * action; a parent that blocks them for the child avoids that too
     * (the mask is inherited through exec: README). */
    sigset_t sigs;
    stop_signals(&sigs);
    sigprocmask(SIG_BLOCK, &sigs, NULL);
    signal(SIGPIPE, SIG_IGN);
    lp_log_start(); /* the log's time zero */
    static options_t o;
    int rc = parse_options(argc, argv, &o);
    if (rc != GO_ON) {
        return rc;
    }
    if (o.eds) {
        return print_eds(o.prod);
    }
    /* static: 127 nodes' instances, sockets and EEPROM mirrors (about a
     * megabyte) are better off the stack; main is the only user. */
    static app_t a;
    rc = set_up(&a, &o);
    if (rc != GO_ON) {
        return rc;
    }
    rc = run(&a);
    shut_down(&a);
    return rc;
}
