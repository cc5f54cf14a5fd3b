/*
 * cmd.c - the line language; see cmd.h. A verb is one row of cmd_verbs[]
 * and its two functions: parse (check, change nothing) and apply.
 */
#include "cmd.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

#include "app.h"
#include "log.h"
#include "sim.h"

/* What a line is served with: the program, the time, and the replay
 * tables the line loaded, one per product (a->replay[t] is table_of[t]'s):
 * the file is read once for all the instances of a product, while every
 * node waits, and each instance takes what was read and checked. */
struct cmd_ctx {
    app_t *a;
    uint32_t now;
    unsigned ntables;
    const product_t *table_of[APP_REPLAY_TABLES];
};

/* ---- Line assembly ------------------------------------------------------ */

bool cmd_lines_put(cmd_lines_t *lb, char c)
{
    if (c == '\n') {
        return true;
    }
    if (lb->len >= CMD_LINE_MAX) {
        lb->overflow = true;
    } else {
        lb->nul = lb->nul || c == '\0';
        lb->line[lb->len++] = c;
    }
    return false;
}

bool cmd_lines_pending(const cmd_lines_t *lb)
{
    return lb->len > 0u || lb->overflow;
}

const char *cmd_lines_take(cmd_lines_t *lb, char *err, size_t errlen)
{
    bool overflow = lb->overflow;
    bool nul = lb->nul;
    size_t n = lb->len;
    lb->len = 0;
    lb->overflow = false;
    lb->nul = false;
    if (overflow) {
        snprintf(err, errlen, "line longer than %u characters", CMD_LINE_MAX);
        return NULL;
    }
    if (nul) {
        /* Not cut at the NUL: "set x=11<NUL>y=99" is neither command. */
        snprintf(err, errlen, "line holds a NUL byte");
        return NULL;
    }
    if (n > 0u && lb->line[n - 1u] == '\r') {
        n--;
    }
    lb->line[n] = '\0';
    return lb->line;
}

size_t cmd_answer_line(const char *text, char *out)
{
    size_t n = strnlen(text, CMD_REPLY_MAX);
    memcpy(out, text, n);
    out[n] = '\n';
    return n + 1u;
}

/* ---- Arguments ---------------------------------------------------------- */

