/*
 * main.c - canopen-sensor: runs one product of od/ as a process on a
 * SocketCAN interface. One event loop (epoll) over the CAN sockets,
 * standard input (the simulated physics) and a signalfd; the timeout is
 * the earliest deadline the nodes, the ports (link watch, simulated
 * bus-off), the sensor sampling and the LEDs ask for.
 *
 * Exit status: 0 after a clean stop (quit, end of input with --on-eof
 * quit, SIGINT, SIGTERM, SIGHUP); 1 when something the command line names
 * fails at start (no such CAN interface, not CAN, no CAN in the kernel, an
 * EEPROM file that cannot be read, GPIO) or the event loop fails; 2 for a
 * wrong command line (including an --nvm that is not a regular file or is
 * in a missing directory). Once running, nothing on the bus or the
 * interface ends the process: a lost interface is a cable pull.
 */
#include <errno.h>
#include <getopt.h>
#include <signal.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/epoll.h>
#include <sys/signalfd.h>
#include <time.h>
#include <unistd.h>

#include "co_filter.h"
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
            "       canopen-sensor --product ID --eds\n"
            "       canopen-sensor --list-products [--json]\n"
            "\n"
            "Runs a simulated CANopen sensor on a SocketCAN interface.\n"
            "\n"
            "  --product ID       product to run (see --list-products)\n"
            "  --iface IFACE      CAN interface, e.g. vcan0; A,B gives a two-node product\n"
            "                     one interface per node\n"
            "  --nvm FILE         EEPROM file (a regular file, or a new one in an existing\n"
            "                     directory): parameters survive restarts (a restart is a\n"
            "                     power cycle); the first save creates it\n"
            "  --log FILE         write the log there instead of stderr\n"
            "  --on-eof quit|run  at the end of standard input (Ctrl-D, the parent's pipe\n"
            "                     closed): stop (quit, the default) or run on until a signal\n"
            "  --led-chip CHIP    drive the LEDs on this GPIO chip (libgpiod), with\n"
            "  --led-green LINE   the green (run) LED line (default 0) and\n"
            "  --led-red LINE     the red (error) LED line (default 1); without --led-chip\n"
            "                     LED changes are logged\n"
            "  --seed N           seed of the simulated noise (default 1): the same\n"
            "                     commands at the same times give the same values\n"
            "  --eds              print the product's EDS (CiA 306) and exit\n"
            "  --list-products    print every product ID with a description\n"
            "  --json             with --list-products: a JSON array instead, one object a\n"
            "                     product: id, family, summary, vendor, nodes,\n"
            "                     default_node_ids (one per node), default_bitrate_kbps,\n"
            "                     lss, inputs (name, unit, limit, initial), faults\n"
            "  --help             this text\n"
            "\n"
            "Standard input, one command a line (a bad line is rejected whole):\n"
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
            "\n"
            "Exit status: 0 clean stop (quit, end of input, SIGINT, SIGTERM, SIGHUP);\n"
            "1 failure at start (interface, EEPROM read, GPIO) or of the event loop;\n"
            "2 wrong command line.\n"
            "\n"
            "Products, their inputs and faults:\n");
    for (size_t i = 0; product_list[i] != NULL; i++) {
        char d[256];
        sim_describe(product_list[i], d, sizeof(d));
        fprintf(f, "  %-16s %s\n", product_list[i]->id, d);
    }
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

static int parse_int(const char *s, int *out)
{
    char *end;
    long v = strtol(s, &end, 0);
    if (end == s || *end != '\0' || v < 0 || v > 4096) {
        return -1;
    }
    *out = (int)v;
    return 0;
}

/* Rejected input lines: at most this many logged a second, the rest counted. */
#define IN_REJECT_LINES 5u

/* epoll's tags: a node's socket is tagged with the node's index. */
#define EV_SIGNAL 100u
#define EV_STDIN 101u

