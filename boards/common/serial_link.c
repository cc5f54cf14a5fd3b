/*
 * serial_link.c - see serial_link.h.
 */
#include "serial_link.h"

/* Longest bus-off hold a `can bus-off SECONDS` line may ask for. */
#define HOLD_MAX_S 60u
/* Bus-off recovery: 128 occurrences of 11 recessive bits (CiA 301 / ISO 11898). */
#define RECOVERY_BITS (128u * 11u)

void serial_link_init(serial_link_t *s, const product_t *p)
{
    *s = (serial_link_t){.prod = p, .can_state = CO_CAN_ACTIVE, .kbps = 250};
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && p->inputs[i].name != NULL; i++) {
        s->values[i] = p->inputs[i].initial;
    }
}

void serial_link_sample(serial_link_t *s, const product_t *p, int32_t values[], uint32_t *faults)
{
    if (s->prod != p) {
        serial_link_init(s, p);
    }
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        values[i] = s->values[i];
    }
    *faults = s->faults;
}

/* ---- output --------------------------------------------------------------- */

#ifndef BOARD_BOOT
/* Printable ASCII only: an answer echoes parts of a rejected line, and a
 * byte such as BEL (an SLCAN line end for python-can) or one above 0x7E
 * (no text to python-can's decoder) would forge or break the master's
 * reading of the line. Anything else goes out as '?' (a quoted line holds
 * no CR: it ended there). */
static void put_str(serial_put_fn put, const char *t)
{
    for (; *t != '\0'; t++) {
        put((char)((*t >= ' ' && *t <= '~') || *t == '\r' ? *t
                                                          : '?')); /* '\r': ours, ends a line */
    }
}
#endif

#ifndef BOARD_BOOT
static void put_uint(serial_put_fn put, uint32_t v)
{
    char d[10];
    unsigned n = 0;
    do {
        d[n++] = (char)('0' + v % 10u);
        v /= 10u;
    } while (v != 0u);
    while (n > 0u) {
        put(d[--n]);
    }
}
#endif

static char hex_digit(unsigned v)
{
    return "0123456789ABCDEF"[v & 15u];
}

void serial_link_tx(const co_frame_t *f, serial_put_fn put)
{
    put(f->rtr ? 'r' : 't');
    put(hex_digit((unsigned)f->id >> 8));
    put(hex_digit((unsigned)f->id >> 4));
    put(hex_digit(f->id));
    put(hex_digit(f->dlc));
    for (unsigned i = 0; i < f->dlc && !f->rtr; i++) {
        put(hex_digit((unsigned)f->data[i] >> 4));
        put(hex_digit(f->data[i]));
    }
    put('\r');
}

bool serial_link_bitrate(serial_link_t *s, uint16_t kbps, serial_put_fn put)
{
    static const uint16_t rates[] = {10, 20, 50, 100, 125, 250, 500, 800, 1000};
    for (unsigned i = 0; i < sizeof(rates) / sizeof(rates[0]); i++) {
        if (rates[i] == kbps) {
            s->kbps = kbps;
            put('S');
            put((char)('0' + i));
            put('\r');
            return true;
        }
    }
    return false;
}

co_can_state_t serial_link_can_state(serial_link_t *s, uint32_t now)
{
    uint32_t recovery_us = (RECOVERY_BITS * 1000u + s->kbps - 1u) / s->kbps;
    if (s->busoff_pending) {
        s->busoff_pending = false;
        s->busoff_end = now + s->busoff_hold_ms * 1000u + recovery_us;
    }
    if (s->busoff_cut) {
        s->busoff_cut = false;
        if (co_time_before(now + recovery_us, s->busoff_end)) {
            s->busoff_end = now + recovery_us;
        }
    }
    if (s->can_state == CO_CAN_BUSOFF && !co_time_before(now, s->busoff_end)) {
        s->can_state = s->back_state;
    }
    return (co_can_state_t)s->can_state;
}

/* ---- input lines -------------------------------------------------------------- */

static int hex_value(char c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'A' && c <= 'F') {
        return c - 'A' + 10;
    }
    return c >= 'a' && c <= 'f' ? c - 'a' + 10 : -1;
}

#ifndef BOARD_BOOT
/* The answer to a rejected line: "error: " and the cause's parts. */
static bool fail(serial_put_fn put, const char *a, const char *b, const char *c)
{
    put_str(put, "error: ");
    put_str(put, a);
    put_str(put, b);
    put_str(put, c);
    put('\r');
    return false;
}

