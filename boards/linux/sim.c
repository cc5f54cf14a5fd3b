/*
 * sim.c - see sim.h.
 */
#include "sim.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

static int input_index(const product_t *p, const char *name, size_t len)
{
    for (int i = 0; i < (int)PRODUCT_MAX_INPUTS && p->inputs[i].name != NULL; i++) {
        if (strlen(p->inputs[i].name) == len && strncmp(p->inputs[i].name, name, len) == 0) {
            return i;
        }
    }
    return -1;
}

static void names(const product_t *p, char *buf, size_t len)
{
    buf[0] = '\0';
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && p->inputs[i].name != NULL; i++) {
        size_t at = strlen(buf);
        snprintf(buf + at, len - at, "%s%s=<%s>", i ? " " : "", p->inputs[i].name,
                 p->inputs[i].unit);
    }
}

void sim_init(sim_t *s, const product_t *p)
{
    memset(s, 0, sizeof(*s));
    s->prod = p;
    s->seed = SIM_SEED_DEFAULT;
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        s->values[i] = p->inputs[i].initial;
        s->motion[i].kind = SIM_HOLD;
        s->motion[i].from = p->inputs[i].initial;
        s->replay.col[i] = -1;
    }
}

void sim_seed(sim_t *s, uint64_t seed)
{
    s->seed = seed;
}

/* splitmix64's output function: a well-mixed 64-bit value of x. */
static uint64_t mix64(uint64_t x)
{
    x += 0x9E3779B97F4A7C15u;
    x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9u;
    x = (x ^ (x >> 27)) * 0x94D049BB133111EBu;
    return x ^ (x >> 31);
}

/* A uniform number in (0, 1] from 64 random bits. */
static double unit_interval(uint64_t r)
{
    return (double)((r >> 11) + 1u) * (1.0 / 9007199254740992.0);
}

/*
 * Standard normal value of input i in simulated millisecond ms: counter-
 * based (a function of seed, i and ms only), Box-Muller on two uniforms.
 */
static double gauss(uint64_t seed, unsigned i, uint64_t ms)
{
    uint64_t key = mix64(seed) ^ mix64(ms * PRODUCT_MAX_INPUTS + i);
    double u1 = unit_interval(mix64(key));
    double u2 = unit_interval(mix64(key ^ 0xD1B54A32D192ED03u));
    return sqrt(-2.0 * log(u1)) * cos(6.283185307179586 * u2);
}

/* num / den rounded to nearest (halves away from zero), den > 0. */
static int64_t div_round(int64_t num, int64_t den)
{
    return num >= 0 ? (num + den / 2) / den : -((-num + den / 2) / den);
}

/* a * b / c rounded (b >= 0, c > 0). Exact in 64 bits while a * b fits;
 * beyond (the GSH-A's +-100 000 mm ramped over a day: 2e8 x 8.6e10), in
 * double, whose error there is far below a thousandth. */
static int64_t scale_round(int64_t a, int64_t b, int64_t c)
{
    int64_t mag = a >= 0 ? a : -a;
    if (b == 0 || mag <= INT64_MAX / b) {
        return div_round(a * b, c);
    }
    return (int64_t)llround((double)a * (double)b / (double)c);
}

/* The motion's value of input i at simulated time t (noise left out). */
static int32_t motion_value(const sim_t *s, unsigned i, uint64_t t)
{
    const sim_motion_t *m = &s->motion[i];
    uint64_t el = t - m->start_us; /* commands start at the last step: t >= start */
    switch (m->kind) {
    case SIM_RAMP:
        if (el >= m->dur_us) {
            return m->to;
        }
        return m->from + (int32_t)scale_round((int64_t)m->to - m->from, (int64_t)el,
                                              (int64_t)m->dur_us);
    case SIM_SINE: {
        double phase = (double)(el % m->dur_us) / (double)m->dur_us;
        return m->from + (int32_t)lround((double)m->amp * sin(6.283185307179586 * phase));
    }
    case SIM_REPLAY: {
        const sim_replay_t *r = &s->replay;
        int c = r->col[i];
        if (el < r->t_us[0]) {
            return m->from;
        }
        uint32_t k = 1;
        while (k < r->rows && r->t_us[k] <= el) {
            k++;
        }
        if (k >= r->rows) {
            return r->v[r->rows - 1u][c];
        }
        int64_t v0 = r->v[k - 1u][c];
        int64_t dt = (int64_t)(r->t_us[k] - r->t_us[k - 1u]);
        return (int32_t)(v0 + scale_round(r->v[k][c] - v0, (int64_t)(el - r->t_us[k - 1u]), dt));
    }
    case SIM_HOLD:
    default:
        return m->from;
    }
}

