/*
 * test_serial_link.c - the emulated boards' serial line
 * (boards/common/serial_link.c): SLCAN frames both ways, the simulated-input
 * lines and their answers, and everything malformed in between.
 */
#include <stdbool.h>
#include <stddef.h>
#include <string.h>

#include "harness.h"
#include "serial_link.h"

/* What the link sent back on the line. */
static char out[512];
static unsigned nout;

static void put(char c)
{
    if (nout + 1u < sizeof(out)) {
        out[nout++] = c;
        out[nout] = '\0';
    }
}

static serial_link_t s;

/* String helpers of our own: the bare-metal build has no C library. */
static size_t length(const char *a)
{
    size_t n = 0;
    while (a[n] != '\0') {
        n++;
    }
    return n;
}

static bool starts(const char *a, const char *prefix)
{
    size_t n = length(prefix);
    return length(a) >= n && memcmp(a, prefix, n) == 0;
}

static bool same(const char *a, const char *b)
{
    return length(a) == length(b) && starts(a, b);
}

/* Feed a whole text; returns how many frames it completed (the last in *f). */
static unsigned feed(const char *text, size_t n, co_frame_t *f)
{
    unsigned frames = 0;
    nout = 0;
    out[0] = '\0';
    for (size_t i = 0; i < n; i++) {
        co_frame_t g;
        if (serial_link_rx(&s, text[i], &g, put)) {
            *f = g;
            frames++;
        }
    }
    return frames;
}

#define FEED(text, f) feed((text), sizeof(text) - 1u, (f))

extern const product_t jd2xxx, gsh_a, dst_x730_xy30;

static void test_frames_in(void)
{
    serial_link_init(&s, &jd2xxx);
    co_frame_t f;
    CHECK_EQ(FEED("t60A84000100000000000\r", &f), 1);
    CHECK(f.id == 0x60A && f.dlc == 8 && !f.rtr && f.data[0] == 0x40 && f.data[1] == 0x00 &&
          f.data[2] == 0x10);
    CHECK_EQ(out[0], '\0');               /* frames are not answered */
    CHECK_EQ(FEED("t0002810a\n", &f), 1); /* lower-case hex, LF ends a line too */
    CHECK(f.id == 0 && f.dlc == 2 && f.data[0] == 0x81 && f.data[1] == 0x0A);
    CHECK_EQ(FEED("r70A0\r", &f), 1);
    CHECK(f.id == 0x70A && f.rtr && f.dlc == 0);
    CHECK_EQ(FEED("t1230\r", &f), 1);
    CHECK(f.id == 0x123 && f.dlc == 0);
    /* Malformed or not for this node: dropped, unanswered. */
    CHECK_EQ(FEED("t60A9000000000000000000\r", &f), 0); /* DLC 9 */
    CHECK_EQ(FEED("t60A201\r", &f), 0);                 /* short data */
    CHECK_EQ(FEED("t60A10102\r", &f), 0);               /* long data */
    CHECK_EQ(FEED("t8001FF\r", &f), 0);                 /* id above 0x7FF */
    CHECK_EQ(FEED("T0000060A200\r", &f), 0);            /* extended frame */
    CHECK_EQ(FEED("t60\r", &f), 0);                     /* cut short */
    CHECK_EQ(FEED("O\rC\rS6\rV\r\r\n", &f), 0);         /* adapter commands, blank lines */
    /* Acceptance code and mask (M, m) as long as a 2-byte frame line. */
    CHECK_EQ(FEED("M00020000\rm7FF200FF\r", &f), 0);
    CHECK_EQ(out[0], '\0');
    /* One too long for the line, then a good one: only the good one. */
    CHECK_EQ(FEED("t60A80000000000000000000000000000000000000000000000000000\rt0010\r", &f), 1);
    CHECK(f.id == 0x001);
    CHECK_EQ(out[0], '\0');
    /* A NUL byte spoils a frame line. */
    CHECK_EQ(feed("t0011\0000\r", 8, &f), 0);
}