/* The next blank-separated token, or NULL. */
static char *token(char **save)
{
    return strtok_r(NULL, " \t\r", save);
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

/* The product's input names as "x|y" (units: "x=<deg> y=<deg>"). */
static void input_list(const product_t *p, bool units, char *buf, size_t len)
{
    buf[0] = '\0';
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && p->inputs[i].name != NULL; i++) {
        size_t at = strlen(buf);
        if (units) {
            snprintf(buf + at, len - at, "%s%s=<%s>", i ? " " : "", p->inputs[i].name,
                     p->inputs[i].unit);
        } else {
            snprintf(buf + at, len - at, "%s%s", i ? "|" : "", p->inputs[i].name);
        }
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

void cmd_describe(const product_t *p, char *buf, size_t len)
{
    char in[128];
    char fl[96];
    input_list(p, true, in, sizeof(in));
    fault_list(p, fl, sizeof(fl));
    snprintf(buf, len, "set %s; %s%s", in, fl[0] != '\0' ? "fault " : "no faults", fl);
}

static sim_t *inst_sim(cmd_ctx_t *c, unsigned k)
{
    return &c->a->inst[k].sim;
}

/* ---- The verbs: parse, apply -------------------------------------------- */

static bool parse_set(cmd_ctx_t *c, unsigned k, char **save, cmd_args_t *args, char *err,
                      size_t errlen)
{
    const product_t *p = inst_sim(c, k)->prod;
    char usage[128];
    input_list(p, true, usage, sizeof(usage));
    char *tok;
    int count = 0;
    while ((tok = token(save)) != NULL) {
        char *eq = strchr(tok, '=');
        int i = eq != NULL ? sim_input_index(p, tok, (size_t)(eq - tok)) : -1;
        if (i < 0) {
            snprintf(err, errlen, "'%s': expected %s", tok, usage);
            return false;
        }
        double lim = p->inputs[i].limit;
        if (!sim_value(eq + 1, lim, &args->v[i])) {
            snprintf(err, errlen, "'%s': not a number within +-%.0f", tok, lim);
            return false;
        }
        args->named[i] = true;
        count++;
    }
    if (count == 0) {
        snprintf(err, errlen, "usage: set %s", usage);
        return false;
    }
    return true;
}

static void apply_set(cmd_ctx_t *c, unsigned k, unsigned node, const cmd_args_t *args)
{
    (void)node;
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        if (args->named[i]) {
            sim_hold(inst_sim(c, k), i, args->v[i]);
        }
    }
}

/* The input a ramp, sine or noise names first ("x=5" or "x"): its index,
 * or -1; *eq the '=' in it or NULL. */
static int motion_input(const product_t *p, const char *tok, const char **eq)
{
    *eq = tok != NULL ? strchr(tok, '=') : NULL;
    size_t n = tok == NULL ? 0u : *eq != NULL ? (size_t)(*eq - tok) : strlen(tok);
    return tok != NULL ? sim_input_index(p, tok, n) : -1;
}

static bool parse_ramp(cmd_ctx_t *c, unsigned k, char **save, cmd_args_t *args, char *err,
                       size_t errlen)
{
    const product_t *p = inst_sim(c, k)->prod;
    char list[64];
    input_list(p, false, list, sizeof(list));
    char *a = token(save);
    char *in = token(save);
    char *d = token(save);
    bool extra = token(save) != NULL;
    const char *eq;
    int i = motion_input(p, a, &eq);
    if (i < 0 || eq == NULL || in == NULL || strcmp(in, "in") != 0 || d == NULL || extra) {
        snprintf(err, errlen, "usage: ramp %s=VALUE in DURATION (e.g. 5s, 250ms)", list);
        return false;
    }
    double lim = p->inputs[i].limit;
    if (!sim_value(eq + 1, lim, &args->value)) {
        snprintf(err, errlen, "'%s': not a number within +-%.0f", a, lim);
        return false;
    }
    if (!parse_duration(d, &args->dur_us)) {
        snprintf(err, errlen, "'%s': not a duration (s or ms, more than 0, at most %us)", d,
                 SIM_DURATION_MAX_S);
        return false;
    }
    args->input = (unsigned)i;
    return true;
}

static void apply_ramp(cmd_ctx_t *c, unsigned k, unsigned node, const cmd_args_t *args)
{
    (void)node;
    sim_ramp(inst_sim(c, k), args->input, args->value, args->dur_us);
}

static bool parse_sine(cmd_ctx_t *c, unsigned k, char **save, cmd_args_t *args, char *err,
                       size_t errlen)
{
    const sim_t *s = inst_sim(c, k);
    char list[64];
    input_list(s->prod, false, list, sizeof(list));
    char *a = token(save);
    char *b = token(save);
    char *d = token(save);
    bool extra = token(save) != NULL;
    const char *eq;
    int i = motion_input(s->prod, a, &eq);
    const char *amp = keyed(b, "amp") != NULL ? keyed(b, "amp") : keyed(d, "amp");
    const char *per = keyed(b, "period") != NULL ? keyed(b, "period") : keyed(d, "period");
    if (i < 0 || eq != NULL || amp == NULL || per == NULL || extra) {
        snprintf(err, errlen, "usage: sine %s amp=A period=DURATION (e.g. 2s, 500ms)", list);
        return false;
    }
    double lim = s->prod->inputs[i].limit;
    if (!sim_value(amp, lim, &args->value) || args->value < 0) {
        snprintf(err, errlen, "amp=%s: not a number within 0..%.0f", amp, lim);
        return false;
    }
    if (!parse_duration(per, &args->dur_us)) {
        snprintf(err, errlen, "period=%s: not a duration (s or ms, more than 0, at most %us)", per,
                 SIM_DURATION_MAX_S);
        return false;
    }
    int32_t now = sim_motion_now(s, (unsigned)i);
    if (llabs((long long)now) + args->value > (long long)lim * 1000) {
        snprintf(err, errlen, "sine around %.3f with amp=%s leaves +-%.0f", now / 1000.0, amp, lim);
        return false;
    }
    args->input = (unsigned)i;
    return true;
}

static void apply_sine(cmd_ctx_t *c, unsigned k, unsigned node, const cmd_args_t *args)
{
    (void)node;
    sim_sine(inst_sim(c, k), args->input, args->value, args->dur_us);
}

static bool parse_noise(cmd_ctx_t *c, unsigned k, char **save, cmd_args_t *args, char *err,
                        size_t errlen)
{
    const product_t *p = inst_sim(c, k)->prod;
    char list[64];
    input_list(p, false, list, sizeof(list));
    char *a = token(save);
    char *b = token(save);
    bool extra = token(save) != NULL;
    const char *eq;
    int i = motion_input(p, a, &eq);
    const char *sd = keyed(b, "sd");
    if (i < 0 || eq != NULL || sd == NULL || extra) {
        snprintf(err, errlen, "usage: noise %s sd=S (S >= 0 in the input's unit; 0 stops it)",
                 list);
        return false;
    }
    double lim = p->inputs[i].limit;
    if (!sim_value(sd, lim, &args->value) || args->value < 0) {
        snprintf(err, errlen, "sd=%s: not a number within 0..%.0f", sd, lim);
        return false;
    }
    args->input = (unsigned)i;
    return true;
}

static void apply_noise(cmd_ctx_t *c, unsigned k, unsigned node, const cmd_args_t *args)
{
    (void)node;
    sim_noise(inst_sim(c, k), args->input, args->value);
}

static bool parse_replay(cmd_ctx_t *c, unsigned k, char **save, cmd_args_t *args, char *err,
                         size_t errlen)
{
    const product_t *p = inst_sim(c, k)->prod;
    char *file = token(save);
    if (file == NULL || token(save) != NULL) {
        snprintf(err, errlen, "usage: replay FILE.csv (no spaces in FILE)");
        return false;
    }
    unsigned t = 0;
    while (t < c->ntables && c->table_of[t] != p) {
        t++;
    }
    if (t == c->ntables) { /* the product's first instance: read the file */
        if (t == APP_REPLAY_TABLES ||
            !replay_csv_load(p, file, &c->a->replay[t], err, (unsigned)errlen)) {
            return false;
        }
        c->table_of[c->ntables++] = p;
    }
    args->table = &c->a->replay[t];
    return true;
}

static void apply_replay(cmd_ctx_t *c, unsigned k, unsigned node, const cmd_args_t *args)
{
    (void)node;
    sim_replay_start(inst_sim(c, k), args->table);
}

static bool parse_fault(cmd_ctx_t *c, unsigned k, char **save, cmd_args_t *args, char *err,
                        size_t errlen)
{
    const product_t *p = inst_sim(c, k)->prod;
    char *what = token(save);
    char *onoff = token(save);
    char list[96];
    fault_list(p, list, sizeof(list));
    if (list[0] == '\0') {
        snprintf(err, errlen, "%s has no simulated faults", p->id);
        return false;
    }
    int f = -1;
    for (int i = 0; i < (int)PRODUCT_MAX_INPUTS && p->faults[i] != NULL; i++) {
        if (what != NULL && strcmp(what, p->faults[i]) == 0) {
            f = i;
        }
    }
    if (f < 0 || onoff == NULL || (strcmp(onoff, "on") != 0 && strcmp(onoff, "off") != 0) ||
        token(save) != NULL) {
        snprintf(err, errlen, "usage: fault %s on|off", list);
        return false;
    }
    args->fault = (unsigned)f;
    args->on = strcmp(onoff, "on") == 0;
    return true;
}

static void apply_fault(cmd_ctx_t *c, unsigned k, unsigned node, const cmd_args_t *args)
{
    (void)node;
    sim_fault(inst_sim(c, k), args->fault, args->on);
}

/* `can bus-off [SECONDS]`, `can passive|warning|active`. */
static bool parse_can(cmd_ctx_t *c, unsigned k, char **save, cmd_args_t *args, char *err,
                      size_t errlen)
{
    (void)c;
    (void)k;
    static const char *const states[] = {
        [CO_CAN_ACTIVE] = "active",
        [CO_CAN_WARNING] = "warning",
        [CO_CAN_PASSIVE] = "passive",
        [CO_CAN_BUSOFF] = "bus-off",
    };
    char *what = token(save);
    char *arg = token(save);
    int st = -1;
    for (int i = 0; i < (int)(sizeof(states) / sizeof(states[0])) && what != NULL; i++) {
        if (strcmp(what, states[i]) == 0) {
            st = i;
        }
    }
    double hold = 0.0;
    if (st == (int)CO_CAN_BUSOFF && arg != NULL) {
        char *end;
        hold = strtod(arg, &end);
        if (end == arg || *end != '\0' || !isfinite(hold) || hold < 0.0 ||
            hold > (double)CMD_HOLD_MAX_S) {
            snprintf(err, errlen, "'%s': not a number of seconds within 0..%u", arg,
                     CMD_HOLD_MAX_S);
            return false;
        }
        arg = token(save);
    }
    if (st < 0 || arg != NULL) {
        snprintf(err, errlen,
                 "usage: can bus-off [SECONDS] | can passive | can warning | "
                 "can active");
        return false;
    }
    args->can_state = (uint8_t)st;
    args->hold_ms = (uint32_t)lround(hold * 1000.0);
    return true;
}

static void apply_can(cmd_ctx_t *c, unsigned k, unsigned node, const cmd_args_t *args)
{
    (void)k;
    app_sim_can(c->a, node, (co_can_state_t)args->can_state, args->hold_ms, c->now);
}

/* `unplug [SECONDS]`, `unplug off`. */
static bool parse_unplug(cmd_ctx_t *c, unsigned k, char **save, cmd_args_t *args, char *err,
                         size_t errlen)
{
    (void)c;
    (void)k;
    char *arg = token(save);
    double hold = 0.0;
    args->on = true;
    if (arg != NULL && strcmp(arg, "off") == 0) {
        args->on = false;
    } else if (arg != NULL) {
        char *end;
        hold = strtod(arg, &end);
        if (end == arg || *end != '\0' || !isfinite(hold) || hold <= 0.0 ||
            hold > (double)CMD_HOLD_MAX_S) {
            snprintf(err, errlen, "'%s': not a number of seconds within 0..%u (more than 0)", arg,
                     CMD_HOLD_MAX_S);
            return false;
        }
    }
    if (token(save) != NULL) {
        snprintf(err, errlen, "usage: unplug [SECONDS] | unplug off");
        return false;
    }
    args->hold_ms = (uint32_t)lround(hold * 1000.0);
    if (args->on && arg != NULL && args->hold_ms == 0u) {
        args->hold_ms = 1u; /* more than 0 s, less than half a millisecond */
    }
    return true;
}

static void apply_unplug(cmd_ctx_t *c, unsigned k, unsigned node, const cmd_args_t *args)
{
    (void)k;
    app_unplug(c->a, node, args->on, args->hold_ms, c->now);
}

/* `heartbeat stop|start`. */
static bool parse_heartbeat(cmd_ctx_t *c, unsigned k, char **save, cmd_args_t *args, char *err,
                            size_t errlen)
{
    (void)c;
    (void)k;
    char *what = token(save);
    if (what == NULL || (strcmp(what, "stop") != 0 && strcmp(what, "start") != 0) ||
        token(save) != NULL) {
        snprintf(err, errlen, "usage: heartbeat stop | heartbeat start");
        return false;
    }
    args->on = strcmp(what, "start") == 0;
    return true;
}

static void apply_heartbeat(cmd_ctx_t *c, unsigned k, unsigned node, const cmd_args_t *args)
{
    (void)k;
    app_heartbeat(c->a, node, args->on);
}

/* Nothing after the verb (get, quit). */
static bool parse_nothing(cmd_ctx_t *c, unsigned k, char **save, cmd_args_t *args, char *err,
                          size_t errlen, const char *verb)
{
    (void)c;
    (void)k;
    (void)args;
    if (token(save) != NULL) {
        snprintf(err, errlen, "%s takes nothing after it", verb);
        return false;
    }
    return true;
}

static bool parse_get(cmd_ctx_t *c, unsigned k, char **save, cmd_args_t *args, char *err,
                      size_t errlen)
{
    return parse_nothing(c, k, save, args, err, errlen, "get");
}

static bool parse_quit(cmd_ctx_t *c, unsigned k, char **save, cmd_args_t *args, char *err,
                       size_t errlen)
{
    return parse_nothing(c, k, save, args, err, errlen, "quit");
}

static void apply_quit(cmd_ctx_t *c, unsigned k, unsigned node, const cmd_args_t *args)
{
    (void)k;
    (void)node;
    (void)args;
    c->a->quit = true;
}

/* The table: a new verb is a row here and its two functions. */
const cmd_verb_t cmd_verbs[] = {
    {"set", "NAME=VALUE ...", "true value of the product's inputs (below)", CMD_INPUTS, parse_set,
     apply_set},
    {"ramp", "NAME=VALUE in DUR",
     "linear from the value now to VALUE over DUR (5s, 250ms, at most a day), then held",
     CMD_INPUTS, parse_ramp, apply_ramp},
    {"sine", "NAME amp=A period=DUR", "around the value now, starting there going up", CMD_INPUTS,
     parse_sine, apply_sine},
    {"noise", "NAME sd=S",
     "Gaussian noise (S in the input's unit) on top of the motion; sd=0 stops it", CMD_INPUTS,
     parse_noise, apply_noise},
    {"replay", "FILE.csv",
     "header t,NAME,... then rows SECONDS,VALUE,... from now: linear between rows, last row "
     "held. set, ramp, sine and replay replace an input's motion, noise stays; values beyond "
     "an input's limit are refused, noise is saturated at it",
     CMD_INPUTS, parse_replay, apply_replay},
    {"fault", "NAME on|off", "force one of the product's faults (below)", CMD_INPUTS, parse_fault,
     apply_fault},
    {"can", "bus-off [SECONDS] | passive | warning | active",
     "the nodes' simulated CAN controller: bus-off sends nothing; the bus stays unusable "
     "SECONDS (default 0, at most 1800), then it is back after 128 x 11 bits at its bit rate",
     CMD_NODES, parse_can, apply_can},
    {"unplug", "[SECONDS] | off",
     "the nodes' cable pulled: no frame in or out, the error counters unchanged, for SECONDS "
     "(at most 1800) or until `unplug off`",
     CMD_NODES, parse_unplug, apply_unplug},
    {"heartbeat", "stop | start",
     "the nodes' heartbeats (and guarding answers) not sent / sent again; the boot-up still "
     "goes",
     CMD_NODES, parse_heartbeat, apply_heartbeat},
    {"get", "", "one node's true inputs and NMT state: ok x=1.000 ... nmt=operational", CMD_QUERY,
     parse_get, NULL},
    {"quit", "", "stop the program", CMD_PROGRAM, parse_quit, apply_quit},
};
const unsigned cmd_nverbs = sizeof(cmd_verbs) / sizeof(cmd_verbs[0]);

void cmd_verb_names(char *buf, size_t len)
{
    buf[0] = '\0';
    for (unsigned v = 0; v < cmd_nverbs; v++) {
        size_t at = strlen(buf);
        snprintf(buf + at, len - at, "%s%s", v ? ", " : "", cmd_verbs[v].name);
    }
}

void cmd_usage(FILE *f)
{
    enum { COL = 28, WIDTH = 79 };
    for (unsigned v = 0; v < cmd_nverbs; v++) {
        char head[80];
        int n = snprintf(head, sizeof(head), "  %s %s", cmd_verbs[v].name, cmd_verbs[v].usage);
        fputs(head, f);
        int at = n;
        if (n >= COL - 1) {
            fputs("\n", f);
            at = 0;
        }
        /* the text wrapped at WIDTH, each line from column COL */
        for (const char *w = cmd_verbs[v].what; *w != '\0';) {
            int len = (int)strcspn(w, " ");
            if (at > COL && at + 1 + len > WIDTH) {
                fputs("\n", f);
                at = 0;
            }
            if (at < COL) {
                fprintf(f, "%*s", COL - at, "");
                at = COL;
            } else {
                fputc(' ', f);
                at++;
            }
            fprintf(f, "%.*s", len, w);
            at += len;
            w += len;
            w += strspn(w, " ");
        }
        fputs("\n", f);
    }
}

/* ---- Selectors ---------------------------------------------------------- */

bool cmd_number(const char *s, long long max, long long *out)
{
    bool hex = s[0] == '0' && (s[1] == 'x' || s[1] == 'X');
    const char *d = hex ? s + 2 : s;
    size_t n = strspn(d, hex ? "0123456789abcdefABCDEF" : "0123456789");
    if (n == 0u || d[n] != '\0') {
        return false;
    }
    /* Leading zeros are no digits of the value: beyond them at most 15 hex
     * or 18 decimal digits, which a long long always holds. */
    if (n - strspn(d, "0") > (hex ? 15u : 18u)) {
        return false;
    }
    long long v = strtoll(d, NULL, hex ? 16 : 10);
    if (v > max) {
        return false;
    }
    *out = v;
    return true;
}

/* The nodes a line's selector names (cmd.h) as the range [*first, *end);
 * returns the rest of the line, or NULL with the cause in err. */
static const char *select_nodes(const app_t *a, const char *line, unsigned *first, unsigned *end,
                                char *err, size_t errlen)
{
    const char *p = line + strspn(line, " \t");
    size_t n = strcspn(p, " \t");
    char tok[32];
    if (n == 0u || (p[0] != '@' && (p[0] < '0' || p[0] > '9'))) {
        const app_inst_t *in = &a->inst[0];
        *first = in->first;
        *end = in->first + in->prod->nodes;
        return p; /* no selector */
    }
    if (n >= sizeof(tok)) {
        snprintf(err, errlen, "'%.20s...': not a node selector (0xNN, NN, @N, @all)", p);
        return NULL;
    }
    memcpy(tok, p, n);
    tok[n] = '\0';
    const char *rest = p + n;
    if (strcmp(tok, "@all") == 0) {
        *first = 0;
        *end = a->nnodes;
        return rest;
    }
    long long v = -1;
    bool num = cmd_number(tok[0] == '@' ? tok + 1 : tok, 100000, &v);
    if (tok[0] == '@') {
        if (!num || v >= (long long)a->nnodes) {
            snprintf(err, errlen, "no node %s (@0..@%u, or @all)", tok, a->nnodes - 1u);
            return NULL;
        }
        *first = (unsigned)v;
        *end = *first + 1u;
        return rest;
    }
    if (!num || v < 1 || v > (long long)CO_NODE_ID_MAX) {
        /* An LSS-unconfigured node has none (it reads 0xFF): @N names it. */
        snprintf(err, errlen,
                 "'%s': not a node-ID 1..127 (a node without one: select it by "
                 "index, @N)",
                 tok);
        return NULL;
    }
    unsigned found = 0;
    for (unsigned i = 0; i < a->nnodes; i++) {
        if (co_node_id(a->nodes[i]) == v) {
            *first = i;
            found++;
        }
    }
    if (found != 1u) {
        snprintf(err, errlen,
                 found == 0u
                     ? "no node with node-ID %s"
                     : "node-ID %s is held by more than one node (several interfaces, or a clash): "
                       "select it by index (@N)",
                 tok);
        return NULL;
    }
    *end = *first + 1u;
    return rest;
}

/* ---- Serving a line ----------------------------------------------------- */

/* `get`: one node's true inputs (its instance's) and NMT state. */
static void answer_get(const app_t *a, unsigned node, char *reply, size_t len)
{
    const app_inst_t *in = &a->inst[a->node_inst[node]];
    size_t at = (size_t)snprintf(reply, len, "ok");
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS && in->prod->inputs[i].name != NULL && at < len;
         i++) {
        int32_t v = in->sim.values[i];
        uint32_t m = v < 0 ? (uint32_t)0 - (uint32_t)v : (uint32_t)v;
        at += (size_t)snprintf(reply + at, len - at, " %s=%s%u.%03u", in->prod->inputs[i].name,
                               v < 0 ? "-" : "", m / 1000u, m % 1000u);
    }
    if (at < len) {
        at += (size_t)snprintf(reply + at, len - at, " nmt=%s", app_nmt_name(a, node));
    }
    /* the master-facing faults that are on */
    if (at < len && a->ports[node].unplugged) {
        at += (size_t)snprintf(reply + at, len - at, " unplug=on");
    }
    if (at < len && a->ports[node].hb_stopped) {
        snprintf(reply + at, len - at, " heartbeat=stopped");
    }
}