/* values[] at the simulated time: motion + noise, saturated at +-limit. */
static void compute(sim_t *s)
{
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && s->prod->inputs[i].name != NULL; i++) {
        int64_t v = motion_value(s, i, s->t_us);
        if (s->motion[i].sd != 0) {
            v += lround((double)s->motion[i].sd * gauss(s->seed, i, s->t_us / 1000u));
        }
        int64_t lim = (int64_t)s->prod->inputs[i].limit * 1000;
        v = v > lim ? lim : v < -lim ? -lim : v;
        s->values[i] = (int32_t)v;
    }
}

void sim_step(sim_t *s, uint32_t now_us)
{
    if (s->stepped) {
        s->t_us += (uint32_t)(now_us - s->last_us);
    }
    s->stepped = true;
    s->last_us = now_us;
    compute(s);
}

/* A new motion of input i from now on (its noise kept). */
static void start_motion(sim_t *s, unsigned i, sim_kind_t kind, int32_t from)
{
    sim_motion_t *m = &s->motion[i];
    m->kind = kind;
    m->from = from;
    m->start_us = s->t_us;
    if (s->replay.col[i] >= 0 && kind != SIM_REPLAY) {
        s->replay.col[i] = -1; /* off the replay */
    }
}

/* The product's fault names as "a|b|c" ("" when it has none). */
static void fault_list(const product_t *p, char *buf, size_t len)
{
    buf[0] = '\0';
    for (unsigned k = 0; k < PRODUCT_MAX_INPUTS && p->faults[k] != NULL; k++) {
        size_t at = strlen(buf);
        snprintf(buf + at, len - at, "%s%s", k ? "|" : "", p->faults[k]);
    }
}

void sim_describe(const product_t *p, char *buf, size_t len)
{
    char in[128];
    char fl[96];
    names(p, in, sizeof(in));
    fault_list(p, fl, sizeof(fl));
    snprintf(buf, len, "set %s; %s%s", in, fl[0] != '\0' ? "fault " : "no faults", fl);
}

/* `can bus-off [SECONDS]`, `can passive|warning|active`. */
static bool can_command(sim_t *s, char **save, char *err, unsigned errlen)
{
    static const char *const states[] = {"active", "warning", "passive", "bus-off"};
    char *what = strtok_r(NULL, " \t\r", save);
    char *arg = strtok_r(NULL, " \t\r", save);
    int st = -1;
    for (int k = 0; k < 4 && what != NULL; k++) {
        if (strcmp(what, states[k]) == 0) {
            st = k;
        }
    }
    double hold = 0.0;
    if (st == (int)CO_CAN_BUSOFF && arg != NULL) {
        char *end;
        hold = strtod(arg, &end);
        /* at most 30 min: the deadline stays within half the 32-bit
         * microsecond clock the board's timers compare on */
        if (end == arg || *end != '\0' || !isfinite(hold) || hold < 0.0 || hold > 1800.0) {
            snprintf(err, errlen, "'%s': not a number of seconds within 0..1800", arg);
            return false;
        }
        arg = strtok_r(NULL, " \t\r", save);
    }
    if (st < 0 || arg != NULL) {
        snprintf(err, errlen, "usage: can bus-off [SECONDS] | can passive | can warning | "
                              "can active");
        return false;
    }
    s->can_request = true;
    s->can_state = (co_can_state_t)st;
    s->can_hold_ms = (uint32_t)lround(hold * 1000.0);
    return true;
}