/* Tokens: the line split at spaces, in place. */
typedef struct tokens {
    char *at;
} tokens_t;

static char *next_token(tokens_t *t)
{
    while (*t->at == ' ' || *t->at == '\t') {
        t->at++;
    }
    if (*t->at == '\0') {
        return NULL;
    }
    char *start = t->at;
    while (*t->at != '\0' && *t->at != ' ' && *t->at != '\t') {
        t->at++;
    }
    if (*t->at != '\0') {
        *t->at++ = '\0';
    }
    return start;
}

static bool equal(const char *a, const char *b)
{
    while (*a != '\0' && *a == *b) {
        a++;
        b++;
    }
    return *a == *b;
}

/*
 * A decimal number of at most 3 decimals ("-12.5", "30", "0.125") within
 * +-limit, in thousandths. False for anything else (more decimals too: a
 * value the input cannot hold is refused, not rounded).
 */
static bool parse_milli(const char *t, int32_t limit, int32_t *out)
{
    bool neg = *t == '-';
    t += (*t == '-' || *t == '+') ? 1 : 0;
    uint32_t v = 0;
    unsigned digits = 0;
    while (*t >= '0' && *t <= '9') {
        if (v > (uint32_t)limit) {
            return false; /* already too large; stops before v x 10 overflows */
        }
        v = v * 10u + (uint32_t)(*t++ - '0');
        digits++;
    }
    uint32_t frac = 0;
    unsigned decimals = 0;
    if (*t == '.') {
        t++;
        while (*t >= '0' && *t <= '9' && decimals < 3u) {
            frac = frac * 10u + (uint32_t)(*t++ - '0');
            decimals++;
        }
    }
    if (*t != '\0' || digits + decimals == 0u || v > (uint32_t)limit) {
        return false;
    }
    for (; decimals < 3u; decimals++) {
        frac *= 10u;
    }
    uint32_t milli = v * 1000u + frac; /* limit < 2^31 / 1000: fits */
    if (milli > (uint32_t)limit * 1000u) {
        return false;
    }
    *out = neg ? -(int32_t)milli : (int32_t)milli;
    return true;
}

static bool cmd_set(serial_link_t *s, tokens_t *t, serial_put_fn put)
{
    int32_t v[PRODUCT_MAX_INPUTS];
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        v[i] = s->values[i];
    }
    unsigned count = 0;
    char *tok;
    while ((tok = next_token(t)) != NULL) {
        char *eq = tok;
        while (*eq != '\0' && *eq != '=') {
            eq++;
        }
        int in = -1;
        if (*eq == '=') {
            *eq = '\0';
            for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && s->prod->inputs[i].name != NULL; i++) {
                if (equal(tok, s->prod->inputs[i].name)) {
                    in = (int)i;
                }
            }
        }
        if (in < 0) {
            return fail(put, "'", tok, "': not an input of this product (NAME=VALUE)");
        }
        int32_t limit = s->prod->inputs[in].limit;
        if (!parse_milli(eq + 1, limit, &v[in])) {
            put_str(put, "error: '");
            put_str(put, eq + 1);
            put_str(put, "': not a number within +-");
            put_uint(put, (uint32_t)limit);
            put_str(put, " (3 decimals at most)\r");
            return false;
        }
        count++;
    }
    if (count == 0u) {
        return fail(put, "usage: set NAME=VALUE [NAME=VALUE...]", "", "");
    }
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        s->values[i] = v[i];
    }
    return true;
}

static bool cmd_fault(serial_link_t *s, tokens_t *t, serial_put_fn put)
{
    char *what = next_token(t);
    char *onoff = next_token(t);
    int k = -1;
    for (unsigned i = 0; what != NULL && i < PRODUCT_MAX_INPUTS && s->prod->faults[i] != NULL;
         i++) {
        if (equal(what, s->prod->faults[i])) {
            k = (int)i;
        }
    }
    if (s->prod->faults[0] == NULL) {
        return fail(put, "this product has no simulated faults", "", "");
    }
    if (k < 0 || onoff == NULL || (!equal(onoff, "on") && !equal(onoff, "off")) ||
        next_token(t) != NULL) {
        put_str(put, "error: usage: fault ");
        for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && s->prod->faults[i] != NULL; i++) {
            put_str(put, i == 0u ? "" : "|");
            put_str(put, s->prod->faults[i]);
        }
        put_str(put, " on|off\r");
        return false;
    }
    if (equal(onoff, "on")) {
        s->faults |= 1u << k;
    } else {
        s->faults &= ~(1u << k);
    }
    return true;
}

