/*
 * log.c - the program's log; see log.h.
 */
#include "log.h"

#include <stdarg.h>
#include <stdio.h>
#include <time.h>

#include "co_common.h"

/* The log is the process's one piece of board state outside the ports
 * (its file, time zero and clock): set once at start-up, only read
 * afterwards. */
static FILE *log_file;
static struct timespec log_t0;
static bool log_wall;

void lp_log_open(FILE *f)
{
    log_file = f;
}

bool lp_log_is_file(void)
{
    return log_file != NULL;
}

void lp_log_start(void)
{
    clock_gettime(CLOCK_MONOTONIC, &log_t0);
}

void lp_log_clock(bool wall)
{
    log_wall = wall;
}

void lp_log(const char *fmt, ...)
{
    FILE *f = log_file != NULL ? log_file : stderr;
    struct timespec ts;
    if (log_wall) {
        /* UTC: a log compared with another machine's, or read in another
         * zone, needs no zone to be known */
        clock_gettime(CLOCK_REALTIME, &ts);
        struct tm tm;
        char when[32];
        gmtime_r(&ts.tv_sec, &tm);
        strftime(when, sizeof(when), "%Y-%m-%d %H:%M:%S", &tm);
        fprintf(f, "[%s.%03ld] ", when, ts.tv_nsec / 1000000L);
    } else {
        /* Seconds since the start (the kernel's boot meant nothing to a reader) */
        clock_gettime(CLOCK_MONOTONIC, &ts);
        long long ns = ((long long)ts.tv_sec - (long long)log_t0.tv_sec) * 1000000000LL +
                       (ts.tv_nsec - log_t0.tv_nsec);
        fprintf(f, "[%4lld.%03lld] ", ns / 1000000000LL, ns / 1000000LL % 1000LL);
    }
    va_list ap;
    va_start(ap, fmt);
    vfprintf(f, fmt, ap);
    va_end(ap);
    fputc('\n', f);
    fflush(f);
}

bool lp_rate_allow(lp_rate_t *r, uint32_t now, unsigned lines)
{
    if (!r->open || !co_time_before(now, r->start + LP_RATE_US)) {
        r->open = true;
        r->start = now;
        r->shown = 0;
    }
    if (r->shown < lines) {
        r->shown++;
        return true;
    }
    return false;
}

uint32_t lp_rate_wait(const lp_rate_t *r, uint32_t now)
{
    return r->open ? co_time_until(now, r->start + LP_RATE_US) : 0u;
}

const char *lp_shown(const char *text, char *out, size_t len)
{
    size_t at = 0;
    for (const unsigned char *c = (const unsigned char *)text; *c != '\0' && at + 5u < len; c++) {
        if (*c >= 0x20u && *c < 0x7Fu && *c != '\\') {
            out[at++] = (char)*c;
        } else {
            at += (size_t)snprintf(out + at, len - at, "\\x%02X", *c);
        }
    }
    out[at] = '\0';
    return out;
}