static void test_frames_out(void)
{
    co_frame_t f = {.id = 0x18A, .dlc = 3, .data = {0x01, 0xAB, 0xFF}};
    nout = 0;
    serial_link_tx(&f, put);
    CHECK(same(out, "t18A301ABFF\r"));
    co_frame_t r = {.id = 0x70A, .dlc = 1, .rtr = true};
    nout = 0;
    serial_link_tx(&r, put);
    CHECK(same(out, "r70A1\r"));
}

static void test_set(void)
{
    serial_link_init(&s, &jd2xxx);
    CHECK_EQ(s.values[0], jd2xxx.inputs[0].initial);
    co_frame_t f;
    CHECK_EQ(FEED("set x=10.5 y=-3.25\r", &f), 0);
    CHECK(same(out, "ok\r"));
    CHECK_EQ(s.values[0], 10500);
    CHECK_EQ(s.values[1], -3250);
    CHECK_EQ(FEED("set  x=+0.001\r\n", &f), 0); /* CR LF: one answer */
    CHECK(same(out, "ok\r"));
    CHECK_EQ(s.values[0], 1);
    CHECK_EQ(FEED("set x=3600 y=-3600\r", &f), 0);
    CHECK_EQ(s.values[0], 3600000);
    CHECK_EQ(s.values[1], -3600000);
    /* Rejected whole: nothing of the line changes anything. */
    static const char *const bad[] = {
        "set x=1 y=3600.001", "set x=1 y=abc",        "set x=1 q=2", "set x=1 y",   "set x=1 y=",
        "set x=1 y=1.2345",   "set x=99999999999999", "set x=1 y=-", "set x=1 y=.", "set x=1 y=1e3",
        "set x=1 =5"};
    for (unsigned i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
        char line[64];
        size_t n = length(bad[i]);
        memcpy(line, bad[i], n);
        line[n] = '\r';
        CHECK_EQ(feed(line, n + 1u, &f), 0);
        CHECK(starts(out, "error: "));
        CHECK_EQ(s.values[0], 3600000);
        CHECK_EQ(s.values[1], -3600000);
    }
    CHECK_EQ(FEED("set x=1 y=abc\r", &f), 0);
    CHECK(same(out, "error: 'abc': not a number within +-3600 (3 decimals at most)\r"));
    CHECK_EQ(FEED("set q=1\r", &f), 0);
    CHECK(same(out, "error: 'q': not an input of this product (NAME=VALUE)\r"));
    CHECK_EQ(FEED("set\r", &f), 0);
    CHECK(same(out, "error: usage: set NAME=VALUE [NAME=VALUE...]\r"));
    CHECK_EQ(FEED("set x=.5\r", &f), 0); /* no integer digits: still a number */
    CHECK_EQ(s.values[0], 500);
    /* An answer quotes printable ASCII only: BEL would end an SLCAN line
     * for python-can (a forged frame), 0xB0 breaks its text decoding. */
    CHECK_EQ(FEED("set x=12,5\xb0 \a\r", &f), 0);
    CHECK(same(out, "error: '12,5?': not a number within +-3600 (3 decimals at most)\r"));
    CHECK_EQ(FEED("\at1FF8AABBCCDDEEFF0011 z\r", &f), 0);
    CHECK(same(out, "error: unknown command '?t1FF8AABBCCDDEEFF0011' (set, fault, can, get)\r"));
}