static const cmd_verb_t *find_verb(const char *name)
{
    for (unsigned v = 0; v < cmd_nverbs; v++) {
        if (strcmp(cmd_verbs[v].name, name) == 0) {
            return &cmd_verbs[v];
        }
    }
    return NULL;
}

/* Parse the line's arguments (after its verb, in buf) for instance k. */
static bool parse_for(cmd_ctx_t *c, const cmd_verb_t *verb, const char *args, unsigned k,
                      cmd_args_t *out, char *err, size_t errlen)
{
    char buf[CMD_LINE_MAX + 1u];
    snprintf(buf, sizeof(buf), "%s", args);
    char *save = NULL;
    (void)strtok_r(buf, " \t\r", &save); /* the verb */
    memset(out, 0, sizeof(*out));
    return verb->parse(c, k, &save, out, err, errlen);
}

/* A verb on instances k0..k1 (nodes [first, end)): checked for every
 * instance, then carried out on all; an error names the instance's
 * product when several are selected. */
static bool run_verb(cmd_ctx_t *c, const cmd_verb_t *verb, const char *cmd, unsigned first,
                     unsigned end, char *reply, size_t len)
{
    app_t *a = c->a;
    unsigned k0 = a->node_inst[first];
    unsigned k1 = a->node_inst[end - 1u];
    char err[600];
    cmd_args_t args;
    for (int pass = 0; pass < 2; pass++) { /* 0: check all; 1: carry out */
        for (unsigned k = k0; k <= k1; k++) {
            /* Pass 1 parses what pass 0 accepted, on instances the line
             * has not changed yet (replay takes pass 0's tables): it
             * succeeds as it did. */
            if (!parse_for(c, verb, cmd, k, &args, err, sizeof(err))) {
                const char *id = a->inst[k].prod->id;
                snprintf(reply, len, "error: %s%s%s", k1 > k0 ? id : "", k1 > k0 ? ": " : "", err);
                return false;
            }
            if (pass == 1 && verb->scope == CMD_NODES) {
                const app_inst_t *in = &a->inst[k];
                unsigned lo = first > in->first ? first : in->first;
                unsigned hi = co_min_u32(end, in->first + in->prod->nodes);
                for (unsigned i = lo; i < hi; i++) {
                    verb->apply(c, k, i, &args);
                }
            } else if (pass == 1) {
                verb->apply(c, k, a->inst[k].first, &args);
                if (verb->scope == CMD_PROGRAM) {
                    break;
                }
            }
        }
    }
    snprintf(reply, len, "ok");
    return true;
}

