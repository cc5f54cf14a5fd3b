/*
 * sim.h - the simulated physics, one command a line on standard input:
 *   set NAME=VALUE [NAME=VALUE...]   true value of inputs (product's names)
 *   ramp NAME=VALUE in DURATION      linear from the input's value now to
 *                                    VALUE over DURATION, then held there
 *   sine NAME amp=A period=DURATION  NAME = C + A sin(2 pi t / period), C the
 *                                    input's value now, t from the command:
 *                                    it starts at C going up (phase 0)
 *   noise NAME sd=S                  Gaussian noise of standard deviation S
 *                                    (input's unit) added on top; sd=0 stops
 *   replay FILE.csv                  play a table (below) from the command on
 *   fault NAME on|off                force a fault (product's names: sensor, ...)
 *   can bus-off [SECONDS]            the CAN controller goes bus-off; the bus
 *                                    stays unusable SECONDS (default 0), then
 *                                    the controller is back after 128 x 11 bits
 *   can passive|warning|active       the controller's error state
 *   quit                             stop the program
 * A bad line is rejected whole: nothing of it changes anything.
 *
 * Motion. DURATION is a number with its unit, s or ms ("5s", "250ms",
 * "1.5s"), more than 0 and at most SIM_DURATION_MAX_S. Each input has one
 * motion (what set, ramp, sine or replay last gave it) and, on top, its
 * noise: a later set, ramp, sine or replay naming the input replaces its
 * motion (a ramp or sine starts from the motion's value at that time, noise
 * left out) and keeps its noise; noise changes only with `noise`.
 * Limits (product_t inputs[].limit): what a command asks outright is
 * refused beyond the limit (set and ramp values, replay values, a sine's
 * C +- A); noise can carry a value past it, and the sum is saturated at
 * +-limit.
 *
 * Replay file (CSV, at most SIM_REPLAY_BYTES bytes and SIM_REPLAY_ROWS
 * rows, lines of at most SIM_LINE_MAX characters, a UTF-8 byte order mark
 * at its start ignored): a header row "t,NAME,..." (t or time, then
 * product input names, each once), then rows "SECONDS,VALUE,...": times
 * from 0, strictly increasing; blank lines and lines starting with # are
 * skipped. The named inputs hold their value now until the first row's
 * time, are interpolated linearly between rows and hold the last row's
 * values after it. One replay runs at a time: a new one stops the former
 * (inputs it drove hold their value), and set/ramp/sine take an input off
 * the replay. A file that cannot be read or is malformed is an error
 * answer naming its line; nothing changes then.
 *
 * Time and determinism. The board passes its clock (microseconds, may
 * wrap) to sim_step() before each sample; the simulated time is the sum of
 * its steps (64 bits, from 0 at the first step). A command takes effect at
 * the time of the last sim_step(). Every value is a function of the
 * commands, the times they were given and the seed: ramp and replay are
 * integer arithmetic; noise is a counter-based generator (splitmix64 of
 * the seed, the input and the simulated millisecond) through Box-Muller,
 * so it does not depend on how often sim_step() is called; a new value
 * each simulated millisecond. Values are int32 thousandths of the unit.
 */
#ifndef LINUX_SIM_H
#define LINUX_SIM_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>

#include "product.h"

/* Every command of the line language, for messages (one list: sim.c's
 * parser and the control socket's answers name them all). */
#define SIM_VERBS "set, ramp, sine, noise, replay, fault, can, get, quit"

/* Longest line accepted, without its newline. */
#define SIM_LINE_MAX 255u

/* Longest ramp, sine period (seconds): one day. */
#define SIM_DURATION_MAX_S 86400u

/* Most data rows of a replay file. */
#define SIM_REPLAY_ROWS 512u

/* Largest replay file: read whole while every node waits, so its size is
 * what one command may cost the loop (256 KiB: about 5 ms in User-Mode
 * Linux, the slowest place it runs). 512 rows of 255 characters fit. */
#define SIM_REPLAY_BYTES 262144u

/* Seed when none is given (--seed). */
#define SIM_SEED_DEFAULT 1u

/* What drives one input (its motion); noise is on top (sim_motion_t.sd). */
typedef enum sim_kind { SIM_HOLD, SIM_RAMP, SIM_SINE, SIM_REPLAY } sim_kind_t;

