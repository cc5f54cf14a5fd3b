/*
 * replay_csv.c - a replay table from a CSV file; see replay_csv.h.
 */
#include "replay_csv.h"

#include <errno.h>
#include <fcntl.h>
#include <math.h>
#include <stdio.h>
#include <stdlib.h>
#include <string.h>
#include <sys/stat.h>
#include <unistd.h>

#include "sim.h"

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

bool replay_csv_load(const product_t *prod, const char *file, sim_replay_t *r, char *err,
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
        snprintf(err, errlen,
                 "replay %s: %lld bytes, more than the %u a replay file may have "
                 "(it is read while every node waits)",
                 file, (long long)st.st_size, SIM_REPLAY_BYTES);
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
                snprintf(err, errlen, "replay %s: line %u: expected a header t,NAME,...", file, no);
                ok = false;
                break;
            }
            for (unsigned k = 1; k < n && ok; k++) {
                int i = sim_input_index(prod, field[k], strlen(field[k]));
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
            snprintf(err, errlen, "replay %s: line %u: time %s not after the row before", file, no,
                     field[0]);
            ok = false;
            break;
        }
        r->t_us[r->rows] = tu;
        for (unsigned k = 1; k < n && ok; k++) {
            double lim = prod->inputs[input_of[k - 1u]].limit;
            if (!sim_value(field[k], lim, &r->v[r->rows][k - 1u])) {
                snprintf(err, errlen, "replay %s: line %u: '%s' not a number within +-%.0f", file,
                         no, field[k], lim);
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