/* "12.5" into thousandths, within +-lim: false if not such a number. */
static bool parse_value(const char *str, double lim, int32_t *out)
{
    char *end;
    double x = strtod(str, &end);
    if (end == str || *end != '\0' || !isfinite(x) || fabs(x) > lim) {
        return false;
    }
    *out = (int32_t)lround(x * 1000.0);
    return true;
}

/* "5s", "250ms", "1.5s" into microseconds: more than 0 (at least 1 us
 * after rounding), at most SIM_DURATION_MAX_S. */
static bool parse_duration(const char *str, uint64_t *us)
{
    char *end;
    double x = strtod(str, &end);
    double scale;
    if (end == str || !isfinite(x)) {
        return false;
    }
    if (strcmp(end, "s") == 0) {
        scale = 1e6;
    } else if (strcmp(end, "ms") == 0) {
        scale = 1e3;
    } else {
        return false;
    }
    double t = x * scale;
    if (!(t >= 1.0) || t > (double)SIM_DURATION_MAX_S * 1e6) {
        return false;
    }
    *us = (uint64_t)llround(t);
    return true;
}

/* `KEY=VALUE` with this key: the value, else NULL. */
static const char *keyed(const char *tok, const char *key)
{
    size_t n = strlen(key);
    return tok != NULL && strncmp(tok, key, n) == 0 && tok[n] == '=' ? tok + n + 1 : NULL;
}

/* The product's input names as "x|y". */
static void input_list(const product_t *p, char *buf, size_t len)
{
    buf[0] = '\0';
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && p->inputs[i].name != NULL; i++) {
        size_t at = strlen(buf);
        snprintf(buf + at, len - at, "%s%s", i ? "|" : "", p->inputs[i].name);
    }
}

/* `ramp NAME=VALUE in DURATION`, `sine NAME amp=A period=DURATION`,
 * `noise NAME sd=S`: checked whole, then applied. */
static bool motion_command(sim_t *s, const char *cmd, char **save, char *err, unsigned errlen)
{
    char list[64];
    input_list(s->prod, list, sizeof(list));
    char *a = strtok_r(NULL, " \t\r", save);
    char *b = strtok_r(NULL, " \t\r", save);
    char *c = strtok_r(NULL, " \t\r", save);
    bool extra = strtok_r(NULL, " \t\r", save) != NULL;
    char *eq = a != NULL ? strchr(a, '=') : NULL;
    size_t nlen = a == NULL ? 0u : eq != NULL ? (size_t)(eq - a) : strlen(a);
    int i = a != NULL ? input_index(s->prod, a, nlen) : -1;
    double lim = i >= 0 ? s->prod->inputs[i].limit : 0.0;
    int32_t now = i >= 0 ? motion_value(s, (unsigned)i, s->t_us) : 0;
    if (strcmp(cmd, "ramp") == 0) {
        int32_t to = 0;
        uint64_t dur = 0;
        if (i < 0 || eq == NULL || b == NULL || strcmp(b, "in") != 0 || c == NULL || extra) {
            snprintf(err, errlen, "usage: ramp %s=VALUE in DURATION (e.g. 5s, 250ms)", list);
            return false;
        }
        if (!parse_value(eq + 1, lim, &to)) {
            snprintf(err, errlen, "'%s': not a number within +-%.0f", a, lim);
            return false;
        }
        if (!parse_duration(c, &dur)) {
            snprintf(err, errlen, "'%s': not a duration (s or ms, more than 0, at most %us)", c,
                     SIM_DURATION_MAX_S);
            return false;
        }
        start_motion(s, (unsigned)i, SIM_RAMP, now);
        s->motion[i].to = to;
        s->motion[i].dur_us = dur;
        return true;
    }
    if (strcmp(cmd, "sine") == 0) {
        const char *amp = keyed(b, "amp") != NULL ? keyed(b, "amp") : keyed(c, "amp");
        const char *per = keyed(b, "period") != NULL ? keyed(b, "period") : keyed(c, "period");
        int32_t am = 0;
        uint64_t dur = 0;
        if (i < 0 || eq != NULL || amp == NULL || per == NULL || extra) {
            snprintf(err, errlen, "usage: sine %s amp=A period=DURATION (e.g. 2s, 500ms)", list);
            return false;
        }
        if (!parse_value(amp, lim, &am) || am < 0) {
            snprintf(err, errlen, "amp=%s: not a number within 0..%.0f", amp, lim);
            return false;
        }
        if (!parse_duration(per, &dur)) {
            snprintf(err, errlen, "period=%s: not a duration (s or ms, more than 0, at most %us)",
                     per, SIM_DURATION_MAX_S);
            return false;
        }
        if (llabs((long long)now) + am > (long long)lim * 1000) {
            snprintf(err, errlen, "sine around %.3f with amp=%s leaves +-%.0f", now / 1000.0, amp,
                     lim);
            return false;
        }
        start_motion(s, (unsigned)i, SIM_SINE, now);
        s->motion[i].amp = am;
        s->motion[i].dur_us = dur;
        return true;
    }
    /* noise */
    const char *sd = keyed(b, "sd");
    int32_t v = 0;
    if (i < 0 || eq != NULL || sd == NULL || c != NULL) {
        snprintf(err, errlen, "usage: noise %s sd=S (S >= 0 in the input's unit; 0 stops it)",
                 list);
        return false;
    }
    if (!parse_value(sd, lim, &v) || v < 0) {
        snprintf(err, errlen, "sd=%s: not a number within 0..%.0f", sd, lim);
        return false;
    }
    s->motion[i].sd = v;
    return true;
}