typedef struct app {
    const product_t *prod;
    unsigned nnodes;
    co_node_t *nodes[PRODUCT_MAX_NODES];
    lp_port_t ports[PRODUCT_MAX_NODES];
    leds_t leds[PRODUCT_MAX_NODES];
    uint8_t last_state[PRODUCT_MAX_NODES];
    sim_t sim;
    bool quit_on_eof;
    lp_rate_t in_rate;
    unsigned long in_held; /* rejected lines not logged yet */
    /* Set up by set_up(), used by the loop: */
    int sfd;               /* signalfd: SIGINT, SIGTERM, SIGHUP */
    int ep;                /* epoll over sfd, stdin and the CAN sockets */
    bool stdin_file;       /* stdin cannot be polled: read a block a pass */
    uint32_t next_sample;  /* when the product samples its inputs next */
    lp_nvm_t nvm;
    uint8_t nvm_mem[PRODUCT_MAX_NODES * CO_STORE_NVM_SIZE];
    /* The instance: in main's frame (app_t lives there), alive until main returns. */
    _Alignas(max_align_t) unsigned char inst[sizeof(product_any_t)];
} app_t;

/* The node sees the CAN state its port shows (link, error frames, simulator). */
static void sync_can_state(app_t *a, unsigned i)
{
    co_can_state_t s = lp_can_state(&a->ports[i]);
    if (s != co_node_can_state(a->nodes[i])) {
        co_node_set_can_state(a->nodes[i], s);
    }
}

/* A `can` command from standard input: every node's simulated controller. */
static void apply_can_command(app_t *a, uint32_t now)
{
    if (!a->sim.can_request) {
        return;
    }
    a->sim.can_request = false;
    for (unsigned i = 0; i < a->nnodes; i++) {
        uint32_t kbps = a->ports[i].kbps;
        if (kbps == 0u) {
            kbps = 125u; /* a code the product does not define: the usual default */
        }
        /* 128 x 11 recessive bits at the node's bit rate, rounded up */
        uint32_t recovery_us = (LP_BUSOFF_RECOVERY_BITS * 1000u + kbps - 1u) / kbps;
        lp_sim_can(&a->ports[i], a->sim.can_state, now, a->sim.can_hold_ms * 1000u, recovery_us);
        sync_can_state(a, i);
    }
}

static void log_held_input(app_t *a, uint32_t now)
{
    if (a->in_held != 0u && lp_rate_wait(&a->in_rate, now) == 0u) {
        lp_log("stdin: %lu more lines rejected (not shown)", a->in_held);
        fprintf(stderr, "canopen-sensor: %lu more lines rejected (not shown)\n", a->in_held);
        a->in_held = 0;
    }
}