static void test_fault_and_unknown(void)
{
    serial_link_init(&s, &gsh_a);
    co_frame_t f;
    CHECK_EQ(FEED("fault tilt-element on\r", &f), 0);
    CHECK(same(out, "ok\r"));
    CHECK_EQ(s.faults, 2u);
    CHECK_EQ(FEED("fault extension-element on\r", &f), 0);
    CHECK_EQ(s.faults, 3u);
    CHECK_EQ(FEED("fault tilt-element off\r", &f), 0);
    CHECK_EQ(s.faults, 1u);
    CHECK_EQ(FEED("fault tilt-element maybe\r", &f), 0);
    CHECK(same(out, "error: usage: fault extension-element|tilt-element on|off\r"));
    CHECK_EQ(FEED("fault nothing on\r", &f), 0);
    CHECK(starts(out, "error: usage: fault"));
    CHECK_EQ(FEED("fault tilt-element on now\r", &f), 0);
    CHECK(starts(out, "error: "));
    CHECK_EQ(s.faults, 1u);
    serial_link_init(&s, &dst_x730_xy30);
    CHECK_EQ(FEED("fault sensor on\r", &f), 0);
    CHECK(same(out, "ok\r"));
    CHECK_EQ(s.faults, 1u);
    serial_link_t jd;
    serial_link_init(&jd, &jd2xxx);
    nout = 0;
    for (const char *c = "fault sensor on\r"; *c != '\0'; c++) {
        CHECK(!serial_link_rx(&jd, *c, &f, put));
    }
    CHECK(same(out, "error: this product has no simulated faults\r"));
    CHECK_EQ(FEED("quit\r", &f), 0);
    CHECK(same(out, "error: 'quit' is not on this target (set, fault, can, get)\r"));
    CHECK_EQ(FEED("tilt 5\r", &f), 0);
    CHECK(same(out, "error: unknown command 'tilt' (set, fault, can, get)\r"));
    CHECK_EQ(FEED("   \r", &f), 0); /* blank input line: no answer */
    CHECK_EQ(out[0], '\0');
    /* Too long, or a NUL byte: an error, the line is not applied. */
    CHECK_EQ(FEED("set x=1 x=1 x=1 x=1 x=1 x=1 x=1 x=1 x=1 x=1 x=1 x=1 x=2\r", &f), 0);
    CHECK(same(out, "error: line too long\r"));
    CHECK_EQ(s.values[0], dst_x730_xy30.inputs[0].initial);
    CHECK_EQ(feed("set x=1\0\r", 9, &f), 0);
    CHECK(same(out, "error: line holds a NUL byte\r"));
    CHECK_EQ(s.values[0], dst_x730_xy30.inputs[0].initial);
    /* The next line is whole again. */
    CHECK_EQ(FEED("set x=2\r", &f), 0);
    CHECK_EQ(s.values[0], 2000);
}

/* `get` answers the true inputs as the Linux program does (without its
 * nmt= word); the Linux program's other commands are "not on this target",
 * each by name, and change nothing. */
static void test_get_and_commands_not_here(void)
{
    serial_link_init(&s, &jd2xxx);
    co_frame_t f;
    CHECK_EQ(FEED("set x=10.5 y=-0.25 temp=-40\r", &f), 0);
    CHECK_EQ(FEED("get\r", &f), 0);
    CHECK(same(out, "ok x=10.500 y=-0.250 temp=-40.000\r"));
    CHECK_EQ(FEED(" get \r", &f), 0);
    CHECK(same(out, "ok x=10.500 y=-0.250 temp=-40.000\r"));
    CHECK_EQ(FEED("set x=-3600 y=0.001\r", &f), 0);
    CHECK_EQ(FEED("get\r", &f), 0);
    CHECK(same(out, "ok x=-3600.000 y=0.001 temp=-40.000\r"));
    CHECK_EQ(FEED("get x\r", &f), 0);
    CHECK(same(out, "error: get takes nothing after it\r"));
    serial_link_init(&s, &gsh_a);
    CHECK_EQ(FEED("get\r", &f), 0);
    CHECK(starts(out, "ok length="));
    static const char *const lines[] = {"ramp x=30 in 5s", "sine x amp=1 period=1s", "noise x sd=1",
                                        "replay a.csv", "quit"};
    static const char *const answers[] = {
        "error: 'ramp' is not on this target (set, fault, can, get)\r",
        "error: 'sine' is not on this target (set, fault, can, get)\r",
        "error: 'noise' is not on this target (set, fault, can, get)\r",
        "error: 'replay' is not on this target (set, fault, can, get)\r",
        "error: 'quit' is not on this target (set, fault, can, get)\r"};
    serial_link_init(&s, &jd2xxx);
    for (unsigned i = 0; i < sizeof(lines) / sizeof(lines[0]); i++) {
        char line[64];
        size_t n = length(lines[i]);
        memcpy(line, lines[i], n);
        line[n] = '\r';
        CHECK_EQ(feed(line, n + 1u, &f), 0);
        CHECK(same(out, answers[i]));
        CHECK_EQ(s.values[0], jd2xxx.inputs[0].initial);
    }
}

