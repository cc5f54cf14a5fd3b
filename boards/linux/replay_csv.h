/*
 * replay_csv.h - a replay table read from a CSV file (the `replay` command).
 *
 * The file: at most SIM_REPLAY_BYTES bytes and SIM_REPLAY_ROWS rows, lines
 * of at most SIM_LINE_MAX characters, a UTF-8 byte order mark at its start
 * ignored; a header row "t,NAME,..." (t or time, then product input names,
 * each once), then rows "SECONDS,VALUE,...": times from 0, strictly
 * increasing; blank lines and lines starting with # are skipped. Values
 * are in the input's unit, within its limit. A file that cannot be read or
 * is malformed is an error naming its line.
 */
#ifndef LINUX_REPLAY_CSV_H
#define LINUX_REPLAY_CSV_H

#include <stdbool.h>
#include <stdint.h>

#include "product.h"

/* Longest line of a replay file, without its newline (the command line's
 * limit too: cmd.h). */
#define SIM_LINE_MAX 255u

/* Most data rows of a replay file. */
#define SIM_REPLAY_ROWS 512u

/* Largest replay file: read whole while every node waits, so its size is
 * what one command may cost the loop (256 KiB: about 5 ms in User-Mode
 * Linux, the slowest place it runs). 512 rows of 255 characters fit. */
#define SIM_REPLAY_BYTES 262144u

/* The replay table: times from the `replay` command's time. */
typedef struct sim_replay {
    uint32_t rows;
    int8_t col[PRODUCT_MAX_INPUTS]; /* input i is column col[i]; -1: not in it */
    uint64_t t_us[SIM_REPLAY_ROWS];
    int32_t v[SIM_REPLAY_ROWS][PRODUCT_MAX_INPUTS]; /* by column */
} sim_replay_t;

/*
 * Load FILE's table for product prod (a regular file only, opened without
 * waiting, so a FIFO cannot stall the program). false with the cause in
 * err (errlen bytes); *r is then unusable. A relative name is the
 * program's working directory's.
 */
bool replay_csv_load(const product_t *prod, const char *file, sim_replay_t *r, char *err,
                     unsigned errlen);

#endif /* LINUX_REPLAY_CSV_H */