/* Split a CSV line at commas into at most max fields (spaces around them
 * trimmed); returns the count, or max + 1 when there are more. */
static unsigned csv_fields(char *line, char *field[], unsigned max)
{
    unsigned n = 0;
    char *p = line;
    for (;;) {
        char *comma = strchr(p, ',');
        if (comma != NULL) {
            *comma = '\0';
        }
        if (n == max) {
            return max + 1u;
        }
        p += strspn(p, " \t");
        size_t len = strlen(p);
        while (len > 0u && (p[len - 1u] == ' ' || p[len - 1u] == '\t' || p[len - 1u] == '\r')) {
            p[--len] = '\0';
        }
        field[n++] = p;
        if (comma == NULL) {
            return n;
        }
        p = comma + 1;
    }
}

/* A replay file read a block at a time (one system call per block, not
 * per line), cut into lines. */
typedef struct line_reader {
    int fd;
    char buf[4096];
    size_t pos, len;
    unsigned long total; /* bytes read */
    bool eof;
} line_reader_t;

/* The reader's results (next_line). */
enum { LR_LINE = 1, LR_END = 0, LR_LONG = -1, LR_NUL = -2, LR_READ = -3, LR_BIG = -4 };

/* The next line, without its newline, into line (SIM_LINE_MAX + 1 bytes):
 * LR_LINE; LR_END at the end; LR_LONG, LR_NUL for a line too long or
 * holding a NUL byte; LR_READ (errno) when read() fails; LR_BIG past
 * SIM_REPLAY_BYTES (a file that grew after fstat). */
static int next_line(line_reader_t *lr, char *line)
{
    size_t n = 0;
    bool nul = false;
    for (;;) {
        if (lr->pos == lr->len) {
            if (lr->eof) {
                break;
            }
            ssize_t got = read(lr->fd, lr->buf, sizeof(lr->buf));
            if (got < 0 && errno == EINTR) {
                continue;
            }
            if (got < 0) {
                return LR_READ;
            }
            lr->pos = 0;
            lr->len = (size_t)got;
            lr->total += (unsigned long)got;
            lr->eof = got == 0;
            if (lr->total > SIM_REPLAY_BYTES) {
                return LR_BIG;
            }
            continue;
        }
        char c = lr->buf[lr->pos++];
        if (c == '\n') {
            line[n] = '\0';
            return nul ? LR_NUL : LR_LINE;
        }
        if (n == SIM_LINE_MAX) {
            return LR_LONG;
        }
        nul |= c == '\0';
        line[n++] = c;
    }
    line[n] = '\0';
    return n == 0u ? LR_END : nul ? LR_NUL : LR_LINE; /* a last line without newline */
}