static void test_can_state_and_bitrate(void)
{
    serial_link_init(&s, &jd2xxx);
    co_frame_t f;
    CHECK_EQ(serial_link_can_state(&s, 0), CO_CAN_ACTIVE);
    nout = 0;
    CHECK(serial_link_bitrate(&s, 500, put));
    CHECK(same(out, "S6\r"));
    nout = 0;
    CHECK(!serial_link_bitrate(&s, 33, put));
    CHECK_EQ(nout, 0);
    CHECK(serial_link_bitrate(&s, 10, put) && out[1] == '0');
    nout = 0;
    CHECK(serial_link_bitrate(&s, 1000, put) && same(out, "S8\r"));
    CHECK_EQ(FEED("can passive\r", &f), 0);
    CHECK(same(out, "ok\r"));
    CHECK_EQ(serial_link_can_state(&s, 0), CO_CAN_PASSIVE);
    /* Bus-off 0.5 s, then 128 x 11 bits at 1 Mbit/s (1.408 ms). */
    CHECK_EQ(FEED("can bus-off 0.5\r", &f), 0);
    CHECK(same(out, "ok\r"));
    uint32_t t0 = 0xFFFFF000u; /* across the clock's wrap */
    CHECK_EQ(serial_link_can_state(&s, t0), CO_CAN_BUSOFF);
    CHECK_EQ(serial_link_can_state(&s, t0 + 501407u), CO_CAN_BUSOFF);
    CHECK_EQ(serial_link_can_state(&s, t0 + 501408u), CO_CAN_ACTIVE);
    CHECK_EQ(FEED("can bus-off\r", &f), 0);
    CHECK_EQ(serial_link_can_state(&s, 0), CO_CAN_BUSOFF);
    CHECK_EQ(FEED("t0002010A\r", &f), 0); /* bus-off: no frame received */
    CHECK_EQ(serial_link_can_state(&s, 1408), CO_CAN_ACTIVE);
    CHECK_EQ(FEED("t0002010A\r", &f), 1); /* back on the bus */
    static const char *const bad[] = {
        "can bus-off 61", "can bus-off -1", "can passive 1", "can nothing", "can",
        "can bus-off 1 2"};
    for (unsigned i = 0; i < sizeof(bad) / sizeof(bad[0]); i++) {
        char line[32];
        size_t n = length(bad[i]);
        memcpy(line, bad[i], n);
        line[n] = '\r';
        CHECK_EQ(feed(line, n + 1u, &f), 0);
        CHECK(starts(out, i < 2u ? "error: '" : "error: usage: can"));
        CHECK_EQ(serial_link_can_state(&s, 5000), CO_CAN_ACTIVE);
    }
}

/* What board_sensor() returns: the product's initial values until a
 * `set`; the first sample starts the link for its product. */
static void test_sample(void)
{
    serial_link_t t = {0};
    int32_t v[PRODUCT_MAX_INPUTS];
    uint32_t faults = 99;
    serial_link_sample(&t, &gsh_a, v, &faults);
    CHECK(t.prod == &gsh_a);
    CHECK_EQ(v[0], gsh_a.inputs[0].initial);
    CHECK_EQ(faults, 0);
    co_frame_t f;
    for (const char *c = "fault tilt-element on\r"; *c != '\0'; c++) {
        CHECK(!serial_link_rx(&t, *c, &f, put));
    }
    serial_link_sample(&t, &gsh_a, v, &faults);
    CHECK_EQ(faults, 2u);
    serial_link_sample(&t, &jd2xxx, v, &faults); /* another product: started anew */
    CHECK_EQ(faults, 0);
    CHECK_EQ(v[2], jd2xxx.inputs[2].initial);
}

/* Every hex digit, both cases, in the identifier and the data; the highest
 * standard identifier 0x7FF; a character that is not a hex digit makes an
 * input line of it (answered), not a frame dropped in silence. */