void cmd_line(app_t *a, cmd_channel_t ch, const char *line, uint32_t now, char *reply, size_t len)
{
    cmd_ctx_t c = {.a = a, .now = now};
    char err[256];
    unsigned first = 0;
    unsigned end = 0;
    const char *cmd = select_nodes(a, line, &first, &end, err, sizeof(err));
    if (cmd == NULL) {
        snprintf(reply, len, "error: %s", err);
        return;
    }
    cmd += strspn(cmd, " \t\r");
    char names[128];
    cmd_verb_names(names, sizeof(names));
    if (cmd[0] == '\0' || cmd[0] == '#') {
        snprintf(reply, len, "error: no command (%s)", names);
        return;
    }
    char word[32];
    size_t n = strcspn(cmd, " \t\r");
    snprintf(word, sizeof(word), "%.*s", (int)(n < sizeof(word) ? n : sizeof(word) - 1u), cmd);
    const cmd_verb_t *verb = n < sizeof(word) ? find_verb(word) : NULL;
    if (verb == NULL) {
        snprintf(reply, len, "error: unknown command '%.*s' (%s)", (int)n, cmd, names);
        return;
    }
    if (verb->scope == CMD_QUERY) {
        cmd_args_t args;
        if (!parse_for(&c, verb, cmd, a->node_inst[first], &args, err, sizeof(err))) {
            snprintf(reply, len, "error: %s", err);
        } else if (end - first != 1u && a->inst[a->node_inst[first]].prod->nodes != end - first) {
            snprintf(reply, len, "error: get needs one node (select it: 0xID or @N)");
        } else {
            answer_get(a, first, reply, len);
        }
        return;
    }
    if (run_verb(&c, verb, cmd, first, end, reply, len) && ch == CMD_CONTROL) {
        char shown_line[4u * CMD_LINE_MAX + 8u];
        lp_log("control: %s", lp_shown(line, shown_line, sizeof(shown_line)));
    }
}
