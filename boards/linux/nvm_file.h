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
    int lock_fd;      /* lp_nvm_lock's hold on this kernel; -1 or 0: none */
    char hold[160];   /* the hold file's line while held ("": none) */
    uint32_t renewed; /* when lp_nvm_renew last touched the hold file */
    bool lost;        /* the hold file is gone or another's: logged once */
} lp_nvm_t;

/*
 * The hold file, FILE.lock beside the file (the resolved path's), holds one
 * line: "canopen-hold 1 boot=B pidns=N pid=P start=S by=NAME", the kernel's
 * boot id, the PID namespace's inode, the holder's PID and start time (field
 * 22 of /proc/PID/stat) and its program. tools/emu --flash makes the same
 * file, so each refuses the other. The holder touches its mtime every
 * LP_NVM_RENEW_US; a hold of another kernel (another User-Mode Linux, or
 * the host seen from one) is stale once it is LP_NVM_LEASE_S seconds old,
 * one of this kernel and PID namespace as soon as its process is gone.
 */
#define LP_NVM_RENEW_US 1000000u
#define LP_NVM_LEASE_S 10

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
 * lp_nvm_unlock: one file, one user, across kernels (see the hold file
 * above). A stale hold file is removed (logged) and the file taken.
 * Returns 0; -2 with the cause in err when another holder (this process
 * or another, on this kernel or another) has the same resolved path; -1
 * when the hold cannot be made. Messages begin with opt and path as
 * lp_nvm_open's.
 */
int lp_nvm_lock(lp_nvm_t *n, const char *opt, const char *path, char *err, unsigned errlen);

/* Keep the hold alive at time now (us, the loop's clock): the hold file's
 * mtime touched when LP_NVM_RENEW_US have passed. Returns the time until
 * the next renewal is due. A hold file gone or another's is logged once. */
uint32_t lp_nvm_renew(lp_nvm_t *n, uint32_t now);

/* Give the hold back: the hold file is removed (if it is still ours). */
void lp_nvm_unlock(lp_nvm_t *n);

/* len bytes at addr of the EEPROM (its mirror); false outside it. */
bool lp_nvm_read(const lp_nvm_t *n, uint32_t addr, void *buf, uint32_t len);

/* Replace len bytes at addr: the file is rewritten atomically, the mirror
 * changed only once that worked (false, cause logged, nothing changed). */
bool lp_nvm_write(lp_nvm_t *n, uint32_t addr, const void *buf, uint32_t len);

#endif /* LINUX_NVM_FILE_H */