static void test_frame_hex_digits_and_limits(void)
{
    serial_link_init(&s, &jd2xxx);
    co_frame_t f;
    CHECK_EQ(FEED("t7FF80123456789ABCDEF\r", &f), 1);
    CHECK(f.id == 0x7FF && f.dlc == 8 && !f.rtr);
    static const uint8_t up[8] = {0x01, 0x23, 0x45, 0x67, 0x89, 0xAB, 0xCD, 0xEF};
    CHECK(memcmp(f.data, up, 8) == 0);
    CHECK_EQ(FEED("t0bc8abcdef9876543210\r", &f), 1);
    static const uint8_t low[8] = {0xAB, 0xCD, 0xEF, 0x98, 0x76, 0x54, 0x32, 0x10};
    CHECK(f.id == 0x0BC && f.dlc == 8 && memcmp(f.data, low, 8) == 0);
    CHECK_EQ(FEED("r7FF8\r", &f), 1);
    CHECK(f.id == 0x7FF && f.rtr && f.dlc == 8);
    CHECK_EQ(out[0], '\0');
    /* A DLC above 8, also on a remote frame; one data digit too many on an
     * 8-byte frame (22 characters). */
    CHECK_EQ(FEED("r1239\r", &f), 0);
    CHECK_EQ(FEED("r123F\r", &f), 0);
    CHECK_EQ(FEED("t12380102030405060708F\r", &f), 0);
    CHECK_EQ(out[0], '\0');
    /* The letter O for a zero, a G: not SLCAN, so an unknown command. */
    CHECK_EQ(FEED("tO120\r", &f), 0);
    CHECK(same(out, "error: unknown command 'tO120' (set, fault, can, get)\r"));
    CHECK_EQ(FEED("t1G30\r", &f), 0);
    CHECK(same(out, "error: unknown command 't1G30' (set, fault, can, get)\r"));
    CHECK_EQ(FEED("t12g0\r", &f), 0);
    CHECK(same(out, "error: unknown command 't12g0' (set, fault, can, get)\r"));
    CHECK_EQ(FEED("t12:0\r", &f), 0);
    CHECK(same(out, "error: unknown command 't12:0' (set, fault, can, get)\r"));
}

/* A line of SERIAL_LINE_MAX characters is whole; one more is too long.
 * Words may be separated by tabs as well as spaces. */
static void test_line_length_and_separators(void)
{
    serial_link_init(&s, &jd2xxx);
    co_frame_t f;
    char line[SERIAL_LINE_MAX + 2u];
    memset(line, ' ', sizeof line);
    memcpy(line, "set x=7", 7);
    line[SERIAL_LINE_MAX] = '\r';
    CHECK_EQ(feed(line, SERIAL_LINE_MAX + 1u, &f), 0);
    CHECK(same(out, "ok\r"));
    CHECK_EQ(s.values[0], 7000);
    memcpy(line, "set x=8", 7);
    line[SERIAL_LINE_MAX] = ' ';
    line[SERIAL_LINE_MAX + 1u] = '\r';
    CHECK_EQ(feed(line, SERIAL_LINE_MAX + 2u, &f), 0);
    CHECK(same(out, "error: line too long\r"));
    CHECK_EQ(s.values[0], 7000);
    CHECK_EQ(FEED("\tset\tx=1\t y=-2\t\r", &f), 0);
    CHECK(same(out, "ok\r"));
    CHECK(s.values[0] == 1000 && s.values[1] == -2000);
    /* The quoted part of an answer keeps every printable character, '~'
     * (the last) included; DEL is not printable. */
    CHECK_EQ(FEED("set x=~ \x7f\r", &f), 0);
    CHECK(same(out, "error: '~': not a number within +-3600 (3 decimals at most)\r"));
    CHECK_EQ(FEED("~\x7f!\r", &f), 0);
    CHECK(same(out, "error: unknown command '~?!' (set, fault, can, get)\r"));
}