typedef struct sim_motion {
    sim_kind_t kind;
    int32_t from;      /* held value, ramp start, sine centre (thousandths) */
    int32_t to;        /* ramp end */
    int32_t amp;       /* sine amplitude */
    uint64_t start_us; /* simulated time the motion began */
    uint64_t dur_us;   /* ramp duration, sine period */
    int32_t sd;        /* noise standard deviation, thousandths; 0: none */
} sim_motion_t;

/* The replay table: times from the `replay` command's time. */
typedef struct sim_replay {
    uint32_t rows;
    int8_t col[PRODUCT_MAX_INPUTS]; /* input i is column col[i]; -1: not in it */
    uint64_t t_us[SIM_REPLAY_ROWS];
    int32_t v[SIM_REPLAY_ROWS][PRODUCT_MAX_INPUTS]; /* by column */
} sim_replay_t;

typedef struct sim {
    const product_t *prod;
    int32_t values[PRODUCT_MAX_INPUTS]; /* thousandths of the input's unit */
    sim_motion_t motion[PRODUCT_MAX_INPUTS];
    sim_replay_t replay;
    uint64_t seed;
    uint64_t t_us;    /* simulated time (sim_step) */
    uint32_t last_us; /* the board's clock at the last sim_step */
    bool stepped;     /* sim_step was called */
    uint32_t faults; /* bit i: the product's faults[i] is on */
    bool quit;
    /* A `get` line (nothing after it) for the board to answer, then clear:
     * standard input's answer goes to standard output (control.h for the
     * socket's). */
    bool get_request;
    /* A `can` command for the board to apply (to every node), then clear. */
    bool can_request;
    co_can_state_t can_state;
    uint32_t can_hold_ms; /* bus-off: how long the bus stays unusable */
    /* A line sim_feed hands another handler first (the board's node
     * selectors); NULL: none. It returns false for a line it leaves to
     * sim_command, true when it took it, with its error in err ("" when
     * the line was applied). */
    bool (*route)(void *ctx, const char *line, char *err, unsigned errlen);
    void *route_ctx;
    /* The standard input line being assembled (sim_feed). */
    char line[SIM_LINE_MAX + 1u];
    size_t len;
    bool overflow; /* longer than SIM_LINE_MAX: rejected at its end */
    bool nul;      /* holds a NUL byte: rejected at its end */
} sim_t;

/* Start with the product's initial input values, no fault, no motion,
 * seed SIM_SEED_DEFAULT. */
void sim_init(sim_t *s, const product_t *p);

/* The noise generator's seed (any value); set before the first command. */
void sim_seed(sim_t *s, uint64_t seed);

/*
 * Advance the simulated time to the board's clock now_us (microseconds,
 * wrapping; steps shorter than half the clock's range) and compute
 * values[] for it. Call before each sample.
 */
void sim_step(sim_t *s, uint32_t now_us);

/* Apply one line (without its newline). Returns false (and writes why to
 * err, errlen bytes) if the line was rejected; nothing changed then. */
bool sim_command(sim_t *s, const char *line, char *err, unsigned errlen);

/*
 * What became of one input line: error NULL when it was applied (line is
 * then the command; empty lines and comments are not reported), else why
 * it was rejected (line: what of it can be shown, maybe "").
 */
typedef void (*sim_report_fn)(void *ctx, const char *line, const char *error);

/*
 * Feed n bytes of standard input (any bytes): every complete line is
 * applied with sim_command() and reported. A line that holds a NUL byte or
 * is longer than SIM_LINE_MAX is rejected whole, never cut short.
 */
void sim_feed(sim_t *s, const char *data, size_t n, sim_report_fn report, void *ctx);

/*
 * `replay FILE` in two steps, so that one file serves many instances of a
 * product read once (the control socket's @all): load FILE's table for
 * prod (a regular file only, opened without waiting; false with the cause
 * in err, *r then unusable), then start it on a sim of that product (its
 * former replay stops, the file's inputs follow the table from now).
 */
bool sim_replay_load(const product_t *prod, const char *file, sim_replay_t *r, char *err,
                     unsigned errlen);
void sim_replay_start(sim_t *s, const sim_replay_t *table);

/* End of input: a last line without its newline is applied like any other. */
void sim_feed_end(sim_t *s, sim_report_fn report, void *ctx);

/* One line for --help: the product's `set` inputs and `fault` names. */
void sim_describe(const product_t *p, char *buf, size_t len);

#endif /* LINUX_SIM_H */
