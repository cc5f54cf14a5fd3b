/*
 * sim.c - see sim.h.
 */
#include "sim.h"

#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>

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
    for (unsigned i = 0; i < PRODUCT_MAX_INPUTS; i++) {
        s->values[i] = p->inputs[i].initial;
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
        int32_t v[PRODUCT_MAX_INPUTS];
        memcpy(v, s->values, sizeof(v));
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
            char *end;
            double x = strtod(eq + 1, &end);
            double lim = s->prod->inputs[i].limit;
            if (end == eq + 1 || *end != '\0' || !isfinite(x) || fabs(x) > lim) {
                snprintf(err, errlen, "'%s': not a number within +-%.0f", tok, lim);
                return false;
            }
            v[i] = (int32_t)lround(x * 1000.0);
            count++;
        }
        if (count == 0) {
            snprintf(err, errlen, "usage: set %s", usage);
            return false;
        }
        memcpy(s->values, v, sizeof(v));
        return true;
    }
    if (strcmp(cmd, "can") == 0) {
        return can_command(s, &save, err, errlen);
    }
    snprintf(err, errlen, "unknown command '%s' (set, fault, can, quit)", cmd);
    return false;
}

/* One complete line: apply it, or reject it whole. */
static void end_line(sim_t *s, sim_report_fn report, void *ctx)
{
    s->line[s->len] = '\0';
    char err[200];
    if (s->overflow) {
        snprintf(err, sizeof(err), "line too long (more than %u characters): ignored",
                 SIM_LINE_MAX);
        report(ctx, "", err);
    } else if (s->nul) {
        /* Not cut at the NUL: "set x=11<NUL>y=99" is neither command. */
        report(ctx, "", "line contains a NUL byte: ignored");
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
