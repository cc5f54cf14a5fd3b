/*
 * prog.h - program download in the Linux program (--program-download):
 * the loader side of co_progdl.h for a product instance, its program area
 * as files beside the instance's EEPROM file, and the dictionary that
 * carries it (the product's own with 1F50h, 1F51h, 1F56h and 1F57h put in).
 * The behaviour for people is docs/program-download.md, "The Linux
 * program".
 *
 * The files, beside the EEPROM file FILE (its resolved path):
 *  - FILE.prog: the installed image, whole (co_image.h). Missing: nothing
 *    was ever downloaded, the program is the build's own (1F56h:1 =
 *    CO_PROGRAM_ID). Empty, or anything that is not a valid image of this
 *    product and board: no valid program (what a clear leaves).
 *  - FILE.prog.tmp: the download in progress, renamed FILE.prog once its
 *    CRC checked again (co_port_prog_commit). Left by a killed process,
 *    it is removed at the next start.
 * Each change of FILE.prog is a rename of a file written and fsync'ed
 * before, and the directory fsync'ed after: a process killed at any point
 * comes back with the old program (before the clear), no valid program
 * (from the clear to the commit), or the whole new one; never a part.
 *
 * The device has one program: its first node carries the loader (the
 * objects and the service); a two-node product's second node keeps the
 * manual's dictionary, and halts and restarts with the first.
 * Everything here runs in the program's one thread; nothing blocks but
 * the file system calls.
 */
#ifndef LINUX_PROG_H
#define LINUX_PROG_H

#include <stdbool.h>
#include <stdint.h>

#include "co_progdl.h"
#include "product.h"

/* Entries a product's table may have for its loader copy (its own and the
 * eight of CO_PROGDL_LOADER_ENTRIES). */
#define LP_PROG_MAX_ENTRIES 256u
/* The largest image the Linux program takes (status "address error" beyond):
 * its payload is not run, only kept, so this only bounds the file. */
#define LP_PROG_MAX_LEN (1u << 20)

/* One product instance's program download. */
typedef struct lp_prog {
    const char *prod_id; /* the product's ID, which an image must carry */
    bool own;            /* no FILE.prog: the build's own program (CO_PROGRAM_ID) */
    char path[4200];     /* FILE.prog */
    char tmp[4200];      /* FILE.prog.tmp */
    int fd;              /* the download's FILE.prog.tmp, -1: none open */
    co_progdl_t pd;      /* the loader's state (co_port_progdl) */
    co_node_t *nodes[PRODUCT_MAX_NODES];
    unsigned nnodes;
    /* The first node's configuration: the product's with the loader. */
    co_od_entry_t entries[LP_PROG_MAX_ENTRIES];
    co_od_t od;
    co_node_cfg_t cfg;
    const co_service_t *services[8];
    /* 100Ah (Manufacturer software version) where the product has one: the
     * manual's text, followed by the installed image's program ID. */
    char version[96];
    char version_base[64];
    co_od_entry_t *version_entry; /* in entries[], NULL: none */
} lp_prog_t;

/*
 * The dictionary and configuration of a loader node whose product's own
 * configuration is base, into g (g->od, g->cfg): the product's table with CO_PROGDL_LOADER_ENTRIES
 * put in, its services with co_progdl_service, SDO segmented and block transfer (an image is more
 * than 4 bytes; a product whose manual has expedited SDO only gets them here), and
 * co_progdl_domain. 100Ah, where the table has it, reads g->version. Returns 0, or -1 with the
 * cause in err (a table too large, or one that has 1F50h-1F57h already).
 */
int lp_prog_build(lp_prog_t *g, const co_node_cfg_t *base, char *err, unsigned errlen);

/*
 * Open the program area of the instance of product prod_id (the ID an
 * image must carry; kept, not copied) whose EEPROM file is nvm_real
 * (resolved, nvm_file.h) and whose nodes are nodes[0..n-1], created and
 * not started; nodes[0] gets g's configuration (lp_prog_build done). A
 * FILE.prog.tmp is removed (a download a killed process left); FILE.prog
 * decides the state (above), logged. Returns 0, or -1 with the cause in
 * err (the name too long, a file that cannot be read or removed).
 */
int lp_prog_open(lp_prog_t *g, const char *prod_id, const char *nvm_real, co_node_t *const nodes[],
                 unsigned n, char *err, unsigned errlen);

/* Whether the product's program runs (1F51h:1 reads 1): false while
 * stopped or without a valid program, when the instance samples nothing
 * and its ports send only what a bootloader sends (can_port.h,
 * lp_port_t.progdl). */
bool lp_prog_running(const lp_prog_t *g);

/* Close what a download left open (at exit): its temporary file stays,
 * and the next start removes it. */
void lp_prog_close(lp_prog_t *g);

#endif /* LINUX_PROG_H */
