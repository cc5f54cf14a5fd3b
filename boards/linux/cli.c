/*
 * cli.c - the command line; see cli.h.
 */
#include "cli.h"

#include <errno.h>
#include <getopt.h>
#include <stdarg.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "cmd.h"
#include "control.h"
#include "eds.h"
#include "log.h"
#include "products_json.h"
#include "prog.h"
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
            "                     take the commands below from clients of a unix\n"
            "                     socket or a TCP port on 127.0.0.1 too, each line answered\n"
            "                     to its client. PATH must not exist, or be a stale socket\n"
            "                     (replaced)\n"
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
            "  --program-download\n"
            "                     each instance takes a new program over CAN (CiA 302-3:\n"
            "                     1F50h, 1F51h, 1F56h, 1F57h on its first node), kept in\n"
            "                     FILE.prog beside its EEPROM file FILE (needs --nvm or\n"
            "                     --nvm-dir); without it the manual's dictionary alone\n"
            "  --eds              print the product's EDS (CiA 306) and exit (with\n"
            "                     --program-download: the objects of program download too)\n"
            "  --list-products    print every product ID with a description (with\n"
            "                     --product: that one only)\n"
            "  --json             with --list-products: a JSON array instead, one object a\n"
            "                     product: id, family, summary, vendor, nodes,\n"
            "                     default_node_ids (one per node), default_bitrate_kbps,\n"
            "                     lss, inputs (name, unit, limit, initial), faults\n"
            "  --help             this text\n"
            "\n");
    fprintf(f, "Commands, one a line, on standard input and on --control, each answered\n"
               "ok or error: <cause> (a bad line is rejected whole; values beyond an\n"
               "input's limit are refused). A line acts on the first instance, or on\n"
               "the nodes a selector at its start names: 0xNN or NN (the node with that\n"
               "active node-ID), @N (node index N, command-line order from 0), @all\n"
               "(every instance, all or none). On standard input get's answer goes to\n"
               "standard output, ok to the log, errors to stderr and the log.\n");
    cmd_usage(f);
    fprintf(f, "\n"
               "Exit status: 0 clean stop (quit, end of input, SIGINT, SIGTERM, SIGHUP, also\n"
               "while starting); 1 failure at start (interface, EEPROM read, GPIO), of the\n"
               "event loop or of the output; 2 wrong command line (an option twice: only\n"
               "--node repeats; an EEPROM file another process holds).\n"
               "\n"
               "Products, their inputs and faults:\n");
    for (size_t i = 0; product_list[i] != NULL; i++) {
        char d[256];
        cmd_describe(product_list[i], d, sizeof(d));
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
void cli_usage_error(const char *fmt, ...)
{
    char msg[512];
    va_list ap;
    va_start(ap, fmt);
    vsnprintf(msg, sizeof(msg), fmt, ap);
    va_end(ap);
    /* One hint a line: the message's own, which ends it (unknown product:
     * see --list-products), or --help. Only the end is looked at: a word
     * of the command line inside the message chooses nothing. */
    static const char own[] = " (see --list-products)";
    size_t len = strlen(msg);
    bool has_own = len >= sizeof(own) - 1u && strcmp(msg + len - (sizeof(own) - 1u), own) == 0;
    fprintf(stderr, "canopen-sensor: %s%s\n", msg, has_own ? "" : " (see --help)");
    if (lp_log_is_file()) { /* a wrong command line found once --log is open */
        lp_log("error: %s", msg);
    }
}

/* A failure at start: one line on stderr, and in the log when it is a file. */
int cli_start_failure(int rc, const char *msg)
{
    fprintf(stderr, "canopen-sensor: %s\n", msg);
    if (lp_log_is_file()) {
        lp_log("error: %s", msg);
    }
    return rc;
}

/* --serial: 1..0xFFFFFFFF (0 is no serial). */
static bool parse_serial(const char *s, uint32_t *out)
{
    long long v = 0;
    if (!cmd_number(s, 0xFFFFFFFFLL, &v) || v == 0) {
        return false;
    }
    *out = (uint32_t)v;
    return true;
}

static int parse_int(const char *s, int *out)
{
    long long v;
    if (!cmd_number(s, 4096, &v)) {
        return -1;
    }
    *out = (int)v;
    return 0;
}

/* A spec's interfaces, one for all its nodes or one per node ("A,B"), from
 * --iface or from --node's /IFACE: opt and val are what a refusal names
 * ("--iface", "A,B" or "--node", "PRODUCT@ID/A,B"), the option the
 * interfaces came from. Returns CLI_GO_ON or the exit status of a wrong
 * command line. */
static int split_ifaces(node_spec_t *o, const char *opt, const char *val)
{
    const product_t *prod = o->prod;
    const char *iface = o->iface;
    if (snprintf(o->ifbuf, sizeof(o->ifbuf), "%s", iface) >= (int)sizeof(o->ifbuf)) {
        return USAGE_ERROR("%s %s: too long", opt, val);
    }
    unsigned nif = 0;
    for (char *s = o->ifbuf, *comma;; s = comma + 1) {
        comma = strchr(s, ',');
        if (comma != NULL) {
            *comma = '\0';
        }
        if (s[0] == '\0' || strlen(s) >= (lp_udp_is(s) ? LP_IFACE_MAX : IFNAMSIZ)) {
            return USAGE_ERROR("%s %s: '%s' is not an interface name", opt, val, s);
        }
        if (nif == prod->nodes) {
            return prod->nodes == 1u
                       ? USAGE_ERROR("%s has one node: give one interface, not '%s'", prod->id,
                                     iface)
                       : USAGE_ERROR("%s has %u nodes: give one interface, or one per node "
                                     "(A,B), not '%s'",
                                     prod->id, prod->nodes, iface);
        }
        o->ifn[nif++] = s;
        if (comma == NULL) {
            break;
        }
    }
    for (unsigned i = nif; i < prod->nodes; i++) {
        o->ifn[i] = o->ifn[0];
    }
    return CLI_GO_ON;
}

/* --node PRODUCT[@NODEID][/IFACE] into the next spec. Returns CLI_GO_ON or 2. */
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
        long long id = 0;
        if (!cmd_number(at + 1, CO_NODE_ID_MAX, &id) || id < 1) {
            return USAGE_ERROR("--node %s: node-ID '%s' is not 1..127 (e.g. 0x21 or 33)", arg,
                               at + 1);
        }
        n->id = (uint8_t)id;
    }
    n->prod = product_find(name);
    if (n->prod == NULL) {
        return USAGE_ERROR("--node %s: unknown product '%s' (see --list-products)", arg, name);
    }
    if (n->id != 0u && n->id + n->prod->nodes - 1u > CO_NODE_ID_MAX) {
        return USAGE_ERROR("--node %s: %s has %u nodes, node-IDs 0x%02X to 0x%02X: the last "
                           "passes 127 (give at most 0x%02X)",
                           arg, n->prod->id, n->prod->nodes, n->id, n->id + n->prod->nodes - 1u,
                           CO_NODE_ID_MAX + 1u - n->prod->nodes);
    }
    n->iface = slash != NULL ? slash + 1 : NULL;
    n->arg = arg;
    o->nspec++;
    return CLI_GO_ON;
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
            if (l >= (lp_udp_is(o->iface) ? LP_IFACE_MAX : IFNAMSIZ)) {
                return USAGE_ERROR("--iface %s: too long", o->iface);
            }
            memcpy(n->ifbuf, o->iface, l); /* the first of --iface's */
            n->ifbuf[l] = '\0';
            for (unsigned i = 0; i < PRODUCT_MAX_NODES; i++) {
                n->ifn[i] = n->ifbuf;
            }
        } else {
            /* spec[0] with --product is --iface's; any other, a --node's. */
            bool product = k == 0u && o->prod != NULL;
            int rc = split_ifaces(n, product ? "--iface" : "--node", product ? n->iface : n->arg);
            if (rc != CLI_GO_ON) {
                return rc;
            }
        }
        o->nnodes_total += n->prod->nodes;
    }
    if (o->nnodes_total > APP_MAX_NODES) {
        return USAGE_ERROR("%u nodes: at most %u in one process", o->nnodes_total, APP_MAX_NODES);
    }
    if (o->serial != 0u && o->serial > 0xFFFFFFFFu - (o->nnodes_total - 1u)) {
        /* long long: a 32-bit host's unsigned long would wrap the last one. */
        return USAGE_ERROR("--serial 0x%08llX: %u nodes take 0x%08llX..0x%08llX, past 0xFFFFFFFF",
                           (unsigned long long)o->serial, o->nnodes_total,
                           (unsigned long long)o->serial,
                           (unsigned long long)o->serial + o->nnodes_total - 1u);
    }
    return CLI_GO_ON;
}

