/*
 * cmd.h - the program's one line language, spoken on standard input and
 * on the control socket (control.h) alike; the emulated boards' serial
 * line speaks a subset of it (boards/common/serial_link.h).
 *
 *   [SELECTOR] VERB [ARGUMENTS]
 *
 * One command a line; every line gets one answer: "ok", "ok NAME=VALUE
 * ..." for `get`, or "error: <cause>". A bad line is rejected whole:
 * nothing of it changes anything, on any of the instances it names.
 *
 * Selectors name the nodes a line is for: none, the first instance;
 * "@all", every instance (the line is checked against each first and
 * applied to all or to none); "@N", node index N (command-line order,
 * from 0); a number ("0x21", "33"), the node whose active node-ID it is.
 * A line for a node acts on its instance (its inputs are the device's;
 * `can` acts on the selected nodes' controllers only).
 *
 * The verbs are the rows of cmd_verbs[] (cmd.c): their usage lines, the
 * "no command" and "unknown command" answers and --help all come from
 * that table. Blank lines and lines starting with # are comments:
 * nothing is done and, on standard input, nothing is answered; on the
 * control socket a client that sends one gets "error: no command (...)".
 *
 * Standard input: "ok" answers are logged, errors go to stderr and the
 * log (rate-limited), the answer to `get` goes to standard output. The
 * control socket: every answer goes back to its client.
 */
#ifndef LINUX_CMD_H
#define LINUX_CMD_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

#include "product.h"
#include "replay_csv.h"

typedef struct app app_t;

/* Longest line accepted, without its newline, on every channel. */
#define CMD_LINE_MAX SIM_LINE_MAX
/* Longest answer line, without its newline. */
#define CMD_REPLY_MAX 511u

/* The longest bus-off hold a line may ask for (s): the deadline stays
 * within half the 32-bit microsecond clock the timers compare on. */
#define CMD_HOLD_MAX_S 1800u

/* ---- Line assembly (every channel's bytes into lines) ------------------ */

/* One line being assembled. A line longer than CMD_LINE_MAX or holding a
 * NUL byte is rejected whole at its end, never cut short; one '\r' before
 * the newline is dropped (CRLF lines). */
typedef struct cmd_lines {
    char line[CMD_LINE_MAX + 1u];
    size_t len;
    bool overflow;
    bool nul;
} cmd_lines_t;

/* Take byte c. Returns true when c ended a line ('\n'): then call
 * cmd_lines_take() for it. */
bool cmd_lines_put(cmd_lines_t *lb, char c);

/* Whether bytes of an unfinished line wait (for the end of input). */
bool cmd_lines_pending(const cmd_lines_t *lb);

/* The line just ended (NUL-terminated, in lb), or NULL with why it is
 * rejected in err (errlen bytes); lb is then ready for the next line. */
const char *cmd_lines_take(cmd_lines_t *lb, char *err, size_t errlen);

/* An answer as it goes out on a channel: text (its first CMD_REPLY_MAX
 * bytes) and a newline into out, which has room for CMD_REPLY_MAX + 1
 * bytes; no NUL. Returns the bytes written: always one line. */
size_t cmd_answer_line(const char *text, char *out);

/* ---- The language ------------------------------------------------------ */

/* A line's parsed arguments (one verb's fields are used). */
typedef struct cmd_args {
    bool named[PRODUCT_MAX_INPUTS]; /* set: the inputs named */
    int32_t v[PRODUCT_MAX_INPUTS];  /* set: their values (thousandths) */
    unsigned input;                 /* ramp, sine, noise: the input */
    int32_t value;                  /* ramp: target; sine: amplitude; noise: sd */
    uint64_t dur_us;                /* ramp: duration; sine: period */
    unsigned fault;                 /* fault: which */
    bool on;                        /* fault: on or off */
    uint8_t can_state;              /* can: co_can_state_t */
    uint32_t hold_ms;               /* can bus-off: the hold */
    const sim_replay_t *table;      /* replay: the loaded table */
} cmd_args_t;

/* What a verb acts on, which says how a selection is served. */
typedef enum cmd_scope {
    CMD_INPUTS,  /* each selected instance's simulated inputs (sim.h) */
    CMD_NODES,   /* the selected nodes (their simulated CAN controllers) */
    CMD_QUERY,   /* answers with one node's state; changes nothing */
    CMD_PROGRAM, /* the program itself */
} cmd_scope_t;

typedef struct cmd_ctx cmd_ctx_t;

/* One verb: a row of cmd_verbs[]. parse checks a line's arguments
 * (tokens after the verb, from cmd_token) for instance k and fills *args,
 * or returns false with the cause in err; it changes nothing. apply
 * carries out what parse accepted: it cannot fail. */
typedef struct cmd_verb {
    const char *name;
    const char *usage; /* its arguments as --help shows them ("" for none) */
    const char *what;  /* what it does, one line for --help */
    cmd_scope_t scope;
    bool (*parse)(cmd_ctx_t *c, unsigned k, char **save, cmd_args_t *args, char *err,
                  size_t errlen);
    void (*apply)(cmd_ctx_t *c, unsigned k, unsigned node, const cmd_args_t *args);
} cmd_verb_t;

/* Every verb, in the order messages list them; cmd_nverbs of them. */
extern const cmd_verb_t cmd_verbs[];
extern const unsigned cmd_nverbs;

/* The verbs' names as "set, ramp, ..." (the table's order), into buf. */
void cmd_verb_names(char *buf, size_t len);

/* --help's lines for the verbs ("  set NAME=VALUE ...   what"), each
 * line ended by a newline, into f. */
void cmd_usage(FILE *f);

/* One line for --help: the product's `set` inputs and `fault` names. */
void cmd_describe(const product_t *p, char *buf, size_t len);

/* A number as the lines and the command line write it: decimal digits
 * ("033" is 33: no octal; leading zeros as many as given) or 0x and hex
 * digits; no sign, no blanks. True with *out (at most max, which is below
 * 10^18), false otherwise. long
 * long: a 32-bit host's long cannot hold the largest serial number. */
bool cmd_number(const char *s, long long max, long long *out);

/* The channel a line came on (what is logged, and where). */
typedef enum cmd_channel { CMD_STDIN, CMD_CONTROL } cmd_channel_t;

/* Serve one line (without its newline) for app a, at time now: the
 * answer into reply (len bytes, no newline). */
void cmd_line(app_t *a, cmd_channel_t ch, const char *line, uint32_t now, char *reply, size_t len);

#endif /* LINUX_CMD_H */