static bool cmd_can(serial_link_t *s, tokens_t *t, serial_put_fn put)
{
    static const struct {
        const char *name;
        uint8_t state;
    } states[] = {{"active", CO_CAN_ACTIVE},
                  {"warning", CO_CAN_WARNING},
                  {"passive", CO_CAN_PASSIVE},
                  {"bus-off", CO_CAN_BUSOFF}};
    char *what = next_token(t);
    char *arg = next_token(t);
    int k = -1;
    for (unsigned i = 0; what != NULL && i < sizeof(states) / sizeof(states[0]); i++) {
        if (equal(what, states[i].name)) {
            k = (int)i;
        }
    }
    int32_t hold_ms = 0;
    bool hold = k >= 0 && states[k].state == CO_CAN_BUSOFF && arg != NULL;
    if (hold && (!parse_milli(arg, (int32_t)HOLD_MAX_S, &hold_ms) || hold_ms < 0)) {
        return fail(put, "'", arg, "': not a number of seconds within 0..60");
    }
    if (k < 0 || next_token(t) != NULL || (arg != NULL && !hold)) {
        return fail(put, "usage: can bus-off [SECONDS] | can passive | can warning | can active",
                    "", "");
    }
    if (s->can_state == CO_CAN_BUSOFF && states[k].state != CO_CAN_BUSOFF) {
        s->back_state = states[k].state; /* back after the recovery alone, in this state */
        s->busoff_cut = true;
        return true;
    }
    s->can_state = states[k].state;
    s->back_state = CO_CAN_ACTIVE;
    s->busoff_pending = states[k].state == CO_CAN_BUSOFF;
    s->busoff_hold_ms = (uint32_t)hold_ms;
    return true;
}

/* `get`: "ok NAME=VALUE ..." in the product's input order, thousandths,
 * as the Linux program answers it but without its "nmt=" word: the line
 * sees the inputs, not the node (its NMT state is on the bus, in the
 * heartbeat). Words after it: answered "error" instead. */
static bool cmd_get(serial_link_t *s, tokens_t *t, serial_put_fn put)
{
    if (next_token(t) != NULL) {
        return fail(put, "get takes nothing after it", "", "");
    }
    put_str(put, "ok");
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && s->prod->inputs[i].name != NULL; i++) {
        int32_t v = s->values[i];
        uint32_t m = v < 0 ? 0u - (uint32_t)v : (uint32_t)v;
        put(' ');
        put_str(put, s->prod->inputs[i].name);
        put_str(put, v < 0 ? "=-" : "=");
        put_uint(put, m / 1000u);
        m %= 1000u;
        put('.');
        put((char)('0' + m / 100u));
        put((char)('0' + m / 10u % 10u));
        put((char)('0' + m % 10u));
    }
    put('\r');
    return false; /* answered already: no "ok" after it */
}

/* The line language's verbs this image serves: each answers its line
 * itself when it fails (or, get, when it succeeds) and returns whether
 * "ok" is still to be sent. */
static const struct {
    const char *name;
    bool (*run)(serial_link_t *s, tokens_t *t, serial_put_fn put);
} verbs[] = {{"set", cmd_set}, {"fault", cmd_fault}, {"can", cmd_can}, {"get", cmd_get}};

/* The Linux program's verbs this image does not have, each answered
 * "error: 'WORD' is not on this target (...)" rather than "unknown
 * command": ramp, sine and noise are motion generators of the simulation
 * that would need a clock and per-input state in the image (a master
 * scripts the same motion as a series of `set` lines); replay reads a
 * file, and the image has no file system; quit: the image runs until QEMU
 * ends (tools/emu, SIGTERM); unplug and heartbeat, the master-facing
 * faults, are the Linux program's port's so far (the images' board code
 * would carry them: not yet written). */
static const char *const absent[] = {"ramp", "sine",   "noise",    "replay",
                                     "quit", "unplug", "heartbeat"};

const char *serial_link_verb(unsigned i)
{
    return i < sizeof(verbs) / sizeof(verbs[0]) ? verbs[i].name : NULL;
}

const char *serial_link_absent_verb(unsigned i)
{
    return i < sizeof(absent) / sizeof(absent[0]) ? absent[i] : NULL;
}

