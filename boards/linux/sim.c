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

bool sim_command(sim_t *s, const char *line, char *err, unsigned errlen)
{
    char buf[256];
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
        char list[96] = "";
        for (int k = 0; k < (int)PRODUCT_MAX_INPUTS && s->prod->faults[k] != NULL; k++) {
            size_t at = strlen(list);
            snprintf(list + at, sizeof(list) - at, "%s%s", k ? "|" : "", s->prod->faults[k]);
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
    snprintf(err, errlen, "unknown command '%s' (set, fault, quit)", cmd);
    return false;
}
