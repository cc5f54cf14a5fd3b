/*
 * bare_io.h - the little of the C library the unit tests use, for the
 * bare-metal test images (no C library is linked there): formatted output
 * over ARM semihosting, which qemu prints on the host's stdout.
 * harness.h includes this after <stdio.h> when HARNESS_BARE is defined, so
 * the tests' printf, fprintf(stderr, ...) and snprintf land here.
 */
#ifndef BARE_IO_H
#define BARE_IO_H

#include <stdarg.h>
#include <stddef.h>

/* printf subset: flags '-' '0', a width, length l/ll/z, and d i u x X c s %. */
int bare_printf(const char *fmt, ...) __attribute__((format(printf, 1, 2)));
int bare_snprintf(char *buf, size_t size, const char *fmt, ...)
    __attribute__((format(printf, 3, 4)));
int bare_vsnprintf(char *buf, size_t size, const char *fmt, va_list ap);

#define printf bare_printf
#define snprintf bare_snprintf
/* One output stream: stdout and stderr both reach qemu's stdout. */
#define fprintf(stream, ...) bare_printf(__VA_ARGS__)

/* Ends the emulator with this exit status (semihosting SYS_EXIT_EXTENDED). */
void bare_exit(int status) __attribute__((noreturn));

#endif /* BARE_IO_H */