bool sim_replay_load(const product_t *prod, const char *file, sim_replay_t *r, char *err,
                     unsigned errlen)
{
    /* A relative name is the program's working directory's: an error
     * says which directory that is. */
    char where[300] = "";
    char cwd[256];
    if (file[0] != '/' && getcwd(cwd, sizeof(cwd)) != NULL) {
        snprintf(where, sizeof(where), " (in %s, the program's working directory)", cwd);
    }
    /* Opened without waiting (a FIFO with no writer would block the
     * whole program, every node), and only a regular file is read. */
    int fd = open(file, O_RDONLY | O_NONBLOCK | O_CLOEXEC);
    struct stat st;
    if (fd < 0 || fstat(fd, &st) != 0) {
        snprintf(err, errlen, "replay %s: %s%s", file, strerror(errno), where);
        if (fd >= 0) {
            close(fd);
        }
        return false;
    }
    if (!S_ISREG(st.st_mode)) {
        snprintf(err, errlen, "replay %s: not a regular file", file);
        close(fd);
        return false;
    }
    /* The whole file is read while every node waits (one thread): its
     * size bounds that wait (a few milliseconds at the limit). A table
     * of SIM_REPLAY_ROWS rows fits many times over. */
    if (st.st_size > (off_t)SIM_REPLAY_BYTES) {
        snprintf(err, errlen, "replay %s: %lld bytes, more than the %u a replay file may have "
                 "(it is read while every node waits)", file, (long long)st.st_size,
                 SIM_REPLAY_BYTES);
        close(fd);
        return false;
    }
    line_reader_t lr = {.fd = fd};
    char line[SIM_LINE_MAX + 1u];
    char *field[PRODUCT_MAX_INPUTS + 1u];
    int input_of[PRODUCT_MAX_INPUTS + 1u] = {0}; /* column -> input */
    unsigned cols = 0;                           /* 0: header not read yet */
    unsigned no = 0;
    bool ok = true;
    memset(r, 0, sizeof(*r));
    memset(r->col, -1, sizeof(r->col));
    int got;
    while (ok && (got = next_line(&lr, line)) != LR_END) {
        no++;
        if (got == LR_READ) {
            snprintf(err, errlen, "replay %s: read error: %s", file, strerror(errno));
            ok = false;
            break;
        }
        if (got == LR_BIG) {
            snprintf(err, errlen, "replay %s: grew past %u bytes while read", file,
                     SIM_REPLAY_BYTES);
            ok = false;
            break;
        }
        if (got == LR_NUL) {
            snprintf(err, errlen, "replay %s: line %u: holds a NUL byte", file, no);
            ok = false;
            break;
        }
        if (got == LR_LONG) {
            snprintf(err, errlen, "replay %s: line %u: longer than %u characters", file, no,
                     SIM_LINE_MAX);
            ok = false;
            break;
        }
        if (no == 1u && strncmp(line, "\xEF\xBB\xBF", 3) == 0) {
            /* UTF-8's byte order mark, as spreadsheets save CSV: not data */
            memmove(line, line + 3, strlen(line + 3) + 1u);
        }
        size_t lead = strspn(line, " \t\r");
        if (line[lead] == '\0' || line[lead] == '#') {
            continue;
        }
        unsigned n = csv_fields(line, field, PRODUCT_MAX_INPUTS + 1u);
        if (cols == 0u) {
            if (n < 2u || n > PRODUCT_MAX_INPUTS + 1u ||
                (strcmp(field[0], "t") != 0 && strcmp(field[0], "time") != 0)) {
                snprintf(err, errlen, "replay %s: line %u: expected a header t,NAME,...", file,
                         no);
                ok = false;
                break;
            }
            for (unsigned k = 1; k < n && ok; k++) {
                int i = input_index(prod, field[k], strlen(field[k]));
                if (i < 0 || r->col[i] >= 0) {
                    snprintf(err, errlen, "replay %s: line %u: '%s' is %s", file, no, field[k],
                             i < 0 ? "not one of the product's inputs" : "named twice");
                    ok = false;
                } else {
                    r->col[i] = (int8_t)(k - 1u);
                    input_of[k - 1u] = i;
                }
            }
            cols = n;
            continue;
        }
        if (n != cols) {
            snprintf(err, errlen, "replay %s: line %u: not %u fields like the header", file, no,
                     cols);
            ok = false;
            break;
        }
        if (r->rows >= SIM_REPLAY_ROWS) {
            snprintf(err, errlen, "replay %s: more than %u rows", file, SIM_REPLAY_ROWS);
            ok = false;
            break;
        }
        char *end;
        double t = strtod(field[0], &end);
        if (end == field[0] || *end != '\0' || !isfinite(t) || t < 0.0 ||
            t > (double)SIM_DURATION_MAX_S) {
            snprintf(err, errlen, "replay %s: line %u: time '%s' not within 0..%u s", file, no,
                     field[0], SIM_DURATION_MAX_S);
            ok = false;
            break;
        }
        uint64_t tu = (uint64_t)llround(t * 1e6);
        if (r->rows > 0u && tu <= r->t_us[r->rows - 1u]) {
            snprintf(err, errlen, "replay %s: line %u: time %s not after the row before", file,
                     no, field[0]);
            ok = false;
            break;
        }
        r->t_us[r->rows] = tu;
        for (unsigned k = 1; k < n && ok; k++) {
            double lim = prod->inputs[input_of[k - 1u]].limit;
            if (!parse_value(field[k], lim, &r->v[r->rows][k - 1u])) {
                snprintf(err, errlen, "replay %s: line %u: '%s' not a number within +-%.0f",
                         file, no, field[k], lim);
                ok = false;
            }
        }
        r->rows++;
    }
    if (ok && r->rows == 0u) {
        snprintf(err, errlen, "replay %s: %s", file, cols == 0u ? "empty" : "no data rows");
        ok = false;
    }
    close(fd);
    return ok;
}

