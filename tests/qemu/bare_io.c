/*
 * bare_io.c - see bare_io.h: semihosting output and exit, a small printf,
 * and the C library functions the tests call (strtoul, abort).
 */
#include "bare_io.h"

#include <stdbool.h>
#include <stdint.h>
#include <stdlib.h>
#include <string.h>

/* ---- ARM semihosting (a "bkpt 0xab" the emulator serves) ------------- */

#define SYS_WRITE0 0x04u
#define SYS_EXIT_EXTENDED 0x20u
#define ADP_STOPPED_APPLICATION_EXIT 0x20026u

static uint32_t semihost(uint32_t op, const void *arg)
{
    register uint32_t r0 __asm__("r0") = op;
    register const void *r1 __asm__("r1") = arg;
    __asm__ volatile("bkpt 0xab" : "+r"(r0) : "r"(r1) : "memory");
    return r0;
}

void bare_exit(int status)
{
    const uint32_t block[2] = {ADP_STOPPED_APPLICATION_EXIT, (uint32_t)status};
    (void)semihost(SYS_EXIT_EXTENDED, block);
    for (;;) {
    }
}

void abort(void)
{
    bare_printf("abort()\n");
    bare_exit(134); /* as a host shell reports SIGABRT */
}

/* ---- formatting ------------------------------------------------------ */

/* Output goes to a buffer (snprintf) or, line by line, to the console. */
typedef struct sink {
    char *buf;
    size_t size; /* buffer bytes, 0 for the console */
    size_t len;  /* characters produced */
    char line[96];
    size_t fill; /* console: characters in line[] */
} sink_t;

static void flush(sink_t *s)
{
    if (s->fill != 0u) {
        s->line[s->fill] = '\0';
        (void)semihost(SYS_WRITE0, s->line);
        s->fill = 0;
    }
}

static void put(sink_t *s, char c)
{
    if (s->size != 0u) {
        if (s->len + 1u < s->size) {
            s->buf[s->len] = c;
        }
    } else {
        s->line[s->fill++] = c;
        if (c == '\n' || s->fill + 1u >= sizeof(s->line)) {
            flush(s);
        }
    }
    s->len++;
}

static void pad(sink_t *s, char c, int n)
{
    while (n-- > 0) {
        put(s, c);
    }
}

static void format(sink_t *s, const char *fmt, va_list ap)
{
    for (; *fmt != '\0'; fmt++) {
        if (*fmt != '%') {
            put(s, *fmt);
            continue;
        }
        fmt++;
        bool left = false;
        char fill = ' ';
        for (;; fmt++) {
            if (*fmt == '-') {
                left = true;
            } else if (*fmt == '0') {
                fill = '0';
            } else {
                break;
            }
        }
        int width = 0;
        while (*fmt >= '0' && *fmt <= '9') {
            width = width * 10 + (*fmt++ - '0');
        }
        int longs = 0; /* 0: int, 1: long or size_t, 2: long long */
        for (; *fmt == 'l' || *fmt == 'z'; fmt++) {
            longs++; /* "z": size_t is no wider than long here */
        }
        char tmp[24];
        int n = 0;
        const char *str = tmp;
        unsigned long long u = 0;
        bool neg = false;
        unsigned base = 10;
        switch (*fmt) {
        case 'd':
        case 'i': {
            long long v = longs == 2   ? va_arg(ap, long long)
                          : longs == 1 ? va_arg(ap, long)
                                       : va_arg(ap, int);
            neg = v < 0;
            u = neg ? 0ull - (unsigned long long)v : (unsigned long long)v;
            break;
        }
        case 'u':
        case 'x':
        case 'X':
            u = longs == 2   ? va_arg(ap, unsigned long long)
                : longs == 1 ? va_arg(ap, unsigned long)
                             : va_arg(ap, unsigned);
            base = *fmt == 'u' ? 10u : 16u;
            break;
        case 'c':
            tmp[0] = (char)va_arg(ap, int);
            n = 1;
            break;
        case 's':
            str = va_arg(ap, const char *);
            if (str == NULL) {
                str = "(null)";
            }
            n = (int)strlen(str);
            break;
        case '%':
            tmp[0] = '%';
            n = 1;
            break;
        default: /* unsupported: show it rather than guess */
            tmp[0] = '%';
            tmp[1] = *fmt;
            n = 2;
            if (*fmt == '\0') {
                fmt--;
                n = 1;
            }
            break;
        }
        if (str == tmp && n == 0) { /* a number, digits from the right */
            const char *digits = *fmt == 'X' ? "0123456789ABCDEF" : "0123456789abcdef";
            char rev[22];
            int k = 0;
            do {
                rev[k++] = digits[u % base];
                u /= base;
            } while (u != 0u);
            if (neg) {
                if (fill == '0') {
                    put(s, '-');
                    width--;
                } else {
                    rev[k++] = '-';
                }
            }
            while (k > 0) {
                tmp[n++] = rev[--k];
            }
        }
        if (!left) {
            pad(s, fill, width - n);
        }
        for (int i = 0; i < n; i++) {
            put(s, str[i]);
        }
        if (left) {
            pad(s, ' ', width - n);
        }
    }
}

int bare_vsnprintf(char *buf, size_t size, const char *fmt, va_list ap)
{
    static char none[1];
    sink_t s = {.buf = size != 0u ? buf : none, .size = size != 0u ? size : 1u};
    format(&s, fmt, ap);
    s.buf[s.len < s.size ? s.len : s.size - 1u] = '\0';
    return (int)s.len;
}

int bare_snprintf(char *buf, size_t size, const char *fmt, ...)
{
    va_list ap;
    va_start(ap, fmt);
    int n = bare_vsnprintf(buf, size, fmt, ap);
    va_end(ap);
    return n;
}

int bare_printf(const char *fmt, ...)
{
    sink_t s = {0};
    va_list ap;
    va_start(ap, fmt);
    format(&s, fmt, ap);
    va_end(ap);
    flush(&s);
    return (int)s.len;
}

/* ---- C library functions the tests call ------------------------------ */

static int digit(char c)
{
    if (c >= '0' && c <= '9') {
        return c - '0';
    }
    if (c >= 'a' && c <= 'z') {
        return c - 'a' + 10;
    }
    if (c >= 'A' && c <= 'Z') {
        return c - 'A' + 10;
    }
    return 99;
}

unsigned long strtoul(const char *restrict str, char **restrict end, int base)
{
    const char *p = str;
    while (*p == ' ' || *p == '\t') {
        p++;
    }
    if ((base == 0 || base == 16) && p[0] == '0' && (p[1] == 'x' || p[1] == 'X') &&
        digit(p[2]) < 16) {
        p += 2;
        base = 16;
    } else if (base == 0) {
        base = p[0] == '0' ? 8 : 10;
    }
    unsigned long v = 0;
    const char *start = p;
    for (; digit(*p) < base; p++) {
        v = v * (unsigned long)base + (unsigned long)digit(*p);
    }
    if (end != NULL) {
        *end = (char *)(p == start ? str : p);
    }
    return v;
}

size_t strlen(const char *s)
{
    size_t n = 0;
    while (s[n] != '\0') {
        n++;
    }
    return n;
}

int strcmp(const char *a, const char *b)
{
    while (*a != '\0' && *a == *b) {
        a++;
        b++;
    }
    return (unsigned char)*a - (unsigned char)*b;
}
