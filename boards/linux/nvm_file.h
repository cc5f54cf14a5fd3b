/*
 * nvm_file.h - the EEPROM of a product instance as a file: read whole at
 * start, held against other users, every save an atomic replacement
 * (temporary file, fsync, rename), so the file is never half-written.
 */
#ifndef LINUX_NVM_FILE_H
#define LINUX_NVM_FILE_H

#include <stdbool.h>
#include <stdint.h>

/* The EEPROM: one file shared by the nodes of a product. */
typedef struct lp_nvm {
    const char *path; /* NULL: RAM only, lost at exit; else path[] below */
    char real[4096];  /* the file's resolved path (symlinks followed) */
    uint8_t *mem;     /* mirror of the file, size bytes (caller's storage); always
                       * what the file holds (a write that fails changes neither) */
    uint32_t size;
    int lock_fd; /* lp_nvm_lock's hold on the file; -1 or 0: none */
} lp_nvm_t;

/*
 * Open the EEPROM file (path NULL: RAM only). path must be a regular file,
 * or not exist in an existing directory; anything else (a directory, a
 * FIFO, a device, a missing directory, a symbolic link to nothing) is
 * refused with -2 and a one-line cause in err (errlen bytes; it begins
 * with opt, the option that named the file, and path); it is looked at
 * with stat() before any
 * open, so a FIFO never blocks. The file is read into mem (size bytes;
 * beyond a short file's end: erased, 0xFF); a missing file reads as
 * erased. Nothing is written, created or changed on disk here: the file is
 * written by the first save only. -1 with the cause in err: the file
 * could not be read. 0: done (notes logged).
 */
int lp_nvm_open(lp_nvm_t *n, const char *opt, const char *path, uint8_t *mem, uint32_t size,
                char *err, unsigned errlen);

/*
 * Hold n's file (lp_nvm_open'ed; nothing for RAM) for this process until
 * lp_nvm_unlock or its end: one file, one user. Returns 0; -2 with the
 * cause in err when another holder (this process or another) has the
 * same resolved path; -1 when the hold cannot be made. Messages begin
 * with opt and path as lp_nvm_open's.
 */
int lp_nvm_lock(lp_nvm_t *n, const char *opt, const char *path, char *err, unsigned errlen);
void lp_nvm_unlock(lp_nvm_t *n);

/* len bytes at addr of the EEPROM (its mirror); false outside it. */
bool lp_nvm_read(const lp_nvm_t *n, uint32_t addr, void *buf, uint32_t len);

/* Replace len bytes at addr: the file is rewritten atomically, the mirror
 * changed only once that worked (false, cause logged, nothing changed). */
bool lp_nvm_write(lp_nvm_t *n, uint32_t addr, const void *buf, uint32_t len);

#endif /* LINUX_NVM_FILE_H */