void sim_replay_start(sim_t *s, const sim_replay_t *table)
{
    int32_t now[PRODUCT_MAX_INPUTS];
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        now[i] = motion_value(s, i, s->t_us);
    }
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        if (s->motion[i].kind == SIM_REPLAY) {
            start_motion(s, i, SIM_HOLD, now[i]); /* the former replay stops */
        }
    }
    if (table != &s->replay) {
        s->replay = *table;
    }
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        if (s->replay.col[i] >= 0) {
            start_motion(s, i, SIM_REPLAY, now[i]);
        }
    }
    compute(s);
}

bool sim_command(sim_t *s, const char *line, char *err, unsigned errlen)
{
    char buf[SIM_LINE_MAX + 1u];
    if (strlen(line) >= sizeof(buf)) {
        snprintf(err, errlen, "line too long");
        return false;
    }
    snprintf(buf, sizeof(buf), "%s", line);
    char *save = NULL;
    char *cmd = strtok_r(buf, " \t\r", &save);
    if (cmd == NULL || cmd[0] == '#') {
        return true; /* empty line or comment */
    }
    if (strcmp(cmd, "quit") == 0) {
        s->quit = true;
        return true;
    }
    if (strcmp(cmd, "get") == 0) {
        if (strtok_r(NULL, " \t\r", &save) != NULL) {
            snprintf(err, errlen, "get takes nothing after it");
            return false;
        }
        s->get_request = true;
        return true;
    }
    if (strcmp(cmd, "fault") == 0) {
        char *what = strtok_r(NULL, " \t\r", &save);
        char *onoff = strtok_r(NULL, " \t\r", &save);
        int i = -1;
        char list[96];
        fault_list(s->prod, list, sizeof(list));
        if (list[0] == '\0') {
            snprintf(err, errlen, "%s has no simulated faults", s->prod->id);
            return false;
        }
        for (int k = 0; k < (int)PRODUCT_MAX_INPUTS && s->prod->faults[k] != NULL; k++) {
            if (what != NULL && strcmp(what, s->prod->faults[k]) == 0) {
                i = k;
            }
        }
        if (i < 0 || onoff == NULL || (strcmp(onoff, "on") != 0 && strcmp(onoff, "off") != 0) ||
            strtok_r(NULL, " \t\r", &save) != NULL) {
            snprintf(err, errlen, "usage: fault %s on|off", list);
            return false;
        }
        if (strcmp(onoff, "on") == 0) {
            s->faults |= 1u << i;
        } else {
            s->faults &= ~(1u << i);
        }
        return true;
    }
    if (strcmp(cmd, "set") == 0) {
        int32_t v[PRODUCT_MAX_INPUTS] = {0};
        bool named[PRODUCT_MAX_INPUTS] = {false};
        char usage[128];
        names(s->prod, usage, sizeof(usage));
        char *tok;
        int count = 0;
        while ((tok = strtok_r(NULL, " \t\r", &save)) != NULL) {
            char *eq = strchr(tok, '=');
            int i = eq != NULL ? input_index(s->prod, tok, (size_t)(eq - tok)) : -1;
            if (i < 0) {
                snprintf(err, errlen, "'%s': expected %s", tok, usage);
                return false;
            }
            double lim = s->prod->inputs[i].limit;
            if (!parse_value(eq + 1, lim, &v[i])) {
                snprintf(err, errlen, "'%s': not a number within +-%.0f", tok, lim);
                return false;
            }
            named[i] = true;
            count++;
        }
        if (count == 0) {
            snprintf(err, errlen, "usage: set %s", usage);
            return false;
        }
        for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
            if (named[i]) {
                start_motion(s, i, SIM_HOLD, v[i]);
            }
        }
        compute(s);
        return true;
    }
    if (strcmp(cmd, "ramp") == 0 || strcmp(cmd, "sine") == 0 || strcmp(cmd, "noise") == 0) {
        if (!motion_command(s, cmd, &save, err, errlen)) {
            return false;
        }
        compute(s);
        return true;
    }
    if (strcmp(cmd, "replay") == 0) {
        char *file = strtok_r(NULL, " \t\r", &save);
        if (file == NULL || strtok_r(NULL, " \t\r", &save) != NULL) {
            snprintf(err, errlen, "usage: replay FILE.csv (no spaces in FILE)");
            return false;
        }
        sim_replay_t r;
        if (!sim_replay_load(s->prod, file, &r, err, errlen)) {
            return false;
        }
        sim_replay_start(s, &r);
        return true;
    }
    if (strcmp(cmd, "can") == 0) {
        return can_command(s, &save, err, errlen);
    }
    snprintf(err, errlen,
             "unknown command '%s' (" SIM_VERBS ")", cmd);
    return false;
}

