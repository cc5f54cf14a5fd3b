/*
 * cli.h - canopen-sensor's command line: the options, the node specs
 * (--product, --node), --help, --list-products, --eds, and the exit
 * statuses.
 *
 * Exit status: 0 after a clean stop (quit, end of input with --on-eof
 * quit, SIGINT, SIGTERM, SIGHUP, also while starting); 1 when something
 * the command line names fails at start (no such CAN interface, not CAN,
 * no CAN in the kernel, an EEPROM file that cannot be read, GPIO) or the
 * event loop fails, or --eds / --list-products / --help cannot write; 2
 * for a wrong command line (including an option given twice, an --nvm
 * that is not a regular file or is in a missing directory, an EEPROM file
 * another user holds, a node-ID clash on one interface, more than 127
 * nodes, a --control path that exists and is no stale socket, a
 * directory as standard input). Once running, nothing on the bus or the
 * interface ends the process: a lost interface is a cable pull.
 */
#ifndef LINUX_CLI_H
#define LINUX_CLI_H

#include <net/if.h>
#include <stdbool.h>
#include <stdint.h>

#include "app.h"
#include "product.h"
#include "udp_bus.h"

/* Exit statuses (above). */
#define CLI_OK 0
#define CLI_FAILED 1
#define CLI_USAGE 2
/* Not an exit status: go on (cli_parse, the set-up's steps). */
#define CLI_GO_ON (-1)

/* One product instance the command line asks for (--product, --node). */
typedef struct node_spec {
    const product_t *prod;
    uint8_t id;        /* factory node-ID of its first node (the next one +1), 0: product's */
    const char *iface; /* its interfaces ("A" or "A,B"), NULL: --iface's first */
    const char *arg;   /* the option's text, for messages */
    /* the interfaces split at their commas; ifn[] points into ifbuf */
    char ifbuf[PRODUCT_MAX_NODES * LP_IFACE_MAX + 8]; /* LP_IFACE_MAX: udp_bus.h */
    const char *ifn[PRODUCT_MAX_NODES];
} node_spec_t;

/* The command line, as cli_parse() leaves it. */
typedef struct options {
    const product_t *prod; /* --product, or NULL */
    const char *iface;
    const char *nvm_path;
    const char *nvm_dir;
    const char *control;             /* --control unix:PATH | tcp:PORT, or NULL */
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
    bool progdl;     /* --program-download (prog.h) */
    uint64_t seed;   /* --seed: the simulator's noise (instance k: seed + k) */
    uint32_t serial; /* --serial: node i's 0x1018 sub 4 is serial + i; 0: derived */
} options_t;

/*
 * The command line into *o, checked: returns CLI_GO_ON; CLI_OK after
 * --help or --list-products (printed; CLI_FAILED when they could not be);
 * CLI_USAGE for a wrong command line (one line on stderr). With --eds only
 * the product is checked. Nothing is opened.
 */
int cli_parse(int argc, char **argv, options_t *o);

/* --eds: the product's EDS on standard output (with progdl, its loader's
 * dictionary: prog.h); returns the exit status. */
int cli_print_eds(const product_t *prod, bool progdl);

/* A wrong command line: "canopen-sensor: <cause> (see --help)" on stderr. */
void cli_usage_error(const char *fmt, ...) __attribute__((format(printf, 1, 2)));

/* cli_usage_error(), then CLI_USAGE: a macro, so that the status is seen
 * where it is returned (clang's analyzer does not follow a variadic call,
 * and would take a wrong command line for one that goes on). */
#define USAGE_ERROR(...) ((void)cli_usage_error(__VA_ARGS__), CLI_USAGE)

/* A failure at start: one line on stderr, and in the log when it is a
 * file (--log); returns rc. A wrong command line found at start
 * (cli_usage_error) goes to the log the same way. */
int cli_start_failure(int rc, const char *msg);

#endif /* LINUX_CLI_H */
