/*
 * cfi_flash.h - a driver for parallel NOR flash with the Intel/Sharp
 * command set (CFI primary command set 0x0001) on a 32-bit bus made of two
 * x16 chips side by side, as QEMU's "virt" machines wire theirs
 * (hw/riscv/virt.c: pflash_cfi01, width 4, device-width 2, 256 KiB
 * blocks; bank 1 at 0x22000000, 32 MiB). It provides the flash_ops_t of
 * boards/common/flash_ee.h, so the EEPROM emulation on this flash is the
 * same code as on the Nucleo's internal flash.
 *
 * Commands go to both chips at once (the byte repeated in each half of the
 * 32-bit word); a status read returns both chips' status registers, one per
 * half. Programming is done a 32-bit word at a time: see cfi_program16().
 *
 * Everything here blocks until the flash is done (polling the status
 * register, bounded) and must not be called from an interrupt handler: the
 * flash reads as status, not as data, while a command is in progress.
 */
#ifndef CFI_FLASH_H
#define CFI_FLASH_H

#include <stdbool.h>
#include <stdint.h>

#include "flash_ee.h"

/* A bank of flash: where it is mapped, its size and its erase block size
 * (bytes, both chips together). Filled in by cfi_flash_probe(). */
typedef struct cfi_flash {
    uint32_t base;
    uint32_t size;
    uint32_t block_size;
} cfi_flash_t;

/*
 * Check that an Intel command set flash answers a CFI query at base, with
 * one uniform erase block region, and record its size and block size
 * (both chips). Leaves the flash in read-array mode. Returns false (and
 * size and block_size 0)
 * when no such flash answers (the bus reads back something else).
 */
bool cfi_flash_probe(cfi_flash_t *f, uint32_t base);

/* The flash_ee_t operations on a probed bank; ctx is the cfi_flash_t.
 * erase: one block (any address in it); program16: an erased (0xFFFF),
 * even-addressed half-word, refused (false) otherwise; read: plain reads
 * in read-array mode. Failures (status register error bits, a flash that
 * does not finish, the read-back differing) return false. */
extern const flash_ops_t cfi_flash_ops;

#endif /* CFI_FLASH_H */