/* One complete line: apply it, or reject it whole. */
static void end_line(sim_t *s, sim_report_fn report, void *ctx)
{
    s->line[s->len] = '\0';
    char err[600]; /* a replay error: two paths (the file's, the working directory) */
    if (s->overflow) {
        snprintf(err, sizeof(err), "line too long (more than %u characters): ignored",
                 SIM_LINE_MAX);
        report(ctx, "", err);
    } else if (s->nul) {
        /* Not cut at the NUL: "set x=11<NUL>y=99" is neither command. */
        report(ctx, "", "line contains a NUL byte: ignored");
    } else if (s->route != NULL && s->route(s->route_ctx, s->line, err, sizeof(err))) {
        report(ctx, s->line, err[0] != '\0' ? err : NULL);
    } else if (!sim_command(s, s->line, err, sizeof(err))) {
        report(ctx, s->line, err);
    } else {
        size_t i = strspn(s->line, " \t\r");
        if (s->line[i] != '\0' && s->line[i] != '#') {
            report(ctx, s->line, NULL);
        }
    }
    s->len = 0;
    s->overflow = false;
    s->nul = false;
}

void sim_feed(sim_t *s, const char *data, size_t n, sim_report_fn report, void *ctx)
{
    for (size_t i = 0; i < n; i++) {
        char c = data[i];
        if (c == '\n') {
            end_line(s, report, ctx);
        } else if (s->len >= SIM_LINE_MAX) {
            s->overflow = true;
        } else {
            s->nul |= c == '\0';
            s->line[s->len++] = c;
        }
    }
}

void sim_feed_end(sim_t *s, sim_report_fn report, void *ctx)
{
    if (s->len > 0u || s->overflow) {
        end_line(s, report, ctx);
    }
}