/* "error: " a, cmd, b, then the verbs served: " (set, fault, can, get)". */
static void fail_verbs(serial_put_fn put, const char *a, const char *cmd, const char *b)
{
    put_str(put, "error: ");
    put_str(put, a);
    put_str(put, cmd);
    put_str(put, b);
    put_str(put, " (");
    for (unsigned i = 0; i < sizeof(verbs) / sizeof(verbs[0]); i++) {
        put_str(put, i > 0u ? ", " : "");
        put_str(put, verbs[i].name);
    }
    put_str(put, ")\r");
}

/* One complete input line, NUL-terminated in s->line. */
static void input_line(serial_link_t *s, serial_put_fn put)
{
    tokens_t t = {.at = s->line};
    char *cmd = next_token(&t);
    if (cmd == NULL) {
        return; /* blank: nothing to answer */
    }
    for (unsigned i = 0; i < sizeof(verbs) / sizeof(verbs[0]); i++) {
        if (equal(cmd, verbs[i].name)) {
            if (verbs[i].run(s, &t, put)) {
                put_str(put, "ok\r");
            }
            return;
        }
    }
    bool here = true;
    for (unsigned i = 0; i < sizeof(absent) / sizeof(absent[0]); i++) {
        here = here && !equal(cmd, absent[i]);
    }
    if (here) {
        fail_verbs(put, "unknown command '", cmd, "'");
    } else {
        fail_verbs(put, "'", cmd, "' is not on this target");
    }
}
#endif

/* A frame line of n characters ("t" or "r", 3 hex digits of identifier,
 * 1 of length, the data) into *f; false for anything else. */
static bool frame_line(const serial_link_t *s, unsigned n, co_frame_t *f)
{
    if (n < 5u || (s->line[0] != 't' && s->line[0] != 'r')) {
        return false;
    }
    unsigned v[21];
    for (unsigned i = 1; i < n; i++) {
        v[i] = (unsigned)hex_value(s->line[i]); /* hex checked by the caller */
    }
    f->rtr = s->line[0] == 'r';
    f->id = (uint16_t)(v[1] << 8 | v[2] << 4 | v[3]);
    f->dlc = (uint8_t)v[4];
    if (f->dlc > 8u || n != (f->rtr ? 5u : 5u + 2u * f->dlc) || f->id > 0x7FFu) {
        return false;
    }
    for (unsigned i = 0; i < f->dlc && !f->rtr; i++) {
        f->data[i] = (uint8_t)(v[5u + 2u * i] << 4 | v[6u + 2u * i]);
    }
    return true;
}

#ifdef BOARD_BOOT
/* The bootloader's line: SLCAN frames only. Anything else (a line too
 * long, a NUL, an SLCAN command, an input line) is dropped without an
 * answer: the bootloader simulates no sensor, and the line language does
 * not fit its 4 KiB. */
bool serial_link_rx(serial_link_t *s, char c, co_frame_t *f, serial_put_fn put)
{
    (void)put;
    if (c != '\r' && c != '\n') {
        s->overflow = s->overflow || s->len == SERIAL_LINE_MAX;
        s->line[s->len < SERIAL_LINE_MAX ? s->len++ : 0] = c;
        return false;
    }
    unsigned n = s->len;
    bool ok = !s->overflow && n <= 21u;
    s->len = 0;
    s->overflow = false;
    for (unsigned i = 1; i < n && ok; i++) {
        ok = hex_value(s->line[i]) >= 0;
    }
    return ok && frame_line(s, n, f);
}
#else
bool serial_link_rx(serial_link_t *s, char c, co_frame_t *f, serial_put_fn put)
{
    if (c != '\r' && c != '\n') {
        if (s->len < SERIAL_LINE_MAX) {
            s->line[s->len++] = c;
        } else {
            s->overflow = true;
        }
        s->nul = s->nul || c == '\0';
        return false;
    }
    unsigned n = s->len;
    bool bad = s->overflow || s->nul;
    const char *why = s->overflow ? "line too long" : "line holds a NUL byte";
    s->len = 0;
    s->overflow = false;
    s->nul = false;
    /* SLCAN: a command letter and hex digits only. */
    bool slcan = n > 0u;
    for (unsigned i = 1; i < n && slcan; i++) {
        slcan = hex_value(s->line[i]) >= 0;
    }
    if (slcan) {
        /* A controller in bus-off receives nothing either (as the Linux
         * program's): frames of that time are lost. */
        return !bad && n <= 21u && s->can_state != CO_CAN_BUSOFF && frame_line(s, n, f);
    }
    if (bad) {
        return fail(put, why, "", "");
    }
    s->line[n] = '\0';
    input_line(s, put);
    return false;
}
#endif