/* SLCAN's bit-rate codes (Lawicel): S0 10, S1 20, S2 50, S3 100, S4 125,
 * S5 250, S6 500, S7 800, S8 1000 kbit/s, no others. At each rate a
 * bus-off without hold ends after 128 x 11 recessive bit times (ISO
 * 11898-1), from 250 kbit/s at start. */
static void test_bitrate_codes_and_recovery(void)
{
    static const uint16_t kbps[] = {10, 20, 50, 100, 125, 250, 500, 800, 1000};
    serial_link_init(&s, &jd2xxx);
    co_frame_t f;
    CHECK_EQ(FEED("can bus-off\r", &f), 0);
    CHECK_EQ(serial_link_can_state(&s, 100u), CO_CAN_BUSOFF);
    CHECK_EQ(serial_link_can_state(&s, 100u + 5631u), CO_CAN_BUSOFF);
    CHECK_EQ(serial_link_can_state(&s, 100u + 5632u), CO_CAN_ACTIVE);
    for (unsigned i = 0; i < sizeof(kbps) / sizeof(kbps[0]); i++) {
        nout = 0;
        CHECK(!serial_link_bitrate(&s, (uint16_t)(kbps[i] - 1u), put));
        CHECK(!serial_link_bitrate(&s, (uint16_t)(kbps[i] + 1u), put));
        CHECK_EQ(nout, 0);
        CHECK(serial_link_bitrate(&s, kbps[i], put));
        CHECK(nout == 3u && out[0] == 'S' && out[1] == (char)('0' + i) && out[2] == '\r');
        CHECK_EQ(FEED("can bus-off\r", &f), 0);
        uint32_t t0 = 0xFFFFFF00u + i; /* across the clock's wrap */
        uint32_t recovery = 1408000u / kbps[i];
        CHECK_EQ(serial_link_can_state(&s, t0), CO_CAN_BUSOFF);
        CHECK_EQ(serial_link_can_state(&s, t0 + recovery - 1u), CO_CAN_BUSOFF);
        CHECK_EQ(serial_link_can_state(&s, t0 + recovery), CO_CAN_ACTIVE);
    }
    /* The hold's range, 0 .. 60 s, both ends included. */
    CHECK_EQ(FEED("can bus-off 0\r", &f), 0);
    CHECK(same(out, "ok\r"));
    CHECK_EQ(serial_link_can_state(&s, 0), CO_CAN_BUSOFF);
    CHECK_EQ(serial_link_can_state(&s, 1407), CO_CAN_BUSOFF);
    CHECK_EQ(serial_link_can_state(&s, 1408), CO_CAN_ACTIVE);
    CHECK_EQ(FEED("can bus-off 60\r", &f), 0);
    CHECK(same(out, "ok\r"));
    CHECK_EQ(serial_link_can_state(&s, 0), CO_CAN_BUSOFF);
    CHECK_EQ(serial_link_can_state(&s, 60001407u), CO_CAN_BUSOFF);
    CHECK_EQ(serial_link_can_state(&s, 60001408u), CO_CAN_ACTIVE);
    CHECK_EQ(FEED("can bus-off 60.001\r", &f), 0);
    CHECK(same(out, "error: '60.001': not a number of seconds within 0..60\r"));
    CHECK_EQ(FEED("can warning\r", &f), 0);
    CHECK(same(out, "ok\r"));
    CHECK_EQ(serial_link_can_state(&s, 0), CO_CAN_WARNING);
    CHECK_EQ(FEED("can active\r", &f), 0);
    CHECK_EQ(serial_link_can_state(&s, 0), CO_CAN_ACTIVE);
}

/* `get` prints zero without a sign and every decimal digit; `fault` needs
 * its on or off. */
