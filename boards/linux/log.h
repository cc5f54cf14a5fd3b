/*
 * log.h - the program's log (stderr, or --log FILE): time-stamped lines,
 * a rate limit for repeated kinds, and text made safe to show.
 */
#ifndef LINUX_LOG_H
#define LINUX_LOG_H

#include <stdbool.h>
#include <stddef.h>
#include <stdint.h>
#include <stdio.h>

/* Repeated log lines of one kind (dropped frames, rejected input) are
 * limited per window of this length (lp_rate_t). */
#define LP_RATE_US 1000000u

/* A rate limit for one kind of log line: a window of LP_RATE_US from the
 * first line, at most a given number of lines in it. */
typedef struct lp_rate {
    uint32_t start; /* start of the current window */
    unsigned shown; /* lines logged in it */
    bool open;      /* a window was started */
} lp_rate_t;

/* Log a line with a time stamp to the log (stderr or --log FILE): by
 * default seconds since lp_log_start ("[   1.234] "), with wall true the
 * UTC wall clock ("[2026-11-25 01:05:12.345] "). */
void lp_log(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
void lp_log_open(FILE *f);
/* Whether the log is a file (--log), not standard error. */
bool lp_log_is_file(void);
/* The log's time zero (call first thing), and its clock (lp_log). */
void lp_log_start(void);
void lp_log_clock(bool wall);

/*
 * Rate limit: true when a line may be logged at time now (at most `lines`
 * in a window); the caller counts what it does not log and logs the count
 * once allowed again. lp_rate_wait() is the delay until the current
 * window ends (0: a line may be logged now).
 */
bool lp_rate_allow(lp_rate_t *r, uint32_t now, unsigned lines);
uint32_t lp_rate_wait(const lp_rate_t *r, uint32_t now);

/* text as the log shows it, into out (len bytes): a byte that is not
 * printable ASCII (control characters, binary input, also UTF-8) and the
 * backslash as \xNN, so that what a client or standard input sent never
 * reaches the log or a terminal raw. Returns out. */
const char *lp_shown(const char *text, char *out, size_t len);

#endif /* LINUX_LOG_H */