/* sim_report_fn: the log (and stderr for rejections, rate-limited). */
static void report_line(void *ctx, const char *line, const char *error)
{
    app_t *a = ctx;
    if (error == NULL) {
        lp_log("stdin: %s", line);
        apply_can_command(a, now_us()); /* each `can` line when it comes */
        return;
    }
    uint32_t now = now_us();
    log_held_input(a, now);
    if (lp_rate_allow(&a->in_rate, now, IN_REJECT_LINES)) {
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

static void log_states(app_t *a)
{
    static const char *const names[] = {[0x00] = "initialising", [0x04] = "stopped",
                                        [0x05] = "operational", [0x7F] = "pre-operational"};
    for (unsigned i = 0; i < a->nnodes; i++) {
        uint8_t s = (uint8_t)co_node_nmt_state(a->nodes[i]);
        if (s != a->last_state[i]) {
            const char *name = (s < sizeof(names) / sizeof(names[0]) && names[s]) ? names[s] : "?";
            lp_log("node %u (ID 0x%02X): NMT %s", i, co_node_id(a->nodes[i]), name);
            a->last_state[i] = s;
        }
    }
}

/* After the start: say which stored sets could not be used (the stack
 * flags them over CAN too, per product: 0x4001, EMCY, LEDs). */
static void log_store_status(app_t *a, const lp_nvm_t *nvm)
{
    static const struct {
        co_cls_t cls;
        const char *what;
    } sets[] = {{CO_CLS_PARA, "parameters"}, {CO_CLS_LSS, "node-ID and bit rate"}};
    const char *file = nvm->path != NULL ? nvm->real : "(RAM)";
    for (unsigned i = 0; i < a->nnodes; i++) {
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
typedef struct options {
    const product_t *prod;
    const char *iface;
    const char *nvm_path;
    const char *log_path;
    const char *led_chip;
    const char *led_line_opt; /* the last --led-green/--led-red given, or NULL */
    int led_green;
    int led_red;
    bool eds;
    bool quit_on_eof;
    uint64_t seed; /* --seed: the simulator's noise */
    /* --iface split at its commas: one interface per node (the first one
     * for every node when one is given); ifn[] points into ifbuf. */
    char ifbuf[PRODUCT_MAX_NODES * IFNAMSIZ + 8];
    const char *ifn[PRODUCT_MAX_NODES];
} options_t;

/* Not an exit status: go on (parse_options, set_up). */
#define GO_ON (-1)

/* --iface: one interface for all nodes, or one per node ("A,B"). Returns
 * GO_ON or the exit status of a wrong command line. */
static int split_ifaces(options_t *o)
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

/* The command line into *o, checked: returns GO_ON, 0 after --help or
 * --list-products (printed), or 2 for a wrong command line (one line on
 * stderr). With --eds only the product is checked. Nothing is opened. */
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
        {NULL, 0, NULL, 0},
    };
    opterr = 0; /* our own one-line messages */
    int c;
    while ((c = getopt_long(argc, argv, ":", opts, NULL)) != -1) {
        switch (c) {
        case 'p': product = optarg; break;
        case 'i': o->iface = optarg; break;
        case 'n': o->nvm_path = optarg; break;
        case 'l': o->log_path = optarg; break;
        case 'c': o->led_chip = optarg; break;
        case 'g':
        case 'r':
            if (parse_int(optarg, c == 'g' ? &o->led_green : &o->led_red) != 0) {
                return USAGE_ERROR("bad GPIO line '%s'", optarg);
            }
            o->led_line_opt = c == 'g' ? "--led-green" : "--led-red";
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
            return 0;
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
        if (json) {
            return products_json(stdout) == 0 ? 0 : 1;
        }
        for (size_t i = 0; product_list[i] != NULL; i++) {
            printf("%-18s %s\n", product_list[i]->id, product_list[i]->summary);
        }
        return 0;
    }
    if (product == NULL) {
        return USAGE_ERROR("--product is missing");
    }
    o->prod = product_find(product);
    if (o->prod == NULL) {
        return USAGE_ERROR("unknown product '%s' (see --list-products)", product);
    }
    if (o->eds) {
        return GO_ON;
    }
    if (o->iface == NULL) {
        return USAGE_ERROR("--iface is missing");
    }
    if (o->led_line_opt != NULL && o->led_chip == NULL) {
        return USAGE_ERROR("%s needs --led-chip", o->led_line_opt);
    }
    if (o->led_chip != NULL && o->led_green == o->led_red) {
        return USAGE_ERROR("--led-green and --led-red are the same line (%d)", o->led_green);
    }
    return split_ifaces(o);
}

/* --eds: the product's EDS on stdout; returns the exit status. */
static int print_eds(const product_t *prod)
{
    if (eds_write(stdout, prod) != 0) {
        fprintf(stderr, "canopen-sensor: %s: EDS overrides that apply to no entry\n", prod->id);
        return 1;
    }
    return fflush(stdout) == 0 ? 0 : 1;
}

/* Everything the loop needs, in the order a failure must be reported:
 * the log, the EEPROM file, the CAN sockets and LEDs, the signals and
 * epoll, then the instance, its first sample and the nodes' start.
 * Returns GO_ON, or the exit status of a failure at start (reported). */
static int set_up(app_t *a, const options_t *o)
{
    memset(a, 0, sizeof(*a));
    a->prod = o->prod;
    a->quit_on_eof = o->quit_on_eof;
    if (o->log_path != NULL) {
        FILE *lf = fopen(o->log_path, "a");
        if (lf == NULL) {
            return USAGE_ERROR("--log %s: %s", o->log_path, strerror(errno));
        }
        lp_log_open(lf);
    }
    bool logf = o->log_path != NULL;
    a->nnodes = a->prod->nodes;
    sim_init(&a->sim, a->prod);
    sim_seed(&a->sim, o->seed);

    char err[600];
    int r = lp_nvm_open(&a->nvm, o->nvm_path, a->nvm_mem,
                        (uint32_t)(a->nnodes * CO_STORE_NVM_SIZE), err, sizeof(err));
    if (r != 0) {
        return start_failure(logf, r == -2 ? 2 : 1, err);
    }
    uint32_t t = now_us();
    void *ports[PRODUCT_MAX_NODES];
    for (unsigned i = 0; i < a->nnodes; i++) {
        if (lp_open(&a->ports[i], o->ifn[i], i, &a->nvm, t, err, sizeof(err)) != 0) {
            return start_failure(logf, 1, err);
        }
        ports[i] = &a->ports[i];
        if (leds_open(&a->leds[i], i == 0 ? o->led_chip : NULL, o->led_green, o->led_red, err,
                      sizeof(err)) != 0) {
            return start_failure(logf, 1, err);
        }
    }

    sigset_t sigs;
    sigemptyset(&sigs);
    sigaddset(&sigs, SIGINT);
    sigaddset(&sigs, SIGTERM);
    sigaddset(&sigs, SIGHUP);
    sigprocmask(SIG_BLOCK, &sigs, NULL);
    signal(SIGPIPE, SIG_IGN);
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

    if (a->prod->inst_size > sizeof(a->inst)) {
        return start_failure(logf, 1, "product instance too large");
    }
    a->prod->create(a->prod, a->inst, ports, a->nodes);
    sim_step(&a->sim, t);
    a->prod->sample(a->inst, a->sim.values, a->sim.faults);
    t = now_us();
    for (unsigned i = 0; i < a->nnodes; i++) {
        co_node_start(a->nodes[i], t);
        lp_log("node %u: %s, node-ID 0x%02X on %s, bit-rate code %u = %u kbit/s (vcan ignores it)",
               i, a->prod->id, co_node_id(a->nodes[i]), o->ifn[i], co_node_bitrate(a->nodes[i]),
               product_kbps(a->prod, co_node_bitrate(a->nodes[i])));
    }
    log_store_status(a, &a->nvm);
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
        *backlog |= lp_flush(&a->ports[i]) > 0u;
        sync_can_state(a, i); /* a write may have found the link gone */
    }
    return wait;
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

/* The event loop, until quit (a command, the end of input, a signal).
 * Returns 0, or 1 when epoll fails. */
static int run(app_t *a)
{
    while (!a->sim.quit) {
        uint32_t t = now_us();
        if (!co_time_before(t, a->next_sample)) {
            sim_step(&a->sim, t);
            a->prod->sample(a->inst, a->sim.values, a->sim.faults);
            a->next_sample += CO_FILTER_PERIOD_US;
            if (!co_time_before(t, a->next_sample)) {
                a->next_sample = t + CO_FILTER_PERIOD_US; /* we slept too long: no burst */
            }
        }
        bool backlog = false;
        uint32_t wait = poll_nodes(a, t, co_time_until(t, a->next_sample), &backlog);
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
        struct epoll_event evs[8];
        int timeout_ms = (int)((wait + 999u) / 1000u);
        int n = epoll_wait(a->ep, evs, 8, timeout_ms);
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
    for (unsigned i = 0; i < a->nnodes; i++) {
        lp_port_t *p = &a->ports[i];
        lp_flush(p);
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
    lp_log("stopped");
}

int main(int argc, char **argv)
{
    options_t o;
    int rc = parse_options(argc, argv, &o);
    if (rc != GO_ON) {
        return rc;
    }
    if (o.eds) {
        return print_eds(o.prod);
    }
    app_t a;
    rc = set_up(&a, &o);
    if (rc != GO_ON) {
        return rc;
    }
    rc = run(&a);
    shut_down(&a);
    return rc;
}