static void test_get_digits_and_fault_usage(void)
{
    serial_link_init(&s, &jd2xxx);
    co_frame_t f;
    CHECK_EQ(FEED("set x=0 y=0.999 temp=-0.001\r", &f), 0);
    CHECK_EQ(FEED("get\r", &f), 0);
    CHECK(same(out, "ok x=0.000 y=0.999 temp=-0.001\r"));
    CHECK_EQ(FEED("set x=-0 y=123.456 temp=-199.989\r", &f), 0);
    CHECK_EQ(FEED("get\r", &f), 0);
    CHECK(same(out, "ok x=0.000 y=123.456 temp=-199.989\r"));
    serial_link_init(&s, &gsh_a);
    CHECK_EQ(FEED("get\r", &f), 0);
    CHECK(same(out, "ok length=0.000 angle=0.000 field=100.000\r"));
    CHECK_EQ(FEED("set length=100000 field=-1000\r", &f), 0);
    CHECK_EQ(FEED("get\r", &f), 0);
    CHECK(same(out, "ok length=100000.000 angle=0.000 field=-1000.000\r"));
    CHECK_EQ(FEED("fault tilt-element\r", &f), 0);
    CHECK(same(out, "error: usage: fault extension-element|tilt-element on|off\r"));
    CHECK_EQ(FEED("fault\r", &f), 0);
    CHECK(same(out, "error: usage: fault extension-element|tilt-element on|off\r"));
    CHECK_EQ(FEED("fault extension-element off\r", &f), 0);
    CHECK(same(out, "ok\r"));
    CHECK_EQ(s.faults, 0u);
}

/* A product of the test's own with every input and fault place used
 * (PRODUCT_MAX_INPUTS of each, no NULL to end the lists) and initial
 * values that are not 0: the link starts from them, and reads, sets, gets
 * and forces within the lists. */
static const product_t full = {
    .id = "test-full",
    .inputs = {{"a", "u", 1500, 10},
               {"b", "u", -2000, 10},
               {"c", "u", 3, 10},
               {"d", "u", 4000, 10}},
    .faults = {"f0", "f1", "f2", "f3"},
    .nodes = 1,
};

static void test_full_lists(void)
{
    serial_link_t t;
    memset(&t, 0x5A, sizeof t);
    int32_t v[PRODUCT_MAX_INPUTS] = {7, 7, 7, 7};
    uint32_t faults = 99;
    serial_link_sample(&t, &full, v, &faults);
    CHECK(v[0] == 1500 && v[1] == -2000 && v[2] == 3 && v[3] == 4000);
    CHECK_EQ(faults, 0);
    serial_link_init(&s, &full);
    co_frame_t f;
    CHECK_EQ(FEED("get\r", &f), 0);
    CHECK(same(out, "ok a=1.500 b=-2.000 c=0.003 d=4.000\r"));
    CHECK_EQ(FEED("set d=9.5\r", &f), 0);
    CHECK(same(out, "ok\r"));
    CHECK(s.values[0] == 1500 && s.values[1] == -2000 && s.values[2] == 3 && s.values[3] == 9500);
    CHECK_EQ(FEED("set f0=1\r", &f), 0);
    CHECK(same(out, "error: 'f0': not an input of this product (NAME=VALUE)\r"));
    CHECK_EQ(FEED("fault f3 on\r", &f), 0);
    CHECK(same(out, "ok\r"));
    CHECK_EQ(s.faults, 8u);
    CHECK_EQ(FEED("fault a on\r", &f), 0);
    CHECK(same(out, "error: usage: fault f0|f1|f2|f3 on|off\r"));
    CHECK_EQ(s.faults, 8u);
    /* A number of more digits than 32 bits hold is refused, not wrapped:
     * 4294967297 is 2^32 + 1. */
    CHECK_EQ(FEED("set a=4294967297\r", &f), 0);
    CHECK(starts(out, "error: '4294967297': not a number"));
    CHECK_EQ(s.values[0], 1500);
}

int main(void)
{
    RUN(test_sample);
    RUN(test_frames_in);
    RUN(test_frames_out);
    RUN(test_set);
    RUN(test_fault_and_unknown);
    RUN(test_get_and_commands_not_here);
    RUN(test_can_state_and_bitrate);
    RUN(test_frame_hex_digits_and_limits);
    RUN(test_line_length_and_separators);
    RUN(test_bitrate_codes_and_recovery);
    RUN(test_get_digits_and_fault_usage);
    RUN(test_full_lists);
    return h_finish();
}