/* The command line into *o, checked: returns CLI_GO_ON, 0 after --help or
 * --list-products (printed; 1 when they could not be), or 2 for a wrong
 * command line (one line on stderr). With --eds only the product is checked. Nothing is opened. */
int cli_parse(int argc, char **argv, options_t *o)
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
        {"product", required_argument, NULL, 'p'},
        {"iface", required_argument, NULL, 'i'},
        {"nvm", required_argument, NULL, 'n'},
        {"log", required_argument, NULL, 'l'},
        {"led-chip", required_argument, NULL, 'c'},
        {"led-green", required_argument, NULL, 'g'},
        {"led-red", required_argument, NULL, 'r'},
        {"list-products", no_argument, NULL, 'L'},
        {"eds", no_argument, NULL, 'E'},
        {"on-eof", required_argument, NULL, 'o'},
        {"seed", required_argument, NULL, 's'},
        {"help", no_argument, NULL, 'h'},
        {"json", no_argument, NULL, 'J'},
        {"node", required_argument, NULL, 'N'},
        {"nvm-dir", required_argument, NULL, 'D'},
        {"control", required_argument, NULL, 'C'},
        {"log-time", required_argument, NULL, 'T'},
        {"serial", required_argument, NULL, 'S'},
        {"program-download", no_argument, NULL, 'P'},
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
        case 'p':
            product = optarg;
            break;
        case 'i':
            o->iface = optarg;
            break;
        case 'n':
            o->nvm_path = optarg;
            break;
        case 'D':
            o->nvm_dir = optarg;
            break;
        case 'C': {
            char err[200];
            if (!ctl_spec_ok(optarg, err, sizeof(err))) {
                return USAGE_ERROR("%s", err);
            }
            o->control = optarg;
            break;
        }
        case 'N': {
            int rc = parse_node(o, optarg);
            if (rc != CLI_GO_ON) {
                return rc;
            }
            break;
        }
        case 'l':
            o->log_path = optarg;
            break;
        case 'c':
            o->led_chip = optarg;
            break;
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
                                   "hex), not '%s'",
                                   optarg);
            }
            break;
        case 'E':
            o->eds = true;
            break;
        case 'P':
            o->progdl = true;
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
        return CLI_GO_ON;
    }
    if (o->iface == NULL && o->nspec == 0u) {
        return USAGE_ERROR("--iface is missing");
    }
    if (o->nvm_path != NULL && o->prod == NULL) {
        return USAGE_ERROR("--nvm is the --product node's EEPROM file: use --nvm-dir with --node");
    }
    if (o->progdl && o->nvm_dir == NULL && (o->nvm_path == NULL || o->nspec > 0u)) {
        return USAGE_ERROR("--program-download needs an EEPROM file for every instance (--nvm "
                           "for --product alone, else --nvm-dir): its program is kept beside it");
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
int cli_print_eds(const product_t *prod, bool progdl)
{
    /* static: the loader's copy of a dictionary is some kilobytes */
    static lp_prog_t g;
    product_t with = *prod;
    if (progdl) {
        char err[200];
        if (lp_prog_build(&g, prod->cfg, err, sizeof(err)) != 0) {
            fprintf(stderr, "canopen-sensor: %s\n", err);
            return 1;
        }
        with.cfg = &g.cfg;
    }
    if (eds_write(stdout, &with) != 0) {
        fprintf(stderr, "canopen-sensor: %s: EDS overrides that apply to no entry\n", prod->id);
        return 1;
    }
    return stdout_done("--eds");
}
