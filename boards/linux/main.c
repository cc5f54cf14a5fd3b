/*
 * main.c - canopen-sensor: runs one product of od/ as a process on a
 * SocketCAN interface. One event loop (epoll) over the CAN sockets,
 * standard input (the simulated physics) and a signalfd; the timeout is
 * the earliest deadline the nodes, the sensor sampling and the LEDs ask for.
 */
#include <errno.h>
#include <getopt.h>
#include <signal.h>
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
#include "sim.h"

static void usage(FILE *f)
{
    fprintf(f,
            "usage: canopen-sensor --product ID --iface IFACE [options]\n"
            "       canopen-sensor --product ID --eds\n"
            "       canopen-sensor --list-products\n"
            "\n"
            "Runs a simulated CANopen sensor on a SocketCAN interface.\n"
            "\n"
            "  --product ID       product to run (see --list-products)\n"
            "  --iface IFACE      CAN interface, e.g. vcan0\n"
            "  --nvm FILE         EEPROM file: parameters survive restarts (a restart\n"
            "                     is a power cycle); created blank (defaults) if absent\n"
            "  --log FILE         write the log there instead of stderr\n"
            "  --led-chip CHIP    drive the LEDs on this GPIO chip (libgpiod), with\n"
            "  --led-green LINE   the green (run) LED line and\n"
            "  --led-red LINE     the red (error) LED line; without them LED changes are logged\n"
            "  --eds              print the product's EDS (CiA 306) and exit\n"
            "  --list-products    print every product ID with a description\n"
            "  --help             this text\n"
            "\n"
            "Standard input, one command a line:\n"
            "  set x=<deg> y=<deg>      true inclination (dual axis)\n"
            "  set z=<deg>              true inclination (single axis)\n"
            "  fault NAME on|off        force a fault (DST: sensor; P+F: range-x,\n"
            "                           range-y, undervoltage)\n"
            "  quit                     stop\n");
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

typedef struct app {
    const product_t *prod;
    unsigned nnodes;
    co_node_t *nodes[PRODUCT_MAX_NODES];
    lp_port_t ports[PRODUCT_MAX_NODES];
    leds_t leds[PRODUCT_MAX_NODES];
    uint8_t last_state[PRODUCT_MAX_NODES];
    sim_t sim;
    char line[256];
    size_t linelen;
    bool line_overflow;
} app_t;

static void handle_line(app_t *a, const char *line)
{
    char err[200];
    if (!sim_command(&a->sim, line, err, sizeof(err))) {
        fprintf(stderr, "canopen-sensor: %s\n", err);
        lp_log("stdin rejected: %s", err);
        return;
    }
    if (line[0] != '\0') {
        lp_log("stdin: %s", line);
    }
}

/* Read what stdin has; returns false at end of input. */
static bool read_stdin(app_t *a)
{
    char buf[512];
    ssize_t n = read(STDIN_FILENO, buf, sizeof(buf));
    if (n <= 0) {
        return n < 0 && (errno == EAGAIN || errno == EINTR);
    }
    for (ssize_t i = 0; i < n; i++) {
        char c = buf[i];
        if (c == '\n') {
            if (a->line_overflow) {
                fprintf(stderr, "canopen-sensor: line too long, ignored\n");
            } else {
                a->line[a->linelen] = '\0';
                handle_line(a, a->line);
            }
            a->linelen = 0;
            a->line_overflow = false;
        } else if (a->linelen + 1u < sizeof(a->line)) {
            a->line[a->linelen++] = c;
        } else {
            a->line_overflow = true;
        }
    }
    return true;
}

static void log_states(app_t *a)
{
    static const char *const names[] = {[0x00] = "initialising", [0x04] = "stopped",
                                        [0x05] = "operational", [0x7F] = "pre-operational"};
    for (unsigned i = 0; i < a->nnodes; i++) {
        uint8_t s = a->nodes[i]->nmt.state;
        if (s != a->last_state[i]) {
            const char *name = (s < sizeof(names) / sizeof(names[0]) && names[s]) ? names[s] : "?";
            lp_log("node %u (ID 0x%02X): NMT %s", i, a->nodes[i]->node_id, name);
            a->last_state[i] = s;
        }
    }
}

int main(int argc, char **argv)
{
    const char *product = NULL;
    const char *iface = NULL;
    const char *nvm_path = NULL;
    const char *log_path = NULL;
    const char *led_chip = NULL;
    int led_green = 0;
    int led_red = 1;
    bool eds = false;
    static const struct option opts[] = {
        {"product", required_argument, NULL, 'p'}, {"iface", required_argument, NULL, 'i'},
        {"nvm", required_argument, NULL, 'n'},     {"log", required_argument, NULL, 'l'},
        {"led-chip", required_argument, NULL, 'c'}, {"led-green", required_argument, NULL, 'g'},
        {"led-red", required_argument, NULL, 'r'}, {"list-products", no_argument, NULL, 'L'},
        {"eds", no_argument, NULL, 'E'},
        {"help", no_argument, NULL, 'h'},          {NULL, 0, NULL, 0},
    };
    int c;
    while ((c = getopt_long(argc, argv, "", opts, NULL)) != -1) {
        switch (c) {
        case 'p': product = optarg; break;
        case 'i': iface = optarg; break;
        case 'n': nvm_path = optarg; break;
        case 'l': log_path = optarg; break;
        case 'c': led_chip = optarg; break;
        case 'g':
        case 'r':
            if (parse_int(optarg, c == 'g' ? &led_green : &led_red) != 0) {
                fprintf(stderr, "canopen-sensor: bad GPIO line '%s'\n", optarg);
                return 2;
            }
            break;
        case 'E':
            eds = true;
            break;
        case 'L':
            for (size_t i = 0; product_list[i] != NULL; i++) {
                printf("%-18s %s\n", product_list[i]->id, product_list[i]->summary);
            }
            return 0;
        case 'h':
            usage(stdout);
            return 0;
        default:
            usage(stderr);
            return 2;
        }
    }
    if (eds && product != NULL && optind == argc) {
        const product_t *p = product_find(product);
        if (p == NULL) {
            fprintf(stderr, "canopen-sensor: unknown product '%s' (see --list-products)\n", product);
            return 2;
        }
        eds_write(stdout, p);
        return 0;
    }
    if (optind != argc || product == NULL || iface == NULL) {
        usage(stderr);
        return 2;
    }
    app_t a;
    memset(&a, 0, sizeof(a));
    a.prod = product_find(product);
    if (a.prod == NULL) {
        fprintf(stderr, "canopen-sensor: unknown product '%s' (see --list-products)\n", product);
        return 2;
    }
    if (log_path != NULL) {
        FILE *lf = fopen(log_path, "a");
        if (lf == NULL) {
            fprintf(stderr, "canopen-sensor: --log %s: %s\n", log_path, strerror(errno));
            return 2;
        }
        lp_log_open(lf);
    }
    a.nnodes = a.prod->nodes;
    sim_init(&a.sim, a.prod);

    /* Interfaces: one for all nodes, or one per node ("A,B"). */
    char ifbuf[128];
    snprintf(ifbuf, sizeof(ifbuf), "%s", iface);
    const char *ifn[PRODUCT_MAX_NODES] = {ifbuf, ifbuf};
    char *comma = strchr(ifbuf, ',');
    if (comma != NULL) {
        *comma = '\0';
        ifn[1] = comma + 1;
        if (a.nnodes < 2u) {
            fprintf(stderr, "canopen-sensor: %s has one node; give one interface\n", a.prod->id);
            return 2;
        }
    }

    uint8_t nvm_mem[PRODUCT_MAX_NODES * CO_STORE_NVM_SIZE];
    lp_nvm_t nvm;
    if (lp_nvm_open(&nvm, nvm_path, nvm_mem, (uint32_t)(a.nnodes * CO_STORE_NVM_SIZE)) != 0) {
        return 1;
    }
    void *ports[PRODUCT_MAX_NODES];
    for (unsigned i = 0; i < a.nnodes; i++) {
        if (lp_open(&a.ports[i], ifn[i], i, &nvm) != 0) {
            return 1;
        }
        ports[i] = &a.ports[i];
        if (leds_open(&a.leds[i], i == 0 ? led_chip : NULL, led_green, led_red) != 0) {
            return 1;
        }
    }

    sigset_t sigs;
    sigemptyset(&sigs);
    sigaddset(&sigs, SIGINT);
    sigaddset(&sigs, SIGTERM);
    sigprocmask(SIG_BLOCK, &sigs, NULL);
    signal(SIGPIPE, SIG_IGN);
    int sfd = signalfd(-1, &sigs, SFD_CLOEXEC | SFD_NONBLOCK);
    int ep = epoll_create1(EPOLL_CLOEXEC);
    if (sfd < 0 || ep < 0) {
        lp_log("error: epoll/signalfd: %s", strerror(errno));
        return 1;
    }
    struct epoll_event ev = {.events = EPOLLIN};
    ev.data.u32 = 100;
    epoll_ctl(ep, EPOLL_CTL_ADD, sfd, &ev);
    ev.data.u32 = 101;
    bool stdin_open = epoll_ctl(ep, EPOLL_CTL_ADD, STDIN_FILENO, &ev) == 0;
    if (!stdin_open) {
        lp_log("standard input cannot be polled (%s): no simulated input", strerror(errno));
    }
    for (unsigned i = 0; i < a.nnodes; i++) {
        ev.data.u32 = i;
        epoll_ctl(ep, EPOLL_CTL_ADD, a.ports[i].fd, &ev);
    }

    /* The instance: on this stack frame, alive until main returns. */
    _Alignas(max_align_t) unsigned char mem[PRODUCT_INST_MAX];
    if (a.prod->inst_size > sizeof(mem)) {
        lp_log("error: product instance too large");
        return 1;
    }
    a.prod->create(a.prod, mem, ports, a.nodes);
    a.prod->sample(mem, a.sim.values, a.sim.faults);
    uint32_t t = now_us();
    for (unsigned i = 0; i < a.nnodes; i++) {
        co_node_start(a.nodes[i], t);
        lp_log("node %u: %s, node-ID 0x%02X on %s, bit-rate code %u = %u kbit/s (vcan ignores it)",
               i, a.prod->id, a.nodes[i]->node_id, ifn[i], a.nodes[i]->bitrate,
               product_kbps(a.prod, a.nodes[i]->bitrate));
    }
    uint32_t next_sample = t + CO_FILTER_PERIOD_US;
    int rc = 0;

    while (!a.sim.quit) {
        t = now_us();
        if (!co_time_before(t, next_sample)) {
            a.prod->sample(mem, a.sim.values, a.sim.faults);
            next_sample += CO_FILTER_PERIOD_US;
            if (!co_time_before(t, next_sample)) {
                next_sample = t + CO_FILTER_PERIOD_US; /* we slept too long: no burst */
            }
        }
        uint32_t wait = co_time_until(t, next_sample);
        bool backlog = false;
        for (unsigned i = 0; i < a.nnodes; i++) {
            wait = co_min_u32(wait, co_node_poll(a.nodes[i], t));
            bool g;
            bool r;
            uint32_t led_next;
            co_led_pattern_t gp;
            co_led_pattern_t rp;
            co_node_leds(a.nodes[i], t, &g, &r, &led_next);
            co_node_led_patterns(a.nodes[i], &gp, &rp);
            leds_set(&a.leds[i], i, g, r, gp, rp);
            wait = co_min_u32(wait, led_next);
            backlog |= lp_flush(&a.ports[i]) > 0u;
        }
        log_states(&a);
        if (backlog) {
            wait = co_min_u32(wait, 1000u); /* retry the kernel's full queue soon */
        }
        struct epoll_event evs[8];
        int timeout_ms = (int)((wait + 999u) / 1000u);
        int n = epoll_wait(ep, evs, 8, timeout_ms);
        if (n < 0 && errno != EINTR) {
            lp_log("error: epoll_wait: %s", strerror(errno));
            rc = 1;
            break;
        }
        t = now_us();
        for (int k = 0; k < n; k++) {
            uint32_t src = evs[k].data.u32;
            if (src == 100u) {
                struct signalfd_siginfo si;
                if (read(sfd, &si, sizeof(si)) == (ssize_t)sizeof(si)) {
                    lp_log("signal %u: stopping", si.ssi_signo);
                    a.sim.quit = true;
                }
            } else if (src == 101u) {
                if (!read_stdin(&a)) {
                    epoll_ctl(ep, EPOLL_CTL_DEL, STDIN_FILENO, NULL);
                    lp_log("end of standard input; running until a signal");
                }
            } else if (src < a.nnodes) {
                co_frame_t f;
                co_can_state_t cs;
                int r;
                co_node_poll(a.nodes[src], t);
                while ((r = lp_read(&a.ports[src], &f, &cs)) > 0) {
                    if (r == 1) {
                        co_node_receive(a.nodes[src], &f);
                    } else {
                        co_node_set_can_state(a.nodes[src], cs);
                    }
                }
                if (r < 0) {
                    rc = 1;
                    a.sim.quit = true;
                }
            }
        }
    }
    for (unsigned i = 0; i < a.nnodes; i++) {
        lp_flush(&a.ports[i]);
        leds_close(&a.leds[i]);
        if (a.nodes[i]->tx_dropped != 0u) {
            lp_log("node %u: %u frames could not be sent", i, a.nodes[i]->tx_dropped);
        }
        close(a.ports[i].fd);
    }
    lp_log("stopped");
    return rc;
}
