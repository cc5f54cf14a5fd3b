/*
 * serial_link.h - the serial line of the emulated boards (rv32-virt,
 * microbit): CAN frames as SLCAN text lines (Lawicel's serial-line CAN
 * protocol, what python-can's `slcan` interface speaks) and, on the same
 * line, the simulated-input language of the Linux program's standard input:
 *
 *   set NAME=VALUE [NAME=VALUE...]   true value of inputs (product's names)
 *   fault NAME on|off                force a fault (product's fault names)
 *   can bus-off [SECONDS]            bus-off; the bus stays unusable SECONDS
 *                                    (default 0, at most 60), then the
 *                                    controller is back after 128 x 11 bits
 *   can passive|warning|active       the controller's error state
 *   get                              "ok NAME=VALUE ..." the true inputs
 *                                    (thousandths; no "nmt=": the line
 *                                    does not see the node)
 *
 * This is the Linux program's line language (boards/linux/cmd.h) less
 * what an image cannot carry: ramp, sine, noise, replay and quit are
 * answered "error: 'WORD' is not on this target (set, fault, can, get)"
 * (why: serial_link.c, absent[]); selectors are not taken (an image is one
 * product); `get` has no "nmt=" word. The verbs it has take the same
 * lines and give the same answers, but for what an image's integer
 * parser and its missing texts cannot carry: numbers are plain decimals
 * with at most three places (the program also takes exponents, and rounds
 * more places to thousandths); a bad `set` argument and a fault on a
 * product without faults are answered without the input list, units or
 * product ID; a bus-off hold is at most 60 s (the program's 1800 s).
 * tests/unit/test_linux_cmd.c checks both the agreement and each
 * difference.
 *
 * Each input line is answered on the line with "ok" or "error: <cause>"
 * (python-can's slcan ignores lines that are not frames; an answer holds
 * printable ASCII only, '?' for any other byte of the line it quotes). A bad line is
 * rejected whole: nothing of it changes anything.
 *
 * Which is which: SLCAN lines are one command letter and hex digits ("t"
 * 3 hex id, 1 dlc, data; "r" id, dlc; "O", "C", "S6", ...). A line with a
 * space, or with a character after its first that is not a hex digit, is
 * an input line ("set ...", "fault ...", "can ...", and anything else is an
 * unknown command). Of the SLCAN lines, standard data and remote frames
 * ("t", "r") are received; extended frames and adapter commands (open,
 * close, bit rate, version) are ignored: the board is the CAN side, it has
 * no adapter to configure; while the simulated controller is bus-off,
 * received frames are lost. A line is at most SERIAL_LINE_MAX characters;
 * a longer one, or one with a NUL byte, is dropped whole (an input line:
 * answered "error").
 *
 * All state is in serial_link_t, which the board owns; put() sends one
 * character on the line.
 */
#ifndef SERIAL_LINK_H
#define SERIAL_LINK_H

#include "co_common.h"
#include "product.h"

#define SERIAL_LINE_MAX 48u

typedef void (*serial_put_fn)(char c);

typedef struct serial_link {
    const product_t *prod;
    int32_t values[PRODUCT_MAX_INPUTS]; /* true input values, thousandths */
    uint32_t faults;                    /* bit i: prod->faults[i] is on */
    uint8_t can_state;                  /* co_can_state_t, simulated */
    bool busoff_pending;                /* bus-off commanded, not yet timed */
    uint32_t busoff_hold_ms;            /* its hold time */
    uint32_t busoff_end;                /* bus-off lasts until then (us) */
    uint8_t back_state;                 /* the state it comes back in */
    bool busoff_cut;                    /* another state commanded: the hold ends */
    uint16_t kbps;                      /* bit rate, for the recovery time */
    char line[SERIAL_LINE_MAX + 1u];
    uint8_t len;
    bool overflow; /* the line is longer than SERIAL_LINE_MAX */
    bool nul;      /* the line holds a NUL byte */
} serial_link_t;

/* Start with the product's initial input values, no fault, error active. */
void serial_link_init(serial_link_t *s, const product_t *p);

/* What a board's board_sensor() returns: the true inputs and faults the
 * line set for product p (its initial values until a `set` line). The
 * first call, made before the node starts (mcu_main.c), starts the link
 * for p, so that a board needs no product at board_init(). */
void serial_link_sample(serial_link_t *s, const product_t *p, int32_t values[], uint32_t *faults);

/* Feed one received character. Returns true when it completed a received
 * frame line, which is then in *f. An input line is applied and answered
 * through put(). */
bool serial_link_rx(serial_link_t *s, char c, co_frame_t *f, serial_put_fn put);

/* The line language's verbs this line serves, by index (NULL past the
 * last), and those of the Linux program's it answers "not on this
 * target" (above). Every verb of the Linux program is in one of the two
 * lists (a unit test checks it against the program's table). */
const char *serial_link_verb(unsigned i);
const char *serial_link_absent_verb(unsigned i);

/* Send one frame as an SLCAN line ("t1FF81122...\r", "r1FF0\r"). */
void serial_link_tx(const co_frame_t *f, serial_put_fn put);

/* The node's bit rate changed to kbps: tell the line the way an SLCAN
 * adapter is told ("S0".."S8" for 10 k .. 1 M; 800 k is S7). Returns false
 * for a rate SLCAN has no code for (nothing sent). */
bool serial_link_bitrate(serial_link_t *s, uint16_t kbps, serial_put_fn put);

/* The simulated controller state at time now (us): a commanded bus-off
 * starts at the first call after it and ends by itself. */
co_can_state_t serial_link_can_state(serial_link_t *s, uint32_t now);

#endif /* SERIAL_LINK_H */
